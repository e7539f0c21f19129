//! Where a multisampled frame's depth is evaluated, per sample: the standard locations, or
//! those the caller measured (`umbrage_render::sample_locations::calibrate_sample_locations`), with the driver
//! defect a frame warns of when they differ.

use super::Renderer;
use umbrage::error::Result;

/// Where a multisampled frame's depth is evaluated, per sample.
#[derive(Clone, Debug, Default)]
pub(crate) struct DepthLocations {
    /// Per sample, in Vulkan's standard order (empty for one sample).
    pub at: Vec<(f64, f64)>,
    /// The driver defect, when they are not the standard locations (a frame's warning).
    pub defect: Option<String>,
}

impl DepthLocations {
    /// Off the standard location by more than this (pixels), a sample's depth is reported.
    const TOLERANCE: f64 = 1e-3;

    /// The standard locations of `n` samples (`standardSampleLocations`), none for one sample:
    /// a renderer's until [`Renderer::use_sample_depth_locations`] says otherwise.
    pub(super) fn standard(n: u32) -> DepthLocations {
        let at = if n < 2 { Vec::new() } else { crate::standard_sample_locations(n).to_vec() };
        DepthLocations { at, defect: None }
    }

    /// The locations `at` measured on `device`: where they differ from the standard ones, the
    /// difference is the frame's warning (SwiftShader evaluates depth at the standard locations
    /// mirrored in x: docs/conform/drivers-notes.md §1f).
    fn measured(device: &str, at: &[(f64, f64)]) -> DepthLocations {
        let standard = crate::standard_sample_locations(at.len() as u32);
        let off: Vec<String> = at
            .iter()
            .zip(standard)
            .enumerate()
            .filter(|(_, (&(x, y), &(sx, sy)))| (x - sx).abs() > Self::TOLERANCE || (y - sy).abs() > Self::TOLERANCE)
            .map(|(k, (&(x, y), &(sx, sy)))| format!("sample {k} at ({x:.4}, {y:.4}), not ({sx}, {sy})"))
            .collect();
        let defect = (!off.is_empty()).then(|| {
            format!(
                "driver defect (docs/conform/drivers-notes.md §1f): {device} evaluates multisampled depth away from the standard \
                 sample locations ({}); a capture's positions are found at the measured locations",
                off.join(", ")
            )
        });
        DepthLocations { at: at.to_vec(), defect }
    }
}

impl Renderer {
    /// Where this device evaluates a multisampled draw's depth, per sample (Vulkan's standard
    /// order, pixels from the pixel's top-left corner), as measured by the caller (umbrage's
    /// `umbrage_render::sample_locations::calibrate_sample_locations` measures it with the conformance case
    /// `legacy.msaa_depth_locations`): a multisampled capture's positions are then found there
    /// instead of at the standard locations, and a frame whose locations are not the standard
    /// ones carries a warning naming the defect.
    ///
    /// # Errors
    /// [`Error::InvalidDesc`](umbrage::Error::InvalidDesc) when `at` does not hold one finite location in [0, 1)² per
    /// sample of the frame.
    pub fn use_sample_depth_locations(&mut self, at: &[(f64, f64)]) -> Result<()> {
        let n = self.own.parts.config.samples as usize;
        let inside = |v: f64| (0.0..1.0).contains(&v);
        if n < 2 || at.len() != n || !at.iter().all(|&(x, y)| inside(x) && inside(y)) {
            return Err(umbrage::Error::desc(
                "Renderer::use_sample_depth_locations",
                format!("{} locations for a frame of {n} samples (one per sample, each in [0, 1)^2)", at.len()),
            ));
        }
        self.own.parts.depth_locations = DepthLocations::measured(&self.own.ctx.info.name, at);
        Ok(())
    }
}
