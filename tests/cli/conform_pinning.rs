//! Crash isolation in plain `umbrage conform` (no dEQP flags), as deqp-runner isolates the CTS:
//! a crash or a hang costs the one case that was running (Crash, Timeout), the rest of its
//! unit runs again in a fresh child, and the timer is per case. The injected faults are the
//! conform harness's child-mode seams (`UMBRAGE_CONFORM_CRASH_CASE=<case>:abort|hang`, and
//! `UMBRAGE_CONFORM_CRASH=<unit>:...` for a driver that fails a whole configuration).

use crate::common;

use std::path::{Path, PathBuf};
use std::process::Command;
use umbrage_conform::suite;

fn umbrage() -> Command {
    let mut c = Command::new(common::exe::umbrage_exe());
    c.env("UMBRAGE_VALIDATION", "1")
        .env_remove("UMBRAGE_CONFORM_BREAK")
        .env_remove("UMBRAGE_CONFORM_CRASH")
        .env_remove("UMBRAGE_CONFORM_CRASH_CASE")
        .env_remove("UMBRAGE_DEVICE");
    c
}

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("umbrage-pinning-test-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

fn json(dir: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(dir.join("conform.json")).unwrap()).unwrap()
}

/// One injected fault in plain `umbrage conform`: exactly the victim is `want` (`crash` or
/// `timeout`), in `conform.json`, the JUnit XML (one `<error>` of that type) and
/// `failures.csv`; every other case of its unit (and of the run) passes or is skipped; the
/// rest of the unit ran again in one child. Returns `conform.json`.
fn one_case_costs(victim: &str, how: &str, want: &str, filter: &str, unit: &dyn Fn(&serde_json::Value) -> bool) -> serde_json::Value {
    let dir = tmp(&format!("one-{how}"));
    let junit = dir.join("junit.xml");
    let out = umbrage()
        .args(["conform", "--timeout", "10", "--filter", filter, "--out"])
        .arg(&dir)
        .arg("--junit")
        .arg(&junit)
        .env("UMBRAGE_CONFORM_CRASH_CASE", format!("{victim}:{how}"))
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(1), "{stdout}");
    let j = json(&dir);
    let cases = j["cases"].as_array().unwrap();
    let selected = suite::all_names().into_iter().filter(|n| filter.split(',').any(|p| suite::matches(p, n))).count();
    assert_eq!(cases.len(), selected, "one result per selected case");
    let mut unit_passed = 0;
    for c in cases {
        if c["name"] == victim {
            assert_eq!(c["status"], want, "{how}: {c}");
        } else {
            assert!(c["status"] == "pass" || c["status"] == "skipped", "{how} cost {} too: {} {}", c["name"], c["status"], c["message"]);
            unit_passed += (unit(c) && c["status"] == "pass") as usize;
        }
    }
    assert!(unit_passed > 0, "{how}: the rest of the victim's unit ran and passed");
    let xml = std::fs::read_to_string(&junit).unwrap();
    assert_eq!(xml.matches("<error ").count(), 1, "{how}");
    assert!(xml.contains(&format!("type=\"{want}\"")), "{how}");
    let csv = std::fs::read_to_string(dir.join("failures.csv")).unwrap();
    let word = if want == "crash" { "Crash" } else { "Timeout" };
    assert_eq!(csv.trim(), format!("umbrage.{victim},{word}"), "{how}");
    // How the unit ran again: the rest of its cases in ONE fresh child, so the run started
    // exactly one child more than the same run without the fault (one a unit). Mutation, run
    // once: a runner that re-runs a crashed or hung child's cases one per child (the pinned
    // branch of `deqp::exec::run` always taking the shared-step fallback) started 66 children
    // for the crash (against 2 without it) and 15 for the hang, and failed here while every
    // assertion above still held.
    let clean = tmp(&format!("clean-{how}"));
    let out = umbrage().args(["conform", "--timeout", "10", "--filter", filter, "--out"]).arg(&clean).output().unwrap();
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stdout));
    let units = json(&clean)["children"].as_u64().unwrap();
    assert!(units >= 2, "{how}: {units} children without the fault");
    assert_eq!(j["children"].as_u64(), Some(units + 1), "{how}: children started with the fault, against {units} without");
    let _ = std::fs::remove_dir_all(&clean);
    let _ = std::fs::remove_dir_all(&dir);
    j
}

/// A crash injected into one case of a configuration's submission, and a hang injected into
/// one single-configuration check: each costs exactly that case (Crash, Timeout), and the rest
/// of its unit passes in a fresh child.
#[test]
fn a_crash_and_a_hang_cost_one_case_each() {
    let Some(_ctx) = common::context() else { return };
    let cfg = "stencil.d32s8.render_pass.static_state.compare.";
    let filter = format!("{cfg},commands.");
    let names: Vec<String> = suite::all_names().into_iter().filter(|n| n.starts_with(cfg)).collect();
    assert!(names.len() > 8, "{}", names.len());
    let in_cfg = |c: &serde_json::Value| c["config"] == "d32s8.render_pass.static_state";
    let j = one_case_costs(&names[4], "abort", "crash", &filter, &in_cfg);
    // The configuration's one submission came from the fresh child, with every case but the
    // victim (the crashed child sent none): not one submission a case.
    let runs: Vec<&serde_json::Value> =
        j["configs"].as_array().unwrap().iter().filter(|c| c["name"] == "d32s8.render_pass.static_state").collect();
    assert_eq!(runs.len(), 1, "{runs:?}");
    let drawn = j["cases"].as_array().unwrap().iter().filter(|c| in_cfg(c) && c["status"] != "skipped").count() as u64;
    assert_eq!(runs[0]["cases"].as_u64(), Some(drawn - 1), "{runs:?}");
    let is_command = |c: &serde_json::Value| c["name"].as_str().is_some_and(|n| n.starts_with("commands."));
    one_case_costs("commands.scissor", "hang", "timeout", &filter, &is_command);
}

/// A driver that aborts (as a driver assertion would) on every case of one configuration
/// (`UMBRAGE_CONFORM_CRASH=<unit>`: each child of the unit aborts at its first case): each of
/// the configuration's cases is pinned in turn, each a JUnit `<error>` naming the signal; the
/// run goes on, the other configurations pass, and the exit status is 1.
#[test]
fn a_crashing_driver_costs_only_its_configuration() {
    let Some(_ctx) = common::context() else { return };
    let dir = tmp("crash");
    let junit = dir.join("junit.xml");
    let crashed_cfg = "d24s8.render_pass.static_state";
    let out = umbrage()
        .args(["conform", "--filter", "zoo.", "--out"])
        .arg(&dir)
        .arg("--junit")
        .arg(&junit)
        .env("UMBRAGE_CONFORM_CRASH", format!("{crashed_cfg}:abort"))
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(1), "{stdout}");
    let j = json(&dir);
    let cases = j["cases"].as_array().unwrap();
    let (mut crashed, mut others) = (0, 0);
    for c in cases {
        let in_cfg = c["config"].as_str() == Some(crashed_cfg);
        if in_cfg && c["status"] != "skipped" {
            assert_eq!(c["status"], "crash", "{}", c["name"]);
            let m = c["message"].as_str().unwrap();
            assert!(m.contains("signal 6 (SIGABRT)") && m.contains(crashed_cfg), "{m}");
            crashed += 1;
        } else {
            assert!(c["status"] == "pass" || c["status"] == "skipped", "{}: {}", c["name"], c["status"]);
            others += (c["status"] == "pass") as usize;
        }
    }
    assert!(crashed > 0 && others > crashed, "{crashed} crashed, {others} passed");
    let xml = std::fs::read_to_string(&junit).unwrap();
    assert_eq!(xml.matches("<error ").count(), crashed);
    assert!(xml.contains(&format!("errors=\"{crashed}\"")));
    assert!(stdout.contains(&format!("{crashed} crashed")), "{stdout}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// The multiview check runs in a unit of its own: a driver crashing there costs that one
/// check, and the other single-configuration checks still report.
#[test]
fn a_multiview_crash_costs_only_the_multiview_check() {
    let Some(_ctx) = common::context() else { return };
    let dir = tmp("crash-multiview");
    let out = umbrage()
        .args(["conform", "--filter", "legacy.", "--out"])
        .arg(&dir)
        .env("UMBRAGE_CONFORM_CRASH", "multiview:abort")
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(1), "{stdout}");
    let j = json(&dir);
    let cases = j["cases"].as_array().unwrap();
    assert_eq!(cases.len(), 10, "{cases:?}");
    for c in cases {
        if c["name"] == "legacy.multiview_cube_faces" {
            assert_eq!(c["status"], "crash");
            let m = c["message"].as_str().unwrap();
            assert!(m.contains("SIGABRT") && m.contains("unit multiview"), "{m}");
        } else {
            assert!(c["status"] == "pass" || c["status"] == "skipped", "{}: {} {}", c["name"], c["status"], c["message"]);
        }
    }
    assert!(cases.iter().filter(|c| c["status"] == "pass").count() >= 6, "{stdout}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// A driver that hangs on every case of a configuration: each case's child is killed at the
/// per-case `--timeout` and that case reported as Timeout; the rest passes.
#[test]
fn a_hanging_driver_is_killed_at_the_timeout() {
    let Some(_ctx) = common::context() else { return };
    let dir = tmp("hang");
    let out = umbrage()
        .args(["conform", "--filter", "zoo.", "--timeout", "3", "--out"])
        .arg(&dir)
        .env("UMBRAGE_CONFORM_CRASH", "s8.render_pass.static_state:hang")
        .output()
        .unwrap();
    // The status the timeout produced, not the wall clock: the hung unit's cases name the
    // timeout that ended them (mutation: a kill that never fires leaves this run hanging and the
    // message absent).
    assert_eq!(out.status.code(), Some(1));
    let j = json(&dir);
    let cases = j["cases"].as_array().unwrap();
    let hung: Vec<_> = cases.iter().filter(|c| c["status"] == "timeout").collect();
    let drawn = cases.iter().filter(|c| c["config"] == "s8.render_pass.static_state" && c["status"] != "skipped").count();
    assert!(!hung.is_empty());
    assert_eq!(hung.len(), drawn, "every drawn case of the hanging configuration, each pinned in turn");
    for c in &hung {
        assert_eq!(c["config"], "s8.render_pass.static_state");
        assert!(c["message"].as_str().unwrap().contains("no result within 3 s"), "{}", c["message"]);
    }
    assert!(cases
        .iter()
        .filter(|c| c["config"] != "s8.render_pass.static_state")
        .all(|c| c["status"] == "pass" || c["status"] == "skipped"));
    let _ = std::fs::remove_dir_all(&dir);
}
