//! The right panel's upper half: the environment (file, rotation, intensity in linear units or
//! stops, background) and the render settings (exposure, tone map, target spp, seed).

use super::super::action::Action;
use super::super::session::Session;
use super::dialogs::{FileDialog, FilePurpose};
use super::viewport::wrap_degrees;
use crate::environment::backdrop::{self, Backdrop};
use crate::environment::{Builtin, EnvironmentRef, MAX_INTENSITY};
use crate::render::Lighting;
use crate::shading::tonemap::Tonemap;
use crate::viewer_state::Edit;

pub fn show(
    ui: &mut egui::Ui,
    session: &Session,
    file_dialog: &mut Option<FileDialog>,
    environments_open: &mut bool,
    actions: &mut Vec<Action>,
) {
    let settings = session.document.settings();
    ui.heading("Light");
    let current = EnvironmentRef::or_default(settings.environment.as_ref());
    ui.horizontal(|ui| {
        let hover = match &current {
            EnvironmentRef::Builtin(name) => Builtin::find(name).map_or(String::new(), |b| b.description.to_string()),
            EnvironmentRef::File(path) => path.display().to_string(),
        };
        ui.label(super::inspector::elide(&current.label())).on_hover_text(hover);
        if ui.button("Open…").clicked() {
            *file_dialog = Some(FileDialog::new(FilePurpose::OpenEnvironment));
        }
        if ui
            .button("Library…")
            .on_hover_text("Browse the environments (the Left and Right arrow keys step through them)")
            .clicked()
        {
            *environments_open = true;
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
        ui.label("");
        if let Some(stops) = stops_control(ui, lighting.intensity) {
            actions.push(Action::Drag(Edit::SetIntensity(stops.exp2())));
        }
        ui.end_row();
        ui.label("Background");
        background_controls(ui, &lighting, &settings.backdrop, actions);
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
        // The target the session renders to, as the progress bar counts it: with
        // --exit-after-spp that, and not the look's, which it leaves alone.
        let mut spp = session.target();
        match session.target_override() {
            Some(_) => {
                ui.add_enabled(false, egui::DragValue::new(&mut spp))
                    .on_disabled_hover_text(format!("Set by --exit-after-spp (the look's target is {})", settings.spp));
            }
            None => {
                if ui
                    .add(egui::DragValue::new(&mut spp).range(1..=1_000_000))
                    .on_hover_text("Accumulation stops here")
                    .changed()
                {
                    actions.push(Action::Drag(Edit::SetTargetSpp(spp)));
                }
            }
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

/// The intensity in stops, 2^EV = intensity, as a drag value beside the linear slider: the same
/// value, so each follows the other. Returns the stops dragged to. An intensity of 0 is shown
/// as the fewest stops an intensity may have.
fn stops_control(ui: &mut egui::Ui, intensity: f32) -> Option<f32> {
    let most = MAX_INTENSITY.log2();
    let mut stops = if intensity > 0.0 { intensity.log2() } else { -most };
    let drag = egui::DragValue::new(&mut stops).range(-most..=most).speed(0.02).suffix(" stops").max_decimals(2);
    ui.add(drag).on_hover_text("The intensity in stops: each stop doubles it").changed().then_some(stops)
}

/// The background's menu (none, environment, blurred, colour, another environment) and the
/// control of the chosen one: the blur in degrees, the colour, or the environment's name.
fn background_controls(ui: &mut egui::Ui, lighting: &Lighting, backdrop: &Backdrop, actions: &mut Vec<Action>) {
    let shown = if lighting.background { backdrop.label() } else { "none" };
    let choices = [
        ("none", None),
        ("environment", Some(Backdrop::Environment)),
        ("blurred", Some(Backdrop::Blurred(backdrop::DEFAULT_BLUR_DEGREES))),
        ("colour", Some(Backdrop::Colour([0.18; 3]))),
        ("other environment", Some(Backdrop::Other(EnvironmentRef::Builtin(Builtin::default_one().name)))),
    ];
    ui.vertical(|ui| {
        egui::ComboBox::from_id_salt("background").selected_text(shown).show_ui(ui, |ui| {
            for (label, choice) in choices {
                if !ui.selectable_label(shown == label, label).clicked() || shown == label {
                    continue;
                }
                actions.push(Action::Edit(match choice {
                    None => Edit::SetBackground(false),
                    // The kind of background it last was keeps its own values.
                    Some(choice) if choice.label() == backdrop.label() => Edit::SetBackdrop(backdrop.clone()),
                    Some(choice) => Edit::SetBackdrop(choice),
                }));
            }
        });
        if !lighting.background {
            return;
        }
        match backdrop {
            Backdrop::Environment => {}
            Backdrop::Blurred(degrees) => {
                let mut degrees = *degrees;
                let slider =
                    egui::Slider::new(&mut degrees, 0.5..=backdrop::MAX_BLUR_DEGREES).suffix("°").max_decimals(1);
                if ui.add(slider).on_hover_text("The blur's standard deviation").changed() {
                    actions.push(Action::Drag(Edit::SetBackdrop(Backdrop::Blurred(degrees))));
                }
            }
            Backdrop::Colour(rgb) => {
                let mut rgb = *rgb;
                if egui::color_picker::color_edit_button_rgb(ui, &mut rgb).on_hover_text("Linear RGB").changed() {
                    actions.push(Action::Drag(Edit::SetBackdrop(Backdrop::Colour(rgb.map(|c| c.max(0.0))))));
                }
            }
            Backdrop::Other(other) => {
                egui::ComboBox::from_id_salt("background environment").selected_text(other.label()).show_ui(ui, |ui| {
                    for builtin in crate::environment::builtin::BUILTINS {
                        let choice = EnvironmentRef::Builtin(builtin.name);
                        if ui.selectable_label(*other == choice, builtin.name).clicked() && *other != choice {
                            actions.push(Action::Edit(Edit::SetBackdrop(Backdrop::Other(choice))));
                        }
                    }
                });
            }
        }
    });
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gpu::{Context, ContextOptions};
    use crate::render::scene::{Scene, SceneSpec};
    use crate::viewer_state::Document;

    /// The panel's text, drawn once in a headless egui context.
    fn panel_text(session: &Session) -> Vec<String> {
        let ctx = egui::Context::default();
        let mut actions = Vec::new();
        let mut out = Vec::new();
        for _ in 0..2 {
            // The second pass lays out with the sizes the first measured.
            let output =
                ctx.run_ui(egui::RawInput::default(), |ui| show(ui, session, &mut None, &mut false, &mut actions));
            out.clear();
            output.shapes.iter().for_each(|clipped| super::super::shape_texts(&clipped.shape, &mut out));
        }
        out
    }

    #[test]
    fn the_target_spp_shown_is_the_one_the_session_renders_to() {
        let ctx = Context::new(&ContextOptions::from_env(std::env::var("LOOKDEV_TEST_DEVICE").ok())).unwrap();
        let scene = Scene::load(&SceneSpec::default()).unwrap();
        let document = Document::new(scene.look.clone(), None, scene.settings.clone());
        let look_target = document.settings().spp;
        assert_ne!(look_target, 16, "the look's own target differs from the override");
        let mut session = Session::of_scene(&ctx, scene, document).unwrap();
        let text = panel_text(&session);
        assert!(text.contains(&look_target.to_string()), "{text:?}");

        // --exit-after-spp 16: the panel's field and its bar both say 16, the look keeps its own.
        session.override_target(16);
        let text = panel_text(&session);
        assert!(text.contains(&"16".to_string()), "the target field shows 16: {text:?}");
        assert!(text.contains(&"0 / 16 spp".to_string()), "{text:?}");
        assert!(!text.contains(&look_target.to_string()), "the look's target is not shown as the target: {text:?}");
        assert_eq!(session.document.settings().spp, look_target);
        drop(session);
        drop(ctx);
    }
}
