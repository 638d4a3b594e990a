//! The right panel's Snapshots section: take one (P), and for each a thumbnail, its name,
//! samples and time, and buttons to restore its look, compare it with the live image (split,
//! side by side or ΔE) and delete it. It also keeps the textures the view and the strip under
//! it show them with, and the flip (B) between the live image and a snapshot or B.

use super::super::action::{Action, Compare};
use super::super::compare::{Comparing, Flip, Showing, SnapshotView};
use super::super::session::Session;
use super::strip;
use egui::{pos2, vec2, Color32, Rect};

/// Thumbnails' height in points.
const THUMBNAIL: f32 = 48.0;

/// The section's state: the name being typed, the chosen view, and the textures.
#[derive(Default)]
pub struct Panel {
    name: String,
    view: SnapshotView,
    /// Each snapshot's display image, by [`Snapshot::id`](super::super::snapshots::Snapshot::id).
    textures: Vec<(u64, egui::TextureHandle)>,
    /// The ΔE heat map, by its serial.
    heat: Option<(u64, egui::TextureHandle)>,
    /// What the flip key shows.
    flip: Flip,
    /// The strip of recent snapshots under the image is hidden (View ▸ Snapshot strip).
    pub strip_hidden: bool,
}

/// What the view draws: the comparison as its mode draws it, or, flipped, the other image alone
/// in the image's place.
pub struct Drawn {
    /// The image, or A of a split.
    pub a: egui::TextureId,
    /// B of a split.
    pub b: Option<egui::TextureId>,
    /// The snapshot compared, side by side or as ΔE.
    pub snapshot: Option<Shown>,
    /// The name of the image the flip shows instead of the comparison.
    pub flipped: Option<String>,
}

/// What the view draws of the snapshot being compared.
pub struct Shown {
    pub name: String,
    pub view: SnapshotView,
    /// The snapshot's display image.
    pub texture: egui::TextureId,
    /// The ΔE heat map, once made.
    pub heat: Option<egui::TextureId>,
    /// Its mean and largest ΔE.
    pub delta: Option<(f32, f32)>,
}

impl Panel {
    /// Makes textures for new snapshots and a new ΔE map, and lets go of those gone.
    pub fn prepare(&mut self, ctx: &egui::Context, session: &Session) {
        let list = &session.snapshots.list;
        self.textures.retain(|(id, _)| list.iter().any(|s| s.id == *id));
        for snapshot in list {
            if !self.textures.iter().any(|(id, _)| *id == snapshot.id) {
                let size = [snapshot.width as usize, snapshot.height as usize];
                let image = egui::ColorImage::from_rgba_unmultiplied(size, &snapshot.display);
                let texture =
                    ctx.load_texture(format!("snapshot-{}", snapshot.id), image, egui::TextureOptions::NEAREST);
                self.textures.push((snapshot.id, texture));
            }
        }
        let delta = session.snapshot_compare().and_then(|s| s.delta.as_ref());
        match delta {
            Some(delta) if self.heat.as_ref().is_none_or(|(serial, _)| *serial != delta.serial) => {
                let size = [delta.width as usize, delta.height as usize];
                let image = egui::ColorImage::from_rgba_unmultiplied(size, &delta.heat_map());
                self.heat = Some((delta.serial, ctx.load_texture("delta-e", image, egui::TextureOptions::NEAREST)));
            }
            Some(_) => {}
            None => self.heat = None,
        }
        with_comparing(session, |comparing| self.flip.follow(comparing));
    }

    /// Presses the flip key: shows the other image, or returns from it. False when there is
    /// nothing to flip to (no snapshot, nothing compared).
    pub fn flip(&mut self, session: &Session) -> bool {
        with_comparing(session, |comparing| self.flip.toggle(comparing))
    }

    /// Whether the flip key has an image to go to.
    pub fn can_flip(&self, session: &Session) -> bool {
        with_comparing(session, |comparing| self.flip.is_on(comparing) || self.flip.other(comparing).is_some())
    }

    /// Which image is on screen, as the status bar says it ("showing snapshot NAME", "showing
    /// live", "showing A | B", …); nothing while there is no other image to confuse it with.
    pub fn showing(&self, session: &Session) -> Option<String> {
        let name = |id: u64| session.snapshots.list.iter().find(|s| s.id == id).map_or("", |s| s.name.as_str());
        with_comparing(session, |comparing| match self.flip.showing(comparing) {
            Showing::Live => self.flip.other(comparing).map(|_| "showing live".to_string()),
            Showing::Compare => Some(match session.snapshot_compare() {
                Some(shown) if shown.view == SnapshotView::DeltaE => {
                    format!("showing ΔE2000 of live vs snapshot {}", shown.name)
                }
                Some(shown) => format!("showing live | snapshot {}", shown.name),
                None => "showing A | B".to_string(),
            }),
            Showing::Snapshot(id) => Some(format!("showing snapshot {}", name(id))),
            Showing::B => Some(format!("showing {}", b_label(session))),
        })
    }

    /// What the view draws this frame; `a` is the live image (or the view shown instead of the
    /// beauty) and `compare` B's rendered image, while comparing.
    pub fn drawn(&self, session: &Session, a: egui::TextureId, compare: Option<egui::TextureId>) -> Drawn {
        let alone = |texture, label| Drawn { a: texture, b: None, snapshot: None, flipped: Some(label) };
        match with_comparing(session, |comparing| self.flip.showing(comparing)) {
            Showing::Snapshot(id) => {
                let snapshot = session.snapshots.list.iter().find(|s| s.id == id);
                if let (Some(snapshot), Some(texture)) = (snapshot, self.texture(id)) {
                    return alone(texture, format!("snapshot {} · {} spp", snapshot.name, snapshot.spp));
                }
            }
            // Before its first pass B's image is not a picture yet, and says so, rather than
            // show A under B's name.
            Showing::B => {
                if let Some(texture) = compare {
                    let label = b_label(session);
                    let ready = session.compare_ready();
                    return alone(texture, if ready { label } else { format!("{label} · waiting for its first pass") });
                }
            }
            Showing::Live | Showing::Compare => {}
        }
        let snapshot = self.shown(session);
        let b = snapshot.as_ref().map_or(compare, |s| Some(s.texture));
        Drawn { a, b, snapshot, flipped: None }
    }

    /// The strip of recent snapshots under the image, while the look has a file to keep them
    /// beside (empty, it keeps its place, so that the first snapshot does not move the image).
    /// A click compares one with the live image, as the panel's Compare does.
    pub fn strip(&mut self, ui: &mut egui::Ui, session: &Session, actions: &mut Vec<Action>) {
        if self.strip_hidden || session.snapshots.look_file().is_none() {
            return;
        }
        let compared = session.snapshot_compare().map(|c| c.id);
        let items: Vec<strip::Item> = session
            .snapshots
            .list
            .iter()
            .rev()
            .filter_map(|s| {
                let texture = self.texture(s.id)?;
                let aspect = s.width as f32 / s.height as f32;
                Some(strip::Item { id: s.id, name: &s.name, spp: s.spp, texture, aspect })
            })
            .collect();
        let view = self.view;
        egui::Panel::bottom("snapshot-strip").exact_size(strip::HEIGHT).show(ui, |ui| {
            if items.is_empty() {
                ui.weak("No snapshots yet: P keeps the image and the look that made it.");
                return;
            }
            let Some(item) = strip::show(ui, &items, compared).map(|index| &items[index]) else { return };
            if compared != Some(item.id) {
                actions.push(Action::Compare(Compare::Snapshot(item.name.to_string(), view)));
            }
        });
    }

    /// A snapshot's display image, once made.
    fn texture(&self, id: u64) -> Option<egui::TextureId> {
        self.textures.iter().find(|(i, _)| *i == id).map(|(_, t)| t.id())
    }

    /// The snapshot being compared, as the view draws it.
    pub fn shown(&self, session: &Session) -> Option<Shown> {
        let compare = session.snapshot_compare()?;
        let texture = self.textures.iter().find(|(id, _)| *id == compare.id)?.1.id();
        Some(Shown {
            name: compare.name.clone(),
            view: compare.view,
            texture,
            heat: compare.delta.as_ref().and(self.heat.as_ref()).map(|(_, t)| t.id()),
            delta: compare.delta.as_ref().map(|d| (d.mean, d.max)),
        })
    }

    pub fn show(&mut self, ui: &mut egui::Ui, session: &Session, actions: &mut Vec<Action>) {
        ui.heading("Snapshots");
        let has_file = session.snapshots.look_file().is_some();
        ui.horizontal(|ui| {
            let hint = session.snapshots.default_name();
            ui.add(egui::TextEdit::singleline(&mut self.name).hint_text(hint).desired_width(140.0));
            let take = ui
                .add_enabled(has_file, egui::Button::new("Snapshot").shortcut_text("P"))
                .on_hover_text("Keep the image and the look that made it, beside the look file")
                .on_disabled_hover_text("Save the look first: snapshots are kept beside its file");
            if take.clicked() {
                let name = std::mem::take(&mut self.name);
                actions.push(Action::Snapshot(Some(name.trim().to_string()).filter(|n| !n.is_empty())));
            }
        });
        if !has_file {
            ui.weak("Save the look to keep snapshots beside it.");
            return;
        }
        let compared = session.snapshot_compare();
        // While comparing, the choice shows and changes how the snapshot is shown.
        if let Some(compare) = compared {
            self.view = compare.view;
        }
        ui.horizontal(|ui| {
            ui.label("Compare as");
            for view in SnapshotView::ALL {
                if ui.selectable_value(&mut self.view, view, view.label()).clicked() {
                    if let Some(compare) = compared.filter(|c| c.view != view) {
                        actions.push(Action::Compare(Compare::Snapshot(compare.name.clone(), view)));
                    }
                }
            }
        });
        if let Some(compare) = compared {
            ui.horizontal(|ui| {
                ui.label(format!("B: {} ({})", compare.name, compare.view.label()));
                if ui.button("Stop").clicked() {
                    actions.push(Action::Compare(Compare::Off));
                }
            });
            if let Some(delta) = &compare.delta {
                ui.label(format!("ΔE2000 mean {:.2}, max {:.2}", delta.mean, delta.max));
            }
            if compare.view == SnapshotView::Split {
                let mut divider = session.divider;
                let slider = egui::Slider::new(&mut divider, 0.0..=1.0).text("divider").max_decimals(3);
                if ui.add(slider).changed() {
                    actions.push(Action::Divider(divider));
                }
            }
        }
        if session.snapshots.list.is_empty() {
            ui.weak("None yet.");
        }
        // Newest first.
        for snapshot in session.snapshots.list.iter().rev() {
            ui.horizontal(|ui| {
                if let Some((_, texture)) = self.textures.iter().find(|(id, _)| *id == snapshot.id) {
                    let aspect = snapshot.width as f32 / snapshot.height as f32;
                    ui.image((texture.id(), egui::vec2(THUMBNAIL * aspect, THUMBNAIL)));
                }
                ui.vertical(|ui| {
                    let current = compared.is_some_and(|c| c.id == snapshot.id);
                    let name = egui::RichText::new(&snapshot.name).strong();
                    ui.label(if current { name.underline() } else { name });
                    ui.weak(format!("{} spp · {}", snapshot.spp, snapshot.taken.replace('T', " ")));
                    ui.horizontal(|ui| {
                        if ui.small_button("Restore").on_hover_text("Restore its look (one undoable edit)").clicked() {
                            actions.push(Action::RestoreSnapshot(snapshot.name.clone()));
                        }
                        if ui.small_button("Compare").on_hover_text("Compare it with the live image").clicked() {
                            actions.push(Action::Compare(Compare::Snapshot(snapshot.name.clone(), self.view)));
                        }
                        if ui.small_button("Delete").on_hover_text("Delete it and its files").clicked() {
                            actions.push(Action::DeleteSnapshot(snapshot.name.clone()));
                        }
                    });
                });
            });
        }
    }
}

/// Runs `f` on what is compared, as the flip sees it.
fn with_comparing<R>(session: &Session, f: impl FnOnce(&Comparing) -> R) -> R {
    let ids: Vec<u64> = session.snapshots.list.iter().map(|s| s.id).collect();
    let snapshot = session.snapshot_compare().map(|s| s.id);
    f(&Comparing { snapshot, b: session.compare_subject().is_some(), snapshots: &ids })
}

/// B's label, "B: …", as the split names it.
fn b_label(session: &Session) -> String {
    session.compare_labels().map_or("B".to_string(), |(_, b)| b)
}

/// Names the image the flip shows on a plate by the image's top-left corner (above it where
/// there is room, else inside), in the warning colour, so that it is never taken for the live
/// image.
pub fn flip_plate(ui: &egui::Ui, label: &str, image: Option<Rect>) {
    let Some(image) = image else { return };
    let view = ui.max_rect();
    let painter = ui.painter_at(view);
    let color = ui.visuals().warn_fg_color;
    let galley = painter.layout_no_wrap(format!("{label}  (B: back)"), egui::FontId::proportional(13.0), color);
    let size = galley.size() + vec2(10.0, 8.0);
    let top = if image.min.y - size.y - 2.0 >= view.min.y { image.min.y - size.y - 2.0 } else { image.min.y + 2.0 };
    let plate = Rect::from_min_size(pos2(image.min.x.max(view.min.x + 2.0), top), size);
    painter.rect_filled(plate, 2.0, Color32::from_black_alpha(190));
    painter.rect_stroke(plate, 2.0, egui::Stroke::new(1.0, color), egui::StrokeKind::Inside);
    painter.galley(plate.min + vec2(5.0, 4.0), galley, color);
}
