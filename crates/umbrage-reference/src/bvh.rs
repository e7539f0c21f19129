//! A bounding volume hierarchy over world-space triangles, in f64, with the watertight
//! ray/triangle test of Woop, Benthin and Wald (JCGT 2013).
//!
//! Built with a binned surface-area heuristic (16 bins, leaves of at most 4 triangles).
//! Rays are tested against both faces of every triangle (no culling). Intervals are open:
//! a hit counts only for `t_min < t < t_max`. Hits exactly on a shared edge or vertex are
//! reported for (at least) one of the triangles sharing it: no ray slips through a
//! closed mesh.

use glam::DVec3;

/// A ray/triangle hit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// Ray parameter: the hit point is `origin + t * dir`.
    pub t: f64,
    /// Index of the triangle in the list the BVH was built from.
    pub tri: u32,
    /// Barycentric weights of vertices 1 and 2 (vertex 0 has `1 - u - v`).
    pub u: f64,
    /// Barycentric weight of vertex 2.
    pub v: f64,
}

#[derive(Clone, Copy, Debug)]
struct Node {
    min: DVec3,
    max: DVec3,
    /// Leaf: first triangle in `tris`. Interior: index of the right child (left is `self + 1`).
    index: u32,
    /// Number of triangles of a leaf; 0 for an interior node.
    count: u32,
}

/// BVH over a triangle soup. Triangle indices in [`Hit::tri`] and in the `ignore` callback
/// refer to the slice given to [`Bvh::build`].
#[derive(Clone, Debug, Default)]
pub struct Bvh {
    nodes: Vec<Node>,
    /// Triangles in leaf order.
    tris: Vec<[DVec3; 3]>,
    /// Original index of each triangle of `tris`.
    ids: Vec<u32>,
}

const MAX_LEAF: usize = 4;
const BINS: usize = 16;

#[derive(Clone, Copy)]
struct Bounds {
    min: DVec3,
    max: DVec3,
}

impl Bounds {
    const EMPTY: Bounds = Bounds { min: DVec3::splat(f64::INFINITY), max: DVec3::splat(f64::NEG_INFINITY) };
    fn grow(&mut self, o: &Bounds) {
        self.min = self.min.min(o.min);
        self.max = self.max.max(o.max);
    }
    fn grow_p(&mut self, p: DVec3) {
        self.min = self.min.min(p);
        self.max = self.max.max(p);
    }
    fn area(&self) -> f64 {
        let e = self.max - self.min;
        if e.x < 0.0 {
            return 0.0;
        }
        2.0 * (e.x * e.y + e.y * e.z + e.z * e.x)
    }
}

struct Prim {
    b: Bounds,
    c: DVec3,
    id: u32,
}

impl Bvh {
    /// Builds the hierarchy. Triangles with non-finite coordinates are skipped (never hit).
    pub fn build(triangles: &[[DVec3; 3]]) -> Bvh {
        let mut prims: Vec<Prim> = triangles
            .iter()
            .enumerate()
            .filter(|(_, t)| t.iter().all(|p| p.is_finite()))
            .map(|(i, t)| {
                let mut b = Bounds::EMPTY;
                t.iter().for_each(|p| b.grow_p(*p));
                Prim { c: (b.min + b.max) * 0.5, b, id: i as u32 }
            })
            .collect();
        let mut bvh = Bvh { nodes: Vec::with_capacity(prims.len() / 2 + 1), tris: Vec::new(), ids: Vec::new() };
        if prims.is_empty() {
            return bvh;
        }
        let n = prims.len();
        bvh.build_rec(&mut prims, 0, n);
        bvh.ids = prims.iter().map(|p| p.id).collect();
        bvh.tris = bvh.ids.iter().map(|&i| triangles[i as usize]).collect();
        bvh
    }

    /// Number of triangles in the hierarchy.
    pub fn len(&self) -> usize {
        self.ids.len()
    }
    /// True iff the hierarchy holds no triangle.
    pub fn is_empty(&self) -> bool {
        self.ids.is_empty()
    }

    fn build_rec(&mut self, prims: &mut [Prim], start: usize, end: usize) -> usize {
        let me = self.nodes.len();
        let mut b = Bounds::EMPTY;
        let mut cb = Bounds::EMPTY;
        for p in &prims[start..end] {
            b.grow(&p.b);
            cb.grow_p(p.c);
        }
        self.nodes.push(Node { min: b.min, max: b.max, index: start as u32, count: (end - start) as u32 });
        let n = end - start;
        if n <= MAX_LEAF {
            return me;
        }
        // Binned SAH on the widest centroid axis.
        let ext = cb.max - cb.min;
        let axis = if ext.x >= ext.y && ext.x >= ext.z {
            0
        } else if ext.y >= ext.z {
            1
        } else {
            2
        };
        if ext[axis].is_nan() || ext[axis] <= 0.0 {
            // All centroids coincide: split in the middle of the list if large, else leaf.
            if n <= 16 {
                return me;
            }
            let mid = start + n / 2;
            self.split_children(prims, me, start, mid, end);
            return me;
        }
        let lo = cb.min[axis];
        let scale = BINS as f64 / ext[axis];
        let bin_of = |c: f64| (((c - lo) * scale) as usize).min(BINS - 1);
        let mut bins = [(Bounds::EMPTY, 0usize); BINS];
        for p in &prims[start..end] {
            let k = bin_of(p.c[axis]);
            bins[k].0.grow(&p.b);
            bins[k].1 += 1;
        }
        let mut right_area = [0.0f64; BINS];
        let mut right_count = [0usize; BINS];
        let mut acc = Bounds::EMPTY;
        let mut cnt = 0;
        for k in (1..BINS).rev() {
            acc.grow(&bins[k].0);
            cnt += bins[k].1;
            right_area[k] = acc.area();
            right_count[k] = cnt;
        }
        let mut best = (f64::INFINITY, 0usize);
        let mut acc = Bounds::EMPTY;
        let mut cnt = 0;
        for k in 0..BINS - 1 {
            acc.grow(&bins[k].0);
            cnt += bins[k].1;
            if cnt == 0 || right_count[k + 1] == 0 {
                continue;
            }
            let cost = acc.area() * cnt as f64 + right_area[k + 1] * right_count[k + 1] as f64;
            if cost < best.0 {
                best = (cost, k);
            }
        }
        let leaf_cost = b.area() * n as f64;
        if best.0.is_infinite() || (best.0 >= leaf_cost && n <= 2 * MAX_LEAF) {
            if n <= 16 {
                return me;
            }
            // Fall back to a median split.
            prims[start..end].sort_by(|a, b| a.c[axis].total_cmp(&b.c[axis]));
            let mid = start + n / 2;
            self.split_children(prims, me, start, mid, end);
            return me;
        }
        // Partition.
        let mut i = start;
        let mut j = end;
        while i < j {
            if bin_of(prims[i].c[axis]) <= best.1 {
                i += 1;
            } else {
                j -= 1;
                prims.swap(i, j);
            }
        }
        let mid = if i == start || i == end { start + n / 2 } else { i };
        self.split_children(prims, me, start, mid, end);
        me
    }

    fn split_children(&mut self, prims: &mut [Prim], me: usize, start: usize, mid: usize, end: usize) {
        self.build_rec(prims, start, mid);
        let right = self.build_rec(prims, mid, end);
        self.nodes[me].index = right as u32;
        self.nodes[me].count = 0;
    }

    /// The closest hit with `t_min < t < t_max`, if any. `dir` need not be unit length.
    pub fn closest_hit(&self, origin: DVec3, dir: DVec3, t_min: f64, t_max: f64) -> Option<Hit> {
        if self.nodes.is_empty() {
            return None;
        }
        let ray = Ray::new(origin, dir);
        let mut best: Option<Hit> = None;
        let mut t_far = t_max;
        let mut stack = [0u32; 96];
        let mut sp = 0usize;
        let mut node = 0usize;
        loop {
            let nd = &self.nodes[node];
            if nd.count > 0 {
                let s = nd.index as usize;
                for k in s..s + nd.count as usize {
                    if let Some((t, u, v)) = ray.intersect(&self.tris[k], t_min, t_far) {
                        t_far = t;
                        best = Some(Hit { t, tri: self.ids[k], u, v });
                    }
                }
            } else {
                let l = node + 1;
                let r = nd.index as usize;
                let tl = ray.slab(&self.nodes[l], t_min, t_far);
                let tr = ray.slab(&self.nodes[r], t_min, t_far);
                match (tl, tr) {
                    (Some(a), Some(b)) => {
                        let (near, far) = if a <= b { (l, r) } else { (r, l) };
                        if sp == stack.len() {
                            // Pathologically deep tree: answer by brute force.
                            return self.brute_closest(origin, dir, t_min, t_max);
                        }
                        stack[sp] = far as u32;
                        sp += 1;
                        node = near;
                        continue;
                    }
                    (Some(_), None) => {
                        node = l;
                        continue;
                    }
                    (None, Some(_)) => {
                        node = r;
                        continue;
                    }
                    (None, None) => {}
                }
            }
            // pop (re-test the box against the shrunk interval)
            loop {
                if sp == 0 {
                    return best;
                }
                sp -= 1;
                let c = stack[sp] as usize;
                if ray.slab(&self.nodes[c], t_min, t_far).is_some() {
                    node = c;
                    break;
                }
            }
        }
    }

    /// Whether any triangle not rejected by `ignore` (called with the original triangle
    /// index) is hit with `t_min < t < t_max`.
    pub fn any_hit(&self, origin: DVec3, dir: DVec3, t_min: f64, t_max: f64, ignore: impl Fn(u32) -> bool) -> bool {
        if self.nodes.is_empty() {
            return false;
        }
        let ray = Ray::new(origin, dir);
        let mut stack = [0u32; 96];
        let mut sp = 0usize;
        stack[sp] = 0;
        sp += 1;
        while sp > 0 {
            sp -= 1;
            let node = stack[sp] as usize;
            let nd = &self.nodes[node];
            if ray.slab(nd, t_min, t_max).is_none() {
                continue;
            }
            if nd.count > 0 {
                let s = nd.index as usize;
                for k in s..s + nd.count as usize {
                    if ray.intersect(&self.tris[k], t_min, t_max).is_some() && !ignore(self.ids[k]) {
                        return true;
                    }
                }
            } else if sp + 2 <= stack.len() {
                stack[sp] = nd.index;
                stack[sp + 1] = (node + 1) as u32;
                sp += 2;
            } else {
                // Pathologically deep tree: fall back to brute force over this subtree's range.
                return self.brute_any(origin, dir, t_min, t_max, &ignore);
            }
        }
        false
    }

    /// Calls `f` for every triangle hit with `t_min < t < t_max`, in no particular order
    /// (each triangle at most once per call; coincident duplicate triangles are separate
    /// triangles and are each reported). `f` returns `false` to stop the traversal early.
    /// Returns `false` iff stopped early. `dir` need not be unit length.
    pub fn all_hits(&self, origin: DVec3, dir: DVec3, t_min: f64, t_max: f64, mut f: impl FnMut(Hit) -> bool) -> bool {
        if self.nodes.is_empty() {
            return true;
        }
        let ray = Ray::new(origin, dir);
        // A growable stack: no depth limit, every triangle visited at most once.
        let mut stack: Vec<u32> = Vec::with_capacity(64);
        stack.push(0);
        while let Some(node) = stack.pop() {
            let nd = &self.nodes[node as usize];
            if ray.slab(nd, t_min, t_max).is_none() {
                continue;
            }
            if nd.count > 0 {
                let s = nd.index as usize;
                for k in s..s + nd.count as usize {
                    if let Some((t, u, v)) = ray.intersect(&self.tris[k], t_min, t_max) {
                        if !f(Hit { t, tri: self.ids[k], u, v }) {
                            return false;
                        }
                    }
                }
            } else {
                stack.push(nd.index);
                stack.push(node + 1);
            }
        }
        true
    }

    /// Every hit with `t_min < t < t_max`, sorted by `t` (ties by triangle index).
    pub fn collect_hits(&self, origin: DVec3, dir: DVec3, t_min: f64, t_max: f64) -> Vec<Hit> {
        let mut v = Vec::new();
        self.all_hits(origin, dir, t_min, t_max, |h| {
            v.push(h);
            true
        });
        v.sort_by(|a, b| a.t.total_cmp(&b.t).then(a.tri.cmp(&b.tri)));
        v
    }

    fn brute_closest(&self, origin: DVec3, dir: DVec3, t_min: f64, t_max: f64) -> Option<Hit> {
        let ray = Ray::new(origin, dir);
        let mut best: Option<Hit> = None;
        let mut t_far = t_max;
        for (k, t) in self.tris.iter().enumerate() {
            if let Some((t, u, v)) = ray.intersect(t, t_min, t_far) {
                t_far = t;
                best = Some(Hit { t, tri: self.ids[k], u, v });
            }
        }
        best
    }

    fn brute_any(&self, origin: DVec3, dir: DVec3, t_min: f64, t_max: f64, ignore: &impl Fn(u32) -> bool) -> bool {
        let ray = Ray::new(origin, dir);
        self.tris.iter().zip(&self.ids).any(|(t, &id)| ray.intersect(t, t_min, t_max).is_some() && !ignore(id))
    }
}

/// A ray with the precomputed shear of the watertight test.
struct Ray {
    o: DVec3,
    inv: DVec3,
    kx: usize,
    ky: usize,
    kz: usize,
    sx: f64,
    sy: f64,
    sz: f64,
}

impl Ray {
    fn new(o: DVec3, d: DVec3) -> Ray {
        let a = d.abs();
        let kz = if a.x >= a.y && a.x >= a.z {
            0
        } else if a.y >= a.z {
            1
        } else {
            2
        };
        let mut kx = (kz + 1) % 3;
        let mut ky = (kx + 1) % 3;
        if d[kz] < 0.0 {
            std::mem::swap(&mut kx, &mut ky);
        }
        Ray { o, inv: d.recip(), kx, ky, kz, sx: d[kx] / d[kz], sy: d[ky] / d[kz], sz: 1.0 / d[kz] }
    }

    /// Entry distance into the node's box within [t0, t1], conservative (Ize 2013 padding).
    #[inline]
    fn slab(&self, n: &Node, t0: f64, t1: f64) -> Option<f64> {
        let a = (n.min - self.o) * self.inv;
        let b = (n.max - self.o) * self.inv;
        let lo = a.min(b);
        let hi = a.max(b);
        // f64::max/min ignore a NaN operand (0 * inf when the origin lies on a slab plane).
        let tn = t0.max(lo.x).max(lo.y).max(lo.z);
        let tf = t1.min(hi.x).min(hi.y).min(hi.z) * (1.0 + 4.0 * f64::EPSILON);
        if tn <= tf {
            Some(tn)
        } else {
            None
        }
    }

    /// Watertight ray/triangle test; returns (t, u, v) for `t0 < t < t1`.
    #[inline]
    fn intersect(&self, tri: &[DVec3; 3], t0: f64, t1: f64) -> Option<(f64, f64, f64)> {
        let (kx, ky, kz) = (self.kx, self.ky, self.kz);
        let a = tri[0] - self.o;
        let b = tri[1] - self.o;
        let c = tri[2] - self.o;
        let ax = a[kx] - self.sx * a[kz];
        let ay = a[ky] - self.sy * a[kz];
        let bx = b[kx] - self.sx * b[kz];
        let by = b[ky] - self.sy * b[kz];
        let cx = c[kx] - self.sx * c[kz];
        let cy = c[ky] - self.sy * c[kz];
        let u = cx * by - cy * bx;
        let v = ax * cy - ay * cx;
        let w = bx * ay - by * ax;
        if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
            return None;
        }
        let det = u + v + w;
        if det == 0.0 || !det.is_finite() {
            return None;
        }
        let az = self.sz * a[kz];
        let bz = self.sz * b[kz];
        let cz = self.sz * c[kz];
        let t = (u * az + v * bz + w * cz) / det;
        if !(t > t0 && t < t1) {
            return None;
        }
        // u, v, w are the weights of vertices 0, 1, 2.
        Some((t, v / det, w / det))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn quad(z: f64) -> Vec<[DVec3; 3]> {
        let p = |x, y| DVec3::new(x, y, z);
        vec![[p(0.0, 0.0), p(1.0, 0.0), p(1.0, 1.0)], [p(0.0, 0.0), p(1.0, 1.0), p(0.0, 1.0)]]
    }

    #[test]
    fn reference_bvh_hits_and_edges() {
        let mut tris = quad(1.0);
        tris.extend(quad(2.0));
        let bvh = Bvh::build(&tris);
        let h = bvh.closest_hit(DVec3::new(0.3, 0.6, 0.0), DVec3::Z, 0.0, f64::INFINITY).unwrap();
        assert!((h.t - 1.0).abs() < 1e-12 && h.tri == 1);
        // Exactly on the shared diagonal: never slips through.
        let h = bvh.closest_hit(DVec3::new(0.5, 0.5, 0.0), DVec3::Z, 0.0, f64::INFINITY).unwrap();
        assert!((h.t - 1.0).abs() < 1e-12);
        assert!(bvh.any_hit(DVec3::new(0.5, 0.5, 0.0), DVec3::Z, 0.0, 1.5, |_| false));
        assert!(!bvh.any_hit(DVec3::new(0.5, 0.5, 0.0), DVec3::Z, 0.0, 1.0, |_| false));
        assert!(bvh.any_hit(DVec3::new(0.2, 0.7, 0.0), DVec3::Z, 0.0, 3.0, |t| t == 1));
        assert!(!bvh.any_hit(DVec3::new(0.2, 0.7, 0.0), DVec3::Z, 0.0, 3.0, |t| t == 1 || t == 3));
        assert!(bvh.closest_hit(DVec3::new(1.5, 0.5, 0.0), DVec3::Z, 0.0, f64::INFINITY).is_none());
    }

    #[test]
    fn reference_bvh_matches_brute_force() {
        // Pseudo-random soup.
        let mut s = 12345u64;
        let mut rnd = || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut tris = Vec::new();
        for _ in 0..2000 {
            let c = DVec3::new(rnd(), rnd(), rnd()) * 10.0;
            let mut r = || c + DVec3::new(rnd() - 0.5, rnd() - 0.5, rnd() - 0.5);
            tris.push([r(), r(), r()]);
        }
        let bvh = Bvh::build(&tris);
        for _ in 0..500 {
            let o = DVec3::new(rnd(), rnd(), rnd()) * 12.0 - 1.0;
            let d = DVec3::new(rnd() - 0.5, rnd() - 0.5, rnd() - 0.5);
            let ray = Ray::new(o, d);
            let brute = tris
                .iter()
                .enumerate()
                .filter_map(|(i, t)| ray.intersect(t, 0.0, f64::INFINITY).map(|h| (h.0, i)))
                .min_by(|a, b| a.0.total_cmp(&b.0));
            let h = bvh.closest_hit(o, d, 0.0, f64::INFINITY);
            assert_eq!(h.map(|h| h.tri as usize), brute.map(|b| b.1));
            assert_eq!(bvh.any_hit(o, d, 0.0, f64::INFINITY, |_| false), brute.is_some());
            let mut all: Vec<u32> =
                tris.iter().enumerate().filter(|(_, t)| ray.intersect(t, 0.0, f64::INFINITY).is_some()).map(|(i, _)| i as u32).collect();
            all.sort();
            let mut got: Vec<u32> = bvh.collect_hits(o, d, 0.0, f64::INFINITY).iter().map(|h| h.tri).collect();
            got.sort();
            assert_eq!(got, all);
        }
    }
}
