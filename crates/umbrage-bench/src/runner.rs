//! Measuring one point of the suite: a renderer for a scene at a size, one counting frame per
//! variant (exact fragments and pipeline statistics; not timed: the warm-up round too), then
//! timed rounds over the variants (round-robin, so drift hits every variant alike), medians
//! and the p10–p90 spread of the GPU timestamps. The suite ([`super::suite`]) measures its
//! sweeps through it, the bound proofs ([`super::proof`]) their ablations.

use super::classic::technique_label;
use super::report::{RowLimits, SuiteRow};
use super::stats::{median, quantile};
use super::sweeps::{self, PointScene};
use std::collections::HashMap;
use std::time::Instant;
use umbrage::error::{Error, Result};
use umbrage::gpu::Context;
use umbrage_render::accuracy::evaluate;
use umbrage_render::{IndexFormat, PassToggles, RenderOptions, RenderTechnique, Renderer, ShadowMap, Technique};
use umbrage_scene::Scene;

/// One way to render a point: the technique plus the pass settings an ablation changes.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct Variant {
    /// The technique.
    pub technique: RenderTechnique,
    /// The pass's optimisations (an ablation switches one off).
    pub toggles: PassToggles,
    /// The index format requested.
    pub index_format: IndexFormat,
    /// The row's `variant` (empty but for the ablations).
    pub label: String,
}

impl Variant {
    /// `t` with every optimisation on and automatic indices.
    pub fn of(t: impl Into<RenderTechnique>) -> Variant {
        let t = t.into();
        Variant { technique: t, toggles: PassToggles::default(), index_format: IndexFormat::Auto, label: String::new() }
    }
}

/// What a point's scene holds, for its rows.
struct PointShape {
    casters: u64,
    triangles: u64,
    nlights: usize,
    /// Shadow-map faces a frame (6 per point light, 1 per other light).
    map_faces: u64,
    /// Each shadow-casting mesh's triangles, by name.
    mesh_triangles: HashMap<String, u64>,
    /// Triangles the G-buffer pass draws: every opaque mesh's, 12 a sphere (its cube).
    gbuffer_triangles: u64,
}

impl PointShape {
    fn of(scene: &Scene) -> PointShape {
        let casting = || scene.meshes.iter().filter(|m| m.casts_shadow);
        PointShape {
            casters: casting().count() as u64,
            triangles: casting().map(|m| m.mesh.triangles.len() as u64).sum(),
            nlights: scene.lights.len(),
            // Six faces per point light, one per spot or directional light.
            map_faces: scene.lights.iter().map(|l| if l.kind == umbrage_scene::LightKind::Point { 6 } else { 1 }).sum(),
            mesh_triangles: casting().map(|m| (m.name.clone(), m.mesh.triangles.len() as u64)).collect(),
            gbuffer_triangles: scene.meshes.iter().filter(|m| m.opacity >= 1.0).map(|m| m.mesh.triangles.len() as u64).sum::<u64>()
                + 12 * scene.spheres.len() as u64,
        }
    }
}

/// Measures points on the suite's one context (lent to each point's renderer in turn).
pub(super) struct Runner {
    /// The context, between renderers.
    pub ctx: Option<Context>,
    /// Print a line per point (progress requested but stderr is not a terminal).
    pub log: bool,
    /// The limits each row carries.
    pub limits: RowLimits,
    /// Timed frames per variant.
    pub frames: usize,
    /// Frames in flight of the renderers.
    pub frames_in_flight: usize,
    /// Progress: one unit per variant measured.
    pub bar: indicatif::ProgressBar,
    /// Variants left out, and why.
    pub skipped: Vec<String>,
    /// When the run started.
    pub start: Instant,
    /// Wall seconds a point's timed rounds may take: past it, fewer frames (at least
    /// [`MIN_FRAMES`]).
    pub point_budget_s: f64,
}

/// Fewest timed frames a point is cut to by its budget.
pub const MIN_FRAMES: usize = 5;

/// Timed rounds for a point whose warm-up (counting) round took `round_s` wall seconds: `frames`, or
/// as many as fit `budget_s` where fewer do, never below [`MIN_FRAMES`] (nor above `frames`).
pub fn frames_within(frames: usize, round_s: f64, budget_s: f64) -> usize {
    let fit = budget_s / round_s.max(1e-6);
    let fit = if fit.is_finite() && fit < frames as f64 { fit as usize } else { frames };
    fit.max(MIN_FRAMES).min(frames)
}

/// A point's scene and its name in the rows.
pub(super) fn scene_of(p: &PointScene) -> Result<(Scene, String)> {
    match p {
        PointScene::Named(n) => Ok((umbrage_scene::load(n)?, n.clone())),
        PointScene::Param(s) => Ok((s.build(), s.name())),
    }
}

/// Where a suite point sits: its sweep, its x on that sweep and its scene's name.
#[derive(Clone, Copy)]
pub(super) struct Point<'a> {
    /// The sweep (the rows' `sweep`).
    pub sweep: &'a str,
    /// The sweep's variable.
    pub x: f64,
    /// The scene's name.
    pub name: &'a str,
}

/// A variant's timed rounds: each GPU span and the CPU planning, frame by frame.
#[derive(Default)]
struct Acc {
    shadow: Vec<f64>,
    map: Vec<f64>,
    frame: Vec<f64>,
    depth: Vec<f64>,
    illum: Vec<f64>,
    accel: Vec<f64>,
    plan: Vec<f64>,
}

/// What a point's rows are made of: where it sits, its frame size and scene, the variants
/// measured, their counting frames' statistics and timed rounds, the McGuire twin's
/// `(sides, fragments)` for edge quads and ray query, each technique's error, the rounds.
struct Measured<'a> {
    at: Point<'a>,
    size: (u32, u32),
    shape: PointShape,
    variants: &'a [&'a Variant],
    counted: Vec<umbrage_render::Stats>,
    acc: Vec<Acc>,
    twin: Option<(u64, Option<u64>)>,
    error: HashMap<RenderTechnique, f64>,
    frames: usize,
}

impl Runner {
    /// Measures every variant on one scene and size: each row with the variant it measured
    /// (variants the device cannot run are left out, and listed in `skipped`). `errors`:
    /// render the reference too and fill in each technique's error.
    pub fn point(
        &mut self,
        at: Point,
        scene: Scene,
        size: (u32, u32),
        variants: &[Variant],
        errors: bool,
    ) -> Result<Vec<(SuiteRow, Variant)>> {
        let t = Instant::now();
        let mut r = self.renderer(scene, size)?;
        self.note("renderer built", t);
        let result = self.measure(&mut r, at, variants, errors);
        self.release(r);
        result
    }

    /// A renderer for `scene` at `size`, on the runner's context (give it back with
    /// [`release`](Runner::release)).
    pub fn renderer(&mut self, scene: Scene, size: (u32, u32)) -> Result<Renderer> {
        let ctx = self.ctx.take().ok_or_else(|| Error::Internal("the bench lost its context".into()))?;
        let opts = RenderOptions { width: size.0, height: size.1, frames_in_flight: self.frames_in_flight, ..Default::default() };
        match Renderer::try_new(ctx, scene, opts) {
            Ok(r) => Ok(r),
            Err(e) => {
                let e = *e;
                self.ctx = Some(e.context);
                Err(e.error)
            }
        }
    }

    /// Takes the context back from a renderer.
    pub fn release(&mut self, r: Renderer) {
        self.ctx = Some(r.into_context());
    }

    /// With a log, how long `what` took since `since`.
    fn note(&self, what: &str, since: Instant) {
        if self.log {
            eprintln!("           {what}: {:.1} s", since.elapsed().as_secs_f64());
        }
    }

    /// Measures every variant on `r`'s scene at its size (see [`point`](Runner::point)).
    pub fn measure(&mut self, r: &mut Renderer, at: Point, variants: &[Variant], errors: bool) -> Result<Vec<(SuiteRow, Variant)>> {
        let Point { sweep, name, .. } = at;
        if self.log {
            let (w, h) = (r.config().width, r.config().height);
            eprintln!("[{:>6.1} s] {sweep} {name} {w}x{h} ({} variants)", self.start.elapsed().as_secs_f64(), variants.len());
        }
        let shape = PointShape::of(r.scene());
        let nlights = shape.nlights;
        let mut kept: Vec<&Variant> = Vec::with_capacity(variants.len());
        for v in variants {
            match v.technique {
                RenderTechnique::ShadowMap(ShadowMap { size, .. }) if !sweeps::shadow_map_fits(size, nlights) => {
                    self.skipped.push(format!("{sweep} {name}: shadowmap-{size} with {nlights} lights (over 2^26 map texels a frame)"));
                    self.bar.inc(1);
                }
                _ if v.index_format == IndexFormat::U8 && !r.context().features.index_type_uint8 => {
                    self.skipped.push(format!("{sweep} {name}: index-u8 (VK_EXT_index_type_uint8 missing)"));
                    self.bar.inc(1);
                }
                _ => kept.push(v),
            }
        }
        let variants = kept;
        let mut error: HashMap<RenderTechnique, f64> = HashMap::new();
        if errors {
            let t = Instant::now();
            let techniques: Vec<RenderTechnique> = variants.iter().map(|v| v.technique).collect();
            let rows = evaluate_fractions(r, name, &techniques)?;
            for (t, f) in techniques.iter().zip(rows) {
                error.insert(*t, f);
            }
            self.note("errors against the reference", t);
        }
        let counting = Instant::now();
        // One frame first: the casters' uploads land in it, not in a variant's counts.
        r.render()?;
        let base = r.settings;
        let apply = |r: &mut Renderer, v: &Variant| {
            r.settings = base;
            r.settings.technique = v.technique;
            r.settings.toggles = v.toggles;
            r.settings.index_format = v.index_format;
        };
        // Counting frames, not timed: also the warm-up round (every variant's buffers sized and
        // first-use costs paid before any timed frame), whose wall time sets how many timed
        // rounds fit the budget (a counting frame costs a little more than a timed one).
        let count = |r: &mut Renderer, v: &Variant| -> Result<_> {
            apply(r, v);
            r.settings.counters = true;
            let stats = r.render()?.stats;
            r.settings.counters = false;
            Ok(stats)
        };
        let mut counted = Vec::with_capacity(variants.len());
        for v in &variants {
            counted.push(count(r, v)?);
        }
        // Edge quads and ray query draw no silhouette sides of their own to count: the McGuire
        // volumes of the same frame give their rows the sides that cover screen area and the
        // fragments rays pass through, `(sides, fragments)` (one more counting frame, with the
        // first such variant's toggles, where no McGuire variant has them).
        let mcguire = RenderTechnique::Pass(Technique::Volumes(umbrage::shadow::Method::McGuire));
        let of = |s: &umbrage_render::Stats| (s.totals.triangles.sides, s.counters.as_ref().and_then(|c| c.stencil_fragments));
        let twin = match variants.iter().find(|v| matches!(v.technique, RenderTechnique::Pass(Technique::EdgeQuads | Technique::RayQuery)))
        {
            Some(v) => match counted.iter().zip(&variants).find(|(_, w)| w.technique == mcguire && w.toggles == v.toggles) {
                Some((s, _)) => Some(of(s)),
                None => Some(of(&count(r, &Variant { technique: mcguire, ..(*v).clone() })?)),
            },
            None => None,
        };
        let frames = frames_within(self.frames, counting.elapsed().as_secs_f64(), self.point_budget_s);
        self.note("counting frames (the warm-up round)", counting);
        let timing = Instant::now();
        // Timed frames, round-robin.
        let mut acc: Vec<Acc> = variants.iter().map(|_| Acc::default()).collect();
        for _ in 0..frames {
            for (v, a) in variants.iter().zip(&mut acc) {
                apply(r, v);
                let f = r.render()?;
                if let Some(g) = &f.stats.gpu_ms {
                    a.shadow.push(g.shadow);
                    a.map.push(g.shadow_map);
                    a.frame.push(g.frame);
                    a.depth.push(g.depth);
                    a.illum.push(g.illuminate);
                    a.accel.push(g.accel);
                }
                a.plan.push(f.stats.cpu_ms.plan + f.stats.cpu_ms.silhouettes);
            }
        }
        r.settings = base;
        self.note(&format!("{frames} timed rounds"), timing);
        let (w, h) = (r.config().width, r.config().height);
        let measured = Measured { at, size: (w, h), shape, variants: &variants, counted, acc, twin, error, frames };
        Ok(self.rows(measured))
    }

    /// The rows of a point's variants, from their counting frames and timed rounds.
    fn rows(&mut self, m: Measured) -> Vec<(SuiteRow, Variant)> {
        let Measured { at: Point { sweep, x, name }, size: (w, h), shape, variants, counted, acc, twin, error, frames } = m;
        let PointShape { casters, triangles, nlights, map_faces, mesh_triangles, gbuffer_triangles } = shape;
        let mut rows = Vec::new();
        for ((v, s), a) in variants.iter().zip(counted).zip(acc) {
            let c = s.counters.clone().unwrap_or_default();
            let map_size = match v.technique {
                RenderTechnique::ShadowMap(ShadowMap { size, .. }) => Some(size as u64),
                _ => None,
            };
            let shadow_map = map_size.is_some();
            let med = |x: Vec<f64>| (!x.is_empty()).then(|| median(x));
            let q = |x: &[f64], p: f64| (!x.is_empty()).then(|| quantile(x, p));
            let (p10, p90) = (q(&a.shadow, 0.1), q(&a.shadow, 0.9));
            // Per light, the casters it did not cull, and their meshes' triangles.
            let drawn = s.lights.iter().flat_map(|l| l.casters.iter()).filter(|c| c.case != umbrage::shadow::Case::Culled);
            let (caster_passes, bound_triangles) =
                drawn.fold((0u64, 0u64), |(n, t), c| (n + 1, t + mesh_triangles.get(&c.name).copied().unwrap_or(0)));
            let lookup: Vec<f64> = a.shadow.iter().zip(&a.map).map(|(s, m)| s - m).collect();
            let (map_ms, lookup_ms) = match shadow_map {
                true => (med(a.map.clone()), med(lookup)),
                false => (None, None),
            };
            let lit_pixels: u64 =
                s.lights.iter().map(|l| l.scissor.map_or(w as u64 * h as u64, |[_, _, sw, sh]| sw as u64 * sh as u64)).sum();
            let (illum_ms, depth_ms) = (med(a.illum), med(a.depth));
            // Work at a limit's rate over the pass's time (1 = at the limit).
            let at = |n: u64, rate: f64, unit: f64, ms: Option<f64>| match ms {
                Some(ms) if rate > 0.0 && ms > 0.0 => Some(n as f64 / (rate * unit) * 1e3 / ms),
                _ => None,
            };
            let mut row = SuiteRow {
                suite: "fill-vertex".into(),
                sweep: sweep.into(),
                x,
                variant: v.label.clone(),
                scene: name.into(),
                method: technique_label(v.technique),
                counter: if shadow_map { "float".into() } else { s.counter.name().to_string() },
                index_format: v.index_format.name().into(),
                width: w,
                height: h,
                triangles,
                casters,
                lights: nlights as u64,
                frames,
                gpu_shadow_ms: med(a.shadow),
                gpu_shadow_ms_p10: p10,
                gpu_shadow_ms_p90: p90,
                gpu_map_ms: map_ms,
                gpu_lookup_ms: lookup_ms,
                gpu_tlas_ms: if v.technique == RenderTechnique::Pass(Technique::RayQuery) { med(a.accel) } else { None },
                blas_build_ms: s
                    .ray_query
                    .as_ref()
                    .filter(|_| v.technique == RenderTechnique::Pass(Technique::RayQuery))
                    .map(|q| q.bottom_level_build_ms),
                gpu_frame_ms: med(a.frame),
                gpu_depth_ms: depth_ms,
                gpu_illuminate_ms: illum_ms,
                lit_pixels,
                lighting_limit_fraction: at(lit_pixels, self.limits.lighting_gpix_s, 1e9, illum_ms),
                gbuffer_triangles,
                gbuffer_limit_fraction: at(gbuffer_triangles, self.limits.gbuffer_tri_mtri_s, 1e6, depth_ms),
                stencil_fragments: c.stencil_fragments,
                shadow_triangles: s.totals.triangles.total(),
                shadow_sides: s.totals.triangles.sides,
                primitives: c.primitives,
                clipped_primitives: c.clipped_primitives,
                vertex_invocations: c.vertex_invocations,
                clipped_triangles: s.totals.triangles.sides + s.totals.triangles.dark_cap,
                map_texels: map_size.map_or(0, |n| n * n * map_faces),
                caster_passes,
                bound_triangles,
                infinite_sides: match v.technique {
                    RenderTechnique::Pass(Technique::Planar | Technique::RayQuery) | RenderTechnique::ShadowMap(_) => 0,
                    RenderTechnique::Pass(Technique::EdgeQuads) => twin.map_or(0, |t| t.0),
                    _ => s.totals.triangles.sides,
                },
                volume_fragments: match v.technique {
                    RenderTechnique::Pass(Technique::RayQuery) => twin.and_then(|t| t.1),
                    _ => None,
                },
                draws: s.totals.draws,
                cpu_plan_ms: median(a.plan),
                bytes: s.totals.bytes_sent,
                error_fraction: error.get(&v.technique).copied(),
                ..Default::default()
            };
            row.limits = self.limits;
            self.bar.inc(1);
            rows.push((row, (*v).clone()));
        }
        rows
    }
}

/// Each technique's worst-light error fraction, in the order given.
fn evaluate_fractions(r: &mut Renderer, name: &str, techniques: &[RenderTechnique]) -> Result<Vec<f64>> {
    let rows = evaluate(r, name, techniques, 1)?;
    if rows.len() != techniques.len() {
        return Err(Error::Internal(format!("accuracy rows: {} for {} techniques", rows.len(), techniques.len())));
    }
    Ok(rows.iter().map(|row| row.fraction).collect())
}

#[cfg(test)]
mod tests {
    use super::{frames_within, MIN_FRAMES};

    #[test]
    fn the_point_budget_cuts_only_heavy_points_and_never_below_the_floor() {
        // A light point keeps every frame.
        assert_eq!(frames_within(9, 0.5, 30.0), 9);
        // A heavy one is cut to what fits the budget...
        assert_eq!(frames_within(9, 4.0, 30.0), 7);
        // ...but keeps at least MIN_FRAMES, whatever a round takes.
        assert_eq!(frames_within(9, 20.0, 30.0), MIN_FRAMES);
        assert_eq!(frames_within(9, f64::INFINITY, 30.0), MIN_FRAMES);
        // No budget (tiny suites, explicit --frames): every frame; fewer asked than the floor: those.
        assert_eq!(frames_within(9, 100.0, f64::INFINITY), 9);
        assert_eq!(frames_within(1, 100.0, 30.0), 1);
        assert_eq!(frames_within(9, 0.0, 30.0), 9);
    }
}
