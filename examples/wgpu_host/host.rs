//! The host's setup and teardown: the scene's meshes as wgpu vertex buffers, the targets (the
//! `Depth24PlusStencil8` texture the shadow pass counts into, the G-buffer, the float
//! accumulation and the sRGB output), the three WGSL pipelines, the ring slots (uniforms and
//! readback buffers per frame in flight), and the [`ShadowPass`] with its gpu-allocator on
//! wgpu's device. `frame.rs` records and reads back frames.

use crate::gpu::{Gpu, DS_FORMAT};
use bytemuck::{Pod, Zeroable};
use glam::Mat4;
use gpu_allocator::vulkan::Allocator;
use std::sync::{Arc, Mutex};
use umbrage::pass::{lit_stencil_state, CasterId, DepthStencilTarget, EnabledFeatures, ShadowPass, ShadowPassDesc};
use umbrage_scene::Scene;
use wgpu::util::DeviceExt;

/// Ring slots: two frames in flight.
pub const FRAMES_IN_FLIGHT: usize = 2;
/// Uniform blocks are bound at dynamic offsets of this stride (wgpu's minimum alignment).
pub const UNIFORM_STRIDE: u64 = 256;
pub const ACCUM_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
pub const ALBEDO_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;
pub const VECTOR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;
pub const OUTPUT_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8UnormSrgb;

/// `Mesh` in frame.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
pub struct MeshBlock {
    pub mvp: [f32; 16],
    pub model_rel: [f32; 16],
    pub n: [[f32; 4]; 3],
    pub color: [f32; 4],
    pub ambient: [f32; 4],
}

/// `LightBlock` in frame.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
pub struct LightBlock {
    pub position: [f32; 4],
    pub color: [f32; 4],
    pub spot: [f32; 4],
    pub params: [f32; 4],
}

/// A scene mesh: object-space positions and face normals, three vertices a triangle.
pub struct MeshGpu {
    pub vertices: wgpu::Buffer,
    pub vertex_count: u32,
    pub caster: Option<CasterId>,
}

/// A texture and its default view.
pub struct Target {
    pub texture: wgpu::Texture,
    pub view: wgpu::TextureView,
}

pub struct Targets {
    pub width: u32,
    pub height: u32,
    /// Depth24PlusStencil8: the pre-pass's depth, the pass's counts, the lighting's test.
    pub ds: Target,
    /// The pass's view of `ds`: wgpu's own Vulkan image view of both aspects.
    pub ds_target: DepthStencilTarget,
    pub accum: Target,
    pub albedo: Target,
    pub normal: Target,
    pub position: Target,
    pub output: Target,
}

/// Bytes a row of a `bpp`-byte format takes in a readback buffer (wgpu wants 256-aligned rows).
pub fn pitch(width: u32, bpp: u32) -> u32 {
    (width * bpp).div_ceil(256) * 256
}

/// A slot's readback buffers: colour always, the rest when the frames are captured.
pub struct Readback {
    pub color: wgpu::Buffer,
    pub capture: Option<Capture>,
}

pub struct Capture {
    /// One stencil image a light, `pitch(w, 1) * h` bytes each.
    pub stencil: wgpu::Buffer,
    pub positions: wgpu::Buffer,
    pub normals: wgpu::Buffer,
}

/// What the frame in flight in a slot remembers until it is read back.
pub struct InFlight {
    pub frame: usize,
    pub submission: wgpu::SubmissionIndex,
    pub captured: bool,
    pub stats: Vec<umbrage::pass::stats::LightStats>,
    pub totals: umbrage::pass::stats::Totals,
    pub cpu_ms: umbrage::pass::stats::CpuMs,
    pub warnings: Vec<String>,
    /// From `prepare` on.
    pub start: std::time::Instant,
    pub prepare_ms: f64,
    pub record_ms: f64,
}

pub struct Slot {
    pub meshes: wgpu::Buffer,
    pub lights: wgpu::Buffer,
    pub mesh_group: wgpu::BindGroup,
    pub light_group: wgpu::BindGroup,
    pub readback: Readback,
    pub in_flight: Option<InFlight>,
}

pub struct Pipes {
    pub gbuffer: wgpu::RenderPipeline,
    pub illuminate: wgpu::RenderPipeline,
    pub tonemap: wgpu::RenderPipeline,
    pub tonemap_group: wgpu::BindGroup,
}

/// Everything the host owns. `Drop` waits for the device, then drops the pass and its
/// allocator before wgpu's resources and device (field order: `gpu` last).
pub struct Host {
    pub scene: Scene,
    /// The caster that moves between frames (index into the scene's meshes) and where it
    /// started.
    pub moving: Option<(usize, Mat4)>,
    pub pass: Option<ShadowPass>,
    allocator: Option<Arc<Mutex<Allocator>>>,
    pub meshes: Vec<MeshGpu>,
    pub targets: Targets,
    pub pipes: Pipes,
    pub slots: Vec<Slot>,
    pub gpu: Gpu,
}

fn target(device: &wgpu::Device, label: &str, format: wgpu::TextureFormat, w: u32, h: u32, usage: wgpu::TextureUsages) -> Target {
    let texture = device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d { width: w, height: h, depth_or_array_layers: 1 },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage,
        view_formats: &[],
    });
    let view = texture.create_view(&wgpu::TextureViewDescriptor::default());
    Target { texture, view }
}

/// The meshes the host can draw: opaque triangle meshes. Analytic spheres and transparent
/// casters are umbrage renderer features this example leaves out.
fn check_scene(scene: &Scene) -> Result<(), String> {
    if !scene.spheres.is_empty() {
        return Err(format!("scene '{}': analytic spheres are not supported by the wgpu host example", scene.name));
    }
    if let Some(m) = scene.meshes.iter().find(|m| m.opacity < 1.0) {
        return Err(format!("scene '{}': mesh '{}' is transparent; the wgpu host example draws opaque meshes only", scene.name, m.name));
    }
    Ok(())
}

impl Host {
    pub fn new(gpu: Gpu, mut scene: Scene, width: u32, height: u32, capture: bool) -> Result<Host, String> {
        check_scene(&scene)?;
        // Area lights become their point-light samples, as in `umbrage render`.
        scene.lights = umbrage::geom::area::expand_lights(&scene.lights, None);
        let device = &gpu.device;
        let limits = device.limits();
        let h = height as u64;
        let mut largest = pitch(width, 4) as u64 * h;
        if capture {
            largest = largest.max(pitch(width, 16) as u64 * h).max(pitch(width, 1) as u64 * h * scene.lights.len() as u64);
        }
        if width.max(height) > limits.max_texture_dimension_2d || largest > limits.max_buffer_size {
            return Err(format!(
                "{width}x{height} is beyond this device's limits ({} texels a side, {} bytes a buffer)",
                limits.max_texture_dimension_2d, limits.max_buffer_size
            ));
        }
        let att = wgpu::TextureUsages::RENDER_ATTACHMENT;
        let tex = wgpu::TextureUsages::TEXTURE_BINDING;
        let src = wgpu::TextureUsages::COPY_SRC;
        let ds = target(device, "depth-stencil", DS_FORMAT, width, height, att | src);
        let ds_view = {
            // SAFETY: the guard is dropped at the end of the block; the raw view lives as long
            // as `ds.view`, which `Targets` keeps for the host's lifetime.
            let v = unsafe { ds.view.as_hal::<wgpu::hal::api::Vulkan>() }.ok_or("the depth-stencil view is not a Vulkan view")?;
            // SAFETY: reading the handle; the view is not destroyed through it.
            unsafe { v.raw_handle() }
        };
        let ds_image = {
            // SAFETY: as for the view: the guard is dropped at the end of the block and the
            // image lives as long as `ds.texture`.
            let t = unsafe { ds.texture.as_hal::<wgpu::hal::api::Vulkan>() }.ok_or("the depth-stencil texture is not a Vulkan texture")?;
            // SAFETY: reading the handle; the image is not destroyed through it.
            unsafe { t.raw_handle() }
        };
        // Declared in DEPTH_STENCIL_ATTACHMENT_OPTIMAL and left there: what wgpu's tracker
        // has for a texture last used as DEPTH_STENCIL_WRITE (shadow.rs).
        let ds_target = DepthStencilTarget::new(ds_image, ds_view, ash::vk::Extent2D { width, height });
        let targets = Targets {
            width,
            height,
            ds,
            ds_target,
            accum: target(device, "accumulation", ACCUM_FORMAT, width, height, att | tex),
            albedo: target(device, "albedo", ALBEDO_FORMAT, width, height, att | tex),
            normal: target(device, "normal", VECTOR_FORMAT, width, height, att | tex | src),
            position: target(device, "position", VECTOR_FORMAT, width, height, att | tex | src),
            output: target(device, "output", OUTPUT_FORMAT, width, height, att | src),
        };
        let pipes = Pipes::new(device, &targets)?;

        let meshes = scene
            .meshes
            .iter()
            .map(|m| {
                let mut verts: Vec<[f32; 6]> = Vec::with_capacity(m.mesh.triangles.len() * 3);
                for t in 0..m.mesh.triangles.len() {
                    let p = m.mesh.triangle(t);
                    let n = (p[1] - p[0]).as_dvec3().cross((p[2] - p[0]).as_dvec3());
                    if n.length_squared().partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
                        continue; // zero-area: nothing to rasterise, no normal to shade with
                    }
                    let n = n.normalize().as_vec3();
                    for v in p {
                        verts.push([v.x, v.y, v.z, n.x, n.y, n.z]);
                    }
                }
                let vertices = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some(&m.name),
                    contents: bytemuck::cast_slice(&verts),
                    usage: wgpu::BufferUsages::VERTEX,
                });
                MeshGpu { vertices, vertex_count: verts.len() as u32, caster: None }
            })
            .collect();

        let slots = (0..FRAMES_IN_FLIGHT).map(|i| Slot::new(device, &pipes, &targets, &scene, i, capture)).collect();
        // The caster that moves: the last opaque shadow-casting mesh.
        let moving = scene.meshes.iter().rposition(|m| m.casts_shadow).map(|i| (i, scene.meshes[i].transform));
        let mut host = Host { scene, moving, pass: None, allocator: None, meshes, targets, pipes, slots, gpu };

        let allocator = host.gpu.allocator()?;
        host.allocator = Some(allocator.clone());
        let desc = ShadowPassDesc {
            depth_stencil_format: host.gpu.ds_format,
            frames_in_flight: FRAMES_IN_FLIGHT,
            // wgpu enables neither depthClamp (infinite far plane: not needed) nor depthBounds.
            features: EnabledFeatures {
                depth_clamp: false,
                depth_bounds: false,
                index_type_uint8: host.gpu.index_type_uint8,
                ray_query: false,
                mesh_shader: false,
                draw_indirect_first_instance: false,
                multi_draw_indirect: false,
                draw_indirect_count: false,
                task_shader: false,
            },
            ..Default::default()
        };
        let mut pass = ShadowPass::new(&host.gpu.raw_instance, host.gpu.physical, &host.gpu.raw_device, allocator, &desc)
            .map_err(|e| format!("ShadowPass::new: {e}"))?;
        for (mi, m) in host.scene.meshes.iter().enumerate() {
            if m.casts_shadow {
                let caster = m.caster().map_err(|e| e.to_string())?;
                let id = pass.add_prepared_caster(caster, m.transform.as_dmat4()).map_err(|e| format!("caster '{}': {e}", m.name))?;
                host.meshes[mi].caster = Some(id);
            }
        }
        host.pass = Some(pass);
        Ok(host)
    }

    pub fn pass(&self) -> &ShadowPass {
        self.pass.as_ref().expect("the pass exists once Host::new returned")
    }

    pub fn pass_mut(&mut self) -> &mut ShadowPass {
        self.pass.as_mut().expect("the pass exists once Host::new returned")
    }
}

impl Drop for Host {
    fn drop(&mut self) {
        // Every submission that used the pass's buffers has completed before they go.
        let _ = self.gpu.device.poll(wgpu::PollType::wait_indefinitely());
        drop(self.pass.take());
        if let Some(a) = self.allocator.take() {
            if Arc::strong_count(&a) != 1 {
                eprintln!("wgpu_host: the allocator is still shared at teardown");
            }
            // The allocator frees its memory blocks here, before wgpu's device goes.
            drop(a);
        }
    }
}

impl Slot {
    fn new(device: &wgpu::Device, pipes: &Pipes, t: &Targets, scene: &Scene, i: usize, capture: bool) -> Slot {
        let uniform = |label: &str, n: usize| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: UNIFORM_STRIDE * n.max(1) as u64,
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            })
        };
        let meshes = uniform(&format!("mesh blocks {i}"), scene.meshes.len());
        let lights = uniform(&format!("light blocks {i}"), scene.lights.len());
        let mesh_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("mesh block"),
            layout: &pipes.gbuffer.get_bind_group_layout(0),
            entries: &[wgpu::BindGroupEntry { binding: 5, resource: block(&meshes, std::mem::size_of::<MeshBlock>()) }],
        });
        let light_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("G-buffer and light block"),
            layout: &pipes.illuminate.get_bind_group_layout(0),
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: wgpu::BindingResource::TextureView(&t.albedo.view) },
                wgpu::BindGroupEntry { binding: 1, resource: wgpu::BindingResource::TextureView(&t.normal.view) },
                wgpu::BindGroupEntry { binding: 2, resource: wgpu::BindingResource::TextureView(&t.position.view) },
                wgpu::BindGroupEntry { binding: 3, resource: block(&lights, std::mem::size_of::<LightBlock>()) },
            ],
        });
        let readback = |label: &str, size: u64| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size,
                usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            })
        };
        let (w, h) = (t.width, t.height as u64);
        let readback = Readback {
            color: readback("color readback", pitch(w, 4) as u64 * h),
            capture: capture.then(|| Capture {
                stencil: readback("stencil readback", pitch(w, 1) as u64 * h * scene.lights.len().max(1) as u64),
                positions: readback("position readback", pitch(w, 16) as u64 * h),
                normals: readback("normal readback", pitch(w, 16) as u64 * h),
            }),
        };
        Slot { meshes, lights, mesh_group, light_group, readback, in_flight: None }
    }
}

/// One uniform block of `buffer` (bound at a dynamic offset).
fn block(buffer: &wgpu::Buffer, size: usize) -> wgpu::BindingResource<'_> {
    wgpu::BindingResource::Buffer(wgpu::BufferBinding { buffer, offset: 0, size: wgpu::BufferSize::new(size as u64) })
}

impl Pipes {
    fn new(device: &wgpu::Device, t: &Targets) -> Result<Pipes, String> {
        // Parsed here (with wgpu's naga) and handed to wgpu as naga IR rather than WGSL text:
        // with no source text wgpu attaches no debug info, so its SPIR-V has no `OpSource
        // WGSL`, which the validation layer of Debian 12 (1.3.239, older SPIR-V tools than
        // naga 30) rejects as "Invalid source language operand: 10".
        let src = include_str!("frame.wgsl");
        let parsed = wgpu::naga::front::wgsl::parse_str(src).map_err(|e| format!("frame.wgsl: {}", e.emit_to_string(src)))?;
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("frame.wgsl"),
            source: wgpu::ShaderSource::Naga(std::borrow::Cow::Owned(parsed)),
        });
        let uniform_dynamic =
            wgpu::BindingType::Buffer { ty: wgpu::BufferBindingType::Uniform, has_dynamic_offset: true, min_binding_size: None };
        let texture = wgpu::BindingType::Texture {
            sample_type: wgpu::TextureSampleType::Float { filterable: false },
            view_dimension: wgpu::TextureViewDimension::D2,
            multisampled: false,
        };
        let entry = |binding, visibility, ty| wgpu::BindGroupLayoutEntry { binding, visibility, ty, count: None };
        let vs_fs = wgpu::ShaderStages::VERTEX | wgpu::ShaderStages::FRAGMENT;
        let frag = wgpu::ShaderStages::FRAGMENT;
        let layout = |label: &str, entries: &[wgpu::BindGroupLayoutEntry]| {
            let bgl = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor { label: Some(label), entries });
            device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some(label),
                bind_group_layouts: &[Some(&bgl)],
                immediate_size: 0,
            })
        };
        let mesh_layout = layout("gbuffer", &[entry(5, vs_fs, uniform_dynamic)]);
        let light_layout = layout(
            "illuminate",
            &[entry(0, frag, texture), entry(1, frag, texture), entry(2, frag, texture), entry(3, frag, uniform_dynamic)],
        );
        let tonemap_layout = layout("tonemap", &[entry(4, frag, texture)]);

        let vertex_attrs = wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3];
        let color = |format| Some(wgpu::ColorTargetState { format, blend: None, write_mask: wgpu::ColorWrites::ALL });
        let no_stencil = wgpu::StencilState::default();
        let gbuffer = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("ambient + G-buffer"),
            layout: Some(&mesh_layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("gbuffer_vs"),
                compilation_options: Default::default(),
                buffers: &[Some(wgpu::VertexBufferLayout {
                    array_stride: 24,
                    step_mode: wgpu::VertexStepMode::Vertex,
                    attributes: &vertex_attrs,
                })],
            },
            // Two-sided: a closed mesh seen from outside shows the same surfaces as with back
            // faces culled; open and inside-out meshes show their visible side.
            primitive: wgpu::PrimitiveState { cull_mode: None, front_face: wgpu::FrontFace::Ccw, ..Default::default() },
            depth_stencil: Some(wgpu::DepthStencilState {
                format: DS_FORMAT,
                depth_write_enabled: Some(true),
                depth_compare: Some(wgpu::CompareFunction::Less),
                stencil: no_stencil.clone(),
                bias: Default::default(),
            }),
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("gbuffer_fs"),
                compilation_options: Default::default(),
                targets: &[color(ACCUM_FORMAT), color(ALBEDO_FORMAT), color(VECTOR_FORMAT), color(VECTOR_FORMAT)],
            }),
            multiview_mask: None,
            cache: None,
        });
        // The lighting pass's stencil test, as umbrage's `lit_stencil_state` (EQUAL against
        // reference 0 on both faces, nothing written).
        let lit = lit_stencil_state();
        assert_eq!(lit.compare_op, ash::vk::CompareOp::EQUAL);
        let face = wgpu::StencilFaceState {
            compare: wgpu::CompareFunction::Equal,
            fail_op: wgpu::StencilOperation::Keep,
            depth_fail_op: wgpu::StencilOperation::Keep,
            pass_op: wgpu::StencilOperation::Keep,
        };
        let add = wgpu::BlendComponent {
            src_factor: wgpu::BlendFactor::One,
            dst_factor: wgpu::BlendFactor::One,
            operation: wgpu::BlendOperation::Add,
        };
        let fullscreen = wgpu::VertexState {
            module: &module,
            entry_point: Some("fullscreen_vs"),
            compilation_options: Default::default(),
            buffers: &[],
        };
        let illuminate = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("illuminate (stencil == 0)"),
            layout: Some(&light_layout),
            vertex: fullscreen.clone(),
            primitive: Default::default(),
            depth_stencil: Some(wgpu::DepthStencilState {
                format: DS_FORMAT,
                depth_write_enabled: Some(false),
                depth_compare: Some(wgpu::CompareFunction::Always),
                stencil: wgpu::StencilState { front: face, back: face, read_mask: lit.compare_mask, write_mask: 0 },
                bias: Default::default(),
            }),
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("illuminate_fs"),
                compilation_options: Default::default(),
                targets: &[Some(wgpu::ColorTargetState {
                    format: ACCUM_FORMAT,
                    blend: Some(wgpu::BlendState { color: add, alpha: add }),
                    write_mask: wgpu::ColorWrites::ALL,
                })],
            }),
            multiview_mask: None,
            cache: None,
        });
        let tonemap = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("tone map"),
            layout: Some(&tonemap_layout),
            vertex: fullscreen,
            primitive: Default::default(),
            depth_stencil: None,
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("tonemap_fs"),
                compilation_options: Default::default(),
                targets: &[color(OUTPUT_FORMAT)],
            }),
            multiview_mask: None,
            cache: None,
        });
        let tonemap_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("accumulation"),
            layout: &tonemap.get_bind_group_layout(0),
            entries: &[wgpu::BindGroupEntry { binding: 4, resource: wgpu::BindingResource::TextureView(&t.accum.view) }],
        });
        Ok(Pipes { gbuffer, illuminate, tonemap, tonemap_group })
    }
}

/// A transform into umbrage's clip space, made wgpu's.
pub fn flip_y(m: Mat4) -> Mat4 {
    // umbrage's projection is Vulkan's (y down); wgpu's clip space is y up and wgpu-hal
    // flips the viewport, so negating y lands every vertex on the same pixel exactly.
    let mut c = m.to_cols_array_2d();
    for col in &mut c {
        col[1] = -col[1];
    }
    Mat4::from_cols_array_2d(&c)
}
