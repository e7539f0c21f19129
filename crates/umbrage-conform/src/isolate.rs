//! Crash isolation, as deqp-runner does for the CTS: the suite's cases run in child processes
//! (`umbrage conform --child UNIT`), one per unit (one configuration's submission, the legacy
//! checks, the multiview check, the mesh checks, the pipeline checks shared among `--jobs`
//! children), through the runner of the driver-CI modes ([`super::deqp::exec`]). A driver
//! that crashes or hangs costs the one case that was running: that case is reported as
//! [`crate::Status::Crash`] or [`crate::Status::Timeout`] (JUnit `<error>`) with the signal or the timer
//! named, the rest of its unit's cases run again in a fresh child, and the run goes on. The
//! timer restarts at each case a child reaches (`--timeout`, per case).
//!
//! The parent opens its own context only to decide what runs (formats, features, skips), so a
//! child's crash never takes the report with it. A child writes its [`ChildResult`] as JSON to
//! the file the parent names, and nothing else counts as a result: an exit without that file is
//! a crash too (with the child's last stderr lines in the message).

pub use super::deqp::exec::ChildResult;
use super::deqp::exec::{self, Exec};
use super::suite::{self, CaseOutcome, ConfigRun, Report, SuiteOptions};
pub use super::units::Unit;
use std::path::PathBuf;
use std::time::{Duration, Instant};
use umbrage::error::Result;
use umbrage::gpu::Context;

/// How the isolated runner starts its children.
#[derive(Clone, Debug)]
pub struct Isolation {
    /// The `umbrage` executable (normally `std::env::current_exe()`).
    pub exe: PathBuf,
    /// The per-case timer: a child that reaches no new case (nor a step its cases share) for
    /// this long is killed, and the case it was running reported as hung.
    pub timeout: Duration,
    /// Children running at once (deqp-runner's `--jobs`).
    pub jobs: usize,
    /// Where the children write their results (created if missing).
    pub scratch: PathBuf,
}

/// Runs `unit` in this process (what a child does).
pub fn run_unit(ctx: &Context, unit: Unit, new_context: &dyn Fn() -> Result<Context>, opts: &SuiteOptions) -> ChildResult {
    match unit {
        Unit::Config(cfg) => {
            let format_ok = super::batch::format_usable(ctx, cfg.format);
            let (cases, config) = suite::run_config(ctx, cfg, format_ok, opts);
            ChildResult { cases, config, legacy: Vec::new() }
        }
        Unit::Legacy | Unit::Multiview => {
            let names = if unit == Unit::Legacy { super::units::legacy_unit() } else { super::units::MULTIVIEW.to_vec() };
            let mut cases = Vec::new();
            let legacy = suite::run_legacy(ctx, new_context, opts, &names, &mut cases);
            ChildResult { cases, config: None, legacy }
        }
        Unit::Mesh => {
            let mut cases = Vec::new();
            let legacy = suite::run_mesh(ctx, opts, &mut cases);
            ChildResult { cases, config: None, legacy }
        }
        Unit::Pipeline { shard, shards } => {
            let mut cases = Vec::new();
            let legacy = suite::run_pipeline(ctx, new_context, opts, (shard, shards), &mut cases);
            ChildResult { cases, config: None, legacy }
        }
    }
}

/// The suite with every unit in a child process: the same report as
/// [`suite::run_suite`], except that the case a crashed or hung child was running is
/// [`crate::Status::Crash`] or [`crate::Status::Timeout`] (the rest of its unit runs again in a fresh child).
/// `ctx` is the parent's own context (device, features, skips); the children write their
/// failure images under `images` (`failures/<case>/`).
pub fn run_suite_isolated(ctx: &Context, opts: &SuiteOptions, iso: &Isolation, images: &std::path::Path) -> Result<Report> {
    let start = Instant::now();
    let selected: Vec<String> = suite::all_names().into_iter().filter(|n| super::outcome::selected(&opts.filter, n)).collect();
    let ex = Exec {
        exe: iso.exe.clone(),
        timeout: iso.timeout,
        jobs: iso.jobs.max(1),
        scratch: iso.scratch.clone(),
        images: images.to_path_buf(),
        chunk: usize::MAX,
        unit_chunk: usize::MAX,
        pipeline_children: iso.jobs.max(1),
    };
    let mut cases: Vec<CaseOutcome> = Vec::new();
    let extras = exec::run(ctx, &selected, &ex, opts, &mut |_| {}, &mut |d| cases.push(d.outcome))?;
    let _ = std::fs::remove_dir_all(&iso.scratch);
    // In generation order, as in process.
    let order: std::collections::HashMap<&str, usize> = selected.iter().enumerate().map(|(i, n)| (n.as_str(), i)).collect();
    cases.sort_by_key(|c| order.get(c.name.as_str()).copied().unwrap_or(usize::MAX));
    let configs: Vec<ConfigRun> = extras.configs;
    Ok(Report {
        device: ctx.info.clone(),
        features: ctx.features.clone(),
        validation: ctx.validation,
        subpixel_bits: ctx.limits.sub_pixel_precision_bits,
        filter: opts.filter.clone(),
        formats: suite::format_support(ctx).into_iter().map(|(_, s)| s).collect(),
        configs,
        cases,
        legacy: extras.legacy,
        seconds: start.elapsed().as_secs_f64(),
        children: extras.children,
    })
}
