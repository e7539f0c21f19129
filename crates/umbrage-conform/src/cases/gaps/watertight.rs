//! Watertightness beyond two-triangle quads: closed convex meshes (icospheres, ellipsoids)
//! drawn with both faces INCR_WRAP — every pixel centre inside the silhouette is covered by
//! exactly one front and one back triangle, so it counts exactly 2 — or front INCR_WRAP /
//! back DECR_WRAP (exactly 0 everywhere, the shadow-volume invariant for a closed caster),
//! and fans and jittered grids split across separate draws in shuffled order. Object
//! coordinates are scaled up to 1e7 and the transform scales them back, so the f32 vertex
//! transform rounds; shared vertices are bit-identical inputs, so shared edges stay shared.
//!
//! The expectation is given directly ([`Case::stencil_override`]): what the spec guarantees
//! ("exactly one of two polygons sharing an edge covers a sample on it") whatever the driver's
//! tie-breaking rule. Pixel centres within [`BAND`] of the outer outline or of any vertex are
//! not judged (the spec says nothing about a sample exactly on a vertex).

use super::{incr_both, stencil_only, two_sided, Rng};
use crate::cases::{pixel_ortho, Case, Config, Draw, DsState};
use glam::camera::rh::proj::vulkan as proj;
use glam::{DVec2, DVec3, DVec4, Mat4, Quat, Vec3};

const SIZE: (u32, u32) = (32, 32);

/// Object coordinates are multiplied by this (and the transform divides it out).
pub(super) const SCALE: f64 = 1e7;

/// The band (pixels) around the outline and the vertices within which nothing is judged: 1.5
/// sub-pixel steps at the coarsest precision Vulkan allows (`subPixelPrecisionBits` = 4; the
/// expectation is fixed before the device is known).
pub(super) const BAND: f64 = 1.5 / 16.0;

/// An icosahedron subdivided `n` times onto the unit sphere: vertices and triangles, wound
/// consistently (counter-clockwise seen from outside).
pub(super) fn icosphere(n: u32) -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let t = (1.0 + 5f64.sqrt()) / 2.0;
    let mut v: Vec<DVec3> = [
        [-1.0, t, 0.0],
        [1.0, t, 0.0],
        [-1.0, -t, 0.0],
        [1.0, -t, 0.0],
        [0.0, -1.0, t],
        [0.0, 1.0, t],
        [0.0, -1.0, -t],
        [0.0, 1.0, -t],
        [t, 0.0, -1.0],
        [t, 0.0, 1.0],
        [-t, 0.0, -1.0],
        [-t, 0.0, 1.0],
    ]
    .iter()
    .map(|p| DVec3::from_array(*p).normalize())
    .collect();
    let mut f: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..n {
        let mut mid = std::collections::HashMap::new();
        let mut midpoint = |a: u32, b: u32, v: &mut Vec<DVec3>| {
            *mid.entry((a.min(b), a.max(b))).or_insert_with(|| {
                v.push(((v[a as usize] + v[b as usize]) * 0.5).normalize());
                v.len() as u32 - 1
            })
        };
        let mut g = Vec::with_capacity(f.len() * 4);
        for &[a, b, c] in &f {
            let (ab, bc, ca) = (midpoint(a, b, &mut v), midpoint(b, c, &mut v), midpoint(c, a, &mut v));
            g.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        f = g;
    }
    (v, f)
}

/// A seeded random rotation.
fn rotation(rng: &mut Rng) -> Quat {
    loop {
        let q = [rng.range(-1.0, 1.0), rng.range(-1.0, 1.0), rng.range(-1.0, 1.0), rng.range(-1.0, 1.0)];
        let n = q.iter().map(|x| x * x).sum::<f64>().sqrt();
        if n > 0.1 && n <= 1.0 {
            return Quat::from_xyzw(q[0] as f32, q[1] as f32, q[2] as f32, q[3] as f32).normalize();
        }
    }
}

/// Object point (f32, as drawn) -> window position under `mvp` for the tile, unsnapped (f64
/// from the f32 values, as the model computes).
pub(super) fn window(mvp: Mat4, v: [f32; 4]) -> DVec2 {
    let c = mvp.as_dmat4() * DVec4::new(v[0] as f64, v[1] as f64, v[2] as f64, v[3] as f64);
    DVec2::new((c.x / c.w + 1.0) * 0.5 * SIZE.0 as f64, (c.y / c.w + 1.0) * 0.5 * SIZE.1 as f64)
}

/// Convex hull (counter-clockwise in x-right, y-up terms; orientation does not matter here).
pub(super) fn hull(mut p: Vec<DVec2>) -> Vec<DVec2> {
    p.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
    p.dedup();
    if p.len() < 3 {
        return p;
    }
    let cross = |o: DVec2, a: DVec2, b: DVec2| (a - o).perp_dot(b - o);
    let mut h: Vec<DVec2> = Vec::new();
    for pass in 0..2 {
        let start = h.len();
        let it: Box<dyn Iterator<Item = &DVec2>> = if pass == 0 { Box::new(p.iter()) } else { Box::new(p.iter().rev()) };
        for &q in it {
            while h.len() >= start + 2 && cross(h[h.len() - 2], h[h.len() - 1], q) <= 0.0 {
                h.pop();
            }
            h.push(q);
        }
        h.pop();
    }
    h
}

fn seg_dist(c: DVec2, a: DVec2, b: DVec2) -> f64 {
    let e = b - a;
    let t = if e.length_squared() == 0.0 { 0.0 } else { ((c - a).dot(e) / e.length_squared()).clamp(0.0, 1.0) };
    (a + e * t - c).length()
}

/// The guaranteed stencil of every pixel: `inside` for centres inside the simple polygon
/// `outline`, `outside` elsewhere, `None` within [`BAND`] of the outline or of any of `verts`.
pub(super) fn outline_override(outline: &[DVec2], verts: &[DVec2], inside: u8, outside: u8) -> Vec<Option<u8>> {
    let mut out = Vec::with_capacity((SIZE.0 * SIZE.1) as usize);
    let n = outline.len();
    for y in 0..SIZE.1 {
        for x in 0..SIZE.0 {
            let c = DVec2::new(x as f64 + 0.5, y as f64 + 0.5);
            let near_edge = (0..n).any(|i| seg_dist(c, outline[i], outline[(i + 1) % n]) <= BAND);
            let near_vertex = verts.iter().any(|v| (*v - c).length() <= BAND);
            if near_edge || near_vertex {
                out.push(None);
                continue;
            }
            // Even-odd crossings of the ray to +x.
            let mut odd = false;
            for i in 0..n {
                let (a, b) = (outline[i], outline[(i + 1) % n]);
                if (a.y > c.y) != (b.y > c.y) && c.x < a.x + (c.y - a.y) / (b.y - a.y) * (b.x - a.x) {
                    odd = !odd;
                }
            }
            out.push(Some(if odd { inside } else { outside }));
        }
    }
    out
}

/// How the triangles are split into draws.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Split {
    /// One draw.
    One,
    /// Every triangle its own draw, in shuffled order.
    Each,
    /// Groups of this many triangles (of a shuffled order) per draw, groups in shuffled order.
    Groups(usize),
}

impl Split {
    fn name(self) -> String {
        match self {
            Split::One => "one_draw".into(),
            Split::Each => "separate_draws".into(),
            Split::Groups(k) => format!("draws_of_{k}"),
        }
    }
    fn what(self) -> String {
        match self {
            Split::One => "in one draw".into(),
            Split::Each => "each triangle its own draw, in shuffled order".into(),
            Split::Groups(k) => format!("in draws of {k} triangles, shuffled"),
        }
    }
}

/// Splits the triangles `tris` (three vertices each) into draws as `split` says.
fn draws(tris: Vec<[[f32; 4]; 3]>, split: Split, state: DsState, mvp: Mat4, rng: &mut Rng) -> Vec<Draw> {
    let mk = |t: &[[[f32; 4]; 3]]| Draw { state, mvp, vertices: t.iter().flatten().copied().collect(), query: false };
    match split {
        Split::One => vec![mk(&tris)],
        Split::Each | Split::Groups(_) => {
            let k = if let Split::Groups(k) = split { k } else { 1 };
            let mut t = tris;
            rng.shuffle(&mut t);
            let mut d: Vec<Draw> = t.chunks(k).map(mk).collect();
            rng.shuffle(&mut d);
            d
        }
    }
}

/// The counting modes: both faces INCR_WRAP (2 inside a closed mesh) or front INCR_WRAP /
/// back DECR_WRAP (0).
#[derive(Clone, Copy, PartialEq, Eq)]
enum Count {
    IncrIncr,
    IncrDecr,
}

/// A closed convex mesh: the icosphere subdivided `subdiv` times under `mvp` (which divides
/// out [`SCALE`]: object vertices are the unit sphere times 1e7).
struct Mesh {
    name: &'static str,
    what: &'static str,
    subdiv: u32,
    mvp: Mat4,
}

/// A closed-mesh case: `mesh` counted as `count`, split into draws as `split` (shuffled with `seed`).
fn mesh_case(config: Config, mesh: Mesh, count: Count, split: Split, seed: u64) -> Case {
    let Mesh { name, what, subdiv, mvp } = mesh;
    let (count_name, state, inside) = match count {
        Count::IncrIncr => ("incr_incr", stencil_only(incr_both()), 2u8),
        Count::IncrDecr => ("incr_decr", stencil_only(two_sided()), 0u8),
    };
    let mut c = Case::new(config, "watertight", &format!("{name}.subdiv_{subdiv}.{}.{count_name}", split.name()), SIZE, 1.0, 0);
    let (v, f) = icosphere(subdiv);
    let verts: Vec<[f32; 4]> = v.iter().map(|p| [(p.x * SCALE) as f32, (p.y * SCALE) as f32, (p.z * SCALE) as f32, 1.0]).collect();
    let tris: Vec<[[f32; 4]; 3]> = f.iter().map(|t| t.map(|i| verts[i as usize])).collect();
    c.draws = draws(tris, split, state, mvp, &mut Rng::new(seed));
    let win: Vec<DVec2> = verts.iter().map(|&p| window(mvp, p)).collect();
    c.stencil_override = Some(outline_override(&hull(win.clone()), &win, inside, 0));
    c.check_depth = false;
    c.what = format!(
        "{what}, {} triangles at object coordinates up to 1e7, {}; {}: every centre inside the silhouette exactly {inside}",
        f.len(),
        split.what(),
        if count == Count::IncrIncr { "both faces INCR_WRAP" } else { "front INCR_WRAP / back DECR_WRAP" }
    );
    c
}

fn unscale() -> Mat4 {
    Mat4::from_scale(Vec3::splat((1.0 / SCALE) as f32))
}

/// A fan of `n` triangles around an off-centre point, its ring at random radii (a star-shaped
/// outline), every triangle its own draw in shuffled order; `mixed`: random windings.
fn fan_case(config: Config, n: usize, mixed: bool, seed: u64) -> Case {
    let rest = format!("fan_{n}.separate_draws{}", if mixed { ".mixed_winding" } else { "" });
    let mut c = Case::new(config, "watertight", &rest, SIZE, 1.0, 0);
    let mut rng = Rng::new(seed);
    let (cx, cy) = (15.37, 16.71);
    let s = SCALE as f32;
    let obj = |x: f64, y: f64| [(x as f32) * s, (y as f32) * s, 0.5, 1.0];
    let ring: Vec<[f32; 4]> = (0..n)
        .map(|k| {
            let a = (k as f64 + rng.range(0.0, 0.8)) / n as f64 * std::f64::consts::TAU;
            let r = rng.range(9.0, 14.5);
            obj(cx + r * a.cos(), cy + r * a.sin())
        })
        .collect();
    let centre = obj(cx, cy);
    let tris: Vec<[[f32; 4]; 3]> = (0..n)
        .map(|k| {
            let (p, q) = (ring[k], ring[(k + 1) % n]);
            if mixed && rng.below(2) == 1 {
                [centre, q, p]
            } else {
                [centre, p, q]
            }
        })
        .collect();
    let mvp = pixel_ortho(SIZE.0, SIZE.1) * Mat4::from_scale(Vec3::new(1.0 / s, 1.0 / s, 1.0));
    c.draws = draws(tris, Split::Each, stencil_only(incr_both()), mvp, &mut rng);
    let outline: Vec<DVec2> = ring.iter().map(|&p| window(mvp, p)).collect();
    let mut verts = outline.clone();
    verts.push(window(mvp, centre));
    c.stencil_override = Some(outline_override(&outline, &verts, 1, 0));
    c.check_depth = false;
    c.what = format!(
        "a {n}-triangle fan with a star-shaped outline at object coordinates of 1e7, each triangle its own draw in shuffled order{}, both faces INCR_WRAP: every centre inside exactly 1",
        if mixed { ", windings random" } else { "" }
    );
    c
}

/// A jittered 8 x 8 grid of quads (two triangles each, diagonals alternating), each row its
/// own draw in shuffled order, at object coordinates of 1e7.
fn grid_case(config: Config, seed: u64) -> Case {
    let mut c = Case::new(config, "watertight", "jittered_grid.row_draws", SIZE, 1.0, 0);
    let mut rng = Rng::new(seed);
    let n = 8usize;
    let cell = 28.0 / n as f64;
    let s = SCALE as f32;
    let p: Vec<Vec<[f32; 4]>> = (0..=n)
        .map(|j| {
            (0..=n)
                .map(|i| {
                    let x = 2.0 + i as f64 * cell + rng.range(-0.3, 0.3) * cell;
                    let y = 2.0 + j as f64 * cell + rng.range(-0.3, 0.3) * cell;
                    [(x as f32) * s, (y as f32) * s, 0.5, 1.0]
                })
                .collect()
        })
        .collect();
    let mvp = pixel_ortho(SIZE.0, SIZE.1) * Mat4::from_scale(Vec3::new(1.0 / s, 1.0 / s, 1.0));
    let state = stencil_only(incr_both());
    let mut rows: Vec<Draw> = (0..n)
        .map(|j| {
            let mut v = Vec::new();
            for i in 0..n {
                let (a, b, cc, d) = (p[j][i], p[j][i + 1], p[j + 1][i + 1], p[j + 1][i]);
                if (i + j) % 2 == 0 {
                    v.extend([a, d, cc, a, cc, b]);
                } else {
                    v.extend([a, d, b, b, d, cc]);
                }
            }
            Draw { state, mvp, vertices: v, query: false }
        })
        .collect();
    rng.shuffle(&mut rows);
    c.draws = rows;
    let mut outline = Vec::new();
    outline.extend((0..n).map(|i| p[0][i]));
    outline.extend((0..n).map(|j| p[j][n]));
    outline.extend((0..n).map(|i| p[n][n - i]));
    outline.extend((0..n).map(|j| p[n - j][0]));
    let outline: Vec<DVec2> = outline.into_iter().map(|q| window(mvp, q)).collect();
    let verts: Vec<DVec2> = p.iter().flatten().map(|&q| window(mvp, q)).collect();
    c.stencil_override = Some(outline_override(&outline, &verts, 1, 0));
    c.check_depth = false;
    c.what = "a jittered 8 x 8 grid of quads (128 triangles, valence-6 vertices) at object coordinates of 1e7, each row its own draw in shuffled order, both faces INCR_WRAP: every centre inside exactly 1".into();
    c
}

/// A strip of `n` quads from a near edge inside the tile (y about 1.5) to a far edge 60 pixels
/// down (outside it, so the bottom plane clips every triangle), 20 pixels wide at the top and
/// 3 at the bottom: each quad's diagonal leaves a sliver narrower than 1/16 pixel across the
/// tile, the shape of a shadow volume's sides running to their vanishing points (drivers notes
/// §1e: SwiftShader walks the clipped polygon's edges in the winding of the unclipped,
/// separately snapped triangle, and drops it where the two disagree). One draw, front
/// INCR_WRAP / back DECR_WRAP: every centre inside the strip exactly 1, however the slivers
/// snap, as long as each polygon's coverage and facing come from the same polygon.
fn sliver_strip_case(config: Config, n: usize, seed: u64) -> Case {
    let mut c = Case::new(config, "watertight", &format!("clipped_sliver_strip_{n}.incr_decr"), SIZE, 1.0, 0);
    let mut rng = Rng::new(seed);
    let near: Vec<[f32; 4]> = (0..=n)
        .map(|i| [(6.0 + 20.0 * (i as f64 + 0.5 * rng.range(0.0, 1.0)) / n as f64) as f32, rng.range(1.3, 1.7) as f32, 0.5, 1.0])
        .collect();
    let far: Vec<[f32; 4]> = (0..=n)
        .map(|i| [(-3.0 + 3.0 * (i as f64 + 0.5 * rng.range(0.0, 1.0)) / n as f64) as f32, rng.range(60.0, 60.3) as f32, 0.5, 1.0])
        .collect();
    let mut verts = Vec::with_capacity(6 * n);
    for i in 0..n {
        verts.extend([near[i], far[i + 1], near[i + 1], near[i], far[i], far[i + 1]]);
    }
    let mvp = pixel_ortho(SIZE.0, SIZE.1);
    c.draws = vec![Draw { state: stencil_only(two_sided()), mvp, vertices: verts, query: false }];
    let mut outline: Vec<DVec2> = near.iter().map(|&p| window(mvp, p)).collect();
    outline.extend(far.iter().rev().map(|&p| window(mvp, p)));
    c.stencil_override = Some(outline_override(&outline, &outline, 1, 0));
    c.check_depth = false;
    c.what = format!(
        "a strip of {n} quads (two triangles each) from inside the tile to 60 pixels below it, every triangle clipped by the bottom plane, \
         the diagonals leaving slivers under 1/16 pixel wide across the tile; one draw, front INCR_WRAP / back DECR_WRAP: every centre inside exactly 1"
    );
    c
}

/// The watertightness cases of `config`. The geometry and its expectation do not depend on the
/// configuration, so they are built once (the first call) and stamped with each configuration.
pub fn cases(config: Config) -> Vec<Case> {
    static TEMPLATES: std::sync::OnceLock<(Config, Vec<Case>)> = std::sync::OnceLock::new();
    let (first, templates) = TEMPLATES.get_or_init(|| (config, build(config)));
    let prefix = format!("watertight.{}.", first.name());
    templates
        .iter()
        .map(|t| {
            let rest = t.name.strip_prefix(&prefix).expect("a template's name starts with its configuration");
            Case { name: format!("watertight.{}.{rest}", config.name()), config, ..t.clone() }
        })
        .collect()
}

fn build(config: Config) -> Vec<Case> {
    let mut v = Vec::new();
    let ortho = |rng: &mut Rng, r: (f32, f32)| {
        pixel_ortho(SIZE.0, SIZE.1)
            * Mat4::from_translation(Vec3::new(16.3, 15.8, 0.5))
            * Mat4::from_rotation_z(rng.range(0.0, std::f64::consts::TAU) as f32)
            * Mat4::from_scale(Vec3::new(r.0, r.1, 0.4))
            * Mat4::from_quat(rotation(rng))
            * unscale()
    };
    let sphere = |seed: u64| ortho(&mut Rng::new(seed), (13.0, 13.0));
    let ellipsoid = |seed: u64| ortho(&mut Rng::new(seed), (14.0, 7.5));
    let persp = |seed: u64| {
        proj::perspective(std::f32::consts::FRAC_PI_3, 1.0, 0.5, 10.0)
            * Mat4::from_translation(Vec3::new(0.15, -0.1, -3.0))
            * Mat4::from_scale(Vec3::splat(1.3))
            * Mat4::from_quat(rotation(&mut Rng::new(seed)))
            * unscale()
    };
    let s = |subdiv, seed| Mesh { name: "icosphere", what: "an icosphere (orthographic)", subdiv, mvp: sphere(seed) };
    let e =
        |seed| Mesh { name: "ellipsoid", what: "a random ellipsoid (an icosphere scaled and rotated)", subdiv: 2, mvp: ellipsoid(seed) };
    let p = |seed| Mesh { name: "icosphere_perspective", what: "an icosphere in perspective", subdiv: 2, mvp: persp(seed) };
    for count in [Count::IncrIncr, Count::IncrDecr] {
        v.push(mesh_case(config, s(2, 11), count, Split::One, 0));
        v.push(mesh_case(config, p(12), count, Split::One, 0));
    }
    v.push(mesh_case(config, s(3, 13), Count::IncrIncr, Split::One, 0));
    v.push(mesh_case(config, s(2, 14), Count::IncrIncr, Split::Each, 15));
    v.push(mesh_case(config, s(2, 16), Count::IncrDecr, Split::Groups(7), 17));
    v.push(mesh_case(config, e(18), Count::IncrIncr, Split::One, 0));
    v.push(mesh_case(config, e(19), Count::IncrDecr, Split::Each, 20));
    v.push(fan_case(config, 64, false, 21));
    v.push(fan_case(config, 500, false, 22));
    v.push(fan_case(config, 500, true, 23));
    v.push(grid_case(config, 24));
    v.push(sliver_strip_case(config, 128, 25));
    v
}
