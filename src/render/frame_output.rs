//! What a frame produced ([`FrameOutput`]), parsed from the slot's readback buffer, and the
//! per-light shadow masks and light fractions the reference is compared with.

use super::readback::{Layout, Readback};
use super::stats::Stats;
use super::TransmitMode;
use crate::error::Result;
use crate::scene::Scene;
use glam::{DVec3, Vec3};

/// What a frame produced.
pub struct FrameOutput {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// sRGB RGBA8, row-major from the top-left.
    pub color: Vec<u8>,
    /// Per light: stencil count after its determination (captured frames only; with the float
    /// counter, the exact count clamped to 0..=255).
    pub stencil: Vec<Vec<u8>>,
    /// Per light: the exact signed count (float counter, captured frames only).
    pub counts: Vec<Vec<i32>>,
    /// Per light: the transparent casters' light fraction reaching each pixel (scenes with
    /// transparent casters, captured frames only).
    pub transmit: Vec<Vec<[f32; 3]>>,
    /// World position per pixel (NaN for background), captured frames only.
    pub positions: Vec<[f32; 3]>,
    /// Geometric face normal per pixel (NaN for background), captured frames only.
    pub normals: Vec<[f32; 3]>,
    /// What the frame did (`--stats`).
    pub stats: Stats,
}

impl FrameOutput {
    /// Per light: 255 where the light reaches the pixel (stencil count zero and the surface
    /// faces the light), 0 where it does not, 128 for background. Captured frames only.
    pub fn shadow_masks(&self, scene: &Scene) -> Vec<Vec<u8>> {
        scene
            .lights
            .iter()
            .enumerate()
            .map(|(k, light)| {
                let l = light.homogeneous();
                (0..(self.width * self.height) as usize)
                    .map(|i| {
                        let p = Vec3::from(self.positions[i]);
                        let n = Vec3::from(self.normals[i]);
                        if !p.x.is_finite() {
                            return 128;
                        }
                        let to_light = if l.w == 0.0 { l.truncate() } else { l.truncate() - p };
                        let faces = n.dot(to_light) > 0.0;
                        let count = match self.counts.get(k) {
                            Some(c) => c[i],
                            None => self.stencil.get(k).map(|s| s[i] as i32).unwrap_or(0),
                        };
                        if faces && light.reaches(p) && count == 0 {
                            255
                        } else {
                            0
                        }
                    })
                    .collect()
            })
            .collect()
    }
}

impl FrameOutput {
    /// Per light, per pixel: the RGB fraction of the light that reaches the visible surface:
    /// 0 where an opaque caster shadows it (or it faces away, or is out of range / cone), the
    /// transparent casters' transmittance otherwise (1 without them); NaN for background.
    pub fn light_fractions(&self, scene: &Scene) -> Vec<Vec<[f32; 3]>> {
        self.shadow_masks(scene)
            .iter()
            .enumerate()
            .map(|(k, mask)| {
                mask.iter()
                    .enumerate()
                    .map(|(i, &m)| match m {
                        128 => [f32::NAN; 3],
                        0 => [0.0; 3],
                        _ => self.transmit.get(k).map(|t| t[i]).unwrap_or([1.0; 3]),
                    })
                    .collect()
            })
            .collect()
    }
}

/// Parses a frame's readback (colour always; the rest when captured). Positions come back
/// eye-relative (NaN where nothing was drawn) and are made world-space in f64.
pub(crate) fn parse(rb: &Readback, layout: &Layout, float_counts: bool, transmit: Option<TransmitMode>, eye: DVec3) -> Result<Captured> {
    let color = rb.bytes(layout.color)?.to_vec();
    let mut c = Captured { color, ..Captured::default() };
    let (Some(pos_r), Some(nrm_r)) = (layout.positions, layout.normals) else { return Ok(c) };
    let floats = |bytes: &[u8]| -> Vec<[f32; 4]> { bytemuck::pod_collect_to_vec::<u8, [f32; 4]>(bytes) };
    let pos = floats(rb.bytes(pos_r)?);
    let nrm = floats(rb.bytes(nrm_r)?);
    for (p, n) in pos.iter().zip(&nrm) {
        if p[3] == 0.0 {
            c.positions.push([f32::NAN; 3]);
            c.normals.push([f32::NAN; 3]);
        } else {
            let wp = DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64) + eye;
            c.positions.push(wp.as_vec3().to_array());
            c.normals.push([n[0], n[1], n[2]]);
        }
    }
    for (li, &range) in layout.counts.iter().enumerate() {
        let raw = rb.bytes(range)?;
        if float_counts {
            let counts: Vec<i32> = bytemuck::pod_collect_to_vec::<u8, f32>(raw).iter().map(|v| v.round() as i32).collect();
            c.stencil.push(counts.iter().map(|&v| v.clamp(0, 255) as u8).collect());
            c.counts.push(counts);
        } else {
            c.stencil.push(raw.to_vec());
        }
        if let (Some(mode), Some(&tr)) = (transmit, layout.transmit.get(li)) {
            let raw = rb.bytes(tr)?;
            let texel = if mode.fp32 { 16 } else { 8 };
            let map: Vec<[f32; 3]> = raw
                .chunks_exact(texel)
                .map(|px| {
                    let ch = |k: usize| {
                        if mode.fp32 {
                            f32::from_le_bytes([px[4 * k], px[4 * k + 1], px[4 * k + 2], px[4 * k + 3]])
                        } else {
                            f16_to_f32(u16::from_le_bytes([px[2 * k], px[2 * k + 1]]))
                        }
                    };
                    let v = [ch(0), ch(1), ch(2)];
                    if mode.log {
                        v.map(f32::exp)
                    } else {
                        v
                    }
                })
                .collect();
            c.transmit.push(map);
        }
    }
    Ok(c)
}

/// What [`parse`] returns (see [`FrameOutput`] for each field).
#[derive(Default)]
pub(crate) struct Captured {
    pub color: Vec<u8>,
    pub positions: Vec<[f32; 3]>,
    pub normals: Vec<[f32; 3]>,
    pub stencil: Vec<Vec<u8>>,
    pub counts: Vec<Vec<i32>>,
    pub transmit: Vec<Vec<[f32; 3]>>,
}

/// IEEE half to single precision (readback of RGBA16F targets).
fn f16_to_f32(h: u16) -> f32 {
    let sign = if h & 0x8000 != 0 { -1.0f32 } else { 1.0 };
    let exp = ((h >> 10) & 0x1f) as i32;
    let mant = (h & 0x3ff) as f32;
    match exp {
        0 => sign * mant * 2f32.powi(-24),
        31 => {
            if mant == 0.0 {
                sign * f32::INFINITY
            } else {
                f32::NAN
            }
        }
        e => sign * (1.0 + mant / 1024.0) * 2f32.powi(e - 15),
    }
}
