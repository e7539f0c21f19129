//! Partial self-shadowing of transparent casters (`--self-shadow`; Kim, Kim & Turk 2008,
//! section 4 "Limitations on self-shadowing" and the algorithm summary, steps 4-6).
//!
//! Without it, transparent casters are drawn forward over the lit scene and receive no
//! shadows. With it, after the "over" pass of the transparent casters:
//!
//! 4. the transparent casters are drawn into a separate depth image (two-sided, LESS, write):
//!    the nearest transparent surface per pixel;
//! 5. per light, two maps are built *on those surfaces*, depth-tested against that image
//!    instead of the opaque depth buffer, inside the light's scissor:
//!    - the opaque casters' volumes counted into an R32F target (the float-counter pipelines,
//!      z-pass LESS / z-fail GREATER_OR_EQUAL; the depth-NEVER light-cap shortcut does not
//!      hold against this depth, so light caps take the general z-fail test);
//!    - the transparent casters' volumes into a second light-intensity map (the same transmit
//!      pipelines as the receivers' map);
//! 6. that light's forward pass over the transparent casters multiplies its contribution by
//!    the map at the fragment's pixel, and by 0 where the opaque count is non-zero.
//!
//! Self-occlusion: a transparent caster is on the multiplicity path, so each of its triangles
//! is the light cap of its own volume and lies exactly on the stored depth. The depth pre-pass
//! (transparent.vert, BIAS variant) pulls every vertex towards the eye by 1/1000 of its
//! distance, so the surface's own cap is robustly *behind* the stored depth: z-pass never
//! counts it, z-fail always does, and both read the point as outside its own triangle's
//! volume. The price ("partially correct", as the paper says): a transparent surface closer
//! than 1/1000 of its distance above another is not shadowed by it.
//!
//! Only the nearest transparent layer per pixel is correct: farther transparent surfaces at the
//! same pixel read the nearest one's value (and so may be lit or shadowed wrongly).
//!
//! Everything here runs only when `RenderOptions::self_shadow` is set and the scene has
//! transparent casters; otherwise the frame records exactly the passes it did before.
//!
//! Inputs / outputs (recorded by `frame/record.rs` right after `transparent::record`):
//! - Reads: the opaque `depth` in `DEPTH_STENCIL_ATTACHMENT_OPTIMAL` and `accum` in `COLOR_ATTACHMENT_OPTIMAL`, as
//!   `transparent` leaves them; its own `count` and `map` sampled in `SHADER_READ_ONLY_OPTIMAL` (its `set`, step 6).
//! - Step 4: its own `depth` `UNDEFINED -> DEPTH_STENCIL_ATTACHMENT_OPTIMAL`, CLEAR (`DS_CLEAR`)/STORE; LOADed by step 5.
//! - Step 5, per light, inside the scissor: `count` and `map` each `UNDEFINED -> COLOR_ATTACHMENT_OPTIMAL`, CLEAR (count 0;
//!   map 1, or 0 in log space)/STORE, then `-> SHADER_READ_ONLY_OPTIMAL`.
//! - Step 6, per light: `accum` (LOAD/STORE, additive) over the opaque `depth` (LOAD/STORE, tested LESS, not written).
//! - Leaves: `accum` and both depth images in attachment layout; its `count` and `map` in `SHADER_READ_ONLY_OPTIMAL`.

use super::{att, transparent, Rec, SceneDraw, COLOR_RW, DS_CLEAR, DS_RW, FRAG_TESTS, ZERO};
use crate::pipelines::{scene_pipeline, FramePipelines};
use crate::push::{ForwardPush, LightPush};
use crate::shaders;
use crate::targets::*;
use ash::vk;
use umbrage::error::Result;
use umbrage::gpu::descriptors::{pipeline_layout, Binding, DescriptorSet};
use umbrage::gpu::pipeline::{self, Blend};
use umbrage::gpu::{Context, Image};
use umbrage::pass::{PreparedFrame, ShadowPass, VolumeKind};

/// The self-shadowing pass's own targets and pipelines.
pub(crate) struct SelfShadow {
    depth: Image,
    count: Image,
    map: Image,
    layout: vk::PipelineLayout,
    set: DescriptorSet,
    depth_pipe: vk::Pipeline,
    light_pipe: vk::Pipeline,
}

impl SelfShadow {
    pub(crate) fn new(ctx: &Context, p: &FramePipelines, extent: vk::Extent2D, transmit_format: vk::Format) -> Result<SelfShadow> {
        let color = vk::ImageUsageFlags::COLOR_ATTACHMENT | vk::ImageUsageFlags::SAMPLED;
        let c = vk::ImageAspectFlags::COLOR;
        let ds = vk::ImageAspectFlags::DEPTH | vk::ImageAspectFlags::STENCIL;
        let [depth, count, map] = Image::new_all(
            ctx,
            extent,
            [
                ("transparent depth", ctx.depth_format, vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT, ds),
                ("self-shadow opaque count", COUNT_FORMAT, color, c),
                ("self-shadow light-intensity map", transmit_format, color, c),
            ],
        )?;
        let set = DescriptorSet::new(ctx, &[Binding::Image(count.view), Binding::Image(map.view), Binding::Sampler(p.sampler)])?;
        let push = std::mem::size_of::<ForwardPush>() as u32;
        let layout = pipeline_layout(ctx, &[set.layout], push, vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT)?;

        let mut d = scene_pipeline(shaders::TRANSPARENT_BIAS_VERT, p.layouts.forward, ctx.depth_format);
        d.depth_test = true;
        d.depth_write = true;
        d.depth_compare = vk::CompareOp::LESS;
        let depth_pipe = pipeline::create(ctx, &d)?;
        let accum = [p.accum_format];
        let mut l = scene_pipeline(shaders::TRANSPARENT_VERT, layout, ctx.depth_format);
        l.fragment = Some(shaders::TRANSPARENT_SS_FRAG);
        l.color_formats = &accum;
        l.depth_test = true;
        l.depth_compare = vk::CompareOp::LESS;
        l.blend = Blend::Additive;
        let light_pipe = pipeline::create(ctx, &l)?;
        Ok(SelfShadow { depth, count, map, layout, set, depth_pipe, light_pipe })
    }

    pub(crate) fn destroy(&mut self, ctx: &Context) {
        // SAFETY: the owner waited for the device; each handle is destroyed once.
        unsafe {
            let d = &ctx.device;
            d.destroy_pipeline(self.depth_pipe, None);
            d.destroy_pipeline(self.light_pipe, None);
            d.destroy_pipeline_layout(self.layout, None);
        }
        self.set.destroy(ctx);
        for img in [&mut self.depth, &mut self.count, &mut self.map] {
            img.destroy(ctx);
        }
    }

    /// Steps 4-6, after the transparent casters' "over" pass.
    ///
    /// # Safety
    /// `rec.cb` is recording outside a rendering instance; the accumulation target and the
    /// opaque depth are in attachment layout; `frame` was prepared by `pass` for this slot.
    pub(crate) unsafe fn record(
        &self,
        rec: &Rec,
        sd: &SceneDraw,
        pass: &ShadowPass,
        frame: &PreparedFrame,
        lights: &[LightPush],
        log: bool,
    ) -> umbrage::error::Result<()> {
        let SceneDraw { t, p, geo, instances, vp_rel, .. } = *sd;
        let d = &rec.ctx.device;
        let cb = rec.cb;
        let load = vk::AttachmentLoadOp::LOAD;
        let clear = vk::AttachmentLoadOp::CLEAR;
        let map_clear = vk::ClearValue { color: vk::ClearColorValue { float32: if log { [0.0; 4] } else { [1.0; 4] } } };
        rec.barrier(
            (vk::PipelineStageFlags2::COLOR_ATTACHMENT_OUTPUT, COLOR_RW),
            (vk::PipelineStageFlags2::COLOR_ATTACHMENT_OUTPUT, COLOR_RW),
        );

        // 4. The nearest transparent surface per pixel.
        rec.transition(&self.depth, vk::ImageLayout::UNDEFINED, vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL);
        let ss_depth = att(&self.depth, clear, DS_CLEAR);
        // SAFETY: the caller's contract; the image was just transitioned.
        unsafe {
            rec.begin(rec.full, &[], Some(&ss_depth));
            d.cmd_bind_pipeline(cb, vk::PipelineBindPoint::GRAPHICS, self.depth_pipe);
            transparent::draw_meshes(rec, p.layouts.forward, geo, instances, &ForwardPush::ambient(vp_rel, glam::Vec3::ZERO));
            d.cmd_end_rendering(cb);
        }
        rec.barrier((FRAG_TESTS, DS_RW), (FRAG_TESTS, DS_RW));

        let ss_depth = att(&self.depth, load, DS_CLEAR);
        for (li, lf) in frame.lights.iter().enumerate() {
            let begin = |target: &[vk::RenderingAttachmentInfo]| {
                let info = vk::RenderingInfo::default()
                    .render_area(lf.scissor)
                    .layer_count(1)
                    .color_attachments(target)
                    .depth_attachment(&ss_depth)
                    .stencil_attachment(&ss_depth);
                // SAFETY: the caller's contract; the attachments are in attachment layout.
                unsafe {
                    d.cmd_begin_rendering(cb, &info);
                    pass.cmd_light_state(cb, frame, li, t.extent)
                }
            };
            // 5a. The opaque casters' volumes counted on the transparent surface.
            rec.transition(&self.count, vk::ImageLayout::UNDEFINED, vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL);
            let state = begin(&[att(&self.count, clear, ZERO)]);
            // SAFETY: inside the rendering instance just begun (R32F + the pass's depth format).
            let drawn = unsafe {
                let r = state.and_then(|_| pass.cmd_draw_volumes(cb, frame, li, VolumeKind::FloatDepthTested));
                d.cmd_end_rendering(cb);
                r
            };
            drawn?;
            rec.transition(&self.count, vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL, vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL);

            // 5b. The transparent casters' volumes into the second light-intensity map.
            rec.transition(&self.map, vk::ImageLayout::UNDEFINED, vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL);
            let state = begin(&[att(&self.map, clear, map_clear)]);
            // SAFETY: as above, with the transmit format.
            let drawn = unsafe {
                let r = state.and_then(|_| pass.cmd_draw_volumes(cb, frame, li, VolumeKind::Transmit { log }));
                d.cmd_end_rendering(cb);
                r
            };
            drawn?;
            rec.transition(&self.map, vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL, vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL);

            // 6. The light's forward pass, scaled by the map (0 where the opaque count is not).
            let accum = [att(&t.accum, load, ZERO)];
            let depth = att(&t.depth, load, DS_CLEAR);
            // SAFETY: the caller's contract.
            unsafe {
                rec.begin(lf.scissor, &accum, Some(&depth));
                d.cmd_bind_pipeline(cb, vk::PipelineBindPoint::GRAPHICS, self.light_pipe);
                d.cmd_bind_descriptor_sets(cb, vk::PipelineBindPoint::GRAPHICS, self.layout, 0, &[self.set.set], &[]);
                transparent::draw_meshes(rec, self.layout, geo, instances, &ForwardPush::light(vp_rel, &lights[li]));
                d.cmd_end_rendering(cb);
            }
            rec.barrier(
                (vk::PipelineStageFlags2::COLOR_ATTACHMENT_OUTPUT | FRAG_TESTS, COLOR_RW | DS_RW),
                (
                    vk::PipelineStageFlags2::COLOR_ATTACHMENT_OUTPUT | FRAG_TESTS | vk::PipelineStageFlags2::FRAGMENT_SHADER,
                    COLOR_RW | DS_RW | vk::AccessFlags2::SHADER_READ,
                ),
            );
        }
        Ok(())
    }
}
