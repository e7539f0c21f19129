//! The compute pass's share of `prepare` (the slot's buffers, records and descriptor sets)
//! and the counts read back after the frame.

use super::frame::ComputeFrame;
use super::SlotCompute;
use crate::error::{Error, Misuse, Result};
use crate::pass::{PreparedFrame, ShadowPass};
use ash::vk;
use gpu_allocator::MemoryLocation;

impl ShadowPass {
    /// Sizes the slot's compute buffers for `cf`, writes its records and one descriptor set
    /// per caster with jobs. The slot's previous frame has retired.
    pub(crate) fn prepare_compute(&mut self, slot: usize, mut cf: ComputeFrame) -> Result<ComputeFrame> {
        let Some(pipes) = self.compute_pipes.as_ref() else {
            return Err(
                Misuse::NotConfigured { call: "Technique::Compute", needs: "a device with compute silhouettes (Capabilities)" }.into()
            );
        };
        let set_layout = pipes.set_layout;
        let dev = &self.dev;
        let sc = &mut self.slots[slot].compute;
        let records_bytes = (cf.records.len() * 4) as u64;
        SlotCompute::ensure(
            dev,
            &mut sc.records,
            &format!("compute records {slot}"),
            records_bytes,
            vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::INDIRECT_BUFFER,
            MemoryLocation::CpuToGpu,
        )?;
        SlotCompute::ensure(
            dev,
            &mut sc.out,
            &format!("compute indices {slot}"),
            cf.out_indices * 2,
            vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::INDEX_BUFFER,
            MemoryLocation::GpuOnly,
        )?;
        SlotCompute::ensure(
            dev,
            &mut sc.facing,
            &format!("compute facing {slot}"),
            cf.facing_words * 4,
            vk::BufferUsageFlags::STORAGE_BUFFER,
            MemoryLocation::GpuOnly,
        )?;
        let (Some(records), Some(out), Some(facing)) = (sc.records.as_mut(), sc.out.as_ref(), sc.facing.as_ref()) else {
            return Err(Error::Internal("compute silhouettes: slot buffers missing".into()));
        };
        records.write(0, bytemuck::cast_slice(&cf.records))?;
        let (records_raw, out_raw, facing_raw) = (records.raw, out.raw, facing.raw);
        let mut casters: Vec<usize> = cf.jobs.iter().flatten().map(|j| j.caster).collect();
        casters.sort_unstable();
        casters.dedup();
        sc.reset_pool(dev, casters.len() as u32)?;
        cf.sets.clear();
        if !casters.is_empty() {
            let layouts = vec![set_layout; casters.len()];
            let d = &dev.device;
            // SAFETY: the pool was reset or created for at least this many sets; the slot's
            // previous frame (the only user of its sets) has retired.
            let sets = unsafe {
                d.allocate_descriptor_sets(&vk::DescriptorSetAllocateInfo::default().descriptor_pool(sc.pool).set_layouts(&layouts))
            }
            .map_err(Error::vk("vkAllocateDescriptorSets"))?;
            let mut infos: Vec<[vk::DescriptorBufferInfo; 1]> = Vec::with_capacity(casters.len() * 7);
            for &ci in &casters {
                let st = self.casters.live[ci].compute.as_ref().ok_or_else(|| Error::Internal("compute tables missing".into()))?;
                for b in [st.planes.raw, st.tris.raw, st.positions.raw, st.edges.raw, facing_raw, records_raw, out_raw] {
                    infos.push([vk::DescriptorBufferInfo { buffer: b, offset: 0, range: vk::WHOLE_SIZE }]);
                }
            }
            let writes: Vec<vk::WriteDescriptorSet> = sets
                .iter()
                .enumerate()
                .flat_map(|(k, &set)| {
                    let infos = &infos;
                    (0..7).map(move |b| {
                        vk::WriteDescriptorSet::default()
                            .dst_set(set)
                            .dst_binding(b as u32)
                            .descriptor_type(vk::DescriptorType::STORAGE_BUFFER)
                            .buffer_info(&infos[k * 7 + b])
                    })
                })
                .collect();
            // SAFETY: the sets are not in use (just allocated); the buffers are alive.
            unsafe { d.update_descriptor_sets(&writes, &[]) };
            cf.sets = casters.into_iter().zip(sets).collect();
        }
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
        if cf.metas.is_empty() {
            return Ok(());
        }
        let Some(records) = slot.compute.records.as_ref() else { return Ok(()) };
        let bytes = records.read()?;
        let words: &[u32] =
            bytemuck::try_cast_slice(&bytes[..cf.records.len() * 4]).map_err(|e| Error::Internal(format!("compute records: {e}")))?;
        cf.read_back(words, &mut frame.lights, &mut frame.totals)
    }
}
