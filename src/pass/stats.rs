//! What one frame of the shadow pass did, per light and caster: the `--stats` JSON's
//! `lights` and `totals` (a contract other tools read: keys as in issue #3, more keys welcome).
//! The typed fields serialise to the names the JSON has always had.

use crate::geom::LightKind;
use crate::shadow::{Case, DarkCap, VolumePath};

crate::named_enum::named_enum!(
    /// The index format a caster's draws used this frame (`index_format` in `--stats`).
    UsedIndexFormat, "used index format", {
        /// Nothing was drawn.
        #[default]
        None => "none",
        /// 8-bit indices.
        U8 => "u8",
        /// 16-bit indices (the paper's 6 bytes a triangle).
        U16 => "u16",
        /// 32-bit indices.
        U32 => "u32",
        /// No indices: vertices streamed as 4 x f32.
        Naive => "naive",
    }
);

impl From<super::desc::IndexFormat> for UsedIndexFormat {
    /// The format a draw used (`Auto` never reaches a draw: it is resolved per chunk first).
    fn from(f: super::desc::IndexFormat) -> Self {
        match f {
            super::desc::IndexFormat::U8 => UsedIndexFormat::U8,
            super::desc::IndexFormat::U16 | super::desc::IndexFormat::Auto => UsedIndexFormat::U16,
            super::desc::IndexFormat::U32 => UsedIndexFormat::U32,
            super::desc::IndexFormat::Naive => UsedIndexFormat::Naive,
        }
    }
}

#[cfg(feature = "serde")]
fn dark_cap_name<S: serde::Serializer>(d: &DarkCap, s: S) -> Result<S::Ok, S::Error> {
    s.serialize_str(d.name())
}

#[derive(Clone, Debug, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
/// Shadow-volume triangles by part.
pub struct Triangles {
    /// Side quads' triangles (two per silhouette edge for a point light, one for a directional).
    pub sides: u64,
    /// Dark-cap triangles (at infinity).
    pub dark_cap: u64,
    /// Light-cap triangles (the caster's own faces, z-fail cases).
    pub light_cap: u64,
}

impl Triangles {
    /// All shadow triangles.
    pub fn total(&self) -> u64 {
        self.sides + self.dark_cap + self.light_cap
    }
    /// Adds `o` into `self`.
    pub fn add(&mut self, o: &Triangles) {
        self.sides += o.sides;
        self.dark_cap += o.dark_cap;
        self.light_cap += o.light_cap;
    }
}

#[derive(Clone, Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
/// One caster's volume for one light.
pub struct CasterStats {
    /// The caster's name (the scene mesh's, or the one given to `add_caster`).
    pub name: String,
    /// `culled`, `zpass`, `zfail` or `zfail_light_cap` (McGuire et al.'s cases 1-3).
    pub case: Case,
    /// Possible silhouette edges found for this light.
    pub silhouette_edges: u64,
    /// Shadow triangles drawn.
    pub triangles: Triangles,
    /// Index bytes the GPU reads from this frame's stream.
    pub index_bytes: u64,
    /// Vertex bytes streamed (the naive format only; 0 otherwise).
    pub vertex_bytes: u64,
    /// Bytes per shadow triangle actually sent this frame (index + streamed vertex bytes).
    pub bytes_per_triangle: f64,
    /// `u8`, `u16`, `u32`, `naive` or `none`.
    pub index_format: UsedIndexFormat,
    /// Which dark cap was emitted (`Fan`, `BackFaces`, ...: the variant's name).
    #[cfg_attr(feature = "serde", serde(serialize_with = "dark_cap_name"))]
    pub dark_cap_kind: DarkCap,
    /// `manifold` (the three-case path), `multiplicity` (open / non-manifold casters),
    /// `edgequad`, `planar`, `compute` or `sphere`.
    pub path: VolumePath,
    /// Why the caster took the multiplicity path (empty for manifold casters).
    pub path_reason: String,
    /// Largest |edge multiplicity| drawn (1 for a manifold silhouette).
    pub multiplicity_max: u32,
    /// Per part (connected component) that was planned: its own case, path and triangles
    /// (empty when the caster was culled whole or drawn with edge quads).
    pub parts: Vec<PartStats>,
    /// For an analytic sphere caster (`path` = `sphere`): its polygon for this light.
    #[cfg_attr(feature = "serde", serde(skip_serializing_if = "Option::is_none"))]
    pub sphere: Option<SphereStats>,
}

/// An analytic sphere caster's shadow-volume polygon for one light.
#[derive(Clone, Copy, Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct SphereStats {
    /// Segments of the polygon circumscribed about the tangency circle.
    pub segments: u32,
    /// Chosen by the half-pixel rule (false: fixed by the scene's `segments`).
    pub auto: bool,
    /// The rule's bound on the shadow's error with these segments, pixels.
    pub error_px: f64,
}

/// One part (connected component) of a caster for one light.
#[derive(Clone, Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct PartStats {
    /// Index of the part in the caster.
    pub part: usize,
    /// The part's case (`culled`, `zpass`, `zfail`, `zfail_light_cap`).
    pub case: Case,
    /// `manifold`, `multiplicity` or `compute`.
    pub path: VolumePath,
    /// Possible silhouette edges of the part.
    pub silhouette_edges: u64,
    /// Its shadow triangles.
    pub triangles: Triangles,
}

#[derive(Clone, Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
/// One light of a frame.
pub struct LightStats {
    /// The light's index in the frame's light list.
    pub index: usize,
    /// `point`, `spot` or `directional`.
    pub kind: LightKind,
    /// The light's scissor rectangle `[x, y, width, height]` in pixels (`None`: whole target).
    pub scissor: Option<[u32; 4]>,
    /// The light's depth bounds `[min, max]` when the device tests them.
    pub depth_bounds: Option<[f32; 2]>,
    /// One entry per caster, in draw order; with [`PassSettings::keep`](super::PassSettings::keep)
    /// only the casters the light draws (the culled ones are counted in [`Cases::culled`]; a
    /// bounded light's casters out of range, found with a spatial index, are not even
    /// visited).
    pub casters: Vec<CasterStats>,
    /// `zpass-clear`: the number of drawn volumes containing the eye (the stencil starts there).
    pub eye_volumes: Option<i32>,
    /// `zpass-clear`: a volume crosses the near-plane rectangle (its corners are in a different
    /// number of volumes than the eye), the notes' caveat: the clear is then wrong somewhere.
    pub near_plane_split: Option<bool>,
}

#[derive(Clone, Debug, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
/// Caster-light pairs per McGuire case.
pub struct Cases {
    /// Casters culled (outside range, cone or view).
    pub culled: u64,
    /// Case 1: z-pass.
    pub zpass: u64,
    /// Case 2: z-fail without a light cap.
    pub zfail: u64,
    /// Case 3: z-fail with a light cap.
    pub zfail_light_cap: u64,
}

#[derive(Clone, Debug, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
/// A frame's totals over lights and casters.
pub struct Totals {
    /// Shadow triangles over all lights and casters.
    pub triangles: Triangles,
    /// Index bytes the GPU reads.
    pub index_bytes: u64,
    /// Streamed vertex bytes (naive format).
    pub vertex_bytes: u64,
    /// Geometry bytes the CPU wrote for this frame: the streams plus any caster uploads
    /// (new, moved-by-deformation casters); 0 for static casters under a GPU-only technique.
    pub bytes_sent: u64,
    /// Caster-light pairs per case.
    pub cases: Cases,
    /// Volume draw calls the determination records (all lights; an edge-quad caster's two).
    pub draws: u64,
    /// [`Technique::Compute`](super::Technique::Compute): bytes the GPU silhouettes' `facing`
    /// and `find` stages read from the casters' static tables (16 a triangle for its plane, 16
    /// an edge, per light and caster); 0 for the other techniques. With `gpu_ms.silhouettes`,
    /// the pass's read rate.
    pub silhouette_read_bytes: u64,
    /// [`Technique::Mesh`](super::Technique::Mesh): the meshlets its draws covered (a part's
    /// meshlets once per draw: sides, dark cap, light cap), read back after the frame; 0 for
    /// the other techniques.
    pub mesh_meshlets: u64,
    /// [`Technique::Mesh`](super::Technique::Mesh): the mesh workgroups that ran: as many as
    /// [`mesh_meshlets`](Self::mesh_meshlets) without a task stage, only the meshlets that
    /// emit something with it ([`PassToggles::mesh_task`](super::PassToggles::mesh_task)).
    pub mesh_workgroups: u64,
    /// Light–caster pairs drawn this frame (not culled; analytic spheres not counted):
    /// `pairs_kept + pairs_replanned`.
    pub pairs_total: u64,
    /// Pairs planned this frame (every drawn pair without [`PassSettings::keep`](super::PassSettings::keep)).
    pub pairs_replanned: u64,
    /// Pairs drawn from index lists kept from an earlier frame (no planning, 0 bytes sent).
    pub pairs_kept: u64,
    /// Bytes of index lists kept across frames, resident after this frame.
    pub kept_bytes: u64,
    /// Kept pairs dropped this frame: evicted past the budget, or their caster moved, changed
    /// or went.
    pub kept_evictions: u64,
}

#[derive(Clone, Debug, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
/// CPU time of a frame by stage, ms.
pub struct CpuMs {
    /// With [`PassSettings::keep`](super::PassSettings::keep): culling, the cases and the
    /// kept lists' look-ups (without it this work is inside `plan`).
    pub cull: f64,
    /// Facing bits and possible silhouettes.
    pub silhouettes: f64,
    /// Culling, cases and index emission.
    pub plan: f64,
    /// Stream building and command recording.
    pub record: f64,
}
