//! [`Technique`]: how the pass computes a frame's shadows (part of `pass/`'s ground floor, with
//! [`desc`](super::desc): it imports nothing above it).

use crate::error::{Error, Result};
use crate::shadow::Method;

/// How a [`ShadowPass`](super::ShadowPass) computes a frame's shadows: every technique it runs,
/// and nothing else (the shadow-map baseline is a renderer's, not the pass's: umbrage's own
/// renderer has it beside this enum, in `umbrage_render::RenderTechnique`).
///
/// All but [`RayQuery`](Technique::RayQuery) build stencil shadow volumes. Open, non-manifold
/// and transparent casters take the multiplicity path (Kim et al. 2008) under each of them.
/// `RayQuery` writes the same stencil from the host's G-buffer
/// ([`ShadowPass::set_ray_query_inputs`](super::ShadowPass::set_ray_query_inputs)).
///
/// Its [`FromStr`](std::str::FromStr) reads the names of `umbrage render --method` (and
/// [`name`](Technique::name) writes them).
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
    /// One shadow ray per pixel with `VK_KHR_ray_query` against acceleration structures of the
    /// casters, writing the volumes' stencil: 1 where the ray towards the light is blocked
    /// (docs/raytrace.md). Needs [`Capabilities::ray_query`](super::Capabilities::ray_query), one sample and the stencil
    /// counter; transparent casters are refused.
    RayQuery,
}

impl Technique {
    /// The name on the command line and in `--stats` (`mcguire`, ..., `edgequad`, `planar`,
    /// `compute`, `mesh`, `rayquery`).
    pub fn name(self) -> &'static str {
        match self {
            Technique::Volumes(m) => m.name(),
            Technique::EdgeQuads => "edgequad",
            Technique::Planar => "planar",
            Technique::Compute => "compute",
            Technique::Mesh => "mesh",
            Technique::RayQuery => "rayquery",
        }
    }
    /// The case rule the planner uses (edge quads, compute, mesh and ray query's culling use
    /// McGuire's rule).
    pub fn method(self) -> Method {
        match self {
            Technique::Volumes(m) => m,
            Technique::EdgeQuads | Technique::Compute | Technique::Mesh | Technique::RayQuery => Method::McGuire,
            // Culling only: the casters' draws are replaced by their flattened triangles.
            Technique::Planar => Method::ZPass,
        }
    }
    /// Whether it counts shadow volumes (or planar projections) in the stencil: every
    /// technique but [`RayQuery`](Technique::RayQuery).
    pub fn is_volume_pass(self) -> bool {
        self != Technique::RayQuery
    }
    /// The five volume methods (z-pass, z-fail, Everitt-Kilgard, Lengyel, McGuire).
    pub fn all_volumes() -> Vec<Technique> {
        Method::ALL.iter().map(|&m| Technique::Volumes(m)).collect()
    }
    /// Every technique's name, for an error listing them (`auto` is McGuire's).
    pub fn names() -> String {
        format!("auto, {}, zpass-clear, edgequad, planar, compute, mesh, rayquery", Method::ALL.map(|m| m.name()).join(", "))
    }
}

impl std::str::FromStr for Technique {
    type Err = Error;
    /// Reads a `--method` name: `auto` (= `mcguire`), a volume method (`mcguire`, `lengyel`,
    /// `everitt-kilgard`, `zfail`, `zpass`, `zpass-clear`), `edgequad`, `planar`, `compute`,
    /// `mesh` or `rayquery`; any other is [`Error::UnknownName`] listing these.
    fn from_str(s: &str) -> Result<Technique> {
        match s {
            "auto" => Ok(Technique::Volumes(Method::McGuire)),
            "edgequad" => Ok(Technique::EdgeQuads),
            "planar" => Ok(Technique::Planar),
            "compute" => Ok(Technique::Compute),
            "mesh" => Ok(Technique::Mesh),
            "rayquery" => Ok(Technique::RayQuery),
            _ => s.parse::<Method>().map(Technique::Volumes).map_err(|_| Error::UnknownName {
                what: "method",
                name: s.into(),
                expected: Technique::names(),
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
