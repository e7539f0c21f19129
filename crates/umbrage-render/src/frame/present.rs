//! What a windowed host (the viewer) needs beyond [`Renderer::render`]: the tone-mapped
//! output image to present from, and a resize that keeps the casters and the pass.

use super::Renderer;
use crate::pipelines::FramePipelines;
use crate::scene_gpu::Sidedness;
use crate::stages::selfshadow::SelfShadow;
use crate::targets::Targets;
use ash::vk;
use umbrage::error::{Error, Result};
use umbrage::gpu::Image;

impl Renderer {
    /// The final pass's sRGB output ([`OUTPUT_FORMAT`](crate::targets::OUTPUT_FORMAT)),
    /// `TRANSFER_SRC` capable. After a submitted frame's commands it is in
    /// `COLOR_ATTACHMENT_OPTIMAL` with its writes done; every frame's first access to it is a
    /// transition from `UNDEFINED` behind an all-commands barrier, so a host may read it (a blit
    /// to a swapchain image) in a later submission on the same queue and return it to
    /// `COLOR_ATTACHMENT_OPTIMAL` there.
    pub fn output_image(&self) -> &Image {
        &self.own.parts.targets.output
    }

    /// Rebuilds the size-dependent targets and pipelines for `width` x `height` (the casters,
    /// the pass and the scene's buffers stay). Waits for the device first; frames in flight are
    /// dropped (their tickets fail in [`finish`](Renderer::finish)). On error the renderer
    /// keeps its old size and stays usable.
    pub fn resize(&mut self, width: u32, height: u32) -> Result<()> {
        if width == 0 || height == 0 || width > 16384 || height > 16384 {
            return Err(Error::argument("image size", format!("invalid image size {width}x{height} (1..=16384 each)")));
        }
        if (width, height) == (self.own.parts.config.width, self.own.parts.config.height) {
            return Ok(());
        }
        let ctx = &self.own.ctx;
        // SAFETY: waiting for every submission before destroying what they use.
        unsafe { ctx.device.device_wait_idle() }.map_err(Error::vk("vkDeviceWaitIdle"))?;
        for s in &mut self.own.parts.slots {
            s.in_flight = None;
        }
        let old = &self.own.parts.targets;
        let transmit_format = old.transmit.format;
        let mut targets = Targets::with_samples(ctx, width, height, transmit_format, old.accum_format, old.samples)?;
        let mut pipes = match FramePipelines::new(ctx, &targets, self.own.parts.pass.capabilities().depth_bounds) {
            Ok(p) => p,
            Err(e) => {
                targets.destroy(ctx);
                return Err(e);
            }
        };
        let self_shadow = match self.own.parts.config.self_shadow && self.own.parts.geo.of(Sidedness::Transparent).next().is_some() {
            true => match SelfShadow::new(ctx, &pipes, targets.extent, transmit_format) {
                Ok(s) => Some(s),
                Err(e) => {
                    // SAFETY: nothing was recorded with the new objects.
                    unsafe { pipes.destroy(ctx) };
                    targets.destroy(ctx);
                    return Err(e);
                }
            },
            false => None,
        };
        let mut old_targets = std::mem::replace(&mut self.own.parts.targets, targets);
        let mut old_pipes = std::mem::replace(&mut self.own.parts.pipes, pipes);
        // SAFETY: the device is idle, so no command buffer uses the old objects.
        unsafe { old_pipes.destroy(ctx) };
        old_targets.destroy(ctx);
        if let Some(mut ss) = std::mem::replace(&mut self.own.parts.self_shadow, self_shadow) {
            ss.destroy(ctx);
        }
        // The shadow maps' screen-space passes are sized by the targets: rebuilt next frame.
        for (mut sm, _) in self.own.parts.shadow_mapper.take().into_iter().chain(self.own.parts.spare_shadow_mappers.drain(..)) {
            sm.destroy(ctx);
        }
        self.own.parts.config.width = width;
        self.own.parts.config.height = height;
        self.own.parts.scene_version += 1;
        Ok(())
    }

    /// The extent the renderer's targets have.
    pub fn extent(&self) -> vk::Extent2D {
        self.own.parts.targets.extent
    }
}
