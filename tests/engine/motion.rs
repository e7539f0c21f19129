//! Frames that move and frames with many lights: the renderer keeps its pipelines, targets and
//! casters while lights, casters and the camera move, with frames in flight, and any number of
//! lights (each with its own stats and timestamps) matches the exact CPU reference.

use crate::common;

use glam::{Mat4, Vec2, Vec3};
use umbrage::shadow::Method;
use umbrage_reference::{metrics::compare_all, Reference};
use umbrage_render::accuracy::evaluate;
use umbrage_render::{FrameOutput, RenderOptions, Renderer, Technique};
use umbrage_scene::{shapes, Camera, Light, LightKind, Scene, SceneMesh};

fn mesh(name: &str, mesh: umbrage::geom::Mesh, transform: Mat4, casts_shadow: bool) -> SceneMesh {
    SceneMesh { name: name.into(), mesh, transform, color: Vec3::new(0.8, 0.75, 0.7), opacity: 1.0, casts_shadow }
}

/// A 4 x 4 grid of cubes on a floor, lit by `n` dim coloured point lights with a radius, on
/// a spiral above the grid (what a new user tries first with "many lights").
fn cube_grid(n: usize) -> Scene {
    let mut meshes = vec![mesh("floor", shapes::plane(Vec2::splat(14.0)), Mat4::IDENTITY, false)];
    for i in 0..16 {
        let (x, z) = ((i % 4) as f32 * 2.0 - 3.0, (i / 4) as f32 * 2.0 - 3.0);
        meshes.push(mesh(&format!("cube{i}"), shapes::cuboid(Vec3::splat(0.8)), Mat4::from_translation(Vec3::new(x, 0.4, z)), true));
    }
    let lights = (0..n)
        .map(|k| {
            let t = k as f32 / n as f32;
            let a = t * std::f32::consts::TAU * 7.0;
            let r = 1.0 + 4.5 * t;
            Light {
                kind: LightKind::Point,
                position: Vec3::new(r * a.cos(), 1.2 + 2.0 * (1.0 - t), r * a.sin()),
                direction: Vec3::NEG_Y,
                color: Vec3::new(0.5 + 0.5 * a.sin(), 0.5 + 0.5 * (a + 2.0).sin(), 0.5 + 0.5 * (a + 4.0).sin()),
                intensity: 4.0 / n as f32,
                radius: Some(3.5),
                cone_deg: 45.0,
                area: None,
            }
        })
        .collect();
    Scene {
        name: format!("cube_grid_{n}"),
        camera: Camera { eye: Vec3::new(0.0, 9.0, 9.0), target: Vec3::ZERO, ..Default::default() },
        lights,
        meshes,
        ambient: Vec3::splat(0.05),
        spheres: Vec::new(),
    }
}

/// Every pixel's shadow mask of every light, flattened.
fn masks(out: &FrameOutput, scene: &Scene) -> Vec<Vec<u8>> {
    out.shadow_masks(scene)
}

fn differing(a: &[Vec<u8>], b: &[Vec<u8>]) -> usize {
    a.iter().zip(b).map(|(x, y)| x.iter().zip(y).filter(|(p, q)| p != q).count()).sum()
}

/// 100 and 1000 lights render (no fixed cap on lights or timestamps) and match the reference.
#[test]
fn hundred_and_thousand_lights_match_the_reference() {
    let Some(mut ctx) = common::context() else { return };
    for (n, w, h) in [(100usize, 160u32, 120u32), (1000, 96, 72)] {
        let scene = cube_grid(n);
        let name = scene.name.clone();
        let mut r = Renderer::new(ctx, scene, RenderOptions { width: w, height: h, ..Default::default() }).unwrap();
        let rows = evaluate(&mut r, &name, &[Technique::Volumes(Method::McGuire)], 1).unwrap();
        let row = &rows[0];
        assert!(row.passed, "{name}: {} mismatches of {} ({:.4}%)", row.mismatches, row.compared, row.fraction * 100.0);
        assert_eq!(row.per_light.len(), n);
        let out = r.render().unwrap();
        assert_eq!(out.stats.lights.len(), n, "one stats entry per light");
        if let Some(g) = &out.stats.gpu_ms {
            assert_eq!(g.per_light.len(), n, "one timing entry per light");
        }
        r.context().check_validation().unwrap();
        ctx = r.into_context();
    }
}

/// Moving a light, a caster and the camera between frames (two frames in flight) gives the
/// masks of a fresh renderer for each state, and both match the reference.
#[test]
fn moving_lights_casters_and_camera_match_a_fresh_render() {
    let Some(mut ctx) = common::context() else { return };
    let (w, h) = (192u32, 128u32);
    let opts = RenderOptions { width: w, height: h, capture: true, frames_in_flight: 2, ..Default::default() };
    let base = cube_grid(3);
    // Three states: a light moved; a caster moved; the camera moved.
    let mut states = Vec::new();
    let mut s1 = base.clone();
    s1.lights[0].position += Vec3::new(0.75, 0.5, -0.25);
    states.push(s1.clone());
    let mut s2 = s1.clone();
    s2.meshes[5].transform = Mat4::from_translation(Vec3::new(-0.5, 0.4, -2.25)) * Mat4::from_rotation_y(0.6);
    states.push(s2.clone());
    let mut s3 = s2.clone();
    s3.camera.eye = Vec3::new(1.5, 8.0, 9.5);
    states.push(s3);

    let mut r = Renderer::new(ctx, base.clone(), opts.clone()).unwrap();
    let first = r.submit().unwrap();
    let mut moved = Vec::new();
    let mut tickets = vec![first];
    for s in &states {
        r.set_lights(s.lights.clone()).unwrap();
        for (i, m) in s.meshes.iter().enumerate() {
            if m.transform != r.scene().meshes[i].transform {
                r.set_mesh_transform(i, m.transform).unwrap();
            }
        }
        if s.camera != r.scene().camera {
            r.set_camera(s.camera.clone()).unwrap();
        }
        tickets.push(r.submit().unwrap());
        // Two frames in flight: finish the older one once the newer is submitted.
        let t = tickets.remove(0);
        moved.push(r.finish(t).unwrap());
    }
    moved.push(r.finish(tickets.remove(0)).unwrap());
    r.context().check_validation().unwrap();
    ctx = r.into_context();

    let all_states: Vec<Scene> = std::iter::once(base).chain(states).collect();
    for (k, (state, out)) in all_states.iter().zip(&moved).enumerate() {
        let mut fresh = Renderer::new(ctx, state.clone(), opts.clone()).unwrap();
        let f = fresh.render().unwrap();
        let (a, b) = (masks(out, state), masks(&f, state));
        let diff = differing(&a, &b);
        // The light and caster states keep the camera at the anchor the geometry was baked
        // for, so their G-buffer is bit for bit a fresh one's; a moved camera re-places the
        // baked positions with an f32 translation, which may move a surface by an ulp.
        let allowed = if k == 3 { (w * h) as usize / 2000 } else { 0 };
        assert!(diff <= allowed, "state {k}: {diff} mask pixels differ from a fresh render (allowed {allowed})");
        if k < 3 {
            assert_eq!(out.stencil, f.stencil, "state {k}: stencil counts differ from a fresh render");
        }
        let reference = Reference::from_scene(state).render(&state.camera, &state.lights, w, h);
        for m in compare_all(&a, &reference, 1).unwrap() {
            assert!(m.fraction_outside_band <= umbrage_render::accuracy::THRESHOLD, "state {k}: {m:?}");
        }
        fresh.context().check_validation().unwrap();
        ctx = fresh.into_context();
    }
}

/// Frames in flight overlap and report a throughput; a ticket can only be finished once.
#[test]
fn throughput_with_frames_in_flight() {
    let Some(ctx) = common::context() else { return };
    let mut r =
        Renderer::new(ctx, cube_grid(4), RenderOptions { width: 128, height: 96, frames_in_flight: 3, ..Default::default() }).unwrap();
    let t = r.throughput(9).unwrap();
    assert_eq!(t.frames, 9);
    assert!(t.fps > 0.0 && t.latency_ms > 0.0, "{t:?}");
    let a = r.submit().unwrap();
    let b = r.submit().unwrap();
    let c = r.submit().unwrap();
    // A fourth submission reuses a's slot: a's output is gone, and finishing it is an error.
    let d = r.submit().unwrap();
    assert!(r.finish(a).is_err());
    for t in [b, c, d] {
        r.finish(t).unwrap();
    }
    r.context().check_validation().unwrap();
}

/// Moving meshes and the camera: bad transforms and cameras are refused, nothing changes.
#[test]
fn bad_motion_is_refused() {
    let Some(ctx) = common::context() else { return };
    let mut r = Renderer::new(ctx, cube_grid(1), RenderOptions { width: 64, height: 48, ..Default::default() }).unwrap();
    let before = r.scene().meshes[3].transform;
    assert!(r.set_mesh_transform(3, Mat4::from_scale(Vec3::new(-1.0, 1.0, 1.0))).is_err(), "handedness change");
    assert!(r.set_mesh_transform(3, Mat4::from_scale(Vec3::new(1.0, 0.0, 1.0))).is_err(), "singular");
    assert!(r.set_mesh_transform(3, Mat4::from_translation(Vec3::new(f32::NAN, 0.0, 0.0))).is_err(), "NaN");
    assert!(r.set_mesh_transform(99, Mat4::IDENTITY).is_err(), "no such mesh");
    assert_eq!(r.scene().meshes[3].transform, before);
    let mut cam = r.scene().camera.clone();
    cam.target = cam.eye;
    assert!(r.set_camera(cam).is_err(), "eye == target");
    r.render().unwrap();
    r.context().check_validation().unwrap();
}
