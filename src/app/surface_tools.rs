//! The surface tools of the selected object in the side panel: offset, fillet with another
//! object, trim and split by another, blend to or match with another's edge, contours, join
//! with the surfaces whose edges meet it, and explode a polysurface. Each is one command (one
//! undo step); a refusal shows its reason and changes nothing.

use crate::ops::contour::Contour;
use crate::ops::offset::Offset;
use crate::scene::operation::Operation;
use eframe::egui;

use super::{AppCommand, KnotworkApp};
use crate::doc::Command;
use crate::doc::surface_ops::{
    BlendRequest, EDITOR_TOLERANCE, FilletRequest, JOIN_TOLERANCE, MatchRequest,
};
use crate::kernel::blend::EdgeContinuity;

/// The surface tools' settings.
#[derive(Debug, Clone, PartialEq)]
pub struct SurfaceToolState {
    pub offset: f64,
    /// The object the selected one is to be filleted with.
    pub fillet_with: Option<usize>,
    pub radius: f64,
    /// A radius that varies along the fillet, to this at its other end.
    pub radius_end: Option<f64>,
    /// The ball lies on the side each normal points to (else behind).
    pub front_a: bool,
    pub front_b: bool,
    /// The object the selected one is to be trimmed or split by.
    pub cut_with: Option<usize>,
    /// A trim waiting for the click on the part to keep: (object, cutter).
    pub pending_trim: Option<(usize, usize)>,
    /// The object whose nearest edge the selected one is blended to or matched with.
    pub edge_with: Option<usize>,
    pub continuity: EdgeContinuity,
    /// The blend's tension at both edges.
    pub tension: f64,
    /// The distance between contour planes and their normal (0: x, 1: y, 2: z).
    pub contour_spacing: f64,
    pub contour_axis: usize,
    /// Whether what Offset, Blend and Contour add keeps its history (made again when the
    /// surfaces it was made from change).
    pub keep_history: bool,
    /// The last tool applied, while its parameters may still be adjusted.
    pub last: Option<LastTool>,
}

/// The last surface tool applied while it is still the document's newest step and nothing
/// else has changed since (Blender's "adjust last operation"): changing the panel's
/// parameters applies it again in its place, still one undo step.
#[derive(Debug, Clone, PartialEq)]
pub struct LastTool {
    /// The command as applied (the newest undo step).
    pub command: Command,
    /// The last command asked for in its place (refused where it differs from `command`).
    pub tried: Command,
    /// The undo depth and document revision right after it.
    pub depth: usize,
    pub revision: u64,
}

impl Default for SurfaceToolState {
    fn default() -> Self {
        Self {
            offset: 0.1,
            fillet_with: None,
            radius: 0.1,
            radius_end: None,
            front_a: false,
            front_b: false,
            cut_with: None,
            pending_trim: None,
            edge_with: None,
            continuity: EdgeContinuity::G2,
            tension: 1.0,
            contour_spacing: 0.25,
            contour_axis: 2,
            keep_history: false,
            last: None,
        }
    }
}

impl SurfaceToolState {
    /// The contour planes' normal: the chosen axis.
    fn contour_normal(&self) -> glam::DVec3 {
        let mut normal = glam::DVec3::ZERO;
        normal[self.contour_axis.min(2)] = 1.0;
        normal
    }

    /// `command` (a tool's) with the panel's current parameters; `None` for a command the
    /// panel does not adjust.
    pub fn adjusted(&self, command: &Command) -> Option<Command> {
        Some(match command {
            Command::Apply {
                operation,
                keep_history,
            } => {
                let operation = if let Some(o) = operation.params::<Offset>() {
                    Operation::new(Offset {
                        distance: self.offset,
                        ..o.clone()
                    })
                } else if let Some(r) = operation.params::<BlendRequest>() {
                    Operation::new(BlendRequest {
                        continuity: self.continuity,
                        tension: [self.tension; 2],
                        ..*r
                    })
                } else if let Some(r) = operation.params::<MatchRequest>() {
                    Operation::new(MatchRequest {
                        continuity: self.continuity,
                        ..*r
                    })
                } else if let Some(r) = operation.params::<FilletRequest>() {
                    Operation::new(FilletRequest {
                        radius: self.radius,
                        radius_end: self.radius_end,
                        front_a: self.front_a,
                        front_b: self.front_b,
                        ..*r
                    })
                } else if let Some(c) = operation.params::<Contour>() {
                    Operation::new(Contour {
                        normal: self.contour_normal().to_array(),
                        spacing: self.contour_spacing,
                        ..c.clone()
                    })
                } else {
                    return None;
                };
                Command::Apply {
                    operation,
                    keep_history: *keep_history,
                }
            }
            _ => return None,
        })
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
        let polysurface = object.geometry.as_polysurface().is_some();
        let others: Vec<(usize, String)> = self
            .scene()
            .objects
            .iter()
            .enumerate()
            .filter(|(k, o)| *k != s && o.kind().space_curve().is_none() && !o.faces().is_empty())
            .map(|(k, o)| (k, o.name.clone()))
            .collect();
        ui.separator();
        ui.horizontal(|ui| {
            ui.label(egui::RichText::new("Surface tools").strong());
            ui.checkbox(&mut self.surface_tools.keep_history, "Follow")
                .on_hover_text(
                    "what Offset, Blend and Contour add keeps its history: it is made again \
                     when the surfaces it was made from change",
                );
        });
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
                command = Some(Command::Apply {
                    operation: Operation::new(Offset {
                        object: s.into(),
                        distance: self.surface_tools.offset,
                        tolerance: EDITOR_TOLERANCE,
                    }),
                    keep_history: self.surface_tools.keep_history,
                });
            }
        });
        if !others.is_empty() {
            let t = &mut self.surface_tools;
            let chosen = object_choice(ui, "Fillet with", &mut t.fillet_with, &others);
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
            ui.horizontal(|ui| {
                let mut varying = t.radius_end.is_some();
                ui.checkbox(&mut varying, "varying to")
                    .on_hover_text("the radius runs linearly along the fillet to this one");
                match (varying, t.radius_end) {
                    (true, None) => t.radius_end = Some(2.0 * t.radius),
                    (false, Some(_)) => t.radius_end = None,
                    _ => {}
                }
                if let Some(end) = t.radius_end.as_mut() {
                    ui.add(
                        egui::DragValue::new(end)
                            .speed(0.01)
                            .range(1e-6..=1e6)
                            .prefix("r "),
                    );
                }
            });
            if ui
                .button("Fillet")
                .on_hover_text("roll a ball between the two; both are trimmed back to it")
                .clicked()
            {
                command = Some(Command::operation(FilletRequest {
                    a: s.into(),
                    b: chosen.into(),
                    radius: t.radius,
                    radius_end: t.radius_end,
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
            let by = object_choice(ui, "Cut by", &mut t.cut_with, &cutters);
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
                    command = Some(Command::operation(crate::ops::split::Split {
                        object: s.into(),
                        cutters: vec![by.into()],
                    }));
                }
            });
            if t.pending_trim == Some((s, by)) {
                ui.label("click the part to keep");
            }
        }
        if !others.is_empty() {
            command = command.or(self.edge_tools(ui, s, trimmable, &others));
        }
        command = command.or(self.contour_tools(ui, s));
        ui.horizontal(|ui| {
            if ui
                .button("Join")
                .on_hover_text("join with every surface whose edges meet this one's")
                .clicked()
            {
                command = Some(Command::operation(crate::ops::join::Join {
                    objects: Vec::new(),
                    tolerance: JOIN_TOLERANCE,
                }));
            }
            if polysurface
                && ui
                    .button("Explode")
                    .on_hover_text("the polysurface's faces as objects of their own")
                    .clicked()
            {
                command = Some(Command::operation(crate::ops::explode::Explode {
                    object: s.into(),
                }));
            }
        });
        if let Some(command) = command {
            self.apply_tool(command);
        }
        self.adjust_last_tool(ui);
    }

    /// Applies a tool's command; one that made an undo step may be adjusted afterwards.
    fn apply_tool(&mut self, command: Command) {
        let depth = self.doc.history.undo_depth();
        self.apply(AppCommand::Edit(command.clone()));
        let after = self.doc.history.undo_depth();
        self.surface_tools.last = (after > depth).then(|| LastTool {
            tried: command.clone(),
            command,
            depth: after,
            revision: self.saved.revision,
        });
    }

    /// While the last tool is still the newest step, applies it again in its place when the
    /// panel's parameters changed; a refused one brings the previous back and says why.
    fn adjust_last_tool(&mut self, ui: &mut egui::Ui) {
        let Some(last) = self.surface_tools.last.clone() else {
            return;
        };
        if self.doc.history.undo_depth() != last.depth || self.saved.revision != last.revision {
            self.surface_tools.last = None;
            return;
        }
        ui.label(
            egui::RichText::new(format!(
                "adjusting the last {}: change its settings above",
                last.command.label()
            ))
            .weak(),
        );
        let Some(next) = self.surface_tools.adjusted(&last.command) else {
            return;
        };
        if next == last.tried {
            return;
        }
        self.apply(AppCommand::Undo);
        self.apply(AppCommand::Edit(next.clone()));
        let accepted = self.doc.history.undo_depth() == last.depth;
        if !accepted {
            let refused = self.status.error.clone();
            self.apply(AppCommand::Redo);
            self.status.error = refused;
        }
        self.surface_tools.last = Some(LastTool {
            command: if accepted { next.clone() } else { last.command },
            tried: next,
            depth: self.doc.history.undo_depth(),
            revision: self.saved.revision,
        });
    }

    /// Blend to or match with the nearest edge of another object.
    fn edge_tools(
        &mut self,
        ui: &mut egui::Ui,
        s: usize,
        movable: bool,
        others: &[(usize, String)],
    ) -> Option<Command> {
        let t = &mut self.surface_tools;
        let with = object_choice(ui, "Edge of", &mut t.edge_with, others);
        let mut command = None;
        ui.horizontal(|ui| {
            for c in [EdgeContinuity::G0, EdgeContinuity::G1, EdgeContinuity::G2] {
                ui.selectable_value(&mut t.continuity, c, c.name())
                    .on_hover_text("position, tangent plane (G1), curvature (G2)");
            }
            ui.add(
                egui::DragValue::new(&mut t.tension)
                    .speed(0.01)
                    .range(0.05..=10.0)
                    .prefix("tension "),
            );
        });
        ui.horizontal(|ui| {
            if ui
                .button("Blend")
                .on_hover_text(
                    "a surface across the gap between the nearest edges of the two, \
                     at this continuity with both",
                )
                .clicked()
            {
                command = Some(Command::Apply {
                    operation: Operation::new(BlendRequest {
                        a: s.into(),
                        b: with.into(),
                        edges: None,
                        continuity: t.continuity,
                        tension: [t.tension; 2],
                        tolerance: EDITOR_TOLERANCE * 1e-2,
                    }),
                    keep_history: t.keep_history,
                });
            }
            if movable
                && ui
                    .button("Match")
                    .on_hover_text(
                        "move this surface's nearest edge onto the other's, \
                         at this continuity (its control rows there move)",
                    )
                    .clicked()
            {
                command = Some(Command::operation(MatchRequest {
                    object: s.into(),
                    target: with.into(),
                    edges: None,
                    continuity: t.continuity,
                    tolerance: EDITOR_TOLERANCE * 1e-2,
                }));
            }
        });
        command
    }

    /// Sections by parallel planes at a spacing, as curves.
    fn contour_tools(&mut self, ui: &mut egui::Ui, s: usize) -> Option<Command> {
        let t = &mut self.surface_tools;
        let mut command = None;
        ui.horizontal(|ui| {
            ui.add(
                egui::DragValue::new(&mut t.contour_spacing)
                    .speed(0.01)
                    .range(1e-4..=1e6)
                    .prefix("every "),
            );
            for (k, axis) in ["x", "y", "z"].into_iter().enumerate() {
                ui.selectable_value(&mut t.contour_axis, k, axis);
            }
            if ui
                .button("Contour")
                .on_hover_text("the sections by planes across this axis, as curves")
                .clicked()
            {
                command = Some(Command::Apply {
                    operation: Operation::new(Contour {
                        object: s.into(),
                        origin: [0.0; 3],
                        normal: t.contour_normal().to_array(),
                        spacing: t.contour_spacing,
                    }),
                    keep_history: t.keep_history,
                });
            }
        });
        command
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
        self.apply(AppCommand::Edit(Command::operation(
            crate::ops::trim::Trim {
                object: object.into(),
                cutters: vec![cutter.into()],
                keep: hit.point.to_array(),
            },
        )));
        true
    }
}

/// A labelled combo box of `choices` (object index, name) whose choice stays one of them (the
/// first when it was none or is gone); the chosen index. `choices` must not be empty.
pub(super) fn object_choice(
    ui: &mut egui::Ui,
    label: &str,
    chosen: &mut Option<usize>,
    choices: &[(usize, String)],
) -> usize {
    let first = choices.first().map_or(0, |(k, _)| *k);
    if chosen.is_none_or(|k| !choices.iter().any(|(j, _)| *j == k)) {
        *chosen = Some(first);
    }
    let current = chosen.unwrap_or(first);
    let name = choices
        .iter()
        .find(|(k, _)| *k == current)
        .map_or("", |(_, n)| n.as_str());
    ui.horizontal(|ui| {
        ui.label(label);
        egui::ComboBox::from_id_salt(label)
            .width(90.0)
            .selected_text(name)
            .show_ui(ui, |ui| {
                for (k, n) in choices {
                    ui.selectable_value(chosen, Some(*k), n);
                }
            });
    });
    chosen.unwrap_or(first)
}
