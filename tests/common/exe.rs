//! The `umbrage` binary (crates/umbrage-cli) for the tests that run it as a process.
//!
//! It is another package's binary, so cargo does not hand its path to these tests
//! (`CARGO_BIN_EXE_*` is per package): it is found beside the test executable, in the same
//! target directory and profile. `cargo test` at the workspace root builds it (umbrage-cli is
//! a default member with an integration test of its own). A missing binary, or one older than
//! any source it is built from, fails the test with what to run: a stale binary would test
//! old code while looking green.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::time::SystemTime;

/// Path of a fresh `target/<profile>/umbrage`; panics (failing the test) if it is missing or stale.
/// The check walks the sources once a test process; every later call returns its answer.
pub fn umbrage_exe() -> PathBuf {
    static EXE: std::sync::OnceLock<PathBuf> = std::sync::OnceLock::new();
    EXE.get_or_init(find_fresh_exe).clone()
}

fn find_fresh_exe() -> PathBuf {
    let test = std::env::current_exe().expect("the test executable's path");
    // target/<profile>/deps/<test>-<hash> -> target/<profile>/umbrage
    let profile_dir = test.parent().and_then(Path::parent).expect("target/<profile>/deps/<test>");
    let exe = profile_dir.join(format!("umbrage{}", std::env::consts::EXE_SUFFIX));
    let built = std::fs::metadata(&exe).and_then(|m| m.modified()).unwrap_or_else(|e| {
        panic!("{}: {e}: build the CLI first (`cargo test` at the workspace root does, or `cargo build -p umbrage-cli`)", exe.display())
    });
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let newest = ["src", "shaders", "build.rs", "crates"].iter().filter_map(|p| newest_source(&root.join(p))).max();
    if let Some((when, path)) = newest {
        assert!(
            when <= built,
            "{} is older than {}: rebuild it (`cargo build -p umbrage-cli`, or `cargo test` at the workspace root)",
            exe.display(),
            path.display()
        );
    }
    exe
}

/// The newest source file (Rust, shader, TOML, OBJ) under `p`, skipping `target` and tests.
fn newest_source(p: &Path) -> Option<(SystemTime, PathBuf)> {
    let meta = std::fs::metadata(p).ok()?;
    if meta.is_file() {
        let ext = p.extension().and_then(|e| e.to_str()).unwrap_or("");
        let source = matches!(ext, "rs" | "toml" | "vert" | "frag" | "comp" | "wgsl" | "obj");
        return if source { Some((meta.modified().ok()?, p.to_path_buf())) } else { None };
    }
    let name = p.file_name().and_then(|n| n.to_str()).unwrap_or("");
    if matches!(name, "target" | "tests" | "benches" | "include") {
        return None;
    }
    std::fs::read_dir(p).ok()?.filter_map(|e| e.ok()).filter_map(|e| newest_source(&e.path())).max()
}
