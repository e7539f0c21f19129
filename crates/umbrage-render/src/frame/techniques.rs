//! The techniques that need more than the shadow pass's volumes: the shadow-map baseline's
//! maps (GPU objects of its own, made when a frame first asks for them and set aside when
//! another technique runs), and the inputs of the pass's ray query (the G-buffer and the CPU
//! reference's surface offset).

use super::Renderer;
use crate::options::Technique;
use crate::shadowmap::ShadowMapper;
use crate::technique::RenderTechnique;
use glam::DVec3;
use umbrage::error::{Error, Result};
use umbrage_scene::Scene;

impl Renderer {
    /// Points the pass's ray query at this frame's G-buffer, with the CPU reference's surface
    /// offset (2e-5 of the scene's diagonal, recomputed when the scene moved). The pass keeps
    /// its acceleration structures across frames and techniques, so a bench alternating
    /// techniques does not rebuild them.
    pub(super) fn update_ray_inputs(&mut self, technique: RenderTechnique) -> Result<()> {
        if technique != RenderTechnique::Pass(Technique::RayQuery) {
            return Ok(());
        }
        let p = &mut self.own.parts;
        let version = p.scene_version;
        let offset = match p.ray_offset {
            Some((v, o)) if v == version => o,
            _ => {
                let o = (2e-5 * scene_size(&p.scene)) as f32;
                p.ray_offset = Some((version, o));
                o
            }
        };
        let inputs =
            umbrage::pass::RayQueryInputs { position: p.targets.position.view, normal: p.targets.normal.view, surface_offset: offset };
        p.pass.set_ray_query_inputs(inputs)
    }

    /// Makes the shadow-map baseline of the asked size and cube layout current (built, or taken from the
    /// kept ones when built for the scene's placement now), and sets it aside when another
    /// technique runs; baselines built for an older placement are destroyed.
    pub(super) fn update_shadow_mapper(&mut self, technique: RenderTechnique) -> Result<()> {
        let wanted = technique.shadow_map().map(|m| (m.size, m.cube));
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

/// Why `scene` cannot be traced yet, if it cannot.
pub(super) fn ray_query_unsupported(scene: &Scene) -> Option<String> {
    if scene.meshes.iter().any(|m| m.casts_shadow && m.opacity < 1.0) {
        return Some("--method rayquery does not trace transparent casters yet (their coloured shadows need the light-intensity map); use a shadow-volume method".into());
    }
    None
}

/// The diagonal of the bounds of every scene triangle and sphere (the CPU reference's
/// `scene_size`).
fn scene_size(scene: &Scene) -> f64 {
    let mut lo = DVec3::splat(f64::INFINITY);
    let mut hi = DVec3::splat(f64::NEG_INFINITY);
    for m in &scene.meshes {
        let b = m.world_bounds();
        if b.min.x <= b.max.x {
            lo = lo.min(b.min.as_dvec3());
            hi = hi.max(b.max.as_dvec3());
        }
    }
    for s in &scene.spheres {
        lo = lo.min(s.sphere.center - s.sphere.radius);
        hi = hi.max(s.sphere.center + s.sphere.radius);
    }
    if lo.x <= hi.x {
        (hi - lo).length()
    } else {
        1.0
    }
}
