//! CPU time per frame of the shadow pass, `mcguire` (CPU possible silhouettes) against
//! `compute` (GPU possible silhouettes), over a tessellation sweep of one caster: a UV sphere
//! of 1k to 1M triangles over a floor, one point light, the camera outside its volume
//! (z-pass) and inside it (z-fail with the fan dark cap).
//!
//! `cargo run --release --example compute_sweep [-- FRAMES]`: prints a markdown table of the
//! medians over FRAMES frames (default 7, after one warm-up frame): CPU ms (the pass's
//! planning with silhouettes + stream / record building, the renderer's recording included),
//! shadow triangles, GPU shadow ms (the determination, compute dispatches included), and the
//! geometry bytes the CPU sent. On a device with mesh shaders (`VK_EXT_mesh_shader`: Mesa
//! lavapipe 25.0.7, `eval "$(scripts/drivers.sh env 25.0.7)"`) `mesh` (mesh-shader extrusion)
//! joins the table, with its task stage's cull (`mesh`) and without it (`mesh (no task)`,
//! `PassToggles::mesh_task` off: every meshlet's mesh workgroup runs), and the mesh
//! workgroups that ran against the meshlets the draws covered. `SWEEP_QUICK=1`: the 10k and
//! 100k spheres only, both views.
use umbrage::shadow::Method;
use umbrage_render::{RenderOptions, Renderer, Technique};

fn scene(segments: u32, rings: u32, eye: [f32; 3]) -> String {
    format!(
        r#"
ambient = [0.05, 0.05, 0.05]
[camera]
eye = [{}, {}, {}]
target = [0.0, 0.0, 0.0]
[[light]]
kind = "point"
position = [1.0, 8.0, 2.0]
[[mesh]]
name = "floor"
shape = "plane"
size = [30.0, 30.0]
casts_shadow = false
[[mesh]]
name = "sphere"
shape = "sphere"
radius = 1.0
segments = {segments}
rings = {rings}
translate = [0.0, 2.5, 0.0]
"#,
        eye[0], eye[1], eye[2]
    )
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() -> umbrage::Result<()> {
    let frames: usize = std::env::args().nth(1).and_then(|a| a.parse().ok()).unwrap_or(7);
    let mut ctx = umbrage::gpu::Context::new()?;
    println!("device: {}, 320x240, medians of {frames} frames\n", ctx.info.name);
    println!(
        "| view | triangles | method | CPU ms (plan + record) | of which silhouettes | shadow triangles | GPU shadow ms | of which GPU silhouettes | bytes sent | mesh workgroups run / meshlets |"
    );
    println!("|---|---:|---|---:|---:|---:|---:|---:|---:|---:|");
    let quick = std::env::var_os("SWEEP_QUICK").is_some();
    // (label, technique, the task stage's cull)
    let mut variants = vec![("mcguire", Technique::Volumes(Method::McGuire), true), ("compute", Technique::Compute, true)];
    if ctx.features.mesh_shader {
        variants.push(("mesh", Technique::Mesh, true));
        if ctx.features.task_shader {
            variants.push(("mesh (no task)", Technique::Mesh, false));
        }
    }
    let views = [("outside (z-pass)", [0.0f32, 4.0, 9.0]), ("in the shadow (z-fail, fan cap)", [0.2, 0.3, 0.4])];
    let sizes = [(32u32, 17u32), (100, 51), (317, 159), (1000, 501)];
    for (view, eye) in &views {
        for &(segments, rings) in if quick { &sizes[1..3] } else { &sizes[..] } {
            let eye = *eye;
            let src = scene(segments, rings, eye);
            let s = umbrage_scene::load_str(&src, "sweep", std::path::Path::new("."))?;
            let tris = s.meshes[1].mesh.triangles.len();
            let opts = RenderOptions { width: 320, height: 240, ..Default::default() };
            let mut r = Renderer::new(ctx, s, opts)?;
            for &(label, t, task) in &variants {
                r.settings.technique = t.into();
                r.settings.toggles.mesh_task = task;
                r.render()?; // warm-up: uploads, static tables, pipelines
                let (mut cpu, mut sil, mut gpu, mut gsil, mut bytes, mut st) = (Vec::new(), Vec::new(), Vec::new(), Vec::new(), 0, 0);
                let mut groups = (0, 0);
                for _ in 0..frames {
                    let f = r.render()?;
                    cpu.push(f.stats.cpu_ms.plan + f.stats.cpu_ms.record);
                    sil.push(f.stats.cpu_ms.silhouettes);
                    gpu.push(f.stats.gpu_ms.as_ref().map_or(f64::NAN, |g| g.shadow));
                    gsil.push(f.stats.gpu_ms.as_ref().map_or(f64::NAN, |g| g.silhouettes));
                    bytes = f.stats.totals.bytes_sent;
                    st = f.stats.totals.triangles.total();
                    groups = (f.stats.totals.mesh_workgroups, f.stats.totals.mesh_meshlets);
                }
                let groups = if t == Technique::Mesh { format!("{} / {}", groups.0, groups.1) } else { "-".into() };
                println!(
                    "| {view} | {tris} | {label} | {:.3} | {:.3} | {st} | {:.2} | {:.2} | {bytes} | {groups} |",
                    median(cpu),
                    median(sil),
                    median(gpu),
                    median(gsil)
                );
            }
            ctx = r.into_context();
        }
    }
    Ok(())
}
