//! umbrage-conform: the driver conformance suite, checking on a Vulkan driver what stencil shadow volumes rely on.
//!
//! `umbrage conform`: the driver conformance suite for what shadow volumes rely on.
//!
//! Two layers:
//!
//! - **The parametrised suite** ([`cases`], [`model`], [`batch`], [`suite`]): the
//!   CTS-style cases (those of formats and features a device lacks are skipped, with the
//!   reason) — the stencil-op table, depth and infinity, depth clamp and bias, depth bounds, unrestricted depth, rasterisation and occlusion queries, a
//!   known-bug zoo, and four families beyond the CTS (deep wrap, homogeneous clipping,
//!   watertightness across draws, exact occlusion counts) — in every configuration the device supports: each depth-stencil format
//!   (D16S8, D24S8, D32S8, S8 as `vkGetPhysicalDeviceFormatProperties` reports them) x
//!   dynamic rendering / a classic render pass x static pipeline state / Vulkan 1.3 dynamic
//!   state. Every case draws into its own tile of one image per configuration (one
//!   submission), and each tile is compared exactly with a CPU model of the spec.
//! - **The single-configuration checks** ([`checks`], named `legacy.*` and
//!   `pipeline.hard_cases.*`): the original nine checks, the last of which runs the whole
//!   shadow pipeline on every `hard/*` scene and method against the CPU reference; the
//!   `commands.*` checks; and the mesh-shader family ([`mesh`], `mesh.*`: what
//!   `--method mesh` relies on of `VK_EXT_mesh_shader`, reported unsupported without it).
//!
//! Outputs: `conform.json`, `conform.md`, JUnit XML (`--junit`), and for every failure the
//! expected, actual and difference images. See docs/conform/cts-mapping.md.
//!
//! The legacy checks:
//!
//! | check | what |
//! |---|---|
//! | `w0_vertices_and_infinity` | w = 0 vertices through the infinite projection: exact coverage, depth exactly 1.0 |
//! | `depth_clamp` | beyond a finite far plane: rasterised at depth 1.0, not clipped (when depthClamp) |
//! | `watertight_fan` | 1000-triangle fan + jittered grid, INCR_WRAP: no gaps, no double hits |
//! | `two_sided_stencil_wrap` | front INCR_WRAP / back DECR_WRAP in one draw, wrap at 256 |
//! | `stencil_formats` | D24S8 / D32S8: stencil clear, write, read back |
//! | `depth_bounds` | stored depth outside the bounds rejected (when depthBounds) |
//! | `index_types` | u32 / u16 / u8 / non-indexed give identical stencil images |
//! | `deep_wrap_float_count` | 1000 front / 700 back faces: exactly 300.0 in an R32F count, 44 in the wrapping stencil (a render pass: runs on Vulkan 1.0) |
//! | `multiview_cube_faces` | a point light inside a box: its six shadow-map faces as multiview views give the atlas tiles' shadow, clipped triangles included (when multiview) |
//! | `shadow_pipeline_hard_cases` | every hard scene x method vs the reference (z-pass expected failures recorded) |
//!
//! A check also fails when the validation layers reported an error during it.
//!
//! The command line runs every unit (a configuration's submission, the legacy checks, the
//! multiview check, the mesh-shader checks, the pipeline checks) in a child process
//! ([`isolate`]), judges a run against a driver's
//! expected failures ([`expect`]), and puts several runs side by side ([`matrix`]). Any
//! Vulkan 1.0 device runs the classic render pass with static state; what needs 1.3 is skipped
//! with the reason.

#![warn(missing_docs)]

/// This crate's shaders, naga-compiled by its build script (`umbrage-shaderc`), beside the
/// shadow pass's and the renderer's (`umbrage_render::shaders`, re-exported; this crate's `ALL` lists its own).
pub mod shaders {
    pub use umbrage_render::shaders::*;
    include!(concat!(env!("OUT_DIR"), "/shaders.rs"));
}
pub mod batch;
pub mod cases;
pub mod checks;
pub mod deqp;
pub mod devices;
pub mod expect;
pub mod harness;
mod image_sink;
pub mod images;
pub mod isolate;
pub mod junit;
pub mod matrix;
pub mod mesh;
pub mod model;
mod outcome;
pub mod progress;
pub mod raster;
pub mod report;
pub mod suite;
mod units;
mod value_images;

pub use suite::{run_suite, Report, SuiteOptions};

use std::path::PathBuf;
use std::process::ExitCode;
use umbrage::error::{Error, Result};
use umbrage::gpu::Context;

#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
/// The outcome of one check.
#[serde(rename_all = "lowercase")]
pub enum Status {
    /// Every expectation held (and the validation layers reported nothing).
    Pass,
    /// An expectation failed, the check returned an error, or the validation layers reported one.
    Fail,
    /// The device lacks the feature the check exercises (e.g. `depthClamp`, `depthBounds`).
    Skipped,
    /// The driver crashed: the child process running the case died of a signal or exited
    /// without a result. JUnit's `<error>`, as deqp-runner reports a crashing CTS case.
    Crash,
    /// The driver hung: the child process running the case made no progress within the
    /// per-case timer (`--timeout`) and was killed. JUnit's `<error type="timeout">`.
    Timeout,
}

impl Status {
    /// The lowercase name used in the reports: `pass`, `fail`, `skipped`, `crash` or `timeout`.
    pub fn name(self) -> &'static str {
        match self {
            Status::Pass => "pass",
            Status::Fail => "fail",
            Status::Skipped => "skipped",
            Status::Crash => "crash",
            Status::Timeout => "timeout",
        }
    }
}

/// One (scene, method) case of `shadow_pipeline_hard_cases`.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct CaseResult {
    /// The built-in scene name (`hard/...`).
    pub scene: String,
    /// The shadow-volume method's name ([`umbrage::shadow::Method::name`]).
    pub method: String,
    /// Number of lights in the scene (one mask compared per light).
    pub lights: usize,
    /// Pixels compared with the reference, summed over lights.
    pub compared: u64,
    /// Pixels whose mask differs from the reference outside the 1-pixel edge band, summed over lights.
    pub mismatches_outside_band: u64,
    /// The largest per-light fraction (0..1) of compared pixels mismatched outside the band.
    pub worst_fraction_outside_band: f64,
    /// Pixels the reference called ambiguous (not judged), summed over lights.
    pub ambiguous: u64,
    /// Pixels inside the edge band (not judged), summed over lights.
    pub band_pixels: u64,
    /// Whether [`umbrage_render::accuracy::expected_failure`] lists this (scene, method) as a known failure.
    pub expected_failure: bool,
    /// pass | fail | expected-failure | unexpected-pass
    pub status: String,
}

/// The result of one check.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct CheckResult {
    /// The check's name, as in the module table (e.g. `watertight_fan`).
    pub name: String,
    /// Pass, fail or skipped.
    pub status: Status,
    /// One line: what held on a pass, the failures joined by `; ` otherwise.
    pub summary: String,
    /// The measured numbers (pixel counts, depths, probes), written to `conform.json`.
    pub numbers: serde_json::Map<String, serde_json::Value>,
    /// Per-case results (only `shadow_pipeline_hard_cases` has any).
    #[serde(skip_serializing_if = "Vec::is_empty", default)]
    pub cases: Vec<CaseResult>,
}

impl CheckResult {
    /// Pass with `what` as the summary when `fails` is empty, else Fail with the failures joined.
    pub fn from_fails(name: &str, fails: Vec<String>, numbers: serde_json::Map<String, serde_json::Value>, what: &str) -> CheckResult {
        let (status, summary) = if fails.is_empty() { (Status::Pass, what.to_string()) } else { (Status::Fail, fails.join("; ")) };
        CheckResult { name: name.into(), status, summary, numbers, cases: Vec::new() }
    }
    /// A skipped check; `why` names the missing feature.
    pub fn skipped(name: &str, why: &str) -> CheckResult {
        CheckResult { name: name.into(), status: Status::Skipped, summary: why.into(), numbers: Default::default(), cases: Vec::new() }
    }
    pub(crate) fn error(name: &str, e: &Error) -> CheckResult {
        CheckResult {
            name: name.into(),
            status: Status::Fail,
            summary: format!("error: {e}"),
            numbers: Default::default(),
            cases: Vec::new(),
        }
    }
}

pub(crate) fn with_validation(r: &mut CheckResult, errors: Vec<String>) {
    r.numbers.insert("validation_errors".into(), serde_json::json!(errors.len()));
    if let Some(first) = errors.first() {
        r.status = Status::Fail;
        r.summary = format!("{} validation errors (first: {first}); {}", errors.len(), r.summary);
    }
}

/// The command line's options (`umbrage conform`).
#[derive(Clone, Debug, Default)]
pub struct RunArgs {
    /// Comma-separated case-name patterns (glob with `*`, else substring).
    pub filter: Option<String>,
    /// Print the selected case names and exit.
    pub list: bool,
    /// Write JUnit XML here.
    pub junit: Option<PathBuf>,
    /// Report directory (default `conform-report`).
    pub out: Option<PathBuf>,
    /// Run on the device whose name contains this.
    pub device: Option<String>,
    /// Run each unit in a child process ([`isolate`]).
    pub isolate: bool,
    /// Seconds before a child is killed as hung.
    pub timeout_s: f64,
    /// Children at once.
    pub jobs: usize,
    /// Child mode: the unit to run ([`isolate::Unit::name`]).
    pub child: Option<String>,
    /// Child mode: where to write the [`isolate::ChildResult`].
    pub child_result: Option<PathBuf>,
    /// Child mode: where to report progress (the parent's per-case timer and crash pinning).
    pub child_progress: Option<PathBuf>,
    /// The driver's expected failures ([`expect`]): the exit status then says whether the
    /// run matched them (no new failure, no unexpected pass) instead of whether it passed.
    pub expect: Option<PathBuf>,
    /// Whether `--timeout` was given (the dEQP-compatible mode's default is lower).
    pub timeout_given: bool,
    /// The standalone driver-CI flags ([`deqp::CiArgs`]).
    pub ci: deqp::CiArgs,
    /// The dEQP flags: the dEQP-compatible mode ([`deqp::run_deqp`]).
    pub deqp: Option<deqp::args::DeqpArgs>,
}

/// Child mode: runs one unit and writes its result as JSON (see [`isolate`]).
fn run_child(ctx: &Context, unit: &str, a: &RunArgs, opts: &SuiteOptions) -> Result<ExitCode> {
    let unit = isolate::Unit::parse(unit).ok_or_else(|| Error::input("--child", format!("unknown unit '{unit}'")))?;
    let result = a.child_result.as_deref().ok_or_else(|| Error::input("--child", "needs --child-result FILE"))?;
    if let Some(p) = &a.child_progress {
        progress::open(p, &unit.name())?;
    }
    let validation = ctx.validation;
    let r = isolate::run_unit(ctx, unit, &|| Context::with_validation(validation), opts);
    let json = serde_json::to_string(&r).map_err(|e| Error::Internal(format!("JSON: {e}")))?;
    std::fs::write(result, json).map_err(|e| Error::io(result.display().to_string(), e))?;
    Ok(ExitCode::SUCCESS)
}

/// The default per-case timer of `--timeout` (seconds), deqp-runner's default per-test timer
/// (the dEQP-compatible mode's is [`deqp::DEQP_TIMEOUT_S`]).
pub const DEFAULT_TIMEOUT_S: f64 = 60.0;

/// Exit status when `--filter` selects nothing.
pub const EXIT_NOTHING_SELECTED: u8 = 2;

/// `umbrage conform`: lists or runs the selected cases (validation as `UMBRAGE_VALIDATION`
/// says), writes the reports, prints the verdict and the failures. Exit 0 only when nothing
/// failed; [`EXIT_NOTHING_SELECTED`] when the filter matches no case. `--device` sets
/// `UMBRAGE_DEVICE` for the context after checking that such a device exists (else the
/// error lists the devices). `UMBRAGE_CONFORM_BREAK=<op>` is the test seam of
/// [`SuiteOptions::break_op`].
pub fn run(mut a: RunArgs) -> Result<ExitCode> {
    if let Some(d) = a.deqp.take() {
        return deqp::run_deqp(d, &a, a.ci.chunk, a.timeout_given);
    }
    let filter: Vec<String> =
        a.filter.as_deref().unwrap_or("").split(',').map(|p| p.trim().to_string()).filter(|p| !p.is_empty()).collect();
    // every case's name, asked once: the selection, and the list a run matches
    let all = suite::all_names();
    if !all.iter().any(|n| filter.is_empty() || filter.iter().any(|p| suite::matches(p, n))) {
        eprintln!(
            "error: --filter '{}' matches none of the {} cases (patterns are substrings, or globs with '*'; --list shows every name)",
            filter.join(","),
            all.len()
        );
        return Ok(ExitCode::from(EXIT_NOTHING_SELECTED));
    }
    if a.list {
        // A closed pipe (`--list | head`) ends the listing quietly.
        use std::io::Write as _;
        let mut stdout = std::io::stdout().lock();
        for n in deqp::list(&filter) {
            if writeln!(stdout, "{n}").is_err() {
                break;
            }
        }
        return Ok(ExitCode::SUCCESS);
    }
    if let Some(d) = &a.device {
        let hits = devices::find(d)?;
        eprintln!("device: {}", hits[0]);
        std::env::set_var("UMBRAGE_DEVICE", d);
    }
    let break_op = match std::env::var("UMBRAGE_CONFORM_BREAK") {
        Ok(v) if !v.is_empty() => {
            Some(cases::parse_op(&v).ok_or_else(|| Error::input("UMBRAGE_CONFORM_BREAK", format!("unknown stencil op '{v}'")))?)
        }
        _ => None,
    };
    let mismatch: Vec<String> = std::env::var("UMBRAGE_CONFORM_MISMATCH")
        .unwrap_or_default()
        .split(',')
        .map(|s| s.trim().to_string())
        .filter(|s| !s.is_empty())
        .collect();
    let out = a.out.clone().unwrap_or_else(|| PathBuf::from("conform-report"));
    let ctx = Context::any_version(umbrage::gpu::context::validation_requested())?;
    let validation = ctx.validation;
    let opts = SuiteOptions { filter: filter.clone(), image_dir: Some(out.clone()), break_op, mismatch, ..Default::default() };
    if let Some(unit) = &a.child {
        return run_child(&ctx, unit, &a, &opts);
    }
    let expectations = a.expect.as_deref().map(expect::Expectations::load).transpose()?;
    if !(a.timeout_s > 0.0 && a.timeout_s.is_finite()) {
        return Err(Error::input("--timeout", format!("must be a positive number of seconds, got {}", a.timeout_s)));
    }
    if a.ci.any() {
        return deqp::run_standalone(&ctx, &a, &filter, &out, &opts);
    }
    let r = if a.isolate {
        let exe = std::env::current_exe().map_err(|e| Error::io("the umbrage executable", e))?;
        let iso = isolate::Isolation {
            exe,
            timeout: std::time::Duration::from_secs_f64(a.timeout_s),
            jobs: match a.jobs {
                0 => std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1),
                n => n,
            },
            scratch: out.join("children"),
        };
        isolate::run_suite_isolated(&ctx, &opts, &iso, &out)?
    } else {
        run_suite(&ctx, &|| Context::with_validation(validation), &opts)
    };
    report::write_all(&out, a.junit.as_deref(), &r)?;
    deqp::write_plain_csvs(&out, &r)?;
    println!("{} | {} | Vulkan {}", r.device.name, r.device.driver_info, r.device.api_version);
    for c in r.failed() {
        println!("FAIL {}: {}", c.name, c.message);
    }
    println!("{}", report::verdict(&r));
    println!("reports: {}/conform.json, {}/conform.md", out.display(), out.display());
    if let Some(j) = &a.junit {
        println!("junit: {}", j.display());
    }
    ctx.check_validation()?;
    // The expectation list this run matches (a new driver's list starts from it).
    let needed = out.join("conform-expectations.txt");
    std::fs::write(&needed, expect::Expectations::from_report(&r, &all)).map_err(|e| Error::io(needed.display().to_string(), e))?;
    if let Some(e) = &expectations {
        let v = e.judge(&r);
        for n in &v.new_failures {
            println!("NEW FAILURE (not in the expectations): {n}");
        }
        for n in &v.unexpected_passes {
            println!("UNEXPECTED PASS (listed as failing or skipping; remove it from the list): {n}");
        }
        for n in &v.new_skips {
            println!("NEW SKIP (not in the expectations; a case that ran now skips): {n}");
        }
        println!(
            "expectations: {} expected failures, {} expected skips, {} new failures, {} unexpected passes, {} new skips (the list this run matches: {})",
            v.expected_failures,
            v.expected_skips,
            v.new_failures.len(),
            v.unexpected_passes.len(),
            v.new_skips.len(),
            needed.display()
        );
        let p = out.join("conform-expect.json");
        let json = serde_json::to_string_pretty(&v).map_err(|e| Error::Internal(format!("JSON: {e}")))?;
        std::fs::write(&p, json + "\n").map_err(|e| Error::io(p.display().to_string(), e))?;
        return Ok(if v.ok() { ExitCode::SUCCESS } else { ExitCode::FAILURE });
    }
    Ok(if r.failed().is_empty() && r.crashed().is_empty() { ExitCode::SUCCESS } else { ExitCode::FAILURE })
}
