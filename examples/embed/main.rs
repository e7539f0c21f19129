//! Embedding umbrage in an engine: a host renderer of its own (`host.rs`: its own instance,
//! device, allocator, depth-stencil image, command buffers, two frames in flight and lighting
//! pass) that records umbrage's [`ShadowPass`](umbrage::pass::ShadowPass) into its command
//! buffers, with a caster moving over four frames. Every frame is read back and compared with
//! the exact CPU reference of that frame's scene.
//!
//! Run: `cargo run --release --example embed` (needs a Vulkan 1.3 driver; lavapipe is fine;
//! `UMBRAGE_VALIDATION=1` turns on the validation layer, and any validation error fails).
//! Exits non-zero on any mismatch outside the 1-pixel band, or any error.

mod host;

use std::process::ExitCode;

const FRAMES: usize = 4;

fn main() -> ExitCode {
    let results = match host::run(FRAMES) {
        Ok(r) => r,
        Err(e) => {
            eprintln!("embed: {e}");
            return ExitCode::FAILURE;
        }
    };
    let mut bad = 0u64;
    for r in &results {
        let t = &r.totals;
        println!(
            "frame {} (slot {}, {}): {} shadow triangles ({} sides, {} dark cap, {} light cap), {} bytes sent; \
             cases {} z-pass / {} z-fail / {} z-fail+light cap / {} culled; cpu {:.2} ms silhouettes + {:.2} ms plan",
            r.frame,
            r.slot,
            r.device,
            t.triangles.total(),
            t.triangles.sides,
            t.triangles.dark_cap,
            t.triangles.light_cap,
            t.bytes_sent,
            t.cases.zpass,
            t.cases.zfail,
            t.cases.zfail_light_cap,
            t.cases.culled,
            r.cpu_ms.silhouettes,
            r.cpu_ms.plan,
        );
        for w in &r.warnings {
            println!("  warning: {w}");
        }
        for (ls, lr) in r.stats.iter().zip(&r.lights) {
            for c in &ls.casters {
                println!(
                    "  light {} {:>6}: {:<15} {:>4} silhouette edges, {:>5} triangles, {:>6} index bytes ({})",
                    ls.index,
                    c.name,
                    c.case,
                    c.silhouette_edges,
                    c.triangles.total(),
                    c.index_bytes,
                    c.index_format
                );
            }
            let shadowed = lr.stencil.iter().zip(&lr.mask).filter(|(&s, &m)| s != 0 && m != 128).count();
            println!(
                "  light {}: {} mismatched pixels outside the {}-pixel band of {} compared ({} pixels with a non-zero count)",
                ls.index,
                lr.mismatches_outside_band,
                host::BAND,
                lr.compared,
                shadowed
            );
            bad += lr.mismatches_outside_band;
        }
    }
    if bad > 0 {
        eprintln!("embed: {bad} mismatched pixels outside the band in total");
        return ExitCode::FAILURE;
    }
    println!("embed: {} frames, 0 mismatched pixels against the CPU reference", results.len());
    ExitCode::SUCCESS
}
