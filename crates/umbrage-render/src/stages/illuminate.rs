//! 2c. Per light, illumination where the count is zero: a full-screen triangle over the
//!     light's scissor, Blinn-Phong from the G-buffer, scaled by the light-intensity map,
//!     added into the float target.
//!
//! Inputs / outputs, per light (after `determine::finish` and `intensity`):
//! - Reads, sampled through `gbuffer_set` (written as `SHADER_READ_ONLY_OPTIMAL`): `albedo`, `normal`, `position` (left
//!   there by `gbuffer`); `count` in the float variants (by `determine::finish`); `transmit` in the transmit variants
//!   (by `intensity`).
//! - Reads: `depth` as the depth-stencil attachment, `DEPTH_STENCIL_ATTACHMENT_OPTIMAL`, LOAD/STORE: the stencil variants
//!   test stencil EQUAL 0 (nothing written), depth bounds where the pass uses them.
//! - Writes: `accum` in `COLOR_ATTACHMENT_OPTIMAL`, LOAD/STORE, additive, inside the light's scissor.
//! - Leaves every layout as it found it; a colour + depth-stencil memory barrier orders it before the next light's passes.

use super::{att, Rec, SceneDraw, COLOR_RW, DS_CLEAR, DS_RW, FRAG_TESTS, ZERO};
use crate::push::LightPush;
use ash::vk;
use umbrage::pass::{PreparedFrame, ShadowPass};

/// Which lighting pipeline: the count in the float target (or the stencil), the light scaled
/// by the transparent casters' light-intensity map (or not).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Lighting {
    pub float: bool,
    pub transmit: bool,
}

/// # Safety
/// `rec.cb` is recording outside a rendering instance; the G-buffer, the count target (float)
/// and the intensity map (`transmit`) are in shader-read layout.
pub(crate) unsafe fn record(
    rec: &Rec,
    pass: &ShadowPass,
    frame: &PreparedFrame,
    light: usize,
    sd: &SceneDraw,
    mode: Lighting,
    push: &LightPush,
) -> umbrage::error::Result<()> {
    let (t, p) = (sd.t, sd.p);
    let Lighting { float, transmit } = mode;
    let load = vk::AttachmentLoadOp::LOAD;
    let accum = [att(&t.accum, load, ZERO)];
    let depth = att(&t.depth, load, DS_CLEAR);
    let d = &rec.ctx.device;
    let cb = rec.cb;
    let scissor = frame.lights[light].scissor;
    // SAFETY: the caller's contract.
    unsafe {
        rec.begin(scissor, &accum, Some(&depth));
        d.cmd_bind_pipeline(cb, vk::PipelineBindPoint::GRAPHICS, p.illuminate[float as usize][transmit as usize]);
        pass.cmd_light_state(cb, frame, light, t.extent)?;
        d.cmd_bind_descriptor_sets(cb, vk::PipelineBindPoint::GRAPHICS, p.layouts.illuminate, 0, &[p.gbuffer_set.set], &[]);
        d.cmd_push_constants(cb, p.layouts.illuminate, vk::ShaderStageFlags::FRAGMENT, 0, bytemuck::bytes_of(push));
        d.cmd_draw(cb, 3, 1, 0, 0);
        d.cmd_end_rendering(cb);
    }
    let stages = vk::PipelineStageFlags2::COLOR_ATTACHMENT_OUTPUT | FRAG_TESTS;
    rec.barrier((stages, COLOR_RW | DS_RW), (stages, COLOR_RW | DS_RW));
    Ok(())
}
