//! The suite's outputs: `bench.json` (a contract other tools read: the keys of issue #10, more
//! keys welcome) and `bench.csv` (one line per row); the Markdown report (docs/bench-*.md) is
//! [`SuiteReport::markdown`], in `bench/markdown.rs`.

use super::limits::Limits;
pub use super::row::{BoundShares, RowAblation, RowLimits, SuiteRow, CSV_COLUMNS};
use serde::Serialize;
use std::path::Path;
use umbrage::error::{Error, Result};

/// How many of the model's candidate bounds the run's ablations confirmed (`bench.json`'s
/// `bound_proofs`). A bound is *claimed* only once confirmed; `claimed` keeps its name from
/// before that rule (the key is a contract) and counts the candidates.
#[derive(Clone, Debug, Default, Serialize)]
pub struct ProofSummary {
    /// Rows measured where the model named a fill, vertex or draw bound clearly
    /// ([`SuiteRow::bound_clear`]): the candidates put to the test.
    pub claimed: usize,
    /// Of them, rows whose ablation ran.
    pub ablated: usize,
    /// Of them, rows whose bound the ablation confirmed: the bounds the report claims.
    pub confirmed: usize,
    /// Of them, rows whose ablation refuted the candidate (ran, not confirmed): the report's
    /// disagreements.
    pub refuted: usize,
    /// Of the ablations that ran, those whose two sides were the sweeps' own points (no
    /// re-timing; [`RowAblation::from_sweep`]).
    pub from_sweep: usize,
    /// Rows whose ablation could not run (no coarser tessellation of the shapes, a single
    /// caster to merge, a variant the device skips).
    pub not_run: usize,
    /// Timed frames per side of each re-timed ablation.
    pub frames: usize,
    /// Renderers the re-timed ablations built (a scene at a size each).
    pub points: usize,
    /// Wall seconds the ablations took.
    pub seconds: f64,
}

/// One phase of the run and what it cost (`bench.json`'s `phases`): where the suite's time
/// goes.
#[derive(Clone, Debug, Default, Serialize)]
pub struct Phase {
    /// `limits`, `scenes`, a sweep's name, `ablation`, `model`, `proofs`, `plots`.
    pub name: String,
    /// Wall seconds.
    pub wall_s: f64,
    /// CPU seconds of the process in it (all threads: lavapipe's rasteriser too), where the OS
    /// reports it.
    pub cpu_s: Option<f64>,
    /// Points measured in it (renderers built: sweep points, ablation scenes, proof scenes).
    pub points: usize,
    /// Points it listed but took from an identical point measured before (one-factor sweeps).
    pub shared_points: usize,
    /// The machine's 1-minute load average when it ended (Linux).
    pub load_average: Option<f64>,
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
    /// The same when the run started.
    pub load_average_start: Option<f64>,
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
    /// How many candidate bounds their ablations confirmed (each row's `ablation` has the
    /// detail).
    pub bound_proofs: ProofSummary,
    /// Where the run's time went, phase by phase.
    pub phases: Vec<Phase>,
    /// The techniques every sweep point ran (`rows`' `method`s).
    pub techniques: Vec<String>,
    /// The techniques the named scenes ran, with their error (more shadow-map sizes in the
    /// quick suite, and each map read with gathers too).
    pub named_techniques: Vec<String>,
    /// Techniques umbrage has that this device could not run, and why (not measured).
    pub not_measured: std::collections::BTreeMap<String, String>,
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
        let json = serde_json::to_string_pretty(self).map_err(|e| Error::Internal(format!("bench report JSON: {e}")))?;
        let p = dir.join("bench.json");
        std::fs::write(&p, json).map_err(|e| Error::io(p.display().to_string(), e))?;
        let p = dir.join("bench.csv");
        std::fs::write(&p, self.csv()).map_err(|e| Error::io(p.display().to_string(), e))?;
        Ok(())
    }
}
