//! Thin wrappers over ash: context, memory, images, pipelines. Knows nothing about shadows.
//! The engine's `unsafe` lives in the GPU layer: this module and [`crate::pass`] (the other
//! crates of the workspace that record their own command buffers have theirs); [`crate::geom`]
//! and [`crate::shadow`] forbid it. Every block has a `// SAFETY:` line and every `unsafe fn` a
//! `# Safety` section (`Cargo.toml`'s `[workspace.lints]`).
#![warn(missing_docs)]
pub mod accel;
pub mod cache;
pub mod caps;
pub mod context;
pub mod creation;
pub mod descriptors;
pub mod fault;
pub mod pipeline;
mod probe;
pub mod quirks;
pub mod resources;
pub mod validation;
pub mod shaders {
    //! The naga-compiled SPIR-V of every shader in `shaders/` (see build.rs).
    include!(concat!(env!("OUT_DIR"), "/shaders.rs"));
}
pub use caps::{DeviceCaps, FeatureSet};
pub use context::{Context, DeviceInfo, Features, GpuDevice, ValidationMode};
pub use resources::{Buffer, Image};
