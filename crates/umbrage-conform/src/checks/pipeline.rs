//! The end-to-end check: the whole shadow pipeline on every `hard/*` scene against the CPU reference.

use crate::{CaseResult, CheckResult, Status};
use serde_json::json;
use umbrage::error::Result;
use umbrage::gpu::Context;
use umbrage::shadow::Method;

/// Threshold on the fraction of compared pixels outside the 1-pixel band (the accuracy suite's).
pub const PIPELINE_THRESHOLD: f64 = umbrage_render::accuracy::THRESHOLD;

/// Check 8: The whole shadow pipeline on every `hard/*` scene and every method (those
/// `selected(scene, method)` accepts), against the CPU
/// reference (through the same dump check as `umbrage check`).
///
/// Each case renders `width` x `height` (one context from `new_context` for the whole check, one
/// renderer per scene with the method switched between frames), dumps the frame
/// and compares each light's mask outside a 1-pixel band; it passes at most
/// [`PIPELINE_THRESHOLD`] of the compared pixels mismatched. Cases [`umbrage_render::accuracy::expected_failure`] lists as
/// expected failures are reported, not failed (an unexpected pass is flagged); validation errors
/// during a render fail the case.
pub fn shadow_pipeline_hard_cases(
    new_context: &dyn Fn() -> Result<Context>,
    width: u32,
    height: u32,
    selected: &dyn Fn(&str, Method) -> bool,
) -> Result<CheckResult> {
    use umbrage_render::{RenderOptions, Renderer, Technique};
    let tmp = std::env::temp_dir().join(format!("umbrage-conform-{}", std::process::id()));
    let mut cases = Vec::new();
    let mut fails = Vec::new();
    let mut flagged = Vec::new();
    // One context for the whole check and one renderer per scene, its method switched between
    // frames as the viewer does: building a renderer (pipelines) is what costs, not a frame.
    let mut spare: Option<Context> = None;
    for name in umbrage_scene::builtin_names().into_iter().filter(|n| n.starts_with("hard/")) {
        let methods: Vec<Method> = Method::ALL.into_iter().filter(|&m| selected(name, m)).collect();
        let Some(&first) = methods.first() else { continue };
        let scene = umbrage_scene::load(name)?;
        let ctx = match spare.take() {
            Some(c) => c,
            None => new_context()?,
        };
        let opts = RenderOptions { width, height, technique: Technique::Volumes(first).into(), capture: true, ..Default::default() };
        let mut renderer = Renderer::new(ctx, scene, opts)?;
        let _ = renderer.context().take_validation_errors();
        for method in methods {
            renderer.settings.technique = Technique::Volumes(method).into();
            let frame = renderer.render()?;
            let validation = renderer.context().take_validation_errors();
            let dir = tmp.join(format!("{}-{}", name.replace('/', "_"), method.name()));
            umbrage_render::output::write_frame_dump(&dir, renderer.scene(), &frame)?;
            let report = match umbrage_reference::check_dump(&dir, 1) {
                Ok(r) => r,
                Err(e) => {
                    let _ = std::fs::remove_dir_all(&dir);
                    return Err(e);
                }
            };
            let expected_failure = umbrage_render::accuracy::expected_failure(name, method, umbrage_render::Counter::Stencil).is_some();
            let passed = report.passed(PIPELINE_THRESHOLD);
            let sum = |f: &dyn Fn(&umbrage_reference::metrics::Metrics) -> u64| report.lights.iter().map(|l| f(&l.metrics)).sum::<u64>();
            let status = if !validation.is_empty() {
                fails.push(format!("{name} {}: {} validation errors: {}", method.name(), validation.len(), validation[0]));
                "fail"
            } else if expected_failure {
                if passed {
                    flagged.push(format!("{name} {}", method.name()));
                    "unexpected-pass"
                } else {
                    "expected-failure"
                }
            } else if passed {
                "pass"
            } else {
                fails.push(format!("{name} {}: {:.4}% outside the band", method.name(), report.worst_fraction() * 100.0));
                // The frame's picture and each light's shadow mask, as the failure's images.
                let case = format!("pipeline.hard_cases.{}.{}", name.trim_start_matches("hard/"), method.name());
                let mut pngs: Vec<std::path::PathBuf> = std::fs::read_dir(&dir)
                    .map(|d| d.flatten().map(|e| e.path()).filter(|p| p.extension().is_some_and(|x| x == "png")).collect())
                    .unwrap_or_default();
                pngs.sort();
                for p in &pngs {
                    super::super::image_sink::copy_for(&case, p);
                }
                "fail"
            };
            let _ = std::fs::remove_dir_all(&dir);
            cases.push(CaseResult {
                scene: name.to_string(),
                method: method.name().to_string(),
                lights: report.lights.len(),
                compared: sum(&|m| m.compared),
                mismatches_outside_band: sum(&|m| m.mismatches_outside_band),
                worst_fraction_outside_band: report.worst_fraction(),
                ambiguous: sum(&|m| m.ambiguous),
                band_pixels: sum(&|m| m.band_pixels),
                expected_failure,
                status: status.to_string(),
            });
        }
        let ctx = renderer.into_context();
        // Teardown complaints (leaked objects) belong to the last case of the scene.
        let teardown = ctx.take_validation_errors();
        if let (Some(first), Some(last)) = (teardown.first(), cases.last_mut()) {
            fails.push(format!("{name}: {} validation errors at teardown: {first}", teardown.len()));
            last.status = "fail".into();
        }
        spare = Some(ctx);
    }
    let _ = std::fs::remove_dir_all(&tmp);
    let mut numbers = serde_json::Map::new();
    numbers.insert("size".into(), json!(format!("{width}x{height}")));
    numbers.insert("band_px".into(), json!(1));
    numbers.insert("threshold_fraction".into(), json!(PIPELINE_THRESHOLD));
    numbers.insert("cases".into(), json!(cases.len()));
    numbers.insert("passed".into(), json!(cases.iter().filter(|c| c.status == "pass").count()));
    numbers.insert("expected_failures".into(), json!(cases.iter().filter(|c| c.status == "expected-failure").count()));
    numbers.insert("unexpected_passes".into(), json!(flagged));
    numbers.insert("failed".into(), json!(cases.iter().filter(|c| c.status == "fail").count()));
    let mut r =
        CheckResult::from_fails("shadow_pipeline_hard_cases", fails, numbers, "every hard scene x method within 0.01% outside the band");
    if !flagged.is_empty() && r.status == Status::Pass {
        r.summary = format!("pass; FLAGGED unexpected passes: {}", flagged.join(", "));
    }
    r.cases = cases;
    Ok(r)
}
