//! The whole per-light planner on `bench/vertex` (36 casters, ~435k triangles): culling, case
//! selection, facing bits, possible silhouettes and index emission, for every method, as
//! `umbrage bench` runs it once per frame and light; `streaming_sum` beside them reads the
//! bytes the planner must at least touch (every caster's positions and triangles) as a plain
//! streaming sum, so its time can be held against memory speed in the same run.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use std::hint::black_box;
use umbrage::shadow::{plan_light, Caster, Method, PlanInput};

fn bench(c: &mut Criterion) {
    let scene = umbrage::scene::load("bench/vertex").expect("bench/vertex loads");
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
    g.bench_function("streaming_sum", |b| b.iter(|| black_box(black_box(&plain).iter().fold(0u64, |a, &x| a.wrapping_add(x as u64)))));
    for method in [Method::McGuire, Method::ZFail, Method::ZPass] {
        let input = PlanInput { camera: cam, width: w, height: h, view_proj: vp, light, method };
        g.bench_function(method.name(), |b| b.iter(|| black_box(plan_light(black_box(&input), &casters).casters.len())));
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
