//! Multiplicity casters (Kim et al. 2008): a CPU stencil simulation over the emitted geometry.

use super::*;

fn quad_tris(b: u32, flip: bool) -> [[u32; 3]; 2] {
    if flip {
        [[b, b + 2, b + 1], [b, b + 3, b + 2]]
    } else {
        [[b, b + 1, b + 2], [b, b + 2, b + 3]]
    }
}

/// The non-closed test meshes, by name.
fn open_meshes() -> Vec<(&'static str, Mesh)> {
    let v = |x: f32, y: f32, z: f32| Vec3::new(x, y, z);
    let mut out = Vec::new();
    out.push(("triangle", Mesh::new(vec![v(-0.6, 0.1, -0.4), v(0.7, -0.1, -0.3), v(0.0, 0.2, 0.6)], vec![[0, 1, 2]])));
    let mut open_box = cube(Vec3::ZERO, 0.5);
    open_box.triangles.retain(|t| !t.iter().all(|&i| i & 2 != 0)); // no +y face
    out.push(("open box", open_box));
    out.push((
        "quad",
        Mesh::new(vec![v(-0.7, 0.0, -0.6), v(0.7, 0.05, -0.6), v(0.7, 0.0, 0.6), v(-0.7, -0.05, 0.6)], quad_tris(0, false).to_vec()),
    ));
    // two boxes sharing a face, both complete: the shared face is a back-to-back pair
    let two = {
        let a = cube(Vec3::new(-0.5, 0.0, 0.0), 0.5);
        let b = cube(Vec3::new(0.5, 0.0, 0.0), 0.5);
        let mut pos = a.positions.clone();
        pos.extend(&b.positions);
        let mut tris = a.triangles.clone();
        tris.extend(b.triangles.iter().map(|t| t.map(|i| i + 8)));
        Mesh::new(pos, tris)
    };
    out.push(("two boxes back-to-back", two.clone()));
    // the same with the shared face kept once: its edges are used by 3 triangles
    let mut one_wall = two.clone();
    let on_wall = |t: &[u32; 3]| t.iter().all(|&i| two.positions[i as usize].x == 0.0);
    let wall: Vec<usize> = (0..two.triangles.len()).filter(|&i| on_wall(&two.triangles[i])).collect();
    assert_eq!(wall.len(), 4);
    one_wall.triangles.remove(wall[3]); // the second box's copy of the wall goes
    one_wall.triangles.remove(wall[2]);
    out.push(("two boxes one wall", one_wall));
    // a box with duplicated faces: two faces repeated as they are, one back-to-back
    let mut dup = cube(Vec3::ZERO, 0.5);
    let (t0, t1, t4) = (dup.triangles[0], dup.triangles[1], dup.triangles[4]);
    dup.triangles.extend([t0, t1, [t4[0], t4[2], t4[1]]]);
    out.push(("box with duplicates", dup));
    // inside-out box: closed and consistent, so forced onto the multiplicity path below
    let mut inv = cube(Vec3::ZERO, 0.5);
    for t in &mut inv.triangles {
        t.swap(1, 2);
    }
    out.push(("inside-out box", inv));
    // "T": three quads on the edge x = y = 0, windings mixed
    let mut pos = Vec::new();
    let mut tris = Vec::new();
    for (k, (d, flip)) in [(v(1.0, 0.0, 0.0), false), (v(-1.0, 0.0, 0.0), false), (v(0.0, 1.0, 0.1), true)].into_iter().enumerate() {
        let b = pos.len() as u32;
        pos.extend([v(0.0, 0.0, -0.5), v(0.0, 0.0, 0.5), d * 0.6 + v(0.0, 0.0, 0.5), d * 0.6 + v(0.0, 0.0, -0.5)]);
        tris.extend(quad_tris(b, flip ^ (k == 1)));
    }
    out.push(("T junction", Mesh::new(pos, tris)));
    out
}

fn multiplicity_caster(name: &str, m: &Mesh, transform: Mat4, limit: usize) -> Caster {
    let mut c = Caster::with_chunk_limit(name, m, transform, limit).unwrap();
    if c.is_manifold() {
        // (only the inside-out box) exercise the multiplicity construction on it too
        c.make_whole_multiplicity("forced by the test".into());
    }
    c
}

/// f64 ray/triangle: Some(t) for a hit at ray parameter t (any sign), None for a miss;
/// Err(()) when the ray passes too close to an edge or is parallel (resample).
fn ray_tri(o: DVec3, d: DVec3, a: DVec3, b: DVec3, c: DVec3) -> Result<Option<(f64, bool)>, ()> {
    let (e1, e2) = (b - a, c - a);
    let n = e1.cross(e2);
    let p = d.cross(e2);
    let det = e1.dot(p);
    let scale = e1.length() * e2.length() * d.length();
    if scale == 0.0 || n.length() <= 1e-12 * e1.length() * e2.length() {
        return Ok(None); // degenerate triangle: covers no pixel
    }
    if det.abs() <= 1e-10 * scale {
        return Ok(None); // edge-on: covers no pixel either
    }
    let inv = 1.0 / det;
    let s = o - a;
    let u = s.dot(p) * inv;
    let q = s.cross(e1);
    let v = d.dot(q) * inv;
    let w = 1.0 - u - v;
    let eps = 1e-7;
    if u < -eps || v < -eps || w < -eps {
        return Ok(None);
    }
    if u < eps || v < eps || w < eps {
        return Err(());
    }
    let t = e2.dot(q) * inv;
    // front face seen along d: the CCW normal points against d
    Ok(Some((t, n.dot(d) < 0.0)))
}

/// World-space positions of a plan's triangles (w=0 copies pushed far away), per list.
fn plan_world_tris(caster: &Caster, p: &CasterPlan, l: Vec4) -> (Vec<[DVec3; 3]>, Vec<[DVec3; 3]>) {
    let m = caster.transform.as_dmat4();
    let lw = l.as_dvec4();
    let centre = m.transform_point3(caster.object_bounds.center().as_dvec3());
    let k = 1e4;
    let mut vol = Vec::new();
    let mut cap = Vec::new();
    for d in &p.chunks {
        let ch = &caster.chunks[d.chunk];
        let n = ch.n();
        let q = |i: u16| {
            let i = i as usize;
            let v = m.transform_point3(ch.vertices[i % n].as_dvec3());
            if i < n {
                v
            } else if lw.w == 0.0 {
                centre - lw.truncate().normalize() * k * 10.0
            } else {
                v + (v - lw.truncate()) * k
            }
        };
        for t in d.volume.chunks(3) {
            vol.push([q(t[0]), q(t[1]), q(t[2])]);
        }
        for t in d.light_cap.chunks(3) {
            cap.push([q(t[0]), q(t[1]), q(t[2])]);
        }
    }
    (vol, cap)
}

/// Number of caster triangles crossed by the segment p -> light (or ray towards a
/// directional light); Err when ambiguous.
fn occluders(caster: &Caster, p: DVec3, l: Vec4) -> Result<i32, ()> {
    let m = caster.transform.as_dmat4();
    let lw = l.as_dvec4();
    let (d, tmax) = if lw.w == 0.0 { (lw.truncate(), f64::INFINITY) } else { (lw.truncate() - p, 1.0) };
    let mut n = 0;
    for t in &caster.mesh().triangles {
        let v = |i: u32| m.transform_point3(caster.mesh().positions[i as usize].as_dvec3());
        if let Some((s, _)) = ray_tri(p, d, v(t[0]), v(t[1]), v(t[2]))? {
            if s.abs() < 1e-9 || (s - tmax).abs() < 1e-9 {
                return Err(());
            }
            if s > 0.0 && s < tmax {
                n += 1;
            }
        }
    }
    Ok(n)
}

/// The stencil value the GPU would leave at a visible point `p` seen from `eye`.
fn simulated_stencil(vol: &[[DVec3; 3]], cap: &[[DVec3; 3]], case: Case, eye: DVec3, p: DVec3) -> Result<i32, ()> {
    let d = p - eye;
    let mut count = 0;
    for t in vol {
        if let Some((s, front)) = ray_tri(eye, d, t[0], t[1], t[2])? {
            if (s - 1.0).abs() < 1e-9 {
                return Err(());
            }
            match case {
                // depth LESS passes in front of p: front +1, back -1
                Case::ZPass if s > 0.0 && s < 1.0 => count += if front { 1 } else { -1 },
                // depth LESS fails behind p: back +1, front -1
                Case::ZFail | Case::ZFailLightCap if s > 1.0 => count += if front { -1 } else { 1 },
                _ => {}
            }
        }
    }
    for t in cap {
        // depth NEVER: every covered pixel fails, z-fail ops
        if let Some((s, front)) = ray_tri(eye, d, t[0], t[1], t[2])? {
            if s > 0.0 {
                count += if front { -1 } else { 1 };
            }
        }
    }
    Ok(count)
}

/// Whether the G-buffer pass hides `p` behind one of the caster's triangles (casters on the
/// multiplicity path are drawn two-sided, so a hit on either face hides).
fn hidden(caster: &Caster, eye: DVec3, p: DVec3) -> Result<bool, ()> {
    let m = caster.transform.as_dmat4();
    let d = p - eye;
    for t in &caster.mesh().triangles {
        let v = |i: u32| m.transform_point3(caster.mesh().positions[i as usize].as_dvec3());
        // the G-buffer draws the indices as they are: the screen winding is the world one
        // (the loader swapped mirrored meshes' object winding so that it is CCW outward)
        let (a, b, c) = (v(t[0]), v(t[1]), v(t[2]));
        if let Some((s, _front)) = ray_tri(eye, d, a, b, c)? {
            if s > 0.0 && s < 1.0 + 1e-12 {
                return Ok(true);
            }
        }
    }
    Ok(false)
}

#[test]
fn multiplicity_counts_equal_occluders() {
    let mut r = rng(2024);
    let mut checked = std::collections::BTreeMap::<String, usize>::new();
    for (name, mesh) in open_meshes() {
        let casters = [
            multiplicity_caster(name, &mesh, Mat4::IDENTITY, MAX_CHUNK_VERTICES_TEST),
            multiplicity_caster(name, &mesh, Mat4::from_translation(Vec3::new(0.2, -0.1, 0.3)) * Mat4::from_rotation_y(0.7), 5),
            {
                let mut m = mesh.clone();
                for t in &mut m.triangles {
                    t.swap(1, 2);
                }
                multiplicity_caster(name, &m, Mat4::from_scale(Vec3::new(-1.0, 1.0, 1.0)), 6)
            },
        ];
        for caster in &casters {
            assert_eq!(caster.kind.path(), VolumePath::Multiplicity);
            let cs = std::slice::from_ref(caster);
            for i in 0..40 {
                let dist = [0.3f32, 0.9, 2.0, 4.0, 25.0][i % 5];
                let lp = Vec3::new(r(), r(), r()).normalize_or(Vec3::X) * dist;
                let light = if i % 6 == 0 { dir(-lp) } else { point(lp) };
                let lh = light.homogeneous();
                let eye = Vec3::new(r(), r(), r()).normalize_or(Vec3::Y) * (3.0 + 2.0 * r().abs());
                // every fourth camera looks away from the caster (McGuire's case 2)
                let target = if i % 4 == 3 { eye * 2.0 } else { Vec3::new(r(), r(), r()) * 0.3 };
                let cam = Camera { up: Vec3::new(0.3, 0.1, 1.0), ..camera(eye, target) };
                let vp = cam.proj_infinite(1.0) * cam.view();
                for method in Method::ALL {
                    let cp = &plan(&cam, &light, method, cs).casters[0];
                    assert_eq!(cp.path, VolumePath::Multiplicity);
                    if cp.case == Case::Culled {
                        continue;
                    }
                    assert_eq!(cp.formulation, Formulation::TwoSided);
                    if cp.case == Case::ZFailLightCap {
                        assert_closed(caster, cp, light.kind == LightKind::Directional);
                    }
                    let (vol, cap) = plan_world_tris(caster, cp, lh);
                    let e = eye.as_dvec3();
                    let truth_eye = occluders(caster, e, lh);
                    let mut n = 0;
                    let mut tries = 0;
                    while n < 25 && tries < 400 {
                        tries += 1;
                        let p = if i % 4 == 3 {
                            e * 1.6 + DVec3::new(r() as f64, r() as f64, r() as f64) * 2.5
                        } else {
                            DVec3::new(r() as f64, r() as f64, r() as f64) * 2.5
                        };
                        let clip = vp.as_dmat4() * p.extend(1.0);
                        if !(clip.w > 0.2 && clip.x.abs() < clip.w && clip.y.abs() < clip.w) {
                            continue; // outside the view frustum: no pixel
                        }
                        let (Ok(false), Ok(truth), Ok(count)) =
                            (hidden(caster, e, p), occluders(caster, p, lh), simulated_stencil(&vol, &cap, cp.case, e, p))
                        else {
                            continue;
                        };
                        let expect = if cp.case == Case::ZPass {
                            // z-pass counts relative to the eye; the occlusion pyramid keeps the
                            // eye lit when a method picks z-pass by itself
                            let te = truth_eye.expect("eye ray ambiguous");
                            if method != Method::ZPass {
                                assert_eq!(te, 0, "{name}: z-pass chosen with the eye in shadow");
                            }
                            truth - te
                        } else {
                            truth
                        };
                        assert_eq!(
                            count,
                            expect,
                            "{name} ({}) {method} {:?} light {lh:?} cam {cam:?} p {p:?} dark {:?} plan {cp:?}",
                            caster.chunks.len(),
                            cp.case,
                            cp.dark_cap_kind
                        );
                        n += 1;
                        *checked.entry(format!("{:?}/{:?}", cp.case, cp.dark_cap_kind)).or_default() += 1;
                        *checked.entry(format!("truth>0 {name}")).or_default() += usize::from(truth > 0);
                    }
                }
            }
        }
    }
    eprintln!("{checked:?}");
    for k in ["ZPass/None", "ZFailLightCap/Fan", "ZFailLightCap/AllFaces", "ZFailLightCap/None", "ZFail/Fan", "ZFail/AllFaces"] {
        assert!(checked.get(k).copied().unwrap_or(0) > 100, "{k}: {checked:?}");
    }
}

const MAX_CHUNK_VERTICES_TEST: usize = crate::shadow::caster::MAX_CHUNK_VERTICES;

/// The rules on small cases: multiplicity per edge, caps, stats.
#[test]
fn multiplicity_rules() {
    let meshes: HashMap<_, _> = open_meshes().into_iter().collect();
    let above = point(Vec3::new(0.05, 5.0, 0.02));
    let one = |name: &str, light: &Light, cam: &Camera, method: Method| {
        let c = multiplicity_caster(name, &meshes[name], Mat4::IDENTITY, MAX_CHUNK_VERTICES_TEST);
        plan(cam, light, method, std::slice::from_ref(&c)).casters[0].clone()
    };
    // a quad: the diagonal cancels (m = 0), the four boundary edges have |m| = 1
    let p = one("quad", &above, &cam3(), Method::McGuire);
    assert_eq!((p.path, p.case, p.dark_cap_kind), (VolumePath::Multiplicity, Case::ZFailLightCap, DarkCap::Fan));
    assert_eq!((p.silhouette_edges, p.multiplicity_max, p.sides, p.dark_cap, p.light_cap), (4, 1, 8, 4, 2));
    // seen from below (cam3 looks up the y axis): both triangles face the eye, caps are NEVER
    assert_eq!(p.chunks[0].light_cap.len(), 6);
    // from above the eye sees the quad's back: the G-buffer draws it two-sided, so its caps
    // still lie on the visible surface and go to the NEVER list
    let cam_above = Camera { up: Vec3::Z, ..camera(Vec3::new(0.0, 3.0, 0.0), Vec3::ZERO) };
    let p = one("quad", &point(Vec3::new(0.05, -5.0, 0.02)), &cam_above, Method::McGuire);
    assert_eq!(p.light_cap, 2);
    assert_eq!(p.chunks[0].light_cap.len(), 6);
    // z-pass: caps never lie strictly in front of the visible surface, so none are drawn
    let p = one("quad", &above, &cam1(), Method::McGuire);
    assert_eq!((p.case, p.light_cap), (Case::ZPass, 0));
    let p = one("quad", &above, &cam_above, Method::ZPass);
    assert_eq!((p.case, p.light_cap, p.chunks[0].volume.len()), (Case::ZPass, 0, 3 * 8));
    // open box lit from above: only the rim, once
    let p = one("open box", &above, &cam3(), Method::ZFail);
    assert_eq!((p.silhouette_edges, p.multiplicity_max, p.dark_cap_kind, p.light_cap), (4, 1, DarkCap::AllFaces, 10));
    assert_eq!(p.dark_cap, 10);
    // a box whose lit (-z) face is duplicated: its rim counts 3 (2 copies + the far wall),
    // 4 on the edge it shares with the back-to-back -y triangle pair
    let p = one("box with duplicates", &point(Vec3::new(0.05, 0.02, -5.0)), &cam3(), Method::McGuire);
    assert_eq!(p.multiplicity_max, 4);
    let c = multiplicity_caster("d", &meshes["box with duplicates"], Mat4::IDENTITY, MAX_CHUNK_VERTICES_TEST);
    let f = facing_bits(c.mesh(), Vec4::new(0.05, 0.02, -5.0, 1.0), false);
    let mult = edge_multiplicities(&c, &f);
    let m_of = |a: u32, b: u32| {
        let e = c.topology.edges.iter().position(|e| e.v == [a.min(b), a.max(b)]).unwrap();
        mult[e] * if a < b { 1 } else { -1 }
    };
    assert_eq!(m_of(0, 1), -4); // welded ids = cube ids here
    assert_eq!(m_of(2, 3).abs(), 3);
    assert_eq!(m_of(0, 3), 0); // the -z diagonal
                               // a closed box on the multiplicity path: every silhouette edge twice (near + far face)
    let p = one("inside-out box", &above, &cam3(), Method::McGuire);
    assert_eq!((p.silhouette_edges, p.multiplicity_max, p.sides), (4, 2, 16));
    // McGuire case 2 (caster out of view): no light cap at all
    let p = one("T junction", &above, &cam2(), Method::McGuire);
    assert_eq!((p.case, p.light_cap), (Case::ZFail, 0));
    assert!(p.chunks.iter().all(|d| d.light_cap.is_empty()));
    // directional: one triangle per side, no dark cap
    let p = one("triangle", &dir(Vec3::NEG_Y), &cam3(), Method::McGuire);
    assert_eq!((p.silhouette_edges, p.sides, p.dark_cap, p.dark_cap_kind), (3, 3, 0, DarkCap::None));
    // light inside the open box: per-triangle dark caps even for McGuire
    let p = one("open box", &point(Vec3::new(0.1, 0.2, -0.1)), &cam3(), Method::McGuire);
    assert_eq!(p.dark_cap_kind, DarkCap::AllFaces);
    // closed manifolds report the manifold path
    let p = &plan(&cam3(), &above, Method::McGuire, &box_caster()).casters[0];
    assert_eq!((p.path, p.multiplicity_max, p.formulation), (VolumePath::Manifold, 1, Formulation::Front));
}

/// A closed cube and an open quad apart in one mesh: two parts, the cube on the manifold
/// path and the quad on the multiplicity path, each with its own counts.
#[test]
fn parts_planned_on_their_own() {
    let mut m = cube(Vec3::ZERO, 0.5);
    let b = m.positions.len() as u32;
    for p in [Vec3::new(2.0, -0.5, -0.5), Vec3::new(3.0, -0.5, -0.5), Vec3::new(3.0, -0.5, 0.5), Vec3::new(2.0, -0.5, 0.5)] {
        m.positions.push(p);
    }
    m.triangles.push([b, b + 1, b + 2]);
    m.triangles.push([b, b + 2, b + 3]);
    let c = Caster::new("two", &m, Mat4::IDENTITY).unwrap();
    assert_eq!(c.parts.len(), 2);
    assert_eq!(c.parts[0].kind, crate::shadow::CasterKind::Manifold);
    assert!(matches!(&c.parts[1].kind, crate::shadow::CasterKind::Multiplicity { reason } if reason.contains("4 boundary edges")));
    assert_eq!(c.parts[0].triangles.len(), 12);
    assert_eq!(c.parts[1].triangles, vec![12, 13]);
    assert!(!c.is_manifold());
    // chunks never mix parts, and each part's apex is its own centre
    for p in &c.parts {
        for ch in &c.chunks[p.chunks.clone()] {
            assert_eq!(*ch.vertices.last().unwrap(), p.object_bounds.center());
            assert!(ch.tri_ids.iter().all(|t| p.triangles.contains(t)));
        }
    }
    let cs = vec![c];
    let cam = camera(Vec3::new(1.5, -6.0, 0.0), Vec3::new(1.5, 0.0, 0.0));
    let l = point(Vec3::new(5.0, 5.0, 0.0));
    let whole = plan(&cam, &l, Method::ZFail, &cs);
    let cp = &whole.casters[0];
    assert_eq!(cp.parts.len(), 2);
    let (cube_p, quad_p) = (&cp.parts[0], &cp.parts[1]);
    assert_eq!((cube_p.path, quad_p.path), (VolumePath::Manifold, VolumePath::Multiplicity));
    assert_eq!(cube_p.formulation, Formulation::Front);
    assert_eq!(quad_p.formulation, Formulation::TwoSided);
    // the cube: 6 faces, the light sees 2 of them (+x and +y): a silhouette of 6 edges
    assert_eq!(cube_p.silhouette_edges, 6);
    assert_eq!((cube_p.sides, cube_p.dark_cap, cube_p.light_cap), (12, 4, 4));
    // the quad: 4 boundary edges of multiplicity 1, both triangles as caps
    assert_eq!((quad_p.silhouette_edges, quad_p.multiplicity_max), (4, 1));
    assert_eq!((quad_p.sides, quad_p.dark_cap, quad_p.light_cap), (8, 2, 2));
    assert_eq!(cp.sides, cube_p.sides + quad_p.sides);
    assert_eq!(cp.triangles(), 12 + 4 + 4 + 8 + 2 + 2);
    let idx: usize = cp.chunks.iter().map(|d| d.volume.len() + d.light_cap.len()).sum();
    assert_eq!(idx, 3 * cp.triangles());
    assert!(cp.chunks.iter().all(|d| d.case == cp.case));
    // the old single-caster path: the whole mesh on the multiplicity path costs more
    let mut all = cs[0].clone();
    all.make_whole_multiplicity("test".into());
    let old = plan(&cam, &l, Method::ZFail, &[all]);
    assert_eq!(old.casters[0].parts.len(), 1);
    assert!(old.casters[0].triangles() > cp.triangles());
    // a part outside the light's radius is culled on its own
    let near = Light { radius: Some(2.0), ..point(Vec3::new(-1.0, 1.0, 0.0)) };
    let p = plan(&cam, &near, Method::McGuire, &cs);
    assert_eq!(p.casters[0].parts[1].case, Case::Culled);
    assert_ne!(p.casters[0].parts[0].case, Case::Culled);
    assert_eq!(p.casters[0].sides, p.casters[0].parts[0].sides);
}
