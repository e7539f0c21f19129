//! The float shadow-volume counter beyond 8 bits: 1000 front and 700 back faces over one
//! region, counted into an R32_SFLOAT target with ONE/ONE additive blending (+1 per front face,
//! -1 per back face, `shaders/count.frag`) and in the stencil with front INCR_WRAP / back
//! DECR_WRAP in the same draw: the float must be exactly 300.0 (every partial sum is an integer
//! far below 2^24, so f32 addition is exact) and the stencil 300 mod 256 = 44.
//!
//! Drawn through a classic `VkRenderPass` (colour + depth-stencil, cleared, stored and left in
//! `TRANSFER_SRC_OPTIMAL`) with a pipeline of its own, so it needs neither dynamic rendering
//! nor synchronization2 beyond what `gpu::resources::memory_barrier` chooses.

use crate::shaders;
use crate::CheckResult;
use ash::vk;
use gpu_allocator::MemoryLocation;
use serde_json::json;
use umbrage::error::{Error, Result};
use umbrage::gpu::resources::{aspect_copy, transfer_to_host_barrier};
use umbrage::gpu::{pipeline, Buffer, Context, Image};

/// Image size; the faces cover `[0, INSIDE) x [0, H)`, the rest stays clear.
const W: u32 = 24;
const H: u32 = 16;
const INSIDE: u32 = 16;
const FRONT: usize = 1000;
const BACK: usize = 700;

/// Two triangles for `[0, INSIDE) x [0, H)` in pixels, counter-clockwise in Vulkan's sense
/// (front facing) or the other way.
fn face(front: bool) -> [[f32; 4]; 6] {
    let (x1, y1) = (INSIDE as f32, H as f32);
    let p = |x: f32, y: f32| [x, y, 0.5, 1.0];
    let (a, b, c, d) = (p(0.0, 0.0), p(0.0, y1), p(x1, y1), p(x1, 0.0));
    if front {
        [a, b, c, a, c, d]
    } else {
        [a, c, b, a, d, c]
    }
}

/// Everything the check creates, destroyed together.
#[derive(Default)]
struct Objects {
    layout: vk::PipelineLayout,
    render_pass: vk::RenderPass,
    framebuffer: vk::Framebuffer,
    pipeline: vk::Pipeline,
    images: Vec<Image>,
    buffers: Vec<Buffer>,
}

impl Objects {
    fn destroy(mut self, ctx: &Context) {
        // SAFETY: one_shot waited for the submission (or nothing was submitted); wait idle
        // anyway so nothing below is in use. Null handles are ignored by the destroy calls.
        unsafe {
            let _ = ctx.device.device_wait_idle();
            ctx.device.destroy_pipeline(self.pipeline, None);
            ctx.device.destroy_framebuffer(self.framebuffer, None);
            ctx.device.destroy_render_pass(self.render_pass, None);
            ctx.device.destroy_pipeline_layout(self.layout, None);
        }
        for b in &mut self.buffers {
            b.destroy(ctx);
        }
        for i in &mut self.images {
            i.destroy(ctx);
        }
    }
}

fn render_pass(ctx: &Context, ds_format: vk::Format) -> Result<vk::RenderPass> {
    let att = [
        vk::AttachmentDescription::default()
            .format(vk::Format::R32_SFLOAT)
            .samples(vk::SampleCountFlags::TYPE_1)
            .load_op(vk::AttachmentLoadOp::CLEAR)
            .store_op(vk::AttachmentStoreOp::STORE)
            .stencil_load_op(vk::AttachmentLoadOp::DONT_CARE)
            .stencil_store_op(vk::AttachmentStoreOp::DONT_CARE)
            .initial_layout(vk::ImageLayout::UNDEFINED)
            .final_layout(vk::ImageLayout::TRANSFER_SRC_OPTIMAL),
        vk::AttachmentDescription::default()
            .format(ds_format)
            .samples(vk::SampleCountFlags::TYPE_1)
            .load_op(vk::AttachmentLoadOp::CLEAR)
            .store_op(vk::AttachmentStoreOp::DONT_CARE)
            .stencil_load_op(vk::AttachmentLoadOp::CLEAR)
            .stencil_store_op(vk::AttachmentStoreOp::STORE)
            .initial_layout(vk::ImageLayout::UNDEFINED)
            .final_layout(vk::ImageLayout::TRANSFER_SRC_OPTIMAL),
    ];
    let colour = [vk::AttachmentReference { attachment: 0, layout: vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL }];
    let ds = vk::AttachmentReference { attachment: 1, layout: vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL };
    let subpass = [vk::SubpassDescription::default()
        .pipeline_bind_point(vk::PipelineBindPoint::GRAPHICS)
        .color_attachments(&colour)
        .depth_stencil_attachment(&ds)];
    let stages = vk::PipelineStageFlags::COLOR_ATTACHMENT_OUTPUT
        | vk::PipelineStageFlags::EARLY_FRAGMENT_TESTS
        | vk::PipelineStageFlags::LATE_FRAGMENT_TESTS;
    let writes = vk::AccessFlags::COLOR_ATTACHMENT_WRITE
        | vk::AccessFlags::COLOR_ATTACHMENT_READ
        | vk::AccessFlags::DEPTH_STENCIL_ATTACHMENT_WRITE
        | vk::AccessFlags::DEPTH_STENCIL_ATTACHMENT_READ;
    let deps = [
        vk::SubpassDependency {
            src_subpass: vk::SUBPASS_EXTERNAL,
            dst_subpass: 0,
            src_stage_mask: stages,
            dst_stage_mask: stages,
            src_access_mask: vk::AccessFlags::empty(),
            dst_access_mask: writes,
            dependency_flags: vk::DependencyFlags::empty(),
        },
        vk::SubpassDependency {
            src_subpass: 0,
            dst_subpass: vk::SUBPASS_EXTERNAL,
            src_stage_mask: stages,
            dst_stage_mask: vk::PipelineStageFlags::TRANSFER,
            src_access_mask: vk::AccessFlags::COLOR_ATTACHMENT_WRITE | vk::AccessFlags::DEPTH_STENCIL_ATTACHMENT_WRITE,
            dst_access_mask: vk::AccessFlags::TRANSFER_READ,
            dependency_flags: vk::DependencyFlags::empty(),
        },
    ];
    let info = vk::RenderPassCreateInfo::default().attachments(&att).subpasses(&subpass).dependencies(&deps);
    // SAFETY: valid device; `info` points at locals alive for the call.
    unsafe { ctx.device.create_render_pass(&info, None) }.map_err(Error::vk("vkCreateRenderPass"))
}

/// The counting pipeline: `shadow.vert` + `count.frag`, additive R32F blending, two-sided
/// stencil INCR_WRAP / DECR_WRAP, no depth test, no culling.
fn counting_pipeline(ctx: &Context, layout: vk::PipelineLayout, render_pass: vk::RenderPass) -> Result<vk::Pipeline> {
    let vs = pipeline::shader_module(ctx, shaders::SHADOW_RAW_VERT)?;
    let fs = match pipeline::shader_module(ctx, shaders::COUNT_FRAG) {
        Ok(f) => f,
        Err(e) => {
            // SAFETY: created above, not used by anything.
            unsafe { ctx.device.destroy_shader_module(vs, None) };
            return Err(e);
        }
    };
    let stages = [
        vk::PipelineShaderStageCreateInfo::default().stage(vk::ShaderStageFlags::VERTEX).module(vs).name(c"main"),
        vk::PipelineShaderStageCreateInfo::default().stage(vk::ShaderStageFlags::FRAGMENT).module(fs).name(c"main"),
    ];
    let bindings = [vk::VertexInputBindingDescription { binding: 0, stride: 16, input_rate: vk::VertexInputRate::VERTEX }];
    let attrs = [vk::VertexInputAttributeDescription { location: 0, binding: 0, format: vk::Format::R32G32B32A32_SFLOAT, offset: 0 }];
    let vi = vk::PipelineVertexInputStateCreateInfo::default().vertex_binding_descriptions(&bindings).vertex_attribute_descriptions(&attrs);
    let ia = vk::PipelineInputAssemblyStateCreateInfo::default().topology(vk::PrimitiveTopology::TRIANGLE_LIST);
    let vp = vk::PipelineViewportStateCreateInfo::default().viewport_count(1).scissor_count(1);
    let rs = vk::PipelineRasterizationStateCreateInfo::default()
        .polygon_mode(vk::PolygonMode::FILL)
        .cull_mode(vk::CullModeFlags::NONE)
        .front_face(vk::FrontFace::COUNTER_CLOCKWISE)
        .line_width(1.0);
    let ms = vk::PipelineMultisampleStateCreateInfo::default().rasterization_samples(vk::SampleCountFlags::TYPE_1);
    let op = |pass| umbrage::gpu::pipeline::stencil_ops(pass, vk::StencilOp::KEEP);
    let ds = vk::PipelineDepthStencilStateCreateInfo::default()
        .stencil_test_enable(true)
        .front(op(vk::StencilOp::INCREMENT_AND_WRAP))
        .back(op(vk::StencilOp::DECREMENT_AND_WRAP))
        .max_depth_bounds(1.0);
    let blend = [pipeline::blend_attachment(pipeline::Blend::Additive, vk::ColorComponentFlags::R)];
    let cb = vk::PipelineColorBlendStateCreateInfo::default().attachments(&blend);
    let dynamic = [vk::DynamicState::VIEWPORT, vk::DynamicState::SCISSOR];
    let dyn_info = vk::PipelineDynamicStateCreateInfo::default().dynamic_states(&dynamic);
    let info = vk::GraphicsPipelineCreateInfo::default()
        .stages(&stages)
        .vertex_input_state(&vi)
        .input_assembly_state(&ia)
        .viewport_state(&vp)
        .rasterization_state(&rs)
        .multisample_state(&ms)
        .depth_stencil_state(&ds)
        .color_blend_state(&cb)
        .dynamic_state(&dyn_info)
        .layout(layout)
        .render_pass(render_pass)
        .subpass(0);
    // SAFETY: every pointer in `info` refers to locals alive for this call; the layout and
    // render pass are valid objects of this device.
    let result = unsafe { ctx.device.create_graphics_pipelines(vk::PipelineCache::null(), &[info], None) };
    // SAFETY: the modules are no longer needed once the pipeline exists (or creation failed).
    unsafe {
        ctx.device.destroy_shader_module(vs, None);
        ctx.device.destroy_shader_module(fs, None);
    }
    result.map(|p| p[0]).map_err(|(_, e)| Error::Vulkan { call: "vkCreateGraphicsPipelines", result: e })
}

/// What came back: the float counter and the stencil, row-major.
struct Counts {
    float: Vec<f32>,
    stencil: Vec<u8>,
}

fn render(ctx: &Context, o: &mut Objects, vertices: &[[f32; 4]]) -> Result<Counts> {
    let ds_format = ctx.depth_format;
    let extent = vk::Extent2D { width: W, height: H };
    let colour_usage = vk::ImageUsageFlags::COLOR_ATTACHMENT | vk::ImageUsageFlags::TRANSFER_SRC;
    o.images.push(Image::new_2d(ctx, "conform-float-count", vk::Format::R32_SFLOAT, extent, colour_usage, vk::ImageAspectFlags::COLOR)?);
    let ds_usage = vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT | vk::ImageUsageFlags::TRANSFER_SRC;
    let ds_aspect = vk::ImageAspectFlags::DEPTH | vk::ImageAspectFlags::STENCIL;
    o.images.push(Image::new_2d(ctx, "conform-float-count-ds", ds_format, extent, ds_usage, ds_aspect)?);
    let push_range = [vk::PushConstantRange {
        stage_flags: vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT,
        offset: 0,
        size: umbrage::pass::push::VolumePush::SIZE,
    }];
    let layout_info = vk::PipelineLayoutCreateInfo::default().push_constant_ranges(&push_range);
    // SAFETY: valid device and create info; destroyed in Objects::destroy.
    o.layout = unsafe { ctx.device.create_pipeline_layout(&layout_info, None) }.map_err(Error::vk("vkCreatePipelineLayout"))?;
    o.render_pass = render_pass(ctx, ds_format)?;
    let views = [o.images[0].view, o.images[1].view];
    let fb = vk::FramebufferCreateInfo::default().render_pass(o.render_pass).attachments(&views).width(W).height(H).layers(1);
    // SAFETY: valid device; the render pass and views are alive until Objects::destroy.
    o.framebuffer = unsafe { ctx.device.create_framebuffer(&fb, None) }.map_err(Error::vk("vkCreateFramebuffer"))?;
    o.pipeline = counting_pipeline(ctx, o.layout, o.render_pass)?;
    let bytes: &[u8] = bytemuck::cast_slice(vertices);
    o.buffers.push(Buffer::with_data(ctx, "conform-float-count-vertices", bytes, vk::BufferUsageFlags::VERTEX_BUFFER)?);
    let n = (W * H) as u64;
    o.buffers.push(Buffer::new(ctx, "conform-float-count-readback", n * 4, vk::BufferUsageFlags::TRANSFER_DST, MemoryLocation::GpuToCpu)?);
    o.buffers.push(Buffer::new(ctx, "conform-stencil-readback", n, vk::BufferUsageFlags::TRANSFER_DST, MemoryLocation::GpuToCpu)?);
    let (vb, float_buf, stencil_buf) = (o.buffers[0].raw, o.buffers[1].raw, o.buffers[2].raw);
    let (colour_img, ds_img) = (o.images[0].raw, o.images[1].raw);
    // +1 for front faces (count.frag multiplies gl_FrontFacing's sign by color.x).
    let push = umbrage::pass::push::VolumePush::new(crate::harness::pixel_ortho(W, H), glam::Vec4::W, [1.0, 0.0, 0.0, 0.0]);
    let area = vk::Rect2D { offset: vk::Offset2D { x: 0, y: 0 }, extent };
    let clears = [
        vk::ClearValue { color: vk::ClearColorValue { float32: [0.0; 4] } },
        vk::ClearValue { depth_stencil: vk::ClearDepthStencilValue { depth: 1.0, stencil: 0 } },
    ];
    let (render_pass, framebuffer, layout, pipe) = (o.render_pass, o.framebuffer, o.layout, o.pipeline);
    ctx.one_shot(|cb| {
        let d = &ctx.device;
        let region = |aspect| aspect_copy(aspect, vk::Extent2D { width: W, height: H }, 0);
        // SAFETY: `cb` is recording (one_shot); every handle was created above on this device
        // and outlives the submission, which one_shot waits for. The render pass leaves both
        // images in TRANSFER_SRC_OPTIMAL, made visible to the copies by its external dependency.
        unsafe {
            let info = vk::RenderPassBeginInfo::default()
                .render_pass(render_pass)
                .framebuffer(framebuffer)
                .render_area(area)
                .clear_values(&clears);
            d.cmd_begin_render_pass(cb, &info, vk::SubpassContents::INLINE);
            d.cmd_set_viewport(
                cb,
                0,
                &[vk::Viewport { x: 0.0, y: 0.0, width: W as f32, height: H as f32, min_depth: 0.0, max_depth: 1.0 }],
            );
            d.cmd_set_scissor(cb, 0, &[area]);
            d.cmd_bind_pipeline(cb, vk::PipelineBindPoint::GRAPHICS, pipe);
            d.cmd_push_constants(cb, layout, vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT, 0, bytemuck::bytes_of(&push));
            d.cmd_bind_vertex_buffers(cb, 0, &[vb], &[0]);
            d.cmd_draw(cb, vertices.len() as u32, 1, 0, 0);
            d.cmd_end_render_pass(cb);
            d.cmd_copy_image_to_buffer(
                cb,
                colour_img,
                vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                float_buf,
                &[region(vk::ImageAspectFlags::COLOR)],
            );
            d.cmd_copy_image_to_buffer(
                cb,
                ds_img,
                vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                stencil_buf,
                &[region(vk::ImageAspectFlags::STENCIL)],
            );
        }
        transfer_to_host_barrier(ctx, cb);
    })?;
    let float = o.buffers[1].read()?.chunks_exact(4).map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]])).collect();
    let stencil = o.buffers[2].read()?.to_vec();
    Ok(Counts { float, stencil })
}

/// The failure images: `count.expected`, `count.actual` (the float counter, grey on a scale of
/// 0 to the largest value of the two), `count.diff` (red: differs, black: equal) and the
/// stencil's `draw1.*` ([`crate::image_sink::stencil_mismatch`]).
fn failure_images(c: &Counts, want: f32, want_stencil: u8) {
    use crate::image_sink::{save, texels, unit_gray};
    let expected: Vec<f32> = (0..W * H).map(|i| if i % W < INSIDE { want } else { 0.0 }).collect();
    let top = expected.iter().chain(&c.float).fold(1.0f32, |m, &v| m.max(v.abs())) as f64;
    save("count.expected", &texels(W, H, |i| unit_gray(expected[i] as f64 / top)));
    save("count.actual", &texels(W, H, |i| unit_gray(c.float[i] as f64 / top)));
    let diff = |i: usize| if c.float[i] != expected[i] { image::Rgb([255, 0, 0]) } else { image::Rgb([0, 0, 0]) };
    save("count.diff", &texels(W, H, diff));
    let stencil: Vec<u8> = (0..W * H).map(|i| if i % W < INSIDE { want_stencil } else { 0 }).collect();
    if stencil != c.stencil {
        crate::image_sink::stencil_mismatch(W, H, &stencil, &vec![true; stencil.len()], &c.stencil);
    }
}

/// Legacy check: 1000 front and 700 back faces (seeded shuffled order, one draw) counted in
/// R32_SFLOAT with additive blending and in the stencil with two-sided INCR_WRAP / DECR_WRAP:
/// exactly 300.0 and 44 (300 mod 256) at every pixel of the covered region, 0.0 and 0 outside.
/// Skipped when R32_SFLOAT cannot be blended.
pub fn deep_wrap_float_count(ctx: &Context) -> Result<CheckResult> {
    const NAME: &str = "deep_wrap_float_count";
    if !ctx.features.r32f_blend {
        return Ok(CheckResult::skipped(NAME, "R32_SFLOAT is not blendable as a colour attachment (COLOR_ATTACHMENT_BLEND)"));
    }
    let mut order: Vec<bool> = [vec![true; FRONT], vec![false; BACK]].concat();
    crate::cases::gaps::Rng::new(7).shuffle(&mut order);
    let vertices: Vec<[f32; 4]> = order.iter().flat_map(|&f| face(f)).collect();
    let mut o = Objects::default();
    let r = render(ctx, &mut o, &vertices);
    o.destroy(ctx);
    let c = r?;
    // The test seam (`value_images::skewed`): expect one face more.
    let net = FRONT as i64 - BACK as i64 + i64::from(crate::value_images::skewed());
    let want = net as f32;
    let want_stencil = net.rem_euclid(256) as u8;
    let (mut bad_float, mut bad_stencil) = (0u64, 0u64);
    let mut first = None;
    for y in 0..H {
        for x in 0..W {
            let i = (y * W + x) as usize;
            let inside = x < INSIDE;
            let (wf, ws) = if inside { (want, want_stencil) } else { (0.0, 0) };
            if c.float[i] != wf || c.stencil[i] != ws {
                bad_float += (c.float[i] != wf) as u64;
                bad_stencil += (c.stencil[i] != ws) as u64;
                first.get_or_insert(format!("({x}, {y}): float {} (want {wf}), stencil {} (want {ws})", c.float[i], c.stencil[i]));
            }
        }
    }
    if first.is_some() {
        failure_images(&c, want, want_stencil);
    }
    let mut numbers = serde_json::Map::new();
    numbers.insert("front_faces".into(), json!(FRONT));
    numbers.insert("back_faces".into(), json!(BACK));
    numbers.insert("float_at_0_0".into(), json!(c.float[0]));
    numbers.insert("stencil_at_0_0".into(), json!(c.stencil[0]));
    numbers.insert("float_mismatches".into(), json!(bad_float));
    numbers.insert("stencil_mismatches".into(), json!(bad_stencil));
    numbers.insert("stencil_format".into(), json!(format!("{:?}", ctx.depth_format)));
    let mut fails = Vec::new();
    if let Some(f) = first {
        fails.push(format!("{bad_float} float and {bad_stencil} stencil mismatches, first at {f}"));
    }
    Ok(CheckResult::from_fails(
        NAME,
        fails,
        numbers,
        "1000 front / 700 back faces: R32F additive count exactly 300.0, stencil INCR/DECR_WRAP 44 (300 mod 256)",
    ))
}
