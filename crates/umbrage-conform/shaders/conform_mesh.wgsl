// The conformance suite's mesh-shader family (`mesh.*`; src/conform/mesh/): what
// `--method mesh` (shaders/extrude.wgsl) relies on of VK_EXT_mesh_shader, drawn by
// vkCmdDrawMeshTasksEXT into a depth-stencil image and recorded into a storage buffer of u32
// words with atomics, for the CPU model to compare pixel for pixel and word for word.
//
// Entry points:
// * `w0` (mesh): triangles of a table, each vertex placed as extrude.wgsl places it: a w = 1
//   vertex is mvp * p, a w = 0 vertex mvp * (p * L.w - L.xyz, 0) — at infinity — with
//   extrude's near-zero w where clip w is exactly 0 (F_NEAR_ZERO_W) or w = 0 as it is.
// * `extrude` (mesh) and `cull` (task) + `extrude_tasked` (mesh): the shadow volume of a closed
//   caster split into meshlets, a workgroup each, as extrude.wgsl builds it: facing per
//   triangle in the triangle's stored vertex order (both meshlets of an edge compute it from
//   the same words, so they agree bit for bit), light and dark caps of the light-facing
//   triangles, and a side quad per silhouette edge from the one meshlet that owns it. The task
//   stage keeps the meshlets that emit anything and hands their ids to the mesh stage in its
//   payload (a varying number of mesh workgroups per task workgroup).
// * `groups` (mesh): what a workgroup is told of the draw (workgroup_id, num_workgroups,
//   local index), one pixel tile a workgroup.
// * `spawn` (task) + `spawned` (mesh): task workgroups emitting (j % 4, 1 + j % 3, 1) mesh
//   workgroups with a payload written by every task invocation; each mesh workgroup records
//   what it read of it, one pixel tile a workgroup.
//
// Every vertex is written as a plain position (no per-primitive outputs: llvmpipe before Mesa
// 26.2.3 mishandles them, wgpu #8727).
enable wgpu_mesh_shader;

struct Push {
    mvp: mat4x4<f32>,
    // The light in object space (w = 1: a point light), as extrude.wgsl's `light`.
    light: vec4<f32>,
    // F_* below.
    flags: u32,
    // `w0`: the first vertex of the draw's triangles in `positions`; `extrude`/`cull`: word
    // offset of the caster's tables in `words`.
    table: u32,
    // Items: triangles (`w0`), meshlets (`extrude`, `cull`), task workgroups (`spawn`).
    count: u32,
    // Word offset, in `records`, of what the draw records.
    rec: u32,
}

@group(0) @binding(0) var<storage, read> positions: array<vec4<f32>>;
@group(0) @binding(1) var<storage, read> words: array<u32>;
@group(0) @binding(2) var<storage, read_write> records: array<atomic<u32>>;

var<immediate> pc: Push;

// Clip w exactly 0 becomes extrude.wgsl's near-zero w (as shadow.vert does).
const F_NEAR_ZERO_W: u32 = 1u;

struct Vertex {
    @builtin(position) position: vec4<f32>,
}

struct Primitive {
    @builtin(triangle_indices) indices: vec3<u32>,
}

// extrude.wgsl's `near`: a w = 1 vertex.
fn near(p: vec4<f32>) -> vec4<f32> {
    return pc.mvp * p;
}

// extrude.wgsl's `far`: the w = 0 copy of vertex `p`, at infinity away from the light.
fn far(p: vec4<f32>) -> vec4<f32> {
    var c = pc.mvp * vec4<f32>(p.xyz * pc.light.w - pc.light.xyz, 0.0);
    if ((pc.flags & F_NEAR_ZERO_W) != 0u && c.w == 0.0) {
        c.w = max(max(abs(c.x), abs(c.y)), abs(c.z)) * 8.6736174e-19;
    }
    return c;
}

// The linear index of a workgroup of a 2D launch (x fastest).
fn linear_group(wg: vec3<u32>, nwg: vec3<u32>) -> u32 {
    return wg.x + nwg.x * (wg.y + nwg.y * wg.z);
}

// ---------------------------------------------------------------------------------------
// `w0`: W0_TRIS triangles a workgroup.

const W0_TRIS: u32 = 8u;

struct TriOutput {
    @builtin(vertex_count) vertex_count: u32,
    @builtin(primitive_count) primitive_count: u32,
    @builtin(vertices) vertices: array<Vertex, 24>,
    @builtin(primitives) primitives: array<Primitive, 8>,
}

var<workgroup> tri_out: TriOutput;

fn place(p: vec4<f32>) -> vec4<f32> {
    if (p.w == 0.0) {
        return far(p);
    }
    return near(p);
}

@mesh(tri_out)
@workgroup_size(8)
fn w0(@builtin(workgroup_id) wg: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>, @builtin(local_invocation_index) lid: u32) {
    let group = linear_group(wg, nwg);
    let first = min(group * W0_TRIS, pc.count);
    let n = min(W0_TRIS, pc.count - first);
    if (lid < n) {
        let v = pc.table + 3u * (first + lid);
        for (var k = 0u; k < 3u; k = k + 1u) {
            tri_out.vertices[3u * lid + k].position = place(positions[v + k]);
        }
        tri_out.primitives[lid].indices = vec3<u32>(3u * lid, 3u * lid + 1u, 3u * lid + 2u);
    }
    if (lid == 0u) {
        tri_out.vertex_count = 3u * n;
        tri_out.primitive_count = n;
        atomicAdd(&records[pc.rec + group], 1u);
    }
}

// ---------------------------------------------------------------------------------------
// `extrude`, `cull`, `extrude_tasked`: the caster's tables, from word `pc.table` of `words`:
//   header: meshlets' offset, triangles' offset, edges' offset (relative to pc.table);
//   meshlets: (first triangle, triangles, first edge, edges) each;
//   triangles: three vertex ids each (into `positions`, absolute);
//   edges: (t0, t1, corner of a in t0) each: a = t0[c], b = t0[c + 1] (t1 walks b -> a).
// Records from word `pc.rec`: per meshlet, the workgroups that ran it; then per meshlet, the
// triangles it emitted; then per task workgroup, the mesh workgroups it launched.

const VOL_THREADS: u32 = 32u;
// The most a meshlet emits (volume.rs checks its meshlets against it, whatever the light): 5
// triangles (light and dark cap: 6 vertices, 2 triangles each) and 11 owned edges (a side
// quad: 4 vertices, 2 triangles each). Small on purpose: lavapipe 25.0.7 takes tens of
// seconds to compile a mesh stage with 192 vertices and 80 triangles (the Mesa shader cache
// off), time growing faster than the arrays.
const VOL_VERTICES: u32 = 80u;
const VOL_PRIMITIVES: u32 = 32u;

struct VolumeOutput {
    @builtin(vertex_count) vertex_count: u32,
    @builtin(primitive_count) primitive_count: u32,
    @builtin(vertices) vertices: array<Vertex, 80>,
    @builtin(primitives) primitives: array<Primitive, 32>,
}

var<workgroup> vol_out: VolumeOutput;
// Output slots taken so far (vertices, triangles).
var<workgroup> vol_taken: array<atomic<u32>, 2>;

fn table(i: u32) -> u32 {
    return words[pc.table + i];
}

fn tri_vertex(t: u32, k: u32) -> u32 {
    return table(table(1u) + 3u * t + k);
}

// Whether triangle `t` faces the light: (p1 - p0) x (p2 - p0) . (L - p0 L.w) > 0, in the
// stored vertex order (integer coordinates: exact in f32, as in the CPU model).
fn facing(t: u32) -> bool {
    let p0 = positions[tri_vertex(t, 0u)].xyz;
    let p1 = positions[tri_vertex(t, 1u)].xyz;
    let p2 = positions[tri_vertex(t, 2u)].xyz;
    let n = cross(p1 - p0, p2 - p0);
    return dot(n, pc.light.xyz - p0 * pc.light.w) > 0.0;
}

fn vol_take(nv: u32, np: u32) -> vec2<u32> {
    return vec2<u32>(atomicAdd(&vol_taken[0], nv), atomicAdd(&vol_taken[1], np));
}

fn vol_cap(t: u32) {
    if (!facing(t)) {
        return;
    }
    let s = vol_take(6u, 2u);
    for (var k = 0u; k < 3u; k = k + 1u) {
        let p = positions[tri_vertex(t, k)];
        vol_out.vertices[s.x + k].position = near(p);
        vol_out.vertices[s.x + 3u + k].position = far(p);
    }
    // the light cap as it is, the dark cap reversed
    vol_out.primitives[s.y].indices = vec3<u32>(s.x, s.x + 1u, s.x + 2u);
    vol_out.primitives[s.y + 1u].indices = vec3<u32>(s.x + 3u, s.x + 5u, s.x + 4u);
}

fn edge_word(e: u32, k: u32) -> u32 {
    return table(table(2u) + 3u * e + k);
}

fn vol_side(e: u32) {
    let t0 = edge_word(e, 0u);
    let f0 = facing(t0);
    if (f0 == facing(edge_word(e, 1u))) {
        return;
    }
    let c = edge_word(e, 2u);
    var a = positions[tri_vertex(t0, c)];
    var b = positions[tri_vertex(t0, (c + 1u) % 3u)];
    if (!f0) {
        // a -> b as in the light-facing triangle
        let x = a;
        a = b;
        b = x;
    }
    let s = vol_take(4u, 2u);
    // 0: b, 1: a, 2: a∞, 3: b∞ (extrude.wgsl's side quad)
    vol_out.vertices[s.x].position = near(b);
    vol_out.vertices[s.x + 1u].position = near(a);
    vol_out.vertices[s.x + 2u].position = far(a);
    vol_out.vertices[s.x + 3u].position = far(b);
    vol_out.primitives[s.y].indices = vec3<u32>(s.x, s.x + 1u, s.x + 2u);
    vol_out.primitives[s.y + 1u].indices = vec3<u32>(s.x, s.x + 2u, s.x + 3u);
}

// Meshlet `m`'s volume (`valid` false: a launched workgroup past the meshlets, which emits
// nothing).
fn extrude_meshlet(m: u32, valid: bool, lid: u32) {
    if (lid < 2u) {
        atomicStore(&vol_taken[lid], 0u);
    }
    workgroupBarrier();
    var tris = 0u;
    var edges = 0u;
    let base = table(0u) + 4u * m;
    if (valid) {
        tris = table(base + 1u);
        edges = table(base + 3u);
    }
    for (var i = lid; i < tris; i = i + VOL_THREADS) {
        vol_cap(table(base) + i);
    }
    for (var i = lid; i < edges; i = i + VOL_THREADS) {
        vol_side(table(base + 2u) + i);
    }
    workgroupBarrier();
    if (lid == 0u) {
        let nv = min(atomicLoad(&vol_taken[0]), VOL_VERTICES);
        let np = min(atomicLoad(&vol_taken[1]), VOL_PRIMITIVES);
        vol_out.vertex_count = nv;
        vol_out.primitive_count = np;
        if (valid) {
            atomicAdd(&records[pc.rec + m], 1u);
            atomicAdd(&records[pc.rec + pc.count + m], np);
        }
    }
}

@mesh(vol_out)
@workgroup_size(32)
fn extrude(@builtin(workgroup_id) wg: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>, @builtin(local_invocation_index) lid: u32) {
    // Workgroups past the meshlets (a 2D launch's last row) emit nothing.
    let m = linear_group(wg, nwg);
    extrude_meshlet(m, m < pc.count, lid);
}

// Meshlets a `cull` workgroup looks at (volume.rs's TASK_MESHLETS).
const TASK_MESHLETS: u32 = 4u;

struct Selected {
    count: u32,
    meshlet: array<u32, 4>,
}

var<task_payload> selected: Selected;
var<workgroup> kept: atomic<u32>;

// Whether meshlet `m` emits anything: a light-facing triangle, or an owned silhouette edge.
fn meshlet_emits(m: u32) -> bool {
    let base = table(0u) + 4u * m;
    for (var i = 0u; i < table(base + 1u); i = i + 1u) {
        if (facing(table(base) + i)) {
            return true;
        }
    }
    for (var i = 0u; i < table(base + 3u); i = i + 1u) {
        let e = table(base + 2u) + i;
        if (facing(edge_word(e, 0u)) != facing(edge_word(e, 1u))) {
            return true;
        }
    }
    return false;
}

@task
@payload(selected)
@workgroup_size(32)
fn cull(@builtin(workgroup_id) wg: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>, @builtin(local_invocation_index) lid: u32) -> @builtin(mesh_task_size) vec3<u32> {
    if (lid == 0u) {
        atomicStore(&kept, 0u);
    }
    workgroupBarrier();
    let j = linear_group(wg, nwg);
    let m = j * TASK_MESHLETS + lid;
    if (lid < TASK_MESHLETS && m < pc.count && meshlet_emits(m)) {
        let slot = atomicAdd(&kept, 1u);
        selected.meshlet[slot] = m;
    }
    workgroupBarrier();
    let n = atomicLoad(&kept);
    if (lid == 0u) {
        selected.count = n;
        atomicAdd(&records[pc.rec + 2u * pc.count + j], n);
    }
    workgroupBarrier();
    return vec3<u32>(n, 1u, 1u);
}

@mesh(vol_out)
@payload(selected)
@workgroup_size(32)
fn extrude_tasked(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) lid: u32) {
    extrude_meshlet(selected.meshlet[min(wg.x, selected.count - 1u)], true, lid);
}

// ---------------------------------------------------------------------------------------
// `groups`, `spawned`: one tile of TILE x TILE pixels a workgroup (two triangles in pixel
// coordinates through pc.mvp), and what the workgroup saw.

const TILE: f32 = 4.0;

struct QuadOutput {
    @builtin(vertex_count) vertex_count: u32,
    @builtin(primitive_count) primitive_count: u32,
    @builtin(vertices) vertices: array<Vertex, 4>,
    @builtin(primitives) primitives: array<Primitive, 2>,
}

var<workgroup> quad_out: QuadOutput;

// The tile at (tx, ty): corners 0 (x0, y0), 1 (x1, y0), 2 (x1, y1), 3 (x0, y1).
fn tile(tx: u32, ty: u32, lid: u32) {
    if (lid < 4u) {
        let x = (f32(tx) + select(0.0, 1.0, lid == 1u || lid == 2u)) * TILE;
        let y = (f32(ty) + select(0.0, 1.0, lid >= 2u)) * TILE;
        quad_out.vertices[lid].position = near(vec4<f32>(x, y, 0.5, 1.0));
    }
    if (lid == 0u) {
        quad_out.primitives[0].indices = vec3<u32>(0u, 2u, 1u);
        quad_out.primitives[1].indices = vec3<u32>(0u, 3u, 2u);
        quad_out.vertex_count = 4u;
        quad_out.primitive_count = 2u;
    }
}

// A workgroup id packed into one word: x in bits 0..16, y in 16..24, z in 24..32.
fn pack_id(v: vec3<u32>) -> u32 {
    return v.x | (v.y << 16u) | (v.z << 24u);
}

// `groups`: records from word pc.rec: a header (num_workgroups x, y, z as the largest any
// invocation saw; workgroups run; invocations run), then two words per workgroup of the
// launch (invocations that ran it; its packed workgroup_id + 1). Draws with F_NO_TILES emit
// nothing: the 65535-group draw only records. Workgroup (x, y, z) draws tile (x, y + ny z).
const GROUPS_HEADER: u32 = 5u;
const F_NO_TILES: u32 = 2u;

@mesh(quad_out)
@workgroup_size(4)
fn groups(@builtin(workgroup_id) wg: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>, @builtin(local_invocation_index) lid: u32) {
    let g = linear_group(wg, nwg);
    atomicMax(&records[pc.rec], nwg.x);
    atomicMax(&records[pc.rec + 1u], nwg.y);
    atomicMax(&records[pc.rec + 2u], nwg.z);
    atomicAdd(&records[pc.rec + 4u], 1u);
    let at = pc.rec + GROUPS_HEADER + 2u * g;
    atomicAdd(&records[at], 1u);
    atomicMax(&records[at + 1u], pack_id(wg) + 1u);
    if (lid == 0u) {
        atomicAdd(&records[pc.rec + 3u], 1u);
    }
    if ((pc.flags & F_NO_TILES) != 0u) {
        if (lid == 0u) {
            quad_out.vertex_count = 0u;
            quad_out.primitive_count = 0u;
        }
        return;
    }
    tile(wg.x, wg.y + nwg.y * wg.z, lid);
}

// `spawn` + `spawned`: task workgroup j (linear) launches (j % 4, 1 + j % 3, 1) mesh
// workgroups. Records from word pc.rec: per task workgroup, its invocations; then per task
// workgroup SPAWN_SLOTS slots of 4 words, one per mesh workgroup (x + nx * y): invocations
// that ran it, the payload's task word + 1, its num_workgroups packed, and the payload words
// that differed from what the task wrote.
const SPAWN_THREADS: u32 = 32u;
const SPAWN_SLOTS: u32 = 9u;

struct Spawn {
    task: u32,
    launch: vec3<u32>,
    value: array<u32, 32>,
}

var<task_payload> spawn_payload: Spawn;

fn spawn_value(j: u32, i: u32) -> u32 {
    return (j * 0x9e3779b9u) ^ (i * 0x85ebca6bu);
}

@task
@payload(spawn_payload)
@workgroup_size(32)
fn spawn(@builtin(workgroup_id) wg: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>, @builtin(local_invocation_index) lid: u32) -> @builtin(mesh_task_size) vec3<u32> {
    let j = linear_group(wg, nwg);
    let launch = vec3<u32>(j % 4u, 1u + j % 3u, 1u);
    spawn_payload.value[lid] = spawn_value(j, lid);
    if (lid == 0u) {
        spawn_payload.task = j;
        spawn_payload.launch = launch;
    }
    atomicAdd(&records[pc.rec + j], 1u);
    workgroupBarrier();
    return launch;
}

@mesh(quad_out)
@payload(spawn_payload)
@workgroup_size(4)
fn spawned(@builtin(workgroup_id) wg: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>, @builtin(local_invocation_index) lid: u32) {
    let j = spawn_payload.task;
    let slot = wg.x + nwg.x * wg.y;
    let at = pc.rec + pc.count + (j * SPAWN_SLOTS + slot) * 4u;
    atomicAdd(&records[at], 1u);
    atomicMax(&records[at + 1u], j + 1u);
    atomicMax(&records[at + 2u], pack_id(nwg));
    var bad = 0u;
    for (var i = lid; i < SPAWN_THREADS; i = i + 4u) {
        if (spawn_payload.value[i] != spawn_value(j, i)) {
            bad = bad + 1u;
        }
    }
    if (any(spawn_payload.launch != nwg)) {
        bad = bad + 1u;
    }
    atomicAdd(&records[at + 3u], bad);
    // the task's block of 3 x 3 tiles, tile (x, y) within it
    tile((j % 4u) * 3u + wg.x, (j / 4u) * 3u + wg.y, lid);
}
