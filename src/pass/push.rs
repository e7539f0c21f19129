//! Push-constant blocks of the shadow pass's shaders, as `#[repr(C)]` structs that mirror the
//! GLSL `layout(push_constant)` blocks field for field (std430: vec4 and mat4 only, so no
//! padding), uploaded with bytemuck.

use bytemuck::{Pod, Zeroable};
use glam::{Mat4, Vec4};

/// `shaders/shadow.vert`, `count.frag`, `transmit.frag`, `volume.frag`, `edgequad.vert`:
/// `{ mat4 mvp; vec4 light; vec4 color; }`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct VolumePush {
    /// Object space -> clip space (eye-relative, composed in f64).
    pub mvp: [f32; 16],
    /// The light in the caster's object space, homogeneous (w = 0: directional).
    pub light: [f32; 4],
    /// Float counter: `x` = the sign a front face contributes (+1 z-pass, -1 z-fail);
    /// light-intensity map: `yzw` = the caster's transmittance; debug overlay: RGBA.
    pub color: [f32; 4],
}

impl VolumePush {
    /// Size in bytes (the pipeline layout's push range).
    pub const SIZE: u32 = std::mem::size_of::<VolumePush>() as u32;

    /// A block for one caster and light.
    pub fn new(mvp: Mat4, light: Vec4, color: [f32; 4]) -> VolumePush {
        VolumePush { mvp: mvp.to_cols_array(), light: light.to_array(), color }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    #[test]
    fn volume_push_matches_the_glsl_block() {
        // mat4 (64) + vec4 (16) + vec4 (16), std430.
        assert_eq!(VolumePush::SIZE, 96);
        assert_eq!(std::mem::offset_of!(VolumePush, light), 64);
        assert_eq!(std::mem::offset_of!(VolumePush, color), 80);
    }
}
