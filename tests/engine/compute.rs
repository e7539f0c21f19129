//! `--method compute` (GPU possible silhouettes, indirect draws) against the CPU path: the
//! same stencil counts as `mcguire` pixel for pixel, the same triangle counts per light,
//! caster and part, 0 geometry bytes sent for static casters, and the same behaviour on bad
//! input. Validation (synchronisation included) on.
use crate::common;
use umbrage::shadow::{Method, VolumePath};
use umbrage_render::{ComputeDraws, FrameOutput, RenderOptions, Renderer, Technique};

fn frame(r: &mut Renderer, t: Technique) -> FrameOutput {
    r.settings.technique = t.into();
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
    assert_eq!(gs.method, Technique::Compute.into());
    common::same_volumes_as_cpu(cs, gs, name, VolumePath::Compute);
    assert_eq!(cs.totals.triangles.total(), gs.totals.triangles.total(), "{name}");
    assert_eq!(gpu2.stats.totals.triangles.total(), gs.totals.triangles.total(), "{name}");
    gpu
}

fn renderer(ctx: umbrage::gpu::Context, scene: umbrage_scene::Scene) -> Renderer {
    let opts = RenderOptions { width: 128, height: 96, capture: true, ..Default::default() };
    Renderer::new(ctx, scene, opts).unwrap()
}

/// Every hard case and built-in scene with casters ([`common::hard_and_builtin_scenes`]).
#[test]
fn compute_equals_mcguire_on_every_hard_case_and_builtin_scene() {
    let Some(mut ctx) = common::context() else { return };
    for name in common::hard_and_builtin_scenes() {
        let mut r = renderer(ctx, umbrage_scene::load(name).unwrap());
        compare(&mut r, name);
        ctx = r.into_context();
    }
}

/// The mixed scene ([`common::MIXED`]: a mirrored caster, a caster of several chunks, a
/// directional light, a light inside a caster's bounds): the same counts; static casters send
/// no geometry after their first frame; frames in flight stay validation clean.
#[test]
fn compute_mirrored_chunked_directional_and_static_bytes() {
    let Some(ctx) = common::context() else { return };
    let scene = common::mixed_scene();
    let mut r = renderer(ctx, scene);
    assert!(r.casters().iter().any(|c| c.chunks.len() > 1), "the dense sphere spans several chunks");
    assert!(r.casters().iter().any(|c| c.mirrored));
    let g = compare(&mut r, "mixed");
    assert!(g.stats.lights.iter().all(|l| l.casters.iter().any(|c| c.triangles.total() > 0)));
    // after the first compute frame the static tables are on the GPU: nothing is sent
    let again = frame(&mut r, Technique::Compute);
    assert_eq!(again.stats.totals.bytes_sent, 0, "static casters on the compute path send no geometry");
    assert!(again.stats.totals.index_bytes > 0);
    assert_eq!(again.stats.cpu_ms.silhouettes, 0.0, "no CPU facing for closed casters");
    // frames in flight: both ring slots, validation (synchronisation included) clean
    r.settings.technique = Technique::Compute.into();
    r.throughput(4).unwrap();
    r.context().check_validation().unwrap();
}

/// Open and non-manifold parts keep the CPU's multiplicity path (stated per part in the
/// stats), the closed parts of the same caster go to the GPU.
#[test]
fn compute_multiplicity_parts_fall_back_to_the_cpu() {
    let Some(ctx) = common::context() else { return };
    let mut r = renderer(ctx, umbrage_scene::load("hard/open_casters").unwrap());
    let g = compare(&mut r, "hard/open_casters");
    let parts: Vec<&str> =
        g.stats.lights.iter().flat_map(|l| l.casters.iter().flat_map(|c| c.parts.iter().map(|p| p.path.name()))).collect();
    assert!(parts.contains(&"multiplicity"), "{parts:?}");
}

/// The ways of recording the compute path's volume draws `ctx` offers, best first.
fn draw_ways(f: &umbrage::gpu::Features) -> Vec<ComputeDraws> {
    let first = f.draw_indirect_first_instance;
    let multi = first && f.multi_draw_indirect;
    let count = multi && f.draw_indirect_count;
    [(ComputeDraws::Count, count), (ComputeDraws::Multi, multi), (ComputeDraws::PerRecord, first), (ComputeDraws::PerChunk, true)]
        .into_iter()
        .filter(|&(_, ok)| ok)
        .map(|(w, _)| w)
        .collect()
}

/// Renders `r`'s scene with the compute path in every way of `ways`, with both counters, and
/// asserts the stencil and float counts bit for bit equal to the first way's, and the draw
/// calls: one per light and pipeline for the merged ways (the same for both), one per record
/// for the others (the same for both).
fn compare_draw_ways(r: &mut Renderer, name: &str, ways: &[ComputeDraws]) {
    use umbrage_render::Counter;
    for counter in [Counter::Stencil, Counter::Float] {
        r.settings.counter = counter;
        let mut first: Option<(ComputeDraws, FrameOutput)> = None;
        let mut draws = Vec::new();
        for &way in ways {
            r.settings.toggles.compute_draws = way;
            let out = frame(r, Technique::Compute);
            draws.push((way, out.stats.totals.draws));
            if let Some((w0, f0)) = &first {
                assert_eq!(out.stencil.len(), f0.stencil.len());
                for (li, (a, b)) in f0.stencil.iter().zip(&out.stencil).enumerate() {
                    let diff = a.iter().zip(b).filter(|(x, y)| x != y).count();
                    assert_eq!(diff, 0, "{name} {counter:?} light {li}: {diff} stencil values of {way} differ from {w0}'s");
                }
                for (li, (a, b)) in f0.counts.iter().zip(&out.counts).enumerate() {
                    let diff = a.iter().zip(b).filter(|(x, y)| x != y).count();
                    assert_eq!(diff, 0, "{name} {counter:?} light {li}: {diff} float counts of {way} differ from {w0}'s");
                }
                assert_eq!(f0.stats.totals.triangles.total(), out.stats.totals.triangles.total(), "{name} {way}");
            } else {
                first = Some((way, out));
            }
        }
        let calls = |w: ComputeDraws| draws.iter().find(|d| d.0 == w).map(|d| d.1);
        if let (Some(c), Some(m)) = (calls(ComputeDraws::Count), calls(ComputeDraws::Multi)) {
            assert_eq!(c, m, "{name}: count and multi record the same calls");
        }
        if let (Some(p), Some(c)) = (calls(ComputeDraws::PerRecord), calls(ComputeDraws::PerChunk)) {
            assert_eq!(p, c, "{name}: one call per record either way");
            if let Some(m) = calls(ComputeDraws::Multi) {
                assert!(m <= c, "{name}: merged {m} calls against {c} per chunk");
            }
        }
    }
}

/// [`compare_draw_ways`] on each named scene, then on the mixed scene, whose renderer it
/// returns.
fn draw_ways_on(mut ctx: umbrage::gpu::Context, names: &[&str], ways: &[ComputeDraws]) -> Renderer {
    for name in names {
        let mut r = renderer(ctx, umbrage_scene::load(name).unwrap());
        compare_draw_ways(&mut r, name, ways);
        ctx = r.into_context();
    }
    let mut r = renderer(ctx, common::mixed_scene());
    compare_draw_ways(&mut r, "mixed", ways);
    r
}

/// Every way of recording the compute path's volume draws (issue #37: one
/// `vkCmdDrawIndexedIndirectCount` per light and pipeline, one multi-draw, one draw per record,
/// one draw per chunk with push constants) gives the same stencil and float counts, bit for
/// bit, on every hard case, every built-in scene and the mixed scene (several chunks, a
/// mirrored caster, a directional light, a light inside a caster's bounds). On the system's
/// lavapipe (22.3.6) every way is there; under CI a missing one fails.
#[test]
fn compute_draw_ways_are_bit_identical() {
    let Some(ctx) = common::context() else { return };
    let ways = draw_ways(&ctx.features);
    if std::env::var_os("CI").is_some() {
        assert_eq!(
            ways.len(),
            4,
            "{}: the merged draws need drawIndirectCount, multiDrawIndirect and drawIndirectFirstInstance",
            ctx.info.name
        );
    }
    let mut r = draw_ways_on(ctx, &common::hard_and_builtin_scenes(), &ways);
    // the merged draws with frames in flight: validation (synchronisation included) clean
    r.settings.toggles.compute_draws = ComputeDraws::Auto;
    r.settings.technique = Technique::Compute.into();
    r.throughput(4).unwrap();
    r.context().check_validation().unwrap();
}

/// The same on SwiftShader (`scripts/drivers.sh install swiftshader`), whichever ways it offers.
#[test]
fn compute_draw_ways_on_swiftshader() {
    common::rerun_on_swiftshader(concat!(module_path!(), "::swiftshader_draw_ways"), &[]);
}

#[test]
#[ignore = "a helper: compute_draw_ways_on_swiftshader runs it on SwiftShader"]
fn swiftshader_draw_ways() {
    let Some(ctx) = common::context() else { return };
    let ways = draw_ways(&ctx.features);
    eprintln!("{}: ways {ways:?}", ctx.info.name);
    assert!(ways.len() >= 2, "{}: no merged way at all", ctx.info.name);
    draw_ways_on(ctx, &["default", "hard/open_casters", "hard/light_inside_caster"], &ways);
}
