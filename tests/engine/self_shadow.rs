//! `--self-shadow` (partial self-shadowing of transparent casters, crates/umbrage-render/src/stages/selfshadow.rs):
//! a transparent surface under another transparent surface gets darker, the opaque receivers'
//! light fractions do not change. The ignored `self_shadow_perf` writes
//! docs/transparency-perf.md (run it with `-- --ignored`).
use crate::common;
use glam::Vec3;
use umbrage_render::{RenderOptions, Renderer};

/// A wide transparent slab (top face at y = 1.1) under a transparent plate (y = 2..2.1), an
/// opaque small box on the floor, a point light straight above. The eye looks at the slab's top
/// face through the gap between the two.
const STACK: &str = r#"
name = "self-shadow stack"
[camera]
eye = [6.0, 2.2, 6.0]
target = [0.0, 1.0, 0.0]
[[light]]
kind = "point"
position = [0.0, 8.0, 0.0]
[[mesh]]
name = "floor"
shape = "plane"
casts_shadow = false
size = [14.0, 14.0]
[[mesh]]
name = "opaque_box"
shape = "box"
size = [0.6, 0.6, 0.6]
translate = [2.5, 0.3, -1.5]
[[mesh]]
name = "slab"
shape = "box"
size = [3.0, 0.2, 3.0]
translate = [0.0, 1.0, 0.0]
color = [0.9, 0.9, 0.9]
opacity = 0.4
[[mesh]]
name = "plate"
shape = "box"
size = [2.0, 0.1, 2.0]
translate = [0.0, 2.05, 0.0]
color = [0.3, 0.5, 1.0]
opacity = 0.5
"#;

fn luminance(c: &[u8], i: usize) -> f64 {
    c[4 * i..4 * i + 3].iter().map(|&v| v as f64).sum()
}

#[test]
fn self_shadow_darkens_covered_transparent_surfaces_only() {
    let Some(mut ctx) = common::context() else {
        return;
    };
    let (w, h) = (240u32, 180u32);
    let mut frames = Vec::new();
    for self_shadow in [false, true] {
        let scene = umbrage_scene::load_str(STACK, "stack", std::path::Path::new(".")).unwrap();
        let mut r =
            Renderer::new(ctx, scene, RenderOptions { width: w, height: h, capture: true, self_shadow, ..Default::default() }).unwrap();
        let out = r.render().unwrap();
        assert_eq!(out.stats.self_shadow, self_shadow);
        let fractions = out.light_fractions(r.scene());
        let cam = r.scene().camera.clone();
        frames.push((out.color, fractions));
        ctx = r.into_context();
        if self_shadow {
            // The slab's top face under the plate's centre: project it to a pixel.
            let vp = cam.proj_infinite(w as f32 / h as f32) * cam.view();
            let c = vp * Vec3::new(0.3, 1.1, 0.3).extend(1.0);
            let (x, y) = (((c.x / c.w) * 0.5 + 0.5) * w as f32, ((c.y / c.w) * 0.5 + 0.5) * h as f32);
            let mean = |color: &[u8]| {
                let mut s = 0.0;
                for dy in -1..=1 {
                    for dx in -1..=1 {
                        s += luminance(color, ((y as i32 + dy) as u32 * w + (x as i32 + dx) as u32) as usize);
                    }
                }
                s / 9.0
            };
            let (without, with) = (mean(&frames[0].0), mean(&frames[1].0));
            eprintln!("slab top under the plate at pixel ({x:.0}, {y:.0}): {without:.1} without, {with:.1} with --self-shadow");
            assert!(with < without - 3.0, "covered transparent surface not darker: {with} vs {without}");
        }
    }
    let (a, b) = (&frames[0], &frames[1]);
    // Nowhere brighter (the option only scales transparent surfaces' light down).
    let brighter = (0..(w * h) as usize).filter(|&i| luminance(&b.0, i) > luminance(&a.0, i) + 3.0).count();
    assert_eq!(brighter, 0, "{brighter} pixels brighter with --self-shadow");
    // The opaque receivers' light fractions (the floor's shadows) are bit for bit the same.
    assert_eq!(a.1.len(), b.1.len());
    for (la, lb) in a.1.iter().zip(&b.1) {
        for (pa, pb) in la.iter().zip(lb) {
            assert_eq!(pa.map(f32::to_bits), pb.map(f32::to_bits));
        }
    }
}

#[test]
#[ignore = "timing: run with -- --ignored; writes docs/transparency-perf.md"]
fn self_shadow_perf() {
    // Timings without the validation layers (they cost CPU time per call); the same passes are
    // validated by the test above.
    if common::context().is_none() {
        return;
    }
    std::env::remove_var("UMBRAGE_VALIDATION");
    let mut ctx = umbrage::gpu::Context::with_validation(false).unwrap();
    let name = "transparent/balls_and_cubes";
    let (w, h) = (640u32, 480u32);
    let mut rows = Vec::new();
    let mut device = String::new();
    for (label, all_opaque, self_shadow) in
        [("opaque", true, false), ("transparent (no s.s.)", false, false), ("transparent (s.s.)", false, true)]
    {
        let mut scene = umbrage_scene::load(name).unwrap();
        if all_opaque {
            for m in &mut scene.meshes {
                m.opacity = 1.0;
            }
        }
        let mut r = Renderer::new(ctx, scene, RenderOptions { width: w, height: h, self_shadow, ..Default::default() }).unwrap();
        r.render().unwrap(); // warm-up
        let mut wall = Vec::new();
        let mut gpu = Vec::new();
        for _ in 0..5 {
            let out = r.render().unwrap();
            assert_eq!(out.stats.self_shadow, self_shadow);
            wall.push(out.stats.wall_ms);
            gpu.extend(out.stats.gpu_ms.map(|g| g.frame));
            device = out.stats.device.clone();
        }
        let median = |v: &mut Vec<f64>| {
            v.sort_by(f64::total_cmp);
            v.get(v.len() / 2).copied()
        };
        rows.push((label, median(&mut wall).unwrap(), median(&mut gpu)));
        ctx = r.into_context();
    }
    let mut md = String::from("# Transparent casters: frame time (the form of Kim, Kim & Turk 2008, Table 1)\n\n");
    md += &format!(
        "Scene `{name}`, {w}x{h}, one point light, default options (`--counter stencil`, `--transmit log16`), \
         median of 5 frames after one warm-up, device **{device}**, optimised build, validation layers off. \"opaque\" is the same scene with \
         every mesh's opacity set to 1; \"s.s.\" is `--self-shadow` (partial self-shadowing, crates/umbrage-render/src/stages/selfshadow.rs).\n\
         Frame = wall time of `Renderer::render` (CPU planning, recording, submission, wait, read-back of the \
         colour image); GPU = the timestamped frame on the device.\n\n"
    );
    md += "| | opaque | transparent (no s.s.) | transparent (s.s.) |\n|---|---|---|---|\n";
    md += &format!("| frames per second | {} |\n", rows.iter().map(|r| format!("{:.1}", 1e3 / r.1)).collect::<Vec<_>>().join(" | "));
    md += &format!("| frame (ms) | {} |\n", rows.iter().map(|r| format!("{:.2}", r.1)).collect::<Vec<_>>().join(" | "));
    md += &format!(
        "| GPU frame (ms) | {} |\n",
        rows.iter().map(|r| r.2.map(|g| format!("{g:.2}")).unwrap_or_else(|| "—".into())).collect::<Vec<_>>().join(" | ")
    );
    md += "\nRegenerate: `cargo test --test engine self_shadow:: -- --ignored self_shadow_perf` (the test profile is optimised).\n";
    eprintln!("{md}");
    std::fs::write(concat!(env!("CARGO_MANIFEST_DIR"), "/docs/transparency-perf.md"), md).unwrap();
}
