//! The `commands.*` checks: the Vulkan commands umbrage records outside its draws, each held
//! to the exact semantics the spec gives it, against a CPU model of the result — not only
//! through the draws they serve. `docs/conform/coverage.md` maps every command and state the
//! renderer, `ShadowPass` and the hosts record to the family that checks it.
//!
//! - `clears`: `vkCmdClearAttachments` inside a rendering instance and inside a classic
//!   subpass, per aspect mask, with several rects, a stencil clear value wider than 8 bits (only
//!   its low bits count), a scissor that must not apply; load ops per aspect (depth `LOAD`,
//!   stencil `CLEAR` and the reverse) limited to a partial render area.
//! - `copy_aspects`: `vkCmdCopyImageToBuffer` of the depth and the stencil aspect of every
//!   depth-stencil format, with a buffer offset, a row length and image height larger than
//!   the region and an image offset: each texel at its address, 2 bytes (D16) or 4 (D24 as X8D24,
//!   D32) of depth, 1 of stencil, every byte outside the region untouched.
//! - `layouts`: contents kept through every layout transition umbrage and its hosts use.
//! - `blit_copy_color`: `vkCmdCopyImage` and `vkCmdBlitImage` (`NEAREST`, scaling up by
//!   non-integer ratios, RGBA to BGRA) as the viewer presents; the copy kept through the colour
//!   layouts.
//! - `buffers`: `vkCmdUpdateBuffer` and `vkCmdCopyBuffer` with offsets: every byte.
//! - `queries`: query resets of a sub-range, precise occlusion counts, results read from a
//!   first query with 32- and 64-bit strides and availability, an unavailable query reported
//!   as such, pipeline statistics in flag-bit order, timestamps in order.
//! - `scissor`: `vkCmdSetScissor` per draw, including a scissor past the image and an empty one.
//! - `indirect`: `vkCmdDrawIndexedIndirect` one record at a time at non-zero offsets, with
//!   `firstIndex`, `vertexOffset` and an `instanceCount` of 0 (the compute path's per chunk).
//! - `fill_buffer`: `vkCmdFillBuffer` at offsets, over an earlier fill, and `VK_WHOLE_SIZE` to
//!   the last whole word of a buffer whose size is not a multiple of 4: every byte.
//! - `dispatch`: `vkCmdDispatch` with the 2D group counts `--method compute` splits a large
//!   dispatch into, after a `vkCmdFillBuffer`: every group and invocation once with its
//!   builtins, storage-buffer atomics exact; group counts of 0 dispatch nothing.
//! - `dispatch_indirect`: `vkCmdDispatchIndirect` of a command at a non-zero offset that an
//!   earlier dispatch grew with `atomicMax`: exactly its groups; a command with x = 0 nothing.
//! - `multi_draw_indirect`, `draw_indirect_count`: the compute path's merged draws (`multidraw.rs`).

use super::rect;
use crate::harness::{self, DrawCall, Draws, Indices, PipeSpec};
use crate::CheckResult;
use ash::vk;
use gpu_allocator::MemoryLocation;
use serde_json::json;
use umbrage::error::{Error, Result};
use umbrage::gpu::resources::{aspect_copy, cleared_depth_stencil, memory_barrier, transfer_to_host_barrier, transition};
use umbrage::gpu::{Buffer, Context, Image};

/// The checks' names (cases `commands.<name>`), in run order.
pub const NAMES: [&str; 13] = [
    "clears",
    "copy_aspects",
    "layouts",
    "blit_copy_color",
    "buffers",
    "queries",
    "scissor",
    "indirect",
    "fill_buffer",
    "dispatch",
    "dispatch_indirect",
    "multi_draw_indirect",
    "draw_indirect_count",
];

fn vkerr(call: &'static str) -> impl Fn(vk::Result) -> Error {
    Error::vk(call)
}

const DS: vk::ImageAspectFlags =
    vk::ImageAspectFlags::from_raw(vk::ImageAspectFlags::DEPTH.as_raw() | vk::ImageAspectFlags::STENCIL.as_raw());
const W: u32 = 64;
const H: u32 = 32;
/// The byte every read-back buffer starts with: a byte the device did not write keeps it.
const UNTOUCHED: u8 = 0xee;

/// The depth-stencil formats with 8 bits of stencil the device can attach and copy from.
fn ds_formats(ctx: &Context) -> Vec<vk::Format> {
    [vk::Format::D16_UNORM_S8_UINT, vk::Format::D24_UNORM_S8_UINT, vk::Format::D32_SFLOAT_S8_UINT]
        .into_iter()
        .filter(|&f| harness::format_supported(ctx, f))
        .collect()
}

fn short(format: vk::Format) -> &'static str {
    match format {
        vk::Format::D16_UNORM_S8_UINT => "d16s8",
        vk::Format::D24_UNORM_S8_UINT => "d24s8",
        _ => "d32s8",
    }
}

/// Bytes per texel of a copied depth aspect: 2 for D16, 4 for D24 (X8_D24, top byte
/// undefined) and D32.
fn depth_texel_bytes(format: vk::Format) -> usize {
    if format == vk::Format::D16_UNORM_S8_UINT {
        2
    } else {
        4
    }
}

/// Whether the copied depth texel `bytes` holds `value`: D32 bit for bit; UNORM formats within
/// one step of `value * (2^b - 1)` (the spec's float-to-unorm conversion picks either
/// neighbour), D24's undefined top byte ignored.
fn depth_matches(format: vk::Format, bytes: &[u8], value: f32) -> bool {
    match format {
        vk::Format::D16_UNORM_S8_UINT => {
            let word = u16::from_le_bytes([bytes[0], bytes[1]]) as f64;
            (word - value as f64 * 65_535.0).abs() < 1.0
        }
        vk::Format::D24_UNORM_S8_UINT => {
            let word = (u32::from_le_bytes([bytes[0], bytes[1], bytes[2], bytes[3]]) & 0x00ff_ffff) as f64;
            (word - value as f64 * 16_777_215.0).abs() < 1.0
        }
        _ => f32::from_le_bytes([bytes[0], bytes[1], bytes[2], bytes[3]]) == value,
    }
}

/// The CPU model of a depth-stencil image.
#[derive(Clone)]
struct Grid {
    depth: Vec<f32>,
    stencil: Vec<u8>,
}

impl Grid {
    fn new(depth: f32, stencil: u8) -> Grid {
        Grid { depth: vec![depth; (W * H) as usize], stencil: vec![stencil; (W * H) as usize] }
    }
    /// Writes `depth` and/or `stencil` over `r` clipped to the image.
    fn fill(&mut self, r: vk::Rect2D, depth: Option<f32>, stencil: Option<u8>) {
        let x1 = (r.offset.x as i64 + r.extent.width as i64).min(W as i64);
        let y1 = (r.offset.y as i64 + r.extent.height as i64).min(H as i64);
        for y in r.offset.y.max(0) as i64..y1 {
            for x in r.offset.x.max(0) as i64..x1 {
                let i = (y * W as i64 + x) as usize;
                if let Some(d) = depth {
                    self.depth[i] = d;
                }
                if let Some(s) = stencil {
                    self.stencil[i] = s;
                }
            }
        }
    }
}

fn rect2d(x: i32, y: i32, w: u32, h: u32) -> vk::Rect2D {
    vk::Rect2D { offset: vk::Offset2D { x, y }, extent: vk::Extent2D { width: w, height: h } }
}

fn full() -> vk::Rect2D {
    rect2d(0, 0, W, H)
}

/// Objects a check made, destroyed (after the device is idle) whatever the check returns.
struct Scratch<'a> {
    ctx: &'a Context,
    images: Vec<Image>,
    buffers: Vec<Buffer>,
    passes: Vec<vk::RenderPass>,
    framebuffers: Vec<vk::Framebuffer>,
    pools: Vec<vk::QueryPool>,
}

impl<'a> Scratch<'a> {
    fn new(ctx: &'a Context) -> Scratch<'a> {
        Scratch { ctx, images: Vec::new(), buffers: Vec::new(), passes: Vec::new(), framebuffers: Vec::new(), pools: Vec::new() }
    }
    fn image(
        &mut self,
        format: vk::Format,
        extent: vk::Extent2D,
        usage: vk::ImageUsageFlags,
        aspect: vk::ImageAspectFlags,
    ) -> Result<usize> {
        self.images.push(Image::new_2d(self.ctx, "conform-commands", format, extent, usage, aspect)?);
        Ok(self.images.len() - 1)
    }
    /// A host-visible transfer buffer of `size` bytes, every byte [`UNTOUCHED`].
    fn readback(&mut self, size: u64) -> Result<usize> {
        let usage = vk::BufferUsageFlags::TRANSFER_DST | vk::BufferUsageFlags::TRANSFER_SRC;
        let mut b = Buffer::new(self.ctx, "conform-commands-readback", size, usage, MemoryLocation::GpuToCpu)?;
        let filled = b.write(0, &vec![UNTOUCHED; size as usize]);
        self.buffers.push(b);
        filled?;
        Ok(self.buffers.len() - 1)
    }
    fn query_pool(&mut self, ty: vk::QueryType, count: u32, stats: vk::QueryPipelineStatisticFlags) -> Result<vk::QueryPool> {
        let info = vk::QueryPoolCreateInfo::default().query_type(ty).query_count(count).pipeline_statistics(stats);
        // SAFETY: valid device and create info; destroyed in Drop.
        let pool = unsafe { self.ctx.device.create_query_pool(&info, None) }.map_err(vkerr("vkCreateQueryPool"))?;
        self.pools.push(pool);
        Ok(pool)
    }
    /// A one-subpass render pass over one depth-stencil attachment of `format` (in and out of
    /// DEPTH_STENCIL_ATTACHMENT_OPTIMAL) with these load ops, both aspects stored, and its
    /// framebuffer over `view`.
    fn render_pass(
        &mut self,
        format: vk::Format,
        view: vk::ImageView,
        (depth_load, stencil_load): (vk::AttachmentLoadOp, vk::AttachmentLoadOp),
    ) -> Result<(vk::RenderPass, vk::Framebuffer)> {
        let layout = vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL;
        let att = [vk::AttachmentDescription::default()
            .format(format)
            .samples(vk::SampleCountFlags::TYPE_1)
            .load_op(depth_load)
            .store_op(vk::AttachmentStoreOp::STORE)
            .stencil_load_op(stencil_load)
            .stencil_store_op(vk::AttachmentStoreOp::STORE)
            .initial_layout(layout)
            .final_layout(layout)];
        let ds_ref = vk::AttachmentReference { attachment: 0, layout };
        let subpass =
            [vk::SubpassDescription::default().pipeline_bind_point(vk::PipelineBindPoint::GRAPHICS).depth_stencil_attachment(&ds_ref)];
        let info = vk::RenderPassCreateInfo::default().attachments(&att).subpasses(&subpass);
        // SAFETY: valid device and create info; destroyed in Drop.
        let pass = unsafe { self.ctx.device.create_render_pass(&info, None) }.map_err(vkerr("vkCreateRenderPass"))?;
        self.passes.push(pass);
        let views = [view];
        let fb_info = vk::FramebufferCreateInfo::default().render_pass(pass).attachments(&views).width(W).height(H).layers(1);
        // SAFETY: as above; the view outlives the framebuffer (both freed in Drop, framebuffers first).
        let fb = unsafe { self.ctx.device.create_framebuffer(&fb_info, None) }.map_err(vkerr("vkCreateFramebuffer"))?;
        self.framebuffers.push(fb);
        Ok((pass, fb))
    }
}

impl Drop for Scratch<'_> {
    fn drop(&mut self) {
        let d = &self.ctx.device;
        // SAFETY: after the wait nothing is in use; every handle was created on this device.
        unsafe {
            let _ = d.device_wait_idle();
            for fb in self.framebuffers.drain(..) {
                d.destroy_framebuffer(fb, None);
            }
            for p in self.passes.drain(..) {
                d.destroy_render_pass(p, None);
            }
            for p in self.pools.drain(..) {
                d.destroy_query_pool(p, None);
            }
        }
        for i in &mut self.images {
            i.destroy(self.ctx);
        }
        for b in &mut self.buffers {
            b.destroy(self.ctx);
        }
    }
}

/// How a rendering instance is begun.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Model {
    DynamicRendering,
    RenderPass,
}

impl Model {
    fn name(self) -> &'static str {
        match self {
            Model::DynamicRendering => "dynamic_rendering",
            Model::RenderPass => "render_pass",
        }
    }
}

/// One rendering instance of the pattern: its load ops and clear value, its render area, and
/// the `vkCmdClearAttachments` calls inside it.
struct Instance {
    load: (vk::AttachmentLoadOp, vk::AttachmentLoadOp),
    clear: (f32, u32),
    area: vk::Rect2D,
    clears: Vec<(vk::ImageAspectFlags, f32, u32, Vec<vk::Rect2D>)>,
}

/// The pattern `clears` checks and the other checks start from: instances with every load-op
/// pair and clears of each aspect mask, and what the spec says the image then holds.
fn pattern() -> (Vec<Instance>, Grid) {
    use vk::AttachmentLoadOp as L;
    use vk::ImageAspectFlags as A;
    let instances = vec![
        Instance {
            load: (L::CLEAR, L::CLEAR),
            clear: (0.25, 0x5a),
            area: full(),
            clears: vec![
                // The depth value of a stencil-only clear (and the stencil of a depth-only one)
                // must be ignored; of the stencil value only the low 8 bits count.
                (A::STENCIL, 0.875, 0x1c3, vec![rect2d(2, 3, 10, 7), rect2d(20, 1, 5, 5)]),
                (A::DEPTH, 0.75, 0x11, vec![rect2d(8, 5, 12, 6)]),
                (DS, 1.0, 0xff, vec![rect2d(30, 10, 4, 4), rect2d(40, 20, 24, 12)]),
                (DS, 0.0, 0x00, vec![rect2d(0, 31, 64, 1)]),
            ],
        },
        // Depth kept, stencil cleared, only inside the render area.
        Instance { load: (L::LOAD, L::CLEAR), clear: (0.5, 0x33), area: rect2d(16, 8, 32, 16), clears: vec![] },
        // Depth cleared, stencil kept; a clear inside the partial area.
        Instance {
            load: (L::CLEAR, L::LOAD),
            clear: (0.125, 0x77),
            area: rect2d(0, 24, 48, 8),
            clears: vec![(A::STENCIL, 0.0, 0x0f, vec![rect2d(44, 26, 4, 2)])],
        },
    ];
    let mut g = Grid::new(0.0, 0);
    for inst in &instances {
        let (d, s) = inst.clear;
        g.fill(inst.area, (inst.load.0 == L::CLEAR).then_some(d), (inst.load.1 == L::CLEAR).then_some(s as u8));
        for (aspect, d, s, rects) in &inst.clears {
            for r in rects {
                g.fill(*r, aspect.contains(A::DEPTH).then_some(*d), aspect.contains(A::STENCIL).then_some((*s & 0xff) as u8));
            }
        }
    }
    (instances, g)
}

/// Makes a `W` x `H` depth-stencil image of `format` (with `usage` besides attachment and
/// transfer source) holding [`pattern`], drawn through `model`; returns its index in `s` and
/// the model of its contents, the image left in DEPTH_STENCIL_ATTACHMENT_OPTIMAL.
fn patterned(s: &mut Scratch<'_>, format: vk::Format, model: Model, usage: vk::ImageUsageFlags) -> Result<(usize, Grid)> {
    let ctx = s.ctx;
    let usage = usage | vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT | vk::ImageUsageFlags::TRANSFER_SRC;
    let i = s.image(format, vk::Extent2D { width: W, height: H }, usage, DS)?;
    let (instances, grid) = pattern();
    let mut passes = Vec::new();
    if model == Model::RenderPass {
        let view = s.images[i].view;
        for inst in &instances {
            passes.push(s.render_pass(format, view, inst.load)?);
        }
    }
    let img = &s.images[i];
    let layout = vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL;
    ctx.one_shot(|cb| {
        let d = &ctx.device;
        transition(ctx, cb, img, vk::ImageLayout::UNDEFINED, layout);
        for (k, inst) in instances.iter().enumerate() {
            if k > 0 {
                // The next instance's load ops read and write what this one stored.
                let tests = vk::PipelineStageFlags2::EARLY_FRAGMENT_TESTS | vk::PipelineStageFlags2::LATE_FRAGMENT_TESTS;
                memory_barrier(
                    ctx,
                    cb,
                    (tests, vk::AccessFlags2::DEPTH_STENCIL_ATTACHMENT_WRITE),
                    (tests, vk::AccessFlags2::DEPTH_STENCIL_ATTACHMENT_READ | vk::AccessFlags2::DEPTH_STENCIL_ATTACHMENT_WRITE),
                );
            }
            let value = vk::ClearValue { depth_stencil: vk::ClearDepthStencilValue { depth: inst.clear.0, stencil: inst.clear.1 } };
            let depth_att = vk::RenderingAttachmentInfo::default()
                .image_view(img.view)
                .image_layout(layout)
                .load_op(inst.load.0)
                .store_op(vk::AttachmentStoreOp::STORE)
                .clear_value(value);
            let stencil_att = depth_att.load_op(inst.load.1);
            let values = [value];
            // SAFETY: `cb` is recording outside a rendering instance; the image, its view and
            // the render passes belong to this device and outlive the submission (one_shot waits).
            unsafe {
                match model {
                    Model::DynamicRendering => {
                        let info = vk::RenderingInfo::default()
                            .render_area(inst.area)
                            .layer_count(1)
                            .depth_attachment(&depth_att)
                            .stencil_attachment(&stencil_att);
                        d.cmd_begin_rendering(cb, &info);
                    }
                    Model::RenderPass => {
                        let (pass, fb) = passes[k];
                        let info = vk::RenderPassBeginInfo::default()
                            .render_pass(pass)
                            .framebuffer(fb)
                            .render_area(inst.area)
                            .clear_values(&values);
                        d.cmd_begin_render_pass(cb, &info, vk::SubpassContents::INLINE);
                    }
                }
                // Clears ignore the scissor (and every other piece of pipeline state).
                d.cmd_set_scissor(cb, 0, &[rect2d(W as i32 - 1, 0, 1, 1)]);
                for (aspect, depth, stencil, rects) in &inst.clears {
                    let clear = [vk::ClearAttachment {
                        aspect_mask: *aspect,
                        color_attachment: 0,
                        clear_value: vk::ClearValue { depth_stencil: vk::ClearDepthStencilValue { depth: *depth, stencil: *stencil } },
                    }];
                    let rects: Vec<vk::ClearRect> =
                        rects.iter().map(|&rect| vk::ClearRect { rect, base_array_layer: 0, layer_count: 1 }).collect();
                    d.cmd_clear_attachments(cb, &clear, &rects);
                }
                match model {
                    Model::DynamicRendering => d.cmd_end_rendering(cb),
                    Model::RenderPass => d.cmd_end_render_pass(cb),
                }
            }
        }
    })?;
    Ok((i, grid))
}

/// Copies both aspects of image `i` (in `layout`, returned to it) tightly into a new buffer:
/// (depth bytes, stencil bytes).
fn read_aspects(s: &mut Scratch<'_>, i: usize, format: vk::Format, layout: vk::ImageLayout) -> Result<(Vec<u8>, Vec<u8>)> {
    let ctx = s.ctx;
    let n = (W * H) as u64;
    let db = depth_texel_bytes(format) as u64;
    let b = s.readback(n * db + n)?;
    let (img, buf) = (&s.images[i], s.buffers[b].raw);
    let extent = vk::Extent2D { width: W, height: H };
    ctx.one_shot(|cb| {
        transition(ctx, cb, img, layout, vk::ImageLayout::TRANSFER_SRC_OPTIMAL);
        let regions = [aspect_copy(vk::ImageAspectFlags::DEPTH, extent, 0), aspect_copy(vk::ImageAspectFlags::STENCIL, extent, n * db)];
        // SAFETY: recording outside rendering; the image is in TRANSFER_SRC_OPTIMAL and the
        // buffer holds both aspects at these offsets (a multiple of 4: n is).
        unsafe { ctx.device.cmd_copy_image_to_buffer(cb, img.raw, vk::ImageLayout::TRANSFER_SRC_OPTIMAL, buf, &regions) };
        transition(ctx, cb, img, vk::ImageLayout::TRANSFER_SRC_OPTIMAL, layout);
        transfer_to_host_barrier(ctx, cb);
    })?;
    let bytes = s.buffers[b].read()?;
    let split = (n * db) as usize;
    Ok((bytes[..split].to_vec(), bytes[split..].to_vec()))
}

/// Mismatched (depth, stencil) texels of tightly packed aspects against `g`.
fn compare_grid(format: vk::Format, g: &Grid, depth: &[u8], stencil: &[u8]) -> (usize, usize) {
    let db = depth_texel_bytes(format);
    let dm = (0..g.depth.len()).filter(|&i| !depth_matches(format, &depth[i * db..(i + 1) * db], g.depth[i])).count();
    let sm = (0..g.stencil.len()).filter(|&i| stencil[i] != g.stencil[i]).count();
    (dm, sm)
}

/// A texel's depth in 0..1 from a read-back depth aspect (`db` bytes a texel).
fn depth_value(format: vk::Format, depth: &[u8], i: usize) -> f64 {
    let db = depth_texel_bytes(format);
    let b = &depth[i * db..(i + 1) * db];
    match format {
        vk::Format::D16_UNORM_S8_UINT => u16::from_le_bytes([b[0], b[1]]) as f64 / 65_535.0,
        vk::Format::D24_UNORM_S8_UINT => (u32::from_le_bytes([b[0], b[1], b[2], b[3]]) & 0x00ff_ffff) as f64 / 16_777_215.0,
        _ => f32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
    }
}

/// A depth-stencil check's failure images (`<label>.expected_stencil`, `.actual_stencil`,
/// `.expected_depth`, `.actual_depth`, `.diff`: red where the stencil differs, yellow where the
/// depth does), `W` x `H` texels.
fn aspect_images(
    label: &str,
    format: vk::Format,
    (exp_depth, exp_stencil): (&dyn Fn(usize) -> f64, &[u8]),
    (depth, stencil): (&[u8], &[u8]),
    depth_bad: &dyn Fn(usize) -> bool,
) {
    use super::super::image_sink::{save, texels, unit_gray};
    let gray = |v: u8| image::Rgb([v, v, v]);
    save(&format!("{label}.expected_stencil"), &texels(W, H, |i| gray(exp_stencil[i])));
    save(&format!("{label}.actual_stencil"), &texels(W, H, |i| gray(stencil[i])));
    save(&format!("{label}.expected_depth"), &texels(W, H, |i| unit_gray(exp_depth(i))));
    save(&format!("{label}.actual_depth"), &texels(W, H, |i| unit_gray(depth_value(format, depth, i))));
    let diff = texels(W, H, |i| {
        if stencil[i] != exp_stencil[i] {
            image::Rgb([255, 0, 0])
        } else if depth_bad(i) {
            image::Rgb([255, 255, 0])
        } else {
            image::Rgb([0, 0, 0])
        }
    });
    save(&format!("{label}.diff"), &diff);
}

mod aspects;
mod copies;
mod dispatch;
mod draws;
mod multidraw;
pub use aspects::{clears, copy_aspects, layouts};
pub use copies::{blit_copy_color, buffers};
pub use dispatch::{dispatch, dispatch_indirect, fill_buffer};
pub use draws::{indirect, queries, scissor};
pub use multidraw::{draw_indirect_count, multi_draw_indirect};
