//! [`ShadowPass`]: the shadow determination of McGuire et al. 2003 (and Kim et al. 2008 for
//! open, non-manifold and transparent casters) as a component that records into a host
//! engine's command buffer.
//!
//! # The embedding contract
//!
//! Modelled on the embeddable ash renderers engines already use (imgui-rs-vulkan-renderer,
//! egui-ash-renderer): the pass takes the host's device and allocator, and **only records**
//! into command buffers the host supplies. It submits nothing, waits on nothing and owns no
//! queue, image or command pool.
//!
//! | who | owns |
//! |---|---|
//! | host | instance, device, queue, command buffers, the depth-stencil image, fences, the lighting pass |
//! | pass | its pipelines, the casters' vertex buffers, one index stream per ring slot |
//!
//! Created for the host's configuration ([`ShadowPassDesc`]): its depth-stencil format,
//! sample count (1, 2, 4 or 8; the count is exact per sample), depth direction (forward or
//! reverse-Z), depth mode (infinite or clamped far plane) and target model (dynamic rendering,
//! or the host's `VkRenderPass` subpass: [`TargetModel`]). Each is checked against the device
//! at creation with a typed error. The pass needs Vulkan 1.1 (1.3 with `dynamicRendering` for
//! the dynamic-rendering model); its barriers are Vulkan 1.0's.
//!
//! A frame:
//! 1. the host waits until the frame that last used ring slot `s` has retired (its fence);
//! 2. [`ShadowPass::prepare`]`(s, view, lights)` ([`ShadowView::from_view_matrix`] builds the
//!    view from the camera's own view matrix): the CPU work (cases, silhouettes, index
//!    streams written into slot `s`). Area lights are refused: expand them first
//!    ([`crate::geom::area::expand_lights`]);
//! 3. outside any rendering: [`ShadowPass::cmd_before_rendering`] (new or deformed casters'
//!    vertex copies, and with [`Technique::Compute`] the GPU possible silhouettes of every
//!    light; in the dynamic-rendering model the first `cmd_determine` of the frame records
//!    them when the host did not, in the render-pass model not calling it first is an error);
//! 4. the host records its depth pre-pass / G-buffer into its depth-stencil image;
//! 5. per light: [`ShadowPass::cmd_determine`] leaves the count in the stencil (cleared inside
//!    the light's scissor), then the host's lighting pass tests `stencil == 0`
//!    ([`lit_stencil_state`]), with [`ShadowPass::cmd_light_state`] setting the light's
//!    viewport, scissor and depth bounds;
//! 6. the host submits; a later `prepare(s, ..)` may only come after that submission retired
//!    (with [`Technique::Compute`], [`ShadowPass::read_back_counts`] after the fence puts the
//!    GPU's triangle counts into the frame's stats).
//!
//! **Ray query** ([`Technique::RayQuery`], where the host enabled it:
//! [`EnabledFeatures::ray_query`]): the same calls and the same stencil out (1 where the
//! pixel's ray to the light is blocked), traced from the host's G-buffer
//! ([`ShadowPass::set_ray_query_inputs`]); `cmd_before_rendering` records the acceleration
//! structures' builds, refits and compactions into the host's command buffer; with
//! [`PassToggles::ray_batch`] and two lights or more, the first `cmd_determine` of each 32
//! lights traces them all in one pass. Every frame's pass commands go to one queue (a refit rewrites
//! a structure earlier frames read).
//!
//! **Frames in flight:** the ring has [`ShadowPassDesc::frames_in_flight`] slots; the host
//! passes the slot of the frame it records. Removing a caster or changing its positions
//! releases its old buffers only once every slot has been prepared again (so no frame in
//! flight can still read them).
//!
//! **Skipped frames lose nothing:** an upload (a new caster's buffers, new positions, the
//! compute tables) stays the pass's until a frame that recorded it has retired, and every
//! frame carries every upload still pending, on any slot. A frame dropped without being
//! recorded needs nothing from the host; one recorded into a command buffer the host then
//! resets without submitting is reported with [`ShadowPass::abandon_frame`]. Ids carry their
//! pass: another pass's caster or sphere id is refused ([`Misuse::ForeignId`]).
//!
//! **Layouts and synchronisation:** the host declares the layout its image is in and the one it
//! wants after ([`DepthStencilTarget::with_layouts`]). With dynamic rendering the pass records
//! both transitions around its rendering instance, waiting for every earlier command and making
//! its stencil writes visible to every later one, so the host needs no barrier of its own. In
//! the render-pass model `cmd_determine` records inside the host's subpass, where no barrier
//! can go: the declared layouts are the subpass's and the host's subpass dependencies order
//! the rest. `cmd_upload` records transfer writes (after an execution barrier behind earlier
//! vertex and compute reads: a copy carried by two frames in flight rewrites the same bytes)
//! followed by a barrier to vertex-attribute,
//! index and compute reads; `cmd_compute_silhouettes` compute writes followed by a barrier to
//! indirect-command and index reads.
//!
//! **Misuse** (a light index out of range, another pass's frame, a stale frame, a target of the
//! wrong size or layout, a call the pass was not configured for or made out of order) is an
//! [`Error::Misuse`] returned before anything is recorded, in release
//! builds too. The counting variants and the debug overlay umbrage's own renderer uses are in
//! [`diagnostics`].
//!
//! **Drop order:** drop the pass while its device and allocator are alive, after every command
//! buffer that uses it has completed (it does not wait for the device: the host owns the
//! device's lifetime).

#![warn(missing_docs)]

mod caster_calls;
mod casters;
mod compute;
mod desc;
mod device;
pub mod diagnostics;
mod draw;
mod draw_volumes;
mod edge_quads;
mod eye;
mod frame;
mod frame_calls;
mod keep;
mod lists;
mod mesh;
mod mesh_pipes;
mod mesh_record;
mod pack;
mod pipelines;
mod planar;
mod prepare;
pub mod push;
mod rays;
mod record;
mod sphere_calls;
mod spheres;
pub mod stats;
mod stencil;
mod target;
mod technique;
mod techniques;
mod view;
mod volumes;

pub use casters::CasterId;
pub use desc::DEFAULT_KEEP_BUDGET;
pub use desc::{
    reverse_z, Capabilities, ComputeDraws, Counter, DepthDirection, DepthMode, EnabledFeatures, IndexFormat, PassSettings, PassToggles,
    RenderPassTarget, ShadowPassDesc, TargetModel, Technique,
};
pub use draw::LightFrame;
pub use frame::{PreparedFrame, MAX_CONE_DEG};
pub use pipelines::COUNT_FORMAT;
pub use rays::work::RayQueryFrame;
pub use rays::{light_rel, RayCounts, RayQueryInputs};
pub use spheres::{SphereId, SphereInfo};
pub use stencil::{lit_stencil_state, VolumeKind};
pub use target::DepthStencilTarget;
pub use view::{ShadowView, MAX_TARGET_SIZE};

use crate::error::{Error, Misuse, Result};
use crate::geom::Light;
use crate::gpu::{Buffer, DeviceCaps};
use ash::vk;
use casters::CasterTable;
use device::PassDevice;
use frame::{check_lights, overflow_warnings};

use gpu_allocator::vulkan::Allocator;
use pack::{pack, PackInput};
use pipelines::Pipelines;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Instant;

/// One ring slot: the index stream of the frame recorded in it, and the staging buffers whose
/// copies that frame records.
struct Slot {
    stream: Option<Buffer>,
    staging: Vec<Buffer>,
    /// Serial of the frame last prepared in this slot.
    serial: Option<u64>,
    /// Set by `cmd_upload` of the frame last prepared in this slot (shared with that frame),
    /// cleared by [`ShadowPass::abandon_frame`]: whether its copies will reach the GPU.
    recorded: Arc<AtomicBool>,
}

/// The shadow determination as an embeddable component (see the [module docs](self) for the
/// contract).
pub struct ShadowPass {
    dev: PassDevice,
    caps: Capabilities,
    desc: ShadowPassDesc,
    settings: PassSettings,
    pipes: Pipelines,
    casters: CasterTable,
    slots: Vec<Slot>,
    serial: u64,
    /// Each technique's own pipelines and per-slot objects (planar, compute, mesh, ray query).
    techniques: techniques::Techniques,
    /// Analytic sphere casters, in draw order (after the mesh casters).
    spheres: Vec<spheres::SphereCaster>,
    next_sphere: u64,
    /// Unique among the process's passes: a frame carries it, so another pass's frame is refused.
    id: u64,
    /// The host's instance (for the ray-query and mesh-shader extensions' functions).
    instance: ash::Instance,
    /// The plans kept across frames ([`PassSettings::keep`]).
    kept: keep::Kept,
}

/// The id of the next pass created.
static NEXT_PASS_ID: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);

impl ShadowPass {
    /// Creates the pass on the host's device. `allocator` is the host's gpu-allocator (shared:
    /// the pass allocates its caster buffers and streams from it). Optional features are the
    /// host's [`ShadowPassDesc::features`] intersected with what `physical_device` reports.
    ///
    /// The host's instance and device are Vulkan 1.1 or later ([`TargetModel::DynamicRendering`]:
    /// 1.3 with `dynamicRendering` enabled).
    ///
    /// Errors, each before anything is created:
    /// - [`Error::InvalidDesc`]: `frames_in_flight` not in 1..=64, `samples` not 1, 2, 4 or 8, a
    ///   depth-stencil format without depth or 8 stencil bits, a [`RenderPassTarget`] whose
    ///   format or sample count differs from the desc, or colour-target options
    ///   (`transmit_format`, `debug_color_format`) with the render-pass model;
    /// - [`Error::Unsupported`]: a device older than Vulkan 1.1 (1.3 for dynamic rendering), a
    ///   format that is no depth-stencil attachment, a sample count the format or device does
    ///   not support, [`DepthMode::Clamp`] (a finite far plane, forward or reverse-Z) without
    ///   `depthClamp`;
    /// - [`Error::Vulkan`]: a failed Vulkan call.
    ///
    /// ```no_run
    /// # use umbrage::pass::*; use ash::vk;
    /// # use std::sync::{Arc, Mutex};
    /// # fn f(instance: &ash::Instance, physical: vk::PhysicalDevice, device: &ash::Device,
    /// #      allocator: Arc<Mutex<gpu_allocator::vulkan::Allocator>>) -> umbrage::Result<()> {
    /// let desc = ShadowPassDesc {
    ///     depth_stencil_format: vk::Format::D32_SFLOAT_S8_UINT, // the host's depth-stencil image
    ///     frames_in_flight: 2,
    ///     samples: 4,
    ///     depth_direction: DepthDirection::Reverse,
    ///     ..Default::default()
    /// };
    /// let pass = ShadowPass::new(instance, physical, device, allocator, &desc)?;
    /// println!("depth bounds used: {}", pass.capabilities().depth_bounds);
    /// # Ok(()) }
    /// ```
    pub fn new(
        instance: &ash::Instance,
        physical_device: vk::PhysicalDevice,
        device: &ash::Device,
        allocator: Arc<Mutex<Allocator>>,
        desc: &ShadowPassDesc,
    ) -> Result<ShadowPass> {
        // The Vulkan 1.1 feature query (the pass refuses older devices below).
        let mut device_caps = DeviceCaps::query(instance, None, physical_device)?;
        for f in [desc.transmit_format, desc.debug_color_format].into_iter().flatten() {
            device_caps.query_format(instance, physical_device, f);
        }
        let caps = Self::capabilities_for(&device_caps, desc)?;
        let dev = PassDevice {
            device: device.clone(),
            allocator,
            pipeline_cache: desc.pipeline_cache,
            max_storage_range: device_caps.limits.max_storage_buffer_range as u64,
            max_draw_indirect_count: device_caps.limits.max_draw_indirect_count.max(1),
        };
        let pipes = Pipelines::new(&dev, desc, caps.depth_clamp, caps.depth_bounds, caps.r32f_blend)?;
        let id = NEXT_PASS_ID.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        let slots = (0..desc.frames_in_flight)
            .map(|_| Slot { stream: None, staging: Vec::new(), serial: None, recorded: Default::default() })
            .collect();
        Ok(ShadowPass {
            dev,
            caps,
            desc: desc.clone(),
            settings: desc.settings,
            pipes,
            casters: CasterTable::new(id),
            slots,
            serial: 0,
            techniques: techniques::Techniques::new(desc.frames_in_flight),
            spheres: Vec::new(),
            next_sphere: 0,
            id,
            instance: instance.clone(),
            kept: keep::Kept::default(),
        })
    }

    /// What a pass made with `desc` would use on the device `device` describes, or the error
    /// [`ShadowPass::new`] would return there, without a device: the same checks and the same
    /// intersection of the host's enabled features with the device's (`ShadowPass::new` calls
    /// it on [`DeviceCaps::query`]'s answer). `device` may come from the device itself or from
    /// a report of it (umbrage's `docs/devices.md` runs it over 68 gpuinfo.org reports).
    ///
    /// # Errors
    /// As [`ShadowPass::new`], for everything but the GPU objects' creation:
    /// [`Error::InvalidDesc`] for a malformed description, [`Error::Unsupported`] for what the
    /// device lacks (Vulkan 1.1; dynamic rendering for [`TargetModel::DynamicRendering`]; the
    /// depth-stencil format as an attachment; the sample count; `depthClamp` for
    /// [`DepthMode::Clamp`]; what the settings' technique needs).
    pub fn capabilities_for(device: &DeviceCaps, desc: &ShadowPassDesc) -> Result<Capabilities> {
        desc.check_shape()?;
        let caps = device::capabilities(device, desc)?;
        if desc.depth_mode == DepthMode::Clamp && !caps.depth_clamp {
            return Err(Error::Unsupported(format!(
                "DepthMode::Clamp (a finite far plane, {} depth) needs the depthClamp feature, present and enabled on the device \
                 (EnabledFeatures::depth_clamp); use DepthMode::Infinite",
                desc.depth_direction.name()
            )));
        }
        desc.settings.check(&caps)?;
        rays::work::check_host(&desc.settings, desc)?;
        Ok(caps)
    }

    /// The receiver plane of [`Technique::Planar`] in world space, `n·x + d = 0` as
    /// `(n, d)` with `n` pointing to the side the light is on (default: y = 0, up).
    pub fn set_planar_receiver(&mut self, plane: glam::DVec4) -> Result<()> {
        if !plane.is_finite() || plane.truncate().length_squared() == 0.0 {
            return Err(Error::argument("planar receiver", format!("{plane} is not a plane")));
        }
        self.techniques.planar.receiver = plane;
        Ok(())
    }

    /// What the pass uses on this device.
    pub fn capabilities(&self) -> Capabilities {
        self.caps
    }

    /// What the pass was created for.
    pub fn desc(&self) -> &ShadowPassDesc {
        &self.desc
    }

    /// The settings the next [`prepare`](Self::prepare) uses.
    pub fn settings(&self) -> PassSettings {
        self.settings
    }

    /// Changes the per-frame settings (technique, counter, index format) for the next frame;
    /// refused when the device cannot honour them.
    pub fn set_settings(&mut self, settings: PassSettings) -> Result<()> {
        settings.check(&self.caps)?;
        rays::work::check_host(&settings, &self.desc)?;
        self.settings = settings;
        Ok(())
    }

    /// Creates now the pipelines that the first frame of `technique` would otherwise create
    /// (the GPU silhouettes' compute pipelines of [`Technique::Compute`], and with them the
    /// mesh pipelines of [`Technique::Mesh`]: with the task stage or without it, as the
    /// current [`PassToggles::mesh_task`] and [`Capabilities::task_shader`] choose; the other
    /// techniques' are made with the pass), so that frame does not wait for the driver's
    /// shader compiler. Idempotent.
    ///
    /// Errors: [`Technique::Mesh`] on a pass without [`Capabilities::mesh_shader`]
    /// ([`Error::Unsupported`]), or the driver's.
    pub fn create_pipelines(&mut self, technique: Technique) -> Result<()> {
        let gpu = matches!(technique, Technique::Compute | Technique::Mesh);
        if technique == Technique::Mesh && !self.caps.mesh_shader {
            return Err(desc::mesh_missing());
        }
        let t = &mut self.techniques;
        if gpu && t.compute.pipes.is_none() {
            t.compute.pipes = Some(compute::ComputePipes::new(&self.dev)?);
        }
        if technique == Technique::Compute && self.caps.draw_indirect_first_instance && t.compute.merged.is_none() {
            let c = &self.caps;
            let caps = (c.depth_clamp, c.depth_bounds, c.r32f_blend);
            t.compute.merged = Some(compute::draw_pipes::DrawPipes::new(&self.dev, &self.desc, self.pipes.layout, caps)?);
        }
        if technique == Technique::Mesh {
            let c = &self.caps;
            if t.mesh.pipes.is_none() {
                let features = (c.depth_clamp, c.depth_bounds, c.r32f_blend);
                t.mesh.pipes = Some(mesh_pipes::MeshPipes::new(&self.instance, &self.dev, features, c.task_shader)?);
            }
            let culled = c.task_shader && self.settings.toggles.mesh_task;
            if let Some(m) = t.mesh.pipes.as_mut() {
                m.ensure(&self.dev, &self.desc, culled)?;
            }
        }
        Ok(())
    }

    /// The pipeline stages the mesh draws read and write in: the mesh stage, and the task
    /// stage where the pass has task shaders (none without mesh shaders).
    fn mesh_stages(&self) -> ash::vk::PipelineStageFlags2 {
        use ash::vk::PipelineStageFlags2 as S;
        match (self.caps.mesh_shader, self.caps.task_shader) {
            (false, _) => S::NONE,
            (true, false) => S::MESH_SHADER_EXT,
            (true, true) => S::MESH_SHADER_EXT | S::TASK_SHADER_EXT,
        }
    }

    fn all_slots(&self) -> u64 {
        if self.slots.len() == 64 {
            u64::MAX
        } else {
            (1u64 << self.slots.len()) - 1
        }
    }
}

impl Drop for ShadowPass {
    fn drop(&mut self) {
        // SAFETY: the embedding contract (module docs): the host drops the pass only after
        // every command buffer that used it has completed, while the device is alive.
        unsafe { self.pipes.destroy(&self.dev.device) };
        self.techniques.destroy(&self.dev);
        self.casters.destroy(&self.dev);
        self.kept.destroy(&self.dev);
        for s in &mut self.slots {
            if let Some(mut b) = s.stream.take() {
                b.destroy(&self.dev);
            }
            for mut b in s.staging.drain(..) {
                b.destroy(&self.dev);
            }
        }
    }
}
