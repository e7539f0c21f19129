//! `docs/devices.md`: the 68 gpuinfo.org device reports of `tests/data/devices/` (cut from
//! Khronos' Vulkan-Profiles by `scripts/device-reports.py`) through the same selection code a
//! live device goes through. This test regenerates the page and fails when the committed one
//! differs (the new one is written: commit it); it also holds the differences between real
//! devices that umbrage must survive to what the reports say.
//!
//! No device: runs everywhere.

use ash::vk;
use umbrage::gpu::caps::{choose, Minimum};
use umbrage::gpu::DeviceCaps;
use umbrage::pass::{ShadowPass, ShadowPassDesc};
use umbrage_cli::profiles::{read_gpuinfo, render_pass_target, report_markdown, PUSH_BYTES};

const DIR: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/devices");
const DOC: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/docs/devices.md");

fn reports() -> Vec<(String, DeviceCaps)> {
    let mut files: Vec<_> =
        std::fs::read_dir(DIR).unwrap().map(|e| e.unwrap().path()).filter(|p| p.extension().is_some_and(|x| x == "json")).collect();
    files.sort();
    files
        .into_iter()
        .map(|p| {
            let caps = read_gpuinfo(&std::fs::read_to_string(&p).unwrap()).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
            (p.file_name().unwrap().to_string_lossy().into_owned(), caps)
        })
        .collect()
}

fn find<'a>(all: &'a [(String, DeviceCaps)], file_starts: &str) -> Vec<&'a DeviceCaps> {
    let v: Vec<_> = all.iter().filter(|(f, _)| f.starts_with(file_starts)).map(|(_, c)| c).collect();
    assert!(!v.is_empty(), "no report {file_starts}*");
    v
}

#[test]
fn devices_md_is_current() {
    let all = reports();
    assert_eq!(all.len(), 68, "the reports of tests/data/devices/");
    let source = "`tests/data/devices/`, cut from the gpuinfo.org exports in \
                  [Vulkan-Profiles](https://github.com/KhronosGroup/Vulkan-Profiles); see its `SOURCE.md`";
    let doc = report_markdown(&all, source);
    let old = std::fs::read_to_string(DOC).unwrap_or_default();
    if old != doc {
        std::fs::write(DOC, &doc).unwrap();
        panic!("docs/devices.md was stale: the regenerated one is written, commit it");
    }
}

/// The differences between real devices the issue names, read back from the reports, and
/// what the selection makes of each.
#[test]
fn real_device_differences_are_handled() {
    let all = reports();
    let d24s8 =
        |c: &DeviceCaps| c.format_features(vk::Format::D24_UNORM_S8_UINT).contains(vk::FormatFeatureFlags::DEPTH_STENCIL_ATTACHMENT);
    // AMD's own drivers have no D24S8: the renderer takes D32S8, a host's D24S8 pass is refused
    // with a clear error, a D32S8 one is taken.
    for amd in find(&all, "amd_radeon_rx_7800_xt_2_0") {
        assert!(!d24s8(amd));
        let c = choose(amd, Minimum::Vulkan13).unwrap();
        assert_eq!(c.depth_format, vk::Format::D32_SFLOAT_S8_UINT);
        let d24 = ShadowPassDesc { depth_stencil_format: vk::Format::D24_UNORM_S8_UINT, ..Default::default() };
        let e = ShadowPass::capabilities_for(amd, &d24).unwrap_err().to_string();
        assert!(e.contains("D24_UNORM_S8_UINT"), "{e}");
        assert!(ShadowPass::capabilities_for(amd, &ShadowPassDesc::default()).is_ok());
    }
    // Intel HD and Apple M1/M3 lack depthBounds: asked for, it is simply not used.
    let no_bounds = find(&all, "intel_r__hd_graphics").into_iter().chain(find(&all, "apple_m1")).chain(find(&all, "apple_m3"));
    for dev in no_bounds {
        assert!(!dev.features.depth_bounds, "{}", dev.name);
        let format = if dev.format_features(vk::Format::D32_SFLOAT_S8_UINT).contains(vk::FormatFeatureFlags::DEPTH_STENCIL_ATTACHMENT) {
            vk::Format::D32_SFLOAT_S8_UINT
        } else {
            vk::Format::D24_UNORM_S8_UINT
        };
        let mut desc = ShadowPassDesc { depth_stencil_format: format, target: render_pass_target(format, 1), ..Default::default() };
        desc.features.depth_bounds = true;
        let caps = ShadowPass::capabilities_for(dev, &desc).unwrap_or_else(|e| panic!("{}: {e}", dev.name));
        assert!(!caps.depth_bounds);
    }
    // Apple M1 and M3 through MoltenVK: the portability subset, at most 4 samples (8 is
    // refused, naming the counts it has); the Vulkan 1.1-1.2 ones are refused by the renderer
    // but taken by the pass in a render pass.
    let f = vk::Format::D32_SFLOAT_S8_UINT;
    let moltenvk =
        all.iter().filter(|(file, c)| (file.starts_with("apple_m1_0_2") || file.starts_with("apple_m3")) && c.driver == "MoltenVK");
    let mut seen = 0;
    for (_, apple) in moltenvk {
        seen += 1;
        assert!(apple.portability_subset(), "{}", apple.name);
        let eight = ShadowPassDesc { samples: 8, target: render_pass_target(f, 8), ..Default::default() };
        let e = ShadowPass::capabilities_for(apple, &eight).unwrap_err().to_string();
        assert!(e.contains("8 samples") && e.contains("1, 2, 4"), "{e}");
        if apple.api_version < vk::API_VERSION_1_3 {
            assert!(choose(apple, Minimum::Vulkan13).is_err());
            let rp = ShadowPassDesc { target: render_pass_target(f, 1), ..Default::default() };
            assert!(ShadowPass::capabilities_for(apple, &rp).is_ok(), "{}", apple.name);
        }
    }
    assert!(seen >= 4, "{seen} MoltenVK M1/M3 reports");
    // Push constants run from 128 to 4096 bytes; every block umbrage declares fits the least.
    let least = all.iter().map(|(_, c)| c.limits.max_push_constants_size).min().unwrap();
    let most = all.iter().map(|(_, c)| c.limits.max_push_constants_size).max().unwrap();
    assert_eq!((least, most), (128, 4096));
    assert!(PUSH_BYTES <= least);
}
