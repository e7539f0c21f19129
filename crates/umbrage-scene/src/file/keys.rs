//! The scene file's keys: the serde tables (unknown keys rejected), the shape parameter
//! table, and [`Ctx`], which turns a bad value into an error naming the file and line of its key.

use glam::Vec3;
use serde::Deserialize;
use std::ops::Range;
use toml::Spanned;
use umbrage::error::{Error, Result};

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct FileScene {
    pub(super) name: Option<String>,
    pub(super) ambient: Option<[f64; 3]>,
    pub(super) camera: Spanned<FileCamera>,
    #[serde(default)]
    pub(super) light: Vec<Spanned<FileLight>>,
    #[serde(default)]
    pub(super) mesh: Vec<Spanned<FileMesh>>,
    #[serde(default)]
    pub(super) sphere: Vec<Spanned<FileSphere>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct FileSphere {
    pub(super) center: [f64; 3],
    pub(super) radius: f64,
    pub(super) name: Option<String>,
    pub(super) color: Option<[f64; 3]>,
    pub(super) opacity: Option<f64>,
    pub(super) casts_shadow: Option<bool>,
    pub(super) segments: Option<i64>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct FileCamera {
    pub(super) eye: [f64; 3],
    pub(super) target: [f64; 3],
    pub(super) up: Option<[f64; 3]>,
    pub(super) fov_y_deg: Option<f64>,
    pub(super) near: Option<f64>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct FileLight {
    pub(super) kind: String,
    pub(super) position: Option<[f64; 3]>,
    pub(super) direction: Option<[f64; 3]>,
    pub(super) color: Option<[f64; 3]>,
    pub(super) intensity: Option<f64>,
    pub(super) radius: Option<f64>,
    pub(super) cone_deg: Option<f64>,
    // area lights (`kind = "area"`)
    pub(super) shape: Option<String>,
    pub(super) size: Option<NumOrVec>,
    pub(super) normal: Option<[f64; 3]>,
    pub(super) tangent: Option<[f64; 3]>,
    pub(super) samples: Option<i64>,
    // motion (src/scene/file/motion.rs)
    pub(super) orbit: Option<FileOrbit>,
    pub(super) keyframes: Option<Vec<FileKeyframe>>,
}

/// `orbit = { center, radius, period_s }` of a light.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct FileOrbit {
    pub(super) center: [f64; 3],
    pub(super) radius: f64,
    pub(super) period_s: f64,
}

/// One of a light's `keyframes = [{ t, position }, ...]`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct FileKeyframe {
    pub(super) t: f64,
    pub(super) position: [f64; 3],
}

#[derive(Deserialize, Clone)]
#[serde(untagged)]
pub(super) enum NumOrVec {
    Num(f64),
    Vec(Vec<f64>),
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct FileMesh {
    pub(super) obj: Option<String>,
    pub(super) shape: Option<String>,
    // shape parameters
    pub(super) size: Option<NumOrVec>,
    pub(super) radius: Option<f64>,
    pub(super) segments: Option<i64>,
    pub(super) rings: Option<i64>,
    pub(super) major_radius: Option<f64>,
    pub(super) minor_radius: Option<f64>,
    pub(super) sides: Option<i64>,
    pub(super) height: Option<f64>,
    pub(super) steps: Option<i64>,
    pub(super) step: Option<[f64; 3]>,
    pub(super) count: Option<NumOrVec>,
    pub(super) spacing: Option<f64>,
    pub(super) offset: Option<[f64; 3]>,
    pub(super) divisions: Option<i64>,
    pub(super) bump: Option<f64>,
    // instance
    pub(super) name: Option<String>,
    pub(super) translate: Option<[f64; 3]>,
    pub(super) rotate_deg: Option<[f64; 3]>,
    pub(super) scale: Option<NumOrVec>,
    pub(super) color: Option<[f64; 3]>,
    pub(super) opacity: Option<f64>,
    pub(super) casts_shadow: Option<bool>,
    // motion (src/scene/file/motion.rs)
    pub(super) spin_deg_per_s: Option<[f64; 3]>,
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

pub(super) fn line_of(src: &str, offset: usize) -> usize {
    src.as_bytes()[..offset.min(src.len())].iter().filter(|&&b| b == b'\n').count() + 1
}

/// Error context: the scene file's name and text.
pub(super) struct Ctx<'a> {
    pub(super) origin: &'a str,
    pub(super) src: &'a str,
}

impl Ctx<'_> {
    pub(super) fn at(&self, line: usize, msg: impl Into<String>) -> Error {
        Error::input(format!("{}:{line}", self.origin), msg)
    }
    /// The line of `key = ...` inside the table starting at `span` (up to the next table
    /// header), or the table's first line.
    pub(super) fn key_line(&self, span: &Range<usize>, key: &str) -> usize {
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
    pub(super) fn key_err(&self, span: &Range<usize>, key: &str, msg: impl std::fmt::Display) -> Error {
        self.at(self.key_line(span, key), format!("{key}: {msg}"))
    }
    pub(super) fn num(&self, span: &Range<usize>, key: &str, v: f64) -> Result<f32> {
        let f = v as f32;
        if f.is_finite() {
            Ok(f)
        } else {
            Err(self.key_err(span, key, format!("non-finite number {v} (nan/inf or out of f32 range)")))
        }
    }
    pub(super) fn v3(&self, span: &Range<usize>, key: &str, v: [f64; 3]) -> Result<Vec3> {
        Ok(Vec3::new(self.num(span, key, v[0])?, self.num(span, key, v[1])?, self.num(span, key, v[2])?))
    }
    pub(super) fn color(&self, span: &Range<usize>, key: &str, v: Option<[f64; 3]>, default: Vec3) -> Result<Vec3> {
        let c = match v {
            Some(v) => self.v3(span, key, v)?,
            None => default,
        };
        if c.min_element() < 0.0 {
            return Err(self.key_err(span, key, "colour components must be >= 0"));
        }
        Ok(c)
    }
    pub(super) fn positive(&self, span: &Range<usize>, key: &str, v: Option<f64>, default: f32) -> Result<f32> {
        let x = match v {
            Some(v) => self.num(span, key, v)?,
            None => default,
        };
        if x <= 0.0 {
            return Err(self.key_err(span, key, format!("must be > 0, got {x}")));
        }
        Ok(x)
    }
    pub(super) fn int(&self, span: &Range<usize>, key: &str, v: Option<i64>, default: u32, min: u32, max: u32) -> Result<u32> {
        let x = v.unwrap_or(default as i64);
        if x < min as i64 || x > max as i64 {
            return Err(self.key_err(span, key, format!("must be an integer in [{min}, {max}], got {x}")));
        }
        Ok(x as u32)
    }
    pub(super) fn vecn(&self, span: &Range<usize>, key: &str, v: &[f64], n: usize) -> Result<Vec<f32>> {
        if v.len() != n {
            return Err(self.key_err(span, key, format!("expected {n} numbers, got {}", v.len())));
        }
        v.iter().map(|&x| self.num(span, key, x)).collect()
    }
    pub(super) fn size_vec(&self, span: &Range<usize>, key: &str, v: &Option<NumOrVec>, default: &[f32]) -> Result<Vec<f32>> {
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

pub(super) fn present_params(m: &FileMesh) -> Vec<&'static str> {
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
