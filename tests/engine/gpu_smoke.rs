use crate::common;
use glam::{Mat4, Vec3};
use umbrage::geom::Mesh;
use umbrage_render::{RenderOptions, Renderer, View};
use umbrage_scene::{Camera, Light, LightKind, Scene, SceneMesh};

fn quad(size: f32) -> Mesh {
    let s = size * 0.5;
    Mesh::new(vec![Vec3::new(-s, 0.0, -s), Vec3::new(s, 0.0, -s), Vec3::new(s, 0.0, s), Vec3::new(-s, 0.0, s)], vec![[0, 2, 1], [0, 3, 2]])
}

#[test]
fn ambient_and_light_without_casters() {
    let Some(ctx) = common::context() else { return };
    let scene = Scene {
        name: "t".into(),
        camera: Camera { eye: Vec3::new(0.0, 5.0, 5.0), target: Vec3::ZERO, ..Default::default() },
        lights: vec![Light {
            kind: LightKind::Point,
            position: Vec3::new(0.0, 4.0, 0.0),
            direction: Vec3::NEG_Y,
            color: Vec3::ONE,
            intensity: 1.0,
            radius: None,
            cone_deg: 45.0,
            area: None,
        }],
        meshes: vec![SceneMesh {
            name: "floor".into(),
            mesh: quad(10.0),
            transform: Mat4::IDENTITY,
            color: Vec3::splat(0.8),
            opacity: 1.0,
            casts_shadow: false,
        }],
        ambient: Vec3::splat(0.05),
        spheres: Vec::new(),
    };
    let mut r = Renderer::new(ctx, scene, RenderOptions { width: 64, height: 48, capture: true, ..Default::default() }).unwrap();
    let out = r.render().unwrap();
    let c = (24 * 64 + 32) * 4;
    assert!(out.color[c] > 100, "centre should be lit: {:?}", &out.color[c..c + 4]);
    assert!(out.positions[24 * 64 + 32][1].abs() < 1e-4);
    r.context().check_validation().unwrap();
    // Teardown: every object destroyed, in order; validation reports leaks at device destruction.
    let log = r.context().validation_log();
    drop(r);
    let errors = log.lock().unwrap().errors.clone();
    assert!(errors.is_empty(), "validation errors during teardown: {errors:#?}");
}

#[test]
fn default_scene_with_every_view_tears_down_cleanly() {
    let Some(mut ctx) = common::context() else { return };
    let mut images = Vec::new();
    for view in [View::Shaded, View::Volumes, View::Stencil] {
        let scene = umbrage_scene::load("default").unwrap();
        let mut r = Renderer::new(ctx, scene, RenderOptions { width: 96, height: 64, view, ..Default::default() }).unwrap();
        let out = r.render().unwrap();
        assert_eq!(out.color.len(), 96 * 64 * 4);
        images.push(out.color);
        r.context().check_validation().unwrap();
        ctx = r.into_context();
    }
    // The debug views really draw: volumes tint part of the shaded image (the default scene's
    // casters are all z-pass, drawn blue), and the stencil heat map is not the shaded image.
    let differ = |a: &[u8], b: &[u8]| a.chunks(4).zip(b.chunks(4)).filter(|(p, q)| p != q).count();
    let bluer = images[0].chunks(4).zip(images[1].chunks(4)).filter(|(p, q)| q[2] as i32 - q[0] as i32 > p[2] as i32 - p[0] as i32).count();
    assert!(differ(&images[0], &images[1]) > 96 * 64 / 10, "volumes view draws nothing");
    assert!(bluer > 96 * 64 / 10, "z-pass volumes should tint blue ({bluer} pixels)");
    assert!(differ(&images[0], &images[2]) > 96 * 64 / 2, "stencil view is the shaded image");
    let log = ctx.validation_log();
    drop(ctx);
    let errors = log.lock().unwrap().errors.clone();
    assert!(errors.is_empty(), "validation errors during teardown: {errors:#?}");
}

/// The messenger really is wired: an invalid call is reported and fails `check_validation`.
#[test]
fn validation_errors_are_caught() {
    let Some(ctx) = common::context() else { return };
    let info = ash::vk::BufferCreateInfo::default().size(0).usage(ash::vk::BufferUsageFlags::VERTEX_BUFFER);
    // SAFETY: deliberately invalid (size 0, VUID-VkBufferCreateInfo-size-00912) but harmless:
    // the buffer, if the driver creates it, is destroyed right away and never used.
    unsafe {
        if let Ok(b) = ctx.device.create_buffer(&info, None) {
            ctx.device.destroy_buffer(b, None);
        }
    }
    let err = ctx.check_validation().expect_err("validation should have reported the size-0 buffer");
    assert!(err.to_string().contains("size"), "{err}");
}
