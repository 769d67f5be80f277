//! The surface tools of the selected object in the side panel: offset, fillet with another
//! object, join with the surfaces whose edges meet it, and explode a polysurface. Each is one
//! command (one undo step); a refusal shows its reason and changes nothing.

use eframe::egui;

use super::{AppCommand, KnotworkApp};
use crate::doc::Command;
use crate::doc::surface_ops::{EDITOR_TOLERANCE, FilletRequest, JOIN_TOLERANCE};
use crate::scene::polysurface::Polysurface;

/// The surface tools' settings.
#[derive(Debug, Clone, PartialEq)]
pub struct SurfaceToolState {
    pub offset: f64,
    /// The object the selected one is to be filleted with.
    pub fillet_with: Option<usize>,
    pub radius: f64,
    /// The ball lies on the side each normal points to (else behind).
    pub front_a: bool,
    pub front_b: bool,
    /// The object the selected one is to be trimmed or split by.
    pub cut_with: Option<usize>,
    /// A trim waiting for the click on the part to keep: (object, cutter).
    pub pending_trim: Option<(usize, usize)>,
}

impl Default for SurfaceToolState {
    fn default() -> Self {
        Self {
            offset: 0.1,
            fillet_with: None,
            radius: 0.1,
            front_a: false,
            front_b: false,
            cut_with: None,
            pending_trim: None,
        }
    }
}

impl KnotworkApp {
    /// The surface tools for the selected object (nothing for an object without faces).
    pub(super) fn surface_tools_panel(&mut self, ui: &mut egui::Ui) {
        let Some(s) = self.selection.object else {
            return;
        };
        let Some(object) = self.scene().objects.get(s) else {
            return;
        };
        if object.kind().space_curve().is_some() || object.faces().is_empty() {
            return;
        }
        let polysurface = object.geometry.downcast_ref::<Polysurface>().is_some();
        let others: Vec<(usize, String)> = self
            .scene()
            .objects
            .iter()
            .enumerate()
            .filter(|(k, o)| *k != s && o.kind().space_curve().is_none() && !o.faces().is_empty())
            .map(|(k, o)| (k, o.name.clone()))
            .collect();
        ui.separator();
        ui.label(egui::RichText::new("Surface tools").strong());
        let mut command = None;
        ui.horizontal(|ui| {
            ui.add(
                egui::DragValue::new(&mut self.surface_tools.offset)
                    .speed(0.01)
                    .prefix("d "),
            );
            if ui
                .button("Offset")
                .on_hover_text("a copy at this distance along the normal (negative: behind)")
                .clicked()
            {
                command = Some(Command::Offset {
                    object: s,
                    distance: self.surface_tools.offset,
                    tolerance: EDITOR_TOLERANCE,
                });
            }
        });
        if !others.is_empty() {
            let t = &mut self.surface_tools;
            if t.fillet_with
                .is_none_or(|k| !others.iter().any(|(j, _)| *j == k))
            {
                t.fillet_with = Some(others[0].0);
            }
            let chosen = t.fillet_with.unwrap_or(others[0].0);
            let name = others
                .iter()
                .find(|(k, _)| *k == chosen)
                .map_or("", |(_, n)| n.as_str());
            ui.horizontal(|ui| {
                ui.label("Fillet with");
                egui::ComboBox::from_id_salt("fillet with")
                    .width(90.0)
                    .selected_text(name)
                    .show_ui(ui, |ui| {
                        for (k, n) in &others {
                            ui.selectable_value(&mut t.fillet_with, Some(*k), n);
                        }
                    });
            });
            ui.horizontal(|ui| {
                ui.add(
                    egui::DragValue::new(&mut t.radius)
                        .speed(0.01)
                        .range(1e-6..=1e6)
                        .prefix("r "),
                );
                ui.checkbox(&mut t.front_a, "front")
                    .on_hover_text("the ball on the side this object's normal points to");
                ui.checkbox(&mut t.front_b, "front")
                    .on_hover_text("the ball on the side the other's normal points to");
            });
            if ui
                .button("Fillet")
                .on_hover_text("roll a ball between the two; both are trimmed back to it")
                .clicked()
            {
                command = Some(Command::Fillet(FilletRequest {
                    a: s,
                    b: chosen,
                    radius: t.radius,
                    front_a: t.front_a,
                    front_b: t.front_b,
                    tolerance: EDITOR_TOLERANCE,
                }));
            }
        }
        let cutters: Vec<(usize, String)> = self
            .scene()
            .objects
            .iter()
            .enumerate()
            .filter(|(k, _)| *k != s)
            .map(|(k, o)| (k, o.name.clone()))
            .collect();
        let trimmable = self
            .scene()
            .objects
            .get(s)
            .is_some_and(|o| o.geometry.as_trimmed().is_some());
        if trimmable && !cutters.is_empty() {
            let t = &mut self.surface_tools;
            if t.cut_with
                .is_none_or(|k| !cutters.iter().any(|(j, _)| *j == k))
            {
                t.cut_with = Some(cutters[0].0);
            }
            let by = t.cut_with.unwrap_or(cutters[0].0);
            let name = cutters
                .iter()
                .find(|(k, _)| *k == by)
                .map_or("", |(_, n)| n.as_str());
            ui.horizontal(|ui| {
                ui.label("Cut by");
                egui::ComboBox::from_id_salt("cut by")
                    .width(90.0)
                    .selected_text(name)
                    .show_ui(ui, |ui| {
                        for (k, n) in &cutters {
                            ui.selectable_value(&mut t.cut_with, Some(*k), n);
                        }
                    });
            });
            ui.horizontal(|ui| {
                let waiting = t.pending_trim == Some((s, by));
                if ui
                    .selectable_label(waiting, "Trim…")
                    .on_hover_text("then click the part of this object to keep")
                    .clicked()
                {
                    t.pending_trim = if waiting { None } else { Some((s, by)) };
                }
                if ui
                    .button("Split")
                    .on_hover_text("cut into the parts the other object divides it into")
                    .clicked()
                {
                    command = Some(Command::SplitBy {
                        object: s,
                        cutters: vec![by],
                    });
                }
            });
            if t.pending_trim == Some((s, by)) {
                ui.label("click the part to keep");
            }
        }
        ui.horizontal(|ui| {
            if ui
                .button("Join")
                .on_hover_text("join with every surface whose edges meet this one's")
                .clicked()
            {
                command = Some(Command::Join {
                    objects: Vec::new(),
                    tolerance: JOIN_TOLERANCE,
                });
            }
            if polysurface
                && ui
                    .button("Explode")
                    .on_hover_text("the polysurface's faces as objects of their own")
                    .clicked()
            {
                command = Some(Command::Explode { object: s });
            }
        });
        if let Some(command) = command {
            self.apply(AppCommand::Edit(command));
        }
    }

    /// A click on the surface while a trim waits for the part to keep: the trim, keeping the
    /// part under the click. True when the click was taken.
    pub(super) fn trim_pick_click(&mut self, hit: Option<crate::view::pick::SurfaceHit>) -> bool {
        let Some((object, cutter)) = self.surface_tools.pending_trim else {
            return false;
        };
        let Some(hit) = hit.filter(|h| h.object == object) else {
            return false;
        };
        self.surface_tools.pending_trim = None;
        self.apply(AppCommand::Edit(Command::TrimBy {
            object,
            cutters: vec![cutter],
            keep: hit.point,
        }));
        true
    }
}
