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
//! are filed by their pair of words.
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

use super::order::TriangleOrder;
use super::silhouette::SilhouetteEdge;
use super::topology::ManifoldEdge;

/// At most this many distance classes (each costs work per visited word and light).
const MAX_CLASSES: usize = 8;
/// A class must hold at least this many edges per facing word it spans on average: below it,
/// its word pass costs more than the per-edge lookups it saves.
const MIN_EDGES_PER_WORD: usize = 2;
/// Far word pairs tested a chunk at a time (their list of pairs to test stays small).
const FAR_CHUNK: usize = 256;

/// Manifold edges prepared for the per-light scan ([`EdgeScan::scan_into`]): distance classes
/// scanned a facing word at a time, and the other edges filed by the facing words they join,
/// two bytes an edge. Built once per caster part; the scan reads only these, and the full edge
/// records of the few edges on the possible silhouette.
#[derive(Clone, Debug, Default)]
pub struct EdgeScan {
    /// Scan order: the near edges word by word, then each far class's edges by increasing
    /// `lo`, then the far residual edges by word pair.
    edges: Vec<ManifoldEdge>,
    near: Near,
    far_classes: Vec<DeltaClass>,
    /// The far residual edges' word pairs, by increasing `(lo word, hi word)`.
    far: Vec<WordPair>,
    /// The far residual edges in word pairs are `edges[far_start..lone_start]`.
    far_start: usize,
    /// Per far residual edge in a word pair: the bit of its `lo` slot in its `lo` word, plus
    /// [`T0`] when that slot is `t0`'s; the bit of its `hi` slot in its `hi` word.
    far_offsets: Vec<[u8; 2]>,
    /// The far residual edges alone in their word pair (a pair costs more than its one edge)
    /// are `edges[lone_start..]`, each with its slots: `t0`'s, `t1`'s.
    lone_start: usize,
    lone: Vec<[u32; 2]>,
    /// The facing words the scan reads: `words.0 .. words.1`.
    words: (usize, usize),
}

/// In an edge's bit positions: its `lo` slot is its `t0`'s.
const T0: u8 = 128;

/// The near edges: those of a class with `δ < 64`, and the residual edges with both slots in
/// one facing word or in a word and the next, filed by the word of their `lo` slot.
#[derive(Clone, Debug, Default)]
struct Near {
    /// The near classes' distances, each below 64.
    deltas: Vec<u32>,
    /// The first word with near edges.
    first: usize,
    /// Word `first + i`'s edges, and one past the last word (only its `base`).
    words: Vec<NearWord>,
    /// Bit `k` of `masks[i * deltas.len() + c][0]`: class `c` has an edge with `lo` slot
    /// `64 (first + i) + k`; of `[1]`: that edge's `lo` slot is its `t0`'s.
    masks: Vec<[u64; 2]>,
    /// `ranks[..]` (indexed as `masks`): the word's edges of the classes before `c`.
    ranks: Vec<u16>,
    /// Per near residual edge, in edge order: its bit positions, the `hi` one in the `lo`
    /// word and the next (0 to 127), and [`T0`] as for the far ones.
    offsets: Vec<[u8; 2]>,
}

/// One word's near edges: `edges[base .. rest]` are its class edges, class after class, by
/// `lo`; `edges[rest .. next]` its residual edges inside the word, `edges[next ..]` (up to the
/// next word's `base`) those reaching into the next word. The residual edge `edges[rest + j]`
/// has bit positions `offsets[off + j]`.
#[derive(Clone, Copy, Debug, Default)]
struct NearWord {
    base: u32,
    rest: u32,
    next: u32,
    off: u32,
}

/// The far residual edges with their `lo` slot in facing word `lo` and their `hi` slot in
/// word `hi`: `edges[start .. end]`, `start` the previous pair's `end` (the first's:
/// `far_start`).
#[derive(Clone, Copy, Debug, Default)]
struct WordPair {
    lo: u32,
    hi: u32,
    end: u32,
}

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

#[inline]
fn oriented(e: &ManifoldEdge, t0_lit: bool) -> SilhouetteEdge {
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
            scan.far.push(WordPair { lo: run[0].1 / 64, hi: run[0].2 / 64, end: scan.edges.len() as u32 });
        }
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
        for p in &scan.far {
            words.0 = words.0.min(p.lo as usize);
            words.1 = words.1.max(p.hi as usize + 1);
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
            + self.far.len() * std::mem::size_of::<WordPair>()
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
        SCRATCH.with_borrow_mut(|Scratch { breaks, hits }| {
            find_breaks(bits, self.words, breaks);
            let mut hits = Hits { list: hits, len: 0 };
            self.scan_near(bits, breaks, &mut hits);
            for c in &self.far_classes {
                self.scan_class(c, bits, breaks, &mut hits);
            }
            self.scan_far(bits, &mut hits);
            self.scan_lone(bits, &mut hits);
            out.extend(hits.found().iter().map(|&h| oriented(&self.edges[h as u32 as usize], h >> 32 != 0)));
        })
    }

    /// The near edges of the words next to a break: every class's edges whose bits differ,
    /// and the residual edges of a mixed word, or a uniform word's that reach into a next word
    /// unlike it.
    fn scan_near(&self, bits: &[u64], breaks: &[u32], hits: &mut Hits) {
        let near = &self.near;
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
                let (list, mut len) = (&mut hits.list[..], hits.len);
                for ((&delta, &[m, t0]), &rank) in near.deltas.iter().zip(&near.masks[at.clone()]).zip(&near.ranks[at]) {
                    let mut s = (f ^ ((f >> delta) | (g << (64 - delta)))) & m;
                    while s != 0 {
                        let k = s.trailing_zeros();
                        s &= s - 1;
                        let rank = u32::from(rank) + (m & ((1u64 << k) - 1)).count_ones();
                        // `f`'s bit k is slot lo's
                        let t0_lit = ((f ^ t0) >> k) & 1 == 0;
                        list[len] = entry(nw.base + rank, t0_lit);
                        len += 1;
                    }
                }
                hits.len = len;
                let start = if mixed(f) {
                    nw.rest
                } else if f != g {
                    nw.next
                } else {
                    end
                };
                let off = (nw.off + start - nw.rest) as usize;
                test_edges(start..end, &near.offsets[off..], f, [f, g], hits);
            }
            done = done.max(top);
        }
    }

    /// The far residual edges of the word pairs whose two words are not the same uniform word.
    fn scan_far(&self, bits: &[u64], hits: &mut Hits) {
        // a chunk of pairs at a time: first the pairs to test, listed without a branch a pair,
        // then their edges
        let mut dirty = [0u16; FAR_CHUNK];
        let mut start = self.far_start as u32;
        for (c, chunk) in self.far.chunks(FAR_CHUNK).enumerate() {
            let mut n = 0;
            for (i, p) in chunk.iter().enumerate() {
                let (a, b) = (word(bits, p.lo as usize), word(bits, p.hi as usize));
                dirty[n] = i as u16;
                n += usize::from(a != b || mixed(a));
            }
            let end = chunk[chunk.len() - 1].end;
            hits.room((end - start) as usize);
            for &i in &dirty[..n] {
                let i = c * FAR_CHUNK + usize::from(i);
                let p = self.far[i];
                let first = if i == 0 { self.far_start as u32 } else { self.far[i - 1].end };
                let b = word(bits, p.hi as usize);
                let off = first as usize - self.far_start;
                test_edges(first..p.end, &self.far_offsets[off..], word(bits, p.lo as usize), [b, b], hits);
            }
            start = end;
        }
    }

    /// The far residual edges alone in their word pair, each by its two bits.
    fn scan_lone(&self, bits: &[u64], hits: &mut Hits) {
        let bit = |s: u32| (word(bits, s as usize / 64) >> (s % 64)) & 1;
        for (c, chunk) in self.lone.chunks(FAR_CHUNK).enumerate() {
            hits.room(chunk.len());
            let (list, mut len) = (&mut hits.list[..], hits.len);
            let first = self.lone_start + c * FAR_CHUNK;
            for (i, &[s0, s1]) in chunk.iter().enumerate() {
                let (f0, f1) = (bit(s0), bit(s1));
                list[len] = entry((first + i) as u32, f0 != 0);
                len += usize::from(f0 != f1);
            }
            hits.len = len;
        }
    }

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
                let mut s = (f ^ shifted(bits, w, c.delta)) & m;
                hits.room(s.count_ones() as usize);
                while s != 0 {
                    let k = s.trailing_zeros();
                    s &= s - 1;
                    let rank = c.ranks[i] + (m & ((1u64 << k) - 1)).count_ones();
                    // `f`'s bit k is slot lo's
                    let t0_lit = ((f ^ c.lo_t0[i]) >> k) & 1 == 0;
                    hits.push(c.first as u32 + rank, t0_lit);
                }
            }
            done = done.max(top);
        }
    }
}

impl Near {
    /// The near `classes` (distance and edges by increasing `lo`) and near residual edges
    /// (`rest`, by `lo` word, those inside the word first), their edges appended to `edges`
    /// in scan order.
    fn build(classes: Vec<(&u32, Vec<Slotted>)>, rest: &[Slotted], edges: &mut Vec<ManifoldEdge>) -> Near {
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
        near
    }
}

/// Lists the residual edges `range` (bit positions `offsets`, from the range's first) whose
/// two bits differ, without a branch an edge: `lo` bits in `a`, `hi` bits in `b` (bit `k` in
/// `b[k / 64]`).
#[inline]
fn test_edges(range: std::ops::Range<u32>, offsets: &[[u8; 2]], a: u64, b: [u64; 2], hits: &mut Hits) {
    let (list, mut len) = (&mut hits.list[..], hits.len);
    for (i, o) in range.zip(offsets) {
        let fl = (a >> (o[0] & 63)) & 1;
        let fh = (b[usize::from(o[1] >> 6 & 1)] >> (o[1] & 63)) & 1;
        // t0 is lit when its slot's bit is set: lo's bit when lo is t0's, else hi's
        let t0_lit = (fl != 0) == (o[0] >= T0);
        list[len] = entry(i, t0_lit);
        len += usize::from(fl != fh);
    }
    hits.len = len;
}

/// A [`Hits`] entry: edge `i`, and whether its `t0` is lit.
#[inline]
fn entry(i: u32, t0_lit: bool) -> u64 {
    u64::from(i) | (u64::from(t0_lit) << 32)
}

/// Facing word `w` (0 past the bits).
#[inline]
fn word(bits: &[u64], w: usize) -> u64 {
    bits.get(w).copied().unwrap_or(0)
}

/// A scan's lists, kept per thread across calls: [`find_breaks`]' breaks and the edges found.
#[derive(Default)]
struct Scratch {
    breaks: Vec<u32>,
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

    /// Appends edge `i` with its orientation. Needs [`room`](Self::room).
    #[inline]
    fn push(&mut self, i: u32, t0_lit: bool) {
        self.list[self.len] = entry(i, t0_lit);
        self.len += 1;
    }

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
mod tests {
    use super::*;
    use crate::geom::silhouette::{possible_silhouette_packed, FacePlanes};
    use crate::geom::testmesh::{cube, shuffled, uv_sphere};
    use crate::geom::topology::Topology;
    use crate::geom::TriangleOrder;
    use glam::{Vec3, Vec4};
    use proptest::prelude::*;

    fn check(edges: Vec<ManifoldEdge>, bits: &[u64]) -> EdgeScan {
        check_in(edges, bits, &TriangleOrder::identity())
    }

    /// The plain scan over `edges` with bits looked up by slot.
    fn plain(edges: &[ManifoldEdge], bits: &[u64], order: &TriangleOrder) -> Vec<SilhouetteEdge> {
        let slotted: Vec<ManifoldEdge> = edges.iter().map(|e| ManifoldEdge { t0: order.slot(e.t0), t1: order.slot(e.t1), ..*e }).collect();
        let mut out = possible_silhouette_packed(&slotted, bits);
        for s in &mut out {
            s.lit = order.triangle(s.lit);
            s.unlit = order.triangle(s.unlit);
        }
        out
    }

    fn check_in(edges: Vec<ManifoldEdge>, bits: &[u64], order: &TriangleOrder) -> EdgeScan {
        let scan = EdgeScan::with_order(edges.clone(), order);
        let mut sorted_in = edges.clone();
        let mut sorted_scan = scan.edges().to_vec();
        let key = |e: &ManifoldEdge| (e.a, e.b, e.t0, e.t1, e.c0, e.c1);
        sorted_in.sort_by_key(key);
        sorted_scan.sort_by_key(key);
        assert_eq!(sorted_in, sorted_scan, "the scan holds exactly the given edges");
        let mut sil = Vec::new();
        scan.scan_into(bits, &mut sil);
        assert_eq!(sil, plain(scan.edges(), bits, order));
        if order.is_identity() {
            assert_eq!(sil, possible_silhouette_packed(scan.edges(), bits));
        }
        scan
    }

    #[test]
    fn sphere_is_scanned_by_words() {
        let t = Topology::build(&uv_sphere(1.0, 120, 61));
        let planes = FacePlanes::new(&t.mesh);
        let mut bits = Vec::new();
        for l in [Vec4::new(3.0, 2.0, 1.0, 1.0), Vec4::new(0.1, 0.2, -0.3, 1.0), Vec4::new(-1.0, 0.5, 0.2, 0.0)] {
            planes.facing_packed(&t.mesh, l, false, &mut bits);
            let scan = check(t.manifold_edges.clone(), &bits);
            // rows of quads: two distances (1 inside a row, 2 slices + 1 across rows) cover all
            // but the seam and pole edges
            assert!(scan.near.deltas.len() + scan.far_classes.len() >= 2, "{:?} classes", scan.near.deltas);
            assert!(
                scan.word_scanned_edges() * 10 >= t.manifold_edges.len() * 9,
                "{} of {}",
                scan.word_scanned_edges(),
                t.manifold_edges.len()
            );
            for b in [&bits[..], &bits[..bits.len() / 2], &[u64::MAX][..], &[][..]] {
                check(t.manifold_edges.clone(), b);
            }
        }
    }

    #[test]
    fn shuffled_triangles_take_the_residual_path() {
        // a fixed pseudo-random triangle order: no distance class, almost every edge alone in
        // its word pair
        let t = Topology::build(&shuffled(&uv_sphere(1.0, 200, 101)));
        let mut bits = Vec::new();
        FacePlanes::new(&t.mesh).facing_packed(&t.mesh, Vec4::new(3.0, 2.0, 1.0, 1.0), false, &mut bits);
        let scan = check(t.manifold_edges.clone(), &bits);
        assert!(scan.word_scanned_edges() * 10 < t.manifold_edges.len());
        assert!(scan.lone.len() * 2 > t.manifold_edges.len(), "{} alone", scan.lone.len());
        // in a spatial order the same mesh's edges fall into few word pairs, most skipped whole
        let all: Vec<u32> = (0..t.mesh.triangles.len() as u32).collect();
        let order = TriangleOrder::spatial(&t.mesh, &[&all]);
        let planes = FacePlanes::with_order(&t.mesh, order.clone());
        for l in [Vec4::new(3.0, 2.0, 1.0, 1.0), Vec4::new(0.1, 0.2, -0.3, 1.0), Vec4::new(-1.0, 0.5, 0.2, 0.0)] {
            planes.facing_packed(&t.mesh, l, false, &mut bits);
            let scan = check_in(t.manifold_edges.clone(), &bits, &order);
            assert!((scan.far.len() + scan.lone.len()) * 8 < t.manifold_edges.len(), "{} pairs, {} alone", scan.far.len(), scan.lone.len());
            // the same silhouette as the mesh's own order, edge set for edge set
            let mut own = Vec::new();
            FacePlanes::new(&t.mesh).facing_packed(&t.mesh, l, false, &mut own);
            let mut a = plain(scan.edges(), &bits, &order);
            let mut b = possible_silhouette_packed(&t.manifold_edges, &own);
            let key = |e: &SilhouetteEdge| (e.a, e.b, e.lit, e.unlit);
            a.sort_by_key(key);
            b.sort_by_key(key);
            assert_eq!(a, b);
        }
    }

    #[test]
    fn doubled_and_self_edges() {
        // two edges between the same two triangles, an edge of a triangle with itself, and
        // distances over 64 (shifts across words)
        let mk = |t0: u32, t1: u32, a: u32| ManifoldEdge { a, b: a + 1, t0, c0: 0, t1, c1: 1 };
        let mut edges = Vec::new();
        for lo in 0..300u32 {
            edges.push(mk(lo, lo + 70, 2 * lo));
            edges.push(mk(lo + 128, lo, 2 * lo + 1));
        }
        edges.push(mk(5, 75, 9999));
        edges.push(mk(7, 7, 10_001));
        for pattern in [0x5555_5555_5555_5555u64, 0xffff_0000_ffff_0000, 0x0123_4567_89ab_cdef] {
            let bits: Vec<u64> = (0..8).map(|i| pattern.rotate_left(i * 7)).collect();
            let scan = check(edges.clone(), &bits);
            assert_eq!((scan.near.deltas.len(), scan.far_classes.len()), (0, 2));
            check(edges.clone(), &bits[..3]);
        }
    }

    #[test]
    fn cube_and_empty() {
        let t = Topology::build(&cube(Vec3::ZERO, 1.0));
        check(t.manifold_edges.clone(), &[0b1010_1010_1010]);
        check(Vec::new(), &[u64::MAX]);
        assert_eq!(EdgeScan::new(Vec::new()).bytes(), 0);
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]
        #[test]
        fn random_pairs_and_bits(
            pairs in prop::collection::vec((0u32..700, 0u32..80), 0..600),
            bits in prop::collection::vec(any::<u64>(), 0..13),
        ) {
            let edges: Vec<ManifoldEdge> = pairs
                .iter()
                .enumerate()
                .map(|(i, &(t, d))| ManifoldEdge { a: i as u32, b: i as u32 + 1, t0: t, c0: 0, t1: t + d % 3 * (d / 3), c1: 2 })
                .collect();
            check(edges.clone(), &bits);
            // any order: a random permutation of the triangles
            let n = 800usize;
            let mut perm: Vec<u32> = (0..n as u32).collect();
            let mut x = bits.first().copied().unwrap_or(7) | 1;
            for i in (1..n).rev() {
                x ^= x << 13;
                x ^= x >> 7;
                x ^= x << 17;
                perm.swap(i, (x % (i as u64 + 1)) as usize);
            }
            check_in(edges, &bits, &TriangleOrder::from_slots(perm).unwrap());
        }
    }
}
