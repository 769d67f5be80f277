//! The editor's one vocabulary of requests: [`AppCommand`]. The page's script interface, tests
//! and the editor's own mouse and panels ask for changes with it, and [`KnotworkApp::apply`]
//! carries every one out in one place. A change to the document is a [`Command`] inside it
//! (one undo step: the history, the GPU sync and the autosave follow from
//! [`KnotworkApp::execute`]); a drag is a sequence of [`DragStep`]s, the incremental path that
//! re-evaluates only the moved points' patches.
//!
//! Requests from outside a frame travel through a channel: a [`CommandSender`] (cloneable,
//! `Send`) queues them and wakes the UI; the editor drains its [`CommandQueue`] at the start of
//! every frame.

use std::sync::{Arc, OnceLock, mpsc};

use eframe::egui;
use glam::DVec3;

use super::{GizmoMode, KnotworkApp, StandardView};
use crate::doc::Command;
use crate::kernel::subdiv::patches::Display;
use crate::view::{AnalysisSettings, ShadingMode};

/// One request to the editor.
#[derive(Debug, Clone, PartialEq)]
pub enum AppCommand {
    /// A change to the document: one undo step. `MovePoints` takes the drag's incremental path
    /// (only the moved points' patches are re-evaluated); `ApplyLattice`'s notice says whether
    /// the result is exact or refitted.
    Edit(Command),
    /// One step of a drag of control points.
    Drag(DragStep),
    Undo,
    Redo,
    /// Opens a file's bytes (as if the file `name` were opened): a project, a glTF, an OBJ.
    Open {
        name: String,
        bytes: Vec<u8>,
    },
    /// A file could not be read (the browser's read failed): shows why, changes nothing.
    OpenFailed {
        name: String,
        reason: String,
    },
    /// Starts again from the sample scene, or (`empty`) from no objects: one undo step.
    NewDocument {
        empty: bool,
    },
    /// Opens entry `index` (0: the newest) of the Recent list: one undo step.
    OpenRecent(usize),
    /// Exports the document as it is when the command's turn comes (after every command sent
    /// before it) as a `.glb`, a frame's budget of objects at a time; the result goes to the status under
    /// `request` ([`crate::status::take_export`]). `options` is JSON as in
    /// [`crate::io::gltf::options_from_json`].
    Export {
        request: u32,
        options: String,
    },
    /// Stops the running export (its result is "cancelled").
    CancelExport,
    /// Stops opening the STEP file being opened; the document stays as it was.
    CancelOpen,
    /// Runs a union, difference or intersection a step at a time, with its progress and
    /// Cancel (a split at once), and applies it as [`Command::Apply`] would: one undo step.
    Boolean {
        params: crate::ops::boolean::Boolean,
        keep_history: bool,
    },
    /// Stops the boolean running a step at a time; the document stays as it was.
    CancelBoolean,
    /// Writes the document's visible objects with faces as a file of `format` (STEP, STL,
    /// 3MF), as it is when the command's turn comes; the bytes go to the status under
    /// `request` ([`crate::status::take_export`]).
    ExportFile {
        request: u32,
        format: super::export::FileExport,
    },
    /// Sets the sharpness of the cage edge between points `a` and `b` of subdivision surface
    /// `object` (0 removes the crease): a [`Command::SetSubdivision`] of its settings.
    SetCrease {
        object: usize,
        a: u32,
        b: u32,
        sharpness: f64,
    },
    /// Shows subdivision surface `object` as `display`, with the adaptive display's flatness
    /// tolerance where given: a [`Command::SetSubdivision`] of its settings.
    SetSubdivisionDisplay {
        object: usize,
        display: Display,
        tolerance: Option<f64>,
    },
    /// Puts one lattice of these degrees around the objects' common box (they share it): a
    /// [`Command::SetLattice`].
    AddLattice {
        objects: Vec<usize>,
        degrees: [usize; 3],
    },
    /// Releases the lattice of `object` and of the objects sharing it.
    ReleaseLattice {
        object: usize,
    },
    /// Segments per Bézier span edge for every object (nothing when they already have them).
    SetSegments(u32),
    /// The global quality factor (multiplies every object's segments; a view setting).
    SetQuality(f32),
    /// View-adaptive (with the tolerated error in pixels) or fixed tessellation.
    SetTessellation {
        adaptive: bool,
        tolerance_px: f32,
    },
    SetShading(ShadingMode),
    /// Turns the camera to a standard view.
    SetView(StandardView),
    SetOrthographic(bool),
    SetGizmo(GizmoMode),
    /// The analysis modes' settings (checked by the sender).
    SetAnalysis(AnalysisSettings),
    /// A manual colour range, or `None` for the automatic one.
    SetRange(Option<(f64, f64)>),
    /// Redraw every frame (for frame-rate measurements) or only on change.
    SetContinuous(bool),
    FrameModel,
    Select(Option<usize>),
    /// Selects control points of the selected object.
    SelectPoints(Vec<usize>),
    /// Chooses the trim tool by name ("circle", "rectangle", "hexagon", "polyline", "curve";
    /// any other name: none) for the selected NURBS surface.
    SetTrimTool(String),
    /// One step of drawing a curve on a construction plane.
    DrawCurve(super::curves::DrawStep),
    /// Sets the curves picked for a construction, in order.
    PickCurves(Vec<usize>),
    /// Builds a construct request on curve objects (its `{"input": k}` is `objects[k]`): a new
    /// object (following its curves when `keep_history`), or with `replace` that object's new
    /// geometry ([`Command::Construct`]).
    ConstructFrom {
        request: serde_json::Value,
        objects: Vec<usize>,
        keep_history: bool,
        replace: Option<usize>,
    },
}

/// One step of a drag: a transient edit of the document that becomes one undo step when it
/// ends. Every step re-evaluates only the Bézier patches the moved points support.
#[derive(Debug, Clone, PartialEq)]
pub enum DragStep {
    /// Starts dragging control points `points` (indices of the object's handles) of `object`.
    Begin { object: usize, points: Vec<usize> },
    /// Moves every dragged point by `offset` from where it started.
    By(DVec3),
    /// Moves dragged points to these positions (the gizmo's rotations and scalings).
    To(Vec<(usize, DVec3)>),
    /// Ends the drag as one undo step.
    End,
    /// Ends the drag and puts everything back.
    Cancel,
}

/// Queues [`AppCommand`]s for the editor from anywhere (the page's script interface, a test, a
/// file dialog's task) and wakes the UI to carry them out.
#[derive(Clone, Debug)]
pub struct CommandSender {
    sender: mpsc::Sender<AppCommand>,
    repaint: Arc<OnceLock<egui::Context>>,
}

/// The editor's end of the channel.
#[derive(Debug)]
pub struct CommandQueue {
    receiver: mpsc::Receiver<AppCommand>,
    repaint: Arc<OnceLock<egui::Context>>,
}

/// A new channel: commands sent before the editor runs wait in it.
pub fn channel() -> (CommandSender, CommandQueue) {
    let (sender, receiver) = mpsc::channel();
    let repaint = Arc::new(OnceLock::new());
    (
        CommandSender {
            sender,
            repaint: Arc::clone(&repaint),
        },
        CommandQueue { receiver, repaint },
    )
}

impl CommandSender {
    /// Queues `command` and asks for a frame to carry it out. A command sent after the editor
    /// has gone is dropped.
    pub fn send(&self, command: AppCommand) {
        if self.sender.send(command).is_ok()
            && let Some(ctx) = self.repaint.get()
        {
            ctx.request_repaint();
        }
    }
}

impl CommandQueue {
    /// Lets senders wake the editor's UI.
    pub(super) fn connect(&self, ctx: &egui::Context) {
        let _ = self.repaint.set(ctx.clone());
    }

    /// The commands queued so far, oldest first.
    pub(super) fn drain(&self) -> Vec<AppCommand> {
        self.receiver.try_iter().collect()
    }
}

impl KnotworkApp {
    /// Takes requests from `queue` (made before the editor, so that nothing sent while it
    /// starts is lost) instead of from the editor's own channel; `sender` is its other end.
    pub fn with_commands(mut self, queue: CommandQueue, sender: CommandSender) -> Self {
        if let Some(ctx) = self.sender.repaint.get() {
            queue.connect(ctx);
        }
        self.commands = queue;
        self.sender = sender;
        self
    }

    /// Where to send this editor requests from outside a frame.
    pub fn command_sender(&self) -> CommandSender {
        self.sender.clone()
    }

    /// Carries out one request: the one place where the page, tests, panels and the mouse
    /// change the editor. Errors show in the status; a refused edit changes nothing. The
    /// status's error is this command's (or a later one's, for work it starts): an error from
    /// an earlier command does not outlive it.
    pub fn apply(&mut self, command: AppCommand) {
        self.status.error = None;
        match command {
            AppCommand::Edit(Command::MovePoints { object, moves }) => {
                self.move_points(object, &moves);
            }
            AppCommand::Edit(Command::ApplyLattice { object, tolerance }) => {
                self.apply_lattice(object, tolerance);
            }
            AppCommand::Edit(command) => self.execute(command),
            AppCommand::Drag(step) => self.drag_step(step),
            AppCommand::Undo => self.step_history(false),
            AppCommand::Redo => self.step_history(true),
            AppCommand::Open { name, bytes } => self.open_file(&name, bytes),
            AppCommand::OpenFailed { name, reason } => self.open_failed(&name, &reason),
            AppCommand::NewDocument { empty } => self.new_document(empty),
            AppCommand::OpenRecent(index) => self.open_recent(index),
            AppCommand::Export { request, options } => self.export_for_page(request, &options),
            AppCommand::CancelExport => self.cancel_export(),
            AppCommand::CancelOpen => self.cancel_open(),
            AppCommand::Boolean {
                params,
                keep_history,
            } => self.start_boolean(params, keep_history),
            AppCommand::CancelBoolean => self.cancel_boolean(),
            AppCommand::ExportFile { request, format } => {
                self.export_file(format, super::export::ExportTarget::Page(request))
            }
            AppCommand::SetCrease {
                object,
                a,
                b,
                sharpness,
            } => self.set_crease(object, a, b, sharpness),
            AppCommand::SetSubdivisionDisplay {
                object,
                display,
                tolerance,
            } => self.set_subdivision_display(object, display, tolerance),
            AppCommand::AddLattice { objects, degrees } => self.add_lattice(&objects, degrees),
            AppCommand::ReleaseLattice { object } => self.set_linked_lattice(object, None),
            AppCommand::SetSegments(n) => self.set_all_segments(n),
            AppCommand::SetQuality(q) => self.set_quality(q),
            AppCommand::SetTessellation {
                adaptive,
                tolerance_px,
            } => self.set_tessellation(adaptive, tolerance_px),
            AppCommand::SetShading(mode) => self.set_shading(mode),
            AppCommand::SetView(view) => self.set_standard_view(view),
            AppCommand::SetGizmo(mode) => self.gizmo_mode = mode,
            AppCommand::SetOrthographic(on) => {
                if self.view.camera.orthographic != on {
                    self.toggle_orthographic();
                }
            }
            AppCommand::SetAnalysis(analysis) => self.view.analysis = analysis,
            AppCommand::SetRange(range) => self.set_manual_range(range),
            AppCommand::SetContinuous(on) => self.continuous = on,
            AppCommand::FrameModel => self.frame_pending = true,
            AppCommand::Select(Some(s)) if s >= self.doc.scene.objects.len() => {
                let count = self.doc.scene.objects.len();
                self.status.error = Some(format!(
                    "select: there is no object {s}; the scene has {count} (0 to {})",
                    count as i64 - 1
                ));
            }
            AppCommand::Select(s) => self.select(s),
            AppCommand::SelectPoints(points) => self.select_points(points),
            AppCommand::SetTrimTool(name) => self.set_trim_tool(&name),
            AppCommand::DrawCurve(step) => self.draw_step(step),
            AppCommand::PickCurves(objects) => self.pick_curves(objects),
            AppCommand::ConstructFrom {
                request,
                objects,
                keep_history,
                replace,
            } => self.construct_from(request, &objects, keep_history, replace),
        }
        self.redraw = true;
    }

    /// Selects control points `points` of the selected object; refused, with the first bad
    /// index named, when nothing is selected or an index is past its points.
    fn select_points(&mut self, points: Vec<usize>) {
        let Some(object) = self
            .selection
            .object
            .and_then(|s| self.doc.scene.objects.get(s))
        else {
            self.status.error = Some("selectPoints: select an object first".into());
            return;
        };
        let count = object.control_point_count();
        if let Some(bad) = points.iter().find(|&&k| k >= count) {
            self.status.error = Some(format!(
                "selectPoints: {} has no point {bad}; its points are 0 to {}",
                object.name,
                count.saturating_sub(1)
            ));
            return;
        }
        self.selection.points = points.into_iter().collect();
        self.update_net();
    }

    /// Carries out one step of a drag: the document moves the points, the GPU re-evaluates
    /// the patches they support.
    pub(super) fn drag_step(&mut self, step: DragStep) {
        let moved = match step {
            DragStep::Begin { object, points } => {
                // A drag under way (the page's) ends as its own undo step first.
                self.end_drag(false);
                self.doc.begin_drag(object, &points).map(|()| None)
            }
            DragStep::By(offset) => self.doc.drag_by(offset).map(Some),
            DragStep::To(moves) => self.doc.drag_to(&moves).map(Some),
            DragStep::End | DragStep::Cancel => {
                self.end_drag(step == DragStep::Cancel);
                return;
            }
        };
        let result = match moved {
            Ok(Some(moved)) => self.show_moved(&moved),
            Ok(None) => Ok(()),
            Err(e) => Err(e.to_string()),
        };
        if let Err(e) = result {
            self.status.error = Some(e);
        }
    }
}
