//! `umbrage bench --suite fill-vertex`: the limits, then every sweep point with every
//! technique ([`super::methods::all_techniques`]), the named scenes with their error against the
//! reference, the ablations; fractions, bounds and crossovers; JSON, CSV and plots.
//!
//! Each point: one renderer for the scene and size; per variant one *counting* frame
//! (`FrameSettings::counters`: exact rasterised fragments and pipeline statistics; not timed),
//! then a warm-up frame and `frames` timed frames round-robin over the variants (drift hits
//! every variant alike), medians of the GPU timestamps.

use super::classic::{median, technique_label};
use super::limits::{self, Limits, LimitsConfig};
use super::methods::all_techniques;
use super::report::{Ablation, RowLimits, SuiteReport, SuiteRow};
use super::sweeps::{self, PointScene, Scale, SweepPoint};
use crate::accuracy::evaluate;
use crate::error::{Error, Result};
use crate::gpu::Context;
use crate::render::{IndexFormat, PassToggles, RenderOptions, Renderer, Technique};
use crate::scene::Scene;
use crate::shadow::Method;
use std::collections::{BTreeMap, HashMap};
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

/// One way to render a point: the technique plus the pass settings an ablation changes.
#[derive(Clone, Debug)]
struct Variant {
    technique: Technique,
    toggles: PassToggles,
    index_format: IndexFormat,
    label: String,
}

impl Variant {
    fn of(t: Technique) -> Variant {
        Variant { technique: t, toggles: PassToggles::default(), index_format: IndexFormat::Auto, label: String::new() }
    }
}

/// What a point's scene holds, for its rows.
struct PointShape<'a> {
    casters: u64,
    triangles: u64,
    nlights: usize,
    /// Shadow-map faces a frame (6 per point light, 1 per other light).
    map_faces: u64,
    /// Each shadow-casting mesh's triangles, by name.
    mesh_triangles: &'a HashMap<String, u64>,
}

struct Runner {
    ctx: Option<Context>,
    /// Print a line per point (progress requested but stderr is not a terminal).
    log: bool,
    limits: RowLimits,
    frames: usize,
    frames_in_flight: usize,
    bar: indicatif::ProgressBar,
    skipped: Vec<String>,
    start: Instant,
    /// Wall seconds a point's timed rounds may take: past it, fewer frames (at least
    /// [`MIN_FRAMES`]).
    point_budget_s: f64,
}

/// Fewest timed frames a point is cut to by its budget.
pub const MIN_FRAMES: usize = 5;

/// Timed rounds for a point whose warm-up round took `round_s` wall seconds: `frames`, or
/// as many as fit `budget_s` where fewer do, never below [`MIN_FRAMES`] (nor above `frames`).
pub fn frames_within(frames: usize, round_s: f64, budget_s: f64) -> usize {
    let fit = budget_s / round_s.max(1e-6);
    let fit = if fit.is_finite() && fit < frames as f64 { fit as usize } else { frames };
    fit.max(MIN_FRAMES).min(frames)
}

fn scene_of(p: &PointScene) -> Result<(Scene, String)> {
    match p {
        PointScene::Named(n) => Ok((crate::scene::load(n)?, n.clone())),
        PointScene::Param(s) => Ok((s.build(), s.name())),
    }
}

/// Where a suite point sits: its sweep, its x on that sweep and its scene's name.
#[derive(Clone, Copy)]
struct Point<'a> {
    sweep: &'a str,
    x: f64,
    name: &'a str,
}

impl Runner {
    /// Measures every variant on one scene and size. `errors`: render the reference too and
    /// fill in each technique's error.
    fn point(&mut self, at: Point, scene: Scene, size: (u32, u32), variants: &[Variant], errors: bool) -> Result<Vec<SuiteRow>> {
        let Point { sweep, name, .. } = at;
        let ctx = self.ctx.take().ok_or_else(|| Error::Other("context lost".into()))?;
        if self.log {
            eprintln!("[{:>6.1} s] {sweep} {name} {}x{} ({} variants)", self.start.elapsed().as_secs_f64(), size.0, size.1, variants.len());
        }
        let opts = RenderOptions { width: size.0, height: size.1, frames_in_flight: self.frames_in_flight, ..Default::default() };
        let casters = scene.meshes.iter().filter(|m| m.casts_shadow).count() as u64;
        let triangles: u64 = scene.meshes.iter().filter(|m| m.casts_shadow).map(|m| m.mesh.triangles.len() as u64).sum();
        let nlights = scene.lights.len();
        // Shadow-map faces a frame: six per point light, one per spot or directional light.
        let map_faces: u64 = scene.lights.iter().map(|l| if l.kind == crate::scene::LightKind::Point { 6 } else { 1 }).sum();
        let mesh_triangles: HashMap<String, u64> =
            scene.meshes.iter().filter(|m| m.casts_shadow).map(|m| (m.name.clone(), m.mesh.triangles.len() as u64)).collect();
        let mut r = Renderer::new(ctx, scene, opts)?;
        let shape = PointShape { casters, triangles, nlights, map_faces, mesh_triangles: &mesh_triangles };
        let result = self.measure(&mut r, at, variants, errors, shape);
        self.ctx = Some(r.into_context());
        result
    }

    fn measure(&mut self, r: &mut Renderer, at: Point, variants: &[Variant], errors: bool, shape: PointShape) -> Result<Vec<SuiteRow>> {
        let Point { sweep, x, name } = at;
        let PointShape { casters, triangles, nlights, map_faces, mesh_triangles } = shape;
        let mut kept: Vec<&Variant> = Vec::with_capacity(variants.len());
        for v in variants {
            match v.technique {
                Technique::ShadowMap { size, .. } if !sweeps::shadow_map_fits(size, nlights) => {
                    self.skipped.push(format!("{sweep} {name}: shadowmap-{size} with {nlights} lights (over 2^26 map texels a frame)"));
                    self.bar.inc(1);
                }
                _ if v.index_format == IndexFormat::U8 && !r.context().features.index_type_uint8 => {
                    self.skipped.push(format!("{sweep} {name}: index-u8 (VK_EXT_index_type_uint8 missing)"));
                    self.bar.inc(1);
                }
                _ => kept.push(v),
            }
        }
        let variants = kept;
        let mut error: HashMap<Technique, f64> = HashMap::new();
        if errors {
            let techniques: Vec<Technique> = variants.iter().map(|v| v.technique).collect();
            let rows = evaluate_fractions(r, name, &techniques)?;
            for (t, f) in techniques.iter().zip(rows) {
                error.insert(*t, f);
            }
        }
        // One frame first: the casters' uploads land in it, not in a variant's counts.
        r.render()?;
        let base = r.settings;
        let apply = |r: &mut Renderer, v: &Variant| {
            r.settings = base;
            r.settings.technique = v.technique;
            r.settings.toggles = v.toggles;
            r.settings.index_format = v.index_format;
        };
        // Counting frames (not timed).
        let mut counted = Vec::with_capacity(variants.len());
        for v in &variants {
            apply(r, v);
            r.settings.counters = true;
            counted.push(r.render()?.stats);
            r.settings.counters = false;
        }
        // Timed frames, round-robin.
        #[derive(Default)]
        struct Acc {
            shadow: Vec<f64>,
            map: Vec<f64>,
            frame: Vec<f64>,
            depth: Vec<f64>,
            illum: Vec<f64>,
            accel: Vec<f64>,
            plan: Vec<f64>,
        }
        let mut acc: Vec<Acc> = variants.iter().map(|_| Acc::default()).collect();
        let mut frames = self.frames;
        let mut frame = 0;
        while frame <= frames {
            let round = Instant::now();
            for (k, v) in variants.iter().enumerate() {
                apply(r, v);
                let f = r.render()?;
                if frame == 0 {
                    continue;
                }
                let a = &mut acc[k];
                if let Some(g) = &f.stats.gpu_ms {
                    a.shadow.push(g.shadow);
                    a.map.push(g.shadow_map);
                    a.frame.push(g.frame);
                    a.depth.push(g.depth);
                    a.illum.push(g.illuminate);
                    a.accel.push(g.accel);
                }
                a.plan.push(f.stats.cpu_ms.plan + f.stats.cpu_ms.silhouettes);
            }
            if frame == 0 {
                // The warm-up round's wall time sets how many timed rounds fit the budget.
                frames = frames_within(frames, round.elapsed().as_secs_f64(), self.point_budget_s);
            }
            frame += 1;
        }
        r.settings = base;
        let (w, h) = (r.config().width, r.config().height);
        let mut rows = Vec::new();
        for ((v, s), a) in variants.iter().zip(counted).zip(acc) {
            let c = s.counters.clone().unwrap_or_default();
            let map_size = match v.technique {
                Technique::ShadowMap { size, .. } => Some(size as u64),
                _ => None,
            };
            let shadow_map = map_size.is_some();
            let med = |x: Vec<f64>| (!x.is_empty()).then(|| median(x));
            let q = |x: &[f64], p: f64| (!x.is_empty()).then(|| super::model::quantile(x, p));
            let (p10, p90) = (q(&a.shadow, 0.1), q(&a.shadow, 0.9));
            // Per light, the casters it did not cull, and their meshes' triangles.
            let drawn = s.lights.iter().flat_map(|l| l.casters.iter()).filter(|c| c.case != crate::shadow::Case::Culled);
            let (caster_passes, bound_triangles) =
                drawn.fold((0u64, 0u64), |(n, t), c| (n + 1, t + mesh_triangles.get(&c.name).copied().unwrap_or(0)));
            let lookup: Vec<f64> = a.shadow.iter().zip(&a.map).map(|(s, m)| s - m).collect();
            let (map_ms, lookup_ms) = match shadow_map {
                true => (med(a.map.clone()), med(lookup)),
                false => (None, None),
            };
            let mut row = SuiteRow {
                suite: "fill-vertex".into(),
                sweep: sweep.into(),
                x,
                variant: v.label.clone(),
                scene: name.into(),
                method: technique_label(v.technique),
                counter: if shadow_map { "float".into() } else { s.counter.name().to_string() },
                index_format: v.index_format.name().into(),
                width: w,
                height: h,
                triangles,
                casters,
                lights: nlights as u64,
                frames,
                gpu_shadow_ms: med(a.shadow),
                gpu_shadow_ms_p10: p10,
                gpu_shadow_ms_p90: p90,
                gpu_map_ms: map_ms,
                gpu_lookup_ms: lookup_ms,
                gpu_tlas_ms: if v.technique == Technique::RayQuery { med(a.accel) } else { None },
                blas_build_ms: s.ray_query.as_ref().filter(|_| v.technique == Technique::RayQuery).map(|q| q.bottom_level_build_ms),
                gpu_frame_ms: med(a.frame),
                gpu_depth_ms: med(a.depth),
                gpu_illuminate_ms: med(a.illum),
                stencil_fragments: c.stencil_fragments,
                shadow_triangles: s.totals.triangles.total(),
                shadow_sides: s.totals.triangles.sides,
                primitives: c.primitives,
                clipped_primitives: c.clipped_primitives,
                vertex_invocations: c.vertex_invocations,
                clipped_triangles: s.totals.triangles.sides + s.totals.triangles.dark_cap,
                map_texels: map_size.map_or(0, |n| n * n * map_faces),
                caster_passes,
                bound_triangles,
                draws: s.totals.draws,
                cpu_plan_ms: median(a.plan),
                bytes: s.totals.bytes_sent,
                error_fraction: error.get(&v.technique).copied(),
                ..Default::default()
            };
            row.limits = self.limits;
            self.bar.inc(1);
            rows.push(row);
        }
        Ok(rows)
    }
}

/// Each technique's worst-light error fraction, in the order given.
fn evaluate_fractions(r: &mut Renderer, name: &str, techniques: &[Technique]) -> Result<Vec<f64>> {
    let rows = evaluate(r, name, techniques, 1)?;
    if rows.len() != techniques.len() {
        return Err(Error::Other(format!("accuracy rows: {} for {} techniques", rows.len(), techniques.len())));
    }
    Ok(rows.iter().map(|row| row.fraction).collect())
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
    let mut rows = Vec::new();
    let all: Vec<Variant> = techniques.iter().map(|&t| Variant::of(t)).collect();
    let named_all: Vec<Variant> = all.iter().chain(&gathers).cloned().collect();
    // The named scenes, with their error (the Pareto chart).
    for &n in named {
        run.bar.set_message(format!("scenes {n}"));
        let scene = crate::scene::load(n)?;
        rows.extend(run.point(Point { sweep: "scenes", x: 0.0, name: n }, scene, base, &named_all, true)?);
    }
    for p in &points {
        let SweepPoint { sweep, x, scene, size } = p;
        let (scene, name) = scene_of(scene)?;
        run.bar.set_message(format!("{sweep} {name} {}x{}", size.0, size.1));
        let variants = if *sweep == "caps" { &caps } else { &all };
        rows.extend(run.point(Point { sweep, x: *x, name: &name }, scene, *size, variants, false)?);
    }
    // Ablations: McGuire with each optimisation off; index formats on the vertex scene.
    for &n in ablation_scenes {
        run.bar.set_message(format!("ablation {n}"));
        let scene = crate::scene::load(n)?;
        rows.extend(run.point(Point { sweep: "ablation", x: 0.0, name: n }, scene, base, &toggle_variants, false)?);
    }
    // Lights with a range, casters beyond some of them: what scissor and culling are for.
    let ranged = super::scenes::SweepScene::ranged();
    rows.extend(run.point(Point { sweep: "ablation", x: 0.0, name: &ranged.name() }, ranged.build(), base, &toggle_variants, false)?);
    run.bar.set_message("ablation index formats");
    rows.extend(run.point(
        Point { sweep: "ablation", x: 0.0, name: index_scene },
        crate::scene::load(index_scene)?,
        base,
        &index_variants,
        false,
    )?);
    run.bar.finish_and_clear();
    let ctx = run.ctx.take().ok_or_else(|| Error::Other("context lost".into()))?;
    ctx.check_validation()?;
    let model = super::model::fit(&mut rows, limit_costs(&limits));
    for r in &mut rows {
        sweeps::classify(r, row_limits);
    }
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

#[cfg(test)]
mod tests {
    use super::{frames_within, MIN_FRAMES};

    #[test]
    fn the_point_budget_cuts_only_heavy_points_and_never_below_the_floor() {
        // A light point keeps every frame.
        assert_eq!(frames_within(9, 0.5, 30.0), 9);
        // A heavy one is cut to what fits the budget...
        assert_eq!(frames_within(9, 4.0, 30.0), 7);
        // ...but keeps at least MIN_FRAMES, whatever a round takes.
        assert_eq!(frames_within(9, 20.0, 30.0), MIN_FRAMES);
        assert_eq!(frames_within(9, f64::INFINITY, 30.0), MIN_FRAMES);
        // No budget (tiny suites, explicit --frames): every frame; fewer asked than the floor: those.
        assert_eq!(frames_within(9, 100.0, f64::INFINITY), 9);
        assert_eq!(frames_within(1, 100.0, 30.0), 1);
        assert_eq!(frames_within(9, 0.0, 30.0), 9);
    }
}
