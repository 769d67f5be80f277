//! The triangular patch and subdivision sections: a cage's rules, level, display and creases.

use eframe::egui;

use super::*;
use crate::app::{AppCommand, KnotworkApp};
use crate::doc::Command;
use crate::kernel::subdiv::adaptive::DEFAULT_TOLERANCE;
use crate::kernel::subdiv::patches::Display;
use crate::kernel::subdiv::{MAX_LEVEL, Options, Scheme};
use crate::scene::SubdivSettings;

impl KnotworkApp {
    /// A triangular Bézier patch: its degree and *Elevate degree* (the shape stays).
    pub(in crate::app) fn triangle_panel(&mut self, ui: &mut egui::Ui) {
        let Some(s) = self.selection.object else {
            return;
        };
        let Some(patch) = self.scene().objects[s].kind().triangle_patch() else {
            return;
        };
        let degree = patch.degree();
        ui.separator();
        ui.label(egui::RichText::new("Triangular patch").strong());
        ui.label(format!(
            "degree {degree}, {} points; drag points to shape it",
            patch.points().len()
        ));
        if ui
            .add_enabled(
                degree < crate::kernel::triangle::MAX_TRIANGLE_DEGREE,
                egui::Button::new("Elevate degree"),
            )
            .on_hover_text("one degree more, the same surface (more points to shape it with)")
            .clicked()
        {
            self.apply(AppCommand::Edit(Command::ElevateDegree {
                object: s,
                direction: crate::kernel::Direction::U,
            }));
        }
    }

    /// Subdivision: "Subdivide" for a polygon mesh; rules, level, display and the sharpness of
    /// the selected edge (its two points) or point for a subdivision surface.
    pub(in crate::app) fn subdivision_panel(&mut self, ui: &mut egui::Ui) {
        let Some(s) = self.selection.object else {
            return;
        };
        let geometry = &self.scene().objects[s].geometry;
        let before = match geometry.as_subdivision() {
            Some(surface) => surface.settings(),
            // A cage that is not subdivided yet (a polygon mesh).
            None if geometry.kind().cage().is_some() => {
                ui.separator();
                ui.label(egui::RichText::new("Subdivision").strong());
                self.subdivide_button(ui, s);
                return;
            }
            None => return,
        };
        ui.separator();
        ui.label(egui::RichText::new("Subdivision").strong());
        let mut settings = before.clone();
        subdivision_rules(ui, &mut settings.options);
        self.subdivision_display(ui, s, &mut settings);
        ui.add(egui::Slider::new(&mut settings.level, 0..=MAX_LEVEL).text("level"));
        self.sharpness_editor(ui, &mut settings);
        if settings != before {
            self.apply(AppCommand::Edit(Command::SetSubdivision {
                object: s,
                settings,
            }));
        }
        self.cage_tools_panel(ui, s);
    }

    /// Turns polygon mesh `s` into a Catmull-Clark surface of level 2.
    pub(in crate::app) fn subdivide_button(&mut self, ui: &mut egui::Ui, s: usize) {
        if ui
            .button("Subdivide")
            .on_hover_text("show the mesh as a Catmull-Clark surface, level 2")
            .clicked()
        {
            let settings = SubdivSettings {
                options: Options::default(),
                level: 2,
                display: Display::Limit,
                tolerance: DEFAULT_TOLERANCE,
                creases: Vec::new(),
                corners: Vec::new(),
            };
            self.apply(AppCommand::Edit(Command::SetSubdivision {
                object: s,
                settings,
            }));
        }
    }

    /// The display (the limit, the refined mesh, a substitute the scheme has, the adaptive
    /// limit and its tolerance) and what it means.
    pub(in crate::app) fn subdivision_display(
        &self,
        ui: &mut egui::Ui,
        s: usize,
        settings: &mut SubdivSettings,
    ) {
        // The efficient substitutes offered are those of the scheme they approximate.
        let mut displays = vec![
            (Display::Limit, "limit surface"),
            (Display::Refined, "refined mesh"),
        ];
        match settings.options.scheme {
            Scheme::CatmullClark => displays.extend([
                (Display::Acc, "ACC patches (bicubic + tangent patches)"),
                (Display::Gregory, "Gregory patches (ACC-2)"),
            ]),
            Scheme::Loop => displays.push((Display::PnTriangles, "PN triangles")),
            _ => {}
        }
        if !matches!(settings.options.scheme, Scheme::DooSabin | Scheme::Sqrt3) {
            displays.push((Display::Adaptive, "adaptive limit (refined where not flat)"));
        }
        if !displays.iter().any(|(d, _)| *d == settings.display) {
            // The scheme changed under a display it does not have: show the limit.
            settings.display = Display::Limit;
        }
        choice(ui, "display", &mut settings.display, &displays);
        if settings.display == Display::Adaptive {
            // The tolerance in percent of the cage's diagonal, on a logarithmic slider.
            let mut percent = settings.tolerance * 100.0;
            ui.add(
                egui::Slider::new(&mut percent, 0.005..=5.0)
                    .logarithmic(true)
                    .suffix(" %")
                    .text("flatness tolerance"),
            )
            .on_hover_text(
                "a piece is refined until its level's limit points lie within this distance \
                 (a share of the cage's diagonal) of its triangles, up to the level",
            );
            settings.tolerance = percent / 100.0;
            if let Some(surface) = self.scene().objects[s].geometry.as_subdivision()
                && let Ok(Some(layout)) = surface.adaptive_layout()
            {
                ui.label(
                    egui::RichText::new(format!(
                        "pieces per level: {}; refined again when a drag ends; \
                         shading \"Refinement level\" colours them",
                        layout.describe()
                    ))
                    .weak(),
                );
            }
        }
        if let Some(kind) = settings.display.substitute() {
            let scope = if kind.is_triangle() {
                "one cubic triangle per face through the limit points and normals"
            } else {
                "one patch per quad; faces at boundaries, creases and sharp points keep the \
                 exact limit"
            };
            ui.label(
                egui::RichText::new(format!(
                    "{}: an approximation of the limit, {scope}",
                    kind.label()
                ))
                .weak(),
            );
        }
    }

    /// The sharpness of the selected edges (both points of each selected) or point (one).
    pub(in crate::app) fn sharpness_editor(
        &self,
        ui: &mut egui::Ui,
        settings: &mut SubdivSettings,
    ) {
        let points: Vec<u32> = self.selection.points.iter().map(|&p| p as u32).collect();
        // The cage edges both of whose points are selected.
        let edges = self
            .selection
            .object
            .filter(|_| points.len() >= 2)
            .and_then(|s| self.scene().objects.get(s))
            .and_then(super::cage::cage_of)
            .map(|cage| cage.edges_within(&points.iter().copied().collect()))
            .unwrap_or_default();
        match (&edges[..], &points[..]) {
            ([(a, b), ..], _) => {
                let before = settings.crease(*a, *b);
                let mut sharpness = before;
                let text = match edges[..] {
                    [_] => format!("edge {a}-{b} sharpness"),
                    _ => format!("sharpness of {} edges", edges.len()),
                };
                ui.add(egui::Slider::new(&mut sharpness, 0.0..=10.0).text(text));
                if sharpness != before {
                    for &(a, b) in &edges {
                        settings.set_crease(a, b, sharpness);
                    }
                }
            }
            ([], [vertex]) => {
                let vertex = *vertex;
                let mut sharpness = settings.corner(vertex);
                ui.add(
                    egui::Slider::new(&mut sharpness, 0.0..=10.0)
                        .text(format!("point {vertex} sharpness")),
                );
                if sharpness != settings.corner(vertex) {
                    settings.set_corner(vertex, sharpness);
                }
            }
            _ => {
                ui.label(
                    egui::RichText::new(
                        "select edges (both their points) or one point to set sharpness; \
                         0 removes it, 10 is infinitely sharp",
                    )
                    .weak(),
                );
            }
        }
        ui.label(format!(
            "{} creases, {} sharp points",
            settings.creases.len(),
            settings.corners.len()
        ));
    }
}
