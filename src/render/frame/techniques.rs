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

    /// Makes the shadow-map baseline of the asked size and cube layout current (built, or taken from the
    /// kept ones when built for the scene's placement now), and sets it aside when another
    /// technique runs; baselines built for an older placement are destroyed.
    pub(super) fn update_shadow_mapper(&mut self, technique: Technique) -> Result<()> {
        let wanted = match technique {
            Technique::ShadowMap { size, cube, .. } => Some((size, cube)),
            _ => None,
        };
        let version = self.own.parts.scene_version;
        let parts = &mut self.own.parts;
        let current = parts.shadow_mapper.as_ref().map(|(m, v)| ((m.size, m.cube), *v));
        if wanted.map(|s| (s, version)) == current {
            return Ok(());
        }
        if let Some(old) = parts.shadow_mapper.take() {
            parts.spare_shadow_mappers.push(old);
        }
        if parts.spare_shadow_mappers.iter().any(|(_, v)| *v != version) {
            // SAFETY: waiting for idle before destroying objects a frame in flight may use.
            unsafe { self.own.ctx.device.device_wait_idle() }.map_err(Error::vk("vkDeviceWaitIdle"))?;
            let (stale, kept): (Vec<_>, Vec<_>) =
                std::mem::take(&mut parts.spare_shadow_mappers).into_iter().partition(|(_, v)| *v != version);
            parts.spare_shadow_mappers = kept;
            for (mut sm, _) in stale {
                sm.destroy(&self.own.ctx);
            }
        }
        if let Some(key) = wanted {
            if let Some(i) = parts.spare_shadow_mappers.iter().position(|(m, _)| (m.size, m.cube) == key) {
                parts.shadow_mapper = Some(parts.spare_shadow_mappers.swap_remove(i));
            } else {
                let sm = ShadowMapper::new(&self.own.ctx, &parts.scene, &parts.targets, key, parts.pipes.sampler)?;
                parts.shadow_mapper = Some((sm, version));
            }
        }
        Ok(())
    }
}
