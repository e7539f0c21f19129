//! `umbrage check`: a frame dump judged against the reference at the GPU's own surface points.

use super::metrics::{self, Metrics};
use super::shade::par_rows;
use super::{read_dump, Dump, LightState, Reference};
use glam::DVec3;
use std::fmt;
use umbrage::error::Result;
use umbrage_scene::Light;

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
    /// The first 32 pixels counted in `metrics.mismatches_outside_band`, as `[x, y]`, in row
    /// order: where to look first.
    pub mismatched: Vec<[u32; 2]>,
}

/// At most this many mismatched pixels are listed per light ([`LightCheck::mismatched`]).
const LISTED_MISMATCHES: usize = 32;

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
            if !l.mismatched.is_empty() {
                let at: Vec<String> = l.mismatched.iter().map(|[x, y]| format!("({x}, {y})")).collect();
                let more = if m.mismatches_outside_band as usize > at.len() { ", ..." } else { "" };
                writeln!(f, "    mismatched at {}{more}", at.join(", "))?;
            }
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
    check(&read_dump(dir)?, &dir.display().to_string(), band)
}

/// [`check_dump`] on a dump in memory (a host checking its own frames without writing them):
/// `name` is what the report's `dir` says.
pub fn check(dump: &Dump, name: &str, band: u32) -> Result<CheckReport> {
    dump.validate(name)?;
    let lights: Vec<Light> = dump.lights.iter().map(|l| l.to_light()).collect::<Result<_>>()?;
    let spheres: Vec<super::RefSphere> =
        dump.spheres.iter().enumerate().map(|(i, &sphere)| super::RefSphere { sphere, occluder: true, mesh: i as u32 }).collect();
    let reference = Reference::from_triangles(dump.triangles.iter().map(|t| [t[0].as_dvec3(), t[1].as_dvec3(), t[2].as_dvec3()]).collect())
        .with_spheres(&spheres);
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
                out.extend(std::iter::repeat_n(LightState::Background, nl));
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
        dir: name.to_string(),
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
        let mismatched = metrics::mismatches_outside_band(&dump.shadow[k], &states, &band_mask, LISTED_MISMATCHES)
            .into_iter()
            .map(|i| [(i % w) as u32, (i / w) as u32])
            .collect();
        report.lights.push(LightCheck {
            index: k,
            position: dump.lights[k].position.to_array(),
            kind: l.kind.name().to_string(),
            metrics: m,
            mismatched,
        });
    }
    Ok(report)
}
