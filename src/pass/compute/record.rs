//! Recording the compute pass: outside any rendering instance, before the frame's first volume
//! draw, for every light at once (each light has its own records and regions, so the volume
//! overlay and later passes can draw any light's volumes again).
//!
//! Barriers (global memory barriers):
//! 1. earlier indirect, index and compute accesses (a previous frame on the queue) and the
//!    caster uploads -> compute reads and writes;
//! 2. between the stages (facing | exact | find and caps): compute writes -> compute reads
//!    and atomics, and the indirect dispatch read of the exact list's size;
//! 3. with the merged draws' compaction ([`super::draws`]): the `find` and `caps` stages'
//!    writes -> its reads;
//! 4. the compute writes -> indirect-command reads, index reads, and host reads (the counts
//!    `--stats` reads back after the fence): the one barrier between the compute and the
//!    draws.

use super::super::ShadowPass;
use super::{rec, LANES};
use crate::pass::frame::PreparedFrame;
use ash::vk;

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
    /// ([`Technique::Compute`](crate::pass::Technique::Compute)): four dispatches for every
    /// (light, caster) pair at once, whatever their number: the facing bits (whole 64-triangle
    /// blocks where their bound decides them, else the plane filter), the exact test of what
    /// it left undecided, the possible silhouette edges with their sides (skipping whole
    /// word-pair groups of uniform blocks) and the face caps, writing 16-bit indices and the
    /// indirect draw counts (and with the merged draws' lists of
    /// [`PassToggles::compute_draws`](crate::pass::PassToggles::compute_draws), a fifth: their
    /// compaction); then one barrier to the indirect draws and index reads. Nothing for other
    /// techniques. Idempotent per frame; also recorded by the first `cmd_determine` /
    /// `cmd_count_float` / `cmd_light_intensity` of the frame when the host did not call it
    /// (hosts drawing with [`cmd_draw_volumes`](Self::cmd_draw_volumes) inside their own
    /// rendering instance call it first, after [`cmd_upload`](Self::cmd_upload)).
    ///
    /// # Safety
    /// As [`cmd_upload`](Self::cmd_upload): `cb` is recording outside any rendering instance on
    /// the pass's device, after the frame's uploads (same or earlier command buffer, same
    /// queue), before every draw of the frame's volumes; `frame` is live.
    pub unsafe fn cmd_compute_silhouettes(&self, cb: vk::CommandBuffer, frame: &PreparedFrame) -> crate::error::Result<()> {
        self.check_frame(frame)?;
        let Some(cf) = frame.compute.as_ref() else { return Ok(()) };
        if cf.recorded.replace(true) || cf.jobs.is_empty() {
            return Ok(());
        }
        let Some(cp) = self.techniques.compute.pipes.as_ref() else {
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
        // Mesh frames: the mesh draws read the facing bits and write their counters (a
        // previous frame's mesh draws may still read the bits this frame rewrites).
        let mesh = self.mesh_stages();
        // compute writes -> the next stage's reads, atomics and indirect dispatch
        let to_next = |this: &Self| {
            barrier(
                &this.dev,
                cb,
                (S::COMPUTE_SHADER, A::SHADER_WRITE),
                (S::COMPUTE_SHADER | S::DRAW_INDIRECT, rw | A::INDIRECT_COMMAND_READ),
            )
        };
        barrier(
            &self.dev,
            cb,
            (
                S::DRAW_INDIRECT | S::VERTEX_INPUT | S::COMPUTE_SHADER | S::TRANSFER | mesh,
                A::INDIRECT_COMMAND_READ | A::INDEX_READ | rw | A::TRANSFER_WRITE,
            ),
            (S::COMPUTE_SHADER | S::TRANSFER, rw | A::TRANSFER_WRITE),
        );
        let [facing, exact, find, caps] = cp.stages;
        let push = cf.push();
        let records = cf.records_buffer;
        // SAFETY: the caller's contract; the pipelines, the set and its buffers live until the
        // slot is prepared again; the set binds the frame's buffers and the arena's tables.
        // (The facing bits need no clearing: the `facing` stage writes every word whole.)
        unsafe {
            if cf.mesh {
                // the mesh draws' counters start at zero (read by the mesh draws only: the
                // last barrier orders them)
                d.cmd_fill_buffer(cb, cf.counts_buffer, 0, (cf.counts_words * 4).max(4), 0);
            }
            // the merged draws' lists start empty (counts 0, every command empty)
            if let Some(m) = &cf.merged {
                self.cmd_clear_draw_lists(cb, m);
            }
        }
        // (the merged draws read the cleared tail of their lists as empty commands)
        barrier(&self.dev, cb, (S::TRANSFER, A::TRANSFER_WRITE), (S::COMPUTE_SHADER | S::DRAW_INDIRECT, rw | A::INDIRECT_COMMAND_READ));
        // SAFETY: as above.
        unsafe {
            d.cmd_bind_descriptor_sets(cb, vk::PipelineBindPoint::COMPUTE, cp.layout, 0, &[cf.set], &[]);
            d.cmd_push_constants(cb, cp.layout, vk::ShaderStageFlags::COMPUTE, 0, bytemuck::bytes_of(&push));
            d.cmd_bind_pipeline(cb, vk::PipelineBindPoint::COMPUTE, facing);
            dispatch_groups(d, cb, cf.groups[0].div_ceil(LANES));
            to_next(self);
            d.cmd_bind_pipeline(cb, vk::PipelineBindPoint::COMPUTE, exact);
            d.cmd_dispatch_indirect(cb, records, (rec::H_EXACT_X * 4) as u64);
        }
        if cf.mesh {
            // The facing bits are all the mesh draws need; the counters' fill too.
            barrier(
                &self.dev,
                cb,
                (S::COMPUTE_SHADER | S::TRANSFER, A::SHADER_WRITE | A::TRANSFER_WRITE),
                (mesh | S::HOST, A::SHADER_READ | A::SHADER_WRITE | A::HOST_READ),
            );
            return Ok(());
        }
        // SAFETY: as above.
        unsafe {
            to_next(self);
            d.cmd_bind_pipeline(cb, vk::PipelineBindPoint::COMPUTE, find);
            dispatch_groups(d, cb, cf.groups[1].div_ceil(LANES));
            if cf.groups[2] > 0 {
                d.cmd_bind_pipeline(cb, vk::PipelineBindPoint::COMPUTE, caps);
                dispatch_groups(d, cb, cf.groups[2]);
            }
        }
        // The merged draws: every non-empty command into its light and pipeline's list.
        if let Some(m) = cf.merged.as_ref().filter(|m| m.compacts()) {
            to_next(self);
            // SAFETY: as above; the lists were cleared above, the records' counts are final.
            unsafe { self.cmd_compact_draws(cb, m)? };
        }
        barrier(
            &self.dev,
            cb,
            (S::COMPUTE_SHADER, A::SHADER_WRITE),
            (S::DRAW_INDIRECT | S::VERTEX_INPUT | S::HOST, A::INDIRECT_COMMAND_READ | A::INDEX_READ | A::HOST_READ),
        );
        Ok(())
    }
}

/// Dispatches `n` workgroups as `(min(n, 65535), ceil(n / 65535))` (the shader's linear
/// workgroup index skips the last row's extras).
///
/// # Safety
/// `cb` is recording outside a rendering instance with a compute pipeline bound.
unsafe fn dispatch_groups(d: &ash::Device, cb: vk::CommandBuffer, n: u32) {
    if n == 0 {
        return;
    }
    // SAFETY: the caller's contract.
    unsafe { d.cmd_dispatch(cb, n.min(super::MAX_GROUPS), n.div_ceil(super::MAX_GROUPS), 1) };
}
