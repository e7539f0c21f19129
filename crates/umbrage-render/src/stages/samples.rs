//! The readback of a multisampled frame, one sample at a time: images of more than one sample
//! cannot be copied to a buffer, so a full-screen pass copies sample `k` of the position,
//! normal or stencil target into a single-sample image ([`SampleReadback`]) that is copied
//! into sample `k`'s block of the readback range.
//!
//! Inputs / outputs (called by `determine::finish` for the stencil capture, and by `frame/record.rs` after the tone
//! map for positions and normals):
//! - Reads: `Source::Stencil`: the `Targets` depth-stencil image, `DEPTH_STENCIL_ATTACHMENT_OPTIMAL ->
//!   SHADER_READ_ONLY_OPTIMAL` for the pass and back afterwards (sampled through its stencil aspect view,
//!   `stencil_set`); `Source::Position` / `Source::Normal`: `position` / `normal` in `SHADER_READ_ONLY_OPTIMAL` (left
//!   there by `gbuffer`), not transitioned.
//! - Writes, per sample: `per_sample.geometry` (position, normal) or `per_sample.stencil`, `UNDEFINED ->
//!   COLOR_ATTACHMENT_OPTIMAL`, DONT_CARE/STORE, then copied out through `TRANSFER_SRC_OPTIMAL` and returned to
//!   `COLOR_ATTACHMENT_OPTIMAL`.
//! - Leaves every `Targets` image in the layout it found it.
//!
//! [`SampleReadback`]: crate::targets::SampleReadback

use super::{att, Rec, ZERO};
use crate::pipelines::FramePipelines;
use crate::readback::Range;
use crate::targets::Targets;
use ash::vk;
use umbrage::error::{Error, Result};

/// What is read back.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Source {
    /// The G-buffer's eye-relative positions (in shader-read layout): a capture's positions
    /// are found on their planes (`frame_output::sample_geometry`), not unprojected from depth.
    Position,
    /// The G-buffer's normals (in shader-read layout).
    Normal,
    /// The stencil (the depth-stencil target in attachment layout; it is returned there).
    Stencil,
}

/// Copies every sample of `source` into `range`, sample after sample.
///
/// # Safety
/// `rec.cb` is recording outside a rendering instance; the targets are multisampled and in
/// the layouts [`Source`] names, with their writes made visible to fragment shaders.
pub(crate) unsafe fn record(rec: &Rec, t: &Targets, p: &FramePipelines, source: Source, range: Range) -> Result<()> {
    let (Some(rb), Some(pipes)) = (&t.per_sample, &p.sample_readback) else {
        return Err(Error::Internal("per-sample readback of a single-sampled frame".into()));
    };
    let (img, pipe, set) = match source {
        Source::Position => (&rb.geometry, pipes.geometry, &pipes.position_set),
        Source::Normal => (&rb.geometry, pipes.geometry, &pipes.normal_set),
        Source::Stencil => (&rb.stencil, pipes.stencil, &pipes.stencil_set),
    };
    let ds = vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL;
    let read = vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL;
    if source == Source::Stencil {
        rec.transition(&t.depth, ds, read);
    }
    let d = &rec.ctx.device;
    for k in 0..t.samples {
        // From UNDEFINED: the previous copy out of the image finishes first (all commands).
        rec.transition(img, vk::ImageLayout::UNDEFINED, vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL);
        let out = [att(img, vk::AttachmentLoadOp::DONT_CARE, ZERO)];
        // SAFETY: the caller's contract; the image was just made an attachment.
        unsafe {
            rec.begin(rec.full, &out, None);
            d.cmd_bind_pipeline(rec.cb, vk::PipelineBindPoint::GRAPHICS, pipe);
            d.cmd_bind_descriptor_sets(rec.cb, vk::PipelineBindPoint::GRAPHICS, pipes.layout, 0, &[set.set], &[]);
            d.cmd_push_constants(rec.cb, pipes.layout, vk::ShaderStageFlags::FRAGMENT, 0, &(k as i32).to_le_bytes());
            d.cmd_draw(rec.cb, 3, 1, 0, 0);
            d.cmd_end_rendering(rec.cb);
        }
        rec.copy_out(img, vk::ImageAspectFlags::COLOR, vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL, range.sample(k, t.samples));
    }
    if source == Source::Stencil {
        rec.transition(&t.depth, read, ds);
    }
    Ok(())
}
