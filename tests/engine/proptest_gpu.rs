//! Property test: random closed casters (star-shaped perturbed spheres, non-convex), random
//! transforms, lights and cameras — the GPU shadow mask of every method that should be exact
//! matches the CPU reference outside a 1-pixel band.
use crate::common;
use glam::{EulerRot, Mat4, Quat, Vec2, Vec3};
use proptest::prelude::*;
use proptest::test_runner::{Config, TestRunner};
use std::cell::RefCell;
use umbrage::shadow::Method;
use umbrage_render::accuracy::{evaluate, THRESHOLD};
use umbrage_render::{RenderOptions, Renderer};
use umbrage_scene::{shapes, Camera, Light, LightKind, Scene, SceneMesh};

/// A tiny deterministic generator for per-vertex perturbations.
fn xorshift(state: &mut u64) -> f32 {
    *state ^= *state << 13;
    *state ^= *state >> 7;
    *state ^= *state << 17;
    (*state >> 40) as f32 / (1u64 << 24) as f32
}

fn star_mesh(seed: u64) -> umbrage::geom::Mesh {
    let mut m = shapes::sphere(0.6, 14, 9);
    let mut s = seed | 1;
    for p in &mut m.positions {
        *p *= 0.7 + 0.6 * xorshift(&mut s);
    }
    m
}

#[derive(Debug, Clone)]
struct Case {
    seeds: Vec<u64>,
    offsets: Vec<(f32, f32, f32)>,
    rotations: Vec<(f32, f32, f32)>,
    light: (f32, f32, f32),
    directional: bool,
    cam_angle: f32,
    cam_height: f32,
    cam_dist: f32,
}

fn strategy() -> impl Strategy<Value = Case> {
    (
        prop::collection::vec((any::<u64>(), (-2.0f32..2.0, 0.6f32..2.5, -2.0f32..2.0), (0.0f32..6.3, 0.0f32..6.3, 0.0f32..6.3)), 1..4),
        (-4.0f32..4.0, 3.0f32..8.0, -4.0f32..4.0),
        any::<bool>(),
        (0.0f32..std::f32::consts::TAU, 0.5f32..6.0, 4.0f32..9.0),
    )
        .prop_map(|(casters, light, directional, (cam_angle, cam_height, cam_dist))| Case {
            seeds: casters.iter().map(|c| c.0).collect(),
            offsets: casters.iter().map(|c| c.1).collect(),
            rotations: casters.iter().map(|c| c.2).collect(),
            light,
            directional,
            cam_angle,
            cam_height,
            cam_dist,
        })
}

fn scene(c: &Case) -> Scene {
    let mut meshes = vec![SceneMesh {
        name: "floor".into(),
        mesh: shapes::plane(Vec2::splat(30.0)),
        transform: Mat4::IDENTITY,
        color: Vec3::splat(0.8),
        opacity: 1.0,
        casts_shadow: false,
    }];
    for (i, ((seed, o), r)) in c.seeds.iter().zip(&c.offsets).zip(&c.rotations).enumerate() {
        meshes.push(SceneMesh {
            name: format!("star{i}"),
            mesh: star_mesh(*seed),
            transform: Mat4::from_rotation_translation(Quat::from_euler(EulerRot::XYZ, r.0, r.1, r.2), Vec3::new(o.0, o.1, o.2)),
            color: Vec3::new(0.7, 0.5, 0.4),
            opacity: 1.0,
            casts_shadow: true,
        });
    }
    let l = Vec3::new(c.light.0, c.light.1, c.light.2);
    let light = if c.directional {
        Light {
            kind: LightKind::Directional,
            position: Vec3::ZERO,
            direction: -l.normalize(),
            color: Vec3::ONE,
            intensity: 1.0,
            radius: None,
            cone_deg: 45.0,
            area: None,
        }
    } else {
        Light {
            kind: LightKind::Point,
            position: l,
            direction: Vec3::NEG_Y,
            color: Vec3::ONE,
            intensity: 1.0,
            radius: None,
            cone_deg: 45.0,
            area: None,
        }
    };
    let eye = Vec3::new(c.cam_angle.cos() * c.cam_dist, c.cam_height, c.cam_angle.sin() * c.cam_dist);
    Scene {
        name: "proptest".into(),
        camera: Camera { eye, target: Vec3::new(0.0, 0.8, 0.0), ..Default::default() },
        lights: vec![light],
        meshes,
        ambient: Vec3::splat(0.05),
        spheres: Vec::new(),
    }
}

/// The fraction `zfail` may miss on SwiftShader: twice the worst measured (`hard/big_caster`,
/// 0.058 %; `tests/engine/hard_cases.rs`' `SLIVER_DEFECT`).
const SWIFTSHADER_SLIVERS: f64 = 2.0 * common::SWIFTSHADER_BIG_CASTER_SLIVERS;

/// Renders `case` with every exact volume method and checks each against the reference.
fn check(ctx: &RefCell<Option<umbrage::gpu::Context>>, case: &Case, drawn: &std::cell::Cell<u64>) -> Result<(), TestCaseError> {
    let methods = [Method::McGuire, Method::ZFail, Method::Lengyel].map(umbrage_render::Technique::Volumes);
    let c = ctx.borrow_mut().take().expect("context");
    let mut r = Renderer::new(c, scene(case), RenderOptions { width: 128, height: 96, ..Default::default() }).expect("renderer");
    let swiftshader = r.context().info.name.contains("SwiftShader");
    let rows = evaluate(&mut r, "proptest", &methods, 1).expect("evaluate");
    r.context().check_validation().expect("validation");
    *ctx.borrow_mut() = Some(r.into_context());
    let mut failures = Vec::new();
    for row in rows {
        drawn.set(drawn.get() + row.shadow_triangles);
        prop_assert!(row.compared > 0, "nothing visible: {:?}", case);
        // SwiftShader drops clipped slivers whose snapped winding flips (a driver defect,
        // docs/conform/drivers-notes.md §1e): z-fail with both caps everywhere counts the
        // sides' slivers behind the receivers and misses a few pixels (at most 0.058 % of a
        // hard case). McGuire's and Lengyel's cases keep the usual threshold: they were exact
        // on every case seen here (z-pass sides can be hit too: tests/engine/parts.rs' city).
        let ceiling = if swiftshader && row.method == "zfail" { SWIFTSHADER_SLIVERS } else { THRESHOLD };
        if row.fraction > ceiling {
            failures.push(format!("{} mismatches {} of {}", row.method, row.mismatches, row.compared));
        }
    }
    prop_assert!(failures.is_empty(), "{} ({:?})", failures.join(", "), case);
    Ok(())
}

/// The property's runner: a fixed seed by default, so that CI is reproducible (a case it
/// finds is kept in [`regressions`]); `UMBRAGE_PROPTEST_SEED=<u64>` replays a run and
/// `UMBRAGE_PROPTEST_SEED=random` explores ([`common::proptest_seed`]), with
/// `UMBRAGE_PROPTEST_CASES` cases (24 by default).
fn runner() -> (TestRunner, String) {
    let cases = std::env::var("UMBRAGE_PROPTEST_CASES").ok().and_then(|v| v.parse().ok()).unwrap_or(24);
    let config = Config { cases, failure_persistence: None, ..Config::default() };
    let seed = common::proptest_seed("proptest_gpu", 0x2026_1203);
    (TestRunner::new_with_rng(config, common::seeded_rng(seed)), format!("UMBRAGE_PROPTEST_SEED={seed}, {cases} cases"))
}

#[test]
fn random_closed_casters_match_the_reference() {
    let Some(ctx) = common::context() else { return };
    let ctx = RefCell::new(Some(ctx));
    let (mut runner, replay) = runner();
    let drawn = std::cell::Cell::new(0u64);
    if let Err(e) = runner.run(&strategy(), |case| check(&ctx, &case, &drawn)) {
        panic!("{e} (replay with {replay})");
    }
    assert!(drawn.get() > 0, "no case drew any shadow volume: the property was vacuous");
}

/// Cases the property once found, kept as fixed tests.
#[test]
fn regressions() {
    let Some(ctx) = common::context() else { return };
    let ctx = RefCell::new(Some(ctx));
    let drawn = std::cell::Cell::new(0u64);
    let cases = [
        // CI, 2026-12-03: every method read 2 self-shadowed pixels next to the terminator as lit
        // (cos 0.0016: the triangle's own silhouette face lies 3e-6 behind the surface, about
        // one ulp of forward float depth); the terminator is now part of the band.
        Case {
            seeds: vec![17357496371626629310],
            offsets: vec![(-1.9853572, 2.240309, 0.22414118)],
            rotations: vec![(3.76996, 3.5952725, 0.3239059)],
            light: (-2.9614964, 3.8641555, 1.4883822),
            directional: false,
            cam_angle: 1.8544235,
            cam_height: 2.0392418,
            cam_dist: 4.7142024,
        },
        // SwiftShader, 2026-12-06 (UMBRAGE_PROPTEST_SEED=539365891): `zfail` missed 1 pixel of
        // 7,518 (the sliver defect above); McGuire and Lengyel exact, lavapipe exact.
        Case {
            seeds: vec![17387287035438895228],
            offsets: vec![(-1.6173371, 1.1300724, -1.6034667)],
            rotations: vec![(0.70888674, 1.6437795, 3.521345)],
            light: (-2.498638, 6.92002, -1.2039063),
            directional: false,
            cam_angle: 5.6249504,
            cam_height: 2.860529,
            cam_dist: 7.6041436,
        },
    ];
    for case in &cases {
        check(&ctx, case, &drawn).unwrap();
    }
}
