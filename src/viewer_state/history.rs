//! Undo and redo by snapshots. A document's state is small (a few stacks of a few layers, and
//! the render settings), so each undo step keeps the whole state from before it: restoring is
//! exact by construction, with no inverse edit to get wrong.

use std::collections::VecDeque;

use super::edit::MergeKey;

/// Undo steps kept; the oldest are dropped beyond this.
pub const UNDO_LIMIT: usize = 1000;

/// The undo and redo stacks of one document, and the gesture still open for merging.
#[derive(Clone, Debug)]
pub(super) struct History<S> {
    /// The state before each step, oldest first.
    undo: VecDeque<S>,
    /// The states undone, the most recently undone last.
    redo: Vec<S>,
    /// The merge key of the newest undo step while its gesture is open: a later edit with the
    /// same key folds into that step instead of making a new one.
    open: Option<MergeKey>,
}

impl<S: PartialEq> History<S> {
    pub fn new() -> History<S> {
        History { undo: VecDeque::new(), redo: Vec::new(), open: None }
    }

    /// Records a change from `before` to `after`. With a `key` equal to the open gesture's, the
    /// change joins the newest step, which keeps its own `before`; any other change is a step of
    /// its own (and opens a gesture when it has a key). Redo is lost either way.
    pub fn record(&mut self, before: S, after: &S, key: Option<MergeKey>) {
        self.redo.clear();
        let merges = key.is_some() && key == self.open;
        if !merges {
            self.undo.push_back(before);
            if self.undo.len() > UNDO_LIMIT {
                self.undo.pop_front();
            }
            self.open = key;
        } else if self.undo.back() == Some(after) {
            // A drag that has come back to where it started is no step at all. The gesture is
            // closed with it, so that nothing merges into the step below.
            self.undo.pop_back();
            self.open = None;
        }
    }

    /// Closes the open gesture: the next edit starts a step of its own.
    pub fn end_gesture(&mut self) {
        self.open = None;
    }

    /// Replaces `current` with the state before the newest step. False when there is none.
    pub fn undo(&mut self, current: &mut S) -> bool {
        let Some(before) = self.undo.pop_back() else {
            return false;
        };
        self.redo.push(std::mem::replace(current, before));
        self.open = None;
        true
    }

    /// Replaces `current` with the state most recently undone. False when there is none.
    pub fn redo(&mut self, current: &mut S) -> bool {
        let Some(after) = self.redo.pop() else {
            return false;
        };
        self.undo.push_back(std::mem::replace(current, after));
        self.open = None;
        true
    }

    pub fn can_undo(&self) -> bool {
        !self.undo.is_empty()
    }

    pub fn can_redo(&self) -> bool {
        !self.redo.is_empty()
    }

    /// Every state kept for undo or redo, for rewriting them all when the document moves.
    pub fn states_mut(&mut self) -> impl Iterator<Item = &mut S> {
        self.undo.iter_mut().chain(self.redo.iter_mut())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Applies `value` to `state` as a document would, recording the step.
    fn change(history: &mut History<i32>, state: &mut i32, value: i32, key: Option<MergeKey>) {
        let before = std::mem::replace(state, value);
        history.record(before, state, key);
    }

    #[test]
    fn steps_undo_and_redo_in_order() {
        let mut history = History::new();
        let mut state = 0;
        change(&mut history, &mut state, 1, None);
        change(&mut history, &mut state, 2, None);
        assert!(history.undo(&mut state) && state == 1);
        assert!(history.undo(&mut state) && state == 0);
        assert!(!history.undo(&mut state) && state == 0);
        assert!(history.redo(&mut state) && state == 1);
        change(&mut history, &mut state, 5, None);
        assert!(!history.can_redo(), "a new change drops what was undone");
        assert!(history.undo(&mut state) && state == 1);
    }

    #[test]
    fn a_gesture_merges_until_it_ends() {
        let mut history = History::new();
        let mut state = 0;
        for value in 1..=5 {
            change(&mut history, &mut state, value, Some(MergeKey::Rotation));
        }
        history.end_gesture();
        change(&mut history, &mut state, 6, Some(MergeKey::Rotation));
        assert!(history.undo(&mut state) && state == 5, "a new gesture is a new step");
        assert!(history.undo(&mut state) && state == 0, "the whole first drag is one step");
        assert!(!history.can_undo());
    }

    #[test]
    fn other_keys_and_keyless_edits_do_not_merge() {
        let mut history = History::new();
        let mut state = 0;
        change(&mut history, &mut state, 1, Some(MergeKey::Rotation));
        change(&mut history, &mut state, 2, Some(MergeKey::Intensity));
        change(&mut history, &mut state, 3, Some(MergeKey::Intensity));
        change(&mut history, &mut state, 4, None);
        change(&mut history, &mut state, 5, Some(MergeKey::Intensity));
        let mut seen = vec![state];
        while history.undo(&mut state) {
            seen.push(state);
        }
        assert_eq!(seen, [5, 4, 3, 1, 0], "2 and 3 were one drag");
    }

    #[test]
    fn a_drag_back_to_its_start_leaves_no_step() {
        let mut history = History::new();
        let mut state = 0;
        change(&mut history, &mut state, 7, None);
        change(&mut history, &mut state, 8, Some(MergeKey::Rotation));
        change(&mut history, &mut state, 7, Some(MergeKey::Rotation));
        assert!(history.undo(&mut state) && state == 0, "only the keyless step remains");
        assert!(!history.can_undo());
    }

    #[test]
    fn the_oldest_steps_are_dropped_beyond_the_limit() {
        let mut history = History::new();
        let mut state = 0;
        for value in 1..=(UNDO_LIMIT as i32 + 10) {
            change(&mut history, &mut state, value, None);
        }
        let mut undone = 0;
        while history.undo(&mut state) {
            undone += 1;
        }
        assert_eq!((undone, state), (UNDO_LIMIT, 10));
    }
}
