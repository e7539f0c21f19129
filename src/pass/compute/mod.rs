//! GPU possible silhouettes ([`Technique::Compute`](super::Technique::Compute)): the static
//! per-caster tables the compute pass reads (in one pass-wide [`arena`]), its pipelines, and
//! the per-slot buffers it writes.
//!
//! Per caster, uploaded once (and again only when a deforming caster moves its vertices),
//! every triangle table in the planes' scan order ([`FacePlanes::order`]: slot `s` holds
//! triangle `order().triangle(s)`, 64 consecutive slots a compact patch of the surface; the
//! facing bits are by slot):
//! * the object-space f32 plane of every slot ([`FacePlanes::planes_xyzd`]'s planes, by slot),
//!   the filter of the CPU's facing test, and per 64-slot block the bound that decides the
//!   whole block with one test (`geom::planes::gpu`);
//! * per slot its triangle's three welded vertex ids, chunk-local corners and chunk, and the
//!   welded positions: the exact fallback of the facing test and the indices the caps are made
//!   of;
//! * the edge table: every edge of the closed manifold parts, `(s0, s1, c0 | c1 << 8, pa | pb
//!   << 8)`, filed by the pair of blocks its two slots lie in ([`tables::WordPairs`]).
//!
//! Per frame the CPU writes one job per (light, caster) pair ([`work::GpuJob`]: the light,
//! the arena offsets, the first invocation or workgroup of the pair in each stage) and one
//! small record per chunk (`RECORD_WORDS` words: the chunk's two
//! `VkDrawIndexedIndirectCommand`s, with zero counts and the first index of the chunk's
//! region, its case parameters and its capacities); the shader (`shaders/silhouette.wgsl`)
//! does the rest, in four dispatches per frame whatever the number of casters and lights. See
//! [`frame`] for the layout and [`record`] for the commands and barriers. Everything observable
//! (plans, stats, the chunks' indices) keeps the caller's triangle order: the shader writes
//! each triangle's chunk-local corners, and the counts do not depend on the order.
//!
//! Facing is bit for bit the CPU's ([`FacePlanes::facing_packed`]): a block decided whole only
//! where its bound proves every slot's plane value beyond the filter's error bound (f32
//! evaluation included), else the same f32 plane filter with the CPU's error bound (Vulkan's
//! f32 add and multiply are correctly rounded, and the bound covers flushed denormals), and
//! where it cannot decide, the exact sign of orient3d of the f32 vertices, summed without
//! rounding in a fixed-point accumulator. So the GPU's triangle counts equal the CPU planner's
//! for the same light and caster.

pub(crate) mod arena;
pub(crate) mod draw_pipes;
pub(crate) mod draws;
pub(crate) mod draws_record;
mod prepare;
pub(crate) mod record;
pub(crate) mod tables;
pub(crate) mod work;

/// Most workgroups of one dispatch dimension (every device has at least this many).
pub(crate) const MAX_GROUPS: u32 = 65535;

use super::device::PassDevice;
use crate::error::{Error, Result};
use crate::gpu::descriptors::{pipeline_layout, storage_set_layout};
use crate::gpu::{pipeline, shaders, Buffer, GpuDevice};
use crate::shadow::meshlet::Meshlets;
use crate::shadow::{Caster, CasterKind};
use ash::vk;
use bytemuck::{Pod, Zeroable};
use gpu_allocator::MemoryLocation;

/// Triangles of one job a workgroup of the `caps` stage (`GROUP` in
/// `shaders/silhouette.wgsl`).
pub(crate) const GROUP: u32 = 256;
/// Invocations a workgroup of the `facing` (a 64-slot block each) and `find` (a word-pair
/// group each) stages (`LANES` in `shaders/silhouette.wgsl`).
pub(crate) const LANES: u32 = 64;
/// Words of one chunk record (see `shaders/silhouette.wgsl`).
pub(crate) const RECORD_WORDS: usize = 20;
/// Words of the frame's header at the start of the records: the exact list's length and its
/// `VkDispatchIndirectCommand` (the rest unused).
pub(crate) const HEADER_WORDS: usize = 16;
/// Record word offsets.
pub(crate) mod rec {
    /// Header: the exact list's length, then its dispatch command (x, y, z).
    pub const H_EXACT: usize = 0;
    pub const H_EXACT_X: usize = 1;
    pub const VOL_COUNT: usize = 0;
    pub const VOL_INSTANCES: usize = 1;
    pub const VOL_FIRST: usize = 2;
    pub const CAP_COUNT: usize = 5;
    pub const CAP_INSTANCES: usize = 6;
    pub const CAP_FIRST: usize = 7;
    pub const SIDES: usize = 10;
    pub const DARK: usize = 11;
    pub const EDGES: usize = 12;
    pub const FLAGS: usize = 13;
    pub const N: usize = 14;
    pub const VOL_CAP: usize = 15;
    pub const CAP_CAP: usize = 16;
    pub const OVERFLOW: usize = 17;
    /// The volume and light-cap commands' `vertexOffset` and `firstInstance` (written by the
    /// CPU for the merged draws: the chunk's first vertex in the arena, the pair's transform).
    pub const VOL_VERTEX_OFFSET: usize = 3;
    pub const VOL_FIRST_INSTANCE: usize = 4;
    pub const CAP_VERTEX_OFFSET: usize = 8;
    pub const CAP_FIRST_INSTANCE: usize = 9;
    /// The merged draws' lists the two commands go to (`shaders/compact_draws.wgsl`): the
    /// word offset of the list's count, or [`NO_LIST`].
    pub const VOL_LIST: usize = 18;
    pub const CAP_LIST: usize = 19;
    pub const NO_LIST: u32 = u32::MAX;
    pub const F_ENABLED: u32 = 1;
    pub const F_BACK: u32 = 2;
    pub const F_DIRECTIONAL: u32 = 4;
    pub const F_LIGHT_CAP: u32 = 32;
    pub const DC_FAN: u32 = 1;
    pub const DC_FRONT: u32 = 2;
    pub const DC_BACK: u32 = 3;
}

/// The push-constant block of `shaders/silhouette.wgsl` (`struct Push`): one per frame.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub(crate) struct SilhouettePush {
    pub jobs: u32,
    /// Invocations of the `facing` stage (64-slot blocks) and of the `find` stage (word-pair
    /// groups), workgroups of the `caps` stage.
    pub blocks: u32,
    pub word_pairs: u32,
    pub cap_groups: u32,
    /// Steps of the shader's binary search over the jobs: ceil(log2(jobs)).
    pub steps: u32,
    pub pad: [u32; 3],
}

impl SilhouettePush {
    pub const SIZE: u32 = std::mem::size_of::<SilhouettePush>() as u32;
}

/// A caster's static tables for the compute pass, on the CPU.
#[derive(Clone, Debug, Default)]
pub(crate) struct ComputeMesh {
    /// Per slot of the scan order ([`FacePlanes::order`](crate::geom::planes::FacePlanes::order)),
    /// its triangle's `(nx, ny, nz, d)`.
    pub planes: Vec<[f32; 4]>,
    /// Per slot: its triangle's welded ids `g0 g1 g2 _`, local corners `l0 l1 l2 chunk`.
    pub tris: Vec<[u32; 8]>,
    /// Welded positions (w unused).
    pub positions: Vec<[f32; 4]>,
    /// Edges of the closed manifold parts: `(s0, s1, c0 | c1 << 8, pa | pb << 8)`, the slots
    /// of `t0` and `t1`, word-pair group after group ([`tables::WordPairs`]).
    pub edges: Vec<[u32; 4]>,
    /// Per 64 slots, the block bound of the `facing` stage (three `vec4<f32>` a block:
    /// `geom::planes::gpu::GpuBlock`).
    pub blocks: Vec<[f32; 4]>,
    /// The edges' word-pair groups `(a, b, first, count)` ([`tables::WordPairs`]).
    pub groups: Vec<[u32; 4]>,
    /// Per chunk: edges of the table with a triangle in the chunk (the side capacity).
    pub chunk_edges: Vec<u32>,
    /// Mesh-shader extrusion: the meshlets of the closed manifold parts
    /// ([`Meshlets`]), `(first triangle, triangles, first edge, edges)`, the firsts relative
    /// to the caster's ranges of the two tables below (made absolute when placed in the arena),
    /// then their culling bounds (`crate::pass::mesh::meshlet_rows`).
    pub meshlets: Vec<[u32; crate::pass::mesh::MESHLET_WORDS]>,
    /// The meshlets' triangles (their slots in the scan order, as the facing bits have them).
    pub meshlet_tris: Vec<u32>,
    /// The meshlets' owned edges, `(s0, s1, c0 | c1 << 8, 0)` (the slots of `t0` and `t1`).
    pub meshlet_edges: Vec<[u32; 4]>,
    /// Per part, its meshlets (relative to the caster's first).
    pub part_meshlets: Vec<std::ops::Range<u32>>,
    /// The index of part 0's apex in `positions` (part `p`'s is `apex_base + p`): the welded
    /// positions come first.
    pub apex_base: u32,
    /// Every chunk's dual-length vertices (n with w = 1, then n with w = 0), chunk after chunk:
    /// the merged volume draws' vertex arena.
    pub vertices: Vec<[f32; 4]>,
    /// Per chunk, its first vertex in `vertices`.
    pub chunk_vertices: Vec<u32>,
}

/// The dual-length vertex data of a chunk: every vertex with w = 1, then again with w = 0.
pub(crate) fn dual_length(vertices: &[glam::Vec3]) -> Vec<[f32; 4]> {
    let mut data: Vec<[f32; 4]> = Vec::with_capacity(vertices.len() * 2);
    data.extend(vertices.iter().map(|v| [v.x, v.y, v.z, 1.0]));
    data.extend(vertices.iter().map(|v| [v.x, v.y, v.z, 0.0]));
    data
}

impl ComputeMesh {
    /// The tables of `caster` (every triangle; the edges of its closed manifold parts only:
    /// the others keep the CPU's multiplicity path).
    pub fn new(caster: &Caster) -> ComputeMesh {
        let mesh = caster.mesh();
        // Every triangle table in the planes' scan order (slot s holds triangle
        // order.triangle(s)): the facing bits, blocks and word pairs follow the terminator.
        let order = caster.planes.order();
        let slot = |t: u32| order.slot(t);
        let planes = caster.planes.planes_scan();
        let blocks = caster
            .planes
            .gpu_blocks(mesh)
            .iter()
            .flat_map(|b| [[b[0], b[1], b[2], b[3]], [b[4], b[5], b[6], b[7]], [b[8], b[9], b[10], b[11]]])
            .collect();
        let tris = (0..mesh.triangles.len() as u32)
            .map(|s| {
                let t = order.triangle(s) as usize;
                let (tri, (ci, li)) = (mesh.triangles[t], caster.tri_chunk[t]);
                let l = caster.chunks[ci as usize].local_tris[li as usize];
                [tri[0], tri[1], tri[2], 0, l[0] as u32, l[1] as u32, l[2] as u32, ci]
            })
            .collect();
        let mut positions: Vec<[f32; 4]> = mesh.positions.iter().map(|p| [p.x, p.y, p.z, 1.0]).collect();
        // Each part's apex (the fan dark cap's common vertex: the last vertex of each of the
        // part's chunks, the same f32 values), after the welded positions.
        let apex_base = positions.len() as u32;
        positions.extend(caster.parts.iter().map(|p| {
            let a = p.chunks.clone().next().and_then(|c| caster.chunks[c].vertices.last().copied()).unwrap_or(p.object_bounds.center());
            [a.x, a.y, a.z, 1.0]
        }));
        let mut edges = Vec::new();
        let mut chunk_edges = vec![0u32; caster.chunks.len()];
        let whole_multiplicity = caster.kind != CasterKind::Manifold && caster.parts.len() == 1;
        for part in caster.parts.iter().filter(|p| p.kind == CasterKind::Manifold && !whole_multiplicity) {
            for e in part.scan.edges() {
                edges.push((slot(e.t0), slot(e.t1), e.c0 as u32 | (e.c1 as u32) << 8));
                let (c0, c1) = (caster.tri_chunk[e.t0 as usize].0, caster.tri_chunk[e.t1 as usize].0);
                chunk_edges[c0 as usize] += 1;
                if c1 != c0 {
                    chunk_edges[c1 as usize] += 1;
                }
            }
        }
        let tables::WordPairs { edges, groups } = tables::word_pairs(edges);
        let mut vertices = Vec::new();
        let mut chunk_vertices = Vec::with_capacity(caster.chunks.len());
        for ch in &caster.chunks {
            chunk_vertices.push(vertices.len() as u32);
            vertices.extend(dual_length(&ch.vertices));
        }
        let ml = Meshlets::build(caster);
        let meshlets = crate::pass::mesh::meshlet_rows(&ml);
        let meshlet_edges = ml.edges.iter().map(|e| [slot(e.t0), slot(e.t1), e.c0 as u32 | (e.c1 as u32) << 8, 0]).collect();
        ComputeMesh {
            planes,
            tris,
            positions,
            edges,
            blocks,
            groups,
            chunk_edges,
            meshlets,
            meshlet_tris: ml.triangles.iter().map(|&t| slot(t)).collect(),
            meshlet_edges,
            part_meshlets: ml.parts,
            apex_base,
            vertices,
            chunk_vertices,
        }
    }

    /// The bytes of each arena table, placed at `base` (the meshlets' firsts made absolute).
    pub fn table_bytes(&self, base: &[u32; arena::N]) -> [std::borrow::Cow<'_, [u8]>; arena::N] {
        use std::borrow::Cow;
        let meshlets: Vec<[u32; crate::pass::mesh::MESHLET_WORDS]> =
            self.meshlets.iter().map(|&row| crate::pass::mesh::placed(row, base[5], base[6])).collect();
        [
            Cow::Borrowed(bytemuck::cast_slice(&self.planes)),
            Cow::Borrowed(bytemuck::cast_slice(&self.tris)),
            Cow::Borrowed(bytemuck::cast_slice(&self.positions)),
            Cow::Borrowed(bytemuck::cast_slice(&self.edges)),
            Cow::Owned(bytemuck::cast_slice(&meshlets).to_vec()),
            Cow::Borrowed(bytemuck::cast_slice(&self.meshlet_tris)),
            Cow::Borrowed(bytemuck::cast_slice(&self.meshlet_edges)),
            Cow::Borrowed(bytemuck::cast_slice(&self.vertices)),
            Cow::Borrowed(bytemuck::cast_slice(&self.blocks)),
            Cow::Borrowed(bytemuck::cast_slice(&self.groups)),
        ]
    }

    /// Where the tables of `caster` are once placed at `base` (`elements` each).
    pub fn placed(self, caster: &Caster, base: [u32; arena::N], elements: [u64; arena::N]) -> ComputeStatic {
        ComputeStatic {
            base,
            elements,
            triangles: self.tris.len() as u32,
            edge_count: self.edges.len() as u32,
            group_count: self.groups.len() as u32,
            chunk_edges: self.chunk_edges,
            chunk_tris: caster.chunks.iter().map(|ch| ch.local_tris.len() as u32).collect(),
            part_meshlets: self.part_meshlets,
            apex_base: self.apex_base,
            chunk_vertex_base: self.chunk_vertices.iter().map(|&v| v + base[arena::VERTICES]).collect(),
        }
    }
}

/// Where a caster's static tables are in the pass's [`arena::ComputeArena`].
#[derive(Clone, Debug)]
pub(crate) struct ComputeStatic {
    /// The first element of its range in each table ([`arena::TABLES`]).
    pub base: [u32; arena::N],
    /// Elements of its range in each table.
    pub elements: [u64; arena::N],
    pub triangles: u32,
    pub edge_count: u32,
    /// Word-pair groups of its edges ([`tables::WordPairs`]).
    pub group_count: u32,
    pub chunk_edges: Vec<u32>,
    /// Triangles per chunk.
    pub chunk_tris: Vec<u32>,
    /// Per part, its meshlets (relative to `base[4]`).
    pub part_meshlets: Vec<std::ops::Range<u32>>,
    /// Part `p`'s apex is position `apex_base + p` (relative to `base[2]`).
    pub apex_base: u32,
    /// Per chunk, its first vertex in the arena's vertex table (absolute: the merged draws'
    /// `vertexOffset`).
    pub chunk_vertex_base: Vec<u32>,
}

/// The compute pipelines (one per stage: facing bits, exact facing, silhouette edges with
/// their sides, face caps) and their layout.
pub(crate) struct ComputePipes {
    pub set_layout: vk::DescriptorSetLayout,
    pub layout: vk::PipelineLayout,
    /// In stage order: `facing`, `exact`, `find`, `caps`.
    pub stages: [vk::Pipeline; 4],
}

/// The entry points of `shaders/silhouette.wgsl`, in [`ComputePipes::stages`] order.
const ENTRIES: [&std::ffi::CStr; 4] = [c"facing", c"exact", c"find", c"caps"];

/// Storage-buffer bindings of the set: 0..4 the arena's tables, 4 the jobs, 5 facing bits,
/// 6 the header and chunk records, 7 the output indices, 8 the exact list,
/// 9 and 10 the arena's block bounds and word-pair groups.
pub(crate) const BINDINGS: u32 = 11;

impl ComputePipes {
    pub fn new(dev: &PassDevice) -> Result<ComputePipes> {
        let d = dev.device();
        // destroyed in `destroy` (or below on error)
        let set_layout = storage_set_layout(dev, BINDINGS, vk::ShaderStageFlags::COMPUTE)?;
        let mut me = ComputePipes { set_layout, layout: vk::PipelineLayout::null(), stages: [vk::Pipeline::null(); 4] };
        match me.create(dev) {
            Ok(()) => Ok(me),
            Err(e) => {
                // SAFETY: nothing created here was used yet.
                unsafe { me.destroy(d) };
                Err(e)
            }
        }
    }

    fn create(&mut self, dev: &PassDevice) -> Result<()> {
        self.layout = pipeline_layout(dev, &[self.set_layout], SilhouettePush::SIZE, vk::ShaderStageFlags::COMPUTE)?;
        let module = pipeline::shader_module(dev, shaders::SILHOUETTE_WGSL)?;
        let d = dev.device();
        let cache = dev.pipeline_cache();
        let make = |entry: &std::ffi::CStr| -> Result<vk::Pipeline> {
            let stage = vk::PipelineShaderStageCreateInfo::default().stage(vk::ShaderStageFlags::COMPUTE).module(module).name(entry);
            let info = [vk::ComputePipelineCreateInfo::default().stage(stage).layout(self.layout)];
            crate::gpu::creation::timed(
                || format!("silhouette.wgsl:{}", entry.to_string_lossy()),
                || {
                    // SAFETY: valid device, module and layout; the create info points at locals.
                    unsafe { d.create_compute_pipelines(cache, &info, None) }
                        .map(|p| p[0])
                        .map_err(|(_, e)| Error::vk("vkCreateComputePipelines")(e))
                },
            )
        };
        let mut r = Ok(());
        for (k, entry) in ENTRIES.iter().enumerate() {
            match make(entry) {
                Ok(p) => self.stages[k] = p,
                Err(e) => {
                    r = Err(e);
                    break;
                }
            }
        }
        // SAFETY: the pipelines keep what they need of the module.
        unsafe { d.destroy_shader_module(module, None) };
        r
    }

    /// # Safety
    /// No pending command buffer uses the pipelines.
    pub unsafe fn destroy(&mut self, d: &ash::Device) {
        // SAFETY: the caller's contract; null handles are ignored.
        unsafe {
            for p in self.stages {
                d.destroy_pipeline(p, None);
            }
            d.destroy_pipeline_layout(self.layout, None);
            d.destroy_descriptor_set_layout(self.set_layout, None);
        }
    }
}

/// The GPU possible silhouettes' state ([`Technique::Compute`](crate::pass::Technique::Compute)
/// and the facing stage of [`Technique::Mesh`](crate::pass::Technique::Mesh)): the compute
/// pipelines, the merged draws' pipelines (with `drawIndirectFirstInstance`), both made with
/// the first frame or `create_pipelines`, and each ring slot's buffers and descriptor sets.
pub(crate) struct ComputeState {
    pub pipes: Option<ComputePipes>,
    pub merged: Option<draw_pipes::DrawPipes>,
    pub slots: Vec<SlotCompute>,
}

impl ComputeState {
    /// Nothing made yet, for a ring of `slots` slots.
    pub fn new(slots: usize) -> ComputeState {
        ComputeState { pipes: None, merged: None, slots: (0..slots).map(|_| SlotCompute::default()).collect() }
    }
}

impl crate::pass::device::TechniqueState for ComputeState {
    fn destroy(&mut self, dev: &PassDevice) {
        if let Some(mut c) = self.pipes.take() {
            // SAFETY: the pass is dropped after every command buffer that used it completed.
            unsafe { c.destroy(&dev.device) };
        }
        if let Some(mut m) = self.merged.take() {
            // SAFETY: as above.
            unsafe { m.destroy(&dev.device) };
        }
        for s in &mut self.slots {
            s.destroy(dev);
        }
    }
}

/// One ring slot's buffers and descriptor set for the compute pass.
#[derive(Default)]
pub(crate) struct SlotCompute {
    /// The header and the chunk records of every light (host visible: written at prepare,
    /// read back for stats).
    pub records: Option<Buffer>,
    /// Output indices (u16, two a word), every light's regions.
    pub out: Option<Buffer>,
    /// Facing bits, two words per 64-slot block of each job.
    pub facing: Option<Buffer>,
    /// The frame's jobs (host visible).
    pub jobs: Option<Buffer>,
    /// The exact list (`(job, slot)` pairs).
    pub lists: Option<Buffer>,
    /// [`Technique::Mesh`](crate::pass::Technique::Mesh): the mesh draws' counters (host
    /// visible: read back for stats).
    pub counts: Option<Buffer>,
    /// The merged draws ([`draws`]): per (light, caster) pair its transform and light (host
    /// visible, per-instance vertex attributes), and the per-light lists of compacted commands.
    pub xforms: Option<Buffer>,
    pub draw_lists: Option<Buffer>,
    pub pool: vk::DescriptorPool,
    pub pool_sets: u32,
}

impl SlotCompute {
    /// Makes `b` at least `size` bytes (the next power of two, at least 64 KiB); its old
    /// contents are dropped (the slot's previous frame has retired).
    pub fn ensure(
        dev: &PassDevice,
        b: &mut Option<Buffer>,
        name: &str,
        size: u64,
        usage: vk::BufferUsageFlags,
        loc: MemoryLocation,
    ) -> Result<()> {
        if b.as_ref().is_some_and(|b| b.size >= size) {
            return Ok(());
        }
        if let Some(mut old) = b.take() {
            old.destroy(dev);
        }
        *b = Some(Buffer::new(dev, name, size.max(1 << 16).next_power_of_two(), usage, loc)?);
        Ok(())
    }

    /// A reset pool with room for `sets` sets (grown when short).
    pub fn reset_pool(&mut self, dev: &PassDevice, sets: u32) -> Result<()> {
        let d = dev.device();
        if self.pool_sets < sets || self.pool == vk::DescriptorPool::null() {
            let n = sets.max(8).next_power_of_two();
            // SAFETY: the slot's previous frame retired: its sets are no longer in use.
            unsafe {
                if self.pool != vk::DescriptorPool::null() {
                    d.destroy_descriptor_pool(self.pool, None);
                    self.pool = vk::DescriptorPool::null();
                }
                let sizes = [vk::DescriptorPoolSize { ty: vk::DescriptorType::STORAGE_BUFFER, descriptor_count: n * BINDINGS }];
                self.pool = d
                    .create_descriptor_pool(&vk::DescriptorPoolCreateInfo::default().max_sets(n).pool_sizes(&sizes), None)
                    .map_err(Error::vk("vkCreateDescriptorPool"))?;
            }
            self.pool_sets = n;
        } else {
            // SAFETY: as above.
            unsafe { d.reset_descriptor_pool(self.pool, vk::DescriptorPoolResetFlags::empty()) }
                .map_err(Error::vk("vkResetDescriptorPool"))?;
        }
        Ok(())
    }

    pub fn destroy(&mut self, dev: &PassDevice) {
        for b in [
            &mut self.records,
            &mut self.out,
            &mut self.facing,
            &mut self.jobs,
            &mut self.lists,
            &mut self.counts,
            &mut self.xforms,
            &mut self.draw_lists,
        ] {
            if let Some(mut b) = b.take() {
                b.destroy(dev);
            }
        }
        if self.pool != vk::DescriptorPool::null() {
            // SAFETY: the pass is dropped after its command buffers completed.
            unsafe { dev.device().destroy_descriptor_pool(self.pool, None) };
            self.pool = vk::DescriptorPool::null();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::testmesh::{cube, uv_sphere};
    use glam::{Mat4, Vec3};

    #[test]
    fn tables_cover_every_edge_and_triangle() {
        let c = Caster::with_chunk_limit("s", &uv_sphere(1.0, 24, 12), Mat4::IDENTITY, 60).unwrap();
        let m = ComputeMesh::new(&c);
        assert_eq!(m.tris.len(), c.triangle_count);
        assert_eq!(m.planes.len(), c.triangle_count);
        assert_eq!(m.edges.len(), c.topology.manifold_edges.len());
        assert!(c.chunks.len() > 2);
        // every edge counted once per chunk it touches
        let touching: u32 = m.chunk_edges.iter().sum();
        assert!(touching as usize >= m.edges.len() && (touching as usize) < 2 * m.edges.len());
        let order = c.planes.order();
        for (s, row) in m.tris.iter().enumerate() {
            let (ci, li) = c.tri_chunk[order.triangle(s as u32) as usize];
            assert_eq!(row[7], ci);
            let lt = c.chunks[ci as usize].local_tris[li as usize];
            assert_eq!([row[4], row[5], row[6]], lt.map(|x| x as u32));
        }
        // corners: the edge a -> b starts at corner c0 of t0 (the table holds their slots)
        for e in &m.edges {
            let (t0, c0) = (order.triangle(e[0]) as usize, (e[2] & 0xff) as usize);
            let (t1, c1) = (order.triangle(e[1]) as usize, (e[2] >> 8) as usize);
            let (a, b) = (c.mesh().triangles[t0][c0], c.mesh().triangles[t0][(c0 + 1) % 3]);
            assert_eq!((c.mesh().triangles[t1][c1], c.mesh().triangles[t1][(c1 + 1) % 3]), (b, a));
        }
        // an open mesh has no compute edges
        let mut open = cube(Vec3::ZERO, 1.0);
        open.triangles.pop();
        let oc = Caster::new("open", &open, Mat4::IDENTITY).unwrap();
        assert!(ComputeMesh::new(&oc).edges.is_empty());
    }

    #[test]
    fn push_and_job_match_the_wgsl_blocks() {
        use super::work::GpuJob;
        assert_eq!(SilhouettePush::SIZE, 32);
        assert_eq!(std::mem::offset_of!(SilhouettePush, steps), 16);
        assert_eq!(std::mem::size_of::<GpuJob>(), 96);
        assert_eq!(std::mem::offset_of!(GpuJob, bound), 32);
        assert_eq!(std::mem::offset_of!(GpuJob, plane_base), 48);
        assert_eq!(std::mem::offset_of!(GpuJob, rec_base), 64);
        assert_eq!(std::mem::offset_of!(GpuJob, g_facing), 72);
        assert_eq!(std::mem::offset_of!(GpuJob, g_caps), 80);
        assert_eq!(std::mem::offset_of!(GpuJob, block_base), 84);
        assert_eq!(std::mem::offset_of!(GpuJob, groups), 92);
    }
}
