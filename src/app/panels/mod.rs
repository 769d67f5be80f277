//! The side panel: file and history buttons, the outliner, the selected object's properties
//! (points, weights, knots, degree, split, reverse, transform), the Create dialog, shading,
//! display and timing.

pub mod cage;
mod create;
mod deform;
pub mod kinds;
mod measure;
mod objects;
mod properties;
mod shading;
mod subdivision;

use eframe::egui;

use super::{AppCommand, KnotworkApp};
use crate::doc::create::PrimitiveParams;
use crate::gpu::records::CURVATURE_RAMP;
use crate::kernel::Direction;
use crate::kernel::subdiv::{Boundary, Creasing, Options, Scheme};
use crate::scene::SceneObject;
use crate::view::{QUALITY_RANGE, TOLERANCE_RANGE};

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
    /// The last mass properties measured: the object, the document's revision then, and the
    /// lines to show (or why it could not be measured).
    pub measured: Option<(usize, u64, Result<Vec<String>, String>)>,
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
            measured: None,
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
    /// Carries out `command` for the panel's widget `widget` ("weight", "knots", …): a refusal
    /// shows beside that widget ([`Self::widget_error`]) as well as in the toast.
    pub(in crate::app) fn apply_from(&mut self, widget: &'static str, command: AppCommand) {
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
    pub(in crate::app) fn widget_error(&self, ui: &mut egui::Ui, widget: &str) {
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
    pub(in crate::app) fn refresh_fields(&mut self) {
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

    /// Adaptive or fixed tessellation, the adaptive error and the quality factor.
    pub(in crate::app) fn tessellation_panel(&mut self, ui: &mut egui::Ui) {
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
                self.kind_panels(ui);
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
