//! Per-light shadow-volume plans: culling, case selection and index generation.
//!
//! Geometry (object space, chunk-local indices; w=1 copy of vertex i is `i`, w=0 copy `i+n`):
//! * sides, per silhouette edge a->b (as in the light-facing triangle): point light
//!   `(b, a, a∞), (b, a∞, b∞)`; directional `(b, a, a∞)` (all ∞ coincide);
//! * dark cap: `Fan` = `(apex∞, b∞, a∞)` per silhouette edge (point light strictly outside
//!   the caster's AABB); `FrontFaces` = every light-facing triangle's w=0 copy reversed;
//!   `BackFaces` = every non-light-facing triangle's w=0 copy as is;
//! * light cap: front formulation = light-facing triangles as is; back formulation =
//!   non-light-facing triangles reversed.
//!
//! Every emitted triangle's front face points OUT of the shadow volume (tests prove it with
//! directed-edge cancellation and a positive signed volume at finite extrusion).
//!
//! # Multiplicity casters (Kim, Kim & Turk 2008)
//!
//! Casters that are not closed 2-manifolds are the sum of one volume per triangle: `V_T` =
//! the points whose segment to the light crosses `T`, whichever way `T` faces. Let `T'` be
//! `T` oriented towards the light (`T` if its facing bit is set, else reversed). `V_T` is
//! closed by the light cap `T'`, the dark cap `T'∞` reversed, and one side `(b, a, a∞, b∞)`
//! per edge `a -> b` of `T'`; every face points out of `V_T`. The stencil count at a point is
//! then the number of caster triangles between it and the light: zero iff lit.
//! Summing the sides of all triangles per undirected edge `(v0 < v1)` gives its
//! **multiplicity** `m = Σ_T s_T`, `s_T = (T walks v0->v1 ? +1 : -1) * (T light-facing ? +1 : -1)`;
//! the side of `v0 -> v1` is emitted `m` times when `m > 0`, the side of `v1 -> v0` `-m` times
//! when `m < 0`, nothing when `m = 0` (interior edges of a consistently facing patch). A
//! closed manifold's silhouette edges get `|m| = 2` here (both the near and the far face
//! occlude), which is why closed manifolds keep the classic path.
//! Caps: the fan dark cap works per edge exactly as for manifolds (`|m|` copies of
//! `(apex∞, b∞, a∞)` for the oriented edge a->b, point light strictly outside the AABB);
//! otherwise every triangle's `T'∞` reversed (`DarkCap::AllFaces`).
//! Light caps: the renderer's depth-NEVER light-cap pipeline counts a cap as if it were
//! behind the visible surface. That holds for a triangle the G-buffer pass drew (front-facing
//! to the eye: back faces are culled), since the visible surface is then at or in front of
//! it; and drawing such caps with LESS instead would z-fight with the very surface they lie
//! on (self-shadowing acne). An open mesh, though, can be seen THROUGH a triangle whose back
//! faces the eye, and that cap may lie in front of the visible surface. So: caps of
//! triangles that face the eye, or have an exact coincident twin that does (duplicates,
//! back-to-back pairs), go to `light_cap` (NEVER, z-fail cases only); the caps of all other
//! triangles go to `volume` (depth LESS) in z-pass and in the z-fail-with-light-cap case.

use super::caster::{Caster, CasterKind, SIDE_TAG_SPLIT};

use crate::geom::bounds::{box_distance, light_depth_bounds, light_scissor, shadow_volume_outside_frustum, Frustum, OcclusionPyramid};
use crate::geom::edgescan::oriented;
use crate::geom::silhouette::{packed_bit, EdgeScan, ScanHit, SilhouetteEdge};
use crate::geom::Aabb;
use crate::geom::LightKind;
use glam::Vec4;
use std::time::Instant;

mod emit;
mod light;
mod types;

use emit::*;
pub use emit::{emit, Emit};
use light::spot_culls;
pub use light::{avoid_vertex, object_light};
pub use types::*;

/// The case a method picks for a caster whose world box is `wb` (same for both paths).
fn select_case(method: Method, pyramid: &OcclusionPyramid, frustum: &Frustum, wb: &Aabb) -> Case {
    match method {
        Method::ZPass | Method::ZPassClear => Case::ZPass,
        Method::ZFail | Method::EverittKilgard => Case::ZFailLightCap,
        Method::Lengyel => {
            if pyramid.intersects_box(wb) {
                Case::ZFailLightCap
            } else {
                Case::ZPass
            }
        }
        Method::McGuire => {
            if !pyramid.intersects_box(wb) {
                Case::ZPass
            } else if !frustum.intersects_box(wb) {
                Case::ZFail
            } else {
                Case::ZFailLightCap
            }
        }
    }
}

mod multiplicity;
pub use multiplicity::{edge_multiplicities, emit_multiplicity, MultiplicityInput, MultiplicityVolume};
use multiplicity::{edge_multiplicities_with, emit_multiplicity_with, VolumeShape};

/// How expensive a case is to draw (the caster's case is its most expensive part's).
fn case_rank(c: Case) -> u8 {
    match c {
        Case::Culled => 0,
        Case::ZPass => 1,
        Case::ZFail => 2,
        Case::ZFailLightCap => 3,
    }
}

/// What a closed manifold part not culled emits for the object-space light `l_obj` in `case`:
/// the back formulation (and the dark cap of its back faces) when a point light is inside the
/// part's bounds, else the front one with McGuire's fan dark cap (`Method::McGuire`) or the
/// front faces' w=0 copies; no dark cap for z-pass or a directional light; the light cap in
/// case 3. The CPU path and the GPU silhouettes (`--method compute`) both follow it.
pub fn manifold_emit(method: Method, part: &super::caster::Part, case: Case, l_obj: Vec4) -> Emit {
    let directional = l_obj.w == 0.0;
    let inside = !directional && part.object_bounds.contains(l_obj.truncate());
    let formulation = if inside { Formulation::Back } else { Formulation::Front };
    let dark_cap = if case == Case::ZPass || directional {
        DarkCap::None
    } else if formulation == Formulation::Back {
        DarkCap::BackFaces
    } else if method == Method::McGuire {
        DarkCap::Fan
    } else {
        DarkCap::FrontFaces
    };
    Emit { formulation, directional, dark_cap, light_cap: case == Case::ZFailLightCap }
}

/// Which part of a caster [`plan_part`] plans, on which path and in which case.
#[derive(Clone, Copy)]
struct PartJob {
    /// Index of the part in [`Caster::parts`].
    part: usize,
    /// The edge-multiplicity path (else the silhouette path).
    multiplicity: bool,
    case: Case,
}

/// Plans one part of a caster for which the facing `bits` are decided (in the caster's scan
/// order, for the edge scan; `tri_bits`: the same bits in welded triangle order, for the
/// per-triangle work); returns the part plan and its draws.
fn plan_part(
    input: &PlanInput,
    caster: &Caster,
    job: PartJob,
    l_obj: Vec4,
    (bits, tri_bits): (&[u64], &[u64]),
    (hits, ends): (&mut Vec<ScanHit>, &mut Vec<SideEnds>),
) -> (PartPlan, Vec<ChunkDraw>) {
    let PartJob { part: pi, multiplicity, case } = job;
    let part = &caster.parts[pi];
    let directional = l_obj.w == 0.0;
    let facing = Packed(tri_bits);
    let inside = !directional && part.object_bounds.contains(l_obj.truncate());
    if multiplicity {
        let mult = edge_multiplicities_with(caster, &part.edges, &facing);
        // The renderer draws opaque multiplicity casters two-sided in the G-buffer pass, so
        // every light cap (a caster triangle itself) lies at or behind the visible surface along
        // any ray that crosses it: all caps are drawn with depth compare NEVER, never z-fighting
        // the surface. Transparent casters are not in the depth buffer: their caps are real
        // geometry in front of or behind the visible surface, depth-tested like the sides.
        let opaque = caster.transmittance.is_none();
        let dark_cap_kind = if case == Case::ZPass || directional {
            DarkCap::None
        } else if input.method == Method::McGuire && !inside {
            DarkCap::Fan
        } else {
            DarkCap::AllFaces
        };
        let MultiplicityVolume { draws, sides, dark_cap, light_cap, edges, max_multiplicity: mmax } = emit_multiplicity_with(
            caster,
            part.chunks.clone(),
            &part.edges,
            &facing,
            |_| opaque,
            &mult,
            VolumeShape { case, directional, dark_cap: dark_cap_kind },
        );
        let pp = PartPlan {
            part: pi,
            case,
            path: VolumePath::Multiplicity,
            silhouette_edges: edges,
            multiplicity_max: mmax,
            sides,
            dark_cap,
            light_cap,
            dark_cap_kind,
            formulation: Formulation::TwoSided,
        };
        return (pp, draws);
    }
    hits.clear();
    part.scan.scan_hits_into(bits, hits);
    let e = manifold_emit(input.method, part, case, l_obj);
    let (formulation, dark_cap_kind) = (e.formulation, e.dark_cap);
    ends.clear();
    ends.extend(hits.iter().map(|&h| hit_ends(caster, &part.scan, h, formulation)));
    let (draws, sides, dark_cap, light_cap) = emit_with(caster, part.chunks.clone(), &facing, ends, e, case);
    let pp = PartPlan {
        part: pi,
        case,
        path: VolumePath::Manifold,
        silhouette_edges: hits.len(),
        multiplicity_max: u32::from(!hits.is_empty()),
        sides,
        dark_cap,
        light_cap,
        dark_cap_kind,
        formulation,
    };
    (pp, draws)
}

/// True when emitting `e` walks every triangle's facing bit (caps), not only the silhouette.
fn needs_triangles(e: Emit) -> bool {
    e.light_cap || matches!(e.dark_cap, DarkCap::FrontFaces | DarkCap::BackFaces)
}

/// Plans every caster's shadow volume for one light.
pub fn plan_light(input: &PlanInput, casters: &[Caster]) -> LightPlan {
    plan_light_opts(input, casters, false)
}

/// [`plan_light`]; with `edge_quads`, closed opaque casters that are not culled are left to the
/// GPU-only edge-quad method (no silhouette work here): their plan has path `"edgequad"`, case
/// z-fail with caps, no index lists, and the static counts the GPU draws (two triangles per
/// edge as sides; every face as a cap, light or dark as the GPU decides).
pub fn plan_light_opts(input: &PlanInput, casters: &[Caster], edge_quads: bool) -> LightPlan {
    plan_light_with(input, casters, &PlanOptions { edge_quads, ..PlanOptions::default() })
}

/// [`plan_light`] with [`PlanOptions`]. Every part of a caster ([`Caster::parts`]) is culled
/// and planned on its own: closed manifold parts on the silhouette path, the others on the
/// multiplicity path.
pub fn plan_light_with(input: &PlanInput, casters: &[Caster], opts: &PlanOptions) -> LightPlan {
    let t0 = Instant::now();
    let ctx = LightContext::new(input);
    let mut scratch = PlanScratch::default();
    let mut plans = Vec::with_capacity(casters.len());
    for (ci, caster) in casters.iter().enumerate() {
        let wb = caster.world_bounds();
        let l_obj = avoid_vertex(caster, object_light(caster, ctx.light_h));
        if ctx.culls(input, opts, &wb) {
            plans.push(culled_caster_plan(ci, caster, l_obj));
            continue;
        }
        if opts.edge_quads && caster.kind == CasterKind::Manifold && caster.transmittance.is_none() {
            plans.push(CasterPlan {
                case: Case::ZFailLightCap,
                path: VolumePath::EdgeQuad,
                sides: 2 * caster.topology.manifold_edges.len(),
                light_cap: caster.triangle_count,
                ..culled_caster_plan(ci, caster, l_obj)
            });
            continue;
        }
        let cases = part_cases(caster, wb, opts.case_per_part, &|b| ctx.culls(input, opts, b), |b| {
            select_case(input.method, &ctx.pyramid, &ctx.frustum, b)
        });
        if cases.iter().all(|&c| c == Case::Culled) {
            plans.push(culled_caster_plan(ci, caster, l_obj));
            continue;
        }
        plans.push(plan_caster(input, opts, (ci, caster), l_obj, &cases, &mut scratch));
    }
    let (scissor, depth_bounds) = light_screen_bounds(input, ctx.directional);
    LightPlan { scissor, depth_bounds, casters: plans, silhouette_ms: scratch.silhouette_ms, plan_ms: t0.elapsed().as_secs_f64() * 1e3 }
}

/// A light's scissor and depth bounds (none for a directional light).
fn light_screen_bounds(input: &PlanInput, directional: bool) -> (Option<[u32; 4]>, Option<(f32, f32)>) {
    if directional {
        (None, None)
    } else {
        (light_scissor(input.light, input.view_proj, input.width, input.height), light_depth_bounds(input.light, input.view_proj))
    }
}

/// What planning one light needs once, whatever the caster: the light in homogeneous
/// coordinates, the view frustum and the occlusion pyramid (the view-dependent half of a
/// plan: culling and the case).
pub struct LightContext {
    light_h: Vec4,
    directional: bool,
    frustum: Frustum,
    pyramid: OcclusionPyramid,
}

impl LightContext {
    /// The context of `input`'s light and view.
    pub fn new(input: &PlanInput) -> LightContext {
        let light_h = input.light.homogeneous();
        LightContext {
            light_h,
            directional: input.light.kind == LightKind::Directional,
            frustum: Frustum::from_view_proj(input.view_proj, false),
            pyramid: OcclusionPyramid::new(light_h, input.view_proj),
        }
    }

    /// The light in homogeneous world coordinates (w = 0 for a directional light).
    pub fn light_h(&self) -> Vec4 {
        self.light_h
    }

    /// Whether a caster (or part) of world box `b` casts nothing into the view: beyond the
    /// light's range or cone, or its volume outside the frustum (never with `no_culling`).
    fn culls(&self, input: &PlanInput, opts: &PlanOptions, b: &Aabb) -> bool {
        let light = input.light;
        let out_of_radius = !self.directional && light.radius.is_some_and(|r| box_distance(b, light.position) > r);
        !opts.no_culling && (out_of_radius || spot_culls(light, b) || shadow_volume_outside_frustum(b, self.light_h, &self.frustum))
    }

    /// The screen half of the light's plan: its scissor and depth bounds, as
    /// [`plan_light_with`] reports them.
    pub fn screen_bounds(&self, input: &PlanInput) -> (Option<[u32; 4]>, Option<(f32, f32)>) {
        light_screen_bounds(input, self.directional)
    }

    /// The view-dependent half of planning `caster` (not on the edge-quad path): `None` when
    /// it is culled whole, else each part's case (culled parts `Case::Culled`), exactly as
    /// [`plan_light_with`] decides them. The rest of its plan ([`plan_caster`]) depends only on
    /// the light, the caster and these cases.
    /// `wb` is the caster's [`world_bounds`](Caster::world_bounds).
    pub fn caster_cases(&self, input: &PlanInput, opts: &PlanOptions, caster: &Caster, wb: Aabb) -> Option<Vec<Case>> {
        let mut cases = Vec::new();
        self.caster_cases_into(input, opts, caster, wb, &mut cases).then_some(cases)
    }

    /// [`caster_cases`](Self::caster_cases) into `cases` (cleared first, left empty when the
    /// caster is culled whole); whether it is drawn.
    pub fn caster_cases_into(&self, input: &PlanInput, opts: &PlanOptions, caster: &Caster, wb: Aabb, cases: &mut Vec<Case>) -> bool {
        cases.clear();
        if self.culls(input, opts, &wb) {
            return false;
        }
        part_cases_into(
            caster,
            wb,
            opts.case_per_part,
            &|b| self.culls(input, opts, b),
            |b| select_case(input.method, &self.pyramid, &self.frustum, b),
            cases,
        );
        cases.iter().any(|&c| c != Case::Culled)
    }
}

/// The plan of a caster culled whole for a light (`l_obj`: the light in its object space).
pub fn culled_caster_plan(ci: usize, caster: &Caster, l_obj: Vec4) -> CasterPlan {
    CasterPlan {
        caster: ci,
        case: Case::Culled,
        path: caster.kind.path(),
        silhouette_edges: 0,
        multiplicity_max: 0,
        sides: 0,
        dark_cap: 0,
        light_cap: 0,
        chunks: Vec::new(),
        dark_cap_kind: DarkCap::None,
        formulation: Formulation::Front,
        light_object: l_obj.to_array(),
        parts: Vec::new(),
    }
}

/// The buffers [`plan_caster`] reuses from one caster to the next, and the time it spent on
/// facing bits.
#[derive(Default)]
pub struct PlanScratch {
    bits: Vec<u64>,
    tri_bits: Vec<u64>,
    hits: Vec<ScanHit>,
    ends: Vec<SideEnds>,
    /// Milliseconds spent computing facing bits so far.
    pub silhouette_ms: f64,
}

/// Plans caster `ci` (not culled whole: `cases` from [`LightContext::caster_cases`]) for the
/// light whose object-space position is `l_obj` ([`avoid_vertex`] of [`object_light`]): its
/// facing, possible silhouettes, caps and index lists. What it returns depends on the light,
/// the caster, the method and `cases` only, never on the view otherwise.
pub fn plan_caster(
    input: &PlanInput,
    opts: &PlanOptions,
    (ci, caster): (usize, &Caster),
    l_obj: Vec4,
    cases: &[Case],
    scratch: &mut PlanScratch,
) -> CasterPlan {
    let PlanScratch { bits, tri_bits, hits, ends, silhouette_ms } = scratch;
    // A caster marked multiplicity as a whole (one part) keeps that path.
    let whole_multiplicity = caster.kind != CasterKind::Manifold && caster.parts.len() == 1;
    let mut cp = culled_caster_plan(ci, caster, l_obj);
    // GPU silhouettes: closed manifold parts of opaque casters are left to the compute
    // pass; the CPU computes facing bits only when a part on the multiplicity path is drawn.
    let gpu = opts.gpu_silhouettes && caster.transmittance.is_none() && !whole_multiplicity;
    let on_gpu = |pi: usize| gpu && caster.parts[pi].kind == CasterKind::Manifold;
    if !cases.iter().enumerate().all(|(pi, &c)| c == Case::Culled || on_gpu(pi)) {
        let ts = Instant::now();
        caster.planes.facing_packed_auto(caster.mesh(), l_obj, caster.mirrored, bits);
        *silhouette_ms += ts.elapsed().as_secs_f64() * 1e3;
    }
    if gpu && caster.kind == CasterKind::Manifold {
        cp.path = VolumePath::Compute;
    }
    let mut best = 0u8;
    let mut tri_bits_done = false;
    for (pi, &case) in cases.iter().enumerate() {
        let part = &caster.parts[pi];
        let multiplicity = whole_multiplicity || part.kind != CasterKind::Manifold;
        if case != Case::Culled && on_gpu(pi) {
            let e = manifold_emit(input.method, part, case, l_obj);
            cp.parts.push(PartPlan::undrawn(pi, case, VolumePath::Compute, e.dark_cap, e.formulation));
            if case_rank(case) > best {
                best = case_rank(case);
                cp.case = case;
                cp.dark_cap_kind = e.dark_cap;
                cp.formulation = e.formulation;
            }
            continue;
        }
        if case == Case::Culled {
            let path = if multiplicity { VolumePath::Multiplicity } else { VolumePath::Manifold };
            cp.parts.push(PartPlan::undrawn(pi, case, path, DarkCap::None, Formulation::Front));
            continue;
        }
        let permuted = !caster.planes.order().is_identity();
        if permuted && !tri_bits_done && (multiplicity || needs_triangles(manifold_emit(input.method, part, case, l_obj))) {
            // walking triangles: the bits in welded order once, not a permutation lookup each
            caster.planes.unpermute(bits, tri_bits);
            tri_bits_done = true;
        }
        // (a part that walks no triangle reads no bit of `tb`)
        let tb: &[u64] = if !permuted {
            bits
        } else if tri_bits_done {
            tri_bits
        } else {
            &[]
        };
        let (pp, draws) = plan_part(input, caster, PartJob { part: pi, multiplicity, case }, l_obj, (bits, tb), (hits, ends));
        cp.silhouette_edges += pp.silhouette_edges;
        cp.multiplicity_max = cp.multiplicity_max.max(pp.multiplicity_max);
        cp.sides += pp.sides;
        cp.dark_cap += pp.dark_cap;
        cp.light_cap += pp.light_cap;
        if case_rank(case) > best {
            best = case_rank(case);
            cp.case = case;
            cp.dark_cap_kind = pp.dark_cap_kind;
            cp.formulation = pp.formulation;
        }
        cp.chunks.extend(draws);
        cp.parts.push(pp);
    }
    cp
}

/// Each part's case: culled by its own bounds (a caster of several parts), or the case its
/// bounds select; unless `case_per_part`, the parts drawn all take one case (the common one,
/// or z-fail with light cap when they differ).
fn part_cases(
    caster: &Caster,
    world_bounds: Aabb,
    case_per_part: bool,
    culls: &dyn Fn(&Aabb) -> bool,
    select: impl Fn(&Aabb) -> Case,
) -> Vec<Case> {
    let mut cases = Vec::with_capacity(caster.parts.len());
    part_cases_into(caster, world_bounds, case_per_part, culls, select, &mut cases);
    cases
}

/// [`part_cases`] into `cases` (cleared first).
fn part_cases_into(
    caster: &Caster,
    world_bounds: Aabb,
    case_per_part: bool,
    culls: &dyn Fn(&Aabb) -> bool,
    select: impl Fn(&Aabb) -> Case,
    cases: &mut Vec<Case>,
) {
    let single = caster.parts.len() == 1;
    cases.clear();
    cases.extend(caster.parts.iter().map(|p| {
        let pb = if single { world_bounds } else { p.object_bounds.transformed(&caster.transform) };
        if !single && culls(&pb) {
            Case::Culled
        } else {
            select(&pb)
        }
    }));
    if !case_per_part {
        let mut live = cases.iter().copied().filter(|&c| c != Case::Culled);
        if let Some(first) = live.next() {
            let uniform = if live.all(|c| c == first) { first } else { Case::ZFailLightCap };
            for c in cases.iter_mut().filter(|c| **c != Case::Culled) {
                *c = uniform;
            }
        }
    }
}

impl PartPlan {
    /// A part with nothing drawn on the CPU path (culled, or left to the compute pass).
    fn undrawn(part: usize, case: Case, path: VolumePath, dark_cap_kind: DarkCap, formulation: Formulation) -> PartPlan {
        PartPlan {
            part,
            case,
            path,
            silhouette_edges: 0,
            multiplicity_max: 0,
            sides: 0,
            dark_cap: 0,
            light_cap: 0,
            dark_cap_kind,
            formulation,
        }
    }
}

#[cfg(test)]
mod tests;
