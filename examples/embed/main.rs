//! Embedding umbrage in an engine: a host renderer of its own (`host.rs`: its own instance,
//! device, allocator, WGSL shaders, depth-stencil image, command buffers, two frames in flight
//! and lighting pass) that records umbrage's [`ShadowPass`](umbrage::pass::ShadowPass) into its
//! command buffers, with a caster moving between frames. Every sample of every frame is read
//! back and checked against the exact CPU reference, as `umbrage check` checks a dump.
//!
//! Run: `cargo run --release --example embed -- [--msaa N] [--reverse-z] [--render-pass]
//! [--scene FILE|NAME] [--size WxH] [--out PNG] [--dump DIR] [--frames N]`
//! (`UMBRAGE_VALIDATION=1` turns on the validation layer, and any validation error fails).
//! `--scene`, `--size`, `--out` and `--dump` mean what they mean for `umbrage render`; with
//! `--msaa N` (N > 1) the dump of every sample goes to `DIR/sample_0` … `DIR/sample_{N-1}`,
//! and the PNG is the resolve (the mean of the samples). The dump and the PNG are of the last
//! frame. Exits non-zero on any mismatch outside the 1-pixel band, or any error; the one
//! exception is SwiftShader at several samples, whose multisampled-depth defect
//! (docs/conform/drivers-notes.md §1f) leaves a few samples near volume edges: up to
//! [`host::SWIFTSHADER_MSAA_MISMATCHES`] a light and sample are reported as a warning.

mod host;

use clap::Parser;
use glam::Vec3;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

#[derive(Parser)]
#[command(name = "embed", about = "umbrage's shadow pass embedded in a raw-ash host renderer")]
struct Args {
    /// Samples per pixel (1, 2, 4 or 8): every target at that count, each sample checked.
    #[arg(long, default_value_t = 1)]
    msaa: u32,
    /// Reverse-Z: the near plane at depth 1, infinity at 0 (depth GREATER, cleared to 0).
    #[arg(long)]
    reverse_z: bool,
    /// A Vulkan 1.1 host with classic render passes (the pass records inside its subpass)
    /// instead of Vulkan 1.3 dynamic rendering.
    #[arg(long)]
    render_pass: bool,
    /// Scene file (TOML) or built-in name, as for `umbrage render`; by default the host's
    /// embedded scene (a torus and a box turning as it slides, two point lights).
    #[arg(long)]
    scene: Option<String>,
    /// Image size, WxH.
    #[arg(long, default_value = "320x200", value_parser = parse_size)]
    size: (u32, u32),
    /// Output PNG of the last frame (the resolve of its samples).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Write the last frame's dump into DIR (`DIR/sample_K` per sample with --msaa > 1), in
    /// the format `umbrage check DIR` reads.
    #[arg(long)]
    dump: Option<PathBuf>,
    /// Frames to render, two in flight, the caster moving between them.
    #[arg(long, default_value_t = 4, value_parser = clap::value_parser!(u32).range(1..=10_000))]
    frames: u32,
}

fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s.split_once(['x', 'X']).ok_or_else(|| format!("expected WxH, got '{s}'"))?;
    let w: u32 = w.trim().parse().map_err(|_| format!("bad width in '{s}'"))?;
    let h: u32 = h.trim().parse().map_err(|_| format!("bad height in '{s}'"))?;
    if w == 0 || h == 0 || w > 8192 || h > 8192 {
        return Err(format!("size {w}x{h} out of range (1..=8192)"));
    }
    Ok((w, h))
}

fn main() -> ExitCode {
    let args = Args::parse();
    match run(&args) {
        Ok(true) => ExitCode::SUCCESS,
        Ok(false) => ExitCode::FAILURE,
        Err(e) => {
            eprintln!("embed: {e}");
            ExitCode::FAILURE
        }
    }
}

fn run(args: &Args) -> Result<bool, String> {
    let config = host::Config {
        samples: args.msaa,
        reverse_z: args.reverse_z,
        render_pass: args.render_pass,
        width: args.size.0,
        height: args.size.1,
        scene: args.scene.clone(),
        skip: Vec::new(),
        validation: None,
    };
    let results = host::run(&config, args.frames as usize)?;
    let mut bad = 0u64;
    let mut tolerated = 0u64;
    let allowed = results.first().map_or(0, |r| host::allowed_mismatches(&r.device, config.samples));
    for r in &results {
        let t = &r.totals;
        println!(
            "frame {} (slot {}, {}, {}): {} shadow triangles ({} sides, {} dark cap, {} light cap), {} bytes sent; \
             cases {} z-pass / {} z-fail / {} z-fail+light cap / {} culled; cpu {:.2} ms silhouettes + {:.2} ms plan; {:.1} ms to the fence",
            r.frame,
            r.slot,
            r.device,
            config.name(),
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
            r.gpu_wall_ms,
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
            println!(
                "  light {}: per sample {:?} mismatched pixels outside the {}-pixel band of {:?} compared ({:?} with a non-zero count)",
                ls.index,
                lr.mismatches,
                host::BAND,
                lr.compared,
                lr.shadowed
            );
            bad += lr.mismatches_beyond(allowed);
            tolerated += lr.mismatches_outside_band() - lr.mismatches_beyond(allowed);
        }
    }
    // The determination's GPU time (timestamps around cmd_determine), median over frames of
    // the sum over lights, and the frame's time to its fence.
    let median = |mut v: Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v.get(v.len() / 2).copied().unwrap_or(f64::NAN)
    };
    let determine = median(results.iter().filter(|r| !r.determine_ms.is_empty()).map(|r| r.determine_ms.iter().sum()).collect());
    let frame_gpu = median(results.iter().map(|r| r.frame_gpu_ms).collect());
    let fence = median(results.iter().map(|r| r.gpu_wall_ms).collect());
    println!(
        "embed: {}: median determination {determine:.3} ms GPU (all lights), median frame {frame_gpu:.3} ms GPU (readback included), \
         {fence:.1} ms record to fence",
        config.name()
    );
    let last = results.last().ok_or("no frame rendered")?;
    if let Some(path) = &args.out {
        let rgba = resolve(last);
        umbrage_render::output::write_png(path, config.width, config.height, &rgba).map_err(|e| e.to_string())?;
        println!("embed: wrote {}", path.display());
    }
    if let Some(dir) = &args.dump {
        for (si, s) in last.samples.iter().enumerate() {
            let d = if last.samples.len() > 1 { dir.join(format!("sample_{si}")) } else { dir.clone() };
            let color = shade(&s.dump);
            umbrage_render::output::write_scene_dump(&d, &last.scene, &s.dump, &s.stencil, &color).map_err(|e| e.to_string())?;
        }
        println!("embed: dumped frame {} into {}", last.frame, dump_names(dir, last.samples.len()));
    }
    if bad > 0 {
        eprintln!("embed: {bad} mismatched pixels outside the band in total (beyond {allowed} a light and sample)");
        return Ok(false);
    }
    if tolerated > 0 {
        println!(
            "embed: warning: {tolerated} samples mismatched outside the band, each light and sample within the {allowed} allowed \
             for this device's multisampled-depth defect (docs/conform/drivers-notes.md §1f)"
        );
        return Ok(true);
    }
    println!("embed: {} frames ({}), 0 mismatched pixels against the CPU reference", results.len(), config.name());
    Ok(true)
}

fn dump_names(dir: &Path, samples: usize) -> String {
    if samples > 1 {
        format!("{}/sample_0 .. sample_{}", dir.display(), samples - 1)
    } else {
        dir.display().to_string()
    }
}

/// One sample's picture (RGBA8): the floor-grey albedo lit by every light that reaches the
/// sample (its mask), Lambert on the dumped normal, a little ambient; the sky for background.
fn shade(d: &umbrage_reference::Dump) -> Vec<u8> {
    let n = (d.width * d.height) as usize;
    let mut out = Vec::with_capacity(4 * n);
    for i in 0..n {
        let p = Vec3::new(d.positions[3 * i], d.positions[3 * i + 1], d.positions[3 * i + 2]);
        let c = if !p.x.is_finite() {
            Vec3::new(0.25, 0.3, 0.4)
        } else {
            let nrm = Vec3::new(d.normals[3 * i], d.normals[3 * i + 1], d.normals[3 * i + 2]);
            let mut lit = 0.1;
            for (k, l) in d.lights.iter().enumerate() {
                if d.shadow[k][i] == 255 {
                    let to = if l.position.w == 0.0 { l.position.truncate() } else { l.position.truncate() - p };
                    lit += 0.9 * nrm.dot(to.normalize()).max(0.0) / d.lights.len() as f32;
                }
            }
            Vec3::splat(0.8 * lit)
        };
        let c = c.clamp(Vec3::ZERO, Vec3::ONE) * 255.0;
        out.extend([c.x as u8, c.y as u8, c.z as u8, 255]);
    }
    out
}

/// The resolve of the last frame: the mean of its samples' pictures.
fn resolve(r: &host::FrameResult) -> Vec<u8> {
    let pictures: Vec<Vec<u8>> = r.samples.iter().map(|s| shade(&s.dump)).collect();
    let len = pictures.first().map_or(0, Vec::len);
    (0..len).map(|i| (pictures.iter().map(|p| p[i] as u32).sum::<u32>() / pictures.len().max(1) as u32) as u8).collect()
}
