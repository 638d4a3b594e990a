//! The preset library browser: every preset the look can name, as thumbnails on the ball, with
//! search and a tag filter. Search lists name matches first, then tag matches, then presets
//! only the description matches, each with why it matched. A click adds the preset as a new layer on top of the selected stack.

use super::super::action::Action;
use super::super::session::Session;
use super::super::thumbnails::{self, Thumbnails};
use super::Message;
use crate::material::library::{self, MatchedBy, Origin};
use crate::material::Params;
use egui::RichText;
use std::collections::{BTreeSet, HashMap};
use std::time::Instant;

/// One preset as the browser lists it.
struct Entry {
    name: String,
    tags: Vec<String>,
    description: String,
    /// `None` when the file does not load; `problem` says why.
    params: Option<Params>,
    problem: Option<String>,
    user: bool,
}

#[derive(Default)]
pub struct Browser {
    pub open: bool,
    /// Whether the search field has had the focus since the library opened.
    focused: bool,
    search: String,
    tag: Option<String>,
    /// Read when the browser opens, and again after a preset is saved.
    entries: Option<Vec<Entry>>,
    /// Thumbnail textures by cache file name.
    textures: HashMap<String, egui::TextureHandle>,
}

impl Browser {
    pub fn refresh(&mut self) {
        self.entries = None;
    }

    pub fn show(
        &mut self,
        ctx: &egui::Context,
        session: &Session,
        thumbnails: &mut Thumbnails,
        actions: &mut Vec<Action>,
        message: &mut Option<Message>,
    ) {
        if !self.open {
            return;
        }
        let entries = self.entries.get_or_insert_with(|| {
            let library = session.document.library();
            library
                .entries()
                .into_iter()
                .map(|(name, origin, preset)| match preset {
                    Ok(p) => Entry {
                        name,
                        tags: p.tags,
                        description: p.description,
                        params: Some(p.params),
                        problem: None,
                        user: origin != Origin::Builtin,
                    },
                    Err(problem) => Entry {
                        name,
                        tags: Vec::new(),
                        description: String::new(),
                        params: None,
                        problem: Some(problem),
                        user: true,
                    },
                })
                .collect()
        });
        let mut open = self.open;
        super::close_on_escape(ctx, &mut open);
        let mut refresh = false;
        let target = session.document.selection().object.map_or("the default stack".to_string(), |o| o.to_string());
        let window = egui::Window::new("Preset library")
            .open(&mut open)
            .default_size([620.0, 560.0])
            .default_pos([360.0, 80.0])
            .resizable(true);
        window.show(ctx, |ui| {
            ui.horizontal(|ui| {
                let search =
                    ui.add(egui::TextEdit::singleline(&mut self.search).hint_text("search names, tags, descriptions"));
                // Typing starts a search as soon as the library opens.
                if !self.focused {
                    search.request_focus();
                    self.focused = true;
                }
                let tags: BTreeSet<&String> = entries.iter().flat_map(|e| &e.tags).collect();
                egui::ComboBox::from_id_salt("tag filter")
                    .selected_text(self.tag.clone().unwrap_or_else(|| "all tags".into()))
                    .show_ui(ui, |ui| {
                        if ui.selectable_label(self.tag.is_none(), "all tags").clicked() {
                            self.tag = None;
                        }
                        for tag in tags {
                            if ui.selectable_label(self.tag.as_ref() == Some(tag), tag).clicked() {
                                self.tag = Some(tag.clone());
                            }
                        }
                    });
                refresh = ui.button("⟳").on_hover_text("Read the library again").clicked();
            });
            ui.label(RichText::new(format!("Click a preset to add it as a layer on top of {target}.")).weak());
            ui.separator();
            // Best first: names, then tags, then descriptions, each saying why it matched.
            let tagged: Vec<&Entry> =
                entries.iter().filter(|e| self.tag.as_ref().is_none_or(|t| e.tags.contains(t))).collect();
            let shown: Vec<(&Entry, Option<MatchedBy>)> = if self.search.trim().is_empty() {
                tagged.into_iter().map(|e| (e, None)).collect()
            } else {
                library::search(&tagged, &self.search, |e| (&e.name, &e.tags, &e.description))
                    .into_iter()
                    .map(|(e, why)| (*e, Some(why)))
                    .collect()
            };
            // One new thumbnail per frame, so the interface stays live while they render.
            let mut may_render = true;
            egui::ScrollArea::vertical().auto_shrink([false, false]).show(ui, |ui| {
                // Rows of as many cells as fit: a wrapping layout would widen the window instead.
                let cell_width = thumbnails::SIZE as f32 + 8.0 + ui.spacing().item_spacing.x;
                let columns = ((ui.available_width() / cell_width) as usize).max(1);
                for row in shown.chunks(columns) {
                    ui.horizontal(|ui| {
                        for (entry, why) in row {
                            let texture = entry.params.as_ref().and_then(|params| {
                                texture(ctx, &mut self.textures, thumbnails, params, &mut may_render, message)
                            });
                            if cell(ui, entry, why.as_ref(), texture) {
                                actions.push(Action::AddPresetLayer(entry.name.clone()));
                            }
                        }
                    });
                }
            });
            if !may_render {
                ctx.request_repaint();
            }
        });
        self.open = open;
        // Opened again, the search field takes the focus again.
        self.focused &= open;
        if refresh {
            self.refresh();
        }
    }
}

/// A preset's thumbnail texture, made from the thumbnail cache when it has the picture.
fn texture(
    ctx: &egui::Context,
    textures: &mut HashMap<String, egui::TextureHandle>,
    thumbnails: &mut Thumbnails,
    params: &Params,
    may_render: &mut bool,
    message: &mut Option<Message>,
) -> Option<egui::TextureId> {
    let key = thumbnails::file_name(params);
    if let Some(texture) = textures.get(&key) {
        return Some(texture.id());
    }
    match thumbnails.get(params, may_render) {
        Ok(Some(image)) => {
            let size = [image.width() as usize, image.height() as usize];
            let pixels = egui::ColorImage::from_rgba_unmultiplied(size, image.as_raw());
            let handle = ctx.load_texture(&key, pixels, egui::TextureOptions::LINEAR);
            let id = handle.id();
            textures.insert(key, handle);
            Some(id)
        }
        Ok(None) => None,
        Err(e) => {
            *message = Some(Message { text: format!("thumbnail: {e}"), error: true, since: Instant::now() });
            None
        }
    }
}

/// One preset's cell; true when clicked.
fn cell(ui: &mut egui::Ui, entry: &Entry, why: Option<&MatchedBy>, texture: Option<egui::TextureId>) -> bool {
    let size = egui::vec2(thumbnails::SIZE as f32, thumbnails::SIZE as f32);
    let response = ui
        .vertical(|ui| {
            ui.set_width(size.x + 8.0);
            match texture {
                Some(id) => {
                    ui.add(egui::Image::new((id, size)));
                }
                None => {
                    let (rect, _) = ui.allocate_exact_size(size, egui::Sense::hover());
                    ui.painter().rect_filled(rect, 4.0, egui::Color32::from_gray(40));
                    if entry.params.is_some() {
                        ui.put(rect, egui::Spinner::new());
                    }
                }
            }
            let mut name = RichText::new(&entry.name).small();
            if entry.problem.is_some() {
                name = name.color(ui.visuals().error_fg_color);
            } else if entry.user {
                name = name.italics();
            }
            ui.label(name);
            if let Some(why) = why {
                ui.label(RichText::new(why.to_string()).small().weak());
            }
        })
        .response
        .interact(egui::Sense::click());
    let hover = match &entry.problem {
        Some(problem) => format!("Cannot be used: {problem}"),
        None => {
            let origin = if entry.user { "user library" } else { "built-in" };
            format!("{}\n\ntags: {}\n({origin})", entry.description, entry.tags.join(", "))
        }
    };
    let response = response.on_hover_text(hover);
    response.clicked() && entry.problem.is_none()
}
