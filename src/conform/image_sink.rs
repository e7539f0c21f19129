//! Failure images of the single-configuration checks (`legacy.*`, `commands.*`): a check that
//! finds texels differing saves what it expected, what it read back and their difference
//! through [`save`], into the directory [`super::units::run_legacy`] opened for that case
//! (`<out>/failures/<case>/`), and the case's outcome lists them as a configuration case's
//! failure lists its tiles. Nothing is written when no directory is open (no `--out`, or the
//! check runs outside a case).

use image::{Rgb, RgbImage};
use std::cell::RefCell;
use std::path::PathBuf;

struct Sink {
    dir: PathBuf,
    written: Vec<String>,
}

thread_local! {
    static SINK: RefCell<Option<Sink>> = const { RefCell::new(None) };
}

/// Opens `dir` (when given) for the images of the check about to run.
pub(crate) fn begin(dir: Option<PathBuf>) {
    SINK.with(|s| *s.borrow_mut() = dir.map(|dir| Sink { dir, written: Vec::new() }));
}

/// Closes the directory: the paths of the images written since [`begin`].
pub(crate) fn finish() -> Vec<String> {
    SINK.with(|s| s.borrow_mut().take().map(|s| s.written).unwrap_or_default())
}

/// Saves `img` as `<dir>/<name>.png` when a directory is open (a failure to write is reported
/// on stderr: the check's verdict stands either way).
pub(crate) fn save(name: &str, img: &RgbImage) {
    SINK.with(|s| {
        let mut s = s.borrow_mut();
        let Some(sink) = s.as_mut() else { return };
        let path = sink.dir.join(format!("{name}.png"));
        let r = std::fs::create_dir_all(&sink.dir).map_err(|e| e.to_string()).and_then(|_| img.save(&path).map_err(|e| e.to_string()));
        match r {
            Ok(()) => sink.written.push(path.display().to_string()),
            Err(e) => eprintln!("umbrage conform: failure image {} not written: {e}", path.display()),
        }
    });
}

/// A `w` x `h` image of per-texel colours, scaled up (nearest) so that the short side is at
/// least 128 pixels.
pub(crate) fn texels(w: u32, h: u32, px: impl Fn(usize) -> Rgb<u8>) -> RgbImage {
    let s = (128 / w.min(h).max(1)).max(1);
    RgbImage::from_fn(w * s, h * s, |x, y| px(((y / s) * w + x / s) as usize))
}

/// Grey of a value in 0..=1 (clamped).
pub(crate) fn unit_gray(v: f64) -> Rgb<u8> {
    let g = (v.clamp(0.0, 1.0) * 255.0).round() as u8;
    Rgb([g, g, g])
}
