//! The readback of every sample: a compute shader ([`super::shaders::EXTRACT_WGSL`]) reads the
//! depth, the stencil, the lighting pass's lit bit and the pre-pass's normal of one sample of
//! every pixel into the slot's readback buffer. With one sample it is the same shader on
//! single-sample views, so every configuration reads back the same way.

use super::pipelines::shader_module;
use super::shaders;
use super::vulkan::vkerr;
use ash::vk;

/// Push block of the extraction shader (six u32).
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
pub(super) struct ExtractPush {
    pub(super) sample: u32,
    pub(super) width: u32,
    pub(super) height: u32,
    pub(super) geometry: u32,
    pub(super) geometry_at: u32,
    pub(super) packed_at: u32,
}

/// The views the shader reads (layouts: DEPTH_STENCIL_READ_ONLY_OPTIMAL for the depth and
/// stencil aspects, SHADER_READ_ONLY_OPTIMAL for the colour targets).
pub(super) struct Views {
    pub(super) depth: vk::ImageView,
    pub(super) stencil: vk::ImageView,
    pub(super) lit: vk::ImageView,
    pub(super) normal: vk::ImageView,
}

/// The compute pipeline, its layout and one descriptor set per ring slot.
pub(super) struct Extract {
    pub(super) set_layout: vk::DescriptorSetLayout,
    pub(super) layout: vk::PipelineLayout,
    pub(super) pipeline: vk::Pipeline,
    pub(super) pool: vk::DescriptorPool,
    pub(super) sets: Vec<vk::DescriptorSet>,
}

impl Extract {
    /// Creates the pipeline for `samples` samples and a set per readback buffer in `buffers`.
    /// On error, what was created is in `self` (destroy it with [`Extract::destroy`]).
    pub(super) fn create(&mut self, device: &ash::Device, samples: u32, views: &Views, buffers: &[vk::Buffer]) -> Result<(), String> {
        let words = shaders::compile(&shaders::extract_source(samples))?;
        let image = |binding| {
            vk::DescriptorSetLayoutBinding::default()
                .binding(binding)
                .descriptor_type(vk::DescriptorType::SAMPLED_IMAGE)
                .descriptor_count(1)
                .stage_flags(vk::ShaderStageFlags::COMPUTE)
        };
        let bindings = [
            image(0),
            image(1),
            image(2),
            image(3),
            vk::DescriptorSetLayoutBinding::default()
                .binding(4)
                .descriptor_type(vk::DescriptorType::STORAGE_BUFFER)
                .descriptor_count(1)
                .stage_flags(vk::ShaderStageFlags::COMPUTE),
        ];
        let push = [vk::PushConstantRange {
            stage_flags: vk::ShaderStageFlags::COMPUTE,
            offset: 0,
            size: std::mem::size_of::<ExtractPush>() as u32,
        }];
        let n = buffers.len() as u32;
        let sizes = [
            vk::DescriptorPoolSize { ty: vk::DescriptorType::SAMPLED_IMAGE, descriptor_count: 4 * n },
            vk::DescriptorPoolSize { ty: vk::DescriptorType::STORAGE_BUFFER, descriptor_count: n },
        ];
        // SAFETY: object creation on a valid device with well-formed create infos; each object
        // is stored in `self` at once, so `destroy` frees it whatever fails later.
        unsafe {
            self.set_layout = device
                .create_descriptor_set_layout(&vk::DescriptorSetLayoutCreateInfo::default().bindings(&bindings), None)
                .map_err(vkerr("vkCreateDescriptorSetLayout"))?;
            let set_layouts = [self.set_layout];
            self.layout = device
                .create_pipeline_layout(
                    &vk::PipelineLayoutCreateInfo::default().set_layouts(&set_layouts).push_constant_ranges(&push),
                    None,
                )
                .map_err(vkerr("vkCreatePipelineLayout"))?;
            let module = shader_module(device, &words)?;
            let stage = vk::PipelineShaderStageCreateInfo::default().stage(vk::ShaderStageFlags::COMPUTE).module(module).name(c"main");
            let info = vk::ComputePipelineCreateInfo::default().stage(stage).layout(self.layout);
            let pipeline = device.create_compute_pipelines(vk::PipelineCache::null(), &[info], None);
            device.destroy_shader_module(module, None);
            self.pipeline = pipeline.map_err(|(_, e)| format!("vkCreateComputePipelines failed: {e:?}"))?[0];
            self.pool = device
                .create_descriptor_pool(&vk::DescriptorPoolCreateInfo::default().max_sets(n).pool_sizes(&sizes), None)
                .map_err(vkerr("vkCreateDescriptorPool"))?;
            let layouts = vec![self.set_layout; buffers.len()];
            self.sets = device
                .allocate_descriptor_sets(&vk::DescriptorSetAllocateInfo::default().descriptor_pool(self.pool).set_layouts(&layouts))
                .map_err(vkerr("vkAllocateDescriptorSets"))?;
        }
        let ds_read = vk::ImageLayout::DEPTH_STENCIL_READ_ONLY_OPTIMAL;
        let shader_read = vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL;
        for (&set, &buffer) in self.sets.iter().zip(buffers) {
            let infos: Vec<[vk::DescriptorImageInfo; 1]> =
                [(views.depth, ds_read), (views.stencil, ds_read), (views.lit, shader_read), (views.normal, shader_read)]
                    .into_iter()
                    .map(|(view, layout)| [vk::DescriptorImageInfo::default().image_view(view).image_layout(layout)])
                    .collect();
            let buffer_info = [vk::DescriptorBufferInfo { buffer, offset: 0, range: vk::WHOLE_SIZE }];
            let mut writes: Vec<vk::WriteDescriptorSet> = infos
                .iter()
                .enumerate()
                .map(|(b, info)| {
                    vk::WriteDescriptorSet::default()
                        .dst_set(set)
                        .dst_binding(b as u32)
                        .descriptor_type(vk::DescriptorType::SAMPLED_IMAGE)
                        .image_info(info)
                })
                .collect();
            writes.push(
                vk::WriteDescriptorSet::default()
                    .dst_set(set)
                    .dst_binding(4)
                    .descriptor_type(vk::DescriptorType::STORAGE_BUFFER)
                    .buffer_info(&buffer_info),
            );
            // SAFETY: the set, views and buffer are live objects of this device; no command
            // buffer using the set is pending (none was recorded yet).
            unsafe { device.update_descriptor_sets(&writes, &[]) };
        }
        Ok(())
    }

    /// Records one sample's readback (see [`ExtractPush`]) with `slot`'s set.
    ///
    /// # Safety
    /// `cb` is recording outside any render pass; the views are in the layouts [`Views`]
    /// names, their writes made visible to compute shader reads.
    pub(super) unsafe fn record(&self, device: &ash::Device, cb: vk::CommandBuffer, slot: usize, push: ExtractPush) {
        // SAFETY: the caller's contract; the push block matches the layout's range.
        unsafe {
            device.cmd_bind_pipeline(cb, vk::PipelineBindPoint::COMPUTE, self.pipeline);
            device.cmd_bind_descriptor_sets(cb, vk::PipelineBindPoint::COMPUTE, self.layout, 0, &[self.sets[slot]], &[]);
            device.cmd_push_constants(cb, self.layout, vk::ShaderStageFlags::COMPUTE, 0, bytemuck::bytes_of(&push));
            device.cmd_dispatch(cb, push.width.div_ceil(8), push.height.div_ceil(8), 1);
        }
    }

    /// Destroys what exists.
    ///
    /// # Safety
    /// No pending command buffer uses the pipeline or the sets.
    pub(super) unsafe fn destroy(&mut self, device: &ash::Device) {
        // SAFETY: the caller's contract; null handles are skipped by Vulkan's destroy calls.
        unsafe {
            device.destroy_pipeline(self.pipeline, None);
            device.destroy_descriptor_pool(self.pool, None); // frees the sets
            device.destroy_pipeline_layout(self.layout, None);
            device.destroy_descriptor_set_layout(self.set_layout, None);
        }
        *self = Extract::default();
    }
}

impl Default for Extract {
    fn default() -> Extract {
        Extract {
            set_layout: vk::DescriptorSetLayout::null(),
            layout: vk::PipelineLayout::null(),
            pipeline: vk::Pipeline::null(),
            pool: vk::DescriptorPool::null(),
            sets: Vec::new(),
        }
    }
}
