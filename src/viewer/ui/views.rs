//! The views' part of the interface: their hotkeys and View menu entries, the name plate and
//! the false-colour legend by the image, the clipping overlay over it, the value under the
//! cursor in the status bar, and the histogram panel.

use super::super::action::Action;
use super::super::session::Session;
use super::super::view_image::Views;
use super::super::views::{self, Axis, View, ViewChoice, FALSE_COLOURS};
use egui::{pos2, vec2, Color32, Key, Modifiers, Rect};

/// `C` and `Shift+C` step through the views, `M` returns to the beauty, `E` toggles false
/// colour and `X` the clipping overlay.
pub fn shortcuts(input: &mut egui::InputState, actions: &mut Vec<Action>) {
    // Shift+C first: a plain C would also match it.
    if input.consume_key(Modifiers::SHIFT, Key::C) {
        actions.push(Action::View(ViewChoice::Previous));
    } else if input.consume_key(Modifiers::NONE, Key::C) {
        actions.push(Action::View(ViewChoice::Next));
    }
    if input.consume_key(Modifiers::NONE, Key::M) {
        actions.push(Action::View(ViewChoice::Beauty));
    }
    if input.consume_key(Modifiers::NONE, Key::E) {
        actions.push(Action::View(ViewChoice::FalseColour));
    }
    if input.consume_key(Modifiers::NONE, Key::X) {
        actions.push(Action::Clipping(None));
    }
}

/// The View menu's entries for views: the hotkeys, then every view by group.
pub fn menu(ui: &mut egui::Ui, session: &Session, state: &Views, actions: &mut Vec<Action>) {
    let current = state.current();
    if ui.add(egui::Button::new("Beauty").selected(*current == View::Beauty).shortcut_text("M")).clicked() {
        actions.push(Action::View(ViewChoice::Beauty));
    }
    if ui.add(egui::Button::new("Next view").shortcut_text("C")).clicked() {
        actions.push(Action::View(ViewChoice::Next));
    }
    if ui.add(egui::Button::new("Previous view").shortcut_text("Shift+C")).clicked() {
        actions.push(Action::View(ViewChoice::Previous));
    }
    let false_colour =
        egui::Button::new("False colour (EV)").selected(*current == View::FalseColour).shortcut_text("E");
    if ui.add(false_colour).clicked() {
        actions.push(Action::View(ViewChoice::FalseColour));
    }
    if ui.add(egui::Button::new("Clipping overlay").selected(state.clipping).shortcut_text("X")).clicked() {
        actions.push(Action::Clipping(None));
    }
    let all = Views::list(session);
    let mut groups: Vec<&str> = all.iter().map(View::group).filter(|g| !g.is_empty()).collect();
    groups.dedup();
    for group in groups {
        ui.menu_button(group, |ui| {
            egui::ScrollArea::vertical().max_height(400.0).show(ui, |ui| {
                for view in all.iter().filter(|v| v.group() == group) {
                    if ui.add(egui::Button::new(view.name()).selected(view == current)).clicked() {
                        actions.push(Action::View(ViewChoice::Named(view.name())));
                    }
                }
            });
        });
    }
}

/// The status bar's view part: the view's name, and the values under the cursor.
pub fn status(state: &Views, hovered: Option<(u32, u32)>) -> String {
    let described = hovered.zip(state.image()).and_then(|((x, y), image)| image.describe(x, y));
    match described {
        Some(line) => line,
        None if state.waiting() => format!("view {} (rendering…)", state.current().name()),
        None => format!("view {}", state.current().name()),
    }
}

/// Over and by the image: the mask and clipping overlays (on A's part in a split), and for a view other
/// than the beauty its name on a plate above the image's top-left corner, and for false colour
/// the legend under the image. Plates sit outside the image where the view has room, so that
/// the image's pixels stay as shown.
pub fn decorate(
    ui: &egui::Ui,
    session: &Session,
    state: &Views,
    mask_overlay: Option<egui::TextureId>,
    image: Option<Rect>,
) {
    let Some(image) = image else { return };
    let view = ui.max_rect();
    let painter = ui.painter_at(view);
    // Overlays cover A's part of a split only.
    let u = session.split_column().map_or(1.0, |c| c as f32 / session.width() as f32);
    let a_rect = Rect::from_min_max(image.min, pos2(image.min.x + image.width() * u, image.max.y));
    let a_uv = Rect::from_min_max(pos2(0.0, 0.0), pos2(u, 1.0));
    for overlay in [mask_overlay, state.overlay()].into_iter().flatten() {
        painter.image(overlay, a_rect, a_uv, Color32::WHITE);
    }
    let current = state.current();
    let mut label = match current {
        View::Beauty => String::new(),
        _ if state.waiting() => format!("{} (rendering…)", current.name()),
        _ => current.name(),
    };
    if state.clipping {
        label = if label.is_empty() { "clipping".into() } else { format!("{label} · clipping") };
    }
    if !label.is_empty() {
        let font = egui::FontId::proportional(12.0);
        let galley = painter.layout_no_wrap(label, font, Color32::WHITE);
        let size = galley.size() + vec2(8.0, 6.0);
        // Above the image where there is room, else inside its top-left corner.
        let top = if image.min.y - size.y - 2.0 >= view.min.y { image.min.y - size.y - 2.0 } else { image.min.y + 2.0 };
        let rect = Rect::from_min_size(pos2(image.min.x.max(view.min.x + 2.0), top), size);
        painter.rect_filled(rect, 2.0, Color32::from_black_alpha(170));
        painter.galley(rect.min + vec2(4.0, 3.0), galley, Color32::WHITE);
    }
    if *current == View::FalseColour {
        legend(&painter, view, image);
    }
}

/// The false-colour bands, a swatch each with its stops, in a row under the image (or over its
/// bottom edge where the view has no room below it).
fn legend(painter: &egui::Painter, view: Rect, image: Rect) {
    let swatch = vec2(30.0, 16.0);
    let caption = painter.layout_no_wrap(
        "stops about 18% grey".into(),
        egui::FontId::proportional(10.0),
        Color32::from_gray(180),
    );
    let swatches = swatch.x * FALSE_COLOURS.len() as f32;
    let width = swatches + 6.0 + caption.size().x;
    let height = swatch.y + 14.0;
    let top = legend_top(view, image, height);
    // Centred under the image, kept inside the view.
    let left = (image.center().x - width / 2.0).min(view.max.x - width - 4.0).max(view.min.x + 4.0);
    painter.rect_filled(
        Rect::from_min_size(pos2(left - 2.0, top - 2.0), vec2(width + 6.0, height + 4.0)),
        2.0,
        Color32::from_black_alpha(190),
    );
    for (i, (colour, label)) in FALSE_COLOURS.iter().enumerate() {
        let min = pos2(left + i as f32 * swatch.x, top);
        painter.rect_filled(Rect::from_min_size(min, swatch), 0.0, Color32::from_rgb(colour[0], colour[1], colour[2]));
        painter.text(
            min + vec2(swatch.x / 2.0, swatch.y + 1.0),
            egui::Align2::CENTER_TOP,
            *label,
            egui::FontId::proportional(10.0),
            Color32::from_gray(220),
        );
    }
    let at = pos2(left + swatches + 6.0, top + (swatch.y - caption.size().y) / 2.0);
    painter.galley(at, caption, Color32::from_gray(180));
}

/// Where the legend's top goes: under the image where there is room above the view's footer
/// (the hint line and the pixel readout), else over the image's bottom edge, and never in the
/// footer.
fn legend_top(view: Rect, image: Rect, height: f32) -> f32 {
    let floor = view.max.y - super::viewport::FOOTER;
    let top = if image.max.y + 4.0 + height <= floor { image.max.y + 4.0 } else { image.max.y - height - 2.0 };
    top.min(floor - height - 2.0)
}

/// The histogram of the current view's luminance: stops about 18% grey for radiance views,
/// values in [0, 1] for the rest.
pub fn histogram(ui: &mut egui::Ui, state: &Views) {
    ui.heading("Histogram");
    let Some(histogram) = state.image().and_then(|i| i.histogram.as_ref()) else {
        let why = if matches!(state.current(), View::Aov(crate::render::aov::Aov::ObjectId)) {
            "object ids are not quantities"
        } else {
            "waiting for samples"
        };
        ui.label(why);
        return;
    };
    let (rect, _) = ui.allocate_exact_size(vec2(ui.available_width().min(280.0), 80.0), egui::Sense::hover());
    let painter = ui.painter_at(rect);
    painter.rect_filled(rect, 2.0, Color32::from_gray(24));
    let most = histogram.bins.iter().copied().max().unwrap_or(0).max(1) as f32;
    let bar = rect.width() / histogram.bins.len() as f32;
    for (i, &count) in histogram.bins.iter().enumerate() {
        // Square-root heights, so that a few pixels still show beside a large flat area.
        let height = (count as f32 / most).sqrt() * (rect.height() - 2.0);
        let x = rect.min.x + i as f32 * bar;
        painter.rect_filled(
            Rect::from_min_max(pos2(x, rect.max.y - height), pos2(x + bar.max(1.0), rect.max.y)),
            0.0,
            Color32::from_gray(190),
        );
    }
    let (left, middle, right, unit) = match histogram.axis {
        Axis::Stops => {
            (format!("{}", views::STOPS.0), "0".to_string(), format!("+{}", views::STOPS.1), "stops about 18% grey")
        }
        Axis::Unit => ("0".into(), "0.5".into(), "1".into(), "value"),
    };
    if histogram.axis == Axis::Stops {
        let x = rect.center().x;
        painter
            .line_segment([pos2(x, rect.min.y), pos2(x, rect.max.y)], egui::Stroke::new(1.0, Color32::from_gray(90)));
    }
    ui.horizontal(|ui| {
        ui.small(left);
        ui.add_space((rect.width() / 2.0 - 30.0).max(0.0));
        ui.small(middle);
        ui.with_layout(egui::Layout::right_to_left(egui::Align::Center), |ui| ui.small(right));
    });
    ui.small(format!("{} · {} pixels", unit, histogram.counted));
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The legend never reaches into the footer, where the hint line is drawn: with the image
    /// filling the view to its bottom edge, it once sat on the hint, text on text.
    #[test]
    fn the_legend_stays_out_of_the_footer() {
        let view = Rect::from_min_max(pos2(0.0, 0.0), pos2(800.0, 600.0));
        let floor = view.max.y - super::super::viewport::FOOTER;
        for image_bottom in [300.0, 540.0, 560.0, 590.0, 600.0, 700.0] {
            let image = Rect::from_min_max(pos2(100.0, 0.0), pos2(700.0, image_bottom));
            let top = legend_top(view, image, 30.0);
            assert!(top + 30.0 <= floor, "image to {image_bottom}: the legend reaches {} past {floor}", top + 30.0);
            if image_bottom + 4.0 + 30.0 <= floor {
                assert_eq!(top, image_bottom + 4.0, "under the image where there is room");
            }
        }
    }
}
