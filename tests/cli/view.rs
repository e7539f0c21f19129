//! `umbrage view` under Xvfb with lavapipe and validation on: its frame equals `umbrage
//! render`'s (the renderer's readback and the presented swapchain image), synthetic input
//! through xdotool moves the light and changes the method, resizing / unmapping / closing
//! mid-frame stay validation-clean, `render --time T` reproduces an animated frame, and
//! without a display the viewer says so and names `umbrage render`.
//!
//! xvfb-run and xdotool come from scripts/deps.sh; without them the tests fail when `CI` is
//! set and are skipped loudly otherwise. They run one at a time (each starts its own X server).

use crate::common;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::Mutex;

static SERIAL: Mutex<()> = Mutex::new(());

const SCREEN: &str = "-screen 0 1280x1024x24";

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("umbrage-view-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn have(tool: &str) -> bool {
    Command::new("sh").arg("-c").arg(format!("command -v {tool}")).output().map(|o| o.status.success()).unwrap_or(false)
}

/// Whether the X tools are here; a failure under CI.
fn x_tools(need_xdotool: bool) -> bool {
    let missing: Vec<&str> = ["xvfb-run", "xdotool"].into_iter().filter(|t| (need_xdotool || *t == "xvfb-run") && !have(t)).collect();
    if missing.is_empty() {
        return true;
    }
    if std::env::var_os("CI").is_some() {
        panic!("{} missing under CI: run scripts/deps.sh", missing.join(", "));
    }
    eprintln!("SKIPPED: {} missing (scripts/deps.sh installs them)", missing.join(", "));
    false
}

/// Runs `script` (bash, with $UMBRAGE the binary) inside a fresh Xvfb, in `dir`.
fn in_xvfb(dir: &Path, script: &str) -> Output {
    in_xvfb_on(dir, script, &[])
}

/// [`in_xvfb`] with a driver's environment (`common::driver_env`) applied.
fn in_xvfb_on(dir: &Path, script: &str, driver: &[(String, Option<String>)]) -> Output {
    let path = dir.join("script.sh");
    std::fs::write(&path, format!("set -u\nUMBRAGE={}\n{script}", common::exe::umbrage_exe().display())).unwrap();
    let mut c = Command::new("timeout");
    c.args(["300", "xvfb-run", "-a", "-s", SCREEN, "bash"]).arg(&path).current_dir(dir).env("UMBRAGE_VALIDATION", "1");
    common::apply_driver_env(&mut c, driver);
    let out = c.output().unwrap();
    eprintln!("--- stdout\n{}--- stderr\n{}", String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    out
}

fn render(dir: &Path, out: &str, args: &[&str]) {
    render_on(dir, out, args, &[])
}

fn render_on(dir: &Path, out: &str, args: &[&str], driver: &[(String, Option<String>)]) {
    let mut c = Command::new(common::exe::umbrage_exe());
    c.arg("render").args(args).arg("--out").arg(dir.join(out)).env("UMBRAGE_VALIDATION", "1");
    common::apply_driver_env(&mut c, driver);
    let o = c.output().unwrap();
    assert!(o.status.success(), "render failed: {}", String::from_utf8_lossy(&o.stderr));
}

fn pixels(p: &Path) -> image::RgbaImage {
    image::open(p).unwrap_or_else(|e| panic!("{}: {e}", p.display())).to_rgba8()
}

/// Tone-mapped pixels equal (no tolerance: the same renderer, and a NEAREST blit between two
/// 8-bit sRGB formats of one size keeps every byte).
fn assert_same(a: &Path, b: &Path) {
    let (x, y) = (pixels(a), pixels(b));
    assert_eq!(x.dimensions(), y.dimensions(), "{} vs {}", a.display(), b.display());
    let differing = x.pixels().zip(y.pixels()).filter(|(p, q)| p != q).count();
    assert_eq!(differing, 0, "{differing} pixels differ between {} and {}", a.display(), b.display());
}

fn json(p: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))).unwrap()
}

fn exit_code(out: &str) -> i32 {
    out.lines().find_map(|l| l.strip_prefix("rc=")).and_then(|v| v.trim().parse().ok()).unwrap_or(-1)
}

/// Starts the viewer in the background and waits for its window: $PID, $W.
const START: &str = r#"
start() {
  "$UMBRAGE" view "$@" > view.out 2> view.err &
  PID=$!
  W=$(xdotool search --sync --name "umbrage view")
  xdotool windowfocus --sync "$W"
  sleep 2
}
finish() { wait "$PID"; echo "rc=$?"; cat view.out; cat view.err >&2; }
"#;

#[test]
fn thirty_frames_equal_render() {
    let _g = SERIAL.lock().unwrap_or_else(|e| e.into_inner());
    if !x_tools(false) {
        return;
    }
    let d = tmp("frames");
    let out =
        in_xvfb(&d, "$UMBRAGE view --scene default --size 320x240 --frames 30 --screenshot a.png --stats s.json --vsync off\necho rc=$?\n");
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(exit_code(&stdout), 0, "view failed");
    assert!(!String::from_utf8_lossy(&out.stderr).contains("validation"), "validation complained");
    let s = json(&d.join("s.json"));
    assert_eq!(s["frames"], 30);
    assert_eq!((s["width"].as_u64(), s["height"].as_u64()), (Some(320), Some(240)));
    assert_eq!(s["stats"]["method"], "mcguire");
    render(&d, "b.png", &["--scene", "default", "--size", "320x240"]);
    assert_same(&d.join("a.png"), &d.join("b.png"));
}

/// The viewer on SwiftShader, whose Linux build has the XCB surface but not the Xlib one
/// winit's windows come with: the window goes through its XCB connection
/// (`view/surface.rs`), and the presented frame equals `umbrage render`'s on the same driver.
#[test]
fn thirty_frames_equal_render_on_swiftshader() {
    let _g = SERIAL.lock().unwrap_or_else(|e| e.into_inner());
    if !x_tools(false) {
        return;
    }
    let Some(driver) = common::driver_env("swiftshader") else {
        let why = "SwiftShader is not installed (scripts/drivers.sh install swiftshader)";
        assert!(std::env::var_os("CI").is_none(), "{why}");
        eprintln!("SKIPPED: {why}");
        return;
    };
    let d = tmp("swiftshader");
    let out = in_xvfb_on(
        &d,
        "$UMBRAGE view --scene default --size 320x240 --frames 30 --screenshot a.png --stats s.json --vsync off\necho rc=$?\n",
        &driver,
    );
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(exit_code(&stdout), 0, "view failed on SwiftShader");
    assert!(stdout.contains("SwiftShader"), "not SwiftShader: {stdout}");
    assert!(!String::from_utf8_lossy(&out.stderr).contains("validation"), "validation complained");
    assert_eq!(json(&d.join("s.json"))["frames"], 30);
    render_on(&d, "b.png", &["--scene", "default", "--size", "320x240"], &driver);
    assert_same(&d.join("a.png"), &d.join("b.png"));
}

/// The overlay shows the light–caster pairs kept across frames and planned again
/// (issue 55): with keeping, a still scene draws every pair from kept plans after its first
/// frame; with `--no-keep`, every pair is planned every frame. `--stats` records the line as
/// the overlay showed it, from the frame's own counts.
#[test]
fn the_overlay_shows_pairs_kept_and_replanned() {
    let _g = SERIAL.lock().unwrap_or_else(|e| e.into_inner());
    if !x_tools(false) {
        return;
    }
    let d = tmp("pairs");
    let run = "$UMBRAGE view --scene default --size 320x240 --frames 12 --time-step 0 --stats kept.json --vsync off
echo rc=$?
               $UMBRAGE view --scene default --size 320x240 --frames 12 --time-step 0 --stats fresh.json --vsync off --no-keep
echo rc=$?
";
    let out = in_xvfb(&d, run);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.matches("rc=0").count() == 2, "view failed: {stdout}");
    for (file, keep) in [("kept.json", true), ("fresh.json", false)] {
        let s = json(&d.join(file));
        let t = &s["stats"]["totals"];
        let (total, kept, replanned) =
            (t["pairs_total"].as_u64().unwrap(), t["pairs_kept"].as_u64().unwrap(), t["pairs_replanned"].as_u64().unwrap());
        assert!(total > 0, "{file}: {t}");
        assert_eq!((kept, replanned), if keep { (total, 0) } else { (0, total) }, "{file}: {t}");
        // The line the overlay showed (a frame or two before the last: the same still frame).
        let line = s["overlay"]["shown"]["pairs"].as_str().unwrap_or_else(|| panic!("{file}: no pairs line: {s}"));
        let want = format!("pairs {total}: kept {kept}, replanned {replanned}");
        assert!(line.starts_with(&want), "{file}: the overlay showed '{line}', the frame counted '{want}'");
    }
}

#[test]
fn synthetic_input_moves_the_light_and_changes_the_method() {
    let _g = SERIAL.lock().unwrap_or_else(|e| e.into_inner());
    if !x_tools(true) {
        return;
    }
    let d = tmp("input");
    let script = format!(
        "{START}
start --scene default --size 480x320 --vsync off --stats s.json
xdotool mousemove --window $W 240 160
xdotool key 3
sleep 0.5
xdotool mousemove --window $W 400 260 mousedown 1
sleep 0.3
xdotool mousemove --window $W 420 270
sleep 0.3
xdotool mousemove --window $W 440 290 mouseup 1
sleep 1
xdotool key m
sleep 1.5
xdotool key h
sleep 1
xdotool key p
sleep 2
xdotool key Escape
finish
"
    );
    let out = in_xvfb(&d, &script);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(exit_code(&stdout), 0, "Esc should exit 0");
    let s = json(&d.join("s.json"));
    assert_eq!(s["mode"], "light", "key 3 selects light mode");
    // M: mcguire -> lengyel, in the settings, the overlay and the frame's stats.
    assert_eq!(s["method"], "lengyel");
    assert_eq!(s["overlay"]["shown"]["method"], "lengyel");
    assert_eq!(s["stats"]["method"], "lengyel");
    assert_eq!(s["overlay"]["visible"], false, "H hides the overlay");
    // The drag turned light 0 about the origin: moved, same distance.
    let p: Vec<f64> = s["lights"][0]["position"].as_array().unwrap().iter().map(|v| v.as_f64().unwrap()).collect();
    let rest = [3.0f64, 7.0, 4.0];
    let moved = p.iter().zip(rest).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
    assert!(moved > 0.05, "the light did not move: {p:?}");
    let (r0, r1) = (rest.iter().map(|v| v * v).sum::<f64>().sqrt(), p.iter().map(|v| v * v).sum::<f64>().sqrt());
    assert!((r0 - r1).abs() < 1e-3, "a rotation about the origin keeps the distance: {r0} vs {r1}");
    // The P screenshot (the presented swapchain image, overlay hidden) is `render` with the
    // moved light.
    let toml = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/default.toml")).unwrap();
    let moved_toml = toml.replacen("position = [3.0, 7.0, 4.0]", &format!("position = [{:?}, {:?}, {:?}]", p[0], p[1], p[2]), 1);
    assert_ne!(toml, moved_toml);
    std::fs::write(d.join("moved.toml"), moved_toml).unwrap();
    let scene = d.join("moved.toml");
    render(&d, "moved.png", &["--scene", scene.to_str().unwrap(), "--size", "480x320", "--method", "lengyel"]);
    render(&d, "rest.png", &["--scene", "default", "--size", "480x320", "--method", "lengyel"]);
    let shot = d.join("umbrage-view-000.png");
    assert_same(&shot, &d.join("moved.png"));
    assert_ne!(pixels(&shot), pixels(&d.join("rest.png")), "the moved light changes the picture");
}

#[test]
fn resizing_unmapping_and_quitting_mid_animation_stay_clean() {
    let _g = SERIAL.lock().unwrap_or_else(|e| e.into_inner());
    if !x_tools(true) {
        return;
    }
    let d = tmp("resize");
    let script = format!(
        "{START}
start --scene stress --size 320x240 --vsync off --stats s.json
for s in '200 150' '400 260' '97 61' '333 222' '1 1' '260 180'; do
  xdotool windowsize $W $s
  sleep 0.4
done
xdotool windowunmap --sync $W
sleep 0.5
xdotool windowmap --sync $W
xdotool windowfocus --sync $W
sleep 0.5
xdotool windowsize $W 300 200
sleep 1
xdotool key Escape
finish
"
    );
    let out = in_xvfb(&d, &script);
    let stdout = String::from_utf8_lossy(&out.stdout);
    let codes: Vec<i32> = stdout.lines().filter_map(|l| l.strip_prefix("rc=")).map(|v| v.trim().parse().unwrap_or(-1)).collect();
    assert_eq!(codes, [0], "Esc with frames in flight exits 0 (validation errors, leaks included, would fail it)");
    assert!(!String::from_utf8_lossy(&out.stderr).contains("[vulkan validation]"));
    let s = json(&d.join("s.json"));
    assert!(s["swapchains"].as_u64().unwrap() >= 5, "each resize rebuilt the swapchain: {}", s["swapchains"]);
    assert_eq!((s["width"].as_u64(), s["height"].as_u64()), (Some(300), Some(200)), "the renderer follows the window");
}

#[test]
fn render_at_the_viewers_time_equals_its_frame() {
    let _g = SERIAL.lock().unwrap_or_else(|e| e.into_inner());
    if !x_tools(false) {
        return;
    }
    let d = tmp("time");
    let out = in_xvfb(
        &d,
        "$UMBRAGE view --scene stress --size 320x200 --frames 12 --time 1.5 --time-step 0.25 --hide-overlay --screenshot a.png --stats s.json --vsync off\necho rc=$?\n",
    );
    assert_eq!(exit_code(&String::from_utf8_lossy(&out.stdout)), 0);
    let s = json(&d.join("s.json"));
    let t = s["time_s"].as_f64().unwrap();
    assert!((t - (1.5 + 11.0 * 0.25)).abs() < 1e-9, "the 12th frame is at 4.25 s, got {t}");
    render(&d, "b.png", &["--scene", "stress", "--size", "320x200", "--time", &format!("{t:?}")]);
    assert_same(&d.join("a.png"), &d.join("b.png"));
    render(&d, "rest.png", &["--scene", "stress", "--size", "320x200"]);
    assert_ne!(pixels(&d.join("a.png")), pixels(&d.join("rest.png")), "the stress scene moves");
}

#[test]
fn no_display_names_render_and_fails() {
    let out = Command::new(common::exe::umbrage_exe())
        .args(["view", "--frames", "1"])
        .env_remove("DISPLAY")
        .env_remove("WAYLAND_DISPLAY")
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert_eq!(err.trim().lines().count(), 1, "one line: {err}");
    assert!(err.contains("no display") && err.contains("umbrage render"), "{err}");
}

/// Injected presentation faults (`UMBRAGE_FAULT=present=...`, see `umbrage::gpu::fault`): an
/// out-of-date swapchain at acquire and at present is recreated and the run finishes its
/// frames; a lost device at present is a clear error, exit 1, nothing leaked (validation on).
#[test]
fn injected_present_faults_recover_or_fail_cleanly() {
    let _g = SERIAL.lock().unwrap_or_else(|e| e.into_inner());
    if !x_tools(false) {
        return;
    }
    let d = tmp("present-faults");
    let out = in_xvfb(
        &d,
        "UMBRAGE_FAULT=present=out_of_date@3,present=out_of_date@8 $UMBRAGE view --scene default --size 160x120 --frames 12 --stats s.json --vsync off\necho rc=$?\n\
         UMBRAGE_FAULT=present=device_lost@6 $UMBRAGE view --scene default --size 160x120 --frames 12 --vsync off\necho rc2=$?\n",
    );
    let (stdout, stderr) = (String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    assert_eq!(exit_code(&stdout), 0, "out-of-date must be recovered from");
    assert_eq!(json(&d.join("s.json"))["frames"], 12);
    let rc2 = stdout.lines().find_map(|l| l.strip_prefix("rc2=")).and_then(|v| v.trim().parse::<i32>().ok());
    assert_eq!(rc2, Some(1), "a lost device at present fails");
    assert!(stderr.contains("ERROR_DEVICE_LOST"), "the error names the fault");
    assert!(!stderr.contains("[vulkan validation]") && !stderr.contains("panicked"), "clean");
}
