//! Paired rounds: two functions timed in alternating batches, so that a host whose speed moves
//! from one second to the next moves both alike (see `benches/silhouette.rs`).

/// Paired rounds of `a` and `b` (see the module docs): per round, `a`'s batch time over `b`'s,
/// sorted, and the median time of one call of `a` and of `b`, in seconds.
pub fn paired_ratios(mut a: impl FnMut(), mut b: impl FnMut(), batch: u32) -> (Vec<f64>, f64, f64) {
    let time = |f: &mut dyn FnMut()| {
        let t = std::time::Instant::now();
        for _ in 0..batch {
            f();
        }
        t.elapsed().as_secs_f64() / f64::from(batch)
    };
    let rounds: Vec<(f64, f64)> = (0..31).map(|_| (time(&mut a), time(&mut b))).collect();
    let median = |mut v: Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    let mut ratios: Vec<f64> = rounds.iter().map(|(x, y)| x / y).collect();
    ratios.sort_by(f64::total_cmp);
    (ratios, median(rounds.iter().map(|r| r.0).collect()), median(rounds.iter().map(|r| r.1).collect()))
}

/// The line printed for [`paired_ratios`]' result: `what` (the function `b`) at the median
/// round's ratio of `a`'s speed (`of_other`: "streaming_sum's"), the quartiles, and the median
/// calls of `b` and `a`.
pub fn paired_line(what: &str, of_other: &str, (ratios, t_a, t_b): (Vec<f64>, f64, f64), batch: u32) -> String {
    format!(
        "{what} at {:.2}x {of_other} speed (median of {} paired rounds of {batch}; quartiles {:.2}x-{:.2}x; median calls {:.2} µs against {:.2} µs)",
        ratios[ratios.len() / 2],
        ratios.len(),
        ratios[ratios.len() / 4],
        ratios[3 * ratios.len() / 4],
        t_b * 1e6,
        t_a * 1e6
    )
}
