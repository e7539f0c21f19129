#version 450
// Final pass: exposure tone map of the float accumulation into the sRGB output
// (the sRGB encode is done by the target format).
// @variant MS MSAA
// The MS variant resolves a multisampled accumulation target: the mean of its samples, each
// tone-mapped first (so an edge pixel blends the two sides' displayed colours).
#ifdef MSAA
layout(set = 0, binding = 0) uniform texture2DMS t_accum;
layout(push_constant) uniform Push {
    int samples;
} pc;
#else
layout(set = 0, binding = 0) uniform texture2D t_accum;
#endif
layout(set = 0, binding = 1) uniform sampler s_nearest;

layout(location = 0) out vec4 out_color;

vec3 tonemap(vec3 c) {
    return vec3(1.0) - exp(-c * 1.1);
}

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
#ifdef MSAA
    vec3 sum = vec3(0.0);
    for (int i = 0; i < pc.samples; i++) {
        sum += tonemap(texelFetch(sampler2DMS(t_accum, s_nearest), px, i).rgb);
    }
    out_color = vec4(sum / float(pc.samples), 1.0);
#else
    out_color = vec4(tonemap(texelFetch(sampler2D(t_accum, s_nearest), px, 0).rgb), 1.0);
#endif
}
