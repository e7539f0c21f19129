//! A caster's index lists (or naive vertices) for one light, written into a byte stream: the
//! frame's stream ([`super::pack`]) or a kept pair's own buffer ([`super::keep`]).

use super::desc::IndexFormat;
use super::draw::{Draw, DrawList};
use super::stats::UsedIndexFormat;
use crate::shadow;
use ash::vk;

/// One caster's index lists (or naive vertices) for one light, written into the stream.
#[derive(Clone)]
pub(crate) struct ChunkDraws {
    pub draws: DrawList,
    pub index_bytes: u64,
    pub vertex_bytes: u64,
    /// The index format used (`none` when nothing was drawn).
    pub fmt_used: UsedIndexFormat,
}

/// Writes caster `cp`'s chunk draws (volume and light-cap lists) into `stream`, each aligned
/// to 16 bytes in the format the settings (`format`) and the device (`u8_ok`) allow;
/// `chunks`: the caster's chunks' vertex buffers.
pub(crate) fn write_chunks(
    stream: &mut Vec<u8>,
    (format, u8_ok): (IndexFormat, bool),
    caster: &shadow::Caster,
    chunks: &[vk::Buffer],
    cp: &shadow::CasterPlan,
) -> ChunkDraws {
    let mut draws = Vec::new();
    let mut index_bytes = 0u64;
    let mut vertex_bytes = 0u64;
    let mut fmt_used = UsedIndexFormat::None;
    for cd in &cp.chunks {
        let chunk = &caster.chunks[cd.chunk];
        let n = chunk.vertices.len();
        for (indices, cap) in [(&cd.volume, false), (&cd.light_cap, true)] {
            if indices.is_empty() {
                continue;
            }
            let fmt = match format {
                IndexFormat::Auto | IndexFormat::U8 if u8_ok && 2 * n <= 256 => IndexFormat::U8,
                IndexFormat::Auto | IndexFormat::U8 => IndexFormat::U16,
                f => f,
            };
            fmt_used = fmt.into();
            align(stream, 16);
            let offset = stream.len() as u64;
            match fmt {
                IndexFormat::U8 => stream.extend(indices.iter().map(|&i| i as u8)),
                IndexFormat::U16 => stream.extend(indices.iter().flat_map(|&i| i.to_le_bytes())),
                IndexFormat::U32 => stream.extend(indices.iter().flat_map(|&i| (i as u32).to_le_bytes())),
                IndexFormat::Naive | IndexFormat::Auto => {
                    for &i in indices.iter() {
                        let i = i as usize;
                        let (v, wv) = if i < n { (chunk.vertices[i], 1.0f32) } else { (chunk.vertices[i - n], 0.0) };
                        for f in [v.x, v.y, v.z, wv] {
                            stream.extend(f.to_le_bytes());
                        }
                    }
                }
            }
            let bytes = stream.len() as u64 - offset;
            if fmt == IndexFormat::Naive {
                vertex_bytes += bytes;
            } else {
                index_bytes += bytes;
            }
            draws.push(Draw {
                vertices: chunks[cd.chunk],
                kept: None,
                offset,
                count: indices.len() as u32,
                format: fmt,
                case: cd.case,
                light_cap: cap,
                indirect: false,
                mesh: None,
            });
        }
    }
    ChunkDraws { draws: DrawList::Own(draws), index_bytes, vertex_bytes, fmt_used }
}

/// Pads `v` with zeros to a multiple of `a` bytes.
pub(crate) fn align(v: &mut Vec<u8>, a: usize) {
    while !v.len().is_multiple_of(a) {
        v.push(0);
    }
}
