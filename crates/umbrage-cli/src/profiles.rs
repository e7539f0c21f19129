//! Device reports: gpuinfo.org's JSON exports (the `vp_gpuinfo_*.json` files of Khronos'
//! Vulkan-Profiles repository, or `scripts/device-reports.py`'s cuts of them in
//! `tests/data/devices/`) read into a [`DeviceCaps`], and what umbrage would use, fall back to
//! and refuse on each device, decided by the same code a live device goes through
//! ([`umbrage::gpu::caps::choose`] for umbrage's own context, [`ShadowPass::capabilities_for`]
//! for the embeddable pass): [`report_markdown`] writes `docs/devices.md`.

use ash::vk;
use serde_json::Value;
use umbrage::error::{Error, Result};
use umbrage::gpu::caps::{choose, version_string, DeviceCaps, FeatureSet, Minimum, QUERIED_FORMATS};
use umbrage::pass::{RenderPassTarget, ShadowPass, ShadowPassDesc, TargetModel};

/// The largest push-constant block any of umbrage's pipelines declares, in bytes (the
/// renderer's forward and sphere blocks; the pass's volume block is 96): the Vulkan minimum
/// of `maxPushConstantsSize`, so it fits every device.
pub const PUSH_BYTES: u32 = 128;

fn bad(what: &str) -> Error {
    Error::InvalidDesc { field: "device report", msg: what.to_string() }
}

/// Reads one gpuinfo.org device report (the Vulkan profiles JSON schema, `capabilities.device`)
/// into a [`DeviceCaps`]: the fields umbrage's choices read. A feature structure missing from
/// the report reads as all features off; a format it does not list, as no features.
///
/// # Errors
/// [`Error::InvalidDesc`] (field `device report`) when the text is not JSON or lacks the
/// device's properties.
pub fn read_gpuinfo(text: &str) -> Result<DeviceCaps> {
    let root: Value = serde_json::from_str(text).map_err(|e| bad(&format!("not JSON: {e}")))?;
    let dev = root.pointer("/capabilities/device").ok_or_else(|| bad("no capabilities.device"))?;
    let props = dev.pointer("/properties/VkPhysicalDeviceProperties").ok_or_else(|| bad("no VkPhysicalDeviceProperties"))?;
    let limits = props.get("limits").ok_or_else(|| bad("no limits"))?;
    let feature = |structs: &[&str], name: &str| {
        structs.iter().any(|s| dev.pointer(&format!("/features/{s}/{name}")).and_then(Value::as_bool).unwrap_or(false))
    };
    let features = FeatureSet {
        depth_clamp: feature(&["VkPhysicalDeviceFeatures"], "depthClamp"),
        depth_bounds: feature(&["VkPhysicalDeviceFeatures"], "depthBounds"),
        pipeline_statistics_query: feature(&["VkPhysicalDeviceFeatures"], "pipelineStatisticsQuery"),
        occlusion_query_precise: feature(&["VkPhysicalDeviceFeatures"], "occlusionQueryPrecise"),
        geometry_shader: feature(&["VkPhysicalDeviceFeatures"], "geometryShader"),
        sample_rate_shading: feature(&["VkPhysicalDeviceFeatures"], "sampleRateShading"),
        multi_draw_indirect: feature(&["VkPhysicalDeviceFeatures"], "multiDrawIndirect"),
        draw_indirect_first_instance: feature(&["VkPhysicalDeviceFeatures"], "drawIndirectFirstInstance"),
        multiview: feature(&["VkPhysicalDeviceVulkan11Features", "VkPhysicalDeviceMultiviewFeaturesKHR"], "multiview"),
        draw_indirect_count: feature(&["VkPhysicalDeviceVulkan12Features"], "drawIndirectCount"),
        buffer_device_address: feature(
            &["VkPhysicalDeviceVulkan12Features", "VkPhysicalDeviceBufferDeviceAddressFeaturesKHR"],
            "bufferDeviceAddress",
        ),
        dynamic_rendering: feature(
            &["VkPhysicalDeviceVulkan13Features", "VkPhysicalDeviceDynamicRenderingFeaturesKHR"],
            "dynamicRendering",
        ),
        synchronization2: feature(&["VkPhysicalDeviceVulkan13Features", "VkPhysicalDeviceSynchronization2FeaturesKHR"], "synchronization2"),
        index_type_uint8: feature(
            &["VkPhysicalDeviceIndexTypeUint8FeaturesEXT", "VkPhysicalDeviceIndexTypeUint8FeaturesKHR"],
            "indexTypeUint8",
        ),
        acceleration_structure: feature(&["VkPhysicalDeviceAccelerationStructureFeaturesKHR"], "accelerationStructure"),
        ray_query: feature(&["VkPhysicalDeviceRayQueryFeaturesKHR"], "rayQuery"),
        mesh_shader: feature(&["VkPhysicalDeviceMeshShaderFeaturesEXT"], "meshShader"),
        task_shader: feature(&["VkPhysicalDeviceMeshShaderFeaturesEXT"], "taskShader"),
    };
    let extensions = dev.get("extensions").and_then(Value::as_object).map(|o| o.keys().cloned().collect()).unwrap_or_default();
    let formats = QUERIED_FORMATS
        .iter()
        .map(|&f| {
            let flags = dev
                .pointer(&format!("/formats/VK_FORMAT_{f:?}/VkFormatProperties/optimalTilingFeatures"))
                .and_then(Value::as_array)
                .map(|a| a.iter().filter_map(Value::as_str).map(format_feature).fold(vk::FormatFeatureFlags::empty(), |x, y| x | y))
                .unwrap_or_default();
            (f, flags)
        })
        .collect();
    let u32_of = |v: &Value, k: &str| v.get(k).and_then(Value::as_u64).map(|x| x.min(u32::MAX as u64) as u32).unwrap_or(0);
    let samples = |k: &str| {
        limits
            .get(k)
            .and_then(Value::as_array)
            .map(|a| {
                a.iter()
                    .filter_map(Value::as_str)
                    .filter_map(|s| s.strip_prefix("VK_SAMPLE_COUNT_")?.strip_suffix("_BIT")?.parse::<u32>().ok())
                    .fold(0, |x, n| x | n)
            })
            .map(vk::SampleCountFlags::from_raw)
            .unwrap_or_default()
    };
    let limits = vk::PhysicalDeviceLimits {
        max_push_constants_size: u32_of(limits, "maxPushConstantsSize"),
        max_image_dimension2_d: u32_of(limits, "maxImageDimension2D"),
        max_draw_indirect_count: u32_of(limits, "maxDrawIndirectCount"),
        max_bound_descriptor_sets: u32_of(limits, "maxBoundDescriptorSets"),
        max_compute_work_group_invocations: u32_of(limits, "maxComputeWorkGroupInvocations"),
        max_storage_buffer_range: u32_of(limits, "maxStorageBufferRange"),
        framebuffer_color_sample_counts: samples("framebufferColorSampleCounts"),
        framebuffer_depth_sample_counts: samples("framebufferDepthSampleCounts"),
        framebuffer_stencil_sample_counts: samples("framebufferStencilSampleCounts"),
        sampled_image_color_sample_counts: samples("sampledImageColorSampleCounts"),
        sampled_image_integer_sample_counts: samples("sampledImageIntegerSampleCounts"),
        sampled_image_depth_sample_counts: samples("sampledImageDepthSampleCounts"),
        sampled_image_stencil_sample_counts: samples("sampledImageStencilSampleCounts"),
        timestamp_period: limits.get("timestampPeriod").and_then(Value::as_f64).unwrap_or(0.0) as f32,
        standard_sample_locations: limits.get("standardSampleLocations").and_then(Value::as_bool).unwrap_or(false).into(),
        ..Default::default()
    };
    let graphics_queue = dev.get("queueFamiliesProperties").and_then(Value::as_array).and_then(|families| {
        families.iter().enumerate().find_map(|(i, f)| {
            let f = f.get("VkQueueFamilyProperties")?;
            let graphics = f.get("queueFlags")?.as_array()?.iter().any(|x| x.as_str() == Some("VK_QUEUE_GRAPHICS_BIT"));
            graphics.then(|| (i as u32, u32_of(f, "timestampValidBits")))
        })
    });
    let driver = ["VkPhysicalDeviceDriverProperties", "VkPhysicalDeviceDriverPropertiesKHR"]
        .iter()
        .find_map(|s| dev.pointer(&format!("/properties/{s}/driverName")).and_then(Value::as_str))
        .unwrap_or_default()
        .to_string();
    // Older exports leave `deviceName` out: the profile's label says "NAME driver X on OS".
    let label = root.get("profiles").and_then(Value::as_object).and_then(|o| o.values().next()).and_then(|p| p.get("label"));
    let name = props
        .get("deviceName")
        .and_then(Value::as_str)
        .or_else(|| label.and_then(Value::as_str).and_then(|l| l.split(" driver ").next()))
        .ok_or_else(|| bad("no deviceName and no profile label"))?
        .to_string();
    Ok(DeviceCaps {
        name,
        device_type: device_type(props.get("deviceType").and_then(Value::as_str).unwrap_or_default()),
        api_version: u32_of(props, "apiVersion"),
        driver,
        extensions,
        features,
        formats,
        depth_stencil_image_samples: Vec::new(),
        limits,
        graphics_queue,
    })
}

/// `VK_FORMAT_FEATURE_X_BIT` (or `_BIT_KHR`) as its flag; unknown names as none.
fn format_feature(name: &str) -> vk::FormatFeatureFlags {
    let Some(stem) = name.strip_prefix("VK_FORMAT_FEATURE_") else { return vk::FormatFeatureFlags::empty() };
    let stem = stem.strip_suffix("_KHR").unwrap_or(stem);
    let Some(stem) = stem.strip_suffix("_BIT") else { return vk::FormatFeatureFlags::empty() };
    (0..32).map(|b| vk::FormatFeatureFlags::from_raw(1 << b)).find(|f| format!("{f:?}") == stem).unwrap_or_default()
}

fn device_type(name: &str) -> vk::PhysicalDeviceType {
    [
        vk::PhysicalDeviceType::DISCRETE_GPU,
        vk::PhysicalDeviceType::INTEGRATED_GPU,
        vk::PhysicalDeviceType::VIRTUAL_GPU,
        vk::PhysicalDeviceType::CPU,
    ]
    .into_iter()
    .find(|t| name == format!("VK_PHYSICAL_DEVICE_TYPE_{t:?}"))
    .unwrap_or(vk::PhysicalDeviceType::OTHER)
}

/// A host's render-pass target for `format` and `samples`, as a description needs it to be
/// checked without a device (the handle is not looked at before pipelines are made).
pub fn render_pass_target(format: vk::Format, samples: u32) -> TargetModel {
    TargetModel::RenderPass(RenderPassTarget {
        render_pass: vk::RenderPass::null(),
        subpass: 0,
        depth_stencil_format: format,
        samples: vk::SampleCountFlags::from_raw(samples),
        color_attachments: 0,
    })
}

/// Sample counts (bit N for N samples) as `1, 2, 4`.
fn counts(bits: u32) -> String {
    let v: Vec<String> = [1u32, 2, 4, 8, 16, 32, 64].iter().filter(|&&n| bits & n != 0).map(|n| n.to_string()).collect();
    if v.is_empty() {
        "none".into()
    } else {
        v.join(", ")
    }
}

fn short_format(f: vk::Format) -> &'static str {
    match f {
        vk::Format::D16_UNORM_S8_UINT => "D16S8",
        vk::Format::D24_UNORM_S8_UINT => "D24S8",
        vk::Format::D32_SFLOAT_S8_UINT => "D32S8",
        _ => "?",
    }
}

/// The first sentence of an error, without its variant's prefix, for a table cell.
fn why(e: &Error) -> String {
    let s = match e {
        Error::Unsupported(s) | Error::NoDevice(s) => s.clone(),
        Error::InvalidDesc { msg, .. } => msg.clone(),
        e => e.to_string(),
    };
    s.replace('|', "/").split(';').next().unwrap_or_default().trim().to_string()
}

/// One device's row facts: what umbrage's renderer and the embeddable pass do there.
struct Verdict {
    device: String,
    renderer: String,
    pass: String,
    gpu_driven: String,
    notes: Vec<String>,
    refused: bool,
    no_depth_bounds: bool,
    no_d24s8: bool,
    pass_dr: bool,
}

fn verdict(file: &str, caps: &DeviceCaps) -> Verdict {
    let f = &caps.features;
    let portability = caps.portability_subset();
    let device = format!(
        "{} ({}{}, Vulkan {}) `{file}`",
        caps.name,
        if caps.driver.is_empty() { "driver not reported".to_string() } else { caps.driver.clone() },
        if portability { ", portability subset" } else { "" },
        version_string(caps.api_version)
    );
    let mut notes = Vec::new();
    let (renderer, refused) = match choose(caps, Minimum::Vulkan13) {
        Ok(c) => {
            let x = &c.features;
            let msaa = if x.sample_rate_shading { counts(x.frame_sample_counts & 0b1111) } else { "1 (no sampleRateShading)".into() };
            let mut uses = vec![
                short_format(c.depth_format).to_string(),
                format!("depth bounds {}", if x.depth_bounds { "yes" } else { "no" }),
                format!("clamp {}", if x.depth_clamp { "yes" } else { "no" }),
                format!("MSAA {msaa}"),
            ];
            if !x.r32f_blend {
                uses.push("no float counter / shadow map (R32F blend)".into());
            }
            if !x.rgba32f_blend {
                uses.push("transmit log16 only".into());
            }
            if x.index_type_uint8 {
                uses.push("u8 indices".into());
            }
            if x.ray_query {
                uses.push("ray query".into());
            }
            if !x.timestamps {
                uses.push("no GPU timings".into());
            }
            (uses.join(", "), false)
        }
        Err(e) => (format!("**refused**: {}", why(&e)), true),
    };
    // The pass: the host's best format first (D24S8 where the device has it: most engines'
    // choice), every enabled feature asked for, one sample; then the largest sample count.
    let formats = [vk::Format::D24_UNORM_S8_UINT, vk::Format::D32_SFLOAT_S8_UINT, vk::Format::D16_UNORM_S8_UINT];
    let desc_for = |format: vk::Format, render_pass: bool, samples: u32| {
        let target = if render_pass { render_pass_target(format, samples) } else { TargetModel::DynamicRendering };
        let mut d = ShadowPassDesc { depth_stencil_format: format, target, samples, ..Default::default() };
        d.features.depth_bounds = true;
        d.features.depth_clamp = true;
        d.features.index_type_uint8 = true;
        d
    };
    let usable: Vec<vk::Format> =
        formats.into_iter().filter(|&fmt| ShadowPass::capabilities_for(caps, &desc_for(fmt, true, 1)).is_ok()).collect();
    let dr = usable.first().is_some_and(|&fmt| ShadowPass::capabilities_for(caps, &desc_for(fmt, false, 1)).is_ok());
    let pass = match usable.first() {
        None => {
            let e = ShadowPass::capabilities_for(caps, &desc_for(vk::Format::D32_SFLOAT_S8_UINT, true, 1))
                .err()
                .map(|e| why(&e))
                .unwrap_or_default();
            format!("**refused**: {e}")
        }
        Some(&best) => {
            let c = ShadowPass::capabilities_for(caps, &desc_for(best, true, 1)).unwrap_or_default();
            let samples: Vec<String> = [1u32, 2, 4, 8]
                .into_iter()
                .filter(|&n| ShadowPass::capabilities_for(caps, &desc_for(best, true, n)).is_ok())
                .map(|n| n.to_string())
                .collect();
            let mut s = vec![
                usable.iter().map(|&f| short_format(f)).collect::<Vec<_>>().join(" / "),
                if dr { "render pass + dynamic rendering".into() } else { "render pass only".into() },
                format!("samples {}", samples.join(", ")),
                format!("depth bounds {}", if c.depth_bounds { "yes" } else { "no" }),
                format!("clamp {}", if c.depth_clamp { "yes" } else { "no" }),
            ];
            if c.index_type_uint8 {
                s.push("u8 indices".into());
            }
            s.join(", ")
        }
    };
    let v12 = caps.api_version >= vk::API_VERSION_1_2;
    let indirect = if v12 && f.draw_indirect_count {
        "drawIndirectCount"
    } else if f.multi_draw_indirect {
        "multi-draw indirect"
    } else {
        "one draw per record"
    };
    let mesh = if caps.has_extension(ash::ext::mesh_shader::NAME) && f.mesh_shader {
        if f.task_shader {
            "mesh + task shaders"
        } else {
            "mesh shaders (no task)"
        }
    } else {
        "no mesh shaders"
    };
    let gpu_driven = format!("{indirect}; {mesh}");
    if caps.limits.max_push_constants_size < PUSH_BYTES {
        notes.push(format!("maxPushConstantsSize {} < {PUSH_BYTES}", caps.limits.max_push_constants_size));
    }
    let shadow_map = vk::FormatFeatureFlags::DEPTH_STENCIL_ATTACHMENT | vk::FormatFeatureFlags::SAMPLED_IMAGE;
    if !caps.format_features(vk::Format::D32_SFLOAT).contains(shadow_map) {
        notes.push("D32_SFLOAT is not a sampled depth attachment: the shadow-map baseline cannot run".into());
    }
    Verdict {
        device,
        renderer,
        pass,
        gpu_driven,
        notes,
        refused,
        no_depth_bounds: !f.depth_bounds,
        no_d24s8: !caps.format_features(vk::Format::D24_UNORM_S8_UINT).contains(vk::FormatFeatureFlags::DEPTH_STENCIL_ATTACHMENT),
        pass_dr: dr,
    }
}

/// `docs/devices.md`: for each report (`(file name, capabilities)`, in the order given), what
/// umbrage's renderer and the embeddable pass would use, fall back to and refuse on that
/// device, with a summary of the differences that matter. `source` says where the reports come
/// from (a sentence of Markdown).
pub fn report_markdown(reports: &[(String, DeviceCaps)], source: &str) -> String {
    let verdicts: Vec<Verdict> = reports.iter().map(|(file, caps)| verdict(file, caps)).collect();
    let n = verdicts.len();
    let count = |p: &dyn Fn(&Verdict) -> bool| verdicts.iter().filter(|v| p(v)).count();
    let mut out = String::new();
    out.push_str("# What umbrage does on real devices\n\n");
    out.push_str(&format!(
        "Generated by `cargo test --test engine devices::` from {n} device reports ({source}). Each report goes through the same \
         selection code a live device does: `gpu::caps::choose` (umbrage's own context: the renderer, viewer and bench) \
         and `ShadowPass::capabilities_for` (the embeddable pass, with every optional feature enabled by the host). \
         A report carries no per-format image sample counts, so the framebuffer limits alone decide the pass's sample \
         counts there.\n\n"
    ));
    out.push_str("## Summary\n\n");
    out.push_str(&format!(
        "- The renderer refuses {} of {n} devices (below Vulkan 1.3, or without dynamicRendering / synchronization2); \
         the embeddable pass takes {} of them with `TargetModel::RenderPass`.\n",
        count(&|v| v.refused),
        count(&|v| v.refused && !v.pass.starts_with("**refused**"))
    ));
    out.push_str(&format!(
        "- {} devices lack `depthBounds` (the light's depth range then bounds nothing: the stencil is the same, \
         only more fragments are rasterised).\n",
        count(&|v| v.no_depth_bounds)
    ));
    out.push_str(&format!(
        "- {} devices have no D24S8 attachment: the renderer takes D32S8 there (it prefers it everywhere), and a host's \
         pass must be given D32S8.\n",
        count(&|v| v.no_d24s8)
    ));
    out.push_str(&format!("- {} devices take the pass with dynamic rendering; the rest only in a render pass.\n", count(&|v| v.pass_dr)));
    out.push_str(&format!(
        "- Push constants: every pipeline's block is at most {PUSH_BYTES} bytes, the Vulkan minimum of \
         `maxPushConstantsSize`; {} devices report less.\n",
        count(&|v| v.notes.iter().any(|x| x.starts_with("maxPushConstantsSize")))
    ));
    out.push_str(&format!("- {} devices have notes (below the table).\n\n", count(&|v| !v.notes.is_empty())));
    out.push_str("## Devices\n\n| device | renderer (umbrage's frame) | ShadowPass (a host's) | GPU-driven volumes |\n|---|---|---|---|\n");
    for v in &verdicts {
        out.push_str(&format!("| {} | {} | {} | {} |\n", v.device, v.renderer, v.pass, v.gpu_driven));
    }
    let noted: Vec<&Verdict> = verdicts.iter().filter(|v| !v.notes.is_empty()).collect();
    if !noted.is_empty() {
        out.push_str("\n## Notes\n\n");
        for v in noted {
            out.push_str(&format!("- {}: {}\n", v.device, v.notes.join("; ")));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn format_feature_names_map_to_their_bits() {
        assert_eq!(format_feature("VK_FORMAT_FEATURE_DEPTH_STENCIL_ATTACHMENT_BIT"), vk::FormatFeatureFlags::DEPTH_STENCIL_ATTACHMENT);
        assert_eq!(format_feature("VK_FORMAT_FEATURE_TRANSFER_SRC_BIT_KHR"), vk::FormatFeatureFlags::TRANSFER_SRC);
        assert_eq!(format_feature("VK_FORMAT_FEATURE_COLOR_ATTACHMENT_BLEND_BIT"), vk::FormatFeatureFlags::COLOR_ATTACHMENT_BLEND);
        assert_eq!(format_feature("VK_FORMAT_FEATURE_NOT_A_THING_BIT"), vk::FormatFeatureFlags::empty());
        assert_eq!(device_type("VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU"), vk::PhysicalDeviceType::INTEGRATED_GPU);
    }

    #[test]
    fn a_report_without_properties_is_a_clear_error() {
        assert!(matches!(read_gpuinfo("{}"), Err(Error::InvalidDesc { .. })));
        assert!(matches!(read_gpuinfo("not json"), Err(Error::InvalidDesc { .. })));
    }
}
