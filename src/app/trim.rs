//! Drawing and editing trim loops: tools that place loops by clicking on the surface (polyline,
//! interpolating cubic loop, circle, rectangle, regular polygon), the loops and their control
//! points drawn on the surface in 3D, and a (u, v) panel with the domain, the knot lines and the
//! loops, whose control points are handles to drag, insert or delete. Every change is one
//! command (one undo step); a loop the kernel refuses changes nothing and says why.

use eframe::egui;
use glam::DVec2;

use super::{AppCommand, KnotworkApp};
use crate::doc::{Command, TrimEdit};
use crate::kernel::trim::shapes;
use crate::kernel::{Direction, GeometryError, TrimLoop, TrimmedSurface};

/// Which loop the next clicks on the surface draw.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum TrimTool {
    #[default]
    None,
    /// Straight segments through the clicked points; Enter or a click on the first closes it.
    Polyline,
    /// The closed cubic through the clicked points.
    Interpolating,
    /// Centre, then a point on the circle: round in model space, on the surface.
    Circle,
    /// Two opposite corners.
    Rectangle,
    /// Centre, then a corner: a regular hexagon in model space, on the surface.
    Polygon,
}

impl TrimTool {
    pub const ALL: [TrimTool; 5] = [
        TrimTool::Polyline,
        TrimTool::Interpolating,
        TrimTool::Circle,
        TrimTool::Rectangle,
        TrimTool::Polygon,
    ];

    pub fn label(self) -> &'static str {
        match self {
            TrimTool::None => "none",
            TrimTool::Polyline => "Polyline",
            TrimTool::Interpolating => "Curve",
            TrimTool::Circle => "Circle",
            TrimTool::Rectangle => "Rectangle",
            TrimTool::Polygon => "Hexagon",
        }
    }

    /// Points after which the loop is complete (`None`: closed by the user).
    fn points_needed(self) -> Option<usize> {
        match self {
            TrimTool::Circle | TrimTool::Rectangle | TrimTool::Polygon => Some(2),
            _ => None,
        }
    }
}

/// A loop being drawn on one object.
#[derive(Debug, Clone, Default)]
pub struct TrimDrawing {
    pub tool: TrimTool,
    pub object: usize,
    pub points: Vec<DVec2>,
}

/// A trim control point being dragged in the (u, v) panel.
#[derive(Debug, Clone, Copy)]
pub struct HandleDrag {
    trim_loop: usize,
    curve: usize,
    point: usize,
    to: DVec2,
}

/// Points on the circle drawn by the Circle tool.
const CIRCLE_POINTS: usize = 24;

/// The loop `tool` makes of `points` (in (u, v)) on `surface`: the circle and the hexagon in
/// model space ([`shapes::model_space_corners`]), the rest in (u, v).
pub fn loop_on(
    tool: TrimTool,
    points: &[DVec2],
    surface: &crate::kernel::NurbsSurface,
) -> Result<TrimLoop, GeometryError> {
    match (tool, points) {
        (TrimTool::Circle, [c, p, ..]) => shapes::interpolating_loop(&shapes::model_space_corners(
            surface,
            *c,
            *p,
            CIRCLE_POINTS,
        )?),
        (TrimTool::Polygon, [c, p, ..]) => {
            shapes::polygon(&shapes::model_space_corners(surface, *c, *p, 6)?)
        }
        _ => loop_from(tool, points),
    }
}

/// The loop `tool` makes of `points` (in (u, v)).
pub fn loop_from(tool: TrimTool, points: &[DVec2]) -> Result<TrimLoop, GeometryError> {
    let refuse = |m: &str| GeometryError::Construction {
        what: "trim loop",
        message: m.into(),
    };
    match tool {
        TrimTool::Polyline => shapes::polygon(points),
        TrimTool::Interpolating => shapes::interpolating_loop(points),
        TrimTool::Circle => match points {
            [c, p, ..] => {
                let r = (*p - *c).length();
                shapes::ellipse(*c, DVec2::splat(r))
            }
            _ => Err(refuse("a circle needs its centre and a point on it")),
        },
        TrimTool::Rectangle => match points {
            [a, b, ..] => {
                if (a.x - b.x).abs() <= 0.0 || (a.y - b.y).abs() <= 0.0 {
                    return Err(refuse("the rectangle's corners must differ in u and in v"));
                }
                shapes::rectangle(a.min(*b), a.max(*b))
            }
            _ => Err(refuse("a rectangle needs two corners")),
        },
        TrimTool::Polygon => match points {
            [c, p, ..] => {
                let d = *p - *c;
                let corners: Vec<DVec2> = (0..6)
                    .map(|k| {
                        let a = k as f64 * std::f64::consts::PI / 3.0;
                        *c + DVec2::new(
                            d.x * a.cos() - d.y * a.sin(),
                            d.x * a.sin() + d.y * a.cos(),
                        )
                    })
                    .collect();
                shapes::polygon(&corners)
            }
            _ => Err(refuse("a polygon needs its centre and a corner")),
        },
        TrimTool::None => Err(refuse("no trim tool is chosen")),
    }
}

impl KnotworkApp {
    /// The selected object's NURBS surface with its loops, if it has one.
    fn selected_trimmed(&self) -> Option<(usize, TrimmedSurface)> {
        let s = self.selection.object?;
        let t = self.scene().objects.get(s)?.geometry.as_trimmed()?;
        Some((s, t))
    }

    /// A click on the surface while a trim tool is active: adds the (u, v) under the cursor to
    /// the loop being drawn, and finishes it when it is complete. Returns whether the click
    /// was used.
    pub(super) fn trim_click(&mut self, hit: Option<crate::view::SurfaceHit>) -> bool {
        let Some(drawing) = self.trim_drawing.as_ref() else {
            return false;
        };
        let object = drawing.object;
        let Some(hit) = hit.filter(|h| h.object == object) else {
            self.status.error = Some("click on the surface being trimmed".into());
            return true;
        };
        let p = DVec2::new(hit.u, hit.v);
        // A click near the first point closes a free loop.
        let first = (drawing.points.len() >= 3).then(|| drawing.points[0]);
        let closes = first.is_some_and(|first| {
            self.pick_view.is_some_and(|view| {
                self.scene()
                    .objects
                    .get(object)
                    .and_then(|o| o.geometry.nurbs_surface())
                    .and_then(|s| s.point_at(first.x, first.y).ok())
                    .and_then(|first| view.project(first))
                    .zip(view.project(hit.point))
                    .is_some_and(|(a, b)| a.screen.distance(b.screen) < 8.0)
            })
        });
        if closes {
            self.finish_trim();
            return true;
        }
        let Some(drawing) = self.trim_drawing.as_mut() else {
            return false;
        };
        drawing.points.push(p);
        if drawing
            .tool
            .points_needed()
            .is_some_and(|n| drawing.points.len() >= n)
        {
            self.finish_trim();
        }
        self.redraw = true;
        true
    }

    /// Chooses a tool by name (the page's script interface); an unknown name turns it off.
    pub(super) fn set_trim_tool(&mut self, name: &str) {
        let tool = TrimTool::ALL.into_iter().find(|t| {
            t.label().eq_ignore_ascii_case(name) || (name == "hexagon" && *t == TrimTool::Polygon)
        });
        self.trim_drawing = match (tool, self.selected_trimmed()) {
            (Some(tool), Some((object, _))) => Some(TrimDrawing {
                tool,
                object,
                points: Vec::new(),
            }),
            (Some(_), None) => {
                self.status.error = Some("select a NURBS surface to trim".into());
                None
            }
            (None, _) => None,
        };
        self.redraw = true;
    }

    /// Turns the loop being drawn into a command (one undo step).
    pub(super) fn finish_trim(&mut self) {
        let Some(drawing) = self.trim_drawing.as_mut() else {
            return;
        };
        let points = std::mem::take(&mut drawing.points);
        let (tool, object) = (drawing.tool, drawing.object);
        let Some((_, trimmed)) = self.selected_trimmed().filter(|(s, _)| *s == object) else {
            self.status.error = Some("select the surface being trimmed".into());
            return;
        };
        match loop_on(tool, &points, trimmed.surface()) {
            Ok(curves) => self.apply(AppCommand::Edit(Command::Trim {
                object,
                edit: TrimEdit::Add {
                    curves,
                    keep_inside: self.panel.trim_keep_inside,
                },
            })),
            Err(e) => self.status.error = Some(e.to_string()),
        }
        self.redraw = true;
    }

    /// Enter closes the loop being drawn, Escape abandons it.
    pub(super) fn trim_keys(&mut self, ctx: &egui::Context) {
        if self.trim_drawing.is_none() || ctx.egui_wants_keyboard_input() {
            return;
        }
        if ctx.input(|i| i.key_pressed(egui::Key::Enter)) {
            self.finish_trim();
        }
        if ctx.input(|i| i.key_pressed(egui::Key::Escape)) {
            self.trim_drawing = None;
            self.redraw = true;
        }
    }

    /// The selected surface's loops, their control points and the loop being drawn, on the
    /// surface in the viewport.
    pub(super) fn paint_trims(&self, ui: &egui::Ui) {
        let (Some(view), Some((s, t))) = (self.pick_view, self.selected_trimmed()) else {
            return;
        };
        let origin = self.viewport_rect.min.to_vec2();
        let screen = |uv: DVec2| -> Option<egui::Pos2> {
            let p = t.surface().point_at(uv.x, uv.y).ok()?;
            let q = view.project(p)?;
            Some(egui::pos2(q.screen.x as f32, q.screen.y as f32) + origin)
        };
        let painter = ui.painter().with_clip_rect(self.viewport_rect);
        let loop_color = egui::Color32::from_rgb(255, 200, 60);
        // Every loop on the surface: edges longer than a 48th of the domain are divided, so
        // that a straight (u, v) edge (the outer loop's) follows the surface, not a chord.
        let [(u0, u1), (v0, v1)] = t.surface().domain();
        let step = (u1 - u0).max(v1 - v0) / 48.0;
        let on_surface = |polygon: &[DVec2], closed: bool| -> Option<Vec<egui::Pos2>> {
            let mut points = Vec::new();
            let count = if closed {
                polygon.len()
            } else {
                polygon.len().saturating_sub(1)
            };
            for k in 0..count {
                let (a, b) = (polygon[k], polygon[(k + 1) % polygon.len()]);
                let pieces = ((a.distance(b) / step).ceil() as usize).clamp(1, 256);
                for i in 0..pieces {
                    points.push(screen(a.lerp(b, i as f64 / pieces as f64))?);
                }
            }
            if !closed {
                points.push(screen(*polygon.last()?)?);
            }
            Some(points)
        };
        for polygon in t.outline().iter() {
            if let Some(points) = on_surface(polygon, true).filter(|p| p.len() > 1) {
                painter.add(egui::Shape::closed_line(
                    points,
                    egui::Stroke::new(1.5, loop_color),
                ));
            }
        }
        for lp in t.loops() {
            for curve in lp {
                for k in 0..curve.count() {
                    if let Some(p) = screen(curve.control_point(k)) {
                        painter.circle_stroke(p, 3.0, egui::Stroke::new(1.0, loop_color));
                    }
                }
            }
        }
        if let Some(drawing) = self.trim_drawing.as_ref().filter(|d| d.object == s) {
            let color = egui::Color32::from_rgb(90, 220, 255);
            for p in drawing.points.iter().filter_map(|&p| screen(p)) {
                painter.circle_filled(p, 3.5, color);
            }
            // The shape as it would be with the cursor's point added: a preview before the
            // click that completes it.
            let hover = ui
                .ctx()
                .pointer_hover_pos()
                .and_then(|pos| self.surface_uv_at(s, pos));
            let mut points = drawing.points.clone();
            points.extend(hover);
            let preview = if points.len() >= 2 {
                loop_on(drawing.tool, &points, t.surface())
                    .ok()
                    .map(|l| crate::kernel::trim::flatten_loop(&l, step * 0.05))
            } else {
                None
            };
            let closed = drawing.tool.points_needed().is_some();
            let line = match &preview {
                Some(polygon) => on_surface(polygon, true),
                None => on_surface(&drawing.points, closed && drawing.points.len() > 2),
            };
            if let Some(line) = line.filter(|l| l.len() > 1) {
                painter.add(egui::Shape::line(line, egui::Stroke::new(1.5, color)));
            }
        }
    }

    /// The (u, v) of object `object`'s surface under the screen position `pos`, if it is there.
    fn surface_uv_at(&self, object: usize, pos: egui::Pos2) -> Option<DVec2> {
        let view = self.pick_view?;
        if !self.viewport_rect.contains(pos) {
            return None;
        }
        let cursor = (pos - self.viewport_rect.min).to_pos2();
        let (origin, direction) = view.ray(glam::DVec2::new(cursor.x as f64, cursor.y as f64));
        let gpu = self.gpu.as_ref()?;
        let objects: Vec<_> = gpu
            .sync
            .feeds()
            .iter()
            .enumerate()
            .map(|(k, d)| (d, k == object))
            .collect();
        let hit = crate::view::pick::pick_surface(&objects, origin, direction)?;
        Some(DVec2::new(hit.u, hit.v))
    }

    /// The Trim section of the panel for a NURBS surface.
    pub(super) fn trim_panel(&mut self, ui: &mut egui::Ui) {
        let Some((s, t)) = self.selected_trimmed() else {
            return;
        };
        ui.separator();
        ui.label(egui::RichText::new("Trim").strong());
        ui.horizontal_wrapped(|ui| {
            for tool in TrimTool::ALL {
                let active = self
                    .trim_drawing
                    .as_ref()
                    .is_some_and(|d| d.tool == tool && d.object == s);
                if ui.selectable_label(active, tool.label()).clicked() {
                    self.trim_drawing = (!active).then(|| TrimDrawing {
                        tool,
                        object: s,
                        points: Vec::new(),
                    });
                    self.redraw = true;
                }
            }
        });
        ui.horizontal(|ui| {
            ui.radio_value(&mut self.panel.trim_keep_inside, false, "cut a hole");
            ui.radio_value(&mut self.panel.trim_keep_inside, true, "keep inside");
        });
        if let Some(drawing) = &self.trim_drawing {
            let hint = match drawing.tool.points_needed() {
                Some(_) => {
                    "click on the surface: first the centre or corner, then the second point"
                }
                None => {
                    "click points on the surface; Enter or a click on the first point closes, Esc cancels"
                }
            };
            ui.label(egui::RichText::new(hint).weak());
        }
        let mut command = None;
        ui.horizontal_wrapped(|ui| {
            if ui
                .add_enabled(t.is_trimmed(), egui::Button::new("Invert"))
                .on_hover_text("keep the other side")
                .clicked()
            {
                command = Some(TrimEdit::Invert);
            }
            if ui
                .add_enabled(t.is_trimmed(), egui::Button::new("Remove all"))
                .clicked()
            {
                command = Some(TrimEdit::Replace { loops: Vec::new() });
            }
        });
        for (l, lp) in t.loops().iter().enumerate() {
            ui.horizontal(|ui| {
                ui.label(format!(
                    "loop {l}: {} curve{}",
                    lp.len(),
                    if lp.len() == 1 { "" } else { "s" }
                ));
                if ui.small_button("Delete").clicked() {
                    command = Some(TrimEdit::Delete { trim_loop: l });
                }
            });
        }
        if let Some(edit) = self.domain_view(ui, &t) {
            command = Some(edit);
        }
        if let Some(edit) = command {
            self.apply(AppCommand::Edit(Command::Trim { object: s, edit }));
        }
    }

    /// The (u, v) domain with its knot lines and the loops; control points are handles: drag to
    /// move, right-click to insert or delete. Returns the edit a handle asked for.
    fn domain_view(&mut self, ui: &mut egui::Ui, t: &TrimmedSurface) -> Option<TrimEdit> {
        let [(u0, u1), (v0, v1)] = t.surface().domain();
        let width = ui.available_width().min(260.0);
        let height = (width * ((v1 - v0) / (u1 - u0)).clamp(0.3, 2.0) as f32).min(260.0);
        let (response, painter) =
            ui.allocate_painter(egui::vec2(width, height), egui::Sense::click_and_drag());
        let rect = response.rect;
        let to_screen = |p: DVec2| {
            egui::pos2(
                rect.left() + ((p.x - u0) / (u1 - u0)) as f32 * rect.width(),
                rect.bottom() - ((p.y - v0) / (v1 - v0)) as f32 * rect.height(),
            )
        };
        let to_uv = |q: egui::Pos2| {
            DVec2::new(
                u0 + f64::from((q.x - rect.left()) / rect.width()) * (u1 - u0),
                v0 + f64::from((rect.bottom() - q.y) / rect.height()) * (v1 - v0),
            )
        };
        painter.rect_filled(rect, 2.0, egui::Color32::from_gray(30));
        let knot = egui::Stroke::new(1.0, egui::Color32::from_gray(70));
        for (d, breaks) in [Direction::U, Direction::V].map(|d| (d, t.surface().span_breaks(d))) {
            for &k in &breaks {
                let (a, b) = if d == Direction::U {
                    (DVec2::new(k, v0), DVec2::new(k, v1))
                } else {
                    (DVec2::new(u0, k), DVec2::new(u1, k))
                };
                painter.line_segment([to_screen(a), to_screen(b)], knot);
            }
        }
        let kept = egui::Color32::from_rgb(255, 200, 60);
        for polygon in t.outline().iter() {
            let points = polygon.iter().map(|&p| to_screen(p)).collect();
            painter.add(egui::Shape::closed_line(
                points,
                egui::Stroke::new(1.5, kept),
            ));
        }
        // Handles: (loop, curve, point, screen position).
        let mut handles = Vec::new();
        for (l, lp) in t.loops().iter().enumerate() {
            for (c, curve) in lp.iter().enumerate() {
                for k in 0..curve.count() {
                    let mut p = curve.control_point(k);
                    if let Some(d) = self
                        .trim_handle
                        .filter(|d| (d.trim_loop, d.curve, d.point) == (l, c, k))
                    {
                        p = d.to;
                    }
                    handles.push((l, c, k, to_screen(p)));
                }
            }
        }
        for &(_, _, _, q) in &handles {
            painter.circle_filled(q, 3.0, egui::Color32::WHITE);
        }
        let nearest = |pos: egui::Pos2| {
            handles
                .iter()
                .copied()
                .filter(|h| h.3.distance(pos) < 8.0)
                .min_by(|a, b| a.3.distance(pos).total_cmp(&b.3.distance(pos)))
        };
        let mut edit = None;
        if response.drag_started()
            && let Some(pos) = response.interact_pointer_pos()
            && let Some((l, c, k, _)) = nearest(pos)
        {
            self.trim_handle = Some(HandleDrag {
                trim_loop: l,
                curve: c,
                point: k,
                to: to_uv(pos),
            });
        }
        if let (Some(drag), Some(pos)) = (&mut self.trim_handle, response.interact_pointer_pos())
            && response.dragged()
        {
            drag.to = to_uv(pos);
        }
        if response.drag_stopped()
            && let Some(drag) = self.trim_handle.take()
        {
            edit = Some(TrimEdit::MovePoint {
                trim_loop: drag.trim_loop,
                curve: drag.curve,
                point: drag.point,
                to: drag.to,
            });
        }
        if let Some(pos) = response.hover_pos()
            && let Some((l, c, k, _)) = nearest(pos)
        {
            self.panel.trim_menu = Some((l, c, k));
        }
        response.context_menu(|ui| {
            let Some((l, c, k)) = self.panel.trim_menu else {
                ui.label("right-click a handle");
                return;
            };
            ui.label(format!("loop {l}, curve {c}, point {k}"));
            if ui.button("Insert point").clicked() {
                edit = Some(TrimEdit::InsertPoint {
                    trim_loop: l,
                    curve: c,
                });
                ui.close();
            }
            if ui.button("Delete point").clicked() {
                edit = Some(TrimEdit::DeletePoint {
                    trim_loop: l,
                    curve: c,
                    point: k,
                });
                ui.close();
            }
        });
        edit
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kernel::construct;
    use glam::DVec3;

    /// On a 5 × 4 sheet over the unit square of (u, v), the circle tool's loop is round in model
    /// space (a circle in (u, v) would be an ellipse there), at the radius the second click
    /// gave; the hexagon is drawn the same way, and two clicks at one place are refused.
    #[test]
    fn the_circle_tool_draws_a_circle_round_in_model_space() {
        let sheet = construct::plane(DVec3::ZERO, DVec3::X * 5.0, DVec3::Y * 4.0).unwrap();
        let (c, p) = (DVec2::new(0.5, 0.5), DVec2::new(0.7, 0.5));
        let circle = loop_on(TrimTool::Circle, &[c, p], &sheet).unwrap();
        let centre = sheet.point_at(c.x, c.y).unwrap();
        let radius = sheet.point_at(p.x, p.y).unwrap().distance(centre);
        assert!((radius - 1.0).abs() < 1e-12);
        for uv in crate::kernel::trim::flatten_loop(&circle, 1e-4) {
            let q = sheet.point_at(uv.x, uv.y).unwrap();
            // The interpolating cubic through 24 points of the circle: within 0.1 % of it.
            assert!(
                (q.distance(centre) - radius).abs() < 1e-3 * radius,
                "{uv} at {q}"
            );
        }
        // In (u, v) the same circle is an ellipse: 0.2 across in u, 0.25 in v.
        let uvs = shapes::model_space_corners(&sheet, c, p, 4).unwrap();
        assert!((uvs[1].y - c.y - 0.25).abs() < 1e-9, "{uvs:?}");
        let hexagon = loop_on(TrimTool::Polygon, &[c, p], &sheet).unwrap();
        assert_eq!(hexagon.len(), 6);
        assert!(matches!(
            loop_on(TrimTool::Circle, &[c, c], &sheet),
            Err(GeometryError::Construction { .. })
        ));
    }
}
