//! Shadow geometry counts and bytes on the GPU path, per caster, against the paper's formulas:
//! point light case 1 = 2s, case 2 = 3s, case 3 = 3s + light-facing faces; directional s sides.
use crate::common;
use umbrage::geom::silhouette::facing_bits;
use umbrage::geom::LightKind;
use umbrage::pass::stats::UsedIndexFormat;
use umbrage::shadow::plan::object_light;
use umbrage::shadow::{Case, DarkCap, Method};
use umbrage_render::{IndexFormat, RenderOptions, Renderer, Stats};

/// Three casters that fall in the three cases for light 0 (behind and above the camera), and
/// a second light in front of the camera that puts the cube on the view axis in case 3.
const CASES: &str = r#"
name = "cases"
[camera]
eye = [0.0, 2.0, 10.0]
target = [0.0, 0.0, 0.0]
[[light]]
kind = "point"
position = [0.0, 10.0, 14.0]
[[light]]
kind = "point"
position = [0.0, 2.5, -6.0]
[[light]]
kind = "directional"
direction = [0.3, -1.0, -0.2]
[[mesh]]
name = "floor"
shape = "plane"
size = [40.0, 40.0]
casts_shadow = false
[[mesh]]
name = "above_behind_camera"
shape = "sphere"
translate = [0.0, 6.0, 12.0]
[[mesh]]
name = "far_on_floor"
shape = "sphere"
translate = [-3.0, 0.5, -2.0]
[[mesh]]
name = "between_eye_and_light1"
shape = "box"
size = [0.6, 0.6, 0.6]
translate = [0.0, 2.4, 3.0]
"#;

fn render(ctx: umbrage::gpu::Context, toml: &str, name: &str, method: Method, fmt: IndexFormat) -> (Stats, Renderer) {
    let scene = if toml.is_empty() {
        umbrage_scene::load(name).unwrap()
    } else {
        umbrage_scene::load_str(toml, name, std::path::Path::new(".")).unwrap()
    };
    let mut r = Renderer::new(
        ctx,
        scene,
        RenderOptions {
            width: 320,
            height: 240,
            technique: umbrage_render::Technique::Volumes(method).into(),
            index_format: fmt,
            ..Default::default()
        },
    )
    .unwrap();
    let out = r.render().unwrap();
    r.context().check_validation().unwrap();
    (out.stats, r)
}

/// Checks every caster of every light against the formulas; returns the cases seen.
fn check_formulas(stats: &Stats, r: &Renderer) -> Vec<Case> {
    let mut seen = Vec::new();
    for ls in &stats.lights {
        let light = &r.scene().lights[ls.index];
        for cs in &ls.casters {
            let caster = r.casters().iter().find(|c| c.name == cs.name).unwrap();
            let s = cs.silhouette_edges;
            let t = &cs.triangles;
            seen.push(cs.case);
            if cs.dark_cap_kind == DarkCap::BackFaces {
                continue; // light inside the caster's box: the back-face formulation (documented)
            }
            let l = object_light(caster, light.homogeneous());
            let lit = facing_bits(caster.mesh(), l, caster.mirrored).iter().filter(|&&b| b).count() as u64;
            let ctx = format!("light {} caster {} case {} s={s} {t:?}", ls.index, cs.name, cs.case);
            if ls.kind == LightKind::Directional {
                assert_eq!(t.sides, s, "{ctx}");
                assert_eq!(t.dark_cap, 0, "{ctx}");
                if cs.case == Case::ZFailLightCap {
                    assert_eq!(t.light_cap, lit, "{ctx}");
                }
                continue;
            }
            match cs.case {
                Case::Culled => assert_eq!(t.total(), 0, "{ctx}"),
                Case::ZPass => assert_eq!((t.sides, t.dark_cap, t.light_cap), (2 * s, 0, 0), "{ctx}"),
                Case::ZFail => assert_eq!((t.sides, t.dark_cap, t.light_cap), (2 * s, s, 0), "{ctx}"),
                Case::ZFailLightCap => assert_eq!((t.sides, t.dark_cap, t.light_cap), (2 * s, s, lit), "{ctx}"),
            }
        }
    }
    seen
}

#[test]
fn mcguire_counts_follow_the_paper_in_every_case() {
    let Some(mut ctx) = common::context() else { return };
    let mut seen = Vec::new();
    for (toml, name) in [(CASES, "cases"), ("", "default"), ("", "stairs"), ("", "cubes"), ("", "spheres")] {
        let (stats, r) = render(ctx, toml, name, Method::McGuire, IndexFormat::U16);
        seen.extend(check_formulas(&stats, &r));
        ctx = r.into_context();
    }
    for case in [Case::ZPass, Case::ZFail, Case::ZFailLightCap] {
        assert!(seen.contains(&case), "no caster fell in case {case}: {seen:?}");
    }
}

#[test]
fn mcguire_draws_fewer_triangles_than_lengyel_when_a_caster_is_in_case_2() {
    let Some(ctx) = common::context() else { return };
    let (mc, r) = render(ctx, CASES, "cases", Method::McGuire, IndexFormat::U16);
    let (le, _r) = render(r.into_context(), CASES, "cases", Method::Lengyel, IndexFormat::U16);
    let mut compared = 0;
    for (lm, ll) in mc.lights.iter().zip(&le.lights) {
        for (cm, cl) in lm.casters.iter().zip(&ll.casters) {
            if cm.case == Case::ZFail {
                compared += 1;
                assert!(
                    cm.triangles.total() < cl.triangles.total(),
                    "light {} {}: mcguire {:?} vs lengyel {:?}",
                    lm.index,
                    cm.name,
                    cm.triangles,
                    cl.triangles
                );
            }
        }
    }
    assert!(compared > 0, "the scene must have a case-2 caster");
    println!("mcguire {} vs lengyel {} shadow triangles in total", mc.totals.triangles.total(), le.totals.triangles.total());
}

#[test]
fn bytes_per_triangle_by_index_format() {
    let Some(mut ctx) = common::context() else { return };
    for (fmt, index_bpt, vertex_bpt) in [(IndexFormat::U16, 6, 0), (IndexFormat::U32, 12, 0), (IndexFormat::Naive, 0, 48)] {
        let (stats, r) = render(ctx, "", "default", Method::McGuire, fmt);
        let tris = stats.totals.triangles.total();
        assert!(tris > 0);
        assert_eq!(stats.totals.index_bytes, index_bpt * tris, "{fmt:?}");
        assert_eq!(stats.totals.vertex_bytes, vertex_bpt * tris, "{fmt:?}: static casters send no vertices unless naive");
        ctx = r.into_context();
    }
    if common::feature(ctx.features.index_type_uint8, "indexTypeUint8") {
        // A box has 9 vertices (8 + apex): 8-bit indices, 3 bytes a triangle.
        let (stats, _r) = render(ctx, CASES, "cases", Method::McGuire, IndexFormat::U8);
        let small: Vec<_> = stats.lights.iter().flat_map(|l| &l.casters).filter(|c| c.index_format == UsedIndexFormat::U8).collect();
        assert!(!small.is_empty(), "no caster used u8 indices");
        for c in small {
            assert_eq!(c.index_bytes, 3 * c.triangles.total(), "{}", c.name);
        }
    }
}
