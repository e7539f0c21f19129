//! One row of the suite (`bench.json`'s `rows`, a line of `bench.csv`): a scene at a size
//! with one technique, its timings and counted work, its model shares, bound and ablation.
//! The ground floor the model, the proofs and the report stand on (it imports none of them).

use serde::Serialize;

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
    /// The lighting pass's limit (full-screen G-buffer reads, additive blend), Gpixels / s.
    pub lighting_gpix_s: f64,
    /// The G-buffer pass's geometry limit, Mtriangles / s.
    pub gbuffer_tri_mtri_s: f64,
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
    /// The largest fraction's name: `fill`, `vertex`, `draw` or `cpu` (`none` without timings):
    /// the model's *candidate* bound, not a claim (see [`SuiteRow::bound_confirmed`]).
    pub bound: String,
    /// Whether the model names the candidate clearly: the largest fraction leads the next by
    /// more than the row's spread ((p90 - p10) / median), the model's error on it and the
    /// share of terms the rows do not identify. Such a candidate is put to the test by an
    /// ablation ([`SuiteRow::ablation`]); it is not claimed until that confirms it.
    pub bound_clear: bool,
    /// The fill, vertex and draw shares of the row's time from the terms the rows identify
    /// only (`model.identifiability`): what names the bound.
    pub bound_shares: Option<BoundShares>,
    /// The share of the row's time in terms the rows do not identify (any group): it could
    /// belong to any bound, so a bound must lead by more than it.
    pub unidentified_fraction: Option<f64>,
    /// Whether the bound is claimed: the model named it clearly ([`SuiteRow::bound_clear`])
    /// and its ablation in the same run saved what the model predicted, beyond the spread
    /// ([`RowAblation::confirmed`]). Only these bounds are claimed anywhere in the report.
    pub bound_confirmed: bool,
    /// The claimed bound's ablation (`None` where no bound is claimed).
    pub ablation: Option<RowAblation>,
    /// The limits the fractions were computed against.
    pub limits: RowLimits,
    /// The sweep that measured this row, where it is another's: a point two sweeps share is
    /// measured once (a one-factor sweep reuses the identical point measured before it) and
    /// listed in both; empty where the row was measured for its own sweep.
    pub measured_in: String,
    /// Pixels the illumination passes cover a frame: every light's scissor (the whole target
    /// without one).
    pub lit_pixels: u64,
    /// `lit_pixels` at the measured lighting limit ([`RowLimits::lighting_gpix_s`]) over
    /// `gpu_illuminate_ms` (1 = at the limit).
    pub lighting_limit_fraction: Option<f64>,
    /// Triangles the G-buffer pass draws a frame: every opaque mesh's, 12 a sphere (its cube).
    pub gbuffer_triangles: u64,
    /// `gbuffer_triangles` at the measured G-buffer geometry limit
    /// ([`RowLimits::gbuffer_tri_mtri_s`]) over `gpu_depth_ms` (1 = at the limit).
    pub gbuffer_limit_fraction: Option<f64>,
    /// Volume side triangles running to infinity that cover screen area: long slivers the
    /// rasteriser bins across the screen. The silhouette's sides (`shadow_sides`) for the
    /// CPU-planned, compute and mesh volumes; for edge quads, the sides of the McGuire plan of
    /// the same frame (every other quad of theirs is degenerate); 0 for planar projection,
    /// shadow maps and ray query.
    pub infinite_sides: u64,
    /// Ray query only: the stencil fragments of the McGuire volumes of the same frame (the
    /// rays that pass through casters' shadow volumes, and how many of them), what the
    /// model's `ray_steps` term weighs by the casters' BVH depth. `None` on other rows.
    pub volume_fragments: Option<u64>,
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

/// The model's candidate bound put to the test: the row's work with what the bound counts cut
/// (fill: the same volumes at half the width and height; vertex: the same shapes, coarser
/// tessellation; draw: the casters merged into one), timed next to the row, against the
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
    /// Whether both sides are the run's own sweep points (the row, and the point its ablation
    /// names: the resolution sweep's half size, the tessellation a quarter of the triangles,
    /// the same spheres as one caster), measured one after the other in the sweeps; otherwise
    /// the row was re-timed right before its ablation.
    pub from_sweep: bool,
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
    "measured_in",
    "lit_pixels",
    "lighting_limit_fraction",
    "gbuffer_triangles",
    "gbuffer_limit_fraction",
    "infinite_sides",
    "volume_fragments",
];

fn opt<T: ToString>(v: Option<T>) -> String {
    v.map(|v| v.to_string()).unwrap_or_default()
}

impl SuiteRow {
    /// The row's bound cell in the report's tables: a claimed bound (its ablation confirmed
    /// it) in bold; otherwise `unconfirmed`, with the model's largest share and why it is not
    /// claimed.
    pub(super) fn bound_cell(&self) -> String {
        let r = self;
        if r.bound_confirmed {
            return format!("**{}**", r.bound);
        }
        let why = match &r.ablation {
            Some(a) if a.predicted_saving_ms.is_some() => "refuted by its ablation",
            Some(_) => "ablation could not run",
            None if r.bound_clear => "no ablation tests it",
            None => "not clear",
        };
        format!("unconfirmed ({}: {why})", r.bound)
    }

    /// The row as a `bench.csv` line ([`CSV_COLUMNS`], in order).
    pub(super) fn csv(&self) -> String {
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
            r.measured_in.clone(),
            r.lit_pixels.to_string(),
            opt(r.lighting_limit_fraction),
            r.gbuffer_triangles.to_string(),
            opt(r.gbuffer_limit_fraction),
            r.infinite_sides.to_string(),
            opt(r.volume_fragments),
        ]
        .iter()
        .map(|f| if f.contains(',') { format!("\"{f}\"") } else { f.clone() })
        .collect::<Vec<_>>()
        .join(",")
    }
}
