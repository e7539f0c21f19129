//! What a frame of `ShadowPass::prepare` costs on the CPU, and what it sends, with the plans
//! kept across frames (`PassSettings::keep`) and without, while the camera walks, casters
//! move or lights move. The numbers of `docs/frame-cost/example.md` came from here (those
//! of `docs/frame-cost.md` come from `umbrage bench --suite frame-cost`).
//!
//! Scenes: `vertex` (`bench/vertex`: 36 casters, ~435k triangles), any other built-in scene
//! or scene file (each with its lights or `--lights N` made around it), and `level`: the
//! built-in `bench/level` (a grid of rooms with walls, pillars, crates and a character each;
//! 1,088 casters at its 8 x 8 rooms, two bounded point or spot lights a room: 128), or with
//! `--rooms N` the same level with N x N rooms, the camera on the scene's walk.
//!
//! Run: `cargo run --release --example frame_cost -- [vertex|level] [--frames N] [--lights N]
//! [--rooms N] [--modes off,keep,keep1]`. Every frame's `prepare` is timed whole (wall clock)
//! and split as the pass reports it (`cpu_ms`: cull, plan, record); medians over the frames
//! after the first two (the first plans every pair: it is reported on its own as `cold`), of
//! the calling thread's CPU time (`CLOCK_THREAD_CPUTIME_ID`: what other processes run
//! meanwhile does not count, but with planning threads their share is not in it) and of the
//! wall clock. Linux, 64-bit.
//! Each mode runs in its own pass, one after the other, on the calling thread (the keep
//! modes' planning on `plan_threads` threads: `keep` every core, `keep1` one).

use glam::{DMat4, DVec3, Vec3};
use std::time::Instant;
use umbrage::geom::{Camera, Light, Mesh};
use umbrage::pass::{PassSettings, ShadowPass, ShadowPassDesc, ShadowView, Technique};
use umbrage::shadow::Method;

const W: u32 = 1280;
const H: u32 = 720;

/// A scene as the example drives it: casters (mesh, transform), lights, and the camera path.
struct World {
    casters: Vec<(String, Mesh, DMat4)>,
    lights: Vec<Light>,
    /// Casters that move in the `casters` case.
    movers: Vec<usize>,
    /// The eye and target at frame `k`.
    walk: Box<dyn Fn(usize) -> (Vec3, Vec3)>,
}

/// A built-in scene (or scene file) with its casters and lights (or `lights` made around it),
/// the camera orbiting its target.
fn scene_world(name: &str, lights: Option<usize>) -> World {
    let scene = umbrage_scene::load(name).unwrap_or_else(|e| panic!("{name}: {e}"));
    let casters: Vec<(String, Mesh, DMat4)> =
        scene.meshes.iter().filter(|m| m.casts_shadow).map(|m| (m.name.clone(), m.mesh.clone(), m.transform.as_dmat4())).collect();
    let cam = scene.camera.clone();
    let centre = cam.target;
    let lights = match lights {
        None => scene.lights.clone(),
        Some(n) => (0..n)
            .map(|i| {
                let a = i as f32 * 2.399;
                let r = 4.0 + (i % 7) as f32;
                Light::point(centre + Vec3::new(r * a.cos(), 6.0 + (i % 3) as f32, r * a.sin()))
            })
            .collect(),
    };
    let n = casters.len();
    let eye0 = cam.eye - centre;
    World {
        casters,
        lights,
        movers: (0..n).step_by(n.div_ceil(4).max(1)).collect(),
        // orbit the scene's camera about its target, a third of a degree a frame
        walk: Box::new(move |k| {
            let a = k as f32 * 0.006;
            (centre + Vec3::new(eye0.x * a.cos() - eye0.z * a.sin(), eye0.y, eye0.x * a.sin() + eye0.z * a.cos()), centre)
        }),
    }
}

/// The built-in `bench/level` (`rooms` = 8), or the same level with another number of rooms a
/// side (`umbrage_scene::level::level_toml`): its casters and lights, the camera on the scene's
/// walk (frame `k` at `k / 30` s), the characters that turn in the scene as the casters that move.
fn level(rooms: usize) -> World {
    let (scene, motion) = if rooms == umbrage_scene::level::LEVEL_ROOMS {
        umbrage_scene::load_animated("bench/level").expect("bench/level")
    } else {
        let text = umbrage_scene::level::level_toml(rooms);
        let no_objs = umbrage_scene::file::ObjSource::Dir(std::path::Path::new(""));
        umbrage_scene::file::parse_animated(&text, "level", no_objs).expect("level")
    };
    let mut casters = Vec::new();
    let mut movers = Vec::new();
    for (i, m) in scene.meshes.iter().enumerate().filter(|(_, m)| m.casts_shadow) {
        if motion.spins.get(i).is_some_and(Option::is_some) {
            movers.push(casters.len());
        }
        casters.push((m.name.clone(), m.mesh.clone(), m.transform.as_dmat4()));
    }
    let rest = scene.camera.clone();
    World {
        casters,
        lights: scene.lights.clone(),
        movers,
        walk: Box::new(move |k| match &motion.camera {
            Some(path) => path.eye_target(&rest, k as f64 / 30.0),
            None => (rest.eye, rest.target),
        }),
    }
}

#[derive(Clone, Copy, PartialEq)]
enum Motion {
    Camera,
    Casters,
    Lights,
    /// Every light moves every frame: every pair planned (the parallel planning's case).
    AllLights,
}

struct Row {
    /// The calling thread's CPU time in `prepare` (its planning threads' not included).
    cpu_ms: f64,
    wall_ms: f64,
    min_ms: f64,
    cull: f64,
    plan: f64,
    record: f64,
    bytes: u64,
    pairs: u64,
    replanned: u64,
    kept: u64,
    kept_bytes: u64,
    cold_ms: f64,
}

/// `struct timespec` of 64-bit Linux.
#[repr(C)]
struct Timespec {
    tv_sec: i64,
    tv_nsec: i64,
}

extern "C" {
    /// POSIX `clock_gettime` (libc).
    fn clock_gettime(clock: i32, tp: *mut Timespec) -> i32;
}

/// Linux's `CLOCK_THREAD_CPUTIME_ID`.
const CLOCK_THREAD_CPUTIME_ID: i32 = 3;

/// This thread's CPU time so far, ns: what `prepare` costs the calling thread, whatever else
/// the machine runs meanwhile (0 where the clock fails).
fn thread_cpu_ns() -> u64 {
    let mut t = Timespec { tv_sec: 0, tv_nsec: 0 };
    // SAFETY: `t` is a valid, writable timespec of this target's layout (64-bit Linux).
    let r = unsafe { clock_gettime(CLOCK_THREAD_CPUTIME_ID, &mut t) };
    if r == 0 {
        t.tv_sec as u64 * 1_000_000_000 + t.tv_nsec as u64
    } else {
        0
    }
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    if v.is_empty() {
        0.0
    } else {
        v[v.len() / 2]
    }
}

fn run(ctx: &umbrage::gpu::Context, world: &World, motion: Motion, keep: bool, threads: usize, frames: usize) -> Row {
    let desc = ShadowPassDesc { depth_stencil_format: ctx.depth_format, frames_in_flight: 1, plan_threads: threads, ..Default::default() };
    let mut pass = ShadowPass::new(&ctx.instance, ctx.physical, &ctx.device, (*ctx.allocator).clone(), &desc).expect("pass");
    pass.set_settings(PassSettings { technique: Technique::Volumes(Method::McGuire), keep, ..Default::default() }).expect("settings");
    let ids: Vec<_> = world.casters.iter().map(|(n, m, t)| pass.add_caster(n, m, *t).expect("caster")).collect();
    let mut lights = world.lights.clone();
    let mut cpu = vec![];
    let (mut wall, mut cull, mut plan, mut record, mut bytes) = (vec![], vec![], vec![], vec![], vec![]);
    let (mut pairs, mut replanned, mut kept, mut kept_bytes) = (vec![], vec![], vec![], vec![]);
    let mut cold_ms = 0.0;
    for k in 0..frames + 2 {
        let (eye, target) = (world.walk)(k);
        let cam = Camera { eye, target, fov_y_deg: 60.0, ..Camera::default() };
        // (the view is relative to the eye: the pass composes it in f64)
        let view = ShadowView {
            eye: eye.as_dvec3(),
            view: glam::camera::rh::view::look_at_mat4(Vec3::ZERO, target - eye, cam.up),
            proj: cam.proj_infinite(W as f32 / H as f32),
            width: W,
            height: H,
        };
        match motion {
            Motion::Camera => {}
            Motion::Casters => {
                for (j, &i) in world.movers.iter().enumerate().take(8) {
                    let wobble = DVec3::new((k as f64 * 0.1 + j as f64).sin() * 0.3, 0.0, (k as f64 * 0.1).cos() * 0.3);
                    pass.set_transform(ids[i], DMat4::from_translation(wobble) * world.casters[i].2).expect("move");
                }
            }
            Motion::AllLights => {
                for (j, l) in lights.iter_mut().enumerate() {
                    l.position = world.lights[j].position + Vec3::new((k as f32 * 0.1).sin() * 0.5, 0.0, (k as f32 * 0.1).cos() * 0.5);
                }
            }
            Motion::Lights => {
                for (j, l) in lights.iter_mut().enumerate().step_by((world.lights.len() / 4).max(1)).take(4) {
                    l.position = world.lights[j].position + Vec3::new((k as f32 * 0.1).sin() * 0.5, 0.0, (k as f32 * 0.1).cos() * 0.5);
                }
            }
        }
        let c0 = thread_cpu_ns();
        let t0 = Instant::now();
        let f = pass.prepare(0, &view, &lights).expect("prepare");
        let ms = t0.elapsed().as_secs_f64() * 1e3;
        let cpu_ms = thread_cpu_ns().saturating_sub(c0) as f64 * 1e-6;
        if k == 0 {
            cold_ms = ms;
            // the casters' vertex uploads reach the GPU once
            // SAFETY: recording outside rendering; one_shot waits for the submission.
            ctx.one_shot(|cb| unsafe { pass.cmd_before_rendering(cb, &f).expect("upload") }).expect("one_shot");
        }
        if k >= 2 {
            cpu.push(cpu_ms);
            wall.push(ms);
            cull.push(f.cpu_ms.cull);
            plan.push(f.cpu_ms.plan + f.cpu_ms.silhouettes);
            record.push(f.cpu_ms.record);
            bytes.push(f.totals.bytes_sent as f64);
            pairs.push(f.totals.pairs_total as f64);
            replanned.push(f.totals.pairs_replanned as f64);
            kept.push(f.totals.pairs_kept as f64);
            kept_bytes.push(f.totals.kept_bytes as f64);
        }
    }
    Row {
        cpu_ms: median(cpu),
        min_ms: wall.iter().copied().fold(f64::INFINITY, f64::min),
        wall_ms: median(wall),
        cull: median(cull),
        plan: median(plan),
        record: median(record),
        bytes: median(bytes) as u64,
        pairs: median(pairs) as u64,
        replanned: median(replanned) as u64,
        kept: median(kept) as u64,
        kept_bytes: median(kept_bytes) as u64,
        cold_ms,
    }
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let opt = |name: &str| args.iter().position(|a| a == name).and_then(|i| args.get(i + 1)).cloned();
    let frames: usize = opt("--frames").and_then(|v| v.parse().ok()).unwrap_or(30);
    let rooms: usize = opt("--rooms").and_then(|v| v.parse().ok()).unwrap_or(8);
    let lights: Option<usize> = opt("--lights").and_then(|v| v.parse().ok());
    let modes = opt("--modes").unwrap_or_else(|| "off,keep1,keep".into());
    let scene = args.first().filter(|a| !a.starts_with("--")).cloned().unwrap_or_else(|| "vertex".into());
    let world = match scene.as_str() {
        "level" => level(rooms),
        "vertex" => scene_world("bench/vertex", lights),
        name => scene_world(name, lights),
    };
    let ctx = umbrage::gpu::Context::new().expect("a Vulkan device");
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    println!(
        "scene {scene}: {} casters, {} lights, {frames} frames at {W}x{H}, McGuire; {cores} cores; device {}",
        world.casters.len(),
        world.lights.len(),
        ctx.info.name
    );
    println!("| motion | mode | thread CPU ms | wall ms | fastest wall ms | cull | plan | record | bytes sent | pairs | replanned | kept | kept bytes | first frame ms |");
    println!("|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
    let motions = opt("--motions").unwrap_or_else(|| "camera,casters,lights".into());
    for (motion, mname) in [
        (Motion::Camera, "camera only"),
        (Motion::Casters, "casters moving"),
        (Motion::Lights, "lights moving"),
        (Motion::AllLights, "every light moving"),
    ] {
        let key = match motion {
            Motion::Camera => "camera",
            Motion::Casters => "casters",
            Motion::Lights => "lights",
            Motion::AllLights => "all-lights",
        };
        if !motions.split(',').any(|m| m == key) {
            continue;
        }
        for mode in modes.split(',') {
            let (keep, threads, label) = match mode {
                "off" => (false, 1, "keep off"),
                "keep1" => (true, 1, "keep on, 1 thread"),
                "keep2" => (true, 2, "keep on, 2 threads"),
                _ => (true, 0, "keep on, every core"),
            };
            let r = run(&ctx, &world, motion, keep, threads, frames);
            println!(
                "| {mname} | {label} | {:.3} | {:.3} | {:.3} | {:.3} | {:.3} | {:.3} | {} | {} | {} | {} | {} | {:.1} |",
                r.cpu_ms, r.wall_ms, r.min_ms, r.cull, r.plan, r.record, r.bytes, r.pairs, r.replanned, r.kept, r.kept_bytes, r.cold_ms
            );
        }
    }
}
