//! The mask overlay (`O`): the image tinted where the selected layer shows, by its share of the
//! blend after its mask's blur and levels, invert and opacity and the layers above it, as
//! Substance Painter shows a layer's mask over the viewport. Made again only when the look, the
//! solo or the selection changes.

use super::session::Session;
use crate::material::stack::layer_shares;
use crate::viewer_state::ObjectRef;

/// The tint: a saturated orange that no material preset is, at most this opaque.
const TINT: [u8; 3] = [255, 96, 0];
const MAX_ALPHA: f32 = 0.6;

/// What an overlay was made for: the look's material revision, the solo and the selected layer.
type Key = (u64, Option<crate::material::look::LayerId>, ObjectRef, usize);

#[derive(Default)]
pub struct MaskOverlay {
    pub on: bool,
    made_for: Option<Key>,
    texture: Option<egui::TextureHandle>,
}

impl MaskOverlay {
    /// Turns the overlay on or off (`None`: toggles it); the message says which, and what it
    /// shows.
    pub fn set(&mut self, on: Option<bool>) -> String {
        self.on = on.unwrap_or(!self.on);
        if self.on {
            "mask overlay on: orange where the selected layer shows".into()
        } else {
            "mask overlay off".into()
        }
    }

    /// Makes the overlay's texture for the selected layer, when it is on and stale.
    pub fn update(&mut self, session: &Session, egui: &egui::Context) {
        let selection = session.document.selection();
        let (Some(object), Some(layer)) = (selection.object, selection.layer) else {
            self.made_for = None;
            return;
        };
        let key = (session.document.material_revision(), session.solo, object, layer);
        if !self.on || self.made_for == Some(key) {
            return;
        }
        self.made_for = Some(key);
        let look = session.rendered_look();
        // An object without a stack of its own shows the default stack, as the panel does.
        let stack = match object {
            ObjectRef::Id(id) => look.stack_for(id),
            ObjectRef::Default => look.objects.iter().find(|o| o.is_default()),
        };
        let Some(stack) = stack else {
            return self.upload(egui, session, None);
        };
        let shares = layer_shares(&look, stack, &session.gbuffer);
        self.upload(egui, session, shares.get(layer).map(Vec::as_slice));
    }

    fn upload(&mut self, egui: &egui::Context, session: &Session, shares: Option<&[f32]>) {
        let size = [session.width() as usize, session.height() as usize];
        let pixels: Vec<egui::Color32> = match shares {
            Some(shares) => shares.iter().map(|&share| tint(share)).collect(),
            None => vec![egui::Color32::TRANSPARENT; size[0] * size[1]],
        };
        let image = egui::ColorImage::new(size, pixels);
        let options =
            egui::TextureOptions { magnification: egui::TextureFilter::Nearest, ..egui::TextureOptions::LINEAR };
        match &mut self.texture {
            Some(texture) => texture.set(image, options),
            None => self.texture = Some(egui.load_texture("mask overlay", image, options)),
        }
    }

    /// The overlay's texture, while it is on and made for the current selection.
    pub fn texture(&self) -> Option<egui::TextureId> {
        self.texture.as_ref().filter(|_| self.on && self.made_for.is_some()).map(egui::TextureHandle::id)
    }
}

/// The overlay's premultiplied colour where the layer's share is `share`.
pub fn tint(share: f32) -> egui::Color32 {
    let alpha = (share.clamp(0.0, 1.0) * MAX_ALPHA * 255.0).round() as u8;
    egui::Color32::from_rgba_unmultiplied(TINT[0], TINT[1], TINT[2], alpha)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_tint_follows_the_share_and_is_clear_where_the_layer_does_not_show() {
        assert_eq!(tint(0.0).a(), 0);
        assert_eq!(tint(1.0).a(), (MAX_ALPHA * 255.0).round() as u8);
        assert!(tint(0.5).a() > tint(0.25).a());
        assert_eq!(tint(-1.0).a(), 0, "clamped");
    }
}
