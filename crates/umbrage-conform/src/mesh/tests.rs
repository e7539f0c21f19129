//! The mesh family's premises, without a device: the geometry is exact in f32, the caster is
//! closed with every edge owned once, the model's closed volume counts to zero, and the
//! scenarios exercise what they claim.

use super::volume::{self, gear, Caster, BUDGET, LIGHT, MESHLET_TRIS, TASK_MESHLETS};
use super::w0::{ahead, behind, clip_tris, dark_caps, in_plane, model_of};
use super::*;
use std::collections::HashMap;

const BITS: u32 = 8;

#[test]
fn push_matches_the_wgsl_block() {
    assert_eq!(Push::SIZE, 96);
    assert_eq!(std::mem::offset_of!(Push, light), 64);
    assert_eq!(std::mem::offset_of!(Push, flags), 80);
    assert_eq!(std::mem::offset_of!(Push, rec), 92);
}

#[test]
fn exact_sum_refuses_what_rounds() {
    assert_eq!(exact_sum(&[1.0, 2.0, -0.25]), Some(2.75));
    // 2^24 + 1 is not an f32, though the whole sum is.
    assert_eq!(exact_sum(&[16_777_216.0, 1.0, -1.0]), None);
    assert!(exact_transform(projection(), [0.1, 0.0, -1.0, 1.0]).is_some());
    assert!(exact_transform(projection(), [0.0, 0.0, -3.0, 1.0 / 3.0]).is_none());
}

#[test]
fn every_w0_scenario_is_exact_and_draws_what_it_claims() {
    for s in [dark_caps(), in_plane(), behind(), ahead()] {
        for near_zero in [false, true] {
            let tris = clip_tris(&s, projection(), near_zero).unwrap();
            assert!(!tris.is_empty());
            for clamp in [false, true] {
                let m = model_of(&s, near_zero, clamp, BITS);
                assert_eq!(m.singular, 0, "{}", s.name);
                let covered = m.stencil.iter().zip(&m.judged).filter(|(&v, &j)| j && v != 0x80).count();
                assert!(covered > 200, "{}: {covered} pixels", s.name);
                let judged = m.judged.iter().filter(|j| **j).count();
                assert!(judged as f64 > 0.97 * m.judged.len() as f64, "{}: {judged} judged", s.name);
            }
        }
    }
    let w = |s: &w0::Scenario, nz| clip_tris(s, projection(), nz).unwrap().iter().flatten().map(|c| c.w).collect::<Vec<_>>();
    // Dark caps: every vertex at depth exactly 1 (z = w > 0), and both facings.
    for t in clip_tris(&dark_caps(), projection(), false).unwrap() {
        assert!(t.iter().all(|c| c.z == c.w && c.w > 0.0));
    }
    let m = model_of(&dark_caps(), false, false, BITS);
    assert!(m.stencil.contains(&0x81) && m.stencil.contains(&0x7f));
    // In plane: far vertices at clip w = 0 exactly, or extrude's near-zero w.
    assert_eq!(w(&in_plane(), false).iter().filter(|&&x| x == 0.0).count(), 12);
    assert!(w(&in_plane(), true).iter().all(|&x| x > 0.0) && w(&in_plane(), true).iter().any(|&x| x < 1e-18));
    // Behind: far vertices at w < 0, and depth clamp changes what is drawn.
    assert!(w(&behind(), false).iter().any(|&x| x < 0.0));
    assert_ne!(model_of(&behind(), false, false, BITS).stencil, model_of(&behind(), false, true, BITS).stencil);
    assert!(w(&ahead(), false).iter().all(|&x| x > 0.0));
}

/// Every directed edge once, its reverse once: a closed, consistently wound surface.
fn closed(c: &Caster) -> bool {
    let mut n: HashMap<(u32, u32), usize> = HashMap::new();
    for t in &c.tris {
        for k in 0..3 {
            *n.entry((t[k], t[(k + 1) % 3])).or_default() += 1;
        }
    }
    n.iter().all(|(&(a, b), &k)| k == 1 && n.get(&(b, a)) == Some(&1))
}

#[test]
fn the_caster_is_closed_and_every_edge_owned_once() {
    let c = gear();
    assert!(closed(&c));
    assert_eq!((c.positions.len(), c.tris.len(), c.edges.len(), c.meshlets.len()), (62, 120, 180, 24));
    let mut seen = std::collections::HashSet::new();
    for (m, &[first, tris, e_first, edges]) in c.meshlets.iter().enumerate() {
        // The shader's output budget holds every cap and every owned edge's side, whatever
        // the light.
        assert!(6 * tris + 4 * edges <= BUDGET.0 && 2 * tris + 2 * edges <= BUDGET.1, "meshlet {m}: {tris} triangles, {edges} edges");
        for e in &c.edges[e_first as usize..(e_first + edges) as usize] {
            // owned by the meshlet of its first triangle, the other triangle walks it back
            assert!((first..first + tris).contains(&e[0]));
            let (t0, t1) = (c.tris[e[0] as usize], c.tris[e[1] as usize]);
            let (a, b) = (t0[e[2] as usize], t0[(e[2] as usize + 1) % 3]);
            assert!((0..3).any(|k| t1[k] == b && t1[(k + 1) % 3] == a));
            assert!(seen.insert((a.min(b), a.max(b))));
        }
    }
    // Each pole is shared by every other meshlet (12 workgroups).
    for (k, m) in c.meshlets.iter().enumerate() {
        let tris = &c.tris[m[0] as usize..(m[0] + m[1]) as usize];
        let pole = if k % 2 == 0 { 0 } else { 61 };
        assert!(tris.iter().any(|t| t.contains(&pole)));
    }
}

#[test]
fn facing_is_exact_in_f32() {
    // Every intermediate of the shader's facing expression stays below 2^24.
    let c = gear();
    let big = |v: i64| v.abs() < 1 << 24;
    for t in &c.tris {
        let p = t.map(|i| c.positions[i as usize].map(|x| x as i64));
        let (e1, e2) = ([0, 1, 2].map(|k| p[1][k] - p[0][k]), [0, 1, 2].map(|k| p[2][k] - p[0][k]));
        let n = [e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]];
        let l = [0, 1, 2].map(|k| LIGHT[k] as i64 - p[0][k]);
        let terms = [n[0] * l[0], n[1] * l[1], n[2] * l[2]];
        assert!(n.iter().all(|&x| big(x)) && terms.iter().all(|&x| big(x)));
        assert!(big(terms.iter().map(|x| x.abs()).sum()));
        assert_ne!(terms.iter().sum::<i64>(), 0, "a triangle edge-on to the light");
    }
}

#[test]
fn the_modelled_volume_is_closed_and_has_layers() {
    let c = gear();
    let (tris, prims) = volume::volume(&c).unwrap();
    assert_eq!(prims.iter().sum::<u32>() as usize, tris.len());
    // Every far vertex ahead of the eye: nothing of the volume is clipped by the near plane.
    assert!(tris.iter().flatten().all(|v| v.w > 0.0));
    let closed = volume::model(&tris, BITS, (1, -1));
    assert!(closed.stencil.iter().zip(&closed.judged).all(|(&s, &j)| !j || s == 0x80));
    let layers = volume::model(&tris, BITS, (1, 1));
    let judged = layers.judged.iter().filter(|j| **j).count();
    assert!(judged as f64 > 0.98 * layers.judged.len() as f64, "{judged}");
    let deep = layers.stencil.iter().zip(&layers.judged).filter(|(&s, &j)| j && s >= 0x82).count();
    assert!(deep > 1000, "{deep} pixels behind two or more volume layers");
    // The silhouette passes through the top pole (a fan of side quads around it from
    // several meshlets), and the task stage has meshlets to drop, in more than one workgroup.
    let sil: Vec<_> = c.edges.iter().filter(|e| c.silhouette(e, LIGHT)).collect();
    let pole_owners: std::collections::HashSet<usize> = sil
        .iter()
        .filter(|e| {
            let t = c.tris[e[0] as usize];
            t[e[2] as usize] == 0 || t[(e[2] as usize + 1) % 3] == 0
        })
        .map(|e| e[0] as usize / MESHLET_TRIS)
        .collect();
    assert!(pole_owners.len() >= 2, "silhouette edges at the top pole owned by {pole_owners:?}");
    let culled: Vec<usize> = (0..prims.len()).filter(|&m| prims[m] == 0).collect();
    assert!(!culled.is_empty() && culled.len() < prims.len());
    let per_task: Vec<usize> =
        (0..prims.len().div_ceil(TASK_MESHLETS)).map(|j| culled.iter().filter(|&&m| m / TASK_MESHLETS == j).count()).collect();
    assert!(per_task.iter().collect::<std::collections::HashSet<_>>().len() > 1, "{per_task:?}");
}
