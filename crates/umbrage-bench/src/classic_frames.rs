//! The classic bench's frames and rows (`umbrage bench`, split out of [`super::classic`]): a
//! scene's variants, the round-robin timed frames (with the scene's motion under `--motion`),
//! each variant's error, and a row from its frames.

use super::classic_rows::{BenchConfig, BenchRow, Variant};
use super::stats::median;
use umbrage::error::{Error, Result};
use umbrage_render::accuracy::evaluate;
use umbrage_render::{ComputeDraws, Counter, RenderTechnique, Renderer, Technique};
use umbrage_scene::motion::Motion;
use umbrage_scene::Scene;

/// The limits measured in the run that the rows are put against.
pub(super) struct RunLimits {
    /// The compute streaming-read rate, GiB / s.
    pub read_gib_s: Option<f64>,
    /// The lighting limit, Gpixels / s.
    pub lighting_gpix_s: Option<f64>,
    /// The lighting limit's first sweep point (one draw an instance), Gpixels / s.
    pub lighting_one_draw: Option<f64>,
    /// The G-buffer geometry limit, Mtriangles / s.
    pub gbuffer_tri_mtri_s: Option<f64>,
    /// The G-buffer fill limit, Gpixels / s.
    pub gbuffer_fill_gpix_s: Option<f64>,
}

/// The variants of a scene: every technique with every counter (the compute and mesh ones once
/// per way and task setting), then the shadow maps (left out where `spheres` cast shadows).
pub(super) fn variants_of(cfg: &BenchConfig, spheres: bool) -> Vec<Variant> {
    let ways: &[ComputeDraws] = if cfg.compute_draws.is_empty() { &[ComputeDraws::Auto] } else { &cfg.compute_draws };
    let tasks: &[bool] = if cfg.mesh_task.is_empty() { &[true] } else { &cfg.mesh_task };
    let mut variants: Vec<Variant> = Vec::new();
    for &counter in &cfg.counters {
        for &technique in cfg.techniques.iter().filter(|t| t.shadow_map().is_none()) {
            let one = Variant { technique, counter, draws: ComputeDraws::Auto, task: true };
            match technique {
                RenderTechnique::Pass(Technique::Compute) => variants.extend(ways.iter().map(|&draws| Variant { draws, ..one })),
                RenderTechnique::Pass(Technique::Mesh) => variants.extend(tasks.iter().map(|&task| Variant { task, ..one })),
                _ => variants.push(one),
            }
        }
    }
    variants.extend(cfg.techniques.iter().filter(|t| t.shadow_map().is_some() && !spheres).map(|&technique| Variant {
        technique,
        counter: Counter::Float,
        draws: ComputeDraws::Auto,
        task: true,
    }));
    variants
}

/// A variant's timed frames: each measure frame by frame, and the last frame's statistics.
#[derive(Default)]
pub(super) struct Acc {
    gpu: Vec<f64>,
    depth: Vec<f64>,
    shadow: Vec<f64>,
    illum: Vec<f64>,
    map: Vec<f64>,
    accel: Vec<f64>,
    silhouettes: Vec<f64>,
    wall: Vec<f64>,
    plan: Vec<f64>,
    cull: Vec<f64>,
    record: Vec<f64>,
    bytes: Vec<f64>,
    pairs: [Vec<f64>; 4],
    last: Option<umbrage_render::Stats>,
}

/// `frames` timed frames after a warm-up, round-robin over `variants`; with `moving` (the
/// scene at rest and its motion), frame `k` at its time ([`super::motion::frame_time`]).
pub(super) fn time_frames(r: &mut Renderer, variants: &[Variant], frames: usize, moving: Option<&(Scene, Motion)>) -> Result<Vec<Acc>> {
    let mut acc: Vec<Acc> = variants.iter().map(|_| Acc::default()).collect();
    for frame in 0..=frames {
        if let Some((rest, motion)) = moving {
            super::motion::move_to(r, rest, motion, super::motion::frame_time(frame))?;
        }
        for (k, v) in variants.iter().enumerate() {
            v.apply(r);
            let f = r.render()?;
            if frame == 0 {
                continue; // warm-up: buffers sized, caches hot
            }
            let a = &mut acc[k];
            if let Some(g) = &f.stats.gpu_ms {
                a.gpu.push(g.frame);
                a.depth.push(g.depth);
                a.shadow.push(g.shadow);
                a.illum.push(g.illuminate);
                a.map.push(g.shadow_map);
                a.accel.push(g.accel);
                a.silhouettes.push(g.silhouettes);
            }
            a.wall.push(f.stats.wall_ms);
            a.plan.push(f.stats.cpu_ms.plan + f.stats.cpu_ms.silhouettes);
            a.cull.push(f.stats.cpu_ms.cull);
            a.record.push(f.stats.cpu_ms.record);
            let t = &f.stats.totals;
            a.bytes.push(t.bytes_sent as f64);
            for (v, n) in a.pairs.iter_mut().zip([t.pairs_total, t.pairs_replanned, t.pairs_kept, t.kept_bytes]) {
                v.push(n as f64);
            }
            a.last = Some(f.stats);
        }
    }
    Ok(acc)
}

/// Where a row comes from: its scene, its variant and error, the run's configuration.
pub(super) struct RowAt<'a> {
    /// The scene's name.
    pub name: &'a str,
    /// The variant.
    pub variant: &'a Variant,
    /// Its error against the reference.
    pub error: &'a umbrage_render::accuracy::Row,
    /// The run's configuration.
    pub cfg: &'a BenchConfig,
    /// Triangles the G-buffer pass draws a frame.
    pub gbuffer_triangles: u64,
}

/// The row of `at`'s variant from its frames `a` (its throughput, and for ray query its refit,
/// measured here).
pub(super) fn row_of(r: &mut Renderer, at: RowAt, a: Acc, limits: &RunLimits) -> Result<BenchRow> {
    let RowAt { name, variant: v, error: err, cfg, gbuffer_triangles } = at;
    v.apply(r);
    let Variant { technique, counter, .. } = *v;
    let throughput = r.throughput(cfg.frames.max(2))?;
    let s = a.last.ok_or_else(|| Error::Internal("no frame was measured".into()))?;
    let c = &s.totals.cases;
    let maps = technique.shadow_map().is_some() && !a.map.is_empty();
    let lookup: Vec<f64> = a.shadow.iter().zip(&a.map).map(|(s, m)| s - m).collect();
    // The acceleration structures' stats and times are the ray-query rows' only.
    let ray = technique == RenderTechnique::Pass(Technique::RayQuery);
    let rays = s.ray_query.as_ref().filter(|_| ray);
    let compute = technique == RenderTechnique::Pass(Technique::Compute) && !a.silhouettes.is_empty();
    let silhouettes_ms = compute.then(|| median(a.silhouettes));
    let read_bytes = compute.then_some(s.totals.silhouette_read_bytes);
    let fraction = match (silhouettes_ms, read_bytes, limits.read_gib_s) {
        (Some(ms), Some(b), Some(rate)) if ms > 0.0 && rate > 0.0 => Some(b as f64 / (rate * (1u64 << 30) as f64) * 1e3 / ms),
        _ => None,
    };
    let lit_pixels: u64 =
        s.lights.iter().map(|l| l.scissor.map_or(s.width as u64 * s.height as u64, |[_, _, w, h]| w as u64 * h as u64)).sum();
    let illum_ms = (!a.illum.is_empty()).then(|| median(a.illum));
    let gbuffer_ms = (!a.depth.is_empty()).then(|| median(a.depth));
    let at = |n: u64, rate: Option<f64>, unit: f64, ms: Option<f64>| match (rate, ms) {
        (Some(rate), Some(ms)) if rate > 0.0 && ms > 0.0 => Some(n as f64 / (rate * unit) * 1e3 / ms),
        _ => None,
    };
    let [pairs_total, pairs_replanned, pairs_kept, kept_bytes] = a.pairs.map(|v| median(v) as u64);
    let (cpu_cull_ms, cpu_record_ms) = (median(a.cull), median(a.record));
    let row = BenchRow {
        scene: name.to_string(),
        method: v.label(),
        counter: counter.name().to_string(),
        index_format: s.index_format.name().to_string(),
        frames: cfg.frames,
        gpu_frame_ms: (!a.gpu.is_empty()).then(|| median(a.gpu)),
        gpu_shadow_ms: (!a.shadow.is_empty()).then(|| median(a.shadow)),
        gpu_illuminate_ms: illum_ms,
        gpu_map_ms: maps.then(|| median(a.map)),
        gpu_lookup_ms: maps.then(|| median(lookup)),
        wall_ms: median(a.wall),
        cpu_plan_ms: median(a.plan),
        throughput_fps: throughput.fps,
        frames_in_flight: r.config().frames_in_flight,
        shadow_triangles: s.totals.triangles.total(),
        shadow_bytes: s.totals.index_bytes + s.totals.vertex_bytes,
        bytes_sent: median(a.bytes) as u64,
        error_fraction: err.fraction,
        cases: [c.culled, c.zpass, c.zfail, c.zfail_light_cap],
        volume_draws: s.totals.draws,
        gpu_tlas_ms: (ray && !a.accel.is_empty()).then(|| median(a.accel)),
        blas_build_ms: rays.map(|q| q.bottom_level_build_ms),
        blas_bytes: rays.map(|q| q.bottom_level_bytes),
        blas_refit_ms: if ray { refit_ms(r)? } else { None },
        gpu_silhouettes_ms: silhouettes_ms,
        silhouette_read_bytes: read_bytes,
        silhouette_limit_fraction: fraction,
        gpu_gbuffer_ms: gbuffer_ms,
        gbuffer_triangles,
        lit_pixels,
        lighting_limit_fraction: at(lit_pixels, limits.lighting_gpix_s, 1e9, illum_ms),
        lighting_one_draw_fraction: at(lit_pixels, limits.lighting_one_draw, 1e9, illum_ms),
        gbuffer_limit_fraction: at(gbuffer_triangles, limits.gbuffer_tri_mtri_s, 1e6, gbuffer_ms),
        gbuffer_fill_fraction: at(s.width as u64 * s.height as u64, limits.gbuffer_fill_gpix_s, 1e9, gbuffer_ms),
        cpu_cull_ms,
        cpu_record_ms,
        pairs_total,
        pairs_replanned,
        pairs_kept,
        kept_bytes,
        motion: cfg.motion,
    };
    Ok(row)
}

/// Each variant's error against the reference, for `r`'s scene as it stands.
pub(super) fn variant_errors(r: &mut Renderer, name: &str, variants: &[Variant]) -> Result<Vec<umbrage_render::accuracy::Row>> {
    let mut errors = Vec::new();
    for v in variants {
        v.apply(r);
        errors.extend(evaluate(r, name, &[v.technique], 1)?);
    }
    Ok(errors)
}

/// Frames [`refit_ms`] times.
const REFIT_FRAMES: usize = 5;

/// Ray query's refit cost on `r`'s scene: the largest mesh caster deformed (a 1 % stretch,
/// growing each frame) `REFIT_FRAMES` times after the deformation that rebuilds it with
/// `ALLOW_UPDATE`; the median acceleration span of the refitting frames. The caster's
/// positions are restored before returning (on error too), so the scene is unchanged.
fn refit_ms(r: &mut Renderer) -> Result<Option<f64>> {
    let meshes = &r.scene().meshes;
    let Some(big) = (0..meshes.len()).filter(|&i| meshes[i].casts_shadow).max_by_key(|&i| meshes[i].mesh.triangles.len()) else {
        return Ok(None);
    };
    let rest = meshes[big].mesh.positions.clone();
    let mut spans = Vec::with_capacity(REFIT_FRAMES);
    let mut measure = |r: &mut Renderer| -> Result<()> {
        for k in 0..=REFIT_FRAMES {
            let s = 1.0 + 0.01 * (k + 1) as f32;
            let moved: Vec<glam::Vec3> = rest.iter().map(|p| *p * glam::Vec3::new(s, 1.0 / s, 1.0)).collect();
            r.set_mesh_positions(big, &moved)?;
            let f = r.render()?;
            let refits = f.stats.ray_query.as_ref().map_or(0, |q| q.refits);
            match (k, f.stats.gpu_ms) {
                // The first deformation rebuilds the bottom level with ALLOW_UPDATE.
                (0, _) => {}
                (_, Some(g)) if refits > 0 => spans.push(g.accel),
                _ => return Err(Error::Internal(format!("ray query: frame {k} after a deformation refitted nothing"))),
            }
        }
        Ok(())
    };
    let measured = measure(r);
    let restored = r.set_mesh_positions(big, &rest);
    measured?;
    restored?;
    Ok((!spans.is_empty()).then(|| median(spans)))
}
