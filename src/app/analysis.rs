//! The editor's analysis overlays and panel: curvature combs and principal directions on the
//! selected surface, continuity hair on every shared edge with its table (a row frames its
//! edge), and the ground grid; the lines are rebuilt only when what they show changes.

use eframe::egui::{self, Ui};

use super::KnotworkApp;
use crate::kernel::continuity::Continuity;
use crate::render::GuideLines;
use crate::render::guides::{
    continuity_hair, curvature_combs, ground_grid, principal_directions, verdict_meets,
};
use crate::scene::continuity::{ContinuityOptions, ContinuityReport, analyse};
use crate::scene::{Scene, SceneObject};
use crate::view::settings::COMB_DENSITY;
use crate::view::{AnalysisSettings, CombCurves, ContinuityTarget};

/// The colour of a polysurface's naked edges (magenta, as CAD tools draw them).
const NAKED_EDGE_COLOR: [f32; 4] = [0.95, 0.2, 0.85, 1.0];
/// A selected cage edge (Blender's selection orange).
const SELECTED_EDGE_COLOR: [f32; 4] = [1.0, 0.55, 0.1, 1.0];

/// What the overlays were last built from, and the lines.
#[derive(Default)]
pub(super) struct AnalysisState {
    /// The selected object (with its displacement and lattice), the settings and the size the
    /// combs and directions were built for, and those lines.
    selected: Option<(SceneObject, AnalysisSettings, f64, GuideLines)>,
    /// The scene and options the continuity report was made for.
    continuity: Option<(Scene, ContinuityOptions, ContinuityReport)>,
    /// The lines the renderer holds.
    uploaded: Option<GuideLines>,
    /// The grid's minor step in the last frame.
    pub grid_step: f64,
}

impl KnotworkApp {
    /// The continuity report of the current scene (made again only when the scene or the
    /// tolerances change).
    pub(super) fn continuity_report(&mut self) -> &ContinuityReport {
        let options = self.view.analysis.continuity_options();
        let stale = self
            .analysis
            .continuity
            .as_ref()
            .is_none_or(|(scene, o, _)| *o != options || scene != &self.doc.scene);
        if stale {
            self.analysis.continuity = None;
        }
        let (_, _, report) = self.analysis.continuity.get_or_insert_with(|| {
            let report = analyse(&self.doc.scene, None, &options);
            (self.doc.scene.clone(), options, report)
        });
        report
    }

    /// The continuity status: edges, how many meet the target, each verdict.
    pub(super) fn continuity_summary(&mut self) -> crate::status::ContinuityStatus {
        let target = self.view.analysis.continuity_target;
        let report = self.continuity_report();
        crate::status::ContinuityStatus {
            edges: report.edges.len() as u32,
            passing: report
                .edges
                .iter()
                .filter(|e| verdict_meets(e.verdict, target))
                .count() as u32,
            verdicts: report
                .edges
                .iter()
                .map(|e| e.verdict.name().to_owned())
                .collect(),
        }
    }

    /// Every line overlay for this frame: grid, combs, directions, polysurfaces' naked edges,
    /// the selected cage's creases and selected edges, continuity hair.
    pub(super) fn guide_lines(&mut self) -> GuideLines {
        let mut lines = GuideLines::default();
        if self.view.overlays.grid {
            let (grid, step) = ground_grid(&self.view.camera);
            lines.extend(&grid);
            self.analysis.grid_step = step;
        }
        let a = self.view.analysis;
        // The selected geometry is only looked at (and cloned for the cache) when it is shown.
        let shown = a.combs != CombCurves::None || a.principal_directions;
        let selected = self
            .selection
            .object
            .filter(|_| shown)
            .and_then(|s| self.scene().objects.get(s))
            .filter(|o| o.visible);
        if let Some(object) = selected {
            // Combs scale with the object itself: at scale 1 the longest hair is a tenth of
            // its own box's diagonal, whatever else is in the scene.
            let size = object
                .bounds()
                .map_or(1.0, |(lo, hi)| lo.distance(hi).max(1e-12));
            let fresh = self
                .analysis
                .selected
                .as_ref()
                .is_some_and(|(o, s, z, _)| o == object && *s == a && *z == size);
            if !fresh {
                let mut built = GuideLines::default();
                if a.combs != CombCurves::None {
                    built.extend(&curvature_combs(object, &a, size));
                }
                if a.principal_directions {
                    built.extend(&principal_directions(object, a.direction_density));
                }
                self.analysis.selected = Some((object.clone(), a, size, built));
            }
            if let Some((_, _, _, built)) = &self.analysis.selected {
                lines.extend(built);
            }
        }
        // A polysurface's naked edges (those no other face shares), always: where it is open.
        for object in self.scene().objects.iter().filter(|o| o.visible) {
            if let Some(p) = object.geometry.as_polysurface() {
                for edge in p.naked_edges().iter() {
                    for w in edge.windows(2) {
                        lines.depth_tested(w[0], w[1], NAKED_EDGE_COLOR);
                    }
                }
            }
        }
        // The selected cage's creases and selected edges (both ends selected), over the
        // surface.
        if let Some(subdiv) = self
            .selection
            .object
            .and_then(|s| self.scene().objects.get(s))
            .filter(|o| o.visible && self.view.overlays.points)
            .and_then(|o| o.geometry.as_subdivision())
        {
            let mesh = subdiv.surface.mesh();
            let points = mesh.points();
            let selected = |v: u32| self.selection.points.contains(&(v as usize));
            // Creased edges (colour by sharpness, white to magenta at 10 and beyond),
            // then the selection over them.
            for c in subdiv.surface.creases() {
                let t = (c.sharpness / 10.0).clamp(0.0, 1.0) as f32;
                let color = [1.0, 1.0 - 0.85 * t, 1.0 - 0.2 * t, 1.0];
                if let (Some(&p), Some(&q)) = (points.get(c.a as usize), points.get(c.b as usize)) {
                    lines.on_top(p, q, color);
                }
            }
            for face in mesh.faces() {
                for c in 0..face.len() {
                    let (p, q) = (face[c], face[(c + 1) % face.len()]);
                    if selected(p) && selected(q) {
                        lines.on_top(points[p as usize], points[q as usize], SELECTED_EDGE_COLOR);
                    }
                }
            }
        }
        if a.continuity {
            let report = self.continuity_report();
            lines.extend(&continuity_hair(
                &report.edges,
                &report.tolerances,
                a.continuity_target,
                report.size,
            ));
        }
        lines
    }

    /// Hands this frame's lines to the renderer if they changed; true when they did.
    pub(super) fn upload_guide_lines(&mut self) -> bool {
        let lines = self.guide_lines();
        if self.analysis.uploaded.as_ref() == Some(&lines) {
            return false;
        }
        if let Some(gpu) = &mut self.gpu {
            gpu.renderer.set_lines(&gpu.device, &gpu.queue, &lines);
        }
        self.analysis.uploaded = Some(lines);
        true
    }

    /// Keeps a panel's change of the analysis settings if they are valid (and redraws), else
    /// puts `before` back.
    pub(super) fn accept_analysis_edit(&mut self, before: AnalysisSettings) {
        if self.view.analysis == before {
            return;
        }
        if self.view.analysis.validate().is_ok() {
            self.redraw = true;
        } else {
            self.view.analysis = before;
        }
    }

    /// The Analysis section: combs, principal directions and continuity (tolerances, target,
    /// the table of shared edges).
    pub(super) fn analysis_panel(&mut self, ui: &mut Ui) {
        ui.label(egui::RichText::new("Analysis").strong());
        let before = self.view.analysis;
        let a = &mut self.view.analysis;
        super::panels::choice(
            ui,
            "curvature combs",
            &mut a.combs,
            &[
                (CombCurves::None, "off"),
                (CombCurves::U, "along u"),
                (CombCurves::V, "along v"),
                (CombCurves::Both, "u and v"),
            ],
        );
        let nothing = self.selection.object.is_none();
        if nothing && (a.combs != CombCurves::None || a.principal_directions) {
            ui.label(
                egui::RichText::new(
                    "select an object: combs and directions show on the selected one",
                )
                .color(egui::Color32::from_rgb(240, 200, 90)),
            );
        }
        if a.combs != CombCurves::None {
            ui.horizontal(|ui| {
                ui.label("curves");
                ui.add(egui::DragValue::new(&mut a.comb_density).range(COMB_DENSITY));
                ui.label("scale");
                ui.add(
                    egui::DragValue::new(&mut a.comb_scale)
                        .range(0.01..=100.0)
                        .speed(0.02),
                );
                ui.checkbox(&mut a.comb_boundary, "edges");
            });
        }
        ui.horizontal(|ui| {
            ui.checkbox(&mut a.principal_directions, "principal directions");
            if a.principal_directions {
                ui.add(egui::DragValue::new(&mut a.direction_density).range(COMB_DENSITY));
                ui.label("k1 warm, k2 cool");
            }
        });
        ui.checkbox(&mut a.continuity, "continuity on shared edges");
        if a.continuity {
            super::panels::choice(
                ui,
                "asks for",
                &mut a.continuity_target,
                &[
                    (ContinuityTarget::G0, "G0 (position)"),
                    (ContinuityTarget::G1, "G1 (tangency)"),
                    (ContinuityTarget::G2, "G2 (curvature)"),
                ],
            );
            ui.horizontal(|ui| {
                ui.label("gap");
                ui.add(
                    egui::DragValue::new(&mut a.gap_tolerance)
                        .range(1e-9..=0.1)
                        .speed(1e-5)
                        .custom_formatter(|v, _| format!("{v:.1e}")),
                )
                .on_hover_text("of the scene's size");
                ui.label("angle");
                ui.add(
                    egui::DragValue::new(&mut a.angle_tolerance)
                        .range(1e-4..=45.0)
                        .speed(0.05)
                        .suffix("°"),
                );
                ui.label("curvature");
                ui.add(
                    egui::DragValue::new(&mut a.curvature_tolerance)
                        .range(1e-4..=10.0)
                        .speed(0.005),
                );
            });
        }
        self.accept_analysis_edit(before);
        if self.view.analysis.continuity {
            self.continuity_table(ui);
        }
    }

    /// One row per shared edge: faces, verdict, the three maxima; a click frames the edge.
    fn continuity_table(&mut self, ui: &mut Ui) {
        let target = self.view.analysis.continuity_target;
        self.continuity_report();
        let Some((_, _, report)) = &self.analysis.continuity else {
            return;
        };
        let scene = &self.doc.scene;
        if report.edges.is_empty() {
            ui.label("no shared edges (boundaries within 1 % of the scene's size)");
            return;
        }
        let failing = report
            .edges
            .iter()
            .filter(|e| !verdict_meets(e.verdict, target))
            .count();
        ui.label(format!(
            "{} shared edges, {} below the target",
            report.edges.len(),
            failing
        ));
        let mut framed = None;
        // Scrolls both ways inside the panel's width, so that long face names never widen the
        // panel (and move the outliner under the cursor); rows do not wrap.
        let width = ui.available_width();
        egui::ScrollArea::both()
            .id_salt("continuity table")
            .max_width(width)
            .max_height(260.0)
            .auto_shrink([false, true])
            .show(ui, |ui| {
                ui.style_mut().wrap_mode = Some(egui::TextWrapMode::Extend);
                egui::Grid::new("continuity rows")
                    .striped(true)
                    .num_columns(5)
                    .show(ui, |ui| {
                        for heading in ["edge", "", "gap", "angle", "Δκ"] {
                            ui.label(egui::RichText::new(heading).small().strong());
                        }
                        ui.end_row();
                        for (k, e) in report.edges.iter().enumerate() {
                            let name = format!(
                                "{} {} · {} {}",
                                report.face_name(scene, e.a.0),
                                e.a.1.name(),
                                report.face_name(scene, e.b.0),
                                e.b.1.name()
                            );
                            if ui
                                .selectable_label(false, egui::RichText::new(name).small())
                                .on_hover_text("frame this edge")
                                .clicked()
                            {
                                framed = Some(k);
                            }
                            let color = if verdict_meets(e.verdict, target) {
                                egui::Color32::from_rgb(90, 210, 110)
                            } else {
                                egui::Color32::from_rgb(240, 90, 80)
                            };
                            ui.colored_label(color, e.verdict.name());
                            ui.label(
                                egui::RichText::new(format!("{:.2e}", e.max_gap.value)).small(),
                            );
                            ui.label(
                                egui::RichText::new(format!("{:.3}°", e.max_angle_degrees.value))
                                    .small(),
                            );
                            let curvature = if e.verdict >= Continuity::G0 {
                                format!(
                                    "{:.1} %",
                                    100.0 * e.max_relative_curvature_difference.value
                                )
                            } else {
                                "–".to_owned()
                            };
                            ui.label(egui::RichText::new(curvature).small());
                            ui.end_row();
                        }
                    });
            });
        if let Some(k) = framed {
            self.frame_edge(k);
        }
    }

    /// Frames shared edge `k` of the continuity report: the box of its samples, padded by a
    /// tenth of the scene's size.
    pub(super) fn frame_edge(&mut self, k: usize) {
        let Some((_, _, report)) = &self.analysis.continuity else {
            return;
        };
        let Some(edge) = report.edges.get(k) else {
            return;
        };
        let points = edge.samples.iter().map(|s| s.point);
        let lo = points.clone().reduce(glam::DVec3::min);
        let hi = points.reduce(glam::DVec3::max);
        if let (Some(lo), Some(hi)) = (lo, hi) {
            let pad = glam::DVec3::splat(0.1 * report.size);
            let aspect = self.viewport_rect.aspect_ratio().max(0.1);
            self.start_camera_move(|camera| {
                camera.frame((lo - pad).as_vec3(), (hi + pad).as_vec3(), aspect);
            });
        }
    }
}
