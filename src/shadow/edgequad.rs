//! The GPU-only method of the "Cg Shadow Volumes" article: no silhouette work on the CPU.
//!
//! Every face of a closed caster gets its own three vertices, each carrying the face's plane
//! `(n, d)`; every manifold edge gets a zero-area quad joining the two faces' copies of its end
//! points. The vertex shader sends a vertex to infinity (away from the light) when *its* face
//! does not face the light. Faces facing the light stay as the light cap, the others become the
//! dark cap at infinity, and the quads of edges between a lit and an unlit face open into the
//! sides; all other quads stay degenerate. The three vertices of a face carry the same plane, so
//! they always agree (the test `n . L + d * L.w > 0` gets identical inputs): the volume is closed
//! by construction, as on the CPU path. Cost: every face and two triangles per edge, every frame.

use super::caster::Caster;

/// Static geometry for one caster: vertices `[x, y, z, nx, ny, nz, d, 0]` (object space), faces
/// (drawn with depth compare NEVER, like light caps: each is a light or a dark cap) and the
/// edge quads (the sides, depth test LESS), as u32 indices.
pub struct EdgeQuadMesh {
    /// Three per face: position, then the face plane `(n, d)` (`n . p + d = 0`), then 0.
    pub vertices: Vec<[f32; 8]>,
    /// Every face's three vertices, in order (`3t, 3t + 1, 3t + 2`).
    pub faces: Vec<u32>,
    /// Two triangles per manifold edge, joining the two faces' copies of its end points.
    pub quads: Vec<u32>,
}

impl EdgeQuadMesh {
    /// Builds the edge-quad mesh of a closed manifold caster. Mirrored casters have their
    /// planes negated so that "facing" means facing in world space.
    pub fn new(caster: &Caster) -> EdgeQuadMesh {
        let mesh = caster.mesh();
        let sign = if caster.mirrored { -1.0 } else { 1.0 };
        let mut vertices = Vec::with_capacity(mesh.triangles.len() * 3);
        let mut faces = Vec::with_capacity(mesh.triangles.len() * 3);
        for t in 0..mesh.triangles.len() {
            let [p0, p1, p2] = mesh.triangle(t);
            let n = (p1 - p0).cross(p2 - p0) * sign;
            let d = -n.dot(p0);
            for p in [p0, p1, p2] {
                faces.push(vertices.len() as u32);
                vertices.push([p.x, p.y, p.z, n.x, n.y, n.z, d, 0.0]);
            }
        }
        // Vertex of triangle t at corner c is 3t + c.
        let mut quads = Vec::with_capacity(caster.topology.manifold_edges.len() * 6);
        for e in &caster.topology.manifold_edges {
            // t0 walks a -> b at corner c0 (a = corner c0, b = corner c0 + 1); t1 walks b -> a.
            let a0 = 3 * e.t0 + e.c0 as u32;
            let b0 = 3 * e.t0 + (e.c0 as u32 + 1) % 3;
            let b1 = 3 * e.t1 + e.c1 as u32;
            let a1 = 3 * e.t1 + (e.c1 as u32 + 1) % 3;
            // With t0 lit: (b, a, a_inf), (b, a_inf, b_inf), the CPU path's side of edge a -> b;
            // with t1 lit the same indices give the side of b -> a (same cyclic order).
            quads.extend_from_slice(&[b0, a0, a1, b0, a1, b1]);
        }
        EdgeQuadMesh { vertices, faces, quads }
    }

    /// Triangle counts `(faces, quad triangles)` the GPU draws every frame.
    pub fn triangles(&self) -> (usize, usize) {
        (self.faces.len() / 3, self.quads.len() / 3)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::testmesh::{torus, uv_sphere};
    use glam::{Mat4, Vec3, Vec4};

    /// CPU emulation of the vertex shader: position after EXTRUDE, as (point, is_infinite).
    fn extrude(v: &[f32; 8], l: Vec4) -> (Vec3, bool) {
        let p = Vec3::new(v[0], v[1], v[2]);
        let n = Vec3::new(v[3], v[4], v[5]);
        let facing = n.dot(l.truncate()) + v[6] * l.w > 0.0;
        if facing {
            (p, false)
        } else {
            ((p * l.w - l.truncate()).normalize(), true)
        }
    }

    /// Every directed edge of the non-degenerate emitted triangles cancels: the volume is
    /// closed (points at infinity compared by direction, quantised).
    #[test]
    fn edge_quad_volumes_are_closed() {
        for mesh in [uv_sphere(1.0, 24, 12), torus(1.0, 0.3, 24, 12)] {
            let c = Caster::new("m", &mesh, Mat4::IDENTITY).unwrap();
            let eq = EdgeQuadMesh::new(&c);
            assert_eq!(eq.triangles(), (c.triangle_count, c.topology.manifold_edges.len() * 2));
            for l in [Vec4::new(3.0, 2.0, 0.5, 1.0), Vec4::new(0.2, 0.1, 0.05, 1.0), Vec4::new(0.3, 1.0, 0.2, 0.0)] {
                let key = |(p, inf): (Vec3, bool)| {
                    let q = (p * 1e4).round();
                    (q.x as i64, q.y as i64, q.z as i64, inf)
                };
                let mut count = std::collections::HashMap::new();
                for tri in eq.faces.chunks(3).chain(eq.quads.chunks(3)) {
                    let k: Vec<_> = tri.iter().map(|&i| key(extrude(&eq.vertices[i as usize], l))).collect();
                    if k[0] == k[1] || k[1] == k[2] || k[0] == k[2] {
                        continue; // degenerate
                    }
                    for j in 0..3 {
                        *count.entry((k[j], k[(j + 1) % 3])).or_insert(0i32) += 1;
                        *count.entry((k[(j + 1) % 3], k[j])).or_insert(0i32) -= 1;
                    }
                }
                assert!(count.values().all(|&v| v == 0), "open edges for light {l:?}");
            }
        }
    }
}
