//! `umbrage view`: an interactive window on the same frame as `umbrage render`.
//!
//! Design notes
//! - The viewer is one more client of [`Renderer`](umbrage_render::Renderer): every frame it
//!   moves the scene (motion at the frame's time, then the user's edits), submits the
//!   renderer's frame (its ring of two slots: the CPU plans frame N while the GPU runs N-1),
//!   and in a second submission on the same queue blits the renderer's tone-mapped sRGB output
//!   into the acquired swapchain image, draws the egui overlay over it and presents. The blit
//!   is between two 8-bit sRGB formats of the same size with NEAREST filtering, so the window
//!   shows the bytes `render` writes to its PNG (tests/cli/view.rs checks both the renderer's
//!   readback and the swapchain image against `render`).
//! - Presentation keeps two frames in flight of its own ([`swapchain::FRAMES_IN_FLIGHT`]):
//!   per frame a command buffer, a fence and an acquire semaphore; per swapchain image a
//!   present semaphore. Resize, out-of-date and suboptimal rebuild the swapchain (and resize
//!   the renderer's targets); a zero extent (minimised) renders nothing until restored.
//! - Time: each frame's scene time advances by the wall clock (or `--time-step`), stops with
//!   `Space`, and is reported in `--stats`, so `umbrage render --time T` reproduces a frame.
//! - Controls ([`controls`]) are plain arithmetic, unit-tested without a window.

#![warn(missing_docs)]

mod app;
pub mod controls;
mod frame;
mod overlay;
mod present;
mod surface;
pub mod swapchain;

use std::path::PathBuf;
use std::process::ExitCode;
use umbrage::error::{Error, Result};
use umbrage::named_enum;
use umbrage_render::{RenderOptions, View};

named_enum!(
    /// `--vsync`.
    Vsync, "vsync", {
        /// FIFO presentation (waits for the display).
        #[default]
        On => "on",
        /// MAILBOX, else IMMEDIATE (FIFO when neither is offered; the overlay says so).
        Off => "off",
    }
);

/// `umbrage view`'s own flags (the frame's are `render`'s).
#[derive(clap::Args, Clone, Debug)]
pub struct ViewArgs {
    /// Exit after N frames (0 or absent: run until Esc or the window closes).
    #[arg(long)]
    pub frames: Option<u64>,
    /// On exit, write the last frame as rendered (without the overlay) to this PNG.
    #[arg(long)]
    pub screenshot: Option<PathBuf>,
    /// on (FIFO) or off (MAILBOX / IMMEDIATE).
    #[arg(long, value_enum, default_value = "on")]
    pub vsync: Vsync,
    /// shaded, volumes (coloured by case) or stencil (heat map of light 0); `V` cycles.
    #[arg(long, value_enum, default_value = "shaded")]
    pub view: View,
    /// On exit, write the viewer's state and the last frame's stats as JSON.
    #[arg(long)]
    pub stats: Option<PathBuf>,
    /// Scene time at the first frame, seconds.
    #[arg(long, default_value_t = 0.0)]
    pub time: f64,
    /// Advance the scene by this many seconds a frame instead of by the wall clock.
    #[arg(long)]
    pub time_step: Option<f64>,
    /// Start with the overlay hidden (`H` toggles it).
    #[arg(long)]
    pub hide_overlay: bool,
    /// Where `P` / `F12` screenshots go (umbrage-view-NNN.png).
    #[arg(long, default_value = ".")]
    pub shot_dir: PathBuf,
}

/// The message for a machine without a display.
pub const NO_DISPLAY: &str =
    "no display: neither DISPLAY nor WAYLAND_DISPLAY is set, so `umbrage view` cannot open a window; use `umbrage render` for headless rendering";

/// Whether a display is named in the environment.
pub fn display_available() -> bool {
    let set = |k: &str| std::env::var_os(k).map(|v| !v.is_empty()).unwrap_or(false);
    set("DISPLAY") || set("WAYLAND_DISPLAY")
}

/// Runs the viewer on scene `spec` with the frame options `opts` (size = the window's
/// initial inner size) until Esc, a close, or `--frames`.
pub fn run(spec: &str, opts: RenderOptions, args: &ViewArgs) -> Result<ExitCode> {
    if !display_available() {
        return Err(Error::Unsupported(NO_DISPLAY.into()));
    }
    if !args.time.is_finite() || args.time_step.map(|s| !s.is_finite() || s < 0.0).unwrap_or(false) {
        return Err(Error::input("--time", "--time must be finite and --time-step finite and >= 0"));
    }
    let (scene, motion) = umbrage_scene::load_animated(spec)?;
    app::run(scene, motion, opts, args)?;
    Ok(ExitCode::SUCCESS)
}
