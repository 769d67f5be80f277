//! The editor: an eframe app that is the same on the web and on the desktop. It owns the model,
//! runs the compute evaluation and the viewport render on eframe's wgpu device, and shows the
//! result as an egui image beside a control panel.

mod analysis;
mod command;
pub mod curves;
pub mod export;
mod features;
mod files;
mod gizmo;
mod input;
pub mod knife;
mod operations;
mod overlay;
pub mod panels;
pub(crate) mod platform;
mod surface_tools;
mod trim;
mod views;

pub use command::{AppCommand, CommandQueue, CommandSender, DragStep, channel};
pub use gizmo::{GizmoHandle, GizmoMode};
pub use views::StandardView;

pub use files::AUTOSAVE_KEY;
#[cfg(not(target_arch = "wasm32"))]
pub use files::{apply_to_file, open_path};
pub use overlay::{CONTROLS, NAVIGATION_HINT};
pub use panels::parse_knots;

use std::collections::BTreeSet;
use std::sync::Arc;

use eframe::egui;
use eframe::egui_wgpu;

use glam::DVec3;

use crate::doc::{Command, Document, EditError, PointsMoved, Touched};

use crate::gpu::timing::GpuTimer;
use crate::gpu::{self, GpuError, SceneSync, effective_segments};
use crate::render::{
    ControlNet, Quality, ViewTarget, ViewportRenderer, adaptive_target, scene_uniform,
};
use crate::scene::Scene;
use crate::status::{self, AppStatus};
use crate::view::{
    Constraint, PickView, QUALITY_RANGE, ShadingMode, SurfaceHit, TOLERANCE_RANGE, ViewSettings,
};

/// The per-object tessellation slider's range (segments per Bézier span edge).
pub const SLIDER_SEGMENTS: std::ops::RangeInclusive<u32> = 1..=128;
/// Control point dot radius in logical pixels.
const POINT_RADIUS: f32 = 3.5;
/// How near (logical pixels) a click must be to a control point to pick it.
pub const PICK_RADIUS: f64 = 8.0;

/// eframe's wgpu setup for knotwork: the device of [`gpu::device_descriptor`]; on the web,
/// WebGPU, else WebGL2 (the CPU evaluates the surfaces there: the panel says so).
pub fn wgpu_configuration(web: bool) -> egui_wgpu::WgpuConfiguration {
    let mut setup = egui_wgpu::WgpuSetupCreateNew::without_display_handle();
    if web {
        setup.instance_descriptor.backends = wgpu::Backends::BROWSER_WEBGPU | wgpu::Backends::GL;
    }
    setup.device_descriptor = Arc::new(gpu::device_descriptor);
    // Natively, the best adapter that has compute shaders; when none has, the first one, so
    // that the window opens and says what is missing instead of failing inside wgpu.
    #[cfg(not(target_arch = "wasm32"))]
    {
        setup.native_adapter_selector = Some(Arc::new(|adapters, surface| {
            let usable: Vec<wgpu::Adapter> = adapters
                .iter()
                .filter(|a| surface.is_none_or(|s| a.is_surface_supported(s)))
                .cloned()
                .collect();
            gpu::choose_adapter(&usable)
                .cloned()
                .or_else(|e| usable.first().cloned().ok_or_else(|| e.to_string()))
        }));
    }
    egui_wgpu::WgpuConfiguration {
        wgpu_setup: egui_wgpu::WgpuSetup::CreateNew(setup),
        ..Default::default()
    }
}

/// The status's and panel's name of the evaluator in use.
pub fn evaluator_label(compute: bool) -> &'static str {
    if compute {
        "GPU compute shaders"
    } else {
        "CPU (WebGL2: no compute shaders)"
    }
}

/// Everything that lives on the GPU for the viewport.
struct ViewportGpu {
    device: wgpu::Device,
    queue: wgpu::Queue,
    egui_renderer: Arc<egui::mutex::RwLock<egui_wgpu::Renderer>>,
    /// The GPU copy of the document: feeds, buffers, evaluator.
    sync: SceneSync,
    net: Option<ControlNet>,
    renderer: ViewportRenderer,
    /// The offscreen targets at rest and in motion ([`Quality::target`]), each with its egui
    /// texture; the motion one is unused where [`Quality`] keeps full quality in motion.
    targets: [Option<(ViewTarget, egui::TextureId)>; 2],
    /// Which of `targets` the last frame drew into (and the viewport shows).
    shown: usize,
    /// Samples and resolution at rest and in motion, from the adapter.
    quality: Quality,
    timer: Option<GpuTimer>,
    /// The export grids' evaluator on this device, made at the first export that uses it.
    export_grids: Option<export::ExportGrids>,
}

impl ViewportGpu {
    fn new(state: &egui_wgpu::RenderState) -> Self {
        let device = state.device.clone();
        Self {
            quality: Quality::for_adapter(&state.adapter.get_info()),
            targets: [None, None],
            shown: 0,
            sync: SceneSync::new(&device, &state.queue),
            renderer: ViewportRenderer::new(&device),
            timer: GpuTimer::new(&device, &state.queue),
            queue: state.queue.clone(),
            egui_renderer: Arc::clone(&state.renderer),
            device,
            net: None,
            export_grids: None,
        }
    }

    /// Makes the target for a viewport of `size` physical pixels, in motion or at rest
    /// ([`Quality::target`]), current; true when it was (re)created.
    fn ensure_target(&mut self, size: (u32, u32), moving: bool) -> bool {
        let wanted = self.quality.target(size, moving);
        let slot = usize::from(wanted != self.quality.target(size, false));
        let (samples, size) = wanted;
        self.shown = slot;
        if self.targets[slot]
            .as_ref()
            .is_some_and(|(t, _)| t.size() == size && t.samples() == samples)
        {
            return false;
        }
        let target = ViewTarget::with_samples(&self.device, size.0, size.1, samples);
        let mut egui_renderer = self.egui_renderer.write();
        let id = match self.targets[slot].take() {
            Some((_, id)) => {
                egui_renderer.update_egui_texture_from_wgpu_texture(
                    &self.device,
                    target.view(),
                    wgpu::FilterMode::Linear,
                    id,
                );
                id
            }
            None => egui_renderer.register_native_texture(
                &self.device,
                target.view(),
                wgpu::FilterMode::Linear,
            ),
        };
        self.targets[slot] = Some((target, id));
        true
    }

    /// The target the last frame drew into, and its egui texture.
    fn target(&self) -> Option<&(ViewTarget, egui::TextureId)> {
        self.targets[self.shown].as_ref()
    }

    /// Runs the compute pass if any patch needs it, then renders the viewport. Returns the
    /// number of patches evaluated.
    fn draw(
        &mut self,
        view: &ViewSettings,
        range: (f64, f64),
        selected: Option<u32>,
        point_radius_px: f32,
    ) -> Option<u32> {
        let (target, _) = self.targets[self.shown].as_ref()?;
        self.sync.surface_buffers()?;
        let mut encoder = self
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("knotwork frame"),
            });
        let mut evaluated = None;
        if self.sync.needs_evaluation() {
            let writes = self.timer.as_mut().and_then(GpuTimer::compute_pass_writes);
            evaluated = Some(self.sync.encode(&mut encoder, writes));
        }
        let surface = self.sync.surface_buffers()?;
        let scene = scene_uniform(view, target, point_radius_px, range, selected);
        let writes = self.timer.as_mut().and_then(GpuTimer::render_pass_writes);
        self.renderer.set_scene(&self.queue, &scene);
        self.renderer.render(
            &mut encoder,
            target,
            surface,
            self.net.as_ref(),
            view.overlays,
            writes,
        );
        if let Some(timer) = &mut self.timer {
            timer.resolve(&mut encoder);
        }
        self.queue.submit([encoder.finish()]);
        self.sync.after_submit();
        if let Some(timer) = &mut self.timer {
            timer.after_submit();
        }
        evaluated
    }
}

/// The sample scene, or an empty one (with the reason in the status) if it cannot be built.
fn default_scene(status: &mut AppStatus) -> Scene {
    Scene::demo().unwrap_or_else(|e| {
        status.error = Some(format!("the sample scene could not be built: {e}"));
        Scene::default()
    })
}

/// The viewport's side of a drag of control points (the document holds the transient edit
/// itself, [`crate::doc::PointDrag`]).
struct DragHandle {
    /// The grabbed point's start; the cursor's ray moves it under the constraint.
    anchor: DVec3,
    /// Mirror editing: the points that follow the dragged ones across the planes, and the
    /// distance within which a point counts as on a plane (or at an image).
    partners: Vec<crate::view::follow::Partner>,
    tolerance: f64,
    /// Proportional editing: the points that follow by a share of a dragged point's offset.
    falloff: Vec<crate::view::follow::Falloff>,
    /// The grabbed point and the cursor's last place (a drag is begun again there when the
    /// wheel changes the radius).
    index: usize,
    cursor: Option<egui::Pos2>,
}

/// What is selected: an object, its control points, the point the panel edits, a box
/// selection being drawn and the last surface point clicked.
#[derive(Default)]
struct Selection {
    object: Option<usize>,
    /// Selected control points of the selected object.
    points: BTreeSet<usize>,
    /// The control point the panel edits, in the selected object.
    edit_point: usize,
    /// Where a box selection started (logical pixels).
    box_start: Option<egui::Pos2>,
    /// The lasso being drawn (Ctrl + right drag), in logical pixels.
    lasso: Option<Vec<egui::Pos2>>,
    /// The last surface point clicked.
    hit: Option<SurfaceHit>,
    /// Curve objects picked for a construction, in the order they were picked.
    curves: Vec<usize>,
}

/// The document's revisions as the autosave and the page's `project()` see them, its name and
/// the Recent list.
#[derive(Default)]
struct Persistence {
    /// What the document was opened as when no New or Open is in the undo history ("sample
    /// scene", "autosaved project"); [`KnotworkApp::document_name`] is what it is now.
    base_name: String,
    /// The revision right after it was opened (`u64::MAX`: a restored autosave, which counts
    /// as changed).
    opened_revision: u64,
    /// Documents that New and Open replaced, newest first ([`files::RECENT_LIMIT`]).
    recent: Vec<files::RecentDocument>,
    /// The Recent list changed since it was last stored.
    recent_changed: bool,
    /// Counts document changes; the autosave writes when it moves.
    revision: u64,
    autosaved_revision: u64,
    last_change: f64,
    pending_revision: u64,
    /// The revision last published as project text (`window.knotwork.project()`, the page
    /// only).
    #[cfg_attr(not(target_arch = "wasm32"), allow(dead_code))]
    published_revision: Option<u64>,
    /// Whether the autosave writes at all (off with `--fresh`).
    autosave: bool,
}

/// A message in a window of its own until the user closes it.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Dialog {
    pub title: String,
    pub text: String,
    /// Whether it reports a refusal (the window then says the document is unchanged) rather
    /// than something done with warnings.
    pub refused: bool,
}

impl Dialog {
    /// A refusal: `title`, why, and that the document is unchanged.
    pub fn refused(title: impl Into<String>, text: impl Into<String>) -> Self {
        Self {
            title: title.into(),
            text: text.into(),
            refused: true,
        }
    }
}

pub struct KnotworkApp {
    doc: Document,
    selection: Selection,
    drag: Option<DragHandle>,
    /// Patch records (global indices) the drag has changed, drawn tinted.
    highlight_patches: Vec<usize>,
    constraint: Constraint,
    /// The trim loop being drawn on the surface, if a trim tool is active.
    trim_drawing: Option<trim::TrimDrawing>,
    /// The curve being drawn, and the curve tools' settings.
    curves: curves::CurveState,
    /// The surface tools' settings (offset, fillet).
    surface_tools: surface_tools::SurfaceToolState,
    /// Whether the Operations panel's operations keep their history.
    operations_keep_history: bool,
    /// The Cage tools' settings.
    cage_tools: panels::cage::CageToolSettings,
    /// Mirror editing across x = 0, y = 0, z = 0 while points are dragged.
    symmetry: [bool; 3],
    /// Shift + E on a cage: the sharpness of the selected edges set by the pointer's distance.
    crease_drag: Option<input::CreaseDrag>,
    /// K on a cage: the knife's line being drawn.
    knife: Option<knife::KnifeLine>,
    /// Proportional editing (O) and its radius (the wheel during a drag).
    proportional: bool,
    proportional_radius: f64,
    /// The Features row's size, the edges picked for it and its value being edited.
    features: features::FeatureState,
    /// The trim control point being dragged in the (u, v) panel.
    trim_handle: Option<trim::HandleDrag>,
    snap: bool,
    snap_step: f64,
    /// The Lattice panel's degrees for a new lattice, and its tolerance for a refit.
    lattice_degrees: [usize; 3],
    lattice_tolerance: f64,
    /// The other objects ticked to share the next lattice.
    lattice_also: std::collections::BTreeSet<usize>,
    /// Dragged points snap to other control points / to other surfaces under the cursor.
    snap_points: bool,
    snap_surface: bool,
    /// The camera and viewport of the last frame, for picking.
    pick_view: Option<PickView>,
    viewport_rect: egui::Rect,
    panel: panels::PanelState,
    export: export::ExportSettings,
    export_estimate: Option<export::ExportEstimate>,
    /// The export being built, a frame's budget of objects at a time.
    running_export: Option<export::RunningExport>,
    /// A STEP file being opened a body at a time ([`files::RunningOpen`]).
    running_open: Option<files::RunningOpen>,
    /// A boolean run a step at a time ([`operations::RunningBoolean`]).
    running_boolean: Option<operations::RunningBoolean>,
    /// Commands that came while a file was being opened, carried out after it, in order.
    deferred: std::collections::VecDeque<AppCommand>,
    /// The `?` overlay with the controls is shown.
    show_help: bool,
    /// The message the viewport's toast shows.
    toast: overlay::Toast,
    /// Revisions of the document: what the autosave and the page have seen of it.
    saved: Persistence,
    /// A modal message, e.g. a file that could not be opened.
    dialog: Option<Dialog>,
    /// The camera, shading, ramp range, overlays and quality (saved with the project).
    view: ViewSettings,
    /// The automatic range of the current curvature mode (`None`: to be computed).
    auto_range: Option<(f64, f64)>,
    continuous: bool,
    gpu: Option<ViewportGpu>,
    /// Why there is no GPU viewport (an adapter without compute shaders, say), shown in it.
    gpu_refusal: Option<String>,
    status: AppStatus,
    /// The viewport must be rendered this frame.
    redraw: bool,
    /// Frame the model once the viewport's aspect ratio is known.
    frame_pending: bool,
    /// Ask for another frame (a GPU timing readback is on its way).
    redraw_soon: bool,
    logged_status: bool,
    /// Close the window after this many viewport frames (desktop smoke tests).
    exit_after_frames: Option<u64>,
    /// The analysis overlays' caches.
    analysis: analysis::AnalysisState,
    /// A camera transition under way (standard views, framing).
    camera_move: Option<views::CameraMove>,
    /// What the transform gizmo does, and its drag under way.
    gizmo_mode: GizmoMode,
    gizmo_drag: Option<gizmo::GizmoDrag>,
    /// Requests from outside a frame (the page's script interface, tests, file tasks).
    commands: CommandQueue,
    sender: CommandSender,
}

impl KnotworkApp {
    /// `adapter_label` names the adapter where wgpu cannot (the browser reports no name).
    /// `restore`: open the autosaved project, if any (and keep autosaving).
    pub fn new(
        cc: &eframe::CreationContext<'_>,
        adapter_label: Option<String>,
        restore: bool,
    ) -> Self {
        let (sender, commands) = channel();
        commands.connect(&cc.egui_ctx);
        cc.egui_ctx.set_theme(egui::Theme::Dark);
        let mut status = AppStatus {
            quality: 1.0,
            ..Default::default()
        };
        let scene = default_scene(&mut status);
        let gpu = match &cc.wgpu_render_state {
            Some(state) => {
                let info = state.adapter.get_info();
                status.backend = gpu::backend_name(info.backend).to_owned();
                status.adapter = if info.name.is_empty() {
                    adapter_label
                        .filter(|label| !label.is_empty())
                        .unwrap_or_else(|| "(unnamed adapter)".to_owned())
                } else {
                    info.name.clone()
                };
                status.software_adapter = crate::render::is_software(&info);
                let limits = state.device.limits();
                status.buffer_limit_mib = (limits
                    .max_storage_buffer_binding_size
                    .min(limits.max_buffer_size)
                    >> 20)
                    .min(u64::from(u32::MAX)) as u32;
                // An adapter without compute shaders (WebGL2) gets the CPU evaluator and the
                // renderer that shades from the vertices alone.
                let gpu = ViewportGpu::new(state);
                status.evaluator = evaluator_label(gpu.sync.evaluates_on_gpu()).to_owned();
                if let Err(e) = gpu::context::check(&state.adapter) {
                    log::warn!("{e}; the CPU evaluates the surfaces");
                }
                Some(gpu)
            }
            None => {
                status.error = Some("eframe started without a wgpu device".to_owned());
                None
            }
        };
        let mut app = Self {
            doc: Document::new(scene),
            selection: Selection::default(),
            drag: None,
            highlight_patches: Vec::new(),
            constraint: Constraint::Free,
            trim_drawing: None,
            curves: curves::CurveState::default(),
            surface_tools: surface_tools::SurfaceToolState::default(),
            operations_keep_history: true,
            cage_tools: panels::cage::CageToolSettings::default(),
            symmetry: [false; 3],
            crease_drag: None,
            knife: None,
            proportional: false,
            proportional_radius: 1.0,
            features: features::FeatureState::default(),
            trim_handle: None,
            snap: false,
            snap_step: 0.25,
            lattice_degrees: [2, 2, 2],
            lattice_tolerance: 1e-3,
            lattice_also: Default::default(),
            snap_points: false,
            snap_surface: false,
            pick_view: None,
            viewport_rect: egui::Rect::NOTHING,
            panel: panels::PanelState::default(),
            export: export::ExportSettings::default(),
            export_estimate: None,
            running_export: None,
            running_open: None,
            running_boolean: None,
            deferred: std::collections::VecDeque::new(),
            show_help: false,
            toast: overlay::Toast::default(),
            saved: Persistence {
                autosave: restore,
                base_name: "sample scene".into(),
                ..Persistence::default()
            },
            dialog: None,
            auto_range: None,
            continuous: false,
            view: ViewSettings {
                // The view-adaptive tessellation runs in compute shaders.
                adaptive: gpu.as_ref().is_none_or(|g| g.sync.evaluates_on_gpu()),
                ..ViewSettings::default()
            },
            gpu,
            gpu_refusal: status.error.clone(),
            status,
            redraw: true,
            frame_pending: true,
            redraw_soon: false,
            logged_status: false,
            exit_after_frames: None,
            analysis: analysis::AnalysisState::default(),
            camera_move: None,
            gizmo_mode: GizmoMode::Move,
            gizmo_drag: None,
            commands,
            sender,
        };
        let restored = if restore {
            app.load_recent(cc.storage);
            app.restore_autosave(cc.storage)
        } else {
            None
        };
        if let Err(e) = app.rebuild_geometry(app.view.quality) {
            app.status.error = Some(e.to_string());
        }
        if let Some(notice) = restored {
            app.status.notice = Some(notice);
        }
        app.select(None);
        app.refresh_status();
        status::publish(&app.status);
        log::info!("knotwork starting: {}", app.status.to_json());
        app
    }

    /// Redraws continuously and closes the window once `frames` viewport frames are drawn
    /// (`knotwork --exit-after-frames N`); the final status stays in [`status::current`].
    pub fn exit_after_frames(mut self, frames: u64) -> Self {
        self.exit_after_frames = Some(frames);
        self.continuous = true;
        self
    }

    /// The camera, shading and overlays.
    pub fn view(&self) -> &ViewSettings {
        &self.view
    }

    /// The open document (scene and history).
    pub fn document(&self) -> &Document {
        &self.doc
    }

    fn scene(&self) -> &Scene {
        &self.doc.scene
    }

    /// Applies a command as one undo step and updates the GPU; a refused command (or one the
    /// GPU cannot show) leaves the document and its history as they were and shows why.
    fn execute(&mut self, command: Command) {
        // A drag in progress becomes its own undo step first.
        self.end_drag(false);
        let before = self.selected_net();
        let result = self
            .doc
            .execute(&command)
            .map(|edit| (edit.touched(), edit.label.clone()));
        match result {
            Ok((touched, label)) => {
                self.finish_edit(touched, &label);
                // A label with more than the command's (a construction's deviation, a surface
                // that could not follow its curves) is worth reading.
                if label != command.label() {
                    self.status.notice = Some(label);
                }
                self.follow_points(before);
            }
            Err(e) => self.status.error = Some(e.to_string()),
        }
    }

    /// The selected object's name and control points (what [`Self::follow_points`] needs).
    fn selected_net(&self) -> Option<(String, Vec<DVec3>)> {
        let object = self.doc.scene.objects.get(self.selection.object?)?;
        Some((object.name.clone(), object.control_points()))
    }

    /// After an edit that changed how many control points the selected object has (a knot
    /// inserted or removed, a degree raised), the edited and the selected points become the
    /// new points nearest to where they were, so that "point 15" never silently becomes
    /// another point; the notice says when a number changed. `before`: [`Self::selected_net`]
    /// before the edit.
    fn follow_points(&mut self, before: Option<(String, Vec<DVec3>)>) {
        let (Some((name, old)), Some(s)) = (before, self.selection.object) else {
            return;
        };
        let Some(object) = self.doc.scene.objects.get(s).filter(|o| o.name == name) else {
            return;
        };
        let new = object.control_points();
        if new.len() == old.len() || new.is_empty() {
            return;
        }
        let nearest = |k: usize| {
            let p = *old.get(k)?;
            (0..new.len()).min_by(|&a, &b| {
                new[a]
                    .distance_squared(p)
                    .total_cmp(&new[b].distance_squared(p))
            })
        };
        let edited = self.selection.edit_point;
        let followed = nearest(edited).unwrap_or(0);
        self.selection.edit_point = followed;
        self.selection.points = self
            .selection
            .points
            .iter()
            .filter_map(|&k| nearest(k))
            .collect();
        self.update_net();
        if followed != edited && self.status.error.is_none() {
            self.status.notice = Some(format!(
                "point {edited} is now point {followed}: the net has {} points (it had {})",
                new.len(),
                old.len()
            ));
        }
    }

    /// Puts one undisturbed lattice of `degrees` around `objects` (the box of them all; they
    /// share it), one undo step; their handles become the lattice's points.
    fn add_lattice(&mut self, objects: &[usize], degrees: [usize; 3]) {
        let mut bounds: Option<(DVec3, DVec3)> = None;
        for &object in objects {
            match self
                .scene()
                .objects
                .get(object)
                .and_then(|o| o.kind().bounds())
            {
                Some((lo, hi)) => {
                    bounds = Some(bounds.map_or((lo, hi), |(a, b)| (a.min(lo), b.max(hi))));
                }
                None => {
                    self.status.error = Some(format!("no object {object} to put a lattice around"));
                    return;
                }
            }
        }
        let Some((lo, hi)) = bounds else {
            self.status.error = Some("no objects to put a lattice around".into());
            return;
        };
        let group = self.scene().new_lattice_group();
        match crate::kernel::ffd::Lattice::around(lo, hi, degrees) {
            Ok(lattice) => {
                self.selection.points.clear();
                self.apply(AppCommand::Edit(Command::SetLattice {
                    objects: objects.to_vec(),
                    lattice: Some(lattice.with_group(group)),
                }));
            }
            Err(e) => self.status.error = Some(e.to_string()),
        }
    }

    /// Sets `lattice` (`None`: releases it) on object `object` and every object sharing its
    /// lattice, one undo step.
    fn set_linked_lattice(&mut self, object: usize, lattice: Option<crate::kernel::ffd::Lattice>) {
        let objects = self.scene().linked_lattices(object);
        self.selection.points.clear();
        self.apply(AppCommand::Edit(Command::SetLattice { objects, lattice }));
    }

    /// Bakes object `object`'s lattice into it; the notice says whether exactly or refitted.
    fn apply_lattice(&mut self, object: usize, tolerance: f64) {
        self.selection.points.clear();
        self.execute(Command::ApplyLattice { object, tolerance });
        if self.status.error.is_none() {
            self.status.notice = self.doc.history.undo_label().map(str::to_owned);
        }
    }

    /// Shows an edit that is applied and recorded; if the GPU cannot show it, the edit is
    /// undone and taken out of the history, and the error says so.
    fn finish_edit(&mut self, touched: Touched, label: &str) {
        match self.after_edit(touched) {
            Err(e) => self.take_back(touched, label, &e),
            Ok(()) => self.status.error = None,
        }
    }

    /// Undoes the newest step, which the GPU could not show, and forgets it.
    fn take_back(&mut self, touched: Touched, label: &str, error: &str) {
        if self.doc.undo().is_ok() {
            self.doc.history.drop_redo();
        }
        let _ = self.after_edit(touched);
        self.status.error = Some(format!("{label}: {error} (the edit was undone)"));
    }

    /// Undo (`redo` false) or redo one step.
    fn step_history(&mut self, redo: bool) {
        self.end_drag(false);
        let before = self.selected_net();
        let result = if redo {
            self.doc.redo()
        } else {
            self.doc.undo()
        };
        match result.map(|edit| (edit.touched(), edit.document.is_some())) {
            Ok((touched, document)) => {
                let result = self.after_edit(touched);
                if document {
                    // New or Open undone or redone: another document, whose name follows the
                    // history. Redone, it is as it was opened; undone, the document before
                    // counts as changed for the Recent list. The Export window's tolerance
                    // follows its size.
                    self.saved.opened_revision = if redo { self.saved.revision } else { u64::MAX };
                    self.export.tolerance = 0.0;
                }
                if let Err(e) = result {
                    self.status.error = Some(e);
                } else {
                    self.status.error = None;
                    self.follow_points(before);
                }
            }
            Err(EditError::NothingTo(_)) => {}
            Err(e) => self.status.error = Some(e.to_string()),
        }
    }

    /// Brings the GPU and the selection up to date with the document after an edit.
    fn after_edit(&mut self, touched: Touched) -> Result<(), String> {
        self.saved.revision += 1;
        self.auto_range = None;
        self.redraw = true;
        if touched.is_structure()
            && self
                .selection
                .object
                .is_some_and(|s| s >= self.doc.scene.objects.len())
        {
            self.selection.object = None;
        }
        if let Some(gpu) = &mut self.gpu {
            let notice = gpu
                .sync
                .apply(&self.doc.scene, touched, self.view.quality)
                .map_err(|e| e.to_string())?;
            self.status.points_uploaded = gpu.sync.points_uploaded() as u32;
            if touched.is_structure() {
                self.status.notice = notice;
            }
        }
        if touched.is_structure() {
            let objects = &self.doc.scene.objects;
            self.selection.curves.retain(|&k| {
                objects
                    .get(k)
                    .is_some_and(|o| o.kind().space_curve().is_some())
            });
        }
        match touched {
            Touched::Structure | Touched::Object(_) | Touched::InsertedOrRemoved(_) => {
                self.select_keep_points(self.selection.object)
            }
            Touched::Points(_) => self.update_net(),
            Touched::Nothing => {}
        }
        Ok(())
    }

    /// Shows points the document moved (a drag step, the panel, the page's API): only their
    /// support is re-derived, uploaded and re-evaluated, and those patches are drawn tinted
    /// while a drag lasts.
    fn show_moved(&mut self, moved: &PointsMoved) -> Result<(), String> {
        self.status.patches_in_drag = moved.patches.len() as u32;
        self.redraw = true;
        let Some(gpu) = &mut self.gpu else {
            return Ok(());
        };
        if let Some(first) = gpu.sync.first_patch(moved.object) {
            self.highlight_patches = moved.patches.iter().map(|p| first + p).collect();
        }
        let uploaded = gpu
            .sync
            .points_moved(&self.doc.scene, moved)
            .map_err(|e| e.to_string())?;
        self.status.points_uploaded = uploaded as u32;
        // The automatic colour range is resampled when the edit ends, not on every step.
        self.update_net();
        Ok(())
    }

    /// Rewrites the control net's points and highlight.
    fn update_net(&mut self) {
        let (Some(gpu), Some(s)) = (&self.gpu, self.selection.object) else {
            return;
        };
        if let (Some(net), Some(object)) = (&gpu.net, self.doc.scene.objects.get(s)) {
            let points = &self.selection.points;
            net.update_points(&gpu.queue, &object.control_points(), &|k| {
                points.contains(&k)
            });
        }
        self.redraw = true;
    }

    /// Uploads every object at `quality`; where the device's buffer or dispatch limits refuse
    /// that, the sync layer lowers the quality until they accept it and the status says so. On
    /// any other failure the current geometry stays and the error is returned.
    fn rebuild_geometry(&mut self, quality: f32) -> Result<(), GpuError> {
        let Some(gpu) = &mut self.gpu else {
            return Ok(());
        };
        self.status.notice = gpu.sync.rebuild(&self.doc.scene, quality)?;
        self.redraw = true;
        Ok(())
    }

    /// Sets every object's segments per span as one undo step; a level outside 1..=1024 is
    /// refused and nothing changes.
    fn set_all_segments(&mut self, segments: u32) {
        if self
            .doc
            .scene
            .objects
            .iter()
            .all(|o| o.segments == segments)
        {
            return;
        }
        self.apply(AppCommand::Edit(Command::SetAllSegments { segments }));
    }

    /// Switches between the view-adaptive tessellation (`tolerance_px` of error on screen) and
    /// the fixed one; a tolerance outside the range is refused and nothing changes.
    fn set_tessellation(&mut self, adaptive: bool, tolerance_px: f32) {
        if !(tolerance_px.is_finite() && TOLERANCE_RANGE.contains(&tolerance_px)) {
            self.status.error = Some(format!(
                "tolerance {tolerance_px} px is outside {}..={}",
                TOLERANCE_RANGE.start(),
                TOLERANCE_RANGE.end()
            ));
            return;
        }
        if (adaptive, tolerance_px) == (self.view.adaptive, self.view.tolerance_px) {
            return;
        }
        let before = (self.view.adaptive, self.view.tolerance_px);
        self.view.adaptive = adaptive;
        self.view.tolerance_px = tolerance_px;
        if let Some(gpu) = &mut self.gpu {
            match gpu
                .sync
                .set_adaptive(&self.doc.scene, adaptive, self.view.quality)
            {
                Ok(notice) => self.status.notice = notice.or(self.status.notice.take()),
                Err(e) => {
                    (self.view.adaptive, self.view.tolerance_px) = before;
                    self.status.error = Some(e.to_string());
                    return;
                }
            }
        }
        self.status.error = None;
        self.saved.revision += 1;
        self.redraw = true;
    }

    fn set_quality(&mut self, quality: f32) {
        if !(quality.is_finite() && QUALITY_RANGE.contains(&quality)) {
            self.status.error = Some(format!(
                "quality {quality} is outside {}..={}",
                QUALITY_RANGE.start(),
                QUALITY_RANGE.end()
            ));
            return;
        }
        // The quality is a view setting (saved with the view), not an undo step.
        let saved = self.view.quality;
        self.view.quality = quality;
        match self.rebuild_geometry(quality) {
            Ok(()) => {
                self.status.error = None;
                self.saved.revision += 1;
            }
            Err(e) => {
                self.view.quality = saved;
                self.status.error = Some(e.to_string());
            }
        }
        self.redraw = true;
    }

    /// Selects an object (or none) and clears the point selection.
    fn select(&mut self, selected: Option<usize>) {
        self.selection.points.clear();
        self.selection.edit_point = 0;
        self.select_keep_points(selected);
    }

    /// Selects an object, keeping those selected points that still exist, and builds its net.
    fn select_keep_points(&mut self, selected: Option<usize>) {
        let selected = selected.filter(|&s| s < self.doc.scene.objects.len());
        if selected != self.selection.object {
            self.selection.points.clear();
        }
        self.selection.object = selected;
        let count = selected.map_or(0, |s| self.doc.scene.objects[s].control_point_count());
        self.selection.points.retain(|&k| k < count);
        if let Some(gpu) = &mut self.gpu {
            let points = &self.selection.points;
            gpu.net = selected
                .filter(|&s| self.doc.scene.objects[s].visible)
                .map(|s| {
                    let object = &self.doc.scene.objects[s];
                    ControlNet::new(
                        &gpu.device,
                        &object.control_points(),
                        &|k| points.contains(&k),
                        &object.net_lines(),
                    )
                });
        }
        self.panel
            .sync(self.doc.scene.objects.get(selected.unwrap_or(usize::MAX)));
        self.redraw = true;
    }

    /// Moves control points as one undo step along the drag's incremental path (the panel's
    /// numeric entry, the page's `moveControlPoint`). If the GPU cannot show the result, the
    /// move is undone and taken out of the history.
    fn move_points(&mut self, object: usize, moves: &[(usize, DVec3)]) {
        self.end_drag(false);
        match self.doc.move_points(object, moves) {
            Ok(moved) => {
                let shown = if moved.relaid {
                    self.after_edit(Touched::Structure)
                } else {
                    self.show_moved(&moved)
                };
                self.highlight_patches.clear();
                match shown {
                    Ok(()) => {
                        self.saved.revision += 1;
                        self.auto_range = None;
                        self.status.error = None;
                    }
                    Err(e) => self.take_back(Touched::Points(object), "move", &e),
                }
            }
            Err(e) => self.status.error = Some(e.to_string()),
        }
    }

    fn set_shading(&mut self, mode: ShadingMode) {
        if mode != self.view.shading {
            // A hand-set range is in the old mode's units (curvature or degrees).
            let degrees = |m: ShadingMode| m == ShadingMode::Isophotes;
            if degrees(mode) != degrees(self.view.shading) {
                self.view.range = None;
            }
            self.view.shading = mode;
            self.auto_range = None;
            self.redraw = true;
        }
    }

    /// The colour ramp's range in the current mode: the manual one, or the robust automatic one
    /// (area-weighted 2–98 % percentiles) over the f64 kernel's curvature samples of every
    /// object.
    pub(super) fn color_range(&mut self) -> Option<(f64, f64)> {
        if self.view.shading == ShadingMode::Isophotes {
            // The angle between the normal and the light, in degrees.
            return Some(self.view.range.unwrap_or((0.0, 180.0)));
        }
        let component = self.view.shading.curvature_component()?;
        if let Some(range) = self.view.range {
            return Some(range);
        }
        if self.auto_range.is_none() {
            self.auto_range = self.doc.scene.curvature_range(component);
        }
        self.auto_range
    }

    /// Whether the view or the model is moving under the user's hand this frame: a drag of
    /// points, the gizmo or a trim handle, an orbit or pan (a button held after pressing in the
    /// viewport), a wheel zoom, or a camera transition. Such frames may be drawn at the lower
    /// quality of [`Quality`].
    fn in_motion(&self, ctx: &egui::Context) -> bool {
        let rect = self.viewport_rect;
        let (held_in_viewport, scrolling) = ctx.input(|i| {
            (
                i.pointer.any_down() && i.pointer.press_origin().is_some_and(|p| rect.contains(p)),
                i.smooth_scroll_delta != egui::Vec2::ZERO || i.zoom_delta() != 1.0,
            )
        });
        self.drag.is_some()
            || self.gizmo_drag.is_some()
            || self.trim_handle.is_some()
            || self.camera_move.is_some()
            || held_in_viewport
            || (scrolling && ctx.pointer_hover_pos().is_some_and(|p| rect.contains(p)))
    }

    fn refresh_status(&mut self) {
        self.status.objects = self.scene().objects.len() as u32;
        self.status.selected_points = self.selection.points.iter().map(|&k| k as u32).collect();
        self.status.undo_steps = self.doc.history.undo_depth() as u32;
        self.status.redo_steps = self.doc.history.redo_depth() as u32;
        self.status.last_edit = self.doc.history.undo_label().map(str::to_owned);
        self.status.dragging = self.doc.drag().is_some();
        self.status.constraint = match &self.gizmo_drag {
            Some(gizmo) => gizmo.handle().label(),
            None => self.constraint.label(),
        };
        self.status.revision = self.saved.revision;
        self.status.recent = self.saved.recent.iter().map(|r| r.label()).collect();
        self.status.autosaved_revision = self.saved.autosaved_revision;
        self.status.drawing = self.curves.drawing.as_ref().map(|d| d.points.len() as u32);
        self.status.picked_curves = self.selection.curves.iter().map(|&k| k as u32).collect();
        if let Some(curves) = self.gpu.as_ref().and_then(|g| g.sync.curves()) {
            self.status.curve_segments = curves.records().len() as u32;
            self.status.curve_vertices = curves.vertex_count();
        }
        self.status.hit = self.selection.hit.map(|h| status::HitStatus {
            object: h.object as u32,
            u: h.u,
            v: h.v,
            point: h.point.to_array(),
        });
        self.status.quality = self.view.quality;
        self.status.tessellation = if self.view.adaptive {
            "adaptive"
        } else {
            "fixed"
        }
        .to_owned();
        self.status.tolerance_px = self.view.tolerance_px;
        if !self.view.adaptive {
            self.status.visible_patches = None;
            self.status.adaptive_coarsening = None;
        }
        self.status.selected = self.selection.object.map(|s| s as u32);
        self.status.shading = self.view.shading.name().to_owned();
        self.status.view = StandardView::of(&self.view.camera)
            .map_or("custom", StandardView::name)
            .to_owned();
        self.status.orthographic = self.view.camera.orthographic;
        self.status.gizmo = self.gizmo_mode.name().to_owned();
        self.status.grid_step = self.view.overlays.grid.then_some(self.analysis.grid_step);
        self.status.continuity = self
            .view
            .analysis
            .continuity
            .then(|| self.continuity_summary());
        self.status.range_auto = self.view.range.is_none();
        self.status.range = self.color_range().map(|(lo, hi)| [lo, hi]);
        let quality_used = self
            .gpu
            .as_ref()
            .map_or(self.view.quality, |g| g.sync.quality_used());
        self.status.segments = self
            .scene()
            .objects
            .iter()
            .map(|o| effective_segments(o.segments, quality_used))
            .collect();
        if let Some(counts) = self.gpu.as_ref().and_then(|g| g.sync.counts()) {
            self.status.patches = counts.patches;
            self.status.control_points = counts.control_points;
            self.status.vertices = counts.vertices;
            self.status.triangles = counts.indices / 3;
        }
    }

    /// Sets one crease of a subdivision surface (one undo step; refused with a message for
    /// another kind of object, an edge the cage lacks or a bad sharpness).
    /// The settings of subdivision surface `object`; `None`, with the error in the status, for
    /// any other object.
    fn subdivision_settings(&mut self, object: usize) -> Option<crate::scene::SubdivSettings> {
        let surface = self
            .doc
            .scene
            .objects
            .get(object)
            .and_then(|o| o.geometry.as_subdivision());
        if surface.is_none() {
            self.status.error = Some(format!("object {object} is not a subdivision surface"));
        }
        surface.map(crate::scene::SubdivObject::settings)
    }

    fn set_crease(&mut self, object: usize, a: u32, b: u32, sharpness: f64) {
        let Some(mut settings) = self.subdivision_settings(object) else {
            return;
        };
        settings
            .creases
            .retain(|c| (c.a, c.b) != (a, b) && (c.a, c.b) != (b, a));
        if sharpness != 0.0 {
            settings
                .creases
                .push(crate::kernel::subdiv::Crease { a, b, sharpness });
        }
        self.apply(AppCommand::Edit(Command::SetSubdivision {
            object,
            settings,
        }));
    }

    /// Shows subdivision surface `object` as `display` (and with flatness tolerance
    /// `tolerance`, where given), as one undo step; a display the scheme lacks is refused.
    fn set_subdivision_display(
        &mut self,
        object: usize,
        display: crate::kernel::subdiv::patches::Display,
        tolerance: Option<f64>,
    ) {
        let Some(mut settings) = self.subdivision_settings(object) else {
            return;
        };
        settings.display = display;
        if let Some(t) = tolerance {
            settings.tolerance = t;
        }
        self.apply(AppCommand::Edit(Command::SetSubdivision {
            object,
            settings,
        }));
    }

    fn set_manual_range(&mut self, range: Option<(f64, f64)>) {
        match range {
            Some((lo, hi)) if !(lo.is_finite() && hi.is_finite() && lo < hi) => {
                self.status.error = Some(format!(
                    "a colour range needs finite low < high, got ({lo}, {hi})"
                ));
            }
            _ => self.view.range = range,
        }
        self.redraw = true;
    }

    fn frame_model(&mut self, aspect: f32) {
        if let Some((lo, hi)) = self.scene().bounds() {
            self.view.camera.frame(lo.as_vec3(), hi.as_vec3(), aspect);
        }
        self.redraw = true;
    }

    fn viewport(&mut self, ui: &mut egui::Ui) {
        let rect = ui.available_rect_before_wrap();
        let response = ui.allocate_rect(rect, egui::Sense::click_and_drag());
        let ppp = ui.ctx().pixels_per_point();
        let size = (
            (rect.width() * ppp).round().max(1.0) as u32,
            (rect.height() * ppp).round().max(1.0) as u32,
        );
        let aspect = rect.width() / rect.height().max(1.0);
        self.viewport_rect = rect;
        self.pick_view = Some(PickView::new(
            self.view.camera.view_projection(aspect),
            rect.width(),
            rect.height(),
        ));
        self.handle_input(ui, &response);
        if std::mem::take(&mut self.frame_pending) {
            self.frame_model(aspect);
        }
        self.pick_view = Some(PickView::new(
            self.view.camera.view_projection(aspect),
            rect.width(),
            rect.height(),
        ));
        status::publish_handles(
            self.projected_handles()
                .iter()
                .map(|p| {
                    p.map(|p| {
                        [
                            p.screen.x as f32 + rect.left(),
                            p.screen.y as f32 + rect.top(),
                        ]
                    })
                })
                .collect(),
        );
        let range = self.color_range().unwrap_or((-1.0, 1.0));
        let selected = self.selection.object.map(|s| s as u32);
        if self.gpu.as_ref().is_none_or(|g| !g.sync.is_built()) {
            let reason = self
                .gpu_refusal
                .as_deref()
                .unwrap_or("see the panel for the reason");
            ui.put(
                rect.shrink(40.0),
                egui::Label::new(
                    egui::RichText::new(format!("The GPU viewport is unavailable: {reason}"))
                        .size(16.0),
                )
                .wrap(),
            );
            // A frame was shown (the message), so --exit-after-frames still ends.
            self.status.frames += 1;
            return;
        }
        if self.upload_guide_lines() {
            self.redraw = true;
        }
        let moving = self.in_motion(ui.ctx());
        let Some(gpu) = self.gpu.as_mut() else {
            return;
        };
        // The last frame in motion was drawn at the lower quality: draw the view at rest.
        let settled = !moving && gpu.shown != 0;
        let resized = gpu.ensure_target(size, moving);
        let point_scale = gpu
            .target()
            .map_or(1.0, |(t, _)| t.size().0 as f32 / size.0.max(1) as f32);
        gpu.renderer
            .set_highlight(&gpu.device, &gpu.queue, &self.highlight_patches);
        let colors: Vec<Option<[f32; 3]>> =
            self.doc.scene.objects.iter().map(|o| o.color).collect();
        gpu.renderer
            .set_object_colors(&gpu.device, &gpu.queue, &colors);
        if !gpu.sync.evaluates_on_gpu() {
            // A project or the autosave asked for the view-adaptive tessellation, which runs in
            // compute shaders: this device has none.
            self.view.adaptive = false;
        }
        if gpu.sync.is_adaptive() != self.view.adaptive {
            // A project or the autosave brought another mode.
            if let Err(e) =
                gpu.sync
                    .set_adaptive(&self.doc.scene, self.view.adaptive, self.view.quality)
            {
                // Keep the mode the GPU copy has, rather than rebuild again every frame.
                self.view.adaptive = gpu.sync.is_adaptive();
                self.status.error = Some(e.to_string());
            }
        }
        // While points are dragged the adaptive levels stay as measured: each step re-evaluates
        // only the patches it changes; the frame after the drag measures everything again.
        gpu.sync.freeze_levels(self.doc.drag().is_some());
        // Only the curvature modes read the vertices' curvature (as the fallback of their own
        // per-pixel evaluation); other modes spare the compute pass that work.
        gpu.sync
            .set_vertex_curvature(self.view.shading.curvature_component().is_some());
        if gpu.sync.is_adaptive()
            && let Some(size) = gpu.target().map(|(t, _)| t.size())
        {
            let target =
                adaptive_target(&self.view.camera, size, f64::from(self.view.tolerance_px));
            gpu.sync.set_view(target);
        }
        let pending = gpu.sync.needs_evaluation();
        if resized || settled || self.redraw || self.continuous || pending {
            let radius = POINT_RADIUS * ppp * point_scale;
            if let Some(evaluated) = gpu.draw(&self.view, range, selected, radius) {
                self.status.patches_reevaluated = evaluated;
            }
            self.status.frames += 1;
            self.redraw = false;
        }
        if gpu.shown != 0 && !ui.ctx().input(|i| i.pointer.any_down()) {
            // A wheel zoom ends without an event of its own: come back to draw the view at rest.
            // (Drags end with the button's release; no frames are asked for while one is held,
            // which would only queue more GPU work behind the frame the user waits for.)
            ui.ctx()
                .request_repaint_after(std::time::Duration::from_millis(120));
        }
        self.status.frame_samples = gpu.target().map_or(0, |(t, _)| t.samples());
        self.status.frame_size = gpu.target().map(|(t, _)| t.size().into());
        if let Some(&(_, texture)) = gpu.target() {
            let uv = egui::Rect::from_min_max(egui::pos2(0.0, 0.0), egui::pos2(1.0, 1.0));
            ui.painter().image(texture, rect, uv, egui::Color32::WHITE);
        }
        self.paint_box(ui);
        self.paint_knife(ui);
        self.paint_trims(ui);
        self.paint_drawing(ui);
        self.paint_feature_edges(ui);
        self.feature_handle(ui);
        self.paint_gizmo(ui);
        self.axis_triad(ui);
        self.viewport_overlays(ui, rect);
        if let Some(drag) = self.doc.drag() {
            // A gizmo drag says which part moves the points; a handle drag its constraint.
            let how = match &self.gizmo_drag {
                Some(gizmo) => gizmo.handle().label(),
                None => format!(
                    "{} · X/Y/Z axis, Shift+X/Y/Z plane",
                    self.constraint.label()
                ),
            };
            ui.painter().text(
                rect.left_bottom() + egui::vec2(10.0, -10.0),
                egui::Align2::LEFT_BOTTOM,
                format!(
                    "moving {} point(s) · {how} · Esc cancels",
                    drag.starts().len()
                ),
                egui::FontId::proportional(14.0),
                egui::Color32::from_rgb(255, 200, 120),
            );
        }
    }

    fn collect_timings(&mut self) {
        let Some(gpu) = &mut self.gpu else {
            return;
        };
        #[cfg(not(target_arch = "wasm32"))]
        {
            // Drives buffer-mapping callbacks on native; the browser does this by itself.
            let _ = gpu.device.poll(wgpu::PollType::Poll);
        }
        if let Some(stats) = gpu.sync.adaptive_stats() {
            self.status.visible_patches = Some(stats.visible_patches);
            self.status.adaptive_coarsening = Some(stats.shift);
        }
        match gpu
            .sync
            .grow_adaptive_room(&self.doc.scene, self.view.quality)
        {
            Ok(true) => self.redraw = true,
            Ok(false) => {}
            Err(e) => self.status.error = Some(e.to_string()),
        }
        if let Some(timer) = &mut gpu.timer {
            if timer.collect() {
                self.status.gpu_eval_ms = timer.latest.eval_ms;
                self.status.gpu_render_ms = timer.latest.render_ms;
            }
            if timer.pending() {
                // Keep frames coming until the figures arrive.
                self.redraw_soon = true;
            }
        }
    }
}

impl eframe::App for KnotworkApp {
    /// eframe's save hook: on exit (and every half minute) the autosave is written at once.
    fn save(&mut self, storage: &mut dyn eframe::Storage) {
        self.write_autosave(storage);
    }

    fn ui(&mut self, ui: &mut egui::Ui, frame: &mut eframe::Frame) {
        // Commands wait while a file is being opened or a boolean runs (but for Cancel), so
        // that each is carried out on the document every command before it left.
        self.deferred.extend(self.commands.drain());
        while (self.running_open.is_none() && self.running_boolean.is_none())
            || matches!(
                self.deferred.front(),
                Some(AppCommand::CancelOpen | AppCommand::CancelBoolean)
            )
        {
            let Some(command) = self.deferred.pop_front() else {
                break;
            };
            self.apply(command);
        }
        // A Cancel waiting behind other commands stops the work they wait for.
        while let Some(k) = self
            .deferred
            .iter()
            .position(|c| matches!(c, AppCommand::CancelOpen | AppCommand::CancelBoolean))
        {
            match self.deferred.remove(k) {
                Some(AppCommand::CancelOpen) => self.cancel_open(),
                _ => self.cancel_boolean(),
            }
        }
        let ctx = ui.ctx().clone();
        self.take_dropped(&ctx);
        self.trim_keys(&ctx);
        self.handle_shortcuts(&ctx);
        self.view_shortcuts(&ctx);
        self.gizmo_keys(&ctx);
        self.step_camera_move(&ctx);
        self.collect_timings();
        egui::Panel::left("controls")
            .resizable(true)
            .default_size(250.0)
            .show(ui, |ui| {
                egui::ScrollArea::vertical().show(ui, |ui| self.controls(ui));
            });
        egui::CentralPanel::default()
            .frame(egui::Frame::NONE)
            .show(ui, |ui| self.viewport(ui));

        self.create_window(&ctx);
        self.export_window(&ctx);
        self.step_export(&ctx);
        self.step_open(&ctx);
        self.step_boolean(&ctx);
        self.dialog_window(&ctx);
        self.history_prompt(&ctx);
        self.autosave(&ctx, frame);
        // The page's script reads the document as project text; the desktop has no reader,
        // so it serialises only to autosave.
        #[cfg(target_arch = "wasm32")]
        if self.saved.published_revision != Some(self.saved.revision) && self.drag.is_none() {
            status::publish_project(self.doc.save(None));
            self.saved.published_revision = Some(self.saved.revision);
        }
        let dt = ui.input(|i| i.unstable_dt);
        if self.continuous {
            self.status.frame_interval_ms = Some(f64::from(dt) * 1e3);
            ui.ctx().request_repaint();
        }
        if self.redraw || std::mem::take(&mut self.redraw_soon) {
            ui.ctx().request_repaint();
        }
        self.refresh_status();
        status::publish(&self.status);
        if !self.logged_status && self.status.frames > 0 {
            log::info!("knotwork status: {}", self.status.to_json());
            self.logged_status = true;
        }
        if self
            .exit_after_frames
            .is_some_and(|frames| self.status.frames >= frames)
            && (!self.saved.autosave || self.saved.autosaved_revision == self.saved.revision)
        {
            ui.ctx().send_viewport_cmd(egui::ViewportCommand::Close);
        }
    }
}
