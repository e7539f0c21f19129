//! Real pixels: a region that must be shadowed is dark, a lit one is bright, and the stencil
//! counts read back are the expected ones (one box = 1, two stacked boxes = 2), for every
//! method that should handle the view, including the eye inside the volumes.
use crate::common;
use umbrage::shadow::Method;
use umbrage_render::{CubeFaces, DepthMode, Pcf, RenderOptions, RenderTechnique, Renderer, ShadowMap, Technique};

/// Two boxes stacked above a floor, a point light straight above, camera looking down at the
/// floor from the side. Floor at the centre of the image lies in both boxes' shadows.
const STACK: &str = r#"
ambient = [0.05, 0.05, 0.05]
[camera]
eye = [0.0, 3.0, 6.0]
target = [0.0, 0.0, 0.0]
[[light]]
kind = "point"
position = [0.0, 12.0, 0.0]
[[mesh]]
name = "floor"
shape = "plane"
size = [30.0, 30.0]
casts_shadow = false
[[mesh]]
name = "low"
shape = "box"
size = [1.0, 0.2, 1.0]
translate = [0.0, 4.0, 0.0]
[[mesh]]
name = "high"
shape = "box"
size = [1.0, 0.2, 1.0]
translate = [0.0, 6.0, 0.0]
"#;

/// The image pixel at which a world point appears.
fn project(r: &Renderer, p: glam::Vec3) -> (usize, usize) {
    let (w, h) = (r.config().width as f32, r.config().height as f32);
    let vp = r.scene().camera.proj_infinite(w / h) * r.scene().camera.view();
    let c = vp * p.extend(1.0);
    let ndc = c.truncate() / c.w;
    (((ndc.x + 1.0) * 0.5 * w) as usize, ((ndc.y + 1.0) * 0.5 * h) as usize)
}

fn luminance(rgba: &[u8], w: usize, (x, y): (usize, usize)) -> u32 {
    let i = (y * w + x) * 4;
    rgba[i] as u32 + rgba[i + 1] as u32 + rgba[i + 2] as u32
}

#[test]
fn stacked_boxes_give_count_two_and_dark_floor() {
    let Some(mut ctx) = common::context() else { return };
    for depth_mode in [DepthMode::Infinite, DepthMode::Clamp] {
        if depth_mode == DepthMode::Clamp && !common::feature(ctx.features.depth_clamp, "depthClamp") {
            continue;
        }
        for method in umbrage::shadow::Method::ALL {
            let scene = umbrage_scene::load_str(STACK, "stack", std::path::Path::new(".")).unwrap();
            let opts = RenderOptions {
                width: 200,
                height: 150,
                technique: Technique::Volumes(method).into(),
                depth_mode,
                capture: true,
                ..Default::default()
            };
            let mut r = Renderer::new(ctx, scene, opts).unwrap();
            let out = r.render().unwrap();
            let w = 200;
            let under = project(&r, glam::Vec3::new(0.0, 0.0, 0.0));
            let away = project(&r, glam::Vec3::new(2.5, 0.0, 2.5));
            let st = &out.stencil[0];
            let label = format!("{method} {depth_mode:?}");
            assert_eq!(st[under.1 * w + under.0], 2, "{label}: floor under both boxes is inside two volumes");
            assert_eq!(st[away.1 * w + away.0], 0, "{label}: open floor is in no volume");
            let (dark, bright) = (luminance(&out.color, w, under), luminance(&out.color, w, away));
            // Shadowed = ambient only (0.05): under a third of the lit floor's brightness.
            assert!(dark * 3 < bright, "{label}: shadowed floor {dark} should be far darker than lit floor {bright}");
            assert!(bright > 400, "{label}: lit floor should be bright, got {bright}");
            r.context().check_validation().unwrap();
            ctx = r.into_context();
        }
    }
}

/// Camera between the floor and the boxes, looking down: the eye is inside both volumes.
#[test]
fn eye_inside_two_volumes_counts_two_except_zpass() {
    let Some(mut ctx) = common::context() else { return };
    let toml =
        STACK.replace("eye = [0.0, 3.0, 6.0]", "eye = [0.1, 2.0, 0.1]").replace("target = [0.0, 0.0, 0.0]", "target = [1.5, 0.0, 0.0]");
    for method in Method::ALL {
        let scene = umbrage_scene::load_str(&toml, "eye-in", std::path::Path::new(".")).unwrap();
        let mut r = Renderer::new(
            ctx,
            scene,
            RenderOptions { width: 160, height: 120, technique: Technique::Volumes(method).into(), capture: true, ..Default::default() },
        )
        .unwrap();
        let out = r.render().unwrap();
        let p = project(&r, glam::Vec3::new(0.3, 0.0, 0.0));
        let count = out.stencil[0][p.1 * 160 + p.0];
        if method == Method::ZPass {
            assert_ne!(count, 2, "z-pass cannot count volumes that contain the eye");
        } else {
            assert_eq!(count, 2, "{method}");
        }
        ctx = r.into_context();
    }
}

/// The shadow-map baseline (PCF) renders under validation and lands close to the reference:
/// not exact (that is the point of comparing), but within half a percent of the pixels on the
/// built-in scenes with 1024-texel maps. The gathering lookup reads the same nine comparisons
/// as the nine taps: the same shadow counts and the same picture, pixel for pixel.
#[test]
fn shadow_map_baseline_is_close_to_the_reference() {
    let Some(mut ctx) = common::context() else { return };
    for name in ["default", "stairs", "spheres", "hard/light_inside_caster", "hard/light_inside_bounds"] {
        let scene = umbrage_scene::load(name).unwrap();
        let sm = RenderTechnique::from(ShadowMap::new(1024));
        let opts = RenderOptions { width: 256, height: 192, technique: sm, capture: true, ..Default::default() };
        let mut r = Renderer::new(ctx, scene, opts).unwrap();
        let rows = umbrage_render::accuracy::evaluate(&mut r, name, &[sm], 1).unwrap();
        let taps = r.render().unwrap();
        assert!(matches!(taps.stats.method, RenderTechnique::ShadowMap(_)));
        assert!(rows[0].fraction < 5e-3, "{name}: shadow map error {:.4}%", rows[0].fraction * 100.0);
        assert!(!taps.counts.is_empty() && taps.counts.iter().flatten().any(|&c| c != 0), "{name}: no shadow to compare");
        r.settings.technique = RenderTechnique::ShadowMap(ShadowMap { size: 1024, pcf: Pcf::Gather, cube: CubeFaces::Atlas });
        let gather = r.render().unwrap();
        assert!(taps.counts == gather.counts, "{name}: the gathers' shadow counts differ from the taps'");
        assert!(taps.color == gather.color, "{name}: the gathers' picture differs from the taps'");
        r.context().check_validation().unwrap();
        ctx = r.into_context();
    }
}

/// A point light's cube faces rendered as six views of one draw (`--cube multiview`) are the
/// atlas's maps: the same shadow counts and picture, pixel for pixel, with taps and gathers, on
/// the scenes whose casters cross the faces' near planes and edges (`hard/light_inside_caster`:
/// a box around the light). Where the device's multiview is missing or known wrong (the
/// system's lavapipe 22.3.6 loses clipped triangles), asking for it is a clear error and the
/// comparison runs on lavapipe 25.0.7 in a child process.
#[test]
fn multiview_cube_faces_are_the_atlas_maps() {
    let Some(ctx) = common::context() else { return };
    let scene = umbrage_scene::load("default").unwrap();
    let mut r = Renderer::new(ctx, scene, RenderOptions { width: 64, height: 48, ..Default::default() }).unwrap();
    r.settings.technique = RenderTechnique::ShadowMap(ShadowMap { size: 256, pcf: Pcf::Taps, cube: CubeFaces::Multiview });
    if let Err(e) = r.render() {
        let msg = e.to_string();
        assert!(matches!(e, umbrage::Error::Unsupported(_)) && msg.contains("--cube atlas"), "{msg}");
        // Refused, not half-made: the atlas still renders.
        r.settings.technique = RenderTechnique::from(ShadowMap::new(256));
        r.render().unwrap();
        r.context().check_validation().unwrap();
        drop(r);
        common::rerun_on_lavapipe_25(concat!(module_path!(), "::multiview_cube_faces_are_the_atlas_maps"), false, &[]);
        return;
    }
    let mut ctx = r.into_context();
    for name in ["default", "stairs", "hard/light_inside_caster", "hard/light_inside_bounds"] {
        let scene = umbrage_scene::load(name).unwrap();
        let opts = RenderOptions {
            width: 256,
            height: 192,
            technique: RenderTechnique::from(ShadowMap::new(1024)),
            capture: true,
            ..Default::default()
        };
        let mut r = Renderer::new(ctx, scene, opts).unwrap();
        let atlas = r.render().unwrap();
        assert!(atlas.counts.iter().flatten().any(|&c| c != 0), "{name}: no shadow to compare");
        for pcf in [Pcf::Taps, Pcf::Gather] {
            r.settings.technique = RenderTechnique::ShadowMap(ShadowMap { size: 1024, pcf, cube: CubeFaces::Multiview });
            let views = r.render().unwrap();
            assert!(atlas.counts == views.counts, "{name}: {pcf} from multiview faces: the shadow counts differ from the atlas's");
            assert!(atlas.color == views.color, "{name}: {pcf} from multiview faces: the picture differs from the atlas's");
        }
        r.context().check_validation().unwrap();
        ctx = r.into_context();
    }
}
