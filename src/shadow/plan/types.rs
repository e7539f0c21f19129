//! The planner's vocabulary: methods, cases, dark caps, formulations, and what a plan holds.

use crate::error::Error;
use crate::geom::{Camera, Light};
use glam::Mat4;

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
    /// The lecture notes' eye-in-shadow fix (§3.1): z-pass with the stencil cleared to the
    /// number of volumes that contain the eye (counted exactly on the CPU) instead of 0. Right
    /// when the near-plane rectangle lies wholly inside or outside every volume; wrong where a
    /// volume crosses it (the notes' own caveat: a viewport only partly shadowed). Not in
    /// [`Method::ALL`] (the planners of the literature); planned as [`Method::ZPass`].
    #[cfg_attr(feature = "serde", serde(rename = "zpass-clear"))]
    ZPassClear,
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
            Method::ZPassClear => "zpass-clear",
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
        Method::ALL.into_iter().chain([Method::ZPassClear]).find(|m| m.name() == s).ok_or_else(|| Error::UnknownName {
            what: "method",
            name: s.to_string(),
            expected: format!("auto, {}, zpass-clear", Method::ALL.map(|m| m.name()).join(", ")),
        })
    }
}

/// How one caster's volume is drawn for one light.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Case {
    /// Nothing drawn (outside the light's radius or cone, or the volume is off screen).
    #[default]
    Culled,
    /// Case 1: z-pass, sides only.
    ZPass,
    /// Case 2: z-fail, sides + dark cap, no light cap.
    ZFail,
    /// Case 3 (and Carmack / Everitt-Kilgard / Lengyel z-fail): sides + dark cap + light cap.
    ZFailLightCap,
}

impl Case {
    /// The name in `--stats` (`culled`, `zpass`, `zfail`, `zfail_light_cap`).
    pub fn name(self) -> &'static str {
        match self {
            Case::Culled => "culled",
            Case::ZPass => "zpass",
            Case::ZFail => "zfail",
            Case::ZFailLightCap => "zfail_light_cap",
        }
    }
}

#[cfg(feature = "serde")]
impl serde::Serialize for Case {
    /// As its [`name`](Case::name).
    fn serialize<S: serde::Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        s.serialize_str(self.name())
    }
}

impl std::fmt::Display for Case {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

crate::named_enum::named_enum!(
    /// Which code path built a caster's (or a part's) volume for one light: `path` in
    /// `--stats` and `umbrage info`.
    VolumePath, "volume path", {
        /// McGuire et al.'s three cases on a closed, consistently oriented 2-manifold.
        #[default]
        Manifold => "manifold",
        /// Kim et al.'s edge multiplicities (open, non-manifold, two-sided or transparent).
        Multiplicity => "multiplicity",
        /// The Cg article's GPU-only edge quads.
        EdgeQuad => "edgequad",
        /// Flattened onto the planar receiver.
        Planar => "planar",
        /// GPU possible silhouettes (left to the compute pass).
        Compute => "compute",
        /// Mesh-shader extrusion (left to the mesh draws of `Technique::Mesh`).
        Mesh => "mesh",
        /// An analytic sphere's circumscribed polygon.
        Sphere => "sphere",
    }
);

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

impl DarkCap {
    /// The name in `--stats`' `dark_cap_kind` (the variant's: `Fan`, `BackFaces`, ...).
    pub fn name(self) -> &'static str {
        match self {
            DarkCap::Fan => "Fan",
            DarkCap::BackFaces => "BackFaces",
            DarkCap::FrontFaces => "FrontFaces",
            DarkCap::None => "None",
            DarkCap::AllFaces => "AllFaces",
        }
    }
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

/// What [`plan_light`](super::plan_light) needs besides the casters: the view, the viewport and one light.
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
    /// Index into the caster's [`Caster::chunks`](crate::shadow::Caster::chunks).
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
    /// Index of the caster in the slice given to [`plan_light`](super::plan_light).
    pub caster: usize,
    /// How the volume is drawn (culled, z-pass, z-fail with or without light cap).
    pub case: Case,
    /// Manifold or multiplicity ([`CasterKind::path`](crate::shadow::CasterKind::path)), edge
    /// quads, planar or compute.
    pub path: VolumePath,
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
    /// One plan per part of the caster ([`Caster::parts`](crate::shadow::Caster::parts), same order). The caster's counts
    /// are the sums of its parts', its draws the concatenation of theirs, its `case` the most
    /// expensive of theirs, and its `dark_cap_kind` and `formulation` those of the first part
    /// with that case.
    pub parts: Vec<PartPlan>,
}

/// The plan of one part (connected component) of a caster.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct PartPlan {
    /// Index into [`Caster::parts`](crate::shadow::Caster::parts).
    pub part: usize,
    /// The part's own case (McGuire's rule on the part's bounds).
    pub case: Case,
    /// Manifold, multiplicity or compute (left to the GPU silhouettes).
    pub path: VolumePath,
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

/// Options of [`plan_light_with`](super::plan_light_with).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PlanOptions {
    /// See [`plan_light_opts`](super::plan_light_opts).
    pub edge_quads: bool,
    /// Each part of a caster gets the case its own bounds call for, recorded per draw in
    /// [`ChunkDraw::case`]: only for renderers that pick the pipeline per draw. Otherwise
    /// (default) the parts of a caster that are not culled share one case (theirs when they
    /// agree, else z-fail with light cap, always valid), so that `CasterPlan::case` holds for
    /// every draw of the caster.
    pub case_per_part: bool,
    /// Closed manifold parts of opaque casters that are not culled get their case,
    /// formulation and dark-cap kind ([`manifold_emit`](super::manifold_emit)) but no facing
    /// bits, silhouette or index lists: path `"compute"`, zero counts (the GPU's compute pass
    /// finds them, `--method compute`). Other parts are planned as usual.
    pub gpu_silhouettes: bool,
    /// Ablation: never cull (out of the light's range or cone, or a volume missing the
    /// frustum); every caster gets a case and its volume. The result stays exact, only slower.
    pub no_culling: bool,
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
    /// `None` = the whole viewport (see [`light_scissor`](crate::geom::bounds::light_scissor)).
    pub scissor: Option<[u32; 4]>,
    /// `(min, max)` depth of the light's range for the depth-bounds test; `None` = unbounded
    /// (see [`light_depth_bounds`](crate::geom::bounds::light_depth_bounds)).
    pub depth_bounds: Option<(f32, f32)>,
    /// One plan per caster, in the order of the casters given (culled ones included).
    pub casters: Vec<CasterPlan>,
    /// Wall time spent on facing bits and silhouette extraction, milliseconds.
    pub silhouette_ms: f64,
    /// Wall time of the whole plan (silhouettes included), milliseconds.
    pub plan_ms: f64,
}
