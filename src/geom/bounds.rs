//! Conservative culling volumes: view frustum (homogeneous, infinite far), the viewport
//! occlusion pyramid of McGuire et al. (Figure 2), light scissor rectangle and depth bounds.
//!
//! Every test here is conservative in the safe direction: "outside" / "no intersection"
//! is only answered when certain (up to f64 rounding on f32 inputs).

use super::mesh::Aabb;
use crate::geom::{Light, LightKind};
use glam::{DMat4, DVec3, DVec4, Mat4, Vec3, Vec4};

/// Clip planes of a view-projection matrix in world space; a homogeneous point `p` is
/// inside plane `k` iff `planes[k] . p >= 0`. Points at infinity (w = 0) work directly.
#[derive(Clone, Debug, PartialEq)]
pub struct Frustum {
    /// Left, right, bottom, top, near (and far when finite) as `(a, b, c, d)`, unnormalised.
    pub planes: Vec<DVec4>,
}

impl Frustum {
    /// x, y within +-w and z >= 0 (Vulkan clip space); with `finite_far` also z <= w.
    pub fn from_view_proj(m: Mat4, finite_far: bool) -> Frustum {
        let m = m.as_dmat4();
        let r = |i: usize| m.row(i);
        let mut planes = vec![r(3) + r(0), r(3) - r(0), r(3) + r(1), r(3) - r(1), r(2)];
        if finite_far {
            planes.push(r(3) - r(2));
        }
        Frustum { planes }
    }

    /// True iff every point is strictly outside one common plane.
    pub fn all_outside_one_plane(&self, pts: &[DVec4]) -> bool {
        self.planes.iter().any(|pl| pts.iter().all(|p| pl.dot(*p) < 0.0))
    }

    /// Conservative: false only when the box is certainly outside.
    pub fn intersects_box(&self, b: &Aabb) -> bool {
        let pts: Vec<DVec4> = b.corners().iter().map(|c| c.as_dvec3().extend(1.0)).collect();
        !self.all_outside_one_plane(&pts)
    }
}

/// Whether the whole shadow volume of a caster inside `caster_world_box` (box corners and
/// their extrusions to infinity away from `light_h`) is outside one frustum plane.
/// A point light inside (or on) the box: never outside (its volume may cover everything).
pub fn shadow_volume_outside_frustum(caster_world_box: &Aabb, light_h: Vec4, frustum: &Frustum) -> bool {
    if caster_world_box.is_empty() {
        return true;
    }
    let l = light_h.as_dvec4();
    // the box's corners, then the directions they extrude in (on the stack: once per caster
    // and light)
    let corners = caster_world_box.corners();
    let mut pts = [DVec4::ZERO; 16];
    for (p, c) in pts.iter_mut().zip(&corners) {
        *p = c.as_dvec3().extend(1.0);
    }
    let n = if l.w != 0.0 {
        let lp = l.truncate() / l.w;
        if caster_world_box.contains(lp.as_vec3()) || box_contains_d(caster_world_box, lp) {
            return false;
        }
        for (p, c) in pts[8..].iter_mut().zip(&corners) {
            *p = (c.as_dvec3() - lp).extend(0.0);
        }
        16
    } else {
        pts[8] = (-l.truncate()).extend(0.0);
        9
    };
    frustum.all_outside_one_plane(&pts[..n])
}

fn box_contains_d(b: &Aabb, p: DVec3) -> bool {
    p.cmpge(b.min.as_dvec3()).all() && p.cmple(b.max.as_dvec3()).all()
}

/// The four world-space corners of the near-plane rectangle of `view_proj` (NDC z = 0).
pub fn near_rectangle(view_proj: Mat4) -> Option<[DVec3; 4]> {
    let m = view_proj.as_dmat4();
    if m.determinant().abs() < 1e-300 {
        return None;
    }
    let inv = m.inverse();
    let mut out = [DVec3::ZERO; 4];
    for (k, (x, y)) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)].into_iter().enumerate() {
        let p = inv * DVec4::new(x, y, 0.0, 1.0);
        if p.w.abs() < 1e-300 || !p.is_finite() {
            return None;
        }
        out[k] = p.truncate() / p.w;
    }
    Some(out)
}

/// The viewport occlusion pyramid: convex hull of the light and the near-plane rectangle
/// (point light), or the infinite prism from the near rectangle towards a directional light.
/// `planes == None` means degenerate (everything intersects).
#[derive(Clone, Debug, PartialEq)]
pub struct OcclusionPyramid {
    /// Inside iff `n . p + d >= 0` for all planes (n, d) packed as DVec4(n, d).
    pub planes: Option<Vec<DVec4>>,
}

impl OcclusionPyramid {
    /// The pyramid for the homogeneous light `light_h` (w = 1 point, w = 0 directional, as
    /// [`Light::homogeneous`]) and the camera's `view_proj`.
    pub fn new(light_h: Vec4, view_proj: Mat4) -> OcclusionPyramid {
        OcclusionPyramid { planes: Self::build(light_h.as_dvec4(), view_proj) }
    }

    fn build(l: DVec4, view_proj: Mat4) -> Option<Vec<DVec4>> {
        let r = near_rectangle(view_proj)?;
        let centre = (r[0] + r[1] + r[2] + r[3]) / 4.0;
        let size = (r[2] - r[0]).length().max(1e-30);
        let nn = (r[1] - r[0]).cross(r[3] - r[0]);
        if nn.length() < 1e-12 * size * size {
            return None;
        }
        let nn = nn.normalize();
        let mut planes = Vec::with_capacity(5);
        // a plane through `p` with normal `n`, oriented so that `inside` is on its + side
        let mut push = |n: DVec3, p: DVec3, inside: DVec3| -> bool {
            let len = n.length();
            if !(len > 1e-12) || !len.is_finite() {
                return false;
            }
            let n = n / len;
            let mut pl = n.extend(-n.dot(p));
            let s = pl.truncate().dot(inside) + pl.w;
            if s.abs() < 1e-9 * size {
                return false;
            }
            if s < 0.0 {
                pl = -pl;
            }
            planes.push(pl);
            true
        };
        if l.w != 0.0 {
            let lp = l.truncate() / l.w;
            let h = nn.dot(lp - centre);
            if h.abs() < 1e-6 * size {
                return None; // light on the near plane: degenerate hull
            }
            let inside = (lp + r[0] + r[1] + r[2] + r[3]) / 5.0;
            if !push(nn, centre, inside) {
                return None;
            }
            for k in 0..4 {
                let (a, b) = (r[k], r[(k + 1) % 4]);
                if !push((b - a).cross(lp - a), a, inside) {
                    return None;
                }
            }
            // supporting plane at the apex (cuts off the mirrored cone behind the light)
            let axis = centre - lp;
            if r.iter().all(|c| (*c - lp).dot(axis) > 1e-9 * axis.length() * size) {
                push(axis, lp, inside);
            }
        } else {
            let d = l.truncate();
            if d.length() == 0.0 || nn.dot(d).abs() < 1e-9 * d.length() {
                return None;
            }
            let d = d.normalize();
            let inside = centre + d * size;
            if !push(nn, centre, inside) {
                return None;
            }
            for k in 0..4 {
                let (a, b) = (r[k], r[(k + 1) % 4]);
                if !push((b - a).cross(d), a, inside) {
                    return None;
                }
            }
        }
        Some(planes)
    }

    /// Conservative: false only when the box is certainly disjoint from the pyramid.
    pub fn intersects_box(&self, b: &Aabb) -> bool {
        let Some(planes) = &self.planes else { return true };
        if b.is_empty() {
            return false;
        }
        let corners = b.corners();
        !planes.iter().any(|pl| corners.iter().all(|c| pl.truncate().dot(c.as_dvec3()) + pl.w < 0.0))
    }
}

/// The world-space cube around the light's sphere of influence (point/spot with a radius).
fn light_sphere(light: &Light) -> Option<(DVec3, f64)> {
    match light.kind {
        LightKind::Directional => None,
        _ => {
            let r = light.radius? as f64;
            if !(r > 0.0) || !r.is_finite() {
                return None;
            }
            Some((light.position.as_dvec3(), r))
        }
    }
}

fn sphere_clip_corners(c: DVec3, r: f64, m: &DMat4) -> Option<Vec<DVec4>> {
    let mut out = Vec::with_capacity(8);
    for i in 0..8 {
        let s = |b: usize| if i & b != 0 { r } else { -r };
        let p = *m * (c + DVec3::new(s(1), s(2), s(4))).extend(1.0);
        // behind or crossing the near plane (z < 0 in Vulkan clip space): not bounded
        if !(p.w > 0.0) || p.z < 0.0 {
            return None;
        }
        out.push(p);
    }
    Some(out)
}

/// Scissor rectangle `[x, y, w, h]` (pixels, row 0 at the top) bounding the light's sphere
/// of influence on screen, clamped to the viewport. `None` = full screen (no radius,
/// directional light, or the sphere's bounding cube crosses the near plane). A rectangle
/// with zero width or height means the light's influence is entirely off screen.
pub fn light_scissor(light: &Light, view_proj: Mat4, width: u32, height: u32) -> Option<[u32; 4]> {
    let (c, r) = light_sphere(light)?;
    let pts = sphere_clip_corners(c, r, &view_proj.as_dmat4())?;
    let (mut x0, mut y0, mut x1, mut y1) = (f64::INFINITY, f64::INFINITY, f64::NEG_INFINITY, f64::NEG_INFINITY);
    for p in pts {
        let (x, y) = (p.x / p.w, p.y / p.w);
        x0 = x0.min(x);
        x1 = x1.max(x);
        y0 = y0.min(y);
        y1 = y1.max(y);
    }
    let to_px = |v: f64, size: u32| ((v + 1.0) * 0.5 * size as f64).clamp(0.0, size as f64);
    let (px0, px1) = (to_px(x0, width).floor() as u32, to_px(x1, width).ceil() as u32);
    let (py0, py1) = (to_px(y0, height).floor() as u32, to_px(y1, height).ceil() as u32);
    Some([px0, py0, px1.saturating_sub(px0), py1.saturating_sub(py0)])
}

/// Depth range `(min, max)` of the light's sphere of influence under `view_proj` (for the
/// infinite projection: depth 0 at the near plane, 1 at infinity), clamped to [0, 1].
/// `None` when not bounded (no radius, directional, or the sphere crosses the near plane).
pub fn light_depth_bounds(light: &Light, view_proj: Mat4) -> Option<(f32, f32)> {
    let (c, r) = light_sphere(light)?;
    let m = view_proj.as_dmat4();
    sphere_clip_corners(c, r, &m)?;
    // Perspective depth is monotonic in clip w: evaluate at the sphere points of extreme w.
    let g = m.row(3).truncate();
    if g.length() == 0.0 {
        return None;
    }
    let dir = g.normalize();
    let depth = |p: DVec3| {
        let q = m * p.extend(1.0);
        q.z / q.w
    };
    let (d0, d1) = (depth(c - dir * r), depth(c + dir * r));
    let (lo, hi) = (d0.min(d1).clamp(0.0, 1.0), d0.max(d1).clamp(0.0, 1.0));
    if !(lo.is_finite() && hi.is_finite()) {
        return None;
    }
    // round outwards to f32
    let lo32 = lo as f32;
    let hi32 = hi as f32;
    let lo32 = if (lo32 as f64) > lo { f32::from_bits(lo32.to_bits().saturating_sub(1)).max(0.0) } else { lo32 };
    let hi32 = if (hi32 as f64) < hi { f32::from_bits(hi32.to_bits() + 1).min(1.0) } else { hi32 };
    Some((lo32, hi32))
}

/// Distance from a point to a box (0 inside).
pub fn box_distance(b: &Aabb, p: Vec3) -> f32 {
    let d = (b.min - p).max(p - b.max).max(Vec3::ZERO);
    d.length()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::Camera;

    fn cam(eye: Vec3, target: Vec3) -> (Camera, Mat4) {
        let c = Camera { eye, target, up: Vec3::Y, fov_y_deg: 60.0, near: 0.1 };
        let vp = c.proj_infinite(1.0) * c.view();
        (c, vp)
    }

    fn unit_box(c: Vec3) -> Aabb {
        Aabb { min: c - Vec3::splat(0.5), max: c + Vec3::splat(0.5) }
    }

    #[test]
    fn frustum_points() {
        let (_, vp) = cam(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO);
        let f = Frustum::from_view_proj(vp, false);
        assert!(f.intersects_box(&unit_box(Vec3::ZERO)));
        assert!(!f.intersects_box(&unit_box(Vec3::new(0.0, 0.0, 10.0)))); // behind
        assert!(!f.intersects_box(&unit_box(Vec3::new(100.0, 0.0, 0.0))));
        assert!(f.intersects_box(&unit_box(Vec3::new(0.0, 0.0, -1e6)))); // infinite far
                                                                         // points at infinity: straight ahead is inside, straight behind outside
        let ahead = DVec4::new(0.0, 0.0, -1.0, 0.0);
        assert!(f.planes.iter().all(|p| p.dot(ahead) >= 0.0));
        assert!(f.all_outside_one_plane(&[DVec4::new(0.0, 0.0, 1.0, 0.0)]));
    }

    #[test]
    fn volume_outside_frustum() {
        let (_, vp) = cam(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO);
        let f = Frustum::from_view_proj(vp, false);
        // box behind the camera, light further behind: volume goes away from the view
        let b = unit_box(Vec3::new(0.0, 0.0, 8.0));
        assert!(shadow_volume_outside_frustum(&b, Vec4::new(0.0, 0.0, 6.0, 1.0), &f));
        // same box, light behind it (at z=12): the volume extends forward into view
        assert!(!shadow_volume_outside_frustum(&b, Vec4::new(0.0, 0.0, 12.0, 1.0), &f));
        // directional travelling +z (towards/behind the camera): outside
        assert!(shadow_volume_outside_frustum(&b, Vec4::new(0.0, 0.0, -1.0, 0.0), &f));
        // directional travelling -z: into the view
        assert!(!shadow_volume_outside_frustum(&b, Vec4::new(0.0, 0.0, 1.0, 0.0), &f));
        // light inside: never outside
        assert!(!shadow_volume_outside_frustum(&b, Vec4::new(0.0, 0.0, 8.0, 1.0), &f));
    }

    #[test]
    fn pyramid() {
        let (_, vp) = cam(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO);
        let light = Vec4::new(0.0, 0.0, -5.0, 1.0);
        let p = OcclusionPyramid::new(light, vp);
        assert!(p.planes.is_some());
        assert!(p.intersects_box(&unit_box(Vec3::ZERO))); // between light and eye
        assert!(!p.intersects_box(&unit_box(Vec3::new(3.0, 0.0, 0.0))));
        assert!(!p.intersects_box(&unit_box(Vec3::new(0.0, 0.0, -8.0)))); // beyond the light
                                                                          // directional from -z (light direction xyz points towards the light = -z)
        let d = OcclusionPyramid::new(Vec4::new(0.0, 0.0, -1.0, 0.0), vp);
        assert!(d.intersects_box(&unit_box(Vec3::new(0.0, 0.0, -100.0))));
        assert!(!d.intersects_box(&unit_box(Vec3::new(2.0, 0.0, 0.0))));
        assert!(!d.intersects_box(&unit_box(Vec3::new(0.0, 0.0, 8.0))));
        // light on the near plane: degenerate, everything intersects
        let c = Camera { eye: Vec3::new(0.0, 0.0, 5.0), target: Vec3::ZERO, up: Vec3::Y, fov_y_deg: 60.0, near: 0.1 };
        let on = Vec4::new(3.0, 0.0, 4.9, 1.0);
        let _ = c;
        let p = OcclusionPyramid::new(on, vp);
        assert!(p.intersects_box(&unit_box(Vec3::new(50.0, 50.0, 50.0))));
        // directional parallel to the near plane: degenerate
        let p = OcclusionPyramid::new(Vec4::new(1.0, 0.0, 0.0, 0.0), vp);
        assert!(p.intersects_box(&unit_box(Vec3::new(50.0, 50.0, 50.0))));
    }

    fn point_light(pos: Vec3, r: Option<f32>) -> Light {
        Light {
            kind: LightKind::Point,
            position: pos,
            direction: Vec3::NEG_Y,
            color: Vec3::ONE,
            intensity: 1.0,
            radius: r,
            cone_deg: 45.0,
            area: None,
        }
    }

    #[test]
    fn scissor_and_depth() {
        let (_, vp) = cam(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO);
        let l = point_light(Vec3::ZERO, Some(1.0));
        let s = light_scissor(&l, vp, 800, 600).unwrap();
        // centred, inside the viewport, not full screen
        assert!(s[0] > 0 && s[1] > 0 && s[0] + s[2] < 800 && s[1] + s[3] < 600, "{s:?}");
        let cx = s[0] as f32 + s[2] as f32 * 0.5;
        let cy = s[1] as f32 + s[3] as f32 * 0.5;
        assert!((cx - 400.0).abs() <= 1.0 && (cy - 300.0).abs() <= 1.0);
        // off to the right/up: the rectangle moves right and UP (smaller rows)
        let s2 = light_scissor(&point_light(Vec3::new(1.0, 1.0, 0.0), Some(0.5)), vp, 800, 600).unwrap();
        assert!(s2[0] > s[0] && s2[1] < s[1], "{s2:?}");
        // crossing the near plane / no radius: None
        assert_eq!(light_scissor(&point_light(Vec3::new(0.0, 0.0, 5.0), Some(1.0)), vp, 800, 600), None);
        assert_eq!(light_scissor(&point_light(Vec3::ZERO, None), vp, 800, 600), None);
        // off screen: empty rectangle
        let s3 = light_scissor(&point_light(Vec3::new(100.0, 0.0, 0.0), Some(1.0)), vp, 800, 600).unwrap();
        assert!(s3[2] == 0 || s3[3] == 0);
        let (d0, d1) = light_depth_bounds(&l, vp).unwrap();
        // distance 4..6 with near 0.1: depth = 1 - 0.1/d
        assert!((d0 as f64 - (1.0 - 0.1 / 4.0)).abs() < 1e-5, "{d0}");
        assert!((d1 as f64 - (1.0 - 0.1 / 6.0)).abs() < 1e-5, "{d1}");
        assert!(d0 <= 1.0 - 0.1 / 4.0 + 1e-7);
        assert_eq!(light_depth_bounds(&point_light(Vec3::new(0.0, 0.0, 5.0), Some(1.0)), vp), None);
    }
}
