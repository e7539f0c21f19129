//! The classic bench's configuration, rows and labels ([`super::classic`] runs them;
//! [`super::classic_frames`] times them): what to measure, one row's settings and numbers,
//! and each technique's row name.

use serde::Serialize;
use umbrage_render::{ComputeDraws, Counter, RenderOptions, RenderTechnique, Renderer, ShadowMap};

/// One (scene, method, counter) measurement: medians over the measured frames.
#[derive(Clone, Debug, Serialize)]
pub struct BenchRow {
    /// Scene name or path, as given.
    pub scene: String,
    /// Method name ([`umbrage::shadow::Method::name`]), or `shadowmap-<size>` / `edgequad` for the baselines.
    pub method: String,
    /// Shadow counter: `stencil` or `float`.
    pub counter: String,
    /// Index format the renderer actually used (`u8`, `u16`, `u32`, ...).
    pub index_format: String,
    /// Frames measured (after one warm-up frame).
    pub frames: usize,
    /// Median GPU time of the whole frame, ms (`None` without timestamp queries).
    pub gpu_frame_ms: Option<f64>,
    /// Median GPU time of the shadow determination (all lights), ms.
    pub gpu_shadow_ms: Option<f64>,
    /// Median GPU time of the illumination passes (all lights), ms.
    pub gpu_illuminate_ms: Option<f64>,
    /// Shadow maps: median GPU time of rendering the maps (all lights), ms, part of
    /// `gpu_shadow_ms` (`None` for the other techniques).
    pub gpu_map_ms: Option<f64>,
    /// Shadow maps: median GPU time of the PCF lookups (all lights), ms: `gpu_shadow_ms` less
    /// the maps, frame by frame (`None` for the other techniques).
    pub gpu_lookup_ms: Option<f64>,
    /// Median wall-clock time of `Renderer::render` (plan, record, submit, wait, read back), ms.
    pub wall_ms: f64,
    /// Median CPU planning time (silhouettes included), ms.
    pub cpu_plan_ms: f64,
    /// Frames per second rendered back to back with `frames_in_flight` frames overlapping
    /// ([`Renderer::throughput`]); `1000 / wall_ms` is the one-at-a-time rate.
    pub throughput_fps: f64,
    /// Frames in flight during the throughput run.
    pub frames_in_flight: usize,
    /// Shadow-volume triangles drawn in one frame (all lights, sides + caps).
    pub shadow_triangles: u64,
    /// Index and vertex bytes the shadow volumes' draws read in one frame (uploaded by the
    /// CPU for the CPU-planned methods, written by the GPU for `compute`; 0 for `mesh`).
    pub shadow_bytes: u64,
    /// Geometry bytes the CPU wrote for the frame (`Totals::bytes_sent`: the streams plus any
    /// caster uploads; 0 for static casters under a GPU-driven technique).
    pub bytes_sent: u64,
    /// Worst light's mismatches outside a 1-pixel band / compared pixels.
    pub error_fraction: f64,
    /// (caster, light) pairs per case in one frame: `[culled, z-pass, z-fail, z-fail + light cap]`.
    pub cases: [u64; 4],
    /// Volume draw calls the frame's determinations record, all lights (`totals.draws` in
    /// `--stats`): one per chunk and case, or for `compute`'s merged draws one per light and
    /// pipeline (`count`, `multi`).
    pub volume_draws: u64,
    /// Ray query: median GPU time of the frame's top-level build, ms (`None` otherwise).
    pub gpu_tlas_ms: Option<f64>,
    /// Ray query: GPU time of the frame that built the bottom levels (its acceleration span:
    /// the builds and that frame's top level), ms.
    pub blas_build_ms: Option<f64>,
    /// Ray query: bottom-level storage after compaction, bytes.
    pub blas_bytes: Option<u64>,
    /// Ray query: median GPU time of a frame that refits the largest caster's bottom level in
    /// place after a deformation ([`Renderer::set_mesh_positions`]: rebuilt once with
    /// `ALLOW_UPDATE`, then refitted; the caster is put back afterwards), its acceleration
    /// span, ms (`None` otherwise, or with no mesh caster).
    pub blas_refit_ms: Option<f64>,
    /// `compute`: median GPU time of the silhouettes' compute pass (every light), ms (`None`
    /// for the other techniques).
    pub gpu_silhouettes_ms: Option<f64>,
    /// `compute`: bytes that pass reads from the static tables a frame (16 a triangle, 16 an
    /// edge, per light and caster).
    pub silhouette_read_bytes: Option<u64>,
    /// `compute`: the time a plain compute read of those bytes takes at the device's measured
    /// rate ([`BenchReport::compute_read_gib_s`](crate::BenchReport::compute_read_gib_s)) over the pass's time (1 = at the limit).
    pub silhouette_limit_fraction: Option<f64>,
    /// Median GPU time of the G-buffer pass, ms (`gpu_ms.depth`).
    pub gpu_gbuffer_ms: Option<f64>,
    /// Triangles the G-buffer pass draws a frame: every opaque mesh's, 12 a sphere (its cube).
    pub gbuffer_triangles: u64,
    /// Pixels the illumination passes cover a frame: every light's scissor (the whole target
    /// without one).
    pub lit_pixels: u64,
    /// `lit_pixels` at the measured lighting limit ([`BenchReport::lighting_gpix_s`](crate::BenchReport::lighting_gpix_s)) over
    /// `gpu_illuminate_ms` (1 = at the limit).
    pub lighting_limit_fraction: Option<f64>,
    /// `lit_pixels` at the lighting limit's first sweep point (one full-screen draw in its own
    /// rendering instance, as each light's pass is drawn) over `gpu_illuminate_ms`.
    pub lighting_one_draw_fraction: Option<f64>,
    /// `gbuffer_triangles` at the measured G-buffer geometry limit
    /// ([`BenchReport::gbuffer_tri_mtri_s`](crate::BenchReport::gbuffer_tri_mtri_s)) over `gpu_gbuffer_ms` (1 = at the limit).
    pub gbuffer_limit_fraction: Option<f64>,
    /// The target's pixels at the measured G-buffer fill limit
    /// ([`BenchReport::gbuffer_fill_gpix_s`](crate::BenchReport::gbuffer_fill_gpix_s)) over `gpu_gbuffer_ms`: the pass's fill against its
    /// limit where the scene covers the target once (more overdraw: more; background: less).
    pub gbuffer_fill_fraction: Option<f64>,
    /// Median CPU time of culling, the cases and the kept plans' look-ups, ms (with
    /// `PassSettings::keep`; 0 without it: that work is then inside `cpu_plan_ms`).
    pub cpu_cull_ms: f64,
    /// Median CPU time of writing the frame's stream and the pass's records, ms.
    pub cpu_record_ms: f64,
    /// Median light–caster pairs drawn a frame.
    pub pairs_total: u64,
    /// Median pairs planned a frame (all drawn pairs without keeping).
    pub pairs_replanned: u64,
    /// Median pairs drawn from plans kept across frames.
    pub pairs_kept: u64,
    /// Median bytes of index lists kept across frames.
    pub kept_bytes: u64,
    /// Whether the frames ran the scene's motion (`--motion`: frame `k` at `k / 30` s; the
    /// error is then the last frame's); `false`: every frame at time 0.
    pub motion: bool,
}

/// What to measure.
pub struct BenchConfig {
    /// Scenes, by built-in name or path ([`umbrage_scene::load`]).
    pub scenes: Vec<String>,
    /// Techniques to compare: volume methods, edge quads, shadow maps (each size its own).
    pub techniques: Vec<RenderTechnique>,
    /// Each volume technique runs with each counter (stencil, float), side by side; shadow
    /// maps run once (they count in the float target).
    pub counters: Vec<Counter>,
    /// Frames measured per variant (at least 1), round-robin over the variants.
    pub frames: usize,
    /// `compute` runs once per way of recording its volume draws here (rows `compute` for
    /// [`ComputeDraws::Auto`], `compute-<way>` for the others); empty: `Auto` only.
    pub compute_draws: Vec<ComputeDraws>,
    /// [`Technique::Mesh`](umbrage::pass::Technique::Mesh)'s task stage ([`umbrage::pass::PassToggles::mesh_task`]): a row per
    /// value, `mesh` (on) and `mesh-notask` (off: every meshlet's mesh workgroup runs), side
    /// by side; empty: on only.
    pub mesh_task: Vec<bool>,
    /// Renderer options for everything else (size, depth mode, ...).
    pub opts: RenderOptions,
    /// Run each scene's motion over the frames ([`super::motion`]: the warm-up frame at time
    /// 0, measured frame `k` at `k / 30` s; each row's error is the last frame's); `false`:
    /// every frame at time 0.
    pub motion: bool,
}

/// The name of a bench row's technique (`shadowmap-512`; `shadowmap-512-multiview` for cube
/// faces rendered as views, then `-gather` for the gathering lookup:
/// `shadowmap-512-multiview-gather`).
pub fn technique_label(t: RenderTechnique) -> String {
    match t {
        RenderTechnique::ShadowMap(ShadowMap { size, pcf, cube }) => {
            let views = match cube {
                umbrage_render::CubeFaces::Atlas => "",
                umbrage_render::CubeFaces::Multiview => MULTIVIEW_SUFFIX,
            };
            let lookup = match pcf {
                umbrage_render::Pcf::Taps => "",
                umbrage_render::Pcf::Gather => GATHER_SUFFIX,
            };
            format!("shadowmap-{size}{views}{lookup}")
        }
        t => t.name().to_string(),
    }
}

/// One row's settings: its technique and counter, and the compute and mesh techniques' own.
#[derive(Clone, Copy, Debug)]
pub(super) struct Variant {
    pub(super) technique: RenderTechnique,
    pub(super) counter: Counter,
    /// [`umbrage::pass::PassToggles::compute_draws`] (only `Auto` for the other techniques).
    pub(super) draws: ComputeDraws,
    /// [`umbrage::pass::PassToggles::mesh_task`] (only `true` for the other techniques).
    pub(super) task: bool,
}

impl Variant {
    /// Sets the renderer up to draw this variant.
    pub(super) fn apply(&self, r: &mut Renderer) {
        r.settings.technique = self.technique;
        r.settings.counter = self.counter;
        r.settings.toggles.compute_draws = self.draws;
        r.settings.toggles.mesh_task = self.task;
    }

    /// The row's `method`: [`technique_label`], then `-<way>` for a compute way other than
    /// `Auto`, or [`NOTASK_SUFFIX`] for a mesh row without its task stage.
    pub(super) fn label(&self) -> String {
        let base = technique_label(self.technique);
        match (self.draws, self.task) {
            (ComputeDraws::Auto, true) => base,
            (ComputeDraws::Auto, false) => format!("{base}{NOTASK_SUFFIX}"),
            (w, _) => format!("{base}-{}", w.name()),
        }
    }
}

/// What a `mesh` row's label has appended when its task stage was off
/// ([`BenchConfig::mesh_task`]).
const NOTASK_SUFFIX: &str = "-notask";

/// What [`technique_label`] appends for a shadow map whose cube faces are multiview views.
const MULTIVIEW_SUFFIX: &str = "-multiview";

/// What [`technique_label`] appends for a shadow map read with gathers.
const GATHER_SUFFIX: &str = "-gather";

/// For a gathering shadow map's label (`shadowmap-512-gather`), the label of the same map read
/// with taps (`shadowmap-512`); `None` for every other label.
pub fn taps_label_of(label: &str) -> Option<&str> {
    label.strip_suffix(GATHER_SUFFIX).filter(|l| l.starts_with("shadowmap"))
}
