//! The host's calls on a frame's ring slot ([`ShadowPass::abandon_frame`]) and the stream
//! each prepared frame writes into it.

use super::ShadowPass;
use crate::error::Result;
use ash::vk;
use std::sync::atomic::Ordering;

impl ShadowPass {
    /// Tells the pass that the frame last prepared on `slot` was recorded but will never be
    /// submitted: the host reset or freed its command buffer (a swapchain that went out of
    /// date between recording and submission, a frame skipped late). Its uploads stay pending
    /// and ride with the next frame on any slot, and recording the same frame again records
    /// its copies again. A frame dropped without being recorded needs no call: the pass sees
    /// that `cmd_upload` never ran. Without this call, a recorded frame is taken to have been
    /// submitted and to have completed by the time its slot is prepared again.
    ///
    /// Errors: [`Misuse::SlotOutOfRange`](crate::error::Misuse::SlotOutOfRange).
    ///
    /// ```no_run
    /// # use umbrage::pass::*; use ash::vk;
    /// # fn f(pass: &mut ShadowPass, frame: &PreparedFrame, device: &ash::Device, cb: vk::CommandBuffer) -> umbrage::Result<()> {
    /// // The swapchain went out of date after recording: the host resets instead of submitting.
    /// // SAFETY: `cb` is not pending execution.
    /// unsafe { device.reset_command_buffer(cb, vk::CommandBufferResetFlags::empty()) }.ok();
    /// pass.abandon_frame(frame.slot())?; // its caster uploads ride with the next frame
    /// # Ok(()) }
    /// ```
    pub fn abandon_frame(&mut self, slot: usize) -> Result<()> {
        match self.slots.get(slot) {
            Some(s) => {
                s.recorded.store(false, Ordering::Release);
                Ok(())
            }
            None => Err(crate::error::Misuse::SlotOutOfRange { slot, slots: self.slots.len() }.into()),
        }
    }

    /// Writes the stream into the slot's buffer (grown to the next power of two when short).
    pub(super) fn write_stream(&mut self, slot: usize, data: &[u8]) -> crate::error::Result<vk::Buffer> {
        let dev = &self.dev;
        let s = &mut self.slots[slot];
        if s.stream.as_ref().map(|b| b.size < data.len() as u64).unwrap_or(true) {
            if let Some(mut old) = s.stream.take() {
                old.destroy(dev);
            }
            let size = (data.len() as u64).max(1 << 16).next_power_of_two();
            s.stream = Some(crate::gpu::Buffer::new(
                dev,
                &format!("shadow stream {slot}"),
                size,
                vk::BufferUsageFlags::INDEX_BUFFER | vk::BufferUsageFlags::VERTEX_BUFFER,
                gpu_allocator::MemoryLocation::CpuToGpu,
            )?);
        }
        let buf = s.stream.as_mut().ok_or_else(|| crate::error::Error::Internal("no stream buffer".into()))?;
        buf.write(0, data)?;
        Ok(buf.raw)
    }
}
