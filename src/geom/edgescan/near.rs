//! The near edges of an [`EdgeScan`](super::EdgeScan): the distance classes with `δ < 64` and
//! the residual edges with both slots in one facing word or in a word and the next, filed by
//! the word of their `lo` slot, so that one visit of a word next to a break tests them all.

use super::{mixed, offsets_of, pad_to_blocks, test_edges, word, BlockMask, Hits, Slotted};
use crate::geom::topology::ManifoldEdge;

/// The near edges: those of a class with `δ < 64`, and the residual edges with both slots in
/// one facing word or in a word and the next, filed by the word of their `lo` slot.
#[derive(Clone, Debug, Default)]
pub(super) struct Near {
    /// The near classes' distances, each below 64.
    pub(super) deltas: Vec<u32>,
    /// The first word with near edges.
    pub(super) first: usize,
    /// Word `first + i`'s edges, and one past the last word (only its `base`).
    pub(super) words: Vec<NearWord>,
    /// Bit `k` of `masks[i * deltas.len() + c][0]`: class `c` has an edge with `lo` slot
    /// `64 (first + i) + k`; of `[1]`: that edge's `lo` slot is its `t0`'s.
    pub(super) masks: Vec<[u64; 2]>,
    /// `ranks[..]` (indexed as `masks`): the word's edges of the classes before `c`.
    pub(super) ranks: Vec<u16>,
    /// Per near residual edge, in edge order: its bit positions, the `hi` one in the `lo`
    /// word and the next (0 to 127), and [`T0`](super::T0) as for the far ones; then a
    /// [`TEST_BLOCK`](super::TEST_BLOCK)'s padding.
    pub(super) offsets: Vec<[u8; 2]>,
}

/// One word's near edges: `edges[base .. rest]` are its class edges, class after class, by
/// `lo`; `edges[rest .. next]` its residual edges inside the word, `edges[next ..]` (up to the
/// next word's `base`) those reaching into the next word. The residual edge `edges[rest + j]`
/// has bit positions `offsets[off + j]`.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct NearWord {
    pub(super) base: u32,
    pub(super) rest: u32,
    pub(super) next: u32,
    pub(super) off: u32,
}

impl Near {
    /// The near `classes` (distance and edges by increasing `lo`) and near residual edges
    /// (`rest`, by `lo` word, those inside the word first), their edges appended to `edges`
    /// in scan order.
    pub(super) fn build(classes: Vec<(&u32, Vec<Slotted>)>, rest: &[Slotted], edges: &mut Vec<ManifoldEdge>) -> Near {
        let word_of = |e: &Slotted| e.1 as usize / 64;
        let firsts = classes.iter().map(|(_, es)| word_of(&es[0])).chain(rest.first().map(word_of));
        let lasts = classes.iter().map(|(_, es)| word_of(&es[es.len() - 1])).chain(rest.last().map(word_of));
        let (Some(first), Some(last)) = (firsts.min(), lasts.max()) else {
            return Near::default();
        };
        let k = classes.len();
        let words = last + 1 - first;
        let mut near = Near {
            deltas: classes.iter().map(|(&d, _)| d).collect(),
            first,
            masks: vec![[0; 2]; words * k],
            ranks: vec![0; words * k],
            ..Near::default()
        };
        let (mut at, mut r) = (vec![0usize; k], 0usize);
        for i in 0..words {
            let w = first + i;
            let base = edges.len() as u32;
            for (c, (_, es)) in classes.iter().enumerate() {
                near.ranks[i * k + c] = (edges.len() as u32 - base) as u16;
                while let Some(e) = es.get(at[c]).filter(|e| word_of(e) == w) {
                    near.masks[i * k + c][0] |= 1 << (e.1 % 64);
                    near.masks[i * k + c][1] |= u64::from(e.3) << (e.1 % 64);
                    edges.push(e.0);
                    at[c] += 1;
                }
            }
            let (rest_at, off) = (edges.len() as u32, near.offsets.len() as u32);
            let mut next = None;
            while let Some(e) = rest.get(r).filter(|e| word_of(e) == w) {
                if e.2 as usize / 64 > w && next.is_none() {
                    next = Some(edges.len() as u32);
                }
                near.offsets.push(offsets_of(e, true));
                edges.push(e.0);
                r += 1;
            }
            near.words.push(NearWord { base, rest: rest_at, next: next.unwrap_or(edges.len() as u32), off });
        }
        near.words.push(NearWord { base: edges.len() as u32, ..NearWord::default() });
        pad_to_blocks(&mut near.offsets);
        near
    }

    /// The near edges of the words next to a break: every class's edges whose bits differ,
    /// and the residual edges of a mixed word, or a uniform word's that reach into a next word
    /// unlike it.
    #[inline(always)]
    pub(super) fn scan(&self, bits: &[u64], breaks: &[u32], hits: &mut Hits, block_mask: impl BlockMask) {
        let near = self;
        let classes = near.deltas.len();
        let (lo, hi) = (near.first, near.first + near.words.len().saturating_sub(1));
        let mut done = lo;
        let from = breaks.partition_point(|&b| (b as usize) < lo);
        for &b in &breaks[from..] {
            let b = b as usize;
            // a break at `b` concerns words `b - 1` (its next word) and `b`
            if b > hi {
                break;
            }
            let top = (b + 1).min(hi);
            for w in b.saturating_sub(1).max(done)..top {
                let (f, g) = (word(bits, w), word(bits, w + 1));
                if f == g && !mixed(f) {
                    // a uniform word and the same next word: no near edge of it differs
                    continue;
                }
                let i = w - lo;
                let (nw, end) = (near.words[i], near.words[i + 1].base);
                hits.room((end - nw.base) as usize);
                let at = i * classes..(i + 1) * classes;
                for ((&delta, &[m, t0]), &rank) in near.deltas.iter().zip(&near.masks[at.clone()]).zip(&near.ranks[at]) {
                    let s = (f ^ ((f >> delta) | (g << (64 - delta)))) & m;
                    hits.class_edges(s, m, f ^ t0, nw.base + u32::from(rank));
                }
                let start = if mixed(f) {
                    nw.rest
                } else if f != g {
                    nw.next
                } else {
                    end
                };
                let off = (nw.off + start - nw.rest) as usize;
                test_edges(start..end, &near.offsets[off..], f, [f, g], hits, block_mask);
            }
            done = done.max(top);
        }
    }
}
