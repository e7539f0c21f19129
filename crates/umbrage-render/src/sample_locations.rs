//! Where a device evaluates a multisampled draw's depth, per sample: the sloped-plane
//! measurement [`calibrate_sample_locations`] hands a renderer (so a multisampled capture's
//! positions are found where its depth tests looked) and the conformance check
//! `legacy.msaa_depth_locations` judges (umbrage-conform).
//!
//! A plane whose depth grows by 1/64 a pixel along x (then, in a second render, along y) is
//! drawn at `n` samples into the context's depth format (sampled), over a rectangle whose right
//! (bottom) edge runs through the middle of a pixel column (row), so that column's samples
//! left of the edge are covered and the others not. Every sample of every pixel is read back
//! (a full-screen pass per sample, `shaders/sample_readback.frag`) and compared with the plane
//! evaluated at the sample's standard location (`standardSampleLocations`, Vulkan's
//! "Multisampling" table): coverage exact, depth within 1e-5 (a quarter pixel off is 0.0039).
//! Where depth is off, the location it was evaluated at is recovered from the two gradients.
//!
//! SwiftShader's coverage is at the standard locations, its depth at the locations mirrored in
//! x about the pixel centre (docs/conform/drivers-notes.md §1f).

use crate::shaders;
use crate::standard_sample_locations;
use ash::vk;
use gpu_allocator::MemoryLocation;
use umbrage::error::{Error, Result};
use umbrage::gpu::descriptors::{pipeline_layout, Binding, DescriptorSet};
use umbrage::gpu::pipeline::{self, PipelineDesc};
use umbrage::gpu::resources::{aspect_copy, cleared_depth_stencil, transfer_to_host_barrier, transition};
use umbrage::gpu::{Buffer, Context, Image};

/// The side of the measured square, pixels.
pub const SIZE: u32 = 16;
/// Depth at x (or y) = 0 and its growth per pixel: exact in f32 at every 1/16 pixel.
const Z0: f64 = 0.25;
const SLOPE: f64 = 1.0 / 64.0;
/// The covered rectangle ends half-way through this column (x render) or row (y render).
const EDGE: f64 = 8.5;
const TOLERANCE: f64 = 1e-5;

/// Sample counts of 2, 4 and 8 the context's depth format supports as a sampled depth
/// attachment (the counts [`measure`] can measure).
pub fn sample_counts(ctx: &Context) -> Vec<u32> {
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

/// The rectangle `[x0, y0, x1, y1]` (pixels) as two triangles, each front facing under
/// `VK_FRONT_FACE_COUNTER_CLOCKWISE` in framebuffer coordinates, at depth 0.5.
fn rect(r: [f32; 4]) -> Vec<[f32; 4]> {
    let [x0, y0, x1, y1] = r;
    let mut out = Vec::new();
    for t in [[[x0, y0], [x0, y1], [x1, y1]], [[x0, y0], [x1, y1], [x1, y0]]] {
        // Vulkan's signed area, -1/2 sum(x_i y_(i+1) - x_(i+1) y_i): positive is front facing.
        let s: f64 = (0..3).map(|i| (t[i][0] as f64) * (t[(i + 1) % 3][1] as f64) - (t[(i + 1) % 3][0] as f64) * (t[i][1] as f64)).sum();
        let t = if -0.5 * s > 0.0 { t } else { [t[0], t[2], t[1]] };
        out.extend(t.iter().map(|p| [p[0], p[1], 0.5, 1.0]));
    }
    out
}

/// Orthographic pixel mapping: object (x, y) in pixels (row 0 at the top), z as given.
fn pixel_ortho(width: u32, height: u32) -> glam::Mat4 {
    glam::Mat4::from_cols(
        glam::Vec4::new(2.0 / width as f32, 0.0, 0.0, 0.0),
        glam::Vec4::new(0.0, 2.0 / height as f32, 0.0, 0.0),
        glam::Vec4::new(0.0, 0.0, 1.0, 0.0),
        glam::Vec4::new(-1.0, -1.0, 0.0, 1.0),
    )
}

/// Renders the plane (depth growing along x when `along_x`, else along y) at `n` samples and
/// reads every sample back: `[sample][pixel]` depth values.
fn render_samples(ctx: &Context, n: u32, along_x: bool) -> Result<Vec<Vec<f32>>> {
    let s = SIZE as f32;
    let r = if along_x { [0.0, 0.0, EDGE as f32, s] } else { [0.0, 0.0, s, EDGE as f32] };
    let mut v = rect(r);
    for p in &mut v {
        p[2] = (Z0 + SLOPE * if along_x { p[0] } else { p[1] } as f64) as f32;
    }
    let mut objects = Objects::default();
    let result = render_inner(ctx, n, &v, &mut objects);
    objects.destroy(ctx);
    result
}

/// Creates the plane's pipeline (shadow.vert, depth test ALWAYS and writes, stencil kept, `n`
/// samples) and vertex buffer into `o`: (pipeline, layout, vertex buffer, vertex count, push).
fn plane_draw(
    ctx: &Context,
    n: u32,
    vertices: &[[f32; 4]],
    o: &mut Objects,
) -> Result<(vk::Pipeline, vk::PipelineLayout, vk::Buffer, Vec<u8>)> {
    o.plane_layout = pipeline_layout(ctx, &[], 96, vk::ShaderStageFlags::VERTEX)?;
    let keep = pipeline::stencil_ops(vk::StencilOp::KEEP, vk::StencilOp::KEEP);
    let mut desc = PipelineDesc::new(shaders::SHADOW_VERT, o.plane_layout, ctx.depth_format);
    desc.vertex_stride = 16;
    desc.attributes = &[(0, vk::Format::R32G32B32A32_SFLOAT, 0)];
    desc.depth_test = true;
    desc.depth_write = true;
    desc.depth_compare = vk::CompareOp::ALWAYS;
    desc.stencil = Some((keep, keep));
    desc.samples = vk::SampleCountFlags::from_raw(n);
    o.plane = pipeline::create(ctx, &desc)?;
    o.buffers.push(Buffer::with_data(ctx, "sample-locations-plane", bytemuck::cast_slice(vertices), vk::BufferUsageFlags::VERTEX_BUFFER)?);
    // shadow.vert's block; w = 1 vertices are transformed as they are.
    let push = umbrage::pass::push::VolumePush::new(pixel_ortho(SIZE, SIZE), glam::Vec4::W, [0.0; 4]);
    Ok((o.plane, o.plane_layout, o.buffers.last().expect("pushed").raw, bytemuck::bytes_of(&push).to_vec()))
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
    plane_layout: vk::PipelineLayout,
    plane: vk::Pipeline,
}

impl Objects {
    fn destroy(mut self, ctx: &Context) {
        // SAFETY: after the wait nothing is in use; null handles are ignored.
        unsafe {
            let _ = ctx.device.device_wait_idle();
            ctx.device.destroy_pipeline(self.pipeline, None);
            ctx.device.destroy_pipeline_layout(self.layout, None);
            ctx.device.destroy_pipeline(self.plane, None);
            ctx.device.destroy_pipeline_layout(self.plane_layout, None);
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

fn render_inner(ctx: &Context, n: u32, vertices: &[[f32; 4]], o: &mut Objects) -> Result<Vec<Vec<f32>>> {
    let extent = vk::Extent2D { width: SIZE, height: SIZE };
    let area = vk::Rect2D { offset: vk::Offset2D { x: 0, y: 0 }, extent };
    let ds_aspects = vk::ImageAspectFlags::DEPTH | vk::ImageAspectFlags::STENCIL;
    let ds_usage = vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT | vk::ImageUsageFlags::SAMPLED;
    let samples = vk::SampleCountFlags::from_raw(n);
    o.images.push(Image::new_2d_samples(ctx, "sample-locations-depth", ctx.depth_format, extent, ds_usage, ds_aspects, samples)?);
    let out_format = vk::Format::R32G32B32A32_SFLOAT;
    let out_usage = vk::ImageUsageFlags::COLOR_ATTACHMENT | vk::ImageUsageFlags::TRANSFER_SRC;
    o.images.push(Image::new_2d(ctx, "sample-locations-out", out_format, extent, out_usage, vk::ImageAspectFlags::COLOR)?);
    let texel_bytes = 16u64;
    let per_sample = (SIZE * SIZE) as u64 * texel_bytes;
    o.buffers.push(Buffer::new(
        ctx,
        "sample-locations-readback",
        per_sample * n as u64,
        vk::BufferUsageFlags::TRANSFER_DST,
        MemoryLocation::GpuToCpu,
    )?);
    // After the read-back buffer (`o.buffers[0]`).
    let (plane, plane_layout, plane_vb, plane_push) = plane_draw(ctx, n, vertices, o)?;
    let vertex_count = vertices.len() as u32;
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
            d.cmd_bind_pipeline(cb, vk::PipelineBindPoint::GRAPHICS, plane);
            d.cmd_push_constants(cb, plane_layout, vk::ShaderStageFlags::VERTEX, 0, &plane_push);
            d.cmd_set_scissor(cb, 0, &[area]);
            d.cmd_bind_vertex_buffers(cb, 0, &[plane_vb], &[0]);
            d.cmd_draw(cb, vertex_count, 1, 0, 0);
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

/// What [`measure`] found at one sample count.
#[derive(Clone, Debug, Default)]
pub struct DepthLocations {
    /// Samples (of both renders) whose coverage differs from the standard locations'.
    pub coverage_mismatches: u64,
    /// Covered samples whose depth is not the plane's at their standard location (beyond 1e-5).
    pub depth_mismatches: u64,
    /// Per sample: the median location (x from the x render, y from the y render) its depth
    /// was evaluated at, over the covered pixels away from the edge (pixel units from the
    /// pixel's top-left corner; NaN where no covered sample was read back).
    pub depth_at: Vec<(f64, f64)>,
}

impl DepthLocations {
    /// Samples compared (both renders, every pixel).
    pub fn compared(n: u32) -> u32 {
        2 * n * SIZE * SIZE
    }
}

/// Renders the two sloped planes at `n` samples and judges every sample against the standard
/// locations (see the module docs). `None` where the depth format cannot be a sampled
/// attachment of `n` samples, or `n` is not 2, 4 or 8.
pub fn measure(ctx: &Context, n: u32) -> Result<Option<DepthLocations>> {
    if !sample_counts(ctx).contains(&n) {
        return Ok(None);
    }
    Ok(Some(judge(n, &render_samples(ctx, n, true)?, &render_samples(ctx, n, false)?)))
}

/// The median of `v` (NaN when empty).
fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v.get(v.len() / 2).copied().unwrap_or(f64::NAN)
}

fn judge(n: u32, x_render: &[Vec<f32>], y_render: &[Vec<f32>]) -> DepthLocations {
    let mut t = DepthLocations::default();
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
/// sloped-plane renders at `n` samples ([`measure`]: the context's depth format, sampled),
/// each sample's median location over the covered pixels. The standard locations on a conformant device;
/// SwiftShader's are mirrored in x (docs/conform/drivers-notes.md §1f). `None` where the
/// depth format cannot be a sampled attachment of `n` samples, or `n` is not 2, 4 or 8.
pub fn measure_depth_locations(ctx: &Context, n: u32) -> Result<Option<Vec<(f64, f64)>>> {
    let Some(t) = measure(ctx, n)? else { return Ok(None) };
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
/// ([`Renderer::use_sample_depth_locations`](crate::Renderer::use_sample_depth_locations)),
/// so a multisampled capture's positions are found where its depth tests looked. Nothing for a
/// one-sample renderer, or where the depth format cannot be sampled at its count (the
/// standard locations stay).
pub fn calibrate_sample_locations(renderer: &mut crate::Renderer) -> Result<()> {
    let n = renderer.config().samples;
    if n < 2 {
        return Ok(());
    }
    match measure_depth_locations(renderer.context(), n)? {
        Some(at) => renderer.use_sample_depth_locations(&at),
        None => Ok(()),
    }
}
