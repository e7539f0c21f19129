//! umbrage-minimal: builds `examples/minimal.rs` against the engine crate alone, with the
//! dependencies an engine has anyway (ash, glam, gpu-allocator, bytemuck, naga for its one
//! shader), so that what an engine compiles is what the example shows. The package has no code
//! of its own; run the example with `cargo run --example minimal` at the workspace root.
