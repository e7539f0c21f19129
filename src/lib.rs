//! umbrage: the engine crate. Exact hard shadows with stencil shadow volumes on raw Vulkan:
//! geometry, planning, the GPU layer and [`pass::ShadowPass`], what an engine links.
//!
//! Layers, each using only those before it: [`geom`] (meshes, topology, silhouettes, culling
//! volumes, the camera and light models; safe Rust, no Vulkan) <- [`shadow`] (pure CPU
//! planning: per caster and light the case, caps and index lists of McGuire et al. 2003; safe
//! Rust, no Vulkan) <- [`pass`] (the embeddable [`pass::ShadowPass`]: the plans on the GPU)
//! which uses [`gpu`] (thin ash wrappers, knowing nothing of shadows). The crate compiles the
//! pass's own shaders and nothing else; scenes, the CPU reference, umbrage's own renderer, the
//! conformance suite, the benchmark and the command line are the workspace's other crates
//! (ARCHITECTURE.md in the repository maps them).
//!
//! # Features
//!
#![doc = document_features::document_features!()]
//!
//! The dependencies are those of `Cargo.toml` (meshopt builds meshoptimizer's C++: a C++
//! compiler is needed).
//!
//! # Example
//!
//! Planning one light's shadow volumes on the CPU, with no Vulkan involved:
//!
//! ```
//! use glam::{Mat4, Vec3};
//! use umbrage::geom::{Camera, Light, LightKind, Mesh};
//! use umbrage::shadow::{plan_light, Case, Caster, Method, PlanInput};
//!
//! // A closed unit cube (counter-clockwise seen from outside), one metre above the origin.
//! let p = |x: f32, y: f32, z: f32| Vec3::new(x, y, z) - 0.5;
//! let positions = vec![
//!     p(0., 0., 0.), p(1., 0., 0.), p(1., 1., 0.), p(0., 1., 0.),
//!     p(0., 0., 1.), p(1., 0., 1.), p(1., 1., 1.), p(0., 1., 1.),
//! ];
//! let triangles = vec![
//!     [0, 2, 1], [0, 3, 2], [4, 5, 6], [4, 6, 7], [0, 1, 5], [0, 5, 4],
//!     [3, 6, 2], [3, 7, 6], [0, 4, 7], [0, 7, 3], [1, 2, 6], [1, 6, 5],
//! ];
//! let cube = Mesh::new(positions, triangles);
//! let caster = Caster::new("cube", &cube, Mat4::from_translation(Vec3::Y))?;
//! assert!(caster.is_manifold());
//!
//! let camera = Camera { eye: Vec3::new(0.0, 3.0, 6.0), target: Vec3::ZERO, ..Default::default() };
//! let light = Light {
//!     kind: LightKind::Point,
//!     position: Vec3::new(1.0, 5.0, 1.0),
//!     direction: Vec3::NEG_Y,
//!     color: Vec3::ONE,
//!     intensity: 1.0,
//!     radius: None,
//!     cone_deg: 45.0,
//!     area: None,
//! };
//! let (width, height) = (640, 480);
//! let view_proj = camera.proj_infinite(width as f32 / height as f32) * camera.view();
//! let input = PlanInput { camera: &camera, width, height, view_proj, light: &light, method: Method::McGuire };
//! let plan = plan_light(&input, std::slice::from_ref(&caster));
//!
//! let cp = &plan.casters[0];
//! assert_ne!(cp.case, Case::Culled);
//! assert!(cp.silhouette_edges >= 4 && cp.sides > 0);
//! // Index lists into each chunk's dual-length vertex buffer, ready to upload.
//! assert!(cp.chunks.iter().all(|c| !c.volume.is_empty() || !c.light_cap.is_empty()));
//! # Ok::<(), umbrage::Error>(())
//! ```
#![warn(unsafe_op_in_unsafe_fn)]
// `!(x > 0.0)` is used on purpose throughout: it is true for NaN, which must be rejected too.
#![allow(clippy::neg_cmp_op_on_partial_ord)]
pub mod error;
pub mod geom;
pub mod gpu;
mod named_enum;
pub mod pass;
pub mod shadow;
pub use error::{Error, Result};
pub use named_enum::NamedEnum;

/// What the exported macros need, not part of the API.
#[doc(hidden)]
pub mod __private {
    #[cfg(feature = "serde")]
    pub use serde;
}
