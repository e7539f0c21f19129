use super::*;
use crate::geom::silhouette::facing_bits;
use crate::geom::testmesh::{cube, signed_volume, torus, uv_sphere};
use crate::geom::Mesh;
use crate::geom::{Camera, Light};
use glam::Mat4;
use glam::{DVec3, Vec3};
use std::collections::HashMap;

fn point(pos: Vec3) -> Light {
    Light {
        kind: LightKind::Point,
        position: pos,
        direction: Vec3::NEG_Y,
        color: Vec3::ONE,
        intensity: 1.0,
        radius: None,
        cone_deg: 45.0,
        area: None,
    }
}
fn dir(d: Vec3) -> Light {
    Light { kind: LightKind::Directional, direction: d, ..point(Vec3::ZERO) }
}
fn camera(eye: Vec3, target: Vec3) -> Camera {
    Camera { eye, target, up: Vec3::Z, fov_y_deg: 60.0, near: 0.1 }
}
fn plan(cam: &Camera, light: &Light, method: Method, casters: &[Caster]) -> LightPlan {
    let vp = cam.proj_infinite(1.0) * cam.view();
    plan_light(&PlanInput { camera: cam, width: 256, height: 256, view_proj: vp, light, method }, casters)
}
fn box_caster() -> Vec<Caster> {
    vec![Caster::new("box", &cube(Vec3::ZERO, 0.5), Mat4::IDENTITY).unwrap()]
}
// case 1: the light-to-viewport pyramid misses the box
fn cam1() -> Camera {
    Camera { up: Vec3::Y, ..camera(Vec3::new(4.0, 6.0, 0.0), Vec3::ZERO) }
}
// case 2: camera in the shadow, looking away from the box
fn cam2() -> Camera {
    camera(Vec3::new(0.0, -3.0, 0.0), Vec3::new(0.0, -10.0, 0.0))
}
// case 3: camera in the shadow, looking at the box (towards the light)
fn cam3() -> Camera {
    camera(Vec3::new(0.0, -3.0, 0.0), Vec3::ZERO)
}

fn counts(p: &CasterPlan) -> (Case, usize, usize, usize) {
    (p.case, p.sides, p.dark_cap, p.light_cap)
}

#[test]
#[cfg(feature = "serde")] // serde_json
fn method_names() {
    for m in Method::ALL {
        assert_eq!(m.to_string().parse::<Method>().unwrap(), m);
        assert_eq!(serde_json::to_string(&m).unwrap(), format!("\"{m}\""));
    }
    assert!("foo".parse::<Method>().unwrap_err().to_string().contains("everitt-kilgard"));
    assert_eq!(serde_json::to_string(&Case::ZFailLightCap).unwrap(), "\"zfail_light_cap\"");
    assert_eq!(serde_json::to_string(&Case::Culled).unwrap(), "\"culled\"");
    assert_eq!(serde_json::to_string(&Case::ZPass).unwrap(), "\"zpass\"");
    assert_eq!(serde_json::to_string(&Case::ZFail).unwrap(), "\"zfail\"");
}

#[test]
fn box_point_light_cases() {
    let c = box_caster();
    let l = point(Vec3::new(0.0, 5.0, 0.0));
    let s = 4;
    let p = plan(&cam1(), &l, Method::McGuire, &c);
    assert_eq!(p.casters[0].silhouette_edges, s);
    assert_eq!(counts(&p.casters[0]), (Case::ZPass, 2 * s, 0, 0));
    let p = plan(&cam2(), &l, Method::McGuire, &c);
    assert_eq!(counts(&p.casters[0]), (Case::ZFail, 2 * s, s, 0));
    assert_eq!(p.casters[0].dark_cap_kind, DarkCap::Fan);
    assert_eq!(p.casters[0].triangles(), 3 * s);
    let p = plan(&cam3(), &l, Method::McGuire, &c);
    assert_eq!(counts(&p.casters[0]), (Case::ZFailLightCap, 2 * s, s, 2));
    assert_eq!(p.casters[0].triangles(), 3 * s + 2);
    assert_closed(&c[0], &p.casters[0], false);
    // the index lists hold exactly the counted triangles
    let idx: usize = p.casters[0].chunks.iter().map(|d| d.volume.len()).sum();
    assert_eq!(idx, 3 * (2 * s + s));
    assert_eq!(p.casters[0].chunks[0].light_cap.len(), 6);

    // other methods
    assert_eq!(counts(&plan(&cam3(), &l, Method::ZPass, &c).casters[0]), (Case::ZPass, 8, 0, 0));
    for m in [Method::ZFail, Method::EverittKilgard] {
        for cam in [cam1(), cam2(), cam3()] {
            let p = plan(&cam, &l, m, &c);
            assert_eq!(counts(&p.casters[0]), (Case::ZFailLightCap, 8, 2, 2));
            assert_eq!(p.casters[0].dark_cap_kind, DarkCap::FrontFaces);
            assert_closed(&c[0], &p.casters[0], false);
        }
    }
    assert_eq!(counts(&plan(&cam1(), &l, Method::Lengyel, &c).casters[0]), (Case::ZPass, 8, 0, 0));
    assert_eq!(counts(&plan(&cam2(), &l, Method::Lengyel, &c).casters[0]), (Case::ZFailLightCap, 8, 2, 2));
    assert_eq!(counts(&plan(&cam3(), &l, Method::Lengyel, &c).casters[0]), (Case::ZFailLightCap, 8, 2, 2));
}

#[test]
fn directional_counts() {
    let c = box_caster();
    let l = dir(Vec3::NEG_Y);
    let p = plan(&cam1(), &l, Method::McGuire, &c);
    assert_eq!(counts(&p.casters[0]), (Case::ZPass, 4, 0, 0));
    let p = plan(&cam2(), &l, Method::McGuire, &c);
    assert_eq!(counts(&p.casters[0]), (Case::ZFail, 4, 0, 0));
    let p = plan(&cam3(), &l, Method::McGuire, &c);
    assert_eq!(counts(&p.casters[0]), (Case::ZFailLightCap, 4, 0, 2));
    assert_eq!(p.casters[0].dark_cap_kind, DarkCap::None);
    assert_closed(&c[0], &p.casters[0], true);
    assert_eq!(p.scissor, None);
    assert_eq!(p.depth_bounds, None);
    let p = plan(&cam3(), &l, Method::ZFail, &c);
    assert_eq!(counts(&p.casters[0]), (Case::ZFailLightCap, 4, 0, 2));
}

#[test]
fn culling() {
    let c = box_caster();
    let mut l = point(Vec3::new(0.0, 5.0, 0.0));
    l.radius = Some(1.0);
    assert_eq!(plan(&cam3(), &l, Method::McGuire, &c).casters[0].case, Case::Culled);
    l.radius = Some(5.0);
    assert_eq!(plan(&cam3(), &l, Method::McGuire, &c).casters[0].case, Case::ZFailLightCap);
    let mut s = point(Vec3::new(0.0, 5.0, 0.0));
    s.kind = LightKind::Spot;
    s.direction = Vec3::Y; // pointing away from the box
    assert_eq!(plan(&cam3(), &s, Method::McGuire, &c).casters[0].case, Case::Culled);
    s.direction = Vec3::NEG_Y;
    assert_eq!(plan(&cam3(), &s, Method::McGuire, &c).casters[0].case, Case::ZFailLightCap);
    // camera above the box looking up: the volume goes down, out of view
    let up = Camera { up: Vec3::Z, ..camera(Vec3::new(0.0, 3.0, 0.0), Vec3::new(0.0, 10.0, 0.0)) };
    let p = plan(&up, &point(Vec3::new(0.0, 2.0, 0.0)), Method::McGuire, &c);
    assert_eq!(p.casters[0].case, Case::Culled);
    assert!(p.casters[0].chunks.is_empty());
}

#[test]
fn light_inside_uses_back_faces() {
    let c = box_caster();
    let l = point(Vec3::new(0.1, 0.2, 0.0));
    let p = plan(&cam3(), &l, Method::McGuire, &c);
    let cp = &p.casters[0];
    assert_eq!(cp.formulation, Formulation::Back);
    assert_eq!(cp.dark_cap_kind, DarkCap::BackFaces);
    assert_eq!(counts(cp), (Case::ZFailLightCap, 0, 12, 12));
    assert_closed(&c[0], cp, false);
    // a light exactly on a vertex (the corner) is moved off it by a tiny distance, away from
    // the box (no w=0 copy may be (0,0,0,0)), and the volume is closed
    let corner = Vec3::new(0.5, 0.5, 0.5);
    let p = plan(&cam3(), &point(corner), Method::McGuire, &c);
    let moved = Vec4::from_array(p.casters[0].light_object).truncate();
    assert!(moved != corner && moved.distance(corner) < 1e-4, "{moved:?}");
    assert!(!c[0].object_bounds.contains(moved));
    assert_closed(&c[0], &p.casters[0], false);
    // a light on a face (not a vertex) stays where it is and uses back faces
    let p = plan(&cam3(), &point(Vec3::new(0.5, 0.1, 0.2)), Method::McGuire, &c);
    assert_eq!(p.casters[0].formulation, Formulation::Back);
    assert_closed(&c[0], &p.casters[0], false);
    // light in the AABB but outside a (non-convex) torus
    let t = vec![Caster::new("torus", &torus(1.0, 0.3, 24, 12), Mat4::IDENTITY).unwrap()];
    let p = plan(&cam3(), &point(Vec3::new(0.0, 0.1, 0.0)), Method::McGuire, &t);
    assert_eq!(p.casters[0].formulation, Formulation::Back);
    assert_closed(&t[0], &p.casters[0], false);
    assert!(finite_signed_volume(&t[0], &p.casters[0], Vec3::new(0.0, 0.1, 0.0)) > 0.0);
}

#[test]
fn light_in_face_plane() {
    let c = box_caster();
    let l = point(Vec3::new(0.0, 0.5, 3.0)); // in the plane of the top face, in front of +z
    let cam = Camera { up: Vec3::Y, ..camera(Vec3::new(0.0, 0.0, -3.0), Vec3::ZERO) };
    let p = plan(&cam, &l, Method::McGuire, &c);
    let cp = &p.casters[0];
    assert_eq!(cp.formulation, Formulation::Front);
    assert_eq!(cp.silhouette_edges, 4);
    assert_eq!(counts(cp), (Case::ZFailLightCap, 8, 4, 2));
    assert_closed(&c[0], cp, false);
    // directional light parallel to the top face
    let p = plan(&cam3(), &dir(Vec3::new(0.0, 0.0, -1.0)), Method::McGuire, &c);
    assert_eq!(p.casters[0].silhouette_edges, 4);
    assert_closed(&c[0], &p.casters[0], true);
}

/// Key of a chunk-local index: (welded vertex id or apex, at infinity?). For a directional
/// light all points at infinity are one point.
fn key(caster: &Caster, chunk: usize, i: u16, directional: bool) -> (u32, bool) {
    let ch = &caster.chunks[chunk];
    let n = ch.n();
    let (local, inf) = if (i as usize) < n { (i as usize, false) } else { (i as usize - n, true) };
    if inf && directional {
        return (u32::MAX - 1, true);
    }
    (ch.global_ids[local], inf)
}

fn all_tris(p: &CasterPlan) -> Vec<(usize, [u16; 3])> {
    let mut out = Vec::new();
    for d in &p.chunks {
        for lst in [&d.volume, &d.light_cap] {
            assert_eq!(lst.len() % 3, 0);
            for t in lst.chunks(3) {
                out.push((d.chunk, [t[0], t[1], t[2]]));
            }
        }
    }
    out
}

/// A vertex of the emitted volume: (welded vertex, at infinity).
type VolumeVertex = (u32, bool);

/// Every directed edge of the emitted volume cancels.
fn assert_closed(caster: &Caster, p: &CasterPlan, directional: bool) {
    let mut m: HashMap<(VolumeVertex, VolumeVertex), i32> = HashMap::new();
    for (c, t) in all_tris(p) {
        for k in 0..3 {
            let (u, v) = (key(caster, c, t[k], directional), key(caster, c, t[(k + 1) % 3], directional));
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
    assert!(open.is_empty(), "{} open edges, e.g. {:?}", open.len(), open.first());
}

/// Signed volume of the emitted volume with the w=0 copies replaced by a finite extrusion
/// p + 20 (p - L) (point light, identity transform).
fn finite_signed_volume(caster: &Caster, p: &CasterPlan, l: Vec3) -> f64 {
    let l = l.as_dvec3();
    let mut mesh_pos = Vec::new();
    let mut tris = Vec::new();
    for (c, t) in all_tris(p) {
        let ch = &caster.chunks[c];
        let n = ch.n();
        let mut tri = [0u32; 3];
        for k in 0..3 {
            let i = t[k] as usize;
            let q: DVec3 = ch.vertices[i % n].as_dvec3();
            let q = if i >= n { q + (q - l) * 20.0 } else { q };
            tri[k] = mesh_pos.len() as u32;
            mesh_pos.push(q.as_vec3());
        }
        tris.push(tri);
    }
    signed_volume(&Mesh::new(mesh_pos, tris))
}

#[test]
fn box_volume_is_outward() {
    let c = box_caster();
    let lp = Vec3::new(0.3, 5.0, -0.2);
    let p = plan(&cam3(), &point(lp), Method::McGuire, &c);
    let cp = &p.casters[0];
    assert_eq!(cp.case, Case::ZFailLightCap);
    assert_closed(&c[0], cp, false);
    let v = finite_signed_volume(&c[0], cp, lp);
    // the frustum between the top face (area 1, at distance ~4.5) and its extrusion by 21x
    // is large and POSITIVE: every face points out of the volume.
    assert!(v > 100.0, "{v}");
    // the O(f) variant encloses the same volume
    let p2 = plan(&cam3(), &point(lp), Method::ZFail, &c);
    let v2 = finite_signed_volume(&c[0], &p2.casters[0], lp);
    // (at a finite extrusion the fan is not the projected cap, so only the sign matches)
    assert!(v2 > 100.0, "{v2}");
    // sides alone for each edge: front faces point away from the box centre
    for s in sil_side_normals(&c[0], cp, lp) {
        assert!(s > 0.0);
    }
    // light inside: volume is everything outside the box => the finite version is the
    // extruded shell minus the box, positive
    let li = Vec3::new(0.1, 0.0, 0.0);
    let p = plan(&cam3(), &point(li), Method::McGuire, &c);
    assert!(finite_signed_volume(&c[0], &p.casters[0], li) > 0.0);
}

/// For every side triangle of the plan (first 2s triangles of the volume lists), the dot
/// product of its normal with (triangle centroid - box centre projected off the light ray).
fn sil_side_normals(caster: &Caster, p: &CasterPlan, l: Vec3) -> Vec<f64> {
    let mut out = Vec::new();
    let l = l.as_dvec3();
    for d in &p.chunks {
        let ch = &caster.chunks[d.chunk];
        let n = ch.n();
        let side_count = 2 * p.sides.min(d.volume.len() / 3) / 2;
        for t in d.volume.chunks(3).take(side_count) {
            let q = |i: u16| {
                let i = i as usize;
                let v = ch.vertices[i % n].as_dvec3();
                if i >= n {
                    v + (v - l) * 20.0
                } else {
                    v
                }
            };
            let (a, b, c) = (q(t[0]), q(t[1]), q(t[2]));
            let nrm = (b - a).cross(c - a);
            // the box centre's shadow axis: points o + s (o - l); compare with the closest
            let o = DVec3::ZERO;
            let axis = (o - l).normalize();
            let cen = (a + b + c) / 3.0;
            let rel = cen - l;
            let radial = rel - axis * rel.dot(axis);
            out.push(nrm.dot(radial));
        }
    }
    out
}

fn rng(seed: u64) -> impl FnMut() -> f32 {
    let mut s = seed;
    move || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        ((s >> 11) as f64 / (1u64 << 53) as f64) as f32 * 2.0 - 1.0
    }
}

#[test]
fn random_lights_closed_sphere_torus() {
    let casters = vec![
        Caster::new("sphere", &uv_sphere(1.0, 24, 13), Mat4::IDENTITY).unwrap(),
        Caster::new("torus", &torus(1.0, 0.35, 20, 10), Mat4::from_translation(Vec3::new(0.5, 0.0, 0.0))).unwrap(),
        // chunked: several chunks, edges crossing chunk boundaries
        Caster::with_chunk_limit("sphere-chunks", &uv_sphere(1.0, 24, 13), Mat4::IDENTITY, 40).unwrap(),
        // mirrored transform (winding swapped as the loader does)
        {
            let mut m = torus(1.0, 0.35, 20, 10);
            for t in &mut m.triangles {
                t.swap(1, 2);
            }
            Caster::new("mirrored", &m, Mat4::from_scale(Vec3::new(-1.0, 1.0, 1.0))).unwrap()
        },
    ];
    assert!(casters[2].chunks.len() > 3);
    let mut r = rng(99);
    let mut seen_fan = 0;
    let mut seen_back = 0;
    for i in 0..200 {
        let dist = [0.2f32, 1.0, 1.5, 4.0, 30.0][i % 5];
        let p = Vec3::new(r(), r(), r()).normalize_or(Vec3::X) * dist;
        let directional = i % 7 == 0;
        let light = if directional { dir(-p) } else { point(p) };
        for method in [Method::McGuire, Method::ZFail] {
            // case 3 camera: inside the shadowed region looking at the casters
            let cam = Camera { up: Vec3::Y, ..camera(-p.normalize_or(Vec3::X) * 6.0 + Vec3::new(0.01, 0.02, 0.0), Vec3::ZERO) };
            let plan = plan(&cam, &light, method, &casters);
            for (ci, cp) in plan.casters.iter().enumerate() {
                if cp.case != Case::ZFailLightCap {
                    continue;
                }
                match cp.dark_cap_kind {
                    DarkCap::Fan => seen_fan += 1,
                    DarkCap::BackFaces => seen_back += 1,
                    _ => {}
                }
                assert_closed(&casters[ci], cp, directional);
                if !directional {
                    let lw = p;
                    // world-space finite signed volume for identity / mirrored casters
                    {
                        let v = finite_signed_volume_world(&casters[ci], cp, lw);
                        assert!(v > 0.0, "caster {ci} light {p:?} {method}: volume {v}");
                    }
                }
            }
        }
    }
    assert!(seen_fan > 50 && seen_back > 10, "{seen_fan} {seen_back}");
}

/// Like `finite_signed_volume` but transforms to world space first.
fn finite_signed_volume_world(caster: &Caster, p: &CasterPlan, l: Vec3) -> f64 {
    let l = l.as_dvec3();
    let m = caster.transform.as_dmat4();
    let mut pos = Vec::new();
    let mut tris = Vec::new();
    for (c, t) in all_tris(p) {
        let ch = &caster.chunks[c];
        let n = ch.n();
        let mut tri = [0u32; 3];
        for k in 0..3 {
            let i = t[k] as usize;
            let q = m.transform_point3(ch.vertices[i % n].as_dvec3());
            let q = if i >= n { q + (q - l) * 20.0 } else { q };
            tri[k] = pos.len() as u32;
            pos.push(q.as_vec3());
        }
        tris.push(tri);
    }
    signed_volume(&Mesh::new(pos, tris))
}

#[test]
fn scissor_depth_in_plan() {
    let c = box_caster();
    let mut l = point(Vec3::new(0.0, 0.0, -2.0));
    l.radius = Some(3.0);
    let cam = Camera { up: Vec3::Y, ..camera(Vec3::new(0.0, 0.0, 10.0), Vec3::ZERO) };
    let p = plan(&cam, &l, Method::McGuire, &c);
    let s = p.scissor.unwrap();
    assert!(s[2] > 0 && s[2] < 256 && s[3] > 0 && s[3] < 256);
    let (d0, d1) = p.depth_bounds.unwrap();
    assert!(0.0 < d0 && d0 < d1 && d1 < 1.0);
    assert!(p.plan_ms >= p.silhouette_ms);
}

/// FNV-1a over the parts of a plan the GPU consumes (index lists, counts, kinds, light).
fn plan_digest(h: &mut u64, p: &CasterPlan) {
    let mut eat = |bytes: &[u8]| {
        for &b in bytes {
            *h ^= b as u64;
            *h = h.wrapping_mul(0x100000001b3);
        }
    };
    let head = format!(
        "{:?}|{}|{}|{}|{}|{:?}|{:?}|{:?}|",
        p.case,
        p.silhouette_edges,
        p.sides,
        p.dark_cap,
        p.light_cap,
        p.dark_cap_kind,
        p.formulation,
        p.light_object.map(f32::to_bits)
    );
    eat(head.as_bytes());
    for d in &p.chunks {
        eat(&(d.chunk as u64).to_le_bytes());
        eat(&(d.volume.len() as u64).to_le_bytes());
        // the volume's triangles as a set: the side order follows the edge scan's order
        let mut tris: Vec<&[u16]> = d.volume.chunks(3).collect();
        tris.sort_unstable();
        for i in tris.concat() {
            eat(&i.to_le_bytes());
        }
        eat(&(d.light_cap.len() as u64).to_le_bytes());
        for i in &d.light_cap {
            eat(&i.to_le_bytes());
        }
    }
}

/// Closed manifold casters keep the exact plans (index bytes, counts, kinds) they had before
/// the multiplicity path existed: the digest was recorded on the manifold-only planner (and
/// re-recorded, identical, with the volume hashed as a set of triangles before the edge scan
/// changed its order).
#[test]
fn closed_manifold_plans_unchanged() {
    let casters = vec![
        Caster::new("box", &cube(Vec3::ZERO, 0.5), Mat4::IDENTITY).unwrap(),
        Caster::new("sphere", &uv_sphere(1.0, 24, 13), Mat4::from_translation(Vec3::new(0.3, -0.2, 0.1))).unwrap(),
        Caster::new("torus", &torus(1.0, 0.35, 20, 10), Mat4::from_translation(Vec3::new(0.5, 0.0, 0.0))).unwrap(),
        Caster::with_chunk_limit("sphere-chunks", &uv_sphere(1.0, 24, 13), Mat4::IDENTITY, 40).unwrap(),
        {
            let mut m = torus(1.0, 0.35, 20, 10);
            for t in &mut m.triangles {
                t.swap(1, 2);
            }
            Caster::new("mirrored", &m, Mat4::from_scale(Vec3::new(-1.0, 1.0, 1.0))).unwrap()
        },
    ];
    let mut r = rng(4242);
    let mut h = 0xcbf29ce484222325u64;
    let mut cases = std::collections::BTreeMap::<String, usize>::new();
    for i in 0..60 {
        let dist = [0.2f32, 1.0, 1.5, 4.0, 30.0][i % 5];
        let p = Vec3::new(r(), r(), r()).normalize_or(Vec3::X) * dist;
        let light = if i % 7 == 0 { dir(-p) } else { point(p) };
        let cams = [
            cam1(),
            cam2(),
            cam3(),
            Camera { up: Vec3::Y, ..camera(-p.normalize_or(Vec3::X) * 6.0 + Vec3::new(0.01, 0.02, 0.0), Vec3::ZERO) },
        ];
        for cam in &cams {
            for method in Method::ALL {
                for cp in &plan(cam, &light, method, &casters).casters {
                    *cases.entry(format!("{:?}/{:?}/{:?}", cp.case, cp.dark_cap_kind, cp.formulation)).or_default() += 1;
                    plan_digest(&mut h, cp);
                }
            }
        }
    }
    assert!(cases.len() >= 7, "{cases:?}");
    assert_eq!(h, 0x4363f26222e22c1d, "digest {h:#018x} {cases:?}");
}

/// Multiplicity casters: a CPU stencil simulation over the emitted geometry.
mod multiplicity;

/// `caster` with its silhouette structures in the caller's triangle order (no load-time
/// reordering): the same welded mesh, chunks and parts.
fn in_caller_order(caster: &Caster) -> Caster {
    let mut c = caster.clone();
    c.planes = crate::geom::silhouette::FacePlanes::new(c.mesh());
    for p in &mut c.parts {
        p.scan = crate::geom::silhouette::EdgeScan::new(p.scan.edges().to_vec());
    }
    c
}

/// A mesh of several parts in a pseudo-random triangle order: a jittered sphere (closed), a
/// torus, an open grid and a soup over a few shared vertices (non-manifold).
fn random_mesh(seed: u64, slices: u32, soup: usize) -> Mesh {
    let mut r = rng(2 * seed + 1);
    let mut m = uv_sphere(1.0, slices, slices / 2 + 2);
    for p in &mut m.positions {
        *p *= 1.0 + 0.1 * r();
    }
    let add = |m: &mut Mesh, o: Mesh, at: Vec3| {
        let base = m.positions.len() as u32;
        m.positions.extend(o.positions.iter().map(|&p| p + at));
        m.triangles.extend(o.triangles.iter().map(|t| t.map(|i| i + base)));
    };
    add(&mut m, torus(0.8, 0.3, slices, slices / 3 + 3), Vec3::new(3.0, 0.0, 0.0));
    let mut grid = Mesh::default();
    for i in 0..6 {
        for j in 0..6 {
            grid.positions.push(Vec3::new(i as f32 * 0.3, r() * 0.2, j as f32 * 0.3));
        }
    }
    for i in 0..5u32 {
        for j in 0..5u32 {
            let v = i * 6 + j;
            grid.triangles.push([v, v + 6, v + 1]);
            grid.triangles.push([v + 1, v + 6, v + 7]);
        }
    }
    add(&mut m, grid, Vec3::new(-3.0, 0.0, 0.0));
    let pool: Vec<Vec3> = (0..8).map(|_| Vec3::new(r(), r(), r()) * 0.5 + Vec3::new(0.0, 3.0, 0.0)).collect();
    let base = m.positions.len() as u32;
    m.positions.extend(pool);
    for k in 0..soup {
        let a = (r().abs() * 8.0) as u32 % 8;
        let b = (a + 1 + (r().abs() * 6.0) as u32 % 6) % 8;
        let c = (0..8).find(|&c| c != a && c != b && (c + k as u32).is_multiple_of(3)).unwrap_or((b + 1) % 8);
        if c != a && c != b {
            m.triangles.push([base + a, base + b, base + c]);
        }
    }
    crate::geom::testmesh::shuffled(&m)
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig::with_cases(24))]
    /// The load-time reordering is invisible: for random meshes (closed, open and non-manifold
    /// parts, triangles in random order), lights, cameras and methods, the plans of a caster
    /// in its scan order and of the same caster scanning in the caller's order are equal (counts,
    /// kinds, light caps index for index, volumes triangle for triangle; the sides' order is the
    /// scan's).
    #[test]
    fn reordering_is_invisible_in_plans(seed in 0u64..1_000_000, slices in 6u32..30, soup in 0usize..12, mirror in proptest::bool::ANY) {
        let m = random_mesh(seed, slices, soup);
        let t = if mirror { Mat4::from_scale(Vec3::new(-1.0, 1.0, 1.0)) } else { Mat4::from_translation(Vec3::new(0.2, -0.1, 0.3)) };
        let c = Caster::with_chunk_limit("r", &m, t, 64 + (seed % 200) as usize).unwrap();
        proptest::prop_assert!(!c.planes.order().is_identity());
        let plain = in_caller_order(&c);
        let transparent = c.clone().into_transparent(Vec3::splat(0.5));
        let transparent_plain = in_caller_order(&transparent);
        let mut r = rng((seed ^ 0x5eed) | 1);
        for i in 0..4 {
            let p = Vec3::new(r(), r(), r()).normalize_or(Vec3::X) * [0.3f32, 2.0, 6.0, 40.0][i];
            let light = if i == 3 { dir(-p) } else { point(p) };
            let cam = Camera { up: Vec3::Y, ..camera(Vec3::new(r(), r(), r()) * 8.0 + Vec3::new(0.01, 0.02, 5.0), Vec3::ZERO) };
            for method in Method::ALL {
                for (a, b) in [(&c, &plain), (&transparent, &transparent_plain)] {
                    let (pa, pb) = (plan(&cam, &light, method, std::slice::from_ref(a)), plan(&cam, &light, method, std::slice::from_ref(b)));
                    let (mut ha, mut hb) = (0u64, 0u64);
                    plan_digest(&mut ha, &pa.casters[0]);
                    plan_digest(&mut hb, &pb.casters[0]);
                    proptest::prop_assert_eq!(ha, hb, "method {:?} light {:?}", method, light.position);
                    proptest::prop_assert_eq!(format!("{:?}", pa.casters[0].parts), format!("{:?}", pb.casters[0].parts));
                }
            }
        }
    }
}
