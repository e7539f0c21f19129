//! `umbrage bench --suite frame-cost` (issue 55): what a frame costs when only some of the
//! scene changed, measured side by side in one run, and written as `docs/frame-cost.md`.
//!
//! - **Side by side** ([`side`]): `bench/level` (its own walk) and `default`, `stress` and
//!   `bench/vertex` (the camera orbiting their target), each in three cases (only the camera
//!   moves; a few casters move too; a few lights move too), each with three techniques
//!   (McGuire's volumes planned every frame, `--no-keep`; the same with the plans kept; the
//!   `compute` technique), through the renderer: the pass's CPU split, the renderer's
//!   recording, bytes sent, pairs planned and kept, GPU shadow time, medians over the frames.
//! - **Curves** ([`curves`]): the shadow pass alone (no drawing), camera walking, CPU per frame
//!   against lights (the level's casters, 8 to 1,024 lights) and against casters (levels of
//!   2 x 2 to 16 x 16 rooms: 68 to 4,352 casters), kept and not, with plots (`plot.rs`).
//!
//! Every timing comes from the timers around the pass's and the renderer's phases
//! (`Stats::cpu_ms`, `gpu_ms`), or the wall clock around `ShadowPass::prepare`.

mod cases;
pub mod curves;
mod markdown;
mod plot;
pub mod side;

use serde::Serialize;
use std::path::PathBuf;
use umbrage::error::{Error, Result};
use umbrage::gpu::Context;

pub use cases::Case;

/// What to run (`umbrage bench --suite frame-cost`).
#[derive(Clone, Debug)]
pub struct FrameCostConfig {
    /// Measured frames of each side-by-side row (after [`WARM_UP`] frames).
    pub frames: usize,
    /// The side-by-side rows' frame size.
    pub size: (u32, u32),
    /// Light counts of the lights curve (the level's casters).
    pub lights: Vec<usize>,
    /// Rooms a side of the casters curve's levels.
    pub rooms: Vec<usize>,
    /// Measured frames of each curve point.
    pub curve_frames: usize,
    /// Where the plots go (the report links them relative to the Markdown's directory).
    pub out: PathBuf,
    /// Print a line per row on stderr.
    pub progress: bool,
}

impl FrameCostConfig {
    /// The report's configuration: 20 frames at 480x270, lights 8 to 1,024, 2 to 16 rooms.
    pub fn full(out: PathBuf) -> FrameCostConfig {
        FrameCostConfig {
            frames: 20,
            size: (480, 270),
            lights: vec![8, 32, 128, 512, 1024],
            rooms: vec![2, 4, 8, 12, 16],
            curve_frames: 12,
            out,
            progress: true,
        }
    }

    /// A small run for tests: 2 frames at 96x54, two points a curve.
    pub fn tiny(out: PathBuf) -> FrameCostConfig {
        FrameCostConfig { frames: 2, size: (96, 54), lights: vec![8, 32], rooms: vec![2, 3], curve_frames: 2, out, progress: false }
    }
}

/// Frames rendered before the measured ones: the first plans every pair, the second settles
/// what the first one's view made of the cases.
pub const WARM_UP: usize = 2;

/// The whole run (`frame-cost.json`).
#[derive(Clone, Debug, Serialize)]
pub struct FrameCostReport {
    /// Vulkan device name.
    pub device: String,
    /// Driver name and info.
    pub driver: String,
    /// CPU cores the process may use.
    pub cores: usize,
    /// The 1-minute load average at the start and at the end (`None` off Linux): other work
    /// on the machine slows the timings.
    pub load_average: [Option<f64>; 2],
    /// Measured frames a side-by-side row, and its frame size.
    pub frames: usize,
    /// Frame size of the side-by-side rows.
    pub size: [u32; 2],
    /// The side-by-side rows, scene by scene, case by case, technique by technique.
    pub rows: Vec<side::SideRow>,
    /// CPU per frame against lights.
    pub lights_curve: Vec<curves::CurvePoint>,
    /// CPU per frame against casters.
    pub casters_curve: Vec<curves::CurvePoint>,
}

/// Runs everything on `ctx` and writes the plots into `cfg.out` (and `frame-cost.json`).
pub fn run(ctx: Context, cfg: &FrameCostConfig) -> Result<FrameCostReport> {
    if cfg.frames == 0 || cfg.curve_frames == 0 {
        return Err(Error::input("frame-cost frames", "must be at least 1"));
    }
    let load0 = super::phases::load_average();
    let device = ctx.info.name.clone();
    let driver = format!("{} {}", ctx.info.driver, ctx.info.driver_info);
    let (ctx, rows) = side::run(ctx, cfg)?;
    let lights_curve = curves::lights(&ctx, cfg)?;
    let casters_curve = curves::casters(&ctx, cfg)?;
    ctx.check_validation()?;
    let report = FrameCostReport {
        device,
        driver,
        cores: std::thread::available_parallelism().map_or(1, |n| n.get()),
        load_average: [load0, super::phases::load_average()],
        frames: cfg.frames,
        size: [cfg.size.0, cfg.size.1],
        rows,
        lights_curve,
        casters_curve,
    };
    std::fs::create_dir_all(&cfg.out).map_err(|e| Error::io(cfg.out.display().to_string(), e))?;
    plot::write(&report, &cfg.out)?;
    let p = cfg.out.join("frame-cost.json");
    let text = serde_json::to_string_pretty(&report).map_err(|e| Error::Internal(format!("frame-cost report JSON: {e}")))?;
    std::fs::write(&p, text).map_err(|e| Error::io(p.display().to_string(), e))?;
    Ok(report)
}

impl FrameCostReport {
    /// The report as Markdown (`docs/frame-cost.md`), the plots linked under `plots`.
    pub fn markdown(&self, plots: &str) -> String {
        markdown::report(self, plots)
    }
}
