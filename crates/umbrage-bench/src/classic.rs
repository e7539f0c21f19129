//! `umbrage bench` without `--suite`: every method's speed *against its error*, measured side
//! by side in one run on one device: per scene and method, the median of N frames (GPU
//! timestamps and wall clock), the shadow geometry sent, and the mismatch fraction against
//! the CPU reference.

use super::classic_frames::{row_of, time_frames, variant_errors, variants_of, RowAt, RunLimits};
pub use super::classic_rows::{taps_label_of, technique_label, BenchConfig, BenchRow};
use serde::Serialize;
use umbrage::error::{Error, Result};
use umbrage::gpu::Context;
use umbrage_render::{RenderTechnique, Renderer, Technique};

/// A whole `umbrage bench` run: the device and every row (the JSON `--out` writes).
#[derive(Clone, Debug, Serialize)]
pub struct BenchReport {
    /// Vulkan device name.
    pub device: String,
    /// Driver name and driver info string.
    pub driver: String,
    /// Frame width, pixels.
    pub width: u32,
    /// Frame height, pixels.
    pub height: u32,
    /// One row per scene and variant, in the order measured.
    pub rows: Vec<BenchRow>,
    /// With `compute` among the methods: the device's compute streaming-read rate, measured in
    /// the same run ([`super::compute_read`]), GiB / s.
    pub compute_read_gib_s: Option<f64>,
    /// Its sweep: `[planes, GiB / s]` per point.
    pub compute_read_sweep: Vec<[f64; 2]>,
    /// The lighting limit measured in this run on a target of the bench's size
    /// ([`super::pass_limits`]), Gpixels / s (`None` without timestamps).
    pub lighting_gpix_s: Option<f64>,
    /// Its sweep: `[pixels, Gpixels / s]` per point.
    pub lighting_sweep: Vec<[f64; 2]>,
    /// Ablation: the real `illuminate.frag` through the lighting limit's state and sweep,
    /// Gpixels / s ([`super::pass_limits::PassLimits::lighting_shaded_gpix_s`]).
    pub lighting_shaded_gpix_s: Option<f64>,
    /// Ablation: a lighting rendering instance with no draw, ms
    /// ([`super::pass_limits::PassLimits::lighting_instance_ms`]).
    pub lighting_instance_ms: Option<f64>,
    /// The G-buffer geometry limit measured in this run, Mtriangles / s (`None` without
    /// timestamps).
    pub gbuffer_tri_mtri_s: Option<f64>,
    /// Its sweep: `[triangles, Mtriangles / s]` per point.
    pub gbuffer_sweep: Vec<[f64; 2]>,
    /// The G-buffer fill limit measured in this run, Gpixels / s (`None` without timestamps).
    pub gbuffer_fill_gpix_s: Option<f64>,
}

/// Runs the benchmark on `ctx`: per scene, first every variant's error against the reference,
/// then `cfg.frames` frames of each variant interleaved (latency), then each variant's
/// throughput with frames in flight (and, for ray query, a deforming caster's refit);
/// `progress` sees each row as it is done. Anything the validation layers reported (when
/// they are on) fails the run with [`Error::Validation`].
pub fn run(ctx: Context, cfg: &BenchConfig, mut progress: impl FnMut(&BenchRow)) -> Result<BenchReport> {
    if cfg.frames == 0 {
        return Err(Error::input("--frames", "must be at least 1"));
    }
    let device = ctx.info.name.clone();
    let driver = format!("{} {}", ctx.info.driver, ctx.info.driver_info);
    // The compute silhouettes are reported against a plain compute read of their bytes.
    let read = match cfg.techniques.contains(&RenderTechnique::Pass(Technique::Compute)) {
        true => Some(super::compute_read::measure(&ctx, 5, 1 << 22)?),
        false => None,
    };
    let read_gib_s = read.as_ref().map(|r| r.gib_s);
    // The lighting and G-buffer passes are reported against their own limits, measured here
    // on a target of the frames' size.
    let passes = match ctx.features.timestamps {
        true => Some(super::pass_limits::measure(&ctx, cfg.opts.width, cfg.opts.height, 5, 9)?),
        false => None,
    };
    let limits = RunLimits {
        read_gib_s,
        lighting_gpix_s: passes.as_ref().map(|p| p.lighting_gpix_s),
        lighting_one_draw: passes.as_ref().and_then(|p| p.lighting_sweep.first()).map(|p| p[1]),
        gbuffer_tri_mtri_s: passes.as_ref().map(|p| p.gbuffer_tri_mtri_s),
        gbuffer_fill_gpix_s: passes.as_ref().map(|p| p.gbuffer_fill_gpix_s),
    };
    let mut ctx = Some(ctx);
    let mut rows = Vec::new();
    for name in &cfg.scenes {
        let (scene, motion) = umbrage_scene::load_animated(name)?;
        let moving = cfg.motion.then(|| (scene.clone(), motion));
        let c = ctx.take().ok_or_else(|| Error::Internal("the bench lost its context".into()))?;
        let mut r = Renderer::new(c, scene, cfg.opts.clone())?;
        // The variants (technique, counter, compute draws, mesh task stage). Shadow maps do not
        // draw analytic sphere casters (the renderer refuses them): left out.
        let spheres = r.scene().spheres.iter().any(|s| s.casts_shadow);
        let variants = variants_of(cfg, spheres);
        let sc = r.scene();
        let gbuffer_triangles = sc.meshes.iter().filter(|m| m.opacity >= 1.0).map(|m| m.mesh.triangles.len() as u64).sum::<u64>()
            + 12 * sc.spheres.len() as u64;
        let mut errors = Vec::new();
        // With motion, the errors are the last frame's (measured after the frames).
        if moving.is_none() {
            errors = variant_errors(&mut r, name, &variants)?;
        }
        // Round-robin over variants, frame by frame, so that drift (thermal, other load) hits
        // every variant alike: the ratios are measured side by side.
        let acc = time_frames(&mut r, &variants, cfg.frames, moving.as_ref())?;
        if moving.is_some() {
            errors = variant_errors(&mut r, name, &variants)?;
        }
        for ((v, err), a) in variants.iter().zip(&errors).zip(acc) {
            let row = row_of(&mut r, RowAt { name, variant: v, error: err, cfg, gbuffer_triangles }, a, &limits)?;
            progress(&row);
            rows.push(row);
        }
        ctx = Some(r.into_context());
    }
    // Under validation (UMBRAGE_VALIDATION), anything the layers reported fails the run.
    if let Some(c) = &ctx {
        c.check_validation()?;
    }
    Ok(BenchReport {
        device,
        driver,
        width: cfg.opts.width,
        height: cfg.opts.height,
        rows,
        compute_read_gib_s: read_gib_s,
        compute_read_sweep: read.map(|r| r.sweep).unwrap_or_default(),
        lighting_gpix_s: limits.lighting_gpix_s,
        gbuffer_tri_mtri_s: limits.gbuffer_tri_mtri_s,
        gbuffer_fill_gpix_s: limits.gbuffer_fill_gpix_s,
        lighting_shaded_gpix_s: passes.as_ref().map(|p| p.lighting_shaded_gpix_s),
        lighting_instance_ms: passes.as_ref().map(|p| p.lighting_instance_ms),
        lighting_sweep: passes.as_ref().map(|p| p.lighting_sweep.clone()).unwrap_or_default(),
        gbuffer_sweep: passes.map(|p| p.gbuffer_sweep).unwrap_or_default(),
    })
}

impl BenchReport {
    /// The report as a Markdown table (docs/bench-*.md).
    pub fn markdown(&self) -> String {
        let mut s = format!(
            "Device: {} ({}), {}x{}. Medians; wall ms = one frame at a time (latency), fps = throughput with frames in flight; error = mismatched pixels outside a 1-pixel band vs the CPU reference (worst light).\n\n",
            self.device, self.driver, self.width, self.height
        );
        s += "| scene | method | counter | GPU frame ms | GPU shadow ms | map / lookup ms | BLAS build / refit / TLAS ms | wall ms | fps | plan ms | shadow tris | draws | bytes read | bytes sent | error | cases c/1/2/3 |\n";
        s += "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
        let f = |v: Option<f64>| v.map(|x| format!("{x:.2}")).unwrap_or_else(|| "—".into());
        for r in &self.rows {
            s += &format!(
                "| {} | {} | {} | {} | {} | {} | {} | {:.2} | {:.1} | {:.3} | {} | {} | {} | {} | {:.4}% | {}/{}/{}/{} |\n",
                r.scene,
                r.method,
                r.counter,
                f(r.gpu_frame_ms),
                f(r.gpu_shadow_ms),
                match (r.gpu_map_ms, r.gpu_lookup_ms) {
                    (Some(m), Some(l)) => format!("{m:.2} / {l:.2}"),
                    _ => "—".into(),
                },
                match (r.blas_build_ms, r.gpu_tlas_ms) {
                    (Some(b), Some(t)) => format!("{b:.2} / {} / {t:.3}", f(r.blas_refit_ms)),
                    _ => "—".into(),
                },
                r.wall_ms,
                r.throughput_fps,
                r.cpu_plan_ms,
                r.shadow_triangles,
                r.volume_draws,
                r.shadow_bytes,
                r.bytes_sent,
                r.error_fraction * 100.0,
                r.cases[0],
                r.cases[1],
                r.cases[2],
                r.cases[3]
            );
        }
        if let Some(rate) = self.compute_read_gib_s {
            s += &format!("\nCompute streaming read (measured in this run, `shaders/compute_read.wgsl`): {rate:.2} GiB/s.\n");
            for r in self.rows.iter().filter(|r| r.gpu_silhouettes_ms.is_some()) {
                if let (Some(ms), Some(b), Some(frac)) = (r.gpu_silhouettes_ms, r.silhouette_read_bytes, r.silhouette_limit_fraction) {
                    s += &format!(
                        "- {} `{}`: silhouettes {ms:.2} ms for {:.1} MB of tables = {:.0} % of the read limit\n",
                        r.scene,
                        r.method,
                        b as f64 / 1e6,
                        frac * 100.0
                    );
                }
            }
        }
        if let (Some(light), Some(tri)) = (self.lighting_gpix_s, self.gbuffer_tri_mtri_s) {
            s += &format!(
                "\nPass limits (measured in this run, `bench::pass_limits`): lighting {light:.3} Gpixels/s (G-buffer reads + additive blend + stencil test, no shading math; {} with one full-screen draw per rendering instance, as each light's pass; the real `illuminate.frag` through the same state {} Gpixels/s), G-buffer geometry {tri:.2} Mtriangles/s (the G-buffer pipeline, 2-pixel triangles), G-buffer fill {} Gpixels/s.\n",
                self.lighting_sweep.first().map(|p| format!("{:.3}", p[1])).unwrap_or_else(|| "—".into()),
                f(self.lighting_shaded_gpix_s),
                self.gbuffer_fill_gpix_s.map(|x| format!("{x:.3}")).unwrap_or_else(|| "—".into())
            );
            for r in &self.rows {
                s += &format!(
                    "- {} `{}` {}: G-buffer {} ms for {} triangles = {} of its triangle limit, the target's pixels {} of its fill limit; lighting {} ms for {:.2} Mpixels = {} of its limit ({} of its one-draw rate)\n",
                    r.scene,
                    r.method,
                    r.counter,
                    f(r.gpu_gbuffer_ms),
                    r.gbuffer_triangles,
                    r.gbuffer_limit_fraction.map(|x| format!("{:.0} %", x * 100.0)).unwrap_or_else(|| "—".into()),
                    r.gbuffer_fill_fraction.map(|x| format!("{:.0} %", x * 100.0)).unwrap_or_else(|| "—".into()),
                    f(r.gpu_illuminate_ms),
                    r.lit_pixels as f64 / 1e6,
                    r.lighting_limit_fraction.map(|x| format!("{:.0} %", x * 100.0)).unwrap_or_else(|| "—".into()),
                    r.lighting_one_draw_fraction.map(|x| format!("{:.0} %", x * 100.0)).unwrap_or_else(|| "—".into()),
                );
            }
        }
        s
    }
}
