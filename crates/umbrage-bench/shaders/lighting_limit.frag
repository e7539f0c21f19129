#version 450
// The lighting limit (bench::pass_limits): what illuminate.frag does per pixel without its
// shading math. The same three G-buffer reads (texelFetch of position, normal and albedo,
// the same bindings and formats), the same background test (position.w == 0: discard), and one
// colour out, added into the accumulation target by the same additive blend. The colour
// depends on every read (none can be dropped by the compiler) through one dot product.
layout(set = 0, binding = 0) uniform texture2D t_albedo;
layout(set = 0, binding = 1) uniform texture2D t_normal;
layout(set = 0, binding = 2) uniform texture2D t_position;
layout(set = 0, binding = 3) uniform sampler s_nearest;

layout(location = 0) out vec4 out_color;

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    vec4 pos = texelFetch(sampler2D(t_position, s_nearest), px, 0);
    if (pos.w == 0.0) {
        discard;
    }
    vec4 normal = texelFetch(sampler2D(t_normal, s_nearest), px, 0);
    vec4 albedo = texelFetch(sampler2D(t_albedo, s_nearest), px, 0);
    out_color = vec4(albedo.rgb * max(dot(normal.xyz, -pos.xyz), 0.0) * 0.001, 0.0);
}
