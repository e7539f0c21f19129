//! The C ABI's enums: result codes, options and flag bits, each value pinned and never
//! renumbered (the header's `_Static_assert`s and `layout.rs` hold them).

/// What every call returns. The values are pinned and never renumbered: 0 is success, 1-99
/// are the Rust `umbrage::Error` variants one to one, 100-199 its `umbrage::Misuse` variants
/// one to one, 200 and up the C boundary's own. `umbrage_last_error_message` says more.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[allow(non_camel_case_types)]
pub enum UmbrageResult {
    /// Success.
    UMBRAGE_SUCCESS = 0,
    /// `Error::Input`: bad input in a file.
    UMBRAGE_ERROR_INPUT = 1,
    /// `Error::Mesh`: a mesh that cannot be used (NaN, empty, out-of-range index...).
    UMBRAGE_ERROR_MESH = 2,
    /// `Error::UnknownName`.
    UMBRAGE_ERROR_UNKNOWN_NAME = 3,
    /// `Error::NoDevice`.
    UMBRAGE_ERROR_NO_DEVICE = 4,
    /// `Error::Vulkan`: a Vulkan call failed; the message names the call and its `VkResult`.
    UMBRAGE_ERROR_VULKAN = 5,
    /// `Error::Allocation`: the pass's allocator could not allocate device memory.
    UMBRAGE_ERROR_ALLOCATION = 6,
    /// `Error::OutOfMemory`.
    UMBRAGE_ERROR_OUT_OF_MEMORY = 7,
    /// `Error::Unsupported`: the device (or what the host enabled) lacks what was asked.
    UMBRAGE_ERROR_UNSUPPORTED = 8,
    /// `Error::Validation`.
    UMBRAGE_ERROR_VALIDATION = 9,
    /// `Error::Internal`: a bug in umbrage. The pass is poisoned: only destroy works after it.
    UMBRAGE_ERROR_INTERNAL = 10,
    /// `Error::InvalidDesc`: a creation option that cannot be honoured; the message names it.
    UMBRAGE_ERROR_INVALID_DESC = 11,
    /// Reserved: the engine's `Error::Other` is gone (0.2), so no call returns it; kept so the
    /// codes after it keep their values.
    UMBRAGE_ERROR_OTHER = 12,
    /// `Error::Io`.
    UMBRAGE_ERROR_IO = 13,
    /// `Misuse::LightIndex`: a light index past the frame's lights.
    UMBRAGE_ERROR_LIGHT_INDEX = 100,
    /// `Misuse::SlotOutOfRange`: a ring slot past `framesInFlight`.
    UMBRAGE_ERROR_SLOT_OUT_OF_RANGE = 101,
    /// `Misuse::ForeignFrame`: a frame another pass prepared.
    UMBRAGE_ERROR_FOREIGN_FRAME = 102,
    /// `Misuse::StaleFrame`: a frame whose slot was prepared again since.
    UMBRAGE_ERROR_STALE_FRAME = 103,
    /// `Misuse::UnknownId`: a caster or sphere id that is not (or no longer) in the pass.
    UMBRAGE_ERROR_UNKNOWN_ID = 104,
    /// `Misuse::ForeignId`: an id another pass made.
    UMBRAGE_ERROR_FOREIGN_ID = 105,
    /// `Misuse::NotConfigured`: a call that needs an option the pass was not created with.
    UMBRAGE_ERROR_NOT_CONFIGURED = 106,
    /// `Misuse::Order`: a call made out of order.
    UMBRAGE_ERROR_ORDER = 107,
    /// `Misuse::Argument`: an argument outside its documented range; the message names it.
    UMBRAGE_ERROR_ARGUMENT = 108,
    /// A required pointer argument was NULL.
    UMBRAGE_ERROR_NULL_POINTER = 200,
    /// A panic was caught at the boundary (a bug in umbrage). The pass is poisoned.
    UMBRAGE_ERROR_PANIC = 201,
    /// The pass was poisoned by an earlier internal error or panic: only
    /// `umbrage_pass_destroy` works on it.
    UMBRAGE_ERROR_POISONED = 202,
    /// The header the host was compiled with is not this library's ABI
    /// (`UmbragePassCreateInfo::abiVersion`).
    UMBRAGE_ERROR_VERSION_MISMATCH = 203,
    /// A struct whose `sType` is not the one the call takes, or an unknown struct in a `pNext`
    /// chain.
    UMBRAGE_ERROR_STRUCTURE_TYPE = 204,
}

/// The `sType` of every extensible struct. Values are pinned, never reused.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[allow(non_camel_case_types)]
pub enum UmbrageStructureType {
    /// [`UmbragePassCreateInfo`].
    UMBRAGE_STRUCTURE_TYPE_PASS_CREATE_INFO = 1,
    /// [`UmbrageRenderPassTarget`], chained to [`UmbragePassCreateInfo`].
    UMBRAGE_STRUCTURE_TYPE_RENDER_PASS_TARGET = 2,
    /// [`UmbrageCasterInfo`].
    UMBRAGE_STRUCTURE_TYPE_CASTER_INFO = 3,
    /// [`UmbrageSphereInfo`].
    UMBRAGE_STRUCTURE_TYPE_SPHERE_INFO = 4,
    /// [`UmbrageView`].
    UMBRAGE_STRUCTURE_TYPE_VIEW = 5,
    /// [`UmbrageDepthStencilTarget`].
    UMBRAGE_STRUCTURE_TYPE_DEPTH_STENCIL_TARGET = 6,
    /// [`UmbrageDeviceDescription`].
    UMBRAGE_STRUCTURE_TYPE_DEVICE_DESCRIPTION = 7,
    /// [`UmbrageFrameStats`].
    UMBRAGE_STRUCTURE_TYPE_FRAME_STATS = 8,
    /// [`UmbrageLightInfo`].
    UMBRAGE_STRUCTURE_TYPE_LIGHT_INFO = 9,
    /// [`UmbrageRayQueryInputs`].
    UMBRAGE_STRUCTURE_TYPE_RAY_QUERY_INPUTS = 10,
}

/// Which way the host's depth runs.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[allow(non_camel_case_types)]
pub enum UmbrageDepthDirection {
    /// Depth 0 at the near plane, 1 at the far plane or infinity (closer is LESS). Default.
    UMBRAGE_DEPTH_DIRECTION_FORWARD = 0,
    /// Reverse-Z: 1 at the near plane, 0 at infinity (closer is GREATER).
    UMBRAGE_DEPTH_DIRECTION_REVERSE = 1,
}

/// How z-fail keeps the far plane out of the way.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[allow(non_camel_case_types)]
pub enum UmbrageDepthMode {
    /// An infinite far plane. Default.
    UMBRAGE_DEPTH_MODE_INFINITE = 0,
    /// A finite far plane with `depthClamp`.
    UMBRAGE_DEPTH_MODE_CLAMP = 1,
}

/// How the shadow volumes are made each frame.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[allow(non_camel_case_types)]
pub enum UmbrageTechnique {
    /// CPU silhouettes and index streams with a case rule ([`UmbrageMethod`]). Default.
    UMBRAGE_TECHNIQUE_VOLUMES = 0,
    /// Static edge quads extruded in the vertex shader.
    UMBRAGE_TECHNIQUE_EDGE_QUADS = 1,
    /// Casters flattened onto one receiver plane (`umbrage_pass_set_planar_receiver`).
    UMBRAGE_TECHNIQUE_PLANAR = 2,
    /// GPU silhouettes in a compute pass, drawn indirect.
    UMBRAGE_TECHNIQUE_COMPUTE = 3,
    /// Mesh-shader extrusion (`VK_EXT_mesh_shader`).
    UMBRAGE_TECHNIQUE_MESH = 4,
    /// One shadow ray a pixel (`VK_KHR_ray_query`), from the host's G-buffer.
    UMBRAGE_TECHNIQUE_RAY_QUERY = 5,
}

/// The case rule of [`UmbrageTechnique::UMBRAGE_TECHNIQUE_VOLUMES`].
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[allow(non_camel_case_types)]
pub enum UmbrageMethod {
    /// McGuire et al. 2003: per caster the cheapest correct case. Default.
    UMBRAGE_METHOD_MCGUIRE = 0,
    /// Heidmann's z-pass for every caster.
    UMBRAGE_METHOD_ZPASS = 1,
    /// Carmack's z-fail for every caster.
    UMBRAGE_METHOD_ZFAIL = 2,
    /// Everitt & Kilgard's robust z-fail.
    UMBRAGE_METHOD_EVERITT_KILGARD = 3,
    /// Lengyel's choice.
    UMBRAGE_METHOD_LENGYEL = 4,
}

/// Where the volumes are counted.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[allow(non_camel_case_types)]
pub enum UmbrageCounter {
    /// The 8-bit stencil (wrapping). Default.
    UMBRAGE_COUNTER_STENCIL = 0,
    /// A 32-bit float target (no wrap).
    UMBRAGE_COUNTER_FLOAT = 1,
}

/// The index format of the per-frame shadow streams.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[allow(non_camel_case_types)]
pub enum UmbrageIndexFormat {
    /// 8-bit where possible, else 16-bit. Default.
    UMBRAGE_INDEX_FORMAT_AUTO = 0,
    /// 32-bit.
    UMBRAGE_INDEX_FORMAT_U32 = 1,
    /// 16-bit.
    UMBRAGE_INDEX_FORMAT_U16 = 2,
    /// 8-bit (needs `indexTypeUint8`).
    UMBRAGE_INDEX_FORMAT_U8 = 3,
    /// No indices (the naive baseline).
    UMBRAGE_INDEX_FORMAT_NAIVE = 4,
}

/// How the compute technique's volume draws are recorded.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[allow(non_camel_case_types)]
pub enum UmbrageComputeDraws {
    /// The best the device and the enabled features allow. Default.
    UMBRAGE_COMPUTE_DRAWS_AUTO = 0,
    /// `vkCmdDrawIndexedIndirectCount`.
    UMBRAGE_COMPUTE_DRAWS_COUNT = 1,
    /// One multi-draw indirect per light and pipeline.
    UMBRAGE_COMPUTE_DRAWS_MULTI = 2,
    /// One indirect draw per record.
    UMBRAGE_COMPUTE_DRAWS_PER_RECORD = 3,
    /// One indirect draw per chunk with push constants.
    UMBRAGE_COMPUTE_DRAWS_PER_CHUNK = 4,
}

/// A light's kind.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[allow(non_camel_case_types)]
pub enum UmbrageLightKind {
    /// A point light at `position`. Default.
    UMBRAGE_LIGHT_KIND_POINT = 0,
    /// A spot light at `position` shining along `direction` within `coneDeg`.
    UMBRAGE_LIGHT_KIND_SPOT = 1,
    /// A directional light travelling along `direction`.
    UMBRAGE_LIGHT_KIND_DIRECTIONAL = 2,
}

/// The index type of a caster's triangles.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[allow(non_camel_case_types)]
pub enum UmbrageIndexType {
    /// `uint32_t` indices. Default.
    UMBRAGE_INDEX_TYPE_UINT32 = 0,
    /// `uint16_t` indices.
    UMBRAGE_INDEX_TYPE_UINT16 = 1,
}

/// The optional device features the host enabled on its `VkDevice` (bits of
/// `UmbragePassCreateInfo::enabledFeatures`). The pass uses one only when the host enabled it
/// and the physical device reports it. Values are pinned.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[allow(non_camel_case_types)]
pub enum UmbrageFeatureFlagBits {
    /// `depthClamp` (needed by `UMBRAGE_DEPTH_MODE_CLAMP`).
    UMBRAGE_FEATURE_DEPTH_CLAMP_BIT = 0x1,
    /// `depthBounds`: the determination limited to the light's depth range.
    UMBRAGE_FEATURE_DEPTH_BOUNDS_BIT = 0x2,
    /// `indexTypeUint8` (`VK_EXT_index_type_uint8` / `VK_KHR_index_type_uint8`).
    UMBRAGE_FEATURE_INDEX_TYPE_UINT8_BIT = 0x4,
    /// `rayQuery` + `accelerationStructure` + `bufferDeviceAddress`.
    UMBRAGE_FEATURE_RAY_QUERY_BIT = 0x8,
    /// `meshShader` (`VK_EXT_mesh_shader`).
    UMBRAGE_FEATURE_MESH_SHADER_BIT = 0x10,
    /// `drawIndirectFirstInstance`.
    UMBRAGE_FEATURE_DRAW_INDIRECT_FIRST_INSTANCE_BIT = 0x20,
    /// `multiDrawIndirect`.
    UMBRAGE_FEATURE_MULTI_DRAW_INDIRECT_BIT = 0x40,
    /// `drawIndirectCount` (Vulkan 1.2).
    UMBRAGE_FEATURE_DRAW_INDIRECT_COUNT_BIT = 0x80,
    /// `taskShader` (with the mesh shader).
    UMBRAGE_FEATURE_TASK_SHADER_BIT = 0x100,
}

/// A set of [`UmbrageFeatureFlagBits`].
pub type UmbrageFeatureFlags = u32;

/// What a physical device reports, for `umbrage_capabilities_for` (bits of
/// `UmbrageDeviceDescription::deviceFeatures`; the first nine are [`UmbrageFeatureFlagBits`]'
/// values). Values are pinned.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[allow(non_camel_case_types)]
pub enum UmbrageDeviceFeatureFlagBits {
    /// `depthClamp`.
    UMBRAGE_DEVICE_FEATURE_DEPTH_CLAMP_BIT = 0x1,
    /// `depthBounds`.
    UMBRAGE_DEVICE_FEATURE_DEPTH_BOUNDS_BIT = 0x2,
    /// `indexTypeUint8`.
    UMBRAGE_DEVICE_FEATURE_INDEX_TYPE_UINT8_BIT = 0x4,
    /// `rayQuery`.
    UMBRAGE_DEVICE_FEATURE_RAY_QUERY_BIT = 0x8,
    /// `meshShader`.
    UMBRAGE_DEVICE_FEATURE_MESH_SHADER_BIT = 0x10,
    /// `drawIndirectFirstInstance`.
    UMBRAGE_DEVICE_FEATURE_DRAW_INDIRECT_FIRST_INSTANCE_BIT = 0x20,
    /// `multiDrawIndirect`.
    UMBRAGE_DEVICE_FEATURE_MULTI_DRAW_INDIRECT_BIT = 0x40,
    /// `drawIndirectCount`.
    UMBRAGE_DEVICE_FEATURE_DRAW_INDIRECT_COUNT_BIT = 0x80,
    /// `taskShader`.
    UMBRAGE_DEVICE_FEATURE_TASK_SHADER_BIT = 0x100,
    /// `accelerationStructure`.
    UMBRAGE_DEVICE_FEATURE_ACCELERATION_STRUCTURE_BIT = 0x200,
    /// `bufferDeviceAddress`.
    UMBRAGE_DEVICE_FEATURE_BUFFER_DEVICE_ADDRESS_BIT = 0x400,
    /// `dynamicRendering` (Vulkan 1.3).
    UMBRAGE_DEVICE_FEATURE_DYNAMIC_RENDERING_BIT = 0x800,
}

/// A set of [`UmbrageDeviceFeatureFlagBits`].
pub type UmbrageDeviceFeatureFlags = u32;
