//! 1. The ambient / G-buffer pass: every opaque mesh, depth LESS, writing the ambient term
//!    into the float accumulation target and albedo, face normal and eye-relative position
//!    into the G-buffer. Closed outward meshes are drawn with back faces culled, every other
//!    opaque mesh two-sided. Analytic spheres are ray-cast in their bounding cubes (exact
//!    depth, normal and position).
//!
//! Inputs / outputs (the first pass of the frame; images are `Targets` fields):
//! - Reads: nothing sampled (the instance buffer and the sphere cubes only).
//! - Writes: `accum` (cleared to `SKY`), `albedo`, `normal`, `position` (cleared to `ZERO`), each
//!   `UNDEFINED -> COLOR_ATTACHMENT_OPTIMAL`, CLEAR/STORE; `depth` `UNDEFINED -> DEPTH_STENCIL_ATTACHMENT_OPTIMAL`,
//!   CLEAR/STORE (`DS_CLEAR`: depth 1, stencil 0), depth LESS with writes.
//! - Leaves: `albedo`, `normal`, `position` in `SHADER_READ_ONLY_OPTIMAL` for the rest of the frame (lighting, shadow-map
//!   lookup, ray query, readback); `accum` in `COLOR_ATTACHMENT_OPTIMAL` and `depth` in `DEPTH_STENCIL_ATTACHMENT_OPTIMAL`,
//!   where every later pass loads them until `tonemap`.

use super::{att, Rec, SceneDraw, DS_CLEAR, SKY, ZERO};
use crate::push::{GBufferPush, SpherePush};
use crate::scene_gpu::Sidedness;
use ash::vk;

/// # Safety
/// `rec.cb` is recording outside a rendering instance; `instances` is this slot's instance
/// buffer and `spheres` this slot's sphere cubes (buffer, vertex count), written for this frame.
pub(crate) unsafe fn record(rec: &Rec, sd: &SceneDraw, spheres: Option<(vk::Buffer, u32)>) {
    let SceneDraw { t, p, geo, instances, vp_rel, ambient } = *sd;
    for img in t.gbuffer() {
        rec.transition(img, vk::ImageLayout::UNDEFINED, vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL);
    }
    rec.transition(&t.depth, vk::ImageLayout::UNDEFINED, vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL);
    // The accumulation starts at the sky colour (what the background shows); the G-buffer at
    // zero (position w = 0: nothing drawn).
    let clear = |i: usize| if i == 0 { SKY } else { ZERO };
    let colors: Vec<_> = t.gbuffer().iter().enumerate().map(|(i, img)| att(img, vk::AttachmentLoadOp::CLEAR, clear(i))).collect();
    let depth = att(&t.depth, vk::AttachmentLoadOp::CLEAR, DS_CLEAR);
    let d = &rec.ctx.device;
    let cb = rec.cb;
    let push = GBufferPush { view_proj: vp_rel.to_cols_array(), ambient: ambient.extend(0.0).to_array() };
    // SAFETY: the caller's contract; the images were just transitioned to attachment layouts.
    unsafe {
        rec.begin(rec.full, &colors, Some(&depth));
        d.cmd_push_constants(
            cb,
            p.layouts.gbuffer,
            vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT,
            0,
            bytemuck::bytes_of(&push),
        );
        for (side, pipe) in [(Sidedness::OneSided, p.gbuffer), (Sidedness::TwoSided, p.gbuffer_two_sided)] {
            if geo.of(side).next().is_some() {
                d.cmd_bind_pipeline(cb, vk::PipelineBindPoint::GRAPHICS, pipe);
                geo.cmd_draw(d, cb, instances, side);
            }
        }
        if let Some((buffer, count)) = spheres {
            d.cmd_bind_pipeline(cb, vk::PipelineBindPoint::GRAPHICS, p.gbuffer_sphere);
            if t.samples > 1 {
                let sp = SpherePush::new(push, vp_rel, t.extent.width, t.extent.height);
                let stages = vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT;
                d.cmd_push_constants(cb, p.layouts.sphere_ms, stages, 0, bytemuck::bytes_of(&sp));
            }
            d.cmd_bind_vertex_buffers(cb, 0, &[buffer], &[0]);
            d.cmd_draw(cb, count, 1, 0, 0);
        }
        d.cmd_end_rendering(cb);
    }
    for img in [&t.albedo, &t.normal, &t.position] {
        rec.transition(img, vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL, vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL);
    }
}
