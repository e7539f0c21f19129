//! Push-constant blocks of the frame's own shaders, as `#[repr(C)]` structs mirroring the GLSL
//! `layout(push_constant)` blocks (vec4 / mat4 only: no std430 padding).

use bytemuck::{Pod, Zeroable};
use glam::{DVec3, Mat4, Vec3, Vec4};
use umbrage_scene::{Light, LightKind};

/// `gbuffer.vert` / `gbuffer.frag`: `{ mat4 view_proj; vec4 ambient; }`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GBufferPush {
    /// Eye-relative view -> clip.
    pub view_proj: [f32; 16],
    /// Ambient light colour (rgb).
    pub ambient: [f32; 4],
}

/// `sphere.frag`'s MS variant (the analytic spheres of a multisampled frame):
/// `{ mat4 view_proj; vec4 ambient; vec4 ray_x; vec4 ray_y; vec4 ray_0; }`, 128 bytes (the
/// push-constant size every device has). `ray_x * x + ray_y * y + ray_0` is the homogeneous
/// eye-relative point on the near plane under window position (x, y): the inverse
/// view-projection with the viewport folded in, so each sample casts its ray through its own
/// location (`gl_FragCoord` under sample shading).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct SpherePush {
    /// The G-buffer block.
    pub gbuffer: GBufferPush,
    /// The inverse view-projection's x column, over the viewport's half width.
    pub ray_x: [f32; 4],
    /// Its y column, over the viewport's half height.
    pub ray_y: [f32; 4],
    /// Its w column minus the x and y columns (window origin at the near plane).
    pub ray_0: [f32; 4],
}

impl SpherePush {
    /// The block for a frame projecting eye-relative positions with `view_proj` into a
    /// `width` x `height` viewport.
    pub fn new(gbuffer: GBufferPush, view_proj: Mat4, width: u32, height: u32) -> SpherePush {
        let inv = view_proj.as_dmat4().inverse();
        let (sx, sy) = (2.0 / width.max(1) as f64, 2.0 / height.max(1) as f64);
        // ndc = 2 * window / size - 1, z = 0 (the near plane; z = 1 is at infinity).
        let ray_x = inv.x_axis * sx;
        let ray_y = inv.y_axis * sy;
        let ray_0 = inv.w_axis - inv.x_axis - inv.y_axis;
        let f = |v: glam::DVec4| v.as_vec4().to_array();
        SpherePush { gbuffer, ray_x: f(ray_x), ray_y: f(ray_y), ray_0: f(ray_0) }
    }
}

/// `illuminate.frag` (and the light half of the forward block):
/// `{ vec4 light_pos; vec4 color; vec4 spot; vec4 params; }`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct LightPush {
    /// xyz relative to the eye, w = 1; or xyz towards the light, w = 0.
    pub light_pos: [f32; 4],
    /// rgb = colour * intensity.
    pub color: [f32; 4],
    /// xyz = travel direction, w = cos(half cone); w = -2 when not a spot.
    pub spot: [f32; 4],
    /// x = radius (0: unbounded), y = 1 when the light-intensity map is in log space,
    /// z = 1 for a forward light pass (0: the ambient "over" pass), w = the shading mode
    /// ([`Shading`](super::Shading): 0 smooth, 1 naive smooth, 2 flat).
    pub params: [f32; 4],
}

impl LightPush {
    /// This block with shading mode `shading` (`params.w`).
    pub fn with_shading(mut self, shading: super::Shading) -> LightPush {
        self.params[3] = shading.code();
        self
    }

    /// A light's block for a frame whose eye is `eye`.
    pub fn new(l: &Light, eye: DVec3, log: bool) -> LightPush {
        let pos = Vec4::from_array(umbrage::pass::light_rel(l, eye));
        let spot = match l.kind {
            LightKind::Spot => l.direction.normalize().extend((l.cone_deg.to_radians() * 0.5).cos()),
            _ => Vec4::new(0.0, 0.0, -1.0, -2.0),
        };
        LightPush {
            light_pos: pos.to_array(),
            color: (l.color * l.intensity).extend(1.0).to_array(),
            spot: spot.to_array(),
            params: [l.radius.unwrap_or(0.0), if log { 1.0 } else { 0.0 }, 0.0, 0.0],
        }
    }
}

/// `transparent.vert` / `transparent.frag`: `{ mat4 view_proj; vec4 light_pos; vec4 color;
/// vec4 spot; vec4 params; }`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct ForwardPush {
    /// Eye-relative view -> clip.
    pub view_proj: [f32; 16],
    /// The light (params.z = 1), or the ambient colour in `color` (params.z = 0).
    pub light: LightPush,
}

impl ForwardPush {
    /// The ambient "over" pass.
    pub fn ambient(view_proj: Mat4, ambient: Vec3) -> ForwardPush {
        let light = LightPush { color: ambient.extend(0.0).to_array(), ..LightPush::default() };
        ForwardPush { view_proj: view_proj.to_cols_array(), light }
    }
    /// A light's forward pass.
    pub fn light(view_proj: Mat4, light: &LightPush) -> ForwardPush {
        let mut light = *light;
        light.params[2] = 1.0;
        ForwardPush { view_proj: view_proj.to_cols_array(), light }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    #[test]
    fn blocks_match_the_glsl_sizes() {
        assert_eq!(std::mem::size_of::<GBufferPush>(), 80);
        assert_eq!(std::mem::size_of::<LightPush>(), 64);
        assert_eq!(std::mem::size_of::<ForwardPush>(), 128);
        assert_eq!(std::mem::offset_of!(ForwardPush, light), 64);
    }
}
