//! `--method mesh` (mesh-shader extrusion, `VK_EXT_mesh_shader`) against the CPU path: the
//! same stencil counts as `mcguire` pixel for pixel, the same triangle counts per light,
//! caster and part, on the built-in scenes and every hard case (bad input among them). Runs
//! on Mesa lavapipe 25.0.7 (re-running itself there when the system's driver has no mesh
//! shaders: `common::mesh_shader_context`). Validation (synchronisation included) on.
use crate::common;
use umbrage::shadow::{Method, VolumePath};
use umbrage_render::{FrameOutput, RenderOptions, Renderer, Technique, View};

/// The (scene, light) pairs where the mesh path's stencil differs from `mcguire`'s at 128x96,
/// and how many pixels at most. The triangles are the CPU's there too, vertex for vertex (their
/// counts are checked per part, and the vertex expressions are shadow.vert's); what differs is
/// lavapipe's viewport transform. Its vertex pipeline maps clip to window coordinates in
/// LLVM-generated code as `fma(x * (1 / w), scale, translate)`; its mesh pipeline (Mesa's draw
/// module, `draw_pt_post_vs` / `draw_cliptest_tmp.h`, C compiled without FMA) as
/// `(x * (1 / w)) * scale + translate`, rounded twice. Where `scale` (half the viewport's
/// width or height) is a power of two the product is exact and both agree bit for bit: at
/// 128x128 every hard case and built-in scene is equal pixel for pixel
/// ([`mesh_equals_mcguire_on_every_hard_case_and_builtin_scene`]); at 128x96 (`scale` 48 in y)
/// a window y differs by an ulp now and then, which moves a pixel centre across an edge
/// (`hard/staircase_300` light 0, the mixed scene's light 1: one pixel) or, where the side
/// quads lie in the visible surface (`hard/near_coplanar` light 1, a slab bumpy by 1e-7 lit
/// from its plane), the depth compare of many coplanar fragments (docs/mesh.md, "Exactness").
/// Measured on Mesa lavapipe 25.0.7: 128x96, 96x96, 160x120 and 256x192 differ; 128x128 and
/// 256x256 do not. The application cannot choose the driver's rounding, so these stay.
const KNOWN_DIFFS_128X96: [(&str, usize, usize); 3] = [("hard/near_coplanar", 1, 250), ("hard/staircase_300", 0, 4), ("mixed", 1, 4)];

fn frame(r: &mut Renderer, t: Technique) -> FrameOutput {
    r.settings.technique = t.into();
    let out = r.render().unwrap();
    r.context().check_validation().unwrap();
    out
}

/// Renders `r`'s scene with McGuire's CPU path and the mesh path and compares stencil counts
/// (`allowed`: the pairs that may differ, and by how many pixels) and triangle counts.
/// Returns the mesh frame.
fn compare(r: &mut Renderer, name: &str, allowed: &[(&str, usize, usize)]) -> FrameOutput {
    let cpu = frame(r, Technique::Volumes(Method::McGuire));
    let gpu = frame(r, Technique::Mesh);
    // twice: the second frame reuses the slot's buffers and static tables
    let gpu2 = frame(r, Technique::Mesh);
    let stencil_check = || {
        assert_eq!(gpu.stencil.len(), cpu.stencil.len(), "{name}");
        for (li, (a, b)) in cpu.stencil.iter().zip(&gpu.stencil).enumerate() {
            let diff = a.iter().zip(b).filter(|(x, y)| x != y).count();
            let allowed = allowed.iter().find(|g| g.0 == name && g.1 == li).map_or(0, |g| g.2);
            assert!(diff <= allowed, "{name} light {li}: {diff} stencil values differ from mcguire's (allowed {allowed})");
        }
    };
    for (g, g2) in gpu.stencil.iter().zip(&gpu2.stencil) {
        assert!(g == g2, "{name}: mesh frames differ");
    }
    let (cs, gs) = (&cpu.stats, &gpu.stats);
    assert_eq!(gs.method, Technique::Mesh.into());
    common::same_volumes_as_cpu(cs, gs, name, VolumePath::Mesh);
    assert_eq!(cs.totals.triangles.total(), gs.totals.triangles.total(), "{name}");
    assert_eq!(gpu2.stats.totals.triangles.total(), gs.totals.triangles.total(), "{name}");
    stencil_check();
    gpu
}

/// A renderer at 128x128: a power-of-two viewport scale, where lavapipe's vertex and mesh
/// pipelines round window coordinates alike ([`KNOWN_DIFFS_128X96`]).
fn renderer(ctx: umbrage::gpu::Context, scene: umbrage_scene::Scene) -> Renderer {
    sized(ctx, scene, 128, 128)
}

fn sized(ctx: umbrage::gpu::Context, scene: umbrage_scene::Scene, width: u32, height: u32) -> Renderer {
    let opts = RenderOptions { width, height, capture: true, ..Default::default() };
    Renderer::new(ctx, scene, opts).unwrap()
}

/// Every hard case and built-in scene with casters ([`common::hard_and_builtin_scenes`]).
#[test]
fn mesh_equals_mcguire_on_every_hard_case_and_builtin_scene() {
    let Some(mut ctx) = common::mesh_shader_context(concat!(module_path!(), "::mesh_equals_mcguire_on_every_hard_case_and_builtin_scene"))
    else {
        return;
    };
    for name in common::hard_and_builtin_scenes() {
        let mut r = renderer(ctx, umbrage_scene::load(name).unwrap());
        compare(&mut r, name, &[]);
        ctx = r.into_context();
    }
}

/// The mixed scene ([`common::MIXED`]; its dense sphere is several draws' worth of meshlets):
/// the same counts; static casters send no geometry after their first frame; frames in flight
/// stay validation clean.
#[test]
fn mesh_mirrored_chunked_directional_and_static_bytes() {
    let Some(ctx) = common::mesh_shader_context(concat!(module_path!(), "::mesh_mirrored_chunked_directional_and_static_bytes")) else {
        return;
    };
    let scene = common::mixed_scene();
    let mut r = renderer(ctx, scene);
    assert!(r.casters().iter().any(|c| c.chunks.len() > 1), "the dense sphere spans several chunks");
    assert!(r.casters().iter().any(|c| c.mirrored));
    let g = compare(&mut r, "mixed", &[]);
    assert!(g.stats.lights.iter().all(|l| l.casters.iter().any(|c| c.triangles.total() > 0)));
    // after the first mesh frame the static tables are on the GPU: nothing is sent, and the
    // mesh draws read no indices
    let again = frame(&mut r, Technique::Mesh);
    assert_eq!(again.stats.totals.bytes_sent, 0, "static casters on the mesh path send no geometry");
    assert_eq!(again.stats.totals.index_bytes, 0);
    assert_eq!(again.stats.cpu_ms.silhouettes, 0.0, "no CPU facing for closed casters");
    // frames in flight: both ring slots, validation (synchronisation included) clean; and
    // switching between the compute and mesh paths, which share the static tables
    r.settings.technique = Technique::Mesh.into();
    r.throughput(4).unwrap();
    r.context().check_validation().unwrap();
    let c = frame(&mut r, Technique::Compute);
    let m = frame(&mut r, Technique::Mesh);
    for (li, (a, b)) in c.stencil.iter().zip(&m.stencil).enumerate() {
        assert!(a == b, "light {li}: stencil values differ between compute and mesh frames");
    }
}

/// At 128x96 (viewport scale 48 in y) the mesh path differs from `mcguire` in the pairs of
/// [`KNOWN_DIFFS_128X96`] only, by at most their bounds: lavapipe's mesh pipeline rounds window
/// coordinates without the FMA its vertex pipeline uses (the constant's docs). Every other
/// light of those scenes is equal pixel for pixel, and so is every pair at 128x128.
#[test]
fn mesh_differs_at_128x96_only_where_lavapipe_rounds_the_viewport_apart() {
    let Some(mut ctx) =
        common::mesh_shader_context(concat!(module_path!(), "::mesh_differs_at_128x96_only_where_lavapipe_rounds_the_viewport_apart"))
    else {
        return;
    };
    for name in ["hard/near_coplanar", "hard/staircase_300", "mixed"] {
        let scene = match name {
            "mixed" => common::mixed_scene(),
            n => umbrage_scene::load(n).unwrap(),
        };
        let mut r = sized(ctx, scene, 128, 96);
        compare(&mut r, name, &KNOWN_DIFFS_128X96);
        ctx = r.into_context();
    }
}

/// A sphere of 32256 triangles lit from one side (z-pass) and from behind it, the eye in its
/// shadow (z-fail with a dark cap).
const CULL: &str = r#"
ambient = [0.05, 0.05, 0.05]
[camera]
eye = [0.0, 1.5, 6.0]
target = [0.0, 1.5, 0.0]
[[light]]
kind = "point"
position = [6.0, 1.6, 0.3]
[[light]]
kind = "point"
position = [0.1, 1.4, -6.0]
[[mesh]]
name = "floor"
shape = "plane"
size = [30.0, 30.0]
casts_shadow = false
[[mesh]]
name = "sphere"
shape = "sphere"
radius = 1.0
segments = 256
rings = 64
translate = [0.0, 1.5, 0.0]
"#;

/// The task stage culls: the mesh workgroups that ran (a counter the task stage adds to, read
/// back with the frame's counts) are far fewer than the meshlets the draws covered, on a
/// sphere lit from one side; with the cull off (`PassToggles::mesh_task`) every meshlet's
/// workgroup runs. Either way the stencil and the counts per light, caster and part are the
/// CPU's (`compare`), so the cull dropped only workgroups that emit nothing.
#[test]
fn mesh_task_stage_culls_meshlets() {
    let Some(ctx) = common::mesh_shader_context(concat!(module_path!(), "::mesh_task_stage_culls_meshlets")) else { return };
    if !ctx.features.task_shader {
        let why = "the mesh-shader device has no taskShader (Mesa lavapipe 25.0.7 has it)";
        assert!(std::env::var_os("CI").is_none(), "{why}");
        eprintln!("SKIPPED: {why}");
        return;
    }
    let scene = umbrage_scene::load_str(CULL, "cull", std::path::Path::new(".")).unwrap();
    let mut r = renderer(ctx, scene);
    let on = compare(&mut r, "cull", &[]);
    let t = &on.stats.totals;
    assert!(on.stats.lights.iter().all(|l| l.casters.iter().any(|c| c.triangles.total() > 0)));
    assert!(t.mesh_meshlets >= 2 * 500, "two lights' draws over the sphere's meshlets: {}", t.mesh_meshlets);
    eprintln!("the task stage ran {} of {} meshlets", t.mesh_workgroups, t.mesh_meshlets);
    assert!(t.mesh_workgroups * 4 < t.mesh_meshlets, "the task stage ran {} of {} meshlets", t.mesh_workgroups, t.mesh_meshlets);
    assert!(t.mesh_workgroups > 0);
    r.settings.toggles.mesh_task = false;
    let off = compare(&mut r, "cull", &[]);
    let u = &off.stats.totals;
    assert_eq!((u.mesh_workgroups, u.mesh_meshlets), (t.mesh_meshlets, t.mesh_meshlets), "without the cull every meshlet runs");
    assert!(off.stencil == on.stencil, "the same stencil with and without the cull");
    assert_eq!(u.triangles.total(), t.triangles.total());
}

/// The debug overlay (`--view volumes`) draws the mesh path's volumes too: the same image as
/// `mcguire`'s (the same triangles, coloured by case, blended alike), and not the shaded one.
#[test]
fn mesh_volumes_overlay_is_mcguires() {
    let Some(mut ctx) = common::mesh_shader_context(concat!(module_path!(), "::mesh_volumes_overlay_is_mcguires")) else { return };
    for name in ["default", "hard/staircase_300"] {
        let mut images = Vec::new();
        for (view, t) in
            [(View::Shaded, Technique::Mesh), (View::Volumes, Technique::Volumes(Method::McGuire)), (View::Volumes, Technique::Mesh)]
        {
            let opts = RenderOptions { width: 128, height: 128, view, technique: t.into(), ..Default::default() };
            let mut r = Renderer::new(ctx, umbrage_scene::load(name).unwrap(), opts).unwrap();
            images.push(r.render().unwrap().color);
            r.context().check_validation().unwrap();
            ctx = r.into_context();
        }
        let differ = |a: &[u8], b: &[u8]| a.chunks(4).zip(b.chunks(4)).filter(|(p, q)| p != q).count();
        assert!(differ(&images[0], &images[2]) > 128 * 128 / 20, "{name}: the mesh overlay draws nothing");
        assert_eq!(differ(&images[1], &images[2]), 0, "{name}: the mesh overlay is not mcguire's");
    }
}

/// Open and non-manifold parts keep the CPU's multiplicity path (stated per part in the
/// stats), the closed parts of the same caster go to the mesh draws.
#[test]
fn mesh_multiplicity_parts_fall_back_to_the_cpu() {
    let Some(ctx) = common::mesh_shader_context(concat!(module_path!(), "::mesh_multiplicity_parts_fall_back_to_the_cpu")) else { return };
    let mut r = renderer(ctx, umbrage_scene::load("hard/open_casters").unwrap());
    let g = compare(&mut r, "hard/open_casters", &[]);
    let parts: Vec<&str> =
        g.stats.lights.iter().flat_map(|l| l.casters.iter().flat_map(|c| c.parts.iter().map(|p| p.path.name()))).collect();
    assert!(parts.contains(&"multiplicity") && parts.contains(&"mesh"), "{parts:?}");
}

/// Without mesh shaders (the system's lavapipe 22.3.6; or a host that did not enable them)
/// the technique is refused with a clear `Error::Unsupported`, never run some other way.
#[test]
fn mesh_is_refused_without_mesh_shaders() {
    use umbrage::pass::{Capabilities, PassSettings};
    assert_eq!("mesh".parse::<Technique>().unwrap(), Technique::Mesh);
    assert_eq!(Technique::Mesh.name(), "mesh");
    let s = PassSettings { technique: Technique::Mesh, ..Default::default() };
    let e = s.check(&Capabilities::default()).unwrap_err();
    assert!(matches!(e, umbrage::Error::Unsupported(_)) && e.to_string().contains("VK_EXT_mesh_shader"), "{e}");
    assert!(s.check(&Capabilities { mesh_shader: true, ..Default::default() }).is_ok());
    let Some(ctx) = common::context() else { return };
    if ctx.features.mesh_shader {
        // The refusal needs a device without mesh shaders: the same test on lavapipe 22.3.6.
        drop(ctx);
        common::rerun_without_the_feature(concat!(module_path!(), "::mesh_is_refused_without_mesh_shaders"));
        return;
    }
    let mut r = renderer(ctx, umbrage_scene::load("default").unwrap());
    r.settings.technique = Technique::Mesh.into();
    let e = r.render().map(|_| ()).unwrap_err();
    assert!(matches!(e, umbrage::Error::Unsupported(_)) && e.to_string().contains("VK_EXT_mesh_shader"), "{e}");
}
