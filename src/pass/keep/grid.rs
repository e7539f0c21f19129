//! A spatial index over the casters' world bounds: a uniform grid of cubic cells, each caster
//! listed in every cell its box overlaps (a caster over [`MAX_CELLS`] cells, a floor under a
//! whole level, in a list every query returns). It is kept as casters move: a caster whose
//! transform or positions changed is taken out of its old cells and put in its new ones; the
//! grid is rebuilt when casters are added or removed.
//!
//! A query returns a superset of the casters whose boxes touch the query box (the cells are
//! found with the same `floor` as the boxes, and the query box is widened by a margin), so a
//! caster it leaves out is one the planner would cull for the light's range anyway.

use crate::geom::Aabb;
use glam::{IVec3, Vec3};
use std::collections::HashMap;

/// Cells a caster may cover before it goes to the list every query returns.
pub(crate) const MAX_CELLS: i64 = 512;
/// Cells a query may visit before it returns every caster instead.
const MAX_QUERY_CELLS: i64 = 4096;

/// The grid (see the module docs).
#[derive(Default)]
pub(crate) struct Grid {
    /// The cell size (0: no grid built yet).
    cell: f32,
    cells: HashMap<IVec3, Vec<u32>, super::fx::FxBuild>,
    /// Casters too big for the cells: every query returns them.
    big: Vec<u32>,
    /// Per caster (dense index), the cell range it is listed in (`None`: in `big`).
    placed: Vec<Option<(IVec3, IVec3)>>,
    /// Per caster, the query stamp that last returned it.
    stamp: Vec<u64>,
    query: u64,
}

/// The cells a box overlaps, at cell size `cell`.
fn cell_range(b: &Aabb, cell: f32) -> (IVec3, IVec3) {
    let lo = (b.min / cell).floor();
    let hi = (b.max / cell).floor();
    let clamp = |v: Vec3| v.clamp(Vec3::splat(-1e9), Vec3::splat(1e9)).as_ivec3();
    (clamp(lo), clamp(hi))
}

/// How many cells a range covers, saturating: a box of huge coordinates (clamped to 1e9
/// cells a side) covers more than an `i64` counts, and is then simply "too big to place".
fn volume((lo, hi): (IVec3, IVec3)) -> i64 {
    let d = (hi.as_i64vec3() - lo.as_i64vec3()) + 1;
    d.x.max(0).saturating_mul(d.y.max(0)).saturating_mul(d.z.max(0))
}

impl Grid {
    /// Builds the grid over `bounds` (one box per caster, dense order): the cell is twice the
    /// median box diagonal (at least a thousandth of the scene's size).
    pub fn rebuild(&mut self, bounds: &[Aabb]) {
        let mut diag: Vec<f32> = bounds.iter().map(|b| b.extent().length()).filter(|d| d.is_finite()).collect();
        diag.sort_by(f32::total_cmp);
        let median = diag.get(diag.len() / 2).copied().unwrap_or(1.0);
        self.cell = (2.0 * median).max(1e-3);
        self.cells.clear();
        self.big.clear();
        self.placed = vec![None; bounds.len()];
        self.stamp = vec![0; bounds.len()];
        for (i, b) in bounds.iter().enumerate() {
            self.insert(i, b);
        }
    }

    /// Whether the grid was built for `n` casters.
    pub fn built_for(&self, n: usize) -> bool {
        self.cell > 0.0 && self.placed.len() == n
    }

    fn insert(&mut self, i: usize, b: &Aabb) {
        let r = cell_range(b, self.cell);
        let finite = b.min.is_finite() && b.max.is_finite();
        if !finite || volume(r) > MAX_CELLS {
            self.big.push(i as u32);
            self.placed[i] = None;
            return;
        }
        for x in r.0.x..=r.1.x {
            for y in r.0.y..=r.1.y {
                for z in r.0.z..=r.1.z {
                    self.cells.entry(IVec3::new(x, y, z)).or_default().push(i as u32);
                }
            }
        }
        self.placed[i] = Some(r);
    }

    /// Caster `i` has new bounds `b`: out of its old cells, into the new ones.
    pub fn update(&mut self, i: usize, b: &Aabb) {
        let id = i as u32;
        match self.placed[i] {
            Some(old) if old == cell_range(b, self.cell) => return,
            Some((lo, hi)) => {
                for x in lo.x..=hi.x {
                    for y in lo.y..=hi.y {
                        for z in lo.z..=hi.z {
                            if let Some(v) = self.cells.get_mut(&IVec3::new(x, y, z)) {
                                v.retain(|&c| c != id);
                            }
                        }
                    }
                }
            }
            None => self.big.retain(|&c| c != id),
        }
        self.insert(i, b);
    }

    /// Marks the casters whose boxes may touch the box `min..max` (`None`: every caster) and
    /// returns the stamp they carry; [`Grid::hit`] then tells each one.
    #[cfg(test)]
    pub fn query(&mut self, bounds: Option<(Vec3, Vec3)>) -> Option<u64> {
        let mut out = Vec::new();
        self.query_into(bounds, &mut out).then_some(self.query)
    }

    /// The casters whose boxes may touch the box `min..max`, in ascending order, into `out`;
    /// `false` (and `out` empty) where the query returns every caster (no bounds, or a box
    /// over more cells than [`MAX_QUERY_CELLS`]).
    pub fn query_into(&mut self, bounds: Option<(Vec3, Vec3)>, out: &mut Vec<u32>) -> bool {
        out.clear();
        let Some((min, max)) = bounds else { return false };
        if !(min.is_finite() && max.is_finite()) {
            return false;
        }
        let margin = (max - min).abs() * 1e-4 + Vec3::splat(self.cell * 1e-3);
        let r = cell_range(&Aabb { min: min - margin, max: max + margin }, self.cell);
        if volume(r) > MAX_QUERY_CELLS {
            return false;
        }
        self.query += 1;
        let q = self.query;
        let mut mark = |c: u32, stamp: &mut [u64]| {
            if stamp[c as usize] != q {
                stamp[c as usize] = q;
                out.push(c);
            }
        };
        for x in r.0.x..=r.1.x {
            for y in r.0.y..=r.1.y {
                for z in r.0.z..=r.1.z {
                    if let Some(v) = self.cells.get(&IVec3::new(x, y, z)) {
                        for &c in v {
                            mark(c, &mut self.stamp);
                        }
                    }
                }
            }
        }
        for &c in &self.big {
            mark(c, &mut self.stamp);
        }
        out.sort_unstable();
        true
    }

    /// Whether caster `i` was returned by the query of stamp `q` (`None`: every caster).
    #[cfg(test)]
    pub fn hit(&self, q: Option<u64>, i: usize) -> bool {
        q.is_none_or(|q| self.stamp[i] == q)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn aabb(min: [f32; 3], max: [f32; 3]) -> Aabb {
        Aabb { min: Vec3::from(min), max: Vec3::from(max) }
    }

    #[test]
    fn queries_return_every_touching_box_and_follow_moves() {
        let mut boxes: Vec<Aabb> = (0..100)
            .map(|i| {
                let p = Vec3::new((i % 10) as f32 * 3.0, 0.0, (i / 10) as f32 * 3.0);
                aabb((p - 0.5).into(), (p + 0.5).into())
            })
            .collect();
        boxes.push(aabb([-1000.0, -1.0, -1000.0], [1000.0, 0.0, 1000.0])); // a floor
        let mut g = Grid::default();
        g.rebuild(&boxes);
        let touches = |b: &Aabb, min: Vec3, max: Vec3| b.min.cmple(max).all() && b.max.cmpge(min).all();
        let check = |g: &mut Grid, boxes: &[Aabb], min: Vec3, max: Vec3| {
            let q = g.query(Some((min, max)));
            let hits = (0..boxes.len()).filter(|&i| g.hit(q, i)).count();
            for (i, b) in boxes.iter().enumerate() {
                assert!(!touches(b, min, max) || g.hit(q, i), "box {i} touches the query but was left out");
            }
            hits
        };
        let n = check(&mut g, &boxes, Vec3::splat(-1.0), Vec3::splat(4.0));
        assert!(n < 20, "a small query returned {n} of {}", boxes.len());
        // move box 55 next to the origin
        boxes[55] = aabb([0.2, 0.0, 0.2], [0.9, 1.0, 0.9]);
        g.update(55, &boxes[55]);
        let q = g.query(Some((Vec3::splat(-0.1), Vec3::splat(0.3))));
        assert!(g.hit(q, 55) && g.hit(q, 0) && g.hit(q, 100) && !g.hit(q, 99));
        check(&mut g, &boxes, Vec3::new(12.0, -1.0, 12.0), Vec3::new(18.0, 1.0, 18.0));
        // a huge query returns everything
        assert!(g.query(Some((Vec3::splat(-1e6), Vec3::splat(1e6)))).is_none());
    }
}
