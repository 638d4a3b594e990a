//! Labelled grids of renders: preset contact sheets and parameter wedges.

use ab_glyph::{Font, FontRef, PxScale, ScaleFont};
use image::{Rgba, RgbaImage};

/// Sheet background and label colours (sRGB).
const PAPER: Rgba<u8> = Rgba([24, 24, 27, 255]);
const INK: [u8; 3] = [225, 225, 230];
const FAINT_INK: [u8; 3] = [140, 140, 150];

/// Draws text with the sans-serif face that egui also uses (Ubuntu Light).
pub struct Labeller {
    font: FontRef<'static>,
}

impl Default for Labeller {
    fn default() -> Self {
        Labeller {
            font: FontRef::try_from_slice(epaint_default_fonts::UBUNTU_LIGHT).expect("the embedded font parses"),
        }
    }
}

impl Labeller {
    /// The advance width of `text` at `size` pixels.
    pub fn width(&self, text: &str, size: f32) -> f32 {
        let font = self.font.as_scaled(PxScale::from(size));
        text.chars().map(|c| font.h_advance(font.glyph_id(c))).sum()
    }

    /// Draws `text` with its top-left at (x, y), `size` pixels high, alpha-blended in `color`.
    /// Text that would run past `max_width` is cut short with an ellipsis.
    #[allow(clippy::too_many_arguments)]
    pub fn draw(&self, image: &mut RgbaImage, text: &str, x: f32, y: f32, size: f32, color: [u8; 3], max_width: f32) {
        let text = self.fit(text, size, max_width);
        let font = self.font.as_scaled(PxScale::from(size));
        let mut caret = x;
        let baseline = y + font.ascent();
        for c in text.chars() {
            let id = font.glyph_id(c);
            let glyph = id.with_scale_and_position(PxScale::from(size), ab_glyph::point(caret, baseline));
            caret += font.h_advance(id);
            let Some(outline) = self.font.outline_glyph(glyph) else {
                continue;
            };
            let bounds = outline.px_bounds();
            outline.draw(|gx, gy, coverage| {
                let (px, py) = (bounds.min.x as i64 + gx as i64, bounds.min.y as i64 + gy as i64);
                if px >= 0 && py >= 0 && (px as u32) < image.width() && (py as u32) < image.height() {
                    let pixel = image.get_pixel_mut(px as u32, py as u32);
                    for (channel, over) in pixel.0.iter_mut().zip(color) {
                        let (under, over) = (*channel as f32, over as f32);
                        *channel = (under + (over - under) * coverage.clamp(0.0, 1.0)).round() as u8;
                    }
                }
            });
        }
    }

    fn fit(&self, text: &str, size: f32, max_width: f32) -> String {
        if self.width(text, size) <= max_width {
            return text.to_string();
        }
        let mut chars: Vec<char> = text.chars().collect();
        while !chars.is_empty() && self.width(&format!("{}…", chars.iter().collect::<String>()), size) > max_width {
            chars.pop();
        }
        format!("{}…", chars.iter().collect::<String>())
    }
}

/// One cell of a grid: a render and up to two lines of caption under it.
pub struct Cell {
    pub image: RgbaImage,
    pub title: String,
    pub caption: String,
}

/// Lays cells out in a grid of `columns`, each render with its caption below.
pub fn grid(cells: &[Cell], columns: usize) -> RgbaImage {
    let labeller = Labeller::default();
    let (w, h) = cells.first().map(|c| c.image.dimensions()).unwrap_or((1, 1));
    let margin = 8;
    let caption = if cells.iter().any(|c| !c.caption.is_empty()) { 34 } else { 20 };
    let rows = cells.len().div_ceil(columns.max(1));
    let cell_w = w + margin;
    let cell_h = h + caption + margin;
    let mut sheet = RgbaImage::from_pixel(columns as u32 * cell_w + margin, rows as u32 * cell_h + margin, PAPER);
    for (i, cell) in cells.iter().enumerate() {
        let (x, y) = ((i % columns) as u32 * cell_w + margin, (i / columns) as u32 * cell_h + margin);
        image::imageops::overlay(&mut sheet, &cell.image, x as i64, y as i64);
        labeller.draw(&mut sheet, &cell.title, x as f32, (y + h + 3) as f32, 15.0, INK, w as f32);
        labeller.draw(&mut sheet, &cell.caption, x as f32, (y + h + 19) as f32, 12.0, FAINT_INK, w as f32);
    }
    sheet
}

/// A wedge: one row per parameter, a row title on the left and each cell's value above it.
pub fn rows(rows: &[(String, Vec<(String, RgbaImage)>)]) -> RgbaImage {
    let labeller = Labeller::default();
    let (w, h) = rows.first().and_then(|r| r.1.first()).map(|c| c.1.dimensions()).unwrap_or((1, 1));
    let margin = 6;
    let title_width = rows.iter().map(|r| labeller.width(&r.0, 16.0)).fold(0.0f32, f32::max).ceil() as u32 + 2 * margin;
    let value_height = 18;
    let columns = rows.iter().map(|r| r.1.len()).max().unwrap_or(0) as u32;
    let row_h = h + value_height + margin;
    let mut sheet =
        RgbaImage::from_pixel(title_width + columns * (w + margin) + margin, rows.len() as u32 * row_h + margin, PAPER);
    for (r, (title, cells)) in rows.iter().enumerate() {
        let y = r as u32 * row_h + margin;
        labeller.draw(
            &mut sheet,
            title,
            margin as f32,
            (y + value_height + h / 2 - 9) as f32,
            16.0,
            INK,
            title_width as f32,
        );
        for (c, (value, image)) in cells.iter().enumerate() {
            let x = title_width + c as u32 * (w + margin);
            labeller.draw(&mut sheet, value, x as f32, y as f32, 13.0, FAINT_INK, w as f32);
            image::imageops::overlay(&mut sheet, image, x as i64, (y + value_height) as i64);
        }
    }
    sheet
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn labels_draw_ink_where_the_text_is_and_nowhere_else() {
        let mut image = RgbaImage::from_pixel(120, 30, PAPER);
        Labeller::default().draw(&mut image, "gold", 4.0, 4.0, 16.0, [255, 255, 255], 100.0);
        let inked: Vec<(u32, u32)> =
            image.enumerate_pixels().filter(|(_, _, p)| p.0[0] > 128).map(|(x, y, _)| (x, y)).collect();
        assert!(inked.len() > 40, "{} inked pixels", inked.len());
        assert!(inked.iter().all(|&(x, y)| x < 60 && (2..26).contains(&y)), "ink outside the text box");
    }

    #[test]
    fn long_labels_are_cut_to_fit() {
        let labeller = Labeller::default();
        let fitted = labeller.fit("a very long preset name indeed", 15.0, 80.0);
        assert!(fitted.ends_with('…') && labeller.width(&fitted, 15.0) <= 80.0, "{fitted}");
    }

    #[test]
    fn grids_place_every_cell() {
        let cell = |v: u8| Cell {
            image: RgbaImage::from_pixel(10, 10, Rgba([v, 0, 0, 255])),
            title: "x".into(),
            caption: String::new(),
        };
        let sheet = grid(&[cell(200), cell(201), cell(202)], 2);
        let reds: std::collections::BTreeSet<u8> =
            sheet.pixels().filter(|p| p.0[1] == 0 && p.0[2] == 0).map(|p| p.0[0]).collect();
        assert_eq!(reds, [200, 201, 202].into());
    }
}
