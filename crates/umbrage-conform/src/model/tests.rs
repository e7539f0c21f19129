//! The model's own tests: the op table, interval compares, judged pixels, the seam, raw depth words.
use super::*;

#[test]
fn stencil_ops_follow_the_spec() {
    assert_eq!(apply_op(vk::StencilOp::INCREMENT_AND_WRAP, 255, 0, 0xff), 0);
    assert_eq!(apply_op(vk::StencilOp::INCREMENT_AND_CLAMP, 255, 0, 0xff), 255);
    assert_eq!(apply_op(vk::StencilOp::DECREMENT_AND_WRAP, 0, 0, 0xff), 255);
    assert_eq!(apply_op(vk::StencilOp::DECREMENT_AND_CLAMP, 0, 0, 0xff), 0);
    assert_eq!(apply_op(vk::StencilOp::INVERT, 0xc3, 0, 0x0f), 0xcc);
    assert_eq!(apply_op(vk::StencilOp::REPLACE, 0x00, 0xab, 0xf0), 0xa0);
    // The write mask keeps the unmasked bits: 0x0f + 1 wraps within the low nibble only.
    assert_eq!(apply_op(vk::StencilOp::INCREMENT_AND_WRAP, 0x1f, 0, 0x0f), 0x10);
    assert!(stencil_test(vk::CompareOp::LESS, 0x03, 0x7f, 0xff));
    assert!(!stencil_test(vk::CompareOp::LESS, 0x83, 0x7f, 0xff));
    assert!(stencil_test(vk::CompareOp::EQUAL, 0x13, 0x23, 0x0f));
}

#[test]
fn interval_compares() {
    assert_eq!(compare(vk::CompareOp::LESS, (0.5, 0.5), (0.75, 0.75)), Some(true));
    assert_eq!(compare(vk::CompareOp::LESS, (1.0, 1.0), (1.0, 1.0)), Some(false));
    assert_eq!(compare(vk::CompareOp::LESS_OR_EQUAL, (1.0, 1.0), (1.0, 1.0)), Some(true));
    assert_eq!(compare(vk::CompareOp::GREATER, (0.4, 0.6), (0.5, 0.5)), None);
    assert_eq!(compare(vk::CompareOp::NOT_EQUAL, (0.0, 0.0), (1.0, 1.0)), Some(true));
}

#[test]
fn stencil_zoo_and_occlusion_cases_judge_every_pixel() {
    use crate::cases::{self, Config, FORMATS};
    let all = cases::all(&Config::all(&FORMATS));
    let mut n = 0;
    for c in all.iter().filter(|c| c.group == "stencil" || c.group == "zoo" || c.name.contains(".occlusion.")) {
        let e = expect(c, 8, None);
        let judged = e.stencil.iter().filter(|s| s.is_some()).count();
        // Perspective draws (w = 0 dark caps) get a one-sub-pixel band around their edges.
        let perspective = c.draws.iter().any(|d| d.vertices.iter().any(|v| v[3] == 0.0));
        if perspective {
            assert!(judged * 10 >= e.stencil.len() * 9, "{}: {judged} of {} judged", c.name, e.stencil.len());
            assert!(e.queries.iter().all(|q| q.1 - q.0 <= 16), "{}: query range {:?}", c.name, e.queries);
        } else {
            assert_eq!(judged, e.stencil.len(), "{}: unjudged pixels", c.name);
            assert!(e.queries.iter().all(|q| q.0 == q.1), "{}: query range {:?}", c.name, e.queries);
        }
        n += 1;
    }
    assert!(n > 800);
}

#[test]
fn the_seam_changes_expectations() {
    use crate::cases::{self, Config};
    let cfg = Config { format: vk::Format::D24_UNORM_S8_UINT, render: cases::RenderModel::RenderPass, state: cases::StateModel::Static };
    let all = cases::all(&[cfg]);
    let changed = all.iter().filter(|c| expect(c, 8, None) != expect(c, 8, Some(vk::StencilOp::INCREMENT_AND_WRAP))).count();
    assert!(changed > 20 && changed < all.len(), "{changed} of {}", all.len());
}

#[test]
fn depth_words_round_trip() {
    for kind in [DepthKind::Unorm16, DepthKind::Unorm24, DepthKind::Float32] {
        for v in [0.0, 0.25, 0.5, 1.0] {
            let q = quantise(kind, v);
            assert_eq!(from_raw(kind, to_raw(kind, q)), q);
        }
    }
    assert_eq!(from_raw(DepthKind::Unorm24, 0xff00_0000 | 16_777_215), 1.0);
}
