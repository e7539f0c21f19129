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
use super::proof::{self, Origin};
use super::report::{Ablation, RowLimits, SuiteReport, SuiteRow};
use super::runner::{scene_of, Point, Runner, Variant};
use super::sweeps::{self, PointScene, Scale, SweepPoint};
use crate::error::{Error, Result};
use crate::gpu::Context;
use crate::render::{IndexFormat, PassToggles, Technique};
use crate::shadow::Method;
use std::collections::BTreeMap;
use std::path::PathBuf;
use std::time::Instant;

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

/// Runs the suite on `ctx` and writes its outputs into `cfg.out`.
pub fn run(ctx: Context, cfg: &SuiteConfig) -> Result<SuiteReport> {
    let start = Instant::now();
    let cpu0 = process_cpu_seconds();
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
    let row_limits = RowLimits {
        stencil_fill_gfrag_s: limits.stencil_fill_gfrag_s,
        small_tri_mtri_s: limits.small_tri_mtri_s,
        sliver_tri_mtri_s: limits.sliver_tri_mtri_s,
        draws_per_s: limits.draws_per_s,
        setup_tri_mtri_s: limits.setup_tri_mtri_s,
        clip_tri_mtri_s: limits.clip_tri_mtri_s,
    };
    // Multiview cube faces where the renderer trusts the device's multiview (gpu::quirks).
    let multiview = ctx.features.multiview && crate::gpu::quirks::multiview_defect(&ctx.info).is_none();
    let techniques = all_techniques(&scale.shadow_map_sizes(), ctx.features.ray_query, multiview, ctx.features.mesh_shader);
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
        .shadow_map_sizes()
        .into_iter()
        .map(|size| Variant::of(Technique::ShadowMap { size, pcf: crate::render::Pcf::Gather, cube: Default::default() }))
        .collect();
    let units = (named.len() + points.len() - caps_points) * techniques.len()
        + named.len() * gathers.len()
        + caps_points * caps.len()
        + (ablation_scenes.len() + 1) * toggle_variants.len()
        + index_variants.len();
    let bar = if cfg.progress {
        let b = indicatif::ProgressBar::new(units as u64);
        if let Ok(style) = indicatif::ProgressStyle::with_template("{elapsed_precise} [{bar:40}] {pos}/{len} {msg}") {
            b.set_style(style);
        }
        b
    } else {
        indicatif::ProgressBar::hidden()
    };
    let log = cfg.progress && bar.is_hidden();
    let mut run = Runner {
        ctx: Some(ctx),
        log,
        limits: row_limits,
        frames,
        frames_in_flight: cfg.frames_in_flight,
        bar,
        skipped: Vec::new(),
        start,
        point_budget_s: if cfg.frames.is_some() { f64::INFINITY } else { scale.point_budget_s() },
    };
    let mut rows: Vec<SuiteRow> = Vec::new();
    let mut origins: Vec<Origin> = Vec::new();
    // Each point's rows, and how each was measured (for its bound's proof).
    let mut keep = |measured: Vec<(SuiteRow, Variant)>, scene: &PointScene, size: (u32, u32)| {
        for (row, variant) in measured {
            rows.push(row);
            origins.push(Origin { scene: scene.clone(), size, variant });
        }
    };
    let all: Vec<Variant> = techniques.iter().map(|&t| Variant::of(t)).collect();
    let named_all: Vec<Variant> = all.iter().chain(&gathers).cloned().collect();
    // The named scenes, with their error (the Pareto chart).
    for &n in named {
        run.bar.set_message(format!("scenes {n}"));
        let scene = crate::scene::load(n)?;
        keep(run.point(Point { sweep: "scenes", x: 0.0, name: n }, scene, base, &named_all, true)?, &PointScene::Named(n.into()), base);
    }
    for p in &points {
        let SweepPoint { sweep, x, scene: source, size } = p;
        let (scene, name) = scene_of(source)?;
        run.bar.set_message(format!("{sweep} {name} {}x{}", size.0, size.1));
        let variants = if *sweep == "caps" { &caps } else { &all };
        keep(run.point(Point { sweep, x: *x, name: &name }, scene, *size, variants, false)?, source, *size);
    }
    // Ablations: McGuire with each optimisation off; index formats on the vertex scene.
    for &n in ablation_scenes {
        run.bar.set_message(format!("ablation {n}"));
        let scene = crate::scene::load(n)?;
        keep(
            run.point(Point { sweep: "ablation", x: 0.0, name: n }, scene, base, &toggle_variants, false)?,
            &PointScene::Named(n.into()),
            base,
        );
    }
    // Lights with a range, casters beyond some of them: what scissor and culling are for.
    let ranged = super::scenes::SweepScene::ranged();
    keep(
        run.point(Point { sweep: "ablation", x: 0.0, name: &ranged.name() }, ranged.build(), base, &toggle_variants, false)?,
        &PointScene::Param(ranged),
        base,
    );
    run.bar.set_message("ablation index formats");
    keep(
        run.point(Point { sweep: "ablation", x: 0.0, name: index_scene }, crate::scene::load(index_scene)?, base, &index_variants, false)?,
        &PointScene::Named(index_scene.into()),
        base,
    );
    let model = super::model::fit(&mut rows, limit_costs(&limits));
    for r in &mut rows {
        sweeps::classify(r, row_limits);
    }
    // Every claimed bound put to the test, on the same device, before the context goes.
    let proof_frames = cfg.frames.map_or(scale.proof_frames(), |f| f.max(3));
    let bound_proofs = proof::prove(&mut run, &mut rows, &origins, &model, proof_frames)?;
    run.bar.finish_and_clear();
    let ctx = run.ctx.take().ok_or_else(|| Error::Other("context lost".into()))?;
    ctx.check_validation()?;
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
        load_average: load_average(),
        skipped: run.skipped,
        bound_proofs,
    };
    std::fs::create_dir_all(&cfg.out).map_err(|e| Error::io(cfg.out.display().to_string(), e))?;
    report.plots = super::plots::write_all(&report, &cfg.out)?;
    report.seconds = start.elapsed().as_secs_f64();
    report.cpu_seconds = process_cpu_seconds().map(|c| c - cpu0.unwrap_or(0.0));
    report.write(&cfg.out)?;
    Ok(report)
}

/// Each term's cost at the device's measured limit, ns per unit, where a limit measures it.
fn limit_costs(limits: &Limits) -> BTreeMap<String, f64> {
    [
        ("fragments", 1.0 / limits.stencil_fill_gfrag_s),
        ("setup_triangles", 1e3 / limits.setup_tri_mtri_s),
        ("clipped_triangles", 1e3 / limits.clip_tri_mtri_s),
        ("draws", 1e9 / limits.draws_per_s),
    ]
    .iter()
    .filter(|(_, v)| v.is_finite())
    .map(|(k, v)| (k.to_string(), *v))
    .collect()
}

/// The depth-bounds ablation of `scene`, skipped: the device has no `depthBounds`.
fn no_depth_bounds(scene: &str) -> Ablation {
    Ablation {
        what: "depth-bounds".into(),
        scene: scene.into(),
        variant: "depth-bounds-off".into(),
        baseline: "all-on".into(),
        time_ratio: None,
        fragment_ratio: None,
        triangle_ratio: None,
        byte_ratio: None,
        skipped: "the device has no depthBounds feature (the pass never uses it here)".into(),
    }
}

fn toggle_variants(ctx: &Context) -> Vec<Variant> {
    let m = Technique::Volumes(Method::McGuire);
    let on = PassToggles::default();
    let mut v = vec![
        Variant { label: "all-on".into(), ..Variant::of(m) },
        Variant { label: "scissor-off".into(), toggles: PassToggles { scissor: false, ..on }, ..Variant::of(m) },
        Variant { label: "culling-off".into(), toggles: PassToggles { culling: false, ..on }, ..Variant::of(m) },
    ];
    if ctx.features.depth_bounds {
        v.push(Variant { label: "depth-bounds-off".into(), toggles: PassToggles { depth_bounds: false, ..on }, ..Variant::of(m) });
    }
    v
}

fn index_variants() -> Vec<Variant> {
    let m = Technique::Volumes(Method::McGuire);
    [IndexFormat::U8, IndexFormat::U16, IndexFormat::U32, IndexFormat::Naive]
        .into_iter()
        .map(|f| Variant { label: format!("index-{}", f.name()), index_format: f, ..Variant::of(m) })
        .collect()
}

/// The constant factors as ratios: toggles against `all-on`, the other methods' triangles and
/// time against McGuire's on the named scenes, index formats against u16.
fn ablations(rows: &[SuiteRow]) -> Vec<Ablation> {
    let ratio = |a: Option<f64>, b: Option<f64>| match (a, b) {
        (Some(a), Some(b)) if b > 0.0 => Some(a / b),
        _ => None,
    };
    let make = |what: &str, v: &SuiteRow, b: &SuiteRow, vl: &str, bl: &str| Ablation {
        what: what.into(),
        scene: v.scene.clone(),
        variant: vl.into(),
        baseline: bl.into(),
        time_ratio: ratio(v.gpu_shadow_ms, b.gpu_shadow_ms),
        fragment_ratio: ratio(v.stencil_fragments.map(|x| x as f64), b.stencil_fragments.map(|x| x as f64)),
        triangle_ratio: ratio(Some(v.shadow_triangles as f64), Some(b.shadow_triangles as f64)),
        byte_ratio: ratio(Some(v.bytes as f64), Some(b.bytes as f64)),
        skipped: String::new(),
    };
    let mut out = Vec::new();
    let abl: Vec<&SuiteRow> = rows.iter().filter(|r| r.sweep == "ablation").collect();
    for b in abl.iter().filter(|r| r.variant == "all-on") {
        for v in abl.iter().filter(|r| r.scene == b.scene && r.variant.ends_with("-off")) {
            out.push(make(v.variant.trim_end_matches("-off"), v, b, &v.variant, "all-on"));
        }
    }
    for b in abl.iter().filter(|r| r.variant == "index-u16") {
        for v in abl.iter().filter(|r| r.scene == b.scene && r.variant.starts_with("index-") && r.variant != "index-u16") {
            out.push(make("index-format", v, b, &v.variant, "index-u16"));
        }
    }
    let scenes: Vec<&SuiteRow> = rows.iter().filter(|r| r.sweep == "scenes").collect();
    for b in scenes.iter().filter(|r| r.method == "mcguire") {
        for v in scenes.iter().filter(|r| r.scene == b.scene && matches!(r.method.as_str(), "lengyel" | "everitt-kilgard" | "zfail")) {
            out.push(make("method", v, b, &v.method, "mcguire"));
        }
    }
    out
}

/// This process's CPU time (user + system, all threads: lavapipe's rasteriser threads too),
/// seconds; Linux only (`/proc/self/stat`, 100 ticks a second).
fn process_cpu_seconds() -> Option<f64> {
    let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
    // Fields after the command name (which may hold spaces) in parentheses.
    let rest = &stat[stat.rfind(')')? + 2..];
    let f: Vec<&str> = rest.split_whitespace().collect();
    let (utime, stime): (f64, f64) = (f.get(11)?.parse().ok()?, f.get(12)?.parse().ok()?);
    Some((utime + stime) / 100.0)
}

/// The machine's 1-minute load average at the end of the run (other work competing for the
/// CPU slows lavapipe); Linux only.
fn load_average() -> Option<f64> {
    std::fs::read_to_string("/proc/loadavg").ok()?.split_whitespace().next()?.parse().ok()
}
