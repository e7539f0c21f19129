//! The command line as a user meets it: bad input gives a clear message and a non-zero exit,
//! never a panic; good input writes what it says.
use crate::common;

use std::path::PathBuf;
use std::process::{Command, Output};

fn umbrage(args: &[&str]) -> Output {
    Command::new(common::exe::umbrage_exe()).args(args).env("UMBRAGE_VALIDATION", "1").output().unwrap()
}

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("umbrage-cli-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn fails_with(out: &Output, needle: &str) {
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "expected failure, got success; stderr: {err}");
    assert!(!err.contains("panicked"), "panicked: {err}");
    assert!(err.contains(needle), "stderr should mention '{needle}': {err}");
}

#[test]
fn bad_inputs_fail_cleanly() {
    let d = tmp("bad");
    fails_with(&umbrage(&["render", "--scene", "no/such/scene.toml", "--out", d.join("a.png").to_str().unwrap()]), "no/such/scene.toml");
    fails_with(&umbrage(&["render", "--scene", "nonexistent_builtin"]), "nonexistent_builtin");
    fails_with(&umbrage(&["render", "--method", "magic"]), "magic");
    fails_with(&umbrage(&["render", "--depth-mode", "sideways"]), "sideways");
    fails_with(&umbrage(&["render", "--index-format", "u7"]), "u7");
    fails_with(&umbrage(&["render", "--size", "0x10"]), "size");
    let nan = d.join("nan.toml");
    std::fs::write(&nan, "[camera]\neye = [0, 1, nan]\ntarget = [0, 0, 0]\n").unwrap();
    fails_with(&umbrage(&["render", "--scene", nan.to_str().unwrap()]), "nan.toml");
    let syntax = d.join("syntax.toml");
    std::fs::write(&syntax, "[camera]\neye = [0, 1, 2\n").unwrap();
    fails_with(&umbrage(&["render", "--scene", syntax.to_str().unwrap()]), "syntax.toml");
    let data = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data");
    let obj = d.join("obj.toml");
    std::fs::write(&obj, format!("[camera]\neye = [0, 1, 4]\ntarget = [0, 0, 0]\n[[light]]\nkind = \"point\"\nposition = [0, 5, 0]\n[[mesh]]\nobj = \"{data}/malformed.obj\"\n")).unwrap();
    fails_with(&umbrage(&["render", "--scene", obj.to_str().unwrap()]), "malformed.obj");
    let empty = d.join("empty.toml");
    std::fs::write(&empty, format!("[camera]\neye = [0, 1, 4]\ntarget = [0, 0, 0]\n[[mesh]]\nobj = \"{data}/no_faces.obj\"\n")).unwrap();
    fails_with(&umbrage(&["render", "--scene", empty.to_str().unwrap()]), "no_faces");
    fails_with(&umbrage(&["check", d.join("missing").to_str().unwrap()]), "missing");
}

#[test]
fn no_vulkan_driver_says_how_to_install_one() {
    let out = Command::new(common::exe::umbrage_exe())
        .args(["info"])
        .env("VK_ICD_FILENAMES", "/nonexistent/icd.json")
        .env("VK_DRIVER_FILES", "/nonexistent/icd.json")
        .output()
        .unwrap();
    fails_with(&out, "mesa-vulkan-drivers");
}

#[test]
fn render_stats_dump_and_check() {
    let d = tmp("good");
    let png = d.join("out.png");
    let stats = d.join("stats.json");
    let dump = d.join("dump");
    let out = umbrage(&[
        "render",
        "--scene",
        "stairs",
        "--size",
        "160x120",
        "--out",
        png.to_str().unwrap(),
        "--stats",
        stats.to_str().unwrap(),
        "--dump",
        dump.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let line = String::from_utf8_lossy(&out.stdout);
    assert_eq!(line.lines().count(), 1, "render prints one line: {line}");
    assert!(png.exists());
    let s: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&stats).unwrap()).unwrap();
    for key in ["device", "method", "depth_mode", "lights", "totals", "cpu_ms", "gpu_ms"] {
        assert!(s.get(key).is_some(), "stats lacks {key}");
    }
    let caster = &s["lights"][0]["casters"][0];
    for key in ["name", "case", "silhouette_edges", "triangles", "index_bytes", "vertex_bytes"] {
        assert!(caster.get(key).is_some(), "caster stats lack {key}");
    }
    for key in ["sides", "dark_cap", "light_cap"] {
        assert!(s["totals"]["triangles"].get(key).is_some());
    }
    for f in ["frame.json", "world.obj", "positions.f32", "normals.f32", "shadow_0.png", "stencil_0.png", "color.png"] {
        assert!(dump.join(f).exists(), "dump lacks {f}");
    }
    assert_eq!(std::fs::metadata(dump.join("positions.f32")).unwrap().len(), 160 * 120 * 3 * 4);
    let check = umbrage(&["check", dump.to_str().unwrap()]);
    assert!(check.status.success(), "{}", String::from_utf8_lossy(&check.stdout));
    let info = umbrage(&["info", "--json", "--scene", "hard/open_casters"]);
    assert!(info.status.success());
    let v: serde_json::Value = serde_json::from_slice(&info.stdout).unwrap();
    assert!(v["features"].get("depth_clamp").is_some());
    // info says which path each caster takes, and why
    let casters = v["casters"].as_array().unwrap();
    let open_box = casters.iter().find(|c| c["name"] == "open_box").unwrap();
    assert_eq!(open_box["path"], "multiplicity");
    assert!(open_box["reason"].as_str().unwrap().contains("boundary"));
    assert!(casters.iter().any(|c| c["path"] == "manifold"));
}

/// `bench --methods` accepts every technique `render --method` accepts (clap value enums on
/// both), and reports throughput beside latency.
#[test]
fn bench_accepts_every_render_method() {
    let d = tmp("bench");
    let json = d.join("bench.json");
    let out = umbrage(&[
        "bench",
        "--scene",
        "default",
        "--methods",
        "edgequad,mcguire,compute,shadowmap,auto",
        "--frames",
        "2",
        "--size",
        "96x64",
        "--shadow-map-size",
        "256",
        "--compute-draws",
        "auto,per-chunk",
        "--json",
        json.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let v: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let rows = v["rows"].as_array().unwrap();
    let methods: Vec<&str> = rows.iter().map(|r| r["method"].as_str().unwrap()).collect();
    assert_eq!(methods, ["edgequad", "mcguire", "compute", "compute-per-chunk", "shadowmap-256"], "auto is mcguire, listed once");
    // The compute path's volume draw calls: merged (one per light and pipeline) where the
    // device has the indirect-draw features, else as many as per chunk; the same shadow.
    let draws = |m: &str| rows.iter().find(|r| r["method"] == m).and_then(|r| r["volume_draws"].as_u64()).unwrap();
    assert!(draws("compute") > 0 && draws("compute") <= draws("compute-per-chunk") && draws("mcguire") > 0, "{v}");
    // The compute silhouettes are timed on their own and put against the compute read rate
    // measured in the same run.
    let rate = v["compute_read_gib_s"].as_f64().unwrap();
    assert!(rate > 0.0 && v["compute_read_sweep"].as_array().is_some_and(|s| s.len() == 3), "{v}");
    // The lighting and G-buffer passes are put against their own limits, measured in the same run.
    let (light, tri) = (v["lighting_gpix_s"].as_f64().unwrap(), v["gbuffer_tri_mtri_s"].as_f64().unwrap());
    assert!(light > 0.0 && tri > 0.0, "{v}");
    assert!(v["lighting_shaded_gpix_s"].as_f64().is_some_and(|x| x > 0.0) && v["lighting_instance_ms"].as_f64().is_some(), "{v}");
    for k in ["lighting_sweep", "gbuffer_sweep"] {
        assert!(v[k].as_array().is_some_and(|s| !s.is_empty()), "{k}: {v}");
    }
    for r in rows {
        let (gbuffer_ms, illum_ms) = (r["gpu_gbuffer_ms"].as_f64().unwrap(), r["gpu_illuminate_ms"].as_f64().unwrap());
        let (tris, pixels) = (r["gbuffer_triangles"].as_u64().unwrap(), r["lit_pixels"].as_u64().unwrap());
        assert!(gbuffer_ms > 0.0 && illum_ms > 0.0 && tris > 0 && pixels > 0, "{r}");
        // default: three lights, each at most the whole 96x64 target.
        assert!(pixels <= 3 * 96 * 64, "{r}");
        let (fl, fg) = (r["lighting_limit_fraction"].as_f64().unwrap(), r["gbuffer_limit_fraction"].as_f64().unwrap());
        let (el, eg) = (pixels as f64 / (light * 1e9) * 1e3 / illum_ms, tris as f64 / (tri * 1e6) * 1e3 / gbuffer_ms);
        assert!(fl > 0.0 && (fl - el).abs() <= 1e-9 * el.max(1.0), "{r}");
        // Against the first point of the sweep (one draw an instance), never above the peak.
        assert!(r["lighting_one_draw_fraction"].as_f64().is_some_and(|x| x >= fl * (1.0 - 1e-9)), "{r}");
        assert!(fg > 0.0 && (fg - eg).abs() <= 1e-9 * eg.max(1.0), "{r}");
        let fill = v["gbuffer_fill_gpix_s"].as_f64().unwrap();
        let ef = (96.0 * 64.0) / (fill * 1e9) * 1e3 / gbuffer_ms;
        assert!(r["gbuffer_fill_fraction"].as_f64().is_some_and(|x| x > 0.0 && (x - ef).abs() <= 1e-9 * ef.max(1.0)), "{r}");
    }
    for r in rows {
        let silhouettes = r["gpu_silhouettes_ms"].as_f64();
        if r["method"].as_str().is_some_and(|m| m.starts_with("compute")) {
            let (ms, bytes, fraction) =
                (silhouettes.unwrap(), r["silhouette_read_bytes"].as_u64().unwrap(), r["silhouette_limit_fraction"].as_f64().unwrap());
            assert!(ms > 0.0 && ms < r["gpu_shadow_ms"].as_f64().unwrap() && bytes > 0, "{r}");
            let expected = bytes as f64 / (rate * (1u64 << 30) as f64) * 1e3 / ms;
            assert!((fraction - expected).abs() <= 1e-9 * expected.max(1.0), "{r}");
        } else {
            assert!(silhouettes.is_none() && r["silhouette_limit_fraction"].is_null(), "{r}");
        }
        assert!(r["throughput_fps"].as_f64().unwrap() > 0.0, "{r}");
        assert!(r["wall_ms"].as_f64().unwrap() > 0.0, "{r}");
        // The shadow map's time splits into its maps and its lookup; the volumes have neither.
        let (map, lookup, shadow) = (r["gpu_map_ms"].as_f64(), r["gpu_lookup_ms"].as_f64(), r["gpu_shadow_ms"].as_f64().unwrap());
        if r["method"] == "shadowmap-256" {
            let (map, lookup) = (map.unwrap(), lookup.unwrap());
            assert!(map > 0.0 && lookup > 0.0 && map < shadow, "{r}");
        } else {
            assert!(map.is_none() && lookup.is_none(), "{r}");
        }
    }
    fails_with(&umbrage(&["bench", "--methods", "magic"]), "magic");
    fails_with(&umbrage(&["render", "--cube", "sphere"]), "sphere");
    // Multiview cube faces render where the device's multiview is trusted, and are otherwise
    // a clear refusal that names the way out.
    let png = d.join("multiview.png");
    let out = umbrage(&["render", "--method", "shadowmap", "--cube", "multiview", "--size", "64x48", "--out", png.to_str().unwrap()]);
    if !out.status.success() {
        fails_with(&out, "--cube atlas");
    }
    for m in ["zpass", "zfail", "everitt-kilgard", "lengyel", "mcguire", "auto", "edgequad", "shadowmap"] {
        let png = d.join(format!("{m}.png"));
        let stats = d.join(format!("{m}.json"));
        let out =
            umbrage(&["render", "--method", m, "--size", "64x48", "--out", png.to_str().unwrap(), "--stats", stats.to_str().unwrap()]);
        assert!(out.status.success(), "{m}: {}", String::from_utf8_lossy(&out.stderr));
        // The shadow map's settings are in its stats, and only in its stats.
        let s: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&stats).unwrap()).unwrap();
        match m {
            "shadowmap" => assert_eq!(s["shadow_map"], serde_json::json!({ "size": 2048, "pcf": "taps", "cube": "atlas" })),
            _ => assert!(s["shadow_map"].is_null(), "{m}: {}", s["shadow_map"]),
        }
    }
}

/// `info --scene` lists each caster's parts (each planned on its own).
#[test]
fn info_lists_caster_parts() {
    let out = umbrage(&["info", "--scene", "hard/open_casters", "--json"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let casters = v["casters"].as_array().unwrap();
    assert!(!casters.is_empty());
    for c in casters {
        let parts = c["parts"].as_array().unwrap();
        assert!(!parts.is_empty(), "{c}");
        let tris: u64 = parts.iter().map(|p| p["triangles"].as_u64().unwrap()).sum();
        assert_eq!(tris, c["triangles"].as_u64().unwrap(), "parts cover the caster: {c}");
    }
}

/// `info --scene` lists analytic sphere casters with the segments the half-pixel rule picks.
#[test]
fn info_lists_sphere_casters() {
    let out = umbrage(&["info", "--scene", "analytic/sphere_and_meshes", "--json"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let spheres: Vec<_> = v["casters"].as_array().unwrap().iter().filter(|c| c["path"] == "sphere").collect();
    assert_eq!(spheres.len(), 3);
    for c in spheres {
        let n = c["sphere"]["segments_per_light"].as_array().unwrap();
        assert_eq!(n.len(), 3, "{c}");
        assert!(n.iter().all(|n| n.as_u64().unwrap() >= 8), "{c}");
        assert!(c["sphere"]["error_px_per_light"].as_array().unwrap().iter().all(|e| e.as_f64().unwrap() <= 0.5), "{c}");
    }
    let text = umbrage(&["info", "--scene", "analytic/sphere_only"]);
    assert!(String::from_utf8_lossy(&text.stdout).contains("sphere"));
    // A bad sphere in a scene file: a clear error naming the file and key, no panic.
    let d = tmp("badsphere");
    let f = d.join("s.toml");
    std::fs::write(&f, "[camera]\neye = [0, 2, 5]\ntarget = [0, 0, 0]\n[[sphere]]\ncenter = [0, 1, 0]\nradius = -1\n").unwrap();
    fails_with(&umbrage(&["render", "--scene", f.to_str().unwrap(), "--out", d.join("a.png").to_str().unwrap()]), "radius");
}

/// `render --msaa 4 --dump DIR`: one complete dump per sample in `DIR/sample_K`, each passing
/// `umbrage check`; the PNG is the resolve. A count the device or method cannot do is refused.
#[test]
fn render_msaa_dumps_every_sample() {
    let d = tmp("msaa");
    let dump = d.join("dump");
    let png = d.join("msaa.png");
    let out = umbrage(&["render", "--size", "120x90", "--msaa", "4", "--out", png.to_str().unwrap(), "--dump", dump.to_str().unwrap()]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(png.exists());
    assert!(!dump.join("positions.f32").exists(), "a multisampled dump is per sample");
    for k in 0..4 {
        let s = dump.join(format!("sample_{k}"));
        for f in ["frame.json", "world.obj", "positions.f32", "normals.f32", "shadow_0.png", "stencil_0.png", "color.png"] {
            assert!(s.join(f).exists(), "sample {k} lacks {f}");
        }
        assert_eq!(std::fs::metadata(s.join("positions.f32")).unwrap().len(), 120 * 90 * 3 * 4);
        let check = umbrage(&["check", s.to_str().unwrap()]);
        assert!(check.status.success(), "sample {k}: {}", String::from_utf8_lossy(&check.stdout));
    }
    fails_with(&umbrage(&["render", "--size", "32x32", "--msaa", "3", "--out", png.to_str().unwrap()]), "1, 2, 4 or 8");
    fails_with(
        &umbrage(&["render", "--size", "32x32", "--msaa", "4", "--method", "shadowmap", "--out", png.to_str().unwrap()]),
        "one sample",
    );
}

/// `umbrage info --pipelines` creates every pipeline the renderer and the shadow pass can
/// create (validation on), one line each with its time, the compute silhouettes' included,
/// and says all were created; with `UMBRAGE_PIPELINE_TRACE=1` each is named before creation.
#[test]
fn info_pipelines_creates_and_times_every_pipeline() {
    let out = Command::new(common::exe::umbrage_exe())
        .args(["info", "--pipelines"])
        .env("UMBRAGE_VALIDATION", "1")
        .env("UMBRAGE_PIPELINE_TRACE", "1")
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    let err = String::from_utf8_lossy(&out.stderr);
    if err.contains("no Vulkan") && std::env::var_os("CI").is_none() {
        eprintln!("SKIPPED (no Vulkan device, CI not set): {err}");
        return;
    }
    assert!(out.status.success(), "info --pipelines failed: {text}\n{err}");
    assert!(text.contains("all created"), "{text}");
    for what in [
        "silhouette.wgsl:exact",
        "silhouette.wgsl:find",
        "shadow.vert depth LESS stencil",
        "fullscreen.vert + illuminate.frag",
        "render-pass",
    ] {
        assert!(text.contains(what), "no {what} in: {text}");
    }
    let lines = text.lines().filter(|l| l.trim_start().split("  ").next().is_some_and(|t| t.ends_with(" ms"))).count();
    let created = err.matches("umbrage: created pipeline").count();
    assert!(created >= 100, "only {created} pipelines traced");
    assert!(lines >= created, "{lines} timed lines for {created} creations");
}

/// `UMBRAGE_PIPELINE_CACHE=FILE`: the context's pipeline cache is saved there and loaded on the
/// next run; a torn file, or another device's (its header names another
/// `pipelineCacheUUID`), is ignored, never handed to the driver; `off` makes no cache.
#[test]
fn the_pipeline_cache_file_round_trips_and_ignores_foreign_data() {
    let d = tmp("pipeline-cache");
    let file = d.join("pipelines.bin");
    let render = |cache: &str| {
        Command::new(common::exe::umbrage_exe())
            .args(["render", "--size", "64x48", "--out"])
            .arg(d.join("out.png"))
            .env("UMBRAGE_VALIDATION", "1")
            .env("UMBRAGE_PIPELINE_CACHE", cache)
            .output()
            .unwrap()
    };
    let first = render(file.to_str().unwrap());
    let err = String::from_utf8_lossy(&first.stderr);
    if err.contains("no Vulkan") && std::env::var_os("CI").is_none() {
        eprintln!("SKIPPED (no Vulkan device, CI not set): {err}");
        return;
    }
    assert!(first.status.success(), "{err}");
    let saved = std::fs::read(&file).expect("the cache file is written");
    assert!(saved.len() >= 32 && saved[..4] == 32u32.to_le_bytes() && saved[4..8] == 1u32.to_le_bytes(), "{} bytes", saved.len());
    // Loaded again: the same picture.
    let png = std::fs::read(d.join("out.png")).unwrap();
    assert!(render(file.to_str().unwrap()).status.success());
    assert_eq!(std::fs::read(d.join("out.png")).unwrap(), png);
    // Another device's cache (its UUID changed) and a torn file: ignored, the same picture.
    let mut foreign = saved.clone();
    foreign[16] ^= 0xff;
    for (what, bytes) in [("foreign", foreign), ("torn", saved[..20].to_vec()), ("garbage", vec![0xa5; 4096])] {
        std::fs::write(&file, &bytes).unwrap();
        let out = render(file.to_str().unwrap());
        assert!(out.status.success(), "{what}: {}", String::from_utf8_lossy(&out.stderr));
        assert_eq!(std::fs::read(d.join("out.png")).unwrap(), png, "{what}");
        let rewritten = std::fs::read(&file).unwrap();
        assert!(rewritten.len() >= 32 && rewritten[16..32] == saved[16..32], "{what}: this device's cache replaces it");
    }
    assert!(render("off").status.success());
    let _ = std::fs::remove_dir_all(&d);
}

/// `--method mesh` on a device without `VK_EXT_mesh_shader` (Mesa lavapipe 22.3.6): a clear
/// error naming the extension and how to get a driver that has it, from the command line and
/// as the library's `Error::Unsupported`.
#[test]
fn mesh_without_the_extension_names_it_and_the_driver_script() {
    use umbrage::pass::{Capabilities, PassSettings, Technique};
    let s = PassSettings { technique: Technique::Mesh, ..Default::default() };
    let e = s.check(&Capabilities::default()).unwrap_err();
    assert!(matches!(e, umbrage::Error::Unsupported(_)), "{e:?}");
    let text = e.to_string();
    assert!(text.contains("VK_EXT_mesh_shader") && text.contains("scripts/drivers.sh install 25.0.7"), "{text}");
    let Some(env) = common::driver_env("22.3.6") else {
        let why = "Mesa lavapipe 22.3.6 is not installed (scripts/drivers.sh install 22.3.6)";
        assert!(std::env::var_os("CI").is_none(), "CI needs {why}");
        eprintln!("SKIPPED: {why}");
        return;
    };
    let d = tmp("mesh");
    let mut c = Command::new(common::exe::umbrage_exe());
    c.args(["render", "--method", "mesh", "--size", "64x48", "--out", d.join("mesh.png").to_str().unwrap()]).env("UMBRAGE_VALIDATION", "1");
    common::apply_driver_env(&mut c, &env);
    let out = c.output().unwrap();
    fails_with(&out, "VK_EXT_mesh_shader");
    fails_with(&out, "scripts/drivers.sh install 25.0.7");
    assert!(!d.join("mesh.png").exists(), "nothing is written");
}
