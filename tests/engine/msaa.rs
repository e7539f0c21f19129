//! `umbrage render --msaa N` (issue 19): the renderer's own frame at N samples. Every sample of
//! every light is held against the exact CPU reference at that sample's own location (the
//! per-sample dump), the resolve differs from the single-sample frame only at edges, and what
//! renders at one sample is refused with a clear error. Validation on.

use crate::common;

use umbrage::error::Error;
use umbrage::shadow::Method;
use umbrage_render::{Counter, FrameOutput, RenderOptions, RenderTechnique, Renderer, ShadowMap, Technique, View};
use umbrage_scene::Scene;

const SAMPLES: u32 = 4;

/// Per light of frame `f` against the reference: (mismatches in all, band included; pixels
/// compared), with no mismatch outside the 1-pixel band and enough pixels compared.
fn against_reference(f: &FrameOutput, scene: &Scene, name: &str) -> Vec<(u64, u64)> {
    let positions = f.positions.iter().flatten().copied().collect();
    let normals = f.normals.iter().flatten().copied().collect();
    let dump = umbrage_render::output::scene_dump(scene, (f.width, f.height), positions, normals, f.shadow_masks(scene));
    let report = umbrage_reference::check(&dump, name, 1).unwrap();
    let mut out = Vec::new();
    for (li, l) in report.lights.iter().enumerate() {
        let m = &l.metrics;
        assert_eq!(m.mismatches_outside_band, 0, "{name} light {li}: {m:?}");
        assert!(m.compared > 5_000, "{name} light {li}: only {} pixels compared", m.compared);
        out.push((m.lit_but_ref_shadowed + m.shadowed_but_ref_lit + m.background_mismatch, m.compared));
    }
    out
}

/// Every sample of `out` against the reference at its own location: no mismatch outside the
/// band, and inside it no more than the single-sample frame `one` has at the pixel centres
/// (plus 0.1 % of the pixels): a sample read back at another sample's location disagrees at
/// hundreds of edge pixels.
fn check_samples(out: &FrameOutput, one: &FrameOutput, scene: &Scene, what: &str) {
    assert_eq!(out.samples.len(), SAMPLES as usize, "{what}: one capture per sample");
    let single = against_reference(one, scene, &format!("{what} 1x"));
    for k in 0..out.samples.len() {
        let name = format!("{what} sample {k}");
        let sample = against_reference(&out.sample(k).unwrap(), scene, &name);
        for (li, (&(all, compared), &(one_all, _))) in sample.iter().zip(&single).enumerate() {
            eprintln!("{name} light {li}: {all} mismatches in the band ({one_all} at 1x), {compared} compared");
            assert!(all <= one_all + compared / 1000, "{name} light {li}: {all} mismatches in the band, {one_all} at 1x");
        }
    }
}

fn render(ctx: umbrage::gpu::Context, name: &str, technique: impl Into<RenderTechnique>, samples: u32) -> (FrameOutput, Renderer) {
    let scene = umbrage_scene::load(name).unwrap();
    let opts = RenderOptions { width: 160, height: 120, technique: technique.into(), capture: true, samples, ..Default::default() };
    let mut r = Renderer::new(ctx, scene, opts).unwrap_or_else(|e| panic!("{name} at {samples} samples: {e}"));
    umbrage_conform::checks::calibrate_sample_locations(&mut r).unwrap();
    let out = r.render().unwrap();
    r.context().check_validation().unwrap();
    (out, r)
}

#[test]
fn every_sample_matches_the_reference() {
    let Some(mut ctx) = common::context() else { return };
    assert!(
        ctx.features.frame_sample_counts & SAMPLES != 0 && ctx.features.sample_rate_shading,
        "the device cannot render the multisampled frame: {:?}",
        ctx.features
    );
    let cases = [
        ("default", Technique::Volumes(Method::McGuire)),
        ("default", Technique::EdgeQuads),
        ("default", Technique::Compute),
        ("stairs", Technique::Volumes(Method::ZFail)),
        ("analytic/sphere_and_meshes", Technique::Volumes(Method::McGuire)),
        ("hard/eye_in_volume", Technique::Volumes(Method::McGuire)),
        ("hard/near_plane_cut", Technique::Volumes(Method::McGuire)),
        ("hard/light_inside_caster", Technique::Volumes(Method::McGuire)),
        ("hard/far_coordinates", Technique::Volumes(Method::McGuire)),
        ("area/disc", Technique::Volumes(Method::McGuire)),
    ];
    for (name, technique) in cases {
        let (one, r) = render(ctx, name, technique, 1);
        let (out, r) = render(r.into_context(), name, technique, SAMPLES);
        check_samples(&out, &one, r.scene(), &format!("{name} {}", technique.name()));
        ctx = r.into_context();
    }
}

#[test]
fn samples_are_at_their_own_locations_and_the_resolve_antialiases() {
    let Some(ctx) = common::context() else { return };
    let t = Technique::Volumes(Method::McGuire);
    let (one, r) = render(ctx, "default", t, 1);
    assert!(one.samples.is_empty(), "a single-sampled frame has no per-sample captures");
    let (four, r) = render(r.into_context(), "default", t, SAMPLES);
    // Each sample's points lie on the floor plane (y = 0) and move between samples by about a
    // quarter pixel: each was found at the sample's own location.
    let floor = |p: &[f32; 3], n: &[f32; 3]| p[0].is_finite() && n[1] > 0.999 && p[1].abs() < 0.05;
    for (k, s) in four.samples.iter().enumerate() {
        let on_floor: Vec<f32> = s.positions.iter().zip(&s.normals).filter(|(p, n)| floor(p, n)).map(|(p, _)| p[1].abs()).collect();
        assert!(on_floor.len() > 5_000, "sample {k}: {} floor pixels", on_floor.len());
        let worst = on_floor.iter().cloned().fold(0.0f32, f32::max);
        assert!(worst < 1e-3, "sample {k}: floor points up to {worst} off the plane");
    }
    let moved = four.samples[0].positions.iter().zip(&four.samples[3].positions).filter(|(a, b)| a[0].is_finite() && a != b).count();
    assert!(moved > 10_000, "samples 0 and 3 share their positions at {moved} pixels only");
    // The resolve: identical to the single-sample frame inside surfaces and shadows, blended at
    // their edges. Measured on lavapipe 22.3.6: 994 of 19,200 pixels (5.2 %); held to
    // twice that, where the bound was 20 % (a resolve blending four times the edges it should
    // would have passed).
    let differ = one.color.chunks(4).zip(four.color.chunks(4)).filter(|(a, b)| a.iter().zip(*b).any(|(x, y)| x.abs_diff(*y) > 2)).count();
    let pixels = (one.width * one.height) as usize;
    println!("the 4x resolve differs from 1x at {differ} of {pixels} pixels");
    assert!(differ > pixels / 200, "the 4x resolve differs from 1x at {differ} of {pixels} pixels: no antialiasing");
    assert!(differ <= 2 * 994 * pixels / 19_200, "the 4x resolve differs from 1x at {differ} of {pixels} pixels (measured: 994 of 19,200)");
    // A sample's stencil agrees with the single-sample frame's away from edges.
    for (li, (a, b)) in one.stencil.iter().zip(&four.samples[0].stencil).enumerate() {
        let same = a.iter().zip(b).filter(|(x, y)| x == y).count();
        assert!(same > pixels * 9 / 10, "light {li}: sample 0's stencil equals 1x's at {same} of {pixels} pixels");
    }
    r.context().check_validation().unwrap();
}

#[test]
fn what_renders_at_one_sample_is_refused() {
    let Some(mut ctx) = common::context() else { return };
    let refused = [
        ("default", 3, RenderTechnique::default(), Counter::Stencil, View::Shaded, "1, 2, 4 or 8"),
        ("default", 0, RenderTechnique::default(), Counter::Stencil, View::Shaded, "1, 2, 4 or 8"),
        ("default", SAMPLES, RenderTechnique::from(ShadowMap::new(256)), Counter::Stencil, View::Shaded, "shadowmap"),
        ("default", SAMPLES, RenderTechnique::default(), Counter::Float, View::Shaded, "float counter"),
        ("default", SAMPLES, RenderTechnique::default(), Counter::Stencil, View::Volumes, "overlay"),
        ("transparent/depth_4", SAMPLES, RenderTechnique::default(), Counter::Stencil, View::Shaded, "transparent"),
    ];
    for (name, samples, technique, counter, view, needle) in refused {
        let scene = umbrage_scene::load(name).unwrap();
        let opts = RenderOptions { width: 64, height: 48, technique, counter, view, samples, ..Default::default() };
        match Renderer::try_new(ctx, scene, opts) {
            Ok(_) => panic!("{name} {samples} samples {technique:?} {counter:?} {view:?}: accepted"),
            Err(e) => {
                let umbrage_render::NewError { error: err, context: back } = *e;
                assert!(matches!(err, Error::InvalidDesc { field: "RenderOptions::samples", .. }), "{err:?}");
                assert!(err.to_string().contains(needle), "'{err}' should mention {needle}");
                ctx = back;
            }
        }
    }
    // Switching a multisampled renderer to a one-sample method is refused at the frame.
    let scene = umbrage_scene::load("default").unwrap();
    let mut r = Renderer::new(ctx, scene, RenderOptions { width: 64, height: 48, samples: SAMPLES, ..Default::default() }).unwrap();
    r.settings.technique = RenderTechnique::from(ShadowMap::new(256));
    let err = r.render().err().expect("a shadow-map frame at 4 samples");
    assert!(err.to_string().contains("one sample"), "{err}");
    r.settings.technique = Technique::default().into();
    r.render().unwrap();
    r.context().check_validation().unwrap();
}

/// On SwiftShader (a child process; tests/common's `rerun_on_swiftshader`): its multisampled
/// depth is evaluated at the standard locations mirrored in x (docs/conform/drivers-notes.md
/// §1f), which `calibrate_sample_locations` measures; with it every sample of the default
/// scene stays within `SWIFTSHADER_BOUND` of the reference outside the band, and the frame warns
/// of the defect. Measured (320x240, 4 samples): 0 to 8 mismatches per light and sample of
/// ~56,000 (samples whose depth location the mirror moves by 0.75 px: coverage and depth are
/// tested at different points there, so an edge pixel can go either way).
#[test]
fn every_sample_is_bounded_on_swiftshader() {
    common::rerun_on_swiftshader(concat!(module_path!(), "::swiftshader_samples"), &[]);
}

/// At most this fraction of a sample's compared pixels may mismatch outside the band on
/// SwiftShader (§1f): twice the measured worst.
const SWIFTSHADER_BOUND: f64 = 0.0003;

#[test]
#[ignore = "a helper: every_sample_is_bounded_on_swiftshader runs it on SwiftShader"]
fn swiftshader_samples() {
    let ctx = common::context().expect("a Vulkan device");
    assert_eq!(ctx.info.driver, "SwiftShader driver", "{} is not SwiftShader", ctx.info.name);
    let scene = umbrage_scene::load("default").unwrap();
    let opts = RenderOptions { width: 320, height: 240, capture: true, samples: SAMPLES, ..Default::default() };
    let mut r = Renderer::new(ctx, scene, opts).unwrap();
    umbrage_conform::checks::calibrate_sample_locations(&mut r).unwrap();
    let out = r.render().unwrap();
    r.context().check_validation().unwrap();
    assert!(out.stats.warnings.iter().any(|w| w.contains("§1f")), "no §1f warning: {:?}", out.stats.warnings);
    let scene = r.scene();
    let mut worst = 0.0f64;
    for k in 0..SAMPLES as usize {
        let f = out.sample(k).unwrap();
        let positions = f.positions.iter().flatten().copied().collect();
        let normals = f.normals.iter().flatten().copied().collect();
        let dump = umbrage_render::output::scene_dump(scene, (f.width, f.height), positions, normals, f.shadow_masks(scene));
        let report = umbrage_reference::check(&dump, "swiftshader", 1).unwrap();
        for (li, l) in report.lights.iter().enumerate() {
            let m = &l.metrics;
            assert!(m.compared > 40_000, "sample {k} light {li}: only {} compared", m.compared);
            let fraction = m.mismatches_outside_band as f64 / m.compared as f64;
            eprintln!("sample {k} light {li}: {} of {} outside the band", m.mismatches_outside_band, m.compared);
            assert!(fraction <= SWIFTSHADER_BOUND, "sample {k} light {li}: {m:?}");
            worst = worst.max(fraction);
        }
    }
    eprintln!("worst: {:.4} %", worst * 100.0);
}
