//! Every embedded SPIR-V module passes `spirv-val` under Vulkan 1.3 rules, and every SPIR-V 1.0
//! module (the GLSL graphics modules and the WGSL modules marked `// @spirv 1.0`) under
//! Vulkan 1.0 rules too (the conformance suite runs on 1.0 devices).
use std::process::Command;

#[test]
fn every_embedded_module_passes_spirv_val() {
    let dir = std::env::temp_dir().join(format!("umbrage-spv-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    if Command::new("spirv-val").arg("--version").output().is_err() {
        assert!(std::env::var_os("CI").is_none(), "spirv-val missing under CI (apt-get install spirv-tools)");
        eprintln!("SKIPPED: spirv-val not installed (apt-get install spirv-tools)");
        return;
    }
    assert!(!umbrage::gpu::shaders::ALL.is_empty());
    for (name, spv) in umbrage::gpu::shaders::ALL {
        let path = dir.join(format!("{name}.spv"));
        std::fs::write(&path, spv).unwrap();
        let out = Command::new("spirv-val").args(["--target-env", "vulkan1.3"]).arg(&path).output().unwrap();
        assert!(out.status.success(), "{name}: {}", String::from_utf8_lossy(&out.stderr));
        // SPIR-V 1.0 (header word 1): the GLSL modules, and WGSL modules marked `// @spirv 1.0`.
        let version = spv.get(4..8).map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]));
        let marked = name.ends_with(".wgsl") && {
            let source = std::fs::read_to_string(format!("{}/shaders/{name}", env!("CARGO_MANIFEST_DIR"))).unwrap();
            source.lines().any(|l| l.trim() == "// @spirv 1.0")
        };
        assert_eq!(version.is_some_and(|v| v == 0x0001_0000), !name.ends_with(".wgsl") || marked, "{name}: SPIR-V version");
        if version == Some(0x0001_0000) {
            let out = Command::new("spirv-val").args(["--target-env", "vulkan1.0"]).arg(&path).output().unwrap();
            assert!(out.status.success(), "{name} (Vulkan 1.0 rules): {}", String::from_utf8_lossy(&out.stderr));
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}
