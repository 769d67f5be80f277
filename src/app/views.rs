//! The viewport habits of CAD tools: standard views (orthographic, from the keypad as in
//! Blender: 1 front, 3 right, 7 top, Ctrl for the opposite, 5 orthographic/perspective, `.`
//! frames the selection), smooth camera transitions, and the axis triad in the corner, whose
//! axis ends are clickable views.

use std::f32::consts::{FRAC_PI_2, PI};

use eframe::egui::{self, Pos2, Ui};
use glam::Vec3;

use super::KnotworkApp;
use crate::view::OrbitCamera;

/// How long a camera transition takes, in seconds.
const TRANSITION: f64 = 0.25;

/// A camera transition under way.
#[derive(Debug, Clone, Copy)]
pub(super) struct CameraMove {
    from: OrbitCamera,
    to: OrbitCamera,
    /// When it started (egui's clock, seconds); `None` until the first frame sees it.
    start: Option<f64>,
}

/// A standard view: where the camera looks from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StandardView {
    Top,
    Bottom,
    Front,
    Back,
    Right,
    Left,
    /// The default three-quarter perspective.
    Perspective,
}

impl StandardView {
    pub const ALL: [StandardView; 7] = [
        StandardView::Top,
        StandardView::Bottom,
        StandardView::Front,
        StandardView::Back,
        StandardView::Right,
        StandardView::Left,
        StandardView::Perspective,
    ];

    /// The name in the menu, the page's API and the status: "top", "bottom", "front", "back",
    /// "right", "left", "perspective".
    pub fn name(self) -> &'static str {
        match self {
            StandardView::Top => "top",
            StandardView::Bottom => "bottom",
            StandardView::Front => "front",
            StandardView::Back => "back",
            StandardView::Right => "right",
            StandardView::Left => "left",
            StandardView::Perspective => "perspective",
        }
    }

    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|v| v.name() == name)
    }

    /// The name in the menu and on the panel's buttons.
    pub fn label(self) -> &'static str {
        match self {
            StandardView::Top => "Top",
            StandardView::Bottom => "Bottom",
            StandardView::Front => "Front",
            StandardView::Back => "Back",
            StandardView::Right => "Right",
            StandardView::Left => "Left",
            StandardView::Perspective => "Perspective",
        }
    }

    /// The keypad key, as the menu shows it.
    pub fn shortcut(self) -> &'static str {
        match self {
            StandardView::Top => "7",
            StandardView::Bottom => "Ctrl+7",
            StandardView::Front => "1",
            StandardView::Back => "Ctrl+1",
            StandardView::Right => "3",
            StandardView::Left => "Ctrl+3",
            StandardView::Perspective => "0",
        }
    }

    /// (yaw, pitch, orthographic): front looks along +Y (X right, Z up), right along −X (Y
    /// right), top down −Z (X right, Y up), as in Blender and Rhino.
    pub fn orientation(self) -> (f32, f32, bool) {
        match self {
            StandardView::Top => (-FRAC_PI_2, FRAC_PI_2, true),
            StandardView::Bottom => (-FRAC_PI_2, -FRAC_PI_2, true),
            StandardView::Front => (-FRAC_PI_2, 0.0, true),
            StandardView::Back => (FRAC_PI_2, 0.0, true),
            StandardView::Right => (0.0, 0.0, true),
            StandardView::Left => (PI, 0.0, true),
            StandardView::Perspective => {
                let d = OrbitCamera::default();
                (d.yaw, d.pitch, false)
            }
        }
    }

    /// The standard view `camera` is in (orientation and projection), if any.
    pub fn of(camera: &OrbitCamera) -> Option<Self> {
        Self::ALL.into_iter().find(|v| {
            let (yaw, pitch, ortho) = v.orientation();
            let turn = (camera.yaw - yaw + PI).rem_euclid(2.0 * PI) - PI;
            ortho == camera.orthographic
                && (camera.pitch - pitch).abs() < 1e-4
                && (turn.abs() < 1e-4 || pitch.abs() == FRAC_PI_2 && camera.pitch == pitch)
        })
    }
}

impl KnotworkApp {
    /// Moves the camera smoothly to what `change` makes of it.
    pub(super) fn start_camera_move(&mut self, change: impl FnOnce(&mut OrbitCamera)) {
        let from = self.view.camera;
        let mut to = from;
        change(&mut to);
        self.camera_move = Some(CameraMove {
            from,
            to,
            start: None,
        });
        self.redraw = true;
    }

    /// Turns the camera to a standard view (keeping its target and distance).
    pub fn set_standard_view(&mut self, view: StandardView) {
        let (yaw, pitch, orthographic) = view.orientation();
        self.start_camera_move(|c| {
            c.yaw = yaw;
            c.pitch = pitch;
            c.orthographic = orthographic;
        });
        self.status.view = view.name().to_owned();
    }

    /// Switches between orthographic and perspective projection.
    pub fn toggle_orthographic(&mut self) {
        self.finish_camera_move();
        self.view.camera.orthographic = !self.view.camera.orthographic;
        self.redraw = true;
    }

    fn finish_camera_move(&mut self) {
        if let Some(m) = self.camera_move.take() {
            self.view.camera = m.to;
        }
    }

    /// Advances a camera transition to time `now` (seconds); asks for the next frame while it
    /// runs.
    pub(super) fn step_camera_move(&mut self, ctx: &egui::Context) {
        let Some(mut m) = self.camera_move else {
            return;
        };
        let now = ctx.input(|i| i.time);
        let start = *m.start.get_or_insert(now);
        let t = ((now - start) / TRANSITION) as f32;
        // Ease in and out.
        let eased = t.clamp(0.0, 1.0);
        let eased = eased * eased * (3.0 - 2.0 * eased);
        self.view.camera = m.from.interpolate(&m.to, eased);
        self.camera_move = if t >= 1.0 { None } else { Some(m) };
        if self.camera_move.is_some() {
            ctx.request_repaint();
        }
        self.redraw = true;
    }

    /// Frames the selected points, else the selected object, else everything.
    pub(super) fn frame_selection(&mut self) {
        let aspect = self.viewport_rect.aspect_ratio().max(0.1);
        let bounds = match self.selection.object {
            Some(s) if !self.selection.points.is_empty() => {
                let points = self.scene().objects[s].control_points();
                let chosen = self
                    .selection
                    .points
                    .iter()
                    .filter_map(|&k| points.get(k).copied());
                let lo = chosen.clone().reduce(glam::DVec3::min);
                let hi = chosen.reduce(glam::DVec3::max);
                lo.zip(hi).map(|(lo, hi)| {
                    // A single point gets a box a twentieth of the object's size.
                    let pad = self.scene().objects[s]
                        .bounds()
                        .map_or(0.1, |(a, b)| 0.05 * a.distance(b));
                    (lo - glam::DVec3::splat(pad), hi + glam::DVec3::splat(pad))
                })
            }
            Some(s) => self.scene().objects[s].bounds(),
            None => self.scene().bounds(),
        };
        if let Some((lo, hi)) = bounds {
            self.start_camera_move(|c| c.frame(lo.as_vec3(), hi.as_vec3(), aspect));
        }
    }

    /// The keypad shortcuts (also the number row): 1 / 3 / 7 front, right, top (Ctrl: back,
    /// left, bottom), 5 orthographic ↔ perspective, 0 perspective, `.` frame the selection.
    pub(super) fn view_shortcuts(&mut self, ctx: &egui::Context) {
        if ctx.egui_wants_keyboard_input() {
            return;
        }
        use egui::{Key, KeyboardShortcut, Modifiers};
        let pressed = |m: Modifiers, k: Key| {
            ctx.input_mut(|i| i.consume_shortcut(&KeyboardShortcut::new(m, k)))
        };
        for (key, view, opposite) in [
            (Key::Num1, StandardView::Front, StandardView::Back),
            (Key::Num3, StandardView::Right, StandardView::Left),
            (Key::Num7, StandardView::Top, StandardView::Bottom),
        ] {
            if pressed(Modifiers::COMMAND, key) {
                self.set_standard_view(opposite);
            } else if pressed(Modifiers::NONE, key) {
                self.set_standard_view(view);
            }
        }
        if pressed(Modifiers::NONE, Key::Num5) {
            self.toggle_orthographic();
        }
        if pressed(Modifiers::NONE, Key::Num0) {
            self.set_standard_view(StandardView::Perspective);
        }
        if pressed(Modifiers::NONE, Key::Period) {
            self.frame_selection();
        }
    }

    /// The View menu's items.
    pub(super) fn view_menu(&mut self, ui: &mut Ui) {
        for view in StandardView::ALL {
            let label = format!("{} ({})", view.label(), view.shortcut());
            if ui.button(label).clicked() {
                self.set_standard_view(view);
                ui.close();
            }
        }
        ui.separator();
        let projection = if self.view.camera.orthographic {
            "Perspective projection (5)"
        } else {
            "Orthographic projection (5)"
        };
        if ui.button(projection).clicked() {
            self.toggle_orthographic();
            ui.close();
        }
        if ui.button("Frame selection (.)").clicked() {
            self.frame_selection();
            ui.close();
        }
        if ui.button("Frame all (F)").clicked() {
            self.frame_pending = true;
            ui.close();
        }
        ui.separator();
        let before = self.view.overlays;
        ui.checkbox(&mut self.view.overlays.grid, "Ground grid");
        ui.checkbox(&mut self.view.overlays.axes, "Axis triad");
        if self.view.overlays != before {
            self.redraw = true;
        }
    }

    /// The axis triad in the viewport's lower left corner: X red, Y green, Z blue as the
    /// camera sees them, the positive ends labelled; clicking an end looks along that axis
    /// (the view from that side, orthographic).
    pub(super) fn axis_triad(&mut self, ui: &Ui) {
        if !self.view.overlays.axes {
            return;
        }
        let rect = self.viewport_rect;
        let centre = Pos2::new(rect.left() + 52.0, rect.bottom() - 52.0);
        let (right, up, back) = self.view.camera.axes();
        let length = 34.0;
        let axes = [
            (
                Vec3::X,
                egui::Color32::from_rgb(230, 70, 60),
                "X",
                StandardView::Right,
                StandardView::Left,
            ),
            (
                Vec3::Y,
                egui::Color32::from_rgb(110, 200, 70),
                "Y",
                StandardView::Back,
                StandardView::Front,
            ),
            (
                Vec3::Z,
                egui::Color32::from_rgb(80, 140, 240),
                "Z",
                StandardView::Top,
                StandardView::Bottom,
            ),
        ];
        // Farthest first, so nearer ends are drawn over them.
        let mut ends: Vec<(f32, Pos2, egui::Color32, &str, StandardView, bool)> = Vec::new();
        for (axis, color, name, positive, negative) in axes {
            for (sign, view) in [(1.0, positive), (-1.0, negative)] {
                let a = axis * sign;
                let offset = egui::vec2(a.dot(right), -a.dot(up)) * length;
                ends.push((a.dot(back), centre + offset, color, name, view, sign > 0.0));
            }
        }
        ends.sort_by(|a, b| a.0.total_cmp(&b.0));
        let painter = ui.painter().with_clip_rect(rect);
        painter.circle_filled(centre, length + 12.0, egui::Color32::from_black_alpha(60));
        let mut clicked = None;
        for (k, (_, end, color, name, view, positive)) in ends.iter().enumerate() {
            if *positive {
                painter.line_segment([centre, *end], egui::Stroke::new(2.0, *color));
                painter.circle_filled(*end, 8.0, *color);
                painter.text(
                    *end,
                    egui::Align2::CENTER_CENTER,
                    *name,
                    egui::FontId::proportional(11.0),
                    egui::Color32::BLACK,
                );
            } else {
                painter.circle_stroke(*end, 6.0, egui::Stroke::new(1.5, *color));
            }
            let response = ui.interact(
                egui::Rect::from_center_size(*end, egui::vec2(16.0, 16.0)),
                ui.scope_id().with(("axis triad", k)),
                egui::Sense::click(),
            );
            if response
                .on_hover_text(format!("{} view", view.name()))
                .clicked()
            {
                clicked = Some(*view);
            }
        }
        if let Some(view) = clicked {
            self.set_standard_view(view);
        }
    }
}
