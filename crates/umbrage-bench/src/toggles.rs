//! The suite's constant-factor ablations (issue #10): McGuire with each optimisation of the
//! pass switched off (scissor, depth bounds, culling), the index formats, and the other z-fail
//! methods against McGuire, each as ratios to its baseline measured in the same point.

use super::report::{Ablation, SuiteRow};
use super::runner::Variant;
use umbrage::gpu::Context;
use umbrage::shadow::Method;
use umbrage_render::{IndexFormat, PassToggles, Technique};

/// The depth-bounds ablation of `scene`, skipped: the device has no `depthBounds`.
pub(super) fn no_depth_bounds(scene: &str) -> Ablation {
    Ablation {
        what: "depth-bounds".into(),
        scene: scene.into(),
        variant: "depth-bounds-off".into(),
        baseline: "all-on".into(),
        time_ratio: None,
        fragment_ratio: None,
        triangle_ratio: None,
        byte_ratio: None,
        skipped: "the device has no depthBounds feature (the pass never uses it here)".into(),
    }
}

/// McGuire with every optimisation on, then with each off in turn (depth bounds where the
/// device has them).
pub(super) fn toggle_variants(ctx: &Context) -> Vec<Variant> {
    let m = Technique::Volumes(Method::McGuire);
    let on = PassToggles::default();
    let mut v = vec![
        Variant { label: "all-on".into(), ..Variant::of(m) },
        Variant { label: "scissor-off".into(), toggles: PassToggles { scissor: false, ..on }, ..Variant::of(m) },
        Variant { label: "culling-off".into(), toggles: PassToggles { culling: false, ..on }, ..Variant::of(m) },
    ];
    if ctx.features.depth_bounds {
        v.push(Variant { label: "depth-bounds-off".into(), toggles: PassToggles { depth_bounds: false, ..on }, ..Variant::of(m) });
    }
    v
}

/// McGuire through each index format.
pub(super) fn index_variants() -> Vec<Variant> {
    let m = Technique::Volumes(Method::McGuire);
    [IndexFormat::U8, IndexFormat::U16, IndexFormat::U32, IndexFormat::Naive]
        .into_iter()
        .map(|f| Variant { label: format!("index-{}", f.name()), index_format: f, ..Variant::of(m) })
        .collect()
}

/// The constant factors as ratios: toggles against `all-on`, the other methods' triangles and
/// time against McGuire's on the named scenes, index formats against u16.
pub(super) fn ablations(rows: &[SuiteRow]) -> Vec<Ablation> {
    let ratio = |a: Option<f64>, b: Option<f64>| match (a, b) {
        (Some(a), Some(b)) if b > 0.0 => Some(a / b),
        _ => None,
    };
    let make = |what: &str, v: &SuiteRow, b: &SuiteRow, vl: &str, bl: &str| Ablation {
        what: what.into(),
        scene: v.scene.clone(),
        variant: vl.into(),
        baseline: bl.into(),
        time_ratio: ratio(v.gpu_shadow_ms, b.gpu_shadow_ms),
        fragment_ratio: ratio(v.stencil_fragments.map(|x| x as f64), b.stencil_fragments.map(|x| x as f64)),
        triangle_ratio: ratio(Some(v.shadow_triangles as f64), Some(b.shadow_triangles as f64)),
        byte_ratio: ratio(Some(v.bytes as f64), Some(b.bytes as f64)),
        skipped: String::new(),
    };
    let mut out = Vec::new();
    let abl: Vec<&SuiteRow> = rows.iter().filter(|r| r.sweep == "ablation").collect();
    for b in abl.iter().filter(|r| r.variant == "all-on") {
        for v in abl.iter().filter(|r| r.scene == b.scene && r.variant.ends_with("-off")) {
            out.push(make(v.variant.trim_end_matches("-off"), v, b, &v.variant, "all-on"));
        }
    }
    for b in abl.iter().filter(|r| r.variant == "index-u16") {
        for v in abl.iter().filter(|r| r.scene == b.scene && r.variant.starts_with("index-") && r.variant != "index-u16") {
            out.push(make("index-format", v, b, &v.variant, "index-u16"));
        }
    }
    let scenes: Vec<&SuiteRow> = rows.iter().filter(|r| r.sweep == "scenes").collect();
    for b in scenes.iter().filter(|r| r.method == "mcguire") {
        for v in scenes.iter().filter(|r| r.scene == b.scene && matches!(r.method.as_str(), "lengyel" | "everitt-kilgard" | "zfail")) {
            out.push(make("method", v, b, &v.method, "mcguire"));
        }
    }
    out
}
