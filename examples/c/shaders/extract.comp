#version 450
// Reads every sample of the depth-stencil image (depth, stencil) and of the plane target into
// the read-back buffer: mode 0 writes the geometry (5 words a pixel: depth, nx, ny, nz, d),
// mode 1 the stencil (1 word a pixel), of sample `sample_index`, at word `offset`.
layout(local_size_x = 8, local_size_y = 8) in;
#ifdef MS
layout(binding = 0) uniform sampler2DMS depth_tex;
layout(binding = 1) uniform usampler2DMS stencil_tex;
layout(binding = 2) uniform sampler2DMS plane_tex;
#define FETCH(t, p) texelFetch(t, p, int(pc.sample_index))
#else
layout(binding = 0) uniform sampler2D depth_tex;
layout(binding = 1) uniform usampler2D stencil_tex;
layout(binding = 2) uniform sampler2D plane_tex;
#define FETCH(t, p) texelFetch(t, p, 0)
#endif
layout(std430, binding = 3) buffer Out { uint words[]; } outb;
layout(push_constant) uniform Push { uint width; uint height; uint sample_index; uint mode; uint offset; } pc;
void main() {
    uvec2 p = gl_GlobalInvocationID.xy;
    if (p.x >= pc.width || p.y >= pc.height) return;
    uint i = p.y * pc.width + p.x;
    ivec2 q = ivec2(p);
    if (pc.mode == 0u) {
        vec4 pl = FETCH(plane_tex, q);
        uint o = pc.offset + 5u * i;
        outb.words[o] = floatBitsToUint(FETCH(depth_tex, q).r);
        outb.words[o + 1u] = floatBitsToUint(pl.x);
        outb.words[o + 2u] = floatBitsToUint(pl.y);
        outb.words[o + 3u] = floatBitsToUint(pl.z);
        outb.words[o + 4u] = floatBitsToUint(pl.w);
    } else {
        outb.words[pc.offset + i] = FETCH(stencil_tex, q).r;
    }
}
