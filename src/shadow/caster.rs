//! Shadow casters prepared once at load: welded mesh, topology, and GPU chunks.
//!
//! Closed, consistently oriented 2-manifolds take the classic path (silhouette edges, one
//! closed volume). Every other mesh (open boundaries, edges shared by 3+ triangles,
//! inconsistent winding, duplicated or back-to-back faces) takes the multiplicity path of
//! Kim, Kim & Turk (2008): every triangle occludes from both sides, and the count at a point
//! is the number of caster triangles between it and the light (see `plan`).

use crate::error::{Error, Result};
use crate::geom::silhouette::{EdgeScan, FacePlanes};
use crate::geom::topology::Topology;
use crate::geom::{Aabb, Mesh, TriangleOrder};
use crate::shadow::VolumePath;
use glam::{Mat4, Vec3};

/// Most vertices a chunk may hold INCLUDING its apex, so that `2n - 1` fits in a u16.
pub const MAX_CHUNK_VERTICES: usize = 32768;

/// Smallest per-surface transmittance: keeps 1/t and log(t) finite in the light-intensity map.
pub const TRANSMITTANCE_FLOOR: f32 = 1e-4;

/// A piece of a caster drawn with one dual-length vertex buffer: index `i` (`i < n`) is
/// `(vertices[i], 1)`, index `i + n` is `(vertices[i], 0)`, `n = vertices.len()`.
#[derive(Clone, Debug)]
pub struct Chunk {
    /// Object space, `n <= 32768`; the LAST vertex is the apex (object-space AABB centre of
    /// the whole caster), used by the dark-cap fan.
    pub vertices: Vec<Vec3>,
    /// The chunk's triangles in local indices (< n - 1).
    pub local_tris: Vec<[u16; 3]>,
    /// Global (welded-mesh) triangle id of each local triangle.
    pub tri_ids: Vec<u32>,
    /// Welded-mesh vertex id of each local vertex (`u32::MAX` for the apex).
    pub global_ids: Vec<u32>,
}

impl Chunk {
    /// `n`, the number of vertices (apex included); the dual-length buffer holds `2n`.
    pub fn n(&self) -> usize {
        self.vertices.len()
    }
    /// Index of the apex's w=1 copy (its w=0 copy is `apex() + n`).
    pub fn apex(&self) -> u16 {
        (self.vertices.len() - 1) as u16
    }
    /// When `n <= 128` every index (< 2n) fits in 8 bits.
    pub fn fits_u8(&self) -> bool {
        self.vertices.len() <= 128
    }
}

/// Which volume construction a caster takes.
#[derive(Clone, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum CasterKind {
    /// Closed, consistently oriented 2-manifold: silhouette edges of the facing bits.
    Manifold,
    /// Anything else: per-edge multiplicities, every triangle a two-sided occluder.
    Multiplicity {
        /// Why the mesh is not a closed manifold ([`Topology::describe_problem`]).
        reason: String,
    },
}

impl CasterKind {
    /// [`VolumePath::Manifold`] or [`VolumePath::Multiplicity`], as in the stats JSON and
    /// `umbrage info`.
    pub fn path(&self) -> VolumePath {
        match self {
            CasterKind::Manifold => VolumePath::Manifold,
            CasterKind::Multiplicity { .. } => VolumePath::Multiplicity,
        }
    }
}

/// One connected component of a caster's welded mesh (triangles sharing a vertex belong to
/// the same part), planned on its own: its own bounds, culling, case and path.
#[derive(Clone, Debug)]
pub struct Part {
    /// [`CasterKind::Manifold`] when this component alone is a closed, consistently oriented
    /// 2-manifold; transparent casters are one multiplicity part.
    pub kind: CasterKind,
    /// Welded triangle ids of the part, ascending.
    pub triangles: Vec<u32>,
    /// The part's chunks: `Caster::chunks[chunks]` (chunks never mix parts; their apex is the
    /// centre of the part's bounds).
    pub chunks: std::ops::Range<usize>,
    /// Object-space bounds of the part's vertices.
    pub object_bounds: Aabb,
    /// Ids of the part's undirected edges in [`Topology::edges`], ascending.
    pub edges: Vec<u32>,
    /// The part's manifold edges, ready for the per-light possible-silhouette scan of facing
    /// bits in the caster's scan order ([`Caster::planes`]); its edges and output keep the
    /// welded triangle ids. Each edge is tagged ([`EdgeScan::tags`], 8 bytes an edge) with its
    /// chunk and chunk-local ends, which the planner reads for a light's silhouette edges next
    /// to the scan's own data instead of in the chunk tables; a scan without tags (one built
    /// anew) is planned the same, from the tables.
    pub scan: EdgeScan,
}

/// A shadow caster: welded mesh, topology and chunks.
#[derive(Clone, Debug)]
pub struct Caster {
    /// The mesh's name, for messages and stats.
    pub name: String,
    /// `Some(t)` for a transparent caster: the RGB fraction of light one of its surfaces lets
    /// through, `(1 - opacity) * color`. Its volumes go to the light-intensity map, not the
    /// opaque counter.
    pub transmittance: Option<glam::Vec3>,
    /// Classic (closed manifold) or multiplicity path.
    pub kind: CasterKind,
    /// Multiplicity casters only (empty otherwise): for every welded triangle, the id of the
    /// group of triangles with exactly the same three welded vertices (any order, any
    /// winding: duplicates and back-to-back pairs), or `u32::MAX` when it has no twin.
    pub coincident: Vec<u32>,
    /// Welded mesh and its edge table (object space).
    pub topology: Topology,
    /// Object-space plane of every welded triangle, for the per-light facing bits
    /// ([`FacePlanes::facing_packed`]); recompute with [`Caster::recompute_planes`] after
    /// changing the welded positions.
    ///
    /// The planes and their packed bits are in the caster's **scan order**
    /// ([`FacePlanes::order`]), computed once at load: each part's triangles, part after part,
    /// in meshoptimizer's spatial order ([`TriangleOrder::spatial`]), so that facing blocks and
    /// edge word pairs are compact patches whatever the order of the caller's triangles. Only
    /// the silhouette structures (these planes, [`Part::scan`]) use it: look a welded
    /// triangle's bit up with [`FacePlanes::bit`]; everything else (mesh, chunks, triangle ids,
    /// plans) is in the caller's order.
    pub planes: FacePlanes,
    /// The welded mesh split into pieces of at most [`MAX_CHUNK_VERTICES`] vertices (never
    /// mixing parts).
    pub chunks: Vec<Chunk>,
    /// The connected components, in order of their first triangle (one part for a connected
    /// mesh, and for transparent casters).
    pub parts: Vec<Part>,
    /// For every welded triangle: (chunk, local triangle index).
    pub tri_chunk: Vec<(u32, u32)>,
    /// Bounding box of the welded mesh, object space.
    pub object_bounds: Aabb,
    /// Object -> world.
    pub transform: Mat4,
    /// World -> object (`transform.inverse()`).
    pub inverse: Mat4,
    /// The transform mirrors (negative determinant): object-space orientation is reversed.
    pub mirrored: bool,
    /// Triangles of the welded mesh.
    pub triangle_count: usize,
    /// Largest chunk vertex count (apex included); `<= 128` means 8-bit indices everywhere.
    pub max_local_vertices: usize,
    /// True iff every chunk can use 8-bit indices.
    pub max_local_vertices_u8: bool,
    /// The chunk vertex limit the caster was built with.
    chunk_limit: usize,
}

impl Caster {
    /// A caster for `mesh` placed by `transform` (object -> world): validates the mesh, welds it,
    /// classifies it (manifold or multiplicity) and splits it into chunks. Fails on an invalid
    /// mesh or a singular transform.
    pub fn new(name: &str, mesh: &Mesh, transform: Mat4) -> Result<Caster> {
        Caster::with_chunk_limit(name, mesh, transform, MAX_CHUNK_VERTICES)
    }

    /// `limit`: most vertices per chunk including the apex (4..=32768, clamped; tests use
    /// small ones).
    pub fn with_chunk_limit(name: &str, mesh: &Mesh, transform: Mat4, limit: usize) -> Result<Caster> {
        let limit = limit.clamp(4, MAX_CHUNK_VERTICES);
        mesh.validate(name)?;
        let topology = Topology::build(mesh);
        let kind = if topology.is_closed_manifold() {
            CasterKind::Manifold
        } else {
            CasterKind::Multiplicity { reason: topology.describe_problem() }
        };
        let det = transform.determinant();
        if !(det.is_finite() && det != 0.0) {
            return Err(Error::mesh(name, "transform is singular"));
        }
        let object_bounds = topology.mesh.bounds();
        let (parts, chunks, tri_chunk, order) = build_parts(&topology, limit, false, None);
        let kind = if parts.len() > 1 && parts.iter().all(|p| p.kind == CasterKind::Manifold) { CasterKind::Manifold } else { kind };
        let max_local_vertices = chunks.iter().map(|c| c.vertices.len()).max().unwrap_or(0);
        let coincident = match kind {
            CasterKind::Manifold => Vec::new(),
            CasterKind::Multiplicity { .. } => coincident_groups(&topology.mesh),
        };
        Ok(Caster {
            name: name.to_string(),
            transmittance: None,
            kind,
            coincident,
            triangle_count: topology.mesh.triangles.len(),
            planes: FacePlanes::with_order(&topology.mesh, order),
            topology,
            chunks,
            parts,
            tri_chunk,
            object_bounds,
            chunk_limit: limit,
            transform,
            inverse: transform.inverse(),
            mirrored: det < 0.0,
            max_local_vertices,
            max_local_vertices_u8: max_local_vertices <= 128,
        })
    }

    /// Puts the whole caster on the multiplicity path as ONE part (transparent casters, whose
    /// every surface attenuates the light; tests): rebuilds the parts and chunks (for a
    /// connected mesh the chunks stay the same) and the coincident groups.
    pub fn make_whole_multiplicity(&mut self, reason: String) {
        self.kind = CasterKind::Multiplicity { reason };
        let order = self.planes.order().clone();
        let (parts, chunks, tri_chunk, _) = build_parts(&self.topology, self.chunk_limit, true, Some(order));
        self.parts = parts;
        self.chunks = chunks;
        self.tri_chunk = tri_chunk;
        self.max_local_vertices = self.chunks.iter().map(|c| c.vertices.len()).max().unwrap_or(0);
        self.max_local_vertices_u8 = self.max_local_vertices <= 128;
        if self.coincident.len() != self.triangle_count {
            self.coincident = coincident_groups(&self.topology.mesh);
        }
    }

    /// Recomputes the triangle planes from the welded mesh's current positions (deforming
    /// casters, after writing `topology.mesh.positions`).
    pub fn recompute_planes(&mut self) {
        self.planes.recompute(&self.topology.mesh);
    }

    /// True iff the caster takes the classic closed-manifold path.
    pub fn is_manifold(&self) -> bool {
        self.kind == CasterKind::Manifold
    }

    /// The welded object-space mesh (what chunks and plans index).
    pub fn mesh(&self) -> &Mesh {
        &self.topology.mesh
    }

    /// World-space box of the object bounds' transformed corners (conservative).
    pub fn world_bounds(&self) -> Aabb {
        self.object_bounds.transformed(&self.transform)
    }
}

/// Groups of triangles with the same welded vertex set (see [`Caster::coincident`]).
fn coincident_groups(mesh: &Mesh) -> Vec<u32> {
    let mut keyed: Vec<([u32; 3], u32)> = mesh
        .triangles
        .iter()
        .enumerate()
        .map(|(t, tri)| {
            let mut k = *tri;
            k.sort_unstable();
            (k, t as u32)
        })
        .collect();
    keyed.sort_unstable();
    let mut out = vec![u32::MAX; mesh.triangles.len()];
    let mut group = 0u32;
    let mut i = 0;
    while i < keyed.len() {
        let mut j = i + 1;
        while j < keyed.len() && keyed[j].0 == keyed[i].0 {
            j += 1;
        }
        if j - i > 1 {
            for &(_, t) in &keyed[i..j] {
                out[t as usize] = group;
            }
            group += 1;
        }
        i = j;
    }
    out
}

/// What [`build_parts`] returns: the parts, the chunks, every triangle's (chunk, local index)
/// and the scan order.
type Built = (Vec<Part>, Vec<Chunk>, Vec<(u32, u32)>, TriangleOrder);

/// Connected components of the welded mesh (triangles sharing a vertex), each with its kind,
/// bounds, edges and chunks; `whole`: one multiplicity part with every triangle. The parts'
/// edge scans are for facing bits in `order`, or, when `None`, in the spatial order of each
/// part's triangles, part after part (returned).
fn build_parts(topo: &Topology, limit: usize, whole: bool, order: Option<TriangleOrder>) -> Built {
    let mesh = &topo.mesh;
    let nt = mesh.triangles.len();
    // union-find over vertices
    let mut parent: Vec<u32> = (0..mesh.positions.len() as u32).collect();
    fn find(parent: &mut [u32], mut x: u32) -> u32 {
        while parent[x as usize] != x {
            let p = parent[parent[x as usize] as usize];
            parent[x as usize] = p;
            x = p;
        }
        x
    }
    let mut comp_of_tri = vec![0u32; nt];
    let mut ncomp = 0usize;
    if !whole {
        for t in &mesh.triangles {
            let r0 = find(&mut parent, t[0]);
            for &v in &t[1..] {
                let r = find(&mut parent, v);
                if r != r0 {
                    parent[r as usize] = r0;
                }
            }
        }
        // components numbered in order of their first triangle
        let mut id = vec![u32::MAX; mesh.positions.len()];
        for (ti, t) in mesh.triangles.iter().enumerate() {
            let r = find(&mut parent, t[0]) as usize;
            if id[r] == u32::MAX {
                id[r] = ncomp as u32;
                ncomp += 1;
            }
            comp_of_tri[ti] = id[r];
        }
    } else {
        ncomp = usize::from(nt > 0);
    }
    let mut tris: Vec<Vec<u32>> = vec![Vec::new(); ncomp];
    for (t, &c) in comp_of_tri.iter().enumerate() {
        tris[c as usize].push(t as u32);
    }
    let order = order.unwrap_or_else(|| {
        let groups: Vec<&[u32]> = tris.iter().map(|t| t.as_slice()).collect();
        TriangleOrder::spatial(mesh, &groups)
    });
    // per-part edge problems (an edge's uses all lie in one part)
    let mut edges: Vec<Vec<u32>> = vec![Vec::new(); ncomp];
    let mut problems = vec![[0usize; 3]; ncomp]; // boundary, non-manifold, inconsistent
    for (ei, e) in topo.edges.iter().enumerate() {
        let uses = topo.edge_uses(ei);
        let Some(u0) = uses.first() else { continue };
        let c = comp_of_tri[u0.tri as usize] as usize;
        edges[c].push(ei as u32);
        match e.use_count {
            1 => problems[c][0] += 1,
            2 if uses[0].forward == uses[1].forward => problems[c][2] += 1,
            2 => {}
            _ => problems[c][1] += 1,
        }
    }
    let mut manifold: Vec<Vec<crate::geom::topology::ManifoldEdge>> = vec![Vec::new(); ncomp];
    for e in &topo.manifold_edges {
        manifold[comp_of_tri[e.t0 as usize] as usize].push(*e);
    }
    let mut chunks = Vec::new();
    let mut tri_chunk = vec![(0u32, 0u32); nt];
    let mut stamp = vec![u32::MAX; mesh.positions.len()];
    let mut local = vec![0u16; mesh.positions.len()];
    let mut parts = Vec::with_capacity(ncomp);
    for (((ptris, pedges), [b, nm, inc]), pman) in tris.into_iter().zip(edges).zip(problems).zip(manifold) {
        let bounds = if ncomp == 1 {
            mesh.bounds()
        } else {
            Aabb::from_points(ptris.iter().flat_map(|&t| mesh.triangles[t as usize].iter().map(|&v| &mesh.positions[v as usize])))
        };
        let kind = if whole {
            CasterKind::Multiplicity { reason: "whole caster".into() }
        } else if !pedges.is_empty() && b == 0 && nm == 0 && inc == 0 {
            CasterKind::Manifold
        } else {
            let mut why = Vec::new();
            if pedges.is_empty() {
                why.push("no edges".to_string());
            }
            if b > 0 {
                why.push(format!("{b} boundary edges (open mesh)"));
            }
            if nm > 0 {
                why.push(format!("{nm} edges shared by more than 2 triangles"));
            }
            if inc > 0 {
                why.push(format!("{inc} edges with inconsistently oriented triangles"));
            }
            CasterKind::Multiplicity { reason: why.join(", ") }
        };
        let first = chunks.len();
        let out = Chunking { chunks: &mut chunks, tri_chunk: &mut tri_chunk, stamp: &mut stamp, local: &mut local };
        build_chunks(mesh, &ptris, bounds.center(), limit, out);
        parts.push(Part {
            kind,
            triangles: ptris,
            chunks: first..chunks.len(),
            object_bounds: bounds,
            edges: pedges,
            scan: EdgeScan::with_order(pman, &order).with_tags(|e| side_tag(e, &chunks, &tri_chunk)),
        });
    }
    (parts, chunks, tri_chunk, order)
}

/// A manifold edge's [`EdgeScan`] tag for the planner (`plan::hit_ends`): its chunk (bits 0-31)
/// and the chunk-local indices of its ends `a` (bits 32-47) and `b` (48-63), the same in both
/// its triangles when they share a chunk; [`SIDE_TAG_SPLIT`] for an edge between two chunks.
fn side_tag(e: &crate::geom::topology::ManifoldEdge, chunks: &[Chunk], tri_chunk: &[(u32, u32)]) -> u64 {
    let ((c0, l0), (c1, _)) = (tri_chunk[e.t0 as usize], tri_chunk[e.t1 as usize]);
    if c0 != c1 {
        return SIDE_TAG_SPLIT;
    }
    // t0 runs a -> b from its corner c0
    let lt = chunks[c0 as usize].local_tris[l0 as usize];
    let (a, b) = (lt[e.c0 as usize % 3], lt[(e.c0 as usize + 1) % 3]);
    u64::from(c0) | u64::from(a) << 32 | u64::from(b) << 48
}

/// [`side_tag`] of an edge whose triangles lie in different chunks (read from the chunks'
/// tables instead).
pub(crate) const SIDE_TAG_SPLIT: u64 = u64::MAX;

/// Where [`build_chunks`] writes: the chunks, each triangle's (chunk, index in it), and the
/// per-vertex scratch shared across calls (the chunk a vertex was last added to, its local
/// index there).
struct Chunking<'a> {
    chunks: &'a mut Vec<Chunk>,
    tri_chunk: &'a mut [(u32, u32)],
    stamp: &'a mut [u32],
    local: &'a mut [u16],
}

/// Greedy chunking of the triangles `tris` in their order (mesh order usually has good
/// locality), appended to `out.chunks`, with the apex at `apex` and at most `limit` vertices
/// a chunk.
fn build_chunks(mesh: &Mesh, tris: &[u32], apex: Vec3, limit: usize, out: Chunking) {
    let Chunking { chunks, tri_chunk, stamp, local } = out;
    let max_local = limit - 1; // room for the apex
    let new_chunk = || Chunk { vertices: Vec::new(), local_tris: Vec::new(), tri_ids: Vec::new(), global_ids: Vec::new() };
    let mut cur = new_chunk();
    let finish = |mut c: Chunk, chunks: &mut Vec<Chunk>| {
        c.vertices.push(apex);
        c.global_ids.push(u32::MAX);
        chunks.push(c);
    };
    for &t in tris {
        let tri = mesh.triangles[t as usize];
        let cid = chunks.len() as u32;
        let mut needed = 0;
        for (k, &v) in tri.iter().enumerate() {
            if stamp[v as usize] != cid && !tri[..k].contains(&v) {
                needed += 1;
            }
        }
        if cur.vertices.len() + needed > max_local {
            finish(std::mem::replace(&mut cur, new_chunk()), chunks);
        }
        let cid = chunks.len() as u32;
        let mut lt = [0u16; 3];
        for (k, &v) in tri.iter().enumerate() {
            if stamp[v as usize] != cid {
                stamp[v as usize] = cid;
                local[v as usize] = cur.vertices.len() as u16;
                cur.vertices.push(mesh.positions[v as usize]);
                cur.global_ids.push(v);
            }
            lt[k] = local[v as usize];
        }
        tri_chunk[t as usize] = (cid, cur.local_tris.len() as u32);
        cur.local_tris.push(lt);
        cur.tri_ids.push(t);
    }
    if !cur.local_tris.is_empty() {
        finish(cur, chunks);
    }
}

impl Caster {
    /// Re-derives what depends on vertex positions after `topology.mesh.positions` changed in
    /// place (same topology, deforming casters): the bounds of the caster and of each part,
    /// every chunk's vertices (the apex at its part's new centre) and the triangle planes.
    pub fn refresh_after_positions_changed(&mut self) {
        self.object_bounds = self.topology.mesh.bounds();
        let mesh = &self.topology.mesh;
        let positions = &mesh.positions;
        let single = self.parts.len() == 1;
        for part in &mut self.parts {
            // As `build_parts`: a connected mesh's part has the whole mesh's bounds.
            let b = if single {
                mesh.bounds()
            } else {
                Aabb::from_points(part.triangles.iter().flat_map(|&t| mesh.triangles[t as usize].iter().map(|&v| &positions[v as usize])))
            };
            part.object_bounds = b;
            let apex = b.center();
            for ch in &mut self.chunks[part.chunks.clone()] {
                for (v, &g) in ch.vertices.iter_mut().zip(&ch.global_ids) {
                    *v = if g == u32::MAX { apex } else { positions[g as usize] };
                }
            }
        }
        self.recompute_planes();
    }

    /// Sets object -> world (finite and invertible; checked by the caller).
    pub fn set_transform(&mut self, transform: Mat4) {
        self.transform = transform;
        self.inverse = transform.inverse();
        self.mirrored = transform.determinant() < 0.0;
    }
}

impl Caster {
    /// This caster as a transparent one letting `transmittance` (RGB, per surface crossed)
    /// through: it takes the multiplicity path whatever its topology, since its count must be
    /// the number of surfaces crossed (Kim et al. 2008).
    pub fn into_transparent(mut self, transmittance: glam::Vec3) -> Caster {
        let reason = match &self.kind {
            CasterKind::Manifold => "transparent: every surface crossed attenuates the light".to_string(),
            CasterKind::Multiplicity { reason } => reason.clone(),
        };
        self.make_whole_multiplicity(reason);
        self.transmittance = Some(transmittance.max(glam::Vec3::splat(TRANSMITTANCE_FLOOR)));
        self
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::testmesh::{cube, uv_sphere};

    #[test]
    fn open_mesh_takes_multiplicity_path() {
        let mut m = cube(Vec3::ZERO, 1.0);
        m.triangles.pop();
        let c = Caster::new("boxy", &m, Mat4::IDENTITY).unwrap();
        assert_eq!(c.kind, CasterKind::Multiplicity { reason: "3 boundary edges (open mesh)".into() });
        assert_eq!(c.kind.path(), VolumePath::Multiplicity);
        assert!(c.coincident.iter().all(|&g| g == u32::MAX));
        check_chunks(&c);
        let closed = Caster::new("box", &cube(Vec3::ZERO, 1.0), Mat4::IDENTITY).unwrap();
        assert_eq!(closed.kind, CasterKind::Manifold);
        assert!(closed.is_manifold() && closed.coincident.is_empty());
        // duplicated and back-to-back faces are grouped
        let mut m = cube(Vec3::ZERO, 1.0);
        let t0 = m.triangles[0];
        m.triangles.push([t0[0], t0[2], t0[1]]);
        m.triangles.push(t0);
        let c = Caster::with_chunk_limit("dup", &m, Mat4::IDENTITY, 5).unwrap();
        assert!(matches!(&c.kind, CasterKind::Multiplicity { reason } if reason.contains("shared by more than 2")));
        let g = c.coincident[0];
        assert!(g != u32::MAX && c.coincident[12] == g && c.coincident[13] == g);
        assert_eq!(c.coincident.iter().filter(|&&x| x != u32::MAX).count(), 3);
        check_chunks(&c);
        // still rejected: empty meshes and singular transforms
        assert!(Caster::new("e", &Mesh::default(), Mat4::IDENTITY).is_err());
        assert!(Caster::new("s", &cube(Vec3::ZERO, 1.0), Mat4::from_scale(Vec3::new(1.0, 0.0, 1.0))).is_err());
    }

    fn check_chunks(c: &Caster) {
        let mut seen = vec![0u32; c.triangle_count];
        for (ci, ch) in c.chunks.iter().enumerate() {
            assert!(ch.vertices.len() <= MAX_CHUNK_VERTICES);
            assert_eq!(*ch.vertices.last().unwrap(), c.object_bounds.center());
            assert_eq!(ch.vertices.len(), ch.global_ids.len());
            for (li, (lt, &g)) in ch.local_tris.iter().zip(&ch.tri_ids).enumerate() {
                seen[g as usize] += 1;
                assert_eq!(c.tri_chunk[g as usize], (ci as u32, li as u32));
                let gt = c.mesh().triangles[g as usize];
                for k in 0..3 {
                    assert!((lt[k] as usize) < ch.vertices.len() - 1);
                    assert_eq!(ch.global_ids[lt[k] as usize], gt[k]);
                    assert_eq!(ch.vertices[lt[k] as usize], c.mesh().positions[gt[k] as usize]);
                }
            }
        }
        assert!(seen.iter().all(|&s| s == 1));
    }

    #[test]
    fn chunks_70k_vertices() {
        let m = uv_sphere(1.0, 350, 202); // 350 * 201 + 2 = 70352 vertices
        assert!(m.positions.len() > 70000);
        let c = Caster::new("sphere", &m, Mat4::IDENTITY).unwrap();
        assert!(c.chunks.len() >= 3);
        assert!(c.chunks.iter().all(|ch| ch.vertices.len() <= 32768 && ch.vertices.len() < 32769));
        check_chunks(&c);
        assert!(!c.max_local_vertices_u8);
    }

    #[test]
    fn small_chunks() {
        let c = Caster::with_chunk_limit("s", &uv_sphere(1.0, 20, 10), Mat4::IDENTITY, 40).unwrap();
        assert!(c.chunks.len() > 3);
        check_chunks(&c);
        assert!(c.max_local_vertices_u8 && c.chunks.iter().all(|c| c.fits_u8()));
    }
}
