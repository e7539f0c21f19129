//! The benches' streaming sums compiled per x86-64 level, like the facing and the edge scan
//! (`umbrage::geom::cpu`), so that both sides of a comparison get the same instructions.

/// `umbrage::geom::cpu`'s `per_cpu_level!` for the benches (the crate's is private): the same
/// target list.
macro_rules! per_cpu_level {
    ($item:item) => {
        #[multiversion::multiversion(targets(
            "x86_64+avx+avx2+bmi1+bmi2+fma+lzcnt+popcnt+sse3+ssse3+sse4.1+sse4.2",
            "x86_64+popcnt+sse3+ssse3+sse4.1+sse4.2"
        ))]
        $item
    };
}
