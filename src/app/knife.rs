//! The knife on a cage (K, as Blender's Knife with Cut Through): a line dragged across the
//! viewport cuts every face of the cage under it, front and back, along the plane through the
//! line and the eye. Esc or a right click leaves the cage as it was.

use eframe::egui;
use glam::{DVec2, DVec3};

use super::KnotworkApp;
use super::panels::cage::{After, cage_of};
use crate::kernel::subdiv::cage_edit::{Cage, Tool};
use crate::view::pick::PickView;

/// A knife being drawn on cage `object`: the line's first end once the drag began.
pub(super) struct KnifeLine {
    object: usize,
    start: Option<egui::Pos2>,
}

/// The knife along the screen line from `a` to `b` (viewport pixels) as `view` sees it: the
/// plane through the line and the eye, cutting the faces of `cage` that an edge crossing the
/// plane within the line's ends belongs to.
pub fn knife_across(cage: &Cage, view: &PickView, a: DVec2, b: DVec2) -> Result<Tool, String> {
    if a.distance(b) < 2.0 {
        return Err("drag a line across the cage to cut it".into());
    }
    let (near_a, dir_a) = view.ray(a);
    let (near_b, _) = view.ray(b);
    let normal = (near_b - near_a).cross(dir_a);
    let Some(normal) = normal.try_normalize() else {
        return Err("the knife's line has no plane in this view".into());
    };
    let side = |p: DVec3| (p - near_a).dot(normal);
    let along = b - a;
    let within = |p: DVec3| {
        view.project(p).is_some_and(|s| {
            let t = (s.screen - a).dot(along) / along.length_squared();
            (0.0..=1.0).contains(&t)
        })
    };
    let faces: Vec<usize> = (0..cage.faces.len())
        .filter(|&f| {
            let face = &cage.faces[f];
            (0..face.len()).any(|c| {
                let (p, q) = (
                    cage.points[face[c] as usize],
                    cage.points[face[(c + 1) % face.len()] as usize],
                );
                let (dp, dq) = (side(p), side(q));
                dp * dq < 0.0 && within(p + (q - p) * (dp / (dp - dq)))
            })
        })
        .collect();
    if faces.is_empty() {
        return Err("the knife's line crosses no face of the cage".into());
    }
    Ok(Tool::Knife {
        faces,
        point: near_a.to_array(),
        normal: normal.to_array(),
        threshold: None,
    })
}

impl KnotworkApp {
    /// K on a cage: the next left drag draws the knife's line.
    pub(super) fn begin_knife(&mut self) {
        if let Some(object) = self.selection.object {
            self.knife = Some(KnifeLine {
                object,
                start: None,
            });
            self.status.notice =
                Some("knife: drag a line across the cage to cut it (Esc cancels)".into());
        }
    }

    /// The pointer while the knife is out: a left drag draws its line, the release cuts.
    pub(super) fn knife_input(&mut self, ui: &egui::Ui, response: &egui::Response) {
        let (escape, secondary, origin) = ui.input(|i| {
            (
                i.key_pressed(egui::Key::Escape),
                i.pointer.button_clicked(egui::PointerButton::Secondary),
                i.pointer.press_origin(),
            )
        });
        self.redraw = true;
        if escape || secondary {
            self.knife = None;
            self.status.notice = Some("knife put away: nothing cut".into());
            return;
        }
        let Some(knife) = &mut self.knife else {
            return;
        };
        if response.drag_started_by(egui::PointerButton::Primary) {
            knife.start = origin;
        }
        if !response.drag_stopped() {
            return;
        }
        let (object, start) = (knife.object, knife.start);
        let (Some(start), Some(end)) = (start, response.interact_pointer_pos()) else {
            return;
        };
        self.knife = None;
        let (Some(view), Some(cage)) = (
            self.pick_view,
            self.scene().objects.get(object).and_then(cage_of),
        ) else {
            return;
        };
        match knife_across(&cage, &view, self.local(start), self.local(end)) {
            Ok(tool) => self.apply_cage_tool(object, tool, After::Nothing),
            Err(e) => self.status.error = Some(e),
        }
    }

    /// The knife's line, from where the drag began to the pointer.
    pub(super) fn paint_knife(&self, ui: &egui::Ui) {
        let Some(KnifeLine {
            start: Some(start), ..
        }) = &self.knife
        else {
            return;
        };
        if let Some(now) = ui.input(|i| i.pointer.hover_pos()) {
            ui.painter().line_segment(
                [*start, now],
                egui::Stroke::new(1.5, egui::Color32::from_rgb(255, 220, 40)),
            );
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The top view, parallel, 800 × 600 pixels: the plane through a screen line and the eye
    /// is the vertical plane over the line.
    fn top_view() -> PickView {
        let camera = crate::view::camera::OrbitCamera {
            pitch: std::f32::consts::FRAC_PI_2,
            orthographic: true,
            distance: 5.0,
            ..Default::default()
        };
        PickView::new(camera.view_projection(800.0 / 600.0), 800.0, 600.0)
    }

    /// Two unit squares side by side along x, from x = −1 to 1.
    fn two_squares() -> Cage {
        Cage {
            points: [
                (-1.0, 0.0),
                (0.0, 0.0),
                (1.0, 0.0),
                (1.0, 1.0),
                (0.0, 1.0),
                (-1.0, 1.0),
            ]
            .iter()
            .map(|&(x, y)| DVec3::new(x, y, 0.0))
            .collect(),
            faces: vec![vec![0, 1, 4, 5], vec![1, 2, 3, 4]],
            ..Cage::default()
        }
    }

    #[test]
    fn the_knife_cuts_the_faces_under_its_line_along_the_plane_through_the_eye() {
        let view = top_view();
        let cage = two_squares();
        let screen = |x: f64, y: f64| view.project(DVec3::new(x, y, 0.0)).unwrap().screen;
        // A vertical screen line over x = 0.5 from below to above the squares: the right one
        // only, along the plane x = 0.5.
        let tool = knife_across(&cage, &view, screen(0.5, -0.5), screen(0.5, 1.5)).unwrap();
        let Tool::Knife {
            faces,
            point,
            normal,
            ..
        } = &tool
        else {
            panic!("{tool:?}");
        };
        assert_eq!(faces, &[1]);
        let normal = DVec3::from_array(*normal);
        assert!(normal.x.abs() > 1.0 - 1e-6, "{normal}");
        // The view is in f32: a ten-thousandth of a unit is a fiftieth of a pixel here.
        assert!((DVec3::from_array(*point).x - 0.5).abs() < 1e-4);
        let cut = cage.apply(&tool).unwrap();
        assert_eq!((cut.points.len(), cut.faces.len()), (8, 3));
        // A line stopping short of the squares cuts nothing, with the reason.
        let short = knife_across(&cage, &view, screen(0.5, 2.0), screen(0.5, 3.0));
        assert!(short.unwrap_err().contains("crosses no face"));
        // A line that only ends over the left square, half way up, crosses one of its edges
        // within the line: that square is named, and its plane (x = −0.5) cuts it in two.
        let tool = knife_across(&cage, &view, screen(-0.5, -0.5), screen(-0.5, 0.5)).unwrap();
        assert!(matches!(&tool, Tool::Knife { faces, .. } if faces == &[0]));
        assert_eq!(cage.apply(&tool).unwrap().faces.len(), 3);
    }
}
