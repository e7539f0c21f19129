//! The scenes a bound's ablation renders ([`super::proof`]): the same shapes with a coarser
//! tessellation (a vertex bound's test) and the casters merged into one (a draw bound's). A
//! fill bound's test needs no other scene: the same volumes at half the width and height.

use super::scenes::{merged, SweepScene};
use super::sweeps::PointScene;
use umbrage::error::{Error, Result};
use umbrage_scene::file::{self, ObjSource};
use umbrage_scene::Scene;

/// Each tessellation parameter of a built-in shape, its default and its least value (the
/// scene format's: `src/scene/file/meshes.rs`).
const TESSELLATION: &[(&str, &str, i64, i64)] = &[
    ("sphere", "segments", 24, 3),
    ("sphere", "rings", 16, 2),
    ("torus", "segments", 32, 3),
    ("torus", "sides", 16, 3),
    ("cylinder", "segments", 24, 3),
    ("bumpy_slab", "divisions", 16, 1),
];

/// A scene file's text with every shadow-casting shape's tessellation parameters halved
/// (spheres and tori: about a quarter of the triangles; the same shapes, radii and places);
/// `None` where no caster has a parameter left to halve (boxes, grids of cubes, OBJ files).
pub fn coarser_toml(text: &str) -> Result<Option<String>> {
    let mut doc: toml::Table = toml::from_str(text).map_err(|e| Error::input("scene TOML", e.to_string()))?;
    let mut changed = false;
    if let Some(toml::Value::Array(meshes)) = doc.get_mut("mesh") {
        for m in meshes.iter_mut().filter_map(|m| m.as_table_mut()) {
            if m.get("casts_shadow").and_then(|v| v.as_bool()) == Some(false) {
                continue;
            }
            let Some(shape) = m.get("shape").and_then(|v| v.as_str()).map(str::to_string) else { continue };
            for &(_, key, default, least) in TESSELLATION.iter().filter(|(s, ..)| *s == shape) {
                let now = m.get(key).and_then(|v| v.as_integer()).unwrap_or(default);
                let half = (now / 2).max(least);
                if half < now {
                    m.insert(key.to_string(), toml::Value::Integer(half));
                    changed = true;
                }
            }
        }
    }
    if !changed {
        return Ok(None);
    }
    toml::to_string(&doc).map(Some).map_err(|e| Error::input("scene TOML", e.to_string()))
}

/// The point's scene with a coarser tessellation of the same shapes, and its name; `None`
/// where it has none (see [`coarser_toml`]; a sphere grid already at its least tessellation).
pub fn coarser(p: &PointScene) -> Result<Option<(Scene, String)>> {
    match p {
        PointScene::Param(s) => {
            let c = SweepScene { triangles: s.triangles / 4, ..*s };
            Ok((c.built_triangles() < s.built_triangles()).then(|| (c.build(), c.name())))
        }
        PointScene::Named(n) => {
            let (text, origin, dir) = match umbrage_scene::builtin::scene(n) {
                Some(t) => {
                    let origin = format!("scenes/{n}.toml");
                    let dir = origin.rsplit_once('/').map_or(String::new(), |(d, _)| d.to_string());
                    (t.to_string(), origin, dir)
                }
                None => {
                    let text = std::fs::read_to_string(n).map_err(|e| Error::input(n, format!("cannot read scene file: {e}")))?;
                    (text, n.clone(), String::new())
                }
            };
            let Some(coarse) = coarser_toml(&text)? else { return Ok(None) };
            let name = format!("{n}+coarser");
            let scene = match umbrage_scene::builtin::scene(n) {
                Some(_) => file::parse(&coarse, &origin, ObjSource::Builtin(&dir))?,
                None => {
                    let dir = std::path::Path::new(n).parent().unwrap_or(std::path::Path::new(""));
                    file::parse(&coarse, &origin, ObjSource::Dir(dir))?
                }
            };
            Ok(Some((scene, name)))
        }
    }
}

/// `scene` with its opaque shadow-casting meshes merged into one (the same triangles in world
/// space, one caster: one draw where there were many); `None` where it has fewer than two.
pub fn merged_casters(scene: &Scene, name: &str) -> Option<(Scene, String)> {
    let opaque = |m: &umbrage_scene::SceneMesh| m.casts_shadow && m.opacity >= 1.0;
    let casters: Vec<_> = scene.meshes.iter().filter(|m| opaque(m)).cloned().collect();
    if casters.len() < 2 {
        return None;
    }
    let mut out = scene.clone();
    out.meshes.retain(|m| !opaque(m));
    out.meshes.push(merged(&casters, "merged-casters"));
    let name = format!("{name}+merged");
    out.name = name.clone();
    Some((out, name))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn caster_triangles(s: &Scene) -> usize {
        s.meshes.iter().filter(|m| m.casts_shadow).map(|m| m.mesh.triangles.len()).sum()
    }

    #[test]
    fn the_named_scenes_coarsen_their_curved_casters_only() {
        // bench/vertex: 36 spheres 96x64 -> 48x32, about a quarter of the triangles.
        let p = PointScene::Named("bench/vertex".into());
        let fine = umbrage_scene::load("bench/vertex").unwrap();
        let (coarse, name) = coarser(&p).unwrap().expect("spheres coarsen");
        assert_eq!(name, "bench/vertex+coarser");
        let ratio = caster_triangles(&coarse) as f64 / caster_triangles(&fine) as f64;
        assert!((0.2..0.3).contains(&ratio), "{ratio}");
        assert_eq!(coarse.meshes.len(), fine.meshes.len());
        assert_eq!(coarse.lights.len(), fine.lights.len());
        // bench/caps: tori; bench/fill: a grid of cubes has nothing to coarsen.
        let caps = coarser(&PointScene::Named("bench/caps".into())).unwrap().expect("tori coarsen");
        assert!(caster_triangles(&caps.0) < caster_triangles(&umbrage_scene::load("bench/caps").unwrap()));
        assert!(coarser(&PointScene::Named("bench/fill".into())).unwrap().is_none());
        // A receiver's tessellation is left alone; a bad file is an error, not a panic.
        let t = "[[mesh]]\nname = \"s\"\nshape = \"sphere\"\ncasts_shadow = false\n";
        assert_eq!(coarser_toml(t).unwrap(), None);
        assert!(coarser_toml("[[mesh]\n").is_err());
        assert!(coarser(&PointScene::Named("/no/such/scene.toml".into())).is_err());
    }

    #[test]
    fn sphere_grids_coarsen_until_their_least_tessellation() {
        let s = SweepScene { casters: 4, triangles: 4 * 512, ..Default::default() };
        let (coarse, name) = coarser(&PointScene::Param(s)).unwrap().unwrap();
        assert!(caster_triangles(&coarse) < caster_triangles(&s.build()) / 3, "{name}");
        let least = SweepScene { casters: 4, triangles: 4 * 24, ..Default::default() };
        assert!(coarser(&PointScene::Param(least)).unwrap().is_none());
    }

    #[test]
    fn merging_keeps_every_triangle_in_one_caster() {
        let s = umbrage_scene::load("bench/vertex").unwrap();
        let (m, name) = merged_casters(&s, "bench/vertex").unwrap();
        assert_eq!(name, "bench/vertex+merged");
        assert_eq!(m.meshes.iter().filter(|m| m.casts_shadow).count(), 1);
        assert_eq!(caster_triangles(&m), caster_triangles(&s));
        // Receivers stay; one caster has nothing to merge.
        assert_eq!(m.meshes.iter().filter(|m| !m.casts_shadow).count(), s.meshes.iter().filter(|m| !m.casts_shadow).count());
        let one = SweepScene { casters: 1, ..Default::default() }.build();
        assert!(merged_casters(&one, "one").is_none());
    }
}
