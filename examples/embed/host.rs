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
//! `examples/embed/main.rs` prints the result; `tests/embed.rs` includes this file and checks
//! it against the reference and umbrage's own renderer.
#![allow(dead_code)]

use ash::vk;
use glam::{DMat4, DVec3, Mat4, Quat, Vec2, Vec3, Vec4};
use gpu_allocator::vulkan::{Allocation, AllocationCreateDesc, AllocationScheme, Allocator, AllocatorCreateDesc};
use gpu_allocator::MemoryLocation;
use std::ffi::{c_void, CStr};
use std::sync::{Arc, Mutex};
use umbrage::geom::{Camera, Light, LightKind};
use umbrage::gpu::shaders::{SHADOW_VERT, VOLUME_FRAG};
use umbrage::pass::push::VolumePush;
use umbrage::pass::stats::{CpuMs, LightStats, Totals};
use umbrage::pass::{lit_stencil_state, CasterId, DepthStencilTarget, EnabledFeatures, ShadowPass, ShadowPassDesc, ShadowView};
use umbrage::reference::{metrics::compare_all, Reference};
use umbrage::scene::{shapes, Scene, SceneMesh};

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

fn vkerr(call: &'static str) -> impl Fn(vk::Result) -> String {
    move |e| format!("{call} failed: {e:?}")
}

fn validation_requested() -> bool {
    std::env::var("UMBRAGE_VALIDATION").map(|v| v == "1" || v.eq_ignore_ascii_case("true")).unwrap_or(false)
}

/// Collects validation ERRORs into the `Mutex<Vec<String>>` passed as user data.
///
/// # Safety
/// Called by the validation layer only, with the user data the messenger was created with.
unsafe extern "system" fn debug_callback(
    severity: vk::DebugUtilsMessageSeverityFlagsEXT,
    _types: vk::DebugUtilsMessageTypeFlagsEXT,
    data: *const vk::DebugUtilsMessengerCallbackDataEXT<'_>,
    user: *mut c_void,
) -> vk::Bool32 {
    // SAFETY: the loader passes valid callback data for the duration of the call; `user` is
    // `Arc::as_ptr` of the host's log, which outlives the messenger (destroyed first).
    let (msg, log) = unsafe {
        let msg = if data.is_null() || (*data).p_message.is_null() {
            String::from("(no message)")
        } else {
            CStr::from_ptr((*data).p_message).to_string_lossy().into_owned()
        };
        (msg, &*(user as *const Mutex<Vec<String>>))
    };
    if severity.contains(vk::DebugUtilsMessageSeverityFlagsEXT::ERROR) {
        eprintln!("[vulkan validation] {msg}");
        if let Ok(mut l) = log.lock() {
            l.push(msg);
        }
    }
    vk::FALSE
}

/// A buffer and its memory from the host's allocator.
struct Buf {
    raw: vk::Buffer,
    alloc: Option<Allocation>,
}

/// An image, its view and its memory.
struct Img {
    raw: vk::Image,
    view: vk::ImageView,
    alloc: Option<Allocation>,
}

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

/// The physical device the host picked, and what it found on it.
struct Picked {
    physical: vk::PhysicalDevice,
    name: String,
    queue_family: u32,
    ds_format: vk::Format,
    depth_clamp: bool,
    depth_bounds: bool,
    index_type_uint8: bool,
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
        let info =
            vk::InstanceCreateInfo::default().application_info(&app).enabled_layer_names(&layers).enabled_extension_names(&extensions);
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

    /// Records and submits frame `f` into ring slot `f % 2`, after retiring that slot's
    /// previous frame (its fence, its readback into `out`).
    fn frame(&mut self, f: usize, out: &mut Vec<FrameResult>) -> Result<(), String> {
        let slot = f % FRAMES_IN_FLIGHT;
        self.retire(slot, out)?;
        let s = scene(f);
        // Move the caster: the pass re-plans from the new transform; nothing is re-created.
        let moving = self.meshes[MOVING_MESH].caster.ok_or("the box casts no shadow")?;
        self.pass().set_transform(moving, s.meshes[MOVING_MESH].transform.as_dmat4()).map_err(|e| e.to_string())?;

        let cam = &s.camera;
        let (w, h) = (WIDTH, HEIGHT);
        let eye = cam.eye.as_dvec3();
        // Eye-relative view (rotation only) and the infinite projection the pass assumes.
        let view = glam::camera::rh::view::look_at_mat4(Vec3::ZERO, cam.target - cam.eye, cam.up.normalize());
        let proj = cam.proj_infinite(w as f32 / h as f32);
        let frame = self
            .pass()
            .prepare(slot, &ShadowView { eye, view, proj, width: w, height: h }, &s.lights)
            .map_err(|e| format!("prepare: {e}"))?;
        // Exactly as the pass composes its casters' MVPs, so the volumes land on these depths.
        let mvps: Vec<Mat4> = s
            .meshes
            .iter()
            .map(|m| (proj.as_dmat4() * view.as_dmat4() * DMat4::from_translation(-eye) * m.transform.as_dmat4()).as_mat4())
            .collect();

        // The lighting pass's index lists: per light and mesh, the triangles facing the light.
        let mut lit_data: Vec<u32> = Vec::new();
        let mut lit_draws = vec![Vec::new(); s.lights.len()];
        for (li, light) in s.lights.iter().enumerate() {
            let lp = light.position.as_dvec3();
            for (mi, m) in s.meshes.iter().enumerate() {
                let xf = m.transform.as_dmat4();
                let world: Vec<DVec3> = self.meshes[mi].positions.iter().map(|p| xf.transform_point3(p.as_dvec3())).collect();
                let first = lit_data.len();
                for t in &self.meshes[mi].triangles {
                    let [a, b, c] = t.map(|i| world[i as usize]);
                    if (b - a).cross(c - a).dot(lp - a) > 0.0 {
                        lit_data.extend_from_slice(t);
                    }
                }
                lit_draws[li].push(((first * 4) as u64, (lit_data.len() - first) as u32));
            }
        }
        write_buffer(&mut self.slots[slot].lit, bytemuck::cast_slice(&lit_data))?;

        let device = self.dev().clone();
        let pass = self.pass.as_ref().ok_or("no pass")?;
        let depth = self.depth.as_ref().ok_or("no depth image")?;
        let lit_img = self.lit_target.as_ref().ok_or("no lit target")?;
        let slot_ref = &self.slots[slot];
        let cb = slot_ref.cmd;
        let layout = Layout { pixels: (w * h) as u64 };
        let full = vk::Rect2D { offset: vk::Offset2D { x: 0, y: 0 }, extent: self.extent };
        let viewport = vk::Viewport { x: 0.0, y: 0.0, width: w as f32, height: h as f32, min_depth: 0.0, max_depth: 1.0 };
        let ds_aspects = vk::ImageAspectFlags::DEPTH | vk::ImageAspectFlags::STENCIL;
        let frag_tests = vk::PipelineStageFlags2::EARLY_FRAGMENT_TESTS | vk::PipelineStageFlags2::LATE_FRAGMENT_TESTS;
        let ds_rw = vk::AccessFlags2::DEPTH_STENCIL_ATTACHMENT_READ | vk::AccessFlags2::DEPTH_STENCIL_ATTACHMENT_WRITE;
        let ds_layout = vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL;
        let src_layout = vk::ImageLayout::TRANSFER_SRC_OPTIMAL;
        let copy = vk::PipelineStageFlags2::COPY;
        let ds_att = |load: vk::AttachmentLoadOp| {
            vk::RenderingAttachmentInfo::default()
                .image_view(depth.view)
                .image_layout(ds_layout)
                .load_op(load)
                .store_op(vk::AttachmentStoreOp::STORE)
                .clear_value(vk::ClearValue { depth_stencil: vk::ClearDepthStencilValue { depth: 1.0, stencil: 0 } })
        };
        let copy_out = |img: vk::Image, aspect: vk::ImageAspectFlags, offset: u64| {
            let region = vk::BufferImageCopy::default()
                .buffer_offset(offset)
                .image_subresource(vk::ImageSubresourceLayers { aspect_mask: aspect, mip_level: 0, base_array_layer: 0, layer_count: 1 })
                .image_extent(vk::Extent3D { width: w, height: h, depth: 1 });
            // SAFETY: `cb` is recording outside a rendering instance; the image is in
            // TRANSFER_SRC_OPTIMAL and the range lies inside the slot's readback buffer.
            unsafe { device.cmd_copy_image_to_buffer(cb, img, src_layout, slot_ref.readback.raw, &[region]) };
        };
        let push = |mvp: Mat4, color: [f32; 4]| {
            let p = VolumePush::new(mvp, Vec4::ZERO, color);
            let stages = vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT;
            // SAFETY: `cb` is recording with a pipeline of `self.layout` bound; 96 bytes.
            unsafe { device.cmd_push_constants(cb, self.layout, stages, 0, bytemuck::bytes_of(&p)) };
        };
        let target = DepthStencilTarget { view: depth.view, extent: self.extent };

        // SAFETY (the whole recording): the slot's previous submission retired (`retire`
        // waited its fence), so its command buffer may be reset and re-recorded; every object
        // recorded belongs to this device and lives until the device is idle at teardown; the
        // layouts named are those the preceding barriers leave; `frame` was prepared for this
        // slot and the slot is not prepared again before this submission's fence is waited.
        unsafe {
            device.reset_command_buffer(cb, vk::CommandBufferResetFlags::empty()).map_err(vkerr("vkResetCommandBuffer"))?;
            device
                .begin_command_buffer(cb, &vk::CommandBufferBeginInfo::default().flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT))
                .map_err(vkerr("vkBeginCommandBuffer"))?;
            // The depth-stencil image: its previous contents (the other frame's) are discarded;
            // ALL_COMMANDS orders this after the previous frame's copies on the queue.
            image_barrier(
                &device,
                cb,
                depth.raw,
                ds_aspects,
                (vk::ImageLayout::UNDEFINED, ds_layout),
                (vk::PipelineStageFlags2::ALL_COMMANDS, vk::AccessFlags2::NONE),
                (frag_tests, ds_rw),
            );
            pass.cmd_upload(cb, &frame);

            // Depth pre-pass: every mesh, depth LESS, stencil cleared to 0.
            let d = ds_att(vk::AttachmentLoadOp::CLEAR);
            device.cmd_begin_rendering(
                cb,
                &vk::RenderingInfo::default().render_area(full).layer_count(1).depth_attachment(&d).stencil_attachment(&d),
            );
            device.cmd_bind_pipeline(cb, vk::PipelineBindPoint::GRAPHICS, self.prepass);
            device.cmd_set_viewport(cb, 0, &[viewport]);
            device.cmd_set_scissor(cb, 0, &[full]);
            for (mi, m) in self.meshes.iter().enumerate() {
                push(mvps[mi], [0.0; 4]);
                device.cmd_bind_vertex_buffers(cb, 0, &[m.vertices.raw], &[0]);
                device.cmd_bind_index_buffer(cb, m.indices.raw, 0, vk::IndexType::UINT32);
                device.cmd_draw_indexed(cb, m.index_count, 1, 0, 0, 0);
            }
            device.cmd_end_rendering(cb);
            memory_barrier(
                &device,
                cb,
                (vk::PipelineStageFlags2::LATE_FRAGMENT_TESTS, vk::AccessFlags2::DEPTH_STENCIL_ATTACHMENT_WRITE),
                (frag_tests, ds_rw),
            );

            for (li, draws) in lit_draws.iter().enumerate() {
                // The shadow determination: the count in the stencil.
                pass.cmd_determine(cb, &frame, li, &target);
                // Stencil out (readback), then back to attachment for the lighting pass.
                image_barrier(
                    &device,
                    cb,
                    depth.raw,
                    ds_aspects,
                    (ds_layout, src_layout),
                    (frag_tests, ds_rw),
                    (copy, vk::AccessFlags2::TRANSFER_READ),
                );
                copy_out(depth.raw, vk::ImageAspectFlags::STENCIL, layout.stencil(li));
                image_barrier(
                    &device,
                    cb,
                    depth.raw,
                    ds_aspects,
                    (src_layout, ds_layout),
                    (copy, vk::AccessFlags2::NONE),
                    (frag_tests, ds_rw),
                );

                // The host's lighting pass: light-facing triangles, depth EQUAL, stencil == 0.
                image_barrier(
                    &device,
                    cb,
                    lit_img.raw,
                    vk::ImageAspectFlags::COLOR,
                    (vk::ImageLayout::UNDEFINED, vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL),
                    (copy, vk::AccessFlags2::NONE),
                    (vk::PipelineStageFlags2::COLOR_ATTACHMENT_OUTPUT, vk::AccessFlags2::COLOR_ATTACHMENT_WRITE),
                );
                let color = [vk::RenderingAttachmentInfo::default()
                    .image_view(lit_img.view)
                    .image_layout(vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL)
                    .load_op(vk::AttachmentLoadOp::CLEAR)
                    .store_op(vk::AttachmentStoreOp::STORE)
                    .clear_value(vk::ClearValue { color: vk::ClearColorValue { float32: [0.0; 4] } })];
                let d = ds_att(vk::AttachmentLoadOp::LOAD);
                device.cmd_begin_rendering(
                    cb,
                    &vk::RenderingInfo::default()
                        .render_area(full)
                        .layer_count(1)
                        .color_attachments(&color)
                        .depth_attachment(&d)
                        .stencil_attachment(&d),
                );
                device.cmd_bind_pipeline(cb, vk::PipelineBindPoint::GRAPHICS, self.lighting);
                // Viewport, the light's scissor and (when used) its depth bounds.
                pass.cmd_light_state(cb, &frame, li, self.extent);
                device.cmd_bind_index_buffer(cb, slot_ref.lit.raw, 0, vk::IndexType::UINT32);
                for (mi, m) in self.meshes.iter().enumerate() {
                    let (offset, count) = draws[mi];
                    if count == 0 {
                        continue;
                    }
                    push(mvps[mi], [1.0; 4]);
                    device.cmd_bind_vertex_buffers(cb, 0, &[m.vertices.raw], &[0]);
                    device.cmd_draw_indexed(cb, count, 1, (offset / 4) as u32, 0, 0);
                }
                device.cmd_end_rendering(cb);
                image_barrier(
                    &device,
                    cb,
                    lit_img.raw,
                    vk::ImageAspectFlags::COLOR,
                    (vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL, src_layout),
                    (vk::PipelineStageFlags2::COLOR_ATTACHMENT_OUTPUT, vk::AccessFlags2::COLOR_ATTACHMENT_WRITE),
                    (copy, vk::AccessFlags2::TRANSFER_READ),
                );
                copy_out(lit_img.raw, vk::ImageAspectFlags::COLOR, layout.lit(li));
                // The next light's determination clears the stencil the lighting pass read.
                memory_barrier(&device, cb, (frag_tests, ds_rw), (frag_tests, ds_rw));
            }

            // The depth, once: background is depth 1.0.
            image_barrier(
                &device,
                cb,
                depth.raw,
                ds_aspects,
                (ds_layout, src_layout),
                (frag_tests, ds_rw),
                (copy, vk::AccessFlags2::TRANSFER_READ),
            );
            copy_out(depth.raw, vk::ImageAspectFlags::DEPTH, layout.depth());
            memory_barrier(
                &device,
                cb,
                (copy, vk::AccessFlags2::TRANSFER_WRITE),
                (vk::PipelineStageFlags2::HOST, vk::AccessFlags2::HOST_READ),
            );
            device.end_command_buffer(cb).map_err(vkerr("vkEndCommandBuffer"))?;
            device.reset_fences(&[slot_ref.fence]).map_err(vkerr("vkResetFences"))?;
            let cbs = [cb];
            device
                .queue_submit(self.queue, &[vk::SubmitInfo::default().command_buffers(&cbs)], slot_ref.fence)
                .map_err(vkerr("vkQueueSubmit"))?;
        }
        self.slots[slot].in_flight = Some(InFlight {
            frame: f,
            stats: frame.lights.iter().map(|l| l.stats.clone()).collect(),
            totals: frame.totals.clone(),
            cpu_ms: frame.cpu_ms.clone(),
            warnings: frame.warnings.clone(),
        });
        Ok(())
    }

    /// Waits for the frame in flight in `slot` (if any), reads its readback and compares it
    /// with the reference of that frame's scene.
    fn retire(&mut self, slot: usize, out: &mut Vec<FrameResult>) -> Result<(), String> {
        let Some(fl) = self.slots[slot].in_flight.take() else { return Ok(()) };
        // SAFETY: the fence belongs to this device and was submitted with the frame.
        unsafe { self.dev().wait_for_fences(&[self.slots[slot].fence], true, u64::MAX) }.map_err(vkerr("vkWaitForFences"))?;
        if let Some(first) = self.log.lock().ok().and_then(|l| l.first().cloned()) {
            return Err(format!("validation error by frame {}: {first}", fl.frame));
        }
        let s = scene(fl.frame);
        let layout = Layout { pixels: (WIDTH * HEIGHT) as u64 };
        let n = layout.pixels as usize;
        let data = self.slots[slot].readback.alloc.as_ref().and_then(|a| a.mapped_slice()).ok_or("readback is not host visible")?;
        let depth = &data[..4 * n];
        let d24 = self.ds_format == vk::Format::D24_UNORM_S8_UINT;
        let background: Vec<bool> = depth
            .chunks_exact(4)
            .map(|b| {
                let v = u32::from_le_bytes([b[0], b[1], b[2], b[3]]);
                if d24 {
                    v & 0x00ff_ffff == 0x00ff_ffff
                } else {
                    f32::from_bits(v) == 1.0
                }
            })
            .collect();
        let mut lights = Vec::with_capacity(s.lights.len());
        for li in 0..s.lights.len() {
            let so = layout.stencil(li) as usize;
            let lo = layout.lit(li) as usize;
            let stencil = data[so..so + n].to_vec();
            let lit = &data[lo..lo + n];
            let mask = (0..n)
                .map(|i| {
                    if background[i] {
                        128
                    } else if lit[i] != 0 {
                        255
                    } else {
                        0
                    }
                })
                .collect();
            lights.push(LightResult { stencil, mask, mismatches_outside_band: 0, compared: 0 });
        }
        let masks: Vec<Vec<u8>> = lights.iter().map(|l| l.mask.clone()).collect();
        let reference = Reference::from_scene(&s).render(&s.camera, &s.lights, WIDTH, HEIGHT);
        let metrics = compare_all(&masks, &reference, BAND).map_err(|e| format!("compare: {e}"))?;
        for (l, m) in lights.iter_mut().zip(&metrics) {
            l.mismatches_outside_band = m.mismatches_outside_band;
            l.compared = m.compared;
        }
        out.push(FrameResult {
            frame: fl.frame,
            slot,
            device: self.device_name.clone(),
            stats: fl.stats,
            totals: fl.totals,
            cpu_ms: fl.cpu_ms,
            warnings: fl.warnings,
            lights,
        });
        Ok(())
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

fn lock(a: &Mutex<Allocator>) -> std::sync::MutexGuard<'_, Allocator> {
    a.lock().unwrap_or_else(|p| p.into_inner())
}

/// The first Vulkan 1.3 device with a graphics queue, dynamicRendering, synchronization2 and
/// a depth-stencil attachment format with 8 stencil bits: discrete before integrated before
/// virtual before CPU (`UMBRAGE_DEVICE=<name substring>` picks one).
fn pick_device(instance: &ash::Instance) -> Result<Picked, String> {
    // SAFETY: enumeration on a valid instance.
    let physicals = unsafe { instance.enumerate_physical_devices() }.map_err(vkerr("vkEnumeratePhysicalDevices"))?;
    let wanted = std::env::var("UMBRAGE_DEVICE").ok().map(|s| s.to_lowercase());
    let mut best: Option<(u32, Picked)> = None;
    for pd in physicals {
        // SAFETY: `pd` comes from the enumeration above (and so below).
        let props = unsafe { instance.get_physical_device_properties(pd) };
        let name = props.device_name_as_c_str().map(|c| c.to_string_lossy().into_owned()).unwrap_or_default();
        if props.api_version < vk::API_VERSION_1_3 || wanted.as_ref().is_some_and(|w| !name.to_lowercase().contains(w)) {
            continue;
        }
        // SAFETY: as above.
        let families = unsafe { instance.get_physical_device_queue_family_properties(pd) };
        let Some(qf) = families.iter().position(|f| f.queue_flags.contains(vk::QueueFlags::GRAPHICS)) else { continue };
        let mut f13 = vk::PhysicalDeviceVulkan13Features::default();
        let mut f2 = vk::PhysicalDeviceFeatures2::default().push_next(&mut f13);
        // SAFETY: the pNext chain points at a local alive for the call.
        unsafe { instance.get_physical_device_features2(pd, &mut f2) };
        let base = f2.features;
        if f13.dynamic_rendering != vk::TRUE || f13.synchronization2 != vk::TRUE {
            continue;
        }
        let needed = vk::FormatFeatureFlags::DEPTH_STENCIL_ATTACHMENT | vk::FormatFeatureFlags::TRANSFER_SRC;
        let ds_format = [vk::Format::D32_SFLOAT_S8_UINT, vk::Format::D24_UNORM_S8_UINT].into_iter().find(|&f| {
            // SAFETY: a format query on a valid physical device.
            let p = unsafe { instance.get_physical_device_format_properties(pd, f) };
            p.optimal_tiling_features.contains(needed)
        });
        let Some(ds_format) = ds_format else { continue };
        // SAFETY: as above.
        let exts = unsafe { instance.enumerate_device_extension_properties(pd) }.map_err(vkerr("vkEnumerateDeviceExtensionProperties"))?;
        let has_u8_ext = exts.iter().any(|e| e.extension_name_as_c_str().map(|n| n == ash::ext::index_type_uint8::NAME).unwrap_or(false));
        let index_type_uint8 = has_u8_ext && {
            let mut u8f = vk::PhysicalDeviceIndexTypeUint8FeaturesEXT::default();
            let mut f2 = vk::PhysicalDeviceFeatures2::default().push_next(&mut u8f);
            // SAFETY: as above.
            unsafe { instance.get_physical_device_features2(pd, &mut f2) };
            u8f.index_type_uint8 == vk::TRUE
        };
        let rank = match props.device_type {
            vk::PhysicalDeviceType::DISCRETE_GPU => 0,
            vk::PhysicalDeviceType::INTEGRATED_GPU => 1,
            vk::PhysicalDeviceType::VIRTUAL_GPU => 2,
            vk::PhysicalDeviceType::CPU => 3,
            _ => 4,
        };
        if best.as_ref().map(|(r, _)| rank < *r).unwrap_or(true) {
            let picked = Picked {
                physical: pd,
                name,
                queue_family: qf as u32,
                ds_format,
                depth_clamp: base.depth_clamp == vk::TRUE,
                depth_bounds: base.depth_bounds == vk::TRUE,
                index_type_uint8,
            };
            best = Some((rank, picked));
        }
    }
    best.map(|(_, p)| p)
        .ok_or_else(|| "no Vulkan 1.3 device with graphics, dynamicRendering, synchronization2 and a D32S8/D24S8 attachment".into())
}

/// The logical device: one graphics queue, Vulkan 1.3's dynamicRendering and
/// synchronization2, depthClamp / depthBounds / indexTypeUint8 where present.
fn create_device(instance: &ash::Instance, p: &Picked) -> Result<ash::Device, String> {
    let enabled = vk::PhysicalDeviceFeatures::default().depth_clamp(p.depth_clamp).depth_bounds(p.depth_bounds);
    let mut f13 = vk::PhysicalDeviceVulkan13Features::default().dynamic_rendering(true).synchronization2(true);
    let mut u8f = vk::PhysicalDeviceIndexTypeUint8FeaturesEXT::default().index_type_uint8(true);
    let mut exts = Vec::new();
    if p.index_type_uint8 {
        exts.push(ash::ext::index_type_uint8::NAME.as_ptr());
    }
    let prio = [1.0f32];
    let queues = [vk::DeviceQueueCreateInfo::default().queue_family_index(p.queue_family).queue_priorities(&prio)];
    let mut info = vk::DeviceCreateInfo::default()
        .queue_create_infos(&queues)
        .enabled_features(&enabled)
        .enabled_extension_names(&exts)
        .push_next(&mut f13);
    if p.index_type_uint8 {
        info = info.push_next(&mut u8f);
    }
    // SAFETY: every pointer in `info` refers to locals alive for the call.
    unsafe { instance.create_device(p.physical, &info, None) }.map_err(vkerr("vkCreateDevice"))
}

fn create_buffer(
    device: &ash::Device,
    allocator: &Mutex<Allocator>,
    name: &str,
    size: u64,
    usage: vk::BufferUsageFlags,
    location: MemoryLocation,
) -> Result<Buf, String> {
    let info = vk::BufferCreateInfo::default().size(size.max(4)).usage(usage).sharing_mode(vk::SharingMode::EXCLUSIVE);
    // SAFETY: a valid create info on a valid device.
    let raw = unsafe { device.create_buffer(&info, None) }.map_err(vkerr("vkCreateBuffer"))?;
    // SAFETY: `raw` was just created on this device.
    let requirements = unsafe { device.get_buffer_memory_requirements(raw) };
    let desc =
        AllocationCreateDesc { name, requirements, location, linear: true, allocation_scheme: AllocationScheme::GpuAllocatorManaged };
    let alloc = match lock(allocator).allocate(&desc) {
        Ok(a) => a,
        Err(e) => {
            // SAFETY: the buffer was never used.
            unsafe { device.destroy_buffer(raw, None) };
            return Err(format!("allocating {name}: {e}"));
        }
    };
    let buf = Buf { raw, alloc: Some(alloc) };
    let a = buf.alloc.as_ref().ok_or("no allocation")?;
    // SAFETY: the allocation was made for this buffer's requirements.
    if let Err(e) = unsafe { device.bind_buffer_memory(raw, a.memory(), a.offset()) } {
        free_buffer(device, allocator, buf);
        return Err(format!("vkBindBufferMemory failed: {e:?}"));
    }
    Ok(buf)
}

fn free_buffer(device: &ash::Device, allocator: &Mutex<Allocator>, mut b: Buf) {
    // SAFETY: the caller guarantees the GPU no longer uses the buffer.
    unsafe { device.destroy_buffer(b.raw, None) };
    if let Some(a) = b.alloc.take() {
        let _ = lock(allocator).free(a);
    }
}

fn write_buffer(b: &mut Buf, data: &[u8]) -> Result<(), String> {
    let slice = b.alloc.as_mut().and_then(|a| a.mapped_slice_mut()).ok_or("buffer is not host visible")?;
    if data.len() > slice.len() {
        return Err(format!("buffer write of {} bytes into {}", data.len(), slice.len()));
    }
    slice[..data.len()].copy_from_slice(data);
    Ok(())
}

/// A host-visible buffer filled with `data` (the meshes are small; an engine would stage).
fn upload(device: &ash::Device, allocator: &Mutex<Allocator>, name: &str, data: &[u8], usage: vk::BufferUsageFlags) -> Result<Buf, String> {
    let mut b = create_buffer(device, allocator, name, data.len() as u64, usage, MemoryLocation::CpuToGpu)?;
    if let Err(e) = write_buffer(&mut b, data) {
        free_buffer(device, allocator, b);
        return Err(e);
    }
    Ok(b)
}

fn create_image(
    device: &ash::Device,
    allocator: &Mutex<Allocator>,
    name: &str,
    format: vk::Format,
    extent: vk::Extent2D,
    usage: vk::ImageUsageFlags,
    aspect: vk::ImageAspectFlags,
) -> Result<Img, String> {
    let info = vk::ImageCreateInfo::default()
        .image_type(vk::ImageType::TYPE_2D)
        .format(format)
        .extent(vk::Extent3D { width: extent.width, height: extent.height, depth: 1 })
        .mip_levels(1)
        .array_layers(1)
        .samples(vk::SampleCountFlags::TYPE_1)
        .tiling(vk::ImageTiling::OPTIMAL)
        .usage(usage)
        .initial_layout(vk::ImageLayout::UNDEFINED);
    // SAFETY: a valid create info on a valid device.
    let raw = unsafe { device.create_image(&info, None) }.map_err(vkerr("vkCreateImage"))?;
    // SAFETY: `raw` is a new image of this device.
    let requirements = unsafe { device.get_image_memory_requirements(raw) };
    let desc = AllocationCreateDesc {
        name,
        requirements,
        location: MemoryLocation::GpuOnly,
        linear: false,
        allocation_scheme: AllocationScheme::GpuAllocatorManaged,
    };
    let alloc = match lock(allocator).allocate(&desc) {
        Ok(a) => a,
        Err(e) => {
            // SAFETY: the image was never used.
            unsafe { device.destroy_image(raw, None) };
            return Err(format!("allocating image {name}: {e}"));
        }
    };
    let range = vk::ImageSubresourceRange { aspect_mask: aspect, base_mip_level: 0, level_count: 1, base_array_layer: 0, layer_count: 1 };
    let view_info =
        vk::ImageViewCreateInfo::default().image(raw).view_type(vk::ImageViewType::TYPE_2D).format(format).subresource_range(range);
    // SAFETY: the allocation satisfies the image's requirements; the view covers its only
    // subresource once the memory is bound.
    let view =
        unsafe { device.bind_image_memory(raw, alloc.memory(), alloc.offset()).and_then(|_| device.create_image_view(&view_info, None)) };
    match view {
        Ok(view) => Ok(Img { raw, view, alloc: Some(alloc) }),
        Err(e) => {
            // SAFETY: the image was never used.
            unsafe { device.destroy_image(raw, None) };
            let _ = lock(allocator).free(alloc);
            Err(format!("binding / viewing image {name}: {e:?}"))
        }
    }
}

fn shader_module(device: &ash::Device, spirv: &[u8]) -> Result<vk::ShaderModule, String> {
    let words: Vec<u32> = spirv.chunks_exact(4).map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]])).collect();
    // SAFETY: `words` is SPIR-V compiled and validated by naga in umbrage's build script.
    unsafe { device.create_shader_module(&vk::ShaderModuleCreateInfo::default().code(&words), None) }.map_err(vkerr("vkCreateShaderModule"))
}

/// What differs between the host's two pipelines.
struct PipelineState {
    vs: vk::ShaderModule,
    fs: Option<vk::ShaderModule>,
    color: Option<vk::Format>,
    depth_compare: vk::CompareOp,
    depth_write: bool,
    stencil: Option<vk::StencilOpState>,
    depth_bounds: bool,
}

/// A dynamic-rendering pipeline (depth AND stencil formats), vertex input `vec4 pos` at
/// location 0, two-sided, dynamic viewport and scissor (and depth bounds when used).
fn create_pipeline(
    device: &ash::Device,
    layout: vk::PipelineLayout,
    ds_format: vk::Format,
    s: &PipelineState,
) -> Result<vk::Pipeline, String> {
    let mut stages = vec![vk::PipelineShaderStageCreateInfo::default().stage(vk::ShaderStageFlags::VERTEX).module(s.vs).name(c"main")];
    if let Some(fs) = s.fs {
        stages.push(vk::PipelineShaderStageCreateInfo::default().stage(vk::ShaderStageFlags::FRAGMENT).module(fs).name(c"main"));
    }
    let bindings = [vk::VertexInputBindingDescription { binding: 0, stride: 16, input_rate: vk::VertexInputRate::VERTEX }];
    let attrs = [vk::VertexInputAttributeDescription { location: 0, binding: 0, format: vk::Format::R32G32B32A32_SFLOAT, offset: 0 }];
    let vertex_input =
        vk::PipelineVertexInputStateCreateInfo::default().vertex_binding_descriptions(&bindings).vertex_attribute_descriptions(&attrs);
    let ia = vk::PipelineInputAssemblyStateCreateInfo::default().topology(vk::PrimitiveTopology::TRIANGLE_LIST);
    let vp = vk::PipelineViewportStateCreateInfo::default().viewport_count(1).scissor_count(1);
    let rs = vk::PipelineRasterizationStateCreateInfo::default()
        .polygon_mode(vk::PolygonMode::FILL)
        .cull_mode(vk::CullModeFlags::NONE)
        .front_face(vk::FrontFace::COUNTER_CLOCKWISE)
        .line_width(1.0);
    let ms = vk::PipelineMultisampleStateCreateInfo::default().rasterization_samples(vk::SampleCountFlags::TYPE_1);
    let st = s.stencil.unwrap_or_default();
    let ds = vk::PipelineDepthStencilStateCreateInfo::default()
        .depth_test_enable(true)
        .depth_write_enable(s.depth_write)
        .depth_compare_op(s.depth_compare)
        .depth_bounds_test_enable(s.depth_bounds)
        .min_depth_bounds(0.0)
        .max_depth_bounds(1.0)
        .stencil_test_enable(s.stencil.is_some())
        .front(st)
        .back(st);
    let blend = [vk::PipelineColorBlendAttachmentState::default().color_write_mask(vk::ColorComponentFlags::RGBA)];
    let formats: Vec<vk::Format> = s.color.into_iter().collect();
    let cb = vk::PipelineColorBlendStateCreateInfo::default().attachments(&blend[..formats.len()]);
    let mut dynamic = vec![vk::DynamicState::VIEWPORT, vk::DynamicState::SCISSOR];
    if s.depth_bounds {
        dynamic.push(vk::DynamicState::DEPTH_BOUNDS);
    }
    let dyn_state = vk::PipelineDynamicStateCreateInfo::default().dynamic_states(&dynamic);
    let mut rendering = vk::PipelineRenderingCreateInfo::default()
        .color_attachment_formats(&formats)
        .depth_attachment_format(ds_format)
        .stencil_attachment_format(ds_format);
    let info = vk::GraphicsPipelineCreateInfo::default()
        .stages(&stages)
        .vertex_input_state(&vertex_input)
        .input_assembly_state(&ia)
        .viewport_state(&vp)
        .rasterization_state(&rs)
        .multisample_state(&ms)
        .depth_stencil_state(&ds)
        .color_blend_state(&cb)
        .dynamic_state(&dyn_state)
        .layout(layout)
        .push_next(&mut rendering);
    // SAFETY: every pointer in `info` refers to locals alive for the call.
    unsafe { device.create_graphics_pipelines(vk::PipelineCache::null(), &[info], None) }
        .map(|p| p[0])
        .map_err(|(_, e)| format!("vkCreateGraphicsPipelines failed: {e:?}"))
}

/// An image layout transition (synchronization2) of one image's whole subresource.
fn image_barrier(
    device: &ash::Device,
    cb: vk::CommandBuffer,
    image: vk::Image,
    aspect: vk::ImageAspectFlags,
    layouts: (vk::ImageLayout, vk::ImageLayout),
    src: (vk::PipelineStageFlags2, vk::AccessFlags2),
    dst: (vk::PipelineStageFlags2, vk::AccessFlags2),
) {
    let b = [vk::ImageMemoryBarrier2::default()
        .src_stage_mask(src.0)
        .src_access_mask(src.1)
        .dst_stage_mask(dst.0)
        .dst_access_mask(dst.1)
        .old_layout(layouts.0)
        .new_layout(layouts.1)
        .image(image)
        .subresource_range(vk::ImageSubresourceRange {
            aspect_mask: aspect,
            base_mip_level: 0,
            level_count: 1,
            base_array_layer: 0,
            layer_count: 1,
        })];
    // SAFETY: `cb` is recording outside a rendering instance; the image belongs to this device.
    unsafe { device.cmd_pipeline_barrier2(cb, &vk::DependencyInfo::default().image_memory_barriers(&b)) };
}

/// A global memory barrier (synchronization2).
fn memory_barrier(
    device: &ash::Device,
    cb: vk::CommandBuffer,
    src: (vk::PipelineStageFlags2, vk::AccessFlags2),
    dst: (vk::PipelineStageFlags2, vk::AccessFlags2),
) {
    let b = [vk::MemoryBarrier2::default().src_stage_mask(src.0).src_access_mask(src.1).dst_stage_mask(dst.0).dst_access_mask(dst.1)];
    // SAFETY: `cb` is recording outside a rendering instance.
    unsafe { device.cmd_pipeline_barrier2(cb, &vk::DependencyInfo::default().memory_barriers(&b)) };
}
