//! What the stencil holds: the kinds of volume draws, and the state a host's lighting pass
//! tests it with (no imports above the pass's ground floor).

use ash::vk;

/// What a volume draw counts into (the pipelines differ, the geometry is the same).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VolumeKind {
    /// Opaque casters into the stencil (two-sided wrapping ops; light caps with depth NEVER).
    Stencil,
    /// Opaque casters into an R32F colour target, ±1 per face, additively blended.
    Float,
    /// As `Float`, but every face depth-tested like the sides, light caps too (the
    /// self-shadowing count against a transparent layer's depth, Kim et al. 2008 step 5).
    FloatDepthTested,
    /// Transparent casters into the light-intensity map: each counted face multiplies by its
    /// transmittance `t` or `1/t` (`log`: adds `±log t`).
    Transmit {
        /// Log-space map (additive) rather than multiplicative.
        log: bool,
    },
    /// Opaque casters with depth and stencil tests always passing and nothing written: under
    /// an occlusion query, the exact number of fragments the volumes rasterise
    /// ([`Diagnostics::cmd_count_rasterised`](super::diagnostics::Diagnostics::cmd_count_rasterised)).
    Rasterised,
}

/// The stencil state of a lighting pass that lights where the count is zero: compare EQUAL
/// against reference 0, no writes, on both faces.
///
/// ```
/// use ash::vk;
/// let s = umbrage::pass::lit_stencil_state();
/// assert_eq!((s.compare_op, s.reference, s.write_mask), (vk::CompareOp::EQUAL, 0, 0));
/// // vk::PipelineDepthStencilStateCreateInfo::default().stencil_test_enable(true).front(s).back(s)
/// ```
pub fn lit_stencil_state() -> vk::StencilOpState {
    crate::gpu::pipeline::stencil_equal(0)
}
