//! The frame's stages, one file each (what the paper calls its passes: "pass" in this
//! workspace names the engine's `ShadowPass` alone, and Vulkan's are "render passes"), in the order [`Renderer::render`](super::Renderer) runs
//! them: G-buffer, per light determination (+ light-intensity map; the shadow-map baseline's
//! maps and lookup, `shadowmap`) and illumination, the transparent casters (with
//! `--self-shadow`, `selfshadow`), the debug views, the tone map.
//!
//! Inputs / outputs, in the order `frame/record.rs` records them (images are `Targets` fields unless named; `COLOR` =
//! `COLOR_ATTACHMENT_OPTIMAL`, `DS` = `DEPTH_STENCIL_ATTACHMENT_OPTIMAL`, `READ` = `SHADER_READ_ONLY_OPTIMAL`, `SRC` =
//! `TRANSFER_SRC_OPTIMAL`; `A -> B` is a transition the pass records, a single layout one it expects and keeps;
//! attachments STORE; "in scissor": only inside the light's scissor):
//!
//! | Pass | Reads (layout, load op) | Writes (layout, load op) |
//! |---|---|---|
//! | `gbuffer` | nothing sampled | `accum`, `albedo`, `normal`, `position` `UNDEFINED -> COLOR`, `depth` `UNDEFINED -> DS`, CLEAR |
//! | (after it) | | `albedo`, `normal`, `position` `COLOR -> READ`; `accum` stays `COLOR`, `depth` stays `DS` |
//! | per light: `shadowmap` maps | nothing sampled | its atlas `UNDEFINED -> DS`, CLEAR, then `-> READ` |
//! | `shadowmap` lookup | `normal`, `position`, atlas (`READ`) | `count` (`COLOR`, by `determine::begin_float`), CLEAR in scissor |
//! | `determine` | depth of `depth` (`DS`, LOAD); ray query: `normal`, `position` (`READ`) | stencil (`DS`, CLEAR in scissor) or `count` (`UNDEFINED -> COLOR`, CLEAR) |
//! | `determine::finish` | with capture: `count` or the stencil via `SRC` and back | float counts: `count` `COLOR -> READ` |
//! | `intensity` (transparent casters) | depth of `depth` (`DS`, LOAD) | `transmit` `UNDEFINED -> COLOR`, CLEAR in scissor, `-> READ` |
//! | `illuminate` | G-buffer, `count`, `transmit` per variant (`READ`); `depth` (`DS`, LOAD) | `accum` (`COLOR`, LOAD), in scissor |
//! | `transparent` | `depth` (`DS`, LOAD, tested, not written) | `accum` (`COLOR`, LOAD) |
//! | `selfshadow` (`--self-shadow`) | `depth` (`DS`, LOAD); its own `count`, `map` (`READ`) | `accum` (`COLOR`, LOAD), in scissor |
//! | (its own images) | | depth `UNDEFINED -> DS`, CLEAR; per light `count`, `map` `UNDEFINED -> COLOR`, CLEAR, `-> READ` |
//! | `debug` (`--view volumes`) | `depth` (`DS`, LOAD) | `accum` (`COLOR`, LOAD) |
//! | `tonemap` | `accum` `COLOR -> READ` | `output` `UNDEFINED -> COLOR`, DONT_CARE |
//! | readback (`record.rs`) | `output` (`COLOR`); `position`, `normal` (`READ`) | the readback buffer, each image via `SRC` and back |
//! | `samples` (MSAA; also in `finish`) | `depth` `DS -> READ -> DS`; `normal` (`READ`) | own images `UNDEFINED -> COLOR`, then `SRC` |
//!
//! Every image a frame writes starts the frame (or the light) from `UNDEFINED`, so nothing relies on the layout the
//! previous frame left (`accum` and the G-buffer `READ`, `depth` `DS`, `output` `COLOR`).

pub(crate) mod debug;
pub(crate) mod determine;
pub(crate) mod gbuffer;
pub(crate) mod illuminate;
pub(crate) mod intensity;
pub(crate) mod samples;
pub(crate) mod selfshadow;
pub mod shadowmap;
pub(crate) mod tonemap;
pub(crate) mod transparent;

use super::readback::Range;
use super::timing::{Span, Timer};
use crate::pipelines::FramePipelines;
use crate::scene_gpu::SceneGeometry;
use crate::targets::Targets;
use ash::vk;
use glam::{Mat4, Vec3};
use umbrage::gpu::resources::{aspect_copy, memory_barrier, transition};
use umbrage::gpu::{Context, Image};

/// What the passes that draw the scene (and the lighting) record with, besides [`Rec`]: the
/// frame's targets and pipelines, the scene's geometry as this slot's instance buffer places it,
/// the eye-relative view-projection and the ambient light.
#[derive(Clone, Copy)]
pub(crate) struct SceneDraw<'a> {
    pub t: &'a Targets,
    pub p: &'a FramePipelines,
    pub geo: &'a SceneGeometry,
    pub instances: vk::Buffer,
    pub vp_rel: Mat4,
    pub ambient: Vec3,
}

/// What every pass records with.
pub(crate) struct Rec<'a> {
    pub ctx: &'a Context,
    pub cb: vk::CommandBuffer,
    pub full: vk::Rect2D,
    pub viewport: vk::Viewport,
    pub timer: &'a Timer,
    /// The slot's readback buffer.
    pub readback: vk::Buffer,
}

/// The background: a muted sky blue in the linear accumulation target (about sRGB 145, 157,
/// 176 after the tone map).
pub(crate) const SKY: vk::ClearValue = vk::ClearValue { color: vk::ClearColorValue { float32: [0.30, 0.38, 0.52, 0.0] } };
pub(crate) const ZERO: vk::ClearValue = vk::ClearValue { color: vk::ClearColorValue { float32: [0.0; 4] } };
pub(crate) const DS_CLEAR: vk::ClearValue = vk::ClearValue { depth_stencil: vk::ClearDepthStencilValue { depth: 1.0, stencil: 0 } };
pub(crate) const FRAG_TESTS: vk::PipelineStageFlags2 = vk::PipelineStageFlags2::from_raw(
    vk::PipelineStageFlags2::EARLY_FRAGMENT_TESTS.as_raw() | vk::PipelineStageFlags2::LATE_FRAGMENT_TESTS.as_raw(),
);
pub(crate) const DS_RW: vk::AccessFlags2 = vk::AccessFlags2::from_raw(
    vk::AccessFlags2::DEPTH_STENCIL_ATTACHMENT_READ.as_raw() | vk::AccessFlags2::DEPTH_STENCIL_ATTACHMENT_WRITE.as_raw(),
);
pub(crate) const COLOR_RW: vk::AccessFlags2 =
    vk::AccessFlags2::from_raw(vk::AccessFlags2::COLOR_ATTACHMENT_READ.as_raw() | vk::AccessFlags2::COLOR_ATTACHMENT_WRITE.as_raw());

/// An attachment of `img` in its attachment layout.
pub(crate) fn att(img: &Image, load: vk::AttachmentLoadOp, clear: vk::ClearValue) -> vk::RenderingAttachmentInfo<'static> {
    vk::RenderingAttachmentInfo::default()
        .image_view(img.view)
        .image_layout(if img.aspect == vk::ImageAspectFlags::COLOR {
            vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL
        } else {
            vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL
        })
        .load_op(load)
        .store_op(vk::AttachmentStoreOp::STORE)
        .clear_value(clear)
}

impl Rec<'_> {
    /// Begins a dynamic-rendering instance over `area` with colour attachments and an
    /// optional depth-stencil attachment (used for both aspects, as lavapipe needs), and sets
    /// the viewport and a scissor equal to `area`.
    ///
    /// # Safety
    /// `self.cb` is recording outside any rendering instance, and every attachment's image is
    /// in the layout its info names.
    pub unsafe fn begin(
        &self,
        area: vk::Rect2D,
        colors: &[vk::RenderingAttachmentInfo],
        depth_stencil: Option<&vk::RenderingAttachmentInfo>,
    ) {
        let mut info = vk::RenderingInfo::default().render_area(area).layer_count(1).color_attachments(colors);
        if let Some(ds) = depth_stencil {
            info = info.depth_attachment(ds).stencil_attachment(ds);
        }
        let d = &self.ctx.device;
        // SAFETY: forwarded to the caller's contract above.
        unsafe {
            d.cmd_begin_rendering(self.cb, &info);
            d.cmd_set_viewport(self.cb, 0, &[self.viewport]);
            d.cmd_set_scissor(self.cb, 0, &[area]);
        }
    }

    pub fn transition(&self, img: &Image, from: vk::ImageLayout, to: vk::ImageLayout) {
        transition(self.ctx, self.cb, img, from, to);
    }

    pub fn barrier(&self, src: (vk::PipelineStageFlags2, vk::AccessFlags2), dst: (vk::PipelineStageFlags2, vk::AccessFlags2)) {
        memory_barrier(self.ctx, self.cb, src, dst);
    }

    /// Copies one aspect of `img` (in `layout`) into `range` of the readback buffer, and
    /// returns it to `layout`.
    pub fn copy_out(&self, img: &Image, aspect: vk::ImageAspectFlags, layout: vk::ImageLayout, range: Range) {
        let region = aspect_copy(aspect, img.extent, range.offset);
        self.transition(img, layout, vk::ImageLayout::TRANSFER_SRC_OPTIMAL);
        // SAFETY: `cb` is recording outside a rendering instance; the range was sized for
        // this image's aspect when the readback buffer was laid out.
        unsafe {
            self.ctx.device.cmd_copy_image_to_buffer(self.cb, img.raw, vk::ImageLayout::TRANSFER_SRC_OPTIMAL, self.readback, &[region])
        };
        self.transition(img, vk::ImageLayout::TRANSFER_SRC_OPTIMAL, layout);
    }
}

/// A span from two stamps.
pub(crate) fn timing_span(begin: Option<u32>, end: Option<u32>) -> Span {
    Span { begin, end }
}
