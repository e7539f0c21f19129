//! Smooth shading (issue 23 item 7): smooth normals with the terminator bound of
//! `geom::shading` light a low-poly caster smoothly, reach zero before the shadow volumes'
//! polygonal terminator (no step along its triangle edges, where naive smooth normals step),
//! keep flat faces as flat shading has them, and change no shadow. Validation on.

use crate::common;

use umbrage_render::{FrameOutput, RenderOptions, Renderer, Shading};

/// A 12-segment sphere over a floor and a box, lit from the side: its terminator crosses
/// the image.
const SCENE: &str = r#"
[camera]
eye = [0, 1.6, 4]
target = [0, 1, 0]
fov_y_deg = 40
[[light]]
kind = "directional"
direction = [-1, -0.25, -0.15]
intensity = 1.0
[[mesh]]
shape = "plane"
size = [10, 10]
color = [0.7, 0.7, 0.7]
[[mesh]]
name = "ball"
shape = "sphere"
radius = 0.9
segments = 12
rings = 8
translate = [0, 1.1, 0]
color = [0.8, 0.8, 0.8]
[[mesh]]
name = "crate"
shape = "box"
size = [0.6, 0.6, 0.6]
translate = [1.6, 0.3, 0.5]
color = [0.8, 0.8, 0.8]
"#;

fn luminance(px: &[u8]) -> i32 {
    px[0] as i32 + px[1] as i32 + px[2] as i32
}

/// The largest brightness step from a lit pixel of the ball to a 4-neighbour of the ball on a
/// face turned away from the light (`to_light`): across the terminator, not into a shadow the
/// crate casts. In sRGB levels summed over RGB.
fn terminator_step(out: &FrameOutput, mask: &[u8], to_light: glam::Vec3) -> i32 {
    let (w, h) = (out.width as usize, out.height as usize);
    let centre = glam::Vec3::new(0.0, 1.1, 0.0);
    let on_ball = |i: usize| {
        let p = glam::Vec3::from(out.positions[i]);
        p.x.is_finite() && (p.distance(centre) - 0.9).abs() < 0.1
    };
    let mut worst = 0;
    for y in 1..h - 1 {
        for x in 1..w - 1 {
            let i = y * w + x;
            if mask[i] != 255 || !on_ball(i) {
                continue;
            }
            for j in [i - 1, i + 1, i - w, i + w] {
                if mask[j] == 0 && on_ball(j) && glam::Vec3::from(out.normals[j]).dot(to_light) <= 0.0 {
                    worst = worst.max(luminance(&out.color[4 * i..]) - luminance(&out.color[4 * j..]));
                }
            }
        }
    }
    worst
}

#[test]
fn smooth_shading_has_no_terminator_step_and_changes_no_shadow() {
    let Some(ctx) = common::context() else { return };
    let scene = umbrage_scene::load_str(SCENE, "shading.toml", std::path::Path::new(".")).unwrap();
    let opts = RenderOptions { width: 320, height: 240, capture: true, ..Default::default() };
    let mut r = Renderer::new(ctx, scene, opts).unwrap();
    let mut frames = Vec::new();
    for shading in [Shading::Smooth, Shading::SmoothNaive, Shading::Flat] {
        r.settings.shading = shading;
        let out = r.render().unwrap();
        r.context().check_validation().unwrap();
        frames.push(out);
    }
    let masks: Vec<Vec<Vec<u8>>> = frames.iter().map(|f| f.shadow_masks(r.scene())).collect();
    for (f, m) in frames.iter().zip(&masks).skip(1) {
        assert_eq!(m, &masks[0], "the shading mode changed a shadow mask");
        assert_eq!(f.stencil, frames[0].stencil, "the shading mode changed a stencil count");
    }
    let to_light = glam::Vec3::new(1.0, 0.25, 0.15).normalize();
    let steps: Vec<i32> = frames.iter().zip(&masks).map(|(f, m)| terminator_step(f, &m[0], to_light)).collect();
    eprintln!("terminator steps (smooth, smooth-naive, flat): {steps:?}");
    let (smooth, naive) = (steps[0], steps[1]);
    assert!(naive > 40, "naive smooth normals should step at the terminator of a 12-segment sphere: {naive}");
    assert!(smooth * 4 < naive && smooth <= 9, "the bounded smooth shading still steps at the terminator: {steps:?}");
    // Flat faces (the crate, the floor) shade as flat shading does: their bound is 0.
    let (w, n) = (frames[0].width as usize, frames[0].positions.len());
    let flat_face = |i: usize| {
        let p = frames[0].positions[i];
        p[0].is_finite() && (p[1].abs() < 1e-4 || (p[0] > 1.25 && p[0] < 1.95 && p[2] > 0.15))
    };
    let mut compared = 0;
    for i in (w..n - w).filter(|&i| flat_face(i)) {
        let (a, b) = (&frames[0].color[4 * i..4 * i + 3], &frames[2].color[4 * i..4 * i + 3]);
        assert!(a.iter().zip(b).all(|(x, y)| x.abs_diff(*y) <= 2), "pixel {i}: smooth {a:?}, flat {b:?}");
        compared += 1;
    }
    assert!(compared > 10_000, "{compared} flat pixels compared");
}

/// Writes docs/shading.png (the 12-segment ball flat, with naive smooth normals and with the
/// bounded smooth shading, side by side at 2x) and docs/default.png (the default scene as
/// `umbrage render` draws it): `cargo test --test engine shading:: -- --ignored`.
#[test]
#[ignore = "writes docs/shading.png and docs/default.png: run with -- --ignored"]
fn write_docs_shading_pictures() {
    let Some(ctx) = common::context() else { return };
    let scene = umbrage_scene::load_str(SCENE, "shading.toml", std::path::Path::new(".")).unwrap();
    let opts = RenderOptions { width: 320, height: 240, ..Default::default() };
    let mut r = Renderer::new(ctx, scene, opts).unwrap();
    let (x0, y0, cw, ch) = (80usize, 40usize, 160usize, 160usize);
    let zoom = 2usize;
    let mut strip = vec![0u8; 3 * cw * zoom * ch * zoom * 4];
    let strip_w = 3 * cw * zoom;
    for (k, shading) in [Shading::Flat, Shading::SmoothNaive, Shading::Smooth].into_iter().enumerate() {
        r.settings.shading = shading;
        let out = r.render().unwrap();
        for y in 0..ch * zoom {
            for x in 0..cw * zoom {
                let src = 4 * ((y0 + y / zoom) * out.width as usize + x0 + x / zoom);
                let dst = 4 * (y * strip_w + k * cw * zoom + x);
                strip[dst..dst + 4].copy_from_slice(&out.color[src..src + 4]);
            }
        }
    }
    r.context().check_validation().unwrap();
    let docs = concat!(env!("CARGO_MANIFEST_DIR"), "/docs");
    umbrage_render::output::write_png(&std::path::Path::new(docs).join("shading.png"), strip_w as u32, (ch * zoom) as u32, &strip).unwrap();
    let scene = umbrage_scene::load("default").unwrap();
    let mut r = Renderer::new(r.into_context(), scene, RenderOptions::default()).unwrap();
    let out = r.render().unwrap();
    umbrage_render::output::write_png(&std::path::Path::new(docs).join("default.png"), out.width, out.height, &out.color).unwrap();
}
