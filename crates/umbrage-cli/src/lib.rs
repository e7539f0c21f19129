//! umbrage-cli: the `umbrage` command line (render, view, check, conform, bench, info) and the
//! interactive viewer; the library half holds what its tests reach: the viewer, the GPU
//! profiles of `umbrage info --profiles` and the soak run.
//!
//! # Features
//!
#![doc = document_features::document_features!()]
#![allow(clippy::neg_cmp_op_on_partial_ord)]
pub mod profiles;
pub mod soak;
#[cfg(feature = "view")]
pub mod view;
