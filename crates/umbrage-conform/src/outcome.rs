//! The suite's ground floor: what a run is asked for ([`SuiteOptions`], the name filter) and
//! what it says of each case ([`CaseOutcome`]). Imports nothing of the suite's runners
//! ([`super::suite`], [`super::units`], [`super::isolate`]), which all build on it.

use super::cases::Bug;
use super::Status;
use ash::vk;
use std::path::PathBuf;

/// Options of a suite run.
#[derive(Clone, Debug)]
pub struct SuiteOptions {
    /// Case-name patterns; a case runs when any matches (empty: every case). A pattern with
    /// `*` is a glob over the whole name, otherwise a substring.
    pub filter: Vec<String>,
    /// Size of the `pipeline.hard_cases.*` renders.
    pub pipeline_size: (u32, u32),
    /// Where failure images go (`<dir>/failures/<case>/`); `None`: not written.
    pub image_dir: Option<PathBuf>,
    /// Test seam: the expectation applies [`super::model::broken`]`(op)` wherever it should apply `op`
    /// (`UMBRAGE_CONFORM_BREAK=<op>` on the command line), so the cases that exercise `op`
    /// must fail — and only those.
    #[doc(hidden)]
    pub break_op: Option<vk::StencilOp>,
    /// Test seam: the single-configuration checks named here (short or full names) expect a
    /// wrong value, and the drawn cases named here (full names) a wrong depth, so they fail
    /// and write their failure images (`UMBRAGE_CONFORM_MISMATCH=<check>,...` on the command
    /// line; see `value_images`).
    #[doc(hidden)]
    pub mismatch: Vec<String>,
}

impl Default for SuiteOptions {
    fn default() -> Self {
        SuiteOptions { filter: Vec::new(), pipeline_size: (160, 120), image_dir: None, break_op: None, mismatch: Vec::new() }
    }
}

/// Whether `name` matches `pattern` (`=NAME`: exactly that name; glob with `*` and `?` when it
/// has either; else substring).
pub fn matches(pattern: &str, name: &str) -> bool {
    if let Some(exact) = pattern.strip_prefix('=') {
        return name == exact;
    }
    if !pattern.contains(['*', '?']) {
        return name.contains(pattern);
    }
    fn glob(p: &[u8], s: &[u8]) -> bool {
        match (p.first(), s.first()) {
            (None, None) => true,
            (Some(b'*'), _) => glob(&p[1..], s) || (!s.is_empty() && glob(p, &s[1..])),
            (Some(b'?'), Some(_)) => glob(&p[1..], &s[1..]),
            (Some(a), Some(b)) if a == b => glob(&p[1..], &s[1..]),
            _ => false,
        }
    }
    glob(pattern.as_bytes(), name.as_bytes())
}

pub(crate) fn selected(filter: &[String], name: &str) -> bool {
    filter.is_empty() || filter.iter().any(|p| matches(p, name))
}

/// One query draw's count.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct QueryOutcome {
    /// Smallest count the model allows.
    pub expected_min: u64,
    /// Largest count the model allows.
    pub expected_max: u64,
    /// What the device counted.
    pub actual: u64,
}

/// The result of one case.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct CaseOutcome {
    /// The full dotted name.
    pub name: String,
    /// `stencil`, `depth`, `raster`, `zoo`, `legacy` or `pipeline`.
    pub group: String,
    /// The configuration (`d24s8.dynamic_rendering.static_state`); `None` for the legacy and
    /// pipeline checks (the renderer's format, dynamic rendering, static state).
    pub config: Option<String>,
    /// Pass, fail or skipped.
    pub status: Status,
    /// Pass: what held; fail: what differed; skipped: the missing feature.
    pub message: String,
    /// What the case checks.
    pub what: String,
    /// The bug a zoo case reproduces (not sent back by an isolated child: the parent has it).
    #[serde(skip_serializing_if = "Option::is_none", skip_deserializing)]
    pub bug: Option<Bug>,
    /// Seconds: the configuration's submission time shared equally among its cases.
    pub seconds: f64,
    /// Pixels whose stencil was judged.
    pub judged_pixels: u64,
    /// Judged pixels whose stencil differed.
    pub stencil_mismatches: u64,
    /// Judged pixels whose depth differed.
    pub depth_mismatches: u64,
    /// Occlusion-query counts.
    #[serde(skip_serializing_if = "Vec::is_empty", default)]
    pub queries: Vec<QueryOutcome>,
    /// Failure images written (expected, actual, diff).
    #[serde(skip_serializing_if = "Vec::is_empty", default)]
    pub images: Vec<String>,
}

impl CaseOutcome {
    pub(crate) fn new(name: String, group: &str, config: Option<String>, what: String) -> CaseOutcome {
        CaseOutcome {
            name,
            group: group.into(),
            config,
            status: Status::Pass,
            message: String::new(),
            what,
            bug: None,
            seconds: 0.0,
            judged_pixels: 0,
            stencil_mismatches: 0,
            depth_mismatches: 0,
            queries: Vec::new(),
            images: Vec::new(),
        }
    }
}
