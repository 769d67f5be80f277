//! The open document: the scene, its undo history and the view it was saved with.

use super::{Command, Edit, EditError, History};
use crate::io::json::FormatError;
use crate::io::project::{self, Project, ViewSettings};
use crate::scene::Scene;

/// The scene being edited and its history.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Document {
    pub scene: Scene,
    pub history: History,
}

impl Document {
    pub fn new(scene: Scene) -> Self {
        Self {
            scene,
            history: History::default(),
        }
    }

    /// Applies a command as a new undo step (see [`History::execute`]).
    pub fn execute(&mut self, command: &Command) -> Result<&Edit, EditError> {
        self.history.execute(&mut self.scene, command)
    }

    pub fn undo(&mut self) -> Result<&Edit, EditError> {
        self.history.undo(&mut self.scene)
    }

    pub fn redo(&mut self) -> Result<&Edit, EditError> {
        self.history.redo(&mut self.scene)
    }

    /// Replaces the document by the project in `text` and returns its view settings. A file
    /// that cannot be read leaves the document and its history exactly as they were.
    pub fn open(&mut self, text: &str) -> Result<Option<ViewSettings>, FormatError> {
        let Project { scene, view } = project::read(text)?;
        *self = Self::new(scene);
        Ok(view)
    }

    /// The document as project text (the history is not saved).
    pub fn save(&self, view: Option<ViewSettings>) -> String {
        project::write(&Project {
            scene: self.scene.clone(),
            view,
        })
    }
}
