//! *Mass properties*: the selected body's area and, closed, its volume, centroid and inertia
//! ([`crate::kernel::mass`]), and its validity (open, non-manifold and misoriented edges, and
//! where its faces cross each other), measured on request and shown while the document is
//! unchanged.

use eframe::egui;

use crate::app::KnotworkApp;
use crate::scene::SceneObject;

/// What a measure of one object found, as the panel's lines (or why it could not).
pub fn measure(object: &SceneObject) -> Result<Vec<String>, String> {
    let body = object
        .body()
        .ok_or_else(|| format!("{} has no NURBS faces to measure", object.name))?;
    let (area, mass) = body.measure().map_err(|e| e.to_string())?;
    let mut lines = match mass {
        None => vec![
            format!("area {area:.6}"),
            "open (naked edges): no volume".into(),
        ],
        Some(m) => {
            let c = m.centroid;
            let i = m.inertia;
            vec![
                format!("area {:.6}", m.area),
                format!("volume {:.6}", m.volume),
                format!("centroid ({:.6}, {:.6}, {:.6})", c.x, c.y, c.z),
                format!(
                    "inertia (unit density, about the centroid) Ixx {:.6}, Iyy {:.6}, Izz {:.6}, Ixy {:.6}, Iyz {:.6}, Izx {:.6}",
                    i.x_axis.x, i.y_axis.y, i.z_axis.z, i.y_axis.x, i.z_axis.y, i.x_axis.z
                ),
            ]
        }
    };
    if let Some(v) = &body.validity
        && (!v.non_manifold.is_empty() || !v.misoriented.is_empty())
    {
        lines.push(format!(
            "{} edge(s) shared by more than two faces, {} whose faces cannot be turned to agree",
            v.non_manifold.len(),
            v.misoriented.len()
        ));
    }
    lines.push(self_intersection_line(&body.faces));
    Ok(lines)
}

/// Whether the faces cross each other ([`crate::kernel::boolean::self_intersections`] at 1e-6
/// of their size), and where the first crossings are.
fn self_intersection_line(faces: &[crate::kernel::TrimmedSurface]) -> String {
    let (lo, hi) = faces.iter().map(|f| f.surface().bounds()).fold(
        (glam::DVec3::INFINITY, glam::DVec3::NEG_INFINITY),
        |(lo, hi), (l, h)| (lo.min(l), hi.max(h)),
    );
    let tolerance = 1e-6 * lo.distance(hi).max(f64::MIN_POSITIVE);
    match crate::kernel::boolean::self_intersections(faces, tolerance) {
        Ok(found) if found.is_empty() => "no self-intersection".into(),
        Ok(found) => {
            let places: Vec<String> = found
                .iter()
                .take(3)
                .map(|c| {
                    format!(
                        "faces {} and {} near ({:.4}, {:.4}, {:.4})",
                        c.faces.0 + 1,
                        c.faces.1 + 1,
                        c.at.x,
                        c.at.y,
                        c.at.z
                    )
                })
                .collect();
            format!(
                "self-intersecting: {} crossing(s): {}{}",
                found.len(),
                places.join("; "),
                if found.len() > 3 { "; …" } else { "" }
            )
        }
        Err(e) => format!("self-intersection not checked: {e}"),
    }
}

impl KnotworkApp {
    /// The Measure button and, for the selected object at the document's present revision,
    /// what it measured.
    pub(in crate::app) fn mass_panel(&mut self, ui: &mut egui::Ui, s: usize) {
        ui.separator();
        ui.label(egui::RichText::new("Mass properties").strong());
        let revision = self.saved.revision;
        let current = self
            .panel
            .measured
            .as_ref()
            .filter(|(object, at, _)| *object == s && *at == revision);
        match current.map(|(_, _, lines)| lines.clone()) {
            Some(Ok(lines)) => {
                for line in lines {
                    ui.label(line);
                }
            }
            Some(Err(e)) => {
                ui.colored_label(egui::Color32::from_rgb(255, 110, 100), e);
            }
            None => {
                if ui
                    .button("Measure")
                    .on_hover_text(
                        "area, and for a closed body volume, centroid and inertia (exact); \
                         whether its faces cross each other",
                    )
                    .clicked()
                    && let Some(object) = self.scene().objects.get(s)
                {
                    self.panel.measured = Some((s, revision, measure(object)));
                }
            }
        }
    }
}
