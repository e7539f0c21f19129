//! Depth and infinity: w = 0 vertices through forward and reverse-Z infinite projections
//! (depth exactly 1.0 / 0.0, drawn over a background cleared to exactly that value, as dark
//! caps are), depth clamp with primitives crossing the near and far planes and with depth bias,
//! depth bounds over edge ranges, and unrestricted depth values.

use super::{cmp_name, quad, Case, Config, Draw, DsState, Req};
use ash::vk;
use glam::camera::rh::proj::vulkan as proj;
use glam::Mat4;

const FOV: f32 = std::f32::consts::FRAC_PI_3;

/// Shadow-volume stencil ops: z-pass (front +1, back -1) on pass, z-fail (front -1, back +1)
/// on depth fail, so the stencil records which path each face took.
fn volume_stencil() -> (vk::StencilOpState, vk::StencilOpState) {
    let s = |pass, dfail| vk::StencilOpState {
        fail_op: vk::StencilOp::KEEP,
        pass_op: pass,
        depth_fail_op: dfail,
        compare_op: vk::CompareOp::ALWAYS,
        compare_mask: 0xff,
        write_mask: 0xff,
        reference: 0,
    };
    (
        s(vk::StencilOp::INCREMENT_AND_WRAP, vk::StencilOp::DECREMENT_AND_WRAP),
        s(vk::StencilOp::DECREMENT_AND_WRAP, vk::StencilOp::INCREMENT_AND_WRAP),
    )
}

fn incr_both() -> (vk::StencilOpState, vk::StencilOpState) {
    let s = vk::StencilOpState {
        fail_op: vk::StencilOp::KEEP,
        pass_op: vk::StencilOp::INCREMENT_AND_WRAP,
        depth_fail_op: vk::StencilOp::KEEP,
        compare_op: vk::CompareOp::ALWAYS,
        compare_mask: 0xff,
        write_mask: 0xff,
        reference: 0,
    };
    (s, s)
}

/// Triangles with every vertex at infinity (w = 0) around the direction at `angle` (radians)
/// off the view axis at `spread`; the second triangle is wound the other way (back facing).
fn w0_triangles(angle: f32, spread: f32) -> Vec<[f32; 4]> {
    let (c, s) = (angle.cos() * spread, angle.sin() * spread);
    let d = |dx: f32, dy: f32| [c + dx, s + dy, -1.0, 0.0];
    vec![d(-0.35, -0.2), d(0.3, -0.25), d(0.05, 0.35), d(0.1, -0.05), d(0.45, 0.3), d(-0.2, 0.4)]
}

fn infinity(config: Config) -> Vec<Case> {
    let mut v = Vec::new();
    let size = (32, 32);
    for (label, reverse) in [("forward", false), ("reverse", true)] {
        let p = if reverse { proj::perspective_infinite_reverse(FOV, 1.0, 0.1) } else { proj::perspective_infinite(FOV, 1.0, 0.1) };
        let clear = if reverse { 0.0 } else { 1.0 };
        let comps = if reverse {
            [vk::CompareOp::GREATER_OR_EQUAL, vk::CompareOp::GREATER]
        } else {
            [vk::CompareOp::LESS_OR_EQUAL, vk::CompareOp::LESS]
        };
        let mut dirs: Vec<(String, Vec<[f32; 4]>)> =
            (0..8).map(|k| (format!("dir_{k}"), w0_triangles(k as f32 * std::f32::consts::FRAC_PI_4, 0.45))).collect();
        dirs.push(("dir_axis".into(), w0_triangles(0.0, 0.0)));
        dirs.push(("dir_edge_crossing".into(), w0_triangles(0.3, 0.75)));
        for (dir, verts) in dirs {
            for comp in comps {
                let mut c = Case::new(config, "depth", &format!("infinity.{label}.{dir}.comp_{}", cmp_name(comp)), size, clear, 0x80);
                c.requires.push(Req::DepthAspect);
                c.what = format!(
                    "w = 0 vertices through the {label} infinite projection land at depth exactly {clear}; compare {} against the background cleared to {clear} (a dark cap)",
                    cmp_name(comp)
                );
                let state = DsState {
                    depth_test: true,
                    depth_write: true,
                    depth_compare: comp,
                    stencil: Some(volume_stencil()),
                    ..Default::default()
                };
                c.draws.push(Draw { state, mvp: p, vertices: verts.clone(), query: false });
                v.push(c);
            }
        }
        // Side-quad-like triangles: finite (w = 1) and infinite (w = 0) vertices mixed.
        let mut c = Case::new(config, "depth", &format!("infinity.{label}.mixed_w"), size, clear, 0x80);
        c.requires.push(Req::DepthAspect);
        c.what =
            format!("triangles mixing w = 1 and w = 0 vertices through the {label} infinite projection: coverage and interpolated depth");
        let verts = vec![
            [-0.8, -0.5, -2.0, 1.0],
            [-0.3, -0.6, -3.0, 1.0],
            [-0.2, -0.1, -1.0, 0.0],
            [0.5, 0.5, -2.5, 1.0],
            [0.1, -0.2, -1.0, 0.0],
            [0.9, 0.6, -4.0, 1.0],
        ];
        let state = DsState {
            depth_test: true,
            depth_write: true,
            depth_compare: vk::CompareOp::ALWAYS,
            stencil: Some(incr_both()),
            ..Default::default()
        };
        c.draws.push(Draw { state, mvp: p, vertices: verts, query: false });
        v.push(c);
    }
    v
}

/// A quad facing the camera's view of the whole (square) frustum at `inset` of its half-width,
/// its top edge at eye depth `z_top` and its bottom edge at `z_bottom` (both negative).
fn tilted_quad(z_top: f32, z_bottom: f32, inset: f32) -> Vec<[f32; 4]> {
    let t = (FOV * 0.5).tan() * inset;
    let p = |sx: f32, top: bool| {
        let z = if top { z_top } else { z_bottom };
        let sy = if top { 1.0 } else { -1.0 };
        [sx * t * -z, sy * t * -z, z, 1.0]
    };
    let (a, b, c, d) = (p(-1.0, true), p(1.0, true), p(1.0, false), p(-1.0, false));
    vec![a, d, c, a, c, b]
}

fn clamp(config: Config) -> Vec<Case> {
    let mut v = Vec::new();
    let size = (32, 32);
    let p: Mat4 = proj::perspective(FOV, 1.0, 1.0, 10.0);
    let geoms: [(&str, f32, f32, &str); 5] = [
        ("far_crossing", -5.0, -20.0, "crossing the far plane (10)"),
        ("near_crossing", -0.5, -3.0, "crossing the near plane (1)"),
        ("both_crossing", -0.5, -30.0, "crossing both planes"),
        ("beyond_far", -12.0, -40.0, "entirely beyond the far plane"),
        ("before_near", -0.3, -0.8, "entirely between the eye and the near plane"),
    ];
    for (name, zt, zb, what) in geoms {
        for on in [true, false] {
            let mut c = Case::new(config, "depth", &format!("clamp.{name}.clamp_{}", if on { "on" } else { "off" }), size, 1.0, 0);
            c.requires.push(Req::DepthAspect);
            if on {
                c.requires.push(Req::DepthClamp);
            }
            c.what = format!(
                "a quad {what}, depth clamp {}: {}",
                if on { "on" } else { "off" },
                if on { "fragments beyond the planes at depth exactly 0.0 / 1.0" } else { "clipped at the planes" }
            );
            let state = DsState {
                depth_test: true,
                depth_write: true,
                depth_compare: vk::CompareOp::ALWAYS,
                depth_clamp: on,
                stencil: Some(incr_both()),
                ..Default::default()
            };
            c.draws.push(Draw { state, mvp: p, vertices: tilted_quad(zt, zb, 0.8), query: false });
            v.push(c);
        }
    }
    // Depth bias (as a shadow-map pass uses it) pushing fragments past the planes: with depth
    // clamp they must still land at exactly 1.0 / 0.0.
    let biased: [(&str, f32, f32, f32); 4] = [
        ("inside.bias_pos", -2.0, -3.0, 2e8),
        ("inside.bias_neg", -2.0, -3.0, -2e8),
        ("far_crossing.bias_pos", -5.0, -20.0, 2e8),
        ("near_crossing.bias_neg", -0.5, -3.0, -2e8),
    ];
    for (name, zt, zb, bias) in biased {
        let mut c = Case::new(config, "depth", &format!("clamp.{name}.clamp_on"), size, 0.5, 0);
        c.requires.extend([Req::DepthAspect, Req::DepthClamp]);
        c.what =
            format!("constant depth bias {bias:e} with depth clamp: every fragment at exactly {}", if bias > 0.0 { "1.0" } else { "0.0" });
        let state = DsState {
            depth_test: true,
            depth_write: true,
            depth_compare: vk::CompareOp::ALWAYS,
            depth_clamp: true,
            depth_bias: Some(bias),
            stencil: Some(incr_both()),
            ..Default::default()
        };
        c.draws.push(Draw { state, mvp: p, vertices: tilted_quad(zt, zb, 0.8), query: false });
        v.push(c);
    }
    v
}

fn bounds(config: Config) -> Vec<Case> {
    let mut v = Vec::new();
    let stored = [0.0, 0.25, 0.5, 0.75, 1.0];
    let ranges: [(f32, f32, bool); 8] = [
        (0.0, 0.0, false),
        (1.0, 1.0, false),
        (0.5, 0.5, false),
        (0.0, 1.0, false),
        (0.25, 0.75, false),
        (0.0, 0.5, false),
        (-1.0, 2.0, true),
        (1.5, 3.0, true),
    ];
    for (lo, hi, unrestricted) in ranges {
        let mut c = Case::new(config, "depth", &format!("bounds.min_{lo}_max_{hi}"), (10, 4), 1.0, 0);
        c.requires.extend([Req::DepthAspect, Req::DepthBounds]);
        if unrestricted {
            c.requires.push(Req::DepthRangeUnrestricted);
        }
        for (i, d) in c.init_depth.iter_mut().enumerate() {
            *d = stored[(i % 10) / 2];
        }
        c.what = format!("depth bounds [{lo}, {hi}] against stored depths 0, 0.25, 0.5, 0.75, 1 (inclusive)");
        let mut verts = Vec::new();
        quad(&mut verts, [0.0, 0.0, 10.0, 4.0], 0.5, true);
        let state = DsState { depth_bounds: Some((lo, hi)), stencil: Some(incr_both()), ..Default::default() };
        c.draws.push(Draw { state, mvp: super::pixel_ortho(10, 4), vertices: verts, query: false });
        v.push(c);
    }
    v
}

fn unrestricted(config: Config) -> Vec<Case> {
    let mut v = Vec::new();
    // (name, stored, quad ndc z, viewport, clamp, what)
    type Row = (&'static str, f64, f32, (f32, f32), bool, &'static str);
    let list: [Row; 4] = [
        ("viewport_0_4", 3.0, 0.5, (0.0, 4.0), false, "viewport depth [0, 4]: ndc 0.5 -> 2.0 < stored 3.0, written unclamped"),
        ("stored_above_one", 2.5, 1.0, (0.0, 1.0), false, "stored 2.5 (outside [0, 1]) compared and overwritten with 1.0"),
        ("negative_viewport", 0.0, 0.5, (-2.0, 1.0), false, "viewport depth [-2, 1]: ndc 0.5 -> -0.5 < stored 0, written"),
        ("clamp_to_viewport", 9.0, 1.5, (0.0, 4.0), true, "depth clamp clamps to the viewport range [0, 4], not [0, 1]"),
    ];
    for (name, stored, z, vp, clamp, what) in list {
        let mut c = Case::new(config, "depth", &format!("unrestricted.{name}"), (8, 8), stored, 0);
        c.requires.extend([Req::DepthAspect, Req::FloatDepth, Req::DepthRangeUnrestricted]);
        if clamp {
            c.requires.push(Req::DepthClamp);
        }
        c.what = what.into();
        let mut verts = Vec::new();
        quad(&mut verts, [1.0, 1.0, 7.0, 7.0], z, true);
        let state = DsState {
            depth_test: true,
            depth_write: true,
            depth_compare: vk::CompareOp::LESS,
            depth_clamp: clamp,
            stencil: Some(incr_both()),
            viewport_depth: vp,
            ..Default::default()
        };
        c.draws.push(Draw { state, mvp: super::pixel_ortho(8, 8), vertices: verts, query: false });
        v.push(c);
    }
    v
}

/// The depth cases of `config` (all need a depth aspect).
pub fn cases(config: Config) -> Vec<Case> {
    let mut v = infinity(config);
    v.extend(clamp(config));
    v.extend(bounds(config));
    v.extend(unrestricted(config));
    v
}
