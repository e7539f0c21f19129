//! The motion keys: a mesh's `spin_deg_per_s = [x, y, z]`, a light's
//! `orbit = { center, radius, period_s }` or `keyframes = [{ t, position }, ...]`, the camera's
//! `orbit` (the same keys as a light's: the eye moves, the target stays) or
//! `keyframes = [{ t, eye, target }, ...]`.

use super::keys::{Ctx, FileCameraKey, FileLight, FileMesh, FileOrbit};
use crate::motion::{orbit_phase, CameraPath, LightPath, Motion};
use crate::{Camera, Light, LightKind};
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

/// The camera's motion (`[camera]`'s `orbit` or `keyframes`), from the camera at rest.
pub(super) fn camera_motion(
    cx: &Ctx,
    s: &std::ops::Range<usize>,
    (orbit, keyframes): (Option<FileOrbit>, Option<Vec<FileCameraKey>>),
    rest: &Camera,
) -> Result<Option<CameraPath>> {
    let s = s.clone();
    Ok(match (&orbit, &keyframes) {
        (Some(_), Some(_)) => return Err(cx.key_err(&s, "keyframes", "give the camera either `orbit` or `keyframes`, not both")),
        (Some(o), None) => {
            let center = cx.v3(&s, "orbit", o.center)?;
            let radius = cx.positive(&s, "orbit", Some(o.radius), 1.0)?;
            let period_s = cx.positive(&s, "orbit", Some(o.period_s), 1.0)?;
            Some(CameraPath::Orbit { center, radius, period_s, phase: orbit_phase(center, rest.eye) })
        }
        (None, Some(keys)) => {
            if keys.len() < 2 {
                return Err(cx.key_err(&s, "keyframes", "needs at least two keys"));
            }
            let mut out: Vec<(f32, glam::Vec3, glam::Vec3)> = Vec::with_capacity(keys.len());
            for k in keys {
                let t = cx.num(&s, "keyframes", k.t)?;
                if let Some(&(prev, _, _)) = out.last() {
                    if t <= prev {
                        return Err(cx.key_err(&s, "keyframes", format!("key times must increase ({t} after {prev})")));
                    }
                }
                let (eye, target) = (cx.v3(&s, "keyframes", k.eye)?, cx.v3(&s, "keyframes", k.target)?);
                if eye == target {
                    return Err(cx.key_err(&s, "keyframes", format!("a key at t = {t} has its eye on its target")));
                }
                out.push((t, eye, target));
            }
            Some(CameraPath::Keyframes(out))
        }
        (None, None) => None,
    })
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
    fn the_camera_orbits_or_follows_its_keyframes() {
        let orbit = "[camera]\neye = [4.0, 2.0, 0.0]\ntarget = [0.0, 0.0, 0.0]\norbit = { center = [0.0, 2.0, 0.0], radius = 4.0, period_s = 8.0 }\n";
        let (scene, motion) = load_animated_str(orbit);
        assert!(!motion.is_static());
        // at rest where the file puts it; a quarter turn later at +z; the target stays
        let at0 = motion.scene_at(&scene, 0.0).camera;
        assert!(at0.eye.distance(scene.camera.eye) < 1e-5, "{}", at0.eye);
        let q = motion.scene_at(&scene, 2.0).camera;
        assert!(q.eye.distance(Vec3::new(0.0, 2.0, 4.0)) < 1e-4 && q.target == Vec3::ZERO, "{q:?}");
        let keys = "[camera]\neye = [0.0, 2.0, 6.0]\ntarget = [0.0, 0.0, 0.0]\n\
                    keyframes = [{ t = 0.0, eye = [0.0, 2.0, 6.0], target = [0.0, 0.0, 0.0] }, \
                    { t = 2.0, eye = [4.0, 2.0, 6.0], target = [2.0, 0.0, 0.0] }]\n";
        let (scene, motion) = load_animated_str(keys);
        let c = motion.scene_at(&scene, 1.0).camera;
        assert_eq!((c.eye, c.target), (Vec3::new(2.0, 2.0, 6.0), Vec3::new(1.0, 0.0, 0.0)));
        // refused: both, one key, times not increasing, an eye on its target
        for (bad, want) in [
            ("orbit = { center = [0.0, 2.0, 0.0], radius = 4.0, period_s = 8.0 }\nkeyframes = [{ t = 0.0, eye = [0.0, 2.0, 6.0], target = [0.0, 0.0, 0.0] }, { t = 1.0, eye = [1.0, 2.0, 6.0], target = [0.0, 0.0, 0.0] }]\n", "not both"),
            ("keyframes = [{ t = 0.0, eye = [0.0, 2.0, 6.0], target = [0.0, 0.0, 0.0] }]\n", "at least two"),
            ("keyframes = [{ t = 1.0, eye = [0.0, 2.0, 6.0], target = [0.0, 0.0, 0.0] }, { t = 1.0, eye = [1.0, 2.0, 6.0], target = [0.0, 0.0, 0.0] }]\n", "increase"),
            ("keyframes = [{ t = 0.0, eye = [0.0, 2.0, 6.0], target = [0.0, 2.0, 6.0] }, { t = 1.0, eye = [1.0, 2.0, 6.0], target = [0.0, 0.0, 0.0] }]\n", "on its target"),
        ] {
            let text = format!("{BASE}{bad}");
            let e = load_str(&text, "m.toml", Path::new("")).err().map(|e| e.to_string()).unwrap_or_else(|| panic!("accepted: {bad}"));
            assert!(e.contains(want), "{e}");
        }
    }

    fn load_animated_str(text: &str) -> (crate::Scene, crate::motion::Motion) {
        crate::file::parse_animated(text, "cam.toml", crate::file::ObjSource::Dir(Path::new(""))).expect("loads")
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
