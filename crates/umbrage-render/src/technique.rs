//! [`RenderTechnique`]: how the renderer computes a frame's shadows, the one enum `--method`
//! parses into: a technique the shadow pass runs ([`umbrage::pass::Technique`], handed to the
//! pass unchanged) or the renderer's own shadow-map baseline ([`ShadowMap`]).

use umbrage::error::{Error, Result};
use umbrage::named_enum;
use umbrage::pass::Technique;

named_enum!(
    /// How the shadow-map baseline reads its 3x3 percentage-closer-filtering taps: the
    /// same nine comparisons either way, bit for bit; what differs is the fetch count.
    Pcf, "pcf", {
        /// Nine single taps of the compare sampler.
        #[default]
        Taps => "taps",
        /// Four gathers of the compare sampler (each four comparisons), nine of whose sixteen
        /// results are the taps (single taps within a texel of a map's edge).
        Gather => "gather",
    }
);

named_enum!(
    /// How the shadow-map baseline renders a point light's six cube faces: the same six
    /// maps, the same per-face culling and the same picture either way; what differs is how
    /// the work reaches the device.
    CubeFaces, "cube", {
        /// Six tiles of one 3 x 2 atlas in one rendering instance, each caster drawn once per
        /// face its bounding sphere meets (a viewport and a draw per face).
        #[default]
        Atlas => "atlas",
        /// Six layers of an array image rendered as six views of one draw (`multiview`,
        /// Vulkan 1.1 core, where the device has it): each caster drawn once, its vertex
        /// shader placing it outside the views whose frustum its bounding sphere misses.
        Multiview => "multiview",
    }
);

/// The shadow-map baseline's settings (PCF 3x3, `--method shadowmap`), and in
/// [`Stats::shadow_map`](crate::Stats::shadow_map) how a frame rendered and read its maps.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize)]
pub struct ShadowMap {
    /// Texels per side of one map (16..=8192; `--shadow-map-size`).
    pub size: u32,
    /// How the lookup reads its 3x3 taps (`--pcf`: `taps` or `gather`).
    pub pcf: Pcf,
    /// How a point light's six cube faces are rendered (`--cube`: `atlas` or `multiview`).
    pub cube: CubeFaces,
}

impl ShadowMap {
    /// Maps of `size` texels with the default lookup ([`Pcf::Taps`]) and cube faces
    /// ([`CubeFaces::Atlas`]).
    pub fn new(size: u32) -> ShadowMap {
        ShadowMap { size, pcf: Pcf::Taps, cube: CubeFaces::Atlas }
    }
}

impl Default for ShadowMap {
    /// 2048-texel maps (`--shadow-map-size`'s default), taps, an atlas.
    fn default() -> Self {
        ShadowMap::new(2048)
    }
}

/// How the renderer computes a frame's shadows: what `--method` names.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum RenderTechnique {
    /// A technique the shadow pass runs, handed to it unchanged.
    Pass(Technique),
    /// The shadow-map baseline (PCF 3x3), drawn by the renderer; the shadow pass only culls
    /// and scissors its lights.
    ShadowMap(ShadowMap),
}

impl RenderTechnique {
    /// The name on the command line and in `--stats` (the pass technique's
    /// [`name`](Technique::name), or `shadowmap`).
    pub fn name(self) -> &'static str {
        match self {
            RenderTechnique::Pass(t) => t.name(),
            RenderTechnique::ShadowMap(_) => "shadowmap",
        }
    }
    /// What the shadow pass runs: the technique itself, or for the shadow-map baseline
    /// McGuire's volumes (whose frame gives the baseline its lights' culling and scissors; it
    /// draws no volume).
    pub fn pass(self) -> Technique {
        match self {
            RenderTechnique::Pass(t) => t,
            RenderTechnique::ShadowMap(_) => Technique::default(),
        }
    }
    /// The shadow-map baseline's settings, if it is the baseline.
    pub fn shadow_map(self) -> Option<ShadowMap> {
        match self {
            RenderTechnique::ShadowMap(m) => Some(m),
            RenderTechnique::Pass(_) => None,
        }
    }
    /// Whether the shadow pass counts volumes (or planar projections) into the stencil: not
    /// ray query, not the shadow-map baseline.
    pub fn is_volume_pass(self) -> bool {
        matches!(self, RenderTechnique::Pass(t) if t.is_volume_pass())
    }
    /// Reads a `--method` name as [`FromStr`](std::str::FromStr) does, `shadowmap` with the
    /// given maps' settings.
    pub fn parse_with(s: &str, shadow_map: ShadowMap) -> Result<RenderTechnique> {
        match s {
            "shadowmap" => Ok(RenderTechnique::ShadowMap(shadow_map)),
            _ => s.parse::<Technique>().map(RenderTechnique::Pass).map_err(|_| Error::UnknownName {
                what: "method",
                name: s.into(),
                expected: format!("{}, shadowmap", Technique::names()),
            }),
        }
    }
}

impl std::str::FromStr for RenderTechnique {
    type Err = Error;
    /// A pass technique's name (`auto`, `mcguire`, ..., `rayquery`: [`Technique`]'s
    /// `FromStr`) or `shadowmap` (with [`ShadowMap::default`]).
    fn from_str(s: &str) -> Result<RenderTechnique> {
        RenderTechnique::parse_with(s, ShadowMap::default())
    }
}

impl From<Technique> for RenderTechnique {
    fn from(t: Technique) -> Self {
        RenderTechnique::Pass(t)
    }
}

impl From<ShadowMap> for RenderTechnique {
    fn from(m: ShadowMap) -> Self {
        RenderTechnique::ShadowMap(m)
    }
}

impl Default for RenderTechnique {
    /// The pass's default technique (McGuire's volumes).
    fn default() -> Self {
        RenderTechnique::Pass(Technique::default())
    }
}

impl std::fmt::Display for RenderTechnique {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl serde::Serialize for RenderTechnique {
    /// As its [`name`](RenderTechnique::name), the `method` of `--stats`.
    fn serialize<S: serde::Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        s.serialize_str(self.name())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use umbrage::shadow::Method;

    #[test]
    fn every_name_reads_back() {
        let mut all: Vec<RenderTechnique> = Method::ALL.iter().map(|&m| Technique::Volumes(m).into()).collect();
        all.extend(
            [Technique::EdgeQuads, Technique::Planar, Technique::Compute, Technique::Mesh, Technique::RayQuery].map(RenderTechnique::Pass),
        );
        all.push(ShadowMap::default().into());
        for t in all {
            assert_eq!(t.name().parse::<RenderTechnique>().unwrap(), t, "{}", t.name());
        }
        assert_eq!("auto".parse::<RenderTechnique>().unwrap(), Technique::Volumes(Method::McGuire).into());
        let e = "shadowmaps".parse::<RenderTechnique>().unwrap_err().to_string();
        assert!(e.contains("shadowmap") && e.contains("rayquery") && e.contains("zpass-clear"), "{e}");
        assert_eq!(RenderTechnique::ShadowMap(ShadowMap::new(64)).pass(), Technique::default());
    }
}
