//! The host's setup beyond instance and device: framebuffers (render-pass model), pipelines,
//! meshes and ring slots; and its teardown.

use super::pipelines::{create_pipeline, shader_module, PipelineState, Target};
use super::shaders;
use super::vulkan::{create_buffer, free_buffer, lock, upload, vkerr};
use super::{Host, Layout, MeshGpu, Slot, FRAMES_IN_FLIGHT, LIT_FORMAT, NORMAL_FORMAT};
use ash::vk;
use gpu_allocator::vulkan::Allocator;
use gpu_allocator::MemoryLocation;
use std::sync::{Arc, Mutex};
use umbrage::pass::lit_stencil_state;

impl Host {
    /// The render-pass model's framebuffers (the images are shared by both ring slots).
    pub(super) fn create_framebuffers(&mut self, device: &ash::Device) -> Result<(), String> {
        let ds = self.depth.as_ref().map(|i| i.view).ok_or("no depth image")?;
        let lit = self.lit_target.as_ref().map(|i| i.view).ok_or("no lit target")?;
        let normal = self.normal_target.as_ref().map(|i| i.view).ok_or("no normal target")?;
        for (rp, color, out) in [(self.passes.prepass, normal, 0), (self.passes.lighting, lit, 1)] {
            let views = [color, ds];
            let info = vk::FramebufferCreateInfo::default()
                .render_pass(rp)
                .attachments(&views)
                .width(self.extent.width)
                .height(self.extent.height)
                .layers(1);
            // SAFETY: the views are live and match the render pass's attachments.
            let fb = unsafe { device.create_framebuffer(&info, None) }.map_err(vkerr("vkCreateFramebuffer"))?;
            if out == 0 {
                self.passes.prepass_fb = fb;
            } else {
                self.passes.lighting_fb = fb;
            }
        }
        Ok(())
    }

    /// The pre-pass (depth LESS, or GREATER with reverse-Z; the normal written) and the
    /// lighting pass (depth EQUAL, stencil EQUAL 0, 1 written), from [`shaders::SCENE_WGSL`].
    pub(super) fn create_pipelines(&mut self, device: &ash::Device) -> Result<(), String> {
        let module = shader_module(device, &shaders::compile(shaders::SCENE_WGSL)?)?;
        let samples = self.config.samples;
        let prepass = PipelineState {
            module,
            fragment: c"fs_normal",
            depth_compare: if self.config.reverse_z { vk::CompareOp::GREATER } else { vk::CompareOp::LESS },
            depth_write: true,
            stencil: None,
            depth_bounds: false,
            samples,
        };
        let lighting = PipelineState {
            module,
            fragment: c"fs_lit",
            depth_compare: vk::CompareOp::EQUAL,
            depth_write: false,
            stencil: Some(lit_stencil_state()),
            depth_bounds: self.depth_bounds,
            samples,
        };
        let (pre_target, lit_target) = if self.config.render_pass {
            (Target::RenderPass(self.passes.prepass, 0), Target::RenderPass(self.passes.lighting, 1))
        } else {
            (Target::Dynamic { color: NORMAL_FORMAT, ds: self.ds_format }, Target::Dynamic { color: LIT_FORMAT, ds: self.ds_format })
        };
        let r1 = create_pipeline(device, self.layout, pre_target, &prepass);
        let r2 = create_pipeline(device, self.layout, lit_target, &lighting);
        // SAFETY: the module may be destroyed once the pipelines exist (or failed).
        unsafe { device.destroy_shader_module(module, None) };
        if let Ok(p) = &r1 {
            self.prepass = *p;
        }
        if let Ok(p) = &r2 {
            self.lighting = *p;
        }
        r1.and(r2).map(|_| ())
    }

    /// Every mesh's vertices (w = 1) and indices; the shadow casters added to the pass.
    pub(super) fn upload_meshes(&mut self, device: &ash::Device, allocator: &Arc<Mutex<Allocator>>) -> Result<(), String> {
        let s = self.scenes.at(0);
        for m in &s.meshes {
            let vertices: Vec<[f32; 4]> = m.mesh.positions.iter().map(|p| p.extend(1.0).to_array()).collect();
            let indices: Vec<u32> = m.mesh.triangles.iter().flatten().copied().collect();
            let vb = upload(
                device,
                allocator,
                &format!("{} vertices", m.name),
                bytemuck::cast_slice(&vertices),
                vk::BufferUsageFlags::VERTEX_BUFFER,
            )?;
            let ib = match upload(
                device,
                allocator,
                &format!("{} indices", m.name),
                bytemuck::cast_slice(&indices),
                vk::BufferUsageFlags::INDEX_BUFFER,
            ) {
                Ok(b) => b,
                Err(e) => {
                    free_buffer(device, allocator, vb);
                    return Err(e);
                }
            };
            let mut gpu = MeshGpu {
                vertices: vb,
                indices: ib,
                index_count: indices.len() as u32,
                positions: m.mesh.positions.clone(),
                triangles: m.mesh.triangles.clone(),
                caster: None,
            };
            if m.casts_shadow {
                match self.pass().add_caster(&m.name, &m.mesh, m.transform.as_dmat4()) {
                    Ok(id) => gpu.caster = Some(id),
                    Err(e) => {
                        self.meshes.push(gpu);
                        return Err(format!("add_caster({}): {e}", m.name));
                    }
                }
            }
            self.meshes.push(gpu);
        }
        Ok(())
    }

    /// Per ring slot: a command buffer, a fence, the readback buffer and the lit index list.
    pub(super) fn create_slots(&mut self, device: &ash::Device, allocator: &Arc<Mutex<Allocator>>) -> Result<(), String> {
        let s = self.scenes.at(0);
        let layout = Layout { pixels: self.extent.width * self.extent.height, samples: self.config.samples };
        let lit_bytes: u64 = s.meshes.iter().map(|m| m.mesh.triangles.len() as u64 * 12).sum::<u64>() * s.lights.len() as u64;
        // SAFETY: allocation from the host's pool; freed in `Drop for Host`.
        let cmds = unsafe {
            device.allocate_command_buffers(
                &vk::CommandBufferAllocateInfo::default()
                    .command_pool(self.pool)
                    .level(vk::CommandBufferLevel::PRIMARY)
                    .command_buffer_count(FRAMES_IN_FLIGHT as u32),
            )
        }
        .map_err(vkerr("vkAllocateCommandBuffers"))?;
        for (i, cmd) in cmds.into_iter().enumerate() {
            // SAFETY: as above.
            let fence = unsafe { device.create_fence(&vk::FenceCreateInfo::default(), None) }.map_err(vkerr("vkCreateFence"));
            let fence = match fence {
                Ok(f) => f,
                Err(e) => {
                    // SAFETY: the buffer was never submitted.
                    unsafe { device.free_command_buffers(self.pool, &[cmd]) };
                    return Err(e);
                }
            };
            let readback = create_buffer(
                device,
                allocator,
                &format!("readback {i}"),
                layout.bytes(s.lights.len()),
                vk::BufferUsageFlags::STORAGE_BUFFER,
                MemoryLocation::GpuToCpu,
            );
            let lit = create_buffer(
                device,
                allocator,
                &format!("lit indices {i}"),
                lit_bytes,
                vk::BufferUsageFlags::INDEX_BUFFER,
                MemoryLocation::CpuToGpu,
            );
            match (readback, lit) {
                (Ok(readback), Ok(lit)) => self.slots.push(Slot { cmd, fence, readback, lit, in_flight: None }),
                (r, l) => {
                    // SAFETY: neither object was ever used by the GPU.
                    unsafe {
                        device.destroy_fence(fence, None);
                        device.free_command_buffers(self.pool, &[cmd]);
                    }
                    let mut err = String::new();
                    for b in [r, l] {
                        match b {
                            Ok(b) => free_buffer(device, allocator, b),
                            Err(e) => err = e,
                        }
                    }
                    return Err(err);
                }
            }
        }
        Ok(())
    }
}

impl Drop for Host {
    /// Teardown: device idle, the pass, the host's buffers and images, the allocator (last
    /// Arc), pipelines, render passes, pool, device, messenger, instance.
    fn drop(&mut self) {
        if let Some(device) = self.device.take() {
            // SAFETY: after the wait nothing on the GPU uses any object destroyed below; each
            // is destroyed once, children before parents, the pass before its device.
            unsafe {
                let _ = device.device_wait_idle();
                drop(self.pass.take());
                self.extract.destroy(&device);
                device.destroy_query_pool(self.queries, None);
                for fb in [self.passes.prepass_fb, self.passes.lighting_fb] {
                    device.destroy_framebuffer(fb, None);
                }
                for v in [self.depth_view, self.stencil_view] {
                    device.destroy_image_view(v, None);
                }
                if let Some(allocator) = self.allocator.take() {
                    for m in self.meshes.drain(..) {
                        free_buffer(&device, &allocator, m.vertices);
                        free_buffer(&device, &allocator, m.indices);
                    }
                    for s in self.slots.drain(..) {
                        free_buffer(&device, &allocator, s.readback);
                        free_buffer(&device, &allocator, s.lit);
                        device.destroy_fence(s.fence, None);
                        device.free_command_buffers(self.pool, &[s.cmd]);
                    }
                    for img in [self.depth.take(), self.lit_target.take(), self.normal_target.take()].into_iter().flatten() {
                        device.destroy_image_view(img.view, None);
                        device.destroy_image(img.raw, None);
                        if let Some(a) = img.alloc {
                            let _ = lock(&allocator).free(a);
                        }
                    }
                    // The allocator frees its memory blocks when the last Arc drops: here,
                    // the pass's clone is gone.
                    if let Err(a) = Arc::try_unwrap(allocator) {
                        if let Ok(mut l) = self.log.lock() {
                            l.push(format!("allocator still shared at teardown ({} references)", Arc::strong_count(&a)));
                        }
                    }
                }
                for p in [self.prepass, self.lighting] {
                    device.destroy_pipeline(p, None);
                }
                device.destroy_pipeline_layout(self.layout, None);
                for rp in [self.passes.prepass, self.passes.lighting] {
                    device.destroy_render_pass(rp, None);
                }
                device.destroy_command_pool(self.pool, None);
                device.destroy_device(None);
            }
        }
        // SAFETY: every child of the instance is gone; the messenger goes before the instance,
        // and the log it writes into is still alive (a field, dropped after this body).
        unsafe {
            if let Some((du, m)) = self.debug.take() {
                du.destroy_debug_utils_messenger(m, None);
            }
            self.instance.destroy_instance(None);
        }
    }
}
