//! `umbrage bench` without `--suite`: every method's speed *against its error*, measured side
//! by side in one run on one device: per scene and method, the median of N frames (GPU
//! timestamps and wall clock), the shadow geometry sent, and the mismatch fraction against
//! the CPU reference.

use super::stats::median;
use serde::Serialize;
use umbrage::error::{Error, Result};
use umbrage::gpu::Context;
use umbrage_render::accuracy::evaluate;
use umbrage_render::{ComputeDraws, Counter, RenderOptions, Renderer, Technique};

/// One (scene, method, counter) measurement: medians over the measured frames.
#[derive(Clone, Debug, Serialize)]
pub struct BenchRow {
    /// Scene name or path, as given.
    pub scene: String,
    /// Method name ([`umbrage::shadow::Method::name`]), or `shadowmap-<size>` / `edgequad` for the baselines.
    pub method: String,
    /// Shadow counter: `stencil` or `float`.
    pub counter: String,
    /// Index format the renderer actually used (`u8`, `u16`, `u32`, ...).
    pub index_format: String,
    /// Frames measured (after one warm-up frame).
    pub frames: usize,
    /// Median GPU time of the whole frame, ms (`None` without timestamp queries).
    pub gpu_frame_ms: Option<f64>,
    /// Median GPU time of the shadow determination (all lights), ms.
    pub gpu_shadow_ms: Option<f64>,
    /// Median GPU time of the illumination passes (all lights), ms.
    pub gpu_illuminate_ms: Option<f64>,
    /// Shadow maps: median GPU time of rendering the maps (all lights), ms, part of
    /// `gpu_shadow_ms` (`None` for the other techniques).
    pub gpu_map_ms: Option<f64>,
    /// Shadow maps: median GPU time of the PCF lookups (all lights), ms: `gpu_shadow_ms` less
    /// the maps, frame by frame (`None` for the other techniques).
    pub gpu_lookup_ms: Option<f64>,
    /// Median wall-clock time of `Renderer::render` (plan, record, submit, wait, read back), ms.
    pub wall_ms: f64,
    /// Median CPU planning time (silhouettes included), ms.
    pub cpu_plan_ms: f64,
    /// Frames per second rendered back to back with `frames_in_flight` frames overlapping
    /// ([`Renderer::throughput`]); `1000 / wall_ms` is the one-at-a-time rate.
    pub throughput_fps: f64,
    /// Frames in flight during the throughput run.
    pub frames_in_flight: usize,
    /// Shadow-volume triangles drawn in one frame (all lights, sides + caps).
    pub shadow_triangles: u64,
    /// Index and vertex bytes the shadow volumes' draws read in one frame (uploaded by the
    /// CPU for the CPU-planned methods, written by the GPU for `compute`; 0 for `mesh`).
    pub shadow_bytes: u64,
    /// Geometry bytes the CPU wrote for the frame (`Totals::bytes_sent`: the streams plus any
    /// caster uploads; 0 for static casters under a GPU-driven technique).
    pub bytes_sent: u64,
    /// Worst light's mismatches outside a 1-pixel band / compared pixels.
    pub error_fraction: f64,
    /// (caster, light) pairs per case in one frame: `[culled, z-pass, z-fail, z-fail + light cap]`.
    pub cases: [u64; 4],
    /// Volume draw calls the frame's determinations record, all lights (`totals.draws` in
    /// `--stats`): one per chunk and case, or for `compute`'s merged draws one per light and
    /// pipeline (`count`, `multi`).
    pub volume_draws: u64,
    /// Ray query: median GPU time of the frame's top-level build, ms (`None` otherwise).
    pub gpu_tlas_ms: Option<f64>,
    /// Ray query: GPU time of the frame that built the bottom levels (its acceleration span:
    /// the builds and that frame's top level), ms.
    pub blas_build_ms: Option<f64>,
    /// Ray query: bottom-level storage after compaction, bytes.
    pub blas_bytes: Option<u64>,
    /// Ray query: median GPU time of a frame that refits the largest caster's bottom level in
    /// place after a deformation ([`Renderer::set_mesh_positions`]: rebuilt once with
    /// `ALLOW_UPDATE`, then refitted; the caster is put back afterwards), its acceleration
    /// span, ms (`None` otherwise, or with no mesh caster).
    pub blas_refit_ms: Option<f64>,
    /// `compute`: median GPU time of the silhouettes' compute pass (every light), ms (`None`
    /// for the other techniques).
    pub gpu_silhouettes_ms: Option<f64>,
    /// `compute`: bytes that pass reads from the static tables a frame (16 a triangle, 16 an
    /// edge, per light and caster).
    pub silhouette_read_bytes: Option<u64>,
    /// `compute`: the time a plain compute read of those bytes takes at the device's measured
    /// rate ([`BenchReport::compute_read_gib_s`]) over the pass's time (1 = at the limit).
    pub silhouette_limit_fraction: Option<f64>,
    /// Median GPU time of the G-buffer pass, ms (`gpu_ms.depth`).
    pub gpu_gbuffer_ms: Option<f64>,
    /// Triangles the G-buffer pass draws a frame: every opaque mesh's, 12 a sphere (its cube).
    pub gbuffer_triangles: u64,
    /// Pixels the illumination passes cover a frame: every light's scissor (the whole target
    /// without one).
    pub lit_pixels: u64,
    /// `lit_pixels` at the measured lighting limit ([`BenchReport::lighting_gpix_s`]) over
    /// `gpu_illuminate_ms` (1 = at the limit).
    pub lighting_limit_fraction: Option<f64>,
    /// `lit_pixels` at the lighting limit's first sweep point (one full-screen draw in its own
    /// rendering instance, as each light's pass is drawn) over `gpu_illuminate_ms`.
    pub lighting_one_draw_fraction: Option<f64>,
    /// `gbuffer_triangles` at the measured G-buffer geometry limit
    /// ([`BenchReport::gbuffer_tri_mtri_s`]) over `gpu_gbuffer_ms` (1 = at the limit).
    pub gbuffer_limit_fraction: Option<f64>,
    /// The target's pixels at the measured G-buffer fill limit
    /// ([`BenchReport::gbuffer_fill_gpix_s`]) over `gpu_gbuffer_ms`: the pass's fill against its
    /// limit where the scene covers the target once (more overdraw: more; background: less).
    pub gbuffer_fill_fraction: Option<f64>,
    /// Median CPU time of culling, the cases and the kept plans' look-ups, ms (with
    /// `PassSettings::keep`; 0 without it: that work is then inside `cpu_plan_ms`).
    pub cpu_cull_ms: f64,
    /// Median CPU time of writing the frame's stream and the pass's records, ms.
    pub cpu_record_ms: f64,
    /// Median light–caster pairs drawn a frame.
    pub pairs_total: u64,
    /// Median pairs planned a frame (all drawn pairs without keeping).
    pub pairs_replanned: u64,
    /// Median pairs drawn from plans kept across frames.
    pub pairs_kept: u64,
    /// Median bytes of index lists kept across frames.
    pub kept_bytes: u64,
    /// Whether the frames ran the scene's motion (`--motion`: frame `k` at `k / 30` s; the
    /// error is then the last frame's); `false`: every frame at time 0.
    pub motion: bool,
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
                _ => return Err(Error::Other(format!("ray query: frame {k} after a deformation refitted nothing"))),
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

/// What to measure.
pub struct BenchConfig {
    /// Scenes, by built-in name or path ([`umbrage_scene::load`]).
    pub scenes: Vec<String>,
    /// Techniques to compare: volume methods, edge quads, shadow maps (each size its own).
    pub techniques: Vec<Technique>,
    /// Each volume technique runs with each counter (stencil, float), side by side; shadow
    /// maps run once (they count in the float target).
    pub counters: Vec<Counter>,
    /// Frames measured per variant (at least 1), round-robin over the variants.
    pub frames: usize,
    /// `compute` runs once per way of recording its volume draws here (rows `compute` for
    /// [`ComputeDraws::Auto`], `compute-<way>` for the others); empty: `Auto` only.
    pub compute_draws: Vec<ComputeDraws>,
    /// [`Technique::Mesh`]'s task stage ([`umbrage::pass::PassToggles::mesh_task`]): a row per
    /// value, `mesh` (on) and `mesh-notask` (off: every meshlet's mesh workgroup runs), side
    /// by side; empty: on only.
    pub mesh_task: Vec<bool>,
    /// Renderer options for everything else (size, depth mode, ...).
    pub opts: RenderOptions,
    /// Run each scene's motion over the frames ([`super::motion`]: the warm-up frame at time
    /// 0, measured frame `k` at `k / 30` s; each row's error is the last frame's); `false`:
    /// every frame at time 0.
    pub motion: bool,
}

/// The name of a bench row's technique (`shadowmap-512`; `shadowmap-512-multiview` for cube
/// faces rendered as views, then `-gather` for the gathering lookup:
/// `shadowmap-512-multiview-gather`).
pub fn technique_label(t: Technique) -> String {
    match t {
        Technique::ShadowMap { size, pcf, cube } => {
            let views = match cube {
                umbrage_render::CubeFaces::Atlas => "",
                umbrage_render::CubeFaces::Multiview => MULTIVIEW_SUFFIX,
            };
            let lookup = match pcf {
                umbrage_render::Pcf::Taps => "",
                umbrage_render::Pcf::Gather => GATHER_SUFFIX,
            };
            format!("shadowmap-{size}{views}{lookup}")
        }
        t => t.name().to_string(),
    }
}

/// One row's settings: its technique and counter, and the compute and mesh techniques' own.
#[derive(Clone, Copy, Debug)]
struct Variant {
    technique: Technique,
    counter: Counter,
    /// [`umbrage::pass::PassToggles::compute_draws`] (only `Auto` for the other techniques).
    draws: ComputeDraws,
    /// [`umbrage::pass::PassToggles::mesh_task`] (only `true` for the other techniques).
    task: bool,
}

impl Variant {
    /// Sets the renderer up to draw this variant.
    fn apply(&self, r: &mut Renderer) {
        r.settings.technique = self.technique;
        r.settings.counter = self.counter;
        r.settings.toggles.compute_draws = self.draws;
        r.settings.toggles.mesh_task = self.task;
    }

    /// The row's `method`: [`technique_label`], then `-<way>` for a compute way other than
    /// `Auto`, or [`NOTASK_SUFFIX`] for a mesh row without its task stage.
    fn label(&self) -> String {
        let base = technique_label(self.technique);
        match (self.draws, self.task) {
            (ComputeDraws::Auto, true) => base,
            (ComputeDraws::Auto, false) => format!("{base}{NOTASK_SUFFIX}"),
            (w, _) => format!("{base}-{}", w.name()),
        }
    }
}

/// What a `mesh` row's label has appended when its task stage was off
/// ([`BenchConfig::mesh_task`]).
const NOTASK_SUFFIX: &str = "-notask";

/// What [`technique_label`] appends for a shadow map whose cube faces are multiview views.
const MULTIVIEW_SUFFIX: &str = "-multiview";

/// What [`technique_label`] appends for a shadow map read with gathers.
const GATHER_SUFFIX: &str = "-gather";

/// For a gathering shadow map's label (`shadowmap-512-gather`), the label of the same map read
/// with taps (`shadowmap-512`); `None` for every other label.
pub fn taps_label_of(label: &str) -> Option<&str> {
    label.strip_suffix(GATHER_SUFFIX).filter(|l| l.starts_with("shadowmap"))
}

/// Runs the benchmark on `ctx`: per scene, first every variant's error against the reference,
/// then `cfg.frames` frames of each variant interleaved (latency), then each variant's
/// throughput with frames in flight (and, for ray query, a deforming caster's refit);
/// `progress` sees each row as it is done. Anything the validation layers reported (when
/// they are on) fails the run with [`Error::Validation`].
pub fn run(ctx: Context, cfg: &BenchConfig, mut progress: impl FnMut(&BenchRow)) -> Result<BenchReport> {
    if cfg.frames == 0 {
        return Err(Error::Other("--frames must be at least 1".into()));
    }
    let device = ctx.info.name.clone();
    let driver = format!("{} {}", ctx.info.driver, ctx.info.driver_info);
    // The compute silhouettes are reported against a plain compute read of their bytes.
    let read = match cfg.techniques.contains(&Technique::Compute) {
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
    let lighting_gpix_s = passes.as_ref().map(|p| p.lighting_gpix_s);
    let gbuffer_tri_mtri_s = passes.as_ref().map(|p| p.gbuffer_tri_mtri_s);
    let gbuffer_fill_gpix_s = passes.as_ref().map(|p| p.gbuffer_fill_gpix_s);
    let lighting_one_draw = passes.as_ref().and_then(|p| p.lighting_sweep.first()).map(|p| p[1]);
    let mut ctx = Some(ctx);
    let mut rows = Vec::new();
    for name in &cfg.scenes {
        let (scene, motion) = umbrage_scene::load_animated(name)?;
        let moving = cfg.motion.then(|| (scene.clone(), motion));
        let c = ctx.take().ok_or_else(|| Error::Other("context lost".into()))?;
        let mut r = Renderer::new(c, scene, cfg.opts.clone())?;
        // The variants (technique, counter, compute draws, mesh task stage), and their error
        // against the reference.
        let ways: &[ComputeDraws] = if cfg.compute_draws.is_empty() { &[ComputeDraws::Auto] } else { &cfg.compute_draws };
        let tasks: &[bool] = if cfg.mesh_task.is_empty() { &[true] } else { &cfg.mesh_task };
        let mut variants: Vec<Variant> = Vec::new();
        for &counter in &cfg.counters {
            for &technique in cfg.techniques.iter().filter(|t| !matches!(t, Technique::ShadowMap { .. })) {
                let one = Variant { technique, counter, draws: ComputeDraws::Auto, task: true };
                match technique {
                    Technique::Compute => variants.extend(ways.iter().map(|&draws| Variant { draws, ..one })),
                    Technique::Mesh => variants.extend(tasks.iter().map(|&task| Variant { task, ..one })),
                    _ => variants.push(one),
                }
            }
        }
        // Shadow maps do not draw analytic sphere casters (the renderer refuses them): left out.
        let spheres = r.scene().spheres.iter().any(|s| s.casts_shadow);
        variants.extend(cfg.techniques.iter().filter(|t| matches!(t, Technique::ShadowMap { .. }) && !spheres).map(|&technique| Variant {
            technique,
            counter: Counter::Float,
            draws: ComputeDraws::Auto,
            task: true,
        }));
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
        #[derive(Default)]
        struct Acc {
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
        let mut acc: Vec<Acc> = variants.iter().map(|_| Acc::default()).collect();
        for frame in 0..=cfg.frames {
            if let Some((rest, motion)) = &moving {
                super::motion::move_to(&mut r, rest, motion, super::motion::frame_time(frame))?;
            }
            for (k, v) in variants.iter().enumerate() {
                v.apply(&mut r);
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
        if moving.is_some() {
            errors = variant_errors(&mut r, name, &variants)?;
        }
        for ((v, err), a) in variants.iter().zip(&errors).zip(acc) {
            v.apply(&mut r);
            let Variant { technique, counter, .. } = *v;
            let throughput = r.throughput(cfg.frames.max(2))?;
            let s = a.last.ok_or_else(|| Error::Other("no frame".into()))?;
            let c = &s.totals.cases;
            let maps = matches!(technique, Technique::ShadowMap { .. }) && !a.map.is_empty();
            let lookup: Vec<f64> = a.shadow.iter().zip(&a.map).map(|(s, m)| s - m).collect();
            // The acceleration structures' stats and times are the ray-query rows' only.
            let ray = technique == Technique::RayQuery;
            let rays = s.ray_query.as_ref().filter(|_| ray);
            let compute = technique == Technique::Compute && !a.silhouettes.is_empty();
            let silhouettes_ms = compute.then(|| median(a.silhouettes));
            let read_bytes = compute.then_some(s.totals.silhouette_read_bytes);
            let fraction = match (silhouettes_ms, read_bytes, read_gib_s) {
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
                scene: name.clone(),
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
                blas_refit_ms: if ray { refit_ms(&mut r)? } else { None },
                gpu_silhouettes_ms: silhouettes_ms,
                silhouette_read_bytes: read_bytes,
                silhouette_limit_fraction: fraction,
                gpu_gbuffer_ms: gbuffer_ms,
                gbuffer_triangles,
                lit_pixels,
                lighting_limit_fraction: at(lit_pixels, lighting_gpix_s, 1e9, illum_ms),
                lighting_one_draw_fraction: at(lit_pixels, lighting_one_draw, 1e9, illum_ms),
                gbuffer_limit_fraction: at(gbuffer_triangles, gbuffer_tri_mtri_s, 1e6, gbuffer_ms),
                gbuffer_fill_fraction: at(s.width as u64 * s.height as u64, gbuffer_fill_gpix_s, 1e9, gbuffer_ms),
                cpu_cull_ms,
                cpu_record_ms,
                pairs_total,
                pairs_replanned,
                pairs_kept,
                kept_bytes,
                motion: cfg.motion,
            };
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
        lighting_gpix_s,
        gbuffer_tri_mtri_s,
        gbuffer_fill_gpix_s,
        lighting_shaded_gpix_s: passes.as_ref().map(|p| p.lighting_shaded_gpix_s),
        lighting_instance_ms: passes.as_ref().map(|p| p.lighting_instance_ms),
        lighting_sweep: passes.as_ref().map(|p| p.lighting_sweep.clone()).unwrap_or_default(),
        gbuffer_sweep: passes.map(|p| p.gbuffer_sweep).unwrap_or_default(),
    })
}

/// Each variant's error against the reference, for `r`'s scene as it stands.
fn variant_errors(r: &mut Renderer, name: &str, variants: &[Variant]) -> Result<Vec<umbrage_render::accuracy::Row>> {
    let mut errors = Vec::new();
    for v in variants {
        v.apply(r);
        errors.extend(evaluate(r, name, &[v.technique], 1)?);
    }
    Ok(errors)
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
