//! Precise occlusion-query counts of seeded random triangles: large ones reaching past the
//! tile, medium ones, thin slivers and sub-pixel ones, in both windings, with vertices on the
//! 1/256 sub-pixel grid or anywhere (f32). Every triangle is its own draw and its own query,
//! in its own cell of the tile (cells never overlap, so no triangle's count depends on an
//! earlier one's undecidable edge pixels); each also increments the stencil, so coverage is
//! checked pixel by pixel next to the count.
//!
//! The count must equal the number of pixel centres the triangle covers: exact when no centre
//! lies within the edge band (1e-4 pixel on the grid, 1.5 sub-pixel steps off it), a range
//! otherwise — the model's query ranges.

use super::{incr_both, stencil_only, Rng};
use crate::cases::{pixel_ortho, Case, Config, Draw, Req};

/// Triangle shapes.
#[derive(Clone, Copy)]
enum Shape {
    /// One triangle per 32 x 32 tile around a point of it, vertices up to 40 pixels out.
    Large,
    /// Eight per 64 x 32 tile, each inside its 16 x 16 cell.
    Medium,
    /// Eight slivers (9 to 13 pixels long, 0.05 to 0.6 wide) in 16 x 16 cells.
    Thin,
    /// Eight triangles under a pixel across, in 8 x 8 cells of a 32 x 16 tile.
    SubPixel,
}

impl Shape {
    fn name(self) -> &'static str {
        match self {
            Shape::Large => "large",
            Shape::Medium => "medium",
            Shape::Thin => "thin",
            Shape::SubPixel => "sub_pixel",
        }
    }
    /// (tile size, cell size)
    fn layout(self) -> ((u32, u32), u32) {
        match self {
            Shape::Large => ((32, 32), 32),
            Shape::Medium | Shape::Thin => ((64, 32), 16),
            Shape::SubPixel => ((32, 16), 8),
        }
    }
}

/// A random triangle of `shape` in the cell whose top-left corner is `o` (pixels).
fn triangle(shape: Shape, o: (f64, f64), cell: f64, rng: &mut Rng) -> [[f64; 2]; 3] {
    let p = |x: f64, y: f64| [o.0 + x, o.1 + y];
    loop {
        let t = match shape {
            Shape::Large => {
                // Around a random point of the tile, vertices 12 to 40 pixels out at angles
                // spread so the triangle contains the point.
                let (cx, cy) = (rng.range(6.0, cell - 6.0), rng.range(6.0, cell - 6.0));
                let a0 = rng.range(0.0, std::f64::consts::TAU);
                let mut v = [[0.0; 2]; 3];
                for (k, q) in v.iter_mut().enumerate() {
                    let a = a0 + k as f64 * std::f64::consts::TAU / 3.0 + rng.range(-0.6, 0.6);
                    let r = rng.range(12.0, 40.0);
                    *q = p(cx + r * a.cos(), cy + r * a.sin());
                }
                v
            }
            Shape::Medium => {
                let r = |rng: &mut Rng| rng.range(0.25, cell - 0.25);
                [p(r(rng), r(rng)), p(r(rng), r(rng)), p(r(rng), r(rng))]
            }
            Shape::Thin => {
                let (cx, cy) = (rng.range(7.0, 9.0), rng.range(7.0, 9.0));
                let a = rng.range(0.0, std::f64::consts::PI);
                let half = rng.range(4.5, 6.5);
                let (dx, dy) = (a.cos() * half, a.sin() * half);
                let w = rng.range(0.05, 0.6);
                let s = rng.range(-0.8, 0.8);
                [p(cx - dx, cy - dy), p(cx + dx, cy + dy), p(cx + s * dx - a.sin() * w, cy + s * dy + a.cos() * w)]
            }
            Shape::SubPixel => {
                // Near a pixel centre, so that about half of them cover one.
                let k = |rng: &mut Rng| (2 + rng.below(cell as usize - 4)) as f64 + 0.5 + rng.range(-0.3, 0.3);
                let (cx, cy) = (k(rng), k(rng));
                let r = |rng: &mut Rng| rng.range(-0.45, 0.45);
                [p(cx + r(rng), cy + r(rng)), p(cx + r(rng), cy + r(rng)), p(cx + r(rng), cy + r(rng))]
            }
        };
        let area = (t[1][0] - t[0][0]) * (t[2][1] - t[0][1]) - (t[2][0] - t[0][0]) * (t[1][1] - t[0][1]);
        if area.abs() > 1e-3 {
            return t;
        }
    }
}

/// One case: the triangles of `shape` from `seed`, on the 1/256 grid or not, front facing
/// (counter-clockwise in Vulkan's sense) or back facing.
fn case(config: Config, shape: Shape, seed: u64, grid: bool, front: bool) -> Case {
    let (size, cell) = shape.layout();
    let rest =
        format!("random.{}.seed_{seed}.{}.{}", shape.name(), if grid { "grid_1_256" } else { "f32" }, if front { "front" } else { "back" });
    let mut c = Case::new(config, "occlusion", &rest, size, 1.0, 0);
    c.requires.push(Req::OcclusionQueryPrecise);
    let mut rng = Rng::new(seed);
    let ortho = pixel_ortho(size.0, size.1);
    let snap = |v: f64| if grid { (v * 256.0).round() / 256.0 } else { v };
    let mut n = 0;
    for cy in 0..size.1 / cell {
        for cx in 0..size.0 / cell {
            let t = triangle(shape, ((cx * cell) as f64, (cy * cell) as f64), cell as f64, &mut rng);
            let mut v: Vec<[f32; 4]> = t.iter().map(|p| [snap(p[0]) as f32, snap(p[1]) as f32, 0.5, 1.0]).collect();
            // Vulkan area under pixel_ortho (y down): positive = front facing.
            let area = -((v[1][0] - v[0][0]) * (v[2][1] - v[0][1]) - (v[2][0] - v[0][0]) * (v[1][1] - v[0][1]));
            if (area > 0.0) != front {
                v.swap(1, 2);
            }
            c.draws.push(Draw { state: stencil_only(incr_both()), mvp: ortho, vertices: v, query: true });
            n += 1;
        }
    }
    c.check_depth = false;
    c.what = format!(
        "precise occlusion queries of {n} seeded random {} {} triangle{} ({}), each its own draw: each count is the number of pixel centres it covers (exact unless a centre lies in the edge band); coverage checked by INCR_WRAP",
        shape.name().replace('_', "-"),
        if front { "front-facing" } else { "back-facing" },
        if n == 1 { "" } else { "s" },
        if grid { "vertices on the 1/256 sub-pixel grid" } else { "f32 vertices off the grid" }
    );
    c
}

/// The occlusion-query cases of `config`.
pub fn cases(config: Config) -> Vec<Case> {
    let mut v = Vec::new();
    for front in [true, false] {
        for seed in [1, 2, 3] {
            v.push(case(config, Shape::Large, seed, seed != 3, front));
        }
        for shape in [Shape::Medium, Shape::Thin, Shape::SubPixel] {
            for grid in [true, false] {
                v.push(case(config, shape, 10, grid, front));
            }
        }
    }
    v
}
