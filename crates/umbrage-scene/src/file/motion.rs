//! The motion keys: a mesh's `spin_deg_per_s = [x, y, z]`, a light's
//! `orbit = { center, radius, period_s }` or `keyframes = [{ t, position }, ...]`.

use super::keys::{Ctx, FileLight, FileMesh};
use crate::motion::{orbit_phase, LightPath, Motion};
use crate::{Light, LightKind};
use toml::Spanned;
use umbrage::error::Result;

/// The scene's motion, validated against its lights at rest.
pub(super) fn motion(cx: &Ctx, meshes: &[Spanned<FileMesh>], file_lights: &[Spanned<FileLight>], lights: &[Light]) -> Result<Motion> {
    let mut m = Motion::default();
    for sm in meshes {
        let (s, fm) = (sm.span(), sm.get_ref());
        m.spins.push(match fm.spin_deg_per_s {
            Some(v) => Some(cx.v3(&s, "spin_deg_per_s", v)?),
            None => None,
        });
    }
    for (sl, rest) in file_lights.iter().zip(lights) {
        let (s, fl) = (sl.span(), sl.get_ref());
        let moving = fl.orbit.is_some() || fl.keyframes.is_some();
        if moving && rest.kind == LightKind::Directional {
            let key = if fl.orbit.is_some() { "orbit" } else { "keyframes" };
            return Err(cx.key_err(&s, key, "a directional light has no position to move"));
        }
        m.paths.push(match (&fl.orbit, &fl.keyframes) {
            (Some(_), Some(_)) => return Err(cx.key_err(&s, "keyframes", "give either `orbit` or `keyframes`, not both")),
            (Some(o), None) => {
                let center = cx.v3(&s, "orbit", o.center)?;
                let radius = cx.positive(&s, "orbit", Some(o.radius), 1.0)?;
                let period_s = cx.positive(&s, "orbit", Some(o.period_s), 1.0)?;
                Some(LightPath::Orbit { center, radius, period_s, phase: orbit_phase(center, rest.position) })
            }
            (None, Some(keys)) => {
                if keys.len() < 2 {
                    return Err(cx.key_err(&s, "keyframes", "needs at least two keys"));
                }
                let mut out = Vec::with_capacity(keys.len());
                for k in keys {
                    let t = cx.num(&s, "keyframes", k.t)?;
                    if let Some(&(prev, _)) = out.last() {
                        if t <= prev {
                            return Err(cx.key_err(&s, "keyframes", format!("key times must increase ({t} after {prev})")));
                        }
                    }
                    out.push((t, cx.v3(&s, "keyframes", k.position)?));
                }
                Some(LightPath::Keyframes(out))
            }
            (None, None) => None,
        });
    }
    Ok(m)
}

#[cfg(test)]
mod tests {
    use crate::motion::LightPath;
    use crate::{load_animated, load_str};
    use glam::Vec3;
    use std::path::Path;

    const BASE: &str = "[camera]\neye = [0.0, 2.0, 6.0]\ntarget = [0.0, 0.0, 0.0]\n";

    fn err(extra: &str) -> String {
        let text = format!("{BASE}{extra}");
        match load_str(&text, "m.toml", Path::new("")) {
            Ok(_) => panic!("accepted:\n{text}"),
            Err(e) => e.to_string(),
        }
    }

    #[test]
    fn the_stress_scene_moves() {
        let (scene, motion) = load_animated("stress").expect("stress loads");
        assert!(!motion.is_static());
        assert_eq!(motion.spins.len(), scene.meshes.len());
        assert!(matches!(motion.paths[0], Some(LightPath::Orbit { .. })));
        assert!(matches!(motion.paths[1], Some(LightPath::Keyframes(_))));
        // At rest the orbiting light is where the file puts it; later it has moved.
        let at0 = motion.scene_at(&scene, 0.0);
        assert!(at0.lights[0].position.distance(scene.lights[0].position) < 1e-5);
        assert!(motion.scene_at(&scene, 3.0).lights[0].position.distance(scene.lights[0].position) > 1.0);
        let torus = scene.meshes.iter().position(|m| m.name == "torus").expect("torus");
        assert_ne!(motion.scene_at(&scene, 1.0).meshes[torus].transform, scene.meshes[torus].transform);
        // Static scenes stay static.
        assert!(load_animated("default").expect("default").1.is_static());
    }

    #[test]
    fn bad_motion_keys_are_refused_with_their_line() {
        let light = "[[light]]\nkind = \"point\"\nposition = [1.0, 3.0, 0.0]\n";
        let e = err(&format!("{light}orbit = {{ center = [0.0, 3.0, 0.0], radius = 0.0, period_s = 4.0 }}\n"));
        assert!(e.contains("m.toml:7") && e.contains("orbit"), "{e}");
        let e = err(&format!("{light}orbit = {{ center = [0.0, 3.0, 0.0], radius = 1.0, period_s = -1.0 }}\n"));
        assert!(e.contains("must be > 0"), "{e}");
        let e = err(&format!("{light}orbit = {{ center = [0.0, 3.0, 0.0], radius = 1.0 }}\n"));
        assert!(e.contains("period_s"), "{e}");
        let e = err(&format!("{light}keyframes = [{{ t = 0.0, position = [0.0, 1.0, 0.0] }}]\n"));
        assert!(e.contains("at least two"), "{e}");
        let e =
            err(&format!("{light}keyframes = [{{ t = 1.0, position = [0.0, 1.0, 0.0] }}, {{ t = 1.0, position = [0.0, 2.0, 0.0] }}]\n"));
        assert!(e.contains("must increase"), "{e}");
        let e = err("[[light]]\nkind = \"directional\"\ndirection = [0.0, -1.0, 0.0]\norbit = { center = [0.0, 3.0, 0.0], radius = 1.0, period_s = 2.0 }\n");
        assert!(e.contains("directional"), "{e}");
        let e = err("[[mesh]]\nshape = \"box\"\nspin_deg_per_s = [0.0, nan, 0.0]\n");
        assert!(e.contains("spin_deg_per_s"), "{e}");
        let e = err("[[mesh]]\nshape = \"box\"\nspin_deg_per_s = [0.0, 1.0]\n");
        assert!(e.contains("spin_deg_per_s") || e.contains("length"), "{e}");
    }

    #[test]
    fn keyframes_parse_in_order() {
        let text = format!(
            "{BASE}[[light]]\nkind = \"spot\"\nposition = [0.0, 3.0, 0.0]\ndirection = [0.0, -1.0, 0.0]\nkeyframes = [{{ t = 0.0, position = [0.0, 3.0, 0.0] }}, {{ t = 2.0, position = [2.0, 3.0, 0.0] }}]\n"
        );
        let dir = std::env::temp_dir().join(format!("umbrage-motion-{}.toml", std::process::id()));
        std::fs::write(&dir, text).expect("write");
        let (scene, motion) = load_animated(dir.to_str().expect("utf-8")).expect("loads");
        let _ = std::fs::remove_file(&dir);
        let l = motion.light(0, &scene.lights[0], 1.0);
        assert_eq!(l.position, Vec3::new(1.0, 3.0, 0.0));
        assert_eq!(l.direction, scene.lights[0].direction);
    }
}
