//! Block bounds of [`FacePlanes`](super::FacePlanes): a block's (or super-block's) planes as a
//! centre plane and its spread, tested in f64 against the light to decide a whole word of
//! facing bits at once, and 8 of them side by side.

use glam::Vec4;

/// The planes of one block of 64 triangles as a centre plane and its spread, for deciding the
/// whole block's facing at once.
///
/// About a point `c`, a triangle's filter value (in exact arithmetic on its stored f32 plane,
/// before the dot product's own rounding) is `V_t = ñ_t · (p̃ - c w) + d'_t w` with
/// `d'_t = d̃_t + ñ_t · c`. With the block's centre plane `(N, D')` and spreads
/// `Δ_i = max_t |ñ_ti - N_i|`, `Δd >= max_t |d'_t - D'|` (f64 rounding of `d'_t` included),
/// every `V_t` lies within `Δ · |q| + Δd |w|` of `N · q + D' w`, `q = p̃ - c w`. The
/// [error bound](super::FacePlanes#error-bound) puts the exact plane value within `e / 2` of `V_t`, so a
/// block whose centre value clears the spread, `e` and a generous allowance for the f64
/// evaluation itself has every triangle's exact facing equal to its sign: the same bits the
/// per-triangle path gives. Blocks with an always-exact triangle are never decided this way.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct BlockBound {
    pub(super) c: [f64; 3],
    pub(super) n: [f64; 3],
    pub(super) d: f64,
    pub(super) spread: [f64; 3],
    pub(super) spread_d: f64,
    /// The magnitudes the evaluation's rounding is relative to: `|N|_1 + |Δ|_1`, `|c|_∞`,
    /// `|D'| + Δd`.
    pub(super) scale: [f64; 3],
    pub(super) decidable: bool,
}

/// The filter light's values every block test uses, computed once per light.
#[derive(Clone, Copy, Debug)]
pub(super) struct Probe {
    pub(super) p: [f64; 3],
    pub(super) w: f64,
    pub(super) pinf: f64,
    pub(super) e: f64,
}

impl Probe {
    /// For the filter light `l` (`w` = ±1 or 0) and error bound `e`.
    pub(super) fn new(l: Vec4, e: f64) -> Probe {
        let p = [l.x as f64, l.y as f64, l.z as f64];
        Probe { p, w: l.w as f64, pinf: p[0].abs().max(p[1].abs()).max(p[2].abs()), e }
    }
}

impl BlockBound {
    /// Without branches: (every triangle faces the probe's light, none does); at most one
    /// is true, neither for a block that is not decidable.
    #[inline(always)]
    pub(super) fn test(&self, probe: &Probe) -> (bool, bool) {
        let (p, w) = (probe.p, probe.w);
        let q = [p[0] - self.c[0] * w, p[1] - self.c[1] * w, p[2] - self.c[2] * w];
        let centre = self.n[0] * q[0] + self.n[1] * q[1] + self.n[2] * q[2] + self.d * w;
        let spread = self.spread[0] * q[0].abs() + self.spread[1] * q[1].abs() + self.spread[2] * q[2].abs() + self.spread_d * w.abs();
        // a dozen f64 operations on terms bounded by these magnitudes: 2^-40 of them is far
        // above their rounding
        let slack = ((self.scale[0] * (probe.pinf + self.scale[1])) + self.scale[2]) * 2f64.powi(-40);
        let margin = spread + slack + probe.e;
        (self.decidable & (centre > margin), self.decidable & (centre < -margin))
    }
}

/// The bounds of one super-block's 8 blocks, field by field, so that their tests run side by
/// side: [`test`](Self::test) does [`BlockBound::test`]'s f64 operations in the same order on
/// each, so it takes the same decisions. A missing block (past the mesh's end) is not
/// decidable.
#[derive(Clone, Debug, Default)]
pub(super) struct Bounds8 {
    pub(super) c: [[f64; 8]; 3],
    pub(super) n: [[f64; 8]; 3],
    pub(super) d: [f64; 8],
    pub(super) spread: [[f64; 8]; 3],
    pub(super) spread_d: [f64; 8],
    pub(super) scale: [[f64; 8]; 3],
    pub(super) decidable: [bool; 8],
}

impl Bounds8 {
    /// The bounds `b` (at most 8).
    pub(super) fn new(b: &[BlockBound]) -> Bounds8 {
        let mut x = Bounds8::default();
        for (i, b) in b.iter().take(8).enumerate() {
            for k in 0..3 {
                (x.c[k][i], x.n[k][i], x.spread[k][i], x.scale[k][i]) = (b.c[k], b.n[k], b.spread[k], b.scale[k]);
            }
            (x.d[i], x.spread_d[i], x.decidable[i]) = (b.d, b.spread_d, b.decidable);
        }
        x
    }

    /// Block `i`'s bound.
    #[cfg(test)]
    pub(super) fn get(&self, i: usize) -> BlockBound {
        BlockBound {
            c: self.c.map(|v| v[i]),
            n: self.n.map(|v| v[i]),
            d: self.d[i],
            spread: self.spread.map(|v| v[i]),
            spread_d: self.spread_d[i],
            scale: self.scale.map(|v| v[i]),
            decidable: self.decidable[i],
        }
    }

    /// [`BlockBound::test`] of the 8 blocks, without branches: bit `i` of the first mask is set
    /// when block `i` faces the probe's light whole, of the second when none of it does.
    #[inline(always)]
    pub(super) fn test(&self, probe: &Probe) -> (u64, u64) {
        let (p, w) = (probe.p, probe.w);
        let (mut ones, mut zeros) = (0u64, 0u64);
        for i in 0..8 {
            let q = [p[0] - self.c[0][i] * w, p[1] - self.c[1][i] * w, p[2] - self.c[2][i] * w];
            let centre = self.n[0][i] * q[0] + self.n[1][i] * q[1] + self.n[2][i] * q[2] + self.d[i] * w;
            let spread = self.spread[0][i] * q[0].abs()
                + self.spread[1][i] * q[1].abs()
                + self.spread[2][i] * q[2].abs()
                + self.spread_d[i] * w.abs();
            let slack = ((self.scale[0][i] * (probe.pinf + self.scale[1][i])) + self.scale[2][i]) * 2f64.powi(-40);
            let margin = spread + slack + probe.e;
            ones |= u64::from(self.decidable[i] & (centre > margin)) << i;
            zeros |= u64::from(self.decidable[i] & (centre < -margin)) << i;
        }
        (ones, zeros)
    }
}
