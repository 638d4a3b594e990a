//! The viewer's panels. They read the session and emit [`Action`]s; nothing here changes the
//! document directly, so the panels and `--script` share one path.
//!
//! Layout: a menu bar, a status bar, the layer stacks on the left, light, render settings and
//! the pixel inspector on the right, the preset library (when open) docked beside the layer
//! stacks, the image in the middle with the strip of recent snapshots under it, and windows for
//! file choosing, saving a preset and the unsaved-edits question.

mod browser;
mod compare;
mod dialogs;
mod environments;
pub mod hotkeys;
mod inspector;
mod layers;
mod lighting;
mod snapshots;
mod strip;
mod viewport;
mod views;

pub use dialogs::{FileDialog, FilePurpose};
pub use viewport::{ImagePlacement, MAX_SCALE, MIN_SCALE};

use super::action::Action;
use super::session::Session;
use super::thumbnails::Thumbnails;
use super::view_image::Views;
use egui::{Key, KeyboardShortcut, Modifiers};
use std::time::{Duration, Instant};

/// What the display filter is, where it is offered and marked.
const DENOISE_HINT: &str = "Shows the accumulation through an edge-avoiding filter guided by the g-buffer's normals, \
    base colours and object ids. Only the view: saved images are never filtered.";

/// What switching the visibility off does, where it is offered and marked.
const VISIBILITY_HINT: &str = "Relights with the g-buffer's visibility (shadows and occlusion), or, off, as if every \
    direction above each pixel's horizon saw the sky, for comparison. Not saved with the look.";

/// What the flip key (B) says when there is no other image.
const NOTHING_TO_FLIP: &str = "Nothing to flip to: take a snapshot (P) or compare";

/// The side panels' widths when first shown; the artist may resize them.
const STACK_WIDTH: f32 = 400.0;
const LIGHT_WIDTH: f32 = 300.0;

/// How long a status message stays.
const MESSAGE_TIME: Duration = Duration::from_secs(8);

/// A line in the status bar: what just happened, or what went wrong.
pub struct Message {
    pub text: String,
    pub error: bool,
    pub since: Instant,
}

/// Why the unsaved-edits question is being asked.
#[derive(Clone, Debug, PartialEq)]
pub enum Pending {
    Quit,
    Open(std::path::PathBuf),
}

/// Timings the status bar shows.
#[derive(Clone, Copy, Debug, Default)]
pub struct FrameFigures {
    /// Mean frame time over the last second or so.
    pub frame: Duration,
}

/// What the panels show that is not in the session.
pub struct Frame<'a> {
    pub session: &'a Session,
    pub view_texture: egui::TextureId,
    /// B's rendered view, while comparing.
    pub compare_texture: Option<egui::TextureId>,
    pub pending: Option<&'a Pending>,
    pub figures: FrameFigures,
    /// The view shown instead of the beauty, its copy and textures.
    pub views: &'a Views,
    /// The mask overlay's texture, while it is on.
    pub mask_overlay: Option<egui::TextureId>,
    /// The environment library, for its browser.
    pub environments: &'a super::environments::EnvironmentLibrary,
}

/// The interface's own state: view, open windows, what is being typed.
#[derive(Default)]
pub struct Interface {
    pub viewport: viewport::Viewport,
    browser: browser::Browser,
    pub file_dialog: Option<FileDialog>,
    save_preset: Option<dialogs::SavePresetForm>,
    pub message: Option<Message>,
    /// Where the image was drawn last frame, in window pixels.
    pub placement: Option<ImagePlacement>,
    /// The hotkey sheet is open.
    pub hotkeys: bool,
    /// The side panels are hidden (H), so that the image has the window's width.
    panels_hidden: bool,
    snapshots: snapshots::Panel,
    environments: environments::Browser,
}

impl Interface {
    /// The interface with the image at `zoom` (`None`: fitted).
    pub fn with_zoom(zoom: Option<f32>) -> Interface {
        let mut interface = Interface::default();
        interface.viewport.zoom_to(zoom);
        interface
    }

    /// Which image is on screen, as the status bar says it: "showing snapshot NAME", "showing
    /// live", "showing A | B", …
    pub fn showing(&self, session: &Session) -> Option<String> {
        self.snapshots.showing(session)
    }

    /// Shows a message in the status bar.
    pub fn tell(&mut self, text: impl Into<String>, error: bool) {
        self.message = Some(Message { text: text.into(), error, since: Instant::now() });
    }

    /// The library browser's list is stale (a preset was saved).
    pub fn refresh_library(&mut self) {
        self.browser.refresh();
    }

    /// The environment browser's list is stale (a folder added, a file opened).
    pub fn refresh_environments(&mut self) {
        self.environments.refresh();
    }

    pub fn show_environments(&mut self) {
        self.environments.open = true;
    }

    /// Lays out and runs one frame of the interface.
    pub fn show(&mut self, ui: &mut egui::Ui, frame: &Frame, thumbnails: &mut Thumbnails, actions: &mut Vec<Action>) {
        self.shortcuts(ui.ctx(), frame, actions);
        self.snapshots.prepare(ui.ctx(), frame.session);
        egui::Panel::top("menu").show(ui, |ui| self.menu(ui, frame, actions));
        egui::Panel::bottom("status").show(ui, |ui| self.status(ui, frame));
        if !self.panels_hidden {
            self.side_panels(ui, frame, thumbnails, actions);
            self.snapshots.strip(ui, frame.session, actions);
        }
        // A view other than the beauty shows in A's place (B, in a split, keeps its beauty); a
        // snapshot compared is B; the flip (B) shows the other image alone.
        let a = frame.views.texture().unwrap_or(frame.view_texture);
        let drawn = self.snapshots.drawn(frame.session, a, frame.compare_texture);
        egui::CentralPanel::no_frame().show(ui, |ui| {
            let placement = self.viewport.show(ui, frame.session, drawn.a, drawn.b, drawn.snapshot.as_ref(), actions);
            self.placement = Some(placement);
            match &drawn.flipped {
                Some(label) => snapshots::flip_plate(ui, label, self.viewport.image_rect),
                None => views::decorate(ui, frame.session, frame.views, frame.mask_overlay, self.viewport.image_rect),
            }
        });
        let ctx = ui.ctx().clone();
        let library = frame.environments;
        if self.environments.show(&ctx, frame.session, library, thumbnails, actions, &mut self.message) {
            self.file_dialog = Some(FileDialog::new(FilePurpose::AddEnvironmentFolder));
        }
        if let Some(form) = &mut self.save_preset {
            if !form.show(&ctx, actions) {
                self.save_preset = None;
            }
        }
        if let Some(dialog) = &mut self.file_dialog {
            if !dialog.show(&ctx, actions) {
                self.file_dialog = None;
            }
        }
        if let Some(pending) = frame.pending {
            dialogs::unsaved_question(&ctx, frame.session, pending, actions);
        }
        hotkeys::show(&ctx, &mut self.hotkeys);
        // A drag of any control ends when the pointer is let go: the next change is a new step.
        if ui.input(|i| i.pointer.any_released()) {
            actions.push(Action::EndGesture);
        }
    }

    /// The layer stack on the left; lighting, comparison, inspector, histogram and snapshots on
    /// the right; the preset library, when open, beside the layer stack, in what they leave.
    fn side_panels(
        &mut self,
        ui: &mut egui::Ui,
        frame: &Frame,
        thumbnails: &mut Thumbnails,
        actions: &mut Vec<Action>,
    ) {
        // Each side panel scrolls what does not fit, both ways, rather than growing with its
        // content: a wide value must not move the image.
        let scrolled = || egui::ScrollArea::both().auto_shrink([false, false]);
        let stack = egui::Panel::left("stack").default_size(STACK_WIDTH).show(ui, |ui| {
            scrolled().show(ui, |ui| {
                let open_browser = layers::show(ui, frame.session, actions);
                if open_browser {
                    self.browser.open = true;
                }
            })
        });
        // A preset dropped on the panel but not between two layers goes on top.
        if let Some(preset) = browser::dropped_preset(&stack.response) {
            actions.push(Action::AddPresetLayer(preset));
        }
        egui::Panel::right("light").default_size(LIGHT_WIDTH).show(ui, |ui| {
            scrolled().show(ui, |ui| {
                lighting::show(ui, frame.session, &mut self.file_dialog, &mut self.environments.open, actions);
                ui.separator();
                compare::show(ui, frame.session, &mut self.file_dialog, actions);
                ui.separator();
                inspector::show(ui, frame.session);
                ui.separator();
                views::histogram(ui, frame.views);
                ui.separator();
                self.snapshots.show(ui, frame.session, actions);
            })
        });
        self.browser.show(ui, frame.session, thumbnails, actions, &mut self.message);
    }

    fn shortcuts(&mut self, ctx: &egui::Context, frame: &Frame, actions: &mut Vec<Action>) {
        if ctx.egui_wants_keyboard_input() {
            return; // typing in a field: its own undo and keys
        }
        let redo = [
            KeyboardShortcut::new(Modifiers::COMMAND | Modifiers::SHIFT, Key::Z),
            KeyboardShortcut::new(Modifiers::COMMAND, Key::Y),
        ];
        ctx.input_mut(|input| {
            if redo.iter().any(|s| input.consume_shortcut(s)) {
                actions.push(Action::Redo);
            } else if input.consume_shortcut(&KeyboardShortcut::new(Modifiers::COMMAND, Key::Z)) {
                actions.push(Action::Undo);
            }
            if input.consume_shortcut(&KeyboardShortcut::new(Modifiers::COMMAND, Key::S)) {
                match frame.session.document.path() {
                    Some(_) => actions.push(Action::SaveLook(None)),
                    None => self.file_dialog = Some(FileDialog::new(FilePurpose::SaveLook)),
                }
            }
            if input.consume_shortcut(&KeyboardShortcut::new(Modifiers::COMMAND, Key::Q)) {
                actions.push(Action::Quit);
            }
            if input.consume_key(Modifiers::NONE, Key::F) {
                self.viewport.fit();
            }
            if input.consume_key(Modifiers::NONE, Key::Num1) {
                self.viewport.actual_pixels();
            }
            if input.consume_key(Modifiers::NONE, Key::Questionmark) {
                self.hotkeys = !self.hotkeys;
            }
            // Photoshop and Substance Painter hide their panels with Tab, which egui keeps for
            // moving the focus between fields: H, for hide.
            if input.consume_key(Modifiers::NONE, Key::H) {
                self.panels_hidden = !self.panels_hidden;
            }
            views::shortcuts(input, actions);
            if layers::shortcuts(input, frame.session, actions) {
                self.browser.open = true;
            }
            if input.consume_key(Modifiers::NONE, Key::P) {
                actions.push(Action::Snapshot(None));
            }
            // B, for the B image: RenderView-style flipping between two images in place.
            if input.consume_key(Modifiers::NONE, Key::B) && !self.snapshots.flip(frame.session) {
                self.message = Some(Message { text: NOTHING_TO_FLIP.into(), error: false, since: Instant::now() });
            }
            if input.consume_key(Modifiers::NONE, Key::D) {
                actions.push(Action::Denoise(!frame.session.denoise));
            }
            if frame.session.has_visibility() && input.consume_key(Modifiers::NONE, Key::O) {
                actions.push(Action::Visibility(!frame.session.visibility));
            }
            // As in Unity's Look Dev: the arrows step through the environment library.
            if input.consume_key(Modifiers::NONE, Key::ArrowLeft) {
                actions.push(Action::StepEnvironment(-1));
            }
            if input.consume_key(Modifiers::NONE, Key::ArrowRight) {
                actions.push(Action::StepEnvironment(1));
            }
        });
    }

    fn menu(&mut self, ui: &mut egui::Ui, frame: &Frame, actions: &mut Vec<Action>) {
        let document = &frame.session.document;
        egui::MenuBar::new().ui(ui, |ui| {
            ui.menu_button("File", |ui| {
                if ui.button("Open look…").clicked() {
                    self.file_dialog = Some(FileDialog::new(FilePurpose::OpenLook));
                }
                if ui
                    .add_enabled(document.path().is_some(), egui::Button::new("Save look").shortcut_text("Ctrl+S"))
                    .clicked()
                {
                    actions.push(Action::SaveLook(None));
                }
                if ui.button("Save look as…").clicked() {
                    self.file_dialog = Some(FileDialog::new(FilePurpose::SaveLook));
                }
                ui.separator();
                let layer_selected = document.selection().layer.is_some();
                if ui.add_enabled(layer_selected, egui::Button::new("Save layer as preset…")).clicked() {
                    self.save_preset = Some(dialogs::SavePresetForm::default());
                }
                if ui.button("Save image…").clicked() {
                    self.file_dialog = Some(FileDialog::new(FilePurpose::SaveImage));
                }
                ui.separator();
                if ui.button("Open environment…").clicked() {
                    self.file_dialog = Some(FileDialog::new(FilePurpose::OpenEnvironment));
                }
                if ui
                    .button("Environments…")
                    .on_hover_text("The environment library (the Left and Right arrow keys step through it)")
                    .clicked()
                {
                    self.environments.open = true;
                }
                ui.separator();
                if ui.add(egui::Button::new("Quit").shortcut_text("Ctrl+Q")).clicked() {
                    actions.push(Action::Quit);
                }
            });
            ui.menu_button("Edit", |ui| {
                if ui.add_enabled(document.can_undo(), egui::Button::new("Undo").shortcut_text("Ctrl+Z")).clicked() {
                    actions.push(Action::Undo);
                }
                let redo = egui::Button::new("Redo").shortcut_text("Ctrl+Shift+Z");
                if ui.add_enabled(document.can_redo(), redo).clicked() {
                    actions.push(Action::Redo);
                }
                ui.separator();
                if ui.button("Add layer from library…").clicked() {
                    self.browser.open = true;
                }
                ui.separator();
                let has_file = document.path().is_some();
                let snapshot = egui::Button::new("Take snapshot").shortcut_text("P");
                if ui.add_enabled(has_file, snapshot).on_disabled_hover_text("Save the look first").clicked() {
                    actions.push(Action::Snapshot(None));
                }
            });
            ui.menu_button("View", |ui| {
                if ui.add(egui::Button::new("Fit").shortcut_text("F")).clicked() {
                    self.viewport.fit();
                }
                if ui.add(egui::Button::new("Actual pixels (1:1)").shortcut_text("1")).clicked() {
                    self.viewport.actual_pixels();
                }
                let hide = egui::Button::selectable(self.panels_hidden, "Hide side panels").shortcut_text("H");
                if ui.add(hide).clicked() {
                    self.panels_hidden = !self.panels_hidden;
                }
                let strip = egui::Button::selectable(!self.snapshots.strip_hidden, "Snapshot strip");
                if ui.add(strip).on_hover_text("Recent snapshots under the image: a click compares one").clicked() {
                    self.snapshots.strip_hidden = !self.snapshots.strip_hidden;
                }
                let flip = egui::Button::new("Flip to the other image").shortcut_text("B");
                let can_flip = self.snapshots.can_flip(frame.session);
                if ui.add_enabled(can_flip, flip).on_disabled_hover_text(NOTHING_TO_FLIP).clicked() {
                    self.snapshots.flip(frame.session);
                }
                ui.separator();
                let denoise =
                    egui::Button::selectable(frame.session.denoise, "Denoise (display filter)").shortcut_text("D");
                if ui.add(denoise).on_hover_text(DENOISE_HINT).clicked() {
                    actions.push(Action::Denoise(!frame.session.denoise));
                }
                let visibility =
                    egui::Button::selectable(frame.session.visibility, "Shadows (visibility)").shortcut_text("O");
                let visibility = ui
                    .add_enabled(frame.session.has_visibility(), visibility)
                    .on_hover_text(VISIBILITY_HINT)
                    .on_disabled_hover_text("The g-buffer has no visibility");
                if visibility.clicked() {
                    actions.push(Action::Visibility(!frame.session.visibility));
                }
                ui.separator();
                views::menu(ui, frame.session, frame.views, actions);
            });
            ui.menu_button("Help", |ui| {
                if ui.add(egui::Button::new("Hotkeys").shortcut_text("?")).clicked() {
                    self.hotkeys = true;
                }
            });
            ui.with_layout(egui::Layout::right_to_left(egui::Align::Center), |ui| {
                let name = document.path().map_or("untitled look".to_string(), |p| p.display().to_string());
                if document.is_dirty() {
                    ui.label(egui::RichText::new("● unsaved edits").color(ui.visuals().warn_fg_color))
                        .on_hover_text("The look has changes that are not saved");
                }
                ui.label(name);
            });
        });
    }

    fn status(&mut self, ui: &mut egui::Ui, frame: &Frame) {
        let session = frame.session;
        ui.horizontal(|ui| {
            let (samples, target) = (session.samples(), session.target());
            let state = if session.converged() { "done" } else { "rendering" };
            ui.label(format!("{samples} / {target} spp ({state})"));
            if let Some(showing) = self.snapshots.showing(session) {
                ui.separator();
                ui.label(egui::RichText::new(showing).strong())
                    .on_hover_text("B flips between this and the other image, in place");
            }
            if let Some((active, noise)) = session.adaptive() {
                ui.separator();
                ui.label(format!("adaptive {}: {} px sampling", noise.threshold, grouped(active as usize)))
                    .on_hover_text(ADAPTIVE_HINT);
            }
            if let Some(region) = session.restarted_region() {
                ui.separator();
                ui.label(region_status(region)).on_hover_text(REGION_HINT);
            }
            ui.separator();
            let rate = session.progressive.samples_per_second_with(session.compare_progressive());
            ui.label(format!("{:.1} M samples/s", rate / 1e6));
            ui.separator();
            ui.label(format!("frame {:.1} ms", frame.figures.frame.as_secs_f64() * 1e3));
            if let Some(first) = session.first_pass_after_change {
                ui.separator();
                ui.label(format!("first pass {:.0} ms", first.as_secs_f64() * 1e3))
                    .on_hover_text("Time from the last change to a first full pass over the image");
            }
            if let Some((preview, block)) = session.progressive.preview {
                ui.separator();
                ui.label(format!("preview {:.0} ms", preview.as_secs_f64() * 1e3)).on_hover_text(format!(
                    "Time from the last change to a whole frame at the new state, one sample per {block}×{block} block"
                ));
            }
            if !session.visibility {
                ui.separator();
                ui.label(egui::RichText::new("no shadows · comparison").color(ui.visuals().warn_fg_color))
                    .on_hover_text(VISIBILITY_HINT);
            }
            if session.denoise {
                ui.separator();
                ui.label(egui::RichText::new("denoised · display filter").color(ui.visuals().warn_fg_color))
                    .on_hover_text(DENOISE_HINT);
            }
            ui.separator();
            ui.label(format!("{}×{} · {}", session.width(), session.height(), session.device_name()));
            ui.separator();
            ui.label(views::status(frame.views, self.viewport.hovered));
            if let Some(message) = &self.message {
                if message.since.elapsed() < MESSAGE_TIME || message.error {
                    ui.separator();
                    let color = if message.error { ui.visuals().error_fg_color } else { ui.visuals().text_color() };
                    ui.label(egui::RichText::new(&message.text).color(color));
                }
            }
        });
    }
}

/// What the status bar says while the pixels an edit restarted catch up with the rest:
/// "re-converging 12 345 px: 5/64 spp".
pub fn region_status((pixels, theirs, rest): (usize, u32, u32)) -> String {
    format!("re-converging {} px: {theirs}/{rest} spp", grouped(pixels))
}

/// A count with its digits in groups of three: "12 345".
fn grouped(n: usize) -> String {
    let digits = n.to_string();
    let mut out = String::new();
    for (i, c) in digits.chars().enumerate() {
        if i > 0 && (digits.len() - i) % 3 == 0 {
            out.push(' ');
        }
        out.push(c);
    }
    out
}

const ADAPTIVE_HINT: &str = "--noise-threshold: each pixel stops once the estimated relative error of its mean \
     luminance is below the threshold; accumulation stops when every pixel has, or at the target spp";

const REGION_HINT: &str = "The edit changed the material of these pixels only: they start again and catch up with \
     the rest, which keep their samples";

/// Every piece of text in a drawn shape, for tests that draw a panel in a headless egui context.
#[cfg(test)]
fn shape_texts(shape: &egui::Shape, out: &mut Vec<String>) {
    match shape {
        egui::Shape::Text(text) => out.push(text.galley.text().to_string()),
        egui::Shape::Vec(shapes) => shapes.iter().for_each(|s| shape_texts(s, out)),
        _ => {}
    }
}

#[cfg(test)]
mod region_tests {
    #[test]
    fn the_restarted_region_reads_with_grouped_digits() {
        assert_eq!(super::region_status((12345, 5, 64)), "re-converging 12 345 px: 5/64 spp");
        assert_eq!(super::region_status((999, 0, 16)), "re-converging 999 px: 0/16 spp");
        assert_eq!(super::region_status((1_048_576, 1, 4)), "re-converging 1 048 576 px: 1/4 spp");
    }
}

/// Closes a window on Escape, as every dialog does: `open` becomes false when Escape was
/// pressed this frame (by a person or a script's `key Escape`).
pub fn close_on_escape(ctx: &egui::Context, open: &mut bool) {
    if *open && ctx.input(|i| i.key_pressed(egui::Key::Escape)) {
        *open = false;
    }
}

#[cfg(test)]
mod escape_tests {
    use super::close_on_escape;

    fn frame_with(ctx: &egui::Context, events: Vec<egui::Event>, open: &mut bool) {
        let input = egui::RawInput { events, ..Default::default() };
        let _ = ctx.run_ui(input, |ui| close_on_escape(ui.ctx(), open));
    }

    /// The preset library and the environments window close on Escape, and only on it: they
    /// once stayed open, by a real key and by a script's.
    #[test]
    fn escape_closes_a_window_and_other_keys_do_not() {
        let ctx = egui::Context::default();
        let key = |key: egui::Key| egui::Event::Key {
            key,
            physical_key: None,
            pressed: true,
            repeat: false,
            modifiers: egui::Modifiers::NONE,
        };
        let mut open = true;
        frame_with(&ctx, vec![key(egui::Key::A)], &mut open);
        assert!(open, "another key leaves it open");
        frame_with(&ctx, Vec::new(), &mut open);
        assert!(open);
        frame_with(&ctx, vec![key(egui::Key::Escape)], &mut open);
        assert!(!open, "Escape closes it");
    }
}
