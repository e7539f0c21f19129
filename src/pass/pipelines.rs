//! The shadow pass's pipelines: every way a volume face is counted, as a table of
//! fixed-function state (stencil ops, depth compare). Destroyed exactly as created.

use super::desc::{sample_flags, DepthDirection, DepthMode, ShadowPassDesc, TargetModel};
use super::push::VolumePush;
use crate::error::Result;
use crate::gpu::descriptors::pipeline_layout;
use crate::gpu::pipeline::{self, Blend, PipelineDesc};
use crate::gpu::{shaders, GpuDevice};
use ash::vk;

/// The float counter's format: 32-bit float, additive (exact integer counts to 2^24).
pub const COUNT_FORMAT: vk::Format = vk::Format::R32_SFLOAT;

/// Stencil counting (two-sided, wrapping).
pub(crate) struct StencilPipes {
    /// Case 1: INCR_WRAP front / DECR_WRAP back on depth pass.
    pub zpass: vk::Pipeline,
    /// Cases 2 and 3: DECR_WRAP front / INCR_WRAP back on depth fail.
    pub zfail: vk::Pipeline,
    /// Light caps: z-fail ops with depth compare NEVER (a cap lies at or behind the visible
    /// surface, so it always fails).
    pub zfail_cap: vk::Pipeline,
    /// Edge quads: faces (light or dark caps) like light caps, quads like sides.
    pub eq_faces: vk::Pipeline,
    pub eq_sides: vk::Pipeline,
}

/// Float counting: the depth test picks exactly the faces the stencil ops would count.
pub(crate) struct CountPipes {
    /// LESS (z-pass).
    pub zpass: vk::Pipeline,
    /// GREATER_OR_EQUAL: the faces that fail LESS (z-fail).
    pub zfail: vk::Pipeline,
    /// ALWAYS: the NEVER light caps, always counted.
    pub cap: vk::Pipeline,
    pub eq_faces: vk::Pipeline,
    pub eq_sides: vk::Pipeline,
}

/// The counting variant ([`VolumeKind::Rasterised`](super::VolumeKind::Rasterised)): depth
/// and stencil tests always pass and nothing is written, so an occlusion query around the
/// draws counts every fragment the volumes rasterise (the stencil fill the pass costs).
pub(crate) struct RasterPipes {
    /// Shadow-volume geometry (shadow.vert).
    pub volume: vk::Pipeline,
    /// Edge quads (edgequad.vert).
    pub edge_quads: vk::Pipeline,
}

pub(crate) struct Pipelines {
    pub layout: vk::PipelineLayout,
    pub stencil: StencilPipes,
    pub raster: RasterPipes,
    /// `None` when R32_SFLOAT does not blend on this device.
    pub count: Option<CountPipes>,
    /// Light-intensity map, `[multiplicative, log][z-pass, z-fail]`.
    pub transmit: Option<[[vk::Pipeline; 2]; 2]>,
    /// Debug overlay (alpha-blended volumes, depth LESS).
    pub overlay: Option<vk::Pipeline>,
    /// Planar projected shadows: stencil REPLACE 1 where a flattened caster lands on the visible
    /// receiver (depth LESS_OR_EQUAL, pulled towards the eye by a depth bias).
    pub planar: vk::Pipeline,
    /// The same into the float counter (+1, additive; any non-zero count is shadow).
    pub planar_count: Option<vk::Pipeline>,
}

/// A depth compare for forward depth, mirrored for reverse-Z (closer is GREATER).
pub(crate) fn mirror(op: vk::CompareOp) -> vk::CompareOp {
    use vk::CompareOp as C;
    match op {
        C::LESS => C::GREATER,
        C::GREATER => C::LESS,
        C::LESS_OR_EQUAL => C::GREATER_OR_EQUAL,
        C::GREATER_OR_EQUAL => C::LESS_OR_EQUAL,
        other => other,
    }
}

impl Pipelines {
    pub fn new(dev: &impl GpuDevice, desc: &ShadowPassDesc, depth_clamp: bool, depth_bounds: bool, r32f_blend: bool) -> Result<Pipelines> {
        let layout = pipeline_layout(dev, &[], VolumePush::SIZE, vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT)?;
        let mut made = Vec::new();
        let r =
            Self::create_all(dev, desc, layout, depth_clamp && desc.depth_mode == DepthMode::Clamp, depth_bounds, r32f_blend, &mut made);
        if r.is_err() {
            // SAFETY: the pipelines and the layout were just created and never used.
            unsafe {
                for p in made {
                    dev.device().destroy_pipeline(p, None);
                }
                dev.device().destroy_pipeline_layout(layout, None);
            }
        }
        r
    }

    fn create_all(
        dev: &impl GpuDevice,
        desc: &ShadowPassDesc,
        layout: vk::PipelineLayout,
        depth_clamp: bool,
        depth_bounds: bool,
        r32f_blend: bool,
        made: &mut Vec<vk::Pipeline>,
    ) -> Result<Pipelines> {
        // Every table below is written for forward depth; reverse-Z mirrors the compares and
        // the depth bias. Samples and the target model apply to every pipeline.
        let render_pass = match desc.target {
            TargetModel::RenderPass(rp) => Some((rp.render_pass, rp.subpass, rp.color_attachments)),
            _ => None,
        };
        let mut create = |d: &PipelineDesc| -> Result<vk::Pipeline> {
            let p = create_volume_pipeline(dev, desc, d)?;
            made.push(p);
            Ok(p)
        };
        use vk::StencilOp as S;
        let df = desc.depth_stencil_format;
        let v = volume_states(shaders::SHADOW_VERT, (0, &[]), layout, df, depth_clamp, depth_bounds);
        let zpass = create(&v.stencil[0])?;
        let zfail = create(&v.stencil[1])?;
        let zfail_cap = create(&v.stencil[2])?;
        // the light cap's state: the edge quads' and the float counter's derive from it
        let s = v.stencil[2].clone();

        let eq_attrs = [(0, vk::Format::R32G32B32_SFLOAT, 0), (1, vk::Format::R32G32B32A32_SFLOAT, 12)];
        let mut e = s.clone();
        e.vertex = shaders::EDGEQUAD_VERT;
        e.vertex_stride = 32;
        e.attributes = &eq_attrs;
        e.depth_compare = vk::CompareOp::NEVER;
        let eq_faces = create(&e)?;
        e.depth_compare = vk::CompareOp::LESS;
        let eq_sides = create(&e)?;
        let stencil = StencilPipes { zpass, zfail, zfail_cap, eq_faces, eq_sides };
        let keep = v.raster.stencil.map(|(k, _)| k).unwrap_or_default();
        let raster_volume = create(&v.raster)?;
        let mut re = e.clone();
        re.depth_compare = vk::CompareOp::ALWAYS;
        re.stencil = Some((keep, keep));
        let raster = RasterPipes { volume: raster_volume, edge_quads: create(&re)? };

        let count_fmt = [COUNT_FORMAT];
        let mut c = s.clone();
        c.fragment = Some(shaders::COUNT_FRAG);
        c.color_formats = &count_fmt;
        c.blend = Blend::Additive;
        c.stencil = None;
        // The float counter, the light-intensity map and the overlay draw into colour targets of
        // their own rendering instances: dynamic rendering only (refused at creation otherwise).
        let dynamic = render_pass.is_none();
        let count = match r32f_blend && dynamic {
            true => Some(count_pipes(&mut create, &v.count, &c, &eq_attrs)?),
            false => None,
        };

        let transmit = match desc.transmit_format.filter(|_| dynamic) {
            Some(format) => Some(transmit_pipes(&mut create, &c, format)?),
            None => None,
        };

        let overlay = match desc.debug_color_format.filter(|_| dynamic) {
            Some(format) => {
                let fmt = [format];
                let mut v = PipelineDesc::new(shaders::SHADOW_VERT, layout, df);
                v.fragment = Some(shaders::VOLUME_FRAG);
                v.vertex_stride = 16;
                v.attributes = &[(0, vk::Format::R32G32B32A32_SFLOAT, 0)];
                v.color_formats = &fmt;
                v.blend = Blend::Alpha;
                v.depth_test = true;
                v.depth_compare = vk::CompareOp::LESS;
                v.depth_clamp = depth_clamp;
                Some(create(&v)?)
            }
            None => None,
        };
        let mut pl = PipelineDesc::new(shaders::SHADOW_VERT, layout, df);
        pl.vertex_stride = 16;
        pl.attributes = &[(0, vk::Format::R32G32B32A32_SFLOAT, 0)];
        pl.depth_test = true;
        pl.depth_compare = vk::CompareOp::LESS_OR_EQUAL;
        pl.depth_clamp = depth_clamp;
        pl.depth_bias = Some((-4.0, -1.0));
        let replace = vk::StencilOpState {
            fail_op: S::KEEP,
            pass_op: S::REPLACE,
            depth_fail_op: S::KEEP,
            compare_op: vk::CompareOp::ALWAYS,
            compare_mask: 0xff,
            write_mask: 0xff,
            reference: 1,
        };
        pl.stencil = Some((replace, replace));
        let planar = create(&pl)?;
        let planar_count = if r32f_blend && dynamic {
            pl.stencil = None;
            pl.fragment = Some(shaders::COUNT_FRAG);
            pl.color_formats = &count_fmt;
            pl.blend = Blend::Additive;
            Some(create(&pl)?)
        } else {
            None
        };
        Ok(Pipelines { layout, stencil, raster, count, transmit, overlay, planar, planar_count })
    }

    /// Every pipeline, once.
    fn all(&self) -> Vec<vk::Pipeline> {
        let s = &self.stencil;
        let mut v = vec![s.zpass, s.zfail, s.zfail_cap, s.eq_faces, s.eq_sides, self.raster.volume, self.raster.edge_quads];
        if let Some(c) = &self.count {
            v.extend([c.zpass, c.zfail, c.cap, c.eq_faces, c.eq_sides]);
        }
        if let Some(t) = &self.transmit {
            v.extend(t.iter().flatten());
        }
        v.extend(self.overlay);
        v.push(self.planar);
        v.extend(self.planar_count);
        v
    }

    /// # Safety
    /// No command buffer that uses these pipelines may be pending.
    pub unsafe fn destroy(&mut self, device: &ash::Device) {
        // SAFETY: forwarded to the caller's contract.
        unsafe {
            for p in self.all() {
                device.destroy_pipeline(p, None);
            }
            device.destroy_pipeline_layout(self.layout, None);
        }
    }
}

/// Creates the pipeline `d` as the pass makes its volume pipelines: compares and depth bias
/// mirrored for reverse-Z, at the desc's sample count, inside its render pass when it has one.
pub(crate) fn create_volume_pipeline(dev: &impl GpuDevice, desc: &ShadowPassDesc, d: &PipelineDesc) -> Result<vk::Pipeline> {
    let mut d = d.clone();
    if desc.depth_direction == DepthDirection::Reverse {
        d.depth_compare = mirror(d.depth_compare);
        d.depth_bias = d.depth_bias.map(|(c, s)| (-c, -s));
    }
    d.samples = sample_flags(desc.samples);
    d.render_pass = match desc.target {
        TargetModel::RenderPass(rp) => Some((rp.render_pass, rp.subpass, rp.color_attachments)),
        _ => None,
    };
    pipeline::create(dev, &d)
}

/// The formats of the float counter's one colour attachment.
const COUNT_FORMATS: [vk::Format; 1] = [COUNT_FORMAT];

/// The fixed-function states of the volumes' pipelines, for a vertex shader (`shadow.vert`
/// or its TABLE variant) reading `(x, y, z, w)` from binding 0 and `instance` (binding 1's
/// stride and attributes; stride 0: none).
pub(crate) struct VolumeStates<'a> {
    /// Stencil counting: z-pass, z-fail, light caps (depth NEVER).
    pub stencil: [PipelineDesc<'a>; 3],
    /// The counting variant: depth and stencil always pass, nothing written.
    pub raster: PipelineDesc<'a>,
    /// The float counter: z-pass (LESS), z-fail (GREATER_OR_EQUAL), light caps (ALWAYS).
    pub count: [PipelineDesc<'a>; 3],
}

/// The states of [`VolumeStates`] (forward depth; [`create_volume_pipeline`] mirrors them).
pub(crate) fn volume_states<'a>(
    vertex: &'a [u8],
    (instance_stride, instance_attributes): (u32, &'a [(u32, vk::Format, u32)]),
    layout: vk::PipelineLayout,
    depth_format: vk::Format,
    depth_clamp: bool,
    depth_bounds: bool,
) -> VolumeStates<'a> {
    use vk::StencilOp as S;
    let mut s = PipelineDesc::new(vertex, layout, depth_format);
    s.vertex_stride = 16;
    s.attributes = &[(0, vk::Format::R32G32B32A32_SFLOAT, 0)];
    s.instance_stride = instance_stride;
    s.instance_attributes = instance_attributes;
    s.depth_test = true;
    s.depth_compare = vk::CompareOp::LESS;
    s.depth_clamp = depth_clamp;
    s.depth_bounds = depth_bounds;
    s.stencil = Some((pipeline::stencil_ops(S::INCREMENT_AND_WRAP, S::KEEP), pipeline::stencil_ops(S::DECREMENT_AND_WRAP, S::KEEP)));
    let zpass = s.clone();
    s.stencil = Some((pipeline::stencil_ops(S::KEEP, S::DECREMENT_AND_WRAP), pipeline::stencil_ops(S::KEEP, S::INCREMENT_AND_WRAP)));
    let zfail = s.clone();
    s.depth_compare = vk::CompareOp::NEVER;
    let cap = s.clone();
    // The counting variant: ALWAYS, write masks 0 (depth bounds kept: they cull fill).
    let keep = vk::StencilOpState { write_mask: 0, ..pipeline::stencil_ops(S::KEEP, S::KEEP) };
    let mut r = s.clone();
    r.depth_compare = vk::CompareOp::ALWAYS;
    r.stencil = Some((keep, keep));
    let mut c = s.clone();
    c.fragment = Some(shaders::COUNT_FRAG);
    c.color_formats = &COUNT_FORMATS;
    c.blend = Blend::Additive;
    c.stencil = None;
    let count = [vk::CompareOp::LESS, vk::CompareOp::GREATER_OR_EQUAL, vk::CompareOp::ALWAYS].map(|op| {
        let mut d = c.clone();
        d.depth_compare = op;
        d
    });
    VolumeStates { stencil: [zpass, zfail, cap], raster: r, count }
}

/// Makes a pipeline from a description (and keeps it for destruction).
type Create<'c> = dyn FnMut(&PipelineDesc) -> Result<vk::Pipeline> + 'c;

/// The float counter's pipelines: z-pass, z-fail and caps (`volume`, from [`volume_states`]),
/// and from the counting description `c` (additive R32F, no stencil) the edge quads' faces and
/// sides (`eq_attrs`: their vertex attributes).
fn count_pipes(
    create: &mut Create,
    volume: &[PipelineDesc; 3],
    c: &PipelineDesc,
    eq_attrs: &[(u32, vk::Format, u32)],
) -> Result<CountPipes> {
    let zpass = create(&volume[0])?;
    let zfail = create(&volume[1])?;
    let cap = create(&volume[2])?;
    let mut ec = c.clone();
    ec.vertex = shaders::EDGEQUAD_VERT;
    ec.vertex_stride = 32;
    ec.attributes = eq_attrs;
    ec.depth_compare = vk::CompareOp::ALWAYS;
    let eq_faces = create(&ec)?;
    ec.depth_compare = vk::CompareOp::GREATER_OR_EQUAL;
    let eq_sides = create(&ec)?;
    Ok(CountPipes { zpass, zfail, cap, eq_faces, eq_sides })
}

/// The light-intensity map's pipelines into `format`: `[multiplicative, log][z-pass, z-fail]`.
fn transmit_pipes(create: &mut Create, c: &PipelineDesc, format: vk::Format) -> Result<[[vk::Pipeline; 2]; 2]> {
    let map_fmt = [format];
    let mut tm = c.clone();
    tm.color_formats = &map_fmt;
    let mut t = [[vk::Pipeline::null(); 2]; 2];
    for (li, (frag, blend)) in
        [(shaders::TRANSMIT_FRAG, Blend::Multiply), (shaders::TRANSMIT_LOG_FRAG, Blend::Additive)].into_iter().enumerate()
    {
        tm.fragment = Some(frag);
        tm.blend = blend;
        for (zi, cmp) in [vk::CompareOp::LESS, vk::CompareOp::GREATER_OR_EQUAL].into_iter().enumerate() {
            tm.depth_compare = cmp;
            t[li][zi] = create(&tm)?;
        }
    }
    Ok(t)
}
