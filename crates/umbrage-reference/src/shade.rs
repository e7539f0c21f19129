//! Light visibility: the per-point decision of the module rules (range, cone, facing,
//! occlusion and their ambiguity tests), the camera rays that find the visible surface of each
//! pixel, and the row-parallel rendering of a [`RefImage`].

use super::{LightState, RefImage, RefPixel, Reference};
use glam::DVec3;
use umbrage_scene::{Camera, Light, LightKind};

impl Reference {
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
    pub(super) fn light_precheck(&self, p: DVec3, n: DVec3, light: &Light, r: f64) -> Option<LightState> {
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
        self.shadow_segment(p, n, light).is_some_and(|(o, d, t_max)| {
            self.occluders.any_hit(o, d, 0.0, t_max, |t| self.filter(t) != [0.0; 3]) || self.sphere_blocks(o, d, t_max)
        })
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
                        st.extend(std::iter::repeat_n(LightState::Background, nl));
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
        let hit = self.visible.closest_hit(o, d, 0.0, f64::INFINITY);
        // An exact sphere in front of the nearest triangle is what the pixel sees.
        let t_tri = hit.as_ref().map_or(f64::INFINITY, |h| h.t);
        let (p, n, mesh, tri) = match self.sphere_hit(o, d, t_tri) {
            Some((t_s, s)) => {
                let p = o + d * t_s;
                ((p), (p - s.sphere.center) / s.sphere.radius, s.mesh, u32::MAX)
            }
            None => {
                let hit = hit?;
                let t = &self.tris[hit.tri as usize];
                let p = t[0] * (1.0 - hit.u - hit.v) + t[1] * hit.u + t[2] * hit.v;
                // The visible side of the surface: its geometric normal turned towards the eye (a
                // closed, outward mesh is only ever seen from the front, so this changes nothing
                // there; open and two-sided surfaces are lit on the side the eye sees when that side
                // faces the light).
                let n = (t[1] - t[0]).cross(t[2] - t[0]).normalize();
                (p, if n.dot(d) > 0.0 { -n } else { n }, self.mesh_of[hit.tri as usize], hit.tri)
            }
        };
        let depth = (p - eye).length();
        let r = self.tolerance.footprint_fraction * depth * pix_angle;
        let pixel = RefPixel { hit: true, position: p.as_vec3(), normal: n.as_vec3(), depth: depth as f32, mesh, tri };
        Some((pixel, p, n, r))
    }
}

impl Reference {
    /// The nearest sphere the ray `o + t d` enters before `t_max` (the eye is outside every
    /// sphere: scenes refuse it), with its `t`.
    fn sphere_hit(&self, o: DVec3, d: DVec3, t_max: f64) -> Option<(f64, &super::RefSphere)> {
        let mut best: Option<(f64, &super::RefSphere)> = None;
        for s in &self.spheres {
            if let Some(t) = s.sphere.ray_hit(o, d, 0.0, best.map_or(t_max, |b| b.0)) {
                best = Some((t, s));
            }
        }
        best
    }

    /// Whether a shadow-casting sphere meets the segment `o + t d`, `0 < t < t_max`.
    pub(crate) fn sphere_blocks(&self, o: DVec3, d: DVec3, t_max: f64) -> bool {
        self.spheres.iter().any(|s| s.occluder && s.sphere.ray_hit(o, d, 0.0, t_max).is_some())
    }
}

/// An orthonormal basis of the plane orthogonal to unit `n` (Duff et al. 2017).
pub(super) fn tangent_basis(n: DVec3) -> (DVec3, DVec3) {
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
