//! Mesh-shader extrusion ([`Technique::Mesh`](super::Technique::Mesh)): the mesh pipelines, their
//! push block and descriptor-set layout, and each part's draws.
//!
//! The CPU plans as for [`Technique::Compute`](super::Technique::Compute) (McGuire's cases from
//! the parts' bounds, culling, the formulation and the dark cap kind); the compute pass's
//! `facing` and `exact` stages find every (light, caster) pair's facing bits, bit for bit the
//! CPU's; then per (light, caster part) and per thing drawn (sides with their fan dark-cap
//! triangles, the dark cap of front or back faces, the light cap) one `vkCmdDrawMeshTasksEXT`
//! over the part's meshlets ([`crate::shadow::meshlet`]), a workgroup each, emits the
//! triangles the CPU would (`shaders/extrude.wgsl`). The caster's static tables (positions,
//! triangles, meshlets, their triangles and owned edges) are the compute pass's arena's; the
//! facing bits and the per-draw counters are the frame's.
//!
//! A draw covers at most [`MAX_TASKS`] meshlets (every device's `maxMeshWorkGroupCount[0]`):
//! larger parts take several draws. With `taskShader` a task stage culls the meshlets that
//! would emit nothing (`shaders/extrude.wgsl`, [`super::mesh_pipes`]): a draw then dispatches
//! one task workgroup per [`TASK_GROUP`] meshlets.

use super::push::VolumePush;
use bytemuck::{Pod, Zeroable};

/// Most meshlets (workgroups) one draw dispatches: Vulkan's minimum `maxMeshWorkGroupCount[0]`.
pub(crate) const MAX_TASKS: u32 = 65535;
/// Meshlets one task workgroup decides (`TASK_GROUP` of `shaders/extrude.wgsl`).
pub(crate) const TASK_GROUP: u32 = 64;
/// Storage-buffer bindings of the mesh set: positions, triangles, meshlets, meshlet triangles,
/// meshlet edges (the arena's), facing bits and the draws' counters (the frame's).
pub(crate) const MESH_BINDINGS: u32 = 7;
/// Words of one draw's counters: sides, dark cap, light cap, silhouette edges, then the
/// meshlets the draws covered and the mesh workgroups that ran (fewer where the task stage
/// culled).
pub(crate) const COUNT_WORDS: usize = 6;
/// Words of one row of the arena's meshlet table (`struct Meshlet` of `shaders/extrude.wgsl`):
/// its ranges, its bounding sphere, its sides' and faces' normal cones.
pub(crate) const MESHLET_WORDS: usize = 16;

/// The meshlet table's rows of `ml`: `(first triangle, triangles, first edge, edges)` (the
/// firsts relative to the caster's ranges of the meshlet triangle and edge tables; see
/// [`placed`]), the sphere `(centre, radius)`, the sides' cone `(axis, cos)` and the faces'
/// cone, as f32 bits.
pub(crate) fn meshlet_rows(ml: &crate::shadow::meshlet::Meshlets) -> Vec<[u32; MESHLET_WORDS]> {
    ml.meshlets
        .iter()
        .zip(&ml.bounds)
        .map(|(m, b)| {
            let (c, s, f) = (b.sphere.center, b.sides.axis, b.faces.axis);
            let floats = [c.x, c.y, c.z, b.sphere.radius, s.x, s.y, s.z, b.sides.cos, f.x, f.y, f.z, b.faces.cos];
            let mut row = [0u32; MESHLET_WORDS];
            row[..4].copy_from_slice(&[m.first_triangle, m.triangle_count, m.first_edge, m.edge_count]);
            for (w, x) in row[4..].iter_mut().zip(floats) {
                *w = x.to_bits();
            }
            row
        })
        .collect()
}

/// A meshlet row with its firsts made absolute: the caster's first meshlet triangle
/// (`tris`) and first meshlet edge (`edges`) in the arena.
pub(crate) fn placed(mut row: [u32; MESHLET_WORDS], tris: u32, edges: u32) -> [u32; MESHLET_WORDS] {
    row[0] += tris;
    row[2] += edges;
    row
}

/// What a draw emits (`pc.flags` of `shaders/extrude.wgsl`).
pub(crate) mod flags {
    /// Owned silhouette edges' sides (and fan triangles).
    pub const SIDES: u32 = 0;
    /// The dark cap of front or back faces.
    pub const DARK: u32 = 1;
    /// The light cap.
    pub const LIGHT: u32 = 2;
    /// A directional light: one side triangle per edge.
    pub const DIRECTIONAL: u32 = 4;
    /// McGuire's fan dark cap, with the sides.
    pub const FAN: u32 = 8;
    /// `DARK`: the front faces' cap (else the back faces'); `LIGHT`: the front formulation.
    pub const WANT: u32 = 16;
}

/// The push block of `shaders/extrude.wgsl` (`struct Push`): 128 bytes, the most every
/// device takes.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub(crate) struct MeshPush {
    /// The volume push block's fields, at its offsets (count.frag reads `color`).
    pub mvp: [f32; 16],
    pub light: [f32; 4],
    pub color: [f32; 4],
    pub meshlet_base: u32,
    pub meshlets: u32,
    pub tri_base: u32,
    pub pos_base: u32,
    pub fac_base: u32,
    pub flags: u32,
    pub apex: u32,
    pub stat: u32,
}

impl MeshPush {
    pub const SIZE: u32 = std::mem::size_of::<MeshPush>() as u32;
}

/// One mesh draw of a caster part (everything of the push block but the caster's matrix,
/// light and sign, which the recording takes from the caster's draw).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct MeshDraw {
    pub meshlet_base: u32,
    pub meshlets: u32,
    pub tri_base: u32,
    pub pos_base: u32,
    pub fac_base: u32,
    pub flags: u32,
    pub apex: u32,
    pub stat: u32,
}

impl MeshDraw {
    /// The push block for the caster's `volume` block.
    pub fn push(&self, volume: &VolumePush) -> MeshPush {
        MeshPush {
            mvp: volume.mvp,
            light: volume.light,
            color: volume.color,
            meshlet_base: self.meshlet_base,
            meshlets: self.meshlets,
            tri_base: self.tri_base,
            pos_base: self.pos_base,
            fac_base: self.fac_base,
            flags: self.flags,
            apex: self.apex,
            stat: self.stat,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    #[test]
    fn push_matches_the_wgsl_block() {
        assert_eq!(MeshPush::SIZE, 128);
        assert_eq!(std::mem::offset_of!(MeshPush, light), 64);
        assert_eq!(std::mem::offset_of!(MeshPush, color), 80);
        assert_eq!(std::mem::offset_of!(MeshPush, meshlet_base), 96);
        assert_eq!(std::mem::offset_of!(MeshPush, stat), 124);
        // the output budget the shader declares is the meshlets' (and within 256 / 256)
        use crate::shadow::meshlet::{MESHLET_OUTPUT_PRIMITIVES, MESHLET_OUTPUT_VERTICES};
        assert_eq!((MESHLET_OUTPUT_VERTICES, MESHLET_OUTPUT_PRIMITIVES), (255, 153));
    }

    /// A meshlet row is `struct Meshlet` of `shaders/extrude.wgsl` (64 bytes, the arena's
    /// element), its bounds as f32 bits, its firsts made absolute by `placed`.
    #[test]
    fn meshlet_rows_match_the_wgsl_struct() {
        use crate::geom::testmesh::uv_sphere;
        use crate::shadow::meshlet::Meshlets;
        assert_eq!(MESHLET_WORDS as u64 * 4, crate::pass::compute::arena::ELEMENT_BYTES[4]);
        let c = crate::shadow::Caster::new("s", &uv_sphere(1.0, 32, 16), glam::Mat4::IDENTITY).unwrap();
        let ml = Meshlets::build(&c);
        let rows = meshlet_rows(&ml);
        assert_eq!(rows.len(), ml.meshlets.len());
        for ((row, m), b) in rows.iter().zip(&ml.meshlets).zip(&ml.bounds) {
            assert_eq!(row[..4], [m.first_triangle, m.triangle_count, m.first_edge, m.edge_count]);
            let f = |k: usize| f32::from_bits(row[k]);
            assert_eq!([f(4), f(5), f(6), f(7)], [b.sphere.center.x, b.sphere.center.y, b.sphere.center.z, b.sphere.radius]);
            assert_eq!([f(8), f(9), f(10), f(11)], [b.sides.axis.x, b.sides.axis.y, b.sides.axis.z, b.sides.cos]);
            assert_eq!([f(12), f(13), f(14), f(15)], [b.faces.axis.x, b.faces.axis.y, b.faces.axis.z, b.faces.cos]);
            let p = placed(*row, 100, 1000);
            assert_eq!((p[0], p[1], p[2], p[3]), (row[0] + 100, row[1], row[2] + 1000, row[3]));
            assert_eq!(p[4..], row[4..]);
        }
        // a sphere of 512 triangles: most meshlets have cones that decide
        assert!(ml.bounds.iter().filter(|b| b.sides.decides() && b.faces.decides()).count() * 2 > ml.bounds.len());
    }
}
