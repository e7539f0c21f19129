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

#[path = "../common/mod.rs"]
mod common;
mod harness;
mod model;
mod sut;

use ash::vk;
use glam::{DMat4, DVec3, Vec3};
use harness::{
    destroy_target, host_render_pass, host_target, new_pass, Harness, HostSlot, LeakHarnessOnPanic, COUNTS, HARNESS, MAX_FRAMES_IN_FLIGHT,
};
use model::{Reference, FRAMES_IN_FLIGHT};
use proptest::test_runner::{Config, FileFailurePersistence};
use proptest_state_machine::{ReferenceStateMachine, StateMachineTest};
use sut::Sequences;
use umbrage::geom::{Light, Mesh, Sphere};
use umbrage::pass::ShadowView;
use umbrage_scene::shapes;

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

/// The panic [`a_failing_sequence_is_reported`] injects (`PASS_SEQUENCES_INJECT_FAILURE` set):
/// in `retire`, before the fence of the third frame submitted in a sequence is waited for.
const INJECTED: &str = "injected failure (PASS_SEQUENCES_INJECT_FAILURE)";

fn injected_failure() -> bool {
    std::env::var_os("PASS_SEQUENCES_INJECT_FAILURE").is_some()
}

fn cases() -> u32 {
    std::env::var("PASS_SEQUENCES_CASES").ok().and_then(|v| v.parse().ok()).unwrap_or(200)
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
        .env("UMBRAGE_VALIDATION", "1")
        .output()
        .unwrap();
    let text = format!("{}{}", String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    let tail = &text[text.len().saturating_sub(3000)..];
    // 101: the test harness's failure exit (a crash has no code, a signal instead)
    assert_eq!(out.status.code(), Some(101), "the child did not fail cleanly ({:?}):\n{tail}", out.status);
    for needle in ["UMBRAGE_PROPTEST_SEED=", INJECTED, "minimal failing input"] {
        assert!(text.contains(needle), "the child's output lacks {needle:?}:\n{tail}");
    }
    // umbrage's own tag for every validation message it reports (gpu::context), not the layer's
    // wording, which changes between layer versions.
    assert!(!text.contains("[vulkan validation]"), "a validation message in the failure path:\n{tail}");
}
