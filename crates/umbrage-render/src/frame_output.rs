//! What a frame produced ([`FrameOutput`]), parsed from the slot's readback buffer, and the
//! per-light shadow masks and light fractions the reference is compared with.

use super::readback::{Layout, Readback};
use super::stats::Stats;
use super::TransmitMode;
use glam::{DMat4, DVec3, DVec4, Vec3};
use umbrage::error::Result;
use umbrage_scene::Scene;

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
    /// A multisampled captured frame ([`RenderOptions::samples`] > 1): every sample's positions,
    /// normals and stencil counts, in Vulkan's standard sample order; `positions`, `normals`
    /// and `stencil` above are sample 0's. Empty for a single-sampled frame.
    ///
    /// [`RenderOptions::samples`]: crate::RenderOptions::samples
    pub samples: Vec<SampleOutput>,
    /// What the frame did (`--stats`).
    pub stats: Stats,
}

/// One sample of a multisampled captured frame: what [`FrameOutput`] has per pixel, at the
/// sample's own position in every pixel (Vulkan's standard sample locations).
#[derive(Clone, Debug, Default)]
pub struct SampleOutput {
    /// World position (NaN for background).
    pub positions: Vec<[f32; 3]>,
    /// Geometric face normal (NaN for background).
    pub normals: Vec<[f32; 3]>,
    /// Per light: the stencil count.
    pub stencil: Vec<Vec<u8>>,
}

impl FrameOutput {
    /// Per light: 255 where the light reaches the pixel (stencil count zero and the surface
    /// faces the light), 0 where it does not, 128 for background. Captured frames only.
    pub fn shadow_masks(&self, scene: &Scene) -> Vec<Vec<u8>> {
        shadow_masks(scene, &self.positions, &self.normals, |k, i| match self.counts.get(k) {
            Some(c) => c[i],
            None => self.stencil.get(k).map(|s| s[i] as i32).unwrap_or(0),
        })
    }

    /// The frame of sample `k` of a multisampled captured frame (colour and stats are the
    /// whole frame's, the rest is the sample's); `None` when there is no such sample.
    pub fn sample(&self, k: usize) -> Option<FrameOutput> {
        let s = self.samples.get(k)?;
        Some(FrameOutput {
            width: self.width,
            height: self.height,
            color: self.color.clone(),
            stencil: s.stencil.clone(),
            counts: Vec::new(),
            transmit: Vec::new(),
            positions: s.positions.clone(),
            normals: s.normals.clone(),
            samples: Vec::new(),
            stats: self.stats.clone(),
        })
    }
}

/// Per light: 255 where the light reaches the pixel (`count(light, pixel)` zero and the
/// surface faces the light), 0 where it does not, 128 for background.
fn shadow_masks(scene: &Scene, positions: &[[f32; 3]], normals: &[[f32; 3]], count: impl Fn(usize, usize) -> i32) -> Vec<Vec<u8>> {
    scene
        .lights
        .iter()
        .enumerate()
        .map(|(k, light)| {
            let l = light.homogeneous();
            positions
                .iter()
                .zip(normals)
                .enumerate()
                .map(|(i, (p, n))| {
                    let (p, n) = (Vec3::from(*p), Vec3::from(*n));
                    if !p.x.is_finite() {
                        return 128;
                    }
                    let to_light = if l.w == 0.0 { l.truncate() } else { l.truncate() - p };
                    let faces = n.dot(to_light) > 0.0;
                    if faces && light.reaches(p) && count(k, i) == 0 {
                        255
                    } else {
                        0
                    }
                })
                .collect()
        })
        .collect()
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
pub(crate) fn parse(
    rb: &Readback,
    layout: &Layout,
    float_counts: bool,
    transmit: Option<TransmitMode>,
    view: &CaptureView,
) -> Result<Captured> {
    let eye = view.eye;
    let color = rb.bytes(layout.color)?.to_vec();
    let mut c = Captured { color, ..Captured::default() };
    let (Some(pos_r), Some(nrm_r)) = (layout.positions, layout.normals) else { return Ok(c) };
    let n = layout.samples.max(1);
    if n > 1 {
        let standard = standard_sample_locations(n);
        for k in 0..n {
            let location = view.locations.get(k as usize).or(standard.get(k as usize)).copied().unwrap_or((0.5, 0.5));
            let mut s = SampleOutput::default();
            (s.positions, s.normals) = sample_geometry(rb.bytes(pos_r.sample(k, n))?, rb.bytes(nrm_r.sample(k, n))?, view, location);
            for &range in &layout.counts {
                s.stencil.push(rb.bytes(range.sample(k, n))?.to_vec());
            }
            c.samples.push(s);
        }
        if let Some(s0) = c.samples.first() {
            (c.positions, c.normals, c.stencil) = (s0.positions.clone(), s0.normals.clone(), s0.stencil.clone());
        }
        return Ok(c);
    }
    (c.positions, c.normals) = geometry(rb.bytes(pos_r)?, rb.bytes(nrm_r)?, eye);
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

/// World positions and normals (NaN for background) from the read-back eye-relative position
/// and normal targets (RGBA32F; w = 0 where nothing was drawn).
fn geometry(pos: &[u8], nrm: &[u8], eye: DVec3) -> (Vec<[f32; 3]>, Vec<[f32; 3]>) {
    let floats = |bytes: &[u8]| -> Vec<[f32; 4]> { bytemuck::pod_collect_to_vec::<u8, [f32; 4]>(bytes) };
    floats(pos)
        .iter()
        .zip(&floats(nrm))
        .map(|(p, n)| match p[3] == 0.0 {
            true => ([f32::NAN; 3], [f32::NAN; 3]),
            false => ((DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64) + eye).as_vec3().to_array(), [n[0], n[1], n[2]]),
        })
        .unzip()
}

/// What a captured frame's positions are recovered with: the eye, and for a multisampled frame
/// the frame's size, the inverse of its eye-relative view-projection and where each sample's
/// depth is evaluated.
pub(crate) struct CaptureView<'a> {
    pub eye: DVec3,
    /// Clip space to eye-relative space: the inverse, in f64, of the matrix the G-buffer pass
    /// projected with.
    pub clip_to_rel: DMat4,
    pub width: u32,
    pub height: u32,
    /// Per sample, where the device evaluates its depth (measured; the standard locations on
    /// a conformant device). Empty: the standard locations.
    pub locations: &'a [(f64, f64)],
}

/// Vulkan's standard sample locations (`standardSampleLocations`) of `samples` samples, in
/// pixel units from the pixel's top-left corner; the pixel centre for one sample.
pub fn standard_sample_locations(samples: u32) -> &'static [(f64, f64)] {
    match samples {
        2 => &[(0.75, 0.75), (0.25, 0.25)],
        4 => &[(0.375, 0.125), (0.875, 0.375), (0.125, 0.625), (0.625, 0.875)],
        8 => &[
            (0.5625, 0.3125),
            (0.4375, 0.6875),
            (0.8125, 0.5625),
            (0.3125, 0.1875),
            (0.1875, 0.8125),
            (0.0625, 0.4375),
            (0.6875, 0.9375),
            (0.9375, 0.0625),
        ],
        _ => &[(0.5, 0.5)],
    }
}

/// One sample's world positions and normals (NaN for background) from its read-back G-buffer
/// position (eye-relative, `w` = 0 where nothing was drawn) and face normal, at the sample's
/// location `(sx, sy)` (where the device evaluates the sample's depth, so where its depth and
/// stencil tests saw the surface): the ray from the eye through that location meets the
/// plane through the G-buffer's point with the face normal. The G-buffer shades once per
/// pixel (its point is the pixel's, on the sample's triangle; the analytic spheres' is the
/// sample's own ray's hit), and its f32 position is exact to about 1e-7 of the distance,
/// where the depth unprojected (1 - depth is about 5e-3 on the default scene's back wall: one
/// ulp there is 1.2e-5 of the distance) is not: SwiftShader's depth plane is off by up to
/// 2.6 ulps across the default scene's back wall, beyond the reference's surface offset
/// (2e-5 of the scene, about 2 ulps), which then called the wall's points behind it shadowed.
/// A ray within 1e-6 of the plane's direction (grazing) keeps the G-buffer's point.
fn sample_geometry(pos: &[u8], nrm: &[u8], view: &CaptureView, (sx, sy): (f64, f64)) -> (Vec<[f32; 3]>, Vec<[f32; 3]>) {
    let floats = |bytes: &[u8]| -> Vec<[f32; 4]> { bytemuck::pod_collect_to_vec::<u8, [f32; 4]>(bytes) };
    let (w, h) = (view.width as usize, view.height.max(1) as usize);
    floats(pos)
        .iter()
        .zip(&floats(nrm))
        .enumerate()
        .map(|(i, (p, n))| {
            if p[3] == 0.0 {
                return ([f32::NAN; 3], [f32::NAN; 3]);
            }
            let x = (i % w.max(1)) as f64 + sx;
            let y = (i / w.max(1)) as f64 + sy;
            // Any point of the sample's ray: the eye is the origin of eye-relative space.
            let clip = DVec4::new(2.0 * x / w as f64 - 1.0, 2.0 * y / h as f64 - 1.0, 0.5, 1.0);
            let r = view.clip_to_rel * clip;
            let dir = (r.truncate() / r.w).normalize_or_zero();
            let g = DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64);
            let normal = DVec3::new(n[0] as f64, n[1] as f64, n[2] as f64).normalize_or_zero();
            let facing = normal.dot(dir);
            let rel = if facing.abs() > 1e-6 { dir * (normal.dot(g) / facing) } else { g };
            ((rel + view.eye).as_vec3().to_array(), [n[0], n[1], n[2]])
        })
        .unzip()
}

/// What [`parse`] returns (see [`FrameOutput`] for each field).
#[derive(Default)]
pub(crate) struct Captured {
    pub samples: Vec<SampleOutput>,
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
