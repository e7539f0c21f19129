//! `mesh.watertight_meshlets`: a closed caster's shadow volume from meshlets in different
//! workgroups (the module doc says what).

use super::rig::{Draw, PipeState, Rig};
use super::{expect_stencil, far, near, projection, stencil_mismatches, Model, Push};
use crate::CheckResult;
use ash::vk;
use glam::{DVec4, Mat4};
use serde_json::json;
use umbrage::error::{Error, Result};
use umbrage::gpu::Context;

/// Image size.
const SIZE: (u32, u32) = (160, 120);
/// Sectors around the poles (two meshlets each), latitude bands, and triangles a meshlet.
const SECTORS: usize = 12;
const BANDS: usize = 6;
pub(super) const MESHLET_TRIS: usize = BANDS - 1;
/// What `conform_mesh.wgsl`'s `vol_out` holds (VOL_VERTICES, VOL_PRIMITIVES).
pub(super) const BUDGET: (u32, u32) = (80, 32);
/// Meshlets a task workgroup of `cull` looks at (`conform_mesh.wgsl`'s TASK_MESHLETS).
pub(super) const TASK_MESHLETS: usize = 4;
/// The light, in the caster's object space (integers: facing is exact in f32).
pub(super) const LIGHT: [f32; 4] = [-36.0, 26.0, 40.0, 1.0];
/// The stencil's start.
const START: u8 = 0x80;

/// A closed, consistently wound caster split into meshlets, with every edge owned by one.
pub(super) struct Caster {
    /// Object-space vertices (integers, w = 1).
    pub positions: Vec<[f32; 4]>,
    /// Three vertex ids a triangle, meshlet after meshlet.
    pub tris: Vec<[u32; 3]>,
    /// (first triangle, triangles, first edge, edges).
    pub meshlets: Vec<[u32; 4]>,
    /// (t0, t1, corner c of t0): a = t0[c], b = t0[c + 1]; t1 walks b -> a. Grouped by owner.
    pub edges: Vec<[u32; 3]>,
}

/// A gear-shaped sphere: a pole on top and one below, five rings of [`SECTORS`] vertices whose
/// radius alternates between 26 and 16 (the teeth make silhouette edges run up and down every
/// sector), rounded to integers (|coordinate| <= 26). Sector `s` is meshlets `2s` (its triangle
/// of the top fan, its two triangles of each of the two upper bands) and `2s + 1` (the two lower
/// bands and its triangle of the bottom fan), so each pole's fan is spread over 12 workgroups.
/// An edge belongs to the meshlet of the first triangle that has it.
pub(super) fn gear() -> Caster {
    let n = SECTORS;
    let rings = BANDS - 1;
    let mut positions = vec![[0.0, 24.0, 0.0, 1.0]];
    for k in 1..=rings {
        let theta = std::f64::consts::PI * k as f64 / BANDS as f64;
        for s in 0..n {
            let phi = 2.0 * std::f64::consts::PI * s as f64 / n as f64;
            let r = if s % 2 == 0 { 26.0 } else { 16.0 };
            let p = [r * theta.sin() * phi.cos(), 24.0 * theta.cos(), r * theta.sin() * phi.sin()];
            positions.push([p[0].round() as f32, p[1].round() as f32, p[2].round() as f32, 1.0]);
        }
    }
    positions.push([0.0, -24.0, 0.0, 1.0]);
    let bottom = positions.len() as u32 - 1;
    let v = |k: usize, s: usize| (1 + (k - 1) * n + s % n) as u32;
    let mut tris = Vec::new();
    let mut meshlets = Vec::new();
    for s in 0..n {
        tris.push([0, v(1, s + 1), v(1, s)]);
        for k in 1..rings {
            tris.push([v(k, s), v(k, s + 1), v(k + 1, s + 1)]);
            tris.push([v(k, s), v(k + 1, s + 1), v(k + 1, s)]);
        }
        tris.push([bottom, v(rings, s), v(rings, s + 1)]);
    }
    for first in (0..tris.len()).step_by(MESHLET_TRIS) {
        meshlets.push([first as u32, MESHLET_TRIS as u32, 0, 0]);
    }
    // Edges, by owner: the first triangle (in order) with the edge owns it.
    let mut seen: std::collections::HashMap<(u32, u32), usize> = std::collections::HashMap::new();
    let mut owned: Vec<Vec<[u32; 3]>> = vec![Vec::new(); meshlets.len()];
    let mut list: Vec<([u32; 3], usize)> = Vec::new();
    for (t, tri) in tris.iter().enumerate() {
        for c in 0..3 {
            let (a, b) = (tri[c], tri[(c + 1) % 3]);
            match seen.get(&(b, a)) {
                Some(&e) => list[e].0[1] = t as u32,
                None => {
                    seen.insert((a, b), list.len());
                    list.push(([t as u32, u32::MAX, c as u32], t / MESHLET_TRIS));
                }
            }
        }
    }
    for (e, m) in list {
        owned[m].push(e);
    }
    let mut edges = Vec::new();
    for (m, o) in owned.into_iter().enumerate() {
        meshlets[m][2] = edges.len() as u32;
        meshlets[m][3] = o.len() as u32;
        edges.extend(o);
    }
    Caster { positions, tris, meshlets, edges }
}

impl Caster {
    /// The shader's `words` table (header, meshlets, triangles, edges).
    pub fn words(&self) -> Vec<u32> {
        let m_off = 3u32;
        let t_off = m_off + 4 * self.meshlets.len() as u32;
        let e_off = t_off + 3 * self.tris.len() as u32;
        let mut w = vec![m_off, t_off, e_off];
        w.extend(self.meshlets.iter().flatten());
        w.extend(self.tris.iter().flatten());
        w.extend(self.edges.iter().flatten());
        w
    }

    /// Whether triangle `t` faces `light` (the shader's expression, in exact integers).
    pub fn facing(&self, t: u32, light: [f32; 4]) -> bool {
        let p = self.tris[t as usize].map(|i| self.positions[i as usize].map(|c| c as i64));
        let (e1, e2) = ([0, 1, 2].map(|k| p[1][k] - p[0][k]), [0, 1, 2].map(|k| p[2][k] - p[0][k]));
        let n = [e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]];
        let l = [0, 1, 2].map(|k| light[k] as i64 - p[0][k] * light[3] as i64);
        n[0] * l[0] + n[1] * l[1] + n[2] * l[2] > 0
    }

    /// Whether the edge `e` is a silhouette edge (its triangles face differently).
    pub fn silhouette(&self, e: &[u32; 3], light: [f32; 4]) -> bool {
        self.facing(e[0], light) != self.facing(e[1], light)
    }

    /// Meshlet `m`'s volume triangles (clip space, as the shader emits them): the light and
    /// dark cap of each light-facing triangle, then the side quad of each owned silhouette edge.
    pub fn meshlet_volume(&self, m: usize, light: [f32; 4], mvp: Mat4) -> Result<Vec<[DVec4; 3]>> {
        let exact = |c: Option<DVec4>| c.ok_or_else(|| Error::Internal("mesh.watertight_meshlets: a vertex is not exact in f32".into()));
        let pos = |i: u32| self.positions[i as usize];
        let [first, count, e_first, e_count] = self.meshlets[m];
        let mut out = Vec::new();
        for t in first..first + count {
            if !self.facing(t, light) {
                continue;
            }
            let v = self.tris[t as usize];
            let n = v.map(|i| near(mvp, pos(i)));
            let f = v.map(|i| far(mvp, light, pos(i), false));
            out.push([exact(n[0])?, exact(n[1])?, exact(n[2])?]);
            out.push([exact(f[0])?, exact(f[2])?, exact(f[1])?]);
        }
        for e in &self.edges[e_first as usize..(e_first + e_count) as usize] {
            if !self.silhouette(e, light) {
                continue;
            }
            let t0 = self.tris[e[0] as usize];
            let (mut a, mut b) = (t0[e[2] as usize], t0[(e[2] as usize + 1) % 3]);
            if !self.facing(e[0], light) {
                std::mem::swap(&mut a, &mut b);
            }
            let (na, nb) = (exact(near(mvp, pos(a)))?, exact(near(mvp, pos(b)))?);
            let (fa, fb) = (exact(far(mvp, light, pos(a), false))?, exact(far(mvp, light, pos(b), false))?);
            out.push([nb, na, fa]);
            out.push([nb, fa, fb]);
        }
        Ok(out)
    }
}

/// The check's transform: the caster 64 units ahead of the eye.
pub(super) fn mvp() -> Mat4 {
    projection() * Mat4::from_translation(glam::Vec3::new(0.0, 0.0, -64.0))
}

/// The whole volume and each meshlet's triangle count; an error when a meshlet's output
/// would not fit the shader's [`BUDGET`] (which it would then cut short).
pub(super) fn volume(c: &Caster) -> Result<(Vec<[DVec4; 3]>, Vec<u32>)> {
    let mut all = Vec::new();
    let mut counts = Vec::new();
    for (m, &[first, tris, e_first, edges]) in c.meshlets.iter().enumerate() {
        let v = c.meshlet_volume(m, LIGHT, mvp())?;
        let caps = (first..first + tris).filter(|&t| c.facing(t, LIGHT)).count() as u32;
        let sides = c.edges[e_first as usize..(e_first + edges) as usize].iter().filter(|e| c.silhouette(e, LIGHT)).count() as u32;
        if 6 * caps + 4 * sides > BUDGET.0 || v.len() as u32 > BUDGET.1 {
            return Err(Error::Internal(format!("mesh.watertight_meshlets: meshlet {m} emits more than the shader holds {BUDGET:?}")));
        }
        counts.push(v.len() as u32);
        all.extend(v);
    }
    Ok((all, counts))
}

/// The model of a pass: front and back deltas.
pub(super) fn model(tris: &[[DVec4; 3]], bits: u32, deltas: (i64, i64)) -> Model {
    expect_stencil(tris, false, SIZE, bits, 1.5 / (1u64 << bits) as f64, START, deltas)
}

/// `mesh.watertight_meshlets`.
pub fn watertight_meshlets(ctx: &Context) -> Result<CheckResult> {
    let format = ctx.depth_format;
    let bits = ctx.limits.sub_pixel_precision_bits;
    let c = gear();
    let m = c.meshlets.len();
    let tasks = m.div_ceil(TASK_MESHLETS);
    let (tris, prims) = volume(&c)?;
    let emits: Vec<bool> = prims.iter().map(|&p| p > 0).collect();
    let mut rig = Rig::new(ctx, &c.positions, &c.words(), 2 * m + tasks)?;
    // One pipeline per stage set, its stencil ops dynamic: closed (front INCR_WRAP, back
    // DECR_WRAP) and layers (INCR_WRAP on both).
    let mut st = PipeState::stencil(vk::StencilOp::INCREMENT_AND_WRAP, vk::StencilOp::DECREMENT_AND_WRAP);
    st.dynamic_ops = true;
    let task = ctx.features.task_shader;
    let mesh_only = rig.pipeline(None, c"extrude", format, st)?;
    let tasked = if task { Some(rig.pipeline(Some(c"cull"), c"extrude_tasked", format, st)?) } else { None };
    let (incr, decr) = (vk::StencilOp::INCREMENT_AND_WRAP, vk::StencilOp::DECREMENT_AND_WRAP);
    let mut passes = Vec::new();
    for (t, p) in [(false, Some(mesh_only)), (true, tasked)] {
        for (name, ops) in [("closed", [incr, decr]), ("layers", [incr, incr])] {
            if let Some(p) = p {
                passes.push((name, t, p, ops));
            }
        }
    }
    let mut numbers = serde_json::Map::new();
    let mut fails = Vec::new();
    let layers_model = model(&tris, bits, (1, 1));
    for (name, tasked, pipeline, ops) in passes {
        let push = Push::new(mvp(), LIGHT, 0, (0, m as u32, 0));
        // 24 meshlets as 6 x 4 workgroups; the task stage: a workgroup per TASK_MESHLETS.
        let groups = if tasked { [tasks as u32, 1, 1] } else { [6, 4, 1] };
        let got = rig.render(format, SIZE, (0.0, START as u32), &[Draw { pipeline, push, groups, ops: Some(ops) }])?;
        let label = format!("{name}{}", if tasked { ".tasked" } else { "" });
        let (judged, bad, first) = match name {
            // A closed volume counted front +1, back -1 leaves every pixel at its start.
            "closed" => {
                let all =
                    Model { stencil: vec![START; (SIZE.0 * SIZE.1) as usize], judged: vec![true; (SIZE.0 * SIZE.1) as usize], singular: 0 };
                stencil_mismatches(&got.image, &all)
            }
            _ => stencil_mismatches(&got.image, &layers_model),
        };
        let mut want = vec![0u32; 2 * m + tasks];
        for k in 0..m {
            let runs = !tasked || emits[k];
            want[k] = runs as u32;
            want[m + k] = if runs { prims[k] } else { 0 };
        }
        if tasked {
            for j in 0..tasks {
                want[2 * m + j] = (j * TASK_MESHLETS..((j + 1) * TASK_MESHLETS).min(m)).filter(|&k| emits[k]).count() as u32;
            }
        }
        let words_bad = got.records.iter().zip(&want).filter(|(a, b)| a != b).count();
        if words_bad > 0 {
            crate::value_images::words(&format!("{label}.records"), &want, &got.records);
        }
        let covered = got.image.stencil.iter().filter(|&&s| s != START).count();
        numbers.insert(
            label.clone(),
            json!({
                "groups": groups, "judged_pixels": judged, "stencil_mismatches": bad, "pixels_off_start": covered,
                "record_words": got.records, "record_word_mismatches": words_bad,
            }),
        );
        if bad > 0 {
            fails.push(format!("{label}: {bad} of {judged} judged pixels differ ({})", first.join(", ")));
        }
        if words_bad > 0 {
            fails.push(format!("{label}: {words_bad} record words differ: {:?}, want {want:?}", got.records));
        }
    }
    let sil: Vec<&[u32; 3]> = c.edges.iter().filter(|e| c.silhouette(e, LIGHT)).collect();
    let at_poles = sil.iter().filter(|e| edge_has(&c, e, 0)).count();
    numbers.insert("triangles".into(), json!(c.tris.len()));
    numbers.insert("meshlets".into(), json!(m));
    numbers.insert("volume_triangles".into(), json!(tris.len()));
    numbers.insert("meshlet_triangles".into(), json!(prims));
    numbers.insert("silhouette_edges".into(), json!(sil.len()));
    numbers.insert("silhouette_edges_at_top_pole".into(), json!(at_poles));
    numbers.insert("culled_meshlets".into(), json!(emits.iter().filter(|e| !**e).count()));
    numbers.insert(
        "layers_judged_fraction".into(),
        json!(layers_model.judged.iter().filter(|j| **j).count() as f64 / layers_model.judged.len() as f64),
    );
    let t = if task {
        ", and again through a task stage that drops the meshlets emitting nothing"
    } else {
        " (no taskShader: the task pass not run)"
    };
    let what = format!(
        "a {}-triangle closed caster's volume from {m} meshlets (6 x 4 workgroups): front +1 / back -1 leaves every pixel at its \
         start, +1 / +1 gives each pixel its count of volume triangles{t}; every meshlet's workgroup once, its triangles counted",
        c.tris.len()
    );
    Ok(CheckResult::from_fails("watertight_meshlets", fails, numbers, &what))
}

/// Whether edge `e` has vertex `v` as an end.
fn edge_has(c: &Caster, e: &[u32; 3], v: u32) -> bool {
    let t = c.tris[e[0] as usize];
    t[e[2] as usize] == v || t[(e[2] as usize + 1) % 3] == v
}
