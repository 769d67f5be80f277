//! The editor's state as the outside sees it — `window.knotwork.status()` in the page, a log line
//! on the desktop. Requests go the other way as [`crate::app::AppCommand`]s.

use std::sync::Mutex;

use serde::Serialize;

/// The continuity overlay's summary.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct ContinuityStatus {
    pub edges: u32,
    /// Edges whose verdict meets the target.
    pub passing: u32,
    /// The verdict of every edge, in the table's order.
    pub verdicts: Vec<String>,
}

/// A snapshot of what the editor shows. Serialized as JSON for scripts and tests.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct AppStatus {
    /// "webgpu", "vulkan", "metal", "dx12", "webgl2/gl"; empty before the GPU is up.
    pub backend: String,
    /// Adapter name, e.g. "llvmpipe (LLVM 15.0.6, 256 bits)" or "google · swiftshader".
    pub adapter: String,
    /// What evaluates the surfaces: "GPU compute shaders", or the CPU where the device has no
    /// compute shaders (WebGL2) ([`crate::app::evaluator_label`]).
    pub evaluator: String,
    /// Objects in the scene.
    pub objects: u32,
    /// Bézier patches evaluated on the GPU (every object's decomposition).
    pub patches: u32,
    /// Points in the GPU's control point pool (the Bézier points).
    pub control_points: u32,
    /// Segments per Bézier span edge of each object, after the quality factor (and any
    /// lowering to fit the device).
    pub segments: Vec<u32>,
    /// The global tessellation quality factor.
    pub quality: f32,
    /// "adaptive" (levels per patch edge from the view) or "fixed" (each object's segments).
    pub tessellation: String,
    /// The adaptive tessellation's tolerated error in pixels.
    pub tolerance_px: f32,
    /// The adaptive tessellation's last figures: patches inside the view, and how many times
    /// every level was halved to fit the buffers (0 normally; the buffers then grow).
    pub visible_patches: Option<u32>,
    pub adaptive_coarsening: Option<u32>,
    /// Patches re-evaluated by the last compute pass (all of them after a tessellation change,
    /// the edited point's support after an edit).
    pub patches_reevaluated: u32,
    /// Bézier control points uploaded by the last edit.
    pub points_uploaded: u32,
    /// The selected object, if any.
    pub selected: Option<u32>,
    /// The shading mode's name ("plain", "normals", "checker", "gaussian", "mean", "k1", "k2").
    pub shading: String,
    /// The standard view the camera is in ("top", "front", ...; "custom" otherwise).
    pub view: String,
    /// Whether the projection is orthographic.
    pub orthographic: bool,
    /// The transform gizmo's mode ("off", "move", "rotate", "scale").
    pub gizmo: String,
    /// What the last dragged point snapped to ("point", "surface", "grid"), if anything.
    pub snapped: Option<String>,
    /// The last gizmo rotation (degrees) or scale factor.
    pub gizmo_amount: Option<f64>,
    /// The ground grid's minor step in model units (None: grid hidden).
    pub grid_step: Option<f64>,
    /// Shared edges and how many meet the continuity target, while continuity is shown.
    pub continuity: Option<ContinuityStatus>,
    /// The colour ramp's (low, high) in a curvature mode.
    pub range: Option<[f64; 2]>,
    /// Whether that range is automatic (robust percentiles) or set by hand.
    pub range_auto: bool,
    /// Vertices the compute pass writes.
    pub vertices: u32,
    pub triangles: u32,
    /// Viewport frames rendered so far.
    pub frames: u64,
    /// Compute pass duration on the GPU (timestamp queries), when the device has them.
    pub gpu_eval_ms: Option<f64>,
    /// Render pass duration on the GPU (timestamp queries), when the device has them.
    pub gpu_render_ms: Option<f64>,
    /// Samples per pixel and size (physical pixels) of the last viewport frame: lower while
    /// the view or the model moves on a software adapter.
    pub frame_samples: u32,
    pub frame_size: Option<[u32; 2]>,
    /// Whether the adapter is a software rasterizer, which draws at a lower quality in motion.
    pub software_adapter: bool,
    /// The largest storage buffer the device binds, in MiB: WebGPU's default 128 on a software
    /// adapter, what a hardware GPU offers up to 1024 ([`crate::gpu::context::limits_for`]).
    pub buffer_limit_mib: u32,
    /// Time between the last two frames, measured on the CPU.
    pub frame_interval_ms: Option<f64>,
    /// Selected control points of the selected object.
    pub selected_points: Vec<u32>,
    /// Steps that can be undone and redone.
    pub undo_steps: u32,
    pub redo_steps: u32,
    /// The label of the newest undo step.
    pub last_edit: Option<String>,
    /// A drag of control points is in progress.
    pub dragging: bool,
    /// Bézier patches re-evaluated by the last drag step.
    pub patches_in_drag: u32,
    /// The drag constraint ("view plane", "X axis", "plane normal to Z").
    pub constraint: String,
    /// Document changes so far, and the change the autosave last wrote.
    pub revision: u64,
    pub autosaved_revision: u64,
    /// The last surface point clicked.
    pub hit: Option<HitStatus>,
    /// Points placed so far while a curve is drawn (null: no curve is being drawn).
    pub drawing: Option<u32>,
    /// Curve objects picked for a construction, in order.
    pub picked_curves: Vec<u32>,
    /// The curve segments the curve pass evaluates and their vertices.
    pub curve_segments: u32,
    pub curve_vertices: u32,
    /// The Recent list: documents New and Open replaced, newest first ("name · N objects").
    pub recent: Vec<String>,
    /// The Export window's triangle count (or why it cannot export), while it is open.
    pub export_estimate: Option<String>,
    /// A running export's progress (0 to 1, by the estimated triangles written), if one runs.
    pub export_progress: Option<f64>,
    /// A STEP file being opened: its progress (0 to 1), while it is.
    pub open_progress: Option<f64>,
    /// A boolean running a step at a time: its progress (0 to 1), while it runs.
    pub boolean_progress: Option<f64>,
    /// The last error the user should see, or null.
    pub error: Option<String>,
    /// What the last file opened could not give (STEP faces skipped: each kind of entity
    /// that cost faces with their count, then each face), empty when it gave everything.
    pub warnings: Vec<String>,
    /// Something the editor did on its own that the user should know (e.g. tessellation lowered
    /// to fit the device), or null.
    pub notice: Option<String>,
}

/// A clicked surface point: the object, its (u, v) and the point.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct HitStatus {
    pub object: u32,
    pub u: f64,
    pub v: f64,
    pub point: [f64; 3],
}

impl AppStatus {
    pub fn to_json(&self) -> String {
        serde_json::to_string(self).unwrap_or_else(|e| format!("{{\"error\":\"{e}\"}}"))
    }
}

struct Shared {
    status: Option<AppStatus>,
    handles: Vec<Option<[f32; 2]>>,
    project: String,
    /// Finished exports the page asked for, by request number, until it takes them.
    exports: Vec<(u32, Result<Vec<u8>, String>)>,
}

static SHARED: Mutex<Shared> = Mutex::new(Shared {
    status: None,
    handles: Vec::new(),
    project: String::new(),
    exports: Vec::new(),
});

fn with_shared<R>(f: impl FnOnce(&mut Shared) -> R) -> R {
    let mut guard = SHARED
        .lock()
        .unwrap_or_else(|poisoned| poisoned.into_inner());
    f(&mut guard)
}

/// Publishes the editor's current status where it changed since the last one (the editor
/// calls this every frame; the copy is made only on a change).
pub fn publish(status: &AppStatus) {
    with_shared(|s| {
        if s.status.as_ref() != Some(status) {
            s.status = Some(status.clone());
        }
    });
}

/// Publishes where the selected object's control points are on the screen (logical pixels
/// from the window's top-left corner; `None` behind the eye).
pub fn publish_handles(handles: Vec<Option<[f32; 2]>>) {
    with_shared(|s| s.handles = handles);
}

/// Publishes the document as project text (after every change).
pub fn publish_project(text: String) {
    with_shared(|s| s.project = text);
}

/// The latest published project text (empty before the editor runs).
pub fn project() -> String {
    with_shared(|s| s.project.clone())
}

/// Publishes the result of export request `request`: the `.glb` bytes or why there are none.
pub fn finish_export(request: u32, result: Result<Vec<u8>, String>) {
    with_shared(|s| s.exports.push((request, result)));
}

/// Takes the result of export request `request`, once it is finished.
pub fn take_export(request: u32) -> Option<Result<Vec<u8>, String>> {
    with_shared(|s| {
        let k = s.exports.iter().position(|(r, _)| *r == request)?;
        Some(s.exports.swap_remove(k).1)
    })
}

/// The latest published handle positions.
pub fn handles() -> Vec<Option<[f32; 2]>> {
    with_shared(|s| s.handles.clone())
}

/// Sets (or replaces) the error shown before the editor is running, e.g. when it failed to start.
pub fn publish_error(message: String) {
    with_shared(|s| {
        s.status.get_or_insert_with(AppStatus::default).error = Some(message);
    });
}

/// The latest published status (a default one with no backend before the editor runs).
pub fn current() -> AppStatus {
    with_shared(|s| s.status.clone().unwrap_or_default())
}
