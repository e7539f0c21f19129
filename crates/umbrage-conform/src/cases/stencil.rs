//! The stencil-op table shadow volumes use, CTS-style (`dEQP-VK.pipeline.*.stencil.*`).
//!
//! Every case draws into an 8 x 8 tile whose rows start at eight different stencil values
//! ([`ROW_STENCIL`]: 0, 1, 3, 0x7f, 0x80, 0xc3, 0xfe, 0xff — both wrap points, both sides of
//! the reference values) and whose columns are, left to right: 2 front-facing pixels whose
//! depth test passes, 2 front-facing where it fails, then the same for back faces. One draw
//! (a front-facing quad over the left half, a back-facing quad over the right half, fragment
//! depth 0.5, compare LESS against stored 0.75 / 0.25) so each case exercises the stencil
//! test, the depth-fail and the pass path of both faces at 8 starting values at once. With
//! S8_UINT there is no depth: every column passes its (absent) depth test.

use super::{cmp_name, op_name, quad, Case, Config, Draw, DsState, COMPARE_OPS, STENCIL_OPS};
use ash::vk;

/// The starting stencil value of each tile row.
pub const ROW_STENCIL: [u8; 8] = [0x00, 0x01, 0x03, 0x7f, 0x80, 0xc3, 0xfe, 0xff];
const REFS: [u32; 6] = [0x00, 0x03, 0x7f, 0x80, 0xfe, 0xff];
const MASKS: [(u32, u32); 5] = [(0xff, 0xff), (0xff, 0x0f), (0x0f, 0xff), (0xf0, 0x3c), (0x7f, 0xfe)];

fn state(op: [vk::StencilOp; 3], comp: vk::CompareOp, reference: u32, masks: (u32, u32)) -> vk::StencilOpState {
    vk::StencilOpState {
        pass_op: op[0],
        depth_fail_op: op[1],
        fail_op: op[2],
        compare_op: comp,
        compare_mask: masks.0,
        write_mask: masks.1,
        reference,
    }
}

fn tile_case(config: Config, rest: String, what: String, front: vk::StencilOpState, back: vk::StencilOpState) -> Case {
    let mut c = Case::new(config, "stencil", &rest, (8, 8), 1.0, 0);
    for (y, &row) in ROW_STENCIL.iter().enumerate() {
        for x in 0..8usize {
            let i = y * 8 + x;
            c.init_stencil[i] = row;
            c.init_depth[i] = if (x / 2) % 2 == 0 { 0.75 } else { 0.25 };
        }
    }
    let mut v = Vec::new();
    quad(&mut v, [0.0, 0.0, 4.0, 8.0], 0.5, true);
    quad(&mut v, [4.0, 0.0, 8.0, 8.0], 0.5, false);
    let state = DsState {
        depth_test: config.has_depth(),
        depth_write: false,
        depth_compare: vk::CompareOp::LESS,
        stencil: Some((front, back)),
        ..Default::default()
    };
    c.draws.push(Draw { state, mvp: super::pixel_ortho(8, 8), vertices: v, query: false });
    c.what = what;
    c
}

/// The stencil cases of `config`.
pub fn cases(config: Config) -> Vec<Case> {
    let mut v = Vec::new();
    // (a) Every (front pass op, back pass op) pair, the other parameters cycling with coprime
    // strides so that every op also appears as depth-fail and fail op, and every compare op,
    // reference and mask pair is used.
    for i in 0..64usize {
        let (fp, bp) = (STENCIL_OPS[i % 8], STENCIL_OPS[i / 8]);
        let dfail = STENCIL_OPS[(i * 3 + 1) % 8];
        let fail = STENCIL_OPS[(i * 5 + 2) % 8];
        let comp = COMPARE_OPS[(i * 3 + i / 8) % 8];
        let r = REFS[i % 6];
        let m = MASKS[i % 5];
        let rest = format!(
            "ops.front_{}.back_{}.dfail_{}.fail_{}.comp_{}.ref_{}.masks_{:02x}_{:02x}",
            op_name(fp),
            op_name(bp),
            op_name(dfail),
            op_name(fail),
            cmp_name(comp),
            r,
            m.0,
            m.1
        );
        v.push(tile_case(
            config,
            rest,
            "pass op per face, shared depth-fail/fail ops, compare op, reference and masks".into(),
            state([fp, dfail, fail], comp, r, m),
            state([bp, dfail, fail], comp, r, m),
        ));
    }
    // (b) z-fail: the depth-fail op per face (Carmack's reverse counts on depth fail).
    let counting = [
        vk::StencilOp::INCREMENT_AND_WRAP,
        vk::StencilOp::DECREMENT_AND_WRAP,
        vk::StencilOp::INCREMENT_AND_CLAMP,
        vk::StencilOp::DECREMENT_AND_CLAMP,
        vk::StencilOp::KEEP,
        vk::StencilOp::INVERT,
    ];
    for &f in &counting {
        for &b in &counting {
            let k = vk::StencilOp::KEEP;
            v.push(tile_case(
                config,
                format!("zfail.front_dfail_{}.back_dfail_{}.comp_always.ref_0.masks_ff_ff", op_name(f), op_name(b)),
                "z-fail counting: depth-fail op per face, pass and fail KEEP".into(),
                state([k, f, k], vk::CompareOp::ALWAYS, 0, (0xff, 0xff)),
                state([k, b, k], vk::CompareOp::ALWAYS, 0, (0xff, 0xff)),
            ));
        }
    }
    // (c) z-pass: the pass op per face with the counting ops.
    for &f in &counting[..4] {
        for &b in &counting[..4] {
            let k = vk::StencilOp::KEEP;
            v.push(tile_case(
                config,
                format!("zpass.front_pass_{}.back_pass_{}.comp_always.ref_0.masks_ff_ff", op_name(f), op_name(b)),
                "z-pass counting: pass op per face, depth-fail and fail KEEP".into(),
                state([f, k, k], vk::CompareOp::ALWAYS, 0, (0xff, 0xff)),
                state([b, k, k], vk::CompareOp::ALWAYS, 0, (0xff, 0xff)),
            ));
        }
    }
    // (d) The stencil test: every compare op against references on both sides of the row
    // values, with and without a compare mask; pass / depth-fail / fail ops all distinct.
    for &comp in &COMPARE_OPS {
        for &r in &[0x00u32, 0x03, 0x80, 0xff] {
            for &m in &[(0xffu32, 0xffu32), (0x0f, 0xff)] {
                let ops = [vk::StencilOp::INCREMENT_AND_WRAP, vk::StencilOp::DECREMENT_AND_WRAP, vk::StencilOp::INVERT];
                v.push(tile_case(
                    config,
                    format!("compare.comp_{}.ref_{}.masks_{:02x}_{:02x}", cmp_name(comp), r, m.0, m.1),
                    "stencil test (reference & mask) OP (stored & mask); pass incr_wrap, dfail decr_wrap, fail invert".into(),
                    state(ops, comp, r, m),
                    state(ops, comp, r, m),
                ));
            }
        }
    }
    // (e) Two-sided with different masks, references, compare ops and ops per face.
    let face_masks = [(0xffu32, 0xffu32), (0x0f, 0x0f), (0xf0, 0x0f), (0xff, 0x01), (0x3c, 0xc3)];
    for &fm in &face_masks {
        for &bm in &face_masks {
            let front = state(
                [vk::StencilOp::INCREMENT_AND_WRAP, vk::StencilOp::REPLACE, vk::StencilOp::INVERT],
                vk::CompareOp::GREATER_OR_EQUAL,
                0x80,
                fm,
            );
            let back =
                state([vk::StencilOp::DECREMENT_AND_WRAP, vk::StencilOp::INVERT, vk::StencilOp::REPLACE], vk::CompareOp::LESS, 0x03, bm);
            v.push(tile_case(
                config,
                format!(
                    "two_sided.front_incr_wrap.back_decr_wrap.dfail_replace_invert.fail_invert_replace.comp_greater_or_equal_less.ref_128_3.masks_{:02x}_{:02x}_{:02x}_{:02x}",
                    fm.0, fm.1, bm.0, bm.1
                ),
                "two-sided stencil: different ops, compare ops, references and compare/write masks per face".into(),
                front,
                back,
            ));
        }
    }
    v
}
