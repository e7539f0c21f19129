//! The frame, as McGuire et al. 2003 section 8 lay it out:
//!
//! 1. ambient pass: depth + the ambient term into a float target, plus a G-buffer
//!    (albedo, face normal, eye-relative position) the illumination reads;
//! 2. per light: shadow determination into the stencil (cleared inside the light's scissor),
//!    then illumination where the stencil count is zero, added into the float target;
//! 3. final pass: tone map to the sRGB output.
//!
//! Rendering is camera-relative: positions are uploaded as (world - eye), computed in f64, so
//! scenes 1e5 from the origin keep f32 precision where it matters (near the eye).
//!
//! Stencil convention (documented in ARCHITECTURE.md): counter-clockwise front faces; z-pass
//! increments on front faces and decrements on back faces when the depth test passes; z-fail
//! increments on back faces and decrements on front faces when it fails. Both give +1 per
//! enclosing volume, with wrap ops so the order of faces does not matter.

pub mod frame;
pub mod options;
pub mod shadowmap;
pub mod stats;
pub mod targets;

pub use frame::{FrameOutput, Renderer};
pub use options::{Counter, DepthMode, IndexFormat, RenderOptions, TransmitMode, View};
pub use stats::Stats;
