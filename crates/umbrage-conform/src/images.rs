//! Failure images: for a failed case, its expected and actual stencil (and depth) tiles and
//! their difference, scaled up with nearest-neighbour so an 8 x 8 tile is readable.

use super::batch::TileResult;
use super::cases::Case;
use super::model::{self, DepthExp, Expected};
use image::{Rgb, RgbImage};
use std::path::Path;
use umbrage::error::{Error, Result};

const UNJUDGED: Rgb<u8> = Rgb([160, 0, 160]);

fn scaled(w: u32, h: u32, px: impl Fn(usize) -> Rgb<u8>) -> RgbImage {
    let s = (128 / w.max(h)).max(1);
    RgbImage::from_fn(w * s, h * s, |x, y| px(((y / s) * w + x / s) as usize))
}

fn gray(v: u8) -> Rgb<u8> {
    Rgb([v, v, v])
}

fn depth_gray(v: f64) -> Rgb<u8> {
    gray((v.clamp(0.0, 1.0) * 255.0).round() as u8)
}

fn save(img: &RgbImage, path: &Path) -> Result<String> {
    img.save(path).map_err(|e| Error::io(path.display().to_string(), std::io::Error::other(e.to_string())))?;
    Ok(path.display().to_string())
}

/// Writes `expected.png`, `actual.png` and `diff.png` (stencil: grey = value, magenta = not
/// judged; diff: red = stencil differs, yellow = depth differs, blue = not judged, black =
/// equal) and, when the case judges depth, `expected_depth.png`, `actual_depth.png` and
/// `diff_depth.png` (yellow = depth differs, blue = not judged, black = equal), into `dir`.
/// Returns the paths written.
pub fn write_failure(dir: &Path, case: &Case, exp: &Expected, got: &TileResult) -> Result<Vec<String>> {
    std::fs::create_dir_all(dir).map_err(|e| Error::io(dir.display().to_string(), e))?;
    let (w, h) = case.size;
    let kind = case.config.depth_kind();
    let depth_bad = |i: usize| !got.depth.is_empty() && !exp.depth[i].accepts(model::from_raw(kind, got.depth[i]));
    let mut paths = Vec::new();
    paths.push(save(&scaled(w, h, |i| exp.stencil[i].map_or(UNJUDGED, gray)), &dir.join("expected.png"))?);
    paths.push(save(&scaled(w, h, |i| gray(got.stencil[i])), &dir.join("actual.png"))?);
    let diff = scaled(w, h, |i| match exp.stencil[i] {
        Some(e) if e != got.stencil[i] => Rgb([255, 0, 0]),
        _ if depth_bad(i) => Rgb([255, 255, 0]),
        None => Rgb([0, 0, 160]),
        _ => Rgb([0, 0, 0]),
    });
    paths.push(save(&diff, &dir.join("diff.png"))?);
    if exp.depth.iter().any(|d| *d != DepthExp::Any) && !got.depth.is_empty() {
        let e = scaled(w, h, |i| match exp.depth[i] {
            DepthExp::Any => UNJUDGED,
            DepthExp::Exact(v) => depth_gray(v),
            DepthExp::Range(a, b) => depth_gray((a + b) * 0.5),
        });
        paths.push(save(&e, &dir.join("expected_depth.png"))?);
        let a = scaled(w, h, |i| depth_gray(model::from_raw(kind, got.depth[i])));
        paths.push(save(&a, &dir.join("actual_depth.png"))?);
        let d = scaled(w, h, |i| match exp.depth[i] {
            DepthExp::Any => Rgb([0, 0, 160]),
            _ if depth_bad(i) => Rgb([255, 255, 0]),
            _ => Rgb([0, 0, 0]),
        });
        paths.push(save(&d, &dir.join("diff_depth.png"))?);
    }
    Ok(paths)
}
