//! `umbrage conform`: the driver conformance suite for what shadow volumes rely on.
//!
//! Each check is a small offscreen render, read back and compared with an exact expectation
//! computed on the CPU (coverage by the pixel-centre rule on the device's sub-pixel grid,
//! stencil counts modulo 256, depth 1.0 at infinity), except the last, which runs the whole
//! shadow pipeline on every `hard/*` scene and method against the CPU reference.
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
//! | `shadow_pipeline_hard_cases` | every hard scene x method vs the reference (z-pass expected failures recorded) |
//!
//! A check also fails when the validation layers reported an error during it.

#![warn(missing_docs)]

pub mod checks;
pub mod harness;
pub mod raster;

use crate::error::{Error, Result};
use crate::gpu::{Context, DeviceInfo, Features};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
/// The outcome of one check.
#[serde(rename_all = "lowercase")]
pub enum Status {
    /// Every expectation held (and the validation layers reported nothing).
    Pass,
    /// An expectation failed, the check returned an error, or the validation layers reported one.
    Fail,
    /// The device lacks the feature the check exercises (e.g. `depthClamp`, `depthBounds`).
    Skipped,
}

impl Status {
    /// The lowercase name used in the reports: `pass`, `fail` or `skipped`.
    pub fn name(self) -> &'static str {
        match self {
            Status::Pass => "pass",
            Status::Fail => "fail",
            Status::Skipped => "skipped",
        }
    }
}

/// One (scene, method) case of `shadow_pipeline_hard_cases`.
#[derive(Clone, Debug, serde::Serialize)]
pub struct CaseResult {
    /// The built-in scene name (`hard/...`).
    pub scene: String,
    /// The shadow-volume method's name ([`crate::shadow::Method::name`]).
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
    /// Whether [`crate::accuracy::expected_failure`] lists this (scene, method) as a known failure.
    pub expected_failure: bool,
    /// pass | fail | expected-failure | unexpected-pass
    pub status: String,
}

/// The result of one check.
#[derive(Clone, Debug, serde::Serialize)]
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
    #[serde(skip_serializing_if = "Vec::is_empty")]
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
    fn error(name: &str, e: &Error) -> CheckResult {
        CheckResult {
            name: name.into(),
            status: Status::Fail,
            summary: format!("error: {e}"),
            numbers: Default::default(),
            cases: Vec::new(),
        }
    }
}

/// The whole suite's result on one device (`conform.json`).
#[derive(Clone, Debug, serde::Serialize)]
pub struct Report {
    /// The physical device and driver the suite ran on.
    pub device: DeviceInfo,
    /// The optional features found (which decide the skipped checks).
    pub features: Features,
    /// Whether the validation layers were on (their errors fail the check they occur in).
    pub validation: bool,
    /// `VkPhysicalDeviceLimits::subPixelPrecisionBits`, the grid the CPU coverage predictions snap to.
    pub subpixel_bits: u32,
    /// One result per check, in the order of the module table.
    pub checks: Vec<CheckResult>,
}

impl Report {
    /// The checks that failed.
    pub fn failed(&self) -> Vec<&CheckResult> {
        self.checks.iter().filter(|c| c.status == Status::Fail).collect()
    }
}

/// Options of the suite.
pub struct Options {
    /// Size of the `shadow_pipeline_hard_cases` renders.
    pub pipeline_size: (u32, u32),
}

impl Default for Options {
    fn default() -> Self {
        Options { pipeline_size: (160, 120) }
    }
}

/// Runs every check on `ctx`; `new_context` makes the fresh contexts the renderer needs for the
/// pipeline check (a [`crate::render::Renderer`] owns its context).
pub fn run_suite(ctx: &Context, new_context: &dyn Fn() -> Result<Context>, opts: &Options) -> Report {
    type Check = fn(&Context) -> Result<CheckResult>;
    let unit: [(&str, Check); 7] = [
        ("w0_vertices_and_infinity", checks::w0_vertices_and_infinity),
        ("depth_clamp", checks::depth_clamp),
        ("watertight_fan", checks::watertight_fan),
        ("two_sided_stencil_wrap", checks::two_sided_stencil_wrap),
        ("stencil_formats", checks::stencil_formats),
        ("depth_bounds", checks::depth_bounds),
        ("index_types", checks::index_types),
    ];
    let mut results = Vec::new();
    let _ = ctx.take_validation_errors();
    for (name, f) in unit {
        let mut r = f(ctx).unwrap_or_else(|e| CheckResult::error(name, &e));
        with_validation(&mut r, ctx.take_validation_errors());
        results.push(r);
    }
    let (w, h) = opts.pipeline_size;
    let r = checks::shadow_pipeline_hard_cases(new_context, w, h).unwrap_or_else(|e| CheckResult::error("shadow_pipeline_hard_cases", &e));
    results.push(r);
    Report {
        device: ctx.info.clone(),
        features: ctx.features.clone(),
        validation: ctx.validation,
        subpixel_bits: ctx.limits.sub_pixel_precision_bits,
        checks: results,
    }
}

fn with_validation(r: &mut CheckResult, errors: Vec<String>) {
    r.numbers.insert("validation_errors".into(), serde_json::json!(errors.len()));
    if let Some(first) = errors.first() {
        r.status = Status::Fail;
        r.summary = format!("{} validation errors (first: {first}); {}", errors.len(), r.summary);
    }
}

/// The summary table (Markdown, also printed).
pub fn summary_table(report: &Report) -> String {
    let mut s = String::from("| check | result | details |\n|---|---|---|\n");
    for c in &report.checks {
        let _ = writeln!(s, "| `{}` | **{}** | {} |", c.name, c.status.name(), c.summary.replace('|', "\\|"));
    }
    s
}

/// The full Markdown report (`conform.md`): device, features, the summary table, then each
/// check's numbers and cases.
pub fn markdown(report: &Report) -> String {
    let d = &report.device;
    let mut s = String::new();
    let _ = writeln!(s, "# umbrage conform: {}\n", d.name);
    let _ = writeln!(s, "- device: {} ({}), vendor 0x{:04x}, device 0x{:04x}", d.name, d.kind, d.vendor_id, d.device_id);
    let _ = writeln!(s, "- driver: {} {}", d.driver, d.driver_info);
    let _ = writeln!(s, "- Vulkan API: {}", d.api_version);
    let _ = writeln!(s, "- validation layers: {}", if report.validation { "on" } else { "off" });
    let _ = writeln!(s, "- sub-pixel precision bits: {}", report.subpixel_bits);
    let f = &report.features;
    let _ = writeln!(
        s,
        "- features: depthClamp {}, depthBounds {}, depth_range_unrestricted {}, indexTypeUint8 {}, depth-stencil format {}\n",
        f.depth_clamp, f.depth_bounds, f.depth_range_unrestricted, f.index_type_uint8, f.depth_stencil_format
    );
    let failed = report.failed().len();
    let _ = writeln!(s, "**{}** ({} failed)\n", if failed == 0 { "PASS" } else { "FAIL" }, failed);
    s.push_str(&summary_table(report));
    for c in &report.checks {
        let _ = writeln!(s, "\n## `{}`: {}\n\n{}\n", c.name, c.status.name(), c.summary);
        if !c.numbers.is_empty() {
            let _ = writeln!(s, "```json\n{}\n```", serde_json::to_string_pretty(&c.numbers).unwrap_or_default());
        }
        if !c.cases.is_empty() {
            s.push_str("\n| scene | method | status | compared | outside band | worst fraction | ambiguous | band |\n|---|---|---|---|---|---|---|---|\n");
            for k in &c.cases {
                let _ = writeln!(
                    s,
                    "| {} | {} | {} | {} | {} | {:.4}% | {} | {} |",
                    k.scene,
                    k.method,
                    k.status,
                    k.compared,
                    k.mismatches_outside_band,
                    k.worst_fraction_outside_band * 100.0,
                    k.ambiguous,
                    k.band_pixels
                );
            }
        }
    }
    s
}

/// Writes `conform.json` and `conform.md` into `dir`.
pub fn write_report(dir: &Path, report: &Report) -> Result<()> {
    std::fs::create_dir_all(dir).map_err(|e| Error::io(dir.display().to_string(), e))?;
    let json = serde_json::to_string_pretty(report).map_err(|e| Error::Other(e.to_string()))?;
    let p = dir.join("conform.json");
    std::fs::write(&p, json + "\n").map_err(|e| Error::io(p.display().to_string(), e))?;
    let p = dir.join("conform.md");
    std::fs::write(&p, markdown(report)).map_err(|e| Error::io(p.display().to_string(), e))?;
    Ok(())
}

/// `umbrage conform [--out DIR]`: runs the suite (validation as `UMBRAGE_VALIDATION` says),
/// writes the reports, prints the summary; failure exit status when any check failed.
pub fn run(out: Option<PathBuf>) -> Result<ExitCode> {
    let out = out.unwrap_or_else(|| PathBuf::from("conform-report"));
    let ctx = Context::new()?;
    let validation = ctx.validation;
    let report = run_suite(&ctx, &|| Context::with_validation(validation), &Options::default());
    write_report(&out, &report)?;
    println!("{} | {} | Vulkan {}", report.device.name, report.device.driver_info, report.device.api_version);
    print!("{}", summary_table(&report));
    println!("reports: {}/conform.json, {}/conform.md", out.display(), out.display());
    ctx.check_validation()?;
    Ok(if report.failed().is_empty() { ExitCode::SUCCESS } else { ExitCode::FAILURE })
}
