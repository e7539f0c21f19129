//! Using umbrage as a library: build a scene in code, plan the shadow volumes on the CPU (the
//! part an engine would call every frame, with no Vulkan in it), then render the frame and
//! compare it with the exact CPU reference.
//!
//! Run: `cargo run --example embed` (needs a Vulkan driver; lavapipe is fine).

use glam::{Mat4, Vec2, Vec3};
use umbrage::reference::{metrics::compare_all, Reference};
use umbrage::render::{RenderOptions, Renderer};
use umbrage::scene::{shapes, Camera, Light, LightKind, Scene, SceneMesh};
use umbrage::shadow::{plan_light, Caster, Method, PlanInput};

fn main() -> umbrage::Result<()> {
    // 1. A scene: a floor (open, does not cast), a torus and a box, one point light.
    let mesh = |name: &str, mesh, transform, casts_shadow| SceneMesh {
        name: name.into(),
        mesh,
        transform,
        color: Vec3::new(0.8, 0.7, 0.6),
        opacity: 1.0,
        casts_shadow,
    };
    let scene = Scene {
        name: "embedded".into(),
        camera: Camera { eye: Vec3::new(0.0, 4.0, 7.0), target: Vec3::new(0.0, 0.5, 0.0), ..Default::default() },
        lights: vec![Light {
            kind: LightKind::Point,
            position: Vec3::new(2.0, 6.0, 2.0),
            direction: Vec3::NEG_Y,
            color: Vec3::ONE,
            intensity: 1.0,
            radius: None,
            cone_deg: 45.0,
        }],
        meshes: vec![
            mesh("floor", shapes::plane(Vec2::splat(20.0)), Mat4::IDENTITY, false),
            mesh("torus", shapes::torus(0.8, 0.25, 48, 24), Mat4::from_translation(Vec3::new(-1.2, 1.0, 0.0)), true),
            mesh("box", shapes::cuboid(Vec3::ONE), Mat4::from_translation(Vec3::new(1.2, 0.5, 0.0)), true),
        ],
        ambient: Vec3::splat(0.06),
    };

    // 2. The CPU side an engine embeds: casters prepared once, a plan per light and frame.
    let casters: Vec<Caster> = scene.meshes.iter().filter(|m| m.casts_shadow).map(Caster::from_scene_mesh).collect::<Result<_, _>>()?;
    let (w, h) = (640, 400);
    let view_proj = scene.camera.proj_infinite(w as f32 / h as f32) * scene.camera.view();
    let plan = plan_light(
        &PlanInput { camera: &scene.camera, width: w, height: h, view_proj, light: &scene.lights[0], method: Method::McGuire },
        &casters,
    );
    for cp in &plan.casters {
        println!(
            "{:>6}: {:?}, {} silhouette edges, {} shadow triangles ({} index lists)",
            casters[cp.caster].name,
            cp.case,
            cp.silhouette_edges,
            cp.triangles(),
            cp.chunks.len()
        );
    }

    // 3. The frame on the GPU, and its error against the CPU reference.
    let ctx = umbrage::gpu::Context::new()?;
    let mut renderer = Renderer::new(ctx, scene, RenderOptions { width: w, height: h, capture: true, ..Default::default() })?;
    let frame = renderer.render()?;
    let reference = Reference::from_scene(renderer.scene()).render(&renderer.scene().camera, &renderer.scene().lights, w, h);
    let metrics = compare_all(&frame.shadow_masks(renderer.scene()), &reference, 1)?;
    umbrage::output::write_png(std::path::Path::new("embed.png"), w, h, &frame.color)?;
    println!(
        "{}: frame {:.2} ms, {} mismatched pixels outside the 1-pixel band of {} compared; wrote embed.png",
        frame.stats.device, frame.stats.wall_ms, metrics[0].mismatches_outside_band, metrics[0].compared
    );
    Ok(())
}
