//! The report's evidence for its bounds (docs/bench-*.md): what the rows identify of the cost
//! model ([`super::identify`]) and every claimed bound's ablation ([`super::proof`]), every
//! disagreement listed.

use super::report::{SuiteReport, SuiteRow};
use std::fmt::Write as _;

/// `v` with three significant digits past the point for small values, or `—`.
fn num(v: Option<f64>) -> String {
    match v {
        Some(x) if x.is_finite() => format!("{x:.3}"),
        Some(x) => format!("{x}"),
        None => "—".into(),
    }
}

impl SuiteReport {
    /// What the rows identify: each coefficient's bootstrap interval and verdict, the pairs
    /// the rows cannot tell apart, the condition number.
    pub(super) fn identifiability_markdown(&self) -> String {
        let id = &self.model.identifiability;
        if id.coefficients.is_empty() {
            return String::new();
        }
        let mut s = String::from("## What the rows identify\n\n");
        let identified: Vec<&str> = id.coefficients.iter().filter(|c| c.identified).map(|c| c.term.as_str()).collect();
        let _ = writeln!(
            s,
            "Each coefficient's {:.0} % interval comes from refitting the model on {} resamples of the {} rows (drawn with replacement, seed {:#x}). A term is identified when some row counts it, its interval stays above zero and within {}x (high over low), and no other term is confounded with it: the design lets the fit trade the two coefficients (their estimates correlated by {} or more in magnitude, from the inverse of the weighted design's Gram matrix). Condition number of the weighted design, columns at unit length: **{}**. Only identified terms name a bound: a row's bound must lead by more than its share of unidentified terms. Identified here: {}.\n",
            id.level * 100.0,
            id.bootstrap_resamples,
            self.model.rows,
            id.seed,
            id.max_ci_ratio,
            id.confounded_at,
            if id.condition_number.is_finite() { format!("{:.1}", id.condition_number) } else { "infinite".into() },
            if identified.is_empty() { "none".to_string() } else { identified.join(", ") }
        );
        let _ =
            writeln!(s, "| term | c (ns per unit) | {:.0} % interval | identified | why not |\n|---|---|---|---|---|", id.level * 100.0);
        for c in &id.coefficients {
            let _ = writeln!(
                s,
                "| {} | {} | {} – {} | {} | {} |",
                c.term,
                num(Some(c.value)),
                num(Some(c.ci_low)),
                num(Some(c.ci_high)),
                if c.identified { "**yes**" } else { "no" },
                c.reason
            );
        }
        if id.confounded_pairs.is_empty() {
            let _ = writeln!(s, "\nNo pair of terms is confounded.\n");
        } else {
            let _ = writeln!(s, "\nPairs the rows cannot tell apart:\n\n| term | term | estimates' correlation |\n|---|---|---|");
            for p in &id.confounded_pairs {
                let _ = writeln!(s, "| {} | {} | {:.3} |", p.a, p.b, p.correlation);
            }
            s.push('\n');
        }
        s
    }

    /// Every claimed bound's ablation: per kind, claimed, run and confirmed, the median of
    /// measured over predicted saving; then every disagreement and every ablation that could
    /// not run.
    pub(super) fn proof_markdown(&self) -> String {
        let p = &self.bound_proofs;
        let mut s = String::from("## Bounds proven by ablation\n\n");
        let _ = writeln!(
            s,
            "A claimed bound is put to the test in the same run: fill — the same volumes at half the width and height (the same renderer, resized); vertex — the same shapes, coarser tessellation (spheres and tori: half the segments and rings); draw — the casters merged into one (the same triangles in world space). The row is re-timed right before its ablation, {} frames each, and the bound is **confirmed** only where the measured saving exceeds the spread (half the sum of the two p10–p90 widths) and lies within the spread of the saving the model predicts from the two's counted work. Only confirmed bounds appear in the tables' bound column; the others say `unconfirmed`. {} rows claimed a bound, {} ablations ran ({} could not), **{} confirmed**; {:.0} s.\n",
            p.frames, p.claimed, p.ablated, p.not_run, p.confirmed, p.seconds
        );
        let with: Vec<&SuiteRow> = self.rows.iter().filter(|r| r.ablation.is_some()).collect();
        if with.is_empty() {
            return s;
        }
        let _ = writeln!(s, "| bound | claimed | ablated | confirmed | median measured / predicted saving |\n|---|---|---|---|---|");
        for kind in ["fill", "vertex", "draw"] {
            let of: Vec<&SuiteRow> = with.iter().copied().filter(|r| r.ablation.as_ref().is_some_and(|a| a.kind == kind)).collect();
            let ran: Vec<&SuiteRow> =
                of.iter().copied().filter(|r| r.ablation.as_ref().is_some_and(|a| a.predicted_saving_ms.is_some())).collect();
            let ratios: Vec<f64> = ran
                .iter()
                .filter_map(|r| r.ablation.as_ref())
                .filter_map(|a| Some(a.measured_saving_ms? / a.predicted_saving_ms.filter(|p| p.abs() > 0.0)?))
                .collect();
            let confirmed = of.iter().filter(|r| r.bound_confirmed).count();
            let ratio = if ratios.is_empty() { "—".to_string() } else { format!("{:.2}", super::model::quantile(&ratios, 0.5)) };
            let _ = writeln!(s, "| {kind} | {} | {} | {confirmed} | {ratio} |", of.len(), ran.len());
        }
        let disagree: Vec<&SuiteRow> = with
            .iter()
            .copied()
            .filter(|r| !r.bound_confirmed && r.ablation.as_ref().is_some_and(|a| a.predicted_saving_ms.is_some()))
            .collect();
        let _ = writeln!(s, "\n### Disagreements ({})\n", disagree.len());
        if disagree.is_empty() {
            let _ = writeln!(s, "Every ablation that ran confirmed its bound.");
        } else {
            let _ = writeln!(
                s,
                "Every ablation that did not confirm its row's bound (times in ms; predicted and measured savings, the spread they are judged by):\n\n| sweep | scene | variant | method | size | bound | ablated | row ms | ablated ms | predicted | measured | spread | verdict |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|"
            );
            for r in disagree {
                let Some(a) = &r.ablation else { continue };
                let _ = writeln!(
                    s,
                    "| {} | {} | {} | {} | {}x{} | {} | {} {}x{} | {} | {} | {} | {} | {} | {} |",
                    r.sweep,
                    r.scene,
                    r.variant,
                    r.method,
                    r.width,
                    r.height,
                    a.kind,
                    a.ablated_scene,
                    a.ablated_size[0],
                    a.ablated_size[1],
                    num(a.baseline_ms),
                    num(a.ablated_ms),
                    num(a.predicted_saving_ms),
                    num(a.measured_saving_ms),
                    num(a.spread_ms),
                    a.verdict
                );
            }
        }
        let not_run: Vec<&SuiteRow> =
            with.iter().copied().filter(|r| r.ablation.as_ref().is_some_and(|a| a.predicted_saving_ms.is_none())).collect();
        if !not_run.is_empty() {
            let _ = writeln!(
                s,
                "\nBounds left unproven because their ablation could not run:\n\n| sweep | scene | variant | method | size | bound | why |\n|---|---|---|---|---|---|---|"
            );
            for r in not_run {
                let Some(a) = &r.ablation else { continue };
                let _ = writeln!(
                    s,
                    "| {} | {} | {} | {} | {}x{} | {} | {} |",
                    r.sweep, r.scene, r.variant, r.method, r.width, r.height, a.kind, a.verdict
                );
            }
        }
        s.push('\n');
        s
    }
}

#[cfg(test)]
mod tests {
    use super::super::identify::{Coefficient, Identifiability, Pair};
    use super::super::report::{ProofSummary, RowAblation, SuiteReport, SuiteRow};

    fn row(method: &str, kind: &str, predicted: Option<f64>, measured: f64, confirmed: bool) -> SuiteRow {
        SuiteRow {
            sweep: "casters".into(),
            scene: "s".into(),
            method: method.into(),
            bound: kind.into(),
            bound_clear: true,
            bound_confirmed: confirmed,
            ablation: Some(RowAblation {
                kind: kind.into(),
                predicted_saving_ms: predicted,
                measured_saving_ms: predicted.map(|_| measured),
                confirmed,
                spread_ms: predicted.map(|_| 0.1),
                verdict: if predicted.is_some() { "verdict".into() } else { "not run: one caster, nothing to merge".into() },
                ..Default::default()
            }),
            ..Default::default()
        }
    }

    #[test]
    fn every_disagreement_and_every_unrun_ablation_is_listed() {
        let report = SuiteReport {
            rows: vec![
                row("mcguire", "draw", Some(5.0), 0.02, false),
                row("zpass", "fill", Some(2.0), 2.05, true),
                row("lengyel", "draw", None, 0.0, false),
            ],
            bound_proofs: ProofSummary { claimed: 3, ablated: 2, confirmed: 1, not_run: 1, frames: 5, seconds: 1.0 },
            ..Default::default()
        };
        let md = report.proof_markdown();
        assert!(md.contains("### Disagreements (1)"), "{md}");
        assert!(md.contains("| casters | s |  | mcguire |") && md.contains("| 5.000 | 0.020 | 0.100 | verdict |"), "{md}");
        assert!(md.contains("| lengyel |") && md.contains("not run: one caster"), "{md}");
        assert!(md.contains("| draw | 2 | 1 | 0 | 0.00 |") && md.contains("| fill | 1 | 1 | 1 | 1.02 |"), "{md}");
    }

    #[test]
    fn the_identifiability_section_names_what_is_not_identified() {
        let mut report = SuiteReport::default();
        report.model.identifiability = Identifiability {
            bootstrap_resamples: 200,
            level: 0.95,
            max_ci_ratio: 3.0,
            confounded_at: 0.95,
            condition_number: f64::INFINITY,
            coefficients: vec![
                Coefficient {
                    term: "draws".into(),
                    value: 1.0,
                    ci_low: 0.0,
                    ci_high: 2.0,
                    identified: false,
                    reason: "confounded with caster_passes (estimates correlated -0.990)".into(),
                },
                Coefficient { term: "fragments".into(), value: 1.0, ci_low: 0.9, ci_high: 1.1, identified: true, reason: String::new() },
            ],
            confounded_pairs: vec![Pair { a: "draws".into(), b: "caster_passes".into(), correlation: -0.99 }],
            ..Default::default()
        };
        let md = report.identifiability_markdown();
        assert!(md.contains("Identified here: fragments.") && md.contains("**infinite**"), "{md}");
        assert!(md.contains("| draws | caster_passes | -0.990 |") && md.contains("| draws | 1.000 | 0.000 – 2.000 | no |"), "{md}");
    }
}
