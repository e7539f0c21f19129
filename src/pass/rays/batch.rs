//! Every light of a ray-query frame in one pass per 32 lights ([`PassToggles::ray_batch`](crate::pass::PassToggles::ray_batch), off by default):
//! `rayquery.wgsl`'s `batch` reads the G-buffer once per pixel and writes a bit mask of the
//! lights whose ray is blocked (the same rays as the per-light pass, bit for bit), then each
//! light's `cmd_determine` turns its bit into the stencil (`rayquery_mask.wgsl`): a texture
//! read per pixel instead of a G-buffer read and a ray.
//!
//! Per ring slot: the lights' storage buffer (eye-relative light and scissor, 32 bytes each) and
//! an `R32_UINT` mask image of the frame's extent with the descriptor set that samples it.

use super::push::RayPush;
use crate::error::{Error, Result};
use crate::gpu::descriptors::{pipeline_layout, Binding, DescriptorSet};
use crate::gpu::pipeline::{self, PipelineDesc};
use crate::gpu::resources::{transition_range, Image};
use crate::gpu::{shaders, Buffer};
use crate::pass::desc::ShadowPassDesc;
use crate::pass::device::PassDevice;
use ash::vk;
use gpu_allocator::MemoryLocation;
use std::cell::Cell;

/// Lights per batch: the bits of the mask.
pub(crate) const BATCH: usize = 32;

/// The mask's format.
const MASK_FORMAT: vk::Format = vk::Format::R32_UINT;

/// One light as `batch` reads it.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
pub(super) struct BatchLight {
    pub light: [f32; 4],
    /// x0, y0, x1, y1 in pixels.
    pub scissor: [f32; 4],
}

/// A slot's batch resources.
#[derive(Default)]
pub(super) struct SlotBatch {
    /// The lights (host visible), and how many it holds.
    pub lights: Option<(Buffer, usize)>,
    /// The mask and the set that samples it.
    pub mask: Option<(Image, DescriptorSet)>,
}

impl SlotBatch {
    /// The lights buffer, grown to hold `n` lights and written with `data` (the slot retired).
    pub fn write_lights(&mut self, dev: &PassDevice, n: usize, data: &[BatchLight]) -> Result<vk::Buffer> {
        if self.lights.as_ref().is_none_or(|(_, cap)| *cap < n.max(1)) {
            if let Some((mut old, _)) = self.lights.take() {
                old.destroy(dev);
            }
            let cap = n.max(1).next_power_of_two();
            let size = (cap * std::mem::size_of::<BatchLight>()) as u64;
            let b = Buffer::new(dev, "ray-query batch lights", size, vk::BufferUsageFlags::STORAGE_BUFFER, MemoryLocation::CpuToGpu)?;
            self.lights = Some((b, cap));
        }
        let (buf, _) = self.lights.as_mut().ok_or_else(|| Error::Internal("no batch lights".into()))?;
        if !data.is_empty() {
            buf.write(0, bytemuck::cast_slice(data))?;
        }
        Ok(buf.raw)
    }

    /// The mask of `extent` (re-made when the extent changed) and its set.
    pub fn mask(&mut self, dev: &PassDevice, extent: vk::Extent2D) -> Result<(&Image, vk::DescriptorSet)> {
        if self.mask.as_ref().is_none_or(|(m, _)| m.extent != extent) {
            self.destroy_mask(dev);
            let usage = vk::ImageUsageFlags::COLOR_ATTACHMENT | vk::ImageUsageFlags::SAMPLED;
            let mut image = Image::new_2d(dev, "ray-query mask", MASK_FORMAT, extent, usage, vk::ImageAspectFlags::COLOR)?;
            match DescriptorSet::new(dev, &[Binding::Image(image.view)]) {
                Ok(set) => self.mask = Some((image, set)),
                Err(e) => {
                    image.destroy(dev);
                    return Err(e);
                }
            }
        }
        match &self.mask {
            Some((image, set)) => Ok((image, set.set)),
            None => Err(Error::Internal("no ray-query mask".into())),
        }
    }

    fn destroy_mask(&mut self, dev: &PassDevice) {
        if let Some((mut image, mut set)) = self.mask.take() {
            set.destroy(dev);
            image.destroy(dev);
        }
    }

    pub fn destroy(&mut self, dev: &PassDevice) {
        self.destroy_mask(dev);
        if let Some((mut b, _)) = self.lights.take() {
            b.destroy(dev);
        }
    }
}

/// The batch pipeline (the rays' layout, an `R32_UINT` colour target) and the resolve pipeline
/// (the mask's set, the stencil marked where the light's bit is set).
pub(super) struct BatchPipes {
    pub batch: vk::Pipeline,
    pub mask_layout: vk::PipelineLayout,
    pub resolve: vk::Pipeline,
}

impl BatchPipes {
    pub fn new(
        dev: &PassDevice,
        desc: &ShadowPassDesc,
        ray_layout: vk::PipelineLayout,
        mask_set: vk::DescriptorSetLayout,
    ) -> Result<BatchPipes> {
        let formats = [MASK_FORMAT];
        let mut b = PipelineDesc::new(shaders::FULLSCREEN_VERT, ray_layout, vk::Format::UNDEFINED);
        b.fragment = Some(shaders::RAYQUERY_WGSL);
        b.fragment_entry = c"batch";
        b.color_formats = &formats;
        let batch = pipeline::create(dev, &b)?;
        let mask_layout = match pipeline_layout(dev, &[mask_set], 4, vk::ShaderStageFlags::FRAGMENT) {
            Ok(l) => l,
            Err(e) => {
                // SAFETY: the pipeline was just created and never used.
                unsafe { dev.device.destroy_pipeline(batch, None) };
                return Err(e);
            }
        };
        let mut r = PipelineDesc::new(shaders::FULLSCREEN_VERT, mask_layout, desc.depth_stencil_format);
        r.fragment = Some(shaders::RAYQUERY_MASK_WGSL);
        r.stencil = Some((super::MARK, super::MARK));
        r.color_write = false;
        match pipeline::create(dev, &r) {
            Ok(resolve) => Ok(BatchPipes { batch, mask_layout, resolve }),
            Err(e) => {
                // SAFETY: both were just created and never used.
                unsafe {
                    dev.device.destroy_pipeline(batch, None);
                    dev.device.destroy_pipeline_layout(mask_layout, None);
                }
                Err(e)
            }
        }
    }

    /// Destroys the pipelines (no pending work uses them).
    pub fn destroy(&mut self, dev: &PassDevice) {
        // SAFETY: the owner's contract.
        unsafe {
            dev.device.destroy_pipeline(self.batch, None);
            dev.device.destroy_pipeline(self.resolve, None);
            dev.device.destroy_pipeline_layout(self.mask_layout, None);
        }
    }
}

/// A batched frame's bindings: the slot's mask, its set, the pipelines, and per batch of
/// [`BATCH`] lights the union of their scissors.
#[derive(Debug)]
pub(crate) struct BatchFrame {
    pub mask: vk::Image,
    pub mask_view: vk::ImageView,
    pub extent: vk::Extent2D,
    pub mask_set: vk::DescriptorSet,
    pub batch: vk::Pipeline,
    pub mask_layout: vk::PipelineLayout,
    pub resolve: vk::Pipeline,
    pub unions: Vec<vk::Rect2D>,
    /// The batch the mask holds now (recorded in this frame's command buffer).
    pub traced: Cell<Option<usize>>,
}

/// The union of `rects` (an empty rectangle for none).
pub(super) fn union(rects: &[vk::Rect2D]) -> vk::Rect2D {
    let mut lo = (i32::MAX, i32::MAX);
    let mut hi = (i32::MIN, i32::MIN);
    for r in rects.iter().filter(|r| r.extent.width > 0 && r.extent.height > 0) {
        lo = (lo.0.min(r.offset.x), lo.1.min(r.offset.y));
        hi = (hi.0.max(r.offset.x + r.extent.width as i32), hi.1.max(r.offset.y + r.extent.height as i32));
    }
    if lo.0 >= hi.0 {
        return vk::Rect2D::default();
    }
    vk::Rect2D {
        offset: vk::Offset2D { x: lo.0, y: lo.1 },
        extent: vk::Extent2D { width: (hi.0 - lo.0) as u32, height: (hi.1 - lo.1) as u32 },
    }
}

/// A light's scissor as `batch` compares fragment centres with it.
pub(super) fn scissor_f32(r: &vk::Rect2D) -> [f32; 4] {
    let (x, y) = (r.offset.x as f32, r.offset.y as f32);
    [x, y, x + r.extent.width as f32, y + r.extent.height as f32]
}

impl BatchFrame {
    /// Records batch `b`'s rays into the mask unless it holds them already: the mask
    /// `UNDEFINED -> COLOR_ATTACHMENT_OPTIMAL`, cleared and written inside the batch's
    /// scissors, then `-> SHADER_READ_ONLY_OPTIMAL`.
    ///
    /// # Safety
    /// `cb` is recording outside any rendering instance, after the frame's acceleration
    /// structures; `set` and `layout` are the rays' (the G-buffer in shader-read layout).
    pub unsafe fn cmd_trace_batch(
        &self,
        dev: &PassDevice,
        cb: vk::CommandBuffer,
        b: usize,
        (set, layout): (vk::DescriptorSet, vk::PipelineLayout),
        push: RayPush,
    ) -> Result<()> {
        if self.traced.get() == Some(b) {
            return Ok(());
        }
        let area = *self.unions.get(b).ok_or_else(|| Error::Internal(format!("no ray batch {b}")))?;
        let d = &dev.device;
        let range = vk::ImageSubresourceRange {
            aspect_mask: vk::ImageAspectFlags::COLOR,
            base_mip_level: 0,
            level_count: 1,
            base_array_layer: 0,
            layer_count: 1,
        };
        transition_range(dev, cb, self.mask, range, vk::ImageLayout::UNDEFINED, vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL);
        let color = [vk::RenderingAttachmentInfo::default()
            .image_view(self.mask_view)
            .image_layout(vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL)
            .load_op(vk::AttachmentLoadOp::CLEAR)
            .store_op(vk::AttachmentStoreOp::STORE)
            .clear_value(vk::ClearValue { color: vk::ClearColorValue { uint32: [0; 4] } })];
        let info = vk::RenderingInfo::default().render_area(area).layer_count(1).color_attachments(&color);
        let viewport = vk::Viewport {
            x: 0.0,
            y: 0.0,
            width: self.extent.width as f32,
            height: self.extent.height as f32,
            min_depth: 0.0,
            max_depth: 1.0,
        };
        // SAFETY: the caller's contract; the mask, set and pipeline live until the slot retires.
        unsafe {
            d.cmd_begin_rendering(cb, &info);
            d.cmd_set_viewport(cb, 0, &[viewport]);
            d.cmd_set_scissor(cb, 0, &[area]);
            d.cmd_bind_pipeline(cb, vk::PipelineBindPoint::GRAPHICS, self.batch);
            d.cmd_bind_descriptor_sets(cb, vk::PipelineBindPoint::GRAPHICS, layout, 0, &[set], &[]);
            d.cmd_push_constants(cb, layout, vk::ShaderStageFlags::FRAGMENT, 0, bytemuck::bytes_of(&push));
            d.cmd_draw(cb, 3, 1, 0, 0);
            d.cmd_end_rendering(cb);
        }
        transition_range(dev, cb, self.mask, range, vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL, vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL);
        self.traced.set(Some(b));
        Ok(())
    }
}
