//! [`Technique::Mesh`](super::Technique::Mesh)'s recording: each caster part the GPU
//! extrudes is a `vkCmdDrawMeshTasksEXT` over its meshlets (the task stage culling them where
//! the device has it), with the frame's mesh set bound; the parts the planner leaves on the
//! CPU draw their planned lists. The overlay (`diagnostics.rs`) draws the same mesh draws
//! through [`record_mesh`](ShadowPass::record_mesh).

use super::draw::{CasterDraw, Draw, LightFrame};
use super::frame::PreparedFrame;
use super::mesh::MeshDraw;
use super::push::VolumePush;
use super::stencil::VolumeKind;
use super::volumes::{casters_for, Bound};
use super::ShadowPass;
use crate::error::{Misuse, Result};
use crate::shadow::Case;
use ash::vk;

impl ShadowPass {
    /// Records `lf`'s volumes for `kind`: mesh draws where the draw is one, the planned
    /// draws otherwise, in the casters' order.
    ///
    /// # Safety
    /// As [`cmd_draw_volumes`](Self::cmd_draw_volumes), which checked the frame, the light and
    /// that `kind` has pipelines.
    pub(super) unsafe fn record_mesh_light(
        &self,
        cb: vk::CommandBuffer,
        frame: &PreparedFrame,
        lf: &LightFrame,
        kind: VolumeKind,
        bound: &mut Bound,
    ) -> Result<()> {
        for c in casters_for(lf, kind) {
            for dr in c.draws.iter() {
                match &dr.mesh {
                    Some(md) => {
                        // SAFETY: the caller's contract; the mesh draw's set and tables live
                        // until the slot is prepared again.
                        if unsafe { self.record_mesh_draw(cb, frame, kind, c, dr, md)? } {
                            bound.reset();
                        }
                    }
                    // SAFETY: the caller's contract.
                    None => unsafe { self.record_planned_draw(cb, frame, kind, c, dr, bound) },
                }
            }
        }
        Ok(())
    }

    /// Records one mesh draw of [`Technique::Mesh`](super::desc::Technique::Mesh) for `kind`
    /// (its pipeline, then [`record_mesh`](Self::record_mesh)); returns whether anything was
    /// bound (a kind the mesh path has no pipeline for draws nothing: the light-intensity
    /// map's casters are never on it).
    ///
    /// # Safety
    /// As [`cmd_draw_volumes`](Self::cmd_draw_volumes); `dr` and `md` are a draw of `c`, of
    /// `frame`.
    unsafe fn record_mesh_draw(
        &self,
        cb: vk::CommandBuffer,
        frame: &PreparedFrame,
        kind: VolumeKind,
        c: &CasterDraw,
        dr: &Draw,
        md: &MeshDraw,
    ) -> Result<bool> {
        let set = self.mesh_set(frame)?;
        let zpass = dr.case == Case::ZPass;
        let pipe = match kind {
            VolumeKind::Stencil => set.stencil_for(dr.case, dr.light_cap),
            VolumeKind::Rasterised => set.raster,
            VolumeKind::Float => match set.count {
                Some(p) => {
                    p[if zpass {
                        0
                    } else if dr.light_cap {
                        2
                    } else {
                        1
                    }]
                }
                None => return Ok(false),
            },
            VolumeKind::FloatDepthTested => match set.count {
                Some(p) => p[if zpass { 0 } else { 1 }],
                None => return Ok(false),
            },
            VolumeKind::Transmit { .. } => return Ok(false),
        };
        let sign = if zpass { 1.0 } else { -1.0 };
        // SAFETY: forwarded contract.
        unsafe { self.record_mesh(cb, frame, pipe, c, md, [sign, 0.0, 0.0, 0.0])? };
        Ok(true)
    }

    /// The mesh pipelines `frame` draws with: the culled set (task stage first) where the pass
    /// has task shaders and the frame's [`PassToggles::mesh_task`](super::PassToggles::mesh_task) is on, else the plain one.
    pub(super) fn mesh_set(&self, frame: &PreparedFrame) -> Result<&super::mesh_pipes::MeshPipeSet> {
        let culled = self.caps.task_shader && frame.settings.toggles.mesh_task;
        self.techniques
            .mesh
            .pipes
            .as_ref()
            .and_then(|mp| mp.set(culled))
            .ok_or_else(|| Misuse::NotConfigured { call: "cmd_draw_volumes (mesh draws)", needs: "Technique::Mesh's pipelines" }.into())
    }

    /// Binds `pipe` (a mesh pipeline of the frame's set) and the frame's mesh set, pushes the
    /// caster's block with `color` and draws `md`'s meshlets (`vkCmdDrawMeshTasksEXT`: with
    /// the task stage, one task workgroup per [`TASK_GROUP`](super::mesh::TASK_GROUP)
    /// meshlets).
    ///
    /// # Safety
    /// As [`cmd_draw_volumes`](Self::cmd_draw_volumes) (or inside the overlay's rendering
    /// instance); `md` is a mesh draw of `c`, of `frame`.
    pub(super) unsafe fn record_mesh(
        &self,
        cb: vk::CommandBuffer,
        frame: &PreparedFrame,
        pipe: vk::Pipeline,
        c: &CasterDraw,
        md: &MeshDraw,
        color: [f32; 4],
    ) -> Result<()> {
        let culled = self.caps.task_shader && frame.settings.toggles.mesh_task;
        let (Some(mp), Some(cf)) = (self.techniques.mesh.pipes.as_ref(), frame.compute.as_ref()) else {
            return Err(Misuse::NotConfigured { call: "cmd_draw_volumes (mesh draws)", needs: "Technique::Mesh's pipelines" }.into());
        };
        let push = md.push(&VolumePush::new(c.mvp, c.light_object, color));
        let groups = if culled { md.meshlets.div_ceil(super::mesh::TASK_GROUP) } else { md.meshlets };
        let d = &self.dev.device;
        // SAFETY: the caller's contract; the push block matches the mesh layout's range; the
        // frame's mesh set and the arena's tables live until the slot is prepared again.
        unsafe {
            d.cmd_bind_pipeline(cb, vk::PipelineBindPoint::GRAPHICS, pipe);
            d.cmd_bind_descriptor_sets(cb, vk::PipelineBindPoint::GRAPHICS, mp.layout, 0, &[cf.mesh_set], &[]);
            d.cmd_push_constants(cb, mp.layout, mp.stages, 0, bytemuck::bytes_of(&push));
            mp.loader.cmd_draw_mesh_tasks(cb, groups, 1, 1);
        }
        Ok(())
    }
}
