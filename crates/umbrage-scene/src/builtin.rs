//! Built-in scenes: the TOML files under `scenes/` at the repository root, embedded.

/// (name, TOML text). The file of `name` is `scenes/<name>.toml`.
pub const SCENES: &[(&str, &str)] = &[
    ("default", include_str!("../../../scenes/default.toml")),
    ("stairs", include_str!("../../../scenes/stairs.toml")),
    ("cubes", include_str!("../../../scenes/cubes.toml")),
    ("spheres", include_str!("../../../scenes/spheres.toml")),
    ("stress", include_str!("../../../scenes/stress.toml")),
    ("bench/fill", include_str!("../../../scenes/bench/fill.toml")),
    ("bench/vertex", include_str!("../../../scenes/bench/vertex.toml")),
    ("bench/caps", include_str!("../../../scenes/bench/caps.toml")),
    ("bench/level", include_str!("../../../scenes/bench/level.toml")),
    ("hard/big_caster", include_str!("../../../scenes/hard/big_caster.toml")),
    ("hard/light_inside_caster", include_str!("../../../scenes/hard/light_inside_caster.toml")),
    ("hard/nested_256", include_str!("../../../scenes/hard/nested_256.toml")),
    ("hard/open_casters", include_str!("../../../scenes/hard/open_casters.toml")),
    ("hard/camera_inside_caster", include_str!("../../../scenes/hard/camera_inside_caster.toml")),
    ("hard/light_at_vertex", include_str!("../../../scenes/hard/light_at_vertex.toml")),
    ("hard/eye_in_volume", include_str!("../../../scenes/hard/eye_in_volume.toml")),
    ("hard/eye_in_two_volumes", include_str!("../../../scenes/hard/eye_in_two_volumes.toml")),
    ("hard/near_plane_cut", include_str!("../../../scenes/hard/near_plane_cut.toml")),
    ("hard/light_inside_bounds", include_str!("../../../scenes/hard/light_inside_bounds.toml")),
    ("hard/light_in_face_plane", include_str!("../../../scenes/hard/light_in_face_plane.toml")),
    ("hard/bounded_lights", include_str!("../../../scenes/hard/bounded_lights.toml")),
    ("hard/grazing_directional", include_str!("../../../scenes/hard/grazing_directional.toml")),
    ("hard/light_very_close", include_str!("../../../scenes/hard/light_very_close.toml")),
    ("hard/near_coplanar", include_str!("../../../scenes/hard/near_coplanar.toml")),
    ("hard/far_coordinates", include_str!("../../../scenes/hard/far_coordinates.toml")),
    ("hard/tiny_casters", include_str!("../../../scenes/hard/tiny_casters.toml")),
    ("hard/slivers", include_str!("../../../scenes/hard/slivers.toml")),
    ("hard/zero_area", include_str!("../../../scenes/hard/zero_area.toml")),
    ("hard/staircase_300", include_str!("../../../scenes/hard/staircase_300.toml")),
    ("hard/background", include_str!("../../../scenes/hard/background.toml")),
    ("hard/look_at_light", include_str!("../../../scenes/hard/look_at_light.toml")),
    ("analytic/sphere_only", include_str!("../../../scenes/analytic/sphere_only.toml")),
    ("analytic/sphere_and_meshes", include_str!("../../../scenes/analytic/sphere_and_meshes.toml")),
    ("transparent/balls_and_cubes", include_str!("../../../scenes/transparent/balls_and_cubes.toml")),
    ("transparent/inner_structure", include_str!("../../../scenes/transparent/inner_structure.toml")),
    ("transparent/depth_1", include_str!("../../../scenes/transparent/depth_1.toml")),
    ("transparent/depth_4", include_str!("../../../scenes/transparent/depth_4.toml")),
    ("transparent/depth_16", include_str!("../../../scenes/transparent/depth_16.toml")),
    ("transparent/depth_64", include_str!("../../../scenes/transparent/depth_64.toml")),
    ("area/disc", include_str!("../../../scenes/area/disc.toml")),
    ("area/rect", include_str!("../../../scenes/area/rect.toml")),
];

/// Embedded data files the built-in scenes reference, by repository-relative path.
pub const DATA: &[(&str, &str)] = &[
    ("scenes/data/zero_area_cube.obj", include_str!("../../../scenes/data/zero_area_cube.obj")),
    ("scenes/data/open_box.obj", include_str!("../../../scenes/data/open_box.obj")),
    ("scenes/data/shared_wall_boxes.obj", include_str!("../../../scenes/data/shared_wall_boxes.obj")),
    ("scenes/data/inside_out_cube.obj", include_str!("../../../scenes/data/inside_out_cube.obj")),
    ("scenes/data/two_sided_card.obj", include_str!("../../../scenes/data/two_sided_card.obj")),
];

/// The TOML text of built-in scene `name`, if there is one.
pub fn scene(name: &str) -> Option<&'static str> {
    SCENES.iter().find(|(n, _)| *n == name).map(|(_, t)| *t)
}

/// The text of an embedded OBJ file by its repository-relative path ([`DATA`]), if embedded.
pub fn obj(path: &str) -> Option<&'static str> {
    DATA.iter().find(|(n, _)| *n == path).map(|(_, t)| *t)
}
