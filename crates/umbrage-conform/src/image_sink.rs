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
    draws: usize,
    /// (case, path) of the files [`copy_for`] copied, for a check that covers several cases.
    per_case: Vec<(String, String)>,
}

thread_local! {
    static SINK: RefCell<Option<Sink>> = const { RefCell::new(None) };
}

/// Opens `dir` (when given) for the images of the check about to run.
pub(crate) fn begin(dir: Option<PathBuf>) {
    SINK.with(|s| *s.borrow_mut() = dir.map(|dir| Sink { dir, written: Vec::new(), draws: 0, per_case: Vec::new() }));
}

/// Closes the directory: the paths of the images written since [`begin`].
pub(crate) fn finish() -> Vec<String> {
    SINK.with(|s| s.borrow_mut().take().map(|s| s.written).unwrap_or_default())
}

/// Closes the directory of a check that covers several cases: (case, path) of each file
/// [`copy_for`] copied.
pub(crate) fn finish_per_case() -> Vec<(String, String)> {
    SINK.with(|s| s.borrow_mut().take().map(|s| s.per_case).unwrap_or_default())
}

/// Copies `src` (an image the check already wrote) into `<dir>/<case>/` when a directory is open.
pub(crate) fn copy_for(case: &str, src: &std::path::Path) {
    SINK.with(|s| {
        let mut s = s.borrow_mut();
        let Some(sink) = s.as_mut() else { return };
        let dir = sink.dir.join(case);
        let Some(name) = src.file_name() else { return };
        let path = dir.join(name);
        match std::fs::create_dir_all(&dir).and_then(|_| std::fs::copy(src, &path)) {
            Ok(_) => sink.per_case.push((case.to_string(), path.display().to_string())),
            Err(e) => eprintln!("umbrage conform: failure image {} not written: {e}", path.display()),
        }
    });
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

/// A draw's stencil that differs from its prediction (the checks' `count_mismatches`):
/// `draw<k>.expected_stencil` (magenta: not judged), `.actual_stencil` (both grey, normalised to
/// the largest value of the two) and `.diff` (red: differs, blue: not judged), `k` counting the
/// draws of the check that differed.
pub(crate) fn stencil_mismatch(w: u32, h: u32, expected: &[u8], judged: &[bool], actual: &[u8]) {
    let n = (w * h) as usize;
    if expected.len() != n || judged.len() != n || actual.len() != n {
        return;
    }
    let Some(k) = next_draw() else { return };
    let top = expected.iter().chain(actual).copied().max().unwrap_or(0).max(1) as u32;
    let gray = |v: u8| {
        let g = (v as u32 * 255 / top) as u8;
        Rgb([g, g, g])
    };
    save(&format!("draw{k}.expected_stencil"), &texels(w, h, |i| if judged[i] { gray(expected[i]) } else { Rgb([160, 0, 160]) }));
    save(&format!("draw{k}.actual_stencil"), &texels(w, h, |i| gray(actual[i])));
    let diff = texels(w, h, |i| match (judged[i], expected[i] == actual[i]) {
        (false, _) => Rgb([0, 0, 160]),
        (true, false) => Rgb([255, 0, 0]),
        (true, true) => Rgb([0, 0, 0]),
    });
    save(&format!("draw{k}.diff"), &diff);
}

/// A draw's depth that differs from its prediction: `draw<k>.expected_depth` (grey = depth,
/// magenta: not judged), `.actual_depth` and `.depth_diff` (yellow: differs, blue: not judged,
/// black: equal), `k` counting the draws of the check that differed, as
/// [`stencil_mismatch`] counts them. `expected[i]` is `None` where the check does not judge
/// pixel `i`; `bad(i)` says whether a judged pixel differs (each check has its tolerance).
pub(crate) fn depth_mismatch(w: u32, h: u32, expected: &[Option<f64>], actual: &[f64], bad: &dyn Fn(usize) -> bool) {
    let n = (w * h) as usize;
    if expected.len() != n || actual.len() != n {
        return;
    }
    let Some(k) = next_draw() else { return };
    save(&format!("draw{k}.expected_depth"), &texels(w, h, |i| expected[i].map_or(Rgb([160, 0, 160]), unit_gray)));
    save(&format!("draw{k}.actual_depth"), &texels(w, h, |i| unit_gray(actual[i])));
    let diff = texels(w, h, |i| match expected[i] {
        None => Rgb([0, 0, 160]),
        Some(_) if bad(i) => Rgb([255, 255, 0]),
        Some(_) => Rgb([0, 0, 0]),
    });
    save(&format!("draw{k}.depth_diff"), &diff);
}

/// The number of the next draw that differed (1, 2, ...), when a directory is open.
fn next_draw() -> Option<usize> {
    SINK.with(|s| {
        s.borrow_mut().as_mut().map(|sink| {
            sink.draws += 1;
            sink.draws
        })
    })
}
