//! The Vulkan context: instance (+ validation and a debug messenger when asked), physical
//! device choice, feature probing, logical device, queue, allocator, command pool.
//!
//! Design notes
//! - Every optional feature the shadow algorithm can use is *probed* and enabled only when
//!   present; [`Features`] records what was found, and the renderer picks its code path from
//!   it (and says so in `umbrage info` and the stats JSON).
//! - Validation messages of severity ERROR are collected in `Context::validation_errors`; tests
//!   (which always run with `UMBRAGE_VALIDATION=1`) fail when any was reported.
//! - Teardown order: device idle -> allocator -> pool -> device -> messenger -> instance.

use super::caps::Minimum;
pub use super::caps::{version_string, DeviceInfo, Features};
pub use super::validation::ValidationMode;
use crate::error::{Error, Result};
use ash::vk;
use std::ffi::{c_void, CStr};
use std::sync::{Arc, Mutex};

/// Shared sink for validation messages, filled by the debug messenger (only when validation is on).
#[derive(Default)]
pub struct ValidationLog {
    /// ERROR-severity messages, and WARNING-severity ones that the allowlist
    /// ([`super::validation::ALLOWED_WARNINGS`]) does not name, in the order reported, until
    /// drained by [`Context::take_validation_errors`] or [`Context::check_validation`]: both fail.
    pub errors: Vec<String>,
    /// How many WARNING-severity messages were reported, allowed ones included.
    pub warnings: usize,
    /// How many of those the allowlist names (printed only with `UMBRAGE_VERBOSE`).
    pub allowed: usize,
    /// Each of `errors`' process-wide sequence number: draining a context's errors drains them
    /// from the process's record too.
    seqs: Vec<u64>,
}

impl ValidationLog {
    fn push(&mut self, seq: u64, msg: String) {
        self.errors.push(msg);
        self.seqs.push(seq);
    }

    /// Drains the errors; a context's drained errors leave the process's record as well.
    fn drain(&mut self) -> Vec<String> {
        let seqs = std::mem::take(&mut self.seqs);
        if !seqs.is_empty() {
            // The context's log is held here and the process's taken second, the order the
            // callback never reverses (it holds one at a time): no deadlock, and no drained
            // error left behind in the process's record to fail the run later.
            if let Ok(mut p) = PROCESS_LOG.lock() {
                let keep: Vec<bool> = p.seqs.iter().map(|s| !seqs.contains(s)).collect();
                let mut k = keep.iter();
                p.errors.retain(|_| *k.next().unwrap_or(&true));
                p.seqs.retain(|s| !seqs.contains(s));
            }
        }
        std::mem::take(&mut self.errors)
    }
}

/// The next validation message's process-wide sequence number.
static SEQ: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);

/// Everything validation reported in this process, whichever context it came from: what a
/// command line checks after it has destroyed every device and instance (leaks are reported at
/// `vkDestroyDevice`), see [`process_validation`].
static PROCESS_LOG: Mutex<ValidationLog> = Mutex::new(ValidationLog { errors: Vec::new(), warnings: 0, allowed: 0, seqs: Vec::new() });

/// `Err(Error::Validation)` if validation reported, anywhere in this process so far, an error
/// or a warning the allowlist does not name (drains them). A command line calls it after its
/// last context is dropped, so that objects leaked at teardown fail the run.
pub fn process_validation() -> Result<()> {
    let errors = PROCESS_LOG.lock().map(|mut l| {
        l.seqs.clear();
        std::mem::take(&mut l.errors)
    });
    validation_result(errors.unwrap_or_default())
}

fn validation_result(errors: Vec<String>) -> Result<()> {
    match errors.first() {
        None => Ok(()),
        Some(first) => Err(Error::Validation { count: errors.len(), first: first.clone() }),
    }
}

/// A context's validation log, kept past the context: [`ValidationWatch::finish`] after the
/// context (and everything made from it) is dropped reports what teardown said too, leaked
/// objects included.
#[derive(Clone)]
pub struct ValidationWatch(Arc<Mutex<ValidationLog>>);

impl ValidationWatch {
    /// `Err(Error::Validation)` if the context's validation reported any error, or any warning
    /// the allowlist does not name, that was not drained before (drains them).
    pub fn finish(&self) -> Result<()> {
        let errors = self.0.lock().map(|mut l| l.drain()).unwrap_or_default();
        validation_result(errors)
    }

    /// Warnings reported so far (allowed ones included), and how many of them were allowed.
    pub fn warnings(&self) -> (usize, usize) {
        self.0.lock().map(|l| (l.warnings, l.allowed)).unwrap_or((0, 0))
    }
}

/// umbrage's own Vulkan context: instance, one physical and logical device with a single
/// graphics queue, the memory allocator and a command pool. Everything is destroyed in `Drop`
/// (after `vkDeviceWaitIdle`), so every object created from it must be destroyed before it is
/// dropped.
pub struct Context {
    /// The loaded Vulkan loader; kept alive as long as the instance.
    pub entry: ash::Entry,
    /// The instance (Vulkan 1.3; with `VK_LAYER_KHRONOS_validation` and `VK_EXT_debug_utils`
    /// when [`Context::validation`] is set).
    pub instance: ash::Instance,
    debug: Option<(ash::ext::debug_utils::Instance, vk::DebugUtilsMessengerEXT)>,
    /// Also the debug messenger's user data (`Arc::as_ptr`), alive until the messenger is gone.
    log: Arc<Mutex<ValidationLog>>,
    /// When set, dropping the context panics if validation reported anything not drained by
    /// then, teardown included (objects leaked are reported at `vkDestroyDevice`): what a test
    /// sets, so that a leak fails the test that leaked, wherever the context ended up (a
    /// renderer that owns it included). Off by default; never set on a path a host runs.
    pub panic_on_teardown_validation: bool,
    /// The chosen physical device: the best-ranked Vulkan 1.3 device with a graphics queue
    /// (discrete > integrated > virtual > CPU, ties in enumeration order) among those whose
    /// name contains `UMBRAGE_DEVICE` (case-insensitive) when that is set; `UMBRAGE_DEVICE=#N`
    /// picks the N-th device of `vkEnumeratePhysicalDevices` (1-based) whatever its name.
    pub physical: vk::PhysicalDevice,
    /// The logical device, with `dynamicRendering` and `synchronization2` and the optional
    /// features recorded in [`Context::features`] enabled.
    pub device: ash::Device,
    /// Queue 0 of [`Context::queue_family`]. Not synchronised: submissions from several
    /// threads must be serialised by the caller.
    pub queue: vk::Queue,
    /// Index of the graphics queue family [`Context::queue`] and [`Context::pool`] belong to.
    pub queue_family: u32,
    /// Shared with embedded components ([`crate::pass::ShadowPass`] takes a clone); dropped
    /// before the device in `Drop`, so every clone must be gone by then.
    pub allocator: std::mem::ManuallyDrop<Arc<Mutex<gpu_allocator::vulkan::Allocator>>>,
    /// Command pool of [`Context::queue_family`], created with `RESET_COMMAND_BUFFER`. Like any
    /// Vulkan pool it is externally synchronised: use it from one thread at a time.
    pub pool: vk::CommandPool,
    /// The pipeline cache of every pipeline umbrage makes on this context (its renderer's
    /// `ShadowPass` included): pipelines made twice in one process (a renderer per scene, the
    /// accuracy tables) are compiled once where the driver caches. Loaded from and saved to the
    /// file `UMBRAGE_PIPELINE_CACHE` names, when set (`gpu::cache`).
    pub pipeline_cache: vk::PipelineCache,
    /// The optional capabilities that were probed (and enabled where present).
    pub features: Features,
    /// Names and versions of the chosen device.
    pub info: DeviceInfo,
    /// Depth-stencil format with 8 stencil bits, usable as attachment and transfer source
    /// (optimal tiling): `D32_SFLOAT_S8_UINT` if supported, else `D24_UNORM_S8_UINT`.
    pub depth_format: vk::Format,
    /// The physical device's limits, as reported.
    pub limits: vk::PhysicalDeviceLimits,
    /// Whether the validation layer and debug messenger are active.
    pub validation: bool,
    /// What the layer checks when [`Context::validation`] is on (`UMBRAGE_VALIDATION`'s mode);
    /// `None` when validation is off.
    pub validation_mode: Option<ValidationMode>,
}

/// Whether validation is requested through `UMBRAGE_VALIDATION`: `1`, `true`, `sync`,
/// `nosync`, `gpu` or `best` (any case; see [`ValidationMode`]).
pub fn validation_requested() -> bool {
    ValidationMode::from_env().is_some()
}

fn vkerr(call: &'static str) -> impl Fn(vk::Result) -> Error {
    Error::vk(call)
}

/// The instance layers and extensions to enable: the validation layer and debug utils when
/// `validation`, the caller's `instance_extensions` (an error naming those the driver lacks),
/// and VK_KHR_get_physical_device_properties2 for a Vulkan 1.0 minimum where the loader has it
/// (the last value: whether it has).
fn instance_layers_and_extensions(
    entry: &ash::Entry,
    validation: bool,
    instance_extensions: &[*const std::ffi::c_char],
    minimum: Minimum,
) -> Result<(Vec<*const std::ffi::c_char>, Vec<*const std::ffi::c_char>, bool)> {
    let layer_name = c"VK_LAYER_KHRONOS_validation";
    let mut layers = Vec::new();
    let mut extensions = Vec::new();
    if validation {
        // SAFETY: plain enumeration calls on a loaded entry.
        let available = unsafe { entry.enumerate_instance_layer_properties() }.map_err(vkerr("vkEnumerateInstanceLayerProperties"))?;
        let has = available.iter().any(|l| l.layer_name_as_c_str().map(|n| n == layer_name).unwrap_or(false));
        if !has {
            return Err(Error::NoDevice(
                "UMBRAGE_VALIDATION is set but VK_LAYER_KHRONOS_validation is not installed (apt-get install vulkan-validationlayers)"
                    .into(),
            ));
        }
        layers.push(layer_name.as_ptr());
        extensions.push(ash::ext::debug_utils::NAME.as_ptr());
    }
    extensions.extend_from_slice(instance_extensions);
    // Vulkan 1.0 devices answer the `*2` property and feature queries only through
    // VK_KHR_get_physical_device_properties2 (every loader since 2017 offers it).
    // SAFETY: plain enumeration call on a loaded entry.
    let instance_exts =
        unsafe { entry.enumerate_instance_extension_properties(None) }.map_err(vkerr("vkEnumerateInstanceExtensionProperties"))?;
    // A window's surface extensions the driver lacks: say which, rather than "no driver"
    // (the viewer takes an X11 window through XCB where a driver has no Xlib surface).
    let missing: Vec<String> = instance_extensions
        .iter()
        // SAFETY: the caller passes NUL-terminated extension names (documented).
        .map(|&p| unsafe { CStr::from_ptr(p) })
        .filter(|want| !instance_exts.iter().any(|e| e.extension_name_as_c_str().is_ok_and(|n| n == *want)))
        .map(|n| n.to_string_lossy().into_owned())
        .collect();
    if !missing.is_empty() {
        return Err(Error::Unsupported(format!(
            "the Vulkan driver has no instance extension {}, which this window's surface needs: render offscreen \
             with `umbrage render`",
            missing.join(", ")
        )));
    }
    let gpdp2 = ash::khr::get_physical_device_properties2::NAME;
    let has_gpdp2 = instance_exts.iter().any(|e| e.extension_name_as_c_str().map(|n| n == gpdp2).unwrap_or(false));
    if has_gpdp2 && minimum == Minimum::Vulkan10 {
        extensions.push(gpdp2.as_ptr());
    }
    Ok((layers, extensions, has_gpdp2))
}

/// The `VK_EXT_debug_utils` messenger callback: records ERROR messages in the
/// [`ValidationLog`] (and prints them) and counts WARNING messages.
///
/// # Safety
///
/// Called only by the Vulkan loader: `data` must be null or point at valid callback data for
/// the duration of the call, and `user` must be `Arc::as_ptr` of a live
/// `Arc<Mutex<ValidationLog>>`.
unsafe extern "system" fn debug_callback(
    severity: vk::DebugUtilsMessageSeverityFlagsEXT,
    _types: vk::DebugUtilsMessageTypeFlagsEXT,
    data: *const vk::DebugUtilsMessengerCallbackDataEXT<'_>,
    user: *mut c_void,
) -> vk::Bool32 {
    // SAFETY: the loader passes a valid callback-data pointer for the duration of the call, and
    // `user` is `Arc::as_ptr` of the context's log, alive until the messenger is destroyed.
    let (msg, id, log) = unsafe {
        let text = |p: *const std::ffi::c_char| (!p.is_null()).then(|| CStr::from_ptr(p).to_string_lossy().into_owned());
        let (msg, id) = if data.is_null() { (None, None) } else { (text((*data).p_message), text((*data).p_message_id_name)) };
        (msg.unwrap_or_else(|| String::from("(no message)")), id.unwrap_or_default(), &*(user as *const Mutex<ValidationLog>))
    };
    let error = severity.contains(vk::DebugUtilsMessageSeverityFlagsEXT::ERROR);
    let warning = !error && severity.contains(vk::DebugUtilsMessageSeverityFlagsEXT::WARNING);
    let allowed = warning && super::validation::allowed_warning(&id).is_some();
    if error || (warning && !allowed) {
        eprintln!("[vulkan validation] {}{msg}", if warning { "warning: " } else { "" });
    } else if allowed && std::env::var_os("UMBRAGE_VERBOSE").is_some() {
        eprintln!("[vulkan warning, allowed] {msg}");
    }
    let seq = SEQ.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    for log in [log, &PROCESS_LOG] {
        if let Ok(mut log) = log.lock() {
            log.warnings += usize::from(warning);
            log.allowed += usize::from(allowed);
            if error || (warning && !allowed) {
                log.push(seq, msg.clone());
            }
        }
    }
    vk::FALSE
}

impl Context {
    /// Creates the context. Validation follows `UMBRAGE_VALIDATION`; the device can be chosen
    /// with `UMBRAGE_DEVICE=<substring of its name>`, or `UMBRAGE_DEVICE=#N` (the N-th device
    /// the loader enumerates, 1-based).
    pub fn new() -> Result<Context> {
        Self::with_validation(validation_requested())
    }

    /// Creates the context with validation on or off regardless of `UMBRAGE_VALIDATION`;
    /// `UMBRAGE_DEVICE` still chooses the device.
    ///
    /// Fails with [`Error::NoDevice`] when there is no loader, driver or Vulkan 1.3 device with a
    /// graphics queue, or when validation is asked for but the layer is not installed, and with
    /// [`Error::Unsupported`] when the device lacks `dynamicRendering`, `synchronization2` or a
    /// depth-stencil format with 8 stencil bits.
    pub fn with_validation(validation: bool) -> Result<Context> {
        Self::with_extensions(validation, &[], &[])
    }

    /// [`with_validation`](Self::with_validation), with extra instance and device extensions
    /// (a windowed host's surface and swapchain extensions). An instance extension the driver
    /// lacks, or a device extension the chosen device lacks, is [`Error::Unsupported`] naming
    /// it; the pointers must be NUL-terminated names.
    pub fn with_extensions(
        validation: bool,
        instance_extensions: &[*const std::ffi::c_char],
        device_extensions: &[&CStr],
    ) -> Result<Context> {
        Self::open(validation, instance_extensions, device_extensions, Minimum::Vulkan13)
    }

    /// A context on any Vulkan 1.0+ device (the best-ranked one with a graphics queue, or the
    /// one `UMBRAGE_DEVICE` names), for what needs nothing newer: the conformance suite's
    /// classic render pass with static state, and `umbrage info`. [`Features`] says what the
    /// device has beyond 1.0 (`dynamic_rendering`, `synchronization2`,
    /// `extended_dynamic_state` need Vulkan 1.3); callers must check them before using it.
    pub fn any_version(validation: bool) -> Result<Context> {
        Self::open(validation, &[], &[], Minimum::Vulkan10)
    }

    fn open(
        validation: bool,
        instance_extensions: &[*const std::ffi::c_char],
        device_extensions: &[&CStr],
        minimum: Minimum,
    ) -> Result<Context> {
        // SAFETY: loading the Vulkan loader library; we keep `entry` alive in the context for as
        // long as any object created from it.
        let entry =
            unsafe { ash::Entry::load() }.map_err(|e| Error::NoDevice(format!("cannot load the Vulkan loader (libvulkan.so.1): {e}")))?;

        let (layers, extensions, has_gpdp2) = instance_layers_and_extensions(&entry, validation, instance_extensions, minimum)?;
        let app = vk::ApplicationInfo::default().application_name(c"umbrage").engine_name(c"umbrage").api_version(vk::API_VERSION_1_3);
        // Synchronisation validation on whenever validation is (a missing barrier is invisible
        // on lavapipe and flickers on a real GPU) unless `UMBRAGE_VALIDATION` picks another
        // mode (see `ValidationMode`).
        let mode = ValidationMode::from_env().unwrap_or(ValidationMode::Sync);
        let mut features = vk::ValidationFeaturesEXT::default().enabled_validation_features(mode.features());
        let mut create =
            vk::InstanceCreateInfo::default().application_info(&app).enabled_layer_names(&layers).enabled_extension_names(&extensions);
        if validation && !mode.features().is_empty() {
            create = create.push_next(&mut features);
        }
        // SAFETY: all pointers in `create` refer to locals alive for this call.
        let instance = unsafe { entry.create_instance(&create, None) }
            .map_err(|e| Error::NoDevice(format!("vkCreateInstance failed ({e:?}): no Vulkan driver installed?")))?;

        let log = Arc::new(Mutex::new(ValidationLog::default()));
        let debug = if validation {
            let du = ash::ext::debug_utils::Instance::new(&entry, &instance);
            let info = vk::DebugUtilsMessengerCreateInfoEXT::default()
                .message_severity(vk::DebugUtilsMessageSeverityFlagsEXT::ERROR | vk::DebugUtilsMessageSeverityFlagsEXT::WARNING)
                .message_type(
                    vk::DebugUtilsMessageTypeFlagsEXT::GENERAL
                        | vk::DebugUtilsMessageTypeFlagsEXT::VALIDATION
                        | vk::DebugUtilsMessageTypeFlagsEXT::PERFORMANCE,
                )
                .pfn_user_callback(Some(debug_callback))
                .user_data(Arc::as_ptr(&log) as *mut c_void);
            // SAFETY: the callback and the log (user data) outlive the messenger (both owned by self).
            let m = unsafe { du.create_debug_utils_messenger(&info, None) }.map_err(vkerr("vkCreateDebugUtilsMessengerEXT"))?;
            Some((du, m))
        } else {
            None
        };

        let gpdp2 = (has_gpdp2 && minimum == Minimum::Vulkan10)
            .then(|| ash::khr::get_physical_device_properties2::Instance::new(&entry, &instance));
        match super::probe::open_device(&instance, gpdp2.as_ref(), device_extensions, minimum) {
            Ok(super::probe::OpenedDevice { physical, device, queue_family, features, info, depth_format, limits }) => {
                // SAFETY: the queue family/index were requested at device creation.
                let queue = unsafe { device.get_device_queue(queue_family, 0) };
                let allocator = gpu_allocator::vulkan::Allocator::new(&gpu_allocator::vulkan::AllocatorCreateDesc {
                    instance: instance.clone(),
                    device: device.clone(),
                    physical_device: physical,
                    debug_settings: Default::default(),
                    // Acceleration-structure inputs and storage need device addresses.
                    buffer_device_address: features.ray_query,
                    allocation_sizes: Default::default(),
                })
                .map_err(|source| Error::Allocation { name: "gpu-allocator".into(), size: 0, source })?;
                let pool_info = vk::CommandPoolCreateInfo::default()
                    .queue_family_index(queue_family)
                    .flags(vk::CommandPoolCreateFlags::RESET_COMMAND_BUFFER);
                // SAFETY: valid device and create info.
                let pool = unsafe { device.create_command_pool(&pool_info, None) }.map_err(vkerr("vkCreateCommandPool"))?;
                // SAFETY: a plain query on the physical device the device was made from.
                let uuid = unsafe { instance.get_physical_device_properties(physical) }.pipeline_cache_uuid;
                let pipeline_cache = super::cache::create(&device, &uuid);
                let ctx = Context {
                    entry,
                    instance,
                    debug,
                    log,
                    physical,
                    device,
                    queue,
                    queue_family,
                    allocator: std::mem::ManuallyDrop::new(Arc::new(Mutex::new(allocator))),
                    pool,
                    pipeline_cache,
                    features,
                    info,
                    depth_format,
                    limits,
                    validation,
                    validation_mode: validation.then_some(mode),
                    panic_on_teardown_validation: false,
                };
                if minimum == Minimum::Vulkan13 && ctx.null_hardware() {
                    return Err(Error::Unsupported(format!(
                        "{} is a driver without a GPU (Mesa's RADV with NODEVICE_SELECT=1 and RADV_FORCE_FAMILY): it creates devices \
                         and compiles pipelines but executes nothing, so nothing can be rendered; `umbrage info --pipelines` \
                         creates every pipeline there",
                        ctx.info.name
                    )));
                }
                Ok(ctx)
            }
            Err(e) => {
                // SAFETY: nothing else was created from the instance except the messenger.
                unsafe {
                    if let Some((du, m)) = &debug {
                        du.destroy_debug_utils_messenger(*m, None);
                    }
                    instance.destroy_instance(None);
                }
                Err(e)
            }
        }
    }

    /// Whether the device is a driver's "null hardware" (Mesa RADV's `Null hardware (RADV
    /// NAVI21)` with `NODEVICE_SELECT=1 RADV_FORCE_FAMILY=...`): real device creation and
    /// shader compilation, but no GPU behind it.
    pub fn null_hardware(&self) -> bool {
        self.info.name.starts_with("Null hardware")
    }

    /// The shared validation log: keep a clone to read what validation said during teardown
    /// (leaked objects are reported when the device is destroyed).
    pub fn validation_log(&self) -> Arc<Mutex<ValidationLog>> {
        self.log.clone()
    }

    /// Validation errors reported so far (drains them).
    pub fn take_validation_errors(&self) -> Vec<String> {
        self.log.lock().map(|mut l| l.drain()).unwrap_or_default()
    }

    /// `Err(Error::Validation)` if validation reported any error, or any warning the allowlist
    /// does not name, so far (drains them).
    pub fn check_validation(&self) -> Result<()> {
        validation_result(self.take_validation_errors())
    }

    /// The validation log as a [`ValidationWatch`], to check after this context is dropped
    /// (what teardown reports: leaked objects at `vkDestroyDevice`).
    pub fn watch(&self) -> ValidationWatch {
        ValidationWatch(self.log.clone())
    }

    /// The allocator, locked (a poisoned lock is recovered: the allocator's state is only
    /// changed inside its own calls).
    pub fn allocator(&self) -> std::sync::MutexGuard<'_, gpu_allocator::vulkan::Allocator> {
        lock_allocator(&self.allocator)
    }

    /// Records commands into a fresh primary command buffer, submits it to [`Context::queue`]
    /// and waits for it to finish (a fence, not a device-wide idle), then frees the buffer.
    ///
    /// `record` receives the buffer in the recording state and must leave it recording (no
    /// `vkEndCommandBuffer`); everything it references must stay alive until this returns.
    /// Blocks the calling thread; uses [`Context::pool`] and the queue, so it must not run
    /// concurrently with other users of either.
    pub fn one_shot(&self, record: impl FnOnce(vk::CommandBuffer)) -> Result<()> {
        let info = vk::CommandBufferAllocateInfo::default().command_pool(self.pool).command_buffer_count(1);
        // SAFETY: valid pool; the buffer is freed below after the fence wait.
        let cb = unsafe { self.device.allocate_command_buffers(&info) }.map_err(vkerr("vkAllocateCommandBuffers"))?[0];
        let begin = vk::CommandBufferBeginInfo::default().flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT);
        // SAFETY: `cb` is a new primary buffer in the initial state.
        unsafe { self.device.begin_command_buffer(cb, &begin) }.map_err(vkerr("vkBeginCommandBuffer"))?;
        record(cb);
        // SAFETY: recording state; then submit with a fence and wait, so `cb` is idle before free.
        let result = unsafe {
            self.device.end_command_buffer(cb).map_err(vkerr("vkEndCommandBuffer"))?;
            let fence = self.device.create_fence(&vk::FenceCreateInfo::default(), None).map_err(vkerr("vkCreateFence"))?;
            let cbs = [cb];
            let submit = vk::SubmitInfo::default().command_buffers(&cbs);
            let submitted = match super::fault::inject(super::fault::FaultPoint::Submit) {
                Some(injected) => Err(injected),
                None => self.device.queue_submit(self.queue, &[submit], fence),
            };
            let r = submitted
                .map_err(vkerr("vkQueueSubmit"))
                .and_then(|_| self.device.wait_for_fences(&[fence], true, u64::MAX).map_err(vkerr("vkWaitForFences")));
            self.device.destroy_fence(fence, None);
            self.device.free_command_buffers(self.pool, &cbs);
            r
        };
        result
    }
}

/// Locks a shared allocator, recovering a poisoned lock.
pub fn lock_allocator(a: &Mutex<gpu_allocator::vulkan::Allocator>) -> std::sync::MutexGuard<'_, gpu_allocator::vulkan::Allocator> {
    match a.lock() {
        Ok(g) => g,
        Err(p) => p.into_inner(),
    }
}

/// What the resource helpers ([`super::Buffer`], [`super::Image`], pipelines, descriptor
/// sets) need from a device: umbrage's own [`Context`], or a host engine's device and
/// allocator handed to [`crate::pass::ShadowPass`].
pub trait GpuDevice {
    /// The logical device.
    fn device(&self) -> &ash::Device;
    /// The memory allocator, locked.
    fn allocator(&self) -> std::sync::MutexGuard<'_, gpu_allocator::vulkan::Allocator>;
    /// Whether `synchronization2` is enabled on the device: the barrier helpers record
    /// `vkCmdPipelineBarrier2` when it is and Vulkan 1.0 `vkCmdPipelineBarrier` otherwise.
    fn synchronization2(&self) -> bool {
        true
    }
    /// The pipeline cache every pipeline made through this device goes through
    /// (`VK_NULL_HANDLE`: none).
    fn pipeline_cache(&self) -> vk::PipelineCache {
        vk::PipelineCache::null()
    }
}

impl GpuDevice for Context {
    fn device(&self) -> &ash::Device {
        &self.device
    }
    fn allocator(&self) -> std::sync::MutexGuard<'_, gpu_allocator::vulkan::Allocator> {
        lock_allocator(&self.allocator)
    }
    fn synchronization2(&self) -> bool {
        self.features.synchronization2
    }
    fn pipeline_cache(&self) -> vk::PipelineCache {
        self.pipeline_cache
    }
}

impl Drop for Context {
    fn drop(&mut self) {
        // SAFETY: wait for all work, then destroy children before parents. The allocator must be
        // dropped (freeing its device memory blocks) before the device.
        unsafe {
            // Null hardware runs nothing, and RADV's null winsys has no queue wait (a call
            // through a null pointer).
            if !self.null_hardware() {
                let _ = self.device.device_wait_idle();
            }
            std::mem::ManuallyDrop::drop(&mut self.allocator);
            super::cache::save_and_destroy(&self.device, self.pipeline_cache);
            self.device.destroy_command_pool(self.pool, None);
            self.device.destroy_device(None);
            if let Some((du, m)) = self.debug.take() {
                du.destroy_debug_utils_messenger(m, None);
            }
            self.instance.destroy_instance(None);
        }
        if self.panic_on_teardown_validation && !std::thread::panicking() {
            let errors = self.log.lock().map(|mut l| l.drain()).unwrap_or_default();
            if let Some(first) = errors.first() {
                panic!(
                    "Vulkan validation reported {} message(s) not checked before the context was dropped, teardown \
                     included (leaked objects are reported at vkDestroyDevice); first: {first}",
                    errors.len()
                );
            }
        }
    }
}
