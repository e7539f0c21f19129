//! The `umbrage` command line: render | view | info | check | conform | bench.

use clap::{Parser, Subcommand};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use umbrage::{Error, Result};
use umbrage_render::{Counter, DepthMode, IndexFormat, RenderOptions, RenderTechnique, Renderer, Shading, ShadowMap, TransmitMode, View};

// `umbrage bench`: its arguments and the classic, suite and soak modes.
#[path = "cli/bench.rs"]
mod bench_cli;
#[path = "cli/pipelines.rs"]
mod pipelines_cli;
// `umbrage export-scene`: a scene in the flat text format the C host reads.
#[path = "cli/export_scene.rs"]
mod export_scene_cli;

#[derive(Parser)]
#[command(name = "umbrage", version, about = "Exact hard shadows with stencil shadow volumes on Vulkan, measured against a CPU reference")]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
}

#[derive(clap::Args, Clone)]
struct FrameArgs {
    /// Scene file (TOML) or built-in name (default, stairs, cubes, spheres, hard/...).
    #[arg(long, default_value = "default")]
    scene: String,
    /// Image size, WxH.
    #[arg(long, default_value = "960x540", value_parser = parse_size)]
    size: (u32, u32),
    /// Shadow method: auto (= mcguire, with open / non-manifold casters on the multiplicity
    /// path), mcguire, lengyel, everitt-kilgard, zfail, zpass, zpass-clear; edgequad (GPU-only silhouettes,
    /// the Cg article); planar; compute (GPU possible silhouettes); mesh (mesh-shader extrusion;
    /// needs VK_EXT_mesh_shader); shadowmap (the PCF baseline); or rayquery (one shadow ray a
    /// pixel; needs VK_KHR_ray_query).
    #[arg(long, default_value = "auto", value_parser = parse_method)]
    method: RenderTechnique,
    /// infinite (far plane at infinity) or clamp (finite far plane + depthClamp).
    #[arg(long, value_enum, default_value = "infinite")]
    depth_mode: DepthMode,
    /// u32, u16, u8, auto, or naive (stream 4 x f32 per shadow vertex, no indices).
    #[arg(long, value_enum, default_value = "auto")]
    index_format: IndexFormat,
    /// stencil (8-bit, wraps at 256 nested volumes) or float (32-bit float target, additive).
    #[arg(long, value_enum, default_value = "stencil")]
    counter: Counter,
    /// Transparent casters' light-intensity map: log16 (default), mul16, log32, mul32.
    #[arg(long, default_value = "log16", value_parser = parse_named::<TransmitMode>)]
    transmit: TransmitMode,
    /// Texels per side of each shadow map (--method shadowmap).
    #[arg(long, default_value_t = 2048)]
    shadow_map_size: u32,
    /// How the shadow map's 3x3 PCF lookup reads its taps (--method shadowmap): nine taps or
    /// four gathers, the same comparisons and picture either way.
    #[arg(long, value_enum, default_value = "taps")]
    pcf: umbrage_render::Pcf,
    /// How a point light's six shadow-map cube faces are rendered (--method shadowmap): tiles
    /// of one atlas, a draw per face; or six views of one draw (needs the device's multiview).
    /// The same maps and picture either way.
    #[arg(long, value_enum, default_value = "atlas")]
    cube: umbrage_render::CubeFaces,
    /// Partial self-shadowing of transparent casters (Kim et al. 2008): their forward light
    /// passes read a light-intensity map built on the nearest transparent surface.
    #[arg(long)]
    self_shadow: bool,
    /// Re-draw the area lights' jittered sample pattern every frame (default: the same
    /// pattern every frame).
    #[arg(long)]
    jitter: bool,
    /// Samples per pixel: 1, 2, 4 or 8. The G-buffer, the shadow volumes' stencil and the
    /// lighting run at every sample and the PNG is their resolve; --dump writes DIR/sample_K
    /// per sample. Stencil shadow-volume methods only.
    #[arg(long, default_value_t = 1)]
    msaa: u32,
    /// smooth (smooth normals, the light reaching zero before the shadow volumes' polygonal
    /// terminator), smooth-naive (smooth normals as they are: a step along the terminator's
    /// edges) or flat. Shadows are the same in every mode.
    #[arg(long, default_value = "smooth", value_parser = parse_named::<Shading>)]
    shading: Shading,
    /// Plan every light–caster pair from scratch every frame (default: each pair's plan and
    /// index lists are kept across frames until its light, caster or case changes; the same
    /// pictures either way).
    #[arg(long)]
    no_keep: bool,
}

/// `--method`: a name [`RenderTechnique`]'s `FromStr` reads (its shadow maps' settings come
/// from `--shadow-map-size`, `--pcf` and `--cube`: [`with_shadow_map`]).
fn parse_method(s: &str) -> std::result::Result<RenderTechnique, String> {
    s.parse().map_err(|e: Error| e.to_string())
}

/// `t`, with the shadow-map baseline's settings replaced by `m` (the other techniques as they are).
fn with_shadow_map(t: RenderTechnique, m: ShadowMap) -> RenderTechnique {
    match t {
        RenderTechnique::ShadowMap(_) => m.into(),
        t => t,
    }
}

/// A value of a named enum of the library (`--shading`, `--transmit`), read by its `FromStr`.
fn parse_named<T: std::str::FromStr<Err = Error>>(s: &str) -> std::result::Result<T, String> {
    s.parse().map_err(|e: Error| e.to_string())
}

#[derive(Subcommand)]
enum Command {
    /// Render a scene to a PNG (and optionally stats JSON and a frame dump).
    Render {
        #[command(flatten)]
        frame: FrameArgs,
        /// Output PNG.
        #[arg(long, default_value = "umbrage.png")]
        out: PathBuf,
        /// Write per-frame statistics (triangles, bytes, cases, timings) as JSON.
        #[arg(long)]
        stats: Option<PathBuf>,
        /// shaded, volumes (shadow volumes coloured by case) or stencil (counts of light 0).
        #[arg(long, value_enum, default_value = "shaded")]
        view: View,
        /// Write a frame dump (frame.json, world.obj, positions/normals, masks) into DIR.
        #[arg(long)]
        dump: Option<PathBuf>,
        /// Render an animated scene at T seconds (spins and light paths; `umbrage view`
        /// reports each frame's time).
        #[arg(long, default_value_t = 0.0)]
        time: f64,
    },
    /// An interactive window (winit + ash-window) on the same frame as `render`, with an
    /// egui overlay; needs a display (X11; Xvfb works).
    #[cfg(feature = "view")]
    View {
        #[command(flatten)]
        frame: FrameArgs,
        #[command(flatten)]
        view: umbrage_cli::view::ViewArgs,
    },
    /// Device, driver, optional features and the code paths they select.
    Info {
        #[arg(long)]
        json: bool,
        /// Also classify this scene's casters: which path each takes (three-case manifold or
        /// multiplicity) and why, with their triangles and chunks.
        #[arg(long)]
        scene: Option<String>,
        /// Create every pipeline the renderer and the shadow pass can create on this device
        /// (recording nothing) and print each one's creation time; non-zero exit when any
        /// creation fails.
        #[arg(long)]
        pipelines: bool,
    },
    /// Speed against error: every method on each scene, side by side on this device; with
    /// `--suite fill-vertex`, the fill-rate vs vertex-rate suite against the device's limits.
    Bench(bench_cli::BenchArgs),
    /// Write a scene (built-in name or TOML file) in the flat text format C hosts read
    /// (docs/c-api.md).
    ExportScene {
        /// Built-in scene name or scene file.
        scene: String,
        /// Output file.
        out: PathBuf,
    },
    /// Compare a frame dump with the exact CPU reference.
    Check {
        dir: PathBuf,
        /// Pixels within this distance of a shadow edge or silhouette are not counted.
        #[arg(long, default_value_t = 1)]
        band: u32,
        /// Highest accepted fraction of mismatched pixels outside the band.
        #[arg(long, default_value_t = 1e-4)]
        threshold: f64,
    },
    /// The driver conformance suite for what shadow volumes rely on (reports into --out).
    Conform {
        /// Report directory (conform.json, conform.md, failures/<case>/*.png); default conform-report.
        #[arg(long)]
        out: Option<PathBuf>,
        /// Run only cases matching these comma-separated patterns (substring, or glob with '*').
        #[arg(long)]
        filter: Option<String>,
        /// List the selected case names and exit.
        #[arg(long)]
        list: bool,
        /// Also write JUnit XML to this file.
        #[arg(long)]
        junit: Option<PathBuf>,
        /// Run on the device whose name contains NAME (case-insensitive).
        #[arg(long, value_name = "NAME")]
        device: Option<String>,
        /// Run every unit (a configuration's submission, the legacy checks, the multiview
        /// check, the pipeline checks) in this process instead of a child process each: faster to debug, but a
        /// driver crash ends the run.
        #[arg(long)]
        no_isolate: bool,
        /// The per-case timer: seconds a child may spend on one case (or one step its cases
        /// share, such as a configuration's submission) before it is killed and that case
        /// reported as Timeout (default 60; 30 in the dEQP-compatible mode, below deqp-runner's
        /// 60 s per-test timer).
        #[arg(long, value_name = "SECONDS")]
        timeout: Option<f64>,
        /// Child processes at once (0: one per CPU core, as deqp-runner does).
        #[arg(long, default_value_t = 0, value_name = "N")]
        jobs: usize,
        /// The driver's expected results (`case,Fail` / `Crash` / `Timeout` / `Skip` lines, as
        /// Mesa's CI keeps them; `*` patterns): exit 0 only when the run matches the list, no
        /// new failure, no unexpected pass and, where it lists skips, no new skip.
        #[arg(long, value_name = "FILE")]
        expect: Option<PathBuf>,
        /// Mesa's baseline: `name,Status` lines (Fail, Crash, Timeout, ...), e.g. a previous
        /// run's failures.csv; exit 0 only when every result is as listed or passes.
        #[arg(long, value_name = "FILE")]
        baseline: Option<PathBuf>,
        /// Regexes (one a line) of flaky cases: an unexpected result there is KnownFlake.
        #[arg(long, value_name = "FILE")]
        flakes: Vec<PathBuf>,
        /// Regexes (one a line) of cases not to run (reported Skip).
        #[arg(long, value_name = "FILE")]
        skips: Vec<PathBuf>,
        /// Run one case in N of the list (a shard; with --fraction-start).
        #[arg(long, value_name = "N")]
        fraction: Option<usize>,
        /// The first case of this shard, 1-based: shards 1..=N of --fraction N run every case once.
        #[arg(long, value_name = "K")]
        fraction_start: Option<usize>,
        /// The most cases of a configuration one child process draws (default 64).
        #[arg(long, value_name = "N")]
        chunk: Option<usize>,
        /// Internal: run one unit and write its result to --child-result (crash isolation).
        #[arg(long, hide = true, value_name = "UNIT")]
        child: Option<String>,
        /// Internal: where a child writes its result.
        #[arg(long, hide = true, value_name = "FILE")]
        child_result: Option<PathBuf>,
        /// Internal: where a child reports the case it is running.
        #[arg(long, hide = true)]
        child_progress: Option<PathBuf>,
    },
    /// The driver matrix: several `conform --out DIR` runs side by side (family x column, every
    /// difference by pattern), as Markdown (`make conform-matrix` writes docs/conform/drivers.md).
    ConformMatrix {
        /// A column: its name and the directory holding that run's conform.json (repeat).
        #[arg(long = "column", value_name = "NAME=DIR", required = true)]
        columns: Vec<String>,
        /// Hand-written explanations appended to the matrix.
        #[arg(long, value_name = "FILE")]
        notes: Option<PathBuf>,
        /// The Markdown file to write.
        #[arg(long, value_name = "FILE")]
        out: PathBuf,
    },
}

impl Default for FrameArgs {
    fn default() -> Self {
        FrameArgs {
            scene: "default".into(),
            size: (960, 540),
            method: RenderTechnique::default(),
            depth_mode: DepthMode::Infinite,
            index_format: IndexFormat::Auto,
            counter: Counter::Stencil,
            transmit: TransmitMode { fp32: false, log: true },
            shadow_map_size: 2048,
            pcf: Default::default(),
            cube: Default::default(),
            self_shadow: false,
            jitter: false,
            msaa: 1,
            shading: Shading::Smooth,
            no_keep: false,
        }
    }
}

fn parse_size(s: &str) -> std::result::Result<(u32, u32), String> {
    let (w, h) = s.split_once(['x', 'X']).ok_or_else(|| format!("expected WxH, got '{s}'"))?;
    let w: u32 = w.trim().parse().map_err(|_| format!("bad width in '{s}'"))?;
    let h: u32 = h.trim().parse().map_err(|_| format!("bad height in '{s}'"))?;
    if w == 0 || h == 0 || w > 16384 || h > 16384 {
        return Err(format!("size {w}x{h} out of range (1..=16384)"));
    }
    Ok((w, h))
}

fn main() -> ExitCode {
    // `conform`'s dEQP flags (--deqp-*, as deqp-runner appends them) are taken out before clap.
    let (argv, mut deqp_args) = match umbrage_conform::deqp::args::split(std::env::args_os().collect()) {
        Ok(split) => split,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::from(2);
        }
    };
    let cli = Cli::parse_from(argv);
    // The pipeline trace and `info --pipelines` name every crate's shaders, not only the pass's.
    for table in [umbrage_render::shaders::ALL, umbrage_conform::shaders::ALL, umbrage_bench::shaders::ALL] {
        umbrage::gpu::creation::name_shaders(table);
    }
    if let Err(e) = install_faults() {
        eprintln!("error: {e}");
        return ExitCode::from(2);
    }
    let result = match cli.command.unwrap_or(Command::Render {
        frame: FrameArgs::default(),
        out: "umbrage.png".into(),
        stats: None,
        view: View::Shaded,
        dump: None,
        time: 0.0,
    }) {
        Command::Render { frame, out, stats, view, dump, time } => render(&frame, &out, stats.as_deref(), view, dump.as_deref(), time),
        #[cfg(feature = "view")]
        Command::View { frame, view } => frame.options().and_then(|o| umbrage_cli::view::run(&frame.scene, o, &view)),
        Command::Info { pipelines: true, .. } => info_pipelines(),
        Command::Info { json, scene, .. } => info(json, scene.as_deref()),
        Command::Check { dir, band, threshold } => check(&dir, band, threshold),
        Command::ExportScene { scene, out } => export_scene_cli::export_scene(&scene, &out).map(|()| ExitCode::SUCCESS),
        Command::Bench(args) => bench_cli::bench_command(args),
        Command::Conform {
            out,
            filter,
            list,
            junit,
            device,
            no_isolate,
            timeout,
            jobs,
            expect,
            baseline,
            flakes,
            skips,
            fraction,
            fraction_start,
            chunk,
            child,
            child_result,
            child_progress,
        } => umbrage_conform::run(umbrage_conform::RunArgs {
            filter,
            list,
            junit,
            out,
            device,
            isolate: !no_isolate,
            timeout_s: timeout.unwrap_or(umbrage_conform::DEFAULT_TIMEOUT_S),
            jobs,
            child,
            child_result,
            child_progress,
            expect,
            timeout_given: timeout.is_some(),
            ci: umbrage_conform::deqp::CiArgs { baseline, flakes, skips, fraction, fraction_start, chunk },
            deqp: deqp_args.take(),
        }),
        Command::ConformMatrix { columns, notes, out } => {
            umbrage_conform::matrix::run(&columns, notes.as_deref(), &out).map(|_| ExitCode::SUCCESS)
        }
    };
    // Every context is gone by now: what validation said while they were torn down (objects
    // leaked at vkDestroyDevice) fails the run like any other validation message. Mutation, run
    // once: the renderer's sampler left undestroyed made `umbrage render` exit 1 (it exited 0).
    let result = result.and_then(|code| umbrage::gpu::context::process_validation().map(|()| code));
    match result {
        Ok(code) => code,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}

impl FrameArgs {
    fn options(&self) -> Result<RenderOptions> {
        Ok(RenderOptions {
            width: self.size.0,
            height: self.size.1,
            technique: with_shadow_map(self.method, ShadowMap { size: self.shadow_map_size, pcf: self.pcf, cube: self.cube }),
            depth_mode: self.depth_mode,
            index_format: self.index_format,
            counter: self.counter,
            transmit: self.transmit,
            self_shadow: self.self_shadow,
            jitter: self.jitter,
            samples: self.msaa,
            shading: self.shading,
            keep: !self.no_keep,
            ..Default::default()
        })
    }
}

fn render(frame: &FrameArgs, out: &Path, stats: Option<&Path>, view: View, dump: Option<&Path>, time: f64) -> Result<ExitCode> {
    let mut opts = frame.options()?;
    opts.view = view;
    opts.capture = dump.is_some();
    if !time.is_finite() {
        return Err(Error::input("--time", format!("must be a finite number of seconds, got {time}")));
    }
    let (scene, motion) = umbrage_scene::load_animated(&frame.scene)?;
    let scene = motion.scene_at(&scene, time);
    let ctx = umbrage::gpu::Context::new()?;
    if let Some(mode) = ctx.validation_mode {
        // What the run checked, so that a caller can hold it to the mode it asked for.
        eprintln!("umbrage: validation on ({})", mode.name());
    }
    let mut renderer = Renderer::new(ctx, scene, opts)?;
    if dump.is_some() {
        // A multisampled capture finds each sample's position where the device evaluated its
        // depth (measured: SwiftShader's are not the standard locations).
        umbrage_render::sample_locations::calibrate_sample_locations(&mut renderer)?;
    }
    let frame_out = renderer.render()?;
    umbrage_render::output::write_png(out, frame_out.width, frame_out.height, &frame_out.color)?;
    if let Some(path) = stats {
        let json = serde_json::to_string_pretty(&frame_out.stats).map_err(|e| Error::Internal(format!("JSON: {e}")))?;
        std::fs::write(path, json).map_err(|e| Error::io(path.display().to_string(), e))?;
    }
    if let Some(dir) = dump {
        umbrage_render::output::write_frame_dump(dir, renderer.scene(), &frame_out)?;
    }
    let s = &frame_out.stats;
    for w in &s.warnings {
        eprintln!("warning: {w}");
    }
    let gpu = s
        .gpu_ms
        .as_ref()
        .map(|g| format!(" (gpu {:.2} ms: shadow {:.2}, illuminate {:.2})", g.frame, g.shadow, g.illuminate))
        .unwrap_or_default();
    println!(
        "{} | {}x{} | {} | frame {:.2} ms{} | {} shadow triangles | {}",
        s.device,
        s.width,
        s.height,
        s.method,
        s.wall_ms,
        gpu,
        s.totals.triangles.total(),
        out.display()
    );
    renderer.context().check_validation()?;
    Ok(ExitCode::SUCCESS)
}

/// The fault injection `UMBRAGE_FAULT` and `UMBRAGE_MEMORY_BUDGET` ask for, installed for this
/// process (`umbrage::gpu::fault`; docs/bad-input.md). A malformed value is an error: a typo
/// in a test seam must not silently disable it.
fn install_faults() -> std::result::Result<(), String> {
    use umbrage::gpu::fault;
    if let Ok(spec) = std::env::var("UMBRAGE_FAULT") {
        fault::set_faults(&fault::parse_faults(&spec).map_err(|e| format!("UMBRAGE_FAULT: {e}"))?);
    }
    if let Ok(v) = std::env::var("UMBRAGE_MEMORY_BUDGET") {
        let bytes = fault::parse_bytes(&v).ok_or_else(|| format!("UMBRAGE_MEMORY_BUDGET='{v}': expected bytes, e.g. 64M"))?;
        fault::set_memory_budget(Some(bytes));
    }
    Ok(())
}

fn info_pipelines() -> Result<ExitCode> {
    let ctx = umbrage::gpu::Context::any_version(umbrage::gpu::context::validation_requested())?;
    let device = format!("{} ({} {})", ctx.info.name, ctx.info.driver, ctx.info.driver_info);
    let (groups, ctx) = pipelines_cli::create_all(ctx);
    let ok = pipelines_cli::print(&device, &groups);
    if let Some(ctx) = ctx {
        ctx.check_validation()?;
    }
    Ok(if ok { ExitCode::SUCCESS } else { ExitCode::FAILURE })
}

fn info(json: bool, scene: Option<&str>) -> Result<ExitCode> {
    let loaded = scene.map(umbrage_scene::load).transpose()?;
    let casters = match &loaded {
        Some(s) => Some(umbrage_render::output::caster_report(s)?),
        None => None,
    };
    let lights = loaded.as_ref().map(umbrage_render::output::light_report);
    let ctx = umbrage::gpu::Context::any_version(umbrage::gpu::context::validation_requested())?;
    let report = umbrage_render::output::info_report(&ctx);
    if json {
        let mut value = serde_json::to_value(&report).map_err(|e| Error::Internal(format!("JSON: {e}")))?;
        if let (Some(obj), Some(c)) = (value.as_object_mut(), casters) {
            obj.insert("casters".into(), serde_json::to_value(c).map_err(|e| Error::Internal(format!("JSON: {e}")))?);
        }
        if let (Some(obj), Some(l)) = (value.as_object_mut(), &lights) {
            obj.insert("lights".into(), serde_json::to_value(l).map_err(|e| Error::Internal(format!("JSON: {e}")))?);
        }
        println!("{}", serde_json::to_string_pretty(&value).map_err(|e| Error::Internal(format!("JSON: {e}")))?);
    } else {
        println!("{}", umbrage_render::output::info_text(&report));
        for (i, l) in lights.iter().flatten().enumerate() {
            let what = match (&l.shape, &l.size) {
                (Some(s), Some(v)) => format!("area {s} {v:?}, {} jittered point lights", l.point_lights),
                _ => l.kind.clone(),
            };
            println!("  light {i:<3} {what}");
        }
        for c in casters.iter().flatten() {
            println!(
                "  caster {:<24} {:<12} {:>8} triangles {:>3} chunk(s){}",
                c.name,
                c.path,
                c.triangles,
                c.chunks,
                if c.reason.is_empty() { String::new() } else { format!("  ({})", c.reason) }
            );
            if c.parts.len() > 1 {
                let manifold = c.parts.iter().filter(|p| p.path == umbrage::shadow::VolumePath::Manifold).count();
                println!(
                    "    {} parts: {} manifold, {} multiplicity (each planned on its own)",
                    c.parts.len(),
                    manifold,
                    c.parts.len() - manifold
                );
                for (i, p) in c.parts.iter().enumerate().filter(|(_, p)| p.path != umbrage::shadow::VolumePath::Manifold) {
                    println!("      part {i}: {} triangles, multiplicity ({})", p.triangles, p.reason);
                }
            }
        }
    }
    Ok(ExitCode::SUCCESS)
}

fn check(dir: &Path, band: u32, threshold: f64) -> Result<ExitCode> {
    let report = umbrage_reference::check_dump(dir, band)?;
    println!("{report}");
    Ok(if report.passed(threshold) { ExitCode::SUCCESS } else { ExitCode::FAILURE })
}
