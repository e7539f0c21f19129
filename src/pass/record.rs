//! Recording: everything the pass writes into the host's command buffers.

use super::desc::TargetModel;
use super::draw::LightFrame;
use super::frame::PreparedFrame;
use super::stencil::VolumeKind;
use super::target::DepthStencilTarget;
use super::ShadowPass;
use crate::error::{Misuse, Result};
use ash::vk;

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

/// What one of the pass's own rendering instances draws into and with
/// ([`ShadowPass::cmd_volume_instance`]).
pub(super) struct Instance {
    /// The stencil's load op, and its clear value when it is CLEAR.
    pub stencil: (vk::AttachmentLoadOp, u32),
    /// An optional colour attachment: a view in COLOR_ATTACHMENT_OPTIMAL, cleared to the value.
    pub color: Option<(vk::ImageView, [f32; 4])>,
    /// The volumes' pipelines.
    pub kind: VolumeKind,
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
        if frame.uploads_recorded.swap(true, std::sync::atomic::Ordering::AcqRel) || frame.uploads.is_empty() {
            return Ok(());
        }
        let d = &self.dev.device;
        use vk::AccessFlags2 as A;
        use vk::PipelineStageFlags2 as S;
        // An upload not yet known to have landed rides with every frame until one that
        // carried it retires, so an earlier frame still in flight may be reading the buffer
        // this copy rewrites (with the same bytes): order the copies after those reads.
        crate::gpu::resources::memory_barrier(
            &self.dev,
            cb,
            (S::VERTEX_INPUT | S::COMPUTE_SHADER | self.mesh_stages(), A::NONE),
            (S::TRANSFER, A::TRANSFER_WRITE),
        );
        // SAFETY: the caller's contract; the staging and destination buffers live until the
        // frame's slot is prepared again.
        unsafe {
            for up in &frame.uploads {
                d.cmd_copy_buffer(cb, up.src, up.dst, &[vk::BufferCopy { src_offset: 0, dst_offset: up.dst_offset, size: up.size }]);
            }
        }
        // (the mesh draws of Technique::Mesh read the compute arena's tables directly)
        let mesh = self.mesh_stages();
        crate::gpu::resources::memory_barrier(
            &self.dev,
            cb,
            (S::TRANSFER, A::TRANSFER_WRITE),
            (S::VERTEX_INPUT | S::COMPUTE_SHADER | mesh, A::VERTEX_ATTRIBUTE_READ | A::INDEX_READ | A::SHADER_READ),
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
    ///
    /// ```no_run
    /// # use umbrage::pass::*; use ash::vk;
    /// # fn f(pass: &ShadowPass, cb: vk::CommandBuffer, frame: &PreparedFrame) -> umbrage::Result<()> {
    /// // SAFETY: `cb` is recording, outside any rendering instance or render pass.
    /// unsafe { pass.cmd_before_rendering(cb, frame)? };
    /// // ... then the host's depth pre-pass, then `cmd_determine` per light.
    /// # Ok(()) }
    /// ```
    pub unsafe fn cmd_before_rendering(&self, cb: vk::CommandBuffer, frame: &PreparedFrame) -> Result<()> {
        // SAFETY: the caller's contract.
        unsafe {
            self.cmd_upload(cb, frame)?;
            self.cmd_build_rays(cb, frame)?;
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
    ///
    /// ```no_run
    /// # use umbrage::pass::*; use ash::vk;
    /// # fn f(pass: &ShadowPass, cb: vk::CommandBuffer, frame: &PreparedFrame, image: vk::Image, view: vk::ImageView,
    /// #      extent: vk::Extent2D, lighting: impl Fn(usize)) -> umbrage::Result<()> {
    /// // The host sampled its depth (DEPTH_STENCIL_READ_ONLY_OPTIMAL) and wants the attachment
    /// // layout back for its lighting pass: the pass records both transitions.
    /// let target = DepthStencilTarget::new(image, view, extent).with_layouts(
    ///     vk::ImageLayout::DEPTH_STENCIL_READ_ONLY_OPTIMAL,
    ///     vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL,
    /// );
    /// for light in 0..frame.lights.len() {
    ///     // SAFETY: `cb` is recording outside rendering; `image` is in the declared layout;
    ///     // `frame` is this pass's and its slot's submission has not retired yet.
    ///     unsafe { pass.cmd_determine(cb, frame, light, &target)? };
    ///     lighting(light); // the host's lighting pass: stencil == 0 is lit
    /// }
    /// # Ok(()) }
    /// ```
    pub unsafe fn cmd_determine(
        &self,
        cb: vk::CommandBuffer,
        frame: &PreparedFrame,
        light: usize,
        target: &DepthStencilTarget,
    ) -> Result<()> {
        let lf = self.light(frame, light)?;
        target.check(frame, &self.desc.target)?;
        if frame.rays.is_some() {
            // SAFETY: forwarded contract.
            return unsafe { self.cmd_trace(cb, frame, light, target) };
        }
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
        unsafe {
            self.cmd_before_rendering(cb, frame)?;
            // Cleared to 0, or to the number of volumes containing the eye (zpass-clear).
            self.cmd_volume_instance(
                cb,
                frame,
                light,
                target,
                Instance { stencil: (vk::AttachmentLoadOp::CLEAR, lf.counter_clear), color: None, kind: VolumeKind::Stencil },
            )
        }
    }

    /// One rendering instance of the pass over light `light`'s scissor on `target`, between
    /// the declared layout transitions: depth loaded, the stencil (LOAD, or CLEAR to the
    /// value), optionally one colour attachment (a view in COLOR_ATTACHMENT_OPTIMAL and
    /// the value it is cleared to), the light's state and its volumes of `kind`.
    ///
    /// # Safety
    /// As [`cmd_determine`](Self::cmd_determine) with dynamic rendering, the frame's uploads
    /// recorded; `frame`, `light` and `target` checked.
    pub(super) unsafe fn cmd_volume_instance(
        &self,
        cb: vk::CommandBuffer,
        frame: &PreparedFrame,
        light: usize,
        target: &DepthStencilTarget,
        instance: Instance,
    ) -> Result<()> {
        let Instance { stencil: (load, clear), color, kind } = instance;
        let lf = self.light(frame, light)?;
        let depth = depth_attachment(target, vk::AttachmentLoadOp::LOAD, 0);
        let stencil = depth_attachment(target, load, clear);
        let colors: Vec<vk::RenderingAttachmentInfo> = color
            .into_iter()
            .map(|(view, value)| {
                vk::RenderingAttachmentInfo::default()
                    .image_view(view)
                    .image_layout(vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL)
                    .load_op(vk::AttachmentLoadOp::CLEAR)
                    .store_op(vk::AttachmentStoreOp::STORE)
                    .clear_value(vk::ClearValue { color: vk::ClearColorValue { float32: value } })
            })
            .collect();
        let info = vk::RenderingInfo::default()
            .render_area(lf.scissor)
            .layer_count(1)
            .color_attachments(&colors)
            .depth_attachment(&depth)
            .stencil_attachment(&stencil);
        let d = &self.dev.device;
        // SAFETY: the caller's contract; the attachments are the caller's image.
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
    pub(super) fn check_recorded_before_rendering(&self, frame: &PreparedFrame) -> Result<()> {
        let compute_pending = frame.compute.as_ref().is_some_and(|cf| !cf.recorded.get() && !cf.jobs.is_empty());
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
        self.light(frame, light)?;
        Self::volume_frame(frame, "the float counter and the light-intensity map")?;
        self.dynamic_only("the float counter and the light-intensity map")?;
        target.check(frame, &self.desc.target)?;
        // SAFETY: the caller's contract (outside a rendering instance).
        unsafe {
            self.cmd_before_rendering(cb, frame)?;
            self.cmd_volume_instance(
                cb,
                frame,
                light,
                target,
                Instance { stencil: (vk::AttachmentLoadOp::LOAD, 0), color: Some((color, clear)), kind },
            )
        }
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
    ///
    /// ```no_run
    /// # use umbrage::pass::*; use ash::vk;
    /// # fn f(pass: &ShadowPass, device: &ash::Device, cb: vk::CommandBuffer, frame: &PreparedFrame,
    /// #      lighting_pipeline: vk::Pipeline, extent: vk::Extent2D) -> umbrage::Result<()> {
    /// // Inside the host's lighting pass for light 0:
    /// // SAFETY: `cb` is recording inside the host's rendering, the pipeline has dynamic
    /// // viewport and scissor (and depth bounds where the pass uses them).
    /// unsafe {
    ///     device.cmd_bind_pipeline(cb, vk::PipelineBindPoint::GRAPHICS, lighting_pipeline);
    ///     pass.cmd_light_state(cb, frame, 0, extent)?;
    /// }
    /// # Ok(()) }
    /// ```
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
}

impl LightFrame {
    /// The light's depth bounds as the lighting pass should set them (`(0, 1)` when unbounded
    /// or when the pass does not use depth bounds).
    pub fn depth_bounds_or_full(&self) -> (f32, f32) {
        self.depth_bounds.unwrap_or((0.0, 1.0))
    }
}
