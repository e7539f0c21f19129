//! The window's Vulkan surface handles as the driver can take them. winit's X11 windows come
//! as Xlib handles, and `ash_window` makes an Xlib surface of them; a driver with
//! `VK_KHR_xcb_surface` but no `VK_KHR_xlib_surface` (SwiftShader as Debian's chromium-common
//! ships it) gets the same window through XCB instead: the connection Xlib itself talks
//! through (`XGetXCBConnection`, libX11-xcb) and the same window id.

use raw_window_handle::{RawDisplayHandle, RawWindowHandle, XcbDisplayHandle, XcbWindowHandle};
use std::ffi::CStr;
use std::num::NonZeroU32;
use std::ptr::NonNull;
use umbrage::error::{Error, Result};

/// Whether the Vulkan loader offers the instance extension `name` (with any driver).
fn instance_has(entry: &ash::Entry, name: &CStr) -> bool {
    // SAFETY: a plain enumeration on a loaded entry.
    unsafe { entry.enumerate_instance_extension_properties(None) }
        .map(|v| v.iter().any(|e| e.extension_name_as_c_str().is_ok_and(|n| n == name)))
        .unwrap_or(false)
}

/// `display` and `window` unchanged, or, for an Xlib window on a driver without the Xlib
/// surface but with the XCB one, the same window as XCB handles.
///
/// # Errors
/// [`Error::Unsupported`] when the driver has neither and says which it would need, or when
/// libX11-xcb cannot be loaded.
pub(super) fn surface_handles(display: RawDisplayHandle, window: RawWindowHandle) -> Result<(RawDisplayHandle, RawWindowHandle)> {
    let (RawDisplayHandle::Xlib(xd), RawWindowHandle::Xlib(xw)) = (display, window) else {
        return Ok((display, window));
    };
    // SAFETY: loading the Vulkan loader library; the entry lives until the end of this call and
    // nothing created from it outlives it.
    let Ok(entry) = (unsafe { ash::Entry::load() }) else { return Ok((display, window)) };
    if instance_has(&entry, ash::khr::xlib_surface::NAME) || !instance_has(&entry, ash::khr::xcb_surface::NAME) {
        // The Xlib route (or no X11 surface at all: Context::with_extensions names it).
        return Ok((display, window));
    }
    let missing = |why: String| {
        Error::Unsupported(format!(
            "the Vulkan driver has VK_KHR_xcb_surface but not VK_KHR_xlib_surface, and the window's XCB connection \
             cannot be had ({why}): install libX11-xcb (Debian: libx11-xcb1), or render offscreen with `umbrage render`"
        ))
    };
    let xlib_display = xd.display.ok_or_else(|| missing("the Xlib display handle is null".into()))?;
    let lib = x11_dl::xlib_xcb::Xlib_xcb::open().map_err(|e| missing(e.to_string()))?;
    // SAFETY: the display is winit's live Xlib display (it outlives the window and so the
    // surface); XGetXCBConnection only reads it. The connection it returns is owned by that
    // display, not by the library handle dropped below.
    let connection = unsafe { (lib.XGetXCBConnection)(xlib_display.as_ptr().cast()) };
    let connection = NonNull::new(connection.cast()).ok_or_else(|| missing("XGetXCBConnection returned null".into()))?;
    let id = u32::try_from(xw.window).ok().and_then(NonZeroU32::new).ok_or_else(|| missing(format!("window id {}", xw.window)))?;
    let display = RawDisplayHandle::Xcb(XcbDisplayHandle::new(Some(connection), xd.screen));
    let mut w = XcbWindowHandle::new(id);
    w.visual_id = NonZeroU32::new(xw.visual_id as u32);
    Ok((display, RawWindowHandle::Xcb(w)))
}
