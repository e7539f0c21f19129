//! Area lights as jittered point lights (McGuire et al. 2003, §8: "soft shadows ... by
//! rendering the shadow volumes of several point lights distributed over the area light").
//!
//! An area light is a flat disc or rectangle with a centre ([`Light::position`]), a unit
//! normal and, for a rectangle, a unit tangent along its width. The renderer replaces it by
//! `samples` point lights, each with `intensity / samples`, placed by a *stratified, jittered*
//! pattern over the shape: the unit square is cut into `samples` cells of equal area (rows of
//! equal-area cells, [`stratified_square`]), one point is drawn uniformly inside each cell
//! (a hash of the light index, the sample index and the pattern seed), and the square is mapped
//! onto the shape (the identity scaled to `width x height` for a rectangle, Shirley and Chiu's
//! area-preserving concentric map for a disc). Each sample's hard shadow is exact; their sum in
//! the float (HDR) target is the soft shadow, with `samples + 1` levels in a penumbra. The
//! jitter keeps neighbouring samples' shadow edges from lining up, which is what shows as
//! banding with a regular grid (a `k x k` grid gives only `k` distinct edges along each axis).
//!
//! The pattern is the same every frame (seed 0) unless the caller animates it
//! ([`expand_lights`] with `Some(frame)`, `--jitter`), which re-draws the jitter every frame
//! so that frames averaged over time converge to the exact soft shadow.
//!
//! Emission: each sample is a point light (it lights both sides of the light's plane, with the
//! renderer's point-light shading), so an area light of size 0 is exactly the point light at
//! its centre, and the light of an area light at a point is the average over its area of the
//! point light there. The CPU reference (`umbrage_reference::area`, another crate of the workspace) computes the visible fraction
//! of the area with many shadow rays, not with these samples.

pub use super::area_shape::{concentric_disc, default_tangent, mix64, pattern_seed, stratified_square, AreaLight, AreaShape, MAX_SAMPLES};
use super::light::{Light, LightKind};

/// Light `light` split into its point-light samples (itself, cloned, when it is not an area
/// light), each with `intensity / samples` and no `area`.
pub fn expand_light(light: &Light, light_index: usize, frame: Option<u64>) -> Vec<Light> {
    let Some(area) = &light.area else { return vec![light.clone()] };
    let n = area.samples.clamp(1, MAX_SAMPLES);
    let centre = light.position.as_dvec3();
    stratified_square(n, pattern_seed(light_index, frame))
        .into_iter()
        .map(|uv| Light {
            kind: LightKind::Point,
            position: area.point(centre, uv).as_vec3(),
            intensity: light.intensity / n as f32,
            area: None,
            ..light.clone()
        })
        .collect()
}

/// Every light of `lights` split into point-light samples ([`expand_light`]), in order; the
/// fixed pattern for `frame = None`, an animated one otherwise.
pub fn expand_lights(lights: &[Light], frame: Option<u64>) -> Vec<Light> {
    lights.iter().enumerate().flat_map(|(i, l)| expand_light(l, i, frame)).collect()
}

/// Per light of `lights`, the range of its samples in [`expand_lights`]'s output.
pub fn sample_ranges(lights: &[Light]) -> Vec<std::ops::Range<usize>> {
    let mut start = 0;
    lights
        .iter()
        .map(|l| {
            let n = l.area.map(|a| a.samples.clamp(1, MAX_SAMPLES) as usize).unwrap_or(1);
            start += n;
            start - n..start
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::{DVec2, DVec3, Vec3};

    fn disc(r: f32, n: u32) -> Light {
        Light {
            kind: LightKind::Point,
            position: Vec3::new(0.0, 4.0, 0.0),
            direction: Vec3::NEG_Y,
            color: Vec3::ONE,
            intensity: 2.0,
            radius: None,
            cone_deg: 45.0,
            area: Some(AreaLight::new(AreaShape::Disc { radius: r }, Vec3::NEG_Y, n)),
        }
    }

    #[test]
    fn stratified_cells_have_one_point_each() {
        for n in [1, 2, 3, 4, 5, 7, 16, 17, 63, 64, 100] {
            let pts = stratified_square(n, 7);
            assert_eq!(pts.len(), n as usize);
            assert!(pts.iter().all(|p| (0.0..1.0).contains(&p.x) && (0.0..1.0).contains(&p.y)), "{n}: {pts:?}");
            // Equal-area strata: any axis-aligned strip of width 1/k holds about n/k points.
            let rows = (n as f64).sqrt().floor() as usize;
            let below = pts.iter().filter(|p| p.y < 0.5).count() as f64;
            assert!((below - n as f64 * 0.5).abs() <= n as f64 / rows as f64 + 1.0, "{n}: {below}");
        }
        // A perfect square is a jittered k x k grid: one point per cell.
        let pts = stratified_square(16, 3);
        let mut cells: Vec<_> = pts.iter().map(|p| ((p.x * 4.0) as u32, (p.y * 4.0) as u32)).collect();
        cells.sort();
        cells.dedup();
        assert_eq!(cells.len(), 16);
    }

    #[test]
    fn samples_lie_on_the_shape_and_sum_to_the_intensity() {
        let l = disc(0.5, 64);
        let s = expand_light(&l, 0, None);
        assert_eq!(s.len(), 64);
        let area = l.area.unwrap();
        for p in &s {
            assert!(area.contains(l.position, p.position, 1e-5), "{:?}", p.position);
            assert!(p.area.is_none() && p.kind == LightKind::Point);
        }
        let sum: f32 = s.iter().map(|p| p.intensity).sum();
        assert!((sum - 2.0).abs() < 1e-5);
        // The mean of the samples is near the centre (stratified: well within a cell).
        let mean = s.iter().map(|p| p.position).sum::<Vec3>() / 64.0;
        assert!(mean.distance(l.position) < 0.05, "{mean}");
        // Fixed unless animated; animated differs per frame.
        assert_eq!(expand_light(&l, 0, None), s);
        assert_ne!(expand_light(&l, 0, Some(1)), expand_light(&l, 0, Some(2)));
        // Rectangles: width along the tangent.
        let r = AreaLight::new(AreaShape::Rect { width: 2.0, height: 0.5 }, Vec3::NEG_Y, 16);
        let pts: Vec<DVec3> = stratified_square(16, 1).into_iter().map(|uv| r.point(DVec3::ZERO, uv)).collect();
        assert!(pts.iter().all(|p| p.x.abs() <= 1.0 && p.z.abs() <= 0.25 && p.y == 0.0));
        assert!(pts.iter().any(|p| p.x.abs() > 0.5));
    }

    #[test]
    fn concentric_map_is_area_preserving() {
        // Uniform grid on the square -> points in the inner half-radius disc hold 1/4 of them.
        let k = 200;
        let mut inner = 0;
        for i in 0..k {
            for j in 0..k {
                let p = concentric_disc(DVec2::new((i as f64 + 0.5) / k as f64, (j as f64 + 0.5) / k as f64));
                assert!(p.length() <= 1.0 + 1e-12);
                inner += (p.length() < 0.5) as u32;
            }
        }
        assert!((inner as f64 / (k * k) as f64 - 0.25).abs() < 0.01, "{inner}");
    }

    #[test]
    fn bad_area_lights_are_refused() {
        let ok = AreaLight::new(AreaShape::Disc { radius: 1.0 }, Vec3::Y, 4);
        assert!(ok.validate().is_ok());
        for bad in [
            AreaLight { shape: AreaShape::Disc { radius: 0.0 }, ..ok },
            AreaLight { shape: AreaShape::Disc { radius: f32::NAN }, ..ok },
            AreaLight { shape: AreaShape::Rect { width: 1.0, height: -1.0 }, ..ok },
            AreaLight { shape: AreaShape::Rect { width: f32::INFINITY, height: 1.0 }, ..ok },
            AreaLight { samples: 0, ..ok },
            AreaLight { samples: MAX_SAMPLES + 1, ..ok },
            AreaLight { normal: Vec3::ZERO, ..ok },
            AreaLight { tangent: Vec3::Y, ..ok },
        ] {
            assert!(bad.validate().is_err(), "{bad:?}");
        }
        let ranges = sample_ranges(&[disc(1.0, 3), Light { area: None, ..disc(1.0, 1) }, disc(1.0, 5)]);
        assert_eq!(ranges, vec![0..3, 3..4, 4..9]);
    }
}
