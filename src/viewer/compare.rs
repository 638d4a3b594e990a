//! The A/B split: a second renderer shows B, the same g-buffer and lighting as the edited look
//! (A) under another BRDF model, or another look file with its own stacks and model. Both
//! accumulate with A's seed and target, so each half is what `lookdev render` makes of it.

use super::progressive::Progressive;
use crate::material::stack::PackedStacks;
use crate::material::Look;
use crate::render::Renderer;
use crate::shading::model::Model;
use std::path::{Path, PathBuf};

/// What B is.
#[derive(Clone, Debug)]
pub enum Subject {
    /// A's look and stacks under this model.
    Model(Model),
    /// Another look: its own stacks and `[model]`; A's environment, lighting and render settings.
    Look { path: PathBuf, look: Box<Look> },
}

impl Subject {
    /// The model B renders with.
    pub fn model(&self) -> Model {
        match self {
            Subject::Model(model) => *model,
            Subject::Look { look, .. } => look.model.unwrap_or_default(),
        }
    }

    pub fn look_path(&self) -> Option<&Path> {
        match self {
            Subject::Model(_) => None,
            Subject::Look { path, .. } => Some(path),
        }
    }
}

/// B's renderer and how far it has got.
pub struct Compare {
    pub subject: Subject,
    pub renderer: Renderer,
    pub progressive: Progressive,
    /// B's stacks: A's when comparing models.
    pub packed: PackedStacks,
}

/// How a snapshot is shown beside the live image.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum SnapshotView {
    /// The divider split, a wipe: live left of the divider, the snapshot right of it.
    #[default]
    Split,
    /// Side by side: each whole image in half the view.
    Side,
    /// The CIEDE2000 difference of the display colours, as a heat map.
    DeltaE,
}

impl SnapshotView {
    pub const ALL: [SnapshotView; 3] = [SnapshotView::Split, SnapshotView::Side, SnapshotView::DeltaE];

    /// The script's word for it.
    pub fn name(self) -> &'static str {
        match self {
            SnapshotView::Split => "split",
            SnapshotView::Side => "side",
            SnapshotView::DeltaE => "delta-e",
        }
    }

    pub fn label(self) -> &'static str {
        match self {
            SnapshotView::Split => "Split",
            SnapshotView::Side => "Side by side",
            SnapshotView::DeltaE => "ΔE2000",
        }
    }

    pub fn parse(text: &str) -> Result<SnapshotView, String> {
        SnapshotView::ALL
            .into_iter()
            .find(|v| v.name() == text)
            .ok_or_else(|| format!("unknown snapshot view '{text}' (expected split, side or delta-e)"))
    }
}

/// The image column where B starts, for a divider at `fraction` of an image `width` wide.
pub fn split_column(fraction: f32, width: u32) -> u32 {
    ((fraction.clamp(0.0, 1.0) * width as f32).round() as u32).min(width)
}

/// The name of a look file as a label shows it.
pub fn file_label(path: Option<&Path>) -> String {
    path.and_then(|p| p.file_name()).map_or("untitled look".into(), |n| n.to_string_lossy().into_owned())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_split_column_rounds_and_stays_in_the_image() {
        assert_eq!(split_column(0.5, 160), 80);
        assert_eq!(split_column(0.0, 160), 0);
        assert_eq!(split_column(1.0, 160), 160);
        assert_eq!(split_column(1.5, 160), 160);
        assert_eq!(split_column(-1.0, 160), 0);
        assert_eq!(split_column(0.3, 161), 48);
    }
}
