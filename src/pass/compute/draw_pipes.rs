//! The merged draws' objects: their pipelines (made once), and each frame's transform table,
//! lists and compaction set in its ring slot. Recording them is [`super::draws_record`].

use super::draws::{Merged, Xform};
use super::SlotCompute;
use crate::error::{Error, Result};
use crate::gpu::descriptors::{pipeline_layout, storage_set_layout};
use crate::gpu::{pipeline, shaders};
use crate::pass::desc::{DepthMode, ShadowPassDesc, TargetModel};
use crate::pass::device::PassDevice;
use crate::pass::pipelines::{create_volume_pipeline, volume_states};
use ash::vk;
use gpu_allocator::MemoryLocation;

/// The compaction stage's push block (`shaders/compact_draws.wgsl`'s `Push`).
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub(super) struct CompactPush {
    pub records: u32,
    pub first: u32,
    pub pad: [u32; 2],
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
