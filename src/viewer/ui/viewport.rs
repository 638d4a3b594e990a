//! The image: fit, zoom about the cursor, pan, 1:1 pixels; Shift+drag turns the light, a click
//! inspects a pixel and selects its object.

use super::super::action::Action;
use super::super::compare::SnapshotView;
use super::super::session::Session;
use crate::viewer_state::Edit;
use egui::{pos2, vec2, Color32, PointerButton, Rect, Sense};

/// Degrees of environment rotation per point dragged: a drag across a typical view is a turn.
const DEGREES_PER_POINT: f32 = 0.4;
/// The band along the view's bottom edge that holds the hint line and the pixel readout; what
/// else is drawn in the view (the false-colour legend) stays above it.
pub const FOOTER: f32 = 24.0;
/// The gap kept between the hint line and the pixel readout.
const FOOTER_GAP: f32 = 16.0;
pub const MIN_SCALE: f32 = 1.0 / 16.0;
pub const MAX_SCALE: f32 = 32.0;

/// How the image sits in the view.
#[derive(Default)]
pub struct Viewport {
    /// Window pixels per image pixel; `None` fits the image to the view, magnifying a small one.
    scale: Option<f32>,
    /// The image centre's offset from the view centre, in points.
    pan: egui::Vec2,
    /// A Shift+drag in progress: the rotation it started from and the distance dragged.
    rotating: Option<(f32, f32)>,
    /// The A/B split's divider is being dragged.
    dividing: bool,
    /// Where the image was drawn last, in points.
    pub image_rect: Option<Rect>,
    /// The image pixel under the pointer, while it hovers over the image.
    pub hovered: Option<(u32, u32)>,
}

/// How near the divider (in points) a drag grabs it rather than panning.
const DIVIDER_GRAB: f32 = 6.0;

/// Where the image was drawn, in window pixels, for the screenshot report.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImagePlacement {
    pub x: i32,
    pub y: i32,
    pub width: u32,
    pub height: u32,
    /// Window pixels per image pixel.
    pub scale: f32,
    /// Where the snapshot's image was drawn beside it, side by side.
    pub second: Option<(i32, i32)>,
}

impl Viewport {
    pub fn fit(&mut self) {
        self.scale = None;
        self.pan = egui::Vec2::ZERO;
    }

    pub fn actual_pixels(&mut self) {
        self.zoom_to(Some(1.0));
    }

    /// Sets the zoom (`None`: fit) about the view's centre.
    pub fn zoom_to(&mut self, scale: Option<f32>) {
        self.scale = scale;
        self.pan = egui::Vec2::ZERO;
    }

    pub fn show(
        &mut self,
        ui: &mut egui::Ui,
        session: &Session,
        texture: egui::TextureId,
        compare: Option<egui::TextureId>,
        snapshot: Option<&super::snapshots::Shown>,
        actions: &mut Vec<Action>,
    ) -> ImagePlacement {
        let rect = ui.max_rect();
        let response = ui.allocate_rect(rect, Sense::click_and_drag());
        let side = snapshot.filter(|s| s.view == SnapshotView::Side);
        // Side by side, each image has half the view; the live one is on the left.
        let view = if side.is_some() { Rect::from_min_max(rect.min, pos2(rect.center().x, rect.max.y)) } else { rect };
        let ppp = ui.ctx().pixels_per_point();
        let (w, h) = (session.width() as f32, session.height() as f32);
        // Fit fills the view both ways: a small g-buffer is magnified rather than left a postage
        // stamp (nearest filtering keeps its pixels sharp).
        // Fitted, the image leaves the footer band free, so the hint line never lies on it.
        let above_footer = Rect::from_min_max(view.min, pos2(view.max.x, (view.max.y - FOOTER).max(view.min.y + 1.0)));
        let fit = fit_scale(above_footer, ppp, (w, h));
        let scale = self.scale.unwrap_or(fit);
        let size = vec2(w, h) * scale / ppp;
        let centre = if self.scale.is_none() { above_footer.center() } else { view.center() } + self.pan;
        // On whole window pixels, so that 1:1 shows each image pixel exactly once.
        let min = ((centre - size / 2.0).to_vec2() * ppp).round() / ppp;
        let image_rect = Rect::from_min_size(min.to_pos2(), size);

        let painter = ui.painter_at(rect);
        painter.rect_filled(rect, 0.0, Color32::from_gray(18));
        let split = compare.zip(session.split_column());
        let whole = Rect::from_min_max(pos2(0.0, 0.0), pos2(1.0, 1.0));
        let mut second = None;
        match split {
            None if side.is_some() => {
                let b_rect = image_rect.translate(vec2(rect.center().x - rect.min.x, 0.0));
                ui.painter_at(view).image(texture, image_rect, whole, Color32::WHITE);
                let right = Rect::from_min_max(pos2(rect.center().x, rect.min.y), rect.max);
                ui.painter_at(right).image(side.expect("side").texture, b_rect, whole, Color32::WHITE);
                second = Some(((b_rect.min.x * ppp).round() as i32, (b_rect.min.y * ppp).round() as i32));
                if let Some((a, b)) = session.compare_labels() {
                    side_labels(&painter, image_rect, b_rect, (a, b));
                }
            }
            None => {
                // The ΔE view shows the heat map in the image's place, once it is made.
                let shown = snapshot.filter(|s| s.view == SnapshotView::DeltaE).and_then(|s| s.heat).unwrap_or(texture);
                painter.image(shown, image_rect, whole, Color32::WHITE);
            }
            Some((b, column)) => {
                // Both images cover the whole frame; each half shows its own part, so dragging
                // the divider costs no rendering.
                let u = column as f32 / w;
                let x = image_rect.min.x + image_rect.width() * u;
                let a_rect = Rect::from_min_max(image_rect.min, pos2(x, image_rect.max.y));
                let b_rect = Rect::from_min_max(pos2(x, image_rect.min.y), image_rect.max);
                painter.image(texture, a_rect, Rect::from_min_max(pos2(0.0, 0.0), pos2(u, 1.0)), Color32::WHITE);
                // Until B has finished a pass, its image is not a picture yet: show A there.
                let b = if session.compare_ready() { b } else { texture };
                painter.image(b, b_rect, Rect::from_min_max(pos2(u, 0.0), pos2(1.0, 1.0)), Color32::WHITE);
            }
        }

        let rotation = session.document.settings().lighting.rotation_degrees;
        if let Some((_, column)) = split {
            self.drag_divider(ui, &response, image_rect, column as f32 / w, actions);
        }
        if !self.dividing {
            self.interact(ui, &response, rotation, scale, actions);
        }
        self.zoom(ui, &response, rect, centre, scale);
        if response.clicked() {
            if let Some(pixel) = response.interact_pointer_pos().and_then(|p| pixel_at(p, image_rect, w, h)) {
                actions.push(Action::Pick { x: pixel.0, y: pixel.1 });
            }
        }
        self.overlay(ui, &response, &painter, rect, image_rect, scale, (w, h), rotation);
        self.image_rect = Some(image_rect);
        self.hovered = response.hover_pos().and_then(|p| pixel_at(p, image_rect, w, h));
        if let Some(inspection) = &session.inspection {
            crosshair(&painter, rect, image_rect, (inspection.x, inspection.y), (w, h));
        }
        if let (Some((_, column)), Some(labels)) = (split, session.compare_labels()) {
            split_overlay(&painter, image_rect, image_rect.min.x + image_rect.width() * column as f32 / w, labels);
        }
        if let Some(shown) = snapshot.filter(|s| s.view == SnapshotView::DeltaE) {
            delta_e_legend(&painter, rect, shown);
        }
        ImagePlacement {
            x: (image_rect.min.x * ppp).round() as i32,
            y: (image_rect.min.y * ppp).round() as i32,
            width: (size.x * ppp).round() as u32,
            height: (size.y * ppp).round() as u32,
            scale,
            second,
        }
    }

    fn interact(
        &mut self,
        ui: &egui::Ui,
        response: &egui::Response,
        rotation: f32,
        scale: f32,
        actions: &mut Vec<Action>,
    ) {
        let shift = ui.input(|i| i.modifiers.shift);
        if response.drag_started_by(PointerButton::Primary) && shift {
            self.rotating = Some((rotation, 0.0));
        }
        if let Some((start, distance)) = &mut self.rotating {
            if response.dragged() {
                *distance += response.drag_delta().x;
                actions.push(Action::Drag(Edit::SetRotation(wrap_degrees(*start + *distance * DEGREES_PER_POINT))));
            }
            if response.drag_stopped() || !response.dragged() {
                self.rotating = None;
                actions.push(Action::EndGesture);
            }
        } else if response.dragged_by(PointerButton::Primary) || response.dragged_by(PointerButton::Middle) {
            // Panning a fitted image keeps its size: fit becomes an explicit zoom.
            self.scale = Some(scale);
            self.pan += response.drag_delta();
        }
    }

    /// A drag that starts on the divider moves it (a fraction of the image's width).
    fn drag_divider(
        &mut self,
        ui: &egui::Ui,
        response: &egui::Response,
        image_rect: Rect,
        at: f32,
        actions: &mut Vec<Action>,
    ) {
        let x = image_rect.min.x + image_rect.width() * at;
        let shift = ui.input(|i| i.modifiers.shift);
        if response.drag_started_by(PointerButton::Primary) && !shift {
            let start = ui.input(|i| i.pointer.press_origin());
            self.dividing =
                start.is_some_and(|p| (p.x - x).abs() <= DIVIDER_GRAB && image_rect.y_range().contains(p.y));
        }
        if self.dividing {
            if let Some(p) = response.interact_pointer_pos().filter(|_| response.dragged()) {
                let fraction = ((p.x - image_rect.min.x) / image_rect.width()).clamp(0.0, 1.0);
                actions.push(Action::Divider(fraction));
            }
            if response.drag_stopped() || !response.dragged() {
                self.dividing = false;
            }
        }
        if response.hover_pos().is_some_and(|p| (p.x - x).abs() <= DIVIDER_GRAB) || self.dividing {
            ui.ctx().set_cursor_icon(egui::CursorIcon::ResizeHorizontal);
        }
    }

    fn zoom(&mut self, ui: &egui::Ui, response: &egui::Response, rect: Rect, centre: egui::Pos2, scale: f32) {
        let Some(cursor) = response.hover_pos() else { return };
        let (scroll, pinch) = ui.input(|i| (i.smooth_scroll_delta.y, i.zoom_delta()));
        let factor = pinch * (scroll * 0.0025).exp();
        if (factor - 1.0).abs() < 1e-4 {
            return;
        }
        let new_scale = (scale * factor).clamp(MIN_SCALE, MAX_SCALE);
        // Keep the image point under the cursor where it is.
        let new_centre = cursor - (cursor - centre) * (new_scale / scale);
        self.pan = new_centre - rect.center();
        self.scale = Some(new_scale);
    }

    #[allow(clippy::too_many_arguments)]
    fn overlay(
        &self,
        ui: &egui::Ui,
        response: &egui::Response,
        painter: &egui::Painter,
        rect: Rect,
        image_rect: Rect,
        scale: f32,
        (w, h): (f32, f32),
        rotation: f32,
    ) {
        let font = egui::FontId::proportional(13.0);
        let color = Color32::from_gray(200);
        if self.rotating.is_some() {
            painter.text(
                rect.left_top() + vec2(10.0, 10.0),
                egui::Align2::LEFT_TOP,
                format!("light rotation {rotation:.1}°"),
                egui::FontId::proportional(18.0),
                Color32::WHITE,
            );
        }
        let zoom = match self.scale {
            None => format!("fit {:.0}%", scale * 100.0),
            Some(_) => format!("{:.0}%", scale * 100.0),
        };
        let mut corner = zoom;
        if let Some(pixel) = response.hover_pos().and_then(|p| pixel_at(p, image_rect, w, h)) {
            corner = format!("{}, {}   {corner}", pixel.0, pixel.1);
        }
        let corner = painter.layout_no_wrap(corner, font.clone(), color);
        let corner_width = corner.size().x;
        painter.galley(rect.right_bottom() - vec2(10.0 + corner_width, 8.0 + corner.size().y), corner, color);
        if response.hovered() && !ui.input(|i| i.pointer.any_down()) {
            // The longest hint that leaves the readout room: never text over text.
            let room = rect.width() - 20.0 - corner_width - FOOTER_GAP;
            let hint = HINTS
                .iter()
                .map(|hint| painter.layout_no_wrap(hint.to_string(), font.clone(), Color32::from_gray(130)))
                .find(|galley| galley.size().x <= room);
            if let Some(hint) = hint {
                painter.galley(rect.left_bottom() + vec2(10.0, -8.0 - hint.size().y), hint, Color32::from_gray(130));
            }
        }
    }
}

/// The scale at which a `w × h` image fills `rect` one way and fits in it the other, within
/// the zoom's bounds.
fn fit_scale(rect: Rect, ppp: f32, (w, h): (f32, f32)) -> f32 {
    (rect.width() * ppp / w).min(rect.height() * ppp / h).clamp(MIN_SCALE, MAX_SCALE)
}

/// The hint line under the image, longest first: the first that fits beside the pixel readout is
/// shown.
const HINTS: [&str; 3] = [
    "click: inspect · Shift+drag: rotate light · drag: pan · wheel: zoom · F: fit · 1: 1:1 · ?: hotkeys",
    "click: inspect · Shift+drag: rotate light · ?: hotkeys",
    "?: hotkeys",
];

/// The divider line and the halves' labels, "A: …" top left and "B: …" top right, each on a dark
/// plate so that it reads over any image.
fn split_overlay(painter: &egui::Painter, image_rect: Rect, x: f32, (a, b): (String, String)) {
    painter.line_segment(
        [pos2(x, image_rect.min.y), pos2(x, image_rect.max.y)],
        egui::Stroke::new(1.0, Color32::from_rgba_unmultiplied(255, 255, 255, 200)),
    );
    let font = egui::FontId::proportional(12.0);
    let margin = vec2(4.0, 3.0);
    let plate = |text: String, anchor: egui::Pos2, align: egui::Align2| {
        let galley = painter.layout_no_wrap(text, font.clone(), Color32::WHITE);
        let rect = align.anchor_size(anchor, galley.size() + margin * 2.0);
        painter.rect_filled(rect, 2.0, Color32::from_black_alpha(170));
        painter.galley(rect.min + margin, galley, Color32::WHITE);
    };
    plate(a, pos2(x - 2.0, image_rect.min.y + 2.0), egui::Align2::RIGHT_TOP);
    plate(b, pos2(x + 2.0, image_rect.min.y + 2.0), egui::Align2::LEFT_TOP);
}

/// Marks the picked pixel with a crosshair whose arms run along its row and column up to the
/// image's edge but never over the image, so the pixels stay as rendered; where the image fills
/// the view on an axis, short ticks at the view's edges stand in for those arms.
fn crosshair(painter: &egui::Painter, view: Rect, image: Rect, (x, y): (u32, u32), (w, h): (f32, f32)) {
    let centre = image.min + vec2((x as f32 + 0.5) / w * image.width(), (y as f32 + 0.5) / h * image.height());
    let stroke = egui::Stroke::new(1.0, Color32::from_rgb(255, 210, 0));
    const TICK: f32 = 10.0;
    let (top, bottom) = (image.min.y.max(view.min.y + TICK), image.max.y.min(view.max.y - TICK));
    let (left, right) = (image.min.x.max(view.min.x + TICK), image.max.x.min(view.max.x - TICK));
    if view.x_range().contains(centre.x) {
        painter.line_segment([pos2(centre.x, view.min.y), pos2(centre.x, top)], stroke);
        painter.line_segment([pos2(centre.x, bottom), pos2(centre.x, view.max.y)], stroke);
    }
    if view.y_range().contains(centre.y) {
        painter.line_segment([pos2(view.min.x, centre.y), pos2(left, centre.y)], stroke);
        painter.line_segment([pos2(right, centre.y), pos2(view.max.x, centre.y)], stroke);
    }
}

/// Side by side: each image's label above its top-left corner, on a dark plate.
fn side_labels(painter: &egui::Painter, a_rect: Rect, b_rect: Rect, (a, b): (String, String)) {
    let font = egui::FontId::proportional(12.0);
    for (text, rect) in [(a, a_rect), (b, b_rect)] {
        let galley = painter.layout_no_wrap(text, font.clone(), Color32::WHITE);
        let plate =
            egui::Align2::LEFT_BOTTOM.anchor_size(rect.left_top() - vec2(0.0, 2.0), galley.size() + vec2(8.0, 6.0));
        painter.rect_filled(plate, 2.0, Color32::from_black_alpha(170));
        painter.galley(plate.min + vec2(4.0, 3.0), galley, Color32::WHITE);
    }
}

/// The ΔE view's legend, top left of the view: the heat map's colour ramp with its stops, and
/// the mean and largest difference.
fn delta_e_legend(painter: &egui::Painter, view: Rect, shown: &super::snapshots::Shown) {
    use super::super::delta_e::{heat, STOPS};
    let font = egui::FontId::proportional(12.0);
    let top_left = view.left_top() + vec2(10.0, 10.0);
    let (width, height) = (200.0, 12.0);
    let top = STOPS[STOPS.len() - 1].0;
    let plate = Rect::from_min_size(top_left - vec2(6.0, 6.0), vec2(width + 28.0, 54.0));
    painter.rect_filled(plate, 3.0, Color32::from_black_alpha(190));
    let title = match shown.delta {
        Some((mean, max)) => format!("ΔE2000 vs {}: mean {mean:.2}, max {max:.2}", shown.name),
        None => format!("ΔE2000 vs {}: waiting for the image", shown.name),
    };
    painter.text(top_left, egui::Align2::LEFT_TOP, title, font.clone(), Color32::WHITE);
    let bar = Rect::from_min_size(top_left + vec2(0.0, 20.0), vec2(width, height));
    let steps = 100;
    for i in 0..steps {
        let [r, g, b] = heat(top * (i as f32 + 0.5) / steps as f32);
        let x0 = bar.min.x + width * i as f32 / steps as f32;
        let slice = Rect::from_min_max(pos2(x0, bar.min.y), pos2(x0 + width / steps as f32 + 0.5, bar.max.y));
        painter.rect_filled(slice, 0.0, Color32::from_rgb(r, g, b));
    }
    for (value, _) in STOPS {
        let x = bar.min.x + width * value / top;
        painter.line_segment([pos2(x, bar.max.y), pos2(x, bar.max.y + 3.0)], egui::Stroke::new(1.0, Color32::WHITE));
        let label = if value == top { format!("{value}+") } else { format!("{value}") };
        painter.text(pos2(x, bar.max.y + 4.0), egui::Align2::CENTER_TOP, label, font.clone(), Color32::from_gray(210));
    }
}

/// The image pixel under window point `p`, if it is on the image.
fn pixel_at(p: egui::Pos2, image_rect: Rect, w: f32, h: f32) -> Option<(u32, u32)> {
    let u = (p - image_rect.min) / image_rect.size();
    (0.0..1.0).contains(&u.x).then_some(())?;
    (0.0..1.0).contains(&u.y).then_some(())?;
    Some(((u.x * w) as u32, (u.y * h) as u32))
}

/// Degrees into (−180, 180].
pub fn wrap_degrees(degrees: f32) -> f32 {
    let wrapped = (degrees + 180.0).rem_euclid(360.0) - 180.0;
    if wrapped == -180.0 {
        180.0
    } else {
        wrapped
    }
}
