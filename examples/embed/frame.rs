//! The host's frame: recording (depth pre-pass, per light the determination, the stencil
//! copy and the lighting pass, the depth copy), submission with the slot's fence, and the
//! readback of a retired slot compared with the reference.

use super::vulkan::{image_barrier, memory_barrier, vkerr, write_buffer};
use super::{scene, FrameResult, Host, InFlight, Layout, LightResult, BAND, FRAMES_IN_FLIGHT, HEIGHT, MOVING_MESH, WIDTH};
use ash::vk;
use glam::{DMat4, DVec3, Mat4, Vec3, Vec4};
use umbrage::pass::push::VolumePush;
use umbrage::pass::{DepthStencilTarget, ShadowView};
use umbrage::reference::{metrics::compare_all, Reference};

impl Host {
    /// Records and submits frame `f` into ring slot `f % 2`, after retiring that slot's
    /// previous frame (its fence, its readback into `out`).
    pub(super) fn frame(&mut self, f: usize, out: &mut Vec<FrameResult>) -> Result<(), String> {
        let slot = f % FRAMES_IN_FLIGHT;
        self.retire(slot, out)?;
        let s = scene(f);
        // Move the caster: the pass re-plans from the new transform; nothing is re-created.
        let moving = self.meshes[MOVING_MESH].caster.ok_or("the box casts no shadow")?;
        self.pass().set_transform(moving, s.meshes[MOVING_MESH].transform.as_dmat4()).map_err(|e| e.to_string())?;

        let cam = &s.camera;
        let (w, h) = (WIDTH, HEIGHT);
        let eye = cam.eye.as_dvec3();
        // Eye-relative view (rotation only) and the infinite projection the pass assumes.
        let view = glam::camera::rh::view::look_at_mat4(Vec3::ZERO, cam.target - cam.eye, cam.up.normalize());
        let proj = cam.proj_infinite(w as f32 / h as f32);
        let frame = self
            .pass()
            .prepare(slot, &ShadowView { eye, view, proj, width: w, height: h }, &s.lights)
            .map_err(|e| format!("prepare: {e}"))?;
        // Exactly as the pass composes its casters' MVPs, so the volumes land on these depths.
        let mvps: Vec<Mat4> = s
            .meshes
            .iter()
            .map(|m| (proj.as_dmat4() * view.as_dmat4() * DMat4::from_translation(-eye) * m.transform.as_dmat4()).as_mat4())
            .collect();

        // The lighting pass's index lists: per light and mesh, the triangles facing the light.
        let mut lit_data: Vec<u32> = Vec::new();
        let mut lit_draws = vec![Vec::new(); s.lights.len()];
        for (li, light) in s.lights.iter().enumerate() {
            let lp = light.position.as_dvec3();
            for (mi, m) in s.meshes.iter().enumerate() {
                let xf = m.transform.as_dmat4();
                let world: Vec<DVec3> = self.meshes[mi].positions.iter().map(|p| xf.transform_point3(p.as_dvec3())).collect();
                let first = lit_data.len();
                for t in &self.meshes[mi].triangles {
                    let [a, b, c] = t.map(|i| world[i as usize]);
                    if (b - a).cross(c - a).dot(lp - a) > 0.0 {
                        lit_data.extend_from_slice(t);
                    }
                }
                lit_draws[li].push(((first * 4) as u64, (lit_data.len() - first) as u32));
            }
        }
        write_buffer(&mut self.slots[slot].lit, bytemuck::cast_slice(&lit_data))?;

        let device = self.dev().clone();
        let pass = self.pass.as_ref().ok_or("no pass")?;
        let depth = self.depth.as_ref().ok_or("no depth image")?;
        let lit_img = self.lit_target.as_ref().ok_or("no lit target")?;
        let slot_ref = &self.slots[slot];
        let cb = slot_ref.cmd;
        let layout = Layout { pixels: (w * h) as u64 };
        let full = vk::Rect2D { offset: vk::Offset2D { x: 0, y: 0 }, extent: self.extent };
        let viewport = vk::Viewport { x: 0.0, y: 0.0, width: w as f32, height: h as f32, min_depth: 0.0, max_depth: 1.0 };
        let ds_aspects = vk::ImageAspectFlags::DEPTH | vk::ImageAspectFlags::STENCIL;
        let frag_tests = vk::PipelineStageFlags2::EARLY_FRAGMENT_TESTS | vk::PipelineStageFlags2::LATE_FRAGMENT_TESTS;
        let ds_rw = vk::AccessFlags2::DEPTH_STENCIL_ATTACHMENT_READ | vk::AccessFlags2::DEPTH_STENCIL_ATTACHMENT_WRITE;
        let ds_layout = vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL;
        let src_layout = vk::ImageLayout::TRANSFER_SRC_OPTIMAL;
        let copy = vk::PipelineStageFlags2::COPY;
        let ds_att = |load: vk::AttachmentLoadOp| {
            vk::RenderingAttachmentInfo::default()
                .image_view(depth.view)
                .image_layout(ds_layout)
                .load_op(load)
                .store_op(vk::AttachmentStoreOp::STORE)
                .clear_value(vk::ClearValue { depth_stencil: vk::ClearDepthStencilValue { depth: 1.0, stencil: 0 } })
        };
        let copy_out = |img: vk::Image, aspect: vk::ImageAspectFlags, offset: u64| {
            let region = vk::BufferImageCopy::default()
                .buffer_offset(offset)
                .image_subresource(vk::ImageSubresourceLayers { aspect_mask: aspect, mip_level: 0, base_array_layer: 0, layer_count: 1 })
                .image_extent(vk::Extent3D { width: w, height: h, depth: 1 });
            // SAFETY: `cb` is recording outside a rendering instance; the image is in
            // TRANSFER_SRC_OPTIMAL and the range lies inside the slot's readback buffer.
            unsafe { device.cmd_copy_image_to_buffer(cb, img, src_layout, slot_ref.readback.raw, &[region]) };
        };
        let push = |mvp: Mat4, color: [f32; 4]| {
            let p = VolumePush::new(mvp, Vec4::ZERO, color);
            let stages = vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT;
            // SAFETY: `cb` is recording with a pipeline of `self.layout` bound; 96 bytes.
            unsafe { device.cmd_push_constants(cb, self.layout, stages, 0, bytemuck::bytes_of(&p)) };
        };
        let target = DepthStencilTarget::new(depth.raw, depth.view, self.extent);

        // SAFETY: (the whole recording) the slot's previous submission retired (`retire`
        // waited its fence), so its command buffer may be reset and re-recorded; every object
        // recorded belongs to this device and lives until the device is idle at teardown; the
        // layouts named are those the preceding barriers leave; `frame` was prepared for this
        // slot and the slot is not prepared again before this submission's fence is waited.
        unsafe {
            device.reset_command_buffer(cb, vk::CommandBufferResetFlags::empty()).map_err(vkerr("vkResetCommandBuffer"))?;
            device
                .begin_command_buffer(cb, &vk::CommandBufferBeginInfo::default().flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT))
                .map_err(vkerr("vkBeginCommandBuffer"))?;
            // The depth-stencil image: its previous contents (the other frame's) are discarded;
            // ALL_COMMANDS orders this after the previous frame's copies on the queue.
            image_barrier(
                &device,
                cb,
                depth.raw,
                ds_aspects,
                (vk::ImageLayout::UNDEFINED, ds_layout),
                (vk::PipelineStageFlags2::ALL_COMMANDS, vk::AccessFlags2::NONE),
                (frag_tests, ds_rw),
            );
            pass.cmd_before_rendering(cb, &frame).map_err(|e| e.to_string())?;

            // Depth pre-pass: every mesh, depth LESS, stencil cleared to 0.
            let d = ds_att(vk::AttachmentLoadOp::CLEAR);
            device.cmd_begin_rendering(
                cb,
                &vk::RenderingInfo::default().render_area(full).layer_count(1).depth_attachment(&d).stencil_attachment(&d),
            );
            device.cmd_bind_pipeline(cb, vk::PipelineBindPoint::GRAPHICS, self.prepass);
            device.cmd_set_viewport(cb, 0, &[viewport]);
            device.cmd_set_scissor(cb, 0, &[full]);
            for (mi, m) in self.meshes.iter().enumerate() {
                push(mvps[mi], [0.0; 4]);
                device.cmd_bind_vertex_buffers(cb, 0, &[m.vertices.raw], &[0]);
                device.cmd_bind_index_buffer(cb, m.indices.raw, 0, vk::IndexType::UINT32);
                device.cmd_draw_indexed(cb, m.index_count, 1, 0, 0, 0);
            }
            device.cmd_end_rendering(cb);
            memory_barrier(
                &device,
                cb,
                (vk::PipelineStageFlags2::LATE_FRAGMENT_TESTS, vk::AccessFlags2::DEPTH_STENCIL_ATTACHMENT_WRITE),
                (frag_tests, ds_rw),
            );

            for (li, draws) in lit_draws.iter().enumerate() {
                // The shadow determination: the count in the stencil.
                pass.cmd_determine(cb, &frame, li, &target).map_err(|e| e.to_string())?;
                // Stencil out (readback), then back to attachment for the lighting pass.
                image_barrier(
                    &device,
                    cb,
                    depth.raw,
                    ds_aspects,
                    (ds_layout, src_layout),
                    (frag_tests, ds_rw),
                    (copy, vk::AccessFlags2::TRANSFER_READ),
                );
                copy_out(depth.raw, vk::ImageAspectFlags::STENCIL, layout.stencil(li));
                image_barrier(
                    &device,
                    cb,
                    depth.raw,
                    ds_aspects,
                    (src_layout, ds_layout),
                    (copy, vk::AccessFlags2::NONE),
                    (frag_tests, ds_rw),
                );

                // The host's lighting pass: light-facing triangles, depth EQUAL, stencil == 0.
                image_barrier(
                    &device,
                    cb,
                    lit_img.raw,
                    vk::ImageAspectFlags::COLOR,
                    (vk::ImageLayout::UNDEFINED, vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL),
                    (copy, vk::AccessFlags2::NONE),
                    (vk::PipelineStageFlags2::COLOR_ATTACHMENT_OUTPUT, vk::AccessFlags2::COLOR_ATTACHMENT_WRITE),
                );
                let color = [vk::RenderingAttachmentInfo::default()
                    .image_view(lit_img.view)
                    .image_layout(vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL)
                    .load_op(vk::AttachmentLoadOp::CLEAR)
                    .store_op(vk::AttachmentStoreOp::STORE)
                    .clear_value(vk::ClearValue { color: vk::ClearColorValue { float32: [0.0; 4] } })];
                let d = ds_att(vk::AttachmentLoadOp::LOAD);
                device.cmd_begin_rendering(
                    cb,
                    &vk::RenderingInfo::default()
                        .render_area(full)
                        .layer_count(1)
                        .color_attachments(&color)
                        .depth_attachment(&d)
                        .stencil_attachment(&d),
                );
                device.cmd_bind_pipeline(cb, vk::PipelineBindPoint::GRAPHICS, self.lighting);
                // Viewport, the light's scissor and (when used) its depth bounds.
                pass.cmd_light_state(cb, &frame, li, self.extent).map_err(|e| e.to_string())?;
                device.cmd_bind_index_buffer(cb, slot_ref.lit.raw, 0, vk::IndexType::UINT32);
                for (mi, m) in self.meshes.iter().enumerate() {
                    let (offset, count) = draws[mi];
                    if count == 0 {
                        continue;
                    }
                    push(mvps[mi], [1.0; 4]);
                    device.cmd_bind_vertex_buffers(cb, 0, &[m.vertices.raw], &[0]);
                    device.cmd_draw_indexed(cb, count, 1, (offset / 4) as u32, 0, 0);
                }
                device.cmd_end_rendering(cb);
                image_barrier(
                    &device,
                    cb,
                    lit_img.raw,
                    vk::ImageAspectFlags::COLOR,
                    (vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL, src_layout),
                    (vk::PipelineStageFlags2::COLOR_ATTACHMENT_OUTPUT, vk::AccessFlags2::COLOR_ATTACHMENT_WRITE),
                    (copy, vk::AccessFlags2::TRANSFER_READ),
                );
                copy_out(lit_img.raw, vk::ImageAspectFlags::COLOR, layout.lit(li));
                // The next light's determination clears the stencil the lighting pass read.
                memory_barrier(&device, cb, (frag_tests, ds_rw), (frag_tests, ds_rw));
            }

            // The depth, once: background is depth 1.0.
            image_barrier(
                &device,
                cb,
                depth.raw,
                ds_aspects,
                (ds_layout, src_layout),
                (frag_tests, ds_rw),
                (copy, vk::AccessFlags2::TRANSFER_READ),
            );
            copy_out(depth.raw, vk::ImageAspectFlags::DEPTH, layout.depth());
            memory_barrier(
                &device,
                cb,
                (copy, vk::AccessFlags2::TRANSFER_WRITE),
                (vk::PipelineStageFlags2::HOST, vk::AccessFlags2::HOST_READ),
            );
            device.end_command_buffer(cb).map_err(vkerr("vkEndCommandBuffer"))?;
            device.reset_fences(&[slot_ref.fence]).map_err(vkerr("vkResetFences"))?;
            let cbs = [cb];
            device
                .queue_submit(self.queue, &[vk::SubmitInfo::default().command_buffers(&cbs)], slot_ref.fence)
                .map_err(vkerr("vkQueueSubmit"))?;
        }
        self.slots[slot].in_flight = Some(InFlight {
            frame: f,
            stats: frame.lights.iter().map(|l| l.stats.clone()).collect(),
            totals: frame.totals.clone(),
            cpu_ms: frame.cpu_ms.clone(),
            warnings: frame.warnings.clone(),
        });
        Ok(())
    }

    /// Waits for the frame in flight in `slot` (if any), reads its readback and compares it
    /// with the reference of that frame's scene.
    pub(super) fn retire(&mut self, slot: usize, out: &mut Vec<FrameResult>) -> Result<(), String> {
        let Some(fl) = self.slots[slot].in_flight.take() else { return Ok(()) };
        // SAFETY: the fence belongs to this device and was submitted with the frame.
        unsafe { self.dev().wait_for_fences(&[self.slots[slot].fence], true, u64::MAX) }.map_err(vkerr("vkWaitForFences"))?;
        if let Some(first) = self.log.lock().ok().and_then(|l| l.first().cloned()) {
            return Err(format!("validation error by frame {}: {first}", fl.frame));
        }
        let s = scene(fl.frame);
        let layout = Layout { pixels: (WIDTH * HEIGHT) as u64 };
        let n = layout.pixels as usize;
        let data = self.slots[slot].readback.alloc.as_ref().and_then(|a| a.mapped_slice()).ok_or("readback is not host visible")?;
        let depth = &data[..4 * n];
        let d24 = self.ds_format == vk::Format::D24_UNORM_S8_UINT;
        let background: Vec<bool> = depth
            .chunks_exact(4)
            .map(|b| {
                let v = u32::from_le_bytes([b[0], b[1], b[2], b[3]]);
                if d24 {
                    v & 0x00ff_ffff == 0x00ff_ffff
                } else {
                    f32::from_bits(v) == 1.0
                }
            })
            .collect();
        let mut lights = Vec::with_capacity(s.lights.len());
        for li in 0..s.lights.len() {
            let so = layout.stencil(li) as usize;
            let lo = layout.lit(li) as usize;
            let stencil = data[so..so + n].to_vec();
            let lit = &data[lo..lo + n];
            let mask = (0..n)
                .map(|i| {
                    if background[i] {
                        128
                    } else if lit[i] != 0 {
                        255
                    } else {
                        0
                    }
                })
                .collect();
            lights.push(LightResult { stencil, mask, mismatches_outside_band: 0, compared: 0 });
        }
        let masks: Vec<Vec<u8>> = lights.iter().map(|l| l.mask.clone()).collect();
        let reference = Reference::from_scene(&s).render(&s.camera, &s.lights, WIDTH, HEIGHT);
        let metrics = compare_all(&masks, &reference, BAND).map_err(|e| format!("compare: {e}"))?;
        for (l, m) in lights.iter_mut().zip(&metrics) {
            l.mismatches_outside_band = m.mismatches_outside_band;
            l.compared = m.compared;
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
        });
        Ok(())
    }
}
