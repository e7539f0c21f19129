//! Flat projected shadows (`--method planar`, the Cg article's first section): every caster
//! flattened onto the receiver plane y = 0 from the light, drawn with the stencil set to 1 so
//! no pixel is darkened twice. Exact on that plane, and asserted wrong on every other receiver.

use crate::common;

use umbrage_reference::metrics::compare_all;
use umbrage_reference::{LightState, Reference};
use umbrage_render::{RenderOptions, Renderer, Technique};

/// The GPU masks with every pixel that is not on the floor (world y = 0) replaced by the
/// reference's own answer, so that only floor pixels can mismatch; and the same restricted to
/// every other surface.
fn split_masks(masks: &[Vec<u8>], positions: &[[f32; 3]], reference: &umbrage_reference::RefImage) -> (Vec<Vec<u8>>, Vec<Vec<u8>>) {
    let truth = |i: usize, k: usize| match reference.states[i * reference.light_count + k] {
        LightState::Lit => 255u8,
        LightState::Background => 128,
        _ => 0,
    };
    let on_floor = |i: usize| positions[i][1].is_finite() && positions[i][1].abs() < 1e-4;
    let pick = |want_floor: bool| -> Vec<Vec<u8>> {
        masks
            .iter()
            .enumerate()
            .map(|(k, m)| m.iter().enumerate().map(|(i, &v)| if on_floor(i) == want_floor { v } else { truth(i, k) }).collect())
            .collect()
    };
    (pick(true), pick(false))
}

#[test]
fn planar_shadows_are_exact_on_the_floor_and_wrong_elsewhere() {
    let Some(mut ctx) = common::context() else { return };
    let (w, h) = (256, 192);
    // A cube floating over a block: its shadow falls on the block's top, not on the floor.
    let over_block = r#"
[camera]
eye = [0.0, 5.0, 7.0]
target = [0.0, 0.5, 0.0]
[[light]]
kind = "point"
position = [0.5, 8.0, 1.0]
[[mesh]]
shape = "plane"
size = [12.0, 12.0]
casts_shadow = false
[[mesh]]
shape = "box"
size = [3.0, 1.0, 3.0]
translate = [0.0, 0.5, 0.0]
[[mesh]]
shape = "box"
size = [0.8, 0.8, 0.8]
translate = [0.0, 2.5, 0.0]
"#;
    for name in ["default", "over_block"] {
        let scene = match name {
            "default" => umbrage_scene::load(name).unwrap(),
            _ => umbrage_scene::load_str(over_block, name, std::path::Path::new(".")).unwrap(),
        };
        let opts = RenderOptions { width: w, height: h, technique: Technique::Planar.into(), capture: true, ..Default::default() };
        let mut r = Renderer::new(ctx, scene, opts).unwrap();
        let out = r.render().unwrap();
        assert_eq!(out.stats.method, umbrage_render::Technique::Planar.into());
        let reference = Reference::from_scene(r.scene()).render(&r.scene().camera, &r.scene().lights, w, h);
        let (floor, elsewhere) = split_masks(&out.shadow_masks(r.scene()), &out.positions, &reference);
        let floor_metrics = compare_all(&floor, &reference, 1).unwrap();
        let other_metrics = compare_all(&elsewhere, &reference, 1).unwrap();
        for (k, m) in floor_metrics.iter().enumerate() {
            assert!(m.fraction_outside_band <= umbrage_render::accuracy::THRESHOLD, "{name} light {k} on the floor: {m:?}");
        }
        let wrong: u64 = other_metrics.iter().map(|m| m.mismatches_outside_band).sum();
        let floor_wrong: u64 = floor_metrics.iter().map(|m| m.mismatches_outside_band).sum();
        eprintln!("{name}: planar: {floor_wrong} mismatched floor pixels, {wrong} mismatched pixels on other receivers");
        assert!(wrong > 0, "{name}: planar shadows should be wrong off the floor (shadows on walls, steps, casters), got {wrong}");
        r.context().check_validation().unwrap();
        ctx = r.into_context();
    }
}
