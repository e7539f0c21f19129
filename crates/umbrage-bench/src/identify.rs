//! Which of the cost model's coefficients the rows can tell apart ([`identify`]): a bootstrap
//! over rows gives each coefficient a confidence interval, the design's columns give the
//! pairs of terms that move together and the design's condition number.
//!
//! A term is *identified* when some row counts it, its bootstrap interval stays above zero
//! and within a factor [`MAX_CI_RATIO`] (the data pins it down), and no other term is
//! confounded with it: the design lets the fit trade the two coefficients against each other,
//! their estimates correlated by [`CONFOUNDED_CORRELATION`] or more in magnitude
//! ([`estimate_correlations`]: from the inverse of the weighted design's Gram matrix, which is
//! what the design columns' collinearity does to the coefficients, every other term held in
//! the model). Only identified terms may name a row's bound ([`super::sweeps::classify`]).
//!
//! Why not the plain Pearson correlation of two design columns: weighted by 1 / time as the
//! fit weighs them, a model that fits makes its columns sum to about one on every row, so
//! centred columns always look dependent; and two columns may each be far from the other and
//! still be told apart only through a third. The estimates' correlation has neither defect.
//!
//! Everything here is plain arithmetic on the design matrix, fitted through the estimator it
//! is given: no GPU, no rows of the suite (the unit tests use synthetic data with known
//! answers).

use super::stats::quantile;
use serde::Serialize;

/// Bootstrap resamples of the rows.
pub const RESAMPLES: usize = 200;

/// The bootstrap's fixed seed (a run's intervals are reproducible from its rows).
pub const SEED: u64 = 0x5eed_b007;

/// Confidence level of the intervals.
pub const LEVEL: f64 = 0.95;

/// Widest interval, as `ci_high / ci_low`, of an identified coefficient.
pub const MAX_CI_RATIO: f64 = 3.0;

/// Magnitude of the correlation of two coefficients' estimates at or above which the rows
/// cannot tell the two terms apart.
pub const CONFOUNDED_CORRELATION: f64 = 0.95;

/// One coefficient's bootstrap interval and verdict.
#[derive(Clone, Debug, Default, Serialize, PartialEq)]
pub struct Coefficient {
    /// The term's name.
    pub term: String,
    /// The fit on every row (in the unit the caller reports: the suite's are ns per unit).
    pub value: f64,
    /// The interval's low end (the (1 - level) / 2 quantile of the resampled fits).
    pub ci_low: f64,
    /// The interval's high end.
    pub ci_high: f64,
    /// Whether the rows identify the term (see the module's rules).
    pub identified: bool,
    /// Why not, in words (empty when identified).
    pub reason: String,
}

/// Two terms the rows cannot tell apart.
#[derive(Clone, Debug, Default, Serialize, PartialEq)]
pub struct Pair {
    /// One term.
    pub a: String,
    /// The other.
    pub b: String,
    /// Correlation of the two coefficients' estimates the weighted design implies
    /// ([`estimate_correlations`]): near -1, the fit can raise one and lower the other at no
    /// cost (columns that move together); near +1, columns that move against each other.
    pub correlation: f64,
}

/// What the rows can identify (`bench.json`'s `model.identifiability`).
#[derive(Clone, Debug, Default, Serialize)]
pub struct Identifiability {
    /// Bootstrap resamples of the rows.
    pub bootstrap_resamples: usize,
    /// The bootstrap's seed.
    pub seed: u64,
    /// Confidence level of the intervals (0.95).
    pub level: f64,
    /// Widest interval (`ci_high / ci_low`) of an identified coefficient.
    pub max_ci_ratio: f64,
    /// Magnitude of the estimates' correlation at or above which a pair is confounded.
    pub confounded_at: f64,
    /// Every term, in the model's order.
    pub coefficients: Vec<Coefficient>,
    /// Condition number of the weighted design, columns scaled to unit length (terms no row
    /// counts left out): above about 30 the columns are nearly dependent somewhere.
    pub condition_number: f64,
    /// Pairs of terms the rows cannot tell apart, most correlated first.
    pub confounded_pairs: Vec<Pair>,
}

impl Identifiability {
    /// Whether the term named `term` is identified (`false` for an unknown name).
    pub fn identified(&self, term: &str) -> bool {
        self.coefficients.iter().any(|c| c.term == term && c.identified)
    }
}

/// The next number of a SplitMix64 sequence (a small, well-mixed generator; fixed seeds give
/// the same resamples on every machine).
pub fn splitmix64(state: &mut u64) -> u64 {
    *state = state.wrapping_add(0x9e37_79b9_7f4a_7c15);
    let mut z = *state;
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// Row indices of resample `k` of `n` rows (with replacement), from `seed`.
fn resample(n: usize, seed: u64, k: usize) -> Vec<usize> {
    let mut s = seed ^ (k as u64).wrapping_mul(0xd134_2543_de82_ef95);
    (0..n).map(|_| (splitmix64(&mut s) % n.max(1) as u64) as usize).collect()
}

/// Coefficients of `resamples` fits of `fit` on rows drawn with replacement from `(x, y)`:
/// one vector per resample, in resample order whatever the threads (`threads` at least 1).
pub fn bootstrap<F>(x: &[Vec<f64>], y: &[f64], fit: &F, resamples: usize, seed: u64, threads: usize) -> Vec<Vec<f64>>
where
    F: Fn(&[Vec<f64>], &[f64]) -> Vec<f64> + Sync,
{
    let n = x.len().min(y.len());
    if n == 0 {
        return Vec::new();
    }
    let one = |k: usize| -> Vec<f64> {
        let idx = resample(n, seed, k);
        let xs: Vec<Vec<f64>> = idx.iter().map(|&i| x[i].clone()).collect();
        let ys: Vec<f64> = idx.iter().map(|&i| y[i]).collect();
        fit(&xs, &ys)
    };
    let threads = threads.clamp(1, resamples.max(1));
    let mut out: Vec<Vec<f64>> = vec![Vec::new(); resamples];
    std::thread::scope(|s| {
        let chunks: Vec<(usize, &mut [Vec<f64>])> = {
            let size = resamples.div_ceil(threads).max(1);
            out.chunks_mut(size).enumerate().map(|(c, chunk)| (c * size, chunk)).collect()
        };
        for (start, chunk) in chunks {
            let one = &one;
            s.spawn(move || {
                for (j, slot) in chunk.iter_mut().enumerate() {
                    *slot = one(start + j);
                }
            });
        }
    });
    out
}

/// The design weighted as the relative fit weighs it (each row over its time `y`): the
/// matrix the identifiability is judged on.
pub fn weighted(x: &[Vec<f64>], y: &[f64]) -> Vec<Vec<f64>> {
    x.iter().zip(y).map(|(r, t)| r.iter().map(|v| if *t > 0.0 { v / t } else { 0.0 }).collect()).collect()
}

/// Pearson correlation of columns `a` and `b` of `x` (NaN where either is constant).
pub fn correlation(x: &[Vec<f64>], a: usize, b: usize) -> f64 {
    let n = x.len() as f64;
    if n < 2.0 {
        return f64::NAN;
    }
    let mean = |j: usize| x.iter().map(|r| r[j]).sum::<f64>() / n;
    let (ma, mb) = (mean(a), mean(b));
    let (mut sab, mut saa, mut sbb) = (0.0, 0.0, 0.0);
    for r in x {
        let (da, db) = (r[a] - ma, r[b] - mb);
        sab += da * db;
        saa += da * da;
        sbb += db * db;
    }
    if saa <= 0.0 || sbb <= 0.0 {
        return f64::NAN;
    }
    sab / (saa * sbb).sqrt()
}

/// Eigenvalues of the symmetric matrix `a` (cyclic Jacobi rotations; `a` is small).
pub fn symmetric_eigenvalues(a: Vec<Vec<f64>>) -> Vec<f64> {
    symmetric_eigen(a).0
}

/// Eigenvalues and eigenvectors (`vectors[k]` belongs to `values[k]`, unit length) of the
/// symmetric matrix `a`, by cyclic Jacobi rotations.
pub fn symmetric_eigen(mut a: Vec<Vec<f64>>) -> (Vec<f64>, Vec<Vec<f64>>) {
    let n = a.len();
    let mut v: Vec<Vec<f64>> = (0..n).map(|i| (0..n).map(|j| if i == j { 1.0 } else { 0.0 }).collect()).collect();
    for _ in 0..100 {
        let off: f64 = (0..n).flat_map(|i| (0..n).filter(move |&j| j != i).map(move |j| (i, j))).map(|(i, j)| a[i][j] * a[i][j]).sum();
        let diag: f64 = (0..n).map(|i| a[i][i] * a[i][i]).sum();
        if off <= 1e-30 * diag.max(1e-300) {
            break;
        }
        for p in 0..n {
            for q in p + 1..n {
                if a[p][q].abs() <= f64::MIN_POSITIVE {
                    continue;
                }
                let theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
                let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
                let t = if theta == 0.0 { 1.0 } else { t };
                let c = 1.0 / (t * t + 1.0).sqrt();
                let s = t * c;
                for row in a.iter_mut() {
                    let (akp, akq) = (row[p], row[q]);
                    row[p] = c * akp - s * akq;
                    row[q] = s * akp + c * akq;
                }
                let (rp, rq) = (a[p].clone(), a[q].clone());
                for (k, (apk, aqk)) in rp.into_iter().zip(rq).enumerate() {
                    a[p][k] = c * apk - s * aqk;
                    a[q][k] = s * apk + c * aqk;
                }
                for row in v.iter_mut() {
                    let (vkp, vkq) = (row[p], row[q]);
                    row[p] = c * vkp - s * vkq;
                    row[q] = s * vkp + c * vkq;
                }
            }
        }
    }
    let values = (0..n).map(|i| a[i][i]).collect();
    let vectors = (0..n).map(|k| (0..n).map(|i| v[i][k]).collect()).collect();
    (values, vectors)
}

/// The correlation matrix of the least-squares estimates of `x`'s columns `cols` (unit
/// noise): `G⁻¹` normalised, `G` the columns' Gram matrix (each column scaled to unit length,
/// which leaves the correlations as they are). A dependent direction (eigenvalue under 1e-12
/// of the largest) is inverted at that floor, so the columns in it come out correlated by
/// about ±1. `result[i][j]` belongs to `cols[i]` and `cols[j]`; NaN for a column of zeros.
pub fn estimate_correlations(x: &[Vec<f64>], cols: &[usize]) -> Vec<Vec<f64>> {
    let k = cols.len();
    let norm: Vec<f64> = cols.iter().map(|&j| x.iter().map(|r| r[j] * r[j]).sum::<f64>().sqrt()).collect();
    let mut g = vec![vec![0.0; k]; k];
    for r in x {
        for a in 0..k {
            if norm[a] <= 0.0 {
                continue;
            }
            let va = r[cols[a]] / norm[a];
            for b in 0..k {
                if norm[b] > 0.0 {
                    g[a][b] += va * r[cols[b]] / norm[b];
                }
            }
        }
    }
    let (values, vectors) = symmetric_eigen(g);
    let top = values.iter().copied().fold(0.0f64, f64::max);
    let floor = (top * 1e-12).max(f64::MIN_POSITIVE);
    let mut inv = vec![vec![0.0; k]; k];
    for (l, v) in values.iter().zip(&vectors) {
        let l = l.max(floor);
        for a in 0..k {
            for b in 0..k {
                inv[a][b] += v[a] * v[b] / l;
            }
        }
    }
    (0..k)
        .map(|a| {
            (0..k).map(|b| if norm[a] > 0.0 && norm[b] > 0.0 { inv[a][b] / (inv[a][a] * inv[b][b]).sqrt() } else { f64::NAN }).collect()
        })
        .collect()
}

/// Condition number of `x`'s columns `cols`, each scaled to unit length: the square root of
/// the largest over the smallest eigenvalue of their Gram matrix (infinite when dependent;
/// 1 for orthogonal columns; NaN without columns).
pub fn condition_number(x: &[Vec<f64>], cols: &[usize]) -> f64 {
    if cols.is_empty() {
        return f64::NAN;
    }
    let norm: Vec<f64> = cols.iter().map(|&j| x.iter().map(|r| r[j] * r[j]).sum::<f64>().sqrt()).collect();
    if norm.iter().any(|n| *n <= 0.0) {
        return f64::INFINITY;
    }
    let k = cols.len();
    let mut g = vec![vec![0.0; k]; k];
    for r in x {
        for a in 0..k {
            let va = r[cols[a]] / norm[a];
            for b in a..k {
                g[a][b] += va * r[cols[b]] / norm[b];
            }
        }
    }
    for a in 1..k {
        let (upper, lower) = g.split_at_mut(a);
        for (b, above) in upper.iter().enumerate() {
            lower[0][b] = above[a];
        }
    }
    let ev = symmetric_eigenvalues(g);
    let max = ev.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let min = ev.iter().copied().fold(f64::INFINITY, f64::min);
    // Round-off leaves a dependent Gram matrix's smallest eigenvalue near 1e-16 of its largest.
    if min <= max * 1e-14 {
        return f64::INFINITY;
    }
    (max / min).sqrt()
}

/// A fitted linear model's design: what [`identify`] judges.
#[derive(Clone, Copy, Debug)]
pub struct Design<'a> {
    /// The rows' counts, one column per term.
    pub x: &'a [Vec<f64>],
    /// The rows' measured times.
    pub y: &'a [f64],
    /// Each column's term.
    pub names: &'a [&'a str],
    /// The fit on every row (the fit's unit).
    pub value: &'a [f64],
    /// From the fit's unit to the reported one (the suite fits ms and reports ns: 1e6).
    pub scale: f64,
}

/// What `d`'s rows identify of the model `fit` estimates: `resamples` bootstrap fits from
/// `seed`, the weighted columns' correlations and condition number.
pub fn identify<F>(d: &Design, fit: &F, resamples: usize, seed: u64) -> Identifiability
where
    F: Fn(&[Vec<f64>], &[f64]) -> Vec<f64> + Sync,
{
    let Design { x, y, names, value, scale } = *d;
    let threads = std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1);
    let boots = bootstrap(x, y, fit, resamples, seed, threads);
    let w = weighted(x, y);
    let present: Vec<usize> = (0..names.len()).filter(|&j| w.iter().any(|r| r.get(j).is_some_and(|v| *v != 0.0))).collect();
    let corr = estimate_correlations(&w, &present);
    let mut pairs = Vec::new();
    for (i, &a) in present.iter().enumerate() {
        for (j, &b) in present.iter().enumerate().skip(i + 1) {
            let r = corr[i][j];
            if r.is_finite() && r.abs() >= CONFOUNDED_CORRELATION {
                pairs.push(Pair { a: names[a].to_string(), b: names[b].to_string(), correlation: r });
            }
        }
    }
    pairs.sort_by(|p, q| q.correlation.abs().total_cmp(&p.correlation.abs()));
    let tail = (1.0 - LEVEL) / 2.0;
    let coefficients = names
        .iter()
        .enumerate()
        .map(|(j, name)| {
            let samples: Vec<f64> = boots.iter().filter_map(|c| c.get(j)).map(|c| c * scale).collect();
            let (lo, hi) = (quantile(&samples, tail), quantile(&samples, 1.0 - tail));
            let partner = pairs.iter().find(|p| p.a == *name || p.b == *name);
            let reason = if !present.contains(&j) {
                "no row counts it".to_string()
            } else if samples.is_empty() || !lo.is_finite() || !hi.is_finite() {
                "no bootstrap fits".to_string()
            } else if let Some(p) = partner {
                let other = if p.a == *name { &p.b } else { &p.a };
                format!("confounded with {other} (estimates correlated {:.3})", p.correlation)
            } else if lo <= 0.0 {
                format!("its {:.0} % interval reaches zero", LEVEL * 100.0)
            } else if hi > MAX_CI_RATIO * lo {
                format!("its {:.0} % interval spans {:.1}x (over {MAX_CI_RATIO}x)", LEVEL * 100.0, hi / lo)
            } else {
                String::new()
            };
            Coefficient {
                term: name.to_string(),
                value: value.get(j).copied().unwrap_or(f64::NAN) * scale,
                ci_low: lo,
                ci_high: hi,
                identified: reason.is_empty(),
                reason,
            }
        })
        .collect();
    Identifiability {
        bootstrap_resamples: boots.len(),
        seed,
        level: LEVEL,
        max_ci_ratio: MAX_CI_RATIO,
        confounded_at: CONFOUNDED_CORRELATION,
        coefficients,
        condition_number: condition_number(&w, &present),
        confounded_pairs: pairs,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Ordinary least squares through the normal equations (Gaussian elimination): the
    /// synthetic tests' estimator, independent of the suite's.
    fn ols(x: &[Vec<f64>], y: &[f64]) -> Vec<f64> {
        let n = x[0].len();
        let mut a = vec![vec![0.0; n + 1]; n];
        for (r, t) in x.iter().zip(y) {
            for i in 0..n {
                for j in 0..n {
                    a[i][j] += r[i] * r[j];
                }
                a[i][n] += r[i] * t;
            }
        }
        for c in 0..n {
            let p = (c..n).max_by(|&i, &j| a[i][c].abs().total_cmp(&a[j][c].abs())).unwrap();
            a.swap(c, p);
            if a[c][c].abs() < 1e-12 {
                continue;
            }
            let pivot = a[c].clone();
            for (i, row) in a.iter_mut().enumerate() {
                if i != c {
                    let f = row[c] / pivot[c];
                    for (x, p) in row.iter_mut().zip(&pivot).skip(c) {
                        *x -= f * p;
                    }
                }
            }
        }
        (0..n).map(|i| if a[i][i].abs() < 1e-12 { 0.0 } else { a[i][n] / a[i][i] }).collect()
    }

    /// Rows of two independent counts and a constant with known coefficients (2, 0.5, 3) and
    /// a few percent of deterministic noise.
    fn synthetic(collinear: bool) -> (Vec<Vec<f64>>, Vec<f64>) {
        let mut s = 7u64;
        let mut u = || (splitmix64(&mut s) >> 11) as f64 / (1u64 << 53) as f64;
        let mut x = Vec::new();
        let mut y = Vec::new();
        for _ in 0..120 {
            let a = 1.0 + 99.0 * u();
            let b = if collinear { 2.0 * a } else { 1.0 + 99.0 * u() };
            let t = 2.0 * a + 0.5 * b + 3.0;
            x.push(vec![a, b, 1.0]);
            y.push(t * (1.0 + 0.04 * (u() - 0.5)));
        }
        (x, y)
    }

    #[test]
    fn an_identifiable_model_recovers_its_coefficients_within_the_intervals() {
        let (x, y) = synthetic(false);
        let all = ols(&x, &y);
        let id = identify(&Design { x: &x, y: &y, names: &["a", "b", "one"], value: &all, scale: 1.0 }, &ols, 200, SEED);
        assert_eq!(id.bootstrap_resamples, 200);
        for (c, truth) in id.coefficients.iter().zip([2.0, 0.5, 3.0]) {
            assert!(c.ci_low <= truth && truth <= c.ci_high, "{c:?} misses {truth}");
            assert!(c.ci_low < c.value && c.value < c.ci_high, "{c:?}");
        }
        assert!(id.identified("a") && id.identified("b"), "{:?}", id.coefficients);
        assert!(id.confounded_pairs.is_empty(), "{:?}", id.confounded_pairs);
        assert!(id.condition_number.is_finite() && id.condition_number < 30.0, "{}", id.condition_number);
    }

    #[test]
    fn two_collinear_columns_are_flagged_and_neither_is_identified() {
        let (x, y) = synthetic(true);
        let all = ols(&x, &y);
        let id = identify(&Design { x: &x, y: &y, names: &["a", "b", "one"], value: &all, scale: 1.0 }, &ols, 100, SEED);
        assert_eq!(id.confounded_pairs.len(), 1, "{:?}", id.confounded_pairs);
        let p = &id.confounded_pairs[0];
        assert_eq!((p.a.as_str(), p.b.as_str()), ("a", "b"));
        // The fit can trade a for b at no cost: their estimates are perfectly anti-correlated.
        assert!((p.correlation + 1.0).abs() < 1e-6, "{p:?}");
        assert!(!id.identified("a") && !id.identified("b"), "{:?}", id.coefficients);
        assert!(id.coefficients[1].reason.contains("confounded with a"), "{:?}", id.coefficients[1]);
        assert!(id.condition_number.is_infinite(), "{}", id.condition_number);
    }

    #[test]
    fn a_term_no_row_counts_or_a_zero_coefficient_is_not_identified() {
        let (mut x, y) = synthetic(false);
        for r in &mut x {
            r.push(0.0);
        }
        // An estimator that clamps b to zero: its interval reaches zero.
        let clamp_b = |x: &[Vec<f64>], y: &[f64]| {
            let mut c = ols(x, y);
            c[1] = 0.0;
            c
        };
        let all = clamp_b(&x, &y);
        let id = identify(&Design { x: &x, y: &y, names: &["a", "b", "one", "never"], value: &all, scale: 1e6 }, &clamp_b, 50, SEED);
        assert!(!id.identified("b") && id.coefficients[1].reason.contains("reaches zero"), "{:?}", id.coefficients[1]);
        assert!(!id.identified("never") && id.coefficients[3].reason == "no row counts it");
        // Reported in the scaled unit.
        assert!((id.coefficients[0].value / 1e6 - all[0]).abs() < 1e-12);
        assert!(!id.identified("no-such-term"));
    }

    #[test]
    fn the_bootstrap_is_reproducible_whatever_the_threads() {
        let (x, y) = synthetic(false);
        let one = bootstrap(&x, &y, &ols, 23, 11, 1);
        let three = bootstrap(&x, &y, &ols, 23, 11, 3);
        assert_eq!(one, three);
        assert_ne!(bootstrap(&x, &y, &ols, 3, 12, 1), bootstrap(&x, &y, &ols, 3, 11, 1));
        assert!(bootstrap(&[], &[], &ols, 5, 1, 2).is_empty());
    }

    #[test]
    fn a_pair_told_apart_only_through_a_third_column_is_confounded() {
        // c = a + b: no two columns are alike, but the three are dependent, so every pair
        // trades off; a fourth independent column stays clear of them.
        let mut s = 3u64;
        let mut u = || (splitmix64(&mut s) >> 11) as f64 / (1u64 << 53) as f64;
        let x: Vec<Vec<f64>> = (0..50)
            .map(|_| {
                let (a, b, d) = (u(), u(), u());
                vec![a, b, a + b, d]
            })
            .collect();
        let c = estimate_correlations(&x, &[0, 1, 2, 3]);
        assert!(correlation(&x, 0, 1).abs() < 0.5, "a and b are not alike as columns");
        assert!(c[0][1].abs() > 0.99 && c[0][2].abs() > 0.99 && c[1][2].abs() > 0.99, "{c:?}");
        assert!(c[0][3].abs() < 0.9 && c[2][3].abs() < 0.9, "{c:?}");
        for (i, row) in c.iter().enumerate() {
            assert!((row[i] - 1.0).abs() < 1e-9);
        }
    }

    #[test]
    fn condition_numbers_and_eigenvalues() {
        let ev = symmetric_eigenvalues(vec![vec![2.0, 1.0], vec![1.0, 2.0]]);
        let (lo, hi) = (ev[0].min(ev[1]), ev[0].max(ev[1]));
        assert!((lo - 1.0).abs() < 1e-12 && (hi - 3.0).abs() < 1e-12, "{ev:?}");
        let orth = vec![vec![1.0, 0.0], vec![0.0, 5.0]];
        assert!((condition_number(&orth, &[0, 1]) - 1.0).abs() < 1e-12);
        // Two unit columns at 45 degrees: Gram [[1, c], [c, 1]], c = 1/sqrt(2).
        let skew = vec![vec![1.0, 1.0], vec![0.0, 1.0]];
        let c = std::f64::consts::FRAC_1_SQRT_2;
        assert!((condition_number(&skew, &[0, 1]) - ((1.0 + c) / (1.0 - c)).sqrt()).abs() < 1e-9);
        assert!(condition_number(&skew, &[]).is_nan());
        // Eigenvectors: A v = l v.
        let a = vec![vec![4.0, 1.0, 0.5], vec![1.0, 3.0, 0.2], vec![0.5, 0.2, 1.0]];
        let (values, vectors) = symmetric_eigen(a.clone());
        for (l, v) in values.iter().zip(&vectors) {
            for i in 0..3 {
                let av: f64 = (0..3).map(|j| a[i][j] * v[j]).sum();
                assert!((av - l * v[i]).abs() < 1e-9, "{values:?} {vectors:?}");
            }
        }
    }
}
