//! Acceleration structures for `VK_KHR_ray_query`: bottom levels built once from triangles
//! or AABBs (one-shot, synchronous), and a top level whose instances are rewritten and rebuilt
//! in a frame's command buffer. Needs [`super::Features::ray_query`] (the context enables
//! buffer device addresses then).

use super::context::Context;
use super::resources::{memory_barrier, Buffer};
use crate::error::{Error, Result};
use ash::vk;
use gpu_allocator::MemoryLocation;

/// Bytes added to scratch buffers so that their device address can be aligned up to
/// `minAccelerationStructureScratchOffsetAlignment` (at most 256 on every known device).
const SCRATCH_SLACK: u64 = 256;

/// The extension's device functions.
pub struct AccelLoader {
    /// `VK_KHR_acceleration_structure`'s functions.
    pub fns: ash::khr::acceleration_structure::Device,
}

impl AccelLoader {
    /// Loads the functions; `Error::Unsupported` when the context has no ray query.
    pub fn new(ctx: &Context) -> Result<AccelLoader> {
        if !ctx.features.ray_query {
            return Err(missing_ray_query(&ctx.info.name));
        }
        Ok(AccelLoader { fns: ash::khr::acceleration_structure::Device::new(&ctx.instance, &ctx.device) })
    }
}

/// The clear error for a device without ray query: which extensions, and where to get a driver
/// that has them.
pub fn missing_ray_query(device: &str) -> Error {
    Error::Unsupported(format!(
        "{device} has no VK_KHR_ray_query with VK_KHR_acceleration_structure (and bufferDeviceAddress), which \
         the rayquery technique needs; Mesa lavapipe 25.0.7 has them: `scripts/drivers.sh install 25.0.7` and \
         `eval \"$(scripts/drivers.sh env 25.0.7)\"` select it"
    ))
}

/// The device address of `buffer` (created with `SHADER_DEVICE_ADDRESS`).
fn address(ctx: &Context, buffer: &Buffer) -> u64 {
    // SAFETY: the buffer is alive, bound, and was created with SHADER_DEVICE_ADDRESS usage on a
    // device with bufferDeviceAddress enabled.
    unsafe { ctx.device.get_buffer_device_address(&vk::BufferDeviceAddressInfo::default().buffer(buffer.raw)) }
}

const INPUT: vk::BufferUsageFlags = vk::BufferUsageFlags::from_raw(
    vk::BufferUsageFlags::ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_KHR.as_raw() | vk::BufferUsageFlags::SHADER_DEVICE_ADDRESS.as_raw(),
);

/// One acceleration structure and the buffer holding it. Not freed on drop: call
/// [`Accel::destroy`].
pub struct Accel {
    /// The handle.
    pub raw: vk::AccelerationStructureKHR,
    /// Its device address (for top-level instances).
    pub address: u64,
    buffer: Buffer,
    /// Bytes of its storage.
    pub size: u64,
}

impl Accel {
    fn new(ctx: &Context, l: &AccelLoader, name: &str, ty: vk::AccelerationStructureTypeKHR, size: u64) -> Result<Accel> {
        let usage = vk::BufferUsageFlags::ACCELERATION_STRUCTURE_STORAGE_KHR | vk::BufferUsageFlags::SHADER_DEVICE_ADDRESS;
        let mut buffer = Buffer::new(ctx, name, size, usage, MemoryLocation::GpuOnly)?;
        let info = vk::AccelerationStructureCreateInfoKHR::default().buffer(buffer.raw).size(size).ty(ty);
        // SAFETY: the buffer is alive, has ACCELERATION_STRUCTURE_STORAGE usage and `size` bytes.
        let raw = match unsafe { l.fns.create_acceleration_structure(&info, None) } {
            Ok(r) => r,
            Err(e) => {
                buffer.destroy(ctx);
                return Err(Error::Vulkan { call: "vkCreateAccelerationStructureKHR", result: e });
            }
        };
        // SAFETY: `raw` was just created on this device.
        let address = unsafe {
            l.fns.get_acceleration_structure_device_address(
                &vk::AccelerationStructureDeviceAddressInfoKHR::default().acceleration_structure(raw),
            )
        };
        Ok(Accel { raw, address, buffer, size })
    }

    /// Destroys the structure and frees its buffer; no pending GPU work may use it.
    pub fn destroy(&mut self, ctx: &Context, l: &AccelLoader) {
        // SAFETY: the owner guarantees the structure is no longer in use.
        unsafe { l.fns.destroy_acceleration_structure(self.raw, None) };
        self.raw = vk::AccelerationStructureKHR::null();
        self.buffer.destroy(ctx);
    }
}

/// Bottom-level geometry.
pub enum Geometry<'a> {
    /// Triangles: f32 positions and three u32 indices each.
    Triangles {
        /// Vertex positions.
        positions: &'a [[f32; 3]],
        /// Vertex indices, three per triangle.
        indices: &'a [[u32; 3]],
    },
    /// Axis-aligned boxes (`[min, max]`) for procedural primitives, intersected in the shader.
    Aabbs(&'a [[[f32; 3]; 2]]),
}

impl Geometry<'_> {
    fn primitives(&self) -> u32 {
        match self {
            Geometry::Triangles { indices, .. } => indices.len() as u32,
            Geometry::Aabbs(b) => b.len() as u32,
        }
    }
}

fn scratch(ctx: &Context, name: &str, size: u64) -> Result<(Buffer, u64)> {
    let usage = vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::SHADER_DEVICE_ADDRESS;
    let b = Buffer::new(ctx, name, size + SCRATCH_SLACK, usage, MemoryLocation::GpuOnly)?;
    let a = address(ctx, &b).next_multiple_of(SCRATCH_SLACK);
    Ok((b, a))
}

/// Builds a bottom-level structure for `geometry` (opaque), preferring fast traces, and
/// compacts it where the device allows. Blocks until the build is done.
pub fn build_blas(ctx: &Context, l: &AccelLoader, name: &str, geometry: Geometry) -> Result<Accel> {
    let count = geometry.primitives();
    let mut inputs: Vec<Buffer> = Vec::new();
    let result = build_blas_inner(ctx, l, name, &geometry, count, &mut inputs);
    for mut b in inputs {
        b.destroy(ctx);
    }
    result
}

fn build_blas_inner(
    ctx: &Context,
    l: &AccelLoader,
    name: &str,
    geometry: &Geometry,
    count: u32,
    inputs: &mut Vec<Buffer>,
) -> Result<Accel> {
    let geom = match geometry {
        Geometry::Triangles { positions, indices } => {
            inputs.push(Buffer::with_data(ctx, "blas vertices", bytemuck::cast_slice(positions), INPUT)?);
            inputs.push(Buffer::with_data(ctx, "blas indices", bytemuck::cast_slice(indices), INPUT)?);
            let tri = vk::AccelerationStructureGeometryTrianglesDataKHR::default()
                .vertex_format(vk::Format::R32G32B32_SFLOAT)
                .vertex_data(vk::DeviceOrHostAddressConstKHR { device_address: address(ctx, &inputs[0]) })
                .vertex_stride(12)
                .max_vertex(positions.len().saturating_sub(1) as u32)
                .index_type(vk::IndexType::UINT32)
                .index_data(vk::DeviceOrHostAddressConstKHR { device_address: address(ctx, &inputs[1]) });
            vk::AccelerationStructureGeometryKHR::default()
                .geometry_type(vk::GeometryTypeKHR::TRIANGLES)
                .geometry(vk::AccelerationStructureGeometryDataKHR { triangles: tri })
                .flags(vk::GeometryFlagsKHR::OPAQUE)
        }
        Geometry::Aabbs(boxes) => {
            inputs.push(Buffer::with_data(ctx, "blas boxes", bytemuck::cast_slice(boxes), INPUT)?);
            let aabbs = vk::AccelerationStructureGeometryAabbsDataKHR::default()
                .data(vk::DeviceOrHostAddressConstKHR { device_address: address(ctx, &inputs[0]) })
                .stride(24);
            vk::AccelerationStructureGeometryKHR::default()
                .geometry_type(vk::GeometryTypeKHR::AABBS)
                .geometry(vk::AccelerationStructureGeometryDataKHR { aabbs })
                .flags(vk::GeometryFlagsKHR::OPAQUE)
        }
    };
    let geoms = [geom];
    let flags = vk::BuildAccelerationStructureFlagsKHR::PREFER_FAST_TRACE | vk::BuildAccelerationStructureFlagsKHR::ALLOW_COMPACTION;
    let mut build = vk::AccelerationStructureBuildGeometryInfoKHR::default()
        .ty(vk::AccelerationStructureTypeKHR::BOTTOM_LEVEL)
        .flags(flags)
        .mode(vk::BuildAccelerationStructureModeKHR::BUILD)
        .geometries(&geoms);
    let mut sizes = vk::AccelerationStructureBuildSizesInfoKHR::default();
    // SAFETY: the build info points at locals alive for the call.
    unsafe { l.fns.get_acceleration_structure_build_sizes(vk::AccelerationStructureBuildTypeKHR::DEVICE, &build, &[count], &mut sizes) };
    let mut accel = Accel::new(ctx, l, name, vk::AccelerationStructureTypeKHR::BOTTOM_LEVEL, sizes.acceleration_structure_size)?;
    let (mut scratch_buf, scratch_addr) = match scratch(ctx, "blas scratch", sizes.build_scratch_size) {
        Ok(s) => s,
        Err(e) => {
            accel.destroy(ctx, l);
            return Err(e);
        }
    };
    build = build.dst_acceleration_structure(accel.raw).scratch_data(vk::DeviceOrHostAddressKHR { device_address: scratch_addr });
    let range = [vk::AccelerationStructureBuildRangeInfoKHR::default().primitive_count(count)];
    let query = compaction_query(ctx);
    let built = ctx.one_shot(|cb| {
        // SAFETY: `cb` is recording; every buffer the build reads or writes is alive until
        // `one_shot` has waited for it.
        unsafe {
            l.fns.cmd_build_acceleration_structures(cb, std::slice::from_ref(&build), &[&range[..]]);
            if let Some(q) = query {
                let b = (vk::PipelineStageFlags2::ACCELERATION_STRUCTURE_BUILD_KHR, vk::AccessFlags2::ACCELERATION_STRUCTURE_WRITE_KHR);
                memory_barrier(
                    ctx,
                    cb,
                    b,
                    (vk::PipelineStageFlags2::ACCELERATION_STRUCTURE_BUILD_KHR, vk::AccessFlags2::ACCELERATION_STRUCTURE_READ_KHR),
                );
                ctx.device.cmd_reset_query_pool(cb, q, 0, 1);
                l.fns.cmd_write_acceleration_structures_properties(
                    cb,
                    &[accel.raw],
                    vk::QueryType::ACCELERATION_STRUCTURE_COMPACTED_SIZE_KHR,
                    q,
                    0,
                );
            }
        }
    });
    scratch_buf.destroy(ctx);
    if let Err(e) = built {
        if let Some(q) = query {
            // SAFETY: the one-shot submission is over (or never happened).
            unsafe { ctx.device.destroy_query_pool(q, None) };
        }
        accel.destroy(ctx, l);
        return Err(e);
    }
    let Some(q) = query else { return Ok(accel) };
    let mut compact = [0u64];
    // SAFETY: the query was written by the finished submission.
    let got = unsafe { ctx.device.get_query_pool_results(q, 0, &mut compact, vk::QueryResultFlags::TYPE_64 | vk::QueryResultFlags::WAIT) };
    // SAFETY: no work uses the pool any more.
    unsafe { ctx.device.destroy_query_pool(q, None) };
    if got.is_err() || compact[0] == 0 || compact[0] >= accel.size {
        return Ok(accel);
    }
    let mut small = match Accel::new(ctx, l, name, vk::AccelerationStructureTypeKHR::BOTTOM_LEVEL, compact[0]) {
        Ok(a) => a,
        Err(_) => return Ok(accel),
    };
    let copied = ctx.one_shot(|cb| {
        let info = vk::CopyAccelerationStructureInfoKHR::default()
            .src(accel.raw)
            .dst(small.raw)
            .mode(vk::CopyAccelerationStructureModeKHR::COMPACT);
        // SAFETY: both structures are alive until `one_shot` has waited.
        unsafe { l.fns.cmd_copy_acceleration_structure(cb, &info) };
    });
    match copied {
        Ok(()) => {
            accel.destroy(ctx, l);
            Ok(small)
        }
        Err(_) => {
            small.destroy(ctx, l);
            Ok(accel)
        }
    }
}

fn compaction_query(ctx: &Context) -> Option<vk::QueryPool> {
    let info = vk::QueryPoolCreateInfo::default().query_type(vk::QueryType::ACCELERATION_STRUCTURE_COMPACTED_SIZE_KHR).query_count(1);
    // SAFETY: valid device with the acceleration-structure extension enabled.
    unsafe { ctx.device.create_query_pool(&info, None) }.ok()
}

/// One top-level instance.
#[derive(Clone, Copy, Debug)]
pub struct Instance {
    /// Object -> world (the space the rays are traced in), rows of a 3x4 matrix.
    pub transform: [[f32; 4]; 3],
    /// `instanceCustomIndex` (24 bits).
    pub custom: u32,
    /// Visibility mask (8 bits), ANDed with the ray's cull mask.
    pub mask: u8,
    /// `VkGeometryInstanceFlagsKHR`.
    pub flags: vk::GeometryInstanceFlagsKHR,
    /// The bottom level's device address.
    pub blas: u64,
}

/// A top-level structure for up to `capacity` instances, rebuilt in place each frame. Not
/// freed on drop: call [`Tlas::destroy`].
pub struct Tlas {
    /// The structure (its handle never changes, so descriptor sets stay valid).
    pub accel: Accel,
    instances: Buffer,
    scratch: Buffer,
    scratch_address: u64,
    capacity: u32,
}

impl Tlas {
    /// Allocates the structure, its instance buffer (host-visible) and scratch memory.
    pub fn new(ctx: &Context, l: &AccelLoader, capacity: u32) -> Result<Tlas> {
        let capacity = capacity.max(1);
        let geoms = [top_geometry(0)];
        let build = vk::AccelerationStructureBuildGeometryInfoKHR::default()
            .ty(vk::AccelerationStructureTypeKHR::TOP_LEVEL)
            .flags(vk::BuildAccelerationStructureFlagsKHR::PREFER_FAST_TRACE)
            .mode(vk::BuildAccelerationStructureModeKHR::BUILD)
            .geometries(&geoms);
        let mut sizes = vk::AccelerationStructureBuildSizesInfoKHR::default();
        // SAFETY: the build info points at locals alive for the call.
        unsafe {
            l.fns.get_acceleration_structure_build_sizes(vk::AccelerationStructureBuildTypeKHR::DEVICE, &build, &[capacity], &mut sizes)
        };
        let mut accel = Accel::new(ctx, l, "tlas", vk::AccelerationStructureTypeKHR::TOP_LEVEL, sizes.acceleration_structure_size)?;
        let size = capacity as u64 * std::mem::size_of::<vk::AccelerationStructureInstanceKHR>() as u64;
        let instances = match Buffer::new(ctx, "tlas instances", size, INPUT, MemoryLocation::CpuToGpu) {
            Ok(b) => b,
            Err(e) => {
                accel.destroy(ctx, l);
                return Err(e);
            }
        };
        match scratch(ctx, "tlas scratch", sizes.build_scratch_size) {
            Ok((scratch, scratch_address)) => Ok(Tlas { accel, instances, scratch, scratch_address, capacity }),
            Err(e) => {
                let mut instances = instances;
                instances.destroy(ctx);
                accel.destroy(ctx, l);
                Err(e)
            }
        }
    }

    /// Writes `instances` and records their build into `cb`, then a barrier making the
    /// structure visible to fragment-shader ray queries.
    ///
    /// # Safety
    /// `cb` is recording outside a rendering instance, and no pending GPU work still reads this
    /// structure or its instance buffer (the frame slot that owns it has retired).
    pub unsafe fn cmd_build(&mut self, ctx: &Context, l: &AccelLoader, cb: vk::CommandBuffer, instances: &[Instance]) -> Result<()> {
        if instances.len() as u32 > self.capacity {
            return Err(Error::Internal(format!("{} instances for a top level of {}", instances.len(), self.capacity)));
        }
        let raw: Vec<vk::AccelerationStructureInstanceKHR> = instances
            .iter()
            .map(|i| vk::AccelerationStructureInstanceKHR {
                transform: vk::TransformMatrixKHR { matrix: bytemuck::cast(i.transform) },
                instance_custom_index_and_mask: vk::Packed24_8::new(i.custom & 0xff_ffff, i.mask),
                instance_shader_binding_table_record_offset_and_flags: vk::Packed24_8::new(0, i.flags.as_raw() as u8),
                acceleration_structure_reference: vk::AccelerationStructureReferenceKHR { device_handle: i.blas },
            })
            .collect();
        // SAFETY: `AccelerationStructureInstanceKHR` is a plain 64-byte record (f32s, packed
        // u32s and a u64), written as bytes into the host-visible instance buffer.
        let data = unsafe { std::slice::from_raw_parts(raw.as_ptr() as *const u8, std::mem::size_of_val(&raw[..])) };
        self.instances.write(0, data)?;
        let geoms = [top_geometry(address(ctx, &self.instances))];
        let build = vk::AccelerationStructureBuildGeometryInfoKHR::default()
            .ty(vk::AccelerationStructureTypeKHR::TOP_LEVEL)
            .flags(vk::BuildAccelerationStructureFlagsKHR::PREFER_FAST_TRACE)
            .mode(vk::BuildAccelerationStructureModeKHR::BUILD)
            .geometries(&geoms)
            .dst_acceleration_structure(self.accel.raw)
            .scratch_data(vk::DeviceOrHostAddressKHR { device_address: self.scratch_address });
        let range = [vk::AccelerationStructureBuildRangeInfoKHR::default().primitive_count(instances.len() as u32)];
        let host = (vk::PipelineStageFlags2::HOST, vk::AccessFlags2::HOST_WRITE);
        let input = (vk::PipelineStageFlags2::ACCELERATION_STRUCTURE_BUILD_KHR, vk::AccessFlags2::SHADER_READ);
        memory_barrier(ctx, cb, host, input);
        // SAFETY: the caller's contract; the instance and scratch buffers and the structure are
        // this object's, alive until it is destroyed.
        unsafe { l.fns.cmd_build_acceleration_structures(cb, std::slice::from_ref(&build), &[&range[..]]) };
        let built = (vk::PipelineStageFlags2::ACCELERATION_STRUCTURE_BUILD_KHR, vk::AccessFlags2::ACCELERATION_STRUCTURE_WRITE_KHR);
        let read = (vk::PipelineStageFlags2::FRAGMENT_SHADER, vk::AccessFlags2::ACCELERATION_STRUCTURE_READ_KHR);
        memory_barrier(ctx, cb, built, read);
        Ok(())
    }

    /// Destroys everything; no pending GPU work may use it.
    pub fn destroy(&mut self, ctx: &Context, l: &AccelLoader) {
        self.accel.destroy(ctx, l);
        self.instances.destroy(ctx);
        self.scratch.destroy(ctx);
    }
}

fn top_geometry(instances: u64) -> vk::AccelerationStructureGeometryKHR<'static> {
    let data = vk::AccelerationStructureGeometryInstancesDataKHR::default()
        .array_of_pointers(false)
        .data(vk::DeviceOrHostAddressConstKHR { device_address: instances });
    vk::AccelerationStructureGeometryKHR::default()
        .geometry_type(vk::GeometryTypeKHR::INSTANCES)
        .geometry(vk::AccelerationStructureGeometryDataKHR { instances: data })
}
