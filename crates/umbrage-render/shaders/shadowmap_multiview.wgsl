// Shadow-map baseline, a point light's six cube faces as six views of one draw (`--cube
// multiview`): the shadow casters' depth (eye-relative positions) into layer `view_index` of
// the map, with that face's view-projection from the face table the lookup reads too. Per-face
// culling: a caster drawn for the views in its push-constant mask is placed outside the clip
// volume (a degenerate point beyond x = w) in every other view, so no fragment reaches them —
// the same maps as the atlas path's one draw per face it meets.

struct Face {
    // Eye-relative world -> this face's clip space.
    view_proj: mat4x4<f32>,
    // Tile in its layer: x0, y0, width, height (texels; unused here).
    tile: vec4<f32>,
    // x: layer, y: compare bias, z: normal offset (unused here).
    params: vec4<f32>,
}

struct Push {
    // Bit i: the caster's bounding sphere meets face i's frustum.
    views: u32,
}

var<immediate> pc: Push;

@group(0) @binding(0) var<storage, read> faces: array<Face, 6>;

@vertex
fn main(@location(0) position: vec3<f32>, @builtin(view_index) view: u32) -> @builtin(position) vec4<f32> {
    if ((pc.views >> view) & 1u) == 0u {
        return vec4<f32>(2.0, 2.0, 0.5, 1.0);
    }
    return faces[view].view_proj * vec4<f32>(position, 1.0);
}
