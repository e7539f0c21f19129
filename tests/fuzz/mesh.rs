//! Mesh topology: base meshes, random soups and the mutations real assets have
//! (`fuzz_topology`, and the planner's casters), and the topology and chunking check.

use crate::Rng;
use glam::{Mat4, Vec3};
use umbrage::geom::topology::{Topology, Weld};
use umbrage::geom::Mesh;
use umbrage::shadow::Caster;
use umbrage_scene::shapes;

/// Named base meshes for mutation.
fn base_mesh(rng: &mut Rng) -> Mesh {
    match rng.below(9) {
        0 => shapes::cuboid(Vec3::new(rng.range(0.1, 2.0), rng.range(0.1, 2.0), rng.range(0.1, 2.0))),
        1 => shapes::sphere(rng.range(0.1, 1.5), 3 + rng.below(8) as u32, 2 + rng.below(6) as u32),
        2 => shapes::torus(0.8, rng.range(0.05, 0.5), 3 + rng.below(6) as u32, 3 + rng.below(5) as u32),
        3 => shapes::cylinder(0.5, rng.range(0.1, 2.0), 3 + rng.below(8) as u32),
        4 => shapes::plane(glam::Vec2::new(rng.range(0.1, 3.0), rng.range(0.1, 3.0))),
        5 => shapes::stairs(1 + rng.below(4) as u32, Vec3::new(1.0, 0.2, 0.3)),
        6 => shapes::cube_grid(1 + rng.below(3) as u32, 1 + rng.below(3) as u32, 0.4, rng.pick(&[1.0, 0.4, 0.2]).to_owned()),
        7 => tetra(),
        _ => soup(rng),
    }
}

pub(crate) fn tetra() -> Mesh {
    Mesh::new(
        vec![Vec3::new(0.0, 0.0, 0.0), Vec3::new(1.0, 0.0, 0.0), Vec3::new(0.0, 1.0, 0.0), Vec3::new(0.0, 0.0, 1.0)],
        vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
    )
}

/// A random triangle soup over a small vertex pool (so indices collide: duplicates, fins,
/// degenerate triangles), with coincident, collinear and coplanar positions.
fn soup(rng: &mut Rng) -> Mesh {
    let nv = 3 + rng.below(10);
    let mut pos: Vec<Vec3> = Vec::with_capacity(nv);
    for i in 0..nv {
        let p = match rng.below(8) {
            0 if i > 0 => pos[rng.below(i)],                                               // coincident
            1 if i > 1 => pos[rng.below(i)].lerp(pos[rng.below(i)], rng.range(-1.0, 2.0)), // collinear
            2 => Vec3::new(rng.range(-1.0, 1.0), 0.0, rng.range(-1.0, 1.0)),               // coplanar y=0
            3 if i > 0 => pos[rng.below(i)] + rng.vec3(1e-6),                              // nearly coincident
            4 => Vec3::new(rng.below(3) as f32, rng.below(3) as f32, rng.below(3) as f32), // lattice
            _ => rng.vec3(1.0),
        };
        pos.push(p);
    }
    let nt = 1 + rng.below(16);
    let tris = (0..nt).map(|_| [rng.below(nv) as u32, rng.below(nv) as u32, rng.below(nv) as u32]).collect();
    Mesh::new(pos, tris)
}

/// Mutations that break closedness or orientation in the ways real assets do.
fn mutate_mesh(rng: &mut Rng, m: &mut Mesh) {
    for _ in 0..rng.below(5) {
        let nt = m.triangles.len();
        if nt == 0 {
            break;
        }
        let t = rng.below(nt);
        match rng.below(10) {
            0 => m.triangles.push(m.triangles[t]), // duplicate
            1 => {
                let [a, b, c] = m.triangles[t];
                m.triangles.push([a, c, b]); // back-to-back
            }
            2 => m.triangles[t].swap(1, 2), // flip (inside-out / inconsistent)
            3 => {
                m.triangles.remove(t); // hole
            }
            4 => {
                // fin: a new triangle on an existing edge (non-manifold)
                let [a, b, _] = m.triangles[t];
                let p = m.positions[a as usize] + rng.vec3(1.0);
                m.positions.push(p);
                m.triangles.push([a, b, m.positions.len() as u32 - 1]);
            }
            5 => {
                // collapse a vertex onto another (degenerate triangles, pinched vertices)
                let [a, b, _] = m.triangles[t];
                m.positions[b as usize] = m.positions[a as usize];
            }
            6 => {
                // split a vertex: same position, new index (open seam until welded)
                let k = rng.below(3);
                let v = m.triangles[t][k] as usize;
                m.positions.push(m.positions[v]);
                m.triangles[t][k] = m.positions.len() as u32 - 1;
            }
            7 => {
                let k = rng.below(3);
                m.triangles[t][k] = m.triangles[t][(k + 1) % 3]; // repeated index
            }
            8 => {
                // jitter one vertex a little (near-coplanar, near-degenerate)
                let v = rng.below(m.positions.len());
                m.positions[v] += rng.vec3(1e-5);
            }
            _ => {
                // all triangles flipped: inside-out
                for t in &mut m.triangles {
                    t.swap(1, 2);
                }
            }
        }
    }
    if rng.chance(0.1) {
        // a second copy of the whole mesh, shifted or coincident: several parts / overlaps
        let off = if rng.chance(0.5) { Vec3::ZERO } else { rng.vec3(2.0) };
        let n = m.positions.len() as u32;
        let extra: Vec<Vec3> = m.positions.iter().map(|&p| p + off).collect();
        m.positions.extend(extra);
        let tris: Vec<[u32; 3]> = m.triangles.iter().map(|t| t.map(|i| i + n)).collect();
        m.triangles.extend(tris);
    }
}

pub(crate) fn random_mesh(rng: &mut Rng) -> Mesh {
    let mut m = base_mesh(rng);
    if rng.chance(0.8) {
        mutate_mesh(rng, &mut m);
    }
    m
}

/// Invalid meshes too (for `Caster::new`, which must refuse them with an error).
pub(crate) fn random_mesh_maybe_invalid(rng: &mut Rng) -> Mesh {
    let mut m = random_mesh(rng);
    match rng.below(30) {
        0 => m.triangles.clear(),
        1 if !m.positions.is_empty() => {
            let v = rng.below(m.positions.len());
            m.positions[v].x = *rng.pick(&[f32::NAN, f32::INFINITY, f32::NEG_INFINITY]);
        }
        2 if !m.triangles.is_empty() => {
            let t = rng.below(m.triangles.len());
            m.triangles[t][rng.below(3)] = *rng.pick(&[m.positions.len() as u32, u32::MAX, u32::MAX - 1]);
        }
        3 => m.positions.clear(),
        4 => {
            // extreme but finite coordinates
            let s = *rng.pick(&[1e30f32, 1e-30, f32::MAX, f32::MIN_POSITIVE]);
            for p in &mut m.positions {
                *p *= s;
            }
        }
        _ => {}
    }
    m
}

#[derive(Debug)]
pub(crate) struct TopoCase {
    pub(crate) mesh: Mesh,
    pub(crate) limit: usize,
    pub(crate) tolerance: f32,
}

pub(crate) fn check_topology(c: &TopoCase) {
    let m = &c.mesh;
    let valid = m.validate("fuzz").is_ok();
    if valid {
        for weld in [Weld::Exact, Weld::Tolerance(c.tolerance)] {
            let t = Topology::build_with(m, weld);
            // every non-degenerate corner of every welded triangle is one use of one edge
            let uses: u32 = t.edges.iter().map(|e| e.use_count).sum();
            assert_eq!(uses as usize, t.uses.len());
            assert!(t.manifold_edges.len() <= t.edges.len());
            let _ = t.is_closed_manifold();
            let _ = t.describe_problem();
        }
    }
    if let Ok(caster) = Caster::with_chunk_limit("fuzz", m, Mat4::IDENTITY, c.limit) {
        assert!(valid, "an invalid mesh was accepted");
        for ch in &caster.chunks {
            assert!(ch.n() <= c.limit.clamp(4, 32768));
            for lt in &ch.local_tris {
                assert!(lt.iter().all(|&i| (i as usize) < ch.n() - 1));
            }
        }
        let covered: usize = caster.parts.iter().map(|p| p.triangles.len()).sum();
        assert_eq!(covered, caster.triangle_count);
    }
    let _ = Caster::new("fuzz", m, Mat4::IDENTITY);
}
