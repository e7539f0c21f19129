//! Recording: everything the pass writes into the host's command buffers.

use super::desc::IndexFormat;
use super::frame::{CasterDraw, Draw, LightFrame, PreparedFrame};
use super::pipelines::CountPipes;
use super::push::VolumePush;
use super::ShadowPass;
use crate::shadow::Case;
use ash::vk;

/// The host's depth-stencil attachment for the determination.
#[derive(Clone, Copy, Debug)]
pub struct DepthStencilTarget {
    /// A view of the host's depth-stencil image covering both aspects, in the format the pass
    /// was created for; the image is in `DEPTH_STENCIL_ATTACHMENT_OPTIMAL` (or
    /// `ATTACHMENT_OPTIMAL`) layout when the pass records.
    pub view: vk::ImageView,
    /// The image's size (the viewport covers all of it).
    pub extent: vk::Extent2D,
}

/// What a volume draw counts into (the pipelines differ, the geometry is the same).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VolumeKind {
    /// Opaque casters into the stencil (two-sided wrapping ops; light caps with depth NEVER).
    Stencil,
    /// Opaque casters into an R32F colour target, ±1 per face, additively blended.
    Float,
    /// As `Float`, but every face depth-tested like the sides, light caps too (the
    /// self-shadowing count against a transparent layer's depth, Kim et al. 2008 step 5).
    FloatDepthTested,
    /// Transparent casters into the light-intensity map: each counted face multiplies by its
    /// transmittance `t` or `1/t` (`log`: adds `±log t`).
    Transmit {
        /// Log-space map (additive) rather than multiplicative.
        log: bool,
    },
    /// Opaque casters with depth and stencil tests always passing and nothing written: under
    /// an occlusion query, the exact number of fragments the volumes rasterise
    /// ([`ShadowPass::cmd_count_rasterised`](super::ShadowPass::cmd_count_rasterised)).
    Rasterised,
}

/// The stencil state of a lighting pass that lights where the count is zero: compare EQUAL
/// against reference 0, no writes, on both faces.
pub fn lit_stencil_state() -> vk::StencilOpState {
    crate::gpu::pipeline::stencil_equal(0)
}

fn depth_attachment(target: &DepthStencilTarget, stencil: vk::AttachmentLoadOp, clear: u32) -> vk::RenderingAttachmentInfo<'static> {
    vk::RenderingAttachmentInfo::default()
        .image_view(target.view)
        .image_layout(vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL)
        .load_op(stencil)
        .store_op(vk::AttachmentStoreOp::STORE)
        .clear_value(vk::ClearValue { depth_stencil: vk::ClearDepthStencilValue { depth: 1.0, stencil: clear & 0xff } })
}

impl ShadowPass {
    /// Records the frame's pending caster uploads (buffer copies, then a barrier to vertex and
    /// index reads). Idempotent per frame: a second call, or the first `cmd_determine` after
    /// it, records nothing.
    ///
    /// # Safety
    /// `cb` is a primary command buffer of the pass's device, recording, outside any rendering
    /// instance; it is submitted before (or in the same submission as, and earlier than) every
    /// command buffer that draws `frame`'s volumes. `frame` was prepared by this pass and its
    /// slot has not been prepared again.
    pub unsafe fn cmd_upload(&self, cb: vk::CommandBuffer, frame: &PreparedFrame) {
        if frame.uploads_recorded.replace(true) || frame.uploads.is_empty() {
            return;
        }
        let d = &self.dev.device;
        // SAFETY: the caller's contract; the staging and destination buffers live until the
        // frame's slot is prepared again.
        unsafe {
            for up in &frame.uploads {
                d.cmd_copy_buffer(cb, up.src, up.dst, &[vk::BufferCopy { src_offset: 0, dst_offset: 0, size: up.size }]);
            }
            let b = [vk::MemoryBarrier2::default()
                .src_stage_mask(vk::PipelineStageFlags2::COPY)
                .src_access_mask(vk::AccessFlags2::TRANSFER_WRITE)
                .dst_stage_mask(vk::PipelineStageFlags2::VERTEX_INPUT | vk::PipelineStageFlags2::COMPUTE_SHADER)
                .dst_access_mask(
                    vk::AccessFlags2::VERTEX_ATTRIBUTE_READ | vk::AccessFlags2::INDEX_READ | vk::AccessFlags2::SHADER_STORAGE_READ,
                )];
            d.cmd_pipeline_barrier2(cb, &vk::DependencyInfo::default().memory_barriers(&b));
        }
    }

    /// Records light `light`'s shadow determination into the host's depth-stencil image: a
    /// rendering instance over the light's scissor with the depth loaded and the stencil
    /// cleared to 0 there, then every opaque caster's volume (two-sided, wrapping). Afterwards
    /// the stencil holds the number of volumes around each pixel's visible point, modulo 256
    /// (0 = lit). Records the frame's uploads first if [`cmd_upload`](Self::cmd_upload) was
    /// not called.
    ///
    /// # Safety
    /// - `cb` is recording, outside any rendering instance, on the pass's device;
    /// - `target.view` is a view of both aspects of an image in the pass's depth-stencil
    ///   format, in `DEPTH_STENCIL_ATTACHMENT_OPTIMAL` layout, whose depth writes are visible
    ///   to fragment tests (the host's barrier);
    /// - `frame` was prepared by this pass, `light < frame.lights.len()`, and the frame's
    ///   slot is not prepared again before `cb` has completed.
    ///
    /// The pass writes only the stencil aspect inside the light's scissor rectangle.
    pub unsafe fn cmd_determine(&self, cb: vk::CommandBuffer, frame: &PreparedFrame, light: usize, target: &DepthStencilTarget) {
        let Some(lf) = frame.lights.get(light) else { return };
        // SAFETY: the caller's contract (outside a rendering instance).
        unsafe {
            self.cmd_upload(cb, frame);
            self.cmd_compute_silhouettes(cb, frame);
        }
        let depth = depth_attachment(target, vk::AttachmentLoadOp::LOAD, 0);
        // Cleared to 0, or to the number of volumes containing the eye (zpass-clear).
        let stencil = depth_attachment(target, vk::AttachmentLoadOp::CLEAR, lf.counter_clear);
        let info =
            vk::RenderingInfo::default().render_area(lf.scissor).layer_count(1).depth_attachment(&depth).stencil_attachment(&stencil);
        let d = &self.dev.device;
        // SAFETY: the caller's contract; the attachments are the caller's image.
        unsafe {
            d.cmd_begin_rendering(cb, &info);
            self.cmd_light_state(cb, frame, light, target.extent);
            self.cmd_draw_volumes(cb, frame, light, VolumeKind::Stencil);
            d.cmd_end_rendering(cb);
        }
    }

    /// The counting variant of [`cmd_determine`](Self::cmd_determine): the same volumes of
    /// light `light` over the same scissor (and depth bounds), with depth and stencil tests
    /// always passing and nothing written. Wrapped by the host in an occlusion query
    /// (`VK_QUERY_CONTROL_PRECISE_BIT` with `occlusionQueryPrecise`), the query counts every
    /// fragment the determination rasterises: the stencil fill it costs. The image's contents
    /// are left as they are.
    ///
    /// # Safety
    /// As [`cmd_determine`](Self::cmd_determine) (the stencil aspect is loaded, not cleared);
    /// the frame's uploads were recorded earlier in `cb` or a command buffer submitted before it.
    pub unsafe fn cmd_count_rasterised(&self, cb: vk::CommandBuffer, frame: &PreparedFrame, light: usize, target: &DepthStencilTarget) {
        let Some(lf) = frame.lights.get(light) else { return };
        // SAFETY: the caller's contract (outside a rendering instance).
        unsafe { self.cmd_upload(cb, frame) };
        let att = depth_attachment(target, vk::AttachmentLoadOp::LOAD, 0);
        let info = vk::RenderingInfo::default().render_area(lf.scissor).layer_count(1).depth_attachment(&att).stencil_attachment(&att);
        let d = &self.dev.device;
        // SAFETY: the caller's contract; the attachments are the caller's image.
        unsafe {
            d.cmd_begin_rendering(cb, &info);
            self.cmd_light_state(cb, frame, light, target.extent);
            self.cmd_draw_volumes(cb, frame, light, VolumeKind::Rasterised);
            d.cmd_end_rendering(cb);
        }
    }

    /// As [`cmd_determine`](Self::cmd_determine), but counting into `count` (an R32F image,
    /// [`COUNT_FORMAT`](super::COUNT_FORMAT), cleared to 0 inside the scissor): exact counts
    /// with no 8-bit wrap. The depth-stencil image is only read.
    ///
    /// # Safety
    /// As `cmd_determine`; in addition `count` is a view of an R32F image of the same size in
    /// `COLOR_ATTACHMENT_OPTIMAL` layout, and the pass was created on a device where R32F
    /// blends ([`Capabilities::r32f_blend`](super::Capabilities)).
    pub unsafe fn cmd_count_float(
        &self,
        cb: vk::CommandBuffer,
        frame: &PreparedFrame,
        light: usize,
        target: &DepthStencilTarget,
        count: vk::ImageView,
    ) {
        let start = frame.lights.get(light).map_or(0.0, |l| l.counter_clear as f32);
        // SAFETY: forwarded contract.
        unsafe { self.cmd_counted_instance(cb, frame, light, target, count, [start, 0.0, 0.0, 0.0], VolumeKind::Float) }
    }

    /// Records the transparent casters' light-intensity map of `light` (Kim et al. 2008) into
    /// `map` (the pass's transmit format), cleared inside the scissor to 1 (0 in log space).
    ///
    /// # Safety
    /// As [`cmd_count_float`](Self::cmd_count_float), with `map` in the format given as
    /// [`ShadowPassDesc::transmit_format`](super::ShadowPassDesc).
    pub unsafe fn cmd_light_intensity(
        &self,
        cb: vk::CommandBuffer,
        frame: &PreparedFrame,
        light: usize,
        target: &DepthStencilTarget,
        map: vk::ImageView,
        log: bool,
    ) {
        let clear = if log { [0.0; 4] } else { [1.0; 4] };
        // SAFETY: forwarded contract.
        unsafe { self.cmd_counted_instance(cb, frame, light, target, map, clear, VolumeKind::Transmit { log }) }
    }

    /// A rendering instance over the light's scissor with one cleared colour attachment and
    /// the depth-stencil loaded, drawing `kind`.
    ///
    /// # Safety
    /// As [`cmd_count_float`](Self::cmd_count_float).
    #[allow(clippy::too_many_arguments)]
    unsafe fn cmd_counted_instance(
        &self,
        cb: vk::CommandBuffer,
        frame: &PreparedFrame,
        light: usize,
        target: &DepthStencilTarget,
        color: vk::ImageView,
        clear: [f32; 4],
        kind: VolumeKind,
    ) {
        let Some(lf) = frame.lights.get(light) else { return };
        // SAFETY: the caller's contract (outside a rendering instance).
        unsafe {
            self.cmd_upload(cb, frame);
            self.cmd_compute_silhouettes(cb, frame);
        }
        let ds = depth_attachment(target, vk::AttachmentLoadOp::LOAD, 0);
        let att = [vk::RenderingAttachmentInfo::default()
            .image_view(color)
            .image_layout(vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL)
            .load_op(vk::AttachmentLoadOp::CLEAR)
            .store_op(vk::AttachmentStoreOp::STORE)
            .clear_value(vk::ClearValue { color: vk::ClearColorValue { float32: clear } })];
        let info = vk::RenderingInfo::default()
            .render_area(lf.scissor)
            .layer_count(1)
            .color_attachments(&att)
            .depth_attachment(&ds)
            .stencil_attachment(&ds);
        let d = &self.dev.device;
        // SAFETY: the caller's contract.
        unsafe {
            d.cmd_begin_rendering(cb, &info);
            self.cmd_light_state(cb, frame, light, target.extent);
            self.cmd_draw_volumes(cb, frame, light, kind);
            d.cmd_end_rendering(cb);
        }
    }

    /// Sets the dynamic state of a light's passes: the viewport over `extent`, the light's
    /// scissor, and its depth bounds when the pass uses them. For the host's lighting pass
    /// too (its pipeline needs these states dynamic: VIEWPORT, SCISSOR, and DEPTH_BOUNDS when
    /// [`Capabilities::depth_bounds`](super::Capabilities)).
    ///
    /// # Safety
    /// `cb` is recording with a graphics pipeline of that dynamic state bound or about to be.
    pub unsafe fn cmd_light_state(&self, cb: vk::CommandBuffer, frame: &PreparedFrame, light: usize, extent: vk::Extent2D) {
        let Some(lf) = frame.lights.get(light) else { return };
        let d = &self.dev.device;
        let viewport =
            vk::Viewport { x: 0.0, y: 0.0, width: extent.width as f32, height: extent.height as f32, min_depth: 0.0, max_depth: 1.0 };
        // SAFETY: the caller's contract.
        unsafe {
            d.cmd_set_viewport(cb, 0, &[viewport]);
            d.cmd_set_scissor(cb, 0, &[lf.scissor]);
            if self.caps.depth_bounds {
                let (lo, hi) = lf.depth_bounds.unwrap_or((0.0, 1.0));
                d.cmd_set_depth_bounds(cb, lo, hi);
            }
        }
    }

    /// Records the volumes of `light` for `kind` inside a rendering instance the caller
    /// began (attachments: the pass's depth-stencil format, plus an R32F colour attachment
    /// for the float kinds or the transmit format for `Transmit`), with the viewport and
    /// scissor set (e.g. by [`cmd_light_state`](Self::cmd_light_state)).
    ///
    /// # Safety
    /// `cb` is recording inside such a rendering instance; the frame's uploads and GPU silhouettes were recorded
    /// earlier ([`cmd_upload`](Self::cmd_upload)); `frame` is live as for `cmd_determine`;
    /// for the float kinds the device blends R32F, for `Transmit` the pass has a transmit format.
    pub unsafe fn cmd_draw_volumes(&self, cb: vk::CommandBuffer, frame: &PreparedFrame, light: usize, kind: VolumeKind) {
        let Some(lf) = frame.lights.get(light) else { return };
        let p = &self.pipes;
        let count = p.count.as_ref();
        let mut bound = vk::Pipeline::null();
        for c in lf.casters.iter().filter(|c| c.case != Case::Culled) {
            let wanted = match kind {
                VolumeKind::Transmit { .. } => c.transmittance.is_some(),
                _ => c.transmittance.is_none(),
            };
            if !wanted {
                continue;
            }
            // Float counter: the sign a front face contributes (+1 z-pass, -1 z-fail);
            // light-intensity map: and the caster's transmittance.
            let color = |case: Case| {
                let sign = if case == Case::ZPass { 1.0 } else { -1.0 };
                let t = c.transmittance.unwrap_or_default();
                [sign, t.x, t.y, t.z]
            };
            if let Some(eq) = &c.edge_quad {
                // SAFETY: the caller's contract; push constants match the pipeline layout.
                unsafe { self.push(cb, c, color(c.case)) };
                let (faces, sides) = match (kind, count) {
                    (VolumeKind::Stencil, _) => (p.stencil.eq_faces, p.stencil.eq_sides),
                    (VolumeKind::Rasterised, _) => (p.raster.edge_quads, p.raster.edge_quads),
                    (VolumeKind::Float, Some(cp)) => (cp.eq_faces, cp.eq_sides),
                    // Self-shadowing leaves edge-quad casters out (their faces are not a
                    // depth-tested volume); transparent casters never take edge quads.
                    _ => continue,
                };
                let d = &self.dev.device;
                // SAFETY: as above; the edge-quad buffers live until the slot retires.
                unsafe {
                    d.cmd_bind_vertex_buffers(cb, 0, &[eq.vertices], &[0]);
                    d.cmd_bind_index_buffer(cb, eq.indices, 0, vk::IndexType::UINT32);
                    d.cmd_bind_pipeline(cb, vk::PipelineBindPoint::GRAPHICS, faces);
                    d.cmd_draw_indexed(cb, eq.face_indices, 1, 0, 0, 0);
                    d.cmd_bind_pipeline(cb, vk::PipelineBindPoint::GRAPHICS, sides);
                    d.cmd_draw_indexed(cb, eq.quad_indices, 1, eq.face_indices, 0, 0);
                }
                bound = sides;
                continue;
            }
            let mut pushed = None;
            for dr in &c.draws {
                let planar = frame.settings.technique == super::desc::Technique::Planar;
                let Some(pipe) = self.pipeline_for(kind, count, dr.case, dr.light_cap, planar) else { continue };
                // Parts of one caster may take different cases: the sign follows the draw's.
                let block = color(dr.case);
                if pushed != Some(block) {
                    // SAFETY: as above.
                    unsafe { self.push(cb, c, block) };
                    pushed = Some(block);
                }
                if pipe != bound {
                    // SAFETY: as above.
                    unsafe { self.dev.device.cmd_bind_pipeline(cb, vk::PipelineBindPoint::GRAPHICS, pipe) };
                    bound = pipe;
                }
                // SAFETY: as above.
                unsafe { self.record_draw(cb, frame, dr) };
            }
        }
    }

    /// Which pipeline counts a draw.
    fn pipeline_for(
        &self,
        kind: VolumeKind,
        count: Option<&CountPipes>,
        case: Case,
        light_cap: bool,
        planar: bool,
    ) -> Option<vk::Pipeline> {
        let s = &self.pipes.stencil;
        if kind == VolumeKind::Rasterised {
            return Some(self.pipes.raster.volume);
        }
        if planar {
            // Flattened casters: the sign pushed is +1 (z-pass), so the float count adds 1.
            return match kind {
                VolumeKind::Stencil => Some(self.pipes.planar),
                VolumeKind::Float => self.pipes.planar_count,
                _ => None,
            };
        }
        let zpass = case == Case::ZPass;
        Some(match kind {
            VolumeKind::Stencil => match (zpass, light_cap) {
                (true, _) => s.zpass,
                (false, false) => s.zfail,
                (false, true) => s.zfail_cap,
            },
            VolumeKind::Float => {
                let c = count?;
                match (zpass, light_cap) {
                    (true, _) => c.zpass,
                    (false, false) => c.zfail,
                    (false, true) => c.cap,
                }
            }
            VolumeKind::FloatDepthTested => {
                let c = count?;
                if zpass {
                    c.zpass
                } else {
                    c.zfail
                }
            }
            // Transparent casters' caps are all in the volume list (not NEVER).
            VolumeKind::Transmit { log } => self.pipes.transmit?[log as usize][(!zpass) as usize],
            VolumeKind::Rasterised => self.pipes.raster.volume,
        })
    }

    /// Draws every light's volumes translucent, coloured by case (z-pass blue, z-fail red,
    /// z-fail with light cap green), light caps left out: the `--view volumes` debug overlay.
    ///
    /// # Safety
    /// `cb` is recording inside a rendering instance with one colour attachment of
    /// [`ShadowPassDesc::debug_color_format`](super::ShadowPassDesc) (the pass must have been
    /// created with it) and the depth-stencil image loaded, viewport and scissor set; the
    /// frame's uploads and GPU silhouettes were recorded; `frame` is live.
    pub unsafe fn cmd_draw_volume_overlay(&self, cb: vk::CommandBuffer, frame: &PreparedFrame) {
        let Some(pipe) = self.pipes.overlay else { return };
        // SAFETY: the caller's contract.
        unsafe { self.dev.device.cmd_bind_pipeline(cb, vk::PipelineBindPoint::GRAPHICS, pipe) };
        for lf in &frame.lights {
            for c in lf.casters.iter().filter(|c| c.case != Case::Culled) {
                for dr in c.draws.iter().filter(|dr| !dr.light_cap) {
                    let color = match dr.case {
                        Case::Culled => continue,
                        Case::ZPass => [0.2f32, 0.4, 1.0, 0.12],
                        Case::ZFail => [1.0, 0.3, 0.2, 0.12],
                        Case::ZFailLightCap => [0.1, 1.0, 0.2, 0.12],
                    };
                    // SAFETY: as above.
                    unsafe {
                        self.push(cb, c, color);
                        self.record_draw(cb, frame, dr);
                    }
                }
            }
        }
    }

    /// # Safety
    /// `cb` is recording with a pipeline of the pass's layout bound or about to be.
    unsafe fn push(&self, cb: vk::CommandBuffer, c: &CasterDraw, color: [f32; 4]) {
        let push = VolumePush::new(c.mvp, c.light_object, color);
        // SAFETY: the caller's contract; the block matches the layout's range.
        unsafe {
            self.dev.device.cmd_push_constants(
                cb,
                self.pipes.layout,
                vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT,
                0,
                bytemuck::bytes_of(&push),
            )
        };
    }

    /// Binds the chunk's vertices (or the streamed naive vertices) and draws.
    ///
    /// # Safety
    /// `cb` is recording inside a rendering instance with a volume pipeline bound; `frame` is
    /// the frame the draw belongs to (its stream, or its compute records and indices, whose
    /// writes [`cmd_compute_silhouettes`](Self::cmd_compute_silhouettes) made visible).
    unsafe fn record_draw(&self, cb: vk::CommandBuffer, frame: &PreparedFrame, dr: &Draw) {
        let d = &self.dev.device;
        let stream = frame.stream;
        // SAFETY: the caller's contract; offsets were computed from the stream just written.
        unsafe {
            if dr.indirect {
                let Some(cf) = frame.compute.as_ref() else { return };
                d.cmd_bind_vertex_buffers(cb, 0, &[dr.vertices], &[0]);
                d.cmd_bind_index_buffer(cb, cf.out_buffer, 0, vk::IndexType::UINT16);
                d.cmd_draw_indexed_indirect(cb, cf.records_buffer, dr.offset, 1, 20);
                return;
            }
            match dr.format {
                IndexFormat::Naive => {
                    d.cmd_bind_vertex_buffers(cb, 0, &[stream], &[dr.offset]);
                    d.cmd_draw(cb, dr.count, 1, 0, 0);
                }
                f => {
                    let ty = match f {
                        IndexFormat::U8 => vk::IndexType::UINT8_EXT,
                        IndexFormat::U32 => vk::IndexType::UINT32,
                        _ => vk::IndexType::UINT16,
                    };
                    d.cmd_bind_vertex_buffers(cb, 0, &[dr.vertices], &[0]);
                    d.cmd_bind_index_buffer(cb, stream, dr.offset, ty);
                    d.cmd_draw_indexed(cb, dr.count, 1, 0, 0, 0);
                }
            }
        }
    }
}

impl LightFrame {
    /// The light's depth bounds as the lighting pass should set them (`(0, 1)` when unbounded
    /// or when the pass does not use depth bounds).
    pub fn depth_bounds_or_full(&self) -> (f32, f32) {
        self.depth_bounds.unwrap_or((0.0, 1.0))
    }
}
