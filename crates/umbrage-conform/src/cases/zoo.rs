//! The known-bug zoo: small repros of stencil-shadow driver bugs reported in public issue
//! trackers, each naming the report it would have caught.

use super::{cmp_name, quad, Bug, Case, Config, Draw, DsState, Req};
use ash::vk;
use glam::camera::rh::proj::vulkan as proj;

const SEPARATE_OPS: Bug = Bug {
    url: "https://github.com/dhewm/dhewm3/issues/522",
    title: "dhewm3: stencil shadows broken on Mesa 22.3 (radeonsi, RX 580); workaround r_useStencilOpSeparate 0 / r_useCarmacksReverse 0",
};
const TWO_SIDED: Bug = Bug {
    url: "https://github.com/ljbade/doom3.gpl/issues/3",
    title: "doom3.gpl: no shadows on a GeForce GTX 560 Ti with two-sided stencil; workaround r_useTwoSidedStencil 0",
};
const CLAMP_FAR: Bug = Bug {
    url: "https://github.com/dolphin-emu/dolphin/pull/4085",
    title: "Mesa bug 97231 (llvmpipe): GL_DEPTH_CLAMP doesn't clamp to the far plane (reported from Dolphin's depth-range work)",
};

fn op(pass: vk::StencilOp, dfail: vk::StencilOp) -> vk::StencilOpState {
    vk::StencilOpState {
        fail_op: vk::StencilOp::KEEP,
        pass_op: pass,
        depth_fail_op: dfail,
        compare_op: vk::CompareOp::ALWAYS,
        compare_mask: 0xff,
        write_mask: 0xff,
        reference: 0,
    }
}

/// The zoo cases of `config`.
pub fn cases(config: Config) -> Vec<Case> {
    let mut v = Vec::new();
    let (w, h) = (16u32, 16u32);
    let ortho = super::pixel_ortho(w, h);
    let k = vk::StencilOp::KEEP;

    // 1. Separate stencil ops (z-fail, Carmack's reverse) right after a one-sided draw: a
    // driver that keeps stale back-face state, or applies the front ops to both faces, counts
    // wrong. Three overlapping box volumes (front faces at 0.3, back faces at 0.7) over a
    // receiver at depth 0.5 in the middle of the tile.
    let mut c = Case::new(config, "zoo", "separate_stencil_ops_zfail", (w, h), 1.0, 0x40);
    c.requires.push(Req::DepthAspect);
    for (i, d) in c.init_depth.iter_mut().enumerate() {
        let (x, y) = (i as u32 % w, i as u32 / w);
        if (3..13).contains(&x) && (3..13).contains(&y) {
            *d = 0.5;
        }
    }
    let mut clear = Vec::new();
    quad(&mut clear, [0.0, 0.0, 16.0, 16.0], 0.0, true);
    quad(&mut clear, [0.0, 8.0, 16.0, 16.0], 0.0, false);
    let zero = op(vk::StencilOp::ZERO, vk::StencilOp::ZERO);
    c.draws.push(Draw { state: DsState { stencil: Some((zero, zero)), ..Default::default() }, mvp: ortho, vertices: clear, query: false });
    let mut boxes = Vec::new();
    for r in [[1.0, 1.0, 10.0, 10.0], [5.0, 4.0, 15.0, 12.0], [2.0, 7.0, 9.0, 15.0]] {
        quad(&mut boxes, r, 0.3, true);
        quad(&mut boxes, r, 0.7, false);
    }
    let state = DsState {
        depth_test: true,
        depth_compare: vk::CompareOp::LESS,
        stencil: Some((op(k, vk::StencilOp::DECREMENT_AND_WRAP), op(k, vk::StencilOp::INCREMENT_AND_WRAP))),
        ..Default::default()
    };
    c.draws.push(Draw { state, mvp: ortho, vertices: boxes, query: false });
    c.what =
        "z-fail with separate front/back depth-fail ops right after a one-sided ZERO draw: 3 overlapping volumes over a receiver".into();
    c.bug = Some(SEPARATE_OPS);
    v.push(c);

    // 2. Two-sided stencil wrapping past 256 in one draw: 260 front-facing layers over the tile
    // and 3 back-facing ones over its left half.
    let mut c = Case::new(config, "zoo", "two_sided_stencil_wrap_260", (w, h), 1.0, 0);
    let mut layers = Vec::new();
    for _ in 0..260 {
        quad(&mut layers, [0.0, 0.0, 16.0, 16.0], 0.5, true);
    }
    for _ in 0..3 {
        quad(&mut layers, [0.0, 0.0, 8.0, 16.0], 0.5, false);
    }
    let state = DsState {
        stencil: Some((op(vk::StencilOp::INCREMENT_AND_WRAP, k), op(vk::StencilOp::DECREMENT_AND_WRAP, k))),
        ..Default::default()
    };
    c.draws.push(Draw { state, mvp: ortho, vertices: layers, query: false });
    c.what = "two-sided z-pass counting in one draw: 260 front layers (+1) and 3 back layers (-1) wrap to 4 and 1".into();
    c.check_depth = false;
    c.bug = Some(TWO_SIDED);
    v.push(c);

    // 3. Dark caps at infinity through a finite far plane with depth clamp: w = 0 vertices
    // project beyond the far plane (z/w = far / (far - near) > 1) and must be clamped to
    // exactly 1.0, where the background was cleared.
    for comp in [vk::CompareOp::LESS_OR_EQUAL, vk::CompareOp::LESS] {
        let mut c = Case::new(config, "zoo", &format!("depth_clamp_w0_finite_far.comp_{}", cmp_name(comp)), (32, 32), 1.0, 0x80);
        c.requires.extend([Req::DepthAspect, Req::DepthClamp]);
        let verts = vec![
            [-0.35, -0.2, -1.0, 0.0],
            [0.3, -0.25, -1.0, 0.0],
            [0.05, 0.35, -1.0, 0.0],
            [0.1, -0.05, -1.0, 0.0],
            [0.45, 0.3, -1.0, 0.0],
            [-0.2, 0.4, -1.0, 0.0],
        ];
        let state = DsState {
            depth_test: true,
            depth_write: true,
            depth_compare: comp,
            depth_clamp: true,
            stencil: Some((
                op(vk::StencilOp::INCREMENT_AND_WRAP, vk::StencilOp::DECREMENT_AND_WRAP),
                op(vk::StencilOp::DECREMENT_AND_WRAP, vk::StencilOp::INCREMENT_AND_WRAP),
            )),
            ..Default::default()
        };
        let mvp = proj::perspective(std::f32::consts::FRAC_PI_3, 1.0, 0.1, 10.0);
        c.draws.push(Draw { state, mvp, vertices: verts, query: false });
        c.what = format!(
            "w = 0 dark-cap triangles through a finite far plane with depth clamp: clamped to exactly 1.0, compare {} against the cleared 1.0",
            cmp_name(comp)
        );
        c.bug = Some(CLAMP_FAR);
        v.push(c);
    }
    v
}
