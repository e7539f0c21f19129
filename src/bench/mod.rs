//! `umbrage bench`: speed measured on the device under test, against its error and against the
//! device's own limits.
//!
//! - [`classic`]: the fixed scenes, every method side by side, medians (`umbrage bench`);
//! - [`suite`]: `umbrage bench --suite fill-vertex`: the device's limits measured in the same
//!   run ([`limits`]), a cost model fitted on the suite's rows ([`model`]), the shadow pass's counters per point, sweeps that cross from
//!   vertex-bound to fill-bound ([`sweeps`]), each pass's fraction of its limits and the
//!   bound it is closest to, the crossovers, ablations, and the outputs ([`report`]: JSON,
//!   CSV, Markdown; [`plots`]: SVG and PNG).
#![warn(missing_docs)]

pub mod classic;
pub mod limits;
pub mod methods;
pub mod model;
pub mod plots;
pub mod report;
pub mod scenes;
pub mod suite;
pub mod sweeps;

pub use classic::{run, technique_label, BenchConfig, BenchReport, BenchRow};
