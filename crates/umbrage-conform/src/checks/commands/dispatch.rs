//! The `commands.*` checks of what `--method compute` records besides its shaders'
//! arithmetic: `fill_buffer`, `dispatch` and `dispatch_indirect` (the parent module says what
//! each holds). The compute ones run `shaders/conform_dispatch.wgsl` (SPIR-V 1.0, so Vulkan 1.0
//! devices with `VK_KHR_storage_buffer_storage_class` run them too), whose invocations record
//! what they are (ids, builtins) into one buffer of u32 words with atomics; every word of that
//! buffer is compared with the CPU model.

use super::*;
use crate::shaders;
use umbrage::gpu::descriptors::{pipeline_layout, Binding, DescriptorSet};
use umbrage::gpu::pipeline::shader_module;
use vk::AccessFlags2 as A;
use vk::PipelineStageFlags2 as S;

/// A word no command wrote: the buffers start as [`UNTOUCHED`] bytes.
const PATTERN: u32 = u32::from_le_bytes([UNTOUCHED; 4]);
/// `conform_dispatch.wgsl`'s region header: words before the per-group words.
const HEADER: usize = 8;
/// `count`'s workgroup size (x).
const COUNT_WG: u32 = 4;
/// `mark`'s workgroup size (x).
const MARK_WG: u32 = 2;
/// Most workgroups of one dispatch dimension, as `--method compute` splits them.
const MAX_GROUPS: u32 = 65535;

fn needs_compute(ctx: &Context, name: &str) -> Option<CheckResult> {
    (!ctx.features.storage_buffer_storage_class).then(|| {
        let v = &ctx.info.api_version;
        CheckResult::skipped(
            name,
            &format!(
                "skipped: the compute module's storage buffers (SPIR-V 1.0) need Vulkan 1.1 or VK_KHR_storage_buffer_storage_class; \
                 the device has Vulkan {v} without it"
            ),
        )
    })
}

/// `conform_dispatch.wgsl`'s push constants: `n`, `base`, `args`, `counts`, `bits`, padding.
fn push(n: u32, base: usize, args: usize, counts: usize, bits: usize) -> [u32; 8] {
    [n, base as u32, args as u32, counts as u32, bits as u32, 0, 0, 0]
}

/// A workgroup id as the shader packs it (x in bits 0..16, y in 16..24, z in 24..32).
fn pack_id(x: u32, y: u32, z: u32) -> u32 {
    x | (y << 16) | (z << 24)
}

/// The compute pipelines of `conform_dispatch.wgsl` over one storage buffer (binding 0), and
/// their layout; destroyed (after the device is idle) on drop.
struct Compute<'a> {
    ctx: &'a Context,
    set: Option<DescriptorSet>,
    layout: vk::PipelineLayout,
    /// `count`, `grow`, `mark`.
    pipes: Vec<vk::Pipeline>,
}

impl<'a> Compute<'a> {
    fn new(ctx: &'a Context, buffer: vk::Buffer) -> Result<Compute<'a>> {
        let mut c = Compute { ctx, set: None, layout: vk::PipelineLayout::null(), pipes: Vec::new() };
        let set = DescriptorSet::with_stages(ctx, &[Binding::StorageBuffer(buffer)], vk::ShaderStageFlags::COMPUTE)?;
        let set_layout = set.layout;
        c.set = Some(set);
        c.layout = pipeline_layout(ctx, &[set_layout], 32, vk::ShaderStageFlags::COMPUTE)?;
        let module = shader_module(ctx, shaders::CONFORM_DISPATCH_WGSL)?;
        let mut r = Ok(());
        for entry in [c"count", c"grow", c"mark"] {
            let stage = vk::PipelineShaderStageCreateInfo::default().stage(vk::ShaderStageFlags::COMPUTE).module(module).name(entry);
            let info = [vk::ComputePipelineCreateInfo::default().stage(stage).layout(c.layout)];
            // SAFETY: valid device, module and layout; the create info points at locals.
            match unsafe { ctx.device.create_compute_pipelines(vk::PipelineCache::null(), &info, None) } {
                Ok(p) => c.pipes.push(p[0]),
                Err((_, e)) => {
                    r = Err(vkerr("vkCreateComputePipelines")(e));
                    break;
                }
            }
        }
        // SAFETY: the pipelines keep what they need of the module; nothing else uses it.
        unsafe { ctx.device.destroy_shader_module(module, None) };
        r.map(|()| c)
    }

    /// Binds the set and pipeline `k` (0 `count`, 1 `grow`, 2 `mark`) and pushes `push`.
    ///
    /// # Safety
    /// `cb` is recording outside a rendering instance on the context's device.
    unsafe fn bind(&self, cb: vk::CommandBuffer, k: usize, push: [u32; 8]) {
        let d = &self.ctx.device;
        let sets: Vec<vk::DescriptorSet> = self.set.iter().map(|s| s.set).collect();
        // SAFETY: the caller's contract; the set, layout and pipeline live until `self` drops
        // (after the device is idle); the push range is the layout's 32 bytes.
        unsafe {
            d.cmd_bind_pipeline(cb, vk::PipelineBindPoint::COMPUTE, self.pipes[k]);
            d.cmd_bind_descriptor_sets(cb, vk::PipelineBindPoint::COMPUTE, self.layout, 0, &sets, &[]);
            d.cmd_push_constants(cb, self.layout, vk::ShaderStageFlags::COMPUTE, 0, bytemuck::bytes_of(&push));
        }
    }
}

impl Drop for Compute<'_> {
    fn drop(&mut self) {
        let d = &self.ctx.device;
        // SAFETY: after the wait nothing is in use; every handle was created on this device
        // (null ones are ignored).
        unsafe {
            let _ = d.device_wait_idle();
            for p in self.pipes.drain(..) {
                d.destroy_pipeline(p, None);
            }
            d.destroy_pipeline_layout(self.layout, None);
        }
        if let Some(mut s) = self.set.take() {
            s.destroy(self.ctx);
        }
    }
}

/// A host-visible buffer of `words` u32 words, every byte [`UNTOUCHED`], usable as a storage
/// buffer, an indirect-command buffer and a fill destination.
fn storage_buffer(s: &mut Scratch<'_>, words: usize) -> Result<usize> {
    let usage = vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::INDIRECT_BUFFER | vk::BufferUsageFlags::TRANSFER_DST;
    let mut b = Buffer::new(s.ctx, "conform-dispatch", (words * 4) as u64, usage, MemoryLocation::GpuToCpu)?;
    let filled = b.write(0, &vec![UNTOUCHED; words * 4]);
    s.buffers.push(b);
    filled?;
    Ok(s.buffers.len() - 1)
}

fn words_of(bytes: &[u8]) -> Vec<u32> {
    bytes.chunks_exact(4).map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]])).collect()
}

/// Compares `got` with `want` over `range`: the mismatches, and the first three described
/// (`name[i]`: got, want).
fn mismatches(got: &[u32], want: &[u32], range: std::ops::Range<usize>, name: &str) -> (usize, Vec<String>) {
    let base = range.start;
    let bad: Vec<usize> = range.filter(|&i| got[i] != want[i]).collect();
    let first = bad.iter().take(3).map(|&i| format!("{name}[{}] = {:#x}, want {:#x}", i - base, got[i], want[i])).collect();
    (bad.len(), first)
}

/// `commands.fill_buffer`: `vkCmdFillBuffer` of sub-ranges of a 1022-byte buffer holding a
/// pattern: at offsets, overlapping an earlier fill (after a barrier), and `VK_WHOLE_SIZE` from
/// an offset whose remainder is not a multiple of 4 (the nearest smaller multiple is filled):
/// every byte.
pub fn fill_buffer(ctx: &Context) -> Result<CheckResult> {
    let size = 1022usize;
    let mut s = Scratch::new(ctx);
    let b = s.readback(size as u64)?;
    let pattern: Vec<u8> = (0..size).map(|k| (k * 29 + 11) as u8).collect();
    s.buffers[b].write(0, &pattern)?;
    let buf = s.buffers[b].raw;
    // (offset, size, data), in order: the third overlaps the end of the first.
    let whole = vk::WHOLE_SIZE;
    let fills = [(12u64, 200u64, 0xdead_beefu32), (300, 4, 0x0102_0304), (196, 24, 0x55aa_33cc), (400, 100, 0), (1000, whole, 0xa5c3_0f81)];
    ctx.one_shot(|cb| {
        for (k, &(offset, n, data)) in fills.iter().enumerate() {
            if k == 2 {
                memory_barrier(ctx, cb, (S::ALL_TRANSFER, A::TRANSFER_WRITE), (S::ALL_TRANSFER, A::TRANSFER_WRITE));
            }
            // SAFETY: recording outside rendering; offsets and sizes are multiples of 4 (or
            // VK_WHOLE_SIZE) within the buffer, a TRANSFER_DST buffer alive until the wait.
            unsafe { ctx.device.cmd_fill_buffer(cb, buf, offset, n, data) };
        }
        transfer_to_host_barrier(ctx, cb);
    })?;
    let mut want = pattern.clone();
    for (offset, n, data) in fills {
        let end = if n == whole { offset as usize + (size - offset as usize) / 4 * 4 } else { (offset + n) as usize };
        for (k, byte) in want.iter_mut().enumerate().take(end).skip(offset as usize) {
            *byte = data.to_le_bytes()[k % 4];
        }
    }
    if crate::value_images::skewed() {
        want[0] ^= 0xff;
    }
    let got = s.buffers[b].read()?;
    let bad: Vec<usize> = (0..size).filter(|&k| got[k] != want[k]).collect();
    if !bad.is_empty() {
        crate::value_images::words("bytes", &want, got);
    }
    let mut numbers = serde_json::Map::new();
    numbers.insert("byte_mismatches".into(), json!(bad.len()));
    let fails = match bad.first() {
        Some(&k) => vec![format!("{} of {size} bytes differ (first at byte {k}: {:#04x}, want {:#04x})", bad.len(), got[k], want[k])],
        None => vec![],
    };
    let what = "vkCmdFillBuffer at offsets, overlapping an earlier fill, VK_WHOLE_SIZE to the last whole word of a 1022-byte \
                buffer: every byte, nothing else written";
    Ok(CheckResult::from_fails("fill_buffer", fails, numbers, what))
}

/// Where `commands.dispatch` puts what it records, in words of its buffer.
struct CountLayout {
    /// Workgroups `count` must count, and the invocations (ids) among them.
    groups: u32,
    n: u32,
    /// The dispatch: `(min(groups, 65535), ceil(groups / 65535))`.
    x: u32,
    y: u32,
    /// The counted region: header, two words per launched group, a counter per launched
    /// invocation, the invocation bitmap; cleared by `vkCmdFillBuffer` first.
    base: usize,
    counts: usize,
    bits: usize,
    end: usize,
    /// The region the empty dispatches would write (never cleared) and the buffer's end.
    zero_base: usize,
    total: usize,
}

impl CountLayout {
    fn new(groups: u32) -> CountLayout {
        let (x, y) = (groups.min(MAX_GROUPS), groups.div_ceil(MAX_GROUPS));
        let launched = (x * y) as usize;
        let base = 4;
        let counts = HEADER + 2 * launched;
        let bits = counts + launched * COUNT_WG as usize;
        let end = base + bits + (launched * COUNT_WG as usize).div_ceil(32);
        let zero_base = end + 16;
        CountLayout { groups, n: groups * COUNT_WG - 3, x, y, base, counts, bits, end, zero_base, total: zero_base + 64 + 16 }
    }

    /// What the buffer holds after the dispatches, as the spec has it.
    fn model(&self) -> Vec<u32> {
        let mut w = vec![PATTERN; self.total];
        w[self.base..self.end].fill(0);
        let h = &mut w[self.base..self.base + HEADER];
        let launched = self.x * self.y;
        h.copy_from_slice(&[self.n, self.n, self.x, self.y, 1, launched, launched * COUNT_WG, 0]);
        for g in 0..launched {
            let at = self.base + HEADER + 2 * g as usize;
            w[at] = COUNT_WG * (pack_id(g % self.x, g / self.x, 0) + 1);
            w[at + 1] = (1 << COUNT_WG) - 1;
        }
        for id in 0..self.n as usize {
            w[self.base + self.counts + id] = 1;
            w[self.base + self.bits + id / 32] |= 1 << (id % 32);
        }
        w
    }
}

/// `commands.dispatch`: `vkCmdFillBuffer` clears a region, then one `vkCmdDispatch` of
/// `count` (4 invocations a group) with the 2D group counts `--method compute` uses,
/// `(65535, 2)` for 70001 groups: every launched group runs once with its own `workgroup_id`
/// and every local index, sees `num_workgroups` = (65535, 2, 1), and exactly the ids below n
/// = 280001 count themselves once (a counter each, a bit each in words shared across
/// workgroups, `atomicAdd`/`atomicOr`/`atomicMax` on shared header words); then dispatches with
/// a group count of 0 (`(0, 1, 1)`, `(5, 0, 1)`) write nothing.
pub fn dispatch(ctx: &Context) -> Result<CheckResult> {
    if let Some(r) = needs_compute(ctx, "dispatch") {
        return Ok(r);
    }
    let l = CountLayout::new(70_001);
    let mut s = Scratch::new(ctx);
    let b = storage_buffer(&mut s, l.total)?;
    let buf = s.buffers[b].raw;
    let compute = Compute::new(ctx, buf)?;
    ctx.one_shot(|cb| {
        let d = &ctx.device;
        // SAFETY: recording outside rendering; the fill's offset and size are multiples of 4
        // within the buffer; the pushes' offsets keep every write inside it; the buffer and
        // the pipelines outlive the wait.
        unsafe {
            d.cmd_fill_buffer(cb, buf, (l.base * 4) as u64, ((l.end - l.base) * 4) as u64, 0);
            memory_barrier(ctx, cb, (S::TRANSFER, A::TRANSFER_WRITE), (S::COMPUTE_SHADER, A::SHADER_READ | A::SHADER_WRITE));
            compute.bind(cb, 0, push(l.n, l.base, 0, l.counts, l.bits));
            d.cmd_dispatch(cb, l.x, l.y, 1);
            compute.bind(cb, 0, push(8, l.zero_base, 0, 16, 32));
            d.cmd_dispatch(cb, 0, 1, 1);
            d.cmd_dispatch(cb, 5, 0, 1);
        }
        memory_barrier(ctx, cb, (S::COMPUTE_SHADER, A::SHADER_WRITE), (S::HOST, A::HOST_READ));
    })?;
    let got = words_of(s.buffers[b].read()?);
    let mut want = l.model();
    if crate::value_images::skewed() {
        want[0] ^= 1;
    }
    let (o, h, g, c, m) = (l.base, l.base + HEADER, l.base + l.counts, l.base + l.bits, l.end);
    let parts = [
        ("before", 0..o),
        ("header", o..h),
        ("groups", h..g),
        ("counts", g..c),
        ("bitmap", c..m),
        ("after", m..l.zero_base),
        ("zero_dispatches", l.zero_base..l.total),
    ];
    let mut numbers = serde_json::Map::new();
    let mut fails = Vec::new();
    for (name, range) in parts {
        let (bad, first) = mismatches(&got, &want, range, name);
        numbers.insert(format!("{name}_word_mismatches"), json!(bad));
        if bad > 0 {
            fails.push(format!("{name}: {bad} words differ ({})", first.join(", ")));
        }
    }
    if !fails.is_empty() {
        crate::value_images::words("words", &want, &got);
    }
    numbers.insert("header".into(), json!(&got[o..h]));
    numbers.insert("dispatch".into(), json!([l.x, l.y, 1]));
    numbers.insert("groups".into(), json!(l.groups));
    let what = "vkCmdDispatch (65535, 2, 1) after vkCmdFillBuffer: every launched group once with its workgroup_id, num_workgroups, \
                every local index; exactly ids < 280001 counted once (atomicAdd, atomicOr, atomicMax); group counts of 0 write nothing";
    Ok(CheckResult::from_fails("dispatch", fails, numbers, what))
}

/// `commands.dispatch_indirect`: a `VkDispatchIndirectCommand` at byte offset 20 of a
/// host-visible storage buffer, written (2, 1, 3) by the host, grown by a dispatch's
/// `atomicMax` to (17, 2, 3) as `--method compute` grows its lists' sizes, then read (after a
/// compute-write -> indirect-read barrier) by `vkCmdDispatchIndirect`: exactly its 102 groups
/// run, each once with its `workgroup_id`, and `num_workgroups` is the command's; a command
/// with x = 0 (y, z = 4) dispatches nothing; the decoy words before the command stay.
pub fn dispatch_indirect(ctx: &Context) -> Result<CheckResult> {
    if let Some(r) = needs_compute(ctx, "dispatch_indirect") {
        return Ok(r);
    }
    // Words: 0..5 decoys (read by a command at the wrong offset), 5..8 the grown command,
    // 8..11 the empty one, then the marked region (cleared by a fill) and the region the empty
    // command would mark (never cleared).
    let (args, zero_args, base, zero_base, total) = (5usize, 8usize, 16usize, 16 + HEADER + 128, 16 + 2 * (HEADER + 128) + 8);
    let (x, y, z) = (17u32, 2u32, 3u32);
    let mut s = Scratch::new(ctx);
    let b = storage_buffer(&mut s, total)?;
    let mut init = vec![PATTERN; total];
    init[..11].copy_from_slice(&[3, 3, 3, 3, 3, 2, 1, z, 0, 4, 4]);
    let bytes: Vec<u8> = init.iter().flat_map(|w| w.to_le_bytes()).collect();
    s.buffers[b].write(0, &bytes)?;
    let buf = s.buffers[b].raw;
    let compute = Compute::new(ctx, buf)?;
    ctx.one_shot(|cb| {
        let d = &ctx.device;
        // SAFETY: as in `dispatch`; the indirect offsets are multiples of 4 and the commands
        // lie within the buffer (an INDIRECT_BUFFER), their group counts within the limits.
        unsafe {
            d.cmd_fill_buffer(cb, buf, (base * 4) as u64, ((HEADER + 128) * 4) as u64, 0);
            memory_barrier(ctx, cb, (S::TRANSFER, A::TRANSFER_WRITE), (S::COMPUTE_SHADER, A::SHADER_READ | A::SHADER_WRITE));
            compute.bind(cb, 1, push(0, 0, args, 0, 0));
            d.cmd_dispatch(cb, 3, 1, 1);
            memory_barrier(
                ctx,
                cb,
                (S::COMPUTE_SHADER, A::SHADER_WRITE),
                (S::COMPUTE_SHADER | S::DRAW_INDIRECT, A::SHADER_READ | A::SHADER_WRITE | A::INDIRECT_COMMAND_READ),
            );
            compute.bind(cb, 2, push(0, base, 0, 0, 0));
            d.cmd_dispatch_indirect(cb, buf, (args * 4) as u64);
            compute.bind(cb, 2, push(0, zero_base, 0, 0, 0));
            d.cmd_dispatch_indirect(cb, buf, (zero_args * 4) as u64);
        }
        memory_barrier(ctx, cb, (S::COMPUTE_SHADER, A::SHADER_WRITE), (S::HOST, A::HOST_READ));
    })?;
    let got = words_of(s.buffers[b].read()?);
    let mut want = init;
    want[args..args + 3].copy_from_slice(&[x, y, z]);
    want[base..base + HEADER + 128].fill(0);
    let groups = x * y * z;
    want[base..base + HEADER].copy_from_slice(&[0, 0, x, y, z, groups, groups * MARK_WG, 0]);
    for g in 0..groups {
        let id = pack_id(g % x, g / x % y, g / (x * y));
        want[base + HEADER + g as usize] = MARK_WG * (id + 1);
    }
    if crate::value_images::skewed() {
        want[0] ^= 1;
    }
    let parts =
        [("commands", 0..base), ("header", base..base + HEADER), ("groups", base + HEADER..zero_base), ("zero_dispatch", zero_base..total)];
    let mut numbers = serde_json::Map::new();
    let mut fails = Vec::new();
    for (name, range) in parts {
        let (bad, first) = mismatches(&got, &want, range, name);
        numbers.insert(format!("{name}_word_mismatches"), json!(bad));
        if bad > 0 {
            fails.push(format!("{name}: {bad} words differ ({})", first.join(", ")));
        }
    }
    if !fails.is_empty() {
        crate::value_images::words("words", &want, &got);
    }
    numbers.insert("command".into(), json!(&got[args..args + 3]));
    numbers.insert("header".into(), json!(&got[base..base + HEADER]));
    let what = "vkCmdDispatchIndirect at byte offset 20 of a command grown by atomicMax to (17, 2, 3): exactly its 102 groups once \
                each with its workgroup_id and num_workgroups; a command with x = 0 dispatches nothing";
    Ok(CheckResult::from_fails("dispatch_indirect", fails, numbers, what))
}
