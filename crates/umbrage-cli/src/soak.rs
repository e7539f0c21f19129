//! `umbrage bench --soak N`: N frames in one process with the lights orbiting and every caster
//! spinning, frames in flight, host memory (RSS) and GPU allocations (gpu-allocator's report)
//! sampled over the run. It fails when memory drifts after warm-up, when validation reports
//! anything, or when the last frame's shadow masks differ from a fresh renderer's frame of the
//! same state.
#![warn(missing_docs)]

use glam::{Mat4, Quat, Vec3};
use serde::Serialize;
use std::collections::VecDeque;
use std::time::Instant;
use umbrage::error::{Error, Result};
use umbrage::gpu::Context;
use umbrage_render::{FrameOutput, FrameTicket, RenderOptions, Renderer};
use umbrage_scene::Scene;

/// What to soak.
#[derive(Clone, Debug)]
pub struct SoakConfig {
    /// Scene, by built-in name or path ([`umbrage_scene::load`]).
    pub scene: String,
    /// Frames to render.
    pub frames: usize,
    /// Frames per full turn of the motion (lights orbit and casters spin once per period);
    /// the first period is the warm-up.
    pub period: usize,
    /// Take a memory sample every this many frames (the last, captured, frame is not sampled).
    pub sample_every: usize,
    /// Allowed relative spread of the samples after warm-up (0.01 = 1 %).
    pub tolerance: f64,
    /// Size, method and frames in flight.
    pub options: RenderOptions,
}

/// One memory sample.
#[derive(Clone, Debug, Serialize)]
pub struct SoakSample {
    /// Frames finished when the sample was taken.
    pub frame: usize,
    /// Seconds since the first frame.
    pub seconds: f64,
    /// Resident set size of the process, bytes (`/proc/self/statm`; 0 where unavailable).
    pub rss_bytes: u64,
    /// Bytes in live gpu-allocator allocations.
    pub gpu_allocated_bytes: u64,
    /// Bytes in gpu-allocator's memory blocks (allocated or not).
    pub gpu_capacity_bytes: u64,
    /// Live allocations.
    pub gpu_allocations: usize,
}

/// The result of a soak (the JSON `--json` writes).
#[derive(Clone, Debug, Serialize)]
pub struct SoakReport {
    /// Vulkan device name.
    pub device: String,
    /// Scene soaked.
    pub scene: String,
    /// Frame size.
    pub width: u32,
    /// Frame size.
    pub height: u32,
    /// Frames rendered.
    pub frames: usize,
    /// Frames in flight.
    pub frames_in_flight: usize,
    /// Frames of warm-up excluded from the drift (one motion period).
    pub warmup_frames: usize,
    /// Wall-clock seconds of the whole run.
    pub seconds: f64,
    /// (max - min) / min of the RSS samples after warm-up: the band the process's memory
    /// moves in (malloc arenas and the driver's own allocations come and go).
    pub rss_spread: f64,
    /// Growth of the RSS after warm-up: the median of the last quarter of the samples over the
    /// median of the first quarter, minus one. A leak shows here; the pass criterion.
    pub rss_drift: f64,
    /// (max - min) / min of the GPU allocated bytes after warm-up.
    pub gpu_spread: f64,
    /// Largest RSS after warm-up, bytes.
    pub rss_max_bytes: u64,
    /// Largest GPU allocation total after warm-up, bytes.
    pub gpu_max_bytes: u64,
    /// Validation errors over the run (0 when validation is off: see `validation`).
    pub validation_errors: usize,
    /// Whether the validation layers were on.
    pub validation: bool,
    /// Shadow-mask pixels of the last frame that differ from a fresh renderer's frame of the
    /// same state (all lights).
    pub final_mask_mismatches: usize,
    /// The allowed spread.
    pub tolerance: f64,
    /// Whether nothing drifted: spreads within tolerance, no validation error, masks equal.
    pub passed: bool,
    /// The samples, in order.
    pub samples: Vec<SoakSample>,
}

/// Resident set size of this process in bytes (0 where `/proc` is missing).
pub fn rss_bytes() -> u64 {
    let Ok(statm) = std::fs::read_to_string("/proc/self/statm") else { return 0 };
    let pages: u64 = statm.split_whitespace().nth(1).and_then(|s| s.parse().ok()).unwrap_or(0);
    pages * 4096
}

/// The scene's state at frame `i`: light `k` orbits the scene's centre about +Y (one turn a
/// period, each light its own phase kept), directional lights turn with it, and caster `m`
/// spins about the vertical axis through its own centre. A pure function of `i`, so any frame
/// can be rebuilt exactly.
pub fn state_at(base: &Scene, i: usize, period: usize) -> Scene {
    let angle = std::f32::consts::TAU * (i % period.max(1)) as f32 / period.max(1) as f32;
    let turn = Quat::from_rotation_y(angle);
    let mut s = base.clone();
    let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
    for m in &base.meshes {
        let b = m.world_bounds();
        lo = lo.min(b.min);
        hi = hi.max(b.max);
    }
    let center = if lo.x <= hi.x { (lo + hi) * 0.5 } else { Vec3::ZERO };
    let pivot = Vec3::new(center.x, 0.0, center.z);
    for l in &mut s.lights {
        l.position = pivot + turn * (l.position - pivot);
        l.direction = turn * l.direction;
    }
    for m in s.meshes.iter_mut().filter(|m| m.casts_shadow) {
        let c = m.world_bounds().center();
        let spin = Mat4::from_translation(c) * Mat4::from_quat(Quat::from_rotation_y(-angle)) * Mat4::from_translation(-c);
        m.transform = spin * m.transform;
    }
    s
}

fn sample(r: &Renderer, frame: usize, start: Instant) -> SoakSample {
    let report = r.context().allocator().generate_report();
    SoakSample {
        frame,
        seconds: start.elapsed().as_secs_f64(),
        rss_bytes: rss_bytes(),
        gpu_allocated_bytes: report.total_allocated_bytes,
        gpu_capacity_bytes: report.total_capacity_bytes,
        gpu_allocations: report.allocations.len(),
    }
}

fn spread(values: impl Iterator<Item = u64>) -> (f64, u64) {
    let v: Vec<u64> = values.collect();
    let (Some(&lo), Some(&hi)) = (v.iter().min(), v.iter().max()) else { return (0.0, 0) };
    ((hi - lo) as f64 / lo.max(1) as f64, hi)
}

/// Median of the last quarter over the median of the first quarter, minus one (0 for fewer
/// than 4 samples).
fn drift(v: &[u64]) -> f64 {
    if v.len() < 4 {
        return 0.0;
    }
    let q = v.len() / 4;
    let median = |w: &[u64]| {
        let mut w = w.to_vec();
        w.sort_unstable();
        w[w.len() / 2] as f64
    };
    let (first, last) = (median(&v[..q]), median(&v[v.len() - q..]));
    last / first.max(1.0) - 1.0
}

fn apply(r: &mut Renderer, state: &Scene) -> Result<()> {
    r.set_lights(state.lights.clone())?;
    for (k, m) in state.meshes.iter().enumerate().filter(|(_, m)| m.casts_shadow) {
        r.set_mesh_transform(k, m.transform)?;
    }
    Ok(())
}

/// Differing mask pixels of two frames, each read with the scene its renderer drew (area
/// lights as their point-light samples).
fn mismatches(a: &FrameOutput, sa: &Scene, b: &FrameOutput, sb: &Scene) -> usize {
    let (ma, mb) = (a.shadow_masks(sa), b.shadow_masks(sb));
    ma.iter().zip(&mb).map(|(x, y)| x.iter().zip(y).filter(|(p, q)| p != q).count()).sum::<usize>()
        + ma.len().abs_diff(mb.len()) * (a.width * a.height) as usize
}

/// Runs the soak (see the module docs), printing a progress line every tenth of the run.
pub fn soak(cfg: &SoakConfig) -> Result<SoakReport> {
    if cfg.frames == 0 || cfg.period == 0 || cfg.sample_every == 0 {
        return Err(Error::input("--soak", "frames, period and sample interval must be at least 1"));
    }
    let base = umbrage_scene::load(&cfg.scene)?;
    let ctx = Context::new()?;
    let validation = ctx.validation;
    let device = ctx.info.name.clone();
    let mut r = Renderer::new(ctx, base.clone(), cfg.options.clone())?;
    let start = Instant::now();
    let mut samples = Vec::new();
    let mut validation_errors = 0;
    let mut queue: VecDeque<FrameTicket> = VecDeque::new();
    let depth = r.config().frames_in_flight.max(1);
    let mut last = None;
    for i in 0..cfg.frames {
        apply(&mut r, &state_at(&base, i, cfg.period))?;
        r.settings.capture = i + 1 == cfg.frames;
        queue.push_back(r.submit()?);
        if queue.len() >= depth || i + 1 == cfg.frames {
            while queue.len() >= depth || (i + 1 == cfg.frames && !queue.is_empty()) {
                let ticket = queue.pop_front().ok_or_else(|| Error::Internal("soak: empty frame queue".into()))?;
                last = Some(r.finish(ticket)?);
            }
        }
        let done = i + 1;
        // The last frame captures its masks (a bigger readback): sampled before it only.
        if done % cfg.sample_every == 0 && done < cfg.frames {
            validation_errors += r.context().take_validation_errors().len();
            samples.push(sample(&r, done, start));
        }
        if done % (cfg.frames / 10).max(1) == 0 {
            eprintln!("soak: {done}/{} frames, {:.0} s", cfg.frames, start.elapsed().as_secs_f64());
        }
    }
    let last = last.ok_or_else(|| Error::Internal("soak: no frame finished".into()))?;
    let state = state_at(&base, cfg.frames - 1, cfg.period);
    let (width, height, frames_in_flight) = (r.config().width, r.config().height, r.config().frames_in_flight);
    let seconds = start.elapsed().as_secs_f64();
    let drawn = r.scene().clone();
    let ctx = r.into_context();
    validation_errors += ctx.take_validation_errors().len();

    // A fresh renderer of the last frame's state, on the same device.
    let mut opts = cfg.options.clone();
    opts.capture = true;
    let mut fresh = Renderer::new(ctx, state.clone(), opts)?;
    let reference = fresh.render()?;
    validation_errors += fresh.context().take_validation_errors().len();
    let final_mask_mismatches = mismatches(&last, &drawn, &reference, fresh.scene());

    let warmup_frames = cfg.period.min(cfg.frames);
    let steady: Vec<&SoakSample> = samples.iter().filter(|s| s.frame > warmup_frames).collect();
    let (rss_spread, rss_max_bytes) = spread(steady.iter().map(|s| s.rss_bytes));
    let (gpu_spread, gpu_max_bytes) = spread(steady.iter().map(|s| s.gpu_allocated_bytes));
    let rss_drift = drift(&steady.iter().map(|s| s.rss_bytes).collect::<Vec<_>>());
    let passed = rss_drift.abs() <= cfg.tolerance && gpu_spread <= cfg.tolerance && validation_errors == 0 && final_mask_mismatches == 0;
    Ok(SoakReport {
        device,
        scene: cfg.scene.clone(),
        width,
        height,
        frames: cfg.frames,
        frames_in_flight,
        warmup_frames,
        seconds,
        rss_spread,
        rss_drift,
        gpu_spread,
        rss_max_bytes,
        gpu_max_bytes,
        validation_errors,
        validation,
        final_mask_mismatches,
        tolerance: cfg.tolerance,
        passed,
        samples,
    })
}

impl SoakReport {
    /// A Markdown summary and sample table (for docs/soak.md).
    pub fn markdown(&self) -> String {
        let mib = |b: u64| b as f64 / (1024.0 * 1024.0);
        let mut s = format!(
            "Device: {}; scene `{}` at {}x{}, {} frames ({} in flight) in {:.1} s; warm-up {} frames (one motion period).\n\n\
             After warm-up: RSS drift {:+.3} % (last quarter's median over the first's), band {:.3} % (max {:.1} MiB), GPU allocations spread {:.3} % (max {:.2} MiB), \
             tolerance {:.1} %; validation errors {} (validation {}); last frame vs a fresh render: {} mask pixels differ. \
             **{}**\n\n| frame | s | RSS MiB | GPU allocated MiB | GPU blocks MiB | allocations |\n|---:|---:|---:|---:|---:|---:|\n",
            self.device,
            self.scene,
            self.width,
            self.height,
            self.frames,
            self.frames_in_flight,
            self.seconds,
            self.warmup_frames,
            self.rss_drift * 100.0,
            self.rss_spread * 100.0,
            mib(self.rss_max_bytes),
            self.gpu_spread * 100.0,
            mib(self.gpu_max_bytes),
            self.tolerance * 100.0,
            self.validation_errors,
            if self.validation { "on" } else { "off" },
            self.final_mask_mismatches,
            if self.passed { "passed" } else { "FAILED" }
        );
        let step = (self.samples.len() / 20).max(1);
        for (k, x) in self.samples.iter().enumerate() {
            if k % step == 0 || k + 1 == self.samples.len() {
                s += &format!(
                    "| {} | {:.1} | {:.2} | {:.3} | {:.3} | {} |\n",
                    x.frame,
                    x.seconds,
                    mib(x.rss_bytes),
                    mib(x.gpu_allocated_bytes),
                    mib(x.gpu_capacity_bytes),
                    x.gpu_allocations
                );
            }
        }
        s
    }
}
