//! Possible-silhouette extraction (facing bits + edge scan) on UV spheres of 10k, 100k and
//! 1M triangles, as the planner does it per light, on the structures a caster built by
//! `Caster::new` holds: triangle planes and edge scan precomputed once at load, in the caster's
//! scan order (each part's triangles spatially sorted by meshoptimizer; outside the timed
//! loops), facing as one f32 dot product per triangle with packed bits, whole 64-triangle
//! blocks decided at once and the exact fallback near the planes (threads from
//! `PLANES_PARALLEL_THRESHOLD` triangles), then the edge scan on the packed bits.
//!
//! * `facing+silhouette`: the sphere in its generator's (row) order, loaded as a caster;
//! * `facing+silhouette_shuffled`: the same sphere with its triangles in a fixed pseudo-random
//!   order, loaded as a caster (the load-time reordering makes it the ordered one's equal);
//! * `facing+silhouette_caller_order` and `facing+silhouette_shuffled_caller_order`: the same
//!   two meshes scanned in their own triangle order (no reordering: the shuffled one is the
//!   worst case, with no decidable blocks and no skippable word pairs);
//! * `facing_serial`, `edge_scan_serial`: the two halves of `facing+silhouette`;
//!   `edge_scan` the per-edge scan of the full edge records;
//! * `streaming_sum`: a plain streaming read of the bytes `facing+silhouette` may read (the
//!   four plane arrays and `EdgeScan::bytes`), in the same run, so the throughput of the other
//!   functions (the group's throughput is those bytes) can be compared to memory speed.
//!
//! After each size's group, **paired rounds** compare `facing+silhouette` with `streaming_sum`
//! directly: 31 rounds, each a batch of one then a batch of the other (about 10 ms each), and
//! the ratio of the two batch times per round. A shared or throttled host changes speed from
//! one second to the next, which moves criterion's separate estimates apart; inside one round
//! both see the same host. The line printed gives the median round's ratio (streaming time
//! over facing+silhouette time: above 1 is faster than the streaming read) and its spread.
//!
//! A second paired line per size compares the copy of the facing and the scan compiled for
//! this CPU's x86-64 level (`umbrage::geom::cpu`; `streaming_sum` is compiled per level too)
//! with the portable copy.
//!
//! The `load/1M` group times `Caster::new` on the 1M sphere, ordered and shuffled, and the
//! reordering alone (`TriangleOrder::spatial`).

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use glam::Mat4;
use glam::Vec4;
use std::hint::black_box;
use umbrage::geom::cpu;
use umbrage::geom::silhouette::{possible_silhouette_packed_into, EdgeScan, FacePlanes, SilhouetteEdge};
use umbrage::geom::topology::Topology;
use umbrage::geom::TriangleOrder;
use umbrage::shadow::Caster;
#[macro_use]
#[path = "common/levels.rs"]
mod levels;
#[path = "common/paired.rs"]
mod paired;
use paired::{paired_line, paired_ratios};
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

per_cpu_level! {
    /// Compiled per x86-64 level like the facing and the scan (`umbrage::geom::cpu`: the same
    /// target list), so that the comparison gives both sides the same instructions.
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
}

fn bench(c: &mut Criterion) {
    let light = Vec4::new(3.0, 2.0, 1.0, 1.0);
    let threads = std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1);
    for (name, slices, stacks) in [("10k", 100u32, 51u32), ("100k", 317, 159), ("1M", 1000, 501)] {
        let sphere = uv_sphere(1.0, slices, stacks);
        let caster = Caster::new("sphere", &sphere, Mat4::IDENTITY).expect("sphere caster");
        assert!(caster.is_manifold() && caster.parts.len() == 1);
        let (planes, scan) = (&caster.planes, &caster.parts[0].scan);
        let mesh = caster.mesh();
        // as many 8-byte records as the scan reads (class masks and residual pairs)
        let pairs: Vec<[u32; 2]> = (0..scan.bytes().div_ceil(8)).map(|i| [i as u32 ^ 1, i as u32 ^ 3]).collect();
        let words = planes.bytes() / 16;
        let plain = PlainArrays {
            a: (0..words).map(|i| i as f32).collect(),
            b: (0..words).map(|i| (i * 3) as f32).collect(),
            c: (0..words).map(|i| (i * 7) as f32).collect(),
            d: (0..words).map(|i| (i * 11) as f32).collect(),
        };
        let bytes = bytes_of(planes, scan);
        let mut g = c.benchmark_group(format!("silhouette/{name}"));
        g.throughput(Throughput::Bytes(bytes));
        if slices >= 1000 {
            g.sample_size(10);
        }
        let tris = mesh.triangles.len();
        let mut bits: Vec<u64> = Vec::new();
        let mut sil: Vec<SilhouetteEdge> = Vec::new();
        g.bench_function(BenchmarkId::new("streaming_sum", tris), |b| {
            b.iter(|| black_box(streaming_sum(black_box(&plain), black_box(&pairs))))
        });
        let mut facing_silhouette = |g: &mut criterion::BenchmarkGroup<_>, id: &str, planes: &FacePlanes, scan: &EdgeScan, mesh: &Mesh| {
            g.bench_function(BenchmarkId::new(id, tris), |b| {
                b.iter(|| {
                    planes.facing_packed_auto(mesh, black_box(light), false, &mut bits);
                    sil.clear();
                    scan.scan_into(&bits, &mut sil);
                    black_box(sil.len())
                })
            });
        };
        facing_silhouette(&mut g, "facing+silhouette", planes, scan, mesh);
        // the same two functions in paired rounds (batches of about 10 ms)
        let batch = (10_000_000 / (tris as u64 / 3).max(1)).clamp(5, 2_000) as u32;
        let (mut bits, mut sil) = (Vec::new(), Vec::new());
        let paired = paired_ratios(
            || {
                black_box(streaming_sum(black_box(&plain), black_box(&pairs)));
            },
            || {
                planes.facing_packed_auto(mesh, black_box(light), false, &mut bits);
                sil.clear();
                scan.scan_into(&bits, &mut sil);
                black_box(sil.len());
            },
            batch,
        );
        println!("{}", paired_line(&format!("silhouette/{name}/paired: facing+silhouette"), "streaming_sum's", paired, batch));
        // what the CPU-specific copies of the facing and the scan buy: the best copy against
        // the portable one, in paired rounds
        let run = |portable: bool, (bits, sil): &mut (Vec<u64>, Vec<SilhouetteEdge>)| {
            cpu::set_portable_only(portable);
            planes.facing_packed_auto(mesh, black_box(light), false, bits);
            sil.clear();
            scan.scan_into(bits, sil);
            black_box(sil.len());
        };
        let level = cpu::level();
        let (mut portable_out, mut best_out) = ((Vec::new(), Vec::new()), (Vec::new(), Vec::new()));
        let paired = paired_ratios(|| run(true, &mut portable_out), || run(false, &mut best_out), batch);
        assert_eq!(portable_out, best_out, "the copies found the same silhouette");
        cpu::set_portable_only(false);
        let what = format!("silhouette/{name}/cpu-level: facing+silhouette's {level} copy");
        println!("{}", paired_line(&what, "the portable copy's", paired, batch));
        // the same sphere, triangles shuffled, loaded as a caster (reordered at load)
        let shuffled_mesh = shuffled(&sphere);
        let sc = Caster::new("shuffled", &shuffled_mesh, Mat4::IDENTITY).expect("shuffled caster");
        facing_silhouette(&mut g, "facing+silhouette_shuffled", &sc.planes, &sc.parts[0].scan, sc.mesh());
        // both meshes in their own triangle order (no reordering)
        for (id, m) in [("facing+silhouette_caller_order", mesh), ("facing+silhouette_shuffled_caller_order", sc.mesh())] {
            let topo = Topology::build(m);
            let (p, s) = (FacePlanes::new(&topo.mesh), EdgeScan::new(topo.manifold_edges.clone()));
            facing_silhouette(&mut g, id, &p, &s, &topo.mesh);
        }
        g.bench_function(BenchmarkId::new("facing_serial", tris), |b| {
            b.iter(|| {
                planes.facing_packed(mesh, black_box(light), false, &mut bits);
                black_box(bits.len())
            })
        });
        g.bench_function(BenchmarkId::new("facing", tris), |b| {
            b.iter(|| {
                planes.facing_packed_threads(mesh, black_box(light), false, threads, &mut bits);
                black_box(bits.len())
            })
        });
        planes.facing_packed(mesh, light, false, &mut bits);
        g.bench_function(BenchmarkId::new("edge_scan_serial", tris), |b| {
            b.iter(|| {
                sil.clear();
                scan.scan_into(black_box(&bits), &mut sil);
                black_box(sil.len())
            })
        });
        let mut own = Vec::new();
        FacePlanes::new(mesh).facing_packed(mesh, light, false, &mut own);
        g.bench_function(BenchmarkId::new("edge_scan", tris), |b| {
            b.iter(|| {
                sil.clear();
                possible_silhouette_packed_into(&caster.topology.manifold_edges, black_box(&own), &mut sil);
                black_box(sil.len())
            })
        });
        g.finish();
        if slices >= 1000 {
            let mut g = c.benchmark_group(format!("load/{name}"));
            g.sample_size(10);
            g.bench_function("caster_new", |b| {
                b.iter(|| black_box(Caster::new("sphere", black_box(&sphere), Mat4::IDENTITY).unwrap().triangle_count))
            });
            g.bench_function("caster_new_shuffled", |b| {
                b.iter(|| black_box(Caster::new("shuffled", black_box(&shuffled_mesh), Mat4::IDENTITY).unwrap().triangle_count))
            });
            let all: Vec<u32> = (0..tris as u32).collect();
            g.bench_function("triangle_order_spatial", |b| b.iter(|| black_box(TriangleOrder::spatial(black_box(mesh), &[&all]).len())));
            g.finish();
        }
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
