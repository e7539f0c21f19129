//! A finished frame's `--stats`: the pass's per-light plans and totals, GPU timestamps per
//! pass and light, CPU times, and which optional features ran.

use super::{FrameTicket, InFlight, Renderer};
use crate::options::{DepthMode, IndexFormat, TransmitMode};
use crate::stats::{GpuMs, LightGpuMs, RayQueryStats, Stats};
use umbrage::error::Result;

impl Renderer {
    /// The frame's `--stats`.
    pub(super) fn stats(&self, ticket: &FrameTicket, f: &InFlight) -> Result<Stats> {
        let ctx = &self.own.ctx;
        let caps = self.own.parts.pass.capabilities();
        let gpu_ms = match ctx.features.timestamps {
            true => {
                let raw = self.own.parts.slots[ticket.slot].timer.read(ctx)?;
                let p = ctx.features.timestamp_period_ns;
                let per_light: Vec<LightGpuMs> = f
                    .spans
                    .shadow
                    .iter()
                    .zip(&f.spans.illuminate)
                    .enumerate()
                    .map(|(li, (s, i))| LightGpuMs {
                        shadow: s.ms(&raw, p),
                        shadow_map: f.spans.shadow_map.get(li).map_or(0.0, |m| m.ms(&raw, p)),
                        illuminate: i.ms(&raw, p),
                    })
                    .collect();
                let silhouettes = f.spans.silhouettes.ms(&raw, p);
                Some(GpuMs {
                    depth: f.spans.depth.ms(&raw, p),
                    shadow: silhouettes + per_light.iter().map(|l| l.shadow).sum::<f64>(),
                    silhouettes,
                    illuminate: per_light.iter().map(|l| l.illuminate).sum(),
                    frame: f.spans.frame.ms(&raw, p),
                    accel: f.spans.accel.ms(&raw, p),
                    shadow_map: per_light.iter().map(|l| l.shadow_map).sum(),
                    per_light,
                })
            }
            false => None,
        };
        let accel_ms = gpu_ms.as_ref().map(|g| g.accel);
        let (mut features_used, mut features_missing) = (Vec::new(), Vec::new());
        let fe = &ctx.features;
        let u8_used = caps.index_type_uint8 && matches!(f.settings.index_format, IndexFormat::U8 | IndexFormat::Auto);
        for (name, has, used) in [
            ("depthClamp", fe.depth_clamp, self.own.parts.config.depth_mode == DepthMode::Clamp),
            ("depthBounds", caps.depth_bounds, caps.depth_bounds),
            ("indexTypeUint8", caps.index_type_uint8, u8_used),
            ("timestamps", fe.timestamps, fe.timestamps),
        ] {
            if used {
                features_used.push(name.to_string());
            } else if !has {
                features_missing.push(name.to_string());
            }
        }
        let mut cpu = f.frame.cpu_ms.clone();
        cpu.record += f.record_ms;
        Ok(Stats {
            device: ctx.info.name.clone(),
            method: f.settings.technique,
            depth_mode: self.own.parts.config.depth_mode,
            index_format: f.settings.index_format,
            counter: f.settings.counter,
            transmit: self
                .own
                .parts
                .has_transparent
                .then(|| TransmitMode { fp32: self.own.parts.config.transmit_fp32, log: f.settings.transmit_log }.name().into()),
            self_shadow: self.own.parts.self_shadow.is_some(),
            width: self.own.parts.config.width,
            height: self.own.parts.config.height,
            lights: f.frame.lights.iter().map(|l| l.stats.clone()).collect(),
            totals: f.frame.totals.clone(),
            cpu_ms: cpu,
            gpu_ms,
            wall_ms: f.wall.elapsed().as_secs_f64() * 1e3,
            features_used,
            features_missing,
            counters: match f.settings.counters {
                true => Some(self.own.parts.slots[ticket.slot].counters.read(ctx)?),
                false => None,
            },
            warnings: {
                let mut w = f.frame.warnings.clone();
                // A multisampled capture's positions rely on where depth is evaluated.
                if let (true, Some(defect)) = (f.settings.capture, &self.own.parts.depth_locations.defect) {
                    w.push(defect.clone());
                }
                w
            },
            ray_query: f.frame.ray_query().map(|r| {
                if let (true, Some(accel)) = (r.builds > 0, accel_ms) {
                    self.own.parts.blas_build_ms.set(accel);
                }
                RayQueryStats {
                    bottom_levels: r.instances,
                    bottom_level_bytes: r.bottom_level_bytes,
                    bottom_level_build_ms: self.own.parts.blas_build_ms.get(),
                    instances: r.instances,
                    offset: r.offset,
                    builds: r.builds,
                    refits: r.refits,
                    compactions: r.compactions,
                    batched: r.batched,
                }
            }),
            shadow_map: f.settings.technique.shadow_map(),
        })
    }
}
