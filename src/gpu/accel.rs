//! Acceleration structures for `VK_KHR_ray_query`, every build recorded into a command
//! buffer the caller supplies (the shadow pass records into its host's): bottom levels from
//! triangles or AABBs, built ([`prepare_blas`]), refitted in place ([`prepare_refit`]) or
//! compacted ([`cmd_compact`] after [`cmd_write_compacted_size`]); a top level whose instances
//! are rewritten and rebuilt every frame ([`Tlas`]). Needs ray query, acceleration structures
//! and buffer device addresses enabled on the device.

use super::context::GpuDevice;
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
    /// Loads the functions of a device the caller created with `VK_KHR_acceleration_structure`
    /// enabled (an embedding host's, checked by the caller).
    pub fn from_device(instance: &ash::Instance, device: &ash::Device) -> AccelLoader {
        AccelLoader { fns: ash::khr::acceleration_structure::Device::new(instance, device) }
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
fn address(ctx: &impl GpuDevice, buffer: &Buffer) -> u64 {
    // SAFETY: the buffer is alive, bound, and was created with SHADER_DEVICE_ADDRESS usage on a
    // device with bufferDeviceAddress enabled.
    unsafe { ctx.device().get_buffer_device_address(&vk::BufferDeviceAddressInfo::default().buffer(buffer.raw)) }
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
    fn new(ctx: &impl GpuDevice, l: &AccelLoader, name: &str, ty: vk::AccelerationStructureTypeKHR, size: u64) -> Result<Accel> {
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
    pub fn destroy(&mut self, ctx: &impl GpuDevice, l: &AccelLoader) {
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

fn scratch(ctx: &impl GpuDevice, name: &str, size: u64) -> Result<(Buffer, u64)> {
    let usage = vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::SHADER_DEVICE_ADDRESS;
    let b = Buffer::new(ctx, name, size + SCRATCH_SLACK, usage, MemoryLocation::GpuOnly)?;
    let a = address(ctx, &b).next_multiple_of(SCRATCH_SLACK);
    Ok((b, a))
}

/// Where a bottom level's inputs are on the device.
#[derive(Clone, Copy, Debug)]
enum GeomAddr {
    Triangles { vertices: u64, max_vertex: u32, indices: u64 },
    Aabbs { boxes: u64 },
}

/// Uploads `geometry`'s inputs into host-visible buffers pushed onto `inputs` (they must
/// outlive the build) and returns their addresses.
fn describe(ctx: &impl GpuDevice, geometry: &Geometry, inputs: &mut Vec<Buffer>) -> Result<GeomAddr> {
    Ok(match geometry {
        Geometry::Triangles { positions, indices } => {
            let v = Buffer::with_data(ctx, "blas vertices", bytemuck::cast_slice(positions), INPUT)?;
            let vertices = address(ctx, &v);
            inputs.push(v);
            let i = Buffer::with_data(ctx, "blas indices", bytemuck::cast_slice(indices), INPUT)?;
            let idx = address(ctx, &i);
            inputs.push(i);
            GeomAddr::Triangles { vertices, max_vertex: positions.len().saturating_sub(1) as u32, indices: idx }
        }
        Geometry::Aabbs(boxes) => {
            let b = Buffer::with_data(ctx, "blas boxes", bytemuck::cast_slice(boxes), INPUT)?;
            let boxes = address(ctx, &b);
            inputs.push(b);
            GeomAddr::Aabbs { boxes }
        }
    })
}

/// The Vulkan geometry of inputs at `addr` (opaque).
fn geometry_of(addr: GeomAddr) -> vk::AccelerationStructureGeometryKHR<'static> {
    match addr {
        GeomAddr::Triangles { vertices, max_vertex, indices } => {
            let tri = vk::AccelerationStructureGeometryTrianglesDataKHR::default()
                .vertex_format(vk::Format::R32G32B32_SFLOAT)
                .vertex_data(vk::DeviceOrHostAddressConstKHR { device_address: vertices })
                .vertex_stride(12)
                .max_vertex(max_vertex)
                .index_type(vk::IndexType::UINT32)
                .index_data(vk::DeviceOrHostAddressConstKHR { device_address: indices });
            vk::AccelerationStructureGeometryKHR::default()
                .geometry_type(vk::GeometryTypeKHR::TRIANGLES)
                .geometry(vk::AccelerationStructureGeometryDataKHR { triangles: tri })
                .flags(vk::GeometryFlagsKHR::OPAQUE)
        }
        GeomAddr::Aabbs { boxes } => {
            let aabbs = vk::AccelerationStructureGeometryAabbsDataKHR::default()
                .data(vk::DeviceOrHostAddressConstKHR { device_address: boxes })
                .stride(24);
            vk::AccelerationStructureGeometryKHR::default()
                .geometry_type(vk::GeometryTypeKHR::AABBS)
                .geometry(vk::AccelerationStructureGeometryDataKHR { aabbs })
                .flags(vk::GeometryFlagsKHR::OPAQUE)
        }
    }
}

/// A bottom-level build or refit whose structure, inputs and scratch memory exist, recorded
/// later into a command buffer the caller supplies ([`BlasJob::cmd_record`]). Plain handles
/// and addresses: the caller keeps the buffers ([`prepare_blas`]'s `transient`) alive until
/// the command buffer has completed.
#[derive(Clone, Copy, Debug)]
pub struct BlasJob {
    geometry: GeomAddr,
    flags: vk::BuildAccelerationStructureFlagsKHR,
    /// An in-place refit of `dst` (mode UPDATE) rather than a build.
    update: bool,
    dst: vk::AccelerationStructureKHR,
    count: u32,
    scratch: u64,
}

/// The build sizes of `count` primitives of `addr` with `flags`.
fn blas_sizes(
    l: &AccelLoader,
    addr: GeomAddr,
    flags: vk::BuildAccelerationStructureFlagsKHR,
    count: u32,
) -> vk::AccelerationStructureBuildSizesInfoKHR<'static> {
    let geoms = [geometry_of(addr)];
    let build = vk::AccelerationStructureBuildGeometryInfoKHR::default()
        .ty(vk::AccelerationStructureTypeKHR::BOTTOM_LEVEL)
        .flags(flags)
        .mode(vk::BuildAccelerationStructureModeKHR::BUILD)
        .geometries(&geoms);
    let mut sizes = vk::AccelerationStructureBuildSizesInfoKHR::default();
    // SAFETY: the build info points at locals alive for the call.
    unsafe { l.fns.get_acceleration_structure_build_sizes(vk::AccelerationStructureBuildTypeKHR::DEVICE, &build, &[count], &mut sizes) };
    sizes
}

/// Creates a bottom level for `geometry` built with `flags`, its inputs and scratch memory
/// (pushed onto `transient`), and returns it with the job that records its build.
pub fn prepare_blas(
    ctx: &impl GpuDevice,
    l: &AccelLoader,
    name: &str,
    geometry: &Geometry,
    flags: vk::BuildAccelerationStructureFlagsKHR,
    transient: &mut Vec<Buffer>,
) -> Result<(Accel, BlasJob)> {
    let count = geometry.primitives();
    let addr = describe(ctx, geometry, transient)?;
    let sizes = blas_sizes(l, addr, flags, count);
    let mut accel = Accel::new(ctx, l, name, vk::AccelerationStructureTypeKHR::BOTTOM_LEVEL, sizes.acceleration_structure_size)?;
    match scratch(ctx, "blas scratch", sizes.build_scratch_size) {
        Ok((b, scratch)) => {
            transient.push(b);
            let job = BlasJob { geometry: addr, flags, update: false, dst: accel.raw, count, scratch };
            Ok((accel, job))
        }
        Err(e) => {
            accel.destroy(ctx, l);
            Err(e)
        }
    }
}

/// The job that refits `accel` (built with `flags`, which include `ALLOW_UPDATE`) in place to
/// new positions of the same triangles; inputs and scratch are pushed onto `transient`.
pub fn prepare_refit(
    ctx: &impl GpuDevice,
    l: &AccelLoader,
    accel: &Accel,
    geometry: &Geometry,
    flags: vk::BuildAccelerationStructureFlagsKHR,
    transient: &mut Vec<Buffer>,
) -> Result<BlasJob> {
    let count = geometry.primitives();
    let addr = describe(ctx, geometry, transient)?;
    let sizes = blas_sizes(l, addr, flags, count);
    let (b, scratch) = scratch(ctx, "blas refit scratch", sizes.update_scratch_size)?;
    transient.push(b);
    Ok(BlasJob { geometry: addr, flags, update: true, dst: accel.raw, count, scratch })
}

impl BlasJob {
    /// Records the build (or refit).
    ///
    /// # Safety
    /// `cb` is recording outside any rendering instance or render pass; the structure and the
    /// job's buffers live until it has completed; a refit's structure is read by no pending
    /// work (an earlier barrier orders it after every earlier read).
    pub unsafe fn cmd_record(&self, l: &AccelLoader, cb: vk::CommandBuffer) {
        let geoms = [geometry_of(self.geometry)];
        let mode = if self.update { vk::BuildAccelerationStructureModeKHR::UPDATE } else { vk::BuildAccelerationStructureModeKHR::BUILD };
        let mut build = vk::AccelerationStructureBuildGeometryInfoKHR::default()
            .ty(vk::AccelerationStructureTypeKHR::BOTTOM_LEVEL)
            .flags(self.flags)
            .mode(mode)
            .geometries(&geoms)
            .dst_acceleration_structure(self.dst)
            .scratch_data(vk::DeviceOrHostAddressKHR { device_address: self.scratch });
        if self.update {
            build = build.src_acceleration_structure(self.dst);
        }
        let range = [vk::AccelerationStructureBuildRangeInfoKHR::default().primitive_count(self.count)];
        // SAFETY: the caller's contract.
        unsafe { l.fns.cmd_build_acceleration_structures(cb, std::slice::from_ref(&build), &[&range[..]]) };
    }

    /// Whether the job refits in place.
    pub fn is_refit(&self) -> bool {
        self.update
    }
}

/// A one-query pool for a structure's compacted size.
pub fn compaction_pool(ctx: &impl GpuDevice) -> Result<vk::QueryPool> {
    compaction_query(ctx).ok_or_else(|| Error::Internal("no acceleration-structure compaction query pool".into()))
}

/// Records the reset of `pool` and the write of `accel`'s compacted size into it.
///
/// # Safety
/// `cb` is recording outside any rendering instance; a barrier orders the structure's build
/// before this read; `pool` is not in use by pending work.
pub unsafe fn cmd_write_compacted_size(
    ctx: &impl GpuDevice,
    l: &AccelLoader,
    cb: vk::CommandBuffer,
    pool: vk::QueryPool,
    accel: vk::AccelerationStructureKHR,
) {
    // SAFETY: the caller's contract.
    unsafe {
        ctx.device().cmd_reset_query_pool(cb, pool, 0, 1);
        l.fns.cmd_write_acceleration_structures_properties(cb, &[accel], vk::QueryType::ACCELERATION_STRUCTURE_COMPACTED_SIZE_KHR, pool, 0);
    }
}

/// The compacted size written into `pool`, if the GPU has written it yet (never waits).
pub fn compacted_size(ctx: &impl GpuDevice, pool: vk::QueryPool) -> Option<u64> {
    let mut size = [0u64];
    // SAFETY: a non-blocking read of a query that was reset and written by recorded work
    // (NOT_READY until then).
    let got = unsafe { ctx.device().get_query_pool_results(pool, 0, &mut size, vk::QueryResultFlags::TYPE_64) };
    got.ok().map(|()| size[0])
}

/// Records the compacting copy of `src` into `dst` (created with the compacted size).
///
/// # Safety
/// `cb` is recording outside any rendering instance; `src`'s build completed before (an
/// earlier submission on the same queue, after a barrier to build reads); both live until `cb`
/// has completed.
pub unsafe fn cmd_compact(l: &AccelLoader, cb: vk::CommandBuffer, src: vk::AccelerationStructureKHR, dst: vk::AccelerationStructureKHR) {
    let info = vk::CopyAccelerationStructureInfoKHR::default().src(src).dst(dst).mode(vk::CopyAccelerationStructureModeKHR::COMPACT);
    // SAFETY: the caller's contract.
    unsafe { l.fns.cmd_copy_acceleration_structure(cb, &info) };
}

/// Creates an empty bottom level of `size` bytes (the destination of [`cmd_compact`]).
pub fn new_blas(ctx: &impl GpuDevice, l: &AccelLoader, name: &str, size: u64) -> Result<Accel> {
    Accel::new(ctx, l, name, vk::AccelerationStructureTypeKHR::BOTTOM_LEVEL, size)
}

fn compaction_query(ctx: &impl GpuDevice) -> Option<vk::QueryPool> {
    let info = vk::QueryPoolCreateInfo::default().query_type(vk::QueryType::ACCELERATION_STRUCTURE_COMPACTED_SIZE_KHR).query_count(1);
    // SAFETY: valid device with the acceleration-structure extension enabled.
    unsafe { ctx.device().create_query_pool(&info, None) }.ok()
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
    pub fn new(ctx: &impl GpuDevice, l: &AccelLoader, capacity: u32) -> Result<Tlas> {
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

    /// Writes `instances` into the host-visible instance buffer (no pending GPU work may
    /// still read it: the frame slot that owns it has retired).
    pub fn write(&mut self, instances: &[Instance]) -> Result<()> {
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
        self.instances.write(0, data)
    }

    /// The most instances the structure holds.
    pub fn capacity(&self) -> u32 {
        self.capacity
    }

    /// Records the build of the first `count` instances [`write`](Self::write) wrote, between
    /// a barrier from the host's write and one to fragment-shader ray queries.
    ///
    /// # Safety
    /// `cb` is recording outside a rendering instance, after [`write`](Self::write) of at least
    /// `count` instances; no pending GPU work still reads this structure or its instance buffer
    /// (the frame slot that owns it has retired).
    pub unsafe fn cmd_record(&self, ctx: &impl GpuDevice, l: &AccelLoader, cb: vk::CommandBuffer, count: u32) {
        let geoms = [top_geometry(address(ctx, &self.instances))];
        let build = vk::AccelerationStructureBuildGeometryInfoKHR::default()
            .ty(vk::AccelerationStructureTypeKHR::TOP_LEVEL)
            .flags(vk::BuildAccelerationStructureFlagsKHR::PREFER_FAST_TRACE)
            .mode(vk::BuildAccelerationStructureModeKHR::BUILD)
            .geometries(&geoms)
            .dst_acceleration_structure(self.accel.raw)
            .scratch_data(vk::DeviceOrHostAddressKHR { device_address: self.scratch_address });
        let range = [vk::AccelerationStructureBuildRangeInfoKHR::default().primitive_count(count.min(self.capacity))];
        let host = (vk::PipelineStageFlags2::HOST, vk::AccessFlags2::HOST_WRITE);
        let input = (vk::PipelineStageFlags2::ACCELERATION_STRUCTURE_BUILD_KHR, vk::AccessFlags2::SHADER_READ);
        memory_barrier(ctx, cb, host, input);
        // SAFETY: the caller's contract; the instance and scratch buffers and the structure are
        // this object's, alive until it is destroyed.
        unsafe { l.fns.cmd_build_acceleration_structures(cb, std::slice::from_ref(&build), &[&range[..]]) };
        let built = (vk::PipelineStageFlags2::ACCELERATION_STRUCTURE_BUILD_KHR, vk::AccessFlags2::ACCELERATION_STRUCTURE_WRITE_KHR);
        let read = (vk::PipelineStageFlags2::FRAGMENT_SHADER, vk::AccessFlags2::ACCELERATION_STRUCTURE_READ_KHR);
        memory_barrier(ctx, cb, built, read);
    }

    /// Destroys everything; no pending GPU work may use it.
    pub fn destroy(&mut self, ctx: &impl GpuDevice, l: &AccelLoader) {
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
