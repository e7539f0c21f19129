//! Graphics pipelines for dynamic rendering, described by a plain struct so that every
//! pipeline of the renderer reads as a table of its fixed-function state.

use super::context::GpuDevice;
use crate::error::{Error, Result};
use ash::vk;

fn vkerr(call: &'static str) -> impl Fn(vk::Result) -> Error {
    Error::vk(call)
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Blend {
    None,
    /// dst += src (light accumulation).
    Additive,
    /// Classic alpha blending (debug views).
    Alpha,
    /// dst *= src (multiplicative light-intensity map).
    Multiply,
    /// Premultiplied "over": dst = src + dst * (1 - src.a).
    Over,
}

/// Everything that varies between the renderer's pipelines.
#[derive(Clone)]
pub struct PipelineDesc<'a> {
    pub vertex: &'a [u8],
    pub fragment: Option<&'a [u8]>,
    /// Vertex stride and (location, format, offset) attributes; stride 0 = no vertex input.
    pub vertex_stride: u32,
    pub attributes: &'a [(u32, vk::Format, u32)],
    /// A second, per-instance binding (1): stride and (location, format, offset) attributes;
    /// stride 0 = none.
    pub instance_stride: u32,
    pub instance_attributes: &'a [(u32, vk::Format, u32)],
    pub color_formats: &'a [vk::Format],
    pub blend: Blend,
    pub color_write: bool,
    pub depth_format: vk::Format,
    pub depth_test: bool,
    pub depth_write: bool,
    pub depth_compare: vk::CompareOp,
    pub depth_clamp: bool,
    pub depth_bounds: bool,
    pub stencil: Option<(vk::StencilOpState, vk::StencilOpState)>,
    pub cull: vk::CullModeFlags,
    /// Constant and slope-scaled depth bias (shadow-map pass).
    pub depth_bias: Option<(f32, f32)>,
    pub layout: vk::PipelineLayout,
}

impl<'a> PipelineDesc<'a> {
    pub fn new(vertex: &'a [u8], layout: vk::PipelineLayout, depth_format: vk::Format) -> Self {
        PipelineDesc {
            vertex,
            fragment: None,
            vertex_stride: 0,
            attributes: &[],
            instance_stride: 0,
            instance_attributes: &[],
            color_formats: &[],
            blend: Blend::None,
            color_write: true,
            depth_format,
            depth_test: false,
            depth_write: false,
            depth_compare: vk::CompareOp::ALWAYS,
            depth_clamp: false,
            depth_bounds: false,
            stencil: None,
            cull: vk::CullModeFlags::NONE,
            depth_bias: None,
            layout,
        }
    }
}

pub fn shader_module(ctx: &impl GpuDevice, spirv: &[u8]) -> Result<vk::ShaderModule> {
    let words: Vec<u32> = spirv.chunks_exact(4).map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]])).collect();
    let info = vk::ShaderModuleCreateInfo::default().code(&words);
    // SAFETY: `words` is SPIR-V produced and validated by naga in build.rs.
    unsafe { ctx.device().create_shader_module(&info, None) }.map_err(vkerr("vkCreateShaderModule"))
}

pub fn create(ctx: &impl GpuDevice, d: &PipelineDesc) -> Result<vk::Pipeline> {
    let vs = shader_module(ctx, d.vertex)?;
    let fs = match d.fragment {
        Some(f) => Some(shader_module(ctx, f)?),
        None => None,
    };
    let mut stages = vec![vk::PipelineShaderStageCreateInfo::default().stage(vk::ShaderStageFlags::VERTEX).module(vs).name(c"main")];
    if let Some(fs) = fs {
        stages.push(vk::PipelineShaderStageCreateInfo::default().stage(vk::ShaderStageFlags::FRAGMENT).module(fs).name(c"main"));
    }
    let mut bindings =
        vec![vk::VertexInputBindingDescription { binding: 0, stride: d.vertex_stride, input_rate: vk::VertexInputRate::VERTEX }];
    let mut attrs: Vec<_> = d
        .attributes
        .iter()
        .map(|&(location, format, offset)| vk::VertexInputAttributeDescription { location, binding: 0, format, offset })
        .collect();
    if d.instance_stride > 0 {
        bindings.push(vk::VertexInputBindingDescription {
            binding: 1,
            stride: d.instance_stride,
            input_rate: vk::VertexInputRate::INSTANCE,
        });
        attrs.extend(d.instance_attributes.iter().map(|&(location, format, offset)| vk::VertexInputAttributeDescription {
            location,
            binding: 1,
            format,
            offset,
        }));
    }
    let vertex_input = if d.vertex_stride == 0 {
        vk::PipelineVertexInputStateCreateInfo::default()
    } else {
        vk::PipelineVertexInputStateCreateInfo::default().vertex_binding_descriptions(&bindings).vertex_attribute_descriptions(&attrs)
    };
    let ia = vk::PipelineInputAssemblyStateCreateInfo::default().topology(vk::PrimitiveTopology::TRIANGLE_LIST);
    let vp = vk::PipelineViewportStateCreateInfo::default().viewport_count(1).scissor_count(1);
    let rs = vk::PipelineRasterizationStateCreateInfo::default()
        .polygon_mode(vk::PolygonMode::FILL)
        .cull_mode(d.cull)
        .front_face(vk::FrontFace::COUNTER_CLOCKWISE)
        .depth_clamp_enable(d.depth_clamp)
        .depth_bias_enable(d.depth_bias.is_some())
        .depth_bias_constant_factor(d.depth_bias.map_or(0.0, |b| b.0))
        .depth_bias_slope_factor(d.depth_bias.map_or(0.0, |b| b.1))
        .line_width(1.0);
    let ms = vk::PipelineMultisampleStateCreateInfo::default().rasterization_samples(vk::SampleCountFlags::TYPE_1);
    let (front, back) = d.stencil.unwrap_or_default();
    let ds = vk::PipelineDepthStencilStateCreateInfo::default()
        .depth_test_enable(d.depth_test)
        .depth_write_enable(d.depth_write)
        .depth_compare_op(d.depth_compare)
        .depth_bounds_test_enable(d.depth_bounds)
        .min_depth_bounds(0.0)
        .max_depth_bounds(1.0)
        .stencil_test_enable(d.stencil.is_some())
        .front(front)
        .back(back);
    let mask = if d.color_write { vk::ColorComponentFlags::RGBA } else { vk::ColorComponentFlags::empty() };
    let att = match d.blend {
        Blend::None => vk::PipelineColorBlendAttachmentState::default().color_write_mask(mask),
        Blend::Additive => vk::PipelineColorBlendAttachmentState::default()
            .blend_enable(true)
            .src_color_blend_factor(vk::BlendFactor::ONE)
            .dst_color_blend_factor(vk::BlendFactor::ONE)
            .color_blend_op(vk::BlendOp::ADD)
            .src_alpha_blend_factor(vk::BlendFactor::ONE)
            .dst_alpha_blend_factor(vk::BlendFactor::ONE)
            .alpha_blend_op(vk::BlendOp::ADD)
            .color_write_mask(mask),
        Blend::Multiply => vk::PipelineColorBlendAttachmentState::default()
            .blend_enable(true)
            .src_color_blend_factor(vk::BlendFactor::ZERO)
            .dst_color_blend_factor(vk::BlendFactor::SRC_COLOR)
            .color_blend_op(vk::BlendOp::ADD)
            .src_alpha_blend_factor(vk::BlendFactor::ZERO)
            .dst_alpha_blend_factor(vk::BlendFactor::ONE)
            .alpha_blend_op(vk::BlendOp::ADD)
            .color_write_mask(mask),
        Blend::Over => vk::PipelineColorBlendAttachmentState::default()
            .blend_enable(true)
            .src_color_blend_factor(vk::BlendFactor::ONE)
            .dst_color_blend_factor(vk::BlendFactor::ONE_MINUS_SRC_ALPHA)
            .color_blend_op(vk::BlendOp::ADD)
            .src_alpha_blend_factor(vk::BlendFactor::ZERO)
            .dst_alpha_blend_factor(vk::BlendFactor::ONE)
            .alpha_blend_op(vk::BlendOp::ADD)
            .color_write_mask(mask),
        Blend::Alpha => vk::PipelineColorBlendAttachmentState::default()
            .blend_enable(true)
            .src_color_blend_factor(vk::BlendFactor::SRC_ALPHA)
            .dst_color_blend_factor(vk::BlendFactor::ONE_MINUS_SRC_ALPHA)
            .color_blend_op(vk::BlendOp::ADD)
            .src_alpha_blend_factor(vk::BlendFactor::ONE)
            .dst_alpha_blend_factor(vk::BlendFactor::ONE_MINUS_SRC_ALPHA)
            .alpha_blend_op(vk::BlendOp::ADD)
            .color_write_mask(mask),
    };
    let atts = vec![att; d.color_formats.len()];
    let cb = vk::PipelineColorBlendStateCreateInfo::default().attachments(&atts);
    let mut dynamic = vec![vk::DynamicState::VIEWPORT, vk::DynamicState::SCISSOR];
    if d.depth_bounds {
        dynamic.push(vk::DynamicState::DEPTH_BOUNDS);
    }
    let dyn_state = vk::PipelineDynamicStateCreateInfo::default().dynamic_states(&dynamic);
    let has_stencil =
        matches!(d.depth_format, vk::Format::D16_UNORM_S8_UINT | vk::Format::D24_UNORM_S8_UINT | vk::Format::D32_SFLOAT_S8_UINT);
    let mut rendering = vk::PipelineRenderingCreateInfo::default()
        .color_attachment_formats(d.color_formats)
        .depth_attachment_format(d.depth_format)
        .stencil_attachment_format(if has_stencil { d.depth_format } else { vk::Format::UNDEFINED });
    let info = vk::GraphicsPipelineCreateInfo::default()
        .stages(&stages)
        .vertex_input_state(&vertex_input)
        .input_assembly_state(&ia)
        .viewport_state(&vp)
        .rasterization_state(&rs)
        .multisample_state(&ms)
        .depth_stencil_state(&ds)
        .color_blend_state(&cb)
        .dynamic_state(&dyn_state)
        .layout(d.layout)
        .push_next(&mut rendering);
    // SAFETY: every pointer in `info` refers to locals alive for this call; the modules are
    // destroyed right after, which Vulkan allows once the pipeline exists.
    let result = unsafe { ctx.device().create_graphics_pipelines(vk::PipelineCache::null(), &[info], None) };
    // SAFETY: modules are no longer needed after pipeline creation.
    unsafe {
        ctx.device().destroy_shader_module(vs, None);
        if let Some(fs) = fs {
            ctx.device().destroy_shader_module(fs, None);
        }
    }
    result.map(|p| p[0]).map_err(|(_, e)| Error::Vulkan { call: "vkCreateGraphicsPipelines", result: e })
}

/// A stencil op state with wrap ops, for the shadow volume passes.
pub fn stencil_ops(pass: vk::StencilOp, depth_fail: vk::StencilOp) -> vk::StencilOpState {
    vk::StencilOpState {
        fail_op: vk::StencilOp::KEEP,
        pass_op: pass,
        depth_fail_op: depth_fail,
        compare_op: vk::CompareOp::ALWAYS,
        compare_mask: 0xff,
        write_mask: 0xff,
        reference: 0,
    }
}

/// Stencil test `== reference`, no writes (illumination pass).
pub fn stencil_equal(reference: u32) -> vk::StencilOpState {
    vk::StencilOpState {
        fail_op: vk::StencilOp::KEEP,
        pass_op: vk::StencilOp::KEEP,
        depth_fail_op: vk::StencilOp::KEEP,
        compare_op: vk::CompareOp::EQUAL,
        compare_mask: 0xff,
        write_mask: 0,
        reference,
    }
}
