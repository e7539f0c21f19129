//! The compute path's merged volume draws: a light's volumes drawn with one indirect draw
//! call per pipeline (z-pass sides and caps, z-fail sides and caps, z-fail light caps),
//! whatever the number of casters.
//!
//! The silhouette stages write one pair of `VkDrawIndexedIndirectCommand`s per chunk record
//! (volume, light cap). For the merged draws the CPU also writes each command's
//! `vertexOffset` (the chunk's first vertex in the arena's vertex table: one vertex buffer for
//! every caster) and `firstInstance` (the (light, caster) pair's entry in the frame's
//! transform table, [`Xform`], read by `shadow.vert`'s TABLE variant as per-instance vertex
//! attributes): no push constants and no vertex-buffer binds per caster. Then, by
//! [`ComputeDraws`]:
//!
//! * `Count` and `Multi`: a further compute stage (`shaders/compact_draws.wgsl`, after `find` and `caps`) copies every
//!   non-empty command into its light and pipeline's list ([`List`]: a count word, then the
//!   commands); `Count` draws each list with one `vkCmdDrawIndexedIndirectCount` (the GPU's
//!   count), `Multi` with one multi-draw `vkCmdDrawIndexedIndirect` over the whole list (its
//!   unused tail cleared to empty commands). A list longer than `maxDrawIndirectCount` is
//!   drawn in pieces.
//! * `PerRecord`: one `vkCmdDrawIndexedIndirect` per command straight from the records (no
//!   compaction), still without push constants or binds per caster.
//! * `PerChunk`: the records as they were before (zero offsets), each drawn with its caster's
//!   push constants and its chunk's own vertex buffer ([`crate::pass::ShadowPass::record_draw`]).
//!
//! The stencil (and float count) is the same every way: the same indices, the same vertices
//! and the same transforms, through the same expressions (`shaders/shadow.vert`), and stencil
//! wrap increments and +-1 additions do not depend on the draws' order.

use super::{rec, HEADER_WORDS, RECORD_WORDS};
use crate::pass::desc::ComputeDraws;
use bytemuck::{Pod, Zeroable};

/// The pipeline of a z-pass command (sides and caps of case 1).
pub(crate) const ZPASS: usize = 0;
/// The pipeline of a z-fail command (sides and dark caps of cases 2 and 3).
pub(crate) const ZFAIL: usize = 1;
/// The pipeline of a light cap (case 3, depth NEVER).
pub(crate) const CAP: usize = 2;
/// The float counter's sign per pipeline: +1 for z-pass, -1 for z-fail and light caps.
pub(crate) const SIGN: [f32; 3] = [1.0, -1.0, -1.0];

/// Words from a list's count to its first command (16 bytes), as in
/// `shaders/compact_draws.wgsl`.
pub(crate) const LIST_HEADER: u32 = 4;
/// Words of one `VkDrawIndexedIndirectCommand`.
pub(crate) const COMMAND_WORDS: u32 = 5;
/// Bytes of one `VkDrawIndexedIndirectCommand` (the stride of every merged draw).
pub(crate) const COMMAND_BYTES: u32 = 4 * COMMAND_WORDS;
/// Invocations of a workgroup of the compaction stage.
pub(crate) const COMPACT_GROUP: u32 = 64;

/// One entry of the transform table (`shadow.vert`'s TABLE variant: locations 1-4 the
/// columns of the object-to-clip matrix, 5 the light in object space).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub(crate) struct Xform {
    pub mvp: [f32; 16],
    pub light: [f32; 4],
}

impl Xform {
    /// Bytes of an entry (binding 1's stride).
    pub const SIZE: u32 = std::mem::size_of::<Xform>() as u32;
    /// Binding 1's attributes: `(location, format, offset)`.
    pub const ATTRIBUTES: [(u32, ash::vk::Format, u32); 5] = [
        (1, ash::vk::Format::R32G32B32A32_SFLOAT, 0),
        (2, ash::vk::Format::R32G32B32A32_SFLOAT, 16),
        (3, ash::vk::Format::R32G32B32A32_SFLOAT, 32),
        (4, ash::vk::Format::R32G32B32A32_SFLOAT, 48),
        (5, ash::vk::Format::R32G32B32A32_SFLOAT, 64),
    ];

    /// The entry of a caster with transform `mvp` and object-space light `light`: the same
    /// f32 values the push constants carry ([`crate::pass::push::VolumePush::new`]).
    pub fn new(mvp: glam::Mat4, light: [f32; 4]) -> Xform {
        Xform { mvp: mvp.to_cols_array(), light }
    }
}

/// An enabled chunk record, as the merged draws see it (pushed by
/// [`super::work::ComputeWork::add_caster`]).
#[derive(Clone, Copy, Debug)]
pub(crate) struct ChunkRecord {
    /// Word offset of the record.
    pub word: usize,
    pub light: usize,
    /// Its (light, caster) pair's entry in the transform table.
    pub xform: u32,
    /// The chunk's first vertex in the arena's vertex table.
    pub vertex_base: u32,
    /// Its part's case is z-pass (else z-fail).
    pub zpass: bool,
    /// Its part has a light cap (case 3): the record's second command.
    pub cap: bool,
}

/// A light's list of one pipeline in the frame's draw-list buffer.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct List {
    /// Word offset of its count (its commands follow [`LIST_HEADER`] words later).
    pub word: u32,
    /// Commands it has room for (the light's chunk records of that pipeline).
    pub capacity: u32,
}

/// The frame's merged draws (see the module docs).
#[derive(Clone, Debug, Default)]
pub(crate) struct Merged {
    /// `Count`, `Multi` or `PerRecord`.
    pub mode: ComputeDraws,
    /// `Count`, `Multi`: per light and pipeline, its list.
    pub lists: Vec<[Option<List>; 3]>,
    /// `PerRecord`: per light and pipeline, the byte offsets of its commands in the records.
    pub records: Vec<[Vec<u64>; 3]>,
    /// Words of the draw-list buffer (the lists, each 16-byte aligned).
    pub list_words: u64,
    /// Chunk records of the frame, enabled or not (the compaction stage's invocations).
    pub chunk_records: u32,
    /// Most commands one draw call may take (`maxDrawIndirectCount`).
    pub max_draws: u32,
    /// Draw calls each determination of the frame records for its merged draws, all lights.
    pub calls: u64,
    /// The draw calls they replace: one per command of an enabled record.
    pub per_chunk_calls: u64,
    /// The GPU objects (filled by `prepare`).
    pub handles: MergedHandles,
}

/// The buffers and set a frame's merged draws use.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct MergedHandles {
    /// The arena's vertex table (binding 0 of the draws).
    pub vertices: ash::vk::Buffer,
    /// The frame's transform table (binding 1).
    pub xforms: ash::vk::Buffer,
    /// The lists (`Count`, `Multi`).
    pub lists: ash::vk::Buffer,
    /// The compaction stage's set (`Count`, `Multi`).
    pub set: ash::vk::DescriptorSet,
}

impl Merged {
    /// Whether the frame runs the compaction stage.
    pub fn compacts(&self) -> bool {
        matches!(self.mode, ComputeDraws::Count | ComputeDraws::Multi) && self.chunk_records > 0 && self.list_words > 0
    }
}

/// Draw calls a list of `capacity` commands takes at `max_draws` commands a call.
pub(crate) fn pieces(capacity: u32, max_draws: u32) -> u32 {
    capacity.div_ceil(max_draws.max(1))
}

/// Lays out a frame's merged draws for `lights` lights in `mode` (already resolved: not
/// `Auto`): `records` is the frame's header and chunk records, `chunks` its enabled ones; writes
/// every enabled record's `vertexOffset`, `firstInstance` and list words. `None` for `PerChunk`
/// (and mesh frames, which the caller sends here as `PerChunk`), whose records keep zero
/// offsets (the commands then read the chunk's own vertex buffer, and need no
/// `drawIndirectFirstInstance`).
pub(crate) fn plan(records: &mut [u32], chunks: &[ChunkRecord], lights: usize, mode: ComputeDraws, max_draws: u32) -> Option<Merged> {
    if matches!(mode, ComputeDraws::PerChunk | ComputeDraws::Auto) {
        return None;
    }
    let compact = matches!(mode, ComputeDraws::Count | ComputeDraws::Multi);
    // Every record starts on no list (records of culled or CPU-path parts are never drawn).
    for r in records[HEADER_WORDS..].chunks_exact_mut(RECORD_WORDS) {
        r[rec::VOL_LIST] = rec::NO_LIST;
        r[rec::CAP_LIST] = rec::NO_LIST;
    }
    let mut capacity = vec![[0u32; 3]; lights];
    for c in chunks {
        capacity[c.light][if c.zpass { ZPASS } else { ZFAIL }] += 1;
        if c.cap {
            capacity[c.light][CAP] += 1;
        }
    }
    let mut m = Merged {
        mode,
        max_draws,
        chunk_records: ((records.len() - HEADER_WORDS) / RECORD_WORDS) as u32,
        per_chunk_calls: chunks.iter().map(|c| 1 + c.cap as u64).sum(),
        ..Merged::default()
    };
    m.lists = capacity
        .iter()
        .map(|caps| {
            caps.map(|capacity| {
                (compact && capacity > 0).then(|| {
                    let list = List { word: m.list_words as u32, capacity };
                    m.list_words += (LIST_HEADER + COMMAND_WORDS * capacity).next_multiple_of(4) as u64;
                    m.calls += pieces(capacity, max_draws) as u64;
                    list
                })
            })
        })
        .collect();
    m.records = vec![Default::default(); lights];
    let no_list = |l: Option<List>| l.map_or(rec::NO_LIST, |l| l.word);
    for c in chunks {
        let class = if c.zpass { ZPASS } else { ZFAIL };
        let r = &mut records[c.word..c.word + RECORD_WORDS];
        r[rec::VOL_VERTEX_OFFSET] = c.vertex_base;
        r[rec::VOL_FIRST_INSTANCE] = c.xform;
        r[rec::CAP_VERTEX_OFFSET] = c.vertex_base;
        r[rec::CAP_FIRST_INSTANCE] = c.xform;
        r[rec::VOL_LIST] = no_list(m.lists[c.light][class]);
        if c.cap {
            r[rec::CAP_LIST] = no_list(m.lists[c.light][CAP]);
        }
        if !compact {
            let per = &mut m.records[c.light];
            per[class].push((c.word * 4) as u64);
            if c.cap {
                per[CAP].push(((c.word + rec::CAP_COUNT) * 4) as u64);
            }
        }
    }
    if !compact {
        m.calls = m.records.iter().flatten().map(|v| v.len() as u64).sum();
    }
    Some(m)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A frame's records (a zero header, then one record per entry and a last one of a culled
    /// part) and its enabled ones.
    struct Frame {
        records: Vec<u32>,
        chunk_records: Vec<ChunkRecord>,
    }

    impl Frame {
        fn plan(&mut self, lights: usize, mode: ComputeDraws, max_draws: u32) -> Option<Merged> {
            plan(&mut self.records, &self.chunk_records, lights, mode, max_draws)
        }
    }

    fn frame(records: &[(usize, bool, bool)]) -> Frame {
        let mut cf = Frame { records: vec![0; HEADER_WORDS], chunk_records: Vec::new() };
        for (k, &(light, zpass, cap)) in records.iter().enumerate() {
            let word = cf.records.len();
            cf.records.resize(word + RECORD_WORDS, 0);
            cf.chunk_records.push(ChunkRecord { word, light, xform: k as u32, vertex_base: 100 * k as u32, zpass, cap });
        }
        // a record of a culled part: on no list
        cf.records.resize(cf.records.len() + RECORD_WORDS, 0);
        cf
    }

    #[test]
    fn lists_hold_each_light_and_pipeline_once() {
        let mut cf = frame(&[(0, true, false), (0, false, true), (1, false, false), (0, true, false), (1, false, true)]);
        let m = cf.plan(2, ComputeDraws::Count, 1 << 16).unwrap();
        let cap = |l: usize, p: usize| m.lists[l][p].map(|l| l.capacity);
        assert_eq!([cap(0, ZPASS), cap(0, ZFAIL), cap(0, CAP)], [Some(2), Some(1), Some(1)]);
        assert_eq!([cap(1, ZPASS), cap(1, ZFAIL), cap(1, CAP)], [None, Some(2), Some(1)]);
        assert_eq!(m.calls, 5);
        // lists are 16-byte aligned and do not overlap
        let mut spans: Vec<(u32, u32)> =
            m.lists.iter().flatten().flatten().map(|l| (l.word, l.word + LIST_HEADER + COMMAND_WORDS * l.capacity)).collect();
        spans.sort();
        assert!(spans.iter().all(|s| s.0 % 4 == 0) && spans.windows(2).all(|w| w[0].1 <= w[1].0));
        assert!(spans.last().unwrap().1 as u64 <= m.list_words);
        // each record names its lists, its vertices and its transform
        let r1 = &cf.records[cf.chunk_records[1].word..][..RECORD_WORDS];
        assert_eq!(r1[rec::VOL_LIST], m.lists[0][ZFAIL].unwrap().word);
        assert_eq!(r1[rec::CAP_LIST], m.lists[0][CAP].unwrap().word);
        assert_eq!((r1[rec::VOL_VERTEX_OFFSET], r1[rec::VOL_FIRST_INSTANCE]), (100, 1));
        assert_eq!((r1[rec::CAP_VERTEX_OFFSET], r1[rec::CAP_FIRST_INSTANCE]), (100, 1));
        let r0 = &cf.records[cf.chunk_records[0].word..][..RECORD_WORDS];
        assert_eq!(r0[rec::CAP_LIST], rec::NO_LIST);
        let culled = &cf.records[cf.records.len() - RECORD_WORDS..];
        assert_eq!((culled[rec::VOL_LIST], culled[rec::CAP_LIST]), (rec::NO_LIST, rec::NO_LIST));
        assert!(m.compacts());
    }

    #[test]
    fn long_lists_are_drawn_in_pieces_and_per_record_draws_every_command() {
        let recs: Vec<(usize, bool, bool)> = (0..7).map(|_| (0, false, true)).collect();
        let mut cf = frame(&recs);
        let m = cf.plan(1, ComputeDraws::Multi, 3).unwrap();
        assert_eq!(m.calls, 3 + 3);
        let mut cf = frame(&recs);
        let m = cf.plan(1, ComputeDraws::PerRecord, 3).unwrap();
        assert!(!m.compacts() && m.list_words == 0);
        assert_eq!((m.records[0][ZFAIL].len(), m.records[0][CAP].len(), m.calls), (7, 7, 14));
        assert_eq!(m.records[0][CAP][0], ((cf.chunk_records[0].word + rec::CAP_COUNT) * 4) as u64);
        let mut cf = frame(&recs);
        assert!(cf.plan(1, ComputeDraws::PerChunk, 3).is_none());
        assert!(cf.records[HEADER_WORDS..].iter().all(|&w| w == 0), "per chunk: the records keep zero offsets");
    }

    #[test]
    fn xform_matches_the_push_block() {
        assert_eq!(Xform::SIZE, 80);
        let m = glam::Mat4::from_cols_array(&std::array::from_fn(|i| i as f32));
        let x = Xform::new(m, [1.0, 2.0, 3.0, 0.0]);
        let p = crate::pass::push::VolumePush::new(m, glam::Vec4::new(1.0, 2.0, 3.0, 0.0), [0.0; 4]);
        assert_eq!((x.mvp, x.light), (p.mvp, p.light));
    }
}
