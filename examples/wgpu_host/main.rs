//! umbrage's [`ShadowPass`](umbrage::pass::ShadowPass) inside a **wgpu** host engine.
//!
//! wgpu (its Vulkan backend) creates the instance, device and queue, owns every texture,
//! buffer and pipeline of the frame, and draws the ambient + G-buffer pass, the per-light
//! lighting and the tone map with WGSL pipelines. Between its passes, umbrage's shadow pass
//! records each light's determination (the stencil count) into a command buffer of wgpu's,
//! through wgpu's raw Vulkan handles (`CommandEncoder::as_hal_mut`, the texture view's raw
//! `VkImageView`). The lighting pass then lights where the count is 0 (stencil compare
//! EQUAL, reference 0), additively over the ambient term, like umbrage's own frame
//! (Blinn-Phong with umbrage's range attenuation and spot falloff, the same tone map).
//! `--frames N` frames are rendered with two in flight while the last shadow-casting mesh
//! slides between frames (0.25 a frame along +x from where the scene puts it, so `--frames 1`
//! draws the scene as `umbrage render` does); the PNG and the dump are of the last frame, with
//! the mesh where that frame drew it.
//!
//! What wgpu needed beyond its own API (see `gpu.rs` and `shadow.rs`):
//! - the pass records `vkCmdBeginRendering` and `vkCmdPipelineBarrier2`: `dynamicRendering`
//!   and `synchronization2` are enabled through wgpu-hal's device-creation callback
//!   (`Adapter::open_with_callback`, then `wgpu::Adapter::create_device_from_hal`);
//! - wgpu 30 refuses raw and wgpu commands in one encoder, so each light's determination is
//!   an encoder of its own, submitted in the same `queue.submit` between wgpu's;
//! - the depth-stencil texture stays in the layout wgpu's tracker believes it is in,
//!   `DEPTH_STENCIL_ATTACHMENT_OPTIMAL` (`TextureUses::DEPTH_STENCIL_WRITE`): the wgpu
//!   encoders before the determination end with `transition_resources` to that state, and
//!   the lighting pass loads and stores depth and stencil (not read-only) to keep it there;
//! - `Depth24PlusStencil8` is D24S8 or D32S8 as wgpu-hal chooses: the pass is created with
//!   the format wgpu-hal reports, on a gpu-allocator made from wgpu's raw handles.
//!
//! Run: `cargo run --example wgpu_host -- --scene default --size 960x540 --out wgpu.png
//! --dump DIR`, then `umbrage check DIR` compares the dump with the exact CPU reference. The
//! flags mean what they mean for `umbrage render` (the default `--out` is `wgpu_host.png`).
//! `UMBRAGE_VALIDATION=1` turns on the Khronos validation layer (with synchronisation
//! validation); any validation error makes the program exit non-zero. `UMBRAGE_DEVICE=<name>`
//! picks the adapter.
//!
//! Limitations: opaque triangle meshes only (scenes with analytic spheres or transparent
//! casters are refused); the stencil counter with McGuire's method only (no `--method`,
//! `--counter float`, `--depth-mode clamp`); no depth-bounds test (wgpu enables no
//! depthBounds), so the pass and the lighting pass use the scissor alone; no GPU timestamps
//! (the frame times are host wall-clock). Needs Vulkan 1.3 with dynamicRendering and
//! synchronization2 (lavapipe 22.3.6 and 25.0.7 are fine; 20.3.5, Vulkan 1.0, is refused).
//! The validation layer Debian 12 ships (1.3.239) checks the wgpu side and the pass's calls,
//! but its synchronisation validation does not follow dynamic-rendering attachments (a
//! determination recorded twice with no barrier between goes unreported), so the barriers
//! around the determination rest on the argument in `shadow.rs` and on the reference check,
//! not on that layer.

mod frame;
mod gpu;
mod host;
mod shadow;

use clap::Parser;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

#[derive(Parser)]
#[command(name = "wgpu_host", about = "umbrage's shadow pass recorded inside a wgpu (Vulkan) host frame")]
struct Args {
    /// Scene file (TOML) or built-in name (default, stairs, cubes, hard/...), as for `umbrage render`.
    #[arg(long, default_value = "default")]
    scene: String,
    /// Image size, WxH.
    #[arg(long, default_value = "960x540", value_parser = parse_size)]
    size: (u32, u32),
    /// Output PNG (the last frame).
    #[arg(long, default_value = "wgpu_host.png")]
    out: PathBuf,
    /// Write the last frame's dump (frame.json, world.obj, positions/normals, masks) into DIR,
    /// in the format `umbrage check DIR` reads.
    #[arg(long)]
    dump: Option<PathBuf>,
    /// Frames to render, two in flight, the last shadow-casting mesh moving between them.
    #[arg(long, default_value_t = 3, value_parser = clap::value_parser!(u32).range(1..=10_000))]
    frames: u32,
}

fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s.split_once(['x', 'X']).ok_or_else(|| format!("expected WxH, got '{s}'"))?;
    let w: u32 = w.trim().parse().map_err(|_| format!("bad width in '{s}'"))?;
    let h: u32 = h.trim().parse().map_err(|_| format!("bad height in '{s}'"))?;
    if w == 0 || h == 0 || w > 16384 || h > 16384 {
        return Err(format!("size {w}x{h} out of range (1..=16384)"));
    }
    Ok((w, h))
}

fn main() -> ExitCode {
    let args = Args::parse();
    let result = run(&args);
    // Teardown is over (the host dropped inside `run`): errors it logged count too.
    match result.and_then(|()| gpu::check_errors("(teardown included)")) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("wgpu_host: {e}");
            ExitCode::FAILURE
        }
    }
}

fn run(args: &Args) -> Result<(), String> {
    let (scene, motion) = umbrage_scene::load_animated(&args.scene).map_err(|e| e.to_string())?;
    let scene = motion.scene_at(&scene, 0.0);
    let (w, h) = args.size;
    let frames = args.frames as usize;
    let gpu = gpu::Gpu::new()?;
    println!("wgpu_host: {} | depth-stencil {:?} (wgpu Depth24PlusStencil8)", gpu.name, gpu.ds_format);
    let mut host = host::Host::new(gpu, scene, w, h, args.dump.is_some())?;
    if let Some((mi, _)) = host.moving {
        println!("wgpu_host: '{}' moves between frames", host.scene.meshes[mi].name);
    }
    let start = std::time::Instant::now();
    let mut timings = Vec::with_capacity(frames);
    for f in 0..frames {
        let last = f + 1 == frames;
        if let Some(r) = host.frame(f, last && args.dump.is_some())? {
            timings.push(r.timing);
        }
    }
    // The frames still in flight, oldest first; the last one is read back.
    let mut output = None;
    for f in frames.saturating_sub(host::FRAMES_IN_FLIGHT)..frames {
        if let Some(r) = host.retire(f % host::FRAMES_IN_FLIGHT, f + 1 == frames)? {
            timings.push(r.timing);
            output = r.output.or(output);
        }
    }
    let total_ms = start.elapsed().as_secs_f64() * 1e3;
    let out = output.ok_or("the last frame was not read back")?;
    for t in &timings {
        println!(
            "frame {} (slot {}): prepare {:.2} ms, record + submit {:.2} ms, prepare to done {:.2} ms",
            t.frame, t.slot, t.prepare_ms, t.record_ms, t.latency_ms
        );
    }
    let s = &out.stats;
    for w in &s.warnings {
        eprintln!("warning: {w}");
    }
    println!(
        "{} | {}x{} | {} | {} frames in {:.2} ms ({:.2} ms a frame, two in flight) | last frame {:.2} ms | {} shadow triangles | {}",
        s.device,
        s.width,
        s.height,
        s.method,
        frames,
        total_ms,
        total_ms / frames as f64,
        s.wall_ms,
        s.totals.triangles.total(),
        args.out.display()
    );
    umbrage_render::output::write_png(&args.out, out.width, out.height, &out.color).map_err(|e| e.to_string())?;
    if let Some(dir) = &args.dump {
        write_dump(dir, &host, &out)?;
        println!("wgpu_host: dump written to {} (check it with `umbrage check {}`)", dir.display(), dir.display());
    }
    drop(host);
    Ok(())
}

fn write_dump(dir: &Path, host: &host::Host, out: &umbrage_render::FrameOutput) -> Result<(), String> {
    // The scene as the last frame drew it (the moving mesh where that frame put it).
    umbrage_render::output::write_frame_dump(dir, &host.scene, out).map_err(|e| e.to_string())
}
