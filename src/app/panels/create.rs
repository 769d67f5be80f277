//! The Create dialog (primitives), the modal dialogs and the information grid.

use eframe::egui;

use crate::app::{AppCommand, KnotworkApp};
use crate::doc::Command;
use crate::doc::create::Primitive;

impl KnotworkApp {
    /// The Create dialog: a primitive from the kernel's constructors.
    pub(in crate::app) fn create_window(&mut self, ctx: &egui::Context) {
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
    pub(in crate::app) fn open_create(&mut self) {
        let p = &self.panel.create;
        let reach = p.size.max(p.height.abs()).max(0.5) * 1.1;
        let wanted = self.view.camera.target.as_dvec3();
        self.panel.create.center = self.scene().free_spot(wanted, reach);
        self.panel.show_create = true;
    }

    /// A dialog: an error (a file that could not be opened and the like) or a file opened
    /// with warnings.
    pub(in crate::app) fn dialog_window(&mut self, ctx: &egui::Context) {
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

    pub(in crate::app) fn info_grid(&self, ui: &mut egui::Ui) {
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
                    (
                        "GPU buffers",
                        format!("up to {} MiB", self.status.buffer_limit_mib),
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
}
