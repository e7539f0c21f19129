#version 450
// Ambient pass: writes depth (fixed function), the ambient term into the float accumulation
// target, and the G-buffer the per-light illumination reads: albedo (a: the terminator bound),
// the face normal (w: the packed smooth normal) and the eye-relative position.
layout(location = 0) in vec3 v_pos;
layout(location = 1) flat in vec3 v_normal;
layout(location = 2) flat in vec3 v_color;
layout(location = 3) in vec3 v_smooth;
layout(location = 4) in float v_bound;

layout(push_constant) uniform Push {
    mat4 view_proj;
    vec4 ambient;
} pc;

layout(location = 0) out vec4 out_accum;
layout(location = 1) out vec4 out_albedo;
layout(location = 2) out vec4 out_normal;
layout(location = 3) out vec4 out_position;

// The smooth shading normal in one float (normal.w): octahedral, 12 bits a component, an
// integer below 2^24 (exact in f32; illuminate.frag unpacks it).
float pack_normal(vec3 n) {
    n /= abs(n.x) + abs(n.y) + abs(n.z);
    vec2 e = n.xy;
    if (n.z < 0.0) {
        e = (vec2(1.0) - abs(n.yx)) * vec2(n.x >= 0.0 ? 1.0 : -1.0, n.y >= 0.0 ? 1.0 : -1.0);
    }
    vec2 q = floor(clamp(e * 0.5 + 0.5, 0.0, 1.0) * 4095.0 + 0.5);
    return q.x * 4096.0 + q.y;
}

void main() {
    out_accum = vec4(v_color * pc.ambient.rgb, 1.0);
    // Two-sided meshes (open, non-manifold, inside-out) show back faces: shade the visible side.
    float side = gl_FrontFacing ? 1.0 : -1.0;
    // The interpolated smooth normal m and bound b: m.L <= b wherever the face looks away from
    // L, so illumination's (n.L - t) with n = m / |m|, t = b / |m| is <= 0 there. t is stored
    // rounded up (8 bits), after a margin for the normal's 12-bit packing.
    float len = length(v_smooth);
    vec3 n = len > 0.0 ? v_smooth / len : v_normal;
    float t = len > 0.0 ? v_bound / len : 0.0;
    out_albedo = vec4(v_color, ceil(clamp(t + 0.004, 0.0, 1.0) * 255.0) / 255.0);
    out_normal = vec4(side * v_normal, pack_normal(side * n));
    out_position = vec4(v_pos, 1.0);
}
