//! Possible silhouettes: per-triangle facing bits (decided once per light) and the edges
//! whose two triangles disagree.

use super::mesh::Mesh;
use super::predicates::facing_f64;
use super::topology::ManifoldEdge;
use glam::{DVec3, Vec4};

/// Meshes with at least this many triangles get their facing bits on several threads
/// (the f64 filtered orientation test is compute-bound).
pub const PARALLEL_THRESHOLD: usize = 200_000;
/// [`FacePlanes::facing_packed_auto`] splits over threads from this many triangles. Measured on
/// the shared 2-core machine (benches/silhouette.rs): 1M triangles took 1.97 ms on one thread and
/// 1.41 ms on two in isolation, but followed by the edge scan (as the planner runs it) 9.4 ms
/// threaded against 3.0 ms serial, and 100k 970 µs against 277 µs; at 10k two threads cost
/// 5x more than they save. Threads do not pay on such a machine: only for very large meshes.
pub const PLANES_PARALLEL_THRESHOLD: usize = 4_000_000;
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
        super::cpu::cores().min(8)
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

pub use super::planes::FacePlanes;

/// The facing bit of triangle `t` in packed bits (false past the end).
#[inline]
pub fn packed_bit(bits: &[u64], t: u32) -> bool {
    bits.get(t as usize / 64).is_some_and(|w| (w >> (t % 64)) & 1 != 0)
}

/// Packed facing bits to one `bool` per triangle (`n` triangles).
pub fn unpack_bits(bits: &[u64], n: usize) -> Vec<bool> {
    (0..n).map(|t| packed_bit(bits, t as u32)).collect()
}

/// [`possible_silhouette`] on packed facing bits ([`FacePlanes::facing_packed`]): the same
/// edges in the same order. An edge naming a triangle past the bits counts it as not facing.
pub fn possible_silhouette_packed(edges: &[ManifoldEdge], bits: &[u64]) -> Vec<SilhouetteEdge> {
    let mut out = Vec::new();
    possible_silhouette_packed_into(edges, bits, &mut out);
    out
}

pub use super::edgescan::{EdgeScan, ScanHit};

/// [`possible_silhouette_packed`] appending to `out` (reuse the allocation across frames).
pub fn possible_silhouette_packed_into(edges: &[ManifoldEdge], bits: &[u64], out: &mut Vec<SilhouetteEdge>) {
    for e in edges {
        let (f0, f1) = (packed_bit(bits, e.t0), packed_bit(bits, e.t1));
        if f0 != f1 {
            out.push(if f0 {
                SilhouetteEdge { a: e.a, b: e.b, lit: e.t0, lit_corner: e.c0, unlit: e.t1, unlit_corner: e.c1 }
            } else {
                SilhouetteEdge { a: e.b, b: e.a, lit: e.t1, lit_corner: e.c1, unlit: e.t0, unlit_corner: e.c0 }
            });
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::planes::exact_bit;
    use crate::geom::testmesh::{cube, uv_sphere};
    use crate::geom::topology::Topology;
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

    fn exact_reference(m: &Mesh, l: Vec4, flip: bool) -> Vec<bool> {
        (0..m.triangles.len()).map(|t| exact_bit(m, t, l, flip)).collect()
    }

    fn check_planes(m: &Mesh, l: Vec4) {
        let planes = FacePlanes::new(m);
        let mut bits = Vec::new();
        for flip in [false, true] {
            let want = exact_reference(m, l, flip);
            planes.facing_packed(m, l, flip, &mut bits);
            assert_eq!(bits.len(), m.triangles.len().div_ceil(64));
            assert_eq!(unpack_bits(&bits, m.triangles.len()), want, "light {l:?} flip {flip}");
            if let Some(&last) = bits.last() {
                if !m.triangles.len().is_multiple_of(64) {
                    assert_eq!(last >> (m.triangles.len() % 64), 0);
                }
            }
            let mut threaded = Vec::new();
            planes.facing_packed_threads(m, l, flip, 3, &mut threaded);
            assert_eq!(threaded, bits);
        }
    }

    #[test]
    fn packed_equals_bools_on_sphere() {
        let t = Topology::build(&uv_sphere(1.0, 60, 31));
        let planes = FacePlanes::new(&t.mesh);
        assert_eq!(planes.len(), t.mesh.triangles.len());
        assert_eq!(planes.bytes(), t.mesh.triangles.len().div_ceil(64) * 64 * 16);
        let mut bits = Vec::new();
        for l in
            [Vec4::new(3.0, 2.0, 1.0, 1.0), Vec4::new(0.1, 0.2, -0.3, 1.0), Vec4::new(-1.0, 0.5, 0.2, 0.0), Vec4::new(6.0, 4.0, 2.0, 2.0)]
        {
            for flip in [false, true] {
                planes.facing_packed(&t.mesh, l, flip, &mut bits);
                let f = facing_bits(&t.mesh, l, flip);
                assert_eq!(unpack_bits(&bits, f.len()), f);
                assert_eq!(possible_silhouette_packed(&t.manifold_edges, &bits), possible_silhouette_serial(&t.manifold_edges, &f));
                let mut sil = Vec::new();
                let scan = EdgeScan::new(t.manifold_edges.clone());
                scan.scan_into(&bits, &mut sil);
                assert_eq!(sil, possible_silhouette_serial(scan.edges(), &f));
            }
            check_planes(&t.mesh, l);
        }
    }

    #[test]
    fn scan_scratch_reused_across_meshes() {
        // the per-thread run tables are reused: larger and smaller meshes in turn, and bits shorter
        // than the triangle ids (the missing triangles read as not facing, never stale bytes)
        let big = Topology::build(&uv_sphere(1.0, 60, 31));
        let small = Topology::build(&cube(Vec3::ZERO, 1.0));
        let l = Vec4::new(3.0, 2.0, 1.0, 1.0);
        for t in [&big, &small, &big, &small] {
            let mut bits = Vec::new();
            FacePlanes::new(&t.mesh).facing_packed(&t.mesh, l, false, &mut bits);
            let scan = EdgeScan::new(t.manifold_edges.clone());
            for b in [&bits[..], &bits[..bits.len() / 2], &[u64::MAX][..]] {
                let mut sil = Vec::new();
                scan.scan_into(b, &mut sil);
                assert_eq!(sil, possible_silhouette_packed(scan.edges(), b));
            }
        }
    }

    #[test]
    fn planes_bad_input() {
        // lights on vertices, in face planes, inside; degenerate triangles; out-of-range indices
        let mut m = cube(Vec3::ZERO, 1.0);
        m.triangles.push([0, 0, 1]);
        m.triangles.push([0, 1, 99]);
        let p = m.positions.clone();
        m.positions.push(p[0] * 2.0 - p[1]); // collinear with p0, p1
        let k = m.positions.len() as u32 - 1;
        m.triangles.push([0, 1, k]);
        for l in [
            p[0].extend(1.0),
            p[3].extend(1.0),
            Vec4::new(0.0, 0.0, 0.0, 1.0),
            Vec4::new(1.0, 1.0, 3.0, 1.0),
            Vec4::new(1.0, 0.0, 0.0, 0.0),
        ] {
            check_planes(&m, l);
        }
        let planes = FacePlanes::new(&m);
        assert_eq!(planes.always_exact(), 3);
        let mut bits = Vec::new();
        planes.facing_packed(&m, Vec4::new(0.0, 5.0, 0.0, 1.0), false, &mut bits);
        assert!(!packed_bit(&bits, 13) && !packed_bit(&bits, 1000));
        // non-finite and huge lights, huge meshes, a mismatched mesh: exact everywhere
        for l in [Vec4::new(f32::NAN, 0.0, 0.0, 1.0), Vec4::new(1e30, 2e30, 0.0, 1.0), Vec4::new(1.0, 2.0, 3.0, 1e-30)] {
            check_planes(&m, l);
        }
        let mut far = cube(Vec3::splat(1e20), 1.0);
        far.positions[0].x = 3e25;
        check_planes(&far, Vec4::new(0.0, 1.0, 0.0, 1.0));
        assert_eq!(FacePlanes::new(&far).always_exact(), far.triangles.len());
        let other = cube(Vec3::ONE, 1.0);
        planes.facing_packed(&other, Vec4::new(0.0, 5.0, 0.0, 1.0), false, &mut bits);
        assert_eq!(unpack_bits(&bits, 12), exact_reference(&other, Vec4::new(0.0, 5.0, 0.0, 1.0), false));
        // empty
        let empty = Mesh::default();
        FacePlanes::new(&empty).facing_packed(&empty, Vec4::ONE, false, &mut bits);
        assert!(bits.is_empty());
        // deforming: recompute follows the new positions
        let mut moving = uv_sphere(1.0, 12, 7);
        let mut planes = FacePlanes::new(&moving);
        for q in &mut moving.positions {
            *q = Vec3::new(q.x * 2.0 + 5.0, -q.y, q.z * 0.5);
        }
        planes.recompute(&moving);
        planes.facing_packed(&moving, Vec4::new(3.0, 1.0, 0.5, 1.0), false, &mut bits);
        assert_eq!(unpack_bits(&bits, moving.triangles.len()), exact_reference(&moving, Vec4::new(3.0, 1.0, 0.5, 1.0), false));
    }

    mod proptests {
        use super::*;
        use proptest::prelude::*;

        /// Coordinates: small lattice values (exact coplanarity is common), uniform values,
        /// huge offsets and tiny ones.
        fn coord() -> impl Strategy<Value = f32> {
            prop_oneof![
                (-4i32..=4).prop_map(|i| i as f32 * 0.5),
                -1.0f32..1.0,
                (-1.0f32..1.0).prop_map(|x| 1e5 + x),
                (-1.0f32..1.0).prop_map(|x| x * 1e7),
                (-1.0f32..1.0).prop_map(|x| x * 1e-6),
                (-1.0f32..1.0).prop_map(|x| 3e17 + x * 1e11),
            ]
        }

        fn point() -> impl Strategy<Value = Vec3> {
            (coord(), coord(), coord()).prop_map(|(x, y, z)| Vec3::new(x, y, z))
        }

        fn mesh_and_light() -> impl Strategy<Value = (Mesh, Vec4)> {
            (
                prop::collection::vec(point(), 3..24),
                prop::collection::vec((0usize..64, 0usize..64, 0usize..64), 1..150),
                0usize..8,
                point(),
                0usize..64,
                -1.0f32..1.0,
            )
                .prop_map(|(pos, tris, kind, free, pick, s)| {
                    let n = pos.len();
                    let triangles: Vec<[u32; 3]> = tris.iter().map(|&(a, b, c)| [(a % n) as u32, (b % n) as u32, (c % n) as u32]).collect();
                    let t = triangles[pick % triangles.len()];
                    let [a, b, c] = t.map(|i| pos[i as usize]);
                    let l = match kind {
                        0 => free.extend(1.0),
                        1 => a.extend(1.0),                       // on a vertex
                        2 => (a + (b - a) + (c - a)).extend(1.0), // in a plane (exact on the lattice)
                        3 => (a + (b - a) * 0.5).extend(1.0),     // on an edge
                        4 => (b - a).extend(0.0),                 // directional, in a plane
                        5 => ((b - a) + (c - a) * s).extend(0.0), // directional, near a plane
                        6 => (a + (b - a) * s).extend(1.0) + Vec4::new(0.0, 0.0, f32::EPSILON * a.z.abs(), 0.0),
                        _ => free.extend(s * 3.0), // general homogeneous w
                    };
                    (Mesh { positions: pos, triangles }, l)
                })
        }

        proptest! {
            #![proptest_config(ProptestConfig { cases: 3000, ..ProptestConfig::default() })]
            #[test]
            fn fast_bits_equal_exact((m, l) in mesh_and_light()) {
                check_planes(&m, l);
            }

            #[test]
            fn near_coplanar_grids(scale in prop_oneof![Just(1.0f32), Just(1e4), Just(1e-4), Just(3e6)], off in point(), tilt in -1e-6f32..1e-6, lz in -1e-5f32..1e-5) {
                // a fan of almost coplanar triangles, lights on and very near their plane
                let m = crate::geom::testmesh::grid(9, 9, |i, j| off + Vec3::new(i as f32, j as f32, (i * j) as f32 * tilt) * scale);
                for l in [(off + Vec3::new(3.0, 4.0, lz) * scale).extend(1.0), off.extend(1.0), Vec3::new(1.0, 2.0, lz).extend(0.0), (off * 2.0).extend(1.0)] {
                    check_planes(&m, l);
                }
            }
        }
    }
}
