//! The Cage tools section of a subdivision surface: what the selected points cover (faces,
//! edges), Blender's selection helpers (edge loop and ring, more, less, linked) and its
//! topology tools (extrude, inset, loop cut, bevel, bridge, merge, dissolve, delete, mirror),
//! each one
//! undo step through the `cage` operation ([`crate::ops::cage`]).
//!
//! As in Blender's vertex mode, the selection is the cage's points: an edge is selected when
//! both its ends are, a face when all its corners are. Box selection, a lasso (Ctrl + right
//! drag), Shift + click and Ctrl + A select points; Alt + click on a cage edge selects its
//! loop, Ctrl + Alt + click its ring. In edge and face mode (2 and 3, as in Blender; 1 is
//! vertex mode) a click picks the edge or face under the cursor and selects its points.

use std::collections::BTreeSet;

use eframe::egui;

use crate::app::{AppCommand, KnotworkApp};
use crate::doc::Command;
use crate::kernel::subdiv::cage_edit::{Cage, Tool};
use crate::ops::cage::CageEdit;
use crate::scene::operation::{ObjectRef, Operation};

/// The tools' settings between frames; lengths are in the model's units, set from the cage's
/// size when another cage is selected.
#[derive(Debug, Clone, PartialEq)]
pub struct CageToolSettings {
    /// The object the lengths were sized for.
    pub sized_for: Option<usize>,
    pub offset: f64,
    /// Extrude each face on its own, along its own normal.
    pub extrude_individual: bool,
    pub thickness: f64,
    /// Inset: how far the inner faces then move out of the surface.
    pub depth: f64,
    pub individual: bool,
    pub cuts: u32,
    /// Loop cut: the cuts slid together along the ring (−1 to 1, 0 evenly spaced).
    pub slide: f64,
    pub width: f64,
    pub segments: u32,
    /// Merge at the point clicked last (else at the centre).
    pub merge_at_last: bool,
    /// Merge by distance: points this near are welded.
    pub merge_distance: f64,
    /// Spin: the angle in degrees, the steps, and the axis (0, 1, 2: x, y, z) through the
    /// origin.
    pub spin_degrees: f64,
    pub spin_steps: u32,
    pub spin_axis: usize,
    /// What a click on the cage picks.
    pub select_mode: SelectMode,
}

/// What a click on a cage picks, as Blender's edit-mode select modes (keys 1, 2, 3): a point,
/// an edge (both its points) or a face (all its corners).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum SelectMode {
    #[default]
    Vertex,
    Edge,
    Face,
}

impl Default for CageToolSettings {
    fn default() -> Self {
        Self {
            sized_for: None,
            offset: 0.5,
            extrude_individual: false,
            thickness: 0.1,
            depth: 0.0,
            individual: false,
            cuts: 1,
            slide: 0.0,
            width: 0.1,
            segments: 1,
            merge_at_last: false,
            merge_distance: 1e-4,
            spin_degrees: 90.0,
            spin_steps: 12,
            spin_axis: 2,
            select_mode: SelectMode::Vertex,
        }
    }
}

/// The cage of a subdivision surface, as the tools take it.
pub fn cage_of(object: &crate::scene::SceneObject) -> Option<Cage> {
    Some(Cage::of_surface(&object.geometry.as_subdivision()?.surface))
}

/// A tool's button: clicked, and enabled or greyed out with what to select.
fn tool_button(ui: &mut egui::Ui, enabled: bool, label: &str, hover: &str, disabled: &str) -> bool {
    ui.add_enabled(enabled, egui::Button::new(label))
        .on_hover_text(hover)
        .on_disabled_hover_text(disabled)
        .clicked()
}

/// Why a tool of one edge is greyed out.
const NEED_EDGE: &str = "select one edge (its two points)";

/// What a tool selects when it is done.
pub(in crate::app) enum After {
    /// The points of these faces (an extrusion's or inset's region, which keeps its indices).
    Faces(Vec<usize>),
    /// These points (a tool that keeps every point's index).
    Points(Vec<u32>),
    Nothing,
}

impl KnotworkApp {
    /// The selected points as cage vertices.
    fn cage_selection(&self) -> BTreeSet<u32> {
        self.selection.points.iter().map(|&k| k as u32).collect()
    }

    /// Replaces the point selection (one undo-free change, as a click is).
    pub(in crate::app) fn select_cage_points(&mut self, points: impl IntoIterator<Item = u32>) {
        self.selection.points = points.into_iter().map(|v| v as usize).collect();
        self.update_net();
    }

    /// The Cage tools section for subdivision surface `s`.
    pub(in crate::app) fn cage_tools_panel(&mut self, ui: &mut egui::Ui, s: usize) {
        let Some(cage) = self.scene().objects.get(s).and_then(cage_of) else {
            return;
        };
        if self.cage_tools.sized_for != Some(s) {
            // Lengths from the cage's mean edge.
            let edges = cage.edges();
            let mean = edges
                .iter()
                .map(|&(a, b)| cage.points[a as usize].distance(cage.points[b as usize]))
                .sum::<f64>()
                / edges.len().max(1) as f64;
            let unit = if mean.is_finite() && mean > 0.0 {
                mean
            } else {
                1.0
            };
            self.cage_tools = CageToolSettings {
                sized_for: Some(s),
                offset: 0.5 * unit,
                thickness: 0.15 * unit,
                width: 0.1 * unit,
                merge_distance: 1e-3 * unit,
                ..self.cage_tools.clone()
            };
        }
        ui.separator();
        ui.label(egui::RichText::new("Cage tools").strong());
        let selected = self.cage_selection();
        let faces = cage.faces_within(&selected);
        let edges = cage.edges_within(&selected);
        ui.label(format!(
            "{} points, {} edges, {} faces selected",
            selected.len(),
            edges.len(),
            faces.len()
        ))
        .on_hover_text(
            "an edge is selected with both its points, a face with all its corners: select \
             points with a click, Shift + click, a box or Ctrl + A; Alt + click on an edge \
             selects its loop, Ctrl + Alt + click its ring",
        );
        ui.horizontal(|ui| {
            ui.label("Pick:");
            let mode = &mut self.cage_tools.select_mode;
            ui.selectable_value(mode, SelectMode::Vertex, "Vertex")
                .on_hover_text("a click picks a point (1)");
            ui.selectable_value(mode, SelectMode::Edge, "Edge")
                .on_hover_text("a click picks an edge, both its points (2)");
            ui.selectable_value(mode, SelectMode::Face, "Face")
                .on_hover_text("a click picks a face, all its corners (3)");
        });
        let one_edge = match edges[..] {
            [edge] => Some(edge),
            _ => None,
        };
        ui.horizontal_wrapped(|ui| {
            ui.label("Select:");
            let enabled = one_edge.is_some();
            if tool_button(
                ui,
                enabled,
                "Loop",
                "the edge loop through the selected edge",
                NEED_EDGE,
            ) && let Some((a, b)) = one_edge
            {
                self.select_edge_loop(&cage, a, b, false, false);
            }
            if tool_button(
                ui,
                enabled,
                "Ring",
                "the edge ring through the selected edge",
                NEED_EDGE,
            ) && let Some((a, b)) = one_edge
            {
                self.select_edge_loop(&cage, a, b, true, false);
            }
            let any = !selected.is_empty();
            if ui
                .add_enabled(any, egui::Button::new("More"))
                .on_hover_text("every point of a face that holds a selected point")
                .clicked()
            {
                self.select_cage_points(cage.grown(&selected));
            }
            if ui
                .add_enabled(any, egui::Button::new("Less"))
                .on_hover_text("the selected points whose faces are all selected")
                .clicked()
            {
                self.select_cage_points(cage.shrunk(&selected));
            }
            if ui
                .add_enabled(any, egui::Button::new("Linked"))
                .on_hover_text("every point joined to a selected one")
                .clicked()
            {
                self.select_cage_points(cage.linked(&selected));
            }
            let creased = !cage.creases.is_empty() || !cage.corners.is_empty();
            if tool_button(
                ui,
                creased,
                "Creased",
                "the points of every creased edge and every sharp point",
                "the cage has no creases or sharp points",
            ) {
                let points = cage.creases.iter().flat_map(|c| [c.a, c.b]);
                self.select_cage_points(points.chain(cage.corners.iter().map(|c| c.vertex)));
            }
        });
        let mut chosen: Option<(Tool, After)> = None;
        let t = &mut self.cage_tools;
        let need_faces = "select faces (all their points)";
        let need_edges = "select edges (both their points)";
        ui.horizontal_wrapped(|ui| {
            if tool_button(
                ui,
                !faces.is_empty(),
                "Extrude faces",
                "the selected faces lifted along their average normal, with sides",
                need_faces,
            ) {
                chosen = Some((
                    Tool::Extrude {
                        faces: faces.clone(),
                        offset: t.offset,
                        individual: t.extrude_individual,
                    },
                    After::Faces(faces.clone()),
                ));
            }
            ui.add(
                egui::DragValue::new(&mut t.offset)
                    .speed(0.01)
                    .prefix("by "),
            );
            ui.checkbox(&mut t.extrude_individual, "each face")
                .on_hover_text("each face lifted on its own along its own normal");
        });
        ui.horizontal_wrapped(|ui| {
            if tool_button(
                ui,
                !faces.is_empty(),
                "Inset faces",
                "a strip of new faces inside the selected faces' border",
                need_faces,
            ) {
                chosen = Some((
                    Tool::Inset {
                        faces: faces.clone(),
                        thickness: t.thickness,
                        depth: t.depth,
                        individual: t.individual,
                    },
                    After::Faces(faces.clone()),
                ));
            }
            ui.add(
                egui::DragValue::new(&mut t.thickness)
                    .speed(0.005)
                    .range(0.0..=f64::MAX)
                    .prefix("width "),
            );
            ui.add(
                egui::DragValue::new(&mut t.depth)
                    .speed(0.005)
                    .prefix("depth "),
            )
            .on_hover_text("how far the inset faces then move out of the surface (negative: in)");
            ui.checkbox(&mut t.individual, "each face");
        });
        ui.horizontal_wrapped(|ui| {
            if tool_button(
                ui,
                one_edge.is_some(),
                "Loop cut",
                "cuts across the edge ring through the selected edge",
                NEED_EDGE,
            ) && let Some((a, b)) = one_edge
            {
                chosen = Some((
                    Tool::LoopCut {
                        edge: [a, b],
                        cuts: t.cuts,
                        slide: t.slide,
                    },
                    After::Nothing,
                ));
            }
            ui.add(
                egui::DragValue::new(&mut t.cuts)
                    .range(1..=64)
                    .suffix(" cuts"),
            );
            ui.add(
                egui::DragValue::new(&mut t.slide)
                    .range(-0.99..=0.99)
                    .speed(0.01)
                    .prefix("slide "),
            )
            .on_hover_text(
                "the cuts slid together along the ring, towards one side (0: evenly spaced), \
                 as Blender's Loop Cut and Slide",
            );
        });
        ui.horizontal_wrapped(|ui| {
            if tool_button(
                ui,
                !edges.is_empty(),
                "Bevel edges",
                "the selected edges rounded into bands of faces",
                need_edges,
            ) {
                chosen = Some((
                    Tool::Bevel {
                        edges: edges.iter().map(|&(a, b)| [a, b]).collect(),
                        width: t.width,
                        segments: t.segments,
                    },
                    After::Nothing,
                ));
            }
            ui.add(
                egui::DragValue::new(&mut t.width)
                    .speed(0.005)
                    .range(0.0..=f64::MAX)
                    .prefix("width "),
            );
            ui.add(
                egui::DragValue::new(&mut t.segments)
                    .range(1..=32)
                    .suffix(" segments"),
            );
            if tool_button(
                ui,
                !selected.is_empty(),
                "Bevel vertices",
                "each selected point cut off the width along its edges, a face where it was \
                 (with more segments a rounded corner)",
                "select one or more points",
            ) {
                chosen = Some((
                    Tool::BevelVertices {
                        vertices: selected.iter().copied().collect(),
                        width: t.width,
                        segments: t.segments,
                    },
                    After::Nothing,
                ));
            }
        });
        ui.horizontal_wrapped(|ui| {
            let loops = cage.closed_loops(&edges).ok().filter(|l| l.len() == 2);
            if tool_button(
                ui,
                loops.is_some(),
                "Bridge loops",
                "faces between the two selected edge loops",
                "select two closed edge loops (border loops)",
            ) && let Some(loops) = loops
            {
                chosen = Some((
                    Tool::Bridge {
                        loop1: loops[0].clone(),
                        loop2: loops[1].clone(),
                    },
                    After::Nothing,
                ));
            }
            if tool_button(
                ui,
                selected.len() >= 2,
                "Merge points",
                "the selected points made one",
                "select two or more points",
            ) {
                let mut vertices: Vec<u32> = selected.iter().copied().collect();
                let last = self.selection.edit_point as u32;
                if let Some(k) = vertices.iter().position(|&v| v == last) {
                    vertices.swap(0, k);
                }
                chosen = Some((
                    Tool::Merge {
                        vertices,
                        at_first: t.merge_at_last,
                    },
                    After::Nothing,
                ));
            }
            ui.checkbox(&mut t.merge_at_last, "at the last clicked");
        });
        ui.horizontal_wrapped(|ui| {
            if tool_button(
                ui,
                !edges.is_empty(),
                "Dissolve edges",
                "the faces each side of the selected edges made one",
                need_edges,
            ) {
                chosen = Some((
                    Tool::Dissolve {
                        edges: edges.iter().map(|&(a, b)| [a, b]).collect(),
                    },
                    After::Nothing,
                ));
            }
            if tool_button(
                ui,
                faces.len() >= 2,
                "Dissolve faces",
                "each joined region of selected faces made one face",
                "select two or more faces that share edges",
            ) {
                chosen = Some((
                    Tool::DissolveFaces {
                        faces: faces.clone(),
                    },
                    After::Nothing,
                ));
            }
            if tool_button(
                ui,
                !faces.is_empty(),
                "Poke faces",
                "each selected face a fan of triangles round its centre",
                need_faces,
            ) {
                chosen = Some((
                    Tool::Poke {
                        faces: faces.clone(),
                    },
                    After::Nothing,
                ));
            }
            if tool_button(
                ui,
                !faces.is_empty(),
                "Subdivide faces",
                "the selected faces' edges cut by the loop cut's number of cuts, each quad and \
                 triangle they close a grid",
                need_faces,
            ) {
                chosen = Some((
                    Tool::Subdivide {
                        faces: faces.clone(),
                        cuts: t.cuts,
                    },
                    After::Nothing,
                ));
            }
            if tool_button(
                ui,
                !faces.is_empty(),
                "Delete faces",
                "the selected faces removed (points no face uses go too)",
                need_faces,
            ) {
                chosen = Some((
                    Tool::Delete {
                        faces: faces.clone(),
                    },
                    After::Nothing,
                ));
            }
        });
        let mut knife = false;
        if ui
            .button("Knife (K)")
            .on_hover_text(
                "drag a line across the viewport: every face under it, front and back, is cut \
                 along the plane through the line and the eye (Esc cancels)",
            )
            .clicked()
        {
            knife = true;
        }
        let points: Vec<u32> = selected.iter().copied().collect();
        let need_points = "select one or more points";
        ui.horizontal_wrapped(|ui| {
            if tool_button(
                ui,
                !faces.is_empty(),
                "Triangulate faces",
                "each selected face split into triangles, the roundest split (Beauty)",
                need_faces,
            ) {
                chosen = Some((
                    Tool::Triangulate {
                        faces: faces.clone(),
                    },
                    After::Points(points.clone()),
                ));
            }
            if tool_button(
                ui,
                faces.len() >= 2,
                "Tris to quads",
                "pairs of the selected triangles joined into quads, the squarest first (normals \
                 within 40°, corners within 40° of square)",
                "select two or more triangles that share an edge",
            ) {
                chosen = Some((
                    Tool::TrisToQuads {
                        faces: faces.clone(),
                        face_degrees: 40.0,
                        shape_degrees: 40.0,
                    },
                    After::Points(points.clone()),
                ));
            }
            if tool_button(
                ui,
                !points.is_empty(),
                "Dissolve points",
                "the faces round each selected point made one, the point gone",
                need_points,
            ) {
                chosen = Some((
                    Tool::DissolveVertices {
                        vertices: points.clone(),
                    },
                    After::Nothing,
                ));
            }
            if tool_button(
                ui,
                !points.is_empty(),
                "Delete points",
                "the selected points removed with every face on them",
                need_points,
            ) {
                chosen = Some((
                    Tool::DeleteVertices {
                        vertices: points.clone(),
                    },
                    After::Nothing,
                ));
            }
            if tool_button(
                ui,
                !edges.is_empty(),
                "Delete edges",
                "the selected edges removed with the faces on them",
                need_edges,
            ) {
                chosen = Some((
                    Tool::DeleteEdges {
                        edges: edges.iter().map(|&(a, b)| [a, b]).collect(),
                    },
                    After::Nothing,
                ));
            }
        });
        let open_edges = cage.open_among(&edges);
        let need_open = "select open edges (on one face), both their points";
        ui.horizontal_wrapped(|ui| {
            let outward = cage.outward_of(&open_edges);
            if tool_button(
                ui,
                outward.is_some(),
                "Extrude edges",
                "the selected open edges pulled out by the extrusion's distance, away from \
                 their faces, into a strip of quads",
                need_open,
            ) && let Some(outward) = outward
            {
                chosen = Some((
                    Tool::ExtrudeEdges {
                        edges: open_edges.iter().map(|&(a, b)| [a, b]).collect(),
                        by: (outward * t.offset).to_array(),
                    },
                    After::Nothing,
                ));
            }
            let rim = cage
                .closed_loops(&open_edges)
                .ok()
                .filter(|l| l.len() == 1)
                .and_then(|mut l| l.pop());
            if tool_button(
                ui,
                rim.is_some(),
                "Fill",
                "a face over the selected closed loop of open edges",
                "select one closed loop of open edges (a hole's rim)",
            ) && let Some(rim) = &rim
            {
                chosen = Some((
                    Tool::Fill {
                        r#loop: rim.clone(),
                    },
                    After::Nothing,
                ));
            }
            let even_rim = rim.as_ref().filter(|r| r.len() >= 4 && r.len() % 2 == 0);
            if tool_button(
                ui,
                even_rim.is_some(),
                "Grid fill",
                "a grid of quads over the selected hole, its sides cut at the rim's sharpest \
                 corners (as Blender's Grid Fill)",
                "select one closed loop of an even number of open edges (a hole's rim)",
            ) && let Some(rim) = even_rim
            {
                chosen = Some((
                    Tool::GridFill {
                        loop1: Vec::new(),
                        loop2: Vec::new(),
                        rim: rim.clone(),
                        span: None,
                        offset: None,
                    },
                    After::Nothing,
                ));
            }
            if tool_button(
                ui,
                points.len() >= 2,
                "Connect",
                "each face holding two or more selected points split between them (J)",
                "select two or more points of a face",
            ) {
                chosen = Some((
                    Tool::Connect {
                        vertices: points.clone(),
                    },
                    After::Points(points.clone()),
                ));
            }
            let spun = !faces.is_empty() || !open_edges.is_empty();
            let mut axis = [0.0; 3];
            axis[t.spin_axis.min(2)] = 1.0;
            if tool_button(
                ui,
                spun,
                "Spin",
                "the selected faces (or else open edges) turned round the axis through the \
                 origin in steps, a ring of quads each step (a full turn of a separate piece \
                 closes it)",
                "select faces, or open edges",
            ) {
                chosen = Some((
                    Tool::Spin {
                        faces: faces.clone(),
                        edges: if faces.is_empty() {
                            open_edges.iter().map(|&(a, b)| [a, b]).collect()
                        } else {
                            Vec::new()
                        },
                        centre: [0.0; 3],
                        axis,
                        degrees: t.spin_degrees,
                        steps: t.spin_steps,
                        advance: 0.0,
                    },
                    After::Nothing,
                ));
            }
            ui.add(
                egui::DragValue::new(&mut t.spin_degrees)
                    .range(-3600.0..=3600.0)
                    .suffix("°"),
            );
            ui.add(
                egui::DragValue::new(&mut t.spin_steps)
                    .range(1..=256)
                    .suffix(" steps"),
            );
            for (k, name) in ["X", "Y", "Z"].iter().enumerate() {
                ui.selectable_value(&mut t.spin_axis, k, *name)
                    .on_hover_text(format!("spin round the {name} axis"));
            }
        });
        ui.horizontal_wrapped(|ui| {
            if ui
                .button("Merge by distance")
                .on_hover_text(
                    "points nearer each other than the distance welded into one (among the \
                     selected points, or all when none is selected)",
                )
                .clicked()
            {
                chosen = Some((
                    Tool::MergeByDistance {
                        vertices: points.clone(),
                        distance: t.merge_distance,
                    },
                    After::Nothing,
                ));
            }
            ui.add(
                egui::DragValue::new(&mut t.merge_distance)
                    .speed(1e-4)
                    .range(0.0..=f64::MAX)
                    .max_decimals(6)
                    .prefix("within "),
            );
        });
        ui.horizontal_wrapped(|ui| {
            ui.label("Mirror editing:")
                .on_hover_text("a dragged point's images across x = 0, y = 0, z = 0 move with it");
            for (axis, name) in ["X mirror", "Y mirror", "Z mirror"].iter().enumerate() {
                ui.checkbox(&mut self.symmetry[axis], *name);
            }
        });
        ui.horizontal_wrapped(|ui| {
            for (axis, name) in ["X", "Y", "Z"].iter().enumerate() {
                if ui
                    .button(format!("Mirror {name}"))
                    .on_hover_text(format!(
                        "the whole cage copied across the plane {name} = 0, points within {} \
                         of it welded to their images",
                        crate::kernel::subdiv::cage_edit::DEFAULT_MERGE_DISTANCE
                    ))
                    .clicked()
                {
                    chosen = Some((
                        Tool::Mirror {
                            axis: axis as u8,
                            merge_distance:
                                crate::kernel::subdiv::cage_edit::DEFAULT_MERGE_DISTANCE,
                        },
                        After::Nothing,
                    ));
                }
            }
        });
        if let Some((tool, after)) = chosen {
            self.apply_cage_tool(s, tool, after);
        }
        if knife {
            self.begin_knife();
        }
    }

    /// Applies `tool` to the cage of object `s` as one undo step; then selects what `after`
    /// says (the selection is cleared where the tool renumbered the points).
    pub(in crate::app) fn apply_cage_tool(&mut self, s: usize, tool: Tool, after: After) {
        let operation = Operation::new(CageEdit {
            object: ObjectRef::Index(s),
            tool,
        });
        self.apply(AppCommand::Edit(Command::Apply {
            operation,
            keep_history: false,
        }));
        if self.status.error.is_some() {
            return;
        }
        // The points are renumbered: no "point k is now point j" notice, the tool's own
        // selection instead.
        self.status.notice = None;
        let Some(cage) = self.scene().objects.get(s).and_then(cage_of) else {
            return;
        };
        let points: Vec<u32> = match after {
            After::Faces(faces) => faces
                .iter()
                .filter_map(|&f| cage.faces.get(f))
                .flatten()
                .copied()
                .collect(),
            After::Points(points) => points,
            After::Nothing => Vec::new(),
        };
        self.select_cage_points(points);
    }

    /// Selects the edge loop (or with `ring` the edge ring) through edge a–b of `cage`; `add`
    /// keeps the selection there is.
    pub(in crate::app) fn select_edge_loop(
        &mut self,
        cage: &Cage,
        a: u32,
        b: u32,
        ring: bool,
        add: bool,
    ) {
        let edges = if ring {
            cage.edge_ring_through(a, b)
        } else {
            cage.edge_loop(a, b)
        };
        match edges {
            Ok(edges) => {
                let mut points = if add {
                    self.cage_selection()
                } else {
                    BTreeSet::new()
                };
                points.extend(edges.iter().flat_map(|&(p, q)| [p, q]));
                self.select_cage_points(points);
            }
            Err(e) => self.status.error = Some(e.to_string()),
        }
    }
}
