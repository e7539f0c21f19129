//! Where `--method mesh`'s stencil differs from `mcguire`'s, by image size: every hard case and
//! built-in scene rendered with `mcguire`, `compute` and `mesh` at each size given (default
//! `128x96 128x128`), printing each (size, scene, light) whose stencil differs from
//! `mcguire`'s, and how many pixels. On Mesa lavapipe 25.0.7 (`eval "$(scripts/drivers.sh env
//! 25.0.7)"`) only the mesh path differs, and only where half the image's width or height is
//! not a power of two: lavapipe's mesh pipeline maps clip to window coordinates without the
//! FMA its vertex pipeline uses (docs/mesh.md, "Exactness").
//!
//! `cargo run --example mesh_viewport -- 128x96 128x128 256x192`
use umbrage::shadow::Method;
use umbrage_render::{RenderOptions, Renderer, Technique};

fn main() -> umbrage::Result<()> {
    let mut sizes: Vec<(u32, u32)> = Vec::new();
    for a in std::env::args().skip(1) {
        let size = a.split_once('x').and_then(|(w, h)| Some((w.parse().ok()?, h.parse().ok()?)));
        sizes.push(size.ok_or_else(|| umbrage::Error::input(a.to_string(), "not WxH"))?);
    }
    if sizes.is_empty() {
        sizes = vec![(128, 96), (128, 128)];
    }
    let mut ctx = umbrage::gpu::Context::new()?;
    if !ctx.features.mesh_shader {
        return Err(umbrage::Error::Unsupported("no mesh shaders: run on Mesa lavapipe 25.0.7 (scripts/drivers.sh)".into()));
    }
    println!("device: {}", ctx.info.name);
    let mut names: Vec<&str> = umbrage_scene::builtin_names().into_iter().filter(|n| n.starts_with("hard/")).collect();
    names.extend(["default", "stairs", "cubes", "spheres"]);
    for (w, h) in sizes {
        let mut differing = 0;
        for name in &names {
            let opts = RenderOptions { width: w, height: h, capture: true, ..Default::default() };
            let mut r = Renderer::new(ctx, umbrage_scene::load(name)?, opts)?;
            let mut frame = |t: Technique| {
                r.settings.technique = t.into();
                r.render().map(|f| f.stencil)
            };
            let reference = frame(Technique::Volumes(Method::McGuire))?;
            for (label, t) in [("compute", Technique::Compute), ("mesh", Technique::Mesh)] {
                for (li, (a, b)) in reference.iter().zip(&frame(t)?).enumerate() {
                    let n = a.iter().zip(b).filter(|(x, y)| x != y).count();
                    if n > 0 {
                        println!("{w}x{h} {name} light {li}: {label} differs from mcguire in {n} pixels");
                        differing += 1;
                    }
                }
            }
            ctx = r.into_context();
        }
        println!("{w}x{h}: {differing} (scene, light, method) triples differ");
    }
    Ok(())
}
