//! What a [`ShadowPass`](super::ShadowPass) is built for ([`ShadowPassDesc`], fixed at
//! creation) and what may change between frames ([`PassSettings`]).

use crate::error::{Error, Result};
use crate::named_enum::named_enum;
use crate::shadow::Method;
use ash::vk;

named_enum!(
    /// How z-fail keeps the far plane out of the way (fixed at creation: the pipelines'
    /// depth-clamp state depends on it).
    DepthMode, "depth mode", {
        /// Far plane at infinity (w = 0 vertices land exactly on depth 1).
        #[default]
        Infinite => "infinite",
        /// A finite far plane beyond the scene, with `depthClamp` on the shadow pipelines.
        Clamp => "clamp",
    }
);

named_enum!(
    /// How shadow geometry reaches the GPU each frame.
    IndexFormat, "index format", {
        /// 4 bytes an index: 12 bytes a shadow triangle.
        U32 => "u32",
        /// 2 bytes an index: the paper's 6 bytes a shadow triangle.
        U16 => "u16",
        /// 8-bit indices for chunks of at most 128 vertices (needs `indexTypeUint8`), else u16.
        U8 => "u8",
        /// u8 where possible, else u16.
        #[default]
        Auto => "auto",
        /// No indices: every shadow-triangle vertex streamed as 4 x f32 (the naive baseline).
        Naive => "naive",
    }
);

named_enum!(
    /// Where shadow volumes are counted.
    Counter, "counter", {
        /// The 8-bit stencil with wrapping increments (counts modulo 256).
        #[default]
        Stencil => "stencil",
        /// A 32-bit float colour target with additive blending: no 8-bit wrap (exact to 2^24).
        Float => "float",
    }
);

/// How the shadow pass builds the volumes of closed opaque casters. Open, non-manifold and
/// transparent casters take the multiplicity path (Kim et al. 2008) under every technique.
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
}

impl Technique {
    /// The name on the command line and in `--stats` (`mcguire`, ..., `edgequad`, `compute`).
    pub fn name(self) -> &'static str {
        match self {
            Technique::Volumes(m) => m.name(),
            Technique::EdgeQuads => "edgequad",
            Technique::Planar => "planar",
            Technique::Compute => "compute",
        }
    }
    /// The case rule the planner uses (edge quads cull with McGuire's rule).
    pub fn method(self) -> Method {
        match self {
            Technique::Volumes(m) => m,
            Technique::EdgeQuads | Technique::Compute => Method::McGuire,
            // Culling only: the casters' draws are replaced by their flattened triangles.
            Technique::Planar => Method::ZPass,
        }
    }
}

impl Default for Technique {
    fn default() -> Self {
        Technique::Volumes(Method::McGuire)
    }
}

/// The optional device features the host enabled on its `VkDevice`. The pass uses a feature
/// only when the host enabled it AND the physical device reports it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct EnabledFeatures {
    /// `VkPhysicalDeviceFeatures::depthClamp` (needed by [`DepthMode::Clamp`]).
    pub depth_clamp: bool,
    /// `VkPhysicalDeviceFeatures::depthBounds`: the determination is limited to the light's
    /// depth range.
    pub depth_bounds: bool,
    /// `VK_EXT_index_type_uint8` / `VK_KHR_index_type_uint8` with `indexTypeUint8`: 3-byte
    /// shadow triangles for chunks of at most 128 vertices.
    pub index_type_uint8: bool,
}

/// What a [`ShadowPass`](super::ShadowPass) is created for. Everything here is fixed for the
/// pass's lifetime (pipelines and ring slots are built from it); per-frame choices are in
/// [`PassSettings`].
#[derive(Clone, Debug, PartialEq)]
pub struct ShadowPassDesc {
    /// The host's depth-stencil format: must have depth and 8 stencil bits
    /// (`D16_UNORM_S8_UINT`, `D24_UNORM_S8_UINT`, `D32_SFLOAT_S8_UINT`).
    pub depth_stencil_format: vk::Format,
    /// Frames the host keeps in flight (ring slots of per-frame streams), at least 1, at most 64.
    pub frames_in_flight: usize,
    /// The host's projection: infinite far plane, or finite with depth clamp.
    pub depth_mode: DepthMode,
    /// The features the host enabled on its device.
    pub features: EnabledFeatures,
    /// The first frame's settings (technique, counter, index format).
    pub settings: PassSettings,
    /// Build the light-intensity-map pipelines for transparent casters (Kim et al. 2008),
    /// rendering into this format (`R16G16B16A16_SFLOAT` or `R32G32B32A32_SFLOAT`; needs
    /// blending on it). `None`: transparent casters are refused.
    pub transmit_format: Option<vk::Format>,
    /// Build the debug pipeline that draws the volumes translucent over a colour target of
    /// this format ([`ShadowPass::cmd_draw_volume_overlay`](super::ShadowPass::cmd_draw_volume_overlay)).
    pub debug_color_format: Option<vk::Format>,
}

impl Default for ShadowPassDesc {
    fn default() -> Self {
        ShadowPassDesc {
            depth_stencil_format: vk::Format::D32_SFLOAT_S8_UINT,
            frames_in_flight: 2,
            depth_mode: DepthMode::Infinite,
            features: EnabledFeatures::default(),
            settings: PassSettings::default(),
            transmit_format: None,
            debug_color_format: None,
        }
    }
}

/// What may change from one frame to the next.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct PassSettings {
    /// Volumes with a case rule, or edge quads.
    pub technique: Technique,
    /// Stencil or float counting; [`ShadowPass::cmd_determine`](super::ShadowPass::cmd_determine)
    /// counts in the stencil, [`ShadowPass::cmd_count_float`](super::ShadowPass::cmd_count_float)
    /// in a float target.
    pub counter: Counter,
    /// Index format of the per-frame streams.
    pub index_format: IndexFormat,
    /// The paper's constant-factor optimisations, each of which can be switched off to
    /// measure what it saves (all on by default).
    pub toggles: PassToggles,
}

/// The per-light optimisations McGuire et al. claim constant factors for; switching one off
/// keeps the shadows exact (they only bound where the volumes are drawn) and costs what it
/// saves. `umbrage bench --suite fill-vertex` measures each as an ablation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PassToggles {
    /// Limit each light's determination (and lighting) to its screen-space scissor rectangle
    /// (off: the whole target).
    pub scissor: bool,
    /// The depth-bounds test to the light's range, when the device has it (off: no bounds).
    pub depth_bounds: bool,
    /// Cull casters whose shadow volume cannot reach the view frustum, or that lie beyond the
    /// light's range or cone (off: every caster's volume is drawn, its case still chosen).
    pub culling: bool,
}

impl Default for PassToggles {
    fn default() -> Self {
        PassToggles { scissor: true, depth_bounds: true, culling: true }
    }
}

/// What the pass can use: the host's enabled features intersected with what the physical
/// device reports, plus the format capabilities it probed.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Capabilities {
    /// depthClamp enabled and present.
    pub depth_clamp: bool,
    /// depthBounds enabled and present.
    pub depth_bounds: bool,
    /// indexTypeUint8 enabled and present.
    pub index_type_uint8: bool,
    /// `R32_SFLOAT` colour attachments blend (float counter).
    pub r32f_blend: bool,
}

/// Refuses a depth-stencil format without a depth aspect or without 8 stencil bits.
pub(crate) fn check_depth_stencil_format(format: vk::Format) -> Result<()> {
    match format {
        vk::Format::D16_UNORM_S8_UINT | vk::Format::D24_UNORM_S8_UINT | vk::Format::D32_SFLOAT_S8_UINT => Ok(()),
        f => Err(Error::Unsupported(format!(
            "depth-stencil format {f:?}: the shadow pass needs a depth aspect and 8 stencil bits \
             (D16_UNORM_S8_UINT, D24_UNORM_S8_UINT or D32_SFLOAT_S8_UINT)"
        ))),
    }
}

impl PassSettings {
    /// Whether the device can honour these settings (checked before every frame).
    pub fn check(&self, caps: &Capabilities) -> Result<()> {
        if self.index_format == IndexFormat::U8 && !caps.index_type_uint8 {
            return Err(Error::Unsupported("--index-format u8 needs VK_EXT_index_type_uint8; use auto or u16".into()));
        }
        if self.counter == Counter::Float && !caps.r32f_blend {
            return Err(Error::Unsupported(
                "--counter float needs R32_SFLOAT colour blending, which this device lacks; use --counter stencil".into(),
            ));
        }
        Ok(())
    }
}
