//! The suite's outputs: `bench.json` (a contract other tools read: the keys of issue #10, more
//! keys welcome), `bench.csv` (one line per row) and the Markdown report (docs/bench-*.md).

use super::limits::Limits;
use crate::error::{Error, Result};
use serde::Serialize;
use std::fmt::Write as _;
use std::path::Path;

/// The limits a row's fractions were computed against (the run's, repeated in each row).
#[derive(Clone, Copy, Debug, Default, Serialize)]
pub struct RowLimits {
    /// Stencil fill, Gfragments / s.
    pub stencil_fill_gfrag_s: f64,
    /// Small-triangle rate, Mtriangles / s.
    pub small_tri_mtri_s: f64,
    /// Sliver rate (screen-spanning thin triangles: volume sides), Mtriangles / s.
    pub sliver_tri_mtri_s: f64,
    /// Draw calls / s.
    pub draws_per_s: f64,
}

/// One measured point: a scene at a size, one technique, medians over the timed frames, the
/// shadow pass's counters from a counting frame, and its fractions of the limits.
#[derive(Clone, Debug, Default, Serialize)]
pub struct SuiteRow {
    /// The suite (`fill-vertex`).
    pub suite: String,
    /// Which sweep or table the row belongs to: `scenes`, `resolution`, `tessellation`,
    /// `lights`, `light_distance`, `casters`, `ablation`.
    pub sweep: String,
    /// The sweep's variable at this point (pixels, caster triangles, lights, light height in
    /// sphere spacings, casters; 0 for `scenes` and `ablation`).
    pub x: f64,
    /// The ablation's variant (`all-on`, `scissor-off`, `depth-bounds-off`, `culling-off`,
    /// `index-u8`, ...); empty elsewhere.
    pub variant: String,
    /// Scene name.
    pub scene: String,
    /// Technique (`mcguire`, ..., `edgequad`, `planar`, `shadowmap-<size>`).
    pub method: String,
    /// `stencil` (volumes) or `float` (shadow maps count in the float target).
    pub counter: String,
    /// Index format requested (`auto`, `u8`, `u16`, `u32`, `naive`).
    pub index_format: String,
    /// Frame width, pixels.
    pub width: u32,
    /// Frame height, pixels.
    pub height: u32,
    /// Shadow-casting triangles in the scene.
    pub triangles: u64,
    /// Shadow-casting meshes.
    pub casters: u64,
    /// Lights.
    pub lights: u64,
    /// Timed frames (medians over them).
    pub frames: usize,
    /// Median GPU time of the shadow determination (all lights), ms.
    pub gpu_shadow_ms: Option<f64>,
    /// Median GPU time of the whole frame, ms.
    pub gpu_frame_ms: Option<f64>,
    /// Median GPU time of the G-buffer pass, ms.
    pub gpu_depth_ms: Option<f64>,
    /// Median GPU time of the illumination passes, ms.
    pub gpu_illuminate_ms: Option<f64>,
    /// Fragments the determination rasterised (exact: precise occlusion query around its
    /// counting variant); `None` without `occlusionQueryPrecise`. 0 for shadow maps (no volumes).
    pub stencil_fragments: Option<u64>,
    /// Shadow-volume triangles drawn (all lights).
    pub shadow_triangles: u64,
    /// Of them, side triangles (extruded to infinity: slivers on screen).
    pub shadow_sides: u64,
    /// Input-assembly primitives of the shadow span (pipeline statistics; for shadow maps the
    /// triangles drawn into the maps).
    pub primitives: Option<u64>,
    /// Primitives out of clipping in the shadow span.
    pub clipped_primitives: Option<u64>,
    /// Volume draw calls.
    pub draws: u64,
    /// Median CPU planning time (silhouettes included), ms.
    pub cpu_plan_ms: f64,
    /// Geometry bytes the CPU wrote for the frame's shadows (streams + uploads).
    pub bytes: u64,
    /// Worst light's mismatched pixels outside a 1-pixel band / compared pixels, where the
    /// reference was rendered for this point (`scenes` rows); `None` elsewhere.
    pub error_fraction: Option<f64>,
    /// `stencil_fragments / stencil fill limit / gpu_shadow_ms`: the share of the pass's time
    /// its fill costs at the measured limit.
    pub fill_fraction: Option<f64>,
    /// `(sides / sliver limit + other shadow triangles / small-triangle limit) / gpu_shadow_ms`
    /// (shadow maps: primitives / small-triangle limit).
    pub vertex_fraction: Option<f64>,
    /// `draws / draw-call limit / gpu_shadow_ms`.
    pub draw_fraction: Option<f64>,
    /// `cpu_plan_ms / gpu_shadow_ms`: above 1 the CPU's planning outlasts the GPU pass.
    pub cpu_fraction: Option<f64>,
    /// The largest fraction's name: `fill`, `vertex`, `draw` or `cpu` (`none` without timings).
    pub bound: String,
    /// The limits the fractions were computed against.
    pub limits: RowLimits,
}

/// Where something changes along a sweep: the bound, or which of two methods is faster.
#[derive(Clone, Debug, Serialize)]
pub struct Crossover {
    /// `bound` (the row's bound changes) or `overtake` (method order changes).
    pub kind: String,
    /// The sweep.
    pub sweep: String,
    /// `bound`: the method; `overtake`: the method faster after the crossing.
    pub method: String,
    /// `bound`: the bound before; `overtake`: the method faster before.
    pub from: String,
    /// `bound`: the bound after; `overtake`: the method faster after (= `method`).
    pub to: String,
    /// The two sweep points the change lies between.
    pub between: [f64; 2],
    /// The crossing, interpolated on a log scale of the sweep variable (fractions or times
    /// equal there).
    pub at: f64,
}

/// One ablation: the same scene and method with an optimisation on and off.
#[derive(Clone, Debug, Serialize)]
pub struct Ablation {
    /// What was switched: `scissor`, `depth-bounds`, `culling`, `method` (triangles of McGuire
    /// vs the others), `index-format`.
    pub what: String,
    /// Scene.
    pub scene: String,
    /// The variant measured against the baseline.
    pub variant: String,
    /// The baseline variant.
    pub baseline: String,
    /// GPU shadow ms, variant / baseline.
    pub time_ratio: Option<f64>,
    /// Rasterised stencil fragments, variant / baseline.
    pub fragment_ratio: Option<f64>,
    /// Shadow triangles, variant / baseline.
    pub triangle_ratio: Option<f64>,
    /// Bytes sent, variant / baseline.
    pub byte_ratio: Option<f64>,
    /// Why the ablation could not run on this device (e.g. no depth bounds), else empty.
    pub skipped: String,
}

/// The whole suite run (`bench.json`).
#[derive(Clone, Debug, Serialize)]
pub struct SuiteReport {
    /// Vulkan device name.
    pub device: String,
    /// Driver name and info.
    pub driver: String,
    /// The suite's name (`fill-vertex`).
    pub suite: String,
    /// `--quick` ran (fewer points and frames).
    pub quick: bool,
    /// `full`, `quick` or `tiny` (the tests' two points a sweep).
    pub scale: String,
    /// Wall-clock seconds the run took (limits included).
    pub seconds: f64,
    /// CPU seconds the process used (all threads; on lavapipe the rendering itself), where the
    /// OS reports it: with other work on the machine, wall time grows but this much less.
    pub cpu_seconds: Option<f64>,
    /// The 1-minute load average when the run ended (Linux), the conditions of the timings.
    pub load_average: Option<f64>,
    /// CPU threads available to the run.
    pub cpu_threads: usize,
    /// The device's limits, measured in this run.
    pub limits: Limits,
    /// Every measured point.
    pub rows: Vec<SuiteRow>,
    /// Where the bound changes or one method overtakes another along a sweep.
    pub crossovers: Vec<Crossover>,
    /// The constant-factor claims, as measured ratios.
    pub ablations: Vec<Ablation>,
    /// Plots written next to the JSON (file names).
    pub plots: Vec<String>,
    /// Variants left out, and why (e.g. big shadow maps with many lights, u8 indices without
    /// the extension).
    pub skipped: Vec<String>,
}

/// The CSV columns, in order (every scalar of a row).
pub const CSV_COLUMNS: &[&str] = &[
    "suite",
    "sweep",
    "x",
    "variant",
    "scene",
    "method",
    "counter",
    "index_format",
    "width",
    "height",
    "triangles",
    "casters",
    "lights",
    "frames",
    "gpu_shadow_ms",
    "gpu_frame_ms",
    "gpu_depth_ms",
    "gpu_illuminate_ms",
    "stencil_fragments",
    "shadow_triangles",
    "shadow_sides",
    "primitives",
    "clipped_primitives",
    "draws",
    "cpu_plan_ms",
    "bytes",
    "error_fraction",
    "fill_fraction",
    "vertex_fraction",
    "draw_fraction",
    "cpu_fraction",
    "bound",
];

fn opt<T: ToString>(v: Option<T>) -> String {
    v.map(|v| v.to_string()).unwrap_or_default()
}

impl SuiteRow {
    fn csv(&self) -> String {
        let r = self;
        [
            r.suite.clone(),
            r.sweep.clone(),
            r.x.to_string(),
            r.variant.clone(),
            r.scene.clone(),
            r.method.clone(),
            r.counter.clone(),
            r.index_format.clone(),
            r.width.to_string(),
            r.height.to_string(),
            r.triangles.to_string(),
            r.casters.to_string(),
            r.lights.to_string(),
            r.frames.to_string(),
            opt(r.gpu_shadow_ms),
            opt(r.gpu_frame_ms),
            opt(r.gpu_depth_ms),
            opt(r.gpu_illuminate_ms),
            opt(r.stencil_fragments),
            r.shadow_triangles.to_string(),
            r.shadow_sides.to_string(),
            opt(r.primitives),
            opt(r.clipped_primitives),
            r.draws.to_string(),
            r.cpu_plan_ms.to_string(),
            r.bytes.to_string(),
            opt(r.error_fraction),
            opt(r.fill_fraction),
            opt(r.vertex_fraction),
            opt(r.draw_fraction),
            opt(r.cpu_fraction),
            r.bound.clone(),
        ]
        .iter()
        .map(|f| if f.contains(',') { format!("\"{f}\"") } else { f.clone() })
        .collect::<Vec<_>>()
        .join(",")
    }
}

impl SuiteReport {
    /// `bench.csv`: a header line, then one line per row.
    pub fn csv(&self) -> String {
        let mut s = CSV_COLUMNS.join(",");
        s.push('\n');
        for r in &self.rows {
            s += &r.csv();
            s.push('\n');
        }
        s
    }

    /// Writes `bench.json` and `bench.csv` into `dir` (created if missing).
    pub fn write(&self, dir: &Path) -> Result<()> {
        std::fs::create_dir_all(dir).map_err(|e| Error::io(dir.display().to_string(), e))?;
        let json = serde_json::to_string_pretty(self).map_err(|e| Error::Other(e.to_string()))?;
        let p = dir.join("bench.json");
        std::fs::write(&p, json).map_err(|e| Error::io(p.display().to_string(), e))?;
        let p = dir.join("bench.csv");
        std::fs::write(&p, self.csv()).map_err(|e| Error::io(p.display().to_string(), e))?;
        Ok(())
    }

    /// The Markdown report: device, limits, the named scenes' bounds, the crossovers, the
    /// ablations and each sweep's table; plots linked from `plot_dir` (relative to the report).
    pub fn markdown(&self, plot_dir: &str) -> String {
        let l = &self.limits;
        let f2 = |v: Option<f64>| v.map(|x| format!("{x:.2}")).unwrap_or_else(|| "—".into());
        let pct = |v: Option<f64>| v.map(|x| format!("{:.0}%", x * 100.0)).unwrap_or_else(|| "—".into());
        let mut s = String::from(
            "Generated by `umbrage bench --suite fill-vertex --quick --out docs/bench --markdown docs/bench-lavapipe.md` (same command on any Vulkan device; `scripts/device-report.sh` adds info and conform). The limits are measured first, in the same run; a busy machine lowers them and the timings alike, so compare rows within one run.\n\n",
        );
        let _ = writeln!(
            s,
            "Device: {} ({}); suite `{}`{}; {} CPU threads; {:.0} s wall, {} s CPU, load average {} at the end.\n",
            self.device,
            self.driver,
            self.suite,
            match self.scale.as_str() {
                "quick" => " --quick",
                "tiny" => " (tiny: test size)",
                _ => "",
            },
            self.cpu_threads,
            self.seconds,
            self.cpu_seconds.map(|c| format!("{c:.0}")).unwrap_or_else(|| "?".into()),
            self.load_average.map(|c| format!("{c:.1}")).unwrap_or_else(|| "?".into()),
        );
        let _ = writeln!(s, "## Limits (measured in the same run, {}x{} target)\n", l.target[0], l.target[1]);
        let _ = writeln!(s, "| limit | value |\n|---|---|");
        let _ = writeln!(s, "| stencil fill (two-sided wrap, depth test) | {:.2} Gfragments/s |", l.stencil_fill_gfrag_s);
        let _ = writeln!(s, "| colour fill (RGBA16F additive, depth test) | {:.2} Gfragments/s |", l.color_fill_gfrag_s);
        let _ = writeln!(s, "| small triangles (2 px) | {:.2} Mtriangles/s |", l.small_tri_mtri_s);
        let _ = writeln!(s, "| screen-sized triangles | {:.4} Mtriangles/s |", l.big_tri_mtri_s);
        let _ = writeln!(s, "| slivers (1 px wide, centre to edge: volume sides) | {:.3} Mtriangles/s |", l.sliver_tri_mtri_s);
        let _ = writeln!(
            s,
            "| indexed, u8 / u16 / u32 / naive | {} / {:.2} / {:.2} / {:.2} Mtriangles/s |",
            f2(l.index_u8_mtri_s),
            l.index_u16_mtri_s,
            l.index_u32_mtri_s,
            l.index_naive_mtri_s
        );
        let _ = writeln!(s, "| draw calls | {:.0} draws/s |", l.draws_per_s);
        let _ = writeln!(s, "| CPU memory stream (one thread) | {:.2} GiB/s |", l.cpu_stream_gib_s);
        for (k, why) in &l.skipped {
            let _ = writeln!(s, "| {k} | skipped: {why} |");
        }
        let _ = writeln!(s, "\nfill = rasterised stencil fragments / stencil fill limit / GPU shadow time; vertex = (side triangles / sliver limit + cap triangles / small-triangle limit) / GPU shadow time (shadow maps: primitives / small-triangle limit); draw = draws / draw limit / time; cpu = CPU plan time / GPU shadow time. The bound is the largest.\n");
        let _ = writeln!(s, "## Named scenes\n");
        s += &table(self.rows.iter().filter(|r| r.sweep == "scenes"), true);
        let _ = writeln!(s, "\n## Crossovers\n");
        if self.crossovers.is_empty() {
            let _ = writeln!(s, "None found.");
        } else {
            let _ = writeln!(s, "| kind | sweep | method | from | to | between | at |\n|---|---|---|---|---|---|---|");
            for c in &self.crossovers {
                let _ = writeln!(
                    s,
                    "| {} | {} | {} | {} | {} | {:.4e} – {:.4e} | {:.4e} |",
                    c.kind, c.sweep, c.method, c.from, c.to, c.between[0], c.between[1], c.at
                );
            }
        }
        let _ = writeln!(s, "\n## Ablations (variant / baseline)\n");
        let _ =
            writeln!(s, "| what | scene | variant | baseline | time | fragments | triangles | bytes |\n|---|---|---|---|---|---|---|---|");
        let r2 = |v: Option<f64>| v.map(|x| format!("{x:.3}")).unwrap_or_else(|| "—".into());
        for a in &self.ablations {
            if a.skipped.is_empty() {
                let _ = writeln!(
                    s,
                    "| {} | {} | {} | {} | {} | {} | {} | {} |",
                    a.what,
                    a.scene,
                    a.variant,
                    a.baseline,
                    r2(a.time_ratio),
                    r2(a.fragment_ratio),
                    r2(a.triangle_ratio),
                    r2(a.byte_ratio)
                );
            } else {
                let _ = writeln!(s, "| {} | {} | {} | {} | skipped: {} | | | |", a.what, a.scene, a.variant, a.baseline, a.skipped);
            }
        }
        for p in &self.plots {
            if p.ends_with(".svg") {
                let _ = writeln!(s, "\n![{p}]({plot_dir}/{p})");
            }
        }
        for sweep in ["resolution", "tessellation", "lights", "light_distance", "casters", "ablation"] {
            let rows: Vec<&SuiteRow> = self.rows.iter().filter(|r| r.sweep == sweep).collect();
            if rows.is_empty() {
                continue;
            }
            let _ = writeln!(s, "\n## Sweep: {sweep}\n");
            s += &table(rows.into_iter(), false);
        }
        let _ = pct;
        s
    }
}

fn table<'a>(rows: impl Iterator<Item = &'a SuiteRow>, error: bool) -> String {
    let f2 = |v: Option<f64>| v.map(|x| format!("{x:.2}")).unwrap_or_else(|| "—".into());
    let pct = |v: Option<f64>| v.map(|x| format!("{:.0}%", x * 100.0)).unwrap_or_else(|| "—".into());
    let mut s = String::from("| scene | x | variant | method | size | tris | lights | shadow ms | frame ms | stencil frags | shadow tris | draws | plan ms | fill | vertex | draw | cpu | bound |");
    if error {
        s += " error |";
    }
    s += "\n|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|";
    if error {
        s += "---|";
    }
    s.push('\n');
    for r in rows {
        let _ = write!(
            s,
            "| {} | {} | {} | {} | {}x{} | {} | {} | {} | {} | {} | {} | {} | {:.3} | {} | {} | {} | {} | **{}** |",
            r.scene,
            r.x,
            r.variant,
            r.method,
            r.width,
            r.height,
            r.triangles,
            r.lights,
            f2(r.gpu_shadow_ms),
            f2(r.gpu_frame_ms),
            r.stencil_fragments.map(|v| v.to_string()).unwrap_or_else(|| "—".into()),
            r.shadow_triangles,
            r.draws,
            r.cpu_plan_ms,
            pct(r.fill_fraction),
            pct(r.vertex_fraction),
            pct(r.draw_fraction),
            pct(r.cpu_fraction),
            r.bound
        );
        if error {
            let _ = write!(s, " {} |", r.error_fraction.map(|e| format!("{:.4}%", e * 100.0)).unwrap_or_else(|| "—".into()));
        }
        s.push('\n');
    }
    s
}
