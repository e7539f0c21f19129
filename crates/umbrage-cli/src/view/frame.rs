//! One viewer frame: the scene moved to the frame's time, the renderer's frame submitted,
//! the overlay built, the presentation, the previous frame finished; and the exit work
//! (the `--screenshot` PNG, the `--stats` JSON).

use super::app::Live;
use super::overlay::{self, Shown};
use super::present::{self, OverlayDraw, Presented};
use super::ViewArgs;
use ash::vk;
use glam::{Mat4, Vec3};
use gpu_allocator::MemoryLocation;
use std::time::Instant;
use umbrage::error::{Error, Result};
use umbrage::gpu::{Buffer, Context};
use umbrage_render::{FrameOutput, Stats};

/// One frame's overlay: its primitives, pixels per point and texture changes.
type OverlayFrame = (Vec<egui::ClippedPrimitive>, f32, egui::TexturesDelta);

impl Live {
    /// Renders and presents one frame; `Ok(true)`: `--frames` reached.
    pub(super) fn frame(&mut self, args: &ViewArgs) -> Result<bool> {
        let size = self.window.inner_size();
        if size.width == 0 || size.height == 0 {
            self.minimised = true;
            return Ok(false);
        }
        if !self.fit_window((size.width, size.height))? {
            self.minimised = true;
            return Ok(false);
        }
        self.minimised = false;
        let start = Instant::now();
        let dt = start.duration_since(self.last_wall).as_secs_f64();
        self.last_wall = start;
        let time = self.time;
        if !self.paused {
            self.time += args.time_step.unwrap_or(dt);
        }

        // 1. The renderer's frame at `time`.
        self.apply_scene(time)?;
        let ticket = match self.renderer.submit() {
            Ok(t) => t,
            Err(e @ (Error::Unsupported(_) | Error::Misuse(_) | Error::InvalidDesc { .. } | Error::Mesh { .. }))
                if self.renderer.settings != self.good =>
            {
                let tried = self.renderer.settings;
                self.notes.push(format!("{} / {} refused: {e}", tried.technique.name(), tried.counter.name()));
                self.renderer.settings = self.good;
                self.technique = self.techniques.iter().position(|t| *t == self.good.technique).unwrap_or(0);
                self.renderer.submit()?
            }
            Err(e) => return Err(e),
        };
        self.good = self.renderer.settings;

        // 2. The overlay.
        let mut draw = self.overlay(time);

        // 3. Present: this slot's previous presentation must be done first.
        let slot = self.slot;
        let ctx = self.renderer.context();
        let fence = self.sc.frames[slot].fence;
        // SAFETY: the fence belongs to this device.
        unsafe { ctx.device.wait_for_fences(&[fence], true, u64::MAX) }.map_err(Error::vk("vkWaitForFences"))?;
        let frees = std::mem::take(&mut self.egui.free[slot]);
        free_textures(ctx, &mut self.egui, &frees)?;
        // Applied here, so no early return drops unapplied deltas (egui asserts against it).
        let mut new_frees = Vec::new();
        if let Some((_, _, delta)) = draw.as_mut() {
            let r = set_textures(ctx, &mut self.egui, delta);
            new_frees = delta.free.drain().collect();
            delta.clear();
            r?;
        }
        let shot = self.shot_requested && self.sc.readable;
        if shot {
            let bytes = self.sc.extent.width as u64 * self.sc.extent.height as u64 * 4;
            if self.shot_buf.as_ref().map(|b| b.size != bytes).unwrap_or(true) {
                if let Some(mut b) = self.shot_buf.take() {
                    // SAFETY: no frame in flight reads back into it (waited above / at shots).
                    unsafe { ctx.device.device_wait_idle() }.map_err(Error::vk("vkDeviceWaitIdle"))?;
                    b.destroy(ctx);
                }
                self.shot_buf = Some(Buffer::new(ctx, "screenshot", bytes, vk::BufferUsageFlags::TRANSFER_DST, MemoryLocation::GpuToCpu)?);
            }
        } else if self.shot_requested {
            self.notes.push("screenshots need TRANSFER_SRC swapchain images, which this surface does not offer".into());
        }
        self.shot_requested = false;
        let overlay_draw = match (&draw, self.egui.renderer.as_mut()) {
            (Some((prims, ppp, _)), Some(r)) => Some(OverlayDraw { renderer: r, primitives: prims, pixels_per_point: *ppp }),
            _ => None,
        };
        let presented = present::present(
            ctx,
            &self.sc,
            slot,
            self.renderer.output_image(),
            overlay_draw,
            if shot { self.shot_buf.as_ref() } else { None },
        )?;
        match presented {
            Presented::Yes { suboptimal } => {
                self.need_rebuild |= suboptimal;
                self.slot = (slot + 1) % self.sc.frames.len();
                if shot {
                    self.write_shot(slot, &args.shot_dir)?;
                }
            }
            Presented::OutOfDate => self.need_rebuild = true,
            Presented::Lost => {
                self.egui.free[slot].extend(new_frees);
                self.settle()?;
                return Ok(true);
            }
        }
        // Freed once this slot's next wait shows the frame that drew with them is done.
        self.egui.free[slot].extend(new_frees);

        // 4. The previous frame is done by now or soon: its stats feed the overlay.
        if let Some((prev, t)) = self.pending.replace((ticket, time)) {
            self.last = Some((self.renderer.finish(prev)?, t));
        }
        self.frames += 1;
        self.frame_ms = start.elapsed().as_secs_f64() * 1e3;
        self.fps_frames += 1;
        let since = self.fps_since.elapsed().as_secs_f64();
        if since >= 1.0 {
            self.fps = self.fps_frames as f64 / since;
            self.fps_frames = 0;
            self.fps_since = Instant::now();
        }
        Ok(args.frames.map(|n| n > 0 && self.frames >= n).unwrap_or(false))
    }

    /// Rebuilds the swapchain (and resizes the renderer) when the window's `size` changed or
    /// presentation asked for it; `Ok(false)`: the window is minimised.
    fn fit_window(&mut self, size: (u32, u32)) -> Result<bool> {
        if self.need_rebuild || size != (self.sc.extent.width, self.sc.extent.height) {
            let old_format = self.sc.format.format;
            if !self.sc.rebuild(self.renderer.context(), size)? {
                return Ok(false);
            }
            self.settle()?;
            self.renderer.resize(self.sc.extent.width, self.sc.extent.height)?;
            if self.sc.format.format != old_format {
                if let Some(r) = self.egui.renderer.as_mut() {
                    let mode = egui_ash_renderer::RenderMode::DynamicRendering(egui_ash_renderer::DynamicRendering {
                        color_attachment_format: self.sc.format.format,
                        depth_attachment_format: None,
                        stencil_attachment_format: None,
                    });
                    r.set_render_mode(mode).map_err(|e| Error::Unsupported(format!("egui overlay: {e}")))?;
                }
            }
            self.need_rebuild = false;
        }
        Ok(true)
    }

    /// The overlay's primitives, scale and texture changes when it (or the menu) is shown;
    /// the user's changes in it are applied to the settings.
    fn overlay(&mut self, time: f64) -> Option<OverlayFrame> {
        if !(self.overlay_visible || self.menu_at.is_some()) {
            return None;
        }
        let raw = self.egui.state.take_egui_input(&self.window);
        let stats = self.last.as_ref().map(|(f, _)| &f.stats);
        let pairs = stats.map(overlay::pairs_line).unwrap_or_default();
        let drawn = self.renderer.scene();
        let caster_name = self.caster_index().map(|i| drawn.meshes[i].name.clone()).unwrap_or_else(|| "(no casters)".into());
        let light = self.renderer.source_lights().get(self.light).map(|l| (self.light, l.position));
        let settings = self.renderer.settings;
        let present =
            format!("{:?}, {:?}, {}x{}", self.sc.present_mode, self.sc.format.format, self.sc.extent.width, self.sc.extent.height);
        let notes: Vec<String> = self.sc.notes.iter().chain(&self.notes).cloned().collect();
        let shown = Shown {
            fps: self.fps,
            frame_ms: self.frame_ms,
            stats,
            techniques: &self.techniques,
            technique: self.technique,
            counter: settings.counter,
            view: settings.view,
            mode: self.mode,
            caster: &caster_name,
            light,
            time,
            paused: self.paused,
            notes: &notes,
            present,
        };
        let visible = self.overlay_visible;
        let mut changes = overlay::Changes::default();
        let menu_at = &mut self.menu_at;
        let out = self.egui.ctx.run_ui(raw, |ui| {
            if visible {
                changes = overlay::ui(ui.ctx(), &shown, menu_at);
            } else {
                changes = overlay::menu_only(ui.ctx(), menu_at);
            }
        });
        if visible {
            self.shown = Some([
                self.techniques[self.technique].name().to_string(),
                settings.counter.name().to_string(),
                settings.view.name().to_string(),
                self.mode.name().to_string(),
                pairs,
            ]);
        }
        self.egui.state.handle_platform_output(&self.window, out.platform_output);
        let prims = self.egui.ctx.tessellate(out.shapes, out.pixels_per_point);
        self.apply_changes(changes);
        Some((prims, out.pixels_per_point, out.textures_delta))
    }

    /// The scene at `time` (motion), with the user's edits, into the renderer.
    fn apply_scene(&mut self, time: f64) -> Result<()> {
        if self.edits.camera != self.renderer.scene().camera {
            self.renderer.set_camera(self.edits.camera.clone())?;
        }
        for i in 0..self.base.meshes.len() {
            let moved = self.motion.mesh_transform(i, self.base.meshes[i].transform, time);
            let edit = self.edits.meshes[i];
            let m = if edit == Mat4::IDENTITY { moved } else { edit * moved };
            if m != self.renderer.scene().meshes[i].transform {
                self.renderer.set_mesh_transform(i, m)?;
            }
        }
        let lights = self.base.lights.iter().enumerate().map(|(i, l)| self.edits.lights[i].apply(&self.motion.light(i, l, time))).collect();
        self.renderer.set_lights(lights)?;
        Ok(())
    }

    fn apply_changes(&mut self, ch: overlay::Changes) {
        if let Some(t) = ch.technique {
            self.set_technique(t);
        }
        if let Some(c) = ch.counter {
            self.renderer.settings.counter = c;
        }
        if let Some(v) = ch.view {
            self.renderer.settings.view = v;
        }
        if let Some(m) = ch.mode {
            self.mode = m;
        }
        if let (Some(p), Some(l)) = (ch.light_position, self.renderer.source_lights().get(self.light)) {
            let delta: Vec3 = p - l.position;
            self.edits.lights[self.light].offset += delta;
        }
    }

    /// Finishes the frame in flight in the renderer (before a resize, and at exit).
    pub(super) fn settle(&mut self) -> Result<()> {
        if let Some((t, time)) = self.pending.take() {
            self.last = Some((self.renderer.finish(t)?, time));
        }
        Ok(())
    }

    /// Writes the screenshot presented from `slot` (waits for it).
    fn write_shot(&mut self, slot: usize, dir: &std::path::Path) -> Result<()> {
        let ctx = self.renderer.context();
        let fence = self.sc.frames[slot].fence;
        // SAFETY: the fence belongs to this device.
        unsafe { ctx.device.wait_for_fences(&[fence], true, u64::MAX) }.map_err(Error::vk("vkWaitForFences"))?;
        let Some(buf) = &self.shot_buf else { return Ok(()) };
        let px = present::shot_rgba(&self.sc, buf)?;
        let path = dir.join(format!("umbrage-view-{:03}.png", self.shots.len()));
        umbrage_render::output::write_png(&path, self.sc.extent.width, self.sc.extent.height, &px)?;
        println!("screenshot {}", path.display());
        self.shots.push(path.display().to_string());
        Ok(())
    }

    /// The exit work: the last frame finished, `--screenshot`, `--stats`, a summary line.
    pub(super) fn finish(&mut self, args: &ViewArgs) -> Result<()> {
        self.settle()?;
        let Some((out, time)) = &self.last else {
            if args.screenshot.is_some() {
                return Err(Error::Internal("no frame was rendered, so there is no --screenshot to write".into()));
            }
            return Ok(());
        };
        if let Some(p) = &args.screenshot {
            umbrage_render::output::write_png(p, out.width, out.height, &out.color)?;
        }
        if let Some(p) = &args.stats {
            let json = serde_json::to_string_pretty(&self.report(out, *time)).map_err(|e| Error::Internal(format!("JSON: {e}")))?;
            std::fs::write(p, json).map_err(|e| Error::io(p.display().to_string(), e))?;
        }
        let s = &out.stats;
        println!(
            "{} | {}x{} | {} | {} frames, t = {:.3} s | {:.1} fps | {:?} | {} shadow triangles",
            s.device,
            s.width,
            s.height,
            s.method,
            self.frames,
            time,
            self.fps,
            self.sc.present_mode,
            s.totals.triangles.total()
        );
        Ok(())
    }

    /// The `--stats` JSON: the viewer's state at the last frame and that frame's stats.
    fn report(&self, out: &FrameOutput, time: f64) -> serde_json::Value {
        let v3 = |v: Vec3| [v.x as f64, v.y as f64, v.z as f64];
        let scene = self.renderer.scene();
        let settings = self.renderer.settings;
        let stats: &Stats = &out.stats;
        serde_json::json!({
            "frames": self.frames,
            "time_s": time,
            "paused": self.paused,
            "method": settings.technique.name(),
            "counter": settings.counter.name(),
            "view": settings.view.name(),
            "mode": self.mode.name(),
            "selected_caster": self.caster_index().map(|i| scene.meshes[i].name.clone()),
            "selected_light": self.light,
            "overlay": {
                "visible": self.overlay_visible,
                "shown": self.shown.as_ref().map(|s| serde_json::json!({"method": s[0], "counter": s[1], "view": s[2], "mode": s[3], "pairs": s[4]})),
            },
            "camera": {"eye": v3(scene.camera.eye), "target": v3(scene.camera.target), "up": v3(scene.camera.up)},
            "lights": scene.lights.iter().map(|l| serde_json::json!({"position": v3(l.position), "direction": v3(l.direction)})).collect::<Vec<_>>(),
            "meshes": scene.meshes.iter().map(|m| serde_json::json!({"name": m.name, "transform": m.transform.to_cols_array().map(|x| x as f64)})).collect::<Vec<_>>(),
            "width": out.width,
            "height": out.height,
            "fps": self.fps,
            "frame_ms": self.frame_ms,
            "present_mode": format!("{:?}", self.sc.present_mode),
            "surface_format": format!("{:?}", self.sc.format.format),
            "swapchains": self.sc.generations,
            "resize_events": self.resizes,
            "notes": self.sc.notes.iter().chain(&self.notes).collect::<Vec<_>>(),
            "screenshots": self.shots,
            "stats": stats,
        })
    }
}

/// Uploads egui's texture changes, whole (partial updates patched into the kept copy). The
/// device is idle first: a texture may be in use by a frame in flight (rare: at start and when
/// new glyphs appear).
fn set_textures(ctx: &Context, egui: &mut super::app::Egui, delta: &egui::TexturesDelta) -> Result<()> {
    if delta.set.is_empty() {
        return Ok(());
    }
    let Some(r) = egui.renderer.as_mut() else { return Ok(()) };
    // SAFETY: waiting before textures a frame in flight may read are replaced.
    unsafe { ctx.device.device_wait_idle() }.map_err(Error::vk("vkDeviceWaitIdle"))?;
    for (id, d) in delta.set.iter().flat_map(|(id, ds)| ds.iter().map(move |d| (id, d))) {
        let egui::ImageData::Color(img) = &d.image;
        let full = match d.pos {
            None => img.as_ref().clone(),
            Some([x, y]) => {
                let mut base =
                    egui.images.remove(id).ok_or_else(|| Error::Internal(format!("egui: partial update of unknown texture {id:?}")))?;
                let (w, bw) = (img.size[0], base.size[0]);
                for row in 0..img.size[1] {
                    let dst = (y + row) * bw + x;
                    base.pixels[dst..dst + w].copy_from_slice(&img.pixels[row * w..(row + 1) * w]);
                }
                base
            }
        };
        r.set_texture(ctx.queue, ctx.pool, *id, &egui::epaint::ImageDelta::full(full.clone(), d.options))
            .map_err(|e| Error::Unsupported(format!("egui texture: {e}")))?;
        egui.images.insert(*id, full);
    }
    Ok(())
}

/// Frees textures egui no longer uses (after the frame that last drew with them).
fn free_textures(ctx: &Context, egui: &mut super::app::Egui, ids: &[egui::TextureId]) -> Result<()> {
    if ids.is_empty() {
        return Ok(());
    }
    let Some(r) = egui.renderer.as_mut() else { return Ok(()) };
    // SAFETY: waiting before destroying textures the other frame in flight may read.
    unsafe { ctx.device.device_wait_idle() }.map_err(Error::vk("vkDeviceWaitIdle"))?;
    for id in ids {
        r.free_texture(*id).map_err(|e| Error::Unsupported(format!("egui texture: {e}")))?;
        egui.images.remove(id);
    }
    Ok(())
}
