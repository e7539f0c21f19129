//! Readback: one host-visible buffer per ring slot, laid out in named ranges (colour, then
//! the captured positions, normals, per-light counts and light-intensity maps).

use ash::vk;
use gpu_allocator::MemoryLocation;
use umbrage::error::Result;
use umbrage::gpu::{Buffer, Context};

/// A byte range of the readback buffer.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct Range {
    pub offset: u64,
    pub size: u64,
}

impl Range {
    /// Sample `k`'s block of a range holding `samples` equal blocks.
    pub fn sample(self, k: u32, samples: u32) -> Range {
        let size = self.size / samples.max(1) as u64;
        Range { offset: self.offset + k as u64 * size, size }
    }
}

/// Where each image of a frame lands. A multisampled frame's positions, normals and counts
/// hold one block per sample, sample after sample ([`Range::sample`]).
#[derive(Clone, Debug, Default)]
pub(crate) struct Layout {
    /// Samples per pixel (1 when single-sampled).
    pub samples: u32,
    pub color: Range,
    pub positions: Option<Range>,
    pub normals: Option<Range>,
    /// Per light: the stencil (1 byte a pixel) or the float count (4 bytes).
    pub counts: Vec<Range>,
    /// Per light: the light-intensity map (8 or 16 bytes a pixel).
    pub transmit: Vec<Range>,
    pub total: u64,
}

impl Layout {
    /// `capture`: positions, normals and per-light counts / maps too.
    pub fn new(pixels: u64, capture: bool, lights: usize, float_counts: bool, transmit_texel: Option<u64>, samples: u32) -> Layout {
        let n = samples.max(1) as u64;
        let mut next = 0u64;
        let mut take = |size: u64| {
            let r = Range { offset: next, size };
            next += size.div_ceil(16) * 16;
            r
        };
        let color = take(pixels * 4);
        let mut l = Layout { color, samples: n as u32, ..Layout::default() };
        if capture {
            l.positions = Some(take(n * pixels * 16));
            l.normals = Some(take(n * pixels * 16));
            let per_light = n * if float_counts { pixels * 4 } else { pixels };
            l.counts = (0..lights).map(|_| take(per_light)).collect();
            if let Some(texel) = transmit_texel {
                l.transmit = (0..lights).map(|_| take(pixels * texel)).collect();
            }
        }
        l.total = next;
        l
    }
}

/// A slot's readback buffer, grown when a frame needs more.
pub(crate) struct Readback {
    pub buffer: Option<Buffer>,
}

impl Readback {
    /// A buffer of at least `size` bytes (the slot's previous frame has retired).
    pub fn ensure(&mut self, ctx: &Context, slot: usize, size: u64) -> Result<vk::Buffer> {
        if self.buffer.as_ref().map(|b| b.size < size).unwrap_or(true) {
            if let Some(mut b) = self.buffer.take() {
                b.destroy(ctx);
            }
            self.buffer =
                Some(Buffer::new(ctx, &format!("readback {slot}"), size, vk::BufferUsageFlags::TRANSFER_DST, MemoryLocation::GpuToCpu)?);
        }
        Ok(self.buffer.as_ref().map(|b| b.raw).unwrap_or_default())
    }

    /// The bytes of `range`.
    pub fn bytes(&self, range: Range) -> Result<&[u8]> {
        let b = self.buffer.as_ref().ok_or_else(|| umbrage::Error::Internal("no readback buffer".into()))?;
        let all = b.read()?;
        all.get(range.offset as usize..(range.offset + range.size) as usize)
            .ok_or_else(|| umbrage::Error::Internal(format!("readback range {range:?} outside {} bytes", all.len())))
    }

    pub fn destroy(&mut self, ctx: &Context) {
        if let Some(mut b) = self.buffer.take() {
            b.destroy(ctx);
        }
    }
}
