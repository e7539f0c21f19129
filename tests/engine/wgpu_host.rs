//! The wgpu host example (`examples/wgpu_host`: wgpu's Vulkan backend as the engine, umbrage's
//! `ShadowPass` recorded between its passes through wgpu's raw handles), run as a program with
//! the validation layer on: it must exit 0 (any validation error makes it fail), and its frame
//! dump must match the exact CPU reference with no mismatch outside the 1-pixel band, on the
//! default scene and on two more.
//!
//! Without a Vulkan device the test is skipped loudly, except under CI (`CI` set), where that is
//! a failure.

use crate::common;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The example's binary, built first (a no-op when it is fresh) with this test's profile. It
/// lies in `examples/` beside the `deps/` folder holding this test's binary.
fn example() -> PathBuf {
    let mut build = Command::new(env!("CARGO"));
    build.args(["build", "--example", "wgpu_host"]).current_dir(env!("CARGO_MANIFEST_DIR"));
    if !cfg!(debug_assertions) {
        build.arg("--release");
    }
    let status = build.status().expect("cargo runs");
    assert!(status.success(), "cargo build --example wgpu_host failed");
    let exe = std::env::current_exe().expect("the test's own path");
    let dir = exe.parent().and_then(Path::parent).expect("target/<profile>/deps");
    let bin = dir.join("examples").join(format!("wgpu_host{}", std::env::consts::EXE_SUFFIX));
    assert!(bin.is_file(), "{} was not built", bin.display());
    bin
}

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("umbrage-wgpu-host-{}-{}", std::process::id(), name.replace('/', "_")));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn no_device(out: &Output) -> bool {
    let err = String::from_utf8_lossy(&out.stderr);
    err.contains("no Vulkan adapter") || err.contains("no Vulkan loader")
}

/// Runs the example on `scene` for `frames` frames with validation on and checks its dump
/// against the reference. Returns the dump's shadow masks, or None when there is no Vulkan
/// device (and `CI` is not set).
fn run_and_check(bin: &Path, scene: &str, size: &str, frames: usize) -> Option<Vec<Vec<u8>>> {
    run_and_check_on(bin, scene, size, frames, &[], None)
}

/// [`run_and_check`] with a driver's environment (`common::driver_env`) applied, and the
/// device's name expected to contain `device`.
fn run_and_check_on(
    bin: &Path,
    scene: &str,
    size: &str,
    frames: usize,
    driver: &[(String, Option<String>)],
    device: Option<&str>,
) -> Option<Vec<Vec<u8>>> {
    let dir = tmp(&format!("{scene}-{frames}-{}", driver.len()));
    let png = dir.join("out.png");
    let dump = dir.join("dump");
    let mut c = Command::new(bin);
    c.args(["--scene", scene, "--size", size, "--frames", &frames.to_string(), "--out"])
        .arg(&png)
        .arg("--dump")
        .arg(&dump)
        .env("UMBRAGE_VALIDATION", "1");
    common::apply_driver_env(&mut c, driver);
    let out = c.output().expect("the example runs");
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    eprintln!("--- {scene}: stdout\n{stdout}--- stderr\n{stderr}");
    if !out.status.success() && no_device(&out) {
        if std::env::var_os("CI").is_some() {
            panic!("no Vulkan device under CI: {stderr}");
        }
        eprintln!("SKIPPED (no Vulkan device, CI not set)");
        return None;
    }
    assert!(out.status.success(), "{scene}: the example failed ({}):\n{stderr}", out.status);
    if let Some(device) = device {
        assert!(stderr.contains(device) || stdout.contains(device), "{scene}: not on {device}");
    }
    assert!(!stderr.contains("[ERROR"), "{scene}: errors were logged:\n{stderr}");
    assert!(png.is_file(), "{scene}: no PNG");
    // Every frame reported, two in flight.
    for f in 0..frames {
        assert!(stdout.contains(&format!("frame {f} (slot {})", f % 2)), "{scene}: frame {f} not reported:\n{stdout}");
    }
    let report = umbrage_reference::check_dump(&dump, 1).unwrap_or_else(|e| panic!("{scene}: check: {e}"));
    eprintln!("{report}");
    assert!(!report.lights.is_empty(), "{scene}: no light checked");
    for l in &report.lights {
        assert!(l.metrics.compared > 1000, "{scene}: light {}: only {} pixels compared", l.index, l.metrics.compared);
        assert_eq!(l.metrics.mismatches_outside_band, 0, "{scene}: light {}: mismatches outside the band", l.index);
    }
    let masks = umbrage_reference::read_dump(&dump).expect("the dump reads back").shadow;
    let _ = std::fs::remove_dir_all(&dir);
    Some(masks)
}

#[test]
fn wgpu_host_matches_reference_with_validation() {
    let bin = example();
    // The default scene (point, spot and directional lights, seven casters), the eye inside a
    // shadow volume (z-fail), and huge volumes over the whole screen (fill); three frames, two
    // in flight, the last caster 0.5 units from where the scene puts it in the last one.
    let mut moved = None;
    for scene in ["default", "hard/eye_in_volume", "bench/fill"] {
        let Some(masks) = run_and_check(&bin, scene, "320x200", 3) else { return };
        moved.get_or_insert(masks);
    }
    // One frame: the scene as loaded. The moved caster's shadow differs (the dump follows the
    // caster, and the pass drew it where the frame put it).
    let Some(still) = run_and_check(&bin, "default", "320x200", 1) else { return };
    let moved = moved.expect("the default scene ran");
    let differ: usize = still.iter().zip(&moved).map(|(a, b)| a.iter().zip(b).filter(|(x, y)| x != y).count()).sum();
    assert!(differ > 100, "the moving caster changed only {differ} mask pixels");
}

/// The same host on SwiftShader (wgpu picks its only adapter; its `Depth24PlusStencil8` is
/// D32S8 there): exact on the default scene and with the eye inside a volume.
#[test]
fn wgpu_host_matches_reference_on_swiftshader() {
    let Some(driver) = common::driver_env("swiftshader") else {
        let why = "SwiftShader is not installed (scripts/drivers.sh install swiftshader)";
        assert!(std::env::var_os("CI").is_none(), "{why}");
        eprintln!("SKIPPED: {why}");
        return;
    };
    let bin = example();
    for scene in ["default", "hard/eye_in_volume"] {
        run_and_check_on(&bin, scene, "320x200", 3, &driver, Some("SwiftShader")).expect("SwiftShader is a Vulkan device");
    }
}
