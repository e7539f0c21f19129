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
//! * **word pairs**: every other edge is filed under the pair of facing words its two slots
//!   lie in, with its two bit positions (two bytes an edge). A pair whose two words are both
//!   all ones or both all zeros (a light far from a compact patch: most pairs, in a spatial
//!   order) holds no silhouette edge and is skipped whole; the others test each edge's two
//!   bits in the two words already loaded, with no further memory access.
//!
//! Per light, the scan first lists the **breaks** among the facing words it touches: the
//! words that are mixed (neither all ones nor all zeros) or differ from the word before.
//! Between two breaks every word is the same uniform word, and no edge with both slots there
//! is on the silhouette: a class visits only the words whose reach (the word and the words `δ`
//! slots on) holds a break, and a facing word's word pairs are skipped up to the first break
//! after it. In a spatial order the work is then about the words the light's terminator
//! crosses, not the mesh's size.
//!
//! Both paths test exactly the same two bits of every edge, so the result is the plain scan's,
//! edge for edge, and its edges keep the caller's triangle ids.

use super::order::TriangleOrder;
use super::silhouette::SilhouetteEdge;
use super::topology::ManifoldEdge;

/// At most this many distance classes (each costs a pass over its words per light).
const MAX_CLASSES: usize = 8;
/// A class must hold at least this many edges per facing word it spans on average: below it,
/// its word pass costs more than the per-edge lookups it saves.
const MIN_EDGES_PER_WORD: usize = 2;

/// Manifold edges prepared for the per-light scan ([`EdgeScan::scan_into`]): distance classes
/// scanned a facing word at a time, and the other edges filed by the pair of facing words
/// they join, two bytes an edge. Built once per caster part; the scan reads only these, and the
/// full edge records of the few edges on the possible silhouette.
#[derive(Clone, Debug, Default)]
pub struct EdgeScan {
    /// Scan order: each class's edges by increasing `lo`, class after class, then the residual
    /// edges by word pair.
    edges: Vec<ManifoldEdge>,
    classes: Vec<DeltaClass>,
    /// `edges[rest..]` are the residual edges.
    rest: usize,
    /// The facing words with residual edges at their `lo` slot, increasing.
    lo_words: Vec<LoWord>,
    /// The residual edges' word pairs, by increasing `(lo word, hi word)`.
    pairs: Vec<WordPair>,
    /// Per residual edge: the bit of its `lo` slot in the pair's `lo` word, plus 128 when
    /// that slot is `t0`'s; the bit of its `hi` slot in the `hi` word.
    offsets: Vec<[u8; 2]>,
    /// The facing words the scan reads: `words.0 .. words.1`.
    words: (usize, usize),
}

/// The word pairs `pairs[start .. end]` (`start` the previous `LoWord`'s `end`) have their
/// `lo` slots in facing word `w`, and their `hi` words at most `max_hi`.
#[derive(Clone, Copy, Debug, Default)]
struct LoWord {
    w: u32,
    max_hi: u32,
    end: u32,
}

/// The residual edges with their `lo` slot in the facing word of their [`LoWord`] and their
/// `hi` slot in word `hi`: `edges[rest + start .. rest + end]`, `start` the previous pair's
/// `end`.
#[derive(Clone, Copy, Debug, Default)]
struct WordPair {
    hi: u32,
    end: u32,
}

/// The edges between slots `lo` and `lo + delta`.
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
    if t0_lit {
        SilhouetteEdge { a: e.a, b: e.b, lit: e.t0, lit_corner: e.c0, unlit: e.t1, unlit_corner: e.c1 }
    } else {
        SilhouetteEdge { a: e.b, b: e.a, lit: e.t1, lit_corner: e.c1, unlit: e.t0, unlit_corner: e.c0 }
    }
}

/// Word `i` of the facing bits shifted down by `delta` bits: bit `k` is the facing of
/// slot `64 i + k + delta` (0 past the end).
#[inline]
fn shifted(bits: &[u64], i: usize, delta: u32) -> u64 {
    let word = |j: usize| bits.get(j).copied().unwrap_or(0);
    let (q, r) = (i + (delta / 64) as usize, delta % 64);
    if r == 0 {
        word(q)
    } else {
        (word(q) >> r) | (word(q + 1) << (64 - r))
    }
}

/// An edge with its slots: `(lo, hi, lo is t0's slot)`.
type Slotted = (ManifoldEdge, u32, u32, bool);

fn slotted(e: ManifoldEdge, order: &TriangleOrder) -> Slotted {
    let (s0, s1) = (order.slot(e.t0), order.slot(e.t1));
    (e, s0.min(s1), s0.max(s1), s0 <= s1)
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
        // every edge goes to the first class of its distance, unless that class already has an
        // edge at its `lo` (two edges between the same two triangles): then to the residual
        let mut members: Vec<Vec<Slotted>> = vec![Vec::new(); deltas.len()];
        let mut residual = Vec::new();
        for e in edges {
            let (_, lo, hi, _) = e;
            match deltas.iter().position(|&d| hi > lo && hi - lo == d) {
                Some(c) => members[c].push(e),
                None => residual.push(e),
            }
        }
        let mut scan = EdgeScan::default();
        for (&delta, mut es) in deltas.iter().zip(members) {
            es.sort_by_key(|e| e.1);
            let mut kept: Vec<Slotted> = Vec::with_capacity(es.len());
            for e in es {
                if kept.last().is_some_and(|k| k.1 == e.1) {
                    residual.push(e);
                } else {
                    kept.push(e);
                }
            }
            let Some(last) = kept.last() else { continue };
            let first_word = kept[0].1 as usize / 64;
            let words = last.1 as usize / 64 - first_word + 1;
            let mut masks = vec![0u64; words];
            let mut lo_t0 = vec![0u64; words];
            for &(_, lo, _, is_t0) in &kept {
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
            scan.classes.push(DeltaClass { delta, first_word, masks, lo_t0, ranks, first: scan.edges.len() });
            scan.edges.extend(kept.into_iter().map(|k| k.0));
        }
        scan.rest = scan.edges.len();
        // residual edges by word pair (stable: the given order inside a pair)
        residual.sort_by_key(|&(_, lo, hi, _)| (lo / 64, hi / 64));
        for by_lo in residual.chunk_by(|x, y| x.1 / 64 == y.1 / 64) {
            for run in by_lo.chunk_by(|x, y| x.2 / 64 == y.2 / 64) {
                for &(e, lo, hi, is_t0) in run {
                    scan.offsets.push([(lo % 64) as u8 | (u8::from(is_t0) << 7), (hi % 64) as u8]);
                    scan.edges.push(e);
                }
                scan.pairs.push(WordPair { hi: run[0].2 / 64, end: scan.offsets.len() as u32 });
            }
            let w = by_lo[0].1 / 64;
            let max_hi = by_lo.iter().map(|x| x.2 / 64).max().unwrap_or(0);
            scan.lo_words.push(LoWord { w, max_hi, end: scan.pairs.len() as u32 });
        }
        // the words read: each class's own and shifted words, each pair's two words
        let mut words = (usize::MAX, 0usize);
        for c in &scan.classes {
            words.0 = words.0.min(c.first_word);
            words.1 = words.1.max(c.first_word + c.masks.len() + (c.delta as usize).div_ceil(64) + 1);
        }
        for l in &scan.lo_words {
            words.0 = words.0.min(l.w as usize);
            words.1 = words.1.max(l.max_hi as usize + 1);
        }
        scan.words = if words.0 < words.1 { words } else { (0, 0) };
        scan
    }

    /// The edges, in scan order: the order of [`scan_into`](Self::scan_into)'s output.
    pub fn edges(&self) -> &[ManifoldEdge] {
        &self.edges
    }

    /// Bytes one scan reads (at most): the class masks and orientation bits, the residual word
    /// pairs and their edges' bit positions.
    pub fn bytes(&self) -> usize {
        self.classes.iter().map(|c| c.masks.len() * 16).sum::<usize>()
            + self.lo_words.len() * std::mem::size_of::<LoWord>()
            + self.pairs.len() * std::mem::size_of::<WordPair>()
            + self.offsets.len() * 2
    }

    /// Edges scanned a facing word at a time by a distance class (the rest are filed by
    /// word pair).
    pub fn word_scanned_edges(&self) -> usize {
        self.rest
    }

    /// Appends the possible silhouette for the packed facing `bits` (in the scan's order) to
    /// `out`: the edges of [`edges`](Self::edges) whose triangles' bits differ, in that order,
    /// each oriented as in its light-facing triangle; the same list as [`possible_silhouette`]
    /// over [`edges`](Self::edges) and the bits looked up by slot (a slot past the bits counts
    /// as not facing).
    ///
    /// [`possible_silhouette`]: super::silhouette::possible_silhouette
    pub fn scan_into(&self, bits: &[u64], out: &mut Vec<SilhouetteEdge>) {
        BREAKS.with_borrow_mut(|breaks| {
            find_breaks(bits, self.words, breaks);
            for c in &self.classes {
                self.scan_class(c, bits, breaks, out);
            }
            self.scan_pairs(bits, breaks, out);
        })
    }

    fn scan_pairs(&self, bits: &[u64], breaks: &[u32], out: &mut Vec<SilhouetteEdge>) {
        let rest = &self.edges[self.rest..];
        let word = |w: u32| bits.get(w as usize).copied().unwrap_or(0);
        let mut first_pair = 0usize;
        // the first break after the current word (the lo words increase)
        let mut next = 0usize;
        for l in &self.lo_words {
            let pairs = first_pair..l.end as usize;
            first_pair = l.end as usize;
            while breaks[next] <= l.w {
                next += 1;
            }
            let a = word(l.w);
            // a uniform word, and every word up to the next break equal to it: the pairs whose
            // hi word lies before that break hold no silhouette edge
            let clear_below = if mixed(a) { 0 } else { breaks[next] };
            if clear_below > l.max_hi {
                continue;
            }
            let mut start = if pairs.start == 0 { 0 } else { self.pairs[pairs.start - 1].end as usize };
            for p in &self.pairs[pairs] {
                let edges = start..p.end as usize;
                start = edges.end;
                if p.hi < clear_below {
                    continue;
                }
                let b = word(p.hi);
                // both words all ones or both all zeros: no edge of the pair is on the silhouette
                if a == b && !mixed(a) {
                    continue;
                }
                for (o, e) in self.offsets[edges.clone()].iter().zip(&rest[edges]) {
                    let fl = (a >> (o[0] & 63)) & 1;
                    let fh = (b >> (o[1] & 63)) & 1;
                    if fl != fh {
                        out.push(oriented(e, (fl != 0) == (o[0] >= 128)));
                    }
                }
            }
        }
    }

    fn scan_class(&self, c: &DeltaClass, bits: &[u64], breaks: &[u32], out: &mut Vec<SilhouetteEdge>) {
        let edges = &self.edges[c.first..];
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
                if m == 0 {
                    continue;
                }
                let f = bits.get(w).copied().unwrap_or(0);
                let mut s = (f ^ shifted(bits, w, c.delta)) & m;
                while s != 0 {
                    let k = s.trailing_zeros();
                    s &= s - 1;
                    let rank = c.ranks[i] + (m & ((1u64 << k) - 1)).count_ones();
                    let e = &edges[rank as usize];
                    // `f`'s bit k is slot lo's
                    let lo_lit = (f >> k) & 1 != 0;
                    let lo_is_t0 = (c.lo_t0[i] >> k) & 1 != 0;
                    out.push(oriented(e, lo_lit == lo_is_t0));
                }
            }
            done = done.max(top);
        }
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
    for (c, chunk) in inside.chunks(64).enumerate() {
        let mut m = 0u64;
        for (k, &a) in chunk.iter().enumerate() {
            m |= u64::from((a != prev) | mixed(a)) << k;
            prev = a;
        }
        while m != 0 {
            let k = m.trailing_zeros() as usize;
            m &= m - 1;
            breaks.push((first + c * 64 + k) as u32);
        }
    }
    let past = first.max(bits.len());
    if past < last && past > first && prev != 0 {
        breaks.push(past as u32);
    }
    breaks.push(u32::MAX);
}

thread_local! {
    /// [`find_breaks`]' list, kept per thread across calls.
    static BREAKS: std::cell::RefCell<Vec<u32>> = const { std::cell::RefCell::new(Vec::new()) };
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
            assert!(scan.classes.len() >= 2, "{} classes", scan.classes.len());
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
        // a fixed pseudo-random triangle order: no distance class, every edge in its own pair
        let t = Topology::build(&shuffled(&uv_sphere(1.0, 200, 101)));
        let mut bits = Vec::new();
        FacePlanes::new(&t.mesh).facing_packed(&t.mesh, Vec4::new(3.0, 2.0, 1.0, 1.0), false, &mut bits);
        let scan = check(t.manifold_edges.clone(), &bits);
        assert!(scan.word_scanned_edges() * 10 < t.manifold_edges.len());
        assert!(scan.pairs.len() * 2 > t.manifold_edges.len());
        // in a spatial order the same mesh's edges fall into few word pairs, most skipped whole
        let all: Vec<u32> = (0..t.mesh.triangles.len() as u32).collect();
        let order = TriangleOrder::spatial(&t.mesh, &[&all]);
        let planes = FacePlanes::with_order(&t.mesh, order.clone());
        for l in [Vec4::new(3.0, 2.0, 1.0, 1.0), Vec4::new(0.1, 0.2, -0.3, 1.0), Vec4::new(-1.0, 0.5, 0.2, 0.0)] {
            planes.facing_packed(&t.mesh, l, false, &mut bits);
            let scan = check_in(t.manifold_edges.clone(), &bits, &order);
            assert!(scan.pairs.len() * 8 < t.manifold_edges.len(), "{} pairs", scan.pairs.len());
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
            assert_eq!(scan.classes.len(), 2);
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
