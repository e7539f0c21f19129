// GPU possible silhouettes (`--method compute`): every (light, caster) pair of the frame in
// one dispatch per stage, whatever the number of casters.
//
// The casters' static tables live in one pass-wide arena (planes, triangles, positions,
// edges: one storage buffer each); the frame's job table gives each (light, caster) pair its
// object-space light, filter, arena offsets, chunk records and facing bits, and the first
// workgroup it owns in each stage (a prefix over the jobs: a workgroup finds its job by a
// binary search, uniform across the workgroup). Stages (`cmd_compute_silhouettes`):
//
// 1. `facing`, a workgroup per GROUP triangles of a job: the facing bit, exactly as the
//    CPU's `FacePlanes::facing_packed` decides it: the f32 plane value is trusted only beyond
//    the CPU's proven error bound (`bound`, computed on the CPU per caster and light). A
//    light-facing triangle sets its bit (the words were cleared by a fill). Every triangle the
//    filter cannot decide (grazing light, degenerate triangles) goes to the frame's exact
//    list, whose indirect dispatch size the same atomics keep up to date.
// 2. `exact` (indirect, over the exact list): the EXACT sign of orient3d of the triangle's f32
//    vertices, evaluated as a sum of 48 (point light) or 24 (directional) products of three
//    f32 values in a fixed-point accumulator of 12-bit limbs (no rounding at all). The bits are
//    therefore the CPU's, bit for bit, and every edge is derived from one bit per triangle:
//    the volume is closed by construction. (Its own stage: in the filter's, its code made
//    lavapipe ten times slower on every triangle.)
// 3. `find`, a workgroup per GROUP manifold edges of a job: an edge whose two triangles' bits
//    differ is a possible silhouette edge, appended to the frame's silhouette list (an atomic
//    per silhouette edge: O(sqrt(n)) of n). Nothing else happens per edge: on lavapipe a
//    branch's code costs every lane whether it is taken or not, and the emitting code in this
//    stage made it 190 ms instead of 13 at 490k triangles. (A workgroup aggregation of the
//    appends, with two workgroup barriers, measured no faster there: 25-27 ms either way.)
//    `caps`, in the same barrier interval, a workgroup per GROUP triangles of the jobs whose
//    chunks need face caps (dark cap of front or back faces, light cap): the caps.
// 4. `emit` (indirect, over the silhouette list): each edge's side quad (one triangle for a
//    directional light) and, for McGuire's fan dark cap, its fan triangle, into the chunk of
//    the light-facing triangle (front formulation) or of the other one (back formulation, the
//    light inside the part's bounds), with the same winding as the CPU's `shadow::plan::emit`.
//
// Output: 16-bit indices into the chunk's dual-length vertex buffer (index i < n: (p, 1),
// i + n: (p, 0)), packed two to a u32 word. A chunk's region is allocated with an atomic add
// on its VkDrawIndexedIndirectCommand::indexCount; a word shared by two allocations is written
// with atomicAnd/atomicOr on disjoint halves (order independent), a word owned whole with
// atomicStore. Regions are sized on the CPU for the worst case of the chunk's case; a write
// past the region is not made and flags the record's overflow word instead (never silent).

struct Push {
    jobs: u32,
    // Workgroups of the `facing`, `find` and `caps` stages (the sums over the jobs).
    facing_groups: u32,
    find_groups: u32,
    cap_groups: u32,
    // Entry offset of the silhouette list in `lists` (the exact list starts at 0).
    sil_base: u32,
    // Steps of the binary search over the jobs: ceil(log2(jobs)).
    steps: u32,
    _pad1: u32,
    _pad2: u32,
}

// One (light, caster) pair (`pass::compute::frame::GpuJob`).
struct Job {
    // The light in the caster's object space (w = 1 point, w = 0 directional), f32 as the
    // CPU planner has it.
    light: vec4<f32>,
    // The plane filter's light (negated for mirroring transforms).
    filt: vec4<f32>,
    // The filter's error bound (+inf: every triangle exact).
    bound: f32,
    // 1: mirroring transform (triangle corners 1 and 2 swapped for the exact test).
    flip: u32,
    tris: u32,
    edges: u32,
    // The caster's first element in each arena table.
    plane_base: u32,
    tri_base: u32,
    pos_base: u32,
    edge_base: u32,
    // Word offset of the pair's chunk records.
    rec_base: u32,
    // Word offset of the pair's facing bits (a bit per triangle, whole workgroups).
    fac_base: u32,
    // The pair's first workgroup in the `facing`, `find` and `caps` stages.
    g_facing: u32,
    g_find: u32,
    g_caps: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}

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
@group(0) @binding(8) var<storage, read_write> lists: array<vec2<u32>>;

var<immediate> pc: Push;

// The frame's header at the start of `records` (`pass::compute::rec::H_*`): the two lists'
// lengths and their indirect dispatch commands (x, y, z).
const H_EXACT: u32 = 0u;
const H_EXACT_X: u32 = 1u;
const H_SIL: u32 = 4u;
const H_SIL_X: u32 = 5u;
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

// Triangles (facing, caps) or edges (find) of one job a workgroup (`pass::compute::GROUP`).
const GROUP: u32 = 256u;

const STAGE_FACING: u32 = 0u;
const STAGE_FIND: u32 = 1u;
const STAGE_CAPS: u32 = 2u;


// ---- jobs ----

// (One field read, not the whole job: this runs log2(jobs) times per invocation.)
fn first_group(j: u32, stage: u32) -> u32 {
    if (stage == STAGE_FACING) {
        return jobs[j].g_facing;
    }
    if (stage == STAGE_FIND) {
        return jobs[j].g_find;
    }
    return jobs[j].g_caps;
}

// The job owning workgroup `w` of `stage`: the last job whose first group is at most `w`
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

fn facing_bit(job: Job, t: u32) -> bool {
    return ((atomicLoad(&facing_bits[job.fac_base + (t >> 5u)]) >> (t & 31u)) & 1u) != 0u;
}

// Appends to a list whose indirect dispatch command is at `x_word`: its x grows to cover
// entry `k` (64 entries a workgroup; the stage strides beyond 65535 workgroups).
fn grow_dispatch(x_word: u32, end: u32) {
    atomicMax(&records[x_word], min((end + 63u) / 64u, MAX_GROUPS));
}

// Appends `entry` to the list whose length is header word `count_word`, its entries from
// `base` in `lists`, its dispatch command's x at `x_word`.
fn append(count_word: u32, x_word: u32, base: u32, entry: vec2<u32>) {
    let k = atomicAdd(&records[count_word], 1u);
    lists[base + k] = entry;
    grow_dispatch(x_word, k + 1u);
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


// Exact facing: point light: det[p0 - L, p1 - L, p2 - L] < 0; directional:
// det[p1 - p0, p2 - p0, d] > 0 (`geom::predicates::facing_exact`). The determinant is the
// sum over the six permutations (i, j, k) of its rows' components, each a product of three
// differences expanded into its terms: point light, rows (x0 - x1) (y0 - y1) (z0 - z1) with
// x = (p0, L), y = (p1, L), z = (p2, L): 8 terms; directional, x = (p1, p0), y = (p2, p0),
// z = d: 4 terms. One loop over the 48 (or 24) terms, so `add3` is inlined once.
fn facing_exact(job: Job, t: u32) -> bool {
    let tri = tris[job.tri_base + t];
    var i1 = tri.g.y;
    var i2 = tri.g.z;
    if (job.flip != 0u) {
        i1 = tri.g.z;
        i2 = tri.g.y;
    }
    let p0 = positions[job.pos_base + tri.g.x].xyz;
    let p1 = positions[job.pos_base + i1].xyz;
    let p2 = positions[job.pos_base + i2].xyz;
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

// Stage 1: the plane filter, GROUP triangles of one job a workgroup (the facing words were
// cleared by the frame's fill). The job's fields are read one by one: loading the whole job
// per invocation cost lavapipe more than the planes themselves.
@compute @workgroup_size(GROUP)
fn facing(@builtin(workgroup_id) wg: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>,
          @builtin(local_invocation_index) lid: u32) {
    let w = group_index(wg, nwg);
    let j = job_of(w, STAGE_FACING);
    let t = (w - jobs[j].g_facing) * GROUP + lid;
    if (w < pc.facing_groups && t < jobs[j].tris) {
        let pl = planes[jobs[j].plane_base + t];
        let f = jobs[j].filt;
        let bound = jobs[j].bound;
        // the CPU's order: ((nx lx + ny ly) + nz lz) + d lw
        let v = ((pl.x * f.x + pl.y * f.y) + pl.z * f.z) + pl.w * f.w;
        if (v > bound) {
            atomicOr(&facing_bits[jobs[j].fac_base + (t >> 5u)], 1u << (t & 31u));
        } else if (!(v < -bound)) {
            // undecided (|v| <= bound, or NaN): the exact test decides
            append(H_EXACT, H_EXACT_X, 0u, vec2<u32>(j, t));
        }
    }
}

// Stage 2: the exact test for the listed triangles (indirect: as many workgroups as the list
// needs, striding beyond the dispatch limit).
@compute @workgroup_size(64)
fn exact(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let stride = nwg.x * 64u;
    let count = atomicLoad(&records[H_EXACT]);
    for (var k = gid.x; k < count; k = k + stride) {
        let e = lists[k];
        let job = jobs[e.x];
        if (facing_exact(job, e.y)) {
            atomicOr(&facing_bits[job.fac_base + (e.y >> 5u)], 1u << (e.y & 31u));
        }
    }
}

// Stage 3a: possible silhouette edges, GROUP edges of one job a workgroup, appended to the
// silhouette list (an atomic per silhouette edge: they are few).
@compute @workgroup_size(GROUP)
fn find(@builtin(workgroup_id) wg: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>,
        @builtin(local_invocation_index) lid: u32) {
    let w = group_index(wg, nwg);
    let j = job_of(w, STAGE_FIND);
    let i = (w - jobs[j].g_find) * GROUP + lid;
    if (w < pc.find_groups && i < jobs[j].edges) {
        let e = edge_table[jobs[j].edge_base + i];
        let fac = jobs[j].fac_base;
        let b0 = (atomicLoad(&facing_bits[fac + (e.x >> 5u)]) >> (e.x & 31u)) & 1u;
        let b1 = (atomicLoad(&facing_bits[fac + (e.y >> 5u)]) >> (e.y & 31u)) & 1u;
        if (b0 != b1) {
            append(H_SIL, H_SIL_X, pc.sil_base, vec2<u32>(j, i));
        }
    }
}

// Stage 3b: triangle t's face caps (dark cap of front or back faces, light cap) for the
// chunks whose case needs them; GROUP triangles of one job with caps a workgroup.
@compute @workgroup_size(GROUP)
fn caps(@builtin(workgroup_id) wg: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>,
        @builtin(local_invocation_index) lid: u32) {
    let w = group_index(wg, nwg);
    let job = jobs[job_of(w, STAGE_CAPS)];
    let t = (w - job.g_caps) * GROUP + lid;
    if (w >= pc.cap_groups || t >= job.tris) {
        return;
    }
    let f = facing_bit(job, t);
    let tri = tris[job.tri_base + t];
    let r = job.rec_base + tri.l.w * RECORD_WORDS;
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
    if (k == 0u) {
        return l.x;
    }
    if (k == 1u) {
        return l.y;
    }
    return l.z;
}

// The side (and fan triangle) of silhouette edge `i` of job `j`.
fn side(j: u32, i: u32) {
    let job = jobs[j];
    let e = edge_table[job.edge_base + i];
    let f0 = facing_bit(job, e.x);
    // lit: the light-facing triangle and the corner where a -> b starts in it
    var lit = e.x;
    var lit_c = e.z & 0xffu;
    var unlit = e.y;
    var unlit_c = (e.z >> 8u) & 0xffu;
    if (!f0) {
        lit = e.y;
        lit_c = (e.z >> 8u) & 0xffu;
        unlit = e.x;
        unlit_c = e.z & 0xffu;
    }
    // which chunk's record decides: the lit triangle's (front) or the unlit one's (back)
    let lit_tri = tris[job.tri_base + lit];
    let r_lit = job.rec_base + lit_tri.l.w * RECORD_WORDS;
    let back = (atomicLoad(&records[r_lit + R_FLAGS]) & F_BACK) != 0u;
    var tri = lit_tri;
    var k = lit_c;
    if (back) {
        tri = tris[job.tri_base + unlit];
        k = unlit_c;
    }
    let r = job.rec_base + tri.l.w * RECORD_WORDS;
    let flags = atomicLoad(&records[r + R_FLAGS]);
    if ((flags & F_ENABLED) == 0u) {
        return;
    }
    let n = atomicLoad(&records[r + R_N]);
    var a = corner(tri.l, k);
    var b = corner(tri.l, (k + 1u) % 3u);
    if (back) {
        let s = a;
        a = b;
        b = s;
    }
    atomicAdd(&records[r + R_EDGES], 1u);
    if ((flags & F_DIRECTIONAL) != 0u) {
        emit(r, false, array<u32, 9>(b, a, a + n, 0u, 0u, 0u, 0u, 0u, 0u), 3u);
        atomicAdd(&records[r + R_SIDES], 1u);
        return;
    }
    let dc = (flags >> 3u) & 3u;
    if (dc == DC_FAN) {
        let apex = n - 1u;
        emit(r, false, array<u32, 9>(b, a, a + n, b, a + n, b + n, apex + n, b + n, a + n), 9u);
        atomicAdd(&records[r + R_DARK], 1u);
    } else {
        emit(r, false, array<u32, 9>(b, a, a + n, b, a + n, b + n, 0u, 0u, 0u), 6u);
    }
    atomicAdd(&records[r + R_SIDES], 2u);
}

// Stage 4: the listed silhouette edges' sides (indirect, striding beyond the dispatch limit).
@compute @workgroup_size(64)
fn sides(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let stride = nwg.x * 64u;
    let count = atomicLoad(&records[H_SIL]);
    for (var k = gid.x; k < count; k = k + stride) {
        let e = lists[pc.sil_base + k];
        side(e.x, e.y);
    }
}
