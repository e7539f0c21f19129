#version 450
// Per-light illumination (Blinn-Phong), drawn as a full-screen pass where the stencil count
// is zero, added into the float accumulation target.
// @variant COUNT FLOAT_COUNT
// @variant T TRANSMIT
// @variant COUNT_T FLOAT_COUNT,TRANSMIT
// @variant MS MSAA
// The COUNT variant reads the volume count from a float target instead of the stencil. The
// MS variant reads multisampled G-buffer targets at this invocation's sample, which shades
// per sample (each sample lit where its own stencil count is zero).
#ifdef MSAA
layout(set = 0, binding = 0) uniform texture2DMS t_albedo;
layout(set = 0, binding = 1) uniform texture2DMS t_normal;
layout(set = 0, binding = 2) uniform texture2DMS t_position;
#define FETCH(t, px) texelFetch(sampler2DMS(t, s_nearest), px, int(gl_SampleID))
#else
layout(set = 0, binding = 0) uniform texture2D t_albedo;
layout(set = 0, binding = 1) uniform texture2D t_normal;
layout(set = 0, binding = 2) uniform texture2D t_position;
#define FETCH(t, px) texelFetch(sampler2D(t, s_nearest), px, 0)
#endif
layout(set = 0, binding = 3) uniform sampler s_nearest;
#ifdef FLOAT_COUNT
layout(set = 0, binding = 4) uniform texture2D t_count;
#endif
#ifdef TRANSMIT
// The T variants scale the light by the transparent casters' light-intensity map.
layout(set = 0, binding = 5) uniform texture2D t_transmit;
#endif

layout(push_constant) uniform Push {
    vec4 light_pos;   // xyz relative to the eye, w = 1; or xyz towards the light, w = 0
    vec4 color;       // rgb = colour * intensity
    vec4 spot;        // xyz = travel direction, w = cos(half cone) (-2 when not a spot)
    vec4 params;      // x = radius (0: unbounded), y = 1 when the intensity map is in log space
} pc;

layout(location = 0) out vec4 out_color;

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
#ifdef FLOAT_COUNT
    if (abs(texelFetch(sampler2D(t_count, s_nearest), px, 0).r) > 0.5) {
        discard;
    }
#endif
    vec4 pos = FETCH(t_position, px);
    if (pos.w == 0.0) {
        discard;
    }
    vec3 n = normalize(FETCH(t_normal, px).xyz);
    vec3 albedo = FETCH(t_albedo, px).rgb;
    vec3 to_light = pc.light_pos.xyz - pos.xyz * pc.light_pos.w;
    float dist = length(to_light);
    vec3 l = to_light / max(dist, 1e-30);
    float ndotl = dot(n, l);
    if (ndotl <= 0.0) {
        discard;
    }
    float atten = 1.0;
    if (pc.params.x > 0.0) {
        float r = clamp(dist / pc.params.x, 0.0, 1.0);
        atten = (1.0 - r * r) * (1.0 - r * r);
    }
    if (pc.spot.w > -1.5) {
        float c = dot(-l, normalize(pc.spot.xyz));
        atten *= smoothstep(pc.spot.w, mix(pc.spot.w, 1.0, 0.15), c);
    }
    vec3 v = normalize(-pos.xyz);
    vec3 h = normalize(l + v);
    float spec = pow(max(dot(n, h), 0.0), 48.0) * 0.3;
    vec3 light = pc.color.rgb * atten;
#ifdef TRANSMIT
    vec3 t = texelFetch(sampler2D(t_transmit, s_nearest), px, 0).rgb;
    light *= pc.params.y > 0.5 ? exp(t) : t;
#endif
    out_color = vec4((albedo * ndotl + vec3(spec)) * light, 0.0);
}
