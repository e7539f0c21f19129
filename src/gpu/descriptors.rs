//! One-shot descriptor sets for full-screen passes: a layout, an exactly-sized pool and one set,
//! written once (images in SHADER_READ_ONLY_OPTIMAL, samplers, top-level acceleration
//! structures, read-only storage buffers; fragment stage).

use super::context::GpuDevice;
use crate::error::{Error, Result};
use ash::vk;

fn vkerr(call: &'static str) -> impl Fn(vk::Result) -> Error {
    Error::vk(call)
}

/// What a binding holds, in binding order.
#[derive(Clone, Copy)]
pub enum Binding {
    /// A `SAMPLED_IMAGE` (GLSL `texture2D`): the view must be in `SHADER_READ_ONLY_OPTIMAL`
    /// whenever the set is used.
    Image(vk::ImageView),
    /// A `SAMPLER` (GLSL `sampler`).
    Sampler(vk::Sampler),
    /// An `ACCELERATION_STRUCTURE_KHR` (WGSL `acceleration_structure`): a top level that
    /// must be built whenever the set is used.
    AccelerationStructure(vk::AccelerationStructureKHR),
    /// A read-only `STORAGE_BUFFER`, the whole buffer.
    StorageBuffer(vk::Buffer),
}

/// A descriptor set layout with one set allocated from its own pool; binding `i` is the `i`-th
/// [`Binding`] given to [`DescriptorSet::new`], one descriptor each, visible to the fragment stage
/// (or the stages given to [`DescriptorSet::with_stages`]).
/// Not freed on drop: call [`DescriptorSet::destroy`].
pub struct DescriptorSet {
    /// The set's layout, for [`pipeline_layout`].
    pub layout: vk::DescriptorSetLayout,
    /// The set, written once at creation.
    pub set: vk::DescriptorSet,
    pool: vk::DescriptorPool,
}

impl DescriptorSet {
    /// Creates the layout, a pool sized for exactly this one set, allocates the set and writes
    /// `bindings` into it. The views and samplers are not owned: they must outlive every use
    /// of the set (and are not destroyed by [`DescriptorSet::destroy`]).
    pub fn new(ctx: &impl GpuDevice, bindings: &[Binding]) -> Result<DescriptorSet> {
        DescriptorSet::with_stages(ctx, bindings, vk::ShaderStageFlags::FRAGMENT)
    }

    /// [`DescriptorSet::new`] with every binding visible to `stages` instead of the fragment
    /// stage alone.
    pub fn with_stages(ctx: &impl GpuDevice, bindings: &[Binding], stages: vk::ShaderStageFlags) -> Result<DescriptorSet> {
        let ty = |b: &Binding| match b {
            Binding::Image(_) => vk::DescriptorType::SAMPLED_IMAGE,
            Binding::Sampler(_) => vk::DescriptorType::SAMPLER,
            Binding::AccelerationStructure(_) => vk::DescriptorType::ACCELERATION_STRUCTURE_KHR,
            Binding::StorageBuffer(_) => vk::DescriptorType::STORAGE_BUFFER,
        };
        let layout_bindings: Vec<_> = bindings
            .iter()
            .enumerate()
            .map(|(i, b)| {
                vk::DescriptorSetLayoutBinding::default().binding(i as u32).descriptor_type(ty(b)).descriptor_count(1).stage_flags(stages)
            })
            .collect();
        let count = |t: vk::DescriptorType| bindings.iter().filter(|b| ty(b) == t).count() as u32;
        let sizes: Vec<_> = [
            vk::DescriptorType::SAMPLED_IMAGE,
            vk::DescriptorType::SAMPLER,
            vk::DescriptorType::ACCELERATION_STRUCTURE_KHR,
            vk::DescriptorType::STORAGE_BUFFER,
        ]
        .into_iter()
        .map(|t| (t, count(t)))
        .filter(|&(_, n)| n > 0)
        .map(|(ty, descriptor_count)| vk::DescriptorPoolSize { ty, descriptor_count })
        .collect();
        let d = ctx.device();
        // SAFETY: creation on a valid device with create infos built from locals; the objects
        // are destroyed in `destroy` (pool before layout, the set with its pool).
        unsafe {
            let layout = d
                .create_descriptor_set_layout(&vk::DescriptorSetLayoutCreateInfo::default().bindings(&layout_bindings), None)
                .map_err(vkerr("vkCreateDescriptorSetLayout"))?;
            let pool = d
                .create_descriptor_pool(&vk::DescriptorPoolCreateInfo::default().max_sets(1).pool_sizes(&sizes), None)
                .map_err(vkerr("vkCreateDescriptorPool"))?;
            let layouts = [layout];
            let set = d
                .allocate_descriptor_sets(&vk::DescriptorSetAllocateInfo::default().descriptor_pool(pool).set_layouts(&layouts))
                .map_err(vkerr("vkAllocateDescriptorSets"))?[0];
            let infos: Vec<[vk::DescriptorImageInfo; 1]> = bindings
                .iter()
                .map(|b| match *b {
                    Binding::Image(view) => [vk::DescriptorImageInfo {
                        sampler: vk::Sampler::null(),
                        image_view: view,
                        image_layout: vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL,
                    }],
                    Binding::Sampler(sampler) => {
                        [vk::DescriptorImageInfo { sampler, image_view: vk::ImageView::null(), image_layout: vk::ImageLayout::UNDEFINED }]
                    }
                    Binding::AccelerationStructure(_) | Binding::StorageBuffer(_) => [vk::DescriptorImageInfo::default()],
                })
                .collect();
            let buffers: Vec<[vk::DescriptorBufferInfo; 1]> = bindings
                .iter()
                .map(|b| match *b {
                    Binding::StorageBuffer(buffer) => [vk::DescriptorBufferInfo { buffer, offset: 0, range: vk::WHOLE_SIZE }],
                    _ => [vk::DescriptorBufferInfo::default()],
                })
                .collect();
            let accels: Vec<[vk::AccelerationStructureKHR; 1]> = bindings
                .iter()
                .map(|b| match *b {
                    Binding::AccelerationStructure(a) => [a],
                    _ => [vk::AccelerationStructureKHR::null()],
                })
                .collect();
            let mut accel_writes: Vec<vk::WriteDescriptorSetAccelerationStructureKHR> =
                accels.iter().map(|a| vk::WriteDescriptorSetAccelerationStructureKHR::default().acceleration_structures(a)).collect();
            let writes: Vec<_> = bindings
                .iter()
                .zip(&infos)
                .zip(accel_writes.iter_mut())
                .zip(&buffers)
                .enumerate()
                .map(|(i, (((b, info), aw), buf))| {
                    let w = vk::WriteDescriptorSet::default().dst_set(set).dst_binding(i as u32).descriptor_type(ty(b));
                    match b {
                        Binding::AccelerationStructure(_) => w.descriptor_count(1).push_next(aw),
                        Binding::StorageBuffer(_) => w.buffer_info(buf),
                        _ => w.image_info(info),
                    }
                })
                .collect();
            d.update_descriptor_sets(&writes, &[]);
            Ok(DescriptorSet { layout, set, pool })
        }
    }

    /// Destroys the pool (freeing the set) and the layout. `ctx` must be the device the set was
    /// created on, and no pending GPU work may still use the set (e.g. after `vkDeviceWaitIdle`).
    /// Call once: the handles are not reset.
    pub fn destroy(&mut self, ctx: &impl GpuDevice) {
        // SAFETY: the owner waited for the device to be idle; freeing the pool frees the set.
        unsafe {
            ctx.device().destroy_descriptor_pool(self.pool, None);
            ctx.device().destroy_descriptor_set_layout(self.layout, None);
        }
    }
}

/// A pipeline layout with the given set layouts (set `i` = `sets[i]`) and one push-constant
/// range of `push_bytes` bytes at offset 0 visible to `stages` (0 bytes: no range; otherwise a
/// multiple of 4 within `maxPushConstantsSize`). The caller owns and destroys the layout.
pub fn pipeline_layout(
    ctx: &impl GpuDevice,
    sets: &[vk::DescriptorSetLayout],
    push_bytes: u32,
    stages: vk::ShaderStageFlags,
) -> Result<vk::PipelineLayout> {
    let ranges = [vk::PushConstantRange { stage_flags: stages, offset: 0, size: push_bytes }];
    let info = vk::PipelineLayoutCreateInfo::default().set_layouts(sets).push_constant_ranges(if push_bytes > 0 { &ranges } else { &[] });
    // SAFETY: valid device; the create info points at locals alive for the call.
    unsafe { ctx.device().create_pipeline_layout(&info, None) }.map_err(vkerr("vkCreatePipelineLayout"))
}

/// A layout of `count` storage-buffer bindings 0, 1, 2, ..., one descriptor each, visible to
/// `stages` (the compute and mesh passes' tables). The caller destroys it.
pub fn storage_set_layout(ctx: &impl GpuDevice, count: u32, stages: vk::ShaderStageFlags) -> Result<vk::DescriptorSetLayout> {
    let bindings: Vec<_> = (0..count)
        .map(|i| {
            vk::DescriptorSetLayoutBinding::default()
                .binding(i)
                .descriptor_type(vk::DescriptorType::STORAGE_BUFFER)
                .descriptor_count(1)
                .stage_flags(stages)
        })
        .collect();
    // SAFETY: valid device; the create info points at locals alive for the call.
    unsafe { ctx.device().create_descriptor_set_layout(&vk::DescriptorSetLayoutCreateInfo::default().bindings(&bindings), None) }
        .map_err(vkerr("vkCreateDescriptorSetLayout"))
}

/// One write per entry of `infos` into `set`'s storage-buffer bindings 0, 1, 2, ... (binding
/// `k` gets `infos[k]`).
pub fn storage_buffer_writes(set: vk::DescriptorSet, infos: &[[vk::DescriptorBufferInfo; 1]]) -> Vec<vk::WriteDescriptorSet<'_>> {
    infos
        .iter()
        .enumerate()
        .map(|(b, info)| {
            vk::WriteDescriptorSet::default()
                .dst_set(set)
                .dst_binding(b as u32)
                .descriptor_type(vk::DescriptorType::STORAGE_BUFFER)
                .buffer_info(info)
        })
        .collect()
}
