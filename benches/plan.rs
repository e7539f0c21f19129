//! The whole per-light planner on `bench/vertex` (36 casters, ~435k triangles): culling, case
//! selection, facing bits, possible silhouettes and index emission, for every method, as
//! `umbrage bench` runs it once per frame and light.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use std::hint::black_box;
use umbrage::shadow::{plan_light, Caster, Method, PlanInput};

fn bench(c: &mut Criterion) {
    let scene = umbrage::scene::load("bench/vertex").expect("bench/vertex loads");
    let casters: Vec<Caster> =
        scene.meshes.iter().filter(|m| m.casts_shadow).map(|m| Caster::from_scene_mesh(m).expect("caster builds")).collect();
    let tris: usize = casters.iter().map(|c| c.triangle_count).sum();
    let (w, h) = (640u32, 480u32);
    let cam = &scene.camera;
    let vp = cam.proj_infinite(w as f32 / h as f32) * cam.view();
    let light = &scene.lights[0];
    let mut g = c.benchmark_group("plan/bench-vertex");
    g.throughput(Throughput::Elements(tris as u64));
    g.sample_size(20);
    for method in [Method::McGuire, Method::ZFail, Method::ZPass] {
        let input = PlanInput { camera: cam, width: w, height: h, view_proj: vp, light, method };
        g.bench_function(method.name(), |b| b.iter(|| black_box(plan_light(black_box(&input), &casters).casters.len())));
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
