//! Indexed triangle meshes: the one geometry type every layer shares.

use crate::error::{Error, Result};
use glam::Vec3;

/// An indexed triangle mesh in object space. Triangles are counter-clockwise seen from
/// outside (outward normal = (p1-p0) x (p2-p0)).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Mesh {
    /// Vertex positions, object space.
    pub positions: Vec<Vec3>,
    /// Vertex indices into `positions`, three per triangle, counter-clockwise seen from outside.
    pub triangles: Vec<[u32; 3]>,
}

/// Axis-aligned bounding box. An empty box has `min > max`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    /// Smallest x, y and z of the box (inclusive).
    pub min: Vec3,
    /// Largest x, y and z of the box (inclusive).
    pub max: Vec3,
}

impl Aabb {
    /// The empty box (`min = +inf`, `max = -inf`): the identity of [`union`](Aabb::union) and [`extend`](Aabb::extend).
    pub const EMPTY: Aabb = Aabb { min: Vec3::splat(f32::INFINITY), max: Vec3::splat(f32::NEG_INFINITY) };

    /// The smallest box containing every point ([`Aabb::EMPTY`] for none).
    pub fn from_points<'a>(points: impl IntoIterator<Item = &'a Vec3>) -> Aabb {
        let mut b = Aabb::EMPTY;
        for p in points {
            b.extend(*p);
        }
        b
    }
    /// Grows the box to contain `p`.
    pub fn extend(&mut self, p: Vec3) {
        self.min = self.min.min(p);
        self.max = self.max.max(p);
    }
    /// The smallest box containing both boxes.
    pub fn union(self, o: Aabb) -> Aabb {
        Aabb { min: self.min.min(o.min), max: self.max.max(o.max) }
    }
    /// True iff the box contains no point (`min > max` on some axis).
    pub fn is_empty(&self) -> bool {
        self.min.x > self.max.x || self.min.y > self.max.y || self.min.z > self.max.z
    }
    /// The centre `(min + max) / 2` (the apex of the dark-cap fan is the caster's object-space centre).
    pub fn center(&self) -> Vec3 {
        (self.min + self.max) * 0.5
    }
    /// Edge lengths `max - min`.
    pub fn extent(&self) -> Vec3 {
        self.max - self.min
    }
    /// The eight corners; bit 0 of the index picks max x, bit 1 max y, bit 2 max z.
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
    /// True iff `p` is inside or on the box.
    pub fn contains(&self, p: Vec3) -> bool {
        p.cmpge(self.min).all() && p.cmple(self.max).all()
    }
    /// The box of this box's corners transformed by `m` (an affine matrix).
    pub fn transformed(&self, m: &glam::Mat4) -> Aabb {
        Aabb::from_points(self.corners().iter().map(|c| m.transform_point3(*c)).collect::<Vec<_>>().iter())
    }
}

impl Mesh {
    /// A mesh from positions and triangles, unchecked (see [`Mesh::validate`]).
    pub fn new(positions: Vec<Vec3>, triangles: Vec<[u32; 3]>) -> Mesh {
        Mesh { positions, triangles }
    }
    /// True iff the mesh has no triangles.
    pub fn is_empty(&self) -> bool {
        self.triangles.is_empty()
    }
    /// The object-space bounding box of the positions (all of them, used or not).
    pub fn bounds(&self) -> Aabb {
        Aabb::from_points(self.positions.iter())
    }
    /// The three corner positions of triangle `t`, in winding order. Panics when out of range.
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
        let mut out =
            Mesh { positions: self.positions.iter().map(|p| m.transform_point3(*p)).collect(), triangles: self.triangles.clone() };
        if m.determinant() < 0.0 {
            for t in &mut out.triangles {
                t.swap(1, 2);
            }
        }
        out
    }
}

impl Mesh {
    /// Whether `p` lies inside this closed mesh (parity of crossings along a fixed, skewed ray,
    /// in f64). Meaningful only for closed meshes; used to notice a camera inside a caster.
    pub fn contains_point(&self, p: glam::DVec3) -> bool {
        // A direction unlikely to graze edges of axis-aligned or symmetric meshes.
        let d = glam::DVec3::new(0.5773, 0.6191, 0.5327).normalize();
        let mut crossings = 0u32;
        for t in 0..self.triangles.len() {
            let [a, b, c] = self.triangle(t).map(|v| v.as_dvec3());
            let (e1, e2) = (b - a, c - a);
            let h = d.cross(e2);
            let det = e1.dot(h);
            if det.abs() < 1e-300 {
                continue;
            }
            let s = p - a;
            let u = s.dot(h) / det;
            let q = s.cross(e1);
            let v = d.dot(q) / det;
            let tt = e2.dot(q) / det;
            if u >= 0.0 && v >= 0.0 && u + v <= 1.0 && tt > 0.0 {
                crossings += 1;
            }
        }
        crossings % 2 == 1
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cube() -> Mesh {
        let v = [
            [-1.0, -1.0, -1.0],
            [1.0, -1.0, -1.0],
            [1.0, 1.0, -1.0],
            [-1.0, 1.0, -1.0],
            [-1.0, -1.0, 1.0],
            [1.0, -1.0, 1.0],
            [1.0, 1.0, 1.0],
            [-1.0, 1.0, 1.0],
        ];
        let q = [[0, 3, 2, 1], [4, 5, 6, 7], [0, 1, 5, 4], [3, 7, 6, 2], [0, 4, 7, 3], [1, 2, 6, 5]];
        let mut tris = Vec::new();
        for f in q {
            tris.push([f[0], f[1], f[2]]);
            tris.push([f[0], f[2], f[3]]);
        }
        Mesh::new(v.iter().map(|p| Vec3::from_array(*p)).collect(), tris)
    }

    #[test]
    fn contains_point_by_parity() {
        let c = cube();
        assert!(c.contains_point(glam::DVec3::ZERO));
        assert!(c.contains_point(glam::DVec3::new(0.9, -0.9, 0.5)));
        assert!(!c.contains_point(glam::DVec3::new(1.5, 0.0, 0.0)));
        assert!(!c.contains_point(glam::DVec3::new(0.0, 0.0, -3.0)));
    }

    #[test]
    fn validate_rejects_bad_meshes() {
        assert!(Mesh::default().validate("e").is_err());
        let mut c = cube();
        c.positions[2].y = f32::NAN;
        assert!(c.validate("nan").unwrap_err().to_string().contains("non-finite"));
        let mut c = cube();
        c.triangles[0][1] = 99;
        assert!(c.validate("idx").unwrap_err().to_string().contains("indexes vertex"));
        assert!(cube().validate("ok").is_ok());
    }
}
