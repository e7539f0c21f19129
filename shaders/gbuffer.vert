#version 450
// Scene geometry, pre-transformed to world space relative to the eye (camera-relative
// rendering keeps precision for scenes far from the origin). Flat face normals.
layout(location = 0) in vec3 in_pos;
layout(location = 1) in vec3 in_normal;
layout(location = 2) in vec3 in_color;

layout(push_constant) uniform Push {
    mat4 view_proj;
    vec4 ambient;
} pc;

layout(location = 0) out vec3 v_pos;
layout(location = 1) flat out vec3 v_normal;
layout(location = 2) flat out vec3 v_color;

void main() {
    v_pos = in_pos;
    v_normal = in_normal;
    v_color = in_color;
    gl_Position = pc.view_proj * vec4(in_pos, 1.0);
}
