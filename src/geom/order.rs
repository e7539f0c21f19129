//! The order the silhouette structures scan a mesh's triangles in ([`TriangleOrder`]).
//!
//! [`FacePlanes`](super::planes::FacePlanes) decides a whole 64-triangle block of facing bits
//! at once when the block's planes are close, and [`EdgeScan`](super::edgescan::EdgeScan)
//! skips every edge between two blocks that face the light the same way: both pay only when
//! the triangles of a block are neighbours on the surface. Meshes from files often are not
//! (scanned or exported meshes come in any order), so casters scan their triangles in a
//! spatial order computed once at load ([`TriangleOrder::spatial`], meshoptimizer's spatial
//! sort of the triangle centroids), while everything observable (the welded mesh, chunks,
//! triangle ids, plans) keeps the caller's order: the permutation lives only in the
//! silhouette structures, and a facing bit is looked up through [`TriangleOrder::slot`].

use super::mesh::Mesh;

/// A permutation of a mesh's triangles: slot `s` of the scan holds triangle
/// [`triangle(s)`](Self::triangle), triangle `t` sits in slot [`slot(t)`](Self::slot).
/// The identity order stores nothing.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct TriangleOrder {
    /// Slot -> triangle (empty for the identity).
    to_triangle: Vec<u32>,
    /// Triangle -> slot (empty for the identity).
    to_slot: Vec<u32>,
}

impl TriangleOrder {
    /// The identity order (every triangle in its own slot).
    pub fn identity() -> TriangleOrder {
        TriangleOrder::default()
    }

    /// The order whose slot `s` holds triangle `to_triangle[s]`; `None` unless `to_triangle`
    /// is a permutation of `0..to_triangle.len()`.
    pub fn from_slots(to_triangle: Vec<u32>) -> Option<TriangleOrder> {
        let mut to_slot = vec![u32::MAX; to_triangle.len()];
        for (s, &t) in to_triangle.iter().enumerate() {
            let slot = to_slot.get_mut(t as usize)?;
            if *slot != u32::MAX {
                return None;
            }
            *slot = s as u32;
        }
        if to_triangle.iter().enumerate().all(|(s, &t)| s as u32 == t) {
            return Some(TriangleOrder::identity());
        }
        Some(TriangleOrder { to_triangle, to_slot })
    }

    /// The groups `groups` (which together must hold every triangle of `mesh` once: a caster's
    /// parts) one after the other, the triangles of each in meshoptimizer's spatial order of
    /// their centroids (`meshopt::spatial_sort_remap`: a space-filling curve, so that 64
    /// consecutive slots are a compact patch of the surface), then reordered for the vertex
    /// cache from that order (`meshopt::optimize_vertex_cache`: strips and fans that stay in a
    /// small region, so that most edges join slots a few apart, which the edge scan's distance
    /// classes take a word at a time). The order of a mesh depends only on its geometry and its
    /// groups' triangle sets, not on the order of its triangles (up to centroids in the same
    /// cell of the sort's 65536³ grid, which keep their relative order). Panics when the groups
    /// are not a partition.
    pub fn spatial(mesh: &Mesh, groups: &[&[u32]]) -> TriangleOrder {
        let mut to_triangle = Vec::with_capacity(mesh.triangles.len());
        let mut centroids: Vec<[f32; 3]> = Vec::new();
        let mut local = vec![u32::MAX; mesh.positions.len()];
        for g in groups {
            centroids.clear();
            centroids.extend(g.iter().map(|&t| {
                let [a, b, c] = mesh.triangles[t as usize].map(|v| mesh.positions[v as usize]);
                ((a + b + c) / 3.0).to_array()
            }));
            // non-finite coordinates would make the sort's quantisation meaningless: such a group
            // keeps its order (the order never changes a result, only the speed)
            let remap: Vec<u32> = if centroids.iter().flatten().all(|x| x.is_finite()) {
                meshopt::spatial_sort_remap_decoder(&centroids)
            } else {
                (0..g.len() as u32).collect()
            };
            let base = to_triangle.len();
            to_triangle.resize(base + g.len(), u32::MAX);
            for (&t, &r) in g.iter().zip(&remap) {
                to_triangle[base + r as usize] = t;
            }
            vertex_cache_order(mesh, &mut to_triangle[base..], &mut local);
        }
        assert_eq!(to_triangle.len(), mesh.triangles.len(), "the groups hold every triangle once");
        TriangleOrder::from_slots(to_triangle).expect("the groups hold every triangle once")
    }

    /// True for the identity order.
    pub fn is_identity(&self) -> bool {
        self.to_slot.is_empty()
    }

    /// The slot of triangle `t`.
    #[inline]
    pub fn slot(&self, t: u32) -> u32 {
        if self.to_slot.is_empty() {
            t
        } else {
            self.to_slot[t as usize]
        }
    }

    /// The triangle in slot `s`.
    #[inline]
    pub fn triangle(&self, s: u32) -> u32 {
        if self.to_triangle.is_empty() {
            s
        } else {
            self.to_triangle[s as usize]
        }
    }

    /// Triangles the order permutes (0 for the identity, which fits any mesh).
    pub fn len(&self) -> usize {
        self.to_slot.len()
    }

    /// True for the identity order (it permutes nothing).
    pub fn is_empty(&self) -> bool {
        self.to_slot.is_empty()
    }

    /// True when the order can index a mesh of `n` triangles (the identity fits every mesh).
    pub fn fits(&self, n: usize) -> bool {
        self.is_identity() || self.to_slot.len() == n
    }

    /// Bytes the order's two tables hold.
    pub fn bytes(&self) -> usize {
        (self.to_slot.len() + self.to_triangle.len()) * 4
    }
}

/// Reorders the triangles `slots` (ids into `mesh`, in place) for the vertex cache, from their
/// current order; meshoptimizer keeps each triangle's corners in place, so each output
/// triangle is found again by its three indices (equal triangles are interchangeable: they take
/// their slots in their given order). `local`: one `u32::MAX` per vertex of the mesh (scratch,
/// left as it was found).
fn vertex_cache_order(mesh: &Mesh, slots: &mut [u32], local: &mut [u32]) {
    if slots.len() < 3 {
        return;
    }
    // the group's vertices numbered from 0, so that meshoptimizer's tables are the group's size
    let mut used = Vec::new();
    let indices: Vec<u32> = slots
        .iter()
        .flat_map(|&t| mesh.triangles[t as usize])
        .map(|v| {
            if local[v as usize] == u32::MAX {
                local[v as usize] = used.len() as u32;
                used.push(v);
            }
            local[v as usize]
        })
        .collect();
    let optimized = meshopt::optimize_vertex_cache(&indices, used.len());
    let mut keyed: Vec<([u32; 3], u32)> = indices.chunks_exact(3).zip(slots.iter()).map(|(k, &t)| ([k[0], k[1], k[2]], t)).collect();
    keyed.sort_by_key(|k| k.0); // stable: equal triangles keep their order
                                // per run of equal triangles (at its first index): how many are placed
    let mut placed = vec![0u32; keyed.len()];
    for (slot, tri) in slots.iter_mut().zip(optimized.chunks_exact(3)) {
        let key = [tri[0], tri[1], tri[2]];
        let first = keyed.partition_point(|k| k.0 < key);
        let i = first + placed[first] as usize;
        placed[first] += 1;
        debug_assert_eq!(keyed[i].0, key, "meshoptimizer keeps every triangle");
        *slot = keyed[i].1;
    }
    for v in used {
        local[v as usize] = u32::MAX;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::testmesh::{shuffled, uv_sphere};
    use proptest::prelude::*;

    #[test]
    fn spatial_is_a_permutation_independent_of_input_order() {
        let m = uv_sphere(1.0, 40, 21);
        let n = m.triangles.len() as u32;
        let all: Vec<u32> = (0..n).collect();
        let o = TriangleOrder::spatial(&m, &[&all]);
        assert!(!o.is_identity() && o.fits(m.triangles.len()) && !o.fits(3));
        for t in 0..n {
            assert_eq!(o.triangle(o.slot(t)), t);
        }
        // the shuffled sphere's order lists the same triangles slot by slot
        let s = shuffled(&m);
        let os = TriangleOrder::spatial(&s, &[&all]);
        for slot in 0..n {
            assert_eq!(m.triangles[o.triangle(slot) as usize], s.triangles[os.triangle(slot) as usize]);
        }
        // groups stay contiguous, in the given order
        let (a, b): (Vec<u32>, Vec<u32>) = all.iter().partition(|&&t| t.is_multiple_of(3));
        let o = TriangleOrder::spatial(&m, &[&b, &a]);
        assert!((0..b.len() as u32).all(|s| !o.triangle(s).is_multiple_of(3)));
    }

    proptest! {
        #[test]
        fn from_slots_checks_and_inverts(mut v in prop::collection::vec(0u32..1000, 0..64), dup in any::<bool>()) {
            v.sort_unstable();
            v.dedup();
            let n = v.len() as u32;
            let perm: Vec<u32> = v.iter().map(|&x| x % n.max(1)).collect();
            let mut p: Vec<u32> = (0..n).collect();
            for (i, &x) in perm.iter().enumerate() {
                p.swap(i, x as usize);
            }
            if dup && n > 1 {
                p[0] = p[1];
                prop_assert!(TriangleOrder::from_slots(p).is_none());
            } else {
                let o = TriangleOrder::from_slots(p.clone()).unwrap();
                for (s, &t) in p.iter().enumerate() {
                    prop_assert_eq!(o.triangle(s as u32), t);
                    prop_assert_eq!(o.slot(t), s as u32);
                }
            }
        }
    }
}
