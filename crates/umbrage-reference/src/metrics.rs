//! Comparing a GPU shadow mask with the reference.
//!
//! Mask values: 255 lit, 0 not lit, 128 background (other values are read as the nearest
//! of the three). The *band* is every pixel within `N` pixels (Chebyshev distance) of
//! * a reference shadow edge: a pixel whose lit/not-lit state differs from a 4-neighbour's,
//!   a terminator pixel (facing the light differs from a 4-neighbour's: see
//!   [`shadow_edges`]), or an Ambiguous pixel, or
//! * a geometric discontinuity between 4-neighbours: different meshes (when known), one of
//!   them background, normals more than 30° apart, or a depth (distance to the camera) jump
//!   of more than 10% of the smaller depth.
//!
//! Ambiguous reference pixels are counted apart and never as mismatches.
//! `fraction_outside_band = mismatches_outside_band / compared`, where `compared` counts
//! pixels where the reference or the mask is not background and the reference is not
//! Ambiguous.

use super::{LightState, RefImage};
use glam::DVec3;
use umbrage::error::{Error, Result};

/// Comparison of one light's GPU mask with the reference.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct Metrics {
    /// W*H.
    pub pixels: u64,
    /// Pixels compared (see the module docs): the denominator of `fraction_outside_band`.
    pub compared: u64,
    /// Background in exactly one of mask and reference.
    pub background_mismatch: u64,
    /// GPU lit, reference not lit.
    pub lit_but_ref_shadowed: u64,
    /// GPU not lit, reference lit.
    pub shadowed_but_ref_lit: u64,
    /// All three kinds of mismatch above, outside the band.
    pub mismatches_outside_band: u64,
    /// Reference Ambiguous pixels (skipped).
    pub ambiguous: u64,
    /// Pixels in the band.
    pub band_pixels: u64,
    /// `mismatches_outside_band / compared` (0 when nothing was compared).
    pub fraction_outside_band: f64,
}

/// What a pixel sees, for the discontinuity part of the band.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum GeoSample {
    /// The ray hits nothing.
    Background,
    /// The ray hits a surface.
    Surface {
        /// World position of the hit.
        position: DVec3,
        /// Unit geometric normal there.
        normal: DVec3,
        /// Distance from the eye.
        depth: f64,
        /// Index of the scene mesh hit, when known.
        mesh: Option<u32>,
    },
}

/// Normal change above which neighbours are a discontinuity (degrees).
pub const NORMAL_JUMP_DEG: f64 = 30.0;
/// Relative depth change above which neighbours are a discontinuity.
pub const DEPTH_JUMP_REL: f64 = 0.1;

fn discontinuous(a: &GeoSample, b: &GeoSample) -> bool {
    match (a, b) {
        (GeoSample::Background, GeoSample::Background) => false,
        (GeoSample::Background, _) | (_, GeoSample::Background) => true,
        (GeoSample::Surface { normal: na, depth: da, mesh: ma, .. }, GeoSample::Surface { normal: nb, depth: db, mesh: mb, .. }) => {
            if let (Some(x), Some(y)) = (ma, mb) {
                if x != y {
                    return true;
                }
            }
            let (na, nb) = (na.normalize_or_zero(), nb.normalize_or_zero());
            if na.dot(nb) < NORMAL_JUMP_DEG.to_radians().cos() {
                return true;
            }
            let jump = (da - db).abs();
            jump.is_nan() || jump > DEPTH_JUMP_REL * da.min(*db)
        }
    }
}

/// Pixels on a geometric discontinuity (both pixels of a discontinuous 4-neighbour pair).
pub fn geometry_edges(geo: &[GeoSample], w: usize, h: usize) -> Vec<bool> {
    pair_edges(w, h, |i, j| discontinuous(&geo[i], &geo[j]))
}

/// Pixels on a reference shadow edge (lit-ness differs from a 4-neighbour's), on a terminator
/// (facing the light differs from a 4-neighbour's, even where both are unlit) or Ambiguous.
///
/// The terminator is an edge because a shadow volume's side faces start there: the faces
/// extruded from the visible triangle's own silhouette edges leave the surface at the
/// grazing angle of the light, so a pixel next to the terminator lies within `cos * footprint`
/// of a volume face, which a depth buffer cannot resolve (the same reason the pixels along
/// a cast shadow's edge are in the band). A self-shadowed pixel there may read lit.
pub fn shadow_edges(states: &[LightState], w: usize, h: usize) -> Vec<bool> {
    let differ = |a: Option<bool>, b: Option<bool>| matches!((a, b), (Some(a), Some(b)) if a != b);
    let mut e = pair_edges(w, h, |i, j| {
        let (a, b) = (states[i], states[j]);
        differ(a.lit(), b.lit()) || differ(a.faces_light(), b.faces_light())
    });
    for (i, s) in states.iter().enumerate() {
        if *s == LightState::Ambiguous {
            e[i] = true;
        }
    }
    e
}

fn pair_edges(w: usize, h: usize, differ: impl Fn(usize, usize) -> bool) -> Vec<bool> {
    let mut e = vec![false; w * h];
    for y in 0..h {
        for x in 0..w {
            let i = y * w + x;
            if x + 1 < w && differ(i, i + 1) {
                e[i] = true;
                e[i + 1] = true;
            }
            if y + 1 < h && differ(i, i + w) {
                e[i] = true;
                e[i + w] = true;
            }
        }
    }
    e
}

/// Dilates `mask` by `n` pixels (Chebyshev distance), O(W*H).
pub fn dilate(mask: &[bool], w: usize, h: usize, n: u32) -> Vec<bool> {
    let n = n as usize;
    if n == 0 {
        return mask.to_vec();
    }
    let run = |get: &dyn Fn(usize) -> bool, len: usize, out: &mut dyn FnMut(usize, bool)| {
        // prefix counts
        let mut pre = vec![0u32; len + 1];
        for k in 0..len {
            pre[k + 1] = pre[k] + get(k) as u32;
        }
        for k in 0..len {
            let lo = k.saturating_sub(n);
            let hi = (k + n + 1).min(len);
            out(k, pre[hi] > pre[lo]);
        }
    };
    let mut tmp = vec![false; w * h];
    for y in 0..h {
        run(&|x| mask[y * w + x], w, &mut |x, v| tmp[y * w + x] = v);
    }
    let mut out = vec![false; w * h];
    for x in 0..w {
        run(&|y| tmp[y * w + x], h, &mut |y, v| out[y * w + x] = v);
    }
    out
}

/// The band: shadow edges of `states` plus `geo_edges`, dilated by `n`.
pub fn band_mask(states: &[LightState], geo_edges: &[bool], w: usize, h: usize, n: u32) -> Vec<bool> {
    let mut e = shadow_edges(states, w, h);
    for (a, b) in e.iter_mut().zip(geo_edges) {
        *a |= *b;
    }
    dilate(&e, w, h, n)
}

#[derive(Clone, Copy, PartialEq, Eq)]
enum MaskValue {
    Lit,
    Unlit,
    Background,
}

fn classify(v: u8) -> MaskValue {
    if v >= 192 {
        MaskValue::Lit
    } else if v < 64 {
        MaskValue::Unlit
    } else {
        MaskValue::Background
    }
}

/// The pixels whose mask value disagrees with the reference outside the band (the ones
/// [`compare_states`] counts in `mismatches_outside_band`), in row order, at most `limit`.
pub fn mismatches_outside_band(mask: &[u8], states: &[LightState], band: &[bool], limit: usize) -> Vec<usize> {
    (0..states.len())
        .filter(|&i| !band[i] && compare_states(&mask[i..=i], &states[i..=i], &[false]).mismatches_outside_band == 1)
        .take(limit)
        .collect()
}

/// Compares a mask with reference states given a precomputed band (all the same length).
pub fn compare_states(mask: &[u8], states: &[LightState], band: &[bool]) -> Metrics {
    let mut m = Metrics { pixels: states.len() as u64, ..Metrics::default() };
    for i in 0..states.len() {
        let in_band = band[i];
        m.band_pixels += in_band as u64;
        let r = states[i];
        let g = classify(mask[i]);
        let ref_bg = r == LightState::Background;
        let gpu_bg = g == MaskValue::Background;
        if ref_bg && gpu_bg {
            continue;
        }
        if r == LightState::Ambiguous {
            m.ambiguous += 1;
            continue;
        }
        m.compared += 1;
        let mismatch = if ref_bg != gpu_bg {
            m.background_mismatch += 1;
            true
        } else {
            let ref_lit = r == LightState::Lit;
            let gpu_lit = g == MaskValue::Lit;
            if gpu_lit && !ref_lit {
                m.lit_but_ref_shadowed += 1;
            } else if !gpu_lit && ref_lit {
                m.shadowed_but_ref_lit += 1;
            }
            gpu_lit != ref_lit
        };
        if mismatch && !in_band {
            m.mismatches_outside_band += 1;
        }
    }
    m.fraction_outside_band = if m.compared == 0 { 0.0 } else { m.mismatches_outside_band as f64 / m.compared as f64 };
    m
}

/// The geometric samples of a reference rendering's pixels (mesh ids known).
pub fn geo_samples(pixels: &[super::RefPixel]) -> Vec<GeoSample> {
    pixels
        .iter()
        .map(|p| {
            if p.hit {
                GeoSample::Surface {
                    position: p.position.as_dvec3(),
                    normal: p.normal.as_dvec3(),
                    depth: p.depth as f64,
                    mesh: Some(p.mesh),
                }
            } else {
                GeoSample::Background
            }
        })
        .collect()
}

/// Checks that a GPU image of `len` pixels and light index `light` fit a `w` x `h` reference
/// with `light_count` lights.
pub fn check_sizes(what: &str, len: usize, w: usize, h: usize, light: usize, light_count: usize) -> Result<()> {
    if len != w * h {
        return Err(Error::input(what, format!("{what} has {len} pixels, reference {w}x{h} has {}", w * h)));
    }
    if light >= light_count {
        return Err(Error::input(what, format!("light {light} but the reference has {light_count} lights")));
    }
    Ok(())
}

/// Compares the GPU mask of light `light` with a reference rendering, band of `band` pixels.
pub fn compare(mask: &[u8], image: &RefImage, light: usize, band: u32) -> Result<Metrics> {
    let (w, h) = (image.width as usize, image.height as usize);
    check_sizes("mask", mask.len(), w, h, light, image.light_count)?;
    let states = image.light_states(light);
    let geo = geometry_edges(&geo_samples(&image.pixels), w, h);
    let band = band_mask(&states, &geo, w, h, band);
    Ok(compare_states(mask, &states, &band))
}

/// [`compare`] for every light at once (`masks[k]` for light k).
pub fn compare_all(masks: &[Vec<u8>], image: &RefImage, band: u32) -> Result<Vec<Metrics>> {
    if masks.len() != image.light_count {
        return Err(Error::input("mask", format!("{} masks for {} lights", masks.len(), image.light_count)));
    }
    masks.iter().enumerate().map(|(k, m)| compare(m, image, k, band)).collect()
}
