//! The side panel: file and history buttons, the outliner, the selected object's properties
//! (points, weights, knots, degree, split, reverse, transform), the Create dialog, shading,
//! display and timing.

use eframe::egui;
use glam::{DAffine3, DQuat, DVec3};

use super::{AppCommand, KnotworkApp, SLIDER_SEGMENTS};
use crate::doc::create::{Primitive, PrimitiveParams};
use crate::doc::{Command, direction_name};
use crate::gpu::records::CURVATURE_RAMP;
use crate::kernel::Direction;
use crate::kernel::subdiv::adaptive::DEFAULT_TOLERANCE;
use crate::kernel::subdiv::patches::Display;
use crate::kernel::subdiv::{Boundary, Creasing, MAX_LEVEL, Options, Scheme};
use crate::render::DRAFT_COLORS;
use crate::scene::{LengthUnit, SceneObject, SubdivObject, SubdivSettings};
use crate::view::settings::{DRAFT_THRESHOLD, ISOPHOTE_SPACING, ZEBRA_PAIRS};
use crate::view::{QUALITY_RANGE, ShadingMode, StripeFrame, TOLERANCE_RANGE, ZebraSource};

/// What the panel's fields hold between frames.
#[derive(Debug, Clone)]
pub struct PanelState {
    pub direction: Direction,
    pub knot_value: f64,
    pub knot_text: [String; 2],
    pub weight: f64,
    pub move_by: [f64; 3],
    pub name: String,
    pub translate: [f64; 3],
    pub rotate_deg: f64,
    pub scale: f64,
    pub create: PrimitiveParams,
    pub show_create: bool,
    /// A new trim loop keeps its inside (else it cuts a hole).
    pub trim_keep_inside: bool,
    /// The trim handle a right-click in the (u, v) panel is about: (loop, curve, point).
    pub trim_menu: Option<(usize, usize, usize)>,
    /// What the fields were last loaded from ([`KnotworkApp::refresh_fields`]).
    pub loaded_for: Option<FieldSource>,
    /// The widget whose last command was refused, and why: shown beside it.
    pub widget_error: Option<(&'static str, String)>,
}

/// What the panel's fields show: the selected object, its edited and selected points, and
/// the document's revision. When any of them changes the fields are loaded again.
#[derive(Debug, Clone, PartialEq)]
pub struct FieldSource {
    object: usize,
    edit_point: usize,
    points: Vec<usize>,
    revision: u64,
}

impl Default for PanelState {
    fn default() -> Self {
        Self {
            direction: Direction::U,
            knot_value: 0.5,
            knot_text: [String::new(), String::new()],
            weight: 1.0,
            move_by: [0.0; 3],
            name: String::new(),
            translate: [0.0; 3],
            rotate_deg: 0.0,
            scale: 1.0,
            create: PrimitiveParams::default(),
            show_create: false,
            trim_keep_inside: false,
            trim_menu: None,
            loaded_for: None,
            widget_error: None,
        }
    }
}

impl PanelState {
    /// The transform fields back to "no change" (after Apply, or for another object).
    fn reset_transform(&mut self) {
        self.translate = [0.0; 3];
        self.rotate_deg = 0.0;
        self.scale = 1.0;
        self.move_by = [0.0; 3];
    }

    /// Loads the fields from the selected object (after a selection change or an edit).
    pub fn sync(&mut self, object: Option<&SceneObject>) {
        let Some(object) = object else {
            return;
        };
        self.name = object.name.clone();
        if let Some(s) = object.geometry.nurbs_surface() {
            for (d, text) in self.knot_text.iter_mut().enumerate() {
                *text = knot_text(s.knots()[d]);
            }
            // The middle of the widest knot span: a value where a knot can always be inserted.
            let breaks = s.span_breaks(self.direction);
            if let Some(w) = breaks
                .windows(2)
                .max_by(|a, b| (a[1] - a[0]).total_cmp(&(b[1] - b[0])))
            {
                self.knot_value = 0.5 * (w[0] + w[1]);
            }
        }
    }
}

/// A knot vector as the panel shows it: "0, 0, 0, 0.5, 1, 1, 1".
fn knot_text(knots: &[f64]) -> String {
    knots
        .iter()
        .map(|k| format!("{k}"))
        .collect::<Vec<_>>()
        .join(", ")
}

/// Parses a knot vector typed in the panel; the kernel validates it further.
pub fn parse_knots(text: &str) -> Result<Vec<f64>, String> {
    text.split([',', ' ', ';'])
        .filter(|t| !t.trim().is_empty())
        .map(|t| {
            t.trim()
                .parse::<f64>()
                .map_err(|_| format!("{t:?} is not a number"))
        })
        .collect()
}

impl KnotworkApp {
    /// New, open, save, undo and redo.
    fn file_bar(&mut self, ui: &mut egui::Ui) {
        ui.horizontal_wrapped(|ui| {
            ui.menu_button("New", |ui| {
                if ui
                    .button("Sample scene")
                    .on_hover_text("the teapot, a sphere and friends (Undo brings your work back)")
                    .clicked()
                {
                    self.apply(AppCommand::NewDocument { empty: false });
                }
                if ui
                    .button("Empty scene")
                    .on_hover_text("no objects: start from Create (Undo brings your work back)")
                    .clicked()
                {
                    self.apply(AppCommand::NewDocument { empty: true });
                }
            });
            if ui
                .button("Open…")
                .on_hover_text("Ctrl + O; or drop a file on the window")
                .clicked()
            {
                self.open_dialog();
            }
            if ui.button("Save…").on_hover_text("Ctrl + S").clicked() {
                self.save_dialog();
            }
            let recent: Vec<String> = self.saved.recent.iter().map(|r| r.label()).collect();
            ui.add_enabled_ui(!recent.is_empty(), |ui| {
                ui.menu_button("Recent", |ui| {
                    for (index, label) in recent.iter().enumerate() {
                        if ui
                            .button(label)
                            .on_hover_text("documents New and Open replaced, newest first")
                            .clicked()
                        {
                            self.apply(AppCommand::OpenRecent(index));
                        }
                    }
                });
            });
            if ui
                .button("Export glTF…")
                .on_hover_text(
                    "Ctrl + E: triangles for other tools, with the editable model inside",
                )
                .clicked()
            {
                self.export.show = true;
            }
            let unit = self.doc.scene.unit;
            let name = |u: Option<LengthUnit>| u.map_or("unitless", LengthUnit::symbol);
            let mut chosen = unit;
            egui::ComboBox::from_id_salt("document unit")
                .selected_text(name(unit))
                .show_ui(ui, |ui| {
                    for u in std::iter::once(None).chain(LengthUnit::ALL.map(Some)) {
                        ui.selectable_value(&mut chosen, u, name(u));
                    }
                })
                .response
                .on_hover_text(
                    "the unit of the document's coordinates (STEP files open in mm; glTF exports metres)",
                );
            if chosen != unit {
                self.apply(AppCommand::Edit(Command::SetUnit { unit: chosen }));
            }
            if ui
                .button("Export STEP…")
                .on_hover_text(
                    "the visible surfaces as exact B-spline faces, for CAD systems (AP214)",
                )
                .clicked()
            {
                self.export_step_to_file();
            }
        });
        ui.horizontal(|ui| {
            let undo = self.doc.history.undo_label().map(str::to_owned);
            let redo = self.doc.history.redo_label().map(str::to_owned);
            if ui
                .add_enabled(undo.is_some(), egui::Button::new("Undo"))
                .on_hover_text(undo.unwrap_or_default())
                .clicked()
            {
                self.apply(AppCommand::Undo);
            }
            if ui
                .add_enabled(redo.is_some(), egui::Button::new("Redo"))
                .on_hover_text(redo.unwrap_or_default())
                .clicked()
            {
                self.apply(AppCommand::Redo);
            }
            ui.label(
                egui::RichText::new(format!(
                    "{} / {}",
                    self.doc.history.undo_depth(),
                    self.doc.history.redo_depth()
                ))
                .weak(),
            );
        });
        let saved = if self.saved.autosaved_revision == self.saved.revision {
            "autosaved"
        } else {
            "autosave pending"
        };
        if self.saved.autosave {
            ui.label(egui::RichText::new(saved).weak().small());
        }
    }

    /// Object `s`'s colour: a few swatches and the editor's grey, each click one undo step.
    fn color_row(&mut self, ui: &mut egui::Ui, s: usize) {
        const SWATCHES: [[f32; 3]; 8] = [
            [0.80, 0.20, 0.15],
            [0.90, 0.55, 0.15],
            [0.90, 0.80, 0.25],
            [0.35, 0.70, 0.30],
            [0.25, 0.55, 0.85],
            [0.50, 0.35, 0.75],
            [0.85, 0.85, 0.85],
            [0.25, 0.25, 0.28],
        ];
        let current = self.scene().objects[s].color;
        let mut chosen = None;
        ui.horizontal_wrapped(|ui| {
            ui.label("Colour");
            let byte = |x: f32| (x.clamp(0.0, 1.0) * 255.0).round() as u8;
            for rgb in SWATCHES {
                let fill = egui::Color32::from_rgb(byte(rgb[0]), byte(rgb[1]), byte(rgb[2]));
                let mut button = egui::Button::new("  ").fill(fill).small();
                if current == Some(rgb) {
                    button = button.stroke(egui::Stroke::new(2.0, egui::Color32::WHITE));
                }
                if ui.add(button).clicked() && current != Some(rgb) {
                    chosen = Some(Some(rgb));
                }
            }
            if ui
                .add_enabled(current.is_some(), egui::Button::new("Grey").small())
                .on_hover_text("the editor's colour")
                .clicked()
            {
                chosen = Some(None);
            }
            if let Some([r, g, b]) = current
                && !SWATCHES.contains(&[r, g, b])
            {
                ui.label(egui::RichText::new(format!("({r:.2}, {g:.2}, {b:.2})")).weak())
                    .on_hover_text("the colour the file gave it (sRGB)");
            }
        });
        if let Some(color) = chosen {
            self.apply(AppCommand::Edit(Command::SetColor { object: s, color }));
        }
    }

    /// The outliner: every object with its visibility, and the object operations.
    fn objects_panel(&mut self, ui: &mut egui::Ui) {
        ui.horizontal(|ui| {
            ui.label(egui::RichText::new("Objects").strong());
            if ui.small_button("+ Create…").clicked() {
                self.open_create();
            }
        });
        let mut clicked = None;
        let mut visibility = None;
        for (k, object) in self.scene().objects.iter().enumerate() {
            ui.horizontal(|ui| {
                let mut visible = object.visible;
                if ui
                    .checkbox(&mut visible, "")
                    .on_hover_text("visible")
                    .changed()
                {
                    visibility = Some((k, visible));
                }
                let response = ui
                    .selectable_label(self.selection.object == Some(k), &object.name)
                    .on_hover_text(object.describe());
                if response.clicked() {
                    clicked = Some(if self.selection.object == Some(k) {
                        None
                    } else {
                        Some(k)
                    });
                }
            });
        }
        if let Some((object, visible)) = visibility {
            self.apply(AppCommand::Edit(Command::SetVisible { object, visible }));
        }
        if let Some(selection) = clicked {
            self.select(selection);
        }
        let Some(s) = self.selection.object else {
            ui.label(egui::RichText::new("click an object to edit it").weak());
            return;
        };
        ui.horizontal(|ui| {
            if ui.button("Duplicate").clicked() {
                self.apply(AppCommand::Edit(Command::Duplicate { object: s }));
            }
            if ui.button("Delete").clicked() {
                self.apply(AppCommand::Edit(Command::Delete { object: s }));
            }
        });
        ui.horizontal(|ui| {
            let edit =
                ui.add(egui::TextEdit::singleline(&mut self.panel.name).desired_width(140.0));
            let enter = edit.lost_focus() && ui.input(|i| i.key_pressed(egui::Key::Enter));
            if (ui.button("Rename").clicked() || enter)
                && self.panel.name != self.scene().objects[s].name
            {
                let name = self.panel.name.clone();
                self.apply_from(
                    "name",
                    AppCommand::Edit(Command::Rename { object: s, name }),
                );
            }
        });
        self.widget_error(ui, "name");
        self.color_row(ui, s);
        ui.label(egui::RichText::new(self.scene().objects[s].describe()).weak());
        let mut segments = self.scene().objects[s].segments;
        ui.label("Segments per span");
        let response = ui.add(egui::Slider::new(&mut segments, SLIDER_SEGMENTS).text("segments"));
        if response.changed() && segments != self.scene().objects[s].segments {
            self.apply_from(
                "segments",
                AppCommand::Edit(Command::SetSegments {
                    object: s,
                    segments,
                }),
            );
        }
        self.widget_error(ui, "segments");
        egui::CollapsingHeader::new("Transform object").show(ui, |ui| {
            ui.horizontal(|ui| {
                let label = ui.label("move");
                for v in &mut self.panel.translate {
                    ui.add(egui::DragValue::new(v).speed(0.05))
                        .labelled_by(label.id);
                }
            });
            ui.horizontal(|ui| {
                ui.label("rotate about z (°)");
                ui.add(egui::DragValue::new(&mut self.panel.rotate_deg).speed(1.0));
            });
            ui.horizontal(|ui| {
                ui.label("scale");
                ui.add(
                    egui::DragValue::new(&mut self.panel.scale)
                        .speed(0.01)
                        .range(0.001..=1000.0),
                );
            });
            if ui.button("Apply transform").clicked() {
                let centre = self.scene().objects[s]
                    .bounds()
                    .map_or(DVec3::ZERO, |(lo, hi)| 0.5 * (lo + hi));
                let p = &self.panel;
                let transform = DAffine3::from_translation(centre + DVec3::from(p.translate))
                    * DAffine3::from_scale_rotation_translation(
                        DVec3::splat(p.scale),
                        DQuat::from_rotation_z(p.rotate_deg.to_radians()),
                        DVec3::ZERO,
                    )
                    * DAffine3::from_translation(-centre);
                self.apply_from(
                    "transform",
                    AppCommand::Edit(Command::Transform {
                        object: s,
                        transform,
                    }),
                );
                self.panel.reset_transform();
            }
            self.widget_error(ui, "transform");
        });
    }

    /// Carries out `command` for the panel's widget `widget` ("weight", "knots", …): a refusal
    /// shows beside that widget ([`Self::widget_error`]) as well as in the toast.
    fn apply_from(&mut self, widget: &'static str, command: AppCommand) {
        self.apply(command);
        self.panel.widget_error = self.status.error.clone().map(|e| (widget, e));
        if self.panel.widget_error.is_some()
            && let Some(source) = &mut self.panel.loaded_for
        {
            // The refused value leaves the field: it shows the document's again.
            source.revision = u64::MAX;
        }
    }

    /// The refusal of `widget`'s last command, in red right below it, until the next one.
    fn widget_error(&self, ui: &mut egui::Ui, widget: &str) {
        if let Some((w, message)) = &self.panel.widget_error
            && *w == widget
        {
            ui.colored_label(egui::Color32::from_rgb(255, 110, 100), message);
        }
    }

    /// Loads the fields that show the document (the weight; the transform and move fields,
    /// which start from "no change" for each object) whenever the selected object, its
    /// edited or selected points or the document changed since they were loaded, so that a
    /// field never shows another point's or an earlier state's value.
    fn refresh_fields(&mut self) {
        let Some(s) = self.selection.object else {
            self.panel.loaded_for = None;
            return;
        };
        let source = FieldSource {
            object: s,
            edit_point: self.selection.edit_point,
            points: self.selection.points.iter().copied().collect(),
            revision: self.saved.revision,
        };
        if self.panel.loaded_for.as_ref() == Some(&source) {
            return;
        }
        if self.panel.loaded_for.as_ref().map(|f| f.object) != Some(s) {
            self.panel.reset_transform();
            self.panel.widget_error = None;
        }
        let shown = source.points.first().copied().unwrap_or(source.edit_point);
        if let Some(object) = self.scene().objects.get(s) {
            self.panel.weight = object.weights().get(shown).copied().unwrap_or(1.0);
        }
        self.panel.loaded_for = Some(source);
    }

    /// The selected object's control points and NURBS operations.
    fn properties_panel(&mut self, ui: &mut egui::Ui) {
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
        self.knots_and_degree(ui, s);
    }

    /// Which control points are selected (all, none, a row or column), and the one edited by
    /// number (of `count`).
    fn point_selection(&mut self, ui: &mut egui::Ui, count: usize) {
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
    fn point_position(&mut self, ui: &mut egui::Ui, s: usize, points: &[DVec3]) {
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
    fn snap_settings(&mut self, ui: &mut egui::Ui) {
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
    }

    /// The weight of the selected points (a rational surface results).
    fn weight_editor(&mut self, ui: &mut egui::Ui, s: usize) {
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
    fn knots_and_degree(&mut self, ui: &mut egui::Ui, s: usize) {
        let Some(surface) = self.scene().objects[s].geometry.nurbs_surface() else {
            ui.label(egui::RichText::new("knots and degree: a NURBS surface only").weak());
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

    /// The Create dialog: a primitive from the kernel's constructors.
    pub(super) fn create_window(&mut self, ctx: &egui::Context) {
        let mut open = self.panel.show_create;
        let mut create = false;
        egui::Window::new("Create")
            .open(&mut open)
            .resizable(false)
            .show(ctx, |ui| {
                let p = &mut self.panel.create;
                egui::ComboBox::new("primitive", "kind")
                    .selected_text(p.kind.label())
                    .show_ui(ui, |ui| {
                        for kind in Primitive::ALL {
                            ui.selectable_value(&mut p.kind, kind, kind.label());
                        }
                    });
                egui::Grid::new("create params")
                    .num_columns(2)
                    .show(ui, |ui| {
                        ui.label("centre");
                        ui.horizontal(|ui| {
                            for v in [&mut p.center.x, &mut p.center.y, &mut p.center.z] {
                                ui.add(egui::DragValue::new(v).speed(0.1));
                            }
                        });
                        ui.end_row();
                        ui.label("size / radius");
                        ui.add(egui::DragValue::new(&mut p.size).speed(0.05));
                        ui.end_row();
                        // Only the fields this primitive uses, named for what they do here.
                        let (height, ratio) = p.kind.fields();
                        if let Some(label) = height {
                            ui.label(label);
                            ui.add(egui::DragValue::new(&mut p.height).speed(0.05));
                            ui.end_row();
                        }
                        if let Some(label) = ratio {
                            ui.label(label);
                            ui.add(egui::DragValue::new(&mut p.ratio).speed(0.01));
                            ui.end_row();
                        }
                        if p.kind == Primitive::BezierPatch {
                            ui.label("degrees (u, v)");
                            ui.horizontal(|ui| {
                                ui.add(egui::DragValue::new(&mut p.degree[0]).range(1..=9));
                                ui.add(egui::DragValue::new(&mut p.degree[1]).range(1..=9));
                            });
                            ui.end_row();
                        }
                        if p.kind == Primitive::TriangleBezier {
                            ui.label("degree");
                            ui.add(
                                egui::DragValue::new(&mut p.degree[0])
                                    .range(1..=crate::kernel::triangle::MAX_TRIANGLE_DEGREE),
                            );
                            ui.end_row();
                        }
                    });
                create = ui.button("Create").clicked();
            });
        self.panel.show_create = open;
        if create {
            match self.panel.create.build() {
                Ok(mut object) => {
                    object.name = self.scene().unique_name(&object.name);
                    self.apply(AppCommand::Edit(Command::Add { object }));
                    if self.status.error.is_none() {
                        let last = self.scene().objects.len().checked_sub(1);
                        self.select(last);
                        // Bring it into view: the camera frames what was just made.
                        self.frame_selection();
                        self.panel.show_create = false;
                    }
                }
                Err(e) => {
                    self.status.error = Some(format!("{}: {e}", self.panel.create.kind.label()))
                }
            }
        }
    }

    /// Opens the Create window with the centre where the new object is free of the others:
    /// the view's centre if nothing is there, else beside the scene.
    pub(super) fn open_create(&mut self) {
        let p = &self.panel.create;
        let reach = p.size.max(p.height.abs()).max(0.5) * 1.1;
        let wanted = self.view.camera.target.as_dvec3();
        self.panel.create.center = self.scene().free_spot(wanted, reach);
        self.panel.show_create = true;
    }

    /// A dialog: an error (a file that could not be opened and the like) or a file opened
    /// with warnings.
    pub(super) fn dialog_window(&mut self, ctx: &egui::Context) {
        let Some(dialog) = self.dialog.clone() else {
            return;
        };
        let mut close = false;
        egui::Window::new(dialog.title)
            .collapsible(false)
            .resizable(false)
            .anchor(egui::Align2::CENTER_CENTER, egui::Vec2::ZERO)
            .show(ctx, |ui| {
                ui.label(dialog.text);
                if dialog.refused {
                    ui.label(egui::RichText::new("The open document is unchanged.").weak());
                }
                close = ui.button("OK").clicked();
            });
        if close {
            self.dialog = None;
        }
    }

    fn info_grid(&self, ui: &mut egui::Ui) {
        egui::Grid::new("info")
            .num_columns(2)
            .striped(true)
            .show(ui, |ui| {
                let rows = [
                    ("Backend", self.status.backend.clone()),
                    ("Adapter", self.status.adapter.clone()),
                    ("Evaluation", self.status.evaluator.clone()),
                    (
                        "Quality",
                        if self.status.software_adapter {
                            "software: ½ res. in motion".to_owned()
                        } else {
                            "4× MSAA".to_owned()
                        },
                    ),
                    ("Objects", self.status.objects.to_string()),
                    ("Bézier patches", self.status.patches.to_string()),
                    (
                        "In view",
                        match (self.status.visible_patches, self.status.adaptive_coarsening) {
                            (Some(visible), Some(0) | None) => format!("{visible} patches"),
                            (Some(visible), Some(shift)) => {
                                format!("{visible} patches (coarsened {shift}×, growing)")
                            }
                            (None, _) => "all (fixed tessellation)".to_owned(),
                        },
                    ),
                    ("Vertices", self.status.vertices.to_string()),
                    ("Triangles", self.status.triangles.to_string()),
                    (
                        "Re-evaluated",
                        format!("{} patches", self.status.patches_reevaluated),
                    ),
                ];
                for (name, value) in rows {
                    ui.label(name);
                    // A long adapter name ("ANGLE (Google, Vulkan 1.3.0 (SwiftShader ...") or
                    // the WebGL2 evaluator wraps within the panel's width: it neither widens
                    // the panel nor is cut off.
                    ui.add(egui::Label::new(value.as_str()).wrap())
                        .on_hover_text(value);
                    ui.end_row();
                }
            });
    }

    fn shading_panel(&mut self, ui: &mut egui::Ui) {
        ui.label(egui::RichText::new("Shading").strong());
        let mut mode = self.view.shading;
        egui::ComboBox::new("shading", "mode")
            .selected_text(mode.label())
            .show_ui(ui, |ui| {
                for m in ShadingMode::ALL {
                    ui.selectable_value(&mut mode, m, m.label());
                }
            });
        self.set_shading(mode);
        let before = self.view.analysis;
        self.analysis_settings(ui);
        self.accept_analysis_edit(before);
        let Some((lo, hi)) = self.color_range() else {
            return;
        };
        let unit = match self.view.shading {
            ShadingMode::Isophotes => "°",
            ShadingMode::Gaussian => " /length²",
            _ => " /length",
        };
        legend(ui, lo, hi, unit);
        let mut auto = self.view.range.is_none();
        if ui.checkbox(&mut auto, "Automatic range (2–98 %)").changed() {
            self.set_manual_range(if auto { None } else { Some((lo, hi)) });
        }
        if let Some((mut a, mut b)) = self.view.range {
            let speed = ((b - a).abs() * 0.01).max(1e-6);
            ui.horizontal(|ui| {
                ui.label("low");
                ui.add(egui::DragValue::new(&mut a).speed(speed));
                ui.label("high");
                ui.add(egui::DragValue::new(&mut b).speed(speed));
            });
            if (a, b) != (lo, hi) && a < b {
                self.set_manual_range(Some((a, b)));
            }
        }
    }

    /// The current analysis mode's settings and, where it has no colour ramp, its legend.
    fn analysis_settings(&mut self, ui: &mut egui::Ui) {
        let a = &mut self.view.analysis;
        match self.view.shading {
            ShadingMode::Zebra => {
                ui.horizontal(|ui| {
                    ui.label("stripe pairs per 180°");
                    ui.add(egui::DragValue::new(&mut a.zebra_pairs).range(ZEBRA_PAIRS));
                });
                ui.horizontal(|ui| {
                    ui.label("direction");
                    ui.add(
                        egui::DragValue::new(&mut a.zebra_angle)
                            .range(0.0..=180.0)
                            .suffix("°"),
                    );
                    if ui.small_button("horizontal").clicked() {
                        a.zebra_angle = 0.0;
                    }
                    if ui.small_button("vertical").clicked() {
                        a.zebra_angle = 90.0;
                    }
                });
                choice(
                    ui,
                    "stripes fixed to",
                    &mut a.zebra_frame,
                    &[
                        (StripeFrame::View, "the view"),
                        (StripeFrame::World, "the world"),
                    ],
                );
                choice(
                    ui,
                    "stripes follow",
                    &mut a.zebra_source,
                    &[
                        (ZebraSource::Reflection, "the reflection"),
                        (ZebraSource::Normal, "the normal"),
                    ],
                );
                ui.label(format!(
                    "{} black and white pairs per half turn of the {}; smooth stripes: G2, kinks: G1, breaks: G0",
                    a.zebra_pairs,
                    match a.zebra_source {
                        ZebraSource::Reflection => "reflected view ray",
                        ZebraSource::Normal => "normal",
                    }
                ));
            }
            ShadingMode::Isophotes => {
                ui.horizontal(|ui| {
                    ui.label("spacing");
                    ui.add(
                        egui::DragValue::new(&mut a.isophote_spacing)
                            .range(ISOPHOTE_SPACING)
                            .speed(0.5)
                            .suffix("°"),
                    );
                });
                direction_editor(ui, "light", &mut a.isophote_direction);
                ui.label(format!(
                    "lines every {}° of angle between the normal and the light",
                    a.isophote_spacing
                ));
            }
            ShadingMode::Draft => {
                direction_editor(ui, "pull", &mut a.pull_direction);
                ui.horizontal(|ui| {
                    ui.label("threshold");
                    ui.add(
                        egui::DragValue::new(&mut a.draft_threshold)
                            .range(DRAFT_THRESHOLD)
                            .speed(0.25)
                            .suffix("°"),
                    );
                });
                let t = a.draft_threshold;
                for (color, text) in DRAFT_COLORS.iter().zip([
                    format!("draft ≥ {t}°"),
                    format!("0° ≤ draft < {t}°"),
                    "undercut (draft < 0°)".to_owned(),
                ]) {
                    ui.horizontal(|ui| {
                        let (rect, _) =
                            ui.allocate_exact_size(egui::vec2(14.0, 14.0), egui::Sense::hover());
                        ui.painter().rect_filled(
                            rect,
                            2.0,
                            egui::Rgba::from_rgb(color[0], color[1], color[2]),
                        );
                        ui.label(text);
                    });
                }
            }
            ShadingMode::Reflection => {
                ui.label("a studio fixed to the world: soft boxes overhead, at the key and behind, a floor");
            }
            _ => {}
        }
    }

    /// Subdivision: "Subdivide" for a polygon mesh; rules, level, display and the sharpness of
    /// the selected edge (its two points) or point for a subdivision surface.
    /// Displacement along the normal for objects with a (u, v) domain: pattern, amplitude,
    /// frequency; each change one undo step.
    fn displacement_panel(&mut self, ui: &mut egui::Ui) {
        use crate::kernel::displace::{Displacement, Pattern};
        let Some(s) = self.selection.object else {
            return;
        };
        let object = &self.scene().objects[s];
        if object.geometry.displacement_domain().is_none() {
            return;
        }
        let before = object.displacement.clone();
        let size = object
            .bounds()
            .map_or(1.0, |(lo, hi)| lo.distance(hi).max(1e-9));
        ui.separator();
        ui.label(egui::RichText::new("Displacement").strong());
        let mut pattern = before.as_ref().map(|d| d.pattern);
        let mut options: Vec<(Option<Pattern>, &str)> = vec![(None, "none")];
        options.extend(Pattern::ALL.map(|p| (Some(p), p.label())));
        options.push((Some(Pattern::Image), "image…"));
        choice(ui, "height map", &mut pattern, &options);
        let image = before.as_ref().and_then(|d| d.image.clone());
        if pattern == Some(Pattern::Image) && image.is_none() {
            // The image comes from a file: the picker, then `use_height_image`.
            self.height_image_dialog();
            return;
        }
        let mut after = pattern.map(|p| {
            let (amplitude, frequency) = before
                .as_ref()
                .map_or((0.02 * size, 4.0), |d| (d.amplitude, d.frequency));
            Displacement {
                pattern: p,
                amplitude,
                frequency,
                image: if p == Pattern::Image {
                    image.clone()
                } else {
                    None
                },
            }
        });
        let mut reload = false;
        if let Some(d) = &mut after {
            ui.horizontal(|ui| {
                ui.label("amplitude");
                ui.add(egui::DragValue::new(&mut d.amplitude).speed(0.002 * size));
                ui.label("frequency");
                ui.add(
                    egui::DragValue::new(&mut d.frequency)
                        .range(0.25..=crate::kernel::displace::MAX_FREQUENCY)
                        .speed(0.1),
                );
            });
            if let Some(image) = &d.image {
                ui.horizontal(|ui| {
                    ui.label(format!(
                        "{} × {} pixels, tiled frequency × frequency times",
                        image.width(),
                        image.height()
                    ));
                    if ui.button("Other image…").clicked() {
                        reload = true;
                    }
                });
            }
            ui.label(
                egui::RichText::new(
                    "moves the surface along its normal by amplitude × a pattern over its \
                     (u, v) (an image: 2 × grey − 1, mid-grey stays put); shown with its own \
                     normals (no curvature); exported with 8 segments per cycle (an image: \
                     one per pixel)",
                )
                .weak(),
            );
        }
        if reload {
            self.height_image_dialog();
            return;
        }
        if after != before {
            self.apply(AppCommand::Edit(Command::SetDisplacement {
                object: s,
                displacement: after,
            }));
        }
    }

    /// Free-form deformation: *Add lattice* of chosen degrees around the selected object and
    /// the other objects ticked (one lattice they share); while it has one, *Reset* (the
    /// undisturbed lattice), *Release* (the undeformed objects) and *Apply* (baked into them,
    /// exactly or refitted within the tolerance; the status says which), each for every object
    /// sharing it. The lattice's points are the handles meanwhile.
    fn lattice_panel(&mut self, ui: &mut egui::Ui) {
        use crate::kernel::ffd::MAX_LATTICE_DEGREE;
        let Some(s) = self.selection.object else {
            return;
        };
        let current = self.scene().objects[s].lattice.clone();
        ui.separator();
        ui.label(egui::RichText::new("Lattice (free-form deformation)").strong());
        let mut degrees = self.lattice_degrees;
        let mut tolerance = self.lattice_tolerance;
        let (mut command, mut add, mut apply) = (None, false, false);
        match &current {
            None => {
                ui.horizontal(|ui| {
                    ui.label("degrees");
                    for d in &mut degrees {
                        ui.add(egui::DragValue::new(d).range(1..=MAX_LATTICE_DEGREE));
                    }
                });
                // Other objects the lattice goes around too.
                let others: Vec<(usize, String)> = self
                    .scene()
                    .objects
                    .iter()
                    .enumerate()
                    .filter(|(k, o)| *k != s && o.visible && o.lattice.is_none())
                    .map(|(k, o)| (k, o.name.clone()))
                    .collect();
                if !others.is_empty() {
                    ui.label("also around");
                    for (k, name) in others {
                        let mut on = self.lattice_also.contains(&k);
                        if ui.checkbox(&mut on, name).changed() {
                            if on {
                                self.lattice_also.insert(k);
                            } else {
                                self.lattice_also.remove(&k);
                            }
                        }
                    }
                }
                if ui
                    .button("Add lattice")
                    .on_hover_text(
                        "a trivariate Bézier lattice around the object (and those ticked): \
                         drag its points and the surfaces follow",
                    )
                    .clicked()
                {
                    add = true;
                }
            }
            Some(lattice) => {
                let [l, m, n] = lattice.degrees();
                let shared = self.scene().linked_lattices(s).len();
                ui.label(format!(
                    "degree ({l}, {m}, {n}), {} points: drag them like handles; the map's \
                     degree is {}{}",
                    lattice.points().len(),
                    lattice.total_degree(),
                    if shared > 1 {
                        format!("; shared by {shared} objects")
                    } else {
                        String::new()
                    }
                ));
                ui.horizontal(|ui| {
                    if ui.button("Reset").clicked()
                        && let Ok(reset) = lattice.reset()
                    {
                        command = Some(Some(reset));
                    }
                    if ui
                        .button("Release")
                        .on_hover_text("remove the lattice: the objects as they were")
                        .clicked()
                    {
                        command = Some(None);
                    }
                });
                ui.horizontal(|ui| {
                    ui.label("tolerance");
                    ui.add(
                        egui::DragValue::new(&mut tolerance)
                            .range(1e-6..=0.1)
                            .speed(1e-4),
                    )
                    .on_hover_text("for a refit: a share of the object's size");
                    if ui
                        .button("Apply")
                        .on_hover_text(
                            "bake the deformation into the objects: exact where the degree \
                             allows, else refitted within the tolerance",
                        )
                        .clicked()
                    {
                        apply = true;
                    }
                });
            }
        }
        self.lattice_degrees = degrees;
        self.lattice_tolerance = tolerance;
        if add {
            let mut objects = vec![s];
            objects.extend(self.lattice_also.iter().copied().filter(|&k| k != s));
            self.lattice_also.clear();
            self.add_lattice(&objects, degrees);
        } else if apply {
            self.apply(AppCommand::Edit(Command::ApplyLattice {
                object: s,
                tolerance,
            }));
        } else if let Some(lattice) = command {
            self.set_linked_lattice(s, lattice);
        }
    }

    /// A triangular Bézier patch: its degree and *Elevate degree* (the shape stays).
    fn triangle_panel(&mut self, ui: &mut egui::Ui) {
        let Some(s) = self.selection.object else {
            return;
        };
        let Some(patch) = self.scene().objects[s]
            .geometry
            .downcast_ref::<crate::kernel::triangle::TriangleBezier>()
        else {
            return;
        };
        let degree = patch.degree();
        ui.separator();
        ui.label(egui::RichText::new("Triangular patch").strong());
        ui.label(format!(
            "degree {degree}, {} points; drag points to shape it",
            patch.points().len()
        ));
        if ui
            .add_enabled(
                degree < crate::kernel::triangle::MAX_TRIANGLE_DEGREE,
                egui::Button::new("Elevate degree"),
            )
            .on_hover_text("one degree more, the same surface (more points to shape it with)")
            .clicked()
        {
            self.apply(AppCommand::Edit(Command::ElevateDegree {
                object: s,
                direction: crate::kernel::Direction::U,
            }));
        }
    }

    fn subdivision_panel(&mut self, ui: &mut egui::Ui) {
        let Some(s) = self.selection.object else {
            return;
        };
        let geometry = &self.scene().objects[s].geometry;
        let before = match geometry.downcast_ref::<SubdivObject>() {
            Some(surface) => surface.settings(),
            // A cage that is not subdivided yet (a polygon mesh).
            None if geometry.kind().cage().is_some() => {
                ui.separator();
                ui.label(egui::RichText::new("Subdivision").strong());
                self.subdivide_button(ui, s);
                return;
            }
            None => return,
        };
        ui.separator();
        ui.label(egui::RichText::new("Subdivision").strong());
        let mut settings = before.clone();
        subdivision_rules(ui, &mut settings.options);
        self.subdivision_display(ui, s, &mut settings);
        ui.add(egui::Slider::new(&mut settings.level, 0..=MAX_LEVEL).text("level"));
        self.sharpness_editor(ui, &mut settings);
        if settings != before {
            self.apply(AppCommand::Edit(Command::SetSubdivision {
                object: s,
                settings,
            }));
        }
    }

    /// Turns polygon mesh `s` into a Catmull-Clark surface of level 2.
    fn subdivide_button(&mut self, ui: &mut egui::Ui, s: usize) {
        if ui
            .button("Subdivide")
            .on_hover_text("show the mesh as a Catmull-Clark surface, level 2")
            .clicked()
        {
            let settings = SubdivSettings {
                options: Options::default(),
                level: 2,
                display: Display::Limit,
                tolerance: DEFAULT_TOLERANCE,
                creases: Vec::new(),
                corners: Vec::new(),
            };
            self.apply(AppCommand::Edit(Command::SetSubdivision {
                object: s,
                settings,
            }));
        }
    }

    /// The display (the limit, the refined mesh, a substitute the scheme has, the adaptive
    /// limit and its tolerance) and what it means.
    fn subdivision_display(&self, ui: &mut egui::Ui, s: usize, settings: &mut SubdivSettings) {
        // The efficient substitutes offered are those of the scheme they approximate.
        let mut displays = vec![
            (Display::Limit, "limit surface"),
            (Display::Refined, "refined mesh"),
        ];
        match settings.options.scheme {
            Scheme::CatmullClark => displays.extend([
                (Display::Acc, "ACC patches (bicubic + tangent patches)"),
                (Display::Gregory, "Gregory patches (ACC-2)"),
            ]),
            Scheme::Loop => displays.push((Display::PnTriangles, "PN triangles")),
            _ => {}
        }
        if !matches!(settings.options.scheme, Scheme::DooSabin | Scheme::Sqrt3) {
            displays.push((Display::Adaptive, "adaptive limit (refined where not flat)"));
        }
        if !displays.iter().any(|(d, _)| *d == settings.display) {
            // The scheme changed under a display it does not have: show the limit.
            settings.display = Display::Limit;
        }
        choice(ui, "display", &mut settings.display, &displays);
        if settings.display == Display::Adaptive {
            // The tolerance in percent of the cage's diagonal, on a logarithmic slider.
            let mut percent = settings.tolerance * 100.0;
            ui.add(
                egui::Slider::new(&mut percent, 0.005..=5.0)
                    .logarithmic(true)
                    .suffix(" %")
                    .text("flatness tolerance"),
            )
            .on_hover_text(
                "a piece is refined until its level's limit points lie within this distance \
                 (a share of the cage's diagonal) of its triangles, up to the level",
            );
            settings.tolerance = percent / 100.0;
            if let Some(surface) = self.scene().objects[s]
                .geometry
                .downcast_ref::<SubdivObject>()
                && let Ok(Some(layout)) = surface.adaptive_layout()
            {
                ui.label(
                    egui::RichText::new(format!(
                        "pieces per level: {}; refined again when a drag ends; \
                         shading \"Refinement level\" colours them",
                        layout.describe()
                    ))
                    .weak(),
                );
            }
        }
        if let Some(kind) = settings.display.substitute() {
            let scope = if kind.is_triangle() {
                "one cubic triangle per face through the limit points and normals"
            } else {
                "one patch per quad; faces at boundaries, creases and sharp points keep the \
                 exact limit"
            };
            ui.label(
                egui::RichText::new(format!(
                    "{}: an approximation of the limit, {scope}",
                    kind.label()
                ))
                .weak(),
            );
        }
    }

    /// The sharpness of the selected edge (two points) or point (one).
    fn sharpness_editor(&self, ui: &mut egui::Ui, settings: &mut SubdivSettings) {
        let points: Vec<u32> = self.selection.points.iter().map(|&p| p as u32).collect();
        match points[..] {
            [a, b] => {
                let mut sharpness = settings.crease(a, b);
                ui.add(
                    egui::Slider::new(&mut sharpness, 0.0..=10.0)
                        .text(format!("edge {a}-{b} sharpness")),
                );
                if sharpness != settings.crease(a, b) {
                    settings.set_crease(a, b, sharpness);
                }
            }
            [vertex] => {
                let mut sharpness = settings.corner(vertex);
                ui.add(
                    egui::Slider::new(&mut sharpness, 0.0..=10.0)
                        .text(format!("point {vertex} sharpness")),
                );
                if sharpness != settings.corner(vertex) {
                    settings.set_corner(vertex, sharpness);
                }
            }
            _ => {
                ui.label(
                    egui::RichText::new(
                        "select an edge's two points (or one point) to set its sharpness; \
                         0 removes it, 10 is infinitely sharp",
                    )
                    .weak(),
                );
            }
        }
        ui.label(format!(
            "{} creases, {} sharp points",
            settings.creases.len(),
            settings.corners.len()
        ));
    }

    /// Adaptive or fixed tessellation, the adaptive error and the quality factor.
    fn tessellation_panel(&mut self, ui: &mut egui::Ui) {
        let mut adaptive = self.view.adaptive;
        let mut tolerance = self.view.tolerance_px;
        let compute = self.gpu.as_ref().is_none_or(|g| g.sync.evaluates_on_gpu());
        ui.horizontal(|ui| {
            ui.add_enabled_ui(compute, |ui| {
                ui.selectable_value(&mut adaptive, true, "Adaptive")
                    .on_hover_text("segments per patch edge from its size and curvature on screen")
                    .on_disabled_hover_text("needs compute shaders (WebGPU, Vulkan, Metal, DX12)");
            });
            ui.selectable_value(&mut adaptive, false, "Fixed")
                .on_hover_text("every object's own segments × the quality");
        });
        if adaptive {
            ui.add(
                egui::Slider::new(&mut tolerance, TOLERANCE_RANGE)
                    .logarithmic(true)
                    .suffix(" px")
                    .text("error"),
            )
            .on_hover_text("the most the triangles may stray from the surface on screen");
        }
        if (adaptive, tolerance) != (self.view.adaptive, self.view.tolerance_px) {
            self.set_tessellation(adaptive, tolerance);
        }
        ui.label("Quality (× every object's segments)");
        let mut quality = self.view.quality;
        if ui
            .add(
                egui::Slider::new(&mut quality, QUALITY_RANGE)
                    .logarithmic(true)
                    .text("quality"),
            )
            .changed()
            && quality != self.view.quality
        {
            self.set_quality(quality);
        }
    }

    pub(super) fn controls(&mut self, ui: &mut egui::Ui) {
        ui.heading("knotwork");
        ui.label(egui::RichText::new("freeform surfaces on the GPU").weak());
        self.file_bar(ui);
        self.refresh_fields();
        ui.horizontal(|ui| {
            ui.label("Gizmo");
            for mode in super::GizmoMode::ALL {
                let key = match mode {
                    super::GizmoMode::Move => " (W)",
                    super::GizmoMode::Rotate => " (E)",
                    super::GizmoMode::Scale => " (R)",
                    super::GizmoMode::Off => "",
                };
                if ui
                    .selectable_label(self.gizmo_mode == mode, mode.name())
                    .on_hover_text(format!("{}{key}", mode.name()))
                    .clicked()
                {
                    self.gizmo_mode = mode;
                    self.redraw = true;
                }
            }
        });
        ui.horizontal(|ui| {
            ui.menu_button("View", |ui| self.view_menu(ui));
            if ui
                .button("Controls  (?)")
                .on_hover_text("the mouse and keyboard controls, over the viewport")
                .clicked()
            {
                self.show_help = !self.show_help;
            }
        });
        // The outliner first, so that it stays in view in a small window; every section folds.
        section(ui, "Objects", true, |ui| self.objects_panel(ui));
        if self.selection.object.is_some() {
            section(ui, "Selected object", true, |ui| {
                self.properties_panel(ui);
                self.surface_tools_panel(ui);
                self.trim_panel(ui);
                self.subdivision_panel(ui);
                self.triangle_panel(ui);
                self.displacement_panel(ui);
                self.lattice_panel(ui);
            });
        }
        if self.selection.object.is_some() {
            section(ui, "Operations", false, |ui| self.operations_panel(ui));
        }
        section(ui, "Curves", true, |ui| self.curves_panel(ui));
        section(ui, "Shading", true, |ui| self.shading_panel(ui));
        section(ui, "Analysis", true, |ui| self.analysis_panel(ui));
        section(ui, "Display", false, |ui| {
            let before = self.view.overlays;
            ui.checkbox(&mut self.view.overlays.surface, "Surface");
            ui.checkbox(&mut self.view.overlays.net, "Control net (selected object)");
            ui.checkbox(&mut self.view.overlays.points, "Control points");
            if self.view.overlays != before {
                self.redraw = true;
            }
            if ui.button("Frame scene  (F)").clicked() {
                self.frame_pending = true;
            }
            ui.checkbox(&mut self.continuous, "Redraw every frame");
        });
        section(ui, "Tessellation", false, |ui| self.tessellation_panel(ui));
        section(ui, "Scene and GPU", false, |ui| {
            self.info_grid(ui);
            ui.separator();
            ui.label("GPU time, last frame");
            let ms = |v: Option<f64>| v.map_or("–".to_owned(), |v| format!("{v:.3} ms"));
            if self.gpu.as_ref().is_some_and(|g| g.timer.is_some()) {
                ui.label(format!("evaluate  {}", ms(self.status.gpu_eval_ms)));
                ui.label(format!("draw      {}", ms(self.status.gpu_render_ms)));
            } else {
                ui.label(egui::RichText::new("no timestamp queries on this device").weak());
            }
            ui.label(format!(
                "frame interval  {}",
                ms(self.status.frame_interval_ms)
            ));
            ui.label(format!("frames drawn  {}", self.status.frames));
        });
        if let Some(notice) = self.status.notice.clone() {
            ui.separator();
            ui.colored_label(egui::Color32::from_rgb(240, 200, 90), notice);
        }
        if let Some(error) = self.status.error.clone() {
            ui.separator();
            ui.colored_label(egui::Color32::from_rgb(255, 110, 100), error);
            if ui.small_button("Dismiss").clicked() {
                self.status.error = None;
            }
        }
    }
}

/// A panel section under a header that folds (`open`: unfolded at first).
fn section(ui: &mut egui::Ui, title: &str, open: bool, body: impl FnOnce(&mut egui::Ui)) {
    egui::CollapsingHeader::new(egui::RichText::new(title).strong())
        .default_open(open)
        .show(ui, body);
}

/// The colour ramp as a bar with its low, middle and high values.
/// A direction as three numbers with buttons for the axes.
pub(super) fn direction_editor(ui: &mut egui::Ui, label: &str, direction: &mut [f64; 3]) {
    ui.horizontal(|ui| {
        ui.label(label);
        for c in direction.iter_mut() {
            ui.add(egui::DragValue::new(c).speed(0.02).max_decimals(3));
        }
    });
    ui.horizontal(|ui| {
        for (name, d) in [
            ("+X", [1.0, 0.0, 0.0]),
            ("+Y", [0.0, 1.0, 0.0]),
            ("+Z", [0.0, 0.0, 1.0]),
            ("−Z", [0.0, 0.0, -1.0]),
        ] {
            if ui.small_button(name).clicked() {
                *direction = d;
            }
        }
    });
}

/// The colour ramp from `lo` to `hi` with its numbers (in degrees where `degrees`).
fn legend(ui: &mut egui::Ui, lo: f64, hi: f64, unit: &str) {
    let width = ui.available_width().min(240.0);
    let (rect, _) = ui.allocate_exact_size(egui::vec2(width, 14.0), egui::Sense::hover());
    let mut mesh = egui::Mesh::default();
    let stops = CURVATURE_RAMP.len();
    for (k, stop) in CURVATURE_RAMP.iter().enumerate() {
        let x = rect.left() + rect.width() * k as f32 / (stops - 1) as f32;
        let color = egui::Rgba::from_rgb(stop[0], stop[1], stop[2]).into();
        mesh.colored_vertex(egui::pos2(x, rect.top()), color);
        mesh.colored_vertex(egui::pos2(x, rect.bottom()), color);
        if k > 0 {
            let i = (2 * k) as u32;
            mesh.add_triangle(i - 2, i - 1, i);
            mesh.add_triangle(i - 1, i + 1, i);
        }
    }
    ui.painter().add(egui::Shape::mesh(mesh));
    ui.horizontal(|ui| {
        let step = (hi - lo).abs();
        ui.label(plain_number(lo, step));
        ui.add_space((width - 180.0).max(4.0) / 2.0);
        ui.label(plain_number(0.5 * (lo + hi), step));
        ui.add_space((width - 180.0).max(4.0) / 2.0);
        ui.label(format!("{}{unit}", plain_number(hi, step)));
    });
}

/// `value` as a plain decimal ("−2.33", "0.0125", "1250") with as many decimals as the
/// `spread` of the numbers shown beside it needs (three significant digits of it); beyond
/// 10⁶ or below 10⁻⁴ (and not zero) in scientific notation ("1.20e−6").
pub fn plain_number(value: f64, spread: f64) -> String {
    if !value.is_finite() {
        return format!("{value}");
    }
    let magnitude = value.abs().max(spread.abs());
    if magnitude == 0.0 {
        return "0".into();
    }
    if !(1e-4..1e6).contains(&magnitude) {
        let exponent = value.abs().max(1e-300).log10().floor() as i32;
        let mantissa = value / 10f64.powi(exponent);
        return format!("{mantissa:.2}e{exponent}").replace('-', "−");
    }
    let reference = if spread > 0.0 { spread } else { magnitude };
    let decimals = (2 - reference.log10().floor() as i32).clamp(0, 6) as usize;
    let text = format!("{value:.decimals$}").replace('-', "−");
    if text
        .trim_start_matches('−')
        .chars()
        .all(|c| c == '0' || c == '.')
    {
        "0".into()
    } else {
        text
    }
}

/// A combo box labelled `label` choosing `value` among `options` (value, text).
pub(super) fn choice<T: PartialEq + Copy>(
    ui: &mut egui::Ui,
    label: &str,
    value: &mut T,
    options: &[(T, &str)],
) {
    let current = options
        .iter()
        .find(|(v, _)| v == value)
        .map_or("", |(_, text)| *text);
    egui::ComboBox::new(label, label)
        .selected_text(current)
        .show_ui(ui, |ui| {
            for &(option, text) in options {
                ui.selectable_value(value, option, text);
            }
        });
}

/// A subdivision surface's rules: the scheme, the boundary rule and the creasing method.
fn subdivision_rules(ui: &mut egui::Ui, options: &mut Options) {
    choice(
        ui,
        "scheme",
        &mut options.scheme,
        &[
            (Scheme::CatmullClark, "Catmull-Clark"),
            (Scheme::Loop, "Loop (triangles)"),
            (Scheme::DooSabin, "Doo-Sabin"),
            (Scheme::Sqrt3, "√3 Kobbelt (triangles)"),
            (
                Scheme::Butterfly,
                "modified butterfly (triangles, interpolating)",
            ),
        ],
    );
    if !options.scheme.has_creases() {
        ui.label(
            egui::RichText::new(format!(
                "{} has no crease rules: creases and sharp points apply under \
                     Catmull-Clark and Loop",
                options.scheme.label()
            ))
            .weak(),
        );
    }
    choice(
        ui,
        "boundary",
        &mut options.boundary,
        &[
            (Boundary::EdgeOnly, "edge only"),
            (Boundary::EdgeAndCorner, "edge and corner"),
        ],
    );
    choice(
        ui,
        "creasing",
        &mut options.creasing,
        &[
            (Creasing::Uniform, "uniform"),
            (Creasing::Chaikin, "Chaikin"),
        ],
    );
}

#[cfg(test)]
mod tests {
    use super::plain_number;

    #[test]
    fn legend_numbers_are_plain_decimals_with_the_digits_their_spread_needs() {
        assert_eq!(plain_number(-2.3321, 4.0), "−2.33");
        assert_eq!(plain_number(0.25, 0.5), "0.250");
        assert_eq!(plain_number(1250.4, 2000.0), "1250");
        assert_eq!(plain_number(0.01234, 0.02), "0.0123");
        assert_eq!(plain_number(0.0, 0.5), "0");
        assert_eq!(plain_number(-1e-9, 0.5), "0");
        assert_eq!(plain_number(1.2e-6, 1e-6), "1.20e−6");
        assert_eq!(plain_number(3.0e7, 1e7), "3.00e7");
    }
}
