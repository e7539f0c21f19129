//! Offscreen render targets: float accumulation, G-buffer, depth-stencil, sRGB output.

use crate::error::Result;
use crate::gpu::{Context, Image};
use ash::vk;

pub const ACCUM_FORMAT: vk::Format = vk::Format::R16G16B16A16_SFLOAT;
pub const ALBEDO_FORMAT: vk::Format = vk::Format::R8G8B8A8_UNORM;
/// Normals and positions in full f32: the dump's positions/normals come straight from here.
pub const NORMAL_FORMAT: vk::Format = vk::Format::R32G32B32A32_SFLOAT;
pub const POSITION_FORMAT: vk::Format = vk::Format::R32G32B32A32_SFLOAT;
pub const OUTPUT_FORMAT: vk::Format = vk::Format::R8G8B8A8_SRGB;
/// The float shadow-volume counter (`--counter float`).
pub use crate::pass::COUNT_FORMAT;

pub struct Targets {
    pub extent: vk::Extent2D,
    pub accum: Image,
    pub albedo: Image,
    pub normal: Image,
    pub position: Image,
    pub depth: Image,
    pub output: Image,
    pub count: Image,
    pub transmit: Image,
}

impl Targets {
    /// `transmit_format`: the transparent casters' light-intensity map (RGBA16F or RGBA32F).
    pub fn new(ctx: &Context, width: u32, height: u32, transmit_format: vk::Format) -> Result<Targets> {
        let extent = vk::Extent2D { width, height };
        let color = vk::ImageUsageFlags::COLOR_ATTACHMENT | vk::ImageUsageFlags::SAMPLED | vk::ImageUsageFlags::TRANSFER_SRC;
        let c = vk::ImageAspectFlags::COLOR;
        Ok(Targets {
            extent,
            accum: Image::new_2d(ctx, "accum", ACCUM_FORMAT, extent, color, c)?,
            albedo: Image::new_2d(ctx, "albedo", ALBEDO_FORMAT, extent, color, c)?,
            normal: Image::new_2d(ctx, "normal", NORMAL_FORMAT, extent, color, c)?,
            position: Image::new_2d(ctx, "position", POSITION_FORMAT, extent, color, c)?,
            depth: Image::new_2d(
                ctx,
                "depth-stencil",
                ctx.depth_format,
                extent,
                vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT | vk::ImageUsageFlags::TRANSFER_SRC,
                vk::ImageAspectFlags::DEPTH | vk::ImageAspectFlags::STENCIL,
            )?,
            count: Image::new_2d(ctx, "count", COUNT_FORMAT, extent, color, c)?,
            transmit: Image::new_2d(ctx, "light-intensity map", transmit_format, extent, color, c)?,
            output: Image::new_2d(
                ctx,
                "output",
                OUTPUT_FORMAT,
                extent,
                vk::ImageUsageFlags::COLOR_ATTACHMENT | vk::ImageUsageFlags::TRANSFER_SRC,
                c,
            )?,
        })
    }

    pub fn gbuffer(&self) -> [&Image; 4] {
        [&self.accum, &self.albedo, &self.normal, &self.position]
    }

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
