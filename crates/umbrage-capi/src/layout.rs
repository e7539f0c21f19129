//! Layouts pinned: every struct's size and every field's offset (LP64: 64-bit pointers), and
//! the enums' values. The header asserts the same numbers (cbindgen.toml's trailer, written
//! from this file by `scripts/capi-layout.py`): a field added, moved or resized on one side
//! only fails a build.

#![allow(clippy::identity_op)]

use crate::types::*;
use std::mem::{offset_of, size_of};

/// `size_of` and each field's `offset_of` of a struct, asserted at compile time.
macro_rules! pin {
    ($t:ident, $size:expr, $($f:ident = $o:expr),* $(,)?) => {
        const _: () = assert!(size_of::<$t>() == $size);
        $(const _: () = assert!(offset_of!($t, $f) == $o);)*
    };
}

#[cfg(target_pointer_width = "64")]
mod lp64 {
    use super::*;
    pin!(UmbrageRenderPassTarget, 32, sType = 0, pNext = 8, renderPass = 16, subpass = 24, colorAttachmentCount = 28);
    pin!(UmbrageKeepInfo, 32, sType = 0, pNext = 8, keepBudgetBytes = 16, planThreads = 24, disableKeep = 28);
    pin!(
        UmbrageKeepStats,
        56,
        sType = 0,
        pNext = 8,
        pairsTotal = 16,
        pairsKept = 24,
        pairsReplanned = 32,
        keptBytes = 40,
        keptEvictions = 48
    );
    pin!(
        UmbragePassCreateInfo,
        112,
        sType = 0,
        pNext = 8,
        abiVersion = 16,
        depthStencilFormat = 20,
        samples = 24,
        framesInFlight = 28,
        depthDirection = 32,
        depthMode = 36,
        enabledFeatures = 40,
        settings = 44,
        transmitFormat = 84,
        pipelineCache = 88,
        pfnWarning = 96,
        pWarningUserData = 104
    );
    pin!(UmbrageVulkanDevice, 40, pfnGetInstanceProcAddr = 0, pfnGetDeviceProcAddr = 8, instance = 16, physicalDevice = 24, device = 32);
    pin!(
        UmbragePassSettings,
        40,
        technique = 0,
        method = 4,
        counter = 8,
        indexFormat = 12,
        computeDraws = 16,
        disableScissor = 20,
        disableDepthBounds = 24,
        disableCulling = 28,
        disableMeshTask = 32,
        rayBatch = 36
    );
    pin!(
        UmbrageCapabilities,
        40,
        rayQuery = 0,
        depthClamp = 4,
        depthBounds = 8,
        indexTypeUint8 = 12,
        r32fBlend = 16,
        meshShader = 20,
        drawIndirectFirstInstance = 24,
        multiDrawIndirect = 28,
        drawIndirectCount = 32,
        taskShader = 36
    );
    pin!(UmbrageFormatFeatures, 12, format = 0, optimalTilingFeatures = 4, sampleCounts = 8);
    pin!(
        UmbrageDeviceDescription,
        64,
        sType = 0,
        pNext = 8,
        apiVersion = 16,
        deviceFeatures = 20,
        ppExtensionNames = 24,
        extensionCount = 32,
        pFormats = 40,
        formatCount = 48,
        pLimits = 56
    );
    pin!(
        UmbrageCasterInfo,
        200,
        sType = 0,
        pNext = 8,
        pName = 16,
        pPositions = 24,
        vertexCount = 32,
        pIndices = 40,
        indexCount = 48,
        indexType = 52,
        transform = 56,
        transparent = 184,
        transmittance = 188
    );
    pin!(UmbrageSphereInfo, 64, sType = 0, pNext = 8, pName = 16, center = 24, radius = 48, segments = 56);
    pin!(UmbrageLight, 36, kind = 0, position = 4, direction = 16, coneDeg = 28, radius = 32);
    pin!(UmbrageView, 184, sType = 0, pNext = 8, eye = 16, view = 40, projection = 104, width = 168, height = 172, culled = 176);
    pin!(UmbrageFrame, 24, pass = 0, serial = 8, slot = 16, lights = 20);
    pin!(UmbrageDepthStencilTarget, 48, sType = 0, pNext = 8, image = 16, view = 24, extent = 32, layout = 40, finalLayout = 44);
    pin!(
        UmbrageLightInfo,
        56,
        sType = 0,
        pNext = 8,
        scissor = 16,
        hasDepthBounds = 32,
        minDepthBounds = 36,
        maxDepthBounds = 40,
        casterCount = 44,
        triangles = 48
    );
    pin!(
        UmbrageFrameStats,
        136,
        sType = 0,
        pNext = 8,
        sideTriangles = 16,
        darkCapTriangles = 24,
        lightCapTriangles = 32,
        indexBytes = 40,
        vertexBytes = 48,
        bytesSent = 56,
        draws = 64,
        casesCulled = 72,
        casesZPass = 80,
        casesZFail = 88,
        casesZFailLightCap = 96,
        cpuSilhouettesMs = 104,
        cpuPlanMs = 112,
        cpuRecordMs = 120,
        warningCount = 128,
        pendingUploads = 132
    );
    pin!(UmbrageRayQueryInputs, 40, sType = 0, pNext = 8, position = 16, normal = 24, surfaceOffset = 32);
}

// Enum values (the header asserts them too).
const _: () = assert!(UmbrageResult::UMBRAGE_SUCCESS as u32 == 0);
const _: () = assert!(UmbrageResult::UMBRAGE_ERROR_INPUT as u32 == 1);
const _: () = assert!(UmbrageResult::UMBRAGE_ERROR_MESH as u32 == 2);
const _: () = assert!(UmbrageResult::UMBRAGE_ERROR_UNKNOWN_NAME as u32 == 3);
const _: () = assert!(UmbrageResult::UMBRAGE_ERROR_NO_DEVICE as u32 == 4);
const _: () = assert!(UmbrageResult::UMBRAGE_ERROR_VULKAN as u32 == 5);
const _: () = assert!(UmbrageResult::UMBRAGE_ERROR_ALLOCATION as u32 == 6);
const _: () = assert!(UmbrageResult::UMBRAGE_ERROR_OUT_OF_MEMORY as u32 == 7);
const _: () = assert!(UmbrageResult::UMBRAGE_ERROR_UNSUPPORTED as u32 == 8);
const _: () = assert!(UmbrageResult::UMBRAGE_ERROR_VALIDATION as u32 == 9);
const _: () = assert!(UmbrageResult::UMBRAGE_ERROR_INTERNAL as u32 == 10);
const _: () = assert!(UmbrageResult::UMBRAGE_ERROR_INVALID_DESC as u32 == 11);
const _: () = assert!(UmbrageResult::UMBRAGE_ERROR_OTHER as u32 == 12);
const _: () = assert!(UmbrageResult::UMBRAGE_ERROR_IO as u32 == 13);
const _: () = assert!(UmbrageResult::UMBRAGE_ERROR_LIGHT_INDEX as u32 == 100);
const _: () = assert!(UmbrageResult::UMBRAGE_ERROR_SLOT_OUT_OF_RANGE as u32 == 101);
const _: () = assert!(UmbrageResult::UMBRAGE_ERROR_FOREIGN_FRAME as u32 == 102);
const _: () = assert!(UmbrageResult::UMBRAGE_ERROR_STALE_FRAME as u32 == 103);
const _: () = assert!(UmbrageResult::UMBRAGE_ERROR_UNKNOWN_ID as u32 == 104);
const _: () = assert!(UmbrageResult::UMBRAGE_ERROR_FOREIGN_ID as u32 == 105);
const _: () = assert!(UmbrageResult::UMBRAGE_ERROR_NOT_CONFIGURED as u32 == 106);
const _: () = assert!(UmbrageResult::UMBRAGE_ERROR_ORDER as u32 == 107);
const _: () = assert!(UmbrageResult::UMBRAGE_ERROR_ARGUMENT as u32 == 108);
const _: () = assert!(UmbrageResult::UMBRAGE_ERROR_NULL_POINTER as u32 == 200);
const _: () = assert!(UmbrageResult::UMBRAGE_ERROR_PANIC as u32 == 201);
const _: () = assert!(UmbrageResult::UMBRAGE_ERROR_POISONED as u32 == 202);
const _: () = assert!(UmbrageResult::UMBRAGE_ERROR_VERSION_MISMATCH as u32 == 203);
const _: () = assert!(UmbrageResult::UMBRAGE_ERROR_STRUCTURE_TYPE as u32 == 204);
const _: () = assert!(size_of::<UmbrageResult>() == 4);
const _: () = assert!(UmbrageStructureType::UMBRAGE_STRUCTURE_TYPE_PASS_CREATE_INFO as u32 == 1);
const _: () = assert!(UmbrageStructureType::UMBRAGE_STRUCTURE_TYPE_RENDER_PASS_TARGET as u32 == 2);
const _: () = assert!(UmbrageStructureType::UMBRAGE_STRUCTURE_TYPE_CASTER_INFO as u32 == 3);
const _: () = assert!(UmbrageStructureType::UMBRAGE_STRUCTURE_TYPE_SPHERE_INFO as u32 == 4);
const _: () = assert!(UmbrageStructureType::UMBRAGE_STRUCTURE_TYPE_VIEW as u32 == 5);
const _: () = assert!(UmbrageStructureType::UMBRAGE_STRUCTURE_TYPE_DEPTH_STENCIL_TARGET as u32 == 6);
const _: () = assert!(UmbrageStructureType::UMBRAGE_STRUCTURE_TYPE_DEVICE_DESCRIPTION as u32 == 7);
const _: () = assert!(UmbrageStructureType::UMBRAGE_STRUCTURE_TYPE_FRAME_STATS as u32 == 8);
const _: () = assert!(UmbrageStructureType::UMBRAGE_STRUCTURE_TYPE_LIGHT_INFO as u32 == 9);
const _: () = assert!(UmbrageStructureType::UMBRAGE_STRUCTURE_TYPE_RAY_QUERY_INPUTS as u32 == 10);
const _: () = assert!(UmbrageStructureType::UMBRAGE_STRUCTURE_TYPE_KEEP_INFO as u32 == 11);
const _: () = assert!(UmbrageStructureType::UMBRAGE_STRUCTURE_TYPE_KEEP_STATS as u32 == 12);
const _: () = assert!(size_of::<UmbrageStructureType>() == 4);
const _: () = assert!(UmbrageDepthDirection::UMBRAGE_DEPTH_DIRECTION_FORWARD as u32 == 0);
const _: () = assert!(UmbrageDepthDirection::UMBRAGE_DEPTH_DIRECTION_REVERSE as u32 == 1);
const _: () = assert!(size_of::<UmbrageDepthDirection>() == 4);
const _: () = assert!(UmbrageDepthMode::UMBRAGE_DEPTH_MODE_INFINITE as u32 == 0);
const _: () = assert!(UmbrageDepthMode::UMBRAGE_DEPTH_MODE_CLAMP as u32 == 1);
const _: () = assert!(size_of::<UmbrageDepthMode>() == 4);
const _: () = assert!(UmbrageTechnique::UMBRAGE_TECHNIQUE_VOLUMES as u32 == 0);
const _: () = assert!(UmbrageTechnique::UMBRAGE_TECHNIQUE_EDGE_QUADS as u32 == 1);
const _: () = assert!(UmbrageTechnique::UMBRAGE_TECHNIQUE_PLANAR as u32 == 2);
const _: () = assert!(UmbrageTechnique::UMBRAGE_TECHNIQUE_COMPUTE as u32 == 3);
const _: () = assert!(UmbrageTechnique::UMBRAGE_TECHNIQUE_MESH as u32 == 4);
const _: () = assert!(UmbrageTechnique::UMBRAGE_TECHNIQUE_RAY_QUERY as u32 == 5);
const _: () = assert!(size_of::<UmbrageTechnique>() == 4);
const _: () = assert!(UmbrageMethod::UMBRAGE_METHOD_MCGUIRE as u32 == 0);
const _: () = assert!(UmbrageMethod::UMBRAGE_METHOD_ZPASS as u32 == 1);
const _: () = assert!(UmbrageMethod::UMBRAGE_METHOD_ZFAIL as u32 == 2);
const _: () = assert!(UmbrageMethod::UMBRAGE_METHOD_EVERITT_KILGARD as u32 == 3);
const _: () = assert!(UmbrageMethod::UMBRAGE_METHOD_LENGYEL as u32 == 4);
const _: () = assert!(size_of::<UmbrageMethod>() == 4);
const _: () = assert!(UmbrageCounter::UMBRAGE_COUNTER_STENCIL as u32 == 0);
const _: () = assert!(UmbrageCounter::UMBRAGE_COUNTER_FLOAT as u32 == 1);
const _: () = assert!(size_of::<UmbrageCounter>() == 4);
const _: () = assert!(UmbrageIndexFormat::UMBRAGE_INDEX_FORMAT_AUTO as u32 == 0);
const _: () = assert!(UmbrageIndexFormat::UMBRAGE_INDEX_FORMAT_U32 as u32 == 1);
const _: () = assert!(UmbrageIndexFormat::UMBRAGE_INDEX_FORMAT_U16 as u32 == 2);
const _: () = assert!(UmbrageIndexFormat::UMBRAGE_INDEX_FORMAT_U8 as u32 == 3);
const _: () = assert!(UmbrageIndexFormat::UMBRAGE_INDEX_FORMAT_NAIVE as u32 == 4);
const _: () = assert!(size_of::<UmbrageIndexFormat>() == 4);
const _: () = assert!(UmbrageComputeDraws::UMBRAGE_COMPUTE_DRAWS_AUTO as u32 == 0);
const _: () = assert!(UmbrageComputeDraws::UMBRAGE_COMPUTE_DRAWS_COUNT as u32 == 1);
const _: () = assert!(UmbrageComputeDraws::UMBRAGE_COMPUTE_DRAWS_MULTI as u32 == 2);
const _: () = assert!(UmbrageComputeDraws::UMBRAGE_COMPUTE_DRAWS_PER_RECORD as u32 == 3);
const _: () = assert!(UmbrageComputeDraws::UMBRAGE_COMPUTE_DRAWS_PER_CHUNK as u32 == 4);
const _: () = assert!(size_of::<UmbrageComputeDraws>() == 4);
const _: () = assert!(UmbrageLightKind::UMBRAGE_LIGHT_KIND_POINT as u32 == 0);
const _: () = assert!(UmbrageLightKind::UMBRAGE_LIGHT_KIND_SPOT as u32 == 1);
const _: () = assert!(UmbrageLightKind::UMBRAGE_LIGHT_KIND_DIRECTIONAL as u32 == 2);
const _: () = assert!(size_of::<UmbrageLightKind>() == 4);
const _: () = assert!(UmbrageIndexType::UMBRAGE_INDEX_TYPE_UINT32 as u32 == 0);
const _: () = assert!(UmbrageIndexType::UMBRAGE_INDEX_TYPE_UINT16 as u32 == 1);
const _: () = assert!(size_of::<UmbrageIndexType>() == 4);
const _: () = assert!(UmbrageFeatureFlagBits::UMBRAGE_FEATURE_DEPTH_CLAMP_BIT as u32 == 0x1);
const _: () = assert!(UmbrageFeatureFlagBits::UMBRAGE_FEATURE_DEPTH_BOUNDS_BIT as u32 == 0x2);
const _: () = assert!(UmbrageFeatureFlagBits::UMBRAGE_FEATURE_INDEX_TYPE_UINT8_BIT as u32 == 0x4);
const _: () = assert!(UmbrageFeatureFlagBits::UMBRAGE_FEATURE_RAY_QUERY_BIT as u32 == 0x8);
const _: () = assert!(UmbrageFeatureFlagBits::UMBRAGE_FEATURE_MESH_SHADER_BIT as u32 == 0x10);
const _: () = assert!(UmbrageFeatureFlagBits::UMBRAGE_FEATURE_DRAW_INDIRECT_FIRST_INSTANCE_BIT as u32 == 0x20);
const _: () = assert!(UmbrageFeatureFlagBits::UMBRAGE_FEATURE_MULTI_DRAW_INDIRECT_BIT as u32 == 0x40);
const _: () = assert!(UmbrageFeatureFlagBits::UMBRAGE_FEATURE_DRAW_INDIRECT_COUNT_BIT as u32 == 0x80);
const _: () = assert!(UmbrageFeatureFlagBits::UMBRAGE_FEATURE_TASK_SHADER_BIT as u32 == 0x100);
const _: () = assert!(size_of::<UmbrageFeatureFlagBits>() == 4);
const _: () = assert!(UmbrageDeviceFeatureFlagBits::UMBRAGE_DEVICE_FEATURE_DEPTH_CLAMP_BIT as u32 == 0x1);
const _: () = assert!(UmbrageDeviceFeatureFlagBits::UMBRAGE_DEVICE_FEATURE_DEPTH_BOUNDS_BIT as u32 == 0x2);
const _: () = assert!(UmbrageDeviceFeatureFlagBits::UMBRAGE_DEVICE_FEATURE_INDEX_TYPE_UINT8_BIT as u32 == 0x4);
const _: () = assert!(UmbrageDeviceFeatureFlagBits::UMBRAGE_DEVICE_FEATURE_RAY_QUERY_BIT as u32 == 0x8);
const _: () = assert!(UmbrageDeviceFeatureFlagBits::UMBRAGE_DEVICE_FEATURE_MESH_SHADER_BIT as u32 == 0x10);
const _: () = assert!(UmbrageDeviceFeatureFlagBits::UMBRAGE_DEVICE_FEATURE_DRAW_INDIRECT_FIRST_INSTANCE_BIT as u32 == 0x20);
const _: () = assert!(UmbrageDeviceFeatureFlagBits::UMBRAGE_DEVICE_FEATURE_MULTI_DRAW_INDIRECT_BIT as u32 == 0x40);
const _: () = assert!(UmbrageDeviceFeatureFlagBits::UMBRAGE_DEVICE_FEATURE_DRAW_INDIRECT_COUNT_BIT as u32 == 0x80);
const _: () = assert!(UmbrageDeviceFeatureFlagBits::UMBRAGE_DEVICE_FEATURE_TASK_SHADER_BIT as u32 == 0x100);
const _: () = assert!(UmbrageDeviceFeatureFlagBits::UMBRAGE_DEVICE_FEATURE_ACCELERATION_STRUCTURE_BIT as u32 == 0x200);
const _: () = assert!(UmbrageDeviceFeatureFlagBits::UMBRAGE_DEVICE_FEATURE_BUFFER_DEVICE_ADDRESS_BIT as u32 == 0x400);
const _: () = assert!(UmbrageDeviceFeatureFlagBits::UMBRAGE_DEVICE_FEATURE_DYNAMIC_RENDERING_BIT as u32 == 0x800);
const _: () = assert!(size_of::<UmbrageDeviceFeatureFlagBits>() == 4);
