//! The renderer: umbrage's own host of the [`ShadowPass`]. It owns the Vulkan context, the
//! scene's geometry, the targets and the frame's pipelines, and records the paper's frame
//! (G-buffer -> per light determination + illumination -> final pass) into one command buffer
//! per ring slot, with frames in flight.

use super::frame_output::{parse, CaptureView, FrameOutput};
use super::guard::{Destroy, Guard, Owned};
use super::options::*;
use super::pipelines::FramePipelines;
use super::push::LightPush;
use super::readback::Layout;
use super::scene_gpu::{SceneGeometry, Sidedness};
use super::sphere_gpu::SphereGeometry;
use super::stages::selfshadow::SelfShadow;
use super::stages::shadowmap::ShadowMapper;
use super::stages::{debug, Rec};
use super::targets::*;
use super::technique::RenderTechnique;
use super::timing::Span;
mod area;
mod checks;
mod locations;
mod slots;
use checks::{check_options, check_spheres, pass_settings};
use locations::DepthLocations;
use slots::FrameSlot;
mod memory;
mod motion;
pub use memory::{largest_device_heap, MemoryEstimate};
mod present;
mod record;
mod stats;
mod techniques;

use ash::vk;
use glam::{Mat4, Vec3};
use std::collections::VecDeque;
use std::time::Instant;
use umbrage::error::{Error, Result};
use umbrage::gpu::Context;
use umbrage::pass::{self as sp, CasterId, PassSettings, PreparedFrame, ShadowPass, ShadowPassDesc, ShadowView};
use umbrage::shadow::Caster;
use umbrage_scene::Scene;

/// A submitted frame, to hand to [`Renderer::finish`].
#[derive(Debug)]
#[must_use = "a submitted frame's output is read with Renderer::finish"]
pub struct FrameTicket {
    slot: usize,
    serial: u64,
}

/// Frames rendered back to back with frames in flight ([`Renderer::throughput`]).
#[derive(Clone, Debug)]
pub struct Throughput {
    /// Frames rendered.
    pub frames: usize,
    /// Frames per second with frames overlapping (CPU planning of frame N+1 during the GPU
    /// work of frame N).
    pub fps: f64,
    /// Median per-frame latency, submit to fence, ms.
    pub latency_ms: f64,
}

/// What a slot remembers about the frame in flight in it.
struct InFlight {
    serial: u64,
    frame: PreparedFrame,
    layout: Layout,
    float_counts: bool,
    eye: glam::DVec3,
    /// The inverse of the G-buffer's eye-relative view-projection (a multisampled capture's
    /// sample rays).
    clip_to_rel: glam::DMat4,
    spans: FrameSpans,
    wall: Instant,
    record_ms: f64,
    settings: FrameSettings,
}

#[derive(Default)]
struct FrameSpans {
    /// The frame's acceleration-structure builds (ray query).
    accel: Span,
    /// The GPU possible silhouettes of every light (`Technique::Compute`).
    silhouettes: Span,
    depth: Span,
    frame: Span,
    shadow: Vec<Span>,
    /// Per light, the shadow-map baseline's map rendering (a prefix of its `shadow` span).
    shadow_map: Vec<Span>,
    illuminate: Vec<Span>,
}

/// umbrage's renderer (see the module docs).
///
/// Its parts and the context that made them are owned together (`guard::Owned`): dropping the
/// renderer or [`Renderer::into_context`] runs the one teardown of `Parts` and drops every
/// part whole, then the context.
pub struct Renderer {
    /// What the next frame does (technique, counter, index format, view, capture); checked
    /// against the device before every frame.
    pub settings: FrameSettings,
    own: Owned<Parts>,
}

/// Everything a renderer holds besides its settings and its context. Its Vulkan objects are
/// destroyed in one place, [`Parts`]'s [`Destroy`]; everything else is released by dropping it
/// as a whole (a field added later included).
struct Parts {
    /// The scene as rendered: its `lights` are the point lights of this frame, every area
    /// light split into its samples ([`umbrage::geom::area`]).
    scene: Scene,
    /// The scene's lights as given (area lights whole).
    source_lights: Vec<umbrage_scene::Light>,
    /// The frame the area-light samples in `scene.lights` were drawn for (`None`: the fixed
    /// pattern).
    samples_for: Option<u64>,
    config: RenderConfig,
    /// Drops itself (its own device and allocator handles), before the context.
    pass: ShadowPass,
    /// Per scene mesh, its caster in the pass (`None`: casts no shadow).
    caster_ids: Vec<Option<CasterId>>,
    has_transparent: bool,
    geo: SceneGeometry,
    spheres: SphereGeometry,
    targets: Targets,
    pipes: FramePipelines,
    self_shadow: Option<SelfShadow>,
    /// The shadow-map baseline and the scene version it was built for.
    shadow_mapper: Option<(ShadowMapper, u64)>,
    /// Baselines of other map sizes built earlier and kept (a bench alternating techniques
    /// neither rebuilds them nor times a freshly allocated atlas); dropped when stale.
    spare_shadow_mappers: Vec<(ShadowMapper, u64)>,
    /// The ray-query surface offset (2e-5 of the scene's diagonal, the CPU reference's) and the
    /// scene version it was computed for.
    ray_offset: Option<(u64, f32)>,
    /// GPU ms of the last frame that built ray-query bottom levels (its acceleration span).
    blas_build_ms: std::cell::Cell<f64>,
    slots: Vec<FrameSlot>,
    next_slot: usize,
    serial: u64,
    /// Bumped when the camera or a mesh moves (the shadow maps are rebuilt then).
    scene_version: u64,
    /// Per sample, where the device evaluates a multisampled draw's depth (pixel units from
    /// the pixel's top-left corner): the standard ones, or as measured
    /// ([`Renderer::use_sample_depth_locations`]); a multisampled capture's positions are found
    /// there.
    depth_locations: DepthLocations,
}

impl Destroy for Parts {
    unsafe fn destroy(&mut self, ctx: &Context) {
        // SAFETY: forwarded to the caller's contract (the device is idle); each part is
        // destroyed once, the pass drops itself.
        unsafe {
            self.slots.destroy(ctx);
            self.pipes.destroy(ctx);
            for (sm, _) in self.shadow_mapper.iter_mut().chain(self.spare_shadow_mappers.iter_mut()) {
                sm.destroy(ctx);
            }
            self.self_shadow.destroy(ctx);
            self.targets.destroy(ctx);
            self.geo.destroy(ctx);
            self.spheres.destroy(ctx);
        }
    }
}

/// A failed [`Renderer::try_new`]: the error, and the context handed back whole (everything
/// the construction had made is released).
pub struct NewError {
    /// Why the renderer could not be made.
    pub error: Error,
    /// The context the renderer was to own.
    pub context: Context,
}

impl std::fmt::Debug for NewError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("NewError").field("error", &self.error).finish_non_exhaustive()
    }
}

impl Renderer {
    /// A renderer for `scene`: its casters prepared and uploaded, targets of the options'
    /// size, pipelines for its fixed settings.
    pub fn new(ctx: Context, scene: Scene, opts: RenderOptions) -> Result<Renderer> {
        Renderer::try_new(ctx, scene, opts).map_err(|e| e.error)
    }

    /// [`Renderer::new`], handing the context back when it fails (to try other options, or
    /// to check that nothing was left behind).
    pub fn try_new(ctx: Context, scene: Scene, opts: RenderOptions) -> std::result::Result<Renderer, Box<NewError>> {
        let settings = opts.settings();
        match Parts::new(&ctx, scene, opts) {
            Ok(parts) => Ok(Renderer { settings, own: Owned::new(parts, ctx) }),
            Err(error) => Err(Box::new(NewError { error, context: ctx })),
        }
    }

    /// Tears the renderer down and hands back its context (to render another scene).
    pub fn into_context(self) -> Context {
        self.own.into_context()
    }

    /// The scene as it stands (camera, lights and transforms included). Its `lights` are the
    /// point lights the frames render: every area light split into its samples (those of the
    /// last submitted frame under `jitter`); [`Renderer::source_lights`] has them whole.
    pub fn scene(&self) -> &Scene {
        &self.own.parts.scene
    }
    /// The fixed configuration.
    pub fn config(&self) -> &RenderConfig {
        &self.own.parts.config
    }
    /// The Vulkan context.
    pub fn context(&self) -> &Context {
        &self.own.ctx
    }
    /// The shadow pass this renderer hosts.
    pub fn shadow_pass(&self) -> &ShadowPass {
        &self.own.parts.pass
    }
    /// The prepared casters (shadow-casting meshes, in scene order).
    pub fn casters(&self) -> &[Caster] {
        self.own.parts.pass.casters()
    }

    /// World -> clip with the configured depth mode (used by the planner for its frustum tests).
    fn projection(&self) -> Mat4 {
        let aspect = self.own.parts.config.width as f32 / self.own.parts.config.height as f32;
        match self.own.parts.config.depth_mode {
            DepthMode::Infinite => self.own.parts.scene.camera.proj_infinite(aspect),
            DepthMode::Clamp => {
                // Far plane just beyond the scene: everything further is clamped to depth 1.
                let eye = self.own.parts.scene.camera.eye;
                let spheres =
                    self.own.parts.scene.spheres.iter().map(|s| (s.sphere.center.distance(eye.as_dvec3()) + s.sphere.radius) as f32);
                let far = self
                    .own
                    .parts
                    .scene
                    .meshes
                    .iter()
                    .flat_map(|m| m.world_bounds().corners())
                    .map(|c| c.distance(eye))
                    .chain(spheres)
                    .fold(1.0f32, f32::max)
                    * 1.5;
                self.own.parts.scene.camera.proj_finite(aspect, far.max(self.own.parts.scene.camera.near * 2.0))
            }
        }
    }

    /// Renders one frame and reads it back: [`submit`](Self::submit) then
    /// [`finish`](Self::finish).
    pub fn render(&mut self) -> Result<FrameOutput> {
        let t = self.submit()?;
        self.finish(t)
    }

    /// Renders `frames` frames back to back, `frames_in_flight` of them overlapping, and
    /// reports the throughput beside the per-frame latency.
    pub fn throughput(&mut self, frames: usize) -> Result<Throughput> {
        let start = Instant::now();
        let mut queue = VecDeque::new();
        let mut latency = Vec::with_capacity(frames);
        for _ in 0..frames {
            queue.push_back(self.submit()?);
            if queue.len() >= self.own.parts.slots.len() {
                if let Some(t) = queue.pop_front() {
                    latency.push(self.wait(&t)?.wall.elapsed().as_secs_f64() * 1e3);
                }
            }
        }
        while let Some(t) = queue.pop_front() {
            latency.push(self.wait(&t)?.wall.elapsed().as_secs_f64() * 1e3);
        }
        let secs = start.elapsed().as_secs_f64();
        latency.sort_by(f64::total_cmp);
        Ok(Throughput {
            frames,
            fps: frames as f64 / secs.max(1e-9),
            latency_ms: latency.get(latency.len() / 2).copied().unwrap_or(f64::NAN),
        })
    }

    /// Plans (CPU), records and submits one frame into the next ring slot, waiting first for
    /// the frame that last used that slot.
    pub fn submit(&mut self) -> Result<FrameTicket> {
        let slot = self.own.parts.next_slot;
        self.own.parts.next_slot = (slot + 1) % self.own.parts.slots.len();
        self.retire(slot)?;
        check_options(&self.own.ctx, &self.own.parts.config, &self.settings)?;
        check_spheres(&self.own.parts.scene, &self.settings)?;
        self.update_area_samples();
        let wall = Instant::now();
        let settings = self.settings;
        let (w, h) = (self.own.parts.config.width, self.own.parts.config.height);
        let proj = self.projection();
        let cam = &self.own.parts.scene.camera;
        // Eye-relative view: rotation only, the translation is folded in f64 into every model
        // matrix (casters) and instance record (scene meshes).
        let view_rel = glam::camera::rh::view::look_at_mat4(Vec3::ZERO, cam.target - cam.eye, cam.up.normalize());
        let eye = cam.eye.as_dvec3();
        let vp_rel = (proj.as_dmat4() * view_rel.as_dmat4()).as_mat4();
        let view = ShadowView { eye, view: view_rel, proj, width: w, height: h };
        self.update_shadow_mapper(settings.technique)?;
        self.update_ray_inputs(settings.technique)?;

        // 1. The CPU work: plans and streams (the shadow-map baseline plans scissors only).
        let frame = match settings.technique {
            RenderTechnique::Pass(t) => {
                self.own.parts.pass.set_settings(PassSettings { technique: t, ..pass_settings(&settings) })?;
                self.own.parts.pass.prepare(slot, &view, &self.own.parts.scene.lights)?
            }
            RenderTechnique::ShadowMap(_) => self.own.parts.pass.prepare_culled(slot, &view, &self.own.parts.scene.lights)?,
        };
        let record_start = Instant::now();
        let instances = self.own.parts.geo.write_instances(slot, &self.own.parts.scene)?;
        let spheres = self.own.parts.spheres.write(slot, &self.own.parts.scene)?;
        let capture = settings.capture || settings.view == View::Stencil;
        let float_counts = settings.counter == Counter::Float || self.own.parts.shadow_mapper.is_some();
        let nlights = self.own.parts.scene.lights.len();
        let texel = self.own.parts.has_transparent.then_some(if self.own.parts.config.transmit_fp32 { 16 } else { 8 });
        let layout = Layout::new((w * h) as u64, capture, nlights, float_counts, texel, self.own.parts.config.samples);
        let lights: Vec<LightPush> = self
            .own
            .parts
            .scene
            .lights
            .iter()
            .map(|l| LightPush::new(l, eye, settings.transmit_log).with_shading(settings.shading))
            .collect();

        // 2. Record the paper's frame.
        let readback = self.own.parts.slots[slot].readback.ensure(&self.own.ctx, slot, layout.total)?;
        let s = &mut self.own.parts.slots[slot];
        let cb = s.cmd;
        let d = &self.own.ctx.device;
        // SAFETY: the slot's previous submission retired (`retire`), so its command buffer
        // may be reset and re-recorded.
        unsafe {
            d.reset_command_buffer(cb, vk::CommandBufferResetFlags::empty()).map_err(Error::vk("vkResetCommandBuffer"))?;
            let begin = vk::CommandBufferBeginInfo::default().flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT);
            d.begin_command_buffer(cb, &begin).map_err(Error::vk("vkBeginCommandBuffer"))?;
        }
        s.timer.begin(&self.own.ctx, cb, 6 + 5 * nlights as u32)?;
        if settings.counters {
            s.counters.begin(&self.own.ctx, cb, nlights as u32)?;
        }
        let s = &self.own.parts.slots[slot];
        let counters = settings.counters.then_some(&s.counters);
        let full = vk::Rect2D { offset: vk::Offset2D { x: 0, y: 0 }, extent: self.own.parts.targets.extent };
        let viewport = vk::Viewport { x: 0.0, y: 0.0, width: w as f32, height: h as f32, min_depth: 0.0, max_depth: 1.0 };
        let rec = Rec { ctx: &self.own.ctx, cb, full, viewport, timer: &s.timer, readback };
        let input =
            record::FrameInputs { frame: &frame, layout: &layout, instances, spheres, vp_rel, lights: &lights, float_counts, counters };
        let spans = self.record_frame(&rec, &input)?;
        // SAFETY: recording finished; the submission signals the slot's fence.
        unsafe {
            d.end_command_buffer(cb).map_err(Error::vk("vkEndCommandBuffer"))?;
            let cbs = [cb];
            let fence = self.own.parts.slots[slot].fence;
            d.reset_fences(&[fence]).map_err(Error::vk("vkResetFences"))?;
            match umbrage::gpu::fault::inject(umbrage::gpu::fault::FaultPoint::Submit) {
                Some(injected) => Err(injected),
                None => d.queue_submit(self.own.ctx.queue, &[vk::SubmitInfo::default().command_buffers(&cbs)], fence),
            }
            .map_err(Error::vk("vkQueueSubmit"))?;
        }
        let record_ms = record_start.elapsed().as_secs_f64() * 1e3;
        let serial = self.own.parts.serial;
        self.own.parts.serial += 1;
        self.own.parts.slots[slot].in_flight = Some(InFlight {
            serial,
            frame,
            layout,
            float_counts,
            eye,
            clip_to_rel: vp_rel.as_dmat4().inverse(),
            spans,
            wall,
            record_ms,
            settings,
        });
        Ok(FrameTicket { slot, serial })
    }

    /// Waits for a submitted frame and reads it back.
    pub fn finish(&mut self, ticket: FrameTicket) -> Result<FrameOutput> {
        let mut f = self.wait(&ticket)?;
        // GPU silhouettes: the triangle counts are in the indirect arguments.
        self.own.parts.pass.read_back_counts(&mut f.frame)?;
        let s = &self.own.parts.slots[ticket.slot];
        let transmit = self
            .own
            .parts
            .has_transparent
            .then_some(TransmitMode { fp32: self.own.parts.config.transmit_fp32, log: f.settings.transmit_log });
        let (width, height) = (self.own.parts.config.width, self.own.parts.config.height);
        let locations = &self.own.parts.depth_locations.at;
        let view = CaptureView { eye: f.eye, clip_to_rel: f.clip_to_rel, width, height, locations };
        let c = parse(&s.readback, &f.layout, f.float_counts, transmit, &view)?;
        let stats = self.stats(&ticket, &f)?;
        let mut out = FrameOutput {
            width: self.own.parts.config.width,
            height: self.own.parts.config.height,
            color: c.color,
            stencil: c.stencil,
            counts: c.counts,
            transmit: c.transmit,
            positions: c.positions,
            normals: c.normals,
            samples: c.samples,
            stats,
        };
        if f.settings.view == View::Stencil {
            if let Some(st) = out.stencil.first() {
                out.color = debug::stencil_heatmap(st);
            }
        }
        Ok(out)
    }

    /// Waits for the ticket's fence and takes the slot's record of it.
    fn wait(&mut self, ticket: &FrameTicket) -> Result<InFlight> {
        let s = &mut self.own.parts.slots[ticket.slot];
        match &s.in_flight {
            Some(f) if f.serial == ticket.serial => {}
            _ => return Err(umbrage::error::Misuse::Order(format!("frame {} was already finished or overwritten", ticket.serial)).into()),
        }
        // SAFETY: the fence belongs to this device and was submitted with the frame.
        unsafe { self.own.ctx.device.wait_for_fences(&[s.fence], true, u64::MAX) }.map_err(Error::vk("vkWaitForFences"))?;
        self.own.ctx.check_validation()?;
        s.in_flight.take().ok_or_else(|| umbrage::error::Misuse::Order("no frame in flight".into()).into())
    }

    /// Makes `slot` free: waits for the frame in flight in it (its output is dropped).
    fn retire(&mut self, slot: usize) -> Result<()> {
        if let Some(f) = &self.own.parts.slots[slot].in_flight {
            let t = FrameTicket { slot, serial: f.serial };
            self.wait(&t)?;
        }
        Ok(())
    }
}

impl Parts {
    /// The renderer's parts for `scene`, made step by step with `ctx`. Each step's result is
    /// guarded, so a failure at any step releases exactly what the steps before it made (the
    /// guards drop in reverse order; the pass drops itself).
    fn new(ctx: &Context, mut scene: Scene, opts: RenderOptions) -> Result<Parts> {
        let (config, settings) = (opts.config(), opts.settings());
        let source_lights = area::checked_lights(&scene.lights)?;
        scene.lights = umbrage::geom::area::expand_lights(&source_lights, None);
        if config.width == 0 || config.height == 0 || config.width > 16384 || config.height > 16384 {
            return Err(Error::desc(
                "RenderConfig::width",
                format!("invalid image size {}x{} (1..=16384 each)", config.width, config.height),
            ));
        }
        if config.frames_in_flight == 0 || config.frames_in_flight > 16 {
            return Err(Error::desc("RenderConfig::frames_in_flight", format!("must be 1..=16, got {}", config.frames_in_flight)));
        }
        check_options(ctx, &config, &settings)?;
        memory::check_fits(ctx, &scene, &config)?;
        let depth_locations = DepthLocations::standard(config.samples);
        let transmit_format = opts.transmit.format();
        let f = &ctx.features;
        let accum_format = area::accum_format(&source_lights, f.rgba32f_blend);
        let desc = ShadowPassDesc {
            depth_stencil_format: ctx.depth_format,
            frames_in_flight: config.frames_in_flight,
            depth_mode: config.depth_mode,
            depth_direction: sp::DepthDirection::Forward,
            samples: config.samples,
            target: sp::TargetModel::DynamicRendering,
            features: sp::EnabledFeatures {
                depth_clamp: f.depth_clamp,
                depth_bounds: f.depth_bounds,
                index_type_uint8: f.index_type_uint8,
                ray_query: f.ray_query,
                mesh_shader: f.mesh_shader,
                draw_indirect_first_instance: f.draw_indirect_first_instance,
                multi_draw_indirect: f.multi_draw_indirect,
                draw_indirect_count: f.draw_indirect_count,
                task_shader: f.task_shader,
            },
            settings: pass_settings(&settings),
            transmit_format: Some(transmit_format),
            debug_color_format: Some(accum_format),
            pipeline_cache: ctx.pipeline_cache,
            ..ShadowPassDesc::default()
        };
        let mut pass = ShadowPass::new(&ctx.instance, ctx.physical, &ctx.device, (*ctx.allocator).clone(), &desc)?;
        let mut caster_ids = Vec::with_capacity(scene.meshes.len());
        for m in &scene.meshes {
            caster_ids.push(match m.casts_shadow {
                true => Some(pass.add_prepared_caster(m.caster()?, m.transform.as_dmat4())?),
                false => None,
            });
        }
        for s in scene.spheres.iter().filter(|s| s.casts_shadow) {
            pass.add_sphere_caster(&s.name, s.sphere, s.segments)?;
        }
        let has_transparent = pass.casters().iter().any(|c| c.transmittance.is_some());
        if has_transparent && config.samples > 1 {
            return Err(Error::InvalidDesc {
                field: "RenderOptions::samples",
                msg: format!(
                    "transparent shadow casters' light-intensity map renders at one sample; multisampling ({} samples) is for opaque casters",
                    config.samples
                ),
            });
        }
        let frames = config.frames_in_flight;
        let geo = Guard::new(ctx, SceneGeometry::new(ctx, &scene, frames)?);
        let spheres = Guard::new(ctx, SphereGeometry::new(ctx, &scene, frames)?);
        let targets =
            Guard::new(ctx, Targets::with_samples(ctx, config.width, config.height, transmit_format, accum_format, config.samples)?);
        let pipes = Guard::new(ctx, FramePipelines::new(ctx, &targets, pass.capabilities().depth_bounds)?);
        let self_shadow = match config.self_shadow && geo.of(Sidedness::Transparent).next().is_some() {
            true => Some(SelfShadow::new(ctx, &pipes, targets.extent, transmit_format)?),
            false => None,
        };
        let self_shadow = Guard::new(ctx, self_shadow);
        let slots = FrameSlot::ring(ctx, frames)?;
        Ok(Parts {
            scene,
            source_lights,
            samples_for: None,
            config,
            pass,
            caster_ids,
            has_transparent,
            geo: geo.into_inner(),
            spheres: spheres.into_inner(),
            targets: targets.into_inner(),
            pipes: pipes.into_inner(),
            self_shadow: self_shadow.into_inner(),
            shadow_mapper: None,
            spare_shadow_mappers: Vec::new(),
            ray_offset: None,
            blas_build_ms: std::cell::Cell::new(0.0),
            slots,
            next_slot: 0,
            serial: 0,
            scene_version: 0,
            depth_locations,
        })
    }
}
