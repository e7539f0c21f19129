//! Depth checks: w = 0 vertices at depth exactly 1.0, depth clamp beyond the far plane, depth bounds.

use super::{count_mismatches, depth_is, incr_both, rect, subpixel_bits, tri_list, view_camera, write_depth};
use crate::harness::{self, DrawCall, Indices, PipeSpec};
use crate::raster;
use crate::CheckResult;
use ash::vk;
use serde_json::json;
use umbrage::error::Result;
use umbrage::gpu::Context;

/// Check 1: w = 0 vertices through the infinite projection.
///
/// Dark-cap-like triangles with every vertex at infinity (`w = 0`), and side-quad-like ones
/// mixing `w = 1` and `w = 0`, drawn with INCR_WRAP: the covered pixels must match the CPU
/// pixel-centre prediction exactly (edge pixels within [`raster::EDGE_EPS`] not judged), and an
/// all-infinite triangle must land at depth exactly 1.0 (D32: bit-exact; D24: within one
/// 24-bit ulp), never outside [0, 1]. Relies on clipping against `0 <= z <= w` keeping such
/// vertices (z = w) and on the homogeneous divide of Vulkan rasterisation.
pub fn w0_vertices_and_infinity(ctx: &Context) -> Result<CheckResult> {
    let (w, h) = (160u32, 120u32);
    let cam = view_camera();
    let mvp = cam.proj_infinite(w as f32 / h as f32) * cam.view();
    let format = ctx.depth_format;
    let bits = subpixel_bits(ctx);
    // A: dark-cap-like triangles, every vertex at infinity (w = 0).
    let a: Vec<[f32; 4]> = vec![
        [-0.5, -0.3, -1.0, 0.0],
        [0.05, 0.45, -1.0, 0.0],
        [0.4, -0.35, -1.0, 0.0],
        [0.6, 0.1, -1.0, 0.0],
        [1.5, 0.2, -1.0, 0.0],
        [0.7, 0.9, -1.0, 0.0],
        [-1.2, -0.4, -2.0, 0.0],
        [-0.3, -0.95, -2.0, 0.0],
        [-0.9, -1.1, -1.5, 0.0],
        [-0.71, 0.52, -3.0, 0.0],
        [-0.70, 0.05, -1.0, 0.0],
        [-0.69, 0.51, -3.0, 0.0],
    ];
    // B: side-quad-like triangles mixing finite (w = 1) and infinite (w = 0) vertices.
    let b: Vec<[f32; 4]> = vec![
        [-0.8, -0.5, -2.0, 1.0],
        [-0.3, -0.6, -3.0, 1.0],
        [-0.2, -0.1, -1.0, 0.0],
        [0.5, 0.5, -2.5, 1.0],
        [0.1, -0.2, -1.0, 0.0],
        [0.9, 0.6, -4.0, 1.0],
        [-1.0, 0.6, -2.0, 1.0],
        [-0.4, 0.3, -1.0, 0.0],
        [-0.9, 0.1, -1.0, 0.0],
    ];
    let mut numbers = serde_json::Map::new();
    let mut fails = Vec::new();
    // The dark caps through the renderer's format and through every other supported
    // 8-bit-stencil depth format (D24: 1.0 within one 24-bit ulp).
    let mut runs = vec![("w0_only".to_string(), a.clone(), true, format), ("mixed_w".to_string(), b, false, format)];
    for other in [vk::Format::D24_UNORM_S8_UINT, vk::Format::D32_SFLOAT_S8_UINT] {
        if other != format && harness::format_supported(ctx, other) {
            runs.push((format!("w0_only_{other:?}"), a.clone(), true, other));
        }
    }
    for (label, verts, check_depth, format) in runs {
        let label = label.as_str();
        let tris = tri_list(verts.len() as u32 / 3);
        let wt = raster::window_tris(mvp, &verts, &tris, w, h, bits);
        let (expected, judged) = raster::expected_counts(&wt, |_| 1, w, h);
        let rb = harness::render(
            ctx,
            format,
            w,
            h,
            0.0,
            0,
            &[DrawCall { spec: write_depth(incr_both()), mvp, vertices: verts, indices: Indices::None }],
        )?;
        let (mism, unjudged) = count_mismatches(&rb, &expected, &judged);
        let covered = rb.stencil.iter().filter(|&&s| s > 0).count();
        let expected_covered = expected.iter().zip(&judged).filter(|(&e, &j)| j && e > 0).count();
        let mut depth_not_one = 0u64;
        let (mut dmin, mut dmax) = (f64::INFINITY, f64::NEG_INFINITY);
        // The test seam (`value_images::skewed`): expect the dark caps at depth 0.5.
        let one = if crate::value_images::skewed() { 0.5 } else { 1.0 };
        for i in 0..rb.stencil.len() {
            if rb.stencil[i] > 0 {
                let d = harness::depth_value(format, rb.depth[i]);
                dmin = dmin.min(d);
                dmax = dmax.max(d);
                if check_depth && !depth_is(format, rb.depth[i], one) {
                    depth_not_one += 1;
                }
            }
        }
        if depth_not_one > 0 {
            covered_depth_images(&rb, format, one);
        }
        let out_of_range = dmin < 0.0 || dmax > 1.0;
        numbers.insert(
            label.into(),
            json!({
                "depth_format": format!("{format:?}"), "triangles": tris.len(), "covered_pixels": covered, "expected_covered_pixels": expected_covered,
                "coverage_mismatches": mism, "edge_pixels_not_judged": unjudged,
                "depth_min": dmin, "depth_max": dmax, "depth_not_exactly_1": if check_depth { json!(depth_not_one) } else { json!(null) },
            }),
        );
        if mism > 0 {
            fails.push(format!("{label}: {mism} coverage mismatches"));
        }
        if depth_not_one > 0 {
            fails.push(format!("{label}: {depth_not_one} pixels with depth != 1.0"));
        }
        if out_of_range {
            fails.push(format!("{label}: depth outside [0, 1] ({dmin}..{dmax})"));
        }
        if expected_covered == 0 {
            fails.push(format!("{label}: test geometry covers nothing"));
        }
    }
    numbers.insert("subpixel_bits".into(), json!(bits));
    Ok(CheckResult::from_fails("w0_vertices_and_infinity", fails, numbers, "coverage exact, dark-cap depth exactly 1.0"))
}

/// Check 2: Depth clamp: geometry beyond a finite far plane is clamped to depth 1, not clipped.
///
/// With `depthClampEnable` the z clip planes are disabled and fragment depth is clamped to the
/// viewport's [0, 1]: triangles beyond (or crossing) the far plane must cover exactly the
/// predicted pixels, at depth exactly 1.0; without it they must be clipped away entirely.
/// Skipped without the `depthClamp` feature.
pub fn depth_clamp(ctx: &Context) -> Result<CheckResult> {
    if !ctx.features.depth_clamp {
        return Ok(CheckResult::skipped("depth_clamp", "skipped: not supported (depthClamp)"));
    }
    let (w, h) = (160u32, 120u32);
    let cam = view_camera();
    let far = 10.0;
    let mvp = cam.proj_finite(w as f32 / h as f32, far) * cam.view();
    let format = ctx.depth_format;
    let bits = subpixel_bits(ctx);
    // Beyond the far plane entirely (z = -20 .. -50), and one triangle crossing it.
    let beyond: Vec<[f32; 4]> = vec![
        [-10.0, -6.0, -20.0, 1.0],
        [4.0, -7.0, -25.0, 1.0],
        [-2.0, 8.0, -30.0, 1.0],
        [15.0, 10.0, -50.0, 1.0],
        [25.0, 3.0, -45.0, 1.0],
        [20.0, 20.0, -40.0, 1.0],
    ];
    let crossing: Vec<[f32; 4]> = vec![[-3.0, -2.0, -5.0, 1.0], [-1.0, -2.0, -5.0, 1.0], [-12.0, -15.0, -30.0, 1.0]];
    let mut numbers = serde_json::Map::new();
    let mut fails = Vec::new();
    for (label, verts, clamp) in
        [("beyond_far_clamped", beyond.clone(), true), ("crossing_far_clamped", crossing, true), ("beyond_far_unclamped", beyond, false)]
    {
        let tris = tri_list(verts.len() as u32 / 3);
        let wt = raster::window_tris(mvp, &verts, &tris, w, h, bits);
        let (mut expected, judged) = raster::expected_counts(&wt, |_| 1, w, h);
        if !clamp {
            expected.iter_mut().for_each(|e| *e = 0); // clipped away entirely
        }
        let mut spec = write_depth(incr_both());
        spec.depth_clamp = clamp;
        let rb = harness::render(ctx, format, w, h, 0.0, 0, &[DrawCall { spec, mvp, vertices: verts, indices: Indices::None }])?;
        let (mism, unjudged) = count_mismatches(&rb, &expected, &judged);
        let covered = rb.stencil.iter().filter(|&&s| s > 0).count();
        let mut not_one = 0u64;
        let mut dmax = f64::NEG_INFINITY;
        // The test seam (`value_images::skewed`): expect the clamped depth at 0.5.
        let one = if crate::value_images::skewed() { 0.5 } else { 1.0 };
        for i in 0..rb.stencil.len() {
            if rb.stencil[i] > 0 {
                let d = harness::depth_value(format, rb.depth[i]);
                dmax = dmax.max(d);
                if label == "beyond_far_clamped" && !depth_is(format, rb.depth[i], one) {
                    not_one += 1;
                }
            }
        }
        if not_one > 0 || dmax > 1.0 {
            covered_depth_images(&rb, format, one);
        }
        numbers.insert(
            label.into(),
            json!({"covered_pixels": covered, "coverage_mismatches": mism, "edge_pixels_not_judged": unjudged,
                   "depth_max": if covered > 0 { json!(dmax) } else { json!(null) }, "depth_not_exactly_1": not_one}),
        );
        if mism > 0 {
            fails.push(format!("{label}: {mism} coverage mismatches"));
        }
        if not_one > 0 {
            fails.push(format!("{label}: {not_one} clamped pixels with depth != 1.0"));
        }
        if covered > 0 && dmax > 1.0 {
            fails.push(format!("{label}: depth {dmax} > 1"));
        }
    }
    numbers.insert("far".into(), json!(far));
    Ok(CheckResult::from_fails("depth_clamp", fails, numbers, "beyond-far geometry rasterised at depth 1.0"))
}

/// The depth failure images of a draw whose covered pixels (stencil > 0) must all lie at depth
/// `want` ([`depth_is`]'s tolerance); the pixels it left uncovered are not judged.
fn covered_depth_images(rb: &harness::Readback, format: vk::Format, want: f64) {
    let expected: Vec<Option<f64>> = rb.stencil.iter().map(|&s| (s > 0).then_some(want)).collect();
    let actual: Vec<f64> = rb.depth.iter().map(|&d| harness::depth_value(format, d)).collect();
    let bad = |i: usize| !depth_is(format, rb.depth[i], want);
    crate::image_sink::depth_mismatch(rb.width, rb.height, &expected, &actual, &bad);
}

/// Check 6: Depth bounds: fragments whose stored depth is outside the bounds are rejected.
///
/// Three strips of stored depth 0.2, 0.5 and 0.8 (the rest 1.0), then a full-screen REPLACE
/// draw with `depthBoundsTestEnable` and dynamic bounds [0.4, 0.6]: only the 0.5 strip may get
/// stencil 1. The test compares the *stored* depth, not the fragment's. Skipped without the
/// `depthBounds` feature.
pub fn depth_bounds(ctx: &Context) -> Result<CheckResult> {
    if !ctx.features.depth_bounds {
        return Ok(CheckResult::skipped("depth_bounds", "skipped: not supported (depthBounds)"));
    }
    let (w, h) = (64u32, 16u32);
    let mvp = harness::pixel_ortho(w, h);
    let mut depth = Vec::new();
    for (x0, z) in [(0.0, 0.2f32), (16.0, 0.5), (32.0, 0.8)] {
        let mut q = Vec::new();
        rect(&mut q, [x0, 0.0, x0 + 16.0, 16.0], true);
        depth.extend(q.into_iter().map(|p| [p[0], p[1], z, 1.0]));
    }
    let mut full = Vec::new();
    rect(&mut full, [0.0, 0.0, 64.0, 16.0], true);
    let full: Vec<[f32; 4]> = full.into_iter().map(|p| [p[0], p[1], 0.0, 1.0]).collect();
    let mut bounded = PipeSpec::replace(1);
    bounded.depth_bounds = Some((0.4, 0.6));
    let keep = write_depth(PipeSpec::stencil(vk::StencilOp::KEEP, vk::StencilOp::KEEP));
    let rb = harness::render(
        ctx,
        ctx.depth_format,
        w,
        h,
        1.0,
        0,
        &[
            DrawCall { spec: keep, mvp, vertices: depth, indices: Indices::None },
            DrawCall { spec: bounded, mvp, vertices: full, indices: Indices::None },
        ],
    )?;
    // Only the 0.5 strip passes; the test seam (`value_images::skewed`) expects the 0.2 one.
    let strip = if crate::value_images::skewed() { 0..16 } else { 16..32 };
    let want: Vec<u8> = (0..w * h).map(|i| u8::from(strip.contains(&(i % w)))).collect();
    let bad = want.iter().zip(&rb.stencil).filter(|(a, b)| a != b).count() as u64;
    if bad > 0 {
        crate::image_sink::stencil_mismatch(w, h, &want, &vec![true; want.len()], &rb.stencil);
    }
    let mut numbers = serde_json::Map::new();
    numbers.insert("bounds".into(), json!([0.4, 0.6]));
    numbers.insert("stored_depths".into(), json!([0.2, 0.5, 0.8, 1.0]));
    numbers.insert("mismatched_pixels".into(), json!(bad));
    let fails = if bad > 0 { vec![format!("{bad} pixels passed/failed the bounds test wrongly")] } else { vec![] };
    Ok(CheckResult::from_fails("depth_bounds", fails, numbers, "only stored depth 0.5 passes bounds [0.4, 0.6]"))
}
