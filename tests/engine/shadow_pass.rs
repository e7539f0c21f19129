//! The embeddable `ShadowPass` on its own: misuse gets a clear `Err` (never a panic or a
//! corrupted frame), deforming and removed casters behave, and buffers of removed casters are
//! released only once every frame in flight has retired.

use crate::common;
#[path = "../../src/geom/testmesh.rs"]
#[allow(dead_code)]
mod testmesh;

use glam::{DMat4, DVec3, Vec3};
use umbrage::geom::{Camera, Light, LightKind, Mesh};
use umbrage::pass::{ShadowPass, ShadowPassDesc, ShadowView};
use umbrage_scene::shapes;

fn pass(ctx: &umbrage::gpu::Context, desc: &ShadowPassDesc) -> umbrage::Result<ShadowPass> {
    ShadowPass::new(&ctx.instance, ctx.physical, &ctx.device, (*ctx.allocator).clone(), desc)
}

fn desc(ctx: &umbrage::gpu::Context) -> ShadowPassDesc {
    ShadowPassDesc { depth_stencil_format: ctx.depth_format, ..Default::default() }
}

fn view() -> ShadowView {
    let cam = Camera { eye: Vec3::new(0.0, 3.0, 6.0), target: Vec3::ZERO, ..Default::default() };
    ShadowView {
        eye: cam.eye.as_dvec3(),
        view: glam::camera::rh::view::look_at_mat4(Vec3::ZERO, cam.target - cam.eye, cam.up),
        proj: cam.proj_infinite(4.0 / 3.0),
        width: 160,
        height: 120,
    }
}

fn light() -> Light {
    Light {
        kind: LightKind::Point,
        position: Vec3::new(1.0, 5.0, 2.0),
        direction: Vec3::NEG_Y,
        color: Vec3::ONE,
        intensity: 1.0,
        radius: None,
        cone_deg: 45.0,
        area: None,
    }
}

fn allocations(ctx: &umbrage::gpu::Context) -> usize {
    ctx.allocator().generate_report().allocations.len()
}

#[test]
fn misuse_is_a_clear_error() {
    let Some(ctx) = common::context() else { return };
    // Depth-stencil formats without 8 stencil bits (or without depth).
    for format in [ash::vk::Format::D32_SFLOAT, ash::vk::Format::D16_UNORM, ash::vk::Format::S8_UINT, ash::vk::Format::R8G8B8A8_UNORM] {
        let e = pass(&ctx, &ShadowPassDesc { depth_stencil_format: format, ..desc(&ctx) }).err().expect("refused");
        assert!(e.to_string().contains("stencil"), "{format:?}: {e}");
    }
    for frames in [0, 65] {
        let e = pass(&ctx, &ShadowPassDesc { frames_in_flight: frames, ..desc(&ctx) }).err().expect("refused");
        assert!(e.to_string().contains("frames_in_flight"), "{e}");
    }
    {
        let mut p = pass(&ctx, &desc(&ctx)).unwrap();
        let cube = shapes::cuboid(Vec3::ONE);
        // NaN and singular transforms.
        assert!(p.add_caster("nan", &cube, DMat4::from_translation(DVec3::new(f64::NAN, 0.0, 0.0))).is_err());
        assert!(p.add_caster("flat", &cube, DMat4::from_scale(DVec3::new(1.0, 0.0, 1.0))).is_err());
        // Empty and NaN meshes.
        assert!(p.add_caster("empty", &umbrage::geom::Mesh { positions: vec![], triangles: vec![] }, DMat4::IDENTITY).is_err());
        let mut bad = cube.clone();
        bad.positions[0].x = f32::NAN;
        assert!(p.add_caster("nan-vertex", &bad, DMat4::IDENTITY).is_err());
        // Transparent casters need a light-intensity map format.
        assert!(p.add_transparent_caster("glass", &cube, DMat4::IDENTITY, Vec3::splat(0.5)).is_err());

        let id = p.add_caster("cube", &cube, DMat4::IDENTITY).unwrap();
        assert!(p.set_transform(id, DMat4::from_scale(DVec3::splat(f64::INFINITY))).is_err());
        assert!(p.update_positions(id, &cube.positions[1..]).is_err(), "wrong vertex count");
        let mut nan = cube.positions.clone();
        nan[3] = Vec3::splat(f32::NAN);
        assert!(p.update_positions(id, &nan).is_err(), "NaN position");
        // Slots out of range, non-finite views and lights.
        assert!(p.prepare(2, &view(), &[light()]).is_err());
        let mut v = view();
        v.eye.x = f64::NAN;
        assert!(p.prepare(0, &v, &[light()]).is_err());
        let mut l = light();
        l.position.y = f32::INFINITY;
        assert!(p.prepare(0, &view(), &[l]).is_err());
        // A removed id is refused everywhere, and never confused with a newer caster.
        p.remove_caster(id).unwrap();
        assert!(p.remove_caster(id).is_err());
        assert!(p.set_transform(id, DMat4::IDENTITY).is_err());
        assert!(p.update_positions(id, &cube.positions).is_err());
        let newer = p.add_caster("cube2", &cube, DMat4::IDENTITY).unwrap();
        assert_ne!(newer, id);
        assert!(p.set_transform(id, DMat4::IDENTITY).is_err());
        p.prepare(0, &view(), &[light()]).unwrap();
    }
    ctx.check_validation().unwrap();
}

/// Ids carry the pass that made them: another pass's caster, transparent-caster or sphere id
/// is refused by every call that takes one (a typed `ForeignId` naming both passes), and
/// nothing of either pass changes.
#[test]
fn another_passes_ids_are_refused() {
    use umbrage::error::{Error, Misuse};
    let Some(ctx) = common::context() else { return };
    {
        let mut a = pass(&ctx, &desc(&ctx)).unwrap();
        let mut b = pass(&ctx, &desc(&ctx)).unwrap();
        let cube = shapes::cuboid(Vec3::ONE);
        // Both passes' first caster has the same index and generation: only the pass differs.
        let ida = a.add_caster("a", &cube, DMat4::IDENTITY).unwrap();
        let idb = b.add_caster("b", &cube, DMat4::from_translation(DVec3::new(0.0, 1.0, 0.0))).unwrap();
        let sa = a.add_sphere_caster("ball", umbrage::geom::Sphere { center: DVec3::new(2.0, 1.0, 0.0), radius: 0.5 }, None).unwrap();
        let foreign = |r: umbrage::Result<()>, what: &str| match r {
            Err(Error::Misuse(Misuse::ForeignId { what: w, owner, this, .. })) => {
                assert_eq!(w, what);
                assert_ne!(owner, this);
            }
            other => panic!("{what}: expected ForeignId, got {other:?}"),
        };
        let bounds = b.casters()[0].object_bounds;
        foreign(b.set_transform(ida, DMat4::from_scale(DVec3::splat(3.0))), "caster");
        foreign(b.update_positions(ida, &cube.positions), "caster");
        foreign(b.remove_caster(ida), "caster");
        foreign(b.caster_kind(ida).map(|_| ()), "caster");
        foreign(b.set_sphere(sa, umbrage::geom::Sphere { center: DVec3::ZERO, radius: 1.0 }), "sphere caster");
        foreign(b.remove_sphere(sa), "sphere caster");
        foreign(a.set_transform(idb, DMat4::IDENTITY), "caster");
        foreign(a.remove_caster(idb), "caster");
        // Nothing changed: B still has its caster where it was, A its caster and sphere.
        assert_eq!(b.casters().len(), 1);
        assert_eq!(b.casters()[0].object_bounds, bounds);
        assert_eq!(b.caster_id(0), Some(idb));
        assert_eq!(a.casters().len(), 1);
        assert_eq!(a.spheres().count(), 1);
        b.set_transform(idb, DMat4::IDENTITY).unwrap();
        a.remove_caster(ida).unwrap();
        a.remove_sphere(sa).unwrap();
    }
    ctx.check_validation().unwrap();
}

/// A caster too big for 16-bit indices is split into chunks, never refused.
#[test]
fn big_casters_are_split_into_16_bit_chunks() {
    let Some(ctx) = common::context() else { return };
    {
        let mut p = pass(&ctx, &desc(&ctx)).unwrap();
        let sphere = testmesh::uv_sphere(1.0, 400, 200);
        assert!(sphere.positions.len() > 65536);
        p.add_caster("sphere", &sphere, DMat4::IDENTITY).unwrap();
        assert!(p.casters()[0].chunks.len() >= 3, "{} chunks", p.casters()[0].chunks.len());
        let f = p.prepare(0, &view(), &[light()]).unwrap();
        assert!(f.totals.triangles.total() > 0);
        assert_eq!(f.pending_uploads(), p.casters()[0].chunks.len());
    }
    ctx.check_validation().unwrap();
}

/// New positions plan exactly like a caster added with those positions; removed casters'
/// buffers are freed once every ring slot has been prepared again.
#[test]
fn deforming_and_removing_casters() {
    let Some(ctx) = common::context() else { return };
    {
        let mut p = pass(&ctx, &desc(&ctx)).unwrap();
        let cube = shapes::cuboid(Vec3::ONE);
        let big: Vec<Vec3> = cube.positions.iter().map(|&v| v * 2.0 + Vec3::new(0.0, 1.0, 0.0)).collect();
        let id = p.add_caster("cube", &cube, DMat4::IDENTITY).unwrap();
        p.update_positions(id, &big).unwrap();
        let deformed = p.prepare(0, &view(), &[light()]).unwrap();

        let mut q = pass(&ctx, &desc(&ctx)).unwrap();
        let mut moved = cube.clone();
        moved.positions = big.clone();
        q.add_caster("cube", &moved, DMat4::IDENTITY).unwrap();
        let fresh = q.prepare(0, &view(), &[light()]).unwrap();
        let stats = |f: &umbrage::pass::PreparedFrame| {
            f.lights
                .iter()
                .flat_map(|l| l.stats.casters.iter().map(|c| (c.case, c.silhouette_edges, c.triangles.total())))
                .collect::<Vec<_>>()
        };
        assert_eq!(stats(&deformed), stats(&fresh));
        assert_eq!(p.casters()[0].object_bounds, q.casters()[0].object_bounds);

        // Deferred release: the removed caster's chunk buffer lives until slots 1 and 0 have
        // both been prepared again (frames in flight may still read it). First a steady state:
        // both slots have their streams, the upload's staging copy is gone.
        // No frame here is recorded, so the upload stays pending (every frame carries it) and
        // its staging copy lives on with it: once the caster is removed, both go together.
        let qid = q.caster_id(0).unwrap();
        q.prepare(1, &view(), &[light()]).unwrap();
        q.prepare(0, &view(), &[light()]).unwrap();
        let before = allocations(&ctx);
        q.remove_caster(qid).unwrap();
        assert_eq!(allocations(&ctx), before, "released too early");
        q.prepare(1, &view(), &[light()]).unwrap();
        assert_eq!(allocations(&ctx), before, "slot 0's frame may still use it");
        q.prepare(0, &view(), &[light()]).unwrap();
        assert_eq!(allocations(&ctx), before - 2, "the chunk and its pending upload's staging, released once every slot retired");
    }
    ctx.check_validation().unwrap();
}
