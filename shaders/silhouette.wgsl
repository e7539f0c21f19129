// GPU possible silhouettes (`--method compute`): every (light, caster) pair of the frame in
// one dispatch per stage, whatever the number of casters.
//
// The casters' static tables live in one pass-wide arena; the frame's job table gives each
// (light, caster) pair its light, filter, offsets, records and facing bits, and its first
// invocation (facing, find) or workgroup (caps) in each stage: an invocation finds its job by
// a binary search of ceil(log2(jobs)) steps.
//
// Every triangle table is in the caster's scan order (`geom::TriangleOrder::spatial`): slot s
// is a triangle, 64 consecutive slots a compact patch (a block); facing bits and edges are by
// slot. Stages (`cmd_compute_silhouettes`; docs/compute.md has the details and the reasons):
// 1. `facing`, an invocation per block: `decide_block` (its f32 bound, `geom::planes::gpu`)
//    decides the block whole where it can; else each slot's plane filter with the CPU's error
//    bound; the undecided slots go to the exact list. Both words written whole.
// 2. `exact` (indirect, over the list): the exact sign of orient3d, summed without rounding in
//    a fixed-point accumulator: the bits are the CPU's, and the volume is closed.
// 3. `find`, an invocation per word-pair group (`pass::compute::tables`): a group of two
//    uniform, equal blocks is skipped; in the others an edge whose two bits differ writes its
//    side (and fan triangle) with the CPU's winding (`side`); `caps`, in the same barrier
//    interval, writes the face caps. Loops, not branches, carry per-slot, per-edge and
//    per-side work: on lavapipe a branch costs every lane, a loop ends when no lane is left.
// Output: 16-bit indices into the chunk's dual-length vertex buffer (i < n: (p, 1), i + n:
// (p, 0)), two to a u32 word, in regions allocated by an atomic add on the chunk's indexCount
// and sized on the CPU for the worst case; a write past one flags the record (never silent).

struct Push {
    jobs: u32,
    // Invocations of `facing` (blocks) and `find` (word-pair groups), workgroups of `caps`.
    blocks: u32,
    word_pairs: u32,
    cap_groups: u32,
    // Steps of the binary search over the jobs: ceil(log2(jobs)).
    steps: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}

// One (light, caster) pair (`pass::compute::frame::GpuJob`), in rows of four words (on
// lavapipe one vec4 load costs about what one scalar load costs).
struct Job {
    // The light in the caster's object space (w = 1 point, w = 0 directional).
    light: vec4<f32>,
    // The plane filter's light (negated for mirroring transforms).
    filt: vec4<f32>,
    // x: the filter's error bound (f32 bits; +inf: every triangle exact); y: J_FLIP (mirroring
    // transform: triangle corners 1 and 2 swapped for the exact test) | J_BLOCKS (the job has
    // a filter, so the block test may decide); z: triangles; w: edges.
    head: vec4<u32>,
    // The caster's first element in the plane, triangle, position and edge tables.
    bases: vec4<u32>,
    // x: word offset of the pair's chunk records; y: word offset of its facing bits (a bit per
    // slot, two words a block); z, w: its first invocation in the `facing` (blocks) and `find`
    // (word-pair groups) stages.
    offsets: vec4<u32>,
    // x: its first workgroup in the `caps` stage; y, z: the caster's first element in the
    // block-bound and word-pair tables; w: its word-pair groups.
    more: vec4<u32>,
}

const J_FLIP: u32 = 1u;
const J_BLOCKS: u32 = 2u;

struct Tri {
    // welded vertex ids (positions, relative to the caster's first)
    g: vec4<u32>,
    // chunk-local corner indices, chunk in w
    l: vec4<u32>,
}

@group(0) @binding(0) var<storage, read> planes: array<vec4<f32>>;
@group(0) @binding(1) var<storage, read> tris: array<Tri>;
@group(0) @binding(2) var<storage, read> positions: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read> edge_table: array<vec4<u32>>;
@group(0) @binding(4) var<storage, read> jobs: array<Job>;
@group(0) @binding(5) var<storage, read_write> facing_bits: array<atomic<u32>>;
@group(0) @binding(6) var<storage, read_write> records: array<atomic<u32>>;
@group(0) @binding(7) var<storage, read_write> out_words: array<atomic<u32>>;
// The exact list: (job, slot).
@group(0) @binding(8) var<storage, read_write> lists: array<vec2<u32>>;
// Per 64-slot block, three vec4s (`geom::planes::GpuBlock`): (c, D'), (N, Δd), (Δ, ok).
@group(0) @binding(9) var<storage, read> blocks: array<vec4<f32>>;
// Word-pair groups (a, b, first edge, edges): `pass::compute::tables::WordPairs`.
@group(0) @binding(10) var<storage, read> word_pairs: array<vec4<u32>>;

var<immediate> pc: Push;

// The frame's header at the start of `records` (`pass::compute::rec::H_*`): the exact list's
// length and its indirect dispatch command (x, y, z).
const H_EXACT: u32 = 0u;
const H_EXACT_X: u32 = 1u;
const MAX_GROUPS: u32 = 65535u;

// Chunk record layout (u32 words, RECORD_WORDS a chunk): the volume's indirect command
// (0..5), the light cap's (5..10), then counters and parameters.
const RECORD_WORDS: u32 = 20u;
const R_VOL_COUNT: u32 = 0u;
const R_VOL_FIRST: u32 = 2u;
const R_CAP_COUNT: u32 = 5u;
const R_CAP_FIRST: u32 = 7u;
const R_SIDES: u32 = 10u;
const R_DARK: u32 = 11u;
const R_EDGES: u32 = 12u;
const R_FLAGS: u32 = 13u;
const R_N: u32 = 14u;
const R_VOL_CAP: u32 = 15u;
const R_CAP_CAP: u32 = 16u;
const R_OVERFLOW: u32 = 17u;

const F_ENABLED: u32 = 1u;
const F_BACK: u32 = 2u;
const F_DIRECTIONAL: u32 = 4u;
const F_LIGHT_CAP: u32 = 32u;
// dark cap in bits 3..5: 0 none, 1 fan, 2 front faces, 3 back faces
const DC_FAN: u32 = 1u;
const DC_FRONT: u32 = 2u;
const DC_BACK: u32 = 3u;

// Triangles of one job a workgroup of the `caps` stage (`pass::compute::GROUP`).
const GROUP: u32 = 256u;
// Invocations a workgroup of the `facing` and `find` stages (`pass::compute::LANES`).
const LANES: u32 = 64u;
// The allowance of the block test (`geom::planes::gpu::ALLOWANCE`): 2^-18.
const ALLOWANCE: f32 = 3.814697265625e-6;

const STAGE_FACING: u32 = 0u;
const STAGE_FIND: u32 = 1u;
const STAGE_CAPS: u32 = 2u;

// ---- jobs ----

// (One field read, not the whole job: this runs log2(jobs) times per invocation.)
fn first_group(j: u32, stage: u32) -> u32 {
    if (stage == STAGE_FACING) {
        return jobs[j].offsets.z;
    }
    if (stage == STAGE_FIND) {
        return jobs[j].offsets.w;
    }
    return jobs[j].more.x;
}

// The job owning workgroup (caps) or invocation (facing, find) `w` of `stage`: the last job
// whose first group is at most `w`
// (jobs with no group in the stage share the next one's first group and are passed over).
// `pc.steps` = ceil(log2(jobs)) steps, no early exit: uniform control flow.
fn job_of(w: u32, stage: u32) -> u32 {
    var lo = 0u;
    var hi = pc.jobs;
    for (var i = 0u; i < pc.steps; i = i + 1u) {
        let open = lo + 1u < hi;
        let mid = (lo + hi) / 2u;
        let le = first_group(min(mid, pc.jobs - 1u), stage) <= w;
        lo = select(lo, mid, open && le);
        hi = select(hi, mid, open && !le);
    }
    return lo;
}

// The linear workgroup index of a stage dispatched as (min(n, 65535), ceil(n / 65535)).
fn group_index(wg: vec3<u32>, nwg: vec3<u32>) -> u32 {
    return wg.x + wg.y * nwg.x;
}

// The linear invocation index of a LANES-wide stage dispatched likewise.
fn lane_index(gid: vec3<u32>, nwg: vec3<u32>) -> u32 {
    return gid.x + gid.y * nwg.x * LANES;
}

// Appends `entry` to the exact list; the `exact` stage's indirect dispatch command grows to
// cover it (64 entries a workgroup; the stage strides beyond 65535 workgroups).
fn append_exact(entry: vec2<u32>) {
    let k = atomicAdd(&records[H_EXACT], 1u);
    lists[k] = entry;
    atomicMax(&records[H_EXACT_X], min((k + 64u) / 64u, MAX_GROUPS));
}

// ---- exact orient3d: fixed-point sum of products of three f32 values ----

const LIMBS: u32 = 72u;
// 3 x (smallest f32 exponent, -149) = -447: bit 0 of the accumulator is 2^-447.
const BIAS: i32 = 447;
var<private> acc: array<i32, 72>;

fn acc_clear() {
    for (var i = 0u; i < LIMBS; i = i + 1u) {
        acc[i] = 0;
    }
}

// An f32's significand (with its hidden bit) and the exponent of its last bit.
fn significand(b: u32) -> u32 {
    let f = b & 0x7fffffu;
    return select(f | 0x800000u, f, ((b >> 23u) & 0xffu) == 0u);
}
fn exponent(b: u32) -> i32 {
    let ef = (b >> 23u) & 0xffu;
    return select(i32(ef) - 150, -149, ef == 0u);
}

// Adds s * x * y * z exactly (s = +1 or -1). Written without loops over private arrays
// or early returns: SwiftShader's compiler (it inlines every call) never finished the form
// with a call site per term (docs/drivers/pipelines.md).
fn add3(x: f32, y: f32, z: f32, s: i32) {
    let bx = bitcast<u32>(x);
    let by = bitcast<u32>(y);
    let bz = bitcast<u32>(z);
    if ((bx & 0x7fffffffu) != 0u && (by & 0x7fffffffu) != 0u && (bz & 0x7fffffffu) != 0u) {
        let sign = select(s, -s, ((bx ^ by ^ bz) >> 31u) != 0u);
        let e = exponent(bx) + exponent(by) + exponent(bz);
        let mx = significand(bx);
        let my = significand(by);
        let mz = significand(bz);
        // mx * my in 12-bit limbs
        let a0 = mx & 0xfffu;
        let a1 = mx >> 12u;
        let b0 = my & 0xfffu;
        let b1 = my >> 12u;
        var r0 = a0 * b0;
        var r1 = a0 * b1 + a1 * b0;
        var r2 = a1 * b1;
        r1 = r1 + (r0 >> 12u);
        r0 = r0 & 0xfffu;
        r2 = r2 + (r1 >> 12u);
        r1 = r1 & 0xfffu;
        let r3 = r2 >> 12u;
        r2 = r2 & 0xfffu;
        // times mz
        let c0 = mz & 0xfffu;
        let c1 = mz >> 12u;
        var t0 = r0 * c0;
        var t1 = r0 * c1 + r1 * c0;
        var t2 = r1 * c1 + r2 * c0;
        var t3 = r2 * c1 + r3 * c0;
        var t4 = r3 * c1;
        t1 = t1 + (t0 >> 12u);
        t0 = t0 & 0xfffu;
        t2 = t2 + (t1 >> 12u);
        t1 = t1 & 0xfffu;
        t3 = t3 + (t2 >> 12u);
        t2 = t2 & 0xfffu;
        t4 = t4 + (t3 >> 12u);
        t3 = t3 & 0xfffu;
        let t5 = t4 >> 12u;
        t4 = t4 & 0xfffu;
        let p = u32(e + BIAS);
        let q = p / 12u;
        let sh = p % 12u;
        let t = array<u32, 6>(t0 << sh, t1 << sh, t2 << sh, t3 << sh, t4 << sh, t5 << sh);
        for (var i = 0u; i < 6u; i = i + 1u) {
            acc[q + i] = acc[q + i] + sign * i32(t[i] & 0xfffu);
            acc[q + i + 1u] = acc[q + i + 1u] + sign * i32(t[i] >> 12u);
        }
    }
}

// Sign of the accumulated sum: -1, 0 or 1.
fn acc_sign() -> i32 {
    var carry = 0i;
    var nonzero = false;
    for (var i = 0u; i < LIMBS; i = i + 1u) {
        let v = acc[i] + carry;
        carry = v >> 12u;
        let limb = v - carry * 4096;
        if (limb != 0) {
            nonzero = true;
        }
    }
    if (carry < 0) {
        return -1;
    }
    if (carry > 0 || nonzero) {
        return 1;
    }
    return 0;
}

// Exact facing (`geom::predicates::facing_exact`): point light det[p0 - L, p1 - L, p2 - L] < 0,
// directional det[p1 - p0, p2 - p0, d] > 0; the six permutations' products of differences
// expanded into 48 (24) terms of three f32 values, one loop so `add3` is inlined once.
fn facing_exact(job: Job, t: u32) -> bool {
    let tri = tris[job.bases.y + t];
    var i1 = tri.g.y;
    var i2 = tri.g.z;
    if ((job.head.y & J_FLIP) != 0u) {
        i1 = tri.g.z;
        i2 = tri.g.y;
    }
    let p0 = positions[job.bases.z + tri.g.x].xyz;
    let p1 = positions[job.bases.z + i1].xyz;
    let p2 = positions[job.bases.z + i2].xyz;
    let l = job.light.xyz;
    let point = job.light.w != 0.0;
    let x0 = select(p1, p0, point);
    let x1 = select(p0, l, point);
    let y0 = select(p2, p1, point);
    let y1 = select(p0, l, point);
    let z0 = select(l, p2, point);
    let z1 = l;
    let terms = select(4u, 8u, point);
    let perms = array<vec4<i32>, 6>(
        vec4<i32>(0, 1, 2, 1), vec4<i32>(0, 2, 1, -1), vec4<i32>(1, 2, 0, 1),
        vec4<i32>(1, 0, 2, -1), vec4<i32>(2, 0, 1, 1), vec4<i32>(2, 1, 0, -1));
    acc_clear();
    for (var n = 0u; n < 6u * terms; n = n + 1u) {
        let pm = perms[n / terms];
        let b = n % terms;
        let x = select(x0[pm.x], x1[pm.x], (b & 1u) != 0u);
        let y = select(y0[pm.y], y1[pm.y], (b & 2u) != 0u);
        let z = select(z0[pm.z], z1[pm.z], (b & 4u) != 0u);
        // each term taken from the subtrahend flips the sign
        let flips = countOneBits(b);
        add3(x, y, z, select(pm.w, -pm.w, (flips & 1u) != 0u));
    }
    let sign = acc_sign();
    return select(sign > 0, sign < 0, point);
}

// ---- output ----

fn put_half(pos: u32, value: u32) {
    let w = pos >> 1u;
    if ((pos & 1u) == 0u) {
        atomicAnd(&out_words[w], 0xffff0000u);
        atomicOr(&out_words[w], value);
    } else {
        atomicAnd(&out_words[w], 0x0000ffffu);
        atomicOr(&out_words[w], value << 16u);
    }
}

// Writes `count` (3, 6 or 9) indices at index position `pos`.
fn put(pos: u32, idx: array<u32, 9>, count: u32) {
    var i = 0u;
    if ((pos & 1u) == 1u) {
        put_half(pos, idx[0]);
        i = 1u;
    }
    loop {
        if (i + 1u >= count) {
            break;
        }
        atomicStore(&out_words[(pos + i) >> 1u], idx[i] | (idx[i + 1u] << 16u));
        i = i + 2u;
    }
    if (i < count) {
        put_half(pos + i, idx[i]);
    }
}

// Allocates `count` indices in the volume (cap = false) or light-cap region of record `r`.
fn emit(r: u32, cap: bool, idx: array<u32, 9>, count: u32) {
    var c = R_VOL_COUNT;
    var first = R_VOL_FIRST;
    var capacity = R_VOL_CAP;
    if (cap) {
        c = R_CAP_COUNT;
        first = R_CAP_FIRST;
        capacity = R_CAP_CAP;
    }
    let at = atomicAdd(&records[r + c], count);
    if (at + count > atomicLoad(&records[r + capacity])) {
        atomicStore(&records[r + R_OVERFLOW], 1u);
        return;
    }
    put(atomicLoad(&records[r + first]) + at, idx, count);
}

// ---- stages ----

// The block test (`geom::planes::gpu`'s mirror, same f32 operations and order, its allowance
// derived there): 1 every slot faces `l` (w = ±1 or 0, filter bound `e`), -1 none, 0 undecided.
fn decide_block(k: u32, l: vec4<f32>, e: f32) -> i32 {
    let cd = blocks[k];
    let nd = blocks[k + 1u];
    let sp = blocks[k + 2u];
    let w = l.w;
    let q = vec3<f32>(l.x - cd.x * w, l.y - cd.y * w, l.z - cd.z * w);
    let aq = abs(q);
    let centre = ((nd.x * q.x + nd.y * q.y) + nd.z * q.z) + cd.w * w;
    let spread = ((sp.x * aq.x + sp.y * aq.y) + sp.z * aq.z) + nd.w * abs(w);
    let mag = ((abs(nd.x) * aq.x + abs(nd.y) * aq.y) + abs(nd.z) * aq.z) + abs(cd.w) * abs(w);
    let t = spread + e;
    let margin = t + (t + mag) * ALLOWANCE;
    let ok = sp.w == 1.0;
    return select(0, select(select(0, -1, centre < -margin), 1, centre > margin), ok);
}

// Stage 1: one 64-slot block of one job an invocation (the job's fields read one by one).
@compute @workgroup_size(LANES)
fn facing(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let g = lane_index(gid, nwg);
    let j = job_of(g, STAGE_FACING);
    let head = jobs[j].head;
    let bases = jobs[j].bases;
    let offsets = jobs[j].offsets;
    let more = jobs[j].more;
    let f = jobs[j].filt;
    let b = g - offsets.z;
    let tris = head.z;
    if (g < pc.blocks && b * 64u < tris) {
        let n = min(tris - b * 64u, 64u);
        let bound = bitcast<f32>(head.x);
        var decided = 0;
        if ((head.y & J_BLOCKS) != 0u) {
            decided = decide_block(more.y + 3u * b, f, bound);
        }
        // the slots' valid bits in the block's two words
        let valid_lo = select(0xffffffffu, (1u << min(n, 31u)) - 1u, n < 32u);
        let valid_hi = select(0u, select(0xffffffffu, (1u << (n - 32u)) - 1u, n < 64u), n > 32u);
        var lo = select(0u, valid_lo, decided > 0);
        var hi = select(0u, valid_hi, decided > 0);
        var unsure_lo = 0u;
        var unsure_hi = 0u;
        // undecided block: each slot's plane (a loop, so blocks decided whole cost nothing
        // here once every lane's block is decided)
        let count = select(n, 0u, decided != 0);
        let base = bases.x + b * 64u;
        for (var k = 0u; k < count; k = k + 1u) {
            let pl = planes[base + k];
            // the CPU's order: ((nx lx + ny ly) + nz lz) + d lw
            let v = ((pl.x * f.x + pl.y * f.y) + pl.z * f.z) + pl.w * f.w;
            let bit = 1u << (k & 31u);
            let up = select(0u, bit, v > bound);
            // undecided (|v| <= bound, or NaN): the exact test decides
            let unsure = select(0u, bit, !(v > bound) && !(v < -bound));
            let low = k < 32u;
            lo = lo | select(0u, up, low);
            hi = hi | select(up, 0u, low);
            unsure_lo = unsure_lo | select(0u, unsure, low);
            unsure_hi = unsure_hi | select(unsure, 0u, low);
        }
        let w = offsets.y + 2u * b;
        atomicStore(&facing_bits[w], lo);
        atomicStore(&facing_bits[w + 1u], hi);
        // the undecided slots to the exact list (no iteration in most blocks)
        var unsure = vec2<u32>(unsure_lo, unsure_hi);
        loop {
            if (unsure.x == 0u && unsure.y == 0u) {
                break;
            }
            let low = unsure.x != 0u;
            let word = select(unsure.y, unsure.x, low);
            let k = firstTrailingBit(word) + select(32u, 0u, low);
            append_exact(vec2<u32>(j, b * 64u + k));
            unsure = select(vec2<u32>(unsure.x, unsure.y & (unsure.y - 1u)), vec2<u32>(unsure.x & (unsure.x - 1u), unsure.y), low);
        }
    }
}

// Stage 2: the exact test of the listed slots (indirect; strides past the dispatch limit).
@compute @workgroup_size(64)
fn exact(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let stride = nwg.x * 64u;
    let count = atomicLoad(&records[H_EXACT]);
    for (var k = gid.x; k < count; k = k + stride) {
        let e = lists[k];
        let job = jobs[e.x];
        if (facing_exact(job, e.y)) {
            atomicOr(&facing_bits[job.offsets.y + (e.y >> 5u)], 1u << (e.y & 31u));
        }
    }
}

// Stage 3a: silhouette edges and their sides, one word-pair group of one job an invocation.
@compute @workgroup_size(LANES)
fn find(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let g = lane_index(gid, nwg);
    let j = job_of(g, STAGE_FIND);
    let offsets = jobs[j].offsets;
    let more = jobs[j].more;
    let i = g - offsets.w;
    if (g < pc.word_pairs && i < more.w) {
        let h = word_pairs[more.z + i];
        let fac = offsets.y;
        let a0 = atomicLoad(&facing_bits[fac + 2u * h.x]);
        let a1 = atomicLoad(&facing_bits[fac + 2u * h.x + 1u]);
        let b0 = atomicLoad(&facing_bits[fac + 2u * h.y]);
        let b1 = atomicLoad(&facing_bits[fac + 2u * h.y + 1u]);
        // both blocks all ones or both all zeros: no edge of the group is on the silhouette
        let uniform = (a0 & a1 & b0 & b1) == 0xffffffffu || (a0 | a1 | b0 | b1) == 0u;
        let count = select(h.w, 0u, uniform);
        let first = jobs[j].bases.w + h.z;
        var sil = 0u;
        for (var k = 0u; k < count; k = k + 1u) {
            // the two slots' bit positions in blocks a and b
            let p = edge_table[first + k].w;
            let pa = p & 63u;
            let pb = (p >> 8u) & 63u;
            let fa = select(a0, a1, pa >= 32u) >> (pa & 31u);
            let fb = select(b0, b1, pb >= 32u) >> (pb & 31u);
            sil = sil | (((fa ^ fb) & 1u) << k);
        }
        loop {
            if (sil == 0u) {
                break;
            }
            side(j, h.z + firstTrailingBit(sil));
            sil = sil & (sil - 1u);
        }
    }
}

// Stage 3b: the face caps of the chunks that need them, GROUP slots of one job a workgroup.
@compute @workgroup_size(GROUP)
fn caps(@builtin(workgroup_id) wg: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>,
        @builtin(local_invocation_index) lid: u32) {
    let w = group_index(wg, nwg);
    // the job's fields one by one (each load is per lane on lavapipe)
    let j = job_of(w, STAGE_CAPS);
    let t = (w - jobs[j].more.x) * GROUP + lid;
    if (w >= pc.cap_groups || t >= jobs[j].head.z) {
        return;
    }
    let offsets = jobs[j].offsets;
    let f = ((atomicLoad(&facing_bits[offsets.y + (t >> 5u)]) >> (t & 31u)) & 1u) != 0u;
    let tri = tris[jobs[j].bases.y + t];
    let r = offsets.x + tri.l.w * RECORD_WORDS;
    let flags = atomicLoad(&records[r + R_FLAGS]);
    if ((flags & F_ENABLED) == 0u) {
        return;
    }
    let n = atomicLoad(&records[r + R_N]);
    let dc = (flags >> 3u) & 3u;
    if ((dc == DC_FRONT && f) || (dc == DC_BACK && !f)) {
        var idx = array<u32, 9>(tri.l.x + n, tri.l.y + n, tri.l.z + n, 0u, 0u, 0u, 0u, 0u, 0u);
        if (dc == DC_FRONT) {
            idx[1] = tri.l.z + n;
            idx[2] = tri.l.y + n;
        }
        emit(r, false, idx, 3u);
        atomicAdd(&records[r + R_DARK], 1u);
    }
    if ((flags & F_LIGHT_CAP) != 0u) {
        let want = (flags & F_BACK) == 0u;
        if (f == want) {
            var idx = array<u32, 9>(tri.l.x, tri.l.y, tri.l.z, 0u, 0u, 0u, 0u, 0u, 0u);
            if (!want) {
                idx[1] = tri.l.z;
                idx[2] = tri.l.y;
            }
            emit(r, true, idx, 3u);
        }
    }
}

fn corner(l: vec4<u32>, k: u32) -> u32 {
    return select(select(l.z, l.y, k == 1u), l.x, k == 0u);
}

// The side (and fan triangle) of silhouette edge `i` of job `j`: one emission of 3, 6 or 9
// indices (selected, not branched: llvmpipe pays every branch's emission on every lane).
fn side(j: u32, i: u32) {
    let bases = jobs[j].bases;
    let offsets = jobs[j].offsets;
    let tri_base = bases.y;
    let rec_base = offsets.x;
    let fac = offsets.y;
    let e = edge_table[bases.w + i].xyz;
    let f0 = ((atomicLoad(&facing_bits[fac + (e.x >> 5u)]) >> (e.x & 31u)) & 1u) != 0u;
    // lit: the light-facing triangle and the corner where a -> b starts in it
    let c0 = e.z & 0xffu;
    let c1 = (e.z >> 8u) & 0xffu;
    let lit = select(e.y, e.x, f0);
    let lit_c = select(c1, c0, f0);
    let unlit = select(e.x, e.y, f0);
    let unlit_c = select(c0, c1, f0);
    // which chunk's record decides: the lit triangle's (front) or the unlit one's (back)
    let lit_l = tris[tri_base + lit].l;
    let back = (atomicLoad(&records[rec_base + lit_l.w * RECORD_WORDS + R_FLAGS]) & F_BACK) != 0u;
    var l = lit_l;
    var k = lit_c;
    if (back) {
        l = tris[tri_base + unlit].l;
        k = unlit_c;
    }
    let r = rec_base + l.w * RECORD_WORDS;
    let flags = atomicLoad(&records[r + R_FLAGS]);
    if ((flags & F_ENABLED) != 0u) {
        let n = atomicLoad(&records[r + R_N]);
        let ca = corner(l, k);
        let cb = corner(l, (k + 1u) % 3u);
        let a = select(ca, cb, back);
        let b = select(cb, ca, back);
        let directional = (flags & F_DIRECTIONAL) != 0u;
        let fan = !directional && ((flags >> 3u) & 3u) == DC_FAN;
        // directional (b, a, a∞); point (b, a, a∞), (b, a∞, b∞); McGuire's fan also
        // (apex∞, b∞, a∞)
        let count = select(select(6u, 9u, fan), 3u, directional);
        let apex = n - 1u;
        emit(r, false, array<u32, 9>(b, a, a + n, b, a + n, b + n, apex + n, b + n, a + n), count);
        atomicAdd(&records[r + R_EDGES], 1u);
        atomicAdd(&records[r + R_SIDES], select(2u, 1u, directional));
        if (fan) {
            atomicAdd(&records[r + R_DARK], 1u);
        }
    }
}
