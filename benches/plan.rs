//! The whole per-light planner on `bench/vertex` (36 casters, ~435k triangles): culling, case
//! selection, facing bits, possible silhouettes and index emission, for every method, as
//! `umbrage bench` runs it once per frame and light; `streaming_sum` beside them reads the
//! bytes the planner must at least touch (every caster's positions and triangles) as a plain
//! streaming sum, so its time can be held against memory speed in the same run. After the
//! group, paired rounds (as in `benches/silhouette.rs`) compare `mcguire` with the streaming
//! sum, and its CPU level's copies of the facing and the edge scan (`umbrage::geom::cpu`) with
//! the portable ones.
//!
//! `plan/buildings` (only when `target/assets/buildings.obj` is there: `scripts/fetch-assets.sh`)
//! plans the OpenFOAM city block (400k triangles, 26 parts) for its two lights, as the file
//! orders its triangles and shuffled, each as loaded (`Caster::new`: the silhouette structures
//! in the load-time spatial order) and scanning in the mesh's own triangle order (no reordering,
//! and no per-edge tags: the planner reads a silhouette edge's chunk and ends from the chunk tables).

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use std::hint::black_box;
use umbrage::geom::cpu;
use umbrage::geom::silhouette::{EdgeScan, FacePlanes};
use umbrage::geom::Mesh;
use umbrage::shadow::{plan_light, Caster, Method, PlanInput};
#[macro_use]
#[path = "common/levels.rs"]
mod levels;
#[path = "common/paired.rs"]
mod paired;
use paired::{paired_line, paired_ratios};
#[path = "../src/geom/testmesh.rs"]
#[allow(dead_code)]
mod testmesh;

per_cpu_level! {
    /// The streaming sum of the casters' bytes; compiled per x86-64 level like the facing and the
    /// scan (`umbrage::geom::cpu`: the same target list), so that both sides get the same
    /// instructions.
    fn plain_sum(plain: &[u32]) -> u64 {
        plain.iter().fold(0u64, |a, &x| a.wrapping_add(x as u64))
    }
}

/// `caster` with its silhouette structures in the mesh's own triangle order (no reordering).
fn in_caller_order(caster: &Caster) -> Caster {
    let mut c = caster.clone();
    c.planes = FacePlanes::new(c.mesh());
    for p in &mut c.parts {
        p.scan = EdgeScan::new(p.scan.edges().to_vec());
    }
    c
}

/// The OpenFOAM city block, z-up, rotated y-up, with a street light among the buildings and a
/// directional light (as tests/parts.rs renders it).
const CITY: &str = r#"
[camera]
eye = [120.0, 260.0, 60.0]
target = [120.0, 0.0, -90.0]
[[light]]
kind = "point"
position = [120.0, 12.0, -95.0]
[[light]]
kind = "directional"
direction = [-0.3, -1.0, -0.45]
[[mesh]]
name = "city"
obj = "OBJ"
rotate_deg = [-90.0, 0.0, 0.0]
"#;

fn buildings(c: &mut Criterion) {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/target/assets/buildings.obj");
    if !std::path::Path::new(path).is_file() {
        eprintln!("NOTE: {path} missing (scripts/fetch-assets.sh): plan/buildings not measured");
        return;
    }
    let scene = umbrage_scene::load_str(&CITY.replace("OBJ", path), "buildings", std::path::Path::new(".")).expect("city loads");
    let city = &scene.meshes[0];
    let loaded = city.caster().expect("city caster");
    let shuffled = Caster::new("city", &testmesh::shuffled(&city.mesh), city.transform).expect("shuffled city caster");
    let (w, h) = (640u32, 480u32);
    let cam = &scene.camera;
    let vp = cam.proj_infinite(w as f32 / h as f32) * cam.view();
    let mut g = c.benchmark_group("plan/buildings");
    g.throughput(Throughput::Elements(loaded.triangle_count as u64));
    g.sample_size(20);
    let variants = [
        ("file_order/reordered", loaded.clone()),
        ("file_order/caller_order", in_caller_order(&loaded)),
        ("shuffled/reordered", shuffled.clone()),
        ("shuffled/caller_order", in_caller_order(&shuffled)),
    ];
    for (li, light) in scene.lights.iter().enumerate() {
        let input = PlanInput { camera: cam, width: w, height: h, view_proj: vp, light, method: Method::McGuire };
        for (name, caster) in &variants {
            let casters = std::slice::from_ref(caster);
            g.bench_function(format!("{name}/light{li}-{:?}", light.kind).to_lowercase(), |b| {
                b.iter(|| black_box(plan_light(black_box(&input), casters).casters.len()))
            });
        }
    }
    g.finish();
}

fn bench(c: &mut Criterion) {
    let scene = umbrage_scene::load("bench/vertex").expect("bench/vertex loads");
    let casters: Vec<Caster> = scene.meshes.iter().filter(|m| m.casts_shadow).map(|m| m.caster().expect("caster builds")).collect();
    let tris: usize = casters.iter().map(|c| c.triangle_count).sum();
    let (w, h) = (640u32, 480u32);
    let cam = &scene.camera;
    let vp = cam.proj_infinite(w as f32 / h as f32) * cam.view();
    let light = &scene.lights[0];
    let mut g = c.benchmark_group("plan/bench-vertex");
    g.throughput(Throughput::Elements(tris as u64));
    g.sample_size(20);
    // The same bytes, read plainly: positions (3 x f32) and triangles (3 x u32) of every caster.
    let plain: Vec<u32> = scene
        .meshes
        .iter()
        .filter(|m| m.casts_shadow)
        .flat_map(|m| {
            let p = m.mesh.positions.iter().flat_map(|v| [v.x.to_bits(), v.y.to_bits(), v.z.to_bits()]);
            p.chain(m.mesh.triangles.iter().flat_map(|t| t.iter().copied()).collect::<Vec<_>>())
        })
        .collect();
    g.bench_function("streaming_sum", |b| b.iter(|| black_box(plain_sum(black_box(&plain)))));
    for method in [Method::McGuire, Method::ZFail, Method::ZPass] {
        let input = PlanInput { camera: cam, width: w, height: h, view_proj: vp, light, method };
        g.bench_function(method.name(), |b| b.iter(|| black_box(plan_light(black_box(&input), &casters).casters.len())));
    }
    g.finish();
    // `mcguire` in paired rounds (batches of about 10 ms): against the streaming sum, and its
    // CPU level's copies of the facing and the scan against the portable ones
    let input = PlanInput { camera: cam, width: w, height: h, view_proj: vp, light, method: Method::McGuire };
    let plan = |portable: bool| {
        cpu::set_portable_only(portable);
        black_box(plan_light(black_box(&input), &casters).casters.len());
    };
    let stream = || {
        black_box(plain_sum(black_box(&plain)));
    };
    let batch = 30;
    println!(
        "{}",
        paired_line("plan/bench-vertex/paired: mcguire", "streaming_sum's", paired_ratios(stream, || plan(false), batch), batch)
    );
    let what = format!("plan/bench-vertex/cpu-level: mcguire with the {} copies", cpu::level());
    println!("{}", paired_line(&what, "the portable copies'", paired_ratios(|| plan(true), || plan(false), batch), batch));
    cpu::set_portable_only(false);
}

criterion_group!(benches, bench, buildings);
criterion_main!(benches);
