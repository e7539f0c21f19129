//! `umbrage export-scene NAME|FILE OUT`: a scene (built-in or TOML) written in a flat text format
//! that a C or C++ host reads with `fscanf` (examples/c/scene.c; docs/c-api.md describes it).
//!
//! ```text
//! umbrage-scene 1
//! camera EX EY EZ TX TY TZ UX UY UZ FOV_Y_DEG NEAR
//! light KIND PX PY PZ DX DY DZ CONE_DEG RADIUS      (KIND point|spot|directional; RADIUS 0: none)
//! mesh NAME CASTS OPACITY VERTICES TRIANGLES          (CASTS 0|1; NAME without spaces)
//! transform M0 .. M15                                 (object -> world, column-major)
//! v X Y Z                                             (VERTICES lines, object space)
//! t A B C                                             (TRIANGLES lines, 0-based)
//! sphere CX CY CZ R CASTS                             (analytic spheres)
//! end
//! ```
//! Numbers are written with Rust's shortest round-trip formatting, so a reader gets the scene's
//! `f32`s back exactly. Area lights are refused (expand them first).

use std::fmt::Write as _;
use std::path::Path;
use umbrage::geom::LightKind;
use umbrage::{Error, Result};

/// Writes the scene `spec` (a built-in name or a TOML file) to `out`.
pub fn export_scene(spec: &str, out: &Path) -> Result<()> {
    let scene = umbrage_scene::load(spec)?;
    let mut s = String::from("umbrage-scene 1\n");
    let c = &scene.camera;
    let v = |v: glam::Vec3| format!("{} {} {}", v.x, v.y, v.z);
    let _ = writeln!(s, "camera {} {} {} {} {}", v(c.eye), v(c.target), v(c.up), c.fov_y_deg, c.near);
    for (i, l) in scene.lights.iter().enumerate() {
        if l.area.is_some() {
            return Err(Error::input(
                spec,
                format!("light {i} is an area light: the scene export has point, spot and directional lights only"),
            ));
        }
        let kind = match l.kind {
            LightKind::Point => "point",
            LightKind::Spot => "spot",
            LightKind::Directional => "directional",
        };
        let _ = writeln!(s, "light {kind} {} {} {} {}", v(l.position), v(l.direction), l.cone_deg, l.radius.unwrap_or(0.0));
    }
    for m in &scene.meshes {
        let name: String = m.name.chars().map(|ch| if ch.is_whitespace() { '_' } else { ch }).collect();
        let _ = writeln!(
            s,
            "mesh {} {} {} {} {}",
            if name.is_empty() { "mesh" } else { &name },
            m.casts_shadow as u32,
            m.opacity,
            m.mesh.positions.len(),
            m.mesh.triangles.len()
        );
        let t: Vec<String> = m.transform.to_cols_array().iter().map(|x| x.to_string()).collect();
        let _ = writeln!(s, "transform {}", t.join(" "));
        for p in &m.mesh.positions {
            let _ = writeln!(s, "v {}", v(*p));
        }
        for t in &m.mesh.triangles {
            let _ = writeln!(s, "t {} {} {}", t[0], t[1], t[2]);
        }
    }
    for sp in &scene.spheres {
        let c = sp.sphere.center;
        let _ = writeln!(s, "sphere {} {} {} {} {}", c.x, c.y, c.z, sp.sphere.radius, sp.casts_shadow as u32);
    }
    s.push_str("end\n");
    std::fs::write(out, s).map_err(|e| Error::io(out.display().to_string(), e))
}
