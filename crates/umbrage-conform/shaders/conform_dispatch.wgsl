// The conformance suite's compute checks (`commands.dispatch`, `commands.dispatch_indirect`;
// src/conform/checks/commands/dispatch.rs): what `--method compute` relies on of vkCmdDispatch
// and vkCmdDispatchIndirect, recorded into one storage buffer of u32 words with atomics, for
// the CPU model to compare word for word.
//
// @spirv 1.0 below: written as SPIR-V 1.0, so Vulkan 1.0 devices with
// VK_KHR_storage_buffer_storage_class run it too.
// @spirv 1.0

struct Push {
    // `count`: invocations counted (ids >= n are launched extras and skip, as the silhouette
    // stages skip a 2D dispatch's last row).
    n: u32,
    // Word offset of the region the dispatch writes (its header first).
    base: u32,
    // `grow`: word offset of the VkDispatchIndirectCommand it grows.
    args: u32,
    // `count`: word offsets, relative to `base`, of the per-invocation counters and of the
    // invocation bitmap (the per-group words start at HEADER).
    counts: u32,
    bits: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}

@group(0) @binding(0) var<storage, read_write> words: array<atomic<u32>>;

var<immediate> pc: Push;

// A region's header (words from `base`): invocations counted, largest id + 1, the
// num_workgroups builtin (x, y, z, each the largest any invocation saw), workgroups run
// (counted by local invocation 0), invocations run.
const H_TOTAL: u32 = 0u;
const H_MAX_ID: u32 = 1u;
const H_NWG: u32 = 2u;
const H_GROUPS: u32 = 5u;
const H_INVOCATIONS: u32 = 6u;
const HEADER: u32 = 8u;

// The linear workgroup index of a 3D dispatch (x fastest).
fn linear_group(wg: vec3<u32>, nwg: vec3<u32>) -> u32 {
    return wg.x + nwg.x * (wg.y + nwg.y * wg.z);
}

// What every invocation records of the dispatch's shape.
fn record_shape(nwg: vec3<u32>, lid: u32) {
    atomicMax(&words[pc.base + H_NWG], nwg.x);
    atomicMax(&words[pc.base + H_NWG + 1u], nwg.y);
    atomicMax(&words[pc.base + H_NWG + 2u], nwg.z);
    atomicAdd(&words[pc.base + H_INVOCATIONS], 1u);
    if lid == 0u {
        atomicAdd(&words[pc.base + H_GROUPS], 1u);
    }
}

// A workgroup id packed into one word: x in bits 0..16, y in 16..24, z in 24..32.
fn pack_id(wg: vec3<u32>) -> u32 {
    return wg.x | (wg.y << 16u) | (wg.z << 24u);
}

// 2D dispatch (x = min(groups, 65535), y = ceil(groups / 65535)): invocation id
// linear_group * 4 + local index. Per launched group g: word HEADER + 2g gets (packed id + 1)
// from each of its 4 invocations, word HEADER + 2g + 1 the bit of each local index. Per id < n:
// its counter incremented and its bit set in the bitmap (32 ids a word: words shared across
// workgroups).
@compute @workgroup_size(4)
fn count(@builtin(workgroup_id) wg: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>,
         @builtin(local_invocation_index) lid: u32) {
    record_shape(nwg, lid);
    let g = linear_group(wg, nwg);
    atomicAdd(&words[pc.base + HEADER + 2u * g], pack_id(wg) + 1u);
    atomicOr(&words[pc.base + HEADER + 2u * g + 1u], 1u << lid);
    let id = g * 4u + lid;
    if id >= pc.n {
        return;
    }
    atomicAdd(&words[pc.base + H_TOTAL], 1u);
    atomicMax(&words[pc.base + H_MAX_ID], id + 1u);
    atomicAdd(&words[pc.base + pc.counts + id], 1u);
    atomicOr(&words[pc.base + pc.bits + (id >> 5u)], 1u << (id & 31u));
}

// Grows the indirect command at `args` as the silhouette stages grow their lists' dispatch
// sizes: invocation i raises x to 7 + (5 i mod 11); invocation 3 raises y to 2; z is left as
// the host wrote it.
@compute @workgroup_size(4)
fn grow(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    atomicMax(&words[pc.args], 7u + (5u * i) % 11u);
    if i == 3u {
        atomicMax(&words[pc.args + 1u], 2u);
    }
}

// Each group of a (3D, indirect) dispatch adds (packed id + 1) to its linear group's word
// HEADER + g from each of its 2 invocations.
@compute @workgroup_size(2)
fn mark(@builtin(workgroup_id) wg: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>,
        @builtin(local_invocation_index) lid: u32) {
    record_shape(nwg, lid);
    atomicAdd(&words[pc.base + HEADER + linear_group(wg, nwg)], pack_id(wg) + 1u);
}
