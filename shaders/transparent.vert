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
#ifdef DEPTH_BIAS
    gl_Position = pc.view_proj * vec4(in_pos * (1.0 - 1.0e-3), 1.0);
#else
    gl_Position = pc.view_proj * vec4(in_pos, 1.0);
#endif
}
