//! `--method rayquery` beyond the accuracy table (tests/hard_cases.rs holds it to the reference
//! on every hard case): a moving caster on a device with `VK_KHR_ray_query` (Mesa lavapipe
//! 25.0.7 from `.drivers/` when the system's driver has none: `common::ray_query_context`),
//! with validation on; and, where the default device has no ray query, asking for it is a clear
//! error naming the extension and the script that installs a driver with it.
mod common;
use umbrage::accuracy::evaluate;
use umbrage::render::{RenderOptions, Renderer, Technique};

/// A caster that moves between frames: the top level is rebuilt from the new transform.
#[test]
fn rayquery_follows_a_moving_caster() {
    let Some(ctx) = common::ray_query_context("rayquery_follows_a_moving_caster") else { return };
    let scene = umbrage::scene::load("default").unwrap();
    let opts = RenderOptions { width: 160, height: 120, ..Default::default() };
    let mut r = Renderer::new(ctx, scene, opts).unwrap();
    for step in 0..3 {
        let i = r.scene().meshes.iter().position(|m| m.casts_shadow).unwrap();
        let moved =
            glam::Mat4::from_translation(glam::Vec3::new(0.3 * step as f32, 0.0, -0.2 * step as f32)) * r.scene().meshes[i].transform;
        r.set_mesh_transform(i, moved).unwrap();
        let rows = evaluate(&mut r, "default", &[Technique::RayQuery], 1).unwrap();
        assert!(rows[0].passed, "step {step}: {} mismatches of {}", rows[0].mismatches, rows[0].compared);
    }
    // The float counter counts volumes; the rays write the stencil: refused, not a stale picture.
    r.settings.technique = Technique::RayQuery;
    r.settings.counter = umbrage::render::Counter::Float;
    let e = r.render().err().expect("ray query with the float counter must fail");
    assert!(matches!(e, umbrage::Error::InvalidDesc { field: "FrameSettings::counter", .. }), "{e:?}");
    r.context().check_validation().unwrap();
}

#[test]
fn missing_ray_query_is_a_clear_error() {
    let Some(ctx) = common::context() else { return };
    if ctx.features.ray_query {
        eprintln!("this device has ray query: the missing-extension error cannot be shown here");
        return;
    }
    let scene = umbrage::scene::load("default").unwrap();
    let mut r = Renderer::new(ctx, scene, RenderOptions { width: 64, height: 48, ..Default::default() }).unwrap();
    r.settings.technique = Technique::RayQuery;
    // The float counter counts volumes: with rays it is refused first, whatever the device.
    r.settings.counter = umbrage::render::Counter::Float;
    let e = r.render().err().expect("ray query with the float counter must fail");
    assert!(matches!(e, umbrage::Error::InvalidDesc { field: "FrameSettings::counter", .. }), "{e:?}");
    r.settings.counter = umbrage::render::Counter::Stencil;
    let e = r.render().err().expect("ray query without the extension must fail").to_string();
    assert!(e.contains("VK_KHR_ray_query") && e.contains("scripts/drivers.sh install 25.0.7"), "{e}");
    // Nothing was left half-made: another technique still renders.
    r.settings.technique = Technique::default();
    r.render().unwrap();
    r.context().check_validation().unwrap();
}

/// A caster that deforms between frames (`Renderer::set_mesh_positions`, the pass's
/// `update_positions`): its bottom level is rebuilt once with ALLOW_UPDATE, then refitted in
/// place; each frame matches the CPU reference of the deformed scene, as the volumes do.
#[test]
fn rayquery_follows_a_deforming_caster() {
    let Some(ctx) = common::ray_query_context("rayquery_follows_a_deforming_caster") else { return };
    let scene = umbrage::scene::load("default").unwrap();
    let opts = RenderOptions { width: 160, height: 120, ..Default::default() };
    let mut r = Renderer::new(ctx, scene, opts).unwrap();
    let i = r.scene().meshes.iter().position(|m| m.casts_shadow).unwrap();
    let rest = r.scene().meshes[i].mesh.positions.clone();
    r.settings.technique = Technique::RayQuery;
    let first = r.render().unwrap().stats.ray_query.expect("ray-query stats");
    assert!(first.builds >= 1 && first.refits == 0, "{first:?}");
    // Once the building frame's slot comes round again, the static bottom levels are compacted
    // (copied into their compacted size), and the picture stays exact.
    let compacted: usize = (0..3).map(|_| r.render().unwrap().stats.ray_query.unwrap().compactions).sum();
    assert_eq!(compacted, first.builds, "every bottom level built in the first frame is compacted once");
    let rows = evaluate(&mut r, "default", &[Technique::RayQuery], 1).unwrap();
    assert!(rows[0].passed, "compacted: {} mismatches of {}", rows[0].mismatches, rows[0].compared);
    let mut refits = 0;
    for step in 1..4 {
        // A shear and a squash: the same triangles, new positions.
        let k = 0.15 * step as f32;
        let bent: Vec<glam::Vec3> = rest.iter().map(|p| glam::Vec3::new(p.x + k * p.y, p.y * (1.0 - 0.1 * step as f32), p.z)).collect();
        r.set_mesh_positions(i, &bent).unwrap();
        r.settings.technique = Technique::RayQuery;
        let s = r.render().unwrap().stats.ray_query.expect("ray-query stats");
        match step {
            1 => assert_eq!((s.builds, s.refits), (1, 0), "the first deformation rebuilds with ALLOW_UPDATE: {s:?}"),
            _ => assert_eq!((s.builds, s.refits), (0, 1), "later deformations refit: {s:?}"),
        }
        refits += s.refits;
        let rows = evaluate(&mut r, "default", &[Technique::RayQuery, Technique::default()], 1).unwrap();
        for row in &rows {
            assert!(row.passed, "step {step}, {}: {} mismatches of {}", row.method, row.mismatches, row.compared);
        }
    }
    assert_eq!(refits, 2);
    // A wrong vertex count is refused and changes nothing.
    assert!(r.set_mesh_positions(i, &rest[..rest.len() - 1]).is_err());
    r.context().check_validation().unwrap();
}
