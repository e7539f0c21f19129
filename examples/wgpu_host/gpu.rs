//! wgpu's Vulkan backend as the host's device: the instance (validation layer and wgpu's own
//! debug messenger when `UMBRAGE_VALIDATION` is set, its ERRORs counted through a `log`
//! logger), the adapter, and the device opened through wgpu-hal's device-creation callback
//! with what the shadow pass records beyond WebGPU: `dynamicRendering` and `synchronization2`
//! (Vulkan 1.3 core, which wgpu does not enable) and, when present, `VK_EXT_index_type_uint8`.
//! Then the raw handles the pass takes (`ash::Instance`, `VkPhysicalDevice`, `ash::Device`),
//! the Vulkan format wgpu-hal picked for `Depth24PlusStencil8`, and a gpu-allocator on wgpu's
//! device for the pass.

use ash::vk;
use std::future::Future;
use std::pin::pin;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};
use std::task::{Context, Poll, Wake, Waker};
use wgpu::hal::api::Vulkan;

/// The depth-stencil texture format of the host (wgpu-hal maps it to D24S8 or D32S8).
pub const DS_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth24PlusStencil8;

/// Validation ERRORs logged by wgpu-hal's debug messenger (and any other `log::error!`).
static ERRORS: AtomicUsize = AtomicUsize::new(0);
static FIRST_ERROR: Mutex<Option<String>> = Mutex::new(None);

/// Prints wgpu's warnings and errors to stderr and counts the errors.
struct CountingLogger;

impl log::Log for CountingLogger {
    fn enabled(&self, meta: &log::Metadata<'_>) -> bool {
        meta.level() <= log::Level::Warn
    }
    fn log(&self, record: &log::Record<'_>) {
        if !self.enabled(record.metadata()) {
            return;
        }
        let text = format!("{}", record.args());
        eprintln!("[{} {}] {text}", record.level(), record.target());
        // wgpu-hal logs a message's queue, command-buffer and object labels as records of
        // their own, indented: one message, one count.
        if record.level() == log::Level::Error && !text.starts_with('\t') {
            ERRORS.fetch_add(1, Ordering::SeqCst);
            if let Ok(mut first) = FIRST_ERROR.lock() {
                first.get_or_insert(text);
            }
        }
    }
    fn flush(&self) {}
}

static LOGGER: CountingLogger = CountingLogger;

/// `UMBRAGE_VALIDATION=1` (or `true`), as for umbrage's own tools.
pub fn validation_requested() -> bool {
    std::env::var("UMBRAGE_VALIDATION").map(|v| v == "1" || v.eq_ignore_ascii_case("true")).unwrap_or(false)
}

/// The errors logged so far: `Err` with their count and the first one.
pub fn check_errors(when: &str) -> Result<(), String> {
    let n = ERRORS.load(Ordering::SeqCst);
    if n == 0 {
        return Ok(());
    }
    let first = FIRST_ERROR.lock().ok().and_then(|f| f.clone()).unwrap_or_default();
    Err(format!("{n} validation error(s) {when}, first: {first}"))
}

/// A waker that does nothing: wgpu's native futures are ready when first polled.
struct NoWake;

impl Wake for NoWake {
    fn wake(self: Arc<Self>) {}
}

/// Drives one of wgpu's futures to completion. On native backends they are ready at once.
pub fn block_on<F: Future>(f: F) -> F::Output {
    let mut f = pin!(f);
    let waker = Waker::from(Arc::new(NoWake));
    let mut cx = Context::from_waker(&waker);
    loop {
        if let Poll::Ready(v) = f.as_mut().poll(&mut cx) {
            return v;
        }
        std::thread::yield_now();
    }
}

/// wgpu's device and queue and the raw Vulkan handles under them.
pub struct Gpu {
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
    /// The adapter's name and driver.
    pub name: String,
    /// Clones of wgpu's function tables; the handles live as long as `device`.
    pub raw_instance: ash::Instance,
    pub raw_device: ash::Device,
    pub physical: vk::PhysicalDevice,
    /// The Vulkan format of [`DS_FORMAT`] on this device.
    pub ds_format: vk::Format,
    /// `VK_EXT_index_type_uint8` was enabled.
    pub index_type_uint8: bool,
    /// Kept so the instance outlives the device (dropped last, field order).
    _instance: wgpu::Instance,
}

/// The first Vulkan adapter, discrete before integrated before virtual before CPU, or the one
/// whose name contains `UMBRAGE_DEVICE` (case-insensitive), as umbrage's own tools choose.
fn pick_adapter(instance: &wgpu::Instance) -> Result<wgpu::Adapter, String> {
    let wanted = std::env::var("UMBRAGE_DEVICE").ok().map(|s| s.to_lowercase());
    let rank = |t: wgpu::DeviceType| match t {
        wgpu::DeviceType::DiscreteGpu => 0,
        wgpu::DeviceType::IntegratedGpu => 1,
        wgpu::DeviceType::VirtualGpu => 2,
        wgpu::DeviceType::Cpu => 3,
        wgpu::DeviceType::Other => 4,
    };
    let mut adapters: Vec<wgpu::Adapter> = block_on(instance.enumerate_adapters(wgpu::Backends::VULKAN))
        .into_iter()
        .filter(|a| wanted.as_ref().is_none_or(|w| a.get_info().name.to_lowercase().contains(w)))
        .collect();
    adapters.sort_by_key(|a| rank(a.get_info().device_type));
    adapters.into_iter().next().ok_or_else(|| match wanted {
        Some(w) => format!("no Vulkan adapter whose name contains '{w}' (UMBRAGE_DEVICE)"),
        None => "no Vulkan adapter (no Vulkan driver?)".into(),
    })
}

impl Gpu {
    pub fn new() -> Result<Gpu, String> {
        let validation = validation_requested();
        if validation {
            check_validation_layer()?;
        }
        // Errors always; warnings too (printed, not counted).
        if log::set_logger(&LOGGER).is_ok() {
            log::set_max_level(log::LevelFilter::Warn);
        }
        let mut desc = wgpu::InstanceDescriptor::new_without_display_handle();
        desc.backends = wgpu::Backends::VULKAN;
        // VALIDATION: the Khronos layer, with synchronisation validation (wgpu-hal enables it
        // whenever VK_EXT_validation_features is there); DEBUG: VK_EXT_debug_utils and wgpu's
        // messenger, which logs every ERROR through `log`.
        desc.flags = if validation { wgpu::InstanceFlags::VALIDATION | wgpu::InstanceFlags::DEBUG } else { wgpu::InstanceFlags::empty() };
        let instance = wgpu::Instance::new(desc);
        let adapter = pick_adapter(&instance)?;
        let info = adapter.get_info();
        let name = format!("{} ({})", info.name, info.driver_info);

        // SAFETY: the guard is used only inside this block, on the adapter it came from.
        let hal_adapter = unsafe { adapter.as_hal::<Vulkan>() }.ok_or("the adapter is not a Vulkan adapter")?;
        let raw_instance = hal_adapter.shared_instance().raw_instance().clone();
        let physical = hal_adapter.raw_physical_device();
        let ds_format = hal_adapter.texture_format_as_raw(DS_FORMAT);
        // SAFETY: plain queries on a physical device of this instance.
        let props = unsafe { raw_instance.get_physical_device_properties(physical) };
        if props.api_version < vk::API_VERSION_1_3 {
            return Err(format!(
                "{name}: Vulkan {}.{}; the shadow pass records vkCmdBeginRendering and vkCmdPipelineBarrier2 (Vulkan 1.3)",
                vk::api_version_major(props.api_version),
                vk::api_version_minor(props.api_version)
            ));
        }
        let mut dr = vk::PhysicalDeviceDynamicRenderingFeatures::default();
        let mut s2 = vk::PhysicalDeviceSynchronization2Features::default();
        let mut u8f = vk::PhysicalDeviceIndexTypeUint8FeaturesEXT::default();
        let has_u8_ext = {
            // SAFETY: as above.
            let exts = unsafe { raw_instance.enumerate_device_extension_properties(physical) }.unwrap_or_default();
            exts.iter().any(|e| e.extension_name_as_c_str() == Ok(ash::ext::index_type_uint8::NAME))
        };
        {
            let mut f2 = vk::PhysicalDeviceFeatures2::default().push_next(&mut dr).push_next(&mut s2);
            if has_u8_ext {
                f2 = f2.push_next(&mut u8f);
            }
            // SAFETY: the pNext chain points at locals alive for the call.
            unsafe { raw_instance.get_physical_device_features2(physical, &mut f2) };
        }
        if dr.dynamic_rendering != vk::TRUE || s2.synchronization2 != vk::TRUE {
            return Err(format!("{name}: no dynamicRendering / synchronization2, which the shadow pass records"));
        }
        let index_type_uint8 = has_u8_ext && u8f.index_type_uint8 == vk::TRUE;

        let features = wgpu::Features::empty();
        // Four G-buffer targets (RGBA16F + RGBA8 + 2 x RGBA32F = 44 bytes a sample).
        // Large frames: the adapter's texture size and buffer size (readbacks) limits.
        let most = adapter.limits();
        let limits = wgpu::Limits {
            max_color_attachment_bytes_per_sample: 64,
            max_texture_dimension_2d: most.max_texture_dimension_2d,
            max_buffer_size: most.max_buffer_size,
            ..wgpu::Limits::default()
        };
        if most.max_color_attachment_bytes_per_sample < limits.max_color_attachment_bytes_per_sample {
            return Err(format!("{name}: fewer than 64 colour attachment bytes a sample"));
        }
        let memory_hints = wgpu::MemoryHints::Performance;
        // What wgpu-hal would enable, plus the pass's features: appended to the pNext chain of
        // VkDeviceCreateInfo as their own structures (wgpu chains Vulkan 1.1-1.3 features one
        // structure each, so VkPhysicalDeviceVulkan13Features would conflict with them).
        let mut dr_on = vk::PhysicalDeviceDynamicRenderingFeatures::default().dynamic_rendering(true);
        let mut s2_on = vk::PhysicalDeviceSynchronization2Features::default().synchronization2(true);
        let mut u8_on = vk::PhysicalDeviceIndexTypeUint8FeaturesEXT::default().index_type_uint8(true);
        let (dr_ref, s2_ref, u8_ref) = (&mut dr_on, &mut s2_on, &mut u8_on);
        let callback: Box<wgpu::hal::vulkan::CreateDeviceCallback<'_>> = Box::new(move |args| {
            // Moved in: the structures outlive the call that reads the chain.
            let (dr, s2, u8) = (dr_ref, s2_ref, u8_ref);
            let mut info = std::mem::take(args.create_info).push_next(dr).push_next(s2);
            if index_type_uint8 {
                args.extensions.push(ash::ext::index_type_uint8::NAME);
                info = info.push_next(u8);
            }
            *args.create_info = info;
        });
        // SAFETY: the callback only adds features and an extension the physical device
        // reports (checked above); wgpu-hal creates the device from this adapter.
        let open = unsafe { hal_adapter.open_with_callback(features, &limits, &memory_hints, Some(callback)) }
            .map_err(|e| format!("{name}: vkCreateDevice through wgpu-hal: {e}"))?;
        drop(hal_adapter);
        let device_desc = wgpu::DeviceDescriptor {
            label: Some("umbrage wgpu host"),
            required_features: features,
            required_limits: limits,
            experimental_features: wgpu::ExperimentalFeatures::disabled(),
            memory_hints,
            trace: wgpu::Trace::Off,
        };
        // SAFETY: `open` was created from this adapter's hal adapter with exactly `features`.
        let (device, queue) =
            unsafe { adapter.create_device_from_hal(open, &device_desc) }.map_err(|e| format!("{name}: wgpu device: {e}"))?;
        let raw_device = {
            // SAFETY: the guard is dropped at the end of the block; the cloned function table
            // refers to a VkDevice that lives as long as `device`.
            let hal_device = unsafe { device.as_hal::<Vulkan>() }.ok_or("the device is not a Vulkan device")?;
            hal_device.raw_device().clone()
        };
        Ok(Gpu { device, queue, name, raw_instance, raw_device, physical, ds_format, index_type_uint8, _instance: instance })
    }

    /// A gpu-allocator on wgpu's device, for the shadow pass's buffers (wgpu-hal keeps its
    /// own allocator for wgpu's resources).
    pub fn allocator(&self) -> Result<Arc<Mutex<gpu_allocator::vulkan::Allocator>>, String> {
        let a = gpu_allocator::vulkan::Allocator::new(&gpu_allocator::vulkan::AllocatorCreateDesc {
            instance: self.raw_instance.clone(),
            device: self.raw_device.clone(),
            physical_device: self.physical,
            debug_settings: Default::default(),
            buffer_device_address: false,
            allocation_sizes: Default::default(),
        })
        .map_err(|e| format!("gpu-allocator: {e}"))?;
        Ok(Arc::new(Mutex::new(a)))
    }
}

/// `UMBRAGE_VALIDATION` asks for the layer: refuse to run without it (wgpu would go on
/// silently).
fn check_validation_layer() -> Result<(), String> {
    // SAFETY: loads the Vulkan loader for one enumeration; dropped at the end.
    let entry = unsafe { ash::Entry::load() }.map_err(|e| format!("no Vulkan loader (libvulkan.so.1): {e}"))?;
    // SAFETY: a plain enumeration on a loaded entry.
    let layers =
        unsafe { entry.enumerate_instance_layer_properties() }.map_err(|e| format!("vkEnumerateInstanceLayerProperties: {e:?}"))?;
    if layers.iter().any(|l| l.layer_name_as_c_str() == Ok(c"VK_LAYER_KHRONOS_validation")) {
        Ok(())
    } else {
        Err("UMBRAGE_VALIDATION is set but VK_LAYER_KHRONOS_validation is not installed".into())
    }
}
