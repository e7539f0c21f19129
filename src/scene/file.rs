//! The TOML scene file format (see `scenes/default.toml` for an example).
//!
//! Rotation convention: `rotate_deg = [x, y, z]` is R = Rz * Ry * Rx (X applied first), the same
//! as glam's `Mat4::from_euler(EulerRot::ZYX, z, y, x)`. A mesh's transform is T * R * S.

use super::{builtin, obj, shapes, Camera, Light, LightKind, Scene, SceneMesh};
use crate::error::{Error, Result};
use crate::geom::Mesh;
use glam::{Mat4, Vec2, Vec3};
use serde::Deserialize;
use std::ops::Range;
use std::path::{Path, PathBuf};
use toml::Spanned;

/// Where `obj = "..."` paths are resolved.
pub(crate) enum ObjSource<'a> {
    /// A directory on disk (the scene file's).
    Dir(&'a Path),
    /// A built-in scene: paths resolve among the embedded files, relative to this
    /// repository-relative directory (e.g. `scenes/hard`).
    Builtin(&'a str),
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct FileScene {
    name: Option<String>,
    ambient: Option<[f64; 3]>,
    camera: Spanned<FileCamera>,
    #[serde(default)]
    light: Vec<Spanned<FileLight>>,
    #[serde(default)]
    mesh: Vec<Spanned<FileMesh>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct FileCamera {
    eye: [f64; 3],
    target: [f64; 3],
    up: Option<[f64; 3]>,
    fov_y_deg: Option<f64>,
    near: Option<f64>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct FileLight {
    kind: String,
    position: Option<[f64; 3]>,
    direction: Option<[f64; 3]>,
    color: Option<[f64; 3]>,
    intensity: Option<f64>,
    radius: Option<f64>,
    cone_deg: Option<f64>,
}

#[derive(Deserialize, Clone)]
#[serde(untagged)]
enum NumOrVec {
    Num(f64),
    Vec(Vec<f64>),
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct FileMesh {
    obj: Option<String>,
    shape: Option<String>,
    // shape parameters
    size: Option<NumOrVec>,
    radius: Option<f64>,
    segments: Option<i64>,
    rings: Option<i64>,
    major_radius: Option<f64>,
    minor_radius: Option<f64>,
    sides: Option<i64>,
    height: Option<f64>,
    steps: Option<i64>,
    step: Option<[f64; 3]>,
    count: Option<NumOrVec>,
    spacing: Option<f64>,
    offset: Option<[f64; 3]>,
    divisions: Option<i64>,
    bump: Option<f64>,
    // instance
    name: Option<String>,
    translate: Option<[f64; 3]>,
    rotate_deg: Option<[f64; 3]>,
    scale: Option<NumOrVec>,
    color: Option<[f64; 3]>,
    opacity: Option<f64>,
    casts_shadow: Option<bool>,
}

/// Shape names and the parameter keys each accepts.
pub const SHAPES: &[(&str, &[&str])] = &[
    ("plane", &["size"]),
    ("box", &["size"]),
    ("sphere", &["radius", "segments", "rings"]),
    ("torus", &["major_radius", "minor_radius", "segments", "sides"]),
    ("cylinder", &["radius", "height", "segments"]),
    ("stairs", &["steps", "step"]),
    ("cube_grid", &["count", "size", "spacing"]),
    ("box_stack", &["count", "size", "offset"]),
    ("bumpy_slab", &["size", "divisions", "bump"]),
];

fn line_of(src: &str, offset: usize) -> usize {
    src.as_bytes()[..offset.min(src.len())].iter().filter(|&&b| b == b'\n').count() + 1
}

/// Error context: the scene file's name and text.
struct Ctx<'a> {
    origin: &'a str,
    src: &'a str,
}

impl Ctx<'_> {
    fn at(&self, line: usize, msg: impl Into<String>) -> Error {
        Error::input(format!("{}:{line}", self.origin), msg)
    }
    /// The line of `key = ...` inside the table starting at `span` (up to the next table
    /// header), or the table's first line.
    fn key_line(&self, span: &Range<usize>, key: &str) -> usize {
        let start = span.start.min(self.src.len());
        let mut off = start;
        for (i, line) in self.src[start..].split_inclusive('\n').enumerate() {
            let t = line.trim_start();
            if i > 0 && t.starts_with('[') {
                break;
            }
            if let Some(rest) = t.strip_prefix(key) {
                if rest.trim_start().starts_with('=') {
                    return line_of(self.src, off);
                }
            }
            off += line.len();
        }
        line_of(self.src, start)
    }
    fn key_err(&self, span: &Range<usize>, key: &str, msg: impl std::fmt::Display) -> Error {
        self.at(self.key_line(span, key), format!("{key}: {msg}"))
    }
    fn num(&self, span: &Range<usize>, key: &str, v: f64) -> Result<f32> {
        let f = v as f32;
        if f.is_finite() {
            Ok(f)
        } else {
            Err(self.key_err(span, key, format!("non-finite number {v} (nan/inf or out of f32 range)")))
        }
    }
    fn v3(&self, span: &Range<usize>, key: &str, v: [f64; 3]) -> Result<Vec3> {
        Ok(Vec3::new(self.num(span, key, v[0])?, self.num(span, key, v[1])?, self.num(span, key, v[2])?))
    }
    fn color(&self, span: &Range<usize>, key: &str, v: Option<[f64; 3]>, default: Vec3) -> Result<Vec3> {
        let c = match v {
            Some(v) => self.v3(span, key, v)?,
            None => default,
        };
        if c.min_element() < 0.0 {
            return Err(self.key_err(span, key, "colour components must be >= 0"));
        }
        Ok(c)
    }
    fn positive(&self, span: &Range<usize>, key: &str, v: Option<f64>, default: f32) -> Result<f32> {
        let x = match v {
            Some(v) => self.num(span, key, v)?,
            None => default,
        };
        if x <= 0.0 {
            return Err(self.key_err(span, key, format!("must be > 0, got {x}")));
        }
        Ok(x)
    }
    fn int(&self, span: &Range<usize>, key: &str, v: Option<i64>, default: u32, min: u32, max: u32) -> Result<u32> {
        let x = v.unwrap_or(default as i64);
        if x < min as i64 || x > max as i64 {
            return Err(self.key_err(span, key, format!("must be an integer in [{min}, {max}], got {x}")));
        }
        Ok(x as u32)
    }
    fn vecn(&self, span: &Range<usize>, key: &str, v: &[f64], n: usize) -> Result<Vec<f32>> {
        if v.len() != n {
            return Err(self.key_err(span, key, format!("expected {n} numbers, got {}", v.len())));
        }
        v.iter().map(|&x| self.num(span, key, x)).collect()
    }
    fn size_vec(&self, span: &Range<usize>, key: &str, v: &Option<NumOrVec>, default: &[f32]) -> Result<Vec<f32>> {
        let out = match v {
            None => default.to_vec(),
            Some(NumOrVec::Vec(a)) => self.vecn(span, key, a, default.len())?,
            Some(NumOrVec::Num(_)) => return Err(self.key_err(span, key, format!("expected an array of {} numbers", default.len()))),
        };
        if out.iter().any(|&x| x <= 0.0) {
            return Err(self.key_err(span, key, "every component must be > 0"));
        }
        Ok(out)
    }
}

/// Parses and validates a scene from TOML text. `origin` names the file in every error.
pub(crate) fn parse(src: &str, origin: &str, objs: ObjSource<'_>) -> Result<Scene> {
    let cx = Ctx { origin, src };
    let file: FileScene = toml::from_str(src).map_err(|e| match e.span() {
        Some(s) => cx.at(line_of(src, s.start), e.message().trim().to_string()),
        None => Error::input(origin, e.message().trim().to_string()),
    })?;
    let top = 0..0;
    let ambient = cx.color(&top, "ambient", file.ambient, Vec3::splat(0.08))?;

    // camera
    let cs = file.camera.span();
    let c = file.camera.into_inner();
    let camera = Camera {
        eye: cx.v3(&cs, "eye", c.eye)?,
        target: cx.v3(&cs, "target", c.target)?,
        up: match c.up {
            Some(u) => cx.v3(&cs, "up", u)?,
            None => Vec3::Y,
        },
        fov_y_deg: match c.fov_y_deg {
            Some(f) => cx.num(&cs, "fov_y_deg", f)?,
            None => 60.0,
        },
        near: cx.positive(&cs, "near", c.near, 0.1)?,
    };
    let view = camera.target - camera.eye;
    if view.length_squared() == 0.0 || !view.is_finite() {
        return Err(cx.key_err(&cs, "target", "camera target must differ from eye"));
    }
    if camera.up.length_squared() == 0.0 || view.normalize().cross(camera.up.normalize()).length() < 1e-4 {
        return Err(cx.key_err(&cs, "up", "camera up must be nonzero and not parallel to the view direction"));
    }
    if !(camera.fov_y_deg > 0.0 && camera.fov_y_deg < 180.0) {
        return Err(cx.key_err(&cs, "fov_y_deg", format!("must be in (0, 180), got {}", camera.fov_y_deg)));
    }

    // lights
    let mut lights = Vec::new();
    for sl in &file.light {
        let s = sl.span();
        let l = sl.get_ref();
        let kind = match l.kind.as_str() {
            "point" => LightKind::Point,
            "spot" => LightKind::Spot,
            "directional" => LightKind::Directional,
            other => {
                return Err(Error::UnknownName {
                    what: "light kind",
                    name: other.to_string(),
                    expected: format!("point, spot, directional; at {}:{}", origin, cx.key_line(&s, "kind")),
                })
            }
        };
        let positional = kind != LightKind::Directional;
        let position = match (positional, l.position) {
            (true, Some(p)) => cx.v3(&s, "position", p)?,
            (true, None) => return Err(cx.at(line_of(src, s.start), format!("{} light needs a position", l.kind))),
            (false, Some(_)) => return Err(cx.key_err(&s, "position", "a directional light has no position")),
            (false, None) => Vec3::ZERO,
        };
        let direction = match (kind != LightKind::Point, l.direction) {
            (true, Some(d)) => {
                let d = cx.v3(&s, "direction", d)?;
                if d.length_squared() == 0.0 || !d.normalize().is_finite() {
                    return Err(cx.key_err(&s, "direction", "direction must be a nonzero vector"));
                }
                d.normalize()
            }
            (true, None) => return Err(cx.at(line_of(src, s.start), format!("{} light needs a direction", l.kind))),
            (false, Some(_)) => return Err(cx.key_err(&s, "direction", "a point light has no direction")),
            (false, None) => Vec3::NEG_Y,
        };
        let cone_deg = match (kind == LightKind::Spot, l.cone_deg) {
            (true, c) => {
                let c = match c {
                    Some(c) => cx.num(&s, "cone_deg", c)?,
                    None => 45.0,
                };
                if !(c > 0.0 && c < 180.0) {
                    return Err(cx.key_err(&s, "cone_deg", format!("must be in (0, 180), got {c}")));
                }
                c
            }
            (false, Some(_)) => return Err(cx.key_err(&s, "cone_deg", "only spot lights have a cone")),
            (false, None) => 45.0,
        };
        let intensity = match l.intensity {
            Some(i) => cx.num(&s, "intensity", i)?,
            None => 1.0,
        };
        if intensity < 0.0 {
            return Err(cx.key_err(&s, "intensity", "must be >= 0"));
        }
        let radius = match l.radius {
            Some(r) => Some(cx.positive(&s, "radius", Some(r), 1.0)?),
            None => None,
        };
        if positional && position == camera.eye {
            return Err(cx.key_err(&s, "position", "a light must not coincide with the camera eye"));
        }
        lights.push(Light { kind, position, direction, color: cx.color(&s, "color", l.color, Vec3::ONE)?, intensity, radius, cone_deg });
    }

    // meshes
    let mut meshes = Vec::new();
    for (i, sm) in file.mesh.iter().enumerate() {
        meshes.push(mesh(&cx, i, &sm.span(), sm.get_ref(), &objs)?);
    }

    let name = file
        .name
        .unwrap_or_else(|| Path::new(origin).file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_else(|| origin.to_string()));
    Ok(Scene { name, camera, lights, meshes, ambient })
}

fn present_params(m: &FileMesh) -> Vec<&'static str> {
    let mut v = Vec::new();
    let mut p = |k: &'static str, b: bool| {
        if b {
            v.push(k)
        }
    };
    p("size", m.size.is_some());
    p("radius", m.radius.is_some());
    p("segments", m.segments.is_some());
    p("rings", m.rings.is_some());
    p("major_radius", m.major_radius.is_some());
    p("minor_radius", m.minor_radius.is_some());
    p("sides", m.sides.is_some());
    p("height", m.height.is_some());
    p("steps", m.steps.is_some());
    p("step", m.step.is_some());
    p("count", m.count.is_some());
    p("spacing", m.spacing.is_some());
    p("offset", m.offset.is_some());
    p("divisions", m.divisions.is_some());
    p("bump", m.bump.is_some());
    v
}

/// Lexically joins `rel` onto `dir` ("a/b" + "../c.obj" -> "a/c.obj").
fn join_lexical(dir: &str, rel: &str) -> String {
    let mut parts: Vec<&str> = dir.split('/').filter(|s| !s.is_empty() && *s != ".").collect();
    for p in rel.split('/') {
        match p {
            "" | "." => {}
            ".." => {
                parts.pop();
            }
            p => parts.push(p),
        }
    }
    parts.join("/")
}

fn mesh(cx: &Ctx, i: usize, s: &Range<usize>, m: &FileMesh, objs: &ObjSource) -> Result<SceneMesh> {
    let table_line = line_of(cx.src, s.start);
    let params = present_params(m);
    let (object, kind): (Mesh, String) = match (&m.obj, &m.shape) {
        (Some(_), Some(_)) | (None, None) => return Err(cx.at(table_line, format!("mesh {i}: give exactly one of `obj` or `shape`"))),
        (Some(path), None) => {
            if let Some(k) = params.first() {
                return Err(cx.key_err(s, k, "shape parameters do not apply to an obj mesh"));
            }
            let wrap = |e: Error| cx.key_err(s, "obj", format!("mesh {i}: {e}"));
            let mesh = match objs {
                ObjSource::Dir(dir) => {
                    let p: PathBuf = dir.join(path);
                    obj::load_obj(&p).map_err(wrap)?
                }
                ObjSource::Builtin(dir) => {
                    let key = join_lexical(dir, path);
                    let text = builtin::obj(&key).ok_or_else(|| cx.key_err(s, "obj", format!("mesh {i}: no embedded file {key}")))?;
                    obj::load_obj_str(text, &key).map_err(wrap)?
                }
            };
            let stem = Path::new(path).file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
            (mesh, stem)
        }
        (None, Some(shape)) => {
            let Some((_, allowed)) = SHAPES.iter().find(|(n, _)| n == shape) else {
                return Err(Error::UnknownName {
                    what: "shape",
                    name: shape.clone(),
                    expected: format!(
                        "{}; at {}:{}",
                        SHAPES.iter().map(|(n, _)| *n).collect::<Vec<_>>().join(", "),
                        cx.origin,
                        cx.key_line(s, "shape")
                    ),
                });
            };
            if let Some(k) = params.iter().find(|k| !allowed.contains(k)) {
                return Err(cx.key_err(s, k, format!("not a parameter of shape '{shape}' (it takes: {})", allowed.join(", "))));
            }
            (build_shape(cx, s, shape, m)?, shape.clone())
        }
    };

    let translate = match m.translate {
        Some(t) => cx.v3(s, "translate", t)?,
        None => Vec3::ZERO,
    };
    let rot = match m.rotate_deg {
        Some(r) => cx.v3(s, "rotate_deg", r)?,
        None => Vec3::ZERO,
    };
    let scale = match &m.scale {
        None => Vec3::ONE,
        Some(NumOrVec::Num(x)) => Vec3::splat(cx.num(s, "scale", *x)?),
        Some(NumOrVec::Vec(v)) => {
            let v = cx.vecn(s, "scale", v, 3)?;
            Vec3::new(v[0], v[1], v[2])
        }
    };
    if scale.cmpeq(Vec3::ZERO).any() {
        return Err(cx.key_err(s, "scale", "scale factors must be nonzero"));
    }
    let r =
        Mat4::from_rotation_z(rot.z.to_radians()) * Mat4::from_rotation_y(rot.y.to_radians()) * Mat4::from_rotation_x(rot.x.to_radians());
    let transform = Mat4::from_translation(translate) * r * Mat4::from_scale(scale);
    if !transform.is_finite() {
        return Err(cx.at(table_line, format!("mesh {i}: transform is not finite")));
    }
    let mut object = object;
    if transform.determinant() < 0.0 {
        for t in &mut object.triangles {
            t.swap(1, 2);
        }
    }
    let name = m.name.clone().unwrap_or_else(|| format!("mesh{i}-{kind}"));
    object.validate(&name).map_err(|e| cx.at(table_line, e.to_string()))?;
    let opacity = match m.opacity {
        Some(o) => cx.num(s, "opacity", o)?,
        None => 1.0,
    };
    if !(0.0..=1.0).contains(&opacity) {
        return Err(cx.key_err(s, "opacity", format!("must be in [0, 1], got {opacity}")));
    }
    Ok(SceneMesh {
        name,
        mesh: object,
        transform,
        color: cx.color(s, "color", m.color, Vec3::splat(0.8))?,
        opacity,
        casts_shadow: m.casts_shadow.unwrap_or(true),
    })
}

const MAX_SEG: u32 = 4096;

fn build_shape(cx: &Ctx, s: &Range<usize>, shape: &str, m: &FileMesh) -> Result<Mesh> {
    Ok(match shape {
        "plane" => {
            let v = cx.size_vec(s, "size", &m.size, &[10.0, 10.0])?;
            shapes::plane(Vec2::new(v[0], v[1]))
        }
        "box" => {
            let v = cx.size_vec(s, "size", &m.size, &[1.0, 1.0, 1.0])?;
            shapes::cuboid(Vec3::new(v[0], v[1], v[2]))
        }
        "sphere" => shapes::sphere(
            cx.positive(s, "radius", m.radius, 0.5)?,
            cx.int(s, "segments", m.segments, 24, 3, MAX_SEG)?,
            cx.int(s, "rings", m.rings, 16, 2, MAX_SEG)?,
        ),
        "torus" => {
            let major = cx.positive(s, "major_radius", m.major_radius, 0.5)?;
            let minor = cx.positive(s, "minor_radius", m.minor_radius, 0.2)?;
            if minor >= major {
                return Err(cx.key_err(s, "minor_radius", "must be smaller than major_radius"));
            }
            shapes::torus(major, minor, cx.int(s, "segments", m.segments, 32, 3, MAX_SEG)?, cx.int(s, "sides", m.sides, 16, 3, MAX_SEG)?)
        }
        "cylinder" => shapes::cylinder(
            cx.positive(s, "radius", m.radius, 0.5)?,
            cx.positive(s, "height", m.height, 1.0)?,
            cx.int(s, "segments", m.segments, 24, 3, MAX_SEG)?,
        ),
        "stairs" => {
            let step = match m.step {
                Some(v) => cx.v3(s, "step", v)?,
                None => Vec3::new(2.0, 0.2, 0.3),
            };
            if step.min_element() <= 0.0 {
                return Err(cx.key_err(s, "step", "every component must be > 0"));
            }
            shapes::stairs(cx.int(s, "steps", m.steps, 8, 1, 10_000)?, step)
        }
        "cube_grid" => {
            let (nx, nz) = match &m.count {
                None => (4, 4),
                Some(NumOrVec::Vec(v)) if v.len() == 2 => {
                    let ok = |x: f64| x.fract() == 0.0 && (1.0..=1000.0).contains(&x);
                    if !(ok(v[0]) && ok(v[1])) {
                        return Err(cx.key_err(s, "count", "expected [nx, nz], integers in [1, 1000]"));
                    }
                    (v[0] as u32, v[1] as u32)
                }
                Some(_) => return Err(cx.key_err(s, "count", "expected [nx, nz], integers in [1, 1000]")),
            };
            let size = match &m.size {
                None => 0.4,
                Some(NumOrVec::Num(x)) => cx.positive(s, "size", Some(*x), 0.4)?,
                Some(_) => return Err(cx.key_err(s, "size", "cube_grid size is one number (the cube edge)")),
            };
            shapes::cube_grid(nx, nz, size, cx.positive(s, "spacing", m.spacing, 1.0)?)
        }
        "box_stack" => {
            let count = match &m.count {
                None => 10,
                Some(NumOrVec::Num(x)) if x.fract() == 0.0 && (1.0..=100_000.0).contains(x) => *x as u32,
                Some(_) => return Err(cx.key_err(s, "count", "expected an integer in [1, 100000]")),
            };
            let v = cx.size_vec(s, "size", &m.size, &[1.0, 0.02, 1.0])?;
            let offset = match m.offset {
                Some(o) => cx.v3(s, "offset", o)?,
                None => Vec3::new(0.0, 0.05, 0.0),
            };
            shapes::box_stack(count, Vec3::new(v[0], v[1], v[2]), offset)
        }
        "bumpy_slab" => {
            let v = cx.size_vec(s, "size", &m.size, &[2.0, 0.05, 2.0])?;
            let bump = match m.bump {
                Some(b) => cx.num(s, "bump", b)?,
                None => 1e-7,
            };
            if bump < 0.0 || bump >= v[1] {
                return Err(cx.key_err(s, "bump", "must be in [0, size y)"));
            }
            shapes::bumpy_slab(Vec3::new(v[0], v[1], v[2]), cx.int(s, "divisions", m.divisions, 16, 1, 1024)?, bump)
        }
        other => return Err(cx.key_err(s, "shape", format!("unknown shape {other}"))),
    })
}

#[cfg(test)]
mod tests {
    use super::super::{builtin_names, load, load_str, shapes};
    use crate::error::Error;
    use glam::{Mat4, Vec3};
    use std::path::Path;

    const CAM: &str = "[camera]\neye = [0, 2, 5]\ntarget = [0, 0, 0]\n";

    fn err(toml: &str) -> String {
        let r = std::panic::catch_unwind(|| load_str(toml, "bad.toml", Path::new(".")));
        match r {
            Ok(Ok(_)) => panic!("expected an error for:\n{toml}"),
            Ok(Err(e)) => e.to_string(),
            Err(_) => panic!("panicked on:\n{toml}"),
        }
    }

    fn check(toml: &str, wants: &[&str]) {
        let e = err(toml);
        assert!(e.contains("bad.toml"), "error does not name the file: {e}");
        for w in wants {
            assert!(e.contains(w), "error '{e}' lacks '{w}'");
        }
    }

    #[test]
    fn every_builtin_loads_and_validates() {
        let names = builtin_names();
        for want in ["default", "stairs", "cubes", "spheres", "hard/eye_in_volume", "hard/staircase_300", "hard/look_at_light"] {
            assert!(names.contains(&want), "{want} missing");
        }
        assert!(names.len() >= 4 + 15);
        for name in names {
            let s = load(name).unwrap_or_else(|e| panic!("{name}: {e}"));
            assert!(!s.lights.is_empty(), "{name}: no lights");
            assert!(!s.meshes.is_empty(), "{name}: no meshes");
            assert!(s.meshes.iter().any(|m| m.mesh.triangles.len() == 2), "{name}: no floor");
            for m in &s.meshes {
                m.mesh.validate(&m.name).unwrap();
                assert!(m.transform.determinant() > 0.0);
                // hard/open_casters is made of open and non-manifold meshes on purpose
                if m.mesh.triangles.len() > 2 && name != "hard/open_casters" {
                    shapes::tests_support::assert_closed_outward(&m.mesh, &format!("{name}/{}", m.name));
                }
            }
            for l in &s.lights {
                assert!(l.position != s.camera.eye, "{name}: light at the eye");
                assert!((l.direction.length() - 1.0).abs() < 1e-5);
            }
        }
    }

    /// Does the segment a-b pass through the box?
    fn seg_hits(a: Vec3, b: Vec3, bx: crate::geom::Aabb) -> bool {
        let (mut t0, mut t1) = (0.0f32, 1.0f32);
        let d = b - a;
        for k in 0..3 {
            if d[k].abs() < 1e-12 {
                if a[k] < bx.min[k] || a[k] > bx.max[k] {
                    return false;
                }
            } else {
                let (u, v) = ((bx.min[k] - a[k]) / d[k], (bx.max[k] - a[k]) / d[k]);
                t0 = t0.max(u.min(v));
                t1 = t1.min(u.max(v));
            }
        }
        t0 <= t1
    }

    fn blockers(name: &str, p: Vec3) -> usize {
        let s = load(name).unwrap();
        let l = s.lights[0].position;
        s.meshes.iter().filter(|m| m.mesh.triangles.len() > 2).filter(|m| seg_hits(p, l, m.world_bounds())).count()
    }

    #[test]
    fn hard_cases_are_exercised() {
        let eye = |n: &str| load(n).unwrap().camera.eye;
        assert_eq!(blockers("hard/eye_in_volume", eye("hard/eye_in_volume")), 1);
        assert_eq!(blockers("hard/eye_in_two_volumes", eye("hard/eye_in_two_volumes")), 2);
        assert_eq!(blockers("hard/look_at_light", eye("hard/look_at_light")), 1);
        // near_plane_cut: eye just outside, a point of the near rectangle 0.2 to its left inside
        let e = eye("hard/near_plane_cut");
        assert_eq!(blockers("hard/near_plane_cut", e), 0);
        assert_eq!(blockers("hard/near_plane_cut", e - Vec3::new(0.2, 0.0, 0.0)), 1);
        // staircase_300: a floor point below all 300 slabs
        let s = load("hard/staircase_300").unwrap();
        let l = s.lights[0].position;
        let m = &s.meshes[1];
        let hits = (0..300)
            .filter(|i| {
                let tri = &m.mesh.positions[i * 8..i * 8 + 8];
                let b = crate::geom::Aabb::from_points(tri.iter()).transformed(&m.transform);
                seg_hits(Vec3::new(0.5, 0.0, 0.0), l, b)
            })
            .count();
        assert_eq!(hits, 300);
    }

    #[test]
    fn default_scene_content() {
        let s = load("default").unwrap();
        assert_eq!(s.name, "default");
        assert!(s.lights.len() >= 2);
        let kinds: Vec<_> = s.lights.iter().map(|l| l.kind).collect();
        assert!(kinds.contains(&super::LightKind::Point) && kinds.contains(&super::LightKind::Spot));
        assert!(s.meshes.len() >= 7);
    }

    #[test]
    fn hard_cases_geometry() {
        // eye inside the caster's shadow column, light inside the torus' bounds, etc.
        let s = load("hard/light_inside_bounds").unwrap();
        let b = s.meshes[1].world_bounds();
        assert!(b.contains(s.lights[0].position));
        let s = load("hard/light_in_face_plane").unwrap();
        let top = s.meshes[1].world_bounds().max.y;
        assert_eq!(top, s.lights[0].position.y);
        let s = load("hard/staircase_300").unwrap();
        assert_eq!(s.meshes[1].mesh.triangles.len(), 300 * 12);
        let s = load("hard/zero_area").unwrap();
        let m = &s.meshes[1].mesh;
        assert!((0..m.triangles.len()).filter(|&t| m.face_normal(t).length() == 0.0).count() == 2);
        let s = load("hard/grazing_directional").unwrap();
        let d = s.lights[0].direction;
        assert!((d.y.asin().to_degrees() + 2.0).abs() < 1e-3);
    }

    #[test]
    fn file_with_obj_and_mirror() {
        let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/scene_with_obj.toml");
        let s = load(p.to_str().unwrap()).unwrap();
        assert_eq!(s.name, "scene_with_obj");
        let m = &s.meshes[0];
        assert_eq!(m.name, "mesh0-cube");
        assert!(m.transform.determinant() < 0.0);
        // world-space triangles are still outward
        let w = m.mesh.transformed(&Mat4::IDENTITY);
        let mut world = w.clone();
        world.positions = w.positions.iter().map(|p| m.transform.transform_point3(*p)).collect();
        assert!(shapes::signed_volume(&world) > 0.0);
    }

    #[test]
    fn transform_conventions() {
        let t = format!("{CAM}[[mesh]]\nshape = \"box\"\ntranslate = [1, 2, 3]\nrotate_deg = [10, 20, 30]\nscale = [2, 3, 4]\n");
        let s = load_str(&t, "t.toml", Path::new(".")).unwrap();
        let r = Mat4::from_euler(glam::EulerRot::ZYX, 30f32.to_radians(), 20f32.to_radians(), 10f32.to_radians());
        let want = Mat4::from_translation(Vec3::new(1.0, 2.0, 3.0)) * r * Mat4::from_scale(Vec3::new(2.0, 3.0, 4.0));
        assert!(s.meshes[0].transform.abs_diff_eq(want, 1e-5));
        assert_eq!(s.ambient, Vec3::splat(0.08));
        assert_eq!(s.camera.fov_y_deg, 60.0);
        assert_eq!(s.meshes[0].color, Vec3::splat(0.8));
        // mirrored box: object-space winding swapped, world outward
        let t = format!("{CAM}[[mesh]]\nshape = \"box\"\nscale = [1, -1, 1]\n");
        let s = load_str(&t, "t.toml", Path::new(".")).unwrap();
        let m = &s.meshes[0];
        assert!(shapes::signed_volume(&m.mesh) < 0.0);
        let mut w = m.mesh.clone();
        w.positions = w.positions.iter().map(|p| m.transform.transform_point3(*p)).collect();
        assert!(shapes::signed_volume(&w) > 0.0);
        // spot direction normalised
        let t = format!("{CAM}[[light]]\nkind = \"spot\"\nposition = [0, 3, 0]\ndirection = [0, -5, 0]\n");
        let s = load_str(&t, "t.toml", Path::new(".")).unwrap();
        assert_eq!(s.lights[0].direction, Vec3::NEG_Y);
        assert_eq!(s.lights[0].cone_deg, 45.0);
    }

    #[test]
    fn syntax_error_has_line() {
        check(&format!("{CAM}\n[[light]\nkind = \"point\"\n"), &["bad.toml:5"]);
        check("name = \"x\"\nambient = [1, 2\n", &["bad.toml:2"]);
    }

    #[test]
    fn unknown_keys() {
        check(&format!("{CAM}fov = 50\n"), &["bad.toml:4", "fov"]);
        check(&format!("{CAM}[[mesh]]\nshape = \"box\"\ncolour = [1, 1, 1]\n"), &["bad.toml:6", "colour"]);
        check(&format!("colour = 1\n{CAM}"), &["bad.toml:1", "colour"]);
        check(&format!("{CAM}[[mesh]]\nshape = \"box\"\nrings = 3\n"), &["bad.toml:6", "rings"]);
        check(&format!("{CAM}[[light]]\nkind = \"point\"\nposition = [0, 1, 0]\ncone_deg = 30\n"), &["bad.toml:7", "cone_deg"]);
    }

    #[test]
    fn wrong_types() {
        check(&format!("{CAM}[[mesh]]\nshape = \"box\"\nsize = \"big\"\n"), &["bad.toml:6"]);
        check(&format!("{CAM}[[mesh]]\nshape = \"sphere\"\nsegments = 2.5\n"), &["bad.toml:6"]);
        check(&format!("{CAM}[[mesh]]\nshape = \"sphere\"\nsegments = -3\n"), &["bad.toml:6", "segments"]);
        check(&format!("{CAM}[[mesh]]\nshape = \"box\"\nsize = [1, 2]\n"), &["bad.toml:6", "size"]);
        check("[camera]\neye = [0, 2]\ntarget = [0, 0, 0]\n", &["bad.toml:2"]);
        check("[camera]\neye = \"up\"\ntarget = [0, 0, 0]\n", &["bad.toml:2"]);
        check("name = 3\n", &["bad.toml:1"]);
        check("", &["bad.toml", "camera"]);
    }

    #[test]
    fn non_finite_numbers() {
        check("[camera]\neye = [0, nan, 5]\ntarget = [0, 0, 0]\n", &["bad.toml:2", "eye", "non-finite"]);
        check(&format!("{CAM}[[light]]\nkind = \"point\"\nposition = [0, inf, 0]\n"), &["bad.toml:6", "position"]);
        check(&format!("{CAM}[[mesh]]\nshape = \"sphere\"\nradius = -inf\n"), &["bad.toml:6", "radius"]);
        check(&format!("{CAM}[[mesh]]\nshape = \"box\"\ntranslate = [1e39, 0, 0]\n"), &["bad.toml:6", "translate"]);
        check(&format!("ambient = [nan, 0, 0]\n{CAM}"), &["bad.toml:1", "ambient"]);
        check(&format!("{CAM}[[mesh]]\nshape = \"box\"\nscale = nan\n"), &["bad.toml:6", "scale"]);
    }

    #[test]
    fn unknown_names() {
        let e = load_str(&format!("{CAM}[[mesh]]\nshape = \"hexagon\"\n"), "bad.toml", Path::new(".")).unwrap_err();
        assert!(matches!(e, Error::UnknownName { what: "shape", .. }));
        let e = e.to_string();
        assert!(e.contains("hexagon") && e.contains("torus") && e.contains("bad.toml:5"), "{e}");
        let e = load_str(&format!("{CAM}[[light]]\nkind = \"area\"\nposition = [0, 1, 0]\n"), "bad.toml", Path::new(".")).unwrap_err();
        assert!(matches!(e, Error::UnknownName { what: "light kind", .. }));
        assert!(e.to_string().contains("bad.toml:5"));
        let e = load("no_such_scene").unwrap_err();
        assert!(matches!(e, Error::UnknownName { what: "scene", .. }));
        let e = e.to_string();
        assert!(e.contains("default") && e.contains("hard/eye_in_volume"), "{e}");
        assert!(matches!(load("hard/nope").unwrap_err(), Error::UnknownName { .. }));
    }

    #[test]
    fn missing_files() {
        let e = load("missing_dir/missing.toml").unwrap_err().to_string();
        assert!(e.contains("missing_dir/missing.toml"), "{e}");
        let e = err(&format!("{CAM}[[mesh]]\nobj = \"nowhere.obj\"\n"));
        assert!(e.contains("bad.toml:5") && e.contains("nowhere.obj"), "{e}");
    }

    #[test]
    fn bad_obj_through_scene() {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data");
        for (f, want) in [("malformed.obj", "malformed"), ("nan_vertex.obj", "vertex 3"), ("no_faces.obj", "empty")] {
            let t = format!("{CAM}[[mesh]]\nobj = \"{f}\"\n");
            let e = load_str(&t, "bad.toml", &dir).unwrap_err().to_string();
            assert!(e.contains("bad.toml:5") && e.contains(f) && e.contains(want), "{e}");
        }
    }

    #[test]
    fn invalid_values() {
        check("[camera]\neye = [0, 0, 0]\ntarget = [0, 0, 0]\n", &["bad.toml:3", "target"]);
        check("[camera]\neye = [0, 2, 0]\ntarget = [0, 0, 0]\n", &["bad.toml", "up"]);
        check("[camera]\neye = [0, 2, 5]\ntarget = [0, 0, 0]\nfov_y_deg = 180\n", &["bad.toml:4", "fov_y_deg"]);
        check("[camera]\neye = [0, 2, 5]\ntarget = [0, 0, 0]\nnear = 0\n", &["bad.toml:4", "near"]);
        check(&format!("{CAM}[[light]]\nkind = \"directional\"\ndirection = [0, 0, 0]\n"), &["bad.toml:6", "direction"]);
        check(&format!("{CAM}[[light]]\nkind = \"spot\"\ndirection = [0, -1, 0]\n"), &["bad.toml:4", "position"]);
        check(&format!("{CAM}[[light]]\nkind = \"point\"\n"), &["bad.toml:4", "position"]);
        check(&format!("{CAM}[[light]]\nkind = \"point\"\nposition = [0, 2, 5]\n"), &["bad.toml:6", "eye"]);
        check(&format!("{CAM}[[light]]\nkind = \"point\"\nposition = [0, 2, 1]\nradius = 0\n"), &["bad.toml:7", "radius"]);
        check(
            &format!("{CAM}[[light]]\nkind = \"spot\"\nposition = [0, 2, 1]\ndirection = [0, -1, 0]\ncone_deg = 180\n"),
            &["bad.toml:8", "cone_deg"],
        );
        check(&format!("{CAM}[[mesh]]\nshape = \"box\"\nopacity = 2\n"), &["bad.toml:6", "opacity"]);
        check(&format!("{CAM}[[mesh]]\nshape = \"box\"\nscale = [1, 0, 1]\n"), &["bad.toml:6", "scale"]);
        check(&format!("{CAM}[[mesh]]\nshape = \"box\"\nobj = \"a.obj\"\n"), &["bad.toml:4", "exactly one"]);
        check(&format!("{CAM}[[mesh]]\nname = \"x\"\n"), &["bad.toml:4", "exactly one"]);
        check(&format!("{CAM}[[mesh]]\nshape = \"torus\"\nminor_radius = 0.6\n"), &["bad.toml:6", "minor_radius"]);
        check(&format!("{CAM}[[mesh]]\nshape = \"cube_grid\"\ncount = [0, 2]\n"), &["bad.toml:6", "count"]);
        check(&format!("{CAM}[[mesh]]\nshape = \"sphere\"\nsegments = 100000000000\n"), &["bad.toml:6", "segments"]);
        check(&format!("{CAM}[[mesh]]\nshape = \"box\"\ncolor = [1, -1, 1]\n"), &["bad.toml:6", "color"]);
    }
}
