//! `mesh.*`: the mesh-shader family — what `--method mesh` (`shaders/extrude.wgsl`,
//! `vkCmdDrawMeshTasksEXT`) relies on of `VK_EXT_mesh_shader`, each check drawn by
//! `shaders/conform_mesh.wgsl` into a depth-stencil image of the renderer's format and compared
//! pixel for pixel (stencil, and depth where the spec makes it exact) with a CPU model, and the
//! words the shaders record with atomics compared word for word.
//!
//! - `w0_vertices`: vertices at infinity out of a mesh stage, placed by extrude.wgsl's own
//!   expressions: dark caps (every vertex w = 0 through the infinite projection: depth exactly
//!   1.0), side quads whose far vertices land at clip w = 0 exactly (handed to the driver as
//!   they are, and as extrude's near-zero w), side quads whose far vertices point behind the eye
//!   (clip w < 0), with depth clamp off and, where the device has `depthClamp`, on. Front
//!   INCR_WRAP / back DECR_WRAP over 0x80: coverage and facing against the CPU model, which
//!   clips in f64.
//! - `watertight_meshlets`: the shadow volume of a closed caster (a 120-triangle gear-shaped
//!   sphere) split into 24 meshlets, a workgroup each, launched as 6 x 4 groups, built as
//!   extrude.wgsl builds it (facing per triangle from the same words in every meshlet, caps of
//!   the light-facing triangles, a side quad per silhouette edge from the meshlet that owns
//!   it); every meshlet shares the poles, so fans of caps and side quads around one vertex
//!   come from several workgroups. Front INCR_WRAP / back DECR_WRAP must leave every pixel
//!   exactly at its start (no crack, no double hit, the volume is closed); INCR_WRAP on both
//!   faces gives each pixel its count of volume triangles (the model's); then the same volume
//!   through a task stage that keeps only the meshlets that emit anything.
//! - `group_counts`: `vkCmdDrawMeshTasksEXT` with (7, 3, 2) groups (each workgroup once with
//!   its workgroup_id, num_workgroups and every local index, one pixel tile each), (0, 1, 1)
//!   and (2, 0, 1) (nothing), and (65535, 1, 1), the most one draw of `--method mesh` launches.
//! - `task_payload`: (4, 3, 1) task workgroups launching a varying number of mesh workgroups
//!   (0 to 9, 2D) with a payload every task invocation wrote: each mesh workgroup once, with
//!   the payload as written and its own num_workgroups.
//!
//! On a device without `VK_EXT_mesh_shader` (Mesa lavapipe before 25, SwiftShader) every check
//! is reported skipped as unsupported, naming the extension and where to get a driver with it.
//!
//! Why a CPU model and not the same triangles through the vertex pipeline: the spec's
//! invariance rules (appendix "Invariance") require identical results only for the same
//! command on the same state; a mesh pipeline and a vertex pipeline are different state, so
//! equal pictures are strongly suggested, not guaranteed. What the spec does guarantee is
//! polygon rasterisation of the primitive the clipped vertices define: the model computes
//! every clip-space vertex exactly (inputs chosen so that every partial sum is a float, so
//! the device's f32 arithmetic, with or without fused multiply-adds, gives the same bits) and
//! leaves out only pixel centres within 1.5 sub-pixel steps of an edge (the window divide and
//! the clipper round). `w0_vertices` also draws the same clip-space vertices through the
//! vertex pipeline and reports how many pixels differ, as a measurement, not a verdict.

mod launch;
mod rig;
mod volume;
mod w0;

pub use launch::{group_counts, task_payload};
pub use volume::watertight_meshlets;
pub use w0::w0_vertices;

use crate::harness::Readback;
use crate::raster::ClippedPoly;
use bytemuck::{Pod, Zeroable};
use glam::{DVec4, Mat4};
use umbrage::gpu::Context;

/// The checks' names (cases `mesh.<name>`), in run order.
pub const NAMES: [&str; 4] = ["w0_vertices", "watertight_meshlets", "group_counts", "task_payload"];

/// Why `ctx` cannot run check `name` (`None`: it can): no `VK_EXT_mesh_shader`, no task
/// shaders for `task_payload`, or no dynamic rendering (the checks draw with it).
pub fn unsupported(ctx: &Context, name: &str) -> Option<String> {
    let f = &ctx.features;
    let v = &ctx.info.api_version;
    if !f.mesh_shader {
        return Some(format!(
            "unsupported: VK_EXT_mesh_shader with meshShader (Vulkan 1.2 or newer) is not on this device (Vulkan {v}); \
             Mesa lavapipe 25.0.7 has it: `scripts/drivers.sh install 25.0.7`, then `eval \"$(scripts/drivers.sh env 25.0.7)\"`"
        ));
    }
    if name == "task_payload" && !f.task_shader {
        return Some("unsupported: taskShader of VK_EXT_mesh_shader is not on this device".into());
    }
    if !f.dynamic_rendering {
        return Some(format!("unsupported here: the mesh checks draw with dynamic rendering (Vulkan 1.3); the device has Vulkan {v}"));
    }
    None
}

/// `conform_mesh.wgsl`'s push block (`struct Push`), 96 bytes.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub(crate) struct Push {
    pub mvp: [f32; 16],
    pub light: [f32; 4],
    pub flags: u32,
    pub table: u32,
    pub count: u32,
    pub rec: u32,
}

impl Push {
    pub const SIZE: u32 = std::mem::size_of::<Push>() as u32;

    fn new(mvp: Mat4, light: [f32; 4], flags: u32, (table, count, rec): (u32, u32, u32)) -> Push {
        Push { mvp: mvp.to_cols_array(), light, flags, table, count, rec }
    }
}

/// `F_NEAR_ZERO_W`: clip w exactly 0 becomes extrude.wgsl's near-zero w.
const F_NEAR_ZERO_W: u32 = 1;
/// `F_NO_TILES`: `groups` records only.
const F_NO_TILES: u32 = 2;
/// extrude.wgsl's near-zero w factor (2^-60).
const NEAR_ZERO: f64 = 8.673_617_379_884_035e-19;

/// The checks' view: an infinite perspective projection with a near plane at 1/4, 90 degrees
/// across, every entry a float whose products with small dyadic numbers are exact: clip =
/// (x, y, -z - w/4, -z).
fn projection() -> Mat4 {
    Mat4::from_cols(
        glam::Vec4::new(1.0, 0.0, 0.0, 0.0),
        glam::Vec4::new(0.0, 1.0, 0.0, 0.0),
        glam::Vec4::new(0.0, 0.0, -1.0, -1.0),
        glam::Vec4::new(0.0, 0.0, -0.25, 0.0),
    )
}

fn is_f32(v: f64) -> bool {
    (v as f32) as f64 == v
}

/// The sum of `terms`, when every term and every subset sum is an f32: then f32 arithmetic
/// in any order, fused or not, computes exactly it.
fn exact_sum(terms: &[f64]) -> Option<f64> {
    let n = terms.len();
    for mask in 1u32..(1 << n) {
        let s: f64 = (0..n).filter(|k| mask & (1 << k) != 0).map(|k| terms[k]).sum();
        if !is_f32(s) {
            return None;
        }
    }
    Some(terms.iter().sum())
}

/// `m * v` exactly as the device computes it in f32 (`None` when some partial sum rounds).
fn exact_transform(m: Mat4, v: [f32; 4]) -> Option<DVec4> {
    let c = m.to_cols_array_2d();
    let row = |r: usize| exact_sum(&(0..4).map(|k| c[k][r] as f64 * v[k] as f64).collect::<Vec<_>>());
    Some(DVec4::new(row(0)?, row(1)?, row(2)?, row(3)?))
}

/// extrude.wgsl's `near`: `mvp * p`.
fn near(mvp: Mat4, p: [f32; 4]) -> Option<DVec4> {
    exact_transform(mvp, p)
}

/// extrude.wgsl's `far`: `mvp * (p.xyz * L.w - L.xyz, 0)`, with the near-zero w where clip w
/// is exactly 0 when `near_zero`.
fn far(mvp: Mat4, light: [f32; 4], p: [f32; 4], near_zero: bool) -> Option<DVec4> {
    let d = |k: usize| exact_sum(&[p[k] as f64 * light[3] as f64, -(light[k] as f64)]).map(|x| x as f32);
    let mut c = exact_transform(mvp, [d(0)?, d(1)?, d(2)?, 0.0])?;
    if near_zero && c.w == 0.0 {
        c.w = c.x.abs().max(c.y.abs()).max(c.z.abs()) * NEAR_ZERO;
    }
    Some(c)
}

/// The expected stencil of a `size` image cleared to `start` after the clip-space triangles
/// `tris` (front faces add `deltas.0`, back faces `deltas.1`, mod 256; clipped to the view
/// volume, without its z planes under `clamp`), and which pixels are judged: not those whose
/// centre lies within `eps` pixels of an edge of a clipped polygon.
fn expect_stencil(tris: &[[DVec4; 3]], clamp: bool, size: (u32, u32), bits: u32, eps: f64, start: u8, deltas: (i64, i64)) -> Model {
    let (w, h) = size;
    let n = (w * h) as usize;
    let mut count = vec![start as i64; n];
    let mut judged = vec![true; n];
    let mut singular = 0;
    for &t in tris {
        let poly = ClippedPoly::new(t, clamp, w, h, bits);
        if poly.singular {
            singular += 1;
            judged.iter_mut().for_each(|j| *j = false);
            continue;
        }
        if poly.p.len() < 3 || poly.vk_area() == 0.0 {
            continue;
        }
        let d = if poly.front_facing() { deltas.0 } else { deltas.1 };
        let xs = poly.p.iter().map(|p| p.x).fold(f64::INFINITY, f64::min).floor().max(0.0) as u32;
        let xe = (poly.p.iter().map(|p| p.x).fold(f64::NEG_INFINITY, f64::max).ceil().max(0.0) as u32).min(w);
        let ys = poly.p.iter().map(|p| p.y).fold(f64::INFINITY, f64::min).floor().max(0.0) as u32;
        let ye = (poly.p.iter().map(|p| p.y).fold(f64::NEG_INFINITY, f64::max).ceil().max(0.0) as u32).min(h);
        for y in ys..ye {
            for x in xs..xe {
                let i = (y * w + x) as usize;
                match poly.cover_eps(x, y, eps) {
                    crate::raster::Cover::In => count[i] += d,
                    crate::raster::Cover::Edge => judged[i] = false,
                    crate::raster::Cover::Out => {}
                }
            }
        }
    }
    Model { stencil: count.into_iter().map(|c| c.rem_euclid(256) as u8).collect(), judged, singular }
}

/// A modelled stencil image.
struct Model {
    stencil: Vec<u8>,
    judged: Vec<bool>,
    /// Triangles whose clipped polygon has a vertex at the clip volume's apex (undefined
    /// projection): every pixel is then left unjudged.
    singular: usize,
}

/// Judged pixels of `got` that differ from `m`: (judged, mismatches, the first three described);
/// the failure images ([`crate::image_sink::stencil_mismatch`]) when any differ. The test seam
/// (`value_images::skewed`) expects the first judged pixel one higher.
fn stencil_mismatches(got: &Readback, m: &Model) -> (u64, u64, Vec<String>) {
    let w = got.width as usize;
    let mut want = m.stencil.clone();
    if let (true, Some(i)) = (crate::value_images::skewed(), m.judged.iter().position(|&j| j)) {
        want[i] = want[i].wrapping_add(1);
    }
    let (mut judged, mut bad, mut first) = (0u64, 0u64, Vec::new());
    for (i, (&e, &j)) in want.iter().zip(&m.judged).enumerate() {
        if !j {
            continue;
        }
        judged += 1;
        if got.stencil[i] != e {
            bad += 1;
            if first.len() < 3 {
                first.push(format!("({}, {}): 0x{:02x}, want 0x{e:02x}", i % w, i / w, got.stencil[i]));
            }
        }
    }
    if bad > 0 {
        crate::image_sink::stencil_mismatch(got.width, got.height, &want, &m.judged, &got.stencil);
    }
    (judged, bad, first)
}

/// The pixel-to-clip mapping of a `width` x `height` image with pixel (x, y) at object (x, y):
/// [`crate::harness::pixel_ortho`].
fn pixels(width: u32, height: u32) -> Mat4 {
    crate::harness::pixel_ortho(width, height)
}

#[cfg(test)]
mod tests;
