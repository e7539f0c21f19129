//! Mesh-shader extrusion ([`Technique::Mesh`](super::Technique::Mesh)): the mesh pipelines, their
//! push block and descriptor-set layout, and each part's draws.
//!
//! The CPU plans as for [`Technique::Compute`](super::Technique::Compute) (McGuire's cases from
//! the parts' bounds, culling, the formulation and the dark cap kind); the compute pass's
//! `facing` and `exact` stages find every (light, caster) pair's facing bits, bit for bit the
//! CPU's; then per (light, caster part) and per thing drawn (sides with their fan dark-cap
//! triangles, the dark cap of front or back faces, the light cap) one `vkCmdDrawMeshTasksEXT`
//! over the part's meshlets ([`crate::shadow::meshlet`]), a workgroup each, emits the
//! triangles the CPU would (`shaders/extrude.wgsl`). The caster's static tables (positions,
//! triangles, meshlets, their triangles and owned edges) are the compute pass's arena's; the
//! facing bits and the per-draw counters are the frame's.
//!
//! A draw covers at most [`MAX_TASKS`] meshlets (every device's `maxMeshWorkGroupCount[0]`):
//! larger parts take several draws.

use super::device::PassDevice;
use super::pipelines::{mirror, COUNT_FORMAT};
use super::push::VolumePush;
use crate::error::{Error, Result};
use crate::gpu::descriptors::pipeline_layout;
use crate::gpu::pipeline::{self, Blend, PipelineDesc};
use crate::gpu::{shaders, GpuDevice};
use crate::shadow::Case;
use ash::vk;
use bytemuck::{Pod, Zeroable};

/// Most meshlets (workgroups) one draw dispatches: Vulkan's minimum `maxMeshWorkGroupCount[0]`.
pub(crate) const MAX_TASKS: u32 = 65535;
/// Storage-buffer bindings of the mesh set: positions, triangles, meshlets, meshlet triangles,
/// meshlet edges (the arena's), facing bits and the draws' counters (the frame's).
pub(crate) const MESH_BINDINGS: u32 = 7;
/// Words of one draw's counters: sides, dark cap, light cap, silhouette edges.
pub(crate) const COUNT_WORDS: usize = 4;

/// What a draw emits (`pc.flags` of `shaders/extrude.wgsl`).
pub(crate) mod flags {
    /// Owned silhouette edges' sides (and fan triangles).
    pub const SIDES: u32 = 0;
    /// The dark cap of front or back faces.
    pub const DARK: u32 = 1;
    /// The light cap.
    pub const LIGHT: u32 = 2;
    /// A directional light: one side triangle per edge.
    pub const DIRECTIONAL: u32 = 4;
    /// McGuire's fan dark cap, with the sides.
    pub const FAN: u32 = 8;
    /// `DARK`: the front faces' cap (else the back faces'); `LIGHT`: the front formulation.
    pub const WANT: u32 = 16;
}

/// The push block of `shaders/extrude.wgsl` (`struct Push`): 128 bytes, the most every
/// device takes.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub(crate) struct MeshPush {
    /// The volume push block's fields, at its offsets (count.frag reads `color`).
    pub mvp: [f32; 16],
    pub light: [f32; 4],
    pub color: [f32; 4],
    pub meshlet_base: u32,
    pub meshlets: u32,
    pub tri_base: u32,
    pub pos_base: u32,
    pub fac_base: u32,
    pub flags: u32,
    pub apex: u32,
    pub stat: u32,
}

impl MeshPush {
    pub const SIZE: u32 = std::mem::size_of::<MeshPush>() as u32;
}

/// One mesh draw of a caster part (everything of the push block but the caster's matrix,
/// light and sign, which the recording takes from the caster's draw).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct MeshDraw {
    pub meshlet_base: u32,
    pub meshlets: u32,
    pub tri_base: u32,
    pub pos_base: u32,
    pub fac_base: u32,
    pub flags: u32,
    pub apex: u32,
    pub stat: u32,
}

impl MeshDraw {
    /// The push block for the caster's `volume` block.
    pub fn push(&self, volume: &VolumePush) -> MeshPush {
        MeshPush {
            mvp: volume.mvp,
            light: volume.light,
            color: volume.color,
            meshlet_base: self.meshlet_base,
            meshlets: self.meshlets,
            tri_base: self.tri_base,
            pos_base: self.pos_base,
            fac_base: self.fac_base,
            flags: self.flags,
            apex: self.apex,
            stat: self.stat,
        }
    }
}

/// The mesh pipelines: as the volume pipelines ([`super::pipelines`]), with `extrude.wgsl`'s
/// mesh stage in place of `shadow.vert`.
pub(crate) struct MeshPipes {
    /// `VK_EXT_mesh_shader`'s commands.
    pub loader: ash::ext::mesh_shader::Device,
    pub set_layout: vk::DescriptorSetLayout,
    pub layout: vk::PipelineLayout,
    /// Stencil counting: z-pass, z-fail, z-fail light caps (depth NEVER).
    pub stencil: [vk::Pipeline; 3],
    /// The counting variant (depth and stencil tests pass, nothing written).
    pub raster: vk::Pipeline,
    /// The float counter's z-pass, z-fail and caps (where R32F blends).
    pub count: Option<[vk::Pipeline; 3]>,
}

impl MeshPipes {
    /// Creates the pipelines for the pass's `desc` (its depth-stencil format, samples, depth
    /// direction and mode, target model), with depth clamp and depth bounds as the volume
    /// pipelines have them.
    pub fn new(
        instance: &ash::Instance,
        dev: &PassDevice,
        desc: &super::ShadowPassDesc,
        (depth_clamp, depth_bounds, r32f_blend): (bool, bool, bool),
    ) -> Result<MeshPipes> {
        let d = dev.device();
        let bindings: Vec<_> = (0..MESH_BINDINGS)
            .map(|i| {
                vk::DescriptorSetLayoutBinding::default()
                    .binding(i)
                    .descriptor_type(vk::DescriptorType::STORAGE_BUFFER)
                    .descriptor_count(1)
                    .stage_flags(vk::ShaderStageFlags::MESH_EXT)
            })
            .collect();
        // SAFETY: creation on a valid device from locals; destroyed in `destroy` (or below on error).
        let set_layout = unsafe { d.create_descriptor_set_layout(&vk::DescriptorSetLayoutCreateInfo::default().bindings(&bindings), None) }
            .map_err(Error::vk("vkCreateDescriptorSetLayout"))?;
        let mut me = MeshPipes {
            loader: ash::ext::mesh_shader::Device::new(instance, d),
            set_layout,
            layout: vk::PipelineLayout::null(),
            stencil: [vk::Pipeline::null(); 3],
            raster: vk::Pipeline::null(),
            count: None,
        };
        match me.create(dev, desc, (depth_clamp, depth_bounds, r32f_blend)) {
            Ok(()) => Ok(me),
            Err(e) => {
                // SAFETY: nothing created here was used yet.
                unsafe { me.destroy(d) };
                Err(e)
            }
        }
    }

    fn create(
        &mut self,
        dev: &PassDevice,
        desc: &super::ShadowPassDesc,
        (depth_clamp, depth_bounds, r32f_blend): (bool, bool, bool),
    ) -> Result<()> {
        use super::desc::{sample_flags, DepthDirection, DepthMode, TargetModel};
        use vk::StencilOp as S;
        let stages = vk::ShaderStageFlags::MESH_EXT | vk::ShaderStageFlags::FRAGMENT;
        self.layout = pipeline_layout(dev, &[self.set_layout], MeshPush::SIZE, stages)?;
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
        s.mesh = Some((shaders::EXTRUDE_WGSL, c"extrude"));
        s.depth_test = true;
        s.depth_compare = vk::CompareOp::LESS;
        s.depth_clamp = depth_clamp && desc.depth_mode == DepthMode::Clamp;
        s.depth_bounds = depth_bounds;
        s.stencil = Some((pipeline::stencil_ops(S::INCREMENT_AND_WRAP, S::KEEP), pipeline::stencil_ops(S::DECREMENT_AND_WRAP, S::KEEP)));
        self.stencil[0] = create(&s)?;
        s.stencil = Some((pipeline::stencil_ops(S::KEEP, S::DECREMENT_AND_WRAP), pipeline::stencil_ops(S::KEEP, S::INCREMENT_AND_WRAP)));
        self.stencil[1] = create(&s)?;
        s.depth_compare = vk::CompareOp::NEVER;
        self.stencil[2] = create(&s)?;
        let keep = vk::StencilOpState { write_mask: 0, ..pipeline::stencil_ops(S::KEEP, S::KEEP) };
        let mut r = s.clone();
        r.depth_compare = vk::CompareOp::ALWAYS;
        r.stencil = Some((keep, keep));
        self.raster = create(&r)?;
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
            self.count = Some(count);
        }
        Ok(())
    }

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
    pub unsafe fn destroy(&mut self, d: &ash::Device) {
        // SAFETY: the caller's contract; null handles are ignored.
        unsafe {
            for p in self.stencil.into_iter().chain([self.raster]).chain(self.count.into_iter().flatten()) {
                d.destroy_pipeline(p, None);
            }
            d.destroy_pipeline_layout(self.layout, None);
            d.destroy_descriptor_set_layout(self.set_layout, None);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    #[test]
    fn push_matches_the_wgsl_block() {
        assert_eq!(MeshPush::SIZE, 128);
        assert_eq!(std::mem::offset_of!(MeshPush, light), 64);
        assert_eq!(std::mem::offset_of!(MeshPush, color), 80);
        assert_eq!(std::mem::offset_of!(MeshPush, meshlet_base), 96);
        assert_eq!(std::mem::offset_of!(MeshPush, stat), 124);
        // the output budget the shader declares is the meshlets' (and within 256 / 256)
        use crate::shadow::meshlet::{MESHLET_OUTPUT_PRIMITIVES, MESHLET_OUTPUT_VERTICES};
        assert_eq!((MESHLET_OUTPUT_VERTICES, MESHLET_OUTPUT_PRIMITIVES), (255, 153));
    }
}
