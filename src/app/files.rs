//! Opening, saving and autosaving projects. Desktop: native dialogs (`rfd`); web: a file
//! picker and a download. Both: files dropped on the window, and the autosave in eframe's
//! storage (local storage in the browser, a file in the data directory natively). Open takes
//! every format of [`crate::io::open`]: projects, knotwork's glTF exports (the embedded model),
//! other glTF files' meshes and OBJ files.

use eframe::egui;

use std::sync::Arc;

use super::{AppCommand, KnotworkApp, default_scene};
use crate::io::project::Project;

/// The storage key of the autosaved project.
pub const AUTOSAVE_KEY: &str = "knotwork.project";
/// The storage key of the recent documents (JSON: [`RecentDocument`]s, newest first).
pub const RECENT_KEY: &str = "knotwork.recent";
/// How many documents the Recent list keeps.
pub const RECENT_LIMIT: usize = 5;

/// A document the editor had open before New or Open replaced it, kept so that a reload can
/// still bring the work back.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct RecentDocument {
    /// What it was opened as ("sample scene", a file's name).
    pub name: String,
    pub objects: usize,
    /// The project text (with its view).
    pub text: String,
}

impl RecentDocument {
    /// "name · 3 objects", as the Recent list shows it.
    pub fn label(&self) -> String {
        let s = if self.objects == 1 { "" } else { "s" };
        format!("{} · {} object{s}", self.name, self.objects)
    }
}
/// Seconds of quiet after an edit before the autosave writes.
const AUTOSAVE_DELAY: f64 = 0.5;

/// The request for a file the browser read (or could not read) in the background.
#[cfg(target_arch = "wasm32")]
fn opened(name: String, bytes: Result<Vec<u8>, String>) -> AppCommand {
    match bytes {
        Ok(bytes) => AppCommand::Open { name, bytes },
        Err(reason) => AppCommand::OpenFailed { name, reason },
    }
}

/// A file with no directory to read companions from (a `.gltf`'s `.bin`).
fn no_companions(name: &str) -> Result<Vec<u8>, String> {
    Err(format!(
        "{name} is a separate file; open a .glb, or a .gltf whose buffers are embedded"
    ))
}

/// The most warnings an opened file's dialog lists.
const SHOWN_WARNINGS: usize = 12;

/// A STEP file being opened a body at a time, so that the editor draws its progress and
/// stays responsive; commands sent meanwhile wait for it.
pub struct RunningOpen {
    name: String,
    job: crate::io::step::OpenJob,
    budget: super::export::FrameBudget,
}

impl KnotworkApp {
    /// Opens a file's bytes in any format [`crate::io::open`] reads (a `.gltf` must have its
    /// buffers embedded here; the desktop's [`open_path`] also reads them from beside it).
    /// A PNG is used as the selected surface's height map instead ([`Self::use_height_image`]).
    pub fn open_file(&mut self, name: &str, bytes: impl Into<Vec<u8>>) {
        let bytes: Vec<u8> = bytes.into();
        let reader = crate::io::formats::format_of(name, &bytes).reader;
        if !reader.opens_document() {
            self.use_height_image(name, &bytes);
            return;
        }
        if reader == crate::io::formats::Reader::Step {
            self.start_open(name, bytes);
            return;
        }
        let project = crate::io::open(name, &bytes, &no_companions).map_err(|e| e.to_string());
        self.open_result(name, project);
    }

    /// Starts opening a STEP file a body at a time ([`RunningOpen`]); refused at once when
    /// it is not valid STEP. A file being opened already is cancelled first.
    fn start_open(&mut self, name: &str, bytes: Vec<u8>) {
        self.cancel_open();
        match crate::io::step::OpenJob::new(bytes) {
            Ok(job) => {
                self.running_open = Some(RunningOpen {
                    name: name.to_owned(),
                    job,
                    budget: Default::default(),
                })
            }
            Err(e) => self.open_failed(name, &e.to_string()),
        }
    }

    /// Stops opening the file being opened; the document stays as it was.
    pub(super) fn cancel_open(&mut self) {
        if let Some(running) = self.running_open.take() {
            self.status.open_progress = None;
            self.status.notice = Some(format!("stopped opening {}", running.name));
        }
    }

    /// The file being opened: bodies for as long as its [`super::export::FrameBudget`] gives
    /// (at least one), with a
    /// progress window and Cancel; the document when the last body is done.
    pub(super) fn step_open(&mut self, ctx: &egui::Context) {
        let Some(running) = &mut self.running_open else {
            self.status.open_progress = None;
            return;
        };
        let progress = running.job.progress();
        self.status.open_progress = Some(progress);
        let title = format!("Opening {}", running.name);
        if super::export::progress_window(ctx, &title, progress, running.job.stage()) {
            self.cancel_open();
            return;
        }
        let job = &mut running.job;
        match running.budget.run(|| job.step()) {
            Ok(false) => ctx.request_repaint(),
            Ok(true) => {
                if let Some(running) = self.running_open.take() {
                    self.status.open_progress = None;
                    let warnings = running.job.warnings().to_vec();
                    let project = running.job.finish().map_err(|e| e.to_string());
                    let opened = project.is_ok();
                    self.open_result(&running.name, project);
                    if opened && self.running_open.is_none() && self.dialog.is_none() {
                        self.show_open_warnings(&running.name, warnings);
                    }
                }
                ctx.request_repaint();
            }
            Err(e) => {
                if let Some(running) = self.running_open.take() {
                    self.status.open_progress = None;
                    self.open_failed(&running.name, &e.to_string());
                }
                ctx.request_repaint();
            }
        }
    }

    /// What an opened file could not give, in the status (`warnings`), the notice and a
    /// dialog listing it (the summary lines first, then each face, at most
    /// [`SHOWN_WARNINGS`]).
    fn show_open_warnings(&mut self, name: &str, warnings: Vec<String>) {
        self.status.warnings = warnings;
        let Some(first) = self.status.warnings.first() else {
            return;
        };
        self.status.notice = Some(format!("opened {name}: {first}"));
        let mut text: Vec<String> = self
            .status
            .warnings
            .iter()
            .take(SHOWN_WARNINGS)
            .cloned()
            .collect();
        let more = self.status.warnings.len().saturating_sub(SHOWN_WARNINGS);
        if more > 0 {
            text.push(format!("… and {more} more"));
        }
        self.dialog = Some(super::Dialog {
            title: format!("Opened {name} with warnings"),
            text: format!(
                "Everything else in the file was read.\n\n{}",
                text.join("\n")
            ),
            refused: false,
        });
    }

    pub(super) fn open_failed(&mut self, name: &str, message: &str) {
        self.dialog = Some(super::Dialog::refused(
            format!("Could not open {name}"),
            message,
        ));
        self.status.error = Some(format!("{name}: {message}"));
    }

    /// Makes `project` the open document as one undo step ("open NAME": Undo brings the
    /// document before back), the document it replaces kept in the Recent list. If the GPU
    /// cannot show it, a dialog names the problem and the document, its history and the GPU
    /// geometry stay as they were.
    pub fn open_project(&mut self, name: &str, project: Project) {
        self.status.warnings.clear();
        let Project { scene, view } = project;
        let previous_view = self.view;
        if let Some(view) = view {
            self.view = view;
        }
        if let Err(e) = self.replace_scene(name, scene, format!("open {name}")) {
            self.view = previous_view;
            self.open_failed(name, &e);
            return;
        }
        if view.is_none() {
            self.frame_pending = true;
        }
        self.status.notice = Some(format!("opened {name}"));
    }

    /// Starts again from the sample scene, or (`empty`) from no objects at all: one undo
    /// step, the document it replaces kept in the Recent list.
    pub(super) fn new_document(&mut self, empty: bool) {
        let (name, scene) = if empty {
            ("empty scene", crate::scene::Scene::default())
        } else {
            ("sample scene", default_scene(&mut self.status))
        };
        match self.replace_scene(name, scene, format!("new {name}")) {
            Ok(()) => self.frame_pending = true,
            Err(e) => self.status.error = Some(e),
        }
    }

    /// Replaces every object by `scene`'s as one undo step labelled `label`, after keeping
    /// the document so far in the Recent list (when it was edited since it was opened). On
    /// failure (the GPU cannot show the new scene) nothing changes.
    fn replace_scene(
        &mut self,
        name: &str,
        scene: crate::scene::Scene,
        label: String,
    ) -> Result<(), String> {
        // A drag in progress belongs to the document being replaced: it ends there.
        self.end_drag(false);
        self.cancel_export();
        let before = self.current_as_recent();
        let command = crate::doc::Command::ReplaceScene {
            scene,
            label,
            name: name.to_owned(),
        };
        let touched = self
            .doc
            .execute(&command)
            .map(crate::doc::Edit::touched)
            .map_err(|e| e.to_string())?;
        if let Err(e) = self.after_edit(touched) {
            // The GPU cannot show it (e.g. a degree above the evaluator's maximum): put the
            // document before back, and forget the step.
            if self.doc.undo().is_ok() {
                self.doc.history.drop_redo();
            }
            let _ = self.after_edit(touched);
            return Err(e);
        }
        if let Some(recent) = before {
            self.remember(recent);
        }
        self.saved.opened_revision = self.saved.revision;
        // The Export window's tolerance follows the new document's size.
        self.export.tolerance = 0.0;
        self.select(None);
        self.status.error = None;
        Ok(())
    }

    /// What the open document was opened as ("sample scene", a file's name): the newest New
    /// or Open the undo history still holds, else what the editor started with.
    pub fn document_name(&self) -> String {
        self.doc
            .history
            .document_name()
            .unwrap_or(&self.saved.base_name)
            .to_owned()
    }

    /// The open document as a Recent entry, if it was changed since it was opened (an
    /// untouched sample or file is there to open again anyway).
    fn current_as_recent(&self) -> Option<RecentDocument> {
        (self.saved.revision != self.saved.opened_revision && !self.scene().objects.is_empty())
            .then(|| RecentDocument {
                name: self.document_name(),
                objects: self.scene().objects.len(),
                text: self.doc.save(Some(self.view)),
            })
    }

    /// Puts `recent` first in the Recent list (once), keeping at most [`RECENT_LIMIT`].
    fn remember(&mut self, recent: RecentDocument) {
        let list = &mut self.saved.recent;
        list.retain(|r| r.text != recent.text);
        list.insert(0, recent);
        list.truncate(RECENT_LIMIT);
        self.saved.recent_changed = true;
    }

    /// Opens entry `index` of the Recent list (one undo step, as Open).
    pub(super) fn open_recent(&mut self, index: usize) {
        let Some(recent) = self.saved.recent.get(index).cloned() else {
            let count = self.saved.recent.len();
            self.status.error = Some(format!(
                "there is no recent document {index}: the list has {count}"
            ));
            return;
        };
        match crate::io::project::read(&recent.text) {
            Ok(project) => self.open_project(&recent.name, project),
            Err(e) => self.open_failed(&recent.name, &e.to_string()),
        }
    }

    /// The Recent list from `storage` (empty where there is none or it cannot be read).
    pub(super) fn load_recent(&mut self, storage: Option<&dyn eframe::Storage>) {
        let text = storage.and_then(|s| s.get_string(RECENT_KEY));
        self.saved.recent = text
            .and_then(|t| serde_json::from_str(&t).ok())
            .unwrap_or_default();
    }

    /// Opens the autosaved project, if there is one; returns what to tell the user.
    pub(super) fn restore_autosave(
        &mut self,
        storage: Option<&dyn eframe::Storage>,
    ) -> Option<String> {
        let text = storage.and_then(|s| s.get_string(AUTOSAVE_KEY))?;
        match self.doc.open(&text) {
            Ok(view) => {
                if let Some(view) = view {
                    self.view = view;
                    self.frame_pending = false;
                }
                self.saved.base_name = "autosaved project".into();
                self.saved.opened_revision = u64::MAX;
                Some("restored the autosaved project".into())
            }
            Err(e) => Some(format!(
                "the autosaved project could not be restored ({e}); starting from the sample scene"
            )),
        }
    }

    /// Writes the project to the storage once edits have settled.
    pub(super) fn autosave(&mut self, ctx: &egui::Context, frame: &mut eframe::Frame) {
        if !self.saved.autosave
            || self.saved.revision == self.saved.autosaved_revision
            || self.doc.drag().is_some()
        {
            return;
        }
        let now = ctx.input(|i| i.time);
        if self.saved.revision != self.saved.pending_revision {
            self.saved.pending_revision = self.saved.revision;
            self.saved.last_change = now;
        }
        if now - self.saved.last_change < AUTOSAVE_DELAY {
            ctx.request_repaint_after(std::time::Duration::from_secs_f64(AUTOSAVE_DELAY));
            return;
        }
        if let Some(storage) = frame.storage_mut() {
            self.write_autosave(storage);
        }
    }

    /// Writes the project to `storage` now, if it changed since the last autosave (a drag still
    /// in progress counts once it ends). eframe calls this when the window closes, so an edit
    /// made within the autosave delay is not lost.
    pub fn write_autosave(&mut self, storage: &mut dyn eframe::Storage) {
        if self.saved.autosave
            && std::mem::take(&mut self.saved.recent_changed)
            && let Ok(text) = serde_json::to_string(&self.saved.recent)
        {
            storage.set_string(RECENT_KEY, text);
        }
        if !self.saved.autosave || self.saved.revision == self.saved.autosaved_revision {
            return;
        }
        storage.set_string(AUTOSAVE_KEY, self.doc.save(Some(self.view)));
        storage.flush();
        self.saved.autosaved_revision = self.saved.revision;
    }

    /// Opens files dropped on the window (the browser reads them in the background and sends
    /// an [`AppCommand::Open`]).
    pub(super) fn take_dropped(&mut self, ctx: &egui::Context) {
        let dropped = ctx.input(|i| i.raw.dropped_files.clone());
        for file in dropped {
            let name = file.path().display().to_string();
            #[cfg(not(target_arch = "wasm32"))]
            {
                // From its path where it has one: the size is checked before reading, and a
                // .gltf's .bin is read from beside it.
                if file.path().is_file() {
                    self.open_path_or_image(file.path());
                    continue;
                }
                match file.bytes() {
                    Ok(bytes) => self.open_file(&name, bytes),
                    Err(e) => self.open_failed(&name, &e),
                }
            }
            #[cfg(target_arch = "wasm32")]
            {
                let sender = self.command_sender();
                wasm_bindgen_futures::spawn_local(async move {
                    let bytes = file.bytes_async().await;
                    sender.send(opened(name, bytes));
                });
            }
        }
    }

    /// Opens `project`, or shows why the file `name` could not be read.
    pub fn open_result(&mut self, name: &str, project: Result<Project, String>) {
        match project {
            Ok(project) => self.open_project(name, project),
            Err(e) => self.open_failed(name, &e),
        }
    }

    /// Uses the PNG `bytes` as the height map of the selected surface: a displacement by the
    /// image (keeping the amplitude and frequency it had, else 5 % of its size, once), one
    /// undo step. Refused with the reason when nothing with a (u, v) domain is selected or the
    /// image cannot be read.
    pub(super) fn use_height_image(&mut self, name: &str, bytes: &[u8]) {
        use crate::kernel::displace::Displacement;
        let target = self.selection.object.filter(|&s| {
            self.scene()
                .objects
                .get(s)
                .is_some_and(|o| o.geometry.displacement_domain().is_some())
        });
        let Some(s) = target else {
            self.status.error = Some(format!(
                "{name}: select a NURBS surface, a Bézier patch set or a triangular patch to use \
                 the image as its height map"
            ));
            return;
        };
        let object = &self.scene().objects[s];
        let size = object
            .kind()
            .bounds()
            .map_or(1.0, |(lo, hi)| lo.distance(hi).max(1e-9));
        let (amplitude, frequency) = object
            .displacement
            .as_ref()
            .map_or((0.05 * size, 1.0), |d| (d.amplitude, d.frequency));
        let displacement = crate::io::height_image::decode_png(bytes).and_then(|image| {
            Displacement::with_image(Arc::new(image), amplitude, frequency)
                .map_err(|e| e.to_string())
        });
        match displacement {
            Ok(d) => self.apply(AppCommand::Edit(crate::doc::Command::SetDisplacement {
                object: s,
                displacement: Some(d),
            })),
            Err(e) => self.status.error = Some(format!("{name}: {e}")),
        }
    }

    /// Lets the user choose a PNG for the selected surface's height map.
    pub(super) fn height_image_dialog(&mut self) {
        #[cfg(not(target_arch = "wasm32"))]
        {
            if let Some(path) = super::platform::choose_file_to_open("PNG height map", &["png"]) {
                let name = path.display().to_string();
                match read_limited(&path) {
                    Ok(bytes) => self.use_height_image(&name, &bytes),
                    Err(e) => self.status.error = Some(format!("{name}: {e}")),
                }
            }
        }
        #[cfg(target_arch = "wasm32")]
        self.pick_in_browser(".png,image/png");
    }

    /// Shows the open dialog (desktop: blocking native dialog; web: the browser's picker).
    pub(super) fn open_dialog(&mut self) {
        #[cfg(not(target_arch = "wasm32"))]
        {
            let mut extensions = crate::io::formats::extensions(true);
            extensions.extend(crate::io::formats::extensions(false));
            let names: Vec<&str> = crate::io::formats::FORMATS.iter().map(|f| f.name).collect();
            if let Some(path) = super::platform::choose_file_to_open(&names.join(", "), &extensions)
            {
                self.open_path_or_image(&path);
            }
        }
        #[cfg(target_arch = "wasm32")]
        self.pick_in_browser(&crate::io::formats::accept_list());
    }

    /// Opens the file at `path`, or uses it as a height map if it is a PNG.
    #[cfg(not(target_arch = "wasm32"))]
    fn open_path_or_image(&mut self, path: &std::path::Path) {
        let name = path.display().to_string();
        if crate::io::height_image::is_height_image(&name) {
            match read_limited(path) {
                Ok(bytes) => self.use_height_image(&name, &bytes),
                Err(e) => self.open_failed(&name, &e),
            }
        } else if crate::io::formats::format_of(&name, &[]).reader
            == crate::io::formats::Reader::Step
        {
            match read_limited(path) {
                Ok(bytes) => self.open_file(&name, bytes),
                Err(e) => self.open_failed(&name, &e),
            }
        } else {
            self.open_result(&name, open_path(path));
        }
    }

    /// The browser's picker (offering `accept`); the file arrives as an [`AppCommand::Open`].
    #[cfg(target_arch = "wasm32")]
    fn pick_in_browser(&mut self, accept: &str) {
        let accept = accept.to_owned();
        let sender = self.command_sender();
        wasm_bindgen_futures::spawn_local(async move {
            if let Some((name, bytes)) = super::platform::pick_file(&accept).await {
                sender.send(opened(name, bytes));
            }
        });
    }

    /// Saves the project (desktop: a native save dialog; web: a download).
    pub(super) fn save_dialog(&mut self) {
        let text = self.doc.save(Some(self.view));
        #[cfg(not(target_arch = "wasm32"))]
        {
            if let Some(path) = super::platform::choose_file_to_save(
                "knotwork project",
                &["json", "knotwork"],
                "project.knotwork.json",
            ) {
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
            match super::platform::download(
                "project.knotwork.json",
                text.as_bytes(),
                "application/json",
            ) {
                Ok(()) => self.status.notice = Some("downloaded project.knotwork.json".into()),
                Err(e) => self.status.error = Some(format!("could not download: {e}")),
            }
        }
    }
}

/// Reads a file's bytes, refusing files over the size limit before reading them.
#[cfg(not(target_arch = "wasm32"))]
fn read_limited(path: &std::path::Path) -> Result<Vec<u8>, String> {
    let size = std::fs::metadata(path).map_err(|e| e.to_string())?.len();
    crate::io::project::check_size(size).map_err(|e| e.to_string())?;
    std::fs::read(path).map_err(|e| e.to_string())
}

/// Opens the file at `path` in any format [`crate::io::open`] reads; a `.gltf`'s buffers are
/// read from its directory.
#[cfg(not(target_arch = "wasm32"))]
pub fn open_path(path: &std::path::Path) -> Result<Project, String> {
    let bytes = read_limited(path)?;
    let directory = path.parent().map(std::path::Path::to_path_buf);
    let companion = move |name: &str| match &directory {
        Some(dir) => read_limited(&dir.join(name)),
        None => no_companions(name),
    };
    crate::io::open(&path.display().to_string(), &bytes, &companion).map_err(|e| e.to_string())
}

/// `knotwork apply`: runs the operation whose JSON value (`{"op": NAME, ...}`) is `operation`
/// on the document in the file `project` (any format [`open_path`] reads), through
/// the document as the editor does (with history when `keep_history`), writes the result as a
/// project to `output` and returns what it did as JSON: `{"label", "added", "changed",
/// "removed"}` (object names), and `"report"` where the operation gives one (an offset's
/// deviation and folds, a fillet's sections). Refused, with nothing written, when the operation cannot be
/// read or the document refuses it.
#[cfg(not(target_arch = "wasm32"))]
pub fn apply_to_file(
    operation: &str,
    project: &std::path::Path,
    output: &std::path::Path,
    keep_history: bool,
) -> Result<serde_json::Value, String> {
    use crate::doc::{Change, Command};
    let operation = crate::ops::parse(operation).map_err(|e| format!("the operation: {e}"))?;
    let mut document =
        open_path(project).map_err(|e| format!("cannot open {}: {e}", project.display()))?;
    let (edit, report) = crate::doc::apply_reporting(
        &mut document.scene,
        &Command::Apply {
            operation,
            keep_history,
        },
    )
    .map_err(|e| e.to_string())?;
    let (mut added, mut changed, mut removed) = (Vec::new(), Vec::new(), Vec::new());
    for change in &edit.changes {
        match change {
            Change::Insert { object, .. } => added.push(object.name.clone()),
            Change::Replace { after, .. } => changed.push(after.name.clone()),
            Change::Remove { object, .. } => removed.push(object.name.clone()),
            Change::Unit { .. } => {}
        }
    }
    std::fs::write(output, crate::io::project::write(&document))
        .map_err(|e| format!("cannot write {}: {e}", output.display()))?;
    let mut result = serde_json::json!({
        "label": edit.label,
        "added": added,
        "changed": changed,
        "removed": removed,
    });
    if let Some(report) = report {
        result["report"] = report;
    }
    Ok(result)
}
