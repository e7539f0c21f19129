#version 450
// GPU-only shadow volumes (the Cg article): each vertex carries its face's plane (n, d); a
// vertex whose face does not face the light goes to infinity away from it (EXTRUDE's w = 0
// formula). All three vertices of a face share the plane, so they always agree.
layout(location = 0) in vec3 in_pos;
layout(location = 1) in vec4 in_plane;

layout(push_constant) uniform Push {
    mat4 mvp;
    vec4 light;   // object space, homogeneous
    vec4 color;
} pc;

void main() {
    vec4 p = vec4(in_pos, 1.0);
    if (dot(in_plane.xyz, pc.light.xyz) + in_plane.w * pc.light.w <= 0.0) {
        p = vec4(in_pos * pc.light.w - pc.light.xyz, 0.0);
    }
    vec4 c = pc.mvp * p;
    // Clip w exactly 0 (a direction perpendicular to the view axis) as +tiny: the same
    // primitive in the limit, and what SwiftShader needs (shadow.vert says why).
    if (p.w == 0.0 && c.w == 0.0) {
        c.w = max(max(abs(c.x), abs(c.y)), abs(c.z)) * 8.6736174e-19;
    }
    gl_Position = c;
}
