//! The environment browser: the library's built-ins, folders and recent files, each shown as
//! its lat-long beside a chrome and a grey ball lit by it. A click makes it the look's
//! environment; ← and → step through the same list.

use super::super::action::Action;
use super::super::environments::EnvironmentLibrary;
use super::super::session::Session;
use super::super::thumbnails::{self, Thumbnails};
use super::Message;
use crate::environment::library::{Entry, Listing, Section};
use crate::environment::{Builtin, EnvironmentRef};
use egui::RichText;
use std::collections::HashMap;
use std::path::PathBuf;
use std::time::Instant;

#[derive(Default)]
pub struct Browser {
    pub open: bool,
    /// The folder field.
    folder: String,
    /// Read when the browser opens or the library changes.
    listing: Option<Listing>,
    /// Thumbnail textures, and the problems of maps whose thumbnail cannot be made.
    textures: HashMap<EnvironmentRef, std::result::Result<egui::TextureHandle, String>>,
}

impl Browser {
    /// The library changed (a folder added, a file opened): list it again.
    pub fn refresh(&mut self) {
        self.listing = None;
    }

    /// Shows the window while it is open; true when its Browse… asks for the folder dialog.
    pub fn show(
        &mut self,
        ctx: &egui::Context,
        session: &Session,
        library: &EnvironmentLibrary,
        thumbnails: &mut Thumbnails,
        actions: &mut Vec<Action>,
        message: &mut Option<Message>,
    ) -> bool {
        if !self.open {
            return false;
        }
        let mut browse = false;
        let listing = self.listing.get_or_insert_with(|| library.listing());
        let current = EnvironmentRef::or_default(session.document.settings().environment.as_ref());
        let mut open = self.open;
        super::close_on_escape(ctx, &mut open);
        let mut refresh = false;
        egui::Window::new("Environments")
            .open(&mut open)
            .default_size([560.0, 560.0])
            .default_pos([380.0, 80.0])
            .resizable(true)
            .show(ctx, |ui| {
                ui.horizontal(|ui| {
                    ui.add(egui::TextEdit::singleline(&mut self.folder).hint_text("a folder of .exr/.hdr maps"));
                    if ui.button("Add folder").clicked() && !self.folder.trim().is_empty() {
                        actions.push(Action::AddEnvironmentFolder(PathBuf::from(self.folder.trim())));
                        self.folder.clear();
                    }
                    browse = ui.button("Browse…").clicked();
                    refresh = ui.button("⟳").on_hover_text("Read the folders again").clicked();
                });
                ui.label(
                    RichText::new(
                        "Click to light the look with it; the Left and Right arrow keys step through the list.",
                    )
                    .weak(),
                );
                for problem in &listing.problems {
                    ui.colored_label(ui.visuals().warn_fg_color, problem);
                }
                ui.separator();
                // One new thumbnail per frame, so the interface stays live while they render.
                let mut may_render = true;
                egui::ScrollArea::vertical().auto_shrink([false, false]).show(ui, |ui| {
                    let mut heading = None;
                    for entry in &listing.entries {
                        let title = section_title(&entry.section);
                        if heading.as_ref() != Some(&title) {
                            ui.add_space(4.0);
                            ui.horizontal(|ui| {
                                ui.strong(&title);
                                if let Section::Folder(folder) = &entry.section {
                                    if ui
                                        .small_button("✕")
                                        .on_hover_text("Take this folder out of the library")
                                        .clicked()
                                    {
                                        actions.push(Action::RemoveEnvironmentFolder(folder.clone()));
                                    }
                                }
                            });
                            heading = Some(title);
                        }
                        let texture =
                            texture(ctx, &mut self.textures, thumbnails, &entry.reference, &mut may_render, message);
                        if row(ui, entry, texture, entry.reference == current) {
                            actions.push(Action::OpenEnvironment(Some(entry.reference.clone())));
                        }
                    }
                });
                if !may_render {
                    ctx.request_repaint();
                }
            });
        self.open = open;
        if refresh {
            self.refresh();
        }
        browse
    }
}

fn section_title(section: &Section) -> String {
    match section {
        Section::Builtin => "Built-in".to_string(),
        Section::Folder(folder) => folder.display().to_string(),
        Section::Recent => "Recent files".to_string(),
    }
}

/// An environment's thumbnail texture (`Err`: why there is none), once the cache has it.
fn texture(
    ctx: &egui::Context,
    textures: &mut HashMap<EnvironmentRef, std::result::Result<egui::TextureHandle, String>>,
    thumbnails: &mut Thumbnails,
    reference: &EnvironmentRef,
    may_render: &mut bool,
    message: &mut Option<Message>,
) -> Option<std::result::Result<egui::TextureId, String>> {
    if let Some(made) = textures.get(reference) {
        return Some(made.as_ref().map(|t| t.id()).map_err(Clone::clone));
    }
    let made = match thumbnails.environment(reference, may_render) {
        Ok(Some(image)) => {
            let size = [image.width() as usize, image.height() as usize];
            let pixels = egui::ColorImage::from_rgba_unmultiplied(size, image.as_raw());
            Ok(ctx.load_texture(reference.to_string(), pixels, egui::TextureOptions::LINEAR))
        }
        Ok(None) => return None,
        Err(e) => {
            *message = Some(Message { text: format!("thumbnail: {e}"), error: true, since: Instant::now() });
            Err(e.to_string())
        }
    };
    let id = made.as_ref().map(|t| t.id()).map_err(Clone::clone);
    textures.insert(reference.clone(), made);
    Some(id)
}

/// One environment's row; true when clicked.
fn row(
    ui: &mut egui::Ui,
    entry: &Entry,
    texture: Option<std::result::Result<egui::TextureId, String>>,
    current: bool,
) -> bool {
    let (w, h) = thumbnails::ENVIRONMENT_SIZE;
    let size = egui::vec2(w as f32, h as f32);
    let response = ui
        .horizontal(|ui| {
            match &texture {
                Some(Ok(id)) => {
                    ui.add(egui::Image::new((*id, size)));
                }
                _ => {
                    let (rect, _) = ui.allocate_exact_size(size, egui::Sense::hover());
                    ui.painter().rect_filled(rect, 4.0, egui::Color32::from_gray(40));
                    if texture.is_none() {
                        ui.put(rect, egui::Spinner::new());
                    }
                }
            }
            ui.vertical(|ui| {
                let mut name = RichText::new(entry.reference.label());
                if current {
                    name = name.strong().color(ui.visuals().selection.stroke.color);
                }
                ui.label(name);
                let detail = match (&texture, &entry.reference) {
                    (Some(Err(problem)), _) => RichText::new(problem).color(ui.visuals().error_fg_color),
                    (_, EnvironmentRef::Builtin(name)) => {
                        RichText::new(Builtin::find(name).map_or("", |b| b.description)).weak()
                    }
                    (_, EnvironmentRef::File(path)) => RichText::new(path.display().to_string()).weak(),
                };
                ui.label(detail.small());
            });
        })
        .response
        .interact(egui::Sense::click());
    response.clicked() && !matches!(texture, Some(Err(_)))
}
