//! The pass's casters: CPU preparation (welding, topology, chunks), their GPU-resident
//! dual-length vertex buffers, uploads recorded into the host's command buffer, and deferred
//! release once every frame in flight that could use a buffer has retired.

use super::compute::arena::{add_elements, mesh_elements, ComputeArena, ELEMENT_BYTES, TABLES};
use super::compute::{dual_length, ComputeMesh, ComputeStatic};
use super::device::PassDevice;
use crate::error::{Error, Result};
use crate::geom::Mesh;
use crate::gpu::Buffer;
use crate::shadow::{Caster, CasterKind};
use ash::vk;
use glam::{DMat4, Vec3};
use gpu_allocator::MemoryLocation;

/// A caster added to a [`ShadowPass`](super::ShadowPass). Ids are never reused: an id of a
/// removed caster is refused with an error, never confused with a newer caster.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct CasterId {
    /// The pass that made it (`ShadowPass`'s process-unique id).
    pub(crate) pass: u64,
    pub(crate) index: u32,
    pub(crate) generation: u32,
}

/// A copy from a staging buffer into a device-local buffer, recorded by `cmd_upload`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Upload {
    pub src: vk::Buffer,
    pub dst: vk::Buffer,
    /// Where in `dst` the bytes go.
    pub dst_offset: u64,
    pub size: u64,
}

/// A copy not yet known to have reached the GPU. It belongs to the pass, not to a frame: every
/// frame carries every pending upload until a frame that recorded it has retired (its slot
/// prepared again, the host not having abandoned it), so a frame dropped unrecorded, or recorded
/// and never submitted, loses nothing. Copying again is harmless: the bytes are the same.
pub(crate) struct PendingUpload {
    pub staging: Buffer,
    pub up: Upload,
    /// Bit `s`: the frame last prepared on ring slot `s` carries it (and may copy from
    /// `staging` until that slot is prepared again).
    pub carried: u64,
}

/// A caster's static edge-quad geometry (u32 indices: faces first, then quads).
pub(crate) struct EdgeQuadGpu {
    pub vertices: Buffer,
    pub indices: Buffer,
    pub face_indices: u32,
    pub quad_indices: u32,
}

/// One live caster.
pub(crate) struct GpuCaster {
    pub id: CasterId,
    /// Object -> world, f64 (composed with the view in f64 every frame).
    pub transform: DMat4,
    /// Connected shells (for the 8-bit stencil overflow warning).
    pub shells: usize,
    /// Per chunk, its dual-length vertex buffer (n x (xyz,1) then n x (xyz,0)), device local.
    pub chunks: Vec<Buffer>,
    /// Edge quads, built the first time a frame asks for them (closed opaque casters only).
    pub edge_quads: Option<EdgeQuadGpu>,
    /// Where the compute pass's static tables are in the arena, placed the first time a frame
    /// asks for them (opaque casters with a closed manifold part).
    pub compute: Option<ComputeStatic>,
    /// Bumped by every `update_positions` (the ray-query bottom levels follow it).
    pub version: u64,
    /// Bumped by every `set_transform` and `update_positions` (the kept plans follow it).
    pub pose: u64,
}

/// Buffers waiting for the frames in flight that may use them to retire: bit `s` of `mask`
/// is set while ring slot `s` has not been prepared again since the buffers were retired.
struct Grave {
    buffers: Vec<Buffer>,
    mask: u64,
}

/// All casters, in insertion order (the order their volumes are drawn in).
pub(crate) struct CasterTable {
    /// The id of the pass that owns the table (every id it hands out carries it).
    pass: u64,
    /// The planner's view of the live casters (a slice, as `shadow::plan_light` takes it).
    pub cpu: Vec<Caster>,
    /// Their GPU side, index for index.
    pub live: Vec<GpuCaster>,
    /// Per id index: its current generation and dense position in `live` (None: removed). (Not
    /// a ring slot: "slot" is the frames-in-flight ring's word alone.)
    ids: Vec<(u32, Option<usize>)>,
    /// Staging copies not yet known to have reached the GPU.
    pub pending: Vec<PendingUpload>,
    graves: Vec<Grave>,
    /// The compute pass's static tables of every caster that has them.
    pub arena: ComputeArena,
}

impl CasterTable {
    pub fn new(pass: u64) -> CasterTable {
        CasterTable {
            pass,
            cpu: Vec::new(),
            live: Vec::new(),
            ids: Vec::new(),
            pending: Vec::new(),
            graves: Vec::new(),
            arena: ComputeArena::default(),
        }
    }

    /// Dense index of a live id of this pass.
    pub fn find(&self, id: CasterId) -> Result<usize> {
        if id.pass != self.pass {
            return Err(crate::error::Misuse::ForeignId {
                what: "caster",
                id: format!("{}:{}", id.index, id.generation),
                owner: id.pass,
                this: self.pass,
            }
            .into());
        }
        match self.ids.get(id.index as usize) {
            Some(&(generation, Some(i))) if generation == id.generation => Ok(i),
            _ => Err(crate::error::Misuse::UnknownId { what: "caster", id: format!("{}:{}", id.index, id.generation) }.into()),
        }
    }

    /// A device-local buffer filled through a staging copy that the next frame records.
    fn staged(&mut self, dev: &PassDevice, name: &str, data: &[u8], usage: vk::BufferUsageFlags) -> Result<Buffer> {
        let staging = Buffer::with_data(dev, &format!("{name} (staging)"), data, vk::BufferUsageFlags::TRANSFER_SRC)?;
        let dst = match Buffer::new(dev, name, data.len() as u64, usage | vk::BufferUsageFlags::TRANSFER_DST, MemoryLocation::GpuOnly) {
            Ok(b) => b,
            Err(e) => {
                let mut staging = staging;
                staging.destroy(dev);
                return Err(e);
            }
        };
        let up = Upload { src: staging.raw, dst: dst.raw, dst_offset: 0, size: data.len() as u64 };
        self.pending.push(PendingUpload { staging, up, carried: 0 });
        Ok(dst)
    }

    /// Stages `data` for a copy into `dst` at `dst_offset` that the next frame records.
    fn staged_into(&mut self, dev: &PassDevice, name: &str, data: &[u8], dst: vk::Buffer, dst_offset: u64) -> Result<()> {
        if data.is_empty() {
            return Ok(());
        }
        let staging = Buffer::with_data(dev, &format!("{name} (staging)"), data, vk::BufferUsageFlags::TRANSFER_SRC)?;
        let up = Upload { src: staging.raw, dst, dst_offset, size: data.len() as u64 };
        self.pending.push(PendingUpload { staging, up, carried: 0 });
        Ok(())
    }

    fn upload_chunks(&mut self, dev: &PassDevice, caster: &Caster) -> Result<Vec<Buffer>> {
        let mut out: Vec<Buffer> = Vec::new();
        for ch in &caster.chunks {
            let data = dual_length(&ch.vertices);
            match self.staged(dev, &format!("caster {}", caster.name), bytemuck::cast_slice(&data), vk::BufferUsageFlags::VERTEX_BUFFER) {
                Ok(b) => out.push(b),
                Err(e) => {
                    for mut b in out {
                        b.destroy(dev);
                    }
                    return Err(e);
                }
            }
        }
        Ok(out)
    }

    pub fn add(&mut self, dev: &PassDevice, caster: Caster, transform: DMat4) -> Result<CasterId> {
        let chunks = self.upload_chunks(dev, &caster)?;
        let index = self.ids.len() as u32;
        let id = CasterId { pass: self.pass, index, generation: 0 };
        self.ids.push((0, Some(self.live.len())));
        let shells = shell_count(caster.mesh());
        self.cpu.push(caster);
        self.live.push(GpuCaster { id, transform, shells, chunks, edge_quads: None, compute: None, version: 0, pose: 0 });
        Ok(id)
    }

    /// Retires a caster's buffers until every slot has been prepared again.
    pub fn remove(&mut self, id: CasterId, all_slots: u64) -> Result<()> {
        let i = self.find(id)?;
        let mut c = self.live.remove(i);
        self.cpu.remove(i);
        self.ids[id.index as usize] = (id.generation.wrapping_add(1), None);
        for s in self.ids.iter_mut() {
            if let (_, Some(j)) = s {
                if *j > i {
                    *j -= 1;
                }
            }
        }
        let mut buffers: Vec<Buffer> = c.chunks.drain(..).collect();
        if let Some(eq) = c.edge_quads.take() {
            buffers.push(eq.vertices);
            buffers.push(eq.indices);
        }
        if let Some(cs) = c.compute.take() {
            self.arena.free(cs.elements);
        }
        self.retire(buffers, all_slots);
        Ok(())
    }

    /// New object-space positions for a caster (same vertex count and triangles as the mesh
    /// it was added with): its chunks are rebuilt and re-uploaded, the old buffers retired.
    pub fn update_positions(&mut self, dev: &PassDevice, id: CasterId, positions: &[Vec3], all_slots: u64) -> Result<()> {
        let i = self.find(id)?;
        let c = &self.cpu[i];
        let remap = &c.topology.remap;
        if positions.len() != remap.len() {
            return Err(Error::mesh(
                &c.name,
                format!("update_positions: {} positions for a mesh of {} vertices", positions.len(), remap.len()),
            ));
        }
        if let Some(k) = positions.iter().position(|p| !p.is_finite()) {
            return Err(Error::mesh(&c.name, format!("update_positions: vertex {k} is not finite ({:?})", positions[k])));
        }
        // Welded vertices must stay welded: two input vertices that were one welded vertex
        // must move together, or the topology (edge table, closedness) would no longer hold.
        let mut welded = vec![None::<Vec3>; c.topology.mesh.positions.len()];
        for (k, (&p, &w)) in positions.iter().zip(remap).enumerate() {
            match welded[w as usize] {
                None => welded[w as usize] = Some(p),
                Some(q) if q == p => {}
                Some(q) => {
                    return Err(Error::mesh(
                        &c.name,
                        format!("update_positions: vertex {k} ({p:?}) and another copy of the same welded vertex ({q:?}) moved apart; the topology must stay the same"),
                    ))
                }
            }
        }
        let mut caster = c.clone();
        for (dst, w) in caster.topology.mesh.positions.iter_mut().zip(welded) {
            if let Some(p) = w {
                *dst = p;
            }
        }
        caster.refresh_after_positions_changed();
        let chunks = self.upload_chunks(dev, &caster)?;
        let entry = &mut self.live[i];
        entry.version += 1;
        entry.pose += 1;
        let mut old: Vec<Buffer> = std::mem::replace(&mut entry.chunks, chunks);
        if let Some(eq) = entry.edge_quads.take() {
            old.push(eq.vertices);
            old.push(eq.indices);
        }
        // New positions: new planes and positions for the compute pass (placed again on
        // demand: the old ranges stay as they are for the frames in flight).
        if let Some(cs) = entry.compute.take() {
            self.arena.free(cs.elements);
        }
        self.cpu[i] = caster;
        self.retire(old, all_slots);
        Ok(())
    }

    /// Builds the edge-quad geometry of every closed opaque caster that lacks it.
    pub fn ensure_edge_quads(&mut self, dev: &PassDevice) -> Result<()> {
        for i in 0..self.live.len() {
            let c = &self.cpu[i];
            if self.live[i].edge_quads.is_some() || c.kind != CasterKind::Manifold || c.transmittance.is_some() {
                continue;
            }
            let m = crate::shadow::edgequad::EdgeQuadMesh::new(c);
            let mut idx = m.faces.clone();
            idx.extend_from_slice(&m.quads);
            let vertices =
                self.staged(dev, "edge-quad vertices", bytemuck::cast_slice(&m.vertices), vk::BufferUsageFlags::VERTEX_BUFFER)?;
            let indices = self.staged(dev, "edge-quad indices", bytemuck::cast_slice(&idx), vk::BufferUsageFlags::INDEX_BUFFER)?;
            self.live[i].edge_quads =
                Some(EdgeQuadGpu { vertices, indices, face_indices: m.faces.len() as u32, quad_indices: m.quads.len() as u32 });
        }
        Ok(())
    }

    /// Whether caster `i` gets compute tables (opaque, with a closed manifold part).
    fn wants_compute(&self, i: usize) -> bool {
        let c = &self.cpu[i];
        c.transmittance.is_none() && c.parts.iter().any(|p| p.kind == CasterKind::Manifold)
    }

    /// Places the compute pass's static tables of every opaque caster with a closed manifold
    /// part that lacks them in the arena (staged copies, recorded by the frame's `cmd_upload`).
    /// When they do not fit, the arena is rebuilt for every such caster (twice their size),
    /// the old tables retired until the slots in `all_slots` have been prepared again.
    pub fn ensure_compute(&mut self, dev: &PassDevice, all_slots: u64) -> Result<()> {
        let todo: Vec<usize> = (0..self.live.len()).filter(|&i| self.live[i].compute.is_none() && self.wants_compute(i)).collect();
        if todo.is_empty() {
            return Ok(());
        }
        let mut meshes: Vec<(usize, ComputeMesh)> = todo.iter().map(|&i| (i, ComputeMesh::new(&self.cpu[i]))).collect();
        let mut need = [0u64; super::compute::arena::N];
        for (_, m) in &meshes {
            add_elements(&mut need, mesh_elements(m));
        }
        if !self.arena.fits(need) {
            // Rebuild for every live caster's tables: the placed ones are staged again.
            let mut live = need;
            for g in &self.live {
                if let Some(cs) = &g.compute {
                    add_elements(&mut live, cs.elements);
                }
            }
            if let Some(old) = self.arena.rebuild(dev, live)? {
                self.retire(old.into(), all_slots);
            }
            for i in 0..self.live.len() {
                if self.live[i].compute.take().is_some() {
                    meshes.push((i, ComputeMesh::new(&self.cpu[i])));
                }
            }
        }
        let tables = self.arena.raw();
        for (i, m) in meshes {
            let elements = mesh_elements(&m);
            let base = self.arena.allocate(elements);
            let bytes = m.table_bytes(&base);
            for k in 0..super::compute::arena::N {
                let offset = base[k] as u64 * ELEMENT_BYTES[k];
                if let Err(e) = self.staged_into(dev, &format!("compute {}", TABLES[k]), &bytes[k], tables[k], offset) {
                    // the ranges stay allocated, unused; the copies already staged are harmless
                    self.arena.free(elements);
                    return Err(e);
                }
            }
            drop(bytes);
            let placed: ComputeStatic = m.placed(&self.cpu[i], base, elements);
            self.live[i].compute = Some(placed);
        }
        Ok(())
    }

    /// Buffers no new frame may use: freed once the slots in `mask` have been prepared again.
    /// Pending uploads into them are dropped (no later frame copies into a retired buffer);
    /// their staging copies wait for the frames that carry them.
    fn retire(&mut self, buffers: Vec<Buffer>, mask: u64) {
        let (dead, live): (Vec<PendingUpload>, Vec<PendingUpload>) =
            std::mem::take(&mut self.pending).into_iter().partition(|p| buffers.iter().any(|b| b.raw == p.up.dst));
        self.pending = live;
        for p in dead {
            self.graves.push(Grave { buffers: vec![p.staging], mask: p.carried });
        }
        self.graves.push(Grave { buffers, mask });
    }

    /// Ring slot `slot` is being prepared: settles the uploads its previous frame carried,
    /// then hands every upload still pending to the new frame. `delivered` says whether that
    /// previous frame recorded its uploads and was not abandoned by the host; then what it
    /// carried has reached the GPU (the slot's work has completed) and is no longer pending.
    /// Returns the new frame's copies and their bytes.
    pub fn carry_uploads(&mut self, slot: usize, delivered: bool) -> (Vec<Upload>, u64) {
        let bit = 1u64 << slot;
        let mut keep = Vec::with_capacity(self.pending.len());
        for mut p in std::mem::take(&mut self.pending) {
            if delivered && p.carried & bit != 0 {
                // Other slots' frames in flight may still copy from the staging buffer.
                self.graves.push(Grave { buffers: vec![p.staging], mask: p.carried & !bit });
            } else {
                p.carried = (p.carried & !bit) | bit;
                keep.push(p);
            }
        }
        self.pending = keep;
        let ups: Vec<Upload> = self.pending.iter().map(|p| p.up).collect();
        let bytes = ups.iter().map(|u| u.size).sum();
        (ups, bytes)
    }

    /// Ring slot `slot` is being prepared, so its previous frame has retired: frees what
    /// waited only for it.
    pub fn slot_retired(&mut self, dev: &PassDevice, slot: usize) {
        let bit = 1u64 << slot;
        for g in &mut self.graves {
            g.mask &= !bit;
        }
        let (done, keep): (Vec<Grave>, Vec<Grave>) = std::mem::take(&mut self.graves).into_iter().partition(|g| g.mask == 0);
        self.graves = keep;
        for g in done {
            for mut b in g.buffers {
                b.destroy(dev);
            }
        }
    }

    /// Frees everything (the host guarantees the device no longer uses any of it).
    pub fn destroy(&mut self, dev: &PassDevice) {
        for c in &mut self.live {
            for b in &mut c.chunks {
                b.destroy(dev);
            }
            if let Some(mut eq) = c.edge_quads.take() {
                eq.vertices.destroy(dev);
                eq.indices.destroy(dev);
            }
            c.compute = None;
        }
        self.arena.destroy(dev);
        self.live.clear();
        self.cpu.clear();
        for mut p in self.pending.drain(..) {
            p.staging.destroy(dev);
        }
        for g in self.graves.drain(..) {
            for mut b in g.buffers {
                b.destroy(dev);
            }
        }
    }
}

/// Validates a caster transform: finite and invertible.
/// A transparent caster's transmittance: each channel in [0, 1] (a surface lets through at
/// most all of the light).
pub(crate) fn check_transmittance(name: &str, t: glam::Vec3) -> Result<()> {
    if !(t.is_finite() && t.min_element() >= 0.0 && t.max_element() <= 1.0) {
        return Err(Error::mesh(name, format!("transmittance {t} is not in [0, 1] per channel")));
    }
    Ok(())
}

pub(crate) fn check_transform(name: &str, m: &DMat4) -> Result<()> {
    let det = m.determinant();
    if !(m.is_finite() && det.is_finite() && det != 0.0) {
        return Err(Error::mesh(name, format!("transform is not finite or singular (determinant {det})")));
    }
    Ok(())
}

/// Connected components of a mesh (triangles sharing a vertex), by union-find.
pub(crate) fn shell_count(mesh: &Mesh) -> usize {
    let mut parent: Vec<u32> = (0..mesh.positions.len() as u32).collect();
    fn find(p: &mut [u32], mut i: u32) -> u32 {
        while p[i as usize] != i {
            p[i as usize] = p[p[i as usize] as usize];
            i = p[i as usize];
        }
        i
    }
    for t in &mesh.triangles {
        for k in 1..3 {
            let (a, b) = (find(&mut parent, t[0]), find(&mut parent, t[k]));
            if a != b {
                parent[a as usize] = b;
            }
        }
    }
    let mut roots: Vec<u32> = mesh.triangles.iter().map(|t| find(&mut parent, t[0])).collect();
    roots.sort_unstable();
    roots.dedup();
    roots.len()
}
