//! The suite's parametric scene: a grid of UV spheres over a floor and a back wall, lit by
//! point lights on a ring above them. Each sweep moves one parameter: the spheres'
//! tessellation (vertex work grows, fill stays), the number of lights, the lights' height
//! above the casters (close: volumes fan out over the screen, fill grows; far: thin volumes),
//! the number of casters (draw calls), while the resolution sweep renders `bench/fill`. With
//! [`SweepScene::groups`] the same spheres are merged into fewer casters: the same triangles
//! and the same shadows in fewer draws (the one-factor casters sweep).

use glam::{Mat4, Vec2, Vec3};
use umbrage::geom::Mesh;
use umbrage_scene::{shapes, Camera, Light, LightKind, Scene, SceneMesh};

/// One point of a parametric sweep.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SweepScene {
    /// Sphere casters, on a square grid (rounded up to the next square, then truncated).
    pub casters: u32,
    /// Caster triangles over all spheres (each sphere gets `triangles / casters`, at least 24).
    pub triangles: u64,
    /// Point lights on a ring above the grid.
    pub lights: u32,
    /// The lights' height above the spheres' centres, in sphere spacings.
    pub light_height: f32,
    /// The lights' range in sphere spacings (`None`: unbounded, so their scissor is the whole
    /// target and no caster is out of range).
    pub light_range: Option<f32>,
    /// The spheres merged into this many casters (contiguous runs of the grid, each one mesh
    /// in world space); `None`: one caster per sphere.
    pub groups: Option<u32>,
}

impl Default for SweepScene {
    fn default() -> Self {
        SweepScene { casters: 4, triangles: 16_000, lights: 1, light_height: 1.5, light_range: None, groups: None }
    }
}

/// Segments around one sphere of about `tris` triangles (rings = segments / 2).
fn sphere_segments(tris: u64) -> u32 {
    // 2 * s * (s / 2 - 1) triangles ~ s^2.
    ((tris.max(24) as f64).sqrt().round() as u32).max(6)
}

impl SweepScene {
    /// The ablations' scene: 64 spheres under 8 lights of limited range (scissors smaller
    /// than the target, casters out of some lights' range).
    pub fn ranged() -> SweepScene {
        SweepScene { casters: 64, triangles: 64 * 2000, lights: 8, light_height: 1.0, light_range: Some(3.0), groups: None }
    }

    /// The scene's name in reports (`sweep/c4-t16000-l1-h1.5`; merged into 16 casters:
    /// `sweep/c256-t131072-l1-h1.5-m16`).
    pub fn name(&self) -> String {
        let range = self.light_range.map(|r| format!("-r{r}")).unwrap_or_default();
        let merged = self.groups.map(|g| format!("-m{g}")).unwrap_or_default();
        format!("sweep/c{}-t{}-l{}-h{}{range}{merged}", self.casters, self.triangles, self.lights, self.light_height)
    }

    /// Shadow-casting meshes the scene holds (spheres, or their groups).
    pub fn caster_count(&self) -> u32 {
        let n = self.casters.max(1);
        self.groups.map_or(n, |g| g.clamp(1, n))
    }

    /// Builds the scene.
    pub fn build(&self) -> Scene {
        let n = self.casters.max(1);
        let side = (n as f64).sqrt().ceil() as u32;
        let spacing = 1.5f32;
        let radius = 0.5f32;
        let extent = side as f32 * spacing;
        let segments = sphere_segments(self.triangles / n as u64);
        let sphere: Mesh = shapes::sphere(radius, segments, (segments / 2).max(2));
        let mut meshes = vec![
            SceneMesh {
                name: "floor".into(),
                mesh: shapes::plane(Vec2::splat(extent * 4.0 + 20.0)),
                transform: Mat4::IDENTITY,
                color: Vec3::splat(0.7),
                opacity: 1.0,
                casts_shadow: false,
            },
            SceneMesh {
                name: "wall".into(),
                mesh: shapes::cuboid(Vec3::new(extent * 4.0 + 20.0, extent * 2.0 + 8.0, 0.5)),
                transform: Mat4::from_translation(Vec3::new(0.0, 0.0, -extent * 0.5 - 2.0)),
                color: Vec3::splat(0.6),
                opacity: 1.0,
                casts_shadow: false,
            },
        ];
        let y = 1.5f32;
        let spheres: Vec<SceneMesh> = (0..n)
            .map(|k| {
                let (i, j) = (k % side, k / side);
                let x = (i as f32 - (side - 1) as f32 * 0.5) * spacing;
                let z = (j as f32 - (side - 1) as f32 * 0.5) * spacing;
                SceneMesh {
                    name: format!("sphere{k}"),
                    mesh: sphere.clone(),
                    transform: Mat4::from_translation(Vec3::new(x, y, z)),
                    color: Vec3::new(0.5, 0.6, 0.9),
                    opacity: 1.0,
                    casts_shadow: true,
                }
            })
            .collect();
        match self.groups {
            None => meshes.extend(spheres),
            Some(_) => {
                let g = self.caster_count() as usize;
                let n = n as usize;
                // Group `k` holds spheres [k n / g, (k + 1) n / g): contiguous, sizes within one.
                for k in 0..g {
                    let run = &spheres[k * n / g..(k + 1) * n / g];
                    meshes.push(merged(run, &format!("group{k}")));
                }
            }
        }
        let h = y + self.light_height * spacing;
        let ring = if self.lights > 1 { extent * 0.35 } else { 0.0 };
        let lights = (0..self.lights.max(1))
            .map(|l| {
                let a = std::f32::consts::TAU * l as f32 / self.lights.max(1) as f32;
                Light {
                    kind: LightKind::Point,
                    position: Vec3::new(ring * a.cos(), h, ring * a.sin() + spacing * 0.25),
                    direction: Vec3::NEG_Y,
                    color: Vec3::ONE,
                    intensity: 1.0 / self.lights.max(1) as f32,
                    radius: self.light_range.map(|r| r * spacing),
                    cone_deg: 45.0,
                    area: None,
                }
            })
            .collect();
        let dist = extent * 0.9 + 5.0;
        let camera = Camera { eye: Vec3::new(0.0, y + dist * 0.6, dist), target: Vec3::new(0.0, y * 0.5, 0.0), ..Camera::default() };
        Scene { name: self.name(), camera, lights, meshes, spheres: Vec::new(), ambient: Vec3::splat(0.06) }
    }

    /// Caster triangles actually built (the spheres' tessellation is rounded).
    pub fn built_triangles(&self) -> u64 {
        let s = sphere_segments(self.triangles / self.casters.max(1) as u64) as u64;
        let rings = (s / 2).max(2);
        self.casters.max(1) as u64 * 2 * s * (rings - 1)
    }
}

/// `meshes` as one mesh named `name`: their triangles in world space (each transform applied,
/// the winding kept where a transform mirrors), identity transform, the first one's colour
/// and opacity, shadow-casting if any of them is. The same triangles in one draw.
pub fn merged(meshes: &[SceneMesh], name: &str) -> SceneMesh {
    let mut mesh = Mesh { positions: Vec::new(), triangles: Vec::new() };
    for m in meshes {
        let base = mesh.positions.len() as u32;
        mesh.positions.extend(m.mesh.positions.iter().map(|p| m.transform.transform_point3(*p)));
        let mirror = m.transform.determinant() < 0.0;
        mesh.triangles.extend(m.mesh.triangles.iter().map(|t| {
            let [a, b, c] = t.map(|i| i + base);
            if mirror {
                [a, c, b]
            } else {
                [a, b, c]
            }
        }));
    }
    let first = meshes.first();
    SceneMesh {
        name: name.to_string(),
        mesh,
        transform: Mat4::IDENTITY,
        color: first.map_or(Vec3::splat(0.7), |m| m.color),
        opacity: first.map_or(1.0, |m| m.opacity),
        casts_shadow: meshes.iter().any(|m| m.casts_shadow),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    #[test]
    fn tessellation_and_counts_follow_the_parameters() {
        for t in [1_000u64, 16_000, 256_000] {
            let s = SweepScene { triangles: t, ..Default::default() };
            let scene = s.build();
            let built: u64 = scene.meshes.iter().filter(|m| m.casts_shadow).map(|m| m.mesh.triangles.len() as u64).sum();
            assert_eq!(built, s.built_triangles());
            assert!((built as f64 / t as f64 - 1.0).abs() < 0.35, "{built} vs {t}");
        }
        let s = SweepScene { casters: 10, lights: 7, ..Default::default() }.build();
        assert_eq!(s.meshes.iter().filter(|m| m.casts_shadow).count(), 10);
        assert_eq!(s.lights.len(), 7);
    }

    #[test]
    fn merged_groups_keep_the_triangles_and_their_places() {
        let apart = SweepScene { casters: 16, triangles: 16 * 64, ..Default::default() };
        let world = |s: &Scene| -> Vec<[Vec3; 3]> {
            let mut t: Vec<[Vec3; 3]> = s
                .meshes
                .iter()
                .filter(|m| m.casts_shadow)
                .flat_map(|m| m.mesh.triangles.iter().map(|t| t.map(|i| m.transform.transform_point3(m.mesh.positions[i as usize]))))
                .collect();
            t.sort_by(|a, b| format!("{a:?}").cmp(&format!("{b:?}")));
            t
        };
        let reference = world(&apart.build());
        for g in [1, 4, 16, 5] {
            let s = SweepScene { groups: Some(g), ..apart };
            let scene = s.build();
            assert_eq!(scene.meshes.iter().filter(|m| m.casts_shadow).count() as u32, g.min(16));
            assert_eq!(s.caster_count(), g.min(16));
            assert_eq!(world(&scene), reference, "groups {g}: other triangles");
            assert!(s.name().ends_with(&format!("-m{g}")), "{}", s.name());
        }
        // A mirroring transform keeps the outward winding.
        let one = SweepScene { casters: 1, ..Default::default() }.build();
        let mut m = one.meshes.iter().find(|m| m.casts_shadow).unwrap().clone();
        m.transform = Mat4::from_scale(Vec3::new(-1.0, 1.0, 1.0));
        let flat = merged(std::slice::from_ref(&m), "x");
        let t = flat.mesh.triangles[0];
        let normal = |p: [Vec3; 3]| (p[1] - p[0]).cross(p[2] - p[0]);
        let before = normal(m.mesh.triangles[0].map(|i| m.mesh.positions[i as usize]));
        let after = normal(t.map(|i| flat.mesh.positions[i as usize]));
        assert!(after.dot(Vec3::new(-before.x, before.y, before.z)) > 0.0, "winding flipped by the mirror");
    }
}
