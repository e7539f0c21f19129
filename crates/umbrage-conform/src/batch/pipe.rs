//! Pipelines of the batch runner: depth/stencil only (no fragment shader), through
//! `shaders/shadow.vert`, for dynamic rendering or a render pass, with the depth/stencil state
//! baked in (static) or left to dynamic state with deliberately wrong static values.

use crate::cases::{Config, DsState, RenderModel, StateModel};
use crate::shaders;
use ash::vk;
use umbrage::error::{Error, Result};
use umbrage::gpu::{pipeline, Context};

/// Static values a dynamic-state pipeline carries and must not use: if a driver ignored the
/// dynamic state, every case drawn with it would fail.
fn decoy() -> vk::StencilOpState {
    vk::StencilOpState {
        fail_op: vk::StencilOp::INVERT,
        pass_op: vk::StencilOp::INVERT,
        depth_fail_op: vk::StencilOp::INVERT,
        compare_op: vk::CompareOp::NEVER,
        compare_mask: 0,
        write_mask: 0x55,
        reference: 0x55,
    }
}

/// The dynamic states of a [`StateModel::Dynamic`] pipeline (`depth_bounds`: the device has
/// `depthBounds`, so the bounds test is dynamic too).
pub fn dynamic_states(model: StateModel, depth_bounds: bool) -> Vec<vk::DynamicState> {
    let mut v = vec![vk::DynamicState::VIEWPORT, vk::DynamicState::SCISSOR];
    if model == StateModel::Dynamic {
        v.extend([
            vk::DynamicState::STENCIL_TEST_ENABLE,
            vk::DynamicState::STENCIL_OP,
            vk::DynamicState::STENCIL_COMPARE_MASK,
            vk::DynamicState::STENCIL_WRITE_MASK,
            vk::DynamicState::STENCIL_REFERENCE,
            vk::DynamicState::DEPTH_TEST_ENABLE,
            vk::DynamicState::DEPTH_WRITE_ENABLE,
            vk::DynamicState::DEPTH_COMPARE_OP,
        ]);
        if depth_bounds {
            v.extend([vk::DynamicState::DEPTH_BOUNDS_TEST_ENABLE, vk::DynamicState::DEPTH_BOUNDS]);
        }
    }
    v
}

/// Creates the pipeline for `st` in `cfg` (`render_pass`: the pass for [`RenderModel::RenderPass`]).
pub fn create(ctx: &Context, cfg: Config, st: &DsState, layout: vk::PipelineLayout, render_pass: vk::RenderPass) -> Result<vk::Pipeline> {
    let vs = pipeline::shader_module(ctx, shaders::SHADOW_RAW_VERT)?;
    let stages = [vk::PipelineShaderStageCreateInfo::default().stage(vk::ShaderStageFlags::VERTEX).module(vs).name(c"main")];
    let bindings = [vk::VertexInputBindingDescription { binding: 0, stride: 16, input_rate: vk::VertexInputRate::VERTEX }];
    let attrs = [vk::VertexInputAttributeDescription { location: 0, binding: 0, format: vk::Format::R32G32B32A32_SFLOAT, offset: 0 }];
    let vi = vk::PipelineVertexInputStateCreateInfo::default().vertex_binding_descriptions(&bindings).vertex_attribute_descriptions(&attrs);
    let ia = vk::PipelineInputAssemblyStateCreateInfo::default().topology(vk::PrimitiveTopology::TRIANGLE_LIST);
    let vp = vk::PipelineViewportStateCreateInfo::default().viewport_count(1).scissor_count(1);
    let rs = vk::PipelineRasterizationStateCreateInfo::default()
        .polygon_mode(vk::PolygonMode::FILL)
        .cull_mode(vk::CullModeFlags::NONE)
        .front_face(vk::FrontFace::COUNTER_CLOCKWISE)
        .depth_clamp_enable(st.depth_clamp)
        .depth_bias_enable(st.depth_bias.is_some())
        .depth_bias_constant_factor(st.depth_bias.unwrap_or(0.0))
        .line_width(1.0);
    let ms = vk::PipelineMultisampleStateCreateInfo::default().rasterization_samples(vk::SampleCountFlags::TYPE_1);
    let has_depth = cfg.has_depth();
    let ds = match cfg.state {
        StateModel::Static => {
            let (front, back) = st.stencil.unwrap_or_default();
            let (lo, hi) = st.depth_bounds.unwrap_or((0.0, 1.0));
            vk::PipelineDepthStencilStateCreateInfo::default()
                .depth_test_enable(st.depth_test && has_depth)
                .depth_write_enable(st.depth_write && has_depth)
                .depth_compare_op(st.depth_compare)
                .depth_bounds_test_enable(st.depth_bounds.is_some())
                .min_depth_bounds(lo)
                .max_depth_bounds(hi)
                .stencil_test_enable(st.stencil.is_some())
                .front(front)
                .back(back)
        }
        StateModel::Dynamic => vk::PipelineDepthStencilStateCreateInfo::default()
            .depth_test_enable(has_depth)
            .depth_write_enable(false)
            .depth_compare_op(vk::CompareOp::NEVER)
            .stencil_test_enable(true)
            .front(decoy())
            .back(decoy())
            .min_depth_bounds(0.0)
            .max_depth_bounds(1.0),
    };
    let cb = vk::PipelineColorBlendStateCreateInfo::default();
    let dynamic = dynamic_states(cfg.state, ctx.features.depth_bounds);
    let dyn_info = vk::PipelineDynamicStateCreateInfo::default().dynamic_states(&dynamic);
    let mut rendering = vk::PipelineRenderingCreateInfo::default()
        .depth_attachment_format(if has_depth { cfg.format } else { vk::Format::UNDEFINED })
        .stencil_attachment_format(cfg.format);
    let mut info = vk::GraphicsPipelineCreateInfo::default()
        .stages(&stages)
        .vertex_input_state(&vi)
        .input_assembly_state(&ia)
        .viewport_state(&vp)
        .rasterization_state(&rs)
        .multisample_state(&ms)
        .depth_stencil_state(&ds)
        .color_blend_state(&cb)
        .dynamic_state(&dyn_info)
        .layout(layout);
    info = match cfg.render {
        RenderModel::DynamicRendering => info.push_next(&mut rendering),
        RenderModel::RenderPass => info.render_pass(render_pass).subpass(0),
    };
    // SAFETY: every pointer in `info` refers to locals alive for this call; the layout and
    // render pass are valid objects of this device.
    let result = unsafe { ctx.device.create_graphics_pipelines(vk::PipelineCache::null(), &[info], None) };
    // SAFETY: the module is no longer needed once the pipeline exists (or creation failed).
    unsafe { ctx.device.destroy_shader_module(vs, None) };
    result.map(|p| p[0]).map_err(|(_, e)| Error::Vulkan { call: "vkCreateGraphicsPipelines", result: e })
}

/// A render pass with the one depth-stencil attachment, loaded and stored, in
/// `DEPTH_STENCIL_ATTACHMENT_OPTIMAL` throughout (the caller transitions around it).
pub fn render_pass(ctx: &Context, cfg: Config) -> Result<vk::RenderPass> {
    let has_depth = cfg.has_depth();
    let att = [vk::AttachmentDescription::default()
        .format(cfg.format)
        .samples(vk::SampleCountFlags::TYPE_1)
        .load_op(if has_depth { vk::AttachmentLoadOp::LOAD } else { vk::AttachmentLoadOp::DONT_CARE })
        .store_op(if has_depth { vk::AttachmentStoreOp::STORE } else { vk::AttachmentStoreOp::DONT_CARE })
        .stencil_load_op(vk::AttachmentLoadOp::LOAD)
        .stencil_store_op(vk::AttachmentStoreOp::STORE)
        .initial_layout(vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL)
        .final_layout(vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL)];
    let ds_ref = vk::AttachmentReference { attachment: 0, layout: vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL };
    let subpass =
        [vk::SubpassDescription::default().pipeline_bind_point(vk::PipelineBindPoint::GRAPHICS).depth_stencil_attachment(&ds_ref)];
    let tests = vk::PipelineStageFlags::EARLY_FRAGMENT_TESTS | vk::PipelineStageFlags::LATE_FRAGMENT_TESTS;
    let ds_access = vk::AccessFlags::DEPTH_STENCIL_ATTACHMENT_READ | vk::AccessFlags::DEPTH_STENCIL_ATTACHMENT_WRITE;
    let deps = [
        vk::SubpassDependency {
            src_subpass: vk::SUBPASS_EXTERNAL,
            dst_subpass: 0,
            src_stage_mask: vk::PipelineStageFlags::TRANSFER,
            dst_stage_mask: tests,
            src_access_mask: vk::AccessFlags::TRANSFER_WRITE,
            dst_access_mask: ds_access,
            dependency_flags: vk::DependencyFlags::empty(),
        },
        vk::SubpassDependency {
            src_subpass: 0,
            dst_subpass: vk::SUBPASS_EXTERNAL,
            src_stage_mask: tests,
            dst_stage_mask: vk::PipelineStageFlags::TRANSFER,
            src_access_mask: vk::AccessFlags::DEPTH_STENCIL_ATTACHMENT_WRITE,
            dst_access_mask: vk::AccessFlags::TRANSFER_READ,
            dependency_flags: vk::DependencyFlags::empty(),
        },
    ];
    let info = vk::RenderPassCreateInfo::default().attachments(&att).subpasses(&subpass).dependencies(&deps);
    // SAFETY: valid device; `info` points at locals alive for the call.
    unsafe { ctx.device.create_render_pass(&info, None) }.map_err(Error::vk("vkCreateRenderPass"))
}
