//! The left panel: objects, the selected object's layer stack (top layer first, as in a paint
//! program), and the selected layer's mask, opacity and eleven parameters.

use super::super::action::Action;
use super::super::session::{layer_label, Session};
use crate::material::look::{Layer, LayerId, ObjectStack};
use crate::material::mask::{MaskAdjust, GAMMA_RANGE, MAX_BLUR};
use crate::material::params::{Param, Value, GROUPS};
use crate::material::physical;
use crate::material::stack::bindable_maps;
use crate::viewer_state::{Edit, ObjectRef, Selection};
use egui::{Color32, RichText};

/// The width of the parameter-name column: "clearcoat_gloss" in the default font, and a margin.
const NAME_WIDTH: f32 = 110.0;

/// Shows the panel; returns true when the artist asked to add a layer from the library.
pub fn show(ui: &mut egui::Ui, session: &Session, actions: &mut Vec<Action>) -> bool {
    let document = &session.document;
    let selection = document.selection();
    objects(ui, session, selection, actions);
    ui.separator();
    let Some(object) = selection.object else {
        ui.label("Select an object, or click one in the image.");
        return false;
    };
    let Some(stack) = document.stack(object) else {
        ui.label("This object has no stack yet.");
        return add_button(ui);
    };
    let own = document.look().objects.iter().any(|o| o.is_for(object.id()));
    if object == ObjectRef::Default && !default_stack_used(session) {
        ui.label(RichText::new(UNUSED_DEFAULT).color(ui.visuals().warn_fg_color));
    } else if !own {
        ui.label(RichText::new("Shows the default stack; the first edit gives this object a copy of its own.").weak());
    }
    let mut catcher = stack.shadow_catcher;
    let hint = "Show only the shadows other objects cast on it, over the background, as Cycles' shadow catcher";
    if ui.checkbox(&mut catcher, "Shadow catcher").on_hover_text(hint).changed() {
        actions.push(Action::SetShadowCatcher(catcher));
    }
    let add = layer_list(ui, object, stack, selection, session.solo, actions);
    if let Some(index) = selection.layer.filter(|&i| i < stack.layers.len()) {
        ui.separator();
        layer_properties(ui, session, object, index, &stack.layers[index], actions);
        ui.separator();
        parameters(ui, session, object, index, &stack.layers[index], actions);
    }
    add
}

fn objects(ui: &mut egui::Ui, session: &Session, selection: Selection, actions: &mut Vec<Action>) {
    ui.heading("Objects");
    let look = session.document.look();
    let mut row = |ui: &mut egui::Ui, object: ObjectRef, text: String| {
        let selected = selection.object == Some(object);
        if ui.selectable_label(selected, text).clicked() && !selected {
            let top = session.document.stack(object).map(|s| s.layers.len().saturating_sub(1));
            actions.push(Action::Select(Selection { object: Some(object), layer: top }));
        }
    };
    let default = if default_stack_used(session) { "Default stack" } else { "Default stack (no pixel uses it)" };
    row(ui, ObjectRef::Default, default.to_string());
    for &id in session.objects() {
        let name = session.gbuffer.object_names.get(&id).map(|n| format!(" {n}")).unwrap_or_default();
        let own = look.objects.iter().any(|o| o.id == Some(id));
        let note = if own { "" } else { "  (default stack)" };
        row(ui, ObjectRef::Id(id), format!("{id}{name}{note}"));
    }
}

/// What the stack panel says of a default stack no pixel shows.
const UNUSED_DEFAULT: &str =
    "No pixel uses this stack: every object in the image has a stack of its own. Edits here change only objects added later.";

/// Whether some object in the image has no stack of its own, and so shows the default stack.
fn default_stack_used(session: &Session) -> bool {
    let look = session.document.look();
    session.objects().iter().any(|&id| !look.objects.iter().any(|o| o.id == Some(id)))
}

fn add_button(ui: &mut egui::Ui) -> bool {
    ui.button("➕ Add layer…").on_hover_text("Add a layer from the preset library").clicked()
}

/// The layer keys, as in Photoshop, which most artists' hands know: Ctrl+Shift+N adds a layer
/// (from the library), Ctrl+J duplicates the selected one, Delete removes it, Ctrl+, hides or
/// shows it; S solos it and L shows its mask overlay. Returns true when the library should open.
pub fn shortcuts(input: &mut egui::InputState, session: &Session, actions: &mut Vec<Action>) -> bool {
    use egui::{Key, KeyboardShortcut, Modifiers};
    let document = &session.document;
    let selection = document.selection();
    let add = input.consume_shortcut(&KeyboardShortcut::new(Modifiers::COMMAND | Modifiers::SHIFT, Key::N));
    if input.consume_key(Modifiers::NONE, Key::L) {
        actions.push(Action::MaskOverlay(None));
    }
    let (Some(object), Some(layer)) = (selection.object, selection.layer) else { return add };
    let Some(stack) = document.stack(object).filter(|s| layer < s.layers.len()) else { return add };
    if input.consume_shortcut(&KeyboardShortcut::new(Modifiers::COMMAND, Key::J)) {
        actions.push(Action::Edit(Edit::DuplicateLayer { object, layer }));
        actions.push(Action::Select(Selection { object: Some(object), layer: Some(layer + 1) }));
    }
    if input.consume_key(Modifiers::NONE, Key::Delete) && stack.layers.len() > 1 {
        actions.push(Action::Edit(Edit::RemoveLayer { object, layer }));
    }
    if input.consume_shortcut(&KeyboardShortcut::new(Modifiers::COMMAND, Key::Comma)) {
        actions.push(Action::Edit(Edit::SetEnabled { object, layer, enabled: !stack.layers[layer].enabled }));
    }
    if input.consume_key(Modifiers::NONE, Key::S) {
        actions.push(Action::Solo(session.solo != Some(stack.layers[layer].id)));
    }
    add
}

/// The stack, top layer first. Returns true when "Add layer" was clicked.
fn layer_list(
    ui: &mut egui::Ui,
    object: ObjectRef,
    stack: &ObjectStack,
    selection: Selection,
    solo: Option<LayerId>,
    actions: &mut Vec<Action>,
) -> bool {
    let count = stack.layers.len();
    let mut add = false;
    ui.horizontal(|ui| {
        ui.heading("Layers");
        add = add_button(ui);
        let selected = selection.layer.filter(|&i| i < count);
        if let Some(layer) = selected {
            if ui.button("Duplicate").on_hover_text("Copy the layer, just above it").clicked() {
                actions.push(Action::Edit(Edit::DuplicateLayer { object, layer }));
                actions.push(Action::Select(Selection { object: Some(object), layer: Some(layer + 1) }));
            }
            let remove = ui.add_enabled(count > 1, egui::Button::new("Remove")).on_hover_text("Remove the layer");
            if remove.clicked() {
                actions.push(Action::Edit(Edit::RemoveLayer { object, layer }));
            }
        }
    });
    ui.label(RichText::new("Drag ☰ to reorder. The bottom layer fills; each layer above blends over it.").weak());
    let mut dropped: Option<(usize, usize)> = None;
    for index in (0..count).rev() {
        let layer = &stack.layers[index];
        let row = ui.horizontal(|ui| {
            let handle = ui.dnd_drag_source(egui::Id::new(("layer", index)), index, |ui| ui.label("☰")).response;
            handle.on_hover_text("Drag to move the layer");
            let mut enabled = layer.enabled;
            let soloed = solo == Some(layer.id);
            let eye = ui.checkbox(&mut enabled, "").on_hover_text("Show or hide the layer; Alt+click solos it");
            // Alt+click on the eye solos the layer, as in Substance Painter.
            if eye.changed() && ui.input(|i| i.modifiers.alt) {
                actions.push(Action::Select(Selection { object: Some(object), layer: Some(index) }));
                actions.push(Action::Solo(!soloed));
            } else if eye.changed() {
                actions.push(Action::Edit(Edit::SetEnabled { object, layer: index, enabled }));
            }
            let solo_button = ui.selectable_label(soloed, "S").on_hover_text("Solo: show this layer alone (S)");
            if solo_button.clicked() {
                actions.push(Action::Select(Selection { object: Some(object), layer: Some(index) }));
                actions.push(Action::Solo(!soloed));
            }
            let mut text = RichText::new(layer_summary(layer, index));
            if !layer.enabled {
                text = text.weak().strikethrough();
            }
            let selected = selection.layer == Some(index);
            if ui.selectable_label(selected, text).clicked() {
                actions.push(Action::Select(Selection { object: Some(object), layer: Some(index) }));
            }
        });
        // The pointer's half of the row says where the layer goes: above the row or below it.
        let rect = row.response.rect;
        let above = ui.ctx().pointer_interact_pos().is_none_or(|p| p.y < rect.center().y);
        // A preset dragged from the library goes into the gap the line shows, as a new layer.
        // Before the layers' own drop: taking a payload of another type would lose it.
        if let Some(preset) = super::browser::dropped_preset(&row.response) {
            let at = if above { index + 1 } else { index };
            actions.push(Action::Edit(Edit::InsertLayer { object, preset, at }));
            actions.push(Action::Select(Selection { object: Some(object), layer: Some(at) }));
        }
        if let Some(from) = row.response.dnd_release_payload::<usize>() {
            dropped = Some((*from, drop_index(*from, index, above)));
        }
        if row.response.dnd_hover_payload::<usize>().is_some() || super::browser::preset_hovering(&row.response) {
            let y = if above { rect.top() } else { rect.bottom() };
            ui.painter().hline(rect.x_range(), y, egui::Stroke::new(2.0, ui.visuals().selection.bg_fill));
        }
    }
    if let Some((from, to)) = dropped.filter(|(from, to)| from != to) {
        actions.push(Action::Edit(Edit::MoveLayer { object, from, to }));
        actions.push(Action::Select(Selection { object: Some(object), layer: Some(to) }));
    }
    add
}

/// Where layer `from` ends up (for [`Edit::MoveLayer`], which removes it, then inserts it)
/// when dropped just above (`above`) or just below the layer `onto`. The list shows the top
/// layer first, so above a row is a higher index.
fn drop_index(from: usize, onto: usize, above: bool) -> usize {
    // The gap it goes into, counted in the stack before the move: gap g lies below layer g.
    let gap = if above { onto + 1 } else { onto };
    // Taking the layer out first shifts every gap above it down by one.
    if from < gap {
        gap - 1
    } else {
        gap
    }
}

/// What a mask's adjustments do, for the header that folds them away: "" when nothing.
fn adjust_summary(adjust: &MaskAdjust) -> String {
    let mut parts = Vec::new();
    if adjust.blur > 0.0 {
        parts.push(format!("blur {:.1} px", adjust.blur));
    }
    if !adjust.levels_are_identity() {
        parts.push(format!("{:.2}–{:.2}, γ {:.2}", adjust.black, adjust.white, adjust.gamma));
    }
    if parts.is_empty() {
        String::new()
    } else {
        format!(": {}", parts.join(", "))
    }
}

/// "gold · stripes (inverted) · 60% · 2 maps".
fn layer_summary(layer: &Layer, index: usize) -> String {
    let mut text = layer_label(layer);
    if index > 0 {
        if let Some(mask) = &layer.mask {
            let adjusted = layer.mask_adjust != MaskAdjust::default();
            let notes: Vec<&str> =
                [(layer.invert, "inverted"), (adjusted, "adjusted")].into_iter().filter(|n| n.0).map(|n| n.1).collect();
            let notes = if notes.is_empty() { String::new() } else { format!(" ({})", notes.join(", ")) };
            text += &format!(" · {mask}{notes}");
        }
        if layer.opacity < 1.0 {
            text += &format!(" · {:.0}%", layer.opacity * 100.0);
        }
    }
    match layer.maps.len() {
        0 => {}
        1 => text += " · 1 map",
        n => text += &format!(" · {n} maps"),
    }
    text
}

fn layer_properties(
    ui: &mut egui::Ui,
    session: &Session,
    object: ObjectRef,
    index: usize,
    layer: &Layer,
    actions: &mut Vec<Action>,
) {
    ui.heading(format!("Layer {index}: {}", layer_label(layer)));
    ui.horizontal(|ui| {
        ui.label("Name");
        // Typing is one undo step (a gesture), ended by the next click; cleared, the layer
        // takes its preset's name again.
        let mut name = layer.name.clone().unwrap_or_default();
        let hint = layer.preset.clone().unwrap_or_else(|| "custom".into());
        let field = ui.add(egui::TextEdit::singleline(&mut name).hint_text(hint).desired_width(180.0));
        if field.changed() {
            let name = Some(name.trim().to_string()).filter(|n| !n.is_empty());
            actions.push(Action::Drag(Edit::RenameLayer { object, layer: index, name }));
        }
        if field.lost_focus() {
            actions.push(Action::EndGesture);
        }
    });
    if index == 0 {
        ui.label(RichText::new("The bottom layer fills the object: its mask and opacity do not apply.").weak());
    }
    ui.add_enabled_ui(index > 0, |ui| {
        egui::Grid::new("layer properties").num_columns(2).show(ui, |ui| {
            ui.label("Mask");
            let current = layer.mask.clone().unwrap_or_else(|| "none".into());
            egui::ComboBox::from_id_salt("mask").selected_text(current).show_ui(ui, |ui| {
                if ui.selectable_label(layer.mask.is_none(), "none").clicked() {
                    actions.push(Action::SetMask(None));
                }
                for mask in session.masks() {
                    if ui.selectable_label(layer.mask.as_ref() == Some(mask), mask).clicked() {
                        actions.push(Action::SetMask(Some(mask.clone())));
                    }
                }
            });
            ui.end_row();
            ui.label("Invert");
            let mut invert = layer.invert;
            if ui.checkbox(&mut invert, "").changed() {
                actions.push(Action::Edit(Edit::SetInvert { object, layer: index, invert }));
            }
            ui.end_row();
            ui.label("Opacity");
            let mut opacity = layer.opacity;
            if ui.add(egui::Slider::new(&mut opacity, 0.0..=1.0)).changed() {
                actions.push(Action::Drag(Edit::SetOpacity { object, layer: index, opacity }));
            }
            ui.end_row();
        });
        ui.add_enabled_ui(layer.mask.is_some(), |ui| mask_adjustments(ui, object, index, layer, actions));
    });
}

/// The mask's blur and levels, each a slider that keeps the others valid (black below white).
fn mask_adjustments(ui: &mut egui::Ui, object: ObjectRef, index: usize, layer: &Layer, actions: &mut Vec<Action>) {
    let current = layer.mask_adjust;
    let mut adjust = current;
    egui::CollapsingHeader::new(format!("Mask blur and levels{}", adjust_summary(&current)))
        .id_salt("mask adjustments")
        .show(ui, |ui| {
            egui::Grid::new("mask adjustments grid").num_columns(2).show(ui, |ui| {
                ui.label("Blur").on_hover_text("A Gaussian's σ, in g-buffer pixels");
                ui.add(egui::Slider::new(&mut adjust.blur, 0.0..=MAX_BLUR).suffix(" px").max_decimals(1));
                ui.end_row();
                ui.label("Black").on_hover_text("The mask value that becomes 0");
                ui.add(egui::Slider::new(&mut adjust.black, 0.0..=0.99).max_decimals(3));
                ui.end_row();
                ui.label("White").on_hover_text("The mask value that becomes 1");
                ui.add(egui::Slider::new(&mut adjust.white, 0.01..=1.0).max_decimals(3));
                ui.end_row();
                ui.label("Gamma").on_hover_text("Above 1 widens the layer's reach, below 1 narrows it");
                ui.add(egui::Slider::new(&mut adjust.gamma, GAMMA_RANGE).logarithmic(true).max_decimals(2));
                ui.end_row();
            });
            if ui.button("Reset").clicked() {
                adjust = MaskAdjust::default();
            }
        });
    if adjust != current {
        // Whichever point moved pushes the other along, so the pair stays ordered.
        if adjust.black != current.black {
            adjust.white = adjust.white.max(adjust.black + 0.01).min(1.0);
        } else {
            adjust.black = adjust.black.min(adjust.white - 0.01).max(0.0);
        }
        actions.push(Action::Drag(Edit::SetMaskAdjust { object, layer: index, adjust }));
    }
}

fn parameters(
    ui: &mut egui::Ui,
    session: &Session,
    object: ObjectRef,
    index: usize,
    layer: &Layer,
    actions: &mut Vec<Action>,
) {
    ui.heading("Parameters");
    ui.horizontal(|ui| {
        override_dot(ui, true);
        ui.label(RichText::new("overridden here").weak());
        override_dot(ui, false);
        ui.label(RichText::new("the preset's value").weak());
    });
    // Bindings show only where there is something to bind to (or something bound).
    let with_maps = !session.gbuffer.maps.is_empty() || !layer.maps.is_empty();
    if with_maps {
        ui.label(
            RichText::new("Click a parameter to bind it to a map: bound (blue), it is its value times the map's.")
                .weak(),
        );
    }
    // Grouped as look-dev tools group them (material::params::GROUPS); each name's tooltip says
    // what the value means physically, from the layer's values now.
    for (group, params) in GROUPS {
        egui::CollapsingHeader::new(RichText::new(group.name()).strong())
            .id_salt(("parameter group", group.name()))
            .default_open(true)
            .show(ui, |ui| {
                egui::Grid::new(("parameters", group.name()))
                    .num_columns(4)
                    .spacing([6.0, 4.0])
                    .min_col_width(12.0)
                    .show(ui, |ui| {
                        for &param in params {
                            parameter_row(ui, session, object, index, layer, param, actions);
                            ui.end_row();
                        }
                    });
            });
    }
}

/// One parameter's row: override dot, name (a map menu where maps can bind), value, reset.
fn parameter_row(
    ui: &mut egui::Ui,
    session: &Session,
    object: ObjectRef,
    index: usize,
    layer: &Layer,
    param: Param,
    actions: &mut Vec<Action>,
) {
    let document = &session.document;
    let with_maps = !session.gbuffer.maps.is_empty() || !layer.maps.is_empty();
    let overridden = document.is_overridden(object, index, param);
    let preset_value = document.preset_value(object, index, param);
    override_dot(ui, overridden).on_hover_text(if overridden {
        format!("Overridden; the preset has {preset_value}")
    } else {
        "The preset's value".to_string()
    });
    let bound = layer.maps.get(&param);
    let meaning = physical::describe(param, &layer.params);
    // One width for the names in every group's grid, so the values line up down the panel.
    ui.horizontal(|ui| {
        ui.set_min_width(NAME_WIDTH);
        if with_maps {
            map_choice(ui, session, param, bound, &meaning, actions);
        } else {
            ui.label(param.name()).on_hover_text(meaning);
        }
    });
    let value = layer.params.get(param);
    let mut changed = None;
    match value {
        Value::Color(mut rgb) => {
            ui.horizontal(|ui| {
                // egui's picker works in sRGB and hands back linear values, as stored; it
                // holds [0, 1], so emission above 1 is typed into the fields.
                if rgb.iter().all(|&c| c <= 1.0)
                    && egui::widgets::color_picker::color_edit_button_rgb(ui, &mut rgb).changed()
                {
                    changed = Some(Value::Color(rgb));
                }
                for channel in 0..3 {
                    let drag =
                        egui::DragValue::new(&mut rgb[channel]).range(0.0..=param.max()).speed(0.002).max_decimals(4);
                    if ui.add(drag).on_hover_text("Linear value").changed() {
                        changed = Some(Value::Color(rgb));
                    }
                }
            });
        }
        Value::Scalar(mut v) => {
            ui.horizontal(|ui| {
                // The slider spans the plausible range; the field takes typed values up
                // to the format's limit.
                let slider =
                    egui::Slider::new(&mut v, 0.0..=1.0).show_value(false).clamping(egui::SliderClamping::Never);
                if ui.add(slider).changed() {
                    changed = Some(Value::Scalar(v.clamp(0.0, param.max())));
                }
                let field = egui::DragValue::new(&mut v).range(0.0..=param.max()).speed(0.005).max_decimals(4);
                if ui.add(field).on_hover_text(format!("0 to {}", param.max())).changed() {
                    changed = Some(Value::Scalar(v));
                }
            });
        }
    }
    if let Some(value) = changed {
        actions.push(Action::Drag(Edit::SetParam { object, layer: index, param, value }));
    }
    let reset = ui.add_enabled(overridden, egui::Button::new("↺").small());
    if reset.on_hover_text("Reset to the preset's value").clicked() {
        actions.push(Action::Edit(Edit::ResetParam { object, layer: index, param }));
    }
}

/// The parameter's name as a menu of the g-buffer's maps it can be bound to: blue when bound,
/// with the map named on hover.
fn map_choice(
    ui: &mut egui::Ui,
    session: &Session,
    param: Param,
    bound: Option<&String>,
    meaning: &str,
    actions: &mut Vec<Action>,
) {
    let mut title = RichText::new(param.name());
    if bound.is_some() {
        title = title.color(ui.visuals().hyperlink_color);
    }
    let menu = ui.menu_button(title, |ui| {
        if ui.selectable_label(bound.is_none(), "no map").clicked() {
            if bound.is_some() {
                actions.push(Action::SetMap { param, map: None });
            }
            ui.close();
        }
        for map in bindable_maps(param, &session.gbuffer) {
            if ui.selectable_label(bound == Some(&map), format!("map.{map}")).clicked() {
                if bound != Some(&map) {
                    actions.push(Action::SetMap { param, map: Some(map.clone()) });
                }
                ui.close();
            }
        }
    });
    menu.response.on_hover_text(match bound {
        Some(map) => format!("{meaning}\n\nBound: the value times map.{map} at each pixel. Click to change."),
        None => format!("{meaning}\n\nClick to bind to a g-buffer map"),
    });
}

/// A filled dot for an overridden parameter, a ring for one at its preset's value.
fn override_dot(ui: &mut egui::Ui, overridden: bool) -> egui::Response {
    let (rect, response) = ui.allocate_exact_size(egui::vec2(12.0, 12.0), egui::Sense::hover());
    if overridden {
        ui.painter().circle_filled(rect.center(), 4.0, ui.visuals().warn_fg_color);
    } else {
        ui.painter().circle_stroke(rect.center(), 3.5, egui::Stroke::new(1.0, Color32::from_gray(110)));
    }
    response
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gpu::{Context, ContextOptions};
    use crate::material::params::Group;
    use crate::render::scene::{GBufferSpec, Scene, SceneSpec};
    use crate::viewer_state::Document;

    /// The panel shows the selected layer's parameters under their groups' headers, in the
    /// table's order: each name after its own header and before the next.
    #[test]
    fn the_parameters_show_under_their_groups() {
        let shown = panel_texts(None, ObjectRef::Id(1));
        let at =
            |text: &str| shown.iter().position(|t| t == text).unwrap_or_else(|| panic!("no '{text}' in {shown:?}"));
        let headers: Vec<usize> = GROUPS.iter().map(|(group, _)| at(group.name())).collect();
        assert!(headers.windows(2).all(|w| w[0] < w[1]), "the groups in order: {shown:?}");
        for (index, (group, params)) in GROUPS.iter().enumerate() {
            let end = headers.get(index + 1).copied().unwrap_or(usize::MAX);
            for param in params.iter() {
                let place = at(param.name());
                assert!(headers[index] < place && place < end, "{param} is not under {}: {shown:?}", group.name());
            }
        }
        assert_eq!(Group::Base.params()[0], Param::BaseColor);
    }

    /// The panel's texts for `look` (the built-in one when None) on the 32² shader ball, with
    /// `object` selected.
    fn panel_texts(look: Option<&str>, object: ObjectRef) -> Vec<String> {
        let ctx = Context::new(&ContextOptions::from_env(std::env::var("LOOKDEV_TEST_DEVICE").ok())).unwrap();
        let look = look.map(|text| {
            crate::render::scene::LookSource::Given(Box::new(
                crate::material::look::Look::parse(text, std::path::Path::new("test.toml")).unwrap(),
            ))
        });
        let spec = SceneSpec {
            gbuffer: GBufferSpec { builtin_size: Some((32, 32)), ..GBufferSpec::default() },
            look: look.unwrap_or_default(),
            ..SceneSpec::default()
        };
        let scene = Scene::load(&spec).unwrap();
        let mut document = Document::new(scene.look.clone(), None, scene.settings.clone());
        document.select(Selection { object: Some(object), layer: Some(0) });
        let session = Session::of_scene(&ctx, scene, document).unwrap();
        let egui = egui::Context::default();
        let mut shown = Vec::new();
        for _ in 0..2 {
            let output = egui.run_ui(egui::RawInput::default(), |ui| {
                egui::ScrollArea::vertical().show(ui, |ui| show(ui, &session, &mut Vec::new()));
            });
            shown.clear();
            output.shapes.iter().for_each(|clipped| super::super::shape_texts(&clipped.shape, &mut shown));
        }
        drop(session);
        drop(ctx);
        shown
    }

    /// The built-in look gives both objects stacks of their own: its default stack is marked as
    /// one no pixel uses, in the list and over the stack. Where an object shows it, it is not.
    #[test]
    fn a_default_stack_no_pixel_uses_is_marked() {
        let texts = panel_texts(None, ObjectRef::Default);
        assert!(texts.iter().any(|t| t == "Default stack (no pixel uses it)"), "{texts:?}");
        assert!(texts.iter().any(|t| t.starts_with("No pixel uses this stack")), "{texts:?}");
        let ball_only = "[[object]]\n[[object.layer]]\npreset = \"gold\"\n[[object]]\nid = 1\n[[object.layer]]\npreset = \"chrome\"\n";
        let texts = panel_texts(Some(ball_only), ObjectRef::Default);
        assert!(texts.iter().any(|t| t == "Default stack"), "{texts:?}");
        assert!(!texts.iter().any(|t| t.contains("no pixel") || t.starts_with("No pixel")), "{texts:?}");
    }

    /// Dropped above or below any layer, dragging up or down, a layer lands next to it, on the
    /// side the drop line showed, and the others keep their order.
    /// A layer's own name replaces its preset's in the stack and the heading, and a layer whose
    /// mask is adjusted says so in the stack.
    #[test]
    fn named_and_adjusted_layers_say_so() {
        let look = "[[object]]\nid = 1\n[[object.layer]]\nname = \"Base coat\"\npreset = \"blue-rubber\"\n\
                    [[object.layer]]\npreset = \"gold\"\nmask = \"stripes\"\nmask_blur = 2\n";
        let texts = panel_texts(Some(look), ObjectRef::Id(1));
        assert!(texts.iter().any(|t| t == "Base coat"), "{texts:?}");
        assert!(texts.iter().any(|t| t == "Layer 0: Base coat"), "{texts:?}");
        assert!(texts.iter().any(|t| t == "gold · stripes (adjusted)"), "{texts:?}");
        assert!(!texts.iter().any(|t| t.contains("blue-rubber")), "the preset's name gives way: {texts:?}");
    }

    #[test]
    fn a_dropped_layer_lands_where_the_line_shows() {
        let count = 4;
        for from in 0..count {
            for onto in (0..count).filter(|&onto| onto != from) {
                for above in [true, false] {
                    let mut stack: Vec<usize> = (0..count).collect();
                    let moved = stack.remove(from);
                    stack.insert(drop_index(from, onto, above), moved);
                    let at = |layer: usize| stack.iter().position(|&l| l == layer).unwrap();
                    let expected = if above { at(onto) + 1 } else { at(onto) - 1 };
                    let side = if above { "above" } else { "below" };
                    assert_eq!(at(from), expected, "layer {from} dropped {side} layer {onto}: {stack:?}");
                    let others: Vec<usize> = stack.iter().copied().filter(|&l| l != from).collect();
                    assert!(others.windows(2).all(|w| w[0] < w[1]), "{stack:?}");
                }
            }
        }
    }

    #[test]
    fn a_layer_dropped_next_to_itself_stays() {
        // Just above the layer below it, or just below the layer above it: no move.
        assert_eq!(drop_index(2, 1, true), 2);
        assert_eq!(drop_index(2, 3, false), 2);
    }
}
