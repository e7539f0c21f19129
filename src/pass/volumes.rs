//! The volumes' draws: the pipeline each draw takes, its push block and its bind-and-draw.

use super::desc::IndexFormat;
use super::draw::{CasterDraw, Draw};
use super::frame::PreparedFrame;
use super::pipelines::CountPipes;
use super::push::VolumePush;
use super::stencil::VolumeKind;
use super::ShadowPass;
use crate::error::{Misuse, Result};
use crate::shadow::Case;
use ash::vk;

impl ShadowPass {
    /// Refuses a ray-query frame where volumes are drawn or counted (it has none: the count
    /// would be a silent zero).
    pub(super) fn volume_frame(frame: &PreparedFrame, call: &'static str) -> Result<()> {
        match frame.rays {
            Some(_) => Err(Misuse::NotConfigured {
                call,
                needs: "a volume technique: the frame was prepared for Technique::RayQuery, which draws no volumes",
            }
            .into()),
            None => Ok(()),
        }
    }

    /// Records the volumes of `light` for `kind` inside a rendering instance the caller
    /// began (attachments: the pass's depth-stencil format, plus an R32F colour attachment
    /// for the float kinds or the transmit format for `Transmit`), with the viewport and
    /// scissor set (e.g. by [`cmd_light_state`](Self::cmd_light_state)).
    ///
    /// With [`TargetModel::RenderPass`](super::TargetModel::RenderPass), inside the host's subpass (stencil and rasterised
    /// kinds only).
    ///
    /// Errors ([`Error::Misuse`](crate::Error::Misuse)): as `cmd_determine`'s frame and light checks, and a kind the
    /// pass has no pipelines for (float kinds without R32F blending or in the render-pass
    /// model, `Transmit` without a transmit format).
    ///
    /// # Safety
    /// `cb` is recording inside such a rendering instance or subpass; the frame's uploads and
    /// GPU silhouettes were recorded earlier ([`cmd_before_rendering`](Self::cmd_before_rendering));
    /// `frame`'s slot is not prepared again before `cb` completes.
    pub unsafe fn cmd_draw_volumes(&self, cb: vk::CommandBuffer, frame: &PreparedFrame, light: usize, kind: VolumeKind) -> Result<()> {
        let lf = self.light(frame, light)?;
        Self::volume_frame(frame, "cmd_draw_volumes")?;
        let p = &self.pipes;
        let count = p.count.as_ref();
        match kind {
            VolumeKind::Float | VolumeKind::FloatDepthTested if count.is_none() => {
                return Err(Misuse::NotConfigured {
                    call: "cmd_draw_volumes (float kinds)",
                    needs: "R32_SFLOAT blending and TargetModel::DynamicRendering",
                }
                .into());
            }
            VolumeKind::Transmit { .. } if p.transmit.is_none() => {
                return Err(Misuse::NotConfigured {
                    call: "cmd_draw_volumes (VolumeKind::Transmit)",
                    needs: "ShadowPassDesc::transmit_format",
                }
                .into());
            }
            _ => {}
        }
        // Technique::Compute's merged draws: the light's GPU-silhouette volumes in one draw
        // call per pipeline (src/pass/compute/draws.rs); their chunk draws are skipped below.
        // SAFETY: the caller's contract; `kind` was checked above.
        unsafe { self.record_merged(cb, frame, light, kind)? };
        let merged = frame.compute.as_ref().is_some_and(|cf| cf.merged.is_some());
        let mut bound = vk::Pipeline::null();
        for c in lf.casters.iter().filter(|c| c.case != Case::Culled) {
            let wanted = match kind {
                VolumeKind::Transmit { .. } => c.transmittance.is_some(),
                _ => c.transmittance.is_none(),
            };
            if !wanted {
                continue;
            }
            // Float counter: the sign a front face contributes (+1 z-pass, -1 z-fail);
            // light-intensity map: and the caster's transmittance.
            let color = |case: Case| {
                let sign = if case == Case::ZPass { 1.0 } else { -1.0 };
                let t = c.transmittance.unwrap_or_default();
                [sign, t.x, t.y, t.z]
            };
            if let Some(eq) = &c.edge_quad {
                // SAFETY: the caller's contract; push constants match the pipeline layout.
                unsafe { self.push(cb, c, color(c.case)) };
                let (faces, sides) = match (kind, count) {
                    (VolumeKind::Stencil, _) => (p.stencil.eq_faces, p.stencil.eq_sides),
                    (VolumeKind::Rasterised, _) => (p.raster.edge_quads, p.raster.edge_quads),
                    (VolumeKind::Float, Some(cp)) => (cp.eq_faces, cp.eq_sides),
                    // Self-shadowing leaves edge-quad casters out (their faces are not a
                    // depth-tested volume); transparent casters never take edge quads.
                    _ => continue,
                };
                let d = &self.dev.device;
                // SAFETY: as above; the edge-quad buffers live until the slot retires.
                unsafe {
                    d.cmd_bind_vertex_buffers(cb, 0, &[eq.vertices], &[0]);
                    d.cmd_bind_index_buffer(cb, eq.indices, 0, vk::IndexType::UINT32);
                    d.cmd_bind_pipeline(cb, vk::PipelineBindPoint::GRAPHICS, faces);
                    d.cmd_draw_indexed(cb, eq.face_indices, 1, 0, 0, 0);
                    d.cmd_bind_pipeline(cb, vk::PipelineBindPoint::GRAPHICS, sides);
                    d.cmd_draw_indexed(cb, eq.quad_indices, 1, eq.face_indices, 0, 0);
                }
                bound = sides;
                continue;
            }
            let mut pushed = None;
            for dr in &c.draws {
                if let Some(md) = &dr.mesh {
                    // SAFETY: the caller's contract; the mesh draw's set and tables live until
                    // the slot is prepared again.
                    if unsafe { self.record_mesh_draw(cb, frame, kind, c, dr, md)? } {
                        bound = vk::Pipeline::null();
                        pushed = None;
                    }
                    continue;
                }
                if dr.indirect && merged {
                    continue;
                }
                let planar = frame.settings.technique == super::desc::Technique::Planar;
                let Some(pipe) = self.pipeline_for(kind, count, dr.case, dr.light_cap, planar) else { continue };
                // Parts of one caster may take different cases: the sign follows the draw's.
                let block = color(dr.case);
                if pushed != Some(block) {
                    // SAFETY: as above.
                    unsafe { self.push(cb, c, block) };
                    pushed = Some(block);
                }
                if pipe != bound {
                    // SAFETY: as above.
                    unsafe { self.dev.device.cmd_bind_pipeline(cb, vk::PipelineBindPoint::GRAPHICS, pipe) };
                    bound = pipe;
                }
                // SAFETY: as above.
                unsafe { self.record_draw(cb, frame, dr) };
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
        c: &super::draw::CasterDraw,
        dr: &super::draw::Draw,
        md: &super::mesh::MeshDraw,
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
        c: &super::draw::CasterDraw,
        md: &super::mesh::MeshDraw,
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

    /// Which pipeline counts a draw.
    fn pipeline_for(
        &self,
        kind: VolumeKind,
        count: Option<&CountPipes>,
        case: Case,
        light_cap: bool,
        planar: bool,
    ) -> Option<vk::Pipeline> {
        let s = &self.pipes.stencil;
        if kind == VolumeKind::Rasterised {
            return Some(self.pipes.raster.volume);
        }
        if planar {
            // Flattened casters: the sign pushed is +1 (z-pass), so the float count adds 1.
            return match kind {
                VolumeKind::Stencil => Some(self.pipes.planar),
                VolumeKind::Float => self.pipes.planar_count,
                _ => None,
            };
        }
        let zpass = case == Case::ZPass;
        Some(match kind {
            VolumeKind::Stencil => match (zpass, light_cap) {
                (true, _) => s.zpass,
                (false, false) => s.zfail,
                (false, true) => s.zfail_cap,
            },
            VolumeKind::Float => {
                let c = count?;
                match (zpass, light_cap) {
                    (true, _) => c.zpass,
                    (false, false) => c.zfail,
                    (false, true) => c.cap,
                }
            }
            VolumeKind::FloatDepthTested => {
                let c = count?;
                if zpass {
                    c.zpass
                } else {
                    c.zfail
                }
            }
            // Transparent casters' caps are all in the volume list (not NEVER).
            VolumeKind::Transmit { log } => self.pipes.transmit?[log as usize][(!zpass) as usize],
            VolumeKind::Rasterised => self.pipes.raster.volume,
        })
    }

    /// # Safety
    /// `cb` is recording with a pipeline of the pass's layout bound or about to be.
    pub(super) unsafe fn push(&self, cb: vk::CommandBuffer, c: &CasterDraw, color: [f32; 4]) {
        let push = VolumePush::new(c.mvp, c.light_object, color);
        // SAFETY: the caller's contract; the block matches the layout's range.
        unsafe {
            self.dev.device.cmd_push_constants(
                cb,
                self.pipes.layout,
                vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT,
                0,
                bytemuck::bytes_of(&push),
            )
        };
    }

    /// Binds the chunk's vertices (or the streamed naive vertices) and draws.
    ///
    /// # Safety
    /// `cb` is recording inside a rendering instance with a volume pipeline bound; `frame` is
    /// the frame the draw belongs to (its stream, or its compute records and indices, whose
    /// writes [`cmd_compute_silhouettes`](Self::cmd_compute_silhouettes) made visible).
    pub(super) unsafe fn record_draw(&self, cb: vk::CommandBuffer, frame: &PreparedFrame, dr: &Draw) {
        let d = &self.dev.device;
        let stream = dr.kept.unwrap_or(frame.stream);
        if dr.mesh.is_some() {
            // mesh draws are recorded by `record_mesh_draw`, never from a vertex pipeline
            return;
        }
        // SAFETY: the caller's contract; offsets were computed from the stream just written.
        unsafe {
            if dr.indirect {
                let Some(cf) = frame.compute.as_ref() else { return };
                // with the merged draws the records address the arena's vertex table
                let vertices = cf.merged.as_ref().map_or(dr.vertices, |m| m.handles.vertices);
                d.cmd_bind_vertex_buffers(cb, 0, &[vertices], &[0]);
                d.cmd_bind_index_buffer(cb, cf.out_buffer, 0, vk::IndexType::UINT16);
                d.cmd_draw_indexed_indirect(cb, cf.records_buffer, dr.offset, 1, 20);
                return;
            }
            match dr.format {
                IndexFormat::Naive => {
                    d.cmd_bind_vertex_buffers(cb, 0, &[stream], &[dr.offset]);
                    d.cmd_draw(cb, dr.count, 1, 0, 0);
                }
                f => {
                    let ty = match f {
                        IndexFormat::U8 => vk::IndexType::UINT8_EXT,
                        IndexFormat::U32 => vk::IndexType::UINT32,
                        _ => vk::IndexType::UINT16,
                    };
                    d.cmd_bind_vertex_buffers(cb, 0, &[dr.vertices], &[0]);
                    d.cmd_bind_index_buffer(cb, stream, dr.offset, ty);
                    d.cmd_draw_indexed(cb, dr.count, 1, 0, 0, 0);
                }
            }
        }
    }
}
