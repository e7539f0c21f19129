//! The runner behind the dEQP-compatible mode and the standalone driver-CI flags: the selected
//! cases of every unit ([`Unit`]: a configuration's submission, the legacy checks, ...) run in
//! child processes of at most [`Exec::chunk`] cases each, and a child that crashes or hangs
//! has its cases run again one per child, so that the crash ([`Code::Crash`]) or the hang
//! ([`Code::Timeout`]) is reported for the case that caused it alone and the others keep the
//! results they really have.
//!
//! Each child reports its progress ([`crate::progress`]): the timer restarts at each case a
//! child reaches (a per-case timer, as deqp-runner's), and a crash or hang with a case running
//! is pinned on that case at once, the child's other cases running again in one fresh child.
//! A crash in a step the cases share (a configuration's one submission) pins nothing: the
//! child's cases then run one per child.
//!
//! The test seam `UMBRAGE_CONFORM_CRASH_CASE=<case>:abort|hang` (read by the conform harness's
//! child mode only, never by the engine) makes a child abort or hang when it reaches `<case>`
//! (public or short name); see [`crate::progress`].

use super::super::cases::{Config, FORMATS};
use super::super::suite::{self, CaseOutcome, ConfigRun, SuiteOptions};
use super::super::units::Unit;
use super::super::CheckResult;
use super::super::Status;
use super::names;
use std::collections::{HashMap, HashSet, VecDeque};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};
use umbrage::error::{Error, Result};
use umbrage::gpu::Context;

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
    /// The child process running the case made no progress within the per-case timer.
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

    /// The status of `conform.json`.
    pub fn status(self) -> Status {
        match self {
            Code::Pass => Status::Pass,
            Code::Fail => Status::Fail,
            Code::NotSupported => Status::Skipped,
            Code::Crash => Status::Crash,
            Code::Timeout => Status::Timeout,
        }
    }

    /// The code of a `conform.json` status.
    pub fn of(status: Status) -> Code {
        match status {
            Status::Pass => Code::Pass,
            Status::Fail => Code::Fail,
            Status::Skipped => Code::NotSupported,
            Status::Crash => Code::Crash,
            Status::Timeout => Code::Timeout,
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
    /// The child processes started (those that re-ran the cases of a crashed or hung one
    /// included).
    pub children: usize,
}

/// How the runner starts its children.
#[derive(Clone, Debug)]
pub struct Exec {
    /// The `umbrage` executable.
    pub exe: PathBuf,
    /// The per-case timer: a child that reports no progress ([`crate::progress`]: a case
    /// reached, a shared step begun) for this long is killed, and the case it was running is
    /// reported as [`Code::Timeout`].
    pub timeout: Duration,
    /// Children at once.
    pub jobs: usize,
    /// Where children write their results (created if missing).
    pub scratch: PathBuf,
    /// Where children write their failure images (`failures/<case>/`).
    pub images: PathBuf,
    /// The most cases of a configuration one child draws.
    pub chunk: usize,
    /// The most cases of a single-configuration unit (legacy, multiview, mesh, pipeline) one
    /// child runs.
    pub unit_chunk: usize,
    /// Children the pipeline unit's cases are shared among (at least 1; each still at most
    /// [`Exec::unit_chunk`] cases).
    pub pipeline_children: usize,
}

impl Exec {
    /// How the dEQP-compatible and the driver-CI modes split the cases: at most `chunk` of a
    /// configuration, an eighth of that of the other units, per child.
    pub fn chunked(exe: PathBuf, timeout: Duration, jobs: usize, scratch: PathBuf, images: PathBuf, chunk: usize) -> Exec {
        let chunk = chunk.max(1);
        Exec { exe, timeout, jobs, scratch, images, chunk, unit_chunk: (chunk / 8).max(1), pipeline_children: 1 }
    }
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
    progress: PathBuf,
    /// The progress file's length when last looked at, and when it last grew.
    seen: u64,
    last: Instant,
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
    // The parent's plan of each configuration case (its configuration, description, bug).
    let mut planned: HashMap<String, CaseOutcome> = HashMap::new();
    let mut queue = plan(ctx, selected, ex, opts, &mut planned, done);
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
                Ok(r) => {
                    extras.children += 1;
                    running.push(r);
                }
                Err((job, e)) => {
                    for n in &job.names {
                        done(lost(n, job.unit, Code::Crash, &format!("the child process could not be started: {e}"), &planned));
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
            let progress = std::fs::read_to_string(&r.progress).unwrap_or_default();
            for f in [&r.result, &r.stderr, &r.progress] {
                let _ = std::fs::remove_file(f);
            }
            let code = if matches!(end, End::Timeout(_)) { Code::Timeout } else { Code::Crash };
            match end {
                End::Result(res) => {
                    extras.configs.extend(res.config);
                    extras.legacy.extend(res.legacy);
                    let mut by_name: HashMap<String, CaseOutcome> = res.cases.into_iter().map(|c| (c.name.clone(), c)).collect();
                    for n in &r.job.names {
                        match by_name.remove(n) {
                            Some(mut o) => {
                                if let Some(p) = planned.get(n) {
                                    o.bug.clone_from(&p.bug);
                                }
                                let code = Code::of(o.status);
                                done(finish(o, code));
                            }
                            None => done(lost(n, r.job.unit, Code::Fail, "the child process returned no result for this case", &planned)),
                        }
                    }
                }
                End::Crash(msg) | End::Timeout(msg) if r.job.names.len() > 1 => {
                    let unit = r.job.unit;
                    match crate::progress::running(&progress).filter(|c| r.job.names.contains(c)) {
                        // Pinned: the running case alone; the rest again, in one fresh child.
                        Some(case) => {
                            eprintln!("umbrage conform: {msg} (unit {}, running {case}): the other cases run again", unit.name());
                            done(lost(&case, unit, code, &msg, &planned));
                            let rest: Vec<String> = r.job.names.into_iter().filter(|n| *n != case).collect();
                            let retry = rest.len() == 1;
                            queue.push_front(Job { unit, names: rest, retry });
                        }
                        // In a step the cases share: every case again, one per child.
                        None => {
                            eprintln!(
                                "umbrage conform: {msg} (unit {}, {} cases, in a shared step): running them one per child",
                                unit.name(),
                                r.job.names.len()
                            );
                            for n in r.job.names.iter().rev() {
                                queue.push_front(Job { unit, names: vec![n.clone()], retry: true });
                            }
                        }
                    }
                }
                End::Crash(msg) | End::Timeout(msg) => done(lost(&r.job.names[0], r.job.unit, code, &msg, &planned)),
            }
        }
        if !running.is_empty() {
            std::thread::sleep(Duration::from_millis(5));
        }
    }
    Ok(extras)
}

/// The jobs of `selected`: each configuration's cases to draw in children of at most
/// [`Exec::chunk`] (those its device skips reported through `done` at once, their plans into
/// `planned`), then the single-configuration units'.
fn plan(
    ctx: &Context,
    selected: &[String],
    ex: &Exec,
    opts: &SuiteOptions,
    planned: &mut HashMap<String, CaseOutcome>,
    done: &mut dyn FnMut(Done),
) -> VecDeque<Job> {
    let wanted: HashSet<&str> = selected.iter().map(String::as_str).collect();
    let mut queue: VecDeque<Job> = VecDeque::new();
    let support = suite::format_support(ctx);
    for cfg in Config::all(&FORMATS) {
        let names: Vec<String> =
            super::super::cases::all(&[cfg]).into_iter().map(|c| c.name).filter(|n| wanted.contains(n.as_str())).collect();
        if names.is_empty() {
            continue;
        }
        let format_ok = support.iter().any(|(f, s)| *f == cfg.format && s.usable);
        let o = SuiteOptions { filter: exact(&names), ..opts.clone() };
        let (outcomes, run) = suite::plan_config(ctx, cfg, format_ok, &o);
        for out in outcomes {
            match out.status {
                Status::Skipped => done(finish(out, Code::NotSupported)),
                _ => {
                    planned.insert(out.name.clone(), out);
                }
            }
        }
        let to_run: Vec<String> = run.into_iter().map(|c| c.name).collect();
        for part in to_run.chunks(ex.chunk.max(1)) {
            queue.push_back(Job { unit: Unit::Config(cfg), names: part.to_vec(), retry: false });
        }
    }
    for unit in [Unit::Legacy, Unit::Multiview, Unit::Mesh, Unit::Pipeline { shard: 0, shards: 1 }] {
        let names: Vec<String> = suite::unit_case_names(unit, &[]).into_iter().filter(|n| wanted.contains(n.as_str())).collect();
        let mut size = ex.unit_chunk.max(1);
        if matches!(unit, Unit::Pipeline { .. }) {
            size = size.min(names.len().div_ceil(ex.pipeline_children.max(1)).max(1));
        }
        for part in names.chunks(size) {
            queue.push_back(Job { unit, names: part.to_vec(), retry: false });
        }
    }
    queue
}

/// Filter patterns that select exactly `names` (see [`suite::matches`]'s `=` form).
pub fn exact(names: &[String]) -> Vec<String> {
    names.iter().map(|n| format!("={n}")).collect()
}

fn finish(outcome: CaseOutcome, code: Code) -> Done {
    Done { public: names::public(&outcome.name), code, outcome }
}

/// A case the child running it took down (or never returned): its plan when the parent has
/// one, the message naming the unit.
fn lost(name: &str, unit: Unit, code: Code, msg: &str, planned: &HashMap<String, CaseOutcome>) -> Done {
    let mut o = planned.get(name).cloned().unwrap_or_else(|| {
        let group = name.split('.').next().unwrap_or("");
        CaseOutcome::new(name.to_string(), group, None, String::new())
    });
    o.status = code.status();
    o.message = format!("{msg} (unit {})", unit.name());
    finish(o, code)
}

fn spawn(ex: &Exec, job: Job, serial: usize) -> std::result::Result<Running, (Job, std::io::Error)> {
    let result = ex.scratch.join(format!("child-{serial}.json"));
    let stderr = ex.scratch.join(format!("child-{serial}.stderr"));
    let progress = ex.scratch.join(format!("child-{serial}.progress"));
    let _ = std::fs::remove_file(&result);
    let _ = std::fs::remove_file(&progress);
    let file = match std::fs::File::create(&stderr) {
        Ok(f) => f,
        Err(e) => return Err((job, e)),
    };
    let mut cmd = Command::new(&ex.exe);
    cmd.args(["conform", "--child", &job.unit.name(), "--child-result"])
        .arg(&result)
        .arg("--child-progress")
        .arg(&progress)
        .arg("--out")
        .arg(&ex.images)
        .arg("--filter")
        .arg(exact(&job.names).join(","))
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(file);
    match cmd.spawn() {
        Ok(child) => Ok(Running { job, child, result, stderr, progress, seen: 0, last: Instant::now() }),
        Err(e) => Err((job, e)),
    }
}

/// `Some` once the child has ended, or was killed for making no progress within `timeout`
/// (the timer restarts whenever its progress file grows).
fn poll(r: &mut Running, timeout: Duration) -> Option<End> {
    let len = std::fs::metadata(&r.progress).map(|m| m.len()).unwrap_or(0);
    if len != r.seen {
        (r.seen, r.last) = (len, Instant::now());
    }
    let status = match r.child.try_wait() {
        Ok(Some(s)) => s,
        Ok(None) if r.last.elapsed() < timeout => return None,
        Ok(None) => {
            let _ = r.child.kill();
            let _ = r.child.wait();
            return Some(End::Timeout(format!(
                "driver hang: no result within {} s (the per-case timer), the child process was killed",
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
