//! The renderer's ring slots: per frame in flight a command buffer, a fence, timestamps,
//! counter queries and a readback buffer.

use super::InFlight;
use crate::counters::CounterPools;
use crate::guard::{Destroy, Guard};
use crate::readback::Readback;
use crate::timing::Timer;
use ash::vk;
use umbrage::error::{Error, Result};
use umbrage::gpu::Context;

/// One ring slot: its command buffer, fence, timestamps and readback.
pub(super) struct FrameSlot {
    pub(super) cmd: vk::CommandBuffer,
    pub(super) fence: vk::Fence,
    pub(super) timer: Timer,
    pub(super) counters: CounterPools,
    pub(super) readback: Readback,
    pub(super) in_flight: Option<InFlight>,
}

impl FrameSlot {
    /// `n` slots, all or nothing: when one cannot be created, those already made are destroyed.
    pub(super) fn ring(ctx: &Context, n: usize) -> Result<Vec<FrameSlot>> {
        let mut slots = Guard::new(ctx, Vec::with_capacity(n));
        for _ in 0..n {
            slots.push(FrameSlot::new(ctx)?);
        }
        Ok(slots.into_inner())
    }

    fn new(ctx: &Context) -> Result<FrameSlot> {
        let info = vk::CommandBufferAllocateInfo::default().command_pool(ctx.pool).command_buffer_count(1);
        // SAFETY: object creation on a valid device; destroyed in `destroy`. The fence is only
        // created once the command buffer exists, which is freed again if it cannot be.
        let (cmd, fence) = unsafe {
            let cbs = ctx.device.allocate_command_buffers(&info).map_err(Error::vk("vkAllocateCommandBuffers"))?;
            match ctx.device.create_fence(&vk::FenceCreateInfo::default(), None) {
                Ok(f) => (cbs[0], f),
                Err(e) => {
                    ctx.device.free_command_buffers(ctx.pool, &cbs);
                    return Err(Error::Vulkan { call: "vkCreateFence", result: e });
                }
            }
        };
        Ok(FrameSlot {
            cmd,
            fence,
            timer: Timer::new(ctx),
            counters: CounterPools::new(ctx),
            readback: Readback { buffer: None },
            in_flight: None,
        })
    }

    /// Destroys the slot's objects.
    ///
    /// # Safety
    ///
    /// The GPU must no longer use them (the slot's fence waited or the device idle).
    pub(super) unsafe fn destroy(&mut self, ctx: &Context) {
        // SAFETY: the caller guarantees the GPU is done with the slot.
        unsafe {
            ctx.device.destroy_fence(self.fence, None);
            ctx.device.free_command_buffers(ctx.pool, &[self.cmd]);
        }
        self.timer.destroy(ctx);
        self.counters.destroy(ctx);
        self.readback.destroy(ctx);
        self.in_flight = None;
    }
}

impl Destroy for FrameSlot {
    unsafe fn destroy(&mut self, ctx: &Context) {
        // SAFETY: the same contract (the GPU no longer uses the slot).
        unsafe { FrameSlot::destroy(self, ctx) }
    }
}
