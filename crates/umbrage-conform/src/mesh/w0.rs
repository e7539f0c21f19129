//! `mesh.w0_vertices`: vertices at infinity out of a mesh stage (the module doc says what).

use super::rig::{Draw, PipeState, Rig};
use super::{expect_stencil, far, near, projection, stencil_mismatches, Push, F_NEAR_ZERO_W};
use crate::harness::{self, DrawCall, Indices, PipeSpec};
use crate::CheckResult;
use ash::vk;
use glam::{DVec4, Mat4};
use serde_json::json;
use umbrage::error::{Error, Result};
use umbrage::gpu::Context;

/// Image size.
pub(super) const SIZE: (u32, u32) = (160, 120);
/// The stencil's start: front faces INCR_WRAP and back faces DECR_WRAP move it either way.
const START: u8 = 0x80;

/// A group of triangles drawn with one light: object-space vertices (w = 1 finite, w = 0
/// extruded away from the light), three a triangle.
pub(super) struct Scenario {
    pub name: &'static str,
    pub light: [f32; 4],
    pub vertices: Vec<[f32; 4]>,
}

/// extrude.wgsl's side quad of edge a -> b: (b, a, a∞), (b, a∞, b∞).
fn side(out: &mut Vec<[f32; 4]>, a: [f32; 3], b: [f32; 3]) {
    let (n, f) = (|p: [f32; 3]| [p[0], p[1], p[2], 1.0], |p: [f32; 3]| [p[0], p[1], p[2], 0.0]);
    out.extend([n(b), n(a), f(a), n(b), f(a), f(b)]);
}

/// Dark caps: every vertex at infinity (light at the eye, so a w = 0 vertex is the direction
/// itself): 12 triangles (two workgroups) — four alone, one of them crossing the view's right
/// side, one the left and top, one back facing — and a fan of eight around a shared vertex.
pub(super) fn dark_caps() -> Scenario {
    let mut v: Vec<[f32; 4]> = vec![
        [-0.5, -0.25, -1.0, 0.0],
        [0.125, 0.5, -1.0, 0.0],
        [0.375, -0.375, -1.0, 0.0],
        [0.5, 0.125, -1.0, 0.0],
        [1.5, 0.25, -1.0, 0.0],
        [0.75, 0.875, -1.0, 0.0],
        [-1.25, -0.5, -2.0, 0.0],
        [-0.25, -1.0, -2.0, 0.0],
        [-1.0, -1.25, -1.5, 0.0],
        [0.25, -0.5, -1.0, 0.0],
        [0.625, -0.75, -1.0, 0.0],
        [0.5, -0.375, -1.0, 0.0],
    ];
    let c = [-0.25f32, 0.5, -1.0];
    let rim: [[f32; 2]; 8] =
        [[0.25, 0.0], [0.125, 0.125], [0.0, 0.25], [-0.125, 0.125], [-0.25, 0.0], [-0.125, -0.125], [0.0, -0.25], [0.125, -0.125]];
    for k in 0..8 {
        let (p, q) = (rim[k], rim[(k + 1) % 8]);
        v.extend([[c[0], c[1], c[2], 0.0], [c[0] + p[0], c[1] + p[1], c[2], 0.0], [c[0] + q[0], c[1] + q[1], c[2], 0.0]]);
    }
    Scenario { name: "dark_caps", light: [0.0, 0.0, 0.0, 1.0], vertices: v }
}

/// Side quads whose far vertices land at clip w = 0 exactly (edges at the light's depth: the
/// extrusion runs parallel to the image plane), fanning out to the view's four sides. The
/// light is off the view axis, so an edge to a far vertex at a small w > 0 instead of
/// infinity would run in another direction on screen.
pub(super) fn in_plane() -> Scenario {
    let mut v = Vec::new();
    side(&mut v, [0.5, 0.25, -2.0], [0.25, 0.5, -2.0]);
    side(&mut v, [-0.5, 0.125, -2.0], [-0.375, -0.5, -2.0]);
    side(&mut v, [0.125, -0.5, -2.0], [0.625, -0.25, -2.0]);
    side(&mut v, [-0.25, 0.625, -2.0], [-0.625, 0.25, -2.0]);
    Scenario { name: "in_plane", light: [0.25, -0.125, -2.0, 1.0], vertices: v }
}

/// Side quads whose far vertices point behind the eye (clip w < 0): the light is farther than
/// the caster, so the volume runs towards the camera and past it. The first quad straddles the
/// view axis and crosses the near plane inside the view: depth clamp keeps what lies between
/// the near plane and the eye, up to the view's edge.
pub(super) fn behind() -> Scenario {
    let mut v = Vec::new();
    side(&mut v, [-0.25, -0.125, -1.5], [0.25, -0.125, -1.5]);
    side(&mut v, [0.5, -0.25, -1.5], [0.0, -0.5, -1.5]);
    Scenario { name: "behind", light: [0.0, -0.3125, -3.0, 1.0], vertices: v }
}

/// Side quads whose far vertices lie ahead (clip w > 0, depth 1).
pub(super) fn ahead() -> Scenario {
    let mut v = Vec::new();
    side(&mut v, [-0.75, -0.25, -1.0], [-0.25, -0.75, -1.0]);
    side(&mut v, [0.75, 0.5, -1.25], [0.375, 0.75, -1.25]);
    Scenario { name: "ahead", light: [0.0, 0.25, -0.5, 1.0], vertices: v }
}

/// The scenario's clip-space triangles, exactly as the shader computes them.
pub(super) fn clip_tris(s: &Scenario, mvp: Mat4, near_zero: bool) -> Result<Vec<[DVec4; 3]>> {
    let place = |p: [f32; 4]| if p[3] == 0.0 { far(mvp, s.light, p, near_zero) } else { near(mvp, p) };
    s.vertices
        .chunks_exact(3)
        .map(|t| match (place(t[0]), place(t[1]), place(t[2])) {
            (Some(a), Some(b), Some(c)) => Ok([a, b, c]),
            _ => Err(Error::Internal(format!("mesh.w0_vertices: the {} vertices are not exact in f32 (the model's premise)", s.name))),
        })
        .collect()
}

/// One render: which scenarios, the near-zero flag, depth clamp, depth written and checked.
struct Run {
    label: String,
    scenarios: Vec<Scenario>,
    near_zero: bool,
    clamp: bool,
    depth: bool,
}

/// Depth word equal to exactly 1.0 in `format` (D32: the float's bits; D24: all ones).
fn depth_one(format: vk::Format, word: u32) -> bool {
    match format {
        vk::Format::D24_UNORM_S8_UINT => word & 0x00ff_ffff == 0x00ff_ffff,
        _ => f32::from_bits(word) == 1.0,
    }
}

/// `mesh.w0_vertices`.
pub fn w0_vertices(ctx: &Context) -> Result<CheckResult> {
    let format = ctx.depth_format;
    let bits = ctx.limits.sub_pixel_precision_bits;
    let eps = 1.5 / (1u64 << bits) as f64;
    let mvp = projection();
    let mut runs = Vec::new();
    for clamp in [false, true] {
        if clamp && !ctx.features.depth_clamp {
            continue;
        }
        let c = if clamp { "clamp_on" } else { "clamp_off" };
        runs.push(Run { label: format!("dark_caps.{c}"), scenarios: vec![dark_caps()], near_zero: false, clamp, depth: true });
        for near_zero in [false, true] {
            let w = if near_zero { "near_zero_w" } else { "w0_as_is" };
            let scenarios = vec![in_plane(), behind(), ahead()];
            runs.push(Run { label: format!("sides.{w}.{c}"), scenarios, near_zero, clamp, depth: false });
        }
    }
    let mut numbers = serde_json::Map::new();
    let mut fails = Vec::new();
    for run in &runs {
        let table: Vec<[f32; 4]> = run.scenarios.iter().flat_map(|s| s.vertices.iter().copied()).collect();
        let mut rig = Rig::new(ctx, &table, &[], 64)?;
        let mut st = PipeState::stencil(vk::StencilOp::INCREMENT_AND_WRAP, vk::StencilOp::DECREMENT_AND_WRAP);
        st.depth_write = run.depth;
        st.depth_clamp = run.clamp;
        let pipe = rig.pipeline(None, c"w0", format, st)?;
        let flags = if run.near_zero { F_NEAR_ZERO_W } else { 0 };
        let (mut draws, mut tris, mut first, mut rec) = (Vec::new(), Vec::new(), 0u32, 0u32);
        let mut groups = Vec::new();
        for s in &run.scenarios {
            let n = (s.vertices.len() / 3) as u32;
            let g = n.div_ceil(8);
            draws.push(Draw { pipeline: pipe, push: Push::new(mvp, s.light, flags, (first, n, rec)), groups: [g, 1, 1], ops: None });
            groups.push((rec, g));
            tris.extend(clip_tris(s, mvp, run.near_zero)?);
            first += 3 * n;
            rec += g;
        }
        let got = rig.render(format, SIZE, (0.0, START as u32), &draws)?;
        let model = expect_stencil(&tris, run.clamp, SIZE, bits, eps, START, (1, -1));
        let (judged, bad, first_bad) = stencil_mismatches(&got.image, &model);
        // Every workgroup ran once.
        let group_words: Vec<u32> = groups.iter().flat_map(|&(r, g)| got.records[r as usize..(r + g) as usize].to_vec()).collect();
        let groups_ok = group_words.iter().all(|&c| c == 1) && got.records[rec as usize..].iter().all(|&c| c == 0);
        let covered = model.stencil.iter().zip(&model.judged).filter(|(&s, &j)| j && s != START).count();
        let mut depth_not_one = 0u64;
        // The test seam (`value_images::skewed`): expect the dark caps at depth 0.5 (none is).
        let (skew, one) = if crate::value_images::skewed() { (true, 0.5) } else { (false, 1.0) };
        let wrong = |word: u32| skew || !depth_one(format, word);
        if run.depth {
            for (i, &s) in model.stencil.iter().enumerate() {
                if model.judged[i] && s != START && wrong(got.image.depth[i]) {
                    depth_not_one += 1;
                }
            }
        }
        if depth_not_one > 0 {
            let covered: Vec<Option<f64>> =
                model.stencil.iter().zip(&model.judged).map(|(&s, &j)| (j && s != START).then_some(one)).collect();
            let actual: Vec<f64> = got.image.depth.iter().map(|&d| harness::depth_value(format, d)).collect();
            let bad = |i: usize| covered[i].is_some() && wrong(got.image.depth[i]);
            crate::image_sink::depth_mismatch(SIZE.0, SIZE.1, &covered, &actual, &bad);
        }
        let vertex = vertex_pipeline_differences(ctx, run, &tris, &got.image)?;
        numbers.insert(
            run.label.clone(),
            json!({
                "triangles": tris.len(), "workgroups": group_words.len(), "workgroup_runs": group_words,
                "judged_pixels": judged, "stencil_mismatches": bad, "covered_pixels_expected": covered,
                "depth_not_exactly_1": if run.depth { json!(depth_not_one) } else { json!(null) },
                "singular_polygons": model.singular,
                "vertex_pipeline_stencil_differences": vertex.0, "vertex_pipeline_depth_differences": vertex.1,
            }),
        );
        let l = &run.label;
        if bad > 0 {
            fails.push(format!("{l}: {bad} of {judged} judged pixels differ ({})", first_bad.join(", ")));
        }
        if !groups_ok {
            fails.push(format!("{l}: workgroups did not each run once: {group_words:?}"));
        }
        if depth_not_one > 0 {
            fails.push(format!("{l}: {depth_not_one} covered pixels with depth != 1.0"));
        }
        if covered == 0 || model.singular > 0 {
            fails.push(format!("{l}: the model covers nothing or has {} singular polygons (a broken check)", model.singular));
        }
    }
    numbers.insert("subpixel_bits".into(), json!(bits));
    numbers.insert("band_pixels".into(), json!(eps));
    let clamp = if ctx.features.depth_clamp { "with and without depth clamp" } else { "without depth clamp (no depthClamp)" };
    let what = format!(
        "mesh-stage vertices at infinity (dark caps at depth exactly 1.0, far vertices at clip w = 0 as they are and as \
         extrude's near-zero w, and behind the eye), {clamp}: coverage and facing exact against the model"
    );
    Ok(CheckResult::from_fails("w0_vertices", fails, numbers, &what))
}

/// The same clip-space triangles through the vertex pipeline (`shadow.vert`'s RAW_W0 variant,
/// identity transform: the vertices reach the clipper bit for bit): the stencil bytes and
/// (when written) depth words that differ from the mesh pipeline's, over every pixel. A
/// measurement: the spec does not require the two pipelines to agree.
fn vertex_pipeline_differences(ctx: &Context, run: &Run, tris: &[[DVec4; 3]], mesh: &harness::Readback) -> Result<(u64, u64)> {
    let vertices: Vec<[f32; 4]> = tris.iter().flat_map(|t| t.map(|c| c.as_vec4().to_array())).collect();
    let mut spec = PipeSpec::stencil(vk::StencilOp::INCREMENT_AND_WRAP, vk::StencilOp::DECREMENT_AND_WRAP);
    if run.depth {
        spec.depth_test = true;
        spec.depth_write = true;
    }
    spec.depth_clamp = run.clamp;
    let draw = DrawCall { spec, mvp: Mat4::IDENTITY, vertices, indices: Indices::None };
    let rb = harness::render(ctx, ctx.depth_format, SIZE.0, SIZE.1, 0.0, START as u32, &[draw])?;
    let stencil = rb.stencil.iter().zip(&mesh.stencil).filter(|(a, b)| a != b).count() as u64;
    let depth = if run.depth { rb.depth.iter().zip(&mesh.depth).filter(|(a, b)| a != b).count() as u64 } else { 0 };
    Ok((stencil, depth))
}

/// The model's stencil of a scenario alone (for the unit tests).
#[cfg(test)]
pub(super) fn model_of(s: &Scenario, near_zero: bool, clamp: bool, bits: u32) -> super::Model {
    let tris = clip_tris(s, projection(), near_zero).expect("exact");
    expect_stencil(&tris, clamp, SIZE, bits, 1.5 / (1u64 << bits) as f64, START, (1, -1))
}
