//! One frame's layout for the compute pass: per light and caster a dispatch pair ([`Job`])
//! and one record per chunk (in one host-visible buffer), the chunks' output regions (in one
//! index buffer), and after the frame the counts read back into `--stats`.
//!
//! A chunk's regions are sized for the worst case of its part's case, so the shader can never
//! run out of room: volume `k · e + f · t` indices (`e` edges of the table touching the chunk,
//! `k` = 9 with the fan dark cap, 6 with other point-light sides, 3 for a directional light;
//! `f` = 3 with a dark cap of front or back faces, else 0; `t` the chunk's triangles) and
//! light cap `3 t` in case 3.

use super::{rec, ComputeStatic, SilhouettePush, RECORD_WORDS};
use crate::error::{Error, Result};
use crate::pass::draw::{Draw, LightFrame};
use crate::pass::stats::{CasterStats, Totals, UsedIndexFormat};
use crate::pass::IndexFormat;
use crate::shadow::plan::{Case, CasterPlan, DarkCap, Formulation, VolumePath};
use crate::shadow::Caster;
use ash::vk;
use std::cell::Cell;

/// One caster's dispatches for one light.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Job {
    /// Index of the caster in the pass's table.
    pub caster: usize,
    pub push: SilhouettePush,
}

/// Where a chunk record's counts go in the stats.
#[derive(Clone, Copy, Debug)]
pub(crate) struct RecordMeta {
    /// Word offset of the record.
    pub word: usize,
    pub light: usize,
    /// Index into the light's casters (plans and stats alike).
    pub caster: usize,
    /// Index into that caster's part stats.
    pub part: usize,
}

/// The frame's compute work, built by `pack` (sizes and records) and completed by `prepare`
/// (buffers and descriptor sets).
#[derive(Debug, Default)]
pub(crate) struct ComputeFrame {
    /// Per light, its jobs.
    pub jobs: Vec<Vec<Job>>,
    /// The records of every light, as written to the slot's records buffer.
    pub records: Vec<u32>,
    pub metas: Vec<RecordMeta>,
    /// Output size in 16-bit indices.
    pub out_indices: u64,
    /// Facing words.
    pub facing_words: u64,
    /// Per caster of the table that has jobs, its descriptor set (filled by `prepare`).
    pub sets: Vec<(usize, vk::DescriptorSet)>,
    pub records_buffer: vk::Buffer,
    pub out_buffer: vk::Buffer,
    pub recorded: Cell<bool>,
    pub read_back: Cell<bool>,
}

/// Where a caster's compute work goes: its light, its index in that light's stats, and its
/// index among the pass's casters.
#[derive(Clone, Copy, Debug)]
pub struct CasterAt {
    /// The light.
    pub light: usize,
    /// The caster's index in the light's lists (its stats).
    pub stat: usize,
    /// The caster's index in the pass.
    pub caster: usize,
}

impl ComputeFrame {
    pub fn set_of(&self, caster: usize) -> Option<vk::DescriptorSet> {
        self.sets.iter().find(|(c, _)| *c == caster).map(|&(_, s)| s)
    }

    /// Lays out caster `at.caster`'s chunk records for light `at.light` from its plan `cp` (the
    /// parts the planner left to the GPU: path `"compute"`), and appends the chunks' indirect
    /// draws to `draws`.
    pub fn add_caster(
        &mut self,
        at: CasterAt,
        caster: &Caster,
        st: &ComputeStatic,
        cp: &CasterPlan,
        chunk_buffers: &[vk::Buffer],
        draws: &mut Vec<Draw>,
    ) {
        let CasterAt { light: li, stat, caster: ci } = at;
        while self.jobs.len() <= li {
            self.jobs.push(Vec::new());
        }
        // a header of 4 words (word 0: the length of the exact test's list), then the chunks
        let job_base = self.records.len();
        let rec_base = job_base + 4;
        self.records.resize(rec_base + RECORD_WORDS * caster.chunks.len(), 0);
        let l_obj = glam::Vec4::from_array(cp.light_object);
        let mut caps = false;
        let directional = l_obj.w == 0.0;
        for (pp_index, pp) in cp.parts.iter().enumerate() {
            if pp.path != VolumePath::Compute || pp.case == Case::Culled {
                continue;
            }
            let part = &caster.parts[pp.part];
            let light_cap = pp.case == Case::ZFailLightCap;
            let (per_edge, faces) = match (directional, pp.dark_cap_kind) {
                (true, _) => (3u64, 0u64),
                (false, DarkCap::Fan) => (9, 0),
                (false, DarkCap::FrontFaces | DarkCap::BackFaces) => (6, 3),
                (false, _) => (6, 0),
            };
            let dc = match pp.dark_cap_kind {
                DarkCap::Fan => rec::DC_FAN,
                DarkCap::FrontFaces => rec::DC_FRONT,
                DarkCap::BackFaces => rec::DC_BACK,
                _ => 0,
            };
            let mut flags = rec::F_ENABLED | dc << 3;
            if pp.formulation == Formulation::Back {
                flags |= rec::F_BACK;
            }
            if directional {
                flags |= rec::F_DIRECTIONAL;
            }
            if light_cap {
                flags |= rec::F_LIGHT_CAP;
            }
            caps |= light_cap || faces > 0;
            for chunk in part.chunks.clone() {
                let t = st.chunk_tris[chunk] as u64;
                let vol = per_edge * st.chunk_edges[chunk] as u64 + faces * t;
                let cap = if light_cap { 3 * t } else { 0 };
                let w = rec_base + chunk * RECORD_WORDS;
                let r = &mut self.records[w..w + RECORD_WORDS];
                r[rec::VOL_INSTANCES] = 1;
                r[rec::CAP_INSTANCES] = 1;
                r[rec::FLAGS] = flags;
                r[rec::N] = caster.chunks[chunk].n() as u32;
                // regions start on even indices (whole words)
                r[rec::VOL_FIRST] = self.out_indices as u32;
                r[rec::VOL_CAP] = vol as u32;
                self.out_indices += vol.div_ceil(2) * 2;
                r[rec::CAP_FIRST] = self.out_indices as u32;
                r[rec::CAP_CAP] = cap as u32;
                self.out_indices += cap.div_ceil(2) * 2;
                self.metas.push(RecordMeta { word: w, light: li, caster: stat, part: pp_index });
                let offset = (w * 4) as u64;
                let draw = |cap_draw: bool, offset: u64| Draw {
                    vertices: chunk_buffers[chunk],
                    offset,
                    count: 0,
                    format: IndexFormat::U16,
                    case: pp.case,
                    light_cap: cap_draw,
                    indirect: true,
                };
                draws.push(draw(false, offset));
                if light_cap {
                    draws.push(draw(true, offset + (rec::CAP_COUNT * 4) as u64));
                }
            }
        }
        let (filt, bound) = match caster.planes.error_bound(l_obj) {
            Some((lf, e)) => (if caster.mirrored { -lf } else { lf }, e),
            None => (glam::Vec4::ZERO, f32::INFINITY),
        };
        let push = SilhouettePush {
            light: cp.light_object,
            filt: filt.to_array(),
            bound,
            flip: caster.mirrored as u32,
            tris: st.triangles,
            edges: st.edge_count,
            rec_base: rec_base as u32,
            fac_base: self.facing_words as u32,
            job_base: job_base as u32,
            caps: caps as u32,
        };
        self.facing_words += 2 * st.triangles as u64;
        self.jobs[li].push(Job { caster: ci, push });
    }

    /// Adds the counts the GPU left in the records (`words`, the slot's records buffer after
    /// the frame completed) to the lights' plans and stats and to `totals`. A region that
    /// overflowed (impossible with the worst-case sizing) is an error, never a silent cut.
    pub fn read_back(&self, words: &[u32], lights: &mut [LightFrame], totals: &mut Totals) -> Result<()> {
        if self.read_back.replace(true) {
            return Ok(());
        }
        for m in &self.metas {
            let r = words.get(m.word..m.word + RECORD_WORDS).ok_or_else(|| Error::Internal("compute records short".into()))?;
            if r[rec::OVERFLOW] != 0 || r[rec::VOL_COUNT] > r[rec::VOL_CAP] || r[rec::CAP_COUNT] > r[rec::CAP_CAP] {
                return Err(Error::Internal(format!(
                    "compute silhouettes: a chunk's index region overflowed ({} of {} volume, {} of {} light-cap indices)",
                    r[rec::VOL_COUNT],
                    r[rec::VOL_CAP],
                    r[rec::CAP_COUNT],
                    r[rec::CAP_CAP]
                )));
            }
            let (sides, dark, cap, edges) = (r[rec::SIDES] as u64, r[rec::DARK] as u64, r[rec::CAP_COUNT] as u64 / 3, r[rec::EDGES] as u64);
            let bytes = 2 * (r[rec::VOL_COUNT] as u64 + r[rec::CAP_COUNT] as u64);
            let lf = &mut lights[m.light];
            let cs: &mut CasterStats = &mut lf.stats.casters[m.caster];
            cs.triangles.sides += sides;
            cs.triangles.dark_cap += dark;
            cs.triangles.light_cap += cap;
            cs.silhouette_edges += edges;
            cs.index_bytes += bytes;
            cs.index_format = UsedIndexFormat::U16;
            cs.multiplicity_max = cs.multiplicity_max.max(u32::from(edges > 0));
            let n = cs.triangles.total();
            cs.bytes_per_triangle = if n > 0 { (cs.index_bytes + cs.vertex_bytes) as f64 / n as f64 } else { 0.0 };
            if let Some(ps) = cs.parts.get_mut(m.part) {
                ps.triangles.sides += sides;
                ps.triangles.dark_cap += dark;
                ps.triangles.light_cap += cap;
                ps.silhouette_edges += edges;
            }
            let cp = &mut lf.plan.casters[m.caster];
            cp.sides += sides as usize;
            cp.dark_cap += dark as usize;
            cp.light_cap += cap as usize;
            cp.silhouette_edges += edges as usize;
            if let Some(pp) = cp.parts.get_mut(m.part) {
                pp.sides += sides as usize;
                pp.dark_cap += dark as usize;
                pp.light_cap += cap as usize;
                pp.silhouette_edges += edges as usize;
                pp.multiplicity_max = pp.multiplicity_max.max(u32::from(edges > 0));
            }
            totals.triangles.sides += sides;
            totals.triangles.dark_cap += dark;
            totals.triangles.light_cap += cap;
            totals.index_bytes += bytes;
        }
        Ok(())
    }
}
