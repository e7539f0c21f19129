//! Every call sequence of `ShadowPass`'s public API against a reference model
//! (proptest-state-machine). The model is the live casters (mesh, transform, deformation),
//! sphere casters and transparent casters, and the settings; the transitions are the host's
//! calls: add, remove and update casters, sphere casters and transparent casters,
//! `set_transform`, `update_positions`, `set_settings` (volume methods and
//! `Technique::Compute`, whose casters' tables live in a pass-wide arena that additions,
//! removals and deformations grow, leave holes in and rebuild), `prepare` on any slot (including
//! invalid ones) with the frame then dropped, recorded and submitted, or recorded and never
//! submitted (`abandon_frame`), interleaved with invalid arguments and another pass's ids.
//!
//! After every submitted frame the stencil must equal, byte for byte, the stencil of a pass
//! holding exactly the model's casters, prepared from scratch (one per configuration, its
//! casters replaced before each comparison: a fresh pass per frame would compile its
//! pipelines hundreds of times). Every refused call must leave the model's picture unchanged
//! (the next comparison checks it), and validation must stay clean. Configurations:
//! `frames_in_flight` 1 to 3; each sequence draws its target model, dynamic rendering or the
//! host's `VkRenderPass` (`TargetModel::RenderPass`: the determination recorded inside the
//! subpass of a render pass that clears the depth-stencil attachment, transparent casters
//! refused for want of `transmit_format`). Both are compared with the same dynamic-rendering
//! reference: the two models must leave the same stencil.
//!
//! Frames overlap on the GPU as a real host's do: each slot has its own command buffer, fence
//! and target image; a submitted frame is waited for only when its slot is prepared again (or
//! the sequence ends), and its stencil is read back and compared then, against the model it
//! was prepared from, while the other slots' frames stay in flight and the host's later calls
//! (removals, new positions, settings) happen around them. The points where the host waits
//! are fixed by the sequence, so a run is as deterministic as the frames' results must be;
//! validation reports a buffer destroyed under a frame still in flight.
//!
//! CI runs `PASS_SEQUENCES_CASES` (default 200) sequences of 30 steps (shrunk on failure) per
//! `frames_in_flight`, split at random between the two target models, from a fixed seed (CI is
//! reproducible; the seed is printed past the harness's capture, so a run the driver aborts
//! still names it); `UMBRAGE_PROPTEST_SEED=<u64>` replays a run and `=random` explores. Before
//! a release run more: `UMBRAGE_PROPTEST_SEED=random PASS_SEQUENCES_CASES=5000 cargo test
//! --release --test pass_sequences`. Failing cases are kept in
//! `proptest-regressions/pass_sequences.txt` and replayed first.

mod common;

use ash::vk;
use glam::{DMat4, DVec3, Vec3};
use gpu_allocator::MemoryLocation;
use proptest::prelude::*;
use proptest::test_runner::{Config, FileFailurePersistence};
use proptest_state_machine::{ReferenceStateMachine, StateMachineTest};
use std::cell::RefCell;
use umbrage::error::Misuse;
use umbrage::geom::{Light, Mesh, Sphere};
use umbrage::gpu::resources::{cleared_depth_stencil, memory_barrier, transition};
use umbrage::gpu::{Buffer, Context, Image};
use umbrage::pass::{
    CasterId, ComputeDraws, DepthStencilTarget, EnabledFeatures, PassSettings, PassToggles, PreparedFrame, RenderPassTarget, ShadowPass,
    ShadowPassDesc, ShadowView, SphereId, TargetModel, Technique,
};
use umbrage::scene::shapes;
use umbrage::shadow::Method;
use umbrage::Error;

const W: u32 = 48;
const H: u32 = 36;
/// The receiver: the depth buffer cleared to a plane 12.5 units in front of the eye
/// (`1 - near / z` with near 0.1), behind every caster.
const RECEIVER_DEPTH: f32 = 0.992;

fn meshes() -> [Mesh; 3] {
    [shapes::cuboid(Vec3::splat(0.8)), shapes::sphere(0.5, 10, 6), shapes::torus(0.5, 0.2, 10, 6)]
}

fn transform(pos: [i8; 3], turn: u8) -> DMat4 {
    let p = DVec3::new(pos[0] as f64 * 0.5, pos[1] as f64 * 0.25 + 0.5, pos[2] as f64 * 0.5);
    DMat4::from_translation(p) * DMat4::from_rotation_y(turn as f64 * 0.4)
}

fn view() -> ShadowView {
    let eye = Vec3::new(0.0, 4.0, 8.0);
    ShadowView {
        eye: eye.as_dvec3(),
        view: glam::camera::rh::view::look_at_mat4(Vec3::ZERO, -eye, Vec3::Y),
        proj: glam::camera::rh::proj::vulkan::perspective_infinite(1.0, W as f32 / H as f32, 0.1),
        width: W,
        height: H,
    }
}

fn light() -> Light {
    Light::point(Vec3::new(1.0, 8.0, 2.0))
}

// ---- The reference model -------------------------------------------------------------------

#[derive(Clone, Debug, PartialEq)]
struct ModelCaster {
    shape: usize,
    pos: [i8; 3],
    turn: u8,
    /// `update_positions` with the mesh scaled by `1 + k / 8` about its origin.
    deform: u8,
}

#[derive(Clone, Debug, PartialEq)]
struct ModelSphere {
    pos: [i8; 3],
    radius: u8,
}

/// Where the system under test records its determination ([`TargetModel`]): its own
/// rendering instances, or inside the harness's render pass (which has no colour target, so
/// `transmit_format` and with it transparent casters are refused there).
#[derive(Clone, Copy, Debug, PartialEq)]
enum Target {
    DynamicRendering,
    RenderPass,
}

#[derive(Clone, Debug)]
struct Model {
    frames_in_flight: usize,
    target: Target,
    casters: Vec<ModelCaster>,
    spheres: Vec<ModelSphere>,
    transparent: Vec<ModelCaster>,
    method: Method,
}

#[derive(Clone, Copy, Debug)]
enum FrameFate {
    Dropped,
    Submitted,
    /// Recorded, then the command buffer reset instead of submitted (`abandon_frame`).
    Abandoned,
}

#[derive(Clone, Debug)]
enum Step {
    AddCaster(ModelCaster),
    RemoveCaster(usize),
    SetTransform(usize, [i8; 3], u8),
    UpdatePositions(usize, u8),
    AddSphere(ModelSphere),
    RemoveSphere(usize),
    SetSphere(usize, ModelSphere),
    AddTransparent(ModelCaster),
    RemoveTransparent(usize),
    /// A volume method, or `None`: `Technique::Compute` (McGuire's cases with the GPU's
    /// possible silhouettes; its stencil is McGuire's byte for byte).
    SetMethod(Option<Method>),
    Prepare(usize, FrameFate),
    /// A call with an invalid argument, or another pass's id: refused, nothing changes.
    Invalid(u8),
}

fn pos() -> impl Strategy<Value = [i8; 3]> {
    [-4i8..=4, 0i8..=4, -4i8..=4]
}

fn caster() -> impl Strategy<Value = ModelCaster> {
    (0usize..3, pos(), 0u8..8).prop_map(|(shape, pos, turn)| ModelCaster { shape, pos, turn, deform: 0 })
}

fn sphere() -> impl Strategy<Value = ModelSphere> {
    (pos(), 1u8..=3).prop_map(|(pos, radius)| ModelSphere { pos, radius })
}

const METHODS: [Option<Method>; 5] = [Some(Method::McGuire), Some(Method::ZPass), Some(Method::ZFail), Some(Method::Lengyel), None];

/// The technique the system under test runs for a [`Step::SetMethod`].
fn technique(m: Option<Method>) -> Technique {
    m.map_or(Technique::Compute, Technique::Volumes)
}

struct Reference;

// The configuration of the current run: frames in flight.
thread_local! {
    static FRAMES_IN_FLIGHT: std::cell::Cell<usize> = const { std::cell::Cell::new(2) };
}

impl ReferenceStateMachine for Reference {
    type State = Model;
    type Transition = Step;

    fn init_state() -> BoxedStrategy<Model> {
        let fif = FRAMES_IN_FLIGHT.with(|f| f.get());
        // The target model is drawn per sequence: the cases split between the two.
        prop_oneof![Just(Target::DynamicRendering), Just(Target::RenderPass)]
            .prop_map(move |target| Model {
                frames_in_flight: fif,
                target,
                casters: vec![],
                spheres: vec![],
                transparent: vec![],
                method: Method::McGuire,
            })
            .boxed()
    }

    fn transitions(state: &Model) -> BoxedStrategy<Step> {
        let (nc, ns, nt, slots) = (state.casters.len(), state.spheres.len(), state.transparent.len(), state.frames_in_flight);
        let any = |n: usize| if n == 0 { Just(0usize).boxed() } else { (0..n).boxed() };
        prop_oneof![
            3 => caster().prop_map(Step::AddCaster),
            1 => any(nc).prop_map(Step::RemoveCaster),
            2 => (any(nc), pos(), 0u8..8).prop_map(|(i, p, t)| Step::SetTransform(i, p, t)),
            1 => (any(nc), 0u8..4).prop_map(|(i, k)| Step::UpdatePositions(i, k)),
            1 => sphere().prop_map(Step::AddSphere),
            1 => any(ns).prop_map(Step::RemoveSphere),
            1 => (any(ns), sphere()).prop_map(|(i, s)| Step::SetSphere(i, s)),
            1 => caster().prop_map(Step::AddTransparent),
            1 => any(nt).prop_map(Step::RemoveTransparent),
            1 => (0usize..METHODS.len()).prop_map(|m| Step::SetMethod(METHODS[m])),
            6 => (0..slots + 1, prop_oneof![1 => Just(FrameFate::Dropped), 3 => Just(FrameFate::Submitted), 1 => Just(FrameFate::Abandoned)])
                .prop_map(|(s, f)| Step::Prepare(s, f)),
            2 => (0u8..8).prop_map(Step::Invalid),
        ]
        .boxed()
    }

    fn preconditions(state: &Model, step: &Step) -> bool {
        match step {
            Step::RemoveCaster(i) | Step::SetTransform(i, ..) | Step::UpdatePositions(i, _) => *i < state.casters.len(),
            Step::RemoveSphere(i) | Step::SetSphere(i, _) => *i < state.spheres.len(),
            Step::RemoveTransparent(i) => *i < state.transparent.len(),
            _ => true,
        }
    }

    fn apply(mut state: Model, step: &Step) -> Model {
        match step {
            Step::AddCaster(c) => state.casters.push(c.clone()),
            Step::RemoveCaster(i) => {
                state.casters.remove(*i);
            }
            Step::SetTransform(i, p, t) => {
                state.casters[*i].pos = *p;
                state.casters[*i].turn = *t;
            }
            Step::UpdatePositions(i, k) => state.casters[*i].deform = *k,
            Step::AddSphere(s) => state.spheres.push(s.clone()),
            Step::RemoveSphere(i) => {
                state.spheres.remove(*i);
            }
            Step::SetSphere(i, s) => state.spheres[*i] = s.clone(),
            // Refused by a render-pass pass (no transmit_format): nothing changes.
            Step::AddTransparent(c) if state.target == Target::DynamicRendering => state.transparent.push(c.clone()),
            Step::AddTransparent(_) => {}
            Step::RemoveTransparent(i) => {
                state.transparent.remove(*i);
            }
            Step::SetMethod(m) => state.method = m.unwrap_or(Method::McGuire),
            Step::Prepare(..) | Step::Invalid(_) => {}
        }
        state
    }
}

// ---- The system under test ------------------------------------------------------------------

/// A depth-stencil image the determination draws into, its framebuffer of the host's render
/// pass, and the buffer its stencil is copied to.
struct HostTarget {
    image: Image,
    framebuffer: vk::Framebuffer,
    readback: Buffer,
}

/// One frame slot of the host: its own target, command buffer and fence, so that up to
/// `frames_in_flight` submitted frames are in flight at once.
struct HostSlot {
    target: HostTarget,
    cb: vk::CommandBuffer,
    fence: vk::Fence,
}

/// The device, the host's render pass and targets (one per test thread). Fields drop in
/// order: nothing here destroys Vulkan objects on drop but the passes, before the context.
struct Harness {
    /// The host's render pass of [`Target::RenderPass`]: one subpass whose only attachment is
    /// the target's image, depth and stencil cleared at its start (to the receiver plane and 0).
    render_pass: vk::RenderPass,
    rp_target: RenderPassTarget,
    /// The command buffers' pool (each buffer resettable).
    pool: vk::CommandPool,
    /// The slots of the system under test: as many as the most frames in flight.
    slots: Vec<HostSlot>,
    /// The comparison pass of each `frames_in_flight` (dynamic rendering whatever the target
    /// model under test: both must leave the same stencil), and its target.
    reference: Vec<(usize, ShadowPass)>,
    reference_target: HostTarget,
    /// A second pass whose ids the SUT must refuse.
    other: ShadowPass,
    other_caster: CasterId,
    other_sphere: SphereId,
    ctx: Context,
}

const MAX_FRAMES_IN_FLIGHT: usize = 3;

thread_local! {
    static HARNESS: RefCell<Option<Harness>> = const { RefCell::new(None) };
    /// Frames compared, those with a shadow, refused calls, abandoned frames, frames compared
    /// of the render-pass model and those with a shadow, frames submitted while an earlier one
    /// was still in flight (not waited for).
    static COUNTS: std::cell::Cell<[usize; 7]> = const { std::cell::Cell::new([0; 7]) };
}

fn count(k: usize) {
    COUNTS.with(|c| {
        let mut v = c.get();
        v[k] += 1;
        c.set(v);
    });
}

/// A pass of `frames_in_flight` slots recording with dynamic rendering (`render_pass`: None,
/// transparent casters configured) or inside the render pass.
fn new_pass(ctx: &Context, frames_in_flight: usize, render_pass: Option<RenderPassTarget>) -> ShadowPass {
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
fn host_render_pass(ctx: &Context) -> (vk::RenderPass, RenderPassTarget) {
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

fn with_harness<R>(f: impl FnOnce(&mut Harness) -> R) -> R {
    HARNESS.with(|h| {
        let mut h = h.borrow_mut();
        let h = h.as_mut().expect("the harness is set up by the test");
        f(h)
    })
}

fn deformed(shape: usize, k: u8) -> Vec<Vec3> {
    let s = 1.0 + k as f32 / 8.0;
    meshes()[shape].positions.iter().map(|p| *p * s).collect()
}

/// Records into `cb` (recording, outside rendering) `frame`'s determination of light 0 into
/// `t` (cleared to the receiver plane), then the copy of its stencil into `t.readback`, made
/// visible to the host. `target` is the model `pass` was made for: with
/// [`Target::RenderPass`] the clear is the render pass's and the determination records inside
/// its subpass.
///
/// The caller has waited for every earlier use of `t` (its slot's fence) and for the frame's
/// slot's previous submission.
fn record(h: &Harness, t: &HostTarget, cb: vk::CommandBuffer, pass: &ShadowPass, frame: &PreparedFrame, target: Target) {
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

fn stencil(t: &HostTarget) -> Vec<u8> {
    t.readback.read().unwrap()[..(W * H) as usize].to_vec()
}

/// The stencil of a pass holding exactly the model's casters, prepared from scratch.
fn reference_stencil(h: &mut Harness, model: &Model) -> Vec<u8> {
    let fif = model.frames_in_flight;
    if !h.reference.iter().any(|(f, _)| *f == fif) {
        let p = new_pass(&h.ctx, fif, None);
        h.reference.push((fif, p));
    }
    let i = h.reference.iter().position(|(f, _)| *f == fif).unwrap();
    let (_, mut pass) = h.reference.swap_remove(i);
    let fresh = new_pass_state(&mut pass, model);
    let frame = pass.prepare(0, &view(), &[light()]).unwrap();
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
    pass.set_settings(PassSettings { technique: Technique::Volumes(model.method), ..Default::default() }).unwrap();
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

fn sphere_of(s: &ModelSphere) -> Sphere {
    Sphere { center: transform(s.pos, 0).w_axis.truncate(), radius: s.radius as f64 * 0.25 }
}

/// A submitted frame not yet waited for: the model it was prepared from, and its place in
/// submission order.
struct InFlight {
    model: Model,
    serial: usize,
}

struct Sut {
    pass: ShadowPass,
    target: Target,
    casters: Vec<CasterId>,
    spheres: Vec<SphereId>,
    transparent: Vec<CasterId>,
    /// Per slot, its submitted frame until the slot is prepared again or the sequence ends
    /// (the host waits for the slot's fence then, and the comparison reads its stencil).
    in_flight: Vec<Option<InFlight>>,
    submitted: usize,
    /// Times `Technique::Compute` was set (each time the next way of recording its draws).
    compute_ways: usize,
}

impl Sut {
    /// Waits for `slot`'s submitted frame, if any, and compares its stencil with a fresh
    /// pass's holding the casters of the model it was prepared from (later calls must not
    /// have reached it).
    fn retire(&mut self, slot: usize) {
        let Some(serial) = self.in_flight.get(slot).and_then(Option::as_ref).map(|f| f.serial) else { return };
        // The entry stays until the fence has signalled: a panic before that leaves it for
        // `Drop` to wait on (the pass must not be dropped under the frame).
        if injected_failure() && serial >= 2 {
            panic!("{INJECTED}");
        }
        let fence = with_harness(|h| {
            let fence = h.slots[slot].fence;
            // SAFETY: the fence was submitted with the slot's frame.
            unsafe { h.ctx.device.wait_for_fences(&[fence], true, u64::MAX) }.unwrap();
            fence
        });
        let Some(InFlight { model, .. }) = self.in_flight[slot].take() else { return };
        let (got, want) = with_harness(|h| {
            // SAFETY: signalled above: its frame has completed.
            unsafe { h.ctx.device.reset_fences(&[fence]) }.unwrap();
            let got = stencil(&h.slots[slot].target);
            (got, reference_stencil(h, &model))
        });
        let differ = got.iter().zip(&want).filter(|(a, b)| a != b).count();
        let shadowed = want.iter().filter(|&&v| v != 0).count();
        assert_eq!(differ, 0, "slot {slot}: {differ} stencil bytes differ from a fresh pass's ({shadowed} shadowed there)");
        let rp = self.target == Target::RenderPass;
        count(0);
        if rp {
            count(4);
        }
        if shadowed > 0 {
            count(1);
            if rp {
                count(5);
            }
        }
    }

    /// Records `frame` into `slot`'s command buffer, then submits it with the slot's fence
    /// (not waited for) or resets it unsubmitted.
    fn record_slot(&mut self, model: &Model, slot: usize, frame: &PreparedFrame, submit: bool) {
        let target = self.target;
        let pass = &self.pass;
        with_harness(|h| {
            let s = &h.slots[slot];
            let d = &h.ctx.device;
            // SAFETY: the slot's buffer is not pending (its fence was waited for before the
            // slot was prepared) and its pool's buffers are resettable; recorded, then
            // submitted with the unsignalled fence, or reset unsubmitted.
            unsafe {
                d.reset_command_buffer(s.cb, vk::CommandBufferResetFlags::empty()).unwrap();
                let begin = vk::CommandBufferBeginInfo::default().flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT);
                d.begin_command_buffer(s.cb, &begin).unwrap();
                record(h, &s.target, s.cb, pass, frame, target);
                d.end_command_buffer(s.cb).unwrap();
                if submit {
                    let cbs = [s.cb];
                    d.queue_submit(h.ctx.queue, &[vk::SubmitInfo::default().command_buffers(&cbs)], s.fence).unwrap();
                } else {
                    d.reset_command_buffer(s.cb, vk::CommandBufferResetFlags::empty()).unwrap();
                }
            }
        });
        if submit {
            if self.in_flight.iter().any(Option::is_some) {
                count(6);
            }
            self.in_flight[slot] = Some(InFlight { model: model.clone(), serial: self.submitted });
            self.submitted += 1;
        }
    }
}

impl Drop for Sut {
    /// After a failure: waits for the frames still in flight (uncompared) before the pass is
    /// dropped, so that the next case finds the harness's slots idle.
    fn drop(&mut self) {
        let slots: Vec<usize> = (0..self.in_flight.len()).filter(|&i| self.in_flight[i].take().is_some()).collect();
        if slots.is_empty() {
            return;
        }
        let _ = HARNESS.try_with(|h| {
            if let Ok(mut h) = h.try_borrow_mut() {
                if let Some(h) = h.as_mut() {
                    for i in slots {
                        // SAFETY: the fence was submitted with the slot's frame.
                        unsafe {
                            let _ = h.ctx.device.wait_for_fences(&[h.slots[i].fence], true, u64::MAX);
                            let _ = h.ctx.device.reset_fences(&[h.slots[i].fence]);
                        }
                    }
                }
            }
        });
    }
}

struct Sequences;

impl StateMachineTest for Sequences {
    type SystemUnderTest = Sut;
    type Reference = Reference;

    fn init_test(model: &Model) -> Sut {
        let pass = with_harness(|h| {
            let rp = (model.target == Target::RenderPass).then_some(h.rp_target);
            new_pass(&h.ctx, model.frames_in_flight, rp)
        });
        let in_flight = (0..model.frames_in_flight).map(|_| None).collect();
        Sut { pass, target: model.target, casters: vec![], spheres: vec![], transparent: vec![], in_flight, submitted: 0, compute_ways: 0 }
    }

    fn apply(mut sut: Sut, model: &Model, step: Step) -> Sut {
        let meshes = meshes();
        match step {
            Step::AddCaster(c) => {
                let id = sut.pass.add_caster("c", &meshes[c.shape], transform(c.pos, c.turn)).unwrap();
                sut.casters.push(id);
            }
            Step::RemoveCaster(i) => sut.pass.remove_caster(sut.casters.remove(i)).unwrap(),
            Step::SetTransform(i, p, t) => sut.pass.set_transform(sut.casters[i], transform(p, t)).unwrap(),
            Step::UpdatePositions(i, k) => {
                // The model has applied the step: its caster i has this shape.
                let shape = model.casters[i].shape;
                sut.pass.update_positions(sut.casters[i], &deformed(shape, k)).unwrap()
            }
            Step::AddSphere(s) => sut.spheres.push(sut.pass.add_sphere_caster("s", sphere_of(&s), None).unwrap()),
            Step::RemoveSphere(i) => sut.pass.remove_sphere(sut.spheres.remove(i)).unwrap(),
            Step::SetSphere(i, s) => sut.pass.set_sphere(sut.spheres[i], sphere_of(&s)).unwrap(),
            Step::AddTransparent(c) => {
                let r = sut.pass.add_transparent_caster("t", &meshes[c.shape], transform(c.pos, c.turn), Vec3::splat(0.5));
                match sut.target {
                    Target::DynamicRendering => sut.transparent.push(r.unwrap()),
                    Target::RenderPass => {
                        let e = r.expect_err("a transparent caster accepted without transmit_format");
                        assert!(matches!(e, Error::Misuse(Misuse::NotConfigured { .. })), "{e}");
                        count(2);
                    }
                }
            }
            Step::RemoveTransparent(i) => sut.pass.remove_caster(sut.transparent.remove(i)).unwrap(),
            Step::SetMethod(m) => {
                // Compute: each time the next way of recording its volume draws the pass can
                // use (merged or per chunk: the same stencil every way).
                const WAYS: [ComputeDraws; 5] =
                    [ComputeDraws::Auto, ComputeDraws::PerChunk, ComputeDraws::PerRecord, ComputeDraws::Multi, ComputeDraws::Count];
                let way = WAYS[sut.compute_ways % WAYS.len()];
                sut.compute_ways += m.is_none() as usize;
                let way = if sut.pass.capabilities().compute_draws(way).is_ok() { way } else { ComputeDraws::Auto };
                let toggles = PassToggles { compute_draws: way, ..Default::default() };
                sut.pass.set_settings(PassSettings { technique: technique(m), toggles, ..Default::default() }).unwrap()
            }
            Step::Prepare(slot, fate) => {
                // As a host: before preparing a slot again, wait for its previous frame (here
                // also compared); the other slots' frames stay in flight.
                sut.retire(slot);
                let r = sut.pass.prepare(slot, &view(), &[light()]);
                if slot >= model.frames_in_flight {
                    assert!(r.is_err(), "slot {slot} of {} was accepted", model.frames_in_flight);
                    return sut;
                }
                let frame = r.unwrap();
                match fate {
                    FrameFate::Dropped => drop(frame),
                    FrameFate::Abandoned => {
                        sut.record_slot(model, slot, &frame, false);
                        sut.pass.abandon_frame(slot).unwrap();
                        count(3);
                    }
                    FrameFate::Submitted => sut.record_slot(model, slot, &frame, true),
                }
            }
            Step::Invalid(k) => {
                let err = match k {
                    0 => sut.pass.add_caster("nan", &Mesh::new(vec![Vec3::NAN; 3], vec![[0, 1, 2]]), DMat4::IDENTITY).err(),
                    1 => sut.pass.add_caster("singular", &meshes[0], DMat4::from_scale(DVec3::ZERO)).err(),
                    2 => with_harness(|h| sut.pass.remove_caster(h.other_caster).err()),
                    3 => with_harness(|h| sut.pass.set_transform(h.other_caster, DMat4::IDENTITY).err()),
                    4 => with_harness(|h| sut.pass.remove_sphere(h.other_sphere).err()),
                    5 => {
                        // `prepare`'s contract holds for a refused call too: slot 0 has retired.
                        sut.retire(0);
                        sut.pass.prepare(0, &view(), &[Light { radius: Some(-1.0), ..light() }]).err()
                    }
                    6 => sut.casters.first().and_then(|&id| sut.pass.update_positions(id, &[Vec3::ZERO]).err()),
                    _ => sut.pass.set_settings(PassSettings { technique: Technique::shadow_map(256), ..Default::default() }).err(),
                };
                // Case 6 needs a caster; every other refusal must happen.
                assert!(err.is_some() || (k == 6 && sut.casters.is_empty()), "invalid call {k} was accepted");
                if err.is_some() {
                    count(2);
                }
            }
        }
        sut
    }

    fn check_invariants(_sut: &Sut, _model: &Model) {
        with_harness(|h| {
            let errors = h.ctx.take_validation_errors();
            assert!(errors.is_empty(), "validation: {errors:#?}");
        });
    }

    /// The end of the sequence: the frames still in flight are waited for and compared, in
    /// the order they were submitted.
    fn teardown(mut sut: Sut, model: Model) {
        let mut slots: Vec<(usize, usize)> =
            sut.in_flight.iter().enumerate().filter_map(|(i, f)| f.as_ref().map(|f| (f.serial, i))).collect();
        slots.sort();
        for (_, slot) in slots {
            sut.retire(slot);
        }
        Self::check_invariants(&sut, &model);
    }
}

/// The panic [`a_failing_sequence_is_reported`] injects (`PASS_SEQUENCES_INJECT_FAILURE` set):
/// in `retire`, before the fence of the third frame submitted in a sequence is waited for.
const INJECTED: &str = "injected failure (PASS_SEQUENCES_INJECT_FAILURE)";

fn injected_failure() -> bool {
    std::env::var_os("PASS_SEQUENCES_INJECT_FAILURE").is_some()
}

fn cases() -> u32 {
    std::env::var("PASS_SEQUENCES_CASES").ok().and_then(|v| v.parse().ok()).unwrap_or(200)
}

/// On a failure, leaks the harness instead of letting the thread-local destructor tear the
/// device down under passes and frames still alive (that crashed the process before the test
/// harness printed the failure).
struct LeakHarnessOnPanic;

impl Drop for LeakHarnessOnPanic {
    fn drop(&mut self) {
        if std::thread::panicking() {
            std::mem::forget(HARNESS.with(|h| h.borrow_mut().take()));
        }
    }
}

/// A W x H depth-stencil image, its framebuffer of `render_pass` and its readback buffer.
fn host_target(ctx: &Context, render_pass: vk::RenderPass, name: &str) -> HostTarget {
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

fn destroy_target(ctx: &Context, mut t: HostTarget) {
    // SAFETY: every command buffer using the framebuffer has completed.
    unsafe { ctx.device.destroy_framebuffer(t.framebuffer, None) };
    t.image.destroy(ctx);
    t.readback.destroy(ctx);
}

#[test]
fn every_call_sequence_matches_a_fresh_pass() {
    let Some(ctx) = common::context() else { return };
    let (render_pass, rp_target) = host_render_pass(&ctx);
    let pool_info =
        vk::CommandPoolCreateInfo::default().queue_family_index(ctx.queue_family).flags(vk::CommandPoolCreateFlags::RESET_COMMAND_BUFFER);
    // SAFETY: a pool of the context's queue family, destroyed at the end.
    let pool = unsafe { ctx.device.create_command_pool(&pool_info, None) }.unwrap();
    let cb_info = vk::CommandBufferAllocateInfo::default().command_pool(pool).command_buffer_count(MAX_FRAMES_IN_FLIGHT as u32);
    // SAFETY: primary buffers of `pool`, freed with it.
    let cbs = unsafe { ctx.device.allocate_command_buffers(&cb_info) }.unwrap();
    let slots = cbs
        .into_iter()
        .enumerate()
        .map(|(i, cb)| {
            // SAFETY: an unsignalled fence, destroyed at the end.
            let fence = unsafe { ctx.device.create_fence(&vk::FenceCreateInfo::default(), None) }.unwrap();
            HostSlot { target: host_target(&ctx, render_pass, &format!("slot {i}")), cb, fence }
        })
        .collect();
    let reference_target = host_target(&ctx, render_pass, "reference");
    let mut other = new_pass(&ctx, 1, None);
    let other_caster = other.add_caster("other", &meshes()[0], DMat4::IDENTITY).unwrap();
    let other_sphere = other.add_sphere_caster("other", Sphere { center: DVec3::Y, radius: 0.5 }, None).unwrap();
    let _leak = LeakHarnessOnPanic;
    HARNESS.with(|h| {
        *h.borrow_mut() = Some(Harness {
            render_pass,
            rp_target,
            pool,
            slots,
            reference: vec![],
            reference_target,
            other,
            other_caster,
            other_sphere,
            ctx,
        })
    });
    // Failing seeds persist in proptest-regressions/pass_sequences.txt (`SourceParallel`, the
    // default, finds no lib.rs above tests/ and persists nothing) and are replayed first.
    let failure_persistence =
        Some(Box::new(FileFailurePersistence::Direct(concat!(env!("CARGO_MANIFEST_DIR"), "/proptest-regressions/pass_sequences.txt")))
            as Box<dyn proptest::test_runner::FailurePersistence>);
    // an injected failure is neither kept nor shrunk far
    let (failure_persistence, max_shrink_iters) = if injected_failure() { (None, 20) } else { (failure_persistence, 2000) };
    let config = Config { cases: cases(), max_shrink_iters, failure_persistence, ..Config::default() };
    let seed = common::proptest_seed("pass_sequences", 0x2026_1206);
    for fif in 1..=MAX_FRAMES_IN_FLIGHT {
        FRAMES_IN_FLIGHT.with(|f| f.set(fif));
        let rng = common::seeded_rng(seed.wrapping_add(fif as u64));
        let mut runner = proptest::test_runner::TestRunner::new_with_rng(config.clone(), rng);
        let result = runner.run(&Reference::sequential_strategy(30..31), |(initial, transitions, seen)| {
            Sequences::test_sequential(config.clone(), initial, transitions, seen);
            Ok(())
        });
        if let Err(e) = result {
            panic!("frames_in_flight {fif} (UMBRAGE_PROPTEST_SEED={seed}): {e}");
        }
    }
    let [compared, shadowed, refused, abandoned, rp_compared, rp_shadowed, overlapped] = COUNTS.with(|c| c.get());
    eprintln!(
        "{compared} frames compared ({shadowed} with a shadow; {rp_compared} ({rp_shadowed}) of them in the host's render pass), \
         {overlapped} submitted with an earlier frame in flight, {refused} calls refused, {abandoned} frames abandoned"
    );
    // The comparisons must have had something to compare, under both target models, and
    // frames must have overlapped.
    assert!(shadowed * 3 >= compared && compared >= cases() as usize, "{shadowed} of {compared} frames had a shadow");
    let dr_shadowed = shadowed - rp_shadowed;
    assert!(rp_shadowed * 5 >= shadowed && dr_shadowed * 5 >= shadowed, "{rp_shadowed} of {shadowed} shadowed frames in the render pass");
    assert!(overlapped * 5 >= compared, "{overlapped} of {compared} frames submitted with another in flight");
    let mut h = HARNESS.with(|h| h.borrow_mut().take()).unwrap();
    h.reference.clear();
    drop(h.other);
    // SAFETY: every submission has completed (each sequence's teardown waited for its frames).
    unsafe {
        for s in h.slots.drain(..) {
            h.ctx.device.destroy_fence(s.fence, None);
            destroy_target(&h.ctx, s.target);
        }
        h.ctx.device.destroy_command_pool(h.pool, None);
        h.ctx.device.destroy_render_pass(h.render_pass, None);
    }
    destroy_target(&h.ctx, h.reference_target);
    h.ctx.check_validation().unwrap();
}

/// A failing sequence must come out as a test failure naming its seed and its case, never as
/// a crash: the test re-runs itself in a child process with a failure injected while a frame
/// is still in flight (the window in which CI once saw the process abort with `free():
/// corrupted unsorted chunks` and no message), and checks the child's exit and output.
#[test]
fn a_failing_sequence_is_reported() {
    if injected_failure() {
        return; // the child runs only the sequences
    }
    let out = std::process::Command::new(std::env::current_exe().unwrap())
        .args(["every_call_sequence_matches_a_fresh_pass", "--exact", "--nocapture", "--test-threads", "1"])
        .env("PASS_SEQUENCES_INJECT_FAILURE", "1")
        .env("PASS_SEQUENCES_CASES", "4")
        .output()
        .unwrap();
    let text = format!("{}{}", String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    let tail = &text[text.len().saturating_sub(3000)..];
    // 101: the test harness's failure exit (a crash has no code, a signal instead)
    assert_eq!(out.status.code(), Some(101), "the child did not fail cleanly ({:?}):\n{tail}", out.status);
    for needle in ["UMBRAGE_PROPTEST_SEED=", INJECTED, "minimal failing input"] {
        assert!(text.contains(needle), "the child's output lacks {needle:?}:\n{tail}");
    }
    assert!(!text.contains("Validation Error"), "a validation error in the failure path:\n{tail}");
}
