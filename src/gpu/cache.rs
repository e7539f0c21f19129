//! The context's `VkPipelineCache`: one per [`Context`](super::Context), so a pipeline made
//! twice in a process (a renderer per scene, the accuracy tables, the bench) is compiled once
//! where the driver caches; optionally kept on disk between runs in the file
//! `UMBRAGE_PIPELINE_CACHE` names. A file is loaded only when its header (Vulkan's
//! `VkPipelineCacheHeaderVersionOne`) names this device's `pipelineCacheUUID`, and is
//! replaced atomically (a temporary file renamed), so a stale or torn file costs a cold cache,
//! never a driver fed foreign data. `UMBRAGE_PIPELINE_CACHE=off` makes no cache at all (every
//! creation compiles: what `umbrage info --pipelines` should time to measure a compiler).

use ash::vk;
use std::path::PathBuf;

/// The file `UMBRAGE_PIPELINE_CACHE` names (unset, empty or `off`: no file).
fn path() -> Option<PathBuf> {
    std::env::var_os("UMBRAGE_PIPELINE_CACHE").filter(|v| !v.is_empty() && !off_value(v)).map(PathBuf::from)
}

fn off_value(v: &std::ffi::OsStr) -> bool {
    v == "off"
}

/// Whether `UMBRAGE_PIPELINE_CACHE=off` asks for no cache.
fn off() -> bool {
    std::env::var_os("UMBRAGE_PIPELINE_CACHE").is_some_and(|v| off_value(&v))
}

/// Whether `data` is a version-one pipeline cache of the device whose `pipelineCacheUUID` is
/// `uuid` (the header: length 32, version 1, vendor and device ids, then the UUID).
pub fn matches_device(data: &[u8], uuid: &[u8; vk::UUID_SIZE]) -> bool {
    let word = |i: usize| data.get(i..i + 4).map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]));
    data.len() >= 32 && word(0) == Some(32) && word(4) == Some(1) && data[16..32] == uuid[..]
}

/// A pipeline cache on `device`, holding the file's data when it matches `uuid`; null when
/// the driver cannot make one or `UMBRAGE_PIPELINE_CACHE=off` (pipelines are then made
/// without a cache).
pub(super) fn create(device: &ash::Device, uuid: &[u8; vk::UUID_SIZE]) -> vk::PipelineCache {
    if off() {
        return vk::PipelineCache::null();
    }
    let initial = path().and_then(|p| std::fs::read(p).ok()).filter(|d| matches_device(d, uuid)).unwrap_or_default();
    let info = vk::PipelineCacheCreateInfo::default().initial_data(&initial);
    // SAFETY: a valid device; `initial` is a cache this device's UUID wrote (or empty).
    match unsafe { device.create_pipeline_cache(&info, None) } {
        Ok(c) => c,
        Err(_) => {
            let empty = vk::PipelineCacheCreateInfo::default();
            // SAFETY: as above, with no initial data.
            unsafe { device.create_pipeline_cache(&empty, None) }.unwrap_or(vk::PipelineCache::null())
        }
    }
}

/// Writes `cache` to the file `UMBRAGE_PIPELINE_CACHE` names (when set; a failure to write is
/// not an error: the next run starts cold), then destroys it.
///
/// # Safety
/// `cache` was made on `device` and no pipeline creation using it is in progress.
pub(super) unsafe fn save_and_destroy(device: &ash::Device, cache: vk::PipelineCache) {
    if cache == vk::PipelineCache::null() {
        return;
    }
    if let Some(p) = path() {
        // SAFETY: the caller's contract.
        if let Ok(data) = unsafe { device.get_pipeline_cache_data(cache) } {
            let tmp = p.with_extension(format!("tmp{}", std::process::id()));
            if std::fs::write(&tmp, &data).is_ok() && std::fs::rename(&tmp, &p).is_err() {
                let _ = std::fs::remove_file(&tmp);
            }
        }
    }
    // SAFETY: the caller's contract.
    unsafe { device.destroy_pipeline_cache(cache, None) };
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_this_devices_header_is_loaded() {
        let uuid = [7u8; vk::UUID_SIZE];
        let mut data = Vec::new();
        data.extend(32u32.to_le_bytes());
        data.extend(1u32.to_le_bytes());
        data.extend(0x10deu32.to_le_bytes());
        data.extend(0x1234u32.to_le_bytes());
        data.extend(uuid);
        data.extend([1, 2, 3]);
        assert!(matches_device(&data, &uuid));
        assert!(!matches_device(&data, &[8u8; vk::UUID_SIZE]), "another device's cache");
        assert!(!matches_device(&data[..31], &uuid), "a torn header");
        let mut v2 = data.clone();
        v2[4] = 2;
        assert!(!matches_device(&v2, &uuid), "another header version");
    }
}
