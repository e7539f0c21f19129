//! Beyond the CTS, where shadow volumes need it: four case families the Vulkan CTS has no
//! equivalent of (see docs/conform/cts-mapping.md, "Beyond the CTS").
//!
//! - `wrap.*` (module `wrap`): hundreds of two-sided faces through one tile, front INCR_WRAP /
//!   back DECR_WRAP as shadow volumes count, so the 8-bit count wraps many times and must come
//!   back exactly to `(N - M) mod 256` (the CTS steps one or two values past a wrap point).
//! - `clip.*` (module `clip`): homogeneous clipping of triangles with vertices behind the eye
//!   (`w < 0`), exactly at `w = 0`, crossing the near and far planes with and without depth
//!   clamp, and infinite-projection side quads extruded behind the eye (the CTS never draws
//!   `w <= 0` vertices, and no infinite projections).
//! - `watertight.*` (module `watertight`): closed meshes and fans at object coordinates of 1e7,
//!   split across separate draws in shuffled order: every pixel inside the outline counted
//!   exactly once per layer (the CTS checks watertightness only on two-triangle quads).
//! - `occlusion.*` (module `occlusion`): precise occlusion-query counts of seeded random large,
//!   thin and sub-pixel triangles in both windings, against the model's count of covered
//!   pixel centres.
//!
//! Every case is judged by the CPU model ([`super::super::model`]) except the watertight ones,
//! whose guaranteed result is given directly ([`Case::stencil_override`]).

mod clip;
mod occlusion;
mod watertight;
mod wrap;

#[cfg(test)]
mod tests;

use super::{Case, Config, DsState};
use ash::vk;

/// SplitMix64: a tiny seeded generator, so every case's geometry is the same on every run.
#[derive(Clone, Debug)]
pub(crate) struct Rng(u64);

impl Rng {
    pub(crate) fn new(seed: u64) -> Rng {
        Rng(seed)
    }
    pub(crate) fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }
    /// Uniform in [lo, hi).
    pub(crate) fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * ((self.next_u64() >> 11) as f64 / (1u64 << 53) as f64)
    }
    /// Uniform integer in [0, n).
    pub(crate) fn below(&mut self, n: usize) -> usize {
        (self.next_u64() % n as u64) as usize
    }
    /// Fisher-Yates.
    pub(crate) fn shuffle<T>(&mut self, v: &mut [T]) {
        for i in (1..v.len()).rev() {
            v.swap(i, self.below(i + 1));
        }
    }
}

/// One face's stencil state: `pass` on pass, KEEP otherwise, compare ALWAYS, masks 0xff.
fn face(pass: vk::StencilOp) -> vk::StencilOpState {
    umbrage::gpu::pipeline::stencil_ops(pass, vk::StencilOp::KEEP)
}

/// Shadow-volume counting: front faces INCR_WRAP, back faces DECR_WRAP (the zoo's two-sided
/// state, so static-state configurations share its pipeline).
fn two_sided() -> (vk::StencilOpState, vk::StencilOpState) {
    (face(vk::StencilOp::INCREMENT_AND_WRAP), face(vk::StencilOp::DECREMENT_AND_WRAP))
}

/// Both faces INCR_WRAP (the raster cases' counting state).
fn incr_both() -> (vk::StencilOpState, vk::StencilOpState) {
    (face(vk::StencilOp::INCREMENT_AND_WRAP), face(vk::StencilOp::INCREMENT_AND_WRAP))
}

/// Stencil only, no depth test.
fn stencil_only(s: (vk::StencilOpState, vk::StencilOpState)) -> DsState {
    DsState { stencil: Some(s), ..Default::default() }
}

/// The group names of this module's families.
pub const GROUPS: [&str; 4] = ["wrap", "clip", "watertight", "occlusion"];

/// Every case of the four families for `config`.
pub fn cases(config: Config) -> Vec<Case> {
    let mut v = wrap::cases(config);
    v.extend(clip::cases(config));
    v.extend(watertight::cases(config));
    v.extend(occlusion::cases(config));
    v
}
