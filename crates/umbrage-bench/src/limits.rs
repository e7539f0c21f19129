//! The device's limits, measured in the same run as the suite by micro-benchmarks of their own,
//! each a small pipeline of [`umbrage::gpu`] on an offscreen target of the suite's base size.
//! Each limit isolates one cost and is swept: the workload doubles until its rate stops
//! growing (saturation: per-submission and warm-up costs amortised), and the peak is reported,
//! the sweep itself kept in `Limits::sweeps`.
//!
//! | limit | what is drawn | why it bounds |
//! |---|---|---|
//! | stencil fill | full-screen quads, alternate windings, two-sided INCR_WRAP / DECR_WRAP, depth test LESS on | two triangles a layer: next to no setup, every sample a stencil fragment |
//! | colour fill | the same quads into RGBA16F, additive blending, depth test LEQUAL (the illumination pass's state) | as above, with colour |
//! | triangle setup | tiny triangles inside a pixel's corner, covering no sample centre (not degenerate, not culled before setup) | setup and the coverage test, no fragment |
//! | clipped triangles | triangles from behind the near plane to a vertex at w = 0 (as volume sides at infinity), a few pixels long on screen inside a band between sample rows | clipping and setup, no fragment |
//! | small triangles | a grid of 2-pixel triangles over the whole target | setup plus two fragments each |
//! | big triangles | screen-covering triangles | setup plus a screen of fragments each |
//! | slivers | 1-pixel-wide triangles from the centre past the edges | setup of a screen-sized bounding box, few fragments |
//! | index fetch | one 256-vertex patch drawn through u8, u16 and u32 indices and as streamed 4 x f32 vertices | vertex and index fetch of small triangles |
//! | draw calls | one tiny triangle per `vkCmdDraw`, each with its push constants and vertex binding (as the shadow pass) | per-draw cost |
//! | CPU stream | a sum over a buffer far larger than the caches | host memory bandwidth |
//! | compute read | a compute shader reading 16-byte planes, a bit set per plane facing a light ([`super::compute_read`]) | what the GPU silhouettes' per-triangle and per-edge reads can reach |
//! | lighting | full-screen triangles reading the G-buffer (three texelFetch) and adding into the accumulation target, stencil EQUAL 0 ([`super::pass_limits`]) | the illumination pass per pixel, without its shading math |
//! | G-buffer fill | full-screen layers through the same pipeline, every fragment written ([`super::pass_limits`]) | the G-buffer pass per pixel |
//! | G-buffer geometry | 2-pixel triangles through the G-buffer pass's own pipeline (its shaders, vertex layout, four targets, depth writes; [`super::pass_limits`]) | the G-buffer pass per triangle |
//!
//! GPU times come from timestamps written outside the rendering instances (on lavapipe those
//! inside do not include rasterisation); each point of a sweep is the median of several
//! repetitions. u8 indices need `VK_EXT_index_type_uint8`: without it the limit is skipped
//! with the reason.

use super::saturate::{depth_stencil, saturate, time_gpu, Rules};
use super::workloads::{big_triangles, clipped_triangles, limit_units, setup_triangles, sliver_fan, small_triangles};
use crate::shaders;
use ash::vk;
use glam::{Mat4, Vec4};
use serde::Serialize;
use std::collections::BTreeMap;
use umbrage::error::{Error, Result};
use umbrage::gpu::descriptors::pipeline_layout;
use umbrage::gpu::pipeline::{self, Blend, PipelineDesc};
use umbrage::gpu::resources::{memory_barrier, transition};
use umbrage::gpu::{Buffer, Context, Image};
use umbrage::pass::push::VolumePush;

/// The measured limits (the `limits` object of `bench.json`; units in the key names and in
/// [`Limits::units`]): each the peak rate of its sweep.
#[derive(Clone, Debug, Default, Serialize)]
pub struct Limits {
    /// Stencil-only fill, two-sided wrapping ops with the depth test on: Gfragments / s.
    pub stencil_fill_gfrag_s: f64,
    /// Depth-tested additive colour fill into RGBA16F: Gfragments / s.
    pub color_fill_gfrag_s: f64,
    /// Triangle setup: triangles covering no sample centre, stencil-only: Mtriangles / s.
    pub setup_tri_mtri_s: f64,
    /// Clipped triangles: crossing the near plane, with a vertex at w = 0, covering no
    /// sample centre: Mtriangles / s.
    pub clip_tri_mtri_s: f64,
    /// Small (2-pixel) triangles, stencil-only: Mtriangles / s.
    pub small_tri_mtri_s: f64,
    /// Screen-covering triangles, stencil-only: Mtriangles / s.
    pub big_tri_mtri_s: f64,
    /// Slivers: triangles from the centre to past the target's edge, a pixel wide there (the
    /// shape of shadow-volume sides extruded to infinity: few fragments, a screen-sized
    /// bounding box), stencil-only: Mtriangles / s. Setup and fill together.
    pub sliver_tri_mtri_s: f64,
    /// Draw calls of one tiny triangle each: draws / s.
    pub draws_per_s: f64,
    /// The CPU's memory-stream read bandwidth (one thread): GiB / s.
    pub cpu_stream_gib_s: f64,
    /// A plain compute read of 16-byte planes (the GPU silhouettes' `facing` stage without its
    /// jobs, [`super::compute_read`]): GiB / s.
    pub compute_read_gib_s: f64,
    /// A full-screen pass reading the G-buffer (position, normal, albedo) and adding a colour
    /// into the accumulation target, the illumination pass without its shading math
    /// ([`super::pass_limits`]): Gpixels / s.
    pub lighting_gpix_s: f64,
    /// The lighting sweep's first point: one full-screen draw in a rendering instance of its
    /// own, as each light's illumination is drawn: Gpixels / s.
    pub lighting_one_draw_gpix_s: f64,
    /// Ablation of the lighting limit, not a limit: the real `illuminate.frag` (its shading
    /// math: Blinn-Phong, every pixel lit by an unbounded point light) through the same state
    /// and sweep, its peak: Gpixels / s.
    pub lighting_shaded_gpix_s: f64,
    /// The same, one shaded draw in an instance of its own (the sweep's first point): what a
    /// light's illumination pass can reach: Gpixels / s.
    pub lighting_shaded_one_draw_gpix_s: f64,
    /// Ablation: one lighting rendering instance with no draw (its targets loaded and stored),
    /// the median: what every light's illumination pays before its first pixel, ms.
    pub lighting_instance_ms: f64,
    /// The G-buffer pass's own pipeline over 2-pixel triangles (its vertex layout, four colour
    /// targets, depth LESS with writes; [`super::pass_limits`]): Mtriangles / s.
    pub gbuffer_tri_mtri_s: f64,
    /// Full-screen layers through the G-buffer pass's pipeline, every fragment written
    /// ([`super::pass_limits`]): Gpixels / s.
    pub gbuffer_fill_gpix_s: f64,
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
    /// Each GPU limit's sweep: `[workload size (layers, triangles or draws), rate in the key's
    /// unit]` per point, in the order measured; the peak is the limit.
    pub sweeps: BTreeMap<String, Vec<[f64; 2]>>,
}

/// How much to measure: repetitions per point and the size of each workload.
#[derive(Clone, Copy, Debug)]
pub struct LimitsConfig {
    /// Target size (the suite's base resolution).
    pub width: u32,
    /// Target height.
    pub height: u32,
    /// Repetitions per point of a sweep (median taken), at least 1.
    pub reps: usize,
    /// Workload scale: 1.0 full, smaller for `--quick` (shorter sweeps).
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
#[derive(Clone, Copy)]
struct Workload {
    pipe: vk::Pipeline,
    vertices: vk::Buffer,
    indices: Option<(vk::Buffer, vk::IndexType, u32)>,
    /// Vertices per non-indexed draw.
    vertex_count: u32,
    /// Draws of the whole buffer (one push and vertex binding each when more than one).
    draws: u32,
}

/// The objects a measurement made, destroyed by [`measure`] whatever happens.
#[derive(Default)]
struct Made {
    pipelines: Vec<vk::Pipeline>,
    buffers: Vec<Buffer>,
    target: Option<Target>,
}

/// Measures every limit on `ctx` (GPU) and this machine (CPU stream).
pub fn measure(ctx: &Context, cfg: &LimitsConfig) -> Result<Limits> {
    let mut made = Made::default();
    let r = measure_with(ctx, cfg, &mut made);
    // SAFETY: one_shot waited for every submission: nothing in use.
    unsafe {
        let _ = ctx.device.device_wait_idle();
        for p in made.pipelines {
            ctx.device.destroy_pipeline(p, None);
        }
        if let Some(t) = &made.target {
            ctx.device.destroy_query_pool(t.pool, None);
            ctx.device.destroy_pipeline_layout(t.layout, None);
        }
    }
    for b in &mut made.buffers {
        b.destroy(ctx);
    }
    if let Some(mut t) = made.target {
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

/// The lab: the target, the two pipelines and the sweep's rules.
struct Lab<'a> {
    ctx: &'a Context,
    t: &'a Target,
    reps: usize,
    /// Most doublings a sweep takes, and the time of a point that ends it.
    rules: Rules,
    sweeps: BTreeMap<String, Vec<[f64; 2]>>,
}

impl Lab<'_> {
    /// Sweeps `base` drawn 1, 2, 4, ... times (`k` draws of the whole buffer, or the draw
    /// count for per-draw workloads) until the rate (`units` per repetition x k / time, in
    /// `unit`) gains under 5 % twice running, a point takes `max_ms`, or `max_steps` points
    /// ran; returns the peak and records the sweep under `key`.
    fn peak(&mut self, key: &str, base: Workload, units: f64, unit: f64, per_draw: bool) -> Result<f64> {
        let (best, points) = saturate(self.rules, units, unit, |k| {
            time(self.ctx, self.t, &Workload { draws: if per_draw { base.draws * k } else { k }, ..base }, self.reps)
        })?;
        self.sweeps.insert(key.to_string(), points);
        Ok(best)
    }
}

/// Creates the offscreen target (into `made`) and the two pipelines: stencil-only (the shadow
/// pass's state) and depth-tested additive colour.
fn setup(ctx: &Context, cfg: &LimitsConfig, made: &mut Made) -> Result<(vk::Pipeline, vk::Pipeline)> {
    let (w, h) = (cfg.width.max(16), cfg.height.max(16));
    let extent = vk::Extent2D { width: w, height: h };
    if !ctx.features.timestamps {
        return Err(Error::Unsupported("the suite's limits need timestamp queries, which this device lacks".into()));
    }
    let ds = depth_stencil(ctx, "limits-ds", extent)?;
    let color = match Image::new_2d(
        ctx,
        "limits-color",
        umbrage_render::targets::ACCUM_FORMAT,
        extent,
        vk::ImageUsageFlags::COLOR_ATTACHMENT,
        vk::ImageAspectFlags::COLOR,
    ) {
        Ok(c) => c,
        Err(e) => {
            let mut ds = ds;
            ds.destroy(ctx);
            return Err(e);
        }
    };
    let layout = pipeline_layout(ctx, &[], VolumePush::SIZE, vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT);
    // SAFETY: creation on a valid device; destroyed by `measure`.
    let pool = unsafe {
        ctx.device.create_query_pool(&vk::QueryPoolCreateInfo::default().query_type(vk::QueryType::TIMESTAMP).query_count(2), None)
    }
    .map_err(Error::vk("vkCreateQueryPool"));
    let (layout, pool) = match (layout, pool) {
        (Ok(l), Ok(p)) => (l, p),
        (l, p) => {
            // SAFETY: nothing submitted yet.
            unsafe {
                if let Ok(l) = &l {
                    ctx.device.destroy_pipeline_layout(*l, None);
                }
                if let Ok(p) = &p {
                    ctx.device.destroy_query_pool(*p, None);
                }
            }
            let (mut ds, mut color) = (ds, color);
            ds.destroy(ctx);
            color.destroy(ctx);
            return Err(l.err().or(p.err()).unwrap_or_else(|| Error::Internal("the limits target was not made".into())));
        }
    };
    made.target = Some(Target { ds, color, pool, layout, extent });

    // Pipelines: stencil-only (the shadow pass's state) and depth-tested additive colour.
    let color_formats = [umbrage_render::targets::ACCUM_FORMAT];
    let mut base = PipelineDesc::new(shaders::SHADOW_VERT, layout, ctx.depth_format);
    base.vertex_stride = 16;
    base.attributes = &[(0, vk::Format::R32G32B32A32_SFLOAT, 0)];
    base.color_formats = &color_formats;
    base.color_write = false;
    base.depth_test = true;
    base.depth_compare = vk::CompareOp::LESS;
    use vk::StencilOp as S;
    base.stencil = Some((pipeline::stencil_ops(S::INCREMENT_AND_WRAP, S::KEEP), pipeline::stencil_ops(S::DECREMENT_AND_WRAP, S::KEEP)));
    let stencil = pipeline::create(ctx, &base)?;
    made.pipelines.push(stencil);
    let mut c = base.clone();
    c.fragment = Some(shaders::VOLUME_FRAG);
    c.color_write = true;
    c.blend = Blend::Additive;
    c.stencil = None;
    c.depth_compare = vk::CompareOp::LESS_OR_EQUAL;
    let color = pipeline::create(ctx, &c)?;
    made.pipelines.push(color);
    Ok((stencil, color))
}

fn measure_with(ctx: &Context, cfg: &LimitsConfig, made: &mut Made) -> Result<Limits> {
    let (w, h) = (cfg.width.max(16), cfg.height.max(16));
    let (stencil, color) = setup(ctx, cfg, made)?;
    let t = made.target.as_ref().ok_or_else(|| Error::Internal("the limits target was not made".into()))?;
    let quick = cfg.scale < 1.0;
    let mut lab = Lab {
        ctx,
        t,
        reps: cfg.reps.max(1),
        rules: Rules { max_steps: if quick { 7 } else { 9 }, max_ms: if quick { 150.0 } else { 400.0 } },
        sweeps: BTreeMap::new(),
    };
    let buffers = &mut made.buffers;
    let mut upload = |name: &str, data: &[u8], usage: vk::BufferUsageFlags| -> Result<vk::Buffer> {
        let b = Buffer::with_data(ctx, name, data, usage)?;
        let raw = b.raw;
        buffers.push(b);
        Ok(raw)
    };
    let px = (w as f64) * (h as f64);
    let (pw, ph) = (2.0 / w as f32, 2.0 / h as f32); // one pixel in NDC
    let vb = vk::BufferUsageFlags::VERTEX_BUFFER;
    let draw = |pipe, vertices, n: usize| Workload { pipe, vertices, indices: None, vertex_count: n as u32, draws: 1 };

    // Fill: full-screen layers, alternate windings (two-sided ops both exercised).
    let layers = 4u32;
    let fill: Vec<[f32; 4]> = (0..layers).flat_map(|i| quad(0.5, i % 2 == 0)).collect();
    let fill_vb = upload("limits-fill", bytes(&fill), vb)?;
    let stencil_fill = lab.peak("stencil_fill_gfrag_s", draw(stencil, fill_vb, fill.len()), layers as f64 * px, 1e9, false)?;
    let color_fill = lab.peak("color_fill_gfrag_s", draw(color, fill_vb, fill.len()), layers as f64 * px, 1e9, false)?;

    // Setup: one tiny triangle per 2x2-pixel block, inside the corner of a pixel, away from
    // its sample centre (x+0.6 .. x+0.9).
    let setup = setup_triangles(w, h);
    let setup_tris = (setup.len() / 3) as f64;
    let setup_vb = upload("limits-setup", bytes(&setup), vb)?;
    let setup_rate = lab.peak("setup_tri_mtri_s", draw(stencil, setup_vb, setup.len()), setup_tris, 1e6, false)?;

    // Clipped: A behind the near plane, B in front, C at w = 0 towards +x: the strip between
    // two lines inside one pixel row (y+0.6 .. y+0.9), from 4 pixels left of the right edge to
    // infinity, cut by the near plane and the right clip plane: short on screen (one tile,
    // like a clipped side's corner), no sample centre in it.
    let clip_n = 65_536usize;
    let clip = clipped_triangles(w, h, clip_n);
    let clip_vb = upload("limits-clip", bytes(&clip), vb)?;
    let clip_rate = lab.peak("clip_tri_mtri_s", draw(stencil, clip_vb, clip.len()), clip_n as f64, 1e6, false)?;

    // Small triangles: a grid of 2x2-pixel cells over the target, each two 2-pixel triangles.
    let small = small_triangles(w, h);
    let small_vb = upload("limits-small", bytes(&small), vb)?;
    let small_rate = lab.peak("small_tri_mtri_s", draw(stencil, small_vb, small.len()), (small.len() / 3) as f64, 1e6, false)?;

    // Big triangles: each covers the target (a triangle twice its size, clipped).
    let big = big_triangles();
    let big_vb = upload("limits-big", bytes(&big), vb)?;
    let big_rate = lab.peak("big_tri_mtri_s", draw(stencil, big_vb, big.len()), 4.0, 1e6, false)?;

    // Slivers: a fan of 1-pixel-wide triangles from the centre out past the edges.
    let slivers = 4096u32;
    let sliver = sliver_fan(slivers, (pw, ph));
    let sliver_vb = upload("limits-sliver", bytes(&sliver), vb)?;
    let sliver_rate = lab.peak("sliver_tri_mtri_s", draw(stencil, sliver_vb, sliver.len()), slivers as f64, 1e6, false)?;

    let IndexRates { u16: u16_rate, u32: u32_rate, u8: u8_rate, naive: naive_rate, skipped } =
        index_limits(&mut lab, &mut upload, stencil, (pw, ph))?;

    // Draw calls: one 1-pixel triangle each, 1024 draws doubled.
    let tiny: [[f32; 4]; 3] = [[0.0, 0.0, 0.5, 1.0], [pw, 0.0, 0.5, 1.0], [0.0, ph, 0.5, 1.0]];
    let tiny_vb = upload("limits-tiny", bytes(&tiny), vb)?;
    let draws = 1024u32;
    let draw_rate = lab.peak("draws_per_s", Workload { draws, ..draw(stencil, tiny_vb, 3) }, draws as f64, 1.0, true)?;
    let read = super::compute_read::measure(ctx, lab.reps, if quick { 1 << 20 } else { 1 << 22 })?;
    lab.sweeps.insert("compute_read_gib_s".into(), read.sweep.clone());
    let passes = super::pass_limits::measure(ctx, w, h, lab.reps, lab.rules.max_steps)?;
    lab.sweeps.insert("lighting_gpix_s".into(), passes.lighting_sweep.clone());
    lab.sweeps.insert("lighting_shaded_gpix_s".into(), passes.lighting_shaded_sweep.clone());
    let first = |sweep: &[[f64; 2]]| sweep.first().map_or(0.0, |p| p[1]);
    lab.sweeps.insert("gbuffer_tri_mtri_s".into(), passes.gbuffer_sweep.clone());
    lab.sweeps.insert("gbuffer_fill_gpix_s".into(), passes.gbuffer_fill_sweep.clone());

    Ok(Limits {
        stencil_fill_gfrag_s: stencil_fill,
        color_fill_gfrag_s: color_fill,
        setup_tri_mtri_s: setup_rate,
        clip_tri_mtri_s: clip_rate,
        small_tri_mtri_s: small_rate,
        big_tri_mtri_s: big_rate,
        sliver_tri_mtri_s: sliver_rate,
        draws_per_s: draw_rate,
        cpu_stream_gib_s: cpu_stream_gib_s(cfg.scale, cfg.reps),
        compute_read_gib_s: read.gib_s,
        lighting_gpix_s: passes.lighting_gpix_s,
        lighting_one_draw_gpix_s: first(&passes.lighting_sweep),
        lighting_shaded_gpix_s: passes.lighting_shaded_gpix_s,
        lighting_shaded_one_draw_gpix_s: first(&passes.lighting_shaded_sweep),
        lighting_instance_ms: passes.lighting_instance_ms,
        gbuffer_tri_mtri_s: passes.gbuffer_tri_mtri_s,
        gbuffer_fill_gpix_s: passes.gbuffer_fill_gpix_s,
        index_u8_mtri_s: u8_rate,
        index_u16_mtri_s: u16_rate,
        index_u32_mtri_s: u32_rate,
        index_naive_mtri_s: naive_rate,
        target: [w, h],
        units: limit_units(),
        skipped,
        sweeps: lab.sweeps,
    })
}

/// The index-fetch limits, Mtriangles / s.
struct IndexRates {
    u16: f64,
    u32: f64,
    /// `None` without `VK_EXT_index_type_uint8` (the reason in `skipped`).
    u8: Option<f64>,
    naive: f64,
    skipped: BTreeMap<String, String>,
}

/// Measures [`IndexRates`].
fn index_limits(
    lab: &mut Lab,
    upload: &mut impl FnMut(&str, &[u8], vk::BufferUsageFlags) -> Result<vk::Buffer>,
    stencil: vk::Pipeline,
    (pw, ph): (f32, f32),
) -> Result<IndexRates> {
    let ctx = lab.ctx;
    let vb = vk::BufferUsageFlags::VERTEX_BUFFER;
    // Index fetch: a 16x16-vertex patch (256 vertices: u8 can address it) of 2-pixel cells,
    // its 450 triangles repeated.
    let patch: Vec<[f32; 4]> = (0..256).map(|k| [-0.5 + (k % 16) as f32 * 2.0 * pw, -0.5 + (k / 16) as f32 * 2.0 * ph, 0.5, 1.0]).collect();
    let mut tri_idx: Vec<u32> = Vec::new();
    for j in 0..15u32 {
        for i in 0..15u32 {
            let (a, b, c, d) = (j * 16 + i, j * 16 + i + 1, (j + 1) * 16 + i + 1, (j + 1) * 16 + i);
            tri_idx.extend([a, b, c, a, c, d]);
        }
    }
    let idx32: Vec<u32> = tri_idx.iter().copied().cycle().take(tri_idx.len() * 100).collect();
    let n_idx = idx32.len() as u32;
    let idx_tris = n_idx as f64 / 3.0;
    let patch_vb = upload("limits-patch", bytes(&patch), vb)?;
    let ib = vk::BufferUsageFlags::INDEX_BUFFER;
    let indexed = |buf, ty| Workload { pipe: stencil, vertices: patch_vb, indices: Some((buf, ty, n_idx)), vertex_count: 0, draws: 1 };
    let i32b = upload("limits-u32", bytes(&idx32), ib)?;
    let idx16: Vec<u16> = idx32.iter().map(|&i| i as u16).collect();
    let i16b = upload("limits-u16", bytes(&idx16), ib)?;
    let u16_rate = lab.peak("index_u16_mtri_s", indexed(i16b, vk::IndexType::UINT16), idx_tris, 1e6, false)?;
    let u32_rate = lab.peak("index_u32_mtri_s", indexed(i32b, vk::IndexType::UINT32), idx_tris, 1e6, false)?;
    let mut skipped = BTreeMap::new();
    let u8_rate = if ctx.features.index_type_uint8 {
        let idx8: Vec<u8> = idx32.iter().map(|&i| i as u8).collect();
        let i8b = upload("limits-u8", &idx8, ib)?;
        Some(lab.peak("index_u8_mtri_s", indexed(i8b, vk::IndexType::UINT8_EXT), idx_tris, 1e6, false)?)
    } else {
        skipped.insert("index_u8_mtri_s".to_string(), "VK_EXT_index_type_uint8 (indexTypeUint8) missing".to_string());
        None
    };
    let naive: Vec<[f32; 4]> = idx32.iter().map(|&i| patch[i as usize]).collect();
    let naive_vb = upload("limits-naive", bytes(&naive), vb)?;
    let naive_wl = Workload { pipe: stencil, vertices: naive_vb, indices: None, vertex_count: naive.len() as u32, draws: 1 };
    let naive_rate = lab.peak("index_naive_mtri_s", naive_wl, idx_tris, 1e6, false)?;
    Ok(IndexRates { u16: u16_rate, u32: u32_rate, u8: u8_rate, naive: naive_rate, skipped })
}

/// Median GPU ms of `reps` repetitions of `wl` (each in its own submission, the target cleared
/// first in a rendering instance of its own, timestamps around the timed one).
fn time(ctx: &Context, t: &Target, wl: &Workload, reps: usize) -> Result<f64> {
    let area = vk::Rect2D { offset: vk::Offset2D { x: 0, y: 0 }, extent: t.extent };
    let viewport =
        vk::Viewport { x: 0.0, y: 0.0, width: t.extent.width as f32, height: t.extent.height as f32, min_depth: 0.0, max_depth: 1.0 };
    let push = VolumePush::new(Mat4::IDENTITY, Vec4::W, [0.01, 0.01, 0.01, 0.0]);
    let info = |load: vk::AttachmentLoadOp| {
        let ds = vk::RenderingAttachmentInfo::default()
            .image_view(t.ds.view)
            .image_layout(vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL)
            .load_op(load)
            .store_op(vk::AttachmentStoreOp::STORE)
            .clear_value(vk::ClearValue { depth_stencil: vk::ClearDepthStencilValue { depth: 1.0, stencil: 0 } });
        let col = vk::RenderingAttachmentInfo::default()
            .image_view(t.color.view)
            .image_layout(vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL)
            .load_op(load)
            .store_op(vk::AttachmentStoreOp::STORE)
            .clear_value(vk::ClearValue { color: vk::ClearColorValue { float32: [0.0; 4] } });
        (ds, [col])
    };
    let d = &ctx.device;
    let prep = |cb: vk::CommandBuffer| {
        let all = (vk::PipelineStageFlags2::ALL_COMMANDS, vk::AccessFlags2::MEMORY_READ | vk::AccessFlags2::MEMORY_WRITE);
        transition(ctx, cb, &t.ds, vk::ImageLayout::UNDEFINED, vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL);
        transition(ctx, cb, &t.color, vk::ImageLayout::UNDEFINED, vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL);
        let (ds, cols) = info(vk::AttachmentLoadOp::CLEAR);
        let clear = vk::RenderingInfo::default()
            .render_area(area)
            .layer_count(1)
            .color_attachments(&cols)
            .depth_attachment(&ds)
            .stencil_attachment(&ds);
        // SAFETY: `cb` is recording outside any instance; both images were just transitioned to
        // their attachment layouts.
        unsafe {
            d.cmd_begin_rendering(cb, &clear);
            d.cmd_end_rendering(cb);
        }
        memory_barrier(ctx, cb, all, all);
    };
    let timed = |cb: vk::CommandBuffer| {
        let (ds, cols) = info(vk::AttachmentLoadOp::LOAD);
        let load = vk::RenderingInfo::default()
            .render_area(area)
            .layer_count(1)
            .color_attachments(&cols)
            .depth_attachment(&ds)
            .stencil_attachment(&ds);
        // SAFETY: `cb` is recording (one_shot); every handle was created on this device and
        // outlives the submission, which one_shot waits for; the images are in attachment
        // layouts (prep).
        unsafe {
            d.cmd_begin_rendering(cb, &load);
            d.cmd_set_viewport(cb, 0, &[viewport]);
            d.cmd_set_scissor(cb, 0, &[area]);
            d.cmd_bind_pipeline(cb, vk::PipelineBindPoint::GRAPHICS, wl.pipe);
            if let Some((ib, ty, _)) = wl.indices {
                d.cmd_bind_index_buffer(cb, ib, 0, ty);
            }
            // Each draw with its own push constants and vertex binding, as the shadow pass
            // issues one per caster chunk.
            for _ in 0..wl.draws {
                d.cmd_push_constants(
                    cb,
                    t.layout,
                    vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT,
                    0,
                    bytemuck::bytes_of(&push),
                );
                d.cmd_bind_vertex_buffers(cb, 0, &[wl.vertices], &[0]);
                match wl.indices {
                    Some((_, _, n)) => d.cmd_draw_indexed(cb, n, 1, 0, 0, 0),
                    None => d.cmd_draw(cb, wl.vertex_count, 1, 0, 0),
                }
            }
            d.cmd_end_rendering(cb);
        }
    };
    time_gpu(ctx, t.pool, reps, &prep, &timed)
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
