//! Indexed triangle meshes: the one geometry type every layer shares.

use crate::error::{Error, Result};
use glam::Vec3;

/// An indexed triangle mesh in object space. Triangles are counter-clockwise seen from
/// outside (outward normal = (p1-p0) x (p2-p0)).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Mesh {
    pub positions: Vec<Vec3>,
    pub triangles: Vec<[u32; 3]>,
}

/// Axis-aligned bounding box. An empty box has `min > max`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    pub min: Vec3,
    pub max: Vec3,
}

impl Aabb {
    pub const EMPTY: Aabb = Aabb { min: Vec3::splat(f32::INFINITY), max: Vec3::splat(f32::NEG_INFINITY) };

    pub fn from_points<'a>(points: impl IntoIterator<Item = &'a Vec3>) -> Aabb {
        let mut b = Aabb::EMPTY;
        for p in points {
            b.extend(*p);
        }
        b
    }
    pub fn extend(&mut self, p: Vec3) {
        self.min = self.min.min(p);
        self.max = self.max.max(p);
    }
    pub fn union(self, o: Aabb) -> Aabb {
        Aabb { min: self.min.min(o.min), max: self.max.max(o.max) }
    }
    pub fn is_empty(&self) -> bool {
        self.min.x > self.max.x || self.min.y > self.max.y || self.min.z > self.max.z
    }
    pub fn center(&self) -> Vec3 {
        (self.min + self.max) * 0.5
    }
    pub fn extent(&self) -> Vec3 {
        self.max - self.min
    }
    pub fn corners(&self) -> [Vec3; 8] {
        let (a, b) = (self.min, self.max);
        [
            Vec3::new(a.x, a.y, a.z),
            Vec3::new(b.x, a.y, a.z),
            Vec3::new(a.x, b.y, a.z),
            Vec3::new(b.x, b.y, a.z),
            Vec3::new(a.x, a.y, b.z),
            Vec3::new(b.x, a.y, b.z),
            Vec3::new(a.x, b.y, b.z),
            Vec3::new(b.x, b.y, b.z),
        ]
    }
    pub fn contains(&self, p: Vec3) -> bool {
        p.cmpge(self.min).all() && p.cmple(self.max).all()
    }
    /// The box of this box's corners transformed by `m` (an affine matrix).
    pub fn transformed(&self, m: &glam::Mat4) -> Aabb {
        Aabb::from_points(self.corners().iter().map(|c| m.transform_point3(*c)).collect::<Vec<_>>().iter())
    }
}

impl Mesh {
    pub fn new(positions: Vec<Vec3>, triangles: Vec<[u32; 3]>) -> Mesh {
        Mesh { positions, triangles }
    }
    pub fn is_empty(&self) -> bool {
        self.triangles.is_empty()
    }
    pub fn bounds(&self) -> Aabb {
        Aabb::from_points(self.positions.iter())
    }
    pub fn triangle(&self, t: usize) -> [Vec3; 3] {
        let [a, b, c] = self.triangles[t];
        [self.positions[a as usize], self.positions[b as usize], self.positions[c as usize]]
    }
    /// Unnormalised outward face normal (p1-p0) x (p2-p0).
    pub fn face_normal(&self, t: usize) -> Vec3 {
        let [a, b, c] = self.triangle(t);
        (b - a).cross(c - a)
    }

    /// Checks what every consumer relies on: at least one triangle, every index in range,
    /// every coordinate finite. Degenerate (zero-area) triangles are allowed here: they are
    /// harmless to rasterise, and the shadow path deals with them explicitly.
    pub fn validate(&self, name: &str) -> Result<()> {
        if self.triangles.is_empty() {
            return Err(Error::mesh(name, "mesh is empty (no triangles)"));
        }
        if let Some((i, p)) = self.positions.iter().enumerate().find(|(_, p)| !p.is_finite()) {
            return Err(Error::mesh(name, format!("vertex {i} has a non-finite coordinate {p:?}")));
        }
        let n = self.positions.len() as u32;
        if let Some((t, tri)) = self.triangles.iter().enumerate().find(|(_, t)| t.iter().any(|&i| i >= n)) {
            return Err(Error::mesh(name, format!("triangle {t} indexes vertex {tri:?} but there are only {n} vertices")));
        }
        Ok(())
    }

    /// Applies an affine transform to every vertex (winding flips if the determinant is negative:
    /// the caller decides whether to swap, see [`Mesh::transformed`]).
    pub fn transformed(&self, m: &glam::Mat4) -> Mesh {
        let mut out = Mesh {
            positions: self.positions.iter().map(|p| m.transform_point3(*p)).collect(),
            triangles: self.triangles.clone(),
        };
        if m.determinant() < 0.0 {
            for t in &mut out.triangles {
                t.swap(1, 2);
            }
        }
        out
    }
}
