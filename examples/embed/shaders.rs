//! The host's own shaders, in WGSL, compiled to SPIR-V by naga when the host starts (an engine
//! has its own shaders; umbrage's internal ones are not part of its API).

use naga::{back::spv, valid};

/// The depth pre-pass and the lighting pass. The vertex stage is shared, so the lighting pass's
/// depth EQUAL sees exactly the pre-pass's depths at every sample. Push block:
/// `mvp` (clip from object) and `rel` (eye-relative world position from object).
///
/// `fs_normal` (pre-pass) writes the visible side's unit face normal, from the screen-space
/// derivatives of the eye-relative position: every sample a triangle covers gets the
/// triangle's plane normal, turned towards the eye; and, in w, the plane's offset `n · rel`
/// (the readback puts the position unprojected from the depth back on the triangle's plane:
/// a rasteriser that snaps vertices coarsely, like SwiftShader's 1/16 pixel, leaves depths a
/// little off the true surface, while the interpolated position stays on it). `fs_lit`
/// (lighting pass) writes 1.
pub const SCENE_WGSL: &str = r#"
struct Push { mvp: mat4x4<f32>, rel: mat4x4<f32> }
var<immediate> pc: Push;

struct VsOut {
    @invariant @builtin(position) clip: vec4<f32>,
    @location(0) rel: vec3<f32>,
}

@vertex
fn vs(@location(0) pos: vec4<f32>) -> VsOut {
    var o: VsOut;
    o.clip = pc.mvp * pos;
    o.rel = (pc.rel * pos).xyz;
    return o;
}

@fragment
fn fs_normal(v: VsOut) -> @location(0) vec4<f32> {
    var n = normalize(cross(dpdx(v.rel), dpdy(v.rel)));
    if dot(n, v.rel) > 0.0 {
        n = -n;
    }
    return vec4<f32>(n, dot(n, v.rel));
}

@fragment
fn fs_lit(v: VsOut) -> @location(0) vec4<f32> {
    return vec4<f32>(1.0);
}
"#;

/// The readback of one sample of every pixel into a storage buffer (images with more than one
/// sample cannot be copied to a buffer): when `geometry` is set, its depth, normal and plane
/// offset as five words at `geometry_at + 5 i` (depth's bits, then the normal's four
/// components); always, the light's stencil
/// count and lit bit (`stencil | lit << 8`) at `packed_at + i`. `MS` is replaced by
/// `multisampled_2d` or `2d` (textureLoad's third argument is then the sample, or the level 0).
pub const EXTRACT_WGSL: &str = r#"
@group(0) @binding(0) var depth_t: texture_depth_MS;
@group(0) @binding(1) var stencil_t: texture_MS<u32>;
@group(0) @binding(2) var lit_t: texture_MS<f32>;
@group(0) @binding(3) var normal_t: texture_MS<f32>;
@group(0) @binding(4) var<storage, read_write> words: array<u32>;

struct Push { sample: u32, width: u32, height: u32, geometry: u32, geometry_at: u32, packed_at: u32 }
var<immediate> pc: Push;

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= pc.width || id.y >= pc.height {
        return;
    }
    let p = vec2<i32>(id.xy);
    let s = i32(pc.sample);
    let i = id.y * pc.width + id.x;
    if pc.geometry != 0u {
        let n = textureLoad(normal_t, p, s);
        let g = pc.geometry_at + 5u * i;
        words[g] = bitcast<u32>(textureLoad(depth_t, p, s));
        words[g + 1u] = bitcast<u32>(n.x);
        words[g + 2u] = bitcast<u32>(n.y);
        words[g + 3u] = bitcast<u32>(n.z);
        words[g + 4u] = bitcast<u32>(n.w);
    }
    let lit = select(0u, 256u, textureLoad(lit_t, p, s).x > 0.5);
    words[pc.packed_at + i] = (textureLoad(stencil_t, p, s).x & 255u) | lit;
}
"#;

/// WGSL to SPIR-V words for Vulkan (no y flip: the projections are Vulkan's already).
pub fn compile(source: &str) -> Result<Vec<u32>, String> {
    let module = naga::front::wgsl::parse_str(source).map_err(|e| e.emit_to_string(source))?;
    let info = valid::Validator::new(valid::ValidationFlags::all(), valid::Capabilities::IMMEDIATES)
        .validate(&module)
        .map_err(|e| e.emit_to_string(source))?;
    let mut options = spv::Options::default();
    options.flags.remove(spv::WriterFlags::ADJUST_COORDINATE_SPACE);
    spv::write_vec(&module, &info, &options, None).map_err(|e| format!("SPIR-V: {e}"))
}

/// [`EXTRACT_WGSL`] for images of `samples` samples.
pub fn extract_source(samples: u32) -> String {
    EXTRACT_WGSL.replace("_MS", if samples > 1 { "_multisampled_2d" } else { "_2d" })
}
