//! What a frame is asked to do: the options of [`Renderer`](super::Renderer) and the CLI.

use crate::technique::RenderTechnique;
use ash::vk;
use umbrage::error::{Error, Result};
use umbrage::named_enum;
pub use umbrage::pass::{ComputeDraws, Counter, DepthMode, IndexFormat, PassToggles, Technique};

named_enum!(
    /// What the final image shows.
    View, "view", {
        /// The lit scene.
        #[default]
        Shaded => "shaded",
        /// Shadow volumes translucent over the scene, coloured by case.
        Volumes => "volumes",
        /// Stencil counts of light 0 as a heat map.
        Stencil => "stencil",
    }
);

named_enum!(
    /// How lit surfaces are shaded (shadows are the same in every mode; see
    /// [`umbrage::geom::shading`]).
    Shading, "shading", {
        /// Smooth normals, shifted by their terminator bound so the light reaches zero before
        /// the shadow volumes' polygonal terminator.
        #[default]
        Smooth => "smooth",
        /// Smooth normals as they are: the light steps to zero along the terminator's
        /// triangle edges (shown for comparison).
        SmoothNaive => "smooth-naive",
        /// One normal per triangle.
        Flat => "flat",
    }
);

impl Shading {
    /// Its code in the lighting pass's push block (`LightPush::params.w`).
    pub(crate) fn code(self) -> f32 {
        match self {
            Shading::Smooth => 0.0,
            Shading::SmoothNaive => 1.0,
            Shading::Flat => 2.0,
        }
    }
}

/// How transparent casters' light-intensity map is stored and accumulated (Kim et al. 2008).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TransmitMode {
    /// RGBA32F (true) or RGBA16F (false).
    pub fp32: bool,
    /// Sum of +-log(t) (additive), or product of t and 1/t (multiplicative blending).
    pub log: bool,
}

impl std::str::FromStr for TransmitMode {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        match s {
            "mul16" => Ok(TransmitMode { fp32: false, log: false }),
            "log16" => Ok(TransmitMode { fp32: false, log: true }),
            "mul32" => Ok(TransmitMode { fp32: true, log: false }),
            "log32" => Ok(TransmitMode { fp32: true, log: true }),
            _ => {
                Err(Error::UnknownName { what: "light-intensity map mode", name: s.into(), expected: "log16, mul16, log32, mul32".into() })
            }
        }
    }
}

impl TransmitMode {
    /// The four modes.
    pub const ALL: [TransmitMode; 4] = [
        TransmitMode { fp32: false, log: false },
        TransmitMode { fp32: false, log: true },
        TransmitMode { fp32: true, log: false },
        TransmitMode { fp32: true, log: true },
    ];
    /// `mul16`, `log16`, `mul32` or `log32`.
    pub fn name(self) -> &'static str {
        match (self.log, self.fp32) {
            (false, false) => "mul16",
            (true, false) => "log16",
            (false, true) => "mul32",
            (true, true) => "log32",
        }
    }
    pub(crate) fn format(self) -> vk::Format {
        if self.fp32 {
            vk::Format::R32G32B32A32_SFLOAT
        } else {
            vk::Format::R16G16B16A16_SFLOAT
        }
    }
}

/// What a [`Renderer`](super::Renderer) is built for: fixed at creation (targets and
/// pipelines are made for it). Set by the renderer's caller (the CLI, the bench, the tests)
/// through [`RenderOptions`] at creation; read back with `Renderer::config`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RenderConfig {
    /// Image width in pixels (1..=16384).
    pub width: u32,
    /// Image height in pixels (1..=16384).
    pub height: u32,
    /// Infinite far plane, or finite with depth clamp.
    pub depth_mode: DepthMode,
    /// The light-intensity map's format: RGBA32F (true) or RGBA16F.
    pub transmit_fp32: bool,
    /// Partial self-shadowing of transparent casters (src/render/stages/selfshadow.rs).
    pub self_shadow: bool,
    /// Frames the renderer keeps in flight (command buffers, fences, readbacks per slot).
    pub frames_in_flight: usize,
    /// Samples per pixel of the frame's targets (1, 2, 4 or 8; see [`RenderOptions::samples`]).
    pub samples: u32,
}

/// The renderer's choices that may change from one frame to the next: what it hands the
/// shadow pass (its [`PassSettings`](umbrage::pass::PassSettings) fields: technique, counter,
/// index format, toggles, keep) and what it draws itself (view, shading, capture, ...). Set by
/// the renderer's caller in `Renderer::settings` between frames (first through
/// [`RenderOptions`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FrameSettings {
    /// What the shadow pass runs, or the shadow-map baseline.
    pub technique: RenderTechnique,
    /// Stencil or float counting.
    pub counter: Counter,
    /// Index format of the shadow streams.
    pub index_format: IndexFormat,
    /// Shaded, volumes overlay, or the stencil heat map.
    pub view: View,
    /// Smooth (default), naive smooth or flat shading.
    pub shading: Shading,
    /// Log-space or multiplicative light-intensity map (its format is fixed at creation).
    pub transmit_log: bool,
    /// Read back per-light counts, positions and normals (dumps, tests).
    pub capture: bool,
    /// Re-draw the area lights' sample pattern every frame (`--jitter`; see
    /// [`umbrage::geom::area`]); off: the same pattern every frame.
    pub jitter: bool,
    /// Scissor, depth bounds and culling on or off (ablations; all on by default).
    pub toggles: PassToggles,
    /// Measure the shadow pass's counters ([`crate::Stats::counters`]): per light an
    /// occlusion query around the counting variant of the determination (the exact number of
    /// fragments its volumes rasterise) and pipeline statistics around the determination.
    /// Adds a pass per light: do not time such frames.
    pub counters: bool,
    /// Keep each light–caster pair's plan across frames ([`umbrage::pass::PassSettings::keep`];
    /// on by default, off: `--no-keep`). The same pictures either way.
    pub keep: bool,
}

/// Everything a renderer is created with, in one struct literal: its [`RenderConfig`] and first
/// [`FrameSettings`] ([`config`](RenderOptions::config) and
/// [`settings`](RenderOptions::settings) split it). For creation only: afterwards the
/// renderer's caller reads the config and changes the settings.
#[derive(Clone, Debug)]
pub struct RenderOptions {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// What the shadow pass runs, or the shadow-map baseline.
    pub technique: RenderTechnique,
    /// Infinite far plane, or finite with depth clamp.
    pub depth_mode: DepthMode,
    /// Index format of the shadow streams.
    pub index_format: IndexFormat,
    /// What the final image shows.
    pub view: View,
    /// How lit surfaces are shaded.
    pub shading: Shading,
    /// Stencil or float counting.
    pub counter: Counter,
    /// Transparent casters' light-intensity map: format fixed at creation, log/mul per frame.
    pub transmit: TransmitMode,
    /// Read back per-light stencil counts, positions and normals (dumps, tests).
    pub capture: bool,
    /// Partial self-shadowing of transparent casters (src/render/stages/selfshadow.rs); no effect on
    /// scenes without them.
    pub self_shadow: bool,
    /// Frames in flight (at least 1).
    pub frames_in_flight: usize,
    /// Animate the area lights' sample pattern ([`FrameSettings::jitter`]).
    pub jitter: bool,
    /// Samples per pixel (`--msaa N`: 1, 2, 4 or 8). With more than one, the G-buffer, the
    /// shadow determination and the lighting run at every sample (the stencil count is exact
    /// per sample; the G-buffer and lighting shade per sample), the output is their resolve,
    /// and a captured frame reads back every sample ([`FrameOutput::samples`]). The stencil
    /// shadow-volume methods only: the float counter, the shadow-map and ray-query baselines,
    /// transparent casters and `--view volumes` render at one sample. Needs the device's
    /// `sampleRateShading` and the sample count on every target.
    ///
    /// [`FrameOutput::samples`]: crate::FrameOutput::samples
    pub samples: u32,
    /// Keep the shadow plans across frames ([`FrameSettings::keep`]; default on).
    pub keep: bool,
}

impl RenderOptions {
    /// The fixed half.
    pub fn config(&self) -> RenderConfig {
        RenderConfig {
            width: self.width,
            height: self.height,
            depth_mode: self.depth_mode,
            transmit_fp32: self.transmit.fp32,
            self_shadow: self.self_shadow,
            frames_in_flight: self.frames_in_flight,
            samples: self.samples,
        }
    }
    /// The per-frame half.
    pub fn settings(&self) -> FrameSettings {
        FrameSettings {
            technique: self.technique,
            counter: self.counter,
            index_format: self.index_format,
            view: self.view,
            shading: self.shading,
            transmit_log: self.transmit.log,
            capture: self.capture,
            jitter: self.jitter,
            toggles: PassToggles::default(),
            counters: false,
            keep: self.keep,
        }
    }
}

impl Default for RenderOptions {
    fn default() -> Self {
        RenderOptions {
            width: 960,
            height: 540,
            technique: RenderTechnique::default(),
            depth_mode: DepthMode::Infinite,
            index_format: IndexFormat::Auto,
            view: View::Shaded,
            shading: Shading::Smooth,
            counter: Counter::Stencil,
            transmit: TransmitMode { fp32: false, log: true },
            capture: false,
            self_shadow: false,
            frames_in_flight: 2,
            jitter: false,
            samples: 1,
            keep: true,
        }
    }
}
