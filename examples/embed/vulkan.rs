//! The host's Vulkan plumbing: validation messenger, device choice and creation, buffers and
//! images from the gpu-allocator, barriers (`pipelines.rs`: shader modules, pipelines, render
//! passes).

use ash::vk;
use gpu_allocator::vulkan::{Allocation, AllocationCreateDesc, AllocationScheme, Allocator};
use gpu_allocator::MemoryLocation;
use std::ffi::{c_void, CStr};
use std::sync::Mutex;

pub(super) fn vkerr(call: &'static str) -> impl Fn(vk::Result) -> String {
    move |e| format!("{call} failed: {e:?}")
}

pub(super) fn validation_requested() -> bool {
    std::env::var("UMBRAGE_VALIDATION").map(|v| v == "1" || v.eq_ignore_ascii_case("true")).unwrap_or(false)
}

/// Collects validation errors and warnings (the warnings of umbrage's allowlist,
/// [`umbrage::gpu::validation::ALLOWED_WARNINGS`], excepted) into the `Mutex<Vec<String>>`
/// passed as user data: any fails the run.
///
/// # Safety
/// Called by the validation layer only, with the user data the messenger was created with.
pub(super) unsafe extern "system" fn debug_callback(
    severity: vk::DebugUtilsMessageSeverityFlagsEXT,
    _types: vk::DebugUtilsMessageTypeFlagsEXT,
    data: *const vk::DebugUtilsMessengerCallbackDataEXT<'_>,
    user: *mut c_void,
) -> vk::Bool32 {
    // SAFETY: the loader passes valid callback data for the duration of the call; `user` is
    // `Arc::as_ptr` of the host's log, which outlives the messenger (destroyed first).
    let (msg, id, log) = unsafe {
        let text = |p: *const std::ffi::c_char| {
            if data.is_null() || p.is_null() {
                String::new()
            } else {
                CStr::from_ptr(p).to_string_lossy().into_owned()
            }
        };
        let (msg, id) =
            if data.is_null() { (String::new(), String::new()) } else { (text((*data).p_message), text((*data).p_message_id_name)) };
        (msg, id, &*(user as *const Mutex<Vec<String>>))
    };
    let allowed =
        !severity.contains(vk::DebugUtilsMessageSeverityFlagsEXT::ERROR) && umbrage::gpu::validation::allowed_warning(&id).is_some();
    if !allowed {
        eprintln!("[vulkan validation] {msg}");
        if let Ok(mut l) = log.lock() {
            l.push(msg);
        }
    }
    vk::FALSE
}

/// A buffer and its memory from the host's allocator.
pub(super) struct Buf {
    pub(super) raw: vk::Buffer,
    pub(super) alloc: Option<Allocation>,
}

/// An image, its view and its memory.
pub(super) struct Img {
    pub(super) raw: vk::Image,
    pub(super) view: vk::ImageView,
    pub(super) alloc: Option<Allocation>,
}

/// The physical device the host picked, and what it found on it.
pub(super) struct Picked {
    pub(super) physical: vk::PhysicalDevice,
    pub(super) name: String,
    pub(super) queue_family: u32,
    pub(super) ds_format: vk::Format,
    pub(super) depth_clamp: bool,
    pub(super) depth_bounds: bool,
    pub(super) index_type_uint8: bool,
    /// `VkPhysicalDeviceLimits::standardSampleLocations`.
    pub(super) standard_sample_locations: bool,
    /// Nanoseconds a timestamp tick, when the queue has timestamps.
    pub(super) timestamp_period: Option<f32>,
}

pub(super) fn lock(a: &Mutex<Allocator>) -> std::sync::MutexGuard<'_, Allocator> {
    a.lock().unwrap_or_else(|p| p.into_inner())
}

/// The first device the host can use with a graphics queue and a depth-stencil format with 8
/// stencil bits that can be an attachment and be sampled (the readback reads every sample in a
/// compute shader): Vulkan 1.3 with dynamicRendering for the dynamic-rendering model, Vulkan
/// 1.1 for the render-pass model. Discrete before integrated before virtual before CPU
/// (`UMBRAGE_DEVICE=<name substring>` picks one).
pub(super) fn pick_device(instance: &ash::Instance, dynamic_rendering: bool) -> Result<Picked, String> {
    // SAFETY: enumeration on a valid instance.
    let physicals = unsafe { instance.enumerate_physical_devices() }.map_err(vkerr("vkEnumeratePhysicalDevices"))?;
    let wanted = std::env::var("UMBRAGE_DEVICE").ok().map(|s| s.to_lowercase());
    let min_api = if dynamic_rendering { vk::API_VERSION_1_3 } else { vk::API_VERSION_1_1 };
    let mut best: Option<(u32, Picked)> = None;
    for pd in physicals {
        // SAFETY: `pd` comes from the enumeration above (and so below).
        let props = unsafe { instance.get_physical_device_properties(pd) };
        let name = props.device_name_as_c_str().map(|c| c.to_string_lossy().into_owned()).unwrap_or_default();
        if props.api_version < min_api || wanted.as_ref().is_some_and(|w| !name.to_lowercase().contains(w)) {
            continue;
        }
        // SAFETY: as above.
        let families = unsafe { instance.get_physical_device_queue_family_properties(pd) };
        let Some(qf) = families.iter().position(|f| f.queue_flags.contains(vk::QueueFlags::GRAPHICS | vk::QueueFlags::COMPUTE)) else {
            continue;
        };
        let mut dynamic = vk::PhysicalDeviceDynamicRenderingFeatures::default();
        let mut f2 = vk::PhysicalDeviceFeatures2::default();
        if dynamic_rendering {
            f2 = f2.push_next(&mut dynamic);
        }
        // SAFETY: the pNext chain points at a local alive for the call.
        unsafe { instance.get_physical_device_features2(pd, &mut f2) };
        let base = f2.features;
        if dynamic_rendering && dynamic.dynamic_rendering != vk::TRUE {
            continue;
        }
        let needed = vk::FormatFeatureFlags::DEPTH_STENCIL_ATTACHMENT | vk::FormatFeatureFlags::SAMPLED_IMAGE;
        let ds_format = [vk::Format::D32_SFLOAT_S8_UINT, vk::Format::D24_UNORM_S8_UINT].into_iter().find(|&f| {
            // SAFETY: a format query on a valid physical device.
            let p = unsafe { instance.get_physical_device_format_properties(pd, f) };
            p.optimal_tiling_features.contains(needed)
        });
        let Some(ds_format) = ds_format else { continue };
        // SAFETY: as above.
        let exts = unsafe { instance.enumerate_device_extension_properties(pd) }.map_err(vkerr("vkEnumerateDeviceExtensionProperties"))?;
        let has_u8_ext = exts.iter().any(|e| e.extension_name_as_c_str().map(|n| n == ash::ext::index_type_uint8::NAME).unwrap_or(false));
        let index_type_uint8 = has_u8_ext && {
            let mut u8f = vk::PhysicalDeviceIndexTypeUint8FeaturesEXT::default();
            let mut f2 = vk::PhysicalDeviceFeatures2::default().push_next(&mut u8f);
            // SAFETY: as above.
            unsafe { instance.get_physical_device_features2(pd, &mut f2) };
            u8f.index_type_uint8 == vk::TRUE
        };
        let rank = match props.device_type {
            vk::PhysicalDeviceType::DISCRETE_GPU => 0,
            vk::PhysicalDeviceType::INTEGRATED_GPU => 1,
            vk::PhysicalDeviceType::VIRTUAL_GPU => 2,
            vk::PhysicalDeviceType::CPU => 3,
            _ => 4,
        };
        if best.as_ref().map(|(r, _)| rank < *r).unwrap_or(true) {
            let picked = Picked {
                physical: pd,
                name,
                queue_family: qf as u32,
                ds_format,
                depth_clamp: base.depth_clamp == vk::TRUE,
                depth_bounds: base.depth_bounds == vk::TRUE,
                index_type_uint8,
                standard_sample_locations: props.limits.standard_sample_locations == vk::TRUE,
                timestamp_period: (families[qf].timestamp_valid_bits > 0 && props.limits.timestamp_period > 0.0)
                    .then_some(props.limits.timestamp_period),
            };
            best = Some((rank, picked));
        }
    }
    best.map(|(_, p)| p).ok_or_else(|| {
        if dynamic_rendering {
            "no Vulkan 1.3 device with graphics, dynamicRendering and a sampled D32S8/D24S8 attachment (--render-pass needs only Vulkan 1.1)"
                .into()
        } else {
            "no Vulkan 1.1 device with graphics and a sampled D32S8/D24S8 attachment".into()
        }
    })
}

/// Whether `format` can be a colour attachment with `samples` samples that is also sampled.
pub(super) fn color_samples_supported(instance: &ash::Instance, pd: vk::PhysicalDevice, format: vk::Format, samples: u32) -> bool {
    // SAFETY: a format query on a valid physical device.
    let p = unsafe {
        instance.get_physical_device_image_format_properties(
            pd,
            format,
            vk::ImageType::TYPE_2D,
            vk::ImageTiling::OPTIMAL,
            vk::ImageUsageFlags::COLOR_ATTACHMENT | vk::ImageUsageFlags::SAMPLED,
            vk::ImageCreateFlags::empty(),
        )
    };
    p.is_ok_and(|p| p.sample_counts.as_raw() & samples != 0)
}

/// The logical device: one graphics queue; dynamicRendering in the dynamic-rendering model;
/// depthClamp / depthBounds / indexTypeUint8 where present.
pub(super) fn create_device(instance: &ash::Instance, p: &Picked, dynamic_rendering: bool) -> Result<ash::Device, String> {
    let enabled = vk::PhysicalDeviceFeatures::default().depth_clamp(p.depth_clamp).depth_bounds(p.depth_bounds);
    let mut dynamic = vk::PhysicalDeviceDynamicRenderingFeatures::default().dynamic_rendering(true);
    let mut u8f = vk::PhysicalDeviceIndexTypeUint8FeaturesEXT::default().index_type_uint8(true);
    let mut exts = Vec::new();
    if p.index_type_uint8 {
        exts.push(ash::ext::index_type_uint8::NAME.as_ptr());
    }
    let prio = [1.0f32];
    let queues = [vk::DeviceQueueCreateInfo::default().queue_family_index(p.queue_family).queue_priorities(&prio)];
    let mut info = vk::DeviceCreateInfo::default().queue_create_infos(&queues).enabled_features(&enabled).enabled_extension_names(&exts);
    if dynamic_rendering {
        info = info.push_next(&mut dynamic);
    }
    if p.index_type_uint8 {
        info = info.push_next(&mut u8f);
    }
    // SAFETY: every pointer in `info` refers to locals alive for the call.
    unsafe { instance.create_device(p.physical, &info, None) }.map_err(vkerr("vkCreateDevice"))
}

pub(super) fn create_buffer(
    device: &ash::Device,
    allocator: &Mutex<Allocator>,
    name: &str,
    size: u64,
    usage: vk::BufferUsageFlags,
    location: MemoryLocation,
) -> Result<Buf, String> {
    let info = vk::BufferCreateInfo::default().size(size.max(4)).usage(usage).sharing_mode(vk::SharingMode::EXCLUSIVE);
    // SAFETY: a valid create info on a valid device.
    let raw = unsafe { device.create_buffer(&info, None) }.map_err(vkerr("vkCreateBuffer"))?;
    // SAFETY: `raw` was just created on this device.
    let requirements = unsafe { device.get_buffer_memory_requirements(raw) };
    let desc =
        AllocationCreateDesc { name, requirements, location, linear: true, allocation_scheme: AllocationScheme::GpuAllocatorManaged };
    let alloc = match lock(allocator).allocate(&desc) {
        Ok(a) => a,
        Err(e) => {
            // SAFETY: the buffer was never used.
            unsafe { device.destroy_buffer(raw, None) };
            return Err(format!("allocating {name}: {e}"));
        }
    };
    let buf = Buf { raw, alloc: Some(alloc) };
    let a = buf.alloc.as_ref().ok_or("no allocation")?;
    // SAFETY: the allocation was made for this buffer's requirements.
    if let Err(e) = unsafe { device.bind_buffer_memory(raw, a.memory(), a.offset()) } {
        free_buffer(device, allocator, buf);
        return Err(format!("vkBindBufferMemory failed: {e:?}"));
    }
    Ok(buf)
}

pub(super) fn free_buffer(device: &ash::Device, allocator: &Mutex<Allocator>, mut b: Buf) {
    // SAFETY: the caller guarantees the GPU no longer uses the buffer.
    unsafe { device.destroy_buffer(b.raw, None) };
    if let Some(a) = b.alloc.take() {
        let _ = lock(allocator).free(a);
    }
}

pub(super) fn write_buffer(b: &mut Buf, data: &[u8]) -> Result<(), String> {
    let slice = b.alloc.as_mut().and_then(|a| a.mapped_slice_mut()).ok_or("buffer is not host visible")?;
    if data.len() > slice.len() {
        return Err(format!("buffer write of {} bytes into {}", data.len(), slice.len()));
    }
    slice[..data.len()].copy_from_slice(data);
    Ok(())
}

/// A host-visible buffer filled with `data` (the meshes are small; an engine would stage).
pub(super) fn upload(
    device: &ash::Device,
    allocator: &Mutex<Allocator>,
    name: &str,
    data: &[u8],
    usage: vk::BufferUsageFlags,
) -> Result<Buf, String> {
    let mut b = create_buffer(device, allocator, name, data.len() as u64, usage, MemoryLocation::CpuToGpu)?;
    if let Err(e) = write_buffer(&mut b, data) {
        free_buffer(device, allocator, b);
        return Err(e);
    }
    Ok(b)
}

/// A 2D image of `samples` samples, its memory, and a view of `aspect`.
#[allow(clippy::too_many_arguments)]
pub(super) fn create_image(
    device: &ash::Device,
    allocator: &Mutex<Allocator>,
    name: &str,
    format: vk::Format,
    extent: vk::Extent2D,
    samples: u32,
    usage: vk::ImageUsageFlags,
    aspect: vk::ImageAspectFlags,
) -> Result<Img, String> {
    let info = vk::ImageCreateInfo::default()
        .image_type(vk::ImageType::TYPE_2D)
        .format(format)
        .extent(vk::Extent3D { width: extent.width, height: extent.height, depth: 1 })
        .mip_levels(1)
        .array_layers(1)
        .samples(vk::SampleCountFlags::from_raw(samples))
        .tiling(vk::ImageTiling::OPTIMAL)
        .usage(usage)
        .initial_layout(vk::ImageLayout::UNDEFINED);
    // SAFETY: a valid create info on a valid device.
    let raw = unsafe { device.create_image(&info, None) }.map_err(vkerr("vkCreateImage"))?;
    // SAFETY: `raw` is a new image of this device.
    let requirements = unsafe { device.get_image_memory_requirements(raw) };
    let desc = AllocationCreateDesc {
        name,
        requirements,
        location: MemoryLocation::GpuOnly,
        linear: false,
        allocation_scheme: AllocationScheme::GpuAllocatorManaged,
    };
    let alloc = match lock(allocator).allocate(&desc) {
        Ok(a) => a,
        Err(e) => {
            // SAFETY: the image was never used.
            unsafe { device.destroy_image(raw, None) };
            return Err(format!("allocating image {name}: {e}"));
        }
    };
    // SAFETY: the allocation satisfies the image's requirements; the view covers its only
    // subresource once the memory is bound.
    let view = unsafe { device.bind_image_memory(raw, alloc.memory(), alloc.offset()) }
        .map_err(vkerr("vkBindImageMemory"))
        .and_then(|_| create_view(device, raw, format, aspect));
    match view {
        Ok(view) => Ok(Img { raw, view, alloc: Some(alloc) }),
        Err(e) => {
            // SAFETY: the image was never used.
            unsafe { device.destroy_image(raw, None) };
            let _ = lock(allocator).free(alloc);
            Err(format!("image {name}: {e}"))
        }
    }
}

/// A 2D view of `aspect` of the image's only subresource.
pub(super) fn create_view(
    device: &ash::Device,
    image: vk::Image,
    format: vk::Format,
    aspect: vk::ImageAspectFlags,
) -> Result<vk::ImageView, String> {
    let range = vk::ImageSubresourceRange { aspect_mask: aspect, base_mip_level: 0, level_count: 1, base_array_layer: 0, layer_count: 1 };
    let info =
        vk::ImageViewCreateInfo::default().image(image).view_type(vk::ImageViewType::TYPE_2D).format(format).subresource_range(range);
    // SAFETY: `image` is a live image of this device with memory bound.
    unsafe { device.create_image_view(&info, None) }.map_err(vkerr("vkCreateImageView"))
}

/// An image layout transition of one image's whole subresource (Vulkan 1.0 barrier: the
/// host runs on Vulkan 1.1 devices too).
#[allow(clippy::too_many_arguments)]
pub(super) fn image_barrier(
    device: &ash::Device,
    cb: vk::CommandBuffer,
    image: vk::Image,
    aspect: vk::ImageAspectFlags,
    layouts: (vk::ImageLayout, vk::ImageLayout),
    src: (vk::PipelineStageFlags, vk::AccessFlags),
    dst: (vk::PipelineStageFlags, vk::AccessFlags),
) {
    let b = [vk::ImageMemoryBarrier::default()
        .src_access_mask(src.1)
        .dst_access_mask(dst.1)
        .old_layout(layouts.0)
        .new_layout(layouts.1)
        .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
        .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
        .image(image)
        .subresource_range(vk::ImageSubresourceRange {
            aspect_mask: aspect,
            base_mip_level: 0,
            level_count: 1,
            base_array_layer: 0,
            layer_count: 1,
        })];
    // SAFETY: `cb` is recording outside a rendering instance or render pass; the image
    // belongs to this device.
    unsafe { device.cmd_pipeline_barrier(cb, src.0, dst.0, vk::DependencyFlags::empty(), &[], &[], &b) };
}

/// A global memory barrier (Vulkan 1.0).
pub(super) fn memory_barrier(
    device: &ash::Device,
    cb: vk::CommandBuffer,
    src: (vk::PipelineStageFlags, vk::AccessFlags),
    dst: (vk::PipelineStageFlags, vk::AccessFlags),
) {
    let b = [vk::MemoryBarrier::default().src_access_mask(src.1).dst_access_mask(dst.1)];
    // SAFETY: `cb` is recording outside a rendering instance or render pass.
    unsafe { device.cmd_pipeline_barrier(cb, src.0, dst.0, vk::DependencyFlags::empty(), &b, &[], &[]) };
}
