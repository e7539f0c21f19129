//! Buffers and images with gpu-allocator memory. Destroyed explicitly through the context
//! (`destroy`), in the owner's `Drop`, after the device is idle.

use super::context::GpuDevice;
use crate::error::{Error, Result};
use ash::vk;
use gpu_allocator::vulkan::{Allocation, AllocationCreateDesc, AllocationScheme};
use gpu_allocator::MemoryLocation;

fn vkerr(call: &'static str) -> impl Fn(vk::Result) -> Error {
    Error::vk(call)
}

pub struct Buffer {
    pub raw: vk::Buffer,
    pub size: u64,
    allocation: Option<Allocation>,
}

impl Buffer {
    pub fn new(ctx: &impl GpuDevice, name: &str, size: u64, usage: vk::BufferUsageFlags, location: MemoryLocation) -> Result<Buffer> {
        let info = vk::BufferCreateInfo::default().size(size.max(4)).usage(usage).sharing_mode(vk::SharingMode::EXCLUSIVE);
        // SAFETY: valid device and create info.
        let raw = unsafe { ctx.device().create_buffer(&info, None) }.map_err(vkerr("vkCreateBuffer"))?;
        // SAFETY: `raw` was just created on this device.
        let requirements = unsafe { ctx.device().get_buffer_memory_requirements(raw) };
        let allocation = GpuDevice::allocator(ctx)
            .allocate(&AllocationCreateDesc {
                name,
                requirements,
                location,
                linear: true,
                allocation_scheme: AllocationScheme::GpuAllocatorManaged,
            })
            .map_err(|source| Error::Allocation { name: name.to_string(), size, source })?;
        // SAFETY: memory and offset come from an allocation made for these requirements.
        unsafe { ctx.device().bind_buffer_memory(raw, allocation.memory(), allocation.offset()) }.map_err(vkerr("vkBindBufferMemory"))?;
        Ok(Buffer { raw, size, allocation: Some(allocation) })
    }

    /// A host-visible buffer filled with `data`.
    pub fn with_data(ctx: &impl GpuDevice, name: &str, data: &[u8], usage: vk::BufferUsageFlags) -> Result<Buffer> {
        let mut b = Buffer::new(ctx, name, data.len() as u64, usage, MemoryLocation::CpuToGpu)?;
        b.write(0, data)?;
        Ok(b)
    }

    pub fn write(&mut self, offset: usize, data: &[u8]) -> Result<()> {
        let slice =
            self.allocation.as_mut().and_then(|a| a.mapped_slice_mut()).ok_or_else(|| Error::Other("buffer is not host visible".into()))?;
        let end = offset + data.len();
        if end > slice.len() {
            return Err(Error::Other(format!("buffer write out of range: {end} > {}", slice.len())));
        }
        slice[offset..end].copy_from_slice(data);
        Ok(())
    }

    pub fn read(&self) -> Result<&[u8]> {
        let s = self.allocation.as_ref().and_then(|a| a.mapped_slice()).ok_or_else(|| Error::Other("buffer is not host visible".into()))?;
        Ok(&s[..self.size as usize])
    }

    pub fn destroy(&mut self, ctx: &impl GpuDevice) {
        if let Some(a) = self.allocation.take() {
            let _ = GpuDevice::allocator(ctx).free(a);
        }
        // SAFETY: the owner guarantees the GPU no longer uses the buffer (device idle).
        unsafe { ctx.device().destroy_buffer(self.raw, None) };
        self.raw = vk::Buffer::null();
    }
}

pub struct Image {
    pub raw: vk::Image,
    pub view: vk::ImageView,
    pub format: vk::Format,
    pub extent: vk::Extent2D,
    pub aspect: vk::ImageAspectFlags,
    allocation: Option<Allocation>,
}

impl Image {
    pub fn new_2d(
        ctx: &impl GpuDevice,
        name: &str,
        format: vk::Format,
        extent: vk::Extent2D,
        usage: vk::ImageUsageFlags,
        aspect: vk::ImageAspectFlags,
    ) -> Result<Image> {
        let info = vk::ImageCreateInfo::default()
            .image_type(vk::ImageType::TYPE_2D)
            .format(format)
            .extent(vk::Extent3D { width: extent.width, height: extent.height, depth: 1 })
            .mip_levels(1)
            .array_layers(1)
            .samples(vk::SampleCountFlags::TYPE_1)
            .tiling(vk::ImageTiling::OPTIMAL)
            .usage(usage)
            .initial_layout(vk::ImageLayout::UNDEFINED);
        // SAFETY: valid create info on a valid device.
        let raw = unsafe { ctx.device().create_image(&info, None) }.map_err(vkerr("vkCreateImage"))?;
        // SAFETY: `raw` is a new image of this device.
        let requirements = unsafe { ctx.device().get_image_memory_requirements(raw) };
        let allocation = GpuDevice::allocator(ctx)
            .allocate(&AllocationCreateDesc {
                name,
                requirements,
                location: MemoryLocation::GpuOnly,
                linear: false,
                allocation_scheme: AllocationScheme::GpuAllocatorManaged,
            })
            .map_err(|source| Error::Allocation { name: format!("image {name}"), size: requirements.size, source })?;
        // SAFETY: the allocation satisfies the image's requirements.
        unsafe { ctx.device().bind_image_memory(raw, allocation.memory(), allocation.offset()) }.map_err(vkerr("vkBindImageMemory"))?;
        let view_info =
            vk::ImageViewCreateInfo::default().image(raw).view_type(vk::ImageViewType::TYPE_2D).format(format).subresource_range(
                vk::ImageSubresourceRange { aspect_mask: aspect, base_mip_level: 0, level_count: 1, base_array_layer: 0, layer_count: 1 },
            );
        // SAFETY: `raw` is bound to memory; the view covers its single subresource.
        let view = unsafe { ctx.device().create_image_view(&view_info, None) }.map_err(vkerr("vkCreateImageView"))?;
        Ok(Image { raw, view, format, extent, aspect, allocation: Some(allocation) })
    }

    pub fn range(&self) -> vk::ImageSubresourceRange {
        vk::ImageSubresourceRange { aspect_mask: self.aspect, base_mip_level: 0, level_count: 1, base_array_layer: 0, layer_count: 1 }
    }

    pub fn destroy(&mut self, ctx: &impl GpuDevice) {
        // SAFETY: the owner guarantees the GPU no longer uses the image (device idle).
        unsafe {
            ctx.device().destroy_image_view(self.view, None);
            ctx.device().destroy_image(self.raw, None);
        }
        if let Some(a) = self.allocation.take() {
            let _ = GpuDevice::allocator(ctx).free(a);
        }
    }
}

/// A full-pipeline image layout transition (synchronization2). Conservative stage masks:
/// the frame has a handful of these, never in an inner loop.
pub fn transition(ctx: &impl GpuDevice, cb: vk::CommandBuffer, image: &Image, from: vk::ImageLayout, to: vk::ImageLayout) {
    let barrier = vk::ImageMemoryBarrier2::default()
        .src_stage_mask(vk::PipelineStageFlags2::ALL_COMMANDS)
        .src_access_mask(vk::AccessFlags2::MEMORY_WRITE)
        .dst_stage_mask(vk::PipelineStageFlags2::ALL_COMMANDS)
        .dst_access_mask(vk::AccessFlags2::MEMORY_READ | vk::AccessFlags2::MEMORY_WRITE)
        .old_layout(from)
        .new_layout(to)
        .image(image.raw)
        .subresource_range(image.range());
    let barriers = [barrier];
    let dep = vk::DependencyInfo::default().image_memory_barriers(&barriers);
    // SAFETY: `cb` is recording; the image belongs to this device.
    unsafe { ctx.device().cmd_pipeline_barrier2(cb, &dep) };
}

/// A global memory barrier between two groups of stages.
pub fn memory_barrier(
    ctx: &impl GpuDevice,
    cb: vk::CommandBuffer,
    src: (vk::PipelineStageFlags2, vk::AccessFlags2),
    dst: (vk::PipelineStageFlags2, vk::AccessFlags2),
) {
    let b = [vk::MemoryBarrier2::default().src_stage_mask(src.0).src_access_mask(src.1).dst_stage_mask(dst.0).dst_access_mask(dst.1)];
    let dep = vk::DependencyInfo::default().memory_barriers(&b);
    // SAFETY: `cb` is recording.
    unsafe { ctx.device().cmd_pipeline_barrier2(cb, &dep) };
}
