#version 450
// Final pass: exposure tone map of the float accumulation into the sRGB output
// (the sRGB encode is done by the target format).
layout(set = 0, binding = 0) uniform texture2D t_accum;
layout(set = 0, binding = 1) uniform sampler s_nearest;

layout(location = 0) out vec4 out_color;

void main() {
    vec3 c = texelFetch(sampler2D(t_accum, s_nearest), ivec2(gl_FragCoord.xy), 0).rgb;
    out_color = vec4(vec3(1.0) - exp(-c * 1.1), 1.0);
}
