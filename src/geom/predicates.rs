//! Exact orientation predicates: which side of a triangle's plane a (homogeneous) light is on.
//!
//! Every shadow-volume edge is derived from ONE facing bit per triangle, so the only thing
//! that has to be right is that bit. A fast f64 filter decides almost every triangle; the
//! few within its error bound fall back to Shewchuk's adaptive exact `orient3d` (crate
//! `robust`).
//!
//! Precision contract:
//! * Point light (`L.w != 0`): the light point is `L.xyz / L.w` (exact when `w == 1`, the
//!   only case the planner produces). The answer is the EXACT sign of
//!   `((p1-p0) x (p2-p0)) . (L - p0)` for the f32 inputs (promoted losslessly to f64).
//! * Directional light (`L.w == 0`): the answer is the sign of `det[p1-p0, p2-p0, d]`,
//!   `d = L.xyz`. The edge vectors are formed in f64; a difference of two f32 values is
//!   exact in f64 unless their exponents differ by more than ~29 binades (e.g. 1e5 vs 1e-5
//!   in one coordinate). The determinant of those f64 vectors is then evaluated EXACTLY
//!   (`orient3d(u, v, d, 0)`). So the result is exact for every mesh whose coordinates along
//!   one axis do not span more than ~9 orders of magnitude, and otherwise exact for edge
//!   vectors perturbed by at most 2^-53 relative — deterministic either way, which is all
//!   closedness needs.
//! * Zero (light in the plane, degenerate triangle) is NOT light-facing.

use glam::{DVec3, Vec3, Vec4};
use robust::{orient3d, Coord3D};

/// Error-bound factor of the f64 3x3 determinant filter (Shewchuk's o3derrboundA,
/// (7 + 56 eps) eps with eps = 2^-53, rounded up generously).
const ERRBOUND: f64 = 1.0e-15;

#[inline]
fn c(p: DVec3) -> Coord3D<f64> {
    Coord3D { x: p.x, y: p.y, z: p.z }
}

/// Fast filtered sign of det[a, b, cc] (rows), with `perm` = permanent of the absolute
/// values. Returns `Some(sign > 0)` when certain, `None` when within the error bound.
#[inline]
fn filtered_det(a: DVec3, b: DVec3, cc: DVec3) -> Option<bool> {
    let bxc = b.cross(cc);
    let det = a.dot(bxc);
    let perm = a.abs().dot(DVec3::new(
        (b.y * cc.z).abs() + (b.z * cc.y).abs(),
        (b.z * cc.x).abs() + (b.x * cc.z).abs(),
        (b.x * cc.y).abs() + (b.y * cc.x).abs(),
    ));
    let bound = ERRBOUND * perm;
    if det > bound {
        Some(true)
    } else if det < -bound {
        Some(false)
    } else {
        None
    }
}

/// Whether the triangle (p0, p1, p2) (CCW seen from its front) faces the homogeneous light
/// `l`: true iff the light is STRICTLY on the positive side of the triangle's plane.
#[inline]
pub fn facing(p0: Vec3, p1: Vec3, p2: Vec3, l: Vec4) -> bool {
    facing_f64(p0.as_dvec3(), p1.as_dvec3(), p2.as_dvec3(), l)
}

/// [`facing`] for points already in f64 (exact conversions of f32 values).
#[inline]
pub fn facing_f64(p0: DVec3, p1: DVec3, p2: DVec3, l: Vec4) -> bool {
    if l.w != 0.0 {
        let lp = if l.w == 1.0 { l.truncate().as_dvec3() } else { l.truncate().as_dvec3() / l.w as f64 };
        // sign((p1-p0) x (p2-p0) . (L-p0)) = sign det[p0-L, p1-L, p2-L]
        let (a, b, cc) = (p0 - lp, p1 - lp, p2 - lp);
        // det[p0-L, p1-L, p2-L] = -n . (L - p0)
        match filtered_det(a, b, cc) {
            Some(s) => !s,
            // robust: positive iff pd lies BELOW the plane of CCW (pa, pb, pc).
            None => orient3d(c(p0), c(p1), c(p2), c(lp)) < 0.0,
        }
    } else {
        let d = l.truncate().as_dvec3();
        let (u, v) = (p1 - p0, p2 - p0);
        // det[u, v, d] = (u x v) . d
        match filtered_det(u, v, d) {
            Some(s) => s,
            // orient3d(u, v, d, 0) = det[u, v, d] exactly.
            None => orient3d(c(u), c(v), c(d), c(DVec3::ZERO)) > 0.0,
        }
    }
}

/// The exact answer, always through `robust::orient3d` (for tests and cross-checks).
pub fn facing_exact(p0: Vec3, p1: Vec3, p2: Vec3, l: Vec4) -> bool {
    let (p0, p1, p2) = (p0.as_dvec3(), p1.as_dvec3(), p2.as_dvec3());
    if l.w != 0.0 {
        let lp = l.truncate().as_dvec3() / l.w as f64;
        orient3d(c(p0), c(p1), c(p2), c(lp)) < 0.0
    } else {
        orient3d(c(p1 - p0), c(p2 - p0), c(l.truncate().as_dvec3()), c(DVec3::ZERO)) > 0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tri() -> (Vec3, Vec3, Vec3) {
        // CCW seen from +z: normal +z.
        (Vec3::new(0.0, 0.0, 0.0), Vec3::new(1.0, 0.0, 0.0), Vec3::new(0.0, 1.0, 0.0))
    }

    #[test]
    fn basic_sides() {
        let (a, b, c) = tri();
        assert!(facing(a, b, c, Vec4::new(0.2, 0.2, 1.0, 1.0)));
        assert!(!facing(a, b, c, Vec4::new(0.2, 0.2, -1.0, 1.0)));
        assert!(facing(a, b, c, Vec4::new(0.0, 0.0, 1.0, 0.0)));
        assert!(!facing(a, b, c, Vec4::new(0.0, 0.0, -1.0, 0.0)));
        assert!(facing_exact(a, b, c, Vec4::new(0.2, 0.2, 1.0, 1.0)));
        assert!(facing_exact(a, b, c, Vec4::new(0.0, 0.0, 1.0, 0.0)));
    }

    #[test]
    fn light_in_plane_is_not_facing() {
        let (a, b, c) = tri();
        assert!(!facing(a, b, c, Vec4::new(5.0, -3.0, 0.0, 1.0)));
        assert!(!facing(a, b, c, Vec4::new(1.0, 1.0, 0.0, 0.0)));
        // tilted plane through exact f32 points
        let (p0, p1, p2) = (Vec3::new(0.1, 0.2, 0.3), Vec3::new(1.1, 0.7, -0.3), Vec3::new(0.3, 1.9, 0.5));
        // p0 + (p1-p0) + (p2-p0) is not exactly representable in general; use an affine
        // combination that is: the vertices themselves and the edge midpoint direction.
        for l in [p0, p1, p2] {
            assert!(!facing(p0, p1, p2, l.extend(1.0)));
            assert!(!facing(p1, p2, p0, l.extend(1.0)));
        }
        // directional light parallel to an edge lies in the plane
        assert!(!facing(a, b, c, Vec4::new(1.0, 0.0, 0.0, 0.0)));
    }

    #[test]
    fn near_plane_1e7() {
        let (a, b, c) = tri();
        assert!(facing(a, b, c, Vec4::new(0.3, 0.3, 1e-7, 1.0)));
        assert!(!facing(a, b, c, Vec4::new(0.3, 0.3, -1e-7, 1.0)));
        assert!(facing(a, b, c, Vec4::new(0.3, 0.3, 1e-7, 0.0)));
        assert!(!facing(a, b, c, Vec4::new(0.3, 0.3, -1e-7, 0.0)));
        // far light, tiny offset: filter must fall back and still be exact
        let l = Vec4::new(1e5, 1e5, 1e-7, 1.0);
        assert!(facing(a, b, c, l));
        assert_eq!(facing(a, b, c, l), facing_exact(a, b, c, l));
    }

    #[test]
    fn huge_coordinates() {
        let o = Vec3::splat(1e5);
        let (a, b, c) = (o, o + Vec3::new(1.0, 0.0, 0.0), o + Vec3::new(0.0, 1.0, 0.0));
        assert!(facing(a, b, c, (o + Vec3::new(0.5, 0.5, 0.0078125)).extend(1.0)));
        assert!(!facing(a, b, c, (o + Vec3::new(0.5, 0.5, -0.0078125)).extend(1.0)));
        assert!(!facing(a, b, c, (o + Vec3::new(7.0, -3.0, 0.0)).extend(1.0)));
        assert!(facing(a, b, c, Vec4::new(0.0, 0.0, 1e-7, 0.0)));
        let big = Vec3::new(1e5, -1e5, 1e5);
        // collinear huge triangle: never light-facing
        assert!(!facing(Vec3::ZERO, big, big * 2.0, Vec4::new(3.0, 4.0, 5.0, 1.0)));
        assert!(!facing(Vec3::ZERO, big, big * 2.0, Vec4::new(3.0, 4.0, 5.0, 0.0)));
    }

    #[test]
    fn tiny_triangles() {
        let s = 1e-3;
        let o = Vec3::new(0.5, 0.25, 2.0);
        let (a, b, c) = (o, o + Vec3::new(s, 0.0, 0.0), o + Vec3::new(0.0, s, 0.0));
        assert!(facing(a, b, c, Vec4::new(100.0, -50.0, 2.0 + 1e-6, 1.0)));
        assert!(!facing(a, b, c, Vec4::new(100.0, -50.0, 2.0 - 1e-6, 1.0)));
        assert!(!facing(a, b, c, Vec4::new(100.0, -50.0, 2.0, 1.0)));
        assert!(facing(a, b, c, Vec4::new(1.0, 1.0, 1e-9, 0.0)));
    }

    #[test]
    fn filter_agrees_with_exact_on_random() {
        let mut s = 12345u64;
        let mut r = || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            ((s >> 11) as f64 / (1u64 << 53) as f64) as f32 * 2.0 - 1.0
        };
        for i in 0..20000 {
            let a = Vec3::new(r(), r(), r());
            let b = Vec3::new(r(), r(), r());
            // every third case puts the light (nearly) in the plane
            let c = Vec3::new(r(), r(), r());
            let mut l = Vec4::new(r(), r(), r(), if i % 2 == 0 { 1.0 } else { 0.0 });
            if i % 3 == 0 {
                let p = a + (b - a) * 0.5;
                l = if l.w == 1.0 { p.extend(1.0) } else { (b - a).extend(0.0) };
            }
            assert_eq!(facing(a, b, c, l), facing_exact(a, b, c, l), "case {i}");
        }
    }
}
