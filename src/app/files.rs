//! Opening, saving and autosaving projects. Desktop: native dialogs (`rfd`); web: a file
//! picker and a download. Both: files dropped on the window, and the autosave in eframe's
//! storage (local storage in the browser, a file in the data directory natively).

use std::sync::{Arc, Mutex};

use eframe::egui;

use super::{KnotworkApp, default_scene};
use crate::doc::Document;
use crate::gpu::ShadingMode;
use crate::io::project::{self, ViewSettings};

/// The storage key of the autosaved project.
pub const AUTOSAVE_KEY: &str = "knotwork.project";
/// Seconds of quiet after an edit before the autosave writes.
const AUTOSAVE_DELAY: f64 = 0.5;

/// Files picked (asynchronously on the web) or dropped, waiting to be opened: (name, text).
pub type Incoming = Arc<Mutex<Vec<(String, Result<String, String>)>>>;

/// Reads dropped or picked bytes as project text, refusing files over the size limit.
fn project_text(bytes: &[u8]) -> Result<String, String> {
    project::check_size(bytes.len() as u64).map_err(|e| e.to_string())?;
    String::from_utf8(bytes.to_vec()).map_err(|e| format!("the file is not UTF-8 text: {e}"))
}

impl KnotworkApp {
    fn view_settings(&self) -> ViewSettings {
        ViewSettings {
            target: self.camera.target.as_dvec3().to_array(),
            distance: f64::from(self.camera.distance),
            yaw: f64::from(self.camera.yaw),
            pitch: f64::from(self.camera.pitch),
            shading: self.shading.name().to_owned(),
            quality: f64::from(self.quality),
        }
    }

    fn apply_view(&mut self, view: &ViewSettings) {
        self.camera.target = glam::DVec3::from(view.target).as_vec3();
        self.camera.distance = view.distance as f32;
        self.camera.yaw = view.yaw as f32;
        self.camera.pitch = (view.pitch as f32).clamp(-1.56, 1.56);
        if let Some(mode) = ShadingMode::from_name(&view.shading) {
            self.shading = mode;
        }
        let quality = view.quality as f32;
        if super::QUALITY_RANGE.contains(&quality) {
            self.quality = quality;
        }
    }

    /// Opens project text; a file that cannot be read shows a dialog naming the problem and
    /// leaves the document, its history and the GPU geometry as they were.
    pub fn open_project(&mut self, name: &str, text: &str) {
        let (scene, view) = match project::read(text) {
            Ok(project) => (project.scene, project.view),
            Err(e) => {
                self.dialog = Some((format!("Could not open {name}"), e.to_string()));
                self.status.error = Some(format!("{name}: {e}"));
                return;
            }
        };
        let previous = std::mem::replace(&mut self.doc, Document::new(scene));
        let (camera, shading, quality) = (self.camera, self.shading, self.quality);
        if let Some(view) = &view {
            self.apply_view(view);
        }
        if let Err(e) = self.after_edit(crate::doc::Touched::Structure) {
            // The GPU cannot show it (e.g. a degree above the evaluator's maximum): put the old
            // document back.
            self.doc = previous;
            (self.camera, self.shading, self.quality) = (camera, shading, quality);
            let _ = self.after_edit(crate::doc::Touched::Structure);
            self.dialog = Some((format!("Could not open {name}"), e.clone()));
            self.status.error = Some(format!("{name}: {e}"));
            return;
        }
        self.select(None);
        if view.is_none() {
            self.frame_pending = true;
        }
        self.status.error = None;
        self.status.notice = Some(format!("opened {name}"));
    }

    /// Starts again from the sample scene (an empty history).
    pub(super) fn new_document(&mut self) {
        let scene = default_scene(&mut self.status);
        self.doc = Document::new(scene);
        self.select(None);
        if let Err(e) = self.after_edit(crate::doc::Touched::Structure) {
            self.status.error = Some(e);
        }
        self.frame_pending = true;
    }

    /// Opens the autosaved project, if there is one; returns what to tell the user.
    pub(super) fn restore_autosave(
        &mut self,
        storage: Option<&dyn eframe::Storage>,
    ) -> Option<String> {
        let text = storage.and_then(|s| s.get_string(AUTOSAVE_KEY))?;
        match self.doc.open(&text) {
            Ok(view) => {
                if let Some(view) = &view {
                    self.apply_view(view);
                    self.frame_pending = false;
                }
                Some("restored the autosaved project".into())
            }
            Err(e) => Some(format!(
                "the autosaved project could not be restored ({e}); starting from the sample scene"
            )),
        }
    }

    /// Writes the project to the storage once edits have settled.
    pub(super) fn autosave(&mut self, ctx: &egui::Context, frame: &mut eframe::Frame) {
        if !self.autosave || self.revision == self.autosaved_revision || self.drag.is_some() {
            return;
        }
        let now = ctx.input(|i| i.time);
        if self.revision != self.pending_revision {
            self.pending_revision = self.revision;
            self.last_change = now;
        }
        if now - self.last_change < AUTOSAVE_DELAY {
            ctx.request_repaint_after(std::time::Duration::from_secs_f64(AUTOSAVE_DELAY));
            return;
        }
        if let Some(storage) = frame.storage_mut() {
            storage.set_string(AUTOSAVE_KEY, self.doc.save(Some(self.view_settings())));
            storage.flush();
            self.autosaved_revision = self.revision;
        }
    }

    /// Files dropped on the window and files the web picker delivered.
    pub(super) fn take_incoming(&mut self, ctx: &egui::Context) {
        let dropped = ctx.input(|i| i.raw.dropped_files.clone());
        for file in dropped {
            let name = file.path().display().to_string();
            #[cfg(not(target_arch = "wasm32"))]
            {
                let text = read_file(file.path())
                    .or_else(|_| file.bytes().and_then(|bytes| project_text(&bytes)));
                self.open_result(&name, text);
            }
            #[cfg(target_arch = "wasm32")]
            {
                let incoming = Arc::clone(&self.incoming);
                wasm_bindgen_futures::spawn_local(async move {
                    let text = file.bytes_async().await.and_then(|b| project_text(&b));
                    if let Ok(mut queue) = incoming.lock() {
                        queue.push((name, text));
                    }
                    if let Some(ctx) = crate::status::repaint_context() {
                        ctx.request_repaint();
                    }
                });
            }
        }
        let picked: Vec<_> = self
            .incoming
            .lock()
            .map(|mut q| std::mem::take(&mut *q))
            .unwrap_or_default();
        for (name, text) in picked {
            self.open_result(&name, text);
        }
    }

    fn open_result(&mut self, name: &str, text: Result<String, String>) {
        match text {
            Ok(text) => self.open_project(name, &text),
            Err(e) => {
                self.dialog = Some((format!("Could not open {name}"), e.clone()));
                self.status.error = Some(format!("{name}: {e}"));
            }
        }
    }

    /// Shows the open dialog (desktop: blocking native dialog; web: the browser's picker).
    pub(super) fn open_dialog(&mut self) {
        #[cfg(not(target_arch = "wasm32"))]
        {
            if let Some(path) = rfd::FileDialog::new()
                .add_filter("knotwork project", &["json", "knotwork"])
                .pick_file()
            {
                let name = path.display().to_string();
                self.open_result(&name, read_file(&path));
            }
        }
        #[cfg(target_arch = "wasm32")]
        {
            let incoming = Arc::clone(&self.incoming);
            wasm_bindgen_futures::spawn_local(async move {
                if let Some(text) = crate::web::pick_file_text().await {
                    if let Ok(mut queue) = incoming.lock() {
                        queue.push(text);
                    }
                    if let Some(ctx) = crate::status::repaint_context() {
                        ctx.request_repaint();
                    }
                }
            });
        }
    }

    /// Saves the project (desktop: a native save dialog; web: a download).
    pub(super) fn save_dialog(&mut self) {
        let text = self.doc.save(Some(self.view_settings()));
        #[cfg(not(target_arch = "wasm32"))]
        {
            if let Some(path) = rfd::FileDialog::new()
                .add_filter("knotwork project", &["json", "knotwork"])
                .set_file_name("project.knotwork.json")
                .save_file()
            {
                match std::fs::write(&path, text) {
                    Ok(()) => self.status.notice = Some(format!("saved {}", path.display())),
                    Err(e) => {
                        self.status.error = Some(format!("could not save {}: {e}", path.display()))
                    }
                }
            }
        }
        #[cfg(target_arch = "wasm32")]
        {
            match crate::web::download("project.knotwork.json", &text) {
                Ok(()) => self.status.notice = Some("downloaded project.knotwork.json".into()),
                Err(e) => self.status.error = Some(format!("could not download: {e}")),
            }
        }
    }
}

/// A project file's text, refusing files over the size limit before reading them.
#[cfg(not(target_arch = "wasm32"))]
pub fn read_file(path: &std::path::Path) -> Result<String, String> {
    let size = std::fs::metadata(path).map_err(|e| e.to_string())?.len();
    project::check_size(size).map_err(|e| e.to_string())?;
    let bytes = std::fs::read(path).map_err(|e| e.to_string())?;
    project_text(&bytes)
}
