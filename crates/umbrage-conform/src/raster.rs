//! CPU predictions of what the rasteriser must produce: clip -> window coordinates (the same
//! viewport transform as the GPU's), snapping to the device's sub-pixel grid, and the
//! pixel-centre coverage rule with an ambiguity band around every edge.

use glam::{DVec2, DVec4, Mat4};

/// Pixels whose centre is within this distance (in pixels) of an edge are not judged.
pub const EDGE_EPS: f64 = 1e-4;

/// A triangle in window coordinates (pixels, row 0 at the top) with its window depths.
#[derive(Clone, Copy, Debug)]
pub struct WinTri {
    /// Window positions, pixels, snapped to the sub-pixel grid.
    pub p: [DVec2; 3],
    /// Window depths: NDC z (the harness viewport's depth range is [0, 1], so unchanged).
    pub z: [f64; 3],
}

impl WinTri {
    /// Vulkan's signed area (`a = -1/2 sum(x_i y_{i+1} - x_{i+1} y_i)` in framebuffer
    /// coordinates): positive = counter-clockwise = front facing here.
    pub fn vk_area(&self) -> f64 {
        let mut s = 0.0;
        for i in 0..3 {
            let (a, b) = (self.p[i], self.p[(i + 1) % 3]);
            s += a.x * b.y - b.x * a.y;
        }
        -0.5 * s
    }
    /// Front facing under `VK_FRONT_FACE_COUNTER_CLOCKWISE` (positive [`WinTri::vk_area`]).
    pub fn front_facing(&self) -> bool {
        self.vk_area() > 0.0
    }
}

/// Coverage of one pixel centre by one triangle.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Cover {
    /// The pixel centre is strictly inside: the rasteriser must cover it.
    In,
    /// Strictly outside (or a degenerate triangle): it must not.
    Out,
    /// Within [`EDGE_EPS`] of an edge: the tie-breaking rule decides, not judged.
    Edge,
}

/// Clip-space vertex (f64 from the f32 matrix and vertex) -> window coordinates, snapped to
/// `1 / 2^subpixel_bits` of a pixel (round to nearest).
pub fn to_window(clip: DVec4, width: u32, height: u32, subpixel_bits: u32) -> (DVec2, f64) {
    let ndc = clip.truncate() / clip.w;
    let s = (1u64 << subpixel_bits) as f64;
    let snap = |v: f64| (v * s).round() / s;
    let x = (ndc.x + 1.0) * 0.5 * width as f64;
    let y = (ndc.y + 1.0) * 0.5 * height as f64;
    (DVec2::new(snap(x), snap(y)), ndc.z)
}

/// Transforms homogeneous object vertices with `mvp` (computed in f64 from the f32 values).
pub fn window_tris(mvp: Mat4, verts: &[[f32; 4]], tris: &[[u32; 3]], width: u32, height: u32, subpixel_bits: u32) -> Vec<WinTri> {
    let m = mvp.as_dmat4();
    let w: Vec<(DVec2, f64)> = verts
        .iter()
        .map(|v| to_window(m * DVec4::new(v[0] as f64, v[1] as f64, v[2] as f64, v[3] as f64), width, height, subpixel_bits))
        .collect();
    tris.iter().map(|t| WinTri { p: t.map(|i| w[i as usize].0), z: t.map(|i| w[i as usize].1) }).collect()
}

/// The clip volume's planes as `dot(plane, clip) >= 0`: `-w <= x <= w`, `-w <= y <= w`, then
/// `0 <= z <= w` (the last two dropped under depth clamp, which disables z clipping). Any
/// point inside satisfies `w >= 0`, so clipping against them removes whatever lies behind the eye.
const PLANES: [[f64; 4]; 6] =
    [[1.0, 0.0, 0.0, 1.0], [-1.0, 0.0, 0.0, 1.0], [0.0, 1.0, 0.0, 1.0], [0.0, -1.0, 0.0, 1.0], [0.0, 0.0, 1.0, 0.0], [0.0, 0.0, -1.0, 1.0]];

/// Sutherland-Hodgman clipping of a clip-space triangle (f64) against the view volume
/// (`PLANES`: the six clip planes; the z planes only without `depth_clamp`). The polygon keeps the triangle's
/// vertex order, so its window-space winding is the clipped primitive's facing. Empty when
/// nothing of the triangle is inside.
pub fn clip_polygon(tri: [DVec4; 3], depth_clamp: bool) -> Vec<DVec4> {
    let mut poly = tri.to_vec();
    let planes = if depth_clamp { &PLANES[..4] } else { &PLANES[..] };
    for pl in planes {
        let pl = DVec4::from_array(*pl);
        let mut out = Vec::with_capacity(poly.len() + 1);
        for i in 0..poly.len() {
            let (a, b) = (poly[i], poly[(i + 1) % poly.len()]);
            let (da, db) = (pl.dot(a), pl.dot(b));
            if da >= 0.0 {
                out.push(a);
            }
            if (da > 0.0 && db < 0.0) || (da < 0.0 && db > 0.0) {
                out.push(a + (b - a) * (da / (da - db)));
            }
        }
        poly = out;
        if poly.is_empty() {
            break;
        }
    }
    poly
}

/// A triangle with a vertex at `w <= 0`, clipped in homogeneous clip space ([`clip_polygon`])
/// and mapped to window coordinates: the convex polygon the rasteriser must fill. Dividing such
/// a triangle's vertices by `w` directly (what [`to_window`] alone does) gives the "external"
/// triangle, which is wrong.
#[derive(Clone, Debug)]
pub struct ClippedPoly {
    /// Window positions (snapped to the sub-pixel grid), in the original triangle's order.
    pub p: Vec<DVec2>,
    /// Window depths (NDC z) of the vertices.
    pub z: Vec<f64>,
    /// Some clipped vertex lies at `w <= 0` (only the clip volume's apex, x = y = z = w = 0):
    /// its projection is undefined.
    pub singular: bool,
}

impl ClippedPoly {
    /// Clips the clip-space triangle `tri` ([`clip_polygon`]) and maps the result to a `width`
    /// x `height` viewport, snapping to `subpixel_bits`.
    pub fn new(tri: [DVec4; 3], depth_clamp: bool, width: u32, height: u32, subpixel_bits: u32) -> ClippedPoly {
        let poly = clip_polygon(tri, depth_clamp);
        let singular = poly.iter().any(|c| c.w <= 0.0);
        let (p, z) =
            if singular { (Vec::new(), Vec::new()) } else { poly.iter().map(|&c| to_window(c, width, height, subpixel_bits)).unzip() };
        ClippedPoly { p, z, singular }
    }
    /// Vulkan's signed area of the polygon in framebuffer coordinates (see [`WinTri::vk_area`]);
    /// its sign is the primitive's facing. For a triangle crossing `w = 0` it is the sign of
    /// `det[x y w]` of the original clip-space vertices, not that of the naively divided
    /// triangle (the two differ when one or three vertices have `w < 0`).
    pub fn vk_area(&self) -> f64 {
        let n = self.p.len();
        let mut s = 0.0;
        for i in 0..n {
            let (a, b) = (self.p[i], self.p[(i + 1) % n]);
            s += a.x * b.y - b.x * a.y;
        }
        -0.5 * s
    }
    /// Front facing under `VK_FRONT_FACE_COUNTER_CLOCKWISE`.
    pub fn front_facing(&self) -> bool {
        self.vk_area() > 0.0
    }
    /// The fan triangles `(0, i, i + 1)` (for depth interpolation).
    pub fn fan(&self) -> Vec<WinTri> {
        (1..self.p.len().saturating_sub(1))
            .map(|i| WinTri { p: [self.p[0], self.p[i], self.p[i + 1]], z: [self.z[0], self.z[i], self.z[i + 1]] })
            .collect()
    }
    /// Coverage of the centre of pixel (x, y) by the (convex) polygon, with centres within
    /// `eps` pixels of any of its edges reported as [`Cover::Edge`]; the fan's inner diagonals
    /// are not edges (exactly one fan triangle covers a centre on one).
    pub fn cover_eps(&self, x: u32, y: u32, eps: f64) -> Cover {
        let area = self.vk_area();
        if area == 0.0 || self.p.len() < 3 {
            return Cover::Out;
        }
        cover_polygon(&self.p, area, x, y, eps)
    }
}

/// Whether triangle `t` covers the centre of pixel (x, y) by the pixel-centre rule, with
/// centres within [`EDGE_EPS`] of an edge reported as [`Cover::Edge`].
pub fn cover(t: &WinTri, x: u32, y: u32) -> Cover {
    cover_eps(t, x, y, EDGE_EPS)
}

/// [`cover`] with centres within `eps` pixels of an edge reported as [`Cover::Edge`] (a wider
/// band where the device's f32 vertex transform may snap a vertex to a neighbouring sub-pixel).
pub fn cover_eps(t: &WinTri, x: u32, y: u32, eps: f64) -> Cover {
    let area = t.vk_area();
    if area == 0.0 {
        return Cover::Out; // degenerate: never rasterised
    }
    cover_polygon(&t.p, area, x, y, eps)
}

/// Coverage of the centre of pixel (x, y) by the convex polygon `p` of Vulkan signed area
/// `area` (non-zero): out past any edge by more than `eps`, on an edge within `eps`, else in.
/// Zero-length edges (repeated clipped vertices) are skipped.
fn cover_polygon(p: &[DVec2], area: f64, x: u32, y: u32, eps: f64) -> Cover {
    let c = DVec2::new(x as f64 + 0.5, y as f64 + 0.5);
    let sign = if (-area) > 0.0 { 1.0 } else { -1.0 };
    let mut ambiguous = false;
    for i in 0..p.len() {
        let (a, b) = (p[i], p[(i + 1) % p.len()]);
        let e = b - a;
        let len = e.length();
        if len == 0.0 {
            continue;
        }
        let d = sign * (e.x * (c.y - a.y) - e.y * (c.x - a.x)) / len;
        if d < -eps {
            return Cover::Out;
        }
        if d <= eps {
            ambiguous = true;
        }
    }
    if ambiguous {
        Cover::Edge
    } else {
        Cover::In
    }
}

/// Expected stencil count per pixel when each triangle adds `delta(tri)` (mod 256), and
/// whether the pixel is judged (no triangle has an edge through its centre).
pub fn expected_counts(tris: &[WinTri], delta: impl Fn(&WinTri) -> i64, width: u32, height: u32) -> (Vec<u8>, Vec<bool>) {
    let n = (width * height) as usize;
    let mut count = vec![0i64; n];
    let mut judged = vec![true; n];
    for t in tris {
        let d = delta(t);
        let xs = t.p.iter().map(|p| p.x).fold(f64::INFINITY, f64::min).floor().max(0.0) as u32;
        let xe = (t.p.iter().map(|p| p.x).fold(f64::NEG_INFINITY, f64::max).ceil().max(0.0) as u32).min(width);
        let ys = t.p.iter().map(|p| p.y).fold(f64::INFINITY, f64::min).floor().max(0.0) as u32;
        let ye = (t.p.iter().map(|p| p.y).fold(f64::NEG_INFINITY, f64::max).ceil().max(0.0) as u32).min(height);
        for y in ys..ye {
            for x in xs..xe {
                let i = (y * width + x) as usize;
                match cover(t, x, y) {
                    Cover::In => count[i] += d,
                    Cover::Edge => judged[i] = false,
                    Cover::Out => {}
                }
            }
        }
    }
    (count.into_iter().map(|c| c.rem_euclid(256) as u8).collect(), judged)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tri(p: [[f64; 2]; 3]) -> WinTri {
        WinTri { p: p.map(|q| DVec2::new(q[0], q[1])), z: [0.5; 3] }
    }

    #[test]
    fn facing_follows_vulkan_area_sign() {
        // Visually counter-clockwise on screen (y down) is front facing.
        assert!(tri([[0.0, 0.0], [0.0, 4.0], [4.0, 4.0]]).front_facing());
        assert!(!tri([[0.0, 0.0], [4.0, 4.0], [0.0, 4.0]]).front_facing());
    }

    #[test]
    fn pixel_centres_and_edges() {
        let t = tri([[0.0, 0.0], [0.0, 4.0], [4.0, 4.0]]);
        assert_eq!(cover(&t, 0, 3), Cover::In);
        assert_eq!(cover(&t, 3, 0), Cover::Out);
        assert_eq!(cover(&t, 1, 1), Cover::Edge); // centre (1.5, 1.5) on the diagonal
        let (c, judged) = expected_counts(&[t, t], |_| 1, 4, 4);
        assert_eq!(c[3 * 4], 2);
        assert!(!judged[4 + 1]);
    }

    #[test]
    fn w0_vertex_lands_on_depth_one() {
        let cam = umbrage_scene::Camera::default();
        let m = cam.proj_infinite(1.5) * cam.view();
        let (_, z) = to_window(m.as_dmat4() * DVec4::new(0.3, -0.2, -1.0, 0.0), 160, 120, 8);
        assert!((z - 1.0).abs() < 1e-12);
    }
}
