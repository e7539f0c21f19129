//! Shadow-volume planning (McGuire et al. 2003): casters prepared at load, and per light
//! the culling, case selection and index lists the GPU side draws.
#![forbid(unsafe_code)]
#![warn(missing_docs)]
pub mod caster;
pub mod edgequad;
pub mod meshlet;
pub mod plan;

pub use caster::{Caster, CasterKind, Chunk, Part, TRANSMITTANCE_FLOOR};
pub use plan::{
    avoid_vertex, culled_caster_plan, object_light, plan_caster, plan_light, plan_light_opts, plan_light_with, Case, CasterPlan, ChunkDraw,
    DarkCap, LightContext, LightPlan, Method, PartPlan, PlanInput, PlanOptions, PlanScratch, VolumePath,
};
