//! TEMPORARY interface stub, replaced by the real planner (branch wt-geom) at merge.
use crate::error::Result;
use crate::scene::{Camera, Light, SceneMesh};
use glam::{Mat4, Vec3};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Method { ZPass, ZFail, EverittKilgard, Lengyel, McGuire }
impl std::fmt::Display for Method {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result { write!(f, "mcguire") }
}
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Case { Culled, ZPass, ZFail, ZFailLightCap }
impl Case { pub fn name(self) -> &'static str { "culled" } }
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DarkCap { Fan, BackFaces, None }
pub struct PlanInput<'a> { pub camera: &'a Camera, pub width: u32, pub height: u32, pub view_proj: Mat4, pub light: &'a Light, pub method: Method }
pub struct ChunkDraw { pub chunk: usize, pub volume: Vec<u16>, pub light_cap: Vec<u16> }
pub struct CasterPlan { pub caster: usize, pub case: Case, pub silhouette_edges: usize, pub sides: usize, pub dark_cap: usize, pub light_cap: usize, pub chunks: Vec<ChunkDraw>, pub dark_cap_kind: DarkCap }
pub struct LightPlan { pub scissor: Option<[u32;4]>, pub depth_bounds: Option<(f32,f32)>, pub casters: Vec<CasterPlan>, pub silhouette_ms: f64, pub plan_ms: f64 }
pub struct Chunk { pub vertices: Vec<Vec3> }
pub struct Caster { pub name: String, pub transform: Mat4, pub chunks: Vec<Chunk> }
impl Caster { pub fn new(_i: usize, m: &SceneMesh) -> Result<Caster> { Ok(Caster { name: m.name.clone(), transform: m.transform, chunks: vec![] }) } }
pub fn plan_light(_i: &PlanInput, _c: &[Caster]) -> LightPlan { LightPlan { scissor: None, depth_bounds: None, casters: vec![], silhouette_ms: 0.0, plan_ms: 0.0 } }
