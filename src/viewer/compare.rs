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

/// The other image the flip key (`B`) puts on screen, full-frame in the image's place.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Other {
    /// A snapshot, by [`Snapshot::id`](super::snapshots::Snapshot::id).
    Snapshot(u64),
    /// B of the A/B compare of another model or look.
    B,
}

/// What is compared, as far as the flip is concerned.
#[derive(Clone, Copy, Debug)]
pub struct Comparing<'a> {
    /// The snapshot shown as B, by id.
    pub snapshot: Option<u64>,
    /// An A/B compare of another model or look is on.
    pub b: bool,
    /// The snapshots there are, by id, oldest first.
    pub snapshots: &'a [u64],
}

impl Comparing<'_> {
    /// The comparison itself, without the list: a flip belongs to one.
    fn key(&self) -> (Option<u64>, bool) {
        (self.snapshot, self.b)
    }
}

/// What the view has on screen.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Showing {
    /// The live image, nothing compared.
    Live,
    /// The comparison as its mode draws it: split, side by side or ΔE.
    Compare,
    /// A snapshot alone, flipped to.
    Snapshot(u64),
    /// B alone, flipped to.
    B,
}

/// The flip: while a comparison is on, the key shows its other image (the snapshot, or B) alone
/// in the image's place, and again returns to the comparison; with none, it flips between the
/// live image and the snapshot compared last (while it is there), else the newest.
#[derive(Clone, Debug, Default)]
pub struct Flip {
    /// The other image while it is shown, with the comparison it was flipped in.
    shown: Option<(Other, (Option<u64>, bool))>,
    /// The snapshot compared last: what the flip goes to once the comparison is over.
    chosen: Option<u64>,
}

impl Flip {
    /// The image the key would flip to, if there is one.
    pub fn other(&self, comparing: &Comparing) -> Option<Other> {
        if let Some(id) = comparing.snapshot {
            return Some(Other::Snapshot(id));
        }
        if comparing.b {
            return Some(Other::B);
        }
        let chosen = self.chosen.filter(|id| comparing.snapshots.contains(id));
        chosen.or(comparing.snapshots.last().copied()).map(Other::Snapshot)
    }

    /// Keeps up with the comparison, once a frame: remembers the snapshot compared, and ends a
    /// flip made in another comparison or to an image the key no longer shows (a snapshot
    /// deleted, a newer one taken), so that a stale image never stays on screen.
    pub fn follow(&mut self, comparing: &Comparing) {
        if let Some(id) = comparing.snapshot {
            self.chosen = Some(id);
        }
        if !self.holds(comparing) {
            self.shown = None;
        }
    }

    /// Presses the key: shows the other image, or returns from it. False, and nothing changes,
    /// when there is nothing to flip to.
    pub fn toggle(&mut self, comparing: &Comparing) -> bool {
        if self.holds(comparing) {
            self.shown = None;
            return true;
        }
        self.shown = self.other(comparing).map(|other| (other, comparing.key()));
        self.shown.is_some()
    }

    /// Whether the other image is on screen.
    pub fn is_on(&self, comparing: &Comparing) -> bool {
        self.holds(comparing)
    }

    /// What is on screen.
    pub fn showing(&self, comparing: &Comparing) -> Showing {
        match self.shown.filter(|_| self.holds(comparing)) {
            Some((Other::Snapshot(id), _)) => Showing::Snapshot(id),
            Some((Other::B, _)) => Showing::B,
            None if comparing.snapshot.is_some() || comparing.b => Showing::Compare,
            None => Showing::Live,
        }
    }

    /// Whether a flip is on and still stands in `comparing`.
    fn holds(&self, comparing: &Comparing) -> bool {
        self.shown.is_some_and(|(other, key)| key == comparing.key() && self.other(comparing) == Some(other))
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

    fn nothing(snapshots: &[u64]) -> Comparing<'_> {
        Comparing { snapshot: None, b: false, snapshots }
    }

    /// With nothing compared the key flips between the live image and the newest snapshot.
    #[test]
    fn with_nothing_compared_the_flip_goes_to_the_newest_snapshot_and_back() {
        let mut flip = Flip::default();
        let comparing = nothing(&[3, 7]);
        assert_eq!(flip.showing(&comparing), Showing::Live);
        assert!(flip.toggle(&comparing));
        assert_eq!(flip.showing(&comparing), Showing::Snapshot(7));
        assert!(flip.toggle(&comparing));
        assert_eq!(flip.showing(&comparing), Showing::Live);
    }

    #[test]
    fn with_no_snapshot_and_nothing_compared_there_is_nothing_to_flip_to() {
        let mut flip = Flip::default();
        assert!(!flip.toggle(&nothing(&[])));
        assert_eq!(flip.showing(&nothing(&[])), Showing::Live);
        assert_eq!(flip.other(&nothing(&[])), None);
    }

    /// While a snapshot is compared, the flip shows it alone and then the comparison again.
    #[test]
    fn while_comparing_the_flip_shows_the_other_image_then_the_comparison() {
        let mut flip = Flip::default();
        let snapshot = Comparing { snapshot: Some(3), b: false, snapshots: &[3, 7] };
        assert_eq!(flip.showing(&snapshot), Showing::Compare);
        assert!(flip.toggle(&snapshot));
        assert_eq!(flip.showing(&snapshot), Showing::Snapshot(3), "the one compared, not the newest");
        flip.toggle(&snapshot);
        assert_eq!(flip.showing(&snapshot), Showing::Compare);

        let b = Comparing { snapshot: None, b: true, snapshots: &[3, 7] };
        assert_eq!(flip.showing(&b), Showing::Compare);
        assert!(flip.toggle(&b));
        assert_eq!(flip.showing(&b), Showing::B);
        flip.toggle(&b);
        assert_eq!(flip.showing(&b), Showing::Compare);
    }

    /// Once a comparison ends, the flip goes to the snapshot compared last while it is there.
    #[test]
    fn the_flip_remembers_the_snapshot_compared_last() {
        let mut flip = Flip::default();
        flip.follow(&Comparing { snapshot: Some(3), b: false, snapshots: &[3, 7] });
        assert_eq!(flip.other(&nothing(&[3, 7])), Some(Other::Snapshot(3)));
        assert_eq!(flip.other(&nothing(&[7])), Some(Other::Snapshot(7)), "3 was deleted: the newest");
    }

    /// A flip ends with the comparison it was made in, and when its image is no longer the one
    /// the key shows: the view never keeps an image the artist did not ask for.
    #[test]
    fn a_flip_ends_when_the_comparison_or_its_image_changes() {
        let snapshot = Comparing { snapshot: Some(3), b: false, snapshots: &[3, 7] };
        let mut flip = Flip::default();
        flip.follow(&snapshot);
        flip.toggle(&snapshot);
        let stopped = nothing(&[3, 7]);
        flip.follow(&stopped);
        assert_eq!(flip.showing(&stopped), Showing::Live, "the comparison was stopped");
        assert!(flip.toggle(&stopped));
        assert_eq!(flip.showing(&stopped), Showing::Snapshot(3));

        // A snapshot taken: the key would now show it, so the old flip is over.
        let taken = nothing(&[3, 7, 9]);
        let mut newest = Flip::default();
        newest.toggle(&nothing(&[3, 7]));
        assert_eq!(newest.showing(&taken), Showing::Live, "not even before follow");
        newest.follow(&taken);
        assert!(newest.toggle(&taken));
        assert_eq!(newest.showing(&taken), Showing::Snapshot(9));

        // Another comparison starts while flipped.
        let mut flip = Flip::default();
        flip.toggle(&snapshot);
        let b = Comparing { snapshot: None, b: true, snapshots: &[3, 7] };
        flip.follow(&b);
        assert_eq!(flip.showing(&b), Showing::Compare);
    }

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
