//! The techniques that keep GPU objects of their own beside the shadow pass: the shadow-map
//! baseline's maps and the ray tracer's acceleration structures, made when a frame first asks
//! for them and dropped when another technique runs.

use super::Renderer;
use crate::error::{Error, Result};
use crate::render::options::Technique;
use crate::render::raytrace::RayTracer;
use crate::render::shadowmap::ShadowMapper;

impl Renderer {
    /// Builds the ray tracer's bottom levels when ray query is first asked for, and keeps them
    /// (the renderer's meshes never change shape; their transforms reach the top level every
    /// frame), so a bench alternating techniques does not rebuild them.
    pub(super) fn update_ray_tracer(&mut self, technique: Technique) -> Result<()> {
        if technique == Technique::RayQuery && self.own.parts.ray_tracer.is_none() {
            let p = &self.own.parts;
            self.own.parts.ray_tracer = Some(RayTracer::new(&self.own.ctx, &p.scene, &p.targets, p.slots.len())?);
        }
        Ok(())
    }

    /// (Re)builds the shadow-map baseline when asked for, or when its size or the scene's
    /// placement changed; drops it when another technique runs.
    pub(super) fn update_shadow_mapper(&mut self, technique: Technique) -> Result<()> {
        let wanted = match technique {
            Technique::ShadowMap { size } => Some(size),
            _ => None,
        };
        let current = self.own.parts.shadow_mapper.as_ref().map(|(m, v)| (m.size, *v));
        if wanted.map(|s| (s, self.own.parts.scene_version)) == current {
            return Ok(());
        }
        if let Some((mut old, _)) = self.own.parts.shadow_mapper.take() {
            // SAFETY: waiting for idle before destroying objects a frame in flight may use.
            unsafe { self.own.ctx.device.device_wait_idle() }.map_err(Error::vk("vkDeviceWaitIdle"))?;
            old.destroy(&self.own.ctx);
        }
        if let Some(size) = wanted {
            let sm = ShadowMapper::new(&self.own.ctx, &self.own.parts.scene, &self.own.parts.targets, size, self.own.parts.pipes.sampler)?;
            self.own.parts.shadow_mapper = Some((sm, self.own.parts.scene_version));
        }
        Ok(())
    }
}
