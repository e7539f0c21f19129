//! The `umbrage` command line: render | view | info | check | conform | bench.

use clap::{Parser, Subcommand, ValueEnum};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use umbrage::render::{Counter, DepthMode, IndexFormat, RenderOptions, Renderer, Technique, TransmitMode, View};
use umbrage::{Error, Result};

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
    /// the Cg article); planar; compute (GPU possible silhouettes); or shadowmap (the PCF baseline).
    #[arg(long, value_enum, default_value = "auto")]
    method: MethodArg,
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
    #[arg(long, value_enum, default_value = "log16")]
    transmit: TransmitArg,
    /// Texels per side of each shadow map (--method shadowmap).
    #[arg(long, default_value_t = 2048)]
    shadow_map_size: u32,
    /// Partial self-shadowing of transparent casters (Kim et al. 2008): their forward light
    /// passes read a light-intensity map built on the nearest transparent surface.
    #[arg(long)]
    self_shadow: bool,
    /// Re-draw the area lights' jittered sample pattern every frame (default: the same
    /// pattern every frame).
    #[arg(long)]
    jitter: bool,
}

/// `--method`: every technique `render` and `bench` accept.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum MethodArg {
    /// McGuire's three cases (open / non-manifold casters on the multiplicity path).
    Auto,
    /// McGuire et al. 2003: z-pass / z-fail / z-fail with light cap per caster.
    Mcguire,
    /// Lengyel: z-fail only where the near plane may cut the volume.
    Lengyel,
    /// Everitt-Kilgard: z-fail everywhere.
    #[value(name = "everitt-kilgard")]
    EverittKilgard,
    /// Carmack's z-fail everywhere.
    Zfail,
    /// z-pass everywhere (wrong with the eye in a volume).
    Zpass,
    /// z-pass with the stencil cleared to the number of volumes containing the eye (the
    /// lecture notes' eye-in-shadow fix; wrong where a volume crosses the near plane).
    #[value(name = "zpass-clear")]
    ZpassClear,
    /// The Cg article's GPU-only edge quads.
    Edgequad,
    /// Flat projected shadows onto y = 0 (the Cg article's baseline).
    Planar,
    /// McGuire's cases with GPU possible silhouettes (compute pass, indirect draws).
    Compute,
    /// The shadow-map baseline (PCF 3x3).
    Shadowmap,
}

impl MethodArg {
    fn technique(self, shadow_map_size: u32) -> Technique {
        use umbrage::shadow::Method as M;
        match self {
            MethodArg::Auto | MethodArg::Mcguire => Technique::Volumes(M::McGuire),
            MethodArg::Lengyel => Technique::Volumes(M::Lengyel),
            MethodArg::EverittKilgard => Technique::Volumes(M::EverittKilgard),
            MethodArg::Zfail => Technique::Volumes(M::ZFail),
            MethodArg::Zpass => Technique::Volumes(M::ZPass),
            MethodArg::ZpassClear => Technique::Volumes(M::ZPassClear),
            MethodArg::Edgequad => Technique::EdgeQuads,
            MethodArg::Planar => Technique::Planar,
            MethodArg::Compute => Technique::Compute,
            MethodArg::Shadowmap => Technique::ShadowMap { size: shadow_map_size },
        }
    }
}

/// `--transmit`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum TransmitArg {
    Log16,
    Mul16,
    Log32,
    Mul32,
}

impl TransmitArg {
    fn mode(self) -> TransmitMode {
        match self {
            TransmitArg::Log16 => TransmitMode { fp32: false, log: true },
            TransmitArg::Mul16 => TransmitMode { fp32: false, log: false },
            TransmitArg::Log32 => TransmitMode { fp32: true, log: true },
            TransmitArg::Mul32 => TransmitMode { fp32: true, log: false },
        }
    }
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
        view: umbrage::view::ViewArgs,
    },
    /// Device, driver, optional features and the code paths they select.
    Info {
        #[arg(long)]
        json: bool,
        /// Also classify this scene's casters: which path each takes (three-case manifold or
        /// multiplicity) and why, with their triangles and chunks.
        #[arg(long)]
        scene: Option<String>,
    },
    /// Speed against error: every method on each scene, side by side on this device; with
    /// `--suite fill-vertex`, the fill-rate vs vertex-rate suite against the device's limits.
    Bench(BenchArgs),
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
        /// Run every unit (a configuration's submission, the legacy checks, the pipeline
        /// checks) in this process instead of a child process each: faster to debug, but a
        /// driver crash ends the run.
        #[arg(long)]
        no_isolate: bool,
        /// Seconds a child may run before it is killed and its cases reported as hung.
        #[arg(long, default_value_t = 300.0, value_name = "SECONDS")]
        timeout: f64,
        /// Child processes at once (0: one per CPU core, as deqp-runner does).
        #[arg(long, default_value_t = 0, value_name = "N")]
        jobs: usize,
        /// The driver's expected failures (`case,Fail` / `case,Crash` lines, as Mesa's CI
        /// keeps them): exit 0 only when the run matches the list, no new failure and no
        /// unexpected pass.
        #[arg(long, value_name = "FILE")]
        expect: Option<PathBuf>,
        /// Internal: run one unit and write its result to --child-result (crash isolation).
        #[arg(long, hide = true, value_name = "UNIT")]
        child: Option<String>,
        /// Internal: where a child writes its result.
        #[arg(long, hide = true, value_name = "FILE")]
        child_result: Option<PathBuf>,
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

/// `umbrage bench` (one struct so that new modes add fields here, not to the dispatch).
#[derive(clap::Args)]
struct BenchArgs {
    /// Scenes (repeatable); default: the fill-rate and vertex-rate bench scenes plus default.
    #[arg(long = "scene")]
    scenes: Vec<String>,
    /// Comma-separated techniques, every one `render --method` accepts (default: the five
    /// volume methods, edgequad and shadowmap).
    #[arg(long, value_enum, value_delimiter = ',')]
    methods: Vec<MethodArg>,
    #[arg(long, default_value_t = 10)]
    frames: usize,
    #[arg(long, default_value = "960x540", value_parser = parse_size)]
    size: (u32, u32),
    #[arg(long, value_enum, default_value = "auto")]
    index_format: IndexFormat,
    /// Comma-separated counters to compare (stencil, float).
    #[arg(long, value_enum, value_delimiter = ',', default_value = "stencil")]
    counters: Vec<Counter>,
    /// Frames in flight for the throughput measurement.
    #[arg(long, default_value_t = 2)]
    frames_in_flight: usize,
    /// Shadow-map size when the shadowmap technique runs (0: leave shadowmap out of the
    /// default technique list).
    #[arg(long, default_value_t = 2048)]
    shadow_map_size: u32,
    /// Write the report as JSON.
    #[arg(long)]
    json: Option<PathBuf>,
    /// Write the report as a Markdown table (with --suite: the suite's report, plots linked
    /// relative to it).
    #[arg(long)]
    markdown: Option<PathBuf>,
    /// Run a benchmark suite instead of the fixed scenes: `fill-vertex` (limits, counters,
    /// sweeps, bounds, crossovers, ablations, plots); writes into --out.
    #[arg(long, value_enum)]
    suite: Option<SuiteArg>,
    /// With --suite: fewer points and frames (about 3 minutes on lavapipe on 2 cores).
    #[arg(long)]
    quick: bool,
    /// With --suite: output directory for bench.json, bench.csv, the plots and bench.md.
    #[arg(long, default_value = "bench-out")]
    out: PathBuf,
    /// With --suite: two points a sweep at 160x90 (tests; also UMBRAGE_BENCH_TINY=1).
    #[arg(long, hide = true)]
    tiny: bool,
    #[command(flatten)]
    soak: SoakArgs,
}

/// `bench --suite`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum SuiteArg {
    /// Fill-rate vs vertex-rate: the limits, sweeps that cross over, the bound at each point.
    #[value(name = "fill-vertex")]
    FillVertex,
}

impl Default for FrameArgs {
    fn default() -> Self {
        FrameArgs {
            scene: "default".into(),
            size: (960, 540),
            method: MethodArg::Auto,
            depth_mode: DepthMode::Infinite,
            index_format: IndexFormat::Auto,
            counter: Counter::Stencil,
            transmit: TransmitArg::Log16,
            shadow_map_size: 2048,
            self_shadow: false,
            jitter: false,
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
    let cli = Cli::parse();
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
        Command::View { frame, view } => frame.options().and_then(|o| umbrage::view::run(&frame.scene, o, &view)),
        Command::Info { json, scene } => info(json, scene.as_deref()),
        Command::Check { dir, band, threshold } => check(&dir, band, threshold),
        Command::Bench(args) => bench_command(args),
        Command::Conform { out, filter, list, junit, device, no_isolate, timeout, jobs, expect, child, child_result } => {
            umbrage::conform::run(umbrage::conform::RunArgs {
                filter,
                list,
                junit,
                out,
                device,
                isolate: !no_isolate,
                timeout_s: timeout,
                jobs,
                child,
                child_result,
                expect,
            })
        }
        Command::ConformMatrix { columns, notes, out } => {
            umbrage::conform::matrix::run(&columns, notes.as_deref(), &out).map(|_| ExitCode::SUCCESS)
        }
    };
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
            technique: self.method.technique(self.shadow_map_size),
            depth_mode: self.depth_mode,
            index_format: self.index_format,
            counter: self.counter,
            transmit: self.transmit.mode(),
            self_shadow: self.self_shadow,
            jitter: self.jitter,
            ..Default::default()
        })
    }
}

fn render(frame: &FrameArgs, out: &Path, stats: Option<&Path>, view: View, dump: Option<&Path>, time: f64) -> Result<ExitCode> {
    let mut opts = frame.options()?;
    opts.view = view;
    opts.capture = dump.is_some();
    if !time.is_finite() {
        return Err(Error::Other(format!("--time must be a finite number of seconds, got {time}")));
    }
    let (scene, motion) = umbrage::scene::load_animated(&frame.scene)?;
    let scene = motion.scene_at(&scene, time);
    let ctx = umbrage::gpu::Context::new()?;
    let mut renderer = Renderer::new(ctx, scene, opts)?;
    let frame_out = renderer.render()?;
    umbrage::output::write_png(out, frame_out.width, frame_out.height, &frame_out.color)?;
    if let Some(path) = stats {
        let json = serde_json::to_string_pretty(&frame_out.stats).map_err(|e| Error::Other(e.to_string()))?;
        std::fs::write(path, json).map_err(|e| Error::io(path.display().to_string(), e))?;
    }
    if let Some(dir) = dump {
        umbrage::output::write_frame_dump(dir, renderer.scene(), &frame_out)?;
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

fn info(json: bool, scene: Option<&str>) -> Result<ExitCode> {
    let loaded = scene.map(umbrage::scene::load).transpose()?;
    let casters = match &loaded {
        Some(s) => Some(umbrage::output::caster_report(s)?),
        None => None,
    };
    let lights = loaded.as_ref().map(umbrage::output::light_report);
    let ctx = umbrage::gpu::Context::any_version(umbrage::gpu::context::validation_requested())?;
    let report = umbrage::output::info_report(&ctx);
    if json {
        let mut value = serde_json::to_value(&report).map_err(|e| Error::Other(e.to_string()))?;
        if let (Some(obj), Some(c)) = (value.as_object_mut(), casters) {
            obj.insert("casters".into(), serde_json::to_value(c).map_err(|e| Error::Other(e.to_string()))?);
        }
        if let (Some(obj), Some(l)) = (value.as_object_mut(), &lights) {
            obj.insert("lights".into(), serde_json::to_value(l).map_err(|e| Error::Other(e.to_string()))?);
        }
        println!("{}", serde_json::to_string_pretty(&value).map_err(|e| Error::Other(e.to_string()))?);
    } else {
        println!("{}", umbrage::output::info_text(&report));
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
                let manifold = c.parts.iter().filter(|p| p.path == "manifold").count();
                println!(
                    "    {} parts: {} manifold, {} multiplicity (each planned on its own)",
                    c.parts.len(),
                    manifold,
                    c.parts.len() - manifold
                );
                for (i, p) in c.parts.iter().enumerate().filter(|(_, p)| p.path != "manifold") {
                    println!("      part {i}: {} triangles, multiplicity ({})", p.triangles, p.reason);
                }
            }
        }
    }
    Ok(ExitCode::SUCCESS)
}

fn check(dir: &Path, band: u32, threshold: f64) -> Result<ExitCode> {
    let report = umbrage::reference::check_dump(dir, band)?;
    println!("{report}");
    Ok(if report.passed(threshold) { ExitCode::SUCCESS } else { ExitCode::FAILURE })
}

fn bench_command(a: BenchArgs) -> Result<ExitCode> {
    if a.soak.soak.is_some() {
        return soak_cmd(
            &a.soak,
            a.scenes.first().map(String::as_str),
            &a.methods,
            a.size,
            a.frames_in_flight,
            a.json.as_deref(),
            a.markdown.as_deref(),
        );
    }
    if a.suite.is_some() {
        return suite(&a);
    }
    let techniques = bench_techniques(&a.methods, a.shadow_map_size);
    let opts = RenderOptions {
        width: a.size.0,
        height: a.size.1,
        index_format: a.index_format,
        frames_in_flight: a.frames_in_flight,
        ..Default::default()
    };
    bench(a.scenes, techniques, a.counters, a.frames, opts, a.json.as_deref(), a.markdown.as_deref())
}

/// `bench --suite fill-vertex`: runs the suite, writes its outputs, prints the Markdown.
fn suite(a: &BenchArgs) -> Result<ExitCode> {
    use umbrage::bench::sweeps::Scale;
    let tiny = a.tiny || std::env::var("UMBRAGE_BENCH_TINY").is_ok_and(|v| v == "1");
    let scale = match (tiny, a.quick) {
        (true, _) => Scale::Tiny,
        (false, true) => Scale::Quick,
        (false, false) => Scale::Full,
    };
    let cfg = umbrage::bench::suite::SuiteConfig {
        scale,
        frames: None,
        frames_in_flight: a.frames_in_flight,
        out: a.out.clone(),
        progress: !tiny,
    };
    let ctx = umbrage::gpu::Context::new()?;
    let report = umbrage::bench::suite::run(ctx, &cfg)?;
    let md = report.markdown(".");
    let p = a.out.join("bench.md");
    std::fs::write(&p, &md).map_err(|e| Error::io(p.display().to_string(), e))?;
    println!("{md}");
    // --markdown: the same report elsewhere (docs/bench-lavapipe.md), plots linked relative to it.
    if let Some(m) = &a.markdown {
        let base = m.parent().unwrap_or(Path::new(""));
        let rel = a.out.strip_prefix(base).map(Path::to_path_buf).unwrap_or_else(|_| a.out.clone());
        let text = report.markdown(&rel.display().to_string());
        std::fs::write(m, text).map_err(|e| Error::io(m.display().to_string(), e))?;
    }
    Ok(ExitCode::SUCCESS)
}

/// The bench's techniques: the given ones, or every volume method, edge quads and (size > 0)
/// shadow maps.
/// `umbrage bench --soak N`: memory and correctness held over many frames in one process.
#[derive(clap::Args, Debug)]
struct SoakArgs {
    /// Soak instead of benchmarking: render N frames of one scene (the first --scene, default
    /// `default`) with the lights orbiting and the casters spinning, and fail if host or GPU
    /// memory drifts after warm-up, validation reports anything, or the last frame differs
    /// from a fresh render of the same state. --json / --markdown write the samples.
    #[arg(long, value_name = "N")]
    soak: Option<usize>,
    /// Frames per turn of the soak's motion (the first turn is the warm-up).
    #[arg(long, default_value_t = 500)]
    soak_period: usize,
    /// Allowed spread of the memory samples after warm-up, percent.
    #[arg(long, default_value_t = 1.0)]
    soak_tolerance: f64,
}

fn soak_cmd(
    args: &SoakArgs,
    scene: Option<&str>,
    methods: &[MethodArg],
    size: (u32, u32),
    frames_in_flight: usize,
    json: Option<&Path>,
    markdown: Option<&Path>,
) -> Result<ExitCode> {
    let frames = args.soak.unwrap_or(0);
    let technique = methods.first().map(|m| m.technique(2048)).unwrap_or_default();
    let options = RenderOptions { width: size.0, height: size.1, technique, frames_in_flight, ..Default::default() };
    let cfg = umbrage::soak::SoakConfig {
        scene: scene.unwrap_or("default").to_string(),
        frames,
        period: args.soak_period.min(frames.max(1)),
        sample_every: (frames / 200).max(1),
        tolerance: args.soak_tolerance / 100.0,
        options,
    };
    let report = umbrage::soak::soak(&cfg)?;
    let md = report.markdown();
    println!("{md}");
    if let Some(p) = json {
        let text = serde_json::to_string_pretty(&report).map_err(|e| Error::Other(e.to_string()))?;
        std::fs::write(p, text).map_err(|e| Error::io(p.display().to_string(), e))?;
    }
    if let Some(p) = markdown {
        std::fs::write(p, &md).map_err(|e| Error::io(p.display().to_string(), e))?;
    }
    Ok(if report.passed { ExitCode::SUCCESS } else { ExitCode::FAILURE })
}

fn bench_techniques(methods: &[MethodArg], shadow_map_size: u32) -> Vec<Technique> {
    let size = if shadow_map_size > 0 { shadow_map_size } else { 2048 };
    let mut out: Vec<Technique> = Vec::new();
    if methods.is_empty() {
        let sizes: &[u32] = if shadow_map_size > 0 { &[size] } else { &[] };
        out = umbrage::bench::methods::all_techniques(sizes);
    } else {
        for m in methods {
            let t = m.technique(size);
            if !out.contains(&t) {
                out.push(t);
            }
        }
    }
    out
}

fn bench(
    scenes: Vec<String>,
    techniques: Vec<Technique>,
    counters: Vec<Counter>,
    frames: usize,
    opts: RenderOptions,
    json: Option<&Path>,
    markdown: Option<&Path>,
) -> Result<ExitCode> {
    let scenes = if scenes.is_empty() { vec!["bench/fill".into(), "bench/vertex".into(), "default".into()] } else { scenes };
    let ctx = umbrage::gpu::Context::new()?;
    let cfg = umbrage::bench::BenchConfig { scenes, techniques, counters, frames, opts };
    let report = umbrage::bench::run(ctx, &cfg, |r| {
        eprintln!(
            "{:<14} {:<16} {:<8} gpu {:>8} ms  shadow {:>8} ms  {:>7.1} fps  {:>8} tris  error {:.4}%",
            r.scene,
            r.method,
            r.counter,
            r.gpu_frame_ms.map(|v| format!("{v:.2}")).unwrap_or_else(|| "-".into()),
            r.gpu_shadow_ms.map(|v| format!("{v:.2}")).unwrap_or_else(|| "-".into()),
            r.throughput_fps,
            r.shadow_triangles,
            r.error_fraction * 100.0
        )
    })?;
    let md = report.markdown();
    println!("{md}");
    if let Some(p) = json {
        let s = serde_json::to_string_pretty(&report).map_err(|e| Error::Other(e.to_string()))?;
        std::fs::write(p, s).map_err(|e| Error::io(p.display().to_string(), e))?;
    }
    if let Some(p) = markdown {
        std::fs::write(p, md).map_err(|e| Error::io(p.display().to_string(), e))?;
    }
    Ok(ExitCode::SUCCESS)
}
