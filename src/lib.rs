//! umbrage: exact hard shadows with stencil shadow volumes on raw Vulkan.
#![forbid(unsafe_op_in_unsafe_fn)]
pub mod error;
pub mod geom;
pub mod scene;
pub mod shadow;
pub use error::{Error, Result};
