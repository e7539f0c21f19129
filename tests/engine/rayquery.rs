//! `--method rayquery` beyond the accuracy table (tests/engine/hard_cases.rs holds it to the reference
//! on every hard case): a moving caster on a device with `VK_KHR_ray_query` (Mesa lavapipe
//! 25.0.7 from `.drivers/` when the system's driver has none: `common::ray_query_context`),
//! with validation on; and, where the default device has no ray query, asking for it is a clear
//! error naming the extension and the script that installs a driver with it.
use crate::common;
use umbrage_render::accuracy::evaluate;
use umbrage_render::{RenderOptions, RenderTechnique, Renderer, ShadowMap, Technique};

/// A caster that moves between frames: the top level is rebuilt from the new transform.
#[test]
fn rayquery_follows_a_moving_caster() {
    let Some(ctx) = common::ray_query_context(concat!(module_path!(), "::rayquery_follows_a_moving_caster")) else { return };
    let scene = umbrage_scene::load("default").unwrap();
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
    r.settings.technique = Technique::RayQuery.into();
    r.settings.counter = umbrage_render::Counter::Float;
    let e = r.render().err().expect("ray query with the float counter must fail");
    assert!(matches!(e, umbrage::Error::InvalidDesc { field: "FrameSettings::counter", .. }), "{e:?}");
    r.context().check_validation().unwrap();
}

#[test]
fn missing_ray_query_is_a_clear_error() {
    let Some(ctx) = common::context() else { return };
    if ctx.features.ray_query {
        // The error needs a device without ray query: the same test on lavapipe 22.3.6.
        drop(ctx);
        common::rerun_without_the_feature(concat!(module_path!(), "::missing_ray_query_is_a_clear_error"));
        return;
    }
    let scene = umbrage_scene::load("default").unwrap();
    let mut r = Renderer::new(ctx, scene, RenderOptions { width: 64, height: 48, ..Default::default() }).unwrap();
    r.settings.technique = Technique::RayQuery.into();
    // The float counter counts volumes: with rays it is refused first, whatever the device.
    r.settings.counter = umbrage_render::Counter::Float;
    let e = r.render().err().expect("ray query with the float counter must fail");
    assert!(matches!(e, umbrage::Error::InvalidDesc { field: "FrameSettings::counter", .. }), "{e:?}");
    r.settings.counter = umbrage_render::Counter::Stencil;
    let e = r.render().err().expect("ray query without the extension must fail").to_string();
    assert!(e.contains("VK_KHR_ray_query") && e.contains("scripts/drivers.sh install 25.0.7"), "{e}");
    // Nothing was left half-made: another technique still renders.
    r.settings.technique = Technique::default().into();
    r.render().unwrap();
    r.context().check_validation().unwrap();
}

/// Every light in one pass (`PassToggles::ray_batch`) traces the same rays as one
/// pass per light: the stencil of every light and the picture are the same, bit for bit, on a
/// scene with three lights, an area light of 40 samples (two batches) and the analytic spheres.
#[test]
fn batched_rays_are_the_per_light_rays() {
    let Some(mut ctx) = common::ray_query_context(concat!(module_path!(), "::batched_rays_are_the_per_light_rays")) else { return };
    for name in ["default", "area/disc", "analytic/sphere_and_meshes"] {
        let mut scene = umbrage_scene::load(name).unwrap();
        for l in scene.lights.iter_mut() {
            if let Some(a) = &mut l.area {
                a.samples = 40;
            }
        }
        let opts = RenderOptions { width: 200, height: 150, ..Default::default() };
        let mut r = Renderer::new(ctx, scene, opts).unwrap();
        r.settings.technique = Technique::RayQuery.into();
        r.settings.capture = true;
        r.settings.toggles.ray_batch = true;
        let batched = r.render().unwrap();
        assert!(batched.stats.ray_query.as_ref().unwrap().batched, "{name}: not batched");
        let lights = batched.stencil.len();
        assert!(lights >= 2, "{name}: {lights} lights");
        r.settings.toggles.ray_batch = false;
        let single = r.render().unwrap();
        assert!(!single.stats.ray_query.as_ref().unwrap().batched);
        for (li, (b, s)) in batched.stencil.iter().zip(&single.stencil).enumerate() {
            let differ = b.iter().zip(s).filter(|(x, y)| x != y).count();
            assert_eq!(differ, 0, "{name}, light {li}: {differ} stencil values differ between batched and per-light rays");
            assert!(b.iter().all(|&v| v <= 1), "{name}, light {li}: a ray writes 0 or 1");
        }
        assert!(batched.stencil.iter().flatten().any(|&v| v == 1), "{name}: no shadow at all");
        assert_eq!(batched.color, single.color, "{name}: the pictures differ");
        r.context().check_validation().unwrap();
        ctx = r.into_context();
    }
}

/// A caster that deforms between frames (`Renderer::set_mesh_positions`, the pass's
/// `update_positions`): its bottom level is rebuilt once with ALLOW_UPDATE, then refitted in
/// place; each frame matches the CPU reference of the deformed scene, as the volumes do.
#[test]
fn rayquery_follows_a_deforming_caster() {
    let Some(ctx) = common::ray_query_context(concat!(module_path!(), "::rayquery_follows_a_deforming_caster")) else { return };
    let scene = umbrage_scene::load("default").unwrap();
    let opts = RenderOptions { width: 160, height: 120, ..Default::default() };
    let mut r = Renderer::new(ctx, scene, opts).unwrap();
    let i = r.scene().meshes.iter().position(|m| m.casts_shadow).unwrap();
    let rest = r.scene().meshes[i].mesh.positions.clone();
    r.settings.technique = Technique::RayQuery.into();
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
        r.settings.technique = Technique::RayQuery.into();
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
    // A shadow-map frame after the ray-query ones prepares no rays (no top level, no stats).
    r.settings.technique = RenderTechnique::ShadowMap(ShadowMap { size: 256, pcf: Default::default(), cube: Default::default() });
    let s = r.render().unwrap().stats;
    assert!(s.ray_query.is_none(), "a shadow-map frame prepared ray query: {:?}", s.ray_query);
    // A wrong vertex count is refused and changes nothing.
    assert!(r.set_mesh_positions(i, &rest[..rest.len() - 1]).is_err());
    r.context().check_validation().unwrap();
}

/// `umbrage bench` gives ray query's acceleration work its own columns: the bottom levels'
/// build, a deforming caster's refit and the top level, as GPU times, beside the row's shadow
/// time (issue 20); other techniques leave them empty, and the refit leaves the scene as it was.
#[test]
fn the_classic_bench_times_builds_refits_and_top_levels() {
    let Some(ctx) = common::ray_query_context(concat!(module_path!(), "::the_classic_bench_times_builds_refits_and_top_levels")) else {
        return;
    };
    let cfg = umbrage_bench::BenchConfig {
        scenes: vec!["default".into()],
        techniques: vec![Technique::RayQuery.into(), RenderTechnique::default()],
        counters: vec![umbrage_render::Counter::Stencil],
        frames: 2,
        opts: RenderOptions { width: 160, height: 120, ..Default::default() },
        compute_draws: Vec::new(),
        mesh_task: Vec::new(),
        motion: false,
    };
    let report = umbrage_bench::run(ctx, &cfg, |_| {}).unwrap();
    let rays = report.rows.iter().find(|r| r.method == "rayquery").expect("a rayquery row");
    for (what, v) in [("build", rays.blas_build_ms), ("refit", rays.blas_refit_ms), ("top level", rays.gpu_tlas_ms)] {
        assert!(v.is_some_and(|ms| ms > 0.0 && ms.is_finite()), "{what}: {v:?}");
    }
    assert_eq!(rays.error_fraction, 0.0, "rayquery is exact on the default scene");
    let volumes = report.rows.iter().find(|r| r.method != "rayquery").unwrap();
    assert_eq!((volumes.blas_build_ms, volumes.blas_refit_ms, volumes.gpu_tlas_ms), (None, None, None));
    let md = report.markdown();
    assert!(md.contains("BLAS build / refit / TLAS ms"), "{md}");
}

/// The GPU cost of the acceleration structures, from each frame's acceleration span
/// (`gpu_ms.accel`: everything `cmd_before_rendering` records): the first frame's bottom-level
/// builds, the frame that compacts them, the top level alone, and a deforming caster's first
/// rebuild (`ALLOW_UPDATE`) and later refits. Writes docs/raytrace/accel.md. Timing, so run on
/// purpose, in release: `cargo test --release --test engine rayquery:: -- --ignored` (on lavapipe 25.0.7
/// when the system driver has no ray query).
#[test]
#[ignore = "timing, writes docs/raytrace/accel.md: run with cargo test --release --test engine rayquery:: -- --ignored"]
fn write_docs_raytrace_accel_md() {
    let Some(ctx) = common::ray_query_context(concat!(module_path!(), "::write_docs_raytrace_accel_md")) else { return };
    let median = |mut v: Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    let spheres = |seg: u32, rings: u32| {
        let mut t = String::from("[camera]\neye = [0.0, 9.0, 12.0]\ntarget = [0.0, 0.0, 0.0]\n[[light]]\nkind = \"point\"\nposition = [2.0, 12.0, 3.0]\n[[mesh]]\nshape = \"plane\"\nsize = [40.0, 40.0]\ncasts_shadow = false\n");
        for (x, z) in [(-3, -3), (-3, 3), (3, -3), (3, 3)] {
            t += &format!(
                "[[mesh]]\nshape = \"sphere\"\nradius = 1.2\nsegments = {seg}\nrings = {rings}\ntranslate = [{x}.0, 1.5, {z}.0]\n"
            );
        }
        t
    };
    let mut doc = format!(
        "# Acceleration-structure cost (GPU)\n\nGenerated by `cargo test --release --test engine rayquery:: -- --ignored` on {} (960x540, \
         validation off unless `UMBRAGE_VALIDATION` is set). Each cell is the GPU time of a frame's acceleration span (everything \
         `ShadowPass::cmd_before_rendering` records for `Technique::RayQuery`), ms: the first frame builds every bottom level; \
         the frame whose slot comes round again compacts them (on lavapipe a copy at the same size); every other frame rebuilds \
         only the top level (median of 8). The deforming caster is the scene's largest: its first deformation rebuilds its \
         bottom level with `ALLOW_UPDATE`, later ones refit it in place (median of 6).\n\n\
         | scene | casters' triangles | first frame: bottom levels + top level | compaction frame | top level only | deform: rebuild | deform: refit | bottom-level bytes |\n\
         |---|---:|---:|---:|---:|---:|---:|---:|\n",
        ctx.info.name
    );
    let mut ctx = Some(ctx);
    let cases: Vec<(String, umbrage_scene::Scene)> = vec![
        ("default".into(), umbrage_scene::load("default").unwrap()),
        ("bench/vertex".into(), umbrage_scene::load("bench/vertex").unwrap()),
        ("4 spheres, 64 x 33".into(), umbrage_scene::load_str(&spheres(64, 33), "s64", std::path::Path::new(".")).unwrap()),
        ("4 spheres, 500 x 251".into(), umbrage_scene::load_str(&spheres(500, 251), "s500", std::path::Path::new(".")).unwrap()),
    ];
    for (name, scene) in cases {
        let tris: usize = scene.meshes.iter().filter(|m| m.casts_shadow).map(|m| m.mesh.triangles.len()).sum();
        let big = (0..scene.meshes.len())
            .filter(|&i| scene.meshes[i].casts_shadow)
            .max_by_key(|&i| scene.meshes[i].mesh.triangles.len())
            .unwrap();
        let rest = scene.meshes[big].mesh.positions.clone();
        let mut r = Renderer::new(ctx.take().unwrap(), scene, RenderOptions { width: 960, height: 540, ..Default::default() }).unwrap();
        r.settings.technique = Technique::RayQuery.into();
        let frame = |r: &mut Renderer| {
            let s = r.render().unwrap().stats;
            (s.gpu_ms.expect("timestamps").accel, s.ray_query.unwrap())
        };
        let (build_ms, first) = frame(&mut r);
        assert!(first.builds > 0);
        let (mut compact_ms, mut top) = (None, Vec::new());
        for _ in 0..10 {
            let (ms, q) = frame(&mut r);
            match q.compactions {
                0 => top.push(ms),
                _ => compact_ms = Some(ms),
            }
        }
        let bytes = frame(&mut r).1.bottom_level_bytes;
        let deform = |r: &mut Renderer, k: usize| {
            let s = 1.0 + 0.01 * k as f32;
            let moved: Vec<glam::Vec3> = rest.iter().map(|p| *p * glam::Vec3::new(s, 1.0 / s, 1.0)).collect();
            r.set_mesh_positions(big, &moved).unwrap();
            frame(r)
        };
        let (rebuild_ms, q) = deform(&mut r, 1);
        assert_eq!((q.builds, q.refits), (1, 0));
        let refit: Vec<f64> = (2..8)
            .map(|k| {
                let (ms, q) = deform(&mut r, k);
                assert_eq!((q.builds, q.refits), (0, 1));
                ms
            })
            .collect();
        doc += &format!(
            "| {name} | {tris} | {build_ms:.2} | {} | {:.3} | {rebuild_ms:.2} | {:.2} | {:.1} MB |\n",
            compact_ms.map_or("-".into(), |m| format!("{m:.2}")),
            median(top),
            median(refit),
            bytes as f64 / 1e6
        );
        r.context().check_validation().unwrap();
        ctx = Some(r.into_context());
    }
    std::fs::write(concat!(env!("CARGO_MANIFEST_DIR"), "/docs/raytrace/accel.md"), doc).unwrap();
}

/// Area lights as N point-light samples: every sample's rays in one pass per 32
/// (`PassToggles::ray_batch`) against one ray pass per sample, and McGuire's volumes, GPU
/// shadow ms side by side (medians of 6 frames, round-robin). The error is the same for both
/// ray variants (the same rays: `batched_rays_are_the_per_light_rays`). Writes
/// docs/raytrace/batch.md; timing, so run on purpose:
/// `cargo test --release --test engine rayquery:: -- --ignored`.
#[test]
#[ignore = "timing, writes docs/raytrace/batch.md: run with cargo test --release --test engine rayquery:: -- --ignored"]
fn write_docs_raytrace_batch_md() {
    let Some(mut ctx) = common::ray_query_context(concat!(module_path!(), "::write_docs_raytrace_batch_md")) else { return };
    let median = |mut v: Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    let mut doc = format!(
        "# Ray query: one pass per light, or every light in one pass\n\nGenerated by `cargo test --release --test engine rayquery:: -- \
         --ignored` on {} (960x540, the `area/disc` scene with its disc light split into N samples, and `default` with its three \
         lights). GPU shadow ms of the whole frame (every light's determination), medians of 6 frames measured round-robin. \
         `batched`: `rayquery.wgsl`'s `batch` traces every sample's ray in one pass per 32 samples into a bit mask, and each \
         sample's determination turns its bit into the stencil (`PassToggles::ray_batch`); `per light`: one ray pass per sample \
         (the default). Both write the same stencil, bit for bit.\n\n\
         | scene | lights | rayquery, batched | rayquery, per light | batched / per light | mcguire | batched / mcguire |\n\
         |---|---:|---:|---:|---:|---:|---:|\n",
        ctx.info.name
    );
    let cases: Vec<(&str, Option<u32>)> =
        vec![("default", None), ("area/disc", Some(1)), ("area/disc", Some(4)), ("area/disc", Some(16)), ("area/disc", Some(64))];
    for (name, samples) in cases {
        let mut scene = umbrage_scene::load(name).unwrap();
        for l in scene.lights.iter_mut() {
            if let (Some(a), Some(n)) = (&mut l.area, samples) {
                a.samples = n;
            }
        }
        let mut r = Renderer::new(ctx, scene, RenderOptions { width: 960, height: 540, ..Default::default() }).unwrap();
        let variants = [(Technique::RayQuery, true), (Technique::RayQuery, false), (Technique::default(), true)];
        let mut times = vec![Vec::new(); variants.len()];
        for round in 0..7 {
            for (k, (t, batch)) in variants.iter().enumerate() {
                r.settings.technique = (*t).into();
                r.settings.toggles.ray_batch = *batch;
                let s = r.render().unwrap().stats;
                if round > 0 {
                    times[k].push(s.gpu_ms.expect("timestamps").shadow);
                }
            }
        }
        let [b, p, m] = [0, 1, 2].map(|k| median(times[k].clone()));
        let lights = r.scene().lights.len();
        doc += &format!("| `{name}` | {lights} | {b:.2} | {p:.2} | {:.2}x | {m:.2} | {:.1}x |\n", b / p, b / m);
        r.context().check_validation().unwrap();
        ctx = r.into_context();
    }
    std::fs::write(concat!(env!("CARGO_MANIFEST_DIR"), "/docs/raytrace/batch.md"), doc).unwrap();
}

/// `ShadowPass` with `Technique::RayQuery`, as an embedding host meets it on a device with ray
/// query: every misuse is a typed error before anything is recorded (MSAA, a render pass, the
/// float counter, no G-buffer, a bad offset, transparent casters, volume calls on a ray frame),
/// and a host that did not enable the feature is told so.
#[test]
fn the_pass_refuses_ray_query_misuse() {
    use umbrage::error::Misuse;
    use umbrage::pass::diagnostics::Diagnostics;
    use umbrage::pass::*;
    use umbrage::Error;
    let Some(ctx) = common::ray_query_context(concat!(module_path!(), "::the_pass_refuses_ray_query_misuse")) else { return };
    let new = |d: &ShadowPassDesc| ShadowPass::new(&ctx.instance, ctx.physical, &ctx.device, (*ctx.allocator).clone(), d);
    let rq = PassSettings { technique: Technique::RayQuery, ..Default::default() };
    let features = EnabledFeatures { ray_query: true, ..Default::default() };
    let base = ShadowPassDesc { depth_stencil_format: ctx.depth_format, features, ..Default::default() };
    // The host did not enable it: refused, whatever the device has.
    let mut off = new(&ShadowPassDesc { features: EnabledFeatures::default(), ..base.clone() }).unwrap();
    assert!(!off.capabilities().ray_query);
    assert!(matches!(off.set_settings(rq), Err(Error::Unsupported(m)) if m.contains("EnabledFeatures::ray_query")));
    let inputs = RayQueryInputs { position: ash::vk::ImageView::null(), normal: ash::vk::ImageView::null(), surface_offset: 1e-4 };
    assert!(matches!(off.set_ray_query_inputs(inputs), Err(Error::Unsupported(_))));
    // One sample and dynamic rendering only.
    match new(&ShadowPassDesc { samples: 4, settings: rq, ..base.clone() }) {
        Err(Error::Unsupported(m)) => assert!(m.contains("4 samples"), "{m}"),
        other => panic!("ray query with 4 samples: {:?}", other.err()),
    }
    let mut p = new(&base).unwrap();
    assert!(p.capabilities().ray_query);
    assert!(matches!(p.set_settings(PassSettings { counter: Counter::Float, ..rq }), Err(Error::InvalidDesc { .. })));
    p.set_settings(rq).unwrap();
    let cube = umbrage_scene::shapes::cuboid(glam::Vec3::ONE);
    p.add_caster("cube", &cube, glam::DMat4::from_translation(glam::DVec3::Y)).unwrap();
    let cam = umbrage::geom::Camera { eye: glam::Vec3::new(0.0, 3.0, 6.0), target: glam::Vec3::ZERO, ..Default::default() };
    let view_m = glam::camera::rh::view::look_at_mat4(cam.eye, cam.target, cam.up);
    let view = ShadowView::from_view_matrix(cam.eye.as_dvec3(), view_m, cam.proj_infinite(4.0 / 3.0), (64, 48)).unwrap();
    let lights =
        [umbrage::geom::Light::point(glam::Vec3::new(1.0, 5.0, 2.0)), umbrage::geom::Light::point(glam::Vec3::new(-1.0, 5.0, 2.0))];
    // No G-buffer yet.
    match p.prepare(0, &view, &lights) {
        Err(Error::Misuse(Misuse::NotConfigured { needs, .. })) => assert!(needs.contains("set_ray_query_inputs")),
        other => panic!("a ray frame without inputs: {:?}", other.err()),
    }
    for bad in [-1.0, f32::NAN, f32::INFINITY] {
        assert!(p.set_ray_query_inputs(RayQueryInputs { surface_offset: bad, ..inputs }).is_err(), "offset {bad} accepted");
    }
    // A real G-buffer (never written: nothing is drawn from it here).
    let extent = ash::vk::Extent2D { width: 64, height: 48 };
    let usage = ash::vk::ImageUsageFlags::SAMPLED | ash::vk::ImageUsageFlags::COLOR_ATTACHMENT;
    let color = ash::vk::ImageAspectFlags::COLOR;
    let mut pos = umbrage::gpu::Image::new_2d(&ctx, "positions", ash::vk::Format::R32G32B32A32_SFLOAT, extent, usage, color).unwrap();
    let mut nrm = umbrage::gpu::Image::new_2d(&ctx, "normals", ash::vk::Format::R32G32B32A32_SFLOAT, extent, usage, color).unwrap();
    p.set_ray_query_inputs(RayQueryInputs { position: pos.view, normal: nrm.view, ..inputs }).unwrap();
    for batch in [false, true] {
        p.set_settings(PassSettings { toggles: PassToggles { ray_batch: batch, ..Default::default() }, ..rq }).unwrap();
        let frame = p.prepare(0, &view, &lights).unwrap();
        let info = frame.ray_query().expect("a ray-query frame says so");
        assert_eq!((info.instances, info.batched), (1, batch));
        assert_eq!(frame.totals.triangles.total(), 0, "a ray frame plans no volumes");
        let target = DepthStencilTarget::new(ash::vk::Image::null(), ash::vk::ImageView::null(), extent);
        let mut refused = Vec::new();
        ctx.one_shot(|cb| {
            // SAFETY: every call below is refused before it records anything (asserted).
            unsafe {
                refused.push(p.cmd_draw_volumes(cb, &frame, 0, VolumeKind::Stencil).err());
                refused.push(p.cmd_count_rasterised(cb, &frame, 0, &target).err());
                refused.push(p.cmd_count_float(cb, &frame, 0, &target, ash::vk::ImageView::null()).err());
                refused.push(p.cmd_draw_volume_overlay(cb, &frame).err());
            }
        })
        .unwrap();
        for e in refused {
            assert!(matches!(e, Some(Error::Misuse(Misuse::NotConfigured { .. }))), "{e:?}");
        }
    }
    // Transparent casters are not traced yet.
    let mut t = new(&ShadowPassDesc { transmit_format: Some(ash::vk::Format::R16G16B16A16_SFLOAT), settings: rq, ..base.clone() }).unwrap();
    t.add_transparent_caster("glass", &cube, glam::DMat4::IDENTITY, glam::Vec3::splat(0.5)).unwrap();
    t.set_ray_query_inputs(RayQueryInputs { position: pos.view, normal: nrm.view, ..inputs }).unwrap();
    assert!(matches!(t.prepare(0, &view, &lights), Err(Error::Unsupported(m)) if m.contains("glass")));
    drop((p, t, off));
    pos.destroy(&ctx);
    nrm.destroy(&ctx);
    ctx.check_validation().unwrap();
}
