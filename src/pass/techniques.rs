//! Each technique's own state, in one registry: the pipelines it makes (with its first frame
//! or [`ShadowPass::create_pipelines`](super::ShadowPass::create_pipelines)), the objects its
//! frames use per ring slot, and how both are released. What every technique shares (the
//! casters, the ring slots' streams and staging, the lights, the targets, the uploads and the
//! kept plans) stays in [`ShadowPass`](super::ShadowPass).
//!
//! Adding a technique: its module, its state type implementing [`TechniqueState`] (in [`super::device`], below every technique), and one
//! field here (with its line in [`Techniques::all`]). The per-frame recording reads each
//! state directly: no dynamic dispatch is added to the hot path.

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
