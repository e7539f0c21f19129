//! The up-front memory check: a scene whose buffers and targets cannot fit the device's
//! largest device-local heap (or the memory budget of [`umbrage::gpu::fault`]) is refused before
//! anything is allocated, with the sizes in the message.

use crate::options::RenderConfig;
use ash::vk;
use umbrage::error::{Error, Result};
use umbrage::gpu::Context;
use umbrage_scene::Scene;

/// Bytes per pixel of the frame's targets, at least: accum (RGBA16F) 8, albedo 4, normal 16,
/// position 16, depth-stencil 4+, count 4, light-intensity map 8+, output 4.
const TARGET_BYTES_PER_PIXEL: u64 = 64;
/// The scene's non-indexed vertex stream: three vertices of ten f32 per triangle.
const SCENE_BYTES_PER_TRIANGLE: u64 = 3 * 40;
/// A caster's dual-length vertex buffer: each vertex as a w=1 and a w=0 vec4.
const CASTER_BYTES_PER_VERTEX: u64 = 2 * 16;
/// A caster's triangles as 16-bit indices (its light cap), at least.
const CASTER_BYTES_PER_TRIANGLE: u64 = 6;

/// What a scene needs in device memory at least, by kind.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct MemoryEstimate {
    /// The frame's render targets.
    pub targets: u64,
    /// The scene's vertex stream (G-buffer and forward passes).
    pub scene: u64,
    /// The shadow casters' vertex and index buffers.
    pub casters: u64,
}

impl MemoryEstimate {
    /// A lower bound on the device memory `scene` needs at `config`'s size.
    pub fn of(scene: &Scene, config: &RenderConfig) -> MemoryEstimate {
        let mut e = MemoryEstimate { targets: config.width as u64 * config.height as u64 * TARGET_BYTES_PER_PIXEL, ..Default::default() };
        for m in &scene.meshes {
            let tris = m.mesh.triangles.len() as u64;
            e.scene = e.scene.saturating_add(tris.saturating_mul(SCENE_BYTES_PER_TRIANGLE));
            if m.casts_shadow {
                let c = (m.mesh.positions.len() as u64).saturating_mul(CASTER_BYTES_PER_VERTEX)
                    + tris.saturating_mul(CASTER_BYTES_PER_TRIANGLE);
                e.casters = e.casters.saturating_add(c);
            }
        }
        e
    }

    /// All of it.
    pub fn total(&self) -> u64 {
        self.targets.saturating_add(self.scene).saturating_add(self.casters)
    }
}

/// The size of the device's largest device-local heap, in bytes.
pub fn largest_device_heap(ctx: &Context) -> u64 {
    // SAFETY: a query on the context's physical device.
    let props = unsafe { ctx.instance.get_physical_device_memory_properties(ctx.physical) };
    props.memory_heaps_as_slice().iter().filter(|h| h.flags.contains(vk::MemoryHeapFlags::DEVICE_LOCAL)).map(|h| h.size).max().unwrap_or(0)
}

/// Refuses `scene` when its [`MemoryEstimate`] exceeds the largest device-local heap or the
/// memory budget, naming the sizes.
pub fn check_fits(ctx: &Context, scene: &Scene, config: &RenderConfig) -> Result<()> {
    let need = MemoryEstimate::of(scene, config);
    let heap = largest_device_heap(ctx);
    let (limit, what) = match umbrage::gpu::fault::memory_budget() {
        Some(b) if b < heap || heap == 0 => (b, "the memory budget (UMBRAGE_MEMORY_BUDGET)"),
        _ => (heap, "the device's largest device-local heap"),
    };
    if limit > 0 && need.total() > limit {
        return Err(Error::OutOfMemory {
            name: format!(
                "scene '{}' at {}x{} (targets {} bytes, scene geometry {} bytes, shadow casters {} bytes; {what})",
                scene.name, config.width, config.height, need.targets, need.scene, need.casters
            ),
            size: need.total(),
            used: 0,
            budget: limit,
        });
    }
    Ok(())
}
