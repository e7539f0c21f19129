//! The per-light edge scan ([`EdgeScan`]): the possible silhouette from packed facing bits,
//! a whole facing word (64 triangles) at a time wherever the triangle order allows.
//!
//! A possible-silhouette edge is a manifold edge whose two triangles have different facing
//! bits. The scan works on the triangles' slots in a [`TriangleOrder`] (the order of the
//! [`FacePlanes`](super::planes::FacePlanes) bits; casters use a spatial one): with `lo < hi`
//! the two slots of an edge,
//!
//! * **distance classes**: strips, grids and fans put many edges between slots a few fixed
//!   distances apart (all but a UV sphere's seam and pole edges have `hi - lo = 1`, inside a
//!   row, or `2 slices + 1`, across rows). For every distance `δ` that covers enough edges, the
//!   scan keeps one mask bit per slot `lo` with an edge to `lo + δ`; the silhouette bits of 64
//!   such edges are then `(F[w] ^ (F >> δ)[w]) & mask[w]`: a handful of word operations.
//! * **residual edges**: every other edge is kept with its two bit positions (two bytes an
//!   edge). A pair of facing words that are both all ones or both all zeros (a light far from
//!   a compact patch: most pairs, in a spatial order) holds no silhouette edge and is skipped
//!   whole; the others test each edge's two bits in the words already loaded, with no further
//!   memory access and no branch an edge.
//!
//! Both kinds are **near** when an edge's two slots lie in one facing word or in a word and
//! the next (a class with `δ < 64`), else **far**. The near edges are filed by the word of
//! their `lo` slot, every near class's mask of a word next to the others', so one visit of a
//! word tests all of them; the far classes keep a mask array each, and the far residual edges
//! are filed by their pair of words, except an edge alone in its pair: it keeps its two slots
//! and is tested by its two bits.
//!
//! Per light, the scan first lists the **breaks** among the facing words it touches: the
//! words that are mixed (neither all ones nor all zeros) or differ from the word before.
//! Between two breaks every word is the same uniform word, and no edge with both slots there
//! is on the silhouette: the near edges are visited only in a break's word and the word
//! before it, and a far class only in the words whose reach (the word and the words `δ` slots
//! on) holds a break. In a spatial order the work is then about the words the light's
//! terminator crosses and the far word pairs, not the mesh's size.
//!
//! Every path tests exactly the same two bits of every edge, so the result is the plain
//! scan's, edge for edge, and its edges keep the caller's triangle ids.

use super::cpu::{self, per_cpu_level};
use super::order::TriangleOrder;
use super::silhouette::SilhouetteEdge;
use super::topology::ManifoldEdge;

mod blocks;
mod far;
mod near;
use blocks::{pad_to_blocks, test_edges, BlockMask};
use far::{WordCodes, WORD_CODES};
use near::{Near, NearWord};

/// At most this many distance classes (each costs work per visited word and light).
const MAX_CLASSES: usize = 8;
/// A class must hold at least this many edges per facing word it spans on average: below it,
/// its word pass costs more than the per-edge lookups it saves.
const MIN_EDGES_PER_WORD: usize = 2;
/// Residual edges are tested this many at a time ([`test_edges`]); their bit positions are
/// padded to a whole block.
const TEST_BLOCK: usize = 8;
/// Manifold edges prepared for the per-light scan ([`EdgeScan::scan_into`]): distance classes
/// scanned a facing word at a time, and the other edges filed by the facing words they join,
/// two bytes an edge. Built once per caster part; the scan reads only these, and the full edge
/// records of the few edges on the possible silhouette.
#[derive(Clone, Debug, Default)]
pub struct EdgeScan {
    /// Scan order: the near edges word by word, then each far class's edges by increasing
    /// `lo`, then the far residual edges by word pair, then the lone ones.
    edges: Vec<ManifoldEdge>,
    near: Near,
    far_classes: Vec<DeltaClass>,
    /// The far residual edges' word pairs, by increasing `(lo word, hi word)`: pair `i` has its
    /// edges' `lo` slots in facing word `far_lo[i]`, their `hi` slots in word `far_hi[i]`, and
    /// its edges are `edges[start .. far_end[i]]`, `start` the previous pair's end (the
    /// first's: `far_start`). Three arrays, not one of structs: the per-light test of every
    /// pair reads only the first two.
    far_lo: Vec<u32>,
    far_hi: Vec<u32>,
    far_end: Vec<u32>,
    /// One past the last word of any far pair.
    far_top: usize,
    /// The far residual edges in word pairs are `edges[far_start..lone_start]`.
    far_start: usize,
    /// Per far residual edge in a word pair: the bit of its `lo` slot in its `lo` word, plus
    /// [`T0`] when that slot is `t0`'s; the bit of its `hi` slot in its `hi` word; then a
    /// [`TEST_BLOCK`]'s padding.
    far_offsets: Vec<[u8; 2]>,
    /// The far residual edges alone in their word pair (a pair costs more than its one edge)
    /// are `edges[lone_start..]`, each with its slots: `t0`'s, `t1`'s.
    lone_start: usize,
    lone: Vec<[u32; 2]>,
    /// The facing words the scan reads: `words.0 .. words.1`.
    words: (usize, usize),
    /// [`EdgeScan::with_tags`]' value per edge, in scan order (or none).
    tags: Vec<u64>,
}

/// One edge of a light's possible silhouette, as [`EdgeScan::scan_hits_into`] lists it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ScanHit(u64);

impl ScanHit {
    /// Its index in [`EdgeScan::edges`] (and [`EdgeScan::tags`]).
    pub fn edge(self) -> usize {
        self.0 as u32 as usize
    }

    /// Whether its `t0` faces the light (then it runs `a -> b` in its light-facing triangle).
    pub fn t0_lit(self) -> bool {
        self.0 >> 32 != 0
    }
}

/// In an edge's bit positions: its `lo` slot is its `t0`'s.
const T0: u8 = 128;

/// The edges between slots `lo` and `lo + delta`, a far class (`delta >= 64`).
#[derive(Clone, Debug, Default)]
struct DeltaClass {
    delta: u32,
    /// `masks[i]` covers `lo` in facing word `first_word + i`.
    first_word: usize,
    /// Bit `k` of `masks[i]`: an edge with `lo = 64 (first_word + i) + k`.
    masks: Vec<u64>,
    /// Bit `k` of `lo_t0[i]`: that edge's `lo` slot is its `t0`'s.
    lo_t0: Vec<u64>,
    /// Edges of the class in the words before word `i` (the rank of a mask bit's edge).
    ranks: Vec<u32>,
    /// The class's edges start at `edges[first]`.
    first: usize,
}

/// `e` as a [`SilhouetteEdge`], oriented as in its light-facing triangle (`t0` when `t0_lit`).
#[inline(always)]
pub(crate) fn oriented(e: &ManifoldEdge, t0_lit: bool) -> SilhouetteEdge {
    // selects, not a branch: which triangle is lit follows the light, not a pattern
    let (ends, tris, corners) = ([e.a, e.b], [e.t0, e.t1], [e.c0, e.c1]);
    let (i, j) = (usize::from(!t0_lit), usize::from(t0_lit));
    SilhouetteEdge { a: ends[i], b: ends[j], lit: tris[i], lit_corner: corners[i], unlit: tris[j], unlit_corner: corners[j] }
}

/// Word `i` of the facing bits shifted down by `delta` bits: bit `k` is the facing of
/// slot `64 i + k + delta` (0 past the end).
#[inline]
fn shifted(bits: &[u64], i: usize, delta: u32) -> u64 {
    let (q, r) = (i + (delta / 64) as usize, delta % 64);
    if r == 0 {
        word(bits, q)
    } else {
        (word(bits, q) >> r) | (word(bits, q + 1) << (64 - r))
    }
}

/// An edge with its slots: `(lo, hi, lo is t0's slot)`.
type Slotted = (ManifoldEdge, u32, u32, bool);

fn slotted(e: ManifoldEdge, order: &TriangleOrder) -> Slotted {
    let (s0, s1) = (order.slot(e.t0), order.slot(e.t1));
    (e, s0.min(s1), s0.max(s1), s0 <= s1)
}

/// The bit positions of residual edge `x` (`hi` relative to the start of its `lo` word when
/// `near`, else to its own word).
fn offsets_of(&(_, lo, hi, is_t0): &Slotted, near: bool) -> [u8; 2] {
    let hi_bit = if near { hi - lo / 64 * 64 } else { hi % 64 };
    [(lo % 64) as u8 | if is_t0 { T0 } else { 0 }, hi_bit as u8]
}

/// The distances worth a class, most edges first: at most [`MAX_CLASSES`], each with at least
/// [`MIN_EDGES_PER_WORD`] edges per facing word between its first and last `lo`.
fn choose_deltas(edges: &[Slotted]) -> Vec<u32> {
    let mut by_delta: Vec<(u32, u32)> = edges.iter().filter_map(|&(_, lo, hi, _)| (hi > lo).then_some((hi - lo, lo))).collect();
    by_delta.sort_unstable();
    let mut counts: Vec<(usize, u32)> = Vec::new();
    for run in by_delta.chunk_by(|x, y| x.0 == y.0) {
        let (first, last) = (run[0].1 as usize / 64, run[run.len() - 1].1 as usize / 64);
        let words = last - first + 1;
        if run.len() >= MIN_EDGES_PER_WORD * words {
            counts.push((run.len(), run[0].0));
        }
    }
    counts.sort_unstable_by(|x, y| y.cmp(x));
    counts.into_iter().take(MAX_CLASSES).map(|(_, d)| d).collect()
}

/// Splits `edges` into the classes of `deltas` (each by increasing `lo`) and the residual:
/// every edge goes to the class of its distance, unless that class already has an edge at its
/// `lo` (two edges between the same two triangles).
fn split_classes(edges: Vec<Slotted>, deltas: &[u32]) -> (Vec<Vec<Slotted>>, Vec<Slotted>) {
    let mut members: Vec<Vec<Slotted>> = vec![Vec::new(); deltas.len()];
    let mut residual = Vec::new();
    for e in edges {
        let (_, lo, hi, _) = e;
        match deltas.iter().position(|&d| hi > lo && hi - lo == d) {
            Some(c) => members[c].push(e),
            None => residual.push(e),
        }
    }
    for es in &mut members {
        es.sort_by_key(|e| e.1);
        let mut kept: Vec<Slotted> = Vec::with_capacity(es.len());
        for &e in es.iter() {
            if kept.last().is_some_and(|k| k.1 == e.1) {
                residual.push(e);
            } else {
                kept.push(e);
            }
        }
        *es = kept;
    }
    (members, residual)
}

impl EdgeScan {
    /// The scan over `edges` with the triangles in their own order (its
    /// [`edges`](Self::edges) are the same edges, in scan order).
    pub fn new(edges: Vec<ManifoldEdge>) -> EdgeScan {
        EdgeScan::with_order(edges, &TriangleOrder::identity())
    }

    /// The scan over `edges` for facing bits in `order` (bit `order.slot(t)` is triangle
    /// `t`'s: the order of the [`FacePlanes`](super::planes::FacePlanes) whose bits it will
    /// scan). Its [`edges`](Self::edges) are the same edges, with the same triangle ids, in
    /// scan order.
    pub fn with_order(edges: Vec<ManifoldEdge>, order: &TriangleOrder) -> EdgeScan {
        let edges: Vec<Slotted> = edges.into_iter().map(|e| slotted(e, order)).collect();
        let deltas = choose_deltas(&edges);
        let (members, mut residual) = split_classes(edges, &deltas);
        // residual edges: the near ones by word (inside the word first), then the far ones by
        // word pair (stable: the given order inside a pair)
        let is_near = |&(_, lo, hi, _): &Slotted| hi / 64 - lo / 64 <= 1;
        residual.sort_by_key(|e| (!is_near(e), e.1 / 64, e.2 / 64));
        let near_count = residual.iter().take_while(|e| is_near(e)).count();
        let (near_rest, far_rest) = residual.split_at(near_count);
        let (near_classes, far_classes): (Vec<_>, Vec<_>) =
            deltas.iter().zip(members).filter(|(_, es)| !es.is_empty()).partition(|(&d, _)| d < 64);
        let mut scan = EdgeScan::default();
        scan.near = Near::build(near_classes, near_rest, &mut scan.edges);
        for (&delta, kept) in &far_classes {
            let first_word = kept[0].1 as usize / 64;
            let words = kept[kept.len() - 1].1 as usize / 64 - first_word + 1;
            let mut masks = vec![0u64; words];
            let mut lo_t0 = vec![0u64; words];
            for &(_, lo, _, is_t0) in kept {
                let lo = lo as usize;
                masks[lo / 64 - first_word] |= 1 << (lo % 64);
                lo_t0[lo / 64 - first_word] |= u64::from(is_t0) << (lo % 64);
            }
            let mut ranks = Vec::with_capacity(words);
            let mut before = 0u32;
            for m in &masks {
                ranks.push(before);
                before += m.count_ones();
            }
            scan.far_classes.push(DeltaClass { delta, first_word, masks, lo_t0, ranks, first: scan.edges.len() });
            scan.edges.extend(kept.iter().map(|k| k.0));
        }
        scan.far_start = scan.edges.len();
        let mut lone = Vec::new();
        for run in far_rest.chunk_by(|x, y| (x.1 / 64, x.2 / 64) == (y.1 / 64, y.2 / 64)) {
            if let [e] = run {
                lone.push(e);
                continue;
            }
            for e in run {
                scan.far_offsets.push(offsets_of(e, false));
                scan.edges.push(e.0);
            }
            scan.far_lo.push(run[0].1 / 64);
            scan.far_hi.push(run[0].2 / 64);
            scan.far_top = scan.far_top.max(run[0].2 as usize / 64 + 1);
            scan.far_end.push(scan.edges.len() as u32);
        }
        pad_to_blocks(&mut scan.far_offsets);
        scan.lone_start = scan.edges.len();
        for &&(e, lo, hi, is_t0) in &lone {
            scan.lone.push(if is_t0 { [lo, hi] } else { [hi, lo] });
            scan.edges.push(e);
        }
        // the words read: the near words and the next, each far class's own and shifted
        // words, each far pair's two words
        let mut words = (usize::MAX, 0usize);
        if let Some(n) = scan.near.words.len().checked_sub(1).filter(|&n| n > 0) {
            words = (scan.near.first, scan.near.first + n + 1);
        }
        for c in &scan.far_classes {
            words.0 = words.0.min(c.first_word);
            words.1 = words.1.max(c.first_word + c.masks.len() + (c.delta as usize).div_ceil(64) + 1);
        }
        // (the pairs are by increasing `lo` word)
        if let Some(&lo) = scan.far_lo.first() {
            words.0 = words.0.min(lo as usize);
            words.1 = words.1.max(scan.far_top);
        }
        for &(_, lo, hi, _) in lone {
            words.0 = words.0.min(lo as usize / 64);
            words.1 = words.1.max(hi as usize / 64 + 1);
        }
        scan.words = if words.0 < words.1 { words } else { (0, 0) };
        scan
    }

    /// The edges, in scan order: the order of [`scan_into`](Self::scan_into)'s output.
    pub fn edges(&self) -> &[ManifoldEdge] {
        &self.edges
    }

    /// Bytes one scan reads (at most): the class masks and orientation bits, the near words'
    /// records, the far word pairs, and the residual edges' bit positions.
    pub fn bytes(&self) -> usize {
        let n = &self.near;
        n.masks.len() * 16
            + n.ranks.len() * 2
            + n.words.len() * std::mem::size_of::<NearWord>()
            + n.offsets.len() * 2
            + self.far_classes.iter().map(|c| c.masks.len() * 16).sum::<usize>()
            + self.far_lo.len() * 3 * std::mem::size_of::<u32>()
            + self.far_offsets.len() * 2
            + self.lone.len() * 8
    }

    /// Edges scanned a facing word at a time by a distance class (the rest are residual
    /// edges, tested one by one where their words are not both the same uniform word).
    pub fn word_scanned_edges(&self) -> usize {
        let near: usize = self.near.masks.iter().map(|m| m[0].count_ones() as usize).sum();
        near + self
            .far_classes
            .iter()
            .map(|c| c.ranks.last().map_or(0, |&r| r as usize) + c.masks.last().map_or(0, |m| m.count_ones() as usize))
            .sum::<usize>()
    }

    /// Appends the possible silhouette for the packed facing `bits` (in the scan's order) to
    /// `out`: the edges of [`edges`](Self::edges) whose triangles' bits differ, in that order,
    /// each oriented as in its light-facing triangle; the same list as [`possible_silhouette`]
    /// over [`edges`](Self::edges) and the bits looked up by slot (a slot past the bits counts
    /// as not facing).
    ///
    /// [`possible_silhouette`]: super::silhouette::possible_silhouette
    pub fn scan_into(&self, bits: &[u64], out: &mut Vec<SilhouetteEdge>) {
        self.with_hits(bits, |hits| out.extend(hits.iter().map(|&h| oriented(&self.edges[h as u32 as usize], h >> 32 != 0))))
    }

    /// [`scan_into`](Self::scan_into)'s edges as [`ScanHit`]s, appended to `out` in the same
    /// order: each edge's index in [`edges`](Self::edges) (and [`tags`](Self::tags)) and which
    /// of its triangles faces the light, without reading the edge records.
    pub fn scan_hits_into(&self, bits: &[u64], out: &mut Vec<ScanHit>) {
        self.with_hits(bits, |hits| out.extend(hits.iter().map(|&h| ScanHit(h))))
    }

    /// The scan's [`Hits`] entries for `bits`, to `f`.
    fn with_hits(&self, bits: &[u64], f: impl FnOnce(&[u64])) {
        SCRATCH.with_borrow_mut(|Scratch { breaks, codes, hits }| {
            let codes = codes.get_or_insert_with(|| Box::new([0; WORD_CODES]));
            let mut found = Hits { list: hits, len: 0 };
            scan_words(self, bits, breaks, codes, &mut found);
            f(found.found())
        })
    }

    /// The scan with a value per edge, `tag(edge)`, kept in scan order beside the edges
    /// ([`tags`](Self::tags)): what a caller would otherwise look up for each silhouette edge
    /// in tables of its own (the shadow planner keeps an edge's chunk and chunk-local ends, so
    /// that a light's silhouette reads them in the scan's order, next to one another). Replaces
    /// earlier tags. The scan itself never reads them.
    pub fn with_tags(mut self, tag: impl FnMut(&ManifoldEdge) -> u64) -> EdgeScan {
        self.tags = self.edges.iter().map(tag).collect();
        self
    }

    /// The tags of [`with_tags`](Self::with_tags), one per edge of [`edges`](Self::edges);
    /// empty for a scan without.
    pub fn tags(&self) -> &[u64] {
        &self.tags
    }

    #[inline(always)]
    fn scan_class(&self, c: &DeltaClass, bits: &[u64], breaks: &[u32], hits: &mut Hits) {
        // the words `w ..= w + reach` are read for the class's word `w`: it can hold a
        // silhouette edge only when a break lies among them
        let reach = (c.delta as usize).div_ceil(64);
        let (lo, hi) = (c.first_word, c.first_word + c.masks.len());
        let mut done = lo;
        let from = breaks.partition_point(|&b| (b as usize) < lo);
        for &b in &breaks[from..] {
            let b = b as usize;
            if b >= hi + reach {
                break;
            }
            let top = (b + 1).min(hi);
            for w in b.saturating_sub(reach).max(done)..top {
                let i = w - lo;
                let m = c.masks[i];
                let f = word(bits, w);
                let s = (f ^ shifted(bits, w, c.delta)) & m;
                hits.room(s.count_ones() as usize);
                hits.class_edges(s, m, f ^ c.lo_t0[i], c.first as u32 + c.ranks[i]);
            }
            done = done.max(top);
        }
    }
}

/// One scan's word work ([`EdgeScan::scan_into`]): the breaks, then every kind of edge, into
/// `hits`, and the edges found appended to `out`; the best copy for this CPU
/// ([`super::cpu`]), or the portable one.
fn scan_words(scan: &EdgeScan, bits: &[u64], breaks: &mut Vec<u32>, codes: &mut WordCodes, hits: &mut Hits) {
    if cpu::portable_only() {
        scan_words_in(scan, bits, breaks, codes, hits, blocks::block_mask)
    } else {
        scan_words_per_level(scan, bits, breaks, codes, hits)
    }
}

per_cpu_level! {
    /// [`scan_words_in`], compiled per CPU level; the copies with SSSE3 test the residual
    /// edges' blocks with byte shuffles ([`blocks::block_mask_ssse3`]), the others bit by bit.
    fn scan_words_per_level(scan: &EdgeScan, bits: &[u64], breaks: &mut Vec<u32>, codes: &mut WordCodes, hits: &mut Hits) {
        let block_mask = cpu::by_feature!(
            "ssse3",
            |block: &[[u8; 2]; TEST_BLOCK], a: u64, b: [u64; 2]| blocks::block_mask_ssse3(block, a, b),
            blocks::block_mask
        );
        scan_words_in(scan, bits, breaks, codes, hits, block_mask)
    }
}

/// [`scan_words`]' body; it and the parts it calls are inlined into each copy.
#[inline(always)]
fn scan_words_in(scan: &EdgeScan, bits: &[u64], breaks: &mut Vec<u32>, codes: &mut WordCodes, hits: &mut Hits, block_mask: impl BlockMask) {
    find_breaks(bits, scan.words, breaks);
    scan.near.scan(bits, breaks, hits, block_mask);
    for c in &scan.far_classes {
        scan.scan_class(c, bits, breaks, hits);
    }
    scan.scan_far(bits, codes, hits, block_mask);
    scan.scan_lone(bits, hits);
}

/// A [`Hits`] entry: edge `i`, and whether its `t0` is lit (bit 0 of `t0_lit`).
#[inline(always)]
fn entry(i: u32, t0_lit: u64) -> u64 {
    u64::from(i) | ((t0_lit & 1) << 32)
}

/// Facing word `w` (0 past the bits).
#[inline]
fn word(bits: &[u64], w: usize) -> u64 {
    bits.get(w).copied().unwrap_or(0)
}

/// A scan's lists, kept per thread across calls: [`find_breaks`]' breaks, the far pairs' word
/// codes (64 KiB) and the edges found.
#[derive(Default)]
struct Scratch {
    breaks: Vec<u32>,
    /// `far::fill_codes`' codes (allocated on the thread's first scan).
    codes: Option<Box<WordCodes>>,
    hits: Vec<u64>,
}

thread_local! {
    static SCRATCH: std::cell::RefCell<Scratch> = std::cell::RefCell::new(Scratch::default());
}

/// The edges on the silhouette, as indices into the scan's edges with bit 32 set when the
/// edge's `t0` is lit, listed without a branch an edge: every candidate is written, and kept
/// by advancing the length.
struct Hits<'a> {
    list: &'a mut Vec<u64>,
    len: usize,
}

impl Hits<'_> {
    /// Room for `more` candidates.
    #[inline]
    fn room(&mut self, more: usize) {
        if self.list.len() < self.len + more {
            self.list.resize((self.len + more).max(2 * self.list.len()), 0);
        }
    }

    /// Appends a class's edges of one word on the silhouette: bit `k` of `s` for the edge of
    /// mask bit `k` of `m`, which is edge `first` plus its rank in `m`; `t0` is lit where bit
    /// `k` of `lo_vs_t0` (the word's facing bits xor the edges' `lo is t0` bits) is clear.
    /// Needs [`room`](Self::room).
    #[inline(always)]
    fn class_edges(&mut self, mut s: u64, m: u64, lo_vs_t0: u64, first: u32) {
        let (list, mut len) = (&mut self.list[..], self.len);
        while s != 0 {
            let k = s.trailing_zeros();
            s &= s - 1;
            let rank = (m & ((1u64 << k) - 1)).count_ones();
            list[len] = entry(first + rank, !(lo_vs_t0 >> k));
            len += 1;
        }
        self.len = len;
    }

    #[inline(always)]
    fn found(&self) -> &[u64] {
        &self.list[..self.len]
    }
}

/// Whether facing word `a` is neither all ones nor all zeros.
#[inline]
fn mixed(a: u64) -> bool {
    a.wrapping_add(1) > 1
}

/// The breaks among facing words `first .. last` into `breaks` (increasing, then `u32::MAX`):
/// every word that is neither all ones nor all zeros, and every other word that differs from
/// the word before it (from `first + 1` on; words past the bits are zeros). Between two breaks
/// all words are one uniform word.
#[inline(always)]
fn find_breaks(bits: &[u64], (first, last): (usize, usize), breaks: &mut Vec<u32>) {
    breaks.clear();
    // the words inside the bits, 64 at a time into a mask (no branch per word), then the
    // zeros past them
    let inside = &bits[first.min(bits.len())..last.min(bits.len())];
    let mut prev = inside.first().copied().unwrap_or(0);
    for (c, chunk) in inside.chunks(8).enumerate() {
        // most runs of 8 words are one uniform word, the one before them: no break
        let a0 = chunk[0];
        if chunk.iter().fold(a0 ^ prev, |x, &a| x | (a ^ a0)) == 0 && !mixed(a0) {
            continue;
        }
        let mut m = 0u64;
        for (k, &a) in chunk.iter().enumerate() {
            m |= u64::from((a != prev) | mixed(a)) << k;
            prev = a;
        }
        while m != 0 {
            let k = m.trailing_zeros() as usize;
            m &= m - 1;
            breaks.push((first + c * 8 + k) as u32);
        }
    }
    let past = first.max(bits.len());
    if past < last && past > first && prev != 0 {
        breaks.push(past as u32);
    }
    breaks.push(u32::MAX);
}

#[cfg(test)]
mod tests;
