//! The frame-dump format (a contract between the renderer and `check`).
//!
//! A dump directory holds:
//! * `frame.json`: `{"width": W, "height": H, "camera_pos": [x,y,z],
//!   "lights": [{"position": [x,y,z,w]}, ...]}` — w=1: point/spot at xyz; w=0: directional,
//!   xyz points towards the light. Optional extra keys written here and understood by the
//!   reader: per light `"kind"` ("point"|"spot"|"directional"), `"direction"` `[x,y,z]` (the
//!   direction the light travels), `"cone_deg"`, `"radius"`; top level `"camera"`
//!   `{"eye","target","up","fov_y_deg","near"}`. Any other top-level key is kept in
//!   [`Dump::extra`]. Readers accept dumps with only the required keys.
//!   `"spheres": [{"center": [x,y,z], "radius": r}, ...]` (f64, world space) lists the
//!   shadow-casting analytic spheres, written when there are any; their pixels in
//!   `positions.f32`/`normals.f32` are the exact sphere surface (ray-cast, not tessellated).
//! * `world.obj`: every shadow-casting triangle in world space (`v x y z`, `f a b c`,
//!   1-based; the reader also accepts `a/b/c` tokens, negative indices and polygons, which
//!   it fans).
//! * `positions.f32`, `normals.f32`: W*H*3 little-endian f32, row-major from the top-left;
//!   NaN for background.
//! * `shadow_K.png` per light K (from 0): 8-bit grey, 255 lit, 0 not lit, 128 background.
//!   (`stencil_K.png` and `color.png` are written by the renderer and ignored here.)

use glam::{Vec3, Vec4};
use std::collections::BTreeMap;
use std::path::Path;
use umbrage::error::{Error, Result};
use umbrage_scene::{Camera, Light, LightKind};

/// One light of a dump: the required homogeneous position plus optional details.
#[derive(Clone, Debug, PartialEq)]
pub struct DumpLight {
    /// (xyz, 1) point/spot; (towards-light direction, 0) directional.
    pub position: Vec4,
    /// Point, spot or directional when the dump says (else inferred from `position.w`).
    pub kind: Option<LightKind>,
    /// Direction the light travels (spot; directional is implied by `position`).
    pub direction: Option<Vec3>,
    /// Full cone angle of a spot light, degrees.
    pub cone_deg: Option<f32>,
    /// Attenuation range, world units (`None`: unbounded).
    pub radius: Option<f32>,
}

impl DumpLight {
    /// Only the required homogeneous position.
    pub fn homogeneous(position: Vec4) -> DumpLight {
        DumpLight { position, kind: None, direction: None, cone_deg: None, radius: None }
    }
    /// Everything needed for an exact check.
    pub fn from_light(l: &Light) -> DumpLight {
        DumpLight {
            position: l.homogeneous(),
            kind: Some(l.kind),
            direction: Some(l.direction),
            cone_deg: (l.kind == LightKind::Spot).then_some(l.cone_deg),
            radius: l.radius,
        }
    }
    /// The light to check against. Without `kind`: w=0 directional, else point. A spot
    /// without direction or cone is an error.
    pub fn to_light(&self) -> Result<Light> {
        let p = self.position;
        if !p.is_finite() {
            return Err(Error::input("frame.json", format!("light position {p:?} is not finite")));
        }
        let kind = self.kind.unwrap_or(if p.w == 0.0 { LightKind::Directional } else { LightKind::Point });
        let mut light = Light {
            kind,
            position: Vec3::ZERO,
            direction: Vec3::NEG_Y,
            color: Vec3::ONE,
            intensity: 1.0,
            radius: self.radius,
            cone_deg: self.cone_deg.unwrap_or(180.0),
            area: None,
        };
        match kind {
            LightKind::Directional => {
                if p.w != 0.0 || p.truncate().length_squared() == 0.0 {
                    return Err(Error::input("frame.json", format!("directional light needs w = 0 and a nonzero direction, got {p:?}")));
                }
                light.direction = -p.truncate().normalize();
                light.radius = None;
            }
            _ => {
                if p.w == 0.0 {
                    return Err(Error::input("frame.json", format!("{kind:?} light with w = 0: {p:?}")));
                }
                light.position = p.truncate() / p.w;
            }
        }
        if kind == LightKind::Spot {
            match (self.direction, self.cone_deg) {
                (Some(d), Some(_)) if d.length_squared() > 0.0 => light.direction = d.normalize(),
                _ => {
                    return Err(Error::input("frame.json", "spot light needs \"direction\" and \"cone_deg\""));
                }
            }
        }
        Ok(light)
    }
}

/// A frame dump in memory.
#[derive(Clone, Debug, PartialEq)]
pub struct Dump {
    /// Image width, pixels.
    pub width: u32,
    /// Image height, pixels.
    pub height: u32,
    /// World-space eye position.
    pub camera_pos: Vec3,
    /// Every light, with its mask in the dump directory.
    pub lights: Vec<DumpLight>,
    /// World-space shadow-casting triangles.
    pub triangles: Vec<[Vec3; 3]>,
    /// W*H*3, NaN for background.
    pub positions: Vec<f32>,
    /// W*H*3, NaN for background.
    pub normals: Vec<f32>,
    /// One W*H mask per light (255 lit, 0 not lit, 128 background).
    pub shadow: Vec<Vec<u8>>,
    /// Shadow-casting analytic spheres (`"spheres"`), world space.
    pub spheres: Vec<umbrage::geom::Sphere>,
    /// Optional full camera (written as "camera").
    pub camera: Option<Camera>,
    /// Other top-level keys of frame.json, kept as they are.
    pub extra: BTreeMap<String, serde_json::Value>,
}

#[derive(serde::Serialize, serde::Deserialize)]
struct FrameJson {
    width: u32,
    height: u32,
    camera_pos: [f32; 3],
    lights: Vec<LightJson>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    camera: Option<CameraJson>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    spheres: Vec<SphereJson>,
    #[serde(flatten)]
    extra: BTreeMap<String, serde_json::Value>,
}

#[derive(serde::Serialize, serde::Deserialize)]
struct LightJson {
    position: [f32; 4],
    #[serde(default, skip_serializing_if = "Option::is_none")]
    kind: Option<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    direction: Option<[f32; 3]>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    cone_deg: Option<f32>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    radius: Option<f32>,
}

#[derive(serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct SphereJson {
    center: [f64; 3],
    radius: f64,
}

#[derive(serde::Serialize, serde::Deserialize)]
struct CameraJson {
    eye: [f32; 3],
    target: [f32; 3],
    up: [f32; 3],
    fov_y_deg: f32,
    near: f32,
}

fn kind_name(k: LightKind) -> &'static str {
    k.name()
}

impl Dump {
    /// Checks the sizes of every array against width/height and the light count.
    pub fn validate(&self, location: &str) -> Result<()> {
        let px = self.width as usize * self.height as usize;
        if px == 0 {
            return Err(Error::input(location, format!("empty image {}x{}", self.width, self.height)));
        }
        if self.positions.len() != px * 3 {
            return Err(Error::input(
                location,
                format!("positions has {} floats, expected {}x{}x3 = {}", self.positions.len(), self.width, self.height, px * 3),
            ));
        }
        if self.normals.len() != px * 3 {
            return Err(Error::input(
                location,
                format!("normals has {} floats, expected {}x{}x3 = {}", self.normals.len(), self.width, self.height, px * 3),
            ));
        }
        if self.shadow.len() != self.lights.len() {
            return Err(Error::input(location, format!("{} shadow masks for {} lights", self.shadow.len(), self.lights.len())));
        }
        for (k, s) in self.shadow.iter().enumerate() {
            if s.len() != px {
                return Err(Error::input(location, format!("shadow mask {k} has {} pixels, expected {px}", s.len())));
            }
        }
        Ok(())
    }
}

fn io<T>(path: &Path, r: std::io::Result<T>) -> Result<T> {
    r.map_err(|e| Error::io(path.display().to_string(), e))
}

fn f32s_to_bytes(v: &[f32]) -> Vec<u8> {
    v.iter().flat_map(|f| f.to_le_bytes()).collect()
}

/// Writes a dump (creating the directory). Removes stale `shadow_K.png` files beyond the
/// light count, so that the directory stays consistent.
pub fn write_dump(dir: impl AsRef<Path>, dump: &Dump) -> Result<()> {
    let dir = dir.as_ref();
    dump.validate(&dir.display().to_string())?;
    io(dir, std::fs::create_dir_all(dir))?;
    let frame = FrameJson {
        width: dump.width,
        height: dump.height,
        camera_pos: dump.camera_pos.to_array(),
        lights: dump
            .lights
            .iter()
            .map(|l| LightJson {
                position: l.position.to_array(),
                kind: l.kind.map(|k| kind_name(k).to_string()),
                direction: l.direction.map(|d| d.to_array()),
                cone_deg: l.cone_deg,
                radius: l.radius,
            })
            .collect(),
        camera: dump.camera.as_ref().map(|c| CameraJson {
            eye: c.eye.to_array(),
            target: c.target.to_array(),
            up: c.up.to_array(),
            fov_y_deg: c.fov_y_deg,
            near: c.near,
        }),
        spheres: dump.spheres.iter().map(|s| SphereJson { center: s.center.to_array(), radius: s.radius }).collect(),
        extra: dump.extra.clone(),
    };
    let p = dir.join("frame.json");
    let json = serde_json::to_string_pretty(&frame).map_err(|e| Error::input(p.display().to_string(), e.to_string()))?;
    io(&p, std::fs::write(&p, json))?;

    let mut obj = String::with_capacity(dump.triangles.len() * 100);
    obj.push_str("# umbrage frame dump: shadow-casting triangles, world space\n");
    for t in &dump.triangles {
        for v in t {
            obj.push_str(&format!("v {} {} {}\n", v.x, v.y, v.z));
        }
    }
    for i in 0..dump.triangles.len() {
        obj.push_str(&format!("f {} {} {}\n", 3 * i + 1, 3 * i + 2, 3 * i + 3));
    }
    let p = dir.join("world.obj");
    io(&p, std::fs::write(&p, obj))?;

    let p = dir.join("positions.f32");
    io(&p, std::fs::write(&p, f32s_to_bytes(&dump.positions)))?;
    let p = dir.join("normals.f32");
    io(&p, std::fs::write(&p, f32s_to_bytes(&dump.normals)))?;

    for (k, s) in dump.shadow.iter().enumerate() {
        let p = dir.join(format!("shadow_{k}.png"));
        let img = image::GrayImage::from_raw(dump.width, dump.height, s.clone())
            .ok_or_else(|| Error::input(p.display().to_string(), "mask size does not match the image"))?;
        img.save_with_format(&p, image::ImageFormat::Png)
            .map_err(|e| Error::input(p.display().to_string(), format!("cannot write PNG: {e}")))?;
    }
    let mut k = dump.shadow.len();
    loop {
        let p = dir.join(format!("shadow_{k}.png"));
        if !p.exists() {
            break;
        }
        io(&p, std::fs::remove_file(&p))?;
        k += 1;
    }
    Ok(())
}

fn read_f32s(path: &Path, expected: usize, what: &str) -> Result<Vec<f32>> {
    let bytes = std::fs::read(path).map_err(|e| Error::input(path.display().to_string(), format!("cannot read {what}: {e}")))?;
    if bytes.len() != expected * 4 {
        return Err(Error::input(
            path.display().to_string(),
            format!("{what} has {} bytes, expected W*H*3*4 = {}", bytes.len(), expected * 4),
        ));
    }
    Ok(bytes.chunks_exact(4).map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]])).collect())
}

/// Parses the OBJ subset of `world.obj` into triangles.
pub fn parse_obj(text: &str, location: &str) -> Result<Vec<[Vec3; 3]>> {
    let mut verts: Vec<Vec3> = Vec::new();
    let mut tris = Vec::new();
    for (ln, line) in text.lines().enumerate() {
        let loc = || format!("{location}:{}", ln + 1);
        let line = line.split('#').next().unwrap_or("").trim();
        let mut it = line.split_whitespace();
        match it.next() {
            Some("v") => {
                let c: Vec<&str> = it.collect();
                if c.len() < 3 || c.len() > 4 {
                    return Err(Error::input(loc(), format!("vertex needs 3 coordinates, got {}", c.len())));
                }
                let mut xyz = [0f32; 3];
                for k in 0..3 {
                    xyz[k] = c[k]
                        .parse::<f32>()
                        .ok()
                        .filter(|f| f.is_finite())
                        .ok_or_else(|| Error::input(loc(), format!("bad vertex coordinate '{}'", c[k])))?;
                }
                verts.push(Vec3::from_array(xyz));
            }
            Some("f") => {
                let mut idx = Vec::new();
                for tok in it {
                    let first = tok.split('/').next().unwrap_or("");
                    let i: i64 = first.parse().map_err(|_| Error::input(loc(), format!("bad face index '{tok}'")))?;
                    let n = verts.len() as i64;
                    let r = if i > 0 { i - 1 } else { n + i };
                    if i == 0 || r < 0 || r >= n {
                        return Err(Error::input(loc(), format!("face index {i} out of range ({n} vertices defined so far)")));
                    }
                    idx.push(verts[r as usize]);
                }
                if idx.len() < 3 {
                    return Err(Error::input(loc(), format!("face with {} vertices", idx.len())));
                }
                for k in 1..idx.len() - 1 {
                    tris.push([idx[0], idx[k], idx[k + 1]]);
                }
            }
            _ => {}
        }
    }
    Ok(tris)
}

/// Reads a dump, checking that every file is present and consistent.
pub fn read_dump(dir: impl AsRef<Path>) -> Result<Dump> {
    let dir = dir.as_ref();
    if !dir.is_dir() {
        return Err(Error::input(dir.display().to_string(), "dump directory does not exist"));
    }
    let p = dir.join("frame.json");
    let loc = p.display().to_string();
    let text = std::fs::read_to_string(&p).map_err(|e| Error::input(&loc, format!("cannot read: {e}")))?;
    let frame: FrameJson = serde_json::from_str(&text).map_err(|e| Error::input(&loc, format!("bad frame.json: {e}")))?;
    let (w, h) = (frame.width, frame.height);
    if w == 0 || h == 0 {
        return Err(Error::input(&loc, format!("empty image {w}x{h}")));
    }
    let px = (w as usize)
        .checked_mul(h as usize)
        .filter(|&n| n <= (1 << 28))
        .ok_or_else(|| Error::input(&loc, format!("image {w}x{h} too large")))?;
    let mut lights = Vec::new();
    for (k, l) in frame.lights.iter().enumerate() {
        let kind = match l.kind.as_deref() {
            None => None,
            Some("point") => Some(LightKind::Point),
            Some("spot") => Some(LightKind::Spot),
            Some("directional") => Some(LightKind::Directional),
            Some(o) => return Err(Error::input(&loc, format!("light {k}: unknown kind '{o}'"))),
        };
        let dl = DumpLight {
            position: Vec4::from_array(l.position),
            kind,
            direction: l.direction.map(Vec3::from_array),
            cone_deg: l.cone_deg,
            radius: l.radius,
        };
        dl.to_light().map_err(|e| Error::input(&loc, format!("light {k}: {e}")))?;
        lights.push(dl);
    }
    let camera = frame.camera.map(|c| Camera {
        eye: Vec3::from_array(c.eye),
        target: Vec3::from_array(c.target),
        up: Vec3::from_array(c.up),
        fov_y_deg: c.fov_y_deg,
        near: c.near,
    });

    let mut spheres = Vec::new();
    for (k, s) in frame.spheres.iter().enumerate() {
        let sphere = umbrage::geom::Sphere { center: glam::DVec3::from_array(s.center), radius: s.radius };
        if let Some(problem) = sphere.problem() {
            return Err(Error::input(&loc, format!("sphere {k}: {problem}")));
        }
        spheres.push(sphere);
    }

    let p = dir.join("world.obj");
    let text = std::fs::read_to_string(&p).map_err(|e| Error::input(p.display().to_string(), format!("cannot read world.obj: {e}")))?;
    let triangles = parse_obj(&text, &p.display().to_string())?;

    let positions = read_f32s(&dir.join("positions.f32"), px * 3, "positions.f32")?;
    let normals = read_f32s(&dir.join("normals.f32"), px * 3, "normals.f32")?;

    let mut shadow = Vec::new();
    for k in 0..lights.len() {
        let p = dir.join(format!("shadow_{k}.png"));
        let ploc = p.display().to_string();
        if !p.is_file() {
            return Err(Error::input(
                &ploc,
                format!("missing: frame.json lists {} lights, so shadow_0..shadow_{} are expected", lights.len(), lights.len() - 1),
            ));
        }
        let img = image::open(&p).map_err(|e| Error::input(&ploc, format!("cannot read PNG: {e}")))?;
        if img.width() != w || img.height() != h {
            return Err(Error::input(&ploc, format!("image is {}x{}, frame.json says {w}x{h}", img.width(), img.height())));
        }
        shadow.push(img.into_luma8().into_raw());
    }
    let extra_png = dir.join(format!("shadow_{}.png", lights.len()));
    if extra_png.exists() {
        return Err(Error::input(
            extra_png.display().to_string(),
            format!("more shadow masks than the {} lights listed in frame.json", lights.len()),
        ));
    }
    Ok(Dump {
        width: w,
        height: h,
        camera_pos: Vec3::from_array(frame.camera_pos),
        lights,
        triangles,
        positions,
        normals,
        shadow,
        spheres,
        camera,
        extra: frame.extra,
    })
}
