//! 4. The final pass: tone map the float accumulation into the sRGB output.
//!
//! Inputs / outputs (the last pass):
//! - Reads: `accum`, `COLOR_ATTACHMENT_OPTIMAL -> SHADER_READ_ONLY_OPTIMAL`, sampled through `accum_set` (resolved by
//!   the multisampled variant).
//! - Writes: `output`, `UNDEFINED -> COLOR_ATTACHMENT_OPTIMAL`, DONT_CARE/STORE, the full frame.
//! - Leaves: `accum` in `SHADER_READ_ONLY_OPTIMAL` (the next frame's `gbuffer` takes it from `UNDEFINED`); `output` in
//!   `COLOR_ATTACHMENT_OPTIMAL`, which `frame/record.rs` copies out through `TRANSFER_SRC_OPTIMAL` and returns there (the
//!   layout `Renderer::output_image` documents). `host_barrier` then makes the frame's transfer writes visible to the host.

use super::{att, Rec, ZERO};
use crate::pipelines::FramePipelines;
use crate::targets::Targets;
use ash::vk;
use umbrage::gpu::resources::memory_barrier;

/// # Safety
/// `rec.cb` is recording outside a rendering instance; the accumulation target is in
/// attachment layout with every pass's writes done.
pub(crate) unsafe fn record(rec: &Rec, t: &Targets, p: &FramePipelines) {
    rec.transition(&t.accum, vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL, vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL);
    rec.transition(&t.output, vk::ImageLayout::UNDEFINED, vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL);
    let out = [att(&t.output, vk::AttachmentLoadOp::DONT_CARE, ZERO)];
    let d = &rec.ctx.device;
    // SAFETY: the caller's contract.
    unsafe {
        rec.begin(rec.full, &out, None);
        d.cmd_bind_pipeline(rec.cb, vk::PipelineBindPoint::GRAPHICS, p.tonemap);
        d.cmd_bind_descriptor_sets(rec.cb, vk::PipelineBindPoint::GRAPHICS, p.layouts.tonemap, 0, &[p.accum_set.set], &[]);
        // The resolving variant's sample count (unused by the single-sample one).
        d.cmd_push_constants(rec.cb, p.layouts.tonemap, vk::ShaderStageFlags::FRAGMENT, 0, &(t.samples as i32).to_le_bytes());
        d.cmd_draw(rec.cb, 3, 1, 0, 0);
        d.cmd_end_rendering(rec.cb);
    }
}

/// Makes the frame's transfer writes visible to the host.
pub(crate) fn host_barrier(rec: &Rec) {
    memory_barrier(
        rec.ctx,
        rec.cb,
        (vk::PipelineStageFlags2::ALL_TRANSFER, vk::AccessFlags2::TRANSFER_WRITE),
        (vk::PipelineStageFlags2::HOST, vk::AccessFlags2::HOST_READ),
    );
}
