//! Multiview against separate draws: a point light's six shadow-map faces rendered as six
//! views of one draw must be the maps six separately drawn atlas tiles give.
//!
//! The scene is `hard/light_inside_caster`: a point light inside a closed box. Every wall
//! triangle surrounds the light, crosses the near plane and the edges of several faces, and
//! must be clipped in each view. This is the case lavapipe 22.3.6 gets wrong (it loses
//! clipped triangles in multiview; `gpu::quirks`, docs/shadowmap-cube.md), which is why the
//! renderer refuses multiview there. This check lifts that refusal for the one frame it
//! renders, so the defect is reported here as a failure rather than avoided.

use crate::CheckResult;
use serde_json::json;
use umbrage::error::Result;
use umbrage::gpu::Context;
use umbrage_render::{CubeFaces, Pcf, RenderOptions, Renderer, ShadowMap};

/// The check's name (`legacy.multiview_cube_faces`).
pub const NAME: &str = "multiview_cube_faces";

/// Check 9: the shadow-map lookup's per-pixel shadow counts from six multiview views equal
/// those from six atlas tiles, on every light of `hard/light_inside_caster` (64-texel maps,
/// 96 x 72 pixels, on a context of its own from `new_context`). Skipped without the
/// `multiview` feature; validation errors fail it.
pub fn multiview_cube_faces(ctx: &Context, new_context: &dyn Fn() -> Result<Context>) -> Result<CheckResult> {
    if !ctx.features.multiview {
        return Ok(CheckResult::skipped(NAME, "skipped: not supported (multiview)"));
    }
    let scene = umbrage_scene::load("hard/light_inside_caster")?;
    let atlas = ShadowMap { size: 64, pcf: Pcf::Taps, cube: CubeFaces::Atlas }.into();
    let opts = RenderOptions { width: 96, height: 72, technique: atlas, capture: true, ..Default::default() };
    let mut r = Renderer::new(new_context()?, scene, opts)?;
    let tiles = r.render()?;
    r.settings.technique = ShadowMap { size: 64, pcf: Pcf::Taps, cube: CubeFaces::Multiview }.into();
    let views = umbrage::gpu::quirks::ignoring(|| r.render())?;
    let mut fails: Vec<String> = r.context().take_validation_errors().into_iter().take(3).map(|e| format!("validation: {e}")).collect();
    let compared: usize = tiles.counts.iter().map(Vec::len).sum();
    let differ: usize = tiles.counts.iter().zip(&views.counts).map(|(a, b)| a.iter().zip(b).filter(|(x, y)| x != y).count()).sum();
    let shadowed: usize = tiles.counts.iter().map(|l| l.iter().filter(|&&c| c != 0).count()).sum();
    if shadowed == 0 {
        fails.push("the atlas shadows nothing: the comparison would prove nothing".into());
    }
    if differ > 0 {
        fails.push(format!(
            "{differ} of {compared} pixels' shadow counts differ between six multiview views and six atlas tiles (clipped triangles lost?)"
        ));
        // Per light: the atlas's shadow (expected), the views' (actual), red where they differ.
        use super::super::image_sink::{save, texels};
        let (w, h) = (96u32, 72u32);
        let shade = |c: i32| if c == 0 { image::Rgb([255, 255, 255]) } else { image::Rgb([64, 64, 64]) };
        for (l, (a, b)) in tiles.counts.iter().zip(&views.counts).enumerate() {
            if a.len() != (w * h) as usize || b.len() != a.len() {
                continue;
            }
            save(&format!("light{l}.expected_atlas"), &texels(w, h, |i| shade(a[i])));
            save(&format!("light{l}.actual_multiview"), &texels(w, h, |i| shade(b[i])));
            save(&format!("light{l}.diff"), &texels(w, h, |i| if a[i] != b[i] { image::Rgb([255, 0, 0]) } else { image::Rgb([0, 0, 0]) }));
        }
    }
    let numbers = json!({ "compared": compared, "differ": differ, "shadowed": shadowed });
    let numbers = numbers.as_object().cloned().unwrap_or_default();
    Ok(CheckResult::from_fails(NAME, fails, numbers, "six multiview views render the six atlas tiles' maps, clipped triangles included"))
}
