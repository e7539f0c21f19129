//! The winit application: the window, the Vulkan objects behind it, and the input handling.
//! The frame itself is in [`super::frame`]'s `Live::frame`.

use super::controls::{self, DragKind, Edits, Mode};
use super::present::EguiRenderer;
use super::swapchain::{Swapchain, FRAMES_IN_FLIGHT};
use super::ViewArgs;
use ash::vk;
use glam::Vec2;
use raw_window_handle::{HasDisplayHandle, HasWindowHandle};
use std::collections::HashMap;
use std::sync::{Arc, Mutex};
use std::time::Instant;
use umbrage::error::{Error, Result};
use umbrage::gpu::context::ValidationLog;
use umbrage::gpu::{Buffer, Context};
use umbrage::shadow::Method;
use umbrage_render::{
    Counter, FrameOutput, FrameSettings, FrameTicket, RenderOptions, RenderTechnique, Renderer, Shading, ShadowMap, Technique, View,
};
use umbrage_scene::motion::Motion;
use umbrage_scene::Scene;
use winit::application::ApplicationHandler;
use winit::event::{ElementState, MouseButton, MouseScrollDelta, WindowEvent};
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::keyboard::{Key, NamedKey};
use winit::window::{Window, WindowId};

/// Runs the event loop until the viewer exits; the first error wins.
pub(super) fn run(scene: Scene, motion: Motion, opts: RenderOptions, args: &ViewArgs) -> Result<()> {
    let el = EventLoop::new()
        .map_err(|e| Error::Unsupported(format!("cannot open the display ({e}); use `umbrage render` for headless rendering")))?;
    let mut app = App { init: Some((scene, motion, opts)), args, live: None, error: None };
    let run = el.run_app(&mut app);
    if let Some(live) = app.live.take() {
        // The loop ended without our exit path (the display went away): still tear down.
        let r = live.teardown();
        app.error = app.error.or(r.err());
    }
    if let Some(e) = app.error {
        return Err(e);
    }
    run.map_err(|e| Error::Unsupported(format!("the window's event loop: {e}")))
}

struct App<'a> {
    init: Option<(Scene, Motion, RenderOptions)>,
    args: &'a ViewArgs,
    live: Option<Live>,
    error: Option<Error>,
}

impl App<'_> {
    /// Ends the viewer: the exit work (screenshot, stats), then the teardown.
    fn stop(&mut self, el: &ActiveEventLoop, error: Option<Error>) {
        if let Some(mut live) = self.live.take() {
            let finished = match error {
                None => live.finish(self.args).err(),
                Some(e) => Some(e),
            };
            let torn = live.teardown().err();
            self.error = self.error.take().or(finished).or(torn);
        } else if let Some(e) = error {
            self.error = self.error.take().or(Some(e));
        }
        el.exit();
    }
}

impl ApplicationHandler for App<'_> {
    fn resumed(&mut self, el: &ActiveEventLoop) {
        let Some((scene, motion, opts)) = self.init.take() else { return };
        match Live::new(el, scene, motion, opts, self.args) {
            Ok(live) => {
                live.window.request_redraw();
                self.live = Some(live);
            }
            Err(e) => self.stop(el, Some(e)),
        }
    }

    fn window_event(&mut self, el: &ActiveEventLoop, _id: WindowId, event: WindowEvent) {
        let Some(live) = self.live.as_mut() else { return };
        let r = match event {
            WindowEvent::RedrawRequested => live.frame(self.args),
            ev => live.event(&ev),
        };
        match r {
            Ok(false) => {}
            Ok(true) => self.stop(el, None),
            Err(e) => self.stop(el, Some(e)),
        }
    }

    fn about_to_wait(&mut self, el: &ActiveEventLoop) {
        if let Some(live) = &self.live {
            if live.idle() {
                // Minimised or hidden: wait for the next event instead of spinning.
                el.set_control_flow(ControlFlow::Wait);
            } else {
                el.set_control_flow(ControlFlow::Poll);
                live.window.request_redraw();
            }
        }
    }

    fn exiting(&mut self, el: &ActiveEventLoop) {
        if self.live.is_some() {
            self.stop(el, None);
        }
    }
}

/// egui's pieces.
pub(super) struct Egui {
    pub ctx: egui::Context,
    pub state: egui_winit::State,
    pub renderer: Option<EguiRenderer>,
    /// Full copies of egui's textures: partial updates are applied here and uploaded whole
    /// (egui-ash-renderer 0.13's partial update starts from an UNDEFINED layout).
    pub images: HashMap<egui::TextureId, egui::ColorImage>,
    /// Per frame slot: textures to free once that slot's frame is done.
    pub free: Vec<Vec<egui::TextureId>>,
}

/// Everything alive while the window is open.
pub(super) struct Live {
    pub window: Window,
    pub renderer: Renderer,
    pub sc: Swapchain,
    pub egui: Egui,
    pub log: Arc<Mutex<ValidationLog>>,
    /// The scene at rest and its motion.
    pub base: Scene,
    pub motion: Motion,
    pub edits: Edits,
    /// `M` cycles these.
    pub techniques: Vec<RenderTechnique>,
    pub technique: usize,
    /// The last settings a frame was accepted with (a refused change reverts to them).
    pub good: FrameSettings,
    pub mode: Mode,
    /// Scene indices of the shadow casters, and the selected one (`Tab` in model mode).
    pub casters: Vec<usize>,
    pub caster: usize,
    pub light: usize,
    pub drag: Option<(DragKind, Vec2)>,
    pub cursor: Vec2,
    pub ctrl: bool,
    pub shift: bool,
    pub paused: bool,
    /// The next frame's scene time, s.
    pub time: f64,
    pub last_wall: Instant,
    /// Frames rendered.
    pub frames: u64,
    pub slot: usize,
    /// The frame in flight in the renderer, with its scene time.
    pub pending: Option<(FrameTicket, f64)>,
    /// The last finished frame and its scene time.
    pub last: Option<(FrameOutput, f64)>,
    pub need_rebuild: bool,
    pub minimised: bool,
    pub occluded: bool,
    pub shot_buf: Option<Buffer>,
    pub shot_requested: bool,
    pub shots: Vec<String>,
    pub fps: f64,
    pub fps_frames: u32,
    pub fps_since: Instant,
    pub frame_ms: f64,
    /// Refused settings and other things the overlay tells.
    pub notes: Vec<String>,
    pub overlay_visible: bool,
    pub menu_at: Option<egui::Pos2>,
    /// What the overlay showed last: method, counter, view, mode, the pairs line
    /// ([`overlay::pairs_line`](super::overlay::pairs_line); empty before a frame finished).
    pub shown: Option<[String; 5]>,
    pub resizes: u32,
}

/// The techniques `M` cycles through, in the order of `render --method`: ray query and mesh
/// shaders where the device has them.
pub(super) fn technique_cycle(shadow_map: ShadowMap, ray_query: bool, mesh_shader: bool) -> Vec<RenderTechnique> {
    let mut v: Vec<RenderTechnique> =
        [Method::McGuire, Method::Lengyel, Method::EverittKilgard, Method::ZFail, Method::ZPass, Method::ZPassClear]
            .into_iter()
            .map(|m| Technique::Volumes(m).into())
            .collect();
    v.extend([Technique::EdgeQuads, Technique::Planar, Technique::Compute].map(RenderTechnique::Pass));
    v.push(shadow_map.into());
    if ray_query {
        v.push(Technique::RayQuery.into());
    }
    if mesh_shader {
        v.push(Technique::Mesh.into());
    }
    v
}

impl Live {
    fn new(el: &ActiveEventLoop, scene: Scene, motion: Motion, mut opts: RenderOptions, args: &ViewArgs) -> Result<Live> {
        let attrs = Window::default_attributes()
            .with_title(format!("umbrage view - {}", scene.name))
            .with_inner_size(winit::dpi::PhysicalSize::new(opts.width, opts.height));
        let window = el.create_window(attrs).map_err(|e| Error::Unsupported(format!("cannot create a window: {e}")))?;
        let display = window.display_handle().map_err(|e| Error::Unsupported(format!("no display handle: {e}")))?.as_raw();
        let handle = window.window_handle().map_err(|e| Error::Unsupported(format!("no window handle: {e}")))?.as_raw();
        let (display, handle) = super::surface::surface_handles(display, handle)?;
        let exts = ash_window::enumerate_required_extensions(display)
            .map_err(|e| Error::Unsupported(format!("no Vulkan surface for this display: {e:?}")))?;
        let ctx = Context::with_extensions(umbrage::gpu::context::validation_requested(), exts, &[ash::khr::swapchain::NAME])?;
        // SAFETY: the handles come from a live window that outlives the surface (the surface
        // is destroyed in `teardown`, before the window is dropped).
        let surface = unsafe { ash_window::create_surface(&ctx.entry, &ctx.instance, display, handle, None) }
            .map_err(|e| Error::Unsupported(format!("cannot create a Vulkan surface for the window: {e:?}")))?;
        let size = window.inner_size();
        let sc = Swapchain::new(&ctx, surface, (size.width.max(1), size.height.max(1)), args.vsync == super::Vsync::On)?;
        let log = ctx.validation_log();
        let format = sc.format.format;
        let srgb = matches!(format, vk::Format::B8G8R8A8_SRGB | vk::Format::R8G8B8A8_SRGB);
        let egui_renderer = EguiRenderer::with_gpu_allocator(
            (*ctx.allocator).clone(),
            ctx.device.clone(),
            egui_ash_renderer::RenderMode::DynamicRendering(egui_ash_renderer::DynamicRendering {
                color_attachment_format: format,
                depth_attachment_format: None,
                stencil_attachment_format: None,
            }),
            egui_ash_renderer::Options { in_flight_frames: FRAMES_IN_FLIGHT, srgb_framebuffer: srgb, ..Default::default() },
        );
        let egui_renderer = match egui_renderer {
            Ok(r) => r,
            Err(e) => {
                let mut sc = sc;
                sc.destroy(&ctx);
                return Err(Error::Unsupported(format!("egui overlay: {e}")));
            }
        };
        let (w, h) = (sc.extent.width.max(1), sc.extent.height.max(1));
        opts.width = w;
        opts.height = h;
        opts.view = args.view;
        opts.frames_in_flight = 2;
        let edits = Edits::new(scene.camera.clone(), scene.meshes.len(), scene.lights.len());
        let at0 = motion.scene_at(&scene, args.time);
        let good = opts.settings();
        // The shadow map the cycle offers: the one asked for, or the default's.
        let shadow_map = opts.technique.shadow_map().unwrap_or_default();
        let mut techniques = technique_cycle(shadow_map, ctx.features.ray_query, ctx.features.mesh_shader);
        let technique = match techniques.iter().position(|t| *t == opts.technique) {
            Some(i) => i,
            None => {
                techniques.insert(0, opts.technique);
                0
            }
        };
        let renderer = match Renderer::new(ctx, at0, opts) {
            Ok(r) => r,
            Err(e) => {
                // The context went with the failed renderer: the swapchain's objects are
                // reported as leaked by validation only; say what failed.
                drop(egui_renderer);
                return Err(e);
            }
        };
        let egui_ctx = egui::Context::default();
        let state =
            egui_winit::State::new(egui_ctx.clone(), egui::ViewportId::ROOT, &window, Some(window.scale_factor() as f32), None, None);
        let casters: Vec<usize> = scene.meshes.iter().enumerate().filter(|(_, m)| m.casts_shadow).map(|(i, _)| i).collect();
        let now = Instant::now();
        Ok(Live {
            window,
            renderer,
            sc,
            egui: Egui {
                ctx: egui_ctx,
                state,
                renderer: Some(egui_renderer),
                images: HashMap::new(),
                free: vec![Vec::new(); FRAMES_IN_FLIGHT],
            },
            log,
            base: scene,
            motion,
            edits,
            techniques,
            technique,
            good,
            mode: Mode::Scene,
            casters,
            caster: 0,
            light: 0,
            drag: None,
            cursor: Vec2::ZERO,
            ctrl: false,
            shift: false,
            paused: false,
            time: args.time,
            last_wall: now,
            frames: 0,
            slot: 0,
            pending: None,
            last: None,
            need_rebuild: false,
            minimised: false,
            occluded: false,
            shot_buf: None,
            shot_requested: false,
            shots: Vec::new(),
            fps: 0.0,
            fps_frames: 0,
            fps_since: now,
            frame_ms: 0.0,
            notes: Vec::new(),
            overlay_visible: !args.hide_overlay,
            menu_at: None,
            shown: None,
            resizes: 0,
        })
    }

    /// Nothing to draw until an event arrives (minimised, or unmapped / fully covered).
    fn idle(&self) -> bool {
        self.minimised || self.occluded
    }

    /// The selected caster's scene index.
    pub(super) fn caster_index(&self) -> Option<usize> {
        self.casters.get(self.caster).copied()
    }

    /// One window event; `Ok(true)`: exit.
    fn event(&mut self, ev: &WindowEvent) -> Result<bool> {
        let egui_live = self.overlay_visible || self.menu_at.is_some();
        if egui_live {
            let _ = self.egui.state.on_window_event(&self.window, ev);
        }
        // Over the overlay at the cursor's position now (egui's own hover state is a frame
        // old, and a press can arrive in the same batch as the move that led to it).
        let ppp = self.window.scale_factor() as f32;
        let over_ui = egui_live
            && (self.egui.ctx.egui_is_using_pointer()
                || self
                    .egui
                    .ctx
                    .layer_id_at(egui::pos2(self.cursor.x / ppp, self.cursor.y / ppp))
                    .is_some_and(|l| l.order != egui::Order::Background));
        match ev {
            WindowEvent::CloseRequested | WindowEvent::Destroyed => return Ok(true),
            WindowEvent::Resized(s) => {
                self.need_rebuild = true;
                self.minimised = s.width == 0 || s.height == 0;
                self.resizes += 1;
            }
            WindowEvent::Occluded(o) => self.occluded = *o,
            WindowEvent::ModifiersChanged(m) => {
                self.ctrl = m.state().control_key();
                self.shift = m.state().shift_key();
            }
            WindowEvent::KeyboardInput { event, .. }
                if event.state == ElementState::Pressed && !event.repeat && !(egui_live && self.egui.ctx.egui_wants_keyboard_input()) =>
            {
                return Ok(self.key(&event.logical_key));
            }
            WindowEvent::CursorMoved { position, .. } => {
                let p = Vec2::new(position.x as f32, position.y as f32);
                if let Some((kind, from)) = self.drag {
                    self.drag_step(kind, from, p);
                    self.drag = Some((kind, p));
                }
                self.cursor = p;
            }
            WindowEvent::MouseInput { state, button, .. } => match (button, state) {
                (MouseButton::Left, ElementState::Pressed) if !over_ui => {
                    self.drag = Some((DragKind::from_modifiers(self.ctrl, self.shift), self.cursor));
                }
                (MouseButton::Left, ElementState::Released) => self.drag = None,
                (MouseButton::Right, ElementState::Pressed) if !over_ui => {
                    self.menu_at = Some(egui::pos2(self.cursor.x / ppp, self.cursor.y / ppp));
                }
                _ => {}
            },
            WindowEvent::MouseWheel { delta, .. } if !over_ui => {
                let steps = match delta {
                    MouseScrollDelta::LineDelta(_, y) => *y,
                    MouseScrollDelta::PixelDelta(p) => p.y as f32 / 40.0,
                };
                self.edits.camera = controls::zoom(&self.edits.camera, steps);
            }
            _ => {}
        }
        Ok(false)
    }

    /// A key press; true: exit.
    fn key(&mut self, key: &Key) -> bool {
        match key {
            Key::Named(NamedKey::Escape) => return true,
            Key::Named(NamedKey::Tab) => match self.mode {
                Mode::Light => self.light = (self.light + 1) % self.base.lights.len().max(1),
                _ => self.caster = (self.caster + 1) % self.casters.len().max(1),
            },
            Key::Named(NamedKey::Space) => self.paused = !self.paused,
            Key::Named(NamedKey::F12) => self.shot_requested = true,
            Key::Character(c) => match c.to_lowercase().as_str() {
                "1" => self.mode = Mode::Scene,
                "2" => self.mode = Mode::Model,
                "3" => self.mode = Mode::Light,
                "m" => self.set_technique((self.technique + 1) % self.techniques.len()),
                "c" => {
                    // The counter counts volumes: the shadow-map and ray-query paths have none.
                    let s = &mut self.renderer.settings;
                    if s.technique.is_volume_pass() {
                        s.counter = if s.counter == Counter::Stencil { Counter::Float } else { Counter::Stencil };
                    }
                }
                "v" => {
                    let s = &mut self.renderer.settings;
                    s.view = match s.view {
                        View::Shaded => View::Volumes,
                        View::Volumes => View::Stencil,
                        View::Stencil => View::Shaded,
                    };
                }
                "s" => {
                    let s = &mut self.renderer.settings;
                    s.shading = match s.shading {
                        Shading::Smooth => Shading::SmoothNaive,
                        Shading::SmoothNaive => Shading::Flat,
                        Shading::Flat => Shading::Smooth,
                    };
                }
                "p" => self.shot_requested = true,
                "h" => self.overlay_visible = !self.overlay_visible,
                _ => {}
            },
            _ => {}
        }
        false
    }

    pub(super) fn set_technique(&mut self, i: usize) {
        if let Some(t) = self.techniques.get(i) {
            self.technique = i;
            self.renderer.settings.technique = *t;
            if *t == RenderTechnique::Pass(Technique::RayQuery) {
                // The rays write the stencil; the float counter would be refused.
                self.renderer.settings.counter = Counter::Stencil;
            }
        }
    }

    /// One step of a left drag from `from` to `to` (window pixels).
    fn drag_step(&mut self, kind: DragKind, from: Vec2, to: Vec2) {
        let size = Vec2::new(self.sc.extent.width as f32, self.sc.extent.height as f32);
        let drawn = self.renderer.scene();
        let (index, origin) = match self.mode {
            Mode::Scene => (0, self.edits.camera.target),
            Mode::Model => match self.caster_index() {
                Some(i) => (i, drawn.meshes[i].transform.w_axis.truncate()),
                None => return,
            },
            // As given (an area light is one light here, not its samples).
            Mode::Light => match self.renderer.source_lights().get(self.light) {
                Some(l) => (self.light, l.position),
                None => return,
            },
        };
        controls::drag(&mut self.edits, self.mode, kind, index, origin, controls::Stroke { from, to, size });
    }

    /// Waits for the device and destroys everything, the context last; validation's
    /// complaints during teardown (leaked objects) are errors.
    pub(super) fn teardown(mut self) -> Result<()> {
        let ctx = self.renderer.context();
        // SAFETY: waiting for all work before destroying what it uses.
        let _ = unsafe { ctx.device.device_wait_idle() };
        if let Some(r) = self.egui.renderer.take() {
            drop(r);
        }
        self.sc.destroy(ctx);
        if let Some(mut b) = self.shot_buf.take() {
            b.destroy(ctx);
        }
        let log = self.log.clone();
        drop(self.renderer);
        drop(self.window);
        let errors = log.lock().map(|mut l| std::mem::take(&mut l.errors)).unwrap_or_default();
        match errors.first() {
            None => Ok(()),
            Some(first) => Err(Error::Validation { count: errors.len(), first: first.clone() }),
        }
    }
}

#[cfg(test)]
mod cycle_tests {
    use super::*;

    #[test]
    fn the_cycle_offers_every_technique_the_device_has_once() {
        let sm = ShadowMap::new(2048);
        let base = technique_cycle(sm, false, false);
        assert_eq!(base[0], Technique::Volumes(Method::McGuire).into());
        assert!(base.contains(&Technique::Compute.into()) && base.contains(&sm.into()));
        assert!(!base.contains(&Technique::RayQuery.into()) && !base.contains(&Technique::Mesh.into()));
        let all = technique_cycle(sm, true, true);
        assert_eq!(all.len(), base.len() + 2);
        assert_eq!(&all[all.len() - 2..], &[Technique::RayQuery.into(), Technique::Mesh.into()]);
        for (i, t) in all.iter().enumerate() {
            assert!(!all[i + 1..].contains(t), "{} twice", t.name());
        }
    }
}
