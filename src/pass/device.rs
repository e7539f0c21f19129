//! The host's device and allocator, as the GPU helpers see them.

use super::desc::{Capabilities, ShadowPassDesc, TargetModel};
use super::pipelines::COUNT_FORMAT;
use crate::error::{Error, Result};
use crate::gpu::caps::DeviceCaps;
use crate::gpu::context::{lock_allocator, GpuDevice};
use ash::vk;
use gpu_allocator::vulkan::Allocator;
use std::sync::{Arc, Mutex};

/// A clone of the host's `ash::Device` (a table of function pointers, not the device's
/// ownership) and a shared handle on its allocator.
pub(crate) struct PassDevice {
    pub device: ash::Device,
    pub allocator: Arc<Mutex<Allocator>>,
    /// The host's pipeline cache ([`ShadowPassDesc::pipeline_cache`]), or null.
    pub pipeline_cache: vk::PipelineCache,
    /// The device's `maxStorageBufferRange` (the compute pass's tables and lists are bound
    /// whole, each at most this long).
    pub max_storage_range: u64,
    /// The device's `maxDrawIndirectCount` (the merged draws split a longer list).
    pub max_draw_indirect_count: u32,
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
    fn pipeline_cache(&self) -> vk::PipelineCache {
        self.pipeline_cache
    }
}

/// What a pass made with `desc` can use on the device `caps` describes, or why
/// [`ShadowPass::new`](super::ShadowPass::new) would refuse it: the Vulkan version, the target
/// model, the depth-stencil format and sample count, and the host's enabled features
/// intersected with the device's. A pure function of `caps`, so a report of a device decides
/// the same as the device itself.
pub(super) fn capabilities(caps: &DeviceCaps, desc: &ShadowPassDesc) -> Result<Capabilities> {
    let api = caps.api_version;
    let version = |v: u32| format!("{}.{}", vk::api_version_major(v), vk::api_version_minor(v));
    if api < vk::API_VERSION_1_1 {
        return Err(Error::Unsupported(format!("the shadow pass needs Vulkan 1.1; the device has {}", version(api))));
    }
    let f = &caps.features;
    if desc.target == TargetModel::DynamicRendering && !(api >= vk::API_VERSION_1_3 && f.dynamic_rendering) {
        return Err(Error::Unsupported(format!(
            "TargetModel::DynamicRendering needs Vulkan 1.3 with dynamicRendering; the device has {} without it: \
             use TargetModel::RenderPass",
            version(api)
        )));
    }
    if !caps.format_features(desc.depth_stencil_format).contains(vk::FormatFeatureFlags::DEPTH_STENCIL_ATTACHMENT) {
        return Err(Error::Unsupported(format!("{:?} is not a depth-stencil attachment format on this device", desc.depth_stencil_format)));
    }
    check_samples(caps, desc)?;
    let blend = vk::FormatFeatureFlags::COLOR_ATTACHMENT | vk::FormatFeatureFlags::COLOR_ATTACHMENT_BLEND;
    for (field, format) in
        [("ShadowPassDesc::transmit_format", desc.transmit_format), ("ShadowPassDesc::debug_color_format", desc.debug_color_format)]
    {
        if let Some(f) = format {
            if !caps.format_features(f).contains(blend) {
                return Err(Error::desc(field, format!("{f:?} is not a blendable colour attachment format on this device")));
            }
        }
    }
    let has = |n: &std::ffi::CStr| caps.has_extension(n);
    let ray_query = api >= vk::API_VERSION_1_2
        && has(ash::khr::acceleration_structure::NAME)
        && has(ash::khr::ray_query::NAME)
        && has(ash::khr::deferred_host_operations::NAME)
        && f.ray_query
        && f.acceleration_structure
        && f.buffer_device_address;
    let u8_ext = has(ash::ext::index_type_uint8::NAME) || has(ash::khr::index_type_uint8::NAME);
    let mesh_shader = api >= vk::API_VERSION_1_2 && has(ash::ext::mesh_shader::NAME) && f.mesh_shader;
    Ok(Capabilities {
        ray_query: desc.features.ray_query && ray_query,
        depth_clamp: desc.features.depth_clamp && f.depth_clamp,
        depth_bounds: desc.features.depth_bounds && f.depth_bounds,
        index_type_uint8: desc.features.index_type_uint8 && u8_ext && f.index_type_uint8,
        r32f_blend: caps.format_features(COUNT_FORMAT).contains(vk::FormatFeatureFlags::COLOR_ATTACHMENT_BLEND)
            && desc.target == TargetModel::DynamicRendering,
        mesh_shader: desc.features.mesh_shader && mesh_shader,
        draw_indirect_first_instance: desc.features.draw_indirect_first_instance && f.draw_indirect_first_instance,
        multi_draw_indirect: desc.features.multi_draw_indirect && f.multi_draw_indirect,
        draw_indirect_count: desc.features.draw_indirect_count && api >= vk::API_VERSION_1_2 && f.draw_indirect_count,
        task_shader: desc.features.mesh_shader && mesh_shader && desc.features.task_shader && f.task_shader,
    })
}

/// Refuses a sample count the device's framebuffer limits or the depth-stencil format lack
/// (the format's image sample counts where `caps` knows them).
fn check_samples(caps: &DeviceCaps, desc: &ShadowPassDesc) -> Result<()> {
    let flag = super::desc::sample_flags(desc.samples);
    let limits = &caps.limits;
    let framebuffer = limits.framebuffer_depth_sample_counts & limits.framebuffer_stencil_sample_counts;
    let image =
        caps.depth_stencil_image_samples.iter().find(|(f, _)| *f == desc.depth_stencil_format).map_or(framebuffer, |&(_, counts)| counts);
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

/// What the pass asks of every technique's state, whichever technique the frame runs.
pub(super) trait TechniqueState {
    /// The ring slot's previous frame retired: release what only that frame used.
    fn slot_retired(&mut self, _dev: &PassDevice, _slot: usize) {}
    /// Releases every object (the pass is dropped, after every frame that used it completed).
    fn destroy(&mut self, dev: &PassDevice);
}
