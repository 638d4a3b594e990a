//! The right panel's Compare section: the A/B split on or off, B's model (a combo box per
//! key) or B's look file, swapping A and B, and the divider.

use super::super::action::{Action, Compare};
use super::super::compare::Subject;
use super::super::session::Session;
use super::dialogs::{FileDialog, FilePurpose};
use crate::shading::model::{Diffuse, Fresnel, Model, SpecularD, SpecularG, GTR_GAMMA_RANGE};

pub fn show(ui: &mut egui::Ui, session: &Session, file_dialog: &mut Option<FileDialog>, actions: &mut Vec<Action>) {
    ui.heading("Compare");
    let subject = session.compare_subject();
    let mut on = subject.is_some() || session.snapshot_compare().is_some();
    let toggle = ui
        .checkbox(&mut on, "A/B split")
        .on_hover_text("A (the edited look) left of the divider, B right of it; drag the divider in the image");
    if toggle.changed() {
        // B starts as A's own model: pick what to change below.
        actions.push(Action::Compare(if on {
            Compare::Model(keys(&Model::default(), &a_model(session)))
        } else {
            Compare::Off
        }));
    }
    if let Some(shown) = session.snapshot_compare() {
        ui.label(format!("B: snapshot {} ({}; see Snapshots)", shown.name, shown.view.label()));
    }
    let Some(subject) = subject else { return };
    let a = a_model(session);
    ui.horizontal(|ui| {
        let is_model = matches!(subject, Subject::Model(_));
        if ui.selectable_label(is_model, "Model").on_hover_text("B: this look under another BRDF model").clicked()
            && !is_model
        {
            actions.push(Action::Compare(Compare::Model(keys(&a, &a))));
        }
        if ui.selectable_label(!is_model, "Look…").on_hover_text("B: another look file").clicked() {
            *file_dialog = Some(FileDialog::new(FilePurpose::CompareLook));
        }
        if ui.button("Swap A/B").clicked() {
            actions.push(Action::Compare(Compare::Swap));
        }
    });
    match subject {
        Subject::Model(b) => model_choice(ui, &a, b, actions),
        Subject::Look { path, look } => {
            ui.label(format!("B: {}", path.display()));
            ui.label(format!("B's model: {}", look.model.unwrap_or_default().label()));
        }
    }
    let mut divider = session.divider;
    let slider = egui::Slider::new(&mut divider, 0.0..=1.0).text("divider").max_decimals(3);
    if ui.add(slider).changed() {
        actions.push(Action::Divider(divider));
    }
}

fn a_model(session: &Session) -> Model {
    session.document.settings().model
}

/// One combo box per key of B's model; a change asks for B = A's model with every key as chosen.
fn model_choice(ui: &mut egui::Ui, a: &Model, b: &Model, actions: &mut Vec<Action>) {
    let mut chosen = *b;
    egui::Grid::new("compare-model").num_columns(2).show(ui, |ui| {
        combo(ui, "diffuse", &mut chosen.diffuse, &Diffuse::ALL, Diffuse::name);
        combo(ui, "specular_d", &mut chosen.specular_d, &SpecularD::ALL, SpecularD::name);
        combo(ui, "specular_g", &mut chosen.specular_g, &SpecularG::ALL, SpecularG::name);
        combo(ui, "fresnel", &mut chosen.fresnel, &Fresnel::ALL, Fresnel::name);
        ui.label("gtr_gamma");
        let (lo, hi) = GTR_GAMMA_RANGE;
        ui.add_enabled(
            chosen.specular_d == SpecularD::Gtr,
            egui::DragValue::new(&mut chosen.gtr_gamma).range(lo..=hi).speed(0.02),
        );
        ui.end_row();
        ui.label("energy_compensation");
        ui.checkbox(&mut chosen.energy_compensation, "");
        ui.end_row();
    });
    if chosen != *b {
        actions.push(Action::Compare(Compare::Model(keys(a, &chosen))));
    }
}

fn combo<T: Copy + PartialEq>(ui: &mut egui::Ui, key: &str, value: &mut T, all: &[T], name: fn(T) -> &'static str) {
    ui.label(key);
    egui::ComboBox::from_id_salt(("compare", key)).selected_text(name(*value)).show_ui(ui, |ui| {
        for option in all {
            ui.selectable_value(value, *option, name(*option));
        }
    });
    ui.end_row();
}

/// The `KEY=VALUE` changes that make `b` from `a`; every key when none differs, so B is A's model.
fn keys(a: &Model, b: &Model) -> Vec<String> {
    let changed: Vec<String> = a
        .entries()
        .into_iter()
        .zip(b.entries())
        .filter(|(x, y)| x.1 != y.1)
        .map(|(_, (key, value))| format!("{key}={}", value.trim_matches('"')))
        .collect();
    if changed.is_empty() {
        b.entries().into_iter().map(|(key, value)| format!("{key}={}", value.trim_matches('"'))).collect()
    } else {
        changed
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_keys_remake_b_from_a() {
        let a = Model { diffuse: Diffuse::Lambert, ..Model::default() };
        let b = Model { fresnel: Fresnel::Conductor, energy_compensation: true, ..a };
        for (from, to) in [(a, b), (b, a), (a, a)] {
            let mut made = from;
            for key in keys(&from, &to) {
                made.set_from_text(&key).unwrap();
            }
            assert_eq!(made, to, "{:?}", keys(&from, &to));
        }
    }
}
