#version 450
// Shadow-map baseline: shadow casters' depth from the light (eye-relative positions).
layout(location = 0) in vec3 in_pos;

layout(push_constant) uniform Push {
    mat4 light_view_proj;
} pc;

void main() {
    gl_Position = pc.light_view_proj * vec4(in_pos, 1.0);
}
