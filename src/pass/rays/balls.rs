//! The analytic sphere casters under ray query: one bottom level of boxes, one per ball,
//! rebuilt when the set changes; each ball is intersected exactly in `rayquery.wgsl`.

use super::{Garbage, Rays, Work, STATIC};
use crate::error::Result;
use crate::gpu::accel::{self, Accel, BlasJob, Geometry};
use crate::gpu::Buffer;
use crate::pass::spheres::SphereCaster;
use ash::vk;
use glam::DVec3;

/// The sphere casters' boxes, the balls the shader tests (f32, relative to `origin`), and what
/// they were built from.
pub(super) struct Balls {
    pub blas: Accel,
    pub buffer: Buffer,
    pub origin: DVec3,
    pub built_from: Vec<[f64; 4]>,
}

impl Rays {
    /// Rebuilds the spheres' bottom level when the sphere casters changed.
    pub(super) fn sync_balls(&mut self, w: &mut Work, spheres: &[SphereCaster]) -> Result<Option<BlasJob>> {
        let now: Vec<[f64; 4]> = spheres.iter().map(|s| s.sphere.center.extend(s.sphere.radius).to_array()).collect();
        if self.balls.as_ref().map(|b| &b.built_from) == Some(&now) || (self.balls.is_none() && now.is_empty()) {
            return Ok(None);
        }
        if let Some(old) = self.balls.take() {
            self.graves.push((Garbage::Accel(old.blas), w.all_slots));
            self.graves.push((Garbage::Buffer(old.buffer), w.all_slots));
        }
        let Some(first) = spheres.first() else { return Ok(None) };
        let origin = first.sphere.center;
        let balls: Vec<[f32; 4]> = spheres
            .iter()
            .map(|s| {
                let c = (s.sphere.center - origin).as_vec3();
                [c.x, c.y, c.z, s.sphere.radius as f32]
            })
            .collect();
        // Each box holds its f32 ball with a margin of a few ulps (the test is exact on the
        // f32 ball; the box only has to contain it).
        let boxes: Vec<[[f32; 3]; 2]> = balls
            .iter()
            .map(|b| {
                let r = b[3] * (1.0 + 1e-5) + 1e-30;
                [[b[0] - r, b[1] - r, b[2] - r], [b[0] + r, b[1] + r, b[2] + r]]
            })
            .collect();
        let data: Vec<u8> = balls.iter().flatten().flat_map(|v| v.to_le_bytes()).collect();
        let buffer = Buffer::with_data(w.dev, "ray-query balls", &data, vk::BufferUsageFlags::STORAGE_BUFFER)?;
        let (blas, job) = match accel::prepare_blas(w.dev, &self.loader, "spheres blas", &Geometry::Aabbs(&boxes), STATIC, w.transient) {
            Ok(r) => r,
            Err(e) => {
                let mut buffer = buffer;
                buffer.destroy(w.dev);
                return Err(e);
            }
        };
        self.counts.builds += 1;
        self.balls = Some(Balls { blas, buffer, origin, built_from: now });
        Ok(Some(job))
    }
}
