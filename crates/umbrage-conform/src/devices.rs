//! The Vulkan devices present, for `umbrage conform --device NAME`.

use ash::vk;
use umbrage::error::{Error, Result};

/// One physical device.
#[derive(Clone, Debug)]
pub struct DeviceEntry {
    /// `deviceName`.
    pub name: String,
    /// Physical device type (`DISCRETE_GPU`, `CPU`, ...).
    pub kind: String,
    /// Its Vulkan API version, `major.minor.patch`.
    pub api_version: String,
}

impl std::fmt::Display for DeviceEntry {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{} ({}, Vulkan {})", self.name, self.kind, self.api_version)
    }
}

/// Every physical device the loader reports (a bare instance, no layers).
pub fn list() -> Result<Vec<DeviceEntry>> {
    // SAFETY: loading the Vulkan loader; `entry` outlives the instance destroyed below.
    let entry = unsafe { ash::Entry::load() }.map_err(|e| Error::NoDevice(format!("cannot load the Vulkan loader: {e}")))?;
    let app = vk::ApplicationInfo::default().application_name(c"umbrage").api_version(vk::API_VERSION_1_3);
    let info = vk::InstanceCreateInfo::default().application_info(&app);
    // SAFETY: `info` points at locals alive for the call.
    let instance =
        unsafe { entry.create_instance(&info, None) }.map_err(|e| Error::NoDevice(format!("vkCreateInstance failed ({e:?})")))?;
    // SAFETY: enumeration on the valid instance; the instance is destroyed right after and
    // nothing else was created from it.
    let result = unsafe {
        let r = instance.enumerate_physical_devices().map(|pds| {
            pds.iter()
                .map(|&pd| {
                    let p = instance.get_physical_device_properties(pd);
                    let v = p.api_version;
                    DeviceEntry {
                        name: p.device_name_as_c_str().map(|c| c.to_string_lossy().into_owned()).unwrap_or_default(),
                        kind: format!("{:?}", p.device_type),
                        api_version: format!("{}.{}.{}", vk::api_version_major(v), vk::api_version_minor(v), vk::api_version_patch(v)),
                    }
                })
                .collect::<Vec<_>>()
        });
        instance.destroy_instance(None);
        r
    };
    result.map_err(Error::vk("vkEnumeratePhysicalDevices"))
}

/// The devices whose name contains `wanted` (case-insensitive), or an error listing every device.
/// `#N` names the N-th device the loader enumerates (1-based), whatever its name.
pub fn find(wanted: &str) -> Result<Vec<DeviceEntry>> {
    let all = list()?;
    if let Some(k) = wanted.strip_prefix('#').and_then(|n| n.parse::<usize>().ok()) {
        return match k.checked_sub(1).and_then(|i| all.get(i)) {
            Some(d) => Ok(vec![d.clone()]),
            None => Err(Error::NoDevice(format!("{wanted}: there are {} Vulkan devices (1-based ids)", all.len()))),
        };
    }
    let w = wanted.to_lowercase();
    let hits: Vec<DeviceEntry> = all.iter().filter(|d| d.name.to_lowercase().contains(&w)).cloned().collect();
    if hits.is_empty() {
        let names: Vec<String> = all.iter().map(|d| format!("  {d}")).collect();
        return Err(Error::NoDevice(format!(
            "no Vulkan device's name contains '{wanted}'; the devices are:\n{}",
            if names.is_empty() { "  (none)".to_string() } else { names.join("\n") }
        )));
    }
    Ok(hits)
}
