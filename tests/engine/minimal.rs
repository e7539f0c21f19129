//! `examples/minimal.rs`, the smallest raw-ash host of `ShadowPass`, run in-process with the
//! validation layer on: its stencil must match the box's analytic shadow (outside the 1-pixel
//! band), with enough shadowed pixels and no validation error. Like `tests/engine/embed.rs` it
//! includes the example's source, so no second build of it is needed; the Makefile's `test`
//! target also runs the example as an engine builds it (`--no-default-features`).

#[path = "../../examples/minimal.rs"]
#[allow(dead_code)] // the example's `main`
mod example;

#[test]
fn minimal_example_matches_the_analytic_shadow() {
    std::env::set_var("UMBRAGE_VALIDATION", "1");
    match example::run() {
        Ok(()) => {}
        // No Vulkan at all: a failure under CI, a loud skip on a developer's machine.
        Err(e) if e.starts_with("no Vulkan") && std::env::var_os("CI").is_none() => {
            eprintln!("SKIPPED (no Vulkan device, CI not set): {e}")
        }
        Err(e) => panic!("examples/minimal.rs: {e}"),
    }
}
