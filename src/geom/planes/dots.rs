//! The filter's dot products, 64 planes (one facing word) a call: four planes a vector in
//! glam's `Vec4` ([`block64`], every copy), or eight in AVX registers ([`block64_avx`], the
//! x86-64-v3 copy). Both do the same f32 operations in the same order on each plane, so they
//! give the same bits; both are safe code (the AVX one calls `std::arch`'s value intrinsics
//! from a `#[target_feature]` function, which only the v3 copy of the facing calls).

use glam::Vec4;

/// Facing and "unsure" bits of 64 planes: bit k of the first word is set when plane k's value
/// exceeds `e`, of the second when its magnitude does not (NaN included).
///
/// Four planes at a time in glam's `Vec4` (SSE2 on x86_64, VEX-encoded in the x86-64-v3 copy;
/// safe): the value is
/// `((nx·lx + ny·ly) + nz·lz) + d·lw` in f32, the same operations in the same order as the
/// scalar form, and each comparison becomes one mask (`movmskps`). The filter's light has
/// `lw = ±1` or `0`, where `d·lw` is exact (`±d`, or a zero that cannot move the value across
/// `±e`): those three are specialised, one multiplication fewer, the same bits.
#[inline(always)]
pub(super) fn block64(nx: &[f32], ny: &[f32], nz: &[f32], d: &[f32], l: Vec4, e: f32) -> (u64, u64) {
    if l.w == 1.0 {
        block64_w(nx, ny, nz, d, l, e, |s, d| s + d)
    } else if l.w == -1.0 {
        block64_w(nx, ny, nz, d, l, e, |s, d| s - d)
    } else if l.w == 0.0 {
        block64_w(nx, ny, nz, d, l, e, |s, _| s)
    } else {
        let lw = Vec4::splat(l.w);
        block64_w(nx, ny, nz, d, l, e, |s, d| s + d * lw)
    }
}

/// [`block64`] with the `d` term `dw(xyz sum, d)`; 16 planes an iteration (four masks merged
/// at constant shifts).
#[inline(always)]
fn block64_w(nx: &[f32], ny: &[f32], nz: &[f32], d: &[f32], l: Vec4, e: f32, dw: impl Fn(Vec4, Vec4) -> Vec4) -> (u64, u64) {
    let (nx, ny, nz, d) = (&nx[..64], &ny[..64], &nz[..64], &d[..64]);
    let (lx, ly, lz, ev, nev) = (Vec4::splat(l.x), Vec4::splat(l.y), Vec4::splat(l.z), Vec4::splat(e), Vec4::splat(-e));
    let (mut bits, mut sure) = (0u64, 0u64);
    for (q, (((x, y), z), w)) in nx.chunks_exact(16).zip(ny.chunks_exact(16)).zip(nz.chunks_exact(16)).zip(d.chunks_exact(16)).enumerate() {
        let (mut b16, mut s16) = (0u32, 0u32);
        for j in 0..4 {
            let r = j * 4..j * 4 + 4;
            let xyz = Vec4::from_slice(&x[r.clone()]) * lx + Vec4::from_slice(&y[r.clone()]) * ly + Vec4::from_slice(&z[r.clone()]) * lz;
            let v = dw(xyz, Vec4::from_slice(&w[r]));
            let (gt, lt) = (v.cmpgt(ev), v.cmplt(nev));
            b16 |= gt.bitmask() << (j * 4);
            s16 |= (gt | lt).bitmask() << (j * 4);
        }
        bits |= u64::from(b16) << (q * 16);
        sure |= u64::from(s16) << (q * 16);
    }
    (bits, !sure)
}

/// [`block64`] eight planes a vector: `vmulps`/`vaddps`/`vsubps` in the same order (no fused
/// multiply-add: Rust never contracts them), `vcmpps` with the ordered predicates `>` and `<`
/// that `cmpgt`/`cmplt` are (false on NaN), one `vmovmskps` per 8 bits. Half the vector
/// operations of the 4-wide form. Safe to call only from code compiled with AVX, which the
/// compiler checks: the x86-64-v3 copy of the facing (`fill_words_per_level`).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx")]
pub(super) fn block64_avx(nx: &[f32], ny: &[f32], nz: &[f32], d: &[f32], l: Vec4, e: f32) -> (u64, u64) {
    use std::arch::x86_64::{_mm256_add_ps, _mm256_mul_ps, _mm256_set1_ps, _mm256_sub_ps};
    if l.w == 1.0 {
        block64_avx_w(nx, ny, nz, d, l, e, |s, d| _mm256_add_ps(s, d))
    } else if l.w == -1.0 {
        block64_avx_w(nx, ny, nz, d, l, e, |s, d| _mm256_sub_ps(s, d))
    } else if l.w == 0.0 {
        block64_avx_w(nx, ny, nz, d, l, e, |s, _| s)
    } else {
        let lw = _mm256_set1_ps(l.w);
        block64_avx_w(nx, ny, nz, d, l, e, |s, d| _mm256_add_ps(s, _mm256_mul_ps(d, lw)))
    }
}

/// [`block64_avx`] with the `d` term `dw(xyz sum, d)`.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx")]
#[inline]
fn block64_avx_w(
    nx: &[f32],
    ny: &[f32],
    nz: &[f32],
    d: &[f32],
    l: Vec4,
    e: f32,
    dw: impl Fn(std::arch::x86_64::__m256, std::arch::x86_64::__m256) -> std::arch::x86_64::__m256,
) -> (u64, u64) {
    use std::arch::x86_64::{
        __m256, _mm256_add_ps, _mm256_cmp_ps, _mm256_movemask_ps, _mm256_mul_ps, _mm256_or_ps, _mm256_set1_ps, _CMP_GT_OQ, _CMP_LT_OQ,
    };
    // eight lanes a vector: the arrays as vectors by value (`bytemuck`, no pointers)
    fn lanes(s: &[f32]) -> &[[f32; 8]] {
        bytemuck::cast_slice(&s[..64])
    }
    let (nx, ny, nz, d) = (lanes(nx), lanes(ny), lanes(nz), lanes(d));
    let (lx, ly, lz) = (_mm256_set1_ps(l.x), _mm256_set1_ps(l.y), _mm256_set1_ps(l.z));
    let (ev, nev) = (_mm256_set1_ps(e), _mm256_set1_ps(-e));
    let v8 = |a: [f32; 8]| -> __m256 { bytemuck::cast(a) };
    let (mut bits, mut sure) = (0u64, 0u64);
    for j in 0..8 {
        let xy = _mm256_add_ps(_mm256_mul_ps(v8(nx[j]), lx), _mm256_mul_ps(v8(ny[j]), ly));
        let xyz = _mm256_add_ps(xy, _mm256_mul_ps(v8(nz[j]), lz));
        let v = dw(xyz, v8(d[j]));
        let (gt, lt) = (_mm256_cmp_ps::<_CMP_GT_OQ>(v, ev), _mm256_cmp_ps::<_CMP_LT_OQ>(v, nev));
        bits |= u64::from(_mm256_movemask_ps(gt) as u8) << (8 * j);
        sure |= u64::from(_mm256_movemask_ps(_mm256_or_ps(gt, lt)) as u8) << (8 * j);
    }
    (bits, !sure)
}
