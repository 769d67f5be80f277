//! The file bar and the outliner: open, save, export, undo; the objects with their names, visibility and colours.

use eframe::egui;
use glam::{DAffine3, DQuat, DVec3};

use crate::app::export::FileExport;
use crate::app::{AppCommand, KnotworkApp, SLIDER_SEGMENTS};
use crate::doc::Command;
use crate::scene::LengthUnit;

impl KnotworkApp {
    /// New, open, save, undo and redo.
    pub(in crate::app) fn file_bar(&mut self, ui: &mut egui::Ui) {
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
                self.export_file_to_path(FileExport::Step);
            }
            ui.menu_button("Export STL / 3MF", |ui| {
                for (format, what) in [
                    (FileExport::Stl, "binary STL: closed bodies watertight, normals outward"),
                    (
                        FileExport::ThreeMf,
                        "3MF: the document's unit and each object's colour, closed bodies watertight",
                    ),
                ] {
                    if ui
                        .button(format!("Export {}…", format.label()))
                        .on_hover_text(what)
                        .clicked()
                    {
                        self.export_file_to_path(format);
                    }
                }
            });
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
    pub(in crate::app) fn color_row(&mut self, ui: &mut egui::Ui, s: usize) {
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
    pub(in crate::app) fn objects_panel(&mut self, ui: &mut egui::Ui) {
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
                    AppCommand::Edit(Command::operation(crate::ops::transform::Transform::new(
                        s, &transform,
                    ))),
                );
                self.panel.reset_transform();
            }
            self.widget_error(ui, "transform");
        });
    }
}
