//! One frame's CPU work as the host holds it ([`PreparedFrame`]), and the checks around it
//! (lights the planner can use, 8-bit stencil overflow). Planning and packing are in
//! `pack`, planar projection in `planar`, the draws in `draw`, the camera in `view`.

use super::casters::{CasterTable, Upload};
use super::compute::work::ComputeWork;
use super::desc::{Counter, PassSettings};
use super::draw::LightFrame;
use super::stats::{CpuMs, Totals};
use crate::error::{Error, Result};
use crate::geom::{Light, LightKind};
use crate::shadow::Case;
use ash::vk;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

/// The CPU work of one frame ([`ShadowPass::prepare`](super::ShadowPass::prepare)): what the
/// recording calls draw. It refers to buffers of ring slot [`slot`](Self::slot), valid until
/// that slot is prepared again.
#[derive(Debug)]
pub struct PreparedFrame {
    /// The id of the pass that prepared it.
    pub(crate) pass: u64,
    pub(crate) slot: usize,
    pub(crate) serial: u64,
    pub(crate) stream: vk::Buffer,
    pub(crate) uploads: Vec<Upload>,
    /// Shared with the pass's slot: set once the copies are recorded (the pass then counts
    /// them delivered when the slot is prepared again), cleared by `abandon_frame`.
    pub(crate) uploads_recorded: Arc<AtomicBool>,
    /// Per light, in the order given to `prepare`.
    pub lights: Vec<LightFrame>,
    /// Totals over all lights (triangles, bytes, cases).
    pub totals: Totals,
    /// CPU time of this frame's planning (the recording adds `record` on the host's side).
    pub cpu_ms: CpuMs,
    /// The settings the frame was prepared with.
    pub settings: PassSettings,
    /// Things the host should tell its user (e.g. a possible 8-bit stencil overflow).
    pub warnings: Vec<String>,
    pub(crate) extent: vk::Extent2D,
    /// The GPU silhouettes of [`Technique::Compute`] (counts read back by
    /// [`ShadowPass::read_back_counts`](super::ShadowPass::read_back_counts)).
    pub(crate) compute: Option<ComputeWork>,
    /// [`Technique::RayQuery`](super::Technique::RayQuery)'s structures and bindings.
    pub(crate) rays: Option<super::rays::work::RayWork>,
}

impl PreparedFrame {
    /// What a ray-query frame traces against (`None` for the other techniques).
    pub fn ray_query(&self) -> Option<super::rays::work::RayQueryFrame> {
        self.rays.as_ref().map(|r| r.info())
    }
    /// The ring slot this frame uses.
    pub fn slot(&self) -> usize {
        self.slot
    }
    /// The target size the frame was prepared for.
    pub fn extent(&self) -> vk::Extent2D {
        self.extent
    }
    /// How many frames were prepared before this one.
    pub fn serial(&self) -> u64 {
        self.serial
    }
    /// Caster buffers this frame must copy before any volume is drawn (recorded by
    /// [`ShadowPass::cmd_upload`](super::ShadowPass::cmd_upload)).
    pub fn pending_uploads(&self) -> usize {
        if self.uploads_recorded.load(Ordering::Acquire) {
            0
        } else {
            self.uploads.len()
        }
    }
}

/// 8-bit stencil counts wrap at 256: a pixel inside a multiple of 256 volumes reads as lit.
/// Flags lights whose drawn casters could nest that deep (a heuristic: one caster folding 256
/// times over itself is not detected).
pub(crate) fn overflow_warnings(table: &CasterTable, lights: &[LightFrame], counter: Counter) -> Vec<String> {
    let mut warnings = Vec::new();
    if counter != Counter::Stencil {
        return warnings;
    }
    for (li, l) in lights.iter().enumerate() {
        let drawn: usize = l.plan.casters.iter().filter(|c| c.case != Case::Culled).map(|c| table.live[c.caster].shells).sum();
        if drawn > 255 {
            warnings.push(format!(
                "light {li}: {drawn} closed shells cast shadow volumes; pixels inside 256k of them wrap to 0 in the 8-bit stencil and read as lit (Counter::Float counts exactly)"
            ));
        }
    }
    warnings
}

/// Rejects lights the planner cannot use (NaN or infinite values, a zero direction).
pub(crate) fn check_lights(lights: &[Light]) -> Result<()> {
    lights.iter().enumerate().try_for_each(|(i, l)| check_light(i, l))
}

/// The largest full cone angle of a spot light, degrees (every direction).
pub const MAX_CONE_DEG: f32 = 360.0;

/// One light against the ranges `docs/contract.md` lists: every error is
/// [`Misuse::Argument`](crate::error::Misuse::Argument) naming the field (`Light::radius`) and
/// the light's index.
fn check_light(i: usize, l: &Light) -> Result<()> {
    let bad = |field: &'static str, msg: String| Err(Error::argument(field, format!("light {i}: {msg}")));
    if l.area.is_some() {
        return bad(
            "Light::area",
            "an area light: the pass determines point, spot and directional lights; expand it into its point-light \
             samples first (geom::area::expand_lights), one determination and lighting pass each"
                .into(),
        );
    }
    if !l.position.is_finite() {
        return bad("Light::position", format!("{} is not finite", l.position));
    }
    if !l.direction.is_finite() {
        return bad("Light::direction", format!("{} is not finite", l.direction));
    }
    if l.kind != LightKind::Point && !(l.direction.length_squared() > 0.0) {
        return bad("Light::direction", format!("a {:?} light needs a non-zero direction, got {}", l.kind, l.direction));
    }
    if !(l.color.is_finite() && l.color.min_element() >= 0.0) {
        return bad("Light::color", format!("{} is not finite and non-negative", l.color));
    }
    if !(l.intensity.is_finite() && l.intensity >= 0.0) {
        return bad("Light::intensity", format!("{} is not finite and non-negative", l.intensity));
    }
    if let Some(r) = l.radius {
        if !(r.is_finite() && r > 0.0) {
            return bad("Light::radius", format!("{r} is not finite and positive (None: the light reaches everything)"));
        }
    }
    if l.kind == LightKind::Spot && !(l.cone_deg > 0.0 && l.cone_deg <= MAX_CONE_DEG) {
        return bad(
            "Light::cone_deg",
            format!("a spot light's full cone angle must be in (0, {MAX_CONE_DEG}] degrees, got {}", l.cone_deg),
        );
    }
    Ok(())
}
