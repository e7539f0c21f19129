//! Recording one frame: the paper's passes in order (section 8), one stage function each.

use super::{FrameSpans, Renderer};
use crate::counters::CounterPools;
use crate::options::*;
use crate::push::LightPush;
use crate::readback::Layout;
use crate::scene_gpu::Sidedness;
use crate::shadowmap::Lookup;
use crate::stages::{self, debug, determine, gbuffer, illuminate, intensity, samples, tonemap, transparent, Rec, SceneDraw};
use crate::technique::RenderTechnique;
use ash::vk;
use glam::Mat4;
use umbrage::error::Result;
use umbrage::pass::PreparedFrame;

/// What one frame's recording reads, besides the renderer's own objects.
pub(super) struct FrameInputs<'a> {
    /// The shadow pass's plans for this slot.
    pub frame: &'a PreparedFrame,
    /// Where the readback lands.
    pub layout: &'a Layout,
    /// This slot's instance buffer (the scene meshes' placement).
    pub instances: vk::Buffer,
    /// This slot's analytic sphere cubes (buffer, vertex count).
    pub spheres: Option<(vk::Buffer, u32)>,
    /// Eye-relative view-projection.
    pub vp_rel: Mat4,
    /// Per light, the lighting pass's push block.
    pub lights: &'a [LightPush],
    /// The count is in the float target.
    pub float_counts: bool,
    /// The counters' query pools (frames that measure them).
    pub counters: Option<&'a CounterPools>,
}

impl Renderer {
    /// The frame as McGuire et al. lay it out (section 8), one pass function each.
    pub(super) fn record_frame(&self, rec: &Rec, input: &FrameInputs) -> Result<FrameSpans> {
        let FrameInputs { frame, layout, instances, spheres, vp_rel, lights, float_counts, counters } = *input;
        let (t, p, pass) = (&self.own.parts.targets, &self.own.parts.pipes, &self.own.parts.pass);
        let sd = SceneDraw { t, p, geo: &self.own.parts.geo, instances, vp_rel, ambient: self.own.parts.scene.ambient };
        let stamp = |stage| rec.timer.stamp(rec.ctx, rec.cb, stage);
        let all = vk::PipelineStageFlags2::ALL_COMMANDS;
        let mut spans = FrameSpans::default();
        spans.frame.begin = stamp(vk::PipelineStageFlags2::TOP_OF_PIPE);
        // SAFETY: every pass records into `rec.cb` (recording, outside rendering instances
        // between passes) with this renderer's objects, alive until the slot retires; the
        // layouts each pass expects are those the previous pass leaves.
        unsafe {
            // The shadow pass's documented sequence, as any host calls it: what precedes
            // rendering (uploads, and the technique's GPU work: every light's silhouettes for
            // compute and mesh, the acceleration structures for ray query), then the depth
            // pass, then `cmd_determine` per light.
            pass.cmd_before_rendering(rec.cb, frame)?;
            let before = stages::timing_span(spans.frame.begin, stamp(all));
            match self.settings.technique {
                RenderTechnique::Pass(Technique::Compute | Technique::Mesh) => spans.silhouettes = before,
                RenderTechnique::Pass(Technique::RayQuery) => spans.accel = before,
                _ => (),
            }
            spans.depth.begin = before.end;
            gbuffer::record(rec, &sd, spheres);
            spans.depth.end = stamp(all);
            let into = match (&self.own.parts.shadow_mapper, self.settings.counter) {
                (Some(_), _) => determine::CountInto::External,
                (None, Counter::Float) => determine::CountInto::Float,
                (None, Counter::Stencil) => determine::CountInto::Stencil,
            };
            let pcf = self.settings.technique.shadow_map().map(|m| m.pcf).unwrap_or_default();
            for (li, light) in self.own.parts.scene.lights.iter().enumerate() {
                let begin = stamp(all);
                if let Some(c) = counters {
                    c.statistics(rec.ctx, rec.cb, li as u32, true);
                }
                if let Some((sm, _)) = &self.own.parts.shadow_mapper {
                    determine::begin_float(rec, t);
                    let maps = sm.record_maps(rec.ctx, rec.cb, light, self.own.parts.scene.camera.eye.as_dvec3());
                    spans.shadow_map.push(stages::timing_span(begin, stamp(all)));
                    let lookup = Lookup { light_pos: lights[li].light_pos, scissor: frame.lights[li].scissor, pcf };
                    sm.record_lookup(rec.ctx, rec.cb, t, &maps, lookup);
                }
                determine::record(rec, pass, frame, li, t, into)?;
                determine::finish(rec, t, p, into, layout.counts.get(li).copied())?;
                if let Some(c) = counters {
                    c.statistics(rec.ctx, rec.cb, li as u32, false);
                }
                spans.shadow.push(stages::timing_span(begin, stamp(all)));
                if let Some(c) = counters {
                    determine::record_count(rec, pass, frame, li, t, c)?;
                }
                if self.own.parts.has_transparent {
                    intensity::record(rec, pass, frame, li, t, self.settings.transmit_log, layout.transmit.get(li).copied())?;
                }
                let begin = stamp(all);
                let mode = illuminate::Lighting { float: float_counts, transmit: self.own.parts.has_transparent };
                illuminate::record(rec, pass, frame, li, &sd, mode, &lights[li])?;
                spans.illuminate.push(stages::timing_span(begin, stamp(all)));
            }
            if self.own.parts.geo.of(Sidedness::Transparent).next().is_some() {
                let forward = if self.own.parts.self_shadow.is_some() { &[][..] } else { lights };
                transparent::record(rec, &sd, forward);
                if let Some(ss) = &self.own.parts.self_shadow {
                    ss.record(rec, &sd, pass, frame, lights, self.settings.transmit_log)?;
                }
            }
            if self.settings.view == View::Volumes && frame.ray_query().is_none() {
                debug::record_volumes(rec, pass, frame, t)?;
            }
            tonemap::record(rec, t, p);
        }
        spans.frame.end = stamp(all);
        rec.copy_out(&t.output, vk::ImageAspectFlags::COLOR, vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL, layout.color);
        match (layout.positions, layout.normals) {
            (Some(pos), Some(nrm)) if t.samples > 1 => {
                // SAFETY: recording outside a rendering instance; the G-buffer is in shader-read
                // layout since its pass.
                unsafe {
                    samples::record(rec, t, p, samples::Source::Position, pos)?;
                    samples::record(rec, t, p, samples::Source::Normal, nrm)?;
                }
            }
            (Some(pos), Some(nrm)) => {
                rec.copy_out(&t.position, vk::ImageAspectFlags::COLOR, vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL, pos);
                rec.copy_out(&t.normal, vk::ImageAspectFlags::COLOR, vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL, nrm);
            }
            _ => {}
        }
        tonemap::host_barrier(rec);
        Ok(spans)
    }
}
