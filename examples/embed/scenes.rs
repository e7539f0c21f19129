//! What the host draws: its embedded scene (a torus and a box turning as it slides, two point
//! lights), or a scene file or built-in name whose last shadow-casting mesh slides.

use super::MOVING_MESH;
use glam::{Mat4, Quat, Vec2, Vec3};
use umbrage::geom::{Camera, Light};
use umbrage_scene::{shapes, Scene, SceneMesh};

/// The moving caster's transform at `frame`: the box slides towards the torus and turns.
pub fn box_transform(frame: usize) -> Mat4 {
    let f = frame as f32;
    Mat4::from_rotation_translation(Quat::from_rotation_y(0.25 * f), Vec3::new(1.2 - 0.3 * f, 0.5, 0.3 * f))
}

/// The embedded scene at `frame`: a floor (open, casts nothing), a torus and a moving box
/// casting, two point lights without radius.
pub fn scene(frame: usize) -> Scene {
    let mesh = |name: &str, mesh, transform, casts_shadow| SceneMesh {
        name: name.into(),
        mesh,
        transform,
        color: Vec3::new(0.8, 0.7, 0.6),
        opacity: 1.0,
        casts_shadow,
    };
    let light = Light::point;
    Scene {
        name: "embedded".into(),
        camera: Camera { eye: Vec3::new(0.0, 4.0, 7.0), target: Vec3::new(0.0, 0.5, 0.0), ..Default::default() },
        lights: vec![light(Vec3::new(2.0, 6.0, 2.0)), light(Vec3::new(-3.0, 5.0, 3.5))],
        meshes: vec![
            mesh("floor", shapes::plane(Vec2::splat(20.0)), Mat4::IDENTITY, false),
            mesh("torus", shapes::torus(0.8, 0.25, 48, 24), Mat4::from_translation(Vec3::new(-1.2, 1.0, 0.0)), true),
            mesh("box", shapes::cuboid(Vec3::ONE), box_transform(frame), true),
        ],
        ambient: Vec3::splat(0.06),
        spheres: Vec::new(),
    }
}

/// What the host draws, frame by frame.
pub(super) struct Scenes {
    pub(super) base: Scene,
    /// The mesh that moves and its transform in `base` (the embedded scene: the box).
    pub(super) moving: Option<(usize, Mat4)>,
    pub(super) embedded: bool,
}

impl Scenes {
    pub(super) fn new(spec: Option<&str>) -> Result<Scenes, String> {
        let Some(spec) = spec else { return Ok(Scenes { base: scene(0), moving: Some((MOVING_MESH, box_transform(0))), embedded: true }) };
        let base = umbrage_scene::load(spec).map_err(|e| e.to_string())?;
        if !base.spheres.is_empty() || base.meshes.iter().any(|m| m.casts_shadow && m.opacity < 1.0) {
            return Err(format!(
                "scene '{spec}': this host draws opaque triangle meshes only (no analytic spheres, no transparent casters)"
            ));
        }
        if base.lights.iter().any(|l| l.area.is_some()) {
            return Err(format!("scene '{spec}': area lights are not supported by this host"));
        }
        let moving = base.meshes.iter().rposition(|m| m.casts_shadow).map(|i| (i, base.meshes[i].transform));
        Ok(Scenes { base, moving, embedded: false })
    }

    /// The scene at frame `f`.
    pub(super) fn at(&self, f: usize) -> Scene {
        if self.embedded {
            return scene(f);
        }
        let mut s = self.base.clone();
        if let Some((mi, base)) = self.moving {
            s.meshes[mi].transform = Mat4::from_translation(Vec3::new(0.25 * f as f32, 0.0, 0.0)) * base;
        }
        s
    }
}
