//! Meshlets for mesh-shader extrusion ([`Technique::Mesh`](crate::pass::Technique::Mesh)):
//! built once per caster, for each of its closed manifold parts.
//!
//! A meshlet is a patch of at most [`MAX_MESHLET_TRIANGLES`] edge-connected triangles of one
//! part, and the edges it **owns**: every manifold edge of the part is owned by exactly one
//! meshlet, the one its first triangle (in the build's breadth-first order) went to, so it is
//! one of the meshlets holding a triangle of the edge. A mesh-shader workgroup draws one
//! meshlet: the side quad (and fan dark-cap triangle) of each owned edge whose two triangles'
//! facing bits differ, or the face caps of its triangles. Since the facing bits are one per
//! triangle, read by every meshlet alike, two meshlets sharing an edge agree on it bit for bit,
//! and since each edge is drawn by its owner only, each silhouette edge is extruded exactly
//! once: the volume is closed by construction.
//!
//! The limits keep one workgroup's output within the smallest budget `VK_EXT_mesh_shader`
//! guarantees (256 vertices, 256 primitives; Mesa lavapipe 25.0.7 has exactly that): an owned
//! edge emits at most 5 vertices and 3 triangles (point light, side quad plus fan triangle),
//! a triangle at most 3 vertices and 1 triangle (a face cap), so [`MAX_MESHLET_EDGES`] = 51
//! edges make 255 vertices and 153 triangles, and 64 triangles 192 vertices.
//!
//! Parts that are not closed 2-manifolds (open, non-manifold, inconsistently oriented) get no
//! meshlets: they keep the CPU's multiplicity path (Kim et al. 2008), part by part.

use super::caster::{Caster, CasterKind};
use crate::geom::topology::ManifoldEdge;
use std::collections::VecDeque;
use std::ops::Range;

/// Most triangles of one meshlet (a workgroup's threads, one triangle each for the caps).
pub const MAX_MESHLET_TRIANGLES: usize = 64;
/// Most edges one meshlet owns (5 output vertices and 3 triangles each at most).
pub const MAX_MESHLET_EDGES: usize = 51;
/// Output vertices one meshlet's workgroup may write: `max(5 · 51, 3 · 64)`.
pub const MESHLET_OUTPUT_VERTICES: usize = 255;
/// Output triangles one meshlet's workgroup may write: `max(3 · 51, 64)`.
pub const MESHLET_OUTPUT_PRIMITIVES: usize = 153;

/// One meshlet: ranges into [`Meshlets::triangles`] and [`Meshlets::edges`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Meshlet {
    /// First entry of its triangles in [`Meshlets::triangles`].
    pub first_triangle: u32,
    /// Its triangles (1..=[`MAX_MESHLET_TRIANGLES`]).
    pub triangle_count: u32,
    /// First entry of its owned edges in [`Meshlets::edges`].
    pub first_edge: u32,
    /// Edges it owns (0..=[`MAX_MESHLET_EDGES`]).
    pub edge_count: u32,
}

impl Meshlet {
    /// Its range in [`Meshlets::triangles`].
    pub fn triangles(&self) -> Range<usize> {
        self.first_triangle as usize..(self.first_triangle + self.triangle_count) as usize
    }
    /// Its range in [`Meshlets::edges`].
    pub fn edges(&self) -> Range<usize> {
        self.first_edge as usize..(self.first_edge + self.edge_count) as usize
    }
}

/// A caster's meshlets, part by part.
#[derive(Clone, Debug, Default)]
pub struct Meshlets {
    /// Every meshlet, part after part.
    pub meshlets: Vec<Meshlet>,
    /// Welded triangle ids, meshlet after meshlet.
    pub triangles: Vec<u32>,
    /// The owned edges, meshlet after meshlet (`t0` walks `a -> b` at corner `c0`, `t1` walks
    /// `b -> a` at corner `c1`, as in the caster's topology).
    pub edges: Vec<ManifoldEdge>,
    /// For each part of the caster ([`Caster::parts`]), its meshlets' range in
    /// [`meshlets`](Self::meshlets): empty for the parts on the multiplicity path.
    pub parts: Vec<Range<u32>>,
}

impl Meshlets {
    /// The meshlets of every closed manifold part of `caster` (none for a caster on the
    /// multiplicity path as a whole: transparent casters, one-part non-manifold meshes).
    pub fn build(caster: &Caster) -> Meshlets {
        let mut out = Meshlets::default();
        let whole_multiplicity = caster.kind != CasterKind::Manifold && caster.parts.len() == 1;
        // Scratch over welded triangles: where a triangle went (`UNASSIGNED` before), and
        // its edges (indices into the part's edge list, up to three).
        let n = caster.triangle_count;
        let mut assigned = vec![UNASSIGNED; n];
        let mut tri_edges: Vec<[u32; 3]> = vec![[NO_EDGE; 3]; n];
        let mut queued = vec![false; n];
        for part in &caster.parts {
            let start = out.meshlets.len() as u32;
            if part.kind == CasterKind::Manifold && !whole_multiplicity {
                let scratch = Scratch { assigned: &mut assigned, tri_edges: &mut tri_edges, queued: &mut queued };
                build_part(part, scratch, &mut out);
            }
            out.parts.push(start..out.meshlets.len() as u32);
        }
        out
    }
}

const UNASSIGNED: u32 = u32::MAX;
const NO_EDGE: u32 = u32::MAX;

/// Per welded triangle, shared by the parts (each part touches only its own triangles): the
/// meshlet it went to (`UNASSIGNED` before), its edges (indices into its part's edge list),
/// whether the breadth-first walk reached it.
struct Scratch<'a> {
    assigned: &'a mut [u32],
    tri_edges: &'a mut [[u32; 3]],
    queued: &'a mut [bool],
}

/// Greedy meshlets of one closed manifold part: triangles in breadth-first order over edge
/// adjacency (restarting at the part's next unvisited triangle), a new meshlet whenever the
/// next triangle would exceed either limit. A triangle's edges whose other triangle is not
/// assigned yet become its meshlet's (each edge is thus owned once, by the meshlet of the
/// first of its two triangles).
fn build_part(part: &super::caster::Part, scratch: Scratch, out: &mut Meshlets) {
    let Scratch { assigned, tri_edges, queued } = scratch;
    let edges = part.scan.edges();
    for (i, e) in edges.iter().enumerate() {
        for t in [e.t0, e.t1] {
            if let Some(slot) = tri_edges[t as usize].iter_mut().find(|s| **s == NO_EDGE) {
                *slot = i as u32;
            }
        }
    }
    let other = |e: &ManifoldEdge, t: u32| if e.t0 == t { e.t1 } else { e.t0 };
    let mut current = Meshlet { first_triangle: out.triangles.len() as u32, first_edge: out.edges.len() as u32, ..Meshlet::default() };
    let mut queue = VecDeque::new();
    for &seed in &part.triangles {
        if queued[seed as usize] {
            continue;
        }
        queued[seed as usize] = true;
        queue.push_back(seed);
        while let Some(t) = queue.pop_front() {
            let new_edges: Vec<u32> = tri_edges[t as usize]
                .iter()
                .filter(|&&i| i != NO_EDGE && assigned[other(&edges[i as usize], t) as usize] == UNASSIGNED)
                .copied()
                .collect();
            if current.triangle_count as usize + 1 > MAX_MESHLET_TRIANGLES
                || current.edge_count as usize + new_edges.len() > MAX_MESHLET_EDGES
            {
                out.meshlets.push(current);
                current = Meshlet { first_triangle: out.triangles.len() as u32, first_edge: out.edges.len() as u32, ..Meshlet::default() };
            }
            assigned[t as usize] = out.meshlets.len() as u32;
            out.triangles.push(t);
            current.triangle_count += 1;
            for &i in &new_edges {
                out.edges.push(edges[i as usize]);
            }
            current.edge_count += new_edges.len() as u32;
            for &i in &tri_edges[t as usize] {
                if i == NO_EDGE {
                    continue;
                }
                let u = other(&edges[i as usize], t);
                if !queued[u as usize] {
                    queued[u as usize] = true;
                    queue.push_back(u);
                }
            }
        }
    }
    if current.triangle_count > 0 {
        out.meshlets.push(current);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::testmesh::{cube, torus, uv_sphere};
    use crate::geom::Mesh;
    use glam::{Mat4, Vec3};

    /// Appends `b` to `a` (a mesh of several parts).
    fn merged(a: &Mesh, b: &Mesh) -> Mesh {
        let n = a.positions.len() as u32;
        let mut positions = a.positions.clone();
        positions.extend(&b.positions);
        let mut triangles = a.triangles.clone();
        triangles.extend(b.triangles.iter().map(|t| t.map(|v| v + n)));
        Mesh::new(positions, triangles)
    }

    /// The invariants: limits, every part triangle in exactly one meshlet of its part, every
    /// edge of a manifold part owned by exactly one meshlet, one holding a triangle of it.
    fn check(c: &Caster, m: &Meshlets) {
        assert_eq!(m.parts.len(), c.parts.len());
        let mut meshlet_of = vec![u32::MAX; c.triangle_count];
        for (k, ml) in m.meshlets.iter().enumerate() {
            assert!(ml.triangle_count >= 1 && ml.triangle_count as usize <= MAX_MESHLET_TRIANGLES, "{ml:?}");
            assert!(ml.edge_count as usize <= MAX_MESHLET_EDGES, "{ml:?}");
            // the output budget of one workgroup
            assert!(5 * ml.edge_count as usize <= MESHLET_OUTPUT_VERTICES && 3 * ml.triangle_count as usize <= MESHLET_OUTPUT_VERTICES);
            assert!(3 * ml.edge_count as usize <= MESHLET_OUTPUT_PRIMITIVES && ml.triangle_count as usize <= MESHLET_OUTPUT_PRIMITIVES);
            for &t in &m.triangles[ml.triangles()] {
                assert_eq!(meshlet_of[t as usize], u32::MAX, "triangle {t} in two meshlets");
                meshlet_of[t as usize] = k as u32;
            }
        }
        let mut owned = std::collections::HashMap::new();
        for (k, ml) in m.meshlets.iter().enumerate() {
            for e in &m.edges[ml.edges()] {
                assert!(owned.insert((e.a, e.b), k).is_none(), "edge {e:?} owned twice");
                assert!(meshlet_of[e.t0 as usize] == k as u32 || meshlet_of[e.t1 as usize] == k as u32, "{e:?} owned by {k}");
            }
        }
        let mut expected = 0;
        for (p, r) in c.parts.iter().zip(&m.parts) {
            let in_part = |t: u32| r.contains(&meshlet_of[t as usize]);
            if p.kind == CasterKind::Manifold && c.transmittance.is_none() {
                assert!(p.triangles.iter().all(|&t| in_part(t)), "a part triangle outside its meshlets");
                assert_eq!(p.triangles.len(), r.clone().map(|k| m.meshlets[k as usize].triangle_count as usize).sum::<usize>());
                for e in p.scan.edges() {
                    assert!(owned.contains_key(&(e.a, e.b)), "edge {e:?} owned by no meshlet");
                }
                expected += p.scan.edges().len();
            } else {
                assert!(r.is_empty(), "a multiplicity part has meshlets");
            }
        }
        assert_eq!(owned.len(), expected);
        assert_eq!(m.edges.len(), expected);
    }

    #[test]
    fn every_edge_owned_once_on_spheres_tori_and_cubes() {
        for mesh in [uv_sphere(1.0, 48, 24), torus(2.0, 0.5, 40, 16), cube(Vec3::ZERO, 1.0), uv_sphere(1.0, 300, 150)] {
            let c = Caster::new("m", &mesh, Mat4::IDENTITY).unwrap();
            let m = Meshlets::build(&c);
            check(&c, &m);
            assert!(m.meshlets.len() >= c.triangle_count.div_ceil(MAX_MESHLET_TRIANGLES));
        }
    }

    #[test]
    fn several_parts_and_chunks() {
        let two = merged(&uv_sphere(1.0, 32, 16), &torus(3.0, 0.4, 24, 12));
        let c = Caster::with_chunk_limit("two", &two, Mat4::IDENTITY, 100).unwrap();
        assert!(c.parts.len() == 2 && c.chunks.len() > 2);
        let m = Meshlets::build(&c);
        check(&c, &m);
        assert!(m.parts.iter().all(|r| !r.is_empty()));
    }

    #[test]
    fn open_parts_get_no_meshlets() {
        let mut open = cube(Vec3::new(5.0, 0.0, 0.0), 1.0);
        open.triangles.pop();
        let mixed = merged(&uv_sphere(1.0, 16, 8), &open);
        let c = Caster::new("mixed", &mixed, Mat4::IDENTITY).unwrap();
        assert_eq!(c.parts.len(), 2);
        let m = Meshlets::build(&c);
        check(&c, &m);
        assert!(!m.parts[0].is_empty() && m.parts[1].is_empty());
        // a caster open as a whole (one part): no meshlets at all
        let mut one = cube(Vec3::ZERO, 1.0);
        one.triangles.pop();
        let c = Caster::new("open", &one, Mat4::IDENTITY).unwrap();
        let m = Meshlets::build(&c);
        check(&c, &m);
        assert!(m.meshlets.is_empty());
    }

    #[test]
    fn ownership_is_exactly_the_first_assigned_triangle() {
        // A meshlet owns an edge iff its other triangle is in a later meshlet or its own.
        let c = Caster::new("s", &uv_sphere(1.0, 64, 32), Mat4::IDENTITY).unwrap();
        let m = Meshlets::build(&c);
        let mut meshlet_of = vec![0usize; c.triangle_count];
        for (k, ml) in m.meshlets.iter().enumerate() {
            for &t in &m.triangles[ml.triangles()] {
                meshlet_of[t as usize] = k;
            }
        }
        for (k, ml) in m.meshlets.iter().enumerate() {
            for e in &m.edges[ml.edges()] {
                assert_eq!(k, meshlet_of[e.t0 as usize].min(meshlet_of[e.t1 as usize]), "{e:?}");
            }
        }
    }
}
