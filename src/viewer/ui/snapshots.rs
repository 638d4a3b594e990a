//! The right panel's Snapshots section: take one (P), and for each a thumbnail, its name,
//! samples and time, and buttons to restore its look, compare it with the live image (split,
//! side by side or ΔE) and delete it. It also keeps the textures the view shows them with.

use super::super::action::{Action, Compare};
use super::super::compare::SnapshotView;
use super::super::session::Session;

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
