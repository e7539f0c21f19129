//! `umbrage bench`: its arguments and its three modes (the classic speed-against-error table,
//! the fill-vertex suite, the soak), split out of main.rs.

use super::{parse_method, parse_size, with_shadow_map};
use clap::ValueEnum;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use umbrage::{Error, Result};
use umbrage_render::{Counter, IndexFormat, RenderOptions, RenderTechnique, ShadowMap, Technique};

/// `umbrage bench` (one struct so that new modes add fields here, not to the dispatch).
#[derive(clap::Args)]
pub(crate) struct BenchArgs {
    /// Scenes (repeatable); default: the fill-rate and vertex-rate bench scenes plus default.
    #[arg(long = "scene")]
    scenes: Vec<String>,
    /// Comma-separated techniques, every one `render --method` accepts (default: the five
    /// volume methods, edgequad and shadowmap, and rayquery where the device has ray query).
    #[arg(long, value_delimiter = ',', value_parser = parse_method)]
    methods: Vec<RenderTechnique>,
    /// Frames measured per variant (after one warm-up frame).
    #[arg(long, default_value_t = 10)]
    frames: usize,
    /// Run each scene's motion (its camera's walk or orbit, its meshes' spins, its lights'
    /// paths) over the frames: the warm-up frame at time 0, frame k at k/30 s; each row's error
    /// is then the last frame's. Without it every frame is at time 0.
    #[arg(long)]
    motion: bool,
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
    /// Comma-separated PCF lookups for the shadowmap technique (taps, gather): one row each,
    /// side by side (`shadowmap-2048`, `shadowmap-2048-gather`).
    #[arg(long, value_enum, value_delimiter = ',', default_value = "taps")]
    pcf: Vec<umbrage_render::Pcf>,
    /// Comma-separated ways to render a point light's cube faces for the shadowmap technique
    /// (atlas, multiview): one row each (`shadowmap-2048`, `shadowmap-2048-multiview`).
    #[arg(long, value_enum, value_delimiter = ',', default_value = "atlas")]
    cube: Vec<umbrage_render::CubeFaces>,
    /// Comma-separated ways to record the compute technique's volume draws (auto, count,
    /// multi, per-record, per-chunk): one row each (`compute`, `compute-per-chunk`, ...), side
    /// by side; a way the device lacks fails the run.
    #[arg(long, value_enum, value_delimiter = ',', default_value = "auto")]
    compute_draws: Vec<umbrage_render::ComputeDraws>,
    /// Comma-separated task-stage settings for the mesh technique (on, off): one row each
    /// (`mesh`, `mesh-notask`: no task stage, every meshlet's mesh workgroup runs).
    #[arg(long, value_enum, value_delimiter = ',', default_value = "on")]
    mesh_task: Vec<OnOff>,
    /// Plan every light–caster pair from scratch every frame (default: plans kept across
    /// frames, `PassSettings::keep`).
    #[arg(long)]
    no_keep: bool,
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
    /// With --suite: fewer points and frames (under 6 minutes on lavapipe on 2 quiet cores, the one-factor sweeps and the bounds' ablations included).
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

/// A setting switched on or off.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum OnOff {
    /// On.
    On,
    /// Off.
    Off,
}

/// `bench --suite`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum SuiteArg {
    /// Fill-rate vs vertex-rate: the limits, sweeps that cross over, the bound at each point.
    #[value(name = "fill-vertex")]
    FillVertex,
    /// What a frame costs when only some of the scene changed (issue 55): bench/level,
    /// default, stress and bench/vertex in motion, planned every frame, kept and compute side
    /// by side, and the CPU against lights and casters; docs/frame-cost.md.
    #[value(name = "frame-cost")]
    FrameCost,
}

pub(crate) fn bench_command(a: BenchArgs) -> Result<ExitCode> {
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
    let techniques = bench_techniques(&a.methods, a.shadow_map_size, (&a.pcf, &a.cube));
    let opts = RenderOptions {
        width: a.size.0,
        height: a.size.1,
        index_format: a.index_format,
        frames_in_flight: a.frames_in_flight,
        keep: !a.no_keep,
        ..Default::default()
    };
    let listed = Listed {
        techniques,
        default_list: a.methods.is_empty(),
        compute_draws: a.compute_draws,
        mesh_task: a.mesh_task.iter().map(|&t| t == OnOff::On).collect(),
    };
    let run = Run { frames: a.frames, motion: a.motion, opts };
    bench(a.scenes, listed, a.counters, run, a.json.as_deref(), a.markdown.as_deref())
}

/// `bench --suite fill-vertex`: runs the suite, writes its outputs, prints the Markdown.
fn suite(a: &BenchArgs) -> Result<ExitCode> {
    use umbrage_bench::sweeps::Scale;
    let tiny = a.tiny || std::env::var("UMBRAGE_BENCH_TINY").is_ok_and(|v| v == "1");
    if a.suite == Some(SuiteArg::FrameCost) {
        return frame_cost(a, tiny);
    }
    let scale = match (tiny, a.quick) {
        (true, _) => Scale::Tiny,
        (false, true) => Scale::Quick,
        (false, false) => Scale::Full,
    };
    let cfg = umbrage_bench::suite::SuiteConfig {
        scale,
        frames: None,
        frames_in_flight: a.frames_in_flight,
        out: a.out.clone(),
        progress: !tiny,
    };
    let ctx = umbrage::gpu::Context::new()?;
    let report = umbrage_bench::suite::run(ctx, &cfg)?;
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

/// `bench --suite frame-cost`: runs it, writes its plots and JSON into --out and its report
/// (`frame-cost.md` there, or --markdown with the plots linked relative to it), prints it.
fn frame_cost(a: &BenchArgs, tiny: bool) -> Result<ExitCode> {
    use umbrage_bench::frame_cost::{self, FrameCostConfig};
    let cfg = if tiny { FrameCostConfig::tiny(a.out.clone()) } else { FrameCostConfig::full(a.out.clone()) };
    let ctx = umbrage::gpu::Context::new()?;
    let report = frame_cost::run(ctx, &cfg)?;
    let (path, plots) = match &a.markdown {
        Some(m) => {
            let base = m.parent().unwrap_or(Path::new(""));
            let rel = a.out.strip_prefix(base).map(Path::to_path_buf).unwrap_or_else(|_| a.out.clone());
            (m.clone(), rel.display().to_string())
        }
        None => (a.out.join("frame-cost.md"), ".".to_string()),
    };
    let md = report.markdown(&plots);
    std::fs::write(&path, &md).map_err(|e| Error::io(path.display().to_string(), e))?;
    println!("{md}");
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
    methods: &[RenderTechnique],
    size: (u32, u32),
    frames_in_flight: usize,
    json: Option<&Path>,
    markdown: Option<&Path>,
) -> Result<ExitCode> {
    let frames = args.soak.unwrap_or(0);
    let technique = methods.first().copied().unwrap_or_default();
    let options = RenderOptions { width: size.0, height: size.1, technique, frames_in_flight, ..Default::default() };
    let cfg = umbrage_cli::soak::SoakConfig {
        scene: scene.unwrap_or("default").to_string(),
        frames,
        period: args.soak_period.min(frames.max(1)),
        sample_every: (frames / 200).max(1),
        tolerance: args.soak_tolerance / 100.0,
        options,
    };
    let report = umbrage_cli::soak::soak(&cfg)?;
    let md = report.markdown();
    println!("{md}");
    if let Some(p) = json {
        let text = serde_json::to_string_pretty(&report).map_err(|e| Error::Internal(format!("JSON: {e}")))?;
        std::fs::write(p, text).map_err(|e| Error::io(p.display().to_string(), e))?;
    }
    if let Some(p) = markdown {
        std::fs::write(p, &md).map_err(|e| Error::io(p.display().to_string(), e))?;
    }
    Ok(if report.passed { ExitCode::SUCCESS } else { ExitCode::FAILURE })
}

fn bench_techniques(
    methods: &[RenderTechnique],
    shadow_map_size: u32,
    (pcfs, cubes): (&[umbrage_render::Pcf], &[umbrage_render::CubeFaces]),
) -> Vec<RenderTechnique> {
    let size = if shadow_map_size > 0 { shadow_map_size } else { 2048 };
    let listed: Vec<RenderTechnique> = if methods.is_empty() {
        let sizes: &[u32] = if shadow_map_size > 0 { &[size] } else { &[] };
        // Ray query and mesh shaders join once the device is known (`bench`).
        umbrage_bench::methods::all_techniques(sizes, false, false, false)
    } else {
        methods.iter().map(|&m| with_shadow_map(m, ShadowMap::new(size))).collect()
    };
    // Each listed once, a shadow map once per way of rendering its cube faces and PCF lookup
    // asked for (`--cube`, `--pcf`, never empty).
    let mut out: Vec<RenderTechnique> = Vec::new();
    for t in listed {
        let variants: Vec<RenderTechnique> = match t {
            RenderTechnique::ShadowMap(ShadowMap { size, .. }) => {
                cubes.iter().flat_map(|&cube| pcfs.iter().map(move |&pcf| ShadowMap { size, pcf, cube }.into())).collect()
            }
            t => vec![t],
        };
        for v in variants {
            if !out.contains(&v) {
                out.push(v);
            }
        }
    }
    out
}

/// The rows `bench` runs: the techniques, and the variants of the compute and mesh ones.
struct Listed {
    techniques: Vec<RenderTechnique>,
    /// No `--methods` given: the device's mesh and ray-query techniques are added.
    default_list: bool,
    /// `--compute-draws`.
    compute_draws: Vec<umbrage_render::ComputeDraws>,
    /// `--mesh-task`, on as `true`.
    mesh_task: Vec<bool>,
}

/// How `bench` runs each row's frames.
struct Run {
    /// `--frames`.
    frames: usize,
    /// `--motion`.
    motion: bool,
    /// The renderer's options.
    opts: RenderOptions,
}

fn bench(
    scenes: Vec<String>,
    Listed { techniques, default_list, compute_draws, mesh_task }: Listed,
    counters: Vec<Counter>,
    Run { frames, motion, opts }: Run,
    json: Option<&Path>,
    markdown: Option<&Path>,
) -> Result<ExitCode> {
    let scenes = if scenes.is_empty() { vec!["bench/fill".into(), "bench/vertex".into(), "default".into()] } else { scenes };
    let ctx = umbrage::gpu::Context::new()?;
    let mut techniques = techniques;
    if default_list && ctx.features.mesh_shader {
        techniques.push(Technique::Mesh.into());
    }
    if default_list && ctx.features.ray_query {
        techniques.push(Technique::RayQuery.into());
    }
    let cfg = umbrage_bench::BenchConfig { scenes, techniques, counters, frames, opts, compute_draws, mesh_task, motion };
    let report = umbrage_bench::run(ctx, &cfg, |r| {
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
        let s = serde_json::to_string_pretty(&report).map_err(|e| Error::Internal(format!("JSON: {e}")))?;
        std::fs::write(p, s).map_err(|e| Error::io(p.display().to_string(), e))?;
    }
    if let Some(p) = markdown {
        std::fs::write(p, md).map_err(|e| Error::io(p.display().to_string(), e))?;
    }
    Ok(ExitCode::SUCCESS)
}
