//! What only umbrage's own renderer, bench and debug view need, kept off [`ShadowPass`]'s
//! core surface: the counting variants of the determination (fill measured under an
//! occlusion query, exact float counts past the 8-bit stencil) and the volume overlay. An
//! engine never needs them; a profiler or a debug view brings them in with
//! `use umbrage::pass::diagnostics::Diagnostics`.

use super::frame::PreparedFrame;
use super::record::Instance;
use super::stencil::VolumeKind;
use super::target::DepthStencilTarget;
use super::ShadowPass;
use crate::error::{Misuse, Result};
use crate::shadow::Case;
use ash::vk;

/// The diagnostic recordings of a [`ShadowPass`]; each has the contract of the core call
/// it mirrors, and returns the same typed errors.
pub trait Diagnostics {
    /// The counting variant of [`cmd_determine`](ShadowPass::cmd_determine): the same volumes of
    /// light `light` over the same scissor (and depth bounds), with depth and stencil tests
    /// always passing and nothing written. Wrapped by the host in an occlusion query
    /// (`VK_QUERY_CONTROL_PRECISE_BIT` with `occlusionQueryPrecise`), the query counts every
    /// fragment the determination rasterises: the stencil fill it costs. The image's contents
    /// are left as they are. Dynamic rendering only.
    ///
    /// # Safety
    /// As [`cmd_determine`](ShadowPass::cmd_determine) (the stencil aspect is loaded, not cleared).
    unsafe fn cmd_count_rasterised(
        &self,
        cb: vk::CommandBuffer,
        frame: &PreparedFrame,
        light: usize,
        target: &DepthStencilTarget,
    ) -> Result<()>;

    /// As [`cmd_determine`](ShadowPass::cmd_determine), but counting into `count` (an R32F image,
    /// [`COUNT_FORMAT`](super::COUNT_FORMAT), cleared to 0 inside the scissor): exact counts
    /// with no 8-bit wrap. The depth-stencil image is only read. Dynamic rendering only, and
    /// needs R32F blending ([`Capabilities::r32f_blend`](super::Capabilities)).
    ///
    /// # Safety
    /// As `cmd_determine`; in addition `count` is a view of an R32F image of the same size
    /// and sample count in `COLOR_ATTACHMENT_OPTIMAL` layout, whose earlier accesses the host
    /// made available.
    unsafe fn cmd_count_float(
        &self,
        cb: vk::CommandBuffer,
        frame: &PreparedFrame,
        light: usize,
        target: &DepthStencilTarget,
        count: vk::ImageView,
    ) -> Result<()>;

    /// Draws every light's volumes translucent, coloured by case (z-pass blue, z-fail red,
    /// z-fail with light cap green), light caps left out: the `--view volumes` debug overlay.
    ///
    /// # Safety
    /// `cb` is recording inside a rendering instance with one colour attachment of
    /// [`ShadowPassDesc::debug_color_format`](super::ShadowPassDesc) (the pass must have been
    /// created with it) and the depth-stencil image loaded, viewport and scissor set; the
    /// frame's uploads and GPU silhouettes were recorded; `frame` is live.
    unsafe fn cmd_draw_volume_overlay(&self, cb: vk::CommandBuffer, frame: &PreparedFrame) -> Result<()>;
}

impl Diagnostics for ShadowPass {
    unsafe fn cmd_count_rasterised(
        &self,
        cb: vk::CommandBuffer,
        frame: &PreparedFrame,
        light: usize,
        target: &DepthStencilTarget,
    ) -> Result<()> {
        self.light(frame, light)?;
        Self::volume_frame(frame, "cmd_count_rasterised")?;
        self.dynamic_only("cmd_count_rasterised")?;
        target.check(frame, &self.desc.target)?;
        // SAFETY: the caller's contract (outside a rendering instance).
        unsafe {
            self.cmd_before_rendering(cb, frame)?;
            self.cmd_volume_instance(
                cb,
                frame,
                light,
                target,
                Instance { stencil: (vk::AttachmentLoadOp::LOAD, 0), color: None, kind: VolumeKind::Rasterised },
            )
        }
    }

    unsafe fn cmd_count_float(
        &self,
        cb: vk::CommandBuffer,
        frame: &PreparedFrame,
        light: usize,
        target: &DepthStencilTarget,
        count: vk::ImageView,
    ) -> Result<()> {
        let start = self.light(frame, light)?.counter_clear as f32;
        if self.pipes.count.is_none() {
            return Err(
                Misuse::NotConfigured { call: "cmd_count_float", needs: "R32_SFLOAT blending and TargetModel::DynamicRendering" }.into()
            );
        }
        // SAFETY: forwarded contract.
        unsafe { self.cmd_counted_instance(cb, frame, light, target, (count, [start, 0.0, 0.0, 0.0]), VolumeKind::Float) }
    }

    unsafe fn cmd_draw_volume_overlay(&self, cb: vk::CommandBuffer, frame: &PreparedFrame) -> Result<()> {
        self.check_frame(frame)?;
        Self::volume_frame(frame, "cmd_draw_volume_overlay")?;
        let Some(pipe) = self.pipes.overlay else {
            return Err(Misuse::NotConfigured { call: "cmd_draw_volume_overlay", needs: "ShadowPassDesc::debug_color_format" }.into());
        };
        let mut bound = vk::Pipeline::null();
        for lf in &frame.lights {
            for c in lf.casters.iter().filter(|c| c.case != Case::Culled) {
                for dr in c.draws.iter().filter(|dr| !dr.light_cap) {
                    let color = match dr.case {
                        Case::Culled => continue,
                        Case::ZPass => [0.2f32, 0.4, 1.0, 0.12],
                        Case::ZFail => [1.0, 0.3, 0.2, 0.12],
                        Case::ZFailLightCap => [0.1, 1.0, 0.2, 0.12],
                    };
                    if let Some(md) = &dr.mesh {
                        // Technique::Mesh: the mesh pipelines' overlay, the same colours
                        let Some(mesh_pipe) = self.mesh_set(frame)?.overlay else {
                            return Err(Misuse::NotConfigured {
                                call: "cmd_draw_volume_overlay",
                                needs: "ShadowPassDesc::debug_color_format",
                            }
                            .into());
                        };
                        // SAFETY: the caller's contract.
                        unsafe { self.record_mesh(cb, frame, mesh_pipe, c, md, color)? };
                        bound = mesh_pipe;
                        continue;
                    }
                    // SAFETY: the caller's contract.
                    unsafe {
                        if bound != pipe {
                            self.dev.device.cmd_bind_pipeline(cb, vk::PipelineBindPoint::GRAPHICS, pipe);
                            bound = pipe;
                        }
                        self.push(cb, c, color);
                        self.record_draw(cb, frame, dr);
                    }
                }
            }
        }
        Ok(())
    }
}
