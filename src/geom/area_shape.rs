//! The shape of an area light and its stratified sampling pattern: the leaf under
//! [`area`](super::area) (which splits lights into samples) and [`light`](super::light) (whose
//! lights may carry an [`AreaLight`]). Re-exported from [`area`](super::area).

use glam::{DVec2, DVec3, Vec3};

/// The most point-light samples one area light may have.
pub const MAX_SAMPLES: u32 = 1024;

/// The shape of an area light, in its own plane (centred on the light's position).
#[derive(Clone, Copy, Debug, PartialEq)]
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

/// What makes a [`Light`](crate::geom::light::Light) an area light (its `kind` is then [`LightKind::Point`](crate::geom::light::LightKind::Point): code that
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
