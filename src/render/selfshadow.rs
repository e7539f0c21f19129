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

use super::*;
use crate::gpu::Image;

/// The self-shadowing targets, descriptors and the two pipelines of its own.
pub(super) struct SelfShadow {
    /// Nearest transparent surface per pixel (depth+stencil format; the stencil is unused but
    /// attached, as every shadow pipeline names it).
    depth: Image,
    /// Opaque casters' volume count on the transparent surfaces (R32F).
    count: Image,
    /// Transparent casters' light-intensity map on the transparent surfaces.
    map: Image,
    layout: vk::PipelineLayout,
    set: DescriptorSet,
    /// Depth pre-pass: transparent.vert (BIAS), no colour, two-sided, LESS + write.
    depth_pipe: vk::Pipeline,
    /// Forward light pass sampling `count` and `map`: transparent.frag (SS), additive.
    light_pipe: vk::Pipeline,
}

impl SelfShadow {
    pub(super) fn new(
        ctx: &Context,
        extent: vk::Extent2D,
        transmit_format: vk::Format,
        sampler: vk::Sampler,
        forward_layout: vk::PipelineLayout,
    ) -> Result<SelfShadow> {
        let color = vk::ImageUsageFlags::COLOR_ATTACHMENT | vk::ImageUsageFlags::SAMPLED;
        let c = vk::ImageAspectFlags::COLOR;
        let depth = Image::new_2d(
            ctx,
            "transparent depth",
            ctx.depth_format,
            extent,
            vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT,
            vk::ImageAspectFlags::DEPTH | vk::ImageAspectFlags::STENCIL,
        )?;
        let count = Image::new_2d(ctx, "self-shadow opaque count", COUNT_FORMAT, extent, color, c)?;
        let map = Image::new_2d(ctx, "self-shadow light-intensity map", transmit_format, extent, color, c)?;
        let set = DescriptorSet::new(ctx, &[Binding::Image(count.view), Binding::Image(map.view), Binding::Sampler(sampler)])?;
        let layout = pipeline_layout(ctx, &[set.layout], 128, vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT)?;

        let attrs = [
            (0, vk::Format::R32G32B32_SFLOAT, 0),
            (1, vk::Format::R32G32B32_SFLOAT, 12),
            (2, vk::Format::R32G32B32_SFLOAT, 24),
            (3, vk::Format::R32_SFLOAT, 36),
        ];
        let mut p = PipelineDesc::new(shaders::TRANSPARENT_BIAS_VERT, forward_layout, ctx.depth_format);
        p.vertex_stride = 40;
        p.attributes = &attrs;
        p.depth_test = true;
        p.depth_write = true;
        p.depth_compare = vk::CompareOp::LESS;
        let depth_pipe = pipeline::create(ctx, &p)?;
        let accum = [ACCUM_FORMAT];
        let mut l = PipelineDesc::new(shaders::TRANSPARENT_VERT, layout, ctx.depth_format);
        l.fragment = Some(shaders::TRANSPARENT_SS_FRAG);
        l.vertex_stride = 40;
        l.attributes = &attrs;
        l.color_formats = &accum;
        l.depth_test = true;
        l.depth_compare = vk::CompareOp::LESS;
        l.blend = Blend::Additive;
        let light_pipe = pipeline::create(ctx, &l)?;
        Ok(SelfShadow { depth, count, map, layout, set, depth_pipe, light_pipe })
    }

    /// The caller waits for the device first.
    pub(super) fn destroy(&mut self, ctx: &Context) {
        // SAFETY: the device is idle (destroy_resources waited); each handle was created by
        // `new` and is destroyed exactly once (the renderer is torn down once).
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
}

/// What the frame hands to the self-shadowing passes.
pub(super) struct SelfShadowFrame<'a> {
    pub vp_rel: Mat4,
    pub viewport: vk::Viewport,
    pub full: vk::Rect2D,
    pub plans: &'a [LightPlan],
    pub draws: &'a [Vec<super::CasterDraws>],
    pub caster_mvp: &'a [Mat4],
    pub light_uniforms: &'a [[Vec4; 4]],
    pub stream: vk::Buffer,
}

impl Renderer {
    /// Steps 4-6, recorded after the transparent casters' "over" pass (outside any rendering
    /// instance): the transparent depth, then per light the two maps and the light's forward
    /// pass over the transparent casters.
    pub(super) fn record_self_shadow(&self, ss: &SelfShadow, cb: vk::CommandBuffer, f: &SelfShadowFrame) {
        let ctx = &self.ctx;
        let d = &ctx.device;
        let t = &self.targets;
        let n = self.scene_vertex_count - self.opaque_count;
        let stages = vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT;
        let frag_tests = vk::PipelineStageFlags2::EARLY_FRAGMENT_TESTS | vk::PipelineStageFlags2::LATE_FRAGMENT_TESTS;
        let ds_rw = vk::AccessFlags2::DEPTH_STENCIL_ATTACHMENT_READ | vk::AccessFlags2::DEPTH_STENCIL_ATTACHMENT_WRITE;
        let color_rw = vk::AccessFlags2::COLOR_ATTACHMENT_READ | vk::AccessFlags2::COLOR_ATTACHMENT_WRITE;
        let att = |img: &Image, load: vk::AttachmentLoadOp, clear: vk::ClearValue| {
            let layout = if img.aspect == vk::ImageAspectFlags::COLOR {
                vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL
            } else {
                vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL
            };
            vk::RenderingAttachmentInfo::default()
                .image_view(img.view)
                .image_layout(layout)
                .load_op(load)
                .store_op(vk::AttachmentStoreOp::STORE)
                .clear_value(clear)
        };
        let ds_clear = vk::ClearValue { depth_stencil: vk::ClearDepthStencilValue { depth: 1.0, stencil: 0 } };
        let zero = vk::ClearValue { color: vk::ClearColorValue { float32: [0.0; 4] } };
        let load = vk::AttachmentLoadOp::LOAD;
        let clear = vk::AttachmentLoadOp::CLEAR;
        let log = self.opts.transmit.log;
        let map_clear = vk::ClearValue { color: vk::ClearColorValue { float32: if log { [0.0; 4] } else { [1.0; 4] } } };
        let mut forward_push = [0f32; 32];
        forward_push[..16].copy_from_slice(&f.vp_rel.to_cols_array());

        // SAFETY: `cb` is recording (between render instances); every handle belongs to this
        // device and lives until Drop; image layouts are tracked in the order written.
        unsafe {
            // 4. Nearest transparent surface per pixel.
            transition(ctx, cb, &ss.depth, vk::ImageLayout::UNDEFINED, vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL);
            let ss_depth = att(&ss.depth, clear, ds_clear);
            d.cmd_begin_rendering(
                cb,
                &vk::RenderingInfo::default().render_area(f.full).layer_count(1).depth_attachment(&ss_depth).stencil_attachment(&ss_depth),
            );
            d.cmd_set_viewport(cb, 0, &[f.viewport]);
            d.cmd_set_scissor(cb, 0, &[f.full]);
            d.cmd_bind_pipeline(cb, vk::PipelineBindPoint::GRAPHICS, ss.depth_pipe);
            d.cmd_push_constants(cb, self.layouts[4], stages, 0, bytes_of(&forward_push));
            d.cmd_bind_vertex_buffers(cb, 0, &[self.scene_vertices.raw], &[0]);
            d.cmd_draw(cb, n, 1, self.opaque_count, 0);
            d.cmd_end_rendering(cb);
            memory_barrier(ctx, cb, (frag_tests, ds_rw), (frag_tests, ds_rw));

            let ss_depth = att(&ss.depth, load, ds_clear);
            for (li, ldraws) in f.draws.iter().enumerate() {
                let scissor = f.plans[li]
                    .scissor
                    .map(|[x, y, sw, sh]| vk::Rect2D {
                        offset: vk::Offset2D { x: x as i32, y: y as i32 },
                        extent: vk::Extent2D { width: sw, height: sh },
                    })
                    .filter(|r| r.extent.width > 0 && r.extent.height > 0)
                    .unwrap_or(f.full);
                let bounds = f.plans[li].depth_bounds.unwrap_or((0.0, 1.0));
                let begin = |target: &[vk::RenderingAttachmentInfo]| {
                    d.cmd_begin_rendering(
                        cb,
                        &vk::RenderingInfo::default()
                            .render_area(scissor)
                            .layer_count(1)
                            .color_attachments(target)
                            .depth_attachment(&ss_depth)
                            .stencil_attachment(&ss_depth),
                    );
                    d.cmd_set_viewport(cb, 0, &[f.viewport]);
                    d.cmd_set_scissor(cb, 0, &[scissor]);
                    if ctx.features.depth_bounds {
                        d.cmd_set_depth_bounds(cb, bounds.0, bounds.1);
                    }
                };

                // 5a. Opaque casters' volumes, counted against the transparent depth.
                transition(ctx, cb, &ss.count, vk::ImageLayout::UNDEFINED, vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL);
                begin(&[att(&ss.count, clear, zero)]);
                for (ci, case, light_obj, cdraws, _) in ldraws {
                    if *case == Case::Culled || self.casters[*ci].transmittance.is_some() {
                        continue;
                    }
                    let zpass = *case == Case::ZPass;
                    let mut push = [0f32; 24];
                    push[..16].copy_from_slice(&f.caster_mvp[*ci].to_cols_array());
                    push[16..20].copy_from_slice(&light_obj.to_array());
                    push[20] = if zpass { 1.0 } else { -1.0 };
                    d.cmd_push_constants(cb, self.layouts[1], stages, 0, bytes_of(&push));
                    // Light caps too take the general z-fail test: an opaque caster may lie in
                    // front of the transparent surface.
                    d.cmd_bind_pipeline(
                        cb,
                        vk::PipelineBindPoint::GRAPHICS,
                        if zpass { self.pipes.count_zpass } else { self.pipes.count_zfail },
                    );
                    for dr in cdraws {
                        self.record_draw(cb, *ci, dr, f.stream);
                    }
                }
                d.cmd_end_rendering(cb);
                transition(ctx, cb, &ss.count, vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL, vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL);

                // 5b. Transparent casters' volumes: the light-intensity map on the casters.
                transition(ctx, cb, &ss.map, vk::ImageLayout::UNDEFINED, vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL);
                begin(&[att(&ss.map, clear, map_clear)]);
                for (ci, case, light_obj, cdraws, _) in ldraws {
                    let Some(tr) = self.casters[*ci].transmittance else {
                        continue;
                    };
                    if *case == Case::Culled {
                        continue;
                    }
                    let zpass = *case == Case::ZPass;
                    let mut push = [0f32; 24];
                    push[..16].copy_from_slice(&f.caster_mvp[*ci].to_cols_array());
                    push[16..20].copy_from_slice(&light_obj.to_array());
                    push[20..24].copy_from_slice(&[if zpass { 1.0 } else { -1.0 }, tr.x, tr.y, tr.z]);
                    d.cmd_push_constants(cb, self.layouts[1], stages, 0, bytes_of(&push));
                    d.cmd_bind_pipeline(cb, vk::PipelineBindPoint::GRAPHICS, self.pipes.transmit[log as usize][(!zpass) as usize]);
                    for dr in cdraws {
                        self.record_draw(cb, *ci, dr, f.stream);
                    }
                }
                d.cmd_end_rendering(cb);
                transition(ctx, cb, &ss.map, vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL, vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL);

                // 6. This light over the transparent casters, scaled by both maps.
                let accum_att = [att(&t.accum, load, zero)];
                let depth_load = att(&t.depth, load, ds_clear);
                begin_pass(d, cb, scissor, f.viewport, &accum_att, Some(&depth_load));
                d.cmd_bind_pipeline(cb, vk::PipelineBindPoint::GRAPHICS, ss.light_pipe);
                d.cmd_bind_descriptor_sets(cb, vk::PipelineBindPoint::GRAPHICS, ss.layout, 0, &[ss.set.set], &[]);
                for (k, v) in f.light_uniforms[li].iter().enumerate() {
                    forward_push[16 + 4 * k..20 + 4 * k].copy_from_slice(&v.to_array());
                }
                forward_push[30] = 1.0; // params.z: light pass
                d.cmd_push_constants(cb, ss.layout, stages, 0, bytes_of(&forward_push));
                d.cmd_bind_vertex_buffers(cb, 0, &[self.scene_vertices.raw], &[0]);
                d.cmd_draw(cb, n, 1, self.opaque_count, 0);
                d.cmd_end_rendering(cb);
                memory_barrier(
                    ctx,
                    cb,
                    (vk::PipelineStageFlags2::COLOR_ATTACHMENT_OUTPUT | frag_tests, color_rw | ds_rw),
                    (
                        vk::PipelineStageFlags2::COLOR_ATTACHMENT_OUTPUT | frag_tests | vk::PipelineStageFlags2::FRAGMENT_SHADER,
                        color_rw | ds_rw | vk::AccessFlags2::SHADER_READ,
                    ),
                );
            }
        }
    }
}
