//! umbrage-reference: the exact CPU ground truth (ray casting in f64) and the error metrics every shadow technique is measured by.
//!
//! The CPU ground truth: exact hard shadows by ray casting in f64.
//!
//! Nothing here is shared with the renderer's shadow algorithm; the only common code is the
//! camera model ([`Camera::pixel_ray`](umbrage_scene::Camera::pixel_ray)) and the scene types.
//!
//! # The rule
//!
//! A surface point `P` with unit geometric normal `N` on its visible side (the face normal,
//! turned towards the eye when the eye sees the back of the triangle) is *lit* by a light iff
//! 1. it is within the light's range (`|L - P| <= radius`, point/spot lights with a radius;
//!    otherwise [`LightState::OutOfRange`]),
//! 2. for a spot light, it is inside the cone (angle between the spot direction and `P - L`
//!    at most `cone_deg / 2`; otherwise [`LightState::OutsideCone`]),
//! 3. it faces the light: `N . (L - P) > 0` (point/spot) or `N . (-dir) > 0` (directional);
//!    otherwise [`LightState::BackFacing`],
//! 4. no shadow-casting triangle lies strictly between `P` and the light (directional: to
//!    infinity); otherwise [`LightState::Shadowed`].
//!
//! The shadow ray starts at `P + N * offset` where `offset = tolerance.surface_offset_rel *
//! scene_size` (scene_size = diagonal of the bounds of all triangles), so GPU positions a
//! little below the surface do not shadow themselves; it stops `offset` short of a point
//! light.
//!
//! # Ambiguity
//!
//! A pixel is [`LightState::Ambiguous`] (never counted as a mismatch) when the answer is not
//! stable under a perturbation of `P` of radius `r` (`r = tolerance.footprint_fraction *
//! pixel footprint`; for [`Reference::shadow_at`], `r = tolerance.min_radius_rel *
//! scene_size`):
//! * grazing light: `|cos(N, L - P)| < tolerance.grazing_cos` (1e-3),
//! * `|dist - radius| <= r` (range boundary), or the cone boundary is within `r` of `P`,
//! * the shadow-ray decision differs between `P` and any of `P ± r t1`, `P ± r t2` (`t1, t2`
//!   an orthonormal tangent basis of the surface).
//!
//! A non-finite or zero normal is also Ambiguous.

#![warn(missing_docs)]
pub mod area;
pub mod bvh;
mod check;
pub mod dump;
pub mod metrics;
mod shade;
pub mod transmit;

use bvh::Bvh;
use glam::{DVec3, Vec3};
use umbrage_scene::Scene;

pub use area::{area_error, sample_fraction, AreaImage, AreaMetrics};
pub use check::{check, check_dump, CheckReport, LightCheck};
pub use dump::{read_dump, write_dump, Dump, DumpLight};
pub use metrics::Metrics;
pub(crate) use shade::par_rows;
use shade::tangent_basis;
pub use transmit::{Transmit, TransmitImage, TransmitMetrics};

/// The reference's decision for one surface point and one light.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum LightState {
    /// Receives light.
    Lit,
    /// Faces the light, in range and cone, but an occluder lies between it and the light.
    Shadowed,
    /// Faces away from the light.
    BackFacing,
    /// Spot light: outside the cone.
    OutsideCone,
    /// Point/spot light with a radius: farther than the radius.
    OutOfRange,
    /// The decision is not stable under a tiny perturbation (see the module docs).
    Ambiguous,
    /// No surface at this pixel.
    Background,
}

impl LightState {
    /// `Some(true)` if lit, `Some(false)` if not lit for any reason, `None` for
    /// Ambiguous and Background.
    pub fn lit(self) -> Option<bool> {
        match self {
            LightState::Lit => Some(true),
            LightState::Shadowed | LightState::BackFacing | LightState::OutsideCone | LightState::OutOfRange => Some(false),
            LightState::Ambiguous | LightState::Background => None,
        }
    }
    /// `Some(true)` where the surface faces the light (Lit or Shadowed), `Some(false)` where it
    /// faces away, `None` where the state does not say (cone, range, Ambiguous, Background).
    pub fn faces_light(self) -> Option<bool> {
        match self {
            LightState::Lit | LightState::Shadowed => Some(true),
            LightState::BackFacing => Some(false),
            LightState::OutsideCone | LightState::OutOfRange | LightState::Ambiguous | LightState::Background => None,
        }
    }
    /// The mask value the GPU would write: 255 lit, 0 not lit, 128 background.
    /// Ambiguous maps to 0.
    pub fn mask_value(self) -> u8 {
        match self {
            LightState::Lit => 255,
            LightState::Background => 128,
            _ => 0,
        }
    }
}

/// Tolerances of the reference (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Tolerance {
    /// |cos| between the normal and the light direction below which the answer is Ambiguous.
    pub grazing_cos: f64,
    /// Perturbation radius as a fraction of the pixel footprint (render, check_dump).
    pub footprint_fraction: f64,
    /// Perturbation radius of [`Reference::shadow_at`], relative to the scene size.
    pub min_radius_rel: f64,
    /// Shadow-ray origin offset along the normal, relative to the scene size.
    pub surface_offset_rel: f64,
}

impl Default for Tolerance {
    fn default() -> Self {
        Tolerance { grazing_cos: 1e-3, footprint_fraction: 0.05, min_radius_rel: 1e-5, surface_offset_rel: 2e-5 }
    }
}

/// One pixel of a [`RefImage`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RefPixel {
    /// The pixel's centre ray hit a surface (false: background).
    pub hit: bool,
    /// World position of the visible surface (NaN for background).
    pub position: Vec3,
    /// Unit outward geometric normal (NaN for background).
    pub normal: Vec3,
    /// Distance from the camera eye (infinite for background).
    pub depth: f32,
    /// Index of the scene mesh (u32::MAX for background).
    pub mesh: u32,
    /// Index of the triangle in the reference's triangle list (u32::MAX for background).
    pub tri: u32,
}

impl RefPixel {
    /// A pixel whose ray hits nothing.
    pub const BACKGROUND: RefPixel =
        RefPixel { hit: false, position: Vec3::NAN, normal: Vec3::NAN, depth: f32::INFINITY, mesh: u32::MAX, tri: u32::MAX };
}

/// A reference rendering: per pixel the visible surface and per light its [`LightState`].
#[derive(Clone, Debug)]
pub struct RefImage {
    /// Width, pixels.
    pub width: u32,
    /// Height, pixels.
    pub height: u32,
    /// Number of lights (the stride of `states`).
    pub light_count: usize,
    /// Row-major from the top-left.
    pub pixels: Vec<RefPixel>,
    /// `states[pixel * light_count + light]`.
    pub states: Vec<LightState>,
}

impl RefImage {
    /// The visible surface at pixel (x, y), row 0 at the top.
    pub fn pixel(&self, x: u32, y: u32) -> &RefPixel {
        &self.pixels[(y * self.width + x) as usize]
    }
    /// What light `light` does at pixel (x, y).
    pub fn state(&self, x: u32, y: u32, light: usize) -> LightState {
        self.states[(y * self.width + x) as usize * self.light_count + light]
    }
    /// All pixel states of one light, row-major.
    pub fn light_states(&self, light: usize) -> Vec<LightState> {
        (0..self.pixels.len()).map(|i| self.states[i * self.light_count + light]).collect()
    }
    /// The reference as a GPU-style mask (255 lit, 0 not lit or ambiguous, 128 background).
    pub fn mask(&self, light: usize) -> Vec<u8> {
        self.light_states(light).into_iter().map(LightState::mask_value).collect()
    }
    /// Positions as W*H*3 f32 (NaN for background), the dump layout.
    pub fn positions_f32(&self) -> Vec<f32> {
        self.pixels.iter().flat_map(|p| p.position.to_array()).collect()
    }
    /// Normals as W*H*3 f32 (NaN for background), the dump layout.
    pub fn normals_f32(&self) -> Vec<f32> {
        self.pixels.iter().flat_map(|p| p.normal.to_array()).collect()
    }
}

/// The ray-cast ground truth over a set of world-space triangles.
#[derive(Clone, Debug)]
pub struct Reference {
    /// BVH over the visible triangles (hit ids index `tris`).
    visible: Bvh,
    /// BVH over the shadow-casting triangles (hit ids index `tris`).
    occluders: Bvh,
    tris: Vec<[DVec3; 3]>,
    mesh_of: Vec<u32>,
    /// Per triangle, the RGB fraction of light it lets through, `(1 - opacity) * color`
    /// (0 for opaque casters); see [`transmit`].
    filters: Vec<[f64; 3]>,
    scale: f64,
    /// Exact spheres, seen and (when they cast shadows) occluding: intersected analytically.
    spheres: Vec<RefSphere>,
    /// How close to a shadow boundary a point may be before it is called ambiguous.
    pub tolerance: Tolerance,
}

/// An exact sphere of a [`Reference`] ([`Reference::with_spheres`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RefSphere {
    /// Centre and radius, world space.
    pub sphere: umbrage::geom::Sphere,
    /// Casts shadows.
    pub occluder: bool,
    /// The id reported in [`RefPixel::mesh`] (after the scene's meshes: `meshes.len() + i`).
    pub mesh: u32,
}

/// Per-triangle flags for [`Reference::new`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TriFlags {
    /// Seen by camera rays.
    pub visible: bool,
    /// Casts shadows.
    pub occluder: bool,
    /// Mesh index reported in [`RefPixel::mesh`].
    pub mesh: u32,
}

impl Reference {
    /// A reference over world-space triangles with per-triangle flags (same length; panics
    /// otherwise).
    /// Zero-area and non-finite triangles are dropped (they can neither be seen nor occlude).
    pub fn new(triangles: Vec<[DVec3; 3]>, flags: &[TriFlags]) -> Reference {
        Reference::with_filters(triangles, flags, &[])
    }

    /// [`Reference::new`] with each triangle's light filter for [`Reference::transmittance_at`]:
    /// `filters[i] = (1 - opacity) * color` of triangle `i` (`[0; 3]` for an opaque caster).
    /// An empty `filters` means every triangle is opaque; otherwise it has one entry per
    /// triangle (panics otherwise). Only shadow-casting triangles ever filter light.
    pub fn with_filters(triangles: Vec<[DVec3; 3]>, flags: &[TriFlags], filters: &[[f64; 3]]) -> Reference {
        assert_eq!(triangles.len(), flags.len(), "one TriFlags per triangle");
        assert!(filters.is_empty() || filters.len() == triangles.len(), "one filter per triangle");
        let ok = |t: &[DVec3; 3]| t.iter().all(|p| p.is_finite()) && (t[1] - t[0]).cross(t[2] - t[0]).length_squared() > 0.0;
        let mut tris = Vec::with_capacity(triangles.len());
        let mut mesh_of = Vec::with_capacity(triangles.len());
        let mut kept_filters = Vec::with_capacity(triangles.len());
        let mut vis = Vec::new();
        let mut occ = Vec::new();
        let mut lo = DVec3::splat(f64::INFINITY);
        let mut hi = DVec3::splat(f64::NEG_INFINITY);
        for (i, (t, f)) in triangles.into_iter().zip(flags).enumerate() {
            if !ok(&t) || !(f.visible || f.occluder) {
                continue;
            }
            for p in &t {
                lo = lo.min(*p);
                hi = hi.max(*p);
            }
            tris.push(t);
            mesh_of.push(f.mesh);
            kept_filters.push(filters.get(i).copied().unwrap_or([0.0; 3]));
            vis.push(f.visible);
            occ.push(f.occluder);
        }
        // Build each BVH over the full list but with non-members replaced by NaN triangles,
        // which `Bvh::build` skips: ids stay global triangle indices.
        let nan = [DVec3::NAN; 3];
        let vis_tris: Vec<[DVec3; 3]> = tris.iter().zip(&vis).map(|(t, &v)| if v { *t } else { nan }).collect();
        let occ_tris: Vec<[DVec3; 3]> = tris.iter().zip(&occ).map(|(t, &o)| if o { *t } else { nan }).collect();
        let scale = if tris.is_empty() { 1.0 } else { (hi - lo).length().max(1e-30) };
        Reference {
            visible: Bvh::build(&vis_tris),
            occluders: Bvh::build(&occ_tris),
            tris,
            mesh_of,
            filters: kept_filters,
            scale,
            spheres: Vec::new(),
            tolerance: Tolerance::default(),
        }
    }

    /// The same reference with exact spheres added (seen by camera rays, occluding when
    /// `occluder`); the scene size then covers them too. Spheres that are not finite or have
    /// no positive radius are dropped.
    pub fn with_spheres(mut self, spheres: &[RefSphere]) -> Reference {
        self.spheres.extend(spheres.iter().copied().filter(|s| s.sphere.problem().is_none()));
        let mut lo = DVec3::splat(f64::INFINITY);
        let mut hi = DVec3::splat(f64::NEG_INFINITY);
        for p in self.tris.iter().flatten() {
            lo = lo.min(*p);
            hi = hi.max(*p);
        }
        for s in &self.spheres {
            lo = lo.min(s.sphere.center - s.sphere.radius);
            hi = hi.max(s.sphere.center + s.sphere.radius);
        }
        if lo.is_finite() && hi.is_finite() {
            self.scale = (hi - lo).length().max(1e-30);
        }
        self
    }

    /// The exact spheres of this reference.
    pub fn spheres(&self) -> &[RefSphere] {
        &self.spheres
    }

    /// All triangles visible, all occluding, mesh 0.
    pub fn from_triangles(triangles: Vec<[DVec3; 3]>) -> Reference {
        let flags = vec![TriFlags { visible: true, occluder: true, mesh: 0 }; triangles.len()];
        Reference::new(triangles, &flags)
    }

    /// World triangles of every mesh (`SceneMesh::transform` applied; the stored winding is
    /// already outward in world space). All meshes are visible; `casts_shadow` ones occlude.
    pub fn from_scene(scene: &Scene) -> Reference {
        let mut tris = Vec::new();
        let mut flags = Vec::new();
        let mut filters = Vec::new();
        for (mi, m) in scene.meshes.iter().enumerate() {
            let filter = transmit::mesh_filter(m);
            let xf = m.transform.as_dmat4();
            let pos: Vec<DVec3> = m.mesh.positions.iter().map(|p| xf.transform_point3(p.as_dvec3())).collect();
            for t in &m.mesh.triangles {
                let g = |i: u32| pos.get(i as usize).copied().unwrap_or(DVec3::NAN);
                tris.push([g(t[0]), g(t[1]), g(t[2])]);
                flags.push(TriFlags {
                    // Transparent meshes are drawn over the scene, not as receivers: the
                    // visible surface is the first opaque one (as in the renderer).
                    visible: m.opacity >= 1.0,
                    occluder: m.casts_shadow,
                    mesh: mi as u32,
                });
                filters.push(filter);
            }
        }
        let base = scene.meshes.len() as u32;
        let spheres: Vec<RefSphere> = scene
            .spheres
            .iter()
            .enumerate()
            .map(|(i, s)| RefSphere { sphere: s.sphere, occluder: s.casts_shadow, mesh: base + i as u32 })
            .collect();
        Reference::with_filters(tris, &flags, &filters).with_spheres(&spheres)
    }

    /// The same reference with another [`Tolerance`].
    pub fn with_tolerance(mut self, tolerance: Tolerance) -> Reference {
        self.tolerance = tolerance;
        self
    }

    /// Diagonal of the bounds of all triangles.
    pub fn scene_size(&self) -> f64 {
        self.scale
    }

    /// Number of (non-degenerate) triangles.
    pub fn triangle_count(&self) -> usize {
        self.tris.len()
    }

    /// Bounding-volume hierarchies (visible, occluders), for callers that cast their own rays.
    pub fn bvhs(&self) -> (&Bvh, &Bvh) {
        (&self.visible, &self.occluders)
    }
}

#[cfg(test)]
mod sphere_tests;
#[cfg(test)]
mod tests;
