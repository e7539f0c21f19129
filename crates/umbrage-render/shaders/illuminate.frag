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
    vec4 params;      // x = radius (0: unbounded), y = 1 when the intensity map is in log space,
                      // w = shading: 0 smooth, 1 naive smooth (no bound), 2 flat
} pc;

layout(location = 0) out vec4 out_color;

// illuminate.frag's inverse of gbuffer.frag's pack_normal.
vec3 unpack_normal(float f) {
    float qx = floor(f / 4096.0);
    vec2 e = vec2(qx, f - qx * 4096.0) / 4095.0 * 2.0 - 1.0;
    vec3 n = vec3(e, 1.0 - abs(e.x) - abs(e.y));
    float t = max(-n.z, 0.0);
    n.x += n.x >= 0.0 ? -t : t;
    n.y += n.y >= 0.0 ? -t : t;
    return normalize(n);
}

// The smooth n.L with the terminator bound t (geom/shading.rs): 0 up to t (every face turned
// away from the light is there), then a cubic rising with zero slope from t that meets n.L
// itself, slope 1, at min(3 t, 1). Continuous with its slope, so the fade shows no crease, and
// plain smooth shading wherever n.L >= 3 t (on a fine mesh, almost everywhere).
float terminator(float x, float t) {
    if (x <= t) {
        return 0.0;
    }
    float x1 = min(3.0 * t, 1.0);
    if (x >= x1) {
        return x;
    }
    float u = (x - t) / (x1 - t);
    return (3.0 - 2.0 * u) * u * u * x1 + (u - 1.0) * u * u * (x1 - t);
}

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
    vec4 normal = FETCH(t_normal, px);
    vec4 albedo = FETCH(t_albedo, px);
    vec3 to_light = pc.light_pos.xyz - pos.xyz * pc.light_pos.w;
    float dist = length(to_light);
    // Nothing is lit at or beyond a bounded light's radius (the attenuation below is 0 there):
    // those pixels skip the shading.
    if (pc.params.x > 0.0 && dist >= pc.params.x) {
        discard;
    }
    vec3 l = to_light / max(dist, 1e-30);
    // Facing by the face normal: what the shadow volumes and the reference decide by (its sign
    // needs no normalisation).
    if (dot(normal.xyz, l) <= 0.0) {
        discard;
    }
    // Shading by the smooth normal, shifted by the terminator bound: 0 on every face that looks
    // away from the light, so it reaches 0 before the volumes' polygonal terminator (no step
    // along the triangle edges there; see geom/shading.rs).
    vec3 n = pc.params.w > 1.5 ? normalize(normal.xyz) : unpack_normal(normal.w);
    float bound = pc.params.w > 0.5 ? 0.0 : albedo.a;
    float diffuse = terminator(dot(n, l), bound);
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
    // x^48 by squaring ((x^3)^16: six products), not pow's exp2(48 log2 x).
    float x = max(dot(n, h), 0.0);
    float x3 = x * x * x;
    float x6 = x3 * x3;
    float x12 = x6 * x6;
    float x24 = x12 * x12;
    float spec = x24 * x24 * 0.3 * clamp(diffuse * 8.0, 0.0, 1.0);
    vec3 light = pc.color.rgb * atten;
#ifdef TRANSMIT
    vec3 t = texelFetch(sampler2D(t_transmit, s_nearest), px, 0).rgb;
    light *= pc.params.y > 0.5 ? exp(t) : t;
#endif
    out_color = vec4((albedo.rgb * diffuse + vec3(spec)) * light, 0.0);
}
