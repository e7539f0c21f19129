//! `umbrage bench --suite fill-vertex` end to end at the tiny test size (two points a sweep,
//! 160x90; the hidden `--tiny`): the bench.json contract (issue #10's keys), the CSV, the
//! Markdown and the SVG + PNG plots, under validation.

use crate::common;
use std::process::Command;

fn keys(v: &serde_json::Value, want: &[&str], what: &str) {
    let o = v.as_object().unwrap_or_else(|| panic!("{what} is not an object"));
    for k in want {
        assert!(o.contains_key(*k), "{what} lacks '{k}'");
    }
}

#[test]
fn tiny_suite_writes_the_contract_and_the_plots() {
    let v = tiny_suite("system", &[]);
    if v.is_null() {
        return;
    }
    // A technique the device cannot run is listed as not measured, with why, and never rowed.
    let techniques: Vec<&str> = v["techniques"].as_array().unwrap().iter().filter_map(|t| t.as_str()).collect();
    for (t, why) in v["not_measured"].as_object().unwrap() {
        assert!(!techniques.contains(&t.as_str()), "{t} both measured and not");
        assert!(why.as_str().unwrap().contains("scripts/drivers.sh") || t == "rayquery", "{t}: {why}");
        assert!(!v["rows"].as_array().unwrap().iter().any(|r| r["method"] == t.as_str()), "rows of {t}, not measured");
    }
    assert!(techniques.contains(&"mesh") != v["not_measured"].get("mesh").is_some(), "mesh neither measured nor said not to be");
}

/// The same on lavapipe 25.0.7, where ray query joins the technique list: its rows carry the
/// acceleration structures' times, and the model fits them with the others.
#[test]
fn tiny_suite_on_lavapipe_25_has_ray_query_rows() {
    let Some(driver) = common::lavapipe_25_env() else {
        assert!(std::env::var_os("CI").is_none(), "CI needs lavapipe 25.0.7 (scripts/drivers.sh install 25.0.7)");
        eprintln!("SKIPPED: lavapipe 25.0.7 is not installed (scripts/drivers.sh install 25.0.7)");
        return;
    };
    let v = tiny_suite("lavapipe-25", &driver);
    assert!(!v.is_null(), "lavapipe 25.0.7 is installed but gave no Vulkan device");
    let rows = v["rows"].as_array().unwrap();
    let rays: Vec<_> = rows.iter().filter(|r| r["method"] == "rayquery").collect();
    assert!(rays.len() >= 10, "{} rayquery rows", rays.len());
    assert!(rays.iter().all(|r| r["model_rel_error"].is_number()), "rayquery rows outside the model");
    // The fit has a ray term (its value is a timing: not asserted; the fitting itself is tested
    // on synthetic rows in umbrage-bench's model tests).
    assert!(v["model"]["coefficients"]["rays"].is_number(), "no ray term in the model");
    // Mesh shaders (issue #37): timed at every point, fitted by a family of their own.
    let mesh: Vec<_> = rows.iter().filter(|r| r["method"] == "mesh").collect();
    assert!(mesh.len() >= 10, "{} mesh rows", mesh.len());
    assert!(
        mesh.iter().all(|r| r["model_rel_error"].is_number() && r["gpu_shadow_ms"].as_f64().is_some_and(|t| t > 0.0)),
        "mesh rows untimed or outside the model"
    );
    assert!(mesh.iter().all(|r| r["caster_passes"].as_u64().unwrap() > 0), "mesh rows without caster passes");
    for term in ["mesh_triangles", "caster_passes_mesh"] {
        assert!(v["model"]["coefficients"][term].is_number(), "no {term} term");
    }
    assert!(v["not_measured"].get("mesh").is_none() && v["techniques"].as_array().unwrap().iter().any(|t| t == "mesh"));
}

/// Runs the tiny suite with `driver`'s environment (each variable set, or removed where
/// `None`) under validation, checks its contract and outputs, and returns its bench.json.
fn tiny_suite(tag: &str, driver: &[(String, Option<String>)]) -> serde_json::Value {
    // One suite at a time: two running side by side (the test harness runs this file's tests
    // in parallel) time each other on a 2-core machine, and the model's fit on such noisy
    // rows once identified no term at all (a fresh-clone CI run, 2026-12-07).
    static ONE_SUITE: std::sync::Mutex<()> = std::sync::Mutex::new(());
    let _one = ONE_SUITE.lock().unwrap_or_else(|e| e.into_inner());
    let dir = std::env::temp_dir().join(format!("umbrage-suite-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let mut c = Command::new(common::exe::umbrage_exe());
    c.args(["bench", "--suite", "fill-vertex", "--quick", "--tiny", "--out", dir.to_str().unwrap()]).env("UMBRAGE_VALIDATION", "1");
    common::apply_driver_env(&mut c, driver);
    let out = c.output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    if !out.status.success() && std::env::var_os("CI").is_none() && err.contains("Vulkan") {
        eprintln!("SKIPPED (no Vulkan device, CI not set): {err}");
        return serde_json::Value::Null;
    }
    assert!(out.status.success(), "suite failed: {err}");
    assert!(!err.contains("panicked"), "{err}");
    let text = std::fs::read_to_string(dir.join("bench.json")).unwrap();
    let v: serde_json::Value = serde_json::from_str(&text).unwrap();
    keys(
        &v,
        &["device", "driver", "limits", "rows", "crossovers", "ablations", "plots", "phases", "techniques", "not_measured"],
        "bench.json",
    );
    phases(&v);
    let limits = &v["limits"];
    const RATES: [&str; 10] = [
        "stencil_fill_gfrag_s",
        "color_fill_gfrag_s",
        "small_tri_mtri_s",
        "big_tri_mtri_s",
        "draws_per_s",
        "cpu_stream_gib_s",
        "compute_read_gib_s",
        "lighting_gpix_s",
        "gbuffer_tri_mtri_s",
        "gbuffer_fill_gpix_s",
    ];
    keys(limits, &[&RATES[..], &["units"]].concat(), "limits");
    for k in RATES {
        let x = limits[k].as_f64().unwrap_or(0.0);
        assert!(x.is_finite() && x > 0.0, "limit {k} = {x}");
    }
    // The pass limits come with their sweeps and units.
    for k in ["lighting_gpix_s", "gbuffer_tri_mtri_s", "gbuffer_fill_gpix_s"] {
        assert!(limits["sweeps"][k].as_array().is_some_and(|s| !s.is_empty()), "sweep of {k}");
        assert!(limits["units"][k].is_string(), "unit of {k}");
    }
    let rows = v["rows"].as_array().unwrap();
    let contract = [
        "suite",
        "scene",
        "method",
        "counter",
        "width",
        "height",
        "triangles",
        "lights",
        "gpu_shadow_ms",
        "gpu_frame_ms",
        "stencil_fragments",
        "shadow_triangles",
        "cpu_plan_ms",
        "bytes",
        "error_fraction",
        "fill_fraction",
        "vertex_fraction",
        "bound",
    ];
    assert!(!rows.is_empty());
    for r in rows {
        keys(r, &contract, "row");
        keys(&r["limits"], &["stencil_fill_gfrag_s", "small_tri_mtri_s", "draws_per_s"], "row limits");
        let bound = r["bound"].as_str().unwrap();
        assert!(["fill", "vertex", "draw", "cpu"].contains(&bound), "bound {bound}");
        keys(r, &["gpu_shadow_ms_p10", "gpu_shadow_ms_p90", "predicted_shadow_ms", "bound_clear", "fixed_fraction"], "row");
        // Acceleration-structure times belong to ray-query rows only (and are timed there).
        let rays = r["method"] == "rayquery";
        for k in ["gpu_tlas_ms", "blas_build_ms"] {
            assert_eq!(r[k].as_f64().is_some_and(|ms| ms > 0.0), rays, "{k} on a {} row: {}", r["method"], r[k]);
        }
        let (lo, mid, hi) =
            (r["gpu_shadow_ms_p10"].as_f64().unwrap(), r["gpu_shadow_ms"].as_f64().unwrap(), r["gpu_shadow_ms_p90"].as_f64().unwrap());
        assert!(lo <= mid && mid <= hi, "spread {lo} {mid} {hi}");
        // The model's shares of the time: none above the time, together at most all of it.
        let share: f64 =
            ["fill_fraction", "vertex_fraction", "draw_fraction", "fixed_fraction"].iter().map(|k| r[*k].as_f64().unwrap()).sum();
        assert!(share <= 1.0 + 1e-9 && share > 0.0, "fractions sum to {share}");
        if r["method"].as_str().unwrap().starts_with("shadowmap") {
            let (map, lookup) = (r["gpu_map_ms"].as_f64().unwrap(), r["gpu_lookup_ms"].as_f64().unwrap());
            assert!(map > 0.0 && lookup > 0.0, "shadow map split {map} + {lookup}");
        }
    }
    // Every sweep and every technique is there.
    for s in ["scenes", "resolution", "tessellation", "lights", "light_distance", "casters", "caps", "ablation"] {
        assert!(rows.iter().any(|r| r["sweep"] == s), "no {s} rows");
    }
    one_factor_sweeps(rows);
    sides_and_ray_steps(rows);
    identifiability(&v["model"]);
    bound_proofs(&v);
    let methods: Vec<&str> = rows.iter().filter(|r| r["sweep"] == "tessellation").filter_map(|r| r["method"].as_str()).collect();
    for m in ["zpass", "zfail", "everitt-kilgard", "lengyel", "mcguire", "zpass-clear", "edgequad", "planar", "shadowmap-512"] {
        assert!(methods.contains(&m), "tessellation sweep lacks {m}");
    }
    // The named scenes carry their error; volumes rasterise counted fragments.
    assert!(rows.iter().filter(|r| r["sweep"] == "scenes").all(|r| r["error_fraction"].is_number()));
    assert!(rows.iter().any(|r| r["method"] == "mcguire" && r["stencil_fragments"].as_u64().unwrap_or(0) > 0));
    // Ablations: scissor and culling measured as ratios.
    let abl = v["ablations"].as_array().unwrap();
    for what in ["scissor", "culling", "index-format"] {
        assert!(abl.iter().any(|a| a["what"] == what && a["time_ratio"].is_number()), "ablation {what}");
    }
    // Outputs.
    let csv = std::fs::read_to_string(dir.join("bench.csv")).unwrap();
    assert_eq!(csv.lines().count(), rows.len() + 1);
    assert!(csv.lines().next().unwrap().starts_with("suite,sweep,x,"));
    // The cost model, checked on held-out rows.
    let model = &v["model"];
    keys(model, &["form", "coefficients", "median_rel_error", "p80_rel_error"], "model");
    assert!(model["coefficients"].as_object().unwrap().values().all(|c| c.as_f64().unwrap() >= 0.0));
    assert!(model["median_rel_error"].as_f64().unwrap().is_finite());
    // The run's repeatability beside it: the rows two sweeps share, measured twice.
    keys(&model["repeat"], &["pairs", "median_rel_diff", "over_30_percent"], "model.repeat");
    assert!(model["repeat"]["pairs"].as_u64().unwrap() > 0, "no row measured twice");
    // The named scenes read each shadow map with taps and with gathers: the same error.
    let error_of = |m: &str| rows.iter().find(|r| r["sweep"] == "scenes" && r["method"] == m).map(|r| r["error_fraction"].clone());
    assert!(error_of("shadowmap-512-gather").is_some(), "no gather row");
    assert_eq!(error_of("shadowmap-512"), error_of("shadowmap-512-gather"), "taps and gathers disagree");
    keys(limits, &["setup_tri_mtri_s", "clip_tri_mtri_s", "sweeps"], "limits");
    plots_and_report(&dir);
    let _ = std::fs::remove_dir_all(&dir);
    v
}

/// The suite's plots (SVG and PNG, each more than 1000 bytes) and bench.md's sections.
fn plots_and_report(dir: &std::path::Path) {
    for p in ["time_vs_triangles", "time_vs_resolution", "roofline", "pareto", "model_fit"] {
        for ext in ["svg", "png"] {
            let f = dir.join(format!("{p}.{ext}"));
            let len = std::fs::metadata(&f).map(|m| m.len()).unwrap_or(0);
            assert!(len > 1000, "{} missing or empty", f.display());
        }
    }
    let svg = std::fs::read_to_string(dir.join("time_vs_triangles.svg")).unwrap();
    assert!(svg.contains("<svg") && svg.contains("mcguire"), "the SVG has a legend");
    let png = std::fs::read(dir.join("roofline.png")).unwrap();
    assert_eq!(&png[1..4], b"PNG");
    let md = std::fs::read_to_string(dir.join("bench.md")).unwrap();
    assert!(md.contains("## Limits") && md.contains("## Crossovers") && md.contains("## Ablations"));
    assert!(md.contains("## What the rows identify") && md.contains("## Bounds proven by ablation") && md.contains("### Disagreements"));
    assert!(md.contains("## Cost model") && md.contains("## Shadow maps: map against lookup") && md.contains("## The paper's claim"));
    assert!(md.contains("## Separate against merged casters") && md.contains("| mcguire |"), "no separate-against-merged pair");
    assert!(md.contains("## The frame's other passes against their limits") && md.contains("- `default`: the lighting pass is "));
    assert!(md.contains("| phase | wall s | CPU s |"), "no phases table");
}

/// The one-factor sweeps (issue #38): each moves one count while the others stay.
/// The model's sliver and ray-step counts: sides to infinity are the volumes' own sides (none
/// for planar projection, shadow maps and ray query); edge quads take those of the McGuire
/// volumes of the same frame (every other quad of theirs is degenerate), ray query their
/// stencil fragments.
fn sides_and_ray_steps(rows: &[serde_json::Value]) {
    let u = |r: &serde_json::Value, k: &str| r[k].as_u64().unwrap_or_else(|| panic!("{k}: {}", r[k]));
    let twin = |r: &serde_json::Value| {
        rows.iter().find(|m| {
            m["method"] == "mcguire" && ["sweep", "x", "scene", "variant", "width", "height", "lights"].iter().all(|k| m[*k] == r[*k])
        })
    };
    let (mut quads, mut rays) = (0, 0);
    for r in rows {
        let method = r["method"].as_str().unwrap();
        let what = format!("{} {} {method}", r["sweep"], r["scene"]);
        match method {
            "planar" | "rayquery" => assert_eq!(u(r, "infinite_sides"), 0, "{what}"),
            m if m.starts_with("shadowmap") => assert_eq!(u(r, "infinite_sides"), 0, "{what}"),
            "edgequad" => {
                if let Some(m) = twin(r) {
                    assert_eq!(u(r, "infinite_sides"), u(m, "shadow_sides"), "{what}: not the McGuire silhouette's sides");
                    quads += 1;
                }
            }
            _ => assert_eq!(u(r, "infinite_sides"), u(r, "shadow_sides"), "{what}"),
        }
        if method == "rayquery" {
            let m = twin(r).unwrap_or_else(|| panic!("{what}: no McGuire row beside it"));
            assert_eq!(r["volume_fragments"], m["stencil_fragments"], "{what}: not the McGuire volumes' fragments");
            rays += 1;
        } else {
            assert!(r["volume_fragments"].is_null(), "{what}: volume fragments outside ray query");
        }
    }
    assert!(quads > 0, "no edge-quad row beside a McGuire one");
    assert!(rays == 0 || rows.iter().any(|r| r["method"] == "rayquery" && r["volume_fragments"].as_u64().unwrap_or(0) > 0));
}

fn one_factor_sweeps(rows: &[serde_json::Value]) {
    let of = |sweep: &str, method: &str| -> Vec<&serde_json::Value> {
        rows.iter().filter(|r| r["sweep"] == sweep && r["method"] == method).collect()
    };
    let u = |r: &serde_json::Value, k: &str| r[k].as_u64().unwrap_or_else(|| panic!("{k} of {r}"));
    for m in ["mcguire", "zpass", "shadowmap-512"] {
        // Casters at fixed triangles: the same caster triangles as 1 and as many casters.
        let c = of("casters_same_triangles", m);
        assert!(c.len() >= 2, "casters_same_triangles {m}: {} rows", c.len());
        assert!(c.iter().all(|r| u(r, "triangles") == u(c[0], "triangles")), "casters_same_triangles moves the triangles");
        let casters: Vec<u64> = c.iter().map(|r| u(r, "casters")).collect();
        assert!(casters.contains(&1) && casters.iter().any(|n| *n > 1), "{casters:?}");
        // Triangles at fixed casters.
        let t = of("triangles_same_casters", m);
        assert!(t.len() >= 2 && t.iter().all(|r| u(r, "casters") == u(t[0], "casters")));
        assert!(t.windows(2).all(|w| u(w[0], "triangles") < u(w[1], "triangles")), "tessellation does not grow");
        // Coverage at fixed triangles and casters.
        let f = of("coverage_same_triangles", m);
        assert!(f.len() >= 2 && f.iter().all(|r| u(r, "casters") == u(f[0], "casters") && u(r, "triangles") == u(f[0], "triangles")));
    }
    // For the volumes, the casters sweep moves the (light, caster) passes (edge quads' draws
    // too; the CPU-planned volumes draw per connected part, merged or not) and the coverage
    // sweep the fragments.
    let c = of("casters_same_triangles", "mcguire");
    assert!(u(c[0], "caster_passes") != u(c[c.len() - 1], "caster_passes"), "merging casters leaves the caster passes");
    let e = of("casters_same_triangles", "edgequad");
    assert!(u(e[0], "draws") != u(e[e.len() - 1], "draws"), "merging casters leaves the edge quads' draws");
    let f = of("coverage_same_triangles", "mcguire");
    assert!(u(f[0], "stencil_fragments") != u(f[f.len() - 1], "stencil_fragments"), "the light's height leaves the fragments");
}

/// `phases`: where the run's time went, every phase timed, their wall seconds within the run's.
fn phases(v: &serde_json::Value) {
    let phases = v["phases"].as_array().unwrap();
    let names: Vec<&str> = phases.iter().filter_map(|p| p["name"].as_str()).collect();
    for n in ["limits", "scenes", "resolution", "casters_same_triangles", "ablation", "model", "proofs", "plots"] {
        assert!(names.contains(&n), "no phase {n}: {names:?}");
    }
    let wall: f64 = phases.iter().map(|p| p["wall_s"].as_f64().unwrap()).sum();
    assert!(wall > 0.0 && wall <= v["seconds"].as_f64().unwrap() + 1e-6, "phases {wall} s of {}", v["seconds"]);
    // The one-factor sweeps take their centre point from each other: measured once.
    let shared: u64 = phases.iter().map(|p| p["shared_points"].as_u64().unwrap()).sum();
    assert!(shared >= 1, "no point shared");
}

/// `model.identifiability`: the keys of issue #38, and verdicts that follow the intervals and
/// the confounded pairs.
fn identifiability(model: &serde_json::Value) {
    let id = &model["identifiability"];
    keys(
        id,
        &["bootstrap_resamples", "coefficients", "condition_number", "confounded_pairs", "max_ci_ratio", "confounded_at"],
        "identifiability",
    );
    assert_eq!(id["bootstrap_resamples"].as_u64(), Some(200));
    let ratio = id["max_ci_ratio"].as_f64().unwrap();
    let at = id["confounded_at"].as_f64().unwrap();
    let pairs = id["confounded_pairs"].as_array().unwrap();
    for p in pairs {
        keys(p, &["a", "b", "correlation"], "confounded pair");
        assert!(p["correlation"].as_f64().unwrap().abs() >= at, "{p}");
    }
    let coefficients = id["coefficients"].as_array().unwrap();
    assert_eq!(coefficients.len(), model["coefficients"].as_object().unwrap().len(), "a verdict per term");
    let mut identified = 0;
    for c in coefficients {
        keys(c, &["term", "value", "ci_low", "ci_high", "identified"], "coefficient");
        let term = c["term"].as_str().unwrap();
        let value = c["value"].as_f64().unwrap();
        assert!((value - model["coefficients"][term].as_f64().unwrap()).abs() <= 1e-9 * value.abs().max(1.0), "{term}: another value");
        if c["identified"] == true {
            identified += 1;
            let (lo, hi) = (c["ci_low"].as_f64().unwrap(), c["ci_high"].as_f64().unwrap());
            assert!(lo > 0.0 && hi <= ratio * lo * (1.0 + 1e-12) && lo <= hi, "{term} identified with [{lo}, {hi}]");
            assert!(!pairs.iter().any(|p| p["a"] == term || p["b"] == term), "{term} identified yet confounded");
        } else {
            assert!(!c["reason"].as_str().unwrap().is_empty(), "{term}: no reason");
        }
    }
    // Whether the rows identify a term depends on the timings (noise): not asserted. Each
    // coefficient's verdict is checked above, and the counting below.
    assert!(identified <= model["identifiability"]["coefficients"].as_array().map_or(0, |c| c.len()));
}

/// Every claimed bound has its ablation, and `confirmed` follows the measured saving, the
/// predicted one and the spread.
fn bound_proofs(v: &serde_json::Value) {
    let rows = v["rows"].as_array().unwrap();
    let (mut claimed, mut ablated, mut confirmed) = (0u64, 0u64, 0u64);
    let (mut refuted, mut from_sweep) = (0u64, 0u64);
    for r in rows {
        keys(r, &["ablation", "bound_confirmed", "unidentified_fraction", "bound_shares", "measured_in"], "row");
        let what = format!("{} {} {} {}", r["sweep"], r["scene"], r["method"], r["variant"]);
        // A shared point's copy in a one-factor sweep carries its measurement's verdict; the
        // summary counts each measurement once.
        if r["measured_in"] != "" {
            let twin = rows.iter().find(|o| {
                o["sweep"] == r["measured_in"] && o["scene"] == r["scene"] && o["method"] == r["method"] && o["width"] == r["width"]
            });
            let twin = twin.unwrap_or_else(|| panic!("{what}: no row measured in {}", r["measured_in"]));
            assert_eq!(twin["gpu_shadow_ms"], r["gpu_shadow_ms"], "{what}: a copy with other timings");
            assert_eq!(twin["ablation"], r["ablation"], "{what}: a copy with another verdict");
            continue;
        }
        let a = &r["ablation"];
        let provable = r["bound_clear"] == true && ["fill", "vertex", "draw"].contains(&r["bound"].as_str().unwrap());
        if !provable {
            assert!(a.is_null(), "{what}: an ablation without a claimed bound");
            assert_eq!(r["bound_confirmed"], false, "{what}");
            continue;
        }
        claimed += 1;
        keys(a, &["kind", "predicted_saving_ms", "measured_saving_ms", "confirmed", "spread_ms"], "ablation");
        assert_eq!(a["kind"], r["bound"], "{what}: ablation of another bound");
        assert_eq!(a["confirmed"], r["bound_confirmed"], "{what}");
        let (Some(p), Some(m), Some(s)) = (a["predicted_saving_ms"].as_f64(), a["measured_saving_ms"].as_f64(), a["spread_ms"].as_f64())
        else {
            assert_eq!(a["confirmed"], false, "{what}: confirmed without a measurement");
            continue;
        };
        ablated += 1;
        let agrees = s > 0.0 && m > s && (m - p).abs() <= s;
        assert_eq!(a["confirmed"].as_bool(), Some(agrees), "{what}: predicted {p}, measured {m}, spread {s}");
        confirmed += agrees as u64;
        refuted += !agrees as u64;
        from_sweep += (a["from_sweep"] == true) as u64;
        let (b, x) = (a["baseline_ms"].as_f64().unwrap(), a["ablated_ms"].as_f64().unwrap());
        assert!((b - x - m).abs() < 1e-9, "{what}: measured saving is not baseline less ablated");
    }
    let summary = &v["bound_proofs"];
    assert_eq!(summary["claimed"].as_u64(), Some(claimed), "bound_proofs.claimed");
    assert_eq!(summary["ablated"].as_u64(), Some(ablated), "bound_proofs.ablated");
    assert_eq!(summary["confirmed"].as_u64(), Some(confirmed), "bound_proofs.confirmed");
    assert_eq!(summary["refuted"].as_u64(), Some(refuted), "bound_proofs.refuted");
    assert_eq!(summary["from_sweep"].as_u64(), Some(from_sweep), "bound_proofs.from_sweep");
    // A bound is claimed only where confirmed: every bold bound cell is a confirmed row's.
    for r in rows.iter().filter(|r| r["bound_confirmed"] == true) {
        assert_eq!(r["ablation"]["confirmed"], true, "{r}");
    }
    // How many bounds are ablated follows from the timings: not asserted (a CI run failed on it,
    // 0b52c50); the summary's counts agree with the rows above.
    // Bound crossovers join confirmed bounds only.
    for c in v["crossovers"].as_array().unwrap().iter().filter(|c| c["kind"] == "bound") {
        let confirmed_at = |x: f64| {
            rows.iter().any(|r| {
                r["sweep"] == c["sweep"] && r["method"] == c["method"] && r["x"].as_f64() == Some(x) && r["bound_confirmed"] == true
            })
        };
        let between = c["between"].as_array().unwrap();
        assert!(confirmed_at(between[0].as_f64().unwrap()) && confirmed_at(between[1].as_f64().unwrap()), "{c}");
    }
}

#[test]
fn suite_refuses_bad_arguments() {
    let out = Command::new(common::exe::umbrage_exe()).args(["bench", "--suite", "no-such-suite"]).output().unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("no-such-suite") && !err.contains("panicked"), "{err}");
}

/// The committed quick-suite report (`docs/bench/`, `docs/bench-lavapipe.md`) meets what the
/// suite promises, and the README quotes it: no row's fill or vertex fraction above 1.15, every
/// timed row with its spread, shadow-map rows split into map and lookup; issue #38's done-when
/// (a bound is claimed only where its ablation confirmed it, every refuted candidate listed,
/// the separate-against-merged pair side by side, unidentified terms flagged, the lighting
/// pass against its limit) and issue #37's (mesh timed where the driver has it, or said not to
/// be). The timing promises — under 8 minutes on 2 cores, the model's held-out share within
/// 30 % at least 80 % — are a quiet machine's: they are held where the run's load average
/// stayed within its CPU threads (the report records it at the start, at every phase's end and
/// at the end); on a busier run the suite must still have fitted 8 minutes of 2 cores' CPU
/// time. Regenerating the report without updating the README fails here.
#[test]
fn the_committed_report_keeps_its_promises() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(root.join("docs/bench/bench.json")).unwrap();
    let v: serde_json::Value = serde_json::from_str(&text).unwrap();
    assert_eq!(v["scale"], "quick", "docs/bench is not a --quick run");
    let md = std::fs::read_to_string(root.join("docs/bench-lavapipe.md")).unwrap();
    assert_eq!(
        md,
        std::fs::read_to_string(root.join("docs/bench/bench.md")).unwrap().replace("](./", "](bench/"),
        "docs/bench-lavapipe.md is not docs/bench/bench.md's run"
    );
    let seconds = v["seconds"].as_f64().unwrap();
    let cpu = v["cpu_seconds"].as_f64().unwrap();
    let threads = v["cpu_threads"].as_f64().unwrap();
    let loads: Vec<f64> = [&v["load_average_start"], &v["load_average"]]
        .into_iter()
        .chain(v["phases"].as_array().unwrap().iter().map(|p| &p["load_average"]))
        .map(|l| l.as_f64().unwrap())
        .collect();
    let quiet = loads.iter().all(|l| *l <= threads);
    assert!(cpu < 480.0 * threads, "the quick suite used {cpu:.0} CPU seconds: over 8 minutes of {threads} cores");
    let within = v["model"]["within_30_percent"].as_f64().unwrap();
    if quiet {
        assert!(seconds < 480.0, "the quick suite took {seconds:.0} s (over 8 minutes) on a quiet machine");
        assert!(within >= 0.8, "the model predicts {:.0} % of rows within 30 % on a quiet machine", within * 100.0);
    } else {
        eprintln!("docs/bench ran on a busy machine (load averages {loads:?} on {threads} threads): its wall time ({seconds:.0} s) and the model's share within 30 % ({:.0} %) are not the quiet machine's promises", within * 100.0);
    }
    let rows = v["rows"].as_array().unwrap();
    for r in rows {
        let what = format!("{} {} {} {}", r["sweep"], r["scene"], r["method"], r["variant"]);
        for k in ["fill_fraction", "vertex_fraction"] {
            let f = r[k].as_f64().unwrap_or(0.0);
            assert!(f <= 1.15, "{what}: {k} {f}");
        }
        if let Some(mid) = r["gpu_shadow_ms"].as_f64() {
            let (lo, hi) = (r["gpu_shadow_ms_p10"].as_f64().unwrap(), r["gpu_shadow_ms_p90"].as_f64().unwrap());
            assert!(lo <= mid && mid <= hi, "{what}: spread {lo} {mid} {hi}");
            if r["method"].as_str().unwrap().starts_with("shadowmap") {
                let (map, lookup) = (r["gpu_map_ms"].as_f64().unwrap(), r["gpu_lookup_ms"].as_f64().unwrap());
                assert!(map > 0.0 && lookup > 0.0, "{what}: map {map} ms, lookup {lookup} ms");
            }
        }
        // Claimed means confirmed: a bound shown in bold is a confirmed ablation's, and every
        // candidate's ablation that ran and refuted it is listed with its savings.
        let a = &r["ablation"];
        if r["bound_confirmed"] == true {
            assert_eq!(a["confirmed"], true, "{what}: claimed without its ablation");
        }
        if r["measured_in"] == "" && a["confirmed"] == false && a["predicted_saving_ms"].is_number() {
            let listed = format!(
                "| {} | {} | {} | {} |",
                r["sweep"].as_str().unwrap(),
                r["scene"].as_str().unwrap(),
                r["variant"].as_str().unwrap(),
                r["method"].as_str().unwrap()
            );
            assert!(md.contains(&listed), "{what}: a refuted candidate the report does not list");
        }
    }
    assert!(md.contains("**A bound is claimed only where its ablation in this run confirmed it.**"));
    assert!(md.contains("### Disagreements: candidates refuted by their ablation"));
    // The separate-against-merged pair, every technique side by side.
    let merged = md.split("## Separate against merged casters").nth(1).expect("no separate-against-merged section");
    let merged = merged.split("\n## ").next().unwrap();
    for m in ["| mcguire |", "| compute |", "| edgequad |", "| zfail |"] {
        assert!(merged.contains(m), "the merged pair lacks {m}");
    }
    // Unidentified terms flagged, each with why.
    for c in v["model"]["identifiability"]["coefficients"].as_array().unwrap().iter().filter(|c| c["identified"] == false) {
        let line = format!("| {} |", c["term"].as_str().unwrap());
        assert!(md.lines().any(|l| l.starts_with(&line) && l.contains("| no |")), "{line}: not flagged in the report");
    }
    // The lighting pass against its limit, measured in the same run, with the verdict.
    let passes = md.split("## The frame's other passes against their limits").nth(1).expect("no frame passes section");
    for scene in ["- `default`: the lighting pass is ", "- `bench/fill`: the lighting pass is "] {
        assert!(passes.contains(scene), "{scene}...: no verdict");
    }
    assert!(v["limits"]["lighting_shaded_one_draw_gpix_s"].as_f64().unwrap() > 0.0);
    // Mesh shaders: measured on a driver that has them, otherwise said not to be, and why.
    let mesh_rows = rows.iter().filter(|r| r["method"] == "mesh").count();
    match v["not_measured"].get("mesh") {
        Some(why) => assert!(mesh_rows == 0 && md.contains(&format!("**Not measured: `mesh`** — {}", why.as_str().unwrap()))),
        None => assert!(mesh_rows > 20 && v["model"]["coefficients"]["caster_passes_mesh"].is_number(), "{mesh_rows} mesh rows"),
    }
    // The prose that quotes the report (docs/tour.md; the README links the report) says what it measured.
    let readme = std::fs::read_to_string(root.join("docs/tour.md")).unwrap();
    let quoted = format!("{:.0} % of rows within 30 %", within * 100.0);
    assert!(readme.contains(&quoted), "docs/tour.md does not say '{quoted}' (docs/bench/bench.json's model)");
    let front = std::fs::read_to_string(root.join("README.md")).unwrap();
    assert!(front.contains("docs/bench-lavapipe.md"), "README.md does not link the benchmark's report");
    let driver = v["driver"].as_str().unwrap();
    let version = driver.split_whitespace().find(|w| w.chars().next().is_some_and(|c| c.is_ascii_digit())).unwrap_or(driver);
    let version = version.split('-').next().unwrap();
    assert!(
        readme.contains(&format!("lavapipe {version}")) && md.contains(version),
        "docs/tour.md does not name the report's driver {version}"
    );
}
