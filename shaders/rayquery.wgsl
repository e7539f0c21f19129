// Ray-query shadow determination (`--method rayquery`): one shadow ray per pixel towards the
// light, drawn as a full-screen triangle inside the light's scissor. A fragment whose ray hits
// a caster survives and the pipeline's stencil op writes 1 (the same "non-zero = shadowed" the
// volumes leave); a lit, back-facing or empty pixel is discarded and keeps the cleared 0.
//
// Space: world, relative to the eye (the G-buffer's positions and the instances' transforms).
//
// Self-shadowing without a fixed tMin epsilon:
// - Closed, consistently oriented casters (instance mask CLOSED) are traced with back faces
//   culled, their fronts counter-clockwise from outside: a ray from a point on such a surface
//   that faces the light leaves through a back face (never counted), so the receiver's own
//   surface cannot shadow it whatever the rounding of its position. A real occluder is always
//   entered through a front face first.
// - Open, two-sided and non-manifold casters (mask OPEN, face culling disabled per instance)
//   can be hit from either side, so the ray starts `offset` off the surface along the normal on
//   the light's side and stops `offset` short of a point light: `offset` is the CPU
//   reference's own surface offset (2e-5 of the scene's size), checked on the CPU to be far
//   above the error bound of the G-buffer's f32 position (see render/raytrace.rs).

enable wgpu_ray_query;

struct Push {
    // (position, 1) of a point or spot light, or (unit direction towards the light, 0).
    light: vec4<f32>,
    // x: the surface offset (world units).
    params: vec4<f32>,
}

var<immediate> pc: Push;

@group(0) @binding(0) var scene: acceleration_structure;
@group(0) @binding(1) var positions: texture_2d<f32>;
@group(0) @binding(2) var normals: texture_2d<f32>;

const CLOSED: u32 = 1u;
const OPEN: u32 = 2u;

fn occluded(origin: vec3<f32>, dir: vec3<f32>, t_max: f32, mask: u32, flags: u32) -> bool {
    var rq: ray_query;
    rayQueryInitialize(&rq, scene, RayDesc(flags | RAY_FLAG_TERMINATE_ON_FIRST_HIT | RAY_FLAG_FORCE_OPAQUE, mask, 0.0, t_max, origin, dir));
    rayQueryProceed(&rq);
    return rayQueryGetCommittedIntersection(&rq).kind != RAY_QUERY_INTERSECTION_NONE;
}

@fragment
fn main(@builtin(position) coord: vec4<f32>) {
    let px = vec2<i32>(floor(coord.xy));
    let p4 = textureLoad(positions, px, 0);
    if p4.w == 0.0 {
        discard;
    }
    let p = p4.xyz;
    let n = textureLoad(normals, px, 0).xyz;
    var dir: vec3<f32>;
    var dist: f32;
    if pc.light.w == 0.0 {
        dir = pc.light.xyz;
        dist = 1.0e30;
    } else {
        let d = pc.light.xyz - p;
        dist = length(d);
        dir = d / dist;
    }
    // Facing away (or exactly edge-on): the lighting pass leaves it unlit whatever the stencil.
    if !(dot(n, dir) > 0.0) {
        discard;
    }
    let offset = pc.params.x;
    let hit = occluded(p, dir, dist, CLOSED, RAY_FLAG_CULL_BACK_FACING)
        || occluded(p + n * offset, dir, dist - offset, OPEN, RAY_FLAG_NONE);
    if !hit {
        discard;
    }
}
