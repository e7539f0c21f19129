//! From the C structs to the engine's types: every enum value, boolean, pointer and count is
//! checked here, before anything reaches the pass.

use crate::error::CError;
use crate::types::UmbrageResult::*;
use crate::types::*;
use ash::vk;
use engine::geom::{Light, LightKind};
use engine::pass::{
    ComputeDraws, Counter, DepthDirection, DepthMode, EnabledFeatures, IndexFormat, PassSettings, PassToggles, RenderPassTarget,
    ShadowPassDesc, TargetModel, Technique,
};
use engine::shadow::Method;
use glam::{DMat4, DVec3, Mat4, Vec3};
use std::ffi::{c_char, c_void, CStr};

/// The ABI this library implements: `(major << 16) | minor`.
#[allow(clippy::identity_op)]
pub(crate) const ABI: u32 = (0 << 16) | 1;

/// Refuses a NULL pointer argument.
pub fn non_null<T>(p: *const T, what: &str) -> Result<*const T, CError> {
    if p.is_null() {
        Err(CError::null(what))
    } else {
        Ok(p)
    }
}

/// An enum value out of its range.
fn bad_enum(field: &str, value: u32) -> CError {
    CError::argument(field, format!("{value} is not one of its values"))
}

/// Checks a struct's `sType`.
pub fn check_stype(got: u32, want: UmbrageStructureType, what: &str) -> Result<(), CError> {
    if got == want as u32 {
        Ok(())
    } else {
        Err(CError::new(UMBRAGE_ERROR_STRUCTURE_TYPE, format!("{what}::sType is {got}, expected {:?} ({})", want, want as u32)))
    }
}

/// Refuses a non-NULL `pNext` on a struct that has no extension yet.
pub fn no_next(p: *const c_void, what: &str) -> Result<(), CError> {
    if p.is_null() {
        Ok(())
    } else {
        Err(CError::new(UMBRAGE_ERROR_STRUCTURE_TYPE, format!("{what}::pNext: this version knows no struct to chain there")))
    }
}

/// The header every chained struct starts with.
#[repr(C)]
struct BaseIn {
    s_type: u32,
    p_next: *const c_void,
}

/// A NUL-terminated name, or a default.
///
/// # Safety
/// `p` is NULL or a NUL-terminated string.
pub unsafe fn name(p: *const c_char, default: &str) -> Result<String, CError> {
    if p.is_null() {
        return Ok(default.to_string());
    }
    // SAFETY: the caller's contract.
    let s = unsafe { CStr::from_ptr(p) };
    s.to_str().map(str::to_string).map_err(|_| CError::argument("pName", "not UTF-8"))
}

pub fn depth_direction(v: u32) -> Result<DepthDirection, CError> {
    match v {
        0 => Ok(DepthDirection::Forward),
        1 => Ok(DepthDirection::Reverse),
        _ => Err(bad_enum("UmbragePassCreateInfo::depthDirection", v)),
    }
}

pub fn depth_mode(v: u32) -> Result<DepthMode, CError> {
    match v {
        0 => Ok(DepthMode::Infinite),
        1 => Ok(DepthMode::Clamp),
        _ => Err(bad_enum("UmbragePassCreateInfo::depthMode", v)),
    }
}

pub fn features(bits: u32) -> Result<EnabledFeatures, CError> {
    if bits & !0x1ff != 0 {
        return Err(CError::argument("UmbragePassCreateInfo::enabledFeatures", format!("unknown bits {:#x}", bits & !0x1ff)));
    }
    let b = |x: UmbrageFeatureFlagBits| bits & x as u32 != 0;
    use UmbrageFeatureFlagBits::*;
    Ok(EnabledFeatures {
        depth_clamp: b(UMBRAGE_FEATURE_DEPTH_CLAMP_BIT),
        depth_bounds: b(UMBRAGE_FEATURE_DEPTH_BOUNDS_BIT),
        index_type_uint8: b(UMBRAGE_FEATURE_INDEX_TYPE_UINT8_BIT),
        ray_query: b(UMBRAGE_FEATURE_RAY_QUERY_BIT),
        mesh_shader: b(UMBRAGE_FEATURE_MESH_SHADER_BIT),
        draw_indirect_first_instance: b(UMBRAGE_FEATURE_DRAW_INDIRECT_FIRST_INSTANCE_BIT),
        multi_draw_indirect: b(UMBRAGE_FEATURE_MULTI_DRAW_INDIRECT_BIT),
        draw_indirect_count: b(UMBRAGE_FEATURE_DRAW_INDIRECT_COUNT_BIT),
        task_shader: b(UMBRAGE_FEATURE_TASK_SHADER_BIT),
    })
}

pub fn technique(t: u32, m: u32) -> Result<Technique, CError> {
    let method = match m {
        0 => Method::McGuire,
        1 => Method::ZPass,
        2 => Method::ZFail,
        3 => Method::EverittKilgard,
        4 => Method::Lengyel,
        _ => return Err(bad_enum("UmbragePassSettings::method", m)),
    };
    Ok(match t {
        0 => Technique::Volumes(method),
        1 => Technique::EdgeQuads,
        2 => Technique::Planar,
        3 => Technique::Compute,
        4 => Technique::Mesh,
        5 => Technique::RayQuery,
        _ => return Err(bad_enum("UmbragePassSettings::technique", t)),
    })
}

pub fn settings(s: &UmbragePassSettings) -> Result<PassSettings, CError> {
    let counter = match s.counter {
        0 => Counter::Stencil,
        1 => Counter::Float,
        v => return Err(bad_enum("UmbragePassSettings::counter", v)),
    };
    let index_format = match s.indexFormat {
        0 => IndexFormat::Auto,
        1 => IndexFormat::U32,
        2 => IndexFormat::U16,
        3 => IndexFormat::U8,
        4 => IndexFormat::Naive,
        v => return Err(bad_enum("UmbragePassSettings::indexFormat", v)),
    };
    let compute_draws = match s.computeDraws {
        0 => ComputeDraws::Auto,
        1 => ComputeDraws::Count,
        2 => ComputeDraws::Multi,
        3 => ComputeDraws::PerRecord,
        4 => ComputeDraws::PerChunk,
        v => return Err(bad_enum("UmbragePassSettings::computeDraws", v)),
    };
    Ok(PassSettings {
        technique: technique(s.technique, s.method)?,
        counter,
        index_format,
        toggles: PassToggles {
            scissor: s.disableScissor == 0,
            depth_bounds: s.disableDepthBounds == 0,
            culling: s.disableCulling == 0,
            ray_batch: s.rayBatch != 0,
            compute_draws,
            mesh_task: s.disableMeshTask == 0,
        },
        // Plans kept across frames, as in every host (this version of the ABI has no field to
        // turn it off: the default, on, is what the pass does).
        ..PassSettings::default()
    })
}

/// The engine's settings in C.
pub fn settings_out(s: &PassSettings) -> UmbragePassSettings {
    let (technique, method) = match s.technique {
        Technique::EdgeQuads => (1, 0),
        Technique::Planar => (2, 0),
        Technique::Compute => (3, 0),
        Technique::Mesh => (4, 0),
        Technique::RayQuery => (5, 0),
        Technique::Volumes(m) => (
            0,
            match m {
                Method::ZPass => 1,
                Method::ZFail => 2,
                Method::EverittKilgard => 3,
                Method::Lengyel => 4,
                _ => 0,
            },
        ),
    };
    let index = |f: IndexFormat| match f {
        IndexFormat::U32 => 1,
        IndexFormat::U16 => 2,
        IndexFormat::U8 => 3,
        IndexFormat::Naive => 4,
        _ => 0,
    };
    let draws = match s.toggles.compute_draws {
        ComputeDraws::Count => 1,
        ComputeDraws::Multi => 2,
        ComputeDraws::PerRecord => 3,
        ComputeDraws::PerChunk => 4,
        _ => 0,
    };
    UmbragePassSettings {
        technique,
        method,
        counter: (s.counter == Counter::Float) as u32,
        indexFormat: index(s.index_format),
        computeDraws: draws,
        disableScissor: (!s.toggles.scissor) as u32,
        disableDepthBounds: (!s.toggles.depth_bounds) as u32,
        disableCulling: (!s.toggles.culling) as u32,
        disableMeshTask: (!s.toggles.mesh_task) as u32,
        rayBatch: s.toggles.ray_batch as u32,
    }
}

pub fn capabilities_out(c: &engine::pass::Capabilities) -> UmbrageCapabilities {
    UmbrageCapabilities {
        rayQuery: c.ray_query as u32,
        depthClamp: c.depth_clamp as u32,
        depthBounds: c.depth_bounds as u32,
        indexTypeUint8: c.index_type_uint8 as u32,
        r32fBlend: c.r32f_blend as u32,
        meshShader: c.mesh_shader as u32,
        drawIndirectFirstInstance: c.draw_indirect_first_instance as u32,
        multiDrawIndirect: c.multi_draw_indirect as u32,
        drawIndirectCount: c.draw_indirect_count as u32,
        taskShader: c.task_shader as u32,
    }
}

/// What the C create info asks for, as the engine's desc.
///
/// # Safety
/// `info`'s `pNext` chain is NULL or valid structs, each starting with `sType` and `pNext`.
pub unsafe fn desc(info: &UmbragePassCreateInfo) -> Result<ShadowPassDesc, CError> {
    check_stype(info.sType, UmbrageStructureType::UMBRAGE_STRUCTURE_TYPE_PASS_CREATE_INFO, "UmbragePassCreateInfo")?;
    let major = |v: u32| v >> 16;
    let minor = |v: u32| v & 0xffff;
    let compatible = major(info.abiVersion) == major(ABI)
        && if major(ABI) == 0 { minor(info.abiVersion) == minor(ABI) } else { minor(info.abiVersion) <= minor(ABI) };
    if !compatible {
        return Err(CError::new(
            UMBRAGE_ERROR_VERSION_MISMATCH,
            format!(
                "UmbragePassCreateInfo::abiVersion is {}.{} (the header the host compiled against); this library is ABI {}.{}",
                major(info.abiVersion),
                minor(info.abiVersion),
                major(ABI),
                minor(ABI)
            ),
        ));
    }
    let format = if info.depthStencilFormat == vk::Format::UNDEFINED { vk::Format::D32_SFLOAT_S8_UINT } else { info.depthStencilFormat };
    let samples = if info.samples == 0 { 1 } else { info.samples };
    let frames = if info.framesInFlight == 0 { 2 } else { info.framesInFlight as usize };
    let mut target = TargetModel::DynamicRendering;
    let mut next = info.pNext;
    while !next.is_null() {
        // SAFETY: the caller's contract: every chained struct starts with sType and pNext.
        let base = unsafe { &*next.cast::<BaseIn>() };
        if base.s_type == UmbrageStructureType::UMBRAGE_STRUCTURE_TYPE_RENDER_PASS_TARGET as u32 {
            // SAFETY: its sType says it is one.
            let rp = unsafe { &*next.cast::<UmbrageRenderPassTarget>() };
            if rp.renderPass == vk::RenderPass::null() {
                return Err(CError::from(engine::Error::desc("UmbrageRenderPassTarget::renderPass", "is VK_NULL_HANDLE")));
            }
            target = TargetModel::RenderPass(RenderPassTarget {
                render_pass: rp.renderPass,
                subpass: rp.subpass,
                depth_stencil_format: format,
                samples: sample_flags(samples),
                color_attachments: rp.colorAttachmentCount,
            });
        } else {
            return Err(CError::new(
                UMBRAGE_ERROR_STRUCTURE_TYPE,
                format!("UmbragePassCreateInfo::pNext: a struct with sType {} is not one this version knows", base.s_type),
            ));
        }
        next = base.p_next;
    }
    Ok(ShadowPassDesc {
        depth_stencil_format: format,
        frames_in_flight: frames,
        depth_mode: depth_mode(info.depthMode)?,
        depth_direction: depth_direction(info.depthDirection)?,
        samples,
        target,
        features: features(info.enabledFeatures)?,
        settings: settings(&info.settings)?,
        transmit_format: (info.transmitFormat != vk::Format::UNDEFINED).then_some(info.transmitFormat),
        debug_color_format: None,
        pipeline_cache: info.pipelineCache,
        // The kept plans' memory budget and the planning threads: the engine's defaults (this
        // version of the ABI has no fields for them).
        ..ShadowPassDesc::default()
    })
}

fn sample_flags(n: u32) -> vk::SampleCountFlags {
    // an unsupported count is refused by the engine's desc check; keep its flag distinct
    vk::SampleCountFlags::from_raw(if n.is_power_of_two() && n <= 64 { n } else { 0 })
}

/// A column-major `double[16]`, all zero meaning the identity.
pub fn transform(m: &[f64; 16]) -> DMat4 {
    if m.iter().all(|&x| x == 0.0) {
        DMat4::IDENTITY
    } else {
        DMat4::from_cols_array(m)
    }
}

pub fn light(i: usize, l: &UmbrageLight) -> Result<Light, CError> {
    let kind = match l.kind {
        0 => LightKind::Point,
        1 => LightKind::Spot,
        2 => LightKind::Directional,
        v => return Err(bad_enum(&format!("UmbrageLight[{i}]::kind"), v)),
    };
    let mut out = Light::point(Vec3::from_array(l.position));
    out.kind = kind;
    out.direction = Vec3::from_array(l.direction);
    out.radius = (l.radius != 0.0).then_some(l.radius);
    if kind == LightKind::Spot {
        out.cone_deg = l.coneDeg;
    }
    Ok(out)
}

pub fn view(v: &UmbrageView) -> Result<engine::pass::ShadowView, CError> {
    check_stype(v.sType, UmbrageStructureType::UMBRAGE_STRUCTURE_TYPE_VIEW, "UmbrageView")?;
    no_next(v.pNext, "UmbrageView")?;
    let eye = DVec3::from_array(v.eye);
    Ok(engine::pass::ShadowView::from_view_matrix(
        eye,
        Mat4::from_cols_array(&v.view),
        Mat4::from_cols_array(&v.projection),
        (v.width, v.height),
    )?)
}

pub fn target(t: &UmbrageDepthStencilTarget) -> Result<engine::pass::DepthStencilTarget, CError> {
    check_stype(t.sType, UmbrageStructureType::UMBRAGE_STRUCTURE_TYPE_DEPTH_STENCIL_TARGET, "UmbrageDepthStencilTarget")?;
    no_next(t.pNext, "UmbrageDepthStencilTarget")?;
    let layout = if t.layout == vk::ImageLayout::UNDEFINED { vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL } else { t.layout };
    let final_layout = if t.finalLayout == vk::ImageLayout::UNDEFINED { layout } else { t.finalLayout };
    Ok(engine::pass::DepthStencilTarget::new(t.image, t.view, t.extent).with_layouts(layout, final_layout))
}

/// A mesh from C arrays.
///
/// # Safety
/// `pPositions` holds `vertexCount * 3` floats and `pIndices` `indexCount` indices of
/// `indexType` (each NULL only with a zero count).
pub unsafe fn mesh(info: &UmbrageCasterInfo) -> Result<engine::geom::Mesh, CError> {
    let nv = info.vertexCount as usize;
    let ni = info.indexCount as usize;
    if nv > 0 {
        non_null(info.pPositions, "UmbrageCasterInfo::pPositions")?;
    }
    if ni > 0 {
        non_null(info.pIndices, "UmbrageCasterInfo::pIndices")?;
    }
    if !ni.is_multiple_of(3) {
        return Err(CError::argument("UmbrageCasterInfo::indexCount", format!("{ni} is not a multiple of 3")));
    }
    let positions: Vec<Vec3> = if nv == 0 {
        Vec::new()
    } else {
        // SAFETY: the caller's contract.
        let p = unsafe { std::slice::from_raw_parts(info.pPositions, nv * 3) };
        p.chunks_exact(3).map(|c| Vec3::new(c[0], c[1], c[2])).collect()
    };
    let indices: Vec<u32> = match (ni, info.indexType) {
        (0, 0 | 1) => Vec::new(),
        // SAFETY: the caller's contract.
        (_, 0) => unsafe { std::slice::from_raw_parts(info.pIndices.cast::<u32>(), ni) }.to_vec(),
        // SAFETY: the caller's contract.
        (_, 1) => unsafe { std::slice::from_raw_parts(info.pIndices.cast::<u16>(), ni) }.iter().map(|&i| i as u32).collect(),
        (_, v) => return Err(bad_enum("UmbrageCasterInfo::indexType", v)),
    };
    // Indices past the vertices are the engine's to refuse (Error::Mesh, docs/contract.md).
    Ok(engine::geom::Mesh { positions, triangles: indices.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect() })
}

/// A device described in C, as the engine's report of it.
///
/// # Safety
/// The description's pointers are valid for their counts (NULL only with a zero count).
pub unsafe fn device_caps(d: &UmbrageDeviceDescription) -> Result<engine::gpu::DeviceCaps, CError> {
    check_stype(d.sType, UmbrageStructureType::UMBRAGE_STRUCTURE_TYPE_DEVICE_DESCRIPTION, "UmbrageDeviceDescription")?;
    no_next(d.pNext, "UmbrageDeviceDescription")?;
    let mut caps = engine::gpu::DeviceCaps { api_version: d.apiVersion, ..Default::default() };
    if d.extensionCount > 0 {
        non_null(d.ppExtensionNames, "UmbrageDeviceDescription::ppExtensionNames")?;
        // SAFETY: the caller's contract.
        let names = unsafe { std::slice::from_raw_parts(d.ppExtensionNames, d.extensionCount as usize) };
        for (i, &n) in names.iter().enumerate() {
            non_null(n, &format!("UmbrageDeviceDescription::ppExtensionNames[{i}]"))?;
            // SAFETY: the caller's contract: a NUL-terminated name.
            caps.extensions.push(unsafe { CStr::from_ptr(n) }.to_string_lossy().into_owned());
        }
    }
    if d.formatCount > 0 {
        non_null(d.pFormats, "UmbrageDeviceDescription::pFormats")?;
        // SAFETY: the caller's contract.
        let formats = unsafe { std::slice::from_raw_parts(d.pFormats, d.formatCount as usize) };
        for f in formats {
            caps.formats.push((f.format, f.optimalTilingFeatures));
            if !f.sampleCounts.is_empty() {
                caps.depth_stencil_image_samples.push((f.format, f.sampleCounts));
            }
        }
    }
    caps.limits = if d.pLimits.is_null() {
        let all = vk::SampleCountFlags::from_raw(0xf);
        vk::PhysicalDeviceLimits {
            framebuffer_depth_sample_counts: all,
            framebuffer_stencil_sample_counts: all,
            max_storage_buffer_range: u32::MAX,
            max_draw_indirect_count: u32::MAX,
            ..Default::default()
        }
    } else {
        // SAFETY: the caller's contract.
        unsafe { *d.pLimits }
    };
    let bits = d.deviceFeatures;
    if bits & !0xfff != 0 {
        return Err(CError::argument("UmbrageDeviceDescription::deviceFeatures", format!("unknown bits {:#x}", bits & !0xfff)));
    }
    let b = |x: UmbrageDeviceFeatureFlagBits| bits & x as u32 != 0;
    use UmbrageDeviceFeatureFlagBits::*;
    let f = &mut caps.features;
    f.depth_clamp = b(UMBRAGE_DEVICE_FEATURE_DEPTH_CLAMP_BIT);
    f.depth_bounds = b(UMBRAGE_DEVICE_FEATURE_DEPTH_BOUNDS_BIT);
    f.index_type_uint8 = b(UMBRAGE_DEVICE_FEATURE_INDEX_TYPE_UINT8_BIT);
    f.ray_query = b(UMBRAGE_DEVICE_FEATURE_RAY_QUERY_BIT);
    f.mesh_shader = b(UMBRAGE_DEVICE_FEATURE_MESH_SHADER_BIT);
    f.draw_indirect_first_instance = b(UMBRAGE_DEVICE_FEATURE_DRAW_INDIRECT_FIRST_INSTANCE_BIT);
    f.multi_draw_indirect = b(UMBRAGE_DEVICE_FEATURE_MULTI_DRAW_INDIRECT_BIT);
    f.draw_indirect_count = b(UMBRAGE_DEVICE_FEATURE_DRAW_INDIRECT_COUNT_BIT);
    f.task_shader = b(UMBRAGE_DEVICE_FEATURE_TASK_SHADER_BIT);
    f.acceleration_structure = b(UMBRAGE_DEVICE_FEATURE_ACCELERATION_STRUCTURE_BIT);
    f.buffer_device_address = b(UMBRAGE_DEVICE_FEATURE_BUFFER_DEVICE_ADDRESS_BIT);
    f.dynamic_rendering = b(UMBRAGE_DEVICE_FEATURE_DYNAMIC_RENDERING_BIT);
    Ok(caps)
}
