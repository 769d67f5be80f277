//! The Operations panel: every registered operation ([`crate::ops::operations`]) that has no
//! panel of its own and applies to the selection (the selected object, then the curves picked
//! in order) is a button; a click runs it with its default parameters through
//! [`crate::doc::Command::Apply`], as the page's `apply` and `knotwork apply` do. With "Keep
//! history" what it adds is made again when the objects it was made from change.

use eframe::egui;

use super::{AppCommand, KnotworkApp};
use crate::doc::Command;

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
                crate::ops::boolean::offered(self.scene(), &selection, kind)?,
                label,
                tip,
            ))
        })
        .collect();
        if offered.is_empty() && booleans.is_empty() {
            ui.weak("none applies to the selection");
            return;
        }
        ui.checkbox(&mut self.operations_keep_history, "Keep history")
            .on_hover_text("what the operation adds follows the objects it was made from");
        let mut chosen = None;
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
                for (operation, label, tip) in booleans {
                    if ui.button(label).on_hover_text(tip).clicked() {
                        chosen = Some(operation);
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
    }
}
