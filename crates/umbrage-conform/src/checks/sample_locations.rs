//! Multisampled depth at the standard sample locations: where a multisampled draw evaluates
//! each sample's coverage and depth.
//!
//! A plane whose depth grows by 1/64 a pixel along x (then, in a second render, along y) is
//! drawn at every sample count in {2, 4, 8} the device supports for the renderer's depth format
//! (sampled), over a rectangle whose right (bottom) edge runs through the middle of a pixel
//! column (row), so that column's samples left of the edge are covered and the others not.
//! Every sample of every pixel is read back (a full-screen pass per sample,
//! `shaders/sample_readback.frag`) and compared with the plane evaluated at the sample's
//! standard location (`standardSampleLocations`, Vulkan's "Multisampling" table): coverage
//! exact, depth within 1e-5 (a quarter pixel off is 0.0039). Where depth is off, the location
//! it was evaluated at is recovered from the two gradients and reported per sample.
//!
//! SwiftShader fails it (docs/conform/drivers-notes.md §1f): its coverage is at the standard
//! locations, its depth at the locations mirrored in x about the pixel centre.

use super::rect;
use crate::harness::{self, DrawCall, Draws, Indices, PipeSpec};
use crate::shaders;
use crate::CheckResult;
use ash::vk;
use gpu_allocator::MemoryLocation;
use serde_json::json;
use umbrage::error::{Error, Result};
use umbrage::gpu::descriptors::{pipeline_layout, Binding, DescriptorSet};
use umbrage::gpu::pipeline::{self, PipelineDesc};
use umbrage::gpu::resources::{aspect_copy, cleared_depth_stencil, transfer_to_host_barrier, transition};
use umbrage::gpu::{Buffer, Context, Image};
use umbrage_render::standard_sample_locations;

/// The check's name (`legacy.msaa_depth_locations`).
pub const NAME: &str = "msaa_depth_locations";

const SIZE: u32 = 16;
/// Depth at x (or y) = 0 and its growth per pixel: exact in f32 at every 1/16 pixel.
const Z0: f64 = 0.25;
const SLOPE: f64 = 1.0 / 64.0;
/// The covered rectangle ends half-way through this column (x render) or row (y render).
const EDGE: f64 = 8.5;
const TOLERANCE: f64 = 1e-5;

/// Sample counts of 2, 4 and 8 the depth format supports as a sampled depth attachment.
fn sample_counts(ctx: &Context) -> Vec<u32> {
    let usage = vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT | vk::ImageUsageFlags::SAMPLED;
    // SAFETY: a format query on the context's valid physical device.
    let props = unsafe {
        ctx.instance.get_physical_device_image_format_properties(
            ctx.physical,
            ctx.depth_format,
            vk::ImageType::TYPE_2D,
            vk::ImageTiling::OPTIMAL,
            usage,
            vk::ImageCreateFlags::empty(),
        )
    };
    let Ok(props) = props else { return Vec::new() };
    let allowed = props.sample_counts & ctx.limits.framebuffer_depth_sample_counts & ctx.limits.sampled_image_depth_sample_counts;
    [2u32, 4, 8].into_iter().filter(|&n| allowed.contains(vk::SampleCountFlags::from_raw(n))).collect()
}

/// Renders the plane (depth growing along x when `along_x`, else along y) at `n` samples and
/// reads every sample back: `[sample][pixel]` depth values.
fn render_samples(ctx: &Context, n: u32, along_x: bool) -> Result<Vec<Vec<f32>>> {
    let samples = vk::SampleCountFlags::from_raw(n);
    let mvp = harness::pixel_ortho(SIZE, SIZE);
    let s = SIZE as f32;
    let mut v = Vec::new();
    let r = if along_x { [0.0, 0.0, EDGE as f32, s] } else { [0.0, 0.0, s, EDGE as f32] };
    rect(&mut v, r, true);
    for p in &mut v {
        p[2] = (Z0 + SLOPE * if along_x { p[0] } else { p[1] } as f64) as f32;
    }
    let mut spec = PipeSpec::stencil(vk::StencilOp::KEEP, vk::StencilOp::KEEP);
    spec.depth_test = true;
    spec.depth_write = true;
    spec.depth_compare = vk::CompareOp::ALWAYS;
    let draws = Draws::with_samples(ctx, ctx.depth_format, samples, &[DrawCall { spec, mvp, vertices: v, indices: Indices::None }])?;
    let mut objects = Objects::default();
    let result = render_inner(ctx, n, &draws, &mut objects);
    draws.destroy(ctx);
    objects.destroy(ctx);
    result
}

/// What [`render_inner`] creates, destroyed whatever fails.
#[derive(Default)]
struct Objects {
    images: Vec<Image>,
    buffers: Vec<Buffer>,
    views: Vec<vk::ImageView>,
    sampler: vk::Sampler,
    sets: Vec<DescriptorSet>,
    layout: vk::PipelineLayout,
    pipeline: vk::Pipeline,
}

impl Objects {
    fn destroy(mut self, ctx: &Context) {
        // SAFETY: after the wait nothing is in use; null handles are ignored.
        unsafe {
            let _ = ctx.device.device_wait_idle();
            ctx.device.destroy_pipeline(self.pipeline, None);
            ctx.device.destroy_pipeline_layout(self.layout, None);
            ctx.device.destroy_sampler(self.sampler, None);
            for v in self.views.drain(..) {
                ctx.device.destroy_image_view(v, None);
            }
        }
        for s in &mut self.sets {
            s.destroy(ctx);
        }
        for b in &mut self.buffers {
            b.destroy(ctx);
        }
        for i in &mut self.images {
            i.destroy(ctx);
        }
    }
}

fn render_inner(ctx: &Context, n: u32, draws: &Draws, o: &mut Objects) -> Result<Vec<Vec<f32>>> {
    let extent = vk::Extent2D { width: SIZE, height: SIZE };
    let area = vk::Rect2D { offset: vk::Offset2D { x: 0, y: 0 }, extent };
    let ds_aspects = vk::ImageAspectFlags::DEPTH | vk::ImageAspectFlags::STENCIL;
    let ds_usage = vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT | vk::ImageUsageFlags::SAMPLED;
    let samples = vk::SampleCountFlags::from_raw(n);
    o.images.push(Image::new_2d_samples(ctx, "conform-ms-depth", ctx.depth_format, extent, ds_usage, ds_aspects, samples)?);
    let out_format = vk::Format::R32G32B32A32_SFLOAT;
    let out_usage = vk::ImageUsageFlags::COLOR_ATTACHMENT | vk::ImageUsageFlags::TRANSFER_SRC;
    o.images.push(Image::new_2d(ctx, "conform-sample-out", out_format, extent, out_usage, vk::ImageAspectFlags::COLOR)?);
    let texel_bytes = 16u64;
    let per_sample = (SIZE * SIZE) as u64 * texel_bytes;
    o.buffers.push(Buffer::new(
        ctx,
        "conform-sample-readback",
        per_sample * n as u64,
        vk::BufferUsageFlags::TRANSFER_DST,
        MemoryLocation::GpuToCpu,
    )?);
    let (ds, out) = (&o.images[0], &o.images[1]);
    let range = vk::ImageSubresourceRange {
        aspect_mask: vk::ImageAspectFlags::DEPTH,
        base_mip_level: 0,
        level_count: 1,
        base_array_layer: 0,
        layer_count: 1,
    };
    let info =
        vk::ImageViewCreateInfo::default().image(ds.raw).view_type(vk::ImageViewType::TYPE_2D).format(ds.format).subresource_range(range);
    // SAFETY: the image is bound and sampled-usable; the view is destroyed by `Objects::destroy`.
    o.views.push(unsafe { ctx.device.create_image_view(&info, None) }.map_err(Error::vk("vkCreateImageView"))?);
    let nearest = vk::SamplerCreateInfo::default().mag_filter(vk::Filter::NEAREST).min_filter(vk::Filter::NEAREST);
    // SAFETY: a valid create info; destroyed by `Objects::destroy`.
    o.sampler = unsafe { ctx.device.create_sampler(&nearest, None) }.map_err(Error::vk("vkCreateSampler"))?;
    o.sets.push(DescriptorSet::new(ctx, &[Binding::Image(o.views[0]), Binding::Sampler(o.sampler)])?);
    o.layout = pipeline_layout(ctx, &[o.sets[0].layout], 4, vk::ShaderStageFlags::FRAGMENT)?;
    let formats = [out_format];
    let mut p = PipelineDesc::new(shaders::FULLSCREEN_VERT, o.layout, vk::Format::UNDEFINED);
    p.fragment = Some(shaders::SAMPLE_READBACK_FRAG);
    p.color_formats = &formats;
    o.pipeline = pipeline::create(ctx, &p)?;
    let (set, layout, readback, buffer) = (o.sets[0].set, o.layout, o.pipeline, o.buffers[0].raw);
    let viewport = vk::Viewport { x: 0.0, y: 0.0, width: SIZE as f32, height: SIZE as f32, min_depth: 0.0, max_depth: 1.0 };
    ctx.one_shot(|cb| {
        let d = &ctx.device;
        transition(ctx, cb, ds, vk::ImageLayout::UNDEFINED, vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL);
        let att = cleared_depth_stencil(ds.view, (1.0, 0));
        let info = vk::RenderingInfo::default().render_area(area).layer_count(1).depth_attachment(&att).stencil_attachment(&att);
        // SAFETY: `cb` is recording (one_shot); every handle was created on this device above
        // and outlives the submission, which one_shot waits for.
        unsafe {
            d.cmd_begin_rendering(cb, &info);
            d.cmd_set_viewport(cb, 0, &[viewport]);
            draws.record(ctx, cb, 0, area);
            d.cmd_end_rendering(cb);
        }
        transition(ctx, cb, ds, vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL, vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL);
        transition(ctx, cb, out, vk::ImageLayout::UNDEFINED, vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL);
        for k in 0..n {
            let color = [vk::RenderingAttachmentInfo::default()
                .image_view(out.view)
                .image_layout(vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL)
                .load_op(vk::AttachmentLoadOp::CLEAR)
                .store_op(vk::AttachmentStoreOp::STORE)
                .clear_value(vk::ClearValue { color: vk::ClearColorValue { float32: [f32::NAN; 4] } })];
            let info = vk::RenderingInfo::default().render_area(area).layer_count(1).color_attachments(&color);
            // SAFETY: as above; the depth image is in SHADER_READ_ONLY_OPTIMAL, as the set needs.
            unsafe {
                d.cmd_begin_rendering(cb, &info);
                d.cmd_set_viewport(cb, 0, &[viewport]);
                d.cmd_set_scissor(cb, 0, &[area]);
                d.cmd_bind_pipeline(cb, vk::PipelineBindPoint::GRAPHICS, readback);
                d.cmd_bind_descriptor_sets(cb, vk::PipelineBindPoint::GRAPHICS, layout, 0, &[set], &[]);
                d.cmd_push_constants(cb, layout, vk::ShaderStageFlags::FRAGMENT, 0, &(k as i32).to_le_bytes());
                d.cmd_draw(cb, 3, 1, 0, 0);
                d.cmd_end_rendering(cb);
            }
            transition(ctx, cb, out, vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL, vk::ImageLayout::TRANSFER_SRC_OPTIMAL);
            let region = aspect_copy(vk::ImageAspectFlags::COLOR, extent, k as u64 * per_sample);
            // SAFETY: recording outside a rendering instance; the buffer holds n samples' texels.
            unsafe { d.cmd_copy_image_to_buffer(cb, out.raw, vk::ImageLayout::TRANSFER_SRC_OPTIMAL, buffer, &[region]) };
            transition(ctx, cb, out, vk::ImageLayout::TRANSFER_SRC_OPTIMAL, vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL);
        }
        transfer_to_host_barrier(ctx, cb);
    })?;
    let texels: Vec<[f32; 4]> = bytemuck::pod_collect_to_vec(o.buffers[0].read()?);
    Ok(texels.chunks_exact((SIZE * SIZE) as usize).map(|s| s.iter().map(|t| t[0]).collect()).collect())
}

/// One sample count's findings.
#[derive(Default)]
struct Tally {
    coverage_mismatches: u64,
    depth_mismatches: u64,
    /// Per sample: the median location (x from the x render, y from the y render) its depth
    /// was evaluated at, over the covered pixels away from the edge.
    depth_at: Vec<(f64, f64)>,
}

/// The median of `v` (NaN when empty).
fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v.get(v.len() / 2).copied().unwrap_or(f64::NAN)
}

fn judge(n: u32, x_render: &[Vec<f32>], y_render: &[Vec<f32>]) -> Tally {
    let mut t = Tally::default();
    for (k, &(sx, sy)) in standard_sample_locations(n).iter().enumerate() {
        let mut along = [Vec::new(), Vec::new()];
        for (axis, render) in [x_render, y_render].into_iter().enumerate() {
            for py in 0..SIZE {
                for px in 0..SIZE {
                    let (x, y) = (px as f64 + sx, py as f64 + sy);
                    let c = if axis == 0 { x } else { y };
                    let got = render[k][(py * SIZE + px) as usize] as f64;
                    let covered = c < EDGE;
                    if covered != (got != 1.0) {
                        t.coverage_mismatches += 1;
                        continue;
                    }
                    if !covered {
                        continue;
                    }
                    if (got - (Z0 + SLOPE * c)).abs() > TOLERANCE {
                        t.depth_mismatches += 1;
                    }
                    let p = if axis == 0 { px } else { py };
                    if (p as f64) < EDGE - 1.0 {
                        along[axis].push((got - Z0) / SLOPE - p as f64);
                    }
                }
            }
        }
        let [ax, ay] = along;
        t.depth_at.push((median(ax), median(ay)));
    }
    t
}

/// Where the device evaluates a multisampled draw's depth, per sample of `n` (in Vulkan's
/// standard sample order, pixel units from the pixel's top-left corner): the check's two
/// sloped-plane renders at `n` samples (the renderer's depth format, sampled), each sample's
/// median location over the covered pixels. The standard locations on a conformant device;
/// SwiftShader's are mirrored in x (docs/conform/drivers-notes.md §1f). `None` where the
/// depth format cannot be a sampled attachment of `n` samples, or `n` is not 2, 4 or 8.
pub fn measure_depth_locations(ctx: &Context, n: u32) -> Result<Option<Vec<(f64, f64)>>> {
    if !sample_counts(ctx).contains(&n) {
        return Ok(None);
    }
    let t = judge(n, &render_samples(ctx, n, true)?, &render_samples(ctx, n, false)?);
    // A location that is not a number (no covered sample read back) is the standard one.
    let at = t
        .depth_at
        .iter()
        .zip(standard_sample_locations(n))
        .map(|(&(x, y), &(sx, sy))| (if x.is_finite() { x } else { sx }, if y.is_finite() { y } else { sy }))
        .collect();
    Ok(Some(at))
}

/// Measures where `renderer`'s device evaluates a multisampled draw's depth
/// ([`measure_depth_locations`]) and hands the locations to it
/// ([`Renderer::use_sample_depth_locations`](umbrage_render::Renderer::use_sample_depth_locations)),
/// so a multisampled capture's positions are found where its depth tests looked. Nothing for a
/// one-sample renderer, or where the depth format cannot be sampled at its count (the
/// standard locations stay).
pub fn calibrate_sample_locations(renderer: &mut umbrage_render::Renderer) -> Result<()> {
    let n = renderer.config().samples;
    if n < 2 {
        return Ok(());
    }
    match measure_depth_locations(renderer.context(), n)? {
        Some(at) => renderer.use_sample_depth_locations(&at),
        None => Ok(()),
    }
}

/// Every sample's coverage and depth at its standard location, at each supported count of 2, 4
/// and 8 (the renderer's depth format, sampled). Skipped without `standardSampleLocations` or
/// without a multisampled, sampled depth format.
pub fn msaa_depth_locations(ctx: &Context) -> Result<CheckResult> {
    if ctx.limits.standard_sample_locations != vk::TRUE {
        return Ok(CheckResult::skipped(NAME, "skipped: no standardSampleLocations"));
    }
    let counts = sample_counts(ctx);
    if counts.is_empty() {
        return Ok(CheckResult::skipped(NAME, "skipped: no 2, 4 or 8 samples for a sampled depth attachment"));
    }
    let mut fails = Vec::new();
    let mut numbers = serde_json::Map::new();
    for &n in &counts {
        let t = judge(n, &render_samples(ctx, n, true)?, &render_samples(ctx, n, false)?);
        let standard = standard_sample_locations(n);
        // The test seam: every location expected a sixteenth of a pixel right of its own.
        let skew = if crate::value_images::skewed() { 1.0 / 16.0 } else { 0.0 };
        let expected: Vec<(f64, f64)> = standard.iter().map(|&(x, y)| (x + skew, y)).collect();
        let mut off = Vec::new();
        for (k, (&(sx, sy), &(dx, dy))) in expected.iter().zip(&t.depth_at).enumerate() {
            if (dx - sx).abs() > 1e-3 || (dy - sy).abs() > 1e-3 {
                off.push(format!("sample {k} at ({dx:.4}, {dy:.4}), not ({sx}, {sy})"));
            }
        }
        if t.coverage_mismatches > 0 {
            fails.push(format!("{n} samples: {} samples' coverage differs from the standard locations'", t.coverage_mismatches));
        }
        if t.depth_mismatches > 0 {
            fails.push(format!(
                "{n} samples: {} samples' depth is not the plane's at their standard location; depth evaluated at: {}",
                t.depth_mismatches,
                if off.is_empty() { "the standard locations (median)".to_string() } else { off.join(", ") }
            ));
        } else if !off.is_empty() {
            fails.push(format!("{n} samples: depth evaluated at {}", off.join(", ")));
        }
        if t.coverage_mismatches + t.depth_mismatches > 0 || !off.is_empty() {
            // Green: where each sample's depth should be evaluated; red: where it was.
            let pt = |v: &[(f64, f64)]| -> Vec<[f32; 2]> { v.iter().map(|&(x, y)| [x as f32, y as f32]).collect() };
            crate::value_images::points(&format!("samples_{n}.depth_locations"), &pt(&expected), &pt(&t.depth_at), 1e-3);
        }
        let at: Vec<[f64; 2]> = t.depth_at.iter().map(|&(x, y)| [x, y]).collect();
        numbers.insert(
            format!("samples_{n}"),
            json!({
                "coverage_mismatches": t.coverage_mismatches,
                "depth_mismatches": t.depth_mismatches,
                "compared": 2 * n * SIZE * SIZE,
                "depth_evaluated_at": at,
                "standard_locations": standard,
            }),
        );
    }
    numbers.insert("sample_counts".into(), json!(counts));
    Ok(CheckResult::from_fails(NAME, fails, numbers, "every sample's coverage and depth at its standard location"))
}
