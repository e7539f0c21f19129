//! Ray-query shadows (`--method rayquery`): the exact alternative engines weigh against
//! volumes today. Per light, a full-screen pass inside the light's scissor traces one shadow
//! ray per pixel from the G-buffer's position towards the light and writes the same stencil
//! the volumes leave (non-zero = shadowed), so the illumination pass, the masks, the dumps and
//! the stats are the same whichever technique runs.
//!
//! Acceleration structures: one bottom level per shadow-casting scene mesh (its welded
//! triangles), built once with `PREFER_FAST_TRACE` and compacted; a top level per ring slot,
//! its instances (the meshes' current transforms, relative to the eye) rewritten and rebuilt in
//! every frame's command buffer, so a moving caster costs a top-level build and nothing else.
//!
//! The shadow ray follows the CPU reference's rule to the letter (`shaders/rayquery.wgsl`):
//! from `P + N * offset` towards the light, stopping `offset` short of a point light, every
//! caster triangle two-sided, with [`RayTracer::offset`] the reference's own surface offset
//! (raised where the scene's eye-relative extent needs more). Analytic sphere casters are
//! procedural boxes in one more bottom level, intersected exactly in the shader's ray-query
//! loop. Transparent casters are not traced yet: a scene with one is refused with a clear
//! error.

use super::targets::Targets;
use crate::error::{Error, Result};
use crate::gpu::accel::{build_blas, Accel, AccelLoader, Geometry, Instance, Tlas};
use crate::gpu::descriptors::{pipeline_layout, Binding, DescriptorSet};
use crate::gpu::pipeline::{self, PipelineDesc};
use crate::gpu::{shaders, Buffer, Context};
use crate::scene::Scene;
use crate::shadow::Caster;
use ash::vk;
use glam::{DMat4, DVec3};

/// `rayquery.wgsl`'s push constants.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct Push {
    light: [f32; 4],
    params: [f32; 4],
}

/// One bottom level and the scene mesh it belongs to.
struct Entry {
    mesh: usize,
    blas: Accel,
}

/// The sphere casters: their boxes' bottom level, the balls the shader tests (centre relative
/// to `origin`, radius; f32), and that origin (world).
struct Balls {
    blas: Accel,
    buffer: Buffer,
    origin: DVec3,
}

/// The ray-query technique's GPU objects.
pub struct RayTracer {
    loader: AccelLoader,
    entries: Vec<Entry>,
    balls: Option<Balls>,
    /// Bound at binding 3 when there are no spheres (a descriptor needs a buffer).
    no_balls: Option<Buffer>,
    tlas: Vec<Tlas>,
    sets: Vec<DescriptorSet>,
    layout: vk::PipelineLayout,
    pipeline: vk::Pipeline,
    /// The CPU reference's surface offset, 2e-5 of the scene's diagonal (world units).
    reference_offset: f32,
    /// World units this frame's rays start off the surface (and stop short of a point light):
    /// [`RayTracer::reference_offset`], or 2^-16 of the largest eye-relative coordinate if that
    /// is larger (128 f32 ulps: far above the few ulps the G-buffer's interpolated position can
    /// be off by). Set by [`RayTracer::cmd_build`] for the eye of the frame it records.
    pub offset: f32,
    /// Bytes of bottom-level storage (after compaction).
    pub blas_bytes: u64,
    /// Milliseconds (CPU wall) the bottom levels took to build, compaction included.
    pub blas_build_ms: f64,
}

/// Why `scene` cannot be traced yet, if it cannot.
pub fn unsupported(scene: &Scene) -> Option<String> {
    if scene.meshes.iter().any(|m| m.casts_shadow && m.opacity < 1.0) {
        return Some("--method rayquery does not trace transparent casters yet (their coloured shadows need the light-intensity map); use a shadow-volume method".into());
    }
    None
}

/// The diagonal of the bounds of every scene triangle (the reference's `scene_size`).
fn scene_size(scene: &Scene) -> f64 {
    let mut lo = DVec3::splat(f64::INFINITY);
    let mut hi = DVec3::splat(f64::NEG_INFINITY);
    for m in &scene.meshes {
        let b = m.world_bounds();
        if b.min.x <= b.max.x {
            lo = lo.min(b.min.as_dvec3());
            hi = hi.max(b.max.as_dvec3());
        }
    }
    for s in &scene.spheres {
        lo = lo.min(s.sphere.center - s.sphere.radius);
        hi = hi.max(s.sphere.center + s.sphere.radius);
    }
    if lo.x <= hi.x {
        (hi - lo).length()
    } else {
        1.0
    }
}

impl RayTracer {
    /// Builds the bottom levels of `scene`'s opaque casters, a top level and a descriptor set
    /// per ring slot (reading `targets`' positions and normals), and the pipeline.
    pub fn new(ctx: &Context, scene: &Scene, targets: &Targets, slots: usize) -> Result<RayTracer> {
        if let Some(why) = unsupported(scene) {
            return Err(Error::Unsupported(why));
        }
        let loader = AccelLoader::new(ctx)?;
        let mut t = RayTracer {
            loader,
            entries: Vec::new(),
            balls: None,
            no_balls: None,
            tlas: Vec::new(),
            sets: Vec::new(),
            layout: vk::PipelineLayout::null(),
            pipeline: vk::Pipeline::null(),
            reference_offset: 0.0,
            offset: 0.0,
            blas_bytes: 0,
            blas_build_ms: 0.0,
        };
        match t.build(ctx, scene, targets, slots) {
            Ok(()) => Ok(t),
            Err(e) => {
                t.destroy(ctx);
                Err(e)
            }
        }
    }

    fn build(&mut self, ctx: &Context, scene: &Scene, targets: &Targets, slots: usize) -> Result<()> {
        let start = std::time::Instant::now();
        for (i, m) in scene.meshes.iter().enumerate() {
            if !m.casts_shadow {
                continue;
            }
            let caster = Caster::new(&m.name, &m.mesh, glam::Mat4::IDENTITY)?;
            let welded = &caster.topology.mesh;
            let positions: Vec<[f32; 3]> = welded.positions.iter().map(|p| p.to_array()).collect();
            let indices = &welded.triangles;
            if indices.is_empty() {
                continue;
            }
            let blas = build_blas(ctx, &self.loader, &m.name, Geometry::Triangles { positions: &positions, indices })?;
            self.blas_bytes += blas.size;
            self.entries.push(Entry { mesh: i, blas });
        }
        let casting: Vec<&crate::geom::Sphere> = scene.spheres.iter().filter(|s| s.casts_shadow).map(|s| &s.sphere).collect();
        if let Some(first) = casting.first() {
            let origin = first.center;
            let balls: Vec<[f32; 4]> = casting
                .iter()
                .map(|s| {
                    let c = (s.center - origin).as_vec3();
                    [c.x, c.y, c.z, s.radius as f32]
                })
                .collect();
            // Each box holds its f32 ball with a margin of a few ulps (the test is exact on
            // the f32 ball; the box only has to contain it).
            let boxes: Vec<[[f32; 3]; 2]> = balls
                .iter()
                .map(|b| {
                    let r = b[3] * (1.0 + 1e-5) + 1e-30;
                    [[b[0] - r, b[1] - r, b[2] - r], [b[0] + r, b[1] + r, b[2] + r]]
                })
                .collect();
            let blas = build_blas(ctx, &self.loader, "spheres", Geometry::Aabbs(&boxes))?;
            self.blas_bytes += blas.size;
            let data: Vec<u8> = balls.iter().flatten().flat_map(|v| v.to_le_bytes()).collect();
            let buffer = match Buffer::with_data(ctx, "ray-query balls", &data, vk::BufferUsageFlags::STORAGE_BUFFER) {
                Ok(b) => b,
                Err(e) => {
                    let mut blas = blas;
                    blas.destroy(ctx, &self.loader);
                    return Err(e);
                }
            };
            self.balls = Some(Balls { blas, buffer, origin });
        }
        self.blas_build_ms = start.elapsed().as_secs_f64() * 1e3;
        let ball_buffer = match &self.balls {
            Some(b) => b.buffer.raw,
            None => {
                let b = Buffer::with_data(ctx, "ray-query no balls", &[0u8; 16], vk::BufferUsageFlags::STORAGE_BUFFER)?;
                let raw = b.raw;
                self.no_balls = Some(b);
                raw
            }
        };
        let instances = self.entries.len() as u32 + self.balls.is_some() as u32;
        for _ in 0..slots {
            self.tlas.push(Tlas::new(ctx, &self.loader, instances)?);
        }
        for tlas in &self.tlas {
            self.sets.push(DescriptorSet::new(
                ctx,
                &[
                    Binding::AccelerationStructure(tlas.accel.raw),
                    Binding::Image(targets.position.view),
                    Binding::Image(targets.normal.view),
                    Binding::StorageBuffer(ball_buffer),
                ],
            )?);
        }
        self.layout = pipeline_layout(ctx, &[self.sets[0].layout], std::mem::size_of::<Push>() as u32, vk::ShaderStageFlags::FRAGMENT)?;
        let mark = vk::StencilOpState {
            fail_op: vk::StencilOp::KEEP,
            pass_op: vk::StencilOp::REPLACE,
            depth_fail_op: vk::StencilOp::KEEP,
            compare_op: vk::CompareOp::ALWAYS,
            compare_mask: 0xff,
            write_mask: 0xff,
            reference: 1,
        };
        let mut d = PipelineDesc::new(shaders::FULLSCREEN_VERT, self.layout, ctx.depth_format);
        d.fragment = Some(shaders::RAYQUERY_WGSL);
        d.stencil = Some((mark, mark));
        self.pipeline = pipeline::create(ctx, &d)?;
        let size = scene_size(scene);
        self.reference_offset = (2e-5 * size) as f32;
        self.offset = self.reference_offset;
        Ok(())
    }

    /// Rewrites slot `slot`'s top level from the meshes' current transforms (relative to
    /// `eye`) and records its build; sets [`RayTracer::offset`] for the scene's
    /// eye-relative extent needs it.
    ///
    /// # Safety
    /// `cb` is recording outside a rendering instance, and the slot's previous frame retired.
    pub unsafe fn cmd_build(&mut self, ctx: &Context, cb: vk::CommandBuffer, slot: usize, scene: &Scene, eye: DVec3) -> Result<()> {
        let to_eye = DMat4::from_translation(-eye);
        let mut extent = 0.0f64;
        let mut instances: Vec<Instance> = self
            .entries
            .iter()
            .map(|e| {
                let m = &scene.meshes[e.mesh];
                let b = m.world_bounds();
                for c in [b.min, b.max] {
                    extent = extent.max((c.as_dvec3() - eye).abs().max_element());
                }
                let x = (to_eye * m.transform.as_dmat4()).transpose();
                let rows = [x.x_axis.as_vec4().to_array(), x.y_axis.as_vec4().to_array(), x.z_axis.as_vec4().to_array()];
                let flags = vk::GeometryInstanceFlagsKHR::TRIANGLE_FACING_CULL_DISABLE;
                Instance { transform: rows, custom: e.mesh as u32, mask: 0xff, flags, blas: e.blas.address }
            })
            .collect();
        if let Some(b) = &self.balls {
            let t = (b.origin - eye).as_vec3();
            let rows = [[1.0, 0.0, 0.0, t.x], [0.0, 1.0, 0.0, t.y], [0.0, 0.0, 1.0, t.z]];
            let flags = vk::GeometryInstanceFlagsKHR::empty();
            instances.push(Instance { transform: rows, custom: 0, mask: 0xff, flags, blas: b.blas.address });
            for s in scene.spheres.iter().filter(|s| s.casts_shadow) {
                extent = extent.max((s.sphere.center - eye).abs().max_element() + s.sphere.radius);
            }
        }
        self.offset = self.reference_offset.max((extent * 2f64.powi(-16)) as f32);
        // SAFETY: forwarded to the caller's contract.
        unsafe { self.tlas[slot].cmd_build(ctx, &self.loader, cb, &instances) }
    }

    /// Records light `light`'s determination: the stencil cleared to 0 inside `scissor`, then
    /// set to 1 where the pixel's shadow ray is blocked. `light` is the eye-relative
    /// homogeneous light (position, 1) or (direction towards the light, 0).
    ///
    /// # Safety
    /// `cb` is recording outside a rendering instance, after [`RayTracer::cmd_build`] for
    /// `slot`; the depth-stencil target is in attachment layout, the G-buffer's positions and
    /// normals in `SHADER_READ_ONLY_OPTIMAL`.
    pub unsafe fn cmd_determine(&self, rec: &super::passes::Rec, t: &Targets, slot: usize, light: [f32; 4], scissor: vk::Rect2D) {
        let d = &rec.ctx.device;
        let ds = super::passes::att(&t.depth, vk::AttachmentLoadOp::LOAD, super::passes::DS_CLEAR);
        let push = Push { light, params: [self.offset, 0.0, 0.0, 0.0] };
        // SAFETY: the caller's contract; the set's images and top level are this slot's.
        unsafe {
            rec.begin(scissor, &[], Some(&ds));
            let clear = vk::ClearAttachment {
                aspect_mask: vk::ImageAspectFlags::STENCIL,
                color_attachment: 0,
                clear_value: vk::ClearValue { depth_stencil: vk::ClearDepthStencilValue { depth: 1.0, stencil: 0 } },
            };
            d.cmd_clear_attachments(rec.cb, &[clear], &[vk::ClearRect { rect: scissor, base_array_layer: 0, layer_count: 1 }]);
            d.cmd_bind_pipeline(rec.cb, vk::PipelineBindPoint::GRAPHICS, self.pipeline);
            d.cmd_bind_descriptor_sets(rec.cb, vk::PipelineBindPoint::GRAPHICS, self.layout, 0, &[self.sets[slot].set], &[]);
            d.cmd_push_constants(rec.cb, self.layout, vk::ShaderStageFlags::FRAGMENT, 0, bytemuck::bytes_of(&push));
            d.cmd_draw(rec.cb, 3, 1, 0, 0);
            d.cmd_end_rendering(rec.cb);
        }
    }

    /// What the frame's stats say about the structures.
    pub fn stats(&self) -> super::stats::RayQueryStats {
        let levels = self.entries.len() + self.balls.is_some() as usize;
        super::stats::RayQueryStats {
            bottom_levels: levels,
            bottom_level_bytes: self.blas_bytes,
            bottom_level_build_ms: self.blas_build_ms,
            instances: levels,
            offset: self.offset,
        }
    }

    /// Destroys everything (the owner waited for the device).
    pub fn destroy(&mut self, ctx: &Context) {
        // SAFETY: the owner waited for the device to be idle; null handles are ignored.
        unsafe {
            ctx.device.destroy_pipeline(self.pipeline, None);
            ctx.device.destroy_pipeline_layout(self.layout, None);
        }
        for mut s in self.sets.drain(..) {
            s.destroy(ctx);
        }
        for mut t in self.tlas.drain(..) {
            t.destroy(ctx, &self.loader);
        }
        for mut e in self.entries.drain(..) {
            e.blas.destroy(ctx, &self.loader);
        }
        if let Some(mut b) = self.balls.take() {
            b.blas.destroy(ctx, &self.loader);
            b.buffer.destroy(ctx);
        }
        if let Some(mut b) = self.no_balls.take() {
            b.destroy(ctx);
        }
    }
}
