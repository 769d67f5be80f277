//! Undo and redo: a stack of applied [`Edit`]s and a stack of undone ones.

use super::{Command, Edit, EditError, apply};
use crate::scene::Scene;

/// Undo steps kept; the oldest are dropped beyond this.
pub const HISTORY_LIMIT: usize = 500;

/// The undo and redo stacks of one document.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct History {
    undo: Vec<Edit>,
    redo: Vec<Edit>,
    /// The document name of the newest step dropped beyond [`HISTORY_LIMIT`] that had one.
    dropped_document: Option<String>,
}

impl History {
    /// Applies `command`; on success it becomes the newest undo step and the redo stack is
    /// cleared. On failure the scene and the history are untouched.
    pub fn execute(&mut self, scene: &mut Scene, command: &Command) -> Result<&Edit, EditError> {
        let edit = apply(scene, command)?;
        Ok(self.record(edit))
    }

    /// Records an edit that has already been applied (a drag, made of many moves, is one step).
    pub fn record(&mut self, edit: Edit) -> &Edit {
        self.redo.clear();
        if self.undo.len() == HISTORY_LIMIT {
            let dropped = self.undo.remove(0);
            if dropped.document.is_some() {
                self.dropped_document = dropped.document;
            }
        }
        self.undo.push(edit);
        &self.undo[self.undo.len() - 1]
    }

    /// Undoes the newest step and returns it. If the scene no longer matches it (which only
    /// code outside the history can cause) the scene is untouched, the history is cleared and
    /// the error says so.
    pub fn undo(&mut self, scene: &mut Scene) -> Result<&Edit, EditError> {
        self.step(scene, false)
    }

    /// Redoes the newest undone step and returns it.
    pub fn redo(&mut self, scene: &mut Scene) -> Result<&Edit, EditError> {
        self.step(scene, true)
    }

    /// Moves one edit from one stack to the other, applying it backward (undo) or forward.
    fn step(&mut self, scene: &mut Scene, forward: bool) -> Result<&Edit, EditError> {
        let what = if forward { "redo" } else { "undo" };
        let from = if forward {
            &mut self.redo
        } else {
            &mut self.undo
        };
        let edit = from.pop().ok_or(EditError::NothingTo(what))?;
        let applied = if forward {
            edit.redo(scene)
        } else {
            edit.undo(scene)
        };
        if let Err(e) = applied {
            // The edit failed, so the scene is as it was: an undo's edit is still applied.
            let showing = match (forward, &edit.document) {
                (false, Some(name)) => Some(name.clone()),
                _ => self.document_name().map(str::to_owned),
            };
            self.clear();
            self.dropped_document = showing;
            return Err(e);
        }
        let to = if forward {
            &mut self.undo
        } else {
            &mut self.redo
        };
        to.push(edit);
        Ok(&to[to.len() - 1])
    }

    /// Forgets the newest undone step (after the editor undid an edit it could not show).
    pub fn drop_redo(&mut self) {
        self.redo.pop();
    }

    /// Forgets every step; the name of the document still showing is kept.
    pub fn clear(&mut self) {
        self.dropped_document = self.document_name().map(str::to_owned);
        self.undo.clear();
        self.redo.clear();
    }

    /// The label of the step [`Self::undo`] would undo.
    pub fn undo_label(&self) -> Option<&str> {
        self.undo.last().map(|e| e.label.as_str())
    }

    /// The label of the step [`Self::redo`] would redo.
    pub fn redo_label(&self) -> Option<&str> {
        self.redo.last().map(|e| e.label.as_str())
    }

    /// The name of the document the newest New or Open still applied made
    /// ([`Edit::document`], or the last one dropped from the history), if any is.
    pub fn document_name(&self) -> Option<&str> {
        self.undo
            .iter()
            .rev()
            .find_map(|e| e.document.as_deref())
            .or(self.dropped_document.as_deref())
    }

    /// Steps that can be undone.
    pub fn undo_depth(&self) -> usize {
        self.undo.len()
    }

    /// Steps that can be redone.
    pub fn redo_depth(&self) -> usize {
        self.redo.len()
    }
}
