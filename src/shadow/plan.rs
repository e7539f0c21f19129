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

use super::caster::{Caster, CasterKind};
use crate::error::Error;
use crate::geom::bounds::{box_distance, light_depth_bounds, light_scissor, shadow_volume_outside_frustum, Frustum, OcclusionPyramid};
use crate::geom::silhouette::{packed_bit, SilhouetteEdge};
use crate::geom::Aabb;
use crate::geom::{Camera, Light, LightKind};
use glam::{Mat4, Vec4};
use std::time::Instant;

/// Which shadow-volume algorithm to plan for.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub enum Method {
    /// Heidmann's z-pass for every caster: sides only ([`Case::ZPass`]); wrong wherever a volume
    /// crosses the near plane.
    #[cfg_attr(feature = "serde", serde(rename = "zpass"))]
    ZPass,
    /// Carmack's z-fail for every caster: sides, light cap and the classic O(f) dark cap
    /// ([`Case::ZFailLightCap`], [`DarkCap::FrontFaces`]).
    #[cfg_attr(feature = "serde", serde(rename = "zfail"))]
    ZFail,
    /// Everitt & Kilgard's robust z-fail (infinite far plane): planned exactly as [`Method::ZFail`].
    #[cfg_attr(feature = "serde", serde(rename = "everitt-kilgard"))]
    EverittKilgard,
    /// Lengyel's choice: z-pass when the caster's box misses the occlusion pyramid, else z-fail
    /// with light cap and the O(f) dark cap.
    #[cfg_attr(feature = "serde", serde(rename = "lengyel"))]
    Lengyel,
    /// McGuire et al. 2003: per caster the cheapest correct of the three [`Case`]s (occlusion
    /// pyramid, then view frustum) and the O(s) fan dark cap.
    #[cfg_attr(feature = "serde", serde(rename = "mcguire"))]
    McGuire,
}

impl Method {
    /// Every method, in the order the CLI and the tables list them.
    pub const ALL: [Method; 5] = [Method::ZPass, Method::ZFail, Method::EverittKilgard, Method::Lengyel, Method::McGuire];
    /// The CLI / JSON name (`zpass`, `zfail`, `everitt-kilgard`, `lengyel`, `mcguire`); [`FromStr`](std::str::FromStr) parses it back.
    pub fn name(self) -> &'static str {
        match self {
            Method::ZPass => "zpass",
            Method::ZFail => "zfail",
            Method::EverittKilgard => "everitt-kilgard",
            Method::Lengyel => "lengyel",
            Method::McGuire => "mcguire",
        }
    }
}

impl std::fmt::Display for Method {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for Method {
    type Err = Error;
    fn from_str(s: &str) -> Result<Method, Error> {
        // `auto` is McGuire et al.'s three cases for closed manifold casters; every caster is
        // classified once at load, and one that is not a closed 2-manifold takes the
        // multiplicity path (Kim et al. 2008) whatever the method.
        if s == "auto" {
            return Ok(Method::McGuire);
        }
        Method::ALL.into_iter().find(|m| m.name() == s).ok_or_else(|| Error::UnknownName {
            what: "method",
            name: s.to_string(),
            expected: format!("auto, {}", Method::ALL.map(|m| m.name()).join(", ")),
        })
    }
}

/// How one caster's volume is drawn for one light.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub enum Case {
    /// Nothing drawn (outside the light's radius or cone, or the volume is off screen).
    #[cfg_attr(feature = "serde", serde(rename = "culled"))]
    #[default]
    Culled,
    /// Case 1: z-pass, sides only.
    #[cfg_attr(feature = "serde", serde(rename = "zpass"))]
    ZPass,
    /// Case 2: z-fail, sides + dark cap, no light cap.
    #[cfg_attr(feature = "serde", serde(rename = "zfail"))]
    ZFail,
    /// Case 3 (and Carmack / Everitt-Kilgard / Lengyel z-fail): sides + dark cap + light cap.
    #[cfg_attr(feature = "serde", serde(rename = "zfail_light_cap"))]
    ZFailLightCap,
}

/// Which dark cap was emitted.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum DarkCap {
    /// Fan from the apex at infinity over the silhouette: s triangles.
    Fan,
    /// w=0 copies of the non-light-facing triangles (back-face formulation: light in/on the
    /// caster's bounding box).
    BackFaces,
    /// w=0 copies of the light-facing triangles, reversed (classic O(f) z-fail cap).
    FrontFaces,
    /// No dark cap (z-pass, or a directional light: all of infinity is one point).
    None,
    /// Multiplicity casters: every triangle's w=0 copy, oriented away from the light.
    AllFaces,
}

/// Which closed volume the geometry describes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum Formulation {
    /// Occluders are the light-facing triangles.
    Front,
    /// Occluders are the non-light-facing triangles (point light inside/on the caster AABB).
    Back,
    /// Multiplicity casters: every triangle occludes, from both sides.
    TwoSided,
}

/// What [`plan_light`] needs besides the casters: the view, the viewport and one light.
pub struct PlanInput<'a> {
    /// The camera `view_proj` was built from (the planner itself reads only `view_proj`).
    pub camera: &'a Camera,
    /// Viewport width, pixels (for the light scissor).
    pub width: u32,
    /// Viewport height, pixels (for the light scissor).
    pub height: u32,
    /// World -> Vulkan clip space of the frame (e.g. `camera.proj_infinite(aspect) * camera.view()`):
    /// frustum, occlusion pyramid, scissor and depth bounds are all derived from it.
    pub view_proj: Mat4,
    /// The light to plan for.
    pub light: &'a Light,
    /// The algorithm whose cases and caps to emit.
    pub method: Method,
}

/// Index lists for one chunk of a caster (indices into its dual-length vertex buffer).
#[derive(Clone, Debug, Default, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct ChunkDraw {
    /// Index into the caster's [`Caster::chunks`].
    pub chunk: usize,
    /// The case these lists were emitted for (the case of the caster's part the chunk belongs
    /// to): the renderer's pipelines (z-pass or z-fail stencil operations) follow it.
    pub case: Case,
    /// Sides then dark cap (then, for multiplicity casters, the light caps that may lie in
    /// front of the visible surface); drawn with depth test LESS.
    pub volume: Vec<u16>,
    /// Light cap; drawn with depth compare NEVER (z-fail cases only).
    pub light_cap: Vec<u16>,
}

/// One caster's shadow volume for one light: the case chosen, what was emitted, and the index lists.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct CasterPlan {
    /// Index of the caster in the slice given to [`plan_light`].
    pub caster: usize,
    /// How the volume is drawn (culled, z-pass, z-fail with or without light cap).
    pub case: Case,
    /// `"manifold"` or `"multiplicity"` ([`CasterKind::path`]).
    pub path: &'static str,
    /// Silhouette edges (manifold) / edges of non-zero multiplicity.
    pub silhouette_edges: usize,
    /// Largest |multiplicity| of an emitted side (1 for a manifold silhouette, 0 when none).
    pub multiplicity_max: u32,
    /// Triangle counts actually emitted.
    pub sides: usize,
    /// Dark-cap triangles (at infinity) emitted.
    pub dark_cap: usize,
    /// Light-cap triangles emitted.
    pub light_cap: usize,
    /// Only chunks with at least one index.
    pub chunks: Vec<ChunkDraw>,
    /// Which dark cap was emitted.
    pub dark_cap_kind: DarkCap,
    /// Which triangles occlude (front, back or two-sided).
    pub formulation: Formulation,
    /// Object-space homogeneous light the facing bits were decided for (the GPU must use the
    /// same value in EXTRUDE).
    pub light_object: [f32; 4],
    /// One plan per part of the caster ([`Caster::parts`], same order). The caster's counts
    /// are the sums of its parts', its draws the concatenation of theirs, its `case` the most
    /// expensive of theirs, and its `dark_cap_kind` and `formulation` those of the first part
    /// with that case.
    pub parts: Vec<PartPlan>,
}

/// The plan of one part (connected component) of a caster.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct PartPlan {
    /// Index into [`Caster::parts`].
    pub part: usize,
    /// The part's own case (McGuire's rule on the part's bounds).
    pub case: Case,
    /// `"manifold"` or `"multiplicity"`.
    pub path: &'static str,
    /// Possible silhouette edges of the part.
    pub silhouette_edges: usize,
    /// Largest |edge multiplicity| drawn (multiplicity parts).
    pub multiplicity_max: u32,
    /// Side triangles.
    pub sides: usize,
    /// Dark-cap triangles.
    pub dark_cap: usize,
    /// Light-cap triangles.
    pub light_cap: usize,
    /// Which dark cap was emitted.
    pub dark_cap_kind: DarkCap,
    /// Which closed volume the geometry describes.
    pub formulation: Formulation,
}

/// Options of [`plan_light_with`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PlanOptions {
    /// See [`plan_light_opts`].
    pub edge_quads: bool,
    /// Each part of a caster gets the case its own bounds call for, recorded per draw in
    /// [`ChunkDraw::case`]: only for renderers that pick the pipeline per draw. Otherwise
    /// (default) the parts of a caster that are not culled share one case (theirs when they
    /// agree, else z-fail with light cap, always valid), so that `CasterPlan::case` holds for
    /// every draw of the caster.
    pub case_per_part: bool,
}

impl CasterPlan {
    /// Every triangle emitted: sides + dark cap + light cap.
    pub fn triangles(&self) -> usize {
        self.sides + self.dark_cap + self.light_cap
    }
}

#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
/// Every caster's plan for one light, with the light's scissor and depth bounds (Lengyel 2002).
pub struct LightPlan {
    /// `[x, y, width, height]` in pixels (row 0 at the top) bounding the light's range on screen;
    /// `None` = the whole viewport (see [`light_scissor`]).
    pub scissor: Option<[u32; 4]>,
    /// `(min, max)` depth of the light's range for the depth-bounds test; `None` = unbounded
    /// (see [`light_depth_bounds`]).
    pub depth_bounds: Option<(f32, f32)>,
    /// One plan per caster, in the order of the casters given (culled ones included).
    pub casters: Vec<CasterPlan>,
    /// Wall time spent on facing bits and silhouette extraction, milliseconds.
    pub silhouette_ms: f64,
    /// Wall time of the whole plan (silhouettes included), milliseconds.
    pub plan_ms: f64,
}

/// Per-chunk index lists into draws, leaving out chunks with nothing to draw.
fn chunk_draws(vol: Vec<Vec<u16>>, cap: Vec<Vec<u16>>, case: Case) -> Vec<ChunkDraw> {
    vol.into_iter()
        .zip(cap)
        .enumerate()
        .filter(|(_, (v, c))| !v.is_empty() || !c.is_empty())
        .map(|(chunk, (volume, light_cap))| ChunkDraw { chunk, case, volume, light_cap })
        .collect()
}

/// The object-space homogeneous light (w exactly 1 or 0).
pub fn object_light(caster: &Caster, light_h: Vec4) -> Vec4 {
    let inv = caster.transform.as_dmat4().inverse();
    let l = inv * light_h.as_dvec4();
    if light_h.w == 0.0 {
        l.truncate().as_vec3().extend(0.0)
    } else {
        (l.truncate() / l.w).as_vec3().extend(1.0)
    }
}

/// A point light exactly on (or within rounding of) a caster vertex would send that vertex's
/// w=0 copy to `(0, 0, 0, 0)`, which is no point at all, and the volume would rasterise as
/// garbage. Such a light is moved away from the caster's centre by a distance far below a pixel
/// (1e-5 of the caster's size): the shadow is then exact to that distance, and every extrusion
/// direction is defined. Other lights are returned unchanged.
pub fn avoid_vertex(caster: &Caster, l_obj: Vec4) -> Vec4 {
    if l_obj.w == 0.0 {
        return l_obj;
    }
    let b = caster.object_bounds;
    let size = b.extent().length().max(f32::MIN_POSITIVE);
    let eps = size * 1e-5;
    let l = l_obj.truncate();
    let near_box = l.cmpge(b.min - eps).all() && l.cmple(b.max + eps).all();
    if !near_box || !caster.mesh().positions.iter().any(|p| p.distance(l) <= eps) {
        return l_obj;
    }
    let away = (l - b.center()).try_normalize().unwrap_or(glam::Vec3::Y);
    (l + away * (4.0 * eps)).extend(1.0)
}

fn spot_culls(light: &Light, b: &Aabb) -> bool {
    if light.kind != LightKind::Spot {
        return false;
    }
    let half = (light.cone_deg as f64 * 0.5).to_radians();
    if !(half < std::f64::consts::FRAC_PI_2) {
        return false;
    }
    let c = b.center().as_dvec3();
    let r = (b.extent().as_dvec3() * 0.5).length();
    let v = c - light.position.as_dvec3();
    let dist = v.length();
    let d = light.direction.as_dvec3();
    if dist <= r || d.length() == 0.0 {
        return false;
    }
    let ang = (v.dot(d) / (dist * d.length())).clamp(-1.0, 1.0).acos();
    ang > half + (r / dist).asin() + 1e-6
}

/// What to emit for one caster.
#[derive(Clone, Copy, Debug)]
pub struct Emit {
    /// Which triangles occlude (front or back; two-sided goes through [`emit_multiplicity`]).
    pub formulation: Formulation,
    /// The light is directional: one side triangle per silhouette edge (all of infinity is one point).
    pub directional: bool,
    /// The dark cap to emit.
    pub dark_cap: DarkCap,
    /// Emit the light cap (case 3 and the classic z-fail methods).
    pub light_cap: bool,
}

/// Per-triangle facing bits, as one `bool` per triangle or packed 64 to a word
/// ([`crate::geom::silhouette::FacePlanes::facing_packed`]).
trait FacingSet {
    fn get(&self, t: u32) -> bool;
}

impl FacingSet for [bool] {
    #[inline]
    fn get(&self, t: u32) -> bool {
        self.get(t as usize).copied().unwrap_or(false)
    }
}

/// Packed facing bits (see [`FacingSet`]).
struct Packed<'a>(&'a [u64]);

impl FacingSet for Packed<'_> {
    #[inline]
    fn get(&self, t: u32) -> bool {
        packed_bit(self.0, t)
    }
}

/// Emits the index lists; returns (chunk draws, sides, dark cap, light cap) triangle counts.
/// Over every chunk of the caster; the draws' `case` is z-fail with light cap when `e.light_cap`,
/// z-fail when there is a dark cap, else z-pass.
pub fn emit(caster: &Caster, facing: &[bool], sil: &[SilhouetteEdge], e: Emit) -> (Vec<ChunkDraw>, usize, usize, usize) {
    let case = if e.light_cap {
        Case::ZFailLightCap
    } else if e.dark_cap != DarkCap::None {
        Case::ZFail
    } else {
        Case::ZPass
    };
    emit_with(caster, 0..caster.chunks.len(), facing, sil, e, case)
}

/// [`emit`] for the part whose chunks are `range` (`sil` from that part's edges).
fn emit_with<F: FacingSet + ?Sized>(
    caster: &Caster,
    range: std::ops::Range<usize>,
    facing: &F,
    sil: &[SilhouetteEdge],
    e: Emit,
    case: Case,
) -> (Vec<ChunkDraw>, usize, usize, usize) {
    let part_chunks = || caster.chunks.iter().enumerate().skip(range.start).take(range.len());
    let nch = caster.chunks.len();
    let mut vol: Vec<Vec<u16>> = vec![Vec::new(); nch];
    let mut cap: Vec<Vec<u16>> = vec![Vec::new(); nch];
    let (mut sides, mut dark, mut light) = (0, 0, 0);
    for s in sil {
        // a->b as in the lit triangle; the back formulation uses the unlit triangle's chunk
        let (tri, corner, rev) = match e.formulation {
            Formulation::Front => (s.lit, s.lit_corner, false),
            Formulation::Back => (s.unlit, s.unlit_corner, true),
            Formulation::TwoSided => unreachable!("multiplicity casters use emit_multiplicity"),
        };
        let (ci, li) = caster.tri_chunk[tri as usize];
        let ch = &caster.chunks[ci as usize];
        let n = ch.n() as u16;
        let lt = ch.local_tris[li as usize];
        let k = corner as usize;
        let (mut a, mut b) = (lt[k], lt[(k + 1) % 3]);
        if rev {
            std::mem::swap(&mut a, &mut b);
        }
        let v = &mut vol[ci as usize];
        if e.directional {
            v.extend_from_slice(&[b, a, a + n]);
            sides += 1;
        } else {
            v.extend_from_slice(&[b, a, a + n, b, a + n, b + n]);
            sides += 2;
        }
    }
    if !e.directional {
        match e.dark_cap {
            DarkCap::Fan => {
                assert_eq!(e.formulation, Formulation::Front, "the fan dark cap needs the front formulation");
                for s in sil {
                    let (ci, li) = caster.tri_chunk[s.lit as usize];
                    let ch = &caster.chunks[ci as usize];
                    let n = ch.n() as u16;
                    let lt = ch.local_tris[li as usize];
                    let k = s.lit_corner as usize;
                    let (a, b) = (lt[k], lt[(k + 1) % 3]);
                    vol[ci as usize].extend_from_slice(&[ch.apex() + n, b + n, a + n]);
                    dark += 1;
                }
            }
            DarkCap::FrontFaces | DarkCap::BackFaces => {
                let want = e.dark_cap == DarkCap::FrontFaces;
                for (ci, ch) in part_chunks() {
                    let n = ch.n() as u16;
                    vol[ci].reserve(ch.local_tris.len() * 3);
                    for (lt, &g) in ch.local_tris.iter().zip(&ch.tri_ids) {
                        if facing.get(g) == want {
                            let t = if want { [lt[0] + n, lt[2] + n, lt[1] + n] } else { [lt[0] + n, lt[1] + n, lt[2] + n] };
                            vol[ci].extend_from_slice(&t);
                            dark += 1;
                        }
                    }
                }
            }
            DarkCap::None => {}
            DarkCap::AllFaces => unreachable!("multiplicity casters use emit_multiplicity"),
        }
    }
    if e.light_cap {
        let want = e.formulation == Formulation::Front;
        for (ci, ch) in part_chunks() {
            cap[ci].reserve(ch.local_tris.len() * 3);
            for (lt, &g) in ch.local_tris.iter().zip(&ch.tri_ids) {
                if facing.get(g) == want {
                    let t = if want { *lt } else { [lt[0], lt[2], lt[1]] };
                    cap[ci].extend_from_slice(&t);
                    light += 1;
                }
            }
        }
    }
    let draws = chunk_draws(vol, cap, case);
    (draws, sides, dark, light)
}

/// The case a method picks for a caster whose world box is `wb` (same for both paths).
fn select_case(method: Method, pyramid: &OcclusionPyramid, frustum: &Frustum, wb: &Aabb) -> Case {
    match method {
        Method::ZPass => Case::ZPass,
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

/// Per-light facing data of a multiplicity caster.
pub struct MultiplicityInput<'a> {
    /// Light-facing bit of every triangle.
    pub facing: &'a [bool],
    /// Whether each triangle's light cap is known to be at or behind the visible surface
    /// (the triangle, or an exact twin of it, is front-facing to the eye, so the G-buffer
    /// pass drew it): such caps go to the depth-NEVER list.
    pub shielded: &'a [bool],
}

/// Signed multiplicity of every undirected edge of the topology (`v[0] -> v[1]` positive).
pub fn edge_multiplicities(caster: &Caster, facing: &[bool]) -> Vec<i32> {
    let ids: Vec<u32> = (0..caster.topology.edges.len() as u32).collect();
    edge_multiplicities_with(caster, &ids, facing)
}

fn edge_multiplicities_with<F: FacingSet + ?Sized>(caster: &Caster, edge_ids: &[u32], facing: &F) -> Vec<i32> {
    let t = &caster.topology;
    edge_ids
        .iter()
        .filter_map(|&e| t.edges.get(e as usize))
        .map(|e| {
            let uses = t.uses.get(e.first_use as usize..(e.first_use + e.use_count) as usize).unwrap_or(&[]);
            uses.iter().map(|u| if u.forward == facing.get(u.tri) { 1 } else { -1 }).sum()
        })
        .collect()
}

/// Emits a multiplicity caster's index lists; returns (draws, sides, dark cap, light cap,
/// edges with m != 0, largest |m|).
pub fn emit_multiplicity(
    caster: &Caster,
    mi: &MultiplicityInput,
    mult: &[i32],
    case: Case,
    directional: bool,
    dark_cap: DarkCap,
) -> (Vec<ChunkDraw>, usize, usize, usize, usize, u32) {
    let edge_ids: Vec<u32> = (0..mult.len() as u32).collect();
    let shielded = |g: u32| mi.shielded.get(g as usize).copied().unwrap_or(true);
    emit_multiplicity_with(caster, 0..caster.chunks.len(), &edge_ids, mi.facing, shielded, mult, case, directional, dark_cap)
}

/// [`emit_multiplicity`] for the part whose chunks are `range` and whose edges are `edge_ids`
/// (`mult[i]` the multiplicity of edge `edge_ids[i]`).
#[allow(clippy::too_many_arguments)]
fn emit_multiplicity_with<F: FacingSet + ?Sized, S: Fn(u32) -> bool>(
    caster: &Caster,
    range: std::ops::Range<usize>,
    edge_ids: &[u32],
    facing: &F,
    shielded: S,
    mult: &[i32],
    case: Case,
    directional: bool,
    dark_cap: DarkCap,
) -> (Vec<ChunkDraw>, usize, usize, usize, usize, u32) {
    let nch = caster.chunks.len();
    let mut vol: Vec<Vec<u16>> = vec![Vec::new(); nch];
    let mut cap: Vec<Vec<u16>> = vec![Vec::new(); nch];
    let (mut sides, mut dark, mut light, mut edges, mut mmax) = (0, 0, 0, 0, 0u32);
    let topo = &caster.topology;
    let part_chunks = || caster.chunks.iter().enumerate().skip(range.start).take(range.len());
    // the oriented edge a->b (chunk-local, in the chunk of its first use) and |m|
    let oriented = |e: usize, m: i32| {
        let u = topo.edge_uses(e)[0];
        let (ci, li) = caster.tri_chunk[u.tri as usize];
        let ch = &caster.chunks[ci as usize];
        let lt = ch.local_tris[li as usize];
        let k = u.corner as usize;
        // the use walks lt[k] -> lt[k+1]; it is v0 -> v1 iff forward
        let (mut a, mut b) = (lt[k], lt[(k + 1) % 3]);
        if u.forward != (m > 0) {
            std::mem::swap(&mut a, &mut b);
        }
        (ci as usize, ch.n() as u16, a, b)
    };
    for (&e, &m) in edge_ids.iter().zip(mult) {
        let e = e as usize;
        if m == 0 {
            continue;
        }
        edges += 1;
        mmax = mmax.max(m.unsigned_abs());
        let (ci, n, a, b) = oriented(e, m);
        for _ in 0..m.unsigned_abs() {
            if directional {
                vol[ci].extend_from_slice(&[b, a, a + n]);
                sides += 1;
            } else {
                vol[ci].extend_from_slice(&[b, a, a + n, b, a + n, b + n]);
                sides += 2;
            }
        }
    }
    if !directional {
        match dark_cap {
            DarkCap::Fan => {
                for (&e, &m) in edge_ids.iter().zip(mult) {
                    if m == 0 {
                        continue;
                    }
                    let (ci, n, a, b) = oriented(e as usize, m);
                    let apex = caster.chunks[ci].apex();
                    for _ in 0..m.unsigned_abs() {
                        vol[ci].extend_from_slice(&[apex + n, b + n, a + n]);
                        dark += 1;
                    }
                }
            }
            DarkCap::AllFaces => {
                for (ci, ch) in part_chunks() {
                    let n = ch.n() as u16;
                    for (lt, &g) in ch.local_tris.iter().zip(&ch.tri_ids) {
                        let t = if facing.get(g) { [lt[0] + n, lt[2] + n, lt[1] + n] } else { [lt[0] + n, lt[1] + n, lt[2] + n] };
                        vol[ci].extend_from_slice(&t);
                        dark += 1;
                    }
                }
            }
            DarkCap::None => {}
            DarkCap::FrontFaces | DarkCap::BackFaces => unreachable!("manifold dark caps on a multiplicity caster"),
        }
    }
    if case != Case::ZFail {
        for (ci, ch) in part_chunks() {
            for (lt, &g) in ch.local_tris.iter().zip(&ch.tri_ids) {
                let t = if facing.get(g) { *lt } else { [lt[0], lt[2], lt[1]] };
                if !shielded(g) {
                    vol[ci].extend_from_slice(&t);
                    light += 1;
                } else if case == Case::ZFailLightCap {
                    cap[ci].extend_from_slice(&t);
                    light += 1;
                }
            }
        }
    }
    let draws = chunk_draws(vol, cap, case);
    (draws, sides, dark, light, edges, mmax)
}

/// How expensive a case is to draw (the caster's case is its most expensive part's).
fn case_rank(c: Case) -> u8 {
    match c {
        Case::Culled => 0,
        Case::ZPass => 1,
        Case::ZFail => 2,
        Case::ZFailLightCap => 3,
    }
}

/// Plans one part of a caster for which the facing `bits` are decided; returns the part plan
/// and its draws.
#[allow(clippy::too_many_arguments)]
fn plan_part(
    input: &PlanInput,
    caster: &Caster,
    pi: usize,
    multiplicity: bool,
    case: Case,
    l_obj: Vec4,
    bits: &[u64],
    sil: &mut Vec<SilhouetteEdge>,
) -> (PartPlan, Vec<ChunkDraw>) {
    let part = &caster.parts[pi];
    let directional = l_obj.w == 0.0;
    let facing = Packed(bits);
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
        let (draws, sides, dark_cap, light_cap, edges, mmax) =
            emit_multiplicity_with(caster, part.chunks.clone(), &part.edges, &facing, |_| opaque, &mult, case, directional, dark_cap_kind);
        let pp = PartPlan {
            part: pi,
            case,
            path: "multiplicity",
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
    sil.clear();
    part.scan.scan_into(bits, sil);
    let formulation = if inside { Formulation::Back } else { Formulation::Front };
    let dark_cap_kind = if case == Case::ZPass || directional {
        DarkCap::None
    } else if formulation == Formulation::Back {
        DarkCap::BackFaces
    } else if input.method == Method::McGuire {
        DarkCap::Fan
    } else {
        DarkCap::FrontFaces
    };
    let e = Emit { formulation, directional, dark_cap: dark_cap_kind, light_cap: case == Case::ZFailLightCap };
    let (draws, sides, dark_cap, light_cap) = emit_with(caster, part.chunks.clone(), &facing, sil, e, case);
    let pp = PartPlan {
        part: pi,
        case,
        path: "manifold",
        silhouette_edges: sil.len(),
        multiplicity_max: u32::from(!sil.is_empty()),
        sides,
        dark_cap,
        light_cap,
        dark_cap_kind,
        formulation,
    };
    (pp, draws)
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
    plan_light_with(input, casters, &PlanOptions { edge_quads, case_per_part: false })
}

/// [`plan_light`] with [`PlanOptions`]. Every part of a caster ([`Caster::parts`]) is culled
/// and planned on its own: closed manifold parts on the silhouette path, the others on the
/// multiplicity path.
pub fn plan_light_with(input: &PlanInput, casters: &[Caster], opts: &PlanOptions) -> LightPlan {
    let t0 = Instant::now();
    let light = input.light;
    let light_h = light.homogeneous();
    let directional = light.kind == LightKind::Directional;
    let frustum = Frustum::from_view_proj(input.view_proj, false);
    let pyramid = OcclusionPyramid::new(light_h, input.view_proj);
    let mut sil_time = 0.0f64;
    let mut plans = Vec::with_capacity(casters.len());
    let mut bits = Vec::new();
    let mut sil = Vec::new();
    for (ci, caster) in casters.iter().enumerate() {
        let wb = caster.world_bounds();
        let l_obj = avoid_vertex(caster, object_light(caster, light_h));
        let culled_plan = |case| CasterPlan {
            caster: ci,
            case,
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
        };
        let culls = |b: &Aabb| {
            let out_of_radius = !directional && light.radius.is_some_and(|r| box_distance(b, light.position) > r);
            out_of_radius || spot_culls(light, b) || shadow_volume_outside_frustum(b, light_h, &frustum)
        };
        if culls(&wb) {
            plans.push(culled_plan(Case::Culled));
            continue;
        }
        if opts.edge_quads && caster.kind == CasterKind::Manifold && caster.transmittance.is_none() {
            plans.push(CasterPlan {
                case: Case::ZFailLightCap,
                path: "edgequad",
                sides: 2 * caster.topology.manifold_edges.len(),
                light_cap: caster.triangle_count,
                ..culled_plan(Case::ZFailLightCap)
            });
            continue;
        }
        // A caster marked multiplicity as a whole (one part) keeps that path.
        let whole_multiplicity = caster.kind != CasterKind::Manifold && caster.parts.len() == 1;
        let single = caster.parts.len() == 1;
        let mut cases: Vec<Case> = caster
            .parts
            .iter()
            .map(|p| {
                let pb = if single { wb } else { p.object_bounds.transformed(&caster.transform) };
                if !single && culls(&pb) {
                    Case::Culled
                } else {
                    select_case(input.method, &pyramid, &frustum, &pb)
                }
            })
            .collect();
        if !opts.case_per_part {
            let mut live = cases.iter().copied().filter(|&c| c != Case::Culled);
            if let Some(first) = live.next() {
                let uniform = if live.all(|c| c == first) { first } else { Case::ZFailLightCap };
                for c in cases.iter_mut().filter(|c| **c != Case::Culled) {
                    *c = uniform;
                }
            }
        }
        let mut cp = culled_plan(Case::Culled);
        if cases.iter().all(|&c| c == Case::Culled) {
            plans.push(cp);
            continue;
        }
        let ts = Instant::now();
        caster.planes.facing_packed_auto(caster.mesh(), l_obj, caster.mirrored, &mut bits);
        sil_time += ts.elapsed().as_secs_f64() * 1e3;
        let mut best = 0u8;
        for (pi, &case) in cases.iter().enumerate() {
            let part = &caster.parts[pi];
            let multiplicity = whole_multiplicity || part.kind != CasterKind::Manifold;
            if case == Case::Culled {
                cp.parts.push(PartPlan {
                    part: pi,
                    case,
                    path: if multiplicity { "multiplicity" } else { "manifold" },
                    silhouette_edges: 0,
                    multiplicity_max: 0,
                    sides: 0,
                    dark_cap: 0,
                    light_cap: 0,
                    dark_cap_kind: DarkCap::None,
                    formulation: Formulation::Front,
                });
                continue;
            }
            let (pp, draws) = plan_part(input, caster, pi, multiplicity, case, l_obj, &bits, &mut sil);
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
        plans.push(cp);
    }
    let (scissor, depth_bounds) = if directional {
        (None, None)
    } else {
        (light_scissor(light, input.view_proj, input.width, input.height), light_depth_bounds(light, input.view_proj))
    };
    LightPlan { scissor, depth_bounds, casters: plans, silhouette_ms: sil_time, plan_ms: t0.elapsed().as_secs_f64() * 1e3 }
}

#[cfg(test)]
mod tests;
