//! umbrage: exact hard shadows with stencil shadow volumes on raw Vulkan.
//!
//! Layers, dependencies pointing one way: [`scene`] -> [`geom`] -> [`shadow`] (pure CPU
//! planning) -> [`gpu`] / [`render`]. [`reference`] is the exact CPU ground truth and shares
//! nothing with the shadow algorithm but the camera model.
#![warn(unsafe_op_in_unsafe_fn)]
// `!(x > 0.0)` is used on purpose throughout: it is true for NaN, which must be rejected too.
#![allow(clippy::neg_cmp_op_on_partial_ord)]
pub mod accuracy;
pub mod bench;
pub mod conform;
pub mod error;
pub mod geom;
pub mod gpu;
pub mod output;
pub mod reference;
pub mod render;
pub mod scene;
pub mod shadow;
pub use error::{Error, Result};
