//! The light as the planner places it in a caster's space: homogeneous in object space, nudged
//! off a caster vertex it sits on, and a spot cone's conservative cull.

use crate::geom::{Aabb, Light, LightKind};
use crate::shadow::Caster;
use glam::Vec4;

/// The object-space homogeneous light (w exactly 1 or 0).
pub fn object_light(caster: &Caster, light_h: Vec4) -> Vec4 {
    let inv = caster.transform.as_dmat4().inverse();
    let l = inv * light_h.as_dvec4();
    if light_h.w == 0.0 {
        l.truncate().as_vec3().extend(0.0)
    } else {
        (l.truncate() / l.w).as_vec3().extend(1.0)
    }
}

/// A point light exactly on (or within rounding of) a caster vertex would send that vertex's
/// w=0 copy to `(0, 0, 0, 0)`, which is no point at all, and the volume would rasterise as
/// garbage. Such a light is moved away from the caster's centre by a distance far below a pixel
/// (1e-5 of the caster's size): the shadow is then exact to that distance, and every extrusion
/// direction is defined. Other lights are returned unchanged.
pub fn avoid_vertex(caster: &Caster, l_obj: Vec4) -> Vec4 {
    if l_obj.w == 0.0 {
        return l_obj;
    }
    let b = caster.object_bounds;
    let size = b.extent().length().max(f32::MIN_POSITIVE);
    let eps = size * 1e-5;
    let l = l_obj.truncate();
    let near_box = l.cmpge(b.min - eps).all() && l.cmple(b.max + eps).all();
    if !near_box || !caster.mesh().positions.iter().any(|p| p.distance(l) <= eps) {
        return l_obj;
    }
    let away = (l - b.center()).try_normalize().unwrap_or(glam::Vec3::Y);
    (l + away * (4.0 * eps)).extend(1.0)
}

/// Whether a spot light's cone misses the box `b` (conservatively: the bounding sphere).
pub(super) fn spot_culls(light: &Light, b: &Aabb) -> bool {
    if light.kind != LightKind::Spot {
        return false;
    }
    let half = (light.cone_deg as f64 * 0.5).to_radians();
    if !(half < std::f64::consts::FRAC_PI_2) {
        return false;
    }
    let c = b.center().as_dvec3();
    let r = (b.extent().as_dvec3() * 0.5).length();
    let v = c - light.position.as_dvec3();
    let dist = v.length();
    let d = light.direction.as_dvec3();
    if dist <= r || d.length() == 0.0 {
        return false;
    }
    let ang = (v.dot(d) / (dist * d.length())).clamp(-1.0, 1.0).acos();
    ang > half + (r / dist).asin() + 1e-6
}
