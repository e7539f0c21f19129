//! The `[camera]` and `[[light]]` tables.

use super::keys::{line_of, Ctx, FileCamera, FileLight};
use crate::{Camera, Light, LightKind};
use glam::Vec3;
use std::ops::Range;
use umbrage::error::{Error, Result};

/// The validated camera of the `[camera]` table at `cs`.
pub(super) fn camera(cx: &Ctx, cs: &Range<usize>, c: FileCamera) -> Result<Camera> {
    let camera = Camera {
        eye: cx.v3(cs, "eye", c.eye)?,
        target: cx.v3(cs, "target", c.target)?,
        up: match c.up {
            Some(u) => cx.v3(cs, "up", u)?,
            None => Vec3::Y,
        },
        fov_y_deg: match c.fov_y_deg {
            Some(f) => cx.num(cs, "fov_y_deg", f)?,
            None => 60.0,
        },
        near: cx.positive(cs, "near", c.near, 0.1)?,
    };
    let view = camera.target - camera.eye;
    if view.length_squared() == 0.0 || !view.is_finite() {
        return Err(cx.key_err(cs, "target", "camera target must differ from eye"));
    }
    if camera.up.length_squared() == 0.0 || view.normalize().cross(camera.up.normalize()).length() < 1e-4 {
        return Err(cx.key_err(cs, "up", "camera up must be nonzero and not parallel to the view direction"));
    }
    if !(camera.fov_y_deg > 0.0 && camera.fov_y_deg < 180.0) {
        return Err(cx.key_err(cs, "fov_y_deg", format!("must be in (0, 180), got {}", camera.fov_y_deg)));
    }
    Ok(camera)
}

/// The validated light of the `[[light]]` table at `s`; `eye` is the camera eye, which a
/// positional light must not coincide with.
pub(super) fn light(cx: &Ctx, s: &Range<usize>, l: &FileLight, eye: Vec3) -> Result<Light> {
    let kind = match l.kind.as_str() {
        "point" | "area" => LightKind::Point,
        "spot" => LightKind::Spot,
        "directional" => LightKind::Directional,
        other => {
            return Err(Error::UnknownName {
                what: "light kind",
                name: other.to_string(),
                expected: format!("point, spot, directional, area; at {}:{}", cx.origin, cx.key_line(s, "kind")),
            })
        }
    };
    if l.kind == "area" && l.direction.is_some() {
        return Err(cx.key_err(s, "direction", "an area light faces its `normal` (it has no direction)"));
    }
    let positional = kind != LightKind::Directional;
    let position = match (positional, l.position) {
        (true, Some(p)) => cx.v3(s, "position", p)?,
        (true, None) => return Err(cx.at(line_of(cx.src, s.start), format!("{} light needs a position", l.kind))),
        (false, Some(_)) => return Err(cx.key_err(s, "position", "a directional light has no position")),
        (false, None) => Vec3::ZERO,
    };
    let direction = match (kind != LightKind::Point, l.direction) {
        (true, Some(d)) => {
            let d = cx.v3(s, "direction", d)?;
            if d.length_squared() == 0.0 || !d.normalize().is_finite() {
                return Err(cx.key_err(s, "direction", "direction must be a nonzero vector"));
            }
            d.normalize()
        }
        (true, None) => return Err(cx.at(line_of(cx.src, s.start), format!("{} light needs a direction", l.kind))),
        (false, Some(_)) => return Err(cx.key_err(s, "direction", "a point light has no direction")),
        (false, None) => Vec3::NEG_Y,
    };
    let cone_deg = match (kind == LightKind::Spot, l.cone_deg) {
        (true, c) => {
            let c = match c {
                Some(c) => cx.num(s, "cone_deg", c)?,
                None => 45.0,
            };
            if !(c > 0.0 && c < 180.0) {
                return Err(cx.key_err(s, "cone_deg", format!("must be in (0, 180), got {c}")));
            }
            c
        }
        (false, Some(_)) => return Err(cx.key_err(s, "cone_deg", "only spot lights have a cone")),
        (false, None) => 45.0,
    };
    let intensity = match l.intensity {
        Some(i) => cx.num(s, "intensity", i)?,
        None => 1.0,
    };
    if intensity < 0.0 {
        return Err(cx.key_err(s, "intensity", "must be >= 0"));
    }
    let radius = match l.radius {
        Some(r) => Some(cx.positive(s, "radius", Some(r), 1.0)?),
        None => None,
    };
    if positional && position == eye {
        return Err(cx.key_err(s, "position", "a light must not coincide with the camera eye"));
    }
    let area = super::area_light::area(cx, s, l, position, eye)?;
    Ok(Light { kind, position, direction, color: cx.color(s, "color", l.color, Vec3::ONE)?, intensity, radius, cone_deg, area })
}
