//! The reference model: the live casters, sphere casters, transparent casters and settings,
//! and the host's calls as its transitions (proptest-state-machine).

use crate::{meshes, transform};
use glam::Vec3;
use proptest::prelude::*;
use proptest_state_machine::ReferenceStateMachine;
use umbrage::geom::Sphere;
use umbrage::pass::Technique;
use umbrage::shadow::Method;

#[derive(Clone, Debug, PartialEq)]
pub(crate) struct ModelCaster {
    pub(crate) shape: usize,
    pub(crate) pos: [i8; 3],
    pub(crate) turn: u8,
    /// `update_positions` with the mesh scaled by `1 + k / 8` about its origin.
    pub(crate) deform: u8,
}

#[derive(Clone, Debug, PartialEq)]
pub(crate) struct ModelSphere {
    pos: [i8; 3],
    radius: u8,
}

/// Where the system under test records its determination
/// ([`TargetModel`](umbrage::pass::TargetModel)): its own rendering instances, or inside the
/// harness's render pass (which has no colour target, so `transmit_format` and with it
/// transparent casters are refused there).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Target {
    DynamicRendering,
    RenderPass,
}

#[derive(Clone, Debug)]
pub(crate) struct Model {
    pub(crate) frames_in_flight: usize,
    pub(crate) target: Target,
    pub(crate) casters: Vec<ModelCaster>,
    pub(crate) spheres: Vec<ModelSphere>,
    pub(crate) transparent: Vec<ModelCaster>,
    pub(crate) method: Method,
    /// The light ([`crate::light_of`]) and camera ([`crate::view_of`]) of the next frames.
    pub(crate) light: u8,
    pub(crate) eye: u8,
    /// [`PassSettings::keep`](umbrage::pass::PassSettings::keep) of the system under test
    /// (the reference plans from scratch: the pictures must not depend on it).
    pub(crate) keep: bool,
}

#[derive(Clone, Copy, Debug)]
pub(crate) enum FrameFate {
    Dropped,
    Submitted,
    /// Recorded, then the command buffer reset instead of submitted (`abandon_frame`).
    Abandoned,
}

#[derive(Clone, Debug)]
pub(crate) enum Step {
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
    /// Moves the light (index into [`crate::light_of`]'s lights).
    MoveLight(u8),
    /// Moves the camera (index into [`crate::EYES`]).
    MoveCamera(u8),
    /// Turns keeping plans across frames on or off.
    SetKeep(bool),
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
pub(crate) fn technique(m: Option<Method>) -> Technique {
    m.map_or(Technique::Compute, Technique::Volumes)
}

pub(crate) struct Reference;

// The configuration of the current run: frames in flight.
thread_local! {
    pub(crate) static FRAMES_IN_FLIGHT: std::cell::Cell<usize> = const { std::cell::Cell::new(2) };
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
                light: 0,
                eye: 0,
                keep: true,
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
            2 => (0u8..5).prop_map(Step::MoveLight),
            2 => (0u8..4).prop_map(Step::MoveCamera),
            1 => prop_oneof![3 => Just(true), 1 => Just(false)].prop_map(Step::SetKeep),
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
            Step::MoveLight(k) => state.light = *k,
            Step::MoveCamera(k) => state.eye = *k,
            Step::SetKeep(k) => state.keep = *k,
            Step::Prepare(..) | Step::Invalid(_) => {}
        }
        state
    }
}

pub(crate) fn deformed(shape: usize, k: u8) -> Vec<Vec3> {
    let s = 1.0 + k as f32 / 8.0;
    meshes()[shape].positions.iter().map(|p| *p * s).collect()
}

pub(crate) fn sphere_of(s: &ModelSphere) -> Sphere {
    Sphere { center: transform(s.pos, 0).w_axis.truncate(), radius: s.radius as f64 * 0.25 }
}
