//! Fuzzing on stable Rust (issue 13, item 2): seeded generators for OBJ text, scene TOML, mesh
//! topology and the planner. Every case asserts "no panic" (errors are fine); planner cases also
//! assert that the emitted volume is closed (z-fail parts with light caps) and that on the
//! multiplicity path every undirected edge's signed side count equals its multiplicity.
//!
//! `UMBRAGE_FUZZ_CASES` = cases per generator (default 1000); `UMBRAGE_FUZZ_SEED` = base seed
//! (default fixed, so CI is reproducible). `make fuzz` runs it in release with a large count.
//! A failing case prints its generator, seed and input; the fixed inputs of past findings are
//! the `regression_*` tests at the bottom.

use glam::{EulerRot, Mat4, Quat, Vec3, Vec4};
use std::cell::RefCell;
use std::collections::HashMap;
use std::fmt::Write as _;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::PathBuf;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Once;
use std::time::Instant;
use umbrage::geom::topology::{Topology, Weld};
use umbrage::geom::{Camera, Light, LightKind, Mesh};
use umbrage::scene::{obj::load_obj_str, shapes};
use umbrage::shadow::{plan_light_with, Case, Caster, CasterPlan, Method, PlanInput, PlanOptions, VolumePath};

// ---------------------------------------------------------------------------------------------
// harness

/// SplitMix64: small, fast, seedable.
/// `bad` is the probability the text generators pick a pathological value where they could
/// (1 = always consider one; small = mostly well-formed input that gets past the parsers).
struct Rng(u64, f64);
impl Rng {
    fn new(seed: u64) -> Rng {
        Rng(seed ^ 0x9E37_79B9_7F4A_7C15, 1.0)
    }
    /// True with probability `bad`.
    fn bad(&mut self) -> bool {
        let p = self.1;
        self.chance(p)
    }
    /// Half the inputs mostly well-formed, half anything goes.
    fn pick_mode(&mut self) {
        self.1 = if self.chance(0.5) { 0.01 } else { 1.0 };
    }
    fn u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// 0..n (n > 0)
    fn below(&mut self, n: usize) -> usize {
        (self.u64() % n.max(1) as u64) as usize
    }
    fn chance(&mut self, p: f64) -> bool {
        self.unit() < p
    }
    fn unit(&mut self) -> f64 {
        (self.u64() >> 11) as f64 / (1u64 << 53) as f64
    }
    fn range(&mut self, a: f32, b: f32) -> f32 {
        a + (b - a) * self.unit() as f32
    }
    fn pick<'a, T>(&mut self, xs: &'a [T]) -> &'a T {
        &xs[self.below(xs.len())]
    }
    /// Any of `xs` when [`Rng::bad`], else one of its first `good`.
    fn pick_good<'a, T>(&mut self, xs: &'a [T], good: usize) -> &'a T {
        let n = if self.bad() { xs.len() } else { good.min(xs.len()) };
        &xs[self.below(n)]
    }
    fn vec3(&mut self, r: f32) -> Vec3 {
        Vec3::new(self.range(-r, r), self.range(-r, r), self.range(-r, r))
    }
}

fn cases() -> usize {
    std::env::var("UMBRAGE_FUZZ_CASES").ok().and_then(|s| s.trim().parse().ok()).unwrap_or(1000)
}

fn base_seed() -> u64 {
    std::env::var("UMBRAGE_FUZZ_SEED").ok().and_then(|s| s.trim().parse().ok()).unwrap_or(0x5EED_0013)
}

thread_local! {
    static LAST_PANIC: RefCell<String> = const { RefCell::new(String::new()) };
}

/// A panic hook that records the panic's location and message for the fuzz loop (which catches
/// it) instead of printing it: one line per distinct panic is reported at the end.
fn quiet_panics() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        std::panic::set_hook(Box::new(|info| {
            let msg = if let Some(s) = info.payload().downcast_ref::<&str>() {
                s.to_string()
            } else if let Some(s) = info.payload().downcast_ref::<String>() {
                s.clone()
            } else {
                "<non-string panic>".to_string()
            };
            let loc = info.location().map(|l| format!("{}:{}", l.file(), l.line())).unwrap_or_default();
            LAST_PANIC.with(|p| *p.borrow_mut() = format!("{loc}: {msg}"));
        }));
    });
}

/// Runs `n` cases of a generator: `make` builds the input from a seeded RNG, `check` runs it
/// (panicking on a broken invariant). Distinct panics (by location) are collected with the
/// first input that hit them; the test fails at the end when there is any.
fn fuzz<T: std::fmt::Debug>(name: &str, n: usize, salt: u64, make: impl Fn(&mut Rng) -> T, check: impl Fn(&T)) {
    quiet_panics();
    let t0 = Instant::now();
    let mut found: HashMap<String, (u64, String, usize)> = HashMap::new();
    for i in 0..n {
        let seed = base_seed().wrapping_mul(0x1000_0000_01B3).wrapping_add(salt << 40).wrapping_add(i as u64);
        let mut rng = Rng::new(seed);
        let input = make(&mut rng);
        if catch_unwind(AssertUnwindSafe(|| check(&input))).is_err() {
            let msg = LAST_PANIC.with(|p| p.borrow().clone());
            let loc = msg.split(": ").next().unwrap_or("").to_string();
            let e = found.entry(loc).or_insert_with(|| (seed, format!("{msg}\n  input: {input:?}"), 0));
            e.2 += 1;
        }
    }
    let dt = t0.elapsed().as_secs_f64();
    println!("fuzz {name}: {n} cases in {dt:.2} s ({:.0} cases/s), {} distinct panics", n as f64 / dt.max(1e-9), found.len());
    if !found.is_empty() {
        let mut report = String::new();
        for (loc, (seed, text, count)) in &found {
            let _ = writeln!(report, "[{name}] {count} cases panic at {loc} (first seed {seed}):\n  {text}");
        }
        println!("{report}");
        panic!("fuzz {name}: {} distinct panics\n{report}", found.len());
    }
}

// ---------------------------------------------------------------------------------------------
// OBJ text

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

fn obj_text(rng: &mut Rng) -> String {
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
fn mutate_bytes(rng: &mut Rng, s: &mut String) {
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
fn check_obj(text: &String) {
    if let Ok(m) = load_obj_str(text, "fuzz.obj") {
        OBJ_OK.fetch_add(1, Ordering::Relaxed);
        m.validate("fuzz.obj").expect("load_obj_str returned an invalid mesh");
        let _ = Topology::build(&m);
        let _ = Caster::new("fuzz.obj", &m, Mat4::IDENTITY);
    }
}

fn tmp_dir() -> PathBuf {
    let d = std::env::temp_dir().join(format!("umbrage-fuzz-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

#[test]
fn fuzz_obj() {
    fuzz("obj", cases(), 1, obj_text, check_obj);
    println!("fuzz obj: {} of {} loaded (the rest got an error)", OBJ_OK.load(Ordering::Relaxed), cases());
    // raw bytes (not UTF-8) through the file loader, a few per run
    let dir = tmp_dir();
    let path = dir.join("fuzz.obj");
    let n = (cases() / 20).max(10);
    fuzz(
        "obj-bytes",
        n,
        2,
        |rng| {
            let mut b = obj_text(rng).into_bytes();
            for _ in 0..(1 + rng.below(6)) {
                let i = rng.below(b.len() + 1);
                b.insert(i, rng.u64() as u8);
            }
            b
        },
        |b| {
            std::fs::write(&path, b).unwrap();
            if let Ok(m) = umbrage::scene::load_obj(&path) {
                m.validate("fuzz.obj").unwrap();
            }
        },
    );
    let _ = std::fs::remove_dir_all(dir);
}

// ---------------------------------------------------------------------------------------------
// scene TOML

fn data_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("scenes/data")
}

fn toml_num(rng: &mut Rng) -> String {
    if !rng.bad() {
        return format!("{:.3}", rng.range(0.05, 3.0));
    }
    match rng.below(20) {
        0 => "nan".into(),
        1 => "inf".into(),
        2 => "-inf".into(),
        3 => "1e39".into(),
        4 => "0".into(),
        5 => "-1".into(),
        6 => "0.0".into(),
        7 => "1e-40".into(),
        8 => format!("{}", rng.u64() as i64),
        9 => "\"1\"".into(),
        10 => "true".into(),
        11 => "[]".into(),
        12 => format!("{:.4}", rng.range(-1e4, 1e4)),
        _ => format!("{:.3}", rng.range(-3.0, 3.0)),
    }
}

fn toml_int(rng: &mut Rng) -> String {
    if !rng.bad() {
        return format!("{}", 3 + rng.below(24));
    }
    match rng.below(10) {
        0 => rng.pick(&["0", "-1", "1", "2", "3", "4097", "1001", "100001", "10001", "1025"]).to_string(),
        1 => format!("{}", rng.u64() as i64),
        2 => "2.5".into(),
        3 => toml_num(rng),
        _ => format!("{}", 3 + rng.below(24)),
    }
}

fn toml_vec(rng: &mut Rng, k: usize) -> String {
    let k = if rng.bad() && rng.chance(0.1) { rng.below(5) } else { k };
    if rng.bad() && rng.chance(0.05) {
        return toml_num(rng);
    }
    let xs: Vec<String> = (0..k).map(|_| if rng.chance(0.9) { format!("{:.3}", rng.range(-6.0, 6.0)) } else { toml_num(rng) }).collect();
    format!("[{}]", xs.join(", "))
}

fn v3(rng: &mut Rng, lo: f32, hi: f32) -> String {
    format!("[{:.3}, {:.3}, {:.3}]", rng.range(lo, hi), rng.range(lo, hi), rng.range(lo, hi))
}

/// A well-formed scene (every key valid for its table), with at most one bad value: gets past
/// the parser to the shape builders, the casters and the planner.
fn scene_text_valid(rng: &mut Rng) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "[camera]\neye = {}\ntarget = {}", v3(rng, -8.0, 8.0), v3(rng, -1.0, 1.0));
    if rng.chance(0.3) {
        let _ = writeln!(s, "fov_y_deg = {:.2}\nnear = {:.3}", rng.range(1.0, 179.0), rng.range(0.001, 1.0));
    }
    for _ in 0..(1 + rng.below(3)) {
        match rng.below(3) {
            0 => {
                let _ = writeln!(s, "[[light]]\nkind = \"point\"\nposition = {}", v3(rng, -5.0, 5.0));
            }
            1 => {
                let _ = writeln!(
                    s,
                    "[[light]]\nkind = \"spot\"\nposition = {}\ndirection = {}\ncone_deg = {:.1}",
                    v3(rng, -5.0, 5.0),
                    v3(rng, -1.0, 1.0),
                    rng.range(1.0, 179.0)
                );
            }
            _ => {
                let _ = writeln!(s, "[[light]]\nkind = \"directional\"\ndirection = {}", v3(rng, -1.0, 1.0));
            }
        }
        if rng.chance(0.3) {
            let _ =
                writeln!(s, "radius = {:.2}\nintensity = {:.2}\ncolor = {}", rng.range(0.1, 20.0), rng.range(0.0, 3.0), v3(rng, 0.0, 1.0));
        }
    }
    for _ in 0..rng.below(4) {
        let _ = writeln!(s, "[[mesh]]");
        if rng.chance(0.15) {
            let f = rng.pick(&["open_box.obj", "inside_out_cube.obj", "shared_wall_boxes.obj", "two_sided_card.obj", "zero_area_cube.obj"]);
            let _ = writeln!(s, "obj = \"{f}\"");
        } else {
            let small = |rng: &mut Rng| 3 + rng.below(14);
            let line = match rng.below(9) {
                0 => format!("shape = \"plane\"\nsize = [{:.2}, {:.2}]", rng.range(0.1, 5.0), rng.range(0.1, 5.0)),
                1 => format!("shape = \"box\"\nsize = {}", v3(rng, 0.01, 3.0)),
                2 => format!(
                    "shape = \"sphere\"\nradius = {:.2}\nsegments = {}\nrings = {}",
                    rng.range(0.01, 2.0),
                    small(rng),
                    small(rng) - 1
                ),
                3 => format!(
                    "shape = \"torus\"\nmajor_radius = {:.2}\nminor_radius = {:.2}\nsegments = {}\nsides = {}",
                    rng.range(0.5, 2.0),
                    rng.range(0.01, 0.6),
                    small(rng),
                    small(rng)
                ),
                4 => format!(
                    "shape = \"cylinder\"\nradius = {:.2}\nheight = {:.2}\nsegments = {}",
                    rng.range(0.01, 2.0),
                    rng.range(0.01, 3.0),
                    small(rng)
                ),
                5 => format!("shape = \"stairs\"\nsteps = {}\nstep = {}", 1 + rng.below(12), v3(rng, 0.01, 1.0)),
                6 => format!(
                    "shape = \"cube_grid\"\ncount = [{}, {}]\nsize = {:.2}\nspacing = {:.2}",
                    1 + rng.below(5),
                    1 + rng.below(5),
                    rng.range(0.05, 1.0),
                    rng.range(0.05, 1.5)
                ),
                7 => format!(
                    "shape = \"box_stack\"\ncount = {}\nsize = {}\noffset = {}",
                    1 + rng.below(12),
                    v3(rng, 0.01, 1.0),
                    v3(rng, -0.1, 0.1)
                ),
                _ => format!(
                    "shape = \"bumpy_slab\"\nsize = [2.0, 0.05, 2.0]\ndivisions = {}\nbump = {:e}",
                    1 + rng.below(16),
                    rng.range(0.0, 0.04)
                ),
            };
            let _ = writeln!(s, "{line}");
        }
        if rng.chance(0.5) {
            let _ = writeln!(s, "translate = {}\nrotate_deg = {}", v3(rng, -3.0, 3.0), v3(rng, -180.0, 180.0));
        }
        if rng.chance(0.3) {
            let sc = match rng.below(3) {
                0 => format!("{:.3}", rng.range(0.01, 3.0)),
                1 => "[-1, 1, 1]".to_string(),
                _ => v3(rng, 0.1, 2.0),
            };
            let _ = writeln!(s, "scale = {sc}");
        }
        if rng.chance(0.2) {
            let _ = writeln!(s, "opacity = {:.2}\ncolor = {}", rng.range(0.0, 1.0), v3(rng, 0.0, 1.0));
        }
        if rng.chance(0.1) {
            let _ = writeln!(s, "casts_shadow = false");
        }
    }
    if rng.chance(0.2) {
        // one bad value somewhere
        let lines: Vec<&str> = s.lines().collect();
        let i = rng.below(lines.len());
        let mut out: Vec<String> = lines.iter().map(|l| l.to_string()).collect();
        if let Some((k, _)) = lines[i].split_once(" = ") {
            out[i] = format!("{k} = {}", toml_num(rng));
        }
        s = out.join("\n");
    }
    s
}

fn scene_text(rng: &mut Rng) -> String {
    rng.pick_mode();
    if !rng.bad() {
        rng.1 = 1.0; // (the one bad value may be anything)
        return scene_text_valid(rng);
    }
    let mut s = String::new();
    let kv = |s: &mut String, key: &str, val: String| {
        let _ = writeln!(s, "{key} = {val}");
    };
    if rng.chance(0.3) {
        kv(&mut s, "name", rng.pick(&["\"fuzz\"", "\"\"", "1", "\"a/b\""]).to_string());
    }
    if rng.chance(0.3) {
        let v = toml_vec(rng, 3);
        kv(&mut s, "ambient", v);
    }
    if rng.bad() && rng.chance(0.05) {
        let _ = writeln!(s, "{} = 1", rng.pick(&["unknown", "lights", "meshes", "camera"]));
    }
    if rng.chance(0.95) {
        let _ = writeln!(s, "[camera]");
        let eye = toml_vec(rng, 3);
        kv(&mut s, "eye", eye);
        let target = if rng.chance(0.05) { "[0.0, 0.0, 0.0]".to_string() } else { toml_vec(rng, 3) };
        kv(&mut s, "target", target);
        if rng.chance(0.4) {
            let up = if rng.chance(0.2) { rng.pick(&["[0, 0, 0]", "[1, 0, 0]", "[0, 1, 0]"]).to_string() } else { toml_vec(rng, 3) };
            kv(&mut s, "up", up);
        }
        if rng.chance(0.4) {
            let f = if rng.chance(0.5) { rng.pick(&["0", "180", "179.9", "0.001", "-10", "360"]).to_string() } else { toml_num(rng) };
            kv(&mut s, "fov_y_deg", f);
        }
        if rng.chance(0.3) {
            let n = toml_num(rng);
            kv(&mut s, "near", n);
        }
        if rng.bad() && rng.chance(0.03) {
            let _ = writeln!(s, "far = 10");
        }
    }
    for _ in 0..rng.below(4) {
        let _ = writeln!(s, "[[light]]");
        let kind = rng.pick_good(&["\"point\"", "\"spot\"", "\"directional\"", "\"point\"", "\"sun\"", "1", "\"\""], 4).to_string();
        kv(&mut s, "kind", kind);
        for (key, p) in [("position", 0.8), ("direction", 0.5), ("color", 0.3)] {
            if rng.chance(p) {
                let v = if key == "direction" && rng.chance(0.1) { "[0, 0, 0]".to_string() } else { toml_vec(rng, 3) };
                kv(&mut s, key, v);
            }
        }
        for (key, p) in [("intensity", 0.3), ("radius", 0.3), ("cone_deg", 0.4)] {
            if rng.chance(p) {
                let v = if key == "cone_deg" && rng.chance(0.5) {
                    rng.pick(&["0", "180", "360", "90", "179", "-5"]).to_string()
                } else {
                    toml_num(rng)
                };
                kv(&mut s, key, v);
            }
        }
    }
    for _ in 0..rng.below(4) {
        let _ = writeln!(s, "[[mesh]]");
        if rng.chance(0.2) {
            let obj = rng
                .pick_good(
                    &[
                        "\"open_box.obj\"",
                        "\"inside_out_cube.obj\"",
                        "\"shared_wall_boxes.obj\"",
                        "\"two_sided_card.obj\"",
                        "\"zero_area_cube.obj\"",
                        "\"missing.obj\"",
                        "\"\"",
                        "\"..\"",
                        "\"/\"",
                        "\"open_box.obj\\u0000\"",
                    ],
                    5,
                )
                .to_string();
            kv(&mut s, "obj", obj);
        }
        if rng.chance(0.9) {
            let shape = rng
                .pick_good(
                    &[
                        "\"plane\"",
                        "\"box\"",
                        "\"sphere\"",
                        "\"torus\"",
                        "\"cylinder\"",
                        "\"stairs\"",
                        "\"cube_grid\"",
                        "\"box_stack\"",
                        "\"bumpy_slab\"",
                        "\"cone\"",
                        "3",
                    ],
                    9,
                )
                .to_string();
            kv(&mut s, "shape", shape);
        }
        // shape parameters, any of them on any shape
        if rng.chance(0.4) {
            let v = match rng.below(4) {
                0 => toml_num(rng),
                1 => toml_vec(rng, 2),
                _ => toml_vec(rng, 3),
            };
            kv(&mut s, "size", v);
        }
        for key in ["radius", "major_radius", "minor_radius", "height", "spacing", "bump"] {
            if rng.chance(0.15) {
                let v = toml_num(rng);
                kv(&mut s, key, v);
            }
        }
        for key in ["segments", "rings", "sides", "steps", "divisions"] {
            if rng.chance(0.15) {
                let v = toml_int(rng);
                kv(&mut s, key, v);
            }
        }
        if rng.chance(0.15) {
            let v = match rng.below(3) {
                0 => format!("{}", 1 + rng.below(30)),
                1 => format!("[{}, {}]", 1 + rng.below(8), rng.below(9)),
                _ => toml_num(rng),
            };
            kv(&mut s, "count", v);
        }
        for key in ["step", "offset", "translate", "rotate_deg", "color"] {
            if rng.chance(0.2) {
                let v = toml_vec(rng, 3);
                kv(&mut s, key, v);
            }
        }
        if rng.chance(0.3) {
            let v = match rng.below(4) {
                0 => toml_vec(rng, 3),
                1 => rng.pick(&["0", "-1", "[1, -1, 1]", "[0, 1, 1]", "1e-20", "1e20"]).to_string(),
                _ => toml_num(rng),
            };
            kv(&mut s, "scale", v);
        }
        if rng.chance(0.2) {
            let v = if rng.chance(0.5) { format!("{:.2}", rng.range(-0.5, 1.5)) } else { toml_num(rng) };
            kv(&mut s, "opacity", v);
        }
        if rng.chance(0.2) {
            let v = rng.pick(&["true", "false", "1", "\"yes\""]).to_string();
            kv(&mut s, "casts_shadow", v);
        }
        if rng.chance(0.1) {
            let v = rng.pick(&["\"m\"", "\"\"", "\"a\\nb\""]).to_string();
            kv(&mut s, "name", v);
        }
        if rng.bad() && rng.chance(0.03) {
            let _ = writeln!(s, "colour = [1, 1, 1]");
        }
    }
    // missing keys and tables: drop a few lines
    if rng.bad() && rng.chance(0.3) {
        let keep: Vec<&str> = s.lines().filter(|_| !rng.chance(0.08)).collect();
        s = keep.join("\n");
    }
    if rng.bad() && rng.chance(0.25) {
        mutate_bytes(rng, &mut s);
    }
    s
}

/// Plans every caster of a loaded scene for every light and checks the volumes.
fn plan_scene(scene: &umbrage::scene::Scene, method: Method) {
    let casters: Vec<Caster> = scene.meshes.iter().filter(|m| m.casts_shadow).filter_map(|m| m.caster().ok()).collect();
    for light in &scene.lights {
        let vp = scene.camera.proj_infinite(1.5) * scene.camera.view();
        let input = PlanInput { camera: &scene.camera, width: 96, height: 64, view_proj: vp, light, method };
        let plan = plan_light_with(&input, &casters, &PlanOptions::default());
        check_plan(&casters, &plan.casters, light.kind == LightKind::Directional);
    }
}

fn check_scene(text: &(String, bool, usize)) {
    let (text, plan, method) = text;
    if let Ok(scene) = umbrage::scene::load_str(text, "fuzz.toml", &data_dir()) {
        SCENE_OK.fetch_add(1, Ordering::Relaxed);
        if *plan {
            plan_scene(&scene, Method::ALL[*method]);
        }
    }
}

#[test]
fn fuzz_scene() {
    fuzz("scene", cases(), 3, |rng| (scene_text(rng), rng.chance(0.25), rng.below(5)), check_scene);
    println!("fuzz scene: {} of {} loaded (the rest got an error)", SCENE_OK.load(Ordering::Relaxed), cases());
}

// ---------------------------------------------------------------------------------------------
// mesh topology

/// Named base meshes for mutation.
fn base_mesh(rng: &mut Rng) -> Mesh {
    match rng.below(9) {
        0 => shapes::cuboid(Vec3::new(rng.range(0.1, 2.0), rng.range(0.1, 2.0), rng.range(0.1, 2.0))),
        1 => shapes::sphere(rng.range(0.1, 1.5), 3 + rng.below(8) as u32, 2 + rng.below(6) as u32),
        2 => shapes::torus(0.8, rng.range(0.05, 0.5), 3 + rng.below(6) as u32, 3 + rng.below(5) as u32),
        3 => shapes::cylinder(0.5, rng.range(0.1, 2.0), 3 + rng.below(8) as u32),
        4 => shapes::plane(glam::Vec2::new(rng.range(0.1, 3.0), rng.range(0.1, 3.0))),
        5 => shapes::stairs(1 + rng.below(4) as u32, Vec3::new(1.0, 0.2, 0.3)),
        6 => shapes::cube_grid(1 + rng.below(3) as u32, 1 + rng.below(3) as u32, 0.4, rng.pick(&[1.0, 0.4, 0.2]).to_owned()),
        7 => tetra(),
        _ => soup(rng),
    }
}

fn tetra() -> Mesh {
    Mesh::new(
        vec![Vec3::new(0.0, 0.0, 0.0), Vec3::new(1.0, 0.0, 0.0), Vec3::new(0.0, 1.0, 0.0), Vec3::new(0.0, 0.0, 1.0)],
        vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
    )
}

/// A random triangle soup over a small vertex pool (so indices collide: duplicates, fins,
/// degenerate triangles), with coincident, collinear and coplanar positions.
fn soup(rng: &mut Rng) -> Mesh {
    let nv = 3 + rng.below(10);
    let mut pos: Vec<Vec3> = Vec::with_capacity(nv);
    for i in 0..nv {
        let p = match rng.below(8) {
            0 if i > 0 => pos[rng.below(i)],                                               // coincident
            1 if i > 1 => pos[rng.below(i)].lerp(pos[rng.below(i)], rng.range(-1.0, 2.0)), // collinear
            2 => Vec3::new(rng.range(-1.0, 1.0), 0.0, rng.range(-1.0, 1.0)),               // coplanar y=0
            3 if i > 0 => pos[rng.below(i)] + rng.vec3(1e-6),                              // nearly coincident
            4 => Vec3::new(rng.below(3) as f32, rng.below(3) as f32, rng.below(3) as f32), // lattice
            _ => rng.vec3(1.0),
        };
        pos.push(p);
    }
    let nt = 1 + rng.below(16);
    let tris = (0..nt).map(|_| [rng.below(nv) as u32, rng.below(nv) as u32, rng.below(nv) as u32]).collect();
    Mesh::new(pos, tris)
}

/// Mutations that break closedness or orientation in the ways real assets do.
fn mutate_mesh(rng: &mut Rng, m: &mut Mesh) {
    for _ in 0..rng.below(5) {
        let nt = m.triangles.len();
        if nt == 0 {
            break;
        }
        let t = rng.below(nt);
        match rng.below(10) {
            0 => m.triangles.push(m.triangles[t]), // duplicate
            1 => {
                let [a, b, c] = m.triangles[t];
                m.triangles.push([a, c, b]); // back-to-back
            }
            2 => m.triangles[t].swap(1, 2), // flip (inside-out / inconsistent)
            3 => {
                m.triangles.remove(t); // hole
            }
            4 => {
                // fin: a new triangle on an existing edge (non-manifold)
                let [a, b, _] = m.triangles[t];
                let p = m.positions[a as usize] + rng.vec3(1.0);
                m.positions.push(p);
                m.triangles.push([a, b, m.positions.len() as u32 - 1]);
            }
            5 => {
                // collapse a vertex onto another (degenerate triangles, pinched vertices)
                let [a, b, _] = m.triangles[t];
                m.positions[b as usize] = m.positions[a as usize];
            }
            6 => {
                // split a vertex: same position, new index (open seam until welded)
                let k = rng.below(3);
                let v = m.triangles[t][k] as usize;
                m.positions.push(m.positions[v]);
                m.triangles[t][k] = m.positions.len() as u32 - 1;
            }
            7 => {
                let k = rng.below(3);
                m.triangles[t][k] = m.triangles[t][(k + 1) % 3]; // repeated index
            }
            8 => {
                // jitter one vertex a little (near-coplanar, near-degenerate)
                let v = rng.below(m.positions.len());
                m.positions[v] += rng.vec3(1e-5);
            }
            _ => {
                // all triangles flipped: inside-out
                for t in &mut m.triangles {
                    t.swap(1, 2);
                }
            }
        }
    }
    if rng.chance(0.1) {
        // a second copy of the whole mesh, shifted or coincident: several parts / overlaps
        let off = if rng.chance(0.5) { Vec3::ZERO } else { rng.vec3(2.0) };
        let n = m.positions.len() as u32;
        let extra: Vec<Vec3> = m.positions.iter().map(|&p| p + off).collect();
        m.positions.extend(extra);
        let tris: Vec<[u32; 3]> = m.triangles.iter().map(|t| t.map(|i| i + n)).collect();
        m.triangles.extend(tris);
    }
}

fn random_mesh(rng: &mut Rng) -> Mesh {
    let mut m = base_mesh(rng);
    if rng.chance(0.8) {
        mutate_mesh(rng, &mut m);
    }
    m
}

/// Invalid meshes too (for `Caster::new`, which must refuse them with an error).
fn random_mesh_maybe_invalid(rng: &mut Rng) -> Mesh {
    let mut m = random_mesh(rng);
    match rng.below(30) {
        0 => m.triangles.clear(),
        1 if !m.positions.is_empty() => {
            let v = rng.below(m.positions.len());
            m.positions[v].x = *rng.pick(&[f32::NAN, f32::INFINITY, f32::NEG_INFINITY]);
        }
        2 if !m.triangles.is_empty() => {
            let t = rng.below(m.triangles.len());
            m.triangles[t][rng.below(3)] = *rng.pick(&[m.positions.len() as u32, u32::MAX, u32::MAX - 1]);
        }
        3 => m.positions.clear(),
        4 => {
            // extreme but finite coordinates
            let s = *rng.pick(&[1e30f32, 1e-30, f32::MAX, f32::MIN_POSITIVE]);
            for p in &mut m.positions {
                *p *= s;
            }
        }
        _ => {}
    }
    m
}

#[derive(Debug)]
struct TopoCase {
    mesh: Mesh,
    limit: usize,
    tolerance: f32,
}

fn check_topology(c: &TopoCase) {
    let m = &c.mesh;
    let valid = m.validate("fuzz").is_ok();
    if valid {
        for weld in [Weld::Exact, Weld::Tolerance(c.tolerance)] {
            let t = Topology::build_with(m, weld);
            // every non-degenerate corner of every welded triangle is one use of one edge
            let uses: u32 = t.edges.iter().map(|e| e.use_count).sum();
            assert_eq!(uses as usize, t.uses.len());
            assert!(t.manifold_edges.len() <= t.edges.len());
            let _ = t.is_closed_manifold();
            let _ = t.describe_problem();
        }
    }
    if let Ok(caster) = Caster::with_chunk_limit("fuzz", m, Mat4::IDENTITY, c.limit) {
        assert!(valid, "an invalid mesh was accepted");
        for ch in &caster.chunks {
            assert!(ch.n() <= c.limit.clamp(4, 32768));
            for lt in &ch.local_tris {
                assert!(lt.iter().all(|&i| (i as usize) < ch.n() - 1));
            }
        }
        let covered: usize = caster.parts.iter().map(|p| p.triangles.len()).sum();
        assert_eq!(covered, caster.triangle_count);
    }
    let _ = Caster::new("fuzz", m, Mat4::IDENTITY);
}

#[test]
fn fuzz_topology() {
    fuzz(
        "topology",
        cases(),
        4,
        |rng| TopoCase {
            mesh: random_mesh_maybe_invalid(rng),
            limit: *rng.pick(&[0, 3, 4, 5, 6, 7, 9, 16, 32768, 40000]),
            tolerance: *rng.pick(&[0.0, 1e-7, 1e-4, 0.1, 10.0]),
        },
        check_topology,
    );
}

// ---------------------------------------------------------------------------------------------
// planner

#[derive(Debug)]
struct PlanCase {
    meshes: Vec<(Mesh, Mat4, usize, bool)>,
    light: Light,
    camera: Camera,
    method: Method,
    opts: PlanOptions,
    aspect: f32,
}

fn random_transform(rng: &mut Rng) -> Mat4 {
    let r = Quat::from_euler(EulerRot::XYZ, rng.range(0.0, 6.3), rng.range(0.0, 6.3), rng.range(0.0, 6.3));
    let s = match rng.below(6) {
        0 => Vec3::new(-1.0, 1.0, 1.0),
        1 => Vec3::splat(rng.range(0.01, 3.0)),
        2 => Vec3::new(rng.range(0.2, 2.0), rng.range(0.2, 2.0), -rng.range(0.2, 2.0)),
        _ => Vec3::ONE,
    };
    match rng.below(4) {
        0 => Mat4::IDENTITY,
        1 => Mat4::from_translation(rng.vec3(2.0)),
        _ => Mat4::from_scale_rotation_translation(s, r, rng.vec3(2.0)),
    }
}

/// A world-space point on, at or near the casters: vertices, edge points, face-plane points.
fn special_point(rng: &mut Rng, meshes: &[(Mesh, Mat4, usize, bool)]) -> Vec3 {
    let (m, xf, _, _) = &meshes[rng.below(meshes.len())];
    let w = |i: u32| xf.transform_point3(m.positions[i as usize]);
    let t = m.triangles[rng.below(m.triangles.len())];
    let (a, b, c) = (w(t[0]), w(t[1]), w(t[2]));
    let p = match rng.below(6) {
        0 => a,                                                                   // at a vertex
        1 => a.lerp(b, rng.range(0.0, 1.0)),                                      // on an edge
        2 => a.lerp(b, rng.range(-3.0, 4.0)),                                     // on an edge's line
        3 => a + (b - a) * rng.range(-2.0, 2.0) + (c - a) * rng.range(-2.0, 2.0), // in the face plane
        4 => xf.transform_point3(m.bounds().center()),
        _ => (a + b + c) / 3.0,
    };
    match rng.below(4) {
        0 => p + rng.vec3(1e-5),
        1 => p + rng.vec3(1e-2),
        _ => p,
    }
}

fn plan_case(rng: &mut Rng) -> PlanCase {
    let n = 1 + rng.below(3);
    let meshes: Vec<(Mesh, Mat4, usize, bool)> = (0..n)
        .map(|_| {
            let mut m = random_mesh(rng);
            if m.validate("x").is_err() {
                m = tetra();
            }
            (m, random_transform(rng), *rng.pick(&[32768, 4, 5, 7, 16]), rng.chance(0.15))
        })
        .collect();
    let kind = *rng.pick(&[LightKind::Point, LightKind::Point, LightKind::Spot, LightKind::Directional]);
    let position = match rng.below(3) {
        0 => rng.vec3(6.0),
        _ => special_point(rng, &meshes),
    };
    let direction = match rng.below(4) {
        0 => {
            // parallel to a face or along an edge
            let (m, xf, _, _) = &meshes[rng.below(meshes.len())];
            let t = m.triangles[rng.below(m.triangles.len())];
            let w = |i: u32| xf.transform_point3(m.positions[i as usize]);
            let d = if rng.chance(0.5) { w(t[1]) - w(t[0]) } else { (w(t[1]) - w(t[0])).lerp(w(t[2]) - w(t[0]), rng.range(0.0, 1.0)) };
            d.try_normalize().unwrap_or(Vec3::NEG_Y)
        }
        1 => *rng.pick(&[Vec3::NEG_Y, Vec3::X, Vec3::NEG_Z, Vec3::new(1.0, -1.0, 0.0).normalize()]),
        _ => rng.vec3(1.0).try_normalize().unwrap_or(Vec3::NEG_Y),
    };
    let light = Light {
        kind,
        position,
        direction,
        color: Vec3::ONE,
        intensity: 1.0,
        radius: if rng.chance(0.2) { Some(rng.range(0.01, 10.0)) } else { None },
        cone_deg: *rng.pick(&[10.0, 45.0, 90.0, 179.0, 180.0, 270.0, 0.0]),
        area: None,
    };
    let eye = match rng.below(5) {
        0 => special_point(rng, &meshes),
        1 => position,
        _ => rng.vec3(8.0),
    };
    let target = if rng.chance(0.7) { special_point(rng, &meshes) } else { rng.vec3(3.0) };
    let camera = Camera {
        eye,
        target,
        up: *rng.pick(&[Vec3::Y, Vec3::Z, Vec3::X]),
        fov_y_deg: *rng.pick(&[60.0, 10.0, 120.0, 170.0, 1.0]),
        near: *rng.pick(&[0.1, 0.01, 1.0, 1e-4]),
    };
    PlanCase {
        meshes,
        light,
        camera,
        method: *rng.pick(&Method::ALL),
        opts: PlanOptions { edge_quads: rng.chance(0.05), case_per_part: rng.chance(0.5), ..PlanOptions::default() },
        aspect: *rng.pick(&[1.0, 1.5, 0.5]),
    }
}

/// What the planner checks looked at: parts checked closed, multiplicity parts whose side
/// counts were checked, parts that were planned (not culled).
static CLOSED_PARTS: AtomicUsize = AtomicUsize::new(0);
static MULTIPLICITY_PARTS: AtomicUsize = AtomicUsize::new(0);
static PLANNED_PARTS: AtomicUsize = AtomicUsize::new(0);
/// Inputs the loaders accepted (the rest got an error).
static OBJ_OK: AtomicUsize = AtomicUsize::new(0);
static SCENE_OK: AtomicUsize = AtomicUsize::new(0);

/// A vertex of the emitted volume: (welded vertex or apex, at infinity).
type VKey = (u32, bool);

fn vkey(caster: &Caster, chunk: usize, i: u16, directional: bool) -> VKey {
    let ch = &caster.chunks[chunk];
    let n = ch.n();
    let (local, inf) = if (i as usize) < n { (i as usize, false) } else { (i as usize - n, true) };
    assert!(local < n, "index {i} out of the dual-length buffer of chunk {chunk} (n = {n})");
    if inf && directional {
        return (u32::MAX - 1, true);
    }
    (ch.global_ids[local], inf)
}

/// Every check on the plans of `casters` for one light.
fn check_plan(casters: &[Caster], plans: &[CasterPlan], directional: bool) {
    assert_eq!(plans.len(), casters.len());
    let mut bits = Vec::new();
    for (caster, cp) in casters.iter().zip(plans) {
        if cp.path == VolumePath::EdgeQuad || cp.case == Case::Culled && cp.chunks.is_empty() {
            continue;
        }
        assert_eq!(cp.triangles(), cp.parts.iter().map(|p| p.sides + p.dark_cap + p.light_cap).sum::<usize>());
        let emitted: usize = cp.chunks.iter().map(|d| d.volume.len() + d.light_cap.len()).sum();
        assert_eq!(emitted, 3 * cp.triangles(), "index lists do not hold the counted triangles");
        let l_obj = Vec4::from_array(cp.light_object);
        caster.planes.facing_packed_auto(caster.mesh(), l_obj, caster.mirrored, &mut bits);
        for pp in &cp.parts {
            if pp.case == Case::Culled {
                continue;
            }
            PLANNED_PARTS.fetch_add(1, Ordering::Relaxed);
            let part = &caster.parts[pp.part];
            let tris: Vec<(usize, [u16; 3])> = cp
                .chunks
                .iter()
                .filter(|d| part.chunks.contains(&d.chunk))
                .flat_map(|d| d.volume.chunks(3).chain(d.light_cap.chunks(3)).map(move |t| (d.chunk, [t[0], t[1], t[2]])))
                .collect();
            assert_eq!(tris.len(), pp.sides + pp.dark_cap + pp.light_cap, "part {} triangle count", pp.part);
            if pp.case == Case::ZFailLightCap {
                CLOSED_PARTS.fetch_add(1, Ordering::Relaxed);
                // closed: every directed edge cancels
                let mut m: HashMap<(VKey, VKey), i32> = HashMap::new();
                for &(c, t) in &tris {
                    for k in 0..3 {
                        let (u, v) = (vkey(caster, c, t[k], directional), vkey(caster, c, t[(k + 1) % 3], directional));
                        if u == v {
                            continue;
                        }
                        if u < v {
                            *m.entry((u, v)).or_default() += 1;
                        } else {
                            *m.entry((v, u)).or_default() -= 1;
                        }
                    }
                }
                let open: Vec<_> = m.iter().filter(|(_, &c)| c != 0).collect();
                assert!(open.is_empty(), "part {} ({}) not closed: {} open edges, e.g. {:?}", pp.part, pp.path, open.len(), open.first());
            }
            if pp.path == VolumePath::Multiplicity {
                MULTIPLICITY_PARTS.fetch_add(1, Ordering::Relaxed);
                // per undirected edge: the signed side count is the multiplicity
                let topo = &caster.topology;
                let mut want: HashMap<(u32, u32), i32> = HashMap::new();
                let (mut nonzero, mut mmax) = (0usize, 0u32);
                for &e in &part.edges {
                    let edge = &topo.edges[e as usize];
                    let mult: i32 =
                        topo.edge_uses(e as usize).iter().map(|u| if u.forward == caster.planes.bit(&bits, u.tri) { 1 } else { -1 }).sum();
                    if mult != 0 {
                        nonzero += 1;
                        mmax = mmax.max(mult.unsigned_abs());
                    }
                    if edge.v[0] != edge.v[1] {
                        *want.entry((edge.v[0], edge.v[1])).or_default() += mult;
                    }
                }
                assert_eq!(pp.silhouette_edges, nonzero, "part {}: edges of non-zero multiplicity", pp.part);
                assert_eq!(pp.multiplicity_max, mmax, "part {}: largest multiplicity", pp.part);
                let mut got: HashMap<(u32, u32), i32> = HashMap::new();
                for &(c, t) in &tris {
                    let ks = t.map(|i| vkey(caster, c, i, false));
                    if ks.iter().filter(|k| !k.1).count() != 2 {
                        continue; // caps (all finite or all at infinity), or the infinite half of a side quad
                    }
                    for k in 0..3 {
                        let (u, v) = (ks[k], ks[(k + 1) % 3]);
                        if !u.1 && !v.1 && u.0 != v.0 {
                            // a side over a -> b is emitted as b -> a finite edge (see multiplicity.rs)
                            if u.0 > v.0 {
                                *got.entry((v.0, u.0)).or_default() += 1;
                            } else {
                                *got.entry((u.0, v.0)).or_default() -= 1;
                            }
                        }
                    }
                }
                want.retain(|_, m| *m != 0);
                got.retain(|_, m| *m != 0);
                assert_eq!(got, want, "part {}: signed side counts differ from the multiplicities", pp.part);
            }
        }
    }
}

fn check_planner(c: &PlanCase) {
    let mut casters = Vec::new();
    for (i, (m, xf, limit, transparent)) in c.meshes.iter().enumerate() {
        let Ok(mut caster) = Caster::with_chunk_limit(&format!("c{i}"), m, *xf, *limit) else { continue };
        if *transparent {
            caster = caster.into_transparent(Vec3::splat(0.5));
        }
        casters.push(caster);
    }
    let vp = c.camera.proj_infinite(c.aspect) * c.camera.view();
    let input = PlanInput { camera: &c.camera, width: 64, height: 48, view_proj: vp, light: &c.light, method: c.method };
    let plan = plan_light_with(&input, &casters, &c.opts);
    check_plan(&casters, &plan.casters, c.light.kind == LightKind::Directional);
    // z-fail with light caps everywhere: every part that is not culled must be closed
    if c.method != Method::ZFail {
        let input = PlanInput { method: Method::ZFail, ..input };
        let plan = plan_light_with(&input, &casters, &PlanOptions { case_per_part: c.opts.case_per_part, ..PlanOptions::default() });
        check_plan(&casters, &plan.casters, c.light.kind == LightKind::Directional);
    }
}

#[test]
fn fuzz_planner() {
    fuzz("planner", cases(), 5, plan_case, check_planner);
    let ld = |a: &AtomicUsize| a.load(Ordering::Relaxed);
    println!(
        "fuzz planner (and planned scenes): {} parts planned, {} checked closed, {} multiplicity parts' side counts checked",
        ld(&PLANNED_PARTS),
        ld(&CLOSED_PARTS),
        ld(&MULTIPLICITY_PARTS)
    );
}

// ---------------------------------------------------------------------------------------------
// regressions: fixed inputs of past findings

/// Found by `fuzz_topology` (seed 14988318902247170122): `Weld::Tolerance` with a tolerance
/// below ~1e-19 (0 is clamped to `f32::MIN_POSITIVE`) saturated the grid cell of any ordinary
/// coordinate to `i64::MAX`, and the neighbour lookup `c + 1` overflowed (debug builds:
/// "attempt to add with overflow" at src/geom/topology.rs:115). Fixed with wrapping neighbours.
#[test]
fn regression_weld_tiny_tolerance() {
    let m = Mesh::new(vec![Vec3::new(1.0, 0.0, 0.0), Vec3::new(0.0, 1.0, 0.0), Vec3::new(0.0, 0.0, 1.0)], vec![[0, 1, 2]]);
    for tol in [0.0, f32::MIN_POSITIVE, 1e-30] {
        let t = Topology::build_with(&m, Weld::Tolerance(tol));
        assert_eq!(t.mesh.positions.len(), 3);
        assert_eq!(t.edges.len(), 3);
    }
    // coincident points still weld at a tiny tolerance
    let m = Mesh::new(vec![Vec3::X, Vec3::Y, Vec3::Z, Vec3::X], vec![[0, 1, 2], [3, 2, 1]]);
    assert_eq!(Topology::build_with(&m, Weld::Tolerance(0.0)).mesh.positions.len(), 3);
}

/// Found by `fuzz_obj` (seed 14988315603712290533): a huge normal index made tobj 4.0.5
/// compute `vn * 3 + 2` with overflow (debug: "attempt to multiply with overflow" at
/// tobj-4.0.5/src/lib.rs:1096; release: with vn * 3 = 2^64 - 1 the bounds check wraps and
/// `normal[vn * 3]` is out of bounds). umbrage now rejects indices beyond the file's line count.
#[test]
fn regression_obj_huge_normal_index() {
    let found = "v 1.120 -0.862 -1.483\nv 1.751 0.461 0.730\nv -0.574 1.150 1.987\nv -1.114 -1.556 -0.443\n\
                 v 1.153 0.356 1.121\nmtllib off\nf 3/1/-2 4/1/-1 4/-1/1 4/1/3185830166813412074\nvn -inf 1.830 nan -1.356\n";
    // the release-build out-of-bounds variant: (2^64 - 1) / 3 + 1
    let oob = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nvn 0 1 0\nf 1//6148914691236517206 2//1 3//1\n";
    let neg = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//-6148914691236517206 2//1 3//1\n";
    let vt = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/9223372036854775807 2/1 3/1\n";
    // found by the 10M-case dev run (seeds 18691697674736, 18691697728204): relative normal /
    // texture indices reaching before the first one (tobj: `norm_sz + x` wraps to ~usize::MAX)
    let rel_vn = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3/1/-2\nvn 0 0 1\n";
    let rel_vt = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1 2/-2/1 3\nvt 0 0\nvt 1 1\n";
    for text in [found, oob, neg, vt, rel_vn, rel_vt] {
        let e = load_obj_str(text, "fuzz.obj").unwrap_err().to_string();
        assert!(e.contains("out of range"), "{e}");
    }
    // ordinary relative and absolute indices still load
    let ok = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nvt 0 0\nf 1//1 2//1 3//-1\nf -3 -2/-1 -1\n";
    assert_eq!(load_obj_str(ok, "ok.obj").unwrap().triangles.len(), 2);
}

/// The planner checks catch a broken volume: one triangle reversed opens a closed volume, and
/// one side reversed breaks the multiplicity count.
#[test]
fn checks_catch_broken_volumes() {
    quiet_panics();
    let cam = Camera { eye: Vec3::new(0.0, -3.0, 0.1), target: Vec3::ZERO, up: Vec3::Z, fov_y_deg: 60.0, near: 0.1 };
    let light = Light {
        kind: LightKind::Point,
        position: Vec3::new(0.3, 5.0, -0.2),
        direction: Vec3::NEG_Y,
        color: Vec3::ONE,
        intensity: 1.0,
        radius: None,
        cone_deg: 45.0,
        area: None,
    };
    let open_box = {
        let mut m = shapes::cuboid(Vec3::ONE);
        m.triangles.truncate(10);
        m
    };
    for (mesh, method) in [(shapes::cuboid(Vec3::ONE), Method::ZFail), (open_box.clone(), Method::ZFail), (open_box, Method::ZPass)] {
        let casters = vec![Caster::new("c", &mesh, Mat4::IDENTITY).unwrap()];
        let vp = cam.proj_infinite(1.0) * cam.view();
        let input = PlanInput { camera: &cam, width: 64, height: 64, view_proj: vp, light: &light, method };
        let plan = plan_light_with(&input, &casters, &PlanOptions::default());
        check_plan(&casters, &plan.casters, false);
        let mut broken = plan.casters.clone();
        let v = &mut broken[0].chunks[0].volume;
        assert!(v.len() >= 3, "{:?}", plan.casters[0]);
        v.swap(0, 1);
        assert!(catch_unwind(AssertUnwindSafe(|| check_plan(&casters, &broken, false))).is_err(), "{method:?} {}", casters[0].kind.path());
    }
}
