//! Compiles this crate's shaders in `shaders/` to SPIR-V (naga, through `umbrage-shaderc`),
//! embedded by its `shaders` module, and the one form of the engine's `shadow.vert` only the
//! suite uses: `RAW_W0`, which hands the driver w = 0 as it is. The pass's own shaders are the
//! engine's (`umbrage::gpu::shaders`).
fn main() {
    umbrage_shaderc::Shaders::new().dir("shaders").variant("../../shaders/shadow.vert", "raw", "RAW_W0").build();
}
