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

    /// Every candidate bound's ablation: per kind, candidates, ablations run, confirmed
    /// (claimed) and refuted, the median of measured over predicted saving; then every
    /// disagreement and every ablation that could not run.
    pub(super) fn proof_markdown(&self) -> String {
        let p = &self.bound_proofs;
        let mut s = String::from(
            "## Bounds proven by ablation

",
        );
        let _ = writeln!(
            s,
            "**A bound is claimed only where its ablation in this run confirmed it.** The model names a *candidate* bound for a row where its largest share of identified terms leads clearly (above); each candidate is then put to the test: fill — the same volumes at half the width and height; vertex — the same shapes, coarser tessellation (spheres and tori: half the segments and rings, a quarter of the triangles); draw — the casters merged into one (the same triangles in world space). Where the ablated work is itself a point the sweeps measured (the resolution and caps sweeps' half sizes, the one-factor triangles sweep's quarter, the one-factor casters sweep's single caster, each measured right after its partner) the two rows are compared as measured ({} rows); every other candidate row is re-timed right before its ablation, {} frames each. A candidate is **confirmed** where the measured saving exceeds the spread (half the sum of the two p10–p90 widths) and lies within the spread of the saving the model predicts from the two's counted work; otherwise its ablation **refutes** it. Only confirmed bounds appear in the tables' bound column (bold); every other row says `unconfirmed`, with the candidate the model named.\n\n{} candidates, {} ablations ran ({} could not), **{} confirmed (the bounds claimed)**, {} refuted (every one listed under Disagreements); {:.0} s.\n",
            p.from_sweep, p.frames, p.claimed, p.ablated, p.not_run, p.confirmed, p.refuted, p.seconds
        );
        // Each measurement once: a one-factor sweep's copy of a shared point is not listed again.
        let with: Vec<&SuiteRow> = self.rows.iter().filter(|r| r.ablation.is_some() && r.measured_in.is_empty()).collect();
        if with.is_empty() {
            return s;
        }
        let _ = writeln!(s, "| bound | candidates | ablated | confirmed (claimed) | refuted | median measured / predicted saving |\n|---|---|---|---|---|---|");
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
            let ratio = if ratios.is_empty() { "—".to_string() } else { format!("{:.2}", super::stats::quantile(&ratios, 0.5)) };
            let _ = writeln!(s, "| {kind} | {} | {} | {confirmed} | {} | {ratio} |", of.len(), ran.len(), ran.len() - confirmed);
        }
        let disagree: Vec<&SuiteRow> = with
            .iter()
            .copied()
            .filter(|r| !r.bound_confirmed && r.ablation.as_ref().is_some_and(|a| a.predicted_saving_ms.is_some()))
            .collect();
        let _ = writeln!(s, "\n### Disagreements: candidates refuted by their ablation ({})\n", disagree.len());
        if disagree.is_empty() {
            let _ = writeln!(s, "Every ablation that ran confirmed its candidate.");
        } else {
            s += &refutations(&disagree);
            let _ = writeln!(
                s,
                "Every row where the model named a bound and its ablation refuted it: none of these bounds is claimed (times in ms; the model's predicted saving against the measured one, and the spread they are judged by; `sweep pair`: both sides are the sweeps' own points):\n\n| sweep | scene | variant | method | size | candidate | ablated | row ms | ablated ms | predicted saving | measured saving | spread | verdict |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|"
            );
            for r in disagree {
                let Some(a) = &r.ablation else { continue };
                let _ = writeln!(
                    s,
                    "| {} | {} | {} | {} | {}x{} | {} | {}{} {}x{} | {} | {} | {} | {} | {} | {} |",
                    r.sweep,
                    r.scene,
                    r.variant,
                    r.method,
                    r.width,
                    r.height,
                    a.kind,
                    if a.from_sweep { "sweep pair: " } else { "" },
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
                "\nCandidates left unproven (not claimed) because their ablation could not run:\n\n| sweep | scene | variant | method | size | bound | why |\n|---|---|---|---|---|---|---|"
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

/// Why the candidates in `refuted` failed, in two counts: the ablation saved time beyond the
/// spread but not what the model predicted (the model's share is wrong: the median measured
/// over predicted saving says by how much), or it saved nothing beyond the spread (no such
/// bound).
fn refutations(refuted: &[&SuiteRow]) -> String {
    let (mut real, mut none) = (Vec::new(), 0usize);
    for a in refuted.iter().filter_map(|r| r.ablation.as_ref()) {
        match (a.measured_saving_ms, a.predicted_saving_ms, a.spread_ms) {
            (Some(m), Some(p), Some(sp)) if m > sp && p.abs() > 0.0 => real.push(m / p),
            _ => none += 1,
        }
    }
    let ratio =
        if real.is_empty() { String::new() } else { format!(" (median measured / predicted {:.2})", super::stats::quantile(&real, 0.5)) };
    format!(
        "Of these {}, **{}** saved time beyond the spread but not what the model predicted{ratio}: the model's share of that work is wrong, not the timing's repeatability; **{none}** saved nothing beyond the spread: the bound is not there.\n\n",
        refuted.len(),
        real.len()
    )
}

impl SuiteReport {
    /// The one-factor casters sweep's two ends side by side (issue #38's pair): the same
    /// spheres as separate casters and merged into one, every technique, in this run.
    pub(super) fn merged_markdown(&self) -> String {
        let of: Vec<&SuiteRow> = self.rows.iter().filter(|r| r.sweep == super::sweeps::ONE_FACTOR[0]).collect();
        let most = of.iter().map(|r| r.x).fold(0.0, f64::max);
        let pairs: Vec<(&SuiteRow, &SuiteRow)> = of
            .iter()
            .filter(|r| r.x == most && most > 1.0)
            .filter_map(|sep| Some((*sep, *of.iter().find(|m| m.x == 1.0 && m.method == sep.method)?)))
            .collect();
        let Some((first, one)) = pairs.first() else { return String::new() };
        let mut s = String::from(
            "## Separate against merged casters

",
        );
        let _ = writeln!(
            s,
            "The one-factor casters sweep's two ends: `{}` — {} spheres, {} caster triangles in all, at {}x{} with {} light — as {} separate casters and merged into one caster (`{}`: the same triangles in world space, one mesh). Every technique side by side, the two points measured one after the other in this run{}. For the volumes the counted work is the same but for the (light, caster) passes: the same shadow triangles, fragments and draws (one per connected part). Times in ms, p10–p90 in brackets; `merging` says whether the merged caster is faster or slower beyond both spreads.\n",
            first.scene,
            first.casters.max(one.casters),
            first.triangles,
            first.width,
            first.height,
            first.lights,
            first.casters,
            one.scene,
            if first.measured_in.is_empty() { String::new() } else { format!(" (the separate point is the `{}` sweep's)", first.measured_in) }
        );
        let _ = writeln!(
            s,
            "| method | separate ms | merged ms | separate / merged | merging | shadow tris (sep / merged) | stencil frags (sep / merged) | caster passes (sep / merged) | plan ms (sep / merged) | separate row's bound |\n|---|---|---|---|---|---|---|---|---|---|"
        );
        let t = |r: &SuiteRow| match (r.gpu_shadow_ms, r.gpu_shadow_ms_p10, r.gpu_shadow_ms_p90) {
            (Some(m), Some(lo), Some(hi)) => format!("{m:.1} ({lo:.1}–{hi:.1})"),
            (Some(m), _, _) => format!("{m:.1}"),
            _ => "—".into(),
        };
        let frags = |r: &SuiteRow| r.stencil_fragments.map_or("—".to_string(), |f| f.to_string());
        for (sep, one) in &pairs {
            let (Some(a), Some(b)) = (sep.gpu_shadow_ms, one.gpu_shadow_ms) else { continue };
            let verdict = match (sep.gpu_shadow_ms_p10, sep.gpu_shadow_ms_p90, one.gpu_shadow_ms_p10, one.gpu_shadow_ms_p90) {
                (Some(slo), _, _, Some(mhi)) if slo > mhi => "saves",
                (_, Some(shi), Some(mlo), _) if shi < mlo => "costs",
                _ => "within spread",
            };
            let _ = writeln!(
                s,
                "| {} | {} | {} | {:.2} | {verdict} | {} / {} | {} / {} | {} / {} | {:.2} / {:.2} | {} |",
                sep.method,
                t(sep),
                t(one),
                a / b,
                sep.shadow_triangles,
                one.shadow_triangles,
                frags(sep),
                frags(one),
                sep.caster_passes,
                one.caster_passes,
                sep.cpu_plan_ms,
                one.cpu_plan_ms,
                sep.bound_cell()
            );
        }
        let ratio = |m: &str| pairs.iter().find(|(a, _)| a.method == m).and_then(|(a, b)| Some(a.gpu_shadow_ms? / b.gpu_shadow_ms?));
        let mut said = Vec::new();
        for m in ["mcguire", "compute", "mesh"] {
            if let Some(r) = ratio(m) {
                said.push(format!("`{m}` {r:.2}x"));
            }
        }
        if !said.is_empty() {
            let _ = writeln!(
                s,
                "\nSeparate over merged: {}. Where merging saves beyond the spread, per-caster cost is real for that technique; where it does not, a draw bound the model might name for it is not (the separate row's draw candidate is tested by exactly this pair: its bound cell says whether it held).\n",
                said.join(", ")
            );
        }
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
            bound_proofs: ProofSummary {
                claimed: 3,
                ablated: 2,
                confirmed: 1,
                refuted: 1,
                not_run: 1,
                frames: 5,
                seconds: 1.0,
                ..Default::default()
            },
            ..Default::default()
        };
        let md = report.proof_markdown();
        assert!(md.contains("### Disagreements: candidates refuted by their ablation (1)"), "{md}");
        assert!(md.contains("| casters | s |  | mcguire |") && md.contains("| 5.000 | 0.020 | 0.100 | verdict |"), "{md}");
        assert!(md.contains("| lengyel |") && md.contains("not run: one caster"), "{md}");
        assert!(md.contains("| draw | 2 | 1 | 0 | 1 | 0.00 |") && md.contains("| fill | 1 | 1 | 1 | 0 | 1.02 |"), "{md}");
        assert!(md.contains("**A bound is claimed only where its ablation in this run confirmed it.**"), "{md}");
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
