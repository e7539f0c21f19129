//! The silhouette side of a caster's static tables in scan order: the edges of its closed
//! manifold parts filed by the pair of 64-slot facing blocks their two triangles lie in
//! ([`WordPairs`]), so the `find` stage skips a whole group whose two blocks are uniform and
//! equal (both all ones or both all zeros) without reading its edges, as the CPU's
//! [`EdgeScan`](crate::geom::edgescan::EdgeScan) skips its word pairs.
//!
//! Slots are the caster's [`TriangleOrder`](crate::geom::order::TriangleOrder) (the planes'
//! scan order): a spatial order, so a block is a compact patch of the surface and most edges
//! join two slots of one block or of neighbouring blocks.

use crate::geom::planes::GPU_BLOCK;

/// Edges one group holds at most: `find` keeps a group's silhouette edges in one `u32` mask.
pub(crate) const GROUP_EDGES: usize = 32;

/// A caster's edge table and its word-pair groups, as `shaders/silhouette.wgsl` reads them.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub(crate) struct WordPairs {
    /// Per edge `(s0, s1, c0 | c1 << 8, pa | pb << 8)`: the slots of its two triangles `t0`
    /// (which walks a -> b from corner `c0`) and `t1`, and the bit positions of its lower and
    /// higher slot in their blocks; group after group.
    pub edges: Vec<[u32; 4]>,
    /// Per group `(a, b, first, count)`: its edges `edges[first .. first + count]` (at most
    /// [`GROUP_EDGES`]) have their lower slot in block `a` and their higher one in block `b`;
    /// groups by increasing `(a, b)`.
    pub groups: Vec<[u32; 4]>,
}

/// Files `edges`, each `(s0, s1, c0 | c1 << 8)` (the two triangles' slots and corners), by
/// the pair of blocks of their slots; the edges of a pair keep their given order.
pub(crate) fn word_pairs(edges: impl IntoIterator<Item = (u32, u32, u32)>) -> WordPairs {
    let block = GPU_BLOCK as u32;
    let mut keyed: Vec<((u32, u32), [u32; 4])> = edges
        .into_iter()
        .map(|(s0, s1, corners)| {
            let (lo, hi) = (s0.min(s1), s0.max(s1));
            ((lo / block, hi / block), [s0, s1, corners, (lo % block) | ((hi % block) << 8)])
        })
        .collect();
    keyed.sort_by_key(|k| k.0);
    let mut out = WordPairs { edges: Vec::with_capacity(keyed.len()), groups: Vec::new() };
    for run in keyed.chunk_by(|x, y| x.0 == y.0) {
        for part in run.chunks(GROUP_EDGES) {
            let (a, b) = part[0].0;
            out.groups.push([a, b, out.edges.len() as u32, part.len() as u32]);
            out.edges.extend(part.iter().map(|k| k.1));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pass::compute::ComputeMesh;
    use crate::shadow::Caster;
    use glam::Mat4;

    /// Every edge exactly once, each group's edges in its two blocks with their bit positions,
    /// the groups contiguous and bounded.
    fn check(input: &[(u32, u32, u32)], w: &WordPairs) {
        let mut given: Vec<[u32; 3]> = input.iter().map(|&(a, b, c)| [a, b, c]).collect();
        let mut filed: Vec<[u32; 3]> = w.edges.iter().map(|e| [e[0], e[1], e[2]]).collect();
        given.sort_unstable();
        filed.sort_unstable();
        assert_eq!(given, filed, "every edge exactly once");
        let mut next = 0;
        let mut last = None;
        for g in &w.groups {
            let [a, b, first, count] = *g;
            assert_eq!(first, next, "groups contiguous");
            assert!(count >= 1 && count as usize <= GROUP_EDGES);
            assert!(a <= b && last.is_none_or(|l| l <= (a, b)), "groups by (a, b)");
            last = Some((a, b));
            for e in &w.edges[first as usize..(first + count) as usize] {
                let (lo, hi) = (e[0].min(e[1]), e[0].max(e[1]));
                assert_eq!((lo / 64, hi / 64), (a, b));
                assert_eq!(e[3], (lo % 64) | ((hi % 64) << 8));
            }
            next = first + count;
        }
        assert_eq!(next as usize, w.edges.len());
    }

    #[test]
    fn word_pairs_cover_every_edge_once() {
        // pseudo-random pairs, many in one block pair (split into groups of 32), some far
        let mut x = 12345u64;
        let mut rnd = |n: u64| {
            x = x.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            ((x >> 33) % n) as u32
        };
        let mut input = Vec::new();
        for k in 0..3000u32 {
            let s0 = rnd(2000);
            let s1 = if k % 3 == 0 { rnd(2000) } else { (s0 / 64) * 64 + rnd(64) };
            input.push((s0, s1, k));
        }
        input.extend((0..100).map(|k| (5, 7, 100_000 + k)));
        let w = word_pairs(input.clone());
        check(&input, &w);
        assert!(w.groups.iter().filter(|g| g[0] == 0 && g[1] == 0).count() >= 4);
        assert_eq!(word_pairs(Vec::new()), WordPairs::default());
    }

    #[test]
    fn caster_tables_are_in_scan_order() {
        let mesh = crate::geom::testmesh::shuffled(&crate::geom::testmesh::uv_sphere(1.0, 40, 21));
        let c = Caster::with_chunk_limit("s", &mesh, Mat4::IDENTITY, 300).unwrap();
        let order = c.planes.order();
        assert!(!order.is_identity());
        let m = ComputeMesh::new(&c);
        let input: Vec<(u32, u32, u32)> =
            c.topology.manifold_edges.iter().map(|e| (order.slot(e.t0), order.slot(e.t1), e.c0 as u32 | (e.c1 as u32) << 8)).collect();
        check(&input, &WordPairs { edges: m.edges.clone(), groups: m.groups.clone() });
        // the triangles, planes and blocks by slot
        for (s, row) in m.tris.iter().enumerate() {
            let t = order.triangle(s as u32) as usize;
            assert_eq!([row[0], row[1], row[2]], c.mesh().triangles[t]);
            assert_eq!(m.planes[s], c.planes.planes_xyzd()[t]);
        }
        assert_eq!(m.blocks.len(), 3 * c.triangle_count.div_ceil(64));
        // a spatial order files most edges inside a block or between a few neighbours
        assert!(m.groups.len() * 8 < m.edges.len(), "{} groups for {} edges", m.groups.len(), m.edges.len());
    }
}
