//! The host's side of the system under test: the device, the host's render pass, its frame
//! slots and targets, the comparison passes, and the recording of a frame's determination.

use crate::model::{deformed, sphere_of, Model, Target};
use crate::{light_of, meshes, transform, view_of, H, RECEIVER_DEPTH, W};
use ash::vk;
use gpu_allocator::MemoryLocation;
use std::cell::RefCell;
use umbrage::geom::Mesh;
use umbrage::gpu::resources::{cleared_depth_stencil, memory_barrier, transition};
use umbrage::gpu::{Buffer, Context, Image};
use umbrage::pass::{
    CasterId, DepthStencilTarget, EnabledFeatures, PassSettings, PreparedFrame, RenderPassTarget, ShadowPass, ShadowPassDesc, SphereId,
    TargetModel, Technique,
};

/// A depth-stencil image the determination draws into, its framebuffer of the host's render
/// pass, and the buffer its stencil is copied to.
pub(crate) struct HostTarget {
    image: Image,
    framebuffer: vk::Framebuffer,
    readback: Buffer,
}

/// One frame slot of the host: its own target, command buffer and fence, so that up to
/// `frames_in_flight` submitted frames are in flight at once.
pub(crate) struct HostSlot {
    pub(crate) target: HostTarget,
    pub(crate) cb: vk::CommandBuffer,
    pub(crate) fence: vk::Fence,
}

/// The device, the host's render pass and targets (one per test thread). Fields drop in
/// order: nothing here destroys Vulkan objects on drop but the passes, before the context.
pub(crate) struct Harness {
    /// The host's render pass of [`Target::RenderPass`]: one subpass whose only attachment is
    /// the target's image, depth and stencil cleared at its start (to the receiver plane and 0).
    pub(crate) render_pass: vk::RenderPass,
    pub(crate) rp_target: RenderPassTarget,
    /// The command buffers' pool (each buffer resettable).
    pub(crate) pool: vk::CommandPool,
    /// The slots of the system under test: as many as the most frames in flight.
    pub(crate) slots: Vec<HostSlot>,
    /// The comparison pass of each `frames_in_flight` (dynamic rendering whatever the target
    /// model under test: both must leave the same stencil), and its target.
    pub(crate) reference: Vec<(usize, ShadowPass)>,
    pub(crate) reference_target: HostTarget,
    /// A second pass whose ids the SUT must refuse.
    pub(crate) other: ShadowPass,
    pub(crate) other_caster: CasterId,
    pub(crate) other_sphere: SphereId,
    pub(crate) ctx: Context,
}

pub(crate) const MAX_FRAMES_IN_FLIGHT: usize = 3;

thread_local! {
    pub(crate) static HARNESS: RefCell<Option<Harness>> = const { RefCell::new(None) };
    /// Frames compared, those with a shadow, refused calls, abandoned frames, frames compared
    /// of the render-pass model and those with a shadow, frames submitted while an earlier one
    /// was still in flight (not waited for).
    pub(crate) static COUNTS: std::cell::Cell<[usize; 7]> = const { std::cell::Cell::new([0; 7]) };
}

pub(crate) fn count(k: usize) {
    COUNTS.with(|c| {
        let mut v = c.get();
        v[k] += 1;
        c.set(v);
    });
}

/// A pass of `frames_in_flight` slots recording with dynamic rendering (`render_pass`: None,
/// transparent casters configured) or inside the render pass.
pub(crate) fn new_pass(ctx: &Context, frames_in_flight: usize, render_pass: Option<RenderPassTarget>) -> ShadowPass {
    let desc = ShadowPassDesc {
        depth_stencil_format: ctx.depth_format,
        frames_in_flight,
        target: render_pass.map_or(TargetModel::DynamicRendering, TargetModel::RenderPass),
        transmit_format: render_pass.is_none().then_some(vk::Format::R16G16B16A16_SFLOAT),
        // the compute path's merged draws where the device has them (Step::SetMethod picks
        // each way of recording them in turn)
        features: EnabledFeatures {
            draw_indirect_first_instance: ctx.features.draw_indirect_first_instance,
            multi_draw_indirect: ctx.features.multi_draw_indirect,
            draw_indirect_count: ctx.features.draw_indirect_count,
            ..Default::default()
        },
        ..Default::default()
    };
    ShadowPass::new(&ctx.instance, ctx.physical, &ctx.device, (*ctx.allocator).clone(), &desc).unwrap()
}

/// The host's render pass: one subpass whose only attachment is a depth-stencil image of the
/// context's format, cleared when the pass begins and left in DEPTH_STENCIL_ATTACHMENT_OPTIMAL.
pub(crate) fn host_render_pass(ctx: &Context) -> (vk::RenderPass, RenderPassTarget) {
    let ds = vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL;
    let attachments = [vk::AttachmentDescription::default()
        .format(ctx.depth_format)
        .samples(vk::SampleCountFlags::TYPE_1)
        .load_op(vk::AttachmentLoadOp::CLEAR)
        .store_op(vk::AttachmentStoreOp::STORE)
        .stencil_load_op(vk::AttachmentLoadOp::CLEAR)
        .stencil_store_op(vk::AttachmentStoreOp::STORE)
        .initial_layout(vk::ImageLayout::UNDEFINED)
        .final_layout(ds)];
    let ds_ref = vk::AttachmentReference { attachment: 0, layout: ds };
    let subpasses =
        [vk::SubpassDescription::default().pipeline_bind_point(vk::PipelineBindPoint::GRAPHICS).depth_stencil_attachment(&ds_ref)];
    let info = vk::RenderPassCreateInfo::default().attachments(&attachments).subpasses(&subpasses);
    // SAFETY: a well-formed create info on the context's device; destroyed by the test.
    let rp = unsafe { ctx.device.create_render_pass(&info, None) }.unwrap();
    // SAFETY: `info` is the create info `rp` was made from, its pointers alive.
    let target = unsafe { RenderPassTarget::new(rp, &info, 0) }.unwrap();
    (rp, target)
}

pub(crate) fn with_harness<R>(f: impl FnOnce(&mut Harness) -> R) -> R {
    HARNESS.with(|h| {
        let mut h = h.borrow_mut();
        let h = h.as_mut().expect("the harness is set up by the test");
        f(h)
    })
}

/// Records into `cb` (recording, outside rendering) `frame`'s determination of light 0 into
/// `t` (cleared to the receiver plane), then the copy of its stencil into `t.readback`, made
/// visible to the host. `target` is the model `pass` was made for: with
/// [`Target::RenderPass`] the clear is the render pass's and the determination records inside
/// its subpass.
///
/// The caller has waited for every earlier use of `t` (its slot's fence) and for the frame's
/// slot's previous submission.
pub(crate) fn record(h: &Harness, t: &HostTarget, cb: vk::CommandBuffer, pass: &ShadowPass, frame: &PreparedFrame, target: Target) {
    let ctx = &h.ctx;
    let ds = vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL;
    let extent = vk::Extent2D { width: W, height: H };
    let determine = DepthStencilTarget::new(t.image.raw, t.image.view, extent);
    match target {
        Target::DynamicRendering => {
            transition(ctx, cb, &t.image, vk::ImageLayout::UNDEFINED, ds);
            let att = cleared_depth_stencil(t.image.view, (RECEIVER_DEPTH, 0));
            let info =
                vk::RenderingInfo::default().render_area(extent.into()).layer_count(1).depth_attachment(&att).stencil_attachment(&att);
            // SAFETY: `cb` is recording outside rendering; the image is in `ds`; the frame is
            // live and its slot's previous submission has completed (the caller's contract).
            unsafe {
                pass.cmd_before_rendering(cb, frame).unwrap();
                ctx.device.cmd_begin_rendering(cb, &info);
                ctx.device.cmd_end_rendering(cb);
                transition(ctx, cb, &t.image, ds, ds);
                pass.cmd_determine(cb, frame, 0, &determine).unwrap();
            }
        }
        Target::RenderPass => {
            let clear = [vk::ClearValue { depth_stencil: vk::ClearDepthStencilValue { depth: RECEIVER_DEPTH, stencil: 0 } }];
            let begin = vk::RenderPassBeginInfo::default()
                .render_pass(h.render_pass)
                .framebuffer(t.framebuffer)
                .render_area(extent.into())
                .clear_values(&clear);
            // SAFETY: `cb` is recording outside rendering; the frame's uploads are recorded
            // before the render pass begins, the determination inside its only subpass, whose
            // attachment is the image (DEPTH_STENCIL_ATTACHMENT_OPTIMAL there, and after it);
            // the frame is live and its slot's previous submission has completed.
            unsafe {
                pass.cmd_before_rendering(cb, frame).unwrap();
                ctx.device.cmd_begin_render_pass(cb, &begin, vk::SubpassContents::INLINE);
                pass.cmd_determine(cb, frame, 0, &determine).unwrap();
                ctx.device.cmd_end_render_pass(cb);
            }
        }
    }
    let src = vk::ImageLayout::TRANSFER_SRC_OPTIMAL;
    transition(ctx, cb, &t.image, ds, src);
    let copy = vk::BufferImageCopy::default()
        .image_subresource(vk::ImageSubresourceLayers::default().aspect_mask(vk::ImageAspectFlags::STENCIL).layer_count(1))
        .image_extent(vk::Extent3D { width: W, height: H, depth: 1 });
    // SAFETY: the image is in TRANSFER_SRC_OPTIMAL; the buffer holds W x H bytes.
    unsafe { ctx.device.cmd_copy_image_to_buffer(cb, t.image.raw, src, t.readback.raw, &[copy]) };
    use vk::{AccessFlags2 as A, PipelineStageFlags2 as S};
    memory_barrier(ctx, cb, (S::TRANSFER, A::TRANSFER_WRITE), (S::HOST, A::HOST_READ));
}

pub(crate) fn stencil(t: &HostTarget) -> Vec<u8> {
    t.readback.read().unwrap()[..(W * H) as usize].to_vec()
}

/// The stencil of a pass holding exactly the model's casters, prepared from scratch.
pub(crate) fn reference_stencil(h: &mut Harness, model: &Model) -> Vec<u8> {
    let fif = model.frames_in_flight;
    if !h.reference.iter().any(|(f, _)| *f == fif) {
        let p = new_pass(&h.ctx, fif, None);
        h.reference.push((fif, p));
    }
    let i = h.reference.iter().position(|(f, _)| *f == fif).unwrap();
    let (_, mut pass) = h.reference.swap_remove(i);
    let fresh = new_pass_state(&mut pass, model);
    let frame = pass.prepare(0, &view_of(model.eye), &[light_of(model.light)]).unwrap();
    h.ctx.one_shot(|cb| record(h, &h.reference_target, cb, &pass, &frame, Target::DynamicRendering)).unwrap();
    let stencil = stencil(&h.reference_target);
    drop(frame);
    for id in fresh.0 {
        pass.remove_caster(id).unwrap();
    }
    for id in fresh.1 {
        pass.remove_sphere(id).unwrap();
    }
    h.reference.push((fif, pass));
    stencil
}

/// Adds the model's casters and spheres to `pass` (whose own are removed after use).
fn new_pass_state(pass: &mut ShadowPass, model: &Model) -> (Vec<CasterId>, Vec<SphereId>) {
    let meshes = meshes();
    // from scratch: nothing kept
    pass.set_settings(PassSettings { technique: Technique::Volumes(model.method), keep: false, ..Default::default() }).unwrap();
    let casters = model
        .casters
        .iter()
        .map(|c| {
            let mesh = Mesh::new(deformed(c.shape, c.deform), meshes[c.shape].triangles.clone());
            pass.add_caster("ref", &mesh, transform(c.pos, c.turn)).unwrap()
        })
        .collect();
    let spheres = model.spheres.iter().map(|s| pass.add_sphere_caster("ref", sphere_of(s), None).unwrap()).collect();
    (casters, spheres)
}

/// On a failure, leaks the harness instead of letting the thread-local destructor tear the
/// device down under passes and frames still alive (that crashed the process before the test
/// harness printed the failure).
pub(crate) struct LeakHarnessOnPanic;

impl Drop for LeakHarnessOnPanic {
    fn drop(&mut self) {
        if std::thread::panicking() {
            std::mem::forget(HARNESS.with(|h| h.borrow_mut().take()));
        }
    }
}

/// A W x H depth-stencil image, its framebuffer of `render_pass` and its readback buffer.
pub(crate) fn host_target(ctx: &Context, render_pass: vk::RenderPass, name: &str) -> HostTarget {
    let extent = vk::Extent2D { width: W, height: H };
    let usage = vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT | vk::ImageUsageFlags::TRANSFER_SRC;
    let image =
        Image::new_2d(ctx, name, ctx.depth_format, extent, usage, vk::ImageAspectFlags::DEPTH | vk::ImageAspectFlags::STENCIL).unwrap();
    let readback = Buffer::new(ctx, name, (W * H) as u64 + 256, vk::BufferUsageFlags::TRANSFER_DST, MemoryLocation::GpuToCpu).unwrap();
    let views = [image.view];
    let fb = vk::FramebufferCreateInfo::default().render_pass(render_pass).attachments(&views).width(W).height(H).layers(1);
    // SAFETY: the image view is of the render pass's attachment format and the framebuffer's
    // size; destroyed before the image.
    let framebuffer = unsafe { ctx.device.create_framebuffer(&fb, None) }.unwrap();
    HostTarget { image, framebuffer, readback }
}

pub(crate) fn destroy_target(ctx: &Context, mut t: HostTarget) {
    // SAFETY: every command buffer using the framebuffer has completed.
    unsafe { ctx.device.destroy_framebuffer(t.framebuffer, None) };
    t.image.destroy(ctx);
    t.readback.destroy(ctx);
}
