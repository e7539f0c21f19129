//! One frame's layout for the compute pass: per light and caster a job ([`GpuJob`]) with its
//! first workgroup in each stage, one record per chunk (after the frame's header, in one
//! host-visible buffer), the chunks' output regions (in one index buffer), and after the frame
//! the counts read back into `--stats`.
//!
//! A chunk's regions are sized for the worst case of its part's case, so the shader can never
//! run out of room: volume `k · e + f · t` indices (`e` edges of the table touching the chunk,
//! `k` = 9 with the fan dark cap, 6 with other point-light sides, 3 for a directional light;
//! `f` = 3 with a dark cap of front or back faces, else 0; `t` the chunk's triangles) and
//! light cap `3 t` in case 3.

use super::{rec, ComputeStatic, SilhouettePush, GROUP, HEADER_WORDS, RECORD_WORDS};
use crate::error::{Error, Result};
use crate::pass::desc::IndexFormat;
use crate::pass::draw::{Draw, LightFrame};
use crate::pass::mesh::{MeshDraw, COUNT_WORDS, MAX_TASKS};
use crate::pass::stats::{CasterStats, Totals, UsedIndexFormat};
use crate::shadow::plan::{Case, CasterPlan, DarkCap, Formulation, VolumePath};
use crate::shadow::Caster;
use ash::vk;
use bytemuck::{Pod, Zeroable};
use std::cell::Cell;

/// One (light, caster) pair as `shaders/silhouette.wgsl` reads it (`struct Job`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub(crate) struct GpuJob {
    /// The light in the caster's object space (w = 1 point, w = 0 directional).
    pub light: [f32; 4],
    /// The plane filter's light (negated for mirroring transforms).
    pub filt: [f32; 4],
    /// The filter's error bound (+inf: every triangle to the exact test).
    pub bound: f32,
    /// Bit 0 ([`J_FLIP`]): mirroring transform; bit 1 ([`J_BLOCKS`]): the facing stage may
    /// decide whole blocks (the job has a filter).
    pub flags: u32,
    pub tris: u32,
    pub edges: u32,
    /// The caster's first element in each arena table.
    pub plane_base: u32,
    pub tri_base: u32,
    pub pos_base: u32,
    pub edge_base: u32,
    /// Word offset of the pair's chunk records.
    pub rec_base: u32,
    /// Word offset of the pair's facing bits (a bit per triangle, whole workgroups).
    pub fac_base: u32,
    /// The pair's first invocation in the `facing` stage (one per 64-slot block) and the
    /// `find` stage (one per word-pair group), and its first workgroup in the `caps` stage.
    pub g_facing: u32,
    pub g_find: u32,
    pub g_caps: u32,
    /// The caster's first element in the block-bound and word-pair tables, and its groups.
    pub block_base: u32,
    pub group_base: u32,
    pub groups: u32,
}

/// [`GpuJob::flags`]: a mirroring transform (corners 1 and 2 swapped for the exact test).
pub(crate) const J_FLIP: u32 = 1;
/// [`GpuJob::flags`]: the facing stage may decide whole blocks (the job has a filter).
pub(crate) const J_BLOCKS: u32 = 2;

/// Workgroups of `n` items, [`GROUP`] a workgroup.
fn groups_of(n: u32) -> u32 {
    n.div_ceil(GROUP)
}

/// 64-slot blocks of `n` triangles (an invocation of the `facing` stage each).
fn blocks_of(n: u32) -> u32 {
    n.div_ceil(crate::geom::planes::GPU_BLOCK as u32)
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

/// The frame's compute work, built by `pack` (sizes, jobs and records) and completed by
/// `prepare` (buffers and the descriptor set).
#[derive(Debug)]
pub(crate) struct ComputeWork {
    /// Every (light, caster) pair with GPU work, lights in order.
    pub jobs: Vec<GpuJob>,
    /// The header, then the records of every light, as written to the slot's records buffer.
    pub records: Vec<u32>,
    pub metas: Vec<RecordMeta>,
    /// Output size in 16-bit indices.
    pub out_indices: u64,
    /// Facing words.
    pub facing_words: u64,
    /// Invocations of the `facing` (blocks) and `find` (word-pair groups) stages, workgroups
    /// of the `caps` stage.
    pub groups: [u32; 3],
    /// Room for the exact list (every job's triangles), in entries.
    pub exact_capacity: u64,
    /// Every job's edges (what a full scan of the edge table would read).
    pub sil_capacity: u64,
    /// The frame's descriptor set (filled by `prepare`).
    pub set: vk::DescriptorSet,
    pub records_buffer: vk::Buffer,
    pub out_buffer: vk::Buffer,
    pub recorded: Cell<bool>,
    pub read_back: Cell<bool>,
    /// Mesh-shader extrusion ([`Technique::Mesh`](crate::pass::Technique::Mesh)): only the
    /// `facing` and `exact` stages run; the parts are drawn by mesh draws.
    pub mesh: bool,
    /// Per mesh-drawn part, where its counters are (`word`: their first word in the counts
    /// buffer) and where they go in the stats.
    pub mesh_metas: Vec<RecordMeta>,
    /// Words of the mesh draws' counters.
    pub counts_words: u64,
    /// The mesh draws' descriptor set and counters (filled by `prepare`).
    pub mesh_set: vk::DescriptorSet,
    pub counts_buffer: vk::Buffer,
    /// The merged draws ([`super::draws`]): per (light, caster) pair with compute parts its
    /// transform and object-space light (the per-instance attributes `firstInstance` selects),
    /// every enabled chunk record, and their layout (filled by `prepare`; `None`: one draw per
    /// chunk with push constants).
    pub xforms: Vec<super::draws::Xform>,
    pub chunk_records: Vec<super::draws::ChunkRecord>,
    pub merged: Option<super::draws::Merged>,
}

impl Default for ComputeWork {
    fn default() -> Self {
        let mut records = vec![0u32; HEADER_WORDS];
        // the lists' dispatch commands: x grows with the lists, y = z = 1
        records[rec::H_EXACT_X + 1] = 1;
        records[rec::H_EXACT_X + 2] = 1;
        ComputeWork {
            jobs: Vec::new(),
            records,
            metas: Vec::new(),
            out_indices: 0,
            facing_words: 0,
            groups: [0; 3],
            exact_capacity: 0,
            sil_capacity: 0,
            set: vk::DescriptorSet::null(),
            records_buffer: vk::Buffer::null(),
            out_buffer: vk::Buffer::null(),
            recorded: Cell::new(false),
            read_back: Cell::new(false),
            mesh: false,
            mesh_metas: Vec::new(),
            counts_words: 0,
            mesh_set: vk::DescriptorSet::null(),
            counts_buffer: vk::Buffer::null(),
            xforms: Vec::new(),
            chunk_records: Vec::new(),
            merged: None,
        }
    }
}

/// Where a caster's compute work goes: its light and its index in that light's stats.
#[derive(Clone, Copy, Debug)]
pub struct CasterAt {
    /// The light.
    pub light: usize,
    /// The caster's index in the light's lists (its stats).
    pub stat: usize,
}

impl ComputeWork {
    /// The frame's push constants.
    pub fn push(&self) -> SilhouettePush {
        SilhouettePush {
            jobs: self.jobs.len() as u32,
            blocks: self.groups[0],
            word_pairs: self.groups[1],
            cap_groups: self.groups[2],
            steps: self.jobs.len().next_power_of_two().trailing_zeros(),
            pad: [0; 3],
        }
    }

    /// Lays out a caster's job and chunk records for light `at.light` from its plan `cp` (the
    /// parts the planner left to the GPU: path `"compute"`), and appends the chunks' indirect
    /// draws to `draws`; `mvp` (object to clip) is the caster's transform for the merged draws.
    pub fn add_caster(
        &mut self,
        at: CasterAt,
        caster: &Caster,
        st: &ComputeStatic,
        cp: &CasterPlan,
        (chunk_buffers, mvp): (&[vk::Buffer], glam::Mat4),
        draws: &mut Vec<Draw>,
    ) {
        let CasterAt { light: li, stat } = at;
        let xform = self.xforms.len() as u32;
        self.xforms.push(super::draws::Xform::new(mvp, cp.light_object));
        let rec_base = self.records.len();
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
                self.chunk_records.push(super::draws::ChunkRecord {
                    word: w,
                    light: li,
                    xform,
                    vertex_base: st.chunk_vertex_base[chunk],
                    zpass: pp.case == Case::ZPass,
                    cap: light_cap,
                });
                let offset = (w * 4) as u64;
                let draw = |cap_draw: bool, offset: u64| Draw {
                    vertices: chunk_buffers[chunk],
                    kept: None,
                    offset,
                    count: 0,
                    format: IndexFormat::U16,
                    case: pp.case,
                    light_cap: cap_draw,
                    indirect: true,
                    mesh: None,
                };
                draws.push(draw(false, offset));
                if light_cap {
                    draws.push(draw(true, offset + (rec::CAP_COUNT * 4) as u64));
                }
            }
        }
        self.push_job(caster, st, cp, rec_base, caps);
    }

    /// Appends the job of a (light, caster) pair whose records start at word `rec_base`, with
    /// `caps` workgroups (face caps) or not; returns its facing bits' first word.
    fn push_job(&mut self, caster: &Caster, st: &ComputeStatic, cp: &CasterPlan, rec_base: usize, caps: bool) -> u32 {
        let l_obj = glam::Vec4::from_array(cp.light_object);
        let (filt, bound) = match caster.planes.error_bound(l_obj) {
            Some((lf, e)) => (if caster.mirrored { -lf } else { lf }, e),
            None => (glam::Vec4::ZERO, f32::INFINITY),
        };
        let blocks = blocks_of(st.triangles);
        let fac_base = self.facing_words as u32;
        let filter = if bound.is_finite() { J_BLOCKS } else { 0 };
        let job = GpuJob {
            light: cp.light_object,
            filt: filt.to_array(),
            bound,
            flags: if caster.mirrored { J_FLIP } else { 0 } | filter,
            tris: st.triangles,
            edges: st.edge_count,
            plane_base: st.base[0],
            tri_base: st.base[1],
            pos_base: st.base[2],
            edge_base: st.base[3],
            rec_base: rec_base as u32,
            fac_base: self.facing_words as u32,
            g_facing: self.groups[0],
            g_find: self.groups[1],
            g_caps: self.groups[2],
            block_base: st.base[super::arena::BLOCKS],
            group_base: st.base[super::arena::GROUPS],
            groups: st.group_count,
        };
        self.groups[0] += blocks;
        self.groups[1] += st.group_count;
        if caps {
            self.groups[2] += groups_of(st.triangles);
        }
        // two words a block, every word written by the `facing` stage
        self.facing_words += 2 * blocks as u64;
        self.exact_capacity += st.triangles as u64;
        self.sil_capacity += st.edge_count as u64;
        self.jobs.push(job);
        fac_base
    }

    /// [`Technique::Mesh`](crate::pass::Technique::Mesh): the caster's job (its facing bits
    /// only) for light `at.light`, and per part the planner left to the GPU (path `"mesh"`) its
    /// mesh draws, appended to `draws`: the sides (with the fan dark cap's triangles), the dark
    /// cap of front or back faces where the part's case has one, the light cap in case 3; at
    /// most [`MAX_TASKS`] meshlets a draw.
    pub fn add_caster_mesh(&mut self, at: CasterAt, caster: &Caster, st: &ComputeStatic, cp: &CasterPlan, draws: &mut Vec<Draw>) {
        use crate::pass::mesh::flags as F;
        let fac_base = self.push_job(caster, st, cp, self.records.len(), false);
        // the `find` and `caps` stages do not run for mesh frames
        if let Some(j) = self.jobs.last_mut() {
            j.edges = 0;
            j.groups = 0;
        }
        self.groups[1] -= st.group_count;
        self.sil_capacity -= st.edge_count as u64;
        let directional = cp.light_object[3] == 0.0;
        for (pp_index, pp) in cp.parts.iter().enumerate() {
            if pp.path != VolumePath::Mesh || pp.case == Case::Culled {
                continue;
            }
            let Some(range) = st.part_meshlets.get(pp.part).filter(|r| !r.is_empty()) else { continue };
            let stat = self.counts_words as u32;
            self.counts_words += COUNT_WORDS as u64;
            self.mesh_metas.push(RecordMeta { word: stat as usize, light: at.light, caster: at.stat, part: pp_index });
            let mut work = Vec::with_capacity(3);
            let fan = !directional && pp.dark_cap_kind == DarkCap::Fan;
            work.push((F::SIDES | if directional { F::DIRECTIONAL } else { 0 } | if fan { F::FAN } else { 0 }, false));
            match pp.dark_cap_kind {
                DarkCap::FrontFaces if !directional => work.push((F::DARK | F::WANT, false)),
                DarkCap::BackFaces if !directional => work.push((F::DARK, false)),
                _ => {}
            }
            if pp.case == Case::ZFailLightCap {
                work.push((F::LIGHT | if pp.formulation == Formulation::Front { F::WANT } else { 0 }, true));
            }
            for (flags, light_cap) in work {
                let mut first = range.start;
                while first < range.end {
                    let n = (range.end - first).min(MAX_TASKS);
                    draws.push(Draw {
                        vertices: vk::Buffer::null(),
                        kept: None,
                        offset: 0,
                        count: 0,
                        format: IndexFormat::U16,
                        case: pp.case,
                        light_cap,
                        indirect: false,
                        mesh: Some(MeshDraw {
                            meshlet_base: st.base[4] + first,
                            meshlets: n,
                            tri_base: st.base[1],
                            pos_base: st.base[2],
                            fac_base,
                            flags,
                            apex: st.base[2] + st.apex_base + pp.part as u32,
                            stat,
                        }),
                    });
                    first += n;
                }
            }
        }
    }

    /// Adds the counts the GPU left in the records (`words`, the slot's records buffer after
    /// the frame completed) to the lights' plans and stats and to `totals`. A region that
    /// overflowed (impossible with the worst-case sizing) is an error, never a silent cut.
    pub fn read_back(&self, words: &[u32], lights: &mut [LightFrame], totals: &mut Totals) -> Result<()> {
        if self.read_back.replace(true) {
            return Ok(());
        }
        // The exact list can never outgrow its room (each entry is one triangle of one job); a
        // count beyond it would mean entries were written out of bounds.
        let exact = words.get(rec::H_EXACT).copied().unwrap_or(0);
        if exact as u64 > self.exact_capacity {
            return Err(Error::Internal(format!(
                "compute silhouettes: the exact list overflowed ({exact} of {} triangles)",
                self.exact_capacity
            )));
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
            add_counts(lights, totals, m, [sides, dark, cap, edges], bytes, UsedIndexFormat::U16);
        }
        Ok(())
    }

    /// Adds the mesh draws' counters (`words`: the slot's counts buffer after the frame
    /// completed) to the lights' plans and stats and to `totals` (no index bytes: the mesh
    /// draws read none).
    pub fn read_back_mesh(&self, words: &[u32], lights: &mut [LightFrame], totals: &mut Totals) -> Result<()> {
        for m in &self.mesh_metas {
            let r = words.get(m.word..m.word + COUNT_WORDS).ok_or_else(|| Error::Internal("mesh counters short".into()))?;
            add_counts(lights, totals, m, [r[0] as u64, r[1] as u64, r[2] as u64, r[3] as u64], 0, UsedIndexFormat::None);
            (totals.mesh_meshlets, totals.mesh_workgroups) = (totals.mesh_meshlets + r[4] as u64, totals.mesh_workgroups + r[5] as u64);
        }
        Ok(())
    }
}

/// Adds one part's GPU counts (`[sides, dark cap, light cap, silhouette edges]`, and the
/// index bytes read) to its light's plan and stats and to `totals`.
fn add_counts(lights: &mut [LightFrame], totals: &mut Totals, m: &RecordMeta, counts: [u64; 4], bytes: u64, format: UsedIndexFormat) {
    let [sides, dark, cap, edges] = counts;
    {
        {
            let lf = &mut lights[m.light];
            let cs: &mut CasterStats = &mut lf.stats.casters[m.caster];
            cs.triangles.sides += sides;
            cs.triangles.dark_cap += dark;
            cs.triangles.light_cap += cap;
            cs.silhouette_edges += edges;
            cs.index_bytes += bytes;
            if format != UsedIndexFormat::None {
                cs.index_format = format;
            }
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
    }
}
