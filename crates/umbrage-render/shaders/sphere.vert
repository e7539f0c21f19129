#version 450
// Analytic spheres, G-buffer pass: each sphere's bounding cube (36 vertices, eye-relative,
// written per frame in f64 on the CPU), drawn with front faces culled so that its back faces
// cover the sphere's whole projection wherever the eye is outside the sphere. The fragment
// shader ray-casts the exact sphere.
layout(location = 0) in vec3 in_pos;
layout(location = 1) in vec3 in_center;
layout(location = 2) in vec3 in_color;
layout(location = 3) in float in_radius;

layout(push_constant) uniform Push {
    mat4 view_proj;
    vec4 ambient;
} pc;

layout(location = 0) out vec3 v_pos;
layout(location = 1) flat out vec3 v_center;
layout(location = 2) flat out vec3 v_color;
layout(location = 3) flat out float v_radius;

void main() {
    v_pos = in_pos;
    v_center = in_center;
    v_color = in_color;
    v_radius = in_radius;
    gl_Position = pc.view_proj * vec4(in_pos, 1.0);
}
