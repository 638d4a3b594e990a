//! The pixel inspector: what a click in the image found there.

use super::super::session::Session;
use crate::material::params::{Param, Value};
use egui::RichText;

/// The most characters a name takes in the inspector's grid, and as the light's environment: a
/// longer one is cut with "…" (the whole name on hover), so that what follows stays in view.
const NAME_CHARS: usize = 28;

/// `text`, cut to [`NAME_CHARS`] characters with "…" if longer.
pub(super) fn elide(text: &str) -> String {
    match text.char_indices().nth(NAME_CHARS - 1) {
        Some((end, _)) if text.chars().count() > NAME_CHARS => format!("{}…", &text[..end]),
        _ => text.to_string(),
    }
}

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
        let object = format!("{}{name}", pixel.object_id);
        ui.label(elide(&object)).on_hover_text(object);
        ui.end_row();
        ui.label("Coverage");
        ui.label(format!("{:.3}", pixel.coverage));
        ui.end_row();
        for (name, value) in &pixel.masks {
            let channel = format!("mask.{name}");
            let label = ui.label(elide(&channel));
            match pixel.mask_names.iter().find(|(mask, _)| mask == name) {
                Some((_, full)) => label.on_hover_text(full.as_str()),
                None => label.on_hover_text(channel),
            };
            ui.label(format!("{value:.3}"));
            ui.end_row();
        }
        for (name, value) in &pixel.maps {
            let channel = format!("map.{name}");
            ui.label(elide(&channel)).on_hover_text(channel);
            ui.label(format!("{value:.3}"));
            ui.end_row();
        }
        if let Some(occlusion) = pixel.occlusion {
            ui.label("Sky seen").on_hover_text(
                "The cosine-weighted share of the hemisphere that sees the environment (the occlusion AOV)",
            );
            ui.label(format!("{occlusion:.3}"));
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn long_names_are_cut_to_a_fixed_width() {
        assert_eq!(elide("mask.stripes"), "mask.stripes");
        let long = "mask.the_long_production_asset_name_v042";
        let cut = elide(long);
        assert_eq!(cut.chars().count(), NAME_CHARS);
        assert!(cut.ends_with('…') && long.starts_with(cut.trim_end_matches('…')), "{cut}");
        assert_eq!(elide(&"é".repeat(NAME_CHARS)), "é".repeat(NAME_CHARS), "a name of exactly the width stays");
    }
}
