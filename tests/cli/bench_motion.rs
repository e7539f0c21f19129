//! `umbrage bench --motion` (issue 55): a scene's motion run over the frames, and the rows'
//! frame-cost keys (the CPU split, the bytes sent, the pairs kept and replanned), with plans
//! kept across frames and without (`--no-keep`), on the built-in `bench/level`.

use crate::common;
use std::process::Command;

/// The row of `umbrage bench --scene bench/level --methods mcguire --frames 1` with `flags`.
fn level_row(name: &str, flags: &[&str]) -> serde_json::Value {
    let dir = std::env::temp_dir().join(format!("umbrage-bench-motion-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let json = dir.join("bench.json");
    let mut args = vec!["bench", "--scene", "bench/level", "--methods", "mcguire", "--frames", "1", "--size", "96x54"];
    args.extend(flags);
    args.extend(["--json", json.to_str().unwrap()]);
    let out = Command::new(common::exe::umbrage_exe()).args(&args).env("UMBRAGE_VALIDATION", "1").output().unwrap();
    assert!(out.status.success(), "{args:?}: {}", String::from_utf8_lossy(&out.stderr));
    let v: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let _ = std::fs::remove_dir_all(&dir);
    let rows = v["rows"].as_array().unwrap();
    assert_eq!(rows.len(), 1, "{v}");
    rows[0].clone()
}

fn u(r: &serde_json::Value, k: &str) -> u64 {
    r[k].as_u64().unwrap_or_else(|| panic!("{k} is not a count: {r}"))
}

fn f(r: &serde_json::Value, k: &str) -> f64 {
    r[k].as_f64().unwrap_or_else(|| panic!("{k} is not a number: {r}"))
}

#[test]
fn motion_rows_carry_the_frame_cost_of_what_moved() {
    // One measured frame (t = 1/30 s after the warm-up at 0): the medians are that frame's.
    let kept = level_row("kept", &["--motion"]);
    assert_eq!(kept["motion"], true, "{kept}");
    let (total, replanned, pairs_kept) = (u(&kept, "pairs_total"), u(&kept, "pairs_replanned"), u(&kept, "pairs_kept"));
    // The walk moved the camera; 8 characters turned and 4 lights circled: their pairs are
    // planned again, every other pair is drawn from its kept lists.
    assert!(total > 1000 && replanned > 0 && pairs_kept > replanned, "{kept}");
    assert_eq!(pairs_kept + replanned, total, "{kept}");
    assert!(u(&kept, "kept_bytes") > 0 && u(&kept, "bytes_sent") > 0, "{kept}");
    for k in ["cpu_cull_ms", "cpu_plan_ms", "cpu_record_ms"] {
        assert!(f(&kept, k) > 0.0 && f(&kept, k).is_finite(), "{k}: {kept}");
    }
    // The error is the last frame's, against the reference of the scene at that time.
    assert!(f(&kept, "error_fraction") <= 1e-4, "{kept}");

    // The same frames planned from scratch: every pair planned and sent, nothing kept.
    let fresh = level_row("fresh", &["--motion", "--no-keep"]);
    assert_eq!(u(&fresh, "pairs_total"), total, "the same pairs drawn: {fresh}");
    assert_eq!((u(&fresh, "pairs_replanned"), u(&fresh, "pairs_kept"), u(&fresh, "kept_bytes")), (total, 0, 0), "{fresh}");
    assert!(u(&fresh, "bytes_sent") > u(&kept, "bytes_sent"), "{fresh} against {kept}");
    assert_eq!(f(&fresh, "cpu_cull_ms"), 0.0, "without keeping the culling is inside the planning: {fresh}");
    assert!(f(&fresh, "cpu_plan_ms") > 0.0, "{fresh}");
    assert_eq!(f(&fresh, "error_fraction"), f(&kept, "error_fraction"), "the same picture");

    // Without --motion every frame is at time 0: after the warm-up nothing moved.
    let still = level_row("still", &[]);
    assert_eq!(still["motion"], false, "{still}");
    assert_eq!((u(&still, "pairs_replanned"), u(&still, "bytes_sent")), (0, 0), "{still}");
    assert_eq!(u(&still, "pairs_kept"), u(&still, "pairs_total"), "{still}");
}

/// `bench --suite frame-cost` at its tiny size: every scene, case and way rowed with the
/// invariants of keeping (nothing kept without it, less sent with it where only the camera
/// moved), the curves, the plots and the report.
#[test]
fn frame_cost_suite_writes_its_rows_curves_and_report() {
    let dir = std::env::temp_dir().join(format!("umbrage-frame-cost-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let md = dir.join("report.md");
    let out = Command::new(common::exe::umbrage_exe())
        .args([
            "bench",
            "--suite",
            "frame-cost",
            "--tiny",
            "--out",
            dir.join("plots").to_str().unwrap(),
            "--markdown",
            md.to_str().unwrap(),
        ])
        .env("UMBRAGE_VALIDATION", "1")
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let v: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(dir.join("plots/frame-cost.json")).unwrap()).unwrap();
    let rows = v["rows"].as_array().unwrap();
    assert_eq!(rows.len(), 4 * 3 * 3, "scenes x cases x ways");
    let row = |scene: &str, case: &str, way: &str| {
        rows.iter().find(|r| r["scene"] == scene && r["case"] == case && r["way"] == way).unwrap_or_else(|| panic!("{scene} {case} {way}"))
    };
    for r in rows {
        let total = u(r, "pairs_total");
        // (medians of each key: kept + replanned is the total frame by frame, not median by median)
        assert!(total > 0 && u(r, "pairs_kept") <= total && u(r, "pairs_replanned") <= total, "{r}");
        match r["way"].as_str().unwrap() {
            "keep-off" | "compute" => assert_eq!((u(r, "pairs_kept"), u(r, "pairs_replanned")), (0, total), "{r}"),
            _ => {}
        }
        assert_eq!(r["moved"].as_u64().unwrap() == 0, r["case"] == "camera", "{r}");
        assert!(f(r, "cpu_frame_ms") >= f(r, "cpu_shadow_ms") && f(r, "cpu_shadow_ms") > 0.0, "{r}");
    }
    for scene in ["bench/level", "default", "stress", "bench/vertex"] {
        let (off, kept) = (row(scene, "camera", "keep-off"), row(scene, "camera", "kept"));
        assert!(u(kept, "bytes_sent") < u(off, "bytes_sent") && u(kept, "pairs_kept") > 0, "{kept} against {off}");
        assert_eq!(u(kept, "pairs_total"), u(off, "pairs_total"), "the same pairs drawn");
    }
    assert_eq!(u(row("bench/level", "casters", "kept"), "moved"), 8, "the level's turning characters");
    for curve in ["lights_curve", "casters_curve"] {
        let points = v[curve].as_array().unwrap();
        assert_eq!(points.len(), 2, "{curve}");
        assert!(points.iter().all(|p| u(p, "pairs_total") > 0 && f(p, "off_ms") > 0.0 && f(p, "kept_ms") > 0.0), "{curve}");
    }
    for plot in ["lights.svg", "casters.svg", "lights.png", "casters.png"] {
        assert!(std::fs::metadata(dir.join("plots").join(plot)).is_ok_and(|m| m.len() > 0), "{plot}");
    }
    let text = std::fs::read_to_string(&md).unwrap();
    assert!(text.contains("umbrage bench --suite frame-cost") && text.contains("](plots/lights.svg)"), "{text}");
    let _ = std::fs::remove_dir_all(&dir);
}
