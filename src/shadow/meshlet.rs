//! Meshlets for mesh-shader extrusion ([`Technique::Mesh`](crate::pass::Technique::Mesh)):
//! built once per caster, for each of its closed manifold parts.
//!
//! A meshlet is a patch of at most [`MAX_MESHLET_TRIANGLES`] triangles of one part, grown
//! breadth-first from a seed over edge adjacency (compact, so that a silhouette crosses few of
//! them and the task stage can drop the rest), and the edges it **owns**: every manifold edge
//! of the part is owned by exactly one meshlet, the one its first triangle (in the build's
//! order) went to, so it is one of the meshlets holding a triangle of the edge. A mesh-shader workgroup draws one
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
//!
//! Each meshlet also carries its [`MeshletBounds`], what the task stage culls it with: a
//! sphere about every vertex it reads and two normal cones ([`crate::geom::cone`]), one of the
//! triangles of its owned edges (both of each edge's, the neighbour's too: if they all face
//! the light strictly the same way, no owned edge is a silhouette edge and its sides emit
//! nothing) and one of its own triangles (if they all face one way, only one of the face caps
//! can have any of them).

use super::caster::{Caster, CasterKind};
use crate::geom::cone::{Bound, FacingCone};
use crate::geom::topology::ManifoldEdge;
use glam::Vec3;
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
    /// Per meshlet, what the task stage culls it with.
    pub bounds: Vec<MeshletBounds>,
}

/// A meshlet's culling bounds (conservative: see [`crate::geom::cone`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct MeshletBounds {
    /// A sphere about every vertex of its triangles and of its owned edges' triangles.
    pub sphere: Bound,
    /// The normal cone of its owned edges' triangles (both of each edge).
    pub sides: FacingCone,
    /// The normal cone of its own triangles.
    pub faces: FacingCone,
}

impl MeshletBounds {
    /// The bounds of meshlet `m` of `out`, from the caster's welded mesh.
    fn of(caster: &Caster, out: &Meshlets, m: &Meshlet) -> MeshletBounds {
        let mesh = caster.mesh();
        let tri = |t: u32| mesh.triangles[t as usize].map(|v| mesh.positions[v as usize]);
        let own: Vec<[Vec3; 3]> = out.triangles[m.triangles()].iter().map(|&t| tri(t)).collect();
        let sides: Vec<[Vec3; 3]> = out.edges[m.edges()].iter().flat_map(|e| [tri(e.t0), tri(e.t1)]).collect();
        MeshletBounds {
            sphere: Bound::of(own.iter().chain(&sides).flatten().copied()),
            sides: FacingCone::of(&sides),
            faces: FacingCone::of(&own),
        }
    }
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
        let mut queued = vec![0u32; n];
        for part in &caster.parts {
            let start = out.meshlets.len() as u32;
            if part.kind == CasterKind::Manifold && !whole_multiplicity {
                let scratch = Scratch { assigned: &mut assigned, tri_edges: &mut tri_edges, queued: &mut queued };
                build_part(part, scratch, &mut out);
            }
            out.parts.push(start..out.meshlets.len() as u32);
        }
        out.bounds = out.meshlets.iter().map(|m| MeshletBounds::of(caster, &out, m)).collect();
        out
    }
}

const UNASSIGNED: u32 = u32::MAX;
const NO_EDGE: u32 = u32::MAX;

/// Per welded triangle, shared by the parts (each part touches only its own triangles): the
/// meshlet it went to (`UNASSIGNED` before), its edges (indices into its part's edge list),
/// the last meshlet whose walk queued it (its index + 1; 0: none).
struct Scratch<'a> {
    assigned: &'a mut [u32],
    tri_edges: &'a mut [[u32; 3]],
    queued: &'a mut [u32],
}

/// Greedy meshlets of one closed manifold part. Each meshlet grows breadth-first over edge
/// adjacency from its first triangle until the next triangle would exceed either limit; that
/// triangle starts the next meshlet, and the rest of the full meshlet's frontier seeds the
/// ones after it (a stack above the part's triangles in order, so each meshlet starts beside
/// the last one and the patches stay compact). A triangle's edges whose other triangle is not
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
    let fresh =
        |out: &Meshlets| Meshlet { first_triangle: out.triangles.len() as u32, first_edge: out.edges.len() as u32, ..Meshlet::default() };
    let mut current = fresh(out);
    // the next seed is the stack's top: the part's triangles in order below the frontiers of
    // the meshlets already full
    let mut seeds: Vec<u32> = part.triangles.iter().rev().copied().collect();
    let mut walk = VecDeque::new();
    while let Some(t) = walk.pop_front().or_else(|| seeds.pop()) {
        if assigned[t as usize] != UNASSIGNED {
            continue;
        }
        let new_edges: Vec<u32> = tri_edges[t as usize]
            .iter()
            .filter(|&&i| i != NO_EDGE && assigned[other(&edges[i as usize], t) as usize] == UNASSIGNED)
            .copied()
            .collect();
        if current.triangle_count as usize + 1 > MAX_MESHLET_TRIANGLES || current.edge_count as usize + new_edges.len() > MAX_MESHLET_EDGES
        {
            out.meshlets.push(current);
            current = fresh(out);
            // the full meshlet's frontier seeds the next ones; `t` starts this one
            seeds.extend(walk.drain(..).rev());
        }
        let id = out.meshlets.len() as u32;
        assigned[t as usize] = id;
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
            if assigned[u as usize] == UNASSIGNED && queued[u as usize] != id + 1 {
                queued[u as usize] = id + 1;
                walk.push_back(u);
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
        check_bounds(c, m);
    }

    /// The bounds contain what they claim: every vertex the meshlet reads is in its sphere,
    /// and for lights about the caster (point, near and inside, directional) a cone that
    /// decides is right for every triangle it covers (the exact predicate).
    fn check_bounds(c: &Caster, m: &Meshlets) {
        use crate::geom::cone::same_facing;
        use crate::geom::predicates::facing_exact;
        use glam::Vec4;
        assert_eq!(m.bounds.len(), m.meshlets.len());
        let mesh = c.mesh();
        let tri = |t: u32| mesh.triangles[t as usize].map(|v| mesh.positions[v as usize]);
        let lights = [
            Vec4::new(3.0, 7.0, 2.0, 1.0),
            Vec4::new(0.1, 0.2, 0.05, 1.0),
            Vec4::new(-20.0, 1.0, 4.0, 1.0),
            Vec4::new(0.3, -1.0, 0.2, 0.0),
            Vec4::new(0.0, 0.0, 1.0, 0.0),
        ];
        let mut decided = 0;
        for (ml, b) in m.meshlets.iter().zip(&m.bounds) {
            let own: Vec<u32> = m.triangles[ml.triangles()].to_vec();
            let sides: Vec<u32> = m.edges[ml.edges()].iter().flat_map(|e| [e.t0, e.t1]).collect();
            for &t in own.iter().chain(&sides) {
                for p in tri(t) {
                    assert!((p.as_dvec3() - b.sphere.center.as_dvec3()).length() <= b.sphere.radius as f64);
                }
            }
            for l in lights {
                for (cone, set) in [(b.sides, &sides), (b.faces, &own)] {
                    if let Some(front) = same_facing(cone, b.sphere, l) {
                        decided += 1;
                        for &t in set.iter() {
                            let [p0, p1, p2] = tri(t);
                            let strict = if front { facing_exact(p0, p1, p2, l) } else { facing_exact(p0, p2, p1, l) };
                            assert!(strict, "triangle {t} against {l}: the cone said {front}");
                        }
                    }
                }
            }
        }
        // on a fine mesh the cones decide most meshlets for lights away from it
        assert!(decided > 0 || m.meshlets.len() < 4, "no meshlet decided");
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
