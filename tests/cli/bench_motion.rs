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
