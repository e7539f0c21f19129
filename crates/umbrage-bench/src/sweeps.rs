//! The suite's points (which scene, at which size, along which sweep), each row's fractions
//! of the limits and its bound, and the crossovers found along the sweeps.

use super::report::{Crossover, RowLimits, SuiteRow};
use super::scenes::SweepScene;

/// How many points: the full suite, `--quick` (under 6 minutes on lavapipe on 2 quiet cores),
/// or the tiny one the tests run (two points a sweep, small targets).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Scale {
    /// Every point.
    Full,
    /// Fewer points and frames.
    Quick,
    /// Two points a sweep at a small size (tests).
    Tiny,
}

/// Where a point's scene comes from.
#[derive(Clone, Debug, PartialEq)]
pub enum PointScene {
    /// A built-in scene or a scene file ([`umbrage_scene::load`]).
    Named(String),
    /// The parametric sphere grid.
    Param(SweepScene),
}

/// One point of a sweep.
#[derive(Clone, Debug, PartialEq)]
pub struct SweepPoint {
    /// The sweep's name (`resolution`, `tessellation`, `lights`, `light_distance`, `casters`,
    /// `caps`: the z-fail methods only, on `bench/caps`; the one-factor sweeps on one grid of
    /// spheres, each moving one count while the others stay: [`ONE_FACTOR`]).
    pub sweep: &'static str,
    /// The sweep variable's value.
    pub x: f64,
    /// The scene.
    pub scene: PointScene,
    /// Frame size.
    pub size: (u32, u32),
}

impl Scale {
    /// The base frame size (named scenes, ablations and the parametric sweeps).
    pub fn base_size(self) -> (u32, u32) {
        match self {
            Scale::Tiny => (160, 90),
            _ => (960, 540),
        }
    }
    /// Timed frames per variant (after a warm-up frame).
    pub fn frames(self) -> usize {
        match self {
            Scale::Full => 11,
            Scale::Quick => 7,
            Scale::Tiny => 1,
        }
    }
    /// Timed frames a side of each bound's ablation ([`super::proof`]): enough for a
    /// p10–p90 spread, fewer than the sweeps' (the ablations re-time most rows).
    pub fn proof_frames(self) -> usize {
        match self {
            Scale::Full => 9,
            Scale::Quick | Scale::Tiny => 4,
        }
    }
    /// Wall seconds a point's timed rounds may take before its frames are cut (to no fewer
    /// than [`super::suite::MIN_FRAMES`]): only the heaviest points (32 lights) reach it.
    pub fn point_budget_s(self) -> f64 {
        match self {
            Scale::Full => 120.0,
            Scale::Quick => 30.0,
            Scale::Tiny => f64::INFINITY,
        }
    }
    /// Shadow-map sizes every sweep point runs (the quick suite's sweeps: the smallest only,
    /// a big map with multiview faces costing as much as five volume methods there).
    pub fn shadow_map_sizes(self) -> Vec<u32> {
        match self {
            Scale::Full => vec![512, 1024, 2048, 4096],
            Scale::Quick | Scale::Tiny => vec![512],
        }
    }
    /// Shadow-map sizes the named scenes run (with their error: the Pareto chart).
    pub fn named_shadow_map_sizes(self) -> Vec<u32> {
        match self {
            Scale::Full => vec![512, 1024, 2048, 4096],
            Scale::Quick => vec![512, 2048],
            Scale::Tiny => vec![512],
        }
    }
}

/// The one-factor sweeps: `casters_same_triangles` (the same spheres merged into fewer
/// casters: draws change, triangles and coverage do not), `triangles_same_casters` (the
/// spheres' tessellation: triangles change, casters and coverage about not) and
/// `coverage_same_triangles` (the light's height: stencil fragments change, triangles and
/// casters do not). The older sweeps move several counts at once (the `casters` sweep grows
/// casters and triangles together), which the model alone cannot separate.
pub const ONE_FACTOR: [&str; 3] = ["casters_same_triangles", "triangles_same_casters", "coverage_same_triangles"];

/// The one-factor sweeps' grid at `scale`: spheres, triangles per sphere, the casters the
/// triangle and coverage sweeps merge the spheres into.
pub fn one_factor_grid(scale: Scale) -> (u32, u64, u32) {
    match scale {
        Scale::Tiny => (16, 64, 4),
        _ => (256, 512, 16),
    }
}

/// The one-factor sweeps' points (see [`ONE_FACTOR`]), around one centre point the three
/// share (the full and quick suites; two in the tiny one), measured once: the suite takes its
/// rows for the sweeps after the first. The casters sweep's far end is the plain grid, the
/// `casters` sweep's point of that size (taken from it too).
fn one_factor_points(scale: Scale) -> Vec<SweepPoint> {
    let base = scale.base_size();
    let (spheres, per, groups) = one_factor_grid(scale);
    let grid = SweepScene { casters: spheres, triangles: spheres as u64 * per, groups: Some(groups), ..SweepScene::default() };
    // One caster per sphere: the plain grid (the `casters` sweep's point of that size, a repeat).
    let grouped = |g: u32| SweepScene { groups: (g < spheres).then_some(g), ..grid };
    let (casters, tess, heights): (Vec<u32>, Vec<u64>, Vec<f32>) = match scale {
        Scale::Full => (vec![1, 4, 16, 64, 256], vec![128, 256, 512, 1024, 2048], vec![0.5, 1.0, 1.5, 4.0, 16.0]),
        Scale::Quick => (vec![1, 16, 256], vec![128, 512, 1024], vec![0.5, 1.5, 8.0]),
        Scale::Tiny => (vec![1, 16], vec![32, 64], vec![1.5, 4.0]),
    };
    let point = |sweep: &'static str, x: f64, p: SweepScene| SweepPoint { sweep, x, scene: PointScene::Param(p), size: base };
    let mut out = Vec::new();
    for g in casters {
        out.push(point(ONE_FACTOR[0], grouped(g).caster_count() as f64, grouped(g)));
    }
    for t in tess {
        let p = SweepScene { triangles: spheres as u64 * t, ..grid };
        out.push(point(ONE_FACTOR[1], p.built_triangles() as f64, p));
    }
    for h in heights {
        out.push(point(ONE_FACTOR[2], h as f64, SweepScene { light_height: h, ..grid }));
    }
    out
}

/// Every sweep's points at `scale`.
pub fn points(scale: Scale) -> Vec<SweepPoint> {
    let pick = |full: &[f64], quick: &[f64], tiny: &[f64]| -> Vec<f64> {
        match scale {
            Scale::Full => full.to_vec(),
            Scale::Quick => quick.to_vec(),
            Scale::Tiny => tiny.to_vec(),
        }
    };
    let base = scale.base_size();
    let mut out = Vec::new();
    let sizes: Vec<(u32, u32)> = match scale {
        Scale::Full => vec![(320, 180), (640, 360), (960, 540), (1280, 720), (1920, 1080)],
        Scale::Quick => vec![(320, 180), (960, 540), (1920, 1080)],
        Scale::Tiny => vec![(80, 45), (160, 90)],
    };
    for s in sizes {
        out.push(SweepPoint { sweep: "resolution", x: (s.0 * s.1) as f64, scene: PointScene::Named("bench/fill".into()), size: s });
    }
    let d = SweepScene::default();
    let param = |sweep: &'static str, x: f64, p: SweepScene| SweepPoint { sweep, x, scene: PointScene::Param(p), size: base };
    for t in pick(&[1e3, 4e3, 16e3, 64e3, 256e3, 1e6, 2e6], &[1e3, 16e3, 256e3], &[1e3, 4e3]) {
        let p = SweepScene { triangles: t as u64, ..d };
        out.push(param("tessellation", p.built_triangles() as f64, p));
    }
    for l in pick(&[1.0, 4.0, 16.0, 64.0, 256.0], &[1.0, 4.0, 8.0], &[1.0, 4.0]) {
        out.push(param("lights", l, SweepScene { lights: l as u32, ..d }));
    }
    for h in pick(&[0.25, 0.5, 1.0, 2.0, 4.0, 8.0, 16.0], &[0.25, 2.0, 16.0], &[0.25, 4.0]) {
        out.push(param("light_distance", h, SweepScene { light_height: h as f32, ..d }));
    }
    for c in pick(&[1.0, 4.0, 16.0, 64.0, 256.0], &[1.0, 16.0, 256.0], &[1.0, 4.0]) {
        out.push(param("casters", c, SweepScene { casters: c as u32, triangles: c as u64 * 512, ..d }));
    }
    out.extend(one_factor_points(scale));
    // The paper's claim: McGuire's O(s) dark-cap fans against the O(f) caps, growing pixels.
    let caps: Vec<(u32, u32)> = match scale {
        Scale::Full => vec![(480, 270), (960, 540), (1280, 720), (1920, 1080), (2560, 1440)],
        Scale::Quick => vec![(480, 270), (960, 540), (1920, 1080), (2560, 1440)],
        Scale::Tiny => vec![(80, 45), (160, 90)],
    };
    for s in caps {
        out.push(SweepPoint { sweep: "caps", x: (s.0 * s.1) as f64, scene: PointScene::Named("bench/caps".into()), size: s });
    }
    out
}

/// Whether shadow maps of `size` run with `lights` lights: a point light renders six faces a
/// frame, so big maps with many lights are left out (lights x size^2 <= 2^26 texels).
pub fn shadow_map_fits(size: u32, lights: usize) -> bool {
    lights as u64 * (size as u64).pow(2) <= 1 << 26
}

/// Fills in a row's CPU fraction, its bound (the largest of its fill, vertex and draw
/// shares, which the cost model filled in from the terms the rows identify
/// ([`SuiteRow::bound_shares`]; the fractions where the model left none), and its CPU
/// fraction) and whether the bound is claimed: the lead over the next share exceeds the
/// row's spread ((p90 - p10) / median of its timed frames) or the model's held-out error on
/// it, whichever is larger, plus the share of unidentified terms (which could belong to the
/// next). A claimed bound is not yet proven ([`SuiteRow::bound_confirmed`]: its ablation).
pub fn classify(row: &mut SuiteRow, limits: RowLimits) {
    row.limits = limits;
    let Some(t) = row.gpu_shadow_ms.filter(|t| *t > 0.0) else {
        row.bound = "none".into();
        row.bound_clear = false;
        return;
    };
    row.cpu_fraction = Some(row.cpu_plan_ms / t);
    let (fill, vertex, draw) = match row.bound_shares {
        Some(s) => (Some(s.fill), Some(s.vertex), Some(s.draw)),
        None => (row.fill_fraction, row.vertex_fraction, row.draw_fraction),
    };
    let mut candidates: Vec<(&str, f64)> = [("fill", fill), ("vertex", vertex), ("draw", draw), ("cpu", row.cpu_fraction)]
        .iter()
        .filter_map(|(n, f)| f.filter(|f| f.is_finite()).map(|f| (*n, f)))
        .collect();
    candidates.sort_by(|a, b| b.1.total_cmp(&a.1));
    row.bound = candidates.first().map_or("none", |c| c.0).to_string();
    let spread = match (row.gpu_shadow_ms_p10, row.gpu_shadow_ms_p90) {
        (Some(lo), Some(hi)) => (hi - lo) / t,
        _ => 0.0,
    };
    let margin = spread.max(row.model_rel_error.unwrap_or(0.0)) + row.unidentified_fraction.unwrap_or(0.0).max(0.0);
    row.bound_clear = match candidates.as_slice() {
        [] => false,
        [_] => true,
        [a, b, ..] => a.1 - b.1 > margin,
    };
}

/// `x` where `a(x) - b(x)` crosses zero between two points, on a log scale of x (linear
/// when a point is at or below 0).
fn interpolate(x0: f64, x1: f64, d0: f64, d1: f64) -> f64 {
    let t = if (d0 - d1).abs() > 0.0 { d0 / (d0 - d1) } else { 0.5 };
    let t = t.clamp(0.0, 1.0);
    if x0 > 0.0 && x1 > 0.0 {
        (x0.ln() + t * (x1.ln() - x0.ln())).exp()
    } else {
        x0 + t * (x1 - x0)
    }
}

fn fraction(r: &SuiteRow, bound: &str) -> f64 {
    match bound {
        "fill" => r.fill_fraction,
        "vertex" => r.vertex_fraction,
        "draw" => r.draw_fraction,
        "cpu" => r.cpu_fraction,
        _ => None,
    }
    .unwrap_or(0.0)
}

/// Whether two rows' timed-frame spreads ([p10, p90]) do not overlap (without spreads: the
/// medians differ).
fn apart(a: &SuiteRow, b: &SuiteRow) -> bool {
    match (a.gpu_shadow_ms_p10, a.gpu_shadow_ms_p90, b.gpu_shadow_ms_p10, b.gpu_shadow_ms_p90) {
        (Some(alo), Some(ahi), Some(blo), Some(bhi)) => ahi < blo || bhi < alo,
        _ => a.gpu_shadow_ms != b.gpu_shadow_ms,
    }
}

/// Along each sweep: per method, where its bound changes (proven bounds only: both rows'
/// ablations confirmed them); per pair of methods, where the faster one changes (GPU shadow
/// time).
pub fn crossovers(rows: &[SuiteRow]) -> Vec<Crossover> {
    let mut out = Vec::new();
    let mut sweeps: Vec<&str> = Vec::new();
    for r in rows {
        if !sweeps.contains(&r.sweep.as_str()) && !matches!(r.sweep.as_str(), "scenes" | "ablation") {
            sweeps.push(&r.sweep);
        }
    }
    for sweep in sweeps {
        let mut methods: Vec<&str> = Vec::new();
        for r in rows.iter().filter(|r| r.sweep == sweep) {
            if !methods.contains(&r.method.as_str()) {
                methods.push(&r.method);
            }
        }
        let series = |m: &str| -> Vec<&SuiteRow> {
            let mut v: Vec<&SuiteRow> = rows.iter().filter(|r| r.sweep == sweep && r.method == m).collect();
            v.sort_by(|a, b| a.x.total_cmp(&b.x));
            v
        };
        for &m in &methods {
            let s = series(m);
            for w in s.windows(2) {
                let (a, b) = (w[0], w[1]);
                if a.bound != b.bound && a.bound_confirmed && b.bound_confirmed {
                    let d0 = fraction(a, &a.bound) - fraction(a, &b.bound);
                    let d1 = fraction(b, &a.bound) - fraction(b, &b.bound);
                    out.push(Crossover {
                        kind: "bound".into(),
                        sweep: sweep.into(),
                        method: m.into(),
                        from: a.bound.clone(),
                        to: b.bound.clone(),
                        between: [a.x, b.x],
                        at: interpolate(a.x, b.x, d0, d1),
                    });
                }
            }
        }
        for (i, &ma) in methods.iter().enumerate() {
            for &mb in &methods[i + 1..] {
                let (sa, sb) = (series(ma), series(mb));
                let pairs: Vec<(f64, f64, f64, bool)> = sa
                    .iter()
                    .filter_map(|a| {
                        let b = sb.iter().find(|b| b.x == a.x)?;
                        Some((a.x, a.gpu_shadow_ms?, b.gpu_shadow_ms?, apart(a, b)))
                    })
                    .collect();
                for w in pairs.windows(2) {
                    let (d0, d1) = (w[0].1 - w[0].2, w[1].1 - w[1].2);
                    // Claimed only where the order holds beyond the spread at both points.
                    if d0 * d1 < 0.0 && w[0].3 && w[1].3 {
                        let (before, after) = if d0 < 0.0 { (ma, mb) } else { (mb, ma) };
                        out.push(Crossover {
                            kind: "overtake".into(),
                            sweep: sweep.into(),
                            method: after.into(),
                            from: before.into(),
                            to: after.into(),
                            between: [w[0].0, w[1].0],
                            at: interpolate(w[0].0, w[1].0, d0, d1),
                        });
                    }
                }
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::super::report::BoundShares;
    use super::*;

    /// A row whose model fractions are fill = frags / 1e9 / s and vertex = tris / 1e6 / s (a
    /// 1 Gfragment/s, 1 Mtriangle/s device), with a 1 % spread.
    fn row(sweep: &str, method: &str, x: f64, frags: u64, tris: u64, ms: f64) -> SuiteRow {
        let secs = ms * 1e-3;
        let mut r = SuiteRow {
            sweep: sweep.into(),
            method: method.into(),
            x,
            stencil_fragments: Some(frags),
            shadow_triangles: tris,
            gpu_shadow_ms: Some(ms),
            gpu_shadow_ms_p10: Some(ms * 0.995),
            gpu_shadow_ms_p90: Some(ms * 1.005),
            fill_fraction: Some(frags as f64 / 1e9 / secs),
            vertex_fraction: Some(tris as f64 / 1e6 / secs),
            draw_fraction: Some(0.0),
            draws: 1,
            ..Default::default()
        };
        classify(&mut r, RowLimits::default());
        // As if every claimed bound's ablation confirmed it.
        r.bound_confirmed = r.bound_clear;
        r
    }

    #[test]
    fn fractions_and_bound() {
        let r = row("t", "m", 1.0, 1_000_000, 100, 2.0);
        assert_eq!(r.bound, "fill");
        assert!(r.bound_clear);
        let r = row("t", "m", 1.0, 1000, 1_000_000, 2.0);
        assert_eq!(r.bound, "vertex");
        // Fill and vertex within the spread: the bound is not claimed.
        let mut close = row("t", "m", 1.0, 1_000_000, 1_000, 2.0);
        close.gpu_shadow_ms_p10 = Some(1.0);
        close.gpu_shadow_ms_p90 = Some(3.0);
        classify(&mut close, RowLimits::default());
        assert!(!close.bound_clear);
        let mut none = SuiteRow::default();
        classify(&mut none, RowLimits::default());
        assert_eq!(none.bound, "none");
    }

    #[test]
    fn only_identified_terms_name_a_bound() {
        // Draw leads on the fractions, but the rows identify none of its terms: the identified
        // shares name fill, and only where fill leads by more than the unidentified share.
        let mut r = row("t", "m", 1.0, 1_000_000, 100, 2.0);
        r.fill_fraction = Some(0.3);
        r.draw_fraction = Some(0.6);
        r.bound_shares = Some(BoundShares { fill: 0.3, vertex: 0.05, draw: 0.0 });
        r.unidentified_fraction = Some(0.6);
        classify(&mut r, RowLimits::default());
        assert_eq!(r.bound, "fill");
        assert!(!r.bound_clear, "the unidentified 60 % could be the draws'");
        r.unidentified_fraction = Some(0.1);
        classify(&mut r, RowLimits::default());
        assert!(r.bound_clear && r.bound == "fill");
    }

    #[test]
    fn unproven_bounds_make_no_crossover() {
        let mut rows = vec![row("tess", "a", 10.0, 1_000_000, 500, 2.0), row("tess", "a", 100.0, 1_000_000, 10_000_000, 20.0)];
        assert_eq!(crossovers(&rows).iter().filter(|c| c.kind == "bound").count(), 1);
        rows[1].bound_confirmed = false;
        assert_eq!(crossovers(&rows).iter().filter(|c| c.kind == "bound").count(), 0);
    }

    #[test]
    fn crossovers_are_found_between_the_points() {
        // Fill constant, triangles growing: fill-bound, then vertex-bound between x=10 and 100.
        let rows = vec![
            row("tess", "a", 1.0, 1_000_000, 100, 2.0),
            row("tess", "a", 10.0, 1_000_000, 500, 2.0),
            row("tess", "a", 100.0, 1_000_000, 10_000_000, 20.0),
            row("tess", "b", 1.0, 1_000_000, 1_000, 1.0),
            row("tess", "b", 10.0, 1_000_000, 1_000, 3.0),
            row("tess", "b", 100.0, 1_000_000, 1_000, 30.0),
        ];
        let c = crossovers(&rows);
        let bound: Vec<_> = c.iter().filter(|c| c.kind == "bound").collect();
        assert_eq!(bound.len(), 1);
        assert_eq!((bound[0].from.as_str(), bound[0].to.as_str()), ("fill", "vertex"));
        assert_eq!(bound[0].between, [10.0, 100.0]);
        assert!(bound[0].at > 10.0 && bound[0].at < 100.0);
        let over: Vec<_> = c.iter().filter(|c| c.kind == "overtake").collect();
        assert_eq!(over.len(), 1);
        assert_eq!((over[0].method.as_str(), over[0].from.as_str()), ("a", "b"));
        assert_eq!(over[0].between, [1.0, 10.0]);
    }

    #[test]
    fn points_per_scale() {
        let quick = points(Scale::Quick);
        let full = points(Scale::Full);
        assert!(quick.len() < full.len());
        for s in ["resolution", "tessellation", "lights", "light_distance", "casters", "caps"].into_iter().chain(ONE_FACTOR) {
            assert!(points(Scale::Tiny).iter().filter(|p| p.sweep == s).count() == 2, "{s}");
        }
        let tess: Vec<f64> = full.iter().filter(|p| p.sweep == "tessellation").map(|p| p.x).collect();
        assert!(tess[0] < 1.5e3 && *tess.last().unwrap() > 1.5e6, "{tess:?}");
        assert!(shadow_map_fits(4096, 1) && !shadow_map_fits(4096, 256) && shadow_map_fits(512, 256));
    }

    #[test]
    fn the_one_factor_sweeps_share_their_centre() {
        for scale in [Scale::Tiny, Scale::Quick, Scale::Full] {
            let all = points(scale);
            // Every one-factor point but the first of each scene repeats one listed before it.
            let shared = all
                .iter()
                .enumerate()
                .filter(|(i, p)| ONE_FACTOR.contains(&p.sweep) && all[..*i].iter().any(|q| q.scene == p.scene && q.size == p.size))
                .count();
            assert!(shared >= if scale == Scale::Tiny { 1 } else { 3 }, "{scale:?}: {shared} shared");
        }
    }

    #[test]
    fn each_one_factor_sweep_moves_one_count() {
        for scale in [Scale::Tiny, Scale::Quick, Scale::Full] {
            let of = |sweep: &str| -> Vec<SweepScene> {
                points(scale)
                    .into_iter()
                    .filter(|p| p.sweep == sweep)
                    .map(|p| match p.scene {
                        PointScene::Param(s) => s,
                        other => panic!("{other:?}"),
                    })
                    .collect()
            };
            let casters = of(ONE_FACTOR[0]);
            assert!(casters.len() >= 2);
            // The same triangles, as few and as many casters as there are spheres.
            assert!(casters
                .iter()
                .all(|s| s.built_triangles() == casters[0].built_triangles() && s.light_height == casters[0].light_height));
            let counts: Vec<u32> = casters.iter().map(|s| s.caster_count()).collect();
            assert_eq!((counts[0], *counts.last().unwrap()), (1, casters[0].casters), "{counts:?}");
            // Tessellation: the same casters, more triangles.
            let tess = of(ONE_FACTOR[1]);
            assert!(tess.iter().all(|s| s.caster_count() == tess[0].caster_count() && s.light_height == tess[0].light_height));
            assert!(tess.windows(2).all(|w| w[0].built_triangles() < w[1].built_triangles()));
            // Coverage: the same casters and triangles, the light moves.
            let cover = of(ONE_FACTOR[2]);
            assert!(cover.iter().all(|s| s.caster_count() == cover[0].caster_count() && s.built_triangles() == cover[0].built_triangles()));
            assert!(cover.windows(2).all(|w| w[0].light_height < w[1].light_height));
        }
    }
}
