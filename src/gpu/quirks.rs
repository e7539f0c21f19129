//! Driver defects umbrage has measured, by driver and version: where a device offers a feature
//! but renders it wrongly, the path that needs it is refused with a clear error (and the
//! default path used instead) rather than drawing a wrong picture. Each entry names what was
//! measured; versions between a bad and a good measurement count as bad until measured.
//!
//! `UMBRAGE_IGNORE_QUIRKS=1` lifts every refusal, to reproduce a defect on the driver (driver
//! developers, conformance runs) or to check a newer version.

use super::context::DeviceInfo;

/// The Mesa version in a driver's `driverInfo` (`Mesa 22.3.6 (LLVM 15.0.6)`,
/// `Mesa 25.0.7-2~bpo12+1 (LLVM 15.0.6)`): `(major, minor, patch)`; `None` for another
/// vendor's driver.
///
/// ```
/// use umbrage::gpu::quirks::mesa_version;
/// assert_eq!(mesa_version("Mesa 25.0.7-2~bpo12+1 (LLVM 15.0.6)"), Some((25, 0, 7)));
/// assert_eq!(mesa_version("550.54"), None);
/// ```
pub fn mesa_version(driver_info: &str) -> Option<(u32, u32, u32)> {
    let v = driver_info.strip_prefix("Mesa ")?.split(|c: char| !(c.is_ascii_digit() || c == '.')).next()?;
    let mut parts = v.split('.').map(|p| p.parse::<u32>().ok());
    Some((parts.next()??, parts.next().flatten().unwrap_or(0), parts.next().flatten().unwrap_or(0)))
}

/// Why this device's multiview cannot be trusted with a point light's cube faces, if it
/// cannot: Mesa lavapipe before 25 loses triangles that need clipping when it renders several
/// views (measured on 22.3.6: `hard/light_inside_caster`'s box walls, which surround the
/// light and cross the faces' near planes, vanish from most faces, and 42,549 of 129,600
/// pixels differ from the atlas; scenes without clipped triangles, like `cubes`, match; 25.0.7
/// renders the atlas's maps bit for bit on every built-in scene tried).
pub fn multiview_defect(info: &DeviceInfo) -> Option<String> {
    if info.driver != "llvmpipe" || ignored() {
        return None;
    }
    match mesa_version(&info.driver_info) {
        Some(v) if v >= (25, 0, 0) => None,
        _ => Some(format!(
            "{} {} loses triangles that need clipping when it renders several views (measured on lavapipe 22.3.6; \
             25.0.7 is right: scripts/drivers.sh install 25.0.7)",
            info.driver, info.driver_info
        )),
    }
}

/// Set while [`ignoring`] runs.
static IGNORING: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

/// Runs `f` with every refusal lifted (process-wide while it runs): the conformance check
/// that measures a defect renders the refused path on purpose.
pub fn ignoring<T>(f: impl FnOnce() -> T) -> T {
    IGNORING.store(true, std::sync::atomic::Ordering::SeqCst);
    let out = f();
    IGNORING.store(false, std::sync::atomic::Ordering::SeqCst);
    out
}

/// Whether the refusals are lifted: `UMBRAGE_IGNORE_QUIRKS` is set (to anything but `0` or
/// empty), or [`ignoring`] is running.
fn ignored() -> bool {
    IGNORING.load(std::sync::atomic::Ordering::SeqCst) || std::env::var("UMBRAGE_IGNORE_QUIRKS").is_ok_and(|v| !v.is_empty() && v != "0")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lavapipe(driver_info: &str) -> DeviceInfo {
        DeviceInfo {
            name: "llvmpipe (LLVM 15.0.6, 256 bits)".into(),
            kind: "CPU".into(),
            driver: "llvmpipe".into(),
            driver_info: driver_info.into(),
            api_version: "1.3.230".into(),
            vendor_id: 0x10005,
            device_id: 0,
        }
    }

    #[test]
    fn mesa_versions_parse() {
        assert_eq!(mesa_version("Mesa 22.3.6 (LLVM 15.0.6)"), Some((22, 3, 6)));
        assert_eq!(mesa_version("Mesa 25.0.7-2~bpo12+1 (LLVM 15.0.6)"), Some((25, 0, 7)));
        assert_eq!(mesa_version("Mesa 24.1"), Some((24, 1, 0)));
        assert_eq!(mesa_version("535.104.05"), None);
    }

    #[test]
    fn old_lavapipe_multiview_is_refused_and_other_drivers_are_not() {
        assert!(multiview_defect(&lavapipe("Mesa 22.3.6 (LLVM 15.0.6)")).is_some());
        assert!(multiview_defect(&lavapipe("Mesa 20.3.5 (LLVM 11.0.1)")).is_some());
        assert!(multiview_defect(&lavapipe("garbled")).is_some());
        assert!(multiview_defect(&lavapipe("Mesa 25.0.7-2~bpo12+1 (LLVM 15.0.6)")).is_none());
        let other = DeviceInfo { driver: "NVIDIA".into(), driver_info: "550.54".into(), ..lavapipe("") };
        assert!(multiview_defect(&other).is_none());
    }
}
