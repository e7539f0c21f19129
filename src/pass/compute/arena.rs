//! The compute pass's static tables of every caster, in one pass-wide arena: nine storage
//! buffers (face planes, triangles, welded positions and the parts' apexes, edges; for
//! mesh-shader extrusion the meshlets, their triangles and their owned edges; the facing
//! stage's block bounds and the `find` stage's word-pair groups) that one
//! descriptor set binds, so one dispatch per stage (or one mesh draw per caster part) serves
//! every (light, caster) pair of a frame; and a tenth, the chunks' dual-length vertices
//! (a vertex buffer), so the merged volume draws address every chunk by its record's
//! `vertexOffset` ([`super::draws`]).
//!
//! A caster's tables are bump-allocated at the end of each table and filled by staged copies
//! (pending uploads: they ride with every frame until one that recorded them retires, like the
//! casters' vertex buffers). Nothing in the arena is ever written twice in place: a caster
//! that is removed, or that moves its vertices (`update_positions`), leaves its ranges dead
//! and takes new ones, so a frame still in flight reads what it was prepared with. When a
//! table is full, the arena is rebuilt: new buffers sized for twice the live tables, every live
//! caster's tables staged again, the old buffers retired until every slot has been prepared
//! again (the frames in flight keep reading them).

use super::ComputeMesh;
use crate::error::{Error, Result};
use crate::gpu::Buffer;
use crate::pass::device::PassDevice;
use ash::vk;
use gpu_allocator::MemoryLocation;

/// The tables, in binding order.
pub(crate) const TABLES: [&str; N] = [
    "planes",
    "triangles",
    "positions",
    "edges",
    "meshlets",
    "meshlet triangles",
    "meshlet edges",
    "volume vertices",
    "block bounds",
    "word pairs",
];
/// The number of tables.
pub(crate) const N: usize = 10;
/// The chunks' dual-length vertices (a vertex buffer, not bound to the compute set).
pub(crate) const VERTICES: usize = 7;
/// The facing stage's block bounds (three `vec4<f32>` per 64 slots).
pub(crate) const BLOCKS: usize = 8;
/// The `find` stage's word-pair groups.
pub(crate) const GROUPS: usize = 9;
/// Bytes of one element of each table (`vec4<f32>`, `Tri`, `vec4<f32>`, `vec4<u32>`,
/// `Meshlet` of `shaders/extrude.wgsl` (16 words), `u32`, `vec4<u32>`, `vec4<f32>`,
/// `vec4<f32>`, `vec4<u32>`).
pub(crate) const ELEMENT_BYTES: [u64; N] = [16, 32, 16, 16, 64, 4, 16, 16, 16, 16];
/// The smallest table, in elements.
const MIN_ELEMENTS: u64 = 1024;

/// `a += b`, table by table.
pub(crate) fn add_elements(a: &mut [u64; N], b: [u64; N]) {
    for (x, y) in a.iter_mut().zip(b) {
        *x += y;
    }
}

/// Elements of each table a caster's [`ComputeMesh`] takes.
pub(crate) fn mesh_elements(m: &ComputeMesh) -> [u64; N] {
    [
        m.planes.len() as u64,
        m.tris.len() as u64,
        m.positions.len() as u64,
        m.edges.len() as u64,
        m.meshlets.len() as u64,
        m.meshlet_tris.len() as u64,
        m.meshlet_edges.len() as u64,
        m.vertices.len() as u64,
        m.blocks.len() as u64,
        m.groups.len() as u64,
    ]
}

/// The pass-wide arena (see the module docs).
#[derive(Default)]
pub(crate) struct ComputeArena {
    /// The tables (absent until the first compute caster).
    pub tables: Option<[Buffer; N]>,
    /// Capacity of each table, in elements.
    pub capacity: [u64; N],
    /// Elements allocated in each table (live and dead).
    pub used: [u64; N],
    /// Elements of dead ranges (removed casters, moved vertices) in each table.
    pub dead: [u64; N],
    /// Times the arena was rebuilt (statistics, and the tests' check of the growth policy).
    pub rebuilds: u64,
}

impl ComputeArena {
    /// Whether `need` more elements fit each table as it is.
    pub fn fits(&self, need: [u64; N]) -> bool {
        self.tables.is_some() && (0..N).all(|k| self.used[k] + need[k] <= self.capacity[k])
    }

    /// Bump-allocates `n` elements in each table: the first element of each range.
    pub fn allocate(&mut self, n: [u64; N]) -> [u32; N] {
        let mut base = [0u32; N];
        for k in 0..N {
            base[k] = self.used[k] as u32;
            self.used[k] += n[k];
        }
        base
    }

    /// Marks a caster's ranges dead.
    pub fn free(&mut self, n: [u64; N]) {
        add_elements(&mut self.dead, n);
    }

    /// New, empty tables with room for `live` elements twice over (at least
    /// [`MIN_ELEMENTS`]); the old buffers are returned for the caller to retire. A table the
    /// device cannot bind whole (`maxStorageBufferRange`) is an error naming it.
    pub fn rebuild(&mut self, dev: &PassDevice, live: [u64; N]) -> Result<Option<[Buffer; N]>> {
        let mut capacity = [0u64; N];
        for k in 0..N {
            let want = (live[k] * 2).max(MIN_ELEMENTS).next_power_of_two();
            let limit = dev.max_storage_range / ELEMENT_BYTES[k];
            if live[k] > limit {
                return Err(Error::Unsupported(format!(
                    "Technique::Compute: the casters' {} table needs {} bytes, more than the device's \
                     maxStorageBufferRange ({} bytes); use Technique::Volumes for this scene",
                    TABLES[k],
                    live[k] * ELEMENT_BYTES[k],
                    dev.max_storage_range
                )));
            }
            capacity[k] = want.min(limit).max(live[k]).max(1);
        }
        let mut made: Vec<Buffer> = Vec::with_capacity(N);
        for k in 0..N {
            let mut usage = vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::TRANSFER_DST;
            if k == VERTICES {
                usage |= vk::BufferUsageFlags::VERTEX_BUFFER;
            }
            match Buffer::new(dev, &format!("compute arena: {}", TABLES[k]), capacity[k] * ELEMENT_BYTES[k], usage, MemoryLocation::GpuOnly)
            {
                Ok(b) => made.push(b),
                Err(e) => {
                    for mut b in made {
                        b.destroy(dev);
                    }
                    return Err(e);
                }
            }
        }
        let tables: [Buffer; N] = made.try_into().map_err(|_| Error::Internal("compute arena tables".into()))?;
        let old = self.tables.replace(tables);
        self.capacity = capacity;
        self.used = [0; N];
        self.dead = [0; N];
        self.rebuilds += 1;
        Ok(old)
    }

    /// The raw handles of the tables (null before the first compute caster).
    pub fn raw(&self) -> [vk::Buffer; N] {
        match &self.tables {
            Some(t) => std::array::from_fn(|k| t[k].raw),
            None => [vk::Buffer::null(); N],
        }
    }

    /// Frees the tables (the host guarantees the device no longer uses them).
    pub fn destroy(&mut self, dev: &PassDevice) {
        if let Some(tables) = self.tables.take() {
            for mut b in tables {
                b.destroy(dev);
            }
        }
    }
}
