//! The window's surface and swapchain: format and present-mode choice (with the fallback
//! named for the overlay), recreation on resize / out-of-date / suboptimal, a zero extent
//! (minimised) skipped, and the per-frame objects of two frames in flight: a command buffer,
//! a fence and an acquire semaphore per frame, a present semaphore per swapchain image (a
//! present's wait is only known to be over when that image is acquired again).

use ash::vk;
use umbrage::error::{Error, Result};
use umbrage::gpu::Context;

/// Frames the viewer's own presentation keeps in flight.
pub const FRAMES_IN_FLIGHT: usize = 2;

/// The surface formats umbrage presents, best first: sRGB 8-bit (the renderer's output is
/// sRGB, so a blit keeps the bytes), then UNORM (see [`Swapchain::note`]).
const FORMATS: [vk::Format; 4] =
    [vk::Format::B8G8R8A8_SRGB, vk::Format::R8G8B8A8_SRGB, vk::Format::R8G8B8A8_UNORM, vk::Format::B8G8R8A8_UNORM];

/// The surface format to use, and a note when it is not sRGB.
pub fn choose_format(available: &[vk::SurfaceFormatKHR]) -> Option<(vk::SurfaceFormatKHR, Option<String>)> {
    let srgb = vk::ColorSpaceKHR::SRGB_NONLINEAR;
    for f in FORMATS {
        if let Some(sf) = available.iter().find(|a| a.format == f && a.color_space == srgb) {
            let note = match f {
                vk::Format::B8G8R8A8_SRGB | vk::Format::R8G8B8A8_SRGB => None,
                vk::Format::R8G8B8A8_UNORM => Some(format!("no sRGB surface format: presenting {f:?} (the sRGB bytes copied as they are)")),
                _ => Some(format!("no sRGB surface format: presenting {f:?} (blit-converted: linear values, darker)")),
            };
            return Some((*sf, note));
        }
    }
    available.first().map(|sf| (*sf, Some(format!("no 8-bit sRGB surface format: presenting {:?} (blit-converted)", sf.format))))
}

/// The present mode for `vsync`, and a note when the wanted one is missing.
pub fn choose_present_mode(available: &[vk::PresentModeKHR], vsync: bool) -> (vk::PresentModeKHR, Option<String>) {
    let wanted: &[vk::PresentModeKHR] =
        if vsync { &[vk::PresentModeKHR::FIFO] } else { &[vk::PresentModeKHR::MAILBOX, vk::PresentModeKHR::IMMEDIATE] };
    if let Some(m) = wanted.iter().find(|m| available.contains(m)) {
        return (*m, None);
    }
    // FIFO is required by the specification; anything else reported is a last resort.
    let m = if available.contains(&vk::PresentModeKHR::FIFO) {
        vk::PresentModeKHR::FIFO
    } else {
        available.first().copied().unwrap_or_default()
    };
    (m, Some(format!("present mode {:?} unavailable: using {m:?}", wanted[0])))
}

/// The swapchain extent for a window of `window` pixels: the surface's current extent when
/// it fixes one, else the window's size clamped to the surface's limits; `None` for a zero
/// extent (a minimised window: nothing to present).
pub fn choose_extent(caps: &vk::SurfaceCapabilitiesKHR, window: (u32, u32)) -> Option<vk::Extent2D> {
    let e = if caps.current_extent.width != u32::MAX {
        caps.current_extent
    } else {
        vk::Extent2D {
            width: window.0.clamp(caps.min_image_extent.width, caps.max_image_extent.width.max(caps.min_image_extent.width)),
            height: window.1.clamp(caps.min_image_extent.height, caps.max_image_extent.height.max(caps.min_image_extent.height)),
        }
    };
    (e.width > 0 && e.height > 0 && window.0 > 0 && window.1 > 0).then_some(e)
}

/// One frame in flight of the presentation.
pub struct PresentFrame {
    /// Blit + overlay + screenshot copy.
    pub cmd: vk::CommandBuffer,
    /// Signalled when the frame's submission is done (created signalled).
    pub fence: vk::Fence,
    /// Signalled by the acquire, waited by the submission.
    pub acquired: vk::Semaphore,
}

/// The surface, its swapchain and the presentation's per-frame objects.
pub struct Swapchain {
    /// `VK_KHR_surface` instance functions.
    pub surface_fn: ash::khr::surface::Instance,
    /// `VK_KHR_swapchain` device functions.
    pub swapchain_fn: ash::khr::swapchain::Device,
    /// The window's surface.
    pub surface: vk::SurfaceKHR,
    /// The swapchain (null while minimised before the first one).
    pub swapchain: vk::SwapchainKHR,
    /// Its images.
    pub images: Vec<vk::Image>,
    /// A colour view of each (the overlay's attachment).
    pub views: Vec<vk::ImageView>,
    /// Per image: signalled by the submission that drew it, waited by its present.
    pub rendered: Vec<vk::Semaphore>,
    /// The surface format in use.
    pub format: vk::SurfaceFormatKHR,
    /// The present mode in use.
    pub present_mode: vk::PresentModeKHR,
    /// The images' size.
    pub extent: vk::Extent2D,
    /// Whether the images can be read back (`P` / `F12` screenshots).
    pub readable: bool,
    /// Fallbacks taken (format, present mode), for the overlay.
    pub notes: Vec<String>,
    /// The frames in flight.
    pub frames: Vec<PresentFrame>,
    /// Swapchains created so far (the first one included).
    pub generations: u32,
    vsync: bool,
}

impl Swapchain {
    /// Per-frame objects for `surface`, and a swapchain for a window of `window` pixels unless
    /// it is minimised. Fails with [`Error::Unsupported`] when the device's queue cannot
    /// present to the surface.
    pub fn new(ctx: &Context, surface: vk::SurfaceKHR, window: (u32, u32), vsync: bool) -> Result<Swapchain> {
        let mut s = Swapchain {
            surface_fn: ash::khr::surface::Instance::new(&ctx.entry, &ctx.instance),
            swapchain_fn: ash::khr::swapchain::Device::new(&ctx.instance, &ctx.device),
            surface,
            swapchain: vk::SwapchainKHR::null(),
            images: Vec::new(),
            views: Vec::new(),
            rendered: Vec::new(),
            format: vk::SurfaceFormatKHR::default(),
            present_mode: vk::PresentModeKHR::FIFO,
            extent: vk::Extent2D::default(),
            readable: false,
            notes: Vec::new(),
            frames: Vec::new(),
            generations: 0,
            vsync,
        };
        match s.init(ctx, window) {
            Ok(()) => Ok(s),
            Err(e) => {
                s.destroy(ctx);
                Err(e)
            }
        }
    }

    fn init(&mut self, ctx: &Context, window: (u32, u32)) -> Result<()> {
        // SAFETY: query on the context's physical device and a surface of its instance.
        let supported = unsafe { self.surface_fn.get_physical_device_surface_support(ctx.physical, ctx.queue_family, self.surface) }
            .map_err(Error::vk("vkGetPhysicalDeviceSurfaceSupportKHR"))?;
        if !supported {
            return Err(Error::Unsupported(format!("{}: its graphics queue cannot present to this window", ctx.info.name)));
        }
        for _ in 0..FRAMES_IN_FLIGHT {
            // SAFETY: object creation on the context's device; destroyed in `destroy`.
            let frame = unsafe {
                let info = vk::CommandBufferAllocateInfo::default().command_pool(ctx.pool).command_buffer_count(1);
                let cmd = ctx.device.allocate_command_buffers(&info).map_err(Error::vk("vkAllocateCommandBuffers"))?[0];
                let fence = ctx
                    .device
                    .create_fence(&vk::FenceCreateInfo::default().flags(vk::FenceCreateFlags::SIGNALED), None)
                    .map_err(Error::vk("vkCreateFence"))?;
                let acquired =
                    ctx.device.create_semaphore(&vk::SemaphoreCreateInfo::default(), None).map_err(Error::vk("vkCreateSemaphore"))?;
                PresentFrame { cmd, fence, acquired }
            };
            self.frames.push(frame);
        }
        self.rebuild(ctx, window)?;
        Ok(())
    }

    /// (Re)creates the swapchain for a window of `window` pixels (the device is idle first).
    /// Returns false when the window is minimised (zero extent): the old swapchain is kept
    /// and nothing should be presented.
    pub fn rebuild(&mut self, ctx: &Context, window: (u32, u32)) -> Result<bool> {
        let (sf, pd) = (&self.surface_fn, ctx.physical);
        // SAFETY: queries on a valid physical device and surface.
        let (caps, formats, modes) = unsafe {
            (
                sf.get_physical_device_surface_capabilities(pd, self.surface)
                    .map_err(Error::vk("vkGetPhysicalDeviceSurfaceCapabilitiesKHR"))?,
                sf.get_physical_device_surface_formats(pd, self.surface).map_err(Error::vk("vkGetPhysicalDeviceSurfaceFormatsKHR"))?,
                sf.get_physical_device_surface_present_modes(pd, self.surface)
                    .map_err(Error::vk("vkGetPhysicalDeviceSurfacePresentModesKHR"))?,
            )
        };
        let Some(extent) = choose_extent(&caps, window) else { return Ok(false) };
        let (format, format_note) = choose_format(&formats).ok_or_else(|| Error::Unsupported("the surface reports no formats".into()))?;
        let (present_mode, mode_note) = choose_present_mode(&modes, self.vsync);
        self.notes = format_note.into_iter().chain(mode_note).collect();
        let needed = vk::ImageUsageFlags::COLOR_ATTACHMENT | vk::ImageUsageFlags::TRANSFER_DST;
        if !caps.supported_usage_flags.contains(needed) {
            return Err(Error::Unsupported(format!("swapchain images lack {needed:?} (supported: {:?})", caps.supported_usage_flags)));
        }
        self.readable = caps.supported_usage_flags.contains(vk::ImageUsageFlags::TRANSFER_SRC);
        let usage = if self.readable { needed | vk::ImageUsageFlags::TRANSFER_SRC } else { needed };
        let mut count = caps.min_image_count.max(FRAMES_IN_FLIGHT as u32 + 1);
        if caps.max_image_count > 0 {
            count = count.min(caps.max_image_count);
        }
        let alpha = [vk::CompositeAlphaFlagsKHR::OPAQUE, vk::CompositeAlphaFlagsKHR::INHERIT, vk::CompositeAlphaFlagsKHR::PRE_MULTIPLIED]
            .into_iter()
            .find(|a| caps.supported_composite_alpha.contains(*a))
            .unwrap_or(vk::CompositeAlphaFlagsKHR::POST_MULTIPLIED);
        let info = vk::SwapchainCreateInfoKHR::default()
            .surface(self.surface)
            .min_image_count(count)
            .image_format(format.format)
            .image_color_space(format.color_space)
            .image_extent(extent)
            .image_array_layers(1)
            .image_usage(usage)
            .image_sharing_mode(vk::SharingMode::EXCLUSIVE)
            .pre_transform(if caps.supported_transforms.contains(vk::SurfaceTransformFlagsKHR::IDENTITY) {
                vk::SurfaceTransformFlagsKHR::IDENTITY
            } else {
                caps.current_transform
            })
            .composite_alpha(alpha)
            .present_mode(present_mode)
            .clipped(true)
            .old_swapchain(self.swapchain);
        // SAFETY: the device is idle (the caller waited), so the old swapchain's images and
        // views are unused; it is retired by the new swapchain's creation and destroyed after.
        unsafe {
            ctx.device.device_wait_idle().map_err(Error::vk("vkDeviceWaitIdle"))?;
            let new = self.swapchain_fn.create_swapchain(&info, None).map_err(|e| {
                Error::Unsupported(format!(
                    "cannot create a {}x{} swapchain ({e:?}); resize the window or use `umbrage render`",
                    extent.width, extent.height
                ))
            })?;
            self.destroy_images(ctx);
            if self.swapchain != vk::SwapchainKHR::null() {
                self.swapchain_fn.destroy_swapchain(self.swapchain, None);
            }
            self.swapchain = new;
            self.images = self.swapchain_fn.get_swapchain_images(new).map_err(Error::vk("vkGetSwapchainImagesKHR"))?;
            for &image in &self.images {
                let view = vk::ImageViewCreateInfo::default()
                    .image(image)
                    .view_type(vk::ImageViewType::TYPE_2D)
                    .format(format.format)
                    .subresource_range(color_range());
                self.views.push(ctx.device.create_image_view(&view, None).map_err(Error::vk("vkCreateImageView"))?);
                self.rendered
                    .push(ctx.device.create_semaphore(&vk::SemaphoreCreateInfo::default(), None).map_err(Error::vk("vkCreateSemaphore"))?);
            }
        }
        self.format = format;
        self.present_mode = present_mode;
        self.extent = extent;
        self.generations += 1;
        Ok(true)
    }

    /// # Safety
    /// The device is idle.
    unsafe fn destroy_images(&mut self, ctx: &Context) {
        // SAFETY: the caller's contract; each handle is destroyed once (the vectors drain).
        unsafe {
            for v in self.views.drain(..) {
                ctx.device.destroy_image_view(v, None);
            }
            for s in self.rendered.drain(..) {
                ctx.device.destroy_semaphore(s, None);
            }
        }
        self.images.clear();
    }

    /// Destroys the swapchain, the per-frame objects and the surface (before the context's
    /// instance goes).
    pub fn destroy(&mut self, ctx: &Context) {
        // SAFETY: after a device-wide wait nothing uses these objects; each is destroyed once.
        unsafe {
            let _ = ctx.device.device_wait_idle();
            self.destroy_images(ctx);
            if self.swapchain != vk::SwapchainKHR::null() {
                self.swapchain_fn.destroy_swapchain(self.swapchain, None);
                self.swapchain = vk::SwapchainKHR::null();
            }
            for f in self.frames.drain(..) {
                ctx.device.destroy_fence(f.fence, None);
                ctx.device.destroy_semaphore(f.acquired, None);
                ctx.device.free_command_buffers(ctx.pool, &[f.cmd]);
            }
            if self.surface != vk::SurfaceKHR::null() {
                self.surface_fn.destroy_surface(self.surface, None);
                self.surface = vk::SurfaceKHR::null();
            }
        }
    }
}

/// The whole colour subresource of a single-level, single-layer image.
pub fn color_range() -> vk::ImageSubresourceRange {
    vk::ImageSubresourceRange {
        aspect_mask: vk::ImageAspectFlags::COLOR,
        base_mip_level: 0,
        level_count: 1,
        base_array_layer: 0,
        layer_count: 1,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sf(format: vk::Format) -> vk::SurfaceFormatKHR {
        vk::SurfaceFormatKHR { format, color_space: vk::ColorSpaceKHR::SRGB_NONLINEAR }
    }

    #[test]
    fn srgb_is_preferred_and_a_fallback_is_named() {
        let (f, note) = choose_format(&[sf(vk::Format::B8G8R8A8_UNORM), sf(vk::Format::B8G8R8A8_SRGB)]).expect("a format");
        assert_eq!((f.format, note), (vk::Format::B8G8R8A8_SRGB, None));
        let (f, note) = choose_format(&[sf(vk::Format::R8G8B8A8_UNORM)]).expect("a format");
        assert_eq!(f.format, vk::Format::R8G8B8A8_UNORM);
        assert!(note.expect("a note").contains("no sRGB"));
        assert!(choose_format(&[]).is_none());
    }

    #[test]
    fn present_modes_fall_back_to_fifo_and_say_so() {
        use vk::PresentModeKHR as P;
        assert_eq!(choose_present_mode(&[P::FIFO, P::MAILBOX], false), (P::MAILBOX, None));
        assert_eq!(choose_present_mode(&[P::FIFO, P::IMMEDIATE], false), (P::IMMEDIATE, None));
        let (m, note) = choose_present_mode(&[P::FIFO], false);
        assert_eq!(m, P::FIFO);
        assert!(note.expect("a note").contains("MAILBOX unavailable"));
        assert_eq!(choose_present_mode(&[P::FIFO], true), (P::FIFO, None));
    }

    #[test]
    fn a_minimised_window_has_no_extent() {
        let mut caps = vk::SurfaceCapabilitiesKHR {
            current_extent: vk::Extent2D { width: 0, height: 0 },
            max_image_extent: vk::Extent2D { width: 4096, height: 4096 },
            ..Default::default()
        };
        assert_eq!(choose_extent(&caps, (0, 0)), None);
        caps.current_extent = vk::Extent2D { width: u32::MAX, height: u32::MAX };
        assert_eq!(choose_extent(&caps, (640, 0)), None);
        assert_eq!(choose_extent(&caps, (640, 480)), Some(vk::Extent2D { width: 640, height: 480 }));
        caps.current_extent = vk::Extent2D { width: 320, height: 200 };
        assert_eq!(choose_extent(&caps, (640, 480)), Some(vk::Extent2D { width: 320, height: 200 }));
    }
}
