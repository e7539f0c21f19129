//! Area lights in the frame: each is rendered as its point-light samples
//! ([`umbrage::geom::area`]), each sample planned, determined (its own scissor and depth bounds)
//! and accumulated into the float target by the per-light loop like any point light.

use super::Renderer;
use umbrage::error::{Error, Result};
use umbrage::geom::area::expand_lights;
use umbrage_scene::{Light, LightKind};

/// The most point lights (area-light samples included) a frame may have.
pub const MAX_FRAME_LIGHTS: usize = 4096;

/// The accumulation format for a scene with `lights`: RGBA32F when one is an area light and
/// the device can blend it (many small additions lose too much in fp16), else RGBA16F (every
/// scene without area lights renders exactly as before).
pub(super) fn accum_format(lights: &[Light], rgba32f_blend: bool) -> ash::vk::Format {
    use crate::targets::{ACCUM_FORMAT, ACCUM_FORMAT_FP32};
    match rgba32f_blend && lights.iter().any(|l| l.area.is_some()) {
        true => ACCUM_FORMAT_FP32,
        false => ACCUM_FORMAT,
    }
}

/// `lights`, checked: every area light valid and of kind point, and no more than
/// [`MAX_FRAME_LIGHTS`] point lights once they are split into samples.
pub(super) fn checked_lights(lights: &[Light]) -> Result<Vec<Light>> {
    let mut total = 0usize;
    for (i, l) in lights.iter().enumerate() {
        if let Some(a) = &l.area {
            if l.kind != LightKind::Point {
                return Err(Error::argument(
                    "area light",
                    format!("light {i}: an area light must be of kind point (its centre), got {:?}", l.kind),
                ));
            }
            if !l.position.is_finite() {
                return Err(Error::argument("area light", format!("light {i}: area light centre {:?} is not finite", l.position)));
            }
            a.validate().map_err(|m| Error::argument("area light", format!("light {i}: {m}")))?;
            total += a.samples as usize;
        } else {
            total += 1;
        }
    }
    if total > MAX_FRAME_LIGHTS {
        return Err(Error::argument(
            "area light",
            format!("{total} point lights once the area lights are split into samples (at most {MAX_FRAME_LIGHTS}); lower `samples`"),
        ));
    }
    Ok(lights.to_vec())
}

impl Renderer {
    /// The scene's lights as given, area lights whole ([`Renderer::scene`]'s `lights` are the
    /// point lights the last frame rendered, every area light split into its samples).
    pub fn source_lights(&self) -> &[Light] {
        &self.own.parts.source_lights
    }

    /// Per source light, the range of its samples in [`Renderer::scene`]'s `lights`.
    pub fn light_samples(&self) -> Vec<std::ops::Range<usize>> {
        umbrage::geom::area::sample_ranges(&self.own.parts.source_lights)
    }

    /// Redraws the area lights' samples for the next frame: a new pattern per frame with
    /// [`FrameSettings::jitter`](crate::FrameSettings::jitter), the fixed one without.
    pub(super) fn update_area_samples(&mut self) {
        if self.own.parts.source_lights.iter().all(|l| l.area.is_none()) {
            return;
        }
        let wanted = self.settings.jitter.then_some(self.own.parts.serial);
        if wanted != self.own.parts.samples_for {
            self.own.parts.scene.lights = expand_lights(&self.own.parts.source_lights, wanted);
            self.own.parts.samples_for = wanted;
            // The shadow-map baseline is rebuilt when lights move.
            self.own.parts.scene_version += 1;
        }
    }
}
