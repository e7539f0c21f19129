//! `rayquery.wgsl`'s push constants, shared by the per-light and the batched passes.

/// `rayquery.wgsl`'s push constants.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub(crate) struct RayPush {
    pub(super) light: [f32; 4],
    pub(super) params: [f32; 4],
}
