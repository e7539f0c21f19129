//! What moves between frames: the camera, the lights, the meshes. Nothing is re-created; the
//! next frame plans with the new state.

use super::Renderer;
use glam::{Mat4, Vec3};
use umbrage::error::{Error, Result};
use umbrage_scene::{Camera, Light};

impl Renderer {
    /// Moves the camera (from the next frame).
    pub fn set_camera(&mut self, camera: Camera) -> Result<()> {
        if !(camera.eye.is_finite() && camera.target.is_finite() && camera.up.is_finite()) || camera.eye == camera.target {
            return Err(Error::argument("camera", format!("invalid camera {camera:?}")));
        }
        self.own.parts.scene.camera = camera;
        self.own.parts.scene_version += 1;
        Ok(())
    }
    /// Replaces the lights (any number; from the next frame). Area lights are split into
    /// their samples ([`umbrage::geom::area`]); an invalid area light is an error and changes
    /// nothing. The accumulation target's format was chosen at creation (RGBA32F if the scene
    /// had area lights then): area lights added to a scene created without any sum in RGBA16F.
    pub fn set_lights(&mut self, lights: Vec<Light>) -> Result<()> {
        let lights = super::area::checked_lights(&lights)?;
        self.own.parts.scene.lights = umbrage::geom::area::expand_lights(&lights, self.own.parts.samples_for);
        self.own.parts.source_lights = lights;
        self.own.parts.scene_version += 1;
        Ok(())
    }
    /// Moves mesh `index` (object -> world; from the next frame). A transform must keep the
    /// mesh's handedness (its winding was fixed at load).
    pub fn set_mesh_transform(&mut self, index: usize, transform: Mat4) -> Result<()> {
        let m = self.own.parts.scene.meshes.get(index).ok_or_else(|| Error::argument("mesh index", format!("no mesh {index}")))?;
        let det = transform.determinant();
        if !(transform.is_finite() && det.is_finite() && det != 0.0) {
            return Err(Error::mesh(&m.name, "transform is not finite or singular"));
        }
        if (det < 0.0) != (m.transform.determinant() < 0.0) {
            return Err(Error::mesh(&m.name, "a new transform may not mirror a mesh that was loaded unmirrored (or the reverse)"));
        }
        if let Some(id) = self.own.parts.caster_ids[index] {
            self.own.parts.pass.set_transform(id, transform.as_dmat4())?;
        }
        self.own.parts.scene.meshes[index].transform = transform;
        self.own.parts.scene_version += 1;
        Ok(())
    }

    /// New object-space positions for mesh `index` (a skinned or cloth mesh: the same vertices,
    /// in the order it was loaded with, and the same triangles), from the next frame.
    ///
    /// The shadow pass rebuilds its caster ([`ShadowPass::update_positions`](umbrage::pass::ShadowPass::update_positions):
    /// new silhouette tables for the volumes; with ray query its bottom level is rebuilt once with
    /// `ALLOW_UPDATE`, then refitted in place). The drawn geometry is baked again, after waiting
    /// for the device: frames in flight are dropped (their tickets fail in
    /// [`finish`](Renderer::finish)). On error nothing changes.
    pub fn set_mesh_positions(&mut self, index: usize, positions: &[Vec3]) -> Result<()> {
        let parts = &mut self.own.parts;
        let m = parts.scene.meshes.get(index).ok_or_else(|| Error::argument("mesh index", format!("no mesh {index}")))?;
        if positions.len() != m.mesh.positions.len() {
            return Err(Error::mesh(&m.name, format!("{} positions for a mesh of {} vertices", positions.len(), m.mesh.positions.len())));
        }
        if let Some(k) = positions.iter().position(|p| !p.is_finite()) {
            return Err(Error::mesh(&m.name, format!("vertex {k} is not finite ({:?})", positions[k])));
        }
        let ctx = &self.own.ctx;
        // SAFETY: waiting for every submission before the old geometry is destroyed.
        unsafe { ctx.device.device_wait_idle() }.map_err(Error::vk("vkDeviceWaitIdle"))?;
        for s in &mut parts.slots {
            s.in_flight = None;
        }
        let old = std::mem::replace(&mut parts.scene.meshes[index].mesh.positions, positions.to_vec());
        let restore = |parts: &mut super::Parts, old: Vec<Vec3>| parts.scene.meshes[index].mesh.positions = old;
        let mut geo = match crate::scene_gpu::SceneGeometry::new(ctx, &parts.scene, parts.slots.len()) {
            Ok(g) => g,
            Err(e) => {
                restore(parts, old);
                return Err(e);
            }
        };
        if let Some(id) = parts.caster_ids[index] {
            if let Err(e) = parts.pass.update_positions(id, positions) {
                geo.destroy(ctx);
                restore(parts, old);
                return Err(e);
            }
        }
        std::mem::swap(&mut parts.geo, &mut geo);
        geo.destroy(ctx);
        parts.scene_version += 1;
        Ok(())
    }
}
