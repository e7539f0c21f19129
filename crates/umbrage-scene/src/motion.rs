//! Scene motion: a caster's spin and a light's path, evaluated at a time in seconds. The
//! same evaluation serves `umbrage render --time T` and every frame of `umbrage view`, so a
//! viewer frame is reproduced exactly by rendering at its time (f64 arithmetic, one rounding
//! to f32 at the end).

use super::{Light, LightKind, Scene};
use glam::{DMat4, DVec3, EulerRot, Mat4, Vec3};

/// How a light moves.
#[derive(Clone, Debug, PartialEq)]
pub enum LightPath {
    /// A horizontal circle (`orbit = { center, radius, period_s }`): position(t) = center +
    /// radius (cos a, 0, sin a), a = phase + 2 pi t / period_s, counter-clockwise seen from
    /// above; the phase is the light's `position` seen from the centre (0 when straight above it).
    Orbit {
        /// Centre of the circle (its height is the light's height).
        center: Vec3,
        /// Radius (> 0).
        radius: f32,
        /// Seconds per turn (> 0).
        period_s: f32,
        /// Angle at t = 0, radians.
        phase: f64,
    },
    /// `keyframes = [{ t, position }, ...]`: linear between keys, times increasing from the
    /// first key's; repeats with the last key's time as the period (make the last key equal
    /// to the first for a closed loop).
    Keyframes(Vec<(f32, Vec3)>),
}

impl LightPath {
    /// The position at time `t` seconds.
    pub fn position(&self, t: f64) -> Vec3 {
        match self {
            LightPath::Orbit { center, radius, period_s, phase } => {
                let a = phase + std::f64::consts::TAU * t / *period_s as f64;
                let c = center.as_dvec3();
                (c + *radius as f64 * DVec3::new(a.cos(), 0.0, a.sin())).as_vec3()
            }
            LightPath::Keyframes(keys) => {
                let (Some(first), Some(last)) = (keys.first(), keys.last()) else { return Vec3::ZERO };
                let (t0, t1) = (first.0 as f64, last.0 as f64);
                let span = t1 - t0;
                let t = if span > 0.0 { t0 + (t - t0).rem_euclid(span) } else { t0 };
                for w in keys.windows(2) {
                    let (a, b) = (w[0], w[1]);
                    if t <= b.0 as f64 {
                        let f = ((t - a.0 as f64) / (b.0 as f64 - a.0 as f64)).clamp(0.0, 1.0);
                        return a.1.as_dvec3().lerp(b.1.as_dvec3(), f).as_vec3();
                    }
                }
                last.1
            }
        }
    }
}

/// What moves in a scene, by scene index.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Motion {
    /// Per mesh (scene order): its spin, degrees per second about its own origin's X, Y and
    /// Z axes (`spin_deg_per_s`; applied as R = Rz Ry Rx, like `rotate_deg`, before the mesh's
    /// own transform's translation and after its rotation and scale).
    pub spins: Vec<Option<Vec3>>,
    /// Per light (scene order): its path.
    pub paths: Vec<Option<LightPath>>,
}

impl Motion {
    /// Nothing moves.
    pub fn is_static(&self) -> bool {
        self.spins.iter().all(Option::is_none) && self.paths.iter().all(Option::is_none)
    }

    /// Mesh `index`'s transform at `t`, from its transform at rest `rest`.
    pub fn mesh_transform(&self, index: usize, rest: Mat4, t: f64) -> Mat4 {
        let Some(Some(spin)) = self.spins.get(index) else { return rest };
        let a = spin.as_dvec3() * t;
        let r = DMat4::from_euler(EulerRot::ZYX, a.z.to_radians(), a.y.to_radians(), a.x.to_radians());
        let rest = rest.as_dmat4();
        let c = rest.w_axis.truncate();
        (DMat4::from_translation(c) * r * DMat4::from_translation(-c) * rest).as_mat4()
    }

    /// Light `index` at `t`, from the light at rest.
    pub fn light(&self, index: usize, rest: &Light, t: f64) -> Light {
        let mut l = rest.clone();
        if let (Some(Some(path)), true) = (self.paths.get(index), rest.kind != LightKind::Directional) {
            l.position = path.position(t);
        }
        l
    }

    /// `rest` with everything moved to time `t` (the scene at rest is the one loaded).
    pub fn scene_at(&self, rest: &Scene, t: f64) -> Scene {
        let mut s = rest.clone();
        for (i, m) in s.meshes.iter_mut().enumerate() {
            m.transform = self.mesh_transform(i, m.transform, t);
        }
        for (i, l) in s.lights.iter_mut().enumerate() {
            *l = self.light(i, l, t);
        }
        s
    }
}

/// A light's orbit phase from its position at rest.
pub(crate) fn orbit_phase(center: Vec3, position: Vec3) -> f64 {
    let d = (position - center).as_dvec3();
    if d.x == 0.0 && d.z == 0.0 {
        0.0
    } else {
        d.z.atan2(d.x)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn orbit_starts_at_the_rest_position_and_turns_once_per_period() {
        let c = Vec3::new(1.0, 4.0, -2.0);
        let p = Vec3::new(4.0, 4.0, -2.0);
        let path = LightPath::Orbit { center: c, radius: 3.0, period_s: 8.0, phase: orbit_phase(c, p) };
        assert!(path.position(0.0).distance(p) < 1e-6);
        assert!(path.position(8.0).distance(p) < 1e-5);
        let q = path.position(2.0); // a quarter turn: +z
        assert!(q.distance(Vec3::new(1.0, 4.0, 1.0)) < 1e-5, "{q}");
    }

    #[test]
    fn keyframes_interpolate_and_repeat() {
        let path = LightPath::Keyframes(vec![(0.0, Vec3::ZERO), (1.0, Vec3::X), (3.0, Vec3::new(1.0, 2.0, 0.0))]);
        assert_eq!(path.position(0.5), Vec3::new(0.5, 0.0, 0.0));
        assert_eq!(path.position(2.0), Vec3::new(1.0, 1.0, 0.0));
        assert_eq!(path.position(3.5), Vec3::new(0.5, 0.0, 0.0));
    }

    #[test]
    fn spin_turns_about_the_mesh_origin() {
        let m = Motion { spins: vec![Some(Vec3::new(0.0, 90.0, 0.0))], paths: vec![] };
        let rest = Mat4::from_translation(Vec3::new(5.0, 1.0, 0.0));
        let t = m.mesh_transform(0, rest, 1.0);
        // The origin stays, +x goes to -z.
        assert!(t.transform_point3(Vec3::ZERO).distance(Vec3::new(5.0, 1.0, 0.0)) < 1e-6);
        assert!(t.transform_point3(Vec3::X).distance(Vec3::new(5.0, 1.0, -1.0)) < 1e-6);
        assert_eq!(m.mesh_transform(0, rest, 0.0), rest);
    }
}
