//! `umbrage bench`: every method's speed *against its error*, measured side by side in one run
//! on one device: per scene and method, the median of N frames (GPU timestamps and wall
//! clock), the shadow geometry sent, and the mismatch fraction against the CPU reference.

use crate::accuracy::evaluate;
use crate::error::{Error, Result};
use crate::gpu::Context;
use crate::render::{Counter, RenderOptions, Renderer};
use crate::shadow::Method;
use serde::Serialize;

#[derive(Clone, Debug, Serialize)]
pub struct BenchRow {
    pub scene: String,
    pub method: String,
    pub counter: String,
    pub index_format: String,
    pub frames: usize,
    pub gpu_frame_ms: Option<f64>,
    pub gpu_shadow_ms: Option<f64>,
    pub gpu_illuminate_ms: Option<f64>,
    pub wall_ms: f64,
    pub cpu_plan_ms: f64,
    pub shadow_triangles: u64,
    pub shadow_bytes: u64,
    /// Worst light's mismatches outside a 1-pixel band / compared pixels.
    pub error_fraction: f64,
    pub cases: [u64; 4],
}

#[derive(Clone, Debug, Serialize)]
pub struct BenchReport {
    pub device: String,
    pub driver: String,
    pub width: u32,
    pub height: u32,
    pub rows: Vec<BenchRow>,
}

fn median(mut v: Vec<f64>) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

pub struct BenchConfig {
    pub scenes: Vec<String>,
    pub methods: Vec<Method>,
    /// Each method runs with each counter (stencil, float), side by side.
    pub counters: Vec<Counter>,
    /// Also measure the shadow-map baseline (PCF) with maps of this many texels a side.
    pub shadow_map: Option<u32>,
    /// Also measure the GPU-only edge-quad method (with the first counter).
    pub edge_quads: bool,
    pub frames: usize,
    pub opts: RenderOptions,
}

pub fn run(ctx: Context, cfg: &BenchConfig, mut progress: impl FnMut(&BenchRow)) -> Result<BenchReport> {
    if cfg.frames == 0 {
        return Err(Error::Other("--frames must be at least 1".into()));
    }
    let device = ctx.info.name.clone();
    let driver = format!("{} {}", ctx.info.driver, ctx.info.driver_info);
    let mut ctx = Some(ctx);
    let mut rows = Vec::new();
    for name in &cfg.scenes {
        let scene = crate::scene::load(name)?;
        let c = ctx.take().ok_or_else(|| Error::Other("context lost".into()))?;
        let mut r = Renderer::new(c, scene, cfg.opts.clone())?;
        // (method, counter, shadow-map size) variants, and their error against the reference.
        let mut variants: Vec<(Method, Counter, Option<u32>, bool)> = Vec::new();
        let mut errors = Vec::new();
        for &counter in &cfg.counters {
            r.opts.counter = counter;
            for (m, e) in cfg.methods.iter().zip(evaluate(&mut r, name, &cfg.methods, 1)?) {
                variants.push((*m, counter, None, false));
                errors.push(e);
            }
        }
        if let Some(size) = cfg.shadow_map {
            r.opts.shadow_map = Some(size);
            errors.extend(evaluate(&mut r, name, &[Method::McGuire], 1)?);
            variants.push((Method::McGuire, Counter::Float, Some(size), false));
            r.opts.shadow_map = None;
        }
        if cfg.edge_quads {
            let counter = cfg.counters.first().copied().unwrap_or(Counter::Stencil);
            r.opts.counter = counter;
            r.opts.edge_quads = true;
            errors.extend(evaluate(&mut r, name, &[Method::McGuire], 1)?);
            variants.push((Method::McGuire, counter, None, true));
            r.opts.edge_quads = false;
        }
        // Round-robin over methods, frame by frame, so that drift (thermal, other load) hits
        // every method alike: the ratios are measured side by side.
        #[derive(Default)]
        struct Acc {
            gpu: Vec<f64>,
            shadow: Vec<f64>,
            illum: Vec<f64>,
            wall: Vec<f64>,
            plan: Vec<f64>,
            last: Option<crate::render::Stats>,
        }
        let mut acc: Vec<Acc> = variants.iter().map(|_| Acc::default()).collect();
        for frame in 0..=cfg.frames {
            for (k, &(method, counter, shadow_map, edge_quads)) in variants.iter().enumerate() {
                r.opts.method = method;
                r.opts.counter = counter;
                r.opts.shadow_map = shadow_map;
                r.opts.edge_quads = edge_quads;
                let f = r.render()?;
                if frame == 0 {
                    continue; // warm-up: buffers sized, caches hot
                }
                let a = &mut acc[k];
                if let Some(g) = &f.stats.gpu_ms {
                    a.gpu.push(g.frame);
                    a.shadow.push(g.shadow);
                    a.illum.push(g.illuminate);
                }
                a.wall.push(f.stats.wall_ms);
                a.plan.push(f.stats.cpu_ms.plan + f.stats.cpu_ms.silhouettes);
                a.last = Some(f.stats);
            }
        }
        r.opts.shadow_map = None;
        r.opts.edge_quads = false;
        for ((&(method, counter, shadow_map, edge_quads), err), a) in variants.iter().zip(&errors).zip(acc) {
            let s = a.last.ok_or_else(|| Error::Other("no frame".into()))?;
            let c = &s.totals.cases;
            let row = BenchRow {
                scene: name.clone(),
                method: match (shadow_map, edge_quads) {
                    (Some(size), _) => format!("shadowmap-{size}"),
                    (None, true) => "edgequad".to_string(),
                    (None, false) => method.to_string(),
                },
                counter: counter.name().to_string(),
                index_format: s.index_format.clone(),
                frames: cfg.frames,
                gpu_frame_ms: (!a.gpu.is_empty()).then(|| median(a.gpu)),
                gpu_shadow_ms: (!a.shadow.is_empty()).then(|| median(a.shadow)),
                gpu_illuminate_ms: (!a.illum.is_empty()).then(|| median(a.illum)),
                wall_ms: median(a.wall),
                cpu_plan_ms: median(a.plan),
                shadow_triangles: s.totals.triangles.total(),
                shadow_bytes: s.totals.index_bytes + s.totals.vertex_bytes,
                error_fraction: err.fraction,
                cases: [c.culled, c.zpass, c.zfail, c.zfail_light_cap],
            };
            progress(&row);
            rows.push(row);
        }
        ctx = Some(r.into_context());
    }
    Ok(BenchReport { device, driver, width: cfg.opts.width, height: cfg.opts.height, rows })
}

impl BenchReport {
    pub fn markdown(&self) -> String {
        let mut s = format!(
            "Device: {} ({}), {}x{}. Medians; error = mismatched pixels outside a 1-pixel band vs the CPU reference (worst light).\n\n",
            self.device, self.driver, self.width, self.height
        );
        s += "| scene | method | counter | GPU frame ms | GPU shadow ms | wall ms | plan ms | shadow tris | bytes | error | cases c/1/2/3 |\n";
        s += "|---|---|---|---|---|---|---|---|---|---|---|\n";
        let f = |v: Option<f64>| v.map(|x| format!("{x:.2}")).unwrap_or_else(|| "—".into());
        for r in &self.rows {
            s += &format!(
                "| {} | {} | {} | {} | {} | {:.2} | {:.3} | {} | {} | {:.4}% | {}/{}/{}/{} |\n",
                r.scene,
                r.method,
                r.counter,
                f(r.gpu_frame_ms),
                f(r.gpu_shadow_ms),
                r.wall_ms,
                r.cpu_plan_ms,
                r.shadow_triangles,
                r.shadow_bytes,
                r.error_fraction * 100.0,
                r.cases[0],
                r.cases[1],
                r.cases[2],
                r.cases[3]
            );
        }
        s
    }
}
