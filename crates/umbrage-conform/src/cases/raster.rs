//! Rasterisation that shadow volumes depend on: watertight fans at large coordinates and of
//! sliver triangles (finite and at infinity), shared edges through pixel centres, and
//! occlusion-query sample counts (the bench suite counts fragments with them).
//!
//! Watertight and shared-edge cases state their expectation directly: the union of the
//! triangles covers the whole tile and every interior edge is shared, so Vulkan's
//! tie-breaking rule ("exactly one of two polygons sharing an edge covers a sample on it")
//! leaves a count of exactly 1 at every pixel — whatever the driver's rule for ties is.

use super::{quad, Case, Config, Draw, DsState, Req};
use ash::vk;
use glam::camera::rh::proj::vulkan as proj;

fn incr() -> (vk::StencilOpState, vk::StencilOpState) {
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

fn counting_state() -> DsState {
    DsState { stencil: Some(incr()), ..Default::default() }
}

fn all_ones(c: &mut Case) {
    c.stencil_override = Some(vec![Some(1); (c.size.0 * c.size.1) as usize]);
    c.check_depth = false;
}

fn watertight(config: Config) -> Vec<Case> {
    let mut v = Vec::new();
    let size = (32u32, 32u32);
    for n in [3u32, 16, 1000] {
        for (rname, r) in [("1e3", 1e3f32), ("1e5", 1e5), ("1e7", 1e7)] {
            let mut c = Case::new(config, "raster", &format!("watertight.fan_{n}.radius_{rname}"), size, 1.0, 0);
            c.what = format!("a {n}-triangle fan of radius {rname} pixels around an off-centre point: every pixel counted exactly once");
            let (cx, cy) = (13.3f32, 17.7f32);
            let ring: Vec<[f32; 2]> = (0..n)
                .map(|k| {
                    let a = k as f32 / n as f32 * std::f32::consts::TAU + 0.1;
                    [cx + r * a.cos(), cy + r * a.sin()]
                })
                .collect();
            let mut verts = Vec::new();
            for k in 0..n as usize {
                let (p, q) = (ring[k], ring[(k + 1) % n as usize]);
                verts.extend([[cx, cy, 0.5, 1.0], [p[0], p[1], 0.5, 1.0], [q[0], q[1], 0.5, 1.0]]);
            }
            c.draws.push(Draw { state: counting_state(), mvp: super::pixel_ortho(size.0, size.1), vertices: verts, query: false });
            all_ones(&mut c);
            v.push(c);
        }
    }
    // A fan at infinity (every vertex w = 0) whose ring lies far outside the frustum: the
    // clipper cuts every triangle, and the pieces must still tile the screen exactly.
    for n in [16u32, 1000] {
        let mut c = Case::new(config, "raster", &format!("watertight.infinite_fan_{n}"), size, 1.0, 0);
        c.what =
            format!("a {n}-triangle fan with every vertex at infinity (w = 0), ring outside the frustum: every pixel counted exactly once");
        let centre = [0.031f32, -0.047];
        let mut verts = Vec::new();
        for k in 0..n {
            let a0 = k as f32 / n as f32 * std::f32::consts::TAU + 0.05;
            let a1 = (k + 1) as f32 / n as f32 * std::f32::consts::TAU + 0.05;
            let rim = |a: f32| [centre[0] + 3.0 * a.cos(), centre[1] + 3.0 * a.sin(), -1.0, 0.0];
            verts.extend([[centre[0], centre[1], -1.0, 0.0], rim(a0), rim(a1)]);
        }
        let mvp = proj::perspective_infinite(std::f32::consts::FRAC_PI_3, 1.0, 0.1);
        c.draws.push(Draw { state: counting_state(), mvp, vertices: verts, query: false });
        all_ones(&mut c);
        v.push(c);
    }
    v
}

fn shared_edges(config: Config) -> Vec<Case> {
    let mut v = Vec::new();
    let size = (8u32, 8u32);
    // (name, P, Q): the shared edge passes through the pixel centres P and Q.
    let lines: [(&str, [f32; 2], [f32; 2]); 6] = [
        ("horizontal", [0.5, 3.5], [7.5, 3.5]),
        ("vertical", [4.5, 0.5], [4.5, 7.5]),
        ("diagonal", [0.5, 0.5], [7.5, 7.5]),
        ("antidiagonal", [0.5, 7.5], [7.5, 0.5]),
        ("slope_half", [0.5, 2.5], [4.5, 4.5]),
        ("slope_three", [2.5, 0.5], [4.5, 6.5]),
    ];
    for (name, p, q) in lines {
        let mut c = Case::new(config, "raster", &format!("shared_edge.{name}"), size, 1.0, 0);
        c.what = "two triangles sharing an edge through pixel centres, drawn separately (INCR_WRAP; INVERT of bit 7): \
                  every centre on the edge covered by exactly one (which one is the driver's choice; the D3D top-left \
                  convention is reported)"
            .into();
        let d = [q[0] - p[0], q[1] - p[1]];
        let (a, b) = ([p[0] - 10.0 * d[0], p[1] - 10.0 * d[1]], [p[0] + 10.0 * d[0], p[1] + 10.0 * d[1]]);
        let n = [-d[1] * 20.0, d[0] * 20.0];
        let m = [(a[0] + b[0]) * 0.5, (a[1] + b[1]) * 0.5];
        let v4 = |x: [f32; 2]| [x[0], x[1], 0.5, 1.0];
        let tri_a = vec![v4(a), v4(b), v4([m[0] + n[0], m[1] + n[1]])];
        let tri_b = vec![v4(b), v4(a), v4([m[0] - n[0], m[1] - n[1]])];
        let ortho = super::pixel_ortho(size.0, size.1);
        c.draws.push(Draw { state: counting_state(), mvp: ortho, vertices: tri_a, query: false });
        let mut high = incr();
        for s in [&mut high.0, &mut high.1] {
            s.pass_op = vk::StencilOp::INVERT;
            s.write_mask = 0x80;
        }
        c.draws.push(Draw { state: DsState { stencil: Some(high), ..Default::default() }, mvp: ortho, vertices: tri_b, query: false });
        // The D3D rule gives the centre to the triangle whose left (or, for a horizontal
        // edge, top) edge it is: A lies on the +n side of a -> b.
        let a_owns = if d[1] != 0.0 { n[0] > 0.0 } else { n[1] > 0.0 };
        for y in 0..size.1 {
            for x in 0..size.0 {
                let (cx, cy) = (x as f32 + 0.5 - p[0], y as f32 + 0.5 - p[1]);
                if cx * d[1] - cy * d[0] == 0.0 {
                    c.either.push(((y * size.0 + x) as usize, [0x01, 0x80], if a_owns { 0x01 } else { 0x80 }));
                }
            }
        }
        c.check_depth = false;
        v.push(c);
    }
    v
}

fn occlusion(config: Config) -> Vec<Case> {
    let mut v = Vec::new();
    let size = (16u32, 16u32);
    let ortho = super::pixel_ortho(size.0, size.1);
    let mut add = |name: &str, what: &str, depth: bool, setup: &dyn Fn(&mut Case)| {
        let mut c = Case::new(config, "raster", &format!("occlusion.{name}"), size, 1.0, 0);
        c.requires.push(Req::OcclusionQueryPrecise);
        if depth {
            c.requires.push(Req::DepthAspect);
        }
        c.what = format!("occlusion query (precise) sample count: {what}");
        setup(&mut c);
        v.push(c);
    };
    add("full_tile", "a quad over the whole tile", false, &|c| {
        let mut verts = Vec::new();
        quad(&mut verts, [0.0, 0.0, 16.0, 16.0], 0.5, true);
        c.draws.push(Draw { state: counting_state(), mvp: ortho, vertices: verts, query: true });
    });
    add("triangle", "a triangle on the sub-pixel grid", false, &|c| {
        let verts = vec![[1.25, 0.75, 0.5, 1.0], [2.5, 15.125, 0.5, 1.0], [14.875, 9.375, 0.5, 1.0]];
        c.draws.push(Draw { state: counting_state(), mvp: ortho, vertices: verts, query: true });
    });
    add("zero_area", "a degenerate triangle counts nothing", false, &|c| {
        let verts = vec![[1.0, 1.0, 0.5, 1.0], [8.0, 8.0, 0.5, 1.0], [15.0, 15.0, 0.5, 1.0]];
        c.draws.push(Draw { state: counting_state(), mvp: ortho, vertices: verts, query: true });
    });
    add("depth_half", "half the samples fail the depth test", true, &|c| {
        for (i, d) in c.init_depth.iter_mut().enumerate() {
            *d = if i % 16 < 8 { 0.25 } else { 0.75 };
        }
        let mut verts = Vec::new();
        quad(&mut verts, [0.0, 0.0, 16.0, 16.0], 0.5, false);
        let state = DsState { depth_test: true, depth_compare: vk::CompareOp::LESS, stencil: Some(incr()), ..Default::default() };
        c.draws.push(Draw { state, mvp: ortho, vertices: verts, query: true });
    });
    add("stencil_half", "half the samples fail the stencil test", false, &|c| {
        for (i, s) in c.init_stencil.iter_mut().enumerate() {
            *s = ((i / 16) % 2) as u8;
        }
        let mut verts = Vec::new();
        quad(&mut verts, [0.0, 0.0, 16.0, 16.0], 0.5, true);
        let mut st = incr();
        st.0.compare_op = vk::CompareOp::EQUAL;
        st.0.reference = 1;
        st.1 = st.0;
        let state = DsState { stencil: Some(st), ..Default::default() };
        c.draws.push(Draw { state, mvp: ortho, vertices: verts, query: true });
    });
    for (label, comp) in [("dark_cap_lequal", vk::CompareOp::LESS_OR_EQUAL), ("dark_cap_less", vk::CompareOp::LESS)] {
        add(label, "w = 0 triangles at depth 1.0 against a background cleared to 1.0", true, &|c| {
            let verts = vec![
                [-0.35, -0.2, -1.0, 0.0],
                [0.3, -0.25, -1.0, 0.0],
                [0.05, 0.35, -1.0, 0.0],
                [0.1, -0.05, -1.0, 0.0],
                [0.45, 0.3, -1.0, 0.0],
                [-0.2, 0.4, -1.0, 0.0],
            ];
            let state = DsState { depth_test: true, depth_compare: comp, stencil: Some(incr()), ..Default::default() };
            let mvp = proj::perspective_infinite(std::f32::consts::FRAC_PI_3, 1.0, 0.1);
            c.draws.push(Draw { state, mvp, vertices: verts, query: true });
        });
    }
    v
}

/// The rasterisation cases of `config`.
pub fn cases(config: Config) -> Vec<Case> {
    let mut v = watertight(config);
    v.extend(shared_edges(config));
    v.extend(occlusion(config));
    v
}
