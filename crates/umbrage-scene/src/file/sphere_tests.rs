//! `[[sphere]]` tables: parsing and every refused input.

use super::tests::{check, CAM};
use crate::load_str;
use glam::DVec3;
use std::path::Path;

const LIGHT: &str = "[[light]]\nkind = \"point\"\nposition = [0, 6, 0]\n";

#[test]
fn spheres_parse_with_defaults_and_keys() {
    let s = load_str(
        &format!("{CAM}{LIGHT}[[sphere]]\ncenter = [0, 1, 0]\nradius = 0.5\n[[sphere]]\nname = \"ball\"\ncenter = [1, 1, 0]\nradius = 0.25\ncolor = [1, 0, 0]\ncasts_shadow = false\nsegments = 12\n"),
        "ok.toml",
        Path::new("."),
    )
    .unwrap();
    assert_eq!(s.spheres.len(), 2);
    assert_eq!(s.spheres[0].name, "sphere0");
    assert_eq!(s.spheres[0].sphere.center, DVec3::new(0.0, 1.0, 0.0));
    assert_eq!(s.spheres[0].segments, None);
    assert!(s.spheres[0].casts_shadow);
    assert_eq!(s.spheres[1].name, "ball");
    assert_eq!(s.spheres[1].segments, Some(12));
    assert!(!s.spheres[1].casts_shadow);
}

#[test]
fn bad_spheres_are_refused_with_their_line() {
    let sp = |body: &str| format!("{CAM}{LIGHT}[[sphere]]\n{body}\n");
    check(&sp("center = [0, 1, 0]\nradius = 0"), &["radius", "> 0", "bad.toml:9"]);
    check(&sp("center = [0, 1, 0]\nradius = -1"), &["radius", "> 0"]);
    check(&sp("center = [0, 1, 0]\nradius = nan"), &["radius", "non-finite"]);
    check(&sp("center = [0, inf, 0]\nradius = 1"), &["center", "non-finite"]);
    check(&sp("center = [0, 1, 0]\nradius = 1e300"), &["center", "beyond"]);
    check(&sp("center = [0, 1, 0]\nradius = 0.5\nsegments = 2"), &["segments", "[3, 4096]"]);
    check(&sp("center = [0, 1, 0]\nradius = 0.5\nsegments = 100000"), &["segments"]);
    check(&sp("center = [0, 1, 0]\nradius = 0.5\nopacity = 0.5"), &["opacity", "transparent spheres"]);
    check(&sp("center = [0, 1, 0]\nradius = 0.5\nopacity = 2"), &["opacity", "[0, 1]"]);
    check(&sp("center = [0, 1, 0]\nradius = 0.5\nwobble = 1"), &["wobble"]);
    check(&sp("radius = 0.5"), &["center"]);
    // The eye inside or on a sphere; a light inside or on a shadow-casting one.
    check(&sp("center = [0, 2, 5]\nradius = 0.5"), &["camera eye", "inside"]);
    check(&sp("center = [0, 2, 4]\nradius = 1"), &["camera eye", "inside or on"]);
    check(&sp("center = [0, 6.5, 0]\nradius = 1"), &["light 0", "inside or on"]);
    check(&sp("center = [0, 5, 0]\nradius = 1"), &["light 0", "inside or on"]);
    // ... but a sphere that casts no shadow may hold the light (it lights nothing outside it).
    load_str(&sp("center = [0, 6.5, 0]\nradius = 1\ncasts_shadow = false"), "ok.toml", Path::new(".")).unwrap();
}
