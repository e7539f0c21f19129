//! The smallest complete host of umbrage's [`ShadowPass`]: read this one first.
//!
//! An engine already owns a Vulkan instance, a device, an allocator, a depth-stencil image and
//! command buffers. The shadow pass borrows the device and the allocator and only *records*
//! commands into the engine's command buffers; it submits nothing and owns no image. This file
//! is such an engine, on raw ash, with umbrage built the way an engine depends on it
//! (`default-features = false`: no scene files, no command line, no renderer of its own):
//!
//! 1. Vulkan: an instance (with the validation layer when `UMBRAGE_VALIDATION=1`), a device
//!    and its queue, a gpu-allocator, a depth-stencil image, one command buffer.
//! 2. A scene made in code: a floor (drawn, casts nothing), a box floating above it (drawn,
//!    and the one shadow caster) and a point light above the box.
//! 3. The pass: `ShadowPass::new`, `add_caster`; for the frame `prepare` (the CPU work), then
//!    the recording: the engine's depth pre-pass, `cmd_determine` (the shadow count lands in
//!    the stencil: 0 = lit), and a copy of the stencil into a buffer we read.
//! 4. The check: every floor pixel's stencil against the box's shadow computed analytically
//!    (the box projected from the light onto the floor is a convex polygon), outside a band of
//!    one pixel around every edge. It prints the counts and a small picture.
//!
//! Run: `cargo run --example minimal --no-default-features` (any Vulkan 1.3 driver with
//! dynamicRendering and synchronization2; Mesa's lavapipe will do). The exit status is
//! non-zero on a mismatch, on any validation error, or when anything fails.
//!
//! Errors return early with a message and leave the clean-up to the end of the process; an
//! engine would wrap these handles in types that destroy them. The successful path shows the
//! teardown order at the end of [`run`].

use ash::vk::{self, AccessFlags2 as A, PipelineStageFlags2 as S};
use glam::{DMat4, DVec2, DVec3, DVec4, Mat4, Vec3, Vec3Swizzles};
use gpu_allocator::vulkan::{Allocation, AllocationCreateDesc, AllocationScheme, Allocator, AllocatorCreateDesc};
use gpu_allocator::MemoryLocation;
use std::ffi::c_void;
use std::process::ExitCode;
use std::sync::atomic::{AtomicU32, Ordering};
use std::sync::{Arc, Mutex};
use umbrage::geom::{Light, LightKind, Mesh};
use umbrage::pass::{DepthStencilTarget, PreparedFrame, ShadowPass, ShadowPassDesc, ShadowView};

/// The image's size in pixels.
const WIDTH: u32 = 320;
const HEIGHT: u32 = 240;
/// The camera: where it is, what it looks at, its vertical field of view and near plane.
const EYE: DVec3 = DVec3::new(0.0, 5.0, 7.0);
const LOOK_AT: DVec3 = DVec3::new(0.0, 0.0, 1.0);
const FOV_Y_DEG: f32 = 45.0;
const NEAR: f32 = 0.1;
/// The point light, up and behind the box: its shadow falls towards the camera.
const LIGHT: DVec3 = DVec3::new(-1.5, 6.0, -2.0);
/// The box, axis-aligned (centre and half-extents); the floor is y = 0, |x|, |z| <= FLOOR_HALF.
const BOX_CENTRE: DVec3 = DVec3::new(0.0, 1.0, 0.0);
const BOX_HALF: DVec3 = DVec3::new(0.6, 0.5, 0.4);
const FLOOR_HALF: f64 = 20.0;
/// The check must see at least this many shadowed floor pixels (an empty stencil fails).
const MIN_SHADOWED: u64 = 1000;

/// The depth pre-pass's vertex shader, in WGSL, compiled to SPIR-V by naga when the example
/// starts. An engine has its own shader pipeline; naga (a dev-dependency, the version
/// umbrage's build script uses) keeps this example free of build steps and binary blobs, with
/// the shader readable right here. It computes `mvp * position` with `w = 1` positions, as the
/// pass's own volume shader does, so the pre-pass's depths and the volumes' agree.
const PREPASS_WGSL: &str = "
var<immediate> mvp: mat4x4<f32>;

@vertex
fn main(@location(0) position: vec4<f32>) -> @builtin(position) vec4<f32> {
    return mvp * position;
}";

/// The box's 12 triangles over corners `i` = (x, y, z) bits, counter-clockwise from outside.
const BOX_TRIANGLES: [[u32; 3]; 12] =
    [[0, 6, 2], [0, 4, 6], [1, 7, 5], [1, 3, 7], [0, 5, 4], [0, 1, 5], [2, 7, 3], [2, 6, 7], [0, 3, 1], [0, 2, 3], [4, 7, 6], [4, 5, 7]];

/// A buffer and its memory.
type Buffer = (vk::Buffer, Allocation);

/// Validation errors seen by [`on_validation`] (the layer calls it from any thread).
static VALIDATION_ERRORS: AtomicU32 = AtomicU32::new(0);

fn main() -> ExitCode {
    if let Err(e) = run() {
        eprintln!("minimal: FAILED: {e}");
        return ExitCode::FAILURE;
    }
    println!("minimal: the stencil matches the analytic shadow");
    ExitCode::SUCCESS
}

/// Sets everything up, renders the one frame, tears everything down and checks the stencil.
/// Errors: a failed step, a mismatch, validation errors; messages starting with "no Vulkan"
/// when there is no loader, driver or suitable device.
pub fn run() -> Result<(), String> {
    // ---- 1. Vulkan: instance, device, queue, allocator --------------------------------------
    let gpu = create_device()?;
    let (instance, physical, device, allocator, ds_format) = (&gpu.instance, gpu.physical, &gpu.device, &gpu.allocator, gpu.ds_format);

    // ---- 2. The scene, and the pass -----------------------------------------------------------
    let floor: Vec<Vec3> =
        [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)].map(|(x, z)| Vec3::new(x, 0.0, z) * FLOOR_HALF as f32).to_vec();
    let box_corners: Vec<Vec3> = (0..8).map(|i| (corner_sign(i) * BOX_HALF).as_vec3()).collect();
    let box_model = DMat4::from_translation(BOX_CENTRE); // object -> world, in f64

    let desc = ShadowPassDesc { depth_stencil_format: ds_format, frames_in_flight: 1, ..Default::default() };
    let mut pass = ShadowPass::new(instance, physical, device, allocator.clone(), &desc).map_err(|e| format!("ShadowPass::new: {e}"))?;
    // A caster is any closed (or open) triangle mesh; the pass keeps its own GPU copy.
    let box_mesh = Mesh::new(box_corners.clone(), BOX_TRIANGLES.to_vec());
    pass.add_caster("box", &box_mesh, box_model).map_err(|e| format!("add_caster: {e}"))?;

    // The engine's own copy of the geometry for its depth pre-pass: floor and box, vec4 (w = 1).
    let vertices: Vec<[f32; 4]> = floor.iter().chain(&box_corners).map(|p| p.extend(1.0).to_array()).collect();
    let indices: Vec<u32> = [0, 1, 2, 0, 2, 3].into_iter().chain(BOX_TRIANGLES.iter().flatten().copied()).collect();
    let vertex_buffer = buffer(device, allocator, bytemuck::cast_slice(&vertices), vk::BufferUsageFlags::VERTEX_BUFFER)?;
    let index_buffer = buffer(device, allocator, bytemuck::cast_slice(&indices), vk::BufferUsageFlags::INDEX_BUFFER)?;
    // Where the stencil is copied to, one byte a pixel (TRANSFER_DST: read back, not uploaded).
    let pixels = (WIDTH * HEIGHT) as usize;
    let readback = buffer(device, allocator, &vec![0; pixels], vk::BufferUsageFlags::TRANSFER_DST)?;

    // The depth-stencil image: the pre-pass writes its depth, the pass its stencil.
    let extent = vk::Extent2D { width: WIDTH, height: HEIGHT };
    let image_info = vk::ImageCreateInfo::default().image_type(vk::ImageType::TYPE_2D).format(ds_format).extent(extent.into());
    let usage = vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT | vk::ImageUsageFlags::TRANSFER_SRC; // TRANSFER_SRC: the stencil copy
    let image_info = image_info.mip_levels(1).array_layers(1).samples(vk::SampleCountFlags::TYPE_1).usage(usage);
    let both_aspects = vk::ImageAspectFlags::DEPTH | vk::ImageAspectFlags::STENCIL;
    let range = vk::ImageSubresourceRange::default().aspect_mask(both_aspects).level_count(1).layer_count(1);
    // SAFETY: valid create infos on a valid device; the memory is bound before the view is made.
    let (depth_image, depth_memory, depth_view) = unsafe {
        let image = device.create_image(&image_info, None).map_err(vk_err("vkCreateImage"))?;
        let requirements = device.get_image_memory_requirements(image);
        let memory = allocate(allocator, requirements, MemoryLocation::GpuOnly)?;
        device.bind_image_memory(image, memory.memory(), memory.offset()).map_err(vk_err("vkBindImageMemory"))?;
        let view_info = vk::ImageViewCreateInfo::default().image(image).view_type(vk::ImageViewType::TYPE_2D).format(ds_format);
        let view = device.create_image_view(&view_info.subresource_range(range), None).map_err(vk_err("vkCreateImageView"))?;
        (image, memory, view)
    };

    // The engine's depth pre-pass pipeline (depth only) and its layout (an `mvp` push constant).
    let (layout, pipeline) = prepass_pipeline(device, ds_format)?;

    // ---- 3. One frame ---------------------------------------------------------------------------
    // The camera, as the pass wants it: the eye in f64, a view without translation (world
    // directions -> view space) and Vulkan's projection with the far plane at infinity (depth
    // 0 at the near plane, 1 at infinity; y down in the framebuffer). Z-fail volumes reach
    // infinity, so this is `DepthMode::Infinite`, the default.
    let view = glam::camera::rh::view::look_at_mat4(Vec3::ZERO, (LOOK_AT - EYE).as_vec3(), Vec3::Y);
    let proj = glam::camera::rh::proj::vulkan::perspective_infinite(FOV_Y_DEG.to_radians(), WIDTH as f32 / HEIGHT as f32, NEAR);
    // Every draw uses `proj * view * (world - eye)`, composed in f64 and rounded once, exactly as
    // the pass composes its volumes' matrices: the pre-pass depths and the volumes then agree.
    let mvp = |model: DMat4| (proj.as_dmat4() * view.as_dmat4() * DMat4::from_translation(-EYE) * model).as_mat4();
    let light = Light {
        kind: LightKind::Point,
        position: LIGHT.as_vec3(),
        direction: Vec3::NEG_Y, // unused by a point light
        color: Vec3::ONE,
        intensity: 1.0,
        radius: None, // no attenuation range: the light reaches everything
        cone_deg: 180.0,
        area: None,
    };
    // The CPU work: per light, which casters matter, their case (z-pass, z-fail, ...), their
    // silhouettes and index streams, written into ring slot 0.
    let shadow_view = ShadowView { eye: EYE, view, proj, width: WIDTH, height: HEIGHT };
    let frame = pass.prepare(0, &shadow_view, std::slice::from_ref(&light)).map_err(|e| format!("prepare: {e}"))?;
    for c in &frame.lights[0].stats.casters {
        println!("minimal: {}: {}, {} silhouette edges, {} shadow triangles", c.name, c.case, c.silhouette_edges, c.triangles.total());
    }

    let geometry = (box_model, &vertex_buffer, &index_buffer);
    record_frame(&gpu, &pass, &frame, mvp, geometry, (depth_image, depth_view, extent, range), (layout, pipeline, &readback))?;
    let stencil = readback.1.mapped_slice().ok_or("the readback buffer is not mapped")?[..pixels].to_vec();

    // ---- 4. Teardown: the GPU is idle; children before parents, the pass before the device --
    let Gpu { entry: _entry, instance, debug_utils, messenger, device, allocator, pool, fence, .. } = gpu;
    // SAFETY: the fence was waited, so no command uses any of these objects; each is destroyed
    // once; the pass goes while the device and the allocator are alive (its drop contract).
    unsafe {
        drop(pass);
        device.destroy_command_pool(pool, None); // frees `cb` too
        device.destroy_fence(fence, None);
        device.destroy_pipeline(pipeline, None);
        device.destroy_pipeline_layout(layout, None);
        device.destroy_image_view(depth_view, None);
        device.destroy_image(depth_image, None);
        let mut guard = allocator.lock().map_err(|_| "allocator lock poisoned")?;
        for (buffer, memory) in [vertex_buffer, index_buffer, readback] {
            device.destroy_buffer(buffer, None);
            guard.free(memory).map_err(|e| format!("free: {e}"))?;
        }
        guard.free(depth_memory).map_err(|e| format!("free: {e}"))?;
        drop(guard);
        // The last reference (the pass's clone went with the pass): frees the memory blocks.
        drop(allocator);
        device.destroy_device(None);
        if let Some(m) = messenger {
            debug_utils.destroy_debug_utils_messenger(m, None);
        }
        instance.destroy_instance(None);
    }

    // ---- 5. The check --------------------------------------------------------------------------
    check(&stencil, proj.as_dmat4() * view.as_dmat4())?;
    match VALIDATION_ERRORS.load(Ordering::SeqCst) {
        0 => Ok(()),
        n => Err(format!("{n} validation error(s) or warning(s)")),
    }
}

/// Step 1's objects: the instance and its messenger, the device, its queue and allocator, and
/// the frame's command pool, fence and command buffer.
struct Gpu {
    entry: ash::Entry,
    instance: ash::Instance,
    debug_utils: ash::ext::debug_utils::Instance,
    messenger: Option<vk::DebugUtilsMessengerEXT>,
    physical: vk::PhysicalDevice,
    ds_format: vk::Format,
    device: ash::Device,
    queue: vk::Queue,
    allocator: Arc<Mutex<Allocator>>,
    pool: vk::CommandPool,
    fence: vk::Fence,
    cb: vk::CommandBuffer,
}

/// Step 1: the instance, the first Vulkan 1.3 device with a graphics queue, its queue and
/// allocator, one command buffer and its fence.
fn create_device() -> Result<Gpu, String> {
    // SAFETY: loads the system's Vulkan loader; `entry` outlives every object made from it.
    let entry = unsafe { ash::Entry::load() }.map_err(|e| format!("no Vulkan loader: {e}"))?;
    let validation = std::env::var("UMBRAGE_VALIDATION").is_ok_and(|v| v == "1");
    let layers: Vec<_> = validation.then_some(c"VK_LAYER_KHRONOS_validation".as_ptr()).into_iter().collect();
    let extensions: Vec<_> = validation.then_some(ash::ext::debug_utils::NAME.as_ptr()).into_iter().collect();
    let app = vk::ApplicationInfo::default().application_name(c"umbrage-minimal").api_version(vk::API_VERSION_1_3);
    // Synchronisation validation checks the barriers we put around the pass's commands.
    let checks = [vk::ValidationFeatureEnableEXT::SYNCHRONIZATION_VALIDATION];
    let mut features = vk::ValidationFeaturesEXT::default().enabled_validation_features(&checks);
    let mut instance_info =
        vk::InstanceCreateInfo::default().application_info(&app).enabled_layer_names(&layers).enabled_extension_names(&extensions);
    if validation {
        instance_info = instance_info.push_next(&mut features);
    }
    // SAFETY: every pointer in `instance_info` refers to locals alive for the call.
    let instance = unsafe { entry.create_instance(&instance_info, None) }
        .map_err(|e| format!("no Vulkan driver (or no validation layer): vkCreateInstance failed ({e:?})"))?;
    let debug_utils = ash::ext::debug_utils::Instance::new(&entry, &instance);
    // The messenger: every validation message goes to `on_validation`, which counts the errors.
    let messenger_info = vk::DebugUtilsMessengerCreateInfoEXT::default()
        .message_severity(vk::DebugUtilsMessageSeverityFlagsEXT::WARNING | vk::DebugUtilsMessageSeverityFlagsEXT::ERROR)
        .message_type(vk::DebugUtilsMessageTypeFlagsEXT::GENERAL | vk::DebugUtilsMessageTypeFlagsEXT::VALIDATION)
        .pfn_user_callback(Some(on_validation));
    // SAFETY: the callback is a plain function with no user data.
    let messenger = validation.then(|| unsafe { debug_utils.create_debug_utils_messenger(&messenger_info, None) });
    let messenger = messenger.transpose().map_err(vk_err("vkCreateDebugUtilsMessengerEXT"))?;

    // The first device with Vulkan 1.3 and a graphics queue, and its depth-stencil format.
    // SAFETY: queries on a valid instance and the physical devices it returns.
    let (physical, family, name) = unsafe {
        let devices = instance.enumerate_physical_devices().map_err(vk_err("vkEnumeratePhysicalDevices"))?;
        devices.into_iter().find_map(|pd| {
            let props = instance.get_physical_device_properties(pd);
            let families = instance.get_physical_device_queue_family_properties(pd);
            let family = families.iter().position(|f| f.queue_flags.contains(vk::QueueFlags::GRAPHICS))?;
            let name = props.device_name_as_c_str().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
            (props.api_version >= vk::API_VERSION_1_3).then_some((pd, family as u32, name))
        })
    }
    .ok_or("no Vulkan 1.3 device with a graphics queue")?;
    let ds_usage = vk::FormatFeatureFlags::DEPTH_STENCIL_ATTACHMENT | vk::FormatFeatureFlags::TRANSFER_SRC;
    let ds_format = [vk::Format::D32_SFLOAT_S8_UINT, vk::Format::D24_UNORM_S8_UINT]
        .into_iter()
        // SAFETY: a format query on a valid physical device.
        .find(|&f| unsafe { instance.get_physical_device_format_properties(physical, f) }.optimal_tiling_features.contains(ds_usage))
        .ok_or("no depth-stencil format with 8 stencil bits")?;
    println!("minimal: {name}, {ds_format:?}, validation {}", if validation { "on" } else { "off" });

    // The pass records vkCmdBeginRendering and vkCmdPipelineBarrier2: dynamicRendering and
    // synchronization2, both core in Vulkan 1.3, must be enabled. (Optional features such as
    // depthBounds go in `ShadowPassDesc::features` when the engine enables them.)
    let mut vulkan13 = vk::PhysicalDeviceVulkan13Features::default().dynamic_rendering(true).synchronization2(true);
    let queues = [vk::DeviceQueueCreateInfo::default().queue_family_index(family).queue_priorities(&[1.0])];
    let device_info = vk::DeviceCreateInfo::default().queue_create_infos(&queues).push_next(&mut vulkan13);
    // SAFETY: every pointer in `device_info` refers to locals alive for the call.
    let device = unsafe { instance.create_device(physical, &device_info, None) }.map_err(vk_err("vkCreateDevice"))?;
    // SAFETY: queue 0 of `family` was requested above.
    let queue = unsafe { device.get_device_queue(family, 0) };
    let allocator = Allocator::new(&AllocatorCreateDesc {
        instance: instance.clone(),
        device: device.clone(),
        physical_device: physical,
        debug_settings: Default::default(),
        buffer_device_address: false,
        allocation_sizes: Default::default(),
    })
    .map_err(|e| format!("gpu-allocator: {e}"))?;
    // Shared with the pass, which allocates its caster buffers and index streams from it.
    let allocator = Arc::new(Mutex::new(allocator));

    // SAFETY: creation on a valid device; destroyed at the end.
    let (pool, fence) = unsafe {
        let pool_info = vk::CommandPoolCreateInfo::default().queue_family_index(family);
        let pool = device.create_command_pool(&pool_info, None).map_err(vk_err("vkCreateCommandPool"))?;
        (pool, device.create_fence(&vk::FenceCreateInfo::default(), None).map_err(vk_err("vkCreateFence"))?)
    };
    let cb_info = vk::CommandBufferAllocateInfo::default().command_pool(pool).command_buffer_count(1);
    // SAFETY: one primary buffer from the pool just made.
    let cb = unsafe { device.allocate_command_buffers(&cb_info) }.map_err(vk_err("vkAllocateCommandBuffers"))?[0];
    Ok(Gpu { entry, instance, debug_utils, messenger, physical, ds_format, device, queue, allocator, pool, fence, cb })
}

/// Step 3's commands: the engine's depth pre-pass (`geometry`: the box's model matrix, the
/// vertex and index buffers), `cmd_determine` on the depth-stencil image, the stencil's copy
/// into `readback`; submitted and waited for.
fn record_frame(
    gpu: &Gpu,
    pass: &ShadowPass,
    frame: &PreparedFrame,
    mvp: impl Fn(DMat4) -> Mat4,
    (box_model, vertex_buffer, index_buffer): (DMat4, &Buffer, &Buffer),
    (depth_image, depth_view, extent, range): (vk::Image, vk::ImageView, vk::Extent2D, vk::ImageSubresourceRange),
    (layout, pipeline, readback): (vk::PipelineLayout, vk::Pipeline, &Buffer),
) -> Result<(), String> {
    let (device, queue, fence, cb) = (&gpu.device, gpu.queue, gpu.fence, gpu.cb);
    // Barriers (synchronization2) on the depth-stencil image: both aspects, a layout change
    // `old -> new` (or none), after `src` (stages, accesses) and before `dst`.
    let (tests, attachment) = (S::EARLY_FRAGMENT_TESTS | S::LATE_FRAGMENT_TESTS, vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL);
    let ds_rw = A::DEPTH_STENCIL_ATTACHMENT_READ | A::DEPTH_STENCIL_ATTACHMENT_WRITE;
    let barrier = |old, new, src: (S, A), dst: (S, A)| {
        let b =
            vk::ImageMemoryBarrier2::default().src_stage_mask(src.0).src_access_mask(src.1).dst_stage_mask(dst.0).dst_access_mask(dst.1);
        let b = [b.old_layout(old).new_layout(new).image(depth_image).subresource_range(range)];
        // SAFETY: recorded into `cb` below, outside rendering instances, the image in `old`.
        unsafe { device.cmd_pipeline_barrier2(cb, &vk::DependencyInfo::default().image_memory_barriers(&b)) };
    };
    let depth_stencil = vk::RenderingAttachmentInfo::default()
        .image_view(depth_view)
        .image_layout(attachment)
        .load_op(vk::AttachmentLoadOp::CLEAR) // depth 1.0 and stencil 0 (the pass needs 0 outside the light's scissor)
        .store_op(vk::AttachmentStoreOp::STORE)
        .clear_value(vk::ClearValue { depth_stencil: vk::ClearDepthStencilValue { depth: 1.0, stencil: 0 } });
    let rendering = vk::RenderingInfo::default().render_area(extent.into()).layer_count(1);
    let rendering = rendering.depth_attachment(&depth_stencil).stencil_attachment(&depth_stencil);
    let copy = vk::BufferImageCopy::default()
        .image_subresource(vk::ImageSubresourceLayers::default().aspect_mask(vk::ImageAspectFlags::STENCIL).layer_count(1))
        .image_extent(extent.into());
    // SAFETY: every handle recorded belongs to `device` and lives until after the fence wait;
    // each barrier names the layout the previous one left; `frame` was prepared for slot 0,
    // which is not prepared again.
    unsafe {
        let begin = vk::CommandBufferBeginInfo::default().flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT);
        device.begin_command_buffer(cb, &begin).map_err(vk_err("vkBeginCommandBuffer"))?;
        // The depth-stencil image into the attachment layout (its old contents discarded).
        barrier(vk::ImageLayout::UNDEFINED, attachment, (S::NONE, A::NONE), (tests, ds_rw));
        // New casters' vertex copies (and compute silhouettes, where used): outside rendering.
        pass.cmd_before_rendering(cb, frame).map_err(|e| format!("cmd_before_rendering: {e}"))?;

        // The engine's depth pre-pass: floor (indices 0..6) and box (6..42, vertices from 4).
        device.cmd_begin_rendering(cb, &rendering);
        device.cmd_bind_pipeline(cb, vk::PipelineBindPoint::GRAPHICS, pipeline);
        device.cmd_bind_vertex_buffers(cb, 0, &[vertex_buffer.0], &[0]);
        device.cmd_bind_index_buffer(cb, index_buffer.0, 0, vk::IndexType::UINT32);
        for (model, first_index, count, vertex_offset) in [(DMat4::IDENTITY, 0, 6, 0), (box_model, 6, 36, 4)] {
            let m = mvp(model).to_cols_array();
            device.cmd_push_constants(cb, layout, vk::ShaderStageFlags::VERTEX, 0, bytemuck::bytes_of(&m));
            device.cmd_draw_indexed(cb, count, 1, first_index, vertex_offset, 0);
        }
        device.cmd_end_rendering(cb);
        // The contract: the pre-pass's depth writes visible to the pass's depth tests.
        barrier(attachment, attachment, (S::LATE_FRAGMENT_TESTS, A::DEPTH_STENCIL_ATTACHMENT_WRITE), (tests, ds_rw));

        // The shadow determination of light 0: afterwards the stencil holds, per pixel, the
        // number of shadow volumes around the visible point (0 = lit).
        // The target is declared in DEPTH_STENCIL_ATTACHMENT_OPTIMAL, and left there.
        let target = DepthStencilTarget::new(depth_image, depth_view, extent);
        pass.cmd_determine(cb, frame, 0, &target).map_err(|e| format!("cmd_determine: {e}"))?;

        // An engine's lighting pass would now test `stencil == 0` (`lit_stencil_state`); we
        // copy the stencil out and make the copy visible to the host.
        let transfer_src = vk::ImageLayout::TRANSFER_SRC_OPTIMAL;
        barrier(attachment, transfer_src, (tests, ds_rw), (S::COPY, A::TRANSFER_READ));
        device.cmd_copy_image_to_buffer(cb, depth_image, transfer_src, readback.0, &[copy]);
        let host = vk::MemoryBarrier2::default().src_stage_mask(S::COPY).src_access_mask(A::TRANSFER_WRITE);
        let host = [host.dst_stage_mask(S::HOST).dst_access_mask(A::HOST_READ)];
        device.cmd_pipeline_barrier2(cb, &vk::DependencyInfo::default().memory_barriers(&host));
        device.end_command_buffer(cb).map_err(vk_err("vkEndCommandBuffer"))?;

        let cbs = [vk::CommandBufferSubmitInfo::default().command_buffer(cb)];
        device.queue_submit2(queue, &[vk::SubmitInfo2::default().command_buffer_infos(&cbs)], fence).map_err(vk_err("vkQueueSubmit2"))?;
        device.wait_for_fences(&[fence], true, u64::MAX).map_err(vk_err("vkWaitForFences"))?;
    }
    Ok(())
}

/// What a pixel centre's camera ray sees, computed from the scene's definition alone.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Sees {
    Sky,
    Box,
    LitFloor,
    ShadowedFloor,
}

/// Compares the stencil (non-zero = shadowed) with the analytic shadow on every floor pixel
/// whose 8 neighbours see the same thing: that leaves out a band of 1 pixel around the
/// shadow's edge, the box's outline and the image border. Prints a picture and the counts.
fn check(stencil: &[u8], view_proj: DMat4) -> Result<(), String> {
    let polygon = shadow_polygon();
    // A pixel centre back to a direction from the eye (the matrices are eye-relative).
    let inverse = view_proj.inverse();
    let (w, h) = (WIDTH as usize, HEIGHT as usize);
    let sees: Vec<Sees> = (0..w * h)
        .map(|i| {
            let ndc = DVec2::new(((i % w) as f64 + 0.5) / w as f64, ((i / w) as f64 + 0.5) / h as f64) * 2.0 - 1.0;
            let p = inverse * DVec4::new(ndc.x, ndc.y, 0.5, 1.0);
            let dir = p.truncate() / p.w;
            let t_floor = if dir.y < 0.0 { -EYE.y / dir.y } else { f64::INFINITY };
            let hit = EYE + dir * t_floor;
            if ray_box(EYE, dir).is_some_and(|t| t < t_floor) {
                Sees::Box
            } else if !t_floor.is_finite() || hit.x.abs() > FLOOR_HALF || hit.z.abs() > FLOOR_HALF {
                Sees::Sky
            } else if inside(&polygon, hit.xz()) {
                Sees::ShadowedFloor
            } else {
                Sees::LitFloor
            }
        })
        .collect();
    let (mut compared, mut shadowed, mut mismatches) = (0u64, 0u64, 0u64);
    for (i, &s) in sees.iter().enumerate() {
        let (x, y) = (i % w, i / w);
        let interior = x > 0 && y > 0 && x + 1 < w && y + 1 < h;
        let uniform = interior && (y - 1..=y + 1).all(|v| (x - 1..=x + 1).all(|u| sees[v * w + u] == s));
        if uniform && matches!(s, Sees::LitFloor | Sees::ShadowedFloor) {
            let expected = s == Sees::ShadowedFloor;
            (compared, shadowed) = (compared + 1, shadowed + expected as u64);
            if expected != (stencil[i] != 0) && mismatches < 5 {
                eprintln!("minimal: pixel ({x}, {y}): stencil {}, expected {}", stencil[i], if expected { "shadow" } else { "lit" });
            }
            mismatches += (expected != (stencil[i] != 0)) as u64;
        }
    }
    // One character per 8 x 16 pixels: '#' stencil non-zero, '.' zero, 'o' the box.
    let glyph = |i: usize| match sees[i] {
        Sees::Box => 'o',
        Sees::Sky => ' ',
        _ if stencil[i] != 0 => '#',
        _ => '.',
    };
    for y in (8..h).step_by(16) {
        println!("    {}", (4..w).step_by(8).map(|x| glyph(y * w + x)).collect::<String>());
    }
    println!(
        "minimal: {compared} floor pixels compared (the shadow: a {}-gon), {shadowed} shadowed, {mismatches} mismatched",
        polygon.len()
    );
    match (mismatches, shadowed) {
        (0, MIN_SHADOWED..) => Ok(()),
        _ => Err(format!("{mismatches} pixels disagree with the analytic shadow; {shadowed} shadowed (at least {MIN_SHADOWED} wanted)")),
    }
}

/// The box's shadow on the floor. The ray from the light through a corner `c` meets y = 0 at
/// `L + (c - L) * L.y / (L.y - c.y)`; the shadow of a convex box is the convex hull of its 8
/// corners' points (x, z), built here counter-clockwise (Andrew's monotone chain).
fn shadow_polygon() -> Vec<DVec2> {
    let project = |c: DVec3| LIGHT + (c - LIGHT) * (LIGHT.y / (LIGHT.y - c.y));
    let mut points: Vec<DVec2> = (0..8).map(|i| project(BOX_CENTRE + corner_sign(i) * BOX_HALF).xz()).collect();
    points.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
    let mut hull: Vec<DVec2> = Vec::new();
    // The lower chain left to right, then the upper chain right to left, left turns only.
    for chain in [points.clone(), points.into_iter().rev().collect()] {
        let start = hull.len();
        for p in chain {
            while hull.len() >= start + 2 && (hull[hull.len() - 1] - hull[hull.len() - 2]).perp_dot(p - hull[hull.len() - 2]) <= 0.0 {
                hull.pop();
            }
            hull.push(p);
        }
        hull.pop(); // each chain's last point is the other chain's first
    }
    hull
}

/// Whether `q` is strictly inside a counter-clockwise convex polygon.
fn inside(polygon: &[DVec2], q: DVec2) -> bool {
    polygon.iter().zip(polygon.iter().cycle().skip(1)).all(|(&a, &b)| (b - a).perp_dot(q - a) > 0.0)
}

/// Where the ray `origin + t * dir` (t > 0) enters the box, if it does (the slab test).
fn ray_box(origin: DVec3, dir: DVec3) -> Option<f64> {
    let (t0, t1) = ((BOX_CENTRE - BOX_HALF - origin) / dir, (BOX_CENTRE + BOX_HALF - origin) / dir);
    let (enter, exit) = (t0.min(t1).max_element(), t0.max(t1).min_element());
    (enter <= exit && exit > 0.0).then_some(enter)
}

/// Corner `i` of the box as a sign per axis: x from bit 0, y from bit 1, z from bit 2.
fn corner_sign(i: u32) -> DVec3 {
    DVec3::from_array([0, 1, 2].map(|bit| if i >> bit & 1 == 1 { 1.0 } else { -1.0 }))
}

/// Counts validation errors and warnings (the warnings of umbrage's allowlist,
/// [`umbrage::gpu::validation::ALLOWED_WARNINGS`], excepted) and prints them all.
///
/// # Safety
/// Called by the validation layer only, with callback data valid for the call.
unsafe extern "system" fn on_validation(
    severity: vk::DebugUtilsMessageSeverityFlagsEXT,
    _types: vk::DebugUtilsMessageTypeFlagsEXT,
    data: *const vk::DebugUtilsMessengerCallbackDataEXT<'_>,
    _user: *mut c_void,
) -> vk::Bool32 {
    // SAFETY: the layer passes valid callback data (or null) for the duration of the call.
    let (message, id) = unsafe { data.as_ref().map_or((None, None), |d| (d.message_as_c_str(), d.message_id_name_as_c_str())) };
    let id = id.map(|i| i.to_string_lossy()).unwrap_or_default();
    eprintln!("[validation {severity:?}] {}", message.map(|m| m.to_string_lossy()).unwrap_or_default());
    let allowed =
        !severity.contains(vk::DebugUtilsMessageSeverityFlagsEXT::ERROR) && umbrage::gpu::validation::allowed_warning(&id).is_some();
    VALIDATION_ERRORS.fetch_add(u32::from(!allowed), Ordering::SeqCst);
    vk::FALSE
}

fn vk_err(call: &'static str) -> impl Fn(vk::Result) -> String {
    move |e| format!("{call} failed: {e:?}")
}

/// Memory from the shared allocator (the pass allocates from the same one).
fn allocate(allocator: &Mutex<Allocator>, requirements: vk::MemoryRequirements, location: MemoryLocation) -> Result<Allocation, String> {
    let linear = location != MemoryLocation::GpuOnly; // buffers here are host-visible, the image is not
    let desc =
        AllocationCreateDesc { name: "minimal", requirements, location, linear, allocation_scheme: AllocationScheme::GpuAllocatorManaged };
    allocator.lock().map_err(|_| "allocator lock poisoned")?.allocate(&desc).map_err(|e| format!("gpu-allocator: {e}"))
}

/// A host-visible buffer holding `data` (small meshes: an engine would stage larger ones);
/// for read-back buffers (TRANSFER_DST) memory the host reads fast.
fn buffer(device: &ash::Device, allocator: &Mutex<Allocator>, data: &[u8], usage: vk::BufferUsageFlags) -> Result<Buffer, String> {
    let location = if usage == vk::BufferUsageFlags::TRANSFER_DST { MemoryLocation::GpuToCpu } else { MemoryLocation::CpuToGpu };
    let info = vk::BufferCreateInfo::default().size(data.len() as u64).usage(usage);
    // SAFETY: a valid create info on a valid device; the memory meets the buffer's requirements.
    unsafe {
        let buffer = device.create_buffer(&info, None).map_err(vk_err("vkCreateBuffer"))?;
        let mut memory = allocate(allocator, device.get_buffer_memory_requirements(buffer), location)?;
        device.bind_buffer_memory(buffer, memory.memory(), memory.offset()).map_err(vk_err("vkBindBufferMemory"))?;
        memory.mapped_slice_mut().ok_or("buffer memory is not mapped")?[..data.len()].copy_from_slice(data);
        Ok((buffer, memory))
    }
}

/// The depth pre-pass: [`PREPASS_WGSL`] with `mvp` pushed, vec4 positions, no fragment
/// shader, depth LESS and written, both faces drawn, into both aspects of `ds_format` (dynamic
/// rendering). Returns the pipeline layout (for the push constant) and the pipeline.
fn prepass_pipeline(device: &ash::Device, ds_format: vk::Format) -> Result<(vk::PipelineLayout, vk::Pipeline), String> {
    use naga::{back::spv, valid};
    let module = naga::front::wgsl::parse_str(PREPASS_WGSL).map_err(|e| e.emit_to_string(PREPASS_WGSL))?;
    let info = valid::Validator::new(valid::ValidationFlags::all(), valid::Capabilities::IMMEDIATES).validate(&module);
    let info = info.map_err(|e| e.emit_to_string(PREPASS_WGSL))?;
    let mut options = spv::Options::default();
    // Our projection is already Vulkan's (y down): naga must not flip y as it does for WebGPU.
    options.flags.remove(spv::WriterFlags::ADJUST_COORDINATE_SPACE);
    let spirv = spv::write_vec(&module, &info, &options, None).map_err(|e| format!("SPIR-V: {e}"))?;
    let push = [vk::PushConstantRange { stage_flags: vk::ShaderStageFlags::VERTEX, offset: 0, size: 64 }];
    // SAFETY: naga validated the module and wrote the words; the layout info is well formed.
    let (module, layout) = unsafe {
        let module = device.create_shader_module(&vk::ShaderModuleCreateInfo::default().code(&spirv), None);
        let layout = device.create_pipeline_layout(&vk::PipelineLayoutCreateInfo::default().push_constant_ranges(&push), None);
        (module.map_err(vk_err("vkCreateShaderModule"))?, layout.map_err(vk_err("vkCreatePipelineLayout"))?)
    };
    let stages = [vk::PipelineShaderStageCreateInfo::default().stage(vk::ShaderStageFlags::VERTEX).module(module).name(c"main")];
    let bindings = [vk::VertexInputBindingDescription { binding: 0, stride: 16, input_rate: vk::VertexInputRate::VERTEX }];
    let attributes = [vk::VertexInputAttributeDescription { location: 0, binding: 0, format: vk::Format::R32G32B32A32_SFLOAT, offset: 0 }];
    let vertex_input =
        vk::PipelineVertexInputStateCreateInfo::default().vertex_binding_descriptions(&bindings).vertex_attribute_descriptions(&attributes);
    let input_assembly = vk::PipelineInputAssemblyStateCreateInfo::default().topology(vk::PrimitiveTopology::TRIANGLE_LIST);
    let viewports = [vk::Viewport { x: 0.0, y: 0.0, width: WIDTH as f32, height: HEIGHT as f32, min_depth: 0.0, max_depth: 1.0 }];
    let scissors = [vk::Rect2D { offset: vk::Offset2D::default(), extent: vk::Extent2D { width: WIDTH, height: HEIGHT } }];
    let viewport = vk::PipelineViewportStateCreateInfo::default().viewports(&viewports).scissors(&scissors);
    let raster = vk::PipelineRasterizationStateCreateInfo::default().cull_mode(vk::CullModeFlags::NONE).line_width(1.0);
    let multisample = vk::PipelineMultisampleStateCreateInfo::default().rasterization_samples(vk::SampleCountFlags::TYPE_1);
    let depth = vk::PipelineDepthStencilStateCreateInfo::default().depth_test_enable(true).depth_write_enable(true);
    let depth = depth.depth_compare_op(vk::CompareOp::LESS);
    let mut rendering = vk::PipelineRenderingCreateInfo::default().depth_attachment_format(ds_format).stencil_attachment_format(ds_format);
    let info = vk::GraphicsPipelineCreateInfo::default()
        .stages(&stages)
        .vertex_input_state(&vertex_input)
        .input_assembly_state(&input_assembly)
        .viewport_state(&viewport)
        .rasterization_state(&raster)
        .multisample_state(&multisample)
        .depth_stencil_state(&depth)
        .layout(layout)
        .push_next(&mut rendering);
    // SAFETY: every pointer in `info` refers to locals alive for the call; the module may go
    // once the pipeline exists.
    let pipeline = unsafe {
        let pipeline = device.create_graphics_pipelines(vk::PipelineCache::null(), &[info], None);
        device.destroy_shader_module(module, None);
        pipeline.map_err(|(_, e)| format!("vkCreateGraphicsPipelines failed: {e:?}"))?[0]
    };
    Ok((layout, pipeline))
}
