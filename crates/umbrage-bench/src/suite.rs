//! `umbrage bench --suite fill-vertex`: the limits, then every sweep point with every
//! technique ([`super::methods::all_techniques`]), the named scenes with their error against the
//! reference, the ablations; fractions, bounds and crossovers; JSON, CSV and plots.
//!
//! Each point: one renderer for the scene and size; per variant one *counting* frame
//! (`FrameSettings::counters`: exact rasterised fragments and pipeline statistics; not timed),
//! then a warm-up frame and `frames` timed frames round-robin over the variants (drift hits
//! every variant alike), medians of the GPU timestamps (`bench/runner.rs`).
//!
//! Then the model is fitted on every row (with what the rows identify of it), each row's bound
//! named and, where claimed, put to the test by its ablation ([`super::proof`]); crossovers
//! of bounds use the confirmed ones only.

pub use super::runner::{frames_within, MIN_FRAMES};

use super::limits::{self, Limits, LimitsConfig};
use super::methods::all_techniques;
use super::phases::{load_average, Clock};
use super::proof::{self, Origin};
use super::report::{RowLimits, SuiteReport, SuiteRow};
use super::runner::{scene_of, Point, Runner, Variant};
use super::sweeps::{self, PointScene, Scale, SweepPoint, ONE_FACTOR};
use super::toggles::{ablations, index_variants, no_depth_bounds, toggle_variants};
use std::collections::BTreeMap;
use std::ops::Range;
use std::path::PathBuf;
use umbrage::error::{Error, Result};
use umbrage::gpu::Context;
use umbrage::shadow::Method;
use umbrage_render::{Pcf, ShadowMap, Technique};

/// What to run (the CLI's `bench --suite` arguments).
#[derive(Clone, Debug)]
pub struct SuiteConfig {
    /// Points and frames ([`Scale::Quick`] for `--quick`).
    pub scale: Scale,
    /// Timed frames per variant (default: the scale's).
    pub frames: Option<usize>,
    /// Frames in flight of the renderers (the counting and timed frames run one at a time).
    pub frames_in_flight: usize,
    /// Output directory (bench.json, bench.csv, plots).
    pub out: PathBuf,
    /// Show a progress bar (it also hides itself when stderr is not a terminal).
    pub progress: bool,
}

/// Rows in measurement order, each segment either measured for its sweep or a sweep's copy
/// of an identical point measured before (relabelled with that sweep and x).
struct Segment {
    rows: Range<usize>,
    copy_as: Option<(&'static str, f64)>,
}

/// Runs the suite on `ctx` and writes its outputs into `cfg.out`.
pub fn run(ctx: Context, cfg: &SuiteConfig) -> Result<SuiteReport> {
    let mut clock = Clock::start();
    let load_average_start = load_average();
    let scale = cfg.scale;
    let frames = cfg.frames.unwrap_or_else(|| scale.frames()).max(1);
    let base = scale.base_size();
    let device = ctx.info.name.clone();
    let driver = format!("{} {}", ctx.info.driver, ctx.info.driver_info);
    let lscale = match scale {
        Scale::Full => 1.0,
        Scale::Quick => 0.5,
        Scale::Tiny => 0.02,
    };
    let limits: Limits = limits::measure(
        &ctx,
        &LimitsConfig { width: base.0, height: base.1, reps: if scale == Scale::Full { 5 } else { 3 }, scale: lscale },
    )?;
    clock.lap("limits", 0, 0);
    let row_limits = RowLimits {
        stencil_fill_gfrag_s: limits.stencil_fill_gfrag_s,
        small_tri_mtri_s: limits.small_tri_mtri_s,
        sliver_tri_mtri_s: limits.sliver_tri_mtri_s,
        draws_per_s: limits.draws_per_s,
        setup_tri_mtri_s: limits.setup_tri_mtri_s,
        clip_tri_mtri_s: limits.clip_tri_mtri_s,
        lighting_gpix_s: limits.lighting_gpix_s,
        gbuffer_tri_mtri_s: limits.gbuffer_tri_mtri_s,
    };
    // Multiview cube faces where the renderer trusts the device's multiview (gpu::quirks).
    let multiview = ctx.features.multiview && umbrage::gpu::quirks::multiview_defect(&ctx.info).is_none();
    let techniques = all_techniques(&scale.shadow_map_sizes(), ctx.features.ray_query, multiview, ctx.features.mesh_shader);
    let named_techniques = all_techniques(&scale.named_shadow_map_sizes(), ctx.features.ray_query, multiview, ctx.features.mesh_shader);
    let not_measured = not_measured(&ctx);
    let points = sweeps::points(scale);
    // The tiny suite (tests) leaves the 435k-triangle vertex scene out.
    let named: &[&str] = if scale == Scale::Tiny { &["bench/fill", "default"] } else { &["bench/fill", "bench/vertex"] };
    let ablation_scenes: &[&str] = if scale == Scale::Tiny { &["default"] } else { &["bench/fill", "bench/vertex", "default"] };
    let index_scene = if scale == Scale::Tiny { "default" } else { "bench/vertex" };
    let toggle_variants = toggle_variants(&ctx);
    let index_variants = index_variants();
    // The caps sweep compares the z-fail methods only (the paper's claim).
    let caps: Vec<Variant> = [Method::McGuire, Method::EverittKilgard, Method::ZFail, Method::Lengyel]
        .into_iter()
        .map(|m| Variant::of(Technique::Volumes(m)))
        .collect();
    let caps_points = points.iter().filter(|p| p.sweep == "caps").count();
    // The named scenes also read each shadow map with gathers (the same picture; the lookup's
    // cost side by side with the nine taps').
    let gathers: Vec<Variant> = scale
        .named_shadow_map_sizes()
        .into_iter()
        .map(|size| Variant::of(ShadowMap { size, pcf: Pcf::Gather, cube: Default::default() }))
        .collect();
    let units = (points.len() - caps_points) * techniques.len()
        + named.len() * (named_techniques.len() + gathers.len())
        + caps_points * caps.len()
        + (ablation_scenes.len() + 1) * toggle_variants.len()
        + index_variants.len();
    let bar = progress_bar(cfg.progress, units);
    let log = cfg.progress && bar.is_hidden();
    let mut run = Runner {
        ctx: Some(ctx),
        log,
        limits: row_limits,
        frames,
        frames_in_flight: cfg.frames_in_flight,
        bar,
        skipped: Vec::new(),
        start: std::time::Instant::now(),
        point_budget_s: if cfg.frames.is_some() { f64::INFINITY } else { scale.point_budget_s() },
    };
    let mut got = Collected::default();
    let all: Vec<Variant> = techniques.iter().map(|&t| Variant::of(t)).collect();
    let named_all: Vec<Variant> = named_techniques.iter().map(|&t| Variant::of(t)).chain(gathers.iter().cloned()).collect();
    // The named scenes, with their error (the Pareto chart).
    for &n in named {
        run.bar.set_message(format!("scenes {n}"));
        let scene = umbrage_scene::load(n)?;
        let measured = run.point(Point { sweep: "scenes", x: 0.0, name: n }, scene, base, &named_all, true)?;
        got.keep(measured, &PointScene::Named(n.into()), base);
    }
    clock.lap("scenes", named.len(), 0);
    measure_sweeps(&mut run, &mut clock, &mut got, &points, (&all, &caps))?;
    measure_ablations(&mut run, &mut got, base, (ablation_scenes, &toggle_variants), (index_scene, &index_variants))?;
    clock.lap("ablation", ablation_scenes.len() + 2, 0);
    let Collected { mut rows, origins, segments } = got;
    let model = super::model::fit(&mut rows, limit_costs(&limits));
    for r in &mut rows {
        sweeps::classify(r, row_limits);
    }
    clock.lap("model", 0, 0);
    // Every candidate bound put to the test, on the same device, before the context goes.
    let proof_frames = cfg.frames.map_or(scale.proof_frames(), |f| f.max(3));
    let bound_proofs = proof::prove(&mut run, &mut rows, &origins, &model, proof_frames)?;
    clock.lap("proofs", bound_proofs.points, 0);
    run.bar.finish_and_clear();
    let ctx = run.ctx.take().ok_or_else(|| Error::Internal("the bench lost its context".into()))?;
    ctx.check_validation()?;
    let rows = in_order(&rows, &segments);
    let crossovers = sweeps::crossovers(&rows);
    let mut ablations = ablations(&rows);
    if !ctx.features.depth_bounds {
        ablations.extend(ablation_scenes.iter().map(|n| no_depth_bounds(n)));
    }
    let mut report = SuiteReport {
        device,
        driver,
        suite: "fill-vertex".into(),
        quick: scale != Scale::Full,
        scale: format!("{scale:?}").to_lowercase(),
        seconds: 0.0,
        cpu_threads: std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1),
        limits,
        rows,
        model,
        crossovers,
        ablations,
        plots: Vec::new(),
        cpu_seconds: None,
        load_average: None,
        load_average_start,
        skipped: run.skipped,
        bound_proofs,
        phases: Vec::new(),
        techniques: techniques.iter().map(|&t| super::classic::technique_label(t)).collect(),
        named_techniques: named_techniques
            .iter()
            .chain(gathers.iter().map(|v| &v.technique))
            .map(|&t| super::classic::technique_label(t))
            .collect(),
        not_measured,
    };
    std::fs::create_dir_all(&cfg.out).map_err(|e| Error::io(cfg.out.display().to_string(), e))?;
    report.plots = super::plots::write_all(&report, &cfg.out)?;
    clock.lap("plots", 0, 0);
    report.phases = clock.phases.clone();
    report.seconds = clock.seconds();
    report.cpu_seconds = clock.cpu_seconds();
    report.load_average = load_average();
    report.write(&cfg.out)?;
    Ok(report)
}

/// The suite's progress bar over `units` variants measured (hidden without `progress`).
fn progress_bar(progress: bool, units: usize) -> indicatif::ProgressBar {
    if !progress {
        return indicatif::ProgressBar::hidden();
    }
    let b = indicatif::ProgressBar::new(units as u64);
    if let Ok(style) = indicatif::ProgressStyle::with_template("{elapsed_precise} [{bar:40}] {pos}/{len} {msg}") {
        b.set_style(style);
    }
    b
}

/// The rows measured so far, how each was measured (for its bound's proof), and the segments
/// that put them in order.
#[derive(Default)]
struct Collected {
    rows: Vec<SuiteRow>,
    origins: Vec<Origin>,
    segments: Vec<Segment>,
}

impl Collected {
    /// A point's rows, measured on `scene` at `size`.
    fn keep(&mut self, measured: Vec<(SuiteRow, Variant)>, scene: &PointScene, size: (u32, u32)) {
        let first = self.rows.len();
        for (row, variant) in measured {
            self.rows.push(row);
            self.origins.push(Origin { scene: scene.clone(), size, variant });
        }
        self.segments.push(Segment { rows: first..self.rows.len(), copy_as: None });
    }
}

/// Every technique's sweep points (`all`; the caps sweep's `caps`), measured once: a
/// one-factor point identical to one measured before (the same scene at the same size, every
/// technique) takes its rows.
fn measure_sweeps(
    run: &mut Runner,
    clock: &mut Clock,
    got: &mut Collected,
    points: &[SweepPoint],
    (all, caps): (&[Variant], &[Variant]),
) -> Result<()> {
    let mut measured_points: Vec<(PointScene, (u32, u32), Range<usize>)> = Vec::new();
    for p in points {
        let SweepPoint { sweep, x, scene: source, size } = p;
        let variants = if *sweep == "caps" { caps } else { all };
        let earlier = measured_points.iter().find(|(s, z, _)| s == source && z == size).map(|m| m.2.clone());
        match earlier.filter(|_| ONE_FACTOR.contains(sweep)) {
            Some(range) => {
                run.bar.inc(range.len() as u64);
                got.segments.push(Segment { rows: range, copy_as: Some((sweep, *x)) });
                clock.lap(sweep, 0, 1);
            }
            None => {
                let (scene, name) = scene_of(source)?;
                run.bar.set_message(format!("{sweep} {name} {}x{}", size.0, size.1));
                let first = got.rows.len();
                let measured = run.point(Point { sweep, x: *x, name: &name }, scene, *size, variants, false)?;
                got.keep(measured, source, *size);
                if variants == all {
                    measured_points.push((source.clone(), *size, first..got.rows.len()));
                }
                clock.lap(sweep, 1, 0);
            }
        }
    }
    Ok(())
}

/// Ablations: McGuire with each optimisation off on `scenes` and on lights with a range
/// (casters beyond some of them: what scissor and culling are for); index formats on
/// `index_scene`.
fn measure_ablations(
    run: &mut Runner,
    got: &mut Collected,
    base: (u32, u32),
    (scenes, toggle_variants): (&[&str], &[Variant]),
    (index_scene, index_variants): (&str, &[Variant]),
) -> Result<()> {
    for &n in scenes {
        run.bar.set_message(format!("ablation {n}"));
        let scene = umbrage_scene::load(n)?;
        let measured = run.point(Point { sweep: "ablation", x: 0.0, name: n }, scene, base, toggle_variants, false)?;
        got.keep(measured, &PointScene::Named(n.into()), base);
    }
    let ranged = super::scenes::SweepScene::ranged();
    let measured = run.point(Point { sweep: "ablation", x: 0.0, name: &ranged.name() }, ranged.build(), base, toggle_variants, false)?;
    got.keep(measured, &PointScene::Param(ranged), base);
    run.bar.set_message("ablation index formats");
    let measured =
        run.point(Point { sweep: "ablation", x: 0.0, name: index_scene }, umbrage_scene::load(index_scene)?, base, index_variants, false)?;
    got.keep(measured, &PointScene::Named(index_scene.into()), base);
    Ok(())
}

/// The rows in measurement order, the shared points' copies relabelled in their places.
fn in_order(rows: &[SuiteRow], segments: &[Segment]) -> Vec<SuiteRow> {
    segments
        .iter()
        .flat_map(|seg| {
            seg.rows.clone().map(|i| {
                let mut r = rows[i].clone();
                if let Some((sweep, x)) = seg.copy_as {
                    r.measured_in = std::mem::replace(&mut r.sweep, sweep.to_string());
                    r.x = x;
                }
                r
            })
        })
        .collect()
}

/// Each term's cost at the device's measured limit, ns per unit, where a limit measures it.
fn limit_costs(limits: &Limits) -> BTreeMap<String, f64> {
    [
        ("fragments", 1.0 / limits.stencil_fill_gfrag_s),
        ("setup_triangles", 1e3 / limits.setup_tri_mtri_s),
        ("clipped_triangles", 1e3 / limits.clip_tri_mtri_s),
        ("infinite_sides", 1e3 / limits.sliver_tri_mtri_s),
        ("draws", 1e9 / limits.draws_per_s),
    ]
    .iter()
    .filter(|(_, v)| v.is_finite())
    .map(|(k, v)| (k.to_string(), *v))
    .collect()
}

/// The techniques this device cannot run, and why (the report says they were not measured).
fn not_measured(ctx: &Context) -> BTreeMap<String, String> {
    let mut out = BTreeMap::new();
    let version = format!("{} {}", ctx.info.driver, ctx.info.driver_info);
    if !ctx.features.mesh_shader {
        out.insert(
            "mesh".to_string(),
            format!("{version} has no VK_EXT_mesh_shader (meshShader, Vulkan 1.2 or newer); Mesa lavapipe 25.0.7 has it (`scripts/drivers.sh install 25.0.7`)"),
        );
    }
    if !ctx.features.ray_query {
        out.insert(
            "rayquery".to_string(),
            format!("{version} has no VK_KHR_ray_query with acceleration structures; Mesa lavapipe 25.0.7 has them"),
        );
    }
    out
}
