//! The eye-in-shadow stencil clear (lecture notes §3.1, last paragraph): how many drawn shadow
//! volumes contain a point, counted exactly on the CPU, so that z-pass can start from that
//! count instead of 0.
//!
//! A point is inside the volume of a closed manifold part iff its segment to the light crosses
//! the part (an odd or positive number of crossings: the count is 1 per part); for a part on
//! the multiplicity path the count is the number of its triangles crossed (Kim et al. 2008).
//! Crossings are decided with exact `orient3d` signs on the f64 object-space coordinates; a
//! segment through an edge or vertex exactly (a zero sign) is not a crossing.

use super::casters::CasterTable;
use crate::geom::{Light, LightKind};
use crate::shadow::{Case, CasterKind, LightPlan};
use glam::DVec3;
use robust::{orient3d, Coord3D};

fn c(p: DVec3) -> Coord3D<f64> {
    Coord3D { x: p.x, y: p.y, z: p.z }
}

/// Whether segment `p -> q` crosses triangle `abc` in its interior (exact signs).
fn crosses(p: DVec3, q: DVec3, a: DVec3, b: DVec3, t: DVec3) -> bool {
    let s1 = orient3d(c(a), c(b), c(t), c(p));
    let s2 = orient3d(c(a), c(b), c(t), c(q));
    if s1 == 0.0 || s2 == 0.0 || (s1 > 0.0) == (s2 > 0.0) {
        return false;
    }
    let e1 = orient3d(c(p), c(q), c(a), c(b));
    let e2 = orient3d(c(p), c(q), c(b), c(t));
    let e3 = orient3d(c(p), c(q), c(t), c(a));
    (e1 > 0.0 && e2 > 0.0 && e3 > 0.0) || (e1 < 0.0 && e2 < 0.0 && e3 < 0.0)
}

/// For each of `points` (world space), the number of the plan's drawn volumes that contain
/// it. Each caster is brought to object space once for all points.
pub(crate) fn volumes_containing(points: &[DVec3], light: &Light, plan: &LightPlan, table: &CasterTable) -> Vec<i32> {
    let mut counts = vec![0; points.len()];
    for cp in plan.casters.iter().filter(|cp| cp.case != Case::Culled) {
        let caster = &table.cpu[cp.caster];
        let inv = table.live[cp.caster].transform.inverse();
        let mesh = caster.mesh();
        for (count, &point) in counts.iter_mut().zip(points) {
            let p = inv.transform_point3(point);
            let q = match light.kind {
                // Towards a directional light: far beyond the caster along the light's direction.
                LightKind::Directional => {
                    let d = inv.transform_vector3(-light.direction.as_dvec3()).normalize();
                    let b = caster.object_bounds;
                    let reach = (b.max.as_dvec3() - b.min.as_dvec3()).length() + (p - b.center().as_dvec3()).length();
                    p + d * (4.0 * reach + 1.0)
                }
                _ => inv.transform_point3(light.position.as_dvec3()),
            };
            for pp in cp.parts.iter().filter(|pp| pp.case != Case::Culled) {
                let part = &caster.parts[pp.part];
                let hits = part
                    .triangles
                    .iter()
                    .filter(|&&t| {
                        let [a, b, t3] = mesh.triangle(t as usize).map(|v| v.as_dvec3());
                        crosses(p, q, a, b, t3)
                    })
                    .count() as i32;
                *count += match part.kind {
                    CasterKind::Manifold => (hits > 0) as i32,
                    CasterKind::Multiplicity { .. } => hits,
                };
            }
        }
    }
    counts
}

#[cfg(test)]
mod tests {
    use super::*;
    #[test]
    fn segment_triangle_crossings_are_exact() {
        let (a, b, t) = (DVec3::ZERO, DVec3::X, DVec3::Y);
        assert!(crosses(DVec3::new(0.2, 0.2, -1.0), DVec3::new(0.2, 0.2, 1.0), a, b, t));
        assert!(!crosses(DVec3::new(0.2, 0.2, 0.5), DVec3::new(0.2, 0.2, 1.0), a, b, t), "both ends above");
        assert!(!crosses(DVec3::new(2.0, 2.0, -1.0), DVec3::new(2.0, 2.0, 1.0), a, b, t), "outside the triangle");
        assert!(!crosses(DVec3::new(0.5, 0.0, -1.0), DVec3::new(0.5, 0.0, 1.0), a, b, t), "through an edge exactly");
    }
}
