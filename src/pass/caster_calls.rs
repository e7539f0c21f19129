//! The host's calls on casters ([`ShadowPass::add_caster`] and the rest): the table they
//! change is [`super::casters`].

use super::casters::*;
use super::ShadowPass;
use crate::error::{Misuse, Result};
use crate::geom::Mesh;
use crate::shadow::{Caster, CasterKind};
use glam::{DMat4, Vec3};

impl ShadowPass {
    /// The prepared casters, in draw order (the planner's view).
    pub fn casters(&self) -> &[Caster] {
        &self.casters.cpu
    }

    /// The id of the caster at `index` of [`casters`](Self::casters).
    pub fn caster_id(&self, index: usize) -> Option<CasterId> {
        self.casters.live.get(index).map(|c| c.id)
    }

    /// Whether a caster is on the multiplicity path (open, non-manifold or transparent).
    pub fn caster_kind(&self, id: CasterId) -> Result<&CasterKind> {
        Ok(&self.casters.cpu[self.casters.find(id)?].kind)
    }

    /// Adds an opaque caster: the mesh is validated (NaN, empty), welded, classified (closed
    /// 2-manifold: McGuire's three cases; anything else: Kim et al.'s multiplicities) and
    /// split into chunks of at most 32768 vertices (16-bit indices), never refused for size.
    /// Its vertex buffers are copied by the next frame's [`cmd_before_rendering`](Self::cmd_before_rendering).
    ///
    /// ```no_run
    /// # use umbrage::pass::*; use glam::{DMat4, DVec3, Vec3};
    /// # fn f(pass: &mut ShadowPass) -> umbrage::Result<()> {
    /// let tetrahedron = umbrage::geom::Mesh {
    ///     positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z],
    ///     triangles: vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
    /// };
    /// // Once per mesh: its silhouette tables and dual-length vertex buffer are built here.
    /// let id = pass.add_caster("tetrahedron", &tetrahedron, DMat4::from_translation(DVec3::Y))?;
    /// # let _ = id; Ok(()) }
    /// ```
    pub fn add_caster(&mut self, name: &str, mesh: &Mesh, transform: DMat4) -> Result<CasterId> {
        check_transform(name, &transform)?;
        let caster = Caster::new(name, mesh, transform.as_mat4())?;
        self.casters.add(&self.dev, caster, transform)
    }

    /// Adds a transparent caster letting `transmittance` (RGB, per surface crossed) through:
    /// it always takes the multiplicity path, and its volumes go to the light-intensity map
    /// ([`VolumeKind::Transmit`](super::VolumeKind::Transmit)), not the opaque count. Needs [`ShadowPassDesc::transmit_format`](super::ShadowPassDesc::transmit_format).
    pub fn add_transparent_caster(&mut self, name: &str, mesh: &Mesh, transform: DMat4, transmittance: Vec3) -> Result<CasterId> {
        if self.pipes.transmit.is_none() {
            return Err(Misuse::NotConfigured { call: "add_transparent_caster", needs: "ShadowPassDesc::transmit_format" }.into());
        }
        check_transmittance(name, transmittance)?;
        check_transform(name, &transform)?;
        let caster = Caster::new(name, mesh, transform.as_mat4())?.into_transparent(transmittance);
        self.casters.add(&self.dev, caster, transform)
    }

    /// Adds a caster prepared by the caller (e.g. `umbrage_scene::SceneMesh::caster`, or [`Caster::new`] then [`Caster::into_transparent`]).
    pub fn add_prepared_caster(&mut self, caster: Caster, transform: DMat4) -> Result<CasterId> {
        check_transform(&caster.name, &transform)?;
        if let Some(t) = caster.transmittance {
            check_transmittance(&caster.name, t)?;
        }
        if caster.transmittance.is_some() && self.pipes.transmit.is_none() {
            return Err(Misuse::NotConfigured {
                call: "add_prepared_caster (a transparent caster)",
                needs: "ShadowPassDesc::transmit_format",
            }
            .into());
        }
        self.casters.add(&self.dev, caster, transform)
    }

    /// Moves a caster (object -> world, f64): takes effect from the next `prepare`; nothing is
    /// re-created.
    ///
    /// ```no_run
    /// # use umbrage::pass::*; use glam::{DMat4, DQuat, DVec3};
    /// # fn f(pass: &mut ShadowPass, id: CasterId, t: f64) -> umbrage::Result<()> {
    /// // Between frames: nothing is re-created, the next `prepare` plans from the new pose.
    /// pass.set_transform(id, DMat4::from_rotation_translation(DQuat::from_rotation_y(t), DVec3::new(t, 0.5, 0.0)))?;
    /// # Ok(()) }
    /// ```
    pub fn set_transform(&mut self, id: CasterId, transform: DMat4) -> Result<()> {
        let i = self.casters.find(id)?;
        check_transform(&self.casters.cpu[i].name, &transform)?;
        self.casters.cpu[i].set_transform(transform.as_mat4());
        self.casters.live[i].transform = transform;
        self.casters.live[i].pose += 1;
        Ok(())
    }

    /// New object-space positions for a deforming caster: the same vertices (in the order of
    /// the mesh it was added with) and triangles. The new dual-length copies are uploaded by
    /// the next frame; the old ones are released once the frames in flight have retired.
    ///
    /// ```no_run
    /// # use umbrage::pass::*; use glam::Vec3;
    /// # fn f(pass: &mut ShadowPass, id: CasterId, skinned: &[Vec3]) -> umbrage::Result<()> {
    /// // A deforming caster (skinning, cloth): same vertex count and triangles, new positions.
    /// pass.update_positions(id, skinned)?;
    /// # Ok(()) }
    /// ```
    pub fn update_positions(&mut self, id: CasterId, positions: &[Vec3]) -> Result<()> {
        let all = self.all_slots();
        self.casters.update_positions(&self.dev, id, positions, all)
    }

    /// Removes a caster; its buffers are released once every frame in flight that may use
    /// them has retired.
    ///
    /// ```no_run
    /// # use umbrage::pass::*;
    /// # fn f(pass: &mut ShadowPass, id: CasterId) -> umbrage::Result<()> {
    /// pass.remove_caster(id)?; // its buffers go once every frame in flight has retired
    /// assert!(pass.set_transform(id, glam::DMat4::IDENTITY).is_err()); // the id is dead
    /// # Ok(()) }
    /// ```
    pub fn remove_caster(&mut self, id: CasterId) -> Result<()> {
        let all = self.all_slots();
        self.casters.remove(id, all)
    }
}
