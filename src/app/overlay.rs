//! What the viewport says by itself: a toolbar over the canvas (standard views, shading,
//! framing, help), a one-line navigation hint, the `?` overlay with the controls, and toasts
//! that show an error where the eye is, whichever widget or script caused it.

use eframe::egui;

use super::KnotworkApp;
use super::views::StandardView;
use crate::view::ShadingMode;

/// The controls the `?` overlay lists, which are exactly the README's Controls table (a test
/// compares the two); the book's Controls chapter has the full table.
pub const CONTROLS: [(&str, &str); 16] = [
    ("right drag", "orbit"),
    ("middle drag, or Shift + right drag", "pan"),
    ("wheel, pinch", "zoom"),
    (
        "click a handle; Shift + click",
        "select a control point; add or remove it",
    ),
    ("drag a handle", "move the selection in the view plane"),
    (
        "X / Y / Z while dragging",
        "keep to that axis (Shift: the plane normal to it); Esc cancels",
    ),
    ("drag on empty space", "box select"),
    (
        "click the surface",
        "select the object and read (u, v) there",
    ),
    (
        "Shift + click curves",
        "pick them, in order, for a surface from curves",
    ),
    ("W / E / R", "gizmo: move / rotate / scale"),
    ("Ctrl + Z; Ctrl + Shift + Z or Ctrl + Y", "undo; redo"),
    ("F; .", "frame the scene; frame the selection"),
    (
        "7 / 1 / 3; 5",
        "top / front / right view (on a cage, 1 / 2 / 3 pick the select mode); orthographic or perspective",
    ),
    (
        "Ctrl + S; Ctrl + O; Ctrl + E",
        "save; open (or drop a file); export glTF",
    ),
    ("Ctrl + D; Delete", "duplicate; delete the selected object"),
    ("?", "show or hide this list"),
];

/// The navigation hint at the bottom of the viewport.
pub const NAVIGATION_HINT: &str =
    "right drag: orbit · middle or Shift + right drag: pan · wheel: zoom · F: frame · ?: controls";

/// How long an error's toast stays (seconds).
const ERROR_SECONDS: f64 = 12.0;

/// The shading modes the toolbar offers (the Shading panel has them all).
const TOOLBAR_SHADING: [(ShadingMode, &str); 5] = [
    (ShadingMode::Plain, "Plain"),
    (ShadingMode::Mean, "Mean"),
    (ShadingMode::Gaussian, "Gauss"),
    (ShadingMode::Zebra, "Zebra"),
    (ShadingMode::Isophotes, "Iso"),
];

/// The error a toast shows and since when (egui's clock).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Toast {
    pub text: String,
    pub since: f64,
}

impl KnotworkApp {
    /// The toolbar, hint, toasts and `?` overlay over the viewport `rect`.
    pub(super) fn viewport_overlays(&mut self, ui: &egui::Ui, rect: egui::Rect) {
        let ctx = ui.ctx().clone();
        if !ctx.egui_wants_keyboard_input()
            && ctx.input_mut(|i| {
                i.consume_key(egui::Modifiers::SHIFT, egui::Key::Questionmark)
                    || i.consume_key(egui::Modifiers::NONE, egui::Key::Questionmark)
            })
        {
            self.show_help = !self.show_help;
        }
        self.toolbar(&ctx, rect);
        if self.doc.drag().is_none() {
            ui.painter().text(
                rect.center_bottom() + egui::vec2(0.0, -8.0),
                egui::Align2::CENTER_BOTTOM,
                NAVIGATION_HINT,
                egui::FontId::proportional(12.5),
                egui::Color32::from_gray(150),
            );
        }
        self.toast(&ctx, rect);
        self.help_overlay(&ctx, rect);
    }

    /// Views, shading and framing in a row over the canvas's top-left corner.
    fn toolbar(&mut self, ctx: &egui::Context, rect: egui::Rect) {
        egui::Area::new(egui::Id::unique("viewport toolbar"))
            .fixed_pos(rect.left_top() + egui::vec2(8.0, 8.0))
            .order(egui::Order::Foreground)
            .show(ctx, |ui| {
                egui::Frame::popup(ui.style()).show(ui, |ui| {
                    ui.horizontal(|ui| {
                        for view in [
                            StandardView::Top,
                            StandardView::Front,
                            StandardView::Right,
                            StandardView::Perspective,
                        ] {
                            let label = match view {
                                StandardView::Perspective => "Persp",
                                other => other.label(),
                            };
                            if ui
                                .small_button(label)
                                .on_hover_text(format!(
                                    "{} view ({})",
                                    view.name(),
                                    view.shortcut()
                                ))
                                .clicked()
                            {
                                self.set_standard_view(view);
                            }
                        }
                        ui.separator();
                        for (mode, label) in TOOLBAR_SHADING {
                            if ui
                                .selectable_label(self.view.shading == mode, label)
                                .on_hover_text(format!("{} shading", mode.label()))
                                .clicked()
                            {
                                self.set_shading(mode);
                            }
                        }
                        ui.separator();
                        if ui
                            .small_button("Frame")
                            .on_hover_text("frame the scene (F)")
                            .clicked()
                        {
                            self.frame_pending = true;
                        }
                        if ui
                            .selectable_label(self.show_help, " ? ")
                            .on_hover_text("the controls (?)")
                            .clicked()
                        {
                            self.show_help = !self.show_help;
                        }
                    });
                });
            });
    }

    /// The newest error over the viewport's top edge, until it times out or is closed (the
    /// panel keeps it, and the notices, at its end).
    fn toast(&mut self, ctx: &egui::Context, rect: egui::Rect) {
        let now = ctx.input(|i| i.time);
        match &self.status.error {
            Some(text) if *text != self.toast.text => {
                self.toast = Toast {
                    text: text.clone(),
                    since: now,
                };
            }
            Some(_) => {}
            None => self.toast = Toast::default(),
        }
        let age = now - self.toast.since;
        if self.toast.text.is_empty() || age > ERROR_SECONDS {
            return;
        }
        ctx.request_repaint_after(std::time::Duration::from_secs_f64(
            (ERROR_SECONDS - age).max(0.05),
        ));
        let (fill, title) = (egui::Color32::from_rgb(120, 36, 36), "Error");
        let mut close = false;
        egui::Area::new(egui::Id::unique("viewport toast"))
            .fixed_pos(rect.center_top() + egui::vec2(-230.0, 48.0))
            .order(egui::Order::Foreground)
            .show(ctx, |ui| {
                egui::Frame::popup(ui.style()).fill(fill).show(ui, |ui| {
                    ui.set_max_width(460.0);
                    ui.horizontal(|ui| {
                        ui.label(
                            egui::RichText::new(title)
                                .strong()
                                .color(egui::Color32::WHITE),
                        );
                        ui.label(egui::RichText::new(&self.toast.text).color(egui::Color32::WHITE));
                        close = ui.small_button("×").on_hover_text("dismiss").clicked();
                    });
                });
            });
        if close {
            self.toast.since = f64::NEG_INFINITY;
            self.status.error = None;
        }
    }

    /// The controls, over the viewport, while `?` is on.
    fn help_overlay(&mut self, ctx: &egui::Context, rect: egui::Rect) {
        if !self.show_help {
            return;
        }
        let mut open = true;
        egui::Window::new("Controls")
            .open(&mut open)
            .collapsible(false)
            .resizable(false)
            .default_pos(rect.right_top() + egui::vec2(-430.0, 48.0))
            .show(ctx, |ui| {
                egui::Grid::new("controls grid")
                    .num_columns(2)
                    .striped(true)
                    .show(ui, |ui| {
                        for (input, action) in CONTROLS {
                            ui.label(egui::RichText::new(input).strong());
                            ui.label(action);
                            ui.end_row();
                        }
                    });
                ui.label(
                    egui::RichText::new("The manual's Controls chapter has every shortcut.").weak(),
                );
            });
        self.show_help &= open;
    }
}
