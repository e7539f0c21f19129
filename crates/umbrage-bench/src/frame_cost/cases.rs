//! The side-by-side's scenes in motion: each scene's camera path (its own, or an orbit about
//! its target), and what else moves in each [`Case`].

use glam::Vec3;
use serde::Serialize;
use umbrage::error::Result;
use umbrage_scene::motion::{CameraPath, LightPath, Motion};
use umbrage_scene::{LightKind, Scene};

/// What moves besides the camera.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Case {
    /// Only the camera.
    Camera,
    /// The camera and a few casters (at most `MOVERS`).
    Casters,
    /// The camera and a few lights (at most `MOVERS`).
    Lights,
}

impl Case {
    /// Every case, in the report's order.
    pub const ALL: [Case; 3] = [Case::Camera, Case::Casters, Case::Lights];

    /// The case in the report's words.
    pub fn label(self) -> &'static str {
        match self {
            Case::Camera => "camera only",
            Case::Casters => "casters moving",
            Case::Lights => "lights moving",
        }
    }
}

/// At most this many casters or lights move in the cases that move them: a quarter of the
/// casters and half the (positional) lights at most, at least one (a scene with its own motion
/// keeps its own: `bench/level` turns 8 characters and circles 4 lights).
pub const MOVERS: usize = 4;

/// The camera's orbit about a scene's target where the scene has no camera path of its own:
/// one turn in this many seconds (a third of a degree a frame at 30 frames a second).
pub const ORBIT_S: f32 = 36.0;

/// `name` at rest and its motion in `case`: the camera on the scene's own path (or an orbit
/// about its target), and, by case, the casters or lights that move (the scene's own spins or
/// light paths where it has them, else up to [`MOVERS`] spread over the scene).
pub fn scene_in(name: &str, case: Case) -> Result<(Scene, Motion)> {
    let (scene, own) = umbrage_scene::load_animated(name)?;
    let camera = own.camera.clone().or_else(|| {
        let c = &scene.camera;
        let centre = Vec3::new(c.target.x, c.eye.y, c.target.z);
        let radius = (c.eye - centre).length();
        let phase = orbit_phase(centre, c.eye);
        (radius > 0.0).then_some(CameraPath::Orbit { center: centre, radius, period_s: ORBIT_S, phase })
    });
    let mut m = Motion { spins: vec![None; scene.meshes.len()], paths: vec![None; scene.lights.len()], camera };
    match case {
        Case::Camera => {}
        Case::Casters if own.spins.iter().any(Option::is_some) => m.spins = own.spins.clone(),
        Case::Casters => {
            let casters: Vec<usize> = (0..scene.meshes.len()).filter(|&i| scene.meshes[i].casts_shadow).collect();
            for &i in spread(&casters, (casters.len() / 4).clamp(1, MOVERS)) {
                m.spins[i] = Some(Vec3::new(0.0, 45.0, 20.0));
            }
        }
        Case::Lights if own.paths.iter().any(Option::is_some) => m.paths = own.paths.clone(),
        Case::Lights => {
            let lights: Vec<usize> = (0..scene.lights.len()).filter(|&i| scene.lights[i].kind != LightKind::Directional).collect();
            for &i in spread(&lights, (lights.len() / 2).clamp(1, MOVERS)) {
                // A circle of radius 0.5 through the light's place at rest, once in 4 s.
                let p = scene.lights[i].position;
                m.paths[i] = Some(LightPath::Orbit { center: p - Vec3::new(0.5, 0.0, 0.0), radius: 0.5, period_s: 4.0, phase: 0.0 });
            }
        }
    }
    Ok((scene, m))
}

/// `n` of `items`, spread evenly.
fn spread(items: &[usize], n: usize) -> impl Iterator<Item = &usize> {
    items.iter().step_by(items.len().div_ceil(n.max(1)).max(1)).take(n)
}

/// The angle of `p` about `centre` in the horizontal plane (the phase of an orbit through it).
fn orbit_phase(centre: Vec3, p: Vec3) -> f64 {
    let d = (p - centre).as_dvec3();
    d.z.atan2(d.x)
}
