//! Possible silhouettes: per-triangle facing bits (decided once per light) and the edges
//! whose two triangles disagree.

use super::mesh::Mesh;
use super::predicates::facing_f64;
use super::topology::ManifoldEdge;
use glam::{DVec3, Vec4};

/// Meshes with at least this many triangles get their facing bits on several threads
/// (the f64 filtered orientation test is compute-bound).
pub const PARALLEL_THRESHOLD: usize = 200_000;
/// The edge scan is memory-bound: on a 2-core machine, 1.5M edges took 1.2 ms serial vs
/// 2.4 ms on 2 threads (benches/silhouette.rs), so it only splits for very large meshes.
pub const PARALLEL_EDGE_THRESHOLD: usize = 8_000_000;

/// One possible-silhouette edge: `a -> b` as it appears in the LIGHT-FACING triangle `lit`
/// (corner `lit_corner`); `unlit` walks it `b -> a` (corner `unlit_corner`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SilhouetteEdge {
    /// Start vertex (welded index) in the light-facing triangle's winding.
    pub a: u32,
    /// End vertex (welded index) in the light-facing triangle's winding.
    pub b: u32,
    /// The light-facing triangle.
    pub lit: u32,
    /// Corner of `lit` where `a -> b` starts.
    pub lit_corner: u8,
    /// The triangle facing away from the light.
    pub unlit: u32,
    /// Corner of `unlit` where `b -> a` starts.
    pub unlit_corner: u8,
}

fn threads_for(n: usize) -> usize {
    if n < PARALLEL_THRESHOLD {
        1
    } else {
        std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1).min(8)
    }
}

/// Facing bit of every triangle for the object-space homogeneous light `l`
/// (`flip`: negate the orientation, for casters whose transform mirrors).
pub fn facing_bits(mesh: &Mesh, l: Vec4, flip: bool) -> Vec<bool> {
    facing_bits_threads(mesh, l, flip, threads_for(mesh.triangles.len()))
}

/// [`facing_bits`] on exactly `threads` threads (benchmarks compare 1 with the default).
pub fn facing_bits_threads(mesh: &Mesh, l: Vec4, flip: bool, threads: usize) -> Vec<bool> {
    let n = mesh.triangles.len();
    let mut out = vec![false; n];
    let work = |tris: &[[u32; 3]], out: &mut [bool]| {
        let p = &mesh.positions;
        for (o, t) in out.iter_mut().zip(tris) {
            let (a, b, c): (DVec3, DVec3, DVec3) = (p[t[0] as usize].as_dvec3(), p[t[1] as usize].as_dvec3(), p[t[2] as usize].as_dvec3());
            *o = if flip { facing_f64(a, c, b, l) } else { facing_f64(a, b, c, l) };
        }
    };
    let th = threads.max(1);
    if th == 1 || n == 0 {
        work(&mesh.triangles, &mut out);
    } else {
        let chunk = n.div_ceil(th);
        std::thread::scope(|s| {
            for (tris, o) in mesh.triangles.chunks(chunk).zip(out.chunks_mut(chunk)) {
                s.spawn(move || work(tris, o));
            }
        });
    }
    out
}

fn sil_range(edges: &[ManifoldEdge], facing: &[bool], out: &mut Vec<SilhouetteEdge>) {
    for e in edges {
        let (f0, f1) = (facing[e.t0 as usize], facing[e.t1 as usize]);
        if f0 != f1 {
            out.push(if f0 {
                SilhouetteEdge { a: e.a, b: e.b, lit: e.t0, lit_corner: e.c0, unlit: e.t1, unlit_corner: e.c1 }
            } else {
                SilhouetteEdge { a: e.b, b: e.a, lit: e.t1, lit_corner: e.c1, unlit: e.t0, unlit_corner: e.c0 }
            });
        }
    }
}

/// The possible silhouette: every manifold edge whose triangles have different facing bits,
/// oriented as in its light-facing triangle.
pub fn possible_silhouette(edges: &[ManifoldEdge], facing: &[bool]) -> Vec<SilhouetteEdge> {
    let th = if edges.len() < PARALLEL_EDGE_THRESHOLD { 1 } else { threads_for(edges.len()) };
    if th == 1 {
        let mut out = Vec::new();
        sil_range(edges, facing, &mut out);
        return out;
    }
    let chunk = edges.len().div_ceil(th);
    let parts: Vec<Vec<SilhouetteEdge>> = std::thread::scope(|s| {
        let hs: Vec<_> = edges
            .chunks(chunk)
            .map(|es| {
                s.spawn(move || {
                    let mut v = Vec::new();
                    sil_range(es, facing, &mut v);
                    v
                })
            })
            .collect();
        hs.into_iter().map(|h| h.join().expect("silhouette worker panicked")).collect()
    });
    parts.concat()
}

/// Single-threaded reference (for benchmarks and tests).
pub fn possible_silhouette_serial(edges: &[ManifoldEdge], facing: &[bool]) -> Vec<SilhouetteEdge> {
    let mut out = Vec::new();
    sil_range(edges, facing, &mut out);
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::topology::Topology;
    use crate::shadow::testmesh::{cube, uv_sphere};
    use glam::Vec3;

    #[test]
    fn cube_from_above() {
        let t = Topology::build(&cube(Vec3::ZERO, 1.0));
        let f = facing_bits(&t.mesh, Vec4::new(0.0, 5.0, 0.0, 1.0), false);
        assert_eq!(f.iter().filter(|&&x| x).count(), 2);
        let s = possible_silhouette(&t.manifold_edges, &f);
        assert_eq!(s.len(), 4);
        for e in &s {
            let tri = t.mesh.triangles[e.lit as usize];
            let k = e.lit_corner as usize;
            assert_eq!((tri[k], tri[(k + 1) % 3]), (e.a, e.b));
            assert!(f[e.lit as usize] && !f[e.unlit as usize]);
            let u = t.mesh.triangles[e.unlit as usize];
            let k = e.unlit_corner as usize;
            assert_eq!((u[k], u[(k + 1) % 3]), (e.b, e.a));
        }
        // silhouette loop: every vertex has one outgoing and one incoming edge
        let mut deg = std::collections::HashMap::<u32, i32>::new();
        for e in &s {
            *deg.entry(e.a).or_default() += 1;
            *deg.entry(e.b).or_default() -= 1;
        }
        assert!(deg.values().all(|&d| d == 0));
    }

    #[test]
    fn parallel_equals_serial() {
        let t = Topology::build(&uv_sphere(1.0, 400, 300));
        let mut many = t.manifold_edges.clone();
        while many.len() < PARALLEL_EDGE_THRESHOLD {
            many.extend_from_within(..);
        }
        let l = Vec4::new(3.0, 1.0, 0.5, 1.0);
        let f = facing_bits(&t.mesh, l, false);
        let mut serial = vec![false; f.len()];
        for (i, tri) in t.mesh.triangles.iter().enumerate() {
            let p = |k: usize| t.mesh.positions[tri[k] as usize];
            serial[i] = crate::geom::predicates::facing(p(0), p(1), p(2), l);
        }
        assert_eq!(f, serial);
        assert_eq!(possible_silhouette(&t.manifold_edges, &f), possible_silhouette_serial(&t.manifold_edges, &f));
        assert_eq!(possible_silhouette(&many, &f), possible_silhouette_serial(&many, &f));
    }
}
