//! 2b. Per light, the transparent casters' light-intensity map (Kim et al. 2008), recorded
//!     by the [`ShadowPass`]: every counted volume face multiplies by `t` or `1/t` (or adds
//!     `±log t`), depth-tested like the float counter.
//!
//! Inputs / outputs, per light (only when the scene has transparent casters):
//! - Reads: `depth` (the `Targets` depth-stencil image) in `DEPTH_STENCIL_ATTACHMENT_OPTIMAL`, LOAD, declared and left there
//!   (`DepthStencilTarget::new`; the pass's own barriers keep that layout).
//! - Writes: `transmit`, `UNDEFINED -> COLOR_ATTACHMENT_OPTIMAL`, CLEAR to 1 (0 with the log map) inside the light's
//!   scissor, STORE; with capture copied out through `TRANSFER_SRC_OPTIMAL` and returned.
//! - Leaves: `transmit` in `SHADER_READ_ONLY_OPTIMAL` for `illuminate` (binding 5 of `gbuffer_set`); `depth` unchanged.

use super::Rec;
use crate::readback::Range;
use crate::targets::Targets;
use ash::vk;
use umbrage::error::Result;
use umbrage::pass::{DepthStencilTarget, PreparedFrame, ShadowPass};

/// # Safety
/// As [`super::determine::record`].
pub(crate) unsafe fn record(
    rec: &Rec,
    pass: &ShadowPass,
    frame: &PreparedFrame,
    light: usize,
    t: &Targets,
    log: bool,
    capture: Option<Range>,
) -> Result<()> {
    rec.transition(&t.transmit, vk::ImageLayout::UNDEFINED, vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL);
    let target = DepthStencilTarget::new(t.depth.raw, t.depth.view, t.extent);
    // SAFETY: the caller's contract, which is `ShadowPass`'s.
    unsafe { pass.cmd_light_intensity(rec.cb, frame, light, &target, t.transmit.view, log)? };
    if let Some(range) = capture {
        rec.copy_out(&t.transmit, vk::ImageAspectFlags::COLOR, vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL, range);
    }
    rec.transition(&t.transmit, vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL, vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL);
    Ok(())
}
