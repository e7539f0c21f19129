//! The host's frame: recording (the pass's uploads, the pre-pass, per light the determination,
//! the lighting pass and the per-sample readback), submission with the slot's fence, and the
//! readback of a retired slot turned into one frame dump per sample, each checked against the
//! reference.

use super::extract::ExtractPush;
use super::vulkan::{image_barrier, memory_barrier, vkerr, write_buffer};
use super::{FrameResult, Host, InFlight, Layout, LightResult, SampleFrame, BAND, FRAMES_IN_FLIGHT, GEOMETRY_WORDS};
use ash::vk;
use glam::{DMat4, DVec3, DVec4, Vec3};
use umbrage::pass::{reverse_z, DepthStencilTarget, ShadowView};

impl Host {
    /// Records and submits frame `f` into ring slot `f % 2`, after retiring that slot's
    /// previous frame (its fence, its readback into `out`).
    pub(super) fn frame(&mut self, f: usize, out: &mut Vec<FrameResult>) -> Result<(), String> {
        let slot = f % FRAMES_IN_FLIGHT;
        self.retire(slot, out)?;
        let s = self.scenes.at(f);
        // Move the caster: the pass re-plans from the new transform; nothing is re-created.
        if let Some((mi, _)) = self.scenes.moving {
            let id = self.meshes[mi].caster.ok_or("the moving mesh casts no shadow")?;
            self.pass().set_transform(id, s.meshes[mi].transform.as_dmat4()).map_err(|e| e.to_string())?;
        }

        let cam = &s.camera;
        let (w, h) = (self.extent.width, self.extent.height);
        let eye = cam.eye.as_dvec3();
        let view = glam::camera::rh::view::look_at_mat4(Vec3::ZERO, cam.target - cam.eye, cam.up.normalize());
        // The infinite projection, reversed for a reverse-Z host: the pass is told which.
        let forward = cam.proj_infinite(w as f32 / h as f32);
        let proj = if self.config.reverse_z { reverse_z(forward) } else { forward };
        let frame = self
            .pass()
            .prepare(slot, &ShadowView { eye, view, proj, width: w, height: h }, &s.lights)
            .map_err(|e| format!("prepare: {e}"))?;
        // Exactly as the pass composes its casters' MVPs, so the volumes land on these depths.
        let view_proj = proj.as_dmat4() * view.as_dmat4();
        let rels: Vec<DMat4> = s.meshes.iter().map(|m| DMat4::from_translation(-eye) * m.transform.as_dmat4()).collect();
        let push: Vec<[[f32; 16]; 2]> =
            rels.iter().map(|rel| [(view_proj * *rel).as_mat4().to_cols_array(), rel.as_mat4().to_cols_array()]).collect();

        // The lighting pass's index lists: per light and mesh, the triangles facing the light.
        let mut lit_data: Vec<u32> = Vec::new();
        let mut lit_draws = vec![Vec::new(); s.lights.len()];
        for (li, light) in s.lights.iter().enumerate() {
            let l = light.homogeneous().as_dvec4();
            for (mi, m) in s.meshes.iter().enumerate() {
                let xf = m.transform.as_dmat4();
                let world: Vec<DVec3> = self.meshes[mi].positions.iter().map(|p| xf.transform_point3(p.as_dvec3())).collect();
                let first = lit_data.len();
                for t in &self.meshes[mi].triangles {
                    let [a, b, c] = t.map(|i| world[i as usize]);
                    let to_light = l.truncate() - a * l.w;
                    if (b - a).cross(c - a).dot(to_light) > 0.0 {
                        lit_data.extend_from_slice(t);
                    }
                }
                lit_draws[li].push((first as u32, (lit_data.len() - first) as u32));
            }
        }
        write_buffer(&mut self.slots[slot].lit, bytemuck::cast_slice(&lit_data))?;

        match self.config.skip.iter().find(|(k, _)| *k == f).map(|&(_, how)| how) {
            Some(super::Skip::Unrecorded) => return Ok(()), // `frame` dropped unrecorded
            Some(super::Skip::RecordedNotSubmitted) => {
                // SAFETY: as below; the command buffer is reset, never submitted.
                unsafe { self.record(slot, &frame, &push, &lit_draws)? };
                // SAFETY: the command buffer was recorded above and is not pending execution.
                unsafe { self.dev().reset_command_buffer(self.slots[slot].cmd, vk::CommandBufferResetFlags::empty()) }
                    .map_err(vkerr("vkResetCommandBuffer"))?;
                return self.pass().abandon_frame(slot).map_err(|e| format!("abandon_frame: {e}"));
            }
            None => {}
        }

        let started = std::time::Instant::now();
        // SAFETY: the slot's previous submission retired (`retire` waited its fence), so its
        // command buffer may be re-recorded; `frame` was prepared for this slot, which is not
        // prepared again before this submission's fence is waited.
        unsafe { self.record(slot, &frame, &push, &lit_draws)? };
        let slot_ref = &self.slots[slot];
        let device = self.dev();
        // SAFETY: the command buffer was recorded and ended above; the fence is unsignalled
        // after the reset and belongs to this device.
        unsafe {
            device.reset_fences(&[slot_ref.fence]).map_err(vkerr("vkResetFences"))?;
            let cbs = [slot_ref.cmd];
            device
                .queue_submit(self.queue, &[vk::SubmitInfo::default().command_buffers(&cbs)], slot_ref.fence)
                .map_err(vkerr("vkQueueSubmit"))?;
        }
        self.slots[slot].in_flight = Some(InFlight {
            frame: f,
            scene: s.clone(),
            view_proj,
            stats: frame.lights.iter().map(|l| l.stats.clone()).collect(),
            totals: frame.totals.clone(),
            cpu_ms: frame.cpu_ms.clone(),
            warnings: frame.warnings.clone(),
            started,
        });
        Ok(())
    }

    /// Records slot `slot`'s command buffer: per mesh its `push` block (`mvp`, `rel`), per
    /// light and mesh its lit triangles (first index, count) in the slot's lit buffer.
    ///
    /// # Safety
    /// The slot's previous submission has completed; `frame` was prepared for `slot`.
    unsafe fn record(
        &self,
        slot: usize,
        frame: &umbrage::pass::PreparedFrame,
        push: &[[[f32; 16]; 2]],
        lit_draws: &[Vec<(u32, u32)>],
    ) -> Result<(), String> {
        let device = self.dev();
        let pass = self.pass.as_ref().ok_or("no pass")?;
        let depth = self.depth.as_ref().ok_or("no depth image")?;
        let lit_img = self.lit_target.as_ref().ok_or("no lit target")?;
        let normal_img = self.normal_target.as_ref().ok_or("no normal target")?;
        let slot_ref = &self.slots[slot];
        let cb = slot_ref.cmd;
        let samples = self.config.samples;
        let layout = Layout { pixels: self.extent.width * self.extent.height, samples };
        let full = vk::Rect2D { offset: vk::Offset2D { x: 0, y: 0 }, extent: self.extent };
        let (w, h) = (self.extent.width as f32, self.extent.height as f32);
        let viewport = vk::Viewport { x: 0.0, y: 0.0, width: w, height: h, min_depth: 0.0, max_depth: 1.0 };
        let clear_depth = if self.config.reverse_z { 0.0 } else { 1.0 };
        let ds_clear = vk::ClearValue { depth_stencil: vk::ClearDepthStencilValue { depth: clear_depth, stencil: 0 } };
        let color_clear = vk::ClearValue { color: vk::ClearColorValue { float32: [0.0; 4] } };
        let ds_aspects = vk::ImageAspectFlags::DEPTH | vk::ImageAspectFlags::STENCIL;
        let tests = vk::PipelineStageFlags::EARLY_FRAGMENT_TESTS | vk::PipelineStageFlags::LATE_FRAGMENT_TESTS;
        let ds_rw = vk::AccessFlags::DEPTH_STENCIL_ATTACHMENT_READ | vk::AccessFlags::DEPTH_STENCIL_ATTACHMENT_WRITE;
        let (ds_att, ds_read) = (vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL, vk::ImageLayout::DEPTH_STENCIL_READ_ONLY_OPTIMAL);
        let (color_att, shader_read) = (vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL, vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL);
        let output = (vk::PipelineStageFlags::COLOR_ATTACHMENT_OUTPUT, vk::AccessFlags::COLOR_ATTACHMENT_WRITE);
        let compute_read = (vk::PipelineStageFlags::COMPUTE_SHADER, vk::AccessFlags::SHADER_READ);
        // Whatever ran before (the previous frame's readback, on the same queue): done first.
        let before = (vk::PipelineStageFlags::ALL_COMMANDS, vk::AccessFlags::empty());
        let draw = |pipeline, draws: Option<&Vec<(u32, u32)>>| {
            // SAFETY: `cb` is recording inside the matching rendering instance or subpass.
            unsafe { self.draw_meshes(cb, pipeline, push, slot_ref.lit.raw, draws) }
        };
        // Dynamic rendering: `color` (its old contents discarded, cleared) and the depth-stencil
        // (`ds_load`: CLEAR for the pre-pass, LOAD for the lighting), over the whole frame.
        let begin_rendering = |color: &super::vulkan::Img, ds_load| {
            image_barrier(device, cb, color.raw, vk::ImageAspectFlags::COLOR, (vk::ImageLayout::UNDEFINED, color_att), before, output);
            let c = [attachment(color.view, color_att, vk::AttachmentLoadOp::CLEAR, color_clear)];
            let d = attachment(depth.view, ds_att, ds_load, ds_clear);
            let info = vk::RenderingInfo::default()
                .render_area(full)
                .layer_count(1)
                .color_attachments(&c)
                .depth_attachment(&d)
                .stencil_attachment(&d);
            // SAFETY: `cb` is recording outside any rendering; the views are live attachments
            // in the layouts the barriers before left them in.
            unsafe { device.cmd_begin_rendering(cb, &info) };
        };
        let begin_render_pass = |rp, fb, clears: &[vk::ClearValue]| begin_render_pass(device, cb, (rp, fb), full, clears);

        // SAFETY: (the whole recording) the caller's contract; every object recorded belongs to
        // this device and lives until the device is idle at teardown; the layouts named are
        // those the preceding barriers or render passes leave.
        unsafe {
            device.reset_command_buffer(cb, vk::CommandBufferResetFlags::empty()).map_err(vkerr("vkResetCommandBuffer"))?;
            device
                .begin_command_buffer(cb, &vk::CommandBufferBeginInfo::default().flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT))
                .map_err(vkerr("vkBeginCommandBuffer"))?;
            // The pass's uploads (new casters' vertices), outside any rendering.
            pass.cmd_before_rendering(cb, frame).map_err(|e| format!("cmd_before_rendering: {e}"))?;
            let lights = lit_draws.len() as u32;
            let first_query = slot as u32 * 2 * (lights + 1);
            if self.queries != vk::QueryPool::null() {
                device.cmd_reset_query_pool(cb, self.queries, first_query, 2 * (lights + 1));
            }
            let timestamp = |stage, query| {
                if self.queries != vk::QueryPool::null() {
                    // (Inside the recording's unsafe block: the query was reset above.)
                    device.cmd_write_timestamp(cb, stage, self.queries, first_query + query);
                }
            };
            timestamp(vk::PipelineStageFlags::TOP_OF_PIPE, 2 * lights);

            // The pre-pass: depth (stencil cleared to 0) and the normal of every sample.
            if self.config.render_pass {
                begin_render_pass(self.passes.prepass, self.passes.prepass_fb, &[color_clear, ds_clear]);
            } else {
                image_barrier(device, cb, depth.raw, ds_aspects, (vk::ImageLayout::UNDEFINED, ds_att), before, (tests, ds_rw));
                begin_rendering(normal_img, vk::AttachmentLoadOp::CLEAR);
            }
            device.cmd_set_viewport(cb, 0, &[viewport]);
            device.cmd_set_scissor(cb, 0, &[full]);
            draw(self.prepass, None);
            if self.config.render_pass {
                device.cmd_end_render_pass(cb);
            } else {
                device.cmd_end_rendering(cb);
                image_barrier(device, cb, normal_img.raw, vk::ImageAspectFlags::COLOR, (color_att, shader_read), output, compute_read);
                let written = (vk::PipelineStageFlags::LATE_FRAGMENT_TESTS, vk::AccessFlags::DEPTH_STENCIL_ATTACHMENT_WRITE);
                image_barrier(device, cb, depth.raw, ds_aspects, (ds_att, ds_read), written, compute_read);
            }

            for (li, draws) in lit_draws.iter().enumerate() {
                if self.config.render_pass {
                    // Inside the host's shadow subpass (depth-stencil only): the pass clears the
                    // stencil in the light's scissor (vkCmdClearAttachments) and counts; the
                    // lighting follows in the next subpass.
                    begin_render_pass(self.passes.lighting, self.passes.lighting_fb, &[color_clear, ds_clear]);
                    let target = DepthStencilTarget::new(depth.raw, depth.view, self.extent);
                    timestamp(vk::PipelineStageFlags::TOP_OF_PIPE, 2 * li as u32);
                    pass.cmd_determine(cb, frame, li, &target).map_err(|e| format!("cmd_determine: {e}"))?;
                    timestamp(vk::PipelineStageFlags::BOTTOM_OF_PIPE, 2 * li as u32 + 1);
                } else {
                    // The image is declared in DEPTH_STENCIL_READ_ONLY_OPTIMAL (the readback
                    // left it there) and wanted back in DEPTH_STENCIL_ATTACHMENT_OPTIMAL: the
                    // pass records both transitions.
                    let target = DepthStencilTarget::new(depth.raw, depth.view, self.extent).with_layouts(ds_read, ds_att);
                    timestamp(vk::PipelineStageFlags::TOP_OF_PIPE, 2 * li as u32);
                    pass.cmd_determine(cb, frame, li, &target).map_err(|e| format!("cmd_determine: {e}"))?;
                    timestamp(vk::PipelineStageFlags::BOTTOM_OF_PIPE, 2 * li as u32 + 1);
                    begin_rendering(lit_img, vk::AttachmentLoadOp::LOAD);
                }
                if self.config.render_pass {
                    // The lighting subpass (the count's stencil writes ordered before it).
                    device.cmd_next_subpass(cb, vk::SubpassContents::INLINE);
                }
                // The host's lighting pass: light-facing triangles, depth EQUAL, stencil == 0;
                // the viewport, the light's scissor and (when used) its depth bounds.
                device.cmd_bind_pipeline(cb, vk::PipelineBindPoint::GRAPHICS, self.lighting);
                pass.cmd_light_state(cb, frame, li, self.extent).map_err(|e| format!("cmd_light_state: {e}"))?;
                draw(self.lighting, Some(draws));
                if self.config.render_pass {
                    device.cmd_end_render_pass(cb);
                } else {
                    device.cmd_end_rendering(cb);
                    image_barrier(device, cb, lit_img.raw, vk::ImageAspectFlags::COLOR, (color_att, shader_read), output, compute_read);
                    let written = (tests, vk::AccessFlags::DEPTH_STENCIL_ATTACHMENT_WRITE);
                    image_barrier(device, cb, depth.raw, ds_aspects, (ds_att, ds_read), written, compute_read);
                }
                // Every sample's stencil and lit bit (and, once, its depth and normal).
                self.record_extract(cb, slot, li, &layout);
            }
            timestamp(vk::PipelineStageFlags::BOTTOM_OF_PIPE, 2 * lights + 1);
            memory_barrier(
                device,
                cb,
                (vk::PipelineStageFlags::COMPUTE_SHADER, vk::AccessFlags::SHADER_WRITE),
                (vk::PipelineStageFlags::HOST, vk::AccessFlags::HOST_READ),
            );
            device.end_command_buffer(cb).map_err(vkerr("vkEndCommandBuffer"))?;
        }
        Ok(())
    }

    /// Binds `pipeline` and draws every mesh with its `push` block: all its triangles (`draws`
    /// `None`), or its (first index, count) range of `draws` in the slot's `lit` index buffer.
    ///
    /// # Safety
    /// `cb` is recording inside the matching rendering instance or subpass.
    unsafe fn draw_meshes(
        &self,
        cb: vk::CommandBuffer,
        pipeline: vk::Pipeline,
        push: &[[[f32; 16]; 2]],
        lit: vk::Buffer,
        draws: Option<&Vec<(u32, u32)>>,
    ) {
        let device = self.dev();
        // SAFETY: the caller's contract.
        unsafe {
            device.cmd_bind_pipeline(cb, vk::PipelineBindPoint::GRAPHICS, pipeline);
            for (mi, m) in self.meshes.iter().enumerate() {
                device.cmd_push_constants(cb, self.layout, vk::ShaderStageFlags::VERTEX, 0, bytemuck::cast_slice(&push[mi]));
                device.cmd_bind_vertex_buffers(cb, 0, &[m.vertices.raw], &[0]);
                match draws {
                    None => {
                        device.cmd_bind_index_buffer(cb, m.indices.raw, 0, vk::IndexType::UINT32);
                        device.cmd_draw_indexed(cb, m.index_count, 1, 0, 0, 0);
                    }
                    Some(d) if d[mi].1 > 0 => {
                        device.cmd_bind_index_buffer(cb, lit, 0, vk::IndexType::UINT32);
                        device.cmd_draw_indexed(cb, d[mi].1, 1, d[mi].0, 0, 0);
                    }
                    Some(_) => {}
                }
            }
        }
    }

    /// Records the extraction of light `li`'s every sample into slot `slot`'s readback.
    ///
    /// # Safety
    /// As `Extract::record`'s: `cb` is recording outside any render pass; the views are in the
    /// layouts `Views` names, their writes made visible to compute shader reads.
    unsafe fn record_extract(&self, cb: vk::CommandBuffer, slot: usize, li: usize, layout: &Layout) {
        for sample in 0..self.config.samples {
            let push = ExtractPush {
                sample,
                width: self.extent.width,
                height: self.extent.height,
                geometry: (li == 0) as u32,
                geometry_at: layout.geometry(sample),
                packed_at: layout.packed(li, sample),
            };
            // SAFETY: the caller's contract.
            unsafe { self.extract.record(self.dev(), cb, slot, push) };
        }
    }

    /// Waits for the frame in flight in `slot` (if any), turns each sample of its readback
    /// into a frame dump and checks it against the reference.
    pub(super) fn retire(&mut self, slot: usize, out: &mut Vec<FrameResult>) -> Result<(), String> {
        let Some(fl) = self.slots[slot].in_flight.take() else { return Ok(()) };
        // SAFETY: the fence belongs to this device and was submitted with the frame.
        unsafe { self.dev().wait_for_fences(&[self.slots[slot].fence], true, u64::MAX) }.map_err(vkerr("vkWaitForFences"))?;
        let gpu_wall_ms = fl.started.elapsed().as_secs_f64() * 1e3;
        if let Some(first) = self.log.lock().ok().and_then(|l| l.first().cloned()) {
            return Err(format!("validation error by frame {}: {first}", fl.frame));
        }
        let s = &fl.scene;
        let (mut determine_ms, mut frame_gpu_ms) = (Vec::new(), f64::NAN);
        if self.queries != vk::QueryPool::null() {
            let n = 2 * (s.lights.len() + 1);
            let mut stamps = vec![0u64; n];
            // SAFETY: the queries were written by the submission whose fence was just waited.
            unsafe {
                self.dev().get_query_pool_results(
                    self.queries,
                    (slot * n) as u32,
                    &mut stamps,
                    vk::QueryResultFlags::TYPE_64 | vk::QueryResultFlags::WAIT,
                )
            }
            .map_err(vkerr("vkGetQueryPoolResults"))?;
            let period = self.timestamp_period as f64;
            let mut ms: Vec<f64> = stamps.chunks_exact(2).map(|t| t[1].saturating_sub(t[0]) as f64 * period * 1e-6).collect();
            frame_gpu_ms = ms.pop().unwrap_or(f64::NAN);
            determine_ms = ms;
        }
        let (w, h) = (self.extent.width, self.extent.height);
        let n = (w * h) as usize;
        let samples = self.config.samples;
        let layout = Layout { pixels: w * h, samples };
        let data = self.slots[slot].readback.alloc.as_ref().and_then(|a| a.mapped_slice()).ok_or("readback is not host visible")?;
        let words: &[u32] = bytemuck::cast_slice(&data[..layout.bytes(s.lights.len()) as usize]);
        let clear_depth = if self.config.reverse_z { 0.0 } else { 1.0 };
        let unproject = fl.view_proj.inverse();
        let eye = s.camera.eye.as_dvec3();
        let mut lights: Vec<LightResult> = (0..s.lights.len())
            .map(|_| LightResult {
                stencil: Vec::new(),
                mask: Vec::new(),
                mismatches: Vec::new(),
                compared: Vec::new(),
                shadowed: Vec::new(),
            })
            .collect();
        let mut sample_frames = Vec::with_capacity(samples as usize);
        for (si, &(sx, sy)) in umbrage_render::standard_sample_locations(samples).iter().enumerate() {
            let geometry = &words[layout.geometry(si as u32) as usize..][..GEOMETRY_WORDS as usize * n];
            let mut positions = Vec::with_capacity(3 * n);
            let mut normals = Vec::with_capacity(3 * n);
            let mut background = Vec::with_capacity(n);
            for (i, g) in geometry.chunks_exact(GEOMETRY_WORDS as usize).enumerate() {
                let depth = f32::from_bits(g[0]);
                let bg = depth == clear_depth;
                background.push(bg);
                if bg {
                    positions.extend([f32::NAN; 3]);
                    normals.extend([f32::NAN; 3]);
                    continue;
                }
                // The sample's position: its depth unprojected at its own location, then put
                // back on its triangle's plane (normal `n`, offset `d` from the eye) along the
                // normal: the depth of a rasteriser that snaps vertices coarsely lies a little
                // off the surface, which moves points in and out of the caster they lie on.
                let (x, y) = ((i % w as usize) as f64 + sx, (i / w as usize) as f64 + sy);
                let clip = DVec4::new(2.0 * x / w as f64 - 1.0, 2.0 * y / h as f64 - 1.0, depth as f64, 1.0);
                let r = unproject * clip;
                let [nx, ny, nz, d] = [g[1], g[2], g[3], g[4]].map(|v| f32::from_bits(v) as f64);
                let normal = DVec3::new(nx, ny, nz);
                let rel = r.truncate() / r.w;
                let p = eye + rel - normal * (normal.dot(rel) - d);
                positions.extend(p.as_vec3().to_array());
                normals.extend([g[1], g[2], g[3]].map(f32::from_bits));
            }
            let mut masks = Vec::with_capacity(s.lights.len());
            let mut stencils = Vec::with_capacity(s.lights.len());
            for (li, light) in s.lights.iter().enumerate() {
                let packed = &words[layout.packed(li, si as u32) as usize..][..n];
                stencils.push(packed.iter().map(|&v| (v & 0xff) as u8).collect::<Vec<u8>>());
                // Lit: the lighting pass wrote the sample (stencil 0, light-facing) and the
                // light reaches it (a spot's cone, a light's range: what a lighting shader's
                // attenuation would apply, applied here as umbrage's renderer does).
                let reaches = |i: usize| light.reaches(Vec3::new(positions[3 * i], positions[3 * i + 1], positions[3 * i + 2]));
                let mask = (0..n).map(|i| {
                    if background[i] {
                        128
                    } else if packed[i] & 0x100 != 0 && reaches(i) {
                        255
                    } else {
                        0
                    }
                });
                masks.push(mask.collect::<Vec<u8>>());
            }
            let dump = umbrage_render::output::scene_dump(s, (w, h), positions, normals, masks);
            let name = format!("frame {} sample {si}", fl.frame);
            let report = umbrage_reference::check(&dump, &name, BAND).map_err(|e| format!("check {name}: {e}"))?;
            for (li, l) in lights.iter_mut().enumerate() {
                let m = &report.lights[li].metrics;
                l.mismatches.push(m.mismatches_outside_band);
                l.compared.push(m.compared);
                l.shadowed.push(stencils[li].iter().zip(&background).filter(|(&s, &bg)| s != 0 && !bg).count() as u64);
                if si == 0 {
                    l.stencil = stencils[li].clone();
                    l.mask = dump.shadow[li].clone();
                }
            }
            sample_frames.push(SampleFrame { dump, stencil: stencils });
        }
        out.push(FrameResult {
            frame: fl.frame,
            slot,
            device: self.device_name.clone(),
            stats: fl.stats,
            totals: fl.totals,
            cpu_ms: fl.cpu_ms,
            warnings: fl.warnings,
            lights,
            samples: sample_frames,
            scene: fl.scene,
            gpu_wall_ms,
            determine_ms,
            frame_gpu_ms,
        });
        Ok(())
    }
}

/// A dynamic-rendering attachment at `view` in `layout`, loaded with `load` (or cleared to
/// `clear`) and stored.
fn attachment(
    view: vk::ImageView,
    layout: vk::ImageLayout,
    load: vk::AttachmentLoadOp,
    clear: vk::ClearValue,
) -> vk::RenderingAttachmentInfo<'static> {
    vk::RenderingAttachmentInfo::default()
        .image_view(view)
        .image_layout(layout)
        .load_op(load)
        .store_op(vk::AttachmentStoreOp::STORE)
        .clear_value(clear)
}

/// Begins render pass `rp` with framebuffer `fb` over `area`, inline contents.
fn begin_render_pass(
    device: &ash::Device,
    cb: vk::CommandBuffer,
    (rp, fb): (vk::RenderPass, vk::Framebuffer),
    area: vk::Rect2D,
    clears: &[vk::ClearValue],
) {
    let info = vk::RenderPassBeginInfo::default().render_pass(rp).framebuffer(fb).render_area(area).clear_values(clears);
    // SAFETY: the framebuffer matches the render pass; `cb` is outside any render pass.
    unsafe { device.cmd_begin_render_pass(cb, &info, vk::SubpassContents::INLINE) };
}
