//! Mesh topology: vertex welding, the edge table, and closed-2-manifold classification.
//!
//! Shadow volumes built from per-triangle facing bits are closed only when the caster is a
//! closed, consistently oriented 2-manifold: every undirected edge used by exactly two
//! triangles, once in each direction.

use super::mesh::Mesh;
use glam::Vec3;
use std::collections::HashMap;

/// One use of an undirected edge by a triangle.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct EdgeUse {
    /// The triangle (index into the welded mesh's triangles).
    pub tri: u32,
    /// Corner k: the edge goes from `triangles[tri][k]` to `triangles[tri][(k+1)%3]`.
    pub corner: u8,
    /// true when the triangle walks the edge from the smaller to the larger vertex index.
    pub forward: bool,
}

/// An undirected edge (`v[0] < v[1]`, welded vertex indices) with its uses.
#[derive(Clone, Debug)]
pub struct Edge {
    /// Its two welded vertices, smaller index first.
    pub v: [u32; 2],
    /// Range into [`Topology::uses`].
    pub first_use: u32,
    /// Number of triangles using it: 1 on a boundary, 2 for a manifold (or inconsistent) edge, 3+ non-manifold.
    pub use_count: u32,
}

/// A manifold edge: `t0` walks a->b (corner `c0`), `t1` walks b->a (corner `c1`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ManifoldEdge {
    /// Smaller welded vertex index.
    pub a: u32,
    /// Larger welded vertex index.
    pub b: u32,
    /// The triangle that walks a -> b.
    pub t0: u32,
    /// Corner of `t0` the edge starts at.
    pub c0: u8,
    /// The triangle that walks b -> a.
    pub t1: u32,
    /// Corner of `t1` the edge starts at.
    pub c1: u8,
}

/// Welded mesh topology.
#[derive(Clone, Debug)]
pub struct Topology {
    /// The welded mesh (positions deduplicated, triangles re-indexed; zero-area triangles kept).
    pub mesh: Mesh,
    /// Original vertex index -> welded vertex index.
    pub remap: Vec<u32>,
    /// Every undirected edge once, sorted by `(v[0], v[1])`; degenerate (a == a) edges are left out.
    pub edges: Vec<Edge>,
    /// The uses of all edges, grouped by edge (see [`Edge::first_use`], [`Topology::edge_uses`]).
    pub uses: Vec<EdgeUse>,
    /// Every edge with exactly two uses in opposite directions (all edges when closed).
    pub manifold_edges: Vec<ManifoldEdge>,
    /// Edges used by one triangle only (holes, open meshes).
    pub boundary_edges: usize,
    /// Edges used by three or more triangles.
    pub non_manifold_edges: usize,
    /// Edges used by two triangles walking them the same way (inconsistent winding).
    pub inconsistent_edges: usize,
    /// Triangles that use the same vertex twice after welding (they have a degenerate edge).
    pub collapsed_triangles: usize,
}

/// How to weld vertices.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Weld {
    /// Exact position equality (+0.0 == -0.0).
    Exact,
    /// Positions closer than this (Euclidean) are merged (greedy, first vertex wins).
    Tolerance(f32),
}

fn key(p: Vec3) -> [u32; 3] {
    // +0.0 and -0.0 compare equal: normalise by adding 0.0.
    [(p.x + 0.0).to_bits(), (p.y + 0.0).to_bits(), (p.z + 0.0).to_bits()]
}

/// Welds positions; returns (welded positions, remap).
pub fn weld(positions: &[Vec3], mode: Weld) -> (Vec<Vec3>, Vec<u32>) {
    let mut out = Vec::new();
    let mut remap = Vec::with_capacity(positions.len());
    match mode {
        Weld::Exact => {
            let mut map: HashMap<[u32; 3], u32> = HashMap::with_capacity(positions.len());
            for p in positions {
                let id = *map.entry(key(*p)).or_insert_with(|| {
                    out.push(*p);
                    (out.len() - 1) as u32
                });
                remap.push(id);
            }
        }
        Weld::Tolerance(tol) => {
            let tol = tol.max(f32::MIN_POSITIVE);
            let cell = |p: Vec3| -> [i64; 3] {
                let q = (p.as_dvec3() / tol as f64).floor();
                [q.x as i64, q.y as i64, q.z as i64]
            };
            let mut grid: HashMap<[i64; 3], Vec<u32>> = HashMap::new();
            for p in positions {
                let c = cell(*p);
                let mut found = None;
                'search: for dx in -1..=1 {
                    for dy in -1..=1 {
                        for dz in -1..=1 {
                            // wrapping: a tiny tolerance saturates the cell to i64::MAX (the exact distance
                            // test below decides, so a wrapped neighbour only costs a lookup)
                            if let Some(list) = grid.get(&[c[0].wrapping_add(dx), c[1].wrapping_add(dy), c[2].wrapping_add(dz)]) {
                                for &id in list {
                                    if out[id as usize].distance(*p) <= tol {
                                        found = Some(id);
                                        break 'search;
                                    }
                                }
                            }
                        }
                    }
                }
                let id = found.unwrap_or_else(|| {
                    out.push(*p);
                    let id = (out.len() - 1) as u32;
                    grid.entry(c).or_default().push(id);
                    id
                });
                remap.push(id);
            }
        }
    }
    (out, remap)
}

impl Topology {
    /// Exact welding, then the edge table.
    pub fn build(mesh: &Mesh) -> Topology {
        Topology::build_with(mesh, Weld::Exact)
    }

    /// Welding by `mode`, then the edge table.
    pub fn build_with(mesh: &Mesh, mode: Weld) -> Topology {
        let (positions, remap) = weld(&mesh.positions, mode);
        let triangles: Vec<[u32; 3]> =
            mesh.triangles.iter().map(|t| [remap[t[0] as usize], remap[t[1] as usize], remap[t[2] as usize]]).collect();
        let welded = Mesh { positions, triangles };
        Topology::from_welded(welded, remap)
    }

    /// Edge table of an already welded mesh (indices are taken as vertex identity).
    pub fn from_welded(mesh: Mesh, remap: Vec<u32>) -> Topology {
        // (min, max, tri, corner, forward), sorted: a radix-free O(E log E) edge table that
        // scales to millions of triangles without hashing.
        let mut recs: Vec<(u64, u32, u8, bool)> = Vec::with_capacity(mesh.triangles.len() * 3);
        let mut collapsed = 0usize;
        for (t, tri) in mesh.triangles.iter().enumerate() {
            if tri[0] == tri[1] || tri[1] == tri[2] || tri[2] == tri[0] {
                collapsed += 1;
            }
            for k in 0..3 {
                let (a, b) = (tri[k], tri[(k + 1) % 3]);
                if a == b {
                    continue; // a degenerate edge is no edge
                }
                let (lo, hi) = if a < b { (a, b) } else { (b, a) };
                recs.push((((lo as u64) << 32) | hi as u64, t as u32, k as u8, a < b));
            }
        }
        recs.sort_unstable();
        let mut edges = Vec::new();
        let mut uses = Vec::with_capacity(recs.len());
        let mut manifold_edges = Vec::new();
        let (mut boundary, mut nonman, mut incons) = (0, 0, 0);
        let mut i = 0;
        while i < recs.len() {
            let k = recs[i].0;
            let mut j = i;
            while j < recs.len() && recs[j].0 == k {
                j += 1;
            }
            let first = uses.len() as u32;
            for r in &recs[i..j] {
                uses.push(EdgeUse { tri: r.1, corner: r.2, forward: r.3 });
            }
            let v = [(k >> 32) as u32, k as u32];
            let n = j - i;
            match n {
                1 => boundary += 1,
                2 => {
                    let (u0, u1) = (uses[first as usize], uses[first as usize + 1]);
                    if u0.forward == u1.forward {
                        incons += 1;
                    } else {
                        let (f, r) = if u0.forward { (u0, u1) } else { (u1, u0) };
                        manifold_edges.push(ManifoldEdge { a: v[0], b: v[1], t0: f.tri, c0: f.corner, t1: r.tri, c1: r.corner });
                    }
                }
                _ => nonman += 1,
            }
            edges.push(Edge { v, first_use: first, use_count: n as u32 });
            i = j;
        }
        Topology {
            mesh,
            remap,
            edges,
            uses,
            manifold_edges,
            boundary_edges: boundary,
            non_manifold_edges: nonman,
            inconsistent_edges: incons,
            collapsed_triangles: collapsed,
        }
    }

    /// The triangles using edge `e` (an index into [`Topology::edges`]).
    pub fn edge_uses(&self, e: usize) -> &[EdgeUse] {
        let e = &self.edges[e];
        &self.uses[e.first_use as usize..(e.first_use + e.use_count) as usize]
    }

    /// Closed, consistently oriented 2-manifold: every edge has exactly 2 opposite uses.
    /// (A triangle using a vertex twice is accepted when its remaining edges still pair up;
    /// such zero-area triangles are kept.)
    pub fn is_closed_manifold(&self) -> bool {
        !self.edges.is_empty() && self.boundary_edges == 0 && self.non_manifold_edges == 0 && self.inconsistent_edges == 0
    }

    /// Human-readable list of what makes the mesh non-closed; empty when closed.
    pub fn describe_problem(&self) -> String {
        let mut parts = Vec::new();
        if self.edges.is_empty() {
            parts.push("no edges".to_string());
        }
        if self.boundary_edges > 0 {
            parts.push(format!("{} boundary edges (open mesh)", self.boundary_edges));
        }
        if self.non_manifold_edges > 0 {
            parts.push(format!("{} edges shared by more than 2 triangles", self.non_manifold_edges));
        }
        if self.inconsistent_edges > 0 {
            parts.push(format!("{} edges with inconsistently oriented triangles", self.inconsistent_edges));
        }
        parts.join(", ")
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::testmesh::{cube, signed_volume, torus, uv_sphere};

    #[test]
    fn test_meshes_are_outward() {
        assert!((signed_volume(&cube(Vec3::ONE, 1.0)) - 8.0).abs() < 1e-9);
        assert!(signed_volume(&uv_sphere(1.0, 32, 16)) > 3.5);
        assert!(signed_volume(&torus(1.0, 0.25, 32, 16)) > 0.5);
    }

    #[test]
    fn cube_closed() {
        let t = Topology::build(&cube(Vec3::ZERO, 1.0));
        assert!(t.is_closed_manifold(), "{}", t.describe_problem());
        assert_eq!(t.edges.len(), 18);
        assert_eq!(t.manifold_edges.len(), 18);
        assert_eq!(t.describe_problem(), "");
    }

    #[test]
    fn unwelded_cube_gets_welded() {
        // split every triangle into its own vertices
        let m = cube(Vec3::ZERO, 1.0);
        let mut pos = Vec::new();
        let mut tris = Vec::new();
        for t in &m.triangles {
            let b = pos.len() as u32;
            for &i in t {
                pos.push(m.positions[i as usize]);
            }
            tris.push([b, b + 1, b + 2]);
        }
        let split = Mesh::new(pos, tris);
        assert!(Topology::build(&split).is_closed_manifold());
        assert_eq!(Topology::build(&split).mesh.positions.len(), 8);
        // tolerance weld of jittered copies
        let mut jit = split.clone();
        for (i, p) in jit.positions.iter_mut().enumerate() {
            *p += Vec3::splat((i % 3) as f32 * 1e-6);
        }
        assert!(!Topology::build(&jit).is_closed_manifold());
        let t = Topology::build_with(&jit, Weld::Tolerance(1e-4));
        assert!(t.is_closed_manifold(), "{}", t.describe_problem());
        assert_eq!(t.mesh.positions.len(), 8);
    }

    #[test]
    fn open_and_nonmanifold() {
        let mut m = cube(Vec3::ZERO, 1.0);
        m.triangles.pop();
        let t = Topology::build(&m);
        assert!(!t.is_closed_manifold());
        assert_eq!(t.boundary_edges, 3);
        assert!(t.describe_problem().contains("3 boundary edges (open mesh)"));
        let mut m = cube(Vec3::ZERO, 1.0);
        let extra = m.triangles[0];
        m.triangles.push(extra);
        let t = Topology::build(&m);
        assert_eq!(t.non_manifold_edges, 3);
        assert!(t.describe_problem().contains("3 edges shared by more than 2 triangles"));
        let mut m = cube(Vec3::ZERO, 1.0);
        m.triangles[0].swap(1, 2);
        let t = Topology::build(&m);
        assert!(t.inconsistent_edges > 0);
        assert!(!t.is_closed_manifold());
    }

    #[test]
    fn zero_area_triangles_kept() {
        // a cube whose one quad is split with a collinear sliver vertex on an edge
        let mut m = cube(Vec3::ZERO, 1.0);
        let before = m.triangles.len();
        // add a degenerate triangle pair that cancels: (0,1,1) uses vertex twice
        m.triangles.push([0, 1, 1]);
        let t = Topology::build(&m);
        assert_eq!(t.mesh.triangles.len(), before + 1);
        assert_eq!(t.collapsed_triangles, 1);
    }

    #[test]
    fn spheres_and_torus_closed() {
        for m in [uv_sphere(1.0, 16, 8), uv_sphere(2.0, 64, 33), torus(1.0, 0.3, 24, 12)] {
            let t = Topology::build(&m);
            assert!(t.is_closed_manifold(), "{}", t.describe_problem());
        }
    }
}
