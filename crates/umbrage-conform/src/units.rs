//! The suite's units ([`Unit`]: what crash isolation runs in one child) and the
//! single-configuration ones: the `legacy.*` checks (split into the `legacy` unit and the
//! `multiview` unit, which crash isolation runs apart), the `mesh.*` family (a unit of its own)
//! and the `pipeline.hard_cases.*` renders against the CPU reference.

use super::cases::{Config, FORMATS};
use super::outcome::{selected, CaseOutcome, SuiteOptions};
use super::{CheckResult, Status};
use std::time::Instant;
use umbrage::error::Result;
use umbrage::gpu::Context;

pub(crate) const LEGACY: [&str; 10] = [
    "w0_vertices_and_infinity",
    "depth_clamp",
    "watertight_fan",
    "two_sided_stencil_wrap",
    "stencil_formats",
    "depth_bounds",
    "index_types",
    "deep_wrap_float_count",
    super::checks::MSAA_DEPTH_LOCATIONS,
    super::checks::MULTIVIEW_CUBE_FACES,
];

/// One unit of the suite, as named on the child's command line.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Unit {
    /// One configuration's submission (`d24s8.render_pass.static_state`).
    Config(Config),
    /// The `legacy.*` single-configuration checks, but multiview.
    Legacy,
    /// `legacy.multiview_cube_faces` on its own (a multiview crash costs no other check).
    Multiview,
    /// The `mesh.*` family on its own (mesh shaders are young in drivers: a crash there costs
    /// no other check).
    Mesh,
    /// The `pipeline.hard_cases.*` renders against the CPU reference, of the hard scenes whose
    /// index is `shard` modulo `shards` (split so that `--jobs` children share them).
    Pipeline {
        /// This unit's share.
        shard: usize,
        /// How many units share the scenes (at least 1).
        shards: usize,
    },
}

impl Unit {
    /// The name a child is given: the configuration's name, `legacy`, `multiview`, `mesh` or
    /// `pipeline`.
    pub fn name(&self) -> String {
        match self {
            Unit::Config(c) => c.name(),
            Unit::Legacy => "legacy".into(),
            Unit::Multiview => "multiview".into(),
            Unit::Mesh => "mesh".into(),
            Unit::Pipeline { shards: 1, .. } => "pipeline".into(),
            Unit::Pipeline { shard, shards } => format!("pipeline.{shard}of{shards}"),
        }
    }

    /// Parses [`Unit::name`].
    pub fn parse(s: &str) -> Option<Unit> {
        match s {
            "legacy" => Some(Unit::Legacy),
            "multiview" => Some(Unit::Multiview),
            "mesh" => Some(Unit::Mesh),
            "pipeline" => Some(Unit::Pipeline { shard: 0, shards: 1 }),
            _ if s.starts_with("pipeline.") => {
                let (k, n) = s["pipeline.".len()..].split_once("of")?;
                let (shard, shards) = (k.parse().ok()?, n.parse().ok()?);
                (shard < shards).then_some(Unit::Pipeline { shard, shards })
            }
            _ => Config::all(&FORMATS).into_iter().find(|c| c.name() == s).map(Unit::Config),
        }
    }
}

/// The `commands.*` checks (run in the `legacy` unit): what umbrage records besides draws.
pub(crate) const COMMANDS: [&str; 13] = super::checks::commands::NAMES;

/// The `mesh.*` checks (the `mesh` unit): the mesh-shader family.
pub(crate) const MESH: [&str; 4] = super::mesh::NAMES;

/// A single-configuration check's case name: `commands.<name>` or `legacy.<name>`.
pub(crate) fn full_name(name: &str) -> String {
    match COMMANDS.contains(&name) {
        true => format!("commands.{name}"),
        false => format!("legacy.{name}"),
    }
}

/// What the `legacy` unit runs: the legacy checks but multiview, and the commands.
pub(crate) fn legacy_unit() -> Vec<&'static str> {
    SINGLE.iter().chain(COMMANDS.iter()).copied().collect()
}

/// The legacy checks the `legacy` unit runs: everything but multiview.
pub(crate) const SINGLE: &[&str] = LEGACY.split_at(9).0;
/// The legacy check the `multiview` unit runs on its own: the renderer's multiview cube faces,
/// the feature most likely to take a driver down (a crash there costs no other check).
pub(crate) const MULTIVIEW: &[&str] = LEGACY.split_at(9).1;

fn pipeline_name(scene: &str, m: umbrage::shadow::Method) -> String {
    format!("pipeline.hard_cases.{}.{}", scene.trim_start_matches("hard/"), m.name())
}

/// The pipeline case names of the hard scenes whose index is `shard.0` modulo `shard.1`.
pub(crate) fn pipeline_shard_names(shard: (usize, usize)) -> Vec<String> {
    let mut v = Vec::new();
    let scenes = umbrage_scene::builtin_names().into_iter().filter(|n| n.starts_with("hard/"));
    for (_, scene) in scenes.enumerate().filter(|(i, _)| i % shard.1.max(1) == shard.0) {
        for m in umbrage::shadow::Method::ALL {
            v.push(pipeline_name(scene, m));
        }
    }
    v
}

/// The selected `legacy.*` checks among `names` (outcomes into `out`, full results returned).
pub fn run_legacy(
    ctx: &Context,
    new_context: &dyn Fn() -> Result<Context>,
    opts: &SuiteOptions,
    names: &[&str],
    out: &mut Vec<CaseOutcome>,
) -> Vec<CheckResult> {
    type Check = fn(&Context) -> Result<CheckResult>;
    type Run<'a> = Box<dyn Fn() -> Result<CheckResult> + 'a>;
    let on_ctx = |f: Check| -> Run<'_> { Box::new(move || f(ctx)) };
    use super::checks::commands;
    let unit: [(&str, Run<'_>); 23] = [
        (LEGACY[0], on_ctx(super::checks::w0_vertices_and_infinity)),
        (LEGACY[1], on_ctx(super::checks::depth_clamp)),
        (LEGACY[2], on_ctx(super::checks::watertight_fan)),
        (LEGACY[3], on_ctx(super::checks::two_sided_stencil_wrap)),
        (LEGACY[4], on_ctx(super::checks::stencil_formats)),
        (LEGACY[5], on_ctx(super::checks::depth_bounds)),
        (LEGACY[6], on_ctx(super::checks::index_types)),
        (LEGACY[7], on_ctx(super::checks::deep_wrap_float_count)),
        (LEGACY[8], on_ctx(super::checks::msaa_depth_locations)),
        // The renderer on a context of its own (the one a frame needs).
        (LEGACY[9], Box::new(|| super::checks::multiview_cube_faces(ctx, new_context))),
        (COMMANDS[0], on_ctx(commands::clears)),
        (COMMANDS[1], on_ctx(commands::copy_aspects)),
        (COMMANDS[2], on_ctx(commands::layouts)),
        (COMMANDS[3], on_ctx(commands::blit_copy_color)),
        (COMMANDS[4], on_ctx(commands::buffers)),
        (COMMANDS[5], on_ctx(commands::queries)),
        (COMMANDS[6], on_ctx(commands::scissor)),
        (COMMANDS[7], on_ctx(commands::indirect)),
        (COMMANDS[8], on_ctx(commands::fill_buffer)),
        (COMMANDS[9], on_ctx(commands::dispatch)),
        (COMMANDS[10], on_ctx(commands::dispatch_indirect)),
        (COMMANDS[11], on_ctx(commands::multi_draw_indirect)),
        (COMMANDS[12], on_ctx(commands::draw_indirect_count)),
    ];
    let mut results = Vec::new();
    for (name, f) in unit {
        let full = full_name(name);
        if !names.contains(&name) || !selected(&opts.filter, &full) {
            continue;
        }
        let command = COMMANDS.contains(&name);
        let (group, what) = match command {
            true => ("commands", format!("recorded command `{name}` against its spec semantics")),
            false => ("legacy", format!("single-configuration check `{name}` (the renderer's depth format)")),
        };
        let mut o = CaseOutcome::new(full, group, None, what);
        // Every legacy check but the float count draws through the harness's dynamic rendering
        // (the commands checks say themselves what they need).
        if !ctx.features.dynamic_rendering && name != "deep_wrap_float_count" && !command {
            o.status = Status::Skipped;
            let version = &ctx.info.api_version;
            o.message =
                format!("the single-configuration checks draw with dynamic rendering (Vulkan 1.3); the device has Vulkan {version}");
            out.push(o);
            continue;
        }
        let t0 = Instant::now();
        super::progress::case(&o.name);
        super::image_sink::begin(opts.image_dir.as_ref().map(|d| d.join("failures").join(&o.name)));
        super::value_images::set_skew(opts.mismatch.iter().any(|m| m == name || *m == o.name));
        let mut r = f().unwrap_or_else(|e| CheckResult::error(name, &e));
        super::value_images::set_skew(false);
        o.images = super::image_sink::finish();
        super::progress::step("end");
        super::with_validation(&mut r, ctx.take_validation_errors());
        o.status = r.status;
        o.message = r.summary.clone();
        o.seconds = t0.elapsed().as_secs_f64();
        out.push(o);
        results.push(r);
    }
    results
}

/// The selected `mesh.*` checks (outcomes into `out`, full results returned): each skipped as
/// unsupported, with the reason, where the device lacks what it needs.
pub fn run_mesh(ctx: &Context, opts: &SuiteOptions, out: &mut Vec<CaseOutcome>) -> Vec<CheckResult> {
    type Check = fn(&Context) -> Result<CheckResult>;
    use super::mesh;
    let checks: [(&str, Check); 4] =
        [(MESH[0], mesh::w0_vertices), (MESH[1], mesh::watertight_meshlets), (MESH[2], mesh::group_counts), (MESH[3], mesh::task_payload)];
    let mut results = Vec::new();
    for (name, f) in checks {
        let full = format!("mesh.{name}");
        if !selected(&opts.filter, &full) {
            continue;
        }
        let mut o = CaseOutcome::new(full, "mesh", None, format!("mesh-shader check `{name}` (VK_EXT_mesh_shader, the renderer's format)"));
        if let Some(why) = mesh::unsupported(ctx, name) {
            o.status = Status::Skipped;
            o.message = why;
            out.push(o);
            continue;
        }
        let t0 = Instant::now();
        let _ = ctx.take_validation_errors();
        super::progress::case(&o.name);
        super::image_sink::begin(opts.image_dir.as_ref().map(|d| d.join("failures").join(&o.name)));
        super::value_images::set_skew(opts.mismatch.iter().any(|m| m == name || *m == o.name));
        let mut r = f(ctx).unwrap_or_else(|e| CheckResult::error(name, &e));
        super::value_images::set_skew(false);
        o.images = super::image_sink::finish();
        super::progress::step("end");
        super::with_validation(&mut r, ctx.take_validation_errors());
        o.status = r.status;
        o.message = r.summary.clone();
        o.seconds = t0.elapsed().as_secs_f64();
        out.push(o);
        results.push(r);
    }
    results
}

/// The selected `pipeline.hard_cases.*` cases of the hard scenes in `shard` (`(k, n)`: those
/// whose index is k modulo n; `(0, 1)`: all), outcomes into `out`, the check's full result
/// returned.
pub fn run_pipeline(
    ctx: &Context,
    new_context: &dyn Fn() -> Result<Context>,
    opts: &SuiteOptions,
    shard: (usize, usize),
    out: &mut Vec<CaseOutcome>,
) -> Vec<CheckResult> {
    let mut results = Vec::new();
    let names: Vec<String> = pipeline_shard_names(shard).into_iter().filter(|n| selected(&opts.filter, n)).collect();
    if !names.is_empty() && !ctx.features.dynamic_rendering {
        for n in names {
            let mut o = CaseOutcome::new(n, "pipeline", None, "the whole shadow pipeline against the exact CPU reference".into());
            o.status = Status::Skipped;
            o.message = format!(
                "the renderer needs Vulkan 1.3 (dynamicRendering, synchronization2); the device has Vulkan {}",
                ctx.info.api_version
            );
            out.push(o);
        }
    } else if !names.is_empty() {
        let t0 = Instant::now();
        let (w, h) = opts.pipeline_size;
        let chosen = |scene: &str, m: umbrage::shadow::Method| names.contains(&pipeline_name(scene, m));
        super::image_sink::begin(opts.image_dir.as_ref().map(|d| d.join("failures")));
        let result = super::checks::shadow_pipeline_hard_cases(new_context, w, h, &chosen);
        super::progress::step("end");
        let images = super::image_sink::finish_per_case();
        match result {
            Ok(r) => {
                let per = t0.elapsed().as_secs_f64() / r.cases.len().max(1) as f64;
                for k in &r.cases {
                    let full = format!("pipeline.hard_cases.{}.{}", k.scene.trim_start_matches("hard/"), k.method);
                    if !names.contains(&full) {
                        continue;
                    }
                    let mut o =
                        CaseOutcome::new(full, "pipeline", None, "the whole shadow pipeline against the exact CPU reference".into());
                    o.seconds = per;
                    o.status = if k.status == "fail" { Status::Fail } else { Status::Pass };
                    o.message = format!(
                        "{}: {} of {} compared pixels mismatched outside the 1-pixel band ({:.4}%)",
                        k.status,
                        k.mismatches_outside_band,
                        k.compared,
                        k.worst_fraction_outside_band * 100.0
                    );
                    if k.expected_failure {
                        o.message.push_str(" — a known limitation of this method (accuracy::expected_failure), reproduced");
                    }
                    o.images = images.iter().filter(|(c, _)| *c == o.name).map(|(_, p)| p.clone()).collect();
                    out.push(o);
                }
                results.push(r);
            }
            Err(e) => {
                for n in names {
                    let mut o = CaseOutcome::new(n, "pipeline", None, "the whole shadow pipeline against the exact CPU reference".into());
                    o.status = Status::Fail;
                    o.message = format!("error: {e}");
                    out.push(o);
                }
            }
        }
    }
    results
}
