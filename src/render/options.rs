//! What a frame is asked to do: the options of [`Renderer`](super::Renderer) and the CLI.

use crate::error::{Error, Result};
use crate::shadow::Method;
use ash::vk;

/// An enum of named options: `name()`, `FromStr` (an unknown name lists the valid ones), `ALL`.
macro_rules! named_enum {
    ($(#[$m:meta])* $name:ident, $what:literal, { $($(#[$vm:meta])* $variant:ident => $s:literal),+ $(,)? }) => {
        $(#[$m])*
        #[derive(Clone, Copy, Debug, PartialEq, Eq)]
        pub enum $name {
            $($(#[$vm])* $variant),+
        }

        impl $name {
            pub const ALL: &'static [$name] = &[$($name::$variant),+];
            pub fn name(self) -> &'static str {
                match self {
                    $($name::$variant => $s),+
                }
            }
        }

        impl std::str::FromStr for $name {
            type Err = Error;
            fn from_str(s: &str) -> Result<Self> {
                Self::ALL.iter().copied().find(|v| v.name() == s).ok_or_else(|| Error::UnknownName {
                    what: $what,
                    name: s.into(),
                    expected: Self::ALL.iter().map(|v| v.name()).collect::<Vec<_>>().join(", "),
                })
            }
        }
    };
}

named_enum!(
    /// How z-fail keeps the far plane out of the way.
    DepthMode, "depth mode", {
        /// Far plane at infinity (w = 0 vertices land exactly on depth 1).
        Infinite => "infinite",
        /// A finite far plane beyond the scene, with `depthClamp` on the shadow pipelines.
        Clamp => "clamp",
    }
);

named_enum!(
    /// How shadow geometry reaches the GPU each frame.
    IndexFormat, "index format", {
        U32 => "u32",
        U16 => "u16",
        /// 8-bit indices for chunks of at most 128 vertices (needs `indexTypeUint8`), else u16.
        U8 => "u8",
        /// u8 where possible, else u16.
        Auto => "auto",
        /// No indices: every shadow-triangle vertex streamed as 4 x f32 (the naive baseline).
        Naive => "naive",
    }
);

named_enum!(
    /// Where shadow volumes are counted.
    Counter, "counter", {
        /// The 8-bit stencil with wrapping increments (counts modulo 256).
        Stencil => "stencil",
        /// A 32-bit float colour target with additive blending: no 8-bit wrap (exact to 2^24).
        Float => "float",
    }
);

named_enum!(
    /// What the final image shows.
    View, "view", {
        /// The lit scene.
        Shaded => "shaded",
        /// Shadow volumes translucent over the scene, coloured by case.
        Volumes => "volumes",
        /// Stencil counts of light 0 as a heat map.
        Stencil => "stencil",
    }
);

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
    pub const ALL: [TransmitMode; 4] = [
        TransmitMode { fp32: false, log: false },
        TransmitMode { fp32: false, log: true },
        TransmitMode { fp32: true, log: false },
        TransmitMode { fp32: true, log: true },
    ];
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

#[derive(Clone, Debug)]
pub struct RenderOptions {
    pub width: u32,
    pub height: u32,
    pub method: Method,
    pub depth_mode: DepthMode,
    pub index_format: IndexFormat,
    pub view: View,
    pub counter: Counter,
    /// Transparent casters' light-intensity map: format fixed at creation, log/mul per frame.
    pub transmit: TransmitMode,
    /// `Some(texels)`: the shadow-map baseline (PCF) instead of shadow volumes.
    pub shadow_map: Option<u32>,
    /// The GPU-only edge-quad method (Cg article) for closed opaque casters: no CPU
    /// silhouettes, every face and edge quad drawn every frame.
    pub edge_quads: bool,
    /// Read back per-light stencil counts, positions and normals (dumps, tests).
    pub capture: bool,
    /// Partial self-shadowing of transparent casters (src/render/selfshadow.rs); no effect on
    /// scenes without them.
    pub self_shadow: bool,
}

impl Default for RenderOptions {
    fn default() -> Self {
        RenderOptions {
            width: 960,
            height: 540,
            method: Method::McGuire,
            depth_mode: DepthMode::Infinite,
            index_format: IndexFormat::Auto,
            view: View::Shaded,
            counter: Counter::Stencil,
            transmit: TransmitMode { fp32: false, log: true },
            shadow_map: None,
            edge_quads: false,
            capture: false,
            self_shadow: false,
        }
    }
}
