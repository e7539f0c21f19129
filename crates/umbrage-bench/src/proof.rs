//! Every bound the report claims, proven by an ablation in the same run (issue #38). Where the
//! model names a row fill-, vertex- or draw-bound clearly (its *candidate*), the row's work is
//! cut where that bound says the time goes — fill: the same volumes at half the width and
//! height; vertex: a coarser tessellation of the same shapes ([`super::reshape::coarser`]);
//! draw: the casters merged into one ([`super::reshape::merged_casters`]) — and timed beside
//! the row. The candidate is *confirmed*, and only then claimed, when the measured saving is
//! beyond the two timings' spread and agrees with the model's predicted saving (its time for
//! the row's counted work less its time for the ablated work's) within that spread
//! ([`decide`]); otherwise the ablation refutes it (a disagreement the report lists).
//!
//! Where the ablated work is a point the sweeps measured anyway ([`ablated_point`]: the
//! resolution and caps sweeps' half sizes, the one-factor triangles sweep's quarter, the
//! one-factor casters sweep's single caster, each measured right after its partner), the two
//! rows are compared as measured; every other candidate row is re-timed right before its
//! ablation, rows sharing a scene and a size on one renderer, then one ablated scene per kind.

use super::model::Model;
use super::report::{ProofSummary, RowAblation, SuiteRow};
use super::reshape::{coarser, merged_casters};
use super::runner::{scene_of, Point, Runner, Variant};
use super::scenes::SweepScene;
use super::sweeps::PointScene;
use std::time::Instant;
use umbrage::error::Result;
use umbrage_render::Renderer;
use umbrage_scene::Scene;

/// How a row was measured: what [`prove`] needs to measure it again.
#[derive(Clone, Debug)]
pub(super) struct Origin {
    /// The scene.
    pub scene: PointScene,
    /// The frame size.
    pub size: (u32, u32),
    /// The technique and pass settings.
    pub variant: Variant,
}

/// A row's median GPU shadow time and the p10–p90 of its timed frames, ms.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Timing {
    /// Median.
    pub median: f64,
    /// 10th percentile.
    pub p10: f64,
    /// 90th percentile.
    pub p90: f64,
}

impl Timing {
    /// `r`'s timing (`None` untimed).
    pub fn of(r: &SuiteRow) -> Option<Timing> {
        let median = r.gpu_shadow_ms.filter(|t| t.is_finite())?;
        Some(Timing { median, p10: r.gpu_shadow_ms_p10.unwrap_or(median), p90: r.gpu_shadow_ms_p90.unwrap_or(median) })
    }
}

/// One ablation's verdict ([`decide`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Verdict {
    /// Baseline median less ablated median, ms.
    pub measured: f64,
    /// Half the sum of the two p10–p90 widths, ms.
    pub spread: f64,
    /// Measured beyond the spread, and within the spread of the prediction.
    pub confirmed: bool,
    /// In words.
    pub why: String,
}

/// Whether an ablation confirms the bound it tests: the saving measured (`base` median less
/// `ablated` median) exceeds the spread (half the sum of the two timings' p10–p90 widths: a
/// real saving, not repeat-timing noise) and lies within the spread of `predicted` (the
/// model's saving). Non-finite inputs, and timings without a spread (a single frame: no
/// repeat to tell a saving from noise), confirm nothing.
pub fn decide(base: Timing, ablated: Timing, predicted: f64) -> Verdict {
    let measured = base.median - ablated.median;
    let spread = ((base.p90 - base.p10).max(0.0) + (ablated.p90 - ablated.p10).max(0.0)) / 2.0;
    let (confirmed, why) = if !(measured.is_finite() && spread.is_finite() && predicted.is_finite()) {
        (false, "no finite timing or prediction".to_string())
    } else if spread <= 0.0 {
        (false, format!("saved {measured:.3} ms with no spread to judge it by (one frame a side?)"))
    } else if measured <= spread {
        (false, format!("saved {measured:.3} ms, within the spread ({spread:.3} ms); the model predicted {predicted:.3} ms"))
    } else if (measured - predicted).abs() > spread {
        (false, format!("saved {measured:.3} ms where the model predicted {predicted:.3} ms (spread {spread:.3} ms)"))
    } else {
        (true, format!("saved {measured:.3} ms, the model predicted {predicted:.3} ms (spread {spread:.3} ms)"))
    };
    Verdict { measured, spread, confirmed, why }
}

/// The ablation a bound calls for (`fill`, `vertex`, `draw`); `None` for others (`cpu`: the
/// GPU time's share is not the CPU's).
pub fn kind_of(bound: &str) -> Option<&'static str> {
    ["fill", "vertex", "draw"].into_iter().find(|k| *k == bound)
}

/// Half the width and height (`None` below 2 pixels either way).
pub fn half_size((w, h): (u32, u32)) -> Option<(u32, u32)> {
    (w >= 2 && h >= 2).then_some((w / 2, h / 2))
}

/// The point a `kind` ablation of `scene` at `size` renders, where it is a point a sweep may
/// have measured: the same scene at half the size (fill), the sphere grid with a quarter of
/// the triangles (vertex), the same spheres as one caster (draw). `None` where the ablation
/// renders a scene no sweep has (a named scene coarsened or merged) or cannot run.
pub fn ablated_point(kind: &str, scene: &PointScene, size: (u32, u32)) -> Option<(PointScene, (u32, u32))> {
    match (kind, scene) {
        ("fill", _) => Some((scene.clone(), half_size(size)?)),
        ("vertex", PointScene::Param(s)) => {
            let c = SweepScene { triangles: s.triangles / 4, ..*s };
            (c.built_triangles() < s.built_triangles()).then_some((PointScene::Param(c), size))
        }
        ("draw", PointScene::Param(s)) => (s.caster_count() > 1).then_some((PointScene::Param(SweepScene { groups: Some(1), ..*s }), size)),
        _ => None,
    }
}

/// Rows of one scene and size with a candidate bound to re-time.
struct Group {
    scene: PointScene,
    size: (u32, u32),
    rows: Vec<usize>,
}

/// An ablation's measured rows, or why it could not run; its scene's name and size.
struct Ablated {
    rows: std::result::Result<Vec<(SuiteRow, Variant)>, String>,
    scene: String,
    size: (u32, u32),
}

/// Measures `variants` on `scene` at `size` with a renderer of its own.
fn measure_on(run: &mut Runner, scene: Scene, name: &str, size: (u32, u32), variants: &[Variant]) -> Ablated {
    let rows = match run.renderer(scene, size) {
        Ok(mut r) => {
            let rows = run.measure(&mut r, Point { sweep: "proof", x: 0.0, name }, variants, false);
            run.release(r);
            rows.map_err(|e| format!("not run: {e}"))
        }
        Err(e) => Err(format!("not run: {e}")),
    };
    Ablated { rows, scene: name.to_string(), size }
}

/// Measures `variants` on `r` resized to half its size.
fn measure_half(run: &mut Runner, r: &mut Renderer, name: &str, size: (u32, u32), variants: &[Variant]) -> Ablated {
    let Some(half) = half_size(size) else {
        return Ablated { rows: Err("not run: under 2 pixels to halve".into()), scene: name.into(), size };
    };
    let rows = match r.resize(half.0, half.1) {
        Ok(()) => run.measure(r, Point { sweep: "proof", x: 0.0, name }, variants, false).map_err(|e| format!("not run: {e}")),
        Err(e) => Err(format!("not run: {e}")),
    };
    Ablated { rows, scene: name.into(), size: half }
}

/// Relative change allowed in the work an ablation must leave alone ([`isolation`]).
pub const ISOLATION_TOLERANCE: f64 = 0.02;

/// Why `kind`'s ablation (`base` against `ablated`, their counted work) does not test the bound
/// alone, or `None` where it does: it must cut the bound's work and leave the rest within
/// [`ISOLATION_TOLERANCE`] — fill: the volumes' triangles, draws and (light, caster) passes
/// (half the size changes none of them unless culling or a case moves); vertex: the draws and
/// passes (the fragments move with the coarser outline, counted by the prediction); draw: the
/// shadow triangles and fragments (merging casters keeps the volumes unless it changes a
/// caster's case or culling, as a merged caster under lights of limited range does).
pub fn isolation(kind: &str, base: &SuiteRow, ablated: &SuiteRow) -> Option<String> {
    let moved = |what: &str, a: Option<u64>, b: Option<u64>| -> Option<String> {
        let (a, b) = (a? as f64, b? as f64);
        let change = (b - a).abs() / a.max(b).max(1.0);
        (change > ISOLATION_TOLERANCE).then(|| format!("{what} {a:.0} -> {b:.0}"))
    };
    let triangles = moved("shadow triangles", Some(base.shadow_triangles), Some(ablated.shadow_triangles));
    let draws = moved("draws", Some(base.draws), Some(ablated.draws));
    let passes = moved("caster passes", Some(base.caster_passes), Some(ablated.caster_passes));
    let fragments = moved("stencil fragments", base.stencil_fragments, ablated.stencil_fragments);
    let changed: Vec<String> = match kind {
        "fill" => [triangles, draws, passes].into_iter().flatten().collect(),
        "vertex" => [draws, passes].into_iter().flatten().collect(),
        _ => [triangles, fragments].into_iter().flatten().collect(),
    };
    (!changed.is_empty()).then(|| format!("not isolated: the {kind} ablation also changed {}", changed.join(", ")))
}

/// `kind`'s ablation of the row timed as `base`, the ablated work timed as `ablated`: the
/// model's predicted saving against the measured one, where the ablation cuts the bound's
/// work alone ([`isolation`]; otherwise no test, and the verdict says what else moved).
fn judge(kind: &str, base: &SuiteRow, ablated: &SuiteRow, model: &Model, frames: usize) -> RowAblation {
    let mut a = RowAblation { kind: kind.into(), frames, ..Default::default() };
    if let Some(why) = isolation(kind, base, ablated) {
        (a.baseline_ms, a.ablated_ms, a.verdict) = (base.gpu_shadow_ms, ablated.gpu_shadow_ms, why);
        return a;
    }
    match (Timing::of(base), Timing::of(ablated), model.predict(base), model.predict(ablated)) {
        (Some(tb), Some(tx), Some(pb), Some(px)) => {
            let v = decide(tb, tx, pb - px);
            a.predicted_saving_ms = Some(pb - px);
            a.measured_saving_ms = Some(v.measured);
            a.spread_ms = Some(v.spread);
            a.baseline_ms = Some(tb.median);
            a.ablated_ms = Some(tx.median);
            a.confirmed = v.confirmed;
            a.verdict = v.why;
        }
        _ => a.verdict = "not run: untimed or without counters".into(),
    }
    a
}

/// Records `a` as row `r`'s ablation, counted in `summary`.
fn record(summary: &mut ProofSummary, r: &mut SuiteRow, a: RowAblation) {
    summary.claimed += 1;
    match a.predicted_saving_ms {
        Some(_) => {
            summary.ablated += 1;
            summary.confirmed += a.confirmed as usize;
            summary.refuted += !a.confirmed as usize;
            summary.from_sweep += a.from_sweep as usize;
        }
        None => summary.not_run += 1,
    }
    r.bound_confirmed = a.confirmed;
    r.ablation = Some(a);
}

/// Runs the ablation of every row where the model names a fill, vertex or draw bound clearly
/// (`rows[i]` measured as `origins[i]`) and fills in its `ablation` and `bound_confirmed`
/// against `model`'s predictions. Where the ablated work is itself a point the sweeps measured
/// with the same variant ([`ablated_point`]: the resolution and caps sweeps' half sizes, the
/// triangles sweep's quarter, the casters sweep's one caster), the two rows are compared as
/// they are, the nearest such point in measurement order; every other row is re-timed
/// (`frames` timed frames a side) right before its ablation, rows of one scene and size on one
/// renderer.
pub(super) fn prove(run: &mut Runner, rows: &mut [SuiteRow], origins: &[Origin], model: &Model, frames: usize) -> Result<ProofSummary> {
    let start = Instant::now();
    let mut summary = ProofSummary { frames, ..Default::default() };
    let mut groups: Vec<Group> = Vec::new();
    for i in 0..rows.len() {
        let Some(kind) = kind_of(&rows[i].bound).filter(|_| rows[i].bound_clear && Timing::of(&rows[i]).is_some()) else { continue };
        let o = &origins[i];
        let twin = ablated_point(kind, &o.scene, o.size).and_then(|(scene, size)| {
            (0..rows.len())
                .filter(|&j| j != i && origins[j].scene == scene && origins[j].size == size && origins[j].variant == o.variant)
                .filter(|&j| Timing::of(&rows[j]).is_some())
                .min_by_key(|&j| j.abs_diff(i))
        });
        if let Some(j) = twin {
            let mut a = judge(kind, &rows[i], &rows[j], model, rows[i].frames.min(rows[j].frames));
            a.from_sweep = true;
            a.ablated_scene = rows[j].scene.clone();
            a.ablated_size = [rows[j].width, rows[j].height];
            record(&mut summary, &mut rows[i], a);
            continue;
        }
        match groups.iter_mut().find(|g| g.scene == o.scene && g.size == o.size) {
            Some(g) => g.rows.push(i),
            None => groups.push(Group { scene: o.scene.clone(), size: o.size, rows: vec![i] }),
        }
    }
    let saved_frames = std::mem::replace(&mut run.frames, frames);
    run.bar.inc_length(groups.iter().map(|g| 2 * g.rows.len() as u64).sum());
    for g in &groups {
        let of_kind = |k: &str| -> Vec<Variant> {
            let mut v: Vec<Variant> = Vec::new();
            for &i in g.rows.iter().filter(|&&i| rows[i].bound == k) {
                if !v.contains(&origins[i].variant) {
                    v.push(origins[i].variant.clone());
                }
            }
            v
        };
        let (fill, vertex, draw) = (of_kind("fill"), of_kind("vertex"), of_kind("draw"));
        // A variant two rows share (the same point in two sweeps) is re-timed once.
        let mut all: Vec<Variant> = Vec::new();
        for v in fill.iter().chain(&vertex).chain(&draw) {
            if !all.contains(v) {
                all.push(v.clone());
            }
        }
        let (scene, name) = scene_of(&g.scene)?;
        run.bar.set_message(format!("proofs {name} {}x{}", g.size.0, g.size.1));
        let merged = match (draw.is_empty(), ablated_point("draw", &g.scene, g.size)) {
            (true, _) => None,
            (false, Some((p, _))) => Some(scene_of(&p)?),
            (false, None) => merged_casters(&scene, &name),
        };
        // The rows re-timed, then at half the size on the same renderer.
        let mut r = run.renderer(scene, g.size)?;
        summary.points += 1;
        let base = run.measure(&mut r, Point { sweep: "proof", x: 0.0, name: &name }, &all, false);
        let half = if fill.is_empty() { None } else { Some(measure_half(run, &mut r, &name, g.size, &fill)) };
        run.release(r);
        let base = base?;
        let coarse = match (vertex.is_empty(), coarser(&g.scene)) {
            (true, _) => None,
            (false, Ok(Some((s, n)))) => Some(measure_on(run, s, &n, g.size, &vertex)),
            (false, Ok(None)) => {
                Some(Ablated { rows: Err("not run: no coarser tessellation of these shapes".into()), scene: name.clone(), size: g.size })
            }
            (false, Err(e)) => Some(Ablated { rows: Err(format!("not run: {e}")), scene: name.clone(), size: g.size }),
        };
        let joined = match (draw.is_empty(), merged) {
            (true, _) => None,
            (false, Some((s, n))) => Some(measure_on(run, s, &n, g.size, &draw)),
            (false, None) => Some(Ablated { rows: Err("not run: one caster, nothing to merge".into()), scene: name.clone(), size: g.size }),
        };
        summary.points += coarse.is_some() as usize + joined.is_some() as usize;
        for &i in &g.rows {
            let kind = kind_of(&rows[i].bound).unwrap_or("fill");
            let ablated = match kind {
                "fill" => half.as_ref(),
                "vertex" => coarse.as_ref(),
                _ => joined.as_ref(),
            };
            let variant = &origins[i].variant;
            let find = |set: &[(SuiteRow, Variant)]| set.iter().find(|(_, v)| v == variant).map(|(r, _)| r.clone());
            let pair = match ablated.map(|ab| &ab.rows) {
                Some(Ok(set)) => match (find(&base), find(set)) {
                    (Some(b), Some(x)) => Ok((b, x)),
                    _ => Err("not run: the device skipped the variant".to_string()),
                },
                Some(Err(why)) => Err(why.clone()),
                None => Err("not run".to_string()),
            };
            let mut a = match pair {
                Ok((b, x)) => judge(kind, &b, &x, model, frames),
                Err(why) => RowAblation { kind: kind.into(), frames, verdict: why, ..Default::default() },
            };
            if let Some(ab) = ablated {
                a.ablated_scene = ab.scene.clone();
                a.ablated_size = [ab.size.0, ab.size.1];
            }
            record(&mut summary, &mut rows[i], a);
        }
    }
    run.frames = saved_frames;
    summary.seconds = start.elapsed().as_secs_f64();
    Ok(summary)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn t(median: f64, p10: f64, p90: f64) -> Timing {
        Timing { median, p10, p90 }
    }

    #[test]
    fn a_saving_beyond_the_spread_that_the_model_predicted_confirms() {
        // 10 -> 4 ms, spreads 1 and 0.6 ms: saving 6 beyond 0.8; predicted 5.5 within it.
        let v = decide(t(10.0, 9.5, 10.5), t(4.0, 3.7, 4.3), 5.5);
        assert!(v.confirmed, "{v:?}");
        assert!((v.measured - 6.0).abs() < 1e-12 && (v.spread - 0.8).abs() < 1e-12);
    }

    #[test]
    fn a_saving_the_model_did_not_predict_does_not_confirm() {
        // Merging 256 casters saved nothing: the draw bound the model named is not there.
        let v = decide(t(20.0, 19.0, 21.0), t(19.9, 19.0, 21.0), 15.0);
        assert!(!v.confirmed && v.why.contains("within the spread"), "{v:?}");
        // A real saving, but half what the model predicted.
        let v = decide(t(20.0, 19.8, 20.2), t(12.0, 11.8, 12.2), 16.0);
        assert!(!v.confirmed && v.why.contains("predicted 16.000"), "{v:?}");
        // More saved than predicted is a disagreement too.
        assert!(!decide(t(20.0, 19.8, 20.2), t(2.0, 1.8, 2.2), 10.0).confirmed);
        // No spread (one frame): no saving can be told from noise.
        assert!(!decide(t(10.0, 10.0, 10.0), t(5.0, 5.0, 5.0), 5.0).confirmed);
        // Slower when ablated, or nonsense in: never confirmed, no panic.
        assert!(!decide(t(5.0, 4.9, 5.1), t(6.0, 5.9, 6.1), -1.0).confirmed);
        assert!(!decide(t(f64::NAN, 1.0, 2.0), t(1.0, 1.0, 1.0), 1.0).confirmed);
        assert!(!decide(t(10.0, 9.0, 11.0), t(1.0, 0.5, 1.5), f64::INFINITY).confirmed);
    }

    #[test]
    fn an_ablation_that_moves_other_work_tests_nothing() {
        let row = |tris: u64, frags: u64, draws: u64, passes: u64| SuiteRow {
            shadow_triangles: tris,
            stencil_fragments: Some(frags),
            draws,
            caster_passes: passes,
            ..Default::default()
        };
        // Merging casters: the same volumes, fewer passes: a draw test.
        assert_eq!(isolation("draw", &row(1000, 5000, 256, 256), &row(1000, 5000, 256, 1)), None);
        // A merged caster that lost its culling draws more volumes: no draw test.
        let why = isolation("draw", &row(1000, 5000, 8, 8), &row(3000, 9000, 1, 1)).unwrap();
        assert!(why.contains("shadow triangles 1000 -> 3000") && why.contains("stencil fragments"), "{why}");
        // Half the size: a quarter of the fragments, the same triangles: a fill test.
        assert_eq!(isolation("fill", &row(1000, 4000, 4, 4), &row(1000, 1000, 4, 4)), None);
        assert!(isolation("fill", &row(1000, 4000, 4, 4), &row(900, 1000, 4, 4)).is_some());
        // Coarser: fewer triangles, the outline's fragments move a little: a vertex test.
        assert_eq!(isolation("vertex", &row(1000, 4000, 4, 4), &row(500, 3900, 4, 4)), None);
        assert!(isolation("vertex", &row(1000, 4000, 4, 4), &row(500, 3900, 2, 4)).is_some());
    }

    #[test]
    fn the_quick_sweeps_hold_their_own_ablations() {
        use super::super::sweeps::{points, Scale, ONE_FACTOR};
        let quick = points(Scale::Quick);
        let at = |sweep: &str, x: f64| quick.iter().find(|p| p.sweep == sweep && p.x == x).unwrap_or_else(|| panic!("{sweep} {x}"));
        let measured = |target: Option<(PointScene, (u32, u32))>| {
            let (scene, size) = target.expect("an ablation");
            quick.iter().any(|p| p.scene == scene && p.size == size)
        };
        // The 256 separate spheres merged: the one-factor casters sweep's single caster.
        let separate = at("casters", 256.0);
        let one = ablated_point("draw", &separate.scene, separate.size).unwrap();
        assert_eq!(one.0, at(ONE_FACTOR[0], 1.0).scene);
        // The centre's quarter of the triangles; the resolution and caps sweeps' half sizes.
        let centre = at(ONE_FACTOR[0], 16.0);
        assert!(measured(ablated_point("vertex", &centre.scene, centre.size)));
        assert!(measured(ablated_point("draw", &centre.scene, centre.size)));
        let full_hd = quick.iter().find(|p| p.sweep == "resolution" && p.size == (1920, 1080)).unwrap();
        assert!(measured(ablated_point("fill", &full_hd.scene, full_hd.size)));
        // A named scene is coarsened or merged by the proof itself; one caster merges nothing.
        assert_eq!(ablated_point("vertex", &PointScene::Named("bench/vertex".into()), (960, 540)), None);
        assert_eq!(ablated_point("draw", &at("casters", 1.0).scene, (960, 540)), None);
    }

    #[test]
    fn kinds_and_sizes() {
        assert_eq!(kind_of("fill"), Some("fill"));
        assert_eq!(kind_of("draw"), Some("draw"));
        assert_eq!(kind_of("cpu"), None);
        assert_eq!(kind_of("none"), None);
        assert_eq!(half_size((960, 540)), Some((480, 270)));
        assert_eq!(half_size((81, 45)), Some((40, 22)));
        assert_eq!(half_size((1, 45)), None);
        let r = SuiteRow { gpu_shadow_ms: Some(2.0), ..Default::default() };
        assert_eq!(Timing::of(&r), Some(t(2.0, 2.0, 2.0)));
        assert_eq!(Timing::of(&SuiteRow::default()), None);
    }
}
