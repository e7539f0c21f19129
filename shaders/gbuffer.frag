#version 450
// Ambient pass: writes depth (fixed function), the ambient term into the float accumulation
// target, and the G-buffer the per-light illumination reads.
layout(location = 0) in vec3 v_pos;
layout(location = 1) flat in vec3 v_normal;
layout(location = 2) flat in vec3 v_color;

layout(push_constant) uniform Push {
    mat4 view_proj;
    vec4 ambient;
} pc;

layout(location = 0) out vec4 out_accum;
layout(location = 1) out vec4 out_albedo;
layout(location = 2) out vec4 out_normal;
layout(location = 3) out vec4 out_position;

void main() {
    out_accum = vec4(v_color * pc.ambient.rgb, 1.0);
    out_albedo = vec4(v_color, 1.0);
    // Two-sided meshes (open, non-manifold, inside-out) show back faces: shade the visible side.
    out_normal = vec4(gl_FrontFacing ? v_normal : -v_normal, 0.0);
    out_position = vec4(v_pos, 1.0);
}
