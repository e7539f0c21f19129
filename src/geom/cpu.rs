//! Which copy of the per-light hot loops runs: the facing words
//! ([`FacePlanes::facing_packed`](super::planes::FacePlanes::facing_packed)) and the edge scan
//! ([`EdgeScan::scan_into`](super::edgescan::EdgeScan::scan_into)) are compiled once for the
//! portable target (x86-64's baseline: SSE2, no `popcnt`) and again for two x86-64 levels,
//! and the best copy this CPU runs is picked at run time (the `multiversion` crate: no
//! `unsafe` here, and the binary stays portable). Every copy is the same source, except two
//! kernels written with `std::arch` value intrinsics for the copies that have the features
//! (the facing's dot products 8 planes a vector with AVX, the scan's residual edges by SSSE3
//! byte shuffles; safe code: `#[target_feature]` functions called from the copies compiled
//! with those features). Every copy gives the same bits, and is tested against the portable
//! one ([`set_portable_only`]).

use std::sync::atomic::{AtomicBool, Ordering};

/// Compiles the item once more per x86-64 level, the best level this CPU has picked at run
/// time: v3 (AVX2, BMI1/2, FMA, `lzcnt`, `popcnt`) and v2 (`popcnt`, SSE4.2). Elsewhere, and
/// on older x86-64 CPUs, the portable copy runs.
macro_rules! per_cpu_level {
    ($item:item) => {
        #[multiversion::multiversion(targets(
            "x86_64+avx+avx2+bmi1+bmi2+fma+lzcnt+popcnt+sse3+ssse3+sse4.1+sse4.2",
            "x86_64+popcnt+sse3+ssse3+sse4.1+sse4.2"
        ))]
        $item
    };
}
pub(crate) use per_cpu_level;

/// Inside an item of [`per_cpu_level!`]: `$fast` in the copies compiled with the x86-64
/// feature `$feature`, `$portable` in the others. A closure given as `$fast` has its copy's
/// target features, so it may call a `#[target_feature]` function of that feature as safe
/// code; the other copies never see it.
macro_rules! by_feature {
    ($feature:literal, $fast:expr, $portable:expr) => {{
        #[multiversion::target::target_cfg(all(target_arch = "x86_64", target_feature = $feature))]
        macro_rules! pick {
            () => {
                $fast
            };
        }
        #[multiversion::target::target_cfg(not(all(target_arch = "x86_64", target_feature = $feature)))]
        macro_rules! pick {
            () => {
                $portable
            };
        }
        pick!()
    }};
}
pub(crate) use by_feature;

static PORTABLE_ONLY: AtomicBool = AtomicBool::new(false);

/// Runs only the portable copies from now on (`true`), in every thread, or the best ones
/// again (`false`, the default): for tests that compare the copies, and for measuring what
/// the CPU-specific copies buy. The results are the same either way.
pub fn set_portable_only(on: bool) {
    PORTABLE_ONLY.store(on, Ordering::Relaxed);
}

/// Whether only the portable copies run ([`set_portable_only`]).
pub fn portable_only() -> bool {
    PORTABLE_ONLY.load(Ordering::Relaxed)
}

/// The copy that runs now: `"x86-64-v3"`, `"x86-64-v2"` or `"portable"` (other architectures,
/// older CPUs, or [`set_portable_only`]).
pub fn level() -> &'static str {
    if portable_only() {
        return "portable";
    }
    #[cfg(target_arch = "x86_64")]
    {
        let v2 = std::arch::is_x86_feature_detected!("popcnt")
            && std::arch::is_x86_feature_detected!("sse3")
            && std::arch::is_x86_feature_detected!("ssse3")
            && std::arch::is_x86_feature_detected!("sse4.1")
            && std::arch::is_x86_feature_detected!("sse4.2");
        let v3 = v2
            && std::arch::is_x86_feature_detected!("avx")
            && std::arch::is_x86_feature_detected!("avx2")
            && std::arch::is_x86_feature_detected!("bmi1")
            && std::arch::is_x86_feature_detected!("bmi2")
            && std::arch::is_x86_feature_detected!("fma")
            && std::arch::is_x86_feature_detected!("lzcnt");
        if v3 {
            return "x86-64-v3";
        }
        if v2 {
            return "x86-64-v2";
        }
    }
    "portable"
}

/// Held by the tests that flip [`set_portable_only`].
#[cfg(test)]
static SWITCH: std::sync::Mutex<()> = std::sync::Mutex::new(());

/// Runs `f` on the portable copies, then on the best ones, checks that both give the same
/// result, and returns it. Serialised: the switch is process-wide.
#[cfg(test)]
pub(crate) fn on_each_copy<T: PartialEq + std::fmt::Debug>(mut f: impl FnMut() -> T) -> T {
    let _held = SWITCH.lock().unwrap_or_else(|e| e.into_inner());
    set_portable_only(true);
    let portable = f();
    set_portable_only(false);
    let best = f();
    assert_eq!(portable, best, "the portable copy and the {} one differ", level());
    best
}

/// The threads this process may use (`std::thread::available_parallelism`, at least 1), asked
/// once per process: on Linux each call reads the cgroup's CPU quota from files (system calls
/// that the per-frame planning has no reason to repeat).
pub fn cores() -> usize {
    static CORES: std::sync::OnceLock<usize> = std::sync::OnceLock::new();
    *CORES.get_or_init(|| std::thread::available_parallelism().map_or(1, |n| n.get()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_switch_selects_the_portable_copy() {
        let _held = SWITCH.lock().unwrap_or_else(|e| e.into_inner());
        set_portable_only(true);
        assert_eq!((portable_only(), level()), (true, "portable"));
        set_portable_only(false);
        assert!(!portable_only());
    }
}
