//! Where a light's shadow maps look from: the view-projections of a directional light's one
//! orthographic map, a spot light's one perspective map or a point light's six cube faces,
//! each map's place (an atlas tile, or a layer of its own), and the per-face culling of the
//! casters against them. Eye-relative throughout; no Vulkan calls.

use crate::CubeFaces;
use glam::{DVec3, Mat4, Vec3, Vec4};
use umbrage_scene::{Camera, Light, LightKind};

/// One caster mesh's vertices in the casters' buffer and its eye-relative bounding sphere
/// (per-face culling).
#[derive(Clone, Copy, Debug)]
pub(super) struct MeshRange {
    /// First vertex in the casters' buffer.
    pub first: u32,
    /// Vertices (three per triangle).
    pub count: u32,
    /// Bounding sphere centre, eye-relative.
    pub center: DVec3,
    /// Bounding sphere radius.
    pub radius: f64,
}

/// The opaque shadow casters as the map pass draws them: their triangles' vertices
/// (eye-relative, three per triangle), each mesh's range and bounding sphere, and the bounding
/// sphere of them all.
pub(super) struct Casters {
    /// Eye-relative vertices, three per triangle, mesh after mesh.
    pub vertices: Vec<[f32; 3]>,
    /// Each non-empty caster mesh's range of [`Casters::vertices`] and bounding sphere.
    pub meshes: Vec<MeshRange>,
    /// All casters' bounding sphere, eye-relative (the origin and 1 without casters).
    pub bounds: (DVec3, f64),
}

impl Casters {
    /// The casters of `scene`, relative to its camera's eye.
    pub fn of(scene: &umbrage_scene::Scene) -> Casters {
        let eye = scene.camera.eye.as_dvec3();
        let mut pos: Vec<[f32; 3]> = Vec::new();
        let mut meshes = Vec::new();
        let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
        for m in scene.meshes.iter().filter(|m| m.casts_shadow && m.opacity >= 1.0) {
            let xf = m.transform.as_dmat4();
            let first = pos.len() as u32;
            let (mut mlo, mut mhi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
            for t in 0..m.mesh.triangles.len() {
                for v in m.mesh.triangle(t) {
                    let r = xf.transform_point3(v.as_dvec3()) - eye;
                    mlo = mlo.min(r);
                    mhi = mhi.max(r);
                    pos.push(r.as_vec3().to_array());
                }
            }
            let count = pos.len() as u32 - first;
            if count > 0 {
                lo = lo.min(mlo);
                hi = hi.max(mhi);
                // A little slack: the vertices were rounded to f32.
                let radius = ((mhi - mlo) * 0.5).length() * (1.0 + 1e-5) + 1e-6;
                meshes.push(MeshRange { first, count, center: (mlo + mhi) * 0.5, radius });
            }
        }
        let bounds = if pos.is_empty() { (DVec3::ZERO, 1.0) } else { ((lo + hi) * 0.5, ((hi - lo) * 0.5).length().max(1e-6)) };
        Casters { vertices: pos, meshes, bounds }
    }
}

/// `shadowmap_lookup.frag`'s (and `shadowmap_multiview.wgsl`'s) `Face` (std430).
#[repr(C)]
#[derive(Clone, Copy, Default, bytemuck::Pod, bytemuck::Zeroable)]
pub(super) struct FaceRow {
    /// Eye-relative world -> this face's clip space.
    pub view_proj: [f32; 16],
    /// Tile in its layer: x0, y0, width, height (texels).
    pub tile: [f32; 4],
    /// x: layer, y: compare bias, z: normal offset.
    pub params: [f32; 4],
}

/// The face table's size: six faces.
pub(super) const FACES_BYTES: u64 = 6 * std::mem::size_of::<FaceRow>() as u64;

/// One map to render and look up: the eye-relative light view-projection and where it lies.
pub(super) struct Face {
    pub view_proj: Mat4,
    /// Its tile's corner in its layer (texels): a 3 x 2 atlas's tile, or (0, 0).
    pub tile: [u32; 2],
    /// Its layer: 0 in an atlas; the face's index when the faces are multiview views.
    pub layer: u32,
    /// World size of one texel near the casters (for the normal offset).
    pub texel_world: f32,
}

impl Face {
    /// The lookup's row for this face, whose maps are `size` texels a side.
    pub fn row(&self, size: u32) -> FaceRow {
        FaceRow {
            view_proj: self.view_proj.to_cols_array(),
            tile: [self.tile[0] as f32, self.tile[1] as f32, size as f32, size as f32],
            params: [self.layer as f32, 2e-5, 1.5 * self.texel_world, 0.0],
        }
    }
}

/// What every light's faces are computed from: the casters and how the maps are laid out.
pub(super) struct Layout<'a> {
    /// The caster meshes (their bounding spheres hug a point or spot light's near and far).
    pub meshes: &'a [MeshRange],
    /// All casters' bounding sphere, eye-relative.
    pub bounds: (DVec3, f64),
    /// Texels per side of one map.
    pub size: u32,
    /// Where a point light's six faces go.
    pub cube: CubeFaces,
}

impl Layout<'_> {
    /// The maps `light` needs, in eye-relative coordinates (`eye` is the frame's eye).
    pub fn faces(&self, light: &Light, eye: DVec3) -> Vec<Face> {
        let (c, r) = self.bounds;
        let s = self.size as f64;
        let rel = |p: Vec3| (p.as_dvec3() - eye).as_vec3();
        match light.kind {
            LightKind::Directional => {
                let dir = light.direction.as_dvec3().normalize();
                let from = c - dir * (2.0 * r);
                let cam = Camera { eye: from.as_vec3(), target: c.as_vec3(), up: any_up(dir), fov_y_deg: 60.0, near: 0.1 };
                let rr = r as f32;
                // Vulkan orthographic: x, y in [-r, r] (y down), depth 0 at the eye .. 1 at 4r.
                let ortho = Mat4::from_cols(
                    Vec4::new(1.0 / rr, 0.0, 0.0, 0.0),
                    Vec4::new(0.0, -1.0 / rr, 0.0, 0.0),
                    Vec4::new(0.0, 0.0, -1.0 / (4.0 * rr), 0.0),
                    Vec4::new(0.0, 0.0, 0.0, 1.0),
                );
                vec![Face { view_proj: ortho * cam.view(), tile: [0, 0], layer: 0, texel_world: (2.0 * r / s) as f32 }]
            }
            LightKind::Spot | LightKind::Point => {
                let l = rel(light.position).as_dvec3();
                // Near and far hug the casters: the nearest and farthest caster spheres.
                let (mut near_c, mut far_c) = (f64::INFINITY, 0.0f64);
                for m in self.meshes {
                    let d = (m.center - l).length();
                    near_c = near_c.min(d - m.radius);
                    far_c = far_c.max(d + m.radius);
                }
                let far = if far_c > 0.0 { far_c * 1.01 } else { ((l - c).length() + r) * 1.01 };
                let near = (0.9 * near_c).max(far * 1e-4).max(1e-4);
                let dist = (l - c).length().max(near);
                let dirs: Vec<(DVec3, f64, Option<u32>)> = if light.kind == LightKind::Spot {
                    vec![(light.direction.as_dvec3().normalize(), (light.cone_deg as f64 + 2.0).min(170.0), None)]
                } else {
                    [DVec3::X, DVec3::NEG_X, DVec3::Y, DVec3::NEG_Y, DVec3::Z, DVec3::NEG_Z]
                        .into_iter()
                        .enumerate()
                        .map(|(i, d)| (d, 90.0, Some(i as u32)))
                        .collect()
                };
                dirs.into_iter()
                    .map(|(d, fov, face)| {
                        let cam =
                            Camera { eye: l.as_vec3(), target: (l + d).as_vec3(), up: any_up(d), fov_y_deg: fov as f32, near: near as f32 };
                        let (tile, layer) = match (face, self.cube) {
                            (None, _) => ([0, 0], 0),
                            (Some(f), CubeFaces::Atlas) => ([(f % 3) * self.size, (f / 3) * self.size], 0),
                            (Some(f), CubeFaces::Multiview) => ([0, 0], f),
                        };
                        let texel_world = (2.0 * dist * (fov.to_radians() * 0.5).tan() / s) as f32;
                        Face { view_proj: cam.proj_finite(1.0, far as f32) * cam.view(), tile, layer, texel_world }
                    })
                    .collect()
            }
        }
    }
}

/// Whether a sphere (eye-relative centre, radius) meets the frustum of a Vulkan clip matrix
/// (0 <= z <= w): its distance to each of the six planes.
pub(super) fn sphere_in_frustum(m: &Mat4, c: DVec3, r: f64) -> bool {
    let rows = [m.row(0).as_dvec4(), m.row(1).as_dvec4(), m.row(2).as_dvec4(), m.row(3).as_dvec4()];
    let planes = [rows[3] + rows[0], rows[3] - rows[0], rows[3] + rows[1], rows[3] - rows[1], rows[2], rows[3] - rows[2]];
    planes.iter().all(|p| {
        let n = p.truncate();
        let len = n.length();
        len == 0.0 || (n.dot(c) + p.w) / len >= -r
    })
}

/// An up vector not parallel to `d`.
fn any_up(d: DVec3) -> Vec3 {
    if d.y.abs() > 0.9 {
        Vec3::Z
    } else {
        Vec3::Y
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cube_faces_take_tiles_or_layers_with_the_same_matrices() {
        let meshes = [MeshRange { first: 0, count: 3, center: DVec3::new(0.0, 0.0, -5.0), radius: 1.0 }];
        let atlas = Layout { meshes: &meshes, bounds: (DVec3::new(0.0, 0.0, -5.0), 1.0), size: 256, cube: CubeFaces::Atlas };
        let views = Layout { cube: CubeFaces::Multiview, ..atlas };
        let light = Light::point(Vec3::new(0.0, 3.0, 0.0));
        let (a, v) = (atlas.faces(&light, DVec3::ZERO), views.faces(&light, DVec3::ZERO));
        assert_eq!((a.len(), v.len()), (6, 6));
        for (i, (a, v)) in a.iter().zip(&v).enumerate() {
            assert_eq!(a.view_proj, v.view_proj, "face {i}");
            assert_eq!((a.tile, a.layer), ([(i as u32 % 3) * 256, (i as u32 / 3) * 256], 0));
            assert_eq!((v.tile, v.layer), ([0, 0], i as u32));
            assert_eq!(v.row(256).params[0], i as f32);
        }
        // The caster below the light and ahead of it (mostly along -z) is in the -z face only.
        let seen: Vec<bool> = v.iter().map(|f| sphere_in_frustum(&f.view_proj, meshes[0].center, meshes[0].radius)).collect();
        assert_eq!(seen, [false, false, false, false, false, true]);
    }
}
