//! The order statistics every bench file uses (medians of timed repetitions, quantiles of
//! errors and spreads): plain arithmetic, the ground floor of `bench/` (imports nothing).

/// The median of `v` (the upper middle of an even count; NaN when empty).
pub fn median(mut v: Vec<f64>) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// The `q`-quantile of the finite values of `v` (linear between order statistics; NaN when
/// none).
pub fn quantile(v: &[f64], q: f64) -> f64 {
    let mut s: Vec<f64> = v.iter().copied().filter(|x| x.is_finite()).collect();
    if s.is_empty() {
        return f64::NAN;
    }
    s.sort_by(f64::total_cmp);
    let p = q.clamp(0.0, 1.0) * (s.len() - 1) as f64;
    let (i, f) = (p.floor() as usize, p - p.floor());
    match s.get(i + 1) {
        Some(next) => s[i] * (1.0 - f) + next * f,
        None => s[i],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn medians_and_quantiles() {
        assert_eq!(median(vec![3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(vec![4.0, 1.0, 3.0, 2.0]), 3.0);
        assert!(median(Vec::new()).is_nan());
        assert_eq!(quantile(&[3.0, 1.0, 2.0], 0.5), 2.0);
        assert!((quantile(&[0.0, 10.0], 0.1) - 1.0).abs() < 1e-12);
        assert_eq!(quantile(&[f64::NAN, 5.0], 0.9), 5.0);
        assert!(quantile(&[], 0.5).is_nan());
    }
}
