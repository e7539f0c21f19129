//! CPU per frame against lights and against casters: the shadow pass alone
//! (`ShadowPass::prepare`, nothing drawn), McGuire's method, the camera on the level's walk,
//! plans kept and not. The wall clock around `prepare` (other work on the machine counts in
//! it) and the pass's own split.

use super::{FrameCostConfig, WARM_UP};
use crate::motion::frame_time;
use crate::stats::median;
use glam::Vec3;
use serde::Serialize;
use std::time::Instant;
use umbrage::error::Result;
use umbrage::geom::{Camera, Light, Mesh};
use umbrage::gpu::Context;
use umbrage::pass::{PassSettings, ShadowPass, ShadowPassDesc, ShadowView, Technique};
use umbrage::shadow::Method;
use umbrage_scene::level::{level_toml, LEVEL_ROOMS};
use umbrage_scene::motion::Motion;
use umbrage_scene::Scene;

/// The curves' frame size (the pass's scissors and cases depend on it; nothing is drawn).
pub const SIZE: (u32, u32) = (1280, 720);

/// One point of a curve: the same frames with plans kept and planned every frame.
#[derive(Clone, Debug, Serialize)]
pub struct CurvePoint {
    /// Rooms a side of the level.
    pub rooms: usize,
    /// Shadow-casting meshes.
    pub casters: usize,
    /// Lights.
    pub lights: usize,
    /// Measured frames (after [`WARM_UP`]).
    pub frames: usize,
    /// Light–caster pairs drawn a frame (median).
    pub pairs_total: u64,
    /// Planned every frame: median wall ms of `prepare`.
    pub off_ms: f64,
    /// Kept: median wall ms of `prepare`.
    pub kept_ms: f64,
    /// Planned every frame: the pass's culling and planning, ms.
    pub off_plan_ms: f64,
    /// Kept: the pass's culling, look-ups and planning, ms.
    pub kept_plan_ms: f64,
    /// Planned every frame: bytes sent a frame.
    pub off_bytes: u64,
    /// Kept: bytes sent a frame.
    pub kept_bytes_sent: u64,
    /// Kept: pairs planned a frame.
    pub kept_replanned: u64,
}

/// A level of `rooms` x `rooms` rooms and its motion (the built-in file for [`LEVEL_ROOMS`]).
fn level(rooms: usize) -> Result<(Scene, Motion)> {
    if rooms == LEVEL_ROOMS {
        return umbrage_scene::load_animated("bench/level");
    }
    let no_objs = umbrage_scene::file::ObjSource::Dir(std::path::Path::new(""));
    umbrage_scene::file::parse_animated(&level_toml(rooms), "level", no_objs)
}

/// The built-in level's casters with `n` of its lights: every k-th where `n` <= 128, else
/// each light repeated with small shifts inside its room.
fn lights_of(scene: &Scene, n: usize) -> Vec<Light> {
    let all = &scene.lights;
    if n <= all.len() {
        return all.iter().step_by(all.len() / n.max(1)).take(n).cloned().collect();
    }
    (0..n)
        .map(|i| {
            let (j, l) = (i / all.len(), &all[i % all.len()]);
            let shift = Vec3::new((j % 4) as f32 * 0.5, 0.0, (j / 4) as f32 * 0.5);
            Light { position: l.position + shift, ..l.clone() }
        })
        .collect()
}

/// CPU against lights: the built-in level's casters, `cfg.lights` lights.
pub fn lights(ctx: &Context, cfg: &FrameCostConfig) -> Result<Vec<CurvePoint>> {
    let (scene, motion) = level(LEVEL_ROOMS)?;
    let mut out = Vec::new();
    for &n in &cfg.lights {
        let lights = lights_of(&scene, n);
        out.push(point(ctx, cfg, LEVEL_ROOMS, (&scene, &motion), &lights)?);
    }
    Ok(out)
}

/// CPU against casters: levels of `cfg.rooms` rooms a side, each with its own lights.
pub fn casters(ctx: &Context, cfg: &FrameCostConfig) -> Result<Vec<CurvePoint>> {
    let mut out = Vec::new();
    for &rooms in &cfg.rooms {
        let (scene, motion) = level(rooms)?;
        out.push(point(ctx, cfg, rooms, (&scene, &motion), &scene.lights)?);
    }
    Ok(out)
}

fn point(ctx: &Context, cfg: &FrameCostConfig, rooms: usize, (scene, motion): (&Scene, &Motion), lights: &[Light]) -> Result<CurvePoint> {
    let off = frames(ctx, cfg.curve_frames, (scene, motion), lights, false)?;
    let kept = frames(ctx, cfg.curve_frames, (scene, motion), lights, true)?;
    let casters = scene.meshes.iter().filter(|m| m.casts_shadow).count();
    if cfg.progress {
        eprintln!(
            "curve: {rooms:>2} x {rooms:<2} rooms, {casters:>5} casters, {:>5} lights: planned every frame {:>9.3} ms, kept {:>8.3} ms ({} pairs)",
            lights.len(),
            off.wall,
            kept.wall,
            kept.pairs
        );
    }
    Ok(CurvePoint {
        rooms,
        casters,
        lights: lights.len(),
        frames: cfg.curve_frames,
        pairs_total: kept.pairs,
        off_ms: off.wall,
        kept_ms: kept.wall,
        off_plan_ms: off.plan,
        kept_plan_ms: kept.plan,
        off_bytes: off.bytes,
        kept_bytes_sent: kept.bytes,
        kept_replanned: kept.replanned,
    })
}

/// Medians of one run of frames.
struct Run {
    wall: f64,
    plan: f64,
    bytes: u64,
    pairs: u64,
    replanned: u64,
}

/// A pass with the scene's casters; [`WARM_UP`] frames, then `n` measured, the camera on
/// its walk at 30 frames a second.
fn frames(ctx: &Context, n: usize, (scene, motion): (&Scene, &Motion), lights: &[Light], keep: bool) -> Result<Run> {
    let desc = ShadowPassDesc { depth_stencil_format: ctx.depth_format, frames_in_flight: 1, ..Default::default() };
    let mut pass = ShadowPass::new(&ctx.instance, ctx.physical, &ctx.device, (*ctx.allocator).clone(), &desc)?;
    pass.set_settings(PassSettings { technique: Technique::Volumes(Method::McGuire), keep, ..Default::default() })?;
    for m in scene.meshes.iter().filter(|m| m.casts_shadow) {
        let mesh: &Mesh = &m.mesh;
        pass.add_caster(&m.name, mesh, m.transform.as_dmat4())?;
    }
    let mut v: [Vec<f64>; 5] = Default::default();
    for k in 0..WARM_UP + n {
        let (eye, target) = match &motion.camera {
            Some(path) => path.eye_target(&scene.camera, frame_time(k)),
            None => (scene.camera.eye, scene.camera.target),
        };
        let cam = Camera { eye, target, ..scene.camera.clone() };
        let view = ShadowView {
            eye: eye.as_dvec3(),
            // (relative to the eye: the pass composes it in f64)
            view: glam::camera::rh::view::look_at_mat4(Vec3::ZERO, target - eye, cam.up),
            proj: cam.proj_infinite(SIZE.0 as f32 / SIZE.1 as f32),
            width: SIZE.0,
            height: SIZE.1,
        };
        let t0 = Instant::now();
        let f = pass.prepare(0, &view, lights)?;
        let ms = t0.elapsed().as_secs_f64() * 1e3;
        if k == 0 {
            // The casters' vertex uploads reach the GPU once.
            let mut recorded = Ok(());
            ctx.one_shot(|cb| {
                // SAFETY: `cb` is recording outside rendering; one_shot waits for it before returning.
                recorded = unsafe { pass.cmd_before_rendering(cb, &f) };
            })?;
            recorded?;
        }
        if k >= WARM_UP {
            let t = &f.totals;
            let plan = f.cpu_ms.cull + f.cpu_ms.plan + f.cpu_ms.silhouettes;
            for (acc, x) in v.iter_mut().zip([ms, plan, t.bytes_sent as f64, t.pairs_total as f64, t.pairs_replanned as f64]) {
                acc.push(x);
            }
        }
    }
    let [wall, plan, bytes, pairs, replanned] = v.map(median);
    Ok(Run { wall, plan, bytes: bytes as u64, pairs: pairs as u64, replanned: replanned as u64 })
}
