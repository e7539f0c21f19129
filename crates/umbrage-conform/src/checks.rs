//! The checks: each a small offscreen render read back and compared with exact expectations.
//!
//! Grouped by family: depth (w = 0 vertices, depth clamp, depth bounds), coverage (watertight
//! edges, index types), stencil (two-sided wrap, stencil formats), the float counter (a deep
//! wrap counted in R32_SFLOAT next to the stencil), multisampling (each sample's coverage and
//! depth at its standard location), multiview (a point light's cube faces as
//! views against atlas tiles) and the end-to-end pipeline check; every
//! check is re-exported here.

pub mod commands;
mod coverage;
mod depth;
mod float_count;
mod multiview;
mod pipeline;
mod sample_locations;
mod stencil;

pub use coverage::{index_types, watertight_fan};
pub use depth::{depth_bounds, depth_clamp, w0_vertices_and_infinity};
pub use float_count::deep_wrap_float_count;
pub use multiview::{multiview_cube_faces, NAME as MULTIVIEW_CUBE_FACES};
pub use pipeline::{shadow_pipeline_hard_cases, PIPELINE_THRESHOLD};
pub use sample_locations::{msaa_depth_locations, NAME as MSAA_DEPTH_LOCATIONS};
pub use stencil::{stencil_formats, two_sided_stencil_wrap};

use super::harness::{PipeSpec, Readback};
use super::raster::WinTri;
use ash::vk;
use glam::Vec3;
use umbrage::gpu::Context;
use umbrage_scene::Camera;

/// The device's sub-pixel precision (`VkPhysicalDeviceLimits::subPixelPrecisionBits`).
fn subpixel_bits(ctx: &Context) -> u32 {
    ctx.limits.sub_pixel_precision_bits
}

/// Depth word equal to 1.0 for `format` (exact for D32, within one 24-bit ulp for D24).
fn depth_is(format: vk::Format, word: u32, value: f64) -> bool {
    if format == vk::Format::D24_UNORM_S8_UINT {
        let expected = (value * 16_777_215.0).round() as i64;
        ((word & 0x00ff_ffff) as i64 - expected).abs() <= 1
    } else {
        f32::from_bits(word) == value as f32
    }
}

/// Compares a stencil read-back with an expectation on judged pixels.
fn count_mismatches(rb: &Readback, expected: &[u8], judged: &[bool]) -> (u64, u64) {
    let mut mism = 0;
    let mut unjudged = 0;
    for i in 0..expected.len() {
        if !judged[i] {
            unjudged += 1;
        } else if rb.stencil[i] != expected[i] {
            mism += 1;
        }
    }
    if mism > 0 {
        super::image_sink::stencil_mismatch(rb.width, rb.height, expected, judged, &rb.stencil);
    }
    (mism, unjudged)
}

fn tri_list(n: u32) -> Vec<[u32; 3]> {
    (0..n).map(|t| [3 * t, 3 * t + 1, 3 * t + 2]).collect()
}

fn incr_both() -> PipeSpec {
    PipeSpec::stencil(vk::StencilOp::INCREMENT_AND_WRAP, vk::StencilOp::INCREMENT_AND_WRAP)
}

fn write_depth(mut s: PipeSpec) -> PipeSpec {
    s.depth_test = true;
    s.depth_write = true;
    s.depth_compare = vk::CompareOp::ALWAYS;
    s
}

fn view_camera() -> Camera {
    Camera { eye: Vec3::ZERO, target: Vec3::new(0.0, 0.0, -1.0), up: Vec3::Y, fov_y_deg: 60.0, near: 0.1 }
}

/// Two triangles for an integer-aligned rectangle, front (counter-clockwise in Vulkan's sense)
/// or back facing.
fn rect(out: &mut Vec<[f32; 4]>, r: [f32; 4], front: bool) {
    let [x0, y0, x1, y1] = r;
    let t1 = [[x0, y0], [x0, y1], [x1, y1]];
    let t2 = [[x0, y0], [x1, y1], [x1, y0]];
    for t in [t1, t2] {
        let wt = WinTri { p: t.map(|p| glam::DVec2::new(p[0] as f64, p[1] as f64)), z: [0.5; 3] };
        let t = if wt.front_facing() == front { t } else { [t[0], t[2], t[1]] };
        out.extend(t.iter().map(|p| [p[0], p[1], 0.5, 1.0]));
    }
}
