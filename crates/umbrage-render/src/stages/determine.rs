//! 2a. Per light, the shadow determination, recorded by the [`ShadowPass`]: the count in the
//!     stencil (cleared inside the light's scissor), or in the float target; with capture,
//!     the count is copied out for the dumps and tests.
//!
//! Inputs / outputs, per light (`depth` is the `Targets` depth-stencil image, always in
//! `DEPTH_STENCIL_ATTACHMENT_OPTIMAL` here, as `gbuffer` left it):
//! - `CountInto::Stencil`: `ShadowPass::cmd_determine` with `DepthStencilTarget::new` (declared and left in
//!   `DEPTH_STENCIL_ATTACHMENT_OPTIMAL`; the pass's own barriers keep that layout): depth aspect LOAD (read only),
//!   stencil CLEAR to the light's `counter_clear` inside its scissor, STORE. With ray query the pass's rays also read
//!   `position` and `normal` (`SHADER_READ_ONLY_OPTIMAL`, as `gbuffer` left them) and write 1 where blocked.
//! - `CountInto::Float`: `begin_float` takes `count` `UNDEFINED -> COLOR_ATTACHMENT_OPTIMAL`; `cmd_count_float` clears it
//!   (to `counter_clear`) inside the scissor and adds into it, the depth-stencil loaded and only read.
//! - `CountInto::External`: nothing recorded by `record`; the caller (`frame/record.rs`) already ran the
//!   shadow-map lookup (`count` left in `COLOR_ATTACHMENT_OPTIMAL`, after `begin_float`).
//! - `finish`: with capture, `count` (`COLOR_ATTACHMENT_OPTIMAL`) or the stencil aspect (`DEPTH_STENCIL_ATTACHMENT_OPTIMAL`)
//!   is copied out through `TRANSFER_SRC_OPTIMAL` and returned (`Rec::copy_out`), or with MSAA the stencil through
//!   `samples`; then, float counts only, `count` goes `COLOR_ATTACHMENT_OPTIMAL -> SHADER_READ_ONLY_OPTIMAL`.
//! - `record_count`: the occlusion-query variant, depth-stencil LOAD in `DEPTH_STENCIL_ATTACHMENT_OPTIMAL`, nothing written.
//! - Leaves: `depth` in `DEPTH_STENCIL_ATTACHMENT_OPTIMAL` (stencil = the count with stencil counting), `count` in
//!   `SHADER_READ_ONLY_OPTIMAL` (float counting, shadow map) for `illuminate`.

use super::{Rec, DS_RW, FRAG_TESTS};
use crate::counters::CounterPools;
use crate::pipelines::FramePipelines;
use crate::readback::Range;
use crate::targets::Targets;
use ash::vk;
use umbrage::error::Result;
use umbrage::pass::diagnostics::Diagnostics;
use umbrage::pass::{DepthStencilTarget, PreparedFrame, ShadowPass};

/// How the light's count is produced.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum CountInto {
    /// The 8-bit stencil.
    Stencil,
    /// The R32F count target, by the shadow pass.
    Float,
    /// The R32F count target, written by the caller (the shadow-map lookup): only the layout
    /// transitions and the capture happen here.
    External,
}

/// Makes the count target writable (float counting).
pub(crate) fn begin_float(rec: &Rec, t: &Targets) {
    // Contents outside the scissor are never read (illumination is scissored too).
    rec.transition(&t.count, vk::ImageLayout::UNDEFINED, vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL);
}

/// # Safety
/// `rec.cb` is recording outside a rendering instance, the depth-stencil target is in
/// attachment layout with the G-buffer's depth written; `frame` was prepared by `pass` for
/// this slot.
pub(crate) unsafe fn record(rec: &Rec, pass: &ShadowPass, frame: &PreparedFrame, light: usize, t: &Targets, into: CountInto) -> Result<()> {
    let target = DepthStencilTarget::new(t.depth.raw, t.depth.view, t.extent);
    // SAFETY: the caller's contract, which is `ShadowPass`'s.
    unsafe {
        match into {
            CountInto::Stencil => pass.cmd_determine(rec.cb, frame, light, &target)?,
            CountInto::Float => {
                begin_float(rec, t);
                pass.cmd_count_float(rec.cb, frame, light, &target, t.count.view)?;
            }
            CountInto::External => {}
        }
    }
    rec.barrier((FRAG_TESTS, DS_RW), (FRAG_TESTS, DS_RW));
    Ok(())
}

/// After [`record`]: copies the light's count into `capture` (captured frames) and makes the
/// float count target readable by the lighting pass.
///
/// # Safety
/// As [`record`], after it.
pub(crate) unsafe fn finish(rec: &Rec, t: &Targets, p: &FramePipelines, into: CountInto, capture: Option<Range>) -> Result<()> {
    let float = matches!(into, CountInto::Float | CountInto::External);
    if let Some(range) = capture {
        if t.samples > 1 {
            // SAFETY: the caller's contract: the stencil is written and in attachment layout.
            unsafe { super::samples::record(rec, t, p, super::samples::Source::Stencil, range)? };
        } else if float {
            rec.copy_out(&t.count, vk::ImageAspectFlags::COLOR, vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL, range);
        } else {
            rec.copy_out(&t.depth, vk::ImageAspectFlags::STENCIL, vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL, range);
        }
    }
    if float {
        rec.transition(&t.count, vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL, vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL);
    }
    Ok(())
}

/// The counting variant of light `light`'s determination inside its occlusion query (outside
/// the light's timed span): the exact number of fragments its volumes rasterise.
///
/// # Safety
/// As [`record`], after it (the depth-stencil target in attachment layout).
pub(crate) unsafe fn record_count(
    rec: &Rec,
    pass: &ShadowPass,
    frame: &PreparedFrame,
    light: usize,
    t: &Targets,
    c: &CounterPools,
) -> Result<()> {
    let target = DepthStencilTarget::new(t.depth.raw, t.depth.view, t.extent);
    c.occlusion(rec.ctx, rec.cb, light as u32, true);
    // A ray-query frame has no volumes: its query counts nothing.
    let r = match frame.ray_query() {
        Some(_) => Ok(()),
        // SAFETY: the caller's contract, which is `ShadowPass`'s.
        None => unsafe { pass.cmd_count_rasterised(rec.cb, frame, light, &target) },
    };
    c.occlusion(rec.ctx, rec.cb, light as u32, false);
    rec.barrier((FRAG_TESTS, DS_RW), (FRAG_TESTS, DS_RW));
    r
}
