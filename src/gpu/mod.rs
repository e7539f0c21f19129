//! Thin wrappers over ash: context, memory, images, pipelines. Knows nothing about shadows.
//! All of the crate's `unsafe` lives under this module and `render`.
#![warn(missing_docs)]
pub mod context;
pub mod descriptors;
pub mod fault;
pub mod pipeline;
pub mod resources;
pub mod validation;
pub mod shaders {
    //! The naga-compiled SPIR-V of every shader in `shaders/` (see build.rs).
    include!(concat!(env!("OUT_DIR"), "/shaders.rs"));
}
pub use context::{Context, DeviceInfo, Features, GpuDevice, ValidationMode};
pub use resources::{Buffer, Image};
