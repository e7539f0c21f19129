//! umbrage-scene: the scenes every harness crate draws (camera, lights and meshes from a TOML file, an OBJ or a built-in name), on the engine's geometry.
//!
//! Scenes: camera, lights and meshes, from a TOML file, an OBJ, or a built-in name.
//!
//! The camera and light models ([`Camera`], [`Light`]) are defined in [`geom::light`](umbrage::geom::light)
//! and re-exported here.

#![warn(missing_docs)]

use glam::{Mat4, Vec3};
use umbrage::geom::{Aabb, Mesh};

/// The camera and light models live in [`geom`](umbrage::geom) (the planner needs them and must not
/// depend on scenes); they are re-exported here so `scene::Light` etc. keep working.
pub use umbrage::geom::{Camera, Light, LightKind};

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
    /// This mesh as a shadow caster. A transparent mesh (opacity < 1) always takes the
    /// multiplicity path, whose count is the number of surfaces crossed (Kim et al. 2008): each
    /// one attenuates the light by `(1 - opacity) * color`.
    pub fn caster(&self) -> umbrage::error::Result<umbrage::shadow::Caster> {
        use umbrage::shadow::{Caster, CasterKind, TRANSMITTANCE_FLOOR};
        let mut c = Caster::new(&self.name, &self.mesh, self.transform)?;
        if self.opacity < 1.0 {
            let reason = match &c.kind {
                CasterKind::Multiplicity { reason } => reason.clone(),
                _ => format!("transparent (opacity {}): every surface crossed attenuates the light", self.opacity),
            };
            c.make_whole_multiplicity(reason);
            c.transmittance = Some(((1.0 - self.opacity) * self.color).max(Vec3::splat(TRANSMITTANCE_FLOOR)));
        }
        Ok(c)
    }

    /// World-space box of the object bounds' transformed corners (conservative).
    pub fn world_bounds(&self) -> Aabb {
        self.mesh.bounds().transformed(&self.transform)
    }
}

/// An analytic sphere of a scene (`[[sphere]]`): drawn exactly (ray-cast), casting a shadow
/// volume from its tangency circle as an n-gon ([`geom::sphere`](umbrage::geom::sphere)).
#[derive(Clone, Debug)]
pub struct SceneSphere {
    /// The table's `name`, else `sphere<i>`.
    pub name: String,
    /// Centre and radius, world space (f64).
    pub sphere: umbrage::geom::Sphere,
    /// Linear RGB albedo.
    pub color: Vec3,
    /// 1 (transparent spheres are refused at load).
    pub opacity: f32,
    /// Whether the sphere casts shadows (every sphere receives them).
    pub casts_shadow: bool,
    /// Fixed number of segments of the shadow volume's polygon (`None`: chosen per frame and
    /// light so the shadow's error stays under half a pixel).
    pub segments: Option<u32>,
}

/// Why a sphere cannot be rendered with this camera and these lights: the eye inside or on
/// it, or a positional light inside or on it while it casts shadows.
pub fn sphere_placement_problem(sp: &SceneSphere, camera: &Camera, lights: &[Light]) -> Option<String> {
    if sp.sphere.contains(camera.eye.as_dvec3()) {
        return Some(format!("{}: the camera eye {} is inside or on the sphere (not supported: move the eye out)", sp.name, camera.eye));
    }
    if sp.casts_shadow {
        for (li, l) in lights.iter().enumerate() {
            if l.kind != LightKind::Directional && sp.sphere.tangency(l.position.as_dvec3().extend(1.0)).is_none() {
                return Some(format!(
                    "{}: light {li} at {} is inside or on the shadow-casting sphere (it would light nothing: no tangent cone exists)",
                    sp.name, l.position
                ));
            }
        }
    }
    None
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
    /// Analytic spheres (`[[sphere]]`).
    pub spheres: Vec<SceneSphere>,
}

pub mod builtin;
pub mod file;
pub mod level;
pub mod motion;
pub mod obj;
pub mod shapes;

pub use obj::load_obj;

use std::path::Path;
use umbrage::error::{Error, Result};

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
