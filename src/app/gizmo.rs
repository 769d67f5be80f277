//! The transform gizmo on the selection (the selected control points, or every point of the
//! selected object when none is selected), drawn over the viewport at the points' centroid:
//! - **move**: an arrow per axis (drag along it) and a square per plane (drag in it);
//! - **rotate**: a ring per axis (drag around it; with grid snapping on, in steps of 15°);
//! - **scale**: a box at each axis end (scale along it) and the centre disc (uniformly).
//!
//! W, E and R choose move, rotate and scale, as in most 3D tools. A gizmo drag is the same
//! transient edit as a handle drag (one undo step, Esc cancels), so only the affected patches
//! are re-evaluated.

use eframe::egui::{self, Color32, Pos2, Stroke};
use glam::{DAffine3, DVec2, DVec3};

use super::{AppCommand, DragHandle, DragStep, KnotworkApp};
use crate::view::pick::{self, Constraint};

/// What the gizmo does.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum GizmoMode {
    Off,
    #[default]
    Move,
    Rotate,
    Scale,
}

impl GizmoMode {
    pub const ALL: [GizmoMode; 4] = [
        GizmoMode::Off,
        GizmoMode::Move,
        GizmoMode::Rotate,
        GizmoMode::Scale,
    ];

    /// "off", "move", "rotate", "scale".
    pub fn name(self) -> &'static str {
        match self {
            GizmoMode::Off => "off",
            GizmoMode::Move => "move",
            GizmoMode::Rotate => "rotate",
            GizmoMode::Scale => "scale",
        }
    }

    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|m| m.name() == name)
    }
}

/// One part of the gizmo.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum GizmoHandle {
    /// Move along axis 0, 1, 2.
    Axis(usize),
    /// Move in the plane normal to the axis.
    Plane(usize),
    /// Rotate about the axis.
    Ring(usize),
    /// Scale along the axis.
    ScaleAxis(usize),
    ScaleUniform,
}

impl GizmoHandle {
    /// What a drag of this part does, for the viewport's hint ("along the X axis").
    pub fn label(self) -> String {
        let axis = |a: usize| ["X", "Y", "Z"][a.min(2)];
        match self {
            GizmoHandle::Axis(a) => format!("gizmo: along the {} axis", axis(a)),
            GizmoHandle::Plane(a) => format!("gizmo: in the plane normal to {}", axis(a)),
            GizmoHandle::Ring(a) => format!("gizmo: rotating about {}", axis(a)),
            GizmoHandle::ScaleAxis(a) => format!("gizmo: scaling along {}", axis(a)),
            GizmoHandle::ScaleUniform => "gizmo: scaling uniformly".into(),
        }
    }
}

impl GizmoDrag {
    /// The part being dragged.
    pub fn handle(&self) -> GizmoHandle {
        self.handle
    }
}

/// A gizmo drag under way.
#[derive(Debug, Clone)]
pub(super) struct GizmoDrag {
    handle: GizmoHandle,
    pivot: DVec3,
    /// Where the cursor's ray met the handle's axis or plane at the press.
    grab: DVec3,
    /// The pivot and the press on the screen (viewport pixels), for uniform scaling.
    pivot_screen: DVec2,
    press_screen: DVec2,
    starts: Vec<(usize, DVec3)>,
}

/// Screen size of the gizmo's arms, in logical pixels.
const ARM: f64 = 90.0;
/// Pixels around the pivot where the arrows and rings do not grab.
const PIVOT_CLEARANCE: f64 = 14.0;
/// How close (pixels) the cursor must be to grab a part.
const GRAB: f64 = 7.0;
const AXIS_COLORS: [Color32; 3] = [
    Color32::from_rgb(230, 70, 60),
    Color32::from_rgb(110, 200, 70),
    Color32::from_rgb(80, 140, 240),
];
const HOVER: Color32 = Color32::from_rgb(255, 220, 90);

fn unit(axis: usize) -> DVec3 {
    DVec3::AXES[axis]
}

fn to_pos(rect: egui::Rect, p: DVec2) -> Pos2 {
    Pos2::new(rect.left() + p.x as f32, rect.top() + p.y as f32)
}

fn segment_distance(p: DVec2, a: DVec2, b: DVec2) -> f64 {
    crate::kernel::vector::distance_to_segment(p, a, b)
}

impl KnotworkApp {
    /// The object and points the gizmo transforms, and their centroid.
    fn gizmo_target(&self) -> Option<(usize, Vec<usize>, DVec3)> {
        if self.gizmo_mode == GizmoMode::Off || self.trim_drawing.is_some() {
            return None;
        }
        let s = self.selection.object?;
        let object = self.scene().objects.get(s)?;
        if !object.visible {
            return None;
        }
        let points = object.control_points();
        let chosen: Vec<usize> = if self.selection.points.is_empty() {
            (0..points.len()).collect()
        } else {
            self.selection.points.iter().copied().collect()
        };
        if chosen.is_empty() {
            return None;
        }
        let centroid = chosen.iter().map(|&k| points[k]).sum::<DVec3>() / chosen.len() as f64;
        Some((s, chosen, centroid))
    }

    /// World length of `ARM` pixels at `pivot`.
    fn gizmo_length(&self, pivot: DVec3) -> Option<f64> {
        let view = self.pick_view?;
        let (right, _, _) = self.view.camera.axes();
        let a = view.project(pivot)?.screen;
        let b = view.project(pivot + right.as_dvec3())?.screen;
        let per_unit = a.distance(b);
        (per_unit > 1e-9).then(|| ARM / per_unit)
    }

    /// The gizmo's parts as screen polylines (viewport pixels): each handle and the points
    /// drawn for it.
    fn gizmo_parts(&self, pivot: DVec3) -> Vec<(GizmoHandle, Vec<DVec2>)> {
        let (Some(view), Some(length)) = (self.pick_view, self.gizmo_length(pivot)) else {
            return Vec::new();
        };
        let screen = |p: DVec3| view.project(p).map(|p| p.screen);
        let mut parts = Vec::new();
        for axis in 0..3 {
            let e = unit(axis);
            let (e1, e2) = (unit((axis + 1) % 3), unit((axis + 2) % 3));
            let polyline = |points: &[DVec3]| {
                points
                    .iter()
                    .map(|&p| screen(p))
                    .collect::<Option<Vec<_>>>()
            };
            let part = match self.gizmo_mode {
                GizmoMode::Move => {
                    let arrow = polyline(&[pivot, pivot + length * e]);
                    let square = polyline(&[
                        pivot + 0.25 * length * (e1 + e2),
                        pivot + 0.25 * length * e1 + 0.45 * length * e2,
                        pivot + 0.45 * length * (e1 + e2),
                        pivot + 0.45 * length * e1 + 0.25 * length * e2,
                        pivot + 0.25 * length * (e1 + e2),
                    ]);
                    vec![
                        (GizmoHandle::Axis(axis), arrow),
                        (GizmoHandle::Plane(axis), square),
                    ]
                }
                GizmoMode::Rotate => {
                    let ring: Vec<DVec3> = (0..=64)
                        .map(|k| {
                            let t = std::f64::consts::TAU * f64::from(k) / 64.0;
                            pivot + 0.9 * length * (t.cos() * e1 + t.sin() * e2)
                        })
                        .collect();
                    vec![(GizmoHandle::Ring(axis), polyline(&ring))]
                }
                GizmoMode::Scale => vec![(
                    GizmoHandle::ScaleAxis(axis),
                    polyline(&[pivot, pivot + length * e]),
                )],
                GizmoMode::Off => Vec::new(),
            };
            parts.extend(part.into_iter().filter_map(|(h, p)| p.map(|p| (h, p))));
        }
        if self.gizmo_mode == GizmoMode::Scale
            && let Some(c) = screen(pivot)
        {
            parts.push((GizmoHandle::ScaleUniform, vec![c]));
        }
        parts
    }

    /// The gizmo's parts as drawn now, in window coordinates (for scripts and tests).
    pub fn gizmo_screen_parts(&self) -> Vec<(GizmoHandle, Vec<Pos2>)> {
        let Some((_, _, pivot)) = self.gizmo_target() else {
            return Vec::new();
        };
        self.gizmo_parts(pivot)
            .into_iter()
            .map(|(h, points)| {
                (
                    h,
                    points
                        .iter()
                        .map(|&p| to_pos(self.viewport_rect, p))
                        .collect(),
                )
            })
            .collect()
    }

    /// The part of `parts` (the gizmo at `pivot`) under `cursor` (viewport pixels), nearest
    /// first.
    fn gizmo_handle_at(
        &self,
        pivot: DVec3,
        parts: &[(GizmoHandle, Vec<DVec2>)],
        cursor: DVec2,
    ) -> Option<GizmoHandle> {
        // The pivot itself stays free for the control point drawn there (a free drag).
        let near_pivot = self
            .pick_view
            .and_then(|v| v.project(pivot))
            .is_some_and(|p| p.screen.distance(cursor) < PIVOT_CLEARANCE);
        let mut best: Option<(f64, GizmoHandle)> = None;
        for (handle, points) in parts {
            let handle = *handle;
            if near_pivot && handle != GizmoHandle::ScaleUniform {
                continue;
            }
            let distance = match handle {
                GizmoHandle::Plane(_) => {
                    if crate::kernel::trim::polygon_contains(&points[..4], cursor) {
                        0.0
                    } else {
                        f64::INFINITY
                    }
                }
                GizmoHandle::ScaleAxis(_) => {
                    points.last().map_or(f64::INFINITY, |e| e.distance(cursor))
                }
                GizmoHandle::ScaleUniform => (points[0].distance(cursor) - 6.0).max(0.0),
                _ => points
                    .windows(2)
                    .map(|w| segment_distance(cursor, w[0], w[1]))
                    .fold(f64::INFINITY, f64::min),
            };
            if distance <= GRAB && best.is_none_or(|(d, _)| distance < d) {
                best = Some((distance, handle));
            }
        }
        best.map(|(_, h)| h)
    }

    /// Starts a gizmo drag if the press at `cursor` (viewport pixels) is on a part; true if so.
    pub(super) fn begin_gizmo_drag(&mut self, cursor: DVec2) -> bool {
        let (Some((object, points, pivot)), Some(view)) = (self.gizmo_target(), self.pick_view)
        else {
            return false;
        };
        let parts = self.gizmo_parts(pivot);
        let Some(handle) = self.gizmo_handle_at(pivot, &parts, cursor) else {
            return false;
        };
        self.apply(AppCommand::Drag(DragStep::Begin {
            object,
            points: points.clone(),
        }));
        if self.doc.drag().is_none() {
            return true;
        }
        let all = self.scene().objects[object].control_points();
        let starts = points.iter().map(|&k| (k, all[k])).collect();
        let grab = self.gizmo_point(handle, pivot, cursor);
        self.gizmo_drag = Some(GizmoDrag {
            handle,
            pivot,
            grab,
            pivot_screen: view.project(pivot).map_or(cursor, |p| p.screen),
            press_screen: cursor,
            starts,
        });
        // The handle drag's bookkeeping (end, cancel) is shared.
        self.drag = Some(DragHandle {
            anchor: pivot,
            partners: Vec::new(),
            tolerance: 0.0,
            falloff: Vec::new(),
            index: 0,
            cursor: None,
        });
        true
    }

    /// Where the cursor's ray meets the handle's axis (move or scale along an axis) or plane
    /// (move in a plane, rotate about an axis).
    fn gizmo_point(&self, handle: GizmoHandle, pivot: DVec3, cursor: DVec2) -> DVec3 {
        let Some(view) = self.pick_view else {
            return pivot;
        };
        let (origin, direction) = view.ray(cursor);
        let view_dir = -self.view.camera.axes().2.as_dvec3();
        let constraint = match handle {
            GizmoHandle::Axis(a) | GizmoHandle::ScaleAxis(a) => Constraint::Axis(a),
            GizmoHandle::Plane(a) | GizmoHandle::Ring(a) => Constraint::Plane(a),
            GizmoHandle::ScaleUniform => Constraint::Free,
        };
        pick::drag_position(pivot, origin, direction, view_dir, constraint)
    }

    /// Moves the points as the gizmo drag says for the cursor at `cursor` (viewport pixels).
    pub(super) fn continue_gizmo_drag(&mut self, cursor: DVec2) {
        let Some(drag) = self.gizmo_drag.clone() else {
            return;
        };
        if self.doc.drag().is_none() {
            self.gizmo_drag = None;
            self.drag = None;
            return;
        }
        let now = self.gizmo_point(drag.handle, drag.pivot, cursor);
        let p = drag.pivot;
        let snap = self.snap.then_some(self.snap_step);
        // Every transform is a translation or affine about the pivot: x ↦ p + M (x − p).
        let about_pivot =
            |m: DAffine3| DAffine3::from_translation(p) * m * DAffine3::from_translation(-p);
        let transform = match drag.handle {
            GizmoHandle::Axis(_) | GizmoHandle::Plane(_) => {
                let mut delta = now - drag.grab;
                if let Some(step) = snap {
                    delta = pick::snap(delta, step);
                }
                DAffine3::from_translation(delta)
            }
            GizmoHandle::Ring(a) => {
                let (e1, e2) = (unit((a + 1) % 3), unit((a + 2) % 3));
                let angle = |q: DVec3| (q - p).dot(e2).atan2((q - p).dot(e1));
                let mut turn = angle(now) - angle(drag.grab);
                if snap.is_some() {
                    let step = 15f64.to_radians();
                    turn = (turn / step).round() * step;
                }
                self.status.gizmo_amount = Some(turn.to_degrees());
                about_pivot(DAffine3::from_axis_angle(unit(a), turn))
            }
            GizmoHandle::ScaleAxis(a) => {
                let e = unit(a);
                let base = (drag.grab - p).dot(e);
                let factor = if base.abs() > 1e-12 {
                    (now - p).dot(e) / base
                } else {
                    1.0
                };
                let mut scale = DVec3::ONE;
                scale[a] = factor;
                self.status.gizmo_amount = Some(factor);
                about_pivot(DAffine3::from_scale(scale))
            }
            GizmoHandle::ScaleUniform => {
                let base = drag.press_screen.distance(drag.pivot_screen).max(1.0);
                let factor = cursor.distance(drag.pivot_screen) / base;
                self.status.gizmo_amount = Some(factor);
                about_pivot(DAffine3::from_scale(DVec3::splat(factor)))
            }
        };
        let moves: Vec<(usize, DVec3)> = drag
            .starts
            .iter()
            .map(|&(k, x)| (k, transform.transform_point3(x)))
            .collect();
        self.apply(AppCommand::Drag(DragStep::To(moves)));
    }

    /// W / E / R: move, rotate, scale (not while dragging or typing).
    pub(super) fn gizmo_keys(&mut self, ctx: &egui::Context) {
        if ctx.egui_wants_keyboard_input() || self.drag.is_some() || self.trim_drawing.is_some() {
            return;
        }
        for (key, mode) in [
            (egui::Key::W, GizmoMode::Move),
            (egui::Key::E, GizmoMode::Rotate),
            (egui::Key::R, GizmoMode::Scale),
        ] {
            if ctx.input_mut(|i| i.consume_key(egui::Modifiers::NONE, key)) {
                self.gizmo_mode = mode;
                self.redraw = true;
            }
        }
    }

    /// Draws the gizmo over the viewport (the hovered or dragged part highlighted).
    pub(super) fn paint_gizmo(&self, ui: &egui::Ui) {
        let Some((_, _, pivot)) = self.gizmo_target() else {
            return;
        };
        let pivot = self.gizmo_drag.as_ref().map_or(pivot, |d| d.pivot);
        let rect = self.viewport_rect;
        let painter = ui.painter().with_clip_rect(rect);
        let parts = self.gizmo_parts(pivot);
        let hovered = self.gizmo_drag.as_ref().map(|d| d.handle).or_else(|| {
            ui.input(|i| i.pointer.hover_pos())
                .filter(|p| rect.contains(*p))
                .and_then(|p| {
                    let cursor =
                        DVec2::new(f64::from(p.x - rect.left()), f64::from(p.y - rect.top()));
                    self.gizmo_handle_at(pivot, &parts, cursor)
                })
        });
        for (handle, points) in parts {
            let axis = match handle {
                GizmoHandle::Axis(a)
                | GizmoHandle::Plane(a)
                | GizmoHandle::Ring(a)
                | GizmoHandle::ScaleAxis(a) => Some(a),
                GizmoHandle::ScaleUniform => None,
            };
            let base = axis.map_or(Color32::from_gray(220), |a| AXIS_COLORS[a]);
            let color = if hovered == Some(handle) { HOVER } else { base };
            let screen: Vec<Pos2> = points.iter().map(|&p| to_pos(rect, p)).collect();
            match handle {
                GizmoHandle::Axis(_) => {
                    painter.line_segment([screen[0], screen[1]], Stroke::new(2.5, color));
                    let dir = (screen[1] - screen[0]).normalized();
                    let side = egui::vec2(-dir.y, dir.x);
                    painter.add(egui::Shape::convex_polygon(
                        vec![
                            screen[1] + dir * 12.0,
                            screen[1] + side * 5.0,
                            screen[1] - side * 5.0,
                        ],
                        color,
                        Stroke::NONE,
                    ));
                }
                GizmoHandle::Plane(_) => {
                    painter.add(egui::Shape::convex_polygon(
                        screen[..4].to_vec(),
                        color.gamma_multiply(0.45),
                        Stroke::new(1.0, color),
                    ));
                }
                GizmoHandle::Ring(_) => {
                    painter.add(egui::Shape::line(screen, Stroke::new(2.0, color)));
                }
                GizmoHandle::ScaleAxis(_) => {
                    painter.line_segment([screen[0], screen[1]], Stroke::new(2.5, color));
                    painter.rect_filled(
                        egui::Rect::from_center_size(screen[1], egui::vec2(10.0, 10.0)),
                        1.0,
                        color,
                    );
                }
                GizmoHandle::ScaleUniform => {
                    painter.circle_stroke(screen[0], 6.0, Stroke::new(2.0, color));
                }
            }
        }
    }
}
