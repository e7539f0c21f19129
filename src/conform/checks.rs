//! The checks: each a small offscreen render read back and compared with exact expectations.

use super::harness::{self, DrawCall, Indices, PipeSpec, Readback};
use super::raster::{self, WinTri};
use super::{CaseResult, CheckResult, Status};
use crate::error::Result;
use crate::gpu::Context;
use crate::scene::Camera;
use ash::vk;
use glam::Vec3;
use serde_json::json;

fn subpixel_bits(ctx: &Context) -> u32 {
    ctx.limits.sub_pixel_precision_bits
}

/// Depth word equal to 1.0 for `format` (exact for D32, within one 24-bit ulp for D24).
fn depth_is(format: vk::Format, word: u32, value: f64) -> bool {
    if format == vk::Format::D24_UNORM_S8_UINT {
        let expected = (value * 16_777_215.0).round() as i64;
        ((word & 0x00ff_ffff) as i64 - expected).abs() <= 1
    } else {
        f32::from_bits(word) == value as f32
    }
}

/// Compares a stencil read-back with an expectation on judged pixels.
fn count_mismatches(rb: &Readback, expected: &[u8], judged: &[bool]) -> (u64, u64) {
    let mut mism = 0;
    let mut unjudged = 0;
    for i in 0..expected.len() {
        if !judged[i] {
            unjudged += 1;
        } else if rb.stencil[i] != expected[i] {
            mism += 1;
        }
    }
    (mism, unjudged)
}

fn tri_list(n: u32) -> Vec<[u32; 3]> {
    (0..n).map(|t| [3 * t, 3 * t + 1, 3 * t + 2]).collect()
}

fn incr_both() -> PipeSpec {
    PipeSpec::stencil(vk::StencilOp::INCREMENT_AND_WRAP, vk::StencilOp::INCREMENT_AND_WRAP)
}

fn write_depth(mut s: PipeSpec) -> PipeSpec {
    s.depth_test = true;
    s.depth_write = true;
    s.depth_compare = vk::CompareOp::ALWAYS;
    s
}

fn view_camera() -> Camera {
    Camera { eye: Vec3::ZERO, target: Vec3::new(0.0, 0.0, -1.0), up: Vec3::Y, fov_y_deg: 60.0, near: 0.1 }
}

/// Check 1: w = 0 vertices through the infinite projection.
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
        for i in 0..rb.stencil.len() {
            if rb.stencil[i] > 0 {
                let d = harness::depth_value(format, rb.depth[i]);
                dmin = dmin.min(d);
                dmax = dmax.max(d);
                if check_depth && !depth_is(format, rb.depth[i], 1.0) {
                    depth_not_one += 1;
                }
            }
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
        for i in 0..rb.stencil.len() {
            if rb.stencil[i] > 0 {
                let d = harness::depth_value(format, rb.depth[i]);
                dmax = dmax.max(d);
                if label == "beyond_far_clamped" && !depth_is(format, rb.depth[i], 1.0) {
                    not_one += 1;
                }
            }
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

/// Check 3: Watertight rasterisation: a 1000-triangle fan and a jittered grid mesh.
pub fn watertight_fan(ctx: &Context) -> Result<CheckResult> {
    let (w, h) = (128u32, 128u32);
    let mvp = harness::pixel_ortho(w, h);
    let bits = subpixel_bits(ctx);
    let mut numbers = serde_json::Map::new();
    let mut fails = Vec::new();

    // Fan: centre + 1000 ring vertices, shared through indices.
    let n = 1000u32;
    let (cx, cy, r) = (63.37f32, 64.21f32, 58.3f32);
    let mut fan = vec![[cx, cy, 0.5, 1.0]];
    for k in 0..n {
        let a = k as f32 / n as f32 * std::f32::consts::TAU;
        fan.push([cx + r * a.cos(), cy + r * a.sin(), 0.5, 1.0]);
    }
    let fan_tris: Vec<[u32; 3]> = (0..n).map(|k| [0, 1 + k, 1 + (k + 1) % n]).collect();
    // Grid: 40 x 40 cells, interior vertices jittered, alternating diagonals.
    let (gx0, gy0, gx1, gy1) = (5.3f32, 6.1f32, 122.7f32, 121.9f32);
    let g = 40u32;
    let mut grid = Vec::new();
    let mut seed = 12345u32;
    let mut rnd = || {
        seed = seed.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
        (seed >> 8) as f32 / (1u32 << 24) as f32 - 0.5
    };
    for j in 0..=g {
        for i in 0..=g {
            let (mut x, mut y) = (gx0 + (gx1 - gx0) * i as f32 / g as f32, gy0 + (gy1 - gy0) * j as f32 / g as f32);
            let (jx, jy) = (rnd(), rnd());
            if i > 0 && i < g && j > 0 && j < g {
                x += jx * 1.2;
                y += jy * 1.2;
            }
            grid.push([x, y, 0.5, 1.0]);
        }
    }
    let mut grid_tris = Vec::new();
    for j in 0..g {
        for i in 0..g {
            let v = |i: u32, j: u32| j * (g + 1) + i;
            let (a, b, c, d) = (v(i, j), v(i + 1, j), v(i + 1, j + 1), v(i, j + 1));
            if (i + j) % 2 == 0 {
                grid_tris.push([a, b, c]);
                grid_tris.push([a, c, d]);
            } else {
                grid_tris.push([a, b, d]);
                grid_tris.push([b, c, d]);
            }
        }
    }
    // Vertices on the sub-pixel grid: the GPU's f32 transform then cannot round a vertex to a
    // different sub-pixel position than the CPU prediction.
    let snap = |v: Vec<[f32; 4]>| -> Vec<[f32; 4]> {
        let s = (1u32 << bits) as f32;
        v.into_iter().map(|p| [(p[0] * s).round() / s, (p[1] * s).round() / s, p[2], p[3]]).collect()
    };
    let (fan, grid) = (snap(fan), snap(grid));
    for (label, verts, tris) in [("fan", fan, fan_tris), ("grid", grid, grid_tris)] {
        let wt = raster::window_tris(mvp, &verts, &tris, w, h, bits);
        // Hull: the fan's ring polygon / the grid's rectangle (boundary vertices not jittered).
        let hull: Vec<glam::DVec2> = if label == "fan" {
            (1..verts.len()).map(|i| raster::window_tris(mvp, &verts, &[[i as u32, i as u32, i as u32]], w, h, bits)[0].p[0]).collect()
        } else {
            let c = [[gx0, gy0], [gx1, gy0], [gx1, gy1], [gx0, gy1]];
            c.iter()
                .map(|p| raster::to_window(mvp.as_dmat4() * glam::DVec4::new(p[0] as f64, p[1] as f64, 0.5, 1.0), w, h, bits).0)
                .collect()
        };
        // Inside by the crossing rule (the snapped ring need not be exactly convex); not judged
        // within EDGE_EPS of a hull segment.
        let inside_hull = |x: u32, y: u32| -> Option<bool> {
            let c = glam::DVec2::new(x as f64 + 0.5, y as f64 + 0.5);
            let mut inside = false;
            let mut min_d = f64::INFINITY;
            for k in 0..hull.len() {
                let (a, b) = (hull[k], hull[(k + 1) % hull.len()]);
                if (a.y > c.y) != (b.y > c.y) && c.x < a.x + (c.y - a.y) / (b.y - a.y) * (b.x - a.x) {
                    inside = !inside;
                }
                let e = b - a;
                let t = ((c - a).dot(e) / e.length_squared()).clamp(0.0, 1.0);
                min_d = min_d.min((a + e * t - c).length());
            }
            if min_d <= raster::EDGE_EPS {
                None
            } else {
                Some(inside)
            }
        };
        let rb = harness::render(
            ctx,
            ctx.depth_format,
            w,
            h,
            1.0,
            0,
            &[DrawCall { spec: incr_both(), mvp, vertices: verts, indices: Indices::U32(tris.iter().flatten().copied().collect()) }],
        )?;
        let (mut zero_inside, mut double, mut outside_hits, mut inside, mut hull_edge) = (0u64, 0u64, 0u64, 0u64, 0u64);
        for y in 0..h {
            for x in 0..w {
                let s = rb.stencil[(y * w + x) as usize];
                if s >= 2 {
                    double += 1;
                }
                match inside_hull(x, y) {
                    Some(true) => {
                        inside += 1;
                        if s == 0 {
                            zero_inside += 1;
                        }
                    }
                    Some(false) => {
                        if s != 0 {
                            outside_hits += 1;
                        }
                    }
                    None => hull_edge += 1,
                }
            }
        }
        // Also the per-triangle prediction, for the record.
        let (expected, judged) = raster::expected_counts(&wt, |_| 1, w, h);
        let (mism, _) = count_mismatches(&rb, &expected, &judged);
        numbers.insert(
            label.into(),
            json!({"triangles": tris.len(), "pixels_inside_hull": inside, "count0_inside_hull": zero_inside,
                   "count_ge2": double, "hits_outside_hull": outside_hits, "hull_edge_pixels_not_judged": hull_edge,
                   "mismatches_vs_cpu_prediction": mism}),
        );
        if zero_inside > 0 || double > 0 || outside_hits > 0 {
            fails.push(format!("{label}: {zero_inside} gaps, {double} double hits, {outside_hits} hits outside the hull"));
        }
    }
    Ok(CheckResult::from_fails("watertight_fan", fails, numbers, "every covered pixel counted exactly once"))
}

/// Two triangles for an integer-aligned rectangle, front (counter-clockwise in Vulkan's sense)
/// or back facing.
fn rect(out: &mut Vec<[f32; 4]>, r: [f32; 4], front: bool) {
    let [x0, y0, x1, y1] = r;
    let t1 = [[x0, y0], [x0, y1], [x1, y1]];
    let t2 = [[x0, y0], [x1, y1], [x1, y0]];
    for t in [t1, t2] {
        let wt = WinTri { p: t.map(|p| glam::DVec2::new(p[0] as f64, p[1] as f64)), z: [0.5; 3] };
        let t = if wt.front_facing() == front { t } else { [t[0], t[2], t[1]] };
        out.extend(t.iter().map(|p| [p[0], p[1], 0.5, 1.0]));
    }
}

/// Check 4: Two-sided wrapping stencil in one draw.
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
        for y in 0..h {
            for x in 0..w {
                let i = (y * w + x) as usize;
                let inside = (8..40).contains(&x) && (8..24).contains(&y);
                let (ws, wd) = if inside { (0xc3, 0.5) } else { (0x5a, 0.25) };
                bad_stencil += (rb.stencil[i] != ws) as u64;
                bad_depth += (!depth_is(format, rb.depth[i], wd)) as u64;
            }
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

/// Check 6: Depth bounds: fragments whose stored depth is outside the bounds are rejected.
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
    let mut bad = 0u64;
    for y in 0..h {
        for x in 0..w {
            let want = u8::from((16..32).contains(&x));
            bad += (rb.stencil[(y * w + x) as usize] != want) as u64;
        }
    }
    let mut numbers = serde_json::Map::new();
    numbers.insert("bounds".into(), json!([0.4, 0.6]));
    numbers.insert("stored_depths".into(), json!([0.2, 0.5, 0.8, 1.0]));
    numbers.insert("mismatched_pixels".into(), json!(bad));
    let fails = if bad > 0 { vec![format!("{bad} pixels passed/failed the bounds test wrongly")] } else { vec![] };
    Ok(CheckResult::from_fails("depth_bounds", fails, numbers, "only stored depth 0.5 passes bounds [0.4, 0.6]"))
}

/// Check 7: The same triangles through u32, u16, u8 (when supported) and no indices.
pub fn index_types(ctx: &Context) -> Result<CheckResult> {
    let (w, h) = (64u32, 64u32);
    let mvp = harness::pixel_ortho(w, h);
    let mut seed = 987_654_321u32;
    let mut rnd = || {
        seed = seed.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
        (seed >> 8) as f32 / (1u32 << 24) as f32
    };
    // 200 shared vertices; a fan over the first 101 and 150 random triangles over all of them.
    let mut verts = vec![[31.7f32, 32.2, 0.5, 1.0]];
    for k in 0..100 {
        let a = k as f32 / 100.0 * std::f32::consts::TAU;
        verts.push([31.7 + 20.0 * a.cos(), 32.2 + 20.0 * a.sin(), 0.5, 1.0]);
    }
    while verts.len() < 200 {
        verts.push([rnd() * 80.0 - 8.0, rnd() * 80.0 - 8.0, 0.5, 1.0]);
    }
    let mut idx: Vec<u32> = (0..100).flat_map(|k| [0, 1 + k, 1 + (k + 1) % 100]).collect();
    for _ in 0..150 {
        for _ in 0..3 {
            idx.push(((rnd() * 200.0) as u32).min(199));
        }
    }
    let spec = PipeSpec::stencil(vk::StencilOp::INCREMENT_AND_WRAP, vk::StencilOp::DECREMENT_AND_WRAP);
    let draw = |indices: Indices, vertices: Vec<[f32; 4]>| {
        harness::render(ctx, ctx.depth_format, w, h, 1.0, 0, &[DrawCall { spec, mvp, vertices, indices }])
    };
    let base = draw(Indices::U32(idx.clone()), verts.clone())?;
    let mut numbers = serde_json::Map::new();
    let mut fails = Vec::new();
    let mut variants: Vec<(&str, Indices, Vec<[f32; 4]>)> = vec![
        ("u16", Indices::U16(idx.iter().map(|&i| i as u16).collect()), verts.clone()),
        ("none", Indices::None, idx.iter().map(|&i| verts[i as usize]).collect()),
    ];
    if ctx.features.index_type_uint8 {
        variants.push(("u8", Indices::U8(idx.iter().map(|&i| i as u8).collect()), verts.clone()));
    } else {
        numbers.insert("u8".into(), json!("skipped: VK_EXT_index_type_uint8 not supported"));
    }
    let nonzero = base.stencil.iter().filter(|&&s| s != 0).count();
    numbers.insert("triangles".into(), json!(idx.len() / 3));
    numbers.insert("nonzero_pixels_u32".into(), json!(nonzero));
    for (name, indices, vertices) in variants {
        let rb = draw(indices, vertices)?;
        let diff = rb.stencil.iter().zip(&base.stencil).filter(|(a, b)| a != b).count();
        numbers.insert(format!("{name}_pixels_differing_from_u32"), json!(diff));
        if diff > 0 {
            fails.push(format!("{name}: {diff} pixels differ from u32"));
        }
    }
    if nonzero == 0 {
        fails.push("test geometry covers nothing".into());
    }
    Ok(CheckResult::from_fails("index_types", fails, numbers, "identical stencil images for every index type"))
}

/// Threshold on the fraction of compared pixels outside the 1-pixel band (the accuracy suite's).
pub const PIPELINE_THRESHOLD: f64 = crate::accuracy::THRESHOLD;

/// Check 8: The whole shadow pipeline on every `hard/*` scene and every method, against the CPU
/// reference (through the same dump check as `umbrage check`).
pub fn shadow_pipeline_hard_cases(new_context: &dyn Fn() -> Result<Context>, width: u32, height: u32) -> Result<CheckResult> {
    use crate::render::{RenderOptions, Renderer, Technique};
    use crate::shadow::Method;
    let tmp = std::env::temp_dir().join(format!("umbrage-conform-{}", std::process::id()));
    let mut cases = Vec::new();
    let mut fails = Vec::new();
    let mut flagged = Vec::new();
    for name in crate::scene::builtin_names().into_iter().filter(|n| n.starts_with("hard/")) {
        for method in Method::ALL {
            let scene = crate::scene::load(name)?;
            let ctx = new_context()?;
            let opts = RenderOptions { width, height, technique: Technique::Volumes(method), capture: true, ..Default::default() };
            let mut renderer = Renderer::new(ctx, scene, opts)?;
            let frame = renderer.render()?;
            let validation = renderer.context().take_validation_errors();
            let dir = tmp.join(format!("{}-{}", name.replace('/', "_"), method.name()));
            crate::output::write_frame_dump(&dir, renderer.scene(), &frame)?;
            drop(renderer);
            let report = crate::reference::check_dump(&dir, 1)?;
            let _ = std::fs::remove_dir_all(&dir);
            let expected_failure = crate::accuracy::expected_failure(name, method, crate::render::Counter::Stencil).is_some();
            let passed = report.passed(PIPELINE_THRESHOLD);
            let sum = |f: &dyn Fn(&crate::reference::metrics::Metrics) -> u64| report.lights.iter().map(|l| f(&l.metrics)).sum::<u64>();
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
                "fail"
            };
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
