//! `EdgeScan` against the plain per-edge scan: spheres, shuffled and spatial orders, doubled
//! and self edges, random edges, bits and permutations.

use super::*;
use crate::geom::cpu::on_each_copy;
use crate::geom::silhouette::{possible_silhouette_packed, FacePlanes};
use crate::geom::testmesh::{cube, shuffled, uv_sphere};
use crate::geom::topology::Topology;
use crate::geom::TriangleOrder;
use glam::{Vec3, Vec4};
use proptest::prelude::*;

thread_local! {
    /// Far word pairs tested by their words, not by the words' codes (as past `WORD_CODES`).
    pub(super) static WORDS_ONLY: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
}

fn check(edges: Vec<ManifoldEdge>, bits: &[u64]) -> EdgeScan {
    check_in(edges, bits, &TriangleOrder::identity())
}

/// The plain scan over `edges` with bits looked up by slot.
fn plain(edges: &[ManifoldEdge], bits: &[u64], order: &TriangleOrder) -> Vec<SilhouetteEdge> {
    let slotted: Vec<ManifoldEdge> = edges.iter().map(|e| ManifoldEdge { t0: order.slot(e.t0), t1: order.slot(e.t1), ..*e }).collect();
    let mut out = possible_silhouette_packed(&slotted, bits);
    for s in &mut out {
        s.lit = order.triangle(s.lit);
        s.unlit = order.triangle(s.unlit);
    }
    out
}

fn check_in(edges: Vec<ManifoldEdge>, bits: &[u64], order: &TriangleOrder) -> EdgeScan {
    let scan = EdgeScan::with_order(edges.clone(), order);
    let mut sorted_in = edges.clone();
    let mut sorted_scan = scan.edges().to_vec();
    let key = |e: &ManifoldEdge| (e.a, e.b, e.t0, e.t1, e.c0, e.c1);
    sorted_in.sort_by_key(key);
    sorted_scan.sort_by_key(key);
    assert_eq!(sorted_in, sorted_scan, "the scan holds exactly the given edges");
    let sil = on_each_copy(|| {
        let mut sil = Vec::new();
        scan.scan_into(bits, &mut sil);
        sil
    });
    assert_eq!(sil, plain(scan.edges(), bits, order));
    // the far word pairs tested by their words (meshes past 2^16 words): the same edges
    WORDS_ONLY.set(true);
    let mut by_words = Vec::new();
    scan.scan_into(bits, &mut by_words);
    WORDS_ONLY.set(false);
    assert_eq!(sil, by_words, "far pairs tested by their words");
    if order.is_identity() {
        assert_eq!(sil, possible_silhouette_packed(scan.edges(), bits));
    }
    scan
}

#[test]
fn sphere_is_scanned_by_words() {
    let t = Topology::build(&uv_sphere(1.0, 120, 61));
    let planes = FacePlanes::new(&t.mesh);
    let mut bits = Vec::new();
    for l in [Vec4::new(3.0, 2.0, 1.0, 1.0), Vec4::new(0.1, 0.2, -0.3, 1.0), Vec4::new(-1.0, 0.5, 0.2, 0.0)] {
        planes.facing_packed(&t.mesh, l, false, &mut bits);
        let scan = check(t.manifold_edges.clone(), &bits);
        // rows of quads: two distances (1 inside a row, 2 slices + 1 across rows) cover all
        // but the seam and pole edges
        assert!(scan.near.deltas.len() + scan.far_classes.len() >= 2, "{:?} classes", scan.near.deltas);
        assert!(
            scan.word_scanned_edges() * 10 >= t.manifold_edges.len() * 9,
            "{} of {}",
            scan.word_scanned_edges(),
            t.manifold_edges.len()
        );
        for b in [&bits[..], &bits[..bits.len() / 2], &[u64::MAX][..], &[][..]] {
            check(t.manifold_edges.clone(), b);
        }
    }
}

#[test]
fn shuffled_triangles_take_the_residual_path() {
    // a fixed pseudo-random triangle order: no distance class, almost every edge alone in
    // its word pair
    let t = Topology::build(&shuffled(&uv_sphere(1.0, 200, 101)));
    let mut bits = Vec::new();
    FacePlanes::new(&t.mesh).facing_packed(&t.mesh, Vec4::new(3.0, 2.0, 1.0, 1.0), false, &mut bits);
    let scan = check(t.manifold_edges.clone(), &bits);
    assert!(scan.word_scanned_edges() * 10 < t.manifold_edges.len());
    assert!(scan.lone.len() * 2 > t.manifold_edges.len(), "{} alone", scan.lone.len());
    // in a spatial order the same mesh's edges fall into few word pairs, most skipped whole
    let all: Vec<u32> = (0..t.mesh.triangles.len() as u32).collect();
    let order = TriangleOrder::spatial(&t.mesh, &[&all]);
    let planes = FacePlanes::with_order(&t.mesh, order.clone());
    for l in [Vec4::new(3.0, 2.0, 1.0, 1.0), Vec4::new(0.1, 0.2, -0.3, 1.0), Vec4::new(-1.0, 0.5, 0.2, 0.0)] {
        planes.facing_packed(&t.mesh, l, false, &mut bits);
        let scan = check_in(t.manifold_edges.clone(), &bits, &order);
        assert!(
            (scan.far_lo.len() + scan.lone.len()) * 8 < t.manifold_edges.len(),
            "{} pairs, {} alone",
            scan.far_lo.len(),
            scan.lone.len()
        );
        // the same silhouette as the mesh's own order, edge set for edge set
        let mut own = Vec::new();
        FacePlanes::new(&t.mesh).facing_packed(&t.mesh, l, false, &mut own);
        let mut a = plain(scan.edges(), &bits, &order);
        let mut b = possible_silhouette_packed(&t.manifold_edges, &own);
        let key = |e: &SilhouetteEdge| (e.a, e.b, e.lit, e.unlit);
        a.sort_by_key(key);
        b.sort_by_key(key);
        assert_eq!(a, b);
    }
}

#[test]
fn doubled_and_self_edges() {
    // two edges between the same two triangles, an edge of a triangle with itself, and
    // distances over 64 (shifts across words)
    let mk = |t0: u32, t1: u32, a: u32| ManifoldEdge { a, b: a + 1, t0, c0: 0, t1, c1: 1 };
    let mut edges = Vec::new();
    for lo in 0..300u32 {
        edges.push(mk(lo, lo + 70, 2 * lo));
        edges.push(mk(lo + 128, lo, 2 * lo + 1));
    }
    edges.push(mk(5, 75, 9999));
    edges.push(mk(7, 7, 10_001));
    for pattern in [0x5555_5555_5555_5555u64, 0xffff_0000_ffff_0000, 0x0123_4567_89ab_cdef] {
        let bits: Vec<u64> = (0..8).map(|i| pattern.rotate_left(i * 7)).collect();
        let scan = check(edges.clone(), &bits);
        assert_eq!((scan.near.deltas.len(), scan.far_classes.len()), (0, 2));
        check(edges.clone(), &bits[..3]);
    }
}

#[test]
fn cube_and_empty() {
    let t = Topology::build(&cube(Vec3::ZERO, 1.0));
    check(t.manifold_edges.clone(), &[0b1010_1010_1010]);
    check(Vec::new(), &[u64::MAX]);
    assert_eq!(EdgeScan::new(Vec::new()).bytes(), 0);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]
    #[test]
    fn random_pairs_and_bits(
        pairs in prop::collection::vec((0u32..700, 0u32..80), 0..600),
        bits in prop::collection::vec(any::<u64>(), 0..13),
    ) {
        let edges: Vec<ManifoldEdge> = pairs
            .iter()
            .enumerate()
            .map(|(i, &(t, d))| ManifoldEdge { a: i as u32, b: i as u32 + 1, t0: t, c0: 0, t1: t + d % 3 * (d / 3), c1: 2 })
            .collect();
        check(edges.clone(), &bits);
        // any order: a random permutation of the triangles
        let n = 800usize;
        let mut perm: Vec<u32> = (0..n as u32).collect();
        let mut x = bits.first().copied().unwrap_or(7) | 1;
        for i in (1..n).rev() {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            perm.swap(i, (x % (i as u64 + 1)) as usize);
        }
        check_in(edges, &bits, &TriangleOrder::from_slots(perm).unwrap());
    }
}
