//! The far residual edges of an [`EdgeScan`]: those filed by their pair of facing words,
//! tested a pair at a time through per-word codes, and those alone in their pair, tested by
//! their two bits.

use super::{entry, mixed, test_edges, word, BlockMask, EdgeScan, Hits};

/// Lone far edges tested a chunk at a time.
const FAR_CHUNK: usize = 256;
/// Far word pairs are tested by their words' codes ([`fill_codes`]) when every word index is
/// below this (facing bits of up to 4,194,304 triangles), else by the words themselves.
pub(super) const WORD_CODES: usize = 1 << 16;

/// Whether [`EdgeScan::scan_far`] must test the words themselves (tests of the path taken
/// past [`WORD_CODES`]).
#[cfg(test)]
fn words_only() -> bool {
    super::tests::WORDS_ONLY.with(std::cell::Cell::get)
}

#[cfg(not(test))]
#[inline(always)]
fn words_only() -> bool {
    false
}

/// A code per facing word: its index is a `u16`, so its reads need no bounds check.
pub(super) type WordCodes = [u8; WORD_CODES];

/// The codes of facing words `words` (below [`WORD_CODES`]): `1` for all zeros, `2` for all
/// ones, `0` for a mixed word. Two words are the same uniform word when their codes share a
/// bit: a word pair holds no silhouette edge when `codes[lo] & codes[hi] != 0`.
#[inline(always)]
fn fill_codes(bits: &[u64], words: std::ops::Range<usize>, codes: &mut WordCodes) {
    let inside = words.start.min(bits.len())..words.end.min(bits.len());
    for (c, &a) in codes[inside.clone()].iter_mut().zip(&bits[inside.clone()]) {
        *c = u8::from(a == 0) | u8::from(a == u64::MAX) << 1;
    }
    codes[inside.end.max(words.start)..words.end].fill(1);
}

impl EdgeScan {
    /// The far residual edges of the word pairs whose two words are not the same uniform word.
    #[inline(always)]
    pub(super) fn scan_far(&self, bits: &[u64], codes: &mut WordCodes, hits: &mut Hits, block_mask: impl BlockMask) {
        // 64 pairs at a time: first their test, one bit a pair into a mask (no branch a pair),
        // then the edges of the pairs it marks
        let fast = self.far_top <= WORD_CODES && !words_only();
        if fast {
            fill_codes(bits, self.far_lo.first().map_or(0, |&w| w as usize)..self.far_top, codes);
        }
        for (c, (los, his)) in self.far_lo.chunks(64).zip(self.far_hi.chunks(64)).enumerate() {
            let mut m = 0u64;
            if fast {
                // (every word index is below 2^16: no bounds check)
                for (k, (&lo, &hi)) in los.iter().zip(his).enumerate() {
                    m |= u64::from(codes[lo as u16 as usize] & codes[hi as u16 as usize] == 0) << k;
                }
            } else {
                for (k, (&lo, &hi)) in los.iter().zip(his).enumerate() {
                    let (a, b) = (word(bits, lo as usize), word(bits, hi as usize));
                    // not the same uniform word
                    m |= u64::from((a != b) | mixed(a)) << k;
                }
            }
            while m != 0 {
                let i = c * 64 + m.trailing_zeros() as usize;
                m &= m - 1;
                let first = if i == 0 { self.far_start as u32 } else { self.far_end[i - 1] };
                let end = self.far_end[i];
                let b = word(bits, self.far_hi[i] as usize);
                let off = first as usize - self.far_start;
                test_edges(first..end, &self.far_offsets[off..], word(bits, self.far_lo[i] as usize), [b, b], hits, block_mask);
            }
        }
    }

    /// The far residual edges alone in their word pair, each by its two bits.
    #[inline(always)]
    pub(super) fn scan_lone(&self, bits: &[u64], hits: &mut Hits) {
        let bit = |s: u32| (word(bits, s as usize / 64) >> (s % 64)) & 1;
        for (c, chunk) in self.lone.chunks(FAR_CHUNK).enumerate() {
            hits.room(chunk.len());
            let (list, mut len) = (&mut hits.list[..], hits.len);
            let first = self.lone_start + c * FAR_CHUNK;
            for (i, &[s0, s1]) in chunk.iter().enumerate() {
                let (f0, f1) = (bit(s0), bit(s1));
                list[len] = entry((first + i) as u32, f0);
                len += ((f0 ^ f1) & 1) as usize;
            }
            hits.len = len;
        }
    }
}
