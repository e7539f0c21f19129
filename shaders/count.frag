#version 450
// Shadow volume counting into a float target (no 8-bit wrap): each rasterised volume face
// adds +1 or -1 by its facing, additively blended. The pipeline's depth test is chosen so
// that exactly the faces the stencil method would count reach this shader: LESS for z-pass,
// GREATER_OR_EQUAL (the faces that fail LESS) for z-fail, ALWAYS for light caps (NEVER).
// pc.color.x is +1 for z-pass (front faces enter) and -1 for z-fail (back faces count up).
layout(push_constant) uniform Push {
    mat4 mvp;
    vec4 light;
    vec4 color;
} pc;

layout(location = 0) out vec4 out_count;

void main() {
    float s = gl_FrontFacing ? 1.0 : -1.0;
    out_count = vec4(s * pc.color.x, 0.0, 0.0, 0.0);
}
