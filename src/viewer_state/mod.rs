//! The document an interactive viewer edits: a look, its render settings, the selection, and the
//! undo history. Pure Rust: no GPU and no user interface, so it is tested like any other data.
//!
//! - **Edits.** Every change is an [`Edit`], given to [`Document::apply`]. It is checked first
//!   (parameter kinds and ranges, layer indexes, opacity in [0, 1], spp ≥ 1, finite rotation,
//!   intensity ≥ 0, exposure within ±64 stops) and an edit that fails changes nothing and records
//!   nothing. An edit that would leave everything as it is records nothing either.
//! - **Implicit stacks.** An edit aimed at [`ObjectRef::Id`] for an object without a stack of its
//!   own first gives it a copy of the default stack (or one default-material layer), and one
//!   aimed at [`ObjectRef::Default`] without a default stack first adds one of a single
//!   default-material layer, both within the edit's own undo step.
//! - **Merging.** [`Document::apply_merging`] is for continuous controls, such as a slider being
//!   dragged. Such an edit joins the previous undo step when that step was made by an edit with
//!   the same [`MergeKey`] (the same kind of edit on the same target: one parameter of one layer,
//!   one layer's opacity or mask, or one of rotation, intensity, exposure, target spp and seed)
//!   and nothing has come between: no other edit, no undo or redo, no save, and no
//!   [`Document::end_gesture`], which the viewer calls when the drag ends. A drag that comes back
//!   to where it started leaves no step. An edit that fails or changes nothing neither merges nor
//!   ends a gesture. [`Document::apply`] never merges.
//! - **Dirty and revisions.** [`Document::is_dirty`] compares content with what was last loaded
//!   or saved, so undoing back to it is clean. [`Document::revision`] changes with every change
//!   of content, undo and redo included, and [`Document::material_revision`] only when the layer
//!   stacks change.
//! - **Settings in the look.** The look's `[environment]` and `[render]` tables follow the
//!   settings, so a saved look reopens as it was. A value is written when the look as last
//!   loaded or saved wrote it, or when it differs from lookdev's default.
//! - **Saving.** [`Document::save`] writes the look atomically and only if it reads back equal;
//!   saved elsewhere, its relative references are rewritten to keep their meaning.
//!   [`Document::save_layer_as_preset`] writes a layer to the user library.

mod edit;
mod history;
mod save;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::{Mutex, MutexGuard, PoisonError};

use crate::material::library::Library;
use crate::material::look::{Layer, LayerId, Look, ObjectStack};
use crate::material::params::{Param, Params, Value};
use crate::render::settings::Settings;

pub use edit::{Edit, MergeKey, ObjectRef};
pub use history::UNDO_LIMIT;

use edit::State;
use history::History;

/// What the artist has selected: a stack, and a layer in it. It is not content: changing it is
/// not an edit, is not undone, and neither dirties the document nor bumps its revisions.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Selection {
    pub object: Option<ObjectRef>,
    /// Kept within the selected stack's layers when edits or undo shorten it.
    pub layer: Option<usize>,
}

/// What the viewer edits: the look, the render settings, the selection, and the undo history.
#[derive(Debug)]
pub struct Document {
    state: State,
    /// Where the look was opened from or last saved to; `None` for a look never saved.
    path: Option<PathBuf>,
    history: History<State>,
    /// The content as last loaded or saved, for [`Document::is_dirty`].
    saved: State,
    selection: Selection,
    /// The selected layer itself, which the selection follows through edits, undo and redo
    /// wherever they move it in its stack.
    selected_layer: Option<LayerId>,
    revision: u64,
    material_revision: u64,
    /// Preset parameters by the reference layers give, read once per document so that every
    /// layer of a preset agrees on its values. A mutex rather than a cell, so that a document
    /// can be shared between threads.
    presets: Mutex<BTreeMap<String, Params>>,
}

impl Document {
    /// `look_path`: `Some(file)` when the look was opened from a file (its folder resolves
    /// presets), `None` for a new or built-in look. `settings` are what the viewer renders with:
    /// the look's values with any command-line overrides, as [`Settings::resolve`] gives them.
    /// The document starts clean, with this as its saved content.
    pub fn new(mut look: Look, look_path: Option<PathBuf>, settings: Settings) -> Document {
        look.file.clone_from(&look_path);
        let mut state = State { look: look.clone(), settings };
        state.mirror_settings(&look);
        Document {
            saved: state.clone(),
            state,
            path: look_path,
            history: History::new(),
            selection: Selection::default(),
            selected_layer: None,
            revision: 0,
            material_revision: 0,
            presets: Mutex::new(BTreeMap::new()),
        }
    }

    /// The look: its layer stacks, and `[environment]` and `[render]` tables that follow
    /// [`Document::settings`].
    pub fn look(&self) -> &Look {
        &self.state.look
    }

    /// What to render with: the environment file, lighting (rotation, intensity, background), the
    /// target spp, seed, exposure and tone map.
    pub fn settings(&self) -> &Settings {
        &self.state.settings
    }

    /// The file the look was opened from or last saved to.
    pub fn path(&self) -> Option<&Path> {
        self.path.as_deref()
    }

    /// The stack edits aimed at `object` act on, as it is now: the object's own stack, else the
    /// default stack (which an edit would copy). `None` when there is neither.
    pub fn stack(&self, object: ObjectRef) -> Option<&ObjectStack> {
        let objects = &self.state.look.objects;
        let own = objects.iter().find(|o| o.id.is_some() && o.is_for(object.id()));
        own.or_else(|| objects.iter().find(|o| o.is_default()))
    }

    /// Whether the content differs from what was last loaded or saved.
    pub fn is_dirty(&self) -> bool {
        self.state != self.saved
    }

    /// Changes with every change of content, undo and redo included: the viewer restarts
    /// accumulation when it does.
    pub fn revision(&self) -> u64 {
        self.revision
    }

    /// Changes only when the layer stacks change: the viewer re-resolves materials only then.
    pub fn material_revision(&self) -> u64 {
        self.material_revision
    }

    pub fn selection(&self) -> Selection {
        self.selection
    }

    /// Selects a stack and a layer; a layer index beyond the stack is brought within it.
    pub fn select(&mut self, selection: Selection) {
        self.selection = selection;
        self.selected_layer = None;
        self.keep_selection_valid();
    }

    /// Selects `object`, as a click on it does: its top layer, unless the object is selected
    /// already, when the layer stays as it is (so that the next edit lands where it did).
    pub fn select_object(&mut self, object: ObjectRef) {
        if self.selection.object == Some(object) {
            return;
        }
        let top = self.stack(object).map(|s| s.layers.len().saturating_sub(1));
        self.select(Selection { object: Some(object), layer: top });
    }

    /// Checks and applies an edit as an undo step of its own. The error is one line, and then
    /// nothing has changed. An edit that changes nothing records nothing.
    pub fn apply(&mut self, edit: Edit) -> Result<(), String> {
        self.apply_with(edit, false)
    }

    /// Like [`Document::apply`], except that an edit of a continuous control joins the previous
    /// undo step when that was the same control and nothing came between (see the module
    /// documentation). Call [`Document::end_gesture`] when the drag ends.
    pub fn apply_merging(&mut self, edit: Edit) -> Result<(), String> {
        self.apply_with(edit, true)
    }

    /// Ends a gesture: the next edit is a new undo step even if it is the same control.
    pub fn end_gesture(&mut self) {
        self.history.end_gesture();
    }

    fn apply_with(&mut self, edit: Edit, merging: bool) -> Result<(), String> {
        let key = edit.merge_key().filter(|_| merging);
        // A duplicate of the selected layer takes the selection, as in a painting application:
        // the next edit is the copy's.
        let duplicated = match &edit {
            Edit::DuplicateLayer { object, layer }
                if self.selection.object == Some(*object) && self.selection.layer == Some(*layer) =>
            {
                Some((*object, *layer + 1))
            }
            _ => None,
        };
        let next = self.state.applied(edit, &|reference| self.preset_params(reference), &self.saved.look)?;
        if next == self.state {
            return Ok(());
        }
        let before = std::mem::replace(&mut self.state, next);
        self.note_change(&before.look.objects);
        self.history.record(before, &self.state, key);
        if let Some((object, copy)) = duplicated {
            self.select(Selection { object: Some(object), layer: Some(copy) });
        }
        Ok(())
    }

    /// Undoes the newest step. False when there is nothing to undo.
    pub fn undo(&mut self) -> bool {
        let stacks = self.state.look.objects.clone();
        let undone = self.history.undo(&mut self.state);
        if undone {
            self.note_change(&stacks);
        }
        undone
    }

    /// Redoes the step most recently undone. False when there is nothing to redo.
    pub fn redo(&mut self) -> bool {
        let stacks = self.state.look.objects.clone();
        let redone = self.history.redo(&mut self.state);
        if redone {
            self.note_change(&stacks);
        }
        redone
    }

    pub fn can_undo(&self) -> bool {
        self.history.can_undo()
    }

    pub fn can_redo(&self) -> bool {
        self.history.can_redo()
    }

    /// The value `param` has in the preset of a layer: what "reset to preset" restores, and what
    /// an override is shown against. The default for a layer without a preset. For an object
    /// without a stack of its own, the layer is the default stack's. If there is no such layer,
    /// or its preset can no longer be read, it is the layer's current value or the default.
    pub fn preset_value(&self, object: ObjectRef, layer: usize, param: Param) -> Value {
        let Some(layer) = self.layer(object, layer) else {
            return Params::default().get(param);
        };
        match &layer.preset {
            None => Params::default().get(param),
            Some(reference) => match self.preset_params(reference) {
                Ok(preset) => preset.get(param),
                Err(_) => layer.params.get(param),
            },
        }
    }

    /// Whether a layer overrides `param`, so that saving writes it. False if there is no such
    /// layer.
    pub fn is_overridden(&self, object: ObjectRef, layer: usize, param: Param) -> bool {
        self.layer(object, layer).is_some_and(|l| l.overrides.contains(&param))
    }

    /// A layer of the stack edits aimed at `object` act on.
    fn layer(&self, object: ObjectRef, layer: usize) -> Option<&Layer> {
        self.stack(object)?.layers.get(layer)
    }

    /// Where the look's preset names and paths resolve: its folder, the user library, then the
    /// built-ins; without a file, the user library and the built-ins.
    pub fn library(&self) -> Library {
        match &self.path {
            Some(path) => Library::for_look(path),
            None => Library::standard(),
        }
    }

    /// A preset's parameters by the reference a layer gives, read once and then remembered.
    fn preset_params(&self, reference: &str) -> Result<Params, String> {
        if let Some(params) = self.preset_cache().get(reference) {
            return Ok(*params);
        }
        let params = self.library().resolve(reference)?.params;
        self.preset_cache().insert(reference.to_string(), params);
        Ok(params)
    }

    fn preset_cache(&self) -> MutexGuard<'_, BTreeMap<String, Params>> {
        // The map is never left half-updated, so a panic elsewhere does not make it wrong.
        self.presets.lock().unwrap_or_else(PoisonError::into_inner)
    }

    /// Bumps the revisions after the content changed from one with `stacks`.
    fn note_change(&mut self, stacks: &[ObjectStack]) {
        self.revision += 1;
        if stacks != self.state.look.objects.as_slice() {
            self.material_revision += 1;
        }
        self.keep_selection_valid();
    }

    /// Keeps the selection on its layer wherever that now is in the stack; where the layer is
    /// gone, on the index, brought within the stack.
    fn keep_selection_valid(&mut self) {
        let ids: Vec<LayerId> = self
            .selection
            .object
            .and_then(|o| self.stack(o))
            .map_or_else(Vec::new, |s| s.layers.iter().map(|l| l.id).collect());
        let followed = self.selected_layer.and_then(|id| ids.iter().position(|&l| l == id));
        self.selection.layer = match (followed, self.selection.layer) {
            (Some(index), Some(_)) => Some(index),
            (_, Some(_)) if ids.is_empty() => None,
            (_, Some(layer)) => Some(layer.min(ids.len() - 1)),
            (_, None) => None,
        };
        self.selected_layer = self.selection.layer.and_then(|i| ids.get(i).copied());
    }
}
