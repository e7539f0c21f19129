//! The runner behind the dEQP-compatible mode and the standalone driver-CI flags: the selected
//! cases of every unit ([`Unit`]: a configuration's submission, the legacy checks, ...) run in
//! child processes of at most [`Exec::chunk`] cases each, and a child that crashes or hangs
//! has its cases run again one per child, so that the crash ([`Code::Crash`]) or the hang
//! ([`Code::Timeout`]) is reported for the case that caused it alone and the others keep the
//! results they really have.
//!
//! The test seam `UMBRAGE_CONFORM_CRASH_CASE=<case>:abort|hang` (read by the conform harness's
//! child mode only, never by the engine) makes the child whose cases include `<case>` (public
//! or short name) abort or hang before it draws; see [`injected_case_fault`].

use super::super::cases::{Config, FORMATS};
use super::super::isolate::ChildResult;
use super::super::suite::{self, CaseOutcome, SuiteOptions};
use super::super::units::Unit;
use super::super::Status;
use super::names;
use std::collections::{HashMap, HashSet, VecDeque};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};
use umbrage::error::{Error, Result};
use umbrage::gpu::Context;

/// A case's status, as dEQP names it (the `StatusCode` of its QPA record and its stdout line).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Code {
    /// Every expectation held.
    Pass,
    /// An expectation failed (or the validation layers reported an error).
    Fail,
    /// The device lacks what the case needs (umbrage's `skipped`).
    NotSupported,
    /// The child process running the case died.
    Crash,
    /// The child process running the case gave no result within the unit timeout.
    Timeout,
}

impl Code {
    /// dEQP's name: `Pass`, `Fail`, `NotSupported`, `Crash`, `Timeout`.
    pub fn name(self) -> &'static str {
        match self {
            Code::Pass => "Pass",
            Code::Fail => "Fail",
            Code::NotSupported => "NotSupported",
            Code::Crash => "Crash",
            Code::Timeout => "Timeout",
        }
    }

    /// The status of `conform.json` (a timeout is a crash there, as it always was).
    pub fn status(self) -> Status {
        match self {
            Code::Pass => Status::Pass,
            Code::Fail => Status::Fail,
            Code::NotSupported => Status::Skipped,
            Code::Crash | Code::Timeout => Status::Crash,
        }
    }
}

/// One finished case.
#[derive(Clone, Debug)]
pub struct Done {
    /// Its public name.
    pub public: String,
    /// Its status.
    pub code: Code,
    /// The full outcome (the short name, message, numbers, failure images).
    pub outcome: CaseOutcome,
}

/// What the children sent back besides their cases: each configuration submission's record and
/// the single-configuration checks' full results (for `conform.json` and `conform.md`).
#[derive(Clone, Debug, Default)]
pub struct Extras {
    /// One record per child that drew a configuration's cases.
    pub configs: Vec<super::super::suite::ConfigRun>,
    /// The full results of the `legacy.*`, `commands.*`, `mesh.*` and pipeline checks.
    pub legacy: Vec<super::super::CheckResult>,
}

/// How the runner starts its children.
#[derive(Clone, Debug)]
pub struct Exec {
    /// The `umbrage` executable.
    pub exe: PathBuf,
    /// A child with no result after this long is killed (its cases then run one per child).
    pub timeout: Duration,
    /// Children at once.
    pub jobs: usize,
    /// Where children write their results (created if missing).
    pub scratch: PathBuf,
    /// Where children write their failure images (`failures/<case>/`).
    pub images: PathBuf,
    /// The most cases of a configuration one child draws (the single-configuration units
    /// take an eighth of it, at least 1).
    pub chunk: usize,
}

struct Job {
    unit: Unit,
    names: Vec<String>,
    /// A re-run of one case of a child that crashed or hung.
    retry: bool,
}

struct Running {
    job: Job,
    child: Child,
    result: PathBuf,
    stderr: PathBuf,
    started: Instant,
}

enum End {
    Result(Box<ChildResult>),
    Crash(String),
    Timeout(String),
}

/// Runs the cases named (short names) in `selected`, in children, calling `started` with a
/// case's public name when a child starts for that case alone (a re-run after a crash: dEQP
/// prints `Test case` then) and `done` as each case finishes. `ctx` decides the skips a
/// configuration's format and features imply. The children inherit the
/// environment (`UMBRAGE_VALIDATION`, `UMBRAGE_CONFORM_BREAK`, the driver's).
pub fn run(
    ctx: &Context,
    selected: &[String],
    ex: &Exec,
    opts: &SuiteOptions,
    started: &mut dyn FnMut(&str),
    done: &mut dyn FnMut(Done),
) -> Result<Extras> {
    let mut extras = Extras::default();
    std::fs::create_dir_all(&ex.scratch).map_err(|e| Error::io(ex.scratch.display().to_string(), e))?;
    let wanted: HashSet<&str> = selected.iter().map(String::as_str).collect();
    let mut queue: VecDeque<Job> = VecDeque::new();
    let support = suite::format_support(ctx);
    let chunk = ex.chunk.max(1);
    for cfg in Config::all(&FORMATS) {
        let names: Vec<String> =
            super::super::cases::all(&[cfg]).into_iter().map(|c| c.name).filter(|n| wanted.contains(n.as_str())).collect();
        if names.is_empty() {
            continue;
        }
        let format_ok = support.iter().any(|(f, s)| *f == cfg.format && s.usable);
        let o = SuiteOptions { filter: exact(&names), ..opts.clone() };
        let (outcomes, run) = suite::plan_config(ctx, cfg, format_ok, &o);
        for out in outcomes.into_iter().filter(|o| o.status == Status::Skipped) {
            done(finish(out, Code::NotSupported));
        }
        let to_run: Vec<String> = run.into_iter().map(|c| c.name).collect();
        for part in to_run.chunks(chunk) {
            queue.push_back(Job { unit: Unit::Config(cfg), names: part.to_vec(), retry: false });
        }
    }
    for unit in [Unit::Legacy, Unit::Multiview, Unit::Mesh, Unit::Pipeline { shard: 0, shards: 1 }] {
        let names: Vec<String> = suite::unit_case_names(unit, &[]).into_iter().filter(|n| wanted.contains(n.as_str())).collect();
        for part in names.chunks((chunk / 8).max(1)) {
            queue.push_back(Job { unit, names: part.to_vec(), retry: false });
        }
    }

    let mut running: Vec<Running> = Vec::new();
    let mut serial = 0usize;
    while !queue.is_empty() || !running.is_empty() {
        while running.len() < ex.jobs.max(1) {
            let Some(job) = queue.pop_front() else { break };
            if job.retry {
                started(&names::public(&job.names[0]));
            }
            serial += 1;
            match spawn(ex, job, serial) {
                Ok(r) => running.push(r),
                Err((job, e)) => {
                    for n in &job.names {
                        done(lost(n, Code::Crash, &format!("the child process could not be started: {e}")));
                    }
                }
            }
        }
        let mut k = 0;
        while k < running.len() {
            let Some(end) = poll(&mut running[k], ex.timeout) else {
                k += 1;
                continue;
            };
            let r = running.swap_remove(k);
            let _ = std::fs::remove_file(&r.result);
            let _ = std::fs::remove_file(&r.stderr);
            match end {
                End::Result(res) => {
                    extras.configs.extend(res.config);
                    extras.legacy.extend(res.legacy);
                    let mut by_name: HashMap<String, CaseOutcome> = res.cases.into_iter().map(|c| (c.name.clone(), c)).collect();
                    for n in &r.job.names {
                        match by_name.remove(n) {
                            Some(o) => {
                                let code = match o.status {
                                    Status::Pass => Code::Pass,
                                    Status::Fail => Code::Fail,
                                    Status::Skipped => Code::NotSupported,
                                    Status::Crash => Code::Crash,
                                };
                                done(finish(o, code));
                            }
                            None => done(lost(n, Code::Fail, "the child process returned no result for this case")),
                        }
                    }
                }
                End::Crash(msg) | End::Timeout(msg) if r.job.names.len() > 1 => {
                    // Pin it: every case again, one per child, before anything else runs.
                    eprintln!(
                        "umbrage conform: {msg} (unit {}, {} cases): running them one per child",
                        r.job.unit.name(),
                        r.job.names.len()
                    );
                    for n in r.job.names.iter().rev() {
                        queue.push_front(Job { unit: r.job.unit, names: vec![n.clone()], retry: true });
                    }
                }
                End::Crash(msg) => done(lost(&r.job.names[0], Code::Crash, &msg)),
                End::Timeout(msg) => done(lost(&r.job.names[0], Code::Timeout, &msg)),
            }
        }
        if !running.is_empty() {
            std::thread::sleep(Duration::from_millis(5));
        }
    }
    Ok(extras)
}

/// Filter patterns that select exactly `names` (see [`suite::matches`]'s `=` form).
pub fn exact(names: &[String]) -> Vec<String> {
    names.iter().map(|n| format!("={n}")).collect()
}

fn finish(outcome: CaseOutcome, code: Code) -> Done {
    Done { public: names::public(&outcome.name), code, outcome }
}

fn lost(name: &str, code: Code, msg: &str) -> Done {
    let group = name.split('.').next().unwrap_or("");
    let mut o = CaseOutcome::new(name.to_string(), group, None, String::new());
    o.status = code.status();
    o.message = msg.to_string();
    finish(o, code)
}

fn spawn(ex: &Exec, job: Job, serial: usize) -> std::result::Result<Running, (Job, std::io::Error)> {
    let result = ex.scratch.join(format!("child-{serial}.json"));
    let stderr = ex.scratch.join(format!("child-{serial}.stderr"));
    let _ = std::fs::remove_file(&result);
    let file = match std::fs::File::create(&stderr) {
        Ok(f) => f,
        Err(e) => return Err((job, e)),
    };
    let mut cmd = Command::new(&ex.exe);
    cmd.args(["conform", "--child", &job.unit.name(), "--child-result"])
        .arg(&result)
        .arg("--out")
        .arg(&ex.images)
        .arg("--filter")
        .arg(exact(&job.names).join(","))
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(file);
    match cmd.spawn() {
        Ok(child) => Ok(Running { job, child, result, stderr, started: Instant::now() }),
        Err(e) => Err((job, e)),
    }
}

fn poll(r: &mut Running, timeout: Duration) -> Option<End> {
    let status = match r.child.try_wait() {
        Ok(Some(s)) => s,
        Ok(None) if r.started.elapsed() < timeout => return None,
        Ok(None) => {
            let _ = r.child.kill();
            let _ = r.child.wait();
            return Some(End::Timeout(format!(
                "driver hang: no result within {} s (the unit timeout), the child process was killed",
                timeout.as_secs_f64()
            )));
        }
        Err(e) => return Some(End::Crash(format!("waiting for the child process failed: {e}"))),
    };
    if status.success() {
        if let Ok(text) = std::fs::read_to_string(&r.result) {
            return Some(match serde_json::from_str::<ChildResult>(&text) {
                Ok(c) => End::Result(Box::new(c)),
                Err(e) => End::Crash(format!("the child's result is unreadable: {e}")),
            });
        }
    }
    let how = describe(status);
    let tail = stderr_tail(&r.stderr);
    Some(End::Crash(if tail.is_empty() { format!("driver crash: {how}") } else { format!("driver crash: {how}; last stderr: {tail}") }))
}

fn describe(status: std::process::ExitStatus) -> String {
    #[cfg(unix)]
    let signal = std::os::unix::process::ExitStatusExt::signal(&status);
    #[cfg(not(unix))]
    let signal: Option<i32> = None;
    match signal {
        Some(sig) => {
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
        }
        None => format!("the child process exited with status {} without a result", status.code().unwrap_or(-1)),
    }
}

fn stderr_tail(path: &Path) -> String {
    let text = std::fs::read_to_string(path).unwrap_or_default();
    let lines: Vec<&str> = text.lines().filter(|l| !l.trim().is_empty()).collect();
    lines[lines.len().saturating_sub(3)..].join(" | ")
}

/// The test seam `UMBRAGE_CONFORM_CRASH_CASE=<case>:abort|hang`, honoured in child mode only:
/// a child whose filter selects `<case>` exactly (the `=name` patterns this runner gives its
/// children) aborts (SIGABRT, as a driver assertion would) or sleeps forever (a hung driver)
/// before it draws. `<case>` is a public (`umbrage.…`) or short name.
pub fn injected_case_fault(filter: &[String]) {
    let Ok(v) = std::env::var("UMBRAGE_CONFORM_CRASH_CASE") else { return };
    let Some((name, how)) = v.rsplit_once(':') else { return };
    let hit = filter.iter().filter_map(|p| p.strip_prefix('=')).any(|n| n == name || names::public(n) == name);
    if !hit {
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
