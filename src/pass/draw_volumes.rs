//! `cmd_draw_volumes`: one light's volumes, recorded by the frame's technique. The CPU-planned
//! volumes and planar shadows draw their lists here (`volumes.rs`' `record_planned_draw`),
//! edge quads in `edge_quads.rs`, mesh draws in `mesh_record.rs`, the compute technique's in
//! `compute/draws_record.rs`; the light is handed over once (an enum match: nothing per draw).

use super::desc::Technique;
use super::frame::PreparedFrame;
use super::stencil::VolumeKind;
use super::volumes::{casters_for, Bound};
use super::ShadowPass;
use crate::error::{Misuse, Result};
use ash::vk;

impl ShadowPass {
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
        // Each technique records its own draws; what the CPU planned (every technique's
        // volumes, or the parts it leaves to the CPU) goes through `record_planned_draw`.
        let mut bound = Bound::default();
        match frame.settings.technique {
            Technique::Volumes(_) | Technique::Planar => {
                for c in casters_for(lf, kind) {
                    for dr in c.draws.iter() {
                        // SAFETY: the caller's contract; `kind` was checked above.
                        unsafe { self.record_planned_draw(cb, frame, kind, c, dr, &mut bound) };
                    }
                }
            }
            // SAFETY: as above.
            Technique::EdgeQuads => unsafe { self.record_edge_quads_light(cb, frame, lf, kind, &mut bound) },
            // SAFETY: as above.
            Technique::Compute => unsafe { self.record_compute_light(cb, frame, lf, light, kind, &mut bound)? },
            // SAFETY: as above.
            Technique::Mesh => unsafe { self.record_mesh_light(cb, frame, lf, kind, &mut bound)? },
            // refused by `volume_frame` above: a ray-query frame has no volumes
            Technique::RayQuery => {}
        }
        Ok(())
    }
}
