//! Procedural shapes for scene files (`shape = "..."`).
//!
//! Every shape is counter-clockwise seen from outside (outward normal = (p1-p0) x (p2-p0)).
//! All shapes except `plane` are closed 2-manifolds with welded vertices: every undirected
//! edge is used by exactly two triangles, once in each direction.
//!
//! Placement conventions (object space, y up):
//! * `plane`: in y = 0, facing +y, centred on the origin, an open quad (2 triangles).
//! * `box`, `sphere`, `torus`, `cylinder`: centred on the origin (torus and cylinder axis = y).
//! * `stairs`, `cube_grid`, `box_stack`, `bumpy_slab`: resting on y = 0, centred in x and z.
//!   The stairs climb towards -z (the lowest step is at +z).

use glam::{Vec2, Vec3};
use std::f32::consts::PI;
use umbrage::geom::Mesh;

#[derive(Default)]
struct Builder {
    positions: Vec<Vec3>,
    triangles: Vec<[u32; 3]>,
}

impl Builder {
    fn v(&mut self, p: Vec3) -> u32 {
        self.positions.push(p);
        (self.positions.len() - 1) as u32
    }
    fn tri(&mut self, a: u32, b: u32, c: u32) {
        self.triangles.push([a, b, c]);
    }
    /// Quad a-b-c-d (in that winding) as two triangles.
    fn quad(&mut self, a: u32, b: u32, c: u32, d: u32) {
        self.tri(a, b, c);
        self.tri(a, c, d);
    }
    /// An axis-aligned closed box with 8 welded vertices, outward CCW.
    fn aabox(&mut self, min: Vec3, max: Vec3) {
        let base = self.positions.len() as u32;
        for i in 0..8u32 {
            let p = Vec3::new(
                if i & 1 != 0 { max.x } else { min.x },
                if i & 2 != 0 { max.y } else { min.y },
                if i & 4 != 0 { max.z } else { min.z },
            );
            self.v(p);
        }
        const FACES: [[u32; 4]; 6] = [[0, 4, 6, 2], [1, 3, 7, 5], [0, 1, 5, 4], [2, 6, 7, 3], [0, 2, 3, 1], [4, 5, 7, 6]];
        for f in FACES {
            self.quad(base + f[0], base + f[1], base + f[2], base + f[3]);
        }
    }
    fn finish(self) -> Mesh {
        Mesh::new(self.positions, self.triangles)
    }
    /// Flips every triangle if the (closed) mesh has negative signed volume.
    fn finish_outward(mut self) -> Mesh {
        let m = Mesh::new(std::mem::take(&mut self.positions), std::mem::take(&mut self.triangles));
        let mut m = m;
        if signed_volume(&m) < 0.0 {
            for t in &mut m.triangles {
                t.swap(1, 2);
            }
        }
        m
    }
}

/// Signed volume of a closed mesh (positive when the triangles face outward).
pub fn signed_volume(m: &Mesh) -> f64 {
    let mut v = 0.0f64;
    for t in 0..m.triangles.len() {
        let [a, b, c] = m.triangle(t);
        let (a, b, c) = (a.as_dvec3(), b.as_dvec3(), c.as_dvec3());
        v += a.dot(b.cross(c));
    }
    v / 6.0
}

/// Open quad in y = 0 facing +y, `size` = (x width, z depth).
pub fn plane(size: Vec2) -> Mesh {
    let (hx, hz) = (size.x * 0.5, size.y * 0.5);
    let mut b = Builder::default();
    let p0 = b.v(Vec3::new(-hx, 0.0, -hz));
    let p1 = b.v(Vec3::new(-hx, 0.0, hz));
    let p2 = b.v(Vec3::new(hx, 0.0, hz));
    let p3 = b.v(Vec3::new(hx, 0.0, -hz));
    b.quad(p0, p1, p2, p3);
    b.finish()
}

/// Closed box centred on the origin.
pub fn cuboid(size: Vec3) -> Mesh {
    let mut b = Builder::default();
    b.aabox(-size * 0.5, size * 0.5);
    b.finish()
}

/// UV sphere: single welded pole vertices, `segments` >= 3 around, `rings` >= 2 bands.
pub fn sphere(radius: f32, segments: u32, rings: u32) -> Mesh {
    let mut b = Builder::default();
    let north = b.v(Vec3::new(0.0, radius, 0.0));
    let mut ring_start = Vec::new();
    for k in 1..rings {
        let theta = PI * k as f32 / rings as f32;
        let (st, ct) = theta.sin_cos();
        ring_start.push(b.positions.len() as u32);
        for j in 0..segments {
            let phi = 2.0 * PI * j as f32 / segments as f32;
            let (sp, cp) = phi.sin_cos();
            b.v(Vec3::new(radius * st * cp, radius * ct, radius * st * sp));
        }
    }
    let south = b.v(Vec3::new(0.0, -radius, 0.0));
    let idx = |r: usize, j: u32| ring_start[r] + (j % segments);
    for j in 0..segments {
        b.tri(north, idx(0, j), idx(0, j + 1));
    }
    for r in 0..ring_start.len().saturating_sub(1) {
        for j in 0..segments {
            let (a0, a1, b0, b1) = (idx(r, j), idx(r, j + 1), idx(r + 1, j), idx(r + 1, j + 1));
            b.tri(a0, b0, b1);
            b.tri(a0, b1, a1);
        }
    }
    let last = ring_start.len() - 1;
    for j in 0..segments {
        b.tri(south, idx(last, j + 1), idx(last, j));
    }
    b.finish_outward()
}

/// Torus around the y axis.
pub fn torus(major: f32, minor: f32, segments: u32, sides: u32) -> Mesh {
    let mut b = Builder::default();
    for i in 0..segments {
        let u = 2.0 * PI * i as f32 / segments as f32;
        let (su, cu) = u.sin_cos();
        for j in 0..sides {
            let v = 2.0 * PI * j as f32 / sides as f32;
            let (sv, cv) = v.sin_cos();
            let r = major + minor * cv;
            b.v(Vec3::new(r * cu, minor * sv, r * su));
        }
    }
    let idx = |i: u32, j: u32| (i % segments) * sides + (j % sides);
    for i in 0..segments {
        for j in 0..sides {
            b.quad(idx(i, j), idx(i + 1, j), idx(i + 1, j + 1), idx(i, j + 1));
        }
    }
    b.finish_outward()
}

/// Capped cylinder around the y axis, centred on the origin.
pub fn cylinder(radius: f32, height: f32, segments: u32) -> Mesh {
    let mut b = Builder::default();
    let h = height * 0.5;
    let bc = b.v(Vec3::new(0.0, -h, 0.0));
    let tc = b.v(Vec3::new(0.0, h, 0.0));
    let start = b.positions.len() as u32;
    for j in 0..segments {
        let phi = 2.0 * PI * j as f32 / segments as f32;
        let (s, c) = phi.sin_cos();
        b.v(Vec3::new(radius * c, -h, radius * s));
        b.v(Vec3::new(radius * c, h, radius * s));
    }
    let bot = |j: u32| start + 2 * (j % segments);
    let top = |j: u32| start + 2 * (j % segments) + 1;
    for j in 0..segments {
        b.quad(bot(j), bot(j + 1), top(j + 1), top(j));
        b.tri(tc, top(j), top(j + 1));
        b.tri(bc, bot(j + 1), bot(j));
    }
    b.finish_outward()
}

/// A closed staircase solid: `steps` steps, each `step` = (width x, rise y, depth z).
/// Resting on y = 0, centred in x and z, climbing towards -z.
pub fn stairs(steps: u32, step: Vec3) -> Mesh {
    let n = steps as usize;
    let (w, h, d) = (step.x, step.y, step.z);
    let z0 = n as f32 * d * 0.5; // front (lowest) edge
                                 // Profile in (z, y); column k occupies z in [z0-(k+1)d, z0-kd], y in [0, (k+1)h].
    let mut prof: Vec<Vec2> = Vec::new(); // (z, y)
                                          // bottom points from front to back: (z0 - k d, 0), k = 0..=n
    for k in 0..=n {
        prof.push(Vec2::new(z0 - k as f32 * d, 0.0));
    }
    // back top: (z0 - n d, n h), then down the steps to the front
    // riser k (k = n-1 .. 0) at z0 - k d from y=(k+1)h down to kh, tread from z0-(k+1)d to z0-kd at (k+1)h
    for k in (0..n).rev() {
        prof.push(Vec2::new(z0 - (k + 1) as f32 * d, (k + 1) as f32 * h));
        prof.push(Vec2::new(z0 - k as f32 * d, (k + 1) as f32 * h));
    }
    // Remove the duplicate of the back-bottom corner path: prof[n] = (z0-nd, 0) then (z0-nd, nh): ok.
    // The loop ends at (z0, h) and closes to (z0, 0) = prof[0]; (z0 - k d, k h) for k>=1 are the
    // inner corners (riser bottoms): they are the points (z0-kd, kh) pushed as tread ends of step k-1.
    let np = prof.len();
    let bottom = |k: usize| k; // (z0 - k d, 0)
                               // index of (z0-(k+1)d, (k+1)h) and (z0-kd, (k+1)h)
    let tread_back = |k: usize| n + 1 + 2 * (n - 1 - k);
    let tread_front = |k: usize| n + 1 + 2 * (n - 1 - k) + 1;
    // Cap triangulation (indices into prof), columns.
    let mut cap: Vec<[usize; 3]> = Vec::new();
    for k in 0..n {
        let a = bottom(k);
        let bb = bottom(k + 1);
        let c = tread_back(k);
        let dd = tread_front(k);
        if k == 0 {
            cap.push([bb, c, dd]);
            cap.push([bb, dd, a]);
        } else {
            // e = (z0 - k d, k h) = tread_back(k-1)
            let e = tread_back(k - 1);
            cap.push([bb, c, dd]);
            cap.push([bb, dd, e]);
            cap.push([bb, e, a]);
        }
    }
    // Orient cap triangles like the loop.
    let area2 = |a: Vec2, b: Vec2, c: Vec2| (b - a).perp_dot(c - a);
    let loop_area: f32 = (0..np).map(|i| prof[i].perp_dot(prof[(i + 1) % np])).sum();
    for t in &mut cap {
        if area2(prof[t[0]], prof[t[1]], prof[t[2]]) * loop_area < 0.0 {
            t.swap(1, 2);
        }
    }
    let mut b = Builder::default();
    let hw = w * 0.5;
    for p in &prof {
        b.v(Vec3::new(-hw, p.y, p.x));
    }
    for p in &prof {
        b.v(Vec3::new(hw, p.y, p.x));
    }
    let l = |i: usize| i as u32;
    let r = |i: usize| (np + i) as u32;
    for t in &cap {
        b.tri(r(t[0]), r(t[1]), r(t[2]));
        b.tri(l(t[0]), l(t[2]), l(t[1]));
    }
    for i in 0..np {
        let j = (i + 1) % np;
        b.quad(l(i), l(j), r(j), r(i));
    }
    b.finish_outward()
}

/// `count` = (nx, nz) separate closed cubes of edge `size`, `spacing` apart (centre to centre),
/// resting on y = 0, the grid centred in x and z. One mesh.
pub fn cube_grid(nx: u32, nz: u32, size: f32, spacing: f32) -> Mesh {
    let mut b = Builder::default();
    for a in 0..nx {
        for c in 0..nz {
            let x = (a as f32 - (nx as f32 - 1.0) * 0.5) * spacing;
            let z = (c as f32 - (nz as f32 - 1.0) * 0.5) * spacing;
            let h = size * 0.5;
            b.aabox(Vec3::new(x - h, 0.0, z - h), Vec3::new(x + h, size, z + h));
        }
    }
    b.finish()
}

/// `count` separate closed boxes of `size`; box i is box 0 moved by i * `offset`. Box 0 rests
/// on y = 0, centred in x and z. With offset (0, pitch, 0) and pitch > size.y, a stack of slabs
/// with gaps between them.
pub fn box_stack(count: u32, size: Vec3, offset: Vec3) -> Mesh {
    let mut b = Builder::default();
    let h = size * 0.5;
    for i in 0..count {
        let c = Vec3::new(0.0, h.y, 0.0) + offset * i as f32;
        b.aabox(c - h, c + h);
    }
    b.finish()
}

/// A closed box (x, y, z) = `size` resting on y = 0 whose top and bottom are `divisions` x
/// `divisions` grids; the interior top vertices are raised/lowered by +-`bump` in a checkerboard,
/// so neighbouring top triangles differ in angle by about 2*bump/(cell size) radians.
pub fn bumpy_slab(size: Vec3, divisions: u32, bump: f32) -> Mesh {
    let n = divisions;
    let mut b = Builder::default();
    let pos = |i: u32, j: u32| Vec2::new(-size.x * 0.5 + size.x * i as f32 / n as f32, -size.z * 0.5 + size.z * j as f32 / n as f32);
    let g = |i: u32, j: u32| i * (n + 1) + j;
    for i in 0..=n {
        for j in 0..=n {
            let p = pos(i, j);
            let interior = i > 0 && j > 0 && i < n && j < n;
            let y = if interior { size.y + if (i + j) % 2 == 0 { bump } else { -bump } } else { size.y };
            b.v(Vec3::new(p.x, y, p.y));
        }
    }
    let off = (n + 1) * (n + 1);
    for i in 0..=n {
        for j in 0..=n {
            let p = pos(i, j);
            b.v(Vec3::new(p.x, 0.0, p.y));
        }
    }
    let t = |i, j| g(i, j);
    let bo = |i, j| off + g(i, j);
    for i in 0..n {
        for j in 0..n {
            b.quad(t(i, j), t(i, j + 1), t(i + 1, j + 1), t(i + 1, j));
            b.quad(bo(i, j), bo(i + 1, j), bo(i + 1, j + 1), bo(i, j + 1));
        }
    }
    // Boundary of the top, as directed edges A->B of the top triangles: side quad (B, A, A', B').
    let mut side = |a: (u32, u32), bb: (u32, u32)| {
        let (ta, tb, ba, bbb) = (t(a.0, a.1), t(bb.0, bb.1), bo(a.0, a.1), bo(bb.0, bb.1));
        b.quad(tb, ta, ba, bbb);
    };
    for k in 0..n {
        side((0, k), (0, k + 1));
        side((k, n), (k + 1, n));
        side((n, k + 1), (n, k));
        side((k + 1, 0), (k, 0));
    }
    b.finish_outward()
}

#[cfg(test)]
pub(crate) mod tests_support {
    use super::*;
    use std::collections::HashMap;

    /// Every undirected edge used exactly twice, once in each direction; welded; no unused vertex.
    pub(crate) fn assert_closed(m: &Mesh, what: &str) {
        let mut directed: HashMap<(u32, u32), u32> = HashMap::new();
        for t in &m.triangles {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                assert_ne!(a, b, "{what}: repeated index in triangle {t:?}");
                *directed.entry((a, b)).or_default() += 1;
            }
        }
        for (&(a, b), &n) in &directed {
            assert_eq!(n, 1, "{what}: directed edge {a}->{b} used {n} times");
            assert_eq!(directed.get(&(b, a)), Some(&1), "{what}: edge {a}->{b} has no opposite");
        }
        // Welded: no two vertices at the same position.
        let mut seen = HashMap::new();
        for (i, p) in m.positions.iter().enumerate() {
            let key = (p.x.to_bits(), p.y.to_bits(), p.z.to_bits());
            if let Some(j) = seen.insert(key, i) {
                panic!("{what}: vertices {j} and {i} coincide at {p:?}");
            }
        }
        let used: std::collections::HashSet<u32> = m.triangles.iter().flatten().copied().collect();
        assert_eq!(used.len(), m.positions.len(), "{what}: unused vertices");
    }

    pub(crate) fn assert_closed_outward(m: &Mesh, what: &str) {
        assert_closed(m, what);
        assert!(signed_volume(m) > 0.0, "{what}: not outward");
    }
}

#[cfg(test)]
mod tests {
    use super::tests_support::assert_closed;
    use super::*;

    fn assert_nondegenerate(m: &Mesh, what: &str) {
        for t in 0..m.triangles.len() {
            assert!(m.face_normal(t).length() > 0.0, "{what}: triangle {t} is degenerate");
        }
    }

    fn check(m: &Mesh, what: &str, volume: Option<f64>) {
        m.validate(what).unwrap();
        assert_closed(m, what);
        assert_nondegenerate(m, what);
        let v = signed_volume(m);
        assert!(v > 0.0, "{what}: signed volume {v} not positive");
        if let Some(want) = volume {
            assert!((v - want).abs() < 0.05 * want, "{what}: volume {v}, expected about {want}");
        }
    }

    #[test]
    fn plane_is_open_quad_facing_up() {
        let m = plane(Vec2::new(4.0, 2.0));
        assert_eq!(m.triangles.len(), 2);
        for t in 0..2 {
            let n = m.face_normal(t);
            assert!(n.y > 0.0 && n.x == 0.0 && n.z == 0.0);
        }
    }

    #[test]
    fn box_closed_outward() {
        let m = cuboid(Vec3::new(1.0, 2.0, 3.0));
        check(&m, "box", Some(6.0));
        // each face normal points away from the centre
        for t in 0..m.triangles.len() {
            let [a, b, c] = m.triangle(t);
            assert!(m.face_normal(t).dot((a + b + c) / 3.0) > 0.0);
        }
    }

    #[test]
    fn sphere_closed_outward() {
        for (s, r) in [(24, 16), (3, 2), (5, 3)] {
            let m = sphere(0.5, s, r);
            check(&m, "sphere", None);
        }
        let m = sphere(1.0, 64, 32);
        check(&m, "sphere", Some(4.0 / 3.0 * std::f64::consts::PI));
        assert_eq!(m.positions.iter().filter(|p| p.y == 1.0).count(), 1, "one north pole");
        assert_eq!(m.positions.iter().filter(|p| p.y == -1.0).count(), 1, "one south pole");
        for t in 0..m.triangles.len() {
            let [a, b, c] = m.triangle(t);
            assert!(m.face_normal(t).dot((a + b + c) / 3.0) > 0.0);
        }
    }

    #[test]
    fn torus_closed_outward() {
        let m = torus(1.0, 0.25, 64, 32);
        let want = 2.0 * std::f64::consts::PI.powi(2) * 1.0 * 0.25f64.powi(2);
        check(&m, "torus", Some(want));
        check(&torus(0.5, 0.2, 3, 3), "torus3", None);
    }

    #[test]
    fn cylinder_closed_outward() {
        let m = cylinder(0.5, 2.0, 64);
        check(&m, "cylinder", Some(std::f64::consts::PI * 0.25 * 2.0));
        check(&cylinder(1.0, 1.0, 3), "cylinder3", None);
    }

    #[test]
    fn stairs_closed_outward() {
        for n in [1, 2, 8] {
            let s = Vec3::new(2.0, 0.2, 0.3);
            let m = stairs(n, s);
            let want = (1..=n).map(|k| k as f64).sum::<f64>() * (2.0 * 0.2 * 0.3);
            check(&m, &format!("stairs{n}"), Some(want));
            let bb = m.bounds();
            assert!((bb.min.y).abs() < 1e-6 && (bb.max.y - 0.2 * n as f32).abs() < 1e-5);
        }
        // climbs towards -z: the highest point is at the back
        let m = stairs(4, Vec3::new(1.0, 1.0, 1.0));
        assert!(m.positions.iter().filter(|p| p.y == 4.0).all(|p| p.z <= -1.0));
    }

    #[test]
    fn cube_grid_closed_outward() {
        let m = cube_grid(3, 2, 0.4, 1.0);
        check(&m, "cube_grid", Some(6.0 * 0.064));
        assert_eq!(m.triangles.len(), 6 * 12);
    }

    #[test]
    fn box_stack_closed_outward() {
        let m = box_stack(5, Vec3::new(2.0, 0.02, 2.0), Vec3::new(0.01, 0.05, 0.0));
        check(&m, "box_stack", Some(5.0 * 0.08));
    }

    #[test]
    fn bumpy_slab_closed_outward() {
        let m = bumpy_slab(Vec3::new(2.0, 0.05, 2.0), 8, 1e-7);
        check(&m, "bumpy_slab", Some(0.2));
        let m = bumpy_slab(Vec3::new(2.0, 0.5, 1.0), 1, 0.1);
        check(&m, "bumpy_slab1", Some(1.0));
    }
}
