//! The host's device and allocator, as the GPU helpers see them.

use super::desc::ShadowPassDesc;
use crate::error::{Error, Result};
use crate::gpu::context::{lock_allocator, GpuDevice};
use ash::vk;
use gpu_allocator::vulkan::Allocator;
use std::sync::{Arc, Mutex};

/// A clone of the host's `ash::Device` (a table of function pointers, not the device's
/// ownership) and a shared handle on its allocator.
pub(crate) struct PassDevice {
    pub device: ash::Device,
    pub allocator: Arc<Mutex<Allocator>>,
}

impl GpuDevice for PassDevice {
    fn device(&self) -> &ash::Device {
        &self.device
    }
    fn allocator(&self) -> std::sync::MutexGuard<'_, Allocator> {
        lock_allocator(&self.allocator)
    }
    /// The pass asks for Vulkan 1.1 only: its barriers are Vulkan 1.0 `vkCmdPipelineBarrier`.
    fn synchronization2(&self) -> bool {
        false
    }
}

/// Whether the device can do dynamic rendering: Vulkan 1.3 with `dynamicRendering`.
pub(super) fn dynamic_rendering_supported(instance: &ash::Instance, pd: vk::PhysicalDevice, api: u32) -> bool {
    if api < vk::API_VERSION_1_3 {
        return false;
    }
    let mut f13 = vk::PhysicalDeviceVulkan13Features::default();
    let mut f2 = vk::PhysicalDeviceFeatures2::default().push_next(&mut f13);
    // SAFETY: a feature query on a valid Vulkan 1.3 physical device with a well-formed pNext chain.
    unsafe { instance.get_physical_device_features2(pd, &mut f2) };
    f13.dynamic_rendering == vk::TRUE
}

/// Refuses a sample count the device's framebuffer limits or the depth-stencil format lack.
pub(super) fn check_samples(
    instance: &ash::Instance,
    pd: vk::PhysicalDevice,
    limits: &vk::PhysicalDeviceLimits,
    desc: &ShadowPassDesc,
) -> Result<()> {
    let flag = super::desc::sample_flags(desc.samples);
    let framebuffer = limits.framebuffer_depth_sample_counts & limits.framebuffer_stencil_sample_counts;
    // SAFETY: a format query on a valid physical device.
    let image = unsafe {
        instance.get_physical_device_image_format_properties(
            pd,
            desc.depth_stencil_format,
            vk::ImageType::TYPE_2D,
            vk::ImageTiling::OPTIMAL,
            vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT,
            vk::ImageCreateFlags::empty(),
        )
    }
    .map(|p| p.sample_counts)
    .unwrap_or(vk::SampleCountFlags::empty());
    if !framebuffer.contains(flag) || !image.contains(flag) {
        let counts = |f: vk::SampleCountFlags| {
            [1u32, 2, 4, 8, 16, 32, 64].into_iter().filter(|&n| f.as_raw() & n != 0).map(|n| n.to_string()).collect::<Vec<_>>().join(", ")
        };
        return Err(Error::Unsupported(format!(
            "{} samples: this device supports {} for {:?} depth-stencil attachments",
            desc.samples,
            counts(framebuffer & image),
            desc.depth_stencil_format
        )));
    }
    Ok(())
}

pub(super) fn index_type_uint8_supported(instance: &ash::Instance, pd: vk::PhysicalDevice) -> bool {
    // SAFETY: enumeration on a valid physical device.
    let exts = unsafe { instance.enumerate_device_extension_properties(pd) }.unwrap_or_default();
    let named = |n: &std::ffi::CStr| exts.iter().any(|e| e.extension_name_as_c_str().map(|x| x == n).unwrap_or(false));
    if !named(ash::ext::index_type_uint8::NAME) && !named(ash::khr::index_type_uint8::NAME) {
        return false;
    }
    let mut u8f = vk::PhysicalDeviceIndexTypeUint8FeaturesEXT::default();
    let mut f2 = vk::PhysicalDeviceFeatures2::default().push_next(&mut u8f);
    // SAFETY: a feature query on a valid physical device with a well-formed pNext chain.
    unsafe { instance.get_physical_device_features2(pd, &mut f2) };
    u8f.index_type_uint8 == vk::TRUE
}

/// Whether the device can trace ray queries: Vulkan 1.2 (`bufferDeviceAddress`),
/// `VK_KHR_acceleration_structure` and `VK_KHR_ray_query` with their features.
pub(super) fn ray_query_supported(instance: &ash::Instance, pd: vk::PhysicalDevice, api: u32) -> bool {
    if api < vk::API_VERSION_1_2 {
        return false;
    }
    // SAFETY: a plain query on a valid physical device.
    let Ok(exts) = (unsafe { instance.enumerate_device_extension_properties(pd) }) else { return false };
    let has = |name: &std::ffi::CStr| exts.iter().any(|e| e.extension_name_as_c_str() == Ok(name));
    if !has(ash::khr::acceleration_structure::NAME) || !has(ash::khr::ray_query::NAME) || !has(ash::khr::deferred_host_operations::NAME) {
        return false;
    }
    let mut rq = vk::PhysicalDeviceRayQueryFeaturesKHR::default();
    let mut acc = vk::PhysicalDeviceAccelerationStructureFeaturesKHR::default();
    let mut v12 = vk::PhysicalDeviceVulkan12Features::default();
    let mut f2 = vk::PhysicalDeviceFeatures2::default().push_next(&mut rq).push_next(&mut acc).push_next(&mut v12);
    // SAFETY: a feature query on a valid Vulkan 1.2 physical device with a well-formed pNext chain.
    unsafe { instance.get_physical_device_features2(pd, &mut f2) };
    rq.ray_query == vk::TRUE && acc.acceleration_structure == vk::TRUE && v12.buffer_device_address == vk::TRUE
}
