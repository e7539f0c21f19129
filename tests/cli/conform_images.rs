//! Every failure carries its images, the numeric checks' included (issue 54): the test seam
//! `UMBRAGE_CONFORM_MISMATCH=<check>,...` makes the named checks expect a wrong value, and each
//! must then fail with images under `<out>/failures/<case>/`, drawn from what it compared; the
//! checks not named still pass.

use crate::common;

use std::path::PathBuf;
use std::process::Command;
use umbrage_conform::deqp::qpa;

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

/// A check the seam makes fail: its case (as `conform.json` names it), an image it must write
/// (relative to its case's directory) and that image's size in pixels.
struct Forced {
    case: &'static str,
    image: &'static str,
    size: (u32, u32),
}

/// The drawn case forced to fail on depth alone (its stencil still matches the model).
const DEPTH_CASE: &str = "depth.d32s8.dynamic_rendering.static_state.infinity.forward.dir_0.comp_less";

/// `umbrage conform` with `driver`'s environment applied (empty: the system's), `args`, and the
/// seam naming every case of `forced`.
fn forced_run(driver: &[(String, Option<String>)], forced: &[Forced], args: &[String]) -> std::process::Output {
    let mut c = Command::new(common::exe::umbrage_exe());
    common::apply_driver_env(&mut c, driver);
    c.arg("conform")
        .args(args)
        .env("UMBRAGE_VALIDATION", "1")
        .env("UMBRAGE_CONFORM_MISMATCH", forced.iter().map(|f| f.case).collect::<Vec<_>>().join(","))
        .env_remove("UMBRAGE_CONFORM_BREAK")
        .env_remove("UMBRAGE_CONFORM_CRASH")
        .env_remove("UMBRAGE_CONFORM_CRASH_CASE")
        .env_remove("UMBRAGE_DEVICE");
    c.output().unwrap()
}

/// Each case of `forced` must fail with its images under `<dir>/failures/<case>/`, listed in
/// `conform.json` (each a PNG of the size of the others of its draw, the named one of its
/// size), and again in dEQP mode, embedded in the QPA log (each image of the record a PNG of
/// the size it states, the named one among them). Returns the report directory.
fn forced_images(name: &str, driver: &[(String, Option<String>)], forced: &[Forced]) -> PathBuf {
    let dir = tmp(name);
    let filter: Vec<String> = forced.iter().map(|f| format!("={}", f.case)).collect();
    let out = forced_run(driver, forced, &["--filter".into(), filter.join(","), "--out".into(), dir.display().to_string()]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(1), "{stdout}{}", String::from_utf8_lossy(&out.stderr));
    let j: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(dir.join("conform.json")).unwrap()).unwrap();
    let cases = j["cases"].as_array().unwrap();
    assert_eq!(cases.len(), forced.len(), "{stdout}");
    for f in forced {
        let c = cases.iter().find(|c| c["name"] == f.case).unwrap_or_else(|| panic!("{} not run: {stdout}", f.case));
        // The drivers are chosen to have what each check needs: a skip is a failure here.
        assert_eq!(c["status"], "fail", "{}: {}", f.case, c["message"]);
        let images: Vec<&str> = c["images"].as_array().map(|v| v.iter().filter_map(|p| p.as_str()).collect()).unwrap_or_default();
        let case_dir = dir.join("failures").join(f.case);
        let mut sizes = std::collections::HashMap::new();
        for p in &images {
            assert!(PathBuf::from(p).starts_with(&case_dir), "{}: {p} outside {}", f.case, case_dir.display());
            let img = image::open(p).unwrap_or_else(|e| panic!("{p}: {e}"));
            let draw = PathBuf::from(p).file_name().unwrap().to_string_lossy().split('.').next().unwrap().to_string();
            let size = *sizes.entry(draw).or_insert((img.width(), img.height()));
            assert_eq!((img.width(), img.height()), size, "{p}: not the size of its draw's other images");
        }
        let want = case_dir.join(f.image);
        assert!(images.iter().any(|p| PathBuf::from(p) == want), "{}: no {} among {images:?}", f.case, f.image);
        assert_eq!(image::image_dimensions(&want).unwrap(), f.size, "{}", want.display());
    }
    // dEQP mode: the same failures, their images embedded in the QPA log.
    let log = dir.join("forced.qpa");
    let cases: Vec<String> = forced.iter().map(|f| format!("umbrage.{}", f.case)).collect();
    let out = forced_run(driver, forced, &[format!("--deqp-case={}", cases.join(",")), format!("--deqp-log-filename={}", log.display())]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let recs = qpa::parse(&std::fs::read_to_string(&log).unwrap()).unwrap();
    for f in forced {
        let r = recs.iter().find(|r| r.name == format!("umbrage.{}", f.case)).unwrap_or_else(|| panic!("no record of {}", f.case));
        assert!(r.xml.contains("<Result StatusCode=\"Fail\">"), "{}: {}", f.case, r.xml);
        let embedded = qpa_images(&r.xml);
        for (stem, size, png) in &embedded {
            assert_eq!(image::load_from_memory(png).map(|i| (i.width(), i.height())).ok(), Some(*size), "{}: {stem}", f.case);
        }
        let stem = f.image.trim_end_matches(".png");
        assert!(embedded.iter().any(|(s, size, _)| s == stem && *size == f.size), "{}: {stem} not embedded", f.case);
    }
    dir
}

/// The pixels of `<dir>/failures/<case>/<image>` of colour `rgb`.
fn count(dir: &std::path::Path, case: &str, image: &str, rgb: [u8; 3]) -> usize {
    let img = image::open(dir.join("failures").join(case).join(image)).unwrap().to_rgb8();
    img.pixels().filter(|p| p.0 == rgb).count()
}

/// The driver environment of `scripts/drivers.sh env VERSION`; `None` (a loud skip) when it is
/// not installed, and a failure under CI.
fn driver(version: &str) -> Option<Vec<(String, Option<String>)>> {
    let env = common::driver_env(version);
    if env.is_none() {
        assert!(std::env::var_os("CI").is_none(), "CI needs {version} (scripts/drivers.sh install {version})");
        eprintln!("SKIPPED: {version} is not installed (scripts/drivers.sh install {version})");
    }
    env
}

/// (name, stated size, decoded PNG) of each `<Image>` of a QPA record.
fn qpa_images(xml: &str) -> Vec<(String, (u32, u32), Vec<u8>)> {
    let attr = |tag: &str, k: &str| tag.split(&format!(" {k}=\"")).nth(1).and_then(|r| r.split('"').next()).unwrap_or("").to_string();
    let mut v = Vec::new();
    for part in xml.split("<Image ").skip(1) {
        let (tag, rest) = part.split_once('>').unwrap();
        let tag = format!(" {tag}");
        let tag = tag.as_str();
        let data = rest.split("</Image>").next().unwrap();
        let size = (attr(tag, "Width").parse().unwrap(), attr(tag, "Height").parse().unwrap());
        v.push((attr(tag, "Name"), size, qpa::unbase64(data).expect("base64")));
    }
    v
}

/// The float count, the depth-only failures (two legacy checks and a drawn case) on the system
/// driver: each forced to fail, with its images.
#[test]
fn depth_and_float_failures_write_images() {
    let Some(_ctx) = common::context() else { return };
    let forced = [
        Forced { case: "legacy.deep_wrap_float_count", image: "count.diff.png", size: (192, 128) },
        Forced { case: "legacy.w0_vertices_and_infinity", image: "draw1.depth_diff.png", size: (160, 120) },
        Forced { case: "legacy.stencil_formats", image: "draw1.depth_diff.png", size: (192, 128) },
        Forced { case: "legacy.depth_clamp", image: "draw1.depth_diff.png", size: (160, 120) },
        Forced { case: DEPTH_CASE, image: "diff_depth.png", size: (128, 128) },
    ];
    let dir = forced_images("depth", &[], &forced);
    // Drawn from the data: the float count differs over the 16 x 16 covered texels (8 x 8
    // pixels each), and nowhere else; the drawn case's stencil matched (no red in its diff),
    // its depth differed at every judged pixel.
    assert_eq!(count(&dir, forced[0].case, "count.diff.png", [255, 0, 0]), 16 * 16 * 64);
    assert_eq!(count(&dir, DEPTH_CASE, "diff.png", [255, 0, 0]), 0);
    assert!(count(&dir, DEPTH_CASE, "diff.png", [255, 255, 0]) > 0);
    assert!(count(&dir, DEPTH_CASE, "diff_depth.png", [255, 255, 0]) > 0);
    assert_eq!(count(&dir, "legacy.stencil_formats", "draw1.depth_diff.png", [255, 255, 0]), 32 * 16 * 16);
    let _ = std::fs::remove_dir_all(&dir);
}

/// `legacy.depth_bounds` on SwiftShader (no lavapipe has depthBounds): forced to fail, with its
/// images; the seam expects the 0.2 strip to pass instead of the 0.5 one, so two 16-texel
/// strips of the 64 x 16 image differ.
#[test]
fn depth_bounds_failure_writes_images() {
    let Some(_ctx) = common::context() else { return };
    let Some(ss) = driver("swiftshader") else { return };
    let forced = [Forced { case: "legacy.depth_bounds", image: "draw1.diff.png", size: (512, 128) }];
    let dir = forced_images("bounds", &ss, &forced);
    assert_eq!(count(&dir, forced[0].case, "draw1.diff.png", [255, 0, 0]), 2 * 16 * 16 * 64);
    let _ = std::fs::remove_dir_all(&dir);
}

/// The `mesh.*` checks on Mesa lavapipe 25.0.7 (the system's 22.3.6 has no mesh shaders):
/// each forced to fail, with its images.
#[test]
fn mesh_failures_write_images() {
    let Some(_ctx) = common::context() else { return };
    let Some(lvp) = driver("25.0.7") else { return };
    let forced = [
        Forced { case: "mesh.w0_vertices", image: "draw1.diff.png", size: (160, 120) },
        Forced { case: "mesh.watertight_meshlets", image: "draw1.diff.png", size: (160, 120) },
        // 89 words of the first draw's records, 16 a row.
        Forced { case: "mesh.group_counts", image: "draw_7x3x2.diff.png", size: (336, 126) },
        // 12 words, one row.
        Forced { case: "mesh.task_payload", image: "task_invocations.diff.png", size: (2048, 128) },
    ];
    let dir = forced_images("mesh", &lvp, &forced);
    // One judged pixel (one word) skewed: one red texel each.
    assert_eq!(count(&dir, "mesh.w0_vertices", "draw1.diff.png", [255, 0, 0]), 1);
    // The dark caps' depth, expected at 0.5 under the seam: the draw after the first run's
    // stencil, every covered pixel yellow.
    let depth_diff = "draw2.depth_diff.png";
    assert_eq!(image::image_dimensions(dir.join("failures/mesh.w0_vertices").join(depth_diff)).unwrap(), (160, 120));
    assert!(count(&dir, "mesh.w0_vertices", depth_diff, [255, 255, 0]) > 100);
    assert_eq!(count(&dir, "mesh.group_counts", "draw_7x3x2.diff.png", [255, 0, 0]), 21 * 21);
    assert_eq!(count(&dir, "mesh.task_payload", "task_invocations.diff.png", [255, 0, 0]), 128 * 128);
    let _ = std::fs::remove_dir_all(&dir);
}
