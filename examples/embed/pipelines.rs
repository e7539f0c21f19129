//! The host's shader modules, graphics pipelines (dynamic rendering or a render pass's
//! subpass) and classic render passes.

use super::vulkan::vkerr;
use ash::vk;
use std::ffi::CStr;

/// A shader module from SPIR-V words (naga's output, validated by naga).
pub(super) fn shader_module(device: &ash::Device, words: &[u32]) -> Result<vk::ShaderModule, String> {
    // SAFETY: `words` is SPIR-V written by naga from a module naga validated.
    unsafe { device.create_shader_module(&vk::ShaderModuleCreateInfo::default().code(words), None) }.map_err(vkerr("vkCreateShaderModule"))
}

/// Where a graphics pipeline renders: dynamic rendering with these formats, or a subpass.
#[derive(Clone, Copy)]
pub(super) enum Target {
    /// Dynamic rendering: one colour attachment of this format and the depth-stencil format.
    Dynamic { color: vk::Format, ds: vk::Format },
    /// This subpass of this render pass (one colour attachment and the depth-stencil).
    RenderPass(vk::RenderPass, u32),
}

/// What differs between the host's two pipelines.
pub(super) struct PipelineState {
    pub(super) module: vk::ShaderModule,
    pub(super) fragment: &'static CStr,
    pub(super) depth_compare: vk::CompareOp,
    pub(super) depth_write: bool,
    pub(super) stencil: Option<vk::StencilOpState>,
    pub(super) depth_bounds: bool,
    pub(super) samples: u32,
}

/// A pipeline with vertex input `vec4 pos` at location 0 (entry `vs`), the fragment entry
/// `s.fragment` writing one colour attachment, two-sided, `s.samples` samples, dynamic viewport
/// and scissor (and depth bounds when used).
pub(super) fn create_pipeline(
    device: &ash::Device,
    layout: vk::PipelineLayout,
    target: Target,
    s: &PipelineState,
) -> Result<vk::Pipeline, String> {
    let stages = [
        vk::PipelineShaderStageCreateInfo::default().stage(vk::ShaderStageFlags::VERTEX).module(s.module).name(c"vs"),
        vk::PipelineShaderStageCreateInfo::default().stage(vk::ShaderStageFlags::FRAGMENT).module(s.module).name(s.fragment),
    ];
    let bindings = [vk::VertexInputBindingDescription { binding: 0, stride: 16, input_rate: vk::VertexInputRate::VERTEX }];
    let attrs = [vk::VertexInputAttributeDescription { location: 0, binding: 0, format: vk::Format::R32G32B32A32_SFLOAT, offset: 0 }];
    let vertex_input =
        vk::PipelineVertexInputStateCreateInfo::default().vertex_binding_descriptions(&bindings).vertex_attribute_descriptions(&attrs);
    let ia = vk::PipelineInputAssemblyStateCreateInfo::default().topology(vk::PrimitiveTopology::TRIANGLE_LIST);
    let vp = vk::PipelineViewportStateCreateInfo::default().viewport_count(1).scissor_count(1);
    let rs = vk::PipelineRasterizationStateCreateInfo::default()
        .polygon_mode(vk::PolygonMode::FILL)
        .cull_mode(vk::CullModeFlags::NONE)
        .front_face(vk::FrontFace::COUNTER_CLOCKWISE)
        .line_width(1.0);
    let ms = vk::PipelineMultisampleStateCreateInfo::default().rasterization_samples(vk::SampleCountFlags::from_raw(s.samples));
    let st = s.stencil.unwrap_or_default();
    let ds = vk::PipelineDepthStencilStateCreateInfo::default()
        .depth_test_enable(true)
        .depth_write_enable(s.depth_write)
        .depth_compare_op(s.depth_compare)
        .depth_bounds_test_enable(s.depth_bounds)
        .min_depth_bounds(0.0)
        .max_depth_bounds(1.0)
        .stencil_test_enable(s.stencil.is_some())
        .front(st)
        .back(st);
    let blend = [vk::PipelineColorBlendAttachmentState::default().color_write_mask(vk::ColorComponentFlags::RGBA)];
    let cb = vk::PipelineColorBlendStateCreateInfo::default().attachments(&blend);
    let mut dynamic = vec![vk::DynamicState::VIEWPORT, vk::DynamicState::SCISSOR];
    if s.depth_bounds {
        dynamic.push(vk::DynamicState::DEPTH_BOUNDS);
    }
    let dyn_state = vk::PipelineDynamicStateCreateInfo::default().dynamic_states(&dynamic);
    let formats;
    let mut rendering;
    let mut info = vk::GraphicsPipelineCreateInfo::default()
        .stages(&stages)
        .vertex_input_state(&vertex_input)
        .input_assembly_state(&ia)
        .viewport_state(&vp)
        .rasterization_state(&rs)
        .multisample_state(&ms)
        .depth_stencil_state(&ds)
        .color_blend_state(&cb)
        .dynamic_state(&dyn_state)
        .layout(layout);
    match target {
        Target::Dynamic { color, ds } => {
            formats = [color];
            rendering = vk::PipelineRenderingCreateInfo::default()
                .color_attachment_formats(&formats)
                .depth_attachment_format(ds)
                .stencil_attachment_format(ds);
            info = info.push_next(&mut rendering);
        }
        Target::RenderPass(rp, subpass) => info = info.render_pass(rp).subpass(subpass),
    }
    // SAFETY: every pointer in `info` refers to locals alive for the call.
    unsafe { device.create_graphics_pipelines(vk::PipelineCache::null(), &[info], None) }
        .map(|p| p[0])
        .map_err(|(_, e)| format!("vkCreateGraphicsPipelines failed: {e:?}"))
}

/// The classic render pass of one of the host's passes: colour attachment 0 (`color`, cleared,
/// left in SHADER_READ_ONLY_OPTIMAL for the readback) and the depth-stencil attachment 1
/// (`clear_ds`: cleared from UNDEFINED, the pre-pass; otherwise loaded from
/// DEPTH_STENCIL_READ_ONLY_OPTIMAL, the lighting pass), left in DEPTH_STENCIL_READ_ONLY_OPTIMAL.
/// The pre-pass has one subpass. The lighting pass (`shadow_subpass`) has two: subpass 0 with
/// the depth-stencil attachment only, where the shadow pass records (no colour attachment, so
/// a driver can run its depth/stencil-only path), then subpass 1, the lighting, with both.
pub(super) struct RenderPassDesc {
    pub(super) attachments: [vk::AttachmentDescription; 2],
    pub(super) color_ref: [vk::AttachmentReference; 1],
    pub(super) ds_ref: vk::AttachmentReference,
    pub(super) dependencies: Vec<vk::SubpassDependency>,
    pub(super) shadow_subpass: bool,
}

impl RenderPassDesc {
    pub(super) fn new(color: vk::Format, ds: vk::Format, samples: u32, clear_ds: bool, shadow_subpass: bool) -> RenderPassDesc {
        let samples = vk::SampleCountFlags::from_raw(samples);
        let read_only = vk::ImageLayout::DEPTH_STENCIL_READ_ONLY_OPTIMAL;
        let (ds_load, ds_initial) =
            if clear_ds { (vk::AttachmentLoadOp::CLEAR, vk::ImageLayout::UNDEFINED) } else { (vk::AttachmentLoadOp::LOAD, read_only) };
        let attachments = [
            vk::AttachmentDescription::default()
                .format(color)
                .samples(samples)
                .load_op(vk::AttachmentLoadOp::CLEAR)
                .store_op(vk::AttachmentStoreOp::STORE)
                .initial_layout(vk::ImageLayout::UNDEFINED)
                .final_layout(vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL),
            vk::AttachmentDescription::default()
                .format(ds)
                .samples(samples)
                .load_op(ds_load)
                .store_op(vk::AttachmentStoreOp::STORE)
                .stencil_load_op(ds_load)
                .stencil_store_op(vk::AttachmentStoreOp::STORE)
                .initial_layout(ds_initial)
                .final_layout(read_only),
        ];
        let tests = vk::PipelineStageFlags::EARLY_FRAGMENT_TESTS | vk::PipelineStageFlags::LATE_FRAGMENT_TESTS;
        let output = vk::PipelineStageFlags::COLOR_ATTACHMENT_OUTPUT;
        let writes = vk::AccessFlags::DEPTH_STENCIL_ATTACHMENT_WRITE | vk::AccessFlags::COLOR_ATTACHMENT_WRITE;
        let last = shadow_subpass as u32;
        let mut dependencies = vec![
            // Everything earlier (the previous readback's compute reads, the uploads): done
            // before the attachments are cleared, loaded or written.
            vk::SubpassDependency::default()
                .src_subpass(vk::SUBPASS_EXTERNAL)
                .dst_subpass(0)
                .src_stage_mask(vk::PipelineStageFlags::ALL_COMMANDS)
                .src_access_mask(vk::AccessFlags::MEMORY_WRITE)
                .dst_stage_mask(tests | output)
                .dst_access_mask(writes | vk::AccessFlags::DEPTH_STENCIL_ATTACHMENT_READ | vk::AccessFlags::COLOR_ATTACHMENT_READ),
            // The attachments' writes visible to the readback's compute shader.
            vk::SubpassDependency::default()
                .src_subpass(last)
                .dst_subpass(vk::SUBPASS_EXTERNAL)
                .src_stage_mask(tests | output)
                .src_access_mask(writes)
                .dst_stage_mask(vk::PipelineStageFlags::COMPUTE_SHADER)
                .dst_access_mask(vk::AccessFlags::SHADER_READ),
        ];
        if shadow_subpass {
            // The colour attachment's first use (and layout transition) is subpass 1: after
            // the previous light's readback read it.
            dependencies.push(
                vk::SubpassDependency::default()
                    .src_subpass(vk::SUBPASS_EXTERNAL)
                    .dst_subpass(1)
                    .src_stage_mask(vk::PipelineStageFlags::ALL_COMMANDS)
                    .src_access_mask(vk::AccessFlags::MEMORY_WRITE)
                    .dst_stage_mask(output)
                    .dst_access_mask(vk::AccessFlags::COLOR_ATTACHMENT_WRITE | vk::AccessFlags::COLOR_ATTACHMENT_READ),
            );
            // The shadow pass's stencil count before the lighting's stencil test.
            dependencies.push(
                vk::SubpassDependency::default()
                    .src_subpass(0)
                    .dst_subpass(1)
                    .src_stage_mask(tests)
                    .src_access_mask(vk::AccessFlags::DEPTH_STENCIL_ATTACHMENT_WRITE)
                    .dst_stage_mask(tests)
                    .dst_access_mask(vk::AccessFlags::DEPTH_STENCIL_ATTACHMENT_READ | vk::AccessFlags::DEPTH_STENCIL_ATTACHMENT_WRITE)
                    .dependency_flags(vk::DependencyFlags::BY_REGION),
            );
        }
        RenderPassDesc {
            attachments,
            color_ref: [vk::AttachmentReference { attachment: 0, layout: vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL }],
            ds_ref: vk::AttachmentReference { attachment: 1, layout: vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL },
            dependencies,
            shadow_subpass,
        }
    }

    /// The subpasses; their pointers refer to `self`.
    pub(super) fn subpasses(&self) -> Vec<vk::SubpassDescription<'_>> {
        let both = vk::SubpassDescription::default()
            .pipeline_bind_point(vk::PipelineBindPoint::GRAPHICS)
            .color_attachments(&self.color_ref)
            .depth_stencil_attachment(&self.ds_ref);
        if !self.shadow_subpass {
            return vec![both];
        }
        let shadow =
            vk::SubpassDescription::default().pipeline_bind_point(vk::PipelineBindPoint::GRAPHICS).depth_stencil_attachment(&self.ds_ref);
        vec![shadow, both]
    }
}

/// Creates the render pass `desc` describes; `info` is handed the create info too (for the
/// shadow pass's [`umbrage::pass::RenderPassTarget::new`]) while its pointers are alive.
pub(super) fn create_render_pass<T>(
    device: &ash::Device,
    desc: &RenderPassDesc,
    info: impl FnOnce(vk::RenderPass, &vk::RenderPassCreateInfo) -> Result<T, String>,
) -> Result<(vk::RenderPass, T), String> {
    let subpasses = desc.subpasses();
    let create = vk::RenderPassCreateInfo::default().attachments(&desc.attachments).subpasses(&subpasses).dependencies(&desc.dependencies);
    // SAFETY: every pointer in `create` refers to `desc` or locals alive for the call.
    let rp = unsafe { device.create_render_pass(&create, None) }.map_err(vkerr("vkCreateRenderPass"))?;
    match info(rp, &create) {
        Ok(t) => Ok((rp, t)),
        Err(e) => {
            // SAFETY: the render pass was never used.
            unsafe { device.destroy_render_pass(rp, None) };
            Err(e)
        }
    }
}
