//! Every pipeline creation, timed and named: what `umbrage info --pipelines` prints, and what
//! a driver that stalls in its shader compiler is caught in. With `UMBRAGE_PIPELINE_TRACE=1`
//! each creation is announced on stderr before the driver is called and timed after, so a
//! creation that never returns names itself.

use crate::error::Result;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Mutex;
use std::time::Instant;

/// One pipeline creation.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Creation {
    /// What was created: the shaders (`shadow.vert`, `silhouette.wgsl:facing`) and the
    /// fixed-function state that tells it apart (depth compare, stencil ops, blend, samples).
    pub label: String,
    /// Wall time of the driver's `vkCreate*Pipelines`, ms.
    pub ms: f64,
    /// The driver's error, when creation failed.
    pub error: Option<String>,
}

static RECORDING: AtomicBool = AtomicBool::new(false);
static CREATIONS: Mutex<Vec<Creation>> = Mutex::new(Vec::new());

/// Starts (or stops) keeping every creation of this process for [`take`].
pub fn record(on: bool) {
    RECORDING.store(on, Ordering::Relaxed);
}

/// The creations kept since [`record`] was turned on, oldest first (and forgets them).
pub fn take() -> Vec<Creation> {
    CREATIONS.lock().map(|mut c| std::mem::take(&mut *c)).unwrap_or_default()
}

fn trace() -> bool {
    static TRACE: std::sync::OnceLock<bool> = std::sync::OnceLock::new();
    *TRACE.get_or_init(|| std::env::var("UMBRAGE_PIPELINE_TRACE").is_ok_and(|v| v == "1"))
}

/// Runs one creation `f`, timing it under `label`.
pub(crate) fn timed<T>(label: impl FnOnce() -> String, f: impl FnOnce() -> Result<T>) -> Result<T> {
    let (recording, trace) = (RECORDING.load(Ordering::Relaxed), trace());
    if !recording && !trace {
        return f();
    }
    let label = label();
    if trace {
        eprintln!("umbrage: creating pipeline {label} ...");
    }
    let start = Instant::now();
    let r = f();
    let ms = start.elapsed().as_secs_f64() * 1e3;
    if trace {
        eprintln!("umbrage: created pipeline {label} in {ms:.1} ms{}", if r.is_err() { " (failed)" } else { "" });
    }
    if recording {
        let error = r.as_ref().err().map(|e| e.to_string());
        if let Ok(mut c) = CREATIONS.lock() {
            c.push(Creation { label, ms, error });
        }
    }
    r
}

/// A table of named SPIR-V modules: a crate's `shaders::ALL`.
pub type ShaderTable = &'static [(&'static str, &'static [u8])];

/// The tables [`shader_name`] searches beyond the pass's own ([`name_shaders`]).
static SHADER_TABLES: Mutex<Vec<ShaderTable>> = Mutex::new(Vec::new());

/// Lets the pipeline trace and the creation records name the shaders of another crate's
/// table (its `shaders::ALL`) by content, as they name the pass's own; without it, its
/// modules are named by their size. Registering a table twice is harmless.
pub fn name_shaders(table: ShaderTable) {
    if let Ok(mut t) = SHADER_TABLES.lock() {
        if !t.iter().any(|known| std::ptr::eq(*known, table)) {
            t.push(table);
        }
    }
}

/// The name of a shader constant of [`super::shaders`] (`shadow.vert`), or of a table given to
/// [`name_shaders`], found by content; other SPIR-V is named by its size.
pub(crate) fn shader_name(spirv: &[u8]) -> String {
    let find = |table: ShaderTable| table.iter().find(|(_, s)| *s == spirv).map(|(n, _)| n.to_string());
    find(super::shaders::ALL)
        .or_else(|| SHADER_TABLES.lock().ok().and_then(|t| t.iter().find_map(|table| find(table))))
        .unwrap_or_else(|| format!("spirv[{} bytes]", spirv.len()))
}
