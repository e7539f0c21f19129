//! The host's calls on analytic sphere casters ([`ShadowPass::add_sphere`] and the rest):
//! what they plan is [`super::spheres`].

use super::spheres::*;
use super::ShadowPass;
use crate::error::Result;

impl ShadowPass {
    /// Adds an analytic sphere caster (lecture notes §2.1): its volume is built every frame
    /// and light from the tangency circle as an n-gon circumscribed about it, `segments`
    /// fixing n (3..=4096) or `None` choosing it so the shadow's error stays under half a
    /// pixel. Opaque; drawn z-fail with its light cap, whatever the method (the polygon is
    /// flattened onto the receiver with [`Technique::Planar`](super::Technique::Planar)). A frame whose positional
    /// light is inside or on a sphere caster is refused by `prepare`.
    pub fn add_sphere_caster(&mut self, name: &str, sphere: crate::geom::Sphere, segments: Option<u32>) -> Result<SphereId> {
        check_sphere(name, &sphere, segments)?;
        let id = SphereId { pass: self.id, n: self.next_sphere };
        self.next_sphere += 1;
        self.spheres.push(SphereCaster { id, name: name.to_string(), sphere, segments });
        Ok(id)
    }

    /// Moves or resizes a sphere caster (from the next `prepare`).
    pub fn set_sphere(&mut self, id: SphereId, sphere: crate::geom::Sphere) -> Result<()> {
        let i = find(&self.spheres, self.id, id)?;
        check_sphere(&self.spheres[i].name, &sphere, self.spheres[i].segments)?;
        self.spheres[i].sphere = sphere;
        Ok(())
    }

    /// Removes a sphere caster (its volumes live in the per-frame stream: nothing to release).
    pub fn remove_sphere(&mut self, id: SphereId) -> Result<()> {
        let i = find(&self.spheres, self.id, id)?;
        self.spheres.remove(i);
        Ok(())
    }

    /// The sphere casters, in draw order.
    pub fn spheres(&self) -> impl Iterator<Item = SphereInfo<'_>> + '_ {
        self.spheres.iter().map(|s| SphereInfo { id: s.id, name: s.name.as_str(), sphere: s.sphere, segments: s.segments })
    }
}
