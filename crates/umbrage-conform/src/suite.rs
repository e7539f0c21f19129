//! Runs the parametrised suite: selects the cases (filter, device support), batches each
//! configuration into one submission, compares every tile with the CPU model, and adds the
//! single-configuration end-to-end checks (`legacy.*`, `pipeline.hard_cases.*`).

use super::batch::{self, TileResult};
use super::cases::{self, Case, Config, RenderModel, Req, StateModel, FORMATS};
use super::model::{self, DepthExp, Expected};
use super::{images, CheckResult, Status};
use ash::vk;
use std::time::Instant;
use umbrage::error::Result;
use umbrage::gpu::{Context, DeviceInfo, Features};

pub(crate) use super::outcome::selected;
pub use super::outcome::{matches, CaseOutcome, QueryOutcome, SuiteOptions};
use super::units::{pipeline_shard_names, Unit, COMMANDS, LEGACY, MESH};
pub use super::units::{run_legacy, run_mesh, run_pipeline};

/// Whether a depth-stencil format was usable.
#[derive(Clone, Debug, serde::Serialize)]
pub struct FormatSupport {
    /// Short name (`d24s8`).
    pub name: String,
    /// Vulkan name.
    pub format: String,
    /// Depth-stencil attachment, transfer source and destination with optimal tiling.
    pub usable: bool,
}

/// One configuration's submission.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct ConfigRun {
    /// `d24s8.dynamic_rendering.static_state`.
    pub name: String,
    /// Cases drawn in the submission.
    pub cases: usize,
    /// Wall time: pipelines, recording, submission, read-back and comparison.
    pub seconds: f64,
    /// Validation errors reported during it (each fails every case of the configuration).
    pub validation_errors: usize,
}

/// The whole run on one device (`conform.json`).
#[derive(Clone, Debug, serde::Serialize)]
pub struct Report {
    /// The physical device and driver.
    pub device: DeviceInfo,
    /// The optional features found.
    pub features: Features,
    /// Whether the validation layers were on.
    pub validation: bool,
    /// `subPixelPrecisionBits`, the grid the CPU model snaps vertices to.
    pub subpixel_bits: u32,
    /// The filter patterns (empty: all).
    pub filter: Vec<String>,
    /// The formats tried.
    pub formats: Vec<FormatSupport>,
    /// The configurations run.
    pub configs: Vec<ConfigRun>,
    /// Every selected case, in name order of generation.
    pub cases: Vec<CaseOutcome>,
    /// The single-configuration checks' full results (numbers: `legacy.*`, `commands.*`,
    /// `mesh.*`, the pipeline check), when selected.
    pub legacy: Vec<CheckResult>,
    /// Wall time of the whole run.
    pub seconds: f64,
    /// The child processes the run started (0: everything ran in this process): one a unit,
    /// plus those that re-ran the cases of a child that crashed or hung.
    pub children: usize,
}

impl Report {
    /// (passed, failed, skipped).
    pub fn counts(&self) -> (usize, usize, usize) {
        let n = |s: Status| self.cases.iter().filter(|c| c.status == s).count();
        (n(Status::Pass), n(Status::Fail), n(Status::Skipped))
    }
    /// The failed cases.
    pub fn failed(&self) -> Vec<&CaseOutcome> {
        self.cases.iter().filter(|c| c.status == Status::Fail).collect()
    }
    /// The cases whose driver crashed or hung (isolated runs only): [`Status::Crash`] and
    /// [`Status::Timeout`].
    pub fn crashed(&self) -> Vec<&CaseOutcome> {
        self.cases.iter().filter(|c| matches!(c.status, Status::Crash | Status::Timeout)).collect()
    }
}

/// The selected case names of the legacy or pipeline unit (empty for a configuration unit).
pub fn unit_case_names(unit: Unit, filter: &[String]) -> Vec<String> {
    let all = match unit {
        Unit::Legacy => super::units::legacy_unit().into_iter().map(super::units::full_name).collect(),
        Unit::Multiview => super::units::MULTIVIEW.iter().map(|n| format!("legacy.{n}")).collect(),
        Unit::Mesh => MESH.iter().map(|n| format!("mesh.{n}")).collect(),
        Unit::Pipeline { shard, shards } => pipeline_shard_names((shard, shards)),
        Unit::Config(_) => Vec::new(),
    };
    all.into_iter().filter(|n| selected(filter, n)).collect()
}

/// Every case name, with or without a device (`--list`), in run order.
pub fn all_names() -> Vec<String> {
    let mut v: Vec<String> = cases::all(&Config::all(&FORMATS)).into_iter().map(|c| c.name).collect();
    v.extend(LEGACY.iter().map(|n| format!("legacy.{n}")));
    v.extend(COMMANDS.iter().map(|n| format!("commands.{n}")));
    v.extend(MESH.iter().map(|n| format!("mesh.{n}")));
    v.extend(pipeline_shard_names((0, 1)));
    v
}

/// Whether `ctx` has what `r` names, for `format`.
fn have(ctx: &Context, r: Req, format: vk::Format) -> bool {
    let f = &ctx.features;
    match r {
        Req::DepthAspect => cases::depth_kind(format) != cases::DepthKind::None,
        Req::DepthClamp => f.depth_clamp,
        Req::DepthBounds => f.depth_bounds,
        Req::DepthRangeUnrestricted => f.depth_range_unrestricted,
        Req::FloatDepth => cases::depth_kind(format) == cases::DepthKind::Float32,
        Req::OcclusionQueryPrecise => f.occlusion_query_precise,
    }
}

/// Why `ctx` cannot run configuration `cfg` at all (its render or state model needs a newer
/// Vulkan than the device has), or `None`.
pub fn config_unsupported(ctx: &Context, cfg: Config) -> Option<String> {
    let f = &ctx.features;
    let v = &ctx.info.api_version;
    if cfg.render == RenderModel::DynamicRendering && !f.dynamic_rendering {
        return Some(format!("dynamic rendering needs Vulkan 1.3 (dynamicRendering); the device has Vulkan {v}"));
    }
    if cfg.state == StateModel::Dynamic && !f.extended_dynamic_state {
        return Some(format!(
            "dynamic depth/stencil state (vkCmdSetStencilOp, vkCmdSetDepthCompareOp, ...) needs Vulkan 1.3; the device has Vulkan {v}"
        ));
    }
    None
}

/// Compares one tile with its expectation: (stencil mismatches, depth mismatches, judged, query outcomes, message).
fn compare(case: &Case, exp: &Expected, got: &TileResult) -> (u64, u64, u64, Vec<QueryOutcome>, Vec<String>) {
    let kind = case.config.depth_kind();
    let (mut sm, mut dm, mut judged) = (0u64, 0u64, 0u64);
    let mut first = Vec::new();
    let w = case.size.0 as usize;
    let mut either = vec![None; exp.stencil.len()];
    for &(i, allowed, _) in &case.either {
        either[i] = Some(allowed);
    }
    for (i, e) in exp.stencil.iter().enumerate() {
        if let Some(allowed) = either[i] {
            judged += 1;
            if !allowed.contains(&got.stencil[i]) {
                sm += 1;
                if first.len() < 3 {
                    first.push(format!(
                        "stencil at ({}, {}) on the shared edge: expected 0x{:02x} or 0x{:02x} (exactly one triangle), got 0x{:02x}",
                        i % w,
                        i / w,
                        allowed[0],
                        allowed[1],
                        got.stencil[i]
                    ));
                }
            }
        } else if let Some(e) = e {
            judged += 1;
            if got.stencil[i] != *e {
                sm += 1;
                if first.len() < 3 {
                    first.push(format!(
                        "stencil at ({}, {}): expected {e} (0x{e:02x}), got {} (0x{:02x})",
                        i % w,
                        i / w,
                        got.stencil[i],
                        got.stencil[i]
                    ));
                }
            }
        }
    }
    for (i, e) in exp.depth.iter().enumerate() {
        if *e == DepthExp::Any || got.depth.is_empty() {
            continue;
        }
        let v = model::from_raw(kind, got.depth[i]);
        if !e.accepts(v) {
            dm += 1;
            if first.len() < 6 {
                first.push(format!("depth at ({}, {}): expected {e:?}, got {v}", i % w, i / w));
            }
        }
    }
    let mut q = Vec::new();
    for (k, &(lo, hi)) in exp.queries.iter().enumerate() {
        let actual = got.queries.get(k).copied().unwrap_or(u64::MAX);
        if actual < lo || actual > hi {
            first.push(format!("occlusion query {k}: expected {lo}..={hi} samples, got {actual}"));
        }
        q.push(QueryOutcome { expected_min: lo, expected_max: hi, actual });
    }
    (sm, dm, judged, q, first)
}

/// The formats tried and whether each is usable on `ctx`.
pub fn format_support(ctx: &Context) -> Vec<(vk::Format, FormatSupport)> {
    FORMATS
        .iter()
        .map(|&f| {
            let usable = batch::format_usable(ctx, f);
            (f, FormatSupport { name: cases::format_name(f).into(), format: format!("{f:?}"), usable })
        })
        .collect()
}

/// One configuration's selected cases: every outcome (skipped ones decided, the others
/// pending as passes) and the cases to draw.
pub fn plan_config(ctx: &Context, cfg: Config, format_ok: bool, opts: &SuiteOptions) -> (Vec<CaseOutcome>, Vec<Case>) {
    let mut outcomes = Vec::new();
    let mut run = Vec::new();
    for c in cases::all(&[cfg]).into_iter().filter(|c| selected(&opts.filter, &c.name)) {
        let mut o = CaseOutcome::new(c.name.clone(), c.group, Some(cfg.name()), c.what.clone());
        o.bug = c.bug.clone();
        if let Some(why) = config_unsupported(ctx, cfg) {
            o.status = Status::Skipped;
            o.message = why;
        } else if !format_ok {
            o.status = Status::Skipped;
            o.message = format!(
                "{:?} not supported as a depth-stencil attachment with transfers (vkGetPhysicalDeviceFormatProperties)",
                cfg.format
            );
        } else if let Some(r) = c.missing(&|r| have(ctx, r, cfg.format)) {
            o.status = Status::Skipped;
            o.message = r.reason().into();
        } else {
            run.push(c);
        }
        outcomes.push(o);
    }
    (outcomes, run)
}

/// Runs one configuration's selected cases in one submission: their outcomes (skipped ones
/// included, in generation order) and the submission's record (`None` when nothing ran).
pub fn run_config(ctx: &Context, cfg: Config, format_ok: bool, opts: &SuiteOptions) -> (Vec<CaseOutcome>, Option<ConfigRun>) {
    let bits = ctx.limits.sub_pixel_precision_bits;
    let (mut outcomes, run) = plan_config(ctx, cfg, format_ok, opts);
    if run.is_empty() {
        return (outcomes, None);
    }
    let _ = ctx.take_validation_errors();
    let t0 = Instant::now();
    let refs: Vec<&Case> = run.iter().collect();
    let result = batch::run(ctx, cfg, &refs);
    let errors = ctx.take_validation_errors();
    let seconds = t0.elapsed().as_secs_f64();
    let per_case = seconds / run.len() as f64;
    let config_run = ConfigRun { name: cfg.name(), cases: run.len(), seconds, validation_errors: errors.len() };
    let mut tiles = result.map_err(|e| e.to_string()).map(|t| t.into_iter());
    let mut k = 0;
    for c in &run {
        while outcomes[k].name != c.name {
            k += 1;
        }
        let o = &mut outcomes[k];
        o.seconds = per_case;
        let tile = match &mut tiles {
            Ok(it) => it.next(),
            Err(_) => None,
        };
        let Some(tile) = tile else {
            o.status = Status::Fail;
            o.message = format!("error: {}", tiles.as_ref().err().cloned().unwrap_or_else(|| "no result".into()));
            continue;
        };
        judge(c, &tile, bits, &errors, opts, o);
    }
    (outcomes, Some(config_run))
}

/// The test seam ([`SuiteOptions::mismatch`] naming a drawn case): every judged depth is
/// expected a quarter away from the model's, so the case fails on depth alone.
fn skew_depth(exp: &mut Expected) {
    let off = |v: f64| if v < 0.5 { 0.25 } else { -0.25 };
    for d in &mut exp.depth {
        *d = match *d {
            DepthExp::Any => DepthExp::Any,
            DepthExp::Exact(v) => DepthExp::Exact(v + off(v)),
            DepthExp::Range(a, b) => DepthExp::Range(a + off(a), b + off(a)),
        };
    }
}

/// Judges one drawn case's tile against the model into `o`.
fn judge(c: &Case, tile: &TileResult, bits: u32, errors: &[String], opts: &SuiteOptions, o: &mut CaseOutcome) {
    let mut exp = model::expect(c, bits, opts.break_op);
    if opts.mismatch.iter().any(|m| m.strip_prefix("umbrage.").unwrap_or(m) == c.name) {
        skew_depth(&mut exp);
    }
    let (sm, dm, judged, q, detail) = compare(c, &exp, tile);
    (o.stencil_mismatches, o.depth_mismatches, o.judged_pixels, o.queries) = (sm, dm, judged, q);
    if !detail.is_empty() || !errors.is_empty() {
        o.status = Status::Fail;
        let mut parts = Vec::new();
        if !errors.is_empty() {
            parts.push(format!("{} validation errors in the configuration (first: {})", errors.len(), errors[0]));
        }
        if sm + dm > 0 {
            parts.push(format!("{sm} stencil and {dm} depth mismatches of {judged} judged pixels"));
        }
        parts.extend(detail);
        o.message = parts.join("; ");
        if let Some(dir) = &opts.image_dir {
            match images::write_failure(&dir.join("failures").join(&c.name), c, &exp, tile) {
                Ok(paths) => o.images = paths,
                Err(e) => o.message.push_str(&format!("; images not written: {e}")),
            }
        }
    } else {
        o.message = format!("{judged} judged pixels exact");
        if !c.either.is_empty() {
            let tl = c.either.iter().filter(|&&(i, _, p)| tile.stencil[i] == p).count();
            o.message.push_str(&format!(
                ", each of the {} centres on the shared edge covered once; the D3D top-left convention held at {tl} of them",
                c.either.len()
            ));
        }
        if !o.queries.is_empty() {
            let exact = o.queries.iter().filter(|q| q.expected_min == q.expected_max).count();
            o.message.push_str(&format!(", {} query counts as modelled ({exact} of them exact)", o.queries.len()));
        }
    }
}

/// Runs the selected cases on `ctx`, in this process. `new_context` makes the fresh contexts
/// the pipeline checks' renderers need. [`super::isolate::run_suite_isolated`] runs the same
/// units in child processes instead.
pub fn run_suite(ctx: &Context, new_context: &dyn Fn() -> Result<Context>, opts: &SuiteOptions) -> Report {
    let start = Instant::now();
    let support = format_support(ctx);
    let mut outcomes = Vec::new();
    let mut configs = Vec::new();
    for cfg in Config::all(&FORMATS) {
        let format_ok = support.iter().any(|(f, s)| *f == cfg.format && s.usable);
        let (o, run) = run_config(ctx, cfg, format_ok, opts);
        outcomes.extend(o);
        configs.extend(run);
    }
    let every: Vec<&str> = LEGACY.iter().chain(COMMANDS.iter()).copied().collect();
    let mut legacy = run_legacy(ctx, new_context, opts, &every, &mut outcomes);
    legacy.extend(run_mesh(ctx, opts, &mut outcomes));
    legacy.extend(run_pipeline(ctx, new_context, opts, (0, 1), &mut outcomes));
    Report {
        device: ctx.info.clone(),
        features: ctx.features.clone(),
        validation: ctx.validation,
        subpixel_bits: ctx.limits.sub_pixel_precision_bits,
        filter: opts.filter.clone(),
        formats: support.into_iter().map(|(_, s)| s).collect(),
        configs,
        cases: outcomes,
        legacy,
        seconds: start.elapsed().as_secs_f64(),
        children: 0,
    }
}

/// The cases whose expectation `brk` changes (the seam test's prediction), among `filter`.
pub fn affected_by_break(brk: vk::StencilOp, filter: &[String], subpixel_bits: u32) -> Vec<String> {
    cases::all(&Config::all(&FORMATS))
        .into_iter()
        .filter(|c| selected(filter, &c.name))
        .filter(|c| model::expect(c, subpixel_bits, None) != model::expect(c, subpixel_bits, Some(brk)))
        .map(|c| c.name)
        .collect()
}
