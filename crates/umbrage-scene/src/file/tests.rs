//! Scene-file tests: every built-in scene, the conventions, and the error messages.

use crate::{builtin_names, load, load_str, shapes, LightKind};
use glam::{Mat4, Vec3};
use std::path::Path;
use umbrage::error::Error;

pub(super) const CAM: &str = "[camera]\neye = [0, 2, 5]\ntarget = [0, 0, 0]\n";

fn err(toml: &str) -> String {
    let r = std::panic::catch_unwind(|| load_str(toml, "bad.toml", Path::new(".")));
    match r {
        Ok(Ok(_)) => panic!("expected an error for:\n{toml}"),
        Ok(Err(e)) => e.to_string(),
        Err(_) => panic!("panicked on:\n{toml}"),
    }
}

pub(super) fn check(toml: &str, wants: &[&str]) {
    let e = err(toml);
    assert!(e.contains("bad.toml"), "error does not name the file: {e}");
    for w in wants {
        assert!(e.contains(w), "error '{e}' lacks '{w}'");
    }
}

#[test]
fn every_builtin_loads_and_validates() {
    let names = builtin_names();
    for want in ["default", "stairs", "cubes", "spheres", "hard/eye_in_volume", "hard/staircase_300", "hard/look_at_light"] {
        assert!(names.contains(&want), "{want} missing");
    }
    assert!(names.len() >= 4 + 15);
    for name in names {
        let s = load(name).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert!(!s.lights.is_empty(), "{name}: no lights");
        // analytic/sphere_only is made of spheres only (its ground is a sphere).
        if name != "analytic/sphere_only" {
            assert!(!s.meshes.is_empty(), "{name}: no meshes");
            assert!(s.meshes.iter().any(|m| m.mesh.triangles.len() == 2), "{name}: no floor");
        } else {
            assert!(s.meshes.is_empty() && s.spheres.len() >= 2, "{name}: spheres only");
        }
        for m in &s.meshes {
            m.mesh.validate(&m.name).unwrap();
            assert!(m.transform.determinant() > 0.0);
            // hard/open_casters is made of open and non-manifold meshes on purpose
            if m.mesh.triangles.len() > 2 && name != "hard/open_casters" {
                shapes::tests_support::assert_closed_outward(&m.mesh, &format!("{name}/{}", m.name));
            }
        }
        for l in &s.lights {
            assert!(l.position != s.camera.eye, "{name}: light at the eye");
            assert!((l.direction.length() - 1.0).abs() < 1e-5);
        }
    }
}

/// Does the segment a-b pass through the box?
fn seg_hits(a: Vec3, b: Vec3, bx: umbrage::geom::Aabb) -> bool {
    let (mut t0, mut t1) = (0.0f32, 1.0f32);
    let d = b - a;
    for k in 0..3 {
        if d[k].abs() < 1e-12 {
            if a[k] < bx.min[k] || a[k] > bx.max[k] {
                return false;
            }
        } else {
            let (u, v) = ((bx.min[k] - a[k]) / d[k], (bx.max[k] - a[k]) / d[k]);
            t0 = t0.max(u.min(v));
            t1 = t1.min(u.max(v));
        }
    }
    t0 <= t1
}

fn blockers(name: &str, p: Vec3) -> usize {
    let s = load(name).unwrap();
    let l = s.lights[0].position;
    s.meshes.iter().filter(|m| m.mesh.triangles.len() > 2).filter(|m| seg_hits(p, l, m.world_bounds())).count()
}

#[test]
fn hard_cases_are_exercised() {
    let eye = |n: &str| load(n).unwrap().camera.eye;
    assert_eq!(blockers("hard/eye_in_volume", eye("hard/eye_in_volume")), 1);
    assert_eq!(blockers("hard/eye_in_two_volumes", eye("hard/eye_in_two_volumes")), 2);
    assert_eq!(blockers("hard/look_at_light", eye("hard/look_at_light")), 1);
    // near_plane_cut: eye just outside, a point of the near rectangle 0.2 to its left inside
    let e = eye("hard/near_plane_cut");
    assert_eq!(blockers("hard/near_plane_cut", e), 0);
    assert_eq!(blockers("hard/near_plane_cut", e - Vec3::new(0.2, 0.0, 0.0)), 1);
    // staircase_300: a floor point below all 300 slabs
    let s = load("hard/staircase_300").unwrap();
    let l = s.lights[0].position;
    let m = &s.meshes[1];
    let hits = (0..300)
        .filter(|i| {
            let tri = &m.mesh.positions[i * 8..i * 8 + 8];
            let b = umbrage::geom::Aabb::from_points(tri.iter()).transformed(&m.transform);
            seg_hits(Vec3::new(0.5, 0.0, 0.0), l, b)
        })
        .count();
    assert_eq!(hits, 300);
}

#[test]
fn default_scene_content() {
    let s = load("default").unwrap();
    assert_eq!(s.name, "default");
    assert!(s.lights.len() >= 2);
    let kinds: Vec<_> = s.lights.iter().map(|l| l.kind).collect();
    assert!(kinds.contains(&LightKind::Point) && kinds.contains(&LightKind::Spot));
    assert!(s.meshes.len() >= 7);
}

#[test]
fn hard_cases_geometry() {
    // eye inside the caster's shadow column, light inside the torus' bounds, etc.
    let s = load("hard/light_inside_bounds").unwrap();
    let b = s.meshes[1].world_bounds();
    assert!(b.contains(s.lights[0].position));
    let s = load("hard/light_in_face_plane").unwrap();
    let top = s.meshes[1].world_bounds().max.y;
    assert_eq!(top, s.lights[0].position.y);
    let s = load("hard/staircase_300").unwrap();
    assert_eq!(s.meshes[1].mesh.triangles.len(), 300 * 12);
    let s = load("hard/zero_area").unwrap();
    let m = &s.meshes[1].mesh;
    assert!((0..m.triangles.len()).filter(|&t| m.face_normal(t).length() == 0.0).count() == 2);
    let s = load("hard/grazing_directional").unwrap();
    let d = s.lights[0].direction;
    assert!((d.y.asin().to_degrees() + 2.0).abs() < 1e-3);
}

#[test]
fn file_with_obj_and_mirror() {
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/data/scene_with_obj.toml");
    let s = load(p.to_str().unwrap()).unwrap();
    assert_eq!(s.name, "scene_with_obj");
    let m = &s.meshes[0];
    assert_eq!(m.name, "mesh0-cube");
    assert!(m.transform.determinant() < 0.0);
    // world-space triangles are still outward
    let w = m.mesh.transformed(&Mat4::IDENTITY);
    let mut world = w.clone();
    world.positions = w.positions.iter().map(|p| m.transform.transform_point3(*p)).collect();
    assert!(shapes::signed_volume(&world) > 0.0);
}

#[test]
fn transform_conventions() {
    let t = format!("{CAM}[[mesh]]\nshape = \"box\"\ntranslate = [1, 2, 3]\nrotate_deg = [10, 20, 30]\nscale = [2, 3, 4]\n");
    let s = load_str(&t, "t.toml", Path::new(".")).unwrap();
    let r = Mat4::from_euler(glam::EulerRot::ZYX, 30f32.to_radians(), 20f32.to_radians(), 10f32.to_radians());
    let want = Mat4::from_translation(Vec3::new(1.0, 2.0, 3.0)) * r * Mat4::from_scale(Vec3::new(2.0, 3.0, 4.0));
    assert!(s.meshes[0].transform.abs_diff_eq(want, 1e-5));
    assert_eq!(s.ambient, Vec3::splat(0.08));
    assert_eq!(s.camera.fov_y_deg, 60.0);
    assert_eq!(s.meshes[0].color, Vec3::splat(0.8));
    // mirrored box: object-space winding swapped, world outward
    let t = format!("{CAM}[[mesh]]\nshape = \"box\"\nscale = [1, -1, 1]\n");
    let s = load_str(&t, "t.toml", Path::new(".")).unwrap();
    let m = &s.meshes[0];
    assert!(shapes::signed_volume(&m.mesh) < 0.0);
    let mut w = m.mesh.clone();
    w.positions = w.positions.iter().map(|p| m.transform.transform_point3(*p)).collect();
    assert!(shapes::signed_volume(&w) > 0.0);
    // spot direction normalised
    let t = format!("{CAM}[[light]]\nkind = \"spot\"\nposition = [0, 3, 0]\ndirection = [0, -5, 0]\n");
    let s = load_str(&t, "t.toml", Path::new(".")).unwrap();
    assert_eq!(s.lights[0].direction, Vec3::NEG_Y);
    assert_eq!(s.lights[0].cone_deg, 45.0);
}

#[test]
fn syntax_error_has_line() {
    check(&format!("{CAM}\n[[light]\nkind = \"point\"\n"), &["bad.toml:5"]);
    check("name = \"x\"\nambient = [1, 2\n", &["bad.toml:2"]);
}

#[test]
fn unknown_keys() {
    check(&format!("{CAM}fov = 50\n"), &["bad.toml:4", "fov"]);
    check(&format!("{CAM}[[mesh]]\nshape = \"box\"\ncolour = [1, 1, 1]\n"), &["bad.toml:6", "colour"]);
    check(&format!("colour = 1\n{CAM}"), &["bad.toml:1", "colour"]);
    check(&format!("{CAM}[[mesh]]\nshape = \"box\"\nrings = 3\n"), &["bad.toml:6", "rings"]);
    check(&format!("{CAM}[[light]]\nkind = \"point\"\nposition = [0, 1, 0]\ncone_deg = 30\n"), &["bad.toml:7", "cone_deg"]);
}

#[test]
fn wrong_types() {
    check(&format!("{CAM}[[mesh]]\nshape = \"box\"\nsize = \"big\"\n"), &["bad.toml:6"]);
    check(&format!("{CAM}[[mesh]]\nshape = \"sphere\"\nsegments = 2.5\n"), &["bad.toml:6"]);
    check(&format!("{CAM}[[mesh]]\nshape = \"sphere\"\nsegments = -3\n"), &["bad.toml:6", "segments"]);
    check(&format!("{CAM}[[mesh]]\nshape = \"box\"\nsize = [1, 2]\n"), &["bad.toml:6", "size"]);
    check("[camera]\neye = [0, 2]\ntarget = [0, 0, 0]\n", &["bad.toml:2"]);
    check("[camera]\neye = \"up\"\ntarget = [0, 0, 0]\n", &["bad.toml:2"]);
    check("name = 3\n", &["bad.toml:1"]);
    check("", &["bad.toml", "camera"]);
}

#[test]
fn non_finite_numbers() {
    check("[camera]\neye = [0, nan, 5]\ntarget = [0, 0, 0]\n", &["bad.toml:2", "eye", "non-finite"]);
    check(&format!("{CAM}[[light]]\nkind = \"point\"\nposition = [0, inf, 0]\n"), &["bad.toml:6", "position"]);
    check(&format!("{CAM}[[mesh]]\nshape = \"sphere\"\nradius = -inf\n"), &["bad.toml:6", "radius"]);
    check(&format!("{CAM}[[mesh]]\nshape = \"box\"\ntranslate = [1e39, 0, 0]\n"), &["bad.toml:6", "translate"]);
    check(&format!("ambient = [nan, 0, 0]\n{CAM}"), &["bad.toml:1", "ambient"]);
    check(&format!("{CAM}[[mesh]]\nshape = \"box\"\nscale = nan\n"), &["bad.toml:6", "scale"]);
}

#[test]
fn unknown_names() {
    let e = load_str(&format!("{CAM}[[mesh]]\nshape = \"hexagon\"\n"), "bad.toml", Path::new(".")).unwrap_err();
    assert!(matches!(e, Error::UnknownName { what: "shape", .. }));
    let e = e.to_string();
    assert!(e.contains("hexagon") && e.contains("torus") && e.contains("bad.toml:5"), "{e}");
    let e = load_str(&format!("{CAM}[[light]]\nkind = \"laser\"\nposition = [0, 1, 0]\n"), "bad.toml", Path::new(".")).unwrap_err();
    assert!(matches!(e, Error::UnknownName { what: "light kind", .. }));
    assert!(e.to_string().contains("bad.toml:5"));
    let e = load("no_such_scene").unwrap_err();
    assert!(matches!(e, Error::UnknownName { what: "scene", .. }));
    let e = e.to_string();
    assert!(e.contains("default") && e.contains("hard/eye_in_volume"), "{e}");
    assert!(matches!(load("hard/nope").unwrap_err(), Error::UnknownName { .. }));
}

#[test]
fn missing_files() {
    let e = load("missing_dir/missing.toml").unwrap_err().to_string();
    assert!(e.contains("missing_dir/missing.toml"), "{e}");
    let e = err(&format!("{CAM}[[mesh]]\nobj = \"nowhere.obj\"\n"));
    assert!(e.contains("bad.toml:5") && e.contains("nowhere.obj"), "{e}");
}

#[test]
fn bad_obj_through_scene() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/data");
    for (f, want) in [("malformed.obj", "malformed"), ("nan_vertex.obj", "vertex 3"), ("no_faces.obj", "empty")] {
        let t = format!("{CAM}[[mesh]]\nobj = \"{f}\"\n");
        let e = load_str(&t, "bad.toml", &dir).unwrap_err().to_string();
        assert!(e.contains("bad.toml:5") && e.contains(f) && e.contains(want), "{e}");
    }
}

#[test]
fn invalid_values() {
    check("[camera]\neye = [0, 0, 0]\ntarget = [0, 0, 0]\n", &["bad.toml:3", "target"]);
    check("[camera]\neye = [0, 2, 0]\ntarget = [0, 0, 0]\n", &["bad.toml", "up"]);
    check("[camera]\neye = [0, 2, 5]\ntarget = [0, 0, 0]\nfov_y_deg = 180\n", &["bad.toml:4", "fov_y_deg"]);
    check("[camera]\neye = [0, 2, 5]\ntarget = [0, 0, 0]\nnear = 0\n", &["bad.toml:4", "near"]);
    check(&format!("{CAM}[[light]]\nkind = \"directional\"\ndirection = [0, 0, 0]\n"), &["bad.toml:6", "direction"]);
    check(&format!("{CAM}[[light]]\nkind = \"spot\"\ndirection = [0, -1, 0]\n"), &["bad.toml:4", "position"]);
    check(&format!("{CAM}[[light]]\nkind = \"point\"\n"), &["bad.toml:4", "position"]);
    check(&format!("{CAM}[[light]]\nkind = \"point\"\nposition = [0, 2, 5]\n"), &["bad.toml:6", "eye"]);
    check(&format!("{CAM}[[light]]\nkind = \"point\"\nposition = [0, 2, 1]\nradius = 0\n"), &["bad.toml:7", "radius"]);
    check(
        &format!("{CAM}[[light]]\nkind = \"spot\"\nposition = [0, 2, 1]\ndirection = [0, -1, 0]\ncone_deg = 180\n"),
        &["bad.toml:8", "cone_deg"],
    );
    check(&format!("{CAM}[[mesh]]\nshape = \"box\"\nopacity = 2\n"), &["bad.toml:6", "opacity"]);
    check(&format!("{CAM}[[mesh]]\nshape = \"box\"\nscale = [1, 0, 1]\n"), &["bad.toml:6", "scale"]);
    check(&format!("{CAM}[[mesh]]\nshape = \"box\"\nobj = \"a.obj\"\n"), &["bad.toml:4", "exactly one"]);
    check(&format!("{CAM}[[mesh]]\nname = \"x\"\n"), &["bad.toml:4", "exactly one"]);
    check(&format!("{CAM}[[mesh]]\nshape = \"torus\"\nminor_radius = 0.6\n"), &["bad.toml:6", "minor_radius"]);
    check(&format!("{CAM}[[mesh]]\nshape = \"cube_grid\"\ncount = [0, 2]\n"), &["bad.toml:6", "count"]);
    check(&format!("{CAM}[[mesh]]\nshape = \"sphere\"\nsegments = 100000000000\n"), &["bad.toml:6", "segments"]);
    check(&format!("{CAM}[[mesh]]\nshape = \"box\"\ncolor = [1, -1, 1]\n"), &["bad.toml:6", "color"]);
}
