//! Area lights in the frame: each is rendered as its point-light samples
//! ([`crate::geom::area`]), each sample planned, determined (its own scissor and depth bounds)
//! and accumulated into the float target by the per-light loop like any point light.

use super::Renderer;
use crate::error::{Error, Result};
use crate::geom::area::expand_lights;
use crate::scene::{Light, LightKind};

/// The most point lights (area-light samples included) a frame may have.
pub const MAX_FRAME_LIGHTS: usize = 4096;

/// `lights`, checked: every area light valid and of kind point, and no more than
/// [`MAX_FRAME_LIGHTS`] point lights once they are split into samples.
pub(super) fn checked_lights(lights: &[Light]) -> Result<Vec<Light>> {
    let mut total = 0usize;
    for (i, l) in lights.iter().enumerate() {
        if let Some(a) = &l.area {
            if l.kind != LightKind::Point {
                return Err(Error::Other(format!("light {i}: an area light must be of kind point (its centre), got {:?}", l.kind)));
            }
            if !l.position.is_finite() {
                return Err(Error::Other(format!("light {i}: area light centre {:?} is not finite", l.position)));
            }
            a.validate().map_err(|m| Error::Other(format!("light {i}: {m}")))?;
            total += a.samples as usize;
        } else {
            total += 1;
        }
    }
    if total > MAX_FRAME_LIGHTS {
        return Err(Error::Other(format!(
            "{total} point lights once the area lights are split into samples (at most {MAX_FRAME_LIGHTS}); lower `samples`"
        )));
    }
    Ok(lights.to_vec())
}

impl Renderer {
    /// The scene's lights as given, area lights whole ([`Renderer::scene`]'s `lights` are the
    /// point lights the last frame rendered, every area light split into its samples).
    pub fn source_lights(&self) -> &[Light] {
        &self.source_lights
    }

    /// Per source light, the range of its samples in [`Renderer::scene`]'s `lights`.
    pub fn light_samples(&self) -> Vec<std::ops::Range<usize>> {
        crate::geom::area::sample_ranges(&self.source_lights)
    }

    /// Redraws the area lights' samples for the next frame: a new pattern per frame with
    /// [`FrameSettings::jitter`](crate::render::FrameSettings::jitter), the fixed one without.
    pub(super) fn update_area_samples(&mut self) {
        if self.source_lights.iter().all(|l| l.area.is_none()) {
            return;
        }
        let wanted = self.settings.jitter.then_some(self.serial);
        if wanted != self.samples_for {
            self.scene.lights = expand_lights(&self.source_lights, wanted);
            self.samples_for = wanted;
            // The shadow-map baseline is rebuilt when lights move.
            self.scene_version += 1;
        }
    }
}
