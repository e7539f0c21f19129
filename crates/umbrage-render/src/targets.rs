//! Offscreen render targets: float accumulation, G-buffer, depth-stencil, sRGB output.

use ash::vk;
use umbrage::error::Result;
use umbrage::gpu::{Context, Image};

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
/// One sample of the position or normal target, read back ([`SampleReadback::geometry`]).
pub const SAMPLE_GEOMETRY_FORMAT: vk::Format = vk::Format::R32G32B32A32_SFLOAT;
/// One sample of the stencil, read back ([`SampleReadback::stencil`]).
pub const SAMPLE_STENCIL_FORMAT: vk::Format = vk::Format::R8_UINT;
/// The float shadow-volume counter (`--counter float`).
pub use umbrage::pass::COUNT_FORMAT;

/// The per-sample readback of a multisampled frame (images of more than one sample cannot be
/// copied to a buffer): one sample at a time is drawn into these single-sample images and
/// copied out.
pub struct SampleReadback {
    /// One sample of the position or of the normal target (RGBA32F).
    pub geometry: Image,
    /// One sample of the stencil (R8_UINT).
    pub stencil: Image,
    /// The depth-stencil target's stencil aspect, sampled.
    pub stencil_view: vk::ImageView,
}

/// The renderer's offscreen targets, all of one size.
pub struct Targets {
    /// Their size.
    pub extent: vk::Extent2D,
    /// Samples per pixel of the accumulation, G-buffer and depth-stencil targets (the count
    /// and intensity maps and the output have one).
    pub samples: u32,
    /// With more than one sample, what reads them back.
    pub per_sample: Option<SampleReadback>,
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
        Targets::with_samples(ctx, width, height, transmit_format, accum_format, 1)
    }

    /// [`Targets::with_accum`] with `samples` samples per pixel (1, 2, 4 or 8, checked by the
    /// caller against the device) on the accumulation, G-buffer and depth-stencil targets.
    pub fn with_samples(
        ctx: &Context,
        width: u32,
        height: u32,
        transmit_format: vk::Format,
        accum_format: vk::Format,
        samples: u32,
    ) -> Result<Targets> {
        let extent = vk::Extent2D { width, height };
        let color = vk::ImageUsageFlags::COLOR_ATTACHMENT | vk::ImageUsageFlags::SAMPLED | vk::ImageUsageFlags::TRANSFER_SRC;
        let c = vk::ImageAspectFlags::COLOR;
        let ds = vk::ImageAspectFlags::DEPTH | vk::ImageAspectFlags::STENCIL;
        let ms = vk::SampleCountFlags::from_raw(samples);
        // Multisampled, the stencil is read by a shader (one sample at a time), not copied.
        let ds_usage = match samples {
            1 => vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT | vk::ImageUsageFlags::TRANSFER_SRC,
            _ => vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT | vk::ImageUsageFlags::SAMPLED,
        };
        let [accum, albedo, normal, position, depth] = Image::new_all_samples(
            ctx,
            extent,
            ms,
            [
                ("accum", accum_format, color, c),
                ("albedo", ALBEDO_FORMAT, color, c),
                ("normal", NORMAL_FORMAT, color, c),
                ("position", POSITION_FORMAT, color, c),
                ("depth-stencil", ctx.depth_format, ds_usage, ds),
            ],
        )?;
        let mut t = Targets {
            extent,
            samples,
            per_sample: None,
            accum,
            accum_format,
            albedo,
            normal,
            position,
            depth,
            output: Image::null(),
            count: Image::null(),
            transmit: Image::null(),
        };
        // From here on a failure destroys what was made (null images destroy as nothing).
        match t.single_sampled(ctx, transmit_format) {
            Ok(()) => Ok(t),
            Err(e) => {
                t.destroy(ctx);
                Err(e)
            }
        }
    }

    /// The single-sample targets, and with more than one sample the per-sample readback.
    fn single_sampled(&mut self, ctx: &Context, transmit_format: vk::Format) -> Result<()> {
        let color = vk::ImageUsageFlags::COLOR_ATTACHMENT | vk::ImageUsageFlags::SAMPLED | vk::ImageUsageFlags::TRANSFER_SRC;
        let c = vk::ImageAspectFlags::COLOR;
        let readback = vk::ImageUsageFlags::COLOR_ATTACHMENT | vk::ImageUsageFlags::TRANSFER_SRC;
        [self.count, self.transmit, self.output] = Image::new_all(
            ctx,
            self.extent,
            [("count", COUNT_FORMAT, color, c), ("light-intensity map", transmit_format, color, c), ("output", OUTPUT_FORMAT, readback, c)],
        )?;
        if self.samples > 1 {
            let [geometry, stencil] = Image::new_all(
                ctx,
                self.extent,
                [("sample readback", SAMPLE_GEOMETRY_FORMAT, readback, c), ("sample stencil readback", SAMPLE_STENCIL_FORMAT, readback, c)],
            )?;
            let mut rb = SampleReadback { geometry, stencil, stencil_view: vk::ImageView::null() };
            let view = |aspect_mask| {
                let info = vk::ImageViewCreateInfo::default()
                    .image(self.depth.raw)
                    .view_type(vk::ImageViewType::TYPE_2D)
                    .format(self.depth.format)
                    .subresource_range(vk::ImageSubresourceRange {
                        aspect_mask,
                        base_mip_level: 0,
                        level_count: 1,
                        base_array_layer: 0,
                        layer_count: 1,
                    });
                // SAFETY: the depth-stencil image is bound and sampled-usable; the view is
                // destroyed in `destroy`, before the image.
                unsafe { ctx.device.create_image_view(&info, None) }.map_err(umbrage::Error::vk("vkCreateImageView"))
            };
            match view(vk::ImageAspectFlags::STENCIL) {
                Ok(s) => rb.stencil_view = s,
                Err(e) => {
                    rb.geometry.destroy(ctx);
                    rb.stencil.destroy(ctx);
                    return Err(e);
                }
            }
            self.per_sample = Some(rb);
        }
        Ok(())
    }

    /// The G-buffer pass's colour attachments, in attachment order.
    pub fn gbuffer(&self) -> [&Image; 4] {
        [&self.accum, &self.albedo, &self.normal, &self.position]
    }

    /// Destroys every target (the owner waited for the device).
    pub fn destroy(&mut self, ctx: &Context) {
        if let Some(mut rb) = self.per_sample.take() {
            // SAFETY: the owner waited for the device; the view is destroyed once.
            unsafe { ctx.device.destroy_image_view(rb.stencil_view, None) };
            rb.geometry.destroy(ctx);
            rb.stencil.destroy(ctx);
        }
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
