//! umbrage-capi's job: umbrage's `ShadowPass` for C and C++ engines, as a C ABI (`umbrage.h`,
//! `libumbrage.so`/`.a`, `umbrage.pc`) whose every entry point checks its arguments, catches
//! panics and returns a result code.
//!
//! The header is generated from this crate by cbindgen (`scripts/capi-header-check.sh`) and
//! committed at `include/umbrage/umbrage.h`; `docs/c-api.md` is the integration guide. Every
//! Vulkan function the pass calls comes from the host's `vkGetInstanceProcAddr` (and
//! `vkGetDeviceProcAddr` where given): the library never links or opens the Vulkan loader.
//!
//! # Features
//!
#![doc = document_features::document_features!()]
#![allow(clippy::missing_safety_doc)] // the exported functions' contract is the header's
#![allow(non_snake_case)] // the C structs' field names are the header's (sType, pNext, ...)

mod convert;
mod error;
mod frame;
mod layout;
mod pass;
pub mod types;

use convert::non_null;
use error::CError;
use pass::{with_pass, State};
use std::ffi::c_char;
use std::sync::{Arc, Mutex};
use types::UmbrageResult::*;
use types::*;

/// The ABI version the header declares: `(major << 16) | minor`. A host passes it in
/// `UmbragePassCreateInfo::abiVersion`; while the major is 0 the minor must match exactly.
#[allow(clippy::identity_op)]
pub const UMBRAGE_ABI_VERSION: u32 = (0 << 16) | 1;

const _: () = assert!(UMBRAGE_ABI_VERSION == convert::ABI);

/// The ABI version of this library (compare with the header's `UMBRAGE_ABI_VERSION`).
#[no_mangle]
pub extern "C" fn umbrage_abi_version() -> u32 {
    UMBRAGE_ABI_VERSION
}

/// Copies this thread's last error message (of the last call that failed on this thread)
/// into `buffer` of `capacity` bytes, NUL-terminated and cut if short, and returns the whole
/// message's length without its NUL: call with NULL and 0 to size the buffer.
#[no_mangle]
pub unsafe extern "C" fn umbrage_last_error_message(buffer: *mut c_char, capacity: usize) -> usize {
    // Nothing here can panic, but the boundary holds for every entry point.
    std::panic::catch_unwind(|| {
        // SAFETY: the header's contract: `buffer` is NULL or holds `capacity` bytes.
        unsafe { error::copy_last(buffer, capacity) }
    })
    .unwrap_or(0)
}

/// This thread's last error message, valid until the next failed call on this thread.
#[no_mangle]
pub extern "C" fn umbrage_last_error() -> *const c_char {
    std::panic::catch_unwind(error::last_ptr).unwrap_or(c"panic".as_ptr())
}

/// The stencil state of a lighting pass that lights where the count is zero (compare EQUAL
/// against 0, no writes): for both faces of the host's lighting pipeline.
#[no_mangle]
pub unsafe extern "C" fn umbrage_lit_stencil_state(out: *mut VkStencilOpState) -> UmbrageResult {
    error::boundary(|| {
        let out = non_null(out, "out")? as *mut VkStencilOpState;
        // SAFETY: non-NULL, and the header's contract: a writable VkStencilOpState.
        unsafe { out.write(engine::pass::lit_stencil_state()) };
        Ok(())
    })
}

/// What a pass made with `info` would use on the device `device` describes, or the code its
/// creation would fail with, without a device.
#[no_mangle]
pub unsafe extern "C" fn umbrage_capabilities_for(
    device: *const UmbrageDeviceDescription,
    info: *const UmbragePassCreateInfo,
    out: *mut UmbrageCapabilities,
) -> UmbrageResult {
    error::boundary(|| {
        // SAFETY: non-NULL checked; the header's contract for the rest.
        let device = unsafe { &*non_null(device, "device")? };
        // SAFETY: as above.
        let info = unsafe { &*non_null(info, "info")? };
        let out = non_null(out, "out")? as *mut UmbrageCapabilities;
        // SAFETY: the header's contract for the pointers inside.
        let caps = unsafe { convert::device_caps(device)? };
        // SAFETY: as above.
        let desc = unsafe { convert::desc(info)? };
        let c = engine::pass::ShadowPass::capabilities_for(&caps, &desc)?;
        // SAFETY: non-NULL, writable by the header's contract.
        unsafe { out.write(convert::capabilities_out(&c)) };
        Ok(())
    })
}

/// Creates a pass on the host's device. `*out` is written only on success.
#[no_mangle]
pub unsafe extern "C" fn umbrage_pass_create(
    vulkan: *const UmbrageVulkanDevice,
    info: *const UmbragePassCreateInfo,
    out: *mut UmbragePass,
) -> UmbrageResult {
    error::boundary(|| {
        // SAFETY: non-NULL checked; the header's contract for the rest.
        let vulkan = unsafe { &*non_null(vulkan, "vulkan")? };
        // SAFETY: as above.
        let info = unsafe { &*non_null(info, "info")? };
        let out = non_null(out, "out")? as *mut UmbragePass;
        // SAFETY: the header's contract for the chain.
        let desc = unsafe { convert::desc(info)? };
        if vulkan.pfnGetInstanceProcAddr == 0 {
            return Err(CError::null("UmbrageVulkanDevice::pfnGetInstanceProcAddr"));
        }
        use ash::vk::Handle;
        for (what, raw) in [
            ("UmbrageVulkanDevice::instance", vulkan.instance.as_raw()),
            ("UmbrageVulkanDevice::physicalDevice", vulkan.physicalDevice.as_raw()),
            ("UmbrageVulkanDevice::device", vulkan.device.as_raw()),
        ] {
            if raw == 0 {
                return Err(CError::null(what));
            }
        }
        // SAFETY: a non-zero address the host gave as its vkGetInstanceProcAddr (a function
        // pointer and usize have one size on every target Rust's Vulkan bindings support).
        let gipa: ash::vk::PFN_vkGetInstanceProcAddr =
            unsafe { std::mem::transmute::<usize, ash::vk::PFN_vkGetInstanceProcAddr>(vulkan.pfnGetInstanceProcAddr) };
        let static_fn = ash::StaticFn { get_instance_proc_addr: gipa };
        // SAFETY: the host's live instance and its loader.
        let instance = unsafe { ash::Instance::load(&static_fn, vulkan.instance) };
        let mut instance_fn = instance.fp_v1_0().clone();
        if vulkan.pfnGetDeviceProcAddr != 0 {
            // SAFETY: as above, the host's vkGetDeviceProcAddr.
            instance_fn.get_device_proc_addr =
                unsafe { std::mem::transmute::<usize, ash::vk::PFN_vkGetDeviceProcAddr>(vulkan.pfnGetDeviceProcAddr) };
        }
        // SAFETY: the host's live device, created on `physicalDevice` of `instance`.
        let device = unsafe { ash::Device::load(&instance_fn, vulkan.device) };
        let allocator = gpu_allocator::vulkan::Allocator::new(&gpu_allocator::vulkan::AllocatorCreateDesc {
            instance: instance.clone(),
            device: device.clone(),
            physical_device: vulkan.physicalDevice,
            debug_settings: Default::default(),
            buffer_device_address: desc.features.ray_query,
            allocation_sizes: Default::default(),
        })
        .map_err(|e| CError::new(UMBRAGE_ERROR_ALLOCATION, format!("creating the pass's allocator: {e}")))?;
        let allocator = Arc::new(Mutex::new(allocator));
        let pass = engine::pass::ShadowPass::new(&instance, vulkan.physicalDevice, &device, allocator.clone(), &desc)?;
        let id = pass::next_pass_id();
        let state = State {
            id,
            poisoned: false,
            frames: (0..desc.frames_in_flight).map(|_| None).collect(),
            pass,
            _allocator: allocator,
            casters: Default::default(),
            spheres: Default::default(),
            next_id: 0,
            warning: info.pfnWarning,
            warning_user: info.pWarningUserData,
        };
        pass::register(state);
        // SAFETY: non-NULL, writable by the header's contract.
        unsafe { out.write(id as usize as UmbragePass) };
        Ok(())
    })
}

/// Destroys a pass (NULL: nothing). The host calls it after every command buffer that used
/// the pass has completed, while its device is alive. Works on a poisoned pass; a destroyed
/// or unknown handle is reported, never dereferenced.
#[no_mangle]
pub extern "C" fn umbrage_pass_destroy(pass: UmbragePass) -> UmbrageResult {
    error::boundary(|| {
        if pass.is_null() {
            return Ok(());
        }
        let id = pass as usize as u64;
        match pass::unregister(id) {
            Some(state) => {
                drop(state);
                Ok(())
            }
            None => Err(CError::argument("pass", format!("{id:#x} is not a live pass (destroyed twice, or never created)"))),
        }
    })
}

/// What the pass uses on its device.
#[no_mangle]
pub unsafe extern "C" fn umbrage_pass_get_capabilities(pass: UmbragePass, out: *mut UmbrageCapabilities) -> UmbrageResult {
    with_pass(pass, |s| {
        let out = non_null(out, "out")? as *mut UmbrageCapabilities;
        // SAFETY: non-NULL, writable by the header's contract.
        unsafe { out.write(convert::capabilities_out(&s.pass.capabilities())) };
        Ok(())
    })
}

/// The settings the next prepare uses.
#[no_mangle]
pub unsafe extern "C" fn umbrage_pass_get_settings(pass: UmbragePass, out: *mut UmbragePassSettings) -> UmbrageResult {
    with_pass(pass, |s| {
        let out = non_null(out, "out")? as *mut UmbragePassSettings;
        // SAFETY: non-NULL, writable by the header's contract.
        unsafe { out.write(convert::settings_out(&s.pass.settings())) };
        Ok(())
    })
}

/// Changes the settings from the next frame on; refused (nothing changed) when the device
/// cannot honour them.
#[no_mangle]
pub unsafe extern "C" fn umbrage_pass_set_settings(pass: UmbragePass, settings: *const UmbragePassSettings) -> UmbrageResult {
    with_pass(pass, |s| {
        // SAFETY: non-NULL checked; readable by the header's contract.
        let settings = convert::settings(unsafe { &*non_null(settings, "settings")? })?;
        Ok(s.pass.set_settings(settings)?)
    })
}

/// Creates now the pipelines the first frame of `technique` would create (idempotent).
#[no_mangle]
pub extern "C" fn umbrage_pass_create_pipelines(pass: UmbragePass, technique: UmbrageTechniqueRaw) -> UmbrageResult {
    with_pass(pass, |s| {
        let t = convert::technique(technique, 0)?;
        Ok(s.pass.create_pipelines(t)?)
    })
}

/// The planar technique's receiver plane, 4 doubles `(nx, ny, nz, d)` (n pointing to the light's side).
#[no_mangle]
pub unsafe extern "C" fn umbrage_pass_set_planar_receiver(pass: UmbragePass, plane: *const f64) -> UmbrageResult {
    with_pass(pass, |s| {
        // SAFETY: non-NULL checked; 4 readable doubles by the header's contract.
        let p = unsafe { *non_null(plane, "plane")?.cast::<[f64; 4]>() };
        Ok(s.pass.set_planar_receiver(glam::DVec4::from_array(p))?)
    })
}

/// The ray-query technique's G-buffer.
#[no_mangle]
pub unsafe extern "C" fn umbrage_pass_set_ray_query_inputs(pass: UmbragePass, inputs: *const UmbrageRayQueryInputs) -> UmbrageResult {
    with_pass(pass, |s| {
        // SAFETY: non-NULL checked; readable by the header's contract.
        let i = unsafe { &*non_null(inputs, "inputs")? };
        convert::check_stype(i.sType, UmbrageStructureType::UMBRAGE_STRUCTURE_TYPE_RAY_QUERY_INPUTS, "UmbrageRayQueryInputs")?;
        convert::no_next(i.pNext, "UmbrageRayQueryInputs")?;
        Ok(s.pass.set_ray_query_inputs(engine::pass::RayQueryInputs {
            position: i.position,
            normal: i.normal,
            surface_offset: i.surfaceOffset,
        })?)
    })
}

/// Adds a caster (opaque, or transparent with `transparent`); `*out` gets its id.
#[no_mangle]
pub unsafe extern "C" fn umbrage_pass_add_caster(
    pass: UmbragePass,
    info: *const UmbrageCasterInfo,
    out: *mut UmbrageCasterId,
) -> UmbrageResult {
    with_pass(pass, |s| {
        // SAFETY: non-NULL checked; readable by the header's contract.
        let info = unsafe { &*non_null(info, "info")? };
        let out = non_null(out, "out")? as *mut UmbrageCasterId;
        convert::check_stype(info.sType, UmbrageStructureType::UMBRAGE_STRUCTURE_TYPE_CASTER_INFO, "UmbrageCasterInfo")?;
        convert::no_next(info.pNext, "UmbrageCasterInfo")?;
        // SAFETY: the header's contract for the name and arrays.
        let name = unsafe { convert::name(info.pName, "caster")? };
        // SAFETY: as above.
        let mesh = unsafe { convert::mesh(info)? };
        let t = convert::transform(&info.transform);
        let id = match info.transparent {
            0 => s.pass.add_caster(&name, &mesh, t)?,
            _ => s.pass.add_transparent_caster(&name, &mesh, t, glam::Vec3::from_array(info.transmittance))?,
        };
        let c = s.new_id()?;
        s.casters.insert(c, id);
        // SAFETY: non-NULL, writable by the header's contract.
        unsafe { out.write(c) };
        Ok(())
    })
}

/// Moves a caster (object -> world, column-major `double[16]`) from the next prepare on.
#[no_mangle]
pub unsafe extern "C" fn umbrage_pass_set_caster_transform(
    pass: UmbragePass,
    caster: UmbrageCasterId,
    transform: *const f64,
) -> UmbrageResult {
    with_pass(pass, |s| {
        // SAFETY: non-NULL checked; 16 readable doubles by the header's contract.
        let m = unsafe { *non_null(transform, "transform")?.cast::<[f64; 16]>() };
        let id = s.caster(caster)?;
        Ok(s.pass.set_transform(id, glam::DMat4::from_cols_array(&m))?)
    })
}

/// New object-space positions (`vertexCount` x 3 floats, the same vertices as added) for a
/// deforming caster.
#[no_mangle]
pub unsafe extern "C" fn umbrage_pass_update_caster_positions(
    pass: UmbragePass,
    caster: UmbrageCasterId,
    positions: *const f32,
    vertex_count: u32,
) -> UmbrageResult {
    with_pass(pass, |s| {
        let id = s.caster(caster)?;
        let p = if vertex_count == 0 {
            Vec::new()
        } else {
            // SAFETY: non-NULL checked; `vertex_count * 3` readable floats by the header's contract.
            unsafe { std::slice::from_raw_parts(non_null(positions, "positions")?, vertex_count as usize * 3) }
                .chunks_exact(3)
                .map(|c| glam::Vec3::new(c[0], c[1], c[2]))
                .collect()
        };
        Ok(s.pass.update_positions(id, &p)?)
    })
}

/// Removes a caster; its id is refused from then on.
#[no_mangle]
pub extern "C" fn umbrage_pass_remove_caster(pass: UmbragePass, caster: UmbrageCasterId) -> UmbrageResult {
    with_pass(pass, |s| {
        let id = s.caster(caster)?;
        s.pass.remove_caster(id)?;
        s.casters.remove(&caster);
        Ok(())
    })
}

/// Adds an analytic sphere caster; `*out` gets its id.
#[no_mangle]
pub unsafe extern "C" fn umbrage_pass_add_sphere(
    pass: UmbragePass,
    info: *const UmbrageSphereInfo,
    out: *mut UmbrageSphereId,
) -> UmbrageResult {
    with_pass(pass, |s| {
        // SAFETY: non-NULL checked; readable by the header's contract.
        let info = unsafe { &*non_null(info, "info")? };
        let out = non_null(out, "out")? as *mut UmbrageSphereId;
        convert::check_stype(info.sType, UmbrageStructureType::UMBRAGE_STRUCTURE_TYPE_SPHERE_INFO, "UmbrageSphereInfo")?;
        convert::no_next(info.pNext, "UmbrageSphereInfo")?;
        // SAFETY: the header's contract for the name.
        let name = unsafe { convert::name(info.pName, "sphere")? };
        let sphere = engine::geom::Sphere { center: glam::DVec3::from_array(info.center), radius: info.radius };
        let id = s.pass.add_sphere_caster(&name, sphere, (info.segments != 0).then_some(info.segments))?;
        let c = s.new_id()?;
        s.spheres.insert(c, id);
        // SAFETY: non-NULL, writable by the header's contract.
        unsafe { out.write(c) };
        Ok(())
    })
}

/// Moves or resizes a sphere caster.
#[no_mangle]
pub unsafe extern "C" fn umbrage_pass_set_sphere(
    pass: UmbragePass,
    sphere: UmbrageSphereId,
    center: *const f64,
    radius: f64,
) -> UmbrageResult {
    with_pass(pass, |s| {
        // SAFETY: non-NULL checked; 3 readable doubles by the header's contract.
        let c = unsafe { *non_null(center, "center")?.cast::<[f64; 3]>() };
        let id = s.sphere(sphere)?;
        Ok(s.pass.set_sphere(id, engine::geom::Sphere { center: glam::DVec3::from_array(c), radius })?)
    })
}

/// Removes a sphere caster.
#[no_mangle]
pub extern "C" fn umbrage_pass_remove_sphere(pass: UmbragePass, sphere: UmbrageSphereId) -> UmbrageResult {
    with_pass(pass, |s| {
        let id = s.sphere(sphere)?;
        s.pass.remove_sphere(id)?;
        s.spheres.remove(&sphere);
        Ok(())
    })
}

/// Test builds only (`--features test-panic`): panics inside the boundary, so a test can check
/// that it returns `UMBRAGE_ERROR_PANIC` and poisons the pass.
#[cfg(feature = "test-panic")]
#[no_mangle]
pub extern "C" fn umbrage_test_inject_panic(pass: UmbragePass) -> UmbrageResult {
    with_pass(pass, |_| panic!("injected by umbrage_test_inject_panic"))
}
