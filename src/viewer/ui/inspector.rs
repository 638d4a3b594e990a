//! The pixel inspector: what a click in the image found there.

use super::super::session::Session;
use crate::material::params::{Param, Value};
use egui::RichText;

pub fn show(ui: &mut egui::Ui, session: &Session) {
    ui.heading("Inspector");
    let Some(pixel) = &session.inspection else {
        ui.label(RichText::new("Click the image to inspect a pixel.").weak());
        return;
    };
    egui::Grid::new("pixel").num_columns(2).show(ui, |ui| {
        ui.label("Pixel");
        ui.label(format!("{}, {}", pixel.x, pixel.y));
        ui.end_row();
        ui.label("Object");
        let name = pixel.object_name.as_ref().map(|n| format!(" ({n})")).unwrap_or_default();
        ui.label(format!("{}{name}", pixel.object_id));
        ui.end_row();
        ui.label("Coverage");
        ui.label(format!("{:.3}", pixel.coverage));
        ui.end_row();
        for (name, value) in &pixel.masks {
            let label = ui.label(format!("mask.{name}"));
            if let Some((_, full)) = pixel.mask_names.iter().find(|(mask, _)| mask == name) {
                label.on_hover_text(full.as_str());
            }
            ui.label(format!("{value:.3}"));
            ui.end_row();
        }
        for (name, value) in &pixel.maps {
            ui.label(format!("map.{name}"));
            ui.label(format!("{value:.3}"));
            ui.end_row();
        }
        ui.label("Radiance");
        let [r, g, b, a] = pixel.radiance;
        ui.label(format!("{r:.4}, {g:.4}, {b:.4}")).on_hover_text(format!(
            "Linear Rec.709 at {} spp; alpha {a:.3}; luminance {:.4}",
            pixel.samples,
            0.2126 * r + 0.7152 * g + 0.0722 * b
        ));
        ui.end_row();
    });
    if pixel.coverage <= 0.0 {
        ui.label(RichText::new("Background: no material here.").weak());
        return;
    }
    if let Some(stack) = pixel.stack {
        ui.label(RichText::new(format!("Layers of {stack}, top first")).strong());
        egui::Grid::new("weights").num_columns(3).show(ui, |ui| {
            ui.label(RichText::new("layer").weak());
            ui.label(RichText::new("blend").weak());
            ui.label(RichText::new("share").weak());
            ui.end_row();
            for (index, (label, weight)) in pixel.layers.iter().enumerate().rev() {
                ui.label(format!("{index}: {label}"));
                match weight {
                    Some(w) => {
                        ui.label(format!("{:.3}", w.blend));
                        ui.label(format!("{:.1}%", w.contribution * 100.0));
                    }
                    None => {
                        ui.label("hidden");
                        ui.label("");
                    }
                }
                ui.end_row();
            }
        });
    }
    ui.label(RichText::new("Resolved material").strong());
    egui::Grid::new("resolved").num_columns(2).show(ui, |ui| {
        for param in Param::ALL {
            ui.label(param.name());
            ui.label(match pixel.params.get(param) {
                Value::Scalar(v) => format!("{v:.4}"),
                Value::Color([r, g, b]) => format!("{r:.4}, {g:.4}, {b:.4}"),
            });
            ui.end_row();
        }
    });
}
