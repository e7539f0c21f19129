//! The device's limits, measured in the same run as the suite by micro-benchmarks of their own,
//! each a small pipeline of [`crate::gpu`] on an offscreen target of the suite's base size:
//!
//! | limit | what is drawn | counted as |
//! |---|---|---|
//! | stencil fill | full-screen quads, alternate windings, two-sided INCR_WRAP / DECR_WRAP, depth test LESS on | fragments / s |
//! | colour fill | full-screen quads into RGBA16F, additive blending, depth test LEQUAL on (the illumination pass's state) | fragments / s |
//! | small triangles | a grid of 2-pixel triangles over the whole target (stencil-only, as the shadow pass) | triangles / s |
//! | big triangles | screen-covering triangles (stencil-only) | triangles / s |
//! | slivers | 1-pixel-wide triangles from the centre past the edges (shadow-volume sides) | triangles / s |
//! | index fetch | one 256-vertex patch drawn through u8, u16 and u32 indices and as streamed 4 x f32 vertices | triangles / s |
//! | draw calls | one tiny triangle per `vkCmdDraw`, each with its push constants and vertex binding (as the shadow pass) | draws / s |
//! | CPU stream | a sum over a buffer far larger than the caches | GiB / s |
//!
//! GPU times come from timestamps written outside the rendering instances (on lavapipe those
//! inside do not include rasterisation); each limit is the median of several repetitions.
//! u8 indices need `VK_EXT_index_type_uint8`: without it the limit is skipped with the reason.

use crate::error::{Error, Result};
use crate::gpu::descriptors::pipeline_layout;
use crate::gpu::pipeline::{self, Blend, PipelineDesc};
use crate::gpu::resources::{memory_barrier, transition};
use crate::gpu::{shaders, Buffer, Context, Image};
use crate::pass::push::VolumePush;
use ash::vk;
use glam::{Mat4, Vec4};
use serde::Serialize;
use std::collections::BTreeMap;

/// The measured limits (the `limits` object of `bench.json`; units in the key names and in
/// [`Limits::units`]).
#[derive(Clone, Debug, Default, Serialize)]
pub struct Limits {
    /// Stencil-only fill, two-sided wrapping ops with the depth test on: Gfragments / s.
    pub stencil_fill_gfrag_s: f64,
    /// Depth-tested additive colour fill into RGBA16F: Gfragments / s.
    pub color_fill_gfrag_s: f64,
    /// Small (2-pixel) triangles, stencil-only: Mtriangles / s.
    pub small_tri_mtri_s: f64,
    /// Screen-covering triangles, stencil-only: Mtriangles / s.
    pub big_tri_mtri_s: f64,
    /// Slivers: triangles from the centre to past the target's edge, a pixel wide there (the
    /// shape of shadow-volume sides extruded to infinity: few fragments, a screen-sized
    /// bounding box), stencil-only: Mtriangles / s.
    pub sliver_tri_mtri_s: f64,
    /// Draw calls of one tiny triangle each: draws / s.
    pub draws_per_s: f64,
    /// The CPU's memory-stream read bandwidth (one thread): GiB / s.
    pub cpu_stream_gib_s: f64,
    /// Indexed small triangles through 8-bit indices: Mtriangles / s (`None`: skipped, see
    /// [`Limits::skipped`]).
    pub index_u8_mtri_s: Option<f64>,
    /// Through 16-bit indices: Mtriangles / s.
    pub index_u16_mtri_s: f64,
    /// Through 32-bit indices: Mtriangles / s.
    pub index_u32_mtri_s: f64,
    /// Non-indexed, every vertex streamed as 4 x f32 (the naive format): Mtriangles / s.
    pub index_naive_mtri_s: f64,
    /// Target the GPU limits were measured on, `[width, height]`.
    pub target: [u32; 2],
    /// Each key's unit.
    pub units: BTreeMap<String, String>,
    /// Limits that were not measured, and why.
    pub skipped: BTreeMap<String, String>,
}

/// How much to measure: repetitions per limit and the size of each workload.
#[derive(Clone, Copy, Debug)]
pub struct LimitsConfig {
    /// Target size (the suite's base resolution).
    pub width: u32,
    /// Target height.
    pub height: u32,
    /// Repetitions per limit (median taken), at least 1.
    pub reps: usize,
    /// Workload scale: 1.0 full, smaller for `--quick` (fewer layers, triangles, draws).
    pub scale: f64,
}

struct Target {
    ds: Image,
    color: Image,
    pool: vk::QueryPool,
    layout: vk::PipelineLayout,
    extent: vk::Extent2D,
}

/// A pipeline and its draws: what one timed repetition records.
struct Workload<'a> {
    pipe: vk::Pipeline,
    vertices: vk::Buffer,
    indices: Option<(vk::Buffer, vk::IndexType, u32)>,
    /// Vertices per non-indexed draw and how many such draws (one push each).
    draw: (u32, u32),
    clear_depth: f32,
    _p: std::marker::PhantomData<&'a ()>,
}

/// Measures every limit on `ctx` (GPU) and this machine (CPU stream).
pub fn measure(ctx: &Context, cfg: &LimitsConfig) -> Result<Limits> {
    let mut made: Vec<vk::Pipeline> = Vec::new();
    let mut buffers: Vec<Buffer> = Vec::new();
    let mut target: Option<Target> = None;
    let r = measure_with(ctx, cfg, &mut made, &mut buffers, &mut target);
    // SAFETY: one_shot waited for every submission: nothing in use.
    unsafe {
        let _ = ctx.device.device_wait_idle();
        for p in made {
            ctx.device.destroy_pipeline(p, None);
        }
        if let Some(t) = &target {
            ctx.device.destroy_query_pool(t.pool, None);
            ctx.device.destroy_pipeline_layout(t.layout, None);
        }
    }
    for b in &mut buffers {
        b.destroy(ctx);
    }
    if let Some(mut t) = target {
        t.ds.destroy(ctx);
        t.color.destroy(ctx);
    }
    r
}

fn bytes<T: bytemuck::Pod>(v: &[T]) -> &[u8] {
    bytemuck::cast_slice(v)
}

fn quad(z: f32, ccw: bool) -> [[f32; 4]; 6] {
    let (a, b, c, d) = ([-1.0, -1.0, z, 1.0], [1.0, -1.0, z, 1.0], [1.0, 1.0, z, 1.0], [-1.0, 1.0, z, 1.0]);
    if ccw {
        [a, b, c, a, c, d]
    } else {
        [a, c, b, a, d, c]
    }
}

fn measure_with(
    ctx: &Context,
    cfg: &LimitsConfig,
    made: &mut Vec<vk::Pipeline>,
    buffers: &mut Vec<Buffer>,
    target: &mut Option<Target>,
) -> Result<Limits> {
    let (w, h) = (cfg.width.max(16), cfg.height.max(16));
    let reps = cfg.reps.max(1);
    let extent = vk::Extent2D { width: w, height: h };
    let ds = Image::new_2d(
        ctx,
        "limits-ds",
        ctx.depth_format,
        extent,
        vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT,
        vk::ImageAspectFlags::DEPTH | vk::ImageAspectFlags::STENCIL,
    )?;
    let color = Image::new_2d(
        ctx,
        "limits-color",
        crate::render::targets::ACCUM_FORMAT,
        extent,
        vk::ImageUsageFlags::COLOR_ATTACHMENT,
        vk::ImageAspectFlags::COLOR,
    )?;
    let layout = pipeline_layout(ctx, &[], VolumePush::SIZE, vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT)?;
    // SAFETY: creation on a valid device; destroyed by `measure`.
    let pool = unsafe {
        ctx.device.create_query_pool(&vk::QueryPoolCreateInfo::default().query_type(vk::QueryType::TIMESTAMP).query_count(2), None)
    }
    .map_err(Error::vk("vkCreateQueryPool"))?;
    *target = Some(Target { ds, color, pool, layout, extent });
    let t = target.as_ref().ok_or_else(|| Error::Other("limits target".into()))?;
    if !ctx.features.timestamps {
        return Err(Error::Unsupported("the suite's limits need timestamp queries, which this device lacks".into()));
    }

    // Pipelines: stencil-only (the shadow pass's state) and depth-tested additive colour.
    let color_formats = [crate::render::targets::ACCUM_FORMAT];
    let mut base = PipelineDesc::new(shaders::SHADOW_VERT, layout, ctx.depth_format);
    base.vertex_stride = 16;
    base.attributes = &[(0, vk::Format::R32G32B32A32_SFLOAT, 0)];
    base.color_formats = &color_formats;
    base.color_write = false;
    base.depth_test = true;
    base.depth_compare = vk::CompareOp::LESS;
    use vk::StencilOp as S;
    base.stencil = Some((pipeline::stencil_ops(S::INCREMENT_AND_WRAP, S::KEEP), pipeline::stencil_ops(S::DECREMENT_AND_WRAP, S::KEEP)));
    let stencil_pipe = pipeline::create(ctx, &base)?;
    made.push(stencil_pipe);
    let mut c = base.clone();
    c.fragment = Some(shaders::VOLUME_FRAG);
    c.color_write = true;
    c.blend = Blend::Additive;
    c.stencil = None;
    c.depth_compare = vk::CompareOp::LESS_OR_EQUAL;
    let color_pipe = pipeline::create(ctx, &c)?;
    made.push(color_pipe);

    let mut upload = |name: &str, data: &[u8], usage: vk::BufferUsageFlags| -> Result<vk::Buffer> {
        let b = Buffer::with_data(ctx, name, data, usage)?;
        let raw = b.raw;
        buffers.push(b);
        Ok(raw)
    };
    let scaled = |n: f64| ((n * cfg.scale).round() as u32).max(1);
    let px = (w as f64) * (h as f64);

    // Fill: full-screen layers, alternate windings (two-sided ops both exercised).
    let layers = scaled(32.0);
    let mut fill: Vec<[f32; 4]> = Vec::new();
    for i in 0..layers {
        fill.extend(quad(0.5, i % 2 == 0));
    }
    let fill_vb = upload("limits-fill", bytes(&fill), vk::BufferUsageFlags::VERTEX_BUFFER)?;
    let mk =
        |pipe, _color: bool, vertices, indices, draw| Workload { pipe, vertices, indices, draw, clear_depth: 1.0, _p: Default::default() };
    let fill_frags = layers as f64 * 2.0 * px / 2.0; // two triangles a layer cover the target once
    let stencil_ms = time(ctx, t, &mk(stencil_pipe, false, fill_vb, None, (6 * layers, 1)), reps)?;
    let color_ms = time(ctx, t, &mk(color_pipe, true, fill_vb, None, (6 * layers, 1)), reps)?;

    // Small triangles: a grid of 2x2-pixel cells, each two 2-pixel triangles.
    let (gx, gy) = ((w / 2).max(1), (h / 2).max(1));
    let cells_wanted = (scaled(200_000.0) / 2) as u64;
    let step = ((gx as u64 * gy as u64) as f64 / cells_wanted as f64).sqrt().max(1.0);
    let mut small: Vec<[f32; 4]> = Vec::new();
    let (sx, sy) = (2.0 / w as f32 * 2.0, 2.0 / h as f32 * 2.0);
    let mut y = 0.0f64;
    while (y as u32) < gy {
        let mut x = 0.0f64;
        while (x as u32) < gx {
            let (x0, y0) = (-1.0 + (x as u32) as f32 * sx, -1.0 + (y as u32) as f32 * sy);
            let (a, b, c, d) = ([x0, y0, 0.5, 1.0], [x0 + sx, y0, 0.5, 1.0], [x0 + sx, y0 + sy, 0.5, 1.0], [x0, y0 + sy, 0.5, 1.0]);
            small.extend([a, b, c, a, c, d]);
            x += step;
        }
        y += step;
    }
    let small_tris = (small.len() / 3) as f64;
    let small_vb = upload("limits-small", bytes(&small), vk::BufferUsageFlags::VERTEX_BUFFER)?;
    let small_ms = time(ctx, t, &mk(stencil_pipe, false, small_vb, None, (small.len() as u32, 1)), reps)?;

    // Big triangles: each covers the target (a triangle twice its size, clipped).
    let big_n = scaled(48.0);
    let mut big: Vec<[f32; 4]> = Vec::new();
    for i in 0..big_n {
        let (a, b, c) = ([-1.0, -1.0, 0.5, 1.0], [3.0, -1.0, 0.5, 1.0], [-1.0, 3.0, 0.5, 1.0]);
        big.extend(if i % 2 == 0 { [a, b, c] } else { [a, c, b] });
    }
    let big_vb = upload("limits-big", bytes(&big), vk::BufferUsageFlags::VERTEX_BUFFER)?;
    let big_ms = time(ctx, t, &mk(stencil_pipe, false, big_vb, None, (3 * big_n, 1)), reps)?;

    // Slivers: a fan of 1-pixel-wide triangles from the centre out past the edges.
    let slivers = scaled(20_000.0);
    let mut sliver: Vec<[f32; 4]> = Vec::new();
    for i in 0..slivers {
        let a = std::f32::consts::TAU * i as f32 / slivers as f32;
        let (s, c) = a.sin_cos();
        let (ex, ey) = (1.5 * c, 1.5 * s);
        // One pixel across at the far end, perpendicular to the sliver.
        let (px, py) = (-s * 2.0 / w as f32, c * 2.0 / h as f32);
        sliver.extend([[0.0, 0.0, 0.5, 1.0], [ex, ey, 0.5, 1.0], [ex + px, ey + py, 0.5, 1.0]]);
    }
    let sliver_vb = upload("limits-sliver", bytes(&sliver), vk::BufferUsageFlags::VERTEX_BUFFER)?;
    let sliver_ms = time(ctx, t, &mk(stencil_pipe, false, sliver_vb, None, (3 * slivers, 1)), reps)?;

    // Index fetch: a 16x16-vertex patch (256 vertices: u8 can address it) of 2-pixel cells,
    // its 450 triangles repeated.
    let mut patch: Vec<[f32; 4]> = Vec::new();
    for j in 0..16 {
        for i in 0..16 {
            patch.push([-0.5 + i as f32 * sx, -0.5 + j as f32 * sy, 0.5, 1.0]);
        }
    }
    let mut tri_idx: Vec<u32> = Vec::new();
    for j in 0..15u32 {
        for i in 0..15u32 {
            let (a, b, c, d) = (j * 16 + i, j * 16 + i + 1, (j + 1) * 16 + i + 1, (j + 1) * 16 + i);
            tri_idx.extend([a, b, c, a, c, d]);
        }
    }
    let repeats = (scaled(200_000.0) as usize / 450).max(1);
    let idx32: Vec<u32> = tri_idx.iter().copied().cycle().take(tri_idx.len() * repeats).collect();
    let n_idx = idx32.len() as u32;
    let idx_tris = n_idx as f64 / 3.0;
    let patch_vb = upload("limits-patch", bytes(&patch), vk::BufferUsageFlags::VERTEX_BUFFER)?;
    let i32b = upload("limits-u32", bytes(&idx32), vk::BufferUsageFlags::INDEX_BUFFER)?;
    let idx16: Vec<u16> = idx32.iter().map(|&i| i as u16).collect();
    let i16b = upload("limits-u16", bytes(&idx16), vk::BufferUsageFlags::INDEX_BUFFER)?;
    let u16_ms = time(ctx, t, &mk(stencil_pipe, false, patch_vb, Some((i16b, vk::IndexType::UINT16, n_idx)), (0, 1)), reps)?;
    let u32_ms = time(ctx, t, &mk(stencil_pipe, false, patch_vb, Some((i32b, vk::IndexType::UINT32, n_idx)), (0, 1)), reps)?;
    let mut skipped = BTreeMap::new();
    let u8_ms = if ctx.features.index_type_uint8 {
        let idx8: Vec<u8> = idx32.iter().map(|&i| i as u8).collect();
        let i8b = upload("limits-u8", &idx8, vk::BufferUsageFlags::INDEX_BUFFER)?;
        Some(time(ctx, t, &mk(stencil_pipe, false, patch_vb, Some((i8b, vk::IndexType::UINT8_EXT, n_idx)), (0, 1)), reps)?)
    } else {
        skipped.insert("index_u8_mtri_s".to_string(), "VK_EXT_index_type_uint8 (indexTypeUint8) missing".to_string());
        None
    };
    let naive: Vec<[f32; 4]> = idx32.iter().map(|&i| patch[i as usize]).collect();
    let naive_vb = upload("limits-naive", bytes(&naive), vk::BufferUsageFlags::VERTEX_BUFFER)?;
    let naive_ms = time(ctx, t, &mk(stencil_pipe, false, naive_vb, None, (n_idx, 1)), reps)?;

    // Draw calls: one 1-pixel triangle each.
    let draws = scaled(20_000.0);
    let tiny: [[f32; 4]; 3] = [[0.0, 0.0, 0.5, 1.0], [sx / 2.0, 0.0, 0.5, 1.0], [0.0, sy / 2.0, 0.5, 1.0]];
    let tiny_vb = upload("limits-tiny", bytes(&tiny), vk::BufferUsageFlags::VERTEX_BUFFER)?;
    let draw_ms = time(ctx, t, &mk(stencil_pipe, false, tiny_vb, None, (3, draws)), reps)?;

    let mut units = BTreeMap::new();
    for (k, u) in [
        ("stencil_fill_gfrag_s", "Gfragments/s"),
        ("color_fill_gfrag_s", "Gfragments/s"),
        ("small_tri_mtri_s", "Mtriangles/s"),
        ("big_tri_mtri_s", "Mtriangles/s"),
        ("sliver_tri_mtri_s", "Mtriangles/s"),
        ("draws_per_s", "draws/s"),
        ("cpu_stream_gib_s", "GiB/s"),
        ("index_u8_mtri_s", "Mtriangles/s"),
        ("index_u16_mtri_s", "Mtriangles/s"),
        ("index_u32_mtri_s", "Mtriangles/s"),
        ("index_naive_mtri_s", "Mtriangles/s"),
    ] {
        units.insert(k.to_string(), u.to_string());
    }
    let rate = |n: f64, ms: f64, unit: f64| n / (ms.max(1e-6) * 1e-3) / unit;
    Ok(Limits {
        stencil_fill_gfrag_s: rate(fill_frags, stencil_ms, 1e9),
        color_fill_gfrag_s: rate(fill_frags, color_ms, 1e9),
        small_tri_mtri_s: rate(small_tris, small_ms, 1e6),
        big_tri_mtri_s: rate(big_n as f64, big_ms, 1e6),
        sliver_tri_mtri_s: rate(slivers as f64, sliver_ms, 1e6),
        draws_per_s: rate(draws as f64, draw_ms, 1.0),
        cpu_stream_gib_s: cpu_stream_gib_s(cfg.scale, reps),
        index_u8_mtri_s: u8_ms.map(|ms| rate(idx_tris, ms, 1e6)),
        index_u16_mtri_s: rate(idx_tris, u16_ms, 1e6),
        index_u32_mtri_s: rate(idx_tris, u32_ms, 1e6),
        index_naive_mtri_s: rate(idx_tris, naive_ms, 1e6),
        target: [w, h],
        units,
        skipped,
    })
}

/// Median GPU ms of `reps` repetitions of `wl` (each in its own submission, the target cleared
/// first in a rendering instance of its own, timestamps around the timed one).
fn time(ctx: &Context, t: &Target, wl: &Workload, reps: usize) -> Result<f64> {
    let mut ms = Vec::with_capacity(reps);
    let area = vk::Rect2D { offset: vk::Offset2D { x: 0, y: 0 }, extent: t.extent };
    let viewport =
        vk::Viewport { x: 0.0, y: 0.0, width: t.extent.width as f32, height: t.extent.height as f32, min_depth: 0.0, max_depth: 1.0 };
    let push = VolumePush::new(Mat4::IDENTITY, Vec4::W, [0.01, 0.01, 0.01, 0.0]);
    // One warm-up repetition (first-use costs), then the timed ones.
    for rep in 0..=reps {
        ctx.one_shot(|cb| {
            let all = (vk::PipelineStageFlags2::ALL_COMMANDS, vk::AccessFlags2::MEMORY_READ | vk::AccessFlags2::MEMORY_WRITE);
            transition(ctx, cb, &t.ds, vk::ImageLayout::UNDEFINED, vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL);
            transition(ctx, cb, &t.color, vk::ImageLayout::UNDEFINED, vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL);
            let attachments = |load: vk::AttachmentLoadOp| {
                let ds = vk::RenderingAttachmentInfo::default()
                    .image_view(t.ds.view)
                    .image_layout(vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL)
                    .load_op(load)
                    .store_op(vk::AttachmentStoreOp::STORE)
                    .clear_value(vk::ClearValue { depth_stencil: vk::ClearDepthStencilValue { depth: wl.clear_depth, stencil: 0 } });
                let col = vk::RenderingAttachmentInfo::default()
                    .image_view(t.color.view)
                    .image_layout(vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL)
                    .load_op(load)
                    .store_op(vk::AttachmentStoreOp::STORE)
                    .clear_value(vk::ClearValue { color: vk::ClearColorValue { float32: [0.0; 4] } });
                (ds, col)
            };
            let (ds_clear, col_clear) = attachments(vk::AttachmentLoadOp::CLEAR);
            let (ds_load, col_load) = attachments(vk::AttachmentLoadOp::LOAD);
            let cols_clear = [col_clear];
            let cols_load = [col_load];
            let clear = vk::RenderingInfo::default()
                .render_area(area)
                .layer_count(1)
                .color_attachments(&cols_clear)
                .depth_attachment(&ds_clear)
                .stencil_attachment(&ds_clear);
            let load = vk::RenderingInfo::default()
                .render_area(area)
                .layer_count(1)
                .color_attachments(&cols_load)
                .depth_attachment(&ds_load)
                .stencil_attachment(&ds_load);
            let d = &ctx.device;
            // SAFETY: `cb` is recording (one_shot); every handle was created on this device and
            // outlives the submission, which one_shot waits for; the query pool has 2 queries.
            unsafe {
                d.cmd_reset_query_pool(cb, t.pool, 0, 2);
                d.cmd_begin_rendering(cb, &clear);
                d.cmd_end_rendering(cb);
                memory_barrier(ctx, cb, all, all);
                d.cmd_write_timestamp2(cb, vk::PipelineStageFlags2::ALL_COMMANDS, t.pool, 0);
                d.cmd_begin_rendering(cb, &load);
                d.cmd_set_viewport(cb, 0, &[viewport]);
                d.cmd_set_scissor(cb, 0, &[area]);
                d.cmd_bind_pipeline(cb, vk::PipelineBindPoint::GRAPHICS, wl.pipe);
                d.cmd_push_constants(
                    cb,
                    t.layout,
                    vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT,
                    0,
                    bytemuck::bytes_of(&push),
                );
                d.cmd_bind_vertex_buffers(cb, 0, &[wl.vertices], &[0]);
                match wl.indices {
                    Some((ib, ty, n)) => {
                        d.cmd_bind_index_buffer(cb, ib, 0, ty);
                        d.cmd_draw_indexed(cb, n, 1, 0, 0, 0);
                    }
                    None => {
                        // Many draws: each with its own push constants and vertex binding,
                        // as the shadow pass issues one per caster chunk.
                        for _ in 0..wl.draw.1 {
                            if wl.draw.1 > 1 {
                                d.cmd_push_constants(
                                    cb,
                                    t.layout,
                                    vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT,
                                    0,
                                    bytemuck::bytes_of(&push),
                                );
                                d.cmd_bind_vertex_buffers(cb, 0, &[wl.vertices], &[0]);
                            }
                            d.cmd_draw(cb, wl.draw.0, 1, 0, 0);
                        }
                    }
                }
                d.cmd_end_rendering(cb);
                d.cmd_write_timestamp2(cb, vk::PipelineStageFlags2::ALL_COMMANDS, t.pool, 1);
            }
        })?;
        let mut raw = [0u64; 2];
        // SAFETY: one_shot waited for the submission: both queries are available.
        unsafe { ctx.device.get_query_pool_results(t.pool, 0, &mut raw, vk::QueryResultFlags::TYPE_64 | vk::QueryResultFlags::WAIT) }
            .map_err(Error::vk("vkGetQueryPoolResults"))?;
        if rep > 0 {
            ms.push(raw[1].wrapping_sub(raw[0]) as f64 * ctx.features.timestamp_period_ns as f64 * 1e-6);
        }
    }
    Ok(super::classic::median(ms))
}

/// One thread summing a buffer of 256 MiB (64 MiB at small scales): the best of `reps` runs.
pub fn cpu_stream_gib_s(scale: f64, reps: usize) -> f64 {
    let bytes: usize = if scale >= 1.0 { 256 << 20 } else { 64 << 20 };
    let v: Vec<u64> = (0..bytes / 8).map(|i| i as u64).collect();
    let mut best = 0.0f64;
    for _ in 0..reps.max(1) {
        let t = std::time::Instant::now();
        let s: u64 = v.iter().fold(0u64, |a, &x| a.wrapping_add(x));
        let secs = t.elapsed().as_secs_f64();
        std::hint::black_box(s);
        best = best.max(bytes as f64 / secs.max(1e-9) / (1u64 << 30) as f64);
    }
    best
}
