//! The baseline users would otherwise pick: shadow mapping with 3x3 percentage-closer
//! filtering (the textbook chapter), on the same frame, measured against the same reference.
//!
//! Per light, the opaque shadow casters' depth is rendered from the light into an atlas
//! (directional: one orthographic map fitted to the casters' bounding sphere; spot: one
//! perspective map over the cone; point: six 90-degree faces, 3 x 2 tiles). A full-screen
//! lookup pass then writes, for every visible point, the fraction of PCF taps that see a nearer
//! occluder into the float counter target, and the counter's illumination pass lights the
//! points whose fraction is below one half. Biases: slope-scaled depth bias when rendering the
//! map, a small compare bias, and a normal offset of about a texel, the usual trade between
//! acne and peter-panning — so unlike shadow volumes, its error is not zero, and the bench says
//! how large it is.

use crate::error::{Error, Result};
use crate::gpu::descriptors::{pipeline_layout, Binding, DescriptorSet};
use crate::gpu::pipeline::{self, Blend, PipelineDesc};
use crate::gpu::resources::{memory_barrier, transition};
use crate::gpu::{shaders, Buffer, Context, Image};
use crate::render::targets::{Targets, COUNT_FORMAT};
use crate::scene::{Camera, LightKind, Scene};
use ash::vk;
use glam::{DVec3, Mat4, Vec3, Vec4};

/// The shadow maps' depth format.
pub const MAP_FORMAT: vk::Format = vk::Format::D32_SFLOAT;

/// The shadow-map baseline's GPU objects.
pub struct ShadowMapper {
    /// Texels per side of one map (a point light uses 3 x 2 of them).
    pub size: u32,
    atlas: Image,
    casters: Option<Buffer>,
    caster_vertices: u32,
    /// Casters' bounding sphere, eye-relative.
    bounds: (DVec3, f64),
    set: DescriptorSet,
    layouts: [vk::PipelineLayout; 2],
    map_pipeline: vk::Pipeline,
    lookup_pipeline: vk::Pipeline,
}

/// `shadowmap_lookup.frag`: `{ mat4 light_view_proj; vec4 tile; vec4 light; vec4 params; }`.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct LookupPush {
    /// Eye-relative world -> this face's clip space.
    light_view_proj: [f32; 16],
    /// Atlas tile: x0, y0, width, height (texels).
    tile: [f32; 4],
    /// Eye-relative light position (w = 1) or towards-light direction (w = 0).
    light: [f32; 4],
    /// x: face (0..5, -1 = single map), y: compare bias, z: normal offset.
    params: [f32; 4],
}

/// One map to render and look up: the eye-relative light view-projection, its atlas tile,
/// and the cube face it stands for (-1 for a single map).
struct Face {
    view_proj: Mat4,
    tile: [u32; 2],
    face: f32,
    /// World size of one texel near the casters (for the normal offset).
    texel_world: f32,
}

impl ShadowMapper {
    /// Maps of `size` texels a side (16..=8192) for the scene's opaque casters, as placed now
    /// relative to the camera (rebuilt by the renderer when either moves).
    pub fn new(ctx: &Context, scene: &Scene, targets: &Targets, size: u32, sampler: vk::Sampler) -> Result<ShadowMapper> {
        if !(16..=8192).contains(&size) {
            return Err(Error::Other(format!("shadow map size {size} out of range (16..=8192)")));
        }
        let eye = scene.camera.eye.as_dvec3();
        let mut pos: Vec<[f32; 3]> = Vec::new();
        let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
        for m in scene.meshes.iter().filter(|m| m.casts_shadow && m.opacity >= 1.0) {
            let xf = m.transform.as_dmat4();
            for t in 0..m.mesh.triangles.len() {
                for v in m.mesh.triangle(t) {
                    let r = xf.transform_point3(v.as_dvec3()) - eye;
                    lo = lo.min(r);
                    hi = hi.max(r);
                    pos.push(r.as_vec3().to_array());
                }
            }
        }
        let bounds = if pos.is_empty() { (DVec3::ZERO, 1.0) } else { ((lo + hi) * 0.5, ((hi - lo) * 0.5).length().max(1e-6)) };
        let casters = if pos.is_empty() {
            None
        } else {
            let mut b = Buffer::new(
                ctx,
                "shadow-map casters",
                (pos.len() * 12) as u64,
                vk::BufferUsageFlags::VERTEX_BUFFER,
                gpu_allocator::MemoryLocation::CpuToGpu,
            )?;
            if let Err(e) = b.write(0, bytemuck::cast_slice(&pos)) {
                b.destroy(ctx);
                return Err(e);
            }
            Some(b)
        };
        let atlas = Image::new_2d(
            ctx,
            "shadow-map atlas",
            MAP_FORMAT,
            vk::Extent2D { width: 3 * size, height: 2 * size },
            vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT | vk::ImageUsageFlags::SAMPLED,
            vk::ImageAspectFlags::DEPTH,
        );
        let atlas = match atlas {
            Ok(a) => a,
            Err(e) => {
                if let Some(mut b) = casters {
                    b.destroy(ctx);
                }
                return Err(e);
            }
        };
        let set = DescriptorSet::new(
            ctx,
            &[
                Binding::Image(targets.albedo.view),
                Binding::Image(targets.normal.view),
                Binding::Image(targets.position.view),
                Binding::Sampler(sampler),
                Binding::Image(targets.count.view),
                Binding::Image(targets.transmit.view),
                Binding::Image(atlas.view),
            ],
        )?;
        let layouts = [
            pipeline_layout(ctx, &[], 64, vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT)?,
            pipeline_layout(ctx, &[set.layout], 112, vk::ShaderStageFlags::FRAGMENT)?,
        ];
        let mut m = PipelineDesc::new(shaders::SHADOWMAP_VERT, layouts[0], MAP_FORMAT);
        m.vertex_stride = 12;
        m.attributes = &[(0, vk::Format::R32G32B32_SFLOAT, 0)];
        m.depth_test = true;
        m.depth_write = true;
        m.depth_compare = vk::CompareOp::LESS;
        m.depth_bias = Some((1.25, 1.75));
        let map_pipeline = pipeline::create(ctx, &m)?;
        let count = [COUNT_FORMAT];
        let mut l = PipelineDesc::new(shaders::FULLSCREEN_VERT, layouts[1], vk::Format::UNDEFINED);
        l.fragment = Some(shaders::SHADOWMAP_LOOKUP_FRAG);
        l.color_formats = &count;
        l.blend = Blend::Additive;
        let lookup_pipeline = pipeline::create(ctx, &l)?;
        Ok(ShadowMapper { size, atlas, caster_vertices: pos.len() as u32, casters, bounds, set, layouts, map_pipeline, lookup_pipeline })
    }

    /// The maps one light needs, in eye-relative coordinates.
    fn faces(&self, light: &crate::scene::Light, eye: DVec3) -> Vec<Face> {
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
                vec![Face { view_proj: ortho * cam.view(), tile: [0, 0], face: -1.0, texel_world: (2.0 * r / s) as f32 }]
            }
            LightKind::Spot | LightKind::Point => {
                let l = rel(light.position).as_dvec3();
                let far = ((l - c).length() + r) * 1.01;
                let near = (far * 1e-4).max(1e-4);
                let dist = (l - c).length().max(near);
                let dirs: Vec<(DVec3, f64, f32)> = if light.kind == LightKind::Spot {
                    vec![(light.direction.as_dvec3().normalize(), (light.cone_deg as f64 + 2.0).min(170.0), -1.0)]
                } else {
                    [DVec3::X, DVec3::NEG_X, DVec3::Y, DVec3::NEG_Y, DVec3::Z, DVec3::NEG_Z]
                        .into_iter()
                        .enumerate()
                        .map(|(i, d)| (d, 90.0, i as f32))
                        .collect()
                };
                dirs.into_iter()
                    .map(|(d, fov, face)| {
                        let cam =
                            Camera { eye: l.as_vec3(), target: (l + d).as_vec3(), up: any_up(d), fov_y_deg: fov as f32, near: near as f32 };
                        let tile = if face < 0.0 { [0, 0] } else { [(face as u32 % 3) * self.size, (face as u32 / 3) * self.size] };
                        let texel_world = (2.0 * dist * (fov.to_radians() * 0.5).tan() / s) as f32;
                        Face { view_proj: cam.proj_finite(1.0, far as f32) * cam.view(), tile, face, texel_world }
                    })
                    .collect()
            }
        }
    }

    /// Renders light `light`'s maps and writes its shadow fractions into `targets.count`
    /// (which must be in COLOR_ATTACHMENT_OPTIMAL; it is left there).
    pub fn record(
        &self,
        ctx: &Context,
        cb: vk::CommandBuffer,
        targets: &Targets,
        light: &crate::scene::Light,
        eye: DVec3,
        scissor: vk::Rect2D,
    ) {
        let d = &ctx.device;
        let faces = self.faces(light, eye);
        let full = vk::Rect2D { offset: vk::Offset2D { x: 0, y: 0 }, extent: self.atlas.extent };
        transition(ctx, cb, &self.atlas, vk::ImageLayout::UNDEFINED, vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL);
        let map_att = vk::RenderingAttachmentInfo::default()
            .image_view(self.atlas.view)
            .image_layout(vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL)
            .load_op(vk::AttachmentLoadOp::CLEAR)
            .store_op(vk::AttachmentStoreOp::STORE)
            .clear_value(vk::ClearValue { depth_stencil: vk::ClearDepthStencilValue { depth: 1.0, stencil: 0 } });
        // SAFETY: `cb` is recording outside any rendering instance; every handle is alive.
        unsafe {
            d.cmd_begin_rendering(cb, &vk::RenderingInfo::default().render_area(full).layer_count(1).depth_attachment(&map_att));
            if let Some(b) = &self.casters {
                d.cmd_bind_pipeline(cb, vk::PipelineBindPoint::GRAPHICS, self.map_pipeline);
                d.cmd_bind_vertex_buffers(cb, 0, &[b.raw], &[0]);
                for f in &faces {
                    let sz = self.size as f32;
                    let vp =
                        vk::Viewport { x: f.tile[0] as f32, y: f.tile[1] as f32, width: sz, height: sz, min_depth: 0.0, max_depth: 1.0 };
                    let sc = vk::Rect2D {
                        offset: vk::Offset2D { x: f.tile[0] as i32, y: f.tile[1] as i32 },
                        extent: vk::Extent2D { width: self.size, height: self.size },
                    };
                    d.cmd_set_viewport(cb, 0, &[vp]);
                    d.cmd_set_scissor(cb, 0, &[sc]);
                    d.cmd_push_constants(
                        cb,
                        self.layouts[0],
                        vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT,
                        0,
                        bytemuck::bytes_of(&f.view_proj.to_cols_array()),
                    );
                    d.cmd_draw(cb, self.caster_vertices, 1, 0, 0);
                }
            }
            d.cmd_end_rendering(cb);
        }
        transition(ctx, cb, &self.atlas, vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL, vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL);

        // Lookup into the float counter.
        let count_att = [vk::RenderingAttachmentInfo::default()
            .image_view(targets.count.view)
            .image_layout(vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL)
            .load_op(vk::AttachmentLoadOp::CLEAR)
            .store_op(vk::AttachmentStoreOp::STORE)
            .clear_value(vk::ClearValue { color: vk::ClearColorValue { float32: [0.0; 4] } })];
        let light_h = match light.kind {
            LightKind::Directional => (-light.direction.normalize()).extend(0.0),
            _ => (light.position.as_dvec3() - eye).as_vec3().extend(1.0),
        };
        let (w, h) = (targets.extent.width as f32, targets.extent.height as f32);
        // SAFETY: as above; the atlas was transitioned for sampling, the G-buffer is in
        // SHADER_READ_ONLY (the caller's invariant during the per-light loop).
        unsafe {
            d.cmd_begin_rendering(cb, &vk::RenderingInfo::default().render_area(scissor).layer_count(1).color_attachments(&count_att));
            d.cmd_set_viewport(cb, 0, &[vk::Viewport { x: 0.0, y: 0.0, width: w, height: h, min_depth: 0.0, max_depth: 1.0 }]);
            d.cmd_set_scissor(cb, 0, &[scissor]);
            d.cmd_bind_pipeline(cb, vk::PipelineBindPoint::GRAPHICS, self.lookup_pipeline);
            d.cmd_bind_descriptor_sets(cb, vk::PipelineBindPoint::GRAPHICS, self.layouts[1], 0, &[self.set.set], &[]);
            for f in &faces {
                let push = LookupPush {
                    light_view_proj: f.view_proj.to_cols_array(),
                    tile: [f.tile[0] as f32, f.tile[1] as f32, self.size as f32, self.size as f32],
                    light: light_h.to_array(),
                    params: [f.face, 2e-5, 1.5 * f.texel_world, 0.0],
                };
                d.cmd_push_constants(cb, self.layouts[1], vk::ShaderStageFlags::FRAGMENT, 0, bytemuck::bytes_of(&push));
                d.cmd_draw(cb, 3, 1, 0, 0);
            }
            d.cmd_end_rendering(cb);
        }
        // The next light's map pass overwrites the atlas the lookup just read.
        memory_barrier(
            ctx,
            cb,
            (vk::PipelineStageFlags2::FRAGMENT_SHADER, vk::AccessFlags2::SHADER_SAMPLED_READ),
            (
                vk::PipelineStageFlags2::EARLY_FRAGMENT_TESTS | vk::PipelineStageFlags2::LATE_FRAGMENT_TESTS,
                vk::AccessFlags2::DEPTH_STENCIL_ATTACHMENT_WRITE,
            ),
        );
    }

    /// Destroys the atlas, pipelines and buffers (the owner waited for the device).
    pub fn destroy(&mut self, ctx: &Context) {
        // SAFETY: the owner waited for the device to be idle.
        unsafe {
            let d = &ctx.device;
            d.destroy_pipeline(self.map_pipeline, None);
            d.destroy_pipeline(self.lookup_pipeline, None);
            for l in self.layouts {
                d.destroy_pipeline_layout(l, None);
            }
        }
        self.set.destroy(ctx);
        self.atlas.destroy(ctx);
        if let Some(mut b) = self.casters.take() {
            b.destroy(ctx);
        }
    }
}

/// An up vector not parallel to `d`.
fn any_up(d: DVec3) -> Vec3 {
    if d.y.abs() > 0.9 {
        Vec3::Z
    } else {
        Vec3::Y
    }
}
