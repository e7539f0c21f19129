//! Tests of the four families: names and counts, the model's exactness on them, and that the
//! model's expectation changes when a draw is perturbed (so a driver doing the same would fail).

use super::*;
use crate::cases::{self, Draw, RenderModel, StateModel, FORMATS};
use crate::model::{expect, DepthExp, Expected};
use crate::raster::{self, ClippedPoly};
use glam::{DVec2, DVec4};
use std::collections::HashSet;

fn cfg() -> Config {
    Config { format: vk::Format::D24_UNORM_S8_UINT, render: RenderModel::RenderPass, state: StateModel::Static }
}

fn find(name: &str) -> Case {
    cases(cfg()).into_iter().find(|c| c.name.ends_with(name)).unwrap_or_else(|| panic!("no case {name}"))
}

fn judged(e: &Expected) -> usize {
    e.stencil.iter().filter(|s| s.is_some()).count()
}

#[test]
fn names_are_unique_and_every_config_has_every_family() {
    let all = cases::all(&Config::all(&FORMATS));
    let names: HashSet<&str> = all.iter().map(|c| c.name.as_str()).collect();
    assert_eq!(names.len(), all.len(), "duplicate names");
    for config in Config::all(&FORMATS) {
        let v = cases(config);
        assert_eq!(v.len(), 69, "{}", config.name());
        for g in GROUPS {
            let n = v.iter().filter(|c| c.group == g).count();
            assert!(n >= 13, "{g}: {n}");
            assert!(v.iter().filter(|c| c.group == g).all(|c| c.name.starts_with(&format!("{g}.{}.", config.name()))));
        }
        assert!(v.iter().all(|c| !c.what.is_empty() && c.init_stencil.len() == (c.size.0 * c.size.1) as usize));
    }
}

/// The case families judge (nearly) every pixel and, on the grid, count queries exactly.
#[test]
fn the_families_are_judged_nearly_everywhere() {
    for c in cases(cfg()) {
        let e = expect(&c, 8, None);
        let n = e.stencil.len();
        let min = if c.group == "watertight" { n * 85 / 100 } else { n * 98 / 100 };
        assert!(judged(&e) >= min, "{}: {} of {n} judged", c.name, judged(&e));
        if c.name.contains(".grid_1_256.") {
            assert!(e.queries.iter().all(|q| q.0 == q.1), "{}: {:?}", c.name, e.queries);
        }
        let exact = e.queries.iter().filter(|q| q.0 == q.1).count();
        assert!(exact * 4 >= e.queries.len() * 3, "{}: {:?}", c.name, e.queries);
    }
}

// ---- wrap ----

#[test]
fn deep_wrap_counts_come_back_exactly() {
    let want = |n: i64, m: i64, init: i64| Some((init + n - m).rem_euclid(256) as u8);
    for c in cases(cfg()).iter().filter(|c| c.group == "wrap") {
        let e = expect(c, 8, None);
        assert_eq!(judged(&e), 256, "{}", c.name);
        let fronts: usize = c.draws.iter().flat_map(|d| d.vertices.chunks(3)).filter(|t| t[1][1] == 40.0).count();
        let backs: usize = c.draws.iter().flat_map(|d| d.vertices.chunks(3)).filter(|t| t[1][1] != 40.0).count();
        let wm = c.draws[0].state.stencil.unwrap().0.write_mask;
        let v = if wm == 0xff { want(fronts as i64, backs as i64, c.init_stencil[0] as i64) } else { e.stencil[0] };
        assert!(e.stencil.iter().all(|s| *s == v), "{}: {:?}", c.name, &e.stencil[..4]);
        assert!(c.name.contains(&format!(".front_{fronts}.back_{backs}")), "{}", c.name);
    }
    // N = M comes back to exactly 0, and the masked cases by hand.
    assert_eq!(expect(&find("deep.fronts_first.front_600.back_600"), 8, None).stencil[0], Some(0));
    assert_eq!(expect(&find("deep.shuffled.front_511.back_511"), 8, None).stencil[0], Some(0));
    assert_eq!(expect(&find("deep.fronts_first.front_0.back_257"), 8, None).stencil[0], Some(255));
    // 0xa5, mask 0x3f: the low six bits count (0x25 + 300) mod 64 = 0x11 under the kept 0x80.
    assert_eq!(expect(&find("front_300.back_0.init_a5.write_mask_3f"), 8, None).stencil[0], Some(0x91));
    // 0x5a, mask 0x0f: (0xa + 299) mod 16 = 5 under the kept 0x50.
    assert_eq!(expect(&find("front_600.back_301.init_5a.write_mask_0f"), 8, None).stencil[0], Some(0x55));
    // 0x0f, mask 0xf0: every increment carries into the high nibble, decrements change nothing.
    assert_eq!(expect(&find("front_300.back_7.init_0f.write_mask_f0"), 8, None).stencil[0], Some(0xcf));
}

#[test]
fn deep_wrap_expectation_changes_when_a_draw_is_perturbed() {
    let base = find("deep.separate_draws.front_300.back_257");
    let e = expect(&base, 8, None);
    // One face dropped, one extra, one face flipped, one op wrong: every pixel changes.
    let mut dropped = base.clone();
    dropped.draws.remove(17);
    let mut extra = base.clone();
    extra.draws.push(base.draws[3].clone());
    let mut flipped = base.clone();
    flipped.draws[5].vertices.swap(1, 2);
    let mut clamp = base.clone();
    for d in &mut clamp.draws {
        let s = d.state.stencil.as_mut().unwrap();
        s.0.pass_op = vk::StencilOp::INCREMENT_AND_CLAMP;
        s.1.pass_op = vk::StencilOp::DECREMENT_AND_CLAMP;
    }
    for (what, c) in [("dropped", dropped), ("extra", extra), ("flipped", flipped), ("clamping ops", clamp)] {
        let p = expect(&c, 8, None);
        assert!(p.stencil.iter().zip(&e.stencil).all(|(a, b)| a.is_some() && a != b), "{what}");
    }
}

// ---- clip ----

fn clip_of(d: &Draw, k: usize) -> [DVec4; 3] {
    let m = d.mvp.as_dmat4();
    [0, 1, 2].map(|i| {
        let v = d.vertices[3 * k + i];
        m * DVec4::new(v[0] as f64, v[1] as f64, v[2] as f64, v[3] as f64)
    })
}

/// The naive divide (what the model did before clipping) gives a different expectation for
/// triangles with a vertex behind the eye: other pixels, and the opposite facing.
#[test]
fn naive_divide_differs_from_clipping_behind_the_eye() {
    for name in
        ["behind_eye.one_vertex.winding_acb.clamp_off", "behind_eye.all_vertices.clamp_off", "infinite.dark_cap_behind_eye.clamp_off"]
    {
        let c = find(name);
        let d = &c.draws[0];
        let wt = raster::window_tris(d.mvp, &d.vertices, &[[0, 1, 2]], 32, 32, 8);
        let naive = raster::expected_counts(&wt, |t| if t.front_facing() { 1 } else { -1 }, 32, 32).0;
        let naive: Vec<Option<u8>> = naive.iter().map(|&n| Some(0x80u8.wrapping_add(n))).collect();
        let e = expect(&c, 8, None);
        let differ = naive.iter().zip(&e.stencil).filter(|(a, b)| b.is_some() && a != b).count();
        assert!(differ > 40, "{name}: {differ} pixels differ");
    }
    // One vertex behind: the clipped polygon is front facing, the naive triangle back facing.
    let c = find("behind_eye.one_vertex.winding_acb.clamp_off");
    let d = &c.draws[0];
    let wt = raster::window_tris(d.mvp, &d.vertices, &[[0, 1, 2]], 32, 32, 8);
    assert!(!wt[0].front_facing());
    assert!(ClippedPoly::new(clip_of(d, 0), false, 32, 32, 8).front_facing());
    let e = expect(&c, 8, None);
    assert!(e.stencil.contains(&Some(0x81)) && !e.stencil.contains(&Some(0x7f)));
    // Entirely behind: nothing drawn, though the naive divide draws a triangle.
    let e = expect(&find("behind_eye.all_vertices.clamp_on"), 8, None);
    assert!(e.stencil.iter().all(|s| *s == Some(0x80)));
}

/// Facing after clipping is the sign of det[x y w] of the original vertices, whichever of
/// them are behind the eye; the naive divide agrees only when an even number are.
#[test]
fn clipped_facing_is_the_homogeneous_determinant() {
    let mut rng = Rng::new(99);
    let (mut checked, mut flipped) = (0, 0);
    for _ in 0..4000 {
        let v = [0, 1, 2].map(|_| DVec4::new(rng.range(-2.0, 2.0), rng.range(-2.0, 2.0), 0.0, rng.range(-1.0, 1.0)));
        let det = glam::DMat3::from_cols(v[0].truncate().with_z(v[0].w), v[1].truncate().with_z(v[1].w), v[2].truncate().with_z(v[2].w))
            .determinant();
        let p = ClippedPoly::new(v, true, 1024, 1024, 16);
        if p.p.len() < 3 || p.vk_area().abs() < 1.0 {
            continue;
        }
        // Under the viewport (y down), Vulkan's area has the sign of -det.
        assert_eq!(p.front_facing(), det < 0.0, "{v:?}");
        checked += 1;
        let behind = v.iter().filter(|c| c.w < 0.0).count();
        if behind % 2 == 1 {
            let naive = v.map(|c| DVec2::new(c.x / c.w, c.y / c.w));
            let area = -((naive[1] - naive[0]).perp_dot(naive[2] - naive[0]));
            assert_eq!(area > 0.0, det > 0.0, "naive facing flips with an odd number of vertices behind");
            flipped += 1;
        }
    }
    assert!(checked > 1000 && flipped > 100, "{checked} {flipped}");
}

#[test]
fn clip_expectation_changes_when_a_draw_is_perturbed() {
    let mut n = 0;
    for c in cases(cfg()).into_iter().filter(|c| c.group == "clip") {
        let e = expect(&c, 8, None);
        if e.stencil.iter().all(|s| *s == Some(0x80)) {
            continue; // nothing drawn
        }
        let mut flipped = c.clone();
        for t in flipped.draws[0].vertices.chunks_mut(3) {
            t.swap(1, 2);
        }
        let f = expect(&flipped, 8, None);
        let differ = f.stencil.iter().zip(&e.stencil).filter(|(a, b)| a.is_some() && b.is_some() && a != b).count();
        assert!(differ > 20, "{}: {differ}", c.name);
        n += 1;
    }
    assert!(n >= 12);
    // Depth clamp keeps what lies between the eye and the near plane, at depth exactly 0.
    let off = expect(&find("behind_eye.one_vertex.winding_abc.clamp_off"), 8, None);
    let on = expect(&find("behind_eye.one_vertex.winding_abc.clamp_on"), 8, None);
    let zero = on.depth.iter().filter(|d| **d == DepthExp::Exact(0.0)).count();
    assert!(zero >= 32 * 5, "{zero}");
    assert!(on.stencil.iter().zip(&off.stencil).filter(|(a, b)| a != b).count() >= zero);
}

/// No case outside this module reaches the clipping path (their expectations did not change).
#[test]
fn older_cases_never_need_clipping() {
    for c in cases::all(&Config::all(&FORMATS)).iter().filter(|c| !GROUPS.contains(&c.group)) {
        for d in &c.draws {
            for k in 0..d.vertices.len() / 3 {
                assert!(clip_of(d, k).iter().all(|v| v.w > 0.0), "{}", c.name);
            }
        }
    }
}

// ---- watertight ----

#[test]
fn icospheres_are_closed_consistently_wound_and_convex() {
    for n in 0..4 {
        let (v, f) = watertight::icosphere(n);
        let mut edges = HashSet::new();
        for t in &f {
            for i in 0..3 {
                assert!(edges.insert((t[i], t[(i + 1) % 3])), "directed edge twice");
            }
            let (a, b, c) = (v[t[0] as usize], v[t[1] as usize], v[t[2] as usize]);
            let nrm = (b - a).cross(c - a);
            assert!(nrm.dot(a) > 0.0, "wound outwards");
            assert!(v.iter().all(|p| nrm.dot(*p - a) <= 1e-12), "convex");
        }
        assert!(edges.iter().all(|&(a, b)| edges.contains(&(b, a))), "closed");
        assert_eq!(f.len(), 20 * 4usize.pow(n));
    }
}

/// The override agrees with the per-triangle model wherever the model can judge, and the
/// model with one triangle dropped (or one drawn twice) disagrees with it: a driver leaving a
/// gap or a double hit fails.
#[test]
fn watertight_override_matches_the_model_and_catches_gaps() {
    for c in cases(cfg()).into_iter().filter(|c| c.group == "watertight") {
        let o = c.stencil_override.clone().unwrap();
        let mut plain = c.clone();
        plain.stencil_override = None;
        let m = expect(&plain, 8, None);
        let (mut both, mut agree) = (0, 0);
        for (a, b) in o.iter().zip(&m.stencil) {
            if let (Some(a), Some(b)) = (a, b) {
                both += 1;
                agree += (a == b) as usize;
            }
        }
        assert_eq!(both, agree, "{}", c.name);
        assert!(both > 400, "{}: {both}", c.name);
        // Drop the largest triangle; then draw it twice.
        let area = |d: &Draw, k: usize| {
            let m4 = d.mvp.as_dmat4();
            let p: Vec<DVec2> = (0..3)
                .map(|i| {
                    let v = d.vertices[3 * k + i];
                    let c = m4 * DVec4::new(v[0] as f64, v[1] as f64, v[2] as f64, v[3] as f64);
                    DVec2::new(c.x / c.w, c.y / c.w)
                })
                .collect();
            (p[1] - p[0]).perp_dot(p[2] - p[0]).abs()
        };
        let (di, k) = (0..c.draws.len())
            .flat_map(|di| (0..c.draws[di].vertices.len() / 3).map(move |k| (di, k)))
            .max_by(|&(a, i), &(b, j)| area(&c.draws[a], i).total_cmp(&area(&c.draws[b], j)))
            .unwrap();
        let d = &c.draws[di];
        for extra in [false, true] {
            let mut bad = plain.clone();
            if extra {
                let t: Vec<[f32; 4]> = d.vertices[3 * k..3 * k + 3].to_vec();
                bad.draws.push(Draw { vertices: t, ..d.clone() });
            } else {
                bad.draws[di].vertices.drain(3 * k..3 * k + 3);
            }
            let b = expect(&bad, 8, None);
            let caught = o.iter().zip(&b.stencil).filter(|(a, b)| a.is_some() && b.is_some() && a != b).count();
            assert!(caught > 0, "{}: a {} triangle goes unnoticed", c.name, if extra { "doubled" } else { "missing" });
        }
    }
}

// ---- occlusion ----

/// Each exact query equals an independent count: pixel centres strictly inside the snapped
/// window triangle by exact orientation tests (the `robust` crate).
#[test]
fn exact_query_counts_match_exact_orientation_tests() {
    let mut checked = 0;
    for c in cases(cfg()).into_iter().filter(|c| c.group == "occlusion") {
        let e = expect(&c, 8, None);
        for (k, d) in c.draws.iter().enumerate() {
            let (lo, hi) = e.queries[k];
            if lo != hi {
                continue;
            }
            let t = raster::window_tris(d.mvp, &d.vertices, &[[0, 1, 2]], c.size.0, c.size.1, 8)[0];
            let pt = |p: DVec2| robust::Coord { x: p.x, y: p.y };
            let mut n = 0;
            for y in 0..c.size.1 {
                for x in 0..c.size.0 {
                    let q = robust::Coord { x: x as f64 + 0.5, y: y as f64 + 0.5 };
                    let s: Vec<f64> = (0..3).map(|i| robust::orient2d(pt(t.p[i]), pt(t.p[(i + 1) % 3]), q)).collect();
                    if s.iter().all(|&v| v > 0.0) || s.iter().all(|&v| v < 0.0) {
                        n += 1;
                    }
                }
            }
            assert_eq!(n, lo, "{} query {k}", c.name);
            checked += 1;
        }
    }
    assert!(checked > 80, "{checked}");
}

#[test]
fn occlusion_expectation_changes_when_a_draw_is_perturbed() {
    for name in ["random.large.seed_1.grid_1_256.front", "random.medium.seed_10.grid_1_256.back", "random.medium.seed_10.f32.front"] {
        let c = find(name);
        let e = expect(&c, 8, None);
        let k = (0..e.queries.len()).max_by_key(|&k| e.queries[k].0).unwrap();
        // A vertex one pixel further out, or the triangle drawn twice: the count changes.
        let mut moved = c.clone();
        let v = &mut moved.draws[k].vertices;
        let centroid = [(v[0][0] + v[1][0] + v[2][0]) / 3.0, (v[0][1] + v[1][1] + v[2][1]) / 3.0];
        let dir = [v[0][0] - centroid[0], v[0][1] - centroid[1]];
        let len = (dir[0] * dir[0] + dir[1] * dir[1]).sqrt();
        v[0][0] += 1.5 * dir[0] / len;
        v[0][1] += 1.5 * dir[1] / len;
        let m = expect(&moved, 8, None);
        assert!(m.queries[k].0 > e.queries[k].1, "{name}: {:?} -> {:?}", e.queries[k], m.queries[k]);
        let mut twice = c.clone();
        twice.draws[k].vertices.extend(c.draws[k].vertices.clone());
        assert_eq!(expect(&twice, 8, None).queries[k].0, 2 * e.queries[k].0, "{name}");
    }
}
