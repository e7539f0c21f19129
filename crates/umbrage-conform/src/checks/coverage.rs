//! Coverage checks: watertight rasterisation of shared edges, and the index types.

use super::{count_mismatches, incr_both, subpixel_bits};
use crate::harness::{self, DrawCall, Indices, PipeSpec};
use crate::raster;
use crate::CheckResult;
use ash::vk;
use serde_json::json;
use umbrage::error::Result;
use umbrage::gpu::Context;

/// Check 3: Watertight rasterisation: a 1000-triangle fan and a jittered grid mesh.
///
/// Both meshes share every interior edge, with vertices on the sub-pixel grid; drawn with
/// INCR_WRAP, every pixel centre inside the hull must be counted exactly once (no gaps, no
/// double hits) and none outside it. Relies on Vulkan's tie-breaking rule, which gives a pixel
/// centre on a shared edge to exactly one of the two triangles.
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

/// Check 7: The same triangles through u32, u16, u8 (when supported) and no indices.
///
/// 250 triangles over 200 shared vertices, counted with INCR_WRAP / DECR_WRAP: every index
/// type must give a stencil image identical to the u32 one, pixel for pixel. u8 needs
/// `VK_EXT_index_type_uint8` (recorded as skipped otherwise).
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
            crate::image_sink::stencil_mismatch(w, h, &base.stencil, &vec![true; base.stencil.len()], &rb.stencil);
            fails.push(format!("{name}: {diff} pixels differ from u32"));
        }
    }
    if nonzero == 0 {
        fails.push("test geometry covers nothing".into());
    }
    Ok(CheckResult::from_fails("index_types", fails, numbers, "identical stencil images for every index type"))
}
