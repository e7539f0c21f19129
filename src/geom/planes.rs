//! Object-space triangle planes for facing bits at memory speed ([`FacePlanes`]): f32 SoA
//! planes with a proven error bound, the exact predicate only where the sign is in doubt.

use super::mesh::Mesh;
use super::predicates::facing_exact;
use super::silhouette::PLANES_PARALLEL_THRESHOLD;
use glam::{Vec3, Vec4};

/// Largest coordinate magnitude (mesh or light) the f32 plane filter accepts: beyond it the
/// products could overflow, and [`FacePlanes::facing_packed`] decides every triangle exactly.
const PLANE_RANGE: f64 = (1u64 << 60) as f64;
/// Triangles whose cross product cancels by more than this factor (`Σ|e_i f_j| / |e × f|_1`)
/// are always decided exactly (zero-area triangles and slivers).
const PLANE_CONDITION: f64 = 65536.0;
/// Unit roundoff of f32.
const U32: f64 = 1.0 / (1u64 << 24) as f64;

/// Object-space triangle planes of one mesh, precomputed once, for facing bits at memory speed.
///
/// For every triangle, `(nx, ny, nz, d)` in f32 (structure of arrays, padded to a multiple of
/// 64 with zero planes) approximates the exact plane of its f32 vertices, scaled so that
/// `|n|_1 = 1`. Facing for the homogeneous light `l` is then the sign of one dot product
/// `n · l.xyz + d · l.w`; it is trusted only where its magnitude exceeds a conservative bound
/// on the total rounding error (see [`FacePlanes::error_bound`]), and every other triangle, and
/// every badly conditioned one (zero-area triangles, slivers), is decided by the exact
/// `robust::orient3d`. The result is therefore bit for bit [`facing_exact`]'s.
///
/// ## Error bound
/// Let `u = 2^-24`, `R` the largest |coordinate| of the mesh, `p` the light point (`l.xyz / l.w`
/// in f64, or the direction when `l.w == 0`). The plane is `n' = fl64(e × f) / s` with
/// `s = |fl64(e × f)|_1`, `ñ = fl32(n')`, `d̃ = fl32(-fl64(ñ · p0))` (the products of f32
/// values are exact in f64). Against the exact plane `(n/s, -n·p0/s)` (any positive scale keeps
/// the sign), the f32 value `ṽ = fl32(ñ · p̃ + d̃ w)` is off by at most
/// * `|ñ - n/s|_1 · |p - p0|_∞ <= (u + 4.0001·2^-53·κ + 2^-53)(|p|_∞ + R)`, with
///   `κ = Σ perm / s <= 65536` (else the triangle is always exact), under `1.01 u (|p|_∞ + R)`;
/// * the plane offset: `|d̃ + ñ · p0| <= u |d| + γ2(f64) R <= 1.01 u R`;
/// * rounding `p` to f32: `1.01 u |p|_∞`;
/// * the f32 dot product of four terms: `γ4 (|ñ|_1 |p̃|_∞ + |d̃|) <= 4.2 u (|p|_∞ + R)`;
/// * underflow: at most 16 subnormal roundings of 2^-150, far below 2^-100;
///
/// in total under `8 u (|p|_∞ + R w) + 2^-100`. The filter uses twice that,
/// `16 u (|p|_∞ + R w) + 2^-100`, rounded up to f32. Coordinates beyond 2^60 (mesh or light)
/// and non-finite lights skip the filter and decide every triangle exactly.
#[derive(Clone, Debug, Default)]
pub struct FacePlanes {
    nx: Vec<f32>,
    ny: Vec<f32>,
    nz: Vec<f32>,
    d: Vec<f32>,
    /// Triangles always decided exactly: their f32 planes are zero, so their value is never
    /// above the error bound and the filter always hands them to the exact predicate.
    exact: usize,
    /// Largest |coordinate| of the mesh.
    reach: f64,
    /// Triangle count (the arrays are padded to a multiple of 64).
    len: usize,
    /// Coordinates out of the filter's range: every triangle is decided exactly.
    all_exact: bool,
}

fn corners(mesh: &Mesh, t: usize) -> Option<[Vec3; 3]> {
    let tri = mesh.triangles.get(t)?;
    let p = |k: usize| mesh.positions.get(tri[k] as usize).copied();
    Some([p(0)?, p(1)?, p(2)?])
}

/// The exact facing bit of triangle `t` ([`facing_exact`], vertices swapped when `flip`);
/// false for a triangle with an index out of range.
pub(crate) fn exact_bit(mesh: &Mesh, t: usize, l: Vec4, flip: bool) -> bool {
    match corners(mesh, t) {
        Some([a, b, c]) => {
            if flip {
                facing_exact(a, c, b, l)
            } else {
                facing_exact(a, b, c, l)
            }
        }
        None => false,
    }
}

impl FacePlanes {
    /// The planes of every triangle of `mesh` (positions as stored; a triangle with an index
    /// out of range gets no plane and is never light-facing).
    pub fn new(mesh: &Mesh) -> FacePlanes {
        let mut p = FacePlanes::default();
        p.recompute(mesh);
        p
    }

    /// Recomputes every plane from `mesh`'s current positions (deforming casters call this
    /// whenever the positions change; the triangles may change too). Reuses the allocations.
    pub fn recompute(&mut self, mesh: &Mesh) {
        let n = mesh.triangles.len();
        let padded = n.div_ceil(64) * 64;
        for v in [&mut self.nx, &mut self.ny, &mut self.nz, &mut self.d] {
            v.clear();
            v.resize(padded, 0.0);
        }
        self.exact = 0;
        self.len = n;
        let reach =
            mesh.positions.iter().map(|p| p.abs().max_element() as f64).fold(0.0f64, |a, b| if b > a || b.is_nan() { b } else { a });
        self.reach = reach;
        self.all_exact = !(reach <= PLANE_RANGE);
        if self.all_exact {
            return;
        }
        for t in 0..n {
            let Some([p0, p1, p2]) = corners(mesh, t) else {
                // no plane, no exact test: never light-facing (see exact_bit)
                self.exact += 1;
                continue;
            };
            let (q0, e, f) = (p0.as_dvec3(), p1.as_dvec3() - p0.as_dvec3(), p2.as_dvec3() - p0.as_dvec3());
            let c = e.cross(f);
            let s = c.x.abs() + c.y.abs() + c.z.abs();
            let perm =
                (e.y * f.z).abs() + (e.z * f.y).abs() + (e.z * f.x).abs() + (e.x * f.z).abs() + (e.x * f.y).abs() + (e.y * f.x).abs();
            if !(s > 0.0 && perm <= PLANE_CONDITION * s) {
                self.exact += 1;
                continue;
            }
            let nn = (c / s).as_vec3();
            let d = -(nn.x as f64 * q0.x + nn.y as f64 * q0.y + nn.z as f64 * q0.z);
            self.nx[t] = nn.x;
            self.ny[t] = nn.y;
            self.nz[t] = nn.z;
            self.d[t] = d as f32;
        }
    }

    /// Number of triangles.
    pub fn len(&self) -> usize {
        self.len
    }

    /// True when there are no triangles.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Triangles that are always decided by the exact predicate (degenerate or badly
    /// conditioned).
    pub fn always_exact(&self) -> usize {
        if self.all_exact {
            self.len
        } else {
            self.exact
        }
    }

    /// The f32 plane `(nx, ny, nz, d)` of every triangle, in triangle order (zero for the
    /// triangles always decided exactly; all zero when the mesh is out of the filter's range):
    /// what the GPU facing pass (`--method compute`) filters with, together with
    /// [`error_bound`](Self::error_bound).
    pub fn planes_xyzd(&self) -> Vec<[f32; 4]> {
        (0..self.len).map(|t| if self.all_exact { [0.0; 4] } else { [self.nx[t], self.ny[t], self.nz[t], self.d[t]] }).collect()
    }

    /// Bytes the facing pass reads per light (the four plane arrays).
    pub fn bytes(&self) -> usize {
        self.nx.len() * 16
    }

    /// The filter's light (f32, w = 1 or 0) and error bound for `l`, or `None` when the light or
    /// the mesh is out of the filter's range (then every triangle is decided exactly).
    pub fn error_bound(&self, l: Vec4) -> Option<(Vec4, f32)> {
        if self.all_exact || !l.is_finite() {
            return None;
        }
        let (p, w) = if l.w == 0.0 { (l.truncate().as_dvec3(), 0.0) } else { (l.truncate().as_dvec3() / l.w as f64, 1.0) };
        let pinf = p.abs().max_element();
        if !(pinf <= PLANE_RANGE) {
            return None;
        }
        let e = (16.0 * U32 * (pinf + self.reach * w) + 2f64.powi(-100)) * (1.0 + 2f64.powi(-20));
        Some((p.as_vec3().extend(w as f32), e as f32))
    }

    /// Facing bits of every triangle for the object-space homogeneous light `l`, packed 64 to a
    /// `u64` word (bit `t % 64` of word `t / 64`; bits past the last triangle are 0), into `out`
    /// (resized). Exactly `facing_exact(p0, p1, p2, l)` per triangle (`(p0, p2, p1)` when `flip`,
    /// for mirroring transforms), for the `mesh` the planes were computed from; if `mesh` has a
    /// different triangle count every triangle is decided exactly.
    pub fn facing_packed(&self, mesh: &Mesh, l: Vec4, flip: bool, out: &mut Vec<u64>) {
        let n = mesh.triangles.len();
        let words = n.div_ceil(64);
        out.clear();
        out.resize(words, 0);
        let filter = if n == self.len { self.error_bound(l) } else { None };
        let Some((lf, e)) = filter else {
            for t in 0..n {
                if exact_bit(mesh, t, l, flip) {
                    out[t / 64] |= 1 << (t % 64);
                }
            }
            return;
        };
        self.fill_words(mesh, l, flip, (lf, e), 0, out);
    }

    /// [`facing_packed`](Self::facing_packed), on every available core (at most 8) for meshes
    /// of at least [`PLANES_PARALLEL_THRESHOLD`] triangles, else on this thread.
    pub fn facing_packed_auto(&self, mesh: &Mesh, l: Vec4, flip: bool, out: &mut Vec<u64>) {
        let th = if self.len < PLANES_PARALLEL_THRESHOLD {
            1
        } else {
            std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1).min(8)
        };
        self.facing_packed_threads(mesh, l, flip, th, out)
    }

    /// [`facing_packed`](Self::facing_packed) split over `threads` threads (contiguous ranges of
    /// whole words); the same bits.
    pub fn facing_packed_threads(&self, mesh: &Mesh, l: Vec4, flip: bool, threads: usize, out: &mut Vec<u64>) {
        let n = mesh.triangles.len();
        let words = n.div_ceil(64);
        let th = threads.clamp(1, words.max(1));
        let filter = if n == self.len { self.error_bound(l) } else { None };
        let Some(filter) = filter.filter(|_| th > 1) else {
            return self.facing_packed(mesh, l, flip, out);
        };
        out.clear();
        out.resize(words, 0);
        let per = words.div_ceil(th);
        std::thread::scope(|s| {
            for (ci, o) in out.chunks_mut(per).enumerate() {
                s.spawn(move || self.fill_words(mesh, l, flip, filter, ci * per, o));
            }
        });
    }

    /// Words `first .. first + out.len()` of the packed bits, with the filter `(lf, e)` of
    /// [`error_bound`](Self::error_bound) (`n == self.len` checked by the caller).
    fn fill_words(&self, mesh: &Mesh, l: Vec4, flip: bool, (lf, e): (Vec4, f32), first: usize, out: &mut [u64]) {
        let n = self.len;
        // flip: the negated plane, i.e. the negated light (exact).
        let lf = if flip { -lf } else { lf };
        let (a, b) = (first * 64, (first + out.len()) * 64);
        let blocks = self.nx[a..b]
            .chunks_exact(64)
            .zip(self.ny[a..b].chunks_exact(64))
            .zip(self.nz[a..b].chunks_exact(64))
            .zip(self.d[a..b].chunks_exact(64));
        for (i, (o, (((nx, ny), nz), d))) in out.iter_mut().zip(blocks).enumerate() {
            let base = a + i * 64;
            let valid = if base + 64 <= n { u64::MAX } else { (1u64 << (n - base)) - 1 };
            let (bits, unsure) = block64(nx, ny, nz, d, lf, e);
            let mut w = bits & valid;
            let mut u = unsure & valid;
            while u != 0 {
                let k = u.trailing_zeros() as usize;
                u &= u - 1;
                w = (w & !(1 << k)) | (u64::from(exact_bit(mesh, base + k, l, flip)) << k);
            }
            *o = w;
        }
    }
}

/// Facing and "unsure" bits of 64 planes: bit k of the first word is set when plane k's value
/// exceeds `e`, of the second when its magnitude does not (NaN included).
///
/// Four planes at a time in glam's `Vec4` (SSE2 on x86_64, safe): the value is
/// `((nx·lx + ny·ly) + nz·lz) + d·lw` in f32, the same operations in the same order as the
/// scalar form, and each comparison becomes one mask (`movmskps`).
#[inline]
fn block64(nx: &[f32], ny: &[f32], nz: &[f32], d: &[f32], l: Vec4, e: f32) -> (u64, u64) {
    let (nx, ny, nz, d) = (&nx[..64], &ny[..64], &nz[..64], &d[..64]);
    let (lx, ly, lz, lw, ev) = (Vec4::splat(l.x), Vec4::splat(l.y), Vec4::splat(l.z), Vec4::splat(l.w), Vec4::splat(e));
    let (mut bits, mut unsure) = (0u64, 0u64);
    for (j, (((x, y), z), w)) in nx.chunks_exact(4).zip(ny.chunks_exact(4)).zip(nz.chunks_exact(4)).zip(d.chunks_exact(4)).enumerate() {
        let v = Vec4::from_slice(x) * lx + Vec4::from_slice(y) * ly + Vec4::from_slice(z) * lz + Vec4::from_slice(w) * lw;
        bits |= (v.cmpgt(ev).bitmask() as u64) << (j * 4);
        unsure |= ((!v.abs().cmpgt(ev).bitmask() & 0xf) as u64) << (j * 4);
    }
    (bits, unsure)
}
