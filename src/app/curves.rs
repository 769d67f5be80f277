//! Curves in the editor: drawing them by clicks on a construction plane (control points,
//! points to pass through, or a polyline; snapping to the grid, to control points, to curves'
//! ends, midpoints and crossings, and perpendicular or tangent to a curve from the last point; Enter or a click on the first point finishes, Escape cancels,
//! Backspace takes the last point back), picking curves in order for a construction (Shift +
//! click), and the constructions and curve edits the panel and the page ask for.

use eframe::egui;
use glam::{DVec2, DVec3};

use super::{AppCommand, KnotworkApp, PICK_RADIUS};
use crate::doc::Command;
use crate::kernel::{GeometryError, SpaceCurve, construct, splines};
use crate::ops::construct::Construct;
use crate::scene::operation::{ObjectRef, Operation};
use crate::scene::{ObjectGeometry, SceneObject};
use crate::view::osnap;

/// What the clicks of a curve being drawn are.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum DrawKind {
    /// The control points of a B-spline (clamped; periodic when closed).
    #[default]
    ControlPoints,
    /// Points the curve passes through (The NURBS Book §9.2, chord length).
    Through,
    /// Corners of a polyline.
    Polyline,
    /// The centre, then a point on the circle (an exact rational circle in the plane).
    Circle,
    /// The start, a point it passes through, and the end (an exact circular arc).
    Arc,
}

impl DrawKind {
    pub const ALL: [DrawKind; 3] = [
        DrawKind::ControlPoints,
        DrawKind::Through,
        DrawKind::Polyline,
    ];

    pub fn label(self) -> &'static str {
        match self {
            DrawKind::ControlPoints => "Control points",
            DrawKind::Through => "Through points",
            DrawKind::Polyline => "Polyline",
            DrawKind::Circle => "Circle",
            DrawKind::Arc => "Arc (3 points)",
        }
    }

    /// Points after which the curve is complete (`None`: finished by the user).
    pub fn points_needed(self) -> Option<usize> {
        match self {
            DrawKind::Circle => Some(2),
            DrawKind::Arc => Some(3),
            _ => None,
        }
    }

    /// The page's name of the kind.
    pub fn name(self) -> &'static str {
        match self {
            DrawKind::ControlPoints => "control",
            DrawKind::Through => "through",
            DrawKind::Polyline => "polyline",
            DrawKind::Circle => "circle",
            DrawKind::Arc => "arc",
        }
    }

    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|k| k.name() == name)
    }
}

/// The plane clicks land on while a curve is drawn.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ConstructionPlane {
    pub origin: DVec3,
    /// Unit normal.
    pub normal: DVec3,
}

/// The standard construction planes by name, and the view's.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum PlaneChoice {
    /// The ground, z = 0.
    #[default]
    Ground,
    /// The front plane, y = 0.
    Front,
    /// The right plane, x = 0.
    Right,
    /// Through the camera's target, facing the viewer.
    View,
    /// Tangent to the surface at the last point clicked on it.
    Surface,
    /// Through three selected control points of the selected object.
    ThreePoints,
}

impl PlaneChoice {
    pub const ALL: [PlaneChoice; 6] = [
        PlaneChoice::Ground,
        PlaneChoice::Front,
        PlaneChoice::Right,
        PlaneChoice::View,
        PlaneChoice::Surface,
        PlaneChoice::ThreePoints,
    ];

    pub fn label(self) -> &'static str {
        match self {
            PlaneChoice::Ground => "Ground (XY)",
            PlaneChoice::Front => "Front (XZ)",
            PlaneChoice::Right => "Right (YZ)",
            PlaneChoice::View => "View",
            PlaneChoice::Surface => "Surface point",
            PlaneChoice::ThreePoints => "Three points",
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            PlaneChoice::Ground => "ground",
            PlaneChoice::Front => "front",
            PlaneChoice::Right => "right",
            PlaneChoice::View => "view",
            PlaneChoice::Surface => "surface",
            PlaneChoice::ThreePoints => "points",
        }
    }

    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|k| k.name() == name)
    }
}

impl ConstructionPlane {
    /// The plane through `origin` with normal `normal` (refused when it is not finite or 0).
    pub fn new(origin: DVec3, normal: DVec3) -> Option<Self> {
        let normal = normal.try_normalize()?;
        origin.is_finite().then_some(Self { origin, normal })
    }

    /// The plane through three points not on a line.
    pub fn through(a: DVec3, b: DVec3, c: DVec3) -> Option<Self> {
        Self::new(a, (b - a).cross(c - a))
    }

    /// Where the ray (`origin`, `direction`) meets the plane, if it does in front of it.
    pub fn hit(&self, origin: DVec3, direction: DVec3) -> Option<DVec3> {
        let denom = direction.dot(self.normal);
        if denom.abs() < 1e-9 {
            return None;
        }
        let t = (self.origin - origin).dot(self.normal) / denom;
        (t > 0.0).then(|| origin + direction * t)
    }

    /// `p` moved along the normal onto the plane.
    pub fn project(&self, p: DVec3) -> DVec3 {
        p - self.normal * (p - self.origin).dot(self.normal)
    }
}

/// A curve being drawn.
#[derive(Debug, Clone, PartialEq)]
pub struct CurveDrawing {
    pub kind: DrawKind,
    pub degree: usize,
    pub plane: ConstructionPlane,
    pub points: Vec<DVec3>,
    /// Where the next click would land (the rubber band's end), and what it snapped to.
    pub hover: Option<(DVec3, Option<&'static str>)>,
}

/// The curve `kind` makes of `points` (degree lowered to what the points allow): a B-spline
/// on them as control points (uniform clamped knots; periodic when `closed`), the interpolant
/// through them (closed: C² at the seam), the polyline (closed: back to the first point), the
/// circle about the first point through the second in the plane with normal `normal`, or the
/// arc from the first point through the second to the third.
pub fn drawn_curve(
    kind: DrawKind,
    degree: usize,
    points: &[DVec3],
    closed: bool,
    normal: DVec3,
) -> Result<SpaceCurve, GeometryError> {
    let n = points.len();
    let too_few = |needed: usize| GeometryError::Construction {
        what: "curve",
        message: format!("needs at least {needed} points, found {n}"),
    };
    match kind {
        DrawKind::Circle => match points {
            [center, on, ..] => {
                construct::circle(*center, normal, *on - *center, center.distance(*on))
            }
            _ => Err(too_few(2)),
        },
        DrawKind::Arc => match points {
            [a, through, b, ..] => construct::arc_through(*a, *through, *b),
            _ => Err(too_few(3)),
        },
        DrawKind::Polyline => {
            if n < 2 || (closed && n < 3) {
                return Err(too_few(if closed { 3 } else { 2 }));
            }
            let mut corners = points.to_vec();
            if closed {
                corners.push(points[0]);
            }
            construct::polyline(&corners)
        }
        DrawKind::ControlPoints if closed => {
            if n < 3 {
                return Err(too_few(3));
            }
            splines::periodic_from_control(points, degree.clamp(1, n - 1))
        }
        DrawKind::ControlPoints => {
            if n < 2 {
                return Err(too_few(2));
            }
            let p = degree.clamp(1, n - 1);
            SpaceCurve::new(
                p,
                crate::kernel::basis::uniform_clamped_knots(p, n),
                points.to_vec(),
                None,
            )
        }
        DrawKind::Through if closed => {
            if n < 3 {
                return Err(too_few(3));
            }
            splines::interpolate_closed(
                points,
                degree.clamp(1, n - 1),
                splines::Parametrization::ChordLength,
            )
        }
        DrawKind::Through => {
            if n < 2 {
                return Err(too_few(2));
            }
            splines::interpolate_through(
                points,
                degree.clamp(1, n - 1),
                splines::Parametrization::ChordLength,
                None,
            )
        }
    }
}

/// One step of drawing a curve (the mouse's clicks and keys, or the page's calls).
#[derive(Debug, Clone, PartialEq)]
pub enum DrawStep {
    /// Starts drawing: what the clicks are, the degree, and the plane.
    Begin {
        kind: DrawKind,
        degree: usize,
        plane: PlaneChoice,
    },
    /// Places a point (moved onto the plane).
    Point(DVec3),
    /// Takes the last point back.
    Undo,
    /// Adds the curve (closed or not) to the document: one undo step.
    Finish {
        close: bool,
    },
    Cancel,
}

/// The largest distance in pixels from `cursor` to the polyline `screen`.
fn distance_to_polyline(screen: &[Option<DVec2>], cursor: DVec2) -> Option<f64> {
    screen
        .windows(2)
        .filter_map(|pair| {
            let (a, b) = (pair[0]?, pair[1]?);
            let ab = b - a;
            let t = ((cursor - a).dot(ab) / ab.length_squared().max(1e-12)).clamp(0.0, 1.0);
            Some(cursor.distance(a + ab * t))
        })
        .reduce(f64::min)
}

impl KnotworkApp {
    /// The plane `choice` stands for now.
    fn plane_for(&self, choice: PlaneChoice) -> Result<ConstructionPlane, String> {
        let camera = &self.view.camera;
        let plane = match choice {
            PlaneChoice::Ground => ConstructionPlane::new(DVec3::ZERO, DVec3::Z),
            PlaneChoice::Front => ConstructionPlane::new(DVec3::ZERO, DVec3::Y),
            PlaneChoice::Right => ConstructionPlane::new(DVec3::ZERO, DVec3::X),
            PlaneChoice::View => ConstructionPlane::new(
                camera.target.as_dvec3(),
                (camera.eye() - camera.target).as_dvec3(),
            ),
            PlaneChoice::Surface => {
                let hit = self
                    .selection
                    .hit
                    .ok_or("click a surface first: the plane is tangent to it there")?;
                let object = self
                    .scene()
                    .objects
                    .get(hit.object)
                    .ok_or("the surface clicked is gone")?;
                let normal = object
                    .faces()
                    .into_iter()
                    .find_map(|(_, f)| f.derivatives(hit.u, hit.v).map(|d| d.su.cross(d.sv)));
                ConstructionPlane::new(hit.point, normal.unwrap_or(DVec3::Z))
            }
            PlaneChoice::ThreePoints => {
                let object = self
                    .selection
                    .object
                    .and_then(|s| self.scene().objects.get(s))
                    .ok_or("select three control points of an object first")?;
                let points = object.control_points();
                let chosen: Vec<DVec3> = self
                    .selection
                    .points
                    .iter()
                    .filter_map(|&k| points.get(k).copied())
                    .collect();
                match chosen.as_slice() {
                    [a, b, c] => ConstructionPlane::through(*a, *b, *c),
                    _ => {
                        return Err(format!(
                            "select exactly three control points ({} are selected)",
                            chosen.len()
                        ));
                    }
                }
            }
        };
        plane.ok_or_else(|| "the construction plane is degenerate".to_owned())
    }

    /// Carries out one drawing step.
    pub(super) fn draw_step(&mut self, step: DrawStep) {
        match step {
            DrawStep::Begin {
                kind,
                degree,
                plane,
            } => match self.plane_for(plane) {
                Ok(plane) => {
                    self.trim_drawing = None;
                    self.curves.drawing = Some(CurveDrawing {
                        kind,
                        degree: degree.clamp(1, 9),
                        plane,
                        points: Vec::new(),
                        hover: None,
                    });
                    self.status.error = None;
                }
                Err(e) => self.status.error = Some(format!("draw curve: {e}")),
            },
            DrawStep::Point(p) => {
                let Some(drawing) = &mut self.curves.drawing else {
                    self.status.error = Some("placePoint: no curve is being drawn".into());
                    return;
                };
                if !p.is_finite() || p.abs().max_element() > crate::doc::MAX_COORDINATE {
                    self.status.error = Some(format!("placePoint: {p} is not a usable point"));
                    return;
                }
                drawing.points.push(drawing.plane.project(p));
                if drawing
                    .kind
                    .points_needed()
                    .is_some_and(|n| drawing.points.len() >= n)
                {
                    self.finish_curve(false);
                }
            }
            DrawStep::Undo => {
                if let Some(drawing) = &mut self.curves.drawing {
                    drawing.points.pop();
                }
            }
            DrawStep::Cancel => self.curves.drawing = None,
            DrawStep::Finish { close } => self.finish_curve(close),
        }
        self.redraw = true;
    }

    /// Adds the curve drawn so far ("Curve N"), selected; the drawing stays when the points
    /// make no curve, and the status says why.
    fn finish_curve(&mut self, close: bool) {
        let Some(drawing) = self.curves.drawing.clone() else {
            return;
        };
        let normal = drawing.plane.normal;
        match drawn_curve(drawing.kind, drawing.degree, &drawing.points, close, normal) {
            Ok(curve) => {
                self.curves.drawing = None;
                let name = self.scene().unique_name("Curve");
                let object = SceneObject::new(name, ObjectGeometry::new(curve));
                let count = self.scene().objects.len();
                self.execute(Command::Add { object });
                if self.scene().objects.len() > count {
                    self.select(Some(count));
                }
            }
            Err(e) => self.status.error = Some(format!("curve: {e}")),
        }
    }

    /// Where a click at `cursor` (viewport pixels) places a point: the nearest within the pick
    /// radius of a control point of a shown object (with point snapping), a curve's end or
    /// midpoint, two curves' crossing, or the foot of the perpendicular or a tangent point from
    /// the last point placed to a curve; else the ray's point on the plane (on the grid when the
    /// grid snap is on).
    fn placement(&self, cursor: DVec2) -> Option<(DVec3, Option<&'static str>)> {
        let drawing = self.curves.drawing.as_ref()?;
        let view = self.pick_view?;
        let mut best: Option<(f64, DVec3, &'static str)> = None;
        let mut consider = |p: DVec3, what: &'static str| {
            if let Some(q) = view.project(p) {
                let d = q.screen.distance(cursor);
                if d <= PICK_RADIUS && best.is_none_or(|(b, _, _)| d < b) {
                    best = Some((d, p, what));
                }
            }
        };
        for object in self.scene().objects.iter().filter(|o| o.visible) {
            if let Some(curve) = object.kind().space_curve() {
                if let Ok((a, b)) = curve.ends() {
                    consider(a, "end");
                    consider(b, "end");
                }
                if let Ok(m) = curve.point_at(curve.parameter_at(0.5)) {
                    consider(m, "midpoint");
                }
            }
            if self.snap_points {
                for p in object.control_points() {
                    consider(p, "point");
                }
            }
        }
        for &p in &drawing.points {
            consider(p, "point");
        }
        // Curves under the cursor: where two cross, and the perpendicular foot and the
        // tangent points from the last point placed.
        let size = self
            .scene()
            .bounds()
            .map_or(1.0, |(lo, hi)| lo.distance(hi).max(1e-12));
        let near: Vec<osnap::Sampled<'_>> = self
            .scene()
            .objects
            .iter()
            .filter(|o| o.visible)
            .filter_map(|o| o.kind().space_curve())
            .map(|c| osnap::Sampled::new(c, &view))
            .filter(|s| s.near(cursor, PICK_RADIUS))
            .collect();
        for (k, a) in near.iter().enumerate() {
            for b in &near[k + 1..] {
                for p in osnap::intersections(a, b, &view, cursor, PICK_RADIUS, 1e-9 * size) {
                    consider(p, "intersection");
                }
            }
            if let Some(&last) = drawing.points.last() {
                if let Some(p) = osnap::perpendicular(a.curve, last) {
                    consider(p, "perpendicular");
                }
                for p in osnap::tangents(a.curve, last, drawing.plane.normal) {
                    consider(p, "tangent");
                }
            }
        }
        if let Some((_, p, what)) = best {
            return Some((p, Some(what)));
        }
        let (origin, direction) = view.ray(cursor);
        let hit = drawing.plane.hit(origin, direction)?;
        if self.snap {
            Some((
                drawing
                    .plane
                    .project(crate::view::pick::snap(hit, self.snap_step)),
                Some("grid"),
            ))
        } else {
            Some((hit, None))
        }
    }

    /// A click while a curve is drawn: a point placed (a click on the first point of three or
    /// more closes the curve). Returns whether the click was the tool's.
    pub(super) fn curve_click(&mut self, cursor: DVec2) -> bool {
        let Some(drawing) = &self.curves.drawing else {
            return false;
        };
        let first = (drawing.points.len() >= 3).then(|| drawing.points[0]);
        let closes = first
            .and_then(|p| self.pick_view?.project(p))
            .is_some_and(|q| q.screen.distance(cursor) <= PICK_RADIUS);
        if closes {
            self.apply(AppCommand::DrawCurve(DrawStep::Finish { close: true }));
        } else if let Some((p, _)) = self.placement(cursor) {
            self.apply(AppCommand::DrawCurve(DrawStep::Point(p)));
        } else {
            self.status.error = Some("the cursor's ray misses the construction plane".into());
        }
        true
    }

    /// The rubber band follows the cursor while a curve is drawn.
    pub(super) fn curve_hover(&mut self, cursor: Option<DVec2>) {
        let hover = cursor.and_then(|c| self.placement(c));
        if let Some(drawing) = &mut self.curves.drawing
            && drawing.hover != hover
        {
            drawing.hover = hover;
            self.status.snapped = hover.and_then(|(_, what)| what).map(str::to_owned);
            self.redraw = true;
        }
    }

    /// Enter finishes, Escape cancels, Backspace takes the last point back; true when a curve
    /// is being drawn (the keys are then the tool's).
    pub(super) fn curve_keys(&mut self, ctx: &egui::Context) -> bool {
        if self.curves.drawing.is_none() || ctx.egui_wants_keyboard_input() {
            return false;
        }
        let pressed = |key| ctx.input_mut(|i| i.consume_key(egui::Modifiers::NONE, key));
        if pressed(egui::Key::Enter) {
            self.apply(AppCommand::DrawCurve(DrawStep::Finish { close: false }));
        } else if pressed(egui::Key::Escape) {
            self.apply(AppCommand::DrawCurve(DrawStep::Cancel));
        } else if pressed(egui::Key::Backspace) {
            self.apply(AppCommand::DrawCurve(DrawStep::Undo));
        }
        true
    }

    /// The curve being drawn, over the viewport: its points, the polygon, the rubber band to
    /// the cursor and the curve as it would be.
    pub(super) fn paint_drawing(&self, ui: &egui::Ui) {
        let (Some(drawing), Some(view)) = (&self.curves.drawing, self.pick_view) else {
            return;
        };
        let origin = self.viewport_rect.min.to_vec2();
        let screen = |p: DVec3| {
            view.project(p)
                .map(|q| egui::pos2(q.screen.x as f32, q.screen.y as f32) + origin)
        };
        let painter = ui.painter().with_clip_rect(self.viewport_rect);
        let accent = egui::Color32::from_rgb(255, 160, 50);
        let mut points = drawing.points.clone();
        if let Some((p, _)) = drawing.hover {
            points.push(p);
        }
        let polygon: Vec<egui::Pos2> = points.iter().filter_map(|&p| screen(p)).collect();
        painter.add(egui::Shape::dashed_line(
            &polygon,
            egui::Stroke::new(1.0, accent.gamma_multiply(0.7)),
            6.0,
            4.0,
        ));
        let preview = drawn_curve(
            drawing.kind,
            drawing.degree,
            &points,
            false,
            drawing.plane.normal,
        );
        if let Ok(curve) = preview {
            let line: Vec<egui::Pos2> = (0..=200)
                .filter_map(|k| {
                    curve
                        .point_at(curve.parameter_at(f64::from(k) / 200.0))
                        .ok()
                })
                .filter_map(screen)
                .collect();
            painter.add(egui::Shape::line(line, egui::Stroke::new(2.0, accent)));
        }
        for (k, &p) in drawing.points.iter().enumerate() {
            if let Some(q) = screen(p) {
                let radius = if k == 0 { 5.0 } else { 3.5 };
                painter.circle_filled(q, radius, accent);
            }
        }
        if let Some((p, Some(what))) = drawing.hover
            && let Some(q) = screen(p)
        {
            painter.circle_stroke(q, 7.0, egui::Stroke::new(1.5, egui::Color32::WHITE));
            painter.text(
                q + egui::vec2(10.0, -10.0),
                egui::Align2::LEFT_BOTTOM,
                what,
                egui::FontId::proportional(12.0),
                egui::Color32::WHITE,
            );
        }
    }

    /// The visible curve object under `cursor` (within the pick radius of its line), the
    /// nearest to the cursor.
    pub(super) fn curve_at(&self, cursor: DVec2) -> Option<usize> {
        let view = self.pick_view?;
        let gpu = self.gpu.as_ref()?;
        let mut best: Option<(f64, usize)> = None;
        for (k, (object, feed)) in self
            .scene()
            .objects
            .iter()
            .zip(gpu.sync.feeds())
            .enumerate()
        {
            let Some(curve) = feed.curve.as_ref().filter(|_| object.visible) else {
                continue;
            };
            for segment in 0..curve.segment_count() {
                let screen: Vec<Option<DVec2>> = (0..=16)
                    .map(|i| {
                        let p = curve.point(segment, f64::from(i) / 16.0)?;
                        view.project(p).map(|q| q.screen)
                    })
                    .collect();
                if let Some(d) = distance_to_polyline(&screen, cursor)
                    && d <= PICK_RADIUS
                    && best.is_none_or(|(b, _)| d < b)
                {
                    best = Some((d, k));
                }
            }
        }
        best.map(|(_, k)| k)
    }

    /// A click on a curve: selects it and makes it the only picked curve, or with `add` adds
    /// it to the picked curves (or takes it out again).
    pub(super) fn click_curve(&mut self, object: usize, add: bool) {
        let picked = &mut self.selection.curves;
        if add {
            match picked.iter().position(|&k| k == object) {
                Some(at) => {
                    picked.remove(at);
                }
                None => picked.push(object),
            }
        } else {
            *picked = vec![object];
        }
        if self.selection.object != Some(object) {
            self.select(Some(object));
        }
        self.redraw = true;
    }

    /// Sets the picked curves (the page's `pickCurves`): every one must be a curve object.
    pub(super) fn pick_curves(&mut self, objects: Vec<usize>) {
        for &k in &objects {
            match self.scene().objects.get(k) {
                Some(o) if o.kind().space_curve().is_some() => {}
                Some(o) => {
                    self.status.error = Some(format!(
                        "pickCurves: {} is {}, not a curve",
                        o.name,
                        o.kind().kind_name()
                    ));
                    return;
                }
                None => {
                    self.status.error = Some(format!(
                        "pickCurves: there is no object {k}; the scene has {}",
                        self.scene().objects.len()
                    ));
                    return;
                }
            }
        }
        self.selection.curves = objects;
        self.redraw = true;
    }

    /// Builds `request` on curve objects `objects` (each `{"input": k}` of the request is
    /// object `objects[k]`; [`Construct::with_inputs`]): a new object that follows its curves
    /// when `keep_history`, or with `replace` the new geometry of that object.
    pub(super) fn construct_from(
        &mut self,
        request: serde_json::Value,
        objects: &[usize],
        keep_history: bool,
        replace: Option<usize>,
    ) {
        let objects: Vec<ObjectRef> = objects.iter().map(|&k| k.into()).collect();
        match Construct::with_inputs("", request, &objects) {
            Ok(mut construct) => {
                construct.replace = replace.map(ObjectRef::Index);
                let count = self.scene().objects.len();
                self.execute(Command::Apply {
                    operation: Operation::new(construct),
                    keep_history: keep_history && replace.is_none(),
                });
                if replace.is_none() && self.scene().objects.len() > count {
                    self.select(Some(count));
                }
            }
            Err(e) => self.status.error = Some(format!("construct: {e}")),
        }
    }
}

/// The drawing tool's and the constructions' state between frames.
#[derive(Debug, Clone)]
pub struct CurveState {
    pub drawing: Option<CurveDrawing>,
    /// An object with construction history whose own points the user began to drag: the
    /// editor asks before that breaks its history.
    pub confirm_break: Option<usize>,
    pub kind: DrawKind,
    pub degree: usize,
    pub plane: PlaneChoice,
    /// Constructions keep their history (the result follows its curves).
    pub keep_history: bool,
    /// The object the selected one is to be intersected with.
    pub intersect_with: Option<usize>,
    /// The surface the selected curve is to be projected or pulled onto.
    pub project_onto: Option<usize>,
    pub loft_closed: bool,
    pub loft_style: crate::kernel::loft::LoftStyle,
    pub revolve_angle: f64,
    pub revolve_axis: [f64; 3],
    pub extrude: [f64; 3],
    pub rebuild_points: usize,
    pub rebuild_degree: usize,
    pub fit_tolerance: f64,
    pub offset: f64,
    pub extend: f64,
}

impl Default for CurveState {
    fn default() -> Self {
        Self {
            drawing: None,
            confirm_break: None,
            kind: DrawKind::ControlPoints,
            degree: 3,
            plane: PlaneChoice::Ground,
            keep_history: true,
            intersect_with: None,
            project_onto: None,
            loft_closed: false,
            loft_style: crate::kernel::loft::LoftStyle::Normal,
            revolve_angle: 360.0,
            revolve_axis: [0.0, 0.0, 1.0],
            extrude: [0.0, 0.0, 1.0],
            rebuild_points: 10,
            rebuild_degree: 3,
            fit_tolerance: 1e-3,
            offset: 0.2,
            extend: 0.5,
        }
    }
}

/// The curvature κ = |C′ × C″| / |C′|³ of `curve` at `count` + 1 evenly spaced parameters
/// (Farin, Curves and Surfaces for CAGD, §10.2); `None` where C′ vanishes.
pub fn curvature_profile(curve: &SpaceCurve, count: usize) -> Vec<(f64, Option<f64>)> {
    (0..=count)
        .map(|k| {
            let t = curve.parameter_at(k as f64 / count as f64);
            let kappa = curve.derivatives(t, 2).ok().and_then(|d| {
                let speed = d[1].length();
                (speed > 1e-300).then(|| d[1].cross(d[2]).length() / speed.powi(3))
            });
            (t, kappa.filter(|k| k.is_finite()))
        })
        .collect()
}

/// The curve's curvature against its parameter, with the largest value named.
fn curvature_graph(ui: &mut egui::Ui, curve: &SpaceCurve) {
    let profile = curvature_profile(curve, 200);
    let largest = profile.iter().filter_map(|(_, k)| *k).fold(0.0, f64::max);
    let size = egui::vec2(ui.available_width().min(300.0), 80.0);
    let (rect, _) = ui.allocate_exact_size(size, egui::Sense::hover());
    let painter = ui.painter_at(rect);
    painter.rect_filled(rect, 2.0, egui::Color32::from_gray(24));
    let (a, b) = curve.domain();
    let to_screen = |t: f64, k: f64| {
        let x = rect.left() + ((t - a) / (b - a).max(1e-300)) as f32 * rect.width();
        let y = rect.bottom() - 4.0 - (k / largest.max(1e-300)) as f32 * (rect.height() - 8.0);
        egui::pos2(x, y)
    };
    let line: Vec<egui::Pos2> = profile
        .iter()
        .filter_map(|&(t, k)| k.map(|k| to_screen(t, k)))
        .collect();
    painter.add(egui::Shape::line(
        line,
        egui::Stroke::new(1.5, egui::Color32::from_rgb(120, 200, 255)),
    ));
    // The knots: where the curvature may jump.
    for (knot, _) in curve.interior_knots() {
        let x = to_screen(knot, 0.0).x;
        painter.vline(
            x,
            rect.y_range(),
            egui::Stroke::new(1.0, egui::Color32::from_gray(70)),
        );
    }
    ui.label(format!(
        "largest curvature {largest:.4} (radius {:.4})",
        1.0 / largest.max(1e-300)
    ));
}

/// `{"input": 0}`, `{"input": 1}`, … for curves `range`.
fn inputs(range: std::ops::Range<usize>) -> Vec<serde_json::Value> {
    range.map(|k| serde_json::json!({ "input": k })).collect()
}

/// A construction the panel offers on the picked curves: its button, how many curves it takes
/// and its request for `n` of them.
struct Offer {
    label: &'static str,
    hint: &'static str,
    fits: fn(usize) -> bool,
}

const OFFERS: [Offer; 8] = [
    Offer {
        label: "Loft",
        hint: "through the picked sections, in order",
        fits: |n| n >= 2,
    },
    Offer {
        label: "Sweep 1",
        hint: "the first curve is the rail, the rest profiles",
        fits: |n| n >= 2,
    },
    Offer {
        label: "Sweep 2",
        hint: "the first two curves are rails, the rest profiles",
        fits: |n| n >= 3,
    },
    Offer {
        label: "Network",
        hint: "curves in two directions that cross, in any order",
        fits: |n| n >= 4,
    },
    Offer {
        label: "Revolve",
        hint: "each picked curve about the axis",
        fits: |n| n == 1,
    },
    Offer {
        label: "Extrude",
        hint: "along the direction below, or (two curves) along the second",
        fits: |n| n == 1 || n == 2,
    },
    Offer {
        label: "Edge surface",
        hint: "from 2, 3 or 4 edge curves (2: ruled)",
        fits: |n| (2..=4).contains(&n),
    },
    Offer {
        label: "Planar",
        hint: "a plane trimmed by closed planar curves (inner ones cut holes)",
        fits: |n| n >= 1,
    },
];

impl KnotworkApp {
    /// Asks whether to break the history of an object whose points the user began to drag
    /// (Break history is one undo step; the drag itself then starts again by hand).
    pub(super) fn history_prompt(&mut self, ctx: &egui::Context) {
        let Some(object) = self.curves.confirm_break else {
            return;
        };
        let Some(target) = self.scene().objects.get(object) else {
            self.curves.confirm_break = None;
            return;
        };
        let text = match &target.recipe {
            Some(recipe) => format!(
                "{} is the {}, and follows them. Editing its own points ends that: it will no \
                 longer follow them.",
                target.name,
                recipe.describe(self.scene())
            ),
            None => {
                self.curves.confirm_break = None;
                return;
            }
        };
        let mut answer = None;
        egui::Window::new("Edit an object that follows others?")
            .collapsible(false)
            .resizable(false)
            .anchor(egui::Align2::CENTER_CENTER, egui::Vec2::ZERO)
            .show(ctx, |ui| {
                ui.label(text);
                ui.horizontal(|ui| {
                    if ui.button("Break history").clicked() {
                        answer = Some(true);
                    }
                    if ui.button("Keep it").clicked() {
                        answer = Some(false);
                    }
                });
            });
        if let Some(answer) = answer {
            self.curves.confirm_break = None;
            if answer {
                self.apply(AppCommand::Edit(Command::BreakHistory { object }));
            }
        }
    }

    /// The request of construction `label` on `n` picked curves.
    fn offer_request(&self, label: &str, n: usize) -> serde_json::Value {
        let s = &self.curves;
        let style = match s.loft_style {
            crate::kernel::loft::LoftStyle::Normal => "normal",
            crate::kernel::loft::LoftStyle::Straight => "straight",
            crate::kernel::loft::LoftStyle::Loose => "loose",
        };
        match label {
            "Loft" => serde_json::json!({
                "construct": "loft", "curves": inputs(0..n), "degree": 3,
                "closed": s.loft_closed, "style": style,
            }),
            "Sweep 1" => serde_json::json!({
                "construct": "sweep1", "rail": {"input": 0}, "profiles": inputs(1..n),
            }),
            "Sweep 2" => serde_json::json!({
                "construct": "sweep2", "rails": inputs(0..2), "profiles": inputs(2..n),
            }),
            "Network" => serde_json::json!({"construct": "network", "curves": inputs(0..n)}),
            "Revolve" => serde_json::json!({
                "construct": "revolve", "profile": {"input": 0},
                "axis": {"origin": [0.0, 0.0, 0.0], "direction": s.revolve_axis},
                "angle": s.revolve_angle,
            }),
            "Extrude" if n == 2 => serde_json::json!({
                "construct": "extrude", "curve": {"input": 0}, "path": {"input": 1},
            }),
            "Extrude" => serde_json::json!({
                "construct": "extrude", "curve": {"input": 0}, "direction": s.extrude,
            }),
            "Edge surface" => serde_json::json!({"construct": "edge", "curves": inputs(0..n)}),
            _ => serde_json::json!({"construct": "planar", "boundary": inputs(0..n)}),
        }
    }

    /// The Curves section: drawing, the picked curves and what can be built from them, and
    /// the selected curve's edits.
    pub(super) fn curves_panel(&mut self, ui: &mut egui::Ui) {
        self.drawing_controls(ui);
        ui.separator();
        let picked = self.selection.curves.clone();
        let names: Vec<String> = picked
            .iter()
            .filter_map(|&k| self.scene().objects.get(k).map(|o| o.name.clone()))
            .collect();
        ui.label(egui::RichText::new("Surface from curves").strong());
        if names.is_empty() {
            ui.label(egui::RichText::new("Shift + click curves to pick them, in order").weak());
        } else {
            ui.horizontal_wrapped(|ui| {
                ui.label(format!("picked: {}", names.join(", ")));
                if ui.small_button("clear").clicked() {
                    self.selection.curves.clear();
                }
            });
        }
        ui.checkbox(
            &mut self.curves.keep_history,
            "Keep history (follows its curves)",
        );
        egui::CollapsingHeader::new("Options").show(ui, |ui| {
            let c = &mut self.curves;
            ui.checkbox(&mut c.loft_closed, "closed loft");
            ui.horizontal(|ui| {
                ui.label("loft");
                for style in [
                    crate::kernel::loft::LoftStyle::Normal,
                    crate::kernel::loft::LoftStyle::Straight,
                    crate::kernel::loft::LoftStyle::Loose,
                ] {
                    let label = format!("{style:?}").to_lowercase();
                    ui.radio_value(&mut c.loft_style, style, label);
                }
            });
            ui.horizontal(|ui| {
                ui.label("revolve by");
                ui.add(egui::DragValue::new(&mut c.revolve_angle).range(-360.0..=360.0));
                ui.label("° about");
            });
            super::panels::direction_editor(ui, "axis", &mut c.revolve_axis);
            super::panels::direction_editor(ui, "extrude by", &mut c.extrude);
        });
        let n = picked.len();
        let mut chosen = None;
        ui.horizontal_wrapped(|ui| {
            for offer in &OFFERS {
                let button = ui.add_enabled((offer.fits)(n), egui::Button::new(offer.label));
                if button.on_hover_text(offer.hint).clicked() {
                    chosen = Some(offer.label);
                }
            }
        });
        if let Some(label) = chosen {
            let request = self.offer_request(label, n);
            let objects = if label == "Revolve" {
                vec![picked[0]]
            } else {
                picked.clone()
            };
            self.apply(AppCommand::ConstructFrom {
                request,
                objects,
                keep_history: self.curves.keep_history,
                replace: None,
            });
        }
        self.history_controls(ui);
        self.intersect_controls(ui);
        self.project_controls(ui);
        self.curve_edit_controls(ui);
    }

    /// Intersect the selected object with another: the curves where they meet become curve
    /// objects (one undo step).
    fn intersect_controls(&mut self, ui: &mut egui::Ui) {
        let Some(s) = self.selection.object else {
            return;
        };
        let with_faces: Vec<(usize, String)> = self
            .scene()
            .objects
            .iter()
            .enumerate()
            .filter(|(k, o)| *k != s && o.kind().space_curve().is_none())
            .map(|(k, o)| (k, o.name.clone()))
            .collect();
        if with_faces.is_empty()
            || self
                .scene()
                .objects
                .get(s)
                .is_none_or(|o| o.kind().space_curve().is_some())
        {
            return;
        }
        ui.separator();
        ui.horizontal(|ui| {
            let chosen = super::surface_tools::object_choice(
                ui,
                "Intersect with",
                &mut self.curves.intersect_with,
                &with_faces,
            );
            if ui
                .button("Intersect")
                .on_hover_text("the curves where they meet, as curve objects")
                .clicked()
            {
                self.apply(AppCommand::Edit(Command::Apply {
                    operation: crate::scene::operation::Operation::new(
                        crate::ops::intersect::Intersect {
                            a: s.into(),
                            b: chosen.into(),
                        },
                    ),
                    keep_history: false,
                }));
            }
        });
    }

    /// Project the selected curve onto a surface along the view, or pull it to the surface's
    /// nearest points: the curves on the surface become curve objects (one undo step).
    fn project_controls(&mut self, ui: &mut egui::Ui) {
        let Some(s) = self.selection.object else {
            return;
        };
        if self
            .scene()
            .objects
            .get(s)
            .is_none_or(|o| o.kind().space_curve().is_none())
        {
            return;
        }
        let onto: Vec<(usize, String)> = self
            .scene()
            .objects
            .iter()
            .enumerate()
            .filter(|(_, o)| o.geometry.as_trimmed().is_some())
            .map(|(k, o)| (k, o.name.clone()))
            .collect();
        if onto.is_empty() {
            return;
        }
        ui.separator();
        let chosen =
            super::surface_tools::object_choice(ui, "Onto", &mut self.curves.project_onto, &onto);
        let camera = &self.view.camera;
        let view = (camera.target - camera.eye()).as_dvec3();
        let mut command = None;
        ui.horizontal(|ui| {
            if ui
                .button("Project")
                .on_hover_text("along the view direction, onto the surface")
                .clicked()
            {
                command = Some(Command::operation(crate::ops::project::ProjectCurves {
                    curves: vec![s.into()],
                    onto: chosen.into(),
                    direction: Some(view.to_array()),
                }));
            }
            if ui
                .button("Pull")
                .on_hover_text("each point to the nearest point of the surface")
                .clicked()
            {
                command = Some(Command::operation(crate::ops::project::ProjectCurves {
                    curves: vec![s.into()],
                    onto: chosen.into(),
                    direction: None,
                }));
            }
        });
        if let Some(command) = command {
            self.apply(AppCommand::Edit(command));
        }
    }

    fn drawing_controls(&mut self, ui: &mut egui::Ui) {
        ui.label(egui::RichText::new("Draw").strong());
        if let Some(drawing) = &self.curves.drawing {
            ui.label(format!(
                "{} · {} point(s) on the {} plane",
                drawing.kind.label(),
                drawing.points.len(),
                self.curves.plane.label()
            ));
            ui.label(
                egui::RichText::new(
                    "click to place · Enter finishes · click the first point closes · Backspace undoes · Esc cancels",
                )
                .weak(),
            );
            ui.horizontal(|ui| {
                for (label, step) in [
                    ("Finish", DrawStep::Finish { close: false }),
                    ("Close", DrawStep::Finish { close: true }),
                    ("Undo point", DrawStep::Undo),
                    ("Cancel", DrawStep::Cancel),
                ] {
                    if ui.button(label).clicked() {
                        self.apply(AppCommand::DrawCurve(step));
                    }
                }
            });
            return;
        }
        ui.horizontal(|ui| {
            egui::ComboBox::from_id_salt("draw kind")
                .selected_text(self.curves.kind.label())
                .show_ui(ui, |ui| {
                    for kind in DrawKind::ALL {
                        ui.selectable_value(&mut self.curves.kind, kind, kind.label());
                    }
                });
            ui.label("degree");
            ui.add(egui::DragValue::new(&mut self.curves.degree).range(1..=5));
        });
        ui.horizontal(|ui| {
            egui::ComboBox::from_id_salt("draw plane")
                .selected_text(self.curves.plane.label())
                .show_ui(ui, |ui| {
                    for plane in PlaneChoice::ALL {
                        ui.selectable_value(&mut self.curves.plane, plane, plane.label());
                    }
                });
            if ui.button("Draw curve").clicked() {
                self.apply(AppCommand::DrawCurve(DrawStep::Begin {
                    kind: self.curves.kind,
                    degree: self.curves.degree,
                    plane: self.curves.plane,
                }));
            }
        });
    }

    /// The selected object's construction history.
    fn history_controls(&mut self, ui: &mut egui::Ui) {
        let Some(s) = self.selection.object else {
            return;
        };
        let Some(described) = self
            .scene()
            .objects
            .get(s)
            .and_then(|o| o.recipe.as_ref())
            .map(|r| r.describe(self.scene()))
        else {
            return;
        };
        ui.horizontal_wrapped(|ui| {
            ui.label(format!("{described} (follows them)"));
            if ui.button("Break history").clicked() {
                self.apply(AppCommand::Edit(Command::BreakHistory { object: s }));
            }
        });
    }

    /// The selected curve's edits.
    fn curve_edit_controls(&mut self, ui: &mut egui::Ui) {
        let Some(s) = self.selection.object else {
            return;
        };
        let Some(curve) = self
            .scene()
            .objects
            .get(s)
            .and_then(|o| o.kind().space_curve().cloned())
        else {
            return;
        };
        ui.separator();
        ui.label(egui::RichText::new("Edit curve").strong());
        let edit = |command: Command| AppCommand::Edit(command);
        let direction = crate::kernel::Direction::U;
        // The parameter of the edited control point, where a point is picked: where the curve
        // splits; else the middle of the domain.
        let at = self
            .selection
            .points
            .iter()
            .next()
            .and_then(|&k| curve.closest_parameter(curve.control_point(k)).ok())
            .filter(|&t| {
                let (a, b) = curve.domain();
                t > a && t < b
            })
            .unwrap_or_else(|| curve.parameter_at(0.5));
        use crate::doc::CurveEdit;
        let curve_edit = |edit: CurveEdit| Command::EditCurve { object: s, edit };
        let at_point = "at the selected point's parameter, or mid-curve";
        let point = self.selection.points.iter().next().copied();
        let other = self.selection.curves.iter().find(|&&k| k != s).copied();
        // (button, hover text, command; None: not offered now).
        let offers = [
            (
                "Reverse",
                "",
                Some(Command::Reverse {
                    object: s,
                    direction,
                }),
            ),
            (
                "Insert knot",
                at_point,
                Some(Command::InsertKnot {
                    object: s,
                    direction,
                    value: at,
                }),
            ),
            (
                "Raise degree",
                "",
                Some(Command::ElevateDegree {
                    object: s,
                    direction,
                }),
            ),
            (
                "Split",
                at_point,
                Some(Command::Split {
                    object: s,
                    direction,
                    value: at,
                }),
            ),
            (
                "Remove point",
                "the selected control point",
                point.map(|point| curve_edit(CurveEdit::RemovePoint { point })),
            ),
            (
                "Close",
                "move the end onto the start",
                Some(curve_edit(CurveEdit::Close)),
            ),
            (
                "Open",
                "a periodic curve as a clamped one",
                Some(curve_edit(CurveEdit::Open)),
            ),
            (
                "Join",
                "the next picked curve onto this one's end",
                other.map(|other| curve_edit(CurveEdit::Join { other })),
            ),
        ];
        let mut commands = Vec::new();
        ui.horizontal_wrapped(|ui| {
            for (label, hint, command) in offers {
                if let Some(command) = command {
                    let button = ui.button(label);
                    let button = if hint.is_empty() {
                        button
                    } else {
                        button.on_hover_text(hint)
                    };
                    if button.clicked() {
                        commands.push(edit(command));
                    }
                }
            }
        });
        egui::CollapsingHeader::new("Curvature graph").show(ui, |ui| curvature_graph(ui, &curve));
        let plane = self.plane_for(self.curves.plane).ok();
        let normal = plane.map_or([0.0, 0.0, 1.0], |p| p.normal.to_array());
        let c = &mut self.curves;
        let mut requests = Vec::new();
        ui.horizontal(|ui| {
            ui.add(egui::DragValue::new(&mut c.rebuild_points).range(2..=200));
            ui.label("points, degree");
            ui.add(egui::DragValue::new(&mut c.rebuild_degree).range(1..=9));
            if ui.button("Rebuild").clicked() {
                let request = serde_json::json!({"construct": "rebuild", "curve": {"input": 0},
                    "points": c.rebuild_points, "degree": c.rebuild_degree});
                requests.push((request, Some(s)));
            }
        });
        ui.horizontal(|ui| {
            ui.add(
                egui::DragValue::new(&mut c.fit_tolerance)
                    .speed(1e-4)
                    .range(1e-9..=1e3),
            );
            if ui.button("Fit to tolerance").clicked() {
                let request = serde_json::json!({"construct": "fit", "curve": {"input": 0},
                    "tolerance": c.fit_tolerance});
                requests.push((request, Some(s)));
            }
        });
        ui.horizontal(|ui| {
            ui.add(egui::DragValue::new(&mut c.offset).speed(0.01));
            if ui
                .button("Offset")
                .on_hover_text("in the construction plane's normal; a new curve that follows")
                .clicked()
            {
                let request = serde_json::json!({"construct": "offset", "curve": {"input": 0},
                    "distance": c.offset, "normal": normal});
                requests.push((request, None));
            }
            ui.add(egui::DragValue::new(&mut c.extend).speed(0.01));
            if ui.button("Extend end").clicked() {
                let request = serde_json::json!({"construct": "extend", "curve": {"input": 0},
                    "length": c.extend, "end": "end"});
                requests.push((request, Some(s)));
            }
        });
        if let Some(plane) = plane
            && ui
                .button("Project onto plane")
                .on_hover_text("onto the construction plane; a new curve that follows")
                .clicked()
        {
            let request = serde_json::json!({"construct": "project", "curve": {"input": 0},
                "plane": {"origin": plane.origin.to_array(), "normal": plane.normal.to_array()}});
            requests.push((request, None));
        }
        for command in commands {
            self.apply(command);
        }
        for (request, replace) in requests {
            let keep_history = replace.is_none() && self.curves.keep_history;
            self.apply(AppCommand::ConstructFrom {
                request,
                objects: vec![s],
                keep_history,
                replace,
            });
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn drawn_curves_keep_the_clicks() {
        let clicks = [
            DVec3::ZERO,
            DVec3::new(1.0, 1.0, 0.0),
            DVec3::new(2.0, -0.5, 0.0),
            DVec3::new(3.0, 0.5, 0.0),
        ];
        let n = DVec3::Z;
        let control = drawn_curve(DrawKind::ControlPoints, 3, &clicks, false, n).unwrap();
        assert_eq!(control.count(), 4);
        assert!((0..4).all(|k| control.control_point(k) == clicks[k]));
        // Degree lowered to what two points allow.
        let line = drawn_curve(DrawKind::ControlPoints, 3, &clicks[..2], false, n).unwrap();
        assert_eq!(line.degree(), 1);
        let through = drawn_curve(DrawKind::Through, 3, &clicks, false, n).unwrap();
        for q in clicks {
            let t = through.closest_parameter(q).unwrap();
            assert!(through.point_at(t).unwrap().distance(q) < 1e-9);
        }
        let closed = drawn_curve(DrawKind::ControlPoints, 3, &clicks, true, n).unwrap();
        let (a, b) = closed.ends().unwrap();
        assert!(a.distance(b) < 1e-12);
        let polygon = drawn_curve(DrawKind::Polyline, 1, &clicks, true, n).unwrap();
        assert_eq!(polygon.count(), 5);
        // A circle about the first click through the second; an arc through all three.
        let circle = drawn_curve(DrawKind::Circle, 2, &clicks[..2], false, n).unwrap();
        let radius = 2f64.sqrt();
        for (_, k) in curvature_profile(&circle, 50) {
            assert!((k.unwrap() - 1.0 / radius).abs() < 1e-9);
        }
        let arc = drawn_curve(DrawKind::Arc, 2, &clicks[..3], false, n).unwrap();
        let (start, end) = arc.ends().unwrap();
        assert!(start.distance(clicks[0]) < 1e-12 && end.distance(clicks[2]) < 1e-12);
        let t = arc.closest_parameter(clicks[1]).unwrap();
        assert!(arc.point_at(t).unwrap().distance(clicks[1]) < 1e-9);
        // Too few points are refused with the count.
        let refused = drawn_curve(DrawKind::Arc, 2, &clicks[..2], false, n).unwrap_err();
        assert!(refused.to_string().contains('3'), "{refused}");
        assert!(drawn_curve(DrawKind::Polyline, 1, &clicks[..1], false, n).is_err());
    }

    #[test]
    fn a_plane_meets_a_ray_in_front_and_projects_points() {
        let plane = ConstructionPlane::new(DVec3::new(0.0, 0.0, 1.0), DVec3::Z * 3.0).unwrap();
        let hit = plane.hit(DVec3::new(1.0, 2.0, 5.0), DVec3::NEG_Z).unwrap();
        assert_eq!(hit, DVec3::new(1.0, 2.0, 1.0));
        assert!(plane.hit(DVec3::new(1.0, 2.0, 5.0), DVec3::Z).is_none());
        assert!(plane.hit(DVec3::ZERO, DVec3::X).is_none());
        assert_eq!(
            plane.project(DVec3::new(4.0, 5.0, 9.0)),
            DVec3::new(4.0, 5.0, 1.0)
        );
        assert!(ConstructionPlane::through(DVec3::ZERO, DVec3::X, DVec3::X * 2.0).is_none());
        assert!(ConstructionPlane::new(DVec3::NAN, DVec3::Z).is_none());
    }
}
