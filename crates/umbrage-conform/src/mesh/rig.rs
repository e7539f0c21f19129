//! The mesh family's GPU side: three storage buffers (`conform_mesh.wgsl`'s `positions`,
//! `words` and `records`) in one descriptor set, the mesh (and task) pipelines over it, and a
//! render of mesh draws into a fresh depth-stencil image, read back with the records.

use super::Push;
use crate::harness::{copy_aspects, Readback};
use crate::shaders;
use ash::vk;
use gpu_allocator::MemoryLocation;
use std::ffi::CStr;
use umbrage::error::{Error, Result};
use umbrage::gpu::descriptors::{pipeline_layout, Binding, DescriptorSet};
use umbrage::gpu::pipeline::shader_module;
use umbrage::gpu::resources::{cleared_depth_stencil, memory_barrier, transfer_to_host_barrier, transition};
use umbrage::gpu::{Buffer, Context, Image};

/// The fixed-function state of a mesh pipeline.
#[derive(Clone, Copy)]
pub(super) struct PipeState {
    /// Stencil state of front-facing triangles (counter-clockwise in Vulkan's sense).
    pub front: vk::StencilOpState,
    /// Stencil state of back-facing triangles.
    pub back: vk::StencilOpState,
    /// Depth written (compare ALWAYS); else no depth test.
    pub depth_write: bool,
    /// `depthClampEnable`.
    pub depth_clamp: bool,
    /// The stencil ops are dynamic state (each [`Draw::ops`] sets them): one pipeline, so one
    /// compile of its shaders, serves several op pairs.
    pub dynamic_ops: bool,
}

impl PipeState {
    /// Stencil `front` / `back` (compare ALWAYS, masks 0xff), no depth test, no clamp.
    pub fn stencil(front: vk::StencilOp, back: vk::StencilOp) -> PipeState {
        let op = |pass| umbrage::gpu::pipeline::stencil_ops(pass, vk::StencilOp::KEEP);
        PipeState { front: op(front), back: op(back), depth_write: false, depth_clamp: false, dynamic_ops: false }
    }
}

/// One `vkCmdDrawMeshTasksEXT`: its pipeline, push block and group counts.
#[derive(Clone, Copy)]
pub(super) struct Draw {
    pub pipeline: vk::Pipeline,
    pub push: Push,
    pub groups: [u32; 3],
    /// The front and back faces' pass ops, for a pipeline with [`PipeState::dynamic_ops`].
    pub ops: Option<[vk::StencilOp; 2]>,
}

/// What a render gave back: both aspects, and every word of the records buffer.
pub(super) struct Rendered {
    pub image: Readback,
    pub records: Vec<u32>,
}

/// The buffers, set, layout and pipelines of one check; destroyed (after the device is idle)
/// on drop.
pub(super) struct Rig<'a> {
    ctx: &'a Context,
    loader: ash::ext::mesh_shader::Device,
    stages: vk::ShaderStageFlags,
    buffers: Vec<Buffer>,
    set: Option<DescriptorSet>,
    layout: vk::PipelineLayout,
    pipelines: Vec<vk::Pipeline>,
    record_words: usize,
}

impl<'a> Rig<'a> {
    /// `positions` and `words` as the shader's read-only tables (never empty: a zero pads
    /// them), and `record_words` zeroed words of records.
    pub fn new(ctx: &'a Context, positions: &[[f32; 4]], words: &[u32], record_words: usize) -> Result<Rig<'a>> {
        let mut stages = vk::ShaderStageFlags::MESH_EXT;
        if ctx.features.task_shader {
            stages |= vk::ShaderStageFlags::TASK_EXT;
        }
        let mut rig = Rig {
            ctx,
            loader: ash::ext::mesh_shader::Device::new(&ctx.instance, &ctx.device),
            stages,
            buffers: Vec::new(),
            set: None,
            layout: vk::PipelineLayout::null(),
            pipelines: Vec::new(),
            record_words,
        };
        let storage = vk::BufferUsageFlags::STORAGE_BUFFER;
        let pos: Vec<u8> = positions.iter().chain([[0.0f32; 4]].iter()).flat_map(|v| v.map(f32::to_le_bytes)).flatten().collect();
        rig.buffers.push(Buffer::with_data(ctx, "conform-mesh-positions", &pos, storage)?);
        let w: Vec<u8> = words.iter().chain([0u32].iter()).flat_map(|w| w.to_le_bytes()).collect();
        rig.buffers.push(Buffer::with_data(ctx, "conform-mesh-words", &w, storage)?);
        let size = (record_words.max(1) * 4) as u64;
        rig.buffers.push(Buffer::new(ctx, "conform-mesh-records", size, storage, MemoryLocation::GpuToCpu)?);
        rig.zero_records()?;
        let bindings: Vec<Binding> = rig.buffers.iter().map(|b| Binding::StorageBuffer(b.raw)).collect();
        let set = DescriptorSet::with_stages(ctx, &bindings, stages)?;
        let set_layout = set.layout;
        rig.set = Some(set);
        rig.layout = pipeline_layout(ctx, &[set_layout], Push::SIZE, stages)?;
        Ok(rig)
    }

    fn zero_records(&mut self) -> Result<()> {
        self.buffers[2].write(0, &vec![0u8; self.record_words.max(1) * 4])
    }

    /// A pipeline of `conform_mesh.wgsl`'s `mesh` entry point (after the `task` one, when
    /// given) for a depth-stencil attachment of `format`, kept until the rig drops.
    pub fn pipeline(&mut self, task: Option<&CStr>, mesh: &CStr, format: vk::Format, st: PipeState) -> Result<vk::Pipeline> {
        let d = &self.ctx.device;
        let module = shader_module(self.ctx, shaders::CONFORM_MESH_WGSL)?;
        let mut stages = Vec::new();
        if let Some(t) = task {
            stages.push(vk::PipelineShaderStageCreateInfo::default().stage(vk::ShaderStageFlags::TASK_EXT).module(module).name(t));
        }
        stages.push(vk::PipelineShaderStageCreateInfo::default().stage(vk::ShaderStageFlags::MESH_EXT).module(module).name(mesh));
        let vp = vk::PipelineViewportStateCreateInfo::default().viewport_count(1).scissor_count(1);
        let rs = vk::PipelineRasterizationStateCreateInfo::default()
            .polygon_mode(vk::PolygonMode::FILL)
            .cull_mode(vk::CullModeFlags::NONE)
            .front_face(vk::FrontFace::COUNTER_CLOCKWISE)
            .depth_clamp_enable(st.depth_clamp)
            .line_width(1.0);
        let ms = vk::PipelineMultisampleStateCreateInfo::default().rasterization_samples(vk::SampleCountFlags::TYPE_1);
        let ds = vk::PipelineDepthStencilStateCreateInfo::default()
            .depth_test_enable(st.depth_write)
            .depth_write_enable(st.depth_write)
            .depth_compare_op(vk::CompareOp::ALWAYS)
            .stencil_test_enable(true)
            .front(st.front)
            .back(st.back)
            .max_depth_bounds(1.0);
        let cb = vk::PipelineColorBlendStateCreateInfo::default();
        let mut dynamic = vec![vk::DynamicState::VIEWPORT, vk::DynamicState::SCISSOR];
        if st.dynamic_ops {
            dynamic.push(vk::DynamicState::STENCIL_OP);
        }
        let dyn_state = vk::PipelineDynamicStateCreateInfo::default().dynamic_states(&dynamic);
        let mut rendering = vk::PipelineRenderingCreateInfo::default().depth_attachment_format(format).stencil_attachment_format(format);
        let info = vk::GraphicsPipelineCreateInfo::default()
            .stages(&stages)
            .viewport_state(&vp)
            .rasterization_state(&rs)
            .multisample_state(&ms)
            .depth_stencil_state(&ds)
            .color_blend_state(&cb)
            .dynamic_state(&dyn_state)
            .layout(self.layout)
            .push_next(&mut rendering);
        // SAFETY: every pointer in `info` refers to locals alive for the call; the module is
        // valid SPIR-V 1.4 validated by naga (build.rs) and destroyed right after, which Vulkan
        // allows once the pipeline exists; the device has meshShader (and taskShader when a
        // task stage is given: the callers check).
        let r = unsafe { d.create_graphics_pipelines(vk::PipelineCache::null(), &[info], None) };
        // SAFETY: the pipeline keeps what it needs of the module; nothing else uses it.
        unsafe { d.destroy_shader_module(module, None) };
        let p = r.map_err(|(_, e)| Error::Vulkan { call: "vkCreateGraphicsPipelines", result: e })?[0];
        self.pipelines.push(p);
        Ok(p)
    }

    /// Zeroes the records, clears a `width` x `height` depth-stencil image of `format` to
    /// `clear`, records `draws` in one rendering instance (viewport and scissor the whole
    /// image, depth range [0, 1]), and reads back both aspects and the records.
    pub fn render(&mut self, format: vk::Format, (width, height): (u32, u32), clear: (f32, u32), draws: &[Draw]) -> Result<Rendered> {
        self.zero_records()?;
        let ctx = self.ctx;
        let extent = vk::Extent2D { width, height };
        let usage = vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT | vk::ImageUsageFlags::TRANSFER_SRC;
        let aspects = vk::ImageAspectFlags::DEPTH | vk::ImageAspectFlags::STENCIL;
        let mut image = Image::new_2d(ctx, "conform-mesh-ds", format, extent, usage, aspects)?;
        let n = (width * height) as u64;
        let mut readback: Vec<Buffer> = Vec::new();
        let result = (|| -> Result<Rendered> {
            let dst = vk::BufferUsageFlags::TRANSFER_DST;
            readback.push(Buffer::new(ctx, "conform-mesh-depth", n * 4, dst, MemoryLocation::GpuToCpu)?);
            readback.push(Buffer::new(ctx, "conform-mesh-stencil", n, dst, MemoryLocation::GpuToCpu)?);
            let (depth_buf, stencil_buf) = (readback[0].raw, readback[1].raw);
            let sets: Vec<vk::DescriptorSet> = self.set.iter().map(|s| s.set).collect();
            ctx.one_shot(|cb| {
                let d = &ctx.device;
                transition(ctx, cb, &image, vk::ImageLayout::UNDEFINED, vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL);
                let att = cleared_depth_stencil(image.view, clear);
                let area = vk::Rect2D { offset: vk::Offset2D { x: 0, y: 0 }, extent };
                let info = vk::RenderingInfo::default().render_area(area).layer_count(1).depth_attachment(&att).stencil_attachment(&att);
                let viewport = vk::Viewport { x: 0.0, y: 0.0, width: width as f32, height: height as f32, min_depth: 0.0, max_depth: 1.0 };
                // SAFETY: `cb` is recording (one_shot); the image, set, layout and pipelines
                // were created on this device and outlive the submission, which one_shot waits
                // for; the push block is the layout's range; group counts are within the
                // device's limits (at most 65535 in x, the minimum maxMeshWorkGroupCount); ops
                // are set only for pipelines with dynamic stencil ops (Vulkan 1.3 core, which
                // the callers require through dynamic rendering).
                unsafe {
                    d.cmd_begin_rendering(cb, &info);
                    d.cmd_set_viewport(cb, 0, &[viewport]);
                    d.cmd_set_scissor(cb, 0, &[area]);
                    d.cmd_bind_descriptor_sets(cb, vk::PipelineBindPoint::GRAPHICS, self.layout, 0, &sets, &[]);
                    for dr in draws {
                        d.cmd_bind_pipeline(cb, vk::PipelineBindPoint::GRAPHICS, dr.pipeline);
                        d.cmd_push_constants(cb, self.layout, self.stages, 0, bytemuck::bytes_of(&dr.push));
                        if let Some([front, back]) = dr.ops {
                            let (keep, always) = (vk::StencilOp::KEEP, vk::CompareOp::ALWAYS);
                            d.cmd_set_stencil_op(cb, vk::StencilFaceFlags::FRONT, keep, front, keep, always);
                            d.cmd_set_stencil_op(cb, vk::StencilFaceFlags::BACK, keep, back, keep, always);
                        }
                        self.loader.cmd_draw_mesh_tasks(cb, dr.groups[0], dr.groups[1], dr.groups[2]);
                    }
                    d.cmd_end_rendering(cb);
                }
                memory_barrier(
                    ctx,
                    cb,
                    (vk::PipelineStageFlags2::ALL_COMMANDS, vk::AccessFlags2::SHADER_WRITE),
                    (vk::PipelineStageFlags2::HOST, vk::AccessFlags2::HOST_READ),
                );
                transition(ctx, cb, &image, vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL, vk::ImageLayout::TRANSFER_SRC_OPTIMAL);
                // SAFETY: recording outside rendering; the image is in TRANSFER_SRC_OPTIMAL and
                // the buffers hold 4 bytes (depth) and 1 byte (stencil) per texel.
                unsafe { copy_aspects(ctx, cb, &image, (depth_buf, stencil_buf)) };
                transfer_to_host_barrier(ctx, cb);
            })?;
            let depth = readback[0].read()?.chunks_exact(4).map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]])).collect();
            let stencil = readback[1].read()?.to_vec();
            let records = self.buffers[2].read()?.chunks_exact(4).map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]])).collect();
            Ok(Rendered { image: Readback { width, height, depth, stencil }, records })
        })();
        for b in &mut readback {
            b.destroy(ctx);
        }
        image.destroy(ctx);
        result
    }
}

impl Drop for Rig<'_> {
    fn drop(&mut self) {
        let d = &self.ctx.device;
        // SAFETY: after the wait nothing is in use; every handle was created on this device
        // (null ones are ignored).
        unsafe {
            let _ = d.device_wait_idle();
            for p in self.pipelines.drain(..) {
                d.destroy_pipeline(p, None);
            }
            d.destroy_pipeline_layout(self.layout, None);
        }
        if let Some(mut s) = self.set.take() {
            s.destroy(self.ctx);
        }
        for b in &mut self.buffers {
            b.destroy(self.ctx);
        }
    }
}
