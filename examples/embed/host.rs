//! A host renderer of its own that embeds [`umbrage::pass::ShadowPass`] the way an engine
//! would: its own `ash::Entry`, instance (validation layer and a debug-utils messenger when
//! `UMBRAGE_VALIDATION` is set), physical device, logical device (Vulkan 1.3 with
//! dynamicRendering and synchronization2; depthClamp, depthBounds and
//! `VK_EXT_index_type_uint8` when present), one graphics queue, a gpu-allocator shared with the
//! pass, a depth-stencil image, a command pool, two frames in flight and its own lighting pass.
//! It uses umbrage's public API only, and never `umbrage::render::Renderer` or
//! `umbrage::gpu::Context`.
//!
//! Per frame (ring slot = frame % 2, its fence waited before `prepare`):
//! 1. `ShadowPass::prepare` plans every light's volumes on the CPU;
//! 2. the host's depth pre-pass draws every mesh (depth LESS, stencil cleared to 0);
//! 3. per light: `cmd_determine` leaves the count in the stencil, the host copies the stencil
//!    out, then its lighting pass draws each mesh's light-facing triangles with depth EQUAL and
//!    stencil EQUAL 0 into an R8 target (1 = lit), copied out too;
//! 4. the depth is copied out once (background = depth 1.0), the frame is submitted with the
//!    slot's fence; when the slot comes round again its readback becomes per light the masks
//!    (128 background, 255 lit, 0 shadowed), compared with the exact CPU reference.
//!
//! This file holds the scene, the host's setup and its teardown; `frame.rs` records, submits
//! and reads back a frame; `vulkan.rs` is the Vulkan plumbing (device choice, allocations,
//! pipelines, barriers). `examples/embed/main.rs` prints the result; `tests/embed.rs` includes
//! this file and checks it against the reference and umbrage's own renderer.
#![allow(dead_code)]

use ash::vk;
use glam::{Mat4, Quat, Vec2, Vec3};
use gpu_allocator::vulkan::{Allocator, AllocatorCreateDesc};
use gpu_allocator::MemoryLocation;
use std::ffi::c_void;
use std::sync::{Arc, Mutex};
use umbrage::geom::{Camera, Light, LightKind};
use umbrage::gpu::shaders::{SHADOW_VERT, VOLUME_FRAG};
use umbrage::pass::push::VolumePush;
use umbrage::pass::stats::{CpuMs, LightStats, Totals};
use umbrage::pass::{lit_stencil_state, CasterId, EnabledFeatures, ShadowPass, ShadowPassDesc};
use umbrage::scene::{shapes, Scene, SceneMesh};
use vulkan::{
    create_buffer, create_device, create_image, create_pipeline, debug_callback, free_buffer, lock, pick_device, shader_module, upload,
    validation_requested, vkerr, Buf, Img, PipelineState,
};

/// The frame's size.
pub const WIDTH: u32 = 320;
/// The frame's height.
pub const HEIGHT: u32 = 200;
/// Ring slots: two frames in flight.
pub const FRAMES_IN_FLIGHT: usize = 2;
/// The band (pixels around shadow edges and geometric discontinuities) where mismatches with
/// the reference are not counted.
pub const BAND: u32 = 1;
/// The colour target of the lighting pass (1 = lit).
const LIT_FORMAT: vk::Format = vk::Format::R8_UNORM;
/// Index of the moving caster (the box) in [`scene`]'s meshes.
pub const MOVING_MESH: usize = 2;

/// One light of a checked frame.
#[derive(Clone, Debug)]
pub struct LightResult {
    /// The stencil after the light's determination, one byte a pixel, row-major from the top.
    pub stencil: Vec<u8>,
    /// 128 background (depth 1.0), 255 lit, 0 shadowed or facing away.
    pub mask: Vec<u8>,
    /// Pixels where the mask and the reference disagree, outside the [`BAND`].
    pub mismatches_outside_band: u64,
    /// Pixels compared with the reference.
    pub compared: u64,
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
}

/// The moving caster's transform at `frame`: the box slides towards the torus and turns.
pub fn box_transform(frame: usize) -> Mat4 {
    let f = frame as f32;
    Mat4::from_rotation_translation(Quat::from_rotation_y(0.25 * f), Vec3::new(1.2 - 0.3 * f, 0.5, 0.3 * f))
}

/// The scene at `frame`: a floor (open, casts nothing), a torus and a moving box casting, two
/// point lights without radius. The reference and umbrage's renderer are given this scene.
pub fn scene(frame: usize) -> Scene {
    let mesh = |name: &str, mesh, transform, casts_shadow| SceneMesh {
        name: name.into(),
        mesh,
        transform,
        color: Vec3::new(0.8, 0.7, 0.6),
        opacity: 1.0,
        casts_shadow,
    };
    let light = |position| Light {
        kind: LightKind::Point,
        position,
        direction: Vec3::NEG_Y,
        color: Vec3::ONE,
        intensity: 1.0,
        radius: None,
        cone_deg: 45.0,
        area: None,
    };
    Scene {
        name: "embedded".into(),
        camera: Camera { eye: Vec3::new(0.0, 4.0, 7.0), target: Vec3::new(0.0, 0.5, 0.0), ..Default::default() },
        lights: vec![light(Vec3::new(2.0, 6.0, 2.0)), light(Vec3::new(-3.0, 5.0, 3.5))],
        meshes: vec![
            mesh("floor", shapes::plane(Vec2::splat(20.0)), Mat4::IDENTITY, false),
            mesh("torus", shapes::torus(0.8, 0.25, 48, 24), Mat4::from_translation(Vec3::new(-1.2, 1.0, 0.0)), true),
            mesh("box", shapes::cuboid(Vec3::ONE), box_transform(frame), true),
        ],
        ambient: Vec3::splat(0.06),
        spheres: Vec::new(),
    }
}

/// Renders `frames` frames of [`scene`] with the box moving, two in flight, and checks each
/// against the reference. Errors: no usable Vulkan device, a failed call, or any validation
/// error (when `UMBRAGE_VALIDATION` is set), including those reported at teardown.
pub fn run(frames: usize) -> Result<Vec<FrameResult>, String> {
    let mut results = Vec::with_capacity(frames);
    let log;
    {
        let mut host = Host::new()?;
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
        return Err(format!("{} validation error(s) (teardown included), first: {first}", errors.len()));
    }
    Ok(results)
}

#[path = "frame.rs"]
mod frame;
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
    stats: Vec<LightStats>,
    totals: Totals,
    cpu_ms: CpuMs,
    warnings: Vec<String>,
}

/// A ring slot: command buffer, fence, readback and the lighting pass's index list.
struct Slot {
    cmd: vk::CommandBuffer,
    fence: vk::Fence,
    readback: Buf,
    lit: Buf,
    in_flight: Option<InFlight>,
}

/// Readback layout: the depth (4 bytes a texel), then per light its stencil and lit bytes.
struct Layout {
    pixels: u64,
}

impl Layout {
    fn depth(&self) -> u64 {
        0
    }
    fn stencil(&self, light: usize) -> u64 {
        self.pixels * (4 + 2 * light as u64)
    }
    fn lit(&self, light: usize) -> u64 {
        self.stencil(light) + self.pixels
    }
    fn total(&self, lights: usize) -> u64 {
        self.stencil(lights)
    }
}

/// Everything the host owns. Fields are filled in order by [`Host::new`]; `Drop` destroys what
/// exists, so a failure half-way cleans up too.
struct Host {
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
    lit_target: Option<Img>,
    meshes: Vec<MeshGpu>,
    slots: Vec<Slot>,
    pool: vk::CommandPool,
    layout: vk::PipelineLayout,
    prepass: vk::Pipeline,
    lighting: vk::Pipeline,
    depth_bounds: bool,
    extent: vk::Extent2D,
}

impl Host {
    fn new() -> Result<Host, String> {
        // SAFETY: loads the Vulkan loader; `entry` is kept in the host as long as the instance.
        let entry = unsafe { ash::Entry::load() }.map_err(|e| format!("no Vulkan loader (libvulkan.so.1): {e}"))?;
        let validation = validation_requested();
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
        let app = vk::ApplicationInfo::default().application_name(c"umbrage-embed").api_version(vk::API_VERSION_1_3);
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
        let log = Arc::new(Mutex::new(Vec::new()));
        let mut host = Host {
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
            lit_target: None,
            meshes: Vec::new(),
            slots: Vec::new(),
            pool: vk::CommandPool::null(),
            layout: vk::PipelineLayout::null(),
            prepass: vk::Pipeline::null(),
            lighting: vk::Pipeline::null(),
            depth_bounds: false,
            extent: vk::Extent2D { width: WIDTH, height: HEIGHT },
        };
        if validation {
            let du = ash::ext::debug_utils::Instance::new(&host._entry, &host.instance);
            let info = vk::DebugUtilsMessengerCreateInfoEXT::default()
                .message_severity(vk::DebugUtilsMessageSeverityFlagsEXT::ERROR | vk::DebugUtilsMessageSeverityFlagsEXT::WARNING)
                .message_type(vk::DebugUtilsMessageTypeFlagsEXT::GENERAL | vk::DebugUtilsMessageTypeFlagsEXT::VALIDATION)
                .pfn_user_callback(Some(debug_callback))
                .user_data(Arc::as_ptr(&host.log) as *mut c_void);
            // SAFETY: the callback is a plain function and the log (user data) outlives the
            // messenger: `Drop for Host` destroys the messenger before the fields drop.
            let m = unsafe { du.create_debug_utils_messenger(&info, None) }.map_err(vkerr("vkCreateDebugUtilsMessengerEXT"))?;
            host.debug = Some((du, m));
        }
        let picked = pick_device(&host.instance)?;
        host.physical = picked.physical;
        host.device_name = picked.name.clone();
        host.ds_format = picked.ds_format;
        host.features = EnabledFeatures {
            depth_clamp: picked.depth_clamp,
            depth_bounds: picked.depth_bounds,
            index_type_uint8: picked.index_type_uint8,
        };
        let device = create_device(&host.instance, &picked)?;
        host.device = Some(device.clone());
        // SAFETY: queue 0 of this family was requested at device creation.
        host.queue = unsafe { device.get_device_queue(picked.queue_family, 0) };
        let allocator = Allocator::new(&AllocatorCreateDesc {
            instance: host.instance.clone(),
            device: device.clone(),
            physical_device: host.physical,
            debug_settings: Default::default(),
            buffer_device_address: false,
            allocation_sizes: Default::default(),
        })
        .map_err(|e| format!("gpu-allocator: {e}"))?;
        let allocator = Arc::new(Mutex::new(allocator));
        host.allocator = Some(allocator.clone());

        let desc = ShadowPassDesc {
            depth_stencil_format: host.ds_format,
            frames_in_flight: FRAMES_IN_FLIGHT,
            features: host.features,
            ..Default::default()
        };
        let pass = ShadowPass::new(&host.instance, host.physical, &device, allocator.clone(), &desc)
            .map_err(|e| format!("ShadowPass::new: {e}"))?;
        host.depth_bounds = host.features.depth_bounds && pass.capabilities().depth_bounds;
        host.pass = Some(pass);

        let extent = host.extent;
        host.depth = Some(create_image(
            &device,
            &allocator,
            "depth-stencil",
            host.ds_format,
            extent,
            vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT | vk::ImageUsageFlags::TRANSFER_SRC,
            vk::ImageAspectFlags::DEPTH | vk::ImageAspectFlags::STENCIL,
        )?);
        host.lit_target = Some(create_image(
            &device,
            &allocator,
            "lit",
            LIT_FORMAT,
            extent,
            vk::ImageUsageFlags::COLOR_ATTACHMENT | vk::ImageUsageFlags::TRANSFER_SRC,
            vk::ImageAspectFlags::COLOR,
        )?);

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
        let range = [vk::PushConstantRange {
            stage_flags: vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT,
            offset: 0,
            size: VolumePush::SIZE,
        }];
        // SAFETY: as above.
        host.layout = unsafe { device.create_pipeline_layout(&vk::PipelineLayoutCreateInfo::default().push_constant_ranges(&range), None) }
            .map_err(vkerr("vkCreatePipelineLayout"))?;
        host.create_pipelines(&device)?;

        let s = scene(0);
        for m in &s.meshes {
            let vertices: Vec<[f32; 4]> = m.mesh.positions.iter().map(|p| p.extend(1.0).to_array()).collect();
            let indices: Vec<u32> = m.mesh.triangles.iter().flatten().copied().collect();
            let vb = upload(
                &device,
                &allocator,
                &format!("{} vertices", m.name),
                bytemuck::cast_slice(&vertices),
                vk::BufferUsageFlags::VERTEX_BUFFER,
            )?;
            let ib = match upload(
                &device,
                &allocator,
                &format!("{} indices", m.name),
                bytemuck::cast_slice(&indices),
                vk::BufferUsageFlags::INDEX_BUFFER,
            ) {
                Ok(b) => b,
                Err(e) => {
                    free_buffer(&device, &allocator, vb);
                    return Err(e);
                }
            };
            let mut gpu = MeshGpu {
                vertices: vb,
                indices: ib,
                index_count: indices.len() as u32,
                positions: m.mesh.positions.clone(),
                triangles: m.mesh.triangles.clone(),
                caster: None,
            };
            if m.casts_shadow {
                let pass = host.pass.as_mut().ok_or("no pass")?;
                match pass.add_caster(&m.name, &m.mesh, m.transform.as_dmat4()) {
                    Ok(id) => gpu.caster = Some(id),
                    Err(e) => {
                        host.meshes.push(gpu);
                        return Err(format!("add_caster({}): {e}", m.name));
                    }
                }
            }
            host.meshes.push(gpu);
        }

        let layout = Layout { pixels: (WIDTH * HEIGHT) as u64 };
        let lit_bytes: u64 = s.meshes.iter().map(|m| m.mesh.triangles.len() as u64 * 12).sum::<u64>() * s.lights.len() as u64;
        // SAFETY: allocation from the host's pool; freed in `Drop for Host`.
        let cmds = unsafe {
            device.allocate_command_buffers(
                &vk::CommandBufferAllocateInfo::default()
                    .command_pool(host.pool)
                    .level(vk::CommandBufferLevel::PRIMARY)
                    .command_buffer_count(FRAMES_IN_FLIGHT as u32),
            )
        }
        .map_err(vkerr("vkAllocateCommandBuffers"))?;
        for (i, cmd) in cmds.into_iter().enumerate() {
            // SAFETY: as above.
            let fence = unsafe { device.create_fence(&vk::FenceCreateInfo::default(), None) }.map_err(vkerr("vkCreateFence"));
            let fence = match fence {
                Ok(f) => f,
                Err(e) => {
                    // SAFETY: the buffer was never submitted.
                    unsafe { device.free_command_buffers(host.pool, &[cmd]) };
                    return Err(e);
                }
            };
            let readback = create_buffer(
                &device,
                &allocator,
                &format!("readback {i}"),
                layout.total(s.lights.len()),
                vk::BufferUsageFlags::TRANSFER_DST,
                MemoryLocation::GpuToCpu,
            );
            let lit = create_buffer(
                &device,
                &allocator,
                &format!("lit indices {i}"),
                lit_bytes,
                vk::BufferUsageFlags::INDEX_BUFFER,
                MemoryLocation::CpuToGpu,
            );
            match (readback, lit) {
                (Ok(readback), Ok(lit)) => host.slots.push(Slot { cmd, fence, readback, lit, in_flight: None }),
                (r, l) => {
                    // SAFETY: neither object was ever used by the GPU.
                    unsafe {
                        device.destroy_fence(fence, None);
                        device.free_command_buffers(host.pool, &[cmd]);
                    }
                    let mut err = String::new();
                    for b in [r, l] {
                        match b {
                            Ok(b) => free_buffer(&device, &allocator, b),
                            Err(e) => err = e,
                        }
                    }
                    return Err(err);
                }
            }
        }
        Ok(host)
    }

    fn dev(&self) -> &ash::Device {
        self.device.as_ref().expect("the device exists once Host::new returned")
    }

    fn pass(&mut self) -> &mut ShadowPass {
        self.pass.as_mut().expect("the pass exists once Host::new returned")
    }

    /// The depth pre-pass and the lighting pass. Both use umbrage's compiled `shadow.vert`
    /// (to keep the example short: with w = 1 positions it is just `mvp * pos`, push block
    /// `{ mat4 mvp; vec4 light; vec4 color; }`), so the lighting pass's depth EQUAL sees
    /// exactly the pre-pass's depths; the lighting pass writes `pc.color` with umbrage's
    /// `volume.frag`; the pre-pass has no fragment shader.
    fn create_pipelines(&mut self, device: &ash::Device) -> Result<(), String> {
        let vs = shader_module(device, SHADOW_VERT)?;
        let fs = match shader_module(device, VOLUME_FRAG) {
            Ok(f) => f,
            Err(e) => {
                // SAFETY: the module is unused.
                unsafe { device.destroy_shader_module(vs, None) };
                return Err(e);
            }
        };
        let prepass = PipelineState {
            vs,
            fs: None,
            color: None,
            depth_compare: vk::CompareOp::LESS,
            depth_write: true,
            stencil: None,
            depth_bounds: false,
        };
        let lit = lit_stencil_state();
        let lighting = PipelineState {
            vs,
            fs: Some(fs),
            color: Some(LIT_FORMAT),
            depth_compare: vk::CompareOp::EQUAL,
            depth_write: false,
            stencil: Some(lit),
            depth_bounds: self.depth_bounds,
        };
        let r1 = create_pipeline(device, self.layout, self.ds_format, &prepass);
        let r2 = create_pipeline(device, self.layout, self.ds_format, &lighting);
        // SAFETY: modules may be destroyed once the pipelines exist (or failed).
        unsafe {
            device.destroy_shader_module(vs, None);
            device.destroy_shader_module(fs, None);
        }
        if let Ok(p) = &r1 {
            self.prepass = *p;
        }
        if let Ok(p) = &r2 {
            self.lighting = *p;
        }
        r1.and(r2).map(|_| ())
    }
}

impl Drop for Host {
    /// Teardown: device idle, the pass, the host's buffers and images, the allocator (last
    /// Arc), pipelines, pool, device, messenger, instance.
    fn drop(&mut self) {
        if let Some(device) = self.device.take() {
            // SAFETY: after the wait nothing on the GPU uses any object destroyed below; each
            // is destroyed once, children before parents, the pass before its device.
            unsafe {
                let _ = device.device_wait_idle();
                drop(self.pass.take());
                if let Some(allocator) = self.allocator.take() {
                    for m in self.meshes.drain(..) {
                        free_buffer(&device, &allocator, m.vertices);
                        free_buffer(&device, &allocator, m.indices);
                    }
                    for s in self.slots.drain(..) {
                        free_buffer(&device, &allocator, s.readback);
                        free_buffer(&device, &allocator, s.lit);
                        device.destroy_fence(s.fence, None);
                        device.free_command_buffers(self.pool, &[s.cmd]);
                    }
                    for img in [self.depth.take(), self.lit_target.take()].into_iter().flatten() {
                        device.destroy_image_view(img.view, None);
                        device.destroy_image(img.raw, None);
                        if let Some(a) = img.alloc {
                            let _ = lock(&allocator).free(a);
                        }
                    }
                    // The allocator frees its memory blocks when the last Arc drops: here,
                    // the pass's clone is gone.
                    if let Err(a) = Arc::try_unwrap(allocator) {
                        if let Ok(mut l) = self.log.lock() {
                            l.push(format!("allocator still shared at teardown ({} references)", Arc::strong_count(&a)));
                        }
                    }
                }
                for p in [self.prepass, self.lighting] {
                    if p != vk::Pipeline::null() {
                        device.destroy_pipeline(p, None);
                    }
                }
                if self.layout != vk::PipelineLayout::null() {
                    device.destroy_pipeline_layout(self.layout, None);
                }
                if self.pool != vk::CommandPool::null() {
                    device.destroy_command_pool(self.pool, None);
                }
                device.destroy_device(None);
            }
        }
        // SAFETY: every child of the instance is gone; the messenger goes before the instance,
        // and the log it writes into is still alive (a field, dropped after this body).
        unsafe {
            if let Some((du, m)) = self.debug.take() {
                du.destroy_debug_utils_messenger(m, None);
            }
            self.instance.destroy_instance(None);
        }
    }
}
