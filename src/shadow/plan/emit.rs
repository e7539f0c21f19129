//! The volume's index lists of one caster part: its sides from the possible silhouette (or the
//! scan's hits), its caps as fans or triangles, into per-chunk draws (McGuire et al. 2003's
//! EXTRUDE, 16-bit indices: 6 bytes a triangle).

use super::*;

/// Per-chunk index lists into draws, leaving out chunks with nothing to draw.
pub(super) fn chunk_draws(vol: Vec<Vec<u16>>, cap: Vec<Vec<u16>>, case: Case) -> Vec<ChunkDraw> {
    vol.into_iter()
        .zip(cap)
        .enumerate()
        .filter(|(_, (v, c))| !v.is_empty() || !c.is_empty())
        .map(|(chunk, (volume, light_cap))| ChunkDraw { chunk, case, volume, light_cap })
        .collect()
}

/// What to emit for one caster.
#[derive(Clone, Copy, Debug)]
pub struct Emit {
    /// Which triangles occlude (front or back; two-sided goes through [`emit_multiplicity`]).
    pub formulation: Formulation,
    /// The light is directional: one side triangle per silhouette edge (all of infinity is one point).
    pub directional: bool,
    /// The dark cap to emit.
    pub dark_cap: DarkCap,
    /// Emit the light cap (case 3 and the classic z-fail methods).
    pub light_cap: bool,
}

/// Per-triangle facing bits, as one `bool` per triangle or packed 64 to a word
/// ([`crate::geom::silhouette::FacePlanes::facing_packed`]).
pub(super) trait FacingSet {
    fn get(&self, t: u32) -> bool;
}

impl FacingSet for [bool] {
    #[inline]
    fn get(&self, t: u32) -> bool {
        self.get(t as usize).copied().unwrap_or(false)
    }
}

/// Packed facing bits in welded triangle order (see [`FacingSet`]).
pub(super) struct Packed<'a>(pub(super) &'a [u64]);

impl FacingSet for Packed<'_> {
    #[inline]
    fn get(&self, t: u32) -> bool {
        packed_bit(self.0, t)
    }
}

/// Emits the index lists; returns (chunk draws, sides, dark cap, light cap) triangle counts.
/// Over every chunk of the caster; the draws' `case` is z-fail with light cap when `e.light_cap`,
/// z-fail when there is a dark cap, else z-pass.
pub fn emit(caster: &Caster, facing: &[bool], sil: &[SilhouetteEdge], e: Emit) -> (Vec<ChunkDraw>, usize, usize, usize) {
    let case = if e.light_cap {
        Case::ZFailLightCap
    } else if e.dark_cap != DarkCap::None {
        Case::ZFail
    } else {
        Case::ZPass
    };
    let ends: Vec<SideEnds> = sil.iter().map(|s| side_ends(caster, s, e.formulation)).collect();
    emit_with(caster, 0..caster.chunks.len(), facing, &ends, e, case)
}

/// A silhouette edge's side as the volume draws it: a chunk and the chunk-local ends `a -> b`
/// of the edge in the light-facing triangle's winding (front formulation), or in the other
/// triangle's, reversed (back): the same two ends in a closed manifold part, each from its own
/// triangle's chunk.
#[derive(Clone, Copy, Debug)]
pub(super) struct SideEnds {
    chunk: u32,
    a: u16,
    b: u16,
}

/// [`SideEnds`] of `s`, from the caster's chunk tables.
pub(super) fn side_ends(caster: &Caster, s: &SilhouetteEdge, formulation: Formulation) -> SideEnds {
    let (tri, corner, rev) = match formulation {
        Formulation::Front => (s.lit, s.lit_corner, false),
        Formulation::Back => (s.unlit, s.unlit_corner, true),
        Formulation::TwoSided => unreachable!("multiplicity casters use emit_multiplicity"),
    };
    let (ci, li) = caster.tri_chunk[tri as usize];
    let lt = caster.chunks[ci as usize].local_tris[li as usize];
    let k = corner as usize % 3;
    let (a, b) = (lt[k], lt[(k + 1) % 3]);
    let (a, b) = if rev { (b, a) } else { (a, b) };
    SideEnds { chunk: ci, a, b }
}

/// [`SideEnds`] of the scan's hit `h`, from the edge's tag (its chunk and ends, next to the
/// scan's other per-edge data: no lookup in the chunk tables, whose rows for a light's
/// silhouette lie scattered over the caster) or, for an edge between two chunks or a scan
/// without tags, from the chunk tables.
pub(super) fn hit_ends(caster: &Caster, scan: &EdgeScan, h: ScanHit, formulation: Formulation) -> SideEnds {
    match scan.tags().get(h.edge()) {
        Some(&tag) if tag != SIDE_TAG_SPLIT && formulation != Formulation::TwoSided => {
            let (ea, eb) = ((tag >> 32) as u16, (tag >> 48) as u16);
            // t0 runs a -> b; either formulation draws the edge as the lit triangle runs it
            let (a, b) = if h.t0_lit() { (ea, eb) } else { (eb, ea) };
            SideEnds { chunk: tag as u32, a, b }
        }
        _ => side_ends(caster, &oriented(&scan.edges()[h.edge()], h.t0_lit()), formulation),
    }
}

/// [`emit`] for the part whose chunks are `range` (`ends`: its silhouette edges' sides, in
/// `e.formulation`).
pub(super) fn emit_with<F: FacingSet + ?Sized>(
    caster: &Caster,
    range: std::ops::Range<usize>,
    facing: &F,
    ends: &[SideEnds],
    e: Emit,
    case: Case,
) -> (Vec<ChunkDraw>, usize, usize, usize) {
    let part_chunks = || caster.chunks.iter().enumerate().skip(range.start).take(range.len());
    let nch = caster.chunks.len();
    let mut vol: Vec<Vec<u16>> = vec![Vec::new(); nch];
    let mut cap: Vec<Vec<u16>> = vec![Vec::new(); nch];
    let (mut sides, mut dark, mut light) = (0, 0, 0);
    // each chunk's side (and fan) indices reserved at once: a pass over the edges' chunks
    // costs less than growing the lists edge by edge (reallocations were 7 % of a plan)
    let fan = !e.directional && e.dark_cap == DarkCap::Fan;
    let edge_indices = if e.directional { 3 } else { 6 } + if fan { 3 } else { 0 };
    let mut per_chunk = vec![0usize; nch];
    for s in ends {
        per_chunk[s.chunk as usize] += edge_indices;
    }
    for (v, &n) in vol.iter_mut().zip(&per_chunk) {
        v.reserve_exact(n);
    }
    for &SideEnds { chunk, a, b } in ends {
        let n = caster.chunks[chunk as usize].n() as u16;
        let v = &mut vol[chunk as usize];
        if e.directional {
            v.extend_from_slice(&[b, a, a + n]);
            sides += 1;
        } else {
            v.extend_from_slice(&[b, a, a + n, b, a + n, b + n]);
            sides += 2;
        }
    }
    if !e.directional {
        match e.dark_cap {
            DarkCap::Fan => {
                // (the front formulation's ends: the light-facing triangle's)
                assert_eq!(e.formulation, Formulation::Front, "the fan dark cap needs the front formulation");
                for &SideEnds { chunk, a, b } in ends {
                    let ch = &caster.chunks[chunk as usize];
                    let n = ch.n() as u16;
                    vol[chunk as usize].extend_from_slice(&[ch.apex() + n, b + n, a + n]);
                    dark += 1;
                }
            }
            DarkCap::FrontFaces | DarkCap::BackFaces => {
                let want = e.dark_cap == DarkCap::FrontFaces;
                for (ci, ch) in part_chunks() {
                    let n = ch.n() as u16;
                    vol[ci].reserve(ch.local_tris.len() * 3);
                    for (lt, &g) in ch.local_tris.iter().zip(&ch.tri_ids) {
                        if facing.get(g) == want {
                            let t = if want { [lt[0] + n, lt[2] + n, lt[1] + n] } else { [lt[0] + n, lt[1] + n, lt[2] + n] };
                            vol[ci].extend_from_slice(&t);
                            dark += 1;
                        }
                    }
                }
            }
            DarkCap::None => {}
            DarkCap::AllFaces => unreachable!("multiplicity casters use emit_multiplicity"),
        }
    }
    if e.light_cap {
        let want = e.formulation == Formulation::Front;
        for (ci, ch) in part_chunks() {
            cap[ci].reserve(ch.local_tris.len() * 3);
            for (lt, &g) in ch.local_tris.iter().zip(&ch.tri_ids) {
                if facing.get(g) == want {
                    let t = if want { *lt } else { [lt[0], lt[2], lt[1]] };
                    cap[ci].extend_from_slice(&t);
                    light += 1;
                }
            }
        }
    }
    let draws = chunk_draws(vol, cap, case);
    (draws, sides, dark, light)
}
