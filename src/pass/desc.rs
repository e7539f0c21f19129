//! What a [`ShadowPass`](super::ShadowPass) is built for ([`ShadowPassDesc`], fixed at
//! creation) and what may change between frames ([`PassSettings`]).

use crate::error::{Error, Result};
use crate::named_enum::named_enum;
use ash::vk;

named_enum!(
    /// How z-fail keeps the far plane out of the way (fixed at creation: the pipelines'
    /// depth-clamp state depends on it).
    DepthMode, "depth mode", {
        /// Far plane at infinity (w = 0 vertices land exactly on depth 1).
        #[default]
        Infinite => "infinite",
        /// A finite far plane beyond the scene, with `depthClamp` on the shadow pipelines.
        Clamp => "clamp",
    }
);

named_enum!(
    /// Which way the host's depth runs (fixed at creation: compare ops, depth bias and the
    /// planner's near plane follow it).
    DepthDirection, "depth direction", {
        /// Depth 0 at the near plane, 1 at the far plane (or infinity); closer is LESS.
        #[default]
        Forward => "forward",
        /// Reverse-Z: depth 1 at the near plane, 0 at the far plane (or infinity, where the
        /// volumes' `w = 0` vertices land exactly); closer is GREATER. A forward projection
        /// `P` becomes [`reverse_z`]`(P)`.
        Reverse => "reverse",
    }
);

/// The reverse-Z projection of a forward Vulkan projection (either way round: the map is its
/// own inverse): clip `z' = w - z`, so depth `d' = 1 - d`. Exact for the usual infinite
/// projection (its depth row becomes `(0, 0, 0, near)`).
pub fn reverse_z(proj: glam::Mat4) -> glam::Mat4 {
    let flip = glam::Mat4::from_cols(
        glam::Vec4::new(1.0, 0.0, 0.0, 0.0),
        glam::Vec4::new(0.0, 1.0, 0.0, 0.0),
        glam::Vec4::new(0.0, 0.0, -1.0, 0.0),
        glam::Vec4::new(0.0, 0.0, 1.0, 1.0),
    );
    flip * proj
}

/// Where the pass records its determination: its own rendering instances, or inside the host's
/// render pass.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum TargetModel {
    /// Dynamic rendering (Vulkan 1.3, or `VK_KHR_dynamic_rendering` promoted): each
    /// `cmd_determine` begins and ends its own rendering instance on the host's image, and
    /// records the layout transitions its [`DepthStencilTarget`](super::DepthStencilTarget)
    /// declares. The host enables `dynamicRendering` on its device.
    #[default]
    DynamicRendering,
    /// The host's `VkRenderPass`: the pipelines are built against its subpass, and
    /// `cmd_determine` records inside that subpass after the host began it (clearing the
    /// stencil inside the light's scissor with `vkCmdClearAttachments`). Vulkan 1.1.
    RenderPass(RenderPassTarget),
}

/// The host's render pass and the subpass the determination records in, with what the pass
/// needs to know about that subpass (Vulkan cannot be asked: fill the fields, or read them
/// from the render pass's create info with [`RenderPassTarget::new`]). Checked against the
/// [`ShadowPassDesc`] when the pass is created.
///
/// Best given a subpass with the depth-stencil attachment only (the lighting in the next
/// subpass, after a dependency from its fragment tests): with a colour attachment bound, even
/// one the pass never writes, lavapipe's determination took 1.4-2.0x as long.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RenderPassTarget {
    /// The host's render pass (it must outlive the pass; pipelines are built against it, so
    /// any render pass *compatible* with it may be begun).
    pub render_pass: vk::RenderPass,
    /// The subpass index.
    pub subpass: u32,
    /// The subpass's depth-stencil attachment format.
    pub depth_stencil_format: vk::Format,
    /// The subpass's sample count.
    pub samples: vk::SampleCountFlags,
    /// The number of colour attachments of the subpass (the pass's pipelines write none).
    pub color_attachments: u32,
}

impl RenderPassTarget {
    /// Reads the subpass `subpass` of the `create_info` the host made `render_pass` with.
    /// Errors: no such subpass, a subpass without a depth-stencil attachment, or one that
    /// uses it read-only.
    ///
    /// # Safety
    /// `create_info`'s pointers are valid for their counts (as when it was built with ash's
    /// builder methods, which tie them to borrowed slices).
    ///
    /// ```no_run
    /// # use umbrage::pass::*; use ash::vk;
    /// # fn f(device: &ash::Device, info: &vk::RenderPassCreateInfo) -> umbrage::Result<()> {
    /// // The host's lighting render pass, whose subpass 0 has the depth-stencil attachment.
    /// // SAFETY: `info` is a well-formed create info; the render pass is destroyed by the host.
    /// let render_pass = unsafe { device.create_render_pass(info, None) }.map_err(umbrage::Error::vk("vkCreateRenderPass"))?;
    /// // SAFETY: `info` is the create info `render_pass` was made from, its pointers alive.
    /// let target = TargetModel::RenderPass(unsafe { RenderPassTarget::new(render_pass, info, 0)? });
    /// let desc = ShadowPassDesc { target, ..Default::default() };
    /// # let _ = desc; Ok(()) }
    /// ```
    pub unsafe fn new(render_pass: vk::RenderPass, create_info: &vk::RenderPassCreateInfo, subpass: u32) -> Result<RenderPassTarget> {
        let field = "RenderPassTarget";
        if render_pass == vk::RenderPass::null() {
            return Err(Error::desc(field, "the render pass is VK_NULL_HANDLE"));
        }
        // SAFETY: the caller's contract; a null pointer or a zero count is never dereferenced.
        let subpasses = unsafe { raw_slice(create_info.p_subpasses, create_info.subpass_count) };
        // SAFETY: as above.
        let attachments = unsafe { raw_slice(create_info.p_attachments, create_info.attachment_count) };
        let sp = subpasses
            .get(subpass as usize)
            .ok_or_else(|| Error::desc(field, format!("subpass {subpass} out of range (the render pass has {})", subpasses.len())))?;
        // SAFETY: the caller's contract: null, or one attachment reference.
        let ds = unsafe { sp.p_depth_stencil_attachment.as_ref() };
        let ds = match ds {
            Some(r) if r.attachment != vk::ATTACHMENT_UNUSED => r,
            _ => return Err(Error::desc(field, format!("subpass {subpass} has no depth-stencil attachment"))),
        };
        let att = attachments
            .get(ds.attachment as usize)
            .ok_or_else(|| Error::desc(field, format!("subpass {subpass}'s depth-stencil attachment {} is out of range", ds.attachment)))?;
        if matches!(
            ds.layout,
            vk::ImageLayout::DEPTH_STENCIL_READ_ONLY_OPTIMAL | vk::ImageLayout::DEPTH_ATTACHMENT_STENCIL_READ_ONLY_OPTIMAL
        ) {
            return Err(Error::desc(
                field,
                format!("subpass {subpass} uses its depth-stencil attachment in {:?}: the stencil must be writable", ds.layout),
            ));
        }
        Ok(RenderPassTarget {
            render_pass,
            subpass,
            depth_stencil_format: att.format,
            samples: att.samples,
            color_attachments: sp.color_attachment_count,
        })
    }
}

/// # Safety
/// `ptr` is null with `len == 0`, or points at `len` valid `T`s that outlive the slice.
unsafe fn raw_slice<'a, T>(ptr: *const T, len: u32) -> &'a [T] {
    if ptr.is_null() || len == 0 {
        &[]
    } else {
        // SAFETY: the caller's contract.
        unsafe { std::slice::from_raw_parts(ptr, len as usize) }
    }
}

named_enum!(
    /// How shadow geometry reaches the GPU each frame.
    IndexFormat, "index format", {
        /// 4 bytes an index: 12 bytes a shadow triangle.
        U32 => "u32",
        /// 2 bytes an index: the paper's 6 bytes a shadow triangle.
        U16 => "u16",
        /// 8-bit indices for chunks of at most 128 vertices (needs `indexTypeUint8`), else u16.
        U8 => "u8",
        /// u8 where possible, else u16.
        #[default]
        Auto => "auto",
        /// No indices: every shadow-triangle vertex streamed as 4 x f32 (the naive baseline).
        Naive => "naive",
    }
);

named_enum!(
    /// Where shadow volumes are counted.
    Counter, "counter", {
        /// The 8-bit stencil with wrapping increments (counts modulo 256).
        #[default]
        Stencil => "stencil",
        /// A 32-bit float colour target with additive blending: no 8-bit wrap (exact to 2^24).
        Float => "float",
    }
);

pub use super::technique::Technique;

/// The optional device features the host enabled on its `VkDevice`: set by the host, in
/// [`ShadowPassDesc::features`], once. The pass uses a feature only when the host enabled it
/// AND the physical device reports it (what it then uses is [`Capabilities`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct EnabledFeatures {
    /// `VkPhysicalDeviceFeatures::depthClamp` (needed by [`DepthMode::Clamp`]).
    pub depth_clamp: bool,
    /// `VkPhysicalDeviceFeatures::depthBounds`: the determination is limited to the light's
    /// depth range.
    pub depth_bounds: bool,
    /// `VK_EXT_index_type_uint8` / `VK_KHR_index_type_uint8` with `indexTypeUint8`: 3-byte
    /// shadow triangles for chunks of at most 128 vertices.
    pub index_type_uint8: bool,
    /// `VK_KHR_ray_query` (`rayQuery`) and `VK_KHR_acceleration_structure`
    /// (`accelerationStructure`) with Vulkan 1.2's `bufferDeviceAddress`, and the host's
    /// gpu-allocator created with `buffer_device_address`: [`Technique::RayQuery`].
    pub ray_query: bool,
    /// `VK_EXT_mesh_shader` with `meshShader` (Vulkan 1.2 or newer):
    /// [`Technique::Mesh`].
    pub mesh_shader: bool,
    /// `VkPhysicalDeviceFeatures::drawIndirectFirstInstance`: [`Technique::Compute`]'s volume
    /// draws read each caster's transform through the draw's `firstInstance`, with no push
    /// constants or buffer binds per caster ([`ComputeDraws`]). Without it: one draw per chunk
    /// with the caster's push constants.
    pub draw_indirect_first_instance: bool,
    /// `VkPhysicalDeviceFeatures::multiDrawIndirect`: with `draw_indirect_first_instance`, one
    /// indirect draw per light and pipeline ([`ComputeDraws::Multi`]).
    pub multi_draw_indirect: bool,
    /// Vulkan 1.2's `drawIndirectCount` (`VkPhysicalDeviceVulkan12Features`): with the two
    /// above, the draw count comes from the GPU (`vkCmdDrawIndexedIndirectCount`,
    /// [`ComputeDraws::Count`]).
    pub draw_indirect_count: bool,
    /// `taskShader` of `VK_EXT_mesh_shader` (with [`mesh_shader`](Self::mesh_shader)):
    /// [`Technique::Mesh`] culls the meshlets that would emit nothing in a task stage
    /// ([`PassToggles::mesh_task`]); without it every meshlet's mesh workgroup runs.
    pub task_shader: bool,
}

named_enum!(
    /// How [`Technique::Compute`]'s volume draws are recorded (the GPU writes one
    /// `VkDrawIndexedIndirectCommand` per chunk and case; the counts are the same whichever
    /// way they are drawn). Every way but `PerChunk` reads each caster's transform and
    /// object-space light as per-instance vertex attributes selected by the record's
    /// `firstInstance`, and the chunks' vertices from one pass-wide buffer at the record's
    /// `vertexOffset`, so a light's draws need no push constants or buffer binds per caster.
    ComputeDraws, "compute draws", {
        /// The best the device and the host's [`EnabledFeatures`] allow: `Count`, else
        /// `Multi`, else `PerRecord`, else `PerChunk`.
        #[default]
        Auto => "auto",
        /// One `vkCmdDrawIndexedIndirectCount` per light and pipeline, its count written by
        /// the GPU (the non-empty records, compacted): `drawIndirectCount`,
        /// `multiDrawIndirect` and `drawIndirectFirstInstance`.
        Count => "count",
        /// One multi-draw `vkCmdDrawIndexedIndirect` per light and pipeline over the
        /// compacted records (the unused tail empty): `multiDrawIndirect` and
        /// `drawIndirectFirstInstance`.
        Multi => "multi",
        /// One `vkCmdDrawIndexedIndirect` per record, without push constants or binds per
        /// caster: `drawIndirectFirstInstance`.
        PerRecord => "per-record",
        /// One `vkCmdDrawIndexedIndirect` per chunk record with the caster's push constants
        /// and its chunk's own vertex buffer: what every device can do.
        PerChunk => "per-chunk",
    }
);

/// The default [`ShadowPassDesc::keep_budget_bytes`]: 64 MiB.
pub const DEFAULT_KEEP_BUDGET: u64 = 64 << 20;

/// What a [`ShadowPass`](super::ShadowPass) is created for: set by the host, once, at
/// [`ShadowPass::new`](super::ShadowPass::new). Everything here is fixed for the pass's
/// lifetime (pipelines and ring slots are built from it); per-frame choices are in
/// [`PassSettings`].
#[derive(Clone, Debug, PartialEq)]
pub struct ShadowPassDesc {
    /// The host's depth-stencil format: must have depth and 8 stencil bits
    /// (`D16_UNORM_S8_UINT`, `D24_UNORM_S8_UINT`, `D32_SFLOAT_S8_UINT`).
    pub depth_stencil_format: vk::Format,
    /// Frames the host keeps in flight (ring slots of per-frame streams), at least 1, at most 64.
    pub frames_in_flight: usize,
    /// The host's projection: infinite far plane, or finite with depth clamp.
    pub depth_mode: DepthMode,
    /// Forward depth or reverse-Z.
    pub depth_direction: DepthDirection,
    /// Samples per pixel of the host's depth-stencil image: 1, 2, 4 or 8 (the stencil count
    /// is exact per sample).
    pub samples: u32,
    /// Dynamic rendering, or the host's render pass.
    pub target: TargetModel,
    /// The features the host enabled on its device.
    pub features: EnabledFeatures,
    /// The first frame's settings (technique, counter, index format).
    pub settings: PassSettings,
    /// Build the light-intensity-map pipelines for transparent casters (Kim et al. 2008),
    /// rendering into this format (`R16G16B16A16_SFLOAT` or `R32G32B32A32_SFLOAT`; needs
    /// blending on it). `None`: transparent casters are refused.
    pub transmit_format: Option<vk::Format>,
    /// Build the debug pipeline that draws the volumes translucent over a colour target of
    /// this format ([`Diagnostics::cmd_draw_volume_overlay`](super::diagnostics::Diagnostics::cmd_draw_volume_overlay)).
    pub debug_color_format: Option<vk::Format>,
    /// The host's `VkPipelineCache`, which every pipeline the pass creates goes through
    /// (`VK_NULL_HANDLE`, the default: none). It must outlive the pass; the pass never
    /// destroys it. A driver whose compiler is slow (SwiftShader) then compiles each pipeline
    /// once per cache, not once per pass.
    pub pipeline_cache: vk::PipelineCache,
    /// The most bytes of index lists kept across frames ([`PassSettings::keep`]); past it
    /// the least recently drawn pairs are evicted. Default 64 MiB; 0 keeps nothing.
    pub keep_budget_bytes: u64,
    /// Threads that plan a frame's changed pairs (with [`PassSettings::keep`]): 0 (the
    /// default) uses every core (`std::thread::available_parallelism`), 1 plans on the
    /// calling thread.
    pub plan_threads: usize,
}

impl ShadowPassDesc {
    /// The checks that need no device: the format has depth and 8 stencil bits, 1..=64 frames
    /// in flight, 1, 2, 4 or 8 samples, and a render-pass target that agrees with the rest.
    pub(crate) fn check_shape(&self) -> Result<()> {
        check_depth_stencil_format(self.depth_stencil_format)?;
        if self.frames_in_flight == 0 || self.frames_in_flight > 64 {
            return Err(Error::desc("ShadowPassDesc::frames_in_flight", format!("must be 1..=64, got {}", self.frames_in_flight)));
        }
        if ![1, 2, 4, 8].contains(&self.samples) {
            return Err(Error::desc("ShadowPassDesc::samples", format!("must be 1, 2, 4 or 8, got {}", self.samples)));
        }
        let samples = sample_flags(self.samples);
        if let TargetModel::RenderPass(rp) = self.target {
            let field = "ShadowPassDesc::target";
            if rp.depth_stencil_format != self.depth_stencil_format {
                return Err(Error::desc(
                    field,
                    format!(
                        "the subpass's depth-stencil attachment is {:?}, the desc says {:?}",
                        rp.depth_stencil_format, self.depth_stencil_format
                    ),
                ));
            }
            if rp.samples != samples {
                return Err(Error::desc(
                    field,
                    format!("the subpass's depth-stencil attachment has {:?} samples, the desc says {}", rp.samples, self.samples),
                ));
            }
            if self.transmit_format.is_some() || self.debug_color_format.is_some() {
                return Err(Error::desc(
                    field,
                    "transmit_format and debug_color_format draw into colour targets of the pass's own rendering instances: \
                     dynamic rendering only",
                ));
            }
        }
        Ok(())
    }
}

impl Default for ShadowPassDesc {
    fn default() -> Self {
        ShadowPassDesc {
            depth_stencil_format: vk::Format::D32_SFLOAT_S8_UINT,
            frames_in_flight: 2,
            depth_mode: DepthMode::Infinite,
            depth_direction: DepthDirection::Forward,
            samples: 1,
            target: TargetModel::DynamicRendering,
            features: EnabledFeatures::default(),
            settings: PassSettings::default(),
            transmit_format: None,
            debug_color_format: None,
            pipeline_cache: vk::PipelineCache::null(),
            keep_budget_bytes: DEFAULT_KEEP_BUDGET,
            plan_threads: 0,
        }
    }
}

/// The pass's choices that may change from one frame to the next: set by the host, first in
/// [`ShadowPassDesc::settings`], then with [`ShadowPass::set_settings`](super::ShadowPass::set_settings)
/// between frames; checked against [`Capabilities`] before every frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PassSettings {
    /// Volumes with a case rule, or edge quads.
    pub technique: Technique,
    /// Stencil or float counting; [`ShadowPass::cmd_determine`](super::ShadowPass::cmd_determine)
    /// counts in the stencil, [`Diagnostics::cmd_count_float`](super::diagnostics::Diagnostics::cmd_count_float)
    /// in a float target.
    pub counter: Counter,
    /// Index format of the per-frame streams.
    pub index_format: IndexFormat,
    /// The paper's constant-factor optimisations, each of which can be switched off to
    /// measure what it saves (all on by default).
    pub toggles: PassToggles,
    /// Keep each light–caster pair's plan and index lists across frames (on by default) with
    /// the CPU-planned techniques ([`Technique::Volumes`], but not
    /// [`Method::ZPassClear`](crate::shadow::Method::ZPassClear), whose clear value counts
    /// from the lists): a pair whose light, caster and case did not change is drawn from the
    /// lists kept on the GPU, with no planning and 0 bytes sent. The same stencil either
    /// way. Off: every pair is planned from scratch every frame (and what was kept is
    /// dropped). The budget is [`ShadowPassDesc::keep_budget_bytes`]. With it, a light of
    /// bounded range meets only the casters a spatial index over their bounds finds in its
    /// range (the others are culled unvisited), and a light's lists
    /// ([`LightStats::casters`](super::stats::LightStats::casters), [`LightFrame::plan`](super::LightFrame::plan))
    /// hold only the casters it draws: a frame costs the pairs that touch, not every light
    /// times every caster.
    pub keep: bool,
}

impl Default for PassSettings {
    fn default() -> Self {
        PassSettings {
            technique: Technique::default(),
            counter: Counter::default(),
            index_format: IndexFormat::default(),
            toggles: PassToggles::default(),
            keep: true,
        }
    }
}

/// The per-light optimisations McGuire et al. claim constant factors for; switching one off
/// keeps the shadows exact (they only bound where the volumes are drawn) and costs what it
/// saves. Part of [`PassSettings`] (all on by default); a host switches one off to measure it,
/// as `umbrage bench --suite fill-vertex` does for each.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PassToggles {
    /// Limit each light's determination (and lighting) to its screen-space scissor rectangle
    /// (off: the whole target).
    pub scissor: bool,
    /// The depth-bounds test to the light's range, when the device has it (off: no bounds).
    pub depth_bounds: bool,
    /// Cull casters whose shadow volume cannot reach the view frustum, or that lie beyond the
    /// light's range or cone (off: every caster's volume is drawn, its case still chosen).
    pub culling: bool,
    /// [`Technique::RayQuery`] with two lights or more: every light's rays in one pass per 32
    /// lights, reading the G-buffer once per pixel into a bit mask that each light's
    /// determination turns into its stencil (off, the default: one ray pass per light). The
    /// same rays, so the same stencil, either way. Off by default because it measured slower
    /// on lavapipe (1.1-1.3x, docs/raytrace.md): the rays cost the same, and the per-light
    /// resolve passes cost more than the G-buffer reads they save.
    pub ray_batch: bool,
    /// How [`Technique::Compute`]'s volume draws are recorded ([`ComputeDraws::Auto`]: the
    /// best the device allows); the same stencil every way. A way the pass cannot use is
    /// refused by [`PassSettings::check`] for `Technique::Compute` frames.
    pub compute_draws: ComputeDraws,
    /// [`Technique::Mesh`] on a pass with [`Capabilities::task_shader`]: a task stage launches
    /// the mesh workgroups of only the meshlets that emit something, decided by each
    /// meshlet's normal cone and bounding sphere where they prove it and by the facing bits
    /// otherwise (off: every meshlet's mesh workgroup runs, as without task shaders). The same
    /// triangles either way.
    pub mesh_task: bool,
}

impl Default for PassToggles {
    fn default() -> Self {
        PassToggles {
            scissor: true,
            depth_bounds: true,
            culling: true,
            ray_batch: false,
            compute_draws: ComputeDraws::Auto,
            mesh_task: true,
        }
    }
}

/// What the pass can use: the host's [`EnabledFeatures`] intersected with what the physical
/// device reports, plus the format capabilities it probed. Computed by the pass
/// ([`ShadowPass::capabilities`](super::ShadowPass::capabilities), or
/// [`ShadowPass::capabilities_for`](super::ShadowPass::capabilities_for) without a device);
/// the host reads it, never sets it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Capabilities {
    /// Ray query enabled and present ([`EnabledFeatures::ray_query`]).
    pub ray_query: bool,
    /// depthClamp enabled and present.
    pub depth_clamp: bool,
    /// depthBounds enabled and present.
    pub depth_bounds: bool,
    /// indexTypeUint8 enabled and present.
    pub index_type_uint8: bool,
    /// `R32_SFLOAT` colour attachments blend (float counter).
    pub r32f_blend: bool,
    /// Mesh shaders enabled and present ([`EnabledFeatures::mesh_shader`]).
    pub mesh_shader: bool,
    /// `drawIndirectFirstInstance` enabled and present.
    pub draw_indirect_first_instance: bool,
    /// `multiDrawIndirect` enabled and present.
    pub multi_draw_indirect: bool,
    /// `drawIndirectCount` (Vulkan 1.2) enabled and present.
    pub draw_indirect_count: bool,
    /// Task shaders too ([`EnabledFeatures::task_shader`]).
    pub task_shader: bool,
}

impl Capabilities {
    /// The way [`Technique::Compute`]'s volume draws are recorded for `want`: `Auto` resolved
    /// to the best these capabilities allow, a forced way kept, or the error naming what it
    /// needs ([`Error::Unsupported`]).
    pub fn compute_draws(&self, want: ComputeDraws) -> Result<ComputeDraws> {
        let first = self.draw_indirect_first_instance;
        let multi = first && self.multi_draw_indirect;
        let count = multi && self.draw_indirect_count;
        let (ok, needs) = match want {
            ComputeDraws::Auto => {
                return Ok(match (count, multi, first) {
                    (true, _, _) => ComputeDraws::Count,
                    (_, true, _) => ComputeDraws::Multi,
                    (_, _, true) => ComputeDraws::PerRecord,
                    _ => ComputeDraws::PerChunk,
                })
            }
            ComputeDraws::Count => (count, "drawIndirectCount (Vulkan 1.2), multiDrawIndirect and drawIndirectFirstInstance"),
            ComputeDraws::Multi => (multi, "multiDrawIndirect and drawIndirectFirstInstance"),
            ComputeDraws::PerRecord => (first, "drawIndirectFirstInstance"),
            ComputeDraws::PerChunk => (true, ""),
        };
        match ok {
            true => Ok(want),
            false => Err(Error::Unsupported(format!(
                "ComputeDraws::{want:?} needs {needs}, present and enabled by the host (EnabledFeatures); use ComputeDraws::Auto"
            ))),
        }
    }
}

/// Refuses a depth-stencil format without a depth aspect or without 8 stencil bits.
pub(crate) fn check_depth_stencil_format(format: vk::Format) -> Result<()> {
    match format {
        vk::Format::D16_UNORM_S8_UINT | vk::Format::D24_UNORM_S8_UINT | vk::Format::D32_SFLOAT_S8_UINT => Ok(()),
        f => Err(Error::Unsupported(format!(
            "depth-stencil format {f:?}: the shadow pass needs a depth aspect and 8 stencil bits \
             (D16_UNORM_S8_UINT, D24_UNORM_S8_UINT or D32_SFLOAT_S8_UINT)"
        ))),
    }
}

impl PassSettings {
    /// Whether the device can honour these settings (checked before every frame).
    pub fn check(&self, caps: &Capabilities) -> Result<()> {
        if self.technique == Technique::RayQuery {
            if !caps.ray_query {
                return Err(rays_missing());
            }
            if self.counter == Counter::Float {
                return Err(Error::InvalidDesc {
                    field: "PassSettings::counter",
                    msg: "Technique::RayQuery writes the stencil (non-zero = shadowed), not a volume count: use Counter::Stencil".into(),
                });
            }
        }
        if self.technique == Technique::Mesh && !caps.mesh_shader {
            return Err(mesh_missing());
        }
        if self.technique == Technique::Compute {
            caps.compute_draws(self.toggles.compute_draws)?;
        }
        if self.index_format == IndexFormat::U8 && !caps.index_type_uint8 {
            return Err(Error::Unsupported(
                "IndexFormat::U8 needs indexTypeUint8 (VK_EXT_index_type_uint8 / VK_KHR_index_type_uint8, enabled); use IndexFormat::Auto or U16".into(),
            ));
        }
        if self.counter == Counter::Float && !caps.r32f_blend {
            return Err(Error::Unsupported(
                "Counter::Float needs R32_SFLOAT colour blending, which this device lacks; use Counter::Stencil".into(),
            ));
        }
        Ok(())
    }
}

/// The sample count flag of `n` samples (1, 2, 4 or 8; checked at creation).
pub(crate) fn sample_flags(n: u32) -> vk::SampleCountFlags {
    match n {
        2 => vk::SampleCountFlags::TYPE_2,
        4 => vk::SampleCountFlags::TYPE_4,
        8 => vk::SampleCountFlags::TYPE_8,
        _ => vk::SampleCountFlags::TYPE_1,
    }
}

/// The clear error for a pass without ray query.
pub(crate) fn rays_missing() -> Error {
    Error::Unsupported(
        "Technique::RayQuery needs VK_KHR_ray_query and VK_KHR_acceleration_structure with bufferDeviceAddress (Vulkan 1.2), \
         enabled by the host (EnabledFeatures::ray_query, and the allocator created with buffer_device_address); \
         Mesa lavapipe 25.0.7 has them: `scripts/drivers.sh install 25.0.7`"
            .into(),
    )
}

/// The clear error for a pass without mesh shaders.
pub(crate) fn mesh_missing() -> Error {
    Error::Unsupported(
        "Technique::Mesh needs VK_EXT_mesh_shader with meshShader (Vulkan 1.2 or newer), enabled by the host \
         (EnabledFeatures::mesh_shader); use Technique::Compute or Technique::Volumes. Mesa lavapipe 25.0.7 has it: \
         `scripts/drivers.sh install 25.0.7`"
            .into(),
    )
}
