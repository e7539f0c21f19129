//! The `commands.*` checks of the compute path's merged volume draws
//! (src/pass/compute/draws.rs): `multi_draw_indirect` (one `vkCmdDrawIndexedIndirect` of
//! several records) and `draw_indirect_count` (`vkCmdDrawIndexedIndirectCount`, its count read
//! from a buffer a transfer wrote in the same submission), drawn as the pass draws them:
//! `shadow.vert`'s TABLE variant, each record's quad in one shared vertex buffer at its
//! `vertexOffset` and `firstIndex`, transformed by the per-instance entry its `firstInstance`
//! (and instance) selects, 20 bytes apart, in a classic render pass (so Vulkan 1.0 devices
//! run the multi-draw check too). The stencil is held to a CPU model of the records, pixel for
//! pixel: a record read from the wrong place, a count or `maxDrawCount` not honoured, or a
//! wrong `vertexOffset`, `firstIndex` or `firstInstance` changes it.

use super::*;

/// The quads of the shared vertex buffer, four vertices each, in pixels: 0 is a decoy
/// covering the image (drawn only by a misread record), 1-4 the records' quads.
const QUADS: [[f32; 4]; 5] =
    [[0.0, 0.0, W as f32, H as f32], [1.0, 1.0, 9.0, 7.0], [10.0, 2.0, 16.0, 12.0], [3.0, 8.0, 12.0, 15.0], [14.0, 9.0, 23.0, 15.0]];
/// The per-instance translations (pixels), entries 0-3 of the transform table.
const MOVES: [[f32; 2]; 4] = [[0.0, 0.0], [24.0, 0.0], [0.0, 16.0], [40.0, 16.0]];
/// Indices: at 0 the chunk's first quad, at 6 its second (local vertices 4-7).
const INDICES: [u16; 12] = [0, 1, 2, 0, 2, 3, 4, 5, 6, 4, 6, 7];
/// Bytes of a record (the stride of every call).
const STRIDE: u32 = std::mem::size_of::<vk::DrawIndexedIndirectCommand>() as u32;

fn rec(index_count: u32, instance_count: u32, first_index: u32, vertex_offset: i32, first_instance: u32) -> vk::DrawIndexedIndirectCommand {
    vk::DrawIndexedIndirectCommand { index_count, instance_count, first_index, vertex_offset, first_instance }
}

/// The records, from byte 0: a garbage lead-in (the decoy over the whole image), six
/// records, a garbage tail. Record 2 reads the second quad of the chunk at vertex 8 (quad 3),
/// record 6 the second quad of the chunk at vertex 4 (quad 2); 3 has no instance, 4 no index.
fn records() -> Vec<vk::DrawIndexedIndirectCommand> {
    let garbage = rec(6, 1, 0, 0, 0);
    vec![
        garbage,
        rec(6, 1, 0, 4, 1),
        rec(6, 2, 6, 8, 2),
        rec(6, 0, 0, 12, 0),
        rec(0, 1, 0, 12, 0),
        rec(6, 1, 0, 16, 0),
        rec(6, 1, 6, 4, 3),
        garbage,
    ]
}

/// What the records `first..first + n` draw into `grid` (stencil increments, wrapping).
fn model(grid: &mut [u8], records: &[vk::DrawIndexedIndirectCommand], first: usize, n: usize) {
    for r in &records[first..first + n] {
        if r.index_count != 6 {
            continue; // the records draw whole quads or nothing
        }
        let quad = QUADS[(r.vertex_offset as usize + if r.first_index == 6 { 4 } else { 0 }) / 4];
        for i in 0..r.instance_count {
            let [dx, dy] = MOVES[(r.first_instance + i) as usize];
            for y in (quad[1] + dy) as u32..(quad[3] + dy) as u32 {
                for x in (quad[0] + dx) as u32..(quad[2] + dx) as u32 {
                    let p = &mut grid[(y * W + x) as usize];
                    *p = p.wrapping_add(1);
                }
            }
        }
    }
}

/// The calls a check records: `Multi(offset in records, draw count)` or `Count(offset, count
/// word, max draw count)`; the count words are written by `vkCmdFillBuffer` first.
#[derive(Clone, Copy)]
enum Call {
    Multi(usize, u32),
    Count(usize, usize, u32),
}

/// Draws `calls` over [`records`] (count words `counts` after them) with the TABLE pipeline
/// into a cleared stencil; returns the stencil and the model's.
fn draw(ctx: &Context, calls: &[Call], counts: &[u32]) -> Result<(Vec<u8>, Vec<u8>)> {
    let format = ctx.depth_format;
    let recs = records();
    let mut want = vec![0u8; (W * H) as usize];
    for &c in calls {
        match c {
            Call::Multi(first, n) => model(&mut want, &recs, first, n as usize),
            Call::Count(first, k, max) => model(&mut want, &recs, first, counts[k].min(max) as usize),
        }
    }
    let mut s = Scratch::new(ctx);
    let vertices: Vec<[f32; 4]> =
        QUADS.iter().flat_map(|q| [[q[0], q[1]], [q[2], q[1]], [q[2], q[3]], [q[0], q[3]]]).map(|[x, y]| [x, y, 0.5, 1.0]).collect();
    let proj = harness::pixel_ortho(W, H);
    let table: Vec<f32> = MOVES
        .iter()
        .flat_map(|&[dx, dy]| {
            let mvp = proj * glam::Mat4::from_translation(glam::Vec3::new(dx, dy, 0.0));
            mvp.to_cols_array().into_iter().chain([0.0, 0.0, 0.0, 1.0])
        })
        .collect();
    let words: Vec<u32> = recs
        .iter()
        .flat_map(|r| [r.index_count, r.instance_count, r.first_index, r.vertex_offset as u32, r.first_instance])
        .chain(counts.iter().map(|_| 0xdead))
        .collect();
    let counts_at = (recs.len() as u32 * STRIDE) as u64;
    let as_bytes = |v: &[u32]| v.iter().flat_map(|w| w.to_le_bytes()).collect::<Vec<u8>>();
    let vertex = vk::BufferUsageFlags::VERTEX_BUFFER;
    let indirect = vk::BufferUsageFlags::INDIRECT_BUFFER | vk::BufferUsageFlags::TRANSFER_DST;
    for (name, data, usage) in [
        ("conform-multidraw-vertices", vertices.iter().flatten().flat_map(|f| f.to_le_bytes()).collect::<Vec<u8>>(), vertex),
        ("conform-multidraw-table", table.iter().flat_map(|f| f.to_le_bytes()).collect(), vertex),
        ("conform-multidraw-indices", INDICES.iter().flat_map(|i| i.to_le_bytes()).collect(), vk::BufferUsageFlags::INDEX_BUFFER),
        ("conform-multidraw-records", as_bytes(&words), indirect),
    ] {
        s.buffers.push(Buffer::with_data(ctx, name, &data, usage)?);
    }
    let n = s.buffers.len();
    let (vb, tb, ib, rb) = (s.buffers[n - 4].raw, s.buffers[n - 3].raw, s.buffers[n - 2].raw, s.buffers[n - 1].raw);
    let usage = vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT | vk::ImageUsageFlags::TRANSFER_SRC;
    let i = s.image(format, vk::Extent2D { width: W, height: H }, usage, DS)?;
    let view = s.images[i].view;
    let (pass, fb) = s.render_pass(format, view, (vk::AttachmentLoadOp::CLEAR, vk::AttachmentLoadOp::CLEAR))?;
    let push = [vk::PushConstantRange { stage_flags: vk::ShaderStageFlags::VERTEX, offset: 0, size: 96 }];
    // SAFETY: valid device and create info; destroyed below.
    let layout = unsafe { ctx.device.create_pipeline_layout(&vk::PipelineLayoutCreateInfo::default().push_constant_ranges(&push), None) }
        .map_err(vkerr("vkCreatePipelineLayout"))?;
    let attributes: Vec<(u32, vk::Format, u32)> = (0..5).map(|k| (1 + k, vk::Format::R32G32B32A32_SFLOAT, 16 * k)).collect();
    let mut desc = umbrage::gpu::pipeline::PipelineDesc::new(crate::shaders::SHADOW_TABLE_VERT, layout, format);
    desc.vertex_stride = 16;
    desc.attributes = &[(0, vk::Format::R32G32B32A32_SFLOAT, 0)];
    desc.instance_stride = 80;
    desc.instance_attributes = &attributes;
    let incr = umbrage::gpu::pipeline::stencil_ops(vk::StencilOp::INCREMENT_AND_WRAP, vk::StencilOp::INCREMENT_AND_WRAP);
    desc.stencil = Some((incr, incr));
    desc.render_pass = Some((pass, 0, 0));
    let pipeline = umbrage::gpu::pipeline::create(ctx, &desc);
    let result = pipeline.and_then(|pipeline| {
        let img = &s.images[i];
        let ran = ctx.one_shot(|cb| {
            let d = &ctx.device;
            transition(ctx, cb, img, vk::ImageLayout::UNDEFINED, vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL);
            // SAFETY: recording outside any render pass; the buffer has room for the words.
            unsafe {
                for (k, &c) in counts.iter().enumerate() {
                    d.cmd_fill_buffer(cb, rb, counts_at + 4 * k as u64, 4, c);
                }
            }
            use vk::AccessFlags2 as A;
            use vk::PipelineStageFlags2 as S;
            memory_barrier(ctx, cb, (S::TRANSFER, A::TRANSFER_WRITE), (S::DRAW_INDIRECT, A::INDIRECT_COMMAND_READ));
            let clear = [vk::ClearValue { depth_stencil: vk::ClearDepthStencilValue { depth: 1.0, stencil: 0 } }];
            let begin = vk::RenderPassBeginInfo::default().render_pass(pass).framebuffer(fb).render_area(full()).clear_values(&clear);
            let viewport = vk::Viewport { x: 0.0, y: 0.0, width: W as f32, height: H as f32, min_depth: 0.0, max_depth: 1.0 };
            // SAFETY: recording; every handle outlives the submission (one_shot waits); the
            // records' reads stay inside the buffer.
            unsafe {
                d.cmd_begin_render_pass(cb, &begin, vk::SubpassContents::INLINE);
                d.cmd_set_viewport(cb, 0, &[viewport]);
                d.cmd_set_scissor(cb, 0, &[full()]);
                d.cmd_bind_pipeline(cb, vk::PipelineBindPoint::GRAPHICS, pipeline);
                d.cmd_bind_vertex_buffers(cb, 0, &[vb, tb], &[0, 0]);
                d.cmd_bind_index_buffer(cb, ib, 0, vk::IndexType::UINT16);
                for &c in calls {
                    match c {
                        Call::Multi(first, n) => d.cmd_draw_indexed_indirect(cb, rb, first as u64 * STRIDE as u64, n, STRIDE),
                        Call::Count(first, k, max) => d.cmd_draw_indexed_indirect_count(
                            cb,
                            rb,
                            first as u64 * STRIDE as u64,
                            rb,
                            counts_at + 4 * k as u64,
                            max,
                            STRIDE,
                        ),
                    }
                }
                d.cmd_end_render_pass(cb);
            }
        });
        // SAFETY: one_shot waited for the submission: the pipeline is no longer in use.
        unsafe { ctx.device.destroy_pipeline(pipeline, None) };
        ran?;
        read_aspects(&mut s, i, format, vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL)
    });
    // SAFETY: nothing uses the layout any more (one_shot waited, or nothing was submitted).
    unsafe { ctx.device.destroy_pipeline_layout(layout, None) };
    let (_, stencil) = result?;
    Ok((stencil, want))
}

/// The result of a check whose stencil is `got` against `want`.
fn judge(name: &str, (got, mut want): (Vec<u8>, Vec<u8>), what: &str) -> CheckResult {
    if crate::value_images::skewed() {
        want[0] = want[0].wrapping_add(1);
    }
    let bad = (0..want.len()).filter(|&i| got[i] != want[i]).count();
    if bad > 0 {
        crate::image_sink::stencil_mismatch(W, H, &want, &vec![true; want.len()], &got);
    }
    let mut numbers = serde_json::Map::new();
    numbers.insert("mismatched_pixels".into(), json!(bad));
    numbers.insert("covered_pixels".into(), json!(want.iter().filter(|&&c| c > 0).count()));
    let fails = if bad > 0 { vec![format!("{bad} pixels differ from the records' coverage")] } else { vec![] };
    CheckResult::from_fails(name, fails, numbers, what)
}

/// `commands.multi_draw_indirect`: two `vkCmdDrawIndexedIndirect` calls of 4 and 2 records
/// (stride 20) between garbage records, with per-record `vertexOffset`, `firstIndex` and
/// `firstInstance`, an empty record of each kind and one of two instances.
pub fn multi_draw_indirect(ctx: &Context) -> Result<CheckResult> {
    let f = &ctx.features;
    if !(f.multi_draw_indirect && f.draw_indirect_first_instance) {
        let why = "unsupported: the device lacks multiDrawIndirect or drawIndirectFirstInstance (the compute path draws one record per call there)";
        return Ok(CheckResult::skipped("multi_draw_indirect", why));
    }
    let got = draw(ctx, &[Call::Multi(1, 4), Call::Multi(5, 2)], &[])?;
    let what = "vkCmdDrawIndexedIndirect with drawCount 4 and 2 (stride 20) at byte offsets 20 and 100: each record's vertexOffset, \
                firstIndex and firstInstance (per-instance attributes), instanceCount 0 and 2, indexCount 0, exact; the garbage \
                records around them never drawn";
    Ok(judge("multi_draw_indirect", got, what))
}

/// `commands.draw_indirect_count`: `vkCmdDrawIndexedIndirectCount` with its count (written by
/// `vkCmdFillBuffer` in the same submission) below `maxDrawCount`, above it, and 0.
pub fn draw_indirect_count(ctx: &Context) -> Result<CheckResult> {
    let f = &ctx.features;
    if !(f.draw_indirect_count && f.multi_draw_indirect && f.draw_indirect_first_instance) {
        let why = format!(
            "unsupported: the device (Vulkan {}) lacks drawIndirectCount (Vulkan 1.2), multiDrawIndirect or \
             drawIndirectFirstInstance (the compute path draws without the count there)",
            ctx.info.api_version
        );
        return Ok(CheckResult::skipped("draw_indirect_count", &why));
    }
    let calls = [Call::Count(1, 0, 6), Call::Count(5, 1, 2), Call::Count(1, 2, 4)];
    let got = draw(ctx, &calls, &[3, 9, 0])?;
    let what = "vkCmdDrawIndexedIndirectCount (stride 20) with the count read from a buffer a fill wrote before (transfer -> \
                indirect barrier): count 3 of at most 6 records, count 9 of at most 2, count 0 of at most 4, each record's \
                vertexOffset, firstIndex and firstInstance exact; no record past min(count, maxDrawCount) drawn";
    Ok(judge("draw_indirect_count", got, what))
}
