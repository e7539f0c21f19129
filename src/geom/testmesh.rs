//! Closed, CCW-outward test meshes (cube, UV sphere, torus) and an open grid for tests and benchmarks: compiled
//! into the crate's own unit tests only (`#[cfg(test)]`), and included by path into the
//! integration tests and benchmarks that need them (their parent module brings `Mesh` into
//! scope), so they are not part of the library.

use super::Mesh;
use glam::Vec3;

/// A grid of `rows x cols` vertices at `at(i, j)` (row `i`, column `j`), two triangles a cell,
/// CCW seen from +z where `at` keeps the grid's orientation: an open sheet, not closed.
pub fn grid(rows: u32, cols: u32, at: impl Fn(u32, u32) -> Vec3) -> Mesh {
    let positions = (0..rows).flat_map(|i| (0..cols).map(move |j| (i, j))).map(|(i, j)| at(i, j)).collect();
    let mut triangles = Vec::new();
    for i in 0..rows.saturating_sub(1) {
        for j in 0..cols.saturating_sub(1) {
            let v = i * cols + j;
            triangles.push([v, v + cols, v + 1]);
            triangles.push([v + 1, v + cols, v + cols + 1]);
        }
    }
    Mesh { positions, triangles }
}

/// Axis-aligned cube of half-size `h` around `c`: 8 vertices, 12 triangles.
pub fn cube(c: Vec3, h: f32) -> Mesh {
    let mut pos = Vec::new();
    for i in 0..8 {
        let s = |b: usize| if i & b != 0 { h } else { -h };
        pos.push(c + Vec3::new(s(1), s(2), s(4)));
    }
    // quads CCW seen from outside
    let quads = [
        [0, 2, 3, 1], // -z
        [4, 5, 7, 6], // +z
        [0, 1, 5, 4], // -y
        [2, 6, 7, 3], // +y
        [0, 4, 6, 2], // -x
        [1, 3, 7, 5], // +x
    ];
    let mut tris = Vec::new();
    for q in quads {
        tris.push([q[0], q[1], q[2]]);
        tris.push([q[0], q[2], q[3]]);
    }
    Mesh::new(pos, tris)
}

/// UV sphere with `slices` around the axis and `stacks` bands (single-vertex poles):
/// `2 * slices * (stacks - 1)` triangles, `slices * (stacks - 1) + 2` vertices.
pub fn uv_sphere(r: f32, slices: u32, stacks: u32) -> Mesh {
    assert!(slices >= 3 && stacks >= 2);
    let mut pos = vec![Vec3::new(0.0, r, 0.0)];
    for i in 1..stacks {
        let th = std::f32::consts::PI * i as f32 / stacks as f32;
        for j in 0..slices {
            let ph = std::f32::consts::TAU * j as f32 / slices as f32;
            pos.push(Vec3::new(r * th.sin() * ph.cos(), r * th.cos(), -r * th.sin() * ph.sin()));
        }
    }
    pos.push(Vec3::new(0.0, -r, 0.0));
    let south = pos.len() as u32 - 1;
    let ring = |i: u32, j: u32| 1 + (i - 1) * slices + (j % slices);
    let mut tris = Vec::new();
    for j in 0..slices {
        tris.push([0, ring(1, j), ring(1, j + 1)]);
    }
    for i in 1..stacks - 1 {
        for j in 0..slices {
            let (a, b, c, d) = (ring(i, j), ring(i + 1, j), ring(i + 1, j + 1), ring(i, j + 1));
            tris.push([a, b, c]);
            tris.push([a, c, d]);
        }
    }
    for j in 0..slices {
        tris.push([south, ring(stacks - 1, j + 1), ring(stacks - 1, j)]);
    }
    Mesh::new(pos, tris)
}

/// `m` with its triangles in a fixed pseudo-random order (xorshift Fisher-Yates): the worst
/// triangle order for order-exploiting scans.
pub fn shuffled(m: &Mesh) -> Mesh {
    let mut order: Vec<usize> = (0..m.triangles.len()).collect();
    let mut x = 0x9e37_79b9_7f4a_7c15u64;
    for i in (1..order.len()).rev() {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        order.swap(i, (x % (i as u64 + 1)) as usize);
    }
    Mesh::new(m.positions.clone(), order.iter().map(|&i| m.triangles[i]).collect())
}

/// Torus around the y axis: `2 * u * v` triangles.
pub fn torus(big_r: f32, small_r: f32, u: u32, v: u32) -> Mesh {
    let mut pos = Vec::new();
    for i in 0..u {
        let a = std::f32::consts::TAU * i as f32 / u as f32;
        for j in 0..v {
            let b = std::f32::consts::TAU * j as f32 / v as f32;
            let rr = big_r + small_r * b.cos();
            pos.push(Vec3::new(rr * a.cos(), small_r * b.sin(), -rr * a.sin()));
        }
    }
    let id = |i: u32, j: u32| (i % u) * v + (j % v);
    let mut tris = Vec::new();
    for i in 0..u {
        for j in 0..v {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            tris.push([a, b, c]);
            tris.push([a, c, d]);
        }
    }
    Mesh::new(pos, tris)
}

/// Signed volume (positive for a closed CCW-outward mesh).
pub fn signed_volume(m: &Mesh) -> f64 {
    m.triangles
        .iter()
        .map(|t| {
            let p = |k: usize| m.positions[t[k] as usize].as_dvec3();
            p(0).dot(p(1).cross(p(2))) / 6.0
        })
        .sum()
}
