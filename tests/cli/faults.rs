//! Injected device faults (issue 13): a memory budget that makes allocations fail at every
//! point of a renderer's life, and `VK_ERROR_DEVICE_LOST` / out-of-memory from queue
//! submission. Each must give a clear error and a non-zero exit, never a panic or a hang, and
//! leave nothing behind: with validation on, an object not destroyed is reported at
//! `vkDestroyDevice`, which these tests see on stderr. And the soak: memory held flat over
//! many frames in one process.

use crate::common;

use std::process::{Command, Output};

fn umbrage(args: &[&str], env: &[(&str, &str)]) -> Output {
    umbrage_on(args, env, &[])
}

/// A driver's environment: each variable set (`Some`) or removed (`None`).
type DriverEnv = Vec<(String, Option<String>)>;

/// [`umbrage`] with a driver's environment (`common::lavapipe_25_env`) applied first.
fn umbrage_on(args: &[&str], env: &[(&str, &str)], driver: &[(String, Option<String>)]) -> Output {
    let mut c = Command::new(common::exe::umbrage_exe());
    c.args(args).env("UMBRAGE_VALIDATION", "1").env_remove("UMBRAGE_FAULT").env_remove("UMBRAGE_MEMORY_BUDGET");
    common::apply_driver_env(&mut c, driver);
    for (k, v) in env {
        c.env(k, v);
    }
    c.output().unwrap()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// Nothing panicked and validation (on in every run) reported nothing, teardown included.
fn clean(o: &Output, what: &str) {
    let err = stderr(o);
    assert!(!err.contains("panicked"), "{what}: panicked: {err}");
    assert!(!err.contains("[vulkan validation]"), "{what}: validation reported: {err}");
}

fn out_png(tag: &str) -> String {
    std::env::temp_dir().join(format!("umbrage-faults-{}-{tag}.png", std::process::id())).display().to_string()
}

/// The numbers in "S bytes requested, U bytes in use" of a budget error.
fn requested_and_used(err: &str) -> (u64, u64) {
    let num_before = |tag: &str| -> u64 {
        let head = &err[..err.find(tag).unwrap_or_else(|| panic!("no '{tag}' in {err}"))];
        head.trim_end().rsplit(' ').next().unwrap().parse().unwrap()
    };
    (num_before(" bytes requested"), num_before(" bytes in use"))
}

/// Walks the budget up from far too small: the first is refused up front with the scene's
/// sizes; then each run's budget is exactly what the failing allocation needed (in use +
/// requested), so the next run gets past it and fails at the next one, until the render
/// succeeds. Every failure is clean (what was made is released again).
#[test]
fn memory_budget_failures_are_clean_at_every_point() {
    let png = out_png("budget");
    let (mut upfront, mut partway) = (0, 0);
    let mut budget = 64u64 << 10;
    loop {
        let b = budget.to_string();
        let o = umbrage(&["render", "--size", "160x120", "--out", &png], &[("UMBRAGE_MEMORY_BUDGET", &b)]);
        let what = format!("budget {b}");
        clean(&o, &what);
        if o.status.success() {
            break;
        }
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(1), "{what}: {err}");
        assert!(err.contains("out of GPU memory") && err.contains(&format!("limit {b} bytes")), "{what}: {err}");
        let (requested, used) = requested_and_used(&err);
        if err.contains("targets") && err.contains("scene geometry") {
            upfront += 1;
        } else {
            partway += 1;
        }
        let next = used + requested;
        assert!(next > budget, "{what}: the walk moves on ({err})");
        budget = next;
        assert!(partway < 500, "the walk ends");
    }
    assert_eq!(upfront, 1, "the first budget is refused up front");
    assert!(partway >= 1, "budgets past the up-front estimate fail part-way ({partway} did)");
    eprintln!("{partway} allocation points failed cleanly; rendered with a budget of {budget} bytes");
}

/// Every allocation a render makes fails in turn (`UMBRAGE_FAULT=alloc=...@n` for n = 1, 2,
/// ... until the render succeeds): each a clear error naming the allocation, everything made
/// before it released again. Also through a frame dump (captures) and the shadow-map baseline.
#[test]
fn every_allocation_failure_is_clean() {
    // Ray query (its acceleration structures, inputs, scratch and batched masks) on lavapipe
    // 25.0.7, where the system's driver has none.
    let lavapipe_25 = common::lavapipe_25_env();
    assert!(lavapipe_25.is_some() || std::env::var_os("CI").is_none(), "CI needs lavapipe 25.0.7 (scripts/drivers.sh install 25.0.7)");
    let rays = ["--method", "rayquery", "--scene", "analytic/sphere_and_meshes"];
    let mut runs: Vec<(&str, &[&str], DriverEnv)> =
        vec![("render", &[][..], Vec::new()), ("shadowmap", &["--method", "shadowmap", "--shadow-map-size", "128"][..], Vec::new())];
    if let Some(env) = lavapipe_25 {
        runs.push(("rayquery", &rays[..], env));
    }
    for (tag, extra, driver) in runs {
        let png = out_png(tag);
        let mut args = vec!["render", "--size", "96x72", "--out", &png];
        args.extend_from_slice(extra);
        let mut n = 1;
        loop {
            let spec = format!("alloc=out_of_device_memory@{n}");
            let o = umbrage_on(&args, &[("UMBRAGE_FAULT", &spec)], &driver);
            let what = format!("{tag} {spec}");
            clean(&o, &what);
            if o.status.success() {
                break;
            }
            let err = stderr(&o);
            assert_eq!(o.status.code(), Some(1), "{what}: {err}");
            assert!(err.contains("error: allocating ") && err.contains("Out of memory"), "{what}: {err}");
            n += 1;
            assert!(n < 400, "the walk ends");
        }
        assert!(n > 20, "{tag}: a render makes more than 20 allocations ({n})");
        eprintln!("{tag}: {} allocation points failed cleanly", n - 1);
    }
}

/// A scene bigger than the budget is refused before anything is allocated.
#[test]
fn a_scene_that_cannot_fit_is_refused_up_front() {
    let o = umbrage(&["render", "--size", "4096x4096", "--out", &out_png("big")], &[("UMBRAGE_MEMORY_BUDGET", "64M")]);
    clean(&o, "4096x4096 in 64 MiB");
    let err = stderr(&o);
    assert!(!o.status.success());
    assert!(err.contains("scene 'default' at 4096x4096") && err.contains("targets 1073741824 bytes"), "{err}");
    assert!(err.contains("limit 67108864 bytes"), "{err}");
}

/// The device lost (or out of memory) at the upload's submit and at the frame's: a clear
/// error, exit 1, everything destroyed.
#[test]
fn injected_submit_faults_are_clean() {
    let png = out_png("submit");
    for (spec, needle) in [
        ("submit=device_lost@1", "ERROR_DEVICE_LOST"),
        ("submit=device_lost@2", "ERROR_DEVICE_LOST"),
        ("submit=out_of_device_memory@2", "ERROR_OUT_OF_DEVICE_MEMORY"),
        ("submit=out_of_host_memory@1", "ERROR_OUT_OF_HOST_MEMORY"),
    ] {
        let o = umbrage(&["render", "--size", "96x72", "--out", &png], &[("UMBRAGE_FAULT", spec)]);
        clean(&o, spec);
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(1), "{spec}: {err}");
        assert!(err.contains("vkQueueSubmit") && err.contains(needle), "{spec}: {err}");
    }
    // A fault later than the run's last submit changes nothing.
    let o = umbrage(&["render", "--size", "96x72", "--out", &png], &[("UMBRAGE_FAULT", "submit=device_lost@100")]);
    clean(&o, "late fault");
    assert!(o.status.success(), "{}", stderr(&o));
}

/// The device lost in the middle of a run of frames in flight (bench's throughput).
#[test]
fn device_lost_mid_run_is_clean() {
    let o = umbrage(
        &["bench", "--scene", "default", "--methods", "mcguire", "--frames", "3", "--size", "96x72"],
        &[("UMBRAGE_FAULT", "submit=device_lost@7")],
    );
    clean(&o, "bench");
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("ERROR_DEVICE_LOST"), "{err}");
}

/// A short soak: lights orbit, casters spin, memory flat after one period, no validation
/// error, the last frame equal to a fresh render of the same state.
#[test]
fn short_soak_holds_memory_flat() {
    let json = std::env::temp_dir().join(format!("umbrage-soak-{}.json", std::process::id()));
    let o = umbrage(&["bench", "--soak", "240", "--soak-period", "60", "--size", "96x72", "--json", json.to_str().unwrap()], &[]);
    clean(&o, "soak");
    assert!(o.status.success(), "{}\n{}", String::from_utf8_lossy(&o.stdout), stderr(&o));
    let v: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert_eq!(v["frames"], 240);
    assert_eq!(v["passed"], true);
    assert_eq!(v["validation_errors"], 0);
    assert_eq!(v["validation"], true);
    assert_eq!(v["final_mask_mismatches"], 0);
    assert!(v["samples"].as_array().unwrap().len() >= 100);
    assert_eq!(v["gpu_spread"], 0.0, "GPU allocations do not move after warm-up");
}
