//! The compute streaming-read limit: a compute shader (`shaders/compute_read.wgsl`) that reads
//! one 16-byte plane per invocation, tests it against a light and sets a bit where it faces it
//! (the GPU silhouettes' `facing` stage without its job table and exact fallback), at 2^20,
//! 2^21 and 2^22 planes (16 to 64 MiB: beyond the caches), the best rate kept. The silhouette
//! pass reads 16 bytes per
//! triangle (its plane) and 16 per edge (the edge table): its time against these bytes at this
//! rate is how near it runs to what the device allows a plain compute read
//! (`bench::classic`'s `silhouette_limit_fraction`).

use super::saturate::time_gpu;
use crate::shaders;
use ash::vk;
use bytemuck::{Pod, Zeroable};
use gpu_allocator::MemoryLocation;
use umbrage::error::{Error, Result};
use umbrage::gpu::descriptors::{pipeline_layout, storage_set_layout};
use umbrage::gpu::{pipeline, Buffer, Context};

/// The push block of `shaders/compute_read.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct Push {
    light: [f32; 4],
    n: u32,
    pad: [u32; 3],
}

/// The measured limit.
#[derive(Clone, Debug, Default)]
pub struct ComputeRead {
    /// Peak bytes read per second, GiB / s.
    pub gib_s: f64,
    /// The sweep: `[planes, GiB / s]` per point.
    pub sweep: Vec<[f64; 2]>,
}

/// The objects made, destroyed whatever happens.
#[derive(Default)]
struct Made {
    set_layout: vk::DescriptorSetLayout,
    layout: vk::PipelineLayout,
    pipeline: vk::Pipeline,
    pool: vk::DescriptorPool,
    queries: vk::QueryPool,
    buffers: Vec<Buffer>,
}

/// Measures the limit: `reps` timed repetitions a point (median), at most `max_planes` planes.
pub fn measure(ctx: &Context, reps: usize, max_planes: u64) -> Result<ComputeRead> {
    let mut made = Made::default();
    let r = measure_with(ctx, reps, max_planes, &mut made);
    // SAFETY: one_shot waited for every submission: nothing is in use; null handles are ignored.
    unsafe {
        let d = &ctx.device;
        d.destroy_pipeline(made.pipeline, None);
        d.destroy_pipeline_layout(made.layout, None);
        d.destroy_descriptor_set_layout(made.set_layout, None);
        d.destroy_descriptor_pool(made.pool, None);
        d.destroy_query_pool(made.queries, None);
    }
    for b in &mut made.buffers {
        b.destroy(ctx);
    }
    r
}

fn measure_with(ctx: &Context, reps: usize, max_planes: u64, made: &mut Made) -> Result<ComputeRead> {
    if !ctx.features.timestamps {
        return Err(Error::Unsupported("the compute read limit needs timestamp queries".into()));
    }
    let d = &ctx.device;
    let max_planes = max_planes.max(1 << 16).min(ctx.limits.max_storage_buffer_range as u64 / 16);
    // destroyed by `measure`
    made.set_layout = storage_set_layout(ctx, 2, vk::ShaderStageFlags::COMPUTE)?;
    made.layout = pipeline_layout(ctx, &[made.set_layout], std::mem::size_of::<Push>() as u32, vk::ShaderStageFlags::COMPUTE)?;
    let module = pipeline::shader_module(ctx, shaders::COMPUTE_READ_WGSL)?;
    let stage = vk::PipelineShaderStageCreateInfo::default().stage(vk::ShaderStageFlags::COMPUTE).module(module).name(c"stream");
    let info = [vk::ComputePipelineCreateInfo::default().stage(stage).layout(made.layout)];
    // SAFETY: valid device, module and layout; the create info points at locals.
    let created = unsafe { d.create_compute_pipelines(vk::PipelineCache::null(), &info, None) };
    // SAFETY: the pipeline (if any) keeps what it needs of the module.
    unsafe { d.destroy_shader_module(module, None) };
    made.pipeline = created.map_err(|(_, e)| Error::vk("vkCreateComputePipelines")(e))?[0];
    // SAFETY: creation on a valid device; destroyed by `measure`.
    made.queries =
        unsafe { d.create_query_pool(&vk::QueryPoolCreateInfo::default().query_type(vk::QueryType::TIMESTAMP).query_count(2), None) }
            .map_err(Error::vk("vkCreateQueryPool"))?;
    let sizes = [vk::DescriptorPoolSize { ty: vk::DescriptorType::STORAGE_BUFFER, descriptor_count: 2 }];
    // SAFETY: creation on a valid device; destroyed by `measure`.
    made.pool = unsafe { d.create_descriptor_pool(&vk::DescriptorPoolCreateInfo::default().max_sets(1).pool_sizes(&sizes), None) }
        .map_err(Error::vk("vkCreateDescriptorPool"))?;

    // Planes in device-local memory (copied from a staging buffer): alternately facing and
    // not, as a closed mesh's triangles are about half and half.
    let planes: Vec<[f32; 4]> = (0..max_planes).map(|i| if i % 2 == 0 { [0.0, 1.0, 0.0, -0.5] } else { [0.0, -1.0, 0.0, 0.5] }).collect();
    let bytes = bytemuck::cast_slice::<_, u8>(&planes);
    let staging = Buffer::with_data(ctx, "compute read (staging)", bytes, vk::BufferUsageFlags::TRANSFER_SRC)?;
    made.buffers.push(staging);
    let usage = vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::TRANSFER_DST;
    let device_planes = Buffer::new(ctx, "compute read planes", bytes.len() as u64, usage, MemoryLocation::GpuOnly)?;
    made.buffers.push(device_planes);
    let bits_bytes = max_planes.div_ceil(32) * 4;
    let bits = Buffer::new(ctx, "compute read bits", bits_bytes, usage, MemoryLocation::GpuOnly)?;
    made.buffers.push(bits);
    let (staging, planes_raw, bits_raw) = (made.buffers[0].raw, made.buffers[1].raw, made.buffers[2].raw);
    ctx.one_shot(|cb| {
        // SAFETY: `cb` is recording; both buffers are large enough.
        unsafe { d.cmd_copy_buffer(cb, staging, planes_raw, &[vk::BufferCopy { src_offset: 0, dst_offset: 0, size: bytes.len() as u64 }]) };
    })?;
    // SAFETY: the pool has room for one set of this layout.
    let set = unsafe {
        d.allocate_descriptor_sets(&vk::DescriptorSetAllocateInfo::default().descriptor_pool(made.pool).set_layouts(&[made.set_layout]))
    }
    .map_err(Error::vk("vkAllocateDescriptorSets"))?[0];
    let infos = [
        [vk::DescriptorBufferInfo { buffer: planes_raw, offset: 0, range: vk::WHOLE_SIZE }],
        [vk::DescriptorBufferInfo { buffer: bits_raw, offset: 0, range: vk::WHOLE_SIZE }],
    ];
    let writes = umbrage::gpu::descriptors::storage_buffer_writes(set, &infos);
    // SAFETY: the set is not in use; the buffers are alive.
    unsafe { d.update_descriptor_sets(&writes, &[]) };

    // From a quarter of the largest size up: 16 MiB and more at the default 2^22, beyond the
    // caches, so that the rate is the memory stream's (a smaller table, resident in a cache, can
    // run above it: its fraction is then over 1).
    let mut out = ComputeRead::default();
    let mut n = (max_planes / 4).max(1 << 16);
    while n <= max_planes {
        let ms = time(ctx, made, set, n, bits_bytes, reps)?;
        let gib_s = (n * 16) as f64 / (ms.max(1e-6) * 1e-3) / (1u64 << 30) as f64;
        out.sweep.push([n as f64, gib_s]);
        out.gib_s = out.gib_s.max(gib_s);
        if ms > 400.0 {
            break;
        }
        n *= 2;
    }
    Ok(out)
}

/// The median GPU time of `reps` dispatches over `n` planes (after one warm-up), ms.
fn time(ctx: &Context, made: &Made, set: vk::DescriptorSet, n: u64, bits_bytes: u64, reps: usize) -> Result<f64> {
    use vk::AccessFlags2 as A;
    use vk::PipelineStageFlags2 as S;
    let d = &ctx.device;
    let groups = n.div_ceil(256) as u32;
    let push = Push { light: [0.0, 1.0, 0.0, 1.0], n: n as u32, pad: [0; 3] };
    let bits_raw = made.buffers[2].raw;
    let prep = |cb: vk::CommandBuffer| {
        // SAFETY: `cb` is recording (one_shot waits for it); the bits buffer outlives it.
        unsafe { d.cmd_fill_buffer(cb, bits_raw, 0, bits_bytes, 0) };
        umbrage::gpu::resources::memory_barrier(
            ctx,
            cb,
            (S::TRANSFER, A::TRANSFER_WRITE),
            (S::COMPUTE_SHADER, A::SHADER_READ | A::SHADER_WRITE),
        );
    };
    let timed = |cb: vk::CommandBuffer| {
        // SAFETY: `cb` is recording (one_shot waits for it); the pipeline, layout and set
        // outlive it; the set's buffers hold `n` planes and their bits.
        unsafe {
            d.cmd_bind_pipeline(cb, vk::PipelineBindPoint::COMPUTE, made.pipeline);
            d.cmd_bind_descriptor_sets(cb, vk::PipelineBindPoint::COMPUTE, made.layout, 0, &[set], &[]);
            d.cmd_push_constants(cb, made.layout, vk::ShaderStageFlags::COMPUTE, 0, bytemuck::bytes_of(&push));
            d.cmd_dispatch(cb, groups.min(65535), groups.div_ceil(65535), 1);
        }
    };
    time_gpu(ctx, made.queries, reps, &prep, &timed)
}
