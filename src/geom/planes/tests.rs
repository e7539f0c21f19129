//! `FacePlanes` against the exact predicate: block bounds, super-blocks and scan orders.

use super::*;
use crate::geom::cpu::on_each_copy;
use crate::geom::testmesh::{grid, uv_sphere};
use proptest::prelude::*;

impl FacePlanes {
    /// Blocks the light decides whole (no per-triangle dot products).
    fn decided_blocks(&self, l: Vec4, flip: bool) -> usize {
        let Some((lf, e)) = self.error_bound(l) else { return 0 };
        let lf = if flip { -lf } else { lf };
        let probe = Probe::new(lf, e as f64);
        self.blocks.iter().map(|b| b.test(&probe)).map(|(ones, zeros)| (ones | zeros).count_ones() as usize).sum()
    }
}

#[test]
fn side_by_side_block_tests_take_each_blocks_decision() {
    // the 8 tests of a super-block at once are the single tests, bit for bit
    let mut m = uv_sphere(1.0, 90, 45);
    m.triangles.truncate(m.triangles.len() - 100); // a last super-block with missing blocks
    let planes = FacePlanes::new(&m);
    let mut x = 0x9e37_79b9_7f4a_7c15u64;
    let mut next = || {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        (x % 2001) as f32 / 500.0 - 2.0
    };
    let mut decided = 0;
    for k in 0..200 {
        let l = Vec4::new(next(), next(), next(), [0.0, 1.0, -1.0][k % 3]);
        let Some((lf, e)) = planes.error_bound(l) else { continue };
        let probe = Probe::new(lf, e as f64);
        for b in &planes.blocks {
            let (ones, zeros) = b.test(&probe);
            for i in 0..8 {
                let (all, none) = b.get(i).test(&probe);
                assert_eq!((all, none), ((ones >> i) & 1 == 1, (zeros >> i) & 1 == 1));
                decided += usize::from(all | none);
            }
        }
    }
    assert!(decided > 1000, "{decided}");
}

fn exact(m: &Mesh, l: Vec4, flip: bool) -> Vec<u64> {
    let mut w = vec![0u64; m.triangles.len().div_ceil(64)];
    for t in 0..m.triangles.len() {
        if exact_bit(m, t, l, flip) {
            w[t / 64] |= 1 << (t % 64);
        }
    }
    w
}

#[test]
fn whole_blocks_decided_and_exact() {
    let mut bits = Vec::new();
    for (r, off) in [(1.0f32, Vec3::ZERO), (1e-3, Vec3::splat(1e4)), (5e3, Vec3::new(-3e6, 2e6, 1e6))] {
        let mut m = uv_sphere(r, 400, 201);
        for p in &mut m.positions {
            *p += off;
        }
        let planes = FacePlanes::new(&m);
        for l in [
            (off + Vec3::new(3.0, 2.0, 1.0) * r).extend(1.0),
            (off + Vec3::new(0.0, 1.0001, 0.0) * r).extend(1.0),
            Vec3::new(-1.0, 0.5, 0.2).extend(0.0),
            (off * 2.0 + Vec3::new(6.0, 4.0, 2.0) * r).extend(2.0),
        ] {
            for flip in [false, true] {
                let bits = on_each_copy(|| {
                    planes.facing_packed(&m, l, flip, &mut bits);
                    bits.clone()
                });
                assert_eq!(bits, exact(&m, l, flip), "r {r} off {off} light {l} flip {flip}");
            }
            if off == Vec3::ZERO && l.w != 0.0 && l.y != 1.0001 {
                let decided = planes.decided_blocks(l, false);
                assert!(decided * 2 > planes.len().div_ceil(64), "{decided} of {} blocks decided", planes.len().div_ceil(64));
            }
        }
    }
}

#[test]
fn ordered_planes_give_the_permuted_bits() {
    // a shuffled sphere: in its own order few blocks are decidable; in the spatial order
    // most are, and every bit is the exact one of the triangle in its slot
    let m = crate::geom::testmesh::shuffled(&uv_sphere(1.0, 200, 101));
    let all: Vec<u32> = (0..m.triangles.len() as u32).collect();
    let order = TriangleOrder::spatial(&m, &[&all]);
    let (own, ordered) = (FacePlanes::new(&m), FacePlanes::with_order(&m, order.clone()));
    assert_eq!(ordered.order(), &order);
    let mut far = m.clone();
    far.positions[0] *= 1e30; // out of the filter's range: every triangle exact
    let far_planes = FacePlanes::with_order(&far, order.clone());
    let mut bits = Vec::new();
    for l in [Vec4::new(3.0, 2.0, 1.0, 1.0), Vec4::new(0.0, 0.99, 0.0, 1.0), Vec4::new(-1.0, 0.5, 0.2, 0.0)] {
        for flip in [false, true] {
            let want = exact(&m, l, flip);
            ordered.facing_packed(&m, l, flip, &mut bits);
            for t in 0..m.triangles.len() as u32 {
                let s = order.slot(t);
                assert_eq!(ordered.bit(&bits, t), (want[t as usize / 64] >> (t % 64)) & 1 != 0);
                assert_eq!(ordered.bit(&bits, t), (bits[s as usize / 64] >> (s % 64)) & 1 != 0);
            }
            let mut unpermuted = Vec::new();
            ordered.unpermute(&bits, &mut unpermuted);
            assert_eq!(unpermuted, want);
            let mut threaded = Vec::new();
            ordered.facing_packed_threads(&m, l, flip, 3, &mut threaded);
            assert_eq!(threaded, bits);
            let want_far = exact(&far, l, flip);
            far_planes.facing_packed(&far, l, flip, &mut bits);
            for t in 0..m.triangles.len() as u32 {
                assert_eq!(far_planes.bit(&bits, t), (want_far[t as usize / 64] >> (t % 64)) & 1 != 0);
            }
        }
        if l.w != 0.0 && l.y != 0.99 {
            let (a, b) = (own.decided_blocks(l, false), ordered.decided_blocks(l, false));
            assert!(
                a * 10 < own.len().div_ceil(64) && b * 2 > ordered.len().div_ceil(64),
                "{a} / {b} of {} blocks decided",
                own.len().div_ceil(64)
            );
        }
    }
    // the GPU's planes stay in triangle order
    let (p0, p1) = (own.planes_xyzd(), ordered.planes_xyzd());
    assert_eq!(p0, p1);
    // a mesh with another triangle count: every triangle exact, in the mesh's order
    let mut fewer = m.clone();
    fewer.triangles.truncate(100);
    ordered.facing_packed(&fewer, Vec4::new(3.0, 2.0, 1.0, 1.0), false, &mut bits);
    assert_eq!(bits, exact(&fewer, Vec4::new(3.0, 2.0, 1.0, 1.0), false));
    let mut re = ordered.clone();
    re.recompute(&fewer);
    assert!(re.order().is_identity());
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]
    #[test]
    fn flat_grids_lights_a_hair_off_the_plane(z in -1e-3f32..1e-3, h in prop_oneof![Just(0.0f32), -1e-6f32..1e-6, -1e-3f32..1e-3], x in -50f32..50.0, big in prop_oneof![Just(1.0f32), Just(1e5)]) {
        // 8 blocks of exactly coplanar (or tilted by h) triangles: their spread is zero,
        // so the block test decides them from lights barely off the plane; it must never
        // disagree with the exact predicate
        let m = grid(17, 17, |i, j| Vec3::new(i as f32, j as f32, z + (i as f32) * h) * big);
        let planes = FacePlanes::new(&m);
        let mut bits = Vec::new();
        for lz in [0.0f32, 1e-7, -1e-7, 1e-4, 3.0] {
            let l = (Vec3::new(x, 4.0, z + lz) * big).extend(1.0);
            for flip in [false, true] {
                let bits = on_each_copy(|| {
                    planes.facing_packed(&m, l, flip, &mut bits);
                    bits.clone()
                });
                prop_assert_eq!(&bits, &exact(&m, l, flip));
            }
        }
        let far = Vec3::new(x, 4.0, z + 3.0) * big;
        prop_assert!(planes.decided_blocks(far.extend(1.0), false) > 0 || h.abs() > 1e-4);
    }
}
