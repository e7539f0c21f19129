//! Failure images of the checks that compare numbers, not texels (`commands.buffers`,
//! `commands.fill_buffer`, `commands.dispatch`, `commands.dispatch_indirect`,
//! `commands.queries`, `legacy.msaa_depth_locations`, ...): what they expected and what they
//! read, drawn from the data itself, through [`super::image_sink::save`] (the same
//! `<out>/failures/<case>/<label>.<kind>.png` as the texel checks' images; nothing is written
//! when no directory is open).
//!
//! - [`words`]: a buffer's words (or bytes) as a heat map, one texel a value (grey on a log
//!   scale), `<label>.expected`, `<label>.actual` and `<label>.diff` (red: differs, black: equal);
//! - [`bars`]: a few counts against their accepted ranges, one row each (`<label>.bars`: the
//!   range in green, the value read a white mark inside it, red outside);
//! - [`points`]: positions in a pixel, expected against measured (`<label>.points`).
//!
//! The test seam [`skewed`]: `UMBRAGE_CONFORM_MISMATCH=<check>[,<check>...]` (read by the
//! command line, like `UMBRAGE_CONFORM_BREAK`) makes the named checks expect a wrong value, so
//! that they fail and write these images (or the texel images of
//! [`super::image_sink`]: `legacy.*`, `commands.*` and `mesh.*` checks alike); a drawn case
//! named there expects a wrong depth (`suite::skew_depth`), a failure on depth alone.

use super::image_sink::{save, texels};
use image::{Rgb, RgbImage};
use std::cell::Cell;

thread_local! {
    static SKEW: Cell<bool> = const { Cell::new(false) };
}

/// Sets [`skewed`] for the check about to run on this thread.
pub(crate) fn set_skew(on: bool) {
    SKEW.with(|s| s.set(on));
}

/// Test seam: whether the running check must expect a wrong value (see the module docs).
pub(crate) fn skewed() -> bool {
    SKEW.with(|s| s.get())
}

const RED: Rgb<u8> = Rgb([255, 0, 0]);
const GREEN: Rgb<u8> = Rgb([0, 160, 0]);
const WHITE: Rgb<u8> = Rgb([255, 255, 255]);
const BLACK: Rgb<u8> = Rgb([0, 0, 0]);

/// Grey of a word on a log scale (0 black, 2^32 - 1 white).
fn log_gray(v: u64) -> Rgb<u8> {
    let g = ((64 - v.leading_zeros()) as f64 / 32.0 * 255.0).min(255.0) as u8;
    Rgb([g, g, g])
}

/// The grid a buffer of `n` values is drawn in: about twice as wide as high, 16 to 1024
/// values a row.
fn grid(n: usize) -> (u32, u32) {
    let w = ((n as f64 * 2.0).sqrt().ceil() as usize).next_power_of_two().clamp(16, 1024);
    (w as u32, n.div_ceil(w).max(1) as u32)
}

/// `<label>.expected`, `<label>.actual`, `<label>.diff` of two equally long buffers of values
/// (words or bytes); values past the end of either are drawn blue.
pub(crate) fn words<T: Copy + Into<u64>>(label: &str, expected: &[T], got: &[T]) {
    let n = expected.len().max(got.len());
    let (w, h) = grid(n);
    let at = |v: &[T], i: usize| v.get(i).map(|&x| x.into());
    let px = |v: Option<u64>| v.map_or(Rgb([0, 0, 160]), log_gray);
    save(&format!("{label}.expected"), &texels(w, h, |i| px(at(expected, i))));
    save(&format!("{label}.actual"), &texels(w, h, |i| px(at(got, i))));
    save(
        &format!("{label}.diff"),
        &texels(w, h, |i| match (at(expected, i), at(got, i)) {
            (Some(a), Some(b)) if a == b => BLACK,
            (None, None) => Rgb([0, 0, 160]),
            _ => RED,
        }),
    );
}

/// One count against the range it must fall in.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Bar {
    /// The least accepted value.
    pub lo: f64,
    /// The largest accepted value.
    pub hi: f64,
    /// What was read.
    pub got: f64,
}

/// `<label>.bars`: a row per [`Bar`], 256 pixels on a scale of its own (0 to 1.25 times the
/// largest of its range and value): the accepted range a green band, the value read a mark,
/// white inside the range and red outside.
pub(crate) fn bars(label: &str, rows: &[Bar]) {
    if rows.is_empty() {
        return;
    }
    const W: u32 = 256;
    const ROW: u32 = 12;
    let mut img = RgbImage::from_pixel(W, ROW * rows.len() as u32, BLACK);
    for (k, b) in rows.iter().enumerate() {
        let top = b.hi.max(b.got).max(b.lo).max(1e-9) * 1.25;
        let x = |v: f64| ((v.max(0.0) / top) * (W - 1) as f64).round() as u32;
        let (lo, hi) = (x(b.lo), x(b.hi).max(x(b.lo) + 1));
        let ok = b.got >= b.lo && b.got <= b.hi;
        let g = x(b.got).min(W - 2);
        for y in k as u32 * ROW + 2..(k as u32 + 1) * ROW - 2 {
            for xx in lo..=hi.min(W - 1) {
                img.put_pixel(xx, y, GREEN);
            }
            for xx in g..g + 2 {
                img.put_pixel(xx, y, if ok { WHITE } else { RED });
            }
        }
    }
    save(&format!("{label}.bars"), &img);
}

/// `<label>.points`: a pixel's square (256 x 256, a grid line every 1/16), each expected
/// position a green cross, each measured one a red cross (white where the two are within
/// `tolerance` of each other); positions in 0..1.
pub(crate) fn points(label: &str, expected: &[[f32; 2]], got: &[[f32; 2]], tolerance: f32) {
    const S: u32 = 256;
    let mut img = RgbImage::from_pixel(S, S, BLACK);
    for k in (0..S).step_by(16) {
        for t in 0..S {
            img.put_pixel(k, t, Rgb([40, 40, 40]));
            img.put_pixel(t, k, Rgb([40, 40, 40]));
        }
    }
    let mut cross = |p: [f32; 2], c: Rgb<u8>| {
        let (cx, cy) = ((p[0].clamp(0.0, 1.0) * (S - 1) as f32) as i32, (p[1].clamp(0.0, 1.0) * (S - 1) as f32) as i32);
        for d in -4..=4 {
            for (x, y) in [(cx + d, cy), (cx, cy + d)] {
                if (0..S as i32).contains(&x) && (0..S as i32).contains(&y) {
                    img.put_pixel(x as u32, y as u32, c);
                }
            }
        }
    };
    for &p in expected {
        cross(p, GREEN);
    }
    for (i, &p) in got.iter().enumerate() {
        let same = expected.get(i).is_some_and(|e| (e[0] - p[0]).abs() <= tolerance && (e[1] - p[1]).abs() <= tolerance);
        cross(p, if same { WHITE } else { RED });
    }
    save(&format!("{label}.points"), &img);
}

#[cfg(test)]
mod tests {
    #[test]
    fn grids_hold_every_value() {
        for n in [1, 7, 512, 1022, 428_000] {
            let (w, h) = super::grid(n);
            assert!((w * h) as usize >= n && (w as usize) * (h as usize - 1) < n, "{n}: {w} x {h}");
        }
    }
}
