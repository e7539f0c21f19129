//! Planar projected shadows ([`Technique::Planar`](super::Technique::Planar)): each caster
//! flattened onto the receiver plane from the light.

use super::casters::CasterTable;
use crate::geom::Light;
use crate::shadow::{self, Case, LightPlan, VolumePath};
use glam::DMat4;

/// Planar projected shadows: every drawn opaque caster's plan becomes all its triangles (w = 1
/// copies) in one z-pass list, and the matrix flattening world space onto the receiver plane
/// `p` from the light `L` is returned: `M = (p·L) I - L pᵀ`. Transparent casters, and every
/// caster when the light is not above the plane, are culled.
pub(crate) fn flatten(plan: &mut LightPlan, table: &CasterTable, light: &Light, p: glam::DVec4) -> DMat4 {
    let l = light.homogeneous().as_dvec4();
    let pl = p.dot(l);
    let m = DMat4::from_diagonal(glam::DVec4::splat(pl)) - DMat4::from_cols(l * p.x, l * p.y, l * p.z, l * p.w);
    for cp in &mut plan.casters {
        let caster = &table.cpu[cp.caster];
        if cp.case == Case::Culled || caster.transmittance.is_some() || !(pl > 0.0) {
            cp.case = Case::Culled;
            cp.chunks.clear();
            cp.parts.clear();
            cp.sides = 0;
            cp.dark_cap = 0;
            cp.light_cap = 0;
            continue;
        }
        cp.case = Case::ZPass;
        cp.path = VolumePath::Planar;
        cp.parts.clear();
        cp.silhouette_edges = 0;
        cp.dark_cap = 0;
        cp.light_cap = 0;
        cp.dark_cap_kind = shadow::DarkCap::None;
        cp.chunks = caster
            .chunks
            .iter()
            .enumerate()
            .map(|(ci, ch)| shadow::ChunkDraw {
                chunk: ci,
                case: Case::ZPass,
                volume: ch.local_tris.iter().flatten().copied().collect(),
                light_cap: Vec::new(),
            })
            .collect();
        cp.sides = caster.chunks.iter().map(|c| c.local_tris.len()).sum();
    }
    m
}

/// [`Technique::Planar`](super::Technique::Planar)'s state: the receiver plane
/// ([`ShadowPass::set_planar_receiver`](super::ShadowPass::set_planar_receiver)).
pub(super) struct PlanarState {
    /// `n·x + d = 0` as `(n, d)`, `n` towards the light's side.
    pub receiver: glam::DVec4,
}

impl Default for PlanarState {
    /// y = 0, up.
    fn default() -> Self {
        PlanarState { receiver: glam::DVec4::Y }
    }
}

impl super::device::TechniqueState for PlanarState {
    fn destroy(&mut self, _dev: &super::device::PassDevice) {}
}
