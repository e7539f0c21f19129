//! Soft shadows of area lights ([`umbrage::geom::area`]): the fraction of the light's area a
//! surface point sees, with many shadow rays, as the ground truth the renderer's jittered point
//! lights are measured against.
//!
//! The visible fraction at `p` (normal `n`) is `V(p) = (1/A) ∫ v(p, y) dA(y)` over the light,
//! where `v(p, y) = 1` when `y` is in front of the surface (`n·(y - p) > 0`), within the
//! light's range, and no opaque caster lies between `p` and `y`. It is estimated with `rays`
//! rays per pixel through a jittered stratified pattern over the light's area (equal-area
//! cells, Shirley and Chiu's concentric map for a disc), its jitter re-drawn for every pixel from
//! a seed unrelated to the renderer's patterns: the estimate's error is noise of about
//! `rays^-3/4` at penumbra edges, never the structured error of a fixed set of points.
//! [`area_error`] compares a GPU light fraction (the mean of its samples' hard-shadow masks,
//! [`sample_fraction`]) with it.

use super::shade::par_rows;
use super::{RefPixel, Reference};
use glam::DVec3;
use umbrage::geom::area::{mix64, stratified_square};
use umbrage_scene::{Camera, Light};

/// Shadow rays per pixel the docs and tests use by default.
pub const DEFAULT_RAYS: u32 = 256;

/// The reference soft shadow of one area light.
#[derive(Clone, Debug)]
pub struct AreaImage {
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// Per pixel, the visible fraction of the light (0..1); NaN for background.
    pub fraction: Vec<f32>,
    /// The visible surface of every pixel.
    pub pixels: Vec<RefPixel>,
    /// Shadow rays per pixel.
    pub rays: u32,
}

/// The error of a GPU light fraction against an [`AreaImage`].
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct AreaMetrics {
    /// Pixels compared: surface in both, outside the band around geometric discontinuities.
    pub compared: u64,
    /// Pixels that are background in exactly one of them (not compared).
    pub background_mismatch: u64,
    /// Mean |GPU - reference| of the light fraction over the compared pixels.
    pub mean_abs_error: f64,
    /// Root mean square error over the compared pixels.
    pub rms_error: f64,
    /// Largest |GPU - reference|.
    pub max_abs_error: f64,
    /// Compared pixels in the reference penumbra (fraction in (0.02, 0.98)).
    pub penumbra: u64,
    /// Mean |GPU - reference| over the penumbra pixels.
    pub penumbra_mean_abs_error: f64,
    /// The threshold of `over_threshold`.
    pub threshold: f64,
    /// Fraction of the compared pixels with |GPU - reference| > `threshold`.
    pub over_threshold: f64,
}

impl Reference {
    /// The visible fraction of area light `light` from surface point `p` with normal `n` (the
    /// visible side's; need not be unit), with `rays` stratified shadow rays jittered by `seed`.
    /// A light without `area` is treated as the point at its position (0 or 1).
    pub fn area_fraction(&self, p: DVec3, n: DVec3, light: &Light, rays: u32, seed: u64) -> f64 {
        let n = n.normalize_or_zero();
        let centre = light.position.as_dvec3();
        let Some(area) = light.area else { return self.point_visible(p, n, light, centre) as u8 as f64 };
        let pts = stratified_square(rays.max(1), seed);
        let lit = pts.iter().filter(|&&uv| self.point_visible(p, n, light, area.point(centre, uv))).count();
        lit as f64 / pts.len() as f64
    }

    /// Whether the light point `y` reaches surface point `p` (unit normal `n`): in front of the
    /// surface, within `light.radius`, and no opaque caster in between.
    fn point_visible(&self, p: DVec3, n: DVec3, light: &Light, y: DVec3) -> bool {
        let d = y - p;
        if n.dot(d) <= 0.0 || light.radius.is_some_and(|r| d.length() >= r as f64) {
            return false;
        }
        let off = self.tolerance.surface_offset_rel * self.scale;
        let o = p + n * off;
        let to = y - o;
        let dist = to.length();
        if !(dist > off) {
            return false;
        }
        !self.occluders.any_hit(o, to / dist, 0.0, dist - off, |t| self.filter(t) != [0.0; 3])
    }

    /// The reference soft shadow of `light` seen by `camera`, `rays` shadow rays per pixel.
    pub fn render_area(&self, camera: &Camera, light: &Light, width: u32, height: u32, rays: u32) -> AreaImage {
        let w = width as usize;
        let rows = par_rows(height as usize, |y| {
            let mut px = Vec::with_capacity(w);
            let mut fr = Vec::with_capacity(w);
            for x in 0..w {
                match self.surface_at_pixel(camera, x as u32, y as u32, width, height) {
                    None => {
                        px.push(RefPixel::BACKGROUND);
                        fr.push(f32::NAN);
                    }
                    Some((pixel, p, n, _)) => {
                        px.push(pixel);
                        let seed = mix64(0x0A8E_A000_0000_0000 ^ (y * w + x) as u64);
                        fr.push(self.area_fraction(p, n, light, rays, seed) as f32);
                    }
                }
            }
            (px, fr)
        });
        let (mut pixels, mut fraction) = (Vec::with_capacity(w * height as usize), Vec::with_capacity(w * height as usize));
        for (p, f) in rows {
            pixels.extend(p);
            fraction.extend(f);
        }
        AreaImage { width, height, fraction, pixels, rays }
    }
}

/// The GPU light fraction of a light rendered as samples `masks` (their shadow masks: 255 lit,
/// 0 not, 128 background): per pixel the fraction of the samples that reach it, NaN where
/// every mask says background.
pub fn sample_fraction(masks: &[Vec<u8>]) -> Vec<f32> {
    let len = masks.first().map(|m| m.len()).unwrap_or(0);
    (0..len)
        .map(|i| {
            let (mut lit, mut any) = (0u32, false);
            for m in masks {
                let v = m[i];
                any |= !(64..192).contains(&v);
                lit += (v >= 192) as u32;
            }
            if any {
                lit as f32 / masks.len() as f32
            } else {
                f32::NAN
            }
        })
        .collect()
}

/// Compares GPU light fraction `gpu` (NaN background) with the reference, leaving out a band
/// of `band` pixels around geometric discontinuities (silhouettes, creases, depth jumps: where
/// the two may see different surfaces); `threshold` for [`AreaMetrics::over_threshold`].
pub fn area_error(gpu: &[f32], reference: &AreaImage, band: u32, threshold: f64) -> umbrage::error::Result<AreaMetrics> {
    use super::metrics::{dilate, geo_samples, geometry_edges};
    let (w, h) = (reference.width as usize, reference.height as usize);
    if gpu.len() != w * h {
        return Err(umbrage::error::Error::input("light fraction", format!("{} pixels, reference {w}x{h}", gpu.len())));
    }
    let edges = dilate(&geometry_edges(&geo_samples(&reference.pixels), w, h), w, h, band);
    let mut m = AreaMetrics { threshold, ..AreaMetrics::default() };
    let (mut sum, mut sq, mut pen_sum, mut over) = (0.0, 0.0, 0.0, 0u64);
    for i in 0..w * h {
        let (g, r) = (gpu[i], reference.fraction[i]);
        match (g.is_nan(), r.is_nan()) {
            (true, true) => continue,
            (true, false) | (false, true) => {
                m.background_mismatch += 1;
                continue;
            }
            _ => {}
        }
        if edges[i] {
            continue;
        }
        let e = (g as f64 - r as f64).abs();
        m.compared += 1;
        sum += e;
        sq += e * e;
        m.max_abs_error = m.max_abs_error.max(e);
        over += (e > threshold) as u64;
        if r > 0.02 && r < 0.98 {
            m.penumbra += 1;
            pen_sum += e;
        }
    }
    let n = m.compared.max(1) as f64;
    m.mean_abs_error = sum / n;
    m.rms_error = (sq / n).sqrt();
    m.over_threshold = over as f64 / n;
    m.penumbra_mean_abs_error = pen_sum / m.penumbra.max(1) as f64;
    Ok(m)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::TriFlags;
    use glam::Vec3;
    use umbrage::geom::area::{AreaLight, AreaShape};
    use umbrage_scene::LightKind;

    /// A unit-square occluder at height 1 over x in [0, 1]: half of a light centred above
    /// x = 0 is hidden from the origin.
    fn half_plane() -> Reference {
        let big = 50.0;
        let tris = vec![
            [DVec3::new(0.0, 1.0, -big), DVec3::new(big, 1.0, -big), DVec3::new(big, 1.0, big)],
            [DVec3::new(0.0, 1.0, -big), DVec3::new(big, 1.0, big), DVec3::new(0.0, 1.0, big)],
        ];
        let f = TriFlags { visible: true, occluder: true, mesh: 0 };
        Reference::new(tris, &[f, f])
    }

    fn area_light(shape: AreaShape) -> Light {
        Light {
            kind: LightKind::Point,
            position: Vec3::new(0.0, 2.0, 0.0),
            direction: Vec3::NEG_Y,
            color: Vec3::ONE,
            intensity: 1.0,
            radius: None,
            cone_deg: 45.0,
            area: Some(AreaLight::new(shape, Vec3::NEG_Y, 1)),
        }
    }

    #[test]
    fn half_covered_lights_are_half_visible() {
        let r = half_plane();
        for shape in [AreaShape::Disc { radius: 0.5 }, AreaShape::Rect { width: 1.0, height: 0.6 }] {
            let l = area_light(shape);
            let v = r.area_fraction(DVec3::ZERO, DVec3::Y, &l, 1024, 5);
            assert!((v - 0.5).abs() < 0.02, "{shape:?}: {v}");
            // Far to the side: all visible; behind the surface: nothing.
            assert_eq!(r.area_fraction(DVec3::new(-5.0, 0.0, 0.0), DVec3::Y, &l, 64, 1), 1.0);
            assert_eq!(r.area_fraction(DVec3::new(-5.0, 0.0, 0.0), DVec3::NEG_Y, &l, 64, 1), 0.0);
        }
        // Without an area, the point light at the centre (exactly on the occluder's edge line:
        // move it off).
        let mut p = area_light(AreaShape::Disc { radius: 0.5 });
        p.area = None;
        p.position.x = -0.1;
        assert_eq!(r.area_fraction(DVec3::ZERO, DVec3::Y, &p, 64, 1), 1.0);
    }

    #[test]
    fn sample_fractions_and_errors() {
        let masks = vec![vec![255, 0, 128], vec![0, 0, 128]];
        let f = sample_fraction(&masks);
        assert_eq!(&f[..2], &[0.5, 0.0]);
        assert!(f[2].is_nan());
        let reference = AreaImage {
            width: 3,
            height: 1,
            fraction: vec![0.5, 0.25, f32::NAN],
            pixels: vec![RefPixel { hit: true, position: Vec3::ZERO, normal: Vec3::Y, depth: 1.0, mesh: 0, tri: 0 }; 3],
            rays: 1,
        };
        let m = area_error(&f, &reference, 0, 0.1).unwrap();
        assert_eq!(m.compared, 2);
        assert!((m.mean_abs_error - 0.125).abs() < 1e-9 && (m.max_abs_error - 0.25).abs() < 1e-9);
        assert_eq!(m.over_threshold, 0.5);
        assert_eq!(m.penumbra, 2);
        assert!(area_error(&f[..2], &reference, 0, 0.1).is_err());
    }
}
