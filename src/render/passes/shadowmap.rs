//! The baseline users would otherwise pick: shadow mapping with 3x3 percentage-closer
//! filtering (the textbook chapter), on the same frame, measured against the same reference.
//!
//! Per light, the opaque shadow casters' depth is rendered from the light into an atlas
//! (directional: one orthographic map fitted to the casters' bounding sphere; spot: one
//! perspective map over the cone; point: six 90-degree faces, 3 x 2 tiles, all in one
//! rendering instance). Each caster mesh is drawn only into the faces whose frustum its
//! bounding sphere meets, and a point or spot light's near and far planes hug its casters.
//! One full-screen lookup pass per light then writes, for every visible point, the fraction
//! of PCF taps that see a nearer occluder into the float counter target (each point picks
//! its cube face in the shader; the comparison is a hardware compare sampler's), and the
//! counter's illumination pass lights the points whose fraction is below one half. Biases:
//! slope-scaled depth bias when rendering the map, a small compare bias, and a normal offset
//! of about a texel, the usual trade between acne and peter-panning — so unlike shadow
//! volumes, its error is not zero, and the bench says how large it is.
//!
//! Inputs / outputs per light (called by `frame/record.rs` after `determine::begin_float`, before `determine::record`):
//! - `record_maps`: writes the atlas, `UNDEFINED -> DEPTH_STENCIL_ATTACHMENT_OPTIMAL`, CLEAR (depth 1)/STORE, the opaque
//!   casters' depth; then `-> SHADER_READ_ONLY_OPTIMAL`.
//! - `record_lookup`: reads `normal` and `position` (`SHADER_READ_ONLY_OPTIMAL`, left by `gbuffer`), the atlas
//!   (`SHADER_READ_ONLY_OPTIMAL`, compare sampler) and the face table; writes `count` in `COLOR_ATTACHMENT_OPTIMAL`
//!   (set from `UNDEFINED` by `determine::begin_float`), CLEAR to 0 inside the scissor, STORE, additive; no depth-stencil
//!   attachment. `determine::finish` (`CountInto::External`) then takes `count` to `SHADER_READ_ONLY_OPTIMAL`.

use crate::error::{Error, Result};
use crate::gpu::descriptors::{pipeline_layout, Binding, DescriptorSet};
use crate::gpu::pipeline::{self, Blend, PipelineDesc};
use crate::gpu::resources::{memory_barrier, transition};
use crate::gpu::{shaders, Buffer, Context, Image};
use crate::render::targets::{Targets, COUNT_FORMAT};
use crate::render::Pcf;
use crate::scene::{Camera, LightKind, Scene};
use ash::vk;
use glam::{DVec3, Mat4, Vec3, Vec4};

/// The shadow maps' depth format.
pub const MAP_FORMAT: vk::Format = vk::Format::D32_SFLOAT;

/// One caster mesh's vertices in the casters' buffer and its eye-relative bounding sphere
/// (per-face culling).
#[derive(Clone, Copy, Debug)]
struct MeshRange {
    first: u32,
    count: u32,
    center: DVec3,
    radius: f64,
}

/// The shadow-map baseline's GPU objects.
pub struct ShadowMapper {
    /// Texels per side of one map (a point light uses 3 x 2 of them).
    pub size: u32,
    atlas: Image,
    casters: Option<Buffer>,
    meshes: Vec<MeshRange>,
    /// Casters' bounding sphere, eye-relative.
    bounds: (DVec3, f64),
    /// The lookup's face table (`shadowmap_lookup.frag`'s `Faces`), updated per light in the
    /// command buffer.
    faces: Buffer,
    compare_sampler: vk::Sampler,
    set: DescriptorSet,
    layouts: [vk::PipelineLayout; 2],
    map_pipeline: vk::Pipeline,
    /// The lookup's pipelines: nine taps (`shadowmap_lookup.frag`), four gathers
    /// (`shadowmap_gather.wgsl`).
    lookup_pipelines: [vk::Pipeline; 2],
}

/// One light's lookup: where the light is, the pass's scissor, how the taps are read.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Lookup {
    /// The frame's eye-relative light ([`LightPush::light_pos`](crate::render::push::LightPush)).
    pub light_pos: [f32; 4],
    /// The light's scissor: the pass's render area.
    pub scissor: vk::Rect2D,
    /// Nine taps or four gathers (the same result).
    pub pcf: Pcf,
}

/// `shadowmap_lookup.frag`'s `Face` (std430).
#[repr(C)]
#[derive(Clone, Copy, Default, bytemuck::Pod, bytemuck::Zeroable)]
struct FaceRow {
    /// Eye-relative world -> this face's clip space.
    view_proj: [f32; 16],
    /// Atlas tile: x0, y0, width, height (texels).
    tile: [f32; 4],
    /// x: unused, y: compare bias, z: normal offset.
    params: [f32; 4],
}

/// The face table's size: six faces.
const FACES_BYTES: u64 = 6 * std::mem::size_of::<FaceRow>() as u64;

/// `shadowmap_lookup.frag`'s push constants.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct LookupPush {
    /// Eye-relative light position (w = 1) or towards-light direction (w = 0).
    light: [f32; 4],
    /// x: faces (1 or 6), y, z: 1 / atlas width, height.
    params: [f32; 4],
}

/// One light's rendered maps, for [`ShadowMapper::record_lookup`].
pub(crate) struct LightMaps {
    faces: Vec<Face>,
}

/// One map to render and look up: the eye-relative light view-projection and its atlas tile.
struct Face {
    view_proj: Mat4,
    tile: [u32; 2],
    /// World size of one texel near the casters (for the normal offset).
    texel_world: f32,
}

/// The objects `ShadowMapper::new` made so far, released if a later step fails.
#[derive(Default)]
struct Partial {
    buffers: Vec<Buffer>,
    images: Vec<Image>,
    sampler: Option<vk::Sampler>,
    set: Option<DescriptorSet>,
    layouts: Vec<vk::PipelineLayout>,
    pipelines: Vec<vk::Pipeline>,
}

impl Partial {
    fn release(mut self, ctx: &Context) {
        // SAFETY: nothing was submitted with these objects yet.
        unsafe {
            for p in self.pipelines.drain(..) {
                ctx.device.destroy_pipeline(p, None);
            }
            for l in self.layouts.drain(..) {
                ctx.device.destroy_pipeline_layout(l, None);
            }
            if let Some(s) = self.sampler.take() {
                ctx.device.destroy_sampler(s, None);
            }
        }
        if let Some(mut s) = self.set.take() {
            s.destroy(ctx);
        }
        for mut b in self.buffers.drain(..) {
            b.destroy(ctx);
        }
        for mut i in self.images.drain(..) {
            i.destroy(ctx);
        }
    }
}

impl ShadowMapper {
    /// Maps of `size` texels a side (16..=8192) for the scene's opaque casters, as placed now
    /// relative to the camera (rebuilt by the renderer when either moves).
    pub fn new(ctx: &Context, scene: &Scene, targets: &Targets, size: u32, sampler: vk::Sampler) -> Result<ShadowMapper> {
        if !(16..=8192).contains(&size) {
            return Err(Error::Other(format!("shadow map size {size} out of range (16..=8192)")));
        }
        let mut partial = Partial::default();
        match Self::build(ctx, scene, targets, size, sampler, &mut partial) {
            Ok(m) => Ok(m),
            Err(e) => {
                partial.release(ctx);
                Err(e)
            }
        }
    }

    fn build(ctx: &Context, scene: &Scene, targets: &Targets, size: u32, sampler: vk::Sampler, made: &mut Partial) -> Result<ShadowMapper> {
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
        if let Some(b) = casters {
            made.buffers.push(b);
        }
        let faces = Buffer::new(
            ctx,
            "shadow-map faces",
            FACES_BYTES,
            vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::TRANSFER_DST,
            gpu_allocator::MemoryLocation::GpuOnly,
        )?;
        let faces_raw = faces.raw;
        made.buffers.push(faces);
        let atlas = Image::new_2d(
            ctx,
            "shadow-map atlas",
            MAP_FORMAT,
            vk::Extent2D { width: 3 * size, height: 2 * size },
            vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT | vk::ImageUsageFlags::SAMPLED,
            vk::ImageAspectFlags::DEPTH,
        )?;
        let atlas_view = atlas.view;
        made.images.push(atlas);
        // Nearest filtering: each tap is one texel's comparison, as the textbook's PCF.
        let info = vk::SamplerCreateInfo::default()
            .mag_filter(vk::Filter::NEAREST)
            .min_filter(vk::Filter::NEAREST)
            .address_mode_u(vk::SamplerAddressMode::CLAMP_TO_EDGE)
            .address_mode_v(vk::SamplerAddressMode::CLAMP_TO_EDGE)
            .compare_enable(true)
            .compare_op(vk::CompareOp::LESS_OR_EQUAL);
        // SAFETY: creation on a valid device; released by `made` or `destroy`.
        let compare_sampler = unsafe { ctx.device.create_sampler(&info, None) }.map_err(Error::vk("vkCreateSampler"))?;
        made.sampler = Some(compare_sampler);
        let set = DescriptorSet::new(
            ctx,
            &[
                Binding::Image(targets.albedo.view),
                Binding::Image(targets.normal.view),
                Binding::Image(targets.position.view),
                Binding::Sampler(sampler),
                Binding::Image(targets.count.view),
                Binding::Image(targets.transmit.view),
                Binding::Image(atlas_view),
                Binding::Sampler(compare_sampler),
                Binding::StorageBuffer(faces_raw),
            ],
        )?;
        let set_layout = set.layout;
        made.set = Some(set);
        made.layouts.push(pipeline_layout(ctx, &[], 64, vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT)?);
        made.layouts.push(pipeline_layout(ctx, &[set_layout], std::mem::size_of::<LookupPush>() as u32, vk::ShaderStageFlags::FRAGMENT)?);
        let layouts = [made.layouts[0], made.layouts[1]];
        let mut m = PipelineDesc::new(shaders::SHADOWMAP_VERT, layouts[0], MAP_FORMAT);
        m.vertex_stride = 12;
        m.attributes = &[(0, vk::Format::R32G32B32_SFLOAT, 0)];
        m.depth_test = true;
        m.depth_write = true;
        m.depth_compare = vk::CompareOp::LESS;
        m.depth_bias = Some((1.25, 1.75));
        made.pipelines.push(pipeline::create(ctx, &m)?);
        let count = [COUNT_FORMAT];
        let mut l = PipelineDesc::new(shaders::FULLSCREEN_VERT, layouts[1], vk::Format::UNDEFINED);
        l.fragment = Some(shaders::SHADOWMAP_LOOKUP_FRAG);
        l.color_formats = &count;
        l.blend = Blend::Additive;
        made.pipelines.push(pipeline::create(ctx, &l)?);
        l.fragment = Some(shaders::SHADOWMAP_GATHER_WGSL);
        made.pipelines.push(pipeline::create(ctx, &l)?);
        // Everything made: hand the objects over.
        let (map_pipeline, lookup_pipelines) = (made.pipelines[0], [made.pipelines[1], made.pipelines[2]]);
        made.pipelines.clear();
        made.layouts.clear();
        made.sampler = None;
        let set = made.set.take().ok_or_else(|| Error::Other("shadow-map set".into()))?;
        let atlas = made.images.pop().ok_or_else(|| Error::Other("shadow-map atlas".into()))?;
        let faces = made.buffers.pop().ok_or_else(|| Error::Other("shadow-map faces".into()))?;
        let casters = made.buffers.pop();
        Ok(ShadowMapper { size, atlas, casters, meshes, bounds, faces, compare_sampler, set, layouts, map_pipeline, lookup_pipelines })
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
                vec![Face { view_proj: ortho * cam.view(), tile: [0, 0], texel_world: (2.0 * r / s) as f32 }]
            }
            LightKind::Spot | LightKind::Point => {
                let l = rel(light.position).as_dvec3();
                // Near and far hug the casters: the nearest and farthest caster spheres.
                let (mut near_c, mut far_c) = (f64::INFINITY, 0.0f64);
                for m in &self.meshes {
                    let d = (m.center - l).length();
                    near_c = near_c.min(d - m.radius);
                    far_c = far_c.max(d + m.radius);
                }
                let far = if far_c > 0.0 { far_c * 1.01 } else { ((l - c).length() + r) * 1.01 };
                let near = (0.9 * near_c).max(far * 1e-4).max(1e-4);
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
                        Face { view_proj: cam.proj_finite(1.0, far as f32) * cam.view(), tile, texel_world }
                    })
                    .collect()
            }
        }
    }

    /// Renders light `light`'s maps into the atlas (one rendering instance, each caster mesh
    /// only into the faces it can be seen in) and returns the faces for
    /// [`ShadowMapper::record_lookup`]. Leaves the atlas in SHADER_READ_ONLY_OPTIMAL.
    pub(crate) fn record_maps(&self, ctx: &Context, cb: vk::CommandBuffer, light: &crate::scene::Light, eye: DVec3) -> LightMaps {
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
        // The tiles in use only (a single map uses one of the six).
        let area = match faces.len() {
            1 => vk::Rect2D { offset: vk::Offset2D { x: 0, y: 0 }, extent: vk::Extent2D { width: self.size, height: self.size } },
            _ => full,
        };
        // SAFETY: `cb` is recording outside any rendering instance; every handle is alive.
        unsafe {
            d.cmd_begin_rendering(cb, &vk::RenderingInfo::default().render_area(area).layer_count(1).depth_attachment(&map_att));
            if let Some(b) = &self.casters {
                d.cmd_bind_pipeline(cb, vk::PipelineBindPoint::GRAPHICS, self.map_pipeline);
                d.cmd_bind_vertex_buffers(cb, 0, &[b.raw], &[0]);
                for f in &faces {
                    let visible: Vec<&MeshRange> =
                        self.meshes.iter().filter(|m| sphere_in_frustum(&f.view_proj, m.center, m.radius)).collect();
                    if visible.is_empty() {
                        continue;
                    }
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
                    for m in visible {
                        d.cmd_draw(cb, m.count, 1, m.first, 0);
                    }
                }
            }
            d.cmd_end_rendering(cb);
        }
        transition(ctx, cb, &self.atlas, vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL, vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL);
        LightMaps { faces }
    }

    /// Writes a light's shadow fractions into `targets.count` (which must be in
    /// COLOR_ATTACHMENT_OPTIMAL; it is left there) from the maps [`ShadowMapper::record_maps`]
    /// rendered for that light: one full-screen pass inside `lookup.scissor`.
    pub(crate) fn record_lookup(&self, ctx: &Context, cb: vk::CommandBuffer, targets: &Targets, maps: &LightMaps, lookup: Lookup) {
        let Lookup { light_pos, scissor, pcf } = lookup;
        let pipeline = match pcf {
            Pcf::Taps => self.lookup_pipelines[0],
            Pcf::Gather => self.lookup_pipelines[1],
        };
        let faces = &maps.faces;
        let d = &ctx.device;
        let mut rows = [FaceRow::default(); 6];
        for (row, f) in rows.iter_mut().zip(faces) {
            *row = FaceRow {
                view_proj: f.view_proj.to_cols_array(),
                tile: [f.tile[0] as f32, f.tile[1] as f32, self.size as f32, self.size as f32],
                params: [0.0, 2e-5, 1.5 * f.texel_world, 0.0],
            };
        }
        let count_att = [vk::RenderingAttachmentInfo::default()
            .image_view(targets.count.view)
            .image_layout(vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL)
            .load_op(vk::AttachmentLoadOp::CLEAR)
            .store_op(vk::AttachmentStoreOp::STORE)
            .clear_value(vk::ClearValue { color: vk::ClearColorValue { float32: [0.0; 4] } })];
        let (aw, ah) = (self.atlas.extent.width as f32, self.atlas.extent.height as f32);
        let push = LookupPush { light: light_pos, params: [faces.len() as f32, 1.0 / aw, 1.0 / ah, 0.0] };
        let (w, h) = (targets.extent.width as f32, targets.extent.height as f32);
        let shader_read = (vk::PipelineStageFlags2::FRAGMENT_SHADER, vk::AccessFlags2::SHADER_STORAGE_READ);
        let transfer_write = (vk::PipelineStageFlags2::ALL_TRANSFER, vk::AccessFlags2::TRANSFER_WRITE);
        // SAFETY: as `record_maps`; the face table is written outside a rendering instance,
        // after the previous light's lookup finished reading it, and read after the write.
        unsafe {
            memory_barrier(ctx, cb, shader_read, transfer_write);
            d.cmd_update_buffer(cb, self.faces.raw, 0, bytemuck::cast_slice(&rows));
            memory_barrier(ctx, cb, transfer_write, shader_read);
            d.cmd_begin_rendering(cb, &vk::RenderingInfo::default().render_area(scissor).layer_count(1).color_attachments(&count_att));
            d.cmd_set_viewport(cb, 0, &[vk::Viewport { x: 0.0, y: 0.0, width: w, height: h, min_depth: 0.0, max_depth: 1.0 }]);
            d.cmd_set_scissor(cb, 0, &[scissor]);
            d.cmd_bind_pipeline(cb, vk::PipelineBindPoint::GRAPHICS, pipeline);
            d.cmd_bind_descriptor_sets(cb, vk::PipelineBindPoint::GRAPHICS, self.layouts[1], 0, &[self.set.set], &[]);
            d.cmd_push_constants(cb, self.layouts[1], vk::ShaderStageFlags::FRAGMENT, 0, bytemuck::bytes_of(&push));
            d.cmd_draw(cb, 3, 1, 0, 0);
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
            for p in self.lookup_pipelines {
                d.destroy_pipeline(p, None);
            }
            for l in self.layouts {
                d.destroy_pipeline_layout(l, None);
            }
            d.destroy_sampler(self.compare_sampler, None);
        }
        self.set.destroy(ctx);
        self.atlas.destroy(ctx);
        self.faces.destroy(ctx);
        if let Some(mut b) = self.casters.take() {
            b.destroy(ctx);
        }
    }
}

/// Whether a sphere (eye-relative centre, radius) meets the frustum of a Vulkan clip matrix
/// (0 <= z <= w): its distance to each of the six planes.
fn sphere_in_frustum(m: &Mat4, c: DVec3, r: f64) -> bool {
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
