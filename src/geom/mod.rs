//! Pure CPU geometry: no Vulkan, no `unsafe`. The heart of the shadow algorithm.
#![forbid(unsafe_code)]
#![warn(missing_docs)]
pub mod mesh;
pub use mesh::{Aabb, Mesh};
pub mod area;
mod area_shape;
pub use area::{AreaLight, AreaShape};
pub mod bounds;
pub mod cone;
pub mod cpu;
pub mod edgescan;
pub mod light;
pub use order::TriangleOrder;
pub mod order;
pub use light::{Camera, Light, LightKind};
pub mod planes;
pub mod predicates;
pub mod shading;
pub mod silhouette;
pub mod sphere;
pub use sphere::Sphere;
#[cfg(test)]
pub(crate) mod testmesh;
pub mod topology;
