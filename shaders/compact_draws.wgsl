// The compute path's merged volume draws (`--method compute`, src/pass/compute/draws.rs):
// after the silhouette stages (shaders/silhouette.wgsl) have written every chunk record's two
// VkDrawIndexedIndirectCommands (volume, light cap) and their index counts, this stage copies
// each non-empty command into the list of its light and pipeline (z-pass sides and caps,
// z-fail sides and caps, z-fail light caps). A list is a count word (padded to 16 bytes) then
// its commands, 20 bytes apart: one `vkCmdDrawIndexedIndirectCount` (the count read from the
// list) or one multi-draw `vkCmdDrawIndexedIndirect` (the whole list, its unused tail cleared
// to empty commands by a fill) draws a light's volumes of one pipeline, whatever the number of
// casters. The command is copied whole: its firstIndex (the chunk's region), vertexOffset (the
// chunk's first vertex in the pass-wide vertex arena) and firstInstance (the pair's transform
// entry), written by the CPU, with the index count the silhouette stages accumulated. The
// order of a list's commands depends on the atomics, not the result: stencil wrap increments
// and the float counter's +-1 additions are order independent.

struct Push {
    // Chunk records (after the frame's header).
    records: u32,
    // Word offset of the first record (the header's length).
    first: u32,
    _pad0: u32,
    _pad1: u32,
}

// The frame's header and chunk records (`pass::compute::rec`): word 0..5 the volume command,
// 5..10 the light-cap command, 18 and 19 the word offsets of their lists' count words in
// `lists` (NONE: the command is drawn by no list).
@group(0) @binding(0) var<storage, read> records: array<u32>;
@group(0) @binding(1) var<storage, read_write> lists: array<atomic<u32>>;

var<immediate> pc: Push;

const RECORD_WORDS: u32 = 20u;
const VOL_LIST: u32 = 18u;
const CAP_LIST: u32 = 19u;
const NONE: u32 = 0xffffffffu;
// Words from a list's count to its first command (16 bytes).
const LIST_HEADER: u32 = 4u;
const GROUP: u32 = 64u;

fn copy_command(r: u32, command: u32, list: u32) {
    if (list == NONE || records[r + command] == 0u) {
        return;
    }
    let k = atomicAdd(&lists[list], 1u);
    let at = list + LIST_HEADER + 5u * k;
    for (var i = 0u; i < 5u; i++) {
        atomicStore(&lists[at + i], records[r + command + i]);
    }
}

// One invocation per chunk record; a dispatch of more than 65535 workgroups comes as rows.
@compute @workgroup_size(64)
fn compact(
    @builtin(workgroup_id) wg: vec3<u32>,
    @builtin(num_workgroups) groups: vec3<u32>,
    @builtin(local_invocation_index) local: u32,
) {
    let i = (wg.y * groups.x + wg.x) * GROUP + local;
    if (i >= pc.records) {
        return;
    }
    let r = pc.first + i * RECORD_WORDS;
    copy_command(r, 0u, records[r + VOL_LIST]);
    copy_command(r, 5u, records[r + CAP_LIST]);
}
