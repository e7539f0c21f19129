//! Packing a frame: every light planned (culling, cases, possible silhouettes, index lists),
//! the index streams (or naive vertices) packed into one byte stream for the ring slot, and
//! the statistics `--stats` reports.

use super::casters::CasterTable;
use super::compute::work::ComputeWork;
use super::desc::{DepthDirection, PassSettings, Technique};
use super::draw::{CasterDraw, EdgeQuadDraw, LightFrame};
use super::lists::{align, write_chunks, ChunkDraws};
use super::planar::flatten;
use super::stats::{CasterStats, CpuMs, LightStats, PartStats, Totals, Triangles, UsedIndexFormat};
use super::view::ShadowView;
use crate::geom::{Camera, Light};
use crate::shadow::{self, Case, CasterKind, LightPlan, PlanInput, PlanOptions, VolumePath};
use ash::vk;
use glam::{DMat4, DVec3, Mat4, Vec4};

/// The plans, packed: what `prepare` builds before writing the slot's stream.
pub(crate) struct Packed {
    pub stream: Vec<u8>,
    /// The compute pass's layout ([`Technique::Compute`]).
    pub compute: Option<ComputeWork>,
    pub lights: Vec<LightFrame>,
    pub totals: Totals,
    pub cpu: CpuMs,
}

/// Inputs of [`pack`].
pub(crate) struct PackInput<'a> {
    pub view: &'a ShadowView,
    /// The host's depth direction (the planner works on the forward view).
    pub direction: DepthDirection,
    pub lights: &'a [Light],
    pub settings: PassSettings,
    pub u8_ok: bool,
    pub depth_bounds: bool,
    /// Plan the casters (false: every caster culled, scissors only).
    pub casters: bool,
    /// The receiver plane of [`Technique::Planar`](super::Technique::Planar) (world, `n·x + d = 0`).
    pub planar_receiver: glam::DVec4,
    /// The analytic sphere casters (planned after the mesh casters, per light).
    pub spheres: &'a [super::spheres::SphereCaster],
}

/// Plans every light and packs the index streams (or naive vertices) into one byte stream.
/// With `kept` (the frame's kept plans, [`super::keep`]), each light's plan comes from there
/// and the kept pairs' draws read their own buffers; the rest is written into the stream.
pub(crate) fn pack(table: &CasterTable, input: &PackInput, kept: Option<Vec<super::keep::KeptLight>>) -> Packed {
    let mut kept = kept.map(|k| k.into_iter());
    let view = input.view;
    // The volumes are drawn with the host's projection; the planner (near plane, frustum,
    // scissor, depth bounds) works on its forward equivalent.
    let fwd = view.forward(input.direction);
    let view_proj = fwd.world_view_proj();
    let vp_rel_d = view.proj.as_dmat4() * view.view.as_dmat4();
    let camera = Camera { eye: view.eye.as_vec3(), ..Camera::default() };
    let edge_quads = input.settings.technique == Technique::EdgeQuads;
    // Mesh-shader extrusion plans as the compute path does and runs its facing stages.
    let mesh = input.settings.technique == Technique::Mesh;
    let gpu_silhouettes = input.settings.technique == Technique::Compute || mesh;
    let mut compute = gpu_silhouettes.then(|| ComputeWork { mesh, ..ComputeWork::default() });
    let method = input.settings.technique.method();
    let mvps: Vec<Mat4> = table.live.iter().map(|g| (vp_rel_d * DMat4::from_translation(-view.eye) * g.transform).as_mat4()).collect();
    let full = vk::Rect2D { offset: vk::Offset2D { x: 0, y: 0 }, extent: vk::Extent2D { width: view.width, height: view.height } };

    let mut stream: Vec<u8> = Vec::new();
    // the lists' bytes of pairs drawn from their kept buffers (not in the stream)
    let mut from_kept = 0u64;
    let mut totals = Totals::default();
    let mut cpu = CpuMs::default();
    let mut lights = Vec::with_capacity(input.lights.len());
    for (li, light) in input.lights.iter().enumerate() {
        // Each part (connected component) of a caster gets its own case; every draw carries it.
        let (mut plan, mut kept_draws) = match kept.as_mut().and_then(|k| k.next()) {
            Some(k) => {
                // the casters out of the light's range, left out of its lists
                totals.cases.culled += k.omitted;
                (k.plan, k.draws)
            }
            None => {
                let plan = shadow::plan_light_with(
                    &PlanInput { camera: &camera, width: view.width, height: view.height, view_proj, light, method },
                    if input.casters { &table.cpu } else { &[] },
                    &PlanOptions { edge_quads, case_per_part: true, gpu_silhouettes, no_culling: !input.settings.toggles.culling },
                );
                (plan, Vec::new())
            }
        };
        if mesh {
            // the parts left to the GPU are drawn by mesh draws
            for cp in &mut plan.casters {
                if cp.path == VolumePath::Compute {
                    cp.path = VolumePath::Mesh;
                }
                for pp in cp.parts.iter_mut().filter(|p| p.path == VolumePath::Compute) {
                    pp.path = VolumePath::Mesh;
                }
            }
        }
        let planar_mvp = (input.settings.technique == Technique::Planar).then(|| flatten(&mut plan, table, light, input.planar_receiver));
        cpu.silhouettes += plan.silhouette_ms;
        // plan_ms covers the whole planner, facing and silhouettes included
        cpu.plan += (plan.plan_ms - plan.silhouette_ms).max(0.0);
        let mut casters = Vec::with_capacity(plan.casters.len());
        let mut cstats = Vec::with_capacity(plan.casters.len());
        for (k, cp) in plan.casters.iter().enumerate() {
            let caster = &table.cpu[cp.caster];
            let gpu = &table.live[cp.caster];
            let chunk_draws = match kept_draws.get_mut(k).and_then(Option::take) {
                Some(d) => {
                    from_kept += d.index_bytes + d.vertex_bytes;
                    d
                }
                None => {
                    let handles: Vec<vk::Buffer> = gpu.chunks.iter().map(|b| b.raw).collect();
                    write_chunks(&mut stream, (input.settings.index_format, input.u8_ok), caster, &handles, cp)
                }
            };
            let ChunkDraws { mut draws, index_bytes, vertex_bytes, mut fmt_used } = chunk_draws;
            if let (Some(cf), Some(st)) = (compute.as_mut(), gpu.compute.as_ref()) {
                let at = crate::pass::compute::work::CasterAt { light: li, stat: cstats.len() };
                if cp.parts.iter().any(|p| p.path == VolumePath::Compute && p.case != Case::Culled) {
                    let buffers: Vec<vk::Buffer> = gpu.chunks.iter().map(|b| b.raw).collect();
                    cf.add_caster(at, caster, st, cp, (&buffers, mvps[cp.caster]), draws.to_mut());
                    fmt_used = UsedIndexFormat::U16;
                }
                if cp.parts.iter().any(|p| p.path == VolumePath::Mesh && p.case != Case::Culled) {
                    cf.add_caster_mesh(at, caster, st, cp, draws.to_mut());
                }
            }
            let tris = Triangles { sides: cp.sides as u64, dark_cap: cp.dark_cap as u64, light_cap: cp.light_cap as u64 };
            totals.triangles.add(&tris);
            totals.index_bytes += index_bytes;
            totals.vertex_bytes += vertex_bytes;
            totals.draws += draws.len() as u64 + if cp.path == VolumePath::EdgeQuad { 2 } else { 0 };
            match cp.case {
                Case::Culled => totals.cases.culled += 1,
                Case::ZPass => totals.cases.zpass += 1,
                Case::ZFail => totals.cases.zfail += 1,
                Case::ZFailLightCap => totals.cases.zfail_light_cap += 1,
            }
            cstats.push(caster_stats(caster, cp, tris, (index_bytes, vertex_bytes), fmt_used));
            let edge_quad = match (&gpu.edge_quads, cp.path == VolumePath::EdgeQuad) {
                (Some(eq), true) => Some(EdgeQuadDraw {
                    vertices: eq.vertices.raw,
                    indices: eq.indices.raw,
                    face_indices: eq.face_indices,
                    quad_indices: eq.quad_indices,
                }),
                _ => None,
            };
            casters.push(CasterDraw {
                case: cp.case,
                mvp: match &planar_mvp {
                    // Flattened: the caster's triangles projected from the light onto the plane.
                    Some(m) => (vp_rel_d * DMat4::from_translation(-view.eye) * *m * table.live[cp.caster].transform).as_mat4(),
                    None => mvps[cp.caster],
                },
                light_object: Vec4::from_array(cp.light_object),
                transmittance: caster.transmittance,
                draws,
                edge_quad,
            });
        }
        if input.casters {
            let sin = super::spheres::SphereInput {
                view,
                scale: super::spheres::view_scale(&fwd),
                light,
                technique: input.settings.technique,
                planar_receiver: input.planar_receiver,
            };
            let start = std::time::Instant::now();
            super::spheres::pack_light(input.spheres, &sin, &mut stream, &mut totals, &mut casters, &mut cstats);
            // The spheres' planning (tangency circles, n, volumes) counts as planning.
            cpu.plan += start.elapsed().as_secs_f64() * 1e3;
        }
        lights.push(light_frame(table, input, (&fwd, full), (li, light), plan, (cstats, casters)));
    }
    align(&mut stream, 16);
    // what the stream carries (kept pairs' lists were sent when they were planned)
    totals.bytes_sent = totals.index_bytes + totals.vertex_bytes - from_kept;
    Packed { stream, lights, totals, cpu, compute }
}

/// Light `li`'s frame from its plan and packed casters: its scissor (the whole target `full`
/// when it has none or scissors are off), depth bounds in the host's direction, and for
/// z-pass with clear the volumes containing the eye.
fn light_frame(
    table: &CasterTable,
    input: &PackInput,
    (fwd, full): (&ShadowView, vk::Rect2D),
    (li, light): (usize, &Light),
    plan: LightPlan,
    (cstats, casters): (Vec<CasterStats>, Vec<CasterDraw>),
) -> LightFrame {
    let view = input.view;
    let method = input.settings.technique.method();
    let scissor = plan
        .scissor
        .map(|[x, y, sw, sh]| vk::Rect2D {
            offset: vk::Offset2D { x: x as i32, y: y as i32 },
            extent: vk::Extent2D { width: sw, height: sh },
        })
        .filter(|r| r.extent.width > 0 && r.extent.height > 0 && input.settings.toggles.scissor)
        .unwrap_or(full);
    let depth_bounds = if input.depth_bounds { plan.depth_bounds } else { None };
    let depth_bounds = match input.direction {
        DepthDirection::Forward => depth_bounds,
        DepthDirection::Reverse => depth_bounds.map(|(lo, hi)| reversed_bounds(lo, hi)),
    };
    let (eye_volumes, near_plane_split) = if method == shadow::Method::ZPassClear {
        let [c0, c1, c2, c3] = near_corners(fwd);
        let counts = super::eye::volumes_containing(&[view.eye, c0, c1, c2, c3], light, &plan, table);
        (Some(counts[0]), Some(counts[1..].iter().any(|&c| c != counts[0])))
    } else {
        (None, None)
    };
    let stats = LightStats {
        index: li,
        kind: light.kind,
        scissor: plan.scissor.filter(|_| input.settings.toggles.scissor),
        depth_bounds: depth_bounds.map(|(a, b)| [a, b]),
        casters: cstats,
        eye_volumes,
        near_plane_split,
    };
    let counter_clear = eye_volumes.unwrap_or(0).max(0) as u32;
    LightFrame { scissor, depth_bounds, stats, plan, counter_clear, casters }
}

/// What `--stats` reports of caster `cp` for one light.
fn caster_stats(
    caster: &shadow::Caster,
    cp: &shadow::CasterPlan,
    tris: Triangles,
    (index_bytes, vertex_bytes): (u64, u64),
    fmt_used: UsedIndexFormat,
) -> CasterStats {
    let ntris = tris.total();
    CasterStats {
        name: caster.name.clone(),
        case: cp.case,
        silhouette_edges: cp.silhouette_edges as u64,
        triangles: tris,
        index_bytes,
        vertex_bytes,
        bytes_per_triangle: if ntris > 0 { (index_bytes + vertex_bytes) as f64 / ntris as f64 } else { 0.0 },
        index_format: fmt_used,
        dark_cap_kind: cp.dark_cap_kind,
        path: cp.path,
        path_reason: match &caster.kind {
            CasterKind::Multiplicity { reason } => reason.clone(),
            _ => String::new(),
        },
        multiplicity_max: cp.multiplicity_max,
        parts: cp
            .parts
            .iter()
            .map(|p| PartStats {
                part: p.part,
                case: p.case,
                path: p.path,
                silhouette_edges: p.silhouette_edges as u64,
                triangles: Triangles { sides: p.sides as u64, dark_cap: p.dark_cap as u64, light_cap: p.light_cap as u64 },
            })
            .collect(),
        sphere: None,
    }
}

/// Forward depth bounds `[lo, hi]` as reverse-Z bounds `[1 - hi, 1 - lo]`, rounded outwards
/// to f32 (the subtraction is exact in f64).
fn reversed_bounds(lo: f32, hi: f32) -> (f32, f32) {
    let (a, b) = (1.0 - hi as f64, 1.0 - lo as f64);
    let (mut a32, mut b32) = (a as f32, b as f32);
    if a32 as f64 > a {
        a32 = f32::from_bits(a32.to_bits().saturating_sub(1));
    }
    if (b32 as f64) < b {
        b32 = f32::from_bits(b32.to_bits() + 1);
    }
    (a32.clamp(0.0, 1.0), b32.clamp(0.0, 1.0))
}

/// The near-plane rectangle's corners in world space (forward Vulkan depth 0).
fn near_corners(view: &ShadowView) -> [DVec3; 4] {
    let inv = (view.proj.as_dmat4() * view.view.as_dmat4()).inverse();
    [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)].map(|(x, y)| {
        let h = inv * glam::DVec4::new(x, y, 0.0, 1.0);
        h.truncate() / h.w + view.eye
    })
}
