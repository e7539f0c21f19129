// Mesh-shader extrusion (`--method mesh`, `Technique::Mesh`): one workgroup per meshlet of a
// caster part (`shadow::meshlet`), one draw (`vkCmdDrawMeshTasksEXT`) per (light, caster part,
// what is drawn). No index buffer and no vertex buffer: the workgroup reads the caster's
// static tables in the compute pass's arena and the facing bits that the compute pass's
// `facing` and `exact` stages (`shaders/silhouette.wgsl`) wrote for this light, bit for bit
// the CPU's.
//
// With `taskShader` (and `PassToggles::mesh_task`), a task stage (`cull`, a meshlet a thread,
// 64 a workgroup) runs first and launches the mesh workgroups (`extrude_culled`) of only the
// meshlets that emit something: a meshlet whose normal cone and bounding sphere prove that
// every triangle it reads faces the light strictly the same way (`geom::cone::same_facing`,
// conservative) has no silhouette edge, and its faces are all of one facing; the others are
// decided from the facing bits themselves (an owned edge whose two bits differ, a triangle of
// the wanted facing). So the same meshlets emit the same triangles as without the task stage
// (`extrude`, every meshlet a workgroup): the cull only drops workgroups that emit nothing.
//
// What a draw emits (`pc.flags`, mode in bits 0..2), with exactly the CPU's triangles and
// windings (`shadow::plan::emit`):
// * MODE_SIDES, one owned edge a thread: an edge whose two triangles' bits differ is a
//   possible silhouette edge. a -> b as in the light-facing triangle: point light
//   (b, a, a∞), (b, a∞, b∞); directional (b, a, a∞); with McGuire's fan dark cap (F_FAN) also
//   (apex∞, b∞, a∞). Each edge is owned by exactly one meshlet, and both of its triangles' bits
//   are read from the same words by whichever meshlet owns it: the volume is closed.
// * MODE_DARK, one triangle a thread: the dark cap of front faces (F_WANT set: light-facing
//   triangles' w = 0 copies reversed) or of back faces (the others' w = 0 copies as they are).
// * MODE_LIGHT, one triangle a thread: the light cap, light-facing triangles as they are (front
//   formulation, F_WANT set) or the others reversed (back formulation).
//
// Vertices are computed exactly as shadow.vert computes them from the dual-length vertex
// buffer (same f32 inputs, same expressions): a w = 1 vertex is mvp * (p, 1); a w = 0 vertex
// is mvp * (p * L.w - L.xyz, 0), moved off clip w = 0 as shadow.vert moves it. So the far
// vertices are the cap vertices' expressions, and every triangle is the CPU path's, vertex for
// vertex. No per-primitive outputs (llvmpipe before Mesa 26.2.3 mishandles them, wgpu #8727).
//
// The output budget (`shadow::meshlet`): at most 51 owned edges x 5 vertices / 3 triangles, or
// 64 triangles x 3 vertices / 1 triangle: 255 vertices, 153 triangles.
//
// Statistics: the workgroup's side, dark-cap and light-cap triangles and silhouette edges
// are summed in workgroup atomics, then added once to the draw's counters; then the meshlets
// the draw covered and the mesh workgroups that ran (words 4 and 5).
enable wgpu_mesh_shader;

struct Push {
    mvp: mat4x4<f32>,
    // The light in the caster's object space (w = 1 point, w = 0 directional).
    light: vec4<f32>,
    // Float counter: x = the sign a front face contributes (count.frag reads it).
    color: vec4<f32>,
    // The draw's first meshlet in the arena's meshlet table, and how many.
    meshlet_base: u32,
    meshlets: u32,
    // The caster's first element in the arena's triangle and position tables.
    tri_base: u32,
    pos_base: u32,
    // Word offset of the (light, caster) pair's facing bits.
    fac_base: u32,
    flags: u32,
    // The part's apex (the fan's common vertex) in the position table (absolute).
    apex: u32,
    // Word offset of the draw's four counters (sides, dark cap, light cap, edges).
    stat: u32,
}

struct Tri {
    // welded vertex ids (relative to the caster's first position)
    g: vec4<u32>,
    // chunk-local corners and chunk (unused here)
    l: vec4<u32>,
}

// One row of the meshlet table (`pass::mesh::meshlet_rows`, `shadow::meshlet::MeshletBounds`).
struct Meshlet {
    // (first triangle, triangles, first edge, edges), absolute in the two tables below
    range: vec4<u32>,
    // a sphere about every vertex of its triangles and its owned edges' triangles: centre, radius
    sphere: vec4<f32>,
    // the normal cones (axis, cosine of the half-angle) of its owned edges' triangles and of
    // its own triangles (cos 0: decides nothing)
    sides: vec4<f32>,
    faces: vec4<f32>,
}

@group(0) @binding(0) var<storage, read> positions: array<vec4<f32>>;
@group(0) @binding(1) var<storage, read> tris: array<Tri>;
@group(0) @binding(2) var<storage, read> meshlets: array<Meshlet>;
// welded triangle ids (relative to the caster's first triangle)
@group(0) @binding(3) var<storage, read> meshlet_tris: array<u32>;
// (t0, t1, c0 | c1 << 8, 0): t0 walks a -> b from corner c0, t1 walks b -> a from corner c1
@group(0) @binding(4) var<storage, read> meshlet_edges: array<vec4<u32>>;
@group(0) @binding(5) var<storage, read> facing_bits: array<u32>;
@group(0) @binding(6) var<storage, read_write> counts: array<atomic<u32>>;

var<immediate> pc: Push;

const MODE_SIDES: u32 = 0u;
const MODE_DARK: u32 = 1u;
const MODE_LIGHT: u32 = 2u;
const F_DIRECTIONAL: u32 = 4u;
const F_FAN: u32 = 8u;
const F_WANT: u32 = 16u;

// Meshlets one task workgroup decides (a thread each).
const TASK_GROUP: u32 = 64u;
// `geom::cone::TEST_MARGIN`: 2^-16.
const TEST_MARGIN: f32 = 1.52587890625e-5;
// The counters' words: the meshlets the draws covered, the mesh workgroups that ran.
const C_MESHLETS: u32 = 4u;
const C_RAN: u32 = 5u;

const MAX_VERTICES: u32 = 255u;
const MAX_PRIMITIVES: u32 = 153u;

struct Vertex {
    @builtin(position) position: vec4<f32>,
}

struct Primitive {
    @builtin(triangle_indices) indices: vec3<u32>,
}

struct MeshOutput {
    @builtin(vertex_count) vertex_count: u32,
    @builtin(primitive_count) primitive_count: u32,
    @builtin(vertices) vertices: array<Vertex, 255>,
    @builtin(primitives) primitives: array<Primitive, 153>,
}

var<workgroup> mesh_out: MeshOutput;
// Output slots taken so far, and the workgroup's statistics (sides, dark, light, edges).
var<workgroup> taken: array<atomic<u32>, 2>;
var<workgroup> tally: array<atomic<u32>, 4>;

// The task stage's launch list: the meshlets (relative to `pc.meshlet_base`) whose mesh
// workgroups run, in order.
struct Payload {
    ids: array<u32, 64>,
}
var<task_payload> payload: Payload;
// The task workgroup's verdicts (1: the meshlet emits something) and how many it launches.
var<workgroup> keep: array<u32, 64>;
var<workgroup> kept: u32;

fn facing(t: u32) -> bool {
    return ((facing_bits[pc.fac_base + (t >> 5u)] >> (t & 31u)) & 1u) != 0u;
}

fn corner(g: vec4<u32>, k: u32) -> u32 {
    if (k == 0u) {
        return g.x;
    }
    if (k == 1u) {
        return g.y;
    }
    return g.z;
}

// shadow.vert's position of welded vertex `v`'s w = 1 copy.
fn near(v: u32) -> vec4<f32> {
    // (w as stored, 1.0: the multiply by it is shadow.vert's, not folded away)
    let p = positions[v];
    return pc.mvp * p;
}

// shadow.vert's position of the w = 0 copy of the vertex at `index` of the position table.
fn far(index: u32) -> vec4<f32> {
    let p = positions[index];
    var c = pc.mvp * vec4<f32>(p.xyz * pc.light.w - pc.light.xyz, 0.0);
    if (c.w == 0.0) {
        c.w = max(max(abs(c.x), abs(c.y)), abs(c.z)) * 8.6736174e-19;
    }
    return c;
}

// Takes `nv` vertex and `np` primitive slots; returns the first of each.
fn take(nv: u32, np: u32) -> vec2<u32> {
    return vec2<u32>(atomicAdd(&taken[0], nv), atomicAdd(&taken[1], np));
}

fn side(e: vec4<u32>) {
    let f0 = facing(e.x);
    if (f0 == facing(e.y)) {
        return;
    }
    // a -> b as in the light-facing triangle
    var t = e.x;
    var k = e.z & 0xffu;
    if (!f0) {
        t = e.y;
        k = (e.z >> 8u) & 0xffu;
    }
    let g = tris[pc.tri_base + t].g;
    let a = pc.pos_base + corner(g, k);
    let b = pc.pos_base + corner(g, (k + 1u) % 3u);
    atomicAdd(&tally[3], 1u);
    if ((pc.flags & F_DIRECTIONAL) != 0u) {
        let s = take(3u, 1u);
        mesh_out.vertices[s.x].position = near(b);
        mesh_out.vertices[s.x + 1u].position = near(a);
        mesh_out.vertices[s.x + 2u].position = far(a);
        mesh_out.primitives[s.y].indices = vec3<u32>(s.x, s.x + 1u, s.x + 2u);
        atomicAdd(&tally[0], 1u);
        return;
    }
    let fan = (pc.flags & F_FAN) != 0u;
    let s = take(select(4u, 5u, fan), select(2u, 3u, fan));
    // 0: b, 1: a, 2: a∞, 3: b∞
    mesh_out.vertices[s.x].position = near(b);
    mesh_out.vertices[s.x + 1u].position = near(a);
    mesh_out.vertices[s.x + 2u].position = far(a);
    mesh_out.vertices[s.x + 3u].position = far(b);
    mesh_out.primitives[s.y].indices = vec3<u32>(s.x, s.x + 1u, s.x + 2u);
    mesh_out.primitives[s.y + 1u].indices = vec3<u32>(s.x, s.x + 2u, s.x + 3u);
    atomicAdd(&tally[0], 2u);
    if (fan) {
        mesh_out.vertices[s.x + 4u].position = far(pc.apex);
        mesh_out.primitives[s.y + 2u].indices = vec3<u32>(s.x + 4u, s.x + 3u, s.x + 2u);
        atomicAdd(&tally[1], 1u);
    }
}

fn face(t: u32, mode: u32) {
    let want = (pc.flags & F_WANT) != 0u;
    if (facing(t) != want) {
        return;
    }
    let g = tris[pc.tri_base + t].g;
    let v = vec3<u32>(pc.pos_base + g.x, pc.pos_base + g.y, pc.pos_base + g.z);
    let s = take(3u, 1u);
    if (mode == MODE_DARK) {
        mesh_out.vertices[s.x].position = far(v.x);
        mesh_out.vertices[s.x + 1u].position = far(v.y);
        mesh_out.vertices[s.x + 2u].position = far(v.z);
        atomicAdd(&tally[1], 1u);
    } else {
        mesh_out.vertices[s.x].position = near(v.x);
        mesh_out.vertices[s.x + 1u].position = near(v.y);
        mesh_out.vertices[s.x + 2u].position = near(v.z);
        atomicAdd(&tally[2], 1u);
    }
    // front faces' dark cap reversed, back faces' as they are; the light cap of the front
    // formulation as it is, the back formulation's reversed
    if ((mode == MODE_DARK) == want) {
        mesh_out.primitives[s.y].indices = vec3<u32>(s.x, s.x + 2u, s.x + 1u);
    } else {
        mesh_out.primitives[s.y].indices = vec3<u32>(s.x, s.x + 1u, s.x + 2u);
    }
}

// Whether every triangle the cone `cone` and the sphere `sphere` bound faces the light
// strictly the same way (`geom::cone::same_facing`, the same f32 arithmetic; its margin covers
// this evaluation's rounding). NaN or infinity anywhere: false.
fn same_facing(cone: vec4<f32>, sphere: vec4<f32>) -> bool {
    let l = pc.light;
    let k = select(0.0, 1.0, l.w != 0.0);
    let v = l.xyz - sphere.xyz * k;
    let s = dot(cone.xyz, v);
    let q = length(cross(cone.xyz, v));
    let sn = sqrt(max(1.0 - cone.w * cone.w, 0.0)) * (1.0 + 1.0 / 1048576.0);
    let m = k * sphere.w + TEST_MARGIN * (length(l.xyz) + k * (length(sphere.xyz) + sphere.w));
    return cone.w * s - sn * q > m || cone.w * s + sn * q < -m;
}

// Whether meshlet `m` emits anything in this draw: exactly the mesh stage's decision (the cone
// only skips reading the bits where it proves the answer).
fn emits(m: Meshlet) -> bool {
    if ((pc.flags & 3u) == MODE_SIDES) {
        if (m.range.w == 0u || same_facing(m.sides, m.sphere)) {
            return false;
        }
        for (var i = 0u; i < m.range.w; i = i + 1u) {
            let e = meshlet_edges[m.range.z + i];
            if (facing(e.x) != facing(e.y)) {
                return true;
            }
        }
        return false;
    }
    let want = (pc.flags & F_WANT) != 0u;
    if (same_facing(m.faces, m.sphere)) {
        // every triangle faces one way: the first one's bit is all of theirs
        return facing(meshlet_tris[m.range.x]) == want;
    }
    for (var i = 0u; i < m.range.y; i = i + 1u) {
        if (facing(meshlet_tris[m.range.x + i]) == want) {
            return true;
        }
    }
    return false;
}

// The workgroup of meshlet `index` (absolute in the meshlet table).
fn extrude_meshlet(index: u32, lid: u32) {
    if (lid < 2u) {
        atomicStore(&taken[lid], 0u);
    }
    if (lid < 4u) {
        atomicStore(&tally[lid], 0u);
    }
    workgroupBarrier();
    let m = meshlets[index].range;
    let mode = pc.flags & 3u;
    if (mode == MODE_SIDES) {
        if (lid < m.w) {
            side(meshlet_edges[m.z + lid]);
        }
    } else if (lid < m.y) {
        face(meshlet_tris[m.x + lid], mode);
    }
    workgroupBarrier();
    if (lid == 0u) {
        mesh_out.vertex_count = min(atomicLoad(&taken[0]), MAX_VERTICES);
        mesh_out.primitive_count = min(atomicLoad(&taken[1]), MAX_PRIMITIVES);
        for (var k = 0u; k < 4u; k = k + 1u) {
            let n = atomicLoad(&tally[k]);
            if (n != 0u) {
                atomicAdd(&counts[pc.stat + k], n);
            }
        }
    }
}

// Without a task stage: every meshlet of the draw a workgroup.
@mesh(mesh_out)
@workgroup_size(64)
fn extrude(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) lid: u32) {
    extrude_meshlet(pc.meshlet_base + wg.x, lid);
    if (lid == 0u) {
        atomicAdd(&counts[pc.stat + C_MESHLETS], 1u);
        atomicAdd(&counts[pc.stat + C_RAN], 1u);
    }
}

// The task stage: TASK_GROUP meshlets a workgroup, a thread each; launches the mesh
// workgroups of those that emit something, in order.
@task
@payload(payload)
@workgroup_size(64)
fn cull(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) lid: u32) -> @builtin(mesh_task_size) vec3<u32> {
    let first = wg.x * TASK_GROUP;
    var k = 0u;
    if (first + lid < pc.meshlets && emits(meshlets[pc.meshlet_base + first + lid])) {
        k = 1u;
    }
    keep[lid] = k;
    workgroupBarrier();
    if (lid == 0u) {
        var n = 0u;
        for (var j = 0u; j < TASK_GROUP; j = j + 1u) {
            if (keep[j] != 0u) {
                payload.ids[n] = first + j;
                n = n + 1u;
            }
        }
        kept = n;
        atomicAdd(&counts[pc.stat + C_MESHLETS], min(pc.meshlets - first, TASK_GROUP));
        if (n != 0u) {
            atomicAdd(&counts[pc.stat + C_RAN], n);
        }
    }
    let n = workgroupUniformLoad(&kept);
    return vec3<u32>(n, 1u, 1u);
}

// After the task stage: the launched meshlets, one workgroup each.
@mesh(mesh_out)
@payload(payload)
@workgroup_size(64)
fn extrude_culled(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) lid: u32) {
    extrude_meshlet(pc.meshlet_base + payload.ids[wg.x], lid);
}
