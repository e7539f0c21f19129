//! Shared helpers for GPU tests: a validated context (validation always on), and a clear
//! failure when no Vulkan device exists while `CI` is set.
#![allow(dead_code)]

pub mod exe;

use umbrage::gpu::Context;

/// A context with validation on. Without a device: panics under CI (a failure), otherwise
/// returns None so a developer without Vulkan sees the test skipped *loudly*.
pub fn context() -> Option<Context> {
    std::env::set_var("UMBRAGE_VALIDATION", "1");
    match Context::with_validation(true) {
        Ok(mut c) => {
            // A leak or any message after the test's last check fails the test at teardown.
            // Mutation, run once: the renderer's sampler left undestroyed fails
            // bench_counters:: with VUID-vkDestroyDevice-device-00378.
            c.panic_on_teardown_validation = true;
            Some(c)
        }
        Err(e) => {
            if std::env::var_os("CI").is_some() {
                panic!("no Vulkan device under CI: {e}");
            }
            eprintln!("SKIPPED (no Vulkan device, CI not set): {e}");
            None
        }
    }
}

/// A validated context on a device with ray query, for the test named `test` (its path in the
/// test binary, e.g. `rayquery_follows_a_moving_caster`).
///
/// When the default device has none (the system's lavapipe 22.3 has none), the test re-runs
/// itself in a child process on Mesa lavapipe 25.0.7 ([`rerun_on_lavapipe_25`]), asserts that
/// the child passed and returns `None`.
pub fn ray_query_context(test: &str) -> Option<Context> {
    let ctx = context()?;
    if ctx.features.ray_query {
        return Some(ctx);
    }
    drop(ctx);
    rerun_on_lavapipe_25(test, false, &[]);
    None
}

/// A validated context on a device with mesh shaders (`VK_EXT_mesh_shader`), for the test
/// named `test`: as [`ray_query_context`], re-running the test on Mesa lavapipe 25.0.7 when
/// the default device has none.
pub fn mesh_shader_context(test: &str) -> Option<Context> {
    let ctx = context()?;
    if ctx.features.mesh_shader {
        return Some(ctx);
    }
    drop(ctx);
    rerun_on_lavapipe_25(test, false, &[]);
    None
}

/// Runs test `test` of this binary (`ignored`: an `#[ignore]`d helper test) in a child process
/// whose only Vulkan device is Mesa lavapipe 25.0.7 from `.drivers/` (`scripts/drivers.sh env
/// 25.0.7`), with `env` added, and asserts that it passed. Returns false when that driver is
/// not installed and `CI` is not set (a loud skip); under `CI` that is a failure. A child that
/// finds no ray query (or no trusted multiview) there fails rather than re-running again.
pub fn rerun_on_lavapipe_25(test: &str, ignored: bool, env: &[(&str, &str)]) -> bool {
    let child = std::env::var_os("UMBRAGE_RAY_QUERY_CHILD").is_some();
    assert!(
        !child,
        "this child already runs on lavapipe 25.0.7, and it lacks what the test needs (ray query, or a multiview it can trust)"
    );
    let Some(vars) = lavapipe_25_env() else {
        let why = "no ray-query device, and Mesa lavapipe 25.0.7 is not installed (scripts/drivers.sh install 25.0.7)";
        assert!(std::env::var_os("CI").is_none(), "{why}");
        eprintln!("SKIPPED: {why}");
        return false;
    };
    let mut env = env.to_vec();
    env.push(("UMBRAGE_RAY_QUERY_CHILD", "1"));
    run_child(test, ignored, &env, &vars, "Mesa lavapipe 25.0.7");
    true
}

/// Runs test `test` of this binary in a child process with the driver environment `vars` and
/// `env` added, and asserts that it passed (and ran).
fn run_child(test: &str, ignored: bool, env: &[(&str, &str)], vars: &[(String, Option<String>)], driver: &str) {
    // `concat!(module_path!(), "::name")` at the call site: libtest's names leave out the crate.
    let test = test.split_once("::").map_or(test, |(_, rest)| rest);
    let mut cmd = std::process::Command::new(std::env::current_exe().expect("test binary"));
    cmd.args(["--exact", test, "--nocapture", "--test-threads", "1"]);
    if ignored {
        cmd.arg("--ignored");
    }
    for (k, v) in env {
        cmd.env(k, v);
    }
    apply_driver_env(&mut cmd, vars);
    let out = cmd.output().unwrap_or_else(|e| panic!("run the test on {driver}: {e}"));
    print!("{}", String::from_utf8_lossy(&out.stdout));
    eprint!("{}", String::from_utf8_lossy(&out.stderr));
    assert!(out.status.success(), "{test} failed on {driver} (output above)");
    assert!(String::from_utf8_lossy(&out.stdout).contains("1 passed"), "{test} did not run in the child");
}

/// The environment that makes Mesa lavapipe 25.0.7 from `.drivers/` the only Vulkan device
/// (`scripts/drivers.sh env 25.0.7`): each variable to set (`Some`) or remove (`None`); `None`
/// when that driver is not installed.
pub fn lavapipe_25_env() -> Option<Vec<(String, Option<String>)>> {
    driver_env("25.0.7")
}

/// The environment of `scripts/drivers.sh env VERSION` (`25.0.7`, `swiftshader`, ...), as
/// [`lavapipe_25_env`] reads it; `None` when that driver is not installed.
pub fn driver_env(version: &str) -> Option<Vec<(String, Option<String>)>> {
    let root = env!("CARGO_MANIFEST_DIR");
    let o = std::process::Command::new(format!("{root}/scripts/drivers.sh")).args(["env", version]).output().ok()?;
    if !o.status.success() {
        return None;
    }
    let mut vars = Vec::new();
    for line in String::from_utf8_lossy(&o.stdout).lines() {
        let line = line.trim();
        if let Some(rest) = line.strip_prefix("export ") {
            if let Some((k, v)) = rest.split_once('=') {
                // `LD_LIBRARY_PATH=dir"${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"`: the directory, then ours.
                let v = v.trim_matches('"');
                let v = match v.split_once("\"${") {
                    Some((dir, _)) => match std::env::var("LD_LIBRARY_PATH") {
                        Ok(old) if !old.is_empty() => format!("{dir}:{old}"),
                        _ => dir.to_string(),
                    },
                    None => v.to_string(),
                };
                vars.push((k.to_string(), Some(v)));
            }
        } else if let Some(rest) = line.strip_prefix("unset ") {
            vars.extend(rest.split_whitespace().map(|k| (k.to_string(), None)));
        }
    }
    Some(vars)
}

/// Applies a driver's environment ([`lavapipe_25_env`]) to `c`: each variable set (`Some`) or
/// removed (`None`).
pub fn apply_driver_env(c: &mut std::process::Command, driver: &[(String, Option<String>)]) {
    for (k, v) in driver {
        match v {
            Some(v) => c.env(k, v),
            None => c.env_remove(k),
        };
    }
}

/// Runs the `#[ignore]`d helper test `test` of this binary in a child process whose only
/// Vulkan device is SwiftShader from `.drivers/` (`scripts/drivers.sh env swiftshader`), with
/// `env` added, and asserts that it passed. Returns false when SwiftShader is not installed
/// and `CI` is not set (a loud skip); under `CI` that is a failure.
pub fn rerun_on_swiftshader(test: &str, env: &[(&str, &str)]) -> bool {
    let Some(vars) = driver_env("swiftshader") else {
        let why = "SwiftShader is not installed (scripts/drivers.sh install swiftshader)";
        assert!(std::env::var_os("CI").is_none(), "{why}");
        eprintln!("SKIPPED: {why}");
        return false;
    };
    run_child(test, true, env, &vars, "SwiftShader");
    true
}

/// The scenes the GPU-driven methods are compared with McGuire on: every `hard/` case (bad
/// input among them: light_in_face_plane, light_at_vertex, light_inside_caster, zero_area,
/// slivers, near_coplanar, far_coordinates, open_casters) and the built-in scenes with casters.
pub fn hard_and_builtin_scenes() -> Vec<&'static str> {
    let mut names: Vec<&str> = umbrage_scene::builtin_names().into_iter().filter(|n| n.starts_with("hard/")).collect();
    names.extend(["default", "stairs", "cubes", "spheres"]);
    names
}

/// A mirrored caster (negative scale), a caster of several chunks (> 32768 vertices), a
/// directional light and point lights, one inside a caster's bounds: the mixed scene the
/// GPU-driven methods' tests share ([`mixed_scene`]).
pub const MIXED: &str = r#"
ambient = [0.05, 0.05, 0.05]
[camera]
eye = [0.0, 5.0, 9.0]
target = [0.0, 0.5, 0.0]
[[light]]
kind = "point"
position = [0.3, 6.0, 0.4]
[[light]]
kind = "directional"
direction = [-0.3, -1.0, -0.2]
[[light]]
kind = "point"
position = [2.6, 0.9, 0.2]
[[mesh]]
name = "floor"
shape = "plane"
size = [30.0, 30.0]
casts_shadow = false
[[mesh]]
name = "mirrored"
shape = "box"
size = [1.0, 1.0, 1.0]
translate = [-2.0, 1.0, 0.0]
scale = [-1.0, 1.0, 1.0]
[[mesh]]
name = "dense"
shape = "sphere"
radius = 0.8
segments = 300
rings = 150
translate = [0.5, 1.5, 0.0]
[[mesh]]
name = "hollow"
shape = "box"
size = [2.0, 2.0, 2.0]
translate = [2.6, 1.0, 0.0]
"#;

/// [`MIXED`], loaded.
pub fn mixed_scene() -> umbrage_scene::Scene {
    umbrage_scene::load_str(MIXED, "mixed", std::path::Path::new(".")).unwrap()
}

/// The seed of a GPU property test's random source: `default` (so that CI is reproducible),
/// `UMBRAGE_PROPTEST_SEED=<u64>` to replay a run, or `UMBRAGE_PROPTEST_SEED=random` to
/// explore. The seed is written straight to the process's stderr, past the test harness's
/// capture, so that a run the driver aborts (a crash loses the captured output) still names
/// the seed that replays it.
pub fn proptest_seed(test: &str, default: u64) -> u64 {
    use std::io::Write;
    let seed = match std::env::var("UMBRAGE_PROPTEST_SEED").as_deref() {
        Ok("random") => random_seed(),
        Ok(v) => v.parse().expect("UMBRAGE_PROPTEST_SEED: a u64 or `random`"),
        Err(_) => default,
    };
    let _ = writeln!(std::io::stderr().lock(), "{test}: UMBRAGE_PROPTEST_SEED={seed}");
    seed
}

/// A ChaCha test RNG from `seed`.
pub fn seeded_rng(seed: u64) -> proptest::test_runner::TestRng {
    use proptest::test_runner::{RngAlgorithm, TestRng};
    let mut bytes = [0u8; 32];
    bytes[..8].copy_from_slice(&seed.to_le_bytes());
    TestRng::from_seed(RngAlgorithm::ChaCha, &bytes)
}

fn random_seed() -> u64 {
    use std::hash::{BuildHasher, Hasher};
    let mut h = std::collections::hash_map::RandomState::new().build_hasher();
    h.write_u128(std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).map(|d| d.as_nanos()).unwrap_or(0));
    h.finish()
}

/// The fraction of `hard/big_caster` that SwiftShader's sliver defect costs the z-fail methods
/// with both caps everywhere (docs/conform/drivers-notes.md §1e), measured: the worst of the
/// defect's cells, which `tests/engine/hard_cases.rs` and `tests/engine/proptest_gpu.rs` hold it to.
pub const SWIFTSHADER_BIG_CASTER_SLIVERS: f64 = 0.00058;

/// `have`, for a check that needs the device feature `name`: without it the check cannot run.
/// Under `CI` that is a failure, never a silent skip (every feature asked for this way is one
/// CI's drivers have: lavapipe 22.3.6 has depthClamp, indexTypeUint8, precise occlusion
/// queries and pipeline statistics); elsewhere the skip is said out loud.
pub fn feature(have: bool, name: &str) -> bool {
    if !have {
        assert!(std::env::var_os("CI").is_none(), "the device lacks {name} under CI: the check that needs it would be skipped");
        eprintln!("SKIPPED (the device lacks {name}): the check that needs it");
    }
    have
}

/// For a refusal check that needs a device *without* a feature: when the default device has
/// it, runs test `test` (a module path, `concat!(module_path!(), "::name")`) in a child process
/// on Mesa lavapipe 22.3.6, which has neither mesh shaders nor ray query, and asserts that it
/// passed. Returns false when that driver is not installed and `CI` is not set (a loud skip);
/// under `CI` that is a failure.
pub fn rerun_without_the_feature(test: &str) -> bool {
    let Some(vars) = driver_env("22.3.6") else {
        let why = "Mesa lavapipe 22.3.6 is not installed (scripts/drivers.sh install 22.3.6)";
        assert!(std::env::var_os("CI").is_none(), "{why}");
        eprintln!("SKIPPED: {why}");
        return false;
    };
    run_child(test, false, &[], &vars, "Mesa lavapipe 22.3.6");
    true
}

/// A GPU-driven frame's statistics (`gs`) against McGuire's CPU-planned ones of the same frame
/// (`cs`): the casters drawn, in draw order, with their cases, triangles and silhouette edges,
/// part by part, and every manifold part on the GPU path `gpu_path`.
pub fn same_volumes_as_cpu(cs: &umbrage_render::Stats, gs: &umbrage_render::Stats, name: &str, gpu_path: umbrage::shadow::VolumePath) {
    for (li, (cl, gl)) in cs.lights.iter().zip(&gs.lights).enumerate() {
        // the casters drawn, in draw order (with PassSettings::keep the CPU path lists only those)
        let culled = umbrage::shadow::Case::Culled;
        let cd: Vec<_> = cl.casters.iter().filter(|c| c.case != culled).collect();
        let gd: Vec<_> = gl.casters.iter().filter(|c| c.case != culled).collect();
        assert_eq!(cd.len(), gd.len(), "{name} light {li}: casters drawn");
        for (&cc, &gc) in cd.iter().zip(&gd) {
            let what = format!("{name} light {li} caster {}", cc.name);
            assert_eq!(cc.case, gc.case, "{what}");
            assert_eq!(
                (cc.triangles.sides, cc.triangles.dark_cap, cc.triangles.light_cap, cc.silhouette_edges),
                (gc.triangles.sides, gc.triangles.dark_cap, gc.triangles.light_cap, gc.silhouette_edges),
                "{what}: triangles and silhouette edges"
            );
            assert_eq!(cc.parts.len(), gc.parts.len(), "{what}");
            for (cp, gp) in cc.parts.iter().zip(&gc.parts) {
                assert_eq!(cp.case, gp.case, "{what} part {}", cp.part);
                assert_eq!(
                    (cp.triangles.sides, cp.triangles.dark_cap, cp.triangles.light_cap, cp.silhouette_edges),
                    (gp.triangles.sides, gp.triangles.dark_cap, gp.triangles.light_cap, gp.silhouette_edges),
                    "{what} part {}",
                    cp.part
                );
                if cp.path == umbrage::shadow::VolumePath::Manifold {
                    assert_eq!(gp.path, gpu_path, "{what} part {}", cp.part);
                }
            }
        }
    }
}
