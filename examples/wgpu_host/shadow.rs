//! The only place the host calls [`ShadowPass`]'s recording: one light's shadow determination,
//! recorded through wgpu's raw Vulkan command buffer, in a command encoder of its own.
//!
//! wgpu 30 refuses to mix its own commands and raw ones in one encoder (it panics: "Mixing
//! the wgpu encoding API with the raw encoding API is not permitted"), so the determination
//! gets an encoder that only [`wgpu::CommandEncoder::as_hal_mut`] records into, submitted in
//! the same `queue.submit` between the wgpu encoders before and after it.
//!
//! **What wgpu's tracker believes, and what this leaves.** wgpu never sees these commands.
//! Before: the encoder ahead ends with `transition_resources(.., DEPTH_STENCIL_WRITE)` on the
//! depth-stencil texture, so wgpu's tracker (and wgpu-hal's `derive_image_layout`) has it in
//! `DEPTH_STENCIL_ATTACHMENT_OPTIMAL`, its depth writes made visible to fragment tests (that
//! transition is a depth-stencil-write to depth-stencil-write barrier: early and late fragment
//! tests, attachment read and write). The pass records in exactly that layout and leaves it
//! there, so the tracker stays right. After: wgpu's next use of the texture (the stencil copy,
//! or the lighting pass) is a transition out of `DEPTH_STENCIL_WRITE`, whose source scope
//! (fragment tests, attachment writes) covers the pass's stencil writes. The two barriers
//! recorded here say the same in Vulkan terms, so the contract does not rest on what wgpu's
//! transitions happen to cover.

use ash::vk;
use umbrage::pass::{DepthStencilTarget, PreparedFrame, ShadowPass};
use wgpu::hal::api::Vulkan;

/// Records light `light`'s determination (the count into the stencil, inside the light's
/// scissor; the frame's caster uploads first when this is the frame's first call) into a
/// new command encoder and returns its command buffer.
///
/// The caller submits it after the encoder that drew the depth (ending with the
/// `DEPTH_STENCIL_WRITE` transition) and before the encoder that reads the stencil, all in
/// one submission, and keeps `target`'s texture and `frame`'s ring slot alive until that
/// submission has completed.
pub fn determine(
    device: &wgpu::Device,
    raw: &ash::Device,
    pass: &ShadowPass,
    frame: &PreparedFrame,
    light: usize,
    target: &DepthStencilTarget,
) -> Result<wgpu::CommandBuffer, String> {
    let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("umbrage shadow determination") });
    let tests = vk::PipelineStageFlags::EARLY_FRAGMENT_TESTS | vk::PipelineStageFlags::LATE_FRAGMENT_TESTS;
    let ds_rw = vk::AccessFlags::DEPTH_STENCIL_ATTACHMENT_READ | vk::AccessFlags::DEPTH_STENCIL_ATTACHMENT_WRITE;
    // SAFETY: the encoder is recorded only through the raw handle inside the closure (never
    // through wgpu's API), is not ended here (wgpu ends it in `finish`), and records outside
    // any render pass. The pass's contract (`cmd_determine`): `target.view` is a view of both
    // aspects of the host's Depth24PlusStencil8 image, in the format the pass was created with
    // and in DEPTH_STENCIL_ATTACHMENT_OPTIMAL (see the module docs), with its depth writes
    // made visible by the first barrier; `frame` was prepared by `pass` and its slot is not
    // prepared again before this submission completes (the caller's contract).
    let recorded = unsafe {
        encoder.as_hal_mut::<Vulkan, _, _>(|e| {
            let Some(e) = e else { return Err("wgpu gave no Vulkan command encoder".to_string()) };
            let cb = e.raw_handle();
            // Depth writes (and the previous light's stencil reads) before the determination.
            let before = [vk::MemoryBarrier::default().src_access_mask(ds_rw).dst_access_mask(ds_rw)];
            raw.cmd_pipeline_barrier(cb, tests, tests, vk::DependencyFlags::empty(), &before, &[], &[]);
            pass.cmd_determine(cb, frame, light, target).map_err(|e| format!("cmd_determine: {e}"))?;
            // The stencil count visible to the copy and to the lighting pass's stencil test.
            let after = [vk::MemoryBarrier::default()
                .src_access_mask(vk::AccessFlags::DEPTH_STENCIL_ATTACHMENT_WRITE)
                .dst_access_mask(ds_rw | vk::AccessFlags::TRANSFER_READ)];
            raw.cmd_pipeline_barrier(cb, tests, tests | vk::PipelineStageFlags::TRANSFER, vk::DependencyFlags::empty(), &after, &[], &[]);
            Ok(())
        })
    };
    recorded?;
    Ok(encoder.finish())
}
