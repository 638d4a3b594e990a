//! The preset library: every preset the look can name, as thumbnails on the ball, with search
//! and a tag filter. It docks as a panel beside the layer stack, between it and the image, so
//! that it never covers the image and a preset is a short drag from the stack.
//!
//! Search lists name matches first, then tag matches, then presets only the description
//! matches, then presets the query is a typo away from ([`library::search_match`]), each with
//! why it matched; when nothing matches, it says so and offers to clear the search or the tag
//! filter. A click adds the preset as a new layer on top of the selected stack; a preset dragged
//! onto the layer list goes where it is dropped ([`dropped_preset`]).

use super::super::action::Action;
use super::super::session::Session;
use super::super::thumbnails::{self, Thumbnails};
use super::Message;
use crate::material::library::{self, MatchedBy, Origin};
use crate::material::Params;
use egui::RichText;
use std::collections::{BTreeSet, HashMap};
use std::time::Instant;

/// A thumbnail cell's width: the picture and its margin; cells are `item_spacing.x` apart.
const CELL_WIDTH: f32 = thumbnails::SIZE as f32 + 8.0;
/// What the panel takes besides its cells: its margins and the scroll bar.
const PANEL_MARGINS: f32 = 36.0;
/// The width the library docks at: two columns of thumbnails (and egui's default spacing
/// between them), so that it leaves the image room.
const DEFAULT_WIDTH: f32 = 2.0 * CELL_WIDTH + 8.0 + PANEL_MARGINS;
/// The narrowest it can be made: one column.
const MIN_WIDTH: f32 = CELL_WIDTH + PANEL_MARGINS;
/// The image's width the library never takes, so that it stays usable beside the side panels
/// in a 1280×720 window.
const MIN_IMAGE_WIDTH: f32 = 320.0;

/// What a preset cell carries while it is dragged: the preset's name.
#[derive(Clone, Debug, PartialEq)]
pub struct DraggedPreset(pub String);

/// The preset dropped on `response` this frame, if one was.
pub fn dropped_preset(response: &egui::Response) -> Option<String> {
    // egui's release takes the payload whatever its type, and would lose a layer being moved.
    if !egui::DragAndDrop::has_payload_of_type::<DraggedPreset>(&response.ctx) {
        return None;
    }
    response.dnd_release_payload::<DraggedPreset>().map(|preset| preset.0.clone())
}

/// Whether a preset is being dragged over `response`.
pub fn preset_hovering(response: &egui::Response) -> bool {
    response.dnd_hover_payload::<DraggedPreset>().is_some()
}

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

/// What the library is asked for besides adding a layer.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Request {
    Close,
    Refresh,
}

/// What is searched for.
#[derive(Default)]
struct Filter {
    /// Whether the search field has had the focus since the library opened.
    focused: bool,
    search: String,
    tag: Option<String>,
}

/// The library's state: open or not, what is searched for, the presets and their pictures.
#[derive(Default)]
pub struct Browser {
    pub open: bool,
    filter: Filter,
    /// Read when the browser opens, and again after a preset is saved.
    entries: Option<Vec<Entry>>,
    /// Thumbnail textures by cache file name.
    textures: HashMap<String, egui::TextureHandle>,
}

impl Browser {
    pub fn refresh(&mut self) {
        self.entries = None;
    }

    /// Shows the library, when open, as a panel on the left of what `ui` has left: beside the
    /// layer stack, when that panel was shown first.
    pub fn show(
        &mut self,
        ui: &mut egui::Ui,
        session: &Session,
        thumbnails: &mut Thumbnails,
        actions: &mut Vec<Action>,
        message: &mut Option<Message>,
    ) {
        super::close_on_escape(ui.ctx(), &mut self.open);
        if !self.open {
            // Opened again, the search field takes the focus again.
            self.filter.focused = false;
            return;
        }
        let entries = self.entries.get_or_insert_with(|| read_entries(session));
        let target = session.document.selection().object.map_or("the default stack".to_string(), |o| o.to_string());
        let ctx = ui.ctx().clone();
        // One new thumbnail per frame, so the interface stays live while they render.
        let mut may_render = true;
        let request = {
            let textures = &mut self.textures;
            let mut thumbnail = |params: &Params| texture(&ctx, textures, thumbnails, params, &mut may_render, message);
            dock(ui).show(ui, |ui| self.filter.contents(ui, entries, &target, &mut thumbnail, actions)).inner
        };
        if !may_render {
            ctx.request_repaint();
        }
        match request {
            Some(Request::Close) => {
                self.open = false;
                self.filter.focused = false;
            }
            Some(Request::Refresh) => self.refresh(),
            None => {}
        }
    }
}

/// The library's panel, sized for what `ui` has left: two columns of thumbnails at first, never
/// narrower than one, and never leaving the image less than [`MIN_IMAGE_WIDTH`] (unless one
/// column needs it).
fn dock(ui: &egui::Ui) -> egui::Panel {
    let widest = (ui.available_width() - MIN_IMAGE_WIDTH).max(MIN_WIDTH);
    egui::Panel::left("preset library")
        .resizable(true)
        .default_size(DEFAULT_WIDTH.min(widest))
        .size_range(MIN_WIDTH..=widest)
}

/// Every preset the look's library can name, read once when the library opens.
fn read_entries(session: &Session) -> Vec<Entry> {
    session
        .document
        .library()
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
}

/// An entry's searched fields, as [`library::search`] takes them.
fn fields<'a>(entry: &'a &Entry) -> (&'a str, &'a [String], &'a str) {
    (&entry.name, &entry.tags, &entry.description)
}

impl Filter {
    /// The library's contents: the search, the tag filter and the presets they match.
    /// `thumbnail` gives a preset's picture when it has one.
    fn contents(
        &mut self,
        ui: &mut egui::Ui,
        entries: &[Entry],
        target: &str,
        thumbnail: &mut dyn FnMut(&Params) -> Option<egui::TextureId>,
        actions: &mut Vec<Action>,
    ) -> Option<Request> {
        let mut request = None;
        ui.horizontal(|ui| {
            ui.heading("Preset library");
            ui.with_layout(egui::Layout::right_to_left(egui::Align::Center), |ui| {
                if ui.button("🗙").on_hover_text("Close the library (Escape)").clicked() {
                    request = Some(Request::Close);
                }
                if ui.button("⟳").on_hover_text("Read the library again").clicked() {
                    request = Some(Request::Refresh);
                }
            });
        });
        let field = egui::TextEdit::singleline(&mut self.search)
            .hint_text("search names, tags, descriptions")
            .desired_width(f32::INFINITY);
        let search = ui.add(field);
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
        let hint = format!("Click a preset to add it on top of {target}, or drag it into the layer stack.");
        ui.label(RichText::new(hint).weak());
        ui.separator();
        let shown = self.shown(entries);
        if shown.is_empty() {
            self.nothing_found(ui, entries);
        } else {
            grid(ui, &shown, thumbnail, actions);
        }
        request
    }

    /// The entries the tag filter and the search let through, best first (see
    /// [`library::search`]), each with why it matched (nothing, without a search).
    fn shown<'e>(&self, entries: &'e [Entry]) -> Vec<(&'e Entry, Option<MatchedBy>)> {
        let tagged: Vec<&Entry> =
            entries.iter().filter(|e| self.tag.as_ref().is_none_or(|t| e.tags.contains(t))).collect();
        if self.search.trim().is_empty() {
            return tagged.into_iter().map(|e| (e, None)).collect();
        }
        library::search(&tagged, &self.search, fields).into_iter().map(|(e, why)| (*e, Some(why))).collect()
    }

    /// In place of an empty grid: that nothing matches, and buttons to clear what hides presets.
    fn nothing_found(&mut self, ui: &mut egui::Ui, entries: &[Entry]) {
        let query = self.search.trim().to_string();
        let everywhere: Vec<&Entry> = entries.iter().collect();
        let untagged = match self.tag {
            Some(_) if !query.is_empty() => library::search(&everywhere, &query, fields).len(),
            _ => 0,
        };
        ui.label(nothing_matches(&query, self.tag.as_deref(), untagged));
        ui.horizontal_wrapped(|ui| {
            // Only where the tag filter is what hides presets.
            let tag_hides = self.tag.is_some() && (query.is_empty() || untagged > 0);
            if tag_hides && ui.button("Show all tags").clicked() {
                self.tag = None;
            }
            if !query.is_empty() && ui.button("Clear the search").clicked() {
                self.search.clear();
            }
        });
    }
}

/// What the library says when it shows nothing, for the search `query` (trimmed) and the tag
/// filter: `untagged` presets match the query under any tag.
fn nothing_matches(query: &str, tag: Option<&str>, untagged: usize) -> String {
    match (query.is_empty(), tag) {
        (false, Some(tag)) if untagged > 0 => {
            let others = match untagged {
                1 => "One preset with other tags does".to_string(),
                n => format!("{n} presets with other tags do"),
            };
            format!("No preset tagged “{tag}” matches “{query}”. {others}: show all tags to see them.")
        }
        (false, _) => format!(
            "No preset matches “{query}”. Search looks at names, tags and descriptions, \
             and forgives a typo; try another word."
        ),
        (true, Some(tag)) => format!("No preset is tagged “{tag}”."),
        (true, None) => "The library has no presets.".to_string(),
    }
}

/// The presets' cells in rows of as many as fit; a click on one adds it as a layer.
fn grid(
    ui: &mut egui::Ui,
    shown: &[(&Entry, Option<MatchedBy>)],
    thumbnail: &mut dyn FnMut(&Params) -> Option<egui::TextureId>,
    actions: &mut Vec<Action>,
) {
    egui::ScrollArea::vertical().auto_shrink([false, false]).show(ui, |ui| {
        // Rows of as many cells as fit: a wrapping layout would widen the panel instead.
        let spacing = ui.spacing().item_spacing.x;
        let columns = (((ui.available_width() + spacing) / (CELL_WIDTH + spacing)) as usize).max(1);
        for row in shown.chunks(columns) {
            ui.horizontal(|ui| {
                for (entry, why) in row {
                    let texture = entry.params.as_ref().and_then(|params| thumbnail(params));
                    if cell(ui, entry, why.as_ref(), texture) {
                        actions.push(Action::AddPresetLayer(entry.name.clone()));
                    }
                }
            });
        }
    });
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

/// One preset's cell, which can be dragged onto the layer stack; true when clicked.
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
        .interact(egui::Sense::click_and_drag());
    if entry.problem.is_none() {
        response.dnd_set_drag_payload(DraggedPreset(entry.name.clone()));
        if response.dragged() {
            drag_label(ui.ctx(), &entry.name);
        }
    }
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

/// The dragged preset's name, beside the pointer.
fn drag_label(ctx: &egui::Context, name: &str) {
    let Some(pointer) = ctx.pointer_interact_pos() else { return };
    egui::Area::new(egui::Id::new("dragged preset"))
        .order(egui::Order::Tooltip)
        // Not interactable, so that what lies under it still sees the pointer (the drop).
        .interactable(false)
        .fixed_pos(pointer + egui::vec2(14.0, 10.0))
        .show(ctx, |ui| {
            egui::Frame::popup(ui.style()).show(ui, |ui| ui.label(format!("➕ {name}")));
        });
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::viewer_state::{Edit, ObjectRef};
    use egui::{pos2, vec2, Event, PointerButton, Pos2, RawInput, Rect};

    /// A preset entry with parameters, as a built-in one is listed.
    fn entry(name: &str, tags: &[&str], description: &str) -> Entry {
        Entry {
            name: name.into(),
            tags: tags.iter().map(|t| t.to_string()).collect(),
            description: description.into(),
            params: Some(Params::default()),
            problem: None,
            user: false,
        }
    }

    fn entries() -> Vec<Entry> {
        vec![
            entry("gold", &["metal", "polished"], "Johnson and Christy's gold"),
            entry("copper", &["metal"], "Polished copper"),
            entry("lacquered-wood", &["dielectric", "wood"], "Varnished oak"),
            entry("wax", &["dielectric"], "Candle wax"),
        ]
    }

    /// A frame's input: a window of `size` at time `time`, with `events`.
    fn input(size: egui::Vec2, time: f64, events: Vec<Event>) -> RawInput {
        RawInput {
            screen_rect: Some(Rect::from_min_size(Pos2::ZERO, size)),
            time: Some(time),
            events,
            ..Default::default()
        }
    }

    /// Every text drawn, with where it was drawn.
    fn placed_texts(output: &egui::FullOutput) -> Vec<(String, Rect)> {
        fn walk(shape: &egui::Shape, out: &mut Vec<(String, Rect)>) {
            match shape {
                egui::Shape::Text(text) => {
                    out.push((text.galley.text().to_string(), text.galley.rect.translate(text.pos.to_vec2())))
                }
                egui::Shape::Vec(shapes) => shapes.iter().for_each(|s| walk(s, out)),
                _ => {}
            }
        }
        let mut out = Vec::new();
        output.shapes.iter().for_each(|clipped| walk(&clipped.shape, &mut out));
        out
    }

    fn at(texts: &[(String, Rect)], text: &str) -> Rect {
        texts.iter().find(|(t, _)| t == text).unwrap_or_else(|| panic!("no '{text}' in {texts:?}")).1
    }

    /// The library's texts for `filter`, drawn headless.
    fn texts(filter: &mut Filter) -> Vec<String> {
        let ctx = egui::Context::default();
        let entries = entries();
        let mut shown = Vec::new();
        // Twice, as egui sizes some things in the first frame.
        for time in [0.0, 0.1] {
            let output = ctx.run_ui(input(vec2(800.0, 600.0), time, Vec::new()), |ui| {
                filter.contents(ui, &entries, "object 1", &mut |_| None, &mut Vec::new());
            });
            shown = placed_texts(&output).into_iter().map(|(text, _)| text).collect();
        }
        shown
    }

    /// A search that matches nothing says so, in place of an empty grid, and what to change;
    /// one that matches shows the presets and no such line.
    #[test]
    fn nothing_matching_is_said_in_words() {
        let mut filter = Filter { search: "xyz".into(), ..Filter::default() };
        let shown = texts(&mut filter);
        let said = "No preset matches “xyz”. Search looks at names, tags and descriptions, \
                    and forgives a typo; try another word.";
        assert!(shown.iter().any(|t| t == said), "{shown:?}");
        assert!(shown.iter().any(|t| t == "Clear the search"), "{shown:?}");
        assert!(!shown.iter().any(|t| t == "gold" || t == "Show all tags"), "{shown:?}");

        // The tag filter hides what the search finds: the line says so and offers to clear it.
        let mut filter = Filter { search: "wood".into(), tag: Some("metal".into()), ..Filter::default() };
        let shown = texts(&mut filter);
        let said =
            "No preset tagged “metal” matches “wood”. One preset with other tags does: show all tags to see them.";
        assert!(shown.iter().any(|t| t == said), "{shown:?}");
        assert!(shown.iter().any(|t| t == "Show all tags"), "{shown:?}");

        let mut filter = Filter { search: "gold".into(), ..Filter::default() };
        let shown = texts(&mut filter);
        assert!(shown.iter().any(|t| t == "gold"), "{shown:?}");
        assert!(!shown.iter().any(|t| t.starts_with("No preset")), "{shown:?}");
    }

    #[test]
    fn the_nothing_found_line_counts_and_names() {
        assert_eq!(
            nothing_matches("oak", Some("metal"), 3),
            "No preset tagged “metal” matches “oak”. 3 presets with other tags do: show all tags to see them."
        );
        assert!(nothing_matches("oak", Some("metal"), 0).starts_with("No preset matches “oak”."));
        assert_eq!(nothing_matches("", Some("metal"), 0), "No preset is tagged “metal”.");
    }

    /// A typo finds the metals, each saying what it is close to.
    #[test]
    fn a_typo_shows_what_it_is_close_to() {
        let mut filter = Filter { search: "metl".into(), ..Filter::default() };
        let shown = texts(&mut filter);
        for name in ["gold", "copper"] {
            assert!(shown.iter().any(|t| t == name), "{name}: {shown:?}");
        }
        assert!(!shown.iter().any(|t| t == "wax"), "{shown:?}");
        assert_eq!(shown.iter().filter(|t| *t == "close to: metal").count(), 2, "{shown:?}");
    }

    /// Beside the side panels at their first widths in a 1280×720 window, the library shows two
    /// columns of thumbnails and leaves the image at least [`MIN_IMAGE_WIDTH`].
    #[test]
    fn docked_at_1280_by_720_the_library_shows_two_columns_and_leaves_the_image_room() {
        let ctx = egui::Context::default();
        let entries = entries();
        let mut filter = Filter::default();
        let (mut image, mut texts) = (0.0, Vec::new());
        for time in [0.0, 0.1] {
            let output = ctx.run_ui(input(vec2(1280.0, 720.0), time, Vec::new()), |ui| {
                // Filled, as the viewer's side panels are by their scroll areas.
                let fill = |ui: &mut egui::Ui| ui.allocate_space(ui.available_size());
                egui::Panel::left("stack").default_size(super::super::STACK_WIDTH).show(ui, fill);
                egui::Panel::right("light").default_size(super::super::LIGHT_WIDTH).show(ui, fill);
                dock(ui).show(ui, |ui| filter.contents(ui, &entries, "object 1", &mut |_| None, &mut Vec::new()));
                image = ui.available_width();
            });
            texts = placed_texts(&output);
        }
        assert!(image >= MIN_IMAGE_WIDTH, "the image has {image} px");
        let (gold, copper, wood) = (at(&texts, "gold"), at(&texts, "copper"), at(&texts, "lacquered-wood"));
        assert_eq!(gold.top(), copper.top(), "two presets a row: {texts:?}");
        assert!(copper.left() > gold.left());
        assert!(wood.top() > gold.top(), "and no more: {texts:?}");
        // The library lies between the stack and the image.
        let (left, right) = (super::super::STACK_WIDTH, 1280.0 - super::super::LIGHT_WIDTH);
        assert!(gold.left() > left && copper.right() < right, "{gold:?} {copper:?} {image}");
    }

    fn pointer(pos: Pos2, pressed: bool) -> Event {
        Event::PointerButton { pos, button: PointerButton::Primary, pressed, modifiers: egui::Modifiers::NONE }
    }

    /// A preset cell dragged onto a drop zone is dropped there by name, and nowhere else; a
    /// click on a cell still adds the preset on top.
    #[test]
    fn a_dragged_preset_drops_by_name_and_a_click_still_adds() {
        let ctx = egui::Context::default();
        let entries = entries();
        let mut filter = Filter { focused: true, ..Filter::default() };
        let mut frame = |time: f64, events: Vec<Event>| {
            let (mut dropped, mut actions) = (None, Vec::new());
            let output = ctx.run_ui(input(vec2(900.0, 600.0), time, events), |ui| {
                let zone = egui::Panel::left("zone").exact_size(200.0).show(ui, |ui| ui.label("drop here"));
                dropped = dropped_preset(&zone.response);
                egui::CentralPanel::default().show(ui, |ui| {
                    filter.contents(ui, &entries, "object 1", &mut |_| None, &mut actions);
                });
            });
            (placed_texts(&output), dropped, actions)
        };
        let (texts, _, _) = frame(0.0, Vec::new());
        // On the thumbnail, above the name.
        let cell = at(&texts, "copper").center_top() - vec2(0.0, 30.0);
        let zone = pos2(100.0, 300.0);
        let steps = [
            vec![Event::PointerMoved(cell)],
            vec![pointer(cell, true)],
            vec![Event::PointerMoved(cell + vec2(20.0, 5.0))],
            vec![Event::PointerMoved(pos2(150.0, 250.0))],
            vec![Event::PointerMoved(zone)],
        ];
        for (step, events) in steps.into_iter().enumerate() {
            let (_, dropped, actions) = frame(0.1 * (step + 1) as f64, events);
            assert_eq!((dropped, actions), (None, Vec::new()), "step {step}");
        }
        let (_, dropped, actions) = frame(1.0, vec![pointer(zone, false)]);
        assert_eq!(dropped.as_deref(), Some("copper"));
        assert!(actions.is_empty(), "a drag is no click: {actions:?}");

        // Let go over the library itself, it drops nowhere.
        frame(1.5, vec![Event::PointerMoved(cell)]);
        frame(1.6, vec![pointer(cell, true)]);
        frame(1.7, vec![Event::PointerMoved(cell + vec2(25.0, 0.0))]);
        let (_, dropped, _) = frame(1.8, vec![pointer(cell + vec2(25.0, 0.0), false)]);
        assert_eq!(dropped, None);

        frame(3.0, vec![pointer(cell, true)]);
        let (_, dropped, actions) = frame(3.05, vec![pointer(cell, false)]);
        assert_eq!(dropped, None);
        assert_eq!(actions, vec![Action::AddPresetLayer("copper".into())], "a click adds it on top");
    }

    /// Dropped on the upper half of a layer's row, a preset goes just above that layer; on the
    /// lower half, just below: one undoable edit, the new layer selected.
    #[test]
    fn a_preset_dropped_on_the_layer_list_goes_where_the_line_shows() {
        use crate::gpu::{Context, ContextOptions};
        use crate::render::scene::{GBufferSpec, LookSource, Scene, SceneSpec};
        use crate::viewer_state::{Document, Selection};
        let look = "[[object]]\n[[object.layer]]\npreset = \"grey-card\"\n\
                    [[object]]\nid = 1\n\
                    [[object.layer]]\npreset = \"blue-rubber\"\n\
                    [[object.layer]]\npreset = \"gold\"\n\
                    [[object.layer]]\npreset = \"grime\"\n";
        let gpu = Context::new(&ContextOptions::from_env(std::env::var("LOOKDEV_TEST_DEVICE").ok())).unwrap();
        let look = crate::material::look::Look::parse(look, std::path::Path::new("test.toml")).unwrap();
        let spec = SceneSpec {
            gbuffer: GBufferSpec { builtin_size: Some((32, 32)), ..GBufferSpec::default() },
            look: LookSource::Given(Box::new(look)),
            ..SceneSpec::default()
        };
        let scene = Scene::load(&spec).unwrap();
        let mut document = Document::new(scene.look.clone(), None, scene.settings.clone());
        let ball = ObjectRef::Id(1);
        document.select(Selection { object: Some(ball), layer: Some(0) });
        let session = Session::of_scene(&gpu, scene, document).unwrap();

        let ctx = egui::Context::default();
        let frame = |time: f64, events: Vec<Event>| {
            let mut actions = Vec::new();
            let output = ctx.run_ui(input(vec2(500.0, 900.0), time, events), |ui| {
                super::super::layers::show(ui, &session, &mut actions);
            });
            (placed_texts(&output), actions)
        };
        let (texts, _) = frame(0.0, Vec::new());
        let row = texts.iter().find(|(t, _)| t.starts_with("gold")).unwrap_or_else(|| panic!("{texts:?}")).1;
        for (dy, at) in [(-4.0, 2), (4.0, 1)] {
            let over = row.center() + vec2(0.0, dy);
            egui::DragAndDrop::set_payload(&ctx, DraggedPreset("chrome".into()));
            let (_, actions) = frame(1.0 + at as f64, vec![Event::PointerMoved(over)]);
            assert!(actions.is_empty(), "{actions:?}");
            let (_, actions) = frame(1.5 + at as f64, vec![pointer(over, false)]);
            let expected = [
                Action::Edit(Edit::InsertLayer { object: ball, preset: "chrome".into(), at }),
                Action::Select(Selection { object: Some(ball), layer: Some(at) }),
            ];
            assert_eq!(actions, expected, "dropped {dy} px from the row's middle");
        }
        drop(session);
        drop(gpu);
    }
}
