//! The `[[sphere]]` tables: analytic sphere casters (`center`, `radius`, `color`, `opacity`,
//! `casts_shadow`, optional `segments` fixing the shadow volume's n-gon), validated against
//! the camera and the lights.

use super::keys::{Ctx, FileSphere};
use crate::{Camera, Light, SceneSphere};
use glam::{DVec3, Vec3};
use std::ops::Range;
use umbrage::error::Result;
use umbrage::geom::sphere::{Sphere, MAX_SEGMENTS};

/// The validated sphere of the `[[sphere]]` table at `s` (index `i`).
pub(super) fn sphere(cx: &Ctx, i: usize, s: &Range<usize>, f: &FileSphere) -> Result<SceneSphere> {
    let finite = |key: &str, v: f64| -> Result<f64> {
        if v.is_finite() {
            Ok(v)
        } else {
            Err(cx.key_err(s, key, format!("non-finite number {v}")))
        }
    };
    let center = DVec3::new(finite("center", f.center[0])?, finite("center", f.center[1])?, finite("center", f.center[2])?);
    let radius = finite("radius", f.radius)?;
    let sphere = Sphere { center, radius };
    if let Some(problem) = sphere.problem() {
        let key = if radius > 0.0 { "center" } else { "radius" };
        return Err(cx.key_err(s, key, format!("sphere {i}: {problem}")));
    }
    let opacity = match f.opacity {
        Some(o) => cx.num(s, "opacity", o)?,
        None => 1.0,
    };
    if !(0.0..=1.0).contains(&opacity) {
        return Err(cx.key_err(s, "opacity", format!("must be in [0, 1], got {opacity}")));
    }
    if opacity < 1.0 {
        return Err(cx.key_err(
            s,
            "opacity",
            "transparent spheres are not supported (opacity must be 1); use a [[mesh]] shape = \"sphere\"",
        ));
    }
    let segments = match f.segments {
        Some(n) => Some(cx.int(s, "segments", Some(n), 3, 3, MAX_SEGMENTS)?),
        None => None,
    };
    Ok(SceneSphere {
        name: f.name.clone().unwrap_or_else(|| format!("sphere{i}")),
        sphere,
        color: cx.color(s, "color", f.color, Vec3::splat(0.8))?,
        opacity,
        casts_shadow: f.casts_shadow.unwrap_or(true),
        segments,
    })
}

/// Refuses a camera eye inside or on a sphere, and a positional light inside or on a
/// shadow-casting sphere (no tangent cone exists: clear errors rather than wrong images).
pub(super) fn check_placement(cx: &Ctx, s: &Range<usize>, sp: &SceneSphere, camera: &Camera, lights: &[Light]) -> Result<()> {
    if let Some(msg) = crate::sphere_placement_problem(sp, camera, lights) {
        return Err(cx.key_err(s, "center", msg));
    }
    Ok(())
}
