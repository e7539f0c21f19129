//! Analytic sphere casters (issue 12 item 1): ray-cast exactly in the G-buffer, shadow volumes
//! from the tangency circle as an n-gon, against the exact CPU reference (which intersects the
//! spheres, not a tessellation). Validation on.

mod common;

use umbrage::accuracy::{evaluate, THRESHOLD};
use umbrage::render::{Counter, RenderOptions, Renderer, Technique};
use umbrage::shadow::Method;

const SCENES: [&str; 2] = ["analytic/sphere_only", "analytic/sphere_and_meshes"];

#[test]
fn sphere_scenes_match_the_reference_with_the_automatic_n() {
    let Some(mut ctx) = common::context() else { return };
    for name in SCENES {
        for counter in [Counter::Stencil, Counter::Float] {
            let scene = umbrage::scene::load(name).unwrap();
            let opts = RenderOptions { width: 320, height: 240, counter, ..Default::default() };
            let mut r = Renderer::new(ctx, scene, opts).unwrap();
            let techniques = [
                Technique::Volumes(Method::McGuire),
                Technique::Volumes(Method::ZFail),
                Technique::Volumes(Method::ZPass),
                Technique::EdgeQuads,
            ];
            for row in evaluate(&mut r, name, &techniques, 1).unwrap() {
                eprintln!(
                    "{name} {} {}: {} / {} ({:.5}%), ambiguous {}",
                    counter.name(),
                    row.method,
                    row.mismatches,
                    row.compared,
                    row.fraction * 100.0,
                    row.ambiguous
                );
                assert!(row.compared > 10_000, "{name}: too few pixels compared");
                assert!(row.fraction <= THRESHOLD, "{name} {} {}: {row:?}", counter.name(), row.method);
            }
            // The stats name every sphere's polygon per light, chosen by the half-pixel rule.
            r.settings.technique = Technique::Volumes(Method::McGuire);
            let out = r.render().unwrap();
            let casting = r.scene().spheres.iter().filter(|s| s.casts_shadow).count();
            for l in &out.stats.lights {
                let spheres: Vec<_> = l.casters.iter().filter(|c| c.path == "sphere").collect();
                assert_eq!(spheres.len(), casting);
                for c in spheres {
                    let s = c.sphere.unwrap();
                    assert!(s.auto && s.error_px <= 0.5 && s.segments >= 8, "{name}: {c:?}");
                    assert_eq!(c.silhouette_edges, s.segments as u64);
                }
            }
            r.context().check_validation().unwrap();
            ctx = r.into_context();
        }
    }
}

#[test]
fn the_g_buffer_holds_the_exact_sphere_surface() {
    let Some(ctx) = common::context() else { return };
    let scene = umbrage::scene::load("analytic/sphere_only").unwrap();
    let opts = RenderOptions { width: 200, height: 150, capture: true, ..Default::default() };
    let mut r = Renderer::new(ctx, scene, opts).unwrap();
    let out = r.render().unwrap();
    let reference = umbrage::reference::Reference::from_scene(r.scene()).render(&r.scene().camera, &r.scene().lights, 200, 150);
    let mut on_spheres = 0;
    let mut worst = 0f64;
    for (i, (p, n)) in out.positions.iter().zip(&out.normals).enumerate() {
        let rp = &reference.pixels[i];
        if !p[0].is_finite() || !rp.hit {
            continue;
        }
        let p = glam::Vec3::from(*p).as_dvec3();
        // On some sphere of the scene, with its exact normal.
        let dist = (p - r.scene().camera.eye.as_dvec3()).length();
        let off = |s: &&umbrage::scene::SceneSphere| ((p - s.sphere.center).length() - s.sphere.radius).abs();
        let on = r.scene().spheres.iter().min_by(|a, b| off(a).total_cmp(&off(b))).filter(|s| off(s) < 1e-5 * dist.max(s.sphere.radius));
        let s = on.unwrap_or_else(|| panic!("pixel {i}: {p} is on no sphere"));
        worst = worst.max(off(&s) / dist);
        let exact = (p - s.sphere.center).normalize();
        assert!(glam::Vec3::from(*n).as_dvec3().normalize().dot(exact) > 0.99999, "pixel {i}: normal {n:?} vs {exact}");
        // The same surface as the reference's camera ray (away from silhouettes).
        if (rp.position.as_dvec3() - p).length() < 1e-2 {
            on_spheres += 1;
        }
    }
    eprintln!("{on_spheres} sphere pixels; worst distance off the sphere / distance from the eye: {worst:.2e}");
    assert!(on_spheres > 20_000, "{on_spheres}");
    r.context().check_validation().unwrap();
}

#[test]
fn too_few_segments_show_and_the_rule_removes_them() {
    let Some(ctx) = common::context() else { return };
    let mut scene = umbrage::scene::load("analytic/sphere_only").unwrap();
    for s in &mut scene.spheres {
        s.segments = Some(5);
    }
    let opts = RenderOptions { width: 320, height: 240, ..Default::default() };
    let mut r = Renderer::new(ctx, scene, opts).unwrap();
    let rows = evaluate(&mut r, "sphere_only n=5", &[Technique::Volumes(Method::McGuire)], 1).unwrap();
    assert!(rows[0].fraction > THRESHOLD, "a pentagon's shadow should differ from a sphere's: {:?}", rows[0]);
    r.context().check_validation().unwrap();
}

#[test]
fn bad_sphere_frames_are_refused_not_drawn() {
    let Some(mut ctx) = common::context() else { return };
    let scene = umbrage::scene::load("analytic/sphere_and_meshes").unwrap();
    let opts = RenderOptions { width: 64, height: 48, ..Default::default() };
    let mut r = Renderer::new(ctx, scene.clone(), opts.clone()).unwrap();
    // Shadow maps do not draw spheres: a clear error, and the renderer keeps working after it.
    r.settings.technique = Technique::ShadowMap { size: 512 };
    let e = r.render().err().expect("refused").to_string();
    assert!(e.contains("sphere"), "{e}");
    r.settings.technique = Technique::Volumes(Method::McGuire);
    r.render().unwrap();
    r.context().check_validation().unwrap();
    ctx = r.into_context();
    // The eye moved inside a sphere; a light moved inside a casting sphere.
    for case in ["eye", "light"] {
        let mut s = scene.clone();
        let c = s.spheres[0].sphere.center.as_vec3();
        match case {
            "eye" => s.camera.eye = c,
            _ => s.lights[0].position = c,
        }
        let mut r = Renderer::new(ctx, s, opts.clone()).unwrap();
        let e = r.render().err().expect("refused").to_string();
        assert!(e.contains("inside"), "{case}: {e}");
        ctx = r.into_context();
    }
}
