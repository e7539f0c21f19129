//! Compiles this crate's shaders in `shaders/` to SPIR-V (naga, through `umbrage-shaderc`),
//! embedded by its `shaders` module. The shadow pass's shaders are the engine's (`umbrage::gpu::shaders`).
fn main() {
    umbrage_shaderc::Shaders::new().dir("shaders").build();
}
