//! [`Technique`]: how a frame's shadows are computed, and the shadow-map baseline's options (part of `pass/`'s ground floor, with
//! [`desc`](super::desc): it imports nothing above it).

use crate::error::{Error, Result};
use crate::named_enum::named_enum;
use crate::shadow::Method;

named_enum!(
    /// How the shadow-map baseline reads its 3x3 percentage-closer-filtering taps: the
    /// same nine comparisons either way, bit for bit; what differs is the fetch count.
    Pcf, "pcf", {
        /// Nine single taps of the compare sampler.
        #[default]
        Taps => "taps",
        /// Four gathers of the compare sampler (each four comparisons), nine of whose sixteen
        /// results are the taps (single taps within a texel of a map's edge).
        Gather => "gather",
    }
);

named_enum!(
    /// How the shadow-map baseline renders a point light's six cube faces: the same six
    /// maps, the same per-face culling and the same picture either way; what differs is how
    /// the work reaches the device.
    CubeFaces, "cube", {
        /// Six tiles of one 3 x 2 atlas in one rendering instance, each caster drawn once per
        /// face its bounding sphere meets (a viewport and a draw per face).
        #[default]
        Atlas => "atlas",
        /// Six layers of an array image rendered as six views of one draw (`multiview`,
        /// Vulkan 1.1 core, where the device has it): each caster drawn once, its vertex
        /// shader placing it outside the views whose frustum its bounding sphere misses.
        Multiview => "multiview",
    }
);

/// How a frame's shadows are computed: one enum for every technique, shared by
/// [`ShadowPass`](super::ShadowPass) and the renderer (`umbrage::render::Renderer`).
///
/// The first four build stencil shadow volumes and run in both. Open, non-manifold and
/// transparent casters take the multiplicity path (Kim et al. 2008) under each of them.
/// [`RayQuery`](Technique::RayQuery) runs in both too, writing the same stencil from the
/// host's G-buffer ([`ShadowPass::set_ray_query_inputs`](super::ShadowPass::set_ray_query_inputs)).
/// [`ShadowMap`](Technique::ShadowMap) is a whole renderer path: a `ShadowPass` refuses it
/// with [`Error::InvalidDesc`] ([`PassSettings::check`](super::PassSettings::check)).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Technique {
    /// CPU possible silhouettes and index streams, with one of the papers' case rules.
    Volumes(Method),
    /// The Cg article's GPU-only method: static per-face planes and zero-area edge quads,
    /// extruded in the vertex shader; no CPU work per frame but culling.
    EdgeQuads,
    /// The Cg article's starting point: every opaque caster flattened onto one receiver plane
    /// from the light ([`ShadowPass::set_planar_receiver`](super::ShadowPass::set_planar_receiver),
    /// default y = 0) and drawn with the stencil set to 1 (so no pixel is darkened twice). Exact
    /// on that plane, wrong everywhere else (no shadows on other surfaces).
    Planar,
    /// GPU possible silhouettes: McGuire's three cases chosen on the CPU from bounds, then per
    /// caster and light a compute pass finds facing (from static object-space planes, exact as
    /// the CPU's), silhouette edges (from a static edge table) and writes the sides and caps as
    /// 16-bit indices, drawn with `vkCmdDrawIndexedIndirect`: no CPU work per triangle and no
    /// geometry sent per frame. Parts on the multiplicity path (open, non-manifold) and
    /// transparent casters keep the CPU path.
    Compute,
    /// Mesh-shader extrusion (`VK_EXT_mesh_shader`): McGuire's three cases chosen on the CPU
    /// from bounds, the facing bits found on the GPU as [`Compute`](Technique::Compute) finds
    /// them (bit for bit the CPU's), then per (light, caster part) one `vkCmdDrawMeshTasksEXT`
    /// over the part's meshlets (built once per caster, each edge owned by exactly one
    /// meshlet) that emits the side quads, the fan dark cap and, for z-fail, the caps, with
    /// no index buffer (docs/mesh.md). Needs [`Capabilities::mesh_shader`](super::Capabilities::mesh_shader). Parts on the
    /// multiplicity path (open, non-manifold) and transparent casters keep the CPU path.
    Mesh,
    /// The shadow-map baseline (PCF 3x3) with maps of `size` texels a side (renderer only).
    ShadowMap {
        /// Texels per side of one map (16..=8192).
        size: u32,
        /// How the lookup reads its taps.
        pcf: Pcf,
        /// How a point light's six cube faces are rendered.
        cube: CubeFaces,
    },
    /// One shadow ray per pixel with `VK_KHR_ray_query` against acceleration structures of the
    /// casters, writing the volumes' stencil: 1 where the ray towards the light is blocked
    /// (docs/raytrace.md). Needs [`Capabilities::ray_query`](super::Capabilities::ray_query), one sample and the stencil
    /// counter; transparent casters are refused.
    RayQuery,
}

impl Technique {
    /// The name on the command line and in `--stats` (`mcguire`, ..., `edgequad`, `compute`,
    /// `mesh`, `shadowmap`, `rayquery`).
    pub fn name(self) -> &'static str {
        match self {
            Technique::Volumes(m) => m.name(),
            Technique::EdgeQuads => "edgequad",
            Technique::Planar => "planar",
            Technique::Compute => "compute",
            Technique::Mesh => "mesh",
            Technique::ShadowMap { .. } => "shadowmap",
            Technique::RayQuery => "rayquery",
        }
    }
    /// The case rule the planner uses (edge quads, compute, mesh, and the renderer-only techniques'
    /// culling use McGuire's rule).
    pub fn method(self) -> Method {
        match self {
            Technique::Volumes(m) => m,
            Technique::EdgeQuads | Technique::Compute | Technique::Mesh | Technique::ShadowMap { .. } | Technique::RayQuery => {
                Method::McGuire
            }
            // Culling only: the casters' draws are replaced by their flattened triangles.
            Technique::Planar => Method::ZPass,
        }
    }
    /// Whether it counts shadow volumes (or planar projections) in the stencil: every
    /// technique a [`ShadowPass`](super::ShadowPass) runs except [`RayQuery`](Technique::RayQuery).
    pub fn is_volume_pass(self) -> bool {
        self.pass_technique().is_some() && self != Technique::RayQuery
    }
    /// `Some(self)` for the techniques a [`ShadowPass`](super::ShadowPass) runs, `None` for
    /// the renderer-only shadow-map baseline.
    pub fn pass_technique(self) -> Option<Technique> {
        match self {
            Technique::Volumes(_)
            | Technique::EdgeQuads
            | Technique::Planar
            | Technique::Compute
            | Technique::Mesh
            | Technique::RayQuery => Some(self),
            Technique::ShadowMap { .. } => None,
        }
    }
    /// The shadow-map baseline with maps of `size` texels, its default lookup ([`Pcf::Taps`])
    /// and cube faces ([`CubeFaces::Atlas`]).
    pub fn shadow_map(size: u32) -> Technique {
        Technique::ShadowMap { size, pcf: Pcf::Taps, cube: CubeFaces::Atlas }
    }
    /// The five volume methods (z-pass, z-fail, Everitt-Kilgard, Lengyel, McGuire).
    pub fn all_volumes() -> Vec<Technique> {
        Method::ALL.iter().map(|&m| Technique::Volumes(m)).collect()
    }
    /// Parses a `--method` value: `auto` (= mcguire), a volume method, `edgequad`, `planar`,
    /// `compute`, `mesh`, `rayquery` or `shadowmap` (with maps of `shadow_map_size` texels, read with
    /// [`Pcf::Taps`], cube faces in an [`CubeFaces::Atlas`]).
    pub fn parse(s: &str, shadow_map_size: u32) -> Result<Technique> {
        match s {
            "edgequad" => Ok(Technique::EdgeQuads),
            "planar" => Ok(Technique::Planar),
            "compute" => Ok(Technique::Compute),
            "mesh" => Ok(Technique::Mesh),
            "shadowmap" => Ok(Technique::shadow_map(shadow_map_size)),
            "rayquery" => Ok(Technique::RayQuery),
            _ => s.parse::<Method>().map(Technique::Volumes).map_err(|_| Error::UnknownName {
                what: "method",
                name: s.into(),
                expected: format!(
                    "auto, {}, edgequad, planar, compute, mesh, shadowmap, rayquery",
                    Method::ALL.map(|m| m.name()).join(", ")
                ),
            }),
        }
    }
}

impl std::fmt::Display for Technique {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

#[cfg(feature = "serde")]
impl serde::Serialize for Technique {
    /// As its [`name`](Technique::name), the `method` of `--stats`.
    fn serialize<S: serde::Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        s.serialize_str(self.name())
    }
}

impl Default for Technique {
    fn default() -> Self {
        Technique::Volumes(Method::McGuire)
    }
}
