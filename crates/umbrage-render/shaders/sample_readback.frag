#version 450
// The readback of one sample of a multisampled frame (a multisampled image cannot be copied
// to a buffer): a full-screen pass copies sample `pc.sample` of the position or normal target
// (or, in the STENCIL variant, of the stencil) into a single-sample image that is copied out.
// @variant STENCIL STENCIL
layout(push_constant) uniform Push {
    int sample_index;
} pc;
layout(set = 0, binding = 1) uniform sampler s_nearest;
#ifdef STENCIL
layout(set = 0, binding = 0) uniform utexture2DMS t_source;
layout(location = 0) out uvec4 out_value;
void main() {
    out_value = texelFetch(usampler2DMS(t_source, s_nearest), ivec2(gl_FragCoord.xy), pc.sample_index);
}
#else
layout(set = 0, binding = 0) uniform texture2DMS t_source;
layout(location = 0) out vec4 out_value;
void main() {
    out_value = texelFetch(sampler2DMS(t_source, s_nearest), ivec2(gl_FragCoord.xy), pc.sample_index);
}
#endif
