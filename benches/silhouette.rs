//! Possible-silhouette extraction (facing bits + edge scan) on UV spheres of 10k, 100k and
//! 1M triangles, as the planner does it per light: triangle planes precomputed once
//! (`FacePlanes::new`, outside the timed loops), facing as one f32 dot product per triangle
//! with packed bits and the exact fallback near the planes (threads from
//! `PLANES_PARALLEL_THRESHOLD` triangles), then the edge scan on the packed bits.
//! `edge_scan_serial` is `EdgeScan`'s scan (distance classes a facing word at a time, the
//! other edges by lookups), `edge_scan` the per-edge scan of the full edge records.
//! `streaming_sum` is a plain streaming read of the same bytes the new path reads (the four
//! plane arrays and `EdgeScan::bytes`), in the same run, so the throughput of the
//! other functions (the group's throughput is those bytes) can be compared to memory speed.
//! `facing+silhouette_shuffled` is the same work on the same sphere with its triangles in
//! random order: no distance classes and no decidable blocks, the worst case (compare its time:
//! it reads more bytes than the group's throughput counts).

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use glam::Vec4;
use std::hint::black_box;
use umbrage::geom::silhouette::{possible_silhouette_packed_into, EdgeScan, FacePlanes, SilhouetteEdge};
use umbrage::geom::topology::Topology;
#[path = "../src/geom/testmesh.rs"]
#[allow(dead_code)]
mod testmesh;
use testmesh::{shuffled, uv_sphere};
use umbrage::geom::Mesh;

fn bytes_of(planes: &FacePlanes, scan: &EdgeScan) -> u64 {
    (planes.bytes() + scan.bytes()) as u64
}

/// The plane arrays as the facing pass sees them (same length and layout: 4 f32 arrays).
struct PlainArrays {
    a: Vec<f32>,
    b: Vec<f32>,
    c: Vec<f32>,
    d: Vec<f32>,
}

fn streaming_sum(p: &PlainArrays, pairs: &[[u32; 2]]) -> u64 {
    let mut s = [0u32; 8];
    for (((a, b), c), d) in p.a.chunks_exact(8).zip(p.b.chunks_exact(8)).zip(p.c.chunks_exact(8)).zip(p.d.chunks_exact(8)) {
        for k in 0..8 {
            s[k] = s[k].wrapping_add(a[k].to_bits() ^ b[k].to_bits() ^ c[k].to_bits() ^ d[k].to_bits());
        }
    }
    let mut t = 0u64;
    for e in pairs {
        t = t.wrapping_add((e[0] ^ e[1]) as u64);
    }
    s.iter().map(|&x| x as u64).sum::<u64>().wrapping_add(t)
}

fn bench(c: &mut Criterion) {
    let light = Vec4::new(3.0, 2.0, 1.0, 1.0);
    let threads = std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1);
    for (name, slices, stacks) in [("10k", 100u32, 51u32), ("100k", 317, 159), ("1M", 1000, 501)] {
        let topo = Topology::build(&uv_sphere(1.0, slices, stacks));
        assert!(topo.is_closed_manifold());
        let planes = FacePlanes::new(&topo.mesh);
        let scan = EdgeScan::new(topo.manifold_edges.clone());
        // as many 8-byte records as the scan reads (class masks and residual pairs)
        let pairs: Vec<[u32; 2]> = (0..scan.bytes() / 8).map(|i| [i as u32 ^ 1, i as u32 ^ 3]).collect();
        let words = planes.bytes() / 16;
        let plain = PlainArrays {
            a: (0..words).map(|i| i as f32).collect(),
            b: (0..words).map(|i| (i * 3) as f32).collect(),
            c: (0..words).map(|i| (i * 7) as f32).collect(),
            d: (0..words).map(|i| (i * 11) as f32).collect(),
        };
        let bytes = bytes_of(&planes, &scan);
        let mut g = c.benchmark_group(format!("silhouette/{name}"));
        g.throughput(Throughput::Bytes(bytes));
        if slices >= 1000 {
            g.sample_size(10);
        }
        let tris = topo.mesh.triangles.len();
        let mut bits: Vec<u64> = Vec::new();
        let mut sil: Vec<SilhouetteEdge> = Vec::new();
        g.bench_function(BenchmarkId::new("streaming_sum", tris), |b| {
            b.iter(|| black_box(streaming_sum(black_box(&plain), black_box(&pairs))))
        });
        g.bench_function(BenchmarkId::new("facing+silhouette", tris), |b| {
            b.iter(|| {
                planes.facing_packed_auto(&topo.mesh, black_box(light), false, &mut bits);
                sil.clear();
                scan.scan_into(&bits, &mut sil);
                black_box(sil.len())
            })
        });
        g.bench_function(BenchmarkId::new("facing_serial", tris), |b| {
            b.iter(|| {
                planes.facing_packed(&topo.mesh, black_box(light), false, &mut bits);
                black_box(bits.len())
            })
        });
        g.bench_function(BenchmarkId::new("facing", tris), |b| {
            b.iter(|| {
                planes.facing_packed_threads(&topo.mesh, black_box(light), false, threads, &mut bits);
                black_box(bits.len())
            })
        });
        planes.facing_packed(&topo.mesh, light, false, &mut bits);
        g.bench_function(BenchmarkId::new("edge_scan_serial", tris), |b| {
            b.iter(|| {
                sil.clear();
                scan.scan_into(black_box(&bits), &mut sil);
                black_box(sil.len())
            })
        });
        g.bench_function(BenchmarkId::new("edge_scan", tris), |b| {
            b.iter(|| {
                sil.clear();
                possible_silhouette_packed_into(&topo.manifold_edges, black_box(&bits), &mut sil);
                black_box(sil.len())
            })
        });
        // The worst case for the edge scan's distance classes and the facing's block bounds:
        // the same sphere with its triangles in a fixed pseudo-random order.
        let shuffled = Topology::build(&shuffled(&uv_sphere(1.0, slices, stacks)));
        let (splanes, sscan) = (FacePlanes::new(&shuffled.mesh), EdgeScan::new(shuffled.manifold_edges.clone()));
        g.bench_function(BenchmarkId::new("facing+silhouette_shuffled", tris), |b| {
            b.iter(|| {
                splanes.facing_packed_auto(&shuffled.mesh, black_box(light), false, &mut bits);
                sil.clear();
                sscan.scan_into(&bits, &mut sil);
                black_box(sil.len())
            })
        });
        g.finish();
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
