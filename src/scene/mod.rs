//! Scenes: camera, lights and meshes, from a TOML file, an OBJ, or a built-in name.
//!
//! The camera and light models ([`Camera`], [`Light`]) are defined in [`geom::light`](crate::geom::light)
//! and re-exported here.

#![warn(missing_docs)]

use crate::geom::{Aabb, Mesh};
use glam::{Mat4, Vec3};

/// The camera and light models live in [`geom`](crate::geom) (the planner needs them and must not
/// depend on scenes); they are re-exported here so `scene::Light` etc. keep working.
pub use crate::geom::{Camera, Light, LightKind};

/// One mesh instance of a scene.
#[derive(Clone, Debug)]
pub struct SceneMesh {
    /// The mesh's name (the scene file's `name`, else `mesh<i>-<kind>`), used in messages and stats.
    pub name: String,
    /// Object-space mesh, validated, CCW outward in world space after `transform`
    /// (a mirroring transform has its winding swapped at load).
    pub mesh: Mesh,
    /// Object -> world.
    pub transform: Mat4,
    /// Linear RGB albedo; for a transparent mesh also the filter colour of the light it lets through.
    pub color: Vec3,
    /// 1 = opaque; below 1 every surface lets `(1 - opacity) * color` of the light through.
    pub opacity: f32,
    /// Whether the mesh casts shadows (every mesh receives them).
    pub casts_shadow: bool,
}

impl SceneMesh {
    /// World-space box of the object bounds' transformed corners (conservative).
    pub fn world_bounds(&self) -> Aabb {
        self.mesh.bounds().transformed(&self.transform)
    }
}

/// A whole scene: one camera, any number of lights and meshes.
#[derive(Clone, Debug)]
pub struct Scene {
    /// The scene file's `name`, else its file stem; used in reports.
    pub name: String,
    /// The camera the frame is rendered from.
    pub camera: Camera,
    /// Every light, each with its own shadow determination and illumination pass.
    pub lights: Vec<Light>,
    /// Every mesh instance, casters and receivers alike.
    pub meshes: Vec<SceneMesh>,
    /// Ambient light colour (default 0.08 grey).
    pub ambient: Vec3,
}

pub mod builtin;
pub mod file;
pub mod motion;
pub mod obj;
pub mod shapes;

pub use obj::load_obj;

use crate::error::{Error, Result};
use std::path::Path;

/// Names accepted by [`load`] besides file paths: `default`, `stairs`, `cubes`, `spheres`
/// and the hard cases `hard/<name>`.
pub fn builtin_names() -> Vec<&'static str> {
    builtin::SCENES.iter().map(|(n, _)| *n).collect()
}

/// Loads a scene: a built-in name (see [`builtin_names`]; takes precedence) or the path of a
/// TOML scene file. A name that is neither a built-in nor an existing file (and does not end
/// in `.toml`) is [`Error::UnknownName`].
pub fn load(spec: &str) -> Result<Scene> {
    load_animated(spec).map(|(scene, _)| scene)
}

/// [`load`], with the scene's motion (spins and light paths; empty for a static scene).
pub fn load_animated(spec: &str) -> Result<(Scene, motion::Motion)> {
    if let Some(text) = builtin::scene(spec) {
        let origin = format!("scenes/{spec}.toml");
        let dir = match origin.rfind('/') {
            Some(i) => origin[..i].to_string(),
            None => String::new(),
        };
        return file::parse_animated(text, &origin, file::ObjSource::Builtin(&dir));
    }
    let path = Path::new(spec);
    if path.is_file() || spec.ends_with(".toml") {
        let text = std::fs::read_to_string(path).map_err(|e| Error::input(spec, format!("cannot read scene file: {e}")))?;
        let dir = path.parent().unwrap_or(Path::new(""));
        return file::parse_animated(&text, spec, file::ObjSource::Dir(dir));
    }
    Err(Error::UnknownName { what: "scene", name: spec.to_string(), expected: builtin_names().join(", ") })
}

/// Parses a scene from TOML text held in memory. `origin` names it in errors; `obj` paths
/// are resolved relative to `base_dir`.
pub fn load_str(toml: &str, origin: &str, base_dir: &Path) -> Result<Scene> {
    file::parse(toml, origin, file::ObjSource::Dir(base_dir))
}
