//! One presentation: acquire, blit the renderer's output into the swapchain image, draw the
//! overlay, optionally read the image back (a `P` / `F12` screenshot), submit, present.

use super::swapchain::{color_range, Swapchain};
use ash::vk;
use umbrage::error::{Error, Result};
use umbrage::gpu::resources::transfer_to_host_barrier;
use umbrage::gpu::{Buffer, Context, Image};

/// What a presentation came to.
#[derive(Debug, PartialEq, Eq)]
pub enum Presented {
    /// The image was presented (`suboptimal`: rebuild the swapchain before the next one).
    Yes {
        /// The swapchain no longer matches the surface exactly.
        suboptimal: bool,
    },
    /// The swapchain is out of date: nothing was presented; rebuild it.
    OutOfDate,
    /// The surface is gone (the window was destroyed under us): stop.
    Lost,
}

/// A layout transition of a swapchain image (whole colour subresource), all commands
/// before and after.
fn transition(ctx: &Context, cb: vk::CommandBuffer, image: vk::Image, from: vk::ImageLayout, to: vk::ImageLayout) {
    let b = [vk::ImageMemoryBarrier2::default()
        .src_stage_mask(vk::PipelineStageFlags2::ALL_COMMANDS)
        .src_access_mask(vk::AccessFlags2::MEMORY_WRITE)
        .dst_stage_mask(vk::PipelineStageFlags2::ALL_COMMANDS)
        .dst_access_mask(vk::AccessFlags2::MEMORY_READ | vk::AccessFlags2::MEMORY_WRITE)
        .old_layout(from)
        .new_layout(to)
        .image(image)
        .subresource_range(color_range())];
    // SAFETY: `cb` is recording; the image is a swapchain image of this device.
    unsafe { ctx.device.cmd_pipeline_barrier2(cb, &vk::DependencyInfo::default().image_memory_barriers(&b)) };
}

/// egui's Vulkan renderer, on the context's shared gpu-allocator.
pub type EguiRenderer = egui_ash_renderer::Renderer<egui_ash_renderer::allocator::GpuAllocator>;

/// What the overlay draws this frame.
pub struct OverlayDraw<'a> {
    /// egui's Vulkan renderer.
    pub renderer: &'a mut EguiRenderer,
    /// The tessellated overlay.
    pub primitives: &'a [egui::ClippedPrimitive],
    /// Physical pixels per egui point.
    pub pixels_per_point: f32,
}

/// Acquires an image on frame `slot` (whose fence the caller waited for), records and
/// submits the blit of `output` (the renderer's tone-mapped image, submitted earlier on the
/// same queue) with the overlay and the optional readback into `shot`, and presents it.
pub fn present(
    ctx: &Context,
    sc: &Swapchain,
    slot: usize,
    output: &Image,
    overlay: Option<OverlayDraw>,
    shot: Option<&Buffer>,
) -> Result<Presented> {
    let f = &sc.frames[slot];
    let d = &ctx.device;
    // An injected fault (`UMBRAGE_FAULT=present=...`) replaces the call: nothing is acquired.
    let acquired = match umbrage::gpu::fault::inject(umbrage::gpu::fault::FaultPoint::Present) {
        Some(injected) => Err(injected),
        // SAFETY: the swapchain is valid and the semaphore unsignalled (its last wait was by the
        // submission this slot's fence covers).
        None => unsafe { sc.swapchain_fn.acquire_next_image(sc.swapchain, u64::MAX, f.acquired, vk::Fence::null()) },
    };
    let index = match acquired {
        Ok((i, _)) => i as usize,
        Err(vk::Result::ERROR_OUT_OF_DATE_KHR) => return Ok(Presented::OutOfDate),
        Err(vk::Result::ERROR_SURFACE_LOST_KHR) => return Ok(Presented::Lost),
        Err(e) => return Err(Error::vk("vkAcquireNextImageKHR")(e)),
    };
    let image = sc.images[index];
    let full = vk::Extent2D { width: sc.extent.width, height: sc.extent.height };
    // SAFETY: the slot's fence was waited, so its command buffer is idle; `output` was last
    // written by an earlier submission on this queue and every access here is behind an
    // all-commands barrier.
    unsafe {
        d.reset_command_buffer(f.cmd, vk::CommandBufferResetFlags::empty()).map_err(Error::vk("vkResetCommandBuffer"))?;
        d.begin_command_buffer(f.cmd, &vk::CommandBufferBeginInfo::default().flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT))
            .map_err(Error::vk("vkBeginCommandBuffer"))?;
        let cb = f.cmd;
        umbrage::gpu::resources::transition(
            ctx,
            cb,
            output,
            vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL,
            vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
        );
        transition(ctx, cb, image, vk::ImageLayout::UNDEFINED, vk::ImageLayout::TRANSFER_DST_OPTIMAL);
        let layers =
            vk::ImageSubresourceLayers { aspect_mask: vk::ImageAspectFlags::COLOR, mip_level: 0, base_array_layer: 0, layer_count: 1 };
        let same_bits = sc.format.format == vk::Format::R8G8B8A8_UNORM && output.extent == full;
        if same_bits {
            // sRGB bytes into a UNORM image of the same channel order: copied as they are.
            let region = vk::ImageCopy::default().src_subresource(layers).dst_subresource(layers).extent(vk::Extent3D {
                width: full.width,
                height: full.height,
                depth: 1,
            });
            d.cmd_copy_image(
                cb,
                output.raw,
                vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                image,
                vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                &[region],
            );
        } else {
            let corner = |e: vk::Extent2D| [vk::Offset3D::default(), vk::Offset3D { x: e.width as i32, y: e.height as i32, z: 1 }];
            let region = vk::ImageBlit::default()
                .src_subresource(layers)
                .src_offsets(corner(output.extent))
                .dst_subresource(layers)
                .dst_offsets(corner(full));
            d.cmd_blit_image(
                cb,
                output.raw,
                vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                image,
                vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                &[region],
                vk::Filter::NEAREST,
            );
        }
        umbrage::gpu::resources::transition(
            ctx,
            cb,
            output,
            vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
            vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL,
        );
        transition(ctx, cb, image, vk::ImageLayout::TRANSFER_DST_OPTIMAL, vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL);
        if let Some(o) = overlay {
            let att = [vk::RenderingAttachmentInfo::default()
                .image_view(sc.views[index])
                .image_layout(vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL)
                .load_op(vk::AttachmentLoadOp::LOAD)
                .store_op(vk::AttachmentStoreOp::STORE)];
            let info = vk::RenderingInfo::default()
                .render_area(vk::Rect2D { offset: vk::Offset2D::default(), extent: full })
                .layer_count(1)
                .color_attachments(&att);
            d.cmd_begin_rendering(cb, &info);
            let r = o.renderer.cmd_draw(cb, full, o.pixels_per_point, o.primitives);
            d.cmd_end_rendering(cb);
            r.map_err(|e| Error::Unsupported(format!("egui overlay: {e}")))?;
        }
        let mut last = vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL;
        if let Some(buf) = shot {
            transition(ctx, cb, image, last, vk::ImageLayout::TRANSFER_SRC_OPTIMAL);
            let region = vk::BufferImageCopy::default().image_subresource(layers).image_extent(vk::Extent3D {
                width: full.width,
                height: full.height,
                depth: 1,
            });
            d.cmd_copy_image_to_buffer(cb, image, vk::ImageLayout::TRANSFER_SRC_OPTIMAL, buf.raw, &[region]);
            transfer_to_host_barrier(ctx, cb);
            last = vk::ImageLayout::TRANSFER_SRC_OPTIMAL;
        }
        transition(ctx, cb, image, last, vk::ImageLayout::PRESENT_SRC_KHR);
        d.end_command_buffer(cb).map_err(Error::vk("vkEndCommandBuffer"))?;

        let waits = [vk::SemaphoreSubmitInfo::default().semaphore(f.acquired).stage_mask(vk::PipelineStageFlags2::ALL_COMMANDS)];
        let signals = [vk::SemaphoreSubmitInfo::default().semaphore(sc.rendered[index]).stage_mask(vk::PipelineStageFlags2::ALL_COMMANDS)];
        let cbs = [vk::CommandBufferSubmitInfo::default().command_buffer(cb)];
        let submit = vk::SubmitInfo2::default().wait_semaphore_infos(&waits).command_buffer_infos(&cbs).signal_semaphore_infos(&signals);
        d.reset_fences(&[f.fence]).map_err(Error::vk("vkResetFences"))?;
        d.queue_submit2(ctx.queue, &[submit], f.fence).map_err(Error::vk("vkQueueSubmit2"))?;

        let sems = [sc.rendered[index]];
        let chains = [sc.swapchain];
        let indices = [index as u32];
        let info = vk::PresentInfoKHR::default().wait_semaphores(&sems).swapchains(&chains).image_indices(&indices);
        let presented = sc.swapchain_fn.queue_present(ctx.queue, &info);
        // An injected fault overrides the result after the real call, so the semaphore wait
        // still happens and only the error path differs.
        let presented = match umbrage::gpu::fault::inject(umbrage::gpu::fault::FaultPoint::Present) {
            Some(injected) => Err(injected),
            None => presented,
        };
        match presented {
            Ok(suboptimal) => Ok(Presented::Yes { suboptimal }),
            Err(vk::Result::ERROR_OUT_OF_DATE_KHR) => Ok(Presented::OutOfDate),
            Err(vk::Result::ERROR_SURFACE_LOST_KHR) => Ok(Presented::Lost),
            Err(e) => Err(Error::vk("vkQueuePresentKHR")(e)),
        }
    }
}

/// The swapchain image read back by a screenshot as RGBA8 (channels swapped from BGRA).
pub fn shot_rgba(sc: &Swapchain, buf: &Buffer) -> Result<Vec<u8>> {
    let mut px = buf.read()?.to_vec();
    if matches!(sc.format.format, vk::Format::B8G8R8A8_SRGB | vk::Format::B8G8R8A8_UNORM) {
        for p in px.chunks_exact_mut(4) {
            p.swap(0, 2);
        }
    }
    Ok(px)
}
