//! The `[[mesh]]` tables: an OBJ file or a built-in shape with its parameters, then the
//! instance transform, colour and opacity.

use super::keys::{line_of, present_params, Ctx, FileMesh, NumOrVec, SHAPES};
use super::ObjSource;
use crate::{builtin, obj, shapes, SceneMesh};
use glam::{Mat4, Vec2, Vec3};
use std::ops::Range;
use std::path::{Path, PathBuf};
use umbrage::error::{Error, Result};
use umbrage::geom::Mesh;

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

pub(super) fn mesh(cx: &Ctx, i: usize, s: &Range<usize>, m: &FileMesh, objs: &ObjSource) -> Result<SceneMesh> {
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
