//! The `--stats` JSON (a contract other tools read: keys as in issue #3, more keys welcome).

use serde::Serialize;

#[derive(Clone, Debug, Default, Serialize)]
pub struct Triangles {
    pub sides: u64,
    pub dark_cap: u64,
    pub light_cap: u64,
}

impl Triangles {
    pub fn total(&self) -> u64 {
        self.sides + self.dark_cap + self.light_cap
    }
    pub fn add(&mut self, o: &Triangles) {
        self.sides += o.sides;
        self.dark_cap += o.dark_cap;
        self.light_cap += o.light_cap;
    }
}

#[derive(Clone, Debug, Serialize)]
pub struct CasterStats {
    pub name: String,
    pub case: String,
    pub silhouette_edges: u64,
    pub triangles: Triangles,
    pub index_bytes: u64,
    pub vertex_bytes: u64,
    /// Bytes per shadow triangle actually sent this frame (index + streamed vertex bytes).
    pub bytes_per_triangle: f64,
    pub index_format: String,
    pub dark_cap_kind: String,
    /// "manifold" (the three-case path) or "multiplicity" (open / non-manifold casters).
    pub path: String,
    /// Why the caster took the multiplicity path (empty for manifold casters).
    pub path_reason: String,
    /// Largest |edge multiplicity| drawn (1 for a manifold silhouette).
    pub multiplicity_max: u32,
}

#[derive(Clone, Debug, Serialize)]
pub struct LightStats {
    pub index: usize,
    pub kind: String,
    pub scissor: Option<[u32; 4]>,
    pub depth_bounds: Option<[f32; 2]>,
    pub casters: Vec<CasterStats>,
}

#[derive(Clone, Debug, Default, Serialize)]
pub struct Cases {
    pub culled: u64,
    pub zpass: u64,
    pub zfail: u64,
    pub zfail_light_cap: u64,
}

#[derive(Clone, Debug, Default, Serialize)]
pub struct Totals {
    pub triangles: Triangles,
    pub index_bytes: u64,
    pub vertex_bytes: u64,
    pub cases: Cases,
}

#[derive(Clone, Debug, Default, Serialize)]
pub struct CpuMs {
    pub silhouettes: f64,
    pub plan: f64,
    pub record: f64,
}

#[derive(Clone, Debug, Default, Serialize)]
pub struct GpuMs {
    pub depth: f64,
    pub shadow: f64,
    pub illuminate: f64,
    pub frame: f64,
}

#[derive(Clone, Debug, Serialize)]
pub struct Stats {
    pub device: String,
    pub method: String,
    pub depth_mode: String,
    pub index_format: String,
    /// "stencil" (8-bit, wraps at 256) or "float" (32-bit float target).
    pub counter: String,
    /// The transparent casters' light-intensity map mode (log16, mul16, log32, mul32), when
    /// the scene has transparent casters.
    pub transmit: Option<String>,
    /// Partial self-shadowing of transparent casters ran (`--self-shadow` on a scene that has
    /// them).
    pub self_shadow: bool,
    pub width: u32,
    pub height: u32,
    pub lights: Vec<LightStats>,
    pub totals: Totals,
    pub cpu_ms: CpuMs,
    /// `None` when the device has no timestamps.
    pub gpu_ms: Option<GpuMs>,
    pub wall_ms: f64,
    /// Which optional features were used and which were missing (so skipped).
    pub features_used: Vec<String>,
    pub features_missing: Vec<String>,
    /// Things the user should know about this frame (e.g. possible 8-bit stencil overflow).
    pub warnings: Vec<String>,
}
