//! Compiles the shadow pass's shaders in `shaders/` to SPIR-V (naga, through
//! `umbrage-shaderc`) into `$OUT_DIR/shaders.rs`, embedded by `gpu::shaders`. Only the pass's
//! own shaders live here: the renderer, the conformance suite and the benchmark compile theirs.
fn main() {
    umbrage_shaderc::Shaders::new().dir("shaders").build();
}
