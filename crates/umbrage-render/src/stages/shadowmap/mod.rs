//! The baseline users would otherwise pick: shadow mapping with 3x3 percentage-closer
//! filtering (the textbook chapter), on the same frame, measured against the same reference.
//!
//! Per light, the opaque shadow casters' depth is rendered from the light (directional: one
//! orthographic map fitted to the casters' bounding sphere; spot: one perspective map over the
//! cone; point: six 90-degree faces, all in one rendering instance: 3 x 2 tiles of an atlas,
//! or with [`CubeFaces::Multiview`] six layers rendered as six views of each draw). Each caster
//! mesh reaches only the faces whose frustum its bounding sphere meets (atlas: it is drawn once
//! per such face; multiview: it is drawn once, and its vertex shader places it outside every
//! other view), and a point or spot light's near and far planes hug its casters.
//! One full-screen lookup pass per light then writes, for every visible point, the fraction
//! of PCF taps that see a nearer occluder into the float counter target (each point picks
//! its cube face in the shader; the comparison is a hardware compare sampler's), and the
//! counter's illumination pass lights the points whose fraction is below one half. Biases:
//! slope-scaled depth bias when rendering the map, a small compare bias, and a normal offset
//! of about a texel, the usual trade between acne and peter-panning — so unlike shadow
//! volumes, its error is not zero, and the bench says how large it is.
//!
//! Inputs / outputs per light (called by `frame/record.rs` after `determine::begin_float`, before `determine::record`):
//! - `record_maps`: writes the face table (a transfer), then the maps (every layer),
//!   `UNDEFINED -> DEPTH_STENCIL_ATTACHMENT_OPTIMAL`, CLEAR (depth 1)/STORE, the opaque casters' depth; then
//!   `-> SHADER_READ_ONLY_OPTIMAL`.
//! - `record_lookup`: reads `normal` and `position` (`SHADER_READ_ONLY_OPTIMAL`, left by `gbuffer`), the maps
//!   (`SHADER_READ_ONLY_OPTIMAL`, a 2D array view, compare sampler) and the face table; writes `count` in `COLOR_ATTACHMENT_OPTIMAL`
//!   (set from `UNDEFINED` by `determine::begin_float`), CLEAR to 0 inside the scissor, STORE, additive; no depth-stencil
//!   attachment. `determine::finish` (`CountInto::External`) then takes `count` to `SHADER_READ_ONLY_OPTIMAL`.

use crate::shaders;
use crate::targets::{Targets, COUNT_FORMAT};
use crate::{CubeFaces, Pcf};
use ash::vk;
use faces::{sphere_in_frustum, Casters, Face, FaceRow, Layout, MeshRange, FACES_BYTES};
use glam::DVec3;
use umbrage::error::{Error, Result};
use umbrage::gpu::descriptors::{pipeline_layout, Binding, DescriptorSet};
use umbrage::gpu::pipeline::{self, Blend, PipelineDesc};
use umbrage::gpu::resources::{cleared_depth_stencil, memory_barrier, transition};
use umbrage::gpu::{Buffer, Context, Image};
use umbrage_scene::Scene;

mod faces;

/// The shadow maps' depth format.
pub const MAP_FORMAT: vk::Format = vk::Format::D32_SFLOAT;

/// The view mask of a point light's six faces rendered as views (bit `i`: face `i`, layer `i`).
const ALL_FACES: u32 = 0b11_1111;

/// Why [`CubeFaces::Multiview`] cannot run on this device, if it cannot: no `multiview`
/// feature, or a driver known to render it wrongly ([`umbrage::gpu::quirks::multiview_defect`]).
pub(crate) fn multiview_refusal(ctx: &Context) -> Option<Error> {
    let why = if !ctx.features.multiview {
        format!("{} does not offer the multiview feature (Vulkan 1.1 core)", ctx.info.name)
    } else {
        umbrage::gpu::quirks::multiview_defect(&ctx.info)?
    };
    Some(Error::Unsupported(format!("--cube multiview: {why}; use --cube atlas (the same maps, a draw per face)")))
}

/// The shadow-map baseline's GPU objects.
pub struct ShadowMapper {
    /// Texels per side of one map (a point light uses 3 x 2 of them in an atlas).
    pub size: u32,
    /// Where a point light's six faces go.
    pub cube: CubeFaces,
    /// The maps: a 3 x 2 atlas in one layer, or six layers of one map each (multiview).
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
    /// The six-view map pass ([`CubeFaces::Multiview`] only).
    views: Option<Views>,
}

/// The multiview map pass's objects: the face table's set (vertex stage), its layout (push:
/// the caster's view mask) and the pipeline (view mask 0b111111).
struct Views {
    set: DescriptorSet,
    layout: vk::PipelineLayout,
    pipeline: vk::Pipeline,
}

/// One light's lookup: where the light is, the pass's scissor, how the taps are read.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Lookup {
    /// The frame's eye-relative light ([`LightPush::light_pos`](crate::push::LightPush)).
    pub light_pos: [f32; 4],
    /// The light's scissor: the pass's render area.
    pub scissor: vk::Rect2D,
    /// Nine taps or four gathers (the same result).
    pub pcf: Pcf,
}

/// `shadowmap_lookup.frag`'s push constants.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct LookupPush {
    /// Eye-relative light position (w = 1) or towards-light direction (w = 0).
    light: [f32; 4],
    /// x: faces (1 or 6), y, z: 1 / layer width, height.
    params: [f32; 4],
}

/// One light's rendered maps, for [`ShadowMapper::record_lookup`].
pub(crate) struct LightMaps {
    faces: Vec<Face>,
}

/// The objects `ShadowMapper::new` made so far, released if a later step fails.
#[derive(Default)]
struct Partial {
    buffers: Vec<Buffer>,
    images: Vec<Image>,
    sampler: Option<vk::Sampler>,
    sets: Vec<DescriptorSet>,
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
        for mut s in self.sets.drain(..) {
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
    /// relative to the camera (rebuilt by the renderer when either moves), a point light's
    /// faces laid out as `cube` says ([`CubeFaces::Multiview`] needs the device's `multiview`).
    pub fn new(
        ctx: &Context,
        scene: &Scene,
        targets: &Targets,
        (size, cube): (u32, CubeFaces),
        sampler: vk::Sampler,
    ) -> Result<ShadowMapper> {
        if !(16..=8192).contains(&size) {
            return Err(Error::argument("shadow map size", format!("{size} is out of range (16..=8192)")));
        }
        if let Some(e) = (cube == CubeFaces::Multiview).then(|| multiview_refusal(ctx)).flatten() {
            return Err(e);
        }
        let mut partial = Partial::default();
        match Self::build(ctx, scene, targets, (size, cube), sampler, &mut partial) {
            Ok(m) => Ok(m),
            Err(e) => {
                partial.release(ctx);
                Err(e)
            }
        }
    }

    fn build(
        ctx: &Context,
        scene: &Scene,
        targets: &Targets,
        (size, cube): (u32, CubeFaces),
        sampler: vk::Sampler,
        made: &mut Partial,
    ) -> Result<ShadowMapper> {
        let Casters { vertices: pos, meshes, bounds } = Casters::of(scene);
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
        let (extent, layers) = match cube {
            CubeFaces::Atlas => (vk::Extent2D { width: 3 * size, height: 2 * size }, 1),
            CubeFaces::Multiview => (vk::Extent2D { width: size, height: size }, 6),
        };
        let atlas = Image::new_array(
            ctx,
            "shadow maps",
            MAP_FORMAT,
            extent,
            layers,
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
        made.sets.push(set);
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
        if cube == CubeFaces::Multiview {
            // The six-view pass: the atlas pass's state, its matrices from the face table.
            made.sets.push(DescriptorSet::with_stages(ctx, &[Binding::StorageBuffer(faces_raw)], vk::ShaderStageFlags::VERTEX)?);
            made.layouts.push(pipeline_layout(ctx, &[made.sets[1].layout], 4, vk::ShaderStageFlags::VERTEX)?);
            m.vertex = shaders::SHADOWMAP_MULTIVIEW_WGSL;
            m.layout = made.layouts[2];
            m.view_mask = ALL_FACES;
            made.pipelines.push(pipeline::create(ctx, &m)?);
        }
        // Everything made: hand the objects over.
        let (map_pipeline, lookup_pipelines) = (made.pipelines[0], [made.pipelines[1], made.pipelines[2]]);
        let views = match cube {
            CubeFaces::Atlas => None,
            CubeFaces::Multiview => {
                let set = made.sets.pop().ok_or_else(|| Error::Internal("shadow-map views set not made".into()))?;
                Some(Views { set, layout: made.layouts[2], pipeline: made.pipelines[3] })
            }
        };
        made.pipelines.clear();
        made.layouts.clear();
        made.sampler = None;
        let set = made.sets.pop().ok_or_else(|| Error::Internal("shadow-map set not made".into()))?;
        let atlas = made.images.pop().ok_or_else(|| Error::Internal("shadow-map atlas not made".into()))?;
        let faces = made.buffers.pop().ok_or_else(|| Error::Internal("shadow-map faces not made".into()))?;
        let casters = made.buffers.pop();
        Ok(ShadowMapper {
            size,
            cube,
            atlas,
            casters,
            meshes,
            bounds,
            faces,
            compare_sampler,
            set,
            layouts,
            map_pipeline,
            lookup_pipelines,
            views,
        })
    }

    /// Writes light `light`'s face table, renders its maps (one rendering instance; each
    /// caster mesh only into the faces it can be seen in) and returns the faces for
    /// [`ShadowMapper::record_lookup`]. Leaves the maps in SHADER_READ_ONLY_OPTIMAL.
    pub(crate) fn record_maps(&self, ctx: &Context, cb: vk::CommandBuffer, light: &umbrage_scene::Light, eye: DVec3) -> LightMaps {
        let layout = Layout { meshes: &self.meshes, bounds: self.bounds, size: self.size, cube: self.cube };
        let faces = layout.faces(light, eye);
        let mut rows = [FaceRow::default(); 6];
        for (row, f) in rows.iter_mut().zip(&faces) {
            *row = f.row(self.size);
        }
        // The previous light's map pass (multiview) and lookup read the table.
        let readers = vk::PipelineStageFlags2::VERTEX_SHADER | vk::PipelineStageFlags2::FRAGMENT_SHADER;
        let shader_read = (readers, vk::AccessFlags2::SHADER_STORAGE_READ);
        let transfer_write = (vk::PipelineStageFlags2::ALL_TRANSFER, vk::AccessFlags2::TRANSFER_WRITE);
        memory_barrier(ctx, cb, shader_read, transfer_write);
        // SAFETY: `cb` is recording outside any rendering instance; the table is this
        // mapper's, and its readers finished (the barrier above).
        unsafe { ctx.device.cmd_update_buffer(cb, self.faces.raw, 0, bytemuck::cast_slice(&rows)) };
        memory_barrier(ctx, cb, transfer_write, shader_read);
        transition(ctx, cb, &self.atlas, vk::ImageLayout::UNDEFINED, vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL);
        let map_att = cleared_depth_stencil(self.atlas.view, (1.0, 0));
        let one = vk::Rect2D { offset: vk::Offset2D { x: 0, y: 0 }, extent: vk::Extent2D { width: self.size, height: self.size } };
        let info = vk::RenderingInfo::default().layer_count(1).depth_attachment(&map_att);
        match (&self.views, faces.len()) {
            // A point light's six faces as six views of each draw.
            (Some(views), 6) => {
                // SAFETY: as above; every handle is alive, and the views' pipeline was made
                // for this view mask.
                unsafe {
                    ctx.device.cmd_begin_rendering(cb, &info.render_area(one).view_mask(ALL_FACES));
                    self.record_views(ctx, cb, views, &faces);
                    ctx.device.cmd_end_rendering(cb);
                }
            }
            // One map (layer 0, tile 0), or six tiles of the atlas.
            _ => {
                let area = if faces.len() == 1 { one } else { vk::Rect2D { offset: one.offset, extent: self.atlas.extent } };
                // SAFETY: as above.
                unsafe {
                    ctx.device.cmd_begin_rendering(cb, &info.render_area(area));
                    self.record_tiles(ctx, cb, &faces);
                    ctx.device.cmd_end_rendering(cb);
                }
            }
        }
        transition(ctx, cb, &self.atlas, vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL, vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL);
        LightMaps { faces }
    }

    /// Draws each caster mesh into each face (a tile of layer 0) whose frustum it meets: a
    /// viewport, a scissor and the face's matrix per face.
    ///
    /// # Safety
    /// `cb` is inside the rendering instance of the maps (no view mask).
    unsafe fn record_tiles(&self, ctx: &Context, cb: vk::CommandBuffer, faces: &[Face]) {
        let d = &ctx.device;
        let Some(b) = &self.casters else { return };
        // SAFETY: the caller's contract; every handle is alive.
        unsafe {
            d.cmd_bind_pipeline(cb, vk::PipelineBindPoint::GRAPHICS, self.map_pipeline);
            d.cmd_bind_vertex_buffers(cb, 0, &[b.raw], &[0]);
            for f in faces {
                let visible: Vec<&MeshRange> = self.meshes.iter().filter(|m| sphere_in_frustum(&f.view_proj, m.center, m.radius)).collect();
                if visible.is_empty() {
                    continue;
                }
                let sz = self.size as f32;
                let vp = vk::Viewport { x: f.tile[0] as f32, y: f.tile[1] as f32, width: sz, height: sz, min_depth: 0.0, max_depth: 1.0 };
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
    }

    /// Draws each caster mesh once into the six views, with the mask of the faces whose
    /// frustum it meets (the vertex shader places it outside the others).
    ///
    /// # Safety
    /// `cb` is inside the rendering instance of the maps with view mask [`ALL_FACES`]; the
    /// face table holds `faces`.
    unsafe fn record_views(&self, ctx: &Context, cb: vk::CommandBuffer, views: &Views, faces: &[Face]) {
        let d = &ctx.device;
        let Some(b) = &self.casters else { return };
        let full = vk::Rect2D { offset: vk::Offset2D { x: 0, y: 0 }, extent: self.atlas.extent };
        let sz = self.size as f32;
        // SAFETY: the caller's contract; every handle is alive.
        unsafe {
            d.cmd_bind_pipeline(cb, vk::PipelineBindPoint::GRAPHICS, views.pipeline);
            d.cmd_bind_descriptor_sets(cb, vk::PipelineBindPoint::GRAPHICS, views.layout, 0, &[views.set.set], &[]);
            d.cmd_bind_vertex_buffers(cb, 0, &[b.raw], &[0]);
            d.cmd_set_viewport(cb, 0, &[vk::Viewport { x: 0.0, y: 0.0, width: sz, height: sz, min_depth: 0.0, max_depth: 1.0 }]);
            d.cmd_set_scissor(cb, 0, &[full]);
            for m in &self.meshes {
                let mask = faces
                    .iter()
                    .enumerate()
                    .filter(|(_, f)| sphere_in_frustum(&f.view_proj, m.center, m.radius))
                    .fold(0u32, |mask, (i, _)| mask | 1 << i);
                if mask == 0 {
                    continue;
                }
                d.cmd_push_constants(cb, views.layout, vk::ShaderStageFlags::VERTEX, 0, &mask.to_ne_bytes());
                d.cmd_draw(cb, m.count, 1, m.first, 0);
            }
        }
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
        let count_att = [vk::RenderingAttachmentInfo::default()
            .image_view(targets.count.view)
            .image_layout(vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL)
            .load_op(vk::AttachmentLoadOp::CLEAR)
            .store_op(vk::AttachmentStoreOp::STORE)
            .clear_value(vk::ClearValue { color: vk::ClearColorValue { float32: [0.0; 4] } })];
        let (aw, ah) = (self.atlas.extent.width as f32, self.atlas.extent.height as f32);
        let push = LookupPush { light: light_pos, params: [faces.len() as f32, 1.0 / aw, 1.0 / ah, 0.0] };
        let (w, h) = (targets.extent.width as f32, targets.extent.height as f32);
        // SAFETY: as `record_maps`; the face table `record_maps` wrote is visible (its barrier).
        unsafe {
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
        if let Some(mut v) = self.views.take() {
            // SAFETY: as above.
            unsafe {
                ctx.device.destroy_pipeline(v.pipeline, None);
                ctx.device.destroy_pipeline_layout(v.layout, None);
            }
            v.set.destroy(ctx);
        }
        self.atlas.destroy(ctx);
        self.faces.destroy(ctx);
        if let Some(mut b) = self.casters.take() {
            b.destroy(ctx);
        }
    }
}
