//! The compute pass's share of `prepare` (the slot's buffers, records and descriptor sets)
//! and the counts read back after the frame.

use super::work::{ComputeWork, GpuJob};
use super::{SlotCompute, BINDINGS};
use crate::error::{Error, Misuse, Result};
use crate::pass::frame::PreparedFrame;
use crate::pass::ShadowPass;
use ash::vk;
use gpu_allocator::MemoryLocation;

impl ShadowPass {
    /// Sizes the slot's compute buffers for `cf`, lays out its merged draws for `lights` lights
    /// in `draws` (resolved: not `Auto`), writes its jobs and records and the frame's
    /// descriptor sets. The slot's previous frame has retired.
    pub(crate) fn prepare_compute(
        &mut self,
        slot: usize,
        mut cf: ComputeWork,
        (lights, draws): (usize, crate::pass::desc::ComputeDraws),
    ) -> Result<ComputeWork> {
        let draws = if cf.mesh { crate::pass::desc::ComputeDraws::PerChunk } else { draws };
        cf.merged = super::draws::plan(&mut cf.records, &cf.chunk_records, lights, draws, self.dev.max_draw_indirect_count);
        let merged_layout = match (&cf.merged, self.techniques.compute.merged.as_ref()) {
            (None, _) => vk::DescriptorSetLayout::null(),
            (Some(_), Some(p)) => p.set_layout,
            (Some(_), None) => return Err(Error::Internal("merged draws without their pipelines".into())),
        };
        let Some(pipes) = self.techniques.compute.pipes.as_ref() else {
            return Err(
                Misuse::NotConfigured { call: "Technique::Compute", needs: "a device with compute silhouettes (Capabilities)" }.into()
            );
        };
        let set_layout = pipes.set_layout;
        let mesh_layout = match (cf.mesh, self.techniques.mesh.pipes.as_ref()) {
            (false, _) => None,
            (true, Some(m)) => Some(m.set_layout),
            (true, None) => return Err(crate::pass::desc::mesh_missing()),
        };
        let dev = &self.dev;
        let arena = self.casters.arena.raw();
        let sc = &mut self.techniques.compute.slots[slot];
        let storage = vk::BufferUsageFlags::STORAGE_BUFFER;
        // (buffer, name, bytes, usage, where): every range the set binds, each at most the
        // device's maxStorageBufferRange
        let sizes = [
            ("records", (cf.records.len() * 4) as u64),
            ("indices", cf.out_indices * 2),
            ("facing bits", cf.facing_words * 4),
            ("jobs", (cf.jobs.len() * std::mem::size_of::<GpuJob>()) as u64),
            ("lists", cf.exact_capacity * 8),
        ];
        for (name, bytes) in sizes {
            if bytes > dev.max_storage_range {
                return Err(Error::Unsupported(format!(
                    "Technique::Compute: the frame's compute {name} need {bytes} bytes, more than the device's \
                     maxStorageBufferRange ({} bytes); use Technique::Volumes, or fewer lights or casters",
                    dev.max_storage_range
                )));
            }
        }
        let ranges: Vec<u64> = sizes.iter().map(|&(_, b)| b.max(16)).collect();
        let specs = [
            (&mut sc.records, storage | vk::BufferUsageFlags::INDIRECT_BUFFER, MemoryLocation::CpuToGpu),
            (&mut sc.out, storage | vk::BufferUsageFlags::INDEX_BUFFER, MemoryLocation::GpuOnly),
            (&mut sc.facing, storage | vk::BufferUsageFlags::TRANSFER_DST, MemoryLocation::GpuOnly),
            (&mut sc.jobs, storage, MemoryLocation::CpuToGpu),
            (&mut sc.lists, storage, MemoryLocation::GpuOnly),
        ];
        for ((b, usage, loc), (&range, (name, _))) in specs.into_iter().zip(ranges.iter().zip(sizes)) {
            SlotCompute::ensure(dev, b, &format!("compute {name} {slot}"), range, usage, loc)?;
        }
        let (Some(records), Some(out), Some(facing), Some(jobs), Some(lists)) =
            (sc.records.as_mut(), sc.out.as_ref(), sc.facing.as_ref(), sc.jobs.as_mut(), sc.lists.as_ref())
        else {
            return Err(Error::Internal("compute silhouettes: slot buffers missing".into()));
        };
        records.write(0, bytemuck::cast_slice(&cf.records))?;
        jobs.write(0, bytemuck::cast_slice(&cf.jobs))?;
        let slot_buffers = [records.raw, out.raw, facing.raw, jobs.raw, lists.raw];
        let (records_raw, out_raw) = (records.raw, out.raw);
        let counts_range = (cf.counts_words * 4).max(16);
        if mesh_layout.is_some() {
            if counts_range > dev.max_storage_range {
                return Err(Error::Unsupported(format!(
                    "Technique::Mesh: the frame's mesh counters need {counts_range} bytes, more than the device's \
                     maxStorageBufferRange ({} bytes); use fewer lights or casters",
                    dev.max_storage_range
                )));
            }
            let usage = storage | vk::BufferUsageFlags::TRANSFER_DST;
            SlotCompute::ensure(dev, &mut sc.counts, &format!("mesh counters {slot}"), counts_range, usage, MemoryLocation::GpuToCpu)?;
        }
        let counts_raw = sc.counts.as_ref().map(|b| b.raw).unwrap_or_default();
        sc.reset_pool(dev, 3)?;
        cf.set = vk::DescriptorSet::null();
        cf.mesh_set = vk::DescriptorSet::null();
        if !cf.jobs.is_empty() {
            let d = &dev.device;
            // SAFETY: the pool was reset or created for at least one set; the slot's previous
            // frame (the only user of its set) has retired.
            let sets = unsafe {
                d.allocate_descriptor_sets(&vk::DescriptorSetAllocateInfo::default().descriptor_pool(sc.pool).set_layouts(&[set_layout]))
            }
            .map_err(Error::vk("vkAllocateDescriptorSets"))?;
            let set = sets[0];
            // binding order: the arena's four tables, jobs, facing, records, indices, lists, the
            // arena's block bounds and word pairs
            let whole = |buffer| [vk::DescriptorBufferInfo { buffer, offset: 0, range: vk::WHOLE_SIZE }];
            let ranged = |k: usize| [vk::DescriptorBufferInfo { buffer: slot_buffers[k], offset: 0, range: ranges[k] }];
            let (blocks, groups) = (arena[super::arena::BLOCKS], arena[super::arena::GROUPS]);
            let infos: [[vk::DescriptorBufferInfo; 1]; BINDINGS as usize] = [
                whole(arena[0]),
                whole(arena[1]),
                whole(arena[2]),
                whole(arena[3]),
                ranged(3),
                ranged(2),
                ranged(0),
                ranged(1),
                ranged(4),
                whole(blocks),
                whole(groups),
            ];
            if arena.contains(&vk::Buffer::null()) {
                return Err(Error::Internal("compute silhouettes: jobs without the arena".into()));
            }
            let writes = crate::gpu::descriptors::storage_buffer_writes(set, &infos);
            // SAFETY: the set is not in use (just allocated); the buffers are alive.
            unsafe { d.update_descriptor_sets(&writes, &[]) };
            cf.set = set;
            if let Some(layout) = mesh_layout {
                // SAFETY: as above (the pool has room for two sets).
                let sets = unsafe {
                    d.allocate_descriptor_sets(&vk::DescriptorSetAllocateInfo::default().descriptor_pool(sc.pool).set_layouts(&[layout]))
                }
                .map_err(Error::vk("vkAllocateDescriptorSets"))?;
                // binding order (`shaders/extrude.wgsl`): positions, triangles, meshlets, meshlet
                // triangles, meshlet edges (the arena's), facing bits, counters
                let counts = [vk::DescriptorBufferInfo { buffer: counts_raw, offset: 0, range: counts_range }];
                let infos: [[vk::DescriptorBufferInfo; 1]; crate::pass::mesh::MESH_BINDINGS as usize] =
                    [whole(arena[2]), whole(arena[1]), whole(arena[4]), whole(arena[5]), whole(arena[6]), ranged(2), counts];
                let writes = crate::gpu::descriptors::storage_buffer_writes(sets[0], &infos);
                // SAFETY: as above.
                unsafe { d.update_descriptor_sets(&writes, &[]) };
                cf.mesh_set = sets[0];
            }
        }
        if let Some(m) = cf.merged.as_mut().filter(|_| !cf.jobs.is_empty()) {
            let b = super::draw_pipes::MergedBuffers {
                xforms: &cf.xforms,
                records: (records_raw, ranges[0]),
                vertices: arena[super::arena::VERTICES],
                set_layout: merged_layout,
            };
            super::draw_pipes::prepare_merged(dev, sc, slot, m, b)?;
        }
        cf.counts_buffer = counts_raw;
        cf.records_buffer = records_raw;
        cf.out_buffer = out_raw;
        Ok(cf)
    }

    /// [`Technique::Compute`](crate::pass::Technique::Compute): adds the triangle counts and
    /// silhouette edges the GPU found (read back from the indirect arguments) to `frame`'s
    /// plans, stats and totals; nothing for other techniques. Call once the frame's command
    /// buffers have completed (its fence) and before its slot is prepared again; a second call
    /// adds nothing.
    ///
    /// Errors: the slot was prepared again since, or a chunk's index region overflowed (the
    /// regions are sized for the worst case, so this would be a bug, reported, never a silent
    /// cut).
    pub fn read_back_counts(&self, frame: &mut PreparedFrame) -> Result<()> {
        let Some(cf) = frame.compute.as_ref() else { return Ok(()) };
        let slot = &self.slots[frame.slot];
        if slot.serial != Some(frame.serial) {
            let current = slot.serial.unwrap_or(0);
            return Err(Misuse::StaleFrame { slot: frame.slot, serial: frame.serial, current }.into());
        }
        if cf.mesh {
            if cf.read_back.replace(true) || cf.mesh_metas.is_empty() {
                return Ok(());
            }
            let Some(counts) = self.techniques.compute.slots[frame.slot].counts.as_ref() else { return Ok(()) };
            let bytes = counts.read()?;
            let words: &[u32] = bytemuck::try_cast_slice(&bytes[..cf.counts_words as usize * 4])
                .map_err(|e| Error::Internal(format!("mesh counters: {e}")))?;
            return cf.read_back_mesh(words, &mut frame.lights, &mut frame.totals);
        }
        if cf.metas.is_empty() {
            return Ok(());
        }
        let Some(records) = self.techniques.compute.slots[frame.slot].records.as_ref() else { return Ok(()) };
        let bytes = records.read()?;
        let words: &[u32] =
            bytemuck::try_cast_slice(&bytes[..cf.records.len() * 4]).map_err(|e| Error::Internal(format!("compute records: {e}")))?;
        cf.read_back(words, &mut frame.lights, &mut frame.totals)
    }
}
