//! Offscreen render targets: float accumulation, G-buffer, depth-stencil, sRGB output.

use crate::error::Result;
use crate::gpu::{Context, Image};
use ash::vk;

/// The float accumulation target (ambient + every light).
pub const ACCUM_FORMAT: vk::Format = vk::Format::R16G16B16A16_SFLOAT;
/// The accumulation target of scenes with area lights (where the device can blend it): many
/// samples of `intensity / samples` each lose too much in fp16 (an 11-bit mantissa: 1024
/// samples of a lit floor summed to 20 levels in 255 off the point light's image, 256 to 6,
/// 64 to 2), in f32 nothing visible.
pub const ACCUM_FORMAT_FP32: vk::Format = vk::Format::R32G32B32A32_SFLOAT;
/// Albedo in the G-buffer.
pub const ALBEDO_FORMAT: vk::Format = vk::Format::R8G8B8A8_UNORM;
/// Normals and positions in full f32: the dump's positions/normals come straight from here.
pub const NORMAL_FORMAT: vk::Format = vk::Format::R32G32B32A32_SFLOAT;
/// Eye-relative positions, f32.
pub const POSITION_FORMAT: vk::Format = vk::Format::R32G32B32A32_SFLOAT;
/// The tone-mapped output.
pub const OUTPUT_FORMAT: vk::Format = vk::Format::R8G8B8A8_SRGB;
/// The float shadow-volume counter (`--counter float`).
pub use crate::pass::COUNT_FORMAT;

/// The renderer's offscreen targets, all of one size.
pub struct Targets {
    /// Their size.
    pub extent: vk::Extent2D,
    /// Float accumulation (RGBA16F, or RGBA32F for area lights: [`Targets::with_accum`]).
    pub accum: Image,
    /// The format of `accum`.
    pub accum_format: vk::Format,
    /// G-buffer albedo.
    pub albedo: Image,
    /// G-buffer face normal (f32).
    pub normal: Image,
    /// G-buffer eye-relative position (f32; w = 0 where nothing was drawn).
    pub position: Image,
    /// Depth-stencil (the device's D32S8 or D24S8).
    pub depth: Image,
    /// sRGB output.
    pub output: Image,
    /// The float counter (R32F).
    pub count: Image,
    /// The transparent casters' light-intensity map.
    pub transmit: Image,
}

impl Targets {
    /// All targets; `transmit_format`: the transparent casters' light-intensity map (RGBA16F or RGBA32F).
    pub fn new(ctx: &Context, width: u32, height: u32, transmit_format: vk::Format) -> Result<Targets> {
        Targets::with_accum(ctx, width, height, transmit_format, ACCUM_FORMAT)
    }
    /// [`Targets::new`] with the accumulation target in `accum_format` ([`ACCUM_FORMAT`] or
    /// [`ACCUM_FORMAT_FP32`]).
    pub fn with_accum(ctx: &Context, width: u32, height: u32, transmit_format: vk::Format, accum_format: vk::Format) -> Result<Targets> {
        let extent = vk::Extent2D { width, height };
        let color = vk::ImageUsageFlags::COLOR_ATTACHMENT | vk::ImageUsageFlags::SAMPLED | vk::ImageUsageFlags::TRANSFER_SRC;
        let c = vk::ImageAspectFlags::COLOR;
        let ds = vk::ImageAspectFlags::DEPTH | vk::ImageAspectFlags::STENCIL;
        let [accum, albedo, normal, position, depth, count, transmit, output] = Image::new_all(
            ctx,
            extent,
            [
                ("accum", accum_format, color, c),
                ("albedo", ALBEDO_FORMAT, color, c),
                ("normal", NORMAL_FORMAT, color, c),
                ("position", POSITION_FORMAT, color, c),
                ("depth-stencil", ctx.depth_format, vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT | vk::ImageUsageFlags::TRANSFER_SRC, ds),
                ("count", COUNT_FORMAT, color, c),
                ("light-intensity map", transmit_format, color, c),
                ("output", OUTPUT_FORMAT, vk::ImageUsageFlags::COLOR_ATTACHMENT | vk::ImageUsageFlags::TRANSFER_SRC, c),
            ],
        )?;
        Ok(Targets { extent, accum, accum_format, albedo, normal, position, depth, output, count, transmit })
    }

    /// The G-buffer pass's colour attachments, in attachment order.
    pub fn gbuffer(&self) -> [&Image; 4] {
        [&self.accum, &self.albedo, &self.normal, &self.position]
    }

    /// Destroys every target (the owner waited for the device).
    pub fn destroy(&mut self, ctx: &Context) {
        for img in [
            &mut self.accum,
            &mut self.albedo,
            &mut self.normal,
            &mut self.position,
            &mut self.depth,
            &mut self.output,
            &mut self.count,
            &mut self.transmit,
        ] {
            img.destroy(ctx);
        }
    }
}
