//! Everything the artist can do in the viewer, as data. The panels produce actions and the
//! script reads them from a file; both are carried out by the same code, so a scripted test
//! drives the real interface.

use crate::environment::EnvironmentRef;
use crate::viewer_state::{Edit, Selection};
use std::path::PathBuf;

/// One thing the artist did.
#[derive(Clone, Debug, PartialEq)]
pub enum Action {
    /// A change to the document, its own undo step.
    Edit(Edit),
    /// A change made while dragging a continuous control: it joins the drag's undo step.
    Drag(Edit),
    /// The drag is over; the next change starts a new undo step.
    EndGesture,
    Undo,
    Redo,
    Select(Selection),
    /// Adds a layer of the named preset on top of the selected stack and selects it.
    AddPresetLayer(String),
    /// Sets the mask of the selected layer, after checking that the g-buffer has it.
    SetMask(Option<String>),
    /// Makes the selected object (the default stack when none is) catch shadows, or not.
    SetShadowCatcher(bool),
    /// Binds a parameter of the selected layer to a g-buffer map (`None`: unbinds it), after
    /// checking that the g-buffer has the map and that it fits the parameter.
    SetMap {
        param: crate::material::Param,
        map: Option<String>,
    },
    /// A click on image pixel (x, y): select the object there and inspect the pixel.
    Pick {
        x: u32,
        y: u32,
    },
    /// Prints what the inspector shows now (a script's `inspect`), which follows edits, undo
    /// and accumulation.
    ShowInspection,
    /// Loads an environment (`None`: the default built-in) and makes it the look's.
    OpenEnvironment(Option<EnvironmentRef>),
    /// Opens another look (asks first when there are unsaved edits).
    OpenLook(PathBuf),
    /// Saves the look, to its own file when `None`.
    SaveLook(Option<PathBuf>),
    /// Saves the selected layer to the user library.
    SaveLayerAsPreset {
        name: String,
        description: String,
        tags: Vec<String>,
        force: bool,
    },
    /// Saves the current render, as `lookdev render` would: PNG display pixels or EXR radiance.
    SaveImage(PathBuf),
    /// Saves the window's contents as a PNG.
    Screenshot(PathBuf),
    /// Closes the viewer (asks first when there are unsaved edits).
    Quit,
    /// The answer to the unsaved-edits question.
    Answer(Answer),
    /// Starts, changes or ends the A/B split.
    Compare(Compare),
    /// Moves the split's divider: a fraction of the image's width, from the left.
    Divider(f32),
    /// A key press, as if typed on the keyboard (a script's `key`): reaches the interface's
    /// shortcuts in the next frame, so a scripted test drives the real hotkeys.
    Key(egui::Key, egui::Modifiers),
    /// Sets the zoom: `None` fits the image to the view, else window pixels per image pixel.
    Zoom(Option<f32>),
    /// Shows another view instead of the beauty (or the beauty again).
    View(super::views::ViewChoice),
    /// Turns the clipping overlay on or off (`None`: toggles it).
    Clipping(Option<bool>),
    /// Prints the current view's values at image pixel (x, y) (a script's `probe`).
    Probe {
        x: u32,
        y: u32,
    },
    /// Snapshots the image with its look (`None`: the next `snapshot-N` name).
    Snapshot(Option<String>),
    /// Restores a snapshot's look and settings, as one undoable edit.
    RestoreSnapshot(String),
    /// Deletes a snapshot and its files.
    DeleteSnapshot(String),
    /// Shows the display filter (denoise) or not: what is shown only, never what is saved.
    Denoise(bool),
    /// Relights with the g-buffer's visibility or without it, for comparison.
    Visibility(bool),
    /// Steps this many environments through the library (←/→, a script's `env next|prev`): an
    /// undoable change of the look's environment, as `OpenEnvironment` makes.
    StepEnvironment(i32),
    /// Adds a folder of `.exr`/`.hdr` environments to the library (kept in the config file).
    AddEnvironmentFolder(PathBuf),
    /// Takes a folder out of the library.
    RemoveEnvironmentFolder(PathBuf),
    /// Opens the environment browser (a script's `environments`).
    ShowEnvironments,
    /// Shows the selected layer alone in its stack, or ends the solo (Painter's Alt+click on
    /// the eye): a way of looking, not an edit.
    Solo(bool),
    /// Tints the image where the selected layer shows, or stops (`None`: toggles it).
    MaskOverlay(Option<bool>),
}

/// What to show as B, beside the edited look (A).
#[derive(Clone, Debug, PartialEq)]
pub enum Compare {
    /// A's look under A's model with these `KEY=VALUE` changes (the keys of `--model`).
    Model(Vec<String>),
    /// Another look file.
    Look(PathBuf),
    /// Swap A and B.
    Swap,
    /// Back to the plain image.
    Off,
    /// A snapshot, shown as a split, side by side, or as a ΔE heat map.
    Snapshot(String, super::compare::SnapshotView),
}

/// What to do with unsaved edits before they would be lost.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Answer {
    /// Save the look, then go on.
    Save,
    /// Drop the edits and go on.
    Discard,
    /// Stay, edits kept.
    Cancel,
}
