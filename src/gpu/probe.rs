//! Physical-device choice and feature probing for [`super::Context`]: which device, what it
//! has (through the Vulkan 1.0 queries, `VK_KHR_get_physical_device_properties2` or the 1.1
//! ones, whichever the device's version allows), and the logical device with it enabled.

use super::caps::{choose, version_string, Choice, DeviceCaps, DeviceInfo, Features, Minimum};
use crate::error::{Error, Result};
use ash::vk;
use std::ffi::CStr;

fn vkerr(call: &'static str) -> impl Fn(vk::Result) -> Error {
    Error::vk(call)
}

/// The device [`open_device`] created, and what was learnt of it on the way.
pub(super) struct OpenedDevice {
    /// The physical device picked.
    pub physical: vk::PhysicalDevice,
    /// The logical device, with the probed optional features enabled.
    pub device: ash::Device,
    /// The graphics (and compute) queue family; queue 0 of it was created.
    pub queue_family: u32,
    /// The optional features probed and enabled.
    pub features: Features,
    /// Name, driver and version.
    pub info: DeviceInfo,
    /// The depth-stencil format the renderer uses.
    pub depth_format: vk::Format,
    /// The physical device's limits.
    pub limits: vk::PhysicalDeviceLimits,
}

/// Picks the physical device (the best-ranked one with a graphics queue at `minimum` or newer,
/// or the one `UMBRAGE_DEVICE` names), probes its optional features through the queries its
/// version has, and creates the logical device with them enabled.
pub(super) fn open_device(
    instance: &ash::Instance,
    gpdp2: Option<&ash::khr::get_physical_device_properties2::Instance>,
    extra_extensions: &[&CStr],
    minimum: Minimum,
) -> Result<OpenedDevice> {
    let Picked { physical, queue_family, props, name } = pick_physical(instance, minimum)?;
    let api = props.api_version;
    let v13 = api >= vk::API_VERSION_1_3;
    let caps = DeviceCaps::query(instance, gpdp2, physical)?;
    let Choice { features, depth_format, extensions } = choose(&caps, minimum)?;
    let ray_query = features.ray_query;
    let u8_supported = features.index_type_uint8;
    let multiview = features.multiview;
    let mesh_shader = features.mesh_shader;
    let enabled = vk::PhysicalDeviceFeatures::default()
        .depth_clamp(features.depth_clamp)
        .depth_bounds(features.depth_bounds)
        .pipeline_statistics_query(features.pipeline_statistics_query)
        .occlusion_query_precise(features.occlusion_query_precise)
        .sample_rate_shading(features.sample_rate_shading)
        .multi_draw_indirect(features.multi_draw_indirect)
        .draw_indirect_first_instance(features.draw_indirect_first_instance);
    let mut e13 = vk::PhysicalDeviceVulkan13Features::default()
        .dynamic_rendering(features.dynamic_rendering)
        .synchronization2(features.synchronization2);
    let mut e_u8 = vk::PhysicalDeviceIndexTypeUint8FeaturesEXT::default().index_type_uint8(true);
    let mut e_as = vk::PhysicalDeviceAccelerationStructureFeaturesKHR::default().acceleration_structure(true);
    let mut e_rq = vk::PhysicalDeviceRayQueryFeaturesKHR::default().ray_query(true);
    let mut e12 =
        vk::PhysicalDeviceVulkan12Features::default().buffer_device_address(ray_query).draw_indirect_count(features.draw_indirect_count);
    let mut e11 = vk::PhysicalDeviceVulkan11Features::default().multiview(true);
    let mut e_mesh = vk::PhysicalDeviceMeshShaderFeaturesEXT::default().mesh_shader(true).task_shader(features.task_shader);
    let mut dev_exts: Vec<_> = extensions.iter().map(|e| e.as_ptr()).collect();
    for &e in extra_extensions {
        if !caps.has_extension(e) {
            return Err(Error::Unsupported(format!("{name}: the device lacks {}", e.to_string_lossy())));
        }
        dev_exts.push(e.as_ptr());
    }
    let prio = [1.0f32];
    let qinfo = [vk::DeviceQueueCreateInfo::default().queue_family_index(queue_family).queue_priorities(&prio)];
    let mut dinfo =
        vk::DeviceCreateInfo::default().queue_create_infos(&qinfo).enabled_features(&enabled).enabled_extension_names(&dev_exts);
    if v13 {
        dinfo = dinfo.push_next(&mut e13);
    }
    if u8_supported {
        dinfo = dinfo.push_next(&mut e_u8);
    }
    if multiview {
        dinfo = dinfo.push_next(&mut e11);
    }
    if ray_query {
        dinfo = dinfo.push_next(&mut e_as).push_next(&mut e_rq);
    }
    // Vulkan 1.2's features: bufferDeviceAddress (ray query), drawIndirectCount.
    if ray_query || features.draw_indirect_count {
        dinfo = dinfo.push_next(&mut e12);
    }
    if mesh_shader {
        dinfo = dinfo.push_next(&mut e_mesh);
    }
    // SAFETY: all pointers refer to locals alive for the call.
    let device = unsafe { instance.create_device(physical, &dinfo, None) }.map_err(vkerr("vkCreateDevice"))?;

    let can_query2 = api >= vk::API_VERSION_1_1 || gpdp2.is_some();
    let has_driver_props = api >= vk::API_VERSION_1_2 || (caps.has_extension(ash::khr::driver_properties::NAME) && can_query2);
    let info = device_info(instance, gpdp2, physical, &props, name, has_driver_props);
    Ok(OpenedDevice { physical, device, queue_family, features, info, depth_format, limits: props.limits })
}

/// The physical device [`open_device`] uses.
struct Picked {
    physical: vk::PhysicalDevice,
    queue_family: u32,
    props: vk::PhysicalDeviceProperties,
    name: String,
}

/// The best device of at least `minimum` with a graphics queue (discrete, integrated, virtual,
/// CPU, in that order; only those whose name contains `UMBRAGE_DEVICE` when it is set, or only
/// the N-th of `vkEnumeratePhysicalDevices`' order, 1-based, when it is `#N`: what VK-GL-CTS's
/// `--deqp-vk-device-id=N` picks, whatever the devices' names).
fn pick_physical(instance: &ash::Instance, minimum: Minimum) -> Result<Picked> {
    let min_version = match minimum {
        Minimum::Vulkan13 => vk::API_VERSION_1_3,
        Minimum::Vulkan10 => vk::API_VERSION_1_0,
    };
    let min_name = match minimum {
        Minimum::Vulkan13 => "Vulkan 1.3",
        Minimum::Vulkan10 => "Vulkan",
    };
    // SAFETY: enumeration on a valid instance.
    let physicals = unsafe { instance.enumerate_physical_devices() }.map_err(vkerr("vkEnumeratePhysicalDevices"))?;
    if physicals.is_empty() {
        return Err(Error::NoDevice("the Vulkan loader found no physical device".into()));
    }
    let wanted = std::env::var("UMBRAGE_DEVICE").ok().map(|s| s.to_lowercase());
    let index = wanted.as_deref().and_then(device_index);
    if let Some(k) = index {
        if k == 0 || k > physicals.len() {
            return Err(Error::NoDevice(format!(
                "UMBRAGE_DEVICE=#{k}: there are {} Vulkan devices (1-based, in vkEnumeratePhysicalDevices' order)",
                physicals.len()
            )));
        }
    }
    let mut candidates = Vec::new();
    let mut too_old = Vec::new();
    for (i, &pd) in physicals.iter().enumerate() {
        // SAFETY: `pd` comes from the enumeration above.
        let props = unsafe { instance.get_physical_device_properties(pd) };
        let name = props.device_name_as_c_str().map(|c| c.to_string_lossy().into_owned()).unwrap_or_default();
        match (index, &wanted) {
            (Some(k), _) if k != i + 1 => continue,
            (None, Some(w)) if !name.to_lowercase().contains(w) => continue,
            _ => {}
        }
        if props.api_version < min_version {
            too_old.push(format!("{name} (Vulkan {})", version_string(props.api_version)));
            continue;
        }
        // SAFETY: as above.
        let families = unsafe { instance.get_physical_device_queue_family_properties(pd) };
        let Some(qf) = families.iter().position(|f| f.queue_flags.contains(vk::QueueFlags::GRAPHICS)) else {
            continue;
        };
        let rank = match props.device_type {
            vk::PhysicalDeviceType::DISCRETE_GPU => 0,
            vk::PhysicalDeviceType::INTEGRATED_GPU => 1,
            vk::PhysicalDeviceType::VIRTUAL_GPU => 2,
            vk::PhysicalDeviceType::CPU => 3,
            _ => 4,
        };
        candidates.push((rank, pd, qf as u32, props, name));
    }
    candidates.sort_by_key(|c| c.0);
    let Some((_, physical, queue_family, props, name)) = candidates.into_iter().next() else {
        if !too_old.is_empty() {
            // A device is there, only too old: not a missing driver.
            return Err(Error::Unsupported(format!(
                "{} has no dynamicRendering and synchronization2 (Vulkan 1.3), which this needs; \
                 `umbrage conform` and `umbrage info` run on any Vulkan 1.0 device, and \
                 `scripts/drivers.sh install 25.0.7` gives a Vulkan 1.4 lavapipe",
                too_old.join(", ")
            )));
        }
        return Err(Error::NoDevice(match wanted {
            Some(w) if index.is_some() => format!("device {w} (UMBRAGE_DEVICE) has no graphics queue"),
            Some(w) => format!("no {min_name} device with graphics whose name contains '{w}' (UMBRAGE_DEVICE)"),
            None => format!("no {min_name} device with a graphics queue"),
        }));
    };
    Ok(Picked { physical, queue_family, props, name })
}

/// `#N` (a 1-based device index, as `UMBRAGE_DEVICE` may give it): N.
pub(crate) fn device_index(wanted: &str) -> Option<usize> {
    wanted.strip_prefix('#')?.parse().ok()
}

/// The device's identification; the driver's name and version string where the device has
/// them (core in 1.2, else `VK_KHR_driver_properties`: `has_driver_props`).
fn device_info(
    instance: &ash::Instance,
    gpdp2: Option<&ash::khr::get_physical_device_properties2::Instance>,
    physical: vk::PhysicalDevice,
    props: &vk::PhysicalDeviceProperties,
    name: String,
    has_driver_props: bool,
) -> DeviceInfo {
    let api = props.api_version;
    let mut driver = vk::PhysicalDeviceDriverProperties::default();
    if has_driver_props {
        let mut p2 = vk::PhysicalDeviceProperties2::default().push_next(&mut driver);
        // SAFETY: chain of locals; the driver-properties struct is defined for this device.
        unsafe {
            match (api >= vk::API_VERSION_1_1, gpdp2) {
                (false, Some(g)) => g.get_physical_device_properties2(physical, &mut p2),
                _ => instance.get_physical_device_properties2(physical, &mut p2),
            }
        }
    }
    DeviceInfo {
        name,
        kind: format!("{:?}", props.device_type),
        driver: driver.driver_name_as_c_str().map(|c| c.to_string_lossy().into_owned()).unwrap_or_default(),
        driver_info: driver.driver_info_as_c_str().map(|c| c.to_string_lossy().into_owned()).unwrap_or_default(),
        api_version: version_string(api),
        vendor_id: props.vendor_id,
        device_id: props.device_id,
    }
}
