//! Buffers and images with gpu-allocator memory. Destroyed explicitly through the context
//! (`destroy`), in the owner's `Drop`, after the device is idle.

use super::context::GpuDevice;
use super::fault;
use crate::error::{Error, Result};
use ash::vk;
use gpu_allocator::vulkan::{Allocation, AllocationCreateDesc, AllocationScheme};
use gpu_allocator::MemoryLocation;

fn vkerr(call: &'static str) -> impl Fn(vk::Result) -> Error {
    Error::vk(call)
}

/// A `VkBuffer` bound to its own gpu-allocator allocation (exclusive sharing). Not freed on
/// drop: call [`Buffer::destroy`].
pub struct Buffer {
    /// The buffer handle; null after [`Buffer::destroy`].
    pub raw: vk::Buffer,
    /// The size asked for, in bytes. The `VkBuffer` itself is at least 4 bytes (Vulkan forbids
    /// size 0), and [`Buffer::read`] returns exactly `size` bytes.
    pub size: u64,
    allocation: Option<Allocation>,
}

impl Buffer {
    /// Creates a buffer of `size` bytes with `usage`, in memory at `location` (host-visible for
    /// `CpuToGpu` / `GpuToCpu`, which [`Buffer::write`] and [`Buffer::read`] need). `name` labels
    /// the allocation in gpu-allocator's reports and in the error.
    pub fn new(ctx: &impl GpuDevice, name: &str, size: u64, usage: vk::BufferUsageFlags, location: MemoryLocation) -> Result<Buffer> {
        let info = vk::BufferCreateInfo::default().size(size.max(4)).usage(usage).sharing_mode(vk::SharingMode::EXCLUSIVE);
        // SAFETY: valid device and create info.
        let raw = unsafe { ctx.device().create_buffer(&info, None) }.map_err(vkerr("vkCreateBuffer"))?;
        // SAFETY: `raw` was just created on this device.
        let requirements = unsafe { ctx.device().get_buffer_memory_requirements(raw) };
        let allocation = {
            let mut allocator = GpuDevice::allocator(ctx);
            fault::check_budget(&allocator, name, requirements.size).and_then(|()| {
                allocator
                    .allocate(&AllocationCreateDesc {
                        name,
                        requirements,
                        location,
                        linear: true,
                        allocation_scheme: AllocationScheme::GpuAllocatorManaged,
                    })
                    .map_err(|source| Error::Allocation { name: name.to_string(), size, source })
            })
        };
        let allocation = match allocation {
            Ok(a) => a,
            Err(e) => {
                // SAFETY: `raw` was created above, is bound to nothing and used by nothing.
                unsafe { ctx.device().destroy_buffer(raw, None) };
                return Err(e);
            }
        };
        // SAFETY: memory and offset come from an allocation made for these requirements.
        if let Err(e) = unsafe { ctx.device().bind_buffer_memory(raw, allocation.memory(), allocation.offset()) } {
            let _ = GpuDevice::allocator(ctx).free(allocation);
            // SAFETY: `raw` is bound to nothing and used by nothing.
            unsafe { ctx.device().destroy_buffer(raw, None) };
            return Err(Error::Vulkan { call: "vkBindBufferMemory", result: e });
        }
        Ok(Buffer { raw, size, allocation: Some(allocation) })
    }

    /// A host-visible buffer filled with `data`.
    pub fn with_data(ctx: &impl GpuDevice, name: &str, data: &[u8], usage: vk::BufferUsageFlags) -> Result<Buffer> {
        let mut b = Buffer::new(ctx, name, data.len() as u64, usage, MemoryLocation::CpuToGpu)?;
        b.write(0, data)?;
        Ok(b)
    }

    /// Copies `data` into the mapped memory at byte `offset`. Fails if the buffer is not host
    /// visible or the write would end past the allocation. The caller must make sure the GPU is
    /// not using that range meanwhile (memory is host-coherent: no flush needed).
    pub fn write(&mut self, offset: usize, data: &[u8]) -> Result<()> {
        let slice = self
            .allocation
            .as_mut()
            .and_then(|a| a.mapped_slice_mut())
            .ok_or_else(|| Error::argument("Buffer::write", "the buffer is not host visible"))?;
        let end = offset + data.len();
        if end > slice.len() {
            return Err(Error::argument("Buffer::write", format!("write out of range: {end} > {}", slice.len())));
        }
        slice[offset..end].copy_from_slice(data);
        Ok(())
    }

    /// The first [`Buffer::size`] bytes of the mapped memory. Fails if the buffer is not host
    /// visible. Meaningful only after the GPU writes have completed (fence wait) and been made
    /// visible to the host (a barrier to `HOST_READ`).
    pub fn read(&self) -> Result<&[u8]> {
        let s = self
            .allocation
            .as_ref()
            .and_then(|a| a.mapped_slice())
            .ok_or_else(|| Error::argument("Buffer::read", "the buffer is not host visible"))?;
        Ok(&s[..self.size as usize])
    }

    /// Frees the memory and destroys the buffer. `ctx` must be the device and allocator it was
    /// created with, and the GPU must no longer use it (e.g. after `vkDeviceWaitIdle`). Calling
    /// it again is harmless.
    pub fn destroy(&mut self, ctx: &impl GpuDevice) {
        if let Some(a) = self.allocation.take() {
            let _ = GpuDevice::allocator(ctx).free(a);
        }
        // SAFETY: the owner guarantees the GPU no longer uses the buffer (device idle).
        unsafe { ctx.device().destroy_buffer(self.raw, None) };
        self.raw = vk::Buffer::null();
    }
}

/// What [`Image::new_all`] creates: name, format, usage and aspect of one image.
pub type ImageSpec<'a> = (&'a str, vk::Format, vk::ImageUsageFlags, vk::ImageAspectFlags);

/// A 2D image (one mip level, one layer unless made by [`Image::new_array`], optimal tiling;
/// one sample unless made by [`Image::new_2d_samples`]) in device-local memory, with a view of
/// the whole image. Not freed on drop: call [`Image::destroy`].
pub struct Image {
    /// The image handle.
    pub raw: vk::Image,
    /// A view of the whole image with [`Image::aspect`]: 2D, or 2D array for an image made by
    /// [`Image::new_array`].
    pub view: vk::ImageView,
    /// The image's (and the view's) format.
    pub format: vk::Format,
    /// Size in pixels.
    pub extent: vk::Extent2D,
    /// The aspects the view and [`Image::range`] cover (`COLOR`, or `DEPTH | STENCIL` for the
    /// depth-stencil buffer).
    pub aspect: vk::ImageAspectFlags,
    /// Samples per pixel.
    pub samples: vk::SampleCountFlags,
    /// Array layers (1 unless made by [`Image::new_array`]).
    pub layers: u32,
    allocation: Option<Allocation>,
}

impl Image {
    /// Creates the image in layout `UNDEFINED` (transition it before use, see [`transition`]),
    /// allocates and binds `GpuOnly` memory, and creates its view over `aspect`, which must
    /// match `format`. `name` labels the allocation.
    pub fn new_2d(
        ctx: &impl GpuDevice,
        name: &str,
        format: vk::Format,
        extent: vk::Extent2D,
        usage: vk::ImageUsageFlags,
        aspect: vk::ImageAspectFlags,
    ) -> Result<Image> {
        Image::new_2d_samples(ctx, name, format, extent, usage, aspect, vk::SampleCountFlags::TYPE_1)
    }

    /// No image (null handles, no memory): a placeholder that [`Image::destroy`] ignores.
    pub fn null() -> Image {
        Image {
            raw: vk::Image::null(),
            view: vk::ImageView::null(),
            format: vk::Format::UNDEFINED,
            extent: vk::Extent2D::default(),
            aspect: vk::ImageAspectFlags::COLOR,
            samples: vk::SampleCountFlags::TYPE_1,
            layers: 1,
            allocation: None,
        }
    }

    /// [`Image::new_2d`] with `samples` samples per pixel (the device must support that count
    /// for the format and usage: the caller checks).
    pub fn new_2d_samples(
        ctx: &impl GpuDevice,
        name: &str,
        format: vk::Format,
        extent: vk::Extent2D,
        usage: vk::ImageUsageFlags,
        aspect: vk::ImageAspectFlags,
        samples: vk::SampleCountFlags,
    ) -> Result<Image> {
        Image::create(ctx, name, (format, aspect), extent, usage, samples, None)
    }

    /// A 2D array image of `layers` layers (one sample), with a `TYPE_2D_ARRAY` view of every
    /// layer (also for one layer: a shader's `texture2DArray` reads it), as
    /// [`Image::new_2d`] otherwise. [`Image::range`] and [`transition`] cover every layer.
    pub fn new_array(
        ctx: &impl GpuDevice,
        name: &str,
        format: vk::Format,
        extent: vk::Extent2D,
        layers: u32,
        usage: vk::ImageUsageFlags,
        aspect: vk::ImageAspectFlags,
    ) -> Result<Image> {
        Image::create(ctx, name, (format, aspect), extent, usage, vk::SampleCountFlags::TYPE_1, Some(layers.max(1)))
    }

    /// The image (`layers`: `None` for a single layer with a 2D view, `Some(n)` for a 2D array
    /// view of `n` layers), its memory and its view.
    fn create(
        ctx: &impl GpuDevice,
        name: &str,
        (format, aspect): (vk::Format, vk::ImageAspectFlags),
        extent: vk::Extent2D,
        usage: vk::ImageUsageFlags,
        samples: vk::SampleCountFlags,
        array: Option<u32>,
    ) -> Result<Image> {
        let layers = array.unwrap_or(1);
        let info = vk::ImageCreateInfo::default()
            .image_type(vk::ImageType::TYPE_2D)
            .format(format)
            .extent(vk::Extent3D { width: extent.width, height: extent.height, depth: 1 })
            .mip_levels(1)
            .array_layers(layers)
            .samples(samples)
            .tiling(vk::ImageTiling::OPTIMAL)
            .usage(usage)
            .initial_layout(vk::ImageLayout::UNDEFINED);
        // SAFETY: valid create info on a valid device.
        let raw = unsafe { ctx.device().create_image(&info, None) }.map_err(vkerr("vkCreateImage"))?;
        // SAFETY: `raw` is a new image of this device.
        let requirements = unsafe { ctx.device().get_image_memory_requirements(raw) };
        let allocation = {
            let mut allocator = GpuDevice::allocator(ctx);
            let label = format!("image {name}");
            fault::check_budget(&allocator, &label, requirements.size).and_then(|()| {
                allocator
                    .allocate(&AllocationCreateDesc {
                        name,
                        requirements,
                        location: MemoryLocation::GpuOnly,
                        linear: false,
                        allocation_scheme: AllocationScheme::GpuAllocatorManaged,
                    })
                    .map_err(|source| Error::Allocation { name: label, size: requirements.size, source })
            })
        };
        // On any failure below, what was created so far is released again.
        let release = |allocation: Option<Allocation>| {
            if let Some(a) = allocation {
                let _ = GpuDevice::allocator(ctx).free(a);
            }
            // SAFETY: `raw` was created above and is used by nothing (no view, no command).
            unsafe { ctx.device().destroy_image(raw, None) };
        };
        let allocation = match allocation {
            Ok(a) => a,
            Err(e) => {
                release(None);
                return Err(e);
            }
        };
        // SAFETY: the allocation satisfies the image's requirements.
        if let Err(e) = unsafe { ctx.device().bind_image_memory(raw, allocation.memory(), allocation.offset()) } {
            release(Some(allocation));
            return Err(Error::Vulkan { call: "vkBindImageMemory", result: e });
        }
        let view_type = if array.is_some() { vk::ImageViewType::TYPE_2D_ARRAY } else { vk::ImageViewType::TYPE_2D };
        let view_info = vk::ImageViewCreateInfo::default().image(raw).view_type(view_type).format(format).subresource_range(
            vk::ImageSubresourceRange { aspect_mask: aspect, base_mip_level: 0, level_count: 1, base_array_layer: 0, layer_count: layers },
        );
        // SAFETY: `raw` is bound to memory; the view covers its layers of its single mip level.
        let view = match unsafe { ctx.device().create_image_view(&view_info, None) } {
            Ok(v) => v,
            Err(e) => {
                release(Some(allocation));
                return Err(Error::Vulkan { call: "vkCreateImageView", result: e });
            }
        };
        Ok(Image { raw, view, format, extent, aspect, samples, layers, allocation: Some(allocation) })
    }

    /// Creates one image of `extent` per spec, all or nothing: when one fails, those already
    /// made are destroyed again before the error is returned.
    pub fn new_all<const N: usize>(ctx: &impl GpuDevice, extent: vk::Extent2D, specs: [ImageSpec<'_>; N]) -> Result<[Image; N]> {
        Image::new_all_samples(ctx, extent, vk::SampleCountFlags::TYPE_1, specs)
    }

    /// [`Image::new_all`] with `samples` samples per pixel each.
    pub fn new_all_samples<const N: usize>(
        ctx: &impl GpuDevice,
        extent: vk::Extent2D,
        samples: vk::SampleCountFlags,
        specs: [ImageSpec<'_>; N],
    ) -> Result<[Image; N]> {
        let mut made: Vec<Image> = Vec::with_capacity(N);
        for (name, format, usage, aspect) in specs {
            match Image::new_2d_samples(ctx, name, format, extent, usage, aspect, samples) {
                Ok(img) => made.push(img),
                Err(e) => {
                    for mut img in made {
                        img.destroy(ctx);
                    }
                    return Err(e);
                }
            }
        }
        made.try_into().map_err(|_| Error::Internal("image count mismatch".into()))
    }

    /// The subresource range of the whole image (its single mip level, every layer, [`Image::aspect`]).
    pub fn range(&self) -> vk::ImageSubresourceRange {
        vk::ImageSubresourceRange {
            aspect_mask: self.aspect,
            base_mip_level: 0,
            level_count: 1,
            base_array_layer: 0,
            layer_count: self.layers,
        }
    }

    /// Destroys the view and the image and frees the memory. `ctx` must be the device and
    /// allocator it was created with, and the GPU must no longer use it (e.g. after
    /// `vkDeviceWaitIdle`). Call once: the handles are not reset.
    pub fn destroy(&mut self, ctx: &impl GpuDevice) {
        // SAFETY: the owner guarantees the GPU no longer uses the image (device idle); null
        // handles (a null image, or one destroyed before) are ignored by Vulkan.
        unsafe {
            ctx.device().destroy_image_view(self.view, None);
            ctx.device().destroy_image(self.raw, None);
        }
        self.view = vk::ImageView::null();
        self.raw = vk::Image::null();
        if let Some(a) = self.allocation.take() {
            let _ = GpuDevice::allocator(ctx).free(a);
        }
    }
}

/// A tightly packed copy between a buffer at `buffer_offset` and one whole `aspect` of a 2D
/// image of `extent` (its single mip level and layer).
pub fn aspect_copy(aspect: vk::ImageAspectFlags, extent: vk::Extent2D, buffer_offset: u64) -> vk::BufferImageCopy {
    vk::BufferImageCopy {
        buffer_offset,
        buffer_row_length: 0,
        buffer_image_height: 0,
        image_subresource: vk::ImageSubresourceLayers { aspect_mask: aspect, mip_level: 0, base_array_layer: 0, layer_count: 1 },
        image_offset: vk::Offset3D::default(),
        image_extent: vk::Extent3D { width: extent.width, height: extent.height, depth: 1 },
    }
}

/// Records a layout transition of the whole `image` from `from` to `to` into `cb` (which must
/// be recording), as a synchronization2 barrier scoped by the two layouts: the writes of the
/// stages that use an image in `from` are made visible to the stages that use it in `to` (see
/// `layout_scope`; layouts without a known use get the full scope). `from` may be `UNDEFINED`
/// (contents discarded; earlier commands are still waited for).
pub fn transition(ctx: &impl GpuDevice, cb: vk::CommandBuffer, image: &Image, from: vk::ImageLayout, to: vk::ImageLayout) {
    transition_range(ctx, cb, image.raw, image.range(), from, to);
}

/// [`transition`] of `range` of a raw image handle (an image held as handles, not an [`Image`]).
pub fn transition_range(
    ctx: &impl GpuDevice,
    cb: vk::CommandBuffer,
    image: vk::Image,
    range: vk::ImageSubresourceRange,
    from: vk::ImageLayout,
    to: vk::ImageLayout,
) {
    let (src_stage, src_access) = layout_scope(from, true);
    let (dst_stage, dst_access) = layout_scope(to, false);
    let barrier = vk::ImageMemoryBarrier2::default()
        .src_stage_mask(src_stage)
        .src_access_mask(src_access)
        .dst_stage_mask(dst_stage)
        .dst_access_mask(dst_access)
        .old_layout(from)
        .new_layout(to)
        .image(image)
        .subresource_range(range);
    if !ctx.synchronization2() {
        let b = [vk::ImageMemoryBarrier::default()
            .src_access_mask(access_v1(src_access))
            .dst_access_mask(access_v1(dst_access))
            .old_layout(from)
            .new_layout(to)
            .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
            .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
            .image(image)
            .subresource_range(range)];
        // SAFETY: `cb` is recording; the image belongs to this device.
        unsafe {
            ctx.device().cmd_pipeline_barrier(
                cb,
                stage_v1(src_stage, true),
                stage_v1(dst_stage, false),
                vk::DependencyFlags::empty(),
                &[],
                &[],
                &b,
            )
        };
        return;
    }
    let barriers = [barrier];
    let dep = vk::DependencyInfo::default().image_memory_barriers(&barriers);
    // SAFETY: `cb` is recording; the image belongs to this device.
    unsafe { ctx.device().cmd_pipeline_barrier2(cb, &dep) };
}

/// A synchronization2 stage mask as Vulkan 1.0 stage flags: the bits below 2^32 are the same
/// (`ALL_TRANSFER` is `TRANSFER`); `NONE` becomes `TOP_OF_PIPE` as a source and
/// `BOTTOM_OF_PIPE` as a destination; the finer 2-only stages widen to `ALL_COMMANDS`.
fn stage_v1(s: vk::PipelineStageFlags2, src: bool) -> vk::PipelineStageFlags {
    if s == vk::PipelineStageFlags2::NONE {
        return if src { vk::PipelineStageFlags::TOP_OF_PIPE } else { vk::PipelineStageFlags::BOTTOM_OF_PIPE };
    }
    if s.as_raw() >> 32 != 0 {
        return vk::PipelineStageFlags::ALL_COMMANDS;
    }
    vk::PipelineStageFlags::from_raw(s.as_raw() as u32)
}

/// A synchronization2 access mask as Vulkan 1.0 access flags (the finer 2-only accesses widen to
/// `MEMORY_READ | MEMORY_WRITE`).
fn access_v1(a: vk::AccessFlags2) -> vk::AccessFlags {
    let low = vk::AccessFlags::from_raw(a.as_raw() as u32);
    if a.as_raw() >> 32 != 0 {
        low | vk::AccessFlags::MEMORY_READ | vk::AccessFlags::MEMORY_WRITE
    } else {
        low
    }
}

/// The stages and accesses an image in `layout` is used with: as the source of a transition
/// (`src`: the writes to make available, and the stages to wait for) or as its destination.
/// `UNDEFINED` as a source still waits for every earlier command (the previous frame may be
/// reading the image: a write-after-read hazard needs the execution dependency); layouts not
/// listed get the full `ALL_COMMANDS` / `MEMORY_*` scope.
fn layout_scope(layout: vk::ImageLayout, src: bool) -> (vk::PipelineStageFlags2, vk::AccessFlags2) {
    use vk::AccessFlags2 as A;
    use vk::ImageLayout as L;
    use vk::PipelineStageFlags2 as S;
    let fragment_tests = S::EARLY_FRAGMENT_TESTS | S::LATE_FRAGMENT_TESTS;
    match layout {
        L::UNDEFINED => (if src { S::ALL_COMMANDS } else { S::NONE }, A::NONE),
        L::COLOR_ATTACHMENT_OPTIMAL => {
            (S::COLOR_ATTACHMENT_OUTPUT, if src { A::COLOR_ATTACHMENT_WRITE } else { A::COLOR_ATTACHMENT_READ | A::COLOR_ATTACHMENT_WRITE })
        }
        L::DEPTH_STENCIL_ATTACHMENT_OPTIMAL => (
            fragment_tests,
            if src { A::DEPTH_STENCIL_ATTACHMENT_WRITE } else { A::DEPTH_STENCIL_ATTACHMENT_READ | A::DEPTH_STENCIL_ATTACHMENT_WRITE },
        ),
        L::SHADER_READ_ONLY_OPTIMAL => (S::FRAGMENT_SHADER | S::COMPUTE_SHADER, if src { A::NONE } else { A::SHADER_READ }),
        L::TRANSFER_SRC_OPTIMAL => (S::ALL_TRANSFER, if src { A::NONE } else { A::TRANSFER_READ }),
        L::TRANSFER_DST_OPTIMAL => (S::ALL_TRANSFER, A::TRANSFER_WRITE),
        L::PRESENT_SRC_KHR => (if src { S::ALL_COMMANDS } else { S::NONE }, A::NONE),
        _ => (S::ALL_COMMANDS, if src { A::MEMORY_WRITE } else { A::MEMORY_READ | A::MEMORY_WRITE }),
    }
}

/// The barrier that makes a command buffer's transfer writes (readback copies) visible to the
/// host once its fence has signalled.
pub fn transfer_to_host_barrier(ctx: &impl GpuDevice, cb: vk::CommandBuffer) {
    memory_barrier(
        ctx,
        cb,
        (vk::PipelineStageFlags2::ALL_TRANSFER, vk::AccessFlags2::TRANSFER_WRITE),
        (vk::PipelineStageFlags2::HOST, vk::AccessFlags2::HOST_READ),
    );
}

/// A depth-stencil attachment of `view` in `DEPTH_STENCIL_ATTACHMENT_OPTIMAL`, cleared to
/// `(depth, stencil)` and stored: what a pass that draws into a fresh depth-stencil image
/// begins its rendering with (use it as both the depth and the stencil attachment).
pub fn cleared_depth_stencil(view: vk::ImageView, (depth, stencil): (f32, u32)) -> vk::RenderingAttachmentInfo<'static> {
    vk::RenderingAttachmentInfo::default()
        .image_view(view)
        .image_layout(vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL)
        .load_op(vk::AttachmentLoadOp::CLEAR)
        .store_op(vk::AttachmentStoreOp::STORE)
        .clear_value(vk::ClearValue { depth_stencil: vk::ClearDepthStencilValue { depth, stencil } })
}

/// Records a global memory barrier into `cb` (which must be recording): `src` and `dst` are
/// `(stages, accesses)` before and after the barrier.
pub fn memory_barrier(
    ctx: &impl GpuDevice,
    cb: vk::CommandBuffer,
    src: (vk::PipelineStageFlags2, vk::AccessFlags2),
    dst: (vk::PipelineStageFlags2, vk::AccessFlags2),
) {
    if !ctx.synchronization2() {
        let b = [vk::MemoryBarrier::default().src_access_mask(access_v1(src.1)).dst_access_mask(access_v1(dst.1))];
        // SAFETY: `cb` is recording.
        unsafe {
            ctx.device().cmd_pipeline_barrier(cb, stage_v1(src.0, true), stage_v1(dst.0, false), vk::DependencyFlags::empty(), &b, &[], &[])
        };
        return;
    }
    let b = [vk::MemoryBarrier2::default().src_stage_mask(src.0).src_access_mask(src.1).dst_stage_mask(dst.0).dst_access_mask(dst.1)];
    let dep = vk::DependencyInfo::default().memory_barriers(&b);
    // SAFETY: `cb` is recording.
    unsafe { ctx.device().cmd_pipeline_barrier2(cb, &dep) };
}
