//! The one list of every technique the benchmarks run: each volume method, edge quads,
//! planar projection and the shadow-map baseline at each size. A technique added to
//! [`Technique`] (the pass's) or a method added to [`Method`] fails to compile here until it is listed,
//! so new techniques join every bench (the default `umbrage bench` list and every point of the
//! suite) from this one place.

use umbrage::shadow::Method;
use umbrage_render::{CubeFaces, Pcf, RenderTechnique, ShadowMap, Technique};

/// Every volume method (the papers' case rules and the lecture notes' z-pass with clear).
pub fn volume_methods() -> Vec<Method> {
    // Exhaustive on purpose: a new Method variant is a compile error until listed below.
    let listed = |m: Method| match m {
        Method::ZPass | Method::ZFail | Method::EverittKilgard | Method::Lengyel | Method::McGuire | Method::ZPassClear => (),
    };
    let all = [Method::ZPass, Method::ZFail, Method::EverittKilgard, Method::Lengyel, Method::McGuire, Method::ZPassClear];
    all.iter().for_each(|&m| listed(m));
    all.to_vec()
}

/// Every technique, shadow maps once per size in `shadow_map_sizes` (none when empty; each
/// size twice, atlas and multiview cube faces, with `multiview`: a device whose multiview the
/// renderer trusts), and ray query when the device has it (`ray_query`:
/// [`umbrage::gpu::Features::ray_query`]), and mesh-shader extrusion when the device has mesh
/// shaders (`mesh_shader`: [`umbrage::gpu::Features::mesh_shader`]).
pub fn all_techniques(shadow_map_sizes: &[u32], ray_query: bool, multiview: bool, mesh_shader: bool) -> Vec<RenderTechnique> {
    let mut out: Vec<RenderTechnique> = volume_methods().into_iter().map(|m| Technique::Volumes(m).into()).collect();
    // Exhaustive on purpose: a new Technique variant is a compile error until listed below.
    let listed = |t: Technique| match t {
        Technique::Volumes(_) | Technique::EdgeQuads | Technique::Compute | Technique::Mesh | Technique::Planar | Technique::RayQuery => (),
    };
    for t in [Technique::EdgeQuads, Technique::Compute, Technique::Planar] {
        listed(t);
        out.push(t.into());
    }
    for &size in shadow_map_sizes {
        out.push(ShadowMap::new(size).into());
        if multiview {
            out.push(ShadowMap { size, pcf: Pcf::Taps, cube: CubeFaces::Multiview }.into());
        }
    }
    if mesh_shader {
        listed(Technique::Mesh);
        out.push(Technique::Mesh.into());
    }
    if ray_query {
        listed(Technique::RayQuery);
        out.push(Technique::RayQuery.into());
    }
    out
}

/// Whether a technique gives exact shadows by construction (the volume methods but z-pass,
/// z-pass with clear and planar are exact; shadow maps are approximations).
pub fn is_exact(t: RenderTechnique) -> bool {
    match t {
        RenderTechnique::Pass(Technique::Volumes(m)) => !matches!(m, Method::ZPass | Method::ZPassClear),
        RenderTechnique::Pass(Technique::EdgeQuads | Technique::Compute | Technique::Mesh | Technique::RayQuery) => true,
        RenderTechnique::Pass(Technique::Planar) | RenderTechnique::ShadowMap(_) => false,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    #[test]
    fn every_method_once() {
        let all = all_techniques(&[512, 4096], true, false, true);
        assert_eq!(all.len(), volume_methods().len() + 7);
        assert_eq!(all_techniques(&[512, 4096], true, true, false).len(), volume_methods().len() + 8);
        for (i, a) in all.iter().enumerate() {
            assert!(!all[i + 1..].contains(a), "{a:?} listed twice");
        }
        assert!(volume_methods().iter().all(|m| Method::ALL.contains(m) || *m == Method::ZPassClear));
    }
}
