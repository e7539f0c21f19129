//! The shadow pass's counters (`FrameSettings::counters`): per light, pipeline statistics
//! around the determination (primitives in, vertex invocations, primitives out of clipping)
//! and an occlusion query around its counting variant
//! ([`Diagnostics::cmd_count_rasterised`](umbrage::pass::diagnostics::Diagnostics::cmd_count_rasterised)):
//! with `occlusionQueryPrecise`, the exact number of fragments the volumes rasterise.
//! One pair of query pools per ring slot, grown with the number of lights.

use ash::vk;
use umbrage::error::{Error, Result};
use umbrage::gpu::Context;

/// What the counters measured in one frame (all lights).
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct PassCounters {
    /// Fragments the determination rasterised (depth and stencil always passing), summed over
    /// lights; `None` without `occlusionQueryPrecise` (an imprecise query only says "some").
    pub stencil_fragments: Option<u64>,
    /// The same per light, in light order (empty when `stencil_fragments` is `None`).
    pub per_light_fragments: Vec<u64>,
    /// Input-assembly primitives of the determination (pipeline statistics; `None` without
    /// `pipelineStatisticsQuery`).
    pub primitives: Option<u64>,
    /// Vertex-shader invocations of the determination.
    pub vertex_invocations: Option<u64>,
    /// Primitives out of clipping (what reached the rasteriser).
    pub clipped_primitives: Option<u64>,
}

const STATS: [vk::QueryPipelineStatisticFlags; 3] = [
    vk::QueryPipelineStatisticFlags::INPUT_ASSEMBLY_PRIMITIVES,
    vk::QueryPipelineStatisticFlags::VERTEX_SHADER_INVOCATIONS,
    vk::QueryPipelineStatisticFlags::CLIPPING_PRIMITIVES,
];

/// A slot's query pools.
pub(crate) struct CounterPools {
    occlusion: vk::QueryPool,
    stats: vk::QueryPool,
    capacity: u32,
    lights: u32,
    precise: bool,
    statistics: bool,
}

impl CounterPools {
    pub fn new(ctx: &Context) -> CounterPools {
        CounterPools {
            occlusion: vk::QueryPool::null(),
            stats: vk::QueryPool::null(),
            capacity: 0,
            lights: 0,
            precise: ctx.features.occlusion_query_precise,
            statistics: ctx.features.pipeline_statistics_query,
        }
    }

    /// Makes room for `lights` queries of each kind (the slot's previous frame retired) and
    /// records their reset.
    pub fn begin(&mut self, ctx: &Context, cb: vk::CommandBuffer, lights: u32) -> Result<()> {
        self.lights = lights;
        if lights == 0 {
            return Ok(());
        }
        if self.capacity < lights {
            self.destroy(ctx);
            let capacity = lights.next_power_of_two().max(8);
            let flags = STATS.iter().fold(vk::QueryPipelineStatisticFlags::empty(), |a, &f| a | f);
            // SAFETY: creation on a valid device; the old pools were destroyed above (unused:
            // the slot retired).
            unsafe {
                self.occlusion = ctx
                    .device
                    .create_query_pool(&vk::QueryPoolCreateInfo::default().query_type(vk::QueryType::OCCLUSION).query_count(capacity), None)
                    .map_err(Error::vk("vkCreateQueryPool"))?;
                if self.statistics {
                    let info = vk::QueryPoolCreateInfo::default()
                        .query_type(vk::QueryType::PIPELINE_STATISTICS)
                        .query_count(capacity)
                        .pipeline_statistics(flags);
                    self.stats = ctx.device.create_query_pool(&info, None).map_err(Error::vk("vkCreateQueryPool"))?;
                }
            }
            self.capacity = capacity;
        }
        // SAFETY: `cb` is recording outside a rendering instance; the pools have `capacity` queries.
        unsafe {
            ctx.device.cmd_reset_query_pool(cb, self.occlusion, 0, self.capacity);
            if self.statistics {
                ctx.device.cmd_reset_query_pool(cb, self.stats, 0, self.capacity);
            }
        }
        Ok(())
    }

    /// Begins (`begin`) or ends light `li`'s pipeline-statistics query.
    pub fn statistics(&self, ctx: &Context, cb: vk::CommandBuffer, li: u32, begin: bool) {
        if !self.statistics || li >= self.lights {
            return;
        }
        // SAFETY: `cb` is recording outside a rendering instance; query `li` was reset by
        // `begin` and is begun and ended once each in this command buffer.
        unsafe {
            match begin {
                true => ctx.device.cmd_begin_query(cb, self.stats, li, vk::QueryControlFlags::empty()),
                false => ctx.device.cmd_end_query(cb, self.stats, li),
            }
        }
    }

    /// Begins (`begin`) or ends light `li`'s occlusion query (precise when the device can).
    pub fn occlusion(&self, ctx: &Context, cb: vk::CommandBuffer, li: u32, begin: bool) {
        if li >= self.lights {
            return;
        }
        let control = if self.precise { vk::QueryControlFlags::PRECISE } else { vk::QueryControlFlags::empty() };
        // SAFETY: as `statistics`; PRECISE only with occlusionQueryPrecise enabled.
        unsafe {
            match begin {
                true => ctx.device.cmd_begin_query(cb, self.occlusion, li, control),
                false => ctx.device.cmd_end_query(cb, self.occlusion, li),
            }
        }
    }

    /// The frame's counts (after the slot's fence).
    pub fn read(&self, ctx: &Context) -> Result<PassCounters> {
        let n = self.lights as usize;
        let mut out = PassCounters::default();
        if n == 0 {
            out.stencil_fragments = self.precise.then_some(0);
            out.primitives = self.statistics.then_some(0);
            out.vertex_invocations = out.primitives;
            out.clipped_primitives = out.primitives;
            return Ok(out);
        }
        let wait = vk::QueryResultFlags::TYPE_64 | vk::QueryResultFlags::WAIT;
        if self.precise {
            let mut occ = vec![0u64; n];
            // SAFETY: the fence wait before this call guarantees the queries completed.
            unsafe { ctx.device.get_query_pool_results(self.occlusion, 0, &mut occ, wait) }.map_err(Error::vk("vkGetQueryPoolResults"))?;
            out.stencil_fragments = Some(occ.iter().sum());
            out.per_light_fragments = occ;
        }
        if self.statistics {
            let mut raw = vec![[0u64; 3]; n];
            // SAFETY: as above; one result of three u64 per query (the three flags).
            unsafe { ctx.device.get_query_pool_results(self.stats, 0, &mut raw, wait) }.map_err(Error::vk("vkGetQueryPoolResults"))?;
            out.primitives = Some(raw.iter().map(|r| r[0]).sum());
            out.vertex_invocations = Some(raw.iter().map(|r| r[1]).sum());
            out.clipped_primitives = Some(raw.iter().map(|r| r[2]).sum());
        }
        Ok(out)
    }

    pub fn destroy(&mut self, ctx: &Context) {
        // SAFETY: the owner waited for the device (or the slot retired).
        unsafe {
            if self.occlusion != vk::QueryPool::null() {
                ctx.device.destroy_query_pool(self.occlusion, None);
            }
            if self.stats != vk::QueryPool::null() {
                ctx.device.destroy_query_pool(self.stats, None);
            }
        }
        self.occlusion = vk::QueryPool::null();
        self.stats = vk::QueryPool::null();
        self.capacity = 0;
    }
}
