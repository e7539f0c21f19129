//! `legacy.msaa_depth_locations`: multisampled depth at the standard sample locations, where a
//! multisampled draw evaluates each sample's coverage and depth, judged on the renderer's own
//! measurement ([`umbrage_render::sample_locations`]: two sloped planes at every sample count
//! in {2, 4, 8} the device supports for the renderer's depth format, sampled; every sample read
//! back and compared with the plane at its standard location: coverage exact, depth within
//! 1e-5; where depth is off, the location it was evaluated at, per sample).
//!
//! SwiftShader fails it (docs/conform/drivers-notes.md §1f): its coverage is at the standard
//! locations, its depth at the locations mirrored in x about the pixel centre. The renderer's
//! `render --dump` calibrates its captures with the same measurement
//! ([`umbrage_render::sample_locations::calibrate_sample_locations`]).

use crate::CheckResult;
use ash::vk;
use serde_json::json;
use umbrage::error::Result;
use umbrage::gpu::Context;
use umbrage_render::{sample_locations, standard_sample_locations};

/// The check's name (`legacy.msaa_depth_locations`).
pub const NAME: &str = "msaa_depth_locations";

/// Every sample's coverage and depth at its standard location, at each supported count of 2, 4
/// and 8 (the renderer's depth format, sampled). Skipped without `standardSampleLocations` or
/// without a multisampled, sampled depth format.
pub fn msaa_depth_locations(ctx: &Context) -> Result<CheckResult> {
    if ctx.limits.standard_sample_locations != vk::TRUE {
        return Ok(CheckResult::skipped(NAME, "skipped: no standardSampleLocations"));
    }
    let counts = sample_locations::sample_counts(ctx);
    if counts.is_empty() {
        return Ok(CheckResult::skipped(NAME, "skipped: no 2, 4 or 8 samples for a sampled depth attachment"));
    }
    let mut fails = Vec::new();
    let mut numbers = serde_json::Map::new();
    for &n in &counts {
        let Some(t) = sample_locations::measure(ctx, n)? else { continue };
        let standard = standard_sample_locations(n);
        // The test seam: every location expected a sixteenth of a pixel right of its own.
        let skew = if crate::value_images::skewed() { 1.0 / 16.0 } else { 0.0 };
        let expected: Vec<(f64, f64)> = standard.iter().map(|&(x, y)| (x + skew, y)).collect();
        let mut off = Vec::new();
        for (k, (&(sx, sy), &(dx, dy))) in expected.iter().zip(&t.depth_at).enumerate() {
            if (dx - sx).abs() > 1e-3 || (dy - sy).abs() > 1e-3 {
                off.push(format!("sample {k} at ({dx:.4}, {dy:.4}), not ({sx}, {sy})"));
            }
        }
        if t.coverage_mismatches > 0 {
            fails.push(format!("{n} samples: {} samples' coverage differs from the standard locations'", t.coverage_mismatches));
        }
        if t.depth_mismatches > 0 {
            fails.push(format!(
                "{n} samples: {} samples' depth is not the plane's at their standard location; depth evaluated at: {}",
                t.depth_mismatches,
                if off.is_empty() { "the standard locations (median)".to_string() } else { off.join(", ") }
            ));
        } else if !off.is_empty() {
            fails.push(format!("{n} samples: depth evaluated at {}", off.join(", ")));
        }
        if t.coverage_mismatches + t.depth_mismatches > 0 || !off.is_empty() {
            // Green: where each sample's depth should be evaluated; red: where it was.
            let pt = |v: &[(f64, f64)]| -> Vec<[f32; 2]> { v.iter().map(|&(x, y)| [x as f32, y as f32]).collect() };
            crate::value_images::points(&format!("samples_{n}.depth_locations"), &pt(&expected), &pt(&t.depth_at), 1e-3);
        }
        let at: Vec<[f64; 2]> = t.depth_at.iter().map(|&(x, y)| [x, y]).collect();
        numbers.insert(
            format!("samples_{n}"),
            json!({
                "coverage_mismatches": t.coverage_mismatches,
                "depth_mismatches": t.depth_mismatches,
                "compared": sample_locations::DepthLocations::compared(n),
                "depth_evaluated_at": at,
                "standard_locations": standard,
            }),
        );
    }
    numbers.insert("sample_counts".into(), json!(counts));
    Ok(CheckResult::from_fails(NAME, fails, numbers, "every sample's coverage and depth at its standard location"))
}
