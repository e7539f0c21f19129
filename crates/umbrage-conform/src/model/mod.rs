//! A CPU model of the Vulkan depth/stencil pipeline (the spec's "Fragment Operations"
//! chapter, in its order: depth bounds, stencil test, depth test, stencil ops with write
//! masks, depth write), run per pixel over a [`Case`]'s draws to give its exact expectation.
//!
//! Where the spec leaves a choice — a pixel centre within [`raster::EDGE_EPS`] of an edge,
//! a fragment depth too close to a stored one for the format's rounding to be known, a depth
//! bound within rounding of a stored value — the pixel becomes unknown from then on and is not
//! judged (and an occlusion query's count gets a range). Everything else is compared exactly:
//! stencil bit for bit, depth as the format's representable value.

use super::cases::{Case, DepthKind, DsState};
use super::raster::{self, ClippedPoly, Cover, WinTri};
use ash::vk;

/// What a pixel's depth must be.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum DepthExp {
    /// Not judged.
    Any,
    /// Exactly this representable value of the format.
    Exact(f64),
    /// Within `[lo, hi]` (interpolated depth).
    Range(f64, f64),
}

impl DepthExp {
    fn interval(self) -> Option<(f64, f64)> {
        match self {
            DepthExp::Any => None,
            DepthExp::Exact(v) => Some((v, v)),
            DepthExp::Range(a, b) => Some((a, b)),
        }
    }
    /// Whether `v` satisfies the expectation.
    pub fn accepts(self, v: f64) -> bool {
        match self {
            DepthExp::Any => true,
            DepthExp::Exact(e) => v == e,
            DepthExp::Range(a, b) => v >= a && v <= b,
        }
    }
}

/// The expected result of a case.
#[derive(Clone, Debug, PartialEq)]
pub struct Expected {
    /// Final stencil per tile pixel; `None` = not judged.
    pub stencil: Vec<Option<u8>>,
    /// Final depth per tile pixel.
    pub depth: Vec<DepthExp>,
    /// Per query draw, the inclusive range of the passing-sample count.
    pub queries: Vec<(u64, u64)>,
}

/// The format's representable value nearest `v` (unorm: clamped to [0, 1], round to nearest).
pub fn quantise(kind: DepthKind, v: f64) -> f64 {
    match kind {
        DepthKind::Unorm16 => (v.clamp(0.0, 1.0) * 65535.0).round() / 65535.0,
        DepthKind::Unorm24 => (v.clamp(0.0, 1.0) * 16_777_215.0).round() / 16_777_215.0,
        DepthKind::Float32 => v as f32 as f64,
        DepthKind::None => v,
    }
}

/// One unit in the last place of the format near `v`.
fn quantum(kind: DepthKind, v: f64) -> f64 {
    match kind {
        DepthKind::Unorm16 => 1.0 / 65535.0,
        DepthKind::Unorm24 => 1.0 / 16_777_215.0,
        DepthKind::Float32 => {
            (v.abs().max(1e-30) as f32).to_bits().checked_add(1).map_or(1e-7, |b| (f32::from_bits(b) - v.abs() as f32) as f64)
        }
        DepthKind::None => 0.0,
    }
}

/// Raw texel word of `v` in the format's buffer-copy layout (D16: 16 bits, D24: low 24
/// bits of a word, D32: f32 bits).
pub fn to_raw(kind: DepthKind, v: f64) -> u32 {
    match kind {
        DepthKind::Unorm16 => (v.clamp(0.0, 1.0) * 65535.0).round() as u32,
        DepthKind::Unorm24 => (v.clamp(0.0, 1.0) * 16_777_215.0).round() as u32,
        DepthKind::Float32 => (v as f32).to_bits(),
        DepthKind::None => 0,
    }
}

/// The value of a raw texel word read back (see [`to_raw`]).
pub fn from_raw(kind: DepthKind, raw: u32) -> f64 {
    match kind {
        DepthKind::Unorm16 => (raw & 0xffff) as f64 / 65535.0,
        DepthKind::Unorm24 => (raw & 0x00ff_ffff) as f64 / 16_777_215.0,
        DepthKind::Float32 => f32::from_bits(raw) as f64,
        DepthKind::None => 0.0,
    }
}

/// The op the `UMBRAGE_CONFORM_BREAK` seam substitutes for `op` (a deliberately wrong expectation).
pub fn broken(op: vk::StencilOp) -> vk::StencilOp {
    match op {
        vk::StencilOp::INCREMENT_AND_WRAP => vk::StencilOp::DECREMENT_AND_WRAP,
        vk::StencilOp::DECREMENT_AND_WRAP => vk::StencilOp::INCREMENT_AND_WRAP,
        vk::StencilOp::INCREMENT_AND_CLAMP => vk::StencilOp::DECREMENT_AND_CLAMP,
        vk::StencilOp::DECREMENT_AND_CLAMP => vk::StencilOp::INCREMENT_AND_CLAMP,
        vk::StencilOp::KEEP => vk::StencilOp::ZERO,
        _ => vk::StencilOp::KEEP,
    }
}

/// A stencil op applied to `s` with reference `r` and write mask `wm` (spec: only the bits
/// set in the write mask change).
pub fn apply_op(op: vk::StencilOp, s: u8, r: u8, wm: u8) -> u8 {
    let v = match op {
        vk::StencilOp::KEEP => s,
        vk::StencilOp::ZERO => 0,
        vk::StencilOp::REPLACE => r,
        vk::StencilOp::INCREMENT_AND_CLAMP => s.saturating_add(1),
        vk::StencilOp::DECREMENT_AND_CLAMP => s.saturating_sub(1),
        vk::StencilOp::INVERT => !s,
        vk::StencilOp::INCREMENT_AND_WRAP => s.wrapping_add(1),
        vk::StencilOp::DECREMENT_AND_WRAP => s.wrapping_sub(1),
        _ => s,
    };
    (s & !wm) | (v & wm)
}

/// `a OP b` when it is the same for every a in `a` and b in `b`, else `None`.
pub fn compare(op: vk::CompareOp, a: (f64, f64), b: (f64, f64)) -> Option<bool> {
    let less = || {
        if a.1 < b.0 {
            Some(true)
        } else if a.0 >= b.1 {
            Some(false)
        } else {
            None
        }
    };
    let lequal = || {
        if a.1 <= b.0 {
            Some(true)
        } else if a.0 > b.1 {
            Some(false)
        } else {
            None
        }
    };
    let equal = || {
        if a.0 == a.1 && b.0 == b.1 && a.0 == b.0 {
            Some(true)
        } else if a.1 < b.0 || a.0 > b.1 {
            Some(false)
        } else {
            None
        }
    };
    match op {
        vk::CompareOp::NEVER => Some(false),
        vk::CompareOp::ALWAYS => Some(true),
        vk::CompareOp::LESS => less(),
        vk::CompareOp::LESS_OR_EQUAL => lequal(),
        vk::CompareOp::EQUAL => equal(),
        vk::CompareOp::NOT_EQUAL => equal().map(|e| !e),
        vk::CompareOp::GREATER => lequal().map(|e| !e),
        vk::CompareOp::GREATER_OR_EQUAL => less().map(|e| !e),
        _ => None,
    }
}

/// The stencil test: `(reference & mask) OP (stored & mask)`.
pub fn stencil_test(op: vk::CompareOp, reference: u8, stored: u8, mask: u8) -> bool {
    let (r, s) = ((reference & mask) as f64, (stored & mask) as f64);
    compare(op, (r, r), (s, s)).unwrap_or(false)
}

enum Frag {
    /// Outside the clip volume's depth range: no fragment.
    Clipped,
    /// Whether the fragment exists is within rounding.
    Maybe,
    /// A fragment with this depth.
    At(DepthExp),
}

fn snap01(z: f64) -> f64 {
    if (z - 1.0).abs() < 1e-9 {
        1.0
    } else if z.abs() < 1e-9 {
        0.0
    } else {
        z
    }
}

/// For a pixel centre on exactly one edge of triangle `wt[ti]`: whether `wt[ti]` covers it by
/// the spec's shared-edge rule ("exactly one of two polygons sharing an edge covers a sample on
/// it"), when that edge is shared with the adjacent triangle in the draw (a quad's diagonal),
/// of the same facing and the same constant depth — so which of the two gets the fragment
/// changes nothing. `None`: not determinable (a vertex, an unshared edge, different planes).
fn shared_edge_owner(wt: &[WinTri], polys: &[Option<ClippedPoly>], ti: usize, x: u32, y: u32, eps: f64) -> Option<bool> {
    let t = &wt[ti];
    let c = glam::DVec2::new(x as f64 + 0.5, y as f64 + 0.5);
    let sign = if t.vk_area() < 0.0 { 1.0 } else { -1.0 };
    let mut on = None;
    for i in 0..3 {
        let (a, b) = (t.p[i], t.p[(i + 1) % 3]);
        let e = b - a;
        let d = sign * (e.x * (c.y - a.y) - e.y * (c.x - a.x)) / e.length();
        if d.abs() <= eps {
            if on.is_some() {
                return None;
            }
            on = Some((a, b));
        } else if d < 0.0 {
            return None;
        }
    }
    let (a, b) = on?;
    let flat = |t: &WinTri| t.z[0] == t.z[1] && t.z[1] == t.z[2];
    // Triangles pair up as (2k, 2k + 1), the way quads are emitted; the partner must share
    // the edge and lie on its other side.
    let u = ti ^ 1;
    if polys.get(u).is_some_and(|p| p.is_some()) {
        return None; // the partner is clipped: its window triangle is not `wt[u]`
    }
    let n = wt.get(u)?;
    let shares = (0..3).any(|i| {
        let (p, q) = (n.p[i], n.p[(i + 1) % 3]);
        (p == b && q == a) || (p == a && q == b)
    });
    let side = |t: &WinTri| {
        let o = t.p.iter().copied().find(|&p| p != a && p != b).unwrap_or(a);
        let e = b - a;
        (e.x * (o.y - a.y) - e.y * (o.x - a.x)).signum()
    };
    if shares && side(t) != side(n) && n.front_facing() == t.front_facing() && flat(t) && flat(n) && t.z[0] == n.z[0] {
        return Some(ti < u);
    }
    None
}

/// The fragment depth of triangle `t` at the centre of pixel (x, y) under `st`. `clipped`: `t`
/// is part of a clipped polygon, whose new vertices the device computes with its own rounding,
/// so even a constant depth is only known within the interpolation tolerance.
fn frag_depth(t: &WinTri, x: u32, y: u32, st: &DsState, kind: DepthKind, subpixel_bits: u32, clipped: bool) -> Frag {
    let c = glam::DVec2::new(x as f64 + 0.5, y as f64 + 0.5);
    let z = t.z.map(snap01);
    let constant = !clipped && z[0] == z[1] && z[1] == z[2];
    let (mut lo, mut hi) = if constant {
        (z[0], z[0])
    } else {
        let e = |a: glam::DVec2, b: glam::DVec2| (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
        let area = e(t.p[0], t.p[1]) + e(t.p[1], t.p[2]) + e(t.p[2], t.p[0]);
        let l0 = e(t.p[1], t.p[2]);
        let l1 = e(t.p[2], t.p[0]);
        let l2 = e(t.p[0], t.p[1]);
        let v = (l0 * z[0] + l1 * z[1] + l2 * z[2]) / area;
        // Tolerance: f32 interpolation, plus the depth change across two sub-pixel steps (the
        // vertices' snapping, and the new vertices of a clipped primitive).
        let (d1, d2) = (t.p[1] - t.p[0], t.p[2] - t.p[0]);
        let det = d1.x * d2.y - d2.x * d1.y;
        let gx = ((z[1] - z[0]) * d2.y - (z[2] - z[0]) * d1.y) / det;
        let gy = ((z[2] - z[0]) * d1.x - (z[1] - z[0]) * d2.x) / det;
        let e = 1e-5 + 2.0 * (gx.abs() + gy.abs()) / (1u64 << subpixel_bits) as f64;
        (v - e, v + e)
    };
    if !st.depth_clamp {
        if hi < 0.0 || lo > 1.0 {
            return Frag::Clipped;
        }
        if lo < 0.0 || hi > 1.0 {
            return Frag::Maybe;
        }
    }
    let (n, f) = (st.viewport_depth.0 as f64, st.viewport_depth.1 as f64);
    let map = |v: f64| n + v * (f - n);
    (lo, hi) = if f >= n { (map(lo), map(hi)) } else { (map(hi), map(lo)) };
    if let Some(b) = st.depth_bias {
        let b = b as f64;
        // r: at most 2 * 2^-n for unorm (at least 2^-n), 2^(e - 23) for float (e: the
        // primitive's largest depth exponent); kept as a range.
        let (r0, r1) = match kind {
            DepthKind::Unorm16 => (1.0 / 65536.0, 2.0 / 65536.0),
            DepthKind::Unorm24 => (1.0 / 16_777_216.0, 2.0 / 16_777_216.0),
            _ => {
                let m = t.z.iter().fold(0.0f64, |m, z| m.max(z.abs())).max(1e-30);
                let e = m.log2().floor();
                (2f64.powf(e - 24.0), 2f64.powf(e - 22.0))
            }
        };
        let (a, c) = (b * r0, b * r1);
        lo += a.min(c);
        hi += a.max(c);
    }
    if st.depth_clamp {
        let (a, b) = (n.min(f), n.max(f));
        lo = lo.clamp(a, b);
        hi = hi.clamp(a, b);
    } else if matches!(kind, DepthKind::Unorm16 | DepthKind::Unorm24) {
        lo = lo.clamp(0.0, 1.0);
        hi = hi.clamp(0.0, 1.0);
    }
    if lo == hi {
        Frag::At(DepthExp::Exact(quantise(kind, lo)))
    } else {
        let q = quantum(kind, hi);
        Frag::At(DepthExp::Range(quantise(kind, lo) - q, quantise(kind, hi) + q))
    }
}

/// The band (pixels) around edges within which coverage is not judged for `draw`:
/// [`raster::EDGE_EPS`] when every vertex lands exactly on the sub-pixel grid (the device's f32
/// transform then snaps it where the model does), else 1.5 sub-pixel steps (a vertex may snap
/// to a neighbouring grid point).
fn edge_band(draw: &super::cases::Draw, w: u32, h: u32, subpixel_bits: u32) -> f64 {
    let m = draw.mvp.as_dmat4();
    let s = (1u64 << subpixel_bits) as f64;
    let on_grid = draw.vertices.iter().all(|v| {
        let c = m * glam::DVec4::new(v[0] as f64, v[1] as f64, v[2] as f64, v[3] as f64);
        let (x, y) = ((c.x / c.w + 1.0) * 0.5 * w as f64, (c.y / c.w + 1.0) * 0.5 * h as f64);
        (x * s).fract() == 0.0 && (y * s).fract() == 0.0
    });
    if on_grid {
        raster::EDGE_EPS
    } else {
        1.5 / s
    }
}

/// For each triangle of `draw`: its clipped window polygon when a vertex has clip-space
/// `w <= 0` (computed in f64 from the f32 matrix and vertices, as [`raster::window_tris`]
/// does), `None` when every vertex is in front of the eye.
fn clipped_polys(draw: &super::cases::Draw, tris: &[[u32; 3]], w: u32, h: u32, subpixel_bits: u32) -> Vec<Option<ClippedPoly>> {
    let m = draw.mvp.as_dmat4();
    let clip: Vec<glam::DVec4> =
        draw.vertices.iter().map(|v| m * glam::DVec4::new(v[0] as f64, v[1] as f64, v[2] as f64, v[3] as f64)).collect();
    tris.iter()
        .map(|t| {
            let c = t.map(|i| clip[i as usize]);
            c.iter().any(|v| v.w <= 0.0).then(|| ClippedPoly::new(c, draw.state.depth_clamp, w, h, subpixel_bits))
        })
        .collect()
}

/// The fan triangle that contains the centre of pixel (x, y) deepest (largest smallest
/// distance to its edges).
fn fan_tri_at(fan: &[WinTri], x: u32, y: u32) -> &WinTri {
    let c = glam::DVec2::new(x as f64 + 0.5, y as f64 + 0.5);
    let depth_in = |t: &WinTri| {
        let sign = if t.vk_area() < 0.0 { 1.0 } else { -1.0 };
        (0..3)
            .map(|i| {
                let (a, b) = (t.p[i], t.p[(i + 1) % 3]);
                let e = b - a;
                let len = e.length();
                if len == 0.0 {
                    f64::NEG_INFINITY
                } else {
                    sign * (e.x * (c.y - a.y) - e.y * (c.x - a.x)) / len
                }
            })
            .fold(f64::INFINITY, f64::min)
    };
    fan.iter().max_by(|a, b| depth_in(a).total_cmp(&depth_in(b))).expect("a polygon of at least three vertices")
}

/// The expected result of `case` on a device with `subpixel_bits` of sub-pixel precision;
/// `brk` substitutes [`broken`]`(op)` for one stencil op (the test seam).
pub fn expect(case: &Case, subpixel_bits: u32, brk: Option<vk::StencilOp>) -> Expected {
    let kind = case.config.depth_kind();
    let (w, h) = case.size;
    let mut s: Vec<Option<u8>> = case.init_stencil.iter().map(|&v| Some(v)).collect();
    let mut d: Vec<DepthExp> =
        case.init_depth.iter().map(|&v| if kind == DepthKind::None { DepthExp::Any } else { DepthExp::Exact(quantise(kind, v)) }).collect();
    let mut queries = Vec::new();
    let op_of = |op: vk::StencilOp| if Some(op) == brk { broken(op) } else { op };
    for draw in &case.draws {
        let st = &draw.state;
        let tris: Vec<[u32; 3]> = (0..draw.vertices.len() as u32 / 3).map(|t| [3 * t, 3 * t + 1, 3 * t + 2]).collect();
        let wt = raster::window_tris(draw.mvp, &draw.vertices, &tris, w, h, subpixel_bits);
        let eps = edge_band(draw, w, h, subpixel_bits);
        // Triangles with a vertex at w <= 0 are clipped in homogeneous clip space first; the
        // others go straight to the viewport (for w > 0 the per-fragment depth check below is
        // the z clipping, and the viewport the x/y clipping).
        let polys = clipped_polys(draw, &tris, w, h, subpixel_bits);
        let clip_eps = eps.max(1.5 / (1u64 << subpixel_bits) as f64);
        let (mut qlo, mut qhi) = (0u64, 0u64);
        let depth_test = st.depth_test && kind != DepthKind::None;
        let depth_write = st.depth_write && kind != DepthKind::None;
        for (ti, t) in wt.iter().enumerate() {
            let poly = polys[ti].as_ref();
            let fan = poly.map(|p| p.fan()).unwrap_or_default();
            let pts: &[glam::DVec2] = match poly {
                Some(p) if p.singular => {
                    // The polygon reaches the clip volume's apex: nothing about it is known.
                    for i in 0..(w * h) as usize {
                        if st.stencil.is_some() {
                            s[i] = None;
                        }
                        if depth_write {
                            d[i] = DepthExp::Any;
                        }
                    }
                    qhi += u64::from(w * h);
                    continue;
                }
                Some(p) if p.vk_area() == 0.0 => continue,
                Some(p) => &p.p,
                None if t.vk_area() == 0.0 || t.p.iter().any(|p| !p.x.is_finite() || !p.y.is_finite()) => continue,
                None => &t.p,
            };
            let front = poly.map_or_else(|| t.front_facing(), |p| p.front_facing());
            let face = if front { st.stencil.map(|s| s.0) } else { st.stencil.map(|s| s.1) };
            let xs = pts.iter().map(|p| p.x).fold(f64::INFINITY, f64::min).floor().clamp(0.0, w as f64) as u32;
            let xe = pts.iter().map(|p| p.x).fold(f64::NEG_INFINITY, f64::max).ceil().clamp(0.0, w as f64) as u32;
            let ys = pts.iter().map(|p| p.y).fold(f64::INFINITY, f64::min).floor().clamp(0.0, h as f64) as u32;
            let ye = pts.iter().map(|p| p.y).fold(f64::NEG_INFINITY, f64::max).ceil().clamp(0.0, h as f64) as u32;
            for y in ys..ye {
                for x in xs..xe {
                    let i = (y * w + x) as usize;
                    let unknown = |s: &mut Vec<Option<u8>>, d: &mut Vec<DepthExp>| {
                        if face.is_some() {
                            s[i] = None;
                        }
                        if depth_write {
                            d[i] = DepthExp::Any;
                        }
                    };
                    // The triangle whose plane gives the depth: the fan triangle of a clipped
                    // polygon that contains the centre best (all lie in one plane).
                    let t = match poly {
                        None => t,
                        Some(p) => match p.cover_eps(x, y, clip_eps) {
                            Cover::Out => continue,
                            Cover::Edge => {
                                unknown(&mut s, &mut d);
                                qhi += 1;
                                continue;
                            }
                            Cover::In => fan_tri_at(&fan, x, y),
                        },
                    };
                    match if poly.is_some() { Cover::In } else { raster::cover_eps(t, x, y, eps) } {
                        Cover::Out => continue,
                        Cover::Edge => match shared_edge_owner(&wt, &polys, ti, x, y, eps) {
                            Some(true) => {}
                            Some(false) => continue,
                            None => {
                                unknown(&mut s, &mut d);
                                qhi += 1;
                                continue;
                            }
                        },
                        Cover::In => {}
                    }
                    let zf = match frag_depth(t, x, y, st, kind, subpixel_bits, poly.is_some()) {
                        Frag::Clipped => continue,
                        Frag::Maybe => {
                            unknown(&mut s, &mut d);
                            qhi += 1;
                            continue;
                        }
                        Frag::At(z) => z,
                    };
                    let f = Fragment { st, face, kind, depth_test, depth_write, op_of: &op_of };
                    let (lo, hi) = f.test(&mut s[i], &mut d[i], zf);
                    qlo += lo;
                    qhi += hi;
                }
            }
        }
        if draw.query {
            queries.push((qlo, qhi));
        }
    }
    if let Some(o) = &case.stencil_override {
        s = o.clone();
    }
    if !case.check_depth || kind == DepthKind::None {
        d = vec![DepthExp::Any; d.len()];
    }
    Expected { stencil: s, depth: d, queries }
}

/// One fragment's tests and writes, after coverage and its depth are known.
struct Fragment<'a> {
    st: &'a DsState,
    /// The stencil state of the face drawn (None: no stencil test).
    face: Option<vk::StencilOpState>,
    kind: DepthKind,
    depth_test: bool,
    depth_write: bool,
    /// The stencil op as the device applies it (the test seam's broken op).
    op_of: &'a dyn Fn(vk::StencilOp) -> vk::StencilOp,
}

impl Fragment<'_> {
    /// Depth bounds (on the stored depth), the stencil test, the depth test and the writes on
    /// the pixel's expected stencil `s` and depth `d` for a fragment of depth `zf`. Returns
    /// the occlusion query's (low, high) increments. What cannot be decided (a value near a
    /// bound, an unknown stored value, an undecidable compare) makes the pixel unknown.
    fn test(&self, s: &mut Option<u8>, d: &mut DepthExp, zf: DepthExp) -> (u64, u64) {
        let unknown = |s: &mut Option<u8>, d: &mut DepthExp| {
            if self.face.is_some() {
                *s = None;
            }
            if self.depth_write {
                *d = DepthExp::Any;
            }
            (0, 1)
        };
        if let (Some((bmin, bmax)), true) = (self.st.depth_bounds, self.kind != DepthKind::None) {
            let Some(za) = d.interval() else { return unknown(s, d) };
            let near = |b: f32| za.0 != za.1 || (za.0 != b as f64 && (za.0 - b as f64).abs() < 1e-6);
            if near(bmin) || near(bmax) {
                return unknown(s, d);
            }
            if za.0 < bmin as f64 || za.0 > bmax as f64 {
                return (0, 0);
            }
        }
        if let Some(fs) = self.face {
            let Some(sv) = *s else { return unknown(s, d) };
            let (r, cm, wm) = (fs.reference as u8, fs.compare_mask as u8, fs.write_mask as u8);
            if !stencil_test(fs.compare_op, r, sv, cm) {
                *s = Some(apply_op((self.op_of)(fs.fail_op), sv, r, wm));
                return (0, 0);
            }
        }
        let pass = if self.depth_test {
            match (zf.interval(), d.interval()) {
                (Some(a), Some(b)) => compare(self.st.depth_compare, a, b),
                _ => None,
            }
        } else {
            Some(true)
        };
        let Some(pass) = pass else { return unknown(s, d) };
        if let Some(fs) = self.face {
            let sv = s.unwrap_or(0);
            let op = if pass { fs.pass_op } else { fs.depth_fail_op };
            *s = Some(apply_op((self.op_of)(op), sv, fs.reference as u8, fs.write_mask as u8));
        }
        if !pass {
            return (0, 0);
        }
        if self.depth_write {
            *d = zf;
        }
        (1, 1)
    }
}

#[cfg(test)]
mod tests;
