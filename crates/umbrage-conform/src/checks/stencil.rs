//! Stencil checks: two-sided wrapping counts, and the 8-bit stencil aspect of each depth format.

use super::{count_mismatches, depth_is, rect, subpixel_bits, tri_list, write_depth};
use crate::harness::{self, DrawCall, Indices, PipeSpec};
use crate::raster;
use crate::CheckResult;
use ash::vk;
use serde_json::json;
use umbrage::error::Result;
use umbrage::gpu::Context;

/// Check 4: Two-sided wrapping stencil in one draw.
///
/// Front faces INCR_WRAP, back faces DECR_WRAP in a single pipeline (the z-fail/z-pass counting
/// of shadow volumes): nested rectangles must count 1, 2, 1, 0, and the 8-bit count must wrap
/// modulo 256 both ways (256 increments give 0, one decrement from 0 gives 255). Every judged
/// pixel is compared with the CPU prediction, and nine probe pixels with fixed values.
pub fn two_sided_stencil_wrap(ctx: &Context) -> Result<CheckResult> {
    let (w, h) = (96u32, 48u32);
    let mvp = harness::pixel_ortho(w, h);
    let mut v = Vec::new();
    // Nested: front, front, back, back -> 1, 2, 1, 0 from the outside in.
    rect(&mut v, [4.0, 4.0, 44.0, 44.0], true);
    rect(&mut v, [10.0, 10.0, 38.0, 38.0], true);
    rect(&mut v, [16.0, 16.0, 32.0, 32.0], false);
    rect(&mut v, [20.0, 20.0, 28.0, 28.0], false);
    for _ in 0..256 {
        rect(&mut v, [50.0, 4.0, 60.0, 14.0], true); // 256 increments -> 0
    }
    for _ in 0..257 {
        rect(&mut v, [62.0, 4.0, 72.0, 14.0], true); // 257 -> 1
    }
    rect(&mut v, [50.0, 20.0, 60.0, 30.0], false); // 0 - 1 -> 255
    rect(&mut v, [62.0, 20.0, 72.0, 30.0], false);
    rect(&mut v, [62.0, 20.0, 72.0, 30.0], false); // -> 254
    for _ in 0..255 {
        rect(&mut v, [76.0, 20.0, 86.0, 30.0], true);
    }
    rect(&mut v, [76.0, 20.0, 86.0, 30.0], false); // 255 up, 1 down -> 254
    let tris = tri_list(v.len() as u32 / 3);
    let wt = raster::window_tris(mvp, &v, &tris, w, h, subpixel_bits(ctx));
    let (expected, judged) = raster::expected_counts(&wt, |t| if t.front_facing() { 1 } else { -1 }, w, h);
    let spec = PipeSpec::stencil(vk::StencilOp::INCREMENT_AND_WRAP, vk::StencilOp::DECREMENT_AND_WRAP);
    let rb = harness::render(ctx, ctx.depth_format, w, h, 1.0, 0, &[DrawCall { spec, mvp, vertices: v, indices: Indices::None }])?;
    let (mism, unjudged) = count_mismatches(&rb, &expected, &judged);
    let at = |x: u32, y: u32| rb.stencil[(y * w + x) as usize];
    let probes = json!({
        "nested_ring1": at(6, 6), "nested_ring2": at(12, 12), "nested_ring3": at(17, 17), "nested_core": at(24, 24),
        "incr_x256": at(55, 9), "incr_x257": at(67, 9), "decr_from_0": at(55, 25), "decr_x2_from_0": at(67, 25), "incr255_decr1": at(81, 25),
    });
    let want = json!({
        "nested_ring1": 1, "nested_ring2": 2, "nested_ring3": 1, "nested_core": 0,
        "incr_x256": 0, "incr_x257": 1, "decr_from_0": 255, "decr_x2_from_0": 254, "incr255_decr1": 254,
    });
    let mut fails = Vec::new();
    if mism > 0 {
        fails.push(format!("{mism} pixels differ from the expected counts"));
    }
    if probes != want {
        fails.push(format!("probe counts {probes} != expected {want}"));
    }
    let mut numbers = serde_json::Map::new();
    numbers.insert("triangles".into(), json!(tris.len()));
    numbers.insert("mismatched_pixels".into(), json!(mism));
    numbers.insert("edge_pixels_not_judged".into(), json!(unjudged));
    numbers.insert("probes".into(), probes);
    Ok(CheckResult::from_fails("two_sided_stencil_wrap", fails, numbers, "front INCR_WRAP / back DECR_WRAP counts and wrap exact"))
}

/// Check 5: Clear, write and read back the stencil aspect of D24S8 and D32S8.
///
/// For each supported format: clear to stencil 0x5a / depth 0.25, REPLACE 0xc3 at depth 0.5 in a
/// rectangle from both faces, then copy each aspect to a buffer separately; every pixel must
/// read back exactly (D24 depth within one 24-bit ulp). Fails when neither format is supported.
pub fn stencil_formats(ctx: &Context) -> Result<CheckResult> {
    let (w, h) = (48u32, 32u32);
    let mvp = harness::pixel_ortho(w, h);
    let mut numbers = serde_json::Map::new();
    let mut fails = Vec::new();
    let mut tested = 0;
    for format in [vk::Format::D24_UNORM_S8_UINT, vk::Format::D32_SFLOAT_S8_UINT] {
        let name = format!("{format:?}");
        if !harness::format_supported(ctx, format) {
            numbers.insert(name, json!("not supported as attachment + transfer source"));
            continue;
        }
        tested += 1;
        let mut v = Vec::new();
        rect(&mut v, [8.0, 8.0, 40.0, 24.0], true);
        rect(&mut v, [8.0, 8.0, 40.0, 24.0], false); // both faces write the same
        let rb = harness::render(
            ctx,
            format,
            w,
            h,
            0.25,
            0x5a,
            &[DrawCall { spec: write_depth(PipeSpec::replace(0xc3)), mvp, vertices: v, indices: Indices::None }],
        )?;
        let (mut bad_stencil, mut bad_depth) = (0u64, 0u64);
        let mut want = vec![0u8; (w * h) as usize];
        let mut want_depth = vec![None; want.len()];
        // The test seam (`value_images::skewed`): expect the written depth at 0.75.
        let written = if crate::value_images::skewed() { 0.75 } else { 0.5 };
        for y in 0..h {
            for x in 0..w {
                let i = (y * w + x) as usize;
                let inside = (8..40).contains(&x) && (8..24).contains(&y);
                let (ws, wd) = if inside { (0xc3, written) } else { (0x5a, 0.25) };
                (want[i], want_depth[i]) = (ws, Some(wd));
                bad_stencil += (rb.stencil[i] != ws) as u64;
                bad_depth += (!depth_is(format, rb.depth[i], wd)) as u64;
            }
        }
        if bad_stencil > 0 {
            crate::image_sink::stencil_mismatch(w, h, &want, &vec![true; want.len()], &rb.stencil);
        }
        if bad_depth > 0 {
            let actual: Vec<f64> = rb.depth.iter().map(|&d| harness::depth_value(format, d)).collect();
            let bad = |i: usize| want_depth[i].is_some_and(|wd| !depth_is(format, rb.depth[i], wd));
            crate::image_sink::depth_mismatch(w, h, &want_depth, &actual, &bad);
        }
        numbers.insert(
            name.clone(),
            json!({"stencil_mismatches": bad_stencil, "depth_mismatches": bad_depth, "cleared": "0x5a / 0.25", "written": "0xc3 / 0.5"}),
        );
        if bad_stencil > 0 || bad_depth > 0 {
            fails.push(format!("{name}: {bad_stencil} stencil and {bad_depth} depth mismatches"));
        }
    }
    numbers.insert("formats_tested".into(), json!(tested));
    if tested == 0 {
        fails.push("no 8-bit-stencil depth format supported".into());
    }
    Ok(CheckResult::from_fails("stencil_formats", fails, numbers, "stencil aspect clears, writes and reads back"))
}
