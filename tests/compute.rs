//! `--method compute` (GPU possible silhouettes, indirect draws) against the CPU path: the
//! same stencil counts as `mcguire` pixel for pixel, the same triangle counts per light,
//! caster and part, 0 geometry bytes sent for static casters, and the same behaviour on bad
//! input. Validation (synchronisation included) on.
mod common;
use umbrage::render::{FrameOutput, RenderOptions, Renderer, Technique};
use umbrage::shadow::Method;

fn frame(r: &mut Renderer, t: Technique) -> FrameOutput {
    r.settings.technique = t;
    let out = r.render().unwrap();
    r.context().check_validation().unwrap();
    out
}

/// Renders `r`'s scene with McGuire's CPU path and the compute path and compares stencil
/// counts and triangle counts. Returns the compute frame.
fn compare(r: &mut Renderer, name: &str) -> FrameOutput {
    let cpu = frame(r, Technique::Volumes(Method::McGuire));
    let gpu = frame(r, Technique::Compute);
    // twice: the second frame reuses the slot's buffers and static tables
    let gpu2 = frame(r, Technique::Compute);
    assert_eq!(gpu.stencil.len(), cpu.stencil.len(), "{name}");
    for (li, (a, b)) in cpu.stencil.iter().zip(&gpu.stencil).enumerate() {
        let diff = a.iter().zip(b).filter(|(x, y)| x != y).count();
        assert_eq!(diff, 0, "{name} light {li}: {diff} stencil values differ from mcguire's");
    }
    for (g, g2) in gpu.stencil.iter().zip(&gpu2.stencil) {
        assert!(g == g2, "{name}: compute frames differ");
    }
    let (cs, gs) = (&cpu.stats, &gpu.stats);
    assert_eq!(gs.method, "compute");
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
                if cp.path == "manifold" {
                    assert_eq!(gp.path, "compute", "{what} part {}", cp.part);
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

#[test]
fn compute_smoke_default() {
    let Some(ctx) = common::context() else { return };
    let mut r = renderer(ctx, umbrage::scene::load("default").unwrap());
    let g = compare(&mut r, "default");
    assert!(g.stats.totals.triangles.total() > 0);
}
