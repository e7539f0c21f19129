//! The conformance suite on lavapipe (or whatever device is present): the CLI's list, filter,
//! bad-input and JUnit contracts, the full suite once (0 failures, every skip explained), and
//! the test seam that breaks one stencil op in the expectation and the expected-failure lists
//! (crash isolation: `conform_pinning`).

use crate::common;

use ash::vk;
use std::collections::HashSet;
use std::path::{Path, PathBuf};
use std::process::Command;
use umbrage::gpu::Context;
use umbrage_conform as conform;
use umbrage_conform::{suite, Status, SuiteOptions};

fn umbrage() -> Command {
    let mut c = Command::new(common::exe::umbrage_exe());
    c.env("UMBRAGE_VALIDATION", "1").env_remove("UMBRAGE_CONFORM_BREAK").env_remove("UMBRAGE_DEVICE");
    c
}

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("umbrage-conform-test-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

fn json(dir: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(dir.join("conform.json")).unwrap()).unwrap()
}

#[test]
fn list_prints_every_case_name_once() {
    // The public names (docs/conform/driver-ci.md): `umbrage.` + the short name.
    let out = umbrage().args(["conform", "--list"]).output().unwrap();
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    let names: Vec<&str> = text.lines().collect();
    assert_eq!(names.len(), suite::all_names().len());
    assert!(names.len() >= 500, "{} cases", names.len());
    assert_eq!(names.iter().collect::<HashSet<_>>().len(), names.len(), "duplicate case names");
    assert!(names.contains(
        &"umbrage.stencil.d24s8.dynamic_rendering.static_state.zfail.front_dfail_decr_wrap.back_dfail_incr_wrap.comp_always.ref_0.masks_ff_ff"
    ));
    for fmt in ["d16s8", "d24s8", "d32s8", "s8"] {
        for model in
            ["dynamic_rendering.static_state", "dynamic_rendering.dynamic_state", "render_pass.static_state", "render_pass.dynamic_state"]
        {
            assert!(names.iter().any(|n| n.starts_with(&format!("umbrage.stencil.{fmt}.{model}."))), "{fmt}.{model}");
        }
    }
    // A filtered list is the matching subset.
    let out = umbrage().args(["conform", "--list", "--filter", "zoo.*.render_pass.*"]).output().unwrap();
    let sub = String::from_utf8(out.stdout).unwrap();
    assert!(!sub.is_empty());
    assert!(sub.lines().all(|n| n.starts_with("umbrage.zoo.") && n.contains(".render_pass.")));
}

#[test]
fn filter_matching_nothing_exits_2_with_a_message() {
    let out = umbrage().args(["conform", "--filter", "no.such.case"]).output().unwrap();
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("matches none"), "{err}");
    // The test seam's variable, misspelt: a clear error, not a silently unbroken run.
    let out = umbrage().args(["conform", "--filter", "zoo."]).env("UMBRAGE_CONFORM_BREAK", "frobnicate").output().unwrap();
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("unknown stencil op"));
}

#[test]
fn unknown_device_lists_the_devices() {
    let Some(_ctx) = common::context() else { return };
    let out = umbrage().args(["conform", "--device", "no-such-device-name"]).output().unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("the devices are"), "{err}");
    assert!(err.contains(&_ctx.info.name), "{err}");
}

#[test]
fn filter_runs_only_the_subset() {
    let Some(ctx) = common::context() else { return };
    let dir = tmp("subset");
    let pattern = "stencil.d32s8.render_pass";
    let out = umbrage().args(["conform", "--filter", pattern, "--device", &ctx.info.name, "--out"]).arg(&dir).output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stdout));
    let j = json(&dir);
    let cases = j["cases"].as_array().unwrap();
    let listed = suite::all_names().into_iter().filter(|n| n.contains(pattern)).count();
    assert_eq!(cases.len(), listed);
    assert!(cases.len() < suite::all_names().len() / 4);
    assert!(cases.iter().all(|c| c["name"].as_str().unwrap().contains(pattern)));
    assert_eq!(j["configs"].as_array().unwrap().len(), 2, "one submission per configuration");
    let _ = std::fs::remove_dir_all(&dir);
}

/// The expectation list of this driver when the repository has one
/// (`docs/conform/expectations/lavapipe-X.Y.Z.txt` for Mesa lavapipe X.Y.Z, `swiftshader.txt`
/// for SwiftShader): its failures and, pinned, its skips.
fn expectations_for(ctx: &Context) -> Option<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/conform/expectations");
    let path = if ctx.info.name.contains("SwiftShader") {
        dir.join("swiftshader.txt")
    } else if ctx.info.driver == "llvmpipe" {
        let (major, minor, patch) = umbrage::gpu::quirks::mesa_version(&ctx.info.driver_info)?;
        dir.join(format!("lavapipe-{major}.{minor}.{patch}.txt"))
    } else {
        return None;
    };
    path.exists().then_some(path)
}

/// The full suite, once: exit 0 with every case ending as the driver's expectation list says
/// (its failures, and its skips pinned, so that a pass turning into a skip fails: mutation-
/// checked by deleting one `Skip` line of lavapipe-22.3.6.txt, which fails this test with
/// "NEW SKIP"), every skip with a reason, no validation errors, and JUnit XML that parses and
/// agrees with the JSON. Under `CI` the driver must have a list; elsewhere a driver without
/// one keeps a floor of passes.
#[test]
fn full_suite_passes_and_writes_valid_junit() {
    let Some(ctx) = common::context() else { return };
    let dir = tmp("full");
    let junit = dir.join("junit.xml");
    let expectations = expectations_for(&ctx);
    assert!(
        expectations.is_some() || std::env::var_os("CI").is_none(),
        "no expectation list for {} ({}) under docs/conform/expectations: write one with scripts/conform-expectations.sh",
        ctx.info.name,
        ctx.info.driver_info
    );
    let mut cmd = umbrage();
    cmd.args(["conform", "--out"]).arg(&dir).arg("--junit").arg(&junit);
    if let Some(e) = &expectations {
        cmd.arg("--expect").arg(e);
    }
    let out = cmd.output().unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    println!("{stdout}");
    assert!(out.status.success(), "conform failed:\n{stdout}\n{}", String::from_utf8_lossy(&out.stderr));
    let j = json(&dir);
    assert_eq!(j["validation"], true);
    let cases = j["cases"].as_array().unwrap();
    let names: HashSet<&str> = cases.iter().map(|c| c["name"].as_str().unwrap()).collect();
    assert_eq!(names.len(), suite::all_names().len(), "every listed case is reported once");
    let count = |s: &str| cases.iter().filter(|c| c["status"] == s).count();
    match &expectations {
        Some(p) => {
            let e = conform::expect::Expectations::load(p).unwrap();
            assert!(e.pins_skips(), "{} lists no skips: regenerate them (scripts/conform-expectations.sh)", p.display());
            for c in cases {
                let name = c["name"].as_str().unwrap();
                let listed = e.listed(name).map(|s| s.name()).unwrap_or("pass");
                assert_eq!(c["status"].as_str().unwrap(), listed, "{name} against {}", p.display());
            }
            let v: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(dir.join("conform-expect.json")).unwrap()).unwrap();
            assert_eq!(v["ok"], true, "{v}");
            assert_eq!(v["expected_skips"], count("skipped"), "{v}");
        }
        None => {
            assert!(count("fail") == 0, "failures on a driver without a list");
            assert!(count("pass") >= 500, "{} passed", count("pass"));
        }
    }
    for c in cases.iter().filter(|c| c["status"] == "skipped") {
        assert!(!c["message"].as_str().unwrap().is_empty(), "skip without a reason: {}", c["name"]);
    }
    for cfg in j["configs"].as_array().unwrap() {
        assert_eq!(cfg["validation_errors"], 0, "{}", cfg["name"]);
    }
    // The pipeline cases still observe the known z-pass limitations (the check is live).
    assert!(cases.iter().any(|c| c["group"] == "pipeline" && c["message"].as_str().unwrap().starts_with("expected-failure")));

    // JUnit: well-formed XML, one testcase per case, skipped ones with their reason.
    let xml = std::fs::read_to_string(&junit).unwrap();
    let mut reader = quick_xml::Reader::from_str(&xml);
    let (mut testcases, mut skipped, mut failures, mut suites) = (0usize, 0usize, 0usize, 0usize);
    let mut elements = 0usize;
    let mut root_tests = None;
    loop {
        match reader.read_event().expect("JUnit XML must be well-formed") {
            quick_xml::events::Event::Eof => break,
            quick_xml::events::Event::Start(e) | quick_xml::events::Event::Empty(e) => {
                let attr = |k: &str| attr(&e, k);
                match e.name().as_ref() {
                    b"testsuites" => root_tests = attr("tests"),
                    b"testsuite" => suites += 1,
                    b"testcase" => {
                        testcases += 1;
                        assert!(attr("name").is_some() && attr("classname").is_some() && attr("time").is_some());
                    }
                    b"skipped" => {
                        skipped += 1;
                        assert!(!attr("message").unwrap_or_default().is_empty());
                    }
                    b"failure" => failures += 1,
                    _ => {}
                }
                elements += 1;
            }
            _ => {}
        }
    }
    assert!(elements > testcases);
    assert_eq!(testcases, cases.len());
    assert_eq!(root_tests.as_deref(), Some(cases.len().to_string().as_str()));
    assert_eq!(skipped, count("skipped"));
    assert_eq!(failures, count("fail"));
    assert!(suites >= 4);
    let _ = std::fs::remove_dir_all(&dir);
}

#[allow(deprecated)] // quick-xml's replacement (normalized_value) needs a version-specific signature
fn attr(e: &quick_xml::events::BytesStart, k: &str) -> Option<String> {
    e.attributes()
        .map(|a| a.expect("well-formed attribute"))
        .find(|a| a.key.as_ref() == k.as_bytes())
        .map(|a| a.unescape_value().expect("valid escapes").into_owned())
}

/// The test seam: an expectation with INCR_WRAP modelled as DECR_WRAP must fail exactly the
/// cases whose expected result that changes, each with its images written.
#[test]
fn broken_expectation_fails_exactly_the_affected_cases() {
    let Some(ctx) = common::context() else { return };
    let dir = tmp("broken");
    let filter: Vec<String> = [
        "stencil.d32s8.dynamic_rendering.dynamic_state",
        "zoo.d32s8.render_pass.static_state",
        "raster.d32s8.render_pass.static_state.occlusion",
    ]
    .map(String::from)
    .to_vec();
    let op = vk::StencilOp::INCREMENT_AND_WRAP;
    let opts = SuiteOptions { filter: filter.clone(), image_dir: Some(dir.clone()), break_op: Some(op), ..Default::default() };
    let report = conform::run_suite(&ctx, &|| Context::with_validation(true), &opts);
    let affected: HashSet<String> = suite::affected_by_break(op, &filter, ctx.limits.sub_pixel_precision_bits).into_iter().collect();
    let failed: HashSet<String> = report.failed().iter().map(|c| c.name.clone()).collect();
    assert!(!affected.is_empty());
    assert!(affected.len() < report.cases.len(), "the break must leave some cases unaffected");
    assert_eq!(failed, affected, "exactly the affected cases fail");
    for c in report.failed() {
        assert!(c.images.len() >= 3, "{}: {:?}", c.name, c.images);
        for p in &c.images {
            assert!(Path::new(p).is_file(), "{p}");
        }
        assert!(dir.join("failures").join(&c.name).join("diff.png").is_file());
    }
    assert!(report.cases.iter().filter(|c| !affected.contains(&c.name)).all(|c| c.status != Status::Fail));
    ctx.check_validation().unwrap();

    // The same seam through the command line: exit 1, one JUnit <failure> per affected case.
    let filter = "zoo.d24s8.dynamic_rendering.static_state";
    let junit = dir.join("cli.xml");
    let out = umbrage()
        .args(["conform", "--filter", filter, "--out"])
        .arg(dir.join("cli"))
        .arg("--junit")
        .arg(&junit)
        .env("UMBRAGE_CONFORM_BREAK", "incr_wrap")
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1), "{}", String::from_utf8_lossy(&out.stdout));
    let expected = suite::affected_by_break(op, &[filter.to_string()], ctx.limits.sub_pixel_precision_bits);
    let xml = std::fs::read_to_string(&junit).unwrap();
    assert_eq!(xml.matches("<failure ").count(), expected.len());
    for name in &expected {
        assert!(xml.contains(&format!("name=\"{name}\"")), "{name}");
        assert!(dir.join("cli").join("failures").join(name).join("expected.png").is_file(), "{name}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// `--expect`: a run is judged against the driver's list of expected failures, Mesa CI style:
/// listed crashes that happen are fine, a listed case that passes (and any unlisted failure)
/// is not.
#[test]
fn expectations_fail_on_any_change() {
    let Some(_ctx) = common::context() else { return };
    let dir = tmp("expect");
    std::fs::create_dir_all(&dir).unwrap();
    let filter = "zoo.*.render_pass.static_state.*";
    let names: Vec<String> = suite::all_names().into_iter().filter(|n| suite::matches(filter, n)).collect();
    let d24: Vec<&String> = names.iter().filter(|n| n.contains(".d24s8.")).collect();
    assert!(!d24.is_empty());
    let list = dir.join("fails.txt");
    let run = |list_text: String, crash: Option<&str>| {
        std::fs::write(&list, list_text).unwrap();
        let mut c = umbrage();
        c.args(["conform", "--filter", filter, "--out"]).arg(dir.join("out")).arg("--expect").arg(&list);
        if let Some(cr) = crash {
            c.env("UMBRAGE_CONFORM_CRASH", cr);
        }
        let out = c.output().unwrap();
        (out.status.code(), String::from_utf8_lossy(&out.stdout).to_string())
    };
    // Every d24s8 case crashes, and the list says so: a match.
    let crash_list: String = d24.iter().map(|n| format!("{n},Crash\n")).collect();
    let (code, stdout) = run(crash_list.clone(), Some("d24s8.render_pass.static_state:abort"));
    assert_eq!(code, Some(0), "{stdout}");
    assert!(
        stdout.contains(&format!("{} expected failures, 0 expected skips, 0 new failures, 0 unexpected passes", d24.len())),
        "{stdout}"
    );
    // The same list without the crash: every listed case is an unexpected pass.
    let (code, stdout) = run(crash_list, None);
    assert_eq!(code, Some(1));
    assert_eq!(stdout.matches("UNEXPECTED PASS").count(), d24.len(), "{stdout}");
    // An empty list with the crash: new failures.
    let (code, stdout) = run(String::new(), Some("d24s8.render_pass.static_state:abort"));
    assert_eq!(code, Some(1));
    assert_eq!(stdout.matches("NEW FAILURE").count(), d24.len(), "{stdout}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// The environment of `scripts/drivers.sh env VERSION`, or `None` (loudly; a failure under
/// `CI`) when that driver is not installed.
fn driver_or_skip(version: &str) -> Option<Vec<(String, Option<String>)>> {
    let env = common::driver_env(version);
    if env.is_none() {
        let why = format!("Mesa lavapipe {version} is not installed (scripts/drivers.sh install {version})");
        assert!(std::env::var_os("CI").is_none(), "CI needs {why}");
        eprintln!("SKIPPED: {why}");
    }
    env
}

/// `umbrage conform --filter mesh.` on driver `version`: its exit status and the cases.
fn mesh_family_on(version: &str) -> Option<(Option<i32>, Vec<serde_json::Value>)> {
    let env = driver_or_skip(version)?;
    let dir = tmp(&format!("mesh-{version}"));
    let mut c = umbrage();
    c.args(["conform", "--filter", "mesh.", "--out"]).arg(&dir);
    common::apply_driver_env(&mut c, &env);
    let out = c.output().unwrap();
    println!("{}", String::from_utf8_lossy(&out.stdout));
    let cases = json(&dir)["cases"].as_array().unwrap().clone();
    let _ = std::fs::remove_dir_all(&dir);
    Some((out.status.code(), cases))
}

/// The mesh-shader family passes on Mesa lavapipe 25.0.7, which has `VK_EXT_mesh_shader` with
/// task shaders.
#[test]
fn mesh_family_passes_on_lavapipe_25() {
    let Some((code, cases)) = mesh_family_on("25.0.7") else { return };
    assert_eq!(code, Some(0), "{cases:?}");
    assert_eq!(cases.len(), conform::mesh::NAMES.len());
    for c in &cases {
        assert_eq!(c["status"], "pass", "{}: {}", c["name"], c["message"]);
        assert_eq!(c["group"], "mesh");
    }
}

/// Without `VK_EXT_mesh_shader` (Mesa lavapipe 22.3.6) every mesh case is reported skipped as
/// unsupported — never passed, never failed — naming the extension and the driver script.
#[test]
fn mesh_family_is_unsupported_without_the_extension() {
    let Some((code, cases)) = mesh_family_on("22.3.6") else { return };
    assert_eq!(code, Some(0), "{cases:?}");
    assert_eq!(cases.len(), conform::mesh::NAMES.len());
    for c in &cases {
        assert_eq!(c["status"], "skipped", "{}", c["name"]);
        let m = c["message"].as_str().unwrap();
        assert!(m.starts_with("unsupported: VK_EXT_mesh_shader") && m.contains("scripts/drivers.sh install 25.0.7"), "{m}");
    }
}
