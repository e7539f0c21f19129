//! [`Technique::EdgeQuads`](super::Technique::EdgeQuads)' recording: the GPU-only silhouettes
//! of the Cg article. Each manifold caster draws from static buffers made once
//! ([`CasterTable::ensure_edge_quads`](super::casters::CasterTable::ensure_edge_quads)): its
//! faces (the caps, extruded by the vertex shader where they face away), then a quad on every
//! edge, degenerate unless the edge is a silhouette. The casters the planner leaves on the CPU
//! (multiplicity and transparent ones) draw their planned lists.

use super::draw::LightFrame;
use super::frame::PreparedFrame;
use super::stencil::VolumeKind;
use super::volumes::{casters_for, color, Bound};
use super::ShadowPass;
use ash::vk;

impl ShadowPass {
    /// Records `lf`'s volumes for `kind` with edge quads where the caster has them.
    /// Self-shadowing's depth-tested float kind leaves edge-quad casters out (their faces are
    /// not a depth-tested volume); transparent casters never take edge quads.
    ///
    /// # Safety
    /// As [`cmd_draw_volumes`](Self::cmd_draw_volumes), which checked the frame, the light and
    /// that `kind` has pipelines; the edge-quad buffers live until the frame's slot retires.
    pub(super) unsafe fn record_edge_quads_light(
        &self,
        cb: vk::CommandBuffer,
        frame: &PreparedFrame,
        lf: &LightFrame,
        kind: VolumeKind,
        bound: &mut Bound,
    ) {
        let p = &self.pipes;
        for c in casters_for(lf, kind) {
            let Some(eq) = &c.edge_quad else {
                for dr in c.draws.iter() {
                    // SAFETY: the caller's contract.
                    unsafe { self.record_planned_draw(cb, frame, kind, c, dr, bound) };
                }
                continue;
            };
            let (faces, sides) = match (kind, p.count.as_ref()) {
                (VolumeKind::Stencil, _) => (p.stencil.eq_faces, p.stencil.eq_sides),
                (VolumeKind::Rasterised, _) => (p.raster.edge_quads, p.raster.edge_quads),
                (VolumeKind::Float, Some(cp)) => (cp.eq_faces, cp.eq_sides),
                _ => continue,
            };
            // SAFETY: the caller's contract; push constants match the pipeline layout.
            unsafe { self.push(cb, c, color(c, c.case)) };
            let d = &self.dev.device;
            // SAFETY: as above; the buffers live until the slot retires.
            unsafe {
                d.cmd_bind_vertex_buffers(cb, 0, &[eq.vertices], &[0]);
                d.cmd_bind_index_buffer(cb, eq.indices, 0, vk::IndexType::UINT32);
                d.cmd_bind_pipeline(cb, vk::PipelineBindPoint::GRAPHICS, faces);
                d.cmd_draw_indexed(cb, eq.face_indices, 1, 0, 0, 0);
                d.cmd_bind_pipeline(cb, vk::PipelineBindPoint::GRAPHICS, sides);
                d.cmd_draw_indexed(cb, eq.quad_indices, 1, eq.face_indices, 0, 0);
            }
            *bound = Bound { pipeline: sides, pushed: None };
        }
    }
}
