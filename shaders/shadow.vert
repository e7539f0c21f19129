#version 450
// @variant table TABLE
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

// The TABLE variant (the compute path's merged draws, src/pass/compute/draws.rs): the
// caster's transform and object-space light are per-instance attributes (binding 1, one
// 80-byte entry per (light, caster) pair), selected by each indirect record's firstInstance,
// instead of push constants. The expressions below are the same either way (the macros expand
// to the push-constant block's members without TABLE), so are the vertices.
#ifdef TABLE
layout(location = 1) in vec4 in_mvp0;
layout(location = 2) in vec4 in_mvp1;
layout(location = 3) in vec4 in_mvp2;
layout(location = 4) in vec4 in_mvp3;
layout(location = 5) in vec4 in_light;
#define MVP mat4(in_mvp0, in_mvp1, in_mvp2, in_mvp3)
#define LIGHT in_light
#else
#define MVP pc.mvp
#define LIGHT pc.light
#endif

void main() {
    vec4 p = in_pos;
    if (in_pos.w == 0.0) {
        p = vec4(in_pos.xyz * LIGHT.w - LIGHT.xyz, 0.0);
    }
    vec4 c = MVP * p;
    // An extruded vertex whose direction is exactly perpendicular to the view axis lands at
    // clip w = 0 exactly. The clip volume (-w <= x, y <= w, 0 <= z <= w) puts it outside, and
    // clipping keeps the part of each edge towards it with w >= 0; SwiftShader instead
    // projects a w = 0 vertex as if w were 1 (conform case clip.*.w0.*, a driver defect:
    // docs/conform/drivers-notes.md). w = +tiny is the same primitive in the limit, on every
    // driver: the edges to it still run through w > 0 only. The conformance suite's
    // variant (RAW_W0) hands the driver w = 0 as it is.
#ifndef RAW_W0
    if (in_pos.w == 0.0 && c.w == 0.0) {
        c.w = max(max(abs(c.x), abs(c.y)), abs(c.z)) * 8.6736174e-19;
    }
#endif
    gl_Position = c;
}
