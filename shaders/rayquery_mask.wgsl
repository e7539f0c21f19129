// Ray query, batched lights: light `bit`'s stencil from the mask `rayquery.wgsl`'s `batch`
// wrote. Drawn as a full-screen triangle inside the light's scissor over a stencil cleared to
// 0: the fragment survives (and the stencil op writes 1) where the light's bit is set.

struct Push {
    bit: u32,
}

var<immediate> pc: Push;

@group(0) @binding(0) var mask: texture_2d<u32>;

@fragment
fn main(@builtin(position) coord: vec4<f32>) {
    let m = textureLoad(mask, vec2<i32>(floor(coord.xy)), 0).x;
    if ((m >> pc.bit) & 1u) == 0u {
        discard;
    }
}
