//! The camera and light models: plain data the planner, the renderer and the CPU reference
//! all share.
//!
//! The camera model (pixel centres, Vulkan clip space, infinite far plane) is the one both the
//! GPU renderer and the CPU reference use; it is the only code they share. It lives in `geom`
//! rather than `scene` so that the planner depends on no scene loading; `scene` re-exports it.

use glam::{Mat4, Vec3, Vec4};

/// A pinhole camera, right-handed, looking from `eye` to `target`.
#[derive(Clone, Debug, PartialEq)]
pub struct Camera {
    /// Centre of projection, world space.
    pub eye: Vec3,
    /// A world-space point on the optical axis (must differ from `eye`).
    pub target: Vec3,
    /// World-space up direction (need not be unit or orthogonal to the view direction, only not parallel to it).
    pub up: Vec3,
    /// Full vertical field of view, degrees.
    pub fov_y_deg: f32,
    /// Distance from `eye` to the near plane, world units (> 0); the far plane is at infinity.
    pub near: f32,
}

impl Default for Camera {
    fn default() -> Self {
        Camera { eye: Vec3::new(0.0, 2.0, 6.0), target: Vec3::ZERO, up: Vec3::Y, fov_y_deg: 60.0, near: 0.1 }
    }
}

impl Camera {
    /// World -> view (right-handed, looking down -Z).
    pub fn view(&self) -> Mat4 {
        glam::camera::rh::view::look_at_mat4(self.eye, self.target, self.up.normalize())
    }
    /// View -> Vulkan clip space with the far plane at infinity: depth 0 at `near`, 1 at
    /// infinity; y points down in the framebuffer (row 0 is the top of the image).
    pub fn proj_infinite(&self, aspect: f32) -> Mat4 {
        let f = 1.0 / (self.fov_y_deg.to_radians() * 0.5).tan();
        Mat4::from_cols(
            Vec4::new(f / aspect, 0.0, 0.0, 0.0),
            Vec4::new(0.0, -f, 0.0, 0.0),
            Vec4::new(0.0, 0.0, -1.0, -1.0),
            Vec4::new(0.0, 0.0, -self.near, 0.0),
        )
    }
    /// Same with a finite far plane (used with depth clamp, `--depth-mode clamp`).
    pub fn proj_finite(&self, aspect: f32, far: f32) -> Mat4 {
        let f = 1.0 / (self.fov_y_deg.to_radians() * 0.5).tan();
        let n = self.near;
        let r = far / (n - far);
        Mat4::from_cols(
            Vec4::new(f / aspect, 0.0, 0.0, 0.0),
            Vec4::new(0.0, -f, 0.0, 0.0),
            Vec4::new(0.0, 0.0, r, -1.0),
            Vec4::new(0.0, 0.0, r * n, 0.0),
        )
    }
    /// The world-space ray through the centre of pixel (x, y) of a `width` x `height` image
    /// (row 0 at the top): origin on the near plane, unit direction. f64 for the reference.
    pub fn pixel_ray(&self, x: u32, y: u32, width: u32, height: u32) -> (glam::DVec3, glam::DVec3) {
        let aspect = width as f64 / height as f64;
        let ndc_x = (x as f64 + 0.5) / width as f64 * 2.0 - 1.0;
        let ndc_y = (y as f64 + 0.5) / height as f64 * 2.0 - 1.0;
        let t = (self.fov_y_deg as f64).to_radians() * 0.5;
        let t = t.tan();
        // view space: x right, y up, looking down -z; ndc y points down.
        let dir_v = glam::DVec3::new(ndc_x * t * aspect, -ndc_y * t, -1.0);
        let eye = self.eye.as_dvec3();
        let fwd = (self.target.as_dvec3() - eye).normalize();
        let right = fwd.cross(self.up.as_dvec3()).normalize();
        let up = right.cross(fwd);
        let d = right * dir_v.x + up * dir_v.y + fwd * (-dir_v.z);
        let origin = eye + d * self.near as f64;
        (origin, d.normalize())
    }
}

/// What sort of light source a [`Light`] is (the homogeneous light position's w: 1 or 0).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "lowercase"))]
pub enum LightKind {
    /// A point light at `position`, shining in every direction (w = 1).
    Point,
    /// A point light at `position` limited to a cone of `cone_deg` around `direction` (w = 1).
    Spot,
    /// A light at infinity, travelling along `direction` (w = 0): every extrusion is parallel.
    Directional,
}

impl LightKind {
    /// The kind's name in scene files, dumps and reports: `point`, `spot` or `directional`.
    pub fn name(self) -> &'static str {
        match self {
            LightKind::Point => "point",
            LightKind::Spot => "spot",
            LightKind::Directional => "directional",
        }
    }
}

/// A light. `direction` is the unit direction the light travels (directional, spot).
#[derive(Clone, Debug, PartialEq)]
pub struct Light {
    /// Point, spot or directional.
    pub kind: LightKind,
    /// World-space position (point and spot lights; ignored for directional).
    pub position: Vec3,
    /// Unit direction the light travels, world space (spot and directional; ignored for point).
    pub direction: Vec3,
    /// Linear RGB colour; the illumination uses `color * intensity`.
    pub color: Vec3,
    /// Scale on `color` (unitless; 1 is the scene files' default).
    pub intensity: f32,
    /// Attenuation range: beyond it the light contributes nothing (and casters are culled).
    pub radius: Option<f32>,
    /// Full cone angle of a spot light, degrees.
    pub cone_deg: f32,
    /// `Some` for an area light ([`crate::geom::area`]): `kind` is then [`LightKind::Point`]
    /// and `position` the centre; the renderer splits it into point-light samples.
    pub area: Option<super::area_shape::AreaLight>,
}

impl Light {
    /// A white point light of intensity 1 at `position`, reaching everything (no radius).
    ///
    /// ```
    /// use glam::Vec3;
    /// use umbrage::geom::{Light, LightKind};
    /// let l = Light::point(Vec3::new(2.0, 6.0, 2.0));
    /// assert_eq!((l.kind, l.radius, l.intensity), (LightKind::Point, None, 1.0));
    /// assert_eq!(l.homogeneous(), glam::Vec4::new(2.0, 6.0, 2.0, 1.0));
    /// ```
    pub fn point(position: Vec3) -> Light {
        Light {
            kind: LightKind::Point,
            position,
            direction: Vec3::NEG_Y,
            color: Vec3::ONE,
            intensity: 1.0,
            radius: None,
            cone_deg: 180.0,
            area: None,
        }
    }

    /// Whether the light reaches `p` at all, shadows aside: within its range (`radius`) and,
    /// for a spot light, inside its cone. Directional lights reach everything.
    pub fn reaches(&self, p: Vec3) -> bool {
        let l = self.homogeneous();
        let to_light = if l.w == 0.0 { l.truncate() } else { l.truncate() - p };
        let in_range = self.radius.map(|r| l.w == 0.0 || to_light.length() < r).unwrap_or(true);
        let in_cone = self.kind != LightKind::Spot
            || (-to_light.normalize()).dot(self.direction.normalize()) > (self.cone_deg.to_radians() * 0.5).cos();
        in_range && in_cone
    }

    /// Homogeneous position: (position, 1) for point and spot, (-direction, 0) for directional
    /// (xyz pointing towards the light), as in McGuire et al. and the dump format.
    pub fn homogeneous(&self) -> Vec4 {
        match self.kind {
            LightKind::Directional => (-self.direction.normalize()).extend(0.0),
            _ => self.position.extend(1.0),
        }
    }
}
