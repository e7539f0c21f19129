//! GPU timing: a timestamp query pool per ring slot, sized for the frame's lights (no fixed
//! cap: 1000 lights get their 4000 queries). Timestamps are written outside rendering
//! instances (on lavapipe, those written inside do not include rasterisation).

use ash::vk;
use std::cell::Cell;
use umbrage::error::{Error, Result};
use umbrage::gpu::Context;

pub(crate) struct Timer {
    pool: vk::QueryPool,
    capacity: u32,
    next: Cell<u32>,
    enabled: bool,
}

impl Timer {
    pub fn new(ctx: &Context) -> Timer {
        Timer { pool: vk::QueryPool::null(), capacity: 0, next: Cell::new(0), enabled: ctx.features.timestamps }
    }

    /// Makes room for `queries` timestamps (the slot's previous frame has retired) and
    /// records the pool's reset.
    pub fn begin(&mut self, ctx: &Context, cb: vk::CommandBuffer, queries: u32) -> Result<()> {
        self.next.set(0);
        if !self.enabled {
            return Ok(());
        }
        if self.capacity < queries {
            let capacity = queries.next_power_of_two().max(64);
            // SAFETY: the old pool is no longer used (the slot retired); creation on a valid device.
            unsafe {
                if self.pool != vk::QueryPool::null() {
                    ctx.device.destroy_query_pool(self.pool, None);
                    self.pool = vk::QueryPool::null();
                    self.capacity = 0;
                }
                self.pool = ctx
                    .device
                    .create_query_pool(&vk::QueryPoolCreateInfo::default().query_type(vk::QueryType::TIMESTAMP).query_count(capacity), None)
                    .map_err(Error::vk("vkCreateQueryPool"))?;
            }
            self.capacity = capacity;
        }
        // SAFETY: `cb` is recording outside a rendering instance; the pool has `capacity` queries.
        unsafe { ctx.device.cmd_reset_query_pool(cb, self.pool, 0, self.capacity) };
        Ok(())
    }

    /// Writes a timestamp after `stage` and returns its index (`None` without timestamps).
    pub fn stamp(&self, ctx: &Context, cb: vk::CommandBuffer, stage: vk::PipelineStageFlags2) -> Option<u32> {
        if !self.enabled || self.next.get() >= self.capacity {
            return None;
        }
        let q = self.next.get();
        self.next.set(q + 1);
        // SAFETY: `cb` is recording outside a rendering instance; `q` was reset by `begin`.
        unsafe { ctx.device.cmd_write_timestamp2(cb, stage, self.pool, q) };
        Some(q)
    }

    /// The frame's timestamps, in ticks (after the slot's fence).
    pub fn read(&self, ctx: &Context) -> Result<Vec<u64>> {
        let n = self.next.get() as usize;
        let mut raw = vec![0u64; n];
        if n > 0 {
            // SAFETY: the fence wait before this call guarantees the queries are available.
            unsafe {
                ctx.device.get_query_pool_results(self.pool, 0, &mut raw, vk::QueryResultFlags::TYPE_64 | vk::QueryResultFlags::WAIT)
            }
            .map_err(Error::vk("vkGetQueryPoolResults"))?;
        }
        Ok(raw)
    }

    pub fn destroy(&mut self, ctx: &Context) {
        if self.pool != vk::QueryPool::null() {
            // SAFETY: the owner waited for the device.
            unsafe { ctx.device.destroy_query_pool(self.pool, None) };
            self.pool = vk::QueryPool::null();
        }
    }
}

/// A pair of timestamps around a piece of work.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Span {
    pub begin: Option<u32>,
    pub end: Option<u32>,
}

impl Span {
    /// Milliseconds between the two stamps (0 when either is missing).
    pub fn ms(&self, raw: &[u64], period_ns: f32) -> f64 {
        match (self.begin, self.end) {
            (Some(a), Some(b)) if (b as usize) < raw.len() => {
                raw[b as usize].wrapping_sub(raw[a as usize]) as f64 * period_ns as f64 * 1e-6
            }
            _ => 0.0,
        }
    }
}
