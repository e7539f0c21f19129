//! Every claimed bound proven by an ablation in the same run (issue #38): where a row is
//! called fill-, vertex- or draw-bound, its work is cut where the bound says the time goes —
//! fill: the same volumes at half the width and height; vertex: a coarser tessellation of the
//! same shapes ([`super::reshape::coarser`]); draw: the casters merged into one
//! ([`super::reshape::merged_casters`]) — and timed right after the row itself, re-timed. The
//! bound is *confirmed* when the measured saving is beyond the two timings' spread and agrees
//! with the model's predicted saving (its time for the row's counted work less its time for
//! the ablated work's) within that spread ([`decide`]). Rows sharing a scene and a size share
//! their renderers: one re-timing of the row's variants, then one ablated scene per kind.

use super::model::Model;
use super::report::{ProofSummary, RowAblation, SuiteRow};
use super::reshape::{coarser, merged_casters};
use super::runner::{scene_of, Point, Runner, Variant};
use super::sweeps::PointScene;
use crate::error::Result;
use crate::render::Renderer;
use crate::scene::Scene;
use std::time::Instant;

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

/// Rows of one scene and size with a claimed bound.
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

/// Runs the ablation of every row with a claimed fill, vertex or draw bound (`rows[i]`
/// measured as `origins[i]`), `frames` timed frames a side, and fills in each such row's
/// `ablation` and `bound_confirmed` against `model`'s predictions.
pub(super) fn prove(run: &mut Runner, rows: &mut [SuiteRow], origins: &[Origin], model: &Model, frames: usize) -> Result<ProofSummary> {
    let start = Instant::now();
    let mut groups: Vec<Group> = Vec::new();
    for (i, (r, o)) in rows.iter().zip(origins).enumerate() {
        if !r.bound_clear || kind_of(&r.bound).is_none() || Timing::of(r).is_none() {
            continue;
        }
        match groups.iter_mut().find(|g| g.scene == o.scene && g.size == o.size) {
            Some(g) => g.rows.push(i),
            None => groups.push(Group { scene: o.scene.clone(), size: o.size, rows: vec![i] }),
        }
    }
    let saved_frames = std::mem::replace(&mut run.frames, frames);
    run.bar.inc_length(groups.iter().map(|g| 2 * g.rows.len() as u64).sum());
    let mut summary = ProofSummary { frames, ..Default::default() };
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
        let merged = if draw.is_empty() { None } else { merged_casters(&scene, &name) };
        // The rows re-timed, then at half the size on the same renderer.
        let mut r = run.renderer(scene, g.size)?;
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
        for &i in &g.rows {
            let kind = kind_of(&rows[i].bound).unwrap_or("fill");
            let ablated = match kind {
                "fill" => half.as_ref(),
                "vertex" => coarse.as_ref(),
                _ => joined.as_ref(),
            };
            let variant = &origins[i].variant;
            let find = |set: &[(SuiteRow, Variant)]| set.iter().find(|(_, v)| v == variant).map(|(r, _)| r.clone());
            let mut a = RowAblation { kind: kind.into(), frames, ..Default::default() };
            if let Some(ab) = ablated {
                a.ablated_scene = ab.scene.clone();
                a.ablated_size = [ab.size.0, ab.size.1];
            }
            let pair = match ablated.map(|ab| &ab.rows) {
                Some(Ok(set)) => match (find(&base), find(set)) {
                    (Some(b), Some(x)) => Ok((b, x)),
                    _ => Err("not run: the device skipped the variant".to_string()),
                },
                Some(Err(why)) => Err(why.clone()),
                None => Err("not run".to_string()),
            };
            match pair {
                Ok((b, x)) => match (Timing::of(&b), Timing::of(&x), model.predict(&b), model.predict(&x)) {
                    (Some(tb), Some(tx), Some(pb), Some(px)) => {
                        let v = decide(tb, tx, pb - px);
                        a.predicted_saving_ms = Some(pb - px);
                        a.measured_saving_ms = Some(v.measured);
                        a.spread_ms = Some(v.spread);
                        a.baseline_ms = Some(tb.median);
                        a.ablated_ms = Some(tx.median);
                        a.confirmed = v.confirmed;
                        a.verdict = v.why;
                        summary.ablated += 1;
                    }
                    _ => a.verdict = "not run: untimed or without counters".into(),
                },
                Err(why) => a.verdict = why,
            }
            if a.predicted_saving_ms.is_none() {
                summary.not_run += 1;
            }
            summary.confirmed += a.confirmed as usize;
            summary.claimed += 1;
            rows[i].bound_confirmed = a.confirmed;
            rows[i].ablation = Some(a);
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
