//! The host's camera as the pass sees it ([`ShadowView`]): the eye in f64, the eye-relative
//! view and the host's projection.

use super::desc::DepthDirection;
use crate::error::{Error, Result};
use glam::{DMat4, DVec3, Mat4};

/// The largest target width or height a [`ShadowView`] may name, in pixels (beyond every
/// device's `maxFramebufferWidth`).
pub const MAX_TARGET_SIZE: u32 = 65536;

/// The host's camera for one frame, as the pass needs it to land its volumes exactly on the
/// host's depth values: the eye in f64 and the host's eye-relative view and projection (the
/// host draws its scene with `proj * view * (world - eye)`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShadowView {
    /// The eye in world space (f64: scenes far from the origin keep their precision).
    pub eye: DVec3,
    /// World directions -> view space: the view matrix without its translation.
    pub view: Mat4,
    /// View -> Vulkan clip space (infinite far plane for [`DepthMode::Infinite`](super::DepthMode),
    /// finite for `Clamp`).
    pub proj: Mat4,
    /// The target's size in pixels (scissor rectangles are computed for it).
    pub width: u32,
    /// The target's height in pixels.
    pub height: u32,
}

impl ShadowView {
    /// The view of a host camera given as its usual (world -> view) matrix `view`, with its
    /// translation: the pass needs the eye in f64 and the rotation alone, so it strips the
    /// translation here (`eye` is the camera's world position, `view` maps it to the origin).
    /// `proj` is the host's view -> Vulkan clip projection (forward or reverse-Z, as the pass
    /// was created for), `size` the target's `(width, height)`.
    ///
    /// Errors: [`Error::Misuse`] when `view` does not map `eye` to the origin (to within
    /// 1e-4 of the scene's scale), or is not a rigid rotation plus translation.
    ///
    /// ```
    /// use glam::{DVec3, Mat4, Vec3};
    /// use umbrage::pass::ShadowView;
    /// let eye = Vec3::new(0.0, 2.0, 6.0);
    /// let view = glam::camera::rh::view::look_at_mat4(eye, Vec3::ZERO, Vec3::Y);
    /// let proj = glam::camera::rh::proj::vulkan::perspective_infinite(1.0, 1.0, 0.1);
    /// let v = ShadowView::from_view_matrix(eye.as_dvec3(), view, proj, (640, 480))?;
    /// assert_eq!(v.view.w_axis.truncate(), Vec3::ZERO);
    /// assert!((v.world_view_proj() - proj * view).abs_diff_eq(Mat4::ZERO, 1e-5));
    /// # Ok::<(), umbrage::Error>(())
    /// ```
    pub fn from_view_matrix(eye: DVec3, view: Mat4, proj: Mat4, size: (u32, u32)) -> Result<ShadowView> {
        let v = view.as_dmat4();
        let at_eye = v.transform_point3(eye);
        let scale = eye.length().max(1.0);
        if !at_eye.is_finite() || at_eye.length() > 1e-4 * scale {
            return Err(Error::argument(
                "ShadowView::from_view_matrix",
                format!("the view matrix maps the eye {eye} to {at_eye}, not to the origin: pass the camera's own view matrix"),
            ));
        }
        let r = glam::DMat3::from_mat4(v);
        if !orthonormal(&r) || (v.row(3) - glam::DVec4::W).length() > 1e-9 {
            return Err(Error::argument("ShadowView::from_view_matrix", "the view matrix is not a rotation and a translation"));
        }
        let rotation = Mat4::from_mat3(glam::Mat3::from_mat4(view));
        let out = ShadowView { eye, view: rotation, proj, width: size.0, height: size.1 };
        out.check()?;
        Ok(out)
    }

    /// The same view with a forward projection: the planner's near plane, frustum, scissors
    /// and depth bounds are computed on it.
    pub(crate) fn forward(&self, direction: DepthDirection) -> ShadowView {
        match direction {
            DepthDirection::Forward => *self,
            DepthDirection::Reverse => ShadowView { proj: super::desc::reverse_z(self.proj), ..*self },
        }
    }

    /// World -> clip, composed in f64 (the planner's frustum and scissor tests).
    pub fn world_view_proj(&self) -> Mat4 {
        (self.proj.as_dmat4() * self.view.as_dmat4() * DMat4::from_translation(-self.eye)).as_mat4()
    }
    /// The ranges `docs/contract.md` lists: every error is
    /// [`Misuse::Argument`](crate::error::Misuse::Argument) naming the field.
    pub(crate) fn check(&self) -> Result<()> {
        if !self.eye.is_finite() {
            return Err(Error::argument("ShadowView::eye", format!("{} is not finite", self.eye)));
        }
        if !self.view.is_finite() {
            return Err(Error::argument("ShadowView::view", "not finite"));
        }
        let v = self.view.as_dmat4();
        let r = glam::DMat3::from_mat4(v);
        let rigid = orthonormal(&r) && r.determinant() > 0.0;
        if !rigid || v.w_axis != glam::DVec4::W || (v.row(3) - glam::DVec4::W).length() != 0.0 {
            return Err(Error::argument(
                "ShadowView::view",
                "not a rotation without translation (the eye-relative view: ShadowView::from_view_matrix makes it from a \
                 camera's view matrix)",
            ));
        }
        let det = self.proj.as_dmat4().determinant();
        if !(self.proj.is_finite() && det.is_finite() && det != 0.0) {
            return Err(Error::argument("ShadowView::proj", format!("not finite or singular (determinant {det})")));
        }
        for (field, n) in [("ShadowView::width", self.width), ("ShadowView::height", self.height)] {
            if !(1..=MAX_TARGET_SIZE).contains(&n) {
                return Err(Error::argument(field, format!("{n} is outside 1..={MAX_TARGET_SIZE}")));
            }
        }
        Ok(())
    }
}

/// Whether `r`'s columns are orthonormal to 1e-4 (a rotation, or a rotation and a mirror).
fn orthonormal(r: &glam::DMat3) -> bool {
    (*r * r.transpose()).abs_diff_eq(glam::DMat3::IDENTITY, 1e-4)
}
