//! `umbrage bench --motion`: a scene's motion (its camera's walk or orbit, its meshes' spins,
//! its lights' paths) run over the measured frames, frame `k` at time `k * FRAME_S`. Only what
//! changed since the last frame is handed to the renderer, so the shadow pass sees a camera
//! move as a camera move, and keeps the plans of every light and caster that stood still.

use umbrage::error::Result;
use umbrage_render::Renderer;
use umbrage_scene::motion::Motion;
use umbrage_scene::Scene;

/// Seconds between two frames of the motion (30 frames a second).
pub const FRAME_S: f64 = 1.0 / 30.0;

/// The time of frame `k` of a motion, seconds.
pub fn frame_time(k: usize) -> f64 {
    k as f64 * FRAME_S
}

/// Moves `r`'s scene to `motion` at `t` seconds from `rest` (the scene as loaded): the camera,
/// the meshes' transforms and the lights, each only where it differs from the renderer's.
pub fn move_to(r: &mut Renderer, rest: &Scene, motion: &Motion, t: f64) -> Result<()> {
    let at = motion.scene_at(rest, t);
    if at.camera != r.scene().camera {
        r.set_camera(at.camera)?;
    }
    for (i, m) in at.meshes.iter().enumerate() {
        if r.scene().meshes.get(i).is_some_and(|now| now.transform != m.transform) {
            r.set_mesh_transform(i, m.transform)?;
        }
    }
    if at.lights != r.source_lights() {
        r.set_lights(at.lights)?;
    }
    Ok(())
}
