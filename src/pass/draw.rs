//! The draws a prepared frame holds (a leaf: the planner's output as the recording reads it,
//! imported by the frame, the compute silhouettes and the sphere casters alike).

use super::desc::IndexFormat;
use super::stats::LightStats;
use crate::shadow::{Case, LightPlan};
use ash::vk;
use glam::{Mat4, Vec3, Vec4};

/// One index-stream draw of a caster chunk.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Draw {
    /// The chunk's dual-length vertex buffer.
    pub vertices: vk::Buffer,
    /// The kept buffer the indices (or naive vertices) are in ([`super::keep`]); `None`: the
    /// frame's stream.
    pub kept: Option<vk::Buffer>,
    /// Byte offset of the indices (or naive vertices) in the frame's stream (or kept buffer).
    pub offset: u64,
    pub count: u32,
    pub format: IndexFormat,
    /// The case of the caster part this chunk belongs to (its pipeline and sign follow it).
    pub case: Case,
    /// A light cap (drawn with the depth-NEVER pipeline by the stencil counter).
    pub light_cap: bool,
    /// GPU silhouettes: `offset` is the byte offset of the draw's
    /// `VkDrawIndexedIndirectCommand` in the frame's compute records, the indices (u16) are in
    /// its compute output buffer, and `count` is unknown (0) until read back.
    pub indirect: bool,
    /// Mesh-shader extrusion: a `vkCmdDrawMeshTasksEXT` over a caster part's meshlets (no
    /// vertex or index buffer: `vertices`, `offset`, `count` and `format` are unused).
    pub mesh: Option<super::mesh::MeshDraw>,
}

/// A caster's draws for one light: its own list (planned this frame), or a kept pair's, shared
/// with the kept plans ([`super::keep`]) so that a kept pair's frame copies no list.
#[derive(Clone, Debug)]
pub(crate) enum DrawList {
    Own(Vec<Draw>),
    Shared(std::sync::Arc<[Draw]>),
}

impl Default for DrawList {
    fn default() -> Self {
        DrawList::Own(Vec::new())
    }
}

impl std::ops::Deref for DrawList {
    type Target = [Draw];
    fn deref(&self) -> &[Draw] {
        match self {
            DrawList::Own(v) => v,
            DrawList::Shared(a) => a,
        }
    }
}

impl DrawList {
    /// The list to change (a shared one copied first).
    pub fn to_mut(&mut self) -> &mut Vec<Draw> {
        if let DrawList::Shared(a) = self {
            *self = DrawList::Own(a.to_vec());
        }
        match self {
            DrawList::Own(v) => v,
            DrawList::Shared(_) => unreachable!("made own above"),
        }
    }
}

/// Edge-quad geometry of a caster (static buffers).
#[derive(Clone, Copy, Debug)]
pub(crate) struct EdgeQuadDraw {
    pub vertices: vk::Buffer,
    pub indices: vk::Buffer,
    pub face_indices: u32,
    pub quad_indices: u32,
}

/// One caster's volume for one light.
#[derive(Clone, Debug)]
pub(crate) struct CasterDraw {
    pub case: Case,
    pub mvp: Mat4,
    pub light_object: Vec4,
    /// `Some(t)` for a transparent caster (light-intensity map, not the opaque counter).
    pub transmittance: Option<Vec3>,
    pub draws: DrawList,
    pub edge_quad: Option<EdgeQuadDraw>,
}

/// One light of a prepared frame.
#[derive(Clone, Debug)]
pub struct LightFrame {
    /// The light's scissor rectangle (the whole target when unbounded): the determination
    /// clears and draws only inside it, and the host's lighting pass should use it too.
    pub scissor: vk::Rect2D,
    /// The light's depth range when the pass uses depth bounds; `(0, 1)` passes everything.
    pub depth_bounds: Option<(f32, f32)>,
    /// What `--stats` reports for this light.
    pub stats: LightStats,
    /// The plan as the planner made it (cases, silhouettes, counts per caster). With
    /// [`PassSettings::keep`](super::PassSettings::keep): the casters the light draws only,
    /// and a kept pair's plan without its index lists (they are on the GPU).
    pub plan: LightPlan,
    /// The value the determination clears the counter to inside the scissor: 0, or with
    /// [`Method::ZPassClear`](crate::shadow::Method) the number of volumes containing the eye.
    pub counter_clear: u32,
    pub(crate) casters: Vec<CasterDraw>,
}

impl LightFrame {
    /// Whether any opaque volume is drawn for this light (else the stencil stays 0 inside
    /// the scissor and every pixel there is lit).
    pub fn has_opaque_volumes(&self) -> bool {
        self.casters.iter().any(|c| c.case != Case::Culled && c.transmittance.is_none())
    }
    /// Whether any transparent caster's volume is drawn (the light-intensity map is needed).
    pub fn has_transparent_volumes(&self) -> bool {
        self.casters.iter().any(|c| c.case != Case::Culled && c.transmittance.is_some())
    }
}
