//! umbrage-bench: speed measured on the device under test, against each method's error and the device's own limits.
//!
//! `umbrage bench`: speed measured on the device under test, against its error and against the
//! device's own limits.
//!
//! - [`classic`]: the fixed scenes, every method side by side, medians (`umbrage bench`);
//! - [`suite`]: `umbrage bench --suite fill-vertex`: the device's limits measured in the same
//!   run ([`limits`]), the shadow pass's counters per point, sweeps that cross from
//!   vertex-bound to fill-bound ([`sweeps`]), a cost model fitted on the rows ([`model`]) that
//!   gives each pass its fill, vertex and draw shares and the bound it is closest to, the crossovers, ablations, and the outputs ([`report`]: JSON,
//!   CSV; `markdown`: the report; [`plots`]: SVG and PNG);
//! - what the rows identify of the model ([`identify`]: bootstrap intervals, confounded pairs,
//!   condition number), and every claimed bound proven by an ablation in the same run
//!   ([`proof`], on the scenes [`reshape`] derives: coarser tessellation, casters merged).
#![warn(missing_docs)]

/// This crate's shaders, naga-compiled by its build script (`umbrage-shaderc`), beside the
/// shadow pass's and the renderer's (`umbrage_render::shaders`, re-exported; this crate's `ALL` lists its own).
pub mod shaders {
    pub use umbrage_render::shaders::*;
    include!(concat!(env!("OUT_DIR"), "/shaders.rs"));
}
pub mod classic;
mod classic_frames;
mod classic_rows;
pub mod compute_read;
mod evidence;
pub mod frame_cost;
mod frame_passes;
pub mod identify;
pub mod limits;
mod markdown;
pub mod methods;
pub mod model;
pub mod motion;
pub mod pass_limits;
mod phases;
pub mod plots;
pub mod proof;
pub mod report;
pub mod reshape;
mod row;
mod runner;
mod saturate;
pub mod scenes;
mod stats;
pub mod suite;
pub mod sweeps;
mod toggles;
mod workloads;

pub use classic::{run, technique_label, BenchConfig, BenchReport, BenchRow};
