//! Ray query's share of the pass's API and recording: the inputs, the per-frame structures'
//! recording ([`ShadowPass::cmd_before_rendering`]) and the traced determination
//! ([`ShadowPass::cmd_determine`]).

use super::batch::BATCH;
use super::push::RayPush;
use super::work::RayWork;
use super::{RayCounts, RayQueryInputs, Rays};
use crate::error::{Error, Misuse, Result};
use crate::geom::Light;
use crate::gpu::accel;
use crate::pass::device::PassDevice;
use crate::pass::frame::PreparedFrame;
use crate::pass::target::DepthStencilTarget;
use crate::pass::view::ShadowView;
use crate::pass::ShadowPass;
use ash::vk;

impl ShadowPass {
    /// Records a ray-query frame's acceleration structures once (part of
    /// [`cmd_before_rendering`](Self::cmd_before_rendering)); nothing for other frames.
    ///
    /// # Safety
    /// As [`cmd_upload`](Self::cmd_upload); every earlier frame is submitted earlier on the
    /// same queue (a refit rewrites a structure they read).
    pub(crate) unsafe fn cmd_build_rays(&self, cb: vk::CommandBuffer, frame: &PreparedFrame) -> Result<()> {
        self.check_frame(frame)?;
        let (Some(rf), Some(rays)) = (&frame.rays, &self.techniques.rays.structures) else { return Ok(()) };
        if rf.recorded.replace(true) {
            return Ok(());
        }
        // SAFETY: forwarded contract.
        unsafe { rf.cmd_record(&self.dev, rays, cb) }
    }

    /// Light `light`'s ray-query determination: the stencil cleared to 0 inside the light's
    /// scissor, then set to 1 where the pixel's shadow ray is blocked.
    ///
    /// # Safety
    /// As [`cmd_determine`](Self::cmd_determine); `frame`, `light` and `target` checked; the
    /// inputs in `SHADER_READ_ONLY_OPTIMAL`.
    pub(crate) unsafe fn cmd_trace(
        &self,
        cb: vk::CommandBuffer,
        frame: &PreparedFrame,
        light: usize,
        target: &DepthStencilTarget,
    ) -> Result<()> {
        let lf = self.light(frame, light)?;
        let rf = frame.rays.as_ref().ok_or_else(|| Error::Internal("not a ray-query frame".into()))?;
        let push = rf.push.get(light).ok_or_else(|| Error::Internal("no ray push for the light".into()))?;
        let d = &self.dev.device;
        // SAFETY: the caller's contract; the set, pipeline and top level live until the slot
        // is prepared again.
        unsafe {
            self.cmd_before_rendering(cb, frame)?;
            // Batched: the light's batch traced into the mask (once), then its bit resolved.
            let bit = (light % BATCH) as u32;
            let (pipeline, layout, set, constants) = match &rf.batch {
                Some(b) => {
                    let first = light - light % BATCH;
                    let count = BATCH.min(rf.push.len() - first);
                    let batch_push = RayPush { light: [0.0; 4], params: [rf.offset, first as f32, count as f32, 0.0] };
                    b.cmd_trace_batch(&self.dev, cb, light / BATCH, (rf.set, rf.layout), batch_push)?;
                    (b.resolve, b.mask_layout, b.mask_set, bytemuck::bytes_of(&bit))
                }
                None => (rf.pipeline, rf.layout, rf.set, bytemuck::bytes_of(push)),
            };
            let draw = || -> Result<()> {
                self.cmd_light_state(cb, frame, light, target.extent)?;
                d.cmd_bind_pipeline(cb, vk::PipelineBindPoint::GRAPHICS, pipeline);
                d.cmd_bind_descriptor_sets(cb, vk::PipelineBindPoint::GRAPHICS, layout, 0, &[set], &[]);
                d.cmd_push_constants(cb, layout, vk::ShaderStageFlags::FRAGMENT, 0, constants);
                d.cmd_draw(cb, 3, 1, 0, 0);
                Ok(())
            };
            let depth = crate::pass::record::depth_attachment(target, vk::AttachmentLoadOp::LOAD, 0);
            let stencil = crate::pass::record::depth_attachment(target, vk::AttachmentLoadOp::CLEAR, 0);
            let info =
                vk::RenderingInfo::default().render_area(lf.scissor).layer_count(1).depth_attachment(&depth).stencil_attachment(&stencil);
            self.enter(cb, target);
            d.cmd_begin_rendering(cb, &info);
            let drawn = draw();
            d.cmd_end_rendering(cb);
            self.leave(cb, target);
            drawn
        }
    }

    /// The G-buffer [`Technique::RayQuery`](crate::pass::Technique::RayQuery) reads, from the next `prepare` on (again after a
    /// resize: the views are bound when a slot is prepared). See [`RayQueryInputs`] for what
    /// the images hold; the pass does not own them.
    ///
    /// Errors: [`Error::Unsupported`] when the device or the host lacks ray query
    /// ([`Capabilities::ray_query`](crate::pass::Capabilities::ray_query)), [`Error::Argument`](crate::Error) for a negative or
    /// non-finite offset.
    pub fn set_ray_query_inputs(&mut self, inputs: RayQueryInputs) -> Result<()> {
        if !self.caps.ray_query {
            return Err(crate::pass::desc::rays_missing());
        }
        if !(inputs.surface_offset.is_finite() && inputs.surface_offset >= 0.0) {
            return Err(Error::argument(
                "RayQueryInputs::surface_offset",
                format!("{} is not a finite offset >= 0", inputs.surface_offset),
            ));
        }
        self.techniques.rays.inputs = Some(inputs);
        Ok(())
    }

    /// What the ray-query structures have cost since the pass was created (bottom-level builds,
    /// refits, compactions); `None` before the first ray-query frame.
    pub fn ray_counts(&self) -> Option<RayCounts> {
        self.techniques.rays.structures.as_ref().map(|r| r.counts)
    }

    /// Refuses a ray-query frame the pass cannot trace.
    pub(crate) fn check_rays(&self) -> Result<()> {
        if self.techniques.rays.inputs.is_none() {
            return Err(Misuse::NotConfigured {
                call: "prepare (Technique::RayQuery)",
                needs: "set_ray_query_inputs (the G-buffer the rays start from)",
            }
            .into());
        }
        if let Some(c) = self.casters.cpu.iter().find(|c| c.transmittance.is_some()) {
            return Err(Error::Unsupported(format!(
                "Technique::RayQuery does not trace transparent casters yet ('{}': its coloured shadow needs the light-intensity map); use a volume technique",
                c.name
            )));
        }
        Ok(())
    }

    pub(crate) fn prepare_rays(&mut self, slot: usize, view: &ShadowView, lights: &[Light], scissors: &[vk::Rect2D]) -> Result<RayWork> {
        let inputs = self.techniques.rays.inputs.ok_or_else(|| Error::Internal("no ray-query inputs".into()))?;
        if self.techniques.rays.structures.is_none() {
            self.techniques.rays.structures = Some(Rays::new(&self.dev, &self.instance, self.slots.len())?);
        }
        let all = self.all_slots();
        let r = self.techniques.rays.structures.as_mut().ok_or_else(|| Error::Internal("no ray-query state".into()))?;
        let mut transient = Vec::new();
        let input = super::FrameInput {
            dev: &self.dev,
            slot,
            casters: &self.casters,
            spheres: &self.spheres,
            view,
            lights,
            scissors,
            batch: self.settings.toggles.ray_batch,
            inputs: &inputs,
            desc: &self.desc,
        };
        let out = r.prepare(&input, all, &mut transient);
        // Inputs and scratch memory go when the slot's frame has retired (as staging copies do).
        self.slots[slot].staging.extend(transient);
        out
    }
}

impl RayWork {
    /// Records the frame's acceleration-structure work: compactions, builds and refits, the
    /// compacted-size queries of new bottom levels, and the top level.
    ///
    /// # Safety
    /// `cb` is recording outside any rendering instance or render pass; the frame's slot is not
    /// prepared again before `cb` has completed; every frame recorded before it is submitted
    /// earlier on the same queue.
    pub unsafe fn cmd_record(&self, dev: &PassDevice, rays: &Rays, cb: vk::CommandBuffer) -> Result<()> {
        use vk::AccessFlags2 as A;
        use vk::PipelineStageFlags2 as S;
        let build = S::ACCELERATION_STRUCTURE_BUILD_KHR;
        let l = rays.loader();
        // Earlier frames' rays and builds finish before a structure is rewritten (refits) or
        // read (compaction sources).
        crate::gpu::resources::memory_barrier(
            dev,
            cb,
            (S::FRAGMENT_SHADER | build, A::ACCELERATION_STRUCTURE_READ_KHR | A::ACCELERATION_STRUCTURE_WRITE_KHR),
            (build, A::ACCELERATION_STRUCTURE_READ_KHR | A::ACCELERATION_STRUCTURE_WRITE_KHR),
        );
        // SAFETY: the caller's contract; every structure and buffer lives until the slot retires.
        unsafe {
            for &(src, dst) in &self.compactions {
                accel::cmd_compact(l, cb, src, dst);
            }
            for job in &self.jobs {
                job.cmd_record(l, cb);
            }
        }
        crate::gpu::resources::memory_barrier(
            dev,
            cb,
            (build, A::ACCELERATION_STRUCTURE_WRITE_KHR),
            (build, A::ACCELERATION_STRUCTURE_READ_KHR),
        );
        // SAFETY: as above; the pools are reset before they are written.
        unsafe {
            for &(pool, blas) in &self.queries {
                accel::cmd_write_compacted_size(dev, l, cb, pool, blas);
            }
            let tlas = rays.tlas(self.tlas_slot).ok_or_else(|| Error::Internal("no top level".into()))?;
            tlas.cmd_record(dev, l, cb, self.instances);
        }
        Ok(())
    }
}
