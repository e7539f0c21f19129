//! What a physical device offers, as far as umbrage's choices go ([`DeviceCaps`]), and the
//! choices themselves ([`choose`]): what a [`Context`](super::Context) enables and uses, or why
//! it refuses the device. The choices are pure functions of a [`DeviceCaps`], so the same code
//! decides on a live device ([`DeviceCaps::query`]) and on a device report without the device
//! (umbrage's `profiles` module reads gpuinfo.org's reports; `docs/devices.md` is made from
//! them). [`crate::pass::ShadowPass::capabilities_for`] is the pass's side of the same.

use crate::error::{Error, Result};
use ash::vk;
use std::ffi::CStr;

/// The oldest device a context accepts.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Minimum {
    /// Vulkan 1.3 with `dynamicRendering` and `synchronization2`: the renderer and the viewer.
    Vulkan13,
    /// Any Vulkan device: the conformance suite and `umbrage info`.
    Vulkan10,
}

/// The depth-stencil formats with 8 stencil bits umbrage's own frame takes, best first: the
/// float depth keeps far and huge coordinates exact, the 24-bit one is the fallback (AMD
/// has no D24S8, many others prefer it).
pub const FRAME_DEPTH_FORMATS: [vk::Format; 2] = [vk::Format::D32_SFLOAT_S8_UINT, vk::Format::D24_UNORM_S8_UINT];

/// Every format whose optimal-tiling features [`DeviceCaps::query`] reads: the depth-stencil
/// formats a host may hand the shadow pass, and the colour and depth formats of umbrage's own
/// frame (G-buffer, counters, intensity map, shadow maps, output).
pub const QUERIED_FORMATS: [vk::Format; 11] = [
    vk::Format::D16_UNORM_S8_UINT,
    vk::Format::D24_UNORM_S8_UINT,
    vk::Format::D32_SFLOAT_S8_UINT,
    vk::Format::D32_SFLOAT,
    vk::Format::R32_SFLOAT,
    vk::Format::R32G32B32A32_SFLOAT,
    vk::Format::R16G16B16A16_SFLOAT,
    vk::Format::R8G8B8A8_UNORM,
    vk::Format::B8G8R8A8_UNORM,
    vk::Format::R32_UINT,
    vk::Format::R8_UINT,
];

/// The device features umbrage asks about, whichever structure reports them (a feature is
/// `true` when the device reports it; [`choose`] applies the version and extension rules that
/// decide whether it can be enabled).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct FeatureSet {
    /// `depthClamp` (Vulkan 1.0).
    pub depth_clamp: bool,
    /// `depthBounds` (Vulkan 1.0).
    pub depth_bounds: bool,
    /// `pipelineStatisticsQuery` (Vulkan 1.0).
    pub pipeline_statistics_query: bool,
    /// `occlusionQueryPrecise` (Vulkan 1.0).
    pub occlusion_query_precise: bool,
    /// `geometryShader` (Vulkan 1.0; reported, never enabled).
    pub geometry_shader: bool,
    /// `sampleRateShading` (Vulkan 1.0).
    pub sample_rate_shading: bool,
    /// `multiDrawIndirect` (Vulkan 1.0).
    pub multi_draw_indirect: bool,
    /// `drawIndirectFirstInstance` (Vulkan 1.0).
    pub draw_indirect_first_instance: bool,
    /// `multiview` (`VkPhysicalDeviceVulkan11Features`, or `VK_KHR_multiview`'s structure).
    pub multiview: bool,
    /// `drawIndirectCount` (`VkPhysicalDeviceVulkan12Features`).
    pub draw_indirect_count: bool,
    /// `bufferDeviceAddress` (Vulkan 1.2, or `VK_KHR_buffer_device_address`).
    pub buffer_device_address: bool,
    /// `dynamicRendering` (Vulkan 1.3 core, or `VK_KHR_dynamic_rendering`).
    pub dynamic_rendering: bool,
    /// `synchronization2` (Vulkan 1.3 core, or `VK_KHR_synchronization2`).
    pub synchronization2: bool,
    /// `indexTypeUint8` (`VK_EXT_index_type_uint8` / `VK_KHR_index_type_uint8`).
    pub index_type_uint8: bool,
    /// `accelerationStructure` (`VK_KHR_acceleration_structure`).
    pub acceleration_structure: bool,
    /// `rayQuery` (`VK_KHR_ray_query`).
    pub ray_query: bool,
    /// `meshShader` (`VK_EXT_mesh_shader`).
    pub mesh_shader: bool,
    /// `taskShader` (`VK_EXT_mesh_shader`).
    pub task_shader: bool,
}

/// What a physical device offers, as far as umbrage's choices go: read from a live device
/// ([`DeviceCaps::query`]) or from a device report.
#[derive(Clone, Debug, Default)]
pub struct DeviceCaps {
    /// `deviceName`.
    pub name: String,
    /// `deviceType`.
    pub device_type: vk::PhysicalDeviceType,
    /// `apiVersion`, packed.
    pub api_version: u32,
    /// The driver's name (`VkPhysicalDeviceDriverProperties::driverName`), empty if unknown.
    pub driver: String,
    /// The device extensions umbrage asks about that the device has (names).
    pub extensions: Vec<String>,
    /// The features umbrage asks about.
    pub features: FeatureSet,
    /// Optimal-tiling features of the formats in [`QUERIED_FORMATS`] (a format the device
    /// does not list has none).
    pub formats: Vec<(vk::Format, vk::FormatFeatureFlags)>,
    /// The sample counts a 2D depth-stencil attachment image of each format may have
    /// (`vkGetPhysicalDeviceImageFormatProperties`), where known; a report does not carry
    /// them, and then the framebuffer limits alone decide.
    pub depth_stencil_image_samples: Vec<(vk::Format, vk::SampleCountFlags)>,
    /// The device's limits. From a report only the fields umbrage reads are filled (the
    /// rest are zero): the push-constant size, the sample counts, the timestamp period,
    /// `standardSampleLocations`, `maxImageDimension2D`, `maxDrawIndirectCount`,
    /// `maxBoundDescriptorSets`, `maxComputeWorkGroupInvocations`, `maxStorageBufferRange`.
    pub limits: vk::PhysicalDeviceLimits,
    /// The first queue family with graphics (umbrage's queue) and its `timestampValidBits`,
    /// or `None` when the device has no graphics queue.
    pub graphics_queue: Option<(u32, u32)>,
}

impl DeviceCaps {
    /// Whether the device has the extension `name`.
    pub fn has_extension(&self, name: &CStr) -> bool {
        let name = name.to_string_lossy();
        self.extensions.iter().any(|e| *e == name)
    }

    /// The optimal-tiling features of `format` (empty when the device does not list it).
    pub fn format_features(&self, format: vk::Format) -> vk::FormatFeatureFlags {
        self.formats.iter().find(|(f, _)| *f == format).map(|&(_, x)| x).unwrap_or_default()
    }

    /// Whether the device reports the portability subset (MoltenVK and other layered
    /// implementations: not a fully conformant Vulkan).
    pub fn portability_subset(&self) -> bool {
        self.has_extension(c"VK_KHR_portability_subset")
    }

    /// Adds `format`'s optimal-tiling features, read from `physical`, when they are not known
    /// yet (a host's colour format beyond [`QUERIED_FORMATS`]).
    pub fn query_format(&mut self, instance: &ash::Instance, physical: vk::PhysicalDevice, format: vk::Format) {
        if !self.formats.iter().any(|(f, _)| *f == format) {
            // SAFETY: a format query on a valid physical device.
            let p = unsafe { instance.get_physical_device_format_properties(physical, format) };
            self.formats.push((format, p.optimal_tiling_features));
        }
    }

    /// Reads what umbrage asks of `physical`: its properties, the extensions and features of
    /// [`FeatureSet`] (through `vkGetPhysicalDeviceFeatures2` on Vulkan 1.1 devices, or
    /// `gpdp2`'s on a Vulkan 1.0 device where the instance has
    /// `VK_KHR_get_physical_device_properties2`; otherwise the Vulkan 1.0 features only), the
    /// formats of [`QUERIED_FORMATS`] and the queue families. A structure is chained only where
    /// the device's version or extensions define it.
    ///
    /// # Errors
    /// [`Error::Vulkan`] when the extensions cannot be enumerated.
    pub fn query(
        instance: &ash::Instance,
        gpdp2: Option<&ash::khr::get_physical_device_properties2::Instance>,
        physical: vk::PhysicalDevice,
    ) -> Result<DeviceCaps> {
        // SAFETY: plain queries on a valid physical device of `instance`.
        let (props, exts, families) = unsafe {
            (
                instance.get_physical_device_properties(physical),
                instance.enumerate_device_extension_properties(physical).map_err(Error::vk("vkEnumerateDeviceExtensionProperties"))?,
                instance.get_physical_device_queue_family_properties(physical),
            )
        };
        let api = props.api_version;
        let (v11, v12, v13) = (api >= vk::API_VERSION_1_1, api >= vk::API_VERSION_1_2, api >= vk::API_VERSION_1_3);
        let extensions: Vec<String> =
            exts.iter().filter_map(|e| e.extension_name_as_c_str().ok()).map(|n| n.to_string_lossy().into_owned()).collect();
        let has = |n: &CStr| extensions.iter().any(|e| *e == n.to_string_lossy());
        let can_query2 = v11 || gpdp2.is_some();
        let u8_ext = (has(ash::ext::index_type_uint8::NAME) || has(ash::khr::index_type_uint8::NAME)) && can_query2;
        let rq_exts = v12
            && [ash::khr::acceleration_structure::NAME, ash::khr::ray_query::NAME, ash::khr::deferred_host_operations::NAME]
                .into_iter()
                .all(has);
        let mesh_ext = v11 && has(ash::ext::mesh_shader::NAME);

        let mut f_as = vk::PhysicalDeviceAccelerationStructureFeaturesKHR::default();
        let mut f_rq = vk::PhysicalDeviceRayQueryFeaturesKHR::default();
        let mut f_u8 = vk::PhysicalDeviceIndexTypeUint8FeaturesEXT::default();
        let mut f_mesh = vk::PhysicalDeviceMeshShaderFeaturesEXT::default();
        let mut f13 = vk::PhysicalDeviceVulkan13Features::default();
        let mut f12 = vk::PhysicalDeviceVulkan12Features::default();
        let mut f11 = vk::PhysicalDeviceVulkan11Features::default();
        let mut f2 = vk::PhysicalDeviceFeatures2::default();
        if v13 {
            f2 = f2.push_next(&mut f13);
        }
        // The Vulkan11/12Features structures are defined from Vulkan 1.2.
        if v12 {
            f2 = f2.push_next(&mut f11).push_next(&mut f12);
        }
        if u8_ext {
            f2 = f2.push_next(&mut f_u8);
        }
        if rq_exts {
            f2 = f2.push_next(&mut f_as).push_next(&mut f_rq);
        }
        if mesh_ext {
            f2 = f2.push_next(&mut f_mesh);
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
        let t = |b: vk::Bool32| b == vk::TRUE;
        let features = FeatureSet {
            depth_clamp: t(base.depth_clamp),
            depth_bounds: t(base.depth_bounds),
            pipeline_statistics_query: t(base.pipeline_statistics_query),
            occlusion_query_precise: t(base.occlusion_query_precise),
            geometry_shader: t(base.geometry_shader),
            sample_rate_shading: t(base.sample_rate_shading),
            multi_draw_indirect: t(base.multi_draw_indirect),
            draw_indirect_first_instance: t(base.draw_indirect_first_instance),
            multiview: t(f11.multiview),
            draw_indirect_count: t(f12.draw_indirect_count),
            buffer_device_address: t(f12.buffer_device_address),
            dynamic_rendering: t(f13.dynamic_rendering),
            synchronization2: t(f13.synchronization2),
            index_type_uint8: t(f_u8.index_type_uint8),
            acceleration_structure: t(f_as.acceleration_structure),
            ray_query: t(f_rq.ray_query),
            mesh_shader: t(f_mesh.mesh_shader),
            task_shader: t(f_mesh.task_shader),
        };
        let formats = QUERIED_FORMATS
            .iter()
            // SAFETY: a format query on a valid physical device.
            .map(|&f| (f, unsafe { instance.get_physical_device_format_properties(physical, f) }.optimal_tiling_features))
            .collect();
        let depth_stencil_image_samples = QUERIED_FORMATS[..3]
            .iter()
            .map(|&f| {
                // SAFETY: an image-format query on a valid physical device.
                let p = unsafe {
                    instance.get_physical_device_image_format_properties(
                        physical,
                        f,
                        vk::ImageType::TYPE_2D,
                        vk::ImageTiling::OPTIMAL,
                        vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT,
                        vk::ImageCreateFlags::empty(),
                    )
                };
                (f, p.map(|p| p.sample_counts).unwrap_or_default())
            })
            .collect();
        let has_driver_props = v12 || (has(ash::khr::driver_properties::NAME) && can_query2);
        let driver = if has_driver_props {
            let mut d = vk::PhysicalDeviceDriverProperties::default();
            let mut p2 = vk::PhysicalDeviceProperties2::default().push_next(&mut d);
            // SAFETY: a chain of locals; the driver-properties struct is defined for this device.
            unsafe {
                match (v11, gpdp2) {
                    (false, Some(g)) => g.get_physical_device_properties2(physical, &mut p2),
                    _ => instance.get_physical_device_properties2(physical, &mut p2),
                }
            }
            d.driver_name_as_c_str().map(|c| c.to_string_lossy().into_owned()).unwrap_or_default()
        } else {
            String::new()
        };
        let graphics_queue = families
            .iter()
            .position(|f| f.queue_flags.contains(vk::QueueFlags::GRAPHICS))
            .map(|i| (i as u32, families[i].timestamp_valid_bits));
        Ok(DeviceCaps {
            name: props.device_name_as_c_str().map(|c| c.to_string_lossy().into_owned()).unwrap_or_default(),
            device_type: props.device_type,
            api_version: api,
            driver,
            extensions,
            features,
            formats,
            depth_stencil_image_samples,
            limits: props.limits,
            graphics_queue,
        })
    }
}

/// What [`choose`] decided for umbrage's own context on a device.
#[derive(Clone, Debug)]
pub struct Choice {
    /// The optional capabilities to enable and use.
    pub features: Features,
    /// The frame's depth-stencil format (one of [`FRAME_DEPTH_FORMATS`]).
    pub depth_format: vk::Format,
    /// The device extensions to enable (beyond the caller's own).
    pub extensions: Vec<&'static CStr>,
}

/// What umbrage's own context (renderer, viewer, bench; or with [`Minimum::Vulkan10`] the
/// conformance suite and `umbrage info`) enables and uses on a device, or why it refuses it.
///
/// The rules: a feature is used only where the device's version defines the structure that
/// enables it (`dynamicRendering` and `synchronization2` from Vulkan 1.3 core, never their
/// extensions; `multiview` from Vulkan 1.2's `Vulkan11Features`; ray query from Vulkan 1.2
/// with its three extensions and `bufferDeviceAddress`; 8-bit indices where the device can
/// be asked through a `*2` query); the depth-stencil format is the first of
/// [`FRAME_DEPTH_FORMATS`] usable as an attachment and a copy source.
///
/// # Errors
/// [`Error::Unsupported`] naming what is missing: a Vulkan version below `minimum`,
/// `dynamicRendering` or `synchronization2` at [`Minimum::Vulkan13`], no depth-stencil
/// format with 8 stencil bits; [`Error::NoDevice`] without a graphics queue.
pub fn choose(caps: &DeviceCaps, minimum: Minimum) -> Result<Choice> {
    let name = &caps.name;
    let api = caps.api_version;
    let (v11, v12, v13) = (api >= vk::API_VERSION_1_1, api >= vk::API_VERSION_1_2, api >= vk::API_VERSION_1_3);
    let Some((_, timestamp_bits)) = caps.graphics_queue else {
        return Err(Error::NoDevice(format!("{name} has no graphics queue")));
    };
    if minimum == Minimum::Vulkan13 && !v13 {
        return Err(Error::Unsupported(format!(
            "{name} is a Vulkan {} device: umbrage's renderer needs Vulkan 1.3 (dynamicRendering and synchronization2 in core); \
             the embeddable ShadowPass takes Vulkan 1.1 with TargetModel::RenderPass",
            version_string(api)
        )));
    }
    let f = &caps.features;
    if minimum == Minimum::Vulkan13 && !(f.dynamic_rendering && f.synchronization2) {
        return Err(Error::Unsupported(format!("{name}: umbrage needs dynamicRendering and synchronization2 (Vulkan 1.3)")));
    }
    // Vulkan 1.0 has no TRANSFER_SRC format feature (VK_KHR_maintenance1): every attachment
    // format may be copied there.
    let needed = if v11 {
        vk::FormatFeatureFlags::DEPTH_STENCIL_ATTACHMENT | vk::FormatFeatureFlags::TRANSFER_SRC
    } else {
        vk::FormatFeatureFlags::DEPTH_STENCIL_ATTACHMENT
    };
    let depth_format = FRAME_DEPTH_FORMATS
        .into_iter()
        .find(|&fmt| caps.format_features(fmt).contains(needed))
        .ok_or_else(|| Error::Unsupported(format!("{name}: no depth-stencil format with 8 stencil bits (D32S8 or D24S8)")))?;
    // Enabled through the EXT extension's name (the KHR one is its promotion, not always
    // offered beside it).
    let index_type_uint8 = f.index_type_uint8 && caps.has_extension(ash::ext::index_type_uint8::NAME);
    let ray_query = v12
        && [ash::khr::acceleration_structure::NAME, ash::khr::ray_query::NAME, ash::khr::deferred_host_operations::NAME]
            .into_iter()
            .all(|e| caps.has_extension(e))
        && f.acceleration_structure
        && f.ray_query
        && f.buffer_device_address;
    let depth_range_unrestricted = caps.has_extension(ash::ext::depth_range_unrestricted::NAME);
    // Mesh shaders: naga writes them as SPIR-V 1.4, which Vulkan 1.2 takes.
    let mesh_shader = v12 && caps.has_extension(ash::ext::mesh_shader::NAME) && f.mesh_shader;
    let storage_buffer_ext = !v11 && caps.has_extension(ash::khr::storage_buffer_storage_class::NAME);
    let blendable = |fmt: vk::Format| caps.format_features(fmt).contains(vk::FormatFeatureFlags::COLOR_ATTACHMENT_BLEND);
    let l = &caps.limits;
    let features = Features {
        api_version: api,
        dynamic_rendering: v13 && f.dynamic_rendering,
        synchronization2: v13 && f.synchronization2,
        extended_dynamic_state: v13,
        depth_clamp: f.depth_clamp,
        depth_bounds: f.depth_bounds,
        depth_range_unrestricted,
        index_type_uint8,
        pipeline_statistics_query: f.pipeline_statistics_query,
        occlusion_query_precise: f.occlusion_query_precise,
        timestamps: timestamp_bits > 0 && l.timestamp_period > 0.0,
        timestamp_period_ns: l.timestamp_period,
        depth_stencil_format: format!("{depth_format:?}"),
        geometry_shader: f.geometry_shader,
        r32f_blend: blendable(vk::Format::R32_SFLOAT),
        rgba32f_blend: blendable(vk::Format::R32G32B32A32_SFLOAT),
        ray_query,
        multiview: v12 && f.multiview,
        mesh_shader,
        task_shader: mesh_shader && f.task_shader,
        multi_draw_indirect: f.multi_draw_indirect,
        draw_indirect_first_instance: f.draw_indirect_first_instance,
        draw_indirect_count: v12 && f.draw_indirect_count,
        sample_rate_shading: f.sample_rate_shading,
        standard_sample_locations: l.standard_sample_locations == vk::TRUE,
        storage_buffer_storage_class: v11 || storage_buffer_ext,
        frame_sample_counts: (l.framebuffer_color_sample_counts
            & l.framebuffer_depth_sample_counts
            & l.framebuffer_stencil_sample_counts
            & l.sampled_image_color_sample_counts
            & l.sampled_image_integer_sample_counts
            & l.sampled_image_stencil_sample_counts)
            .as_raw(),
    };
    let mut extensions = Vec::new();
    if ray_query {
        extensions.extend([ash::khr::acceleration_structure::NAME, ash::khr::ray_query::NAME, ash::khr::deferred_host_operations::NAME]);
    }
    if index_type_uint8 {
        extensions.push(ash::ext::index_type_uint8::NAME);
    }
    if depth_range_unrestricted {
        extensions.push(ash::ext::depth_range_unrestricted::NAME);
    }
    if mesh_shader {
        extensions.push(ash::ext::mesh_shader::NAME);
    }
    if storage_buffer_ext {
        extensions.push(ash::khr::storage_buffer_storage_class::NAME);
    }
    Ok(Choice { features, depth_format, extensions })
}

/// Optional device capabilities, as probed.
#[derive(Clone, Debug, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Features {
    /// The device's Vulkan version as `VK_MAKE_API_VERSION` packs it (`DeviceInfo::api_version`
    /// spells it out). Below 1.3 only what Vulkan 1.0 core offers is used, and the context is
    /// made only through [`Context::any_version`](super::Context::any_version).
    #[cfg_attr(feature = "serde", serde(skip))]
    pub api_version: u32,
    /// `dynamicRendering` (Vulkan 1.3 core) is enabled: `vkCmdBeginRendering` may be used.
    pub dynamic_rendering: bool,
    /// `synchronization2` (Vulkan 1.3 core) is enabled: barriers are recorded with
    /// `vkCmdPipelineBarrier2`; without it [`super::resources::transition`] and
    /// [`super::resources::memory_barrier`] record Vulkan 1.0 barriers.
    pub synchronization2: bool,
    /// The Vulkan 1.3 core dynamic depth/stencil state (`vkCmdSetStencilOp`,
    /// `vkCmdSetDepthCompareOp`, ..., formerly `VK_EXT_extended_dynamic_state`) can be used.
    pub extended_dynamic_state: bool,
    /// `depthClamp` is supported (and enabled on the device): `--depth-mode clamp` (finite far
    /// plane, geometry beyond it clamped to depth 1.0 instead of clipped).
    pub depth_clamp: bool,
    /// `depthBounds` is supported (and enabled): pipelines may use the depth-bounds test.
    pub depth_bounds: bool,
    /// `VK_EXT_depth_range_unrestricted` is available (and enabled).
    pub depth_range_unrestricted: bool,
    /// `VK_EXT_index_type_uint8` with its `indexTypeUint8` feature (both enabled when present):
    /// 8-bit index buffers can be bound.
    pub index_type_uint8: bool,
    /// `pipelineStatisticsQuery` is supported (and enabled).
    pub pipeline_statistics_query: bool,
    /// `occlusionQueryPrecise` is supported (and enabled): occlusion queries with
    /// `VK_QUERY_CONTROL_PRECISE_BIT` count samples exactly (the bench's rasterised-fragment
    /// counter; the conformance suite checks them).
    pub occlusion_query_precise: bool,
    /// The graphics queue writes timestamps (`timestampValidBits > 0`) and the device reports a
    /// non-zero `timestampPeriod`.
    pub timestamps: bool,
    /// Nanoseconds per timestamp tick (`VkPhysicalDeviceLimits::timestampPeriod`).
    pub timestamp_period_ns: f32,
    /// The chosen depth-stencil format, as its `Debug` name (`D32_SFLOAT_S8_UINT` or
    /// `D24_UNORM_S8_UINT`); the format itself is [`Context::depth_format`](super::Context::depth_format).
    pub depth_stencil_format: String,
    /// `geometryShader` is supported (probed and reported only; never enabled).
    pub geometry_shader: bool,
    /// R32_SFLOAT can be blended as a colour attachment (optional in Vulkan): `--counter float`
    /// and the shadow-map baseline need it.
    pub r32f_blend: bool,
    /// R32G32B32A32_SFLOAT can be blended (optional): the fp32 light-intensity map needs it.
    pub rgba32f_blend: bool,
    /// `VK_KHR_ray_query` and `VK_KHR_acceleration_structure` (with `rayQuery`,
    /// `accelerationStructure` and `bufferDeviceAddress`) are present and enabled:
    /// `--method rayquery` can run (Mesa lavapipe 25 has them; 22.3 has not).
    pub ray_query: bool,
    /// `multiview` (Vulkan 1.1 core) is supported and enabled: the shadow-map baseline can
    /// render a point light's six cube faces as six views of one draw (`--cube multiview`).
    pub multiview: bool,
    /// `VK_EXT_mesh_shader` with `meshShader` (Vulkan 1.2 or newer) is present and enabled:
    /// `--method mesh` can run (Mesa lavapipe 25 has it; 22.3 has not).
    pub mesh_shader: bool,
    /// `taskShader` of `VK_EXT_mesh_shader` is present and enabled too (only with
    /// [`mesh_shader`](Self::mesh_shader)).
    pub task_shader: bool,
    /// `multiDrawIndirect` is supported and enabled: indirect draws of more than one record
    /// per call (the compute path's merged volume draws).
    pub multi_draw_indirect: bool,
    /// `drawIndirectFirstInstance` is supported and enabled: indirect records with a non-zero
    /// `firstInstance` (the merged draws' per-caster transforms are selected by it).
    pub draw_indirect_first_instance: bool,
    /// `drawIndirectCount` (Vulkan 1.2 core) is supported and enabled:
    /// `vkCmdDrawIndexedIndirectCount` (the merged draws' count comes from the GPU).
    pub draw_indirect_count: bool,
    /// `sampleRateShading` is supported and enabled: the renderer's multisampled frame
    /// (`--msaa N`) shades its G-buffer and lighting per sample.
    pub sample_rate_shading: bool,
    /// Sample counts (bit `N` for N samples) that every target of the renderer's multisampled
    /// frame supports: the colour and depth-stencil framebuffer counts and the sampled-image
    /// counts (colour, integer for the stencil, depth) together.
    pub frame_sample_counts: u32,
    /// `standardSampleLocations`: multisampled images use Vulkan's standard sample locations
    /// (a multisampled capture's positions are found at them).
    pub standard_sample_locations: bool,
    /// SPIR-V 1.0 modules may declare storage buffers through
    /// `SPV_KHR_storage_buffer_storage_class` (as naga writes them): Vulkan 1.1 core, or
    /// `VK_KHR_storage_buffer_storage_class` (enabled where present on a Vulkan 1.0 device).
    /// The conformance suite's compute checks need it.
    pub storage_buffer_storage_class: bool,
}

/// Identification of the chosen physical device, for `umbrage info`, logs and the stats JSON.
#[derive(Clone, Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct DeviceInfo {
    /// `deviceName`, e.g. `llvmpipe (LLVM 15.0.7, 256 bits)`.
    pub name: String,
    /// The device type as its `Debug` name: `DISCRETE_GPU`, `INTEGRATED_GPU`, `VIRTUAL_GPU`, `CPU`, ...
    pub kind: String,
    /// `driverName` from `VkPhysicalDeviceDriverProperties` (empty if the driver leaves it empty).
    pub driver: String,
    /// `driverInfo` from `VkPhysicalDeviceDriverProperties`, typically the driver's version string.
    pub driver_info: String,
    /// The device's Vulkan version, `major.minor.patch` (at least 1.3.0, except for a context
    /// made with [`Context::any_version`](super::Context::any_version)).
    pub api_version: String,
    /// PCI vendor id (`vendorID`).
    pub vendor_id: u32,
    /// Vendor-specific device id (`deviceID`).
    pub device_id: u32,
}

/// `major.minor.patch` of a packed Vulkan version.
pub fn version_string(v: u32) -> String {
    format!("{}.{}.{}", vk::api_version_major(v), vk::api_version_minor(v), vk::api_version_patch(v))
}
