//! Possible-silhouette extraction (facing bits + edge scan) on UV spheres of 10k, 100k and
//! 1M triangles, next to a plain streaming read (sum) over the same bytes (positions +
//! indices + edge records) in the same run, so throughput can be compared to memory speed.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use glam::Vec4;
use std::hint::black_box;
use umbrage::geom::silhouette::{facing_bits, facing_bits_threads, possible_silhouette, possible_silhouette_serial};
use umbrage::geom::topology::Topology;
use umbrage::shadow::testmesh::uv_sphere;

fn bytes_of(t: &Topology) -> u64 {
    (t.mesh.positions.len() * 12 + t.mesh.triangles.len() * 12 + t.manifold_edges.len() * std::mem::size_of_val(&t.manifold_edges[0]))
        as u64
}

fn streaming_sum(t: &Topology) -> u64 {
    let mut s = 0u64;
    for p in &t.mesh.positions {
        s = s.wrapping_add((p.x.to_bits() ^ p.y.to_bits() ^ p.z.to_bits()) as u64);
    }
    for tri in &t.mesh.triangles {
        s = s.wrapping_add((tri[0] ^ tri[1] ^ tri[2]) as u64);
    }
    for e in &t.manifold_edges {
        s = s.wrapping_add((e.a ^ e.b ^ e.t0 ^ e.t1) as u64);
    }
    s
}

fn bench(c: &mut Criterion) {
    let light = Vec4::new(3.0, 2.0, 1.0, 1.0);
    for (name, slices, stacks) in [("10k", 100u32, 51u32), ("100k", 317, 159), ("1M", 1000, 501)] {
        let topo = Topology::build(&uv_sphere(1.0, slices, stacks));
        assert!(topo.is_closed_manifold());
        let bytes = bytes_of(&topo);
        let mut g = c.benchmark_group(format!("silhouette/{name}"));
        g.throughput(Throughput::Bytes(bytes));
        if slices >= 1000 {
            g.sample_size(10);
        }
        let tris = topo.mesh.triangles.len();
        g.bench_function(BenchmarkId::new("streaming_sum", tris), |b| b.iter(|| black_box(streaming_sum(black_box(&topo)))));
        g.bench_function(BenchmarkId::new("facing+silhouette", tris), |b| {
            b.iter(|| {
                let f = facing_bits(&topo.mesh, black_box(light), false);
                black_box(possible_silhouette(&topo.manifold_edges, &f).len())
            })
        });
        g.bench_function(BenchmarkId::new("facing_serial", tris), |b| {
            b.iter(|| black_box(facing_bits_threads(&topo.mesh, black_box(light), false, 1).len()))
        });
        g.bench_function(BenchmarkId::new("facing", tris), |b| {
            b.iter(|| black_box(facing_bits(&topo.mesh, black_box(light), false).len()))
        });
        let f = facing_bits(&topo.mesh, light, false);
        g.bench_function(BenchmarkId::new("edge_scan_serial", tris), |b| {
            b.iter(|| black_box(possible_silhouette_serial(&topo.manifold_edges, black_box(&f)).len()))
        });
        g.bench_function(BenchmarkId::new("edge_scan", tris), |b| {
            b.iter(|| black_box(possible_silhouette(&topo.manifold_edges, black_box(&f)).len()))
        });
        g.finish();
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
