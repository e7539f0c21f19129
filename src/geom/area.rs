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
//! point light there. The CPU reference (`reference::area`, behind the `cli` feature) computes the visible fraction
//! of the area with many shadow rays, not with these samples.

use super::light::{Light, LightKind};
use glam::{DVec2, DVec3, Vec3};

/// The most point-light samples one area light may have.
pub const MAX_SAMPLES: u32 = 1024;

/// The shape of an area light, in its own plane (centred on the light's position).
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub enum AreaShape {
    /// A disc of this radius (world units, > 0).
    Disc {
        /// Radius, world units.
        radius: f32,
    },
    /// A rectangle, `width` along the light's tangent and `height` along normal x tangent.
    Rect {
        /// Extent along the tangent, world units.
        width: f32,
        /// Extent along `normal.cross(tangent)`, world units.
        height: f32,
    },
}

/// What makes a [`Light`] an area light (its `kind` is then [`LightKind::Point`]: code that
/// knows nothing of area lights sees the point light at the centre, which is the size-0 limit).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AreaLight {
    /// Disc or rectangle.
    pub shape: AreaShape,
    /// Unit normal of the light's plane (the direction it "faces"; emission is two-sided).
    pub normal: Vec3,
    /// Unit vector in the plane along a rectangle's width (orthogonal to `normal`).
    pub tangent: Vec3,
    /// Point lights the renderer splits it into (1..=[`MAX_SAMPLES`]).
    pub samples: u32,
}

impl AreaLight {
    /// A light of this shape facing `normal`, the tangent chosen by [`default_tangent`].
    /// `normal` must be nonzero (it is normalised).
    pub fn new(shape: AreaShape, normal: Vec3, samples: u32) -> AreaLight {
        let normal = normal.normalize_or_zero();
        AreaLight { shape, normal, tangent: default_tangent(normal), samples }
    }

    /// Why this area light is unusable, if it is: a size that is not finite and > 0, a zero
    /// or non-unit normal or tangent, a tangent not orthogonal to the normal, or a sample count
    /// outside 1..=[`MAX_SAMPLES`].
    pub fn validate(&self) -> Result<(), String> {
        let sizes: &[(&str, f32)] = match &self.shape {
            AreaShape::Disc { radius } => &[("radius", *radius)],
            AreaShape::Rect { width, height } => &[("width", *width), ("height", *height)],
        };
        for (what, v) in sizes {
            if !(v.is_finite() && *v > 0.0) {
                return Err(format!("area light {what} must be finite and > 0, got {v} (use kind = \"point\" for a point light)"));
            }
            if *v > 1e6 {
                return Err(format!("area light {what} {v} is too large (at most 1e6)"));
            }
        }
        if !(self.samples >= 1 && self.samples <= MAX_SAMPLES) {
            return Err(format!("area light samples must be 1..={MAX_SAMPLES}, got {}", self.samples));
        }
        let unit = |v: Vec3| v.is_finite() && (v.length() - 1.0).abs() < 1e-3;
        if !unit(self.normal) {
            return Err(format!("area light normal must be a nonzero finite vector, got {:?}", self.normal));
        }
        if !unit(self.tangent) || self.tangent.dot(self.normal).abs() > 1e-3 {
            return Err(format!("area light tangent must be a nonzero vector not parallel to the normal, got {:?}", self.tangent));
        }
        Ok(())
    }

    /// The shape's area, world units squared.
    pub fn area(&self) -> f64 {
        match self.shape {
            AreaShape::Disc { radius } => std::f64::consts::PI * (radius as f64).powi(2),
            AreaShape::Rect { width, height } => width as f64 * height as f64,
        }
    }

    /// The radius of the smallest sphere around the centre containing the shape.
    pub fn extent(&self) -> f32 {
        match self.shape {
            AreaShape::Disc { radius } => radius,
            AreaShape::Rect { width, height } => 0.5 * (width * width + height * height).sqrt(),
        }
    }

    /// The world point of unit-square coordinates `uv` on the light centred at `centre`
    /// (area-preserving: uniform `uv` gives uniform points on the shape).
    pub fn point(&self, centre: DVec3, uv: DVec2) -> DVec3 {
        let t = self.tangent.as_dvec3();
        let b = self.normal.as_dvec3().cross(t);
        let local = match self.shape {
            AreaShape::Rect { width, height } => DVec2::new((uv.x - 0.5) * width as f64, (uv.y - 0.5) * height as f64),
            AreaShape::Disc { radius } => concentric_disc(uv) * radius as f64,
        };
        centre + t * local.x + b * local.y
    }

    /// Whether world point `q` lies on the light (within `eps` of its plane and inside its shape).
    pub fn contains(&self, centre: Vec3, q: Vec3, eps: f32) -> bool {
        let d = q - centre;
        if d.dot(self.normal).abs() > eps {
            return false;
        }
        let (x, y) = (d.dot(self.tangent), d.dot(self.normal.cross(self.tangent)));
        match self.shape {
            AreaShape::Disc { radius } => x * x + y * y <= (radius + eps) * (radius + eps),
            AreaShape::Rect { width, height } => x.abs() <= 0.5 * width + eps && y.abs() <= 0.5 * height + eps,
        }
    }
}

/// A unit tangent orthogonal to unit `normal`: world X projected onto the plane, or world Z
/// when the normal is (nearly) along X.
pub fn default_tangent(normal: Vec3) -> Vec3 {
    let axis = if normal.x.abs() > 0.9 { Vec3::Z } else { Vec3::X };
    (axis - normal * axis.dot(normal)).normalize_or_zero()
}

/// Shirley and Chiu's concentric map of the unit square onto the unit disc (area-preserving,
/// low distortion, so stratified squares stay stratified on the disc).
pub fn concentric_disc(uv: DVec2) -> DVec2 {
    let a = uv * 2.0 - DVec2::ONE;
    if a == DVec2::ZERO {
        return DVec2::ZERO;
    }
    let q = std::f64::consts::FRAC_PI_4;
    let (r, theta) = if a.x.abs() > a.y.abs() { (a.x, q * (a.y / a.x)) } else { (a.y, 2.0 * q - q * (a.x / a.y)) };
    DVec2::new(r * theta.cos(), r * theta.sin())
}

/// A 64-bit mix (SplitMix64's finaliser): decorrelated bits from a counter.
pub fn mix64(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// A uniform number in [0, 1) from a hash.
fn unit(h: u64) -> f64 {
    (h >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
}

/// `n` points in the unit square, one uniformly jittered (by `seed`) inside each of `n` cells of
/// equal area: `floor(sqrt n)` rows, the counts per row differing by at most one, each row's
/// height proportional to its count. A perfect square gives the usual `k x k` jittered grid.
pub fn stratified_square(n: u32, seed: u64) -> Vec<DVec2> {
    let n = n.max(1) as u64;
    let rows = ((n as f64).sqrt().floor() as u64).max(1);
    let mut out = Vec::with_capacity(n as usize);
    let mut y0 = 0.0;
    let mut k = 0u64;
    for r in 0..rows {
        let cols = n / rows + u64::from(r < n % rows);
        let hgt = cols as f64 / n as f64;
        for c in 0..cols {
            let h = mix64(seed ^ mix64(k));
            let (jx, jy) = (unit(h), unit(mix64(h)));
            out.push(DVec2::new((c as f64 + jx) / cols as f64, (y0 + jy * hgt).min(1.0 - f64::EPSILON)));
            k += 1;
        }
        y0 += hgt;
    }
    out
}

/// The seed of light `light_index`'s pattern for `frame` (`None`: the fixed pattern).
pub fn pattern_seed(light_index: usize, frame: Option<u64>) -> u64 {
    let f = frame.map(|f| mix64(f ^ 0xA5A5_5A5A_D00D_F00D)).unwrap_or(0);
    mix64(light_index as u64 ^ 0x5EED_0000_0000_0000) ^ f
}

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
