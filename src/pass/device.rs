//! The host's device and allocator, as the GPU helpers see them.

use crate::gpu::context::{lock_allocator, GpuDevice};
use gpu_allocator::vulkan::Allocator;
use std::sync::{Arc, Mutex};

/// A clone of the host's `ash::Device` (a table of function pointers, not the device's
/// ownership) and a shared handle on its allocator.
pub(crate) struct PassDevice {
    pub device: ash::Device,
    pub allocator: Arc<Mutex<Allocator>>,
}

impl GpuDevice for PassDevice {
    fn device(&self) -> &ash::Device {
        &self.device
    }
    fn allocator(&self) -> std::sync::MutexGuard<'_, Allocator> {
        lock_allocator(&self.allocator)
    }
    /// The pass asks for Vulkan 1.1 only: its barriers are Vulkan 1.0 `vkCmdPipelineBarrier`.
    fn synchronization2(&self) -> bool {
        false
    }
}
