//! Possible silhouettes: per-triangle facing bits (decided once per light) and the edges
//! whose two triangles disagree.

use super::mesh::Mesh;
use super::predicates::{facing_exact, facing_f64};
use super::topology::ManifoldEdge;
use glam::{DVec3, Vec3, Vec4};

/// Meshes with at least this many triangles get their facing bits on several threads
/// (the f64 filtered orientation test is compute-bound).
pub const PARALLEL_THRESHOLD: usize = 200_000;
/// [`FacePlanes::facing_packed_auto`] splits over threads from this many triangles. Measured on
/// the shared 2-core machine (benches/silhouette.rs): 1M triangles took 1.97 ms on one thread and
/// 1.41 ms on two in isolation, but followed by the edge scan (as the planner runs it) 9.4 ms
/// threaded against 3.0 ms serial, and 100k 970 µs against 277 µs; at 10k two threads cost
/// 5x more than they save. Threads do not pay on such a machine: only for very large meshes.
pub const PLANES_PARALLEL_THRESHOLD: usize = 4_000_000;
/// The edge scan is memory-bound: on a 2-core machine, 1.5M edges took 1.2 ms serial vs
/// 2.4 ms on 2 threads (benches/silhouette.rs), so it only splits for very large meshes.
pub const PARALLEL_EDGE_THRESHOLD: usize = 8_000_000;

/// One possible-silhouette edge: `a -> b` as it appears in the LIGHT-FACING triangle `lit`
/// (corner `lit_corner`); `unlit` walks it `b -> a` (corner `unlit_corner`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SilhouetteEdge {
    /// Start vertex (welded index) in the light-facing triangle's winding.
    pub a: u32,
    /// End vertex (welded index) in the light-facing triangle's winding.
    pub b: u32,
    /// The light-facing triangle.
    pub lit: u32,
    /// Corner of `lit` where `a -> b` starts.
    pub lit_corner: u8,
    /// The triangle facing away from the light.
    pub unlit: u32,
    /// Corner of `unlit` where `b -> a` starts.
    pub unlit_corner: u8,
}

fn threads_for(n: usize) -> usize {
    if n < PARALLEL_THRESHOLD {
        1
    } else {
        std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1).min(8)
    }
}

/// Facing bit of every triangle for the object-space homogeneous light `l`
/// (`flip`: negate the orientation, for casters whose transform mirrors).
pub fn facing_bits(mesh: &Mesh, l: Vec4, flip: bool) -> Vec<bool> {
    facing_bits_threads(mesh, l, flip, threads_for(mesh.triangles.len()))
}

/// [`facing_bits`] on exactly `threads` threads (benchmarks compare 1 with the default).
pub fn facing_bits_threads(mesh: &Mesh, l: Vec4, flip: bool, threads: usize) -> Vec<bool> {
    let n = mesh.triangles.len();
    let mut out = vec![false; n];
    let work = |tris: &[[u32; 3]], out: &mut [bool]| {
        let p = &mesh.positions;
        for (o, t) in out.iter_mut().zip(tris) {
            let (a, b, c): (DVec3, DVec3, DVec3) = (p[t[0] as usize].as_dvec3(), p[t[1] as usize].as_dvec3(), p[t[2] as usize].as_dvec3());
            *o = if flip { facing_f64(a, c, b, l) } else { facing_f64(a, b, c, l) };
        }
    };
    let th = threads.max(1);
    if th == 1 || n == 0 {
        work(&mesh.triangles, &mut out);
    } else {
        let chunk = n.div_ceil(th);
        std::thread::scope(|s| {
            for (tris, o) in mesh.triangles.chunks(chunk).zip(out.chunks_mut(chunk)) {
                s.spawn(move || work(tris, o));
            }
        });
    }
    out
}

fn sil_range(edges: &[ManifoldEdge], facing: &[bool], out: &mut Vec<SilhouetteEdge>) {
    for e in edges {
        let (f0, f1) = (facing[e.t0 as usize], facing[e.t1 as usize]);
        if f0 != f1 {
            out.push(if f0 {
                SilhouetteEdge { a: e.a, b: e.b, lit: e.t0, lit_corner: e.c0, unlit: e.t1, unlit_corner: e.c1 }
            } else {
                SilhouetteEdge { a: e.b, b: e.a, lit: e.t1, lit_corner: e.c1, unlit: e.t0, unlit_corner: e.c0 }
            });
        }
    }
}

/// The possible silhouette: every manifold edge whose triangles have different facing bits,
/// oriented as in its light-facing triangle.
pub fn possible_silhouette(edges: &[ManifoldEdge], facing: &[bool]) -> Vec<SilhouetteEdge> {
    let th = if edges.len() < PARALLEL_EDGE_THRESHOLD { 1 } else { threads_for(edges.len()) };
    if th == 1 {
        let mut out = Vec::new();
        sil_range(edges, facing, &mut out);
        return out;
    }
    let chunk = edges.len().div_ceil(th);
    let parts: Vec<Vec<SilhouetteEdge>> = std::thread::scope(|s| {
        let hs: Vec<_> = edges
            .chunks(chunk)
            .map(|es| {
                s.spawn(move || {
                    let mut v = Vec::new();
                    sil_range(es, facing, &mut v);
                    v
                })
            })
            .collect();
        hs.into_iter().map(|h| h.join().expect("silhouette worker panicked")).collect()
    });
    parts.concat()
}

/// Single-threaded reference (for benchmarks and tests).
pub fn possible_silhouette_serial(edges: &[ManifoldEdge], facing: &[bool]) -> Vec<SilhouetteEdge> {
    let mut out = Vec::new();
    sil_range(edges, facing, &mut out);
    out
}

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
fn exact_bit(mesh: &Mesh, t: usize, l: Vec4, flip: bool) -> bool {
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
#[inline]
#[allow(clippy::needless_range_loop)] // indexed form: the compiler vectorises it
fn block64(nx: &[f32], ny: &[f32], nz: &[f32], d: &[f32], l: Vec4, e: f32) -> (u64, u64) {
    let (nx, ny, nz, d) = (&nx[..64], &ny[..64], &nz[..64], &d[..64]);
    let (mut bits, mut unsure) = (0u64, 0u64);
    for j in 0..8 {
        let mut v = [0f32; 8];
        for k in 0..8 {
            let i = j * 8 + k;
            v[k] = nx[i] * l.x + ny[i] * l.y + nz[i] * l.z + d[i] * l.w;
        }
        let (mut b, mut u) = (0u64, 0u64);
        for (k, &x) in v.iter().enumerate() {
            b |= ((x > e) as u64) << k;
            u |= ((!(x.abs() > e)) as u64) << k;
        }
        bits |= b << (j * 8);
        unsure |= u << (j * 8);
    }
    (bits, unsure)
}

/// The facing bit of triangle `t` in packed bits (false past the end).
#[inline]
pub fn packed_bit(bits: &[u64], t: u32) -> bool {
    bits.get(t as usize / 64).is_some_and(|w| (w >> (t % 64)) & 1 != 0)
}

/// Packed facing bits to one `bool` per triangle (`n` triangles).
pub fn unpack_bits(bits: &[u64], n: usize) -> Vec<bool> {
    (0..n).map(|t| packed_bit(bits, t as u32)).collect()
}

/// [`possible_silhouette`] on packed facing bits ([`FacePlanes::facing_packed`]): the same
/// edges in the same order. An edge naming a triangle past the bits counts it as not facing.
pub fn possible_silhouette_packed(edges: &[ManifoldEdge], bits: &[u64]) -> Vec<SilhouetteEdge> {
    let mut out = Vec::new();
    possible_silhouette_packed_into(edges, bits, &mut out);
    out
}

/// Manifold edges prepared for the per-light scan: the full records, and their triangle pairs
/// `(t0, t1)` packed 8 bytes an edge, which is all the scan reads except for the few edges on
/// the possible silhouette.
#[derive(Clone, Debug, Default)]
pub struct EdgeScan {
    edges: Vec<ManifoldEdge>,
    pairs: Vec<[u32; 2]>,
    /// Largest triangle id of any edge.
    max_tri: u32,
}

impl EdgeScan {
    /// The scan over `edges` (in this order).
    pub fn new(edges: Vec<ManifoldEdge>) -> EdgeScan {
        let pairs = edges.iter().map(|e| [e.t0, e.t1]).collect();
        let max_tri = edges.iter().map(|e| e.t0.max(e.t1)).max().unwrap_or(0);
        EdgeScan { edges, pairs, max_tri }
    }

    /// The edges, in scan order.
    pub fn edges(&self) -> &[ManifoldEdge] {
        &self.edges
    }

    /// Bytes one scan reads (the triangle pairs).
    pub fn bytes(&self) -> usize {
        self.pairs.len() * 8
    }

    /// Appends the possible silhouette for the packed facing `bits` to `out`: the same edges in
    /// the same order as [`possible_silhouette`] on the unpacked bits (a triangle past the bits
    /// counts as not facing).
    pub fn scan_into(&self, bits: &[u64], out: &mut Vec<SilhouetteEdge>) {
        let bit = |t: u32| bits.get(t as usize / 64).map_or(0, |w| (w >> (t % 64)) & 1);
        // One byte a triangle (a short, vectorisable pass over the words): the scan's two
        // lookups an edge are then plain byte loads. Triangle ids past the bits read 0.
        let len = (self.max_tri as usize + 1).max(bits.len() * 64);
        let mut bytes = vec![0u8; len];
        for (dst, &w) in bytes.chunks_exact_mut(64).zip(bits) {
            for (k, d) in dst.iter_mut().enumerate() {
                *d = ((w >> k) & 1) as u8;
            }
        }
        let fast = |t: u32| bytes.get(t as usize).copied().unwrap_or(0);
        for (chunk, es) in self.pairs.chunks(64).zip(self.edges.chunks(64)) {
            // most blocks hold no silhouette edge: one OR-reduction (no shifts into a mask), and
            // only the rare blocks with one are walked again
            let mut any = 0u8;
            for p in chunk {
                any |= fast(p[0]) ^ fast(p[1]);
            }
            if any == 0 {
                continue;
            }
            for (p, &e) in chunk.iter().zip(es) {
                if fast(p[0]) == fast(p[1]) {
                    continue;
                }
                out.push(if bit(e.t0) != 0 {
                    SilhouetteEdge { a: e.a, b: e.b, lit: e.t0, lit_corner: e.c0, unlit: e.t1, unlit_corner: e.c1 }
                } else {
                    SilhouetteEdge { a: e.b, b: e.a, lit: e.t1, lit_corner: e.c1, unlit: e.t0, unlit_corner: e.c0 }
                });
            }
        }
    }
}

/// [`possible_silhouette_packed`] appending to `out` (reuse the allocation across frames).
pub fn possible_silhouette_packed_into(edges: &[ManifoldEdge], bits: &[u64], out: &mut Vec<SilhouetteEdge>) {
    for e in edges {
        let (f0, f1) = (packed_bit(bits, e.t0), packed_bit(bits, e.t1));
        if f0 != f1 {
            out.push(if f0 {
                SilhouetteEdge { a: e.a, b: e.b, lit: e.t0, lit_corner: e.c0, unlit: e.t1, unlit_corner: e.c1 }
            } else {
                SilhouetteEdge { a: e.b, b: e.a, lit: e.t1, lit_corner: e.c1, unlit: e.t0, unlit_corner: e.c0 }
            });
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::topology::Topology;
    use crate::shadow::testmesh::{cube, uv_sphere};

    #[test]
    fn cube_from_above() {
        let t = Topology::build(&cube(Vec3::ZERO, 1.0));
        let f = facing_bits(&t.mesh, Vec4::new(0.0, 5.0, 0.0, 1.0), false);
        assert_eq!(f.iter().filter(|&&x| x).count(), 2);
        let s = possible_silhouette(&t.manifold_edges, &f);
        assert_eq!(s.len(), 4);
        for e in &s {
            let tri = t.mesh.triangles[e.lit as usize];
            let k = e.lit_corner as usize;
            assert_eq!((tri[k], tri[(k + 1) % 3]), (e.a, e.b));
            assert!(f[e.lit as usize] && !f[e.unlit as usize]);
            let u = t.mesh.triangles[e.unlit as usize];
            let k = e.unlit_corner as usize;
            assert_eq!((u[k], u[(k + 1) % 3]), (e.b, e.a));
        }
        // silhouette loop: every vertex has one outgoing and one incoming edge
        let mut deg = std::collections::HashMap::<u32, i32>::new();
        for e in &s {
            *deg.entry(e.a).or_default() += 1;
            *deg.entry(e.b).or_default() -= 1;
        }
        assert!(deg.values().all(|&d| d == 0));
    }

    #[test]
    fn parallel_equals_serial() {
        let t = Topology::build(&uv_sphere(1.0, 400, 300));
        let mut many = t.manifold_edges.clone();
        while many.len() < PARALLEL_EDGE_THRESHOLD {
            many.extend_from_within(..);
        }
        let l = Vec4::new(3.0, 1.0, 0.5, 1.0);
        let f = facing_bits(&t.mesh, l, false);
        let mut serial = vec![false; f.len()];
        for (i, tri) in t.mesh.triangles.iter().enumerate() {
            let p = |k: usize| t.mesh.positions[tri[k] as usize];
            serial[i] = crate::geom::predicates::facing(p(0), p(1), p(2), l);
        }
        assert_eq!(f, serial);
        assert_eq!(possible_silhouette(&t.manifold_edges, &f), possible_silhouette_serial(&t.manifold_edges, &f));
        assert_eq!(possible_silhouette(&many, &f), possible_silhouette_serial(&many, &f));
    }

    fn exact_reference(m: &Mesh, l: Vec4, flip: bool) -> Vec<bool> {
        (0..m.triangles.len()).map(|t| exact_bit(m, t, l, flip)).collect()
    }

    fn check_planes(m: &Mesh, l: Vec4) {
        let planes = FacePlanes::new(m);
        let mut bits = Vec::new();
        for flip in [false, true] {
            let want = exact_reference(m, l, flip);
            planes.facing_packed(m, l, flip, &mut bits);
            assert_eq!(bits.len(), m.triangles.len().div_ceil(64));
            assert_eq!(unpack_bits(&bits, m.triangles.len()), want, "light {l:?} flip {flip}");
            if let Some(&last) = bits.last() {
                if m.triangles.len() % 64 != 0 {
                    assert_eq!(last >> (m.triangles.len() % 64), 0);
                }
            }
            let mut threaded = Vec::new();
            planes.facing_packed_threads(m, l, flip, 3, &mut threaded);
            assert_eq!(threaded, bits);
        }
    }

    #[test]
    fn packed_equals_bools_on_sphere() {
        let t = Topology::build(&uv_sphere(1.0, 60, 31));
        let planes = FacePlanes::new(&t.mesh);
        assert_eq!(planes.len(), t.mesh.triangles.len());
        assert_eq!(planes.bytes(), t.mesh.triangles.len().div_ceil(64) * 64 * 16);
        let mut bits = Vec::new();
        for l in
            [Vec4::new(3.0, 2.0, 1.0, 1.0), Vec4::new(0.1, 0.2, -0.3, 1.0), Vec4::new(-1.0, 0.5, 0.2, 0.0), Vec4::new(6.0, 4.0, 2.0, 2.0)]
        {
            for flip in [false, true] {
                planes.facing_packed(&t.mesh, l, flip, &mut bits);
                let f = facing_bits(&t.mesh, l, flip);
                assert_eq!(unpack_bits(&bits, f.len()), f);
                assert_eq!(possible_silhouette_packed(&t.manifold_edges, &bits), possible_silhouette_serial(&t.manifold_edges, &f));
                let mut sil = Vec::new();
                EdgeScan::new(t.manifold_edges.clone()).scan_into(&bits, &mut sil);
                assert_eq!(sil, possible_silhouette_serial(&t.manifold_edges, &f));
            }
            check_planes(&t.mesh, l);
        }
    }

    #[test]
    fn planes_bad_input() {
        // lights on vertices, in face planes, inside; degenerate triangles; out-of-range indices
        let mut m = cube(Vec3::ZERO, 1.0);
        m.triangles.push([0, 0, 1]);
        m.triangles.push([0, 1, 99]);
        let p = m.positions.clone();
        m.positions.push(p[0] * 2.0 - p[1]); // collinear with p0, p1
        let k = m.positions.len() as u32 - 1;
        m.triangles.push([0, 1, k]);
        for l in [
            p[0].extend(1.0),
            p[3].extend(1.0),
            Vec4::new(0.0, 0.0, 0.0, 1.0),
            Vec4::new(1.0, 1.0, 3.0, 1.0),
            Vec4::new(1.0, 0.0, 0.0, 0.0),
        ] {
            check_planes(&m, l);
        }
        let planes = FacePlanes::new(&m);
        assert_eq!(planes.always_exact(), 3);
        let mut bits = Vec::new();
        planes.facing_packed(&m, Vec4::new(0.0, 5.0, 0.0, 1.0), false, &mut bits);
        assert!(!packed_bit(&bits, 13) && !packed_bit(&bits, 1000));
        // non-finite and huge lights, huge meshes, a mismatched mesh: exact everywhere
        for l in [Vec4::new(f32::NAN, 0.0, 0.0, 1.0), Vec4::new(1e30, 2e30, 0.0, 1.0), Vec4::new(1.0, 2.0, 3.0, 1e-30)] {
            check_planes(&m, l);
        }
        let mut far = cube(Vec3::splat(1e20), 1.0);
        far.positions[0].x = 3e25;
        check_planes(&far, Vec4::new(0.0, 1.0, 0.0, 1.0));
        assert_eq!(FacePlanes::new(&far).always_exact(), far.triangles.len());
        let other = cube(Vec3::ONE, 1.0);
        planes.facing_packed(&other, Vec4::new(0.0, 5.0, 0.0, 1.0), false, &mut bits);
        assert_eq!(unpack_bits(&bits, 12), exact_reference(&other, Vec4::new(0.0, 5.0, 0.0, 1.0), false));
        // empty
        let empty = Mesh::default();
        FacePlanes::new(&empty).facing_packed(&empty, Vec4::ONE, false, &mut bits);
        assert!(bits.is_empty());
        // deforming: recompute follows the new positions
        let mut moving = uv_sphere(1.0, 12, 7);
        let mut planes = FacePlanes::new(&moving);
        for q in &mut moving.positions {
            *q = Vec3::new(q.x * 2.0 + 5.0, -q.y, q.z * 0.5);
        }
        planes.recompute(&moving);
        planes.facing_packed(&moving, Vec4::new(3.0, 1.0, 0.5, 1.0), false, &mut bits);
        assert_eq!(unpack_bits(&bits, moving.triangles.len()), exact_reference(&moving, Vec4::new(3.0, 1.0, 0.5, 1.0), false));
    }

    mod proptests {
        use super::*;
        use proptest::prelude::*;

        /// Coordinates: small lattice values (exact coplanarity is common), uniform values,
        /// huge offsets and tiny ones.
        fn coord() -> impl Strategy<Value = f32> {
            prop_oneof![
                (-4i32..=4).prop_map(|i| i as f32 * 0.5),
                -1.0f32..1.0,
                (-1.0f32..1.0).prop_map(|x| 1e5 + x),
                (-1.0f32..1.0).prop_map(|x| x * 1e7),
                (-1.0f32..1.0).prop_map(|x| x * 1e-6),
                (-1.0f32..1.0).prop_map(|x| 3e17 + x * 1e11),
            ]
        }

        fn point() -> impl Strategy<Value = Vec3> {
            (coord(), coord(), coord()).prop_map(|(x, y, z)| Vec3::new(x, y, z))
        }

        fn mesh_and_light() -> impl Strategy<Value = (Mesh, Vec4)> {
            (
                prop::collection::vec(point(), 3..24),
                prop::collection::vec((0usize..64, 0usize..64, 0usize..64), 1..150),
                0usize..8,
                point(),
                0usize..64,
                -1.0f32..1.0,
            )
                .prop_map(|(pos, tris, kind, free, pick, s)| {
                    let n = pos.len();
                    let triangles: Vec<[u32; 3]> = tris.iter().map(|&(a, b, c)| [(a % n) as u32, (b % n) as u32, (c % n) as u32]).collect();
                    let t = triangles[pick % triangles.len()];
                    let [a, b, c] = t.map(|i| pos[i as usize]);
                    let l = match kind {
                        0 => free.extend(1.0),
                        1 => a.extend(1.0),                       // on a vertex
                        2 => (a + (b - a) + (c - a)).extend(1.0), // in a plane (exact on the lattice)
                        3 => (a + (b - a) * 0.5).extend(1.0),     // on an edge
                        4 => (b - a).extend(0.0),                 // directional, in a plane
                        5 => ((b - a) + (c - a) * s).extend(0.0), // directional, near a plane
                        6 => (a + (b - a) * s).extend(1.0) + Vec4::new(0.0, 0.0, f32::EPSILON * a.z.abs(), 0.0),
                        _ => free.extend(s * 3.0), // general homogeneous w
                    };
                    (Mesh { positions: pos, triangles }, l)
                })
        }

        proptest! {
            #![proptest_config(ProptestConfig { cases: 3000, ..ProptestConfig::default() })]
            #[test]
            fn fast_bits_equal_exact((m, l) in mesh_and_light()) {
                check_planes(&m, l);
            }

            #[test]
            fn near_coplanar_grids(scale in prop_oneof![Just(1.0f32), Just(1e4), Just(1e-4), Just(3e6)], off in point(), tilt in -1e-6f32..1e-6, lz in -1e-5f32..1e-5) {
                // a fan of almost coplanar triangles, lights on and very near their plane
                let mut positions = Vec::new();
                for i in 0..9 {
                    for j in 0..9 {
                        positions.push(off + Vec3::new(i as f32, j as f32, (i * j) as f32 * tilt) * scale);
                    }
                }
                let mut triangles = Vec::new();
                for i in 0..8u32 {
                    for j in 0..8u32 {
                        let v = i * 9 + j;
                        triangles.push([v, v + 9, v + 1]);
                        triangles.push([v + 1, v + 9, v + 10]);
                    }
                }
                let m = Mesh { positions, triangles };
                for l in [(off + Vec3::new(3.0, 4.0, lz) * scale).extend(1.0), off.extend(1.0), Vec3::new(1.0, 2.0, lz).extend(0.0), (off * 2.0).extend(1.0)] {
                    check_planes(&m, l);
                }
            }
        }
    }
}
