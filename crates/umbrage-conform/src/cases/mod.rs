//! The parametrised cases: what each draws into its own tile, what it needs from the device,
//! and how its name is spelled.
//!
//! A case is data, not code: an initial depth and stencil value per pixel of its tile, a list
//! of draws (fixed-function state, transform, vertices), and the features it needs. The CPU
//! model ([`super::model`]) turns it into the expected result, the batch runner
//! ([`super::batch`]) draws every case of one [`Config`] into one image in one submission.
//!
//! Names follow the CTS's dotted style, most general first:
//! `<group>.<format>.<render model>.<state model>.<what>`, e.g.
//! `stencil.d24s8.dynamic_rendering.static_state.ops.front_incr_wrap.back_decr_wrap.dfail_keep.fail_zero.comp_always.ref_3.masks_ff_0f`.

mod depth;
pub mod gaps;
mod raster;
mod stencil;
mod zoo;

use ash::vk;
use glam::Mat4;

/// How the render targets are bound.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum RenderModel {
    /// `vkCmdBeginRendering` (Vulkan 1.3 dynamic rendering).
    DynamicRendering,
    /// A classic `VkRenderPass` + `VkFramebuffer` (`vkCmdBeginRenderPass`).
    RenderPass,
}

/// Where the depth/stencil state comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum StateModel {
    /// Baked into one pipeline per distinct state.
    Static,
    /// One pipeline whose static depth/stencil state is deliberately wrong, overridden per draw
    /// by Vulkan 1.3 core dynamic state (`vkCmdSetStencilOp`, `vkCmdSetStencilReference`,
    /// compare/write masks, depth test/write/compare, and `vkCmdSetDepthBounds` with
    /// `vkCmdSetDepthBoundsTestEnable` where `depthBounds` exists).
    Dynamic,
}

/// One configuration: a depth-stencil format, a render model and a state model. Every case
/// of a configuration is drawn in one submission.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Config {
    /// The depth-stencil attachment format.
    pub format: vk::Format,
    /// Dynamic rendering or a render pass.
    pub render: RenderModel,
    /// Static or dynamic depth/stencil state.
    pub state: StateModel,
}

/// The depth-stencil formats tried, in name order.
pub const FORMATS: [vk::Format; 4] =
    [vk::Format::D16_UNORM_S8_UINT, vk::Format::D24_UNORM_S8_UINT, vk::Format::D32_SFLOAT_S8_UINT, vk::Format::S8_UINT];

/// How a format stores depth.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DepthKind {
    /// No depth aspect (S8_UINT).
    None,
    /// 16-bit unsigned normalised.
    Unorm16,
    /// 24-bit unsigned normalised (in the low bits of a 32-bit word).
    Unorm24,
    /// 32-bit float.
    Float32,
}

/// Short name of a format as used in case names (`d24s8`).
pub fn format_name(f: vk::Format) -> &'static str {
    match f {
        vk::Format::D16_UNORM_S8_UINT => "d16s8",
        vk::Format::D24_UNORM_S8_UINT => "d24s8",
        vk::Format::D32_SFLOAT_S8_UINT => "d32s8",
        vk::Format::S8_UINT => "s8",
        _ => "unknown",
    }
}

/// The depth representation of `f`.
pub fn depth_kind(f: vk::Format) -> DepthKind {
    match f {
        vk::Format::D16_UNORM_S8_UINT => DepthKind::Unorm16,
        vk::Format::D24_UNORM_S8_UINT => DepthKind::Unorm24,
        vk::Format::D32_SFLOAT_S8_UINT => DepthKind::Float32,
        _ => DepthKind::None,
    }
}

impl RenderModel {
    /// `dynamic_rendering` or `render_pass`.
    pub fn name(self) -> &'static str {
        match self {
            RenderModel::DynamicRendering => "dynamic_rendering",
            RenderModel::RenderPass => "render_pass",
        }
    }
}

impl StateModel {
    /// `static_state` or `dynamic_state`.
    pub fn name(self) -> &'static str {
        match self {
            StateModel::Static => "static_state",
            StateModel::Dynamic => "dynamic_state",
        }
    }
}

impl Config {
    /// `d24s8.dynamic_rendering.static_state`.
    pub fn name(&self) -> String {
        format!("{}.{}.{}", format_name(self.format), self.render.name(), self.state.name())
    }
    /// How the format stores depth.
    pub fn depth_kind(&self) -> DepthKind {
        depth_kind(self.format)
    }
    /// Whether the format has a depth aspect.
    pub fn has_depth(&self) -> bool {
        self.depth_kind() != DepthKind::None
    }
    /// Every configuration of `formats` (format-major, then render model, then state model).
    pub fn all(formats: &[vk::Format]) -> Vec<Config> {
        let mut v = Vec::new();
        for &format in formats {
            for render in [RenderModel::DynamicRendering, RenderModel::RenderPass] {
                for state in [StateModel::Static, StateModel::Dynamic] {
                    v.push(Config { format, render, state });
                }
            }
        }
        v
    }
}

/// A device capability a case needs; without it the case is skipped with [`Req::reason`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Req {
    /// The format has a depth aspect.
    DepthAspect,
    /// `depthClamp`.
    DepthClamp,
    /// `depthBounds`.
    DepthBounds,
    /// `VK_EXT_depth_range_unrestricted`.
    DepthRangeUnrestricted,
    /// A floating-point depth format (values outside [0, 1] are representable).
    FloatDepth,
    /// `occlusionQueryPrecise` (exact sample counts).
    OcclusionQueryPrecise,
}

impl Req {
    /// Why a case needing this is skipped.
    pub fn reason(self) -> &'static str {
        match self {
            Req::DepthAspect => "the format has no depth aspect",
            Req::DepthClamp => "depthClamp not supported",
            Req::DepthBounds => "depthBounds not supported",
            Req::DepthRangeUnrestricted => "VK_EXT_depth_range_unrestricted not supported",
            Req::FloatDepth => "needs a floating-point depth format (values outside [0, 1])",
            Req::OcclusionQueryPrecise => "occlusionQueryPrecise not supported (sample counts not exact)",
        }
    }
}

/// Fixed-function state of one draw (static pipeline state or dynamic state, per [`StateModel`]).
#[derive(Clone, Copy, Debug)]
pub struct DsState {
    /// Depth test enabled.
    pub depth_test: bool,
    /// Depth writes enabled.
    pub depth_write: bool,
    /// Depth compare op.
    pub depth_compare: vk::CompareOp,
    /// `depthClampEnable` (always static pipeline state).
    pub depth_clamp: bool,
    /// Constant depth bias factor (slope factor 0), static pipeline state.
    pub depth_bias: Option<f32>,
    /// The depth-bounds test with these bounds.
    pub depth_bounds: Option<(f32, f32)>,
    /// `(front, back)` stencil state; `None` disables the stencil test.
    pub stencil: Option<(vk::StencilOpState, vk::StencilOpState)>,
    /// The viewport's `(minDepth, maxDepth)`.
    pub viewport_depth: (f32, f32),
}

impl Default for DsState {
    fn default() -> Self {
        DsState {
            depth_test: false,
            depth_write: false,
            depth_compare: vk::CompareOp::ALWAYS,
            depth_clamp: false,
            depth_bias: None,
            depth_bounds: None,
            stencil: None,
            viewport_depth: (0.0, 1.0),
        }
    }
}

impl DsState {
    /// The key of the pipeline this state needs under `model` (static: everything baked in;
    /// dynamic: only what stays static — clamp and bias).
    pub fn pipeline_key(&self, model: StateModel) -> String {
        match model {
            StateModel::Static => {
                let mut s = *self;
                s.viewport_depth = (0.0, 1.0);
                format!("{s:?}")
            }
            StateModel::Dynamic => format!("clamp={} bias={:?}", self.depth_clamp, self.depth_bias),
        }
    }
}

/// One draw of a case: triangles (non-indexed list) through `shaders/shadow.vert` with the
/// light at the origin, so `(xyz, 0)` vertices are directions to infinity.
#[derive(Clone, Debug)]
pub struct Draw {
    /// Depth/stencil state.
    pub state: DsState,
    /// Object -> clip transform.
    pub mvp: Mat4,
    /// Homogeneous vertices, three per triangle.
    pub vertices: Vec<[f32; 4]>,
    /// Whether an occlusion query counts this draw's passing samples.
    pub query: bool,
}

/// A known driver bug a zoo case reproduces.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Bug {
    /// The public report (issue or pull-request thread).
    pub url: &'static str,
    /// What went wrong, in a line.
    pub title: &'static str,
}

/// One parametrised case.
#[derive(Clone, Debug)]
pub struct Case {
    /// The full dotted name.
    pub name: String,
    /// The configuration it runs in.
    pub config: Config,
    /// `stencil`, `depth`, `raster`, `zoo`, or one of [`gaps::GROUPS`] (`wrap`, `clip`,
    /// `watertight`, `occlusion`).
    pub group: &'static str,
    /// One line: what the case checks.
    pub what: String,
    /// What the device must support.
    pub requires: Vec<Req>,
    /// Tile size, pixels.
    pub size: (u32, u32),
    /// Initial depth of each tile pixel (row-major), quantised to the format on upload.
    pub init_depth: Vec<f64>,
    /// Initial stencil of each tile pixel.
    pub init_stencil: Vec<u8>,
    /// The draws, in order.
    pub draws: Vec<Draw>,
    /// Expected stencil given directly (`None` entries not judged) instead of by the model:
    /// for properties the model cannot predict pixel by pixel but the spec guarantees
    /// (a watertight mesh counts every pixel exactly once).
    pub stencil_override: Option<Vec<Option<u8>>>,
    /// Pixels whose stencil may be either of two values (a centre on a shared edge: which
    /// triangle covers it is the implementation's choice), with the value the D3D top-left
    /// convention predicts (reported, not required: Vulkan does not mandate it).
    pub either: Vec<(usize, [u8; 2], u8)>,
    /// Whether depth is compared (false: only stencil and queries).
    pub check_depth: bool,
    /// The bug a zoo case would catch.
    pub bug: Option<Bug>,
}

impl Case {
    /// A case with uniform initial `depth` / `stencil` and no draws yet.
    pub fn new(config: Config, group: &'static str, rest: &str, size: (u32, u32), depth: f64, stencil: u8) -> Case {
        let n = (size.0 * size.1) as usize;
        Case {
            name: format!("{group}.{}.{rest}", config.name()),
            config,
            group,
            what: String::new(),
            requires: Vec::new(),
            size,
            init_depth: vec![depth; n],
            init_stencil: vec![stencil; n],
            draws: Vec::new(),
            stencil_override: None,
            either: Vec::new(),
            check_depth: true,
            bug: None,
        }
    }
    /// The first requirement `have` lacks, if any.
    pub fn missing(&self, have: &dyn Fn(Req) -> bool) -> Option<Req> {
        self.requires.iter().copied().find(|&r| !have(r))
    }
}

/// The short name of a stencil op used in case names (`incr_wrap`).
pub fn op_name(op: vk::StencilOp) -> &'static str {
    match op {
        vk::StencilOp::KEEP => "keep",
        vk::StencilOp::ZERO => "zero",
        vk::StencilOp::REPLACE => "replace",
        vk::StencilOp::INCREMENT_AND_CLAMP => "incr_clamp",
        vk::StencilOp::DECREMENT_AND_CLAMP => "decr_clamp",
        vk::StencilOp::INVERT => "invert",
        vk::StencilOp::INCREMENT_AND_WRAP => "incr_wrap",
        vk::StencilOp::DECREMENT_AND_WRAP => "decr_wrap",
        _ => "unknown",
    }
}

/// Parses [`op_name`] back (for the `UMBRAGE_CONFORM_BREAK` test seam).
pub fn parse_op(s: &str) -> Option<vk::StencilOp> {
    STENCIL_OPS.iter().copied().find(|&o| op_name(o) == s)
}

/// The short name of a compare op (`less_or_equal`).
pub fn cmp_name(op: vk::CompareOp) -> &'static str {
    match op {
        vk::CompareOp::NEVER => "never",
        vk::CompareOp::LESS => "less",
        vk::CompareOp::EQUAL => "equal",
        vk::CompareOp::LESS_OR_EQUAL => "less_or_equal",
        vk::CompareOp::GREATER => "greater",
        vk::CompareOp::NOT_EQUAL => "not_equal",
        vk::CompareOp::GREATER_OR_EQUAL => "greater_or_equal",
        vk::CompareOp::ALWAYS => "always",
        _ => "unknown",
    }
}

/// Every stencil op.
pub const STENCIL_OPS: [vk::StencilOp; 8] = [
    vk::StencilOp::KEEP,
    vk::StencilOp::ZERO,
    vk::StencilOp::REPLACE,
    vk::StencilOp::INCREMENT_AND_CLAMP,
    vk::StencilOp::DECREMENT_AND_CLAMP,
    vk::StencilOp::INVERT,
    vk::StencilOp::INCREMENT_AND_WRAP,
    vk::StencilOp::DECREMENT_AND_WRAP,
];

/// Every compare op.
pub const COMPARE_OPS: [vk::CompareOp; 8] = [
    vk::CompareOp::NEVER,
    vk::CompareOp::LESS,
    vk::CompareOp::EQUAL,
    vk::CompareOp::LESS_OR_EQUAL,
    vk::CompareOp::GREATER,
    vk::CompareOp::NOT_EQUAL,
    vk::CompareOp::GREATER_OR_EQUAL,
    vk::CompareOp::ALWAYS,
];

/// Orthographic pixel mapping for a `w` x `h` tile: object (x, y) in pixels (row 0 at the
/// top), z unchanged.
pub fn pixel_ortho(w: u32, h: u32) -> Mat4 {
    super::harness::pixel_ortho(w, h)
}

/// Two triangles covering the integer rectangle `[x0, x1) x [y0, y1)` at depth `z`, front
/// facing (counter-clockwise in Vulkan's sense under [`pixel_ortho`]) or back facing.
pub fn quad(out: &mut Vec<[f32; 4]>, r: [f32; 4], z: f32, front: bool) {
    let [x0, y0, x1, y1] = r;
    // Under pixel_ortho (y down on screen), (x0,y0) -> (x0,y1) -> (x1,y1) has positive
    // Vulkan area: front facing.
    let t1 = [[x0, y0], [x0, y1], [x1, y1]];
    let t2 = [[x0, y0], [x1, y1], [x1, y0]];
    for t in [t1, t2] {
        let t = if front { t } else { [t[0], t[2], t[1]] };
        out.extend(t.iter().map(|p| [p[0], p[1], z, 1.0]));
    }
}

/// Every case of every configuration in `configs`, in a stable order.
pub fn all(configs: &[Config]) -> Vec<Case> {
    let mut v = Vec::new();
    for c in configs {
        v.extend(stencil::cases(*c));
        v.extend(depth::cases(*c));
        v.extend(raster::cases(*c));
        v.extend(zoo::cases(*c));
        v.extend(gaps::cases(*c));
    }
    v
}
