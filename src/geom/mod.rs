//! Pure CPU geometry: no Vulkan, no `unsafe`. The heart of the shadow algorithm.
pub mod mesh;
pub use mesh::{Aabb, Mesh};
pub mod bounds;
pub mod predicates;
pub mod silhouette;
pub mod topology;
