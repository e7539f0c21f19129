//! `umbrage conform`'s dEQP-compatible mode and standalone driver-CI flags, as deqp-runner
//! sees them (docs/conform/driver-ci.md), without deqp-runner (scripts/deqp-ci.sh runs the
//! real one): the stdout protocol, the QPA log, the renderer probe, a crash and a hang pinned
//! on one case, shards, baselines and the CSV files; and that nothing is written into the
//! working directory.

use crate::common;

use std::path::{Path, PathBuf};
use std::process::Command;
use umbrage_conform::deqp::qpa;

fn umbrage(cwd: &Path) -> Command {
    let mut c = Command::new(common::exe::umbrage_exe());
    c.current_dir(cwd)
        .env("UMBRAGE_VALIDATION", "1")
        .env_remove("UMBRAGE_CONFORM_BREAK")
        .env_remove("UMBRAGE_CONFORM_CRASH_CASE")
        .env_remove("UMBRAGE_DEVICE");
    c
}

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("umbrage-deqp-test-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// (name, status word, message) of each `Test case` the stdout reports, in order.
fn statuses(stdout: &str) -> Vec<(String, String)> {
    let mut out = Vec::new();
    let mut current = None;
    for line in stdout.lines() {
        if let Some(n) = line.strip_prefix("Test case '").and_then(|r| r.strip_suffix("'..")) {
            current = Some(n.to_string());
        } else if let (Some(rest), Some(n)) = (line.strip_prefix("  "), current.as_ref()) {
            if let Some((word, msg)) = rest.split_once(" (") {
                assert!(msg.ends_with(')'), "status line without its closing parenthesis: {line}");
                out.push((n.clone(), word.to_string()));
                current = None;
            }
        }
    }
    out
}

/// The first `n` cases of the d32s8 dynamic-rendering static-state stencil family (one child
/// of 64 and one of the rest).
fn some_cases(n: usize) -> Vec<String> {
    umbrage_conform::deqp::list::all_public()
        .into_iter()
        .filter(|c| c.starts_with("umbrage.stencil.d32s8.render_pass.static_state."))
        .take(n)
        .collect()
}

#[test]
fn runs_a_case_list_as_deqp_runner_does() {
    let Some(_ctx) = common::context() else { return };
    let dir = tmp("list");
    let cwd = tmp("list-cwd");
    let cases = some_cases(70);
    std::fs::write(dir.join("c.txt"), cases.join("\n") + "\n").unwrap();
    let out = umbrage(&cwd)
        .args(["conform"])
        .arg(format!("--deqp-caselist-file={}", dir.join("c.txt").display()))
        .arg(format!("--deqp-log-filename={}", dir.join("c.qpa").display()))
        .args(["--deqp-log-flush=disable", "--deqp-shadercache-filename=/nonexistent/x.cache", "--deqp-surface-type=pbuffer"])
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{stdout}\n{}", String::from_utf8_lossy(&out.stderr));
    let got = statuses(&stdout);
    assert_eq!(got.iter().map(|(n, _)| n.clone()).collect::<Vec<_>>(), cases, "one result per listed case, in order");
    assert!(got.iter().all(|(_, s)| s == "Pass" || s == "NotSupported"), "{got:?}");
    let log = std::fs::read_to_string(dir.join("c.qpa")).unwrap();
    let recs = qpa::parse(&log).unwrap();
    assert_eq!(recs.iter().map(|r| r.name.clone()).collect::<Vec<_>>(), cases);
    for r in &recs {
        assert!(r.xml.contains(&format!("CasePath=\"{}\"", r.name)));
        assert!(r.xml.contains("<Result StatusCode=\""));
    }
    assert_eq!(std::fs::read_dir(&cwd).unwrap().count(), 0, "the working directory stays empty");
    let _ = std::fs::remove_dir_all(&dir);
    let _ = std::fs::remove_dir_all(&cwd);
}

#[test]
fn answers_the_renderer_probe() {
    let Some(ctx) = common::context() else { return };
    let dir = tmp("probe");
    let out = umbrage(&dir)
        .args(["conform", "--deqp-case=umbrage.info.renderer,umbrage.info.version,umbrage.info.extensions"])
        .arg(format!("--deqp-log-filename={}", dir.join("i.qpa").display()))
        .output()
        .unwrap();
    assert!(out.status.success());
    let recs = qpa::parse(&std::fs::read_to_string(dir.join("i.qpa")).unwrap()).unwrap();
    assert_eq!(recs.len(), 3);
    assert!(recs[0].xml.contains(&format!("<Text>{}</Text>", qpa::esc(&ctx.info.name))), "{}", recs[0].xml);
    assert!(recs[1].xml.contains("<Text>Vulkan "));
    assert!(recs[2].xml.matches("<Text>VK_").count() > 3, "{}", recs[2].xml);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_crash_and_a_hang_cost_one_case_each() {
    let Some(_ctx) = common::context() else { return };
    let cases = some_cases(20);
    let victim = &cases[4];
    for (how, want) in [("abort", "Crash"), ("hang", "Timeout")] {
        let dir = tmp(how);
        let out = umbrage(&dir)
            .args(["conform", "--timeout", "8", "--chunk", "16"])
            .arg(format!("--deqp-case={}", cases.join(",")))
            .env("UMBRAGE_CONFORM_CRASH_CASE", format!("{victim}:{how}"))
            .output()
            .unwrap();
        assert!(out.status.success());
        let got = statuses(&String::from_utf8_lossy(&out.stdout));
        assert_eq!(got.len(), cases.len());
        for (n, s) in &got {
            if n == victim {
                assert_eq!(s, want, "{how}");
            } else {
                assert!(s == "Pass" || s == "NotSupported", "{how} cost {n} too: {s}");
            }
        }
        assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 0, "the working directory stays empty");
        let _ = std::fs::remove_dir_all(&dir);
    }
}

#[test]
fn shards_baselines_and_csvs() {
    let Some(_ctx) = common::context() else { return };
    let dir = tmp("shards");
    let filter = "stencil.d32s8.render_pass.static_state.compare.*";
    let mut union: Vec<String> = Vec::new();
    for k in 1..=3 {
        let out_dir = dir.join(format!("s{k}"));
        let out = umbrage(&dir)
            .args(["conform", "--filter", filter, "--fraction", "3", "--fraction-start", &k.to_string(), "--out"])
            .arg(&out_dir)
            .output()
            .unwrap();
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stdout));
        let csv = std::fs::read_to_string(out_dir.join("results.csv")).unwrap();
        union.extend(csv.lines().map(|l| l.split(',').next().unwrap().to_string()));
        assert_eq!(std::fs::read_to_string(out_dir.join("failures.csv")).unwrap(), "");
        assert!(out_dir.join("conform.json").exists() && out_dir.join("conform.md").exists());
    }
    let all = String::from_utf8(umbrage(&dir).args(["conform", "--list", "--filter", filter]).output().unwrap().stdout).unwrap();
    let mut all: Vec<String> = all.lines().map(String::from).collect();
    all.sort();
    union.sort();
    assert_eq!(union, all, "the three shards run every case once");

    // A baseline listing a passing case: UnexpectedImprovement, exit 1; a skips file: Skip.
    let first = &all[0];
    std::fs::write(dir.join("base.txt"), format!("{first},Fail\n")).unwrap();
    std::fs::write(dir.join("skips.txt"), format!("# why\n{}\n", all[1])).unwrap();
    let out_dir = dir.join("b");
    let out = umbrage(&dir)
        .args(["conform", "--filter", filter, "--fraction", "1", "--baseline"])
        .arg(dir.join("base.txt"))
        .arg("--skips")
        .arg(dir.join("skips.txt"))
        .arg("--out")
        .arg(&out_dir)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    let failures = std::fs::read_to_string(out_dir.join("failures.csv")).unwrap();
    assert_eq!(failures, format!("{first},UnexpectedImprovement(Pass)\n"));
    let results = std::fs::read_to_string(out_dir.join("results.csv")).unwrap();
    assert!(results.lines().any(|l| l.starts_with(&format!("{},Skip,", all[1]))), "{results}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// Runs `umbrage conform ARGS` in `dir` with two drivers' environments at once (their ICD
/// lists and library paths joined: the loader enumerates both devices, `a`'s first).
fn two_drivers<'a>(
    a: &'a [(String, Option<String>)],
    b: &'a [(String, Option<String>)],
    dir: &'a Path,
) -> impl Fn(&[String]) -> std::process::Output + 'a {
    let get = |env: &[(String, Option<String>)], k: &str| env.iter().find(|(n, _)| n == k).and_then(|(_, v)| v.clone());
    move |args: &[String]| {
        let mut c = umbrage(dir);
        for k in ["VK_ICD_FILENAMES", "VK_DRIVER_FILES", "LD_LIBRARY_PATH"] {
            c.env(k, [get(a, k), get(b, k)].into_iter().flatten().collect::<Vec<_>>().join(":"));
        }
        c.env_remove("VK_ADD_DRIVER_FILES").env_remove("VK_LOADER_DRIVERS_SELECT").env_remove("VK_LOADER_DRIVERS_DISABLE");
        c.arg("conform").args(args).output().unwrap()
    }
}

/// The devices in the loader's order, as `conform --device` lists them when none matches:
/// (name, Vulkan version) each, and the listing (stderr) for messages.
fn listed_devices(run: &impl Fn(&[String]) -> std::process::Output) -> (Vec<(String, String)>, String) {
    let out = run(&["--device".into(), "no-such-device-anywhere".into(), "--filter".into(), "legacy.depth_clamp".into()]);
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    let devices = stderr
        .lines()
        .filter_map(|l| l.strip_prefix("  "))
        .filter_map(|l| l.strip_suffix(')'))
        .filter_map(|l| l.rsplit_once(", Vulkan "))
        .filter_map(|(head, version)| head.rsplit_once(" (").map(|(name, _)| (name.to_string(), version.to_string())))
        .collect();
    (devices, stderr)
}

/// `--deqp-vk-device-id=N` is the N-th device the loader enumerates (1-based, as VK-GL-CTS
/// counts), for the context that answers the probe: with lavapipe 22.3.6 and SwiftShader
/// installed side by side (two devices), each id's renderer is that device's name, in the
/// order `conform --device` lists them; an id past the last is an error naming the count.
#[test]
fn device_id_is_the_nth_device() {
    let Some(_ctx) = common::context() else { return };
    let (Some(lvp), Some(ss)) = (common::driver_env("22.3.6"), common::driver_env("swiftshader")) else {
        assert!(std::env::var_os("CI").is_none(), "CI needs lavapipe 22.3.6 and SwiftShader (scripts/drivers.sh install)");
        eprintln!("SKIPPED: lavapipe 22.3.6 or SwiftShader not installed (scripts/drivers.sh install 22.3.6 swiftshader)");
        return;
    };
    let dir = tmp("device-id");
    let run = two_drivers(&lvp, &ss, &dir);
    let (devices, stderr) = listed_devices(&run);
    let names: Vec<String> = devices.into_iter().map(|(name, _)| name).collect();
    assert_eq!(names.len(), 2, "{names:?} {stderr}");
    assert_ne!(names[0], names[1]);
    for (k, name) in names.iter().enumerate() {
        let log = dir.join(format!("id{}.qpa", k + 1));
        let out = run(&[
            "--deqp-case=umbrage.info.renderer".into(),
            format!("--deqp-vk-device-id={}", k + 1),
            format!("--deqp-log-filename={}", log.display()),
        ]);
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        let recs = qpa::parse(&std::fs::read_to_string(&log).unwrap()).unwrap();
        assert!(recs[0].xml.contains(&format!("<Text>{}</Text>", qpa::esc(name))), "id {}: {}", k + 1, recs[0].xml);
    }
    let out = run(&["--deqp-case=umbrage.info.renderer".into(), "--deqp-vk-device-id=3".into()]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("there are 2 Vulkan devices"), "{}", String::from_utf8_lossy(&out.stderr));
    let _ = std::fs::remove_dir_all(&dir);
}

/// `--deqp-vk-device-id=N` picks by place, not by name: with lavapipe 22.3.6 and 25.0.7
/// installed side by side, the loader enumerates two devices of ONE name (`llvmpipe (LLVM
/// 15.0.6, 256 bits)`), told apart only by their Vulkan and driver versions; id 1 must answer
/// the version probe with the first device's version and id 2 with the second's. Mutation, run
/// once: `set_device_by_id` choosing the N-th device's name (`UMBRAGE_DEVICE=<name>`, the first
/// device of that name) answered both ids with the first device's version and failed here,
/// while `device_id_is_the_nth_device` (two names) still passed.
#[test]
fn device_id_picks_by_place_among_devices_of_one_name() {
    let Some(_ctx) = common::context() else { return };
    let (Some(old), Some(new)) = (common::driver_env("22.3.6"), common::driver_env("25.0.7")) else {
        assert!(std::env::var_os("CI").is_none(), "CI needs lavapipe 22.3.6 and 25.0.7 (scripts/drivers.sh install)");
        eprintln!("SKIPPED: lavapipe 22.3.6 or 25.0.7 not installed (scripts/drivers.sh install 22.3.6 25.0.7)");
        return;
    };
    let dir = tmp("device-id-one-name");
    let run = two_drivers(&old, &new, &dir);
    let (devices, stderr) = listed_devices(&run);
    assert_eq!(devices.len(), 2, "{devices:?} {stderr}");
    assert_eq!(devices[0].0, devices[1].0, "the premise: two devices of one name");
    assert_ne!(devices[0].1, devices[1].1, "told apart by their versions");
    for (k, (_, version)) in devices.iter().enumerate() {
        let log = dir.join(format!("id{}.qpa", k + 1));
        let out = run(&[
            "--deqp-case=umbrage.info.version".into(),
            format!("--deqp-vk-device-id={}", k + 1),
            format!("--deqp-log-filename={}", log.display()),
        ]);
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        let recs = qpa::parse(&std::fs::read_to_string(&log).unwrap()).unwrap();
        assert!(recs[0].xml.contains(&format!("<Text>Vulkan {version} (")), "id {}: want Vulkan {version}: {}", k + 1, recs[0].xml);
    }
    let _ = std::fs::remove_dir_all(&dir);
}
