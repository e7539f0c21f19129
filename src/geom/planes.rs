//! Object-space triangle planes for facing bits at memory speed ([`FacePlanes`]): f32 SoA
//! planes with a proven error bound, the exact predicate only where the sign is in doubt.

use super::cpu::{self, per_cpu_level};
use super::mesh::Mesh;
use super::order::TriangleOrder;
use super::predicates::facing_exact;
use super::silhouette::PLANES_PARALLEL_THRESHOLD;
use glam::{Vec3, Vec4};

mod bounds;
mod dots;
use bounds::{BlockBound, Bounds8, Probe};

/// Largest coordinate magnitude (mesh or light) the f32 plane filter accepts: beyond it the
/// products could overflow, and [`FacePlanes::facing_packed`] decides every triangle exactly.
const PLANE_RANGE: f64 = (1u64 << 60) as f64;
/// Triangles whose cross product cancels by more than this factor (`Σ|e_i f_j| / |e × f|_1`)
/// are always decided exactly (zero-area triangles and slivers).
const PLANE_CONDITION: f64 = 65536.0;
/// Blocks (facing words) per super-block bound, coarse to fine.
const SUPER_BLOCKS: [usize; 1] = [8];
// a super-block's block bounds are tested side by side, 8 at a time (`Bounds8`)
const _: () = assert!(SUPER_BLOCKS[0] == 8);
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
/// Each block of 64 triangles (one word of bits) also keeps its centre plane and spread
/// (`BlockBound`): a light far enough from every plane of a block decides its whole word
/// with a dozen f64 operations instead of 64 dot products, with the same bits; and so does
/// each run of 8 blocks (512 triangles), for their 8 words at once.
///
/// The planes, blocks and bits are in the planes' [`TriangleOrder`] ([`FacePlanes::with_order`];
/// the mesh's own order for [`FacePlanes::new`]): bit `s` is the facing of triangle
/// `order().triangle(s)`, so that a block is a compact patch of the surface whatever the
/// order of the mesh's triangles. Look a triangle's bit up with [`FacePlanes::bit`].
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
    /// One bound per 64-triangle block (word of facing bits): lets a light decide a whole word
    /// without its 64 dot products (see [`BlockBound`]); a super-block's 8 side by side.
    blocks: Vec<Bounds8>,
    /// One bound per `SUPER_BLOCKS[i]` blocks for each level `i` (compact patches of 512
    /// triangles in a spatial order): a light far from all of them decides their words at once.
    supers: [Vec<BlockBound>; 1],
    /// The scan order: slot `s` (bit `s` of the packed bits) is triangle `order.triangle(s)`.
    order: TriangleOrder,
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
        FacePlanes::with_order(mesh, TriangleOrder::identity())
    }

    /// [`new`](Self::new) with the triangles in `order` (bit `s` of the packed bits is triangle
    /// `order.triangle(s)`); an order that does not fit the mesh's triangle count is replaced by
    /// the identity.
    pub fn with_order(mesh: &Mesh, order: TriangleOrder) -> FacePlanes {
        let mut p = FacePlanes { order, ..FacePlanes::default() };
        p.recompute(mesh);
        p
    }

    /// The order of the planes and of the packed bits.
    pub fn order(&self) -> &TriangleOrder {
        &self.order
    }

    /// Triangle `t`'s facing bit in packed `bits` from [`facing_packed`](Self::facing_packed)
    /// (false past the end of the bits).
    #[inline]
    pub fn bit(&self, bits: &[u64], t: u32) -> bool {
        let s = self.order.slot(t);
        bits.get(s as usize / 64).is_some_and(|w| (w >> (s % 64)) & 1 != 0)
    }

    /// The packed `bits` of [`facing_packed`](Self::facing_packed) (scan order) in triangle
    /// order, into `out` (resized): bit `t` is [`bit(bits, t)`](Self::bit). One pass over the
    /// set bits, for work that walks every triangle in the mesh's order.
    pub fn unpermute(&self, bits: &[u64], out: &mut Vec<u64>) {
        out.clear();
        out.resize(self.len.div_ceil(64), 0);
        if self.order.is_identity() {
            let n = out.len().min(bits.len());
            out[..n].copy_from_slice(&bits[..n]);
            return;
        }
        for (w, &word) in bits.iter().enumerate().take(out.len()) {
            let mut x = word;
            while x != 0 {
                let s = w * 64 + x.trailing_zeros() as usize;
                x &= x - 1;
                if s < self.len {
                    let t = self.order.triangle(s as u32) as usize;
                    out[t / 64] |= 1 << (t % 64);
                }
            }
        }
    }

    /// The triangle of mesh `mesh` in slot `s` (the identity when the order does not fit).
    #[inline]
    fn tri(&self, s: usize) -> usize {
        self.order.triangle(s as u32) as usize
    }

    /// Recomputes every plane from `mesh`'s current positions (deforming casters call this
    /// whenever the positions change; the triangles may change too: then an order that no
    /// longer fits their count becomes the identity). Reuses the allocations.
    pub fn recompute(&mut self, mesh: &Mesh) {
        let n = mesh.triangles.len();
        if !self.order.fits(n) {
            self.order = TriangleOrder::identity();
        }
        let padded = n.div_ceil(64) * 64;
        for v in [&mut self.nx, &mut self.ny, &mut self.nz, &mut self.d] {
            v.clear();
            v.resize(padded, 0.0);
        }
        self.exact = 0;
        self.len = n;
        self.blocks.clear();
        self.supers = Default::default();
        let reach =
            mesh.positions.iter().map(|p| p.abs().max_element() as f64).fold(0.0f64, |a, b| if b > a || b.is_nan() { b } else { a });
        self.reach = reach;
        self.all_exact = !(reach <= PLANE_RANGE);
        if self.all_exact {
            return;
        }
        let mut exact_ids = Vec::new();
        for t in 0..n {
            let Some([p0, p1, p2]) = corners(mesh, self.tri(t)) else {
                // no plane, no exact test: never light-facing (see exact_bit)
                self.exact += 1;
                exact_ids.push(t);
                continue;
            };
            let (q0, e, f) = (p0.as_dvec3(), p1.as_dvec3() - p0.as_dvec3(), p2.as_dvec3() - p0.as_dvec3());
            let c = e.cross(f);
            let s = c.x.abs() + c.y.abs() + c.z.abs();
            let perm =
                (e.y * f.z).abs() + (e.z * f.y).abs() + (e.z * f.x).abs() + (e.x * f.z).abs() + (e.x * f.y).abs() + (e.y * f.x).abs();
            if !(s > 0.0 && perm <= PLANE_CONDITION * s) {
                self.exact += 1;
                exact_ids.push(t);
                continue;
            }
            let nn = (c / s).as_vec3();
            let d = -(nn.x as f64 * q0.x + nn.y as f64 * q0.y + nn.z as f64 * q0.z);
            self.nx[t] = nn.x;
            self.ny[t] = nn.y;
            self.nz[t] = nn.z;
            self.d[t] = d as f32;
        }
        let mut always_exact = vec![false; n];
        for t in exact_ids {
            always_exact[t] = true;
        }
        let blocks: Vec<BlockBound> =
            (0..n.div_ceil(64)).map(|b| self.block_bound(mesh, b * 64..n.min(b * 64 + 64), &always_exact)).collect();
        self.blocks = blocks.chunks(SUPER_BLOCKS[0]).map(Bounds8::new).collect();
        for (level, size) in SUPER_BLOCKS.iter().enumerate() {
            let step = 64 * size;
            self.supers[level] =
                (0..n.div_ceil(step)).map(|b| self.block_bound(mesh, b * step..n.min(b * step + step), &always_exact)).collect();
        }
    }

    /// Triangle `t`'s stored plane in f64: its normal and offset.
    fn plane64(&self, t: usize) -> ([f64; 3], f64) {
        ([self.nx[t] as f64, self.ny[t] as f64, self.nz[t] as f64], self.d[t] as f64)
    }

    /// The mean of the first corners of triangles `ts` (a block's centre point), in f64;
    /// `None` where a triangle has no corners in `mesh`.
    fn block_centre(&self, mesh: &Mesh, ts: std::ops::Range<usize>) -> Option<[f64; 3]> {
        let k = ts.len() as f64;
        let mut c = [0.0f64; 3];
        for t in ts {
            let [p0, ..] = corners(mesh, self.tri(t))?;
            for (ci, pi) in c.iter_mut().zip(p0.to_array()) {
                *ci += pi as f64 / k;
            }
        }
        Some(c)
    }

    /// Triangle `t`'s plane offset about the centre `c` (`|c|_inf` = `cinf`),
    /// `d + n · c`, and a bound on its f64 rounding (four roundings of terms at most
    /// `|d| + |n|_1 |c|_inf`).
    fn offset(&self, t: usize, c: [f64; 3], cinf: f64) -> (f64, f64) {
        let (n, d) = self.plane64(t);
        let v = d + n[0] * c[0] + n[1] * c[1] + n[2] * c[2];
        (v, 4.0 * (d.abs() + (n[0].abs() + n[1].abs() + n[2].abs()) * cinf) * 2f64.powi(-53))
    }

    /// The spreads of triangles `ts` about a centre normal `nm` and offset `dm` (offsets
    /// taken about `c`): per normal component the largest `|n_i - nm_i|`, and the largest
    /// `|offset - dm|` plus its rounding bound. Not yet rounded up.
    fn block_spreads(&self, ts: std::ops::Range<usize>, c: [f64; 3], cinf: f64, nm: [f64; 3], dm: f64) -> ([f64; 3], f64) {
        let (mut spread, mut spread_d) = ([0.0f64; 3], 0.0f64);
        for t in ts {
            let (n, _) = self.plane64(t);
            for i in 0..3 {
                spread[i] = spread[i].max((n[i] - nm[i]).abs());
            }
            let (v, err) = self.offset(t, c, cinf);
            spread_d = spread_d.max((v - dm).abs() + err);
        }
        (spread, spread_d)
    }

    /// The [`BlockBound`] of triangles `ts` (one block).
    fn block_bound(&self, mesh: &Mesh, ts: std::ops::Range<usize>, always_exact: &[bool]) -> BlockBound {
        if ts.is_empty() || always_exact[ts.clone()].iter().any(|&x| x) {
            return BlockBound::default();
        }
        let k = ts.len() as f64;
        let Some(c) = self.block_centre(mesh, ts.clone()) else { return BlockBound::default() };
        let cinf = c.iter().fold(0.0f64, |a, x| a.max(x.abs()));
        let mut nm = [0.0f64; 3];
        let mut dm = 0.0f64;
        for t in ts.clone() {
            let (n, _) = self.plane64(t);
            for i in 0..3 {
                nm[i] += n[i] / k;
            }
            dm += self.offset(t, c, cinf).0 / k;
        }
        let (spread, spread_d) = self.block_spreads(ts, c, cinf, nm, dm);
        // round the spreads up past their own f64 rounding
        let up = 1.0 + 2f64.powi(-40);
        let spread = spread.map(|x| x * up);
        let spread_d = spread_d * up;
        let l1 = |v: [f64; 3]| v[0].abs() + v[1].abs() + v[2].abs();
        let scale = [l1(nm) + l1(spread), cinf, dm.abs() + spread_d];
        let finite = scale.iter().all(|x| x.is_finite());
        BlockBound { c, n: nm, d: dm, spread, spread_d, scale, decidable: finite }
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

    /// The f32 plane `(nx, ny, nz, d)` of every triangle, in the mesh's triangle order (not
    /// the planes' [order](Self::order); zero for the triangles always decided exactly; all
    /// zero when the mesh is out of the filter's range): what the GPU facing pass
    /// (`--method compute`) filters with, together with [`error_bound`](Self::error_bound).
    pub fn planes_xyzd(&self) -> Vec<[f32; 4]> {
        (0..self.len)
            .map(|t| {
                let s = self.order.slot(t as u32) as usize;
                if self.all_exact {
                    [0.0; 4]
                } else {
                    [self.nx[s], self.ny[s], self.nz[s], self.d[s]]
                }
            })
            .collect()
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
    /// `u64` word in the planes' [order](Self::order) (bit `s % 64` of word `s / 64` is
    /// triangle `order().triangle(s)`: look bits up with [`bit`](Self::bit); bits past the last
    /// triangle are 0), into `out` (resized). Exactly `facing_exact(p0, p1, p2, l)` per triangle
    /// (`(p0, p2, p1)` when `flip`, for mirroring transforms), for the `mesh` the planes were
    /// computed from; if `mesh` has a different triangle count every triangle is decided
    /// exactly, in the mesh's own order.
    pub fn facing_packed(&self, mesh: &Mesh, l: Vec4, flip: bool, out: &mut Vec<u64>) {
        let n = mesh.triangles.len();
        let words = n.div_ceil(64);
        let filter = if n == self.len { self.error_bound(l) } else { None };
        let Some((lf, e)) = filter else {
            out.clear();
            out.resize(words, 0);
            let same = n == self.len;
            for t in 0..n {
                if exact_bit(mesh, if same { self.tri(t) } else { t }, l, flip) {
                    out[t / 64] |= 1 << (t % 64);
                }
            }
            return;
        };
        // (every word is written: no need to clear them first)
        out.resize(words, 0);
        fill_words(self, mesh, l, flip, (lf, e), 0, out);
    }

    /// [`facing_packed`](Self::facing_packed), on every available core (at most 8) for meshes
    /// of at least [`PLANES_PARALLEL_THRESHOLD`] triangles, else on this thread.
    pub fn facing_packed_auto(&self, mesh: &Mesh, l: Vec4, flip: bool, out: &mut Vec<u64>) {
        let th = if self.len < PLANES_PARALLEL_THRESHOLD { 1 } else { super::cpu::cores().min(8) };
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
        // (the threads write every word)
        out.resize(words, 0);
        let per = words.div_ceil(th);
        std::thread::scope(|s| {
            for (ci, o) in out.chunks_mut(per).enumerate() {
                s.spawn(move || fill_words(self, mesh, l, flip, filter, ci * per, o));
            }
        });
    }
}

/// Words `first .. first + out.len()` of `planes`' packed bits, with the filter `(lf, e)` of
/// [`FacePlanes::error_bound`] (`n == planes.len` checked by the caller); the best copy for
/// this CPU ([`super::cpu`]), or the portable one.
fn fill_words(planes: &FacePlanes, mesh: &Mesh, l: Vec4, flip: bool, filter: (Vec4, f32), first: usize, out: &mut [u64]) {
    if cpu::portable_only() {
        fill_words_in(planes, mesh, l, flip, filter, first, out, dots::block64)
    } else {
        fill_words_per_level(planes, mesh, l, flip, filter, first, out)
    }
}

per_cpu_level! {
    /// [`fill_words_in`], compiled per CPU level; the copies with AVX take their dot products
    /// eight planes a vector ([`dots::block64_avx`]), the others four.
    fn fill_words_per_level(planes: &FacePlanes, mesh: &Mesh, l: Vec4, flip: bool, filter: (Vec4, f32), first: usize, out: &mut [u64]) {
        let dots = cpu::by_feature!(
            "avx",
            |nx: &[f32], ny: &[f32], nz: &[f32], d: &[f32], l: Vec4, e: f32| dots::block64_avx(nx, ny, nz, d, l, e),
            dots::block64
        );
        fill_words_in(planes, mesh, l, flip, filter, first, out, dots)
    }
}

/// The dot products of one facing word: `(facing, unsure)` bits of 64 planes
/// (`nx, ny, nz, d`) for the filter light and bound ([`dots::block64`]).
trait Dots: Fn(&[f32], &[f32], &[f32], &[f32], Vec4, f32) -> (u64, u64) + Copy {}
impl<F: Fn(&[f32], &[f32], &[f32], &[f32], Vec4, f32) -> (u64, u64) + Copy> Dots for F {}

/// [`fill_words`]' body, inlined into each copy, with that copy's dot products.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn fill_words_in(
    planes: &FacePlanes,
    mesh: &Mesh,
    l: Vec4,
    flip: bool,
    (lf, e): (Vec4, f32),
    first: usize,
    out: &mut [u64],
    dots: impl Dots,
) {
    let n = planes.len;
    // flip: the negated plane, i.e. the negated light (exact).
    let lf = if flip { -lf } else { lf };
    let (words, last) = (n.div_ceil(64), first + out.len());
    let probe = Probe::new(lf, e as f64);
    let size = SUPER_BLOCKS[0];
    let valid = |w: usize| valid_bits(n, w);
    let mut w = first;
    while w < last {
        // the super-block of word `w`, tested where all its words are this call's
        let s = w / size;
        let s_end = ((s + 1) * size).min(words);
        let end = s_end.min(last);
        let sup = match planes.supers[0].get(s) {
            Some(b) if s * size >= first && s_end <= last => b.test(&probe),
            _ => (false, false),
        };
        let ours = &mut out[w - first..end - first];
        if sup.0 || sup.1 {
            ours.fill(if sup.0 { u64::MAX } else { 0 });
        } else {
            // its blocks' bounds, all at once: the decided words, then the others' dot products
            let (ones, zeros) = planes.blocks.get(s).map_or((0, 0), |b| b.test(&probe));
            let (ones, zeros) = (ones >> (w - s * size), zeros >> (w - s * size));
            for (k, o) in ours.iter_mut().enumerate() {
                *o = 0u64.wrapping_sub((ones >> k) & 1);
            }
            let mut undecided = !(ones | zeros) & ((1 << ours.len()) - 1);
            while undecided != 0 {
                let k = undecided.trailing_zeros() as usize;
                undecided &= undecided - 1;
                ours[k] = dot_word(planes, mesh, (l, lf, e), flip, w + k, dots);
            }
        }
        // the last word's bits past the triangles stay clear
        if end == words {
            out[end - 1 - first] &= valid(end - 1);
        }
        w = end;
    }
}

/// The bits of word `w` that are triangles (of `n`).
#[inline(always)]
fn valid_bits(n: usize, w: usize) -> u64 {
    if (w + 1) * 64 <= n {
        u64::MAX
    } else {
        (1u64 << (n - w * 64)) - 1
    }
}

/// Facing word `w` of `planes` from its 64 dot products with the filter's light `lf` and
/// bound `e`, the exact test (light `l`) where they are unsure. Not a closure: it is inlined
/// into each CPU level's copy of [`fill_words`].
#[inline(always)]
fn dot_word(planes: &FacePlanes, mesh: &Mesh, (l, lf, e): (Vec4, Vec4, f32), flip: bool, w: usize, dots: impl Dots) -> u64 {
    let r = w * 64..w * 64 + 64;
    let (bits, unsure) = dots(&planes.nx[r.clone()], &planes.ny[r.clone()], &planes.nz[r.clone()], &planes.d[r], lf, e);
    let valid = valid_bits(planes.len, w);
    let (mut word, mut u) = (bits & valid, unsure & valid);
    while u != 0 {
        let k = u.trailing_zeros() as usize;
        u &= u - 1;
        word = (word & !(1 << k)) | (u64::from(exact_bit(mesh, planes.tri(w * 64 + k), l, flip)) << k);
    }
    word
}

mod gpu;
pub(crate) use gpu::GPU_BLOCK;

#[cfg(test)]
mod tests;
