//! The frame's own pipelines (everything but the shadow determination, which is the
//! [`ShadowPass`](umbrage::pass::ShadowPass)'s), their layouts and descriptor sets: a set that
//! destroys exactly what it created.

use super::push::{ForwardPush, GBufferPush, LightPush, SpherePush};
use super::scene_gpu::{GBUFFER_ATTRIBUTES, INSTANCE_ATTRIBUTES, INSTANCE_STRIDE, SCENE_VERTEX_STRIDE, VERTEX_ATTRIBUTES, VERTEX_STRIDE};
use super::targets::*;
use crate::shaders;
use ash::vk;
use umbrage::error::Result;
use umbrage::gpu::descriptors::{pipeline_layout, Binding, DescriptorSet};
use umbrage::gpu::pipeline::{self, Blend, PipelineDesc};
use umbrage::gpu::Context;

/// Layouts, by what they serve.
pub(crate) struct Layouts {
    /// G-buffer: [`GBufferPush`].
    pub gbuffer: vk::PipelineLayout,
    /// Illumination: the G-buffer set + [`LightPush`].
    pub illuminate: vk::PipelineLayout,
    /// Tone map: the accumulation set.
    pub tonemap: vk::PipelineLayout,
    /// Transparent forward passes: [`ForwardPush`].
    pub forward: vk::PipelineLayout,
    /// The analytic spheres of a multisampled frame: [`SpherePush`].
    pub sphere_ms: vk::PipelineLayout,
}

/// The per-sample readback of a multisampled frame ([`SampleReadback`]): a full-screen pass
/// copies one sample of the position, normal or stencil target into a single-sample image.
pub(crate) struct SampleReadbackPipes {
    /// One source image and the sampler; push: the sample index (an `i32`).
    pub layout: vk::PipelineLayout,
    /// Into the RGBA32F readback image.
    pub geometry: vk::Pipeline,
    /// Into the R8_UINT readback image.
    pub stencil: vk::Pipeline,
    /// The position, normal and stencil sources.
    pub position_set: DescriptorSet,
    pub normal_set: DescriptorSet,
    pub stencil_set: DescriptorSet,
}

pub(crate) struct FramePipelines {
    pub layouts: Layouts,
    /// Set 0 of illumination: albedo, normal, position, sampler, float count, intensity map.
    pub gbuffer_set: DescriptorSet,
    /// Set 0 of the tone map: accumulation, sampler.
    pub accum_set: DescriptorSet,
    pub sampler: vk::Sampler,
    pub gbuffer: vk::Pipeline,
    pub gbuffer_two_sided: vk::Pipeline,
    /// Analytic spheres: their bounding cubes' back faces, ray-cast, depth written.
    pub gbuffer_sphere: vk::Pipeline,
    /// `[stencil, float count][without, with the light-intensity map]`.
    pub illuminate: [[vk::Pipeline; 2]; 2],
    pub transparent_over: vk::Pipeline,
    pub transparent_light: vk::Pipeline,
    pub tonemap: vk::Pipeline,
    /// The accumulation target's format the pipelines draw into.
    pub accum_format: vk::Format,
    /// With multisampled targets, the per-sample readback.
    pub sample_readback: Option<SampleReadbackPipes>,
    made: Vec<vk::Pipeline>,
}

/// A scene-geometry pipeline description (vertex + instance bindings).
pub fn scene_pipeline<'a>(vertex: &'a [u8], layout: vk::PipelineLayout, depth_format: vk::Format) -> PipelineDesc<'a> {
    let mut p = PipelineDesc::new(vertex, layout, depth_format);
    p.vertex_stride = SCENE_VERTEX_STRIDE;
    p.attributes = &VERTEX_ATTRIBUTES;
    p.instance_stride = INSTANCE_STRIDE;
    p.instance_attributes = &INSTANCE_ATTRIBUTES;
    p
}

impl FramePipelines {
    /// `depth_bounds`: illumination tests the stored depth against the light's depth range
    /// (dynamic state) when the device has the feature.
    pub fn new(ctx: &Context, targets: &Targets, depth_bounds: bool) -> Result<FramePipelines> {
        let d = &ctx.device;
        // SAFETY: plain object creation on a valid device; destroyed in `destroy`.
        let sampler = unsafe {
            d.create_sampler(&vk::SamplerCreateInfo::default().mag_filter(vk::Filter::NEAREST).min_filter(vk::Filter::NEAREST), None)
        }
        .map_err(umbrage::Error::vk("vkCreateSampler"))?;
        let t = targets;
        let gbuffer_set = DescriptorSet::new(
            ctx,
            &[
                Binding::Image(t.albedo.view),
                Binding::Image(t.normal.view),
                Binding::Image(t.position.view),
                Binding::Sampler(sampler),
                Binding::Image(t.count.view),
                Binding::Image(t.transmit.view),
            ],
        )?;
        let accum_set = DescriptorSet::new(ctx, &[Binding::Image(t.accum.view), Binding::Sampler(sampler)])?;
        let ms = t.samples > 1;
        let samples = vk::SampleCountFlags::from_raw(t.samples);
        let vf = vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT;
        let frag = vk::ShaderStageFlags::FRAGMENT;
        let size = |n: usize| n as u32;
        let layouts = Layouts {
            gbuffer: pipeline_layout(ctx, &[], size(std::mem::size_of::<GBufferPush>()), vf)?,
            illuminate: pipeline_layout(ctx, &[gbuffer_set.layout], size(std::mem::size_of::<LightPush>()), frag)?,
            // The resolving variant's push: the sample count.
            tonemap: pipeline_layout(ctx, &[accum_set.layout], 4, frag)?,
            forward: pipeline_layout(ctx, &[], size(std::mem::size_of::<ForwardPush>()), vf)?,
            sphere_ms: pipeline_layout(ctx, &[], size(std::mem::size_of::<SpherePush>()), vf)?,
        };
        let mut made = Vec::new();
        let mut create = |desc: &PipelineDesc| -> Result<vk::Pipeline> {
            let p = pipeline::create(ctx, desc)?;
            made.push(p);
            Ok(p)
        };
        let df = ctx.depth_format;
        let gbuffer_formats = [t.accum_format, ALBEDO_FORMAT, NORMAL_FORMAT, POSITION_FORMAT];
        let mut g = scene_pipeline(shaders::GBUFFER_VERT, layouts.gbuffer, df);
        g.fragment = Some(shaders::GBUFFER_FRAG);
        g.samples = samples;
        g.attributes = &GBUFFER_ATTRIBUTES;
        g.color_formats = &gbuffer_formats;
        g.depth_test = true;
        g.depth_write = true;
        g.depth_compare = vk::CompareOp::LESS;
        g.cull = vk::CullModeFlags::BACK;
        let gbuffer = create(&g)?;
        g.cull = vk::CullModeFlags::NONE;
        let gbuffer_two_sided = create(&g)?;
        let mut gs = PipelineDesc::new(shaders::SPHERE_VERT, if ms { layouts.sphere_ms } else { layouts.gbuffer }, df);
        gs.fragment = Some(if ms { shaders::SPHERE_MS_FRAG } else { shaders::SPHERE_FRAG });
        gs.samples = samples;
        gs.vertex_stride = VERTEX_STRIDE;
        gs.attributes = &VERTEX_ATTRIBUTES;
        gs.color_formats = &gbuffer_formats;
        gs.depth_test = true;
        gs.depth_write = true;
        gs.depth_compare = vk::CompareOp::LESS;
        // Back faces: they cover the sphere's projection wherever the eye is outside it.
        gs.cull = vk::CullModeFlags::FRONT;
        let gbuffer_sphere = create(&gs)?;

        let accum = [t.accum_format];
        let mut i = PipelineDesc::new(shaders::FULLSCREEN_VERT, layouts.illuminate, df);
        i.color_formats = &accum;
        i.blend = Blend::Additive;
        i.depth_bounds = depth_bounds;
        i.samples = samples;
        let lit = Some((umbrage::pass::lit_stencil_state(), umbrage::pass::lit_stencil_state()));
        let mut illuminate = [[vk::Pipeline::null(); 2]; 2];
        for (ci, counted) in [false, true].into_iter().enumerate() {
            for (ti, transmit) in [false, true].into_iter().enumerate() {
                i.fragment = Some(match (counted, transmit) {
                    (false, false) if ms => shaders::ILLUMINATE_MS_FRAG,
                    (false, false) => shaders::ILLUMINATE_FRAG,
                    (false, true) => shaders::ILLUMINATE_T_FRAG,
                    (true, false) => shaders::ILLUMINATE_COUNT_FRAG,
                    (true, true) => shaders::ILLUMINATE_COUNT_T_FRAG,
                });
                i.stencil = if counted { None } else { lit };
                illuminate[ci][ti] = create(&i)?;
            }
        }

        let mut tp = scene_pipeline(shaders::TRANSPARENT_VERT, layouts.forward, df);
        tp.fragment = Some(shaders::TRANSPARENT_FRAG);
        tp.color_formats = &accum;
        tp.depth_test = true;
        tp.depth_compare = vk::CompareOp::LESS;
        tp.blend = Blend::Over;
        tp.samples = samples;
        let transparent_over = create(&tp)?;
        tp.blend = Blend::Additive;
        let transparent_light = create(&tp)?;

        let out = [OUTPUT_FORMAT];
        let mut tm = PipelineDesc::new(shaders::FULLSCREEN_VERT, layouts.tonemap, vk::Format::UNDEFINED);
        tm.fragment = Some(if ms { shaders::TONEMAP_MS_FRAG } else { shaders::TONEMAP_FRAG });
        tm.color_formats = &out;
        let tonemap = create(&tm)?;
        let sample_readback = match &t.per_sample {
            Some(rb) => Some(SampleReadbackPipes::new(ctx, t, rb.stencil_view, sampler, &mut create)?),
            None => None,
        };
        Ok(FramePipelines {
            layouts,
            gbuffer_set,
            accum_set,
            sampler,
            gbuffer,
            gbuffer_two_sided,
            gbuffer_sphere,
            illuminate,
            transparent_over,
            transparent_light,
            tonemap,
            accum_format: t.accum_format,
            sample_readback,
            made,
        })
    }

    /// Destroys every pipeline, layout, set and the sampler this created.
    ///
    /// # Safety
    /// No pending command buffer uses them.
    pub unsafe fn destroy(&mut self, ctx: &Context) {
        let d = &ctx.device;
        // SAFETY: forwarded to the caller's contract; each handle is destroyed once.
        unsafe {
            for p in self.made.drain(..) {
                d.destroy_pipeline(p, None);
            }
            let l = &self.layouts;
            for layout in [l.gbuffer, l.illuminate, l.tonemap, l.forward, l.sphere_ms] {
                d.destroy_pipeline_layout(layout, None);
            }
            d.destroy_sampler(self.sampler, None);
        }
        self.gbuffer_set.destroy(ctx);
        self.accum_set.destroy(ctx);
        if let Some(mut r) = self.sample_readback.take() {
            // SAFETY: as above (its pipelines are in `made`).
            unsafe { d.destroy_pipeline_layout(r.layout, None) };
            r.position_set.destroy(ctx);
            r.normal_set.destroy(ctx);
            r.stencil_set.destroy(ctx);
        }
    }
}

impl SampleReadbackPipes {
    /// The readback's sets and pipelines; `create` makes (and owns) the pipelines.
    fn new(
        ctx: &Context,
        t: &Targets,
        stencil_view: vk::ImageView,
        sampler: vk::Sampler,
        create: &mut impl FnMut(&PipelineDesc) -> Result<vk::Pipeline>,
    ) -> Result<SampleReadbackPipes> {
        let set = |view| DescriptorSet::new(ctx, &[Binding::Image(view), Binding::Sampler(sampler)]);
        let mut sets = Vec::with_capacity(3);
        let made = (|| -> Result<(vk::PipelineLayout, vk::Pipeline, vk::Pipeline)> {
            for view in [t.position.view, t.normal.view, stencil_view] {
                sets.push(set(view)?);
            }
            let layout = pipeline_layout(ctx, &[sets[0].layout], 4, vk::ShaderStageFlags::FRAGMENT)?;
            let geometry_formats = [SAMPLE_GEOMETRY_FORMAT];
            let stencil_formats = [SAMPLE_STENCIL_FORMAT];
            let mut p = PipelineDesc::new(shaders::FULLSCREEN_VERT, layout, vk::Format::UNDEFINED);
            p.fragment = Some(shaders::SAMPLE_READBACK_FRAG);
            p.color_formats = &geometry_formats;
            let made = (|| {
                let geometry = create(&p)?;
                p.fragment = Some(shaders::SAMPLE_READBACK_STENCIL_FRAG);
                p.color_formats = &stencil_formats;
                Ok((geometry, create(&p)?))
            })();
            match made {
                Ok((g, s)) => Ok((layout, g, s)),
                Err(e) => {
                    // SAFETY: no pipeline made with the layout is in use.
                    unsafe { ctx.device.destroy_pipeline_layout(layout, None) };
                    Err(e)
                }
            }
        })();
        match made {
            Ok((layout, geometry, stencil)) => {
                let mut it = sets.into_iter();
                let (Some(position_set), Some(normal_set), Some(stencil_set)) = (it.next(), it.next(), it.next()) else {
                    return Err(umbrage::Error::Internal("sample readback sets".into()));
                };
                Ok(SampleReadbackPipes { layout, geometry, stencil, position_set, normal_set, stencil_set })
            }
            Err(e) => {
                for mut s in sets {
                    s.destroy(ctx);
                }
                Err(e)
            }
        }
    }
}
