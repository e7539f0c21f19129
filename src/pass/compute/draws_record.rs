//! [`Technique::Compute`](crate::pass::Technique::Compute)'s recording: one light's volumes
//! (the merged draws, or one indirect draw per GPU-silhouette record, and the planned lists
//! of the parts the planner leaves on the CPU), and the merged volume draws on the GPU
//! ([`super::draws`]): their pipelines (the volume pipelines' states with `shadow.vert`'s
//! TABLE variant, and the compaction stage), the slot's buffers and descriptor set and the
//! compaction dispatch.

use super::draw_pipes::CompactPush;
use super::draws::{pieces, Merged, COMMAND_BYTES, COMPACT_GROUP, LIST_HEADER, SIGN};
use super::HEADER_WORDS;
use crate::error::{Misuse, Result};
use crate::pass::desc::ComputeDraws;
use crate::pass::draw::LightFrame;
use crate::pass::frame::PreparedFrame;
use crate::pass::push::VolumePush;
use crate::pass::stencil::VolumeKind;
use crate::pass::volumes::{casters_for, Bound};
use crate::pass::ShadowPass;
use ash::vk;

impl ShadowPass {
    /// Records `lf`'s volumes for `kind`: the merged draws (the light's GPU-silhouette
    /// volumes in one draw call per pipeline) where the frame has them, else each record's
    /// indirect draw; and the planned draws of the parts left to the CPU.
    ///
    /// # Safety
    /// As [`cmd_draw_volumes`](Self::cmd_draw_volumes), which checked the frame, the light and
    /// that `kind` has pipelines; the silhouette stages were recorded
    /// ([`cmd_before_rendering`](Self::cmd_before_rendering)).
    pub(in crate::pass) unsafe fn record_compute_light(
        &self,
        cb: vk::CommandBuffer,
        frame: &PreparedFrame,
        lf: &LightFrame,
        light: usize,
        kind: VolumeKind,
        bound: &mut Bound,
    ) -> Result<()> {
        // SAFETY: the caller's contract.
        unsafe { self.record_merged(cb, frame, light, kind)? };
        let merged = frame.compute.as_ref().is_some_and(|cf| cf.merged.is_some());
        for c in casters_for(lf, kind) {
            for dr in c.draws.iter().filter(|dr| !(dr.indirect && merged)) {
                // SAFETY: the caller's contract.
                unsafe { self.record_planned_draw(cb, frame, kind, c, dr, bound) };
            }
        }
        Ok(())
    }

    /// Records the merged draws' compaction (`shaders/compact_draws.wgsl`), after the
    /// silhouette stages and their barrier; the caller records the barrier to the draws. The
    /// lists were cleared by [`cmd_clear_draw_lists`](Self::cmd_clear_draw_lists).
    ///
    /// # Safety
    /// `cb` is recording outside any rendering instance; `m` is the frame's, whose set and
    /// buffers live until its slot is prepared again.
    pub(crate) unsafe fn cmd_compact_draws(&self, cb: vk::CommandBuffer, m: &Merged) -> Result<()> {
        if !m.compacts() {
            return Ok(());
        }
        let Some(dp) = self.techniques.compute.merged.as_ref() else {
            return Err(Misuse::NotConfigured { call: "cmd_compute_silhouettes", needs: "the merged draws' pipelines" }.into());
        };
        let d = &self.dev.device;
        let push = CompactPush { records: m.chunk_records, first: HEADER_WORDS as u32, pad: [0; 2] };
        let groups = push.records.div_ceil(COMPACT_GROUP);
        // SAFETY: the caller's contract; the set binds the frame's records and lists.
        unsafe {
            d.cmd_bind_pipeline(cb, vk::PipelineBindPoint::COMPUTE, dp.compact);
            d.cmd_bind_descriptor_sets(cb, vk::PipelineBindPoint::COMPUTE, dp.layout, 0, &[m.handles.set], &[]);
            d.cmd_push_constants(cb, dp.layout, vk::ShaderStageFlags::COMPUTE, 0, bytemuck::bytes_of(&push));
            d.cmd_dispatch(cb, groups.min(super::MAX_GROUPS), groups.div_ceil(super::MAX_GROUPS), 1);
        }
        Ok(())
    }

    /// Clears the frame's lists (counts 0, every command empty) before the compaction.
    ///
    /// # Safety
    /// As [`cmd_compact_draws`](Self::cmd_compact_draws); the caller orders the fill after
    /// earlier reads of the lists and before the compaction.
    pub(crate) unsafe fn cmd_clear_draw_lists(&self, cb: vk::CommandBuffer, m: &Merged) {
        if m.compacts() {
            // SAFETY: the caller's contract.
            unsafe { self.dev.device.cmd_fill_buffer(cb, m.handles.lists, 0, m.list_words * 4, 0) };
        }
    }

    /// Records light `light`'s merged draws for `kind` inside the caller's rendering instance
    /// (nothing for a frame without merged draws, or for `Transmit`: the compute path's
    /// casters are opaque). It binds its own pipelines and vertex buffers (the caller binds
    /// again for what it draws next).
    ///
    /// # Safety
    /// As [`cmd_draw_volumes`](Self::cmd_draw_volumes), which checked the frame, the light and
    /// that `kind` has pipelines.
    pub(in crate::pass) unsafe fn record_merged(
        &self,
        cb: vk::CommandBuffer,
        frame: &PreparedFrame,
        light: usize,
        kind: VolumeKind,
    ) -> Result<()> {
        let Some((cf, m)) = frame.compute.as_ref().and_then(|cf| cf.merged.as_ref().map(|m| (cf, m))) else { return Ok(()) };
        let Some(dp) = self.techniques.compute.merged.as_ref() else {
            return Err(Misuse::NotConfigured { call: "cmd_draw_volumes (merged draws)", needs: "the merged draws' pipelines" }.into());
        };
        let count = || dp.count.ok_or(Misuse::NotConfigured { call: "cmd_draw_volumes (float kinds)", needs: "R32_SFLOAT blending" });
        let pipes = match kind {
            VolumeKind::Stencil => dp.stencil,
            VolumeKind::Float => count()?,
            // self-shadowing: the light caps depth-tested like the rest
            VolumeKind::FloatDepthTested => count().map(|c| [c[0], c[1], c[1]])?,
            VolumeKind::Rasterised => [dp.raster; 3],
            VolumeKind::Transmit { .. } => return Ok(()),
        };
        let (lists, records) = (m.lists.get(light), m.records.get(light));
        let drawn = |p: usize| match m.mode {
            ComputeDraws::Count | ComputeDraws::Multi => lists.is_some_and(|l| l[p].is_some()),
            _ => records.is_some_and(|r| !r[p].is_empty()),
        };
        if !(0..3).any(drawn) {
            return Ok(());
        }
        let d = &self.dev.device;
        let h = &m.handles;
        // SAFETY: the caller's contract; the buffers live until the frame's slot is prepared
        // again, and the compute pass's barrier made the records, lists and indices visible.
        unsafe {
            d.cmd_bind_vertex_buffers(cb, 0, &[h.vertices, h.xforms], &[0, 0]);
            d.cmd_bind_index_buffer(cb, cf.out_buffer, 0, vk::IndexType::UINT16);
        }
        for p in (0..3).filter(|&p| drawn(p)) {
            let push = VolumePush::new(glam::Mat4::IDENTITY, glam::Vec4::ZERO, [SIGN[p], 0.0, 0.0, 0.0]);
            // SAFETY: as above; the push block matches the layout's range.
            unsafe {
                d.cmd_bind_pipeline(cb, vk::PipelineBindPoint::GRAPHICS, pipes[p]);
                d.cmd_push_constants(
                    cb,
                    self.pipes.layout,
                    vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT,
                    0,
                    bytemuck::bytes_of(&push),
                );
            }
            match (m.mode, lists.and_then(|l| l[p])) {
                (ComputeDraws::Count | ComputeDraws::Multi, Some(list)) => {
                    let count_at = list.word as u64 * 4;
                    let first = (list.word + LIST_HEADER) as u64 * 4;
                    for k in 0..pieces(list.capacity, m.max_draws) {
                        let start = k * m.max_draws;
                        let n = (list.capacity - start).min(m.max_draws);
                        let at = first + start as u64 * COMMAND_BYTES as u64;
                        // SAFETY: as above. A piece past the GPU's count draws the cleared
                        // (empty) commands or, with the count, nothing.
                        unsafe {
                            match m.mode {
                                ComputeDraws::Count => {
                                    d.cmd_draw_indexed_indirect_count(cb, h.lists, at, h.lists, count_at, n, COMMAND_BYTES)
                                }
                                _ => d.cmd_draw_indexed_indirect(cb, h.lists, at, n, COMMAND_BYTES),
                            }
                        }
                    }
                }
                _ => {
                    for &at in records.map(|r| r[p].as_slice()).unwrap_or_default() {
                        // SAFETY: as above.
                        unsafe { d.cmd_draw_indexed_indirect(cb, cf.records_buffer, at, 1, COMMAND_BYTES) };
                    }
                }
            }
        }
        Ok(())
    }
}
