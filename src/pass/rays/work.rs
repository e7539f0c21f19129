//! What a ray-query frame carries (its structures and bindings) and which hosts can take ray
//! query: the data the pass's recording ([`super::record`]) reads.

use super::push::RayPush;
use crate::error::{Error, Result};
use crate::gpu::accel::BlasJob;
use crate::pass::desc::{PassSettings, ShadowPassDesc, TargetModel, Technique};
use ash::vk;
use std::cell::Cell;

/// What a ray-query frame traces against ([`PreparedFrame::ray_query`](crate::pass::PreparedFrame::ray_query)).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayQueryFrame {
    /// World units the rays start off the surface (and stop short of a point light).
    pub offset: f32,
    /// Instances in the top level (one per caster, one for all sphere casters).
    pub instances: usize,
    /// Bytes of bottom-level storage (compacted where done).
    pub bottom_level_bytes: u64,
    /// Bottom levels this frame builds (new or first-deformed casters, a changed sphere set).
    pub builds: usize,
    /// Bottom levels this frame refits in place (deformed casters).
    pub refits: usize,
    /// Bottom levels this frame compacts.
    pub compactions: usize,
    /// Every light traced in one pass per 32 ([`PassToggles::ray_batch`](crate::pass::PassToggles::ray_batch)).
    pub batched: bool,
}

/// One frame's ray-query work: the jobs [`cmd_before_rendering`](super::ShadowPass::cmd_before_rendering)
/// records, and what `cmd_determine` binds.
#[derive(Debug)]
pub(crate) struct RayWork {
    pub(super) compactions: Vec<(vk::AccelerationStructureKHR, vk::AccelerationStructureKHR)>,
    pub(super) jobs: Vec<BlasJob>,
    pub(super) queries: Vec<(vk::QueryPool, vk::AccelerationStructureKHR)>,
    pub(super) instances: u32,
    pub(super) tlas_slot: usize,
    pub set: vk::DescriptorSet,
    pub layout: vk::PipelineLayout,
    pub pipeline: vk::Pipeline,
    /// Per light, the push constants.
    pub push: Vec<RayPush>,
    /// Bottom levels built in this frame.
    pub builds: usize,
    pub recorded: Cell<bool>,
    /// The offset the rays use (world units).
    pub offset: f32,
    /// Bytes of bottom-level storage.
    pub blas_bytes: u64,
    /// Every light in one pass per 32 ([`PassToggles::ray_batch`](crate::pass::PassToggles::ray_batch), two lights or more).
    pub batch: Option<super::batch::BatchFrame>,
}

impl RayWork {
    pub fn info(&self) -> RayQueryFrame {
        let refits = self.jobs.iter().filter(|j| j.is_refit()).count();
        RayQueryFrame {
            offset: self.offset,
            instances: self.instances as usize,
            bottom_level_bytes: self.blas_bytes,
            builds: self.builds,
            refits,
            compactions: self.compactions.len(),
            batched: self.batch.is_some(),
        }
    }
}

/// Refuses settings the host's configuration cannot take: ray query traces one ray per pixel
/// of a single-sample G-buffer, in the pass's own rendering instance.
pub(crate) fn check_host(settings: &PassSettings, desc: &ShadowPassDesc) -> Result<()> {
    if settings.technique != Technique::RayQuery {
        return Ok(());
    }
    if desc.samples > 1 {
        return Err(Error::Unsupported(format!(
            "Technique::RayQuery traces one ray per pixel from a single-sample G-buffer; the pass has {} samples (per-sample rays are not built)",
            desc.samples
        )));
    }
    if desc.target != TargetModel::DynamicRendering {
        return Err(Error::Unsupported(
            "Technique::RayQuery records in the pass's own rendering instance: TargetModel::DynamicRendering only (inside a host's render pass it is not built)".into(),
        ));
    }
    Ok(())
}
