//! Recording: everything the pass writes into the host's command buffers.

use super::desc::{IndexFormat, TargetModel};
use super::frame::{CasterDraw, Draw, LightFrame, PreparedFrame};
use super::pipelines::CountPipes;
use super::push::VolumePush;
use super::target::DepthStencilTarget;
use super::ShadowPass;
use crate::error::{Misuse, Result};
use crate::shadow::Case;
use ash::vk;

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
    /// ([`Diagnostics::cmd_count_rasterised`](super::diagnostics::Diagnostics::cmd_count_rasterised)).
    Rasterised,
}

/// The stencil state of a lighting pass that lights where the count is zero: compare EQUAL
/// against reference 0, no writes, on both faces.
pub fn lit_stencil_state() -> vk::StencilOpState {
    crate::gpu::pipeline::stencil_equal(0)
}

pub(super) fn depth_attachment(
    target: &DepthStencilTarget,
    stencil: vk::AttachmentLoadOp,
    clear: u32,
) -> vk::RenderingAttachmentInfo<'static> {
    vk::RenderingAttachmentInfo::default()
        .image_view(target.view)
        .image_layout(vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL)
        .load_op(stencil)
        .store_op(vk::AttachmentStoreOp::STORE)
        .clear_value(vk::ClearValue { depth_stencil: vk::ClearDepthStencilValue { depth: 0.0, stencil: clear & 0xff } })
}

/// The fragment-test stages and depth-stencil accesses of the pass's own rendering.
const TESTS: (vk::PipelineStageFlags, vk::AccessFlags) = (
    vk::PipelineStageFlags::from_raw(
        vk::PipelineStageFlags::EARLY_FRAGMENT_TESTS.as_raw() | vk::PipelineStageFlags::LATE_FRAGMENT_TESTS.as_raw(),
    ),
    vk::AccessFlags::from_raw(
        vk::AccessFlags::DEPTH_STENCIL_ATTACHMENT_READ.as_raw() | vk::AccessFlags::DEPTH_STENCIL_ATTACHMENT_WRITE.as_raw(),
    ),
);

/// Everything before or after the pass, in any layout the host declared.
const ANY: (vk::PipelineStageFlags, vk::AccessFlags) = (
    vk::PipelineStageFlags::ALL_COMMANDS,
    vk::AccessFlags::from_raw(vk::AccessFlags::MEMORY_READ.as_raw() | vk::AccessFlags::MEMORY_WRITE.as_raw()),
);

impl ShadowPass {
    /// The frame, if this pass prepared it and its slot still holds it.
    pub(crate) fn check_frame(&self, frame: &PreparedFrame) -> Result<()> {
        if frame.pass != self.id {
            return Err(Misuse::ForeignFrame.into());
        }
        let current = self.slots.get(frame.slot).and_then(|s| s.serial);
        match current {
            Some(c) if c == frame.serial => Ok(()),
            Some(c) => Err(Misuse::StaleFrame { slot: frame.slot, serial: frame.serial, current: c }.into()),
            None => Err(Misuse::SlotOutOfRange { slot: frame.slot, slots: self.slots.len() }.into()),
        }
    }

    /// Light `light` of a live frame of this pass.
    pub(super) fn light<'f>(&self, frame: &'f PreparedFrame, light: usize) -> Result<&'f LightFrame> {
        self.check_frame(frame)?;
        frame.lights.get(light).ok_or_else(|| Misuse::LightIndex { index: light, lights: frame.lights.len() }.into())
    }

    pub(super) fn dynamic_only(&self, call: &'static str) -> Result<()> {
        match self.desc.target {
            TargetModel::DynamicRendering => Ok(()),
            _ => Err(Misuse::NotConfigured { call, needs: "TargetModel::DynamicRendering (it begins its own rendering instance)" }.into()),
        }
    }

    /// A layout transition (or, in the same layout, a plain dependency) of the host's image.
    ///
    /// # Safety
    /// `cb` is recording outside any rendering instance or render pass; `image` is the host's
    /// depth-stencil image in `from`.
    unsafe fn image_barrier(
        &self,
        cb: vk::CommandBuffer,
        image: vk::Image,
        (from, to): (vk::ImageLayout, vk::ImageLayout),
        src: (vk::PipelineStageFlags, vk::AccessFlags),
        dst: (vk::PipelineStageFlags, vk::AccessFlags),
    ) {
        let b = [vk::ImageMemoryBarrier::default()
            .src_access_mask(src.1)
            .dst_access_mask(dst.1)
            .old_layout(from)
            .new_layout(to)
            .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
            .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
            .image(image)
            .subresource_range(vk::ImageSubresourceRange {
                aspect_mask: vk::ImageAspectFlags::DEPTH | vk::ImageAspectFlags::STENCIL,
                base_mip_level: 0,
                level_count: vk::REMAINING_MIP_LEVELS,
                base_array_layer: 0,
                layer_count: vk::REMAINING_ARRAY_LAYERS,
            })];
        // SAFETY: the caller's contract.
        unsafe { self.dev.device.cmd_pipeline_barrier(cb, src.0, dst.0, vk::DependencyFlags::empty(), &[], &[], &b) };
    }

    /// Records the frame's pending caster uploads (buffer copies, then a barrier to vertex and
    /// index reads). Idempotent per frame: a second call, or the first `cmd_determine` after
    /// it, records nothing.
    ///
    /// Reads the pass's staging buffers; writes its caster vertex buffers. The host's images
    /// are not touched.
    ///
    /// Errors ([`Error::Misuse`](crate::Error::Misuse)): `frame` is another pass's, or its slot was prepared again.
    ///
    /// # Safety
    /// `cb` is a primary command buffer of the pass's device, recording, outside any rendering
    /// instance or render pass; it is submitted before (or in the same submission as, and
    /// earlier than) every command buffer that draws `frame`'s volumes, and completes before
    /// the frame's slot is prepared again.
    pub unsafe fn cmd_upload(&self, cb: vk::CommandBuffer, frame: &PreparedFrame) -> Result<()> {
        self.check_frame(frame)?;
        if frame.uploads_recorded.replace(true) || frame.uploads.is_empty() {
            return Ok(());
        }
        let d = &self.dev.device;
        // SAFETY: the caller's contract; the staging and destination buffers live until the
        // frame's slot is prepared again.
        unsafe {
            for up in &frame.uploads {
                d.cmd_copy_buffer(cb, up.src, up.dst, &[vk::BufferCopy { src_offset: 0, dst_offset: 0, size: up.size }]);
            }
        }
        use vk::AccessFlags2 as A;
        use vk::PipelineStageFlags2 as S;
        crate::gpu::resources::memory_barrier(
            &self.dev,
            cb,
            (S::TRANSFER, A::TRANSFER_WRITE),
            (S::VERTEX_INPUT | S::COMPUTE_SHADER, A::VERTEX_ATTRIBUTE_READ | A::INDEX_READ | A::SHADER_READ),
        );
        Ok(())
    }

    /// Records what must precede any rendering of `frame`, outside a rendering instance or
    /// render pass: [`cmd_upload`](Self::cmd_upload) and
    /// [`cmd_compute_silhouettes`](Self::cmd_compute_silhouettes). Hosts of the render-pass
    /// model call it before beginning their render pass; with dynamic rendering the first
    /// `cmd_determine` records it when the host did not.
    ///
    /// # Safety
    /// As [`cmd_upload`](Self::cmd_upload).
    pub unsafe fn cmd_before_rendering(&self, cb: vk::CommandBuffer, frame: &PreparedFrame) -> Result<()> {
        // SAFETY: the caller's contract.
        unsafe {
            self.cmd_upload(cb, frame)?;
            self.cmd_compute_silhouettes(cb, frame)
        }
    }

    /// Records light `light`'s shadow determination into the host's depth-stencil image.
    /// Afterwards the stencil holds the number of volumes around each pixel's visible point
    /// (each sample's, with MSAA), modulo 256 (0 = lit), inside the light's
    /// [`scissor`](LightFrame::scissor); outside it the stencil is unchanged.
    ///
    /// - Reads: the depth aspect (never written), the frame's buffers.
    /// - Writes: the stencil aspect, inside the light's scissor only (cleared to
    ///   [`LightFrame::counter_clear`], then counted).
    /// - Leaves: with [`TargetModel::DynamicRendering`], `target.final_layout`, with the
    ///   stencil writes visible to every later command; it records the frame's uploads and
    ///   GPU silhouettes first if the host did not ([`cmd_before_rendering`](Self::cmd_before_rendering)).
    ///   With [`TargetModel::RenderPass`] it records inside the host's subpass: viewport,
    ///   scissor and depth bounds set for the light, the stencil cleared with
    ///   `vkCmdClearAttachments`, the volumes drawn; the host's render pass and subpass
    ///   dependencies order it with the rest.
    ///
    /// Errors ([`Error::Misuse`](crate::Error::Misuse)), with nothing recorded: `light` out of range, a frame of
    /// another pass or a stale one, a target whose extent differs from the frame's view or
    /// whose declared layouts the model cannot take, and (render-pass model) a frame whose
    /// uploads or GPU silhouettes were not recorded before the render pass began.
    ///
    /// # Safety
    /// - `cb` is recording on the pass's device: outside any rendering instance or render pass
    ///   (dynamic rendering), or inside the subpass of [`TargetModel::RenderPass`] (a render
    ///   pass compatible with it, begun with `VK_SUBPASS_CONTENTS_INLINE`);
    /// - `target` describes the host's image truthfully: both aspects, the pass's format and
    ///   sample count, in `target.layout`;
    /// - the frame's slot is not prepared again before `cb` has completed.
    pub unsafe fn cmd_determine(
        &self,
        cb: vk::CommandBuffer,
        frame: &PreparedFrame,
        light: usize,
        target: &DepthStencilTarget,
    ) -> Result<()> {
        let lf = self.light(frame, light)?;
        target.check(frame, &self.desc.target)?;
        let d = &self.dev.device;
        if let TargetModel::RenderPass(_) = self.desc.target {
            self.check_recorded_before_rendering(frame)?;
            let clear = [vk::ClearAttachment {
                aspect_mask: vk::ImageAspectFlags::STENCIL,
                color_attachment: 0,
                clear_value: vk::ClearValue { depth_stencil: vk::ClearDepthStencilValue { depth: 0.0, stencil: lf.counter_clear & 0xff } },
            }];
            let rect = [vk::ClearRect { rect: lf.scissor, base_array_layer: 0, layer_count: 1 }];
            // SAFETY: the caller's contract (inside the subpass, whose depth-stencil attachment
            // is the target).
            unsafe {
                d.cmd_clear_attachments(cb, &clear, &rect);
                self.cmd_light_state(cb, frame, light, target.extent)?;
                self.cmd_draw_volumes(cb, frame, light, VolumeKind::Stencil)?;
            }
            return Ok(());
        }
        // SAFETY: the caller's contract (outside a rendering instance).
        unsafe { self.cmd_before_rendering(cb, frame)? };
        let depth = depth_attachment(target, vk::AttachmentLoadOp::LOAD, 0);
        // Cleared to 0, or to the number of volumes containing the eye (zpass-clear).
        let stencil = depth_attachment(target, vk::AttachmentLoadOp::CLEAR, lf.counter_clear);
        let info =
            vk::RenderingInfo::default().render_area(lf.scissor).layer_count(1).depth_attachment(&depth).stencil_attachment(&stencil);
        // SAFETY: the caller's contract; the attachments are the caller's image.
        unsafe {
            self.enter(cb, target);
            d.cmd_begin_rendering(cb, &info);
            self.cmd_light_state(cb, frame, light, target.extent)?;
            self.cmd_draw_volumes(cb, frame, light, VolumeKind::Stencil)?;
            d.cmd_end_rendering(cb);
            self.leave(cb, target);
        }
        Ok(())
    }

    /// The transition into the pass's rendering.
    ///
    /// # Safety
    /// Outside any rendering instance; `target` describes the host's image truthfully.
    pub(super) unsafe fn enter(&self, cb: vk::CommandBuffer, target: &DepthStencilTarget) {
        let ds = vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL;
        // SAFETY: the caller's contract.
        unsafe { self.image_barrier(cb, target.image, (target.layout, ds), ANY, TESTS) };
    }

    /// The transition out of the pass's rendering, to the declared final layout.
    ///
    /// # Safety
    /// As [`enter`](Self::enter), after it.
    pub(super) unsafe fn leave(&self, cb: vk::CommandBuffer, target: &DepthStencilTarget) {
        let ds = vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL;
        // SAFETY: the caller's contract.
        unsafe { self.image_barrier(cb, target.image, (ds, target.final_layout), TESTS, ANY) };
    }

    /// Refuses a frame whose uploads or GPU silhouettes would have to be recorded inside the
    /// host's render pass.
    fn check_recorded_before_rendering(&self, frame: &PreparedFrame) -> Result<()> {
        let compute_pending = frame.compute.as_ref().is_some_and(|cf| !cf.recorded.get() && !cf.jobs.iter().all(|j| j.is_empty()));
        if frame.pending_uploads() > 0 || compute_pending {
            return Err(Misuse::Order(
                "the frame's uploads or GPU silhouettes are not recorded: call cmd_before_rendering before beginning the render pass"
                    .into(),
            )
            .into());
        }
        Ok(())
    }

    /// Records the transparent casters' light-intensity map of `light` (Kim et al. 2008) into
    /// `map` (the pass's transmit format), cleared inside the scissor to 1 (0 in log space).
    ///
    /// # Safety
    /// As [`Diagnostics::cmd_count_float`](super::diagnostics::Diagnostics::cmd_count_float), with `map` in the format given as
    /// [`ShadowPassDesc::transmit_format`](super::ShadowPassDesc).
    pub unsafe fn cmd_light_intensity(
        &self,
        cb: vk::CommandBuffer,
        frame: &PreparedFrame,
        light: usize,
        target: &DepthStencilTarget,
        map: vk::ImageView,
        log: bool,
    ) -> Result<()> {
        if self.pipes.transmit.is_none() {
            return Err(Misuse::NotConfigured { call: "cmd_light_intensity", needs: "ShadowPassDesc::transmit_format" }.into());
        }
        let clear = if log { [0.0; 4] } else { [1.0; 4] };
        // SAFETY: forwarded contract.
        unsafe { self.cmd_counted_instance(cb, frame, light, target, (map, clear), VolumeKind::Transmit { log }) }
    }

    /// A rendering instance over the light's scissor with one colour attachment (`color`: the
    /// view and its clear value) and the depth-stencil loaded, drawing `kind`.
    ///
    /// # Safety
    /// As [`Diagnostics::cmd_count_float`](super::diagnostics::Diagnostics::cmd_count_float).
    pub(super) unsafe fn cmd_counted_instance(
        &self,
        cb: vk::CommandBuffer,
        frame: &PreparedFrame,
        light: usize,
        target: &DepthStencilTarget,
        (color, clear): (vk::ImageView, [f32; 4]),
        kind: VolumeKind,
    ) -> Result<()> {
        let lf = self.light(frame, light)?;
        self.dynamic_only("the float counter and the light-intensity map")?;
        target.check(frame, &self.desc.target)?;
        // SAFETY: the caller's contract (outside a rendering instance).
        unsafe { self.cmd_before_rendering(cb, frame)? };
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
            self.enter(cb, target);
            d.cmd_begin_rendering(cb, &info);
            self.cmd_light_state(cb, frame, light, target.extent)?;
            self.cmd_draw_volumes(cb, frame, light, kind)?;
            d.cmd_end_rendering(cb);
            self.leave(cb, target);
        }
        Ok(())
    }

    /// Sets the dynamic state of a light's passes: the viewport over `extent`, the light's
    /// scissor, and its depth bounds when the pass uses them. For the host's lighting pass
    /// too (its pipeline needs these states dynamic: VIEWPORT, SCISSOR, and DEPTH_BOUNDS when
    /// [`Capabilities::depth_bounds`](super::Capabilities)).
    ///
    /// Errors: as [`cmd_determine`](Self::cmd_determine)'s frame and light checks.
    ///
    /// # Safety
    /// `cb` is recording with a graphics pipeline of that dynamic state bound or about to be.
    pub unsafe fn cmd_light_state(&self, cb: vk::CommandBuffer, frame: &PreparedFrame, light: usize, extent: vk::Extent2D) -> Result<()> {
        let lf = self.light(frame, light)?;
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
        Ok(())
    }

    /// Records the volumes of `light` for `kind` inside a rendering instance the caller
    /// began (attachments: the pass's depth-stencil format, plus an R32F colour attachment
    /// for the float kinds or the transmit format for `Transmit`), with the viewport and
    /// scissor set (e.g. by [`cmd_light_state`](Self::cmd_light_state)).
    ///
    /// With [`TargetModel::RenderPass`], inside the host's subpass (stencil and rasterised
    /// kinds only).
    ///
    /// Errors ([`Error::Misuse`](crate::Error::Misuse)): as `cmd_determine`'s frame and light checks, and a kind the
    /// pass has no pipelines for (float kinds without R32F blending or in the render-pass
    /// model, `Transmit` without a transmit format).
    ///
    /// # Safety
    /// `cb` is recording inside such a rendering instance or subpass; the frame's uploads and
    /// GPU silhouettes were recorded earlier ([`cmd_before_rendering`](Self::cmd_before_rendering));
    /// `frame`'s slot is not prepared again before `cb` completes.
    pub unsafe fn cmd_draw_volumes(&self, cb: vk::CommandBuffer, frame: &PreparedFrame, light: usize, kind: VolumeKind) -> Result<()> {
        let lf = self.light(frame, light)?;
        let p = &self.pipes;
        let count = p.count.as_ref();
        match kind {
            VolumeKind::Float | VolumeKind::FloatDepthTested if count.is_none() => {
                return Err(Misuse::NotConfigured {
                    call: "cmd_draw_volumes (float kinds)",
                    needs: "R32_SFLOAT blending and TargetModel::DynamicRendering",
                }
                .into());
            }
            VolumeKind::Transmit { .. } if p.transmit.is_none() => {
                return Err(Misuse::NotConfigured {
                    call: "cmd_draw_volumes (VolumeKind::Transmit)",
                    needs: "ShadowPassDesc::transmit_format",
                }
                .into());
            }
            _ => {}
        }
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
        Ok(())
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

    /// # Safety
    /// `cb` is recording with a pipeline of the pass's layout bound or about to be.
    pub(super) unsafe fn push(&self, cb: vk::CommandBuffer, c: &CasterDraw, color: [f32; 4]) {
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
    pub(super) unsafe fn record_draw(&self, cb: vk::CommandBuffer, frame: &PreparedFrame, dr: &Draw) {
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
