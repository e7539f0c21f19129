//! The CPU-planned volumes' draws, which every technique's recording falls back on for the
//! parts the planner leaves on the CPU: the pipeline each draw takes, its push block and its
//! bind-and-draw, and what one light's recording shares ([`Bound`], [`casters_for`],
//! [`color`]). `draw_volumes.rs` hands each light to its technique.

use super::desc::{IndexFormat, Technique};
use super::draw::{CasterDraw, Draw, LightFrame};
use super::frame::PreparedFrame;
use super::pipelines::CountPipes;
use super::push::VolumePush;
use super::stencil::VolumeKind;
use super::ShadowPass;
use crate::error::{Misuse, Result};
use crate::shadow::Case;
use ash::vk;

/// What the recording of one light last bound: the pipeline, and the caster and block it
/// last pushed (a repeat is skipped).
#[derive(Default)]
pub(super) struct Bound {
    pub pipeline: vk::Pipeline,
    pub pushed: Option<(*const CasterDraw, [f32; 4])>,
}

impl Bound {
    /// Forgets what was bound (after a draw that binds its own pipeline or layout).
    pub fn reset(&mut self) {
        *self = Bound::default();
    }
}

/// The casters of `lf` that `kind` draws: not culled, transparent for the light-intensity
/// map, opaque otherwise.
pub(super) fn casters_for(lf: &LightFrame, kind: VolumeKind) -> impl Iterator<Item = &CasterDraw> {
    let transmit = matches!(kind, VolumeKind::Transmit { .. });
    lf.casters.iter().filter(move |c| c.case != Case::Culled && c.transmittance.is_some() == transmit)
}

/// The block a draw of `c` pushes for `case`: the sign a front face contributes to the float
/// counter (+1 z-pass, -1 z-fail), then the caster's transmittance (light-intensity map).
pub(super) fn color(c: &CasterDraw, case: Case) -> [f32; 4] {
    let sign = if case == Case::ZPass { 1.0 } else { -1.0 };
    let t = c.transmittance.unwrap_or_default();
    [sign, t.x, t.y, t.z]
}

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

    /// Records one CPU-planned draw of caster `c` (an index stream, or the naive vertices)
    /// with the pipeline its case takes for `kind`, pushing the caster's block and binding
    /// the pipeline where they changed since `bound`; a draw `kind` has no pipeline for draws
    /// nothing.
    ///
    /// # Safety
    /// As [`cmd_draw_volumes`](Self::cmd_draw_volumes); `dr` is a draw of `c`, of `frame`.
    pub(super) unsafe fn record_planned_draw(
        &self,
        cb: vk::CommandBuffer,
        frame: &PreparedFrame,
        kind: VolumeKind,
        c: &CasterDraw,
        dr: &Draw,
        bound: &mut Bound,
    ) {
        let planar = frame.settings.technique == Technique::Planar;
        let Some(pipe) = self.pipeline_for(kind, self.pipes.count.as_ref(), dr.case, dr.light_cap, planar) else { return };
        // Parts of one caster may take different cases: the sign follows the draw's.
        let block = color(c, dr.case);
        if bound.pushed != Some((c as *const CasterDraw, block)) {
            // SAFETY: the caller's contract.
            unsafe { self.push(cb, c, block) };
            bound.pushed = Some((c as *const CasterDraw, block));
        }
        if pipe != bound.pipeline {
            // SAFETY: as above.
            unsafe { self.dev.device.cmd_bind_pipeline(cb, vk::PipelineBindPoint::GRAPHICS, pipe) };
            bound.pipeline = pipe;
        }
        // SAFETY: as above.
        unsafe { self.record_draw(cb, frame, dr) };
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
