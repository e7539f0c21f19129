//! Plans kept across frames ([`PassSettings::keep`](super::PassSettings::keep)): for each
//! light–caster pair of the CPU-planned techniques ([`Technique::Volumes`](super::Technique)),
//! what depends only on the light and the caster (facing, possible silhouette, caps and their
//! index lists) stays in a buffer of its own until the light or the caster changes; every
//! frame redoes only what depends on the view (culling, each part's case, scissor, depth
//! bounds). Doom 3 kept its `idInteraction`s' shadow triangles the same way.
//!
//! **What a kept list is keyed by.** The case decides which lists are drawn (z-pass: sides
//! only; z-fail: sides and dark cap; z-fail with light cap: and the light cap), so a pair's
//! lists are kept per case vector (one case per caster part): the key is the light's
//! homogeneous position (or direction), the caster's id and pose (bumped by every
//! `set_transform` and `update_positions`), the method, the index format and the parts'
//! cases. Each frame therefore draws exactly the lists planning from scratch would emit (the
//! planner's output is a function of those inputs, never of the view otherwise); a pair
//! whose case changes is planned for its new case, and both lists stay kept. A light's range
//! and cone only cull: a spot light turning keeps its pairs.
//!
//! **What moves is not kept.** A pair whose light or caster moved since the previous frame
//! (the light of the same index in the previous frame's list; a caster whose pose changed) is
//! planned into the frame's stream, as without keeping, and kept once both stand still: a
//! moving light or character costs what it costs without keeping, and no buffer is made for
//! lists drawn once.
//!
//! **Memory.** Each kept pair has its own host-visible index buffer, written once when it is
//! planned (those are the frame's only bytes sent for it). Over
//! [`ShadowPassDesc::keep_budget_bytes`](super::ShadowPassDesc::keep_budget_bytes), the least
//! recently drawn pairs are evicted (never one the frame draws: a pair that does not fit is
//! drawn from the frame's stream instead, as without keeping). Kept lists of removed or moved
//! casters are dropped at the next `prepare`. An evicted buffer is released once every ring
//! slot has been prepared again, as the casters' buffers are.
//!
//! **Work.** A spatial index over the casters' bounds ([`grid`]) gives each bounded light the
//! casters its range may reach; the pairs to plan are planned on
//! [`ShadowPassDesc::plan_threads`](super::ShadowPassDesc::plan_threads) threads.

mod fx;
pub(crate) mod grid;
use fx::FxBuild;

use super::casters::{CasterId, CasterTable};
use super::desc::IndexFormat;
use super::device::PassDevice;
use super::draw::{Draw, DrawList};
use super::lists::{write_chunks, ChunkDraws};
use crate::error::Result;
use crate::geom::{Camera, Light, LightKind};
use crate::gpu::Buffer;
use crate::shadow::{self, Case, CasterPlan, LightContext, LightPlan, Method, PlanInput, PlanOptions, PlanScratch};
use ash::vk;
use glam::{Mat4, Vec3, Vec4};
use std::collections::HashMap;
use std::sync::Arc;
use std::time::Instant;

/// Below this many caster triangles to plan, a frame plans them on the calling thread:
/// starting and joining the planning threads costs more than planning fewer (the measurement,
/// `examples/frame_cost.rs vertex --motions lights`: docs/frame-cost/example.md, "The threads'
/// threshold").
const PARALLEL_MIN_TRIANGLES: usize = 1_500_000;

/// What a kept pair's lists are keyed by (see the module docs).
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
struct Key {
    /// The light's homogeneous position (w = 0: a direction), as bits.
    light: [u32; 4],
    caster: CasterId,
    pose: u64,
    method: Method,
    format: IndexFormat,
    cases: CasesKey,
}

/// The parts' cases of a key: two bits a part up to 32 parts (no allocation for a look-up),
/// else the list.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
enum CasesKey {
    Packed { parts: u8, bits: u64 },
    Long(Vec<Case>),
}

impl CasesKey {
    fn new(cases: &[Case]) -> CasesKey {
        if cases.len() > 32 {
            return CasesKey::Long(cases.to_vec());
        }
        let bits = cases.iter().enumerate().fold(0u64, |b, (i, c)| {
            let v = match c {
                Case::Culled => 0u64,
                Case::ZPass => 1,
                Case::ZFail => 2,
                Case::ZFailLightCap => 3,
            };
            b | v << (2 * i)
        });
        CasesKey::Packed { parts: cases.len() as u8, bits }
    }
}

/// One kept pair.
struct Entry {
    buffer: Buffer,
    /// The caster's plan without its index lists (which are in `buffer`).
    plan: CasterPlan,
    /// Shared with each frame that draws the pair ([`DrawList::Shared`]).
    draws: Arc<[Draw]>,
    index_bytes: u64,
    vertex_bytes: u64,
    fmt_used: super::stats::UsedIndexFormat,
    /// The frame that last drew it.
    last_used: u64,
}

impl Entry {
    fn bytes(&self) -> u64 {
        self.buffer.size
    }
}

/// Buffers waiting for the frames in flight that may draw them (bit `s`: slot `s` not yet
/// prepared again).
struct Grave {
    buffer: Buffer,
    mask: u64,
}

/// A frame's keeping, for its statistics.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct KeepStats {
    /// The frame was planned with keeping (else only `evictions` counts).
    pub active: bool,
    /// Pairs drawn from kept lists.
    pub pairs_kept: u64,
    /// Pairs planned this frame.
    pub pairs_replanned: u64,
    /// Bytes of kept lists resident after the frame.
    pub kept_bytes: u64,
    /// Kept pairs evicted this frame (over the budget, or their caster changed or went).
    pub evictions: u64,
    /// Bytes written into new kept buffers this frame.
    pub bytes_written: u64,
    /// Culling, cases and look-ups, ms.
    pub cull_ms: f64,
    /// Planning and writing the pairs planned this frame, ms (wall time over the threads).
    pub plan_ms: f64,
}

/// A light of a kept frame: its plan (the kept pairs' plans without index lists; only the
/// casters the light draws) and, per caster of the plan, the
/// draws of a kept pair (`None`: culled, or drawn from the stream).
pub(crate) struct KeptLight {
    pub plan: LightPlan,
    pub draws: Vec<Option<ChunkDraws>>,
    /// Casters culled for the light (beyond its range by the spatial index, or by the
    /// planner's tests): not in `plan`.
    pub omitted: u64,
}

/// The pass's kept plans.
#[derive(Default)]
pub(crate) struct Kept {
    entries: HashMap<Key, Entry, FxBuild>,
    bytes: u64,
    graves: Vec<Grave>,
    frame: u64,
    grid: grid::Grid,
    /// The casters the grid was built for, with their poses.
    grid_casters: Vec<(CasterId, u64)>,
    /// The previous frame's lights' keys, in its order.
    prev_lights: Vec<[u32; 4]>,
}

/// What one frame's keeping reads.
pub(crate) struct KeepInput<'a> {
    pub camera: &'a Camera,
    pub width: u32,
    pub height: u32,
    pub view_proj: Mat4,
    pub lights: &'a [Light],
    pub method: Method,
    pub format: IndexFormat,
    pub u8_ok: bool,
    pub no_culling: bool,
    pub budget: u64,
    pub threads: usize,
    /// Every ring slot's bit (evicted buffers wait for all of them).
    pub all_slots: u64,
}

/// One pair to plan this frame.
struct Miss {
    light: usize,
    caster: usize,
    key: Key,
    /// The parts' cases (the key holds them packed).
    cases: Vec<Case>,
    l_obj: Vec4,
    /// Neither the light nor the caster moved since the previous frame (a pair that moves is
    /// drawn from the stream: keeping it would cost a buffer used once).
    keep: bool,
}

/// A pair planned this frame: its plan, and its lists serialised from offset 0 (a pair to
/// keep).
struct Planned {
    plan: CasterPlan,
    lists: Option<(Vec<u8>, ChunkDraws)>,
}

impl Kept {
    /// Ring slot `slot` is being prepared: frees what waited only for its previous frame.
    pub fn slot_retired(&mut self, dev: &PassDevice, slot: usize) {
        let bit = 1u64 << slot;
        for g in &mut self.graves {
            g.mask &= !bit;
        }
        let (done, keep): (Vec<Grave>, Vec<Grave>) = std::mem::take(&mut self.graves).into_iter().partition(|g| g.mask == 0);
        self.graves = keep;
        for mut g in done {
            g.buffer.destroy(dev);
        }
    }

    /// Bytes of kept lists resident now.
    pub fn bytes(&self) -> u64 {
        self.bytes
    }

    fn bury(&mut self, e: Entry, mask: u64) {
        self.bytes -= e.bytes();
        self.graves.push(Grave { buffer: e.buffer, mask });
    }

    /// Drops every kept pair (settings that keep nothing; the buffers wait for the slots).
    pub fn clear(&mut self, all_slots: u64) -> u64 {
        let n = self.entries.len() as u64;
        for (_, e) in std::mem::take(&mut self.entries) {
            self.bury(e, all_slots);
        }
        n
    }

    /// Frees everything (the host guarantees the device no longer uses any of it).
    pub fn destroy(&mut self, dev: &PassDevice) {
        for (_, mut e) in self.entries.drain() {
            e.buffer.destroy(dev);
        }
        for mut g in self.graves.drain(..) {
            g.buffer.destroy(dev);
        }
        self.bytes = 0;
    }

    /// Drops the kept pairs of casters removed or changed since the last frame, and keeps the
    /// spatial index up to date. Returns the pairs dropped, and per caster whether it moved
    /// since the last frame.
    fn follow_casters(&mut self, table: &CasterTable, all_slots: u64) -> (u64, Vec<bool>) {
        let now: Vec<(CasterId, u64)> = table.live.iter().map(|g| (g.id, g.pose)).collect();
        let mut evicted = 0;
        let mut moved = vec![false; now.len()];
        if now != self.grid_casters {
            let before: HashMap<CasterId, u64> = self.grid_casters.iter().copied().collect();
            for (m, (id, pose)) in moved.iter_mut().zip(&now) {
                *m = before.get(id).is_some_and(|p| p != pose);
            }
            let live: HashMap<CasterId, u64> = now.iter().copied().collect();
            let stale: Vec<Key> = self.entries.keys().filter(|k| live.get(&k.caster) != Some(&k.pose)).cloned().collect();
            for k in stale {
                if let Some(e) = self.entries.remove(&k) {
                    self.bury(e, all_slots);
                    evicted += 1;
                }
            }
            let same_set = now.len() == self.grid_casters.len() && now.iter().zip(&self.grid_casters).all(|(a, b)| a.0 == b.0);
            if same_set && self.grid.built_for(now.len()) {
                for (i, (a, b)) in now.iter().zip(&self.grid_casters).enumerate() {
                    if a.1 != b.1 {
                        self.grid.update(i, &table.cpu[i].world_bounds());
                    }
                }
            } else {
                let bounds: Vec<_> = table.cpu.iter().map(|c| c.world_bounds()).collect();
                self.grid.rebuild(&bounds);
            }
            self.grid_casters = now;
        } else if !self.grid.built_for(now.len()) {
            let bounds: Vec<_> = table.cpu.iter().map(|c| c.world_bounds()).collect();
            self.grid.rebuild(&bounds);
        }
        (evicted, moved)
    }

    /// Evicts the least recently drawn pairs not drawn by this frame until `need` more bytes
    /// fit in `budget`; whether they fit.
    fn make_room(&mut self, need: u64, budget: u64, all_slots: u64, evicted: &mut u64) -> bool {
        if self.bytes + need <= budget {
            return true;
        }
        let mut old: Vec<(u64, Key)> =
            self.entries.iter().filter(|(_, e)| e.last_used < self.frame).map(|(k, e)| (e.last_used, k.clone())).collect();
        old.sort_by_key(|(t, _)| *t);
        for (_, k) in old {
            if self.bytes + need <= budget {
                break;
            }
            if let Some(e) = self.entries.remove(&k) {
                self.bury(e, all_slots);
                *evicted += 1;
            }
        }
        self.bytes + need <= budget
    }

    /// Plans every light of a frame, drawing each pair from its kept lists where the light,
    /// the caster and the case allow, planning (in parallel) and keeping the others.
    pub fn plan_frame(&mut self, dev: &PassDevice, table: &CasterTable, input: &KeepInput) -> Result<(Vec<KeptLight>, KeepStats)> {
        let t0 = Instant::now();
        self.frame += 1;
        let (evictions, caster_moved) = self.follow_casters(table, input.all_slots);
        let mut stats = KeepStats { active: true, evictions, ..KeepStats::default() };
        let light_keys: Vec<[u32; 4]> = input.lights.iter().map(|l| l.homogeneous().to_array().map(f32::to_bits)).collect();
        let opts = PlanOptions { edge_quads: false, case_per_part: true, gpu_silhouettes: false, no_culling: input.no_culling };
        let Matched { mut lights, misses, pending } = self.match_pairs(table, input, &opts, (&light_keys, &caster_moved), &mut stats);
        stats.cull_ms = t0.elapsed().as_secs_f64() * 1e3;

        // Plan the pairs that need it, on every thread allowed.
        let t1 = Instant::now();
        let planned = plan_misses(table, input, &opts, &misses);
        stats.pairs_replanned = pending.len() as u64;
        // Keep them (or, past the budget, draw them from the stream as planning from scratch
        // would), then hand each light its plans.
        let (plans, kept) = self.keep_planned(dev, input, misses, planned, &mut stats)?;
        distribute(&mut lights, pending, plans, kept);
        stats.plan_ms = t1.elapsed().as_secs_f64() * 1e3;
        stats.kept_bytes = self.bytes;
        self.prev_lights = light_keys;
        Ok((lights, stats))
    }

    /// Culls every light's casters (through the grid for a bounded light) and takes each
    /// drawn pair's plan from what is kept, or records it as a miss to plan.
    fn match_pairs(
        &mut self,
        table: &CasterTable,
        input: &KeepInput,
        opts: &PlanOptions,
        (light_keys, caster_moved): (&[[u32; 4]], &[bool]),
        stats: &mut KeepStats,
    ) -> Matched {
        let bounds: Vec<crate::geom::Aabb> = table.cpu.iter().map(|c| c.world_bounds()).collect();
        let mut cases: Vec<Case> = Vec::new();
        let n = table.cpu.len();
        let mut candidates: Vec<u32> = Vec::new();
        let all: Vec<u32> = (0..n as u32).collect();
        let mut lights: Vec<KeptLight> = Vec::with_capacity(input.lights.len());
        let mut misses: Vec<Miss> = Vec::new();
        // the first miss of each key this frame (two equal lights plan a pair once)
        let mut first_miss: HashMap<Key, usize, FxBuild> = HashMap::default();
        // per light and caster: the miss index of a pair planned this frame
        let mut pending: Vec<(usize, usize, usize)> = Vec::new();
        for (li, light) in input.lights.iter().enumerate() {
            let pi = PlanInput {
                camera: input.camera,
                width: input.width,
                height: input.height,
                view_proj: input.view_proj,
                light,
                method: input.method,
            };
            let ctx = LightContext::new(&pi);
            let reach = match (light.kind, light.radius, input.no_culling) {
                (LightKind::Directional, _, _) | (_, None, _) | (_, _, true) => None,
                (_, Some(r), false) => Some((light.position - Vec3::splat(r), light.position + Vec3::splat(r))),
            };
            // the casters in the light's range (ascending: draw order), or every caster
            let some = self.grid.query_into(reach, &mut candidates);
            let omitted_unvisited = if some { (n - candidates.len()) as u64 } else { 0 };
            let visit: &[u32] = if some { &candidates } else { &all };
            let light_bits = light_keys[li];
            // moved since the previous frame (the light of the same index): not kept until it stands still
            let light_moved = self.prev_lights.get(li).is_some_and(|p| *p != light_bits);
            let mut casters = Vec::new();
            let mut draws: Vec<Option<ChunkDraws>> = Vec::new();
            // beyond the light's range: culled, not even visited, left out of the light's lists
            let mut omitted = omitted_unvisited;
            for &ci in visit {
                let (ci, caster) = (ci as usize, &table.cpu[ci as usize]);
                if !ctx.caster_cases_into(&pi, opts, caster, bounds[ci], &mut cases) {
                    // culled (range, cone or view): left out too
                    omitted += 1;
                    continue;
                }
                let g = &table.live[ci];
                let key = Key {
                    light: light_bits,
                    caster: g.id,
                    pose: g.pose,
                    method: input.method,
                    format: input.format,
                    cases: CasesKey::new(&cases),
                };
                match self.entries.get_mut(&key) {
                    Some(e) => {
                        e.last_used = self.frame;
                        let mut plan = e.plan.clone();
                        plan.caster = ci;
                        casters.push(plan);
                        draws.push(Some(ChunkDraws {
                            draws: DrawList::Shared(e.draws.clone()),
                            index_bytes: e.index_bytes,
                            vertex_bytes: e.vertex_bytes,
                            fmt_used: e.fmt_used,
                        }));
                        stats.pairs_kept += 1;
                    }
                    None => {
                        let l_obj = shadow::avoid_vertex(caster, shadow::object_light(caster, ctx.light_h()));
                        let m = *first_miss.entry(key.clone()).or_insert_with(|| {
                            misses.push(Miss {
                                light: li,
                                caster: ci,
                                key,
                                cases: cases.clone(),
                                l_obj,
                                keep: !light_moved && !caster_moved[ci],
                            });
                            misses.len() - 1
                        });
                        pending.push((li, casters.len(), m));
                        casters.push(shadow::culled_caster_plan(ci, caster, l_obj));
                        draws.push(None);
                    }
                }
            }
            let (scissor, depth_bounds) = ctx.screen_bounds(&pi);
            lights.push(KeptLight { plan: LightPlan { scissor, depth_bounds, casters, silhouette_ms: 0.0, plan_ms: 0.0 }, draws, omitted });
        }
        Matched { lights, misses, pending }
    }

    /// Keeps each planned pair's lists in a buffer of its own, within the budget; the plans
    /// and, for the pairs kept, their draws from the kept buffer.
    fn keep_planned(
        &mut self,
        dev: &PassDevice,
        input: &KeepInput,
        misses: Vec<Miss>,
        planned: Vec<Planned>,
        stats: &mut KeepStats,
    ) -> Result<(Vec<CasterPlan>, Vec<Option<ChunkDraws>>)> {
        let mut kept: Vec<Option<ChunkDraws>> = Vec::with_capacity(planned.len());
        let mut plans: Vec<CasterPlan> = Vec::with_capacity(planned.len());
        for (m, p) in misses.into_iter().zip(planned) {
            let Planned { mut plan, lists } = p;
            let Some((bytes, mut draws)) = lists else {
                kept.push(None);
                plans.push(plan);
                continue;
            };
            let size = (bytes.len() as u64).max(16);
            if !self.make_room(size, input.budget, input.all_slots, &mut stats.evictions) {
                kept.push(None);
                plans.push(plan);
                continue;
            }
            let mut buffer = Buffer::new(
                dev,
                "kept shadow lists",
                size,
                vk::BufferUsageFlags::INDEX_BUFFER | vk::BufferUsageFlags::VERTEX_BUFFER,
                gpu_allocator::MemoryLocation::CpuToGpu,
            )?;
            if let Err(e) = buffer.write(0, &bytes) {
                buffer.destroy(dev);
                return Err(e);
            }
            stats.bytes_written += bytes.len() as u64;
            for d in draws.draws.to_mut() {
                d.kept = Some(buffer.raw);
            }
            let shared: Arc<[Draw]> = Arc::from(&draws.draws[..]);
            plan.chunks.clear();
            plans.push(plan.clone());
            kept.push(Some(ChunkDraws { draws: DrawList::Shared(shared.clone()), ..draws }));
            self.bytes += buffer.size;
            let e = Entry {
                buffer,
                plan,
                draws: shared,
                index_bytes: draws.index_bytes,
                vertex_bytes: draws.vertex_bytes,
                fmt_used: draws.fmt_used,
                last_used: self.frame,
            };
            self.entries.insert(m.key, e);
        }
        Ok((plans, kept))
    }
}

/// What [`Kept::match_pairs`] found: each light's plans (the missed pairs' culled
/// placeholders), the pairs to plan, and where each missed pair goes (light, position in its
/// lists, miss).
struct Matched {
    lights: Vec<KeptLight>,
    misses: Vec<Miss>,
    pending: Vec<(usize, usize, usize)>,
}

/// Plans the missed pairs, on up to `input.threads` threads above
/// [`PARALLEL_MIN_TRIANGLES`] (contiguous runs of about equal triangle counts, one a thread).
fn plan_misses(table: &CasterTable, input: &KeepInput, opts: &PlanOptions, misses: &[Miss]) -> Vec<Planned> {
    let handles: Vec<Vec<vk::Buffer>> = table.live.iter().map(|g| g.chunks.iter().map(|b| b.raw).collect()).collect();
    let job = |m: &Miss, scratch: &mut PlanScratch| -> Planned {
        let pi = PlanInput {
            camera: input.camera,
            width: input.width,
            height: input.height,
            view_proj: input.view_proj,
            light: &input.lights[m.light],
            method: input.method,
        };
        let caster = &table.cpu[m.caster];
        let plan = shadow::plan_caster(&pi, opts, (m.caster, caster), m.l_obj, &m.cases, scratch);
        // (a pair that moves goes to the stream: `pack` writes it there)
        let lists = m.keep.then(|| {
            let mut bytes = Vec::new();
            let draws = write_chunks(&mut bytes, (input.format, input.u8_ok), caster, &handles[m.caster], &plan);
            (bytes, draws)
        });
        Planned { plan, lists }
    };
    let threads = input.threads.max(1).min(misses.len().max(1));
    let work: Vec<usize> = misses.iter().map(|m| table.cpu[m.caster].triangle_count.max(1)).collect();
    let total: usize = work.iter().sum();
    if threads <= 1 || total < PARALLEL_MIN_TRIANGLES {
        let mut scratch = PlanScratch::default();
        misses.iter().map(|m| job(m, &mut scratch)).collect()
    } else {
        // contiguous runs of about equal triangle counts, one a thread
        let mut parts: Vec<&[Miss]> = Vec::with_capacity(threads);
        let (mut start, mut acc) = (0, 0);
        for (i, w) in work.iter().enumerate() {
            acc += w;
            if acc * threads >= total * (parts.len() + 1) && parts.len() + 1 < threads {
                parts.push(&misses[start..=i]);
                start = i + 1;
            }
        }
        parts.push(&misses[start..]);
        std::thread::scope(|s| {
            let workers: Vec<_> = parts
                .into_iter()
                .map(|part| {
                    let job = &job;
                    s.spawn(move || {
                        let mut scratch = PlanScratch::default();
                        part.iter().map(|m| job(m, &mut scratch)).collect::<Vec<_>>()
                    })
                })
                .collect();
            workers.into_iter().flat_map(|w| w.join().unwrap_or_else(|p| std::panic::resume_unwind(p))).collect()
        })
    }
}

/// Puts each planned pair's plan and draws in the lists of every light that drew it (a plan
/// drawn by one light is moved, not copied: its index lists may be long).
fn distribute(lights: &mut [KeptLight], pending: Vec<(usize, usize, usize)>, plans: Vec<CasterPlan>, mut kept: Vec<Option<ChunkDraws>>) {
    let mut uses = vec![0usize; plans.len()];
    for &(_, _, m) in &pending {
        uses[m] += 1;
    }
    let mut plans: Vec<Option<CasterPlan>> = plans.into_iter().map(Some).collect();
    for (li, k, m) in pending {
        let l = &mut lights[li];
        uses[m] -= 1;
        let mut plan = match uses[m] {
            0 => plans[m].take().unwrap_or_else(|| l.plan.casters[k].clone()),
            _ => plans[m].clone().unwrap_or_else(|| l.plan.casters[k].clone()),
        };
        plan.caster = l.plan.casters[k].caster;
        l.plan.casters[k] = plan;
        l.draws[k] = if uses[m] == 0 { kept[m].take() } else { kept[m].clone() };
    }
}
