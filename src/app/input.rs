//! Viewport input: picking and dragging control points, box selection, clicking the surface,
//! the camera, and the keyboard shortcuts.
//!
//! Left click: pick a control point of the selected object (Shift toggles it, Alt takes its
//! row, Alt + Shift its column) or, off the handles, the surface under the cursor (which
//! selects that object and reports (u, v)); on a cage in edge or face mode, the edge or face
//! under the cursor. Left drag on a handle: move the selection in the view plane (X / Y / Z:
//! along an axis; Shift + X / Y / Z: in a plane; Esc cancels). Left drag elsewhere: box select
//! (Shift adds). Ctrl + right drag: lasso select (Shift adds). Right drag: orbit; middle drag
//! or Shift + right drag: pan.

use eframe::egui;
use glam::{DVec2, DVec3};

use super::{AppCommand, DragHandle, DragStep, KnotworkApp, PICK_RADIUS};

/// Shift + E on a cage, as in Blender: the pointer's distance from the selection's centre on
/// the screen sets the selected edges' sharpness (nearer: sharper), a click or Enter sets it
/// as one undo step, Esc or a right click leaves it as it was.
pub(super) struct CreaseDrag {
    object: usize,
    edges: Vec<(u32, u32)>,
    /// The selected points' centre on the screen and the pointer's first distance from it.
    centre: egui::Pos2,
    start: f32,
    /// The first edge's sharpness when it began, and the value now.
    initial: f64,
    value: f64,
}
use crate::view::follow;
use crate::view::pick::{self, Constraint, Projected};

impl KnotworkApp {
    /// The selected object's control points on the screen (logical pixels from the viewport's
    /// top-left corner).
    pub(super) fn projected_handles(&self) -> Vec<Option<Projected>> {
        let (Some(view), Some(s)) = (self.pick_view, self.selection.object) else {
            return Vec::new();
        };
        if !self.scene().objects[s].visible {
            return Vec::new();
        }
        self.scene().objects[s]
            .control_points()
            .iter()
            .map(|&p| view.project(p))
            .collect()
    }

    /// The control point of the selected object under `cursor` (viewport pixels).
    fn handle_at(&self, cursor: DVec2) -> Option<usize> {
        if !self.view.overlays.points {
            return None;
        }
        pick::pick_point(&self.projected_handles(), cursor, PICK_RADIUS)
    }

    pub(super) fn local(&self, pos: egui::Pos2) -> DVec2 {
        DVec2::new(
            f64::from(pos.x - self.viewport_rect.left()),
            f64::from(pos.y - self.viewport_rect.top()),
        )
    }

    /// A click in the viewport at `pos`.
    fn click(&mut self, pos: egui::Pos2, modifiers: egui::Modifiers) {
        let (shift, alt) = (modifiers.shift, modifiers.alt);
        let cursor = self.local(pos);
        if self.curve_click(cursor) {
            return;
        }
        if alt && self.cage_edge_click(cursor, modifiers.command, shift) {
            return;
        }
        if !alt && self.cage_pick_click(cursor, shift) {
            return;
        }
        if let Some(index) = self.handle_at(cursor) {
            if alt {
                self.select_row(index, shift);
            } else if shift {
                if !self.selection.points.remove(&index) {
                    self.selection.points.insert(index);
                }
            } else {
                self.selection.points = [index].into();
            }
            self.selection.edit_point = index;
            self.update_net();
            return;
        }
        let Some(view) = self.pick_view else {
            return;
        };
        // A curve under the cursor wins over the surface behind it.
        if self.trim_drawing.is_none()
            && let Some(curve) = self.curve_at(cursor)
        {
            self.click_curve(curve, shift);
            return;
        }
        let (origin, direction) = view.ray(cursor);
        let Some(gpu) = &self.gpu else {
            return;
        };
        let objects: Vec<_> = gpu
            .sync
            .feeds()
            .iter()
            .zip(&self.doc.scene.objects)
            .map(|(d, o)| (d, o.visible))
            .collect();
        let hit = pick::pick_surface(&objects, origin, direction);
        let face = hit.map(|h| h.point);
        if self.feature_click(cursor, shift, face) {
            return;
        }
        self.selection.hit = hit;
        if self.trim_click(self.selection.hit) || self.trim_pick_click(self.selection.hit) {
            return;
        }
        if !shift {
            self.selection.curves.clear();
        }
        match self.selection.hit {
            Some(hit) => {
                if self.selection.object != Some(hit.object) {
                    self.select(Some(hit.object));
                } else if !shift {
                    self.selection.points.clear();
                    self.update_net();
                }
            }
            None if !shift => {
                if self.selection.points.is_empty() {
                    self.select(None);
                } else {
                    self.selection.points.clear();
                    self.update_net();
                }
            }
            None => {}
        }
        self.redraw = true;
    }

    /// The selected object's cage, where it is a subdivision surface.
    fn selected_cage(&self) -> Option<crate::kernel::subdiv::cage_edit::Cage> {
        self.selection
            .object
            .and_then(|s| self.scene().objects.get(s))
            .and_then(super::panels::cage::cage_of)
    }

    /// Alt + click on an edge of the selected cage: its edge loop (`ring`: its ring; `add`:
    /// added to the selection). False where no cage edge is under the cursor.
    fn cage_edge_click(&mut self, cursor: DVec2, ring: bool, add: bool) -> bool {
        if !self.view.overlays.points {
            return false;
        }
        let Some(cage) = self.selected_cage() else {
            return false;
        };
        let edges = cage.edges();
        let handles = self.projected_handles();
        let Some(k) = pick::pick_segment(&handles, &edges, cursor, PICK_RADIUS) else {
            return false;
        };
        let (a, b) = edges[k];
        self.select_edge_loop(&cage, a, b, ring, add);
        true
    }

    /// A click on the selected cage in edge or face mode: the points of the edge or face
    /// under the cursor become the selection (`toggle`: they are added, or taken away where
    /// all of them were selected). False in vertex mode or where nothing is under the cursor.
    fn cage_pick_click(&mut self, cursor: DVec2, toggle: bool) -> bool {
        use super::panels::cage::SelectMode;
        let mode = self.cage_tools.select_mode;
        if mode == SelectMode::Vertex || !self.view.overlays.points {
            return false;
        }
        let Some(cage) = self.selected_cage() else {
            return false;
        };
        let handles = self.projected_handles();
        let picked: Vec<usize> = match mode {
            SelectMode::Edge => {
                let edges = cage.edges();
                let Some(k) = pick::pick_segment(&handles, &edges, cursor, PICK_RADIUS) else {
                    return false;
                };
                vec![edges[k].0 as usize, edges[k].1 as usize]
            }
            _ => {
                let Some(f) = pick::pick_face(&handles, &cage.faces, cursor) else {
                    return false;
                };
                cage.faces[f].iter().map(|&v| v as usize).collect()
            }
        };
        if !toggle {
            self.selection.points.clear();
        }
        if toggle && picked.iter().all(|p| self.selection.points.contains(p)) {
            for p in &picked {
                self.selection.points.remove(p);
            }
        } else {
            self.selection.points.extend(picked.iter().copied());
        }
        if let Some(&last) = picked.last() {
            self.selection.edit_point = last;
        }
        self.update_net();
        true
    }

    /// Selects the row (fixed i, along v) through point `index` of a NURBS net, or with
    /// `column` the column (fixed j, along u); `add` keeps the current selection.
    pub(super) fn select_row(&mut self, index: usize, column: bool) {
        let Some(object) = self.selection.object.map(|s| &self.doc.scene.objects[s]) else {
            return;
        };
        let Some([nu, nv]) = object.net_grid() else {
            self.status.error = Some(format!(
                "rows and columns need a rectangular net; {} is {}",
                object.name,
                object.kind().kind_name()
            ));
            return;
        };
        let (i, j) = (index / nv, index % nv);
        self.selection.points = if column {
            (0..nu).map(|i| i * nv + j).collect()
        } else {
            (0..nv).map(|j| i * nv + j).collect()
        };
        self.update_net();
    }

    /// Shift + E: begins setting the selected cage edges' sharpness by the pointer.
    fn begin_crease_drag(&mut self, pointer: Option<egui::Pos2>) {
        let Some(object) = self.selection.object else {
            return;
        };
        let Some(cage) = self.selected_cage() else {
            return;
        };
        let points: std::collections::BTreeSet<u32> =
            self.selection.points.iter().map(|&p| p as u32).collect();
        let edges = cage.edges_within(&points);
        if edges.is_empty() {
            self.status.error = Some("select edges (both their points) to crease them".into());
            return;
        }
        let handles = self.projected_handles();
        let on_screen: Vec<DVec2> = points
            .iter()
            .filter_map(|&p| handles.get(p as usize).copied().flatten())
            .map(|p| p.screen)
            .collect();
        if on_screen.is_empty() {
            return;
        }
        let mean = on_screen.iter().sum::<DVec2>() / on_screen.len() as f64;
        let centre = self.viewport_rect.left_top() + egui::vec2(mean.x as f32, mean.y as f32);
        let start = pointer.map_or(100.0, |p| p.distance(centre)).max(20.0);
        let initial = self.scene().objects[object]
            .geometry
            .as_subdivision()
            .map_or(0.0, |s| s.settings().crease(edges[0].0, edges[0].1));
        self.crease_drag = Some(CreaseDrag {
            object,
            edges,
            centre,
            start,
            initial,
            value: initial,
        });
        self.crease_notice();
    }

    fn crease_notice(&mut self) {
        if let Some(drag) = &self.crease_drag {
            self.status.notice = Some(format!(
                "crease {:.2} on {} edges: move towards the centre for sharper; click or Enter \
                 sets it, Esc cancels",
                drag.value,
                drag.edges.len()
            ));
        }
    }

    /// The pointer during a crease drag: the value follows it; a click or Enter sets it.
    fn crease_drag_input(&mut self, ui: &egui::Ui, response: &egui::Response) {
        let (pointer, enter, escape, primary, secondary) = ui.input(|i| {
            (
                i.pointer.hover_pos(),
                i.key_pressed(egui::Key::Enter),
                i.key_pressed(egui::Key::Escape),
                i.pointer.button_clicked(egui::PointerButton::Primary),
                i.pointer.button_clicked(egui::PointerButton::Secondary),
            )
        });
        let Some(drag) = &mut self.crease_drag else {
            return;
        };
        if let Some(p) = pointer {
            let nearer = 1.0 - f64::from(p.distance(drag.centre) / drag.start);
            drag.value = (drag.initial + 10.0 * nearer).clamp(0.0, 10.0);
        }
        self.redraw = true;
        if escape || secondary {
            self.crease_drag = None;
            self.status.notice = Some("crease left as it was".into());
            return;
        }
        if enter || primary || response.clicked() {
            let Some(drag) = self.crease_drag.take() else {
                return;
            };
            let Some(mut settings) = self.scene().objects[drag.object]
                .geometry
                .as_subdivision()
                .map(|s| s.settings())
            else {
                return;
            };
            for &(a, b) in &drag.edges {
                settings.set_crease(a, b, drag.value);
            }
            self.apply(AppCommand::Edit(crate::doc::Command::SetSubdivision {
                object: drag.object,
                settings,
            }));
            self.status.notice = Some(format!(
                "crease {:.2} set on {} edges",
                drag.value,
                drag.edges.len()
            ));
            return;
        }
        self.crease_notice();
    }

    /// Starts dragging the selection from handle `index`: a transient edit of the document.
    fn begin_drag(&mut self, index: usize, shift: bool) {
        let Some(object) = self.selection.object else {
            return;
        };
        if self.scene().objects[object].has_history() {
            // Its shape comes from its curves: ask before its own points move.
            self.curves.confirm_break = Some(object);
            return;
        }
        if !self.selection.points.contains(&index) {
            if !shift {
                self.selection.points.clear();
            }
            self.selection.points.insert(index);
        }
        let mut points: Vec<usize> = self.selection.points.iter().copied().collect();
        // Mirror editing: the selected points' images move with them.
        let net = self.doc.scene.objects[object].control_points();
        let size = net.iter().fold(0.0f64, |m, p| m.max(p.abs().max_element()));
        let tolerance = 1e-6 * size.max(1e-300);
        let partners = if self.symmetry.contains(&true) {
            follow::partners(&net, &points, self.symmetry, tolerance)
        } else {
            Vec::new()
        };
        points.extend(partners.iter().map(|p| p.point));
        let falloff = if self.proportional {
            follow::falloff(&net, &points, self.proportional_radius)
        } else {
            Vec::new()
        };
        points.extend(falloff.iter().map(|f| f.point));
        self.apply(AppCommand::Drag(DragStep::Begin { object, points }));
        if self.doc.drag().is_none() {
            return;
        }
        let anchor = net[index];
        self.drag = Some(DragHandle {
            anchor,
            partners,
            tolerance,
            falloff,
            index,
            cursor: None,
        });
        self.constraint = Constraint::Free;
        self.selection.edit_point = index;
        self.update_net();
    }

    /// The wheel during a proportional drag: the radius grows (or shrinks) by 15 % a notch, and
    /// the drag is begun again with the points the new radius takes, at the cursor.
    fn resize_falloff(&mut self, steps: f32) {
        let Some(drag) = &self.drag else {
            return;
        };
        let (index, cursor, constraint) = (drag.index, drag.cursor, self.constraint);
        self.proportional_radius =
            (self.proportional_radius * 1.15f64.powf(f64::from(steps))).clamp(1e-6, 1e9);
        // The points go back, and the drag starts over from the same point.
        if let Some(object) = self.doc.cancel_drag()
            && let Err(e) = self.after_edit(crate::doc::Touched::Points(object))
        {
            self.status.error = Some(e);
        }
        self.drag = None;
        self.begin_drag(index, true);
        self.constraint = constraint;
        if let Some(pos) = cursor {
            self.continue_drag(pos);
        }
        self.status.notice = Some(format!(
            "proportional radius {:.4}",
            self.proportional_radius
        ));
    }

    /// Moves the dragged points so that the grabbed one follows the cursor's ray under the
    /// constraint (and the grid snap); only the affected Bézier patches are re-evaluated.
    fn continue_drag(&mut self, pos: egui::Pos2) {
        let (Some(drag), Some(view)) = (&self.drag, self.pick_view) else {
            return;
        };
        if self.doc.drag().is_none() {
            // The document was replaced or edited under the drag: it is over.
            self.drag = None;
            return;
        }
        let anchor = drag.anchor;
        let (origin, direction) = view.ray(self.local(pos));
        let view_dir = (self.view.camera.target - self.view.camera.eye())
            .as_dvec3()
            .normalize_or(DVec3::X);
        let mut target = pick::drag_position(anchor, origin, direction, view_dir, self.constraint);
        let cursor = self.local(pos);
        if let Some((snapped, what)) = self.snap_target(cursor, origin, direction) {
            target = snapped;
            self.status.snapped = Some(what.to_owned());
        } else if self.snap {
            self.status.snapped = Some("grid".to_owned());
            target = pick::snap(target, self.snap_step);
            // Snapping must not leave the constraint's axis or plane.
            match self.constraint {
                Constraint::Axis(a) => {
                    for b in (0..3).filter(|&b| b != a) {
                        target[b] = anchor[b];
                    }
                }
                Constraint::Plane(a) => target[a] = anchor[a],
                Constraint::Free => {}
            }
        } else {
            self.status.snapped = None;
        }
        let delta = target - anchor;
        if let Some(drag) = &mut self.drag {
            drag.cursor = Some(pos);
        }
        if !self.symmetry.contains(&true) && !self.proportional {
            self.apply(AppCommand::Drag(DragStep::By(delta)));
            return;
        }
        // Mirror editing: each dragged point keeps to the planes it lies on, and its images
        // move by its offset mirrored. Proportional editing: the points near them follow by
        // a share of their nearest's offset.
        let (Some(drag), Some(state)) = (&self.drag, self.doc.drag()) else {
            return;
        };
        let starts = state.starts();
        let start_of = |k: usize| {
            starts
                .binary_search_by_key(&k, |&(d, _)| d)
                .ok()
                .map(|i| starts[i].1)
        };
        let axes = self.symmetry;
        let offset_of = |k: usize| {
            start_of(k).map_or(delta, |p| {
                follow::kept_on_planes(p, delta, axes, drag.tolerance)
            })
        };
        let follows: std::collections::HashSet<usize> = drag
            .partners
            .iter()
            .map(|p| p.point)
            .chain(drag.falloff.iter().map(|f| f.point))
            .collect();
        let mut offsets: std::collections::HashMap<usize, DVec3> = starts
            .iter()
            .filter(|(k, _)| !follows.contains(k))
            .map(|&(k, _)| (k, offset_of(k)))
            .collect();
        for partner in &drag.partners {
            offsets.insert(
                partner.point,
                follow::flipped(offset_of(partner.source), partner.flip),
            );
        }
        let mut moves: Vec<(usize, DVec3)> = offsets
            .iter()
            .filter_map(|(&k, &o)| Some((k, start_of(k)? + o)))
            .collect();
        for f in &drag.falloff {
            if let (Some(p), Some(&o)) = (start_of(f.point), offsets.get(&f.source)) {
                moves.push((f.point, p + o * f.weight));
            }
        }
        self.apply(AppCommand::Drag(DragStep::To(moves)));
    }

    /// Where a dragged point snaps to under `cursor` (viewport pixels) and what it snapped to:
    /// a control point of any shown object within the pick radius (not one being dragged),
    /// else a point of another object's surface under the cursor.
    fn snap_target(
        &self,
        cursor: DVec2,
        origin: DVec3,
        direction: DVec3,
    ) -> Option<(DVec3, &'static str)> {
        let view = self.pick_view?;
        let dragged_object = self.selection.object;
        if self.snap_points {
            let dragged: std::collections::BTreeSet<usize> = self
                .doc
                .drag()
                .map(|d| d.starts().iter().map(|(k, _)| *k).collect())
                .unwrap_or_default();
            let mut best: Option<(f64, DVec3)> = None;
            for (k, object) in self.scene().objects.iter().enumerate() {
                if !object.visible {
                    continue;
                }
                for (i, p) in object.control_points().into_iter().enumerate() {
                    if Some(k) == dragged_object && dragged.contains(&i) {
                        continue;
                    }
                    let Some(projected) = view.project(p) else {
                        continue;
                    };
                    let d = projected.screen.distance(cursor);
                    if d <= PICK_RADIUS && best.is_none_or(|(b, _)| d < b) {
                        best = Some((d, p));
                    }
                }
            }
            if let Some((_, p)) = best {
                return Some((p, "point"));
            }
        }
        if self.snap_surface
            && let Some(gpu) = &self.gpu
        {
            let objects: Vec<_> = gpu
                .sync
                .feeds()
                .iter()
                .zip(&self.doc.scene.objects)
                .enumerate()
                .map(|(k, (d, o))| (d, o.visible && Some(k) != dragged_object))
                .collect();
            if let Some(hit) = pick::pick_surface(&objects, origin, direction) {
                return Some((hit.point, "surface"));
            }
        }
        None
    }

    /// Ends the drag: one undo step for the whole move (`cancel`: put everything back).
    pub(super) fn end_drag(&mut self, cancel: bool) {
        self.gizmo_drag = None;
        if self.drag.take().is_none() && self.doc.drag().is_none() {
            return;
        }
        self.constraint = Constraint::Free;
        self.highlight_patches.clear();
        self.auto_range = None;
        self.redraw = true;
        if cancel {
            // Objects sharing the dragged lattice, or built from the dragged curve, come back
            // too: then everything is rebuilt.
            let linked = self
                .doc
                .drag()
                .is_some_and(|d| !d.linked().is_empty() || !d.dependents().is_empty());
            if let Some(object) = self.doc.cancel_drag() {
                let touched = if linked {
                    crate::doc::Touched::Structure
                } else {
                    crate::doc::Touched::Points(object)
                };
                if let Err(e) = self.after_edit(touched) {
                    self.status.error = Some(e);
                }
            }
        } else if let Some((touched, ended)) = self.doc.commit_drag().map(|edit| {
            (
                edit.touched(),
                edit.ends_history().then(|| edit.label.clone()),
            )
        }) {
            if let Some(ended) = ended {
                self.status.notice = Some(ended);
            }
            if touched.is_structure() {
                // The object chose another layout for its new shape (adaptive refinement).
                if let Err(e) = self.after_edit(touched) {
                    self.status.error = Some(e);
                }
            } else {
                self.saved.revision += 1;
            }
        }
    }

    /// Keys while dragging: X / Y / Z constrain to an axis, with Shift to the plane normal to
    /// it; pressing the same again frees the drag.
    fn drag_keys(&mut self, ui: &egui::Ui) {
        for (key, axis) in [(egui::Key::X, 0), (egui::Key::Y, 1), (egui::Key::Z, 2)] {
            if let Some(shift) = ui.input(|i| i.key_pressed(key).then_some(i.modifiers.shift)) {
                let next = if shift {
                    Constraint::Plane(axis)
                } else {
                    Constraint::Axis(axis)
                };
                self.constraint = if self.constraint == next {
                    Constraint::Free
                } else {
                    next
                };
            }
        }
    }

    pub(super) fn handle_input(&mut self, ui: &egui::Ui, response: &egui::Response) {
        if self.crease_drag.is_some() {
            self.crease_drag_input(ui, response);
            return;
        }
        if self.knife.is_some() {
            self.knife_input(ui, response);
            return;
        }
        let shift = ui.input(|i| i.modifiers.shift);
        if self.curves.drawing.is_some() {
            let hover = response.hover_pos().map(|p| self.local(p));
            self.curve_hover(hover);
        }
        let press = ui.input(|i| i.pointer.press_origin());
        if response.drag_started_by(egui::PointerButton::Primary)
            && let Some(origin) = press
        {
            // A control point under the cursor wins over the gizmo (its parts are long and easy
            // to grab elsewhere; a point is not).
            match self.handle_at(self.local(origin)) {
                Some(index) => self.begin_drag(index, shift),
                None if self.begin_gizmo_drag(self.local(origin)) => {}
                None => self.selection.box_start = Some(origin),
            }
        }
        if self.drag.is_some() {
            self.drag_keys(ui);
            if ui.input(|i| i.key_pressed(egui::Key::Escape)) {
                self.apply(AppCommand::Drag(DragStep::Cancel));
            } else if let Some(pos) = response.interact_pointer_pos()
                && response.dragged_by(egui::PointerButton::Primary)
            {
                if self.gizmo_drag.is_some() {
                    self.continue_gizmo_drag(self.local(pos));
                } else {
                    self.continue_drag(pos);
                }
            }
        }
        // Ctrl + right drag: a lasso.
        if response.drag_started_by(egui::PointerButton::Secondary)
            && ui.input(|i| i.modifiers.command)
            && let Some(origin) = press
        {
            self.selection.lasso = Some(vec![origin]);
        }
        if let (Some(lasso), Some(pos)) =
            (&mut self.selection.lasso, response.interact_pointer_pos())
            && lasso.last().is_none_or(|last| last.distance(pos) >= 2.0)
        {
            lasso.push(pos);
        }
        if response.drag_stopped()
            && let Some(lasso) = self.selection.lasso.take()
        {
            let outline: Vec<DVec2> = lasso.iter().map(|&p| self.local(p)).collect();
            let inside = pick::points_in_lasso(&self.projected_handles(), &outline);
            if !shift {
                self.selection.points.clear();
            }
            self.selection.points.extend(inside);
            self.update_net();
        }
        if response.drag_stopped() {
            self.apply(AppCommand::Drag(DragStep::End));
            if let (Some(start), Some(end)) = (
                self.selection.box_start.take(),
                response.interact_pointer_pos(),
            ) {
                let inside = pick::points_in_box(
                    &self.projected_handles(),
                    self.local(start),
                    self.local(end),
                );
                if !shift {
                    self.selection.points.clear();
                }
                self.selection.points.extend(inside);
                self.update_net();
            }
        }
        if response.clicked()
            && let Some(pos) = response.interact_pointer_pos()
        {
            self.click(pos, ui.input(|i| i.modifiers));
        }
        let hover = response.hover_pos().map(|p| self.local(p));
        self.feature_hover(hover);
        let delta = response.drag_delta();
        if delta != egui::Vec2::ZERO && self.selection.lasso.is_none() {
            let height = self.viewport_rect.height();
            if response.dragged_by(egui::PointerButton::Middle)
                || (shift && response.dragged_by(egui::PointerButton::Secondary))
            {
                self.view.camera.pan(delta.x, delta.y, height);
                self.redraw = true;
            } else if response.dragged_by(egui::PointerButton::Secondary) {
                self.view.camera.orbit(delta.x, delta.y);
                self.redraw = true;
            }
        }
        if self.selection.box_start.is_some()
            || self.selection.lasso.is_some()
            || self.drag.is_some()
        {
            self.redraw = true;
        }
        if response.hovered() {
            let (scroll, zoom) = ui.input(|i| (i.smooth_scroll_delta.y, i.zoom_delta()));
            // One wheel notch is about 50 points of scroll.
            let steps = scroll / 50.0 + zoom.ln() / 0.15;
            if steps != 0.0 && self.proportional && self.drag.is_some() {
                self.resize_falloff(steps);
            } else if steps != 0.0 {
                self.view.camera.zoom(steps);
                self.redraw = true;
            }
        }
    }

    /// Shortcuts that work anywhere except while typing in a field.
    pub(super) fn handle_shortcuts(&mut self, ctx: &egui::Context) {
        if ctx.egui_wants_keyboard_input() || self.curve_keys(ctx) {
            return;
        }
        use egui::{Key, KeyboardShortcut, Modifiers};
        let command = Modifiers::COMMAND;
        let shortcut = |m: Modifiers, k: Key| KeyboardShortcut::new(m, k);
        let pressed = |s: KeyboardShortcut| ctx.input_mut(|i| i.consume_shortcut(&s));
        if pressed(shortcut(command | Modifiers::SHIFT, Key::Z))
            || pressed(shortcut(command, Key::Y))
        {
            self.apply(AppCommand::Redo);
        } else if pressed(shortcut(command, Key::Z)) {
            self.apply(AppCommand::Undo);
        }
        if pressed(shortcut(command, Key::S)) {
            self.save_dialog();
        }
        if pressed(shortcut(command, Key::O)) {
            self.open_dialog();
        }
        if pressed(shortcut(command, Key::E)) {
            self.export.show = true;
        }
        if pressed(shortcut(command, Key::A)) {
            self.select_all_points();
        }
        if pressed(shortcut(command, Key::D))
            && let Some(object) = self.selection.object
        {
            self.apply(AppCommand::Edit(crate::doc::Command::Duplicate { object }));
        }
        if self.drag.is_none() && self.crease_drag.is_none() && self.knife.is_none() {
            if pressed(shortcut(Modifiers::ALT, Key::A))
                || pressed(shortcut(Modifiers::NONE, Key::Escape))
            {
                self.selection.points.clear();
                self.update_net();
            }
            if pressed(shortcut(Modifiers::NONE, Key::Delete))
                && let Some(object) = self.selection.object
            {
                self.apply(AppCommand::Edit(crate::doc::Command::Delete { object }));
            }
            if pressed(shortcut(Modifiers::NONE, Key::F)) {
                self.frame_pending = true;
            }
            // On a cage, 1 / 2 / 3 pick the select mode as in Blender's edit mode (the views
            // keep Ctrl + 1 / 3 and the View menu).
            let on_cage = self
                .selection
                .object
                .and_then(|s| self.scene().objects.get(s))
                .is_some_and(|o| o.geometry.as_subdivision().is_some());
            if on_cage && pressed(shortcut(Modifiers::SHIFT, Key::E)) {
                let pointer = ctx.input(|i| i.pointer.hover_pos());
                self.begin_crease_drag(pointer);
            }
            if on_cage && pressed(shortcut(Modifiers::NONE, Key::K)) {
                self.begin_knife();
            }
            if on_cage {
                use super::panels::cage::SelectMode;
                for (key, mode, name) in [
                    (Key::Num1, SelectMode::Vertex, "vertex"),
                    (Key::Num2, SelectMode::Edge, "edge"),
                    (Key::Num3, SelectMode::Face, "face"),
                ] {
                    if pressed(shortcut(Modifiers::NONE, key)) {
                        self.cage_tools.select_mode = mode;
                        self.status.notice = Some(format!("{name} select mode"));
                    }
                }
            }
            if pressed(shortcut(Modifiers::NONE, Key::O)) {
                self.proportional = !self.proportional;
                self.status.notice = Some(format!(
                    "proportional editing {} (radius {:.4}; the wheel changes it while dragging)",
                    if self.proportional { "on" } else { "off" },
                    self.proportional_radius
                ));
            }
        }
    }

    pub(super) fn select_all_points(&mut self) {
        if let Some(s) = self.selection.object {
            self.selection.points = (0..self.doc.scene.objects[s].control_point_count()).collect();
            self.update_net();
        }
    }

    /// The box or lasso being dragged, drawn over the viewport.
    pub(super) fn paint_box(&self, ui: &egui::Ui) {
        let color = egui::Color32::from_rgb(255, 140, 30);
        if let (Some(drag), Some(now)) = (&self.crease_drag, ui.input(|i| i.pointer.hover_pos())) {
            ui.painter().add(egui::Shape::dashed_line(
                &[drag.centre, now],
                egui::Stroke::new(1.0, color),
                6.0,
                4.0,
            ));
            ui.painter().text(
                now + egui::vec2(12.0, -12.0),
                egui::Align2::LEFT_BOTTOM,
                format!("crease {:.2}", drag.value),
                egui::FontId::proportional(14.0),
                color,
            );
        }
        if let Some(lasso) = &self.selection.lasso {
            let mut closed = lasso.clone();
            closed.extend(lasso.first().copied());
            ui.painter().add(egui::Shape::dashed_line(
                &closed,
                egui::Stroke::new(1.0, color),
                6.0,
                4.0,
            ));
        }
        let (Some(start), Some(now)) = (
            self.selection.box_start,
            ui.input(|i| i.pointer.hover_pos()),
        ) else {
            return;
        };
        let rect = egui::Rect::from_two_pos(start, now);
        ui.painter()
            .rect_filled(rect, 0.0, color.gamma_multiply(0.12));
        ui.painter().rect_stroke(
            rect,
            0.0,
            egui::Stroke::new(1.0, color),
            egui::StrokeKind::Inside,
        );
    }
}
