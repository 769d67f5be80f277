//! The Features row of the Operations section: fillets, chamfers and shells of the selected
//! closed body ([`crate::ops::features`]), their size, and the edges they take picked in the
//! viewport (*Pick*: a click near an edge picks it, Shift adds more, a click on a face away
//! from edges picks the face, for a shell; the picked edges are drawn, and the one under the
//! cursor); and, for a feature made with history, its value, which edits it in place (one
//! undo step, [`Command::EditRecipe`]), in the row or, for a fillet or chamfer of picked
//! edges, by a handle dragged in the viewport.

use eframe::egui;
use glam::{DVec2, DVec3};

use super::KnotworkApp;
use crate::doc::Command;
use crate::ops::features::{ChamferEdges, FEATURE_TOLERANCE, FilletEdges, Shell};
use crate::scene::operation::Operation;

/// How near the cursor an edge must pass to be picked (points).
const PICK_RADIUS: f64 = 10.0;

/// What the cached edges were made from: the object, and the document's undo and redo
/// depths.
type EdgesKey = (usize, usize, usize);

/// The Features row's state.
#[derive(Default)]
pub(super) struct FeatureState {
    /// The radius, distance or wall thickness (0: not set yet, a fiftieth of the scene's
    /// size).
    size: f64,
    /// A feature's value being dragged or typed, until it is let go.
    edit: Option<f64>,
    /// Whether clicks in the viewport pick edges (and faces) of the selected body.
    picking: bool,
    /// The points picked: on edges, or on faces.
    picks: Vec<DVec3>,
    /// The selected body's shared edges as polylines, and what they were made from.
    edges: Option<(EdgesKey, Vec<Vec<DVec3>>)>,
    /// The edge under the cursor.
    hover: Option<usize>,
    /// A fillet's radius or a chamfer's distance while its handle is dragged.
    handle: Option<f64>,
    /// A fillet's radii at edge ends being dragged or typed, one per radius set.
    edit_ends: Vec<Option<f64>>,
}

/// How far right of its edge point a feature's handle sits at a value of 0 (points).
const HANDLE_GAP: f64 = 14.0;

/// The nearest point to `p` on the segment from `a` to `b` (2D), as a fraction along it, and
/// its distance.
fn along_segment(a: DVec2, b: DVec2, p: DVec2) -> (f64, f64) {
    let d = b - a;
    let t = ((p - a).dot(d) / d.length_squared().max(f64::MIN_POSITIVE)).clamp(0.0, 1.0);
    (t, p.distance(a + d * t))
}

impl KnotworkApp {
    /// The selected closed body's edges as polylines (made again when the body or the
    /// document changed).
    fn feature_edges(&mut self) -> Option<&[Vec<DVec3>]> {
        let k = self.selection.object?;
        let key = (
            k,
            self.doc.history.undo_depth(),
            self.doc.history.redo_depth(),
        );
        if self.features.edges.as_ref().map(|(made, _)| *made) != Some(key) {
            let body = self.doc.scene.objects.get(k)?.body()?;
            let topology = body.topology.as_ref()?;
            let size = crate::doc::surface_ops::scene_size(&self.doc.scene);
            let lines = topology
                .shared
                .iter()
                .filter_map(|s| {
                    crate::kernel::join::edge_polyline(&body.faces, s.a, 1e-3 * size).ok()
                })
                .collect();
            self.features.edges = Some((key, lines));
        }
        self.features
            .edges
            .as_ref()
            .map(|(_, lines)| lines.as_slice())
    }

    /// The edge of the selected body nearest `cursor` (viewport pixels) within
    /// [`PICK_RADIUS`], and the point on it there.
    fn feature_edge_at(&mut self, cursor: DVec2) -> Option<(usize, DVec3)> {
        let view = self.pick_view?;
        let lines = self.feature_edges()?;
        let mut best: Option<(f64, usize, DVec3)> = None;
        for (k, line) in lines.iter().enumerate() {
            for pair in line.windows(2) {
                let (Some(a), Some(b)) = (view.project(pair[0]), view.project(pair[1])) else {
                    continue;
                };
                let (t, distance) = along_segment(a.screen, b.screen, cursor);
                if distance <= PICK_RADIUS && best.is_none_or(|(d, _, _)| distance < d) {
                    best = Some((distance, k, pair[0].lerp(pair[1], t)));
                }
            }
        }
        best.map(|(_, k, p)| (k, p))
    }

    /// A click while picking: the edge near it (or the face under it) picked, added to the
    /// picks with Shift. False when not picking.
    pub(super) fn feature_click(
        &mut self,
        cursor: DVec2,
        shift: bool,
        face: Option<DVec3>,
    ) -> bool {
        if !self.features.picking || self.selection.object.is_none() {
            return false;
        }
        let picked = self.feature_edge_at(cursor).map(|(_, p)| p).or(face);
        if let Some(p) = picked {
            if !shift {
                self.features.picks.clear();
            }
            self.features.picks.push(p);
            self.redraw = true;
        }
        true
    }

    /// The edge under the cursor while picking, drawn lighter.
    pub(super) fn feature_hover(&mut self, cursor: Option<DVec2>) {
        let hover = if self.features.picking {
            cursor.and_then(|c| self.feature_edge_at(c)).map(|(k, _)| k)
        } else {
            None
        };
        if hover != self.features.hover {
            self.features.hover = hover;
            self.redraw = true;
        }
    }

    /// The picked edges (and the one under the cursor) over the viewport.
    pub(super) fn paint_feature_edges(&mut self, ui: &egui::Ui) {
        if !self.features.picking {
            return;
        }
        let (Some(view), rect) = (self.pick_view, self.viewport_rect) else {
            return;
        };
        let picks = self.features.picks.clone();
        let hover = self.features.hover;
        let Some(lines) = self.feature_edges() else {
            return;
        };
        let nearest = |p: DVec3| {
            (0..lines.len()).min_by(|&i, &j| {
                let d = |k: usize| {
                    lines[k]
                        .iter()
                        .map(|q| q.distance(p))
                        .fold(f64::INFINITY, f64::min)
                };
                d(i).total_cmp(&d(j))
            })
        };
        let picked: Vec<usize> = picks.iter().filter_map(|&p| nearest(p)).collect();
        let painter = ui.painter().with_clip_rect(rect);
        let origin = rect.min.to_vec2();
        let screen = |p: DVec3| {
            view.project(p)
                .map(|q| egui::pos2(q.screen.x as f32, q.screen.y as f32) + origin)
        };
        let accent = egui::Color32::from_rgb(255, 160, 50);
        for (k, line) in lines.iter().enumerate() {
            let stroke = if picked.contains(&k) {
                egui::Stroke::new(3.0, accent)
            } else if hover == Some(k) {
                egui::Stroke::new(2.0, accent.gamma_multiply(0.6))
            } else {
                continue;
            };
            let points: Vec<egui::Pos2> = line.iter().filter_map(|&p| screen(p)).collect();
            painter.add(egui::Shape::line(points, stroke));
        }
        for &p in &picks {
            if let Some(q) = screen(p) {
                painter.circle_filled(q, 3.0, accent);
            }
        }
    }

    /// For a selected fillet or chamfer made with history on picked edges, a handle right of
    /// its first picked point, as far as the radius (or distance) looks on screen there:
    /// dragged sideways it sets the value, shown beside it, and letting go edits the feature
    /// in place (one undo step), as the row's value does.
    pub(super) fn feature_handle(&mut self, ui: &egui::Ui) {
        let (Some(k), Some(view), rect) =
            (self.selection.object, self.pick_view, self.viewport_rect)
        else {
            return;
        };
        let Some(recipe) = self.scene().objects.get(k).and_then(|o| o.recipe.clone()) else {
            return;
        };
        let operation = &recipe.operation;
        let (value, near, label) = if let Some(p) = operation.params::<FilletEdges>() {
            (p.radius, p.near.first().copied(), "r")
        } else if let Some(p) = operation.params::<ChamferEdges>() {
            (p.distance, p.near.first().copied(), "d")
        } else {
            return;
        };
        let Some(anchor) = near.map(DVec3::from_array) else {
            return;
        };
        let Some(centre) = view.project(anchor) else {
            return;
        };
        // Points per unit length at the anchor: the longest image of a short step along an
        // axis.
        let step = value.abs().max(1e-9);
        let scale = [DVec3::X, DVec3::Y, DVec3::Z]
            .iter()
            .filter_map(|&e| view.project(anchor + e * step))
            .map(|q| q.screen.distance(centre.screen) / step)
            .fold(0.0, f64::max);
        if !(scale.is_finite() && scale > 0.0) {
            return;
        }
        let origin = rect.min.to_vec2();
        let at_anchor = egui::pos2(centre.screen.x as f32, centre.screen.y as f32) + origin;
        let shown = self.features.handle.unwrap_or(value);
        let at = at_anchor + egui::vec2((HANDLE_GAP + shown * scale) as f32, 0.0);
        let id = ui.scope_id().with("feature handle");
        let response = ui.interact(
            egui::Rect::from_center_size(at, egui::vec2(16.0, 16.0)),
            id,
            egui::Sense::drag(),
        );
        response
            .widget_info(|| egui::WidgetInfo::labeled(egui::Role::Slider, true, "Feature handle"));
        if response.dragged()
            && let Some(pointer) = response.interact_pointer_pos()
        {
            let v = (f64::from(pointer.x - at_anchor.x) - HANDLE_GAP) / scale;
            self.features.handle = Some(v.max(1e-3 * value.abs()));
            self.redraw = true;
        }
        let accent = egui::Color32::from_rgb(255, 160, 50);
        let painter = ui.painter().with_clip_rect(rect);
        painter.line_segment([at_anchor, at], egui::Stroke::new(1.5, accent));
        painter.circle_filled(at_anchor, 3.0, accent);
        painter.circle(
            at,
            if response.hovered() || response.dragged() {
                7.0
            } else {
                5.0
            },
            egui::Color32::WHITE,
            egui::Stroke::new(2.0, accent),
        );
        painter.text(
            at + egui::vec2(10.0, -10.0),
            egui::Align2::LEFT_BOTTOM,
            format!("{label} {shown:.4}"),
            egui::FontId::proportional(13.0),
            egui::Color32::WHITE,
        );
        if response.drag_stopped()
            && let Some(v) = self.features.handle.take()
            && v != value
        {
            let operation = if let Some(p) = operation.params::<FilletEdges>() {
                Operation::new(FilletEdges {
                    radius: v,
                    ..p.clone()
                })
            } else if let Some(p) = operation.params::<ChamferEdges>() {
                Operation::new(ChamferEdges {
                    distance: v,
                    ..p.clone()
                })
            } else {
                return;
            };
            self.execute(Command::EditRecipe {
                object: k,
                operation,
            });
        }
    }

    /// The Features row, for a selected closed body: a size, *Pick* and the buttons that
    /// fillet or chamfer the picked edges (every edge when none is picked) with it or shell
    /// the body to it (inward), the picked faces left open; and for a fillet, chamfer or
    /// shell made with history, its value, which edits it in place (one undo step). False
    /// where neither applies.
    pub(super) fn features_row(&mut self, ui: &mut egui::Ui, selection: &[usize]) -> bool {
        let Some(&k) = selection.first() else {
            return false;
        };
        let Some(object) = self.scene().objects.get(k) else {
            return false;
        };
        let recipe = object.recipe.clone();
        let closed = object.body().is_some_and(|b| b.closed());
        let mut command = None;
        // A feature's value, edited in place when the drag or the typing ends.
        if let Some(recipe) = &recipe {
            let operation = &recipe.operation;
            let editing = &mut self.features.edit;
            let edited = if let Some(p) = operation.params::<FilletEdges>() {
                let mut p = p.clone();
                let mut changed = value_row(ui, "Fillet radius", &mut p.radius, editing);
                // Radii at edge ends: each a row; a picked edge's fillet can be made to vary.
                let ends = &mut self.features.edit_ends;
                ends.resize(p.radius_at.len(), None);
                let mut dropped = None;
                for (i, (at, editing)) in p.radius_at.iter_mut().zip(ends.iter_mut()).enumerate() {
                    ui.horizontal(|ui| {
                        changed |=
                            value_row(ui, &format!("Radius at end {}", i + 1), &mut at[3], editing);
                        if ui
                            .small_button("×")
                            .on_hover_text("take this radius out")
                            .clicked()
                        {
                            dropped = Some(i);
                        }
                    });
                }
                if let Some(i) = dropped {
                    p.radius_at.remove(i);
                    changed = true;
                }
                if let Some(&first) = p.near.first()
                    && ui
                        .small_button("Vary radius")
                        .on_hover_text(
                            "set the radius at the end of the first picked edge nearest where it \
                             was picked; the radius then runs linearly to the other end",
                        )
                        .clicked()
                {
                    p.radius_at
                        .push([first[0], first[1], first[2], 2.0 * p.radius]);
                    changed = true;
                }
                changed.then(|| Operation::new(p))
            } else if let Some(p) = operation.params::<ChamferEdges>() {
                let mut p = p.clone();
                value_row(ui, "Chamfer distance", &mut p.distance, editing)
                    .then(|| Operation::new(p))
            } else if let Some(p) = operation.params::<Shell>() {
                let mut p = p.clone();
                value_row(ui, "Shell thickness", &mut p.thickness, editing)
                    .then(|| Operation::new(p))
            } else {
                None
            };
            if let Some(operation) = edited {
                command = Some(Command::EditRecipe {
                    object: k,
                    operation,
                });
            }
        }
        if !closed {
            self.features.picking = false;
        }
        if closed {
            if !(self.features.size > 0.0) {
                self.features.size = 0.02 * crate::doc::surface_ops::scene_size(self.scene());
            }
            let size = self.features.size;
            let keep = self.operations_keep_history;
            let near: Vec<[f64; 3]> = self.features.picks.iter().map(|p| p.to_array()).collect();
            ui.horizontal_wrapped(|ui| {
                ui.label("Features:");
                ui.add(
                    egui::DragValue::new(&mut self.features.size)
                        .speed(0.01 * size)
                        .range(1e-9..=f64::MAX),
                )
                .on_hover_text("the radius, chamfer distance or wall thickness");
                ui.toggle_value(&mut self.features.picking, "Pick")
                    .on_hover_text(
                        "click near edges to pick them (Shift adds more), or on a face to leave \
                         it open in a shell; none picked: every edge",
                    );
                if !self.features.picks.is_empty() {
                    ui.weak(format!("{} picked", self.features.picks.len()));
                    if ui.small_button("Clear").clicked() {
                        self.features.picks.clear();
                    }
                }
            });
            ui.horizontal_wrapped(|ui| {
                let apply = |operation| Command::Apply {
                    operation,
                    keep_history: keep,
                };
                let object = k.into();
                let which = if near.is_empty() {
                    "every"
                } else {
                    "each picked"
                };
                if ui
                    .button("Fillet edges")
                    .on_hover_text(format!(
                        "round {which} edge with a rolling ball of this radius"
                    ))
                    .clicked()
                {
                    command = Some(apply(Operation::new(FilletEdges {
                        object,
                        radius: size,
                        near: near.clone(),
                        radius_at: Vec::new(),
                        tolerance: FEATURE_TOLERANCE,
                    })));
                }
                if ui
                    .button("Chamfer edges")
                    .on_hover_text(format!("cut {which} edge back this far on both faces"))
                    .clicked()
                {
                    command = Some(apply(Operation::new(ChamferEdges {
                        object,
                        distance: size,
                        other: None,
                        near: near.clone(),
                        tolerance: FEATURE_TOLERANCE,
                    })));
                }
                if ui
                    .button("Shell")
                    .on_hover_text(
                        "hollow the body to this wall thickness, inside it; the faces picked \
                         are left open",
                    )
                    .clicked()
                {
                    command = Some(apply(Operation::new(Shell {
                        object,
                        thickness: -size,
                        open: near.clone(),
                        tolerance: FEATURE_TOLERANCE,
                    })));
                }
            });
        }
        let shown = closed || recipe.is_some();
        if let Some(command) = command {
            self.features.picks.clear();
            self.features.picking = false;
            self.execute(command);
        }
        shown
    }
}

/// A labelled value of a feature made with history, `editing` the value being dragged or
/// typed (kept between frames); true, with `value` the new one, when the drag or the typing
/// ends on a change.
fn value_row(ui: &mut egui::Ui, label: &str, value: &mut f64, editing: &mut Option<f64>) -> bool {
    ui.horizontal(|ui| {
        ui.label(label);
        let mut shown = editing.unwrap_or(*value);
        let speed = 0.01 * shown.abs().max(1e-6);
        let response = ui.add(egui::DragValue::new(&mut shown).speed(speed));
        if response.changed() {
            *editing = Some(shown);
        }
        let done = response.drag_stopped() || response.lost_focus();
        match editing.take() {
            Some(v) if done => {
                let changed = v != *value;
                *value = v;
                changed
            }
            other => {
                *editing = other;
                false
            }
        }
    })
    .inner
}
