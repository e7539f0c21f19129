//! Every failure carries its images, the numeric checks' included (issue 54): the test seam
//! `UMBRAGE_CONFORM_MISMATCH=<check>,...` makes the named checks expect a wrong value, and each
//! must then fail with images under `<out>/failures/<case>/`, drawn from what it compared; the
//! checks not named still pass.

use crate::common;

use std::path::PathBuf;
use std::process::Command;

/// The checks the seam skews, with the image each must write (relative to its case's directory).
const SKEWED: [(&str, &str); 9] = [
    ("commands.buffers", "bytes.diff.png"),
    ("commands.fill_buffer", "bytes.diff.png"),
    ("commands.queries", "counts.bars.png"),
    ("commands.dispatch", "words.diff.png"),
    ("commands.dispatch_indirect", "words.diff.png"),
    ("commands.indirect", "draw1.diff.png"),
    ("commands.multi_draw_indirect", "draw1.diff.png"),
    ("commands.draw_indirect_count", "draw1.diff.png"),
    ("legacy.msaa_depth_locations", "depth_locations.points.png"),
];

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("umbrage-images-test-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

#[test]
fn numeric_checks_write_failure_images() {
    let Some(_ctx) = common::context() else { return };
    let dir = tmp("numeric");
    let short: Vec<&str> = SKEWED.iter().map(|(c, _)| c.split_once('.').unwrap().1).collect();
    let out = Command::new(common::exe::umbrage_exe())
        .args(["conform", "--filter", "commands.,legacy.msaa_depth_locations", "--out"])
        .arg(&dir)
        .env("UMBRAGE_VALIDATION", "1")
        .env("UMBRAGE_CONFORM_MISMATCH", short.join(","))
        .env_remove("UMBRAGE_CONFORM_BREAK")
        .env_remove("UMBRAGE_CONFORM_CRASH")
        .env_remove("UMBRAGE_CONFORM_CRASH_CASE")
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(1), "{stdout}");
    let j: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(dir.join("conform.json")).unwrap()).unwrap();
    let cases = j["cases"].as_array().unwrap();
    for c in cases {
        let name = c["name"].as_str().unwrap();
        let Some((_, image)) = SKEWED.iter().find(|(n, _)| *n == name) else {
            assert!(c["status"] == "pass" || c["status"] == "skipped", "{name} not skewed: {} {}", c["status"], c["message"]);
            continue;
        };
        if c["status"] == "skipped" {
            // A device without what the check needs (no skip under CI: the CI drivers have it all).
            assert!(std::env::var_os("CI").is_none(), "{name} skipped under CI: {}", c["message"]);
            continue;
        }
        assert_eq!(c["status"], "fail", "{name}: {}", c["message"]);
        let images: Vec<&str> = c["images"].as_array().map(|v| v.iter().filter_map(|p| p.as_str()).collect()).unwrap_or_default();
        assert!(!images.is_empty(), "{name} failed without images");
        let case_dir = dir.join("failures").join(name);
        for p in &images {
            assert!(PathBuf::from(p).starts_with(&case_dir), "{name}: {p} outside {}", case_dir.display());
            let img = image::open(p).unwrap_or_else(|e| panic!("{p}: {e}"));
            assert!(img.width() > 0 && img.height() > 0);
        }
        assert!(images.iter().any(|p| p.ends_with(image)), "{name}: no {image} among {images:?}");
    }
    // Drawn from the data: the buffers check's one skewed byte (its first) is the diff's one
    // red texel, at the top-left; the rest of the buffer matched.
    let diff = image::open(dir.join("failures/commands.buffers/bytes.diff.png")).unwrap().to_rgb8();
    let red = diff.pixels().filter(|p| p.0 == [255, 0, 0]).count();
    assert_eq!(diff.get_pixel(0, 0).0, [255, 0, 0]);
    assert_eq!(diff.get_pixel(diff.width() - 1, diff.height() - 1).0, [0, 0, 0]);
    let scale = diff.width() / 32;
    assert_eq!(red as u32, scale * scale, "one texel of {} x {} pixels", scale, scale);
    let _ = std::fs::remove_dir_all(&dir);
}
