//! The residual edges' test, a block of [`TEST_BLOCK`] edges at a time: each edge's two bits
//! gathered from the facing words it joins and compared, into one mask bit an edge. Bit by
//! bit in every copy ([`block_mask`]), or with byte shuffles where the copy has SSSE3
//! ([`block_mask_ssse3`]: the x86-64-v2 and v3 ones). Both give the same mask.

use super::{entry, Hits, T0, TEST_BLOCK};

/// One block's test: bit `k` set when edge `k`'s two bits differ, for the bit positions
/// `block` (`[lo, hi]` an edge: `lo`'s bit in `a` with [`T0`] as a flag, `hi`'s in `b`, bit
/// `p` of `b[p / 64]`).
pub(super) trait BlockMask: Fn(&[[u8; 2]; TEST_BLOCK], u64, [u64; 2]) -> u64 + Copy {}
impl<F: Fn(&[[u8; 2]; TEST_BLOCK], u64, [u64; 2]) -> u64 + Copy> BlockMask for F {}

/// [`BlockMask`] bit by bit: selects and shifts only, so the block's lanes can sit side by
/// side in vector registers.
#[inline(always)]
pub(super) fn block_mask(block: &[[u8; 2]; TEST_BLOCK], a: u64, b: [u64; 2]) -> u64 {
    let mut m = 0u64;
    for (k, o) in block.iter().enumerate() {
        let (o0, o1) = (u64::from(o[0]), u64::from(o[1]));
        // the two bits in bit 0
        let hw = if o1 & 64 != 0 { b[1] } else { b[0] };
        m |= (((a >> (o0 & 63)) ^ (hw >> (o1 & 63))) & 1) << k;
    }
    m
}

/// [`block_mask`] with SSSE3 byte shuffles: the block's 16 bytes split into its 8 `lo` and 8
/// `hi` positions (`pshufb`), each position into a byte index (`p >> 3`) and a bit in that byte
/// (`1 << (p & 7)`, by a table lookup), the bytes gathered from the words (`pshufb` again:
/// `a`'s 8 bytes for the `lo` lanes, `b`'s 16 for the `hi` ones), the bits tested, and the
/// two halves compared. About 15 instructions a block where the bit-by-bit form
/// takes about 60. Safe to call only from code compiled with SSSE3, which the compiler checks:
/// the x86-64-v2 and v3 copies of the scan.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "ssse3")]
#[inline]
pub(super) fn block_mask_ssse3(block: &[[u8; 2]; TEST_BLOCK], a: u64, b: [u64; 2]) -> u64 {
    use std::arch::x86_64::{
        __m128i, _mm_and_si128, _mm_cmpeq_epi8, _mm_movemask_epi8, _mm_set1_epi64x, _mm_set_epi64x, _mm_setr_epi8, _mm_setzero_si128,
        _mm_shuffle_epi8, _mm_srli_epi16,
    };
    const _: () = assert!(TEST_BLOCK == 8 && T0 == 1 << 7);
    // the positions by value (`bytemuck`, no pointer): lanes 0-7 the `lo` ones, 8-15 the `hi`
    let raw: __m128i = bytemuck::cast(*block);
    let pos = _mm_shuffle_epi8(raw, _mm_setr_epi8(0, 2, 4, 6, 8, 10, 12, 14, 1, 3, 5, 7, 9, 11, 13, 15));
    // byte index: `lo` in `a`'s 8 bytes (its `T0` flag dropped), `hi` in `b`'s 16 (the 16-bit
    // shift's spill from the next byte lands in bits the mask clears)
    let byte = _mm_and_si128(_mm_srli_epi16::<3>(pos), _mm_setr_epi8(7, 7, 7, 7, 7, 7, 7, 7, 15, 15, 15, 15, 15, 15, 15, 15));
    let bit = _mm_shuffle_epi8(
        _mm_setr_epi8(1, 2, 4, 8, 16, 32, 64, -128, 1, 2, 4, 8, 16, 32, 64, -128),
        _mm_and_si128(pos, _mm_setr_epi8(7, 7, 7, 7, 7, 7, 7, 7, 7, 7, 7, 7, 7, 7, 7, 7)),
    );
    // per lane, whether its bit is clear in the bytes gathered (one mask bit a lane): the
    // `lo` lanes' from `a`, the `hi` lanes' from `b`
    let clear = |words: __m128i| {
        let gathered = _mm_shuffle_epi8(words, byte);
        _mm_movemask_epi8(_mm_cmpeq_epi8(_mm_and_si128(gathered, bit), _mm_setzero_si128())) as u32
    };
    let lo_clear = clear(_mm_set1_epi64x(a as i64)) & 0xff;
    let hi_clear = clear(_mm_set_epi64x(b[1] as i64, b[0] as i64)) >> 8;
    u64::from((lo_clear ^ hi_clear) & 0xff)
}

/// Pads residual edges' bit positions `offsets` (when any) so that [`test_edges`] may read a
/// whole block past the last edge.
pub(super) fn pad_to_blocks(offsets: &mut Vec<[u8; 2]>) {
    if !offsets.is_empty() {
        offsets.resize(offsets.len() + TEST_BLOCK - 1, [0; 2]);
    }
}

/// Lists the residual edges `range` (bit positions `offsets`, from the range's first, padded
/// to a whole [`TEST_BLOCK`]) whose two bits differ: `lo` bits in `a`, `hi` bits in `b` (bit
/// `k` in `b[k / 64]`). A block of edges at a time, without a branch or a store an edge:
/// their tests into a mask (`block_mask`), then the few edges it marks (needs no
/// [`Hits::room`]). The blocks' fixed length spares the branch mispredicted at the end of a
/// short loop of varying length (a word's or a word pair's edges: 5 or 6 on average).
#[inline(always)]
pub(super) fn test_edges(
    range: std::ops::Range<u32>,
    offsets: &[[u8; 2]],
    a: u64,
    b: [u64; 2],
    hits: &mut Hits,
    block_mask: impl BlockMask,
) {
    let n = (range.end - range.start) as usize;
    let blocks: &[[[u8; 2]; TEST_BLOCK]] = bytemuck::cast_slice(&offsets[..n.next_multiple_of(TEST_BLOCK)]);
    for (c, block) in blocks.iter().enumerate() {
        // (the padding past the range's last edge cleared)
        let mut m = block_mask(block, a, b) & ((1 << (n - c * TEST_BLOCK).min(TEST_BLOCK)) - 1);
        if m == 0 {
            continue;
        }
        hits.room(m.count_ones() as usize);
        let (list, mut len) = (&mut hits.list[..], hits.len);
        let first = range.start + (c * TEST_BLOCK) as u32;
        while m != 0 {
            let k = m.trailing_zeros();
            m &= m - 1;
            let o0 = u64::from(block[k as usize][0]);
            // t0 is lit when its slot's bit is set: lo's bit when lo is t0's (`T0`), else hi's
            // (which differs from lo's)
            let t0_lit = (a >> (o0 & 63)) ^ (o0 >> 7) ^ 1;
            list[len] = entry(first + k, t0_lit);
            len += 1;
        }
        hits.len = len;
    }
}
