//! The Operations panel: every registered operation ([`crate::ops::operations`]) that has no
//! panel of its own and applies to the selection (the selected object, then the curves picked
//! in order) is a button; a click runs it with its default parameters through
//! [`crate::doc::Command::Apply`], as the page's `apply` and `knotwork apply` do. With "Keep
//! history" what it adds is made again when the objects it was made from change.

use eframe::egui;

use super::export::FrameBudget;
use super::{AppCommand, KnotworkApp};
use crate::doc::Command;
use crate::ops::boolean::{Boolean, Kind};
use crate::scene::operation::Operation;

impl KnotworkApp {
    /// The selected object, then the picked curves (each once).
    fn operation_selection(&self) -> Vec<usize> {
        let mut selection: Vec<usize> = self.selection.object.into_iter().collect();
        for &k in &self.selection.curves {
            if !selection.contains(&k) {
                selection.push(k);
            }
        }
        selection
    }

    /// The Operations section's contents.
    pub(super) fn operations_panel(&mut self, ui: &mut egui::Ui) {
        let selection = self.operation_selection();
        let offered: Vec<_> = crate::ops::operations()
            .into_iter()
            .filter(|entry| !entry.own_panel)
            .filter_map(|entry| Some((entry, (entry.on_selection)(self.scene(), &selection)?)))
            .collect();
        let booleans: Vec<_> = [
            (
                crate::ops::boolean::Kind::Union,
                "Union",
                "one body of all the selected",
            ),
            (
                crate::ops::boolean::Kind::Difference,
                "Difference",
                "the first selected body minus the others",
            ),
            (
                crate::ops::boolean::Kind::Intersection,
                "Intersection",
                "what the first selected body has in common with the others",
            ),
            (
                crate::ops::boolean::Kind::Split,
                "Split",
                "the first selected body cut by the other selected surfaces into closed pieces",
            ),
        ]
        .into_iter()
        .filter_map(|(kind, label, tip)| {
            Some((
                crate::ops::boolean::params(self.scene(), &selection, kind)?,
                label,
                tip,
            ))
        })
        .collect();
        let features = self.features_row(ui, &selection);
        if offered.is_empty() && booleans.is_empty() {
            if !features {
                ui.weak("none applies to the selection");
            }
            return;
        }
        ui.checkbox(&mut self.operations_keep_history, "Keep history")
            .on_hover_text("what the operation adds follows the objects it was made from");
        let (mut chosen, mut chosen_boolean) = (None, None);
        ui.horizontal_wrapped(|ui| {
            for (entry, operation) in offered {
                if ui.button(entry.name).on_hover_text(entry.summary).clicked() {
                    chosen = Some(operation);
                }
            }
        });
        if !booleans.is_empty() {
            ui.horizontal_wrapped(|ui| {
                ui.label("Solids:");
                for (params, label, tip) in booleans {
                    if ui.button(label).on_hover_text(tip).clicked() {
                        chosen_boolean = Some(params);
                    }
                }
            });
        }
        if let Some(operation) = chosen {
            self.apply(AppCommand::Edit(Command::Apply {
                operation,
                keep_history: self.operations_keep_history,
            }));
        }
        if let Some(params) = chosen_boolean {
            self.apply(AppCommand::Boolean {
                params,
                keep_history: self.operations_keep_history,
            });
        }
    }

    /// Starts the boolean `params` a step at a time ([`RunningBoolean`]): as much as
    /// [`FIRST_TURN_MS`] allows at once (a short boolean is applied in this frame), the rest
    /// a frame's budget at a time with a progress window and Cancel. A split, and a boolean
    /// refused before it starts, are applied as usual (the refusal in the status).
    pub(super) fn start_boolean(&mut self, params: Boolean, keep_history: bool) {
        self.cancel_boolean();
        let operation = Operation::new(params.clone());
        let prepared = match params.prepare(self.scene()) {
            Ok(Some(prepared)) => prepared,
            Ok(None) | Err(_) => {
                self.execute(Command::Apply {
                    operation,
                    keep_history,
                });
                return;
            }
        };
        let mut running = RunningBoolean {
            title: format!(
                "{} of {} bodies",
                capitalised(params.operation),
                params.a.len() + params.b.len()
            ),
            operation,
            keep_history,
            prepared,
            budget: FrameBudget::default(),
        };
        let job = &mut running.prepared.job;
        let first = super::export::steps_within(FIRST_TURN_MS, || job.step());
        self.running_boolean = Some(running);
        self.boolean_turned(first);
    }

    /// Stops the running boolean; the document stays as it was.
    pub(super) fn cancel_boolean(&mut self) {
        if let Some(running) = self.running_boolean.take() {
            self.status.boolean_progress = None;
            self.status.notice = Some(format!("stopped the {}", running.title.to_lowercase()));
        }
    }

    /// The running boolean: steps for as long as its [`FrameBudget`] gives, with a progress
    /// window and Cancel; applied when the last step is done.
    pub(super) fn step_boolean(&mut self, ctx: &egui::Context) {
        let Some(running) = &mut self.running_boolean else {
            self.status.boolean_progress = None;
            return;
        };
        let progress = running.prepared.job.progress();
        self.status.boolean_progress = Some(progress);
        let stage = running.prepared.job.stage();
        if super::export::progress_window(ctx, &running.title, progress, stage) {
            self.cancel_boolean();
            return;
        }
        let job = &mut running.prepared.job;
        let turn = running.budget.run(|| job.step());
        self.boolean_turned(turn);
        ctx.request_repaint();
    }

    /// After a turn of the running boolean: when it is done, its result kept and the
    /// operation applied (one undo step, taking the result rather than running again); a
    /// refusal in the status, the document as it was.
    fn boolean_turned(&mut self, turn: Result<bool, crate::kernel::GeometryError>) {
        match turn {
            Ok(false) => {}
            Ok(true) => {
                if let Some(running) = self.running_boolean.take() {
                    self.status.boolean_progress = None;
                    match running.prepared.finished() {
                        Ok(()) => self.execute(Command::Apply {
                            operation: running.operation,
                            keep_history: running.keep_history,
                        }),
                        Err(e) => self.status.error = Some(e.to_string()),
                    }
                }
            }
            Err(e) => {
                if let Some(running) = self.running_boolean.take() {
                    self.status.boolean_progress = None;
                    self.status.error = Some(running.prepared.refused(e).to_string());
                }
            }
        }
    }
}

/// How long a boolean may run in the frame it is started before it shows its progress
/// (milliseconds): booleans of a few dozen faces are done within it.
const FIRST_TURN_MS: f64 = 50.0;

/// "Union", "Difference", … for a progress window's title.
fn capitalised(kind: Kind) -> &'static str {
    match kind {
        Kind::Union => "Union",
        Kind::Difference => "Difference",
        Kind::Intersection => "Intersection",
        Kind::Split => "Split",
    }
}

/// A boolean run a step at a time, so that the editor draws its progress and stays
/// responsive; commands sent meanwhile wait for it. Its result is applied through the
/// operation, as a click on Union or Difference would (with history when asked).
pub struct RunningBoolean {
    title: String,
    operation: Operation,
    keep_history: bool,
    prepared: crate::doc::surface_ops::PreparedBoolean,
    budget: FrameBudget,
}
