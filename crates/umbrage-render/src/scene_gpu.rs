//! The scene's own geometry on the GPU (what the G-buffer and forward passes draw): flat
//! triangles with smooth shading normals baked once relative to an anchor (the eye at creation) in f64, one contiguous
//! range per mesh, and per frame a small instance buffer placing each mesh relative to the
//! current eye, so meshes and the camera move without re-creating anything.

use super::upload;
use ash::vk;
use glam::{DMat3, DMat4, DVec3};
use gpu_allocator::MemoryLocation;
use umbrage::error::{Error, Result};
use umbrage::geom::shading;
use umbrage::geom::topology::Topology;
use umbrage::gpu::{Buffer, Context};
use umbrage_scene::Scene;

/// The analytic spheres' cube vertices ([`VERTEX_ATTRIBUTES`]): 10 floats.
pub(crate) const VERTEX_STRIDE: u32 = 40;
/// Scene vertex layout: position (anchor-relative), face normal, colour, opacity, then the
/// smooth shading normal and its terminator bound ([`umbrage::geom::shading`]): 14 floats.
pub const SCENE_VERTEX_STRIDE: u32 = 56;
/// The scene vertices' shading attributes (binding 0, after [`VERTEX_ATTRIBUTES`]): the smooth
/// normal (location 10) and the bound (location 11).
pub(crate) const SHADING_ATTRIBUTES: [(u32, vk::Format, u32); 2] =
    [(10, vk::Format::R32G32B32_SFLOAT, 40), (11, vk::Format::R32_SFLOAT, 52)];
/// The G-buffer pass's vertex attributes: position, face normal, colour, smooth normal, bound.
pub const GBUFFER_ATTRIBUTES: [(u32, vk::Format, u32); 5] =
    [VERTEX_ATTRIBUTES[0], VERTEX_ATTRIBUTES[1], VERTEX_ATTRIBUTES[2], SHADING_ATTRIBUTES[0], SHADING_ATTRIBUTES[1]];
/// Per-mesh instance data: 3 rows of the position map, 3 rows of the normal map.
pub const INSTANCE_BYTES: u64 = 96;
/// The instance binding's stride: 0, every vertex of a draw reads the one record bound at
/// the mesh's offset (no reliance on `firstInstance`; and synchronisation validation 1.3.239
/// sizes instance-rate reads by the vertex count, which reported false hazards on the
/// buffers next to the instance buffer).
pub(crate) const INSTANCE_STRIDE: u32 = 0;
/// The first four vertex attributes (binding 0) of every scene pipeline (and the spheres').
pub(crate) const VERTEX_ATTRIBUTES: [(u32, vk::Format, u32); 4] = [
    (0, vk::Format::R32G32B32_SFLOAT, 0),
    (1, vk::Format::R32G32B32_SFLOAT, 12),
    (2, vk::Format::R32G32B32_SFLOAT, 24),
    (3, vk::Format::R32_SFLOAT, 36),
];
/// The instance attributes (binding 1).
pub(crate) const INSTANCE_ATTRIBUTES: [(u32, vk::Format, u32); 6] = [
    (4, vk::Format::R32G32B32A32_SFLOAT, 0),
    (5, vk::Format::R32G32B32A32_SFLOAT, 16),
    (6, vk::Format::R32G32B32A32_SFLOAT, 32),
    (7, vk::Format::R32G32B32A32_SFLOAT, 48),
    (8, vk::Format::R32G32B32A32_SFLOAT, 64),
    (9, vk::Format::R32G32B32A32_SFLOAT, 80),
];

/// How a mesh is drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Sidedness {
    /// Closed, outward: back faces culled.
    OneSided,
    /// Open, non-manifold, inside-out, or the camera is inside it: both sides shaded.
    TwoSided,
    /// Transparent: drawn forward over the lit scene.
    Transparent,
}

/// One mesh's vertex range.
#[derive(Clone, Copy, Debug)]
pub(crate) struct MeshRange {
    /// Index of the mesh in the scene (and of its instance record).
    pub mesh: u32,
    pub first: u32,
    pub count: u32,
    pub side: Sidedness,
}

pub(crate) struct SceneGeometry {
    pub vertices: Buffer,
    /// Ranges ordered one-sided, two-sided, transparent.
    pub ranges: Vec<MeshRange>,
    /// The eye the vertices were baked relative to.
    anchor: DVec3,
    /// Each mesh's object -> world transform when baked.
    baked: Vec<DMat4>,
    /// Per ring slot, the instance buffer (host visible).
    instances: Vec<Buffer>,
}

impl SceneGeometry {
    pub fn new(ctx: &Context, scene: &Scene, slots: usize) -> Result<SceneGeometry> {
        let eye = scene.camera.eye.as_dvec3();
        let mut per_side: [Vec<(u32, Vec<[f32; 14]>)>; 3] = [Vec::new(), Vec::new(), Vec::new()];
        for (mi, m) in scene.meshes.iter().enumerate() {
            let topo = Topology::build(&m.mesh);
            // A camera inside a closed mesh sees its inside: draw that one two-sided too.
            let eye_inside = topo.is_closed_manifold()
                && m.world_bounds().contains(scene.camera.eye)
                && m.mesh.contains_point(m.transform.as_dmat4().inverse().transform_point3(eye));
            let outward = topo.is_closed_manifold() && signed_volume(&m.mesh) > 0.0 && !eye_inside;
            let side = if m.opacity < 1.0 {
                2
            } else if outward {
                0
            } else {
                1
            };
            let xf = m.transform.as_dmat4();
            let world: Vec<[DVec3; 3]> =
                (0..m.mesh.triangles.len()).map(|t| m.mesh.triangle(t).map(|v| xf.transform_point3(v.as_dvec3()))).collect();
            let smooth = shading::corner_normals(&world, &topo.mesh.triangles, shading::CREASE_DEG);
            let mut verts = Vec::with_capacity(m.mesh.triangles.len() * 3);
            for (p, corners) in world.iter().zip(&smooth) {
                let n = (p[1] - p[0]).cross(p[2] - p[0]);
                if !(n.length_squared() > 0.0) {
                    continue; // zero-area: nothing to rasterise, and no normal to shade with
                }
                let n = n.normalize().as_vec3();
                for (v, c) in p.iter().zip(corners) {
                    let r = (*v - eye).as_vec3();
                    let s = c.normal.as_vec3();
                    let (x, y, z) = (m.color.x, m.color.y, m.color.z);
                    verts.push([r.x, r.y, r.z, n.x, n.y, n.z, x, y, z, m.opacity, s.x, s.y, s.z, c.bound as f32]);
                }
            }
            per_side[side].push((mi as u32, verts));
        }
        let mut all: Vec<[f32; 14]> = Vec::new();
        let mut ranges = Vec::new();
        for (side, list) in per_side.into_iter().enumerate() {
            for (mesh, verts) in list {
                let side = [Sidedness::OneSided, Sidedness::TwoSided, Sidedness::Transparent][side];
                ranges.push(MeshRange { mesh, first: all.len() as u32, count: verts.len() as u32, side });
                all.extend(verts);
            }
        }
        if all.is_empty() {
            if scene.spheres.is_empty() {
                return Err(Error::input(format!("scene '{}'", scene.name), "it has no triangle or sphere to draw"));
            }
            // Spheres only: a buffer to bind (never drawn from; no mesh ranges).
            all.push([0.0; 14]);
        }
        let vertices = upload(ctx, "scene", bytemuck::cast_slice(&all), vk::BufferUsageFlags::VERTEX_BUFFER)?;
        let baked = scene.meshes.iter().map(|m| m.transform.as_dmat4()).collect();
        let mut geo = SceneGeometry { vertices, ranges, anchor: eye, baked, instances: Vec::new() };
        for s in 0..slots {
            let size = (scene.meshes.len().max(1) as u64) * INSTANCE_BYTES;
            match Buffer::new(ctx, &format!("scene instances {s}"), size, vk::BufferUsageFlags::VERTEX_BUFFER, MemoryLocation::CpuToGpu) {
                Ok(b) => geo.instances.push(b),
                Err(e) => {
                    geo.destroy(ctx);
                    return Err(e);
                }
            }
        }
        Ok(geo)
    }

    /// Writes slot `slot`'s instance records for the scene's current transforms and eye, and
    /// returns the buffer to bind at binding 1.
    pub fn write_instances(&mut self, slot: usize, scene: &Scene) -> Result<vk::Buffer> {
        let eye = scene.camera.eye.as_dvec3();
        let mut data: Vec<[[f32; 4]; 6]> = Vec::with_capacity(self.baked.len());
        for (m, baked) in scene.meshes.iter().zip(&self.baked) {
            let now = m.transform.as_dmat4();
            // Baked anchor-relative p -> eye-relative: (now * baked^-1) (p + anchor) - eye. A
            // mesh that has not moved keeps the identity exactly (no rounding at all).
            let (pos, nrm) = if now == *baked {
                (DMat4::from_translation(self.anchor - eye), DMat3::IDENTITY)
            } else {
                let delta = now * baked.inverse();
                let a = DMat4::from_translation(-eye) * delta * DMat4::from_translation(self.anchor);
                (a, DMat3::from_mat4(delta).inverse().transpose())
            };
            let pos = pos.transpose();
            let nrm = nrm.transpose();
            data.push([
                pos.x_axis.as_vec4().to_array(),
                pos.y_axis.as_vec4().to_array(),
                pos.z_axis.as_vec4().to_array(),
                nrm.x_axis.as_vec3().extend(0.0).to_array(),
                nrm.y_axis.as_vec3().extend(0.0).to_array(),
                nrm.z_axis.as_vec3().extend(0.0).to_array(),
            ]);
        }
        let buf = self.instances.get_mut(slot).ok_or_else(|| Error::Internal(format!("instance slot {slot} out of range")))?;
        buf.write(0, bytemuck::cast_slice(&data))?;
        Ok(buf.raw)
    }

    /// Draws every mesh of `side`, each with its instance record of this slot's `instances`.
    ///
    /// # Safety
    /// `cb` is recording inside a rendering instance with a scene pipeline bound (its push
    /// constants set).
    pub unsafe fn cmd_draw(&self, device: &ash::Device, cb: vk::CommandBuffer, instances: vk::Buffer, side: Sidedness) {
        // SAFETY: the caller's contract; the buffers live until the slot retires.
        unsafe {
            device.cmd_bind_vertex_buffers(cb, 0, &[self.vertices.raw], &[0]);
            for r in self.of(side) {
                device.cmd_bind_vertex_buffers(cb, 1, &[instances], &[r.mesh as u64 * INSTANCE_BYTES]);
                device.cmd_draw(cb, r.count, 1, r.first, 0);
            }
        }
    }

    /// Ranges of one kind.
    pub fn of(&self, side: Sidedness) -> impl Iterator<Item = &MeshRange> {
        self.ranges.iter().filter(move |r| r.side == side)
    }

    pub fn destroy(&mut self, ctx: &Context) {
        self.vertices.destroy(ctx);
        for b in &mut self.instances {
            b.destroy(ctx);
        }
    }
}

/// Six times the signed volume (positive for a closed mesh wound outward).
fn signed_volume(mesh: &umbrage::geom::Mesh) -> f64 {
    (0..mesh.triangles.len())
        .map(|t| {
            let [a, b, c] = mesh.triangle(t).map(|p| p.as_dvec3());
            a.dot(b.cross(c))
        })
        .sum()
}
