//! One frame, recorded as a list of command buffers in one `queue.submit`:
//! 1. wgpu: the ambient + G-buffer pass (depth LESS into the Depth24PlusStencil8 texture,
//!    stencil cleared to 0), then the texture transitioned to `DEPTH_STENCIL_WRITE`;
//! 2. per light: the shadow determination through wgpu's raw Vulkan handles
//!    ([`shadow::determine`]), then wgpu: the stencil copied out (captured frames), the
//!    lighting pass (stencil EQUAL 0 inside the light's scissor, added into the float target);
//! 3. wgpu: the tone map into the sRGB output and its copy out (and the G-buffer's positions
//!    and normals, captured frames).
//!
//! A retired frame's readback becomes umbrage's [`FrameOutput`], which `umbrage render` writes
//! with the same functions (`--out`, `--dump`).

use crate::host::{flip_y, pitch, Host, InFlight, LightBlock, MeshBlock, FRAMES_IN_FLIGHT, UNIFORM_STRIDE};
use crate::shadow;
use glam::{DMat4, DVec3, Mat4, Vec3, Vec4};
use std::time::Instant;
use umbrage::geom::LightKind;
use umbrage::pass::ShadowView;
use umbrage_render::{FrameOutput, Stats};

/// Where the moving caster is at frame `f`, relative to where the scene puts it: it slides
/// along +x, 0.25 a frame (frame 0, and so `--frames 1`, is the scene as loaded). The dump
/// of the last frame has it there too, so `umbrage check` judges the moved caster's shadow.
pub fn displacement(f: usize) -> Vec3 {
    Vec3::new(0.25 * f as f32, 0.0, 0.0)
}

/// What a retired frame took.
#[derive(Clone, Debug)]
pub struct Timing {
    pub frame: usize,
    pub slot: usize,
    /// `prepare` (the pass's CPU planning), ms.
    pub prepare_ms: f64,
    /// Uniform writes, encoding and `queue.submit`, ms.
    pub record_ms: f64,
    /// From `prepare` until the host saw the submission complete, ms (a frame waited for only
    /// when its slot comes round again includes the next frame's recording).
    pub latency_ms: f64,
}

/// A retired frame: its timing and, for the frame that was read back, its output.
pub struct Retired {
    pub timing: Timing,
    pub output: Option<FrameOutput>,
}

impl Host {
    /// Records and submits frame `f` into ring slot `f % 2`, after retiring the slot's
    /// previous frame (returned). `capture`: copy out the stencil per light and the
    /// G-buffer's positions and normals (for `--dump`).
    pub fn frame(&mut self, f: usize, capture: bool) -> Result<Option<Retired>, String> {
        let slot = f % FRAMES_IN_FLIGHT;
        let retired = self.retire(slot, false)?;
        let start = Instant::now();
        if let Some((mi, base)) = self.moving {
            let xf = Mat4::from_translation(displacement(f)) * base;
            self.scene.meshes[mi].transform = xf;
            let id = self.meshes[mi].caster.ok_or("the moving mesh casts no shadow")?;
            self.pass_mut().set_transform(id, xf.as_dmat4()).map_err(|e| e.to_string())?;
        }
        let (w, h) = (self.targets.width, self.targets.height);
        let cam = &self.scene.camera;
        let proj = cam.proj_infinite(w as f32 / h as f32);
        // Eye-relative view (rotation only): the translation goes into every model matrix in f64.
        let view_rel = glam::camera::rh::view::look_at_mat4(Vec3::ZERO, cam.target - cam.eye, cam.up.normalize());
        let eye = cam.eye.as_dvec3();
        let view = ShadowView { eye, view: view_rel, proj, width: w, height: h };
        let pass = self.pass.as_mut().ok_or("no pass")?;
        let prepared = pass.prepare(slot, &view, &self.scene.lights).map_err(|e| format!("prepare: {e}"))?;
        let prepare_ms = start.elapsed().as_secs_f64() * 1e3;
        let record_start = Instant::now();

        // Uniforms: per mesh its MVP (composed in f64 exactly as the pass composes its
        // volumes', so the volumes land on these depths), eye-relative model and normal map.
        self.write_uniforms(slot, eye, proj.as_dmat4() * view_rel.as_dmat4());
        let s = &self.slots[slot];
        let (device, queue) = (&self.gpu.device, &self.gpu.queue);

        let t = &self.targets;
        let pass = self.pass.as_ref().ok_or("no pass")?;
        let capture = if capture { s.readback.capture.as_ref() } else { None };
        let ds_write = || {
            std::iter::once(wgpu::TextureTransition {
                texture: &t.ds.texture,
                selector: None,
                state: wgpu::TextureUses::DEPTH_STENCIL_WRITE,
            })
        };
        let encoder = |label: &str| device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some(label) });
        let clear = |view| {
            Some(wgpu::RenderPassColorAttachment {
                view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations { load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT), store: wgpu::StoreOp::Store },
            })
        };
        let ds_ops = |depth, stencil| {
            Some(wgpu::RenderPassDepthStencilAttachment {
                view: &t.ds.view,
                depth_ops: Some(wgpu::Operations { load: depth, store: wgpu::StoreOp::Store }),
                stencil_ops: Some(wgpu::Operations { load: stencil, store: wgpu::StoreOp::Store }),
            })
        };
        let mut cbs = Vec::with_capacity(2 + 2 * self.scene.lights.len());

        // 1. Ambient + G-buffer.
        let mut e = encoder("ambient + G-buffer");
        {
            let mut rp = e.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("ambient + G-buffer"),
                color_attachments: &[clear(&t.accum.view), clear(&t.albedo.view), clear(&t.normal.view), clear(&t.position.view)],
                depth_stencil_attachment: ds_ops(wgpu::LoadOp::Clear(1.0), wgpu::LoadOp::Clear(0)),
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            rp.set_pipeline(&self.pipes.gbuffer);
            for (i, m) in self.meshes.iter().enumerate().filter(|(_, m)| m.vertex_count > 0) {
                rp.set_bind_group(0, &s.mesh_group, &[(i as u64 * UNIFORM_STRIDE) as u32]);
                rp.set_vertex_buffer(0, m.vertices.slice(..));
                rp.draw(0..m.vertex_count, 0..1);
            }
        }
        // What the raw determination expects: DEPTH_STENCIL_ATTACHMENT_OPTIMAL, depth written.
        e.transition_resources(std::iter::empty(), ds_write());
        cbs.push(e.finish());

        // 2. Per light: determination (raw), stencil out, lighting (wgpu).
        for (li, lf) in prepared.lights.iter().enumerate() {
            cbs.push(shadow::determine(device, &self.gpu.raw_device, pass, &prepared, li, &t.ds_target)?);
            let mut e = encoder("stencil readback + lighting");
            if let Some(c) = capture {
                copy_stencil_out(&mut e, &t.ds.texture, &c.stencil, li, (w, h));
            }
            let sc = lf.scissor;
            if sc.extent.width > 0 && sc.extent.height > 0 {
                let mut rp = e.begin_render_pass(&wgpu::RenderPassDescriptor {
                    label: Some("illuminate"),
                    color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                        view: &t.accum.view,
                        depth_slice: None,
                        resolve_target: None,
                        ops: wgpu::Operations { load: wgpu::LoadOp::Load, store: wgpu::StoreOp::Store },
                    })],
                    // Loaded and stored (not read-only), so wgpu keeps the texture in
                    // DEPTH_STENCIL_WRITE / DEPTH_STENCIL_ATTACHMENT_OPTIMAL between lights.
                    depth_stencil_attachment: ds_ops(wgpu::LoadOp::Load, wgpu::LoadOp::Load),
                    timestamp_writes: None,
                    occlusion_query_set: None,
                    multiview_mask: None,
                });
                rp.set_pipeline(&self.pipes.illuminate);
                rp.set_bind_group(0, &s.light_group, &[(li as u64 * UNIFORM_STRIDE) as u32]);
                rp.set_scissor_rect(sc.offset.x as u32, sc.offset.y as u32, sc.extent.width, sc.extent.height);
                rp.set_stencil_reference(0);
                rp.draw(0..3, 0..1);
            }
            // The next light's determination clears the stencil this pass tested.
            e.transition_resources(std::iter::empty(), ds_write());
            cbs.push(e.finish());
        }

        // 3. Tone map and copies out.
        let mut e = encoder("tone map + readback");
        self.tone_map(&mut e);
        copy_out(&mut e, &t.output.texture, &s.readback.color, 4, (w, h));
        if let Some(c) = capture {
            copy_out(&mut e, &t.position.texture, &c.positions, 16, (w, h));
            copy_out(&mut e, &t.normal.texture, &c.normals, 16, (w, h));
        }
        cbs.push(e.finish());
        let submission = queue.submit(cbs);
        let record_ms = record_start.elapsed().as_secs_f64() * 1e3;

        self.slots[slot].in_flight = Some(InFlight {
            frame: f,
            submission,
            captured: capture.is_some(),
            stats: prepared.lights.iter().map(|l| l.stats.clone()).collect(),
            totals: prepared.totals.clone(),
            cpu_ms: prepared.cpu_ms.clone(),
            warnings: prepared.warnings.clone(),
            start,
            prepare_ms,
            record_ms,
        });
        Ok(retired)
    }

    /// Writes slot `slot`'s uniforms: per mesh its MVP (`view_proj`, eye-relative, times the
    /// model in f64), eye-relative model and normal map; per light its block.
    fn write_uniforms(&self, slot: usize, eye: DVec3, view_proj: DMat4) {
        let vp = view_proj * DMat4::from_translation(-eye);
        let mut mesh_bytes = vec![0u8; UNIFORM_STRIDE as usize * self.scene.meshes.len().max(1)];
        for (i, m) in self.scene.meshes.iter().enumerate() {
            let model = m.transform.as_dmat4();
            let normal = model.inverse().transpose();
            let col = |v: glam::DVec4| v.truncate().as_vec3().extend(0.0).to_array();
            let block = MeshBlock {
                mvp: flip_y((vp * model).as_mat4()).to_cols_array(),
                model_rel: (DMat4::from_translation(-eye) * model).as_mat4().to_cols_array(),
                n: [col(normal.x_axis), col(normal.y_axis), col(normal.z_axis)],
                color: m.color.extend(1.0).to_array(),
                ambient: self.scene.ambient.extend(0.0).to_array(),
            };
            let o = i * UNIFORM_STRIDE as usize;
            mesh_bytes[o..o + std::mem::size_of::<MeshBlock>()].copy_from_slice(bytemuck::bytes_of(&block));
        }
        let mut light_bytes = vec![0u8; UNIFORM_STRIDE as usize * self.scene.lights.len().max(1)];
        for (i, l) in self.scene.lights.iter().enumerate() {
            let block = light_block(l, eye);
            let o = i * UNIFORM_STRIDE as usize;
            light_bytes[o..o + std::mem::size_of::<LightBlock>()].copy_from_slice(bytemuck::bytes_of(&block));
        }
        let s = &self.slots[slot];
        let queue = &self.gpu.queue;
        queue.write_buffer(&s.meshes, 0, &mesh_bytes);
        queue.write_buffer(&s.lights, 0, &light_bytes);
    }

    /// The tone map of the float target into the sRGB output.
    fn tone_map(&self, e: &mut wgpu::CommandEncoder) {
        let clear = |view| {
            Some(wgpu::RenderPassColorAttachment {
                view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations { load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT), store: wgpu::StoreOp::Store },
            })
        };
        let mut rp = e.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("tone map"),
            color_attachments: &[clear(&self.targets.output.view)],
            depth_stencil_attachment: None,
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        rp.set_pipeline(&self.pipes.tonemap);
        rp.set_bind_group(0, &self.pipes.tonemap_group, &[]);
        rp.draw(0..3, 0..1);
    }

    /// Waits for the frame in flight in `slot`, if any; with `read`, maps its readback into a
    /// [`FrameOutput`].
    pub fn retire(&mut self, slot: usize, read: bool) -> Result<Option<Retired>, String> {
        let Some(fl) = self.slots[slot].in_flight.take() else { return Ok(None) };
        let device = &self.gpu.device;
        device
            .poll(wgpu::PollType::Wait { submission_index: Some(fl.submission.clone()), timeout: None })
            .map_err(|e| format!("frame {}: {e}", fl.frame))?;
        let latency_ms = fl.start.elapsed().as_secs_f64() * 1e3;
        crate::gpu::check_errors(&format!("by frame {}", fl.frame))?;
        let timing = Timing { frame: fl.frame, slot, prepare_ms: fl.prepare_ms, record_ms: fl.record_ms, latency_ms };
        if !read {
            return Ok(Some(Retired { timing, output: None }));
        }
        let (w, h) = (self.targets.width, self.targets.height);
        let rb = &self.slots[slot].readback;
        let color = read_rows(device, &rb.color, w, h, 4)?;
        let mut out = FrameOutput {
            width: w,
            height: h,
            color,
            stencil: Vec::new(),
            counts: Vec::new(),
            transmit: Vec::new(),
            positions: Vec::new(),
            normals: Vec::new(),
            samples: Vec::new(),
            stats: self.stats(&fl, latency_ms),
        };
        if let (true, Some(c)) = (fl.captured, rb.capture.as_ref()) {
            let n = (w * h) as usize;
            let stencil = read_rows(device, &c.stencil, w, h * self.scene.lights.len() as u32, 1)?;
            out.stencil = stencil.chunks_exact(n).map(|s| s.to_vec()).collect();
            let pos: Vec<[f32; 4]> = bytemuck::pod_collect_to_vec(&read_rows(device, &c.positions, w, h, 16)?);
            let nrm: Vec<[f32; 4]> = bytemuck::pod_collect_to_vec(&read_rows(device, &c.normals, w, h, 16)?);
            let eye = self.scene.camera.eye.as_dvec3();
            for (p, n) in pos.iter().zip(&nrm) {
                if p[3] == 0.0 {
                    out.positions.push([f32::NAN; 3]);
                    out.normals.push([f32::NAN; 3]);
                } else {
                    // Eye-relative in the G-buffer; world space in f64.
                    out.positions.push((DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64) + eye).as_vec3().to_array());
                    out.normals.push([n[0], n[1], n[2]]);
                }
            }
        }
        Ok(Some(Retired { timing, output: Some(out) }))
    }

    /// The `--stats` record of a frame, as `umbrage render` fills it (no GPU timestamps).
    fn stats(&self, fl: &InFlight, wall_ms: f64) -> Stats {
        let settings = self.pass().settings();
        let caps = self.pass().capabilities();
        let feature = |name: &str, on: bool| (name.to_string(), on);
        let features = [
            feature("dynamicRendering", true),
            feature("synchronization2", true),
            feature("indexTypeUint8", caps.index_type_uint8),
            feature("depthBounds", caps.depth_bounds),
            feature("depthClamp", caps.depth_clamp),
        ];
        Stats {
            device: self.gpu.name.clone(),
            method: settings.technique.into(),
            depth_mode: self.pass().desc().depth_mode,
            index_format: settings.index_format,
            counter: settings.counter,
            transmit: None,
            self_shadow: false,
            width: self.targets.width,
            height: self.targets.height,
            lights: fl.stats.clone(),
            totals: fl.totals.clone(),
            cpu_ms: fl.cpu_ms.clone(),
            gpu_ms: None,
            wall_ms,
            features_used: features.iter().filter(|f| f.1).map(|f| f.0.clone()).collect(),
            features_missing: features.iter().filter(|f| !f.1).map(|f| f.0.clone()).collect(),
            counters: None,
            warnings: fl.warnings.clone(),
            ray_query: None,
            shadow_map: None,
        }
    }
}

/// A light's block for a frame whose eye is `eye` (as umbrage's `LightPush`).
fn light_block(l: &umbrage::geom::Light, eye: DVec3) -> LightBlock {
    let position = match l.kind {
        LightKind::Directional => (-l.direction.normalize()).extend(0.0),
        _ => (l.position.as_dvec3() - eye).as_vec3().extend(1.0),
    };
    let spot = match l.kind {
        LightKind::Spot => l.direction.normalize().extend((l.cone_deg.to_radians() * 0.5).cos()),
        _ => Vec4::new(0.0, 0.0, -1.0, -2.0),
    };
    LightBlock {
        position: position.to_array(),
        color: (l.color * l.intensity).extend(1.0).to_array(),
        spot: spot.to_array(),
        params: [l.radius.unwrap_or(0.0), 0.0, 0.0, 0.0],
    }
}

/// Maps a readback buffer (rows of `pitch(w, bpp)` bytes) and returns its `rows` rows, tight.
fn read_rows(device: &wgpu::Device, buffer: &wgpu::Buffer, w: u32, rows: u32, bpp: u32) -> Result<Vec<u8>, String> {
    let slice = buffer.slice(..);
    let (tx, rx) = std::sync::mpsc::channel();
    slice.map_async(wgpu::MapMode::Read, move |r| {
        let _ = tx.send(r);
    });
    device.poll(wgpu::PollType::wait_indefinitely()).map_err(|e| format!("poll: {e}"))?;
    rx.recv().map_err(|e| format!("map: {e}"))?.map_err(|e| format!("map: {e}"))?;
    let p = pitch(w, bpp) as usize;
    let row = (w * bpp) as usize;
    let out = {
        let data = slice.get_mapped_range().map_err(|e| format!("mapped range: {e}"))?;
        let mut out = Vec::with_capacity(row * rows as usize);
        for r in 0..rows as usize {
            out.extend_from_slice(&data[r * p..r * p + row]);
        }
        out
    };
    buffer.unmap();
    Ok(out)
}

/// Copies light `li`'s stencil out of the depth-stencil `texture` into its place in `buffer`
/// (lights one after another, rows `pitch(w, 1)` bytes apart).
fn copy_stencil_out(e: &mut wgpu::CommandEncoder, texture: &wgpu::Texture, buffer: &wgpu::Buffer, li: usize, (w, h): (u32, u32)) {
    let stencil_pitch = pitch(w, 1);
    e.copy_texture_to_buffer(
        wgpu::TexelCopyTextureInfo { texture, mip_level: 0, origin: wgpu::Origin3d::ZERO, aspect: wgpu::TextureAspect::StencilOnly },
        wgpu::TexelCopyBufferInfo {
            buffer,
            layout: wgpu::TexelCopyBufferLayout {
                offset: li as u64 * stencil_pitch as u64 * h as u64,
                bytes_per_row: Some(stencil_pitch),
                rows_per_image: Some(h),
            },
        },
        wgpu::Extent3d { width: w, height: h, depth_or_array_layers: 1 },
    );
}

/// Copies `texture` (`bpp` bytes a pixel) into `buffer`, rows `pitch(w, bpp)` bytes apart.
fn copy_out(e: &mut wgpu::CommandEncoder, texture: &wgpu::Texture, buffer: &wgpu::Buffer, bpp: u32, (w, h): (u32, u32)) {
    e.copy_texture_to_buffer(
        texture.as_image_copy(),
        wgpu::TexelCopyBufferInfo {
            buffer,
            layout: wgpu::TexelCopyBufferLayout { offset: 0, bytes_per_row: Some(pitch(w, bpp)), rows_per_image: Some(h) },
        },
        wgpu::Extent3d { width: w, height: h, depth_or_array_layers: 1 },
    );
}
