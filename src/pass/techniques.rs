//! Each technique's own state, in one registry: the pipelines it makes (with its first frame
//! or [`ShadowPass::create_pipelines`](super::ShadowPass::create_pipelines)), the objects its
//! frames use per ring slot, and how both are released. What every technique shares (the
//! casters, the ring slots' streams and staging, the lights, the targets, the uploads and the
//! kept plans) stays in [`ShadowPass`](super::ShadowPass).
//!
//! Each technique also records its own draws of a light: `cmd_draw_volumes` (`draw_volumes.rs`)
//! hands the light to the frame's technique, once per light (an enum match: nothing per draw
//! is added to the hot path): the CPU-planned volumes and planar shadows in `volumes.rs`,
//! edge quads in `edge_quads.rs`, mesh draws in `mesh_record.rs`, the compute technique's in
//! `compute/draws_record.rs`; each falls back on `record_planned_draw` for the parts the
//! planner leaves on the CPU.
//!
//! Adding a technique: its module, its state type implementing [`TechniqueState`] (in
//! [`super::device`], below every technique), one field here (with its line in
//! [`Techniques::all`]), and its arm in `cmd_draw_volumes`.

use super::compute::ComputeState;
use super::device::{PassDevice, TechniqueState};
use super::mesh_pipes::MeshState;
use super::planar::PlanarState;
use super::rays::RayState;

/// The registry: one field per technique with state of its own.
pub(super) struct Techniques {
    /// [`Technique::Planar`](super::Technique::Planar): the receiver plane.
    pub planar: PlanarState,
    /// The GPU possible silhouettes of [`Technique::Compute`](super::Technique::Compute) and
    /// [`Technique::Mesh`](super::Technique::Mesh): pipelines, merged draws, per-slot buffers.
    pub compute: ComputeState,
    /// [`Technique::Mesh`](super::Technique::Mesh)'s extrusion pipelines.
    pub mesh: MeshState,
    /// [`Technique::RayQuery`](super::Technique::RayQuery)'s structures and G-buffer inputs.
    pub rays: RayState,
}

impl Techniques {
    /// No technique's objects yet (each makes them with its first frame), for a ring of
    /// `slots` slots.
    pub fn new(slots: usize) -> Techniques {
        Techniques {
            planar: PlanarState::default(),
            compute: ComputeState::new(slots),
            mesh: MeshState::default(),
            rays: RayState::default(),
        }
    }

    fn all(&mut self) -> [&mut dyn TechniqueState; 4] {
        [&mut self.planar, &mut self.compute, &mut self.mesh, &mut self.rays]
    }

    /// [`TechniqueState::slot_retired`] for every technique.
    pub fn slot_retired(&mut self, dev: &PassDevice, slot: usize) {
        for t in self.all() {
            t.slot_retired(dev, slot);
        }
    }

    /// [`TechniqueState::destroy`] for every technique.
    pub fn destroy(&mut self, dev: &PassDevice) {
        for t in self.all() {
            t.destroy(dev);
        }
    }
}
