//! 3. Transparent casters, forward over the lit scene: premultiplied "over" with the ambient
//!    term, then each light added (unsorted: an order-independent approximation; without
//!    `--self-shadow` transparent surfaces receive no shadows).
//!
//! Inputs / outputs (after the last light's `illuminate`; no transition recorded here):
//! - Reads: `depth` (the opaque depth) in `DEPTH_STENCIL_ATTACHMENT_OPTIMAL`, LOAD/STORE, tested LESS, not written;
//!   nothing sampled.
//! - Writes: `accum` in `COLOR_ATTACHMENT_OPTIMAL`, LOAD/STORE ("over", then additive per forward light).
//! - Leaves both in those layouts, where `selfshadow`, `debug` and `tonemap` expect them.

use super::{att, Rec, SceneDraw, DS_CLEAR, ZERO};
use crate::push::{ForwardPush, LightPush};
use crate::scene_gpu::{SceneGeometry, Sidedness};
use ash::vk;

/// Draws every transparent mesh with `push` (the caller binds the pipeline).
///
/// # Safety
/// `rec.cb` is recording inside a rendering instance with a scene pipeline of the forward
/// layout `layout` bound.
pub(crate) unsafe fn draw_meshes(rec: &Rec, layout: vk::PipelineLayout, geo: &SceneGeometry, instances: vk::Buffer, push: &ForwardPush) {
    let d = &rec.ctx.device;
    // SAFETY: the caller's contract.
    unsafe {
        d.cmd_push_constants(rec.cb, layout, vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT, 0, bytemuck::bytes_of(push));
        geo.cmd_draw(d, rec.cb, instances, Sidedness::Transparent);
    }
}

/// `lights`: the per-light forward passes (empty with `--self-shadow`, whose light passes
/// are recorded by the self-shadowing pass).
///
/// # Safety
/// `rec.cb` is recording outside a rendering instance; accumulation and depth in attachment layout.
pub(crate) unsafe fn record(rec: &Rec, sd: &SceneDraw, lights: &[LightPush]) {
    let SceneDraw { t, p, geo, instances, vp_rel, ambient } = *sd;
    let load = vk::AttachmentLoadOp::LOAD;
    let accum = [att(&t.accum, load, ZERO)];
    let depth = att(&t.depth, load, DS_CLEAR);
    let d = &rec.ctx.device;
    // SAFETY: the caller's contract.
    unsafe {
        rec.begin(rec.full, &accum, Some(&depth));
        d.cmd_bind_pipeline(rec.cb, vk::PipelineBindPoint::GRAPHICS, p.transparent_over);
        draw_meshes(rec, p.layouts.forward, geo, instances, &ForwardPush::ambient(vp_rel, ambient));
        d.cmd_bind_pipeline(rec.cb, vk::PipelineBindPoint::GRAPHICS, p.transparent_light);
        for l in lights {
            draw_meshes(rec, p.layouts.forward, geo, instances, &ForwardPush::light(vp_rel, l));
        }
        d.cmd_end_rendering(rec.cb);
    }
}
