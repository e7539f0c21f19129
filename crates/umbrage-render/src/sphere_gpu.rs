//! The scene's analytic spheres on the GPU (what the G-buffer pass ray-casts): per ring slot a
//! small host-visible buffer with each sphere's bounding cube (36 vertices), positions and
//! centre relative to the current eye, computed in f64 and rewritten every frame (the camera
//! and the spheres may move). Vertex layout = the scene vertices' ([`VERTEX_ATTRIBUTES`]):
//! cube corner, sphere centre (in the normal's slot), colour, radius (in the opacity's slot).
//!
//! [`VERTEX_ATTRIBUTES`]: super::scene_gpu::VERTEX_ATTRIBUTES

use ash::vk;
use glam::DVec3;
use gpu_allocator::MemoryLocation;
use umbrage::error::{Error, Result};
use umbrage::gpu::{Buffer, Context};
use umbrage_scene::Scene;

/// Cube margin over the radius: the cube's faces stay clear of the sphere's silhouette.
const MARGIN: f64 = 1.02;

pub(crate) struct SphereGeometry {
    /// Per ring slot (empty when the scene has no sphere).
    buffers: Vec<Buffer>,
    count: u32,
}

/// The 36 corners (12 outward, counter-clockwise triangles) of the cube `c ± h`.
fn cube(c: DVec3, h: f64) -> [DVec3; 36] {
    let corner =
        |i: usize| c + DVec3::new(if i & 1 != 0 { h } else { -h }, if i & 2 != 0 { h } else { -h }, if i & 4 != 0 { h } else { -h });
    // Faces as corner quads (bit patterns), each wound outward.
    const FACES: [[usize; 4]; 6] = [[4, 6, 2, 0], [3, 7, 5, 1], [1, 5, 4, 0], [6, 7, 3, 2], [2, 3, 1, 0], [5, 7, 6, 4]];
    let mut out = [DVec3::ZERO; 36];
    for (f, q) in FACES.iter().enumerate() {
        let [a, b, cc, d] = q.map(corner);
        let tri = [a, b, cc, a, cc, d];
        out[f * 6..f * 6 + 6].copy_from_slice(&tri);
    }
    out
}

impl SphereGeometry {
    pub fn new(ctx: &Context, scene: &Scene, slots: usize) -> Result<SphereGeometry> {
        let mut g = SphereGeometry { buffers: Vec::new(), count: 36 * scene.spheres.len() as u32 };
        if scene.spheres.is_empty() {
            return Ok(g);
        }
        for s in 0..slots {
            match Buffer::new(
                ctx,
                &format!("spheres {s}"),
                g.count as u64 * 40,
                vk::BufferUsageFlags::VERTEX_BUFFER,
                MemoryLocation::CpuToGpu,
            ) {
                Ok(b) => g.buffers.push(b),
                Err(e) => {
                    g.destroy(ctx);
                    return Err(e);
                }
            }
        }
        Ok(g)
    }

    /// Writes slot `slot`'s cubes for the scene's spheres and eye: the buffer and its vertex
    /// count, or `None` without spheres.
    pub fn write(&mut self, slot: usize, scene: &Scene) -> Result<Option<(vk::Buffer, u32)>> {
        if self.buffers.is_empty() {
            return Ok(None);
        }
        if 36 * scene.spheres.len() as u32 != self.count {
            return Err(Error::argument("scene spheres", "their number changed after the renderer was created"));
        }
        let eye = scene.camera.eye.as_dvec3();
        let mut data: Vec<[f32; 10]> = Vec::with_capacity(self.count as usize);
        for s in &scene.spheres {
            let c = s.sphere.center - eye;
            let cf = c.as_vec3();
            for p in cube(c, s.sphere.radius * MARGIN) {
                let p = p.as_vec3();
                data.push([p.x, p.y, p.z, cf.x, cf.y, cf.z, s.color.x, s.color.y, s.color.z, s.sphere.radius as f32]);
            }
        }
        let buf = self.buffers.get_mut(slot).ok_or_else(|| Error::Internal(format!("sphere slot {slot} out of range")))?;
        buf.write(0, bytemuck::cast_slice(&data))?;
        Ok(Some((buf.raw, self.count)))
    }

    pub fn destroy(&mut self, ctx: &Context) {
        for b in &mut self.buffers {
            b.destroy(ctx);
        }
        self.buffers.clear();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    #[test]
    fn cube_faces_are_outward() {
        let c = DVec3::new(1.0, -2.0, 3.0);
        let v = cube(c, 0.5);
        for t in v.chunks(3) {
            let n = (t[1] - t[0]).cross(t[2] - t[0]);
            let centroid = (t[0] + t[1] + t[2]) / 3.0;
            assert!(n.dot(centroid - c) > 0.0, "inward triangle {t:?}");
        }
    }
}
