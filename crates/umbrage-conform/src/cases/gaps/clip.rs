//! Homogeneous clipping: triangles with vertices behind the eye (clip-space `w < 0`), exactly
//! at `w = 0`, and crossing the near and far planes, with and without depth clamp, and
//! shadow-volume geometry through an infinite projection extruded behind the eye.
//!
//! Dividing a triangle with a vertex at `w < 0` by `w` gives the "external" triangle: the
//! wrong pixels, and for one or three vertices behind, the wrong facing. The rasteriser must
//! draw the triangle clipped to the view volume (`-w <= x, y <= w`, and `0 <= z <= w` unless
//! depth clamp is on), whose facing is the sign of `det[x y w]` of the original vertices. The
//! model clips the same way (`raster::clip_polygon`); pixels within 1.5 sub-pixel steps of an
//! edge of the clipped polygon are not judged.
//!
//! Each case draws with front INCR_WRAP / back DECR_WRAP over a stencil of 0x80 (so coverage
//! and facing are both exact: 0x81 front, 0x7f back) and depth writes (compare ALWAYS), and
//! runs with depth clamp off and on.

use super::{stencil_only, two_sided};
use crate::cases::{Case, Config, Draw, DsState, Req};
use crate::raster::ClippedPoly;
use ash::vk;
use glam::camera::rh::proj::vulkan as proj;
use glam::{DVec4, Mat4};

const SIZE: (u32, u32) = (32, 32);
const FOV: f32 = std::f32::consts::FRAC_PI_2;

/// One geometry: a name, what it shows, the transform and the vertices (one draw).
struct Geometry {
    name: &'static str,
    what: &'static str,
    mvp: Mat4,
    verts: Vec<[f32; 4]>,
}

/// The facing of triangle `k` of `g` after clipping: "front", "back" or "nothing drawn".
fn facing(g: &Geometry, k: usize, clamp: bool) -> &'static str {
    let m = g.mvp.as_dmat4();
    let c = |i: usize| {
        let v = g.verts[3 * k + i];
        m * DVec4::new(v[0] as f64, v[1] as f64, v[2] as f64, v[3] as f64)
    };
    let p = ClippedPoly::new([c(0), c(1), c(2)], clamp, SIZE.0, SIZE.1, 8);
    if p.p.len() < 3 || p.vk_area() == 0.0 {
        "nothing drawn"
    } else if p.front_facing() {
        "front"
    } else {
        "back"
    }
}

fn geometries() -> Vec<Geometry> {
    let persp = proj::perspective(FOV, 1.0, 0.5, 10.0);
    let short = proj::perspective(FOV, 1.0, 0.5, 2.0);
    let infinite = proj::perspective_infinite(FOV, 1.0, 0.1);
    let id = Mat4::IDENTITY;
    // A floor 0.3 below the eye (perspective, near 0.5): the near plane cuts it at 80% of the
    // tile's height, the eye plane (w = 0) off the tile.
    let (a, b, c) = ([-1.5, -0.3, -3.0, 1.0], [1.5, -0.3, -3.0, 1.0], [0.4, -0.3, 1.5, 1.0]);
    // Side quad of a shadow volume whose light (0, 0, -6) is beyond the occluder: the edge
    // P0 P1 extruded away from the light runs behind the eye, so the (xyz, 0) vertices have
    // clip-space w < 0 (4 and 3.5 behind).
    let (p0, p1) = ([-0.5, -0.4, -2.0, 1.0], [0.6, -0.3, -2.5, 1.0]);
    let (d0, d1) = ([-0.5, -0.4, 4.0, 0.0], [0.6, -0.3, 3.5, 0.0]);
    vec![
        Geometry {
            name: "behind_eye.one_vertex.winding_abc",
            what: "a floor triangle with one vertex behind the eye (w < 0): the naive divide draws the external triangle above the horizon with the opposite facing",
            mvp: persp,
            verts: vec![a, b, c],
        },
        Geometry {
            name: "behind_eye.one_vertex.winding_acb",
            what: "the same triangle wound the other way",
            mvp: persp,
            verts: vec![a, c, b],
        },
        Geometry {
            name: "behind_eye.two_vertices",
            what: "a floor triangle with two vertices behind the eye: only the tip in front is drawn",
            mvp: persp,
            verts: vec![[0.3, -0.3, -4.0, 1.0], [-2.5, -0.3, 1.0, 1.0], [2.0, -0.3, 1.5, 1.0]],
        },
        Geometry {
            name: "behind_eye.all_vertices",
            what: "a triangle entirely behind the eye (w < 0 at every vertex; the naive divide draws it mirrored)",
            mvp: persp,
            verts: vec![[-1.0, -0.3, 1.0, 1.0], [0.0, 0.5, 2.0, 1.0], [1.0, -0.3, 1.0, 1.0]],
        },
        Geometry {
            name: "behind_eye.near_and_far",
            what: "a floor triangle from beyond the far plane (2) to behind the eye: cut at both planes, or clamped to 1.0 and 0.0",
            mvp: short,
            verts: vec![[-40.0, -0.3, -30.0, 1.0], [0.0, -0.3, 2.0, 1.0], [40.0, -0.3, -30.0, 1.0]],
        },
        Geometry {
            name: "w0.at_vertex",
            what: "clip space, one vertex at w = 0 (a point at infinity), one at w = 1, one at w < 0, in the plane z = w / 2: a wedge at depth 0.5",
            mvp: id,
            verts: vec![[-0.5, -0.4, 0.5, 1.0], [0.6, 0.3, 0.0, 0.0], [0.2, 0.8, -0.25, -0.5]],
        },
        Geometry {
            name: "w0.wedge",
            what: "clip space, two vertices at w = 0 and one at w = 0.5, in the plane z = w / 2: an infinite wedge at depth 0.5",
            mvp: id,
            verts: vec![[-0.2, 0.1, 0.25, 0.5], [0.9, 0.3, 0.0, 0.0], [0.2, 0.95, 0.0, 0.0]],
        },
        Geometry {
            name: "w0.with_behind",
            what: "clip space, two vertices at w = 0 and one at w < 0: nothing in front of the eye, nothing drawn",
            mvp: id,
            verts: vec![[0.5, 0.2, 0.0, 0.0], [-0.6, 0.4, 0.0, 0.0], [0.1, -0.3, -0.25, -0.5]],
        },
        Geometry {
            name: "infinite.side_quad_behind_eye",
            what: "a shadow-volume side quad through the infinite projection, its (xyz, 0) vertices extruded behind the eye (w < 0): drawn away from, not towards, their vanishing points",
            mvp: infinite,
            verts: vec![p0, p1, d1, p0, d1, d0],
        },
        Geometry {
            name: "infinite.dark_cap_behind_eye",
            what: "a dark cap at infinity behind the eye through the infinite projection (every vertex (xyz, 0) with w < 0): nothing drawn (the naive divide draws it)",
            mvp: infinite,
            verts: vec![[-0.3, -0.2, 1.0, 0.0], [0.3, -0.25, 1.0, 0.0], [0.05, 0.35, 1.0, 0.0]],
        },
    ]
}

/// The clipping cases of `config`.
pub fn cases(config: Config) -> Vec<Case> {
    let mut v = Vec::new();
    for g in geometries() {
        for clamp in [false, true] {
            let rest = format!("{}.clamp_{}", g.name, if clamp { "on" } else { "off" });
            let mut c = Case::new(config, "clip", &rest, SIZE, 1.0, 0x80);
            if clamp {
                c.requires.push(Req::DepthClamp);
            }
            let facings: Vec<&str> = (0..g.verts.len() / 3).map(|k| facing(&g, k, clamp)).collect();
            c.what = format!(
                "{}; depth clamp {}; front INCR_WRAP / back DECR_WRAP from 0x80 and depth written: {}",
                g.what,
                if clamp { "on" } else { "off" },
                facings.join(", ")
            );
            let state = DsState {
                depth_test: true,
                depth_write: true,
                depth_compare: vk::CompareOp::ALWAYS,
                depth_clamp: clamp,
                ..stencil_only(two_sided())
            };
            c.draws.push(Draw { state, mvp: g.mvp, vertices: g.verts.clone(), query: false });
            v.push(c);
        }
    }
    v
}
