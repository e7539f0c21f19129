//! Recording the compute pass: outside any rendering instance, before the frame's first volume
//! draw, for every light at once (each light has its own records and regions, so the volume
//! overlay and later passes can draw any light's volumes again).
//!
//! Barriers (global memory barriers, synchronization2):
//! 1. earlier indirect, index and compute accesses (a previous frame on the queue) and the
//!    caster uploads -> compute reads and writes;
//! 2. the facing filter's writes -> the exact facing pass; its writes -> the caps-and-edges
//!    pass's reads and atomics;
//! 3. the compute writes -> indirect-command reads, index reads, and host reads (the counts
//!    `--stats` reads back after the fence).

use super::super::ShadowPass;
use super::frame::ComputeFrame;
use super::SilhouettePush;
use crate::pass::PreparedFrame;
use ash::vk;

/// Most workgroups of one dispatch (the shader strides over the rest).
const MAX_GROUPS: u32 = 65535;
/// Workgroups of the exact facing pass (it strides over the filter's list of undecided
/// triangles, usually empty).
const EXACT_GROUPS: u32 = 16;

fn groups(n: u32) -> u32 {
    n.div_ceil(64).min(MAX_GROUPS)
}

/// A global memory barrier, recorded as Vulkan 1.0 (the pass needs no synchronization2).
fn barrier(
    dev: &super::super::device::PassDevice,
    cb: vk::CommandBuffer,
    src: (vk::PipelineStageFlags2, vk::AccessFlags2),
    dst: (vk::PipelineStageFlags2, vk::AccessFlags2),
) {
    crate::gpu::resources::memory_barrier(dev, cb, src, dst);
}

impl ShadowPass {
    /// Records the GPU possible silhouettes of every light of `frame`
    /// ([`Technique::Compute`](crate::pass::Technique::Compute)): per caster and light a facing
    /// filter, the exact test of what it left undecided, and a caps-and-edges pass writing 16-bit indices and the indirect draw counts, then a barrier
    /// to the indirect draws and index reads. Nothing for other techniques. Idempotent per
    /// frame; also recorded by the first `cmd_determine` / `cmd_count_float` /
    /// `cmd_light_intensity` of the frame when the host did not call it (hosts drawing with
    /// [`cmd_draw_volumes`](Self::cmd_draw_volumes) inside their own rendering instance call it
    /// first, after [`cmd_upload`](Self::cmd_upload)).
    ///
    /// # Safety
    /// As [`cmd_upload`](Self::cmd_upload): `cb` is recording outside any rendering instance on
    /// the pass's device, after the frame's uploads (same or earlier command buffer, same
    /// queue), before every draw of the frame's volumes; `frame` is live.
    pub unsafe fn cmd_compute_silhouettes(&self, cb: vk::CommandBuffer, frame: &PreparedFrame) -> crate::error::Result<()> {
        self.check_frame(frame)?;
        let Some(cf) = frame.compute.as_ref() else { return Ok(()) };
        if cf.recorded.replace(true) || cf.jobs.iter().all(|j| j.is_empty()) {
            return Ok(());
        }
        let Some(cp) = self.compute_pipes.as_ref() else {
            return Err(crate::error::Misuse::NotConfigured {
                call: "cmd_compute_silhouettes",
                needs: "Technique::Compute on a device with compute silhouettes",
            }
            .into());
        };
        let d = &self.dev.device;
        use vk::AccessFlags2 as A;
        use vk::PipelineStageFlags2 as S;
        let rw = A::SHADER_READ | A::SHADER_WRITE;
        barrier(
            &self.dev,
            cb,
            (
                S::DRAW_INDIRECT | S::VERTEX_INPUT | S::COMPUTE_SHADER | S::TRANSFER,
                A::INDIRECT_COMMAND_READ | A::INDEX_READ | rw | A::TRANSFER_WRITE,
            ),
            (S::COMPUTE_SHADER, rw),
        );
        // SAFETY: the caller's contract; the pipelines, sets and buffers live until the slot
        // is prepared again.
        unsafe {
            d.cmd_bind_pipeline(cb, vk::PipelineBindPoint::COMPUTE, cp.facing);
            self.dispatch_all(cb, cf, cp.layout, |p| groups(p.tris));
        }
        barrier(&self.dev, cb, (S::COMPUTE_SHADER, A::SHADER_WRITE), (S::COMPUTE_SHADER, rw));
        // SAFETY: as above.
        unsafe {
            d.cmd_bind_pipeline(cb, vk::PipelineBindPoint::COMPUTE, cp.exact);
            // a few workgroups striding over the (usually empty) list
            self.dispatch_all(cb, cf, cp.layout, |p| groups(p.tris).min(EXACT_GROUPS));
        }
        barrier(&self.dev, cb, (S::COMPUTE_SHADER, A::SHADER_WRITE), (S::COMPUTE_SHADER, rw));
        // SAFETY: as above.
        unsafe {
            d.cmd_bind_pipeline(cb, vk::PipelineBindPoint::COMPUTE, cp.edges);
            self.dispatch_all(cb, cf, cp.layout, |p| groups(if p.caps != 0 { p.edges.max(p.tris) } else { p.edges }));
        }
        barrier(
            &self.dev,
            cb,
            (S::COMPUTE_SHADER, A::SHADER_WRITE),
            (S::DRAW_INDIRECT | S::VERTEX_INPUT | S::HOST, A::INDIRECT_COMMAND_READ | A::INDEX_READ | A::HOST_READ),
        );
        Ok(())
    }

    /// # Safety
    /// `cb` is recording outside a rendering instance with a compute pipeline of `layout` bound.
    unsafe fn dispatch_all(
        &self,
        cb: vk::CommandBuffer,
        cf: &ComputeFrame,
        layout: vk::PipelineLayout,
        count: impl Fn(&SilhouettePush) -> u32,
    ) {
        let d = &self.dev.device;
        let mut bound = None;
        for job in cf.jobs.iter().flatten() {
            let Some(set) = cf.set_of(job.caster) else { continue };
            let g = count(&job.push);
            if g == 0 {
                continue;
            }
            // SAFETY: the caller's contract; the set was written for this slot's buffers.
            unsafe {
                if bound != Some(set) {
                    d.cmd_bind_descriptor_sets(cb, vk::PipelineBindPoint::COMPUTE, layout, 0, &[set], &[]);
                    bound = Some(set);
                }
                d.cmd_push_constants(cb, layout, vk::ShaderStageFlags::COMPUTE, 0, bytemuck::bytes_of(&job.push));
                d.cmd_dispatch(cb, g, 1, 1);
            }
        }
    }
}
