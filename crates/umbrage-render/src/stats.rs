//! The `--stats` JSON (a contract other tools read: keys as in issue #3, more keys welcome).

use serde::Serialize;

pub use umbrage::pass::stats::{Cases, CasterStats, CpuMs, LightStats, Totals, Triangles};

/// GPU time of a frame by pass, ms (timestamps outside rendering instances).
#[derive(Clone, Debug, Default, Serialize)]
pub struct GpuMs {
    /// The G-buffer pass.
    pub depth: f64,
    /// Every light's determination, summed (with the GPU silhouettes of
    /// [`Technique::Compute`](umbrage::pass::Technique::Compute), recorded once for every light).
    pub shadow: f64,
    /// Of `shadow`, the GPU possible silhouettes of every light (`Technique::Compute`: the
    /// compute pass; `Technique::Mesh`: its facing stages; 0 for the other techniques): the
    /// pass's `cmd_before_rendering`, so with the frame's caster uploads when it has any.
    pub silhouettes: f64,
    /// Every light's illumination, summed.
    pub illuminate: f64,
    /// The whole frame.
    pub frame: f64,
    /// The frame's acceleration-structure builds (ray query: the pass's `cmd_before_rendering`,
    /// the top level's build and any bottom level's; 0 otherwise).
    pub accel: f64,
    /// Of `shadow`, the shadow-map baseline's map rendering (every light's maps; 0 for the
    /// other techniques). `shadow - shadow_map` is its lookup.
    pub shadow_map: f64,
    /// Per light, in the frame's light order.
    pub per_light: Vec<LightGpuMs>,
}

/// One light's GPU time.
#[derive(Clone, Debug, Default, Serialize)]
pub struct LightGpuMs {
    /// Its determination (and the shadow-map passes for the baseline).
    pub shadow: f64,
    /// Of `shadow`, rendering its shadow maps (the baseline; 0 otherwise).
    pub shadow_map: f64,
    /// Its illumination.
    pub illuminate: f64,
}

/// The `--stats` JSON of one frame.
#[derive(Clone, Debug, Serialize)]
pub struct Stats {
    /// The device's name.
    pub device: String,
    /// The technique that ran (`mcguire`, ..., `edgequad`, `shadowmap`: its name).
    pub method: super::RenderTechnique,
    /// `infinite` or `clamp`.
    pub depth_mode: super::DepthMode,
    /// The requested index format (`auto`, `u16`, ...).
    pub index_format: super::IndexFormat,
    /// `stencil` (8-bit, wraps at 256) or `float` (32-bit float target).
    pub counter: super::Counter,
    /// The transparent casters' light-intensity map mode (log16, mul16, log32, mul32), when
    /// the scene has transparent casters.
    pub transmit: Option<String>,
    /// Partial self-shadowing of transparent casters ran (`--self-shadow` on a scene that has
    /// them).
    pub self_shadow: bool,
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Per light, in scene order.
    pub lights: Vec<LightStats>,
    /// Totals over lights and casters.
    pub totals: Totals,
    /// CPU time by stage.
    pub cpu_ms: CpuMs,
    /// `None` when the device has no timestamps.
    pub gpu_ms: Option<GpuMs>,
    /// Submit to read-back, ms.
    pub wall_ms: f64,
    /// Which optional features were used and which were missing (so skipped).
    pub features_used: Vec<String>,
    /// Optional features the device lacks (their paths were skipped).
    pub features_missing: Vec<String>,
    /// The shadow pass's counters, when the frame measured them (`FrameSettings::counters`).
    pub counters: Option<super::PassCounters>,
    /// Things the user should know about this frame (e.g. possible 8-bit stencil overflow).
    pub warnings: Vec<String>,
    /// The ray-query technique's acceleration structures (`None` for the other techniques).
    pub ray_query: Option<RayQueryStats>,
    /// The shadow-map baseline's maps and lookup (`None` for the other techniques).
    pub shadow_map: Option<crate::ShadowMap>,
}

/// What `--method rayquery` traces against.
#[derive(Clone, Debug, Default, Serialize)]
pub struct RayQueryStats {
    /// Bottom levels: one per shadow-casting mesh, one for the analytic spheres.
    pub bottom_levels: usize,
    /// Their storage, bytes (compacted once the frame that built them has retired).
    pub bottom_level_bytes: u64,
    /// GPU time of the last frame that built bottom levels (its acceleration-structure span:
    /// the builds and that frame's top level), ms; 0 when the timestamps are off.
    pub bottom_level_build_ms: f64,
    /// Top-level instances rebuilt every frame.
    pub instances: usize,
    /// The offset the shadow rays start off the surface (world units).
    pub offset: f32,
    /// Bottom levels this frame built (new casters, a caster's first deformation, a changed
    /// sphere set).
    pub builds: usize,
    /// Bottom levels this frame refitted in place (deformed casters, `ALLOW_UPDATE`).
    pub refits: usize,
    /// Bottom levels this frame compacted (built `frames_in_flight` frames earlier).
    pub compactions: usize,
    /// Every light's rays in one pass per 32 lights (`PassToggles::ray_batch`, two lights or
    /// more), rather than one pass per light.
    pub batched: bool,
}
