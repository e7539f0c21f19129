//! The renderer: owns the Vulkan context, the scene's GPU buffers, the GPU-resident casters
//! and the pipelines, and records one frame per [`Renderer::render`].

use super::options::*;
use super::stats::*;
use super::targets::*;
use crate::error::{Error, Result};
use crate::gpu::descriptors::{pipeline_layout, Binding, DescriptorSet};
use crate::gpu::pipeline::{self, Blend, PipelineDesc};
use crate::gpu::resources::{memory_barrier, transition};
use crate::gpu::{shaders, Buffer, Context};
use crate::scene::{LightKind, Scene};
use crate::shadow::{self, Case, Caster, LightPlan, PlanInput};
use ash::vk;
use glam::{DMat4, DVec3, Mat4, Vec3, Vec4};
use gpu_allocator::MemoryLocation;
use std::time::Instant;

// --self-shadow: partial self-shadowing of transparent casters (a child module, so that it
// records with the renderer's private state).
#[path = "selfshadow.rs"]
mod selfshadow;

fn vkerr(call: &'static str) -> impl Fn(vk::Result) -> Error {
    Error::vk(call)
}

/// What a frame produced.
pub struct FrameOutput {
    pub width: u32,
    pub height: u32,
    /// sRGB RGBA8, row-major from the top-left.
    pub color: Vec<u8>,
    /// Per light: stencil count after its determination (captured frames only; with the float
    /// counter, the exact count clamped to 0..=255).
    pub stencil: Vec<Vec<u8>>,
    /// Per light: the exact signed count (float counter, captured frames only).
    pub counts: Vec<Vec<i32>>,
    /// Per light: the transparent casters' light fraction reaching each pixel (scenes with
    /// transparent casters, captured frames only).
    pub transmit: Vec<Vec<[f32; 3]>>,
    /// World position per pixel (NaN for background), captured frames only.
    pub positions: Vec<[f32; 3]>,
    /// Geometric face normal per pixel (NaN for background), captured frames only.
    pub normals: Vec<[f32; 3]>,
    pub stats: Stats,
}

impl FrameOutput {
    /// Per light: 255 where the light reaches the pixel (stencil count zero and the surface
    /// faces the light), 0 where it does not, 128 for background. Captured frames only.
    pub fn shadow_masks(&self, scene: &Scene) -> Vec<Vec<u8>> {
        scene
            .lights
            .iter()
            .enumerate()
            .map(|(k, light)| {
                let l = light.homogeneous();
                (0..(self.width * self.height) as usize)
                    .map(|i| {
                        let p = Vec3::from(self.positions[i]);
                        let n = Vec3::from(self.normals[i]);
                        if !p.x.is_finite() {
                            return 128;
                        }
                        let to_light = if l.w == 0.0 { l.truncate() } else { l.truncate() - p };
                        let faces = n.dot(to_light) > 0.0;
                        // The light reaches the point at all: within its range and its cone.
                        let in_range = light.radius.map(|r| l.w == 0.0 || to_light.length() < r).unwrap_or(true);
                        let in_cone = light.kind != LightKind::Spot
                            || (-to_light.normalize()).dot(light.direction.normalize()) > (light.cone_deg.to_radians() * 0.5).cos();
                        let count = match self.counts.get(k) {
                            Some(c) => c[i],
                            None => self.stencil.get(k).map(|s| s[i] as i32).unwrap_or(0),
                        };
                        if faces && in_range && in_cone && count == 0 {
                            255
                        } else {
                            0
                        }
                    })
                    .collect()
            })
            .collect()
    }
}

impl FrameOutput {
    /// Per light, per pixel: the RGB fraction of the light that reaches the visible surface:
    /// 0 where an opaque caster shadows it (or it faces away, or is out of range / cone), the
    /// transparent casters' transmittance otherwise (1 without them); NaN for background.
    pub fn light_fractions(&self, scene: &Scene) -> Vec<Vec<[f32; 3]>> {
        self.shadow_masks(scene)
            .iter()
            .enumerate()
            .map(|(k, mask)| {
                mask.iter()
                    .enumerate()
                    .map(|(i, &m)| match m {
                        128 => [f32::NAN; 3],
                        0 => [0.0; 3],
                        _ => self.transmit.get(k).map(|t| t[i]).unwrap_or([1.0; 3]),
                    })
                    .collect()
            })
            .collect()
    }
}

/// A caster's static edge-quad geometry (u32 indices: faces first, then quads).
struct EdgeQuadGpu {
    vertices: Buffer,
    indices: Buffer,
    face_indices: u32,
    quad_indices: u32,
}

/// A caster chunk on the GPU: the dual-length vertex buffer (n x (xyz,1) then n x (xyz,0)).
struct GpuChunk {
    vertices: Buffer,
}

struct Pipelines {
    gbuffer: vk::Pipeline,
    gbuffer_two_sided: vk::Pipeline,
    zpass: vk::Pipeline,
    zfail: vk::Pipeline,
    zfail_cap: vk::Pipeline,
    count_zpass: vk::Pipeline,
    count_zfail: vk::Pipeline,
    count_cap: vk::Pipeline,
    eq_faces: vk::Pipeline,
    eq_sides: vk::Pipeline,
    eq_faces_count: vk::Pipeline,
    eq_sides_count: vk::Pipeline,
    illuminate: vk::Pipeline,
    illuminate_count: vk::Pipeline,
    illuminate_t: vk::Pipeline,
    illuminate_count_t: vk::Pipeline,
    /// [multiplicative, log] x [z-pass, z-fail] into the light-intensity map.
    transmit: [[vk::Pipeline; 2]; 2],
    transparent_over: vk::Pipeline,
    transparent_light: vk::Pipeline,
    volumes: vk::Pipeline,
    tonemap: vk::Pipeline,
}

pub struct Renderer {
    pub scene: Scene,
    pub opts: RenderOptions,
    casters: Vec<Caster>,
    /// Per caster, its number of connected shells (for the stencil-overflow warning).
    shells: Vec<usize>,
    /// Some caster is transparent: the light-intensity map pass runs.
    has_transparent: bool,
    /// Per caster, its static edge-quad geometry (closed opaque casters; built on first use).
    edge_quads: Vec<Option<EdgeQuadGpu>>,
    /// The shadow-map baseline, created on the first frame that asks for it.
    shadow_mapper: Option<super::shadowmap::ShadowMapper>,
    /// Per caster (same order as `casters`), its chunks' GPU buffers.
    gpu_casters: Vec<Vec<GpuChunk>>,
    scene_vertices: Buffer,
    scene_vertex_count: u32,
    /// The first `one_sided_count` scene vertices belong to closed outward meshes.
    one_sided_count: u32,
    /// Opaque vertices (one- and two-sided) come first; transparent meshes' after them.
    opaque_count: u32,
    targets: Targets,
    layouts: [vk::PipelineLayout; 5],
    sets: [DescriptorSet; 2],
    sampler: vk::Sampler,
    pipes: Pipelines,
    /// `--self-shadow` on a scene with transparent casters.
    self_shadow: Option<selfshadow::SelfShadow>,
    stream: Option<Buffer>,
    readback: Vec<Buffer>,
    query_pool: vk::QueryPool,
    cmd: vk::CommandBuffer,
    fence: vk::Fence,
    // Last so it drops after everything above has been destroyed in `Drop`.
    pub ctx: Context,
}

const MAX_TIMESTAMPS: u32 = 256;
const TS_BEGIN: u32 = 0;
const TS_DEPTH: u32 = 1;
const TS_END: u32 = 2;

fn bytes_of<T: Copy>(v: &[T]) -> &[u8] {
    // SAFETY: T is a plain-old-data type (f32 arrays / integers) with no padding; the slice is
    // viewed as bytes for upload only.
    unsafe { std::slice::from_raw_parts(v.as_ptr() as *const u8, std::mem::size_of_val(v)) }
}

impl Renderer {
    pub fn new(ctx: Context, scene: Scene, opts: RenderOptions) -> Result<Renderer> {
        if opts.width == 0 || opts.height == 0 || opts.width > 16384 || opts.height > 16384 {
            return Err(Error::Other(format!("invalid image size {}x{} (1..=16384 each)", opts.width, opts.height)));
        }
        check_options(&ctx, &opts)?;
        // Casters: CPU preparation (welding, topology, chunks) then the dual-length buffers.
        let mut casters = Vec::new();
        for m in &scene.meshes {
            if m.casts_shadow {
                casters.push(Caster::from_scene_mesh(m)?);
            }
        }
        let mut gpu_casters = Vec::new();
        for c in &casters {
            let mut chunks = Vec::new();
            for ch in &c.chunks {
                let mut data: Vec<[f32; 4]> = Vec::with_capacity(ch.vertices.len() * 2);
                data.extend(ch.vertices.iter().map(|v| [v.x, v.y, v.z, 1.0]));
                data.extend(ch.vertices.iter().map(|v| [v.x, v.y, v.z, 0.0]));
                let vertices = upload(&ctx, &format!("caster {}", c.name), bytes_of(&data), vk::BufferUsageFlags::VERTEX_BUFFER)?;
                chunks.push(GpuChunk { vertices });
            }
            gpu_casters.push(chunks);
        }

        // Scene geometry for the ambient pass: flat-shaded triangles, eye-relative. Closed,
        // outward meshes first (drawn with back faces culled), then every other mesh (open,
        // non-manifold, inside-out), drawn two-sided so that what the eye sees is what is there.
        let eye = scene.camera.eye.as_dvec3();
        let mut one_sided: Vec<[f32; 10]> = Vec::new();
        let mut two_sided: Vec<[f32; 10]> = Vec::new();
        let mut transparent: Vec<[f32; 10]> = Vec::new();
        for m in &scene.meshes {
            let topo = crate::geom::topology::Topology::build(&m.mesh);
            // A camera inside a closed mesh sees its inside: draw that one two-sided too.
            let eye_inside = topo.is_closed_manifold()
                && m.world_bounds().contains(scene.camera.eye)
                && m.mesh.contains_point(m.transform.as_dmat4().inverse().transform_point3(eye));
            let outward = topo.is_closed_manifold() && signed_volume(&m.mesh) > 0.0 && !eye_inside;
            let verts = if m.opacity < 1.0 {
                &mut transparent
            } else if outward {
                &mut one_sided
            } else {
                &mut two_sided
            };
            let xf = m.transform.as_dmat4();
            for t in 0..m.mesh.triangles.len() {
                let p = m.mesh.triangle(t).map(|v| xf.transform_point3(v.as_dvec3()));
                let n = (p[1] - p[0]).cross(p[2] - p[0]);
                if !(n.length_squared() > 0.0) {
                    continue; // zero-area: nothing to rasterise, and no normal to shade with
                }
                let n = n.normalize().as_vec3();
                for v in p {
                    let r = (v - eye).as_vec3();
                    verts.push([r.x, r.y, r.z, n.x, n.y, n.z, m.color.x, m.color.y, m.color.z, m.opacity]);
                }
            }
        }
        let one_sided_count = one_sided.len() as u32;
        let mut verts = one_sided;
        verts.extend(two_sided);
        let opaque_count = verts.len() as u32;
        verts.extend(transparent);
        if verts.is_empty() {
            return Err(Error::Other(format!("scene '{}' has no triangle to draw", scene.name)));
        }
        let scene_vertices = upload(&ctx, "scene", bytes_of(&verts), vk::BufferUsageFlags::VERTEX_BUFFER)?;
        let targets = Targets::new(&ctx, opts.width, opts.height, opts.transmit.format())?;

        // Descriptors: set 0 = G-buffer (albedo, normal, position, sampler, float count,
        // light-intensity map) for illumination; set 1 = accumulation for tone mapping.
        // SAFETY: plain object creation on a valid device; destroyed in `destroy_resources`.
        let sampler = unsafe {
            ctx.device
                .create_sampler(&vk::SamplerCreateInfo::default().mag_filter(vk::Filter::NEAREST).min_filter(vk::Filter::NEAREST), None)
        }
        .map_err(vkerr("vkCreateSampler"))?;
        let t = &targets;
        let sets = [
            DescriptorSet::new(
                &ctx,
                &[
                    Binding::Image(t.albedo.view),
                    Binding::Image(t.normal.view),
                    Binding::Image(t.position.view),
                    Binding::Sampler(sampler),
                    Binding::Image(t.count.view),
                    Binding::Image(t.transmit.view),
                ],
            )?,
            DescriptorSet::new(&ctx, &[Binding::Image(t.accum.view), Binding::Sampler(sampler)])?,
        ];
        let vf = vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT;
        let frag = vk::ShaderStageFlags::FRAGMENT;
        let layouts = [
            pipeline_layout(&ctx, &[], 80, vf)?,
            pipeline_layout(&ctx, &[], 96, vf)?,
            pipeline_layout(&ctx, &[sets[0].layout], 64, frag)?,
            pipeline_layout(&ctx, &[sets[1].layout], 0, frag)?,
            pipeline_layout(&ctx, &[], 128, vf)?,
        ];

        let pipes = create_pipelines(&ctx, &layouts, opts.depth_mode, ctx.features.depth_bounds, opts.transmit.format())?;

        let d = &ctx.device;
        // SAFETY: object creation on a valid device; destroyed in Drop.
        let (query_pool, cmd, fence) = unsafe {
            let qp = d
                .create_query_pool(
                    &vk::QueryPoolCreateInfo::default().query_type(vk::QueryType::TIMESTAMP).query_count(MAX_TIMESTAMPS),
                    None,
                )
                .map_err(vkerr("vkCreateQueryPool"))?;
            let cmd = d
                .allocate_command_buffers(&vk::CommandBufferAllocateInfo::default().command_pool(ctx.pool).command_buffer_count(1))
                .map_err(vkerr("vkAllocateCommandBuffers"))?[0];
            let fence = d.create_fence(&vk::FenceCreateInfo::default(), None).map_err(vkerr("vkCreateFence"))?;
            (qp, cmd, fence)
        };

        let self_shadow = if opts.self_shadow && opaque_count < verts.len() as u32 {
            Some(selfshadow::SelfShadow::new(&ctx, targets.extent, opts.transmit.format(), sampler, layouts[4])?)
        } else {
            None
        };
        let shells = casters.iter().map(|c| shell_count(c.mesh())).collect();
        let has_transparent = casters.iter().any(|c| c.transmittance.is_some());
        Ok(Renderer {
            scene,
            opts,
            casters,
            shells,
            has_transparent,
            shadow_mapper: None,
            edge_quads: Vec::new(),
            gpu_casters,
            scene_vertex_count: verts.len() as u32,
            one_sided_count,
            opaque_count,
            scene_vertices,
            targets,
            layouts,
            sets,
            sampler,
            pipes,
            self_shadow,
            stream: None,
            readback: Vec::new(),
            query_pool,
            cmd,
            fence,
            ctx,
        })
    }

    /// Tears the renderer down and hands back its context (to render another scene).
    pub fn into_context(self) -> Context {
        let mut me = std::mem::ManuallyDrop::new(self);
        me.destroy_resources();
        // SAFETY: `me` is never used or dropped again; each remaining field is read out exactly
        // once (or dropped in place), so nothing is freed twice.
        unsafe {
            std::ptr::drop_in_place(&mut me.scene);
            std::ptr::drop_in_place(&mut me.opts);
            std::ptr::drop_in_place(&mut me.casters);
            std::ptr::drop_in_place(&mut me.shells);
            std::ptr::drop_in_place(&mut me.gpu_casters);
            std::ptr::drop_in_place(&mut me.readback);
            std::ptr::drop_in_place(&mut me.stream);
            std::ptr::read(&me.ctx)
        }
    }

    pub fn casters(&self) -> &[Caster] {
        &self.casters
    }

    /// World -> clip with the configured depth mode (used by the planner for its frustum tests).
    fn projection(&self) -> Mat4 {
        let aspect = self.opts.width as f32 / self.opts.height as f32;
        match self.opts.depth_mode {
            DepthMode::Infinite => self.scene.camera.proj_infinite(aspect),
            DepthMode::Clamp => {
                // Far plane just beyond the scene: everything further is clamped to depth 1.
                let eye = self.scene.camera.eye;
                let far =
                    self.scene.meshes.iter().flat_map(|m| m.world_bounds().corners()).map(|c| c.distance(eye)).fold(1.0f32, f32::max) * 1.5;
                self.scene.camera.proj_finite(aspect, far.max(self.scene.camera.near * 2.0))
            }
        }
    }

    /// Plans every light (CPU), then records, submits and reads back one frame.
    pub fn render(&mut self) -> Result<FrameOutput> {
        check_options(&self.ctx, &self.opts)?;
        let wall = Instant::now();
        let (w, h) = (self.opts.width, self.opts.height);
        let proj = self.projection();
        let cam = &self.scene.camera;
        let view_world = cam.view();
        let view_proj = proj * view_world;
        // Eye-relative view: rotation only, the translation is folded into every model matrix
        // in f64.
        let view_rel = glam::camera::rh::view::look_at_mat4(Vec3::ZERO, cam.target - cam.eye, cam.up.normalize());
        let eye = cam.eye.as_dvec3();
        let vp_rel_d = proj.as_dmat4() * view_rel.as_dmat4();
        let vp_rel = vp_rel_d.as_mat4();

        // The shadow-map baseline replaces the volumes (created on first use, or re-created when
        // the map size changes).
        match self.opts.shadow_map {
            Some(size) if self.shadow_mapper.as_ref().map(|m| m.size) != Some(size) => {
                if let Some(mut old) = self.shadow_mapper.take() {
                    // SAFETY: waiting for idle before destroying objects a frame may have used.
                    unsafe { self.ctx.device.device_wait_idle() }.map_err(vkerr("vkDeviceWaitIdle"))?;
                    old.destroy(&self.ctx);
                }
                self.shadow_mapper = Some(super::shadowmap::ShadowMapper::new(&self.ctx, &self.scene, &self.targets, size, self.sampler)?);
            }
            None => {
                if let Some(mut old) = self.shadow_mapper.take() {
                    // SAFETY: as above.
                    unsafe { self.ctx.device.device_wait_idle() }.map_err(vkerr("vkDeviceWaitIdle"))?;
                    old.destroy(&self.ctx);
                }
            }
            _ => {}
        }
        if self.opts.edge_quads && self.edge_quads.is_empty() {
            for c in &self.casters {
                let eq = if c.kind == crate::shadow::CasterKind::Manifold && c.transmittance.is_none() {
                    let m = crate::shadow::edgequad::EdgeQuadMesh::new(c);
                    let mut idx = m.faces.clone();
                    idx.extend_from_slice(&m.quads);
                    Some(EdgeQuadGpu {
                        vertices: upload(&self.ctx, "edge-quad vertices", bytes_of(&m.vertices), vk::BufferUsageFlags::VERTEX_BUFFER)?,
                        indices: upload(&self.ctx, "edge-quad indices", bytes_of(&idx), vk::BufferUsageFlags::INDEX_BUFFER)?,
                        face_indices: m.faces.len() as u32,
                        quad_indices: m.quads.len() as u32,
                    })
                } else {
                    None
                };
                self.edge_quads.push(eq);
            }
        }
        let cam = &self.scene.camera;

        // 1. Plans (pure CPU; no casters for the shadow-map baseline, only scissors).
        let plan_casters: &[Caster] = if self.shadow_mapper.is_some() { &[] } else { &self.casters };
        let plans: Vec<LightPlan> = self
            .scene
            .lights
            .iter()
            .map(|light| {
                shadow::plan_light_opts(
                    &PlanInput { camera: cam, width: w, height: h, view_proj, light, method: self.opts.method },
                    plan_casters,
                    self.opts.edge_quads,
                )
            })
            .collect();

        // 2. Shadow geometry stream for the frame.
        let record_start = Instant::now();
        let StreamedFrame { draws, light_stats, totals, mut cpu, stream: stream_raw } = self.build_stream(&plans)?;

        // 3. Readback buffers.
        let npx = (w * h) as u64;
        let nlights = self.scene.lights.len();
        let capture = self.opts.capture || self.opts.view == View::Stencil;
        let float_counts = self.opts.counter == Counter::Float || self.opts.shadow_map.is_some();
        let mut sizes = vec![npx * 4];
        if capture {
            sizes.push(npx * 16); // positions
            sizes.push(npx * 16); // normals
            let per_light = if float_counts { npx * 4 } else { npx };
            sizes.extend(std::iter::repeat(per_light).take(nlights)); // stencil or float count per light
            if self.has_transparent {
                let texel = if self.opts.transmit.fp32 { 16 } else { 8 };
                sizes.extend(std::iter::repeat(npx * texel).take(nlights)); // light-intensity map per light
            }
        }
        if self.readback.len() != sizes.len() || self.readback.iter().zip(&sizes).any(|(b, &s)| b.size != s) {
            for mut b in self.readback.drain(..) {
                b.destroy(&self.ctx);
            }
            for (i, &s) in sizes.iter().enumerate() {
                self.readback.push(Buffer::new(
                    &self.ctx,
                    &format!("readback {i}"),
                    s,
                    vk::BufferUsageFlags::TRANSFER_DST,
                    MemoryLocation::GpuToCpu,
                )?);
            }
        }

        // 4. Record.
        let ambient = self.scene.ambient;
        let light_uniforms: Vec<[Vec4; 4]> = self
            .scene
            .lights
            .iter()
            .map(|l| {
                let pos = match l.kind {
                    LightKind::Directional => (-l.direction.normalize()).extend(0.0),
                    _ => (l.position.as_dvec3() - eye).as_vec3().extend(1.0),
                };
                let spot = match l.kind {
                    LightKind::Spot => l.direction.normalize().extend((l.cone_deg.to_radians() * 0.5).cos()),
                    _ => Vec4::new(0.0, 0.0, -1.0, -2.0),
                };
                let log = if self.opts.transmit.log { 1.0 } else { 0.0 };
                [pos, (l.color * l.intensity).extend(1.0), spot, Vec4::new(l.radius.unwrap_or(0.0), log, 0.0, 0.0)]
            })
            .collect();
        // Per caster: MVP (eye-relative, composed in f64) and the light in object space per light.
        let caster_mvp: Vec<Mat4> =
            self.casters.iter().map(|c| (vp_rel_d * DMat4::from_translation(-eye) * c.transform.as_dmat4()).as_mat4()).collect();

        let ctx = &self.ctx;
        let d = &ctx.device;
        let cb = self.cmd;
        let t = &self.targets;
        let full = vk::Rect2D { offset: vk::Offset2D { x: 0, y: 0 }, extent: t.extent };
        let viewport = vk::Viewport { x: 0.0, y: 0.0, width: w as f32, height: h as f32, min_depth: 0.0, max_depth: 1.0 };
        let timestamps = ctx.features.timestamps;
        let mut ts_next = 3u32;
        let mut ts_shadow: Vec<(u32, u32)> = Vec::new();
        let mut ts_illum: Vec<(u32, u32)> = Vec::new();
        let ts = |stage: vk::PipelineStageFlags2, q: u32| {
            if timestamps && q < MAX_TIMESTAMPS {
                // SAFETY: `cb` is recording; the query was reset at the start of the buffer.
                unsafe { d.cmd_write_timestamp2(cb, stage, self.query_pool, q) };
            }
        };
        let att = |img: &crate::gpu::Image, load: vk::AttachmentLoadOp, clear: vk::ClearValue| {
            vk::RenderingAttachmentInfo::default()
                .image_view(img.view)
                .image_layout(if img.aspect == vk::ImageAspectFlags::COLOR {
                    vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL
                } else {
                    vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL
                })
                .load_op(load)
                .store_op(vk::AttachmentStoreOp::STORE)
                .clear_value(clear)
        };
        let zero = vk::ClearValue { color: vk::ClearColorValue { float32: [0.0; 4] } };
        let ds_clear = vk::ClearValue { depth_stencil: vk::ClearDepthStencilValue { depth: 1.0, stencil: 0 } };
        let load = vk::AttachmentLoadOp::LOAD;

        // SAFETY: every command below is recorded into `cb`, which is reset and begun here and
        // submitted once; all handles belong to this device and live until Drop; layouts are
        // tracked by hand in the order written.
        unsafe {
            d.reset_command_buffer(cb, vk::CommandBufferResetFlags::empty()).map_err(vkerr("vkResetCommandBuffer"))?;
            d.begin_command_buffer(cb, &vk::CommandBufferBeginInfo::default().flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT))
                .map_err(vkerr("vkBeginCommandBuffer"))?;
            if timestamps {
                d.cmd_reset_query_pool(cb, self.query_pool, 0, MAX_TIMESTAMPS);
            }
            for img in t.gbuffer() {
                transition(ctx, cb, img, vk::ImageLayout::UNDEFINED, vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL);
            }
            transition(ctx, cb, &t.depth, vk::ImageLayout::UNDEFINED, vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL);
            ts(vk::PipelineStageFlags2::TOP_OF_PIPE, TS_BEGIN);

            // Ambient pass.
            let colors: Vec<_> = t.gbuffer().iter().map(|i| att(i, vk::AttachmentLoadOp::CLEAR, zero)).collect();
            let depth_att = att(&t.depth, vk::AttachmentLoadOp::CLEAR, ds_clear);
            begin_pass(d, cb, full, viewport, &colors, Some(&depth_att));
            d.cmd_bind_pipeline(cb, vk::PipelineBindPoint::GRAPHICS, self.pipes.gbuffer);
            let mut push = [0f32; 20];
            push[..16].copy_from_slice(&vp_rel.to_cols_array());
            push[16..19].copy_from_slice(&ambient.to_array());
            d.cmd_push_constants(cb, self.layouts[0], vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT, 0, bytes_of(&push));
            d.cmd_bind_vertex_buffers(cb, 0, &[self.scene_vertices.raw], &[0]);
            d.cmd_draw(cb, self.one_sided_count, 1, 0, 0);
            if self.opaque_count > self.one_sided_count {
                d.cmd_bind_pipeline(cb, vk::PipelineBindPoint::GRAPHICS, self.pipes.gbuffer_two_sided);
                d.cmd_draw(cb, self.opaque_count - self.one_sided_count, 1, self.one_sided_count, 0);
            }
            d.cmd_end_rendering(cb);
            ts(vk::PipelineStageFlags2::ALL_COMMANDS, TS_DEPTH);
            for img in [&t.albedo, &t.normal, &t.position] {
                transition(ctx, cb, img, vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL, vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL);
            }

            let frag_tests = vk::PipelineStageFlags2::EARLY_FRAGMENT_TESTS | vk::PipelineStageFlags2::LATE_FRAGMENT_TESTS;
            let ds_rw = vk::AccessFlags2::DEPTH_STENCIL_ATTACHMENT_READ | vk::AccessFlags2::DEPTH_STENCIL_ATTACHMENT_WRITE;
            let color_rw = vk::AccessFlags2::COLOR_ATTACHMENT_READ | vk::AccessFlags2::COLOR_ATTACHMENT_WRITE;
            for (li, ldraws) in draws.iter().enumerate() {
                let plan = &plans[li];
                let scissor = plan
                    .scissor
                    .map(|[x, y, sw, sh]| vk::Rect2D {
                        offset: vk::Offset2D { x: x as i32, y: y as i32 },
                        extent: vk::Extent2D { width: sw, height: sh },
                    })
                    .filter(|r| r.extent.width > 0 && r.extent.height > 0)
                    .unwrap_or(full);
                let bounds = if ctx.features.depth_bounds { plan.depth_bounds } else { None };

                // Shadow determination: the counter (stencil, or the float target) cleared inside
                // the scissor, volumes drawn.
                let float = self.opts.counter == Counter::Float || self.shadow_mapper.is_some();
                let q0 = ts_next;
                ts(vk::PipelineStageFlags2::ALL_COMMANDS, q0);
                let depth_load = att(&t.depth, load, ds_clear);
                let stencil_clear = att(&t.depth, vk::AttachmentLoadOp::CLEAR, ds_clear);
                let count_att = [att(&t.count, vk::AttachmentLoadOp::CLEAR, zero)];
                if float {
                    // Contents outside the scissor are never read (illumination is scissored too).
                    transition(ctx, cb, &t.count, vk::ImageLayout::UNDEFINED, vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL);
                }
                if let Some(sm) = &self.shadow_mapper {
                    // Shadow-map baseline: maps from the light, PCF lookup into the float counter.
                    sm.record(ctx, cb, t, &self.scene.lights[li], eye, scissor);
                } else {
                    let info = vk::RenderingInfo::default().render_area(scissor).layer_count(1).depth_attachment(&depth_load);
                    let info = if float {
                        info.color_attachments(&count_att).stencil_attachment(&depth_load)
                    } else {
                        info.stencil_attachment(&stencil_clear)
                    };
                    d.cmd_begin_rendering(cb, &info);
                    d.cmd_set_viewport(cb, 0, &[viewport]);
                    d.cmd_set_scissor(cb, 0, &[scissor]);
                    if ctx.features.depth_bounds {
                        let (lo, hi) = bounds.unwrap_or((0.0, 1.0));
                        d.cmd_set_depth_bounds(cb, lo, hi);
                    }
                    let mut bound_pipe = vk::Pipeline::null();
                    for (ci, case, light_obj, cdraws, edge_quad) in ldraws {
                        if *case == Case::Culled || self.casters[*ci].transmittance.is_some() {
                            continue;
                        }
                        let mut push = [0f32; 24];
                        push[..16].copy_from_slice(&caster_mvp[*ci].to_cols_array());
                        push[16..20].copy_from_slice(&light_obj.to_array());
                        // Float counter: the sign a front face contributes (+1 z-pass, -1 z-fail).
                        push[20] = if *case == Case::ZPass { 1.0 } else { -1.0 };
                        d.cmd_push_constants(
                            cb,
                            self.layouts[1],
                            vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT,
                            0,
                            bytes_of(&push),
                        );
                        if *edge_quad {
                            if let Some(eq) = self.edge_quads.get(*ci).and_then(|e| e.as_ref()) {
                                let p = &self.pipes;
                                let (faces, sides) = if float { (p.eq_faces_count, p.eq_sides_count) } else { (p.eq_faces, p.eq_sides) };
                                d.cmd_bind_vertex_buffers(cb, 0, &[eq.vertices.raw], &[0]);
                                d.cmd_bind_index_buffer(cb, eq.indices.raw, 0, vk::IndexType::UINT32);
                                d.cmd_bind_pipeline(cb, vk::PipelineBindPoint::GRAPHICS, faces);
                                d.cmd_draw_indexed(cb, eq.face_indices, 1, 0, 0, 0);
                                d.cmd_bind_pipeline(cb, vk::PipelineBindPoint::GRAPHICS, sides);
                                d.cmd_draw_indexed(cb, eq.quad_indices, 1, eq.face_indices, 0, 0);
                                bound_pipe = sides;
                            }
                            continue;
                        }
                        for dr in cdraws {
                            let p = &self.pipes;
                            let pipe = match (case, dr.light_cap, float) {
                                (Case::ZPass, _, false) => p.zpass,
                                (_, false, false) => p.zfail,
                                (_, true, false) => p.zfail_cap,
                                (Case::ZPass, _, true) => p.count_zpass,
                                (_, false, true) => p.count_zfail,
                                (_, true, true) => p.count_cap,
                            };
                            if pipe != bound_pipe {
                                d.cmd_bind_pipeline(cb, vk::PipelineBindPoint::GRAPHICS, pipe);
                                bound_pipe = pipe;
                            }
                            self.record_draw(cb, *ci, dr, stream_raw);
                        }
                    }
                    d.cmd_end_rendering(cb);
                }
                ts(vk::PipelineStageFlags2::ALL_COMMANDS, q0 + 1);
                ts_shadow.push((q0, q0 + 1));
                memory_barrier(ctx, cb, (frag_tests, ds_rw), (frag_tests, ds_rw));

                if capture {
                    let region = |aspect| {
                        vk::BufferImageCopy::default()
                            .image_subresource(vk::ImageSubresourceLayers {
                                aspect_mask: aspect,
                                mip_level: 0,
                                base_array_layer: 0,
                                layer_count: 1,
                            })
                            .image_extent(vk::Extent3D { width: w, height: h, depth: 1 })
                    };
                    if float {
                        transition(ctx, cb, &t.count, vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL, vk::ImageLayout::TRANSFER_SRC_OPTIMAL);
                        d.cmd_copy_image_to_buffer(
                            cb,
                            t.count.raw,
                            vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                            self.readback[3 + li].raw,
                            &[region(vk::ImageAspectFlags::COLOR)],
                        );
                        transition(ctx, cb, &t.count, vk::ImageLayout::TRANSFER_SRC_OPTIMAL, vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL);
                    } else {
                        transition(
                            ctx,
                            cb,
                            &t.depth,
                            vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL,
                            vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                        );
                        d.cmd_copy_image_to_buffer(
                            cb,
                            t.depth.raw,
                            vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                            self.readback[3 + li].raw,
                            &[region(vk::ImageAspectFlags::STENCIL)],
                        );
                        transition(
                            ctx,
                            cb,
                            &t.depth,
                            vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                            vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL,
                        );
                    }
                } else if float {
                    transition(ctx, cb, &t.count, vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL, vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL);
                }

                // Transparent casters: the light-intensity map (Kim et al. 2008), every volume face
                // multiplying by t or 1/t (or adding +-log t), depth-tested like the float counter.
                if self.has_transparent {
                    let log = self.opts.transmit.log;
                    let clear = vk::ClearValue { color: vk::ClearColorValue { float32: if log { [0.0; 4] } else { [1.0; 4] } } };
                    transition(ctx, cb, &t.transmit, vk::ImageLayout::UNDEFINED, vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL);
                    let map_att = [att(&t.transmit, vk::AttachmentLoadOp::CLEAR, clear)];
                    begin_pass(d, cb, scissor, viewport, &map_att, Some(&depth_load));
                    if ctx.features.depth_bounds {
                        let (lo, hi) = bounds.unwrap_or((0.0, 1.0));
                        d.cmd_set_depth_bounds(cb, lo, hi);
                    }
                    for (ci, case, light_obj, cdraws, _) in ldraws {
                        let Some(tr) = self.casters[*ci].transmittance else { continue };
                        if *case == Case::Culled {
                            continue;
                        }
                        let zpass = *case == Case::ZPass;
                        let mut push = [0f32; 24];
                        push[..16].copy_from_slice(&caster_mvp[*ci].to_cols_array());
                        push[16..20].copy_from_slice(&light_obj.to_array());
                        push[20..24].copy_from_slice(&[if zpass { 1.0 } else { -1.0 }, tr.x, tr.y, tr.z]);
                        d.cmd_push_constants(
                            cb,
                            self.layouts[1],
                            vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT,
                            0,
                            bytes_of(&push),
                        );
                        d.cmd_bind_pipeline(cb, vk::PipelineBindPoint::GRAPHICS, self.pipes.transmit[log as usize][(!zpass) as usize]);
                        for dr in cdraws {
                            // Transparent casters' caps are all in the volume list (not NEVER).
                            self.record_draw(cb, *ci, dr, stream_raw);
                        }
                    }
                    d.cmd_end_rendering(cb);
                    if capture {
                        transition(ctx, cb, &t.transmit, vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL, vk::ImageLayout::TRANSFER_SRC_OPTIMAL);
                        let region = vk::BufferImageCopy::default()
                            .image_subresource(vk::ImageSubresourceLayers {
                                aspect_mask: vk::ImageAspectFlags::COLOR,
                                mip_level: 0,
                                base_array_layer: 0,
                                layer_count: 1,
                            })
                            .image_extent(vk::Extent3D { width: w, height: h, depth: 1 });
                        d.cmd_copy_image_to_buffer(
                            cb,
                            t.transmit.raw,
                            vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                            self.readback[3 + nlights + li].raw,
                            &[region],
                        );
                        transition(ctx, cb, &t.transmit, vk::ImageLayout::TRANSFER_SRC_OPTIMAL, vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL);
                    } else {
                        transition(
                            ctx,
                            cb,
                            &t.transmit,
                            vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL,
                            vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL,
                        );
                    }
                }

                // Illumination where the count is zero.
                let q1 = q0 + 2;
                ts(vk::PipelineStageFlags2::ALL_COMMANDS, q1);
                let accum_att = [att(&t.accum, load, zero)];
                begin_pass(d, cb, scissor, viewport, &accum_att, Some(&depth_load));
                let p = &self.pipes;
                let illuminate = match (float, self.has_transparent) {
                    (false, false) => p.illuminate,
                    (true, false) => p.illuminate_count,
                    (false, true) => p.illuminate_t,
                    (true, true) => p.illuminate_count_t,
                };
                d.cmd_bind_pipeline(cb, vk::PipelineBindPoint::GRAPHICS, illuminate);
                if ctx.features.depth_bounds {
                    let (lo, hi) = bounds.unwrap_or((0.0, 1.0));
                    d.cmd_set_depth_bounds(cb, lo, hi);
                }
                d.cmd_bind_descriptor_sets(cb, vk::PipelineBindPoint::GRAPHICS, self.layouts[2], 0, &[self.sets[0].set], &[]);
                d.cmd_push_constants(cb, self.layouts[2], vk::ShaderStageFlags::FRAGMENT, 0, bytes_of(&light_uniforms[li]));
                d.cmd_draw(cb, 3, 1, 0, 0);
                d.cmd_end_rendering(cb);
                ts(vk::PipelineStageFlags2::ALL_COMMANDS, q1 + 1);
                ts_illum.push((q1, q1 + 1));
                ts_next += 4;
                memory_barrier(
                    ctx,
                    cb,
                    (vk::PipelineStageFlags2::COLOR_ATTACHMENT_OUTPUT | frag_tests, color_rw | ds_rw),
                    (vk::PipelineStageFlags2::COLOR_ATTACHMENT_OUTPUT | frag_tests, color_rw | ds_rw),
                );
            }

            // Transparent casters, forward over the lit scene: premultiplied "over" with the
            // ambient term, then each light added (unsorted: an order-independent approximation;
            // transparent surfaces receive no shadows).
            if self.opaque_count < self.scene_vertex_count {
                let accum_att = [att(&t.accum, load, zero)];
                let depth_load = att(&t.depth, load, ds_clear);
                begin_pass(d, cb, full, viewport, &accum_att, Some(&depth_load));
                d.cmd_bind_vertex_buffers(cb, 0, &[self.scene_vertices.raw], &[0]);
                let n = self.scene_vertex_count - self.opaque_count;
                let mut push = [0f32; 32];
                push[..16].copy_from_slice(&vp_rel.to_cols_array());
                push[20..23].copy_from_slice(&ambient.to_array());
                let stages = vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT;
                d.cmd_bind_pipeline(cb, vk::PipelineBindPoint::GRAPHICS, self.pipes.transparent_over);
                d.cmd_push_constants(cb, self.layouts[4], stages, 0, bytes_of(&push));
                d.cmd_draw(cb, n, 1, self.opaque_count, 0);
                d.cmd_bind_pipeline(cb, vk::PipelineBindPoint::GRAPHICS, self.pipes.transparent_light);
                // --self-shadow: the light passes are recorded by record_self_shadow below.
                for lu in light_uniforms.iter().filter(|_| self.self_shadow.is_none()) {
                    for (k, v) in lu.iter().enumerate() {
                        push[16 + 4 * k..20 + 4 * k].copy_from_slice(&v.to_array());
                    }
                    push[30] = 1.0; // params.z: light pass
                    d.cmd_push_constants(cb, self.layouts[4], stages, 0, bytes_of(&push));
                    d.cmd_draw(cb, n, 1, self.opaque_count, 0);
                }
                d.cmd_end_rendering(cb);
                // --- self-shadowing (src/render/selfshadow.rs): steps 4-6 of Kim et al. ---
                if let Some(ss) = &self.self_shadow {
                    memory_barrier(
                        ctx,
                        cb,
                        (vk::PipelineStageFlags2::COLOR_ATTACHMENT_OUTPUT, color_rw),
                        (vk::PipelineStageFlags2::COLOR_ATTACHMENT_OUTPUT, color_rw),
                    );
                    let frame = selfshadow::SelfShadowFrame {
                        vp_rel,
                        viewport,
                        full,
                        plans: &plans,
                        draws: &draws,
                        caster_mvp: &caster_mvp,
                        light_uniforms: &light_uniforms,
                        stream: stream_raw,
                    };
                    self.record_self_shadow(ss, cb, &frame);
                }
                // --- end self-shadowing ---
            }

            if self.opts.view == View::Volumes {
                let accum_att = [att(&t.accum, load, zero)];
                let depth_load = att(&t.depth, load, ds_clear);
                begin_pass(d, cb, full, viewport, &accum_att, Some(&depth_load));
                d.cmd_bind_pipeline(cb, vk::PipelineBindPoint::GRAPHICS, self.pipes.volumes);
                for ldraws in draws.iter() {
                    for (ci, case, light_obj, cdraws, _) in ldraws {
                        let color = match case {
                            Case::Culled => continue,
                            Case::ZPass => [0.2f32, 0.4, 1.0, 0.12],
                            Case::ZFail => [1.0, 0.3, 0.2, 0.12],
                            Case::ZFailLightCap => [0.1, 1.0, 0.2, 0.12],
                        };
                        let mut push = [0f32; 24];
                        push[..16].copy_from_slice(&caster_mvp[*ci].to_cols_array());
                        push[16..20].copy_from_slice(&light_obj.to_array());
                        push[20..24].copy_from_slice(&color);
                        d.cmd_push_constants(
                            cb,
                            self.layouts[1],
                            vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT,
                            0,
                            bytes_of(&push),
                        );
                        for dr in cdraws.iter().filter(|dr| !dr.light_cap) {
                            self.record_draw(cb, *ci, dr, stream_raw);
                        }
                    }
                }
                d.cmd_end_rendering(cb);
            }

            // Final pass: tone map to sRGB.
            transition(ctx, cb, &t.accum, vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL, vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL);
            transition(ctx, cb, &t.output, vk::ImageLayout::UNDEFINED, vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL);
            let out_att = [att(&t.output, vk::AttachmentLoadOp::DONT_CARE, zero)];
            begin_pass(d, cb, full, viewport, &out_att, None);
            d.cmd_bind_pipeline(cb, vk::PipelineBindPoint::GRAPHICS, self.pipes.tonemap);
            d.cmd_bind_descriptor_sets(cb, vk::PipelineBindPoint::GRAPHICS, self.layouts[3], 0, &[self.sets[1].set], &[]);
            d.cmd_draw(cb, 3, 1, 0, 0);
            d.cmd_end_rendering(cb);
            ts(vk::PipelineStageFlags2::ALL_COMMANDS, TS_END);

            // Readback.
            transition(ctx, cb, &t.output, vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL, vk::ImageLayout::TRANSFER_SRC_OPTIMAL);
            let color_region = |aspect| {
                vk::BufferImageCopy::default()
                    .image_subresource(vk::ImageSubresourceLayers {
                        aspect_mask: aspect,
                        mip_level: 0,
                        base_array_layer: 0,
                        layer_count: 1,
                    })
                    .image_extent(vk::Extent3D { width: w, height: h, depth: 1 })
            };
            d.cmd_copy_image_to_buffer(
                cb,
                t.output.raw,
                vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                self.readback[0].raw,
                &[color_region(vk::ImageAspectFlags::COLOR)],
            );
            if capture {
                for (img, buf) in [(&t.position, 1), (&t.normal, 2)] {
                    transition(ctx, cb, img, vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL, vk::ImageLayout::TRANSFER_SRC_OPTIMAL);
                    d.cmd_copy_image_to_buffer(
                        cb,
                        img.raw,
                        vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                        self.readback[buf].raw,
                        &[color_region(vk::ImageAspectFlags::COLOR)],
                    );
                }
            }
            memory_barrier(
                ctx,
                cb,
                (vk::PipelineStageFlags2::ALL_TRANSFER, vk::AccessFlags2::TRANSFER_WRITE),
                (vk::PipelineStageFlags2::HOST, vk::AccessFlags2::HOST_READ),
            );
            d.end_command_buffer(cb).map_err(vkerr("vkEndCommandBuffer"))?;
            cpu.record = record_start.elapsed().as_secs_f64() * 1e3;

            let cbs = [cb];
            d.reset_fences(&[self.fence]).map_err(vkerr("vkResetFences"))?;
            d.queue_submit(ctx.queue, &[vk::SubmitInfo::default().command_buffers(&cbs)], self.fence).map_err(vkerr("vkQueueSubmit"))?;
            d.wait_for_fences(&[self.fence], true, u64::MAX).map_err(vkerr("vkWaitForFences"))?;
        }
        ctx.check_validation()?;

        // 5. Timings.
        let gpu_ms = if timestamps {
            let n = ts_next.min(MAX_TIMESTAMPS) as usize;
            let mut raw = vec![0u64; n];
            // SAFETY: the fence wait above guarantees the queries are available.
            unsafe { d.get_query_pool_results(self.query_pool, 0, &mut raw, vk::QueryResultFlags::TYPE_64 | vk::QueryResultFlags::WAIT) }
                .map_err(vkerr("vkGetQueryPoolResults"))?;
            let ms =
                |a: u32, b: u32| (raw[b as usize].wrapping_sub(raw[a as usize])) as f64 * ctx.features.timestamp_period_ns as f64 * 1e-6;
            Some(GpuMs {
                depth: ms(TS_BEGIN, TS_DEPTH),
                shadow: ts_shadow.iter().map(|&(a, b)| ms(a, b)).sum(),
                illuminate: ts_illum.iter().map(|&(a, b)| ms(a, b)).sum(),
                frame: ms(TS_BEGIN, TS_END),
            })
        } else {
            None
        };

        // 6. Read back.
        let Captured { color, positions, normals, stencil, counts, transmit } = self.read_back(capture, float_counts, eye)?;

        let mut features_used = Vec::new();
        let mut features_missing = Vec::new();
        let f = &ctx.features;
        for (name, has, used) in [
            ("depthClamp", f.depth_clamp, self.opts.depth_mode == DepthMode::Clamp),
            ("depthBounds", f.depth_bounds, f.depth_bounds),
            (
                "indexTypeUint8",
                f.index_type_uint8,
                f.index_type_uint8 && matches!(self.opts.index_format, IndexFormat::U8 | IndexFormat::Auto),
            ),
            ("timestamps", f.timestamps, f.timestamps),
        ] {
            if used {
                features_used.push(name.to_string());
            } else if !has {
                features_missing.push(name.to_string());
            }
        }
        // 8-bit stencil counts wrap at 256: a pixel inside a multiple of 256 volumes reads as
        // lit. Flag lights whose drawn casters could nest that deep (a heuristic: one caster
        // folding 256 times over itself is not detected).
        let mut warnings = Vec::new();
        for (li, plan) in plans.iter().enumerate() {
            let drawn: usize = plan.casters.iter().filter(|c| c.case != Case::Culled).map(|c| self.shells[c.caster]).sum();
            if drawn > 255 && self.opts.counter == Counter::Stencil {
                warnings.push(format!(
                    "light {li}: {drawn} closed shells cast shadow volumes; pixels inside 256k of them wrap to 0 in the 8-bit stencil and read as lit (use --counter float)"
                ));
            }
        }
        let stats = Stats {
            device: ctx.info.name.clone(),
            method: if self.shadow_mapper.is_some() {
                "shadowmap".to_string()
            } else if self.opts.edge_quads {
                "edgequad".to_string()
            } else {
                self.opts.method.to_string()
            },
            depth_mode: self.opts.depth_mode.name().into(),
            index_format: self.opts.index_format.name().into(),
            counter: self.opts.counter.name().into(),
            transmit: if self.has_transparent { Some(self.opts.transmit.name().into()) } else { None },
            self_shadow: self.self_shadow.is_some(),
            width: w,
            height: h,
            lights: light_stats,
            totals,
            cpu_ms: cpu,
            gpu_ms,
            wall_ms: wall.elapsed().as_secs_f64() * 1e3,
            features_used,
            features_missing,
            warnings,
        };
        let mut out = FrameOutput { width: w, height: h, color, stencil, counts, transmit, positions, normals, stats };
        if self.opts.view == View::Stencil {
            if let Some(s) = out.stencil.first() {
                out.color = stencil_heatmap(s);
            }
        }
        Ok(out)
    }

    /// Turns the plans into this frame's shadow-geometry stream (indices in the chosen format,
    /// or naive vertices), uploads it, and gathers the per-caster statistics.
    fn build_stream(&mut self, plans: &[LightPlan]) -> Result<StreamedFrame> {
        let u8_ok = self.ctx.features.index_type_uint8;
        let mut stream: Vec<u8> = Vec::new();
        // Per light, per caster: draws (chunk, stream offset, count, format, is_light_cap).
        let mut draws: Vec<Vec<CasterDraws>> = Vec::new();
        let mut light_stats = Vec::new();
        let mut totals = Totals::default();
        let mut cpu = CpuMs::default();
        for (li, plan) in plans.iter().enumerate() {
            cpu.silhouettes += plan.silhouette_ms;
            cpu.plan += plan.plan_ms;
            let mut ldraws = Vec::new();
            let mut cstats = Vec::new();
            for cp in &plan.casters {
                let caster = &self.casters[cp.caster];
                let mut cdraws = Vec::new();
                let mut index_bytes = 0u64;
                let mut vertex_bytes = 0u64;
                let mut fmt_used = "none";
                for cd in &cp.chunks {
                    let chunk = &caster.chunks[cd.chunk];
                    let n = chunk.vertices.len();
                    for (indices, cap) in [(&cd.volume, false), (&cd.light_cap, true)] {
                        if indices.is_empty() {
                            continue;
                        }
                        let fmt = match self.opts.index_format {
                            IndexFormat::Auto | IndexFormat::U8 if u8_ok && 2 * n <= 256 => IndexFormat::U8,
                            IndexFormat::Auto | IndexFormat::U8 => IndexFormat::U16,
                            f => f,
                        };
                        fmt_used = fmt.name();
                        align(&mut stream, 16);
                        let offset = stream.len() as u64;
                        match fmt {
                            IndexFormat::U8 => stream.extend(indices.iter().map(|&i| i as u8)),
                            IndexFormat::U16 => stream.extend(indices.iter().flat_map(|&i| i.to_le_bytes())),
                            IndexFormat::U32 => stream.extend(indices.iter().flat_map(|&i| (i as u32).to_le_bytes())),
                            IndexFormat::Naive | IndexFormat::Auto => {
                                for &i in indices.iter() {
                                    let i = i as usize;
                                    let (v, wv) = if i < n { (chunk.vertices[i], 1.0f32) } else { (chunk.vertices[i - n], 0.0) };
                                    for f in [v.x, v.y, v.z, wv] {
                                        stream.extend(f.to_le_bytes());
                                    }
                                }
                            }
                        }
                        let bytes = stream.len() as u64 - offset;
                        if fmt == IndexFormat::Naive {
                            vertex_bytes += bytes;
                        } else {
                            index_bytes += bytes;
                        }
                        cdraws.push(Draw { chunk: cd.chunk, offset, count: indices.len() as u32, format: fmt, light_cap: cap });
                    }
                }
                let tris = Triangles { sides: cp.sides as u64, dark_cap: cp.dark_cap as u64, light_cap: cp.light_cap as u64 };
                let ntris = tris.total();
                totals.triangles.add(&tris);
                totals.index_bytes += index_bytes;
                totals.vertex_bytes += vertex_bytes;
                match cp.case {
                    Case::Culled => totals.cases.culled += 1,
                    Case::ZPass => totals.cases.zpass += 1,
                    Case::ZFail => totals.cases.zfail += 1,
                    Case::ZFailLightCap => totals.cases.zfail_light_cap += 1,
                }
                cstats.push(CasterStats {
                    name: caster.name.clone(),
                    case: case_name(cp.case).to_string(),
                    silhouette_edges: cp.silhouette_edges as u64,
                    triangles: tris,
                    index_bytes,
                    vertex_bytes,
                    bytes_per_triangle: if ntris > 0 { (index_bytes + vertex_bytes) as f64 / ntris as f64 } else { 0.0 },
                    index_format: fmt_used.to_string(),
                    dark_cap_kind: format!("{:?}", cp.dark_cap_kind),
                    path: cp.path.to_string(),
                    path_reason: match &caster.kind {
                        crate::shadow::CasterKind::Multiplicity { reason } => reason.clone(),
                        _ => String::new(),
                    },
                    multiplicity_max: cp.multiplicity_max,
                });
                ldraws.push((cp.caster, cp.case, Vec4::from_array(cp.light_object), cdraws, cp.path == "edgequad"));
            }
            let light = &self.scene.lights[li];
            light_stats.push(LightStats {
                index: li,
                kind: format!("{:?}", light.kind).to_lowercase(),
                scissor: plan.scissor,
                depth_bounds: if self.ctx.features.depth_bounds { plan.depth_bounds.map(|(a, b)| [a, b]) } else { None },
                casters: cstats,
            });
            draws.push(ldraws);
        }
        align(&mut stream, 16);
        if self.stream.as_ref().map(|b| b.size < stream.len() as u64).unwrap_or(true) {
            if let Some(mut old) = self.stream.take() {
                old.destroy(&self.ctx);
            }
            let size = (stream.len() as u64).max(1 << 16).next_power_of_two();
            self.stream = Some(Buffer::new(
                &self.ctx,
                "shadow stream",
                size,
                vk::BufferUsageFlags::INDEX_BUFFER | vk::BufferUsageFlags::VERTEX_BUFFER,
                MemoryLocation::CpuToGpu,
            )?);
        }
        let stream_buf = self.stream.as_mut().ok_or_else(|| Error::Other("no stream buffer".into()))?;
        stream_buf.write(0, &stream)?;
        let stream_raw = stream_buf.raw;
        Ok(StreamedFrame { draws, light_stats, totals, cpu, stream: stream_raw })
    }

    /// Reads the frame's readback buffers: colour always; positions (world, NaN for
    /// background), normals, per-light counts and light-intensity maps when captured.
    fn read_back(&self, capture: bool, float_counts: bool, eye: DVec3) -> Result<Captured> {
        let nlights = self.scene.lights.len();
        let color = self.readback[0].read()?.to_vec();
        let (mut positions, mut normals, mut stencil, mut counts, mut transmit) =
            (Vec::new(), Vec::new(), Vec::new(), Vec::new(), Vec::new());
        if capture {
            let floats = |b: &Buffer| -> Result<Vec<[f32; 4]>> {
                Ok(b.read()?
                    .chunks_exact(16)
                    .map(|c| std::array::from_fn(|k| f32::from_le_bytes([c[4 * k], c[4 * k + 1], c[4 * k + 2], c[4 * k + 3]])))
                    .collect())
            };
            let pos = floats(&self.readback[1])?;
            let nrm = floats(&self.readback[2])?;
            for (p, n) in pos.iter().zip(&nrm) {
                if p[3] == 0.0 {
                    positions.push([f32::NAN; 3]);
                    normals.push([f32::NAN; 3]);
                } else {
                    let wp = DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64) + eye;
                    positions.push(wp.as_vec3().to_array());
                    normals.push([n[0], n[1], n[2]]);
                }
            }
            for li in 0..nlights {
                let raw = self.readback[3 + li].read()?;
                if float_counts {
                    let c: Vec<i32> = raw.chunks_exact(4).map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]).round() as i32).collect();
                    stencil.push(c.iter().map(|&v| v.clamp(0, 255) as u8).collect());
                    counts.push(c);
                } else {
                    stencil.push(raw.to_vec());
                }
                if self.has_transparent {
                    let raw = self.readback[3 + nlights + li].read()?;
                    let mode = self.opts.transmit;
                    let texel = if mode.fp32 { 16 } else { 8 };
                    let map: Vec<[f32; 3]> = raw
                        .chunks_exact(texel)
                        .map(|px| {
                            let ch = |k: usize| {
                                if mode.fp32 {
                                    f32::from_le_bytes([px[4 * k], px[4 * k + 1], px[4 * k + 2], px[4 * k + 3]])
                                } else {
                                    f16_to_f32(u16::from_le_bytes([px[2 * k], px[2 * k + 1]]))
                                }
                            };
                            let v = [ch(0), ch(1), ch(2)];
                            if mode.log {
                                v.map(f32::exp)
                            } else {
                                v
                            }
                        })
                        .collect();
                    transmit.push(map);
                }
            }
        }

        Ok(Captured { color, positions, normals, stencil, counts, transmit })
    }

    /// Binds the chunk's vertices (or the streamed naive vertices) and draws.
    fn record_draw(&self, cb: vk::CommandBuffer, caster: usize, dr: &Draw, stream: vk::Buffer) {
        let d = &self.ctx.device;
        let chunk = &self.gpu_casters[caster][dr.chunk];
        // SAFETY: `cb` is recording inside a rendering instance with a bound shadow pipeline; the
        // buffers live until Drop and the offsets were computed from the stream just written.
        unsafe {
            match dr.format {
                IndexFormat::Naive => {
                    d.cmd_bind_vertex_buffers(cb, 0, &[stream], &[dr.offset]);
                    d.cmd_draw(cb, dr.count, 1, 0, 0);
                }
                f => {
                    let ty = match f {
                        IndexFormat::U8 => vk::IndexType::UINT8_EXT,
                        IndexFormat::U32 => vk::IndexType::UINT32,
                        _ => vk::IndexType::UINT16,
                    };
                    d.cmd_bind_vertex_buffers(cb, 0, &[chunk.vertices.raw], &[0]);
                    d.cmd_bind_index_buffer(cb, stream, dr.offset, ty);
                    d.cmd_draw_indexed(cb, dr.count, 1, 0, 0, 0);
                }
            }
        }
    }
}

/// Six times the signed volume (positive for a closed mesh wound outward).
fn signed_volume(mesh: &crate::geom::Mesh) -> f64 {
    (0..mesh.triangles.len())
        .map(|t| {
            let [a, b, c] = mesh.triangle(t).map(|p| p.as_dvec3());
            a.dot(b.cross(c))
        })
        .sum()
}

/// Connected components of a mesh (triangles sharing a vertex), by union-find.
fn shell_count(mesh: &crate::geom::Mesh) -> usize {
    let mut parent: Vec<u32> = (0..mesh.positions.len() as u32).collect();
    fn find(p: &mut [u32], mut i: u32) -> u32 {
        while p[i as usize] != i {
            p[i as usize] = p[p[i as usize] as usize];
            i = p[i as usize];
        }
        i
    }
    for t in &mesh.triangles {
        for k in 1..3 {
            let (a, b) = (find(&mut parent, t[0]), find(&mut parent, t[k]));
            if a != b {
                parent[a as usize] = b;
            }
        }
    }
    let mut roots: Vec<u32> = mesh.triangles.iter().map(|t| find(&mut parent, t[0])).collect();
    roots.sort_unstable();
    roots.dedup();
    roots.len()
}

/// Begins a dynamic-rendering instance over `area` with colour attachments and an optional
/// depth-stencil attachment (used for both aspects, as lavapipe needs), and sets the viewport
/// and a scissor equal to `area`.
///
/// # Safety
/// `cb` must be recording outside any rendering instance, and every attachment's image must be
/// in the layout its info names.
unsafe fn begin_pass(
    d: &ash::Device,
    cb: vk::CommandBuffer,
    area: vk::Rect2D,
    viewport: vk::Viewport,
    colors: &[vk::RenderingAttachmentInfo],
    depth_stencil: Option<&vk::RenderingAttachmentInfo>,
) {
    let mut info = vk::RenderingInfo::default().render_area(area).layer_count(1).color_attachments(colors);
    if let Some(ds) = depth_stencil {
        info = info.depth_attachment(ds).stencil_attachment(ds);
    }
    // SAFETY: forwarded to the caller's contract above.
    unsafe {
        d.cmd_begin_rendering(cb, &info);
        d.cmd_set_viewport(cb, 0, &[viewport]);
        d.cmd_set_scissor(cb, 0, &[area]);
    }
}

/// The options this device can honour (checked at creation and before every frame, since
/// benchmarks switch methods and counters between frames).
fn check_options(ctx: &Context, opts: &RenderOptions) -> Result<()> {
    if opts.depth_mode == DepthMode::Clamp && !ctx.features.depth_clamp {
        return Err(Error::Unsupported("--depth-mode clamp needs the depthClamp feature; use --depth-mode infinite".into()));
    }
    if opts.index_format == IndexFormat::U8 && !ctx.features.index_type_uint8 {
        return Err(Error::Unsupported("--index-format u8 needs VK_EXT_index_type_uint8; use auto or u16".into()));
    }
    if (opts.counter == Counter::Float || opts.shadow_map.is_some() || opts.self_shadow) && !ctx.features.r32f_blend {
        return Err(Error::Unsupported(
        "--counter float, --method shadowmap and --self-shadow need R32_SFLOAT colour blending, which this device lacks; use --counter stencil".into(),
        ));
    }
    if opts.transmit.fp32 && !ctx.features.rgba32f_blend {
        return Err(Error::Unsupported(
            "--transmit log32/mul32 need R32G32B32A32_SFLOAT blending, which this device lacks; use log16".into(),
        ));
    }
    Ok(())
}

/// IEEE half to single precision (readback of RGBA16F targets).
fn f16_to_f32(h: u16) -> f32 {
    let sign = if h & 0x8000 != 0 { -1.0f32 } else { 1.0 };
    let exp = ((h >> 10) & 0x1f) as i32;
    let mant = (h & 0x3ff) as f32;
    match exp {
        0 => sign * mant * 2f32.powi(-24),
        31 => {
            if mant == 0.0 {
                sign * f32::INFINITY
            } else {
                f32::NAN
            }
        }
        e => sign * (1.0 + mant / 1024.0) * 2f32.powi(e - 15),
    }
}

fn case_name(c: Case) -> &'static str {
    match c {
        Case::Culled => "culled",
        Case::ZPass => "zpass",
        Case::ZFail => "zfail",
        Case::ZFailLightCap => "zfail_light_cap",
    }
}

/// What [`Renderer::read_back`] returns (see [`FrameOutput`] for each field).
struct Captured {
    color: Vec<u8>,
    positions: Vec<[f32; 3]>,
    normals: Vec<[f32; 3]>,
    stencil: Vec<Vec<u8>>,
    counts: Vec<Vec<i32>>,
    transmit: Vec<Vec<[f32; 3]>>,
}

/// What [`Renderer::build_stream`] hands to the recording.
struct StreamedFrame {
    /// Per light, per caster.
    draws: Vec<Vec<CasterDraws>>,
    light_stats: Vec<LightStats>,
    totals: Totals,
    cpu: CpuMs,
    stream: vk::Buffer,
}

/// Per caster and light: caster index, case, object-space light, index-stream draws, and
/// whether the GPU-only edge-quad method draws it instead.
type CasterDraws = (usize, Case, Vec4, Vec<Draw>, bool);

struct Draw {
    chunk: usize,
    offset: u64,
    count: u32,
    format: IndexFormat,
    light_cap: bool,
}

fn align(v: &mut Vec<u8>, a: usize) {
    while v.len() % a != 0 {
        v.push(0);
    }
}

/// Stencil counts as a heat map: 0 black, then blue -> green -> yellow -> red by count.
pub fn stencil_heatmap(s: &[u8]) -> Vec<u8> {
    let ramp = [[0u8, 0, 0], [40, 60, 220], [30, 200, 80], [240, 220, 40], [230, 40, 30], [255, 255, 255]];
    s.iter()
        .flat_map(|&c| {
            let rgb = ramp[(c as usize).min(ramp.len() - 1)];
            [rgb[0], rgb[1], rgb[2], 255]
        })
        .collect()
}

/// Uploads `data` into a device-local buffer through a staging buffer.
fn upload(ctx: &Context, name: &str, data: &[u8], usage: vk::BufferUsageFlags) -> Result<Buffer> {
    let mut staging = Buffer::with_data(ctx, "staging", data, vk::BufferUsageFlags::TRANSFER_SRC)?;
    let dst = Buffer::new(ctx, name, data.len() as u64, usage | vk::BufferUsageFlags::TRANSFER_DST, MemoryLocation::GpuOnly)?;
    let r = ctx.one_shot(|cb| {
        // SAFETY: both buffers are at least `data.len()` bytes and alive until after the wait.
        unsafe {
            ctx.device.cmd_copy_buffer(
                cb,
                staging.raw,
                dst.raw,
                &[vk::BufferCopy { src_offset: 0, dst_offset: 0, size: data.len() as u64 }],
            )
        };
    });
    staging.destroy(ctx);
    r.map(|_| dst)
}

/// `depth_bounds`: when the device has the feature, the determination and illumination
/// pipelines test the stored depth against the light's depth range (set per light, dynamic
/// state; [0, 1] when the light is unbounded, which passes everything).
fn create_pipelines(
    ctx: &Context,
    layouts: &[vk::PipelineLayout; 5],
    depth_mode: DepthMode,
    depth_bounds: bool,
    transmit_format: vk::Format,
) -> Result<Pipelines> {
    let df = ctx.depth_format;
    let gbuffer_formats = [ACCUM_FORMAT, ALBEDO_FORMAT, NORMAL_FORMAT, POSITION_FORMAT];
    let mut g = PipelineDesc::new(shaders::GBUFFER_VERT, layouts[0], df);
    g.fragment = Some(shaders::GBUFFER_FRAG);
    g.vertex_stride = 40;
    g.attributes = &[(0, vk::Format::R32G32B32_SFLOAT, 0), (1, vk::Format::R32G32B32_SFLOAT, 12), (2, vk::Format::R32G32B32_SFLOAT, 24)];
    g.color_formats = &gbuffer_formats;
    g.depth_test = true;
    g.depth_write = true;
    g.depth_compare = vk::CompareOp::LESS;
    g.cull = vk::CullModeFlags::BACK;
    let gbuffer = pipeline::create(ctx, &g)?;
    g.cull = vk::CullModeFlags::NONE;
    let gbuffer_two_sided = pipeline::create(ctx, &g)?;

    use vk::StencilOp as S;
    let mut s = PipelineDesc::new(shaders::SHADOW_VERT, layouts[1], df);
    s.vertex_stride = 16;
    s.attributes = &[(0, vk::Format::R32G32B32A32_SFLOAT, 0)];
    s.depth_test = true;
    s.depth_compare = vk::CompareOp::LESS;
    s.depth_clamp = depth_mode == DepthMode::Clamp;
    s.depth_bounds = depth_bounds;
    s.stencil = Some((pipeline::stencil_ops(S::INCREMENT_AND_WRAP, S::KEEP), pipeline::stencil_ops(S::DECREMENT_AND_WRAP, S::KEEP)));
    let zpass = pipeline::create(ctx, &s)?;
    s.stencil = Some((pipeline::stencil_ops(S::KEEP, S::DECREMENT_AND_WRAP), pipeline::stencil_ops(S::KEEP, S::INCREMENT_AND_WRAP)));
    let zfail = pipeline::create(ctx, &s)?;
    s.depth_compare = vk::CompareOp::NEVER;
    let zfail_cap = pipeline::create(ctx, &s)?;

    // Float counter: the same volumes, counted in a float target by additive blending. The depth
    // test selects exactly the fragments the stencil ops would act on.
    let count_fmt = [COUNT_FORMAT];
    let mut c = s.clone();
    c.fragment = Some(shaders::COUNT_FRAG);
    c.color_formats = &count_fmt;
    c.blend = Blend::Additive;
    c.stencil = None;
    c.depth_compare = vk::CompareOp::LESS;
    let count_zpass = pipeline::create(ctx, &c)?;
    c.depth_compare = vk::CompareOp::GREATER_OR_EQUAL;
    let count_zfail = pipeline::create(ctx, &c)?;
    c.depth_compare = vk::CompareOp::ALWAYS;
    let count_cap = pipeline::create(ctx, &c)?;

    // GPU-only edge quads: faces like light caps (NEVER / ALWAYS), quads like sides.
    let eq_attrs = [(0, vk::Format::R32G32B32_SFLOAT, 0), (1, vk::Format::R32G32B32A32_SFLOAT, 12)];
    let mut e = s.clone();
    e.vertex = shaders::EDGEQUAD_VERT;
    e.vertex_stride = 32;
    e.attributes = &eq_attrs;
    e.depth_compare = vk::CompareOp::NEVER;
    let eq_faces = pipeline::create(ctx, &e)?;
    e.depth_compare = vk::CompareOp::LESS;
    let eq_sides = pipeline::create(ctx, &e)?;
    let mut ec = c.clone();
    ec.vertex = shaders::EDGEQUAD_VERT;
    ec.vertex_stride = 32;
    ec.attributes = &eq_attrs;
    ec.depth_compare = vk::CompareOp::ALWAYS;
    let eq_faces_count = pipeline::create(ctx, &ec)?;
    ec.depth_compare = vk::CompareOp::GREATER_OR_EQUAL;
    let eq_sides_count = pipeline::create(ctx, &ec)?;

    let accum = [ACCUM_FORMAT];
    let mut v = PipelineDesc::new(shaders::SHADOW_VERT, layouts[1], df);
    v.fragment = Some(shaders::VOLUME_FRAG);
    v.vertex_stride = 16;
    v.attributes = &[(0, vk::Format::R32G32B32A32_SFLOAT, 0)];
    v.color_formats = &accum;
    v.blend = Blend::Alpha;
    v.depth_test = true;
    v.depth_compare = vk::CompareOp::LESS;
    v.depth_clamp = depth_mode == DepthMode::Clamp;
    let volumes = pipeline::create(ctx, &v)?;

    let mut i = PipelineDesc::new(shaders::FULLSCREEN_VERT, layouts[2], df);
    i.fragment = Some(shaders::ILLUMINATE_FRAG);
    i.color_formats = &accum;
    i.blend = Blend::Additive;
    i.depth_bounds = depth_bounds;
    i.stencil = Some((pipeline::stencil_equal(0), pipeline::stencil_equal(0)));
    let illuminate = pipeline::create(ctx, &i)?;
    i.fragment = Some(shaders::ILLUMINATE_COUNT_FRAG);
    i.stencil = None;
    let illuminate_count = pipeline::create(ctx, &i)?;
    i.fragment = Some(shaders::ILLUMINATE_COUNT_T_FRAG);
    let illuminate_count_t = pipeline::create(ctx, &i)?;
    i.fragment = Some(shaders::ILLUMINATE_T_FRAG);
    i.stencil = Some((pipeline::stencil_equal(0), pipeline::stencil_equal(0)));
    let illuminate_t = pipeline::create(ctx, &i)?;

    // Transparent casters' light-intensity map: [multiplicative, log] x [z-pass, z-fail].
    let map_fmt = [transmit_format];
    let mut tm = c.clone();
    tm.color_formats = &map_fmt;
    let mut transmit = [[vk::Pipeline::null(); 2]; 2];
    for (li, (frag, blend)) in
        [(shaders::TRANSMIT_FRAG, Blend::Multiply), (shaders::TRANSMIT_LOG_FRAG, Blend::Additive)].into_iter().enumerate()
    {
        tm.fragment = Some(frag);
        tm.blend = blend;
        for (zi, cmp) in [vk::CompareOp::LESS, vk::CompareOp::GREATER_OR_EQUAL].into_iter().enumerate() {
            tm.depth_compare = cmp;
            transmit[li][zi] = pipeline::create(ctx, &tm)?;
        }
    }

    // Transparent casters drawn forward over the lit scene.
    let mut tp = PipelineDesc::new(shaders::TRANSPARENT_VERT, layouts[4], df);
    tp.fragment = Some(shaders::TRANSPARENT_FRAG);
    tp.vertex_stride = 40;
    tp.attributes = &[
        (0, vk::Format::R32G32B32_SFLOAT, 0),
        (1, vk::Format::R32G32B32_SFLOAT, 12),
        (2, vk::Format::R32G32B32_SFLOAT, 24),
        (3, vk::Format::R32_SFLOAT, 36),
    ];
    tp.color_formats = &accum;
    tp.depth_test = true;
    tp.depth_compare = vk::CompareOp::LESS;
    tp.blend = Blend::Over;
    let transparent_over = pipeline::create(ctx, &tp)?;
    tp.blend = Blend::Additive;
    let transparent_light = pipeline::create(ctx, &tp)?;

    let out = [OUTPUT_FORMAT];
    let mut t = PipelineDesc::new(shaders::FULLSCREEN_VERT, layouts[3], vk::Format::UNDEFINED);
    t.fragment = Some(shaders::TONEMAP_FRAG);
    t.color_formats = &out;
    let tonemap = pipeline::create(ctx, &t)?;
    Ok(Pipelines {
        gbuffer,
        gbuffer_two_sided,
        zpass,
        zfail,
        zfail_cap,
        count_zpass,
        count_zfail,
        count_cap,
        eq_faces,
        eq_sides,
        eq_faces_count,
        eq_sides_count,
        illuminate,
        illuminate_count,
        illuminate_t,
        illuminate_count_t,
        transmit,
        transparent_over,
        transparent_light,
        volumes,
        tonemap,
    })
}

impl Drop for Renderer {
    fn drop(&mut self) {
        self.destroy_resources();
    }
}

impl Renderer {
    fn destroy_resources(&mut self) {
        let ctx = &self.ctx;
        // SAFETY: wait for the GPU, then destroy everything this renderer created; the context
        // (declared last) is dropped after this body.
        unsafe {
            let _ = ctx.device.device_wait_idle();
            let d = &ctx.device;
            let p = &self.pipes;
            let mut all = vec![
                p.gbuffer,
                p.gbuffer_two_sided,
                p.zpass,
                p.zfail,
                p.zfail_cap,
                p.count_zpass,
                p.count_zfail,
                p.count_cap,
                p.eq_faces,
                p.eq_sides,
                p.eq_faces_count,
                p.eq_sides_count,
                p.illuminate,
                p.illuminate_count,
                p.illuminate_t,
                p.illuminate_count_t,
                p.transparent_over,
                p.transparent_light,
                p.volumes,
                p.tonemap,
            ];
            all.extend(p.transmit.iter().flatten());
            for pipe in all {
                d.destroy_pipeline(pipe, None);
            }
            for l in self.layouts {
                d.destroy_pipeline_layout(l, None);
            }
            d.destroy_sampler(self.sampler, None);
            d.destroy_query_pool(self.query_pool, None);
            d.destroy_fence(self.fence, None);
            d.free_command_buffers(ctx.pool, &[self.cmd]);
        }
        for set in &mut self.sets {
            set.destroy(ctx);
        }
        if let Some(mut sm) = self.shadow_mapper.take() {
            sm.destroy(ctx);
        }
        for mut eq in self.edge_quads.drain(..).flatten() {
            eq.vertices.destroy(ctx);
            eq.indices.destroy(ctx);
        }
        if let Some(mut ss) = self.self_shadow.take() {
            ss.destroy(ctx);
        }
        self.targets.destroy(ctx);
        self.scene_vertices.destroy(ctx);
        for chunks in &mut self.gpu_casters {
            for c in chunks {
                c.vertices.destroy(ctx);
            }
        }
        if let Some(mut s) = self.stream.take() {
            s.destroy(ctx);
        }
        for b in &mut self.readback {
            b.destroy(ctx);
        }
    }
}
