//! Smooth shading normals for meshes drawn from flat triangles, with the bound that keeps smooth
//! shading consistent with exact shadow volumes at the terminator.
//!
//! A shadow volume shadows a caster's light-facing side exactly along its polygonal silhouette:
//! every triangle that faces away from the light is in shadow. Smooth (interpolated) normals
//! still light part of the last light-facing triangles near that silhouette, so plain smooth
//! shading steps from lit to shadowed along triangle edges (the faceted terminator users of
//! shadow volumes complain of). [`corner_normals`] gives each triangle corner its smooth normal
//! `n` and a bound `b`: wherever a triangle faces away from a light (`n_F · L <= 0`), each of
//! its corners has `n · L <= b`, because `n` is within `asin b` of `n_F`. Interpolating `n` and
//! `b` with the same weights keeps `m · L <= b` over the whole triangle (`m` the interpolated,
//! unnormalised normal), so the lighting `max(0, (m · L - b) / (|m| - b))` is 0 on every
//! back-facing triangle, reaches 0 continuously on the lit side before the silhouette, and is
//! the ordinary smooth `n · L` on well-tessellated meshes (where `b` is small). Which pixels are
//! lit (the stencil and the geometric facing) does not change.

use glam::DVec3;

/// The crease angle: faces meeting at a vertex at more than this are not smoothed together
/// (a box stays flat; a sphere of 8 or more segments a turn is smooth).
pub const CREASE_DEG: f64 = 50.0;

/// One triangle corner's smooth shading normal.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct CornerNormal {
    /// Unit normal: the area-weighted mean of the normals of the faces around the corner's
    /// vertex that lie within the crease angle of the corner's own face (zero for a zero-area
    /// face).
    pub normal: DVec3,
    /// The sine of the largest angle between `normal` and a face normal it averages, the own
    /// face's among them (1 when one is 90 degrees or more away): 0 for a flat corner.
    pub bound: f64,
}

/// Per triangle, its three corners' smooth normals. `triangles` are the triangles' positions
/// (counter-clockwise seen from the front) and `vertices` their welded vertex ids (corners
/// with the same id are one vertex; ids index a dense range). Corners of faces that see the
/// same faces within the crease get bit-identical results, so the shading is continuous
/// across their edges.
pub fn corner_normals(triangles: &[[DVec3; 3]], vertices: &[[u32; 3]], crease_deg: f64) -> Vec<[CornerNormal; 3]> {
    let area_normal: Vec<DVec3> = triangles.iter().map(|p| (p[1] - p[0]).cross(p[2] - p[0])).collect();
    let unit: Vec<DVec3> = area_normal.iter().map(|n| n.try_normalize().unwrap_or(DVec3::ZERO)).collect();
    let count = vertices.iter().flatten().map(|&v| v as usize + 1).max().unwrap_or(0);
    // Faces around each vertex (compressed rows), each face once per vertex.
    let mut start = vec![0usize; count + 1];
    for t in vertices {
        for &v in t {
            start[v as usize + 1] += 1;
        }
    }
    for i in 0..count {
        start[i + 1] += start[i];
    }
    let mut fill = start.clone();
    let mut faces = vec![0u32; start[count]];
    for (f, t) in vertices.iter().enumerate() {
        for &v in t {
            faces[fill[v as usize]] = f as u32;
            fill[v as usize] += 1;
        }
    }
    let cos_crease = crease_deg.to_radians().cos();
    vertices
        .iter()
        .enumerate()
        .map(|(f, t)| {
            t.map(|v| {
                let own = unit[f];
                if own == DVec3::ZERO {
                    return CornerNormal::default();
                }
                let around = &faces[start[v as usize]..start[v as usize + 1]];
                let smooth = |g: &&u32| unit[**g as usize].dot(own) >= cos_crease;
                let sum: DVec3 = around.iter().filter(smooth).map(|&g| area_normal[g as usize]).sum();
                let normal = sum.try_normalize().unwrap_or(own);
                let bound = around
                    .iter()
                    .filter(smooth)
                    .map(|&g| {
                        let n = unit[g as usize];
                        if n.dot(normal) <= 0.0 {
                            1.0
                        } else {
                            normal.cross(n).length().min(1.0)
                        }
                    })
                    .fold(0.0, f64::max);
                CornerNormal { normal, bound }
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A UV sphere of `seg` segments and `seg / 2` rings (shared vertices).
    fn sphere(seg: u32) -> (Vec<[DVec3; 3]>, Vec<[u32; 3]>) {
        let rings = seg / 2;
        // One vertex per pole, `seg` per ring between them.
        let mut pos = vec![DVec3::Y];
        for r in 1..rings {
            let th = std::f64::consts::PI * r as f64 / rings as f64;
            for s in 0..seg {
                let ph = std::f64::consts::TAU * s as f64 / seg as f64;
                pos.push(DVec3::new(th.sin() * ph.cos(), th.cos(), th.sin() * ph.sin()));
            }
        }
        pos.push(-DVec3::Y);
        let last = pos.len() as u32 - 1;
        let id = |r: u32, s: u32| match r {
            0 => 0,
            _ if r == rings => last,
            _ => 1 + (r - 1) * seg + s % seg,
        };
        let mut ids = Vec::new();
        for r in 0..rings {
            for s in 0..seg {
                let (a, b, c, d) = (id(r, s), id(r, s + 1), id(r + 1, s), id(r + 1, s + 1));
                if r > 0 {
                    ids.push([a, b, c]);
                }
                if r + 1 < rings {
                    ids.push([b, d, c]);
                }
            }
        }
        // Outward winding: flip where the face normal points inwards.
        let mut tris = Vec::new();
        for t in &mut ids {
            let p = t.map(|i| pos[i as usize]);
            if (p[1] - p[0]).cross(p[2] - p[0]).dot(p[0] + p[1] + p[2]) < 0.0 {
                t.swap(1, 2);
            }
            tris.push(t.map(|i| pos[i as usize]));
        }
        (tris, ids)
    }

    #[test]
    fn a_sphere_gets_radial_normals_and_a_box_stays_flat() {
        let (tris, ids) = sphere(24);
        for (t, corners) in tris.iter().zip(corner_normals(&tris, &ids, CREASE_DEG)) {
            for (p, c) in t.iter().zip(corners) {
                assert!(c.normal.angle_between(p.normalize()) < 0.05, "{c:?} at {p}");
                assert!(c.bound > 0.0 && c.bound < 0.2, "{c:?}");
            }
        }
        // Two faces of a box meeting at 90 degrees: each keeps its own normal, bound 0.
        let (a, b, c, d) = (DVec3::ZERO, DVec3::X, DVec3::new(1.0, 0.0, -1.0), DVec3::Y);
        let tris = [[a, b, c], [a, d, b]];
        let out = corner_normals(&tris, &[[0, 1, 2], [0, 3, 1]], CREASE_DEG);
        assert_eq!(out[0][0], CornerNormal { normal: DVec3::Y, bound: 0.0 });
        assert_eq!(out[1][0], CornerNormal { normal: DVec3::NEG_Z, bound: 0.0 });
    }

    #[test]
    fn back_facing_triangles_stay_within_their_bound() {
        for seg in [6, 8, 12, 24] {
            let (tris, ids) = sphere(seg);
            let normals = corner_normals(&tris, &ids, CREASE_DEG);
            let mut checked = 0;
            for k in 0..200 {
                let a = k as f64 * 2.399963;
                let l = DVec3::new(a.cos() * (k as f64 * 0.37).sin(), (k as f64 * 0.61).cos(), a.sin()).normalize();
                for (t, corners) in tris.iter().zip(&normals) {
                    let face = (t[1] - t[0]).cross(t[2] - t[0]).normalize();
                    if face.dot(l) > 0.0 {
                        continue;
                    }
                    // Any point of the triangle: barycentric weights on a grid.
                    for (u, v) in [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (0.3, 0.3), (0.5, 0.5), (0.1, 0.8)] {
                        let w = [1.0 - u - v, u, v];
                        let m: DVec3 = (0..3).map(|i| corners[i].normal * w[i]).sum();
                        let b: f64 = (0..3).map(|i| corners[i].bound * w[i]).sum();
                        assert!(m.dot(l) <= b + 1e-12, "{seg} segments: m.L {} > bound {b}", m.dot(l));
                        checked += 1;
                    }
                }
            }
            assert!(checked > 1000);
        }
    }

    #[test]
    fn shared_vertices_of_one_smooth_region_agree_bit_for_bit() {
        let (tris, ids) = sphere(12);
        let normals = corner_normals(&tris, &ids, CREASE_DEG);
        let mut seen: std::collections::HashMap<u32, CornerNormal> = Default::default();
        for (t, corners) in ids.iter().zip(&normals) {
            for (&v, c) in t.iter().zip(corners) {
                let first = *seen.entry(v).or_insert(*c);
                assert_eq!(first, *c, "vertex {v}");
            }
        }
    }

    #[test]
    fn zero_area_faces_get_no_normal_and_are_not_averaged() {
        let (a, b, c) = (DVec3::ZERO, DVec3::X, DVec3::Y);
        let tris = [[a, b, c], [a, b, b * 2.0]];
        let out = corner_normals(&tris, &[[0, 1, 2], [0, 1, 3]], CREASE_DEG);
        assert_eq!(out[1][0], CornerNormal::default());
        assert_eq!(out[0][0].normal, DVec3::Z);
        assert_eq!(corner_normals(&[], &[], CREASE_DEG).len(), 0);
    }
}
