//! The TOML scene file format (see `scenes/default.toml` for an example).
//!
//! Rotation convention: `rotate_deg = [x, y, z]` is R = Rz * Ry * Rx (X applied first), the same
//! as glam's `Mat4::from_euler(EulerRot::ZYX, z, y, x)`. A mesh's transform is T * R * S.

mod area_light;
mod keys;
mod lights;
mod meshes;
mod motion;
mod spheres;

use super::motion::Motion;
use super::Scene;
use glam::Vec3;
use keys::{line_of, Ctx, FileScene};
use std::path::Path;
use umbrage::error::{Error, Result};

pub use keys::SHAPES;

/// Where `obj = "..."` paths are resolved.
pub enum ObjSource<'a> {
    /// A directory on disk (the scene file's).
    Dir(&'a Path),
    /// A built-in scene: paths resolve among the embedded files, relative to this
    /// repository-relative directory (e.g. `scenes/hard`).
    Builtin(&'a str),
}

/// Parses and validates a scene from TOML text. `origin` names the file in every error.
pub fn parse(src: &str, origin: &str, objs: ObjSource<'_>) -> Result<Scene> {
    parse_animated(src, origin, objs).map(|(scene, _)| scene)
}

/// [`parse`], with the scene's motion (spins and light paths).
pub fn parse_animated(src: &str, origin: &str, objs: ObjSource<'_>) -> Result<(Scene, Motion)> {
    let cx = Ctx { origin, src };
    let file: FileScene = toml::from_str(src).map_err(|e| match e.span() {
        Some(s) => cx.at(line_of(src, s.start), e.message().trim().to_string()),
        None => Error::input(origin, e.message().trim().to_string()),
    })?;
    let top = 0..0;
    let ambient = cx.color(&top, "ambient", file.ambient, Vec3::splat(0.08))?;

    let cs = file.camera.span();
    let camera = lights::camera(&cx, &cs, file.camera.into_inner())?;

    let mut lights = Vec::new();
    for sl in &file.light {
        lights.push(lights::light(&cx, &sl.span(), sl.get_ref(), camera.eye)?);
    }

    let mut meshes = Vec::new();
    for (i, sm) in file.mesh.iter().enumerate() {
        meshes.push(meshes::mesh(&cx, i, &sm.span(), sm.get_ref(), &objs)?);
    }

    let mut spheres = Vec::new();
    for (i, ss) in file.sphere.iter().enumerate() {
        let sp = spheres::sphere(&cx, i, &ss.span(), ss.get_ref())?;
        spheres::check_placement(&cx, &ss.span(), &sp, &camera, &lights)?;
        spheres.push(sp);
    }

    let motion = motion::motion(&cx, &file.mesh, &file.light, &lights)?;
    let name = file
        .name
        .unwrap_or_else(|| Path::new(origin).file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_else(|| origin.to_string()));
    Ok((Scene { name, camera, lights, meshes, ambient, spheres }, motion))
}

#[cfg(test)]
mod sphere_tests;
#[cfg(test)]
mod tests;
