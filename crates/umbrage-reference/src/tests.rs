//! Analytic known answers for the reference.

use super::metrics::{self, compare_states, dilate, shadow_edges};
use super::*;
use glam::{DVec3, Mat4, Vec3, Vec4};
use umbrage::geom::Mesh;
use umbrage_scene::{Camera, Light, LightKind, Scene, SceneMesh};

/// Fixes the winding of every triangle of a convex mesh so that it faces away from `centre`.
fn outward(mut m: Mesh, centre: Vec3) -> Mesh {
    for t in 0..m.triangles.len() {
        let [a, b, c] = m.triangle(t);
        if (b - a).cross(c - a).dot((a + b + c) / 3.0 - centre) < 0.0 {
            m.triangles[t].swap(1, 2);
        }
    }
    m
}

fn box_mesh(min: Vec3, max: Vec3) -> Mesh {
    let p: Vec<Vec3> = (0..8)
        .map(|i| {
            Vec3::new(
                if i & 1 != 0 { max.x } else { min.x },
                if i & 2 != 0 { max.y } else { min.y },
                if i & 4 != 0 { max.z } else { min.z },
            )
        })
        .collect();
    let faces = [[0, 1, 3, 2], [4, 5, 7, 6], [0, 1, 5, 4], [2, 3, 7, 6], [0, 2, 6, 4], [1, 3, 7, 5]];
    let mut tris = Vec::new();
    for f in faces {
        tris.push([f[0], f[1], f[2]]);
        tris.push([f[0], f[2], f[3]]);
    }
    outward(Mesh::new(p, tris), (min + max) * 0.5)
}

/// Ground plane y = 0, |x|,|z| <= s, normal +y.
fn plane(s: f32) -> Mesh {
    let p = vec![Vec3::new(-s, 0.0, -s), Vec3::new(s, 0.0, -s), Vec3::new(s, 0.0, s), Vec3::new(-s, 0.0, s)];
    let m = Mesh::new(p, vec![[0, 1, 2], [0, 2, 3]]);
    outward(m, Vec3::new(0.0, -1.0, 0.0))
}

fn icosphere(centre: Vec3, r: f32, subdiv: u32) -> Mesh {
    let t = (1.0 + 5f32.sqrt()) / 2.0;
    let mut v: Vec<Vec3> = [
        (-1.0, t, 0.0),
        (1.0, t, 0.0),
        (-1.0, -t, 0.0),
        (1.0, -t, 0.0),
        (0.0, -1.0, t),
        (0.0, 1.0, t),
        (0.0, -1.0, -t),
        (0.0, 1.0, -t),
        (t, 0.0, -1.0),
        (t, 0.0, 1.0),
        (-t, 0.0, -1.0),
        (-t, 0.0, 1.0),
    ]
    .iter()
    .map(|&(x, y, z)| Vec3::new(x, y, z).normalize())
    .collect();
    let mut f: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..subdiv {
        let mut cache = std::collections::HashMap::new();
        let mut mid = |a: u32, b: u32, v: &mut Vec<Vec3>| {
            *cache.entry((a.min(b), a.max(b))).or_insert_with(|| {
                v.push(((v[a as usize] + v[b as usize]) * 0.5).normalize());
                (v.len() - 1) as u32
            })
        };
        let mut nf = Vec::new();
        for [a, b, c] in f {
            let ab = mid(a, b, &mut v);
            let bc = mid(b, c, &mut v);
            let ca = mid(c, a, &mut v);
            nf.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        f = nf;
    }
    let m = Mesh::new(v.into_iter().map(|p| centre + p * r).collect(), f);
    outward(m, centre)
}

fn point_light(p: Vec3) -> Light {
    Light {
        kind: LightKind::Point,
        position: p,
        direction: Vec3::NEG_Y,
        color: Vec3::ONE,
        intensity: 1.0,
        radius: None,
        cone_deg: 45.0,
        area: None,
    }
}

fn dir_light(d: Vec3) -> Light {
    Light { kind: LightKind::Directional, position: Vec3::ZERO, direction: d.normalize(), ..point_light(Vec3::ZERO) }
}

fn scene(meshes: Vec<(Mesh, bool)>, lights: Vec<Light>, camera: Camera) -> Scene {
    Scene {
        name: "test".into(),
        camera,
        lights,
        meshes: meshes
            .into_iter()
            .enumerate()
            .map(|(i, (mesh, casts))| SceneMesh {
                name: format!("m{i}"),
                mesh,
                transform: Mat4::IDENTITY,
                color: Vec3::ONE,
                opacity: 1.0,
                casts_shadow: casts,
            })
            .collect(),
        ambient: Vec3::splat(0.08),
        spheres: Vec::new(),
    }
}

fn top_camera() -> Camera {
    Camera { eye: Vec3::new(0.0, 10.0, 0.0), target: Vec3::ZERO, up: Vec3::NEG_Z, fov_y_deg: 40.0, near: 0.1 }
}

/// Unit box y in [1, 2] above the plane, light at (0, 4, 0): the shadow is the projection of
/// the top face, the square |x|, |z| < 1.
fn box_scene() -> Scene {
    scene(
        vec![(plane(10.0), true), (box_mesh(Vec3::new(-0.5, 1.0, -0.5), Vec3::new(0.5, 2.0, 0.5)), true)],
        vec![point_light(Vec3::new(0.0, 4.0, 0.0))],
        top_camera(),
    )
}

#[test]
fn reference_box_shadow_at() {
    let s = box_scene();
    let r = Reference::from_scene(&s);
    let l = &s.lights[0];
    let up = DVec3::Y;
    let at = |x: f64, z: f64| r.shadow_at(DVec3::new(x, 0.0, z), up, l);
    for (x, z) in [(0.0, 0.0), (0.9, 0.9), (-0.95, 0.5), (0.99, -0.99), (0.5, 0.97)] {
        assert_eq!(at(x, z), LightState::Shadowed, "({x}, {z})");
    }
    for (x, z) in [(1.01, 0.0), (1.05, 1.05), (-3.0, 2.0), (0.0, -1.02), (9.0, 9.0)] {
        assert_eq!(at(x, z), LightState::Lit, "({x}, {z})");
    }
    // Top face lit, bottom face and sides facing away.
    assert_eq!(r.shadow_at(DVec3::new(0.1, 2.0, 0.2), up, l), LightState::Lit);
    assert_eq!(r.shadow_at(DVec3::new(0.1, 1.0, 0.2), -up, l), LightState::BackFacing);
    assert_eq!(r.shadow_at(DVec3::new(0.5, 1.5, 0.0), DVec3::X, l), LightState::BackFacing);
    // On the edge with a visible perturbation radius: ambiguous.
    assert_eq!(r.shadow_at_radius(DVec3::new(1.0, 0.0, 0.3), up, l, 0.01), LightState::Ambiguous);
    assert_eq!(r.shadow_at_radius(DVec3::new(1.02, 0.0, 0.3), up, l, 0.01), LightState::Lit);
    // Grazing.
    assert_eq!(r.shadow_at(DVec3::new(3.0, 4.0, 0.0), up, l), LightState::Ambiguous);
    // Slightly below the surface (f32 GPU positions): still no self-shadowing.
    assert_eq!(r.shadow_at(DVec3::new(3.0, -1e-6, 0.0), up, l), LightState::Lit);
    // Range and cone.
    let mut lr = l.clone();
    lr.radius = Some(5.0);
    assert_eq!(r.shadow_at(DVec3::new(2.0, 0.0, 0.0), up, &lr), LightState::Lit);
    assert_eq!(r.shadow_at(DVec3::new(4.0, 0.0, 0.0), up, &lr), LightState::OutOfRange);
    let mut sp = l.clone();
    sp.kind = LightKind::Spot;
    sp.direction = Vec3::NEG_Y;
    sp.cone_deg = 90.0; // half angle 45 deg: lit disc of radius 4 on the plane
    assert_eq!(r.shadow_at(DVec3::new(3.5, 0.0, 0.0), up, &sp), LightState::Lit);
    assert_eq!(r.shadow_at(DVec3::new(4.5, 0.0, 0.0), up, &sp), LightState::OutsideCone);
    assert_eq!(r.shadow_at(DVec3::new(0.5, 0.0, 0.0), up, &sp), LightState::Shadowed);
}

#[test]
fn reference_box_render_top_view() {
    let s = box_scene();
    let r = Reference::from_scene(&s);
    let (w, h) = (128, 128);
    let img = r.render(&s.camera, &s.lights, w, h);
    let (mut shadowed, mut lit, mut boxpx) = (0, 0, 0);
    for y in 0..h {
        for x in 0..w {
            let p = img.pixel(x, y);
            assert!(p.hit, "plane fills the view");
            let st = img.state(x, y, 0);
            if p.mesh == 1 {
                boxpx += 1;
                assert!((p.position.y - 2.0).abs() < 1e-5, "top view sees the box top");
                assert_eq!(st, LightState::Lit);
                continue;
            }
            assert!(p.position.y.abs() < 1e-5 && (p.normal - Vec3::Y).length() < 1e-6);
            let m = p.position.x.abs().max(p.position.z.abs());
            if m < 0.97 {
                assert_eq!(st, LightState::Shadowed, "{:?}", p.position);
                shadowed += 1;
            } else if m > 1.03 {
                assert_eq!(st, LightState::Lit, "{:?}", p.position);
                lit += 1;
            }
        }
    }
    assert!(shadowed > 100 && lit > 1000 && boxpx > 100, "{shadowed} {lit} {boxpx}");
    // Image orientation: row 0 is the top; up = -Z, so row 0 sees negative z, and x grows
    // to the right.
    assert!(img.pixel(0, 0).position.z < 0.0 && img.pixel(0, 0).position.x < 0.0);
    assert!(img.pixel(w - 1, h - 1).position.z > 0.0 && img.pixel(w - 1, h - 1).position.x > 0.0);
    // The reference agrees with itself.
    let m = metrics::compare(&img.mask(0), &img, 0, 1).unwrap();
    assert_eq!(m.mismatches_outside_band, 0);
}

#[test]
fn reference_non_caster_does_not_shadow() {
    let mut s = box_scene();
    s.meshes[1].casts_shadow = false;
    let r = Reference::from_scene(&s);
    assert_eq!(r.shadow_at(DVec3::ZERO, DVec3::Y, &s.lights[0]), LightState::Lit);
}

fn sphere_scene(dir: Vec3) -> Scene {
    scene(vec![(plane(10.0), true), (icosphere(Vec3::new(0.0, 3.0, 0.0), 1.0, 4), true)], vec![dir_light(dir)], top_camera())
}

#[test]
fn reference_sphere_disc_shadow() {
    let s = sphere_scene(Vec3::NEG_Y);
    let r = Reference::from_scene(&s);
    let l = &s.lights[0];
    // Icosphere level 4: inscribed, max radial error ~ 1 - cos(edge angle) < 0.5%.
    for k in 0..32 {
        let a = k as f64 * std::f64::consts::TAU / 32.0;
        let d = DVec3::new(a.cos(), 0.0, a.sin());
        assert_eq!(r.shadow_at(d * 0.98, DVec3::Y, l), LightState::Shadowed, "angle {a}");
        assert_eq!(r.shadow_at(d * 1.01, DVec3::Y, l), LightState::Lit, "angle {a}");
    }
    // Rendered: the fraction of shadowed plane pixels matches the disc area.
    let img = r.render(&s.camera, &s.lights, 96, 96);
    let mut area_ok = 0;
    for y in 0..96 {
        for x in 0..96 {
            let p = img.pixel(x, y);
            let st = img.state(x, y, 0);
            if p.mesh == 0 {
                let rr = (p.position.x * p.position.x + p.position.z * p.position.z).sqrt();
                if rr < 0.97 {
                    unreachable!("the sphere hides the disc from above");
                } else if rr > 1.02 {
                    assert_eq!(st, LightState::Lit);
                    area_ok += 1;
                }
            } else {
                // Upper hemisphere faces the light, lower one is back-facing (never seen).
                assert!(matches!(st, LightState::Lit | LightState::Ambiguous), "{st:?}");
            }
        }
    }
    assert!(area_ok > 1000);

    // Oblique light: the shadow is an ellipse centred at x = 1.5 with semi-axes
    // sqrt(1.25) along x and 1 along z.
    let s = sphere_scene(Vec3::new(0.5, -1.0, 0.0));
    let r = Reference::from_scene(&s);
    let l = &s.lights[0];
    let (ax, az) = (1.25f64.sqrt(), 1.0);
    for k in 0..32 {
        let a = k as f64 * std::f64::consts::TAU / 32.0;
        let e = |f: f64| DVec3::new(1.5 + f * ax * a.cos(), 0.0, f * az * a.sin());
        assert_eq!(r.shadow_at(e(0.98), DVec3::Y, l), LightState::Shadowed, "angle {a}");
        assert_eq!(r.shadow_at(e(1.01), DVec3::Y, l), LightState::Lit, "angle {a}");
    }
}

fn dump_from(img: &RefImage, s: &Scene) -> Dump {
    let r_tris: Vec<[Vec3; 3]> =
        s.meshes.iter().filter(|m| m.casts_shadow).flat_map(|m| (0..m.mesh.triangles.len()).map(move |t| m.mesh.triangle(t))).collect();
    Dump {
        width: img.width,
        height: img.height,
        camera_pos: s.camera.eye,
        lights: s.lights.iter().map(DumpLight::from_light).collect(),
        triangles: r_tris,
        positions: img.positions_f32(),
        normals: img.normals_f32(),
        shadow: (0..img.light_count).map(|k| img.mask(k)).collect(),
        spheres: s.spheres.iter().filter(|s| s.casts_shadow).map(|s| s.sphere).collect(),
        camera: Some(s.camera.clone()),
        extra: Default::default(),
    }
}

fn tmpdir(name: &str) -> std::path::PathBuf {
    let d = std::env::temp_dir().join(format!("umbrage-ref-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

#[test]
fn reference_dump_round_trip_and_check() {
    let mut s = box_scene();
    s.camera = Camera { eye: Vec3::new(3.0, 6.0, 5.0), target: Vec3::ZERO, up: Vec3::Y, fov_y_deg: 50.0, near: 0.1 };
    s.lights.push(dir_light(Vec3::new(-0.3, -1.0, 0.2)));
    let r = Reference::from_scene(&s);
    let img = r.render(&s.camera, &s.lights, 64, 48);
    let mut dump = dump_from(&img, &s);
    dump.extra.insert("method".into(), serde_json::json!("zfail"));
    let dir = tmpdir("rt");
    write_dump(&dir, &dump).unwrap();
    let back = read_dump(&dir).unwrap();
    // NaN != NaN: compare bitwise.
    let bits = |v: &[f32]| v.iter().map(|f| f.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&back.positions), bits(&dump.positions));
    assert_eq!(bits(&back.normals), bits(&dump.normals));
    assert_eq!(back.triangles, dump.triangles);
    assert_eq!(back.shadow, dump.shadow);
    assert_eq!(back.lights, dump.lights);
    assert_eq!(back.camera, dump.camera);
    assert_eq!(back.extra, dump.extra);
    assert_eq!((back.width, back.height, back.camera_pos), (dump.width, dump.height, dump.camera_pos));

    // The check at the dump's own positions passes.
    let rep = check_dump(&dir, 1).unwrap();
    assert_eq!(rep.lights.len(), 2);
    assert!(rep.passed(0.0), "{rep}");
    let _ = format!("{rep}");
    let _ = serde_json::to_string(&rep).unwrap();

    // A wrong block of pixels far from any edge is found.
    let mut bad = dump.clone();
    let mut flipped = 0;
    for i in 0..64 * 48 {
        if img.states[i * 2] == LightState::Lit && (i % 64) < 20 && bad.shadow[0][i] == 255 {
            bad.shadow[0][i] = 0;
            flipped += 1;
        }
    }
    assert!(flipped > 0);
    write_dump(&dir, &bad).unwrap();
    let rep = check_dump(&dir, 1).unwrap();
    assert!(!rep.passed(0.01), "{rep}");
    assert!(rep.lights[0].metrics.shadowed_but_ref_lit > 0);
    assert_eq!(rep.lights[1].metrics.mismatches_outside_band, 0);

    // Minimal frame.json (required keys only) is accepted.
    std::fs::write(
        dir.join("frame.json"),
        r#"{"width": 64, "height": 48, "camera_pos": [3, 6, 5], "lights": [{"position": [0, 4, 0, 1]}, {"position": [0.3, 1.0, -0.2, 0]}]}"#,
    )
    .unwrap();
    write_shadows(&dir, &dump);
    let d = read_dump(&dir).unwrap();
    assert_eq!(d.lights[0].to_light().unwrap().kind, LightKind::Point);
    assert_eq!(d.lights[1].to_light().unwrap().kind, LightKind::Directional);
    assert!(check_dump(&dir, 1).unwrap().passed(0.0));
    let _ = std::fs::remove_dir_all(&dir);
}

fn write_shadows(dir: &std::path::Path, d: &Dump) {
    for (k, s) in d.shadow.iter().enumerate() {
        image::GrayImage::from_raw(d.width, d.height, s.clone()).unwrap().save(dir.join(format!("shadow_{k}.png"))).unwrap();
    }
}

#[test]
fn reference_read_dump_errors() {
    let s = box_scene();
    let r = Reference::from_scene(&s);
    let img = r.render(&s.camera, &s.lights, 8, 6);
    let dump = dump_from(&img, &s);
    let dir = tmpdir("err");
    let fresh = || {
        let _ = std::fs::remove_dir_all(&dir);
        write_dump(&dir, &dump).unwrap();
        read_dump(&dir).unwrap();
    };
    let err = |what: &str| {
        let e = read_dump(&dir).expect_err(what).to_string();
        eprintln!("{what}: {e}");
        e
    };
    assert!(read_dump(dir.join("nope")).is_err());
    fresh();
    std::fs::remove_file(dir.join("frame.json")).unwrap();
    assert!(err("missing frame.json").contains("frame.json"));
    fresh();
    std::fs::write(dir.join("frame.json"), "{\"width\": 8,").unwrap();
    assert!(err("bad json").contains("frame.json"));
    fresh();
    std::fs::write(dir.join("frame.json"), r#"{"width": 8, "height": 6, "lights": []}"#).unwrap();
    assert!(err("missing key").contains("camera_pos"));
    fresh();
    std::fs::write(dir.join("positions.f32"), [0u8; 10]).unwrap();
    assert!(err("short positions").contains("positions.f32"));
    fresh();
    std::fs::remove_file(dir.join("normals.f32")).unwrap();
    assert!(err("missing normals").contains("normals.f32"));
    fresh();
    std::fs::remove_file(dir.join("shadow_0.png")).unwrap();
    assert!(err("missing shadow").contains("shadow_0"));
    fresh();
    std::fs::copy(dir.join("shadow_0.png"), dir.join("shadow_1.png")).unwrap();
    assert!(err("extra shadow").contains("shadow_1"));
    fresh();
    image::GrayImage::new(3, 3).save(dir.join("shadow_0.png")).unwrap();
    assert!(err("wrong png size").contains("3x3"));
    fresh();
    std::fs::write(dir.join("shadow_0.png"), b"not a png").unwrap();
    assert!(err("corrupt png").contains("shadow_0"));
    fresh();
    std::fs::write(dir.join("world.obj"), "v 0 0 0\nv 1 0 0\nf 1 2 3\n").unwrap();
    assert!(err("bad obj index").contains("world.obj:3"));
    fresh();
    std::fs::write(dir.join("world.obj"), "v 0 zero 0\n").unwrap();
    assert!(err("bad obj vertex").contains("world.obj:1"));
    fresh();
    std::fs::remove_file(dir.join("world.obj")).unwrap();
    assert!(err("missing obj").contains("world.obj"));
    fresh();
    std::fs::write(dir.join("frame.json"), r#"{"width": 8, "height": 6, "camera_pos": [0,0,0], "lights": [{"position": [0,0,0,0]}]}"#)
        .unwrap();
    assert!(err("zero directional").contains("light 0"));
    // Writing an inconsistent dump is refused too.
    let mut bad = dump.clone();
    bad.normals.pop();
    assert!(write_dump(&dir, &bad).is_err());
    let mut bad = dump.clone();
    bad.shadow.clear();
    assert!(write_dump(&dir, &bad).is_err());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn reference_metrics_band() {
    let (w, h) = (20usize, 10usize);
    // Left half lit, right half shadowed, last row background, one ambiguous pixel.
    let mut states = vec![LightState::Lit; w * h];
    for y in 0..h {
        for x in 10..w {
            states[y * w + x] = LightState::Shadowed;
        }
    }
    for x in 0..w {
        states[(h - 1) * w + x] = LightState::Background;
    }
    states[2 * w + 3] = LightState::Ambiguous;
    let edges = shadow_edges(&states, w, h);
    assert!(edges[9] && edges[10] && !edges[8] && !edges[11]);
    assert!(edges[2 * w + 3], "ambiguous pixels are edges");
    let band = metrics::band_mask(&states, &vec![false; w * h], w, h, 2);
    // Chebyshev distance 2 from x = 9/10: x in 7..=12.
    assert!(band[7] && band[12] && !band[6] && !band[13]);
    // Dilation is a square.
    let mut one = vec![false; 25];
    one[12] = true;
    let d = dilate(&one, 5, 5, 1);
    assert_eq!(d.iter().filter(|&&b| b).count(), 9);
    assert!(d[6] && d[18] && !d[2]);

    let mut mask: Vec<u8> = states.iter().map(|s| s.mask_value()).collect();
    mask[2 * w + 3] = 0; // ambiguous: never a mismatch
    mask[3 * w + 10] = 255; // edge pixel wrong: in band
    mask[5 * w + 1] = 0; // far from the edge: outside band
    mask[6 * w + 18] = 255; // far: outside band
    mask[7 * w + 15] = 128; // background mismatch outside band
    let m = compare_states(&mask, &states, &band);
    assert_eq!(m.pixels, 200);
    assert_eq!(m.ambiguous, 1);
    assert_eq!(m.compared, 200 - 20 - 1);
    assert_eq!(m.lit_but_ref_shadowed, 2);
    assert_eq!(m.shadowed_but_ref_lit, 1);
    assert_eq!(m.background_mismatch, 1);
    assert_eq!(m.mismatches_outside_band, 3);
    assert!((m.fraction_outside_band - 3.0 / 179.0).abs() < 1e-12);
    assert!(m.band_pixels >= 6 * 9);
    // The listed pixels are the ones counted, in row order, up to the limit.
    assert_eq!(metrics::mismatches_outside_band(&mask, &states, &band, 10), vec![5 * w + 1, 6 * w + 18, 7 * w + 15]);
    assert_eq!(metrics::mismatches_outside_band(&mask, &states, &band, 2), vec![5 * w + 1, 6 * w + 18]);
    // Geometric discontinuities widen the band.
    let geo: Vec<metrics::GeoSample> = (0..w * h)
        .map(|i| {
            if i / w == h - 1 {
                metrics::GeoSample::Background
            } else {
                let n = if i % w < 4 { DVec3::X } else { DVec3::Y };
                metrics::GeoSample::Surface { position: DVec3::ZERO, normal: n, depth: 1.0, mesh: Some(0) }
            }
        })
        .collect();
    let ge = metrics::geometry_edges(&geo, w, h);
    assert!(ge[3] && ge[4] && !ge[5] && ge[(h - 2) * w + 15] && ge[(h - 1) * w + 15]);
    let band2 = metrics::band_mask(&states, &ge, w, h, 2);
    let m2 = compare_states(&mask, &states, &band2);
    // (1,5) is now near the normal jump at x = 3/4; (18,6) and (15,7) near the background
    // row 9 (edge rows 8 and 9).
    assert!(band2[5 * w + 1] && band2[6 * w + 18] && band2[7 * w + 15] && !band2[4 * w + 18]);
    assert_eq!(m2.mismatches_outside_band, 0, "{m2:?}");
    assert!(m2.band_pixels > m.band_pixels);
}

#[test]
fn reference_homogeneous_light_round_trip() {
    let l = dir_light(Vec3::new(1.0, -2.0, 0.5));
    let d = DumpLight::homogeneous(l.homogeneous());
    let back = d.to_light().unwrap();
    assert!((back.direction - l.direction).length() < 1e-6);
    let p = point_light(Vec3::new(1.0, 2.0, 3.0));
    assert_eq!(DumpLight::homogeneous(Vec4::new(2.0, 4.0, 6.0, 2.0)).to_light().unwrap().position, p.position);
}

/// Timing check (run with `cargo test --lib reference_perf -- --ignored --nocapture`):
/// ~100k triangles, 512x512, two lights.
#[test]
#[ignore = "timing: ~100k triangles at 512x512; run with -- --ignored --nocapture"]
fn reference_perf_512() {
    let mut meshes = vec![(plane(10.0), true)];
    for k in 0..5 {
        let c = Vec3::new(-4.0 + 2.0 * k as f32, 1.5, (k as f32 - 2.0) * 0.7);
        meshes.push((icosphere(c, 0.9, 5), true));
    }
    let cam = Camera { eye: Vec3::new(0.0, 7.0, 9.0), target: Vec3::ZERO, up: Vec3::Y, fov_y_deg: 60.0, near: 0.1 };
    let s = scene(meshes, vec![point_light(Vec3::new(1.0, 6.0, 1.0)), dir_light(Vec3::new(0.3, -1.0, -0.4))], cam);
    let t0 = std::time::Instant::now();
    let r = Reference::from_scene(&s);
    let t1 = std::time::Instant::now();
    let img = r.render(&s.camera, &s.lights, 512, 512);
    let t2 = std::time::Instant::now();
    let amb = img.states.iter().filter(|s| **s == LightState::Ambiguous).count();
    let sh = img.states.iter().filter(|s| **s == LightState::Shadowed).count();
    eprintln!("{} tris: build {:?}, render 512x512x2 lights {:?}; shadowed {sh}, ambiguous {amb}", r.triangle_count(), t1 - t0, t2 - t1);
}
