//! Displacement and free-form deformation lattices of the selected object.

use eframe::egui;

use super::*;
use crate::app::{AppCommand, KnotworkApp};
use crate::doc::Command;

impl KnotworkApp {
    /// Displacement along the normal for objects with a (u, v) domain: pattern, amplitude,
    /// frequency; each change one undo step.
    pub(in crate::app) fn displacement_panel(&mut self, ui: &mut egui::Ui) {
        use crate::kernel::displace::{Displacement, Pattern};
        let Some(s) = self.selection.object else {
            return;
        };
        let object = &self.scene().objects[s];
        if object.geometry.displacement_domain().is_none() {
            return;
        }
        let before = object.displacement.clone();
        let size = object
            .bounds()
            .map_or(1.0, |(lo, hi)| lo.distance(hi).max(1e-9));
        ui.separator();
        ui.label(egui::RichText::new("Displacement").strong());
        let mut pattern = before.as_ref().map(|d| d.pattern);
        let mut options: Vec<(Option<Pattern>, &str)> = vec![(None, "none")];
        options.extend(Pattern::ALL.map(|p| (Some(p), p.label())));
        options.push((Some(Pattern::Image), "image…"));
        choice(ui, "height map", &mut pattern, &options);
        let image = before.as_ref().and_then(|d| d.image.clone());
        if pattern == Some(Pattern::Image) && image.is_none() {
            // The image comes from a file: the picker, then `use_height_image`.
            self.height_image_dialog();
            return;
        }
        let mut after = pattern.map(|p| {
            let (amplitude, frequency) = before
                .as_ref()
                .map_or((0.02 * size, 4.0), |d| (d.amplitude, d.frequency));
            Displacement {
                pattern: p,
                amplitude,
                frequency,
                image: if p == Pattern::Image {
                    image.clone()
                } else {
                    None
                },
            }
        });
        let mut reload = false;
        if let Some(d) = &mut after {
            ui.horizontal(|ui| {
                ui.label("amplitude");
                ui.add(egui::DragValue::new(&mut d.amplitude).speed(0.002 * size));
                ui.label("frequency");
                ui.add(
                    egui::DragValue::new(&mut d.frequency)
                        .range(0.25..=crate::kernel::displace::MAX_FREQUENCY)
                        .speed(0.1),
                );
            });
            if let Some(image) = &d.image {
                ui.horizontal(|ui| {
                    ui.label(format!(
                        "{} × {} pixels, tiled frequency × frequency times",
                        image.width(),
                        image.height()
                    ));
                    if ui.button("Other image…").clicked() {
                        reload = true;
                    }
                });
            }
            ui.label(
                egui::RichText::new(
                    "moves the surface along its normal by amplitude × a pattern over its \
                     (u, v) (an image: 2 × grey − 1, mid-grey stays put); shown with its own \
                     normals (no curvature); exported with 8 segments per cycle (an image: \
                     one per pixel)",
                )
                .weak(),
            );
        }
        if reload {
            self.height_image_dialog();
            return;
        }
        if after != before {
            self.apply(AppCommand::Edit(Command::SetDisplacement {
                object: s,
                displacement: after,
            }));
        }
    }

    /// Free-form deformation: *Add lattice* of chosen degrees around the selected object and
    /// the other objects ticked (one lattice they share); while it has one, *Reset* (the
    /// undisturbed lattice), *Release* (the undeformed objects) and *Apply* (baked into them,
    /// exactly or refitted within the tolerance; the status says which), each for every object
    /// sharing it. The lattice's points are the handles meanwhile.
    pub(in crate::app) fn lattice_panel(&mut self, ui: &mut egui::Ui) {
        use crate::kernel::ffd::MAX_LATTICE_DEGREE;
        let Some(s) = self.selection.object else {
            return;
        };
        let current = self.scene().objects[s].lattice.clone();
        ui.separator();
        ui.label(egui::RichText::new("Lattice (free-form deformation)").strong());
        let mut degrees = self.lattice_degrees;
        let mut tolerance = self.lattice_tolerance;
        let (mut command, mut add, mut apply) = (None, false, false);
        match &current {
            None => {
                ui.horizontal(|ui| {
                    ui.label("degrees");
                    for d in &mut degrees {
                        ui.add(egui::DragValue::new(d).range(1..=MAX_LATTICE_DEGREE));
                    }
                });
                // Other objects the lattice goes around too.
                let others: Vec<(usize, String)> = self
                    .scene()
                    .objects
                    .iter()
                    .enumerate()
                    .filter(|(k, o)| *k != s && o.visible && o.lattice.is_none())
                    .map(|(k, o)| (k, o.name.clone()))
                    .collect();
                if !others.is_empty() {
                    ui.label("also around");
                    for (k, name) in others {
                        let mut on = self.lattice_also.contains(&k);
                        if ui.checkbox(&mut on, name).changed() {
                            if on {
                                self.lattice_also.insert(k);
                            } else {
                                self.lattice_also.remove(&k);
                            }
                        }
                    }
                }
                if ui
                    .button("Add lattice")
                    .on_hover_text(
                        "a trivariate Bézier lattice around the object (and those ticked): \
                         drag its points and the surfaces follow",
                    )
                    .clicked()
                {
                    add = true;
                }
            }
            Some(lattice) => {
                let [l, m, n] = lattice.degrees();
                let shared = self.scene().linked_lattices(s).len();
                ui.label(format!(
                    "degree ({l}, {m}, {n}), {} points: drag them like handles; the map's \
                     degree is {}{}",
                    lattice.points().len(),
                    lattice.total_degree(),
                    if shared > 1 {
                        format!("; shared by {shared} objects")
                    } else {
                        String::new()
                    }
                ));
                ui.horizontal(|ui| {
                    if ui.button("Reset").clicked()
                        && let Ok(reset) = lattice.reset()
                    {
                        command = Some(Some(reset));
                    }
                    if ui
                        .button("Release")
                        .on_hover_text("remove the lattice: the objects as they were")
                        .clicked()
                    {
                        command = Some(None);
                    }
                });
                ui.horizontal(|ui| {
                    ui.label("tolerance");
                    ui.add(
                        egui::DragValue::new(&mut tolerance)
                            .range(1e-6..=0.1)
                            .speed(1e-4),
                    )
                    .on_hover_text("for a refit: a share of the object's size");
                    if ui
                        .button("Apply")
                        .on_hover_text(
                            "bake the deformation into the objects: exact where the degree \
                             allows, else refitted within the tolerance",
                        )
                        .clicked()
                    {
                        apply = true;
                    }
                });
            }
        }
        self.lattice_degrees = degrees;
        self.lattice_tolerance = tolerance;
        if add {
            let mut objects = vec![s];
            objects.extend(self.lattice_also.iter().copied().filter(|&k| k != s));
            self.lattice_also.clear();
            self.add_lattice(&objects, degrees);
        } else if apply {
            self.apply(AppCommand::Edit(Command::ApplyLattice {
                object: s,
                tolerance,
            }));
        } else if let Some(lattice) = command {
            self.set_linked_lattice(s, lattice);
        }
    }
}
