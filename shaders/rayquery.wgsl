// Ray-query shadow determination (`--method rayquery`): one shadow ray per pixel towards the
// light, drawn as a full-screen triangle inside the light's scissor. `main`: a fragment whose
// ray hits a caster survives and the pipeline's stencil op writes 1 (the same "non-zero =
// shadowed" the volumes leave); a lit, back-facing or empty pixel is discarded and keeps the
// cleared 0. `batch`: the same rays for up to 32 lights in one pass, as a bit mask per pixel
// that `rayquery_mask.wgsl` turns into each light's stencil.
//
// Space: world, relative to the eye (the G-buffer's positions and the instances' transforms).
//
// The rule is the CPU reference's, to the letter: a shadow ray from P + N * offset (N the
// surface normal on its visible side, facing the light) towards the light, stopping offset
// short of a point light; every caster triangle two-sided. `offset` is the reference's own
// surface offset (2e-5 of the scene's size), raised on the CPU to at least 2^-16 of the
// scene's largest eye-relative coordinate (128 f32 ulps), far above the few ulps the
// G-buffer's interpolated position can be off by: the receiver's own triangle lies behind the
// ray's origin and cannot shadow it, whatever the rounding. No culling: a receiver inside a
// closed caster (the eye inside it) is shadowed by the wall its ray leaves through.

enable wgpu_ray_query;

struct Push {
    // (position, 1) of a point or spot light, or (unit direction towards the light, 0)
    // (`main`).
    light: vec4<f32>,
    // x: the surface offset (world units); `batch`: y the first light, z how many.
    params: vec4<f32>,
}

var<immediate> pc: Push;

@group(0) @binding(0) var scene: acceleration_structure;
@group(0) @binding(1) var positions: texture_2d<f32>;
@group(0) @binding(2) var normals: texture_2d<f32>;
// Analytic sphere casters: (centre relative to their instance's origin, radius), indexed by
// the AABB primitive. The instance is a translation, so object-space directions are world's.
@group(0) @binding(3) var<storage, read> balls: array<vec4<f32>>;
// The frame's lights for `batch`: eye-relative as `Push::light`, and their scissors.
struct BatchLight {
    light: vec4<f32>,
    scissor: vec4<f32>,
}
@group(0) @binding(4) var<storage, read> batch_lights: array<BatchLight>;

// The entry distance of the ray `o + t d` (unit d) into ball `b`, clamped to 0 when `o` is
// inside, or -1 when it misses [0, t_max].
fn ball_hit(o: vec3<f32>, d: vec3<f32>, b: vec4<f32>, t_max: f32) -> f32 {
    let oc = o - b.xyz;
    let half_b = dot(oc, d);
    let c = dot(oc, oc) - b.w * b.w;
    let h = half_b * half_b - c;
    if h < 0.0 {
        return -1.0;
    }
    let s = sqrt(h);
    let t0 = -half_b - s;
    let t1 = -half_b + s;
    if t1 < 0.0 || t0 > t_max {
        return -1.0;
    }
    return max(t0, 0.0);
}

fn occluded(origin: vec3<f32>, dir: vec3<f32>, t_max: f32) -> bool {
    var rq: ray_query;
    let flags = RAY_FLAG_TERMINATE_ON_FIRST_HIT | RAY_FLAG_FORCE_OPAQUE;
    rayQueryInitialize(&rq, scene, RayDesc(flags, 0xffu, 0.0, t_max, origin, dir));
    // Triangles are opaque and commit themselves; a sphere's box is a candidate that commits
    // only when the exact ray-sphere test hits.
    while rayQueryProceed(&rq) {
        let c = rayQueryGetCandidateIntersection(&rq);
        if c.kind == RAY_QUERY_INTERSECTION_AABB {
            let o = c.world_to_object * vec4<f32>(origin, 1.0);
            let t = ball_hit(o, dir, balls[c.primitive_index], t_max);
            if t >= 0.0 {
                rayQueryGenerateIntersection(&rq, t);
            }
        }
    }
    return rayQueryGetCommittedIntersection(&rq).kind != RAY_QUERY_INTERSECTION_NONE;
}

// Whether the ray from the pixel's visible point towards `light` (eye-relative (position, 1)
// or (direction towards the light, 0)) is blocked: false for background, back-facing and lit
// pixels.
fn shadowed(px: vec2<i32>, light: vec4<f32>, offset: f32) -> bool {
    let p4 = textureLoad(positions, px, 0);
    if p4.w == 0.0 {
        return false;
    }
    let p = p4.xyz;
    let n = textureLoad(normals, px, 0).xyz;
    // The reference's facing test, from the surface point itself.
    let to_light = select(light.xyz - p, light.xyz, light.w == 0.0);
    if !(dot(n, to_light) > 0.0) {
        return false;
    }
    let origin = p + n * offset;
    var dir: vec3<f32>;
    var t_max: f32;
    if light.w == 0.0 {
        dir = light.xyz;
        t_max = 1.0e30;
    } else {
        let d = light.xyz - origin;
        let dist = length(d);
        dir = d / dist;
        t_max = dist - offset;
    }
    return occluded(origin, dir, t_max);
}

// One light: the fragment survives (and the stencil op writes 1) where its ray is blocked.
@fragment
fn main(@builtin(position) coord: vec4<f32>) {
    if !shadowed(vec2<i32>(floor(coord.xy)), pc.light, pc.params.x) {
        discard;
    }
}

// Up to 32 lights of the frame in one pass (`params.y` the first, `params.z` how many): bit
// `i` of the mask is set where light `first + i`'s ray is blocked, inside that light's
// scissor only (`batch_lights[..].scissor`: x0, y0, x1, y1 in pixels).
@fragment
fn batch(@builtin(position) coord: vec4<f32>) -> @location(0) u32 {
    let px = vec2<i32>(floor(coord.xy));
    let first = u32(pc.params.y);
    let count = u32(pc.params.z);
    var mask = 0u;
    for (var i = 0u; i < count; i++) {
        let l = batch_lights[first + i];
        let inside = coord.x >= l.scissor.x && coord.y >= l.scissor.y && coord.x < l.scissor.z && coord.y < l.scissor.w;
        if inside && shadowed(px, l.light, pc.params.x) {
            mask |= 1u << i;
        }
    }
    return mask;
}
