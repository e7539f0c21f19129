//! The `umbrage` binary run as a process (found by `common::exe`): commands, flags, exit
//! codes, reports, fault injection, validation modes and the viewer under Xvfb. Each module is
//! one suite; run one with `cargo test --test cli cli:: <module>::`.

#[path = "../common/mod.rs"]
mod common;

mod area_lights;
mod bench_motion;
mod bench_suite;
mod cli;
mod conform;
mod conform_deqp;
mod conform_images;
mod conform_pinning;
mod faults;
mod validation;
mod view;
