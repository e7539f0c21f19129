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
    /// Triangle setup (no fragments), Mtriangles / s.
    pub setup_tri_mtri_s: f64,
    /// Clipped triangles (near plane and w = 0, no fragments), Mtriangles / s.
    pub clip_tri_mtri_s: f64,
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
    /// 10th percentile of the timed frames' shadow times, ms (the spread's low end).
    pub gpu_shadow_ms_p10: Option<f64>,
    /// 90th percentile of the same, ms.
    pub gpu_shadow_ms_p90: Option<f64>,
    /// Shadow maps: median GPU time rendering the maps, ms (`None` for other techniques).
    pub gpu_map_ms: Option<f64>,
    /// Shadow maps: median GPU time of the PCF lookup (shadow time less map time), ms.
    pub gpu_lookup_ms: Option<f64>,
    /// The cost model's prediction of `gpu_shadow_ms` (fitted on every row; see
    /// [`super::model`]), ms.
    pub predicted_shadow_ms: Option<f64>,
    /// The model's held-out relative error on this row (predicted by the folds that did not
    /// contain it).
    pub model_rel_error: Option<f64>,
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
    /// Vertex-shader invocations in the shadow span (pipeline statistics).
    pub vertex_invocations: Option<u64>,
    /// Volume triangles with a vertex at infinity (sides and dark caps): clipped by
    /// construction.
    pub clipped_triangles: u64,
    /// Shadow maps: texels cleared and rendered per frame (faces x size^2 over lights); 0
    /// otherwise.
    pub map_texels: u64,
    /// (light, caster) pairs the pass did not cull.
    pub caster_passes: u64,
    /// Triangles of the casters' meshes over those pairs (what the volume draws index into,
    /// not what they draw).
    pub bound_triangles: u64,
    /// Volume draw calls.
    pub draws: u64,
    /// Median CPU planning time (silhouettes included), ms.
    pub cpu_plan_ms: f64,
    /// Geometry bytes the CPU wrote for the frame's shadows (streams + uploads).
    pub bytes: u64,
    /// Worst light's mismatched pixels outside a 1-pixel band / compared pixels, where the
    /// reference was rendered for this point (`scenes` rows); `None` elsewhere.
    pub error_fraction: Option<f64>,
    /// The cost model's per-fragment and per-pixel terms over `gpu_shadow_ms` (over the
    /// prediction where it is larger): the share of the pass's time its fill costs.
    pub fill_fraction: Option<f64>,
    /// The model's per-triangle and per-vertex terms (setup, clipping, vertex shading,
    /// compute silhouettes) over `gpu_shadow_ms`.
    pub vertex_fraction: Option<f64>,
    /// The model's per-draw term over `gpu_shadow_ms`.
    pub draw_fraction: Option<f64>,
    /// The model's per-light and per-frame constants over `gpu_shadow_ms`.
    pub fixed_fraction: Option<f64>,
    /// `cpu_plan_ms / gpu_shadow_ms`: above 1 the CPU's planning outlasts the GPU pass.
    pub cpu_fraction: Option<f64>,
    /// The largest fraction's name: `fill`, `vertex`, `draw` or `cpu` (`none` without timings).
    pub bound: String,
    /// Whether the bound is claimed: the largest fraction leads the next by more than the
    /// row's spread ((p90 - p10) / median) and the model's error on it.
    pub bound_clear: bool,
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
    /// The cost model fitted on the rows.
    pub model: super::model::Model,
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
    "gpu_shadow_ms_p10",
    "gpu_shadow_ms_p90",
    "gpu_map_ms",
    "gpu_lookup_ms",
    "predicted_shadow_ms",
    "model_rel_error",
    "vertex_invocations",
    "clipped_triangles",
    "map_texels",
    "caster_passes",
    "bound_triangles",
    "fixed_fraction",
    "bound_clear",
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
            opt(r.gpu_shadow_ms_p10),
            opt(r.gpu_shadow_ms_p90),
            opt(r.gpu_map_ms),
            opt(r.gpu_lookup_ms),
            opt(r.predicted_shadow_ms),
            opt(r.model_rel_error),
            opt(r.vertex_invocations),
            r.clipped_triangles.to_string(),
            r.map_texels.to_string(),
            r.caster_passes.to_string(),
            r.bound_triangles.to_string(),
            opt(r.fixed_fraction),
            r.bound_clear.to_string(),
        ]
        .iter()
        .map(|f| if f.contains(',') { format!("\"{f}\"") } else { f.clone() })
        .collect::<Vec<_>>()
        .join(",")
    }
}

impl SuiteReport {
    /// The cost model's section: its form, held-out errors, coefficients against the limits,
    /// and where it fits worst.
    fn model_markdown(&self) -> String {
        let m = &self.model;
        let mut s = String::from("## Cost model\n\n");
        let _ = writeln!(
            s,
            "GPU shadow ms ≈ 10⁻⁶ · Σ c·count (c in ns per unit, c ≥ 0), fitted by non-negative least squares in relative error on the {} timed rows of this run. Checked on rows it was not fitted on ({}-fold cross-validation): median error **{:.1}%**, 80th percentile **{:.1}%**, **{:.0}%** of rows within 30% (on the fitted rows: median {:.1}%). Each row's fill, vertex and draw fractions are its model terms over its measured time (over the prediction where the model predicts more, so no share exceeds the time); `fixed` is the per-light and per-frame constant. A bound is claimed (bold) only where the largest fraction leads the next by more than the row's spread and the model's error on it.\n",
            m.rows,
            m.folds,
            m.median_rel_error * 100.0,
            m.p80_rel_error * 100.0,
            m.within_30_percent * 100.0,
            m.fit_median_rel_error * 100.0
        );
        let _ = writeln!(s, "| term | counts | c (ns per unit) | at the measured limit (ns) |\n|---|---|---|---|");
        for (name, _, what) in super::model::TERMS {
            let c = m.coefficients.get(*name).copied().unwrap_or(0.0);
            let lim = m.limit_ns.get(*name).map(|v| format!("{v:.3}")).unwrap_or_else(|| "—".into());
            let _ = writeln!(s, "| {name} | {what} | {c:.4} | {lim} |");
        }
        let _ = writeln!(s, "\n| technique | median held-out error |\n|---|---|");
        for (k, e) in &m.median_rel_error_by_method {
            let _ = writeln!(s, "| {k} | {:.1}% |", e * 100.0);
        }
        let mut worst: Vec<&SuiteRow> = self.rows.iter().filter(|r| r.model_rel_error.is_some()).collect();
        worst.sort_by(|a, b| b.model_rel_error.unwrap_or(0.0).total_cmp(&a.model_rel_error.unwrap_or(0.0)));
        let _ = writeln!(s, "\nWorst-predicted rows (held out):\n\n| sweep | scene | variant | method | size | measured ms | predicted ms | error |\n|---|---|---|---|---|---|---|---|");
        for r in worst.iter().take(8) {
            let _ = writeln!(
                s,
                "| {} | {} | {} | {} | {}x{} | {:.2} | {:.2} | {:.0}% |",
                r.sweep,
                r.scene,
                r.variant,
                r.method,
                r.width,
                r.height,
                r.gpu_shadow_ms.unwrap_or(0.0),
                r.predicted_shadow_ms.unwrap_or(0.0),
                r.model_rel_error.unwrap_or(0.0) * 100.0
            );
        }
        s.push('\n');
        s
    }

    /// McGuire et al.'s claim ("the simplification method trades vertex rate for fill rate
    /// and will slow down applications that are fill rate bound"), measured on the `caps`
    /// sweep: McGuire's O(s) fan caps against Everitt-Kilgard's O(f) caps, per size.
    fn claim_markdown(&self) -> String {
        let caps: Vec<&SuiteRow> = self.rows.iter().filter(|r| r.sweep == "caps").collect();
        let mut xs: Vec<f64> = caps.iter().map(|r| r.x).collect();
        xs.sort_by(f64::total_cmp);
        xs.dedup();
        if xs.is_empty() {
            return String::new();
        }
        let mut s = String::from("## The paper's claim: O(s) caps trade vertex rate for fill rate\n\nMcGuire et al. 2003: \"the simplification method trades vertex rate for fill rate and will slow down applications that are fill rate bound\". On `bench/caps` (tilted tori above the eye, which stands in their shadow looking away from the light: McGuire's case 2, z-fail without light cap) McGuire draws each dark cap as a fan over the possible silhouette, O(s) triangles that overlap themselves where the silhouette is not convex; Everitt-Kilgard draws the O(f) caps. Ratios are McGuire / Everitt-Kilgard; the time ratio's range comes from the two rows' p10–p90.\n\n| size | triangles | stencil fragments | shadow ms (mcguire / e-k) | time ratio | range | faster |\n|---|---|---|---|---|---|---|\n");
        let mut slower = Vec::new();
        for x in xs {
            let find = |m: &str| caps.iter().find(|r| r.x == x && r.method == m).copied();
            let (Some(a), Some(b)) = (find("mcguire"), find("everitt-kilgard")) else { continue };
            let (Some(ta), Some(tb)) = (a.gpu_shadow_ms, b.gpu_shadow_ms) else { continue };
            let lo = a.gpu_shadow_ms_p10.unwrap_or(ta) / b.gpu_shadow_ms_p90.unwrap_or(tb);
            let hi = a.gpu_shadow_ms_p90.unwrap_or(ta) / b.gpu_shadow_ms_p10.unwrap_or(tb);
            let verdict = if lo > 1.0 {
                slower.push(format!("{}x{}", a.width, a.height));
                "everitt-kilgard"
            } else if hi < 1.0 {
                "mcguire"
            } else {
                "within spread"
            };
            let ratio = |p: Option<u64>, q: Option<u64>| match (p, q) {
                (Some(p), Some(q)) if q > 0 => format!("{:.2}", p as f64 / q as f64),
                _ => "—".into(),
            };
            let _ = writeln!(
                s,
                "| {}x{} | {} / {} ({:.2}) | {} / {} ({}) | {ta:.2} / {tb:.2} | {:.2} | {lo:.2}–{hi:.2} | {verdict} |",
                a.width,
                a.height,
                a.shadow_triangles,
                b.shadow_triangles,
                a.shadow_triangles as f64 / b.shadow_triangles.max(1) as f64,
                a.stencil_fragments.map_or("—".into(), |v| v.to_string()),
                b.stencil_fragments.map_or("—".into(), |v| v.to_string()),
                ratio(a.stencil_fragments, b.stencil_fragments),
                ta / tb
            );
        }
        let _ = writeln!(
            s,
            "\n{}\n",
            if slower.is_empty() {
                "On this device McGuire's caps were not slower than Everitt-Kilgard's beyond the spread at any size measured: the claim's slowdown did not show here.".to_string()
            } else {
                format!(
                    "On this device McGuire's caps were slower than Everitt-Kilgard's beyond the spread at {}: the claim holds there.",
                    slower.join(", ")
                )
            }
        );
        s
    }

    /// The shadow-map rows' time split into rendering the maps and the PCF lookup.
    fn shadow_map_markdown(&self) -> String {
        let rows: Vec<&SuiteRow> = self.rows.iter().filter(|r| r.gpu_map_ms.is_some() && r.sweep != "ablation").collect();
        if rows.is_empty() {
            return String::new();
        }
        let mut s = String::from("## Shadow maps: map against lookup\n\n| sweep | scene | method | size | lights | map texels | map ms | lookup ms | shadow ms | error |\n|---|---|---|---|---|---|---|---|---|---|\n");
        for r in rows {
            let _ = writeln!(
                s,
                "| {} | {} | {} | {}x{} | {} | {} | {:.2} | {:.2} | {:.2} | {} |",
                r.sweep,
                r.scene,
                r.method,
                r.width,
                r.height,
                r.lights,
                r.map_texels,
                r.gpu_map_ms.unwrap_or(0.0),
                r.gpu_lookup_ms.unwrap_or(0.0),
                r.gpu_shadow_ms.unwrap_or(0.0),
                r.error_fraction.map(|e| format!("{:.4}%", e * 100.0)).unwrap_or_else(|| "—".into())
            );
        }
        // Per unit of work, next to the volumes' fill: which part costs, and at what rate.
        let per = |f: &dyn Fn(&SuiteRow) -> Option<f64>| -> Option<f64> {
            let v: Vec<f64> = self.rows.iter().filter(|r| r.sweep != "ablation").filter_map(f).filter(|x| x.is_finite()).collect();
            (!v.is_empty()).then(|| super::model::quantile(&v, 0.5))
        };
        let lookup_ns = per(&|r| Some(r.gpu_lookup_ms? * 1e6 / (r.width as f64 * r.height as f64 * r.lights as f64)));
        let map_ns = per(&|r| (r.map_texels > 0).then(|| r.gpu_map_ms.unwrap_or(0.0) * 1e6 / r.map_texels as f64));
        let frag_ns = self.model.coefficients.get("fragments").copied();
        if let (Some(l), Some(m), Some(f)) = (lookup_ns, map_ns, frag_ns) {
            let _ = writeln!(
                s,
                "\nMedians over these rows: the PCF lookup costs {l:.1} ns per pixel and light (two G-buffer fetches, a matrix, nine compare taps: a full-screen shader), the map {m:.2} ns per texel cleared and rendered; the volumes' stencil fill costs {f:.2} ns per fragment (fixed-function, no shader). Small maps are lookup-bound, large maps pay for their texels as much again.\n"
            );
        }
        s
    }

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
        let _ = writeln!(s, "| triangle setup (no sample covered) | {:.2} Mtriangles/s |", l.setup_tri_mtri_s);
        let _ = writeln!(s, "| clipped triangles (near plane and w = 0, no sample covered) | {:.3} Mtriangles/s |", l.clip_tri_mtri_s);
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
        let _ = writeln!(
            s,
            "\nEach GPU limit is the peak of a sweep that doubles its workload until the rate stops growing (`limits.sweeps` in bench.json has every point): {}.\n",
            l.sweeps.iter().map(|(k, v)| format!("{k} {} points", v.len())).collect::<Vec<_>>().join(", ")
        );
        s += &self.model_markdown();
        s += &self.shadow_map_markdown();
        s += &self.claim_markdown();
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
        for sweep in ["resolution", "tessellation", "lights", "light_distance", "casters", "caps", "ablation"] {
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
    let mut s = String::from("| scene | x | variant | method | size | tris | lights | shadow ms | p10–p90 | model ms | frame ms | stencil frags | shadow tris | draws | plan ms | fill | vertex | draw | fixed | cpu | bound |");
    if error {
        s += " error |";
    }
    s += "\n|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|";
    if error {
        s += "---|";
    }
    s.push('\n');
    for r in rows {
        let _ = write!(
            s,
            "| {} | {} | {} | {} | {}x{} | {} | {} | {} | {}–{} | {} | {} | {} | {} | {} | {:.3} | {} | {} | {} | {} | {} | {} |",
            r.scene,
            r.x,
            r.variant,
            r.method,
            r.width,
            r.height,
            r.triangles,
            r.lights,
            f2(r.gpu_shadow_ms),
            f2(r.gpu_shadow_ms_p10),
            f2(r.gpu_shadow_ms_p90),
            f2(r.predicted_shadow_ms),
            f2(r.gpu_frame_ms),
            r.stencil_fragments.map(|v| v.to_string()).unwrap_or_else(|| "—".into()),
            r.shadow_triangles,
            r.draws,
            r.cpu_plan_ms,
            pct(r.fill_fraction),
            pct(r.vertex_fraction),
            pct(r.draw_fraction),
            pct(r.fixed_fraction),
            pct(r.cpu_fraction),
            if r.bound_clear { format!("**{}**", r.bound) } else { format!("{} (within spread)", r.bound) }
        );
        if error {
            let _ = write!(s, " {} |", r.error_fraction.map(|e| format!("{:.4}%", e * 100.0)).unwrap_or_else(|| "—".into()));
        }
        s.push('\n');
    }
    s
}
