//! OBJ text: a generator of mostly well-formed and pathological OBJ files (`fuzz_obj`), the
//! byte-level mutation the scene generator shares, and the check of a loaded mesh.

use crate::{Rng, OBJ_OK};
use glam::Mat4;
use std::fmt::Write as _;
use std::sync::atomic::Ordering;
use umbrage::geom::topology::Topology;
use umbrage::shadow::Caster;
use umbrage_scene::obj::load_obj_str;

fn number(rng: &mut Rng) -> String {
    if !rng.bad() {
        return format!("{:.3}", rng.range(-3.0, 3.0));
    }
    match rng.below(24) {
        0 => "nan".into(),
        1 => "NaN".into(),
        2 => "inf".into(),
        3 => "-inf".into(),
        4 => "1e39".into(),
        5 => "-1e39".into(),
        6 => "1e-45".into(),
        7 => "-0".into(),
        8 => rng.pick(&["", "-", "+", ".", "e", "1e", "--1", "0x1p3", "1,5", "1.2.3", "٣", "\u{0}", "1_000"]).to_string(),
        9 => format!("{}", rng.u64()),
        10 => format!("{:e}", f32::from_bits(rng.u64() as u32)),
        11 => format!("{}", rng.range(-1e6, 1e6)),
        12 => format!("{}", rng.range(-1e-6, 1e-6)),
        _ => format!("{:.3}", rng.range(-3.0, 3.0)),
    }
}

fn index(rng: &mut Rng, nv: i64) -> String {
    let nv = nv.max(1);
    if !rng.bad() {
        return format!("{}", 1 + rng.below(nv as usize));
    }
    match rng.below(20) {
        0 => "0".into(),
        1 => format!("{}", nv + 1 + rng.below(5) as i64),
        2 => format!("-{}", nv + 1),
        3 => format!("-{}", 1 + rng.below(nv as usize) as i64),
        4 => {
            rng.pick(&["", "-", "x", "1.5", "99999999999999999999", "-99999999999999999999", "4294967296", "2147483648", "-0"]).to_string()
        }
        5 => format!("{}", rng.u64() as i64),
        _ => format!("{}", 1 + rng.below(nv as usize)),
    }
}

pub(crate) fn obj_text(rng: &mut Rng) -> String {
    rng.pick_mode();
    let mut s = String::new();
    let nlines = 1 + rng.below(40);
    let mut nv = 0i64;
    let (mut nvt, mut nvn) = (0i64, 0i64);
    // mostly-sane prologue so that faces often refer to real vertices
    if rng.chance(0.7) {
        for _ in 0..(3 + rng.below(8)) {
            let _ = writeln!(s, "v {:.3} {:.3} {:.3}", rng.range(-2.0, 2.0), rng.range(-2.0, 2.0), rng.range(-2.0, 2.0));
            nv += 1;
        }
    }
    for _ in 0..nlines {
        match if rng.bad() { rng.below(16) } else { rng.below(11) } {
            0..=3 => {
                let k = if rng.bad() { *rng.pick(&[3, 3, 3, 0, 1, 2, 4, 6]) } else { 3 };
                let xs: Vec<String> = (0..k).map(|_| number(rng)).collect();
                let _ = writeln!(s, "v {}", xs.join(" "));
                nv += 1;
            }
            4 => {
                let k = if rng.bad() { rng.below(4) } else { 2 };
                let xs: Vec<String> = (0..k).map(|_| number(rng)).collect();
                let _ = writeln!(s, "vt {}", xs.join(" "));
                nvt += 1;
            }
            5 => {
                let k = if rng.bad() { rng.below(5) } else { 3 };
                let xs: Vec<String> = (0..k).map(|_| number(rng)).collect();
                let _ = writeln!(s, "vn {}", xs.join(" "));
                nvn += 1;
            }
            6..=10 => {
                let k = if rng.bad() { *rng.pick(&[3, 3, 3, 4, 4, 5, 8, 0, 1, 2, 12]) } else { *rng.pick(&[3, 3, 4, 5]) };
                let style = if rng.bad() { rng.below(5) } else { 0 };
                let corners: Vec<String> = (0..k)
                    .map(|_| {
                        let v = index(rng, nv);
                        match if rng.chance(0.1) { rng.below(5) } else { style } {
                            0 => v,
                            1 => format!("{v}/{}", index(rng, nvt)),
                            2 => format!("{v}/{}/{}", index(rng, nvt), index(rng, nvn)),
                            3 => format!("{v}//{}", index(rng, nvn)),
                            _ => format!("{v}/{}", rng.pick(&["", "/", "//", "a", "1/2/3/4"])),
                        }
                    })
                    .collect();
                let _ = writeln!(s, "f {}", corners.join(" "));
            }
            11 => {
                let _ = writeln!(
                    s,
                    "{} {}",
                    rng.pick(&["o", "g", "s", "usemtl", "mtllib", "l", "p"]),
                    rng.pick(&["", "a", "b c", "1", "off", "x.mtl", "1 2 3"])
                );
            }
            12 => {
                let _ = writeln!(
                    s,
                    "{}",
                    rng.pick(&["", "#", "# comment", "   ", "\t", "\\", "v\\", "f 1 2 3 \\", "vp 1 2", "cstype bezier", "\r"])
                );
            }
            13 => {
                // garbage (valid UTF-8; raw bytes go through `load_obj` below)
                let n = rng.below(20);
                let g: String = (0..n).map(|_| char::from_u32(rng.below(0x3000) as u32).unwrap_or('?')).collect();
                let _ = writeln!(s, "{g}");
            }
            14 => {
                let _ = write!(s, "{}", rng.pick(&["v 1 2 3", "f 1 2", "f", "v", "f 1 2 3"]));
                // no newline
            }
            _ => {
                let _ = writeln!(s, "{} {}", rng.pick(&["V", "F", "vv", "ff", "v1", "f1", " v", "\tf"]), number(rng));
            }
        }
    }
    if rng.bad() && rng.chance(0.3) {
        mutate_bytes(rng, &mut s);
    }
    s
}

/// Random byte-level edits that keep the text valid UTF-8 (edits at char boundaries).
pub(crate) fn mutate_bytes(rng: &mut Rng, s: &mut String) {
    for _ in 0..(1 + rng.below(4)) {
        if s.is_empty() {
            s.push('v');
        }
        let mut i = rng.below(s.len() + 1);
        while !s.is_char_boundary(i) {
            i -= 1;
        }
        match rng.below(4) {
            0 => s.insert(i, *rng.pick(&[' ', '\n', '/', '-', '#', '=', '"', '[', ']', '.', '0', 'e', '\u{feff}', '\u{0}'])),
            1 => {
                let mut j = (i + 1 + rng.below(8)).min(s.len());
                while !s.is_char_boundary(j) {
                    j += 1;
                }
                s.replace_range(i..j, "");
            }
            2 => {
                // duplicate a line-ish slice
                let mut j = (i + rng.below(40)).min(s.len());
                while !s.is_char_boundary(j) {
                    j += 1;
                }
                let piece = s[i..j].to_string();
                s.insert_str(i, &piece);
            }
            _ => {
                let mut j = (i + 1).min(s.len());
                while !s.is_char_boundary(j) {
                    j += 1;
                }
                const R: [&str; 7] = ["1", "x", " ", "\n", "-1", "nan", "9e99"];
                let r = R[rng.below(R.len())];
                s.replace_range(i..j, r);
            }
        }
    }
}

#[allow(clippy::ptr_arg)] // the generator's input type
pub(crate) fn check_obj(text: &String) {
    if let Ok(m) = load_obj_str(text, "fuzz.obj") {
        OBJ_OK.fetch_add(1, Ordering::Relaxed);
        m.validate("fuzz.obj").expect("load_obj_str returned an invalid mesh");
        let _ = Topology::build(&m);
        let _ = Caster::new("fuzz.obj", &m, Mat4::IDENTITY);
    }
}
