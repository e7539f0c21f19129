//! The CPU ground truth: exact hard shadows by ray casting in f64.
//!
//! Nothing here is shared with the renderer's shadow algorithm; the only common code is the
//! camera model ([`Camera::pixel_ray`]) and the scene types.
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
pub mod bvh;
pub mod dump;
pub mod metrics;
pub mod transmit;

use crate::error::Result;
use crate::scene::{Camera, Light, LightKind, Scene};
use bvh::Bvh;
use glam::{DVec3, Vec3};
use std::fmt;

pub use dump::{read_dump, write_dump, Dump, DumpLight};
pub use metrics::Metrics;
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
    /// How close to a shadow boundary a point may be before it is called ambiguous.
    pub tolerance: Tolerance,
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
            tolerance: Tolerance::default(),
        }
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
        Reference::with_filters(tris, &flags, &filters)
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

    /// The state of surface point `p` with normal `n` (need not be unit) for `light`, with
    /// the perturbation radius `tolerance.min_radius_rel * scene_size`.
    pub fn shadow_at(&self, p: DVec3, n: DVec3, light: &Light) -> LightState {
        self.shadow_at_radius(p, n, light, self.tolerance.min_radius_rel * self.scale)
    }

    /// [`Reference::shadow_at`] with an explicit perturbation radius (0: no perturbation,
    /// only the grazing test can then give Ambiguous).
    pub fn shadow_at_radius(&self, p: DVec3, n: DVec3, light: &Light, radius: f64) -> LightState {
        let n = n.normalize_or_zero();
        let r = radius.max(0.0);
        if let Some(state) = self.light_precheck(p, n, light, r) {
            return state;
        }
        let centre = self.occluded(p, n, light);
        if r > 0.0 {
            let (t1, t2) = tangent_basis(n);
            for q in [p + t1 * r, p - t1 * r, p + t2 * r, p - t2 * r] {
                if self.occluded(q, n, light) != centre {
                    return LightState::Ambiguous;
                }
            }
        }
        if centre {
            LightState::Shadowed
        } else {
            LightState::Lit
        }
    }

    /// Rules 1-3 of the module docs and their ambiguity tests, for unit (or zero) `n` and
    /// perturbation radius `r >= 0`: `Some(state)` when they decide (Ambiguous, OutOfRange,
    /// OutsideCone, BackFacing), `None` when only the occlusion test is left.
    fn light_precheck(&self, p: DVec3, n: DVec3, light: &Light, r: f64) -> Option<LightState> {
        if n == DVec3::ZERO || !n.is_finite() || !p.is_finite() {
            return Some(LightState::Ambiguous);
        }
        let lpos = light.position.as_dvec3();
        let ldir = light.direction.as_dvec3().normalize_or_zero();
        // Direction to the light and distance.
        let (to_l, dist) = match light.kind {
            LightKind::Directional => {
                if ldir == DVec3::ZERO {
                    return Some(LightState::Ambiguous);
                }
                (-ldir, f64::INFINITY)
            }
            _ => {
                let d = lpos - p;
                let len = d.length();
                if len.is_nan() || len <= 0.0 {
                    return Some(LightState::Ambiguous);
                }
                (d / len, len)
            }
        };
        if light.kind != LightKind::Directional {
            if let Some(rad) = light.radius {
                let rad = rad as f64;
                if (dist - rad).abs() <= r {
                    return Some(LightState::Ambiguous);
                }
                if dist > rad {
                    return Some(LightState::OutOfRange);
                }
            }
        }
        if light.kind == LightKind::Spot {
            if ldir == DVec3::ZERO {
                return Some(LightState::Ambiguous);
            }
            let half = (light.cone_deg as f64 * 0.5).to_radians();
            let ang = (-to_l).dot(ldir).clamp(-1.0, 1.0).acos();
            // Distance of P from the cone surface, approximately (angle difference * dist).
            if (ang - half).abs() * dist <= r {
                return Some(LightState::Ambiguous);
            }
            if ang > half {
                return Some(LightState::OutsideCone);
            }
        }
        let cos = n.dot(to_l);
        if cos.abs() < self.tolerance.grazing_cos {
            return Some(LightState::Ambiguous);
        }
        if cos < 0.0 {
            return Some(LightState::BackFacing);
        }
        None
    }

    /// Whether an opaque shadow caster lies strictly between `p` (offset along `n`) and the
    /// light. Transparent casters (non-zero filter) do not occlude: they attenuate, and are
    /// judged by [`Reference::transmittance_at`].
    fn occluded(&self, p: DVec3, n: DVec3, light: &Light) -> bool {
        self.shadow_segment(p, n, light)
            .is_some_and(|(o, d, t_max)| self.occluders.any_hit(o, d, 0.0, t_max, |t| self.filter(t) != [0.0; 3]))
    }

    /// The shadow ray of surface point `p` (offset along `n`): origin, unit direction towards
    /// the light, and the distance to stop at (short of a point light by the same offset).
    /// `None` when a point light is closer than the offset.
    pub(crate) fn shadow_segment(&self, p: DVec3, n: DVec3, light: &Light) -> Option<(DVec3, DVec3, f64)> {
        let off = self.tolerance.surface_offset_rel * self.scale;
        let o = p + n * off;
        match light.kind {
            LightKind::Directional => Some((o, -light.direction.as_dvec3().normalize(), f64::INFINITY)),
            _ => {
                let to = light.position.as_dvec3() - o;
                let dist = to.length();
                if dist.is_nan() || dist <= off {
                    return None;
                }
                Some((o, to / dist, dist - off))
            }
        }
    }

    /// Renders the reference for `camera` (its [`Camera::pixel_ray`] model) and `lights`.
    /// Rows are split over the available cores.
    pub fn render(&self, camera: &Camera, lights: &[Light], width: u32, height: u32) -> RefImage {
        let (w, h) = (width as usize, height as usize);
        let nl = lights.len();
        let rows: Vec<(Vec<RefPixel>, Vec<LightState>)> = par_rows(h, |y| {
            let mut px = Vec::with_capacity(w);
            let mut st = Vec::with_capacity(w * nl);
            for x in 0..w {
                match self.surface_at_pixel(camera, x as u32, y as u32, width, height) {
                    None => {
                        px.push(RefPixel::BACKGROUND);
                        st.extend(std::iter::repeat(LightState::Background).take(nl));
                    }
                    Some((pixel, p, n, r)) => {
                        px.push(pixel);
                        for l in lights {
                            st.push(self.shadow_at_radius(p, n, l, r));
                        }
                    }
                }
            }
            (px, st)
        });
        let mut pixels = Vec::with_capacity(w * h);
        let mut states = Vec::with_capacity(w * h * nl);
        for (p, s) in rows {
            pixels.extend(p);
            states.extend(s);
        }
        RefImage { width, height, light_count: nl, pixels, states }
    }
}

impl Reference {
    /// The visible surface at pixel (x, y): the pixel, its f64 position and unit normal of the
    /// visible side, and the perturbation radius (`footprint_fraction` x pixel footprint).
    pub(crate) fn surface_at_pixel(
        &self,
        camera: &Camera,
        x: u32,
        y: u32,
        width: u32,
        height: u32,
    ) -> Option<(RefPixel, DVec3, DVec3, f64)> {
        let eye = camera.eye.as_dvec3();
        // Angular size of one pixel (vertical), for the footprint.
        let pix_angle = 2.0 * ((camera.fov_y_deg as f64).to_radians() * 0.5).tan() / height.max(1) as f64;
        let (o, d) = camera.pixel_ray(x, y, width, height);
        let hit = self.visible.closest_hit(o, d, 0.0, f64::INFINITY)?;
        let t = &self.tris[hit.tri as usize];
        let p = t[0] * (1.0 - hit.u - hit.v) + t[1] * hit.u + t[2] * hit.v;
        // The visible side of the surface: its geometric normal turned towards the eye (a
        // closed, outward mesh is only ever seen from the front, so this changes nothing
        // there; open and two-sided surfaces are lit on the side the eye sees when that side
        // faces the light).
        let n = (t[1] - t[0]).cross(t[2] - t[0]).normalize();
        let n = if n.dot(d) > 0.0 { -n } else { n };
        let depth = (p - eye).length();
        let r = self.tolerance.footprint_fraction * depth * pix_angle;
        let pixel = RefPixel {
            hit: true,
            position: p.as_vec3(),
            normal: n.as_vec3(),
            depth: depth as f32,
            mesh: self.mesh_of[hit.tri as usize],
            tri: hit.tri,
        };
        Some((pixel, p, n, r))
    }
}

/// An orthonormal basis of the plane orthogonal to unit `n` (Duff et al. 2017).
fn tangent_basis(n: DVec3) -> (DVec3, DVec3) {
    let s = 1f64.copysign(n.z);
    let a = -1.0 / (s + n.z);
    let b = n.x * n.y * a;
    (DVec3::new(1.0 + s * n.x * n.x * a, s * b, -s * n.x), DVec3::new(b, s + n.y * n.y * a, -n.y))
}

/// Runs `f(row)` for rows `0..h` over the available cores; results in row order.
pub(crate) fn par_rows<T: Send>(h: usize, f: impl Fn(usize) -> T + Sync) -> Vec<T> {
    let threads = std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1).min(h.max(1));
    if threads <= 1 {
        return (0..h).map(&f).collect();
    }
    let next = std::sync::atomic::AtomicUsize::new(0);
    let mut parts: Vec<Vec<(usize, T)>> = Vec::new();
    std::thread::scope(|s| {
        let handles: Vec<_> = (0..threads)
            .map(|_| {
                s.spawn(|| {
                    let mut out = Vec::new();
                    loop {
                        let y = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                        if y >= h {
                            break;
                        }
                        out.push((y, f(y)));
                    }
                    out
                })
            })
            .collect();
        for hd in handles {
            match hd.join() {
                Ok(v) => parts.push(v),
                Err(e) => std::panic::resume_unwind(e),
            }
        }
    });
    let mut all: Vec<(usize, T)> = parts.into_iter().flatten().collect();
    all.sort_by_key(|(y, _)| *y);
    all.into_iter().map(|(_, t)| t).collect()
}

/// Per-light result of [`check_dump`].
#[derive(Clone, Debug, serde::Serialize)]
pub struct LightCheck {
    /// The light's index in the dump.
    pub index: usize,
    /// Homogeneous position as in frame.json.
    pub position: [f32; 4],
    /// "point", "spot" or "directional" (as used for the check).
    pub kind: String,
    /// The dumped mask compared with the reference's.
    pub metrics: Metrics,
}

/// The result of checking a frame dump against the reference.
#[derive(Clone, Debug, serde::Serialize)]
pub struct CheckReport {
    /// The dump directory checked.
    pub dir: String,
    /// Image width, pixels.
    pub width: u32,
    /// Image height, pixels.
    pub height: u32,
    /// Width in pixels of the band around reference shadow edges left out of the comparison.
    pub band: u32,
    /// Triangles the reference was built from.
    pub triangles: usize,
    /// One result per light.
    pub lights: Vec<LightCheck>,
}

impl CheckReport {
    /// The largest `fraction_outside_band` over the lights (0 with no lights).
    pub fn worst_fraction(&self) -> f64 {
        self.lights.iter().map(|l| l.metrics.fraction_outside_band).fold(0.0, f64::max)
    }
    /// True iff every light has `fraction_outside_band <= threshold_fraction` (background
    /// mismatches outside the band count in that fraction).
    pub fn passed(&self, threshold_fraction: f64) -> bool {
        self.lights.iter().all(|l| l.metrics.fraction_outside_band <= threshold_fraction)
    }
}

impl fmt::Display for CheckReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "dump {} ({}x{}, {} shadow-casting triangles, band {} px)",
            self.dir, self.width, self.height, self.triangles, self.band
        )?;
        for l in &self.lights {
            let m = &l.metrics;
            writeln!(
                f,
                "  light {} ({} at [{}, {}, {}, {}]): {} compared, {} mismatches outside band ({:.4}%), \
                 lit-but-shadowed {}, shadowed-but-lit {}, background mismatches {}, ambiguous {}, band {}",
                l.index,
                l.kind,
                l.position[0],
                l.position[1],
                l.position[2],
                l.position[3],
                m.compared,
                m.mismatches_outside_band,
                m.fraction_outside_band * 100.0,
                m.lit_but_ref_shadowed,
                m.shadowed_but_ref_lit,
                m.background_mismatch,
                m.ambiguous,
                m.band_pixels
            )?;
        }
        write!(f, "  worst fraction outside band: {:.6}", self.worst_fraction())
    }
}

/// Checks a frame dump: builds a reference from `world.obj`, evaluates
/// [`Reference::shadow_at_radius`] at the GPU's own position and normal of every
/// non-background pixel (perturbation radius = `footprint_fraction` x the distance to the
/// nearest neighbouring pixel's position on the same surface), and compares with each
/// `shadow_K.png`. The band is built from the reference states and from position/normal
/// discontinuities of the dump itself (no camera needed).
pub fn check_dump(dir: impl AsRef<std::path::Path>, band: u32) -> Result<CheckReport> {
    let dir = dir.as_ref();
    let dump = read_dump(dir)?;
    let lights: Vec<Light> = dump.lights.iter().map(|l| l.to_light()).collect::<Result<_>>()?;
    let reference = Reference::from_triangles(dump.triangles.iter().map(|t| [t[0].as_dvec3(), t[1].as_dvec3(), t[2].as_dvec3()]).collect());
    let (w, h) = (dump.width as usize, dump.height as usize);
    let pos = |i: usize| DVec3::new(dump.positions[3 * i] as f64, dump.positions[3 * i + 1] as f64, dump.positions[3 * i + 2] as f64);
    let nrm = |i: usize| DVec3::new(dump.normals[3 * i] as f64, dump.normals[3 * i + 1] as f64, dump.normals[3 * i + 2] as f64);
    let cam = dump.camera_pos.as_dvec3();
    let geo: Vec<metrics::GeoSample> = (0..w * h)
        .map(|i| {
            let p = pos(i);
            if p.is_finite() {
                metrics::GeoSample::Surface { position: p, normal: nrm(i), depth: (p - cam).length(), mesh: None }
            } else {
                metrics::GeoSample::Background
            }
        })
        .collect();
    let cos30 = 30f64.to_radians().cos();
    // Footprint: distance to the nearest 4-neighbour on the same surface.
    let footprint = |i: usize| -> f64 {
        let (x, y) = (i % w, i / w);
        let p = pos(i);
        let n = nrm(i).normalize_or_zero();
        let mut best = f64::INFINITY;
        let mut consider = |j: usize| {
            let q = pos(j);
            if q.is_finite() && nrm(j).normalize_or_zero().dot(n) > cos30 {
                best = best.min((q - p).length());
            }
        };
        if x > 0 {
            consider(i - 1);
        }
        if x + 1 < w {
            consider(i + 1);
        }
        if y > 0 {
            consider(i - w);
        }
        if y + 1 < h {
            consider(i + w);
        }
        if best.is_finite() && best > 0.0 {
            best
        } else {
            1e-3 * (p - cam).length()
        }
    };
    let min_r = reference.tolerance.min_radius_rel * reference.scene_size();
    let nl = lights.len();
    let rows: Vec<Vec<LightState>> = par_rows(h, |y| {
        let mut out = Vec::with_capacity(w * nl);
        for x in 0..w {
            let i = y * w + x;
            let p = pos(i);
            if !p.is_finite() {
                out.extend(std::iter::repeat(LightState::Background).take(nl));
                continue;
            }
            let r = (reference.tolerance.footprint_fraction * footprint(i)).max(min_r);
            for l in &lights {
                out.push(reference.shadow_at_radius(p, nrm(i), l, r));
            }
        }
        out
    });
    let all: Vec<LightState> = rows.into_iter().flatten().collect();
    let geo_edges = metrics::geometry_edges(&geo, w, h);
    let mut report = CheckReport {
        dir: dir.display().to_string(),
        width: dump.width,
        height: dump.height,
        band,
        triangles: reference.triangle_count(),
        lights: Vec::new(),
    };
    for (k, l) in lights.iter().enumerate() {
        let states: Vec<LightState> = (0..w * h).map(|i| all[i * nl + k]).collect();
        let band_mask = metrics::band_mask(&states, &geo_edges, w, h, band);
        let m = metrics::compare_states(&dump.shadow[k], &states, &band_mask);
        report.lights.push(LightCheck {
            index: k,
            position: dump.lights[k].position.to_array(),
            kind: match l.kind {
                LightKind::Point => "point",
                LightKind::Spot => "spot",
                LightKind::Directional => "directional",
            }
            .to_string(),
            metrics: m,
        });
    }
    Ok(report)
}

#[cfg(test)]
mod tests;
