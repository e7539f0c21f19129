// The suite's compute streaming-read limit (`bench::compute_read`): the GPU silhouettes'
// `facing` stage without its job table or exact fallback. One invocation a plane: read 16
// bytes, test the plane against the light, set the item's bit when it faces it (the bits were
// cleared by a fill). A plain compute read of the bytes the silhouette pass reads per
// triangle, at the same workgroup size and in the same dispatch shape.

struct Push {
    light: vec4<f32>,
    n: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}

@group(0) @binding(0) var<storage, read> planes: array<vec4<f32>>;
@group(0) @binding(1) var<storage, read_write> bits: array<atomic<u32>>;

var<immediate> pc: Push;

@compute @workgroup_size(256)
fn stream(@builtin(workgroup_id) wg: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>,
        @builtin(local_invocation_index) lid: u32) {
    let i = (wg.x + wg.y * nwg.x) * 256u + lid;
    if (i < pc.n) {
        if (dot(planes[i], pc.light) > 0.0) {
            atomicOr(&bits[i >> 5u], 1u << (i & 31u));
        }
    }
}
