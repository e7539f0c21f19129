//! [`Technique::RayQuery`](super::Technique::RayQuery) in the pass: one shadow ray per pixel
//! towards the light, traced with `VK_KHR_ray_query` from the host's G-buffer, writing the
//! same stencil the volumes write (non-zero = shadowed) through the same
//! [`cmd_determine`](super::ShadowPass::cmd_determine).
//!
//! Acceleration structures, all recorded into the host's command buffers by
//! [`cmd_before_rendering`](super::ShadowPass::cmd_before_rendering) (the pass owns no queue):
//! - one bottom level per caster (its welded triangles, object space), built with
//!   `PREFER_FAST_TRACE | ALLOW_COMPACTION`, then compacted once the frame that built it has
//!   retired (its compacted size is read back without waiting, when its slot is prepared
//!   again);
//! - a caster whose positions change ([`update_positions`](super::ShadowPass::update_positions))
//!   is rebuilt once with `ALLOW_UPDATE`, then refitted in place on every later change;
//! - the sphere casters as procedural boxes in one more bottom level (rebuilt when they
//!   change), each ball intersected exactly in the shader;
//! - a top level per ring slot, rewritten from the casters' transforms (relative to the
//!   view's eye) and rebuilt every frame.
//!
//! The ray follows the CPU reference's rule (`shaders/rayquery.wgsl`): from `P + N * offset`
//! towards the light, stopping `offset` short of a point light, every triangle two-sided;
//! `offset` is [`RayQueryInputs::surface_offset`] raised to 2^-16 of the casters' largest
//! eye-relative coordinate (128 f32 ulps, far above what a G-buffer position is off by).

use super::casters::{CasterId, CasterTable};
use super::desc::ShadowPassDesc;
use super::device::PassDevice;
use super::spheres::SphereCaster;
use super::view::ShadowView;
use crate::error::{Error, Result};
use crate::geom::{Light, LightKind};
use crate::gpu::accel::{self, Accel, AccelLoader, BlasJob, Geometry, Instance, Tlas};
use crate::gpu::descriptors::{pipeline_layout, Binding, DescriptorSet};
use crate::gpu::pipeline::{self, PipelineDesc};
use crate::gpu::{shaders, Buffer};
use ash::vk;
use glam::{DMat4, DVec3};
use std::cell::Cell;

mod balls;
mod batch;
mod push;
pub(crate) mod work;
use push::RayPush;
use work::RayWork;
mod record;
use balls::Balls;

/// The host's G-buffer as the rays read it ([`ShadowPass::set_ray_query_inputs`](super::ShadowPass::set_ray_query_inputs)).
///
/// Both views are sampled images of the frame's extent, one sample, in
/// `SHADER_READ_ONLY_OPTIMAL` whenever [`cmd_determine`](super::ShadowPass::cmd_determine) runs,
/// their writes made visible to fragment shaders by the host.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayQueryInputs {
    /// Float RGBA (`R32G32B32A32_SFLOAT` for exactness): the visible point's world position
    /// **relative to the view's eye** ([`ShadowView::eye`]) in xyz, and w != 0 where there is
    /// a surface (w = 0: background, never shadowed).
    pub position: vk::ImageView,
    /// Float RGBA: the visible point's unit world normal, on the side the eye sees, in xyz.
    pub normal: vk::ImageView,
    /// World units the ray starts off the surface (along the normal) and stops short of a
    /// point light: at least the host's own surface tolerance (umbrage's CPU reference uses
    /// 2e-5 of the scene's diagonal). The pass raises it where the eye-relative coordinates
    /// need more.
    pub surface_offset: f32,
}

/// A caster's bottom level.
struct Entry {
    id: CasterId,
    /// The caster's positions version it was built (or refitted) from.
    version: u64,
    blas: Accel,
    /// Built with `ALLOW_UPDATE` (the caster deformed once): refitted from then on.
    deformable: bool,
    /// The compacted-size query written by the frame of slot `.1`, read when that slot is
    /// prepared again.
    compaction: Option<(vk::QueryPool, usize)>,
}

/// A ring slot's top level and descriptor set (with the handles it was written with).
struct RaySlot {
    tlas: Option<Tlas>,
    set: Option<(DescriptorSet, [u64; 5])>,
    /// The batched lights and mask ([`PassToggles::ray_batch`](crate::pass::PassToggles::ray_batch)).
    batch: batch::SlotBatch,
}

/// What waits for the frames in flight to retire.
enum Garbage {
    Accel(Accel),
    Buffer(Buffer),
    Pool(vk::QueryPool),
}

/// The pass's ray-query state, made when a frame first asks for [`Technique::RayQuery`](super::Technique::RayQuery).
pub(crate) struct Rays {
    loader: AccelLoader,
    entries: Vec<Entry>,
    balls: Option<Balls>,
    /// Bound at binding 3 when there are no spheres.
    no_balls: Buffer,
    slots: Vec<RaySlot>,
    /// The pipeline and its layout, made with the first descriptor set.
    pipeline: Option<(vk::PipelineLayout, vk::Pipeline)>,
    /// The batched frames' pipelines, made by the first batched frame.
    batch_pipes: Option<batch::BatchPipes>,
    graves: Vec<(Garbage, u64)>,
    /// Bottom-level builds, refits and compactions recorded so far (for the stats).
    pub counts: RayCounts,
}

/// What the pass did with bottom levels since it was created.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RayCounts {
    /// Bottom levels built (new casters, first deformations, sphere sets).
    pub builds: u64,
    /// In-place refits of deformed casters.
    pub refits: u64,
    /// Bottom levels compacted.
    pub compactions: u64,
}

/// The eye-relative homogeneous light, f32: (position - eye, 1) or (direction towards the
/// light, 0). The rays take this one; a host's lighting pass that takes the same one agrees
/// with them to the bit.
pub fn light_rel(l: &Light, eye: DVec3) -> [f32; 4] {
    match l.kind {
        LightKind::Directional => (-l.direction.normalize()).extend(0.0).to_array(),
        _ => (l.position.as_dvec3() - eye).as_vec3().extend(1.0).to_array(),
    }
}

const STATIC: vk::BuildAccelerationStructureFlagsKHR = vk::BuildAccelerationStructureFlagsKHR::from_raw(
    vk::BuildAccelerationStructureFlagsKHR::PREFER_FAST_TRACE.as_raw() | vk::BuildAccelerationStructureFlagsKHR::ALLOW_COMPACTION.as_raw(),
);
const DEFORMABLE: vk::BuildAccelerationStructureFlagsKHR = vk::BuildAccelerationStructureFlagsKHR::from_raw(
    vk::BuildAccelerationStructureFlagsKHR::PREFER_FAST_TRACE.as_raw() | vk::BuildAccelerationStructureFlagsKHR::ALLOW_UPDATE.as_raw(),
);

/// What a ray-query frame is prepared from.
#[derive(Clone, Copy)]
pub(crate) struct FrameInput<'a> {
    pub dev: &'a PassDevice,
    /// The ring slot (its previous frame retired).
    pub slot: usize,
    pub casters: &'a CasterTable,
    pub spheres: &'a [SphereCaster],
    pub view: &'a ShadowView,
    /// The frame's lights and their scissors.
    pub lights: &'a [Light],
    pub scissors: &'a [vk::Rect2D],
    /// [`PassToggles::ray_batch`](crate::pass::PassToggles::ray_batch).
    pub batch: bool,
    pub inputs: &'a RayQueryInputs,
    pub desc: &'a ShadowPassDesc,
}

/// What one prepare allocates or retires on the way.
struct Work<'a> {
    dev: &'a PassDevice,
    transient: &'a mut Vec<Buffer>,
    all_slots: u64,
}

impl Rays {
    pub fn new(dev: &PassDevice, instance: &ash::Instance, slots: usize) -> Result<Rays> {
        let no_balls = Buffer::with_data(dev, "ray-query no balls", &[0u8; 16], vk::BufferUsageFlags::STORAGE_BUFFER)?;
        Ok(Rays {
            loader: AccelLoader::from_device(instance, &dev.device),
            entries: Vec::new(),
            balls: None,
            no_balls,
            slots: (0..slots).map(|_| RaySlot { tlas: None, set: None, batch: Default::default() }).collect(),
            pipeline: None,
            batch_pipes: None,
            graves: Vec::new(),
            counts: RayCounts::default(),
        })
    }

    /// Slot `slot` is being prepared: frees what waited only for its previous frame.
    pub fn slot_retired(&mut self, dev: &PassDevice, slot: usize) {
        let bit = 1u64 << slot;
        for (_, mask) in &mut self.graves {
            *mask &= !bit;
        }
        let (done, keep): (Vec<_>, Vec<_>) = std::mem::take(&mut self.graves).into_iter().partition(|(_, m)| *m == 0);
        self.graves = keep;
        for (g, _) in done {
            self.free(dev, g);
        }
    }

    fn free(&self, dev: &PassDevice, g: Garbage) {
        match g {
            Garbage::Accel(mut a) => a.destroy(dev, &self.loader),
            Garbage::Buffer(mut b) => b.destroy(dev),
            // SAFETY: no pending work uses the pool (its frames retired, or the device is idle).
            Garbage::Pool(p) => unsafe { dev.device.destroy_query_pool(p, None) },
        }
    }

    /// Plans slot `slot`'s frame (the slot's previous frame retired): bottom levels built,
    /// refitted or compacted as the casters need, the top level's instances written, the
    /// slot's descriptor set made for `inputs`.
    ///
    /// On error every bottom level is retired (some may have been made or swapped for builds
    /// and copies this frame will never record), so the next frame builds them all again.
    pub fn prepare(&mut self, f: &FrameInput, all_slots: u64, transient: &mut Vec<Buffer>) -> Result<RayWork> {
        let r = self.prepare_inner(f, &mut Work { dev: f.dev, transient, all_slots });
        if r.is_err() {
            for e in std::mem::take(&mut self.entries) {
                self.graves.push((Garbage::Accel(e.blas), all_slots));
                if let Some((p, _)) = e.compaction {
                    self.graves.push((Garbage::Pool(p), all_slots));
                }
            }
            if let Some(b) = self.balls.take() {
                self.graves.push((Garbage::Accel(b.blas), all_slots));
                self.graves.push((Garbage::Buffer(b.buffer), all_slots));
            }
        }
        r
    }

    fn prepare_inner(&mut self, f: &FrameInput, w: &mut Work) -> Result<RayWork> {
        let FrameInput { dev, slot, casters, spheres, view, lights, scissors, batch: settings_batch, inputs, desc } = *f;
        let compactions = self.compact(w, slot)?;
        let mut jobs = Vec::new();
        let mut queries = Vec::new();
        self.sync_casters(w, slot, casters, &mut jobs, &mut queries)?;
        let mut builds = jobs.iter().filter(|j| !j.is_refit()).count();
        if let Some(job) = self.sync_balls(w, spheres)? {
            jobs.push(job);
            builds += 1;
        }
        // The top level: every caster, then the spheres' boxes.
        let eye = view.eye;
        let to_eye = DMat4::from_translation(-eye);
        let mut extent = 0.0f64;
        let mut instances: Vec<Instance> = Vec::with_capacity(self.entries.len() + 1);
        for (k, (e, (c, live))) in self.entries.iter().zip(casters.cpu.iter().zip(&casters.live)).enumerate() {
            let b = c.object_bounds.transformed(&c.transform);
            for p in [b.min, b.max] {
                extent = extent.max((p.as_dvec3() - eye).abs().max_element());
            }
            let x = (to_eye * live.transform).transpose();
            let rows = [x.x_axis.as_vec4().to_array(), x.y_axis.as_vec4().to_array(), x.z_axis.as_vec4().to_array()];
            let flags = vk::GeometryInstanceFlagsKHR::TRIANGLE_FACING_CULL_DISABLE;
            instances.push(Instance { transform: rows, custom: k as u32, mask: 0xff, flags, blas: e.blas.address });
        }
        if let Some(b) = &self.balls {
            let t = (b.origin - eye).as_vec3();
            let rows = [[1.0, 0.0, 0.0, t.x], [0.0, 1.0, 0.0, t.y], [0.0, 0.0, 1.0, t.z]];
            instances.push(Instance {
                transform: rows,
                custom: 0,
                mask: 0xff,
                flags: vk::GeometryInstanceFlagsKHR::empty(),
                blas: b.blas.address,
            });
            for s in spheres {
                extent = extent.max((s.sphere.center - eye).abs().max_element() + s.sphere.radius);
            }
        }
        let offset = inputs.surface_offset.max((extent * 2f64.powi(-16)) as f32);
        let push: Vec<RayPush> = lights.iter().map(|l| RayPush { light: light_rel(l, eye), params: [offset, 0.0, 0.0, 0.0] }).collect();
        let batched = lights.len() > 1 && settings_batch;
        let data: Vec<batch::BatchLight> = match batched {
            true => push.iter().zip(scissors).map(|(p, r)| batch::BatchLight { light: p.light, scissor: batch::scissor_f32(r) }).collect(),
            false => Vec::new(),
        };
        let lights_buffer = self.slots[slot].batch.write_lights(dev, lights.len(), &data)?;
        let (set, layout, pipeline) = self.slot_objects(dev, slot, instances.len() as u32, (inputs, lights_buffer), desc)?;
        let tlas = self.slots[slot].tlas.as_mut().ok_or_else(|| Error::Internal("no top level".into()))?;
        tlas.write(&instances)?;
        let batch = match batched {
            true => Some(self.batch_frame(dev, slot, view, scissors, desc)?),
            false => None,
        };
        Ok(RayWork {
            compactions,
            jobs,
            queries,
            instances: instances.len() as u32,
            tlas_slot: slot,
            set,
            layout,
            pipeline,
            push,
            builds,
            recorded: Cell::new(false),
            offset,
            blas_bytes: self.entries.iter().map(|e| e.blas.size).sum::<u64>() + self.balls.as_ref().map_or(0, |b| b.blas.size),
            batch,
        })
    }

    /// Reads the compacted sizes the retired frame of `slot` wrote, and swaps in the compacted
    /// copies (recorded by this frame).
    fn compact(&mut self, w: &mut Work, slot: usize) -> Result<Vec<(vk::AccelerationStructureKHR, vk::AccelerationStructureKHR)>> {
        let mut copies = Vec::new();
        for i in 0..self.entries.len() {
            let Some((pool, s)) = self.entries[i].compaction else { continue };
            if s != slot {
                continue;
            }
            self.entries[i].compaction = None;
            self.graves.push((Garbage::Pool(pool), w.all_slots));
            let Some(size) = accel::compacted_size(w.dev, pool) else { continue };
            // Compacted even at the same size (lavapipe reports no saving): one copy per caster,
            // once, and the path is the same on every driver.
            if size == 0 || size > self.entries[i].blas.size {
                continue;
            }
            let small = accel::new_blas(w.dev, &self.loader, "caster blas (compacted)", size)?;
            copies.push((self.entries[i].blas.raw, small.raw));
            let old = std::mem::replace(&mut self.entries[i].blas, small);
            self.graves.push((Garbage::Accel(old), w.all_slots));
            self.counts.compactions += 1;
        }
        Ok(copies)
    }

    /// Matches the entries to the live casters, index for index: new casters built, deformed
    /// ones rebuilt for updates or refitted, removed ones retired.
    fn sync_casters(
        &mut self,
        w: &mut Work,
        slot: usize,
        casters: &CasterTable,
        jobs: &mut Vec<BlasJob>,
        queries: &mut Vec<(vk::QueryPool, vk::AccelerationStructureKHR)>,
    ) -> Result<()> {
        let mut old: Vec<Entry> = std::mem::take(&mut self.entries);
        for (c, live) in casters.cpu.iter().zip(&casters.live) {
            let found = old.iter().position(|e| e.id == live.id).map(|i| old.swap_remove(i));
            let found = match found {
                Some(e) if e.version == live.version => {
                    self.entries.push(e);
                    continue;
                }
                other => other,
            };
            // Built or refitted this frame: only then are the positions copied.
            let mesh = &c.topology.mesh;
            let positions: Vec<[f32; 3]> = mesh.positions.iter().map(|p| p.to_array()).collect();
            let geometry = Geometry::Triangles { positions: &positions, indices: &mesh.triangles };
            let entry = match found {
                Some(e) if e.deformable => {
                    jobs.push(accel::prepare_refit(w.dev, &self.loader, &e.blas, &geometry, DEFORMABLE, w.transient)?);
                    self.counts.refits += 1;
                    Entry { version: live.version, ..e }
                }
                previous => {
                    let deformable = previous.is_some();
                    if let Some(e) = previous {
                        self.retire_entry(w, e);
                    }
                    let flags = if deformable { DEFORMABLE } else { STATIC };
                    let name = format!("blas {}", c.name);
                    let (blas, job) = accel::prepare_blas(w.dev, &self.loader, &name, &geometry, flags, w.transient)?;
                    jobs.push(job);
                    self.counts.builds += 1;
                    let compaction = match deformable {
                        false => {
                            let pool = accel::compaction_pool(w.dev);
                            match pool {
                                Ok(p) => {
                                    queries.push((p, blas.raw));
                                    Some((p, slot))
                                }
                                Err(_) => None,
                            }
                        }
                        true => None,
                    };
                    Entry { id: live.id, version: live.version, blas, deformable, compaction }
                }
            };
            self.entries.push(entry);
        }
        for e in old {
            self.retire_entry(w, e);
        }
        Ok(())
    }

    fn retire_entry(&mut self, w: &Work, e: Entry) {
        self.graves.push((Garbage::Accel(e.blas), w.all_slots));
        if let Some((p, _)) = e.compaction {
            self.graves.push((Garbage::Pool(p), w.all_slots));
        }
    }

    /// The slot's top level (grown to `instances`) and its descriptor set for `inputs`,
    /// (re)made when they changed, and the pipeline.
    fn slot_objects(
        &mut self,
        dev: &PassDevice,
        slot: usize,
        instances: u32,
        (inputs, lights): (&RayQueryInputs, vk::Buffer),
        desc: &ShadowPassDesc,
    ) -> Result<(vk::DescriptorSet, vk::PipelineLayout, vk::Pipeline)> {
        let s = &mut self.slots[slot];
        if s.tlas.as_ref().is_none_or(|t| t.capacity() < instances) {
            // The slot's previous frame retired: nothing reads its top level or set any more.
            if let Some(mut t) = s.tlas.take() {
                t.destroy(dev, &self.loader);
            }
            s.tlas = Some(Tlas::new(dev, &self.loader, instances.max(1).next_power_of_two())?);
        }
        let tlas = s.tlas.as_ref().map(|t| t.accel.raw).unwrap_or_default();
        let balls = self.balls.as_ref().map_or(self.no_balls.raw, |b| b.buffer.raw);
        use vk::Handle;
        let key = [tlas.as_raw(), inputs.position.as_raw(), inputs.normal.as_raw(), balls.as_raw(), lights.as_raw()];
        if s.set.as_ref().map(|(_, k)| *k) != Some(key) {
            if let Some((mut old, _)) = s.set.take() {
                old.destroy(dev);
            }
            let set = DescriptorSet::new(
                dev,
                &[
                    Binding::AccelerationStructure(tlas),
                    Binding::Image(inputs.position),
                    Binding::Image(inputs.normal),
                    Binding::StorageBuffer(balls),
                    Binding::StorageBuffer(lights),
                ],
            )?;
            s.set = Some((set, key));
        }
        let (set, set_layout) = match &s.set {
            Some((set, _)) => (set.set, set.layout),
            None => return Err(Error::Internal("no ray-query descriptor set".into())),
        };
        if self.pipeline.is_none() {
            self.pipeline = Some(make_pipeline(dev, desc, set_layout)?);
        }
        let (layout, pipeline) = self.pipeline.ok_or_else(|| Error::Internal("no ray-query pipeline".into()))?;
        Ok((set, layout, pipeline))
    }

    /// A batched frame's mask (of the view's extent), its set, the pipelines (made by the first
    /// batched frame) and the union of each batch's scissors.
    fn batch_frame(
        &mut self,
        dev: &PassDevice,
        slot: usize,
        view: &ShadowView,
        scissors: &[vk::Rect2D],
        desc: &ShadowPassDesc,
    ) -> Result<batch::BatchFrame> {
        let extent = vk::Extent2D { width: view.width, height: view.height };
        let (image, mask_set) = self.slots[slot].batch.mask(dev, extent)?;
        let (mask, mask_view) = (image.raw, image.view);
        if self.batch_pipes.is_none() {
            let ray_layout = self.pipeline.map(|(l, _)| l).ok_or_else(|| Error::Internal("no ray-query pipeline".into()))?;
            let mask_set_layout = match &self.slots[slot].batch.mask {
                Some((_, set)) => set.layout,
                None => return Err(Error::Internal("no ray-query mask".into())),
            };
            self.batch_pipes = Some(batch::BatchPipes::new(dev, desc, ray_layout, mask_set_layout)?);
        }
        let p = self.batch_pipes.as_ref().ok_or_else(|| Error::Internal("no batch pipelines".into()))?;
        Ok(batch::BatchFrame {
            mask,
            mask_view,
            extent,
            mask_set,
            batch: p.batch,
            mask_layout: p.mask_layout,
            resolve: p.resolve,
            unions: scissors.chunks(batch::BATCH).map(batch::union).collect(),
            traced: Cell::new(None),
        })
    }

    /// The slot's top level.
    pub fn tlas(&self, slot: usize) -> Option<&Tlas> {
        self.slots.get(slot).and_then(|s| s.tlas.as_ref())
    }

    /// The extension's functions.
    pub fn loader(&self) -> &AccelLoader {
        &self.loader
    }

    /// Frees everything (no pending work uses any of it).
    pub fn destroy(&mut self, dev: &PassDevice) {
        for (g, _) in std::mem::take(&mut self.graves) {
            self.free(dev, g);
        }
        for e in std::mem::take(&mut self.entries) {
            self.free(dev, Garbage::Accel(e.blas));
            if let Some((p, _)) = e.compaction {
                self.free(dev, Garbage::Pool(p));
            }
        }
        if let Some(b) = self.balls.take() {
            self.free(dev, Garbage::Accel(b.blas));
            self.free(dev, Garbage::Buffer(b.buffer));
        }
        for s in &mut self.slots {
            if let Some(mut t) = s.tlas.take() {
                t.destroy(dev, &self.loader);
            }
            if let Some((mut set, _)) = s.set.take() {
                set.destroy(dev);
            }
            s.batch.destroy(dev);
        }
        if let Some(mut p) = self.batch_pipes.take() {
            p.destroy(dev);
        }
        self.no_balls.destroy(dev);
        if let Some((layout, pipeline)) = self.pipeline.take() {
            // SAFETY: no pending work uses them.
            unsafe {
                dev.device.destroy_pipeline(pipeline, None);
                dev.device.destroy_pipeline_layout(layout, None);
            }
        }
    }
}

/// The stencil of a shadowed pixel: 1, written where the fragment survives.
pub(crate) const MARK: vk::StencilOpState = vk::StencilOpState {
    fail_op: vk::StencilOp::KEEP,
    pass_op: vk::StencilOp::REPLACE,
    depth_fail_op: vk::StencilOp::KEEP,
    compare_op: vk::CompareOp::ALWAYS,
    compare_mask: 0xff,
    write_mask: 0xff,
    reference: 1,
};

/// The full-screen ray pipeline: stencil REPLACE 1 where the fragment survives (its ray is
/// blocked), no depth test, one sample, dynamic rendering (the only model ray query takes).
fn make_pipeline(
    dev: &PassDevice,
    desc: &ShadowPassDesc,
    set_layout: vk::DescriptorSetLayout,
) -> Result<(vk::PipelineLayout, vk::Pipeline)> {
    let layout = pipeline_layout(dev, &[set_layout], std::mem::size_of::<RayPush>() as u32, vk::ShaderStageFlags::FRAGMENT)?;
    let mut d = PipelineDesc::new(shaders::FULLSCREEN_VERT, layout, desc.depth_stencil_format);
    d.fragment = Some(shaders::RAYQUERY_WGSL);
    d.stencil = Some((MARK, MARK));
    d.color_write = false;
    match pipeline::create(dev, &d) {
        Ok(p) => Ok((layout, p)),
        Err(e) => {
            // SAFETY: the layout was just created and is unused.
            unsafe { dev.device.destroy_pipeline_layout(layout, None) };
            Err(e)
        }
    }
}

/// [`Technique::RayQuery`](super::Technique::RayQuery)'s state: its acceleration structures
/// (made by the first frame that traces) and the G-buffer the rays read
/// ([`ShadowPass::set_ray_query_inputs`](super::ShadowPass::set_ray_query_inputs)).
#[derive(Default)]
pub(super) struct RayState {
    pub structures: Option<Rays>,
    pub inputs: Option<RayQueryInputs>,
}

impl super::device::TechniqueState for RayState {
    fn slot_retired(&mut self, dev: &PassDevice, slot: usize) {
        if let Some(r) = &mut self.structures {
            r.slot_retired(dev, slot);
        }
    }
    fn destroy(&mut self, dev: &PassDevice) {
        if let Some(mut r) = self.structures.take() {
            r.destroy(dev);
        }
    }
}
