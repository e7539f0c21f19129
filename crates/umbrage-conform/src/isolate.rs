//! Crash isolation, as deqp-runner does for the CTS: every unit of the suite (one
//! configuration's submission, the legacy checks, the multiview check, the pipeline checks) runs in a child
//! process (`umbrage conform --child UNIT`) with a timeout. A driver that crashes or hangs
//! costs exactly that unit's cases, each reported as [`Status::Crash`] (JUnit `<error>`) with
//! the signal or the timeout named, and the run goes on.
//!
//! The parent opens its own context only to decide what runs (formats, features, skips), so a
//! child's crash never takes the report with it. A child writes its [`ChildResult`] as JSON to
//! the file the parent names, and nothing else counts as a result: an exit without that file is
//! a crash too (with the child's last stderr lines in the message).

use super::cases::{Config, FORMATS};
use super::suite::{self, CaseOutcome, ConfigRun, Report, SuiteOptions};
pub use super::units::Unit;
use super::{CheckResult, Status};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};
use umbrage::error::{Error, Result};
use umbrage::gpu::Context;

/// How the isolated runner starts its children.
#[derive(Clone, Debug)]
pub struct Isolation {
    /// The `umbrage` executable (normally `std::env::current_exe()`).
    pub exe: PathBuf,
    /// A unit with no result after this long is killed and its cases reported as hung.
    pub timeout: Duration,
    /// Children running at once (deqp-runner's `--jobs`).
    pub jobs: usize,
    /// Where the children write their results (created if missing).
    pub scratch: PathBuf,
}

/// What a child sends back.
#[derive(Debug, serde::Serialize, serde::Deserialize)]
pub struct ChildResult {
    /// The unit's selected cases, in generation order.
    pub cases: Vec<CaseOutcome>,
    /// The submission's record (a configuration unit that drew something).
    pub config: Option<ConfigRun>,
    /// The single-configuration checks' full results.
    pub legacy: Vec<CheckResult>,
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

/// The test seam `UMBRAGE_CONFORM_CRASH=<unit>:abort|hang`: the child running `<unit>`
/// aborts (SIGABRT, as a driver assertion would) or sleeps forever (a hung driver) before it
/// draws. Honoured only in child mode.
pub fn injected_crash(unit: Unit) {
    let Ok(v) = std::env::var("UMBRAGE_CONFORM_CRASH") else { return };
    let Some((name, how)) = v.rsplit_once(':') else { return };
    if name != unit.name() {
        return;
    }
    match how {
        "abort" => std::process::abort(),
        "hang" => loop {
            std::thread::sleep(Duration::from_secs(3600));
        },
        _ => {}
    }
}

/// A running child and what it stands for.
struct Running {
    child: Child,
    result: PathBuf,
    stderr: PathBuf,
    started: Instant,
}

/// How a child ended.
enum End {
    /// It wrote its result.
    Result(Box<ChildResult>),
    /// It crashed, hung or exited without a result: the message for each of its cases.
    Crash(String),
}

/// The suite with every unit in a child process: the same report as
/// [`suite::run_suite`], except that a unit whose child crashed or hung has its cases as
/// [`Status::Crash`]. `ctx` is the parent's own context (device, features, skips); `args` are
/// passed to every child (`--filter`, `--out`) after `conform --child UNIT --child-result FILE`.
pub fn run_suite_isolated(ctx: &Context, opts: &SuiteOptions, iso: &Isolation, args: &[String]) -> Result<Report> {
    let start = Instant::now();
    std::fs::create_dir_all(&iso.scratch).map_err(|e| Error::io(iso.scratch.display().to_string(), e))?;
    let support = suite::format_support(ctx);
    // Every unit's planned outcomes (skips decided here), and the units that need a child.
    let mut planned: Vec<(Unit, Vec<CaseOutcome>, bool)> = Vec::new();
    for cfg in Config::all(&FORMATS) {
        let format_ok = support.iter().any(|(f, s)| *f == cfg.format && s.usable);
        let (outcomes, run) = suite::plan_config(ctx, cfg, format_ok, opts);
        if !outcomes.is_empty() {
            let needs = !run.is_empty();
            planned.push((Unit::Config(cfg), outcomes, needs));
        }
    }
    let shards = iso.jobs.max(1);
    let units = [Unit::Legacy, Unit::Multiview, Unit::Mesh].into_iter().chain((0..shards).map(|shard| Unit::Pipeline { shard, shards }));
    for unit in units {
        let names = suite::unit_case_names(unit, &opts.filter);
        if names.is_empty() {
            continue;
        }
        // The child decides what its device skips (it may draw nothing at all).
        let outcomes = names.into_iter().map(|n| CaseOutcome::new(n, unit_group(unit), None, String::new())).collect();
        planned.push((unit, outcomes, true));
    }

    let mut ends: Vec<Option<End>> = planned.iter().map(|_| None).collect();
    let mut queue: Vec<usize> = (0..planned.len()).filter(|&i| planned[i].2).collect();
    queue.reverse();
    let mut running: Vec<(usize, Running)> = Vec::new();
    while !queue.is_empty() || !running.is_empty() {
        while running.len() < iso.jobs.max(1) {
            let Some(i) = queue.pop() else { break };
            match spawn(iso, planned[i].0, args) {
                Ok(r) => running.push((i, r)),
                Err(e) => ends[i] = Some(End::Crash(format!("the child process could not be started: {e}"))),
            }
        }
        let mut k = 0;
        while k < running.len() {
            match poll(&mut running[k].1, iso.timeout) {
                Some(end) => {
                    let (i, _) = running.swap_remove(k);
                    ends[i] = Some(end);
                }
                None => k += 1,
            }
        }
        if !running.is_empty() {
            std::thread::sleep(Duration::from_millis(5));
        }
    }

    let mut cases = Vec::new();
    let mut configs = Vec::new();
    let mut legacy = Vec::new();
    for ((unit, mut outcomes, needs), end) in planned.into_iter().zip(ends) {
        match end {
            Some(End::Result(r)) if matches!(unit, Unit::Config(_)) => {
                // Keep the parent's descriptions (what, bug); take the child's verdicts.
                for o in &mut outcomes {
                    if let Some(c) = r.cases.iter().find(|c| c.name == o.name) {
                        let (what, bug) = (std::mem::take(&mut o.what), o.bug.take());
                        *o = c.clone();
                        (o.what, o.bug) = (what, bug);
                    }
                }
                configs.extend(r.config);
            }
            Some(End::Result(r)) => {
                outcomes = r.cases;
                legacy.extend(r.legacy);
            }
            Some(End::Crash(msg)) => {
                // Every case the child was to draw; those skipped here stay skipped.
                for o in outcomes.iter_mut().filter(|o| needs && o.status != Status::Skipped) {
                    o.status = Status::Crash;
                    o.message = format!("{msg} (unit {})", unit.name());
                }
            }
            None => {}
        }
        cases.extend(outcomes);
    }
    // In generation order, as in process (the pipeline shards interleave the scenes).
    let order: std::collections::HashMap<String, usize> = suite::all_names().into_iter().enumerate().map(|(i, n)| (n, i)).collect();
    cases.sort_by_key(|c| order.get(&c.name).copied().unwrap_or(usize::MAX));
    Ok(Report {
        device: ctx.info.clone(),
        features: ctx.features.clone(),
        validation: ctx.validation,
        subpixel_bits: ctx.limits.sub_pixel_precision_bits,
        filter: opts.filter.clone(),
        formats: support.into_iter().map(|(_, s)| s).collect(),
        configs,
        cases,
        legacy,
        seconds: start.elapsed().as_secs_f64(),
    })
}

fn unit_group(unit: Unit) -> &'static str {
    match unit {
        Unit::Pipeline { .. } => "pipeline",
        Unit::Mesh => "mesh",
        _ => "legacy",
    }
}

fn spawn(iso: &Isolation, unit: Unit, args: &[String]) -> std::io::Result<Running> {
    let name = unit.name();
    let result = iso.scratch.join(format!("{name}.json"));
    let stderr = iso.scratch.join(format!("{name}.stderr"));
    let _ = std::fs::remove_file(&result);
    let child = Command::new(&iso.exe)
        .args(["conform", "--child", &name, "--child-result"])
        .arg(&result)
        .args(args)
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(std::fs::File::create(&stderr)?)
        .spawn()?;
    Ok(Running { child, result, stderr, started: Instant::now() })
}

/// `Some` once the child has ended (or was killed for running past `timeout`).
fn poll(r: &mut Running, timeout: Duration) -> Option<End> {
    let status = match r.child.try_wait() {
        Ok(Some(s)) => s,
        Ok(None) if r.started.elapsed() < timeout => return None,
        Ok(None) => {
            let _ = r.child.kill();
            let _ = r.child.wait();
            return Some(End::Crash(format!("driver hang: no result within {} s, the child process was killed", timeout.as_secs_f64())));
        }
        Err(e) => return Some(End::Crash(format!("waiting for the child process failed: {e}"))),
    };
    if status.success() {
        if let Ok(text) = std::fs::read_to_string(&r.result) {
            match serde_json::from_str::<ChildResult>(&text) {
                Ok(c) => return Some(End::Result(Box::new(c))),
                Err(e) => return Some(End::Crash(format!("the child's result {} is unreadable: {e}", r.result.display()))),
            }
        }
    }
    let how = describe(status);
    let tail = stderr_tail(&r.stderr);
    Some(End::Crash(if tail.is_empty() { format!("driver crash: {how}") } else { format!("driver crash: {how}; last stderr: {tail}") }))
}

/// "the child process was killed by signal 11 (SIGSEGV)" or "... exited with status 101 ...".
fn describe(status: std::process::ExitStatus) -> String {
    #[cfg(unix)]
    let signal = std::os::unix::process::ExitStatusExt::signal(&status);
    #[cfg(not(unix))]
    let signal: Option<i32> = None;
    if let Some(sig) = signal {
        let name = match sig {
            4 => "SIGILL",
            6 => "SIGABRT",
            7 => "SIGBUS",
            8 => "SIGFPE",
            9 => "SIGKILL",
            11 => "SIGSEGV",
            15 => "SIGTERM",
            _ => "signal",
        };
        format!("the child process was killed by signal {sig} ({name})")
    } else {
        format!("the child process exited with status {} without a result", status.code().unwrap_or(-1))
    }
}

/// The last few lines of a child's stderr, joined with ` | `.
fn stderr_tail(path: &Path) -> String {
    let text = std::fs::read_to_string(path).unwrap_or_default();
    let lines: Vec<&str> = text.lines().filter(|l| !l.trim().is_empty()).collect();
    lines[lines.len().saturating_sub(3)..].join(" | ")
}
