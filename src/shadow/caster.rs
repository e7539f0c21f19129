//! Shadow casters prepared once at load: welded mesh, topology, and GPU chunks.
//!
//! Closed, consistently oriented 2-manifolds take the classic path (silhouette edges, one
//! closed volume). Every other mesh (open boundaries, edges shared by 3+ triangles,
//! inconsistent winding, duplicated or back-to-back faces) takes the multiplicity path of
//! Kim, Kim & Turk (2008): every triangle occludes from both sides, and the count at a point
//! is the number of caster triangles between it and the light (see `plan`).

use crate::error::{Error, Result};
use crate::geom::silhouette::FacePlanes;
use crate::geom::topology::Topology;
use crate::geom::{Aabb, Mesh};
use crate::scene::SceneMesh;
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
    pub fn path(&self) -> &'static str {
        match self {
            CasterKind::Manifold => "manifold",
            CasterKind::Multiplicity { .. } => "multiplicity",
        }
    }
}

/// A shadow caster: welded mesh, topology and chunks.
#[derive(Clone, Debug)]
pub struct Caster {
    pub name: String,
    /// `Some(t)` for a transparent caster: the RGB fraction of light one of its surfaces lets
    /// through, `(1 - opacity) * color`. Its volumes go to the light-intensity map, not the
    /// opaque counter.
    pub transmittance: Option<glam::Vec3>,
    pub kind: CasterKind,
    /// Multiplicity casters only (empty otherwise): for every welded triangle, the id of the
    /// group of triangles with exactly the same three welded vertices (any order, any
    /// winding: duplicates and back-to-back pairs), or `u32::MAX` when it has no twin.
    pub coincident: Vec<u32>,
    pub topology: Topology,
    /// Object-space plane of every welded triangle, for the per-light facing bits
    /// ([`FacePlanes::facing_packed`]); recompute with [`Caster::recompute_planes`] after
    /// changing the welded positions.
    pub planes: FacePlanes,
    pub chunks: Vec<Chunk>,
    /// For every welded triangle: (chunk, local triangle index).
    pub tri_chunk: Vec<(u32, u32)>,
    pub object_bounds: Aabb,
    pub transform: Mat4,
    pub inverse: Mat4,
    /// The transform mirrors (negative determinant): object-space orientation is reversed.
    pub mirrored: bool,
    pub triangle_count: usize,
    /// Largest chunk vertex count (apex included); `<= 128` means 8-bit indices everywhere.
    pub max_local_vertices: usize,
    /// True iff every chunk can use 8-bit indices.
    pub max_local_vertices_u8: bool,
}

impl Caster {
    /// A caster for a scene mesh. A transparent mesh (opacity < 1) always takes the
    /// multiplicity path, whose count is the number of surfaces crossed (Kim et al. 2008): each
    /// one attenuates the light by `(1 - opacity) * color`.
    pub fn from_scene_mesh(m: &SceneMesh) -> Result<Caster> {
        let mut c = Caster::new(&m.name, &m.mesh, m.transform)?;
        if m.opacity < 1.0 {
            if c.kind == CasterKind::Manifold {
                c.kind = CasterKind::Multiplicity {
                    reason: format!("transparent (opacity {}): every surface crossed attenuates the light", m.opacity),
                };
                c.coincident = coincident_groups(&c.topology.mesh);
            }
            c.transmittance = Some(((1.0 - m.opacity) * m.color).max(glam::Vec3::splat(TRANSMITTANCE_FLOOR)));
        }
        Ok(c)
    }

    pub fn new(name: &str, mesh: &Mesh, transform: Mat4) -> Result<Caster> {
        Caster::with_chunk_limit(name, mesh, transform, MAX_CHUNK_VERTICES)
    }

    /// `limit`: most vertices per chunk including the apex (2..=32768; tests use small ones).
    pub fn with_chunk_limit(name: &str, mesh: &Mesh, transform: Mat4, limit: usize) -> Result<Caster> {
        assert!((4..=MAX_CHUNK_VERTICES).contains(&limit));
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
        let apex = object_bounds.center();
        let (chunks, tri_chunk) = build_chunks(&topology.mesh, apex, limit);
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
            planes: FacePlanes::new(&topology.mesh),
            topology,
            chunks,
            tri_chunk,
            object_bounds,
            transform,
            inverse: transform.inverse(),
            mirrored: det < 0.0,
            max_local_vertices,
            max_local_vertices_u8: max_local_vertices <= 128,
        })
    }

    /// Recomputes the triangle planes from the welded mesh's current positions (deforming
    /// casters, after writing `topology.mesh.positions`).
    pub fn recompute_planes(&mut self) {
        self.planes.recompute(&self.topology.mesh);
    }

    pub fn is_manifold(&self) -> bool {
        self.kind == CasterKind::Manifold
    }

    pub fn mesh(&self) -> &Mesh {
        &self.topology.mesh
    }

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

/// Greedy chunking in triangle order (mesh order usually has good locality).
fn build_chunks(mesh: &Mesh, apex: Vec3, limit: usize) -> (Vec<Chunk>, Vec<(u32, u32)>) {
    let max_local = limit - 1; // room for the apex
    let mut chunks = Vec::new();
    let mut tri_chunk = vec![(0u32, 0u32); mesh.triangles.len()];
    // vertex -> (chunk stamp, local index)
    let mut stamp = vec![u32::MAX; mesh.positions.len()];
    let mut local = vec![0u16; mesh.positions.len()];
    let new_chunk = || Chunk { vertices: Vec::new(), local_tris: Vec::new(), tri_ids: Vec::new(), global_ids: Vec::new() };
    let mut cur = new_chunk();
    let finish = |mut c: Chunk, chunks: &mut Vec<Chunk>| {
        c.vertices.push(apex);
        c.global_ids.push(u32::MAX);
        chunks.push(c);
    };
    for (t, tri) in mesh.triangles.iter().enumerate() {
        let cid = chunks.len() as u32;
        let mut needed = 0;
        for (k, &v) in tri.iter().enumerate() {
            if stamp[v as usize] != cid && !tri[..k].contains(&v) {
                needed += 1;
            }
        }
        if cur.vertices.len() + needed > max_local {
            finish(std::mem::replace(&mut cur, new_chunk()), &mut chunks);
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
        tri_chunk[t] = (cid, cur.local_tris.len() as u32);
        cur.local_tris.push(lt);
        cur.tri_ids.push(t as u32);
    }
    if !cur.local_tris.is_empty() {
        finish(cur, &mut chunks);
    }
    (chunks, tri_chunk)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shadow::testmesh::{cube, uv_sphere};

    #[test]
    fn open_mesh_takes_multiplicity_path() {
        let mut m = cube(Vec3::ZERO, 1.0);
        m.triangles.pop();
        let c = Caster::new("boxy", &m, Mat4::IDENTITY).unwrap();
        assert_eq!(c.kind, CasterKind::Multiplicity { reason: "3 boundary edges (open mesh)".into() });
        assert_eq!(c.kind.path(), "multiplicity");
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
