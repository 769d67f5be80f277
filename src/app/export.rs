//! The Export glTF window: tessellation by tolerance or segments, curvature attributes, the
//! triangle count before writing, then a save dialog (desktop) or a download (web); and the
//! exports written at once ([`FileExport`]): STEP, and STL and 3MF for printing.

use eframe::egui;

use super::KnotworkApp;
use crate::gpu::records::curvature_ramp_rgb;
use crate::io::gltf::{self, CurvatureColors, ExportOptions};
use crate::io::project::Project;
use crate::kernel::tess::{GridSampler, Tessellation};

/// What the Export window remembers.
#[derive(Debug, Clone, PartialEq)]
pub struct ExportSettings {
    pub show: bool,
    /// Tolerance (true) or fixed segments (false).
    pub by_tolerance: bool,
    /// Model units; 0 means "not set yet" (the default is taken from the scene's size).
    pub tolerance: f64,
    pub segments: u32,
    /// COLOR_0 from the current curvature shading mode.
    pub colors: bool,
    /// The `_CURVATURE` attribute.
    pub curvature: bool,
    /// Desktop: `.gltf` + `.bin` instead of `.glb`.
    pub text_format: bool,
}

impl Default for ExportSettings {
    fn default() -> Self {
        Self {
            show: false,
            by_tolerance: true,
            tolerance: 0.0,
            segments: 16,
            colors: false,
            curvature: false,
            text_format: false,
        }
    }
}

/// The triangle count shown before writing, for the document revision and settings it was
/// computed for.
#[derive(Debug, Clone, PartialEq)]
pub struct ExportEstimate {
    revision: u64,
    tessellation: Tessellation,
    pub result: Result<usize, String>,
}

impl ExportSettings {
    pub fn tessellation(&self) -> Tessellation {
        if self.by_tolerance {
            Tessellation::Tolerance(self.tolerance)
        } else {
            Tessellation::Segments(self.segments)
        }
    }
}

/// About how many triangles the visible objects make at `tessellation`, or why they cannot
/// be exported ([`gltf::estimate_triangles`]: quick however small the tolerance).
pub fn estimate_triangles(
    scene: &crate::scene::Scene,
    tessellation: Tessellation,
) -> Result<usize, String> {
    use crate::kernel::tess::{Estimate, MAX_TRIANGLES};
    gltf::estimate_triangles(scene, tessellation, MAX_TRIANGLES, Estimate::Close)
        .map(|counts| counts.iter().sum())
        .map_err(|e| e.to_string())
}

/// The least a frame spends on long work (an export, opening a file) before it draws again
/// (milliseconds).
const LEAST_WORK_MS: f64 = 30.0;
/// The most a frame spends on long work (milliseconds): the page answers (Cancel, a click)
/// within about this, however slow drawing is.
const MOST_WORK_MS: f64 = 1_000.0;
/// Long work takes this many times as long per frame as the rest of the frame (drawing,
/// the browser) took since its last turn: 80 % of the wall time, however slow drawing is.
const WORK_PER_OTHER: f64 = 4.0;

/// Long work spread over frames by wall time: each frame works [`WORK_PER_OTHER`] times as
/// long as everything else took since the last turn, within [`LEAST_WORK_MS`] and
/// [`MOST_WORK_MS`]. A fast frame (a GPU) keeps the page at 10 frames a second or more;
/// a slow one (a software adapter, where one frame may take seconds) no longer holds the
/// work back to a few milliseconds per frame: it works up to a second between frames.
#[derive(Debug, Default)]
pub(super) struct FrameBudget {
    /// When the last turn ended ([`super::platform::now_ms`]).
    last_end_ms: Option<f64>,
    /// The last turn's budget (milliseconds; 0 before the first).
    last_budget_ms: f64,
}

impl FrameBudget {
    /// How long this frame's turn may work (milliseconds), given the time now: at most twice
    /// the last turn's, so that a job starts with short turns (its progress shows, Cancel
    /// answers at once) and grows to its share over a few frames.
    fn budget_ms(&self, now_ms: f64) -> f64 {
        let other = self.last_end_ms.map_or(0.0, |end| (now_ms - end).max(0.0));
        (WORK_PER_OTHER * other)
            .min(2.0 * self.last_budget_ms)
            .clamp(LEAST_WORK_MS, MOST_WORK_MS)
    }

    /// One frame's turn: [`steps_within`] this frame's budget.
    pub(super) fn run<E>(&mut self, step: impl FnMut() -> Result<bool, E>) -> Result<bool, E> {
        let budget = self.budget_ms(super::platform::now_ms());
        let result = steps_within(budget, step);
        self.last_end_ms = Some(super::platform::now_ms());
        self.last_budget_ms = budget;
        result
    }
}

/// A window at the top with a progress bar, what is under way and Cancel (a long export or
/// open); true when Cancel was clicked.
pub(super) fn progress_window(
    ctx: &egui::Context,
    title: &str,
    progress: f64,
    doing: &str,
) -> bool {
    let mut cancel = false;
    egui::Window::new(title)
        .collapsible(false)
        .resizable(false)
        .anchor(egui::Align2::CENTER_TOP, egui::vec2(0.0, 60.0))
        .show(ctx, |ui| {
            ui.add(
                egui::ProgressBar::new(progress as f32)
                    .show_percentage()
                    .desired_width(260.0),
            );
            ui.label(doing);
            cancel = ui.button("Cancel").clicked();
        });
    cancel
}

/// Runs `step` (true when the work is done) until it is done or fails, or `budget_ms` have
/// passed: at least once, so that work always moves on, and then only while the frame has time.
pub(super) fn steps_within<E>(
    budget_ms: f64,
    mut step: impl FnMut() -> Result<bool, E>,
) -> Result<bool, E> {
    let started = super::platform::now_ms();
    let mut result = step();
    while matches!(result, Ok(false)) && super::platform::now_ms() - started < budget_ms {
        result = step();
    }
    result
}

/// Who evaluates an export's tessellation grids: `backend` in the page's export options
/// (`"auto"`, `"gpu"` or `"cpu"`), as `--backend` is on the command line.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum GridBackend {
    /// The GPU on a hardware adapter that runs the compute shaders, else the kernel.
    #[default]
    Auto,
    /// The GPU wherever the compute shaders run (a software adapter too), else the kernel.
    Gpu,
    /// The f64 kernel.
    Cpu,
}

impl GridBackend {
    /// The `backend` of the page's export options (JSON), [`Self::Auto`] where it is absent.
    pub fn from_json(options: &str) -> Result<Self, String> {
        let value: serde_json::Value =
            serde_json::from_str(options).map_err(|e| format!("export options: {e}"))?;
        match value.get("backend") {
            None | Some(serde_json::Value::Null) => Ok(Self::Auto),
            Some(name) => match name.as_str() {
                Some("auto") => Ok(Self::Auto),
                Some("gpu") => Ok(Self::Gpu),
                Some("cpu") => Ok(Self::Cpu),
                _ => Err(format!(
                    "export options: backend must be auto, gpu or cpu, got {name}"
                )),
            },
        }
    }
}

/// The export grids' evaluator as the viewport keeps it: shared with the export job that
/// waits for it on any thread natively, and with the one that asks without waiting in the
/// page (where the device's handles are not shared between threads).
#[cfg(not(target_arch = "wasm32"))]
pub(super) type ExportGrids = std::sync::Arc<crate::gpu::export_grids::GpuGrids>;
#[cfg(target_arch = "wasm32")]
pub(super) type ExportGrids = std::rc::Rc<crate::gpu::export_grids::GpuGrids>;

/// Where a finished export goes.
#[derive(Debug, Clone, PartialEq)]
pub enum ExportTarget {
    /// The page's `exportGlb` call with this request number.
    Page(u32),
    /// The Export window's file: the path chosen on the desktop (a `.gltf` writes its `.bin`
    /// beside it), the download's name in the page.
    File(String),
}

/// A file export written at once, without the glTF window's settings: exact STEP, or a mesh
/// for printing.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FileExport {
    /// AP214 with exact B-spline faces, solids as `MANIFOLD_SOLID_BREP`.
    Step,
    /// Binary STL.
    Stl,
    /// 3MF with the document's unit and each object's colour.
    ThreeMf,
}

impl FileExport {
    /// The format's name, as menus say it.
    pub fn label(self) -> &'static str {
        match self {
            FileExport::Step => "STEP",
            FileExport::Stl => "STL",
            FileExport::ThreeMf => "3MF",
        }
    }

    /// The file name extensions, the usual one first.
    pub fn extensions(self) -> &'static [&'static str] {
        match self {
            FileExport::Step => &["step", "stp"],
            FileExport::Stl => &["stl"],
            FileExport::ThreeMf => &["3mf"],
        }
    }

    /// The media type of a download.
    #[cfg(target_arch = "wasm32")]
    fn mime(self) -> &'static str {
        match self {
            FileExport::Step => "model/step",
            FileExport::Stl => "model/stl",
            FileExport::ThreeMf => "model/3mf",
        }
    }

    /// The format named `name` (as the page names it: "step", "stl", "3mf").
    pub fn from_name(name: &str) -> Option<Self> {
        [FileExport::Step, FileExport::Stl, FileExport::ThreeMf]
            .into_iter()
            .find(|f| f.extensions().contains(&name.to_ascii_lowercase().as_str()))
    }

    /// The file of `scene`'s visible objects in this format, and notes for the status (what
    /// was left out or approximated), or why it cannot be written.
    pub fn write(
        self,
        scene: &crate::scene::Scene,
        file_name: &str,
        sampler: &dyn GridSampler,
    ) -> Result<(Vec<u8>, String), String> {
        let tessellation = Tessellation::Tolerance(gltf::default_tolerance(scene));
        match self {
            FileExport::Step => {
                let tolerance = crate::io::step::default_tolerance(scene);
                let written = crate::io::step::export_scene(scene, file_name, tolerance)
                    .map_err(|e| e.to_string())?;
                let mut notes = String::new();
                if !written.left_out.is_empty() {
                    notes = format!("; left out {}", written.left_out.join("; "));
                }
                for a in &written.approximated {
                    notes.push_str("; ");
                    notes.push_str(a);
                }
                Ok((written.text.into_bytes(), notes))
            }
            FileExport::Stl => {
                let (bytes, facets) = crate::io::stl::write(scene, tessellation, sampler)
                    .map_err(|e| e.to_string())?;
                Ok((bytes, format!(": {facets} facets")))
            }
            FileExport::ThreeMf => {
                let package = crate::io::threemf::write(scene, tessellation, sampler)
                    .map_err(|e| e.to_string())?;
                Ok((
                    package.bytes,
                    format!(
                        ": {} objects, {} triangles",
                        package.objects, package.triangles
                    ),
                ))
            }
        }
    }
}

/// An export under way: the job and where its result goes.
pub struct RunningExport {
    job: gltf::ExportJob,
    target: ExportTarget,
    budget: FrameBudget,
}

impl KnotworkApp {
    /// The export options the window's settings and the current shading mode give.
    fn export_options(&mut self) -> ExportOptions {
        let colors = if self.export.colors {
            self.view
                .shading
                .curvature_component()
                .map(|component| CurvatureColors {
                    component,
                    range: self.color_range().unwrap_or((-1.0, 1.0)),
                    ramp: curvature_ramp_rgb(),
                })
        } else {
            None
        };
        ExportOptions {
            tessellation: self.export.tessellation(),
            curvature: self.export.curvature,
            colors,
        }
    }

    pub(super) fn export_window(&mut self, ctx: &egui::Context) {
        if !self.export.show {
            return;
        }
        if !(self.export.tolerance > 0.0) {
            self.export.tolerance = gltf::default_tolerance(&self.doc.scene);
        }
        let tessellation = self.export.tessellation();
        let stale = self
            .export_estimate
            .as_ref()
            .is_none_or(|e| e.revision != self.saved.revision || e.tessellation != tessellation);
        if stale {
            self.export_estimate = Some(ExportEstimate {
                revision: self.saved.revision,
                tessellation,
                result: estimate_triangles(&self.doc.scene, tessellation),
            });
        }
        let estimate = match self.export_estimate.as_ref().map(|e| &e.result) {
            Some(Ok(t)) => Ok(format!("about {t} triangles")),
            Some(Err(e)) => Err(e.clone()),
            None => Ok(String::new()),
        };
        self.status.export_estimate = Some(estimate.clone().unwrap_or_else(|e| e));
        let mut open = true;
        let mut write = false;
        let curvature_mode = self.view.shading.curvature_component().is_some();
        let running = self.running_export.is_some();
        let settings = &mut self.export;
        let before = settings.clone();
        egui::Window::new("Export glTF")
            .open(&mut open)
            .resizable(false)
            .show(ctx, |ui| {
                ui.radio_value(&mut settings.by_tolerance, true, "By tolerance");
                ui.add_enabled(
                    settings.by_tolerance,
                    egui::Slider::new(&mut settings.tolerance, 1e-6..=10.0)
                        .logarithmic(true)
                        .text("max. distance (model units)"),
                );
                ui.radio_value(&mut settings.by_tolerance, false, "By segments");
                ui.add_enabled(
                    !settings.by_tolerance,
                    egui::Slider::new(&mut settings.segments, 1..=256)
                        .logarithmic(true)
                        .text("segments per span"),
                );
                ui.add_enabled(
                    curvature_mode,
                    egui::Checkbox::new(
                        &mut settings.colors,
                        "Curvature colours (COLOR_0, this shading mode)",
                    ),
                );
                ui.checkbox(
                    &mut settings.curvature,
                    "Raw curvature (_CURVATURE: K, H, k1, k2)",
                );
                if cfg!(not(target_arch = "wasm32")) {
                    ui.checkbox(&mut settings.text_format, ".gltf + .bin instead of .glb");
                }
                ui.separator();
                match &estimate {
                    Ok(text) => ui.label(text),
                    Err(e) => ui.colored_label(egui::Color32::from_rgb(255, 110, 100), e),
                };
                write = ui
                    .add_enabled(estimate.is_ok() && !running, egui::Button::new("Export…"))
                    .clicked();
            });
        if *settings != before {
            ctx.request_repaint();
        }
        self.export.show = open;
        if !curvature_mode {
            self.export.colors = false;
        }
        if write {
            self.export_to_file();
        }
    }

    /// Starts the export the window's settings give, to a file (desktop: the path chosen
    /// first in a save dialog; web: a download when it is done).
    fn export_to_file(&mut self) {
        #[cfg(not(target_arch = "wasm32"))]
        let path = {
            let (filter, extension) = if self.export.text_format {
                ("glTF (text + .bin)", "gltf")
            } else {
                ("glTF binary", "glb")
            };
            let Some(path) = super::platform::choose_file_to_save(
                filter,
                &[extension],
                &format!("knotwork.{extension}"),
            ) else {
                return;
            };
            let mut path = path.display().to_string();
            if !path
                .to_ascii_lowercase()
                .ends_with(&format!(".{extension}"))
            {
                path.push('.');
                path.push_str(extension);
            }
            path
        };
        #[cfg(target_arch = "wasm32")]
        let path = "knotwork.glb".to_owned();
        let options = self.export_options();
        self.start_export(options, GridBackend::Auto, ExportTarget::File(path));
    }

    /// Writes the visible objects as `format` to a file: the path chosen in a save dialog
    /// (desktop), a download (web).
    pub(super) fn export_file_to_path(&mut self, format: FileExport) {
        let default_name = format!("knotwork.{}", format.extensions()[0]);
        #[cfg(not(target_arch = "wasm32"))]
        let path = {
            let Some(path) = super::platform::choose_file_to_save(
                format.label(),
                format.extensions(),
                &default_name,
            ) else {
                return;
            };
            let mut path = path.display().to_string();
            let extension = crate::io::formats::extension(&path);
            if !format.extensions().contains(&extension.as_str()) {
                path.push('.');
                path.push_str(format.extensions()[0]);
            }
            path
        };
        #[cfg(target_arch = "wasm32")]
        let path = default_name;
        self.export_file(format, ExportTarget::File(path));
    }

    /// Writes the visible objects with faces as `format` to `target`: STEP at the writer's
    /// default tolerance ([`crate::io::step::export_scene`]), STL and 3MF at the glTF export's
    /// default tolerance; what was left out is said in the status, a refusal in a dialog.
    pub(super) fn export_file(&mut self, format: FileExport, target: ExportTarget) {
        let file_name = match &target {
            ExportTarget::File(path) => std::path::Path::new(path)
                .file_name()
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_default(),
            ExportTarget::Page(_) => format!("knotwork.{}", format.extensions()[0]),
        };
        let sampler = self.export_sampler(GridBackend::Auto);
        let scene = &self.doc.scene;
        let (bytes, notes) = match format.write(scene, &file_name, sampler.as_ref()) {
            Ok(written) => written,
            Err(e) => {
                match target {
                    ExportTarget::Page(request) => crate::status::finish_export(request, Err(e)),
                    ExportTarget::File(_) => {
                        self.dialog = Some(super::Dialog::refused(
                            format!("Could not export {}", format.label()),
                            e.clone(),
                        ));
                        self.status.error = Some(format!("{} export: {e}", format.label()));
                    }
                }
                return;
            }
        };
        match target {
            ExportTarget::Page(request) => crate::status::finish_export(request, Ok(bytes)),
            ExportTarget::File(path) => {
                #[cfg(not(target_arch = "wasm32"))]
                let written = std::fs::write(&path, &bytes).map_err(|e| e.to_string());
                #[cfg(target_arch = "wasm32")]
                let written = super::platform::download(&path, &bytes, format.mime());
                match written {
                    Ok(()) => {
                        self.status.notice =
                            Some(format!("wrote {path} ({} bytes){notes}", bytes.len()))
                    }
                    Err(e) => self.status.error = Some(format!("could not write {path}: {e}")),
                }
            }
        }
    }

    /// Starts the page's export request `request` with `options` (JSON, read against the
    /// document as it is now).
    pub(super) fn export_for_page(&mut self, request: u32, options: &str) {
        let parsed = gltf::options_from_json(options, &self.doc.scene, curvature_ramp_rgb())
            .and_then(|o| Ok((o, GridBackend::from_json(options)?)));
        match parsed {
            Ok((options, backend)) => {
                self.start_export(options, backend, ExportTarget::Page(request))
            }
            Err(e) => crate::status::finish_export(request, Err(e)),
        }
    }

    /// Whether `backend` has an export's grids evaluated on the GPU here: where the viewport's
    /// device runs the compute shaders, asked for, or by default on a hardware adapter (on a
    /// software one the kernel's SIMD grids are faster than the emulated GPU).
    fn exports_on_gpu(&self, backend: GridBackend) -> bool {
        let wanted = match backend {
            GridBackend::Auto => !self.status.software_adapter,
            GridBackend::Gpu => true,
            GridBackend::Cpu => false,
        };
        wanted
            && self
                .gpu
                .as_ref()
                .is_some_and(|gpu| gpu.sync.evaluates_on_gpu())
    }

    /// The GPU's export grids on the viewport's device, made at the first export that uses
    /// them.
    fn gpu_export_grids(&mut self) -> Option<ExportGrids> {
        let gpu = self.gpu.as_mut()?;
        Some(
            gpu.export_grids
                .get_or_insert_with(|| {
                    ExportGrids::new(crate::gpu::export_grids::GpuGrids::new(
                        &gpu.device,
                        &gpu.queue,
                    ))
                })
                .clone(),
        )
    }

    /// Who evaluates an export's tessellation grids while the caller waits: on the desktop,
    /// the GPU's compute shaders where [`Self::exports_on_gpu`]; else the f64 kernel (always in
    /// the page, whose GPU cannot be read back within a frame: there the glTF export asks for
    /// its grids without waiting, [`Self::deferred_export_grids`]). The triangles are the
    /// kernel's either way.
    fn export_sampler(&mut self, backend: GridBackend) -> std::sync::Arc<dyn GridSampler + Send> {
        #[cfg(not(target_arch = "wasm32"))]
        if self.exports_on_gpu(backend)
            && let Some(grids) = self.gpu_export_grids()
        {
            return grids;
        }
        let _ = backend;
        std::sync::Arc::new(crate::kernel::tess::KernelGrids)
    }

    /// In the page, the GPU's grids for a glTF export that does not wait for them, where
    /// [`Self::exports_on_gpu`]: the export asks for an object's grids in one frame and writes
    /// the object when they are back, a frame or more later.
    fn deferred_export_grids(
        &mut self,
        backend: GridBackend,
    ) -> Option<std::rc::Rc<dyn crate::kernel::tess::DeferredGridSampler>> {
        #[cfg(target_arch = "wasm32")]
        if self.exports_on_gpu(backend) {
            return self
                .gpu_export_grids()
                .map(|grids| grids as std::rc::Rc<dyn crate::kernel::tess::DeferredGridSampler>);
        }
        let _ = backend;
        None
    }

    /// Starts an export of the document as it is now; refused (to its target) when one is
    /// running, when nothing is visible or when the estimate is over the limit.
    fn start_export(&mut self, options: ExportOptions, backend: GridBackend, target: ExportTarget) {
        if self.running_export.is_some() {
            self.deliver_export(target, Err(gltf::ExportError::Busy));
            return;
        }
        let project = Project {
            scene: self.doc.scene.clone(),
            view: Some(self.view),
        };
        let sampler = self.export_sampler(backend);
        let deferred = self.deferred_export_grids(backend);
        match gltf::ExportJob::new(project, options, crate::kernel::tess::MAX_TRIANGLES) {
            Ok(mut job) => {
                job.sample_grids_with(sampler);
                if let Some(deferred) = deferred {
                    job.sample_grids_deferred(deferred);
                }
                self.running_export = Some(RunningExport {
                    job,
                    target,
                    budget: FrameBudget::default(),
                })
            }
            Err(e) => self.deliver_export(target, Err(e)),
        }
    }

    /// Stops the running export; its target hears that it was cancelled.
    pub(super) fn cancel_export(&mut self) {
        if let Some(running) = self.running_export.take() {
            self.deliver_export(running.target, Err(gltf::ExportError::Cancelled));
        }
    }

    /// The running export's objects for as long as its [`FrameBudget`] gives (at least one)
    /// per frame, with its progress window; the result goes to its target when the last
    /// object is done.
    pub(super) fn step_export(&mut self, ctx: &egui::Context) {
        let Some(running) = &mut self.running_export else {
            self.status.export_progress = None;
            return;
        };
        let next = running.job.next_name().unwrap_or_default().to_owned();
        let progress = running.job.progress();
        self.status.export_progress = Some(progress);
        if progress_window(
            ctx,
            "Exporting glTF",
            progress,
            &format!("tessellating {next}"),
        ) {
            self.cancel_export();
            return;
        }
        // Objects until a frame's budget is spent (at least one), so that small exports end
        // in a frame or two and large ones leave the page responsive between steps; an object
        // waiting for its grids from the GPU ends the turn (they come back between frames).
        let job = &mut running.job;
        match running
            .budget
            .run(|| job.step().map(|done| done || job.is_waiting()))
        {
            Ok(true) if running.job.is_waiting() => ctx.request_repaint(),
            Ok(false) => ctx.request_repaint(),
            Ok(true) => {
                if let Some(running) = self.running_export.take() {
                    let result = running.job.finish();
                    self.deliver_export(running.target, result);
                }
                ctx.request_repaint();
            }
            Err(e) => {
                if let Some(running) = self.running_export.take() {
                    self.deliver_export(running.target, Err(e));
                }
            }
        }
    }

    /// Hands a finished export to its target: the page's request, a file (desktop) or a
    /// download (web), with what happened in the status.
    fn deliver_export(
        &mut self,
        target: ExportTarget,
        result: Result<gltf::Export, gltf::ExportError>,
    ) {
        let path = match target {
            ExportTarget::Page(request) => {
                let bytes = result.map(|e| gltf::to_glb(&e)).map_err(|e| e.to_string());
                crate::status::finish_export(request, bytes);
                return;
            }
            ExportTarget::File(path) => path,
        };
        let export = match result {
            Ok(export) => export,
            Err(e) => {
                if e != gltf::ExportError::Cancelled {
                    self.dialog = Some(super::Dialog::refused("Could not export", e.to_string()));
                }
                self.status.error = Some(format!("export: {e}"));
                return;
            }
        };
        let summary = format!("{} triangles", export.triangles);
        #[cfg(not(target_arch = "wasm32"))]
        {
            for (file, bytes) in gltf::files(&export, &path) {
                if let Err(e) = std::fs::write(&file, bytes) {
                    self.status.error = Some(format!("could not write {file}: {e}"));
                    return;
                }
            }
            self.status.notice = Some(format!("exported {summary} to {path}"));
        }
        #[cfg(target_arch = "wasm32")]
        {
            let bytes = gltf::to_glb(&export);
            match super::platform::download(&path, &bytes, "model/gltf-binary") {
                Ok(()) => self.status.notice = Some(format!("downloaded {path} ({summary})")),
                Err(e) => self.status.error = Some(format!("could not download: {e}")),
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_page_names_who_evaluates_the_grids_or_leaves_it_to_the_adapter() {
        for (options, backend) in [
            ("{}", GridBackend::Auto),
            (r#"{"backend": null, "tolerance": 0.1}"#, GridBackend::Auto),
            (r#"{"backend": "auto"}"#, GridBackend::Auto),
            (r#"{"backend": "gpu"}"#, GridBackend::Gpu),
            (r#"{"backend": "cpu", "curvature": true}"#, GridBackend::Cpu),
        ] {
            assert_eq!(GridBackend::from_json(options), Ok(backend), "{options}");
        }
        for (options, says) in [
            (
                r#"{"backend": "GPU"}"#,
                r#"backend must be auto, gpu or cpu, got "GPU""#,
            ),
            (
                r#"{"backend": 1}"#,
                "backend must be auto, gpu or cpu, got 1",
            ),
            ("{", "export options:"),
        ] {
            let e = GridBackend::from_json(options).expect_err(options);
            assert!(e.contains(says), "{options}: {e}");
        }
    }

    /// The turn is four times the rest of the frame, within 30 ms and 1 s, and at most twice
    /// the last: a first turn (nothing measured yet) and a fast frame get the least, a frame
    /// that drew for 20 ms 80 ms, and a software adapter's 4 s frames 30, 60, 120, … ms up to
    /// the most.
    #[test]
    fn a_turn_of_long_work_grows_with_the_time_the_rest_of_the_frame_takes() {
        let mut budget = FrameBudget::default();
        assert_eq!(budget.budget_ms(1000.0), 30.0);
        budget.last_end_ms = Some(1000.0);
        budget.last_budget_ms = 1000.0;
        assert_eq!(budget.budget_ms(1001.0), 30.0);
        assert_eq!(budget.budget_ms(1020.0), 80.0);
        assert_eq!(budget.budget_ms(1200.0), 800.0);
        assert_eq!(budget.budget_ms(5000.0), 1000.0);
        // A clock that steps back counts as no time.
        assert_eq!(budget.budget_ms(900.0), 30.0);
        // Slow frames from the start: the turns double up to the most.
        let mut slow = FrameBudget::default();
        let mut turns = Vec::new();
        let mut now = 0.0;
        for _ in 0..8 {
            let b = slow.budget_ms(now);
            turns.push(b);
            slow.last_budget_ms = b;
            now += b;
            slow.last_end_ms = Some(now);
            now += 4000.0;
        }
        assert_eq!(
            turns,
            [30.0, 60.0, 120.0, 240.0, 480.0, 960.0, 1000.0, 1000.0]
        );
    }
}
