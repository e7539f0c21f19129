//! The suite's outputs: `bench.json` (a contract other tools read: the keys of issue #10, more
//! keys welcome) and `bench.csv` (one line per row); the Markdown report (docs/bench-*.md) is
//! [`SuiteReport::markdown`], in `bench/markdown.rs`.

use super::limits::Limits;
use crate::error::{Error, Result};
use serde::Serialize;
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
    /// Ray query: median GPU time of the timed frames' acceleration span (the top level
    /// rebuilt each frame; not part of `gpu_shadow_ms`), ms (`None` for other techniques).
    pub gpu_tlas_ms: Option<f64>,
    /// Ray query: GPU time of the frame that built the bottom levels, ms.
    pub blas_build_ms: Option<f64>,
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
    /// row's spread ((p90 - p10) / median), the model's error on it and the share of terms
    /// the rows do not identify. A claimed bound is put to the test by an ablation
    /// ([`SuiteRow::ablation`]).
    pub bound_clear: bool,
    /// The fill, vertex and draw shares of the row's time from the terms the rows identify
    /// only (`model.identifiability`): what names the bound.
    pub bound_shares: Option<BoundShares>,
    /// The share of the row's time in terms the rows do not identify (any group): it could
    /// belong to any bound, so a bound must lead by more than it.
    pub unidentified_fraction: Option<f64>,
    /// Whether the bound is proven: claimed, and its ablation in the same run saved what the
    /// model predicted, beyond the spread ([`RowAblation::confirmed`]).
    pub bound_confirmed: bool,
    /// The claimed bound's ablation (`None` where no bound is claimed).
    pub ablation: Option<RowAblation>,
    /// The limits the fractions were computed against.
    pub limits: RowLimits,
}

/// A row's fill, vertex and draw shares from identified terms only.
#[derive(Clone, Copy, Debug, Default, Serialize, PartialEq)]
pub struct BoundShares {
    /// Identified fill terms over the time.
    pub fill: f64,
    /// Identified vertex terms over the time.
    pub vertex: f64,
    /// Identified draw terms over the time.
    pub draw: f64,
}

/// A claimed bound put to the test: the row's work with what the bound counts cut (fill: the
/// same volumes at half the width and height; vertex: the same shapes, coarser tessellation;
/// draw: the casters merged into one), timed next to the row itself re-timed, against the
/// model's predicted saving. The first four keys are a contract (issue #38).
#[derive(Clone, Debug, Default, Serialize, PartialEq)]
pub struct RowAblation {
    /// `fill`, `vertex` or `draw`: the bound tested.
    pub kind: String,
    /// The model's time for the row less its time for the ablated work (both from their
    /// counted work), ms; `None` where the ablation could not run.
    pub predicted_saving_ms: Option<f64>,
    /// The re-timed row's median less the ablated one's, ms.
    pub measured_saving_ms: Option<f64>,
    /// Whether the bound is proven: the measured saving exceeds `spread_ms` and lies within
    /// `spread_ms` of the predicted one.
    pub confirmed: bool,
    /// Half the sum of the two timings' p10–p90 widths, ms: how far apart repeat timings of
    /// the two land.
    pub spread_ms: Option<f64>,
    /// The re-timed row: median GPU shadow ms.
    pub baseline_ms: Option<f64>,
    /// The ablated work: median GPU shadow ms.
    pub ablated_ms: Option<f64>,
    /// The ablated scene's name.
    pub ablated_scene: String,
    /// The ablated frame size.
    pub ablated_size: [u32; 2],
    /// Timed frames of each of the two.
    pub frames: usize,
    /// The verdict in words (why not confirmed, or why the ablation could not run).
    pub verdict: String,
}

/// How many claimed bounds the run proved (`bench.json`'s `bound_proofs`).
#[derive(Clone, Debug, Default, Serialize)]
pub struct ProofSummary {
    /// Rows with a claimed fill, vertex or draw bound.
    pub claimed: usize,
    /// Of them, rows whose ablation ran.
    pub ablated: usize,
    /// Of them, rows whose bound the ablation confirmed.
    pub confirmed: usize,
    /// Rows whose ablation could not run (no coarser tessellation of the shapes, a single
    /// caster to merge, a variant the device skips).
    pub not_run: usize,
    /// Timed frames per side of each ablation.
    pub frames: usize,
    /// Wall seconds the ablations took.
    pub seconds: f64,
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
#[derive(Clone, Debug, Default, Serialize)]
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
    /// How many claimed bounds their ablations proved (each row's `ablation` has the detail).
    pub bound_proofs: ProofSummary,
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
    "gpu_tlas_ms",
    "blas_build_ms",
    "unidentified_fraction",
    "bound_confirmed",
    "ablation_kind",
    "ablation_predicted_saving_ms",
    "ablation_measured_saving_ms",
    "ablation_spread_ms",
    "ablation_confirmed",
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
            opt(r.gpu_tlas_ms),
            opt(r.blas_build_ms),
            opt(r.unidentified_fraction),
            r.bound_confirmed.to_string(),
            r.ablation.as_ref().map(|a| a.kind.clone()).unwrap_or_default(),
            opt(r.ablation.as_ref().and_then(|a| a.predicted_saving_ms)),
            opt(r.ablation.as_ref().and_then(|a| a.measured_saving_ms)),
            opt(r.ablation.as_ref().and_then(|a| a.spread_ms)),
            opt(r.ablation.as_ref().map(|a| a.confirmed)),
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
}
