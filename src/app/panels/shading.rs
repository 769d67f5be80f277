//! The Shading and Analysis sections.

use eframe::egui;

use super::*;
use crate::app::KnotworkApp;
use crate::render::DRAFT_COLORS;
use crate::view::settings::{DRAFT_THRESHOLD, ISOPHOTE_SPACING, ZEBRA_PAIRS};
use crate::view::{ShadingMode, StripeFrame, ZebraSource};

impl KnotworkApp {
    pub(in crate::app) fn shading_panel(&mut self, ui: &mut egui::Ui) {
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
    pub(in crate::app) fn analysis_settings(&mut self, ui: &mut egui::Ui) {
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
}
