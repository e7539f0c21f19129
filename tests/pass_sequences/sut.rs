//! The system under test: a pass driven through the model's steps as a host would, its
//! submitted frames in flight until their slots are prepared again, then compared.

use crate::harness::{count, new_pass, record, reference_stencil, stencil, with_harness, HARNESS};
use crate::model::{deformed, sphere_of, technique, FrameFate, Model, Reference, Step, Target};
use crate::{injected_failure, light, light_of, meshes, transform, view, view_of, INJECTED};
use ash::vk;
use glam::{DMat4, DVec3, Vec3};
use proptest_state_machine::StateMachineTest;
use umbrage::error::Misuse;
use umbrage::geom::{Light, Mesh};
use umbrage::pass::{CasterId, ComputeDraws, Counter, PassSettings, PassToggles, PreparedFrame, ShadowPass, SphereId, Technique};
use umbrage::Error;

/// A submitted frame not yet waited for: the model it was prepared from, and its place in
/// submission order.
struct InFlight {
    model: Model,
    serial: usize,
}

pub(crate) struct Sut {
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

pub(crate) struct Sequences;

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
                sut.pass.set_settings(PassSettings { technique: technique(m), toggles, keep: model.keep, ..Default::default() }).unwrap()
            }
            // the next prepare takes them
            Step::MoveLight(_) | Step::MoveCamera(_) => {}
            Step::SetKeep(keep) => {
                let s = sut.pass.settings();
                sut.pass.set_settings(PassSettings { keep, ..s }).unwrap()
            }
            Step::Prepare(slot, fate) => {
                // As a host: before preparing a slot again, wait for its previous frame (here
                // also compared); the other slots' frames stay in flight.
                sut.retire(slot);
                let r = sut.pass.prepare(slot, &view_of(model.eye), &[light_of(model.light)]);
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
                    _ => {
                        // Refused on every device: ray query writes the stencil, never a float count.
                        let s = PassSettings { technique: Technique::RayQuery, counter: Counter::Float, ..Default::default() };
                        sut.pass.set_settings(s).err()
                    }
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
