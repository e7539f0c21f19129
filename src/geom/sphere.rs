//! Analytic sphere casters (lecture notes §2.1): the exact sphere, its tangency circle with
//! respect to a light, and the shadow volume built from that circle as an n-gon.
//!
//! # The volume
//!
//! Seen from a point light `L` at distance `d` from the centre `C`, a sphere of radius `r`
//! is bounded by the cone of half-angle `α`, `sin α = r / d`, which touches it along the
//! *tangency circle*: centre `C + u r²/d` (`u` the unit vector from `C` to `L`), radius
//! `ρ = r √(d² - r²) / d`. A directional light's tangency circle is the great circle
//! orthogonal to it (a cylinder, `ρ = r`).
//!
//! The volume drawn is the one of a closed polyhedron whose silhouette from the light is an
//! n-gon *circumscribed* about the tangency circle (vertices at `ρ / cos(π/n)`):
//! - light cap: the flat n-gon in the tangency plane (normal towards the light);
//! - sides: each polygon edge extruded away from the light. An edge is tangent to the circle
//!   at its midpoint, so the plane through it and the light is tangent to the sphere: the
//!   sides are the tangent planes of a circumscribed pyramid, outside the sphere but for n
//!   points of contact;
//! - dark cap: the n-gon at infinity (point lights; a directional light's sides meet in one
//!   point at infinity and need none).
//!
//! **Circumscribed**, so that the volume contains the true shadow (every point the sphere
//! hides from the light is counted; the error is a thin rim of extra shadow, never a lit
//! hole), and so that the shadow of a polygon never falls inside the exact one.
//!
//! **Terminator.** The light cap lies in the tangency plane, which separates the sphere's lit
//! cap (`N·L > 0`, on the light's side of the plane) from its dark half. So the lit side is
//! never inside the volume: the volume does not darken the sphere where illumination's
//! analytic `N·L` lights it, and the dark half, inside the volume, has `N·L < 0` anyway.
//! Inside the circle the cap is inside the sphere, hence behind every visible point (z-fail
//! may count it with depth compare NEVER, as for mesh light caps); only the corners of the
//! circumscribed polygon stick out of the sphere, by at most `ρ (sec(π/n) - 1)`, below half
//! a pixel by the rule below.
//!
//! # Choosing n
//!
//! At a distance `s` from a point light along the shadow's axis the polygon's cone is wider
//! than the true one by `s tan α (sec(π/n) - 1)` (a directional light's cylinder:
//! `r (sec(π/n) - 1)`). Seen from the eye at distance `D`, that is `width / D` radians, and one pixel is
//! `pixel_angle` radians (the smallest pixel of the view, at its corners). [`auto_segments`]
//! takes the worst ratio along the axis (sampled geometrically from the sphere to 10^6 times
//! its distance, plus the axis point closest to the eye; `D` is the distance from the eye to
//! the cone's cross-section there, at least the near distance) and the smallest `n` whose
//! error there is at most half a pixel, clamped to [`MIN_SEGMENTS`] ..= [`MAX_SEGMENTS`]. The rule
//! bounds the error perpendicular to the light's rays; on a receiver at a grazing angle to
//! the light the shadow's edge is stretched by `1 / cos` (that is where the comparison's band
//! and the reference's ambiguity take over).

use glam::{DVec3, DVec4};

/// Fewest segments [`auto_segments`] picks.
pub const MIN_SEGMENTS: u32 = 8;
/// Most segments [`auto_segments`] picks, and the largest `segments` a scene may ask for.
pub const MAX_SEGMENTS: u32 = 4096;
/// Largest accepted |centre| + radius (beyond this f32 eye-relative rendering loses the
/// sphere's shape; scene files are refused).
pub const MAX_EXTENT: f64 = 1e7;

/// An exact sphere, world space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sphere {
    /// Centre.
    pub center: DVec3,
    /// Radius (> 0).
    pub radius: f64,
}

/// The tangency circle of a sphere seen from a light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tangency {
    /// Unit vector from the sphere's centre towards the light (the circle's normal).
    pub axis: DVec3,
    /// The circle's centre.
    pub center: DVec3,
    /// The circle's radius `ρ`.
    pub radius: f64,
    /// `tan α` of the tangent cone (0 for a directional light: a cylinder).
    pub tan_half_angle: f64,
    /// Distance from a point light to the tangency plane (`None`: directional).
    pub light_distance: Option<f64>,
}

impl Sphere {
    /// A description of what is wrong with this sphere (non-finite, radius <= 0, too large),
    /// or `None`.
    pub fn problem(&self) -> Option<String> {
        if !self.center.is_finite() || !self.radius.is_finite() {
            return Some(format!("centre {} / radius {} not finite", self.center, self.radius));
        }
        if !(self.radius > 0.0) {
            return Some(format!("radius must be > 0, got {}", self.radius));
        }
        if self.center.abs().max_element() + self.radius > MAX_EXTENT {
            return Some(format!("centre {} with radius {} reaches beyond {MAX_EXTENT:e}", self.center, self.radius));
        }
        None
    }

    /// Whether `p` is inside or on the sphere (within a relative `1e-9` of the radius).
    pub fn contains(&self, p: DVec3) -> bool {
        (p - self.center).length() <= self.radius * (1.0 + 1e-9)
    }

    /// The tangency circle for a light `(xyz, 1)` (point) or `(towards-light, 0)`
    /// (directional); `None` when a point light is inside or on the sphere (within a
    /// relative `1e-6`: no cone touches it there).
    pub fn tangency(&self, light: DVec4) -> Option<Tangency> {
        if light.w == 0.0 {
            let axis = light.truncate().normalize_or_zero();
            if axis == DVec3::ZERO || !axis.is_finite() {
                return None;
            }
            return Some(Tangency { axis, center: self.center, radius: self.radius, tan_half_angle: 0.0, light_distance: None });
        }
        let l = light.truncate() / light.w;
        let to_l = l - self.center;
        let d = to_l.length();
        let r = self.radius;
        if !(d > r * (1.0 + 1e-6)) {
            return None;
        }
        let axis = to_l / d;
        let rho = r * ((d - r) * (d + r)).sqrt() / d;
        let offset = r * r / d;
        Some(Tangency {
            axis,
            center: self.center + axis * offset,
            radius: rho,
            tan_half_angle: r / ((d - r) * (d + r)).sqrt(),
            light_distance: Some(d - offset),
        })
    }

    /// The nearest `t` in `(t_min, t_max)` where the ray `o + t d` (unit `d`) meets the
    /// sphere, entering or leaving it.
    pub fn ray_hit(&self, o: DVec3, d: DVec3, t_min: f64, t_max: f64) -> Option<f64> {
        let oc = o - self.center;
        let b = oc.dot(d);
        let c = oc.length_squared() - self.radius * self.radius;
        let disc = b * b - c;
        if !(disc >= 0.0) {
            return None;
        }
        let s = disc.sqrt();
        // The near root without cancellation: q = -(b + sign(b) s), roots c/q and q.
        let q = -(b + s.copysign(b));
        let (mut t0, mut t1) = if q != 0.0 { (c / q, q) } else { (0.0, 0.0) };
        if t0 > t1 {
            std::mem::swap(&mut t0, &mut t1);
        }
        [t0, t1].into_iter().find(|&t| t > t_min && t < t_max)
    }
}

/// An orthonormal pair spanning the plane orthogonal to unit `n`, with `e1 × e2 = n`.
pub fn plane_basis(n: DVec3) -> (DVec3, DVec3) {
    let s = 1f64.copysign(n.z);
    let a = -1.0 / (s + n.z);
    let b = n.x * n.y * a;
    let e1 = DVec3::new(1.0 + s * n.x * n.x * a, s * b, -s * n.x);
    let e2 = DVec3::new(b, s + n.y * n.y * a, -n.y);
    if e1.cross(e2).dot(n) >= 0.0 {
        (e1, e2)
    } else {
        (e2, e1)
    }
}

/// The `n` vertices of the polygon circumscribed about the tangency circle, counter-clockwise
/// seen from the light.
pub fn polygon(t: &Tangency, n: u32) -> Vec<DVec3> {
    let n = n.max(3);
    let (e1, e2) = plane_basis(t.axis);
    let big = t.radius / (std::f64::consts::PI / n as f64).cos();
    (0..n)
        .map(|k| {
            let a = std::f64::consts::TAU * k as f64 / n as f64;
            t.center + (e1 * a.cos() + e2 * a.sin()) * big
        })
        .collect()
}

/// The shadow volume's triangles relative to `origin` (the sphere's centre keeps them
/// precise in f32): `(sides and dark cap, light cap)`, outward, counter-clockwise seen from
/// outside. Vertices with `w = 0` are extruded to infinity away from the light by the
/// volume shader (`(p.xyz * L.w - L.xyz, 0)`, the same convention as mesh casters).
pub fn volume_triangles(t: &Tangency, n: u32, directional: bool, origin: DVec3) -> (Vec<[DVec4; 3]>, Vec<[DVec4; 3]>) {
    let ring: Vec<DVec3> = polygon(t, n).into_iter().map(|p| p - origin).collect();
    let n = ring.len();
    let fin = |p: DVec3| p.extend(1.0);
    let inf = |p: DVec3| p.extend(0.0);
    let mut volume = Vec::with_capacity(3 * n);
    for k in 0..n {
        let (a, b) = (ring[k], ring[(k + 1) % n]);
        volume.push([fin(a), inf(a), fin(b)]);
        if !directional {
            volume.push([fin(b), inf(a), inf(b)]);
        }
    }
    if !directional {
        for k in 1..n - 1 {
            volume.push([inf(ring[0]), inf(ring[k + 1]), inf(ring[k])]);
        }
    }
    let cap = (1..n - 1).map(|k| [fin(ring[0]), fin(ring[k]), fin(ring[k + 1])]).collect();
    (volume, cap)
}

/// What [`auto_segments`] needs to know about the view.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ViewScale {
    /// The eye, world space.
    pub eye: DVec3,
    /// The smallest angle one pixel subtends (radians).
    pub pixel_angle: f64,
    /// Distance from the eye to the near plane (nothing closer is seen).
    pub near: f64,
}

impl ViewScale {
    /// The scale of `camera` rendering a `width` x `height` image (the renderer's projection:
    /// vertical field of view `fov_y_deg`, square pixels).
    pub fn from_camera(camera: &crate::geom::Camera, width: u32, height: u32) -> ViewScale {
        let ty = ((camera.fov_y_deg as f64).to_radians() * 0.5).tan();
        let tx = ty * width.max(1) as f64 / height.max(1) as f64;
        let cos2 = 1.0 / (1.0 + tx * tx + ty * ty);
        ViewScale { eye: camera.eye.as_dvec3(), pixel_angle: 2.0 * ty / height.max(1) as f64 * cos2, near: camera.near as f64 }
    }
}

/// The worst ratio (world width of the polygon's excess / distance from the eye), per unit of
/// `sec(π/n) - 1`, along the shadow's axis.
fn worst_ratio(sphere: &Sphere, t: &Tangency, light: DVec4, view: &ViewScale) -> f64 {
    let away = -t.axis;
    // Cross-section radius allowance for n >= MIN_SEGMENTS.
    let widen = 1.0 / (std::f64::consts::PI / MIN_SEGMENTS as f64).cos();
    let mut worst = 0.0f64;
    let mut at = |axis_point: DVec3, excess_per_unit: f64, section: f64| {
        let dist = ((axis_point - view.eye).length() - section * widen).max(view.near);
        worst = worst.max(excess_per_unit / dist);
    };
    match t.light_distance {
        Some(s0) => {
            let l = light.truncate() / light.w;
            let s_eye = (view.eye - l).dot(away);
            let samples = (0..=240).map(|i| s0 * 10f64.powf(i as f64 / 40.0)).chain((s_eye > s0).then_some(s_eye));
            for s in samples {
                at(l + away * s, s * t.tan_half_angle, s * t.tan_half_angle);
            }
        }
        None => {
            let c = sphere.center;
            let s_eye = (view.eye - c).dot(away);
            let scale = sphere.radius.max(1e-30);
            let samples =
                std::iter::once(0.0).chain((0..=240).map(|i| scale * 10f64.powf(i as f64 / 40.0))).chain((s_eye > 0.0).then_some(s_eye));
            for s in samples {
                at(c + away * s, sphere.radius, sphere.radius);
            }
        }
    }
    worst
}

/// The largest shadow error in pixels of the `n`-gon volume ([module docs](self)).
pub fn shadow_error_px(sphere: &Sphere, t: &Tangency, light: DVec4, view: &ViewScale, n: u32) -> f64 {
    let sec = 1.0 / (std::f64::consts::PI / n.max(3) as f64).cos();
    (sec - 1.0) * worst_ratio(sphere, t, light, view) / view.pixel_angle
}

/// The smallest `n` in [`MIN_SEGMENTS`] ..= [`MAX_SEGMENTS`] whose [`shadow_error_px`] is at most
/// half a pixel (`MAX_SEGMENTS` when none is).
pub fn auto_segments(sphere: &Sphere, t: &Tangency, light: DVec4, view: &ViewScale) -> u32 {
    let k = worst_ratio(sphere, t, light, view) / view.pixel_angle;
    if !(k > 0.0) || !k.is_finite() {
        return if k == 0.0 { MIN_SEGMENTS } else { MAX_SEGMENTS };
    }
    // sec(π/n) - 1 <= 0.5 / k  <=>  π/n <= acos(1 / (1 + 0.5/k)).
    let limit = (1.0 / (1.0 + 0.5 / k)).acos();
    let n = (std::f64::consts::PI / limit).ceil();
    if !n.is_finite() || n > MAX_SEGMENTS as f64 {
        return MAX_SEGMENTS;
    }
    let mut n = (n as u32).max(MIN_SEGMENTS);
    // Guard the rounding of the closed form.
    while n < MAX_SEGMENTS && shadow_error_px(sphere, t, light, view, n) > 0.5 {
        n += 1;
    }
    n
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sphere() -> Sphere {
        Sphere { center: DVec3::new(1.0, 2.0, -0.5), radius: 0.75 }
    }

    #[test]
    fn tangency_circle_touches_the_sphere_and_the_cone() {
        let s = sphere();
        let l = DVec3::new(4.0, 6.0, 1.0);
        let t = s.tangency(l.extend(1.0)).unwrap();
        let (e1, e2) = plane_basis(t.axis);
        for k in 0..16 {
            let a = k as f64 * 0.4;
            let p = t.center + (e1 * a.cos() + e2 * a.sin()) * t.radius;
            // On the sphere, and the ray from the light is tangent there (orthogonal to the normal).
            assert!(((p - s.center).length() - s.radius).abs() < 1e-12);
            assert!((p - l).normalize().dot((p - s.center).normalize()).abs() < 1e-12);
        }
        assert!(s.tangency(s.center.extend(1.0)).is_none());
        assert!(s.tangency((s.center + DVec3::X * s.radius).extend(1.0)).is_none());
        let dir = s.tangency(DVec4::new(0.0, 1.0, 0.0, 0.0)).unwrap();
        assert_eq!(dir.radius, s.radius);
    }

    #[test]
    fn volume_is_closed_and_outward() {
        let s = sphere();
        let l = DVec3::new(4.0, 6.0, 1.0);
        let t = s.tangency(l.extend(1.0)).unwrap();
        let (vol, cap) = volume_triangles(&t, 12, false, s.center);
        // Finite stand-in: extrude w = 0 vertices to 100 times their distance from the light.
        let lo = l - s.center;
        let fin = |v: DVec4| if v.w == 1.0 { v.truncate() } else { lo + (v.truncate() - lo) * 100.0 };
        let tris: Vec<[DVec3; 3]> = vol.iter().chain(&cap).map(|t| t.map(fin)).collect();
        // Closed: every directed edge has its reverse.
        let key = |p: DVec3| (p * 1e6).round().as_i64vec3().to_array();
        let mut edges = std::collections::HashMap::new();
        for t in &tris {
            for i in 0..3 {
                *edges.entry((key(t[i]), key(t[(i + 1) % 3]))).or_insert(0) += 1;
            }
        }
        for ((a, b), c) in &edges {
            assert_eq!(edges.get(&(*b, *a)), Some(c), "edge not matched");
        }
        // Outward: positive signed volume (divergence theorem).
        let vol6: f64 = tris.iter().map(|t| t[0].dot(t[1].cross(t[2]))).sum();
        assert!(vol6 > 0.0, "volume {vol6}");
        // The light cap faces the light.
        for c in &cap {
            let [a, b, cc] = c.map(fin);
            assert!((b - a).cross(cc - a).dot(t.axis) > 0.0);
        }
    }

    #[test]
    fn ray_hits_are_exact() {
        let s = sphere();
        let o = DVec3::new(1.0, 2.0, 10.0);
        let t = s.ray_hit(o, DVec3::NEG_Z, 0.0, f64::INFINITY).unwrap();
        assert!((t - (10.5 - 0.75)).abs() < 1e-12);
        assert!(s.ray_hit(o, DVec3::Z, 0.0, f64::INFINITY).is_none());
        assert!(s.ray_hit(o, DVec3::NEG_Z, 0.0, 5.0).is_none());
    }

    #[test]
    fn auto_n_bounds_the_error_and_grows_with_size() {
        let view = |eye: DVec3| ViewScale { eye, pixel_angle: 2.0 * (30f64.to_radians()).tan() / 1080.0, near: 0.1 };
        let s = Sphere { center: DVec3::new(0.0, 1.0, 0.0), radius: 0.5 };
        let light = DVec4::new(0.0, 6.0, 0.0, 1.0);
        let t = s.tangency(light).unwrap();
        let near = auto_segments(&s, &t, light, &view(DVec3::new(0.0, 2.0, 4.0)));
        let far = auto_segments(&s, &t, light, &view(DVec3::new(0.0, 2.0, 40.0)));
        assert!(near > far, "near {near} far {far}");
        for n in [near, far] {
            assert!((MIN_SEGMENTS..=MAX_SEGMENTS).contains(&n));
        }
        assert!(shadow_error_px(&s, &t, light, &view(DVec3::new(0.0, 2.0, 4.0)), near) <= 0.5);
        assert!(shadow_error_px(&s, &t, light, &view(DVec3::new(0.0, 2.0, 4.0)), near - 1) > 0.5 || near == MIN_SEGMENTS);
    }
}
