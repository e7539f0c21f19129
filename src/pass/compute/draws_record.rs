//! The merged volume draws on the GPU ([`super::draws`]): their pipelines (the volume
//! pipelines' states with `shadow.vert`'s TABLE variant, and the compaction stage), the
//! slot's buffers and descriptor set, the compaction dispatch, and one light's draws.

use super::draws::{pieces, Merged, Xform, COMMAND_BYTES, COMPACT_GROUP, LIST_HEADER, SIGN};
use super::{SlotCompute, HEADER_WORDS};
use crate::error::{Error, Misuse, Result};
use crate::gpu::descriptors::{pipeline_layout, storage_set_layout};
use crate::gpu::{pipeline, shaders};
use crate::pass::desc::{ComputeDraws, DepthMode, ShadowPassDesc, TargetModel};
use crate::pass::device::PassDevice;
use crate::pass::pipelines::{create_volume_pipeline, volume_states};
use crate::pass::push::VolumePush;
use crate::pass::{PreparedFrame, ShadowPass, VolumeKind};
use ash::vk;
use gpu_allocator::MemoryLocation;

/// The compaction stage's push block (`shaders/compact_draws.wgsl`'s `Push`).
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
struct CompactPush {
    records: u32,
    first: u32,
    pad: [u32; 2],
}

/// The merged draws' pipelines: per volume pipeline of the pass (stencil z-pass, z-fail and
/// light caps; the float counter's three; the counting variant) the same state with
/// `shadow.vert`'s TABLE variant (the transforms as per-instance attributes, binding 1), in
/// the pass's pipeline layout (its push block: the float counter's sign); and the compaction
/// stage with its set layout (the records, the lists) and layout.
pub(crate) struct DrawPipes {
    pub set_layout: vk::DescriptorSetLayout,
    pub layout: vk::PipelineLayout,
    pub compact: vk::Pipeline,
    /// z-pass, z-fail, light caps.
    pub stencil: [vk::Pipeline; 3],
    /// The float counter's z-pass, z-fail, light caps (where the pass has a float counter).
    pub count: Option<[vk::Pipeline; 3]>,
    pub raster: vk::Pipeline,
}

impl DrawPipes {
    /// The pipelines for a pass made with `desc`, whose volume pipelines use `volume_layout`;
    /// `(depth clamp, depth bounds, R32F blending)` as the pass's capabilities have them.
    pub fn new(dev: &PassDevice, desc: &ShadowPassDesc, volume_layout: vk::PipelineLayout, caps: (bool, bool, bool)) -> Result<DrawPipes> {
        let mut me = DrawPipes {
            set_layout: vk::DescriptorSetLayout::null(),
            layout: vk::PipelineLayout::null(),
            compact: vk::Pipeline::null(),
            stencil: [vk::Pipeline::null(); 3],
            count: None,
            raster: vk::Pipeline::null(),
        };
        match me.create(dev, desc, volume_layout, caps) {
            Ok(()) => Ok(me),
            Err(e) => {
                // SAFETY: nothing created here was used yet; null handles are ignored.
                unsafe { me.destroy(&dev.device) };
                Err(e)
            }
        }
    }

    fn create(
        &mut self,
        dev: &PassDevice,
        desc: &ShadowPassDesc,
        volume_layout: vk::PipelineLayout,
        caps: (bool, bool, bool),
    ) -> Result<()> {
        let (depth_clamp, depth_bounds, r32f_blend) = caps;
        let clamp = depth_clamp && desc.depth_mode == DepthMode::Clamp;
        let v = volume_states(
            shaders::SHADOW_TABLE_VERT,
            (Xform::SIZE, &Xform::ATTRIBUTES),
            volume_layout,
            desc.depth_stencil_format,
            clamp,
            depth_bounds,
        );
        for (k, d) in v.stencil.iter().enumerate() {
            self.stencil[k] = create_volume_pipeline(dev, desc, d)?;
        }
        self.raster = create_volume_pipeline(dev, desc, &v.raster)?;
        // The float counter draws into a colour target of its own rendering instance.
        if r32f_blend && desc.target == TargetModel::DynamicRendering {
            let mut count = [vk::Pipeline::null(); 3];
            for (k, d) in v.count.iter().enumerate() {
                match create_volume_pipeline(dev, desc, d) {
                    Ok(p) => count[k] = p,
                    Err(e) => {
                        self.count = Some(count);
                        return Err(e);
                    }
                }
            }
            self.count = Some(count);
        }
        let d = &dev.device;
        // destroyed in `destroy`
        self.set_layout = storage_set_layout(dev, 2, vk::ShaderStageFlags::COMPUTE)?;
        let push = std::mem::size_of::<CompactPush>() as u32;
        self.layout = pipeline_layout(dev, &[self.set_layout], push, vk::ShaderStageFlags::COMPUTE)?;
        let module = pipeline::shader_module(dev, shaders::COMPACT_DRAWS_WGSL)?;
        let stage = vk::PipelineShaderStageCreateInfo::default().stage(vk::ShaderStageFlags::COMPUTE).module(module).name(c"compact");
        let info = [vk::ComputePipelineCreateInfo::default().stage(stage).layout(self.layout)];
        let made = crate::gpu::creation::timed(
            || "compact_draws.wgsl:compact".to_string(),
            || {
                // SAFETY: valid device, module and layout; the create info points at locals.
                unsafe { d.create_compute_pipelines(dev.pipeline_cache, &info, None) }
                    .map(|p| p[0])
                    .map_err(|(_, e)| Error::vk("vkCreateComputePipelines")(e))
            },
        );
        // SAFETY: the pipeline keeps what it needs of the module.
        unsafe { d.destroy_shader_module(module, None) };
        self.compact = made?;
        Ok(())
    }

    /// # Safety
    /// No pending command buffer uses the pipelines.
    pub unsafe fn destroy(&mut self, d: &ash::Device) {
        // SAFETY: the caller's contract; null handles are ignored.
        unsafe {
            for p in self.stencil.into_iter().chain(self.count.into_iter().flatten()).chain([self.raster, self.compact]) {
                d.destroy_pipeline(p, None);
            }
            d.destroy_pipeline_layout(self.layout, None);
            d.destroy_descriptor_set_layout(self.set_layout, None);
        }
    }
}

/// The buffers and handles of a frame's merged draws in ring slot `slot`'s `sc`: the transform
/// table (written), and where the frame compacts, the lists and the compaction stage's set
/// (allocated from the slot's pool, which has room for it) binding `records` (the records
/// buffer and its bound range) and the lists.
pub(crate) struct MergedBuffers<'a> {
    pub xforms: &'a [Xform],
    pub records: (vk::Buffer, u64),
    /// The arena's vertex table.
    pub vertices: vk::Buffer,
    pub set_layout: vk::DescriptorSetLayout,
}

/// Prepares `m`'s buffers and set (see [`MergedBuffers`]) in `sc`, ring slot `slot`.
pub(crate) fn prepare_merged(dev: &PassDevice, sc: &mut SlotCompute, slot: usize, m: &mut Merged, b: MergedBuffers) -> Result<()> {
    let bytes = std::mem::size_of_val(b.xforms) as u64;
    let usage = vk::BufferUsageFlags::VERTEX_BUFFER;
    SlotCompute::ensure(dev, &mut sc.xforms, &format!("compute transforms {slot}"), bytes.max(16), usage, MemoryLocation::CpuToGpu)?;
    let xforms = sc.xforms.as_mut().ok_or_else(|| Error::Internal("compute transforms missing".into()))?;
    xforms.write(0, bytemuck::cast_slice(b.xforms))?;
    m.handles.xforms = xforms.raw;
    m.handles.vertices = b.vertices;
    if !m.compacts() {
        return Ok(());
    }
    let range = (m.list_words * 4).max(16);
    if range > dev.max_storage_range {
        return Err(Error::Unsupported(format!(
            "Technique::Compute: the frame's merged draw lists need {range} bytes, more than the device's maxStorageBufferRange \
             ({} bytes); use ComputeDraws::PerRecord, or fewer lights or casters",
            dev.max_storage_range
        )));
    }
    let usage = vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::INDIRECT_BUFFER | vk::BufferUsageFlags::TRANSFER_DST;
    SlotCompute::ensure(dev, &mut sc.draw_lists, &format!("compute draw lists {slot}"), range, usage, MemoryLocation::GpuOnly)?;
    let lists = sc.draw_lists.as_ref().ok_or_else(|| Error::Internal("compute draw lists missing".into()))?.raw;
    let d = &dev.device;
    // SAFETY: the pool was reset for the frame with room for this set; the slot's previous
    // frame (the only user of its sets) has retired.
    let sets = unsafe {
        d.allocate_descriptor_sets(&vk::DescriptorSetAllocateInfo::default().descriptor_pool(sc.pool).set_layouts(&[b.set_layout]))
    }
    .map_err(Error::vk("vkAllocateDescriptorSets"))?;
    let infos = [
        [vk::DescriptorBufferInfo { buffer: b.records.0, offset: 0, range: b.records.1 }],
        [vk::DescriptorBufferInfo { buffer: lists, offset: 0, range }],
    ];
    let writes = crate::gpu::descriptors::storage_buffer_writes(sets[0], &infos);
    // SAFETY: the set is not in use (just allocated); the buffers are alive.
    unsafe { d.update_descriptor_sets(&writes, &[]) };
    m.handles.lists = lists;
    m.handles.set = sets[0];
    Ok(())
}

impl ShadowPass {
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
            d.cmd_dispatch(cb, groups.min(super::record::MAX_GROUPS), groups.div_ceil(super::record::MAX_GROUPS), 1);
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
