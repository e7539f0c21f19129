#version 450
// Transparent casters, drawn forward over the lit opaque scene (not receivers: no shadows on
// them, the paper's "no self-shadowing" variant).
// The BIAS variant is the self-shadowing depth pre-pass (src/render/selfshadow.rs): every
// vertex is pulled towards the eye by 1/1000 of its distance, so that a transparent surface's
// own light cap (the same triangle, drawn by shadow.vert with another transform) lies robustly
// *behind* the stored depth: z-pass (LESS) never counts it, z-fail (GREATER_OR_EQUAL) always
// does, and in both the surface reads as outside its own volume (no self-occlusion acne).
// @variant BIAS DEPTH_BIAS
layout(location = 0) in vec3 in_pos;
layout(location = 1) in vec3 in_normal;
layout(location = 2) in vec3 in_color;
layout(location = 3) in float in_opacity;
// Per-mesh placement (instance rate, binding 1): rows of the affine map from the baked
// anchor-relative positions to eye-relative ones, and of the normals' linear map. Exactly the
// identity (and zero translation) for a mesh that has not moved with the eye at the anchor,
// so static frames are bit for bit what the baked positions give.
layout(location = 4) in vec4 in_xf0;
layout(location = 5) in vec4 in_xf1;
layout(location = 6) in vec4 in_xf2;
layout(location = 7) in vec4 in_n0;
layout(location = 8) in vec4 in_n1;
layout(location = 9) in vec4 in_n2;

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
    vec4 p = vec4(in_pos, 1.0);
    vec3 pos = vec3(dot(in_xf0, p), dot(in_xf1, p), dot(in_xf2, p));
    v_pos = pos;
    v_normal = vec3(dot(in_n0.xyz, in_normal), dot(in_n1.xyz, in_normal), dot(in_n2.xyz, in_normal));
    v_color = vec4(in_color, in_opacity);
#ifdef DEPTH_BIAS
    gl_Position = pc.view_proj * vec4(pos * (1.0 - 1.0e-3), 1.0);
#else
    gl_Position = pc.view_proj * vec4(pos, 1.0);
#endif
}
