//! The per-light edge scan ([`EdgeScan`]): the possible silhouette from packed facing bits,
//! a whole facing word (64 triangles) at a time wherever the mesh's triangle order allows.
//!
//! A possible-silhouette edge is a manifold edge whose two triangles `lo < hi` have different
//! facing bits. Meshes are rarely in random triangle order: strips, grids and fans put most
//! edges between triangles a few fixed distances apart (all but a UV sphere's seam and pole
//! edges have `hi - lo = 1`, inside a row, or `2 slices + 1`, across rows). For every such distance
//! `δ` that covers enough edges, the scan keeps one mask bit per triangle `lo` with an edge to
//! `lo + δ`; the silhouette bits of 64 such edges are then `(F[w] ^ (F >> δ)[w]) & mask[w]`:
//! a handful of word operations, with no per-edge table lookup at all. The edges no class
//! covers (seams, poles, irregular meshes: in the worst case all of them) take the per-edge
//! path, two byte lookups an edge. Both paths test exactly the same two bits of every edge,
//! so the result is the plain scan's, edge for edge.

use super::silhouette::SilhouetteEdge;
use super::topology::ManifoldEdge;

/// At most this many distance classes (each costs a pass over its words per light).
const MAX_CLASSES: usize = 8;
/// A class must hold at least this many edges per facing word it spans on average: below it,
/// its word pass costs more than the per-edge lookups it saves.
const MIN_EDGES_PER_WORD: usize = 2;
/// Residual edges needing the byte-a-triangle table: fewer take two direct bit lookups each
/// (building the table costs about one byte store per triangle).
const TABLE_MIN_EDGES: usize = 4096;

/// Manifold edges prepared for the per-light scan ([`EdgeScan::scan_into`]): distance classes
/// scanned a facing word at a time, and the residual edges' triangle pairs packed 8 bytes an
/// edge. Built once per caster part; the scan reads only these, and the full edge records of
/// the few edges on the possible silhouette.
#[derive(Clone, Debug, Default)]
pub struct EdgeScan {
    /// Scan order: each class's edges by increasing `lo`, class after class, then the residual
    /// edges in their given order.
    edges: Vec<ManifoldEdge>,
    classes: Vec<DeltaClass>,
    /// `edges[rest..]` are the residual edges.
    rest: usize,
    /// Their triangle pairs `(t0, t1)`.
    pairs: Vec<[u32; 2]>,
    /// Largest triangle id of any residual edge.
    max_tri: u32,
}

/// The edges between triangles `lo` and `lo + delta`.
#[derive(Clone, Debug, Default)]
struct DeltaClass {
    delta: u32,
    /// `masks[i]` covers `lo` in facing word `first_word + i`.
    first_word: usize,
    /// Bit `k` of `masks[i]`: an edge with `lo = 64 (first_word + i) + k`.
    masks: Vec<u64>,
    /// Edges of the class in the words before word `i` (the rank of a mask bit's edge).
    ranks: Vec<u32>,
    /// The class's edges start at `edges[first]`.
    first: usize,
}

fn lo_hi(e: &ManifoldEdge) -> (u32, u32) {
    (e.t0.min(e.t1), e.t0.max(e.t1))
}

#[inline]
fn oriented(e: &ManifoldEdge, t0_lit: bool) -> SilhouetteEdge {
    if t0_lit {
        SilhouetteEdge { a: e.a, b: e.b, lit: e.t0, lit_corner: e.c0, unlit: e.t1, unlit_corner: e.c1 }
    } else {
        SilhouetteEdge { a: e.b, b: e.a, lit: e.t1, lit_corner: e.c1, unlit: e.t0, unlit_corner: e.c0 }
    }
}

/// The facing bit of triangle `t` (false past the end of the bits).
#[inline]
fn bit(bits: &[u64], t: u32) -> bool {
    bits.get(t as usize / 64).is_some_and(|w| (w >> (t % 64)) & 1 != 0)
}

/// Word `i` of the facing bits shifted down by `delta` bits: bit `k` is the facing of
/// triangle `64 i + k + delta` (0 past the end).
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

/// The distances worth a class, most edges first: at most [`MAX_CLASSES`], each with at least
/// [`MIN_EDGES_PER_WORD`] edges per facing word between its first and last `lo`.
fn choose_deltas(edges: &[ManifoldEdge]) -> Vec<u32> {
    let mut by_delta: Vec<(u32, u32)> = edges
        .iter()
        .filter_map(|e| {
            let (lo, hi) = lo_hi(e);
            (hi > lo).then_some((hi - lo, lo))
        })
        .collect();
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
    /// The scan over `edges` (its [`edges`](Self::edges) are the same edges, in scan order).
    pub fn new(edges: Vec<ManifoldEdge>) -> EdgeScan {
        let deltas = choose_deltas(&edges);
        // every edge goes to the first class of its distance, unless that class already has an
        // edge at its `lo` (two edges between the same two triangles): then to the residual
        let mut members: Vec<Vec<ManifoldEdge>> = vec![Vec::new(); deltas.len()];
        let mut residual = Vec::new();
        for e in edges {
            let (lo, hi) = lo_hi(&e);
            match deltas.iter().position(|&d| hi > lo && hi - lo == d) {
                Some(c) => members[c].push(e),
                None => residual.push(e),
            }
        }
        let mut scan = EdgeScan::default();
        for (&delta, mut es) in deltas.iter().zip(members) {
            es.sort_by_key(|e| lo_hi(e).0);
            let mut kept: Vec<ManifoldEdge> = Vec::with_capacity(es.len());
            for e in es {
                if kept.last().is_some_and(|k| lo_hi(k).0 == lo_hi(&e).0) {
                    residual.push(e);
                } else {
                    kept.push(e);
                }
            }
            let Some(last) = kept.last() else { continue };
            let first_word = lo_hi(&kept[0]).0 as usize / 64;
            let words = lo_hi(last).0 as usize / 64 - first_word + 1;
            let mut masks = vec![0u64; words];
            for e in &kept {
                let lo = lo_hi(e).0 as usize;
                masks[lo / 64 - first_word] |= 1 << (lo % 64);
            }
            let mut ranks = Vec::with_capacity(words);
            let mut before = 0u32;
            for m in &masks {
                ranks.push(before);
                before += m.count_ones();
            }
            scan.classes.push(DeltaClass { delta, first_word, masks, ranks, first: scan.edges.len() });
            scan.edges.extend(kept);
        }
        scan.rest = scan.edges.len();
        scan.pairs = residual.iter().map(|e| [e.t0, e.t1]).collect();
        scan.max_tri = residual.iter().map(|e| e.t0.max(e.t1)).max().unwrap_or(0);
        scan.edges.extend(residual);
        scan
    }

    /// The edges, in scan order: the order of [`scan_into`](Self::scan_into)'s output.
    pub fn edges(&self) -> &[ManifoldEdge] {
        &self.edges
    }

    /// Bytes one scan reads: the class masks and the residual triangle pairs.
    pub fn bytes(&self) -> usize {
        self.classes.iter().map(|c| c.masks.len() * 8).sum::<usize>() + self.pairs.len() * 8
    }

    /// Edges scanned a facing word at a time (the rest take two lookups each).
    pub fn word_scanned_edges(&self) -> usize {
        self.rest
    }

    /// Appends the possible silhouette for the packed facing `bits` to `out`: the edges of
    /// [`edges`](Self::edges) whose triangles' bits differ, in that order, each oriented as in
    /// its light-facing triangle; the same list as [`possible_silhouette`] over
    /// [`edges`](Self::edges) and the unpacked bits (a triangle past the bits counts as not
    /// facing).
    ///
    /// [`possible_silhouette`]: super::silhouette::possible_silhouette
    pub fn scan_into(&self, bits: &[u64], out: &mut Vec<SilhouetteEdge>) {
        for c in &self.classes {
            self.scan_class(c, bits, out);
        }
        let rest = &self.edges[self.rest..];
        if self.pairs.len() >= TABLE_MIN_EDGES {
            scan_table(&self.pairs, rest, self.max_tri, bits, out);
        } else {
            for (p, e) in self.pairs.iter().zip(rest) {
                let f0 = bit(bits, p[0]);
                if f0 != bit(bits, p[1]) {
                    out.push(oriented(e, f0));
                }
            }
        }
    }

    fn scan_class(&self, c: &DeltaClass, bits: &[u64], out: &mut Vec<SilhouetteEdge>) {
        let edges = &self.edges[c.first..];
        let mut hit = |i: usize, m: u64, mut s: u64| {
            while s != 0 {
                let k = s.trailing_zeros();
                s &= s - 1;
                let rank = c.ranks[i] + (m & ((1u64 << k) - 1)).count_ones();
                let e = &edges[rank as usize];
                out.push(oriented(e, bit(bits, e.t0)));
            }
        };
        let (q, r) = ((c.delta / 64) as usize, c.delta % 64);
        // Words whose own and shifted words all lie inside the bits: plain slices, no bounds
        // checks in the loop (a shift by 64 would overflow, so r == 0 reads one word).
        let inside = bits.len().saturating_sub(c.first_word + q + 1).min(c.masks.len());
        let own = bits.get(c.first_word..).unwrap_or(&[]);
        let far = bits.get(c.first_word + q..).unwrap_or(&[]);
        if r == 0 {
            for (i, ((&m, &f), &g)) in c.masks[..inside].iter().zip(own).zip(far).enumerate() {
                let s = (f ^ g) & m;
                if s != 0 {
                    hit(i, m, s);
                }
            }
        } else {
            for (i, ((&m, &f), g)) in c.masks[..inside].iter().zip(own).zip(far.windows(2)).enumerate() {
                let s = (f ^ ((g[0] >> r) | (g[1] << (64 - r)))) & m;
                if s != 0 {
                    hit(i, m, s);
                }
            }
        }
        for (i, &m) in c.masks.iter().enumerate().skip(inside) {
            let w = c.first_word + i;
            let f = bits.get(w).copied().unwrap_or(0);
            let s = (f ^ shifted(bits, w, c.delta)) & m;
            if s != 0 {
                hit(i, m, s);
            }
        }
    }
}

/// The residual scan with a byte a triangle: the two lookups an edge are then plain byte
/// loads. The table is this thread's, reused across calls (no allocation and no zeroing of
/// fresh pages per light), sized to a power of two so that a masked index needs no bounds
/// check; triangle ids past the bits read 0.
fn scan_table(pairs: &[[u32; 2]], edges: &[ManifoldEdge], max_tri: u32, bits: &[u64], out: &mut Vec<SilhouetteEdge>) {
    let need = (max_tri as usize + 1).max(bits.len() * 64);
    let size = need.next_power_of_two();
    let mask = size - 1;
    SCAN_TABLE.with_borrow_mut(|table| {
        if table.len() < size {
            table.clear();
            table.resize(size, 0);
        }
        let table = &mut table[..size];
        for (dst, &w) in table.chunks_exact_mut(64).zip(bits) {
            for (d8, byte) in dst.chunks_exact_mut(8).zip(w.to_le_bytes()) {
                d8.copy_from_slice(&SPREAD[byte as usize].to_le_bytes());
            }
        }
        table[(bits.len() * 64).min(size)..need].fill(0);
        let tab: &[u8] = table;
        let fast = |t: u32| tab[t as usize & mask];
        for (chunk, es) in pairs.chunks(16).zip(edges.chunks(16)) {
            // most blocks hold no silhouette edge: one OR-reduction, and only the rare blocks
            // with one are walked again
            let mut any = 0u8;
            for p in chunk {
                any |= fast(p[0]) ^ fast(p[1]);
            }
            if any == 0 {
                continue;
            }
            for (p, e) in chunk.iter().zip(es) {
                if fast(p[0]) != fast(p[1]) {
                    out.push(oriented(e, fast(p[0]) != 0));
                }
            }
        }
    });
}

thread_local! {
    /// [`scan_table`]'s byte-a-triangle table, kept per thread across calls.
    static SCAN_TABLE: std::cell::RefCell<Vec<u8>> = const { std::cell::RefCell::new(Vec::new()) };
}

/// Byte `k` of `SPREAD[b]` is bit `k` of `b`.
static SPREAD: [u64; 256] = {
    let mut t = [0u64; 256];
    let mut b = 0;
    while b < 256 {
        let mut k = 0;
        while k < 8 {
            t[b] |= (((b >> k) & 1) as u64) << (8 * k);
            k += 1;
        }
        b += 1;
    }
    t
};

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::silhouette::{possible_silhouette_packed, FacePlanes};
    use crate::geom::testmesh::{cube, shuffled, uv_sphere};
    use crate::geom::topology::Topology;
    use glam::{Vec3, Vec4};
    use proptest::prelude::*;

    fn check(edges: Vec<ManifoldEdge>, bits: &[u64]) -> EdgeScan {
        let scan = EdgeScan::new(edges.clone());
        let mut sorted_in = edges.clone();
        let mut sorted_scan = scan.edges().to_vec();
        let key = |e: &ManifoldEdge| (e.a, e.b, e.t0, e.t1, e.c0, e.c1);
        sorted_in.sort_by_key(key);
        sorted_scan.sort_by_key(key);
        assert_eq!(sorted_in, sorted_scan, "the scan holds exactly the given edges");
        let mut sil = Vec::new();
        scan.scan_into(bits, &mut sil);
        assert_eq!(sil, possible_silhouette_packed(scan.edges(), bits));
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
        // a fixed pseudo-random triangle order: no distance class, every edge looked up
        let t = Topology::build(&shuffled(&uv_sphere(1.0, 200, 101)));
        let mut bits = Vec::new();
        FacePlanes::new(&t.mesh).facing_packed(&t.mesh, Vec4::new(3.0, 2.0, 1.0, 1.0), false, &mut bits);
        let scan = check(t.manifold_edges.clone(), &bits);
        assert!(scan.pairs.len() >= TABLE_MIN_EDGES, "the byte table path is exercised");
        assert!(scan.word_scanned_edges() * 10 < t.manifold_edges.len());
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
            check(edges, &bits);
        }
    }
}
