//! The GPU facing stage's tables (`--method compute`, `shaders/silhouette.wgsl`): the planes in
//! scan order and, per 64-slot block, an f32 bound that decides the block's whole word of
//! facing bits with one test ([`GpuBlock`]; the test is `decide_block` in the shader).
//!
//! The CPU's [`BlockBound`](super::BlockBound) evaluates in f64 with a generous slack; the GPU
//! has only f32, so the bound is stored as f32 values whose spreads are measured about the
//! *stored* centre (rounded up past every f64 rounding of their computation), and the test
//! adds an allowance for its own f32 evaluation, derived below.
//!
//! ## The bound
//! For the slots `t` of a block, with stored f32 planes `(ñ_t, d̃_t)`, the block keeps an f32
//! centre point `c`, centre normal `N`, offset `D'` and spreads `Δ_i >= max_t |ñ_ti - N_i|`,
//! `Δd >= max_t |d'_t - D'|` with `d'_t = d̃_t + ñ_t · c` (real numbers; computed in f64 with
//! an error term and rounded up to f32). For the filter light `(p̃, w)`, `w` = ±1 or 0, the
//! filter's value of slot `t` in exact arithmetic is
//! `V_t = ñ_t · p̃ + d̃_t w = ñ_t · q + d'_t w` with `q = p̃ - c w`, so every `V_t` lies within
//! `S = Δ · |q| + Δd |w|` of the centre value `C = N · q + D' w`.
//!
//! ## The f32 evaluation and its allowance
//! The stage computes, in f32 with correctly rounded add and multiply (Vulkan's precision for
//! `OpFAdd`/`OpFMul`; a fused multiply-add only removes roundings; denormals may be flushed),
//! `q̂ = fl(p̃ - c w)` (`c w` exact), `Ĉ = ((N_x q̂_x + N_y q̂_y) + N_z q̂_z) + D' w`,
//! `Ŝ = ((Δ_x |q̂_x| + Δ_y |q̂_y|) + Δ_z |q̂_z|) + Δd |w|` and the magnitude
//! `M̂ = ((|N_x| |q̂_x| + |N_y| |q̂_y|) + |N_z| |q̂_z|) + |D'| |w|`, and decides the block when
//! `Ĉ > m̂` (every slot light-facing) or `Ĉ < -m̂` (none), with
//! `m̂ = T + (T + M̂) · 2^-18`, `T = Ŝ + e` (`e` the job's filter bound, at least `2^-100`).
//! With `u = 2^-24`, `γ_4 = 4u / (1 - 4u)` and `M` the exact magnitude sum on `q̂` (a sum of
//! four terms, three of them rounded products: at most four roundings on each):
//! * `|q̂_i - q_i| <= u |q_i| + 2^-126` (a difference below `2^-126` is exact, or flushed);
//! * `|Ĉ - (N · q̂ + D' w)| <= γ_4 M + 7 · 2^-126`, so `C >= Ĉ - (γ_4 + 2u) M - 2^-120`;
//! * likewise `S <= Ŝ (1 + 6u) + 2^-120` and `M̂ >= M (1 - γ_4) - 2^-123`;
//! * the three roundings of `m̂` lose at most `3u` of it.
//!
//! So `m̂ >= (Ŝ + e)(1 + 60u) + 60u M - 2^-123 >= S + e + (γ_4 + 2u) M + 2^-119` (the
//! absolute terms are covered by `60u e >= 2^-119`), and `Ĉ > m̂` gives `C - S > e`: every
//! slot's `V_t` exceeds `e`, more than the `e / 2` by which `V_t` can differ from the exact
//! plane value (the [error bound](super::FacePlanes#error-bound)), so every slot faces the
//! light exactly, the same bit the per-slot filter and the exact test give. Likewise for
//! `Ĉ < -m̂`. Coordinates within the filter's range (`2^60`) keep every value finite. A block
//! with an always-exact slot (a zero plane: degenerate or badly conditioned triangles, or every
//! slot of a mesh out of the filter's range) is never decided (`ok` = 0), and neither is any
//! block of a job without a filter (the shader checks the job's flag).
//!
//! `planes::tests::gpu_blocks_*` check that a decided block's every `V_t` (evaluated exactly)
//! clears `e`, and that without the allowance a light near the threshold breaks it.

use super::FacePlanes;
use crate::geom::mesh::Mesh;
#[cfg(test)]
use glam::Vec4;

/// Slots per GPU block: one 64-bit pair of facing words (two `u32`s on the GPU).
pub(crate) const GPU_BLOCK: usize = 64;

/// The allowance of the f32 block test: `m̂ = T + (T + M̂) · ALLOWANCE` (module docs;
/// `ALLOWANCE` in the shader).
#[cfg(test)]
const ALLOWANCE: f32 = 1.0 / 262144.0;

/// One block's bound as the shader reads it, three `vec4<f32>`:
/// `(c.x, c.y, c.z, D')`, `(N.x, N.y, N.z, Δd)`, `(Δ_x, Δ_y, Δ_z, ok)`; `ok` is 1 for a block
/// the test may decide, 0 otherwise.
pub(crate) type GpuBlock = [f32; 12];

/// The smallest f32 at least `x` (`x` finite and non-negative; infinity past the range).
fn up32(x: f64) -> f32 {
    let f = x as f32;
    if (f as f64) < x {
        f.next_up()
    } else {
        f
    }
}

impl FacePlanes {
    /// The f32 plane `(nx, ny, nz, d)` of every slot, in the planes' [order](Self::order)
    /// (zero for the always-exact triangles, all zero when the mesh is out of the filter's
    /// range): what the GPU facing stage reads, slot `s` being triangle
    /// `order().triangle(s)`.
    pub(crate) fn planes_scan(&self) -> Vec<[f32; 4]> {
        (0..self.len).map(|s| if self.all_exact { [0.0; 4] } else { [self.nx[s], self.ny[s], self.nz[s], self.d[s]] }).collect()
    }

    /// The [`GpuBlock`] of every 64 slots (the last block may be shorter), for the `mesh` the
    /// planes were computed from.
    pub(crate) fn gpu_blocks(&self, mesh: &Mesh) -> Vec<GpuBlock> {
        (0..self.len.div_ceil(GPU_BLOCK)).map(|b| self.gpu_block(mesh, b * GPU_BLOCK..self.len.min(b * GPU_BLOCK + GPU_BLOCK))).collect()
    }

    fn gpu_block(&self, mesh: &Mesh, ts: std::ops::Range<usize>) -> GpuBlock {
        let none = [0.0; 12];
        // a zero plane is an always-exact slot (a real plane has |n|_1 = 1)
        if self.all_exact || ts.is_empty() || ts.clone().any(|s| self.plane64(s).0 == [0.0; 3]) {
            return none;
        }
        let k = ts.len() as f64;
        let Some(c) = self.block_centre(mesh, ts.clone()) else { return none };
        let c = c.map(|x| x as f32 as f64);
        let mut nm = [0.0f64; 3];
        for s in ts.clone() {
            let (n, _) = self.plane64(s);
            for i in 0..3 {
                nm[i] += n[i] / k;
            }
        }
        let nm = nm.map(|x| x as f32 as f64);
        let cinf = c.iter().fold(0.0f64, |a, x| a.max(x.abs()));
        // d'_s = d̃_s + ñ_s · c: products of f32 values are exact in f64, three additions round
        let dm = (ts.clone().map(|s| self.offset(s, c, cinf).0).sum::<f64>() / k) as f32 as f64;
        let (spread, spread_d) = self.block_spreads(ts, c, cinf, nm, dm);
        // past the f64 roundings of the differences, then up to f32
        let up = 1.0 + 2f64.powi(-50);
        let spread = spread.map(|x| up32(x * up));
        let spread_d = up32(spread_d * up);
        let b = [
            c[0] as f32,
            c[1] as f32,
            c[2] as f32,
            dm as f32,
            nm[0] as f32,
            nm[1] as f32,
            nm[2] as f32,
            spread_d,
            spread[0],
            spread[1],
            spread[2],
            1.0,
        ];
        if b.iter().all(|x| x.is_finite()) {
            b
        } else {
            none
        }
    }
}

/// The GPU block test (`shaders/silhouette.wgsl`'s `decide_block`, the same f32 operations in
/// the same order): `Some(true)` when every slot of the block faces the filter light `l`
/// (`w` = ±1 or 0, negated for mirroring casters) with the job's filter bound `e`,
/// `Some(false)` when none does, `None` when the block is left to the per-slot filter. (The
/// shader is the implementation; this mirror is what the tests check.)
#[cfg(test)]
fn decide_gpu_block(b: &GpuBlock, l: Vec4, e: f32) -> Option<bool> {
    decide_with(b, l, e, ALLOWANCE)
}

/// [`decide_gpu_block`] with the allowance factor `allowance` (the tests drop it).
#[cfg(test)]
fn decide_with(b: &GpuBlock, l: Vec4, e: f32, allowance: f32) -> Option<bool> {
    if b[11] != 1.0 {
        return None;
    }
    let w = l.w;
    let q = [l.x - b[0] * w, l.y - b[1] * w, l.z - b[2] * w];
    let centre = ((b[4] * q[0] + b[5] * q[1]) + b[6] * q[2]) + b[3] * w;
    let spread = ((b[8] * q[0].abs() + b[9] * q[1].abs()) + b[10] * q[2].abs()) + b[7] * w.abs();
    let mag = ((b[4].abs() * q[0].abs() + b[5].abs() * q[1].abs()) + b[6].abs() * q[2].abs()) + b[3].abs() * w.abs();
    let t = spread + e;
    let margin = t + (t + mag) * allowance;
    if centre > margin {
        Some(true)
    } else if centre < -margin {
        Some(false)
    } else {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::super::exact_bit;
    use super::*;
    use crate::geom::order::TriangleOrder;
    use crate::geom::testmesh::{grid, shuffled, torus, uv_sphere};
    use glam::Vec3;

    /// The exact sign of `Σ terms` (each an f64 value, the sum not rounded): Shewchuk's
    /// expansion sum, the sign of its largest component.
    fn exact_sign(terms: &[f64]) -> f64 {
        let mut e: Vec<f64> = Vec::new();
        for &b in terms {
            let mut q = b;
            let mut next = Vec::with_capacity(e.len() + 1);
            for &a in &e {
                let s = q + a;
                let bv = s - q;
                let err = (q - (s - bv)) + (a - bv);
                if err != 0.0 {
                    next.push(err);
                }
                q = s;
            }
            next.push(q);
            e = next;
        }
        e.iter().rev().find(|x| **x != 0.0).map_or(0.0, |x| x.signum())
    }

    /// Whether slot `s`'s filter value in exact arithmetic, `ñ · p̃ + d̃ w`, clears `e` with
    /// the sign `facing` (the invariant a decided block guarantees each of its slots).
    fn clears(p: &FacePlanes, s: usize, l: Vec4, e: f32, facing: bool) -> bool {
        let sign = if facing { 1.0 } else { -1.0 };
        let t = [
            p.nx[s] as f64 * l.x as f64,
            p.ny[s] as f64 * l.y as f64,
            p.nz[s] as f64 * l.z as f64,
            p.d[s] as f64 * l.w as f64,
            -sign * e as f64,
        ];
        exact_sign(&t) == sign
    }

    /// Checks every decided block of `planes` (for `mesh`) against the exact bits and the
    /// invariant; returns how many were decided.
    fn check(planes: &FacePlanes, mesh: &Mesh, l: Vec4, flip: bool) -> usize {
        let Some((lf, e)) = planes.error_bound(l) else { return 0 };
        let lf = if flip { -lf } else { lf };
        let mut decided = 0;
        for (b, block) in planes.gpu_blocks(mesh).iter().enumerate() {
            let Some(all) = decide_gpu_block(block, lf, e) else { continue };
            decided += 1;
            for s in b * GPU_BLOCK..planes.len().min(b * GPU_BLOCK + GPU_BLOCK) {
                assert_eq!(exact_bit(mesh, planes.tri(s), l, flip), all, "block {b} slot {s} light {l} flip {flip}");
                assert!(clears(planes, s, lf, e, all), "block {b} slot {s}: its value does not clear e = {e}");
            }
        }
        decided
    }

    #[test]
    fn gpu_blocks_decide_exactly() {
        for (r, off) in [(1.0f32, Vec3::ZERO), (1e-3, Vec3::splat(1e4)), (5e3, Vec3::new(-3e6, 2e6, 1e6))] {
            let mut m = shuffled(&uv_sphere(r, 200, 101));
            for p in &mut m.positions {
                *p += off;
            }
            let all: Vec<u32> = (0..m.triangles.len() as u32).collect();
            let planes = FacePlanes::with_order(&m, TriangleOrder::spatial(&m, &[&all]));
            let blocks = planes.len().div_ceil(GPU_BLOCK);
            for l in [
                (off + Vec3::new(3.0, 2.0, 1.0) * r).extend(1.0),
                (off + Vec3::new(0.0, 1.0001, 0.0) * r).extend(1.0),
                Vec3::new(-1.0, 0.5, 0.2).extend(0.0),
                (off + Vec3::new(30.0, -20.0, 10.0) * r).extend(1.0),
            ] {
                let decided = [false, true].map(|flip| check(&planes, &m, l, flip));
                assert_eq!(decided[0], decided[1]);
                if off == Vec3::ZERO && l.y != 1.0001 {
                    assert!(decided[0] * 2 > blocks, "{} of {blocks} blocks decided for {l}", decided[0]);
                }
            }
        }
    }

    #[test]
    fn gpu_blocks_never_decide_always_exact_slots() {
        let mut m = uv_sphere(1.0, 24, 12);
        // a zero-area triangle in the first block, and a mesh out of the filter's range
        let t = m.triangles[3];
        m.triangles[3] = [t[0], t[0], t[1]];
        let planes = FacePlanes::new(&m);
        let b = planes.gpu_blocks(&m);
        assert_eq!(b[0][11], 0.0);
        assert!(b[1..].iter().all(|x| x[11] == 1.0));
        let mut far = uv_sphere(1.0, 24, 12);
        far.positions[0] *= 1e30;
        let fp = FacePlanes::new(&far);
        assert!(fp.gpu_blocks(&far).iter().all(|x| *x == [0.0; 12]));
        assert!(fp.planes_scan().iter().all(|p| *p == [0.0; 4]));
    }

    /// A block of 64 exactly coplanar triangles on the plane `z = 2x - y` (its f32 normal
    /// `(0.5, -0.25, -0.25)` exact), far from the origin, and lights far along the plane: the
    /// f32 evaluation of the centre value rounds (the light's offset from the centre is not
    /// exact in f32), so near the decision threshold the test without its allowance decides
    /// blocks whose values do not clear `e`; with it, never.
    #[test]
    fn gpu_blocks_need_the_allowance() {
        let (x0, y0) = (100_000.0f32, 5_000.0f32);
        let m = grid(5, 9, |i, j| {
            let (x, y) = (x0 + i as f32 * 0.5, y0 + j as f32 * 0.5);
            Vec3::new(x, y, 2.0 * x - y)
        });
        let planes = FacePlanes::new(&m);
        let block = planes.gpu_blocks(&m)[0];
        assert_eq!(block[11], 1.0);
        assert_eq!(block[8..11], [0.0; 3], "coplanar: no normal spread");
        let (mut tried, mut broken) = (0, 0);
        for k in 0..400 {
            // a light far along the plane, then off it (along z) to where the test decides
            let px = 1.3e6 + k as f32 * 37.25;
            let py = y0 + (k % 7) as f32 * 1000.0 + 0.375;
            let light = |dz: f32| Vec4::new(px, py, 2.0 * px - py + dz, 1.0);
            let decide = |dz: f32, allowance: f32| {
                let Some((lf, e)) = planes.error_bound(light(dz)) else { unreachable!() };
                (decide_with(&block, lf, e, allowance), lf, e)
            };
            let (mut lo, mut hi) = (0.0f32, 64.0f32);
            assert!(decide(hi, 0.0).0.is_some() && decide(lo, 0.0).0.is_none());
            for _ in 0..60 {
                let mid = (lo + hi) / 2.0;
                if decide(mid, 0.0).0.is_some() {
                    hi = mid;
                } else {
                    lo = mid;
                }
            }
            let mut dz = hi;
            for _ in 0..8 {
                let (without, lf, e) = decide(dz, 0.0);
                if let Some(all) = without {
                    tried += 1;
                    if !(0..m.triangles.len()).all(|s| clears(&planes, s, lf, e, all)) {
                        broken += 1;
                    }
                }
                if let (Some(all), _, _) = decide(dz, ALLOWANCE) {
                    assert!((0..m.triangles.len()).all(|s| clears(&planes, s, lf, e, all)), "with the allowance, light {lf}");
                }
                dz = dz.next_up();
            }
        }
        assert!(tried > 0);
        assert!(broken > 0, "without the allowance no light near the threshold broke the invariant ({tried} tried)");
    }

    /// A small xorshift generator for the randomised lights.
    fn next(x: &mut u64) -> f32 {
        *x ^= *x << 13;
        *x ^= *x >> 7;
        *x ^= *x << 17;
        (*x >> 40) as f32 / (1u64 << 24) as f32 * 2.0 - 1.0
    }

    /// Every block the f32 test decides agrees with every slot's exact facing (and clears the
    /// filter's bound), for lights grazing a flat patch far from the origin (point lights a
    /// hair above, on and below its plane, directional lights nearly parallel to it), for a
    /// torus near the filter's range (2^60), and for a sphere with degenerate triangles
    /// scattered through its blocks (those blocks are never decided; the others still are).
    #[test]
    fn gpu_blocks_agree_near_grazing_far_and_degenerate() {
        let mut x = 0x2545_f491_4f6c_dd1du64;
        // a flat 16 x 16 grid (512 triangles, 8 blocks) on z = z0, far from the origin
        let (x0, y0, z0) = (1.0e5f32, -2.0e5f32, 3.0e4f32);
        let mut positions = Vec::new();
        for i in 0..17 {
            for j in 0..17 {
                positions.push(Vec3::new(x0 + i as f32 * 0.25, y0 + j as f32 * 0.25, z0));
            }
        }
        let mut triangles = Vec::new();
        for i in 0..16u32 {
            for j in 0..16u32 {
                let v = i * 17 + j;
                triangles.push([v, v + 17, v + 1]);
                triangles.push([v + 1, v + 17, v + 18]);
            }
        }
        let flat = Mesh::new(positions, triangles);
        let planes = FacePlanes::new(&flat);
        let mut decided = 0;
        for k in 0..200 {
            let (dx, dy) = (next(&mut x) * 1.0e4, next(&mut x) * 1.0e4);
            let dz = [0.0, 1.0e-6, -1.0e-6, 1.0e-3, -1.0e-3, 0.5, -0.5, 64.0][k % 8] * (1.0 + next(&mut x).abs());
            let l = Vec4::new(x0 + 2.0 + dx, y0 + 2.0 + dy, z0 + dz, 1.0);
            decided += [false, true].map(|flip| check(&planes, &flat, l, flip)).iter().sum::<usize>();
            let d = Vec4::new(next(&mut x), next(&mut x), dz * 1.0e-3, 0.0);
            decided += [false, true].map(|flip| check(&planes, &flat, d, flip)).iter().sum::<usize>();
        }
        assert!(decided > 0, "no grazing light decided a block of the flat patch");

        // a torus at 10^17 (inside the filter's range), in the spatial order
        let mut far = shuffled(&torus(4.0e14, 1.0e14, 64, 32));
        let off = Vec3::new(1.0e17, -7.0e16, 3.0e16);
        for p in &mut far.positions {
            *p += off;
        }
        let all: Vec<u32> = (0..far.triangles.len() as u32).collect();
        let planes = FacePlanes::with_order(&far, TriangleOrder::spatial(&far, &[&all]));
        let mut decided = 0;
        for _ in 0..40 {
            let v = Vec3::new(next(&mut x), next(&mut x), next(&mut x));
            for scale in [1.0e14f32, 5.0e14, 1.0e16] {
                let l = (off + v * scale).extend(1.0);
                decided += [false, true].map(|flip| check(&planes, &far, l, flip)).iter().sum::<usize>();
            }
            decided += check(&planes, &far, v.extend(0.0), false);
        }
        assert!(decided > 0, "no block of the far torus decided");

        // a sphere with every 37th triangle collapsed (zero area) or a sliver
        let mut m = uv_sphere(2.0, 96, 48);
        for t in (5..m.triangles.len()).step_by(37) {
            let [a, b, _] = m.triangles[t];
            m.triangles[t] = if t % 2 == 0 { [a, a, b] } else { [a, b, b] };
        }
        let all: Vec<u32> = (0..m.triangles.len() as u32).collect();
        let planes = FacePlanes::with_order(&m, TriangleOrder::spatial(&m, &[&all]));
        let blocks = planes.gpu_blocks(&m);
        let mut decided = 0;
        for _ in 0..60 {
            let v = Vec3::new(next(&mut x), next(&mut x), next(&mut x)).normalize_or(Vec3::X);
            for r in [2.0f32, 2.0001, 2.5, 40.0] {
                decided += [false, true].map(|flip| check(&planes, &m, (v * r).extend(1.0), flip)).iter().sum::<usize>();
            }
        }
        for (b, block) in blocks.iter().enumerate() {
            let degenerate = (b * GPU_BLOCK..planes.len().min(b * GPU_BLOCK + GPU_BLOCK)).any(|s| {
                let [a, b, c] = m.triangles[planes.tri(s)];
                a == b || b == c || a == c
            });
            assert!(!degenerate || block[11] == 0.0, "block {b} holds a degenerate triangle and is decidable");
        }
        assert!(decided > 0 && blocks.iter().any(|b| b[11] == 1.0));
    }
}
