//! The planner: random casters, lights and cameras (`fuzz_planner`), and the checks on the
//! emitted volumes (closed z-fail parts, multiplicity side counts).

use crate::mesh::{random_mesh, tetra};
use crate::{Rng, CLOSED_PARTS, MULTIPLICITY_PARTS, PLANNED_PARTS};
use glam::{EulerRot, Mat4, Quat, Vec3, Vec4};
use std::collections::HashMap;
use std::sync::atomic::Ordering;
use umbrage::geom::{Camera, Light, LightKind, Mesh};
use umbrage::shadow::{plan_light_with, Case, Caster, CasterPlan, Method, PlanInput, PlanOptions, VolumePath};

#[derive(Debug)]
pub(crate) struct PlanCase {
    meshes: Vec<(Mesh, Mat4, usize, bool)>,
    light: Light,
    camera: Camera,
    method: Method,
    opts: PlanOptions,
    aspect: f32,
}

fn random_transform(rng: &mut Rng) -> Mat4 {
    let r = Quat::from_euler(EulerRot::XYZ, rng.range(0.0, 6.3), rng.range(0.0, 6.3), rng.range(0.0, 6.3));
    let s = match rng.below(6) {
        0 => Vec3::new(-1.0, 1.0, 1.0),
        1 => Vec3::splat(rng.range(0.01, 3.0)),
        2 => Vec3::new(rng.range(0.2, 2.0), rng.range(0.2, 2.0), -rng.range(0.2, 2.0)),
        _ => Vec3::ONE,
    };
    match rng.below(4) {
        0 => Mat4::IDENTITY,
        1 => Mat4::from_translation(rng.vec3(2.0)),
        _ => Mat4::from_scale_rotation_translation(s, r, rng.vec3(2.0)),
    }
}

/// A world-space point on, at or near the casters: vertices, edge points, face-plane points.
fn special_point(rng: &mut Rng, meshes: &[(Mesh, Mat4, usize, bool)]) -> Vec3 {
    let (m, xf, _, _) = &meshes[rng.below(meshes.len())];
    let w = |i: u32| xf.transform_point3(m.positions[i as usize]);
    let t = m.triangles[rng.below(m.triangles.len())];
    let (a, b, c) = (w(t[0]), w(t[1]), w(t[2]));
    let p = match rng.below(6) {
        0 => a,                                                                   // at a vertex
        1 => a.lerp(b, rng.range(0.0, 1.0)),                                      // on an edge
        2 => a.lerp(b, rng.range(-3.0, 4.0)),                                     // on an edge's line
        3 => a + (b - a) * rng.range(-2.0, 2.0) + (c - a) * rng.range(-2.0, 2.0), // in the face plane
        4 => xf.transform_point3(m.bounds().center()),
        _ => (a + b + c) / 3.0,
    };
    match rng.below(4) {
        0 => p + rng.vec3(1e-5),
        1 => p + rng.vec3(1e-2),
        _ => p,
    }
}

pub(crate) fn plan_case(rng: &mut Rng) -> PlanCase {
    let n = 1 + rng.below(3);
    let meshes: Vec<(Mesh, Mat4, usize, bool)> = (0..n)
        .map(|_| {
            let mut m = random_mesh(rng);
            if m.validate("x").is_err() {
                m = tetra();
            }
            (m, random_transform(rng), *rng.pick(&[32768, 4, 5, 7, 16]), rng.chance(0.15))
        })
        .collect();
    let kind = *rng.pick(&[LightKind::Point, LightKind::Point, LightKind::Spot, LightKind::Directional]);
    let position = match rng.below(3) {
        0 => rng.vec3(6.0),
        _ => special_point(rng, &meshes),
    };
    let direction = match rng.below(4) {
        0 => {
            // parallel to a face or along an edge
            let (m, xf, _, _) = &meshes[rng.below(meshes.len())];
            let t = m.triangles[rng.below(m.triangles.len())];
            let w = |i: u32| xf.transform_point3(m.positions[i as usize]);
            let d = if rng.chance(0.5) { w(t[1]) - w(t[0]) } else { (w(t[1]) - w(t[0])).lerp(w(t[2]) - w(t[0]), rng.range(0.0, 1.0)) };
            d.try_normalize().unwrap_or(Vec3::NEG_Y)
        }
        1 => *rng.pick(&[Vec3::NEG_Y, Vec3::X, Vec3::NEG_Z, Vec3::new(1.0, -1.0, 0.0).normalize()]),
        _ => rng.vec3(1.0).try_normalize().unwrap_or(Vec3::NEG_Y),
    };
    let light = Light {
        kind,
        position,
        direction,
        color: Vec3::ONE,
        intensity: 1.0,
        radius: if rng.chance(0.2) { Some(rng.range(0.01, 10.0)) } else { None },
        cone_deg: *rng.pick(&[10.0, 45.0, 90.0, 179.0, 180.0, 270.0, 0.0]),
        area: None,
    };
    let eye = match rng.below(5) {
        0 => special_point(rng, &meshes),
        1 => position,
        _ => rng.vec3(8.0),
    };
    let target = if rng.chance(0.7) { special_point(rng, &meshes) } else { rng.vec3(3.0) };
    let camera = Camera {
        eye,
        target,
        up: *rng.pick(&[Vec3::Y, Vec3::Z, Vec3::X]),
        fov_y_deg: *rng.pick(&[60.0, 10.0, 120.0, 170.0, 1.0]),
        near: *rng.pick(&[0.1, 0.01, 1.0, 1e-4]),
    };
    PlanCase {
        meshes,
        light,
        camera,
        method: *rng.pick(&Method::ALL),
        opts: PlanOptions { edge_quads: rng.chance(0.05), case_per_part: rng.chance(0.5), ..PlanOptions::default() },
        aspect: *rng.pick(&[1.0, 1.5, 0.5]),
    }
}

/// A vertex of the emitted volume: (welded vertex or apex, at infinity).
type VKey = (u32, bool);

fn vkey(caster: &Caster, chunk: usize, i: u16, directional: bool) -> VKey {
    let ch = &caster.chunks[chunk];
    let n = ch.n();
    let (local, inf) = if (i as usize) < n { (i as usize, false) } else { (i as usize - n, true) };
    assert!(local < n, "index {i} out of the dual-length buffer of chunk {chunk} (n = {n})");
    if inf && directional {
        return (u32::MAX - 1, true);
    }
    (ch.global_ids[local], inf)
}

/// Every check on the plans of `casters` for one light.
pub(crate) fn check_plan(casters: &[Caster], plans: &[CasterPlan], directional: bool) {
    assert_eq!(plans.len(), casters.len());
    let mut bits = Vec::new();
    for (caster, cp) in casters.iter().zip(plans) {
        if cp.path == VolumePath::EdgeQuad || cp.case == Case::Culled && cp.chunks.is_empty() {
            continue;
        }
        assert_eq!(cp.triangles(), cp.parts.iter().map(|p| p.sides + p.dark_cap + p.light_cap).sum::<usize>());
        let emitted: usize = cp.chunks.iter().map(|d| d.volume.len() + d.light_cap.len()).sum();
        assert_eq!(emitted, 3 * cp.triangles(), "index lists do not hold the counted triangles");
        let l_obj = Vec4::from_array(cp.light_object);
        caster.planes.facing_packed_auto(caster.mesh(), l_obj, caster.mirrored, &mut bits);
        for pp in &cp.parts {
            if pp.case == Case::Culled {
                continue;
            }
            PLANNED_PARTS.fetch_add(1, Ordering::Relaxed);
            let part = &caster.parts[pp.part];
            let tris: Vec<(usize, [u16; 3])> = cp
                .chunks
                .iter()
                .filter(|d| part.chunks.contains(&d.chunk))
                .flat_map(|d| d.volume.chunks(3).chain(d.light_cap.chunks(3)).map(move |t| (d.chunk, [t[0], t[1], t[2]])))
                .collect();
            assert_eq!(tris.len(), pp.sides + pp.dark_cap + pp.light_cap, "part {} triangle count", pp.part);
            if pp.case == Case::ZFailLightCap {
                CLOSED_PARTS.fetch_add(1, Ordering::Relaxed);
                // closed: every directed edge cancels
                let mut m: HashMap<(VKey, VKey), i32> = HashMap::new();
                for &(c, t) in &tris {
                    for k in 0..3 {
                        let (u, v) = (vkey(caster, c, t[k], directional), vkey(caster, c, t[(k + 1) % 3], directional));
                        if u == v {
                            continue;
                        }
                        if u < v {
                            *m.entry((u, v)).or_default() += 1;
                        } else {
                            *m.entry((v, u)).or_default() -= 1;
                        }
                    }
                }
                let open: Vec<_> = m.iter().filter(|(_, &c)| c != 0).collect();
                assert!(open.is_empty(), "part {} ({}) not closed: {} open edges, e.g. {:?}", pp.part, pp.path, open.len(), open.first());
            }
            if pp.path == VolumePath::Multiplicity {
                MULTIPLICITY_PARTS.fetch_add(1, Ordering::Relaxed);
                // per undirected edge: the signed side count is the multiplicity
                let topo = &caster.topology;
                let mut want: HashMap<(u32, u32), i32> = HashMap::new();
                let (mut nonzero, mut mmax) = (0usize, 0u32);
                for &e in &part.edges {
                    let edge = &topo.edges[e as usize];
                    let mult: i32 =
                        topo.edge_uses(e as usize).iter().map(|u| if u.forward == caster.planes.bit(&bits, u.tri) { 1 } else { -1 }).sum();
                    if mult != 0 {
                        nonzero += 1;
                        mmax = mmax.max(mult.unsigned_abs());
                    }
                    if edge.v[0] != edge.v[1] {
                        *want.entry((edge.v[0], edge.v[1])).or_default() += mult;
                    }
                }
                assert_eq!(pp.silhouette_edges, nonzero, "part {}: edges of non-zero multiplicity", pp.part);
                assert_eq!(pp.multiplicity_max, mmax, "part {}: largest multiplicity", pp.part);
                let mut got: HashMap<(u32, u32), i32> = HashMap::new();
                for &(c, t) in &tris {
                    let ks = t.map(|i| vkey(caster, c, i, false));
                    if ks.iter().filter(|k| !k.1).count() != 2 {
                        continue; // caps (all finite or all at infinity), or the infinite half of a side quad
                    }
                    for k in 0..3 {
                        let (u, v) = (ks[k], ks[(k + 1) % 3]);
                        if !u.1 && !v.1 && u.0 != v.0 {
                            // a side over a -> b is emitted as b -> a finite edge (see multiplicity.rs)
                            if u.0 > v.0 {
                                *got.entry((v.0, u.0)).or_default() += 1;
                            } else {
                                *got.entry((u.0, v.0)).or_default() -= 1;
                            }
                        }
                    }
                }
                want.retain(|_, m| *m != 0);
                got.retain(|_, m| *m != 0);
                assert_eq!(got, want, "part {}: signed side counts differ from the multiplicities", pp.part);
            }
        }
    }
}

pub(crate) fn check_planner(c: &PlanCase) {
    let mut casters = Vec::new();
    for (i, (m, xf, limit, transparent)) in c.meshes.iter().enumerate() {
        let Ok(mut caster) = Caster::with_chunk_limit(&format!("c{i}"), m, *xf, *limit) else { continue };
        if *transparent {
            caster = caster.into_transparent(Vec3::splat(0.5));
        }
        casters.push(caster);
    }
    let vp = c.camera.proj_infinite(c.aspect) * c.camera.view();
    let input = PlanInput { camera: &c.camera, width: 64, height: 48, view_proj: vp, light: &c.light, method: c.method };
    let plan = plan_light_with(&input, &casters, &c.opts);
    check_plan(&casters, &plan.casters, c.light.kind == LightKind::Directional);
    // z-fail with light caps everywhere: every part that is not culled must be closed
    if c.method != Method::ZFail {
        let input = PlanInput { method: Method::ZFail, ..input };
        let plan = plan_light_with(&input, &casters, &PlanOptions { case_per_part: c.opts.case_per_part, ..PlanOptions::default() });
        check_plan(&casters, &plan.casters, c.light.kind == LightKind::Directional);
    }
}
