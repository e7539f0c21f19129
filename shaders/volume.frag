#version 450
// Debug view: shadow volume faces drawn translucent, coloured by case.
layout(push_constant) uniform Push {
    mat4 mvp;
    vec4 light;
    vec4 color;
} pc;

layout(location = 0) out vec4 out_color;

void main() {
    out_color = pc.color;
}
