//! The interactive viewer, `lookdev view`: the artist edits layer stacks and turns the light
//! while the same kernels as `lookdev render` relight the g-buffer progressively.
//!
//! - [`session`] keeps the GPU renderer in step with the [`Document`](crate::viewer_state::Document)
//!   being edited, and answers pixel inspections.
//! - [`ui`] draws the panels and turns every click and drag into an [`Action`].
//! - [`script`] reads the same actions from a file, for tests and automation.
//! - [`app`] owns the window and runs a frame: script step, relight band, interface, present.
//! - [`schedule`] decides what each turn of the event loop does: draw, relight or wait.
//! - [`presenter`], [`gui`] and [`progressive`] are the plumbing under it.
//! - [`views`] and [`view_image`]: the views shown instead of the beauty (AOVs, false colour),
//!   and the current one's CPU copy for the histogram, clipping overlay and values under the
//!   cursor.

mod action;
mod app;
mod compare;
mod delta_e;
mod environments;
mod gui;
mod mask_overlay;
mod presenter;
mod progressive;
mod schedule;
mod script;
mod session;
mod snapshots;
pub mod thumbnails;
mod ui;
mod view_image;
pub mod views;

pub use action::Action;
pub use script::{zoom, Script, Step};

use crate::render::scene::SceneSpec;
use crate::{Error, Result};
use std::path::PathBuf;

/// What `lookdev view` was asked to open, and how.
#[derive(Clone, Debug, Default)]
pub struct ViewOptions {
    /// What opens: the look, the g-buffer, `--set` and the flags over the look's settings.
    pub scene: SceneSpec,
    pub device: Option<String>,
    /// The window's inner size in logical pixels.
    pub window_size: (u32, u32),
    /// The zoom the image opens at: `None` fits it to the view, else window pixels per image
    /// pixel.
    pub zoom: Option<f32>,
    /// Render to this many samples per pixel, save the window as a PNG and exit.
    pub screenshot: Option<PathBuf>,
    pub exit_after_spp: Option<u32>,
    pub script: Option<Script>,
    /// `--compare-model KEY=VALUE`: open with an A/B split, B being the look under A's model
    /// with these keys changed.
    pub compare_model: Vec<String>,
    /// `--compare-look FILE`: open with an A/B split, B being this look.
    pub compare_look: Option<PathBuf>,
}

/// The window's default inner size: room for both side panels and a 720p-tall view.
pub const DEFAULT_WINDOW_SIZE: (u32, u32) = (1600, 960);

/// Opens the viewer and runs it until the window closes (or the headless hooks finish).
pub fn run(options: ViewOptions) -> Result<()> {
    check_display()?;
    app::run(options)
}

/// A window needs a display server; say which, and how to get one, before winit tries.
fn check_display() -> Result<()> {
    let set = |name: &str| std::env::var_os(name).is_some_and(|v| !v.is_empty());
    if set("DISPLAY") || set("WAYLAND_DISPLAY") {
        Ok(())
    } else {
        Err(no_display("neither DISPLAY nor WAYLAND_DISPLAY is set"))
    }
}

/// The error for a display that cannot be opened, with what to do about it.
fn no_display(detail: impl std::fmt::Display) -> Error {
    Error::gpu(format!(
        "cannot open a window: {detail}. The viewer needs an X11 or Wayland display; on a machine \
         without one, run it under a virtual X server: `xvfb-run lookdev view ...` (apt-get install xvfb)"
    ))
}
