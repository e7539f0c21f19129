//! `bench/level`'s motion (issue 55): the camera walking, characters turning and lights
//! circling, rendered with the plans kept across frames and planned from scratch
//! (`RenderOptions::keep`): every frame's stencil is the same, byte for byte, light by light.

use crate::common;
use umbrage_render::{RenderOptions, Renderer};

/// The motion's times, seconds: the first frames (every pair planned, then mostly kept),
/// larger steps, and the walk's first corner (the view turning on the spot).
const TIMES: [f64; 6] = [0.0, 1.0 / 30.0, 2.0 / 30.0, 0.5, 1.5, 47.0];

/// Each frame's per-light stencils and its (pairs kept, pairs replanned).
type Frames = Vec<(Vec<Vec<u8>>, (u64, u64))>;

fn walk(ctx: umbrage::gpu::Context, keep: bool) -> (umbrage::gpu::Context, Frames) {
    let (scene, motion) = umbrage_scene::load_animated("bench/level").unwrap();
    let opts = RenderOptions { width: 128, height: 72, capture: true, keep, ..Default::default() };
    let mut r = Renderer::new(ctx, scene.clone(), opts).unwrap();
    let mut frames = Vec::new();
    for t in TIMES {
        umbrage_bench::motion::move_to(&mut r, &scene, &motion, t).unwrap();
        let f = r.render().unwrap();
        frames.push((f.stencil, (f.stats.totals.pairs_kept, f.stats.totals.pairs_replanned)));
    }
    r.context().check_validation().unwrap();
    (r.into_context(), frames)
}

#[test]
fn level_motion_kept_and_fresh_stencils_are_the_same() {
    let Some(ctx) = common::context() else { return };
    let (ctx, kept) = walk(ctx, true);
    let (ctx, fresh) = walk(ctx, false);
    ctx.check_validation().unwrap();
    let mut shadowed = 0;
    for (k, ((a, (kept_pairs, replanned)), (b, (fresh_kept, _)))) in kept.iter().zip(&fresh).enumerate() {
        assert_eq!(*fresh_kept, 0, "frame {k}: nothing is kept without keeping");
        if k > 0 {
            // Not vacuous: the frame drew kept plans, and planned what moved.
            assert!(*kept_pairs > 0 && *replanned > 0, "frame {k}: {kept_pairs} kept, {replanned} replanned");
        }
        assert_eq!(a.len(), b.len());
        for (l, (sa, sb)) in a.iter().zip(b).enumerate() {
            assert!(sa == sb, "frame {k} (t = {} s), light {l}: the kept plans' stencil differs", TIMES[k]);
            shadowed += sa.iter().filter(|&&s| s != 0).count();
        }
    }
    assert!(shadowed > 0, "no shadow in any frame");
}
