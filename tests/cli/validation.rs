//! The validation modes of `UMBRAGE_VALIDATION` beyond the default (API + synchronisation,
//! on in every other GPU test): GPU-assisted validation (instrumented shaders: out-of-bounds
//! buffer, descriptor and indirect-argument accesses) over every technique, including the
//! indirect and edge-quad paths, with zero errors; best practices with zero warnings beyond
//! the allowlist (`umbrage::gpu::validation::ALLOWED_WARNINGS`). Each run must report the mode
//! it ran.

use crate::common;
use std::process::Command;

fn run(mode: &str, method: &str) -> (bool, String) {
    let png = std::env::temp_dir().join(format!("umbrage-validation-{}-{method}.png", std::process::id()));
    let o = Command::new(common::exe::umbrage_exe())
        .args(["render", "--scene", "default", "--size", "96x72", "--method", method, "--out", png.to_str().unwrap()])
        .env("UMBRAGE_VALIDATION", mode)
        .output()
        .unwrap();
    (o.status.success(), String::from_utf8_lossy(&o.stderr).into_owned())
}

#[test]
fn gpu_assisted_validation_is_clean_for_every_technique() {
    let methods = ["auto", "zpass", "everitt-kilgard", "compute", "edgequad", "planar", "shadowmap"];
    for m in methods {
        let (ok, err) = run("gpu", m);
        assert!(ok, "{m}: {err}");
        // The mode really engaged (a layer without GPU-assisted validation would run clean).
        assert!(err.contains("umbrage: validation on (gpu)"), "{m}: the run does not report GPU-assisted validation: {err}");
        assert!(!err.contains("[vulkan validation]") && !err.contains("panicked"), "{m}: {err}");
    }
}

#[test]
fn best_practices_warnings_are_only_the_allowed_ones() {
    let (ok, err) = run("best", "auto");
    assert!(ok, "{err}");
    assert!(err.contains("umbrage: validation on (best)"), "the run does not report best practices: {err}");
    assert!(!err.contains("[vulkan validation]"), "{err}");
}
