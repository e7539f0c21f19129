//! The in-process integration tests, one binary: the engine driven through the workspace's
//! crates (scenes, the renderer, the reference), every GPU test with Vulkan validation on.
//! Each module is one suite; run one with `cargo test --test engine <module>::`.

#[path = "../common/mod.rs"]
mod common;

mod bench_counters;
mod compute;
mod conform_coverage;
mod contract;
mod counts;
mod devices;
mod embed;
mod gpu_smoke;
mod hard_cases;
mod keep;
mod level_motion;
mod mesh;
mod minimal;
mod motion;
mod msaa;
mod parts;
mod pass_contract;
mod pixels;
mod planar;
mod proptest_gpu;
mod rayquery;
mod real_assets;
mod self_shadow;
mod shaders;
mod shading;
mod shadow_pass;
mod spheres;
mod teardown;
mod transparent;
mod wgpu_host;
