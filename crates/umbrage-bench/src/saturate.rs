//! How every limit is measured ([`super::limits`], [`super::pass_limits`],
//! [`super::compute_read`]): a recorded workload timed on the GPU ([`time_gpu`]: repetitions
//! in submissions of their own, timestamps around the timed part, the median), and swept to
//! saturation ([`saturate`]: the workload doubled until its rate stops growing, the peak kept),
//! on targets of their own ([`depth_stencil`]).

use super::stats::median;
use ash::vk;
use umbrage::error::{Error, Result};
use umbrage::gpu::{Context, Image};

/// A depth-stencil attachment of `extent` in the device's depth format (the limits' targets).
pub(super) fn depth_stencil(ctx: &Context, name: &str, extent: vk::Extent2D) -> Result<Image> {
    let aspect = vk::ImageAspectFlags::DEPTH | vk::ImageAspectFlags::STENCIL;
    Image::new_2d(ctx, name, ctx.depth_format, extent, vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT, aspect)
}

/// The median GPU time of `reps` repetitions of `timed` (after one warm-up repetition), ms:
/// each in a submission of its own after `prep`, with timestamps 0 and 1 of `queries` (a pool
/// of at least two timestamp queries) written around it, outside any rendering instance.
pub(super) fn time_gpu(
    ctx: &Context,
    queries: vk::QueryPool,
    reps: usize,
    prep: &dyn Fn(vk::CommandBuffer),
    timed: &dyn Fn(vk::CommandBuffer),
) -> Result<f64> {
    let d = &ctx.device;
    let mut ms = Vec::with_capacity(reps);
    for rep in 0..=reps.max(1) {
        ctx.one_shot(|cb| {
            // SAFETY: `cb` is recording (one_shot waits for it); the pool has 2 queries.
            unsafe { d.cmd_reset_query_pool(cb, queries, 0, 2) };
            prep(cb);
            // SAFETY: as above.
            unsafe { d.cmd_write_timestamp2(cb, vk::PipelineStageFlags2::ALL_COMMANDS, queries, 0) };
            timed(cb);
            // SAFETY: as above.
            unsafe { d.cmd_write_timestamp2(cb, vk::PipelineStageFlags2::ALL_COMMANDS, queries, 1) };
        })?;
        let mut raw = [0u64; 2];
        // SAFETY: one_shot waited for the submission: both queries are available.
        unsafe { d.get_query_pool_results(queries, 0, &mut raw, vk::QueryResultFlags::TYPE_64 | vk::QueryResultFlags::WAIT) }
            .map_err(Error::vk("vkGetQueryPoolResults"))?;
        if rep > 0 {
            ms.push(raw[1].wrapping_sub(raw[0]) as f64 * ctx.features.timestamp_period_ns as f64 * 1e-6);
        }
    }
    Ok(median(ms))
}

/// A sweep's rules: at most `max_steps` points, and a point slower than `max_ms` ends it.
#[derive(Clone, Copy, Debug)]
pub(super) struct Rules {
    /// Most points (doublings) a sweep takes.
    pub max_steps: u32,
    /// A point whose time exceeds this ends the sweep, ms.
    pub max_ms: f64,
}

/// A point faster than this is recorded but does not set the peak (where any point is slower):
/// lavapipe 25's timestamps around a few microseconds of work land anywhere (its draw-call
/// sweep read 20-30 M draws/s at 1024 draws and 0.3-0.4 M at 4096 and more, in one run), ms.
pub(super) const RESOLVABLE_MS: f64 = 0.5;

/// Sweeps a workload of `units` (a layer, a grid, a draw) repeated k = 1, 2, 4, ... times,
/// `time(k)` its GPU ms, until the rate (`units` x k / time, in `unit` per second) gains
/// under 5 % twice running, a point takes over `rules.max_ms`, or `rules.max_steps` points
/// ran: the peak rate and every point as `[units x k, rate]`. Points under [`RESOLVABLE_MS`]
/// neither set the peak nor end the sweep as flat, unless no point reaches it.
pub(super) fn saturate(rules: Rules, units: f64, unit: f64, mut time: impl FnMut(u32) -> Result<f64>) -> Result<(f64, Vec<[f64; 2]>)> {
    let (mut best, mut any, mut flat, mut k) = (0.0f64, 0.0f64, 0, 1u32);
    let mut points = Vec::new();
    for _ in 0..rules.max_steps.max(1) {
        let ms = time(k)?;
        let rate = units * k as f64 / (ms.max(1e-6) * 1e-3) / unit;
        points.push([units * k as f64, rate]);
        any = any.max(rate);
        if ms >= RESOLVABLE_MS {
            flat = if rate > best * 1.05 { 0 } else { flat + 1 };
            best = best.max(rate);
        }
        if flat >= 2 || ms > rules.max_ms {
            break;
        }
        k *= 2;
    }
    Ok((if best > 0.0 { best } else { any }, points))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_sweep_stops_where_the_rate_stops_growing() {
        // 1 ms of overhead plus 1 ms per unit: the rate approaches 1000 units/s.
        let rules = Rules { max_steps: 20, max_ms: 1e9 };
        let (peak, points) = saturate(rules, 1.0, 1.0, |k| Ok(1.0 + k as f64)).unwrap();
        assert!(peak > 900.0 && peak < 1000.0, "{peak}");
        assert!(points.len() < 10, "{points:?}");
        assert!(points.windows(2).all(|w| w[1][0] == 2.0 * w[0][0]));
        // A slow point ends the sweep; so does the step limit.
        let (_, slow) = saturate(Rules { max_steps: 20, max_ms: 5.0 }, 1.0, 1.0, |k| Ok(k as f64 * 3.0)).unwrap();
        assert_eq!(slow.len(), 2);
        let (_, few) = saturate(Rules { max_steps: 3, max_ms: 1e9 }, 1.0, 1.0, |_| Ok(1.0)).unwrap();
        assert_eq!(few.len(), 3);
        // Points too short to time neither set the peak nor end the sweep...
        let (peak, points) = saturate(rules, 1.0, 1.0, |k| Ok(if k < 4 { 0.001 } else { k as f64 })).unwrap();
        assert!(points.len() > 3 && (peak - 1000.0).abs() < 1e-9, "{peak} {points:?}");
        // ...unless none is longer.
        let (peak, _) = saturate(Rules { max_steps: 3, max_ms: 1e9 }, 1.0, 1.0, |_| Ok(0.01)).unwrap();
        assert!((peak - 400_000.0).abs() < 1e-6, "{peak}");
        // An error stops it too.
        assert!(saturate(rules, 1.0, 1.0, |_| Err(Error::Internal("x".into()))).is_err());
    }
}
