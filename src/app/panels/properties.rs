//! The selected object's properties: its points (selection, position, snapping), weights, knots and degree.

use eframe::egui;
use glam::DVec3;

use super::*;
use crate::app::{AppCommand, KnotworkApp};
use crate::doc::{Command, direction_name};
use crate::kernel::Direction;

impl KnotworkApp {
    /// The selected object's control points and NURBS operations.
    pub(in crate::app) fn properties_panel(&mut self, ui: &mut egui::Ui) {
        let Some(s) = self.selection.object else {
            return;
        };
        ui.label(egui::RichText::new("Control points").strong());
        let points = self.scene().objects[s].control_points();
        if points.is_empty() {
            return;
        }
        self.point_selection(ui, points.len());
        self.point_position(ui, s, &points);
        self.snap_settings(ui);
        if self.scene().objects[s].has_weights() {
            self.weight_editor(ui, s);
        }
    }

    /// Which control points are selected (all, none, a row or column), and the one edited by
    /// number (of `count`).
    pub(in crate::app) fn point_selection(&mut self, ui: &mut egui::Ui, count: usize) {
        ui.horizontal(|ui| {
            if ui.button("All").clicked() {
                self.select_all_points();
            }
            if ui.button("None").clicked() {
                self.selection.points.clear();
                self.update_net();
            }
            let grid = self
                .selection
                .object
                .and_then(|s| self.scene().objects.get(s))
                .is_some_and(|o| o.net_grid().is_some());
            if grid
                && ui
                    .button("Row")
                    .on_hover_text("the row (along v) through the point below")
                    .clicked()
            {
                self.select_row(self.selection.edit_point, false);
            }
            if grid
                && ui
                    .button("Column")
                    .on_hover_text("the column (along u) through the point below")
                    .clicked()
            {
                self.select_row(self.selection.edit_point, true);
            }
        });
        ui.label(format!("{} selected", self.selection.points.len()));
        ui.horizontal(|ui| {
            let label = ui.label("Point");
            ui.add(egui::DragValue::new(&mut self.selection.edit_point).range(0..=count - 1))
                .labelled_by(label.id);
        });
        self.selection.edit_point = self.selection.edit_point.min(count - 1);
    }

    /// The edited point's coordinates, and moving the selection by an offset.
    pub(in crate::app) fn point_position(&mut self, ui: &mut egui::Ui, s: usize, points: &[DVec3]) {
        let mut p = points[self.selection.edit_point];
        let before = p;
        ui.horizontal(|ui| {
            for (axis, value) in ["x", "y", "z"]
                .into_iter()
                .zip([&mut p.x, &mut p.y, &mut p.z])
            {
                ui.label(axis);
                ui.add(egui::DragValue::new(value).speed(0.01));
            }
        });
        if p != before {
            self.apply_from(
                "point",
                AppCommand::Edit(Command::MovePoints {
                    object: s,
                    moves: vec![(self.selection.edit_point, p)],
                }),
            );
        }
        ui.horizontal(|ui| {
            ui.label("Move selection by");
            for v in &mut self.panel.move_by {
                ui.add(egui::DragValue::new(v).speed(0.01));
            }
        });
        if ui
            .add_enabled(!self.selection.points.is_empty(), egui::Button::new("Move"))
            .clicked()
        {
            let delta = DVec3::from(self.panel.move_by);
            let moves: Vec<(usize, DVec3)> = self
                .selection
                .points
                .iter()
                .map(|&k| (k, points[k] + delta))
                .collect();
            self.apply_from(
                "point",
                AppCommand::Edit(Command::MovePoints { object: s, moves }),
            );
        }
        self.widget_error(ui, "point");
    }

    /// Snapping of drags: to the grid (and its step), to points, to surfaces.
    pub(in crate::app) fn snap_settings(&mut self, ui: &mut egui::Ui) {
        ui.horizontal(|ui| {
            ui.checkbox(&mut self.snap, "Snap drags to grid");
            ui.add(
                egui::DragValue::new(&mut self.snap_step)
                    .speed(0.01)
                    .range(0.001..=100.0),
            );
            if ui
                .small_button("= grid")
                .on_hover_text("the ground grid's minor step")
                .clicked()
                && self.analysis.grid_step > 0.0
            {
                self.snap_step = self.analysis.grid_step;
            }
        });
        ui.horizontal(|ui| {
            ui.label("Snap to");
            ui.checkbox(&mut self.snap_points, "points");
            ui.checkbox(&mut self.snap_surface, "surfaces");
        });
        ui.horizontal_wrapped(|ui| {
            ui.checkbox(&mut self.proportional, "Proportional editing")
                .on_hover_text(
                    "points within the radius of a dragged point follow it, by the smooth \
                     falloff of their distance (O; the wheel changes the radius while dragging)",
                );
            ui.add(
                egui::DragValue::new(&mut self.proportional_radius)
                    .speed(0.01)
                    .range(1e-6..=1e9)
                    .prefix("radius "),
            );
        });
    }

    /// The weight of the selected points (a rational surface results).
    pub(in crate::app) fn weight_editor(&mut self, ui: &mut egui::Ui, s: usize) {
        let weights = self.scene().objects[s].weights();
        let points = &self.selection.points;
        let what = match points.first() {
            None => format!(
                "point {}: {}",
                self.selection.edit_point,
                weights
                    .get(self.selection.edit_point)
                    .copied()
                    .unwrap_or(1.0)
            ),
            Some(_) => {
                let mut values = points.iter().filter_map(|&k| weights.get(k).copied());
                let first = values.next().unwrap_or(1.0);
                let same = values.all(|w| w == first);
                let s = if points.len() == 1 { "" } else { "s" };
                if same {
                    format!("{} selected point{s}: {first}", points.len())
                } else {
                    format!("{} selected points: mixed, the first {first}", points.len())
                }
            }
        };
        ui.horizontal(|ui| {
            ui.label("Weight");
            ui.label(egui::RichText::new(format!("({what})")).weak());
        });
        ui.horizontal(|ui| {
            let slider = ui.add(
                egui::Slider::new(&mut self.panel.weight, 0.05..=20.0)
                    .logarithmic(true)
                    // Typed values are not clamped: the command refuses w <= 0 with a message.
                    .clamping(egui::SliderClamping::Never)
                    .text("w"),
            );
            let apply = ui.button("Set").clicked()
                || slider.drag_stopped()
                || (slider.changed() && !slider.dragged());
            if apply {
                let points = if self.selection.points.is_empty() {
                    vec![self.selection.edit_point]
                } else {
                    self.selection.points.iter().copied().collect()
                };
                let weight = self.panel.weight;
                self.apply_from(
                    "weight",
                    AppCommand::Edit(Command::SetWeight {
                        object: s,
                        points,
                        weight,
                    }),
                );
            }
        });
        self.widget_error(ui, "weight");
    }

    /// A NURBS surface's knots and degree: insert, remove, elevate, split, reverse, swap, and
    /// the knot vectors as text.
    pub(in crate::app) fn knots_and_degree(&mut self, ui: &mut egui::Ui, s: usize) {
        let Some(surface) = self.scene().objects[s].geometry.nurbs_surface() else {
            return;
        };
        let surface = surface.clone();
        let [(u0, u1), (v0, v1)] = surface.domain();
        let degree = surface.degree();
        ui.separator();
        ui.label(egui::RichText::new("Knots and degree").strong());
        let previous = self.panel.direction;
        ui.horizontal(|ui| {
            ui.selectable_value(&mut self.panel.direction, Direction::U, "u");
            ui.selectable_value(&mut self.panel.direction, Direction::V, "v");
            let d = self.panel.direction;
            ui.label(format!("degree {}", degree[d.index()]));
        });
        if self.panel.direction != previous {
            self.panel.sync(
                self.doc
                    .scene
                    .objects
                    .get(self.selection.object.unwrap_or(usize::MAX)),
            );
        }
        let d = self.panel.direction;
        let (lo, hi) = if d == Direction::U {
            (u0, u1)
        } else {
            (v0, v1)
        };
        ui.horizontal(|ui| {
            ui.label("at");
            ui.add(
                egui::DragValue::new(&mut self.panel.knot_value)
                    .speed((hi - lo) * 0.005)
                    .range(lo..=hi),
            );
            if let Some(hit) = self.selection.hit.filter(|h| h.object == s)
                && ui
                    .button("clicked (u, v)")
                    .on_hover_text(format!("u = {:.4}, v = {:.4}", hit.u, hit.v))
                    .clicked()
            {
                self.panel.knot_value = if d == Direction::U { hit.u } else { hit.v };
            }
        });
        let value = self.panel.knot_value;
        let tolerance = 1e-6 * surface.size().max(1.0);
        let mut command = None;
        ui.horizontal_wrapped(|ui| {
            if ui.button("Insert knot").clicked() {
                command = Some(Command::InsertKnot {
                    object: s,
                    direction: d,
                    value,
                });
            }
            if ui
                .button("Remove knot")
                .on_hover_text("only if the shape stays within 1e-6 of the size")
                .clicked()
            {
                command = Some(Command::RemoveKnot {
                    object: s,
                    direction: d,
                    value,
                    tolerance,
                });
            }
            if ui.button("Elevate degree").clicked() {
                command = Some(Command::ElevateDegree {
                    object: s,
                    direction: d,
                });
            }
            if ui.button("Split").clicked() {
                command = Some(Command::Split {
                    object: s,
                    direction: d,
                    value,
                });
            }
            if ui
                .button(format!("Reverse {}", direction_name(d)))
                .clicked()
            {
                command = Some(Command::Reverse {
                    object: s,
                    direction: d,
                });
            }
            if ui.button("Swap u, v").clicked() {
                command = Some(Command::SwapUv { object: s });
            }
        });
        ui.label(format!("{} knots", direction_name(d)));
        ui.add(
            egui::TextEdit::multiline(&mut self.panel.knot_text[d.index()])
                .desired_rows(2)
                .desired_width(f32::INFINITY),
        );
        if ui.button("Apply knots").clicked() {
            match parse_knots(&self.panel.knot_text[d.index()]) {
                Ok(knots) => {
                    command = Some(Command::SetKnots {
                        object: s,
                        direction: d,
                        knots,
                    })
                }
                Err(e) => {
                    let message = format!("{} knots: {e}", direction_name(d));
                    self.status.error = Some(message.clone());
                    self.panel.widget_error = Some(("knots", message));
                }
            }
        }
        if let Some(command) = command {
            self.apply_from("knots", AppCommand::Edit(command));
            self.panel.sync(
                self.doc
                    .scene
                    .objects
                    .get(self.selection.object.unwrap_or(usize::MAX)),
            );
        }
        self.widget_error(ui, "knots");
        if let Some(hit) = self.selection.hit {
            ui.label(
                egui::RichText::new(format!(
                    "clicked: object {}, u = {:.4}, v = {:.4}, point ({:.3}, {:.3}, {:.3})",
                    hit.object, hit.u, hit.v, hit.point.x, hit.point.y, hit.point.z
                ))
                .weak(),
            );
        }
    }
}
