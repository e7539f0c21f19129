//! The shadow pass's counters and ablation toggles (the bench suite's inputs): the counting
//! variant under an occlusion query, pipeline statistics, scissor and culling switched off.

use crate::common;

use umbrage_render::{PassToggles, RenderOptions, Renderer, Stats};

fn frame(r: &mut Renderer, toggles: PassToggles) -> Stats {
    r.settings.toggles = toggles;
    r.settings.counters = true;
    let f = r.render().expect("frame");
    f.stats
}

#[test]
fn counters_count_fragments_and_toggles_cost_what_they_save() {
    let Some(ctx) = common::context() else { return };
    let precise = common::feature(ctx.features.occlusion_query_precise, "occlusionQueryPrecise");
    let statistics = common::feature(ctx.features.pipeline_statistics_query, "pipelineStatisticsQuery");
    let scene = umbrage_scene::load("default").expect("scene");
    let opts = RenderOptions { width: 160, height: 90, ..Default::default() };
    let mut r = Renderer::new(ctx, scene, opts).expect("renderer");
    let on = frame(&mut r, PassToggles::default());
    let c = on.counters.clone().expect("counters asked for");
    if precise {
        let frags = c.stencil_fragments.expect("precise occlusion queries");
        assert!(frags > 0, "the default scene's volumes rasterise fragments");
        assert_eq!(c.per_light_fragments.iter().sum::<u64>(), frags);
        // At most every light's scissor area per volume triangle layer: bounded by the pixels
        // times the triangles (a loose, always-true bound that a wrong query would break).
        assert!(frags <= 160 * 90 * on.totals.triangles.total().max(1));
    } else {
        assert!(c.stencil_fragments.is_none());
    }
    if statistics {
        let prims = c.primitives.expect("pipeline statistics");
        assert_eq!(prims, on.totals.triangles.total(), "input-assembly primitives = shadow triangles drawn");
    }
    assert!(on.totals.draws > 0);
    // Scissor off: each light's determination covers the whole target: never fewer fragments.
    let no_scissor = frame(&mut r, PassToggles { scissor: false, ..Default::default() });
    assert!(no_scissor.lights.iter().all(|l| l.scissor.is_none()));
    if precise {
        assert!(no_scissor.counters.as_ref().and_then(|c| c.stencil_fragments) >= c.stencil_fragments);
    }
    // Culling off: no caster culled, never fewer triangles.
    let no_cull = frame(&mut r, PassToggles { culling: false, ..Default::default() });
    assert_eq!(no_cull.totals.cases.culled, 0);
    assert!(no_cull.totals.triangles.total() >= on.totals.triangles.total());
    // The image is the same with every optimisation off (they only bound the work).
    r.settings.counters = false;
    r.settings.toggles = PassToggles::default();
    let a = r.render().expect("frame").color;
    r.settings.toggles = PassToggles { scissor: false, depth_bounds: false, culling: false, ..PassToggles::default() };
    let b = r.render().expect("frame").color;
    assert_eq!(a, b, "scissor, depth bounds and culling change the cost, not the image");
    r.context().check_validation().expect("validation clean");
}
