//! The side-by-side rows: each scene, case and technique through the renderer, frame `k` of
//! the motion at `k / 30` s, medians over the measured frames.

use super::cases::{scene_in, Case};
use super::{FrameCostConfig, WARM_UP};
use crate::motion::{frame_time, move_to};
use crate::stats::median;
use serde::Serialize;
use umbrage::error::{Error, Result};
use umbrage::gpu::Context;
use umbrage::shadow::Method;
use umbrage_render::{RenderOptions, Renderer, Technique};

/// The side-by-side's scenes.
pub const SCENES: [&str; 4] = ["bench/level", "default", "stress", "bench/vertex"];

/// The three ways compared.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Way {
    /// McGuire's volumes, every pair planned every frame (`--no-keep`).
    KeepOff,
    /// McGuire's volumes, plans kept across frames (the default).
    Kept,
    /// The `compute` technique (possible silhouettes on the GPU, every frame).
    Compute,
}

impl Way {
    /// Every way, in the report's order.
    pub const ALL: [Way; 3] = [Way::KeepOff, Way::Kept, Way::Compute];

    /// The way in the report's words.
    pub fn label(self) -> &'static str {
        match self {
            Way::KeepOff => "planned every frame (--no-keep)",
            Way::Kept => "kept",
            Way::Compute => "compute",
        }
    }

    fn options(self, size: (u32, u32)) -> RenderOptions {
        let technique = match self {
            Way::Compute => Technique::Compute,
            _ => Technique::Volumes(Method::McGuire),
        };
        RenderOptions {
            width: size.0,
            height: size.1,
            technique: technique.into(),
            keep: self != Way::KeepOff,
            frames_in_flight: 1,
            ..Default::default()
        }
    }
}

/// One scene, case and way: medians over the measured frames.
#[derive(Clone, Debug, Serialize)]
pub struct SideRow {
    /// Scene name.
    pub scene: String,
    /// What moved.
    pub case: Case,
    /// How the shadows were planned.
    pub way: Way,
    /// Shadow-casting meshes.
    pub casters: usize,
    /// Lights.
    pub lights: usize,
    /// Casters (in the casters case) or lights (in the lights case) that move; 0 when only the
    /// camera does.
    pub moved: usize,
    /// Measured frames.
    pub frames: usize,
    /// The pass's culling, cases and kept plans' look-ups, ms (0 without keeping: inside
    /// `cpu_plan_ms`).
    pub cpu_cull_ms: f64,
    /// The pass's planning (facing and silhouettes included), ms.
    pub cpu_plan_ms: f64,
    /// Writing the pass's stream and recording the frame's commands (the renderer's, every
    /// pass of the frame), ms.
    pub cpu_record_ms: f64,
    /// `cpu_cull_ms + cpu_plan_ms`: the CPU the shadows' planning costs a frame, ms.
    pub cpu_shadow_ms: f64,
    /// The frame's CPU in the pass and the recording (`cpu_shadow_ms + cpu_record_ms`, frame by
    /// frame), ms.
    pub cpu_frame_ms: f64,
    /// Geometry bytes sent a frame.
    pub bytes_sent: u64,
    /// Light–caster pairs drawn.
    pub pairs_total: u64,
    /// Pairs planned this frame.
    pub pairs_replanned: u64,
    /// Pairs drawn from kept plans.
    pub pairs_kept: u64,
    /// Bytes of kept index lists after the frame.
    pub kept_bytes: u64,
    /// GPU time of the shadow determination (all lights), ms.
    pub gpu_shadow_ms: Option<f64>,
    /// GPU time of the whole frame, ms.
    pub gpu_frame_ms: Option<f64>,
    /// Wall clock of `Renderer::render` (plan, record, submit, wait, read back), ms.
    pub wall_ms: f64,
}

/// Every row of [`SCENES`] x [`Case::ALL`] x [`Way::ALL`]; the context back.
pub fn run(mut ctx: Context, cfg: &FrameCostConfig) -> Result<(Context, Vec<SideRow>)> {
    let mut rows = Vec::new();
    for name in SCENES {
        for case in Case::ALL {
            for way in Way::ALL {
                let (c, row) = measure(ctx, name, case, way, cfg)?;
                ctx = c;
                if cfg.progress {
                    eprintln!(
                        "{name:<13} {:<15} {:<32} CPU {:>8.3} ms (plan {:>8.3}) {:>9} bytes {:>6} replanned {:>6} kept  GPU shadow {} ms",
                        case.label(),
                        way.label(),
                        row.cpu_frame_ms,
                        row.cpu_shadow_ms,
                        row.bytes_sent,
                        row.pairs_replanned,
                        row.pairs_kept,
                        row.gpu_shadow_ms.map_or("-".into(), |v| format!("{v:.2}"))
                    );
                }
                rows.push(row);
            }
        }
    }
    Ok((ctx, rows))
}

/// One row: a renderer for the scene, [`WARM_UP`] frames, then `cfg.frames` measured ones.
fn measure(ctx: Context, name: &str, case: Case, way: Way, cfg: &FrameCostConfig) -> Result<(Context, SideRow)> {
    let (scene, motion) = scene_in(name, case)?;
    let (casters, lights) = (scene.meshes.iter().filter(|m| m.casts_shadow).count(), scene.lights.len());
    let moved = match case {
        Case::Camera => 0,
        Case::Casters => motion.spins.iter().zip(&scene.meshes).filter(|(s, m)| s.is_some() && m.casts_shadow).count(),
        Case::Lights => motion.paths.iter().filter(|p| p.is_some()).count(),
    };
    let mut r = match Renderer::try_new(ctx, scene.clone(), way.options(cfg.size)) {
        Ok(r) => r,
        Err(e) => return Err(e.error),
    };
    let mut v: [Vec<f64>; 13] = Default::default();
    let measured = (|| -> Result<()> {
        for k in 0..WARM_UP + cfg.frames {
            move_to(&mut r, &scene, &motion, frame_time(k))?;
            let f = r.render()?;
            if k < WARM_UP {
                continue;
            }
            let (c, t) = (&f.stats.cpu_ms, &f.stats.totals);
            let g = f.stats.gpu_ms.as_ref();
            let values = [
                c.cull,
                c.plan + c.silhouettes,
                c.record,
                t.bytes_sent as f64,
                t.pairs_total as f64,
                t.pairs_replanned as f64,
                t.pairs_kept as f64,
                t.kept_bytes as f64,
                g.map_or(f64::NAN, |g| g.shadow),
                g.map_or(f64::NAN, |g| g.frame),
                f.stats.wall_ms,
                c.cull + c.plan + c.silhouettes,
                c.cull + c.plan + c.silhouettes + c.record,
            ];
            for (acc, x) in v.iter_mut().zip(values) {
                acc.push(x);
            }
        }
        r.context().check_validation()
    })();
    let ctx = r.into_context();
    measured?;
    let [cull, plan, record, bytes, total, replanned, kept, kept_bytes, shadow, frame, wall, planning, cpu] = v.map(median);
    let gpu = |x: f64| x.is_finite().then_some(x);
    let row = SideRow {
        scene: name.to_string(),
        case,
        way,
        casters,
        lights,
        moved,
        frames: cfg.frames,
        cpu_cull_ms: cull,
        cpu_plan_ms: plan,
        cpu_record_ms: record,
        cpu_shadow_ms: planning,
        cpu_frame_ms: cpu,
        bytes_sent: bytes as u64,
        pairs_total: total as u64,
        pairs_replanned: replanned as u64,
        pairs_kept: kept as u64,
        kept_bytes: kept_bytes as u64,
        gpu_shadow_ms: gpu(shadow),
        gpu_frame_ms: gpu(frame),
        wall_ms: wall,
    };
    if row.pairs_total == 0 {
        return Err(Error::Internal(format!("frame-cost: {name} drew no light–caster pair")));
    }
    Ok((ctx, row))
}
