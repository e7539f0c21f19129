//! Conservative facing bounds of a set of triangles: a **normal cone** (an axis and the cosine
//! of a half-angle that contains every triangle's unit normal) and a **bounding sphere** of
//! their vertices. Together they prove, for a homogeneous light, that every triangle of the
//! set faces it strictly the same way ([`same_facing`]), so that a mesh-shader task stage may
//! drop a meshlet that would emit nothing (`shaders/extrude.wgsl`).
//!
//! # The test
//!
//! A triangle with unit normal `n` and a vertex `p` faces the light `L` (point `L.xyz` when
//! `L.w != 0`, direction `L.xyz` when `L.w = 0`; as the GPU's exact facing stage reads it)
//! iff `n · (L.xyz - k p) > 0`, `k = 1` for a point light and `0` for a directional one; the
//! vertex chosen does not matter, since `n` is orthogonal to the triangle's edges. With `v =
//! L.xyz - k c` (`c` the sphere's centre, `r` its radius, so `|c - p| <= r`):
//! `n · (L.xyz - k p) = n · v + k n · (c - p) >= n · v - k r`. If every normal is within the
//! angle `θ` of the unit axis `a`, and `φ` is the angle between `a` and `v`, then
//! `n · v >= |v| cos(θ + φ) = cos θ (a · v) - sin θ |a × v|` while `θ + φ <= π`. So
//!
//! * all strictly light-facing if `cos θ (a · v) - sin θ |a × v| > k r`,
//! * all strictly facing away if `cos θ (a · v) + sin θ |a × v| < -k r`
//!
//! (the first needs `θ + φ < π/2`, the second `φ - θ > π/2`, both implied when `θ < π/2`).
//! A light inside the sphere (`|v| <= r`) or a cone of `θ >= 85°` decides nothing.
//!
//! # Conservative in floating point
//!
//! The facing it must agree with is the EXACT sign of orient3d of the f32 vertices
//! ([`crate::geom::predicates::facing_exact`], bit for bit the GPU's facing bits). So the
//! construction works in f64 on the f32 vertices and widens everything it rounds: each
//! normal's direction error (the f64 cross product's error bound; a triangle whose normal that
//! bound cannot fix, degenerate or a sliver, makes the set undecidable: a degenerate
//! triangle's bit is 0 whatever the light), the half-angle (rounded up, its cosine stored
//! rounded down, the sine derived from it rounded up), the radius (rounded up about the f32
//! centre). The test itself runs in f32 on the GPU, so it asks for a margin of `2^-16`
//! (about 500 f32 ulps) of `|L.xyz| + k (|c| + r)` beyond the bound: far more than its own
//! rounding. A NaN or infinity anywhere decides nothing (every comparison is false).

use glam::{DVec3, Vec3, Vec4};

/// The widest half-angle a cone may have and still decide anything (85°).
pub const MAX_HALF_ANGLE: f64 = 85.0 * std::f64::consts::PI / 180.0;

/// The margin of the test, relative to `|L.xyz| + k (|c| + r)`: `2^-16`.
pub const TEST_MARGIN: f32 = 1.0 / 65536.0;

/// A cone containing the unit normals of a set of triangles: `axis` (unit to f32 precision)
/// and `cos`, the cosine of its half-angle, rounded down. `cos = 0` (and a zero axis, as
/// [`FacingCone::NONE`]) decides nothing.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FacingCone {
    /// The cone's axis.
    pub axis: Vec3,
    /// The cosine of its half-angle (at least `cos 85°`), or 0: undecidable.
    pub cos: f32,
}

impl FacingCone {
    /// The cone that decides nothing (empty sets, degenerate or sliver triangles, normals
    /// spread over more than 85° from their mean, non-finite vertices).
    pub const NONE: FacingCone = FacingCone { axis: Vec3::ZERO, cos: 0.0 };

    /// Whether the cone can decide anything.
    pub fn decides(&self) -> bool {
        self.cos > 0.0
    }

    /// The sine of the half-angle the test uses: `sqrt(1 - cos²)` rounded up, exactly as the
    /// task shader computes it (its own rounding is covered by the factor).
    pub fn sin(&self) -> f32 {
        (1.0 - self.cos * self.cos).max(0.0).sqrt() * (1.0 + 1.0 / 1048576.0)
    }

    /// The cone of the triangles `tris` (f32 vertices, counter-clockwise from their front),
    /// widened for every rounding (see the module docs).
    pub fn of(tris: &[[Vec3; 3]]) -> FacingCone {
        if tris.is_empty() {
            return FacingCone::NONE;
        }
        let mut normals = Vec::with_capacity(tris.len());
        let mut deviation = 0.0f64;
        let mut sum = DVec3::ZERO;
        for t in tris {
            let [p0, p1, p2] = t.map(|v| v.as_dvec3());
            if !(p0.is_finite() && p1.is_finite() && p2.is_finite()) {
                return FacingCone::NONE;
            }
            let (e1, e2) = (p1 - p0, p2 - p0);
            let n = e1.cross(e2);
            // |n - n_exact| <= 8 ε64 |e1| |e2| per component, the differences included: 1e-14
            // (45 ε64) of |e1| |e2| bounds the vector's error.
            let err = 1e-14 * e1.length() * e2.length();
            let len = n.length();
            if !(len.is_finite() && len > 1e3 * err && len > 0.0) {
                return FacingCone::NONE;
            }
            // the direction's error: asin(err / len) <= 1.01 err / len for err / len <= 1e-3
            deviation = deviation.max(1.01 * err / len);
            let u = n / len;
            normals.push(u);
            sum += u;
        }
        let slen = sum.length();
        if !(slen > 1e-3 * tris.len() as f64) {
            return FacingCone::NONE;
        }
        let axis = (sum / slen).as_vec3();
        let a = axis.as_dvec3();
        let alen = a.length();
        let min_cos = normals.iter().map(|n| n.dot(a) / alen).fold(1.0f64, f64::min);
        // the half-angle about the stored axis, widened by the normals' error and by the
        // f64 rounding of acos and of the dot products
        let theta = min_cos.clamp(-1.0, 1.0).acos() + deviation + 1e-6;
        if theta >= MAX_HALF_ANGLE {
            return FacingCone::NONE;
        }
        // rounded down (so the angle it stands for is wider)
        let cos = down(theta.cos());
        FacingCone { axis, cos }
    }
}

/// A sphere containing every vertex of a set of triangles: `center` (f32) and `radius`,
/// rounded up about that f32 centre.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Bound {
    /// The sphere's centre.
    pub center: Vec3,
    /// Its radius (infinite for non-finite vertices: then nothing is decided).
    pub radius: f32,
}

impl Bound {
    /// The sphere about the centre of the points' bounding box.
    pub fn of(points: impl IntoIterator<Item = Vec3> + Clone) -> Bound {
        let (mut lo, mut hi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
        for p in points.clone() {
            lo = lo.min(p.as_dvec3());
            hi = hi.max(p.as_dvec3());
        }
        if !(lo.is_finite() && hi.is_finite()) {
            return Bound { center: Vec3::ZERO, radius: f32::INFINITY };
        }
        let center = ((lo + hi) * 0.5).as_vec3();
        let c = center.as_dvec3();
        let r = points.into_iter().map(|p| (p.as_dvec3() - c).length()).fold(0.0f64, f64::max);
        Bound { center, radius: up(r * (1.0 + 1e-9)) }
    }
}

/// Whether every triangle of the set bounded by `cone` and `sphere` faces the homogeneous
/// light `l` strictly the same way: `Some(true)` all light-facing, `Some(false)` all facing
/// away (the light strictly behind every plane), `None` undecided. Exactly the task shader's
/// f32 arithmetic (`shaders/extrude.wgsl`, `same_facing`).
pub fn same_facing(cone: FacingCone, sphere: Bound, l: Vec4) -> Option<bool> {
    let k = if l.w != 0.0 { 1.0 } else { 0.0 };
    let lx = l.truncate();
    let v = lx - sphere.center * k;
    let s = cone.axis.dot(v);
    let q = cone.axis.cross(v).length();
    let sin = cone.sin();
    let m = k * sphere.radius + TEST_MARGIN * (lx.length() + k * (sphere.center.length() + sphere.radius));
    if cone.cos * s - sin * q > m {
        Some(true)
    } else if cone.cos * s + sin * q < -m {
        Some(false)
    } else {
        None
    }
}

/// The largest f32 not above `x`.
fn down(x: f64) -> f32 {
    let f = x as f32;
    if f as f64 > x {
        f.next_down()
    } else {
        f
    }
}

/// The smallest f32 not below `x`.
fn up(x: f64) -> f32 {
    let f = x as f32;
    if (f as f64) < x {
        f.next_up()
    } else {
        f
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::predicates::facing_exact;
    use crate::geom::testmesh::{cube, torus, uv_sphere};

    /// A small deterministic generator (xorshift), for reproducible random lights.
    struct Rng(u64);
    impl Rng {
        fn next(&mut self) -> f32 {
            self.0 ^= self.0 << 13;
            self.0 ^= self.0 >> 7;
            self.0 ^= self.0 << 17;
            (self.0 >> 40) as f32 / (1u64 << 24) as f32
        }
        fn range(&mut self, lo: f32, hi: f32) -> f32 {
            lo + (hi - lo) * self.next()
        }
        fn unit(&mut self) -> Vec3 {
            loop {
                let v = Vec3::new(self.range(-1.0, 1.0), self.range(-1.0, 1.0), self.range(-1.0, 1.0));
                if v.length_squared() > 0.01 && v.length_squared() <= 1.0 {
                    return v.normalize();
                }
            }
        }
    }

    /// Checks the claim of [`same_facing`] against the exact predicate for every triangle:
    /// all light-facing, or all strictly facing away (light-facing once reversed).
    fn check(tris: &[[Vec3; 3]], l: Vec4) -> Option<bool> {
        let cone = FacingCone::of(tris);
        let sphere = Bound::of(tris.iter().flatten().copied());
        let got = same_facing(cone, sphere, l);
        if let Some(front) = got {
            for t in tris {
                if front {
                    assert!(facing_exact(t[0], t[1], t[2], l), "{t:?} not light-facing for {l}, cone {cone:?} {sphere:?}");
                } else {
                    assert!(facing_exact(t[0], t[2], t[1], l), "{t:?} not strictly away from {l}, cone {cone:?} {sphere:?}");
                }
            }
        }
        got
    }

    fn patches(mesh: &crate::geom::Mesh, size: usize) -> Vec<Vec<[Vec3; 3]>> {
        let tris: Vec<[Vec3; 3]> = mesh.triangles.iter().map(|t| t.map(|v| mesh.positions[v as usize])).collect();
        tris.chunks(size).map(|c| c.to_vec()).collect()
    }

    #[test]
    fn never_wrong_for_random_lights_on_spheres_tori_and_cubes() {
        let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
        let mut decided = 0;
        let mut total = 0;
        for mesh in [uv_sphere(1.0, 64, 32), torus(2.0, 0.5, 48, 16), cube(Vec3::new(0.3, -0.2, 0.1), 0.7)] {
            for patch in patches(&mesh, 24) {
                for i in 0..40 {
                    let l = match i % 4 {
                        // far point lights
                        0 => (rng.unit() * rng.range(3.0, 50.0)).extend(1.0),
                        // near ones, inside the mesh's bounds too
                        1 => (rng.unit() * rng.range(0.0, 1.5)).extend(1.0),
                        // directional
                        2 => rng.unit().extend(0.0),
                        // on the plane of one of the patch's triangles (grazing)
                        _ => {
                            let t = patch[(rng.next() * patch.len() as f32) as usize % patch.len()];
                            (t[0] + (t[1] - t[0]) * rng.range(-3.0, 3.0) + (t[2] - t[0]) * rng.range(-3.0, 3.0)).extend(1.0)
                        }
                    };
                    total += 1;
                    decided += check(&patch, l).is_some() as usize;
                }
            }
        }
        // an acceleration that decides most far and directional cases on fine meshes
        assert!(decided * 3 > total, "{decided} of {total} decided");
    }

    #[test]
    fn a_flat_patch_decides_every_light_off_its_plane_and_none_in_it() {
        // a planar grid: the cone is one normal (half-angle of the rounding only)
        let mut tris = Vec::new();
        for i in 0..4 {
            for j in 0..4 {
                let (x, y) = (i as f32 * 0.25, j as f32 * 0.25);
                let (a, b, c, d) =
                    (Vec3::new(x, y, 0.0), Vec3::new(x + 0.25, y, 0.0), Vec3::new(x + 0.25, y + 0.25, 0.0), Vec3::new(x, y + 0.25, 0.0));
                tris.push([a, b, c]);
                tris.push([a, c, d]);
            }
        }
        let cone = FacingCone::of(&tris);
        assert!(cone.decides() && cone.cos > 0.999_999);
        assert_eq!(check(&tris, Vec4::new(0.5, 0.5, 3.0, 1.0)), Some(true));
        assert_eq!(check(&tris, Vec4::new(0.5, 0.5, -3.0, 1.0)), Some(false));
        assert_eq!(check(&tris, Vec4::new(0.0, 0.0, 1.0, 0.0)), Some(true));
        assert_eq!(check(&tris, Vec4::new(0.3, 0.1, -1.0, 0.0)), Some(false));
        // in the plane, or grazing it, or inside the bounding sphere: undecided
        assert_eq!(check(&tris, Vec4::new(5.0, 0.5, 0.0, 1.0)), None);
        assert_eq!(check(&tris, Vec4::new(1.0, 0.0, 0.0, 0.0)), None);
        assert_eq!(check(&tris, Vec4::new(0.5, 0.5, 1e-3, 1.0)), None);
        assert_eq!(check(&tris, Vec4::new(50.0, 0.5, 1e-6, 1.0)), None);
    }

    #[test]
    fn undecidable_sets() {
        let z = Vec3::ZERO;
        let (x, y) = (Vec3::X, Vec3::Y);
        // empty, degenerate (its bit is 0 for every light), sliver, non-finite
        assert_eq!(FacingCone::of(&[]), FacingCone::NONE);
        assert!(!FacingCone::of(&[[z, x, y], [z, x, x * 2.0]]).decides());
        assert!(!FacingCone::of(&[[z, x, x * 2.0 + y * 1e-14]]).decides());
        assert!(!FacingCone::of(&[[z, x, Vec3::new(f32::NAN, 0.0, 0.0)]]).decides());
        // normals spread over more than the widest half-angle: opposite faces, and a box's
        // faces about a corner and the opposite corner
        assert!(!FacingCone::of(&[[z, x, y], [z, y, x]]).decides());
        assert!(!FacingCone::of(&[[z, x, y], [z, Vec3::Z, x], [z, y, Vec3::Z], [z, y, x]]).decides());
        // three faces about a corner fit in a cone of 54.7°
        assert!(FacingCone::of(&[[z, x, y], [z, Vec3::Z, x], [z, y, Vec3::Z]]).decides());
        // NONE decides nothing, for any light
        let b = Bound::of([z, x, y]);
        for l in [Vec4::new(0.0, 0.0, 5.0, 1.0), Vec4::new(0.0, 0.0, -1.0, 0.0), Vec4::ZERO] {
            assert_eq!(same_facing(FacingCone::NONE, b, l), None);
        }
        // a non-finite light decides nothing either
        let cone = FacingCone::of(&[[z, x, y]]);
        assert!(cone.decides());
        assert_eq!(same_facing(cone, b, Vec4::new(f32::INFINITY, 0.0, 5.0, 1.0)), None);
        assert_eq!(same_facing(cone, b, Vec4::new(f32::NAN, 0.0, 5.0, 1.0)), None);
        assert_eq!(same_facing(cone, b, Vec4::new(0.0, 0.0, 5.0, 1.0)), Some(true));
    }

    #[test]
    fn far_coordinates_stay_conservative() {
        // a patch far from the origin, lights near its planes at that scale
        let mut rng = Rng(42);
        let off = Vec3::new(1.0e5, -3.0e4, 2.0e5);
        let mesh = uv_sphere(1.0, 32, 16);
        for patch in patches(&mesh, 16) {
            let moved: Vec<[Vec3; 3]> = patch.iter().map(|t| t.map(|p| p * 10.0 + off)).collect();
            for _ in 0..30 {
                let l = (off + rng.unit() * rng.range(5.0, 200.0)).extend(1.0);
                check(&moved, l);
                check(&moved, rng.unit().extend(0.0));
            }
        }
    }

    #[test]
    fn bound_contains_its_points() {
        let mesh = torus(2.0, 0.5, 24, 12);
        let b = Bound::of(mesh.positions.iter().copied());
        for p in &mesh.positions {
            assert!((p.as_dvec3() - b.center.as_dvec3()).length() <= b.radius as f64);
        }
        assert_eq!(Bound::of([Vec3::new(f32::INFINITY, 0.0, 0.0)]).radius, f32::INFINITY);
    }
}
