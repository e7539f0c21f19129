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
    /// `best`: API usage, synchronisation and best-practices warnings (logged with
    /// `UMBRAGE_VERBOSE`, never fatal).
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
