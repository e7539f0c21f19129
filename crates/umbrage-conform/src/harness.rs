//! A tiny offscreen harness for the conformance checks: one depth-stencil image of a chosen
//! format, a list of draws through `shaders/shadow.vert` (the EXTRUDE shader, with the light at
//! the origin so that `(xyz, 0)` vertices pass through unchanged), and a read-back of both
//! aspects. Every Vulkan object it creates is destroyed before `render` returns.

use crate::shaders;
use ash::vk;
use glam::Mat4;
use gpu_allocator::MemoryLocation;
use umbrage::error::{Error, Result};
use umbrage::gpu::pipeline::{self, PipelineDesc};
use umbrage::gpu::resources::{aspect_copy, cleared_depth_stencil, transfer_to_host_barrier, transition};
use umbrage::gpu::{Buffer, Context, Image};

/// Fixed-function state of one draw.
#[derive(Clone, Copy)]
pub struct PipeSpec {
    /// Depth test enabled.
    pub depth_test: bool,
    /// Depth writes enabled.
    pub depth_write: bool,
    /// Depth compare op (when `depth_test`).
    pub depth_compare: vk::CompareOp,
    /// `depthClampEnable`: fragments beyond the far plane are clamped to depth 1, not clipped.
    pub depth_clamp: bool,
    /// Depth bounds test with these bounds (dynamic state).
    pub depth_bounds: Option<(f32, f32)>,
    /// Stencil state of front-facing (counter-clockwise in Vulkan's sense) triangles.
    pub front: vk::StencilOpState,
    /// Stencil state of back-facing triangles.
    pub back: vk::StencilOpState,
    /// The scissor set (`vkCmdSetScissor`) before this draw; `None`: the whole image.
    pub scissor: Option<vk::Rect2D>,
}

impl PipeSpec {
    /// No depth test, stencil `op` on both faces (compare ALWAYS).
    pub fn stencil(front: vk::StencilOp, back: vk::StencilOp) -> PipeSpec {
        PipeSpec {
            depth_test: false,
            depth_write: false,
            depth_compare: vk::CompareOp::ALWAYS,
            depth_clamp: false,
            depth_bounds: None,
            front: pipeline::stencil_ops(front, vk::StencilOp::KEEP),
            back: pipeline::stencil_ops(back, vk::StencilOp::KEEP),
            scissor: None,
        }
    }
    /// Stencil REPLACE with `reference` on both faces.
    pub fn replace(reference: u32) -> PipeSpec {
        let mut s = PipeSpec::stencil(vk::StencilOp::REPLACE, vk::StencilOp::REPLACE);
        s.front.reference = reference;
        s.back.reference = reference;
        s
    }
}

/// The index buffer of a draw.
pub enum Indices {
    /// Non-indexed: `vkCmdDraw` over the vertices in order.
    None,
    /// `VK_INDEX_TYPE_UINT8_EXT` (needs `VK_EXT_index_type_uint8`).
    U8(Vec<u8>),
    /// `VK_INDEX_TYPE_UINT16`.
    U16(Vec<u16>),
    /// `VK_INDEX_TYPE_UINT32`.
    U32(Vec<u32>),
    /// `VK_INDEX_TYPE_UINT16` drawn through `vkCmdDrawIndexedIndirect`, one call per record
    /// (draw count 1, stride 20, as `ShadowPass`'s compute path draws): the records sit in one
    /// indirect buffer after `lead_in` unused records, so every call has a non-zero offset.
    Indirect16 {
        /// The index buffer.
        indices: Vec<u16>,
        /// The draws' parameters.
        records: Vec<vk::DrawIndexedIndirectCommand>,
        /// Records (filled with garbage that must never be drawn) before the first one.
        lead_in: u32,
    },
}

/// One draw of a [`render`]: triangles through their own pipeline.
pub struct DrawCall {
    /// The fixed-function state.
    pub spec: PipeSpec,
    /// Object -> clip transform (the shader's model-view-projection).
    pub mvp: Mat4,
    /// Homogeneous object-space vertices.
    pub vertices: Vec<[f32; 4]>,
    /// The index buffer (triangle list).
    pub indices: Indices,
}

/// What came back: raw depth words (f32 bits for D32, 24-bit unorm in the low bits for D24)
/// and stencil bytes, row-major from the top-left.
pub struct Readback {
    /// Width, pixels.
    pub width: u32,
    /// Height, pixels.
    pub height: u32,
    /// One raw depth word per pixel (see [`depth_value`]).
    pub depth: Vec<u32>,
    /// One stencil byte per pixel.
    pub stencil: Vec<u8>,
}

fn vkerr(call: &'static str) -> impl Fn(vk::Result) -> Error {
    Error::vk(call)
}

/// Whether `format` can be a depth-stencil attachment and a transfer source (optimal tiling).
pub fn format_supported(ctx: &Context, format: vk::Format) -> bool {
    let needed = vk::FormatFeatureFlags::DEPTH_STENCIL_ATTACHMENT | vk::FormatFeatureFlags::TRANSFER_SRC;
    // SAFETY: a format query on the context's valid physical device.
    let p = unsafe { ctx.instance.get_physical_device_format_properties(ctx.physical, format) };
    p.optimal_tiling_features.contains(needed)
}

/// Depth word -> depth value for `format`.
pub fn depth_value(format: vk::Format, word: u32) -> f64 {
    if format == vk::Format::D24_UNORM_S8_UINT {
        (word & 0x00ff_ffff) as f64 / 16_777_215.0
    } else {
        f32::from_bits(word) as f64
    }
}

fn bytes<T: Copy>(v: &[T]) -> Vec<u8> {
    // SAFETY: only called with plain numeric types (f32 arrays, u8/u16/u32) without padding.
    unsafe { std::slice::from_raw_parts(v.as_ptr() as *const u8, std::mem::size_of_val(v)) }.to_vec()
}

/// Draws ready to record: their pipeline layout (shadow.vert's push block), pipelines, vertex,
/// index and indirect buffers. [`Draws::destroy`] frees them once the device is done.
pub(crate) struct Draws {
    layout: vk::PipelineLayout,
    pipelines: Vec<vk::Pipeline>,
    buffers: Vec<Buffer>,
    draws: Vec<RecordedDraw>,
}

impl Draws {
    /// Creates every draw's pipeline (for `format`) and buffers; on an error, what was made
    /// is destroyed.
    pub(crate) fn new(ctx: &Context, format: vk::Format, draws: &[DrawCall]) -> Result<Draws> {
        Draws::with_samples(ctx, format, vk::SampleCountFlags::TYPE_1, draws)
    }

    /// [`Draws::new`] for attachments of `samples` samples per pixel.
    pub(crate) fn with_samples(ctx: &Context, format: vk::Format, samples: vk::SampleCountFlags, draws: &[DrawCall]) -> Result<Draws> {
        let push_range = [vk::PushConstantRange { stage_flags: vk::ShaderStageFlags::VERTEX, offset: 0, size: 96 }];
        let layout_info = vk::PipelineLayoutCreateInfo::default().push_constant_ranges(&push_range);
        // SAFETY: valid device and create info; destroyed by `destroy`.
        let layout = unsafe { ctx.device.create_pipeline_layout(&layout_info, None) }.map_err(vkerr("vkCreatePipelineLayout"))?;
        let mut out = Draws { layout, pipelines: Vec::new(), buffers: Vec::new(), draws: Vec::with_capacity(draws.len()) };
        for d in draws {
            match prepare_draw(ctx, layout, (format, samples), d, &mut out.pipelines, &mut out.buffers) {
                Ok(r) => out.draws.push(r),
                Err(e) => {
                    out.destroy(ctx);
                    return Err(e);
                }
            }
        }
        Ok(out)
    }

    /// How many draws there are.
    pub(crate) fn len(&self) -> usize {
        self.draws.len()
    }

    /// Records draw `i` (pipeline, push block, depth bounds, scissor — `area` when the draw
    /// names none — vertex and index buffers, the draw command).
    ///
    /// # Safety
    /// `cb` is recording inside a rendering instance (or subpass) compatible with the draws'
    /// format, with the viewport set; the draws outlive the submission.
    pub(crate) unsafe fn record(&self, ctx: &Context, cb: vk::CommandBuffer, i: usize, area: vk::Rect2D) {
        let d = &ctx.device;
        let r = &self.draws[i];
        // SAFETY: the caller's contract; every handle was created on this device by `new`.
        unsafe {
            d.cmd_bind_pipeline(cb, vk::PipelineBindPoint::GRAPHICS, r.pipeline);
            d.cmd_push_constants(cb, self.layout, vk::ShaderStageFlags::VERTEX, 0, &r.push);
            if let Some((lo, hi)) = r.depth_bounds {
                d.cmd_set_depth_bounds(cb, lo, hi);
            }
            d.cmd_set_scissor(cb, 0, &[r.scissor.unwrap_or(area)]);
            d.cmd_bind_vertex_buffers(cb, 0, &[r.vertices], &[0]);
            match (r.indices, &r.indirect) {
                (Some((ib, ty, _)), Some((buf, offsets))) => {
                    d.cmd_bind_index_buffer(cb, ib, 0, ty);
                    for &o in offsets {
                        d.cmd_draw_indexed_indirect(cb, *buf, o, 1, std::mem::size_of::<vk::DrawIndexedIndirectCommand>() as u32);
                    }
                }
                (Some((ib, ty, count)), None) => {
                    d.cmd_bind_index_buffer(cb, ib, 0, ty);
                    d.cmd_draw_indexed(cb, count, 1, 0, 0, 0);
                }
                (None, _) => d.cmd_draw(cb, r.vertex_count, 1, 0, 0),
            }
        }
    }

    /// Waits for the device and destroys everything.
    pub(crate) fn destroy(mut self, ctx: &Context) {
        // SAFETY: after the wait nothing is in use.
        unsafe {
            let _ = ctx.device.device_wait_idle();
            for p in self.pipelines.drain(..) {
                ctx.device.destroy_pipeline(p, None);
            }
            ctx.device.destroy_pipeline_layout(self.layout, None);
        }
        for b in &mut self.buffers {
            b.destroy(ctx);
        }
    }
}

/// Clears a `width` x `height` depth-stencil image of `format` to (`clear_depth`,
/// `clear_stencil`), records `draws` in order, and reads both aspects back.
pub fn render(
    ctx: &Context,
    format: vk::Format,
    width: u32,
    height: u32,
    clear_depth: f32,
    clear_stencil: u32,
    draws: &[DrawCall],
) -> Result<Readback> {
    let prepared = Draws::new(ctx, format, draws)?;
    let mut buffers: Vec<Buffer> = Vec::new();
    let mut image: Option<Image> = None;
    let result = (|| -> Result<Readback> {
        let extent = vk::Extent2D { width, height };
        image = Some(Image::new_2d(
            ctx,
            "conform-ds",
            format,
            extent,
            vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT | vk::ImageUsageFlags::TRANSFER_SRC,
            vk::ImageAspectFlags::DEPTH | vk::ImageAspectFlags::STENCIL,
        )?);
        let img = image.as_ref().expect("just created");
        let n = (width * height) as u64;
        buffers.push(Buffer::new(ctx, "conform-depth-readback", n * 4, vk::BufferUsageFlags::TRANSFER_DST, MemoryLocation::GpuToCpu)?);
        buffers.push(Buffer::new(ctx, "conform-stencil-readback", n, vk::BufferUsageFlags::TRANSFER_DST, MemoryLocation::GpuToCpu)?);
        let (depth_buf, stencil_buf) = (buffers[0].raw, buffers[1].raw);
        ctx.one_shot(|cb| {
            transition(ctx, cb, img, vk::ImageLayout::UNDEFINED, vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL);
            let att = cleared_depth_stencil(img.view, (clear_depth, clear_stencil));
            let area = vk::Rect2D { offset: vk::Offset2D { x: 0, y: 0 }, extent };
            let info = vk::RenderingInfo::default().render_area(area).layer_count(1).depth_attachment(&att).stencil_attachment(&att);
            let viewport = vk::Viewport { x: 0.0, y: 0.0, width: width as f32, height: height as f32, min_depth: 0.0, max_depth: 1.0 };
            // SAFETY: `cb` is recording (one_shot); every handle used was created above on this
            // device and outlives the submission, which one_shot waits for.
            unsafe {
                ctx.device.cmd_begin_rendering(cb, &info);
                ctx.device.cmd_set_viewport(cb, 0, &[viewport]);
                for i in 0..prepared.len() {
                    prepared.record(ctx, cb, i, area);
                }
                ctx.device.cmd_end_rendering(cb);
            }
            transition(ctx, cb, img, vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL, vk::ImageLayout::TRANSFER_SRC_OPTIMAL);
            // SAFETY: recording; the image is in TRANSFER_SRC_OPTIMAL and the buffers are large
            // enough for one aspect each (4 bytes per depth texel, 1 per stencil texel).
            unsafe { copy_aspects(ctx, cb, img, (depth_buf, stencil_buf)) };
            transfer_to_host_barrier(ctx, cb);
        })?;
        let depth_bytes = buffers[0].read()?;
        let depth = depth_bytes.chunks_exact(4).map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]])).collect();
        let stencil = buffers[1].read()?.to_vec();
        Ok(Readback { width, height, depth, stencil })
    })();
    prepared.destroy(ctx);
    for b in &mut buffers {
        b.destroy(ctx);
    }
    if let Some(mut i) = image {
        i.destroy(ctx);
    }
    result
}

/// One draw, ready to record: its pipeline, vertex and index buffers, push block and bounds.
struct RecordedDraw {
    pipeline: vk::Pipeline,
    vertices: vk::Buffer,
    indices: Option<(vk::Buffer, vk::IndexType, u32)>,
    /// The indirect buffer and the offsets of its records (`Indices::Indirect16`).
    indirect: Option<(vk::Buffer, Vec<u64>)>,
    vertex_count: u32,
    push: Vec<u8>,
    depth_bounds: Option<(f32, f32)>,
    scissor: Option<vk::Rect2D>,
}

/// Creates `d`'s pipeline and buffers, handing them to `pipelines` and `buffers` (which the
/// caller destroys, whatever fails later).
fn prepare_draw(
    ctx: &Context,
    layout: vk::PipelineLayout,
    (format, samples): (vk::Format, vk::SampleCountFlags),
    d: &DrawCall,
    pipelines: &mut Vec<vk::Pipeline>,
    buffers: &mut Vec<Buffer>,
) -> Result<RecordedDraw> {
    let mut desc = PipelineDesc::new(shaders::SHADOW_RAW_VERT, layout, format);
    desc.vertex_stride = 16;
    desc.attributes = &[(0, vk::Format::R32G32B32A32_SFLOAT, 0)];
    desc.depth_test = d.spec.depth_test;
    desc.depth_write = d.spec.depth_write;
    desc.depth_compare = d.spec.depth_compare;
    desc.depth_clamp = d.spec.depth_clamp;
    desc.depth_bounds = d.spec.depth_bounds.is_some();
    desc.stencil = Some((d.spec.front, d.spec.back));
    desc.samples = samples;
    let pipeline = pipeline::create(ctx, &desc)?;
    pipelines.push(pipeline);
    let vb = Buffer::with_data(ctx, "conform-vertices", &bytes(&d.vertices), vk::BufferUsageFlags::VERTEX_BUFFER)?;
    let vertices = vb.raw;
    buffers.push(vb);
    let index = match &d.indices {
        Indices::None => None,
        Indices::U8(i) => Some((bytes(i), vk::IndexType::UINT8_EXT, i.len())),
        Indices::U16(i) => Some((bytes(i), vk::IndexType::UINT16, i.len())),
        Indices::U32(i) => Some((bytes(i), vk::IndexType::UINT32, i.len())),
        Indices::Indirect16 { indices, .. } => Some((bytes(indices), vk::IndexType::UINT16, indices.len())),
    };
    let indirect = match &d.indices {
        Indices::Indirect16 { records, lead_in, .. } => {
            // The lead-in records would draw every index 1000 times over: drawn by mistake,
            // they show.
            let garbage = vk::DrawIndexedIndirectCommand {
                index_count: 3,
                instance_count: 1000,
                first_index: 0,
                vertex_offset: 0,
                first_instance: 0,
            };
            let all: Vec<vk::DrawIndexedIndirectCommand> =
                std::iter::repeat_n(garbage, *lead_in as usize).chain(records.iter().copied()).collect();
            let words: Vec<u32> = all
                .iter()
                .flat_map(|r| [r.index_count, r.instance_count, r.first_index, r.vertex_offset as u32, r.first_instance])
                .collect();
            let ib = Buffer::with_data(ctx, "conform-indirect", &bytes(&words), vk::BufferUsageFlags::INDIRECT_BUFFER)?;
            let raw = ib.raw;
            buffers.push(ib);
            let stride = std::mem::size_of::<vk::DrawIndexedIndirectCommand>() as u64;
            Some((raw, (0..records.len() as u64).map(|i| (*lead_in as u64 + i) * stride).collect()))
        }
        _ => None,
    };
    let indices = match index {
        Some((data, ty, n)) => {
            let ib = Buffer::with_data(ctx, "conform-indices", &data, vk::BufferUsageFlags::INDEX_BUFFER)?;
            let raw = ib.raw;
            buffers.push(ib);
            Some((raw, ty, n as u32))
        }
        None => None,
    };
    // shadow.vert's block; light (0, 0, 0, 1): w = 0 vertices extrude away from the origin.
    let push = umbrage::pass::push::VolumePush::new(d.mvp, glam::Vec4::W, [0.0; 4]);
    Ok(RecordedDraw {
        pipeline,
        vertices,
        indices,
        indirect,
        vertex_count: d.vertices.len() as u32,
        push: bytemuck::bytes_of(&push).to_vec(),
        depth_bounds: d.spec.depth_bounds,
        scissor: d.spec.scissor,
    })
}

/// Copies `img`'s depth and stencil aspects into `buffers` (depth, stencil).
///
/// # Safety
/// `cb` is recording outside a rendering instance; `img` is in TRANSFER_SRC_OPTIMAL and the
/// buffers hold 4 bytes (depth) and 1 byte (stencil) per texel.
pub(crate) unsafe fn copy_aspects(ctx: &Context, cb: vk::CommandBuffer, img: &Image, (depth, stencil): (vk::Buffer, vk::Buffer)) {
    let region = |aspect| aspect_copy(aspect, img.extent, 0);
    let src = vk::ImageLayout::TRANSFER_SRC_OPTIMAL;
    // SAFETY: the caller's contract.
    unsafe {
        ctx.device.cmd_copy_image_to_buffer(cb, img.raw, src, depth, &[region(vk::ImageAspectFlags::DEPTH)]);
        ctx.device.cmd_copy_image_to_buffer(cb, img.raw, src, stencil, &[region(vk::ImageAspectFlags::STENCIL)]);
    }
}

/// Orthographic pixel mapping: object (x, y) in pixels (row 0 at the top), z as given -> depth.
pub fn pixel_ortho(width: u32, height: u32) -> Mat4 {
    Mat4::from_cols(
        glam::Vec4::new(2.0 / width as f32, 0.0, 0.0, 0.0),
        glam::Vec4::new(0.0, 2.0 / height as f32, 0.0, 0.0),
        glam::Vec4::new(0.0, 0.0, 1.0, 0.0),
        glam::Vec4::new(-1.0, -1.0, 0.0, 1.0),
    )
}
