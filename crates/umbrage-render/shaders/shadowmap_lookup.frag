#version 450
// Shadow-map baseline, lookup: for each visible surface point (G-buffer), the fraction of
// 3x3 percentage-closer-filtering taps that see an occluder nearer the light, written into
// the float counter target (0 = lit). One full-screen pass per light: a point light's six
// faces sit in one atlas (tiles of layer 0) or in six layers (one per face, `--cube
// multiview`), and each point picks its face here (the face matrices, tiles and layers come
// from a storage buffer the pass updates per light). The depth comparison is the sampler's (a
// hardware compare sampler, nearest filtering: the same nine taps as a shader compare).
layout(set = 0, binding = 0) uniform texture2D t_albedo;
layout(set = 0, binding = 1) uniform texture2D t_normal;
layout(set = 0, binding = 2) uniform texture2D t_position;
layout(set = 0, binding = 3) uniform sampler s_nearest;
layout(set = 0, binding = 4) uniform texture2D t_count;
layout(set = 0, binding = 5) uniform texture2D t_transmit;
layout(set = 0, binding = 6) uniform texture2DArray t_map;
layout(set = 0, binding = 7) uniform samplerShadow s_compare;

struct Face {
    mat4 view_proj;  // eye-relative world -> this face's clip space
    vec4 tile;       // tile in its layer: x0, y0, width, height (texels)
    vec4 params;     // x: layer, y: compare bias, z: normal offset
};

layout(std430, set = 0, binding = 8) readonly buffer Faces {
    Face faces[6];
};

layout(push_constant) uniform Push {
    vec4 light;   // xyz eye-relative light position (w = 1) or towards-light direction (w = 0)
    vec4 params;  // x: faces (1 or 6), yz: 1 / layer size (texels)
} pc;

layout(location = 0) out vec4 out_shadow;

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    vec4 pos = texelFetch(sampler2D(t_position, s_nearest), px, 0);
    if (pos.w == 0.0) {
        discard;
    }
    vec3 n = normalize(texelFetch(sampler2D(t_normal, s_nearest), px, 0).xyz);
    int face = 0;
    if (pc.params.x > 1.0) {
        // Cube face of the direction from the light: 0 +x, 1 -x, 2 +y, 3 -y, 4 +z, 5 -z.
        vec3 d = pos.xyz - pc.light.xyz;
        vec3 a = abs(d);
        if (a.x >= a.y && a.x >= a.z) {
            face = d.x > 0.0 ? 0 : 1;
        } else if (a.y >= a.z) {
            face = d.y > 0.0 ? 2 : 3;
        } else {
            face = d.z > 0.0 ? 4 : 5;
        }
    }
    vec4 tile = faces[face].tile;
    vec4 q = faces[face].view_proj * vec4(pos.xyz + n * faces[face].params.z, 1.0);
    if (q.w <= 0.0) {
        out_shadow = vec4(0.0);
        return;
    }
    vec3 ndc = q.xyz / q.w;
    // Receivers beyond the map's far plane compare as if on it: any caster in front shadows them.
    ndc.z = min(ndc.z, 1.0);
    vec2 uv = ndc.xy * 0.5 + 0.5;
    if (uv.x < 0.0 || uv.x > 1.0 || uv.y < 0.0 || uv.y > 1.0) {
        out_shadow = vec4(0.0);
        return;
    }
    vec2 texel = tile.xy + uv * tile.zw;
    float reference = ndc.z - faces[face].params.y;
    float layer = faces[face].params.x;
    float lit = 0.0;
    for (int j = -1; j <= 1; j++) {
        for (int i = -1; i <= 1; i++) {
            // The tap's texel, kept inside this face's tile, sampled at its centre.
            vec2 t = floor(clamp(texel + vec2(float(i), float(j)), tile.xy, tile.xy + tile.zw - 1.0)) + 0.5;
            // (GLSL has no textureLod for array shadow samplers: zero gradients are level 0.)
            lit += textureGrad(sampler2DArrayShadow(t_map, s_compare), vec4(t * pc.params.yz, layer, reference), vec2(0.0), vec2(0.0));
        }
    }
    out_shadow = vec4(1.0 - lit / 9.0, 0.0, 0.0, 0.0);
}
