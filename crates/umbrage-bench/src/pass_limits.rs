//! The limits of the frame's two host passes, each measured through a pipeline of its own on an
//! offscreen target of the frame's size, swept to saturation (the workload doubles until the
//! rate gains under 5 % twice running):
//!
//! | limit | what is drawn | what it bounds |
//! |---|---|---|
//! | lighting | full-screen triangles through `fullscreen.vert` and `shaders/lighting_limit.frag`: the illumination pass's three G-buffer reads (texelFetch of position, normal, albedo in their formats), its background test and its additive blend into [`ACCUM_FORMAT`], stencil test EQUAL 0 as the stencil pass, without the Blinn-Phong math; every pixel foreground and unshadowed | the illumination pass per pixel it covers (`lighting_gpix_s`) |
//! | G-buffer geometry | the G-buffer pipeline itself (`gbuffer.vert` / `gbuffer.frag`, its vertex layout, four colour targets and depth LESS with writes, two-sided), non-indexed as the pass draws, over a grid of 2-pixel triangles (the target's first rows, at most 16384 triangles a draw), each draw nearer than the last (every fragment passes the depth test and writes) | the G-buffer pass per triangle (`gbuffer_tri_mtri_s`) |
//!
//! | G-buffer fill | full-screen layers through the same pipeline, each nearer than the last | the G-buffer pass per pixel it writes (`gbuffer_fill_gpix_s`) |
//!
//! `bench::classic` sets each pass's time against these: the pixels the lighting passes cover
//! (every light's scissor) at `lighting_gpix_s`, the opaque triangles at `gbuffer_tri_mtri_s`.

use super::saturate::{depth_stencil, saturate, time_gpu, Rules};
use super::workloads::small_triangles;
use crate::shaders;
use ash::vk;
use glam::Mat4;
use umbrage::error::{Error, Result};
use umbrage::gpu::descriptors::{pipeline_layout, Binding, DescriptorSet};
use umbrage::gpu::pipeline::{self, Blend, PipelineDesc};
use umbrage::gpu::resources::{memory_barrier, transition};
use umbrage::gpu::{Buffer, Context, Image};
use umbrage_render::push::{GBufferPush, LightPush};
use umbrage_render::scene_gpu::{GBUFFER_ATTRIBUTES, INSTANCE_BYTES, SCENE_VERTEX_STRIDE};
use umbrage_render::targets::{ACCUM_FORMAT, ALBEDO_FORMAT, NORMAL_FORMAT, POSITION_FORMAT};

/// The measured limits and their sweeps.
#[derive(Clone, Debug, Default)]
pub struct PassLimits {
    /// Lighting: pixels a second, Gpixels / s.
    pub lighting_gpix_s: f64,
    /// Its sweep: `[pixels, Gpixels / s]` per point.
    pub lighting_sweep: Vec<[f64; 2]>,
    /// Ablation, not a limit: the real `illuminate.frag` (Blinn-Phong, every pixel lit, an
    /// unbounded point light) through the same pipeline state and sweep, Gpixels / s.
    pub lighting_shaded_gpix_s: f64,
    /// Its sweep: `[pixels, Gpixels / s]` per point (the first: one shaded draw in its own
    /// rendering instance, as each light's pass is drawn).
    pub lighting_shaded_sweep: Vec<[f64; 2]>,
    /// Ablation: one rendering instance of the lighting state with no draw (the accumulation
    /// and depth-stencil targets loaded and stored), the median, ms: what every light's
    /// illumination pays before its first pixel.
    pub lighting_instance_ms: f64,
    /// G-buffer geometry: triangles a second, Mtriangles / s.
    pub gbuffer_tri_mtri_s: f64,
    /// Its sweep: `[triangles, Mtriangles / s]` per point.
    pub gbuffer_sweep: Vec<[f64; 2]>,
    /// G-buffer fill: full-screen layers through the same pipeline, every fragment written to
    /// the four targets and depth, Gpixels / s.
    pub gbuffer_fill_gpix_s: f64,
    /// Its sweep: `[pixels, Gpixels / s]` per point.
    pub gbuffer_fill_sweep: Vec<[f64; 2]>,
}

/// The objects made, destroyed whatever happens.
#[derive(Default)]
struct Made {
    /// accum, albedo, normal, position, depth-stencil.
    images: Vec<Image>,
    buffers: Vec<Buffer>,
    pipelines: Vec<vk::Pipeline>,
    layouts: Vec<vk::PipelineLayout>,
    sampler: vk::Sampler,
    set: Option<DescriptorSet>,
    queries: vk::QueryPool,
}

/// Measures both limits on a `width` x `height` target: `reps` timed repetitions a point
/// (median), at most `max_steps` doublings a sweep.
pub fn measure(ctx: &Context, width: u32, height: u32, reps: usize, max_steps: u32) -> Result<PassLimits> {
    let mut made = Made::default();
    let r = measure_with(ctx, width.max(16), height.max(16), reps.max(1), max_steps.max(2), &mut made);
    // SAFETY: one_shot waited for every submission: nothing is in use; null handles are ignored.
    unsafe {
        let d = &ctx.device;
        let _ = d.device_wait_idle();
        for p in &made.pipelines {
            d.destroy_pipeline(*p, None);
        }
        for l in &made.layouts {
            d.destroy_pipeline_layout(*l, None);
        }
        d.destroy_query_pool(made.queries, None);
    }
    if let Some(s) = &mut made.set {
        s.destroy(ctx);
    }
    // SAFETY: the set that used the sampler is gone; null is ignored.
    unsafe { ctx.device.destroy_sampler(made.sampler, None) };
    for b in &mut made.buffers {
        b.destroy(ctx);
    }
    for i in &mut made.images {
        i.destroy(ctx);
    }
    r
}

const ACCUM: usize = 0;
/// Triangles a draw of the G-buffer limit's grid, at most.
const GRID_TRIANGLES: usize = 16_384;
const DS: usize = 4;

fn color_att(img: &Image, load: vk::AttachmentLoadOp, clear: [f32; 4]) -> vk::RenderingAttachmentInfo<'static> {
    vk::RenderingAttachmentInfo::default()
        .image_view(img.view)
        .image_layout(vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL)
        .load_op(load)
        .store_op(vk::AttachmentStoreOp::STORE)
        .clear_value(vk::ClearValue { color: vk::ClearColorValue { float32: clear } })
}

fn ds_att(img: &Image, load: vk::AttachmentLoadOp) -> vk::RenderingAttachmentInfo<'static> {
    vk::RenderingAttachmentInfo::default()
        .image_view(img.view)
        .image_layout(vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL)
        .load_op(load)
        .store_op(vk::AttachmentStoreOp::STORE)
        .clear_value(vk::ClearValue { depth_stencil: vk::ClearDepthStencilValue { depth: 1.0, stencil: 0 } })
}

/// The pass limits' images, sampler, descriptor set, layouts, timestamp queries and pipelines,
/// each recorded in `made` (which `measure` destroys).
struct Objects {
    set_handle: vk::DescriptorSet,
    light_layout: vk::PipelineLayout,
    gb_layout: vk::PipelineLayout,
    lighting: vk::Pipeline,
    shaded: vk::Pipeline,
    gbuffer: vk::Pipeline,
}

fn objects(ctx: &Context, extent: vk::Extent2D, made: &mut Made) -> Result<Objects> {
    let d = &ctx.device;
    let color = vk::ImageUsageFlags::COLOR_ATTACHMENT;
    let sampled = color | vk::ImageUsageFlags::SAMPLED;
    for (name, format, usage) in [
        ("pass limits: accum", ACCUM_FORMAT, color),
        ("pass limits: albedo", ALBEDO_FORMAT, sampled),
        ("pass limits: normal", NORMAL_FORMAT, sampled),
        ("pass limits: position", POSITION_FORMAT, sampled),
    ] {
        made.images.push(Image::new_2d(ctx, name, format, extent, usage, vk::ImageAspectFlags::COLOR)?);
    }
    made.images.push(depth_stencil(ctx, "pass limits: depth-stencil", extent)?);
    // SAFETY: creation on a valid device; destroyed by `measure`.
    made.sampler = unsafe {
        d.create_sampler(&vk::SamplerCreateInfo::default().mag_filter(vk::Filter::NEAREST).min_filter(vk::Filter::NEAREST), None)
    }
    .map_err(Error::vk("vkCreateSampler"))?;
    let im = &made.images;
    let set = DescriptorSet::new(
        ctx,
        &[Binding::Image(im[1].view), Binding::Image(im[2].view), Binding::Image(im[3].view), Binding::Sampler(made.sampler)],
    )?;
    let (set_layout, set_handle) = (set.layout, set.set);
    made.set = Some(set);
    let light_push = std::mem::size_of::<LightPush>() as u32;
    let light_layout = pipeline_layout(ctx, &[set_layout], light_push, vk::ShaderStageFlags::FRAGMENT)?;
    made.layouts.push(light_layout);
    let vf = vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT;
    let gb_layout = pipeline_layout(ctx, &[], std::mem::size_of::<GBufferPush>() as u32, vf)?;
    made.layouts.push(gb_layout);
    // SAFETY: creation on a valid device; destroyed by `measure`.
    made.queries =
        unsafe { d.create_query_pool(&vk::QueryPoolCreateInfo::default().query_type(vk::QueryType::TIMESTAMP).query_count(2), None) }
            .map_err(Error::vk("vkCreateQueryPool"))?;

    // The illumination pass's state: full-screen triangle, stencil EQUAL 0, additive blend.
    let accum_formats = [ACCUM_FORMAT];
    let mut lp = PipelineDesc::new(shaders::FULLSCREEN_VERT, light_layout, ctx.depth_format);
    lp.fragment = Some(shaders::LIGHTING_LIMIT_FRAG);
    lp.color_formats = &accum_formats;
    lp.blend = Blend::Additive;
    lp.stencil = Some((umbrage::pass::lit_stencil_state(), umbrage::pass::lit_stencil_state()));
    let lighting = pipeline::create(ctx, &lp)?;
    made.pipelines.push(lighting);
    lp.fragment = Some(shaders::ILLUMINATE_FRAG);
    let shaded = pipeline::create(ctx, &lp)?;
    made.pipelines.push(shaded);
    // The G-buffer pass's pipeline (as `render::pipelines` makes it, two-sided).
    let gformats = [ACCUM_FORMAT, ALBEDO_FORMAT, NORMAL_FORMAT, POSITION_FORMAT];
    let mut g = umbrage_render::pipelines::scene_pipeline(shaders::GBUFFER_VERT, gb_layout, ctx.depth_format);
    g.fragment = Some(shaders::GBUFFER_FRAG);
    g.attributes = &GBUFFER_ATTRIBUTES;
    g.color_formats = &gformats;
    g.depth_test = true;
    g.depth_write = true;
    g.depth_compare = vk::CompareOp::LESS;
    let gbuffer = pipeline::create(ctx, &g)?;
    made.pipelines.push(gbuffer);
    Ok(Objects { set_handle, light_layout, gb_layout, lighting, shaded, gbuffer })
}

/// The G-buffer limit's grid, the identity instance record and the fill limit's full-screen
/// quad, into `made.buffers` (in that order); the grid's and the quad's vertex counts.
fn buffers(ctx: &Context, w: u32, h: u32, made: &mut Made) -> Result<(usize, usize)> {
    // The grid in the scene vertex layout (14 floats): position (clip space, the push's
    // view_proj the identity), face normal, colour, opacity, smooth normal, bound.
    // The grid's first rows, at most GRID_TRIANGLES (a point of the sweep then stays well under
    // its 400 ms on a software rasteriser, and the sweep has room to saturate).
    let grid: Vec<[f32; 14]> = small_triangles(w, h)
        .iter()
        .take(3 * GRID_TRIANGLES)
        .map(|p| [p[0], p[1], 0.9, 0.0, 0.0, 1.0, 0.6, 0.5, 0.4, 1.0, 0.0, 0.0, 1.0, 0.0])
        .collect();
    debug_assert_eq!(std::mem::size_of::<[f32; 14]>() as u32, SCENE_VERTEX_STRIDE);
    let vb = Buffer::with_data(ctx, "pass limits: grid", bytemuck::cast_slice(&grid), vk::BufferUsageFlags::VERTEX_BUFFER)?;
    made.buffers.push(vb);
    // One instance record: the identity placement (3 rows of positions, 3 of normals).
    let rows: [[f32; 4]; 6] = [
        [1.0, 0.0, 0.0, 0.0],
        [0.0, 1.0, 0.0, 0.0],
        [0.0, 0.0, 1.0, 0.0],
        [1.0, 0.0, 0.0, 0.0],
        [0.0, 1.0, 0.0, 0.0],
        [0.0, 0.0, 1.0, 0.0],
    ];
    debug_assert_eq!(std::mem::size_of_val(&rows) as u64, INSTANCE_BYTES);
    let ib = Buffer::with_data(ctx, "pass limits: instance", bytemuck::cast_slice(&rows), vk::BufferUsageFlags::VERTEX_BUFFER)?;
    made.buffers.push(ib);
    // A full-screen quad in the same layout (the fill limit's layer).
    let quad: Vec<[f32; 14]> = [[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]]
        .iter()
        .map(|p| [p[0], p[1], 0.9, 0.0, 0.0, 1.0, 0.6, 0.5, 0.4, 1.0, 0.0, 0.0, 1.0, 0.0])
        .collect();
    let qb = Buffer::with_data(ctx, "pass limits: quad", bytemuck::cast_slice(&quad), vk::BufferUsageFlags::VERTEX_BUFFER)?;
    made.buffers.push(qb);
    Ok((grid.len(), quad.len()))
}

fn measure_with(ctx: &Context, w: u32, h: u32, reps: usize, max_steps: u32, made: &mut Made) -> Result<PassLimits> {
    if !ctx.features.timestamps {
        return Err(Error::Unsupported("the pass limits need timestamp queries, which this device lacks".into()));
    }
    let d = &ctx.device;
    let extent = vk::Extent2D { width: w, height: h };
    let vf = vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT;
    let Objects { set_handle, light_layout, gb_layout, lighting, shaded, gbuffer } = objects(ctx, extent, made)?;
    let (grid_len, quad_len) = buffers(ctx, w, h, made)?;
    let (vb, ib, qb) = (made.buffers[0].raw, made.buffers[1].raw, made.buffers[2].raw);
    let tris = (grid_len / 3) as f64;
    let im = &made.images;
    let area = vk::Rect2D { offset: vk::Offset2D { x: 0, y: 0 }, extent };
    let viewport = vk::Viewport { x: 0.0, y: 0.0, width: w as f32, height: h as f32, min_depth: 0.0, max_depth: 1.0 };
    let all = (vk::PipelineStageFlags2::ALL_COMMANDS, vk::AccessFlags2::MEMORY_READ | vk::AccessFlags2::MEMORY_WRITE);

    // G-buffer: every target from UNDEFINED, cleared, then `k` draws of the grid, draw i at
    // depth 0.9 - i * step (LESS: every fragment passes and writes).
    let gb_prep = |cb: vk::CommandBuffer| {
        for img in &im[..DS] {
            transition(ctx, cb, img, vk::ImageLayout::UNDEFINED, vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL);
        }
        transition(ctx, cb, &im[DS], vk::ImageLayout::UNDEFINED, vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL);
        let cols: Vec<_> = im[..DS].iter().map(|i| color_att(i, vk::AttachmentLoadOp::CLEAR, [0.0; 4])).collect();
        clear(ctx, cb, area, &cols, &ds_att(&im[DS], vk::AttachmentLoadOp::CLEAR));
        memory_barrier(ctx, cb, all, all);
    };
    let gb_timed = |cb: vk::CommandBuffer, (vb, count): (vk::Buffer, u32), k: u32| {
        let cols: Vec<_> = im[..DS].iter().map(|i| color_att(i, vk::AttachmentLoadOp::LOAD, [0.0; 4])).collect();
        begin(ctx, cb, area, &cols, &ds_att(&im[DS], vk::AttachmentLoadOp::LOAD));
        let step = 0.8 / k.max(1) as f32;
        // SAFETY: `cb` is recording inside the instance begun above; every handle outlives the
        // submission (one_shot waits).
        unsafe {
            d.cmd_set_viewport(cb, 0, &[viewport]);
            d.cmd_set_scissor(cb, 0, &[area]);
            d.cmd_bind_pipeline(cb, vk::PipelineBindPoint::GRAPHICS, gbuffer);
            d.cmd_bind_vertex_buffers(cb, 0, &[vb, ib], &[0, 0]);
            for i in 0..k {
                let vp = Mat4::from_translation(glam::Vec3::new(0.0, 0.0, -(i as f32) * step));
                let push = GBufferPush { view_proj: vp.to_cols_array(), ambient: [0.1, 0.1, 0.1, 0.0] };
                d.cmd_push_constants(cb, gb_layout, vf, 0, bytemuck::bytes_of(&push));
                d.cmd_draw(cb, count, 1, 0, 0);
            }
            d.cmd_end_rendering(cb);
        }
    };
    let queries = made.queries;
    let rules = Rules { max_steps, max_ms: 400.0 };
    let sweep = |units: f64, unit: f64, prep: &dyn Fn(vk::CommandBuffer), timed: &dyn Fn(vk::CommandBuffer, u32)| {
        saturate(rules, units, unit, |k| time_gpu(ctx, queries, reps, prep, &|cb| timed(cb, k)))
    };
    let grid_draw = (vb, grid_len as u32);
    let (gbuffer_tri_mtri_s, gbuffer_sweep) = sweep(tris, 1e6, &gb_prep, &|cb, k| gb_timed(cb, grid_draw, k))?;
    let quad_draw = (qb, quad_len as u32);
    let layer = w as f64 * h as f64;
    let (gbuffer_fill_gpix_s, gbuffer_fill_sweep) = sweep(layer, 1e9, &gb_prep, &|cb, k| gb_timed(cb, quad_draw, k))?;

    // Lighting: the G-buffer filled once (foreground everywhere: position w = 1), then per
    // repetition the accumulation target and the stencil cleared, `k` full-screen triangles.
    ctx.one_shot(|cb| {
        for img in &im[1..DS] {
            transition(ctx, cb, img, vk::ImageLayout::UNDEFINED, vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL);
        }
        let values = [[0.6, 0.5, 0.4, 0.1], [0.0, 0.0, 1.0, 8_390_656.0], [0.1, 0.2, -3.0, 1.0]];
        let cols: Vec<_> = im[1..DS].iter().zip(values).map(|(i, v)| color_att(i, vk::AttachmentLoadOp::CLEAR, v)).collect();
        let info = vk::RenderingInfo::default().render_area(area).layer_count(1).color_attachments(&cols);
        // SAFETY: `cb` is recording; the images are in attachment layout.
        unsafe {
            d.cmd_begin_rendering(cb, &info);
            d.cmd_end_rendering(cb);
        }
        for img in &im[1..DS] {
            transition(ctx, cb, img, vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL, vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL);
        }
    })?;
    let light_prep = |cb: vk::CommandBuffer| {
        transition(ctx, cb, &im[ACCUM], vk::ImageLayout::UNDEFINED, vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL);
        transition(ctx, cb, &im[DS], vk::ImageLayout::UNDEFINED, vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL);
        clear(
            ctx,
            cb,
            area,
            &[color_att(&im[ACCUM], vk::AttachmentLoadOp::CLEAR, [0.0; 4])],
            &ds_att(&im[DS], vk::AttachmentLoadOp::CLEAR),
        );
        memory_barrier(ctx, cb, all, all);
    };
    // An unbounded white point light at the eye: every pixel (position (0.1, 0.2, -3), normal
    // +z) faces it and is lit.
    let push = LightPush { light_pos: [0.0, 0.0, 0.0, 1.0], color: [1.0, 1.0, 1.0, 0.0], spot: [0.0, 0.0, -1.0, -2.0], params: [0.0; 4] };
    let light_timed = |cb: vk::CommandBuffer, pipe: vk::Pipeline, k: u32| {
        begin(ctx, cb, area, &[color_att(&im[ACCUM], vk::AttachmentLoadOp::LOAD, [0.0; 4])], &ds_att(&im[DS], vk::AttachmentLoadOp::LOAD));
        // SAFETY: `cb` is recording inside the instance begun above; the G-buffer is in
        // SHADER_READ_ONLY_OPTIMAL (the set's contract); every handle outlives the submission
        // (one_shot waits).
        unsafe {
            d.cmd_set_viewport(cb, 0, &[viewport]);
            d.cmd_set_scissor(cb, 0, &[area]);
            d.cmd_bind_pipeline(cb, vk::PipelineBindPoint::GRAPHICS, pipe);
            d.cmd_bind_descriptor_sets(cb, vk::PipelineBindPoint::GRAPHICS, light_layout, 0, &[set_handle], &[]);
            d.cmd_push_constants(cb, light_layout, vk::ShaderStageFlags::FRAGMENT, 0, bytemuck::bytes_of(&push));
            for _ in 0..k {
                d.cmd_draw(cb, 3, 1, 0, 0);
            }
            d.cmd_end_rendering(cb);
        }
    };
    let px = w as f64 * h as f64;
    let (lighting_gpix_s, lighting_sweep) = sweep(px, 1e9, &light_prep, &|cb, k| light_timed(cb, lighting, k))?;
    let (lighting_shaded_gpix_s, lighting_shaded_sweep) = sweep(px, 1e9, &light_prep, &|cb, k| light_timed(cb, shaded, k))?;
    let lighting_instance_ms = time_gpu(ctx, queries, reps, &light_prep, &|cb| light_timed(cb, lighting, 0))?;
    Ok(PassLimits {
        lighting_gpix_s,
        lighting_sweep,
        lighting_shaded_gpix_s,
        lighting_shaded_sweep,
        lighting_instance_ms,
        gbuffer_tri_mtri_s,
        gbuffer_sweep,
        gbuffer_fill_gpix_s,
        gbuffer_fill_sweep,
    })
}

/// Begins a rendering instance over `area` into `cols` with `ds` as its depth and stencil
/// attachment (`cb` recording outside any instance, every image in the layout its attachment
/// declares).
fn begin(ctx: &Context, cb: vk::CommandBuffer, area: vk::Rect2D, cols: &[vk::RenderingAttachmentInfo], ds: &vk::RenderingAttachmentInfo) {
    let info =
        vk::RenderingInfo::default().render_area(area).layer_count(1).color_attachments(cols).depth_attachment(ds).stencil_attachment(ds);
    // SAFETY: the caller records `cb` outside any instance, with the attachments' images in
    // their declared layouts (every caller here transitions them first).
    unsafe { ctx.device.cmd_begin_rendering(cb, &info) };
}

/// A rendering instance that only clears (or loads) its attachments: [`begin`], then its end.
fn clear(ctx: &Context, cb: vk::CommandBuffer, area: vk::Rect2D, cols: &[vk::RenderingAttachmentInfo], ds: &vk::RenderingAttachmentInfo) {
    begin(ctx, cb, area, cols, ds);
    // SAFETY: `cb` is inside the instance just begun.
    unsafe { ctx.device.cmd_end_rendering(cb) };
}
