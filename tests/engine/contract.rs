//! `docs/contract.md`: every public input of `ShadowPass` a host fills in (each field of
//! `Light` for every kind, `ShadowView`, `ShadowPassDesc`, `PassSettings`, meshes, transforms,
//! sphere casters and transmittances), its valid range, and the typed error it gets outside it.
//! The table is this file's `rows()` (its groups in `contract/table.rs`): the test walks it value by value, at and just past each
//! edge, through the public call that takes the input (`prepare`, `ShadowPass::new`,
//! `set_settings`, `add_caster`, ...) on a real pass with validation on; every accepted value
//! must succeed and every refused one must fail with the row's error naming the field. The page
//! is regenerated from the same rows and the test fails when the committed one differs (the new
//! one is written: commit it).

use crate::common;

use glam::{DMat4, DVec3, Mat4, Vec3};
use umbrage::error::Misuse;
use umbrage::geom::{Light, LightKind, Mesh, Sphere};
use umbrage::gpu::Context;
use umbrage::pass::{
    ComputeDraws, Counter, DepthMode, IndexFormat, PassSettings, ShadowPass, ShadowPassDesc, ShadowView, Technique, MAX_CONE_DEG,
    MAX_TARGET_SIZE,
};
use umbrage::shadow::Method;
use umbrage::Error;
use umbrage_scene::shapes;

mod table;

const DOC: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/docs/contract.md");

/// The error a refused value must get.
#[derive(Clone, Copy)]
enum Expect {
    /// `Misuse::Argument { what }` with `what` the field.
    Argument(&'static str),
    /// `Error::InvalidDesc { field }`.
    Desc(&'static str),
    /// `Error::Mesh` whose message contains the text.
    Mesh(&'static str),
    /// `Error::Unsupported` whose message contains the text (what the device lacks).
    Unsupported(&'static str),
}

impl Expect {
    fn holds(self, e: &Error) -> bool {
        match (self, e) {
            (Expect::Argument(f), Error::Misuse(Misuse::Argument { what, .. })) => *what == f,
            (Expect::Desc(f), Error::InvalidDesc { field, .. }) => *field == f,
            (Expect::Mesh(t), Error::Mesh { .. }) | (Expect::Unsupported(t), Error::Unsupported(_)) => e.to_string().contains(t),
            _ => false,
        }
    }

    fn describe(self) -> String {
        match self {
            Expect::Argument(f) => format!("`Misuse::Argument` naming `{f}`"),
            Expect::Desc(f) => format!("`Error::InvalidDesc` naming `{f}`"),
            Expect::Mesh(t) => format!("`Error::Mesh` naming the mesh (\"{t}\")"),
            Expect::Unsupported(t) => format!("`Error::Unsupported` (\"{t}\")"),
        }
    }
}

/// One public call with one input changed.
type Probe = Box<dyn Fn(&mut Harness) -> umbrage::Result<()>>;

struct Row {
    /// The input and the call that checks it.
    input: &'static str,
    field: &'static str,
    range: &'static str,
    expect: Expect,
    accepted: Vec<(String, Probe)>,
    refused: Vec<(String, Probe)>,
}

/// Fields drop in declaration order: the pass before the context whose device it uses, also
/// when a probe panics (a context dropped first would leave the pass's drop calling a
/// destroyed device).
struct Harness {
    pass: ShadowPass,
    ctx: Context,
}

impl Harness {
    fn desc(&self) -> ShadowPassDesc {
        ShadowPassDesc { depth_stencil_format: self.ctx.depth_format, ..Default::default() }
    }
    fn new_pass(&self, desc: &ShadowPassDesc) -> umbrage::Result<()> {
        ShadowPass::new(&self.ctx.instance, self.ctx.physical, &self.ctx.device, (*self.ctx.allocator).clone(), desc).map(drop)
    }
}

fn view() -> ShadowView {
    let eye = Vec3::new(0.0, 3.0, 6.0);
    ShadowView {
        eye: eye.as_dvec3(),
        view: glam::camera::rh::view::look_at_mat4(Vec3::ZERO, -eye, Vec3::Y),
        proj: glam::camera::rh::proj::vulkan::perspective_infinite(1.0, 4.0 / 3.0, 0.1),
        width: 160,
        height: 120,
    }
}

fn light(kind: LightKind) -> Light {
    Light { kind, direction: Vec3::new(0.2, -1.0, 0.1), cone_deg: 60.0, ..Light::point(Vec3::new(1.0, 5.0, 2.0)) }
}

/// Probes that each take the input `base` makes, change it by `set(value)`, and hand it to the
/// public call `call`.
fn probes<I: 'static, T: Copy + std::fmt::Debug + 'static>(
    values: &[T],
    base: impl Fn(&Harness) -> I + Clone + 'static,
    set: fn(&mut I, T),
    call: fn(&mut Harness, I) -> umbrage::Result<()>,
) -> Vec<(String, Probe)> {
    values
        .iter()
        .map(|&v| {
            let base = base.clone();
            let probe: Probe = Box::new(move |h: &mut Harness| {
                let mut input = base(h);
                set(&mut input, v);
                call(h, input)
            });
            (format!("{v:?}"), probe)
        })
        .collect()
}

/// `prepare` with one light of `kind` changed by `set(value)`.
fn light_probes<T: Copy + std::fmt::Debug + 'static>(kind: LightKind, values: &[T], set: fn(&mut Light, T)) -> Vec<(String, Probe)> {
    probes(values, move |_| light(kind), set, |h, l| h.pass.prepare(0, &view(), &[l]).map(drop))
}

/// `prepare` with the view changed by `set(value)`.
fn view_probes<T: Copy + std::fmt::Debug + 'static>(values: &[T], set: fn(&mut ShadowView, T)) -> Vec<(String, Probe)> {
    probes(values, |_| view(), set, |h, w| h.pass.prepare(0, &w, &[light(LightKind::Point)]).map(drop))
}

/// `ShadowPass::new` with the description changed by `set(value)`.
fn desc_probes<T: Copy + std::fmt::Debug + 'static>(values: &[T], set: fn(&mut ShadowPassDesc, T)) -> Vec<(String, Probe)> {
    probes(values, |h| h.desc(), set, |h, d| h.new_pass(&d))
}

/// `set_settings` with the settings changed by `set(value)` (the defaults restored after).
fn settings_probes<T: Copy + std::fmt::Debug + 'static>(values: &[T], set: fn(&mut PassSettings, T)) -> Vec<(String, Probe)> {
    probes(
        values,
        |_| PassSettings::default(),
        set,
        |h, s| {
            let r = h.pass.set_settings(s);
            h.pass.set_settings(PassSettings::default()).unwrap();
            r
        },
    )
}

fn mesh_probes(values: Vec<(&'static str, Mesh)>) -> Vec<(String, Probe)> {
    values
        .into_iter()
        .map(|(label, m)| {
            let probe: Probe = Box::new(move |h: &mut Harness| {
                let id = h.pass.add_caster("probe", &m, DMat4::IDENTITY)?;
                h.pass.remove_caster(id)
            });
            (label.to_string(), probe)
        })
        .collect()
}

fn transform_probes(values: Vec<(&'static str, DMat4)>) -> Vec<(String, Probe)> {
    values
        .into_iter()
        .map(|(label, t)| {
            let probe: Probe = Box::new(move |h: &mut Harness| {
                let id = h.pass.add_caster("probe", &shapes::cuboid(Vec3::ONE), t)?;
                h.pass.remove_caster(id)
            });
            (label.to_string(), probe)
        })
        .collect()
}

fn sphere_probes(values: Vec<(&'static str, Sphere, Option<u32>)>) -> Vec<(String, Probe)> {
    values
        .into_iter()
        .map(|(label, s, n)| {
            let probe: Probe = Box::new(move |h: &mut Harness| {
                let id = h.pass.add_sphere_caster("probe", s, n)?;
                h.pass.remove_sphere(id)
            });
            (label.to_string(), probe)
        })
        .collect()
}

fn transmittance_probes(values: &[Vec3]) -> Vec<(String, Probe)> {
    values
        .iter()
        .map(|&t| {
            let probe: Probe = Box::new(move |h: &mut Harness| {
                let desc = ShadowPassDesc { transmit_format: Some(ash::vk::Format::R16G16B16A16_SFLOAT), ..h.desc() };
                let mut p = ShadowPass::new(&h.ctx.instance, h.ctx.physical, &h.ctx.device, (*h.ctx.allocator).clone(), &desc)?;
                p.add_transparent_caster("probe", &shapes::cuboid(Vec3::ONE), DMat4::IDENTITY, t).map(drop)
            });
            (format!("{t}"), probe)
        })
        .collect()
}

const NAN: f32 = f32::NAN;
const INF: f32 = f32::INFINITY;

fn rows(ctx: &Context) -> Vec<Row> {
    let mut rows = table::light_rows();
    rows.extend(table::view_rows());
    rows.extend(table::desc_rows(ctx));
    rows.extend(table::settings_rows());
    rows.extend(table::mesh_rows());
    rows.extend(table::sphere_and_transmittance_rows());
    rows
}

fn markdown(rows: &[Row]) -> String {
    let mut s = String::from(
        "# The embedding contract: every input's range\n\n\
         Generated by `cargo test --test engine contract::` from its table, which the same test walks value by value on a real \
         `ShadowPass` (lavapipe, validation on): each value in the last column goes through the public call named in \
         the first, the accepted ones must succeed and the refused ones must fail with the error in the fourth column, \
         naming the field. Nothing is clamped silently: a value outside its range is an error, and a field a light's \
         kind does not use is ignored (said so). A refused call changes nothing (a refused `prepare` leaves that slot's \
         earlier frame valid).\n\n\
         | input, call | field | valid range | outside it | tried: accepted / refused |\n|---|---|---|---|---|\n",
    );
    for r in rows {
        let list = |v: &[(String, Probe)]| {
            if v.is_empty() {
                "—".to_string()
            } else {
                v.iter().map(|(l, _)| format!("`{l}`")).collect::<Vec<_>>().join(", ")
            }
        };
        let outside = if r.refused.is_empty() { "— (nothing to refuse on this device)".to_string() } else { r.expect.describe() };
        s.push_str(&format!(
            "| {} | `{}` | {} | {} | {} / {} |\n",
            r.input,
            r.field,
            r.range,
            outside,
            list(&r.accepted),
            list(&r.refused)
        ));
    }
    s.push_str(
        "\nDevice-dependent refusals (a sample count, format or feature the device lacks) are `Error::Unsupported` \
         naming what is missing; `ShadowPass::capabilities_for` answers them without a device ([devices.md](devices.md)). \
         Ids of another pass or of a removed caster are `Misuse::ForeignId` / `Misuse::UnknownId`; a slot out of range \
         `Misuse::SlotOutOfRange` (tests/engine/pass_contract.rs, tests/engine/shadow_pass.rs).\n\n\
         Call sequences: `tests/pass_sequences/` drives random sequences of every public call (casters, sphere and \
         transparent casters added, moved, deformed and removed; settings; `prepare` on any slot with the frame dropped, \
         submitted, or recorded and abandoned; invalid arguments and another pass's ids interleaved) against a reference \
         model (proptest-state-machine), and after every submitted frame compares the stencil, byte for byte, with a \
         pass holding exactly the model's casters; `frames_in_flight` 1 to 3, 200 sequences of 30 steps each in CI, each sequence under one target model (dynamic rendering, \
         or recorded inside the host's `VkRenderPass`: both compared with the same dynamic-rendering reference), switching between \
         volume methods and `Technique::Compute` (McGuire's stencil, byte for byte). Frames overlap as a host's do: each slot has \
         its own command buffer, fence and image, and a submitted frame is waited for (and compared) only when its slot is \
         prepared again, the host's later calls happening while it is in flight (about 2,300 frames compared on lavapipe 22.3.6, \
         half in the render pass and about 850 submitted with an earlier frame in flight, all byte-identical). \
         Before a release: `PASS_SEQUENCES_CASES=5000 cargo test --release --test pass_sequences`.\n",
    );
    s
}

#[test]
fn every_documented_range_is_checked_at_and_past_its_edges() {
    let Some(ctx) = common::context() else { return };
    let desc = ShadowPassDesc { depth_stencil_format: ctx.depth_format, ..Default::default() };
    let pass = ShadowPass::new(&ctx.instance, ctx.physical, &ctx.device, (*ctx.allocator).clone(), &desc).unwrap();
    let rows = rows(&ctx);
    let doc = markdown(&rows);
    let mut h = Harness { pass, ctx };
    let mut failures = Vec::new();
    let (mut accepted, mut refused) = (0, 0);
    for r in &rows {
        for (label, probe) in &r.accepted {
            accepted += 1;
            if let Err(e) = probe(&mut h) {
                failures.push(format!("{} = {label}: refused ({e})", r.field));
            }
        }
        for (label, probe) in &r.refused {
            refused += 1;
            match probe(&mut h) {
                Ok(()) => failures.push(format!("{} = {label}: accepted", r.field)),
                Err(e) if !r.expect.holds(&e) => failures.push(format!("{} = {label}: wrong error {e:?}", r.field)),
                Err(_) => {}
            }
        }
    }
    h.ctx.check_validation().unwrap();
    drop(h.pass);
    assert!(
        failures.is_empty(),
        "{} of {accepted} accepted and {refused} refused values broke the contract:\n{}",
        failures.len(),
        failures.join("\n")
    );
    assert!(refused > 60, "only {refused} refused values tried");
    let old = std::fs::read_to_string(DOC).unwrap_or_default();
    if old != doc {
        std::fs::write(DOC, &doc).unwrap();
        panic!("docs/contract.md was stale: the regenerated one is written, commit it");
    }
}
