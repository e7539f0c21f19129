//! Physical-device choice and feature probing for [`super::Context`]: which device, what it
//! has (through the Vulkan 1.0 queries, `VK_KHR_get_physical_device_properties2` or the 1.1
//! ones, whichever the device's version allows), and the logical device with it enabled.

use super::context::{version_string, DeviceInfo, Features};
use crate::error::{Error, Result};
use ash::vk;
use std::ffi::CStr;

fn vkerr(call: &'static str) -> impl Fn(vk::Result) -> Error {
    Error::vk(call)
}

/// The oldest device a context accepts.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Minimum {
    /// Vulkan 1.3 with `dynamicRendering` and `synchronization2`: the renderer and the viewer.
    Vulkan13,
    /// Any Vulkan device: the conformance suite and `umbrage info`.
    Vulkan10,
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
    let v11 = api >= vk::API_VERSION_1_1;
    let v12 = api >= vk::API_VERSION_1_2;
    let v13 = api >= vk::API_VERSION_1_3;

    // Probe optional features: through the Vulkan 1.1 core query, or on a Vulkan 1.0 device
    // through VK_KHR_get_physical_device_properties2 (when the loader has it; otherwise
    // only the 1.0 features are known).
    // SAFETY: enumeration of extensions on a valid physical device.
    let exts =
        unsafe { instance.enumerate_device_extension_properties(physical) }.map_err(vkerr("vkEnumerateDeviceExtensionProperties"))?;
    let has_ext = |n: &CStr| exts.iter().any(|e| e.extension_name_as_c_str().map(|x| x == n).unwrap_or(false));
    let can_query2 = v11 || gpdp2.is_some();
    let has_u8_ext = has_ext(ash::ext::index_type_uint8::NAME) && can_query2;
    let has_dru = has_ext(ash::ext::depth_range_unrestricted::NAME);
    // Ray query (`--method rayquery`): the two extensions, deferred host operations (which
    // acceleration structures require) and buffer device addresses (Vulkan 1.2 core).
    let has_rq_exts = v12
        && [ash::khr::acceleration_structure::NAME, ash::khr::ray_query::NAME, ash::khr::deferred_host_operations::NAME]
            .into_iter()
            .all(has_ext);
    let Probed { base, dyn_rendering, sync2, u8_supported, ray_query, multiview } =
        probe_features(instance, gpdp2, physical, (v11, v12, v13), has_u8_ext, has_rq_exts);
    if minimum == Minimum::Vulkan13 && (!dyn_rendering || !sync2) {
        return Err(Error::Unsupported(format!("{name}: umbrage needs dynamicRendering and synchronization2 (Vulkan 1.3)")));
    }
    // SAFETY: as above.
    let families = unsafe { instance.get_physical_device_queue_family_properties(physical) };
    let timestamps = families[queue_family as usize].timestamp_valid_bits > 0 && props.limits.timestamp_period > 0.0;

    let depth_format = depth_stencil_format(instance, physical, v11, &name)?;

    let blendable = |f: vk::Format| {
        // SAFETY: format query on a valid physical device.
        let p = unsafe { instance.get_physical_device_format_properties(physical, f) };
        p.optimal_tiling_features.contains(vk::FormatFeatureFlags::COLOR_ATTACHMENT_BLEND)
    };
    let features = Features {
        api_version: api,
        dynamic_rendering: v13 && dyn_rendering,
        synchronization2: v13 && sync2,
        extended_dynamic_state: v13,
        depth_clamp: base.depth_clamp == vk::TRUE,
        depth_bounds: base.depth_bounds == vk::TRUE,
        depth_range_unrestricted: has_dru,
        index_type_uint8: u8_supported,
        pipeline_statistics_query: base.pipeline_statistics_query == vk::TRUE,
        occlusion_query_precise: base.occlusion_query_precise == vk::TRUE,
        timestamps,
        timestamp_period_ns: props.limits.timestamp_period,
        depth_stencil_format: format!("{depth_format:?}"),
        geometry_shader: base.geometry_shader == vk::TRUE,
        r32f_blend: blendable(vk::Format::R32_SFLOAT),
        rgba32f_blend: blendable(vk::Format::R32G32B32A32_SFLOAT),
        ray_query,
        multiview,
        sample_rate_shading: base.sample_rate_shading == vk::TRUE,
        standard_sample_locations: props.limits.standard_sample_locations == vk::TRUE,
        frame_sample_counts: {
            let l = &props.limits;
            (l.framebuffer_color_sample_counts
                & l.framebuffer_depth_sample_counts
                & l.framebuffer_stencil_sample_counts
                & l.sampled_image_color_sample_counts
                & l.sampled_image_integer_sample_counts
                & l.sampled_image_stencil_sample_counts)
                .as_raw()
        },
    };

    let enabled = vk::PhysicalDeviceFeatures::default()
        .depth_clamp(features.depth_clamp)
        .depth_bounds(features.depth_bounds)
        .pipeline_statistics_query(features.pipeline_statistics_query)
        .occlusion_query_precise(features.occlusion_query_precise)
        .sample_rate_shading(features.sample_rate_shading);
    let mut e13 = vk::PhysicalDeviceVulkan13Features::default()
        .dynamic_rendering(features.dynamic_rendering)
        .synchronization2(features.synchronization2);
    let mut e_u8 = vk::PhysicalDeviceIndexTypeUint8FeaturesEXT::default().index_type_uint8(true);
    let mut e_as = vk::PhysicalDeviceAccelerationStructureFeaturesKHR::default().acceleration_structure(true);
    let mut e_rq = vk::PhysicalDeviceRayQueryFeaturesKHR::default().ray_query(true);
    let mut e12 = vk::PhysicalDeviceVulkan12Features::default().buffer_device_address(true);
    let mut e11 = vk::PhysicalDeviceVulkan11Features::default().multiview(true);
    let mut dev_exts = Vec::new();
    if ray_query {
        for e in [ash::khr::acceleration_structure::NAME, ash::khr::ray_query::NAME, ash::khr::deferred_host_operations::NAME] {
            dev_exts.push(e.as_ptr());
        }
    }
    if u8_supported {
        dev_exts.push(ash::ext::index_type_uint8::NAME.as_ptr());
    }
    if has_dru {
        dev_exts.push(ash::ext::depth_range_unrestricted::NAME.as_ptr());
    }
    for &e in extra_extensions {
        if !has_ext(e) {
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
        dinfo = dinfo.push_next(&mut e_as).push_next(&mut e_rq).push_next(&mut e12);
    }
    // SAFETY: all pointers refer to locals alive for the call.
    let device = unsafe { instance.create_device(physical, &dinfo, None) }.map_err(vkerr("vkCreateDevice"))?;

    let has_driver_props = api >= vk::API_VERSION_1_2 || (has_ext(ash::khr::driver_properties::NAME) && can_query2);
    let info = device_info(instance, gpdp2, physical, &props, name, has_driver_props);
    Ok(OpenedDevice { physical, device, queue_family, features, info, depth_format, limits: props.limits })
}

/// What [`probe_features`] found.
struct Probed {
    base: vk::PhysicalDeviceFeatures,
    dyn_rendering: bool,
    sync2: bool,
    u8_supported: bool,
    ray_query: bool,
    multiview: bool,
}

/// The device's features: through the Vulkan 1.1 core query, or on a Vulkan 1.0 device through
/// `VK_KHR_get_physical_device_properties2` (`gpdp2`, when the loader has it; otherwise only
/// the 1.0 features). A structure is chained only where the device's version (`v11`, `v13`)
/// or extensions (`has_u8_ext`, `has_rq_exts`) define it; `multiview` is read from the
/// Vulkan 1.2 `Vulkan11Features` structure.
fn probe_features(
    instance: &ash::Instance,
    gpdp2: Option<&ash::khr::get_physical_device_properties2::Instance>,
    physical: vk::PhysicalDevice,
    (v11, v12, v13): (bool, bool, bool),
    has_u8_ext: bool,
    has_rq_exts: bool,
) -> Probed {
    let mut f_as = vk::PhysicalDeviceAccelerationStructureFeaturesKHR::default();
    let mut f_rq = vk::PhysicalDeviceRayQueryFeaturesKHR::default();
    let mut f12 = vk::PhysicalDeviceVulkan12Features::default();
    let mut f_u8 = vk::PhysicalDeviceIndexTypeUint8FeaturesEXT::default();
    let mut f13 = vk::PhysicalDeviceVulkan13Features::default();
    let mut f11 = vk::PhysicalDeviceVulkan11Features::default();
    let mut f2 = vk::PhysicalDeviceFeatures2::default();
    if v13 {
        f2 = f2.push_next(&mut f13);
    }
    // The Vulkan11Features structure is defined from Vulkan 1.2 (1.1 has the per-feature ones).
    if v12 {
        f2 = f2.push_next(&mut f11);
    }
    if has_u8_ext {
        f2 = f2.push_next(&mut f_u8);
    }
    if has_rq_exts {
        f2 = f2.push_next(&mut f_as).push_next(&mut f_rq).push_next(&mut f12);
    }
    // SAFETY: the chain points at locals alive for this call; a struct is chained only when
    // the device's version or extensions define it.
    unsafe {
        match (v11, gpdp2) {
            (true, _) => instance.get_physical_device_features2(physical, &mut f2),
            (false, Some(g)) => g.get_physical_device_features2(physical, &mut f2),
            (false, None) => f2.features = instance.get_physical_device_features(physical),
        }
    }
    let base = f2.features;
    let (dyn_rendering, sync2) = (f13.dynamic_rendering == vk::TRUE, f13.synchronization2 == vk::TRUE);
    let u8_supported = has_u8_ext && f_u8.index_type_uint8 == vk::TRUE;
    let ray_query =
        has_rq_exts && f_as.acceleration_structure == vk::TRUE && f_rq.ray_query == vk::TRUE && f12.buffer_device_address == vk::TRUE;
    let multiview = v12 && f11.multiview == vk::TRUE;
    Probed { base, dyn_rendering, sync2, u8_supported, ray_query, multiview }
}

/// The physical device [`open_device`] uses.
struct Picked {
    physical: vk::PhysicalDevice,
    queue_family: u32,
    props: vk::PhysicalDeviceProperties,
    name: String,
}

/// The best device of at least `minimum` with a graphics queue (discrete, integrated, virtual,
/// CPU, in that order; only those whose name contains `UMBRAGE_DEVICE` when it is set).
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
    let mut candidates = Vec::new();
    let mut too_old = Vec::new();
    for &pd in &physicals {
        // SAFETY: `pd` comes from the enumeration above.
        let props = unsafe { instance.get_physical_device_properties(pd) };
        let name = props.device_name_as_c_str().map(|c| c.to_string_lossy().into_owned()).unwrap_or_default();
        if let Some(w) = &wanted {
            if !name.to_lowercase().contains(w) {
                continue;
            }
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
            Some(w) => format!("no {min_name} device with graphics whose name contains '{w}' (UMBRAGE_DEVICE)"),
            None => format!("no {min_name} device with a graphics queue"),
        }));
    };
    Ok(Picked { physical, queue_family, props, name })
}

/// A depth-stencil format with 8 stencil bits, usable as attachment and transfer source.
fn depth_stencil_format(instance: &ash::Instance, physical: vk::PhysicalDevice, v11: bool, name: &str) -> Result<vk::Format> {
    let needed = vk::FormatFeatureFlags::DEPTH_STENCIL_ATTACHMENT | vk::FormatFeatureFlags::TRANSFER_SRC;
    [vk::Format::D32_SFLOAT_S8_UINT, vk::Format::D24_UNORM_S8_UINT]
        .into_iter()
        .find(|&f| {
            // SAFETY: format query on a valid physical device.
            let p = unsafe { instance.get_physical_device_format_properties(physical, f) };
            // Vulkan 1.0 has no TRANSFER_SRC format feature (VK_KHR_maintenance1): every
            // attachment format may be copied there.
            p.optimal_tiling_features.contains(if v11 { needed } else { vk::FormatFeatureFlags::DEPTH_STENCIL_ATTACHMENT })
        })
        .ok_or_else(|| Error::Unsupported(format!("{name}: no depth-stencil format with 8 stencil bits (D32S8 or D24S8)")))
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
