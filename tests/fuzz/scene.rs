//! Scene TOML: generators of well-formed and broken scene files (`fuzz_scene`), and the check
//! that loads a scene and plans its casters.

use crate::obj::mutate_bytes;
use crate::plan::check_plan;
use crate::{Rng, SCENE_OK};
use std::fmt::Write as _;
use std::path::PathBuf;
use std::sync::atomic::Ordering;
use umbrage::geom::LightKind;
use umbrage::shadow::{plan_light_with, Caster, Method, PlanInput, PlanOptions};

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

pub(crate) fn scene_text(rng: &mut Rng) -> String {
    rng.pick_mode();
    if !rng.bad() {
        rng.1 = 1.0; // (the one bad value may be anything)
        return scene_text_valid(rng);
    }
    let mut s = String::new();
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
        camera_text(rng, &mut s);
    }
    for _ in 0..rng.below(4) {
        light_text(rng, &mut s);
    }
    for _ in 0..rng.below(4) {
        mesh_text(rng, &mut s);
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

/// A `key = value` line.
fn kv(s: &mut String, key: &str, val: String) {
    let _ = writeln!(s, "{key} = {val}");
}

/// The `[camera]` table: eye and target, maybe up, fov_y_deg and near (and, bad, `far`).
fn camera_text(rng: &mut Rng, s: &mut String) {
    let _ = writeln!(s, "[camera]");
    let eye = toml_vec(rng, 3);
    kv(s, "eye", eye);
    let target = if rng.chance(0.05) { "[0.0, 0.0, 0.0]".to_string() } else { toml_vec(rng, 3) };
    kv(s, "target", target);
    if rng.chance(0.4) {
        let up = if rng.chance(0.2) { rng.pick(&["[0, 0, 0]", "[1, 0, 0]", "[0, 1, 0]"]).to_string() } else { toml_vec(rng, 3) };
        kv(s, "up", up);
    }
    if rng.chance(0.4) {
        let f = if rng.chance(0.5) { rng.pick(&["0", "180", "179.9", "0.001", "-10", "360"]).to_string() } else { toml_num(rng) };
        kv(s, "fov_y_deg", f);
    }
    if rng.chance(0.3) {
        let n = toml_num(rng);
        kv(s, "near", n);
    }
    if rng.bad() && rng.chance(0.03) {
        let _ = writeln!(s, "far = 10");
    }
}

/// One `[[light]]` table: a kind (maybe a bad one), maybe position, direction, colour,
/// intensity, radius and cone_deg.
fn light_text(rng: &mut Rng, s: &mut String) {
    let _ = writeln!(s, "[[light]]");
    let kind = rng.pick_good(&["\"point\"", "\"spot\"", "\"directional\"", "\"point\"", "\"sun\"", "1", "\"\""], 4).to_string();
    kv(s, "kind", kind);
    for (key, p) in [("position", 0.8), ("direction", 0.5), ("color", 0.3)] {
        if rng.chance(p) {
            let v = if key == "direction" && rng.chance(0.1) { "[0, 0, 0]".to_string() } else { toml_vec(rng, 3) };
            kv(s, key, v);
        }
    }
    for (key, p) in [("intensity", 0.3), ("radius", 0.3), ("cone_deg", 0.4)] {
        if rng.chance(p) {
            let v = if key == "cone_deg" && rng.chance(0.5) {
                rng.pick(&["0", "180", "360", "90", "179", "-5"]).to_string()
            } else {
                toml_num(rng)
            };
            kv(s, key, v);
        }
    }
}

/// One `[[mesh]]` table: maybe an obj, a shape, any shape's parameters, the transform,
/// opacity, casts_shadow and name (and, bad, `colour`).
fn mesh_text(rng: &mut Rng, s: &mut String) {
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
        kv(s, "obj", obj);
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
        kv(s, "shape", shape);
    }
    // shape parameters, any of them on any shape
    if rng.chance(0.4) {
        let v = match rng.below(4) {
            0 => toml_num(rng),
            1 => toml_vec(rng, 2),
            _ => toml_vec(rng, 3),
        };
        kv(s, "size", v);
    }
    for key in ["radius", "major_radius", "minor_radius", "height", "spacing", "bump"] {
        if rng.chance(0.15) {
            let v = toml_num(rng);
            kv(s, key, v);
        }
    }
    for key in ["segments", "rings", "sides", "steps", "divisions"] {
        if rng.chance(0.15) {
            let v = toml_int(rng);
            kv(s, key, v);
        }
    }
    if rng.chance(0.15) {
        let v = match rng.below(3) {
            0 => format!("{}", 1 + rng.below(30)),
            1 => format!("[{}, {}]", 1 + rng.below(8), rng.below(9)),
            _ => toml_num(rng),
        };
        kv(s, "count", v);
    }
    for key in ["step", "offset", "translate", "rotate_deg", "color"] {
        if rng.chance(0.2) {
            let v = toml_vec(rng, 3);
            kv(s, key, v);
        }
    }
    if rng.chance(0.3) {
        let v = match rng.below(4) {
            0 => toml_vec(rng, 3),
            1 => rng.pick(&["0", "-1", "[1, -1, 1]", "[0, 1, 1]", "1e-20", "1e20"]).to_string(),
            _ => toml_num(rng),
        };
        kv(s, "scale", v);
    }
    if rng.chance(0.2) {
        let v = if rng.chance(0.5) { format!("{:.2}", rng.range(-0.5, 1.5)) } else { toml_num(rng) };
        kv(s, "opacity", v);
    }
    if rng.chance(0.2) {
        let v = rng.pick(&["true", "false", "1", "\"yes\""]).to_string();
        kv(s, "casts_shadow", v);
    }
    if rng.chance(0.1) {
        let v = rng.pick(&["\"m\"", "\"\"", "\"a\\nb\""]).to_string();
        kv(s, "name", v);
    }
    if rng.bad() && rng.chance(0.03) {
        let _ = writeln!(s, "colour = [1, 1, 1]");
    }
}

/// Plans every caster of a loaded scene for every light and checks the volumes.
fn plan_scene(scene: &umbrage_scene::Scene, method: Method) {
    let casters: Vec<Caster> = scene.meshes.iter().filter(|m| m.casts_shadow).filter_map(|m| m.caster().ok()).collect();
    for light in &scene.lights {
        let vp = scene.camera.proj_infinite(1.5) * scene.camera.view();
        let input = PlanInput { camera: &scene.camera, width: 96, height: 64, view_proj: vp, light, method };
        let plan = plan_light_with(&input, &casters, &PlanOptions::default());
        check_plan(&casters, &plan.casters, light.kind == LightKind::Directional);
    }
}

pub(crate) fn check_scene(text: &(String, bool, usize)) {
    let (text, plan, method) = text;
    if let Ok(scene) = umbrage_scene::load_str(text, "fuzz.toml", &data_dir()) {
        SCENE_OK.fetch_add(1, Ordering::Relaxed);
        if *plan {
            plan_scene(&scene, Method::ALL[*method]);
        }
    }
}
