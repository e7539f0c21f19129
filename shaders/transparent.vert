#version 450
// Transparent casters, drawn forward over the lit opaque scene (not receivers: no shadows on
// them, the paper's "no self-shadowing" variant).
layout(location = 0) in vec3 in_pos;
layout(location = 1) in vec3 in_normal;
layout(location = 2) in vec3 in_color;
layout(location = 3) in float in_opacity;

layout(push_constant) uniform Push {
    mat4 view_proj;
    vec4 light_pos;
    vec4 color;
    vec4 spot;
    vec4 params;
} pc;

layout(location = 0) out vec3 v_pos;
layout(location = 1) flat out vec3 v_normal;
layout(location = 2) flat out vec4 v_color;

void main() {
    v_pos = in_pos;
    v_normal = in_normal;
    v_color = vec4(in_color, in_opacity);
    gl_Position = pc.view_proj * vec4(in_pos, 1.0);
}
