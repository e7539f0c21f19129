#version 450
// McGuire et al. 2003, EXTRUDE: the dual-length vertex buffer holds every caster vertex twice,
// (xyz, 1) and (xyz, 0). A w = 0 copy is sent to infinity away from the light:
//   (P.xyz * L.w - L.xyz, 0)
// which is the direction P - L for a point light (L.w = 1) and the single point -L for a
// directional light (L.w = 0). L is the light in the caster's object space.
layout(location = 0) in vec4 in_pos;

layout(push_constant) uniform Push {
    mat4 mvp;
    vec4 light;
    vec4 color;
} pc;

void main() {
    vec4 p = in_pos;
    if (in_pos.w == 0.0) {
        p = vec4(in_pos.xyz * pc.light.w - pc.light.xyz, 0.0);
    }
    gl_Position = pc.mvp * p;
}
