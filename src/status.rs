//! The editor's state as the outside sees it — `window.knotwork.status()` in the page, a log line
//! on the desktop — and commands the outside can send in (`window.knotwork.setSegments(n)`).

use std::sync::Mutex;

use serde::Serialize;

/// A snapshot of what the editor shows. Serialized as JSON for scripts and tests.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct AppStatus {
    /// "webgpu", "vulkan", "metal", "dx12", "webgl2/gl"; empty before the GPU is up.
    pub backend: String,
    /// Adapter name, e.g. "llvmpipe (LLVM 15.0.6, 256 bits)" or "google · swiftshader".
    pub adapter: String,
    pub patches: u32,
    pub control_points: u32,
    /// Segments per patch edge.
    pub segments: u32,
    /// Vertices the compute pass writes.
    pub vertices: u32,
    pub triangles: u32,
    /// Viewport frames rendered so far.
    pub frames: u64,
    /// Compute pass duration on the GPU (timestamp queries), when the device has them.
    pub gpu_eval_ms: Option<f64>,
    /// Render pass duration on the GPU (timestamp queries), when the device has them.
    pub gpu_render_ms: Option<f64>,
    /// Time between the last two frames, measured on the CPU.
    pub frame_interval_ms: Option<f64>,
    /// The last error the user should see, or null.
    pub error: Option<String>,
}

impl AppStatus {
    pub fn to_json(&self) -> String {
        serde_json::to_string(self).unwrap_or_else(|e| format!("{{\"error\":\"{e}\"}}"))
    }
}

/// Requests from outside the UI (page scripts, tests).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ExternalCommand {
    SetSegments(u32),
    /// Redraw every frame (for frame-rate measurements) or only on change.
    SetContinuous(bool),
    FrameModel,
}

struct Shared {
    status: Option<AppStatus>,
    commands: Vec<ExternalCommand>,
    repaint: Option<eframe::egui::Context>,
}

static SHARED: Mutex<Shared> = Mutex::new(Shared {
    status: None,
    commands: Vec::new(),
    repaint: None,
});

fn with_shared<R>(f: impl FnOnce(&mut Shared) -> R) -> R {
    let mut guard = SHARED
        .lock()
        .unwrap_or_else(|poisoned| poisoned.into_inner());
    f(&mut guard)
}

/// Publishes the editor's current status.
pub fn publish(status: &AppStatus) {
    with_shared(|s| s.status = Some(status.clone()));
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

/// Lets [`send`] wake the UI.
pub fn set_repaint_context(ctx: &eframe::egui::Context) {
    with_shared(|s| s.repaint = Some(ctx.clone()));
}

/// Queues a command for the editor and asks for a frame to process it.
pub fn send(command: ExternalCommand) {
    let ctx = with_shared(|s| {
        s.commands.push(command);
        s.repaint.clone()
    });
    if let Some(ctx) = ctx {
        ctx.request_repaint();
    }
}

/// Takes the queued commands.
pub fn take_commands() -> Vec<ExternalCommand> {
    with_shared(|s| std::mem::take(&mut s.commands))
}
