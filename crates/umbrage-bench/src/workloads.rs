//! The limit sweeps' workloads as plain geometry (clip-space vertices, `[x, y, z, w]`): each
//! isolates one cost of the pipeline ([`super::limits`] says which and why).

use std::collections::BTreeMap;

/// One pixel in NDC for a `w` x `h` target.
pub(super) fn pixel_ndc(w: u32, h: u32) -> (f32, f32) {
    (2.0 / w as f32, 2.0 / h as f32)
}

/// One tiny triangle per 2x2-pixel block, inside the corner of a pixel, away from its sample
/// centre (x+0.6 .. x+0.9): set up, never rasterised.
pub(super) fn setup_triangles(w: u32, h: u32) -> Vec<[f32; 4]> {
    let (pw, ph) = pixel_ndc(w, h);
    let mut setup: Vec<[f32; 4]> = Vec::new();
    for y in (0..h).step_by(2) {
        for x in (0..w).step_by(2) {
            let (x0, y0) = (-1.0 + (x as f32 + 0.6) * pw, -1.0 + (y as f32 + 0.6) * ph);
            setup.extend([[x0, y0, 0.5, 1.0], [x0 + 0.3 * pw, y0, 0.5, 1.0], [x0, y0 + 0.3 * ph, 0.5, 1.0]]);
        }
    }
    setup
}

/// `n` clipped triangles: A behind the near plane, B in front, C at w = 0 towards +x: the strip
/// between two lines inside one pixel row (y+0.6 .. y+0.9), from 4 pixels left of the right
/// edge to infinity, cut by the near plane and the right clip plane: short on screen (one
/// tile, like a clipped side's corner), no sample centre in it.
pub(super) fn clipped_triangles(w: u32, h: u32, n: usize) -> Vec<[f32; 4]> {
    let (pw, ph) = pixel_ndc(w, h);
    let mut clip: Vec<[f32; 4]> = Vec::with_capacity(3 * n);
    let x = 1.0 - 4.0 * pw;
    for i in 0..n {
        let row = (i as u32 * 7) % h;
        let (y1, y2) = (-1.0 + (row as f32 + 0.6) * ph, -1.0 + (row as f32 + 0.9) * ph);
        clip.extend([[x, y1, -0.5, 1.0], [x, y2, 0.5, 1.0], [1.0, 0.0, 0.0, 0.0]]);
    }
    clip
}

/// A grid of 2x2-pixel cells over the target, each two 2-pixel triangles.
pub(super) fn small_triangles(w: u32, h: u32) -> Vec<[f32; 4]> {
    let (pw, ph) = pixel_ndc(w, h);
    let mut small: Vec<[f32; 4]> = Vec::new();
    for y in (0..h.saturating_sub(1)).step_by(2) {
        for x in (0..w.saturating_sub(1)).step_by(2) {
            let (x0, y0) = (-1.0 + x as f32 * pw, -1.0 + y as f32 * ph);
            let (a, b, c, d) = (
                [x0, y0, 0.5, 1.0],
                [x0 + 2.0 * pw, y0, 0.5, 1.0],
                [x0 + 2.0 * pw, y0 + 2.0 * ph, 0.5, 1.0],
                [x0, y0 + 2.0 * ph, 0.5, 1.0],
            );
            small.extend([a, b, c, a, c, d]);
        }
    }
    small
}

/// Four triangles, each covering the target (twice its size, clipped), alternate windings.
pub(super) fn big_triangles() -> Vec<[f32; 4]> {
    (0..4)
        .flat_map(|i| {
            let (a, b, c) = ([-1.0, -1.0, 0.5, 1.0], [3.0, -1.0, 0.5, 1.0], [-1.0, 3.0, 0.5, 1.0]);
            if i % 2 == 0 {
                [a, b, c]
            } else {
                [a, c, b]
            }
        })
        .collect()
}

/// A fan of `n` 1-pixel-wide triangles from the centre out past the edges.
pub(super) fn sliver_fan(n: u32, (pw, ph): (f32, f32)) -> Vec<[f32; 4]> {
    let mut sliver: Vec<[f32; 4]> = Vec::new();
    for i in 0..n {
        let a = std::f32::consts::TAU * i as f32 / n as f32;
        let (s, c) = a.sin_cos();
        let (ex, ey) = (1.5 * c, 1.5 * s);
        let (qx, qy) = (-s * pw, c * ph); // one pixel across at the far end
        sliver.extend([[0.0, 0.0, 0.5, 1.0], [ex, ey, 0.5, 1.0], [ex + qx, ey + qy, 0.5, 1.0]]);
    }
    sliver
}

/// Each limit's unit, for the report.
pub(super) fn limit_units() -> BTreeMap<String, String> {
    let mut units = BTreeMap::new();
    for (k, u) in [
        ("stencil_fill_gfrag_s", "Gfragments/s"),
        ("color_fill_gfrag_s", "Gfragments/s"),
        ("setup_tri_mtri_s", "Mtriangles/s"),
        ("clip_tri_mtri_s", "Mtriangles/s"),
        ("small_tri_mtri_s", "Mtriangles/s"),
        ("big_tri_mtri_s", "Mtriangles/s"),
        ("sliver_tri_mtri_s", "Mtriangles/s"),
        ("draws_per_s", "draws/s"),
        ("cpu_stream_gib_s", "GiB/s"),
        ("compute_read_gib_s", "GiB/s"),
        ("lighting_gpix_s", "Gpixels/s"),
        ("lighting_one_draw_gpix_s", "Gpixels/s"),
        ("lighting_shaded_gpix_s", "Gpixels/s"),
        ("lighting_shaded_one_draw_gpix_s", "Gpixels/s"),
        ("lighting_instance_ms", "ms"),
        ("gbuffer_tri_mtri_s", "Mtriangles/s"),
        ("gbuffer_fill_gpix_s", "Gpixels/s"),
        ("index_u8_mtri_s", "Mtriangles/s"),
        ("index_u16_mtri_s", "Mtriangles/s"),
        ("index_u32_mtri_s", "Mtriangles/s"),
        ("index_naive_mtri_s", "Mtriangles/s"),
    ] {
        units.insert(k.to_string(), u.to_string());
    }
    units
}
