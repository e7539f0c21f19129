//! The host's depth-stencil image as the pass records into it, and its declared layouts.

use super::desc::TargetModel;
use super::frame::PreparedFrame;
use crate::error::{Error, Result};
use ash::vk;

/// The host's depth-stencil image as the determination uses it, with the layouts the host
/// declares (FidelityFX / NRD style): the layout it is in when the call is recorded, and the
/// layout the host wants it left in.
///
/// With [`TargetModel::DynamicRendering`] the pass records the transitions itself: from
/// [`layout`](Self::layout) to `DEPTH_STENCIL_ATTACHMENT_OPTIMAL` (waiting for every earlier
/// command's writes), its rendering, then to [`final_layout`](Self::final_layout) (its stencil
/// writes made visible to every later command). With [`TargetModel::RenderPass`] the image is
/// the subpass's attachment and no transition can be recorded inside the render pass: both
/// layouts must be the subpass's layout, and the host's subpass dependencies do the rest.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DepthStencilTarget {
    /// The host's depth-stencil image (both aspects are transitioned).
    pub image: vk::Image,
    /// A view of both aspects of [`image`](Self::image), in the format and sample count the
    /// pass was created for.
    pub view: vk::ImageView,
    /// The image's size (the viewport covers all of it); equal to the frame's view size.
    pub extent: vk::Extent2D,
    /// The layout the image is in when the call is recorded (never `UNDEFINED`: the depth is
    /// read).
    pub layout: vk::ImageLayout,
    /// The layout the pass leaves the image in.
    pub final_layout: vk::ImageLayout,
}

impl DepthStencilTarget {
    /// A target in `DEPTH_STENCIL_ATTACHMENT_OPTIMAL` before and after.
    ///
    /// ```
    /// use ash::vk;
    /// use umbrage::pass::DepthStencilTarget;
    /// let t = DepthStencilTarget::new(vk::Image::null(), vk::ImageView::null(), vk::Extent2D { width: 1280, height: 720 });
    /// assert_eq!(t.layout, vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL);
    /// assert_eq!(t.final_layout, t.layout);
    /// ```
    pub fn new(image: vk::Image, view: vk::ImageView, extent: vk::Extent2D) -> DepthStencilTarget {
        let l = vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL;
        DepthStencilTarget { image, view, extent, layout: l, final_layout: l }
    }

    /// The same target, declared in `layout` and to be left in `final_layout`.
    ///
    /// ```
    /// use ash::vk::{self, ImageLayout as L};
    /// use umbrage::pass::DepthStencilTarget;
    /// let t = DepthStencilTarget::new(vk::Image::null(), vk::ImageView::null(), vk::Extent2D { width: 64, height: 64 })
    ///     .with_layouts(L::DEPTH_STENCIL_READ_ONLY_OPTIMAL, L::SHADER_READ_ONLY_OPTIMAL);
    /// assert_eq!((t.layout, t.final_layout), (L::DEPTH_STENCIL_READ_ONLY_OPTIMAL, L::SHADER_READ_ONLY_OPTIMAL));
    /// ```
    pub fn with_layouts(self, layout: vk::ImageLayout, final_layout: vk::ImageLayout) -> DepthStencilTarget {
        DepthStencilTarget { layout, final_layout, ..self }
    }

    pub(super) fn check(&self, frame: &PreparedFrame, model: &TargetModel) -> Result<()> {
        use vk::ImageLayout as L;
        if self.extent != frame.extent() {
            return Err(Error::argument(
                "DepthStencilTarget",
                format!(
                    "extent {}x{} differs from the frame's view {}x{}",
                    self.extent.width,
                    self.extent.height,
                    frame.extent().width,
                    frame.extent().height
                ),
            ));
        }
        if matches!(self.layout, L::UNDEFINED | L::PREINITIALIZED) || matches!(self.final_layout, L::UNDEFINED | L::PREINITIALIZED) {
            return Err(Error::argument(
                "DepthStencilTarget",
                format!(
                    "declared layouts {:?} -> {:?}: the depth is read, so neither may be UNDEFINED or PREINITIALIZED",
                    self.layout, self.final_layout
                ),
            ));
        }
        if matches!(model, TargetModel::RenderPass(_)) && self.layout != self.final_layout {
            return Err(Error::argument(
                "DepthStencilTarget",
                format!(
                    "{:?} -> {:?} inside the host's render pass: no transition can be recorded there; declare the subpass's layout twice",
                    self.layout, self.final_layout
                ),
            ));
        }
        Ok(())
    }
}
