//! The right panel's upper half: the environment (file, rotation, intensity, background) and
//! the render settings (exposure, tone map, target spp, seed).

use super::super::action::Action;
use super::super::session::Session;
use super::dialogs::{FileDialog, FilePurpose};
use super::viewport::wrap_degrees;
use crate::shading::tonemap::Tonemap;
use crate::viewer_state::Edit;

pub fn show(ui: &mut egui::Ui, session: &Session, file_dialog: &mut Option<FileDialog>, actions: &mut Vec<Action>) {
    let settings = session.document.settings();
    ui.heading("Light");
    let name = settings
        .environment
        .as_ref()
        .map_or("studio (built-in)".to_string(), |p| p.file_name().unwrap_or(p.as_os_str()).to_string_lossy().into());
    ui.horizontal(|ui| {
        ui.label(name).on_hover_text(
            settings
                .environment
                .as_ref()
                .map_or("The embedded CC0 studio environment".into(), |p| p.display().to_string()),
        );
        if ui.button("Open…").clicked() {
            *file_dialog = Some(FileDialog::new(FilePurpose::OpenEnvironment));
        }
        if settings.environment.is_some() && ui.button("Studio").clicked() {
            actions.push(Action::OpenEnvironment(None));
        }
    });
    let lighting = settings.lighting;
    egui::Grid::new("light").num_columns(2).show(ui, |ui| {
        ui.label("Rotation");
        let mut rotation = lighting.rotation_degrees;
        let slider = egui::Slider::new(&mut rotation, -180.0..=180.0).suffix("°").max_decimals(1);
        if ui.add(slider).on_hover_text("Or Shift+drag in the image").changed() {
            actions.push(Action::Drag(Edit::SetRotation(wrap_degrees(rotation))));
        }
        ui.end_row();
        ui.label("Intensity");
        let mut intensity = lighting.intensity;
        let slider = egui::Slider::new(&mut intensity, 0.0..=4.0).clamping(egui::SliderClamping::Never).max_decimals(3);
        if ui.add(slider).changed() {
            actions.push(Action::Drag(Edit::SetIntensity(intensity.max(0.0))));
        }
        ui.end_row();
        ui.label("Background");
        let mut background = lighting.background;
        if ui.checkbox(&mut background, "show the environment").changed() {
            actions.push(Action::Edit(Edit::SetBackground(background)));
        }
        ui.end_row();
    });

    ui.separator();
    ui.heading("Render");
    egui::Grid::new("render").num_columns(2).show(ui, |ui| {
        ui.label("Exposure");
        let mut exposure = settings.exposure;
        let slider = egui::Slider::new(&mut exposure, -8.0..=8.0)
            .suffix(" EV")
            .clamping(egui::SliderClamping::Never)
            .max_decimals(2);
        if ui.add(slider).changed() {
            actions.push(Action::Drag(Edit::SetExposure(exposure)));
        }
        ui.end_row();
        ui.label("Tone map");
        egui::ComboBox::from_id_salt("tonemap").selected_text(settings.tonemap.name()).show_ui(ui, |ui| {
            for tonemap in Tonemap::ALL {
                if ui.selectable_label(settings.tonemap == tonemap, tonemap.name()).clicked() {
                    actions.push(Action::Edit(Edit::SetTonemap(tonemap)));
                }
            }
        });
        ui.end_row();
        ui.label("Target spp");
        let mut spp = settings.spp;
        if ui
            .add(egui::DragValue::new(&mut spp).range(1..=1_000_000))
            .on_hover_text("Accumulation stops here")
            .changed()
        {
            actions.push(Action::Drag(Edit::SetTargetSpp(spp)));
        }
        ui.end_row();
        ui.label("Seed");
        let mut seed = settings.seed;
        if ui.add(egui::DragValue::new(&mut seed)).changed() {
            actions.push(Action::Drag(Edit::SetSeed(seed)));
        }
        ui.end_row();
    });
    let progress = session.samples() as f32 / session.target().max(1) as f32;
    ui.add(egui::ProgressBar::new(progress.min(1.0)).text(format!("{} / {} spp", session.samples(), session.target())));
}
