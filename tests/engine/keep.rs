//! Plans kept across frames (`PassSettings::keep`): what each kind of change replans, what
//! the budget evicts, and what the frame statistics say. (That the pictures are the same,
//! byte for byte, is `tests/pass_sequences`'s job.)

use crate::common;

use ash::vk;
use glam::{DMat4, DVec3, Vec3};
use umbrage::geom::{Camera, Light, LightKind};
use umbrage::pass::{PassSettings, PreparedFrame, ShadowPass, ShadowPassDesc, ShadowView, Technique};
use umbrage::shadow::Method;
use umbrage_scene::shapes;

fn pass(ctx: &umbrage::gpu::Context, desc: ShadowPassDesc) -> ShadowPass {
    let desc = ShadowPassDesc { depth_stencil_format: ctx.depth_format, frames_in_flight: 1, ..desc };
    ShadowPass::new(&ctx.instance, ctx.physical, &ctx.device, (*ctx.allocator).clone(), &desc).unwrap()
}

fn view(eye: Vec3) -> ShadowView {
    let cam = Camera { eye, target: Vec3::ZERO, ..Default::default() };
    ShadowView {
        eye: cam.eye.as_dvec3(),
        view: glam::camera::rh::view::look_at_mat4(Vec3::ZERO, cam.target - cam.eye, cam.up),
        proj: cam.proj_infinite(4.0 / 3.0),
        width: 160,
        height: 120,
    }
}

fn point(p: Vec3, radius: Option<f32>) -> Light {
    Light { radius, ..Light::point(p) }
}

/// Four casters in a row along x.
fn casters(pass: &mut ShadowPass) -> Vec<umbrage::pass::CasterId> {
    let meshes = [shapes::cuboid(Vec3::splat(0.6)), shapes::sphere(0.4, 10, 6), shapes::torus(0.4, 0.15, 10, 6), shapes::cuboid(Vec3::ONE)];
    meshes
        .iter()
        .enumerate()
        .map(|(i, m)| pass.add_caster("c", m, DMat4::from_translation(DVec3::new(i as f64 * 1.5 - 2.25, 0.5, 0.0))).unwrap())
        .collect()
}

/// Prepares slot 0 and records its uploads (so the next frame sends only what it plans).
fn frame(ctx: &umbrage::gpu::Context, pass: &mut ShadowPass, eye: Vec3, lights: &[Light]) -> PreparedFrame {
    let f = pass.prepare(0, &view(eye), lights).unwrap();
    // SAFETY: `cb` is recording outside rendering; one_shot waits for it before returning.
    ctx.one_shot(|cb: vk::CommandBuffer| unsafe { pass.cmd_before_rendering(cb, &f).unwrap() }).unwrap();
    f
}

const EYE: Vec3 = Vec3::new(0.0, 3.0, 7.0);

/// After a move: the next frame plans the `n` pairs that moved again and keeps them (they
/// stand still now), the one after plans nothing and sends nothing.
fn settle(ctx: &umbrage::gpu::Context, pass: &mut ShadowPass, eye: Vec3, lights: &[Light], n: u64) {
    let f = frame(ctx, pass, eye, lights);
    assert_eq!(f.totals.pairs_replanned, n, "{:?}", f.totals);
    let before = f.totals.kept_bytes;
    drop(f);
    let f = frame(ctx, pass, eye, lights);
    assert_eq!((f.totals.pairs_replanned, f.totals.bytes_sent, f.totals.kept_bytes), (0, 0, before), "{:?}", f.totals);
}

#[test]
fn each_change_replans_what_it_touches_and_nothing_else() {
    let Some(ctx) = common::context() else { return };
    let mut p = pass(&ctx, ShadowPassDesc { plan_threads: 2, ..Default::default() });
    let ids = casters(&mut p);
    let lights = [point(Vec3::new(1.0, 5.0, 2.0), None), point(Vec3::new(-2.0, 4.0, 1.0), Some(20.0))];
    let f = frame(&ctx, &mut p, EYE, &lights);
    let t = &f.totals;
    assert_eq!((t.pairs_total, t.pairs_replanned, t.pairs_kept), (8, 8, 0), "{t:?}");
    assert!(t.kept_bytes > 0 && t.bytes_sent >= t.kept_bytes, "{t:?}");
    drop(f);

    // nothing changed: every pair kept, nothing sent
    let f = frame(&ctx, &mut p, EYE, &lights);
    let t = &f.totals;
    assert_eq!((t.pairs_total, t.pairs_replanned, t.pairs_kept, t.bytes_sent, t.kept_evictions), (8, 0, 8, 0, 0), "{t:?}");
    let kept_bytes = t.kept_bytes;
    drop(f);

    // the camera moves a little (the same cases): still nothing planned or sent
    let f = frame(&ctx, &mut p, EYE + Vec3::new(0.3, 0.1, -0.2), &lights);
    assert_eq!((f.totals.pairs_replanned, f.totals.pairs_kept, f.totals.bytes_sent), (0, 8, 0), "{:?}", f.totals);
    drop(f);

    // one caster moves: its two pairs are planned again, its old lists dropped; while it
    // moves they are drawn from the stream (nothing kept), once it stands still they are kept
    p.set_transform(ids[1], DMat4::from_translation(DVec3::new(-0.75, 0.8, 0.3))).unwrap();
    let f = frame(&ctx, &mut p, EYE, &lights);
    let t = &f.totals;
    assert_eq!((t.pairs_replanned, t.pairs_kept, t.kept_evictions), (2, 6, 2), "{t:?}");
    assert!(t.bytes_sent > 0 && t.kept_bytes < kept_bytes, "{t:?}");
    drop(f);
    settle(&ctx, &mut p, EYE, &lights, 2);

    // one caster deforms: the same
    let scaled: Vec<Vec3> = shapes::torus(0.4, 0.15, 10, 6).positions.iter().map(|v| *v * 1.2).collect();
    p.update_positions(ids[2], &scaled).unwrap();
    let f = frame(&ctx, &mut p, EYE, &lights);
    assert_eq!((f.totals.pairs_replanned, f.totals.pairs_kept, f.totals.kept_evictions), (2, 6, 2), "{:?}", f.totals);
    drop(f);
    settle(&ctx, &mut p, EYE, &lights, 2);

    // one light moves: its four pairs are planned again (the other light's stay kept)
    let moved = [lights[0].clone(), point(Vec3::new(-2.0, 4.5, 1.0), Some(20.0))];
    let f = frame(&ctx, &mut p, EYE, &moved);
    assert_eq!((f.totals.pairs_replanned, f.totals.pairs_kept, f.totals.kept_evictions), (4, 4, 0), "{:?}", f.totals);
    drop(f);
    settle(&ctx, &mut p, EYE, &moved, 4);

    // a light's range changes but still reaches every caster: only culling depends on it
    let wider = [lights[0].clone(), point(Vec3::new(-2.0, 4.5, 1.0), Some(30.0))];
    let f = frame(&ctx, &mut p, EYE, &wider);
    assert_eq!((f.totals.pairs_replanned, f.totals.pairs_kept), (0, 8), "{:?}", f.totals);
    drop(f);

    // a range that reaches no caster: its pairs are culled, not planned
    let short = [lights[0].clone(), point(Vec3::new(-2.0, 9.0, 1.0), Some(1.0))];
    let f = frame(&ctx, &mut p, EYE, &short);
    assert_eq!((f.totals.pairs_total, f.totals.pairs_replanned, f.totals.pairs_kept), (4, 0, 4), "{:?}", f.totals);
    assert_eq!(f.totals.cases.culled, 4);
    drop(f);

    // the method changes the lists: planned again, kept beside the old ones
    let s = p.settings();
    p.set_settings(PassSettings { technique: Technique::Volumes(Method::ZFail), ..s }).unwrap();
    let f = frame(&ctx, &mut p, EYE, &lights);
    assert_eq!((f.totals.pairs_replanned, f.totals.pairs_kept), (8, 0), "{:?}", f.totals);
    assert!(f.totals.kept_bytes > kept_bytes);
    drop(f);

    // keeping off: everything planned, every kept list dropped
    p.set_settings(PassSettings { keep: false, ..s }).unwrap();
    let f = frame(&ctx, &mut p, EYE, &lights);
    let t = &f.totals;
    assert_eq!((t.pairs_total, t.pairs_replanned, t.pairs_kept, t.kept_bytes), (8, 8, 0, 0), "{t:?}");
    assert!(t.kept_evictions > 0 && t.bytes_sent > 0, "{t:?}");
    assert_eq!(f.cpu_ms.cull, 0.0);
    drop(f);
    let f = frame(&ctx, &mut p, EYE, &lights);
    assert_eq!((f.totals.kept_evictions, f.totals.pairs_replanned), (0, 8), "{:?}", f.totals);
    drop(f);
    drop(p);
    ctx.check_validation().unwrap();
}

#[test]
fn a_case_change_draws_the_lists_of_the_new_case() {
    let Some(ctx) = common::context() else { return };
    let mut p = pass(&ctx, ShadowPassDesc::default());
    casters(&mut p);
    // right above the first box (0.6 wide, from y = 0.2 to 0.8)
    let lights = [point(Vec3::new(-2.25, 6.0, 0.0), None)];
    let under = Vec3::new(-2.25, 0.05, 0.1);
    // outside every volume, then under the box (inside its shadow): z-pass, then z-fail
    let outside = frame(&ctx, &mut p, EYE, &lights);
    let inside = frame(&ctx, &mut p, under, &lights);
    assert!(inside.totals.cases.zpass < outside.totals.cases.zpass, "{:?} {:?}", outside.totals.cases, inside.totals.cases);
    assert!(inside.totals.pairs_replanned > 0 && inside.totals.triangles.dark_cap > 0, "{:?}", inside.totals);
    // and back: both cases' lists are kept
    drop((outside, inside));
    let back = frame(&ctx, &mut p, EYE, &lights);
    assert_eq!((back.totals.pairs_replanned, back.totals.pairs_kept), (0, 4), "{:?}", back.totals);
    let again = frame(&ctx, &mut p, under, &lights);
    assert_eq!((again.totals.pairs_replanned, again.totals.pairs_kept), (0, 4), "{:?}", again.totals);
    drop((back, again));
    drop(p);
    ctx.check_validation().unwrap();
}

#[test]
fn the_budget_evicts_the_least_recently_drawn() {
    let Some(ctx) = common::context() else { return };
    // measure one frame's lists, then allow a bit more than one light's worth
    let mut probe = pass(&ctx, ShadowPassDesc::default());
    casters(&mut probe);
    let a = [point(Vec3::new(1.0, 5.0, 2.0), None)];
    let b = [point(Vec3::new(-1.0, 5.0, 2.0), None)];
    let one = frame(&ctx, &mut probe, EYE, &a).totals.kept_bytes;
    drop(probe);
    let mut probe = pass(&ctx, ShadowPassDesc::default());
    casters(&mut probe);
    let other = frame(&ctx, &mut probe, EYE, &b).totals.kept_bytes;
    drop(probe);
    // room for either light's lists, not both
    let budget = one.max(other);
    assert!(one.min(other) > 0);
    let mut p = pass(&ctx, ShadowPassDesc { keep_budget_bytes: budget, ..Default::default() });
    casters(&mut p);
    let fa = frame(&ctx, &mut p, EYE, &a);
    assert_eq!((fa.totals.kept_bytes, fa.totals.kept_evictions, fa.totals.pairs_replanned), (one, 0, 4));
    drop(fa);
    // the light moves to b: drawn from the stream while it moves, nothing evicted
    let fb = frame(&ctx, &mut p, EYE, &b);
    assert_eq!((fb.totals.kept_bytes, fb.totals.kept_evictions, fb.totals.pairs_replanned), (one, 0, 4));
    drop(fb);
    // it stays: light b's lists do not fit beside a's, a's (least recently drawn) go
    let fb = frame(&ctx, &mut p, EYE, &b);
    assert!(fb.totals.kept_bytes <= budget && fb.totals.kept_evictions > 0, "{:?}", fb.totals);
    drop(fb);
    let fb2 = frame(&ctx, &mut p, EYE, &b);
    assert_eq!(fb2.totals.pairs_replanned, 0, "{:?}", fb2.totals);
    drop(fb2);
    let fa2 = frame(&ctx, &mut p, EYE, &a);
    assert!(fa2.totals.pairs_replanned > 0, "{:?}", fa2.totals);
    drop(fa2);
    // both lights in one frame: what does not fit is drawn from the stream, never over budget
    let both = [a[0].clone(), b[0].clone()];
    for _ in 0..2 {
        let f = frame(&ctx, &mut p, EYE, &both);
        assert!(f.totals.kept_bytes <= budget, "{:?}", f.totals);
        assert_eq!(f.totals.pairs_total, 8);
        assert!(f.totals.pairs_replanned > 0, "{:?}", f.totals);
    }
    drop(p);
    ctx.check_validation().unwrap();
}

#[test]
fn techniques_that_plan_elsewhere_keep_nothing() {
    let Some(ctx) = common::context() else { return };
    let mut p = pass(&ctx, ShadowPassDesc::default());
    casters(&mut p);
    let lights = [Light { kind: LightKind::Point, ..point(Vec3::new(1.0, 5.0, 2.0), None) }];
    let s = p.settings();
    for t in [Technique::Volumes(Method::ZPassClear), Technique::EdgeQuads, Technique::Compute] {
        p.set_settings(PassSettings { technique: t, ..s }).unwrap();
        for _ in 0..2 {
            let f = frame(&ctx, &mut p, EYE, &lights);
            assert_eq!((f.totals.pairs_kept, f.totals.kept_bytes), (0, 0), "{t:?}: {:?}", f.totals);
            assert_eq!(f.totals.pairs_replanned, f.totals.pairs_total);
        }
    }
    drop(p);
    ctx.check_validation().unwrap();
}

/// The pairs to plan go to threads past 1.5M caster triangles (`PARALLEL_MIN_TRIANGLES` in
/// src/pass/keep.rs): four spheres of 409,600 triangles (1.64M) plan on two threads what one
/// thread plans, pair for pair (case, silhouette, triangles and bytes of every caster) and in
/// the frame's totals, on the first frame (every pair planned) and after the light moved.
/// (Mutation-checked: joining the threads' runs in reverse order fails it.)
#[test]
fn two_planning_threads_plan_what_one_plans() {
    let Some(ctx) = common::context() else { return };
    let sphere = shapes::sphere(0.4, 640, 320);
    assert!(4 * sphere.triangles.len() > 1_500_000, "the frame must reach the threads' threshold");
    let mut passes: Vec<ShadowPass> = [1, 2].map(|plan_threads| pass(&ctx, ShadowPassDesc { plan_threads, ..Default::default() })).into();
    for p in &mut passes {
        for i in 0..4 {
            p.add_caster("sphere", &sphere, DMat4::from_translation(DVec3::new(i as f64 * 1.5 - 2.25, 0.5, 0.0))).unwrap();
        }
    }
    for light in [Vec3::new(1.0, 5.0, 2.0), Vec3::new(-1.0, 4.0, 1.0)] {
        let lights = [point(light, None)];
        let frames: Vec<PreparedFrame> = passes.iter_mut().map(|p| frame(&ctx, p, EYE, &lights)).collect();
        let (one, two) = (&frames[0], &frames[1]);
        assert_eq!(two.totals.pairs_replanned, 4, "{:?}", two.totals);
        assert_eq!(format!("{:?}", one.totals.triangles), format!("{:?}", two.totals.triangles));
        assert_eq!((one.totals.bytes_sent, one.totals.kept_bytes), (two.totals.bytes_sent, two.totals.kept_bytes));
        let summary = |f: &PreparedFrame| -> Vec<String> {
            f.lights
                .iter()
                .flat_map(|l| l.stats.casters.iter())
                .map(|c| format!("{:?} {} {:?} {} {}", c.case, c.silhouette_edges, c.triangles, c.index_bytes, c.vertex_bytes))
                .collect()
        };
        assert_eq!(summary(one), summary(two), "light at {light}");
        assert!(summary(one).len() == 4 && one.totals.triangles.total() > 0);
    }
    drop(passes);
    ctx.check_validation().unwrap();
}
