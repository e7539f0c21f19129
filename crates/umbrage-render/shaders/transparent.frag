#version 450
// params.z == 0: the "over" pass: dst = dst * (1 - a) + a * albedo * ambient (pc.color.rgb);
// params.z == 1: one light, added: a * albedo * diffuse (no shadows on transparent surfaces).
// The SS variant (partial self-shadowing, --self-shadow) scales each light by what reaches the
// nearest transparent surface at this pixel: 0 where the opaque casters' count (against the
// transparent depth) is non-zero, else the transparent casters' light-intensity map there
// (params.y = 1: stored as log). Exact only for the nearest transparent layer; farther layers
// at the same pixel read the nearest layer's value.
// @variant SS SELF_SHADOW
layout(location = 0) in vec3 v_pos;
layout(location = 1) flat in vec3 v_normal;
layout(location = 2) flat in vec4 v_color;

layout(push_constant) uniform Push {
    mat4 view_proj;
    vec4 light_pos;
    vec4 color;
    vec4 spot;
    vec4 params;
} pc;

layout(location = 0) out vec4 out_color;

#ifdef SELF_SHADOW
layout(set = 0, binding = 0) uniform texture2D t_count;
layout(set = 0, binding = 1) uniform texture2D t_map;
layout(set = 0, binding = 2) uniform sampler s_nearest;
#endif

void main() {
    float a = v_color.a;
    if (pc.params.z < 0.5) {
        out_color = vec4(a * v_color.rgb * pc.color.rgb, a);
        return;
    }
    vec3 n = normalize(gl_FrontFacing ? v_normal : -v_normal);
    vec3 to_light = pc.light_pos.xyz - v_pos * pc.light_pos.w;
    float dist = length(to_light);
    vec3 l = to_light / max(dist, 1e-30);
    float ndotl = max(dot(n, l), 0.0);
    float atten = 1.0;
    if (pc.params.x > 0.0) {
        float r = clamp(dist / pc.params.x, 0.0, 1.0);
        atten = (1.0 - r * r) * (1.0 - r * r);
    }
#ifdef SELF_SHADOW
    ivec2 px = ivec2(gl_FragCoord.xy);
    float opaque = abs(texelFetch(sampler2D(t_count, s_nearest), px, 0).r) > 0.5 ? 0.0 : 1.0;
    vec3 t = texelFetch(sampler2D(t_map, s_nearest), px, 0).rgb;
    vec3 reach = opaque * (pc.params.y > 0.5 ? exp(t) : t);
    out_color = vec4(a * v_color.rgb * ndotl * atten * pc.color.rgb * reach, 0.0);
#else
    out_color = vec4(a * v_color.rgb * ndotl * atten * pc.color.rgb, 0.0);
#endif
}
