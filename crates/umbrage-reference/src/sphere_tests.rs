//! The reference's exact spheres: camera rays see the analytic surface, shadow rays stop at it,
//! and frame dumps carry them.

use super::*;
use glam::{DVec3, Mat4, Vec3};
use umbrage::geom::{Mesh, Sphere};
use umbrage_scene::{Camera, Light, LightKind, Scene, SceneMesh, SceneSphere};

fn floor_and_ball() -> Scene {
    let floor = Mesh::new(
        vec![Vec3::new(-5.0, 0.0, -5.0), Vec3::new(5.0, 0.0, -5.0), Vec3::new(5.0, 0.0, 5.0), Vec3::new(-5.0, 0.0, 5.0)],
        vec![[0, 2, 1], [0, 3, 2]],
    );
    Scene {
        name: "ball".into(),
        camera: Camera { eye: Vec3::new(0.0, 8.0, 0.01), target: Vec3::ZERO, up: Vec3::NEG_Z, fov_y_deg: 50.0, near: 0.1 },
        lights: vec![Light {
            kind: LightKind::Point,
            position: Vec3::new(0.0, 6.0, 0.0),
            direction: Vec3::NEG_Y,
            color: Vec3::ONE,
            intensity: 1.0,
            radius: None,
            cone_deg: 45.0,
            area: None,
        }],
        meshes: vec![SceneMesh {
            name: "floor".into(),
            mesh: floor,
            transform: Mat4::IDENTITY,
            color: Vec3::ONE,
            opacity: 1.0,
            casts_shadow: false,
        }],
        ambient: Vec3::splat(0.08),
        spheres: vec![SceneSphere {
            name: "ball".into(),
            sphere: Sphere { center: DVec3::new(0.0, 2.0, 0.0), radius: 1.0 },
            color: Vec3::ONE,
            opacity: 1.0,
            casts_shadow: true,
            segments: None,
        }],
    }
}

#[test]
fn shadow_rays_stop_at_the_exact_sphere() {
    let s = floor_and_ball();
    let r = Reference::from_scene(&s);
    let l = &s.lights[0];
    // The exact shadow on y = 0: the tangent cone from (0,6,0) around the unit ball at y = 2,
    // sin a = 1/4, radius 6 tan a = 6 / sqrt(15) = 1.5492 (a tessellated ball would differ).
    let edge = 6.0 / 15f64.sqrt();
    let at = |x: f64| r.shadow_at_radius(DVec3::new(x, 0.0, 0.0), DVec3::Y, l, 0.0);
    assert_eq!(at(edge - 1e-3), LightState::Shadowed);
    assert_eq!(at(edge + 1e-3), LightState::Lit);
    assert_eq!(at(0.5), LightState::Shadowed);
    // The ball's own top is lit, its underside faces away.
    assert_eq!(r.shadow_at(DVec3::new(0.0, 3.0, 0.0), DVec3::Y, l), LightState::Lit);
    assert_eq!(r.shadow_at(DVec3::new(0.0, 1.0, 0.0), DVec3::NEG_Y, l), LightState::BackFacing);
}

#[test]
fn camera_rays_see_the_exact_sphere() {
    let s = floor_and_ball();
    let img = Reference::from_scene(&s).render(&s.camera, &s.lights, 64, 64);
    let c = img.pixel(32, 32);
    // Straight down from y = 8 onto the ball's top at y = 3 (pixel centres are half a pixel off).
    assert!((c.position.y - 3.0).abs() < 5e-3, "{:?}", c.position);
    assert!(c.normal.y > 0.99);
    assert_eq!(c.mesh, 1, "spheres are numbered after the meshes");
    let on_sphere = img.pixels.iter().filter(|p| p.mesh == 1).count();
    assert!(on_sphere > 100);
    for p in img.pixels.iter().filter(|p| p.mesh == 1) {
        let d = (p.position.as_dvec3() - DVec3::new(0.0, 2.0, 0.0)).length();
        assert!((d - 1.0).abs() < 1e-6, "not on the sphere: {d}");
    }
}

#[test]
fn dumps_carry_the_spheres_and_check_against_them() {
    let mut s = floor_and_ball();
    s.camera = Camera { eye: Vec3::new(4.0, 5.0, 4.0), target: Vec3::new(0.0, 0.5, 0.0), ..s.camera };
    s.camera.up = Vec3::Y;
    let img = Reference::from_scene(&s).render(&s.camera, &s.lights, 96, 96);
    let dump = Dump {
        width: 96,
        height: 96,
        camera_pos: s.camera.eye,
        lights: s.lights.iter().map(DumpLight::from_light).collect(),
        triangles: Vec::new(),
        positions: img.positions_f32(),
        normals: img.normals_f32(),
        shadow: vec![img.mask(0)],
        spheres: vec![s.spheres[0].sphere],
        camera: Some(s.camera.clone()),
        extra: Default::default(),
    };
    let dir = std::env::temp_dir().join(format!("umbrage-ref-{}-spheres", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    write_dump(&dir, &dump).unwrap();
    let json = std::fs::read_to_string(dir.join("frame.json")).unwrap();
    let v: serde_json::Value = serde_json::from_str(&json).unwrap();
    assert_eq!(v["spheres"][0]["center"], serde_json::json!([0.0, 2.0, 0.0]));
    assert_eq!(v["spheres"][0]["radius"], serde_json::json!(1.0));
    let back = read_dump(&dir).unwrap();
    assert_eq!(back.spheres, dump.spheres);
    // The reference's own masks check clean against the dumped sphere (no triangles at all).
    let report = check_dump(&dir, 1).unwrap();
    assert!(report.passed(0.0), "{report}");
    // Without the sphere the floor's shadow would be wrong: the check must see it.
    let mut no_sphere = dump.clone();
    no_sphere.spheres.clear();
    write_dump(&dir, &no_sphere).unwrap();
    assert!(!check_dump(&dir, 1).unwrap().passed(0.0));
    // A dumped sphere with a bad radius: an error naming frame.json and the sphere.
    write_dump(&dir, &dump).unwrap();
    let json = std::fs::read_to_string(dir.join("frame.json")).unwrap().replace("\"radius\": 1.0", "\"radius\": -1.0");
    std::fs::write(dir.join("frame.json"), json).unwrap();
    let e = read_dump(&dir).unwrap_err().to_string();
    assert!(e.contains("frame.json") && e.contains("sphere 0") && e.contains("radius"), "{e}");
    let _ = std::fs::remove_dir_all(&dir);
}
