//! `--method mesh` (mesh-shader extrusion, `VK_EXT_mesh_shader`) against the CPU path: the
//! same stencil counts as `mcguire` pixel for pixel, the same triangle counts per light,
//! caster and part, on the built-in scenes and every hard case (bad input among them). Runs
//! on Mesa lavapipe 25.0.7 (re-running itself there when the system's driver has no mesh
//! shaders: `common::mesh_shader_context`). Validation (synchronisation included) on.
mod common;
use umbrage::render::{FrameOutput, RenderOptions, Renderer, Technique};
use umbrage::shadow::{Method, VolumePath};

fn frame(r: &mut Renderer, t: Technique) -> FrameOutput {
    r.settings.technique = t;
    let out = r.render().unwrap();
    r.context().check_validation().unwrap();
    out
}

/// Renders `r`'s scene with McGuire's CPU path and the mesh path and compares stencil counts
/// and triangle counts. Returns the mesh frame.
fn compare(r: &mut Renderer, name: &str) -> FrameOutput {
    let cpu = frame(r, Technique::Volumes(Method::McGuire));
    let gpu = frame(r, Technique::Mesh);
    // twice: the second frame reuses the slot's buffers and static tables
    let gpu2 = frame(r, Technique::Mesh);
    assert_eq!(gpu.stencil.len(), cpu.stencil.len(), "{name}");
    for (li, (a, b)) in cpu.stencil.iter().zip(&gpu.stencil).enumerate() {
        let diff = a.iter().zip(b).filter(|(x, y)| x != y).count();
        assert_eq!(diff, 0, "{name} light {li}: {diff} stencil values differ from mcguire's");
    }
    for (g, g2) in gpu.stencil.iter().zip(&gpu2.stencil) {
        assert!(g == g2, "{name}: mesh frames differ");
    }
    let (cs, gs) = (&cpu.stats, &gpu.stats);
    assert_eq!(gs.method, Technique::Mesh);
    for (li, (cl, gl)) in cs.lights.iter().zip(&gs.lights).enumerate() {
        for (cc, gc) in cl.casters.iter().zip(&gl.casters) {
            let what = format!("{name} light {li} caster {}", cc.name);
            assert_eq!(cc.case, gc.case, "{what}");
            assert_eq!(
                (cc.triangles.sides, cc.triangles.dark_cap, cc.triangles.light_cap, cc.silhouette_edges),
                (gc.triangles.sides, gc.triangles.dark_cap, gc.triangles.light_cap, gc.silhouette_edges),
                "{what}: triangles and silhouette edges"
            );
            assert_eq!(cc.parts.len(), gc.parts.len(), "{what}");
            for (cp, gp) in cc.parts.iter().zip(&gc.parts) {
                assert_eq!(cp.case, gp.case, "{what} part {}", cp.part);
                assert_eq!(
                    (cp.triangles.sides, cp.triangles.dark_cap, cp.triangles.light_cap, cp.silhouette_edges),
                    (gp.triangles.sides, gp.triangles.dark_cap, gp.triangles.light_cap, gp.silhouette_edges),
                    "{what} part {}",
                    cp.part
                );
                if cp.path == VolumePath::Manifold {
                    assert_eq!(gp.path, VolumePath::Mesh, "{what} part {}", cp.part);
                }
            }
        }
    }
    assert_eq!(cs.totals.triangles.total(), gs.totals.triangles.total(), "{name}");
    assert_eq!(gpu2.stats.totals.triangles.total(), gs.totals.triangles.total(), "{name}");
    gpu
}

fn renderer(ctx: umbrage::gpu::Context, scene: umbrage::scene::Scene) -> Renderer {
    let opts = RenderOptions { width: 128, height: 96, capture: true, ..Default::default() };
    Renderer::new(ctx, scene, opts).unwrap()
}

/// Every hard case (bad input among them: light_in_face_plane, light_at_vertex,
/// light_inside_caster, zero_area, slivers, near_coplanar, far_coordinates, open_casters) and
/// every built-in scene.
#[test]
fn mesh_equals_mcguire_on_every_hard_case_and_builtin_scene() {
    let Some(mut ctx) = common::mesh_shader_context("mesh_equals_mcguire_on_every_hard_case_and_builtin_scene") else { return };
    let mut names: Vec<&str> = umbrage::scene::builtin_names().into_iter().filter(|n| n.starts_with("hard/")).collect();
    names.extend(["default", "stairs", "cubes", "spheres"]);
    for name in names {
        let mut r = renderer(ctx, umbrage::scene::load(name).unwrap());
        compare(&mut r, name);
        ctx = r.into_context();
    }
}
