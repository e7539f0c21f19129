//! Graphics pipelines for dynamic rendering or a render pass's subpass, described by a plain struct so that every
//! pipeline of the renderer reads as a table of its fixed-function state.

use super::context::GpuDevice;
use crate::error::{Error, Result};
use ash::vk;

fn vkerr(call: &'static str) -> impl Fn(vk::Result) -> Error {
    Error::vk(call)
}

/// Colour blending, the same for every colour attachment of a pipeline.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Blend {
    /// No blending: the fragment's colour replaces dst.
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
///
/// Fixed for all of them: triangle lists, fill mode, counter-clockwise front faces, line width 1, the vertex entry point `main`, and viewport and scissor as dynamic state (one each), so
/// the caller sets both before drawing.
#[derive(Clone)]
pub struct PipelineDesc<'a> {
    /// SPIR-V of the vertex shader (little-endian words, e.g. a [`super::shaders`] constant).
    pub vertex: &'a [u8],
    /// SPIR-V of the fragment shader; `None` = no fragment stage (depth/stencil-only passes).
    pub fragment: Option<&'a [u8]>,
    /// The fragment shader's entry point (`main` unless a WGSL module holds several).
    pub fragment_entry: &'a std::ffi::CStr,
    /// Byte stride of vertex binding 0 (per-vertex); 0 = no vertex input at all, in which case
    /// the instance binding below is ignored too.
    pub vertex_stride: u32,
    /// `(location, format, offset in bytes)` of each attribute read from binding 0.
    pub attributes: &'a [(u32, vk::Format, u32)],
    /// Byte stride of the per-instance binding 1; 0 = no such binding.
    pub instance_stride: u32,
    /// `(location, format, offset in bytes)` of each attribute read from binding 1.
    pub instance_attributes: &'a [(u32, vk::Format, u32)],
    /// Formats of the colour attachments, in attachment order (dynamic rendering); may be empty.
    pub color_formats: &'a [vk::Format],
    /// Blending of every colour attachment.
    pub blend: Blend,
    /// Whether RGBA is written to the colour attachments (false: write mask empty, e.g. stencil-only passes).
    pub color_write: bool,
    /// Format of the depth attachment, `UNDEFINED` for none. A format with stencil is also
    /// used as the stencil attachment format.
    pub depth_format: vk::Format,
    /// Depth test enabled.
    pub depth_test: bool,
    /// Depth writes enabled.
    pub depth_write: bool,
    /// Depth comparison, when [`PipelineDesc::depth_test`] is on.
    pub depth_compare: vk::CompareOp,
    /// Depth clamping instead of clipping at the near/far planes; needs [`super::Features::depth_clamp`].
    pub depth_clamp: bool,
    /// Depth-bounds test; the bounds are then dynamic state (`vkCmdSetDepthBounds` before
    /// drawing). Needs [`super::Features::depth_bounds`].
    pub depth_bounds: bool,
    /// `(front, back)` stencil state; `Some` enables the stencil test, which needs a depth
    /// format with stencil.
    pub stencil: Option<(vk::StencilOpState, vk::StencilOpState)>,
    /// Faces culled (front faces are counter-clockwise).
    pub cull: vk::CullModeFlags,
    /// Constant and slope-scaled depth bias (shadow-map pass), in Vulkan's depth-bias units.
    pub depth_bias: Option<(f32, f32)>,
    /// The pipeline layout; must match the shaders' descriptor sets and push constants.
    pub layout: vk::PipelineLayout,
    /// Rasterisation samples (the attachments' sample count).
    pub samples: vk::SampleCountFlags,
    /// `Some(render pass, subpass, colour attachments of the subpass)`: built for that
    /// subpass instead of dynamic rendering. When [`PipelineDesc::color_formats`] is empty the
    /// pipeline still has one blend state per colour attachment of the subpass, writing
    /// nothing.
    pub render_pass: Option<(vk::RenderPass, u32, u32)>,
    /// The views (bit `i`: view `i`, rendered into layer `i`) of the rendering instances the
    /// pipeline is used in; 0 (the default): no multiview. Non-zero needs the `multiview`
    /// feature and dynamic rendering.
    pub view_mask: u32,
    /// A mesh-shader pipeline (`VK_EXT_mesh_shader`, enabled): the SPIR-V module and its
    /// mesh entry point replace the vertex stage (`vertex`, the vertex input and the input
    /// assembly are then ignored). `None` (the default): a vertex pipeline.
    pub mesh: Option<(&'a [u8], &'a std::ffi::CStr)>,
    /// With [`PipelineDesc::mesh`]: a task entry point of the same module (`taskShader`
    /// enabled), run before the mesh stage. `None` (the default): no task stage.
    pub task: Option<&'a std::ffi::CStr>,
}

impl<'a> PipelineDesc<'a> {
    /// A pipeline with a vertex shader only and everything off: no vertex input, no colour
    /// attachments, no blending (colour writes on), no depth test or writes (compare `ALWAYS`),
    /// no clamp, bounds, stencil, culling or bias. Set the fields that differ.
    pub fn new(vertex: &'a [u8], layout: vk::PipelineLayout, depth_format: vk::Format) -> Self {
        PipelineDesc {
            vertex,
            fragment: None,
            fragment_entry: c"main",
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
            samples: vk::SampleCountFlags::TYPE_1,
            render_pass: None,
            view_mask: 0,
            mesh: None,
            task: None,
        }
    }
}

/// Creates a shader module from SPIR-V bytes (little-endian words; a trailing partial word is
/// ignored). `spirv` must be valid SPIR-V for the device, as the [`super::shaders`] constants
/// (validated by naga at build time) are. The caller destroys the module.
pub fn shader_module(ctx: &impl GpuDevice, spirv: &[u8]) -> Result<vk::ShaderModule> {
    let words: Vec<u32> = spirv.chunks_exact(4).map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]])).collect();
    let info = vk::ShaderModuleCreateInfo::default().code(&words);
    // SAFETY: valid device; `info` points at `words`, alive for the call. `words` is SPIR-V
    // produced and validated by naga in build.rs (the callers pass `shaders::` constants).
    unsafe { ctx.device().create_shader_module(&info, None) }.map_err(vkerr("vkCreateShaderModule"))
}

/// Creates the graphics pipeline `d` describes, for dynamic rendering or the subpass of
/// [`PipelineDesc::render_pass`]. The
/// shader modules are created and destroyed here; the pipeline is the caller's to destroy,
/// and `d.layout` must outlive every use of it.
pub fn create(ctx: &impl GpuDevice, d: &PipelineDesc) -> Result<vk::Pipeline> {
    let (first_module, first_stage, first_entry) = match d.mesh {
        Some((module, entry)) => (module, vk::ShaderStageFlags::MESH_EXT, entry),
        None => (d.vertex, vk::ShaderStageFlags::VERTEX, c"main"),
    };
    let vs = shader_module(ctx, first_module)?;
    let fs = match d.fragment.map(|f| shader_module(ctx, f)).transpose() {
        Ok(fs) => fs,
        Err(e) => {
            // SAFETY: the module was just created and is used by nothing.
            unsafe { ctx.device().destroy_shader_module(vs, None) };
            return Err(e);
        }
    };
    let mut stages = vec![vk::PipelineShaderStageCreateInfo::default().stage(first_stage).module(vs).name(first_entry)];
    if let (Some(task), Some(_)) = (d.task, d.mesh) {
        stages.push(vk::PipelineShaderStageCreateInfo::default().stage(vk::ShaderStageFlags::TASK_EXT).module(vs).name(task));
    }
    if let Some(fs) = fs {
        stages.push(vk::PipelineShaderStageCreateInfo::default().stage(vk::ShaderStageFlags::FRAGMENT).module(fs).name(d.fragment_entry));
    }
    let mut bindings =
        vec![vk::VertexInputBindingDescription { binding: 0, stride: d.vertex_stride, input_rate: vk::VertexInputRate::VERTEX }];
    let mut attrs: Vec<_> = d
        .attributes
        .iter()
        .map(|&(location, format, offset)| vk::VertexInputAttributeDescription { location, binding: 0, format, offset })
        .collect();
    if !d.instance_attributes.is_empty() {
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
    let ms = vk::PipelineMultisampleStateCreateInfo::default().rasterization_samples(d.samples);
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
    let att = blend_attachment(d.blend, mask);
    let atts = match d.render_pass {
        // A subpass's colour attachments the pipeline does not write.
        Some((_, _, n)) if d.color_formats.is_empty() => {
            vec![vk::PipelineColorBlendAttachmentState::default().color_write_mask(vk::ColorComponentFlags::empty()); n as usize]
        }
        _ => vec![att; d.color_formats.len()],
    };
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
        .stencil_attachment_format(if has_stencil { d.depth_format } else { vk::Format::UNDEFINED })
        .view_mask(d.view_mask);
    let mut info = vk::GraphicsPipelineCreateInfo::default().stages(&stages);
    if d.mesh.is_none() {
        info = info.vertex_input_state(&vertex_input).input_assembly_state(&ia);
    }
    info = info
        .viewport_state(&vp)
        .rasterization_state(&rs)
        .multisample_state(&ms)
        .depth_stencil_state(&ds)
        .color_blend_state(&cb)
        .dynamic_state(&dyn_state)
        .layout(d.layout);
    info = match d.render_pass {
        Some((render_pass, subpass, _)) => info.render_pass(render_pass).subpass(subpass),
        None => info.push_next(&mut rendering),
    };
    let result = super::creation::timed(
        || label(d),
        || {
            // SAFETY: every pointer in `info` refers to locals alive for this call; the modules
            // are destroyed right after, which Vulkan allows once the pipeline exists.
            unsafe { ctx.device().create_graphics_pipelines(ctx.pipeline_cache(), &[info], None) }
                .map_err(|(_, e)| Error::Vulkan { call: "vkCreateGraphicsPipelines", result: e })
        },
    );
    // SAFETY: modules are no longer needed after pipeline creation.
    unsafe {
        ctx.device().destroy_shader_module(vs, None);
        if let Some(fs) = fs {
            ctx.device().destroy_shader_module(fs, None);
        }
    }
    result.map(|p| p[0])
}

/// The colour attachment state of `blend`, writing the components of `mask` (what
/// [`create`] gives each colour attachment; for pipelines made by hand).
pub fn blend_attachment(blend: Blend, mask: vk::ColorComponentFlags) -> vk::PipelineColorBlendAttachmentState {
    match blend {
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
    }
}

/// A graphics pipeline's name in [`super::creation`]'s log: its shaders and the state that
/// tells the renderer's pipelines apart.
fn label(d: &PipelineDesc) -> String {
    let mut s = match d.mesh {
        Some((module, entry)) => format!("{}:{}", super::creation::shader_name(module), entry.to_string_lossy()),
        None => super::creation::shader_name(d.vertex),
    };
    if let (Some(task), Some(_)) = (d.task, d.mesh) {
        s += &format!(" (task {})", task.to_string_lossy());
    }
    if let Some(f) = d.fragment {
        s += &format!(" + {}", super::creation::shader_name(f));
        if d.fragment_entry != c"main" {
            s += &format!(":{}", d.fragment_entry.to_string_lossy());
        }
    }
    if d.depth_test {
        s += &format!(" depth {:?}{}", d.depth_compare, if d.depth_write { " write" } else { "" });
    }
    if let Some((f, b)) = d.stencil {
        s += &format!(" stencil {:?}/{:?} back {:?}/{:?}", f.pass_op, f.depth_fail_op, b.pass_op, b.depth_fail_op);
    }
    if d.blend != Blend::None {
        s += &format!(" blend {:?}", d.blend);
    }
    for (on, what) in [
        (d.depth_clamp, " clamp"),
        (d.depth_bounds, " bounds"),
        (d.depth_bias.is_some(), " bias"),
        (d.render_pass.is_some(), " render-pass"),
    ] {
        if on {
            s += what;
        }
    }
    if d.samples != vk::SampleCountFlags::TYPE_1 {
        s += &format!(" {}x", d.samples.as_raw());
    }
    if d.view_mask != 0 {
        s += &format!(" views {:#x}", d.view_mask);
    }
    s
}

/// A stencil op state for the shadow-volume passes: the test always passes, `pass` is applied
/// where the depth test passes and `depth_fail` where it fails (e.g. `INCREMENT_AND_WRAP` /
/// `DECREMENT_AND_WRAP`), all 8 bits compared and written, reference 0.
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

/// Stencil test `stencil == reference` on all 8 bits, no writes (illumination pass: lit where
/// the count is `reference`, usually 0).
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
