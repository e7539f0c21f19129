//! The batch runner: every case of one [`Config`] drawn into its own tile of one
//! depth-stencil image, in one command buffer and one submission.
//!
//! Per configuration: the initial depth and stencil of every tile are uploaded with buffer
//! copies (so any per-pixel starting state is exact), the image goes to
//! `DEPTH_STENCIL_ATTACHMENT_OPTIMAL`, one rendering instance (dynamic rendering or a render
//! pass) draws every case with the viewport and scissor set to its tile, then both aspects
//! are copied back. Occlusion queries, one per query draw, are read after the fence.

mod pipe;

use super::cases::{Case, Config, DepthKind, RenderModel, StateModel};
use super::model::to_raw;
use ash::vk;
use gpu_allocator::MemoryLocation;
use std::collections::HashMap;
use umbrage::error::{Error, Result};
use umbrage::gpu::resources::{aspect_copy, transfer_to_host_barrier, transition};
use umbrage::gpu::{Buffer, Context, Image};

/// What came back for one case's tile.
#[derive(Clone, Debug)]
pub struct TileResult {
    /// Raw depth words (see [`super::model::from_raw`]), row-major; empty without depth.
    pub depth: Vec<u32>,
    /// Stencil bytes, row-major.
    pub stencil: Vec<u8>,
    /// Passing-sample counts of the case's query draws, in order.
    pub queries: Vec<u64>,
}

/// Shelf-packs `sizes` into rows at most `max_w` wide: the tile origins and the image size.
pub fn layout(sizes: &[(u32, u32)], max_w: u32) -> (Vec<(u32, u32)>, u32, u32) {
    let (mut x, mut y, mut row_h, mut w) = (0u32, 0u32, 0u32, 1u32);
    let mut out = Vec::with_capacity(sizes.len());
    for &(tw, th) in sizes {
        if x + tw > max_w && x > 0 {
            y += row_h;
            x = 0;
            row_h = 0;
        }
        out.push((x, y));
        x += tw;
        w = w.max(x);
        row_h = row_h.max(th);
    }
    (out, w, (y + row_h).max(1))
}

fn bytes<T: bytemuck::Pod>(v: &[T]) -> &[u8] {
    bytemuck::cast_slice(v)
}

fn depth_bpp(kind: DepthKind) -> u32 {
    match kind {
        DepthKind::None => 0,
        DepthKind::Unorm16 => 2,
        _ => 4,
    }
}

/// Whether `format` can be used by the runner: depth-stencil attachment, transfer source and
/// destination (optimal tiling).
pub fn format_usable(ctx: &Context, format: vk::Format) -> bool {
    // Vulkan 1.0 without VK_KHR_maintenance1 has no transfer format features: there every
    // format may be copied.
    let transfer = if ctx.features.api_version >= vk::API_VERSION_1_1 {
        vk::FormatFeatureFlags::TRANSFER_SRC | vk::FormatFeatureFlags::TRANSFER_DST
    } else {
        vk::FormatFeatureFlags::empty()
    };
    let needed = vk::FormatFeatureFlags::DEPTH_STENCIL_ATTACHMENT | transfer;
    // SAFETY: a format query on the context's valid physical device.
    let p = unsafe { ctx.instance.get_physical_device_format_properties(ctx.physical, format) };
    p.optimal_tiling_features.contains(needed)
}

struct Objects {
    layout: vk::PipelineLayout,
    render_pass: vk::RenderPass,
    framebuffer: vk::Framebuffer,
    pipelines: Vec<vk::Pipeline>,
    query_pool: vk::QueryPool,
    buffers: Vec<Buffer>,
}

impl Objects {
    fn destroy(mut self, ctx: &Context) {
        // SAFETY: the submission finished (one_shot waits) or never happened; wait idle anyway
        // so nothing below is in use.
        unsafe {
            let _ = ctx.device.device_wait_idle();
            for p in self.pipelines.drain(..) {
                ctx.device.destroy_pipeline(p, None);
            }
            ctx.device.destroy_query_pool(self.query_pool, None);
            ctx.device.destroy_framebuffer(self.framebuffer, None);
            ctx.device.destroy_render_pass(self.render_pass, None);
            ctx.device.destroy_pipeline_layout(self.layout, None);
        }
        for b in &mut self.buffers {
            b.destroy(ctx);
        }
    }
}

/// Draws `cases` (all of configuration `cfg`) in one submission and returns each tile.
pub fn run(ctx: &Context, cfg: Config, cases: &[&Case]) -> Result<Vec<TileResult>> {
    let push_range = [vk::PushConstantRange { stage_flags: vk::ShaderStageFlags::VERTEX, offset: 0, size: 96 }];
    let layout_info = vk::PipelineLayoutCreateInfo::default().push_constant_ranges(&push_range);
    // SAFETY: valid device and create info; destroyed in Objects::destroy.
    let layout = unsafe { ctx.device.create_pipeline_layout(&layout_info, None) }.map_err(Error::vk("vkCreatePipelineLayout"))?;
    let mut objs = Objects {
        layout,
        render_pass: vk::RenderPass::null(),
        framebuffer: vk::Framebuffer::null(),
        pipelines: Vec::new(),
        query_pool: vk::QueryPool::null(),
        buffers: Vec::new(),
    };
    let sizes: Vec<(u32, u32)> = cases.iter().map(|c| c.size).collect();
    let (origins, width, height) = self::layout(&sizes, 512);
    let aspect = if cfg.has_depth() { vk::ImageAspectFlags::DEPTH | vk::ImageAspectFlags::STENCIL } else { vk::ImageAspectFlags::STENCIL };
    let image = Image::new_2d(
        ctx,
        "conform-batch-ds",
        cfg.format,
        vk::Extent2D { width, height },
        vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT | vk::ImageUsageFlags::TRANSFER_SRC | vk::ImageUsageFlags::TRANSFER_DST,
        aspect,
    );
    let mut image = match image {
        Ok(i) => i,
        Err(e) => {
            objs.destroy(ctx);
            return Err(e);
        }
    };
    let r = run_inner(ctx, cfg, cases, &origins, &image, &mut objs);
    objs.destroy(ctx);
    image.destroy(ctx);
    r
}

fn run_inner(ctx: &Context, cfg: Config, cases: &[&Case], origins: &[(u32, u32)], img: &Image, o: &mut Objects) -> Result<Vec<TileResult>> {
    let kind = cfg.depth_kind();
    let has_depth = kind != DepthKind::None;
    let (width, height) = (img.extent.width, img.extent.height);
    let n = (width * height) as usize;
    let bpp = depth_bpp(kind) as usize;

    // Initial state: 1.0 / 0 outside the tiles, each case's own inside.
    let (depth_init, stencil_init) = initial_state(kind, cases, origins, width, n);
    let extent = img.extent;
    let mut upload = depth_init.clone();
    let stencil_offset = upload.len() as u64;
    upload.extend_from_slice(&stencil_init);
    o.buffers.push(Buffer::with_data(ctx, "conform-batch-upload", &upload, vk::BufferUsageFlags::TRANSFER_SRC)?);
    let upload_buf = o.buffers.last().expect("pushed").raw;
    o.buffers.push(Buffer::new(
        ctx,
        "conform-batch-readback",
        upload.len() as u64,
        vk::BufferUsageFlags::TRANSFER_DST,
        MemoryLocation::GpuToCpu,
    )?);
    let read_idx = o.buffers.len() - 1;
    let read_buf = o.buffers[read_idx].raw;

    if cfg.render == RenderModel::RenderPass {
        o.render_pass = pipe::render_pass(ctx, cfg)?;
        let views = [img.view];
        let fb = vk::FramebufferCreateInfo::default().render_pass(o.render_pass).attachments(&views).width(width).height(height).layers(1);
        // SAFETY: valid device; the render pass and view are alive until Objects::destroy.
        o.framebuffer = unsafe { ctx.device.create_framebuffer(&fb, None) }.map_err(Error::vk("vkCreateFramebuffer"))?;
    }

    // Pipelines, vertices, queries.
    let (recs, mut verts, queries) = batch_draws(ctx, cfg, cases, origins, o)?;
    if verts.is_empty() {
        verts.push([0.0; 4]);
    }
    o.buffers.push(Buffer::with_data(ctx, "conform-batch-vertices", bytes(&verts), vk::BufferUsageFlags::VERTEX_BUFFER)?);
    let vb = o.buffers.last().expect("pushed").raw;
    if queries > 0 {
        let qi = vk::QueryPoolCreateInfo::default().query_type(vk::QueryType::OCCLUSION).query_count(queries);
        // SAFETY: valid device; destroyed in Objects::destroy.
        o.query_pool = unsafe { ctx.device.create_query_pool(&qi, None) }.map_err(Error::vk("vkCreateQueryPool"))?;
    }
    let precise = if ctx.features.occlusion_query_precise { vk::QueryControlFlags::PRECISE } else { vk::QueryControlFlags::empty() };
    let dynamic = cfg.state == StateModel::Dynamic;
    let bounds_feature = ctx.features.depth_bounds;

    let region = |aspect: vk::ImageAspectFlags, offset: u64| aspect_copy(aspect, extent, offset);
    let mut regions = vec![region(vk::ImageAspectFlags::STENCIL, stencil_offset)];
    if has_depth {
        regions.push(region(vk::ImageAspectFlags::DEPTH, 0));
    }
    let (query_pool, render_pass, framebuffer, layout) = (o.query_pool, o.render_pass, o.framebuffer, o.layout);
    // From here on every case shares the submission: a crash or hang pins none.
    crate::progress::step("submit");
    ctx.one_shot(|cb| {
        let d = &ctx.device;
        // SAFETY: `cb` is recording (one_shot); every handle was created above on this device
        // and stays alive until Objects::destroy, after one_shot's fence wait. The copies stay
        // inside the buffers (sized for every aspect) and the image.
        unsafe {
            if queries > 0 {
                d.cmd_reset_query_pool(cb, query_pool, 0, queries);
            }
            transition(ctx, cb, img, vk::ImageLayout::UNDEFINED, vk::ImageLayout::TRANSFER_DST_OPTIMAL);
            d.cmd_copy_buffer_to_image(cb, upload_buf, img.raw, vk::ImageLayout::TRANSFER_DST_OPTIMAL, &regions);
            transition(ctx, cb, img, vk::ImageLayout::TRANSFER_DST_OPTIMAL, vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL);
            let area = vk::Rect2D { offset: vk::Offset2D { x: 0, y: 0 }, extent };
            let att = vk::RenderingAttachmentInfo::default()
                .image_view(img.view)
                .image_layout(vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL)
                .load_op(vk::AttachmentLoadOp::LOAD)
                .store_op(vk::AttachmentStoreOp::STORE);
            match cfg.render {
                RenderModel::DynamicRendering => {
                    let mut info = vk::RenderingInfo::default().render_area(area).layer_count(1).stencil_attachment(&att);
                    if has_depth {
                        info = info.depth_attachment(&att);
                    }
                    d.cmd_begin_rendering(cb, &info);
                }
                RenderModel::RenderPass => {
                    let info = vk::RenderPassBeginInfo::default().render_pass(render_pass).framebuffer(framebuffer).render_area(area);
                    d.cmd_begin_render_pass(cb, &info, vk::SubpassContents::INLINE);
                }
            }
            d.cmd_bind_vertex_buffers(cb, 0, &[vb], &[0]);
            let mut bound = vk::Pipeline::null();
            for r in &recs {
                let (x, y, w, h) = r.tile;
                let (n, f) = r.state.viewport_depth;
                let viewport = vk::Viewport { x: x as f32, y: y as f32, width: w as f32, height: h as f32, min_depth: n, max_depth: f };
                d.cmd_set_viewport(cb, 0, &[viewport]);
                let scissor =
                    vk::Rect2D { offset: vk::Offset2D { x: x as i32, y: y as i32 }, extent: vk::Extent2D { width: w, height: h } };
                d.cmd_set_scissor(cb, 0, &[scissor]);
                if r.pipeline != bound {
                    d.cmd_bind_pipeline(cb, vk::PipelineBindPoint::GRAPHICS, r.pipeline);
                    bound = r.pipeline;
                }
                if dynamic {
                    set_dynamic_state(d, cb, &r.state, has_depth, bounds_feature);
                }
                d.cmd_push_constants(cb, layout, vk::ShaderStageFlags::VERTEX, 0, &r.push);
                if let Some(q) = r.query {
                    d.cmd_begin_query(cb, query_pool, q, precise);
                }
                d.cmd_draw(cb, r.count, 1, r.first, 0);
                if let Some(q) = r.query {
                    d.cmd_end_query(cb, query_pool, q);
                }
            }
            match cfg.render {
                RenderModel::DynamicRendering => d.cmd_end_rendering(cb),
                RenderModel::RenderPass => d.cmd_end_render_pass(cb),
            }
            transition(ctx, cb, img, vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL, vk::ImageLayout::TRANSFER_SRC_OPTIMAL);
            d.cmd_copy_image_to_buffer(cb, img.raw, vk::ImageLayout::TRANSFER_SRC_OPTIMAL, read_buf, &regions);
            transfer_to_host_barrier(ctx, cb);
        }
    })?;
    let mut counts = vec![0u64; queries as usize];
    if queries > 0 {
        // SAFETY: the queries were reset, begun and ended in the finished submission.
        unsafe {
            ctx.device.get_query_pool_results(query_pool, 0, &mut counts, vk::QueryResultFlags::TYPE_64 | vk::QueryResultFlags::WAIT)
        }
        .map_err(Error::vk("vkGetQueryPoolResults"))?;
    }
    let data = o.buffers[read_idx].read()?;
    let (depth_bytes, stencil_bytes) = data.split_at(stencil_offset as usize);
    let out = tiles(cases, origins, width, (depth_bytes, stencil_bytes), bpp, &counts);
    Ok(out)
}

/// The batch image's initial depth (`depth_bpp` bytes a texel) and stencil: 1.0 / 0 outside
/// the tiles, each case's own values inside its tile.
fn initial_state(kind: DepthKind, cases: &[&Case], origins: &[(u32, u32)], width: u32, n: usize) -> (Vec<u8>, Vec<u8>) {
    let has_depth = kind != DepthKind::None;
    let bpp = depth_bpp(kind) as usize;
    let mut depth_init = vec![0u8; n * bpp];
    let mut stencil_init = vec![0u8; n];
    let put_depth = |buf: &mut [u8], i: usize, v: f64| {
        let raw = to_raw(kind, v);
        buf[i * bpp..(i + 1) * bpp].copy_from_slice(&raw.to_le_bytes()[..bpp]);
    };
    if has_depth {
        for i in 0..n {
            put_depth(&mut depth_init, i, 1.0);
        }
    }
    for (c, &(ox, oy)) in cases.iter().zip(origins) {
        for ty in 0..c.size.1 {
            for tx in 0..c.size.0 {
                let (ti, ii) = ((ty * c.size.0 + tx) as usize, ((oy + ty) * width + ox + tx) as usize);
                stencil_init[ii] = c.init_stencil[ti];
                if has_depth {
                    put_depth(&mut depth_init, ii, c.init_depth[ti]);
                }
            }
        }
    }
    (depth_init, stencil_init)
}

/// One draw of the batch, ready to record.
struct BatchDraw {
    /// Its case's tile: x, y, width, height.
    tile: (u32, u32, u32, u32),
    pipeline: vk::Pipeline,
    state: super::cases::DsState,
    push: Vec<u8>,
    first: u32,
    count: u32,
    query: Option<u32>,
}

/// Every case's draws in order, one pipeline per distinct state (kept in `o`), their vertices
/// in one array, and the number of occlusion queries.
fn batch_draws(
    ctx: &Context,
    cfg: Config,
    cases: &[&Case],
    origins: &[(u32, u32)],
    o: &mut Objects,
) -> Result<(Vec<BatchDraw>, Vec<[f32; 4]>, u32)> {
    let mut pipe_of: HashMap<String, vk::Pipeline> = HashMap::new();
    let mut verts: Vec<[f32; 4]> = Vec::new();
    let mut recs = Vec::new();
    let mut queries = 0u32;
    for (c, &(ox, oy)) in cases.iter().zip(origins) {
        // Pipeline creation is where a case of its own can take a driver down.
        crate::progress::case(&c.name);
        for d in &c.draws {
            let key = d.state.pipeline_key(cfg.state);
            let p = match pipe_of.get(&key) {
                Some(&p) => p,
                None => {
                    let p = pipe::create(ctx, cfg, &d.state, o.layout, o.render_pass)?;
                    o.pipelines.push(p);
                    pipe_of.insert(key, p);
                    p
                }
            };
            let push = umbrage::pass::push::VolumePush::new(d.mvp, glam::Vec4::W, [0.0; 4]);
            let query = if d.query {
                queries += 1;
                Some(queries - 1)
            } else {
                None
            };
            recs.push(BatchDraw {
                tile: (ox, oy, c.size.0, c.size.1),
                pipeline: p,
                state: d.state,
                push: bytemuck::bytes_of(&push).to_vec(),
                first: verts.len() as u32,
                count: d.vertices.len() as u32,
                query,
            });
            verts.extend_from_slice(&d.vertices);
        }
    }
    Ok((recs, verts, queries))
}

/// Sets `st`'s stencil, depth and depth-bounds state (the dynamic-state model).
///
/// # Safety
/// `cb` is recording inside a rendering instance with a pipeline that has these states dynamic.
unsafe fn set_dynamic_state(d: &ash::Device, cb: vk::CommandBuffer, st: &super::cases::DsState, has_depth: bool, bounds_feature: bool) {
    let (front, back) = st.stencil.unwrap_or_default();
    // SAFETY: the caller's contract.
    unsafe {
        d.cmd_set_stencil_test_enable(cb, st.stencil.is_some());
        for (face, s) in [(vk::StencilFaceFlags::FRONT, front), (vk::StencilFaceFlags::BACK, back)] {
            d.cmd_set_stencil_op(cb, face, s.fail_op, s.pass_op, s.depth_fail_op, s.compare_op);
            d.cmd_set_stencil_compare_mask(cb, face, s.compare_mask);
            d.cmd_set_stencil_write_mask(cb, face, s.write_mask);
            d.cmd_set_stencil_reference(cb, face, s.reference);
        }
        d.cmd_set_depth_test_enable(cb, st.depth_test && has_depth);
        d.cmd_set_depth_write_enable(cb, st.depth_write && has_depth);
        d.cmd_set_depth_compare_op(cb, st.depth_compare);
        if bounds_feature {
            let (lo, hi) = st.depth_bounds.unwrap_or((0.0, 1.0));
            d.cmd_set_depth_bounds_test_enable(cb, st.depth_bounds.is_some());
            d.cmd_set_depth_bounds(cb, lo, hi);
        }
    }
}

/// Each case's tile of the read-back depth (`bpp` bytes a texel; none when 0 or no depth) and
/// stencil, with its share of the occlusion query `counts`.
fn tiles(
    cases: &[&Case],
    origins: &[(u32, u32)],
    width: u32,
    (depth_bytes, stencil_bytes): (&[u8], &[u8]),
    bpp: usize,
    counts: &[u64],
) -> Vec<TileResult> {
    let mut out = Vec::with_capacity(cases.len());
    let mut qi = 0usize;
    for (c, &(ox, oy)) in cases.iter().zip(origins) {
        let (tw, th) = c.size;
        let mut t = TileResult { depth: Vec::new(), stencil: Vec::with_capacity((tw * th) as usize), queries: Vec::new() };
        for ty in 0..th {
            for tx in 0..tw {
                let ii = ((oy + ty) * width + ox + tx) as usize;
                t.stencil.push(stencil_bytes[ii]);
                if bpp > 0 {
                    let mut w = [0u8; 4];
                    w[..bpp].copy_from_slice(&depth_bytes[ii * bpp..(ii + 1) * bpp]);
                    t.depth.push(u32::from_le_bytes(w));
                }
            }
        }
        let nq = c.draws.iter().filter(|d| d.query).count();
        t.queries = counts[qi..qi + nq].to_vec();
        qi += nq;
        out.push(t);
    }
    out
}
