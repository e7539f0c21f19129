//! The C ABI's types: result codes, enums with pinned values, and the `#[repr(C)]` structs the
//! header declares. Every struct that a later version may extend starts with `sType` and
//! `pNext`; every option is all-zero by default. Layouts are pinned by `layout.rs` here and by
//! `_Static_assert`s in the header.

use std::ffi::{c_char, c_void};

// Vulkan types as the header spells them (it includes vulkan_core.h; cbindgen does not emit
// these aliases: cbindgen.toml excludes them). Non-dispatchable handles are 64-bit.
/// `VkInstance`.
pub type VkInstance = ash::vk::Instance;
/// `VkPhysicalDevice`.
pub type VkPhysicalDevice = ash::vk::PhysicalDevice;
/// `VkDevice`.
pub type VkDevice = ash::vk::Device;
/// `VkCommandBuffer`.
pub type VkCommandBuffer = ash::vk::CommandBuffer;
/// `VkRenderPass`.
pub type VkRenderPass = ash::vk::RenderPass;
/// `VkImage`.
pub type VkImage = ash::vk::Image;
/// `VkImageView`.
pub type VkImageView = ash::vk::ImageView;
/// `VkPipelineCache`.
pub type VkPipelineCache = ash::vk::PipelineCache;
/// `VkFormat`.
pub type VkFormat = ash::vk::Format;
/// `VkImageLayout`.
pub type VkImageLayout = ash::vk::ImageLayout;
/// `VkExtent2D`.
pub type VkExtent2D = ash::vk::Extent2D;
/// `VkRect2D`.
pub type VkRect2D = ash::vk::Rect2D;
/// `VkStencilOpState`.
pub type VkStencilOpState = ash::vk::StencilOpState;
/// `VkFormatFeatureFlags`.
pub type VkFormatFeatureFlags = ash::vk::FormatFeatureFlags;
/// `VkSampleCountFlags`.
pub type VkSampleCountFlags = ash::vk::SampleCountFlags;
/// `VkPhysicalDeviceLimits`.
pub type VkPhysicalDeviceLimits = ash::vk::PhysicalDeviceLimits;
/// `PFN_vkGetInstanceProcAddr` in the header; read as an address here (NULL: 0) and checked
/// before it becomes a function pointer.
pub type RawGetInstanceProcAddr = usize;
/// `PFN_vkGetDeviceProcAddr` in the header, as [`RawGetInstanceProcAddr`].
pub type RawGetDeviceProcAddr = usize;

// The enums as C passes them: 32-bit values, checked before they become Rust enums (a value
// out of range is an error, never undefined behaviour). The header names each by its enum
// (cbindgen.toml renames them).
/// [`UmbrageStructureType`] as passed from C.
pub type UmbrageStructureTypeRaw = u32;
/// [`UmbrageDepthDirection`] as passed from C.
pub type UmbrageDepthDirectionRaw = u32;
/// [`UmbrageDepthMode`] as passed from C.
pub type UmbrageDepthModeRaw = u32;
/// [`UmbrageTechnique`] as passed from C.
pub type UmbrageTechniqueRaw = u32;
/// [`UmbrageMethod`] as passed from C.
pub type UmbrageMethodRaw = u32;
/// [`UmbrageCounter`] as passed from C.
pub type UmbrageCounterRaw = u32;
/// [`UmbrageIndexFormat`] as passed from C.
pub type UmbrageIndexFormatRaw = u32;
/// [`UmbrageComputeDraws`] as passed from C.
pub type UmbrageComputeDrawsRaw = u32;
/// [`UmbrageLightKind`] as passed from C.
pub type UmbrageLightKindRaw = u32;
/// [`UmbrageIndexType`] as passed from C.
pub type UmbrageIndexTypeRaw = u32;

/// A boolean: 0 is false, anything else true (`uint32_t`, as `VkBool32`).
pub type UmbrageBool = u32;

mod enums;
pub use enums::*;

/// The opaque pass (one `ShadowPass` on the host's device): never defined, never dereferenced
/// (a handle is a number the library looks up).
#[allow(non_camel_case_types)]
pub struct UmbragePass_T {
    _private: (),
}

/// The pass handle. NULL is never a valid pass.
pub type UmbragePass = *mut UmbragePass_T;

/// The warning callback: `message` (UTF-8, NUL-terminated) is valid during the call only.
pub type UmbrageWarningCallback = Option<unsafe extern "C" fn(user_data: *mut c_void, message: *const c_char)>;

/// A caster id: a value. A removed caster's id, or another pass's, is refused with
/// `UMBRAGE_ERROR_UNKNOWN_ID` / `UMBRAGE_ERROR_FOREIGN_ID`; 0 is never an id.
pub type UmbrageCasterId = u64;

/// A sphere caster id (the same rules as [`UmbrageCasterId`]).
pub type UmbrageSphereId = u64;

/// The host's render pass and subpass the determination records in (chain it to
/// [`UmbragePassCreateInfo::pNext`] for the render-pass target model; without it the pass uses
/// dynamic rendering).
#[repr(C)]
#[derive(Clone, Copy, Debug)]
#[allow(non_snake_case)]
pub struct UmbrageRenderPassTarget {
    /// `UMBRAGE_STRUCTURE_TYPE_RENDER_PASS_TARGET`.
    pub sType: UmbrageStructureTypeRaw,
    /// NULL (no extension yet).
    pub pNext: *const c_void,
    /// The host's render pass (it must outlive the pass).
    pub renderPass: VkRenderPass,
    /// The subpass index.
    pub subpass: u32,
    /// The number of colour attachments of that subpass.
    pub colorAttachmentCount: u32,
}

/// The plans kept across frames (chain it to [`UmbragePassCreateInfo::pNext`]; without it the
/// pass keeps every unchanged light–caster pair's plan, within a 64 MiB budget, and plans on
/// every core for scenes above 100,000 triangles). A pair whose light, caster and case did not
/// change is drawn from what the GPU kept, with no planning and 0 bytes sent; the stencil is
/// the same either way.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
#[allow(non_snake_case)]
pub struct UmbrageKeepInfo {
    /// `UMBRAGE_STRUCTURE_TYPE_KEEP_INFO`.
    pub sType: UmbrageStructureTypeRaw,
    /// NULL, or further structs chained to [`UmbragePassCreateInfo`].
    pub pNext: *const c_void,
    /// Bytes of GPU memory the kept plans may hold (the least recently drawn are evicted
    /// beyond it); 0: the default, 64 MiB.
    pub keepBudgetBytes: u64,
    /// Threads that plan a frame's changed pairs; 0: automatic (every core above 100,000
    /// triangles), 1: the calling thread only.
    pub planThreads: u32,
    /// Non-zero: plan every pair from scratch every frame (the budget is then unused). The
    /// settings of `umbrage_pass_set_settings` leave this choice as it was made here.
    pub disableKeep: UmbrageBool,
}

/// How the pass is created (`umbrage_pass_create`). All-zero fields mean the defaults, except
/// `sType` and `abiVersion`, which say what this struct is.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
#[allow(non_snake_case)]
pub struct UmbragePassCreateInfo {
    /// `UMBRAGE_STRUCTURE_TYPE_PASS_CREATE_INFO`.
    pub sType: UmbrageStructureTypeRaw,
    /// NULL, or a chain of [`UmbrageRenderPassTarget`] and [`UmbrageKeepInfo`] (each at most
    /// once).
    pub pNext: *const c_void,
    /// `UMBRAGE_ABI_VERSION` of the header the host compiled against.
    pub abiVersion: u32,
    /// The host's depth-stencil format (0, `VK_FORMAT_UNDEFINED`: `VK_FORMAT_D32_SFLOAT_S8_UINT`).
    pub depthStencilFormat: VkFormat,
    /// Samples per pixel: 1, 2, 4 or 8 (0: 1).
    pub samples: u32,
    /// Ring slots, 1..=64 (0: 2).
    pub framesInFlight: u32,
    /// Forward (default) or reverse-Z.
    pub depthDirection: UmbrageDepthDirectionRaw,
    /// Infinite far plane (default) or clamped.
    pub depthMode: UmbrageDepthModeRaw,
    /// The features the host enabled on its device ([`UmbrageFeatureFlagBits`]).
    pub enabledFeatures: UmbrageFeatureFlags,
    /// The first frame's settings.
    pub settings: UmbragePassSettings,
    /// The light-intensity map's format for transparent casters (0: none, transparent casters
    /// refused).
    pub transmitFormat: VkFormat,
    /// The host's pipeline cache, or `VK_NULL_HANDLE`.
    pub pipelineCache: VkPipelineCache,
    /// Called with each warning of a frame (e.g. a possible 8-bit stencil overflow); NULL:
    /// none.
    pub pfnWarning: UmbrageWarningCallback,
    /// Passed to `pfnWarning`.
    pub pWarningUserData: *mut c_void,
}

/// The host's Vulkan objects and function loaders (`umbrage_pass_create`). Every Vulkan
/// function the pass calls is loaded through these: the library never links or opens the
/// Vulkan loader.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
#[allow(non_snake_case)]
pub struct UmbrageVulkanDevice {
    /// The host's `vkGetInstanceProcAddr` (required).
    pub pfnGetInstanceProcAddr: RawGetInstanceProcAddr,
    /// The host's `vkGetDeviceProcAddr`, or NULL (then loaded through the instance).
    pub pfnGetDeviceProcAddr: RawGetDeviceProcAddr,
    /// The host's instance (Vulkan 1.1 or later).
    pub instance: VkInstance,
    /// The physical device `device` was created on.
    pub physicalDevice: VkPhysicalDevice,
    /// The host's device.
    pub device: VkDevice,
}

/// What may change between frames. All-zero is the default: McGuire's volumes, the stencil
/// counter, automatic index format, every optimisation on.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[allow(non_snake_case)]
pub struct UmbragePassSettings {
    /// The technique.
    pub technique: UmbrageTechniqueRaw,
    /// The case rule of `UMBRAGE_TECHNIQUE_VOLUMES`.
    pub method: UmbrageMethodRaw,
    /// The counter.
    pub counter: UmbrageCounterRaw,
    /// The streams' index format.
    pub indexFormat: UmbrageIndexFormatRaw,
    /// How compute draws are recorded.
    pub computeDraws: UmbrageComputeDrawsRaw,
    /// Non-zero: no per-light scissor (the whole target).
    pub disableScissor: UmbrageBool,
    /// Non-zero: no depth-bounds test.
    pub disableDepthBounds: UmbrageBool,
    /// Non-zero: every caster's volume drawn, none culled.
    pub disableCulling: UmbrageBool,
    /// Non-zero: no task-stage culling for the mesh technique.
    pub disableMeshTask: UmbrageBool,
    /// Non-zero: ray query traces every light's rays in one pass per 32 lights.
    pub rayBatch: UmbrageBool,
}

/// What the pass uses on its device: the host's enabled features intersected with the
/// device's.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[allow(non_snake_case)]
pub struct UmbrageCapabilities {
    /// Ray query.
    pub rayQuery: UmbrageBool,
    /// depthClamp.
    pub depthClamp: UmbrageBool,
    /// depthBounds: the lighting pass should set the light's depth bounds.
    pub depthBounds: UmbrageBool,
    /// indexTypeUint8.
    pub indexTypeUint8: UmbrageBool,
    /// `R32_SFLOAT` blending (the float counter).
    pub r32fBlend: UmbrageBool,
    /// Mesh shaders.
    pub meshShader: UmbrageBool,
    /// drawIndirectFirstInstance.
    pub drawIndirectFirstInstance: UmbrageBool,
    /// multiDrawIndirect.
    pub multiDrawIndirect: UmbrageBool,
    /// drawIndirectCount.
    pub drawIndirectCount: UmbrageBool,
    /// Task shaders.
    pub taskShader: UmbrageBool,
}

/// A format's optimal-tiling features, for [`UmbrageDeviceDescription`].
#[repr(C)]
#[derive(Clone, Copy, Debug)]
#[allow(non_snake_case)]
pub struct UmbrageFormatFeatures {
    /// The format.
    pub format: VkFormat,
    /// Its `optimalTilingFeatures`.
    pub optimalTilingFeatures: VkFormatFeatureFlags,
    /// The sample counts of a 2D optimal-tiling depth-stencil attachment image in this format
    /// (0: not known, the framebuffer limits decide).
    pub sampleCounts: VkSampleCountFlags,
}

/// A device described without the device (from `vkGetPhysicalDevice*` answers or a report of
/// them), for `umbrage_capabilities_for`.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
#[allow(non_snake_case)]
pub struct UmbrageDeviceDescription {
    /// `UMBRAGE_STRUCTURE_TYPE_DEVICE_DESCRIPTION`.
    pub sType: UmbrageStructureTypeRaw,
    /// NULL.
    pub pNext: *const c_void,
    /// `VkPhysicalDeviceProperties::apiVersion`.
    pub apiVersion: u32,
    /// The features it reports ([`UmbrageDeviceFeatureFlagBits`]).
    pub deviceFeatures: UmbrageDeviceFeatureFlags,
    /// `extensionCount` NUL-terminated extension names (may be NULL when the count is 0).
    pub ppExtensionNames: *const *const c_char,
    /// How many.
    pub extensionCount: u32,
    /// `formatCount` formats with their features.
    pub pFormats: *const UmbrageFormatFeatures,
    /// How many.
    pub formatCount: u32,
    /// Its limits (the framebuffer sample counts are read), or NULL (then every count up to 8
    /// is taken as supported).
    pub pLimits: *const VkPhysicalDeviceLimits,
}

/// A caster's mesh (`umbrage_pass_add_caster`): object-space positions and triangles,
/// counter-clockwise seen from outside.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
#[allow(non_snake_case)]
pub struct UmbrageCasterInfo {
    /// `UMBRAGE_STRUCTURE_TYPE_CASTER_INFO`.
    pub sType: UmbrageStructureTypeRaw,
    /// NULL.
    pub pNext: *const c_void,
    /// A name for messages and stats (NUL-terminated UTF-8), or NULL.
    pub pName: *const c_char,
    /// `vertexCount` x 3 floats (x, y, z).
    pub pPositions: *const f32,
    /// How many vertices.
    pub vertexCount: u32,
    /// `indexCount` indices of `indexType`, three a triangle.
    pub pIndices: *const c_void,
    /// How many indices (a multiple of 3).
    pub indexCount: u32,
    /// 32-bit (default) or 16-bit indices.
    pub indexType: UmbrageIndexTypeRaw,
    /// Object -> world, column-major `double[16]`; all zero means the identity.
    pub transform: [f64; 16],
    /// Non-zero: a transparent caster letting `transmittance` through (needs
    /// `UmbragePassCreateInfo::transmitFormat`).
    pub transparent: UmbrageBool,
    /// RGB fraction of light one surface lets through (transparent casters).
    pub transmittance: [f32; 3],
}

/// An analytic sphere caster (`umbrage_pass_add_sphere`).
#[repr(C)]
#[derive(Clone, Copy, Debug)]
#[allow(non_snake_case)]
pub struct UmbrageSphereInfo {
    /// `UMBRAGE_STRUCTURE_TYPE_SPHERE_INFO`.
    pub sType: UmbrageStructureTypeRaw,
    /// NULL.
    pub pNext: *const c_void,
    /// A name, or NULL.
    pub pName: *const c_char,
    /// World-space centre.
    pub center: [f64; 3],
    /// Radius (> 0).
    pub radius: f64,
    /// Segments of its silhouette polygon (0: chosen per frame from its size on screen).
    pub segments: u32,
}

/// A light (`umbrage_pass_prepare`). All-zero: a point light at the origin, unbounded.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
#[allow(non_snake_case)]
pub struct UmbrageLight {
    /// Point, spot or directional.
    pub kind: UmbrageLightKindRaw,
    /// World position (point, spot).
    pub position: [f32; 3],
    /// Direction the light travels (spot, directional; need not be unit).
    pub direction: [f32; 3],
    /// Full cone angle of a spot light, degrees, in (0, 360].
    pub coneDeg: f32,
    /// Attenuation range in world units; 0: unbounded.
    pub radius: f32,
}

/// The camera of a frame (`umbrage_pass_prepare`).
#[repr(C)]
#[derive(Clone, Copy, Debug)]
#[allow(non_snake_case)]
pub struct UmbrageView {
    /// `UMBRAGE_STRUCTURE_TYPE_VIEW`.
    pub sType: UmbrageStructureTypeRaw,
    /// NULL.
    pub pNext: *const c_void,
    /// The eye's world position, in double (the planner works in f64).
    pub eye: [f64; 3],
    /// The camera's world -> view matrix (with its translation), column-major `float[16]`.
    pub view: [f32; 16],
    /// View -> Vulkan clip projection, column-major (forward or reverse-Z as the pass was
    /// created for).
    pub projection: [f32; 16],
    /// The target's size.
    pub width: u32,
    /// The target's size.
    pub height: u32,
    /// Non-zero: every caster culled (only the lights' scissors and depth bounds).
    pub culled: UmbrageBool,
}

/// A prepared frame: a value. Calls with a frame whose slot was prepared again return
/// `UMBRAGE_ERROR_STALE_FRAME`; another pass's, `UMBRAGE_ERROR_FOREIGN_FRAME`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct UmbrageFrame {
    /// The pass that prepared it.
    pub pass: u64,
    /// Frames the pass prepared before it.
    pub serial: u64,
    /// Its ring slot.
    pub slot: u32,
    /// How many lights it was prepared with.
    pub lights: u32,
}

/// The host's depth-stencil image as the determination uses it.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
#[allow(non_snake_case)]
pub struct UmbrageDepthStencilTarget {
    /// `UMBRAGE_STRUCTURE_TYPE_DEPTH_STENCIL_TARGET`.
    pub sType: UmbrageStructureTypeRaw,
    /// NULL.
    pub pNext: *const c_void,
    /// The image.
    pub image: VkImage,
    /// A view of both aspects.
    pub view: VkImageView,
    /// Its size (equal to the frame's view size).
    pub extent: VkExtent2D,
    /// Its layout when the call is recorded (0, `VK_IMAGE_LAYOUT_UNDEFINED`:
    /// `VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL`).
    pub layout: VkImageLayout,
    /// The layout to leave it in (0: as `layout`).
    pub finalLayout: VkImageLayout,
}

/// What the host's lighting pass needs for one light of a frame.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
#[allow(non_snake_case)]
pub struct UmbrageLightInfo {
    /// `UMBRAGE_STRUCTURE_TYPE_LIGHT_INFO`.
    pub sType: UmbrageStructureTypeRaw,
    /// NULL.
    pub pNext: *mut c_void,
    /// The light's scissor.
    pub scissor: VkRect2D,
    /// Non-zero when the light has depth bounds.
    pub hasDepthBounds: UmbrageBool,
    /// Its depth bounds (0, 1 when it has none).
    pub minDepthBounds: f32,
    /// Its depth bounds.
    pub maxDepthBounds: f32,
    /// Casters planned (drawn or culled) for the light.
    pub casterCount: u32,
    /// Shadow triangles drawn for the light.
    pub triangles: u64,
}

/// A frame's statistics.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
#[allow(non_snake_case)]
pub struct UmbrageFrameStats {
    /// `UMBRAGE_STRUCTURE_TYPE_FRAME_STATS`.
    pub sType: UmbrageStructureTypeRaw,
    /// NULL, or a chain of output structs the call fills ([`UmbrageKeepStats`]).
    pub pNext: *mut c_void,
    /// Side triangles.
    pub sideTriangles: u64,
    /// Dark-cap triangles.
    pub darkCapTriangles: u64,
    /// Light-cap triangles.
    pub lightCapTriangles: u64,
    /// Bytes of indices written.
    pub indexBytes: u64,
    /// Bytes of streamed vertices.
    pub vertexBytes: u64,
    /// Bytes sent to the GPU this frame (streams and uploads).
    pub bytesSent: u64,
    /// Draw calls.
    pub draws: u64,
    /// Casters culled, over all lights.
    pub casesCulled: u64,
    /// Casters drawn z-pass.
    pub casesZPass: u64,
    /// Casters drawn z-fail.
    pub casesZFail: u64,
    /// Casters drawn z-fail with a light cap.
    pub casesZFailLightCap: u64,
    /// CPU milliseconds: possible silhouettes.
    pub cpuSilhouettesMs: f64,
    /// CPU milliseconds: planning.
    pub cpuPlanMs: f64,
    /// CPU milliseconds: writing the streams.
    pub cpuRecordMs: f64,
    /// Warnings of the frame (also sent to the warning callback).
    pub warningCount: u32,
    /// Caster uploads this frame records.
    pub pendingUploads: u32,
}

/// What the frame's plans kept and replanned (chain it to [`UmbrageFrameStats::pNext`];
/// `umbrage_frame_get_stats` fills it).
#[repr(C)]
#[derive(Clone, Copy, Debug)]
#[allow(non_snake_case)]
pub struct UmbrageKeepStats {
    /// `UMBRAGE_STRUCTURE_TYPE_KEEP_STATS`.
    pub sType: UmbrageStructureTypeRaw,
    /// NULL, or further structs chained to [`UmbrageFrameStats`].
    pub pNext: *mut c_void,
    /// Light–caster pairs drawn (not culled), over all lights.
    pub pairsTotal: u64,
    /// Of those, drawn from plans kept from an earlier frame (nothing planned or sent).
    pub pairsKept: u64,
    /// Of those, planned this frame.
    pub pairsReplanned: u64,
    /// Bytes the kept plans hold on the GPU after this frame.
    pub keptBytes: u64,
    /// Kept plans evicted this frame to stay within the budget.
    pub keptEvictions: u64,
}

/// The ray-query technique's G-buffer inputs.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
#[allow(non_snake_case)]
pub struct UmbrageRayQueryInputs {
    /// `UMBRAGE_STRUCTURE_TYPE_RAY_QUERY_INPUTS`.
    pub sType: UmbrageStructureTypeRaw,
    /// NULL.
    pub pNext: *const c_void,
    /// Float RGBA: world position relative to the eye in xyz, w != 0 where there is a surface.
    pub position: VkImageView,
    /// Float RGBA: unit world normal in xyz.
    pub normal: VkImageView,
    /// World units the ray starts off the surface.
    pub surfaceOffset: f32,
}
