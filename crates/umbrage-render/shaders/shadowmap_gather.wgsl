// Shadow-map baseline, lookup with gathers (`Pcf::Gather`): `shadowmap_lookup.frag`'s result,
// bit for bit, from fewer fetch instructions. For each visible surface point (G-buffer), the
// fraction of 3x3 percentage-closer-filtering taps that see an occluder nearer the light,
// written into the float counter target (0 = lit); a point light's six faces sit in one atlas
// (tiles of layer 0) or in six layers (`--cube multiview`), and each point picks its face (the
// face matrices, tiles and layers come from a storage buffer the pass updates per light). The depth comparison is the sampler's (a hardware compare sampler).
//
// The nine taps are read with four gathers of the compare sampler (WGSL, because naga's GLSL
// front end has no textureGather): each returns the comparisons of a 2x2 block, so four cover
// the 4x4 texels around the point, of which the taps are 3x3. The same texels, reference and
// compare op as nine single taps, so the result is bit for bit theirs. Near a tile's edge,
// where the 4x4 block would reach into a neighbouring tile, the nine taps are read one by one,
// clamped to the tile.

struct Face {
    // Eye-relative world -> this face's clip space.
    view_proj: mat4x4<f32>,
    // Tile in its layer: x0, y0, width, height (texels).
    tile: vec4<f32>,
    // x: layer, y: compare bias, z: normal offset.
    params: vec4<f32>,
}

struct Push {
    // xyz eye-relative light position (w = 1) or towards-light direction (w = 0).
    light: vec4<f32>,
    // x: faces (1 or 6), yz: 1 / layer size (texels).
    params: vec4<f32>,
}

var<immediate> pc: Push;

@group(0) @binding(1) var t_normal: texture_2d<f32>;
@group(0) @binding(2) var t_position: texture_2d<f32>;
@group(0) @binding(6) var t_map: texture_depth_2d_array;
@group(0) @binding(7) var s_compare: sampler_comparison;
@group(0) @binding(8) var<storage, read> faces: array<Face, 6>;

// The cube face of direction `d` from the light: 0 +x, 1 -x, 2 +y, 3 -y, 4 +z, 5 -z.
fn cube_face(d: vec3<f32>) -> i32 {
    let a = abs(d);
    if a.x >= a.y && a.x >= a.z {
        return select(1, 0, d.x > 0.0);
    } else if a.y >= a.z {
        return select(3, 2, d.y > 0.0);
    }
    return select(5, 4, d.z > 0.0);
}

// Lit taps of the 3x3 around texel `c` (all inside the tile with one texel to spare).
fn gathered(c: vec2<f32>, layer: i32, reference: f32) -> f32 {
    let inv = pc.params.yz;
    // Components: x (u0, v1), y (u1, v1), z (u1, v0), w (u0, v0).
    let g00 = textureGatherCompare(t_map, s_compare, c * inv, layer, reference);
    let g10 = textureGatherCompare(t_map, s_compare, (c + vec2<f32>(2.0, 0.0)) * inv, layer, reference);
    let g01 = textureGatherCompare(t_map, s_compare, (c + vec2<f32>(0.0, 2.0)) * inv, layer, reference);
    let g11 = textureGatherCompare(t_map, s_compare, (c + vec2<f32>(2.0, 2.0)) * inv, layer, reference);
    // Column c+2 and row c+2 are outside the 3x3.
    return dot(g00, vec4<f32>(1.0)) + g10.x + g10.w + g01.z + g01.w + g11.w;
}

// Lit taps of the 3x3 around `texel`, each clamped to the tile and sampled at its centre.
fn tapped(texel: vec2<f32>, tile: vec4<f32>, layer: i32, reference: f32) -> f32 {
    var lit = 0.0;
    for (var j = -1; j <= 1; j++) {
        for (var i = -1; i <= 1; i++) {
            let t = floor(clamp(texel + vec2<f32>(f32(i), f32(j)), tile.xy, tile.xy + tile.zw - 1.0)) + 0.5;
            lit += textureSampleCompareLevel(t_map, s_compare, t * pc.params.yz, layer, reference);
        }
    }
    return lit;
}

@fragment
fn main(@builtin(position) coord: vec4<f32>) -> @location(0) vec4<f32> {
    let px = vec2<i32>(coord.xy);
    let pos = textureLoad(t_position, px, 0);
    if pos.w == 0.0 {
        discard;
    }
    let n = normalize(textureLoad(t_normal, px, 0).xyz);
    var face = 0;
    if pc.params.x > 1.0 {
        face = cube_face(pos.xyz - pc.light.xyz);
    }
    let tile = faces[face].tile;
    let q = faces[face].view_proj * vec4<f32>(pos.xyz + n * faces[face].params.z, 1.0);
    if q.w <= 0.0 {
        return vec4<f32>(0.0);
    }
    var ndc = q.xyz / q.w;
    // Receivers beyond the map's far plane compare as if on it: any caster in front shadows them.
    ndc.z = min(ndc.z, 1.0);
    let uv = ndc.xy * 0.5 + 0.5;
    if uv.x < 0.0 || uv.x > 1.0 || uv.y < 0.0 || uv.y > 1.0 {
        return vec4<f32>(0.0);
    }
    let texel = tile.xy + uv * tile.zw;
    let reference = ndc.z - faces[face].params.y;
    let layer = i32(faces[face].params.x);
    // The taps are texels c-1 .. c+1; the gathers read c-1 .. c+2.
    let c = floor(texel);
    var lit: f32;
    if all(c - 1.0 >= tile.xy) && all(c + 2.0 <= tile.xy + tile.zw - 1.0) {
        lit = gathered(c, layer, reference);
    } else {
        lit = tapped(texel, tile, layer, reference);
    }
    return vec4<f32>(1.0 - lit / 9.0, 0.0, 0.0, 0.0);
}
