//! The validation modes `UMBRAGE_VALIDATION` selects.

use ash::vk;

/// What `UMBRAGE_VALIDATION` asks the Khronos layer to check beyond API usage.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ValidationMode {
    /// `1`, `true` or `sync`: API usage and synchronisation validation (the default of every
    /// test and CI run).
    Sync,
    /// `nosync`: API usage only.
    ApiOnly,
    /// `gpu`: API usage and GPU-assisted validation (instrumented shaders: out-of-bounds
    /// descriptor, buffer and indirect-argument accesses). Synchronisation validation cannot
    /// run in the same instance, so it is off.
    GpuAssisted,
    /// `best`: API usage, synchronisation and best-practices warnings (each fails like an
    /// error unless [`ALLOWED_WARNINGS`] names it).
    BestPractices,
}

impl ValidationMode {
    /// Parses an `UMBRAGE_VALIDATION` value; `None` for off (`0`, empty, unknown).
    pub fn parse(v: &str) -> Option<ValidationMode> {
        match v.trim().to_ascii_lowercase().as_str() {
            "1" | "true" | "sync" => Some(ValidationMode::Sync),
            "nosync" => Some(ValidationMode::ApiOnly),
            "gpu" => Some(ValidationMode::GpuAssisted),
            "best" => Some(ValidationMode::BestPractices),
            _ => None,
        }
    }
    /// The mode `UMBRAGE_VALIDATION` asks for, if any.
    pub fn from_env() -> Option<ValidationMode> {
        std::env::var("UMBRAGE_VALIDATION").ok().and_then(|v| ValidationMode::parse(&v))
    }
    /// The mode's name, as `UMBRAGE_VALIDATION` spells it: `sync`, `nosync`, `gpu` or `best`.
    pub fn name(self) -> &'static str {
        match self {
            ValidationMode::Sync => "sync",
            ValidationMode::ApiOnly => "nosync",
            ValidationMode::GpuAssisted => "gpu",
            ValidationMode::BestPractices => "best",
        }
    }
    /// The layer features this mode enables.
    pub fn features(self) -> &'static [vk::ValidationFeatureEnableEXT] {
        match self {
            ValidationMode::Sync => &[vk::ValidationFeatureEnableEXT::SYNCHRONIZATION_VALIDATION],
            ValidationMode::ApiOnly => &[],
            ValidationMode::GpuAssisted => {
                &[vk::ValidationFeatureEnableEXT::GPU_ASSISTED, vk::ValidationFeatureEnableEXT::GPU_ASSISTED_RESERVE_BINDING_SLOT]
            }
            ValidationMode::BestPractices => {
                &[vk::ValidationFeatureEnableEXT::SYNCHRONIZATION_VALIDATION, vk::ValidationFeatureEnableEXT::BEST_PRACTICES]
            }
        }
    }
}

/// A validation warning that does not fail a run: its message ID, why it is expected, and the
/// driver or layer versions it was seen with. Every other warning fails like an error.
#[derive(Clone, Copy, Debug)]
pub struct AllowedWarning {
    /// The layer's message ID name (`VUID-...`, `WARNING-...`, `BestPractices-...`).
    pub id: &'static str,
    /// Why umbrage does what the warning names, on purpose.
    pub reason: &'static str,
    /// The driver or layer version(s) it applies to.
    pub applies_to: &'static str,
}

/// The one allowlist of validation warnings (see [`AllowedWarning`]).
pub const ALLOWED_WARNINGS: &[AllowedWarning] = &[
    AllowedWarning {
        id: "UNASSIGNED-BestPractices-Error-Result",
        reason: "feature detection: vkGetPhysicalDeviceImageFormatProperties is asked about formats and sample counts the \
                 device may lack, and VK_ERROR_FORMAT_NOT_SUPPORTED is the answer that says so",
        applies_to: "Khronos validation layer 1.3.239 (Debian 12), best-practices mode (UMBRAGE_VALIDATION=best) only",
    },
    AllowedWarning {
        id: "UNASSIGNED-BestPractices-pipeline-stage-flags",
        reason: "umbrage's own context's uploads and read-backs wait with ALL_COMMANDS barriers: correct and off the \
                 measured path (the shadow pass's own barriers name their stages)",
        applies_to: "Khronos validation layer 1.3.239 (Debian 12), best-practices mode only",
    },
    AllowedWarning {
        id: "UNASSIGNED-BestPractices-ImageBarrierAccessLayout",
        reason: "the renderer's layout transitions use MEMORY_READ|MEMORY_WRITE access, a superset of the \
                 attachment accesses the layout implies: correct, not the narrowest",
        applies_to: "Khronos validation layer 1.3.239 (Debian 12), best-practices mode only",
    },
    AllowedWarning {
        id: "UNASSIGNED-BestPractices-vkCreateCommandPool-command-buffer-reset",
        reason: "the context's pool resets command buffers one by one (frames in flight reuse their own buffer)",
        applies_to: "Khronos validation layer 1.3.239 (Debian 12), best-practices mode only",
    },
];

/// The allowlist's entry for a warning with message ID name `id`, if it has one.
pub fn allowed_warning(id: &str) -> Option<&'static AllowedWarning> {
    ALLOWED_WARNINGS.iter().find(|a| a.id == id)
}
