//! The multiplicity path (Kim, Kim & Turk 2008; see the module docs of [`super`]): per
//! undirected edge the signed multiplicity of the triangles' sides, and the index lists of a
//! caster that is not a closed 2-manifold.

use super::*;

/// Per-light facing data of a multiplicity caster.
pub struct MultiplicityInput<'a> {
    /// Light-facing bit of every triangle.
    pub facing: &'a [bool],
    /// Whether each triangle's light cap is known to be at or behind the visible surface
    /// (the triangle, or an exact twin of it, is front-facing to the eye, so the G-buffer
    /// pass drew it): such caps go to the depth-NEVER list.
    pub shielded: &'a [bool],
}

/// Signed multiplicity of every undirected edge of the topology (`v[0] -> v[1]` positive).
pub fn edge_multiplicities(caster: &Caster, facing: &[bool]) -> Vec<i32> {
    let ids: Vec<u32> = (0..caster.topology.edges.len() as u32).collect();
    edge_multiplicities_with(caster, &ids, facing)
}

pub(super) fn edge_multiplicities_with<F: FacingSet + ?Sized>(caster: &Caster, edge_ids: &[u32], facing: &F) -> Vec<i32> {
    let t = &caster.topology;
    edge_ids
        .iter()
        .filter_map(|&e| t.edges.get(e as usize))
        .map(|e| {
            let uses = t.uses.get(e.first_use as usize..(e.first_use + e.use_count) as usize).unwrap_or(&[]);
            uses.iter().map(|u| if u.forward == facing.get(u.tri) { 1 } else { -1 }).sum()
        })
        .collect()
}

/// What [`emit_multiplicity`] emits for one caster (or part) and light: its draws and the
/// triangle counts the stats report.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MultiplicityVolume {
    /// One draw per chunk that has triangles.
    pub draws: Vec<ChunkDraw>,
    /// Side triangles: per edge, |m| quads (two triangles; one towards a directional light).
    pub sides: usize,
    /// Dark-cap triangles.
    pub dark_cap: usize,
    /// Light-cap triangles.
    pub light_cap: usize,
    /// Edges with a non-zero multiplicity (the silhouette).
    pub edges: usize,
    /// The largest |m|.
    pub max_multiplicity: u32,
}

/// Emits a multiplicity caster's index lists and counts.
pub fn emit_multiplicity(
    caster: &Caster,
    mi: &MultiplicityInput,
    mult: &[i32],
    case: Case,
    directional: bool,
    dark_cap: DarkCap,
) -> MultiplicityVolume {
    let edge_ids: Vec<u32> = (0..mult.len() as u32).collect();
    let shielded = |g: u32| mi.shielded.get(g as usize).copied().unwrap_or(true);
    let shape = VolumeShape { case, directional, dark_cap };
    emit_multiplicity_with(caster, 0..caster.chunks.len(), &edge_ids, mi.facing, shielded, mult, shape)
}

/// What volume [`emit_multiplicity_with`] emits: the case, a directional light (no dark cap),
/// and the dark cap's kind.
#[derive(Clone, Copy, Debug)]
pub(super) struct VolumeShape {
    pub case: Case,
    pub directional: bool,
    pub dark_cap: DarkCap,
}

/// [`emit_multiplicity`] for the part whose chunks are `range` and whose edges are `edge_ids`
/// (`mult[i]` the multiplicity of edge `edge_ids[i]`).
pub(super) fn emit_multiplicity_with<F: FacingSet + ?Sized, S: Fn(u32) -> bool>(
    caster: &Caster,
    range: std::ops::Range<usize>,
    edge_ids: &[u32],
    facing: &F,
    shielded: S,
    mult: &[i32],
    shape: VolumeShape,
) -> MultiplicityVolume {
    let VolumeShape { case, directional, dark_cap } = shape;
    let nch = caster.chunks.len();
    let mut vol: Vec<Vec<u16>> = vec![Vec::new(); nch];
    let mut cap: Vec<Vec<u16>> = vec![Vec::new(); nch];
    let (mut sides, mut dark, mut light, mut edges, mut mmax) = (0, 0, 0, 0, 0u32);
    let topo = &caster.topology;
    let part_chunks = || caster.chunks.iter().enumerate().skip(range.start).take(range.len());
    // the oriented edge a->b (chunk-local, in the chunk of its first use) and |m|
    let oriented = |e: usize, m: i32| {
        let u = topo.edge_uses(e)[0];
        let (ci, li) = caster.tri_chunk[u.tri as usize];
        let ch = &caster.chunks[ci as usize];
        let lt = ch.local_tris[li as usize];
        let k = u.corner as usize;
        // the use walks lt[k] -> lt[k+1]; it is v0 -> v1 iff forward
        let (mut a, mut b) = (lt[k], lt[(k + 1) % 3]);
        if u.forward != (m > 0) {
            std::mem::swap(&mut a, &mut b);
        }
        (ci as usize, ch.n() as u16, a, b)
    };
    for (&e, &m) in edge_ids.iter().zip(mult) {
        let e = e as usize;
        if m == 0 {
            continue;
        }
        edges += 1;
        mmax = mmax.max(m.unsigned_abs());
        let (ci, n, a, b) = oriented(e, m);
        for _ in 0..m.unsigned_abs() {
            if directional {
                vol[ci].extend_from_slice(&[b, a, a + n]);
                sides += 1;
            } else {
                vol[ci].extend_from_slice(&[b, a, a + n, b, a + n, b + n]);
                sides += 2;
            }
        }
    }
    if !directional {
        match dark_cap {
            DarkCap::Fan => {
                for (&e, &m) in edge_ids.iter().zip(mult) {
                    if m == 0 {
                        continue;
                    }
                    let (ci, n, a, b) = oriented(e as usize, m);
                    let apex = caster.chunks[ci].apex();
                    for _ in 0..m.unsigned_abs() {
                        vol[ci].extend_from_slice(&[apex + n, b + n, a + n]);
                        dark += 1;
                    }
                }
            }
            DarkCap::AllFaces => {
                for (ci, ch) in part_chunks() {
                    let n = ch.n() as u16;
                    for (lt, &g) in ch.local_tris.iter().zip(&ch.tri_ids) {
                        let t = if facing.get(g) { [lt[0] + n, lt[2] + n, lt[1] + n] } else { [lt[0] + n, lt[1] + n, lt[2] + n] };
                        vol[ci].extend_from_slice(&t);
                        dark += 1;
                    }
                }
            }
            DarkCap::None => {}
            DarkCap::FrontFaces | DarkCap::BackFaces => unreachable!("manifold dark caps on a multiplicity caster"),
        }
    }
    if case != Case::ZFail {
        for (ci, ch) in part_chunks() {
            for (lt, &g) in ch.local_tris.iter().zip(&ch.tri_ids) {
                let t = if facing.get(g) { *lt } else { [lt[0], lt[2], lt[1]] };
                if !shielded(g) {
                    vol[ci].extend_from_slice(&t);
                    light += 1;
                } else if case == Case::ZFailLightCap {
                    cap[ci].extend_from_slice(&t);
                    light += 1;
                }
            }
        }
    }
    let draws = chunk_draws(vol, cap, case);
    MultiplicityVolume { draws, sides, dark_cap: dark, light_cap: light, edges, max_multiplicity: mmax }
}
