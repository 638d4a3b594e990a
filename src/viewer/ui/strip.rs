//! The strip of recent snapshots under the image, as in Arnold's RenderView: thumbnails, newest
//! first and as many as fit, each with its name and samples; a click compares one with the live
//! image, and the one compared is framed.

use egui::{pos2, vec2, Color32, Rect, Sense};

/// Thumbnails' height in points: the strip stays thin.
const THUMBNAIL: f32 = 48.0;
/// The narrowest a cell is, so that a name has room under a tall image's thumbnail.
const MIN_WIDTH: f32 = 72.0;
/// The widest a thumbnail is, so that a panorama leaves room for others.
const MAX_WIDTH: f32 = 4.0 * THUMBNAIL;
/// The labels' font size, and the height of each of their two lines.
const FONT: f32 = 11.0;
const LINE: f32 = 14.0;
/// The strip's height with its margins: the same with or without snapshots, so that taking the
/// first one neither moves nor rescales the image.
pub const HEIGHT: f32 = THUMBNAIL + 2.0 * LINE + 16.0;

/// One snapshot in the strip.
pub struct Item<'a> {
    pub id: u64,
    pub name: &'a str,
    pub spp: u32,
    /// Its display image.
    pub texture: egui::TextureId,
    /// Its width over its height.
    pub aspect: f32,
}

/// Draws `items` (newest first) left to right while they fit, framing the one `compared`.
/// Returns the index of the one clicked.
pub fn show(ui: &mut egui::Ui, items: &[Item], compared: Option<u64>) -> Option<usize> {
    let mut clicked = None;
    ui.horizontal(|ui| {
        ui.spacing_mut().item_spacing.x = 8.0;
        for (index, item) in items.iter().enumerate() {
            let thumbnail = vec2((THUMBNAIL * item.aspect).min(MAX_WIDTH), THUMBNAIL);
            let width = thumbnail.x.max(MIN_WIDTH);
            // Whole cells only: a cut thumbnail would read as another image.
            if ui.available_width() < width {
                break;
            }
            if cell(ui, item, thumbnail, width, compared == Some(item.id)).clicked() {
                clicked = Some(index);
            }
        }
    });
    clicked
}

/// One snapshot's cell: its thumbnail, its name and its samples, framed when it is compared.
fn cell(ui: &mut egui::Ui, item: &Item, thumbnail: egui::Vec2, width: f32, compared: bool) -> egui::Response {
    let (rect, response) = ui.allocate_exact_size(vec2(width, THUMBNAIL + 2.0 * LINE), Sense::click());
    let painter = ui.painter_at(rect.expand(3.0));
    let image = Rect::from_min_size(pos2(rect.center().x - thumbnail.x / 2.0, rect.min.y), thumbnail);
    let whole = Rect::from_min_max(pos2(0.0, 0.0), pos2(1.0, 1.0));
    painter.image(item.texture, image, whole, Color32::WHITE);
    let visuals = ui.visuals();
    let font = egui::FontId::proportional(FONT);
    let name_color = if compared { visuals.strong_text_color() } else { visuals.text_color() };
    let lines = [(item.name.to_string(), name_color), (format!("{} spp", item.spp), visuals.weak_text_color())];
    for (row, (text, color)) in lines.into_iter().enumerate() {
        let mut job = egui::text::LayoutJob::simple_singleline(text, font.clone(), color);
        // A long name ends in an ellipsis rather than running into the next cell.
        job.wrap = egui::text::TextWrapping::truncate_at_width(width);
        let galley = painter.layout_job(job);
        let top = image.max.y + 1.0 + row as f32 * LINE;
        painter.galley(pos2(rect.center().x - galley.size().x / 2.0, top), galley, color);
    }
    if compared {
        painter.rect_stroke(rect.expand(2.0), 3.0, visuals.selection.stroke, egui::StrokeKind::Outside);
    } else if response.hovered() {
        painter.rect_stroke(rect.expand(2.0), 3.0, visuals.widgets.hovered.bg_stroke, egui::StrokeKind::Outside);
    }
    let hint = if compared {
        "compared with the live image (B flips to it)"
    } else {
        "click to compare it with the live image"
    };
    response.on_hover_text(format!("{}: {} spp; {hint}", item.name, item.spp))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A text drawn in the strip, and where.
    struct Text {
        text: String,
        at: egui::Pos2,
    }

    fn texts(shape: &egui::Shape, out: &mut Vec<Text>) {
        match shape {
            egui::Shape::Text(text) => out.push(Text { text: text.galley.text().to_string(), at: text.pos }),
            egui::Shape::Vec(shapes) => shapes.iter().for_each(|s| texts(s, out)),
            _ => {}
        }
    }

    /// The strip as a bottom panel of a window `width` points wide, one frame per event list:
    /// what each frame drew, and what was clicked.
    fn frames(
        width: f32,
        names: &[&str],
        compared: Option<u64>,
        events: Vec<Vec<egui::Event>>,
    ) -> Vec<(Vec<Text>, Vec<egui::Shape>, Option<usize>)> {
        let ctx = egui::Context::default();
        ctx.set_visuals(egui::Visuals::dark());
        let image = egui::ColorImage::from_rgba_unmultiplied([2, 2], &[128; 16]);
        let texture = ctx.load_texture("strip-test", image, egui::TextureOptions::NEAREST);
        // Newest first, as the snapshot panel gives them; ids count down from the newest.
        let items: Vec<Item> = names
            .iter()
            .enumerate()
            .map(|(i, name)| Item {
                id: (names.len() - i) as u64,
                name,
                spp: 4 * (i as u32 + 1),
                texture: texture.id(),
                aspect: 1.0,
            })
            .collect();
        let screen = Rect::from_min_size(pos2(0.0, 0.0), vec2(width, 400.0));
        events
            .into_iter()
            .map(|events| {
                let input = egui::RawInput { screen_rect: Some(screen), events, ..Default::default() };
                let mut clicked = None;
                let output = ctx.run_ui(input, |ui| {
                    egui::Panel::bottom("strip").exact_size(HEIGHT).show(ui, |ui| {
                        clicked = show(ui, &items, compared);
                    });
                });
                let mut drawn = Vec::new();
                output.shapes.iter().for_each(|clipped| texts(&clipped.shape, &mut drawn));
                let shapes = output.shapes.into_iter().map(|clipped| clipped.shape).collect();
                (drawn, shapes, clicked)
            })
            .collect()
    }

    fn names(drawn: &[Text]) -> Vec<&str> {
        drawn.iter().map(|t| t.text.as_str()).filter(|t| !t.ends_with("spp")).collect()
    }

    /// Newest first, each with its samples, and only as many as fit: a narrow window shows the
    /// newest ones whole and leaves the rest out.
    #[test]
    fn the_strip_shows_the_newest_snapshots_that_fit_with_their_samples() {
        let all = ["e", "d", "c", "b", "a"];
        let (wide, _, _) = &frames(1000.0, &all, None, vec![vec![], vec![]])[1];
        assert_eq!(names(wide), all, "all fit");
        assert!(wide.iter().any(|t| t.text == "4 spp") && wide.iter().any(|t| t.text == "20 spp"));
        let (narrow, _, _) = &frames(250.0, &all, None, vec![vec![], vec![]])[1];
        let shown = names(narrow);
        assert!(!shown.is_empty() && shown.len() < all.len(), "{shown:?}");
        assert_eq!(shown, all[..shown.len()], "the newest ones");
    }

    /// A click on a cell gives its index; the one compared is framed in the selection's colour.
    #[test]
    fn a_click_picks_a_snapshot_and_the_compared_one_is_framed() {
        let all = ["new", "old"];
        let (drawn, _, _) = &frames(1000.0, &all, None, vec![vec![], vec![]])[1];
        let at = drawn.iter().find(|t| t.text == "old").expect("drawn").at + vec2(2.0, -10.0);
        let button = |pressed| egui::Event::PointerButton {
            pos: at,
            button: egui::PointerButton::Primary,
            pressed,
            modifiers: egui::Modifiers::NONE,
        };
        let clicks = vec![vec![], vec![egui::Event::PointerMoved(at)], vec![button(true)], vec![button(false)]];
        let clicked: Vec<Option<usize>> = frames(1000.0, &all, None, clicks).into_iter().map(|f| f.2).collect();
        assert_eq!(clicked, [None, None, None, Some(1)]);

        let framed = |compared: Option<u64>| -> Vec<Rect> {
            let (_, shapes, _) = frames(1000.0, &all, compared, vec![vec![], vec![]]).pop().unwrap();
            let selection = egui::Visuals::dark().selection.stroke;
            let mut rects = Vec::new();
            for shape in &shapes {
                if let egui::Shape::Rect(rect) = shape {
                    if rect.stroke == selection {
                        rects.push(rect.rect);
                    }
                }
            }
            rects
        };
        assert!(framed(None).is_empty());
        // "old" is id 1: its frame holds its name.
        let old = framed(Some(1));
        assert_eq!(old.len(), 1);
        let name = drawn.iter().find(|t| t.text == "old").unwrap().at;
        assert!(old[0].contains(name), "{old:?} frames {name:?}");
    }
}
