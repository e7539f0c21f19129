//! Debug views: `--view volumes` (the shadow pass's volumes translucent over the scene,
//! coloured by case) and `--view stencil` (light 0's counts as a heat map, on the CPU).
//!
//! Inputs / outputs (`record_volumes`, `--view volumes` only, after the transparent passes, before `tonemap`):
//! - Reads: `depth` as the depth-stencil attachment in `DEPTH_STENCIL_ATTACHMENT_OPTIMAL`, LOAD/STORE; nothing sampled.
//! - Writes: `accum` in `COLOR_ATTACHMENT_OPTIMAL`, LOAD/STORE (the overlay over the lit scene).
//! - Leaves both there (no transition), as `tonemap` expects. `stencil_heatmap` works on the read-back stencil on the CPU.

use super::{att, Rec, DS_CLEAR, ZERO};
use crate::targets::Targets;
use ash::vk;
use umbrage::pass::diagnostics::Diagnostics;
use umbrage::pass::{PreparedFrame, ShadowPass};

/// # Safety
/// `rec.cb` is recording outside a rendering instance; accumulation and depth in attachment
/// layout; the pass was created with the accumulation format as its debug colour format.
pub(crate) unsafe fn record_volumes(rec: &Rec, pass: &ShadowPass, frame: &PreparedFrame, t: &Targets) -> umbrage::error::Result<()> {
    let load = vk::AttachmentLoadOp::LOAD;
    let accum = [att(&t.accum, load, ZERO)];
    let depth = att(&t.depth, load, DS_CLEAR);
    // SAFETY: the caller's contract.
    unsafe {
        rec.begin(rec.full, &accum, Some(&depth));
        let r = pass.cmd_draw_volume_overlay(rec.cb, frame);
        rec.ctx.device.cmd_end_rendering(rec.cb);
        r
    }
}

/// Stencil counts as a heat map: 0 black, then blue -> green -> yellow -> red by count.
pub fn stencil_heatmap(s: &[u8]) -> Vec<u8> {
    let ramp = [[0u8, 0, 0], [40, 60, 220], [30, 200, 80], [240, 220, 40], [230, 40, 30], [255, 255, 255]];
    s.iter()
        .flat_map(|&c| {
            let rgb = ramp[(c as usize).min(ramp.len() - 1)];
            [rgb[0], rgb[1], rgb[2], 255]
        })
        .collect()
}
