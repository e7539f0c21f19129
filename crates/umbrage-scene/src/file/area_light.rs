//! The area-light keys of a `[[light]]` table (`kind = "area"`):
//!
//! ```toml
//! [[light]]
//! kind = "area"
//! position = [0, 4, 0]   # the centre
//! shape = "disc"         # "disc" (default) | "rect"
//! size = 0.5             # disc: its radius; rect: [width, height]
//! normal = [0, -1, 0]    # the way it faces (default straight down); emission is two-sided
//! # tangent = [1, 0, 0]  # rect: the direction of its width (default: world X in its plane)
//! samples = 16           # point lights it is rendered with (1..=1024, default 16)
//! ```

use super::keys::{Ctx, FileLight, NumOrVec};
use glam::Vec3;
use std::ops::Range;
use umbrage::error::Result;
use umbrage::geom::area::{default_tangent, AreaLight, AreaShape, MAX_SAMPLES};

/// Default point-light samples of an area light.
const DEFAULT_SAMPLES: u32 = 16;

/// The area part of light `l` (table at `s`): `Some` for `kind = "area"`, `None` otherwise
/// (where the area keys are refused). `position` is the validated centre, `eye` the camera's.
pub(super) fn area(cx: &Ctx, s: &Range<usize>, l: &FileLight, position: Vec3, eye: Vec3) -> Result<Option<AreaLight>> {
    if l.kind != "area" {
        let keys = [
            ("shape", l.shape.is_some()),
            ("size", l.size.is_some()),
            ("normal", l.normal.is_some()),
            ("tangent", l.tangent.is_some()),
            ("samples", l.samples.is_some()),
        ];
        if let Some((k, _)) = keys.iter().find(|(_, present)| *present) {
            return Err(cx.key_err(s, k, format!("only area lights (kind = \"area\") have `{k}`")));
        }
        return Ok(None);
    }
    if l.cone_deg.is_some() {
        return Err(cx.key_err(s, "cone_deg", "an area light has no cone"));
    }
    let shape_name = l.shape.as_deref().unwrap_or("disc");
    let size =
        l.size.as_ref().ok_or_else(|| cx.key_err(s, "kind", "an area light needs a `size` (disc: radius; rect: [width, height])"))?;
    let shape = match (shape_name, size) {
        ("disc", NumOrVec::Num(r)) => AreaShape::Disc { radius: cx.num(s, "size", *r)? },
        ("disc", NumOrVec::Vec(_)) => return Err(cx.key_err(s, "size", "a disc's size is its radius, one number")),
        ("rect", NumOrVec::Vec(v)) => {
            let v = cx.vecn(s, "size", v, 2)?;
            AreaShape::Rect { width: v[0], height: v[1] }
        }
        ("rect", NumOrVec::Num(_)) => return Err(cx.key_err(s, "size", "a rectangle's size is [width, height]")),
        (other, _) => return Err(cx.key_err(s, "shape", format!("unknown area-light shape `{other}` (expected disc, rect)"))),
    };
    let normal = match l.normal {
        Some(n) => cx.v3(s, "normal", n)?,
        None => Vec3::NEG_Y,
    };
    if normal.length_squared() == 0.0 || !normal.normalize().is_finite() {
        return Err(cx.key_err(s, "normal", "must be a nonzero vector"));
    }
    let normal = normal.normalize();
    let tangent = match (l.tangent, shape) {
        (Some(_), AreaShape::Disc { .. }) => return Err(cx.key_err(s, "tangent", "only a rectangle has a tangent")),
        (Some(t), _) => {
            let t = cx.v3(s, "tangent", t)?;
            let t = t - normal * t.dot(normal);
            if t.length_squared() < 1e-12 || !t.normalize().is_finite() {
                return Err(cx.key_err(s, "tangent", "must be a nonzero vector not parallel to the normal"));
            }
            t.normalize()
        }
        (None, _) => default_tangent(normal),
    };
    let samples = cx.int(s, "samples", l.samples, DEFAULT_SAMPLES, 1, MAX_SAMPLES)?;
    let area = AreaLight { shape, normal, tangent, samples };
    area.validate().map_err(|m| cx.key_err(s, "size", m))?;
    if area.contains(position, eye, 1e-6 * (1.0 + position.length())) {
        return Err(cx.key_err(s, "position", "the camera eye lies on the area light"));
    }
    Ok(Some(area))
}
