//! A host renderer of its own that embeds [`umbrage::pass::ShadowPass`] the way an engine
//! would: its own `ash::Entry`, instance (validation layer with synchronisation validation and
//! a debug-utils messenger when `UMBRAGE_VALIDATION` is set), physical device, logical device,
//! one queue, a gpu-allocator shared with the pass, its own WGSL shaders, a depth-stencil
//! image, two frames in flight and its own lighting pass. It uses umbrage's public API only,
//! never `umbrage_render::Renderer` or `umbrage::gpu::Context`.
//!
//! [`Config`] picks what engines differ on:
//! - `samples` (1, 2, 4, 8): every target and pipeline at that count; each sample is read back
//!   and checked on its own;
//! - `reverse_z`: the host's projection maps the near plane to depth 1 and infinity to 0
//!   (depth GREATER, cleared to 0); the pass is created with `DepthDirection::Reverse`;
//! - `render_pass`: a Vulkan 1.1 host with classic `VkRenderPass`es and no dynamic rendering;
//!   the pass is created for the lighting render pass's subpass and `cmd_determine` records
//!   inside it. Otherwise a Vulkan 1.3 host with dynamic rendering, and the pass transitions
//!   the depth-stencil image from and to the layouts the host declares.
//!
//! Per frame (ring slot = frame % 2, its fence waited before `prepare`):
//! 1. `ShadowPass::prepare` plans every light's volumes on the CPU;
//! 2. `cmd_before_rendering` records the pass's uploads;
//! 3. the pre-pass draws every mesh (depth and the face normal of each sample);
//! 4. per light: `cmd_determine` leaves the count in the stencil; the lighting pass draws each
//!    mesh's light-facing triangles with depth EQUAL and stencil EQUAL 0 into an R8 target;
//!    a compute shader reads every sample's stencil and lit bit (and, for light 0, its depth
//!    and normal) into the slot's readback buffer;
//! 5. when the slot comes round again, each sample becomes a frame dump (positions
//!    unprojected from the sample's depth at its standard location) checked against the CPU
//!    reference exactly as `umbrage check` checks `umbrage render --dump`.
//!
//! This file holds the configuration, the scene, instance and device; `setup.rs` the rest of
//! the setup and the teardown; `frame.rs` records, submits and reads back a frame;
//! `extract.rs` is the per-sample readback; `shaders.rs` the WGSL; `vulkan.rs` the Vulkan
//! plumbing and `pipelines.rs` its pipelines and render passes. `examples/embed/main.rs` is the
//! command line; `tests/engine/embed.rs` includes this file and runs every configuration.
#![allow(dead_code)]

use ash::vk;
use glam::Vec3;
use gpu_allocator::vulkan::{Allocator, AllocatorCreateDesc};
use pipelines::{create_render_pass, RenderPassDesc};
use std::ffi::c_void;
use std::sync::{Arc, Mutex};
use umbrage::pass::stats::{CpuMs, LightStats, Totals};
use umbrage::pass::{CasterId, DepthDirection, EnabledFeatures, RenderPassTarget, ShadowPass, ShadowPassDesc, TargetModel};
use umbrage_reference::Dump;
use umbrage_scene::Scene;
use vulkan::{
    color_samples_supported, create_device, create_image, create_view, debug_callback, pick_device, validation_requested, vkerr, Buf, Img,
    Picked,
};

/// The default frame size.
pub const WIDTH: u32 = 320;
/// The default frame height.
pub const HEIGHT: u32 = 200;
/// Ring slots: two frames in flight.
pub const FRAMES_IN_FLIGHT: usize = 2;
/// The band (pixels around shadow edges and geometric discontinuities) where mismatches with
/// the reference are not counted.
pub const BAND: u32 = 1;
/// The lighting pass's target (1 = lit).
const LIT_FORMAT: vk::Format = vk::Format::R8_UNORM;
/// The pre-pass's normal target.
const NORMAL_FORMAT: vk::Format = vk::Format::R32G32B32A32_SFLOAT;
/// Index of the moving caster (the box) in [`scene`]'s meshes.
pub const MOVING_MESH: usize = 2;

/// What the host is: the configurations engines differ on, and what it draws.
#[derive(Clone, Debug)]
pub struct Config {
    /// Samples per pixel: 1, 2, 4 or 8.
    pub samples: u32,
    /// Reverse-Z (near plane at depth 1, infinity at 0) instead of forward.
    pub reverse_z: bool,
    /// A Vulkan 1.1 host with classic render passes instead of dynamic rendering.
    pub render_pass: bool,
    /// Frame size.
    pub width: u32,
    /// Frame height.
    pub height: u32,
    /// `None`: the embedded scene ([`scene`], the box turning and sliding); otherwise a scene
    /// (`umbrage_scene::load`'s file or built-in name) whose last shadow-casting mesh slides
    /// 0.25 a frame along +x (frame 0 is the scene as loaded).
    pub scene: Option<String>,
    /// Frames the host skips after `prepare`, and how (what a host does when its swapchain
    /// goes out of date): they produce no [`FrameResult`], and the pass must lose nothing.
    pub skip: Vec<(usize, Skip)>,
    /// The Khronos validation layer on (errors fail the run): `None` follows
    /// `UMBRAGE_VALIDATION` (`1` or `true`), as the command line does; the tests say `Some(true)`.
    pub validation: Option<bool>,
}

/// How a host gives up a prepared frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Skip {
    /// The frame is dropped without recording anything.
    Unrecorded,
    /// The frame is recorded, then the command buffer is reset instead of submitted, and the
    /// pass is told (`ShadowPass::abandon_frame`).
    RecordedNotSubmitted,
}

impl Default for Config {
    fn default() -> Config {
        Config {
            samples: 1,
            reverse_z: false,
            render_pass: false,
            width: WIDTH,
            height: HEIGHT,
            scene: None,
            skip: Vec::new(),
            validation: None,
        }
    }
}

impl Config {
    /// A short name: `4x reverse-Z render-pass`.
    pub fn name(&self) -> String {
        format!(
            "{}x {} {}",
            self.samples,
            if self.reverse_z { "reverse-Z" } else { "forward" },
            if self.render_pass { "render-pass" } else { "dynamic-rendering" }
        )
    }
}

/// One sample of one frame: its dump (what `--dump` writes and `umbrage check` reads) and per
/// light its stencil.
#[derive(Clone, Debug)]
pub struct SampleFrame {
    /// The sample's frame dump: positions and normals at the sample's location, masks from
    /// the host's lighting pass (255 lit, 0 not, 128 background).
    pub dump: Dump,
    /// Per light, the stencil count after its determination.
    pub stencil: Vec<Vec<u8>>,
}

/// One light of a checked frame, summed over its samples.
#[derive(Clone, Debug)]
pub struct LightResult {
    /// Sample 0's stencil after the light's determination, one byte a pixel, row-major.
    pub stencil: Vec<u8>,
    /// Sample 0's mask: 128 background, 255 lit, 0 shadowed or facing away.
    pub mask: Vec<u8>,
    /// Per sample: mismatches with the reference outside the [`BAND`].
    pub mismatches: Vec<u64>,
    /// Per sample: pixels compared with the reference.
    pub compared: Vec<u64>,
    /// Per sample: pixels with a non-zero count.
    pub shadowed: Vec<u64>,
}

impl LightResult {
    /// Mismatches outside the band, over all samples.
    pub fn mismatches_outside_band(&self) -> u64 {
        self.mismatches.iter().sum()
    }

    /// Mismatches outside the band beyond `allowed` a sample, over all samples.
    pub fn mismatches_beyond(&self, allowed: u64) -> u64 {
        self.mismatches.iter().map(|&m| m.saturating_sub(allowed)).sum()
    }
}

/// SwiftShader stores multisampled depth at its sample locations mirrored in x
/// (docs/conform/drivers-notes.md §1f, a driver defect): with several samples, a sample's
/// stencil counts the volume faces covering its location whose depth, at the mirrored
/// location, is in front, so near volume edges a few samples disagree with the reference
/// outside the band whatever location the host unprojects at. At most this many a light and
/// sample are allowed there (twice the most measured: 3 of ~43,600, chromium-common
/// 156.0.8078.129, every configuration of the embedded scene; `scripts/capi-test.sh` holds the
/// C host to twice its own most measured); 1 sample, and every other device, must stay exact.
pub const SWIFTSHADER_MSAA_MISMATCHES: u64 = 6;

/// The mismatches outside the band allowed a light and sample on `device` at `samples`
/// samples: [`SWIFTSHADER_MSAA_MISMATCHES`] on SwiftShader at more than one sample, else 0.
pub fn allowed_mismatches(device: &str, samples: u32) -> u64 {
    if device.contains("SwiftShader") && samples > 1 {
        SWIFTSHADER_MSAA_MISMATCHES
    } else {
        0
    }
}

/// One frame, read back and compared with the CPU reference of that frame's scene.
#[derive(Clone, Debug)]
pub struct FrameResult {
    /// The frame's number (0-based).
    pub frame: usize,
    /// The ring slot it used.
    pub slot: usize,
    /// The physical device it ran on.
    pub device: String,
    /// The shadow pass's per-light statistics (cases, silhouettes, triangles, bytes).
    pub stats: Vec<LightStats>,
    /// The shadow pass's totals over all lights.
    pub totals: Totals,
    /// The shadow pass's CPU time for the frame.
    pub cpu_ms: CpuMs,
    /// The pass's warnings (e.g. a possible 8-bit overflow).
    pub warnings: Vec<String>,
    /// Per light, the readback and its comparison.
    pub lights: Vec<LightResult>,
    /// Per sample, its dump and stencils (kept for the last frames only: see [`run`]).
    pub samples: Vec<SampleFrame>,
    /// The frame's scene (the moving caster where the frame put it).
    pub scene: Scene,
    /// Milliseconds from the start of recording to the fence (queue and GPU time, with the
    /// other slot's frame in flight).
    pub gpu_wall_ms: f64,
    /// Per light, the GPU time of its `cmd_determine` (timestamps around it), ms; empty when
    /// the queue has no timestamps.
    pub determine_ms: Vec<f64>,
    /// The GPU time of the whole command buffer (timestamps at its start and end), ms; NaN
    /// when the queue has no timestamps.
    pub frame_gpu_ms: f64,
}

/// Renders `frames` frames with `config`, two in flight, and checks every sample of each
/// against the reference. The last two frames keep their [`SampleFrame`]s. Errors: no usable
/// Vulkan device, an unsupported configuration, a failed call, or any validation error (when
/// `UMBRAGE_VALIDATION` is set), including those reported at teardown.
pub fn run(config: &Config, frames: usize) -> Result<Vec<FrameResult>, String> {
    let mut results = Vec::with_capacity(frames);
    let log;
    {
        let mut host = Host::new(config)?;
        log = host.log.clone();
        for f in 0..frames {
            host.frame(f, &mut results)?;
        }
        // The frames still in flight, oldest first.
        for f in frames.saturating_sub(FRAMES_IN_FLIGHT)..frames {
            host.retire(f % FRAMES_IN_FLIGHT, &mut results)?;
        }
        // `host` drops here: the whole teardown, in order (see `Drop for Host`).
    }
    let errors = log.lock().map(|l| l.clone()).unwrap_or_default();
    if let Some(first) = errors.first() {
        return Err(format!("{} validation error(s) or warning(s) (teardown included), first: {first}", errors.len()));
    }
    let keep_from = results.len().saturating_sub(FRAMES_IN_FLIGHT);
    for r in &mut results[..keep_from] {
        r.samples.clear();
    }
    Ok(results)
}

#[path = "extract.rs"]
mod extract;
#[path = "frame.rs"]
mod frame;
#[path = "pipelines.rs"]
mod pipelines;
#[path = "scenes.rs"]
mod scenes;
#[path = "setup.rs"]
mod setup;
use scenes::Scenes;
#[allow(unused_imports)] // used by tests/engine/embed.rs
pub use scenes::{box_transform, scene};
#[path = "shaders.rs"]
mod shaders;
#[path = "vulkan.rs"]
mod vulkan;

/// A scene mesh as the host draws it: positions (w = 1), all triangles for the pre-pass.
struct MeshGpu {
    vertices: Buf,
    indices: Buf,
    index_count: u32,
    positions: Vec<Vec3>,
    triangles: Vec<[u32; 3]>,
    caster: Option<CasterId>,
}

/// What a ring slot remembers of the frame in flight in it.
struct InFlight {
    frame: usize,
    scene: Scene,
    view_proj: glam::DMat4,
    stats: Vec<LightStats>,
    totals: Totals,
    cpu_ms: CpuMs,
    warnings: Vec<String>,
    started: std::time::Instant,
}

/// A ring slot: command buffer, fence, readback and the lighting pass's index list.
struct Slot {
    cmd: vk::CommandBuffer,
    fence: vk::Fence,
    readback: Buf,
    lit: Buf,
    in_flight: Option<InFlight>,
}

/// Readback layout, in 4-byte words: per sample its geometry ([`GEOMETRY_WORDS`] a pixel:
/// depth, normal, plane offset),
/// then per light and sample its packed stencil and lit bit (1 word a pixel).
struct Layout {
    pixels: u32,
    samples: u32,
}

/// Words of one pixel's geometry in the readback.
const GEOMETRY_WORDS: u32 = 5;

impl Layout {
    fn geometry(&self, sample: u32) -> u32 {
        GEOMETRY_WORDS * self.pixels * sample
    }
    fn packed(&self, light: usize, sample: u32) -> u32 {
        GEOMETRY_WORDS * self.pixels * self.samples + self.pixels * (light as u32 * self.samples + sample)
    }
    fn bytes(&self, lights: usize) -> u64 {
        4 * self.packed(lights, 0) as u64
    }
}

/// The classic render passes (render-pass model) and their framebuffers.
#[derive(Default)]
struct RenderPasses {
    prepass: vk::RenderPass,
    lighting: vk::RenderPass,
    prepass_fb: vk::Framebuffer,
    lighting_fb: vk::Framebuffer,
}

/// Everything the host owns. Fields are filled in order by [`Host::new`]; `Drop` destroys what
/// exists, so a failure half-way cleans up too.
struct Host {
    config: Config,
    scenes: Scenes,
    _entry: ash::Entry,
    instance: ash::Instance,
    debug: Option<(ash::ext::debug_utils::Instance, vk::DebugUtilsMessengerEXT)>,
    log: Arc<Mutex<Vec<String>>>,
    physical: vk::PhysicalDevice,
    device_name: String,
    device: Option<ash::Device>,
    queue: vk::Queue,
    ds_format: vk::Format,
    features: EnabledFeatures,
    allocator: Option<Arc<Mutex<Allocator>>>,
    pass: Option<ShadowPass>,
    depth: Option<Img>,
    /// Views of the depth-stencil image's depth and stencil aspects (the readback's).
    depth_view: vk::ImageView,
    stencil_view: vk::ImageView,
    lit_target: Option<Img>,
    normal_target: Option<Img>,
    meshes: Vec<MeshGpu>,
    slots: Vec<Slot>,
    pool: vk::CommandPool,
    layout: vk::PipelineLayout,
    prepass: vk::Pipeline,
    lighting: vk::Pipeline,
    passes: RenderPasses,
    extract: extract::Extract,
    /// Per ring slot, two timestamps per light around `cmd_determine` and two around the
    /// whole command buffer (null: no timestamps).
    queries: vk::QueryPool,
    timestamp_period: f32,
    depth_bounds: bool,
    extent: vk::Extent2D,
}

impl Host {
    fn new(config: &Config) -> Result<Host, String> {
        if ![1, 2, 4, 8].contains(&config.samples) {
            return Err(format!("--msaa {}: the sample count is 1, 2, 4 or 8", config.samples));
        }
        let scenes = Scenes::new(config.scene.as_deref())?;
        let dynamic = !config.render_pass;
        let (entry, instance, validation) = create_instance(config, dynamic)?;
        let log = Arc::new(Mutex::new(Vec::new()));
        let mut host = Host {
            config: config.clone(),
            scenes,
            _entry: entry,
            instance,
            debug: None,
            log,
            physical: vk::PhysicalDevice::null(),
            device_name: String::new(),
            device: None,
            queue: vk::Queue::null(),
            ds_format: vk::Format::UNDEFINED,
            features: EnabledFeatures::default(),
            allocator: None,
            pass: None,
            depth: None,
            depth_view: vk::ImageView::null(),
            stencil_view: vk::ImageView::null(),
            lit_target: None,
            normal_target: None,
            meshes: Vec::new(),
            slots: Vec::new(),
            pool: vk::CommandPool::null(),
            layout: vk::PipelineLayout::null(),
            prepass: vk::Pipeline::null(),
            lighting: vk::Pipeline::null(),
            passes: RenderPasses::default(),
            extract: extract::Extract::default(),
            queries: vk::QueryPool::null(),
            timestamp_period: 0.0,
            depth_bounds: false,
            extent: vk::Extent2D { width: config.width, height: config.height },
        };
        if validation {
            host.create_messenger()?;
        }
        let picked = pick_device(&host.instance, dynamic)?;
        if config.samples > 1 && !picked.standard_sample_locations {
            return Err(format!("{}: no standard sample locations, so the samples cannot be checked", picked.name));
        }
        for format in [LIT_FORMAT, NORMAL_FORMAT] {
            if !color_samples_supported(&host.instance, picked.physical, format, config.samples) {
                return Err(format!("{}: {format:?} has no {}-sample sampled colour attachments", picked.name, config.samples));
            }
        }
        let (device, allocator) = host.open_device(&picked, dynamic)?;

        host.create_pass(config, &device, &allocator)?;

        host.create_targets(config, &device, &allocator)?;

        // SAFETY: object creation on a valid device; destroyed in `Drop for Host`.
        host.pool = unsafe {
            device.create_command_pool(
                &vk::CommandPoolCreateInfo::default()
                    .queue_family_index(picked.queue_family)
                    .flags(vk::CommandPoolCreateFlags::RESET_COMMAND_BUFFER),
                None,
            )
        }
        .map_err(vkerr("vkCreateCommandPool"))?;
        let range = [vk::PushConstantRange { stage_flags: vk::ShaderStageFlags::VERTEX, offset: 0, size: 128 }];
        // SAFETY: as above.
        host.layout = unsafe { device.create_pipeline_layout(&vk::PipelineLayoutCreateInfo::default().push_constant_ranges(&range), None) }
            .map_err(vkerr("vkCreatePipelineLayout"))?;
        host.create_pipelines(&device)?;
        host.upload_meshes(&device, &allocator)?;
        host.create_slots(&device, &allocator)?;
        let views = extract::Views {
            depth: host.depth_view,
            stencil: host.stencil_view,
            lit: host.lit_target.as_ref().map(|i| i.view).ok_or("no lit target")?,
            normal: host.normal_target.as_ref().map(|i| i.view).ok_or("no normal target")?,
        };
        if let Some(period) = picked.timestamp_period {
            let count = (FRAMES_IN_FLIGHT * (host.scenes.base.lights.len() + 1) * 2) as u32;
            let info = vk::QueryPoolCreateInfo::default().query_type(vk::QueryType::TIMESTAMP).query_count(count.max(1));
            // SAFETY: object creation on a valid device; destroyed in `Drop for Host`.
            host.queries = unsafe { device.create_query_pool(&info, None) }.map_err(vkerr("vkCreateQueryPool"))?;
            host.timestamp_period = period;
        }
        let buffers: Vec<vk::Buffer> = host.slots.iter().map(|s| s.readback.raw).collect();
        let mut extract = extract::Extract::default();
        let created = extract.create(&device, config.samples, &views, &buffers);
        host.extract = extract;
        created?;
        Ok(host)
    }

    /// The validation messenger: messages go to `self.log`, destroyed in `Drop for Host`.
    fn create_messenger(&mut self) -> Result<(), String> {
        let du = ash::ext::debug_utils::Instance::new(&self._entry, &self.instance);
        let info = vk::DebugUtilsMessengerCreateInfoEXT::default()
            .message_severity(vk::DebugUtilsMessageSeverityFlagsEXT::ERROR | vk::DebugUtilsMessageSeverityFlagsEXT::WARNING)
            .message_type(vk::DebugUtilsMessageTypeFlagsEXT::GENERAL | vk::DebugUtilsMessageTypeFlagsEXT::VALIDATION)
            .pfn_user_callback(Some(debug_callback))
            .user_data(Arc::as_ptr(&self.log) as *mut c_void);
        // SAFETY: the callback is a plain function and the log (user data) outlives the
        // messenger: `Drop for Host` destroys the messenger before the fields drop.
        let m = unsafe { du.create_debug_utils_messenger(&info, None) }.map_err(vkerr("vkCreateDebugUtilsMessengerEXT"))?;
        self.debug = Some((du, m));
        Ok(())
    }

    /// The picked device opened: its features recorded in `self.features`, the device, its
    /// queue and the allocator shared with the pass.
    fn open_device(&mut self, picked: &Picked, dynamic: bool) -> Result<(ash::Device, Arc<Mutex<Allocator>>), String> {
        self.physical = picked.physical;
        self.device_name = picked.name.clone();
        self.ds_format = picked.ds_format;
        self.features = EnabledFeatures {
            depth_clamp: picked.depth_clamp,
            depth_bounds: picked.depth_bounds,
            index_type_uint8: picked.index_type_uint8,
            // This host's G-buffer is depth only: no positions and normals for rays.
            ray_query: false,
            mesh_shader: false,
            // A host that enables none of the indirect-draw features: the compute path's
            // volumes are drawn one chunk at a time with push constants.
            draw_indirect_first_instance: false,
            multi_draw_indirect: false,
            draw_indirect_count: false,
            task_shader: false,
        };
        let device = create_device(&self.instance, picked, dynamic)?;
        self.device = Some(device.clone());
        // SAFETY: queue 0 of this family was requested at device creation.
        self.queue = unsafe { device.get_device_queue(picked.queue_family, 0) };
        let allocator = Allocator::new(&AllocatorCreateDesc {
            instance: self.instance.clone(),
            device: device.clone(),
            physical_device: self.physical,
            debug_settings: Default::default(),
            buffer_device_address: false,
            allocation_sizes: Default::default(),
        })
        .map_err(|e| format!("gpu-allocator: {e}"))?;
        let allocator = Arc::new(Mutex::new(allocator));
        self.allocator = Some(allocator.clone());
        Ok((device, allocator))
    }

    /// The render passes (with `--render-pass`) and the shadow pass, built against the lighting one.
    fn create_pass(&mut self, config: &Config, device: &ash::Device, allocator: &Arc<Mutex<Allocator>>) -> Result<(), String> {
        // The render passes first (the pass's pipelines are built against the lighting one).
        let mut target = TargetModel::DynamicRendering;
        if config.render_pass {
            let pre = RenderPassDesc::new(NORMAL_FORMAT, self.ds_format, config.samples, true, false);
            self.passes.prepass = create_render_pass(device, &pre, |_, _| Ok(()))?.0;
            let light = RenderPassDesc::new(LIT_FORMAT, self.ds_format, config.samples, false, true);
            let (rp, t) = create_render_pass(device, &light, |rp, info| {
                // SAFETY: `info` is the create info `rp` was just created from, its pointers alive.
                unsafe { RenderPassTarget::new(rp, info, 0) }.map_err(|e| format!("RenderPassTarget::new: {e}"))
            })?;
            self.passes.lighting = rp;
            target = TargetModel::RenderPass(t);
        }
        let desc = ShadowPassDesc {
            depth_stencil_format: self.ds_format,
            frames_in_flight: FRAMES_IN_FLIGHT,
            features: self.features,
            samples: config.samples,
            depth_direction: if config.reverse_z { DepthDirection::Reverse } else { DepthDirection::Forward },
            target,
            ..Default::default()
        };
        let pass = ShadowPass::new(&self.instance, self.physical, device, allocator.clone(), &desc)
            .map_err(|e| format!("ShadowPass::new: {e}"))?;
        self.depth_bounds = self.features.depth_bounds && pass.capabilities().depth_bounds;
        self.pass = Some(pass);
        Ok(())
    }

    /// The depth-stencil image (and its depth and stencil views), the lit and normal targets,
    /// and with `--render-pass` the framebuffers.
    fn create_targets(&mut self, config: &Config, device: &ash::Device, allocator: &Arc<Mutex<Allocator>>) -> Result<(), String> {
        let extent = self.extent;
        let sampled = vk::ImageUsageFlags::SAMPLED;
        let ds_aspects = vk::ImageAspectFlags::DEPTH | vk::ImageAspectFlags::STENCIL;
        self.depth = Some(create_image(
            device,
            allocator,
            "depth-stencil",
            self.ds_format,
            extent,
            config.samples,
            vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT | sampled,
            ds_aspects,
        )?);
        let ds_raw = self.depth.as_ref().map(|d| d.raw).ok_or("no depth image")?;
        self.depth_view = create_view(device, ds_raw, self.ds_format, vk::ImageAspectFlags::DEPTH)?;
        self.stencil_view = create_view(device, ds_raw, self.ds_format, vk::ImageAspectFlags::STENCIL)?;
        let color = vk::ImageUsageFlags::COLOR_ATTACHMENT | sampled;
        let aspect = vk::ImageAspectFlags::COLOR;
        self.lit_target = Some(create_image(device, allocator, "lit", LIT_FORMAT, extent, config.samples, color, aspect)?);
        self.normal_target = Some(create_image(device, allocator, "normal", NORMAL_FORMAT, extent, config.samples, color, aspect)?);
        if config.render_pass {
            self.create_framebuffers(device)?;
        }
        Ok(())
    }

    fn dev(&self) -> &ash::Device {
        self.device.as_ref().expect("the device exists once Host::new returned")
    }

    fn pass(&mut self) -> &mut ShadowPass {
        self.pass.as_mut().expect("the pass exists once Host::new returned")
    }
}

/// The Vulkan loader and an instance (Vulkan 1.3 with dynamic rendering, 1.1 with render
/// passes), with the validation layer and synchronisation validation when asked for; also
/// whether validation is on.
fn create_instance(config: &Config, dynamic: bool) -> Result<(ash::Entry, ash::Instance, bool), String> {
    // SAFETY: loads the Vulkan loader; `entry` is kept in the host as long as the instance.
    let entry = unsafe { ash::Entry::load() }.map_err(|e| format!("no Vulkan loader (libvulkan.so.1): {e}"))?;
    let validation = config.validation.unwrap_or_else(validation_requested);
    let layer = c"VK_LAYER_KHRONOS_validation";
    let (mut layers, mut extensions) = (Vec::new(), Vec::new());
    if validation {
        // SAFETY: a plain enumeration on a loaded entry.
        let available = unsafe { entry.enumerate_instance_layer_properties() }.map_err(vkerr("vkEnumerateInstanceLayerProperties"))?;
        if !available.iter().any(|l| l.layer_name_as_c_str().map(|n| n == layer).unwrap_or(false)) {
            return Err("UMBRAGE_VALIDATION is set but VK_LAYER_KHRONOS_validation is not installed".into());
        }
        layers.push(layer.as_ptr());
        extensions.push(ash::ext::debug_utils::NAME.as_ptr());
    }
    let api = if dynamic { vk::API_VERSION_1_3 } else { vk::API_VERSION_1_1 };
    let app = vk::ApplicationInfo::default().application_name(c"umbrage-embed").api_version(api);
    // Synchronisation validation too: the host's barriers around the pass are checked.
    let sync = [vk::ValidationFeatureEnableEXT::SYNCHRONIZATION_VALIDATION];
    let mut features = vk::ValidationFeaturesEXT::default().enabled_validation_features(&sync);
    let mut info =
        vk::InstanceCreateInfo::default().application_info(&app).enabled_layer_names(&layers).enabled_extension_names(&extensions);
    if !layers.is_empty() {
        info = info.push_next(&mut features);
    }
    // SAFETY: every pointer in `info` refers to locals alive for the call.
    let instance =
        unsafe { entry.create_instance(&info, None) }.map_err(|e| format!("vkCreateInstance failed ({e:?}): no Vulkan driver?"))?;
    Ok((entry, instance, validation))
}
