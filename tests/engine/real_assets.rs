//! Real assets (tests/data/assets, from Debian's assimp-testmodels): open, non-manifold and
//! inconsistently wound meshes take the multiplicity path, and every method's shadow mask
//! matches the CPU reference outside a 1-pixel band, with both counters.
use crate::common;
use umbrage_render::accuracy::evaluate;
use umbrage_render::{Counter, RenderOptions, Renderer};

fn scene(obj: &str, scale: f32, lift: f32, eye: [f32; 3]) -> String {
    format!(
        r#"
[camera]
eye = [{}, {}, {}]
target = [0.0, 0.8, 0.0]
[[light]]
kind = "point"
position = [2.0, 8.0, 3.0]
[[light]]
kind = "directional"
direction = [-0.4, -1.0, -0.2]
intensity = 0.5
[[mesh]]
shape = "plane"
size = [30.0, 30.0]
casts_shadow = false
[[mesh]]
name = "asset"
obj = "{obj}"
scale = {scale}
translate = [0.0, {lift}, 0.0]
rotate_deg = [0.0, 30.0, 0.0]
"#,
        eye[0], eye[1], eye[2]
    )
}

#[test]
fn real_open_and_non_manifold_assets_match_the_reference() {
    let Some(mut ctx) = common::context() else { return };
    let data = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/assets");
    let cases = [("spider.obj", 0.015, 1.2, [0.0, 3.0, 5.0]), ("WusonOBJ.obj", 1.0, 0.3, [0.5, 2.5, 4.5])];
    for (file, scale, lift, eye) in cases {
        let toml = scene(&format!("{data}/{file}"), scale, lift, eye);
        for counter in [Counter::Stencil, Counter::Float] {
            let scene = umbrage_scene::load_str(&toml, file, std::path::Path::new(data)).unwrap();
            let mut r = Renderer::new(ctx, scene, RenderOptions { width: 256, height: 192, counter, ..Default::default() }).unwrap();
            let stats = r.render().unwrap().stats;
            let asset = stats.lights[0].casters.iter().find(|c| c.name == "asset").unwrap();
            assert_eq!(asset.path, umbrage::shadow::VolumePath::Multiplicity, "{file}: {}", asset.path_reason);
            for row in evaluate(&mut r, file, &umbrage_render::Technique::all_volumes(), 1).unwrap() {
                assert!(
                    row.passed,
                    "{file} {} {:?}: {} mismatches of {} ({:.4}%)",
                    row.method,
                    counter,
                    row.mismatches,
                    row.compared,
                    row.fraction * 100.0
                );
            }
            r.context().check_validation().unwrap();
            ctx = r.into_context();
        }
    }
}
