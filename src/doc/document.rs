//! The open document: the scene, its undo history and the view it was saved with.

use super::{Command, Edit, EditError, History, PointDrag};
use crate::io::project::{self, Project};
use crate::scene::Scene;
use crate::scene::json::FormatError;
use crate::view::ViewSettings;

/// The scene being edited, its history and the drag in progress (a transient edit that is not
/// in the history yet). Replacing the document (open, new) drops its drag with it, so a drag can
/// never reach into another document.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Document {
    pub scene: Scene,
    pub history: History,
    pub(super) drag: Option<PointDrag>,
}

impl Document {
    pub fn new(scene: Scene) -> Self {
        Self {
            scene,
            history: History::default(),
            drag: None,
        }
    }

    /// Applies a command as a new undo step (see [`History::execute`]); a drag in progress is
    /// committed first, as its own step.
    pub fn execute(&mut self, command: &Command) -> Result<&Edit, EditError> {
        self.commit_drag();
        self.history.execute(&mut self.scene, command)
    }

    /// Undoes one step (a drag in progress is committed first, so it is what is undone).
    pub fn undo(&mut self) -> Result<&Edit, EditError> {
        self.commit_drag();
        self.history.undo(&mut self.scene)
    }

    pub fn redo(&mut self) -> Result<&Edit, EditError> {
        self.commit_drag();
        self.history.redo(&mut self.scene)
    }

    /// Replaces the document by the project in `text` and returns its view settings. A file
    /// that cannot be read leaves the document, its history and any drag exactly as they were.
    pub fn open(&mut self, text: &str) -> Result<Option<ViewSettings>, FormatError> {
        let Project { scene, view } = project::read(text)?;
        *self = Self::new(scene);
        Ok(view)
    }

    /// The document as project text (the history is not saved).
    pub fn save(&self, view: Option<ViewSettings>) -> String {
        project::write_scene(&self.scene, view.as_ref())
    }
}
