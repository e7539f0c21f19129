//! umbrage-render: umbrage's own renderer, a host of the shadow pass like any engine: it draws scenes, dumps them, and measures them against the reference (the accuracy tables).
//!
//! The frame, as McGuire et al. 2003 section 8 lay it out:
//!
//! 1. ambient pass: depth + the ambient term into a float target, plus a G-buffer
//!    (albedo, face normal, eye-relative position) the illumination reads;
//! 2. per light: shadow determination into the stencil (cleared inside the light's scissor),
//!    then illumination where the stencil count is zero, added into the float target;
//! 3. final pass: tone map to the sRGB output.
//!
//! Rendering is camera-relative: positions are uploaded as (world - eye), computed in f64, so
//! scenes 1e5 from the origin keep f32 precision where it matters (near the eye).
//!
//! Stencil convention (documented in docs/design.md): counter-clockwise front faces; z-pass
//! increments on front faces and decrements on back faces when the depth test passes; z-fail
//! increments on back faces and decrements on front faces when it fails. Both give +1 per
//! enclosing volume, with wrap ops so the order of faces does not matter.

#![warn(missing_docs)]

/// This crate's shaders, naga-compiled by its build script (`umbrage-shaderc`), beside the
/// shadow pass's (`umbrage::gpu::shaders`, re-exported; this crate's `ALL` lists its own).
pub mod shaders {
    pub use umbrage::gpu::shaders::*;
    include!(concat!(env!("OUT_DIR"), "/shaders.rs"));
}
pub mod accuracy;
pub mod counters;
pub mod frame;
mod frame_output;
pub(crate) mod guard;
pub mod options;
pub mod output;
pub mod pipelines;
pub mod push;
mod readback;
pub mod scene_gpu;
pub(crate) mod stages;
/// The shadow-map baseline (a stage of the frame, in `stages/`).
pub use stages::shadowmap;
mod sphere_gpu;
pub mod stats;
pub mod targets;
pub mod technique;
mod timing;

pub use counters::PassCounters;
pub use frame::{largest_device_heap, FrameTicket, MemoryEstimate, NewError, Renderer, Throughput};
pub use frame_output::{standard_sample_locations, FrameOutput, SampleOutput};
pub use options::{
    ComputeDraws, Counter, DepthMode, FrameSettings, IndexFormat, PassToggles, RenderConfig, RenderOptions, Shading, Technique,
    TransmitMode, View,
};
pub use stages::debug::stencil_heatmap;
pub use stats::Stats;
pub use technique::{CubeFaces, Pcf, RenderTechnique, ShadowMap};

use ash::vk;
use gpu_allocator::MemoryLocation;
use umbrage::error::Result;
use umbrage::gpu::{Buffer, Context};

/// Uploads `data` into a device-local buffer through a staging buffer (waits for the copy).
pub(crate) fn upload(ctx: &Context, name: &str, data: &[u8], usage: vk::BufferUsageFlags) -> Result<Buffer> {
    let mut staging = Buffer::with_data(ctx, "staging", data, vk::BufferUsageFlags::TRANSFER_SRC)?;
    let dst = match Buffer::new(ctx, name, data.len() as u64, usage | vk::BufferUsageFlags::TRANSFER_DST, MemoryLocation::GpuOnly) {
        Ok(b) => b,
        Err(e) => {
            staging.destroy(ctx);
            return Err(e);
        }
    };
    let r = ctx.one_shot(|cb| {
        // SAFETY: both buffers are at least `data.len()` bytes and alive until after the wait.
        unsafe {
            ctx.device.cmd_copy_buffer(
                cb,
                staging.raw,
                dst.raw,
                &[vk::BufferCopy { src_offset: 0, dst_offset: 0, size: data.len() as u64 }],
            )
        };
    });
    staging.destroy(ctx);
    match r {
        Ok(()) => Ok(dst),
        Err(e) => {
            let mut dst = dst;
            dst.destroy(ctx);
            Err(e)
        }
    }
}
