//! Scenes: camera, lights and meshes, from a TOML file, an OBJ, or a built-in name.
//!
//! The camera model here (pixel centres, Vulkan clip space, infinite far plane) is the one
//! both the GPU renderer and the CPU reference use; it is the only code they share.

use crate::geom::{Aabb, Mesh};
use glam::{Mat4, Vec3, Vec4};

/// A pinhole camera, right-handed, looking from `eye` to `target`.
#[derive(Clone, Debug, PartialEq)]
pub struct Camera {
    pub eye: Vec3,
    pub target: Vec3,
    pub up: Vec3,
    pub fov_y_deg: f32,
    pub near: f32,
}

impl Default for Camera {
    fn default() -> Self {
        Camera { eye: Vec3::new(0.0, 2.0, 6.0), target: Vec3::ZERO, up: Vec3::Y, fov_y_deg: 60.0, near: 0.1 }
    }
}

impl Camera {
    /// World -> view (right-handed, looking down -Z).
    pub fn view(&self) -> Mat4 {
        glam::camera::rh::view::look_at_mat4(self.eye, self.target, self.up.normalize())
    }
    /// View -> Vulkan clip space with the far plane at infinity: depth 0 at `near`, 1 at
    /// infinity; y points down in the framebuffer (row 0 is the top of the image).
    pub fn proj_infinite(&self, aspect: f32) -> Mat4 {
        let f = 1.0 / (self.fov_y_deg.to_radians() * 0.5).tan();
        Mat4::from_cols(
            Vec4::new(f / aspect, 0.0, 0.0, 0.0),
            Vec4::new(0.0, -f, 0.0, 0.0),
            Vec4::new(0.0, 0.0, -1.0, -1.0),
            Vec4::new(0.0, 0.0, -self.near, 0.0),
        )
    }
    /// Same with a finite far plane (used with depth clamp, `--depth-mode clamp`).
    pub fn proj_finite(&self, aspect: f32, far: f32) -> Mat4 {
        let f = 1.0 / (self.fov_y_deg.to_radians() * 0.5).tan();
        let n = self.near;
        let r = far / (n - far);
        Mat4::from_cols(
            Vec4::new(f / aspect, 0.0, 0.0, 0.0),
            Vec4::new(0.0, -f, 0.0, 0.0),
            Vec4::new(0.0, 0.0, r, -1.0),
            Vec4::new(0.0, 0.0, r * n, 0.0),
        )
    }
    /// The world-space ray through the centre of pixel (x, y) of a `width` x `height` image
    /// (row 0 at the top): origin on the near plane, unit direction. f64 for the reference.
    pub fn pixel_ray(&self, x: u32, y: u32, width: u32, height: u32) -> (glam::DVec3, glam::DVec3) {
        let aspect = width as f64 / height as f64;
        let ndc_x = (x as f64 + 0.5) / width as f64 * 2.0 - 1.0;
        let ndc_y = (y as f64 + 0.5) / height as f64 * 2.0 - 1.0;
        let t = (self.fov_y_deg as f64).to_radians() * 0.5;
        let t = t.tan();
        // view space: x right, y up, looking down -z; ndc y points down.
        let dir_v = glam::DVec3::new(ndc_x * t * aspect, -ndc_y * t, -1.0);
        let eye = self.eye.as_dvec3();
        let fwd = (self.target.as_dvec3() - eye).normalize();
        let right = fwd.cross(self.up.as_dvec3()).normalize();
        let up = right.cross(fwd);
        let d = right * dir_v.x + up * dir_v.y + fwd * (-dir_v.z);
        let origin = eye + d * self.near as f64;
        (origin, d.normalize())
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum LightKind {
    Point,
    Spot,
    Directional,
}

/// A light. `direction` is the unit direction the light travels (directional, spot).
#[derive(Clone, Debug, PartialEq)]
pub struct Light {
    pub kind: LightKind,
    pub position: Vec3,
    pub direction: Vec3,
    pub color: Vec3,
    pub intensity: f32,
    /// Attenuation range: beyond it the light contributes nothing (and casters are culled).
    pub radius: Option<f32>,
    /// Full cone angle of a spot light, degrees.
    pub cone_deg: f32,
}

impl Light {
    /// Homogeneous position: (position, 1) for point and spot, (-direction, 0) for directional
    /// (xyz pointing towards the light), as in McGuire et al. and the dump format.
    pub fn homogeneous(&self) -> Vec4 {
        match self.kind {
            LightKind::Directional => (-self.direction.normalize()).extend(0.0),
            _ => self.position.extend(1.0),
        }
    }
}

/// One mesh instance of a scene.
#[derive(Clone, Debug)]
pub struct SceneMesh {
    pub name: String,
    /// Object-space mesh, validated, CCW outward in world space after `transform`
    /// (a mirroring transform has its winding swapped at load).
    pub mesh: Mesh,
    /// Object -> world.
    pub transform: Mat4,
    pub color: Vec3,
    pub opacity: f32,
    pub casts_shadow: bool,
}

impl SceneMesh {
    pub fn world_bounds(&self) -> Aabb {
        self.mesh.bounds().transformed(&self.transform)
    }
}

#[derive(Clone, Debug)]
pub struct Scene {
    pub name: String,
    pub camera: Camera,
    pub lights: Vec<Light>,
    pub meshes: Vec<SceneMesh>,
    /// Ambient light colour (default 0.08 grey).
    pub ambient: Vec3,
}

pub mod builtin;
pub mod file;
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
    if let Some(text) = builtin::scene(spec) {
        let origin = format!("scenes/{spec}.toml");
        let dir = match origin.rfind('/') {
            Some(i) => origin[..i].to_string(),
            None => String::new(),
        };
        return file::parse(text, &origin, file::ObjSource::Builtin(&dir));
    }
    let path = Path::new(spec);
    if path.is_file() || spec.ends_with(".toml") {
        let text = std::fs::read_to_string(path).map_err(|e| Error::input(spec, format!("cannot read scene file: {e}")))?;
        let dir = path.parent().unwrap_or(Path::new(""));
        return load_str(&text, spec, dir);
    }
    Err(Error::UnknownName { what: "scene", name: spec.to_string(), expected: builtin_names().join(", ") })
}

/// Parses a scene from TOML text held in memory. `origin` names it in errors; `obj` paths
/// are resolved relative to `base_dir`.
pub fn load_str(toml: &str, origin: &str, base_dir: &Path) -> Result<Scene> {
    file::parse(toml, origin, file::ObjSource::Dir(base_dir))
}
