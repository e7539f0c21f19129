//! Each part of a mesh planned on its own (issue 9, item 3): a many-part asset with a few bad
//! edges no longer sends every part down the multiplicity path. Measured against the whole
//! caster on that path (what the planner did before parts existed), on the CPU, and the
//! per-part frame is checked against the reference on the GPU.
//!
//! The real asset is `buildings.obj` from Debian's openfoam-examples (GPL-3+, so not in this
//! repository): `scripts/fetch-assets.sh` downloads it into `target/assets/`. Without it the
//! synthetic city below (the same shape of problem) still runs, and the test says so.

use crate::common;

use umbrage::shadow::{plan_light_opts, plan_light_with, Caster, Method, PlanInput, PlanOptions};
use umbrage_render::accuracy::evaluate;
use umbrage_render::{RenderOptions, Renderer, Technique};
use umbrage_scene::Scene;

/// Shadow triangles of light `li` with every part planned on its own, and with the whole
/// caster on the multiplicity path.
fn triangles(scene: &Scene, li: usize, w: u32, h: u32) -> (usize, usize) {
    let view_proj = scene.camera.proj_infinite(w as f32 / h as f32) * scene.camera.view();
    let input = PlanInput { camera: &scene.camera, width: w, height: h, view_proj, light: &scene.lights[li], method: Method::McGuire };
    let parts: Vec<Caster> = scene.meshes.iter().filter(|m| m.casts_shadow).map(|m| m.caster().unwrap()).collect();
    let whole: Vec<Caster> = parts
        .iter()
        .cloned()
        .map(|mut c| {
            if c.parts.len() > 1 && c.parts.iter().any(|p| p.kind.path() != umbrage::shadow::VolumePath::Manifold) {
                c.make_whole_multiplicity("whole caster (as before parts)".into());
            }
            c
        })
        .collect();
    let per_part = plan_light_with(&input, &parts, &PlanOptions { case_per_part: true, ..PlanOptions::default() });
    let before = plan_light_opts(&input, &whole, false);
    (per_part.casters.iter().map(|c| c.triangles()).sum(), before.casters.iter().map(|c| c.triangles()).sum())
}

/// 26 closed boxes in one mesh, one of them with a fin sharing an edge (3 faces on an edge:
/// non-manifold), and a street light among them.
fn synthetic_city() -> String {
    let mut obj = String::new();
    let mut v = 0;
    for k in 0..26 {
        let (x, z) = ((k % 6) as f32 * 4.0 - 10.0, (k / 6) as f32 * 4.0 - 8.0);
        let hgt = 2.0 + (k % 5) as f32;
        let c = [(0., 0., 0.), (2., 0., 0.), (2., 0., 2.), (0., 0., 2.), (0., hgt, 0.), (2., hgt, 0.), (2., hgt, 2.), (0., hgt, 2.)];
        for (a, b, d) in c {
            obj += &format!("v {} {} {}\n", x + a, b, z + d);
        }
        for f in [[1, 4, 3, 2], [5, 6, 7, 8], [1, 2, 6, 5], [2, 3, 7, 6], [3, 4, 8, 7], [4, 1, 5, 8]] {
            obj += &format!("f {} {} {} {}\n", v + f[0], v + f[1], v + f[2], v + f[3]);
        }
        if k == 7 {
            // A fin on the roof edge 5-6: that edge now has three triangles.
            obj += &format!("v {} {} {}\nf {} {} {}\n", x + 1.0, hgt + 1.0, z - 0.5, v + 5, v + 6, v + 9);
            v += 1;
        }
        v += 8;
    }
    obj
}

fn city_scene(obj_path: &str, transform: &str, light: [f32; 3], eye: [f32; 3], target: [f32; 3], size: f32) -> String {
    format!(
        r#"
[camera]
eye = {eye:?}
target = {target:?}
[[light]]
kind = "point"
position = {light:?}
[[light]]
kind = "directional"
direction = [-0.3, -1.0, -0.45]
intensity = 0.6
[[mesh]]
shape = "plane"
size = [{size}, {size}]
translate = {target:?}
casts_shadow = false
[[mesh]]
name = "city"
obj = "{obj_path}"
{transform}
"#
    )
}

/// Scenes where SwiftShader leaves holes in z-pass volumes (docs/conform/drivers-notes.md
/// §1e: isolated pixels and thin wedges with a lower count than lavapipe's, which is exact
/// there), with the fraction outside the band measured on SwiftShader (Debian 12's
/// `chromium-common` 156.0.8078.114).
const SWIFTSHADER_HOLES: &[(&str, f64)] = &[("synthetic city", 5.0 / 46137.0)];

fn check_city(ctx: umbrage::gpu::Context, name: &str, toml: &str, dir: &std::path::Path) -> umbrage::gpu::Context {
    let scene = umbrage_scene::load_str(toml, name, dir).unwrap();
    let (w, h) = (256, 192);
    let (per_part, whole) = triangles(&scene, 0, w, h);
    let ratio = whole as f64 / per_part.max(1) as f64;
    eprintln!("{name}: street light: {per_part} shadow triangles with parts, {whole} as one multiplicity caster ({ratio:.1}x)");
    assert!(ratio >= 3.0, "{name}: only {ratio:.2}x fewer triangles ({per_part} vs {whole})");
    let swiftshader = ctx.info.name.contains("SwiftShader");
    let mut r = Renderer::new(ctx, scene, RenderOptions { width: w, height: h, ..Default::default() }).unwrap();
    for row in evaluate(&mut r, name, &[Technique::Volumes(Method::McGuire)], 1).unwrap() {
        let why = format!("{name}: {} mismatches of {} ({:.4}%)", row.mismatches, row.compared, row.fraction * 100.0);
        match SWIFTSHADER_HOLES.iter().find(|(n, _)| *n == name).filter(|_| swiftshader) {
            // held to twice its measured fraction, and failing while the defect lasts
            Some((_, measured)) => {
                assert!(
                    !row.passed && row.fraction <= 2.0 * measured,
                    "{why}: SwiftShader's holes changed: update SWIFTSHADER_HOLES and docs/conform/drivers-notes.md §1e"
                );
                eprintln!("{why}: SwiftShader's holes (docs/conform/drivers-notes.md §1e), as measured");
            }
            None => assert!(row.passed, "{why}"),
        }
    }
    let stats = r.render().unwrap().stats;
    let city = stats.lights[0].casters.iter().find(|c| c.name == "city").unwrap();
    assert!(city.parts.len() > 1 || city.case == umbrage::shadow::Case::Culled, "per-part stats");
    r.context().check_validation().unwrap();
    r.into_context()
}

#[test]
fn many_part_assets_plan_each_part_on_its_own() {
    let Some(mut ctx) = common::context() else { return };
    let dir = std::env::temp_dir().join(format!("umbrage-parts-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("city.obj"), synthetic_city()).unwrap();
    let toml = city_scene("city.obj", "", [1.0, 3.0, 1.0], [2.0, 22.0, 16.0], [0.0, 0.0, 0.0], 60.0);
    ctx = check_city(ctx, "synthetic city", &toml, &dir);

    let real = concat!(env!("CARGO_MANIFEST_DIR"), "/target/assets/buildings.obj");
    if std::path::Path::new(real).is_file() {
        // The OpenFOAM city block is z-up: rotate it y-up; a street light among the buildings.
        let toml =
            city_scene(real, "rotate_deg = [-90.0, 0.0, 0.0]", [120.0, 12.0, -95.0], [120.0, 260.0, 60.0], [120.0, 0.0, -90.0], 400.0);
        ctx = check_city(ctx, "buildings.obj", &toml, &dir);
    } else {
        // Under CI the real asset is required (make test fetches it from Debian's packages): a
        // run that silently measured only the synthetic stand-in would look the same.
        assert!(std::env::var_os("CI").is_none(), "{real} missing under CI (scripts/fetch-assets.sh)");
        eprintln!("NOTE: {real} missing (run scripts/fetch-assets.sh): the OpenFOAM city block was not measured in this run");
    }
    drop(ctx);
    let _ = std::fs::remove_dir_all(&dir);
}
