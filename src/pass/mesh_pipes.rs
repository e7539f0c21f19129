//! The pipelines of [`Technique::Mesh`](super::Technique::Mesh): as the volume pipelines
//! ([`super::pipelines`]: the same stencil, depth, clamp and bounds state), with
//! `shaders/extrude.wgsl`'s mesh stage in place of `shadow.vert`, and where the device has
//! `taskShader` a second set with its task stage (`cull`) in front, which launches only the
//! meshlets that emit something ([`super::mesh`]). Each set is made with the first frame that
//! draws with it: the culled set where the pass has task shaders and
//! [`PassToggles::mesh_task`](super::PassToggles::mesh_task) is on, else the plain one.

use super::device::PassDevice;
use super::mesh::{MeshPush, MESH_BINDINGS};
use super::pipelines::{mirror, COUNT_FORMAT};
use crate::error::{Error, Result};
use crate::gpu::descriptors::{pipeline_layout, storage_set_layout};
use crate::gpu::pipeline::{self, Blend, PipelineDesc};
use crate::gpu::{shaders, GpuDevice};
use crate::shadow::Case;
use ash::vk;

/// One set of mesh pipelines (plain or culled).
pub(crate) struct MeshPipeSet {
    /// Stencil counting: z-pass, z-fail, z-fail light caps (depth NEVER).
    pub stencil: [vk::Pipeline; 3],
    /// The counting variant (depth and stencil tests pass, nothing written).
    pub raster: vk::Pipeline,
    /// The float counter's z-pass, z-fail and caps (where R32F blends).
    pub count: Option<[vk::Pipeline; 3]>,
    /// The debug overlay (alpha-blended volumes, depth LESS; with a debug colour format and
    /// dynamic rendering), as the volume pipelines' overlay.
    pub overlay: Option<vk::Pipeline>,
}

impl MeshPipeSet {
    /// The stencil pipeline of a draw of `case` (`light_cap`: the light cap's).
    pub fn stencil_for(&self, case: Case, light_cap: bool) -> vk::Pipeline {
        match (case == Case::ZPass, light_cap) {
            (true, _) => self.stencil[0],
            (false, false) => self.stencil[1],
            (false, true) => self.stencil[2],
        }
    }

    /// # Safety
    /// No pending command buffer uses the pipelines.
    unsafe fn destroy(&self, d: &ash::Device) {
        // SAFETY: the caller's contract; null handles are ignored.
        unsafe {
            for p in self.stencil.into_iter().chain([self.raster]).chain(self.count.into_iter().flatten()).chain(self.overlay) {
                d.destroy_pipeline(p, None);
            }
        }
    }
}

/// The mesh pipelines' layouts and sets.
pub(crate) struct MeshPipes {
    /// `VK_EXT_mesh_shader`'s commands.
    pub loader: ash::ext::mesh_shader::Device,
    pub set_layout: vk::DescriptorSetLayout,
    pub layout: vk::PipelineLayout,
    /// The stages the set and the push block are visible to (every push names them all):
    /// mesh and fragment, and task where the pass has task shaders.
    pub stages: vk::ShaderStageFlags,
    /// The plain set (every meshlet a mesh workgroup) and the culled one (the task stage
    /// first), each made with the first frame that draws with it.
    sets: [Option<MeshPipeSet>; 2],
    /// depthClamp, depthBounds, R32F blending: as the volume pipelines have them.
    features: (bool, bool, bool),
}

impl MeshPipes {
    /// The layouts (no pipeline yet: [`ensure`](Self::ensure)); `task`: the pass has
    /// `taskShader`, so the culled set can be made and every stage flag names the task stage.
    pub fn new(instance: &ash::Instance, dev: &PassDevice, features: (bool, bool, bool), task: bool) -> Result<MeshPipes> {
        let d = dev.device();
        let mut stages = vk::ShaderStageFlags::MESH_EXT;
        if task {
            stages |= vk::ShaderStageFlags::TASK_EXT;
        }
        // destroyed in `destroy` (or below on error)
        let set_layout = storage_set_layout(dev, MESH_BINDINGS, stages)?;
        let stages = stages | vk::ShaderStageFlags::FRAGMENT;
        let layout = match pipeline_layout(dev, &[set_layout], MeshPush::SIZE, stages) {
            Ok(l) => l,
            Err(e) => {
                // SAFETY: just created, used by nothing.
                unsafe { d.destroy_descriptor_set_layout(set_layout, None) };
                return Err(e);
            }
        };
        Ok(MeshPipes { loader: ash::ext::mesh_shader::Device::new(instance, d), set_layout, layout, stages, sets: [None, None], features })
    }

    /// Whether the culled set can be made (the pass has task shaders).
    pub fn has_task(&self) -> bool {
        self.stages.contains(vk::ShaderStageFlags::TASK_EXT)
    }

    /// The set frames draw with (`culled`: the task stage's), if made.
    pub fn set(&self, culled: bool) -> Option<&MeshPipeSet> {
        self.sets[culled as usize].as_ref()
    }

    /// Makes the plain set, or the culled one (`culled`, only with task shaders), for the
    /// pass's `desc` (its depth-stencil format, samples, depth direction and mode, target
    /// model). Idempotent.
    pub fn ensure(&mut self, dev: &PassDevice, desc: &super::desc::ShadowPassDesc, culled: bool) -> Result<()> {
        if self.sets[culled as usize].is_some() {
            return Ok(());
        }
        if culled && !self.has_task() {
            return Err(Error::Internal("the culled mesh pipelines need task shaders".into()));
        }
        let mut set = MeshPipeSet { stencil: [vk::Pipeline::null(); 3], raster: vk::Pipeline::null(), count: None, overlay: None };
        match self.create(dev, desc, culled, &mut set) {
            Ok(()) => {
                self.sets[culled as usize] = Some(set);
                Ok(())
            }
            Err(e) => {
                // SAFETY: nothing created here was used yet.
                unsafe { set.destroy(dev.device()) };
                Err(e)
            }
        }
    }

    fn create(&self, dev: &PassDevice, desc: &super::desc::ShadowPassDesc, culled: bool, out: &mut MeshPipeSet) -> Result<()> {
        use super::desc::{sample_flags, DepthDirection, DepthMode, TargetModel};
        use vk::StencilOp as S;
        let (depth_clamp, depth_bounds, r32f_blend) = self.features;
        let reverse = desc.depth_direction == DepthDirection::Reverse;
        let render_pass = match desc.target {
            TargetModel::RenderPass(rp) => Some((rp.render_pass, rp.subpass, rp.color_attachments)),
            _ => None,
        };
        let create = |p: &PipelineDesc| -> Result<vk::Pipeline> {
            let mut p = p.clone();
            if reverse {
                p.depth_compare = mirror(p.depth_compare);
            }
            p.samples = sample_flags(desc.samples);
            p.render_pass = render_pass;
            pipeline::create(dev, &p)
        };
        let mut s = PipelineDesc::new(shaders::SHADOW_VERT, self.layout, desc.depth_stencil_format);
        if culled {
            s.mesh = Some((shaders::EXTRUDE_WGSL, c"extrude_culled"));
            s.task = Some(c"cull");
        } else {
            s.mesh = Some((shaders::EXTRUDE_WGSL, c"extrude"));
        }
        s.depth_test = true;
        s.depth_compare = vk::CompareOp::LESS;
        s.depth_clamp = depth_clamp && desc.depth_mode == DepthMode::Clamp;
        s.depth_bounds = depth_bounds;
        s.stencil = Some((pipeline::stencil_ops(S::INCREMENT_AND_WRAP, S::KEEP), pipeline::stencil_ops(S::DECREMENT_AND_WRAP, S::KEEP)));
        out.stencil[0] = create(&s)?;
        s.stencil = Some((pipeline::stencil_ops(S::KEEP, S::DECREMENT_AND_WRAP), pipeline::stencil_ops(S::KEEP, S::INCREMENT_AND_WRAP)));
        out.stencil[1] = create(&s)?;
        s.depth_compare = vk::CompareOp::NEVER;
        out.stencil[2] = create(&s)?;
        let keep = vk::StencilOpState { write_mask: 0, ..pipeline::stencil_ops(S::KEEP, S::KEEP) };
        let mut r = s.clone();
        r.depth_compare = vk::CompareOp::ALWAYS;
        r.stencil = Some((keep, keep));
        out.raster = create(&r)?;
        if r32f_blend && render_pass.is_none() {
            let fmt = [COUNT_FORMAT];
            let mut c = s.clone();
            c.fragment = Some(shaders::COUNT_FRAG);
            c.color_formats = &fmt;
            c.blend = Blend::Additive;
            c.stencil = None;
            let mut count = [vk::Pipeline::null(); 3];
            for (k, cmp) in [vk::CompareOp::LESS, vk::CompareOp::GREATER_OR_EQUAL, vk::CompareOp::ALWAYS].into_iter().enumerate() {
                c.depth_compare = cmp;
                match create(&c) {
                    Ok(p) => count[k] = p,
                    Err(e) => {
                        // SAFETY: the pipelines were just created and never used.
                        unsafe { count.iter().for_each(|&p| dev.device().destroy_pipeline(p, None)) };
                        return Err(e);
                    }
                }
            }
            out.count = Some(count);
        }
        if let Some(format) = desc.debug_color_format.filter(|_| render_pass.is_none()) {
            let fmt = [format];
            let mut v = s.clone();
            v.fragment = Some(shaders::VOLUME_FRAG);
            v.color_formats = &fmt;
            v.blend = Blend::Alpha;
            v.depth_compare = vk::CompareOp::LESS;
            v.depth_bounds = false;
            v.stencil = None;
            out.overlay = Some(create(&v)?);
        }
        Ok(())
    }

    /// # Safety
    /// No pending command buffer uses the pipelines.
    pub unsafe fn destroy(&mut self, d: &ash::Device) {
        // SAFETY: the caller's contract; null handles are ignored.
        unsafe {
            for set in self.sets.iter_mut().filter_map(Option::take) {
                set.destroy(d);
            }
            d.destroy_pipeline_layout(self.layout, None);
            d.destroy_descriptor_set_layout(self.set_layout, None);
        }
    }
}

/// [`Technique::Mesh`](super::Technique::Mesh)'s state: its pipelines, made with its first
/// frame or `create_pipelines` (its facing bits are [`ComputeState`](super::compute::ComputeState)'s).
#[derive(Default)]
pub(super) struct MeshState {
    pub pipes: Option<MeshPipes>,
}

impl super::device::TechniqueState for MeshState {
    fn destroy(&mut self, dev: &PassDevice) {
        if let Some(mut m) = self.pipes.take() {
            // SAFETY: the pass is dropped after every command buffer that used it completed.
            unsafe { m.destroy(&dev.device) };
        }
    }
}
