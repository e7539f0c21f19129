//! A child's progress, as the parent watches it ([`super::deqp::exec`]): the child appends a line
//! to the file the parent names (`--child-progress FILE`) as it reaches each case and each
//! shared step, so that
//!
//! - the parent's timer restarts at each line (a per-case timer, as deqp-runner's restarts at
//!   each test), and a hang is reported as a Timeout of the one case that was running;
//! - a crash is pinned on the case that was running (the last line is `case NAME`), and the
//!   rest of the child's cases run again in a fresh child. A crash in a shared step (a
//!   configuration's one submission: the last line is `step ...`) pins nothing, and the
//!   parent runs each of the child's cases in a child of its own.
//!
//! The lines: `case <short name>` when a case starts (a single-configuration check before it
//! runs; a configuration case when its draws are recorded, pipelines included), `step <what>`
//! when a step shared by the cases begins or a case ended (`step end`).
//!
//! The test seams live here, read in child mode only (nothing is watched otherwise), never by
//! the engine:
//! - `UMBRAGE_CONFORM_CRASH_CASE=<case>:abort|hang`: the child aborts (SIGABRT, as a driver
//!   assertion would) or sleeps forever (a hung driver) when it reaches `<case>` (a short or
//!   public name);
//! - `UMBRAGE_CONFORM_CRASH=<unit>:abort|hang`: every child of unit `<unit>` (a configuration's
//!   name, `legacy`, `multiview`, `mesh`, `pipeline`) does so at the first case it reaches: a
//!   driver that fails the whole configuration, so that each of its cases is pinned in turn.

use std::io::Write as _;
use std::path::Path;
use std::sync::Mutex;
use std::time::Duration;

struct Sink {
    file: std::fs::File,
    unit: String,
    cases: usize,
}

static SINK: Mutex<Option<Sink>> = Mutex::new(None);

/// Child mode: opens `path` for the progress of a child running `unit` (its
/// [`super::units::Unit::name`]).
pub(crate) fn open(path: &Path, unit: &str) -> umbrage::error::Result<()> {
    let file = std::fs::File::create(path).map_err(|e| umbrage::error::Error::io(path.display().to_string(), e))?;
    *SINK.lock().unwrap_or_else(|e| e.into_inner()) = Some(Sink { file, unit: unit.to_string(), cases: 0 });
    Ok(())
}

fn line(s: &str) {
    let mut g = SINK.lock().unwrap_or_else(|e| e.into_inner());
    if let Some(sink) = g.as_mut() {
        // Unbuffered: the line is in the file before the case's first driver call.
        let _ = writeln!(sink.file, "{s}");
    }
}

/// Case `name` (short name) starts: the marker, then the injected faults that name it.
pub(crate) fn case(name: &str) {
    let first = {
        let mut g = SINK.lock().unwrap_or_else(|e| e.into_inner());
        let Some(sink) = g.as_mut() else { return };
        let _ = writeln!(sink.file, "case {name}");
        sink.cases += 1;
        (sink.cases == 1).then(|| sink.unit.clone())
    };
    if let Ok(v) = std::env::var("UMBRAGE_CONFORM_CRASH_CASE") {
        if let Some((victim, how)) = v.rsplit_once(':') {
            if victim == name || super::deqp::names::public(name) == victim {
                fault(how);
            }
        }
    }
    if let (Some(unit), Ok(v)) = (first, std::env::var("UMBRAGE_CONFORM_CRASH")) {
        if let Some((u, how)) = v.rsplit_once(':') {
            if u == unit || (u == "pipeline" && unit.starts_with("pipeline")) {
                fault(how);
            }
        }
    }
}

/// A step shared by the cases begins (`what`: `submit`), or the running case ended (`end`).
pub(crate) fn step(what: &str) {
    line(&format!("step {what}"));
}

fn fault(how: &str) {
    match how {
        "abort" => std::process::abort(),
        "hang" => loop {
            std::thread::sleep(Duration::from_secs(3600));
        },
        _ => {}
    }
}

/// The case that was running when the child writing `text` stopped: the last line's, when it
/// is a `case` line.
pub fn running(text: &str) -> Option<String> {
    text.lines().rev().find(|l| !l.trim().is_empty())?.strip_prefix("case ").map(|s| s.trim().to_string())
}

#[cfg(test)]
mod tests {
    #[test]
    fn the_running_case_is_the_last_case_line() {
        assert_eq!(super::running("case a\nstep end\ncase b\n").as_deref(), Some("b"));
        assert_eq!(super::running("case a\nstep submit\n"), None);
        assert_eq!(super::running(""), None);
    }
}
