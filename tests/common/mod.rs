//! Shared helpers for GPU tests: a validated context (validation always on), and a clear
//! failure when no Vulkan device exists while `CI` is set.
#![allow(dead_code)]

use umbrage::gpu::Context;

/// A context with validation on. Without a device: panics under CI (a failure), otherwise
/// returns None so a developer without Vulkan sees the test skipped *loudly*.
pub fn context() -> Option<Context> {
    std::env::set_var("UMBRAGE_VALIDATION", "1");
    match Context::with_validation(true) {
        Ok(c) => Some(c),
        Err(e) => {
            if std::env::var_os("CI").is_some() {
                panic!("no Vulkan device under CI: {e}");
            }
            eprintln!("SKIPPED (no Vulkan device, CI not set): {e}");
            None
        }
    }
}
