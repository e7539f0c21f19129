//! What moves between frames: the camera, the lights, the meshes. Nothing is re-created; the
//! next frame plans with the new state.

use super::Renderer;
use crate::error::{Error, Result};
use crate::scene::{Camera, Light};
use glam::Mat4;

impl Renderer {
    /// Moves the camera (from the next frame).
    pub fn set_camera(&mut self, camera: Camera) -> Result<()> {
        if !(camera.eye.is_finite() && camera.target.is_finite() && camera.up.is_finite()) || camera.eye == camera.target {
            return Err(Error::Other(format!("invalid camera {camera:?}")));
        }
        self.own.parts.scene.camera = camera;
        self.own.parts.scene_version += 1;
        Ok(())
    }
    /// Replaces the lights (any number; from the next frame). Area lights are split into
    /// their samples ([`crate::geom::area`]); an invalid area light is an error and changes
    /// nothing. The accumulation target's format was chosen at creation (RGBA32F if the scene
    /// had area lights then): area lights added to a scene created without any sum in RGBA16F.
    pub fn set_lights(&mut self, lights: Vec<Light>) -> Result<()> {
        let lights = super::area::checked_lights(&lights)?;
        self.own.parts.scene.lights = crate::geom::area::expand_lights(&lights, self.own.parts.samples_for);
        self.own.parts.source_lights = lights;
        self.own.parts.scene_version += 1;
        Ok(())
    }
    /// Moves mesh `index` (object -> world; from the next frame). A transform must keep the
    /// mesh's handedness (its winding was fixed at load).
    pub fn set_mesh_transform(&mut self, index: usize, transform: Mat4) -> Result<()> {
        let m = self.own.parts.scene.meshes.get(index).ok_or_else(|| Error::Other(format!("no mesh {index}")))?;
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
}
