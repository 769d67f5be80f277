//! The editor's UI driven headlessly with egui_kittest on wgpu (lavapipe in CI): select an
//! object in the outliner, pick a control point by clicking its projected position, drag it with
//! the X constraint, check that only x changed and only the point's local support was
//! re-evaluated, then undo with Ctrl+Z and find the document as it was; create a sphere in the
//! Create dialog and insert a knot from the panel, checking the shape against the analytic one.
//!
//! The tests share the editor's published status, so they take turns.

use eframe::egui::{self, Event, Key, Modifiers, PointerButton, Pos2};
use egui_kittest::Harness;
use egui_kittest::kittest::{NodeT, Queryable};
use knotwork::app::{AppCommand, DragStep, KnotworkApp, wgpu_configuration};
use knotwork::doc::Command;
use knotwork::status;

pub(crate) static ONE_EDITOR_AT_A_TIME: std::sync::Mutex<()> = std::sync::Mutex::new(());

pub(crate) fn editor() -> Harness<'static, KnotworkApp> {
    let setup = wgpu_configuration(false).wgpu_setup;
    let mut harness = Harness::builder()
        .with_size(egui::vec2(1280.0, 800.0))
        .wgpu_setup(setup)
        .build_eframe(|cc| KnotworkApp::new(cc, None, false));
    harness.run_steps(3);
    assert_eq!(status::current().error, None, "{:?}", status::current());
    harness
}

fn press(harness: &Harness<'_, KnotworkApp>, pos: Pos2, pressed: bool) {
    harness.event(Event::PointerButton {
        pos,
        button: PointerButton::Primary,
        pressed,
        modifiers: Modifiers::NONE,
    });
}

/// The non-uniform B-spline of the sample scene (polynomial: coordinates are stored exactly).
const SHEET: usize = 3;

/// Selects object `object` in the outliner and returns a handle of it well inside the viewport
/// (right of the panel), not hidden behind another: its index and where it is.
fn select_with_free_handle(harness: &mut Harness<'_, KnotworkApp>, object: usize) -> (usize, Pos2) {
    let label = harness.state().document().scene.objects[object]
        .name
        .clone();
    harness.get_by_label(&label).click();
    harness.run_steps(3);
    assert_eq!(status::current().selected, Some(object as u32));
    let handles = status::handles();
    handles
        .iter()
        .enumerate()
        .filter_map(|(k, h)| h.map(|p| (k, Pos2::new(p[0], p[1]))))
        .filter(|(_, p)| p.x > 450.0 && p.x < 1200.0 && p.y > 100.0 && p.y < 700.0)
        .find(|(k, p)| {
            handles.iter().enumerate().all(|(j, h)| {
                j == *k || h.is_none_or(|q| Pos2::new(q[0], q[1]).distance(*p) > 20.0)
            })
        })
        .unwrap_or_else(|| panic!("a free handle on screen: {handles:?}"))
}

/// Selects object `object` through the editor's command channel, as the page does.
fn page_select(harness: &mut Harness<'_, KnotworkApp>, object: usize) {
    let page = harness.state().command_sender();
    page.send(AppCommand::Select(Some(object)));
    harness.run_steps(2);
}

/// Presses the primary button at `at` and moves the mouse `steps` times by `step`, holding it.
fn drag_from(
    harness: &mut Harness<'_, KnotworkApp>,
    at: Pos2,
    step: egui::Vec2,
    steps: u32,
) -> Pos2 {
    press(harness, at, true);
    harness.run_steps(1);
    let mut end = at;
    for k in 1..=steps {
        end = at + step * k as f32;
        harness.hover_at(end);
        harness.run_steps(1);
    }
    end
}

#[test]
fn click_drag_with_axis_constraint_and_undo() {
    let _turn = ONE_EDITOR_AT_A_TIME
        .lock()
        .unwrap_or_else(|p| p.into_inner());
    let mut harness = editor();

    const OBJECT: usize = SHEET;
    let before = harness.state().document().scene.objects[OBJECT].clone();
    let (index, at) = select_with_free_handle(&mut harness, OBJECT);

    // Click it: it becomes the selection.
    harness.hover_at(at);
    harness.run_steps(1);
    press(&harness, at, true);
    harness.run_steps(1);
    press(&harness, at, false);
    harness.run_steps(2);
    assert_eq!(status::current().selected_points, vec![index as u32]);

    // At rest the viewport has 4× multisampling at full resolution.
    let rest = status::current();
    assert!(rest.software_adapter, "these tests run on lavapipe");
    assert_eq!(
        rest.buffer_limit_mib, 128,
        "a software adapter keeps WebGPU's defaults"
    );
    assert_eq!(rest.frame_samples, 4);
    let full = rest.frame_size.expect("a frame was drawn");

    // Drag it: start freely, press X, keep moving, release.
    drag_from(&mut harness, at, egui::vec2(10.0, -6.0), 4);
    let moving = status::current();
    assert!(moving.dragging);
    // On a software adapter the frames in motion have one sample at half the resolution.
    assert_eq!(moving.frame_samples, 1);
    assert_eq!(
        moving.frame_size,
        Some([full[0].div_ceil(2), full[1].div_ceil(2)]),
        "half of {full:?}"
    );
    harness.key_press(Key::X);
    harness.run_steps(1);
    assert_eq!(status::current().constraint, "X axis");
    let end = at + egui::vec2(80.0, -30.0);
    harness.hover_at(end);
    harness.run_steps(1);
    press(&harness, end, false);
    harness.run_steps(2);
    let s = status::current();
    assert!(!s.dragging);
    assert_eq!(s.undo_steps, 1, "a drag is one undo step");
    // Released: the view at rest is drawn at full quality again.
    assert_eq!((s.frame_samples, s.frame_size), (4, Some(full)));
    // Only the point's support was re-evaluated: a (2, 5) B-spline point touches few patches.
    let total = harness.state().document().scene.objects[OBJECT]
        .decompose()
        .unwrap()
        .set
        .patches()
        .len() as u32;
    assert!(
        s.patches_in_drag > 0 && s.patches_in_drag < total,
        "{} of {total}",
        s.patches_in_drag
    );

    let after = harness.state().document().scene.objects[OBJECT].clone();
    let (p0, p1) = (before.control_points(), after.control_points());
    let moved = p1[index] - p0[index];
    assert!(moved.x.abs() > 1e-3, "the point moved along x: {moved}");
    assert_eq!((moved.y, moved.z), (0.0, 0.0), "only along x");
    for (k, (a, b)) in p0.iter().zip(&p1).enumerate() {
        if k != index {
            assert_eq!(a, b, "point {k} must not move");
        }
    }
    assert!(
        after
            .geometry
            .downcast_ref::<knotwork::kernel::NurbsSurface>()
            .is_some()
    );

    // Ctrl+Z restores the document exactly; Ctrl+Shift+Z redoes.
    harness.key_press_modifiers(Modifiers::COMMAND, Key::Z);
    harness.run_steps(2);
    assert_eq!(harness.state().document().scene.objects[OBJECT], before);
    assert_eq!(status::current().redo_steps, 1);
    harness.key_press_modifiers(Modifiers::COMMAND | Modifiers::SHIFT, Key::Z);
    harness.run_steps(2);
    assert_eq!(harness.state().document().scene.objects[OBJECT], after);
}

#[test]
fn create_a_sphere_and_insert_a_knot_from_the_panel() {
    let _turn = ONE_EDITOR_AT_A_TIME
        .lock()
        .unwrap_or_else(|p| p.into_inner());
    let mut harness = editor();
    let camera_before = harness.state().view().camera.target;
    harness.get_by_label("+ Create…").click();
    harness.run_steps(2);
    // The dialog opens on a sphere of radius 2, placed clear of the sample's objects.
    harness
        .get_by_role_and_label(egui::accesskit::Role::Button, "Create")
        .click();
    harness.run_steps(3);
    let s = status::current();
    assert_eq!(
        (s.objects, s.selected, s.error.clone()),
        (7, Some(6), None),
        "{s:?}"
    );
    let scene = harness.state().document().scene.clone();
    let sphere = scene.objects[6].clone();
    let (lo, hi) = sphere.bounds().unwrap();
    for other in &scene.objects[..6] {
        let (a, b) = other.bounds().unwrap();
        let apart = (0..3).any(|k| hi[k] < a[k] || lo[k] > b[k]);
        assert!(apart, "the new sphere overlaps {}", other.name);
    }
    // The camera frames it.
    let target = harness.state().view().camera.target.as_dvec3();
    assert!(
        target.distance(0.5 * (lo + hi)) < 1e-3,
        "{target} vs {lo} {hi}"
    );
    assert_ne!(harness.state().view().camera.target, camera_before);
    // A second one gets a name of its own.
    harness.get_by_label("+ Create…").click();
    harness.run_steps(2);
    harness
        .get_by_role_and_label(egui::accesskit::Role::Button, "Create")
        .click();
    harness.run_steps(3);
    let names: Vec<String> = harness.state().document().scene.objects[6..]
        .iter()
        .map(|o| o.name.clone())
        .collect();
    assert_eq!(names, ["Sphere", "Sphere 2"]);
    harness.key_press_modifiers(Modifiers::COMMAND, Key::Z);
    harness.run_steps(2);
    page_select(&mut harness, 6);
    let Some(before) = sphere
        .geometry
        .downcast_ref::<knotwork::kernel::NurbsSurface>()
    else {
        panic!("a NURBS sphere")
    };

    harness.get_by_label("Insert knot").scroll_to_me();
    harness.run_steps(2);
    // (A pointer click inside the scrolled panel does not reach the button in the harness; the
    // accessibility action does what a click does.)
    harness.get_by_label("Insert knot").click_accesskit();
    harness.run_steps(3);
    assert_eq!(status::current().error, None);
    let Some(after) = harness.state().document().scene.objects[6]
        .geometry
        .downcast_ref::<knotwork::kernel::NurbsSurface>()
    else {
        panic!("still NURBS")
    };
    assert_eq!(
        after.count()[0],
        before.count()[0] + 1,
        "one more row of points in u"
    );
    // Still the sphere of radius 2: compared with the analytic surface, not the old net.
    let centre = 0.5 * (lo + hi);
    for k in 0..50 {
        let (u, v) = (k as f64 / 49.0, (k * 7 % 50) as f64 / 49.0);
        let p = after.point_at(u, v).unwrap();
        assert!(
            (p.distance(centre) - 2.0).abs() < 1e-12,
            "{p} at ({u}, {v})"
        );
    }
    assert_eq!(status::current().undo_steps, 2);
    harness.key_press_modifiers(Modifiers::COMMAND, Key::Z);
    harness.run_steps(2);
    assert_eq!(harness.state().document().scene.objects[6], sphere);
    harness.key_press_modifiers(Modifiers::COMMAND, Key::Z);
    harness.run_steps(2);
    assert_eq!(status::current().objects, 6);
}

#[test]
fn obj_and_gltf_files_open_in_the_editor_and_the_export_window_counts_triangles() {
    let _turn = ONE_EDITOR_AT_A_TIME
        .lock()
        .unwrap_or_else(|p| p.into_inner());
    let mut harness = editor();
    let original = harness.state().document().scene.clone();

    // The Export window shows the triangle count of the open scene before writing anything.
    harness.get_by_label("Export glTF…").click_accesskit();
    harness.run_steps(3);
    let estimate = status::current().export_estimate.unwrap_or_default();
    assert!(estimate.starts_with("about "), "{estimate}");
    let triangles: usize = estimate.split(' ').nth(1).unwrap().parse().unwrap();
    assert!(triangles > 1000, "{estimate}");

    // A knotwork export opens as its editable model, drawn by the compute shaders.
    let project = knotwork::io::project::Project {
        scene: original.clone(),
        view: None,
    };
    let options = knotwork::io::gltf::ExportOptions {
        tessellation: knotwork::kernel::tess::Tessellation::Segments(2),
        curvature: false,
        colors: None,
    };
    let glb = knotwork::io::gltf::to_glb(&knotwork::io::gltf::export(&project, &options).unwrap());
    harness.state_mut().open_file("scene.glb", glb.as_slice());
    harness.run_steps(3);
    assert_eq!(harness.state().document().scene, original);
    assert_eq!(status::current().error, None);

    // An OBJ opens as a polygon mesh: each quad one bilinear patch on the GPU.
    let cube = "o cube\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n\
        f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n";
    harness.state_mut().open_file("cube.obj", cube.as_bytes());
    harness.run_steps(3);
    let s = status::current();
    assert_eq!(
        (s.error.as_deref(), s.objects, s.patches),
        (None, 1, 6),
        "{s:?}"
    );
    assert!(
        harness.state().document().scene.objects[0]
            .geometry
            .downcast_ref::<knotwork::kernel::PolygonMesh>()
            .is_some()
    );
    // A broken file is refused and the cube stays.
    harness
        .state_mut()
        .open_file("broken.obj", b"v 0 0 0\nf 1 2 3\n");
    harness.run_steps(2);
    let s = status::current();
    assert!(
        s.error.as_deref().is_some_and(|e| e.contains("line 2")),
        "{s:?}"
    );
    assert_eq!(s.objects, 1);
}

#[test]
fn a_file_opened_during_a_drag_ends_the_drag_and_the_new_document_is_untouched() {
    let _turn = ONE_EDITOR_AT_A_TIME
        .lock()
        .unwrap_or_else(|p| p.into_inner());
    let mut harness = editor();
    let (_, at) = select_with_free_handle(&mut harness, SHEET);
    let end = drag_from(&mut harness, at, egui::vec2(8.0, 5.0), 3);
    assert!(status::current().dragging);
    // The sample with the drag's transient move in it.
    let dragged = harness.state().document().scene.clone();

    // A file arrives mid-drag (a drop, the page's openFile): a cube of 8 points, 6 quads.
    let cube = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n\
                f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n";
    harness.state_mut().open_file("cube.obj", cube.as_bytes());
    let opened = harness.state().document().clone();
    harness.run_steps(1);
    // The mouse keeps moving and is released: nothing reaches the new document.
    for k in 1..=3 {
        harness.hover_at(end + egui::vec2(12.0 * k as f32, -4.0));
        harness.run_steps(1);
    }
    press(&harness, end + egui::vec2(36.0, -4.0), false);
    harness.run_steps(2);
    let s = status::current();
    assert!(!s.dragging, "the drag ended with the old document");
    assert_eq!(s.error, None);
    let doc = harness.state().document();
    assert_eq!(doc.scene.objects.len(), 1);
    assert_eq!(doc.scene, opened.scene, "the opened cube is as read");
    assert_eq!(
        (doc.history.undo_depth(), doc.history.redo_depth()),
        (2, 0),
        "the drag ended as a step of the old document, then the open"
    );
    assert!(doc.drag().is_none());
    // Undo takes the open back: the old document, with the drag as it was when the file came.
    harness.key_press_modifiers(Modifiers::COMMAND, Key::Z);
    harness.run_steps(2);
    assert_eq!(harness.state().document().scene, dragged);
    assert_eq!(status::current().error, None);
    // Undo again: the drag's step, the sample as it was before the drag.
    harness.key_press_modifiers(Modifiers::COMMAND, Key::Z);
    harness.run_steps(2);
    let before = harness.state().document().scene.clone();
    assert_eq!(before.objects.len(), dragged.objects.len());
    assert_ne!(before.objects[SHEET], dragged.objects[SHEET]);
    // Redo twice: the cube again.
    for _ in 0..2 {
        harness.key_press_modifiers(Modifiers::COMMAND | Modifiers::SHIFT, Key::Z);
        harness.run_steps(2);
    }
    assert_eq!(harness.state().document().scene, opened.scene);
}

/// The status after a move: its support was re-evaluated, and only that.
fn reevaluated_only(support: u32, what: &str) -> status::AppStatus {
    let s = status::current();
    assert_eq!(
        (s.patches_in_drag, s.patches_reevaluated),
        (support, support),
        "{what}"
    );
    s
}

#[test]
fn the_drag_the_panel_and_the_page_take_one_path_and_re_evaluate_the_same_patches() {
    let _turn = ONE_EDITOR_AT_A_TIME
        .lock()
        .unwrap_or_else(|p| p.into_inner());
    let mut harness = editor();
    // What the page sends goes through the editor's command channel.
    let page = harness.state().command_sender();
    // The locality of an edit is the fixed tessellation's (the adaptive one re-measures every
    // patch for the view after any change).
    page.send(AppCommand::SetTessellation {
        adaptive: false,
        tolerance_px: 0.5,
    });
    harness.run_steps(2);
    assert_eq!(status::current().tessellation, "fixed");
    let (index, at) = select_with_free_handle(&mut harness, SHEET);
    let support = harness.state().document().scene.objects[SHEET]
        .clone()
        .move_control_point(index, glam::DVec3::ZERO)
        .unwrap()
        .len() as u32;
    let total = harness.state().document().scene.objects[SHEET]
        .decompose()
        .unwrap()
        .set
        .patches()
        .len() as u32;
    assert!(support > 0 && support < total, "{support} of {total}");

    // 1. The mouse.
    let end = drag_from(&mut harness, at, egui::vec2(6.0, -9.0), 3);
    press(&harness, end, false);
    harness.run_steps(2);
    let s = reevaluated_only(support, "drag");
    assert_eq!(s.undo_steps, 1);

    // 2. The page's moveControlPoint.
    let p = harness.state().document().scene.objects[SHEET].control_points()[index];
    page.send(AppCommand::Edit(Command::MovePoints {
        object: SHEET,
        moves: vec![(index, p + glam::DVec3::new(0.0, 0.0, 0.25))],
    }));
    harness.run_steps(2);
    let s = reevaluated_only(support, "page");
    assert_eq!(s.undo_steps, 2);
    assert_eq!(s.last_edit.as_deref(), Some("move 1 point(s)"));

    // 3. The panel's Move button (the selected point, by the panel's offset).
    page.send(AppCommand::SelectPoints(vec![index]));
    harness.run_steps(1);
    harness
        .get_by_role_and_label(egui::accesskit::Role::Button, "Move")
        .click_accesskit();
    harness.run_steps(2);
    let s = reevaluated_only(support, "panel");
    assert_eq!(s.error, None);
    let steps = s.undo_steps;

    // 4. A script's drag: the same steps the mouse takes, as commands.
    let before = harness.state().document().scene.objects[SHEET].control_points()[index];
    page.send(AppCommand::Drag(DragStep::Begin {
        object: SHEET,
        points: vec![index],
    }));
    for k in 1..=3 {
        page.send(AppCommand::Drag(DragStep::By(glam::DVec3::new(
            0.0,
            0.1 * f64::from(k),
            0.0,
        ))));
        harness.run_steps(1);
        assert!(status::current().dragging);
        reevaluated_only(support, "script's drag step");
    }
    page.send(AppCommand::Drag(DragStep::End));
    harness.run_steps(2);
    let s = status::current();
    assert!(!s.dragging);
    assert_eq!((s.undo_steps, s.error.as_deref()), (steps + 1, None));
    let after = harness.state().document().scene.objects[SHEET].control_points()[index];
    assert!(
        (after - before - glam::DVec3::new(0.0, 0.3, 0.0)).length() < 1e-12,
        "{before} -> {after}"
    );
}

/// An in-memory stand-in for eframe's storage.
#[derive(Default)]
struct MemoryStorage(std::collections::HashMap<String, String>);

impl eframe::Storage for MemoryStorage {
    fn get_string(&self, key: &str) -> Option<String> {
        self.0.get(key).cloned()
    }
    fn set_string(&mut self, key: &str, value: String) {
        self.0.insert(key.to_owned(), value);
    }
    fn remove_string(&mut self, key: &str) {
        self.0.remove(key);
    }
    fn flush(&mut self) {}
}

#[test]
fn closing_right_after_an_edit_writes_the_autosave() {
    let _turn = ONE_EDITOR_AT_A_TIME
        .lock()
        .unwrap_or_else(|p| p.into_inner());
    let setup = wgpu_configuration(false).wgpu_setup;
    // With the autosave on, as the app starts by default.
    let mut harness = Harness::builder()
        .with_size(egui::vec2(1280.0, 800.0))
        .wgpu_setup(setup)
        .build_eframe(|cc| KnotworkApp::new(cc, None, true));
    harness.run_steps(3);
    let moved_to = [1.5, -2.0, 3.25];
    harness
        .state()
        .command_sender()
        .send(AppCommand::Edit(Command::MovePoints {
            object: SHEET,
            moves: vec![(5, glam::DVec3::from(moved_to))],
        }));
    harness.run_steps(1);
    let s = status::current();
    assert!(
        s.revision > s.autosaved_revision,
        "within the autosave delay nothing is written yet"
    );
    // The window closes now: eframe calls save.
    let mut storage = MemoryStorage::default();
    eframe::App::save(harness.state_mut(), &mut storage);
    let text = eframe::Storage::get_string(&storage, knotwork::app::AUTOSAVE_KEY)
        .expect("the autosave was written on exit");
    let saved = knotwork::io::project::read(&text).unwrap();
    assert_eq!(saved.scene, harness.state().document().scene);
    assert_eq!(
        saved.scene.objects[SHEET].control_points()[5].to_array(),
        moved_to
    );
}

#[test]
fn an_obj_cage_is_subdivided_dragged_and_undone_in_the_editor() {
    let _turn = ONE_EDITOR_AT_A_TIME
        .lock()
        .unwrap_or_else(|p| p.into_inner());
    let mut harness = editor();
    let cube = "o cube\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n\
        f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n";
    harness.state_mut().open_file("cube.obj", cube.as_bytes());
    harness.run_steps(3);
    let (index, at) = select_with_free_handle(&mut harness, 0);
    harness.get_by_label("Subdivide").scroll_to_me();
    harness.run_steps(2);
    harness.get_by_label("Subdivide").click_accesskit();
    harness.run_steps(3);
    let s = status::current();
    // Level 2: each quad's four level-1 quads are limit-stencil patches.
    assert_eq!((s.error.as_deref(), s.patches), (None, 24), "{s:?}");
    let subdivided = harness.state().document().scene.objects[0].clone();
    assert!(
        subdivided
            .geometry
            .downcast_ref::<knotwork::scene::SubdivObject>()
            .is_some()
    );

    // Drag a cage point with the mouse: one undo step, the cage point moves.
    harness.hover_at(at);
    harness.run_steps(1);
    let end = drag_from(&mut harness, at, egui::vec2(12.0, -8.0), 4);
    press(&harness, end, false);
    harness.run_steps(2);
    let s = status::current();
    // Opening the file was a step too.
    assert_eq!((s.error.as_deref(), s.undo_steps), (None, 3), "{s:?}");
    assert!(s.patches_in_drag > 0 && s.patches_in_drag <= 24, "{s:?}");
    let dragged = harness.state().document().scene.objects[0].clone();
    assert_ne!(
        dragged.control_points()[index],
        subdivided.control_points()[index]
    );

    // Undo twice: the subdivided cube, then the mesh.
    harness.key_press_modifiers(Modifiers::COMMAND, Key::Z);
    harness.run_steps(2);
    assert_eq!(harness.state().document().scene.objects[0], subdivided);
    harness.key_press_modifiers(Modifiers::COMMAND, Key::Z);
    harness.run_steps(2);
    assert!(
        harness.state().document().scene.objects[0]
            .geometry
            .downcast_ref::<knotwork::kernel::PolygonMesh>()
            .is_some()
    );
    assert_eq!(status::current().patches, 6);
}

/// The cage of object `k` as (points, faces).
fn cage_counts(harness: &Harness<'_, KnotworkApp>, k: usize) -> (usize, usize) {
    let object = &harness.state().document().scene.objects[k];
    let subdiv = object
        .geometry
        .downcast_ref::<knotwork::scene::SubdivObject>()
        .expect("a subdivision surface");
    let mesh = subdiv.surface.mesh();
    (mesh.points().len(), mesh.faces().count())
}

/// An editor with a unit cube cage opened and subdivided, selected.
fn subdivided_cube() -> Harness<'static, KnotworkApp> {
    let mut harness = editor();
    let cube = "o cube\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n\
        f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n";
    harness.state_mut().open_file("cube.obj", cube.as_bytes());
    harness.run_steps(3);
    select_with_free_handle(&mut harness, 0);
    click_label(&mut harness, "Subdivide");
    harness
}

/// Shift + E on a cage edge, as in Blender: the pointer moved towards the selection's centre
/// sharpens it and a click sets it as one undo step; Esc leaves it as it was.
#[test]
fn shift_e_creases_the_selected_edges_by_the_pointer() {
    let _turn = ONE_EDITOR_AT_A_TIME
        .lock()
        .unwrap_or_else(|p| p.into_inner());
    let mut harness = subdivided_cube();
    let crease = |harness: &Harness<'_, KnotworkApp>| {
        harness.state().document().scene.objects[0]
            .geometry
            .downcast_ref::<knotwork::scene::SubdivObject>()
            .expect("a subdivision surface")
            .settings()
            .crease(0, 1)
    };
    assert_eq!(crease(&harness), 0.0);
    let page = harness.state().command_sender();
    page.send(AppCommand::SelectPoints(vec![0, 1]));
    harness.run_steps(2);
    let handles = status::handles();
    let at = |k: usize| {
        let p = handles[k].expect("on screen");
        Pos2::new(p[0], p[1])
    };
    let centre = at(0).lerp(at(1), 0.5);
    let steps = status::current().undo_steps;
    // Esc: nothing changes.
    harness.hover_at(centre + egui::vec2(200.0, 0.0));
    harness.run_steps(1);
    harness.key_press_modifiers(Modifiers::SHIFT, Key::E);
    harness.run_steps(1);
    harness.hover_at(centre + egui::vec2(20.0, 0.0));
    harness.run_steps(1);
    harness.key_press(Key::Escape);
    harness.run_steps(2);
    assert_eq!(crease(&harness), 0.0);
    assert_eq!(status::current().undo_steps, steps);
    // Begun 200 px out and moved to 20 px (a tenth of the way left): sharpness 9; a click
    // sets it.
    harness.hover_at(centre + egui::vec2(200.0, 0.0));
    harness.run_steps(1);
    harness.key_press_modifiers(Modifiers::SHIFT, Key::E);
    harness.run_steps(1);
    let near = centre + egui::vec2(20.0, 0.0);
    harness.hover_at(near);
    harness.run_steps(1);
    press(&harness, near, true);
    harness.run_steps(1);
    press(&harness, near, false);
    harness.run_steps(2);
    let s = status::current();
    assert_eq!(
        (s.error.as_deref(), s.undo_steps),
        (None, steps + 1),
        "{s:?}"
    );
    let sharp = crease(&harness);
    assert!((sharp - 9.0).abs() < 0.2, "{sharp}");
}

/// The clean-up tools from the panel on the cube's cage (8 points, 6 quads): each one undo
/// step with the counts its closed form gives, and a merge with nothing near refused with the
/// reason, the cage and the history as they were.
#[test]
fn cage_clean_up_tools_triangulate_dissolve_delete_and_merge_from_the_panel() {
    let _turn = ONE_EDITOR_AT_A_TIME
        .lock()
        .unwrap_or_else(|p| p.into_inner());
    let mut harness = subdivided_cube();
    let steps = status::current().undo_steps;
    // The top quad becomes two triangles: 8 points, 7 faces; its points stay selected.
    let s = panel_step(&mut harness, "Triangulate faces", vec![4, 5, 6, 7]);
    assert_eq!(
        (s.error.as_deref(), s.undo_steps),
        (None, steps + 1),
        "{s:?}"
    );
    assert_eq!(cage_counts(&harness, 0), (8, 7));
    assert_eq!(s.selected_points.len(), 4);
    // Tris to quads joins them back (and is undone, to go on from the triangles).
    let s = panel_step(&mut harness, "Tris to quads", vec![4, 5, 6, 7]);
    assert_eq!(
        (s.error.as_deref(), cage_counts(&harness, 0)),
        (None, (8, 6))
    );
    harness.key_press_modifiers(Modifiers::COMMAND, Key::Z);
    harness.run_steps(2);
    assert_eq!(cage_counts(&harness, 0), (8, 7));
    // A bottom corner: its three quads become one hexagon through its three neighbours.
    let s = panel_step(&mut harness, "Dissolve points", vec![0]);
    assert_eq!(
        (s.error.as_deref(), s.undo_steps),
        (None, steps + 2),
        "{s:?}"
    );
    assert_eq!(cage_counts(&harness, 0), (7, 5));
    // Nothing lies within the merge distance of anything: refused, nothing changes.
    let before = harness.state().document().scene.objects[0].clone();
    let s = panel_step(&mut harness, "Merge by distance", vec![]);
    let error = s.error.clone().unwrap_or_default();
    assert!(error.contains("nothing to merge"), "{s:?}");
    assert_eq!(s.undo_steps, steps + 2);
    assert_eq!(
        harness.state().document().scene.objects[0].control_points(),
        before.control_points()
    );
    // Point 6 (the file's 7: a top corner) goes with every face on it.
    let faces_on_it = cage_faces_on(&harness, 6);
    let s = panel_step(&mut harness, "Delete points", vec![6]);
    assert_eq!(
        (s.error.as_deref(), s.undo_steps),
        (None, steps + 3),
        "{s:?}"
    );
    assert_eq!(cage_counts(&harness, 0).1, 5 - faces_on_it);
    // Undo walks back through every step to the cube.
    for _ in 0..3 {
        harness.key_press_modifiers(Modifiers::COMMAND, Key::Z);
        harness.run_steps(2);
    }
    assert_eq!(cage_counts(&harness, 0), (8, 6));
}

/// Fill, Grid fill, Connect, Extrude edges and Spin from the panel: the open top of the cube
/// (its lid deleted) filled again (by a face, then by a grid), its bottom split along a
/// diagonal, the rim pulled up by the extrusion's distance, and the bottom face spun a quarter
/// turn in 12 steps.
#[test]
fn cage_fill_connect_extrude_edges_and_spin_from_the_panel() {
    let _turn = ONE_EDITOR_AT_A_TIME
        .lock()
        .unwrap_or_else(|p| p.into_inner());
    let mut harness = subdivided_cube();
    let steps = status::current().undo_steps;
    panel_step(&mut harness, "Delete faces", vec![4, 5, 6, 7]);
    assert_eq!(cage_counts(&harness, 0), (8, 5));
    // Fill puts a face back over the rim, and Connect splits the bottom face along its
    // diagonal; each is undone.
    let undo = |harness: &mut Harness<'_, KnotworkApp>| {
        harness.key_press_modifiers(Modifiers::COMMAND, Key::Z);
        harness.run_steps(2);
    };
    let s = panel_step(&mut harness, "Fill", vec![4, 5, 6, 7]);
    assert_eq!(
        (s.error.as_deref(), cage_counts(&harness, 0)),
        (None, (8, 6))
    );
    undo(&mut harness);
    // Grid fill over the same rim of four edges: one quad.
    let s = panel_step(&mut harness, "Grid fill", vec![4, 5, 6, 7]);
    assert_eq!(
        (s.error.as_deref(), cage_counts(&harness, 0)),
        (None, (8, 6))
    );
    undo(&mut harness);
    let s = panel_step(&mut harness, "Connect", vec![0, 2]);
    assert_eq!(
        (s.error.as_deref(), cage_counts(&harness, 0)),
        (None, (8, 6))
    );
    undo(&mut harness);
    assert_eq!(cage_counts(&harness, 0), (8, 5));
    let open = harness.state().document().scene.objects[0].control_points();
    let s = panel_step(&mut harness, "Extrude edges", vec![4, 5, 6, 7]);
    assert_eq!(
        (s.error.as_deref(), s.undo_steps),
        (None, steps + 2),
        "{s:?}"
    );
    assert_eq!(cage_counts(&harness, 0), (12, 9));
    // The rim's copies lie the extrusion's distance (half the mean edge: 0.5) straight out
    // of the side faces' planes: each is its rim point moved along the box's up axis.
    let pulled = harness.state().document().scene.objects[0].control_points();
    let up = (open[4] - open[0]).normalize();
    for k in 0..4 {
        let moved = pulled[8 + k] - open[4 + k];
        assert!((moved - up * 0.5).length() < 1e-9, "{k}: {moved}");
    }
    // The bottom face (points 0-3) spun 90° round z in 12 steps: 4 side quads a step, the
    // face moved to the end; the border's copies at every step.
    let s = panel_step(&mut harness, "Spin", vec![0, 1, 2, 3]);
    assert_eq!(
        (s.error.as_deref(), s.undo_steps),
        (None, steps + 3),
        "{s:?}"
    );
    assert_eq!(cage_counts(&harness, 0), (12 + 48, 9 + 48));
    // Every new point is an old one turned round z: its distance from the z axis and its
    // height are a bottom corner's.
    let spun = harness.state().document().scene.objects[0].control_points();
    for p in &spun[12..] {
        let matched = open[..4].iter().any(|q| {
            (p.truncate().length() - q.truncate().length()).abs() < 1e-9 && (p.z - q.z).abs() < 1e-9
        });
        assert!(matched, "{p} is no bottom corner turned round z");
    }
}

/// K on a cage, as Blender's Knife with Cut Through: a line dragged across the cube on the
/// screen cuts every face under it, front and back, as one undo step; Esc puts the knife away
/// with nothing cut. Then *Bevel vertices* cuts a corner off.
#[test]
fn the_knife_cuts_the_cage_along_a_line_dragged_across_it_and_a_corner_bevels() {
    let _turn = ONE_EDITOR_AT_A_TIME
        .lock()
        .unwrap_or_else(|p| p.into_inner());
    let mut harness = subdivided_cube();
    let steps = status::current().undo_steps;
    let handles = status::handles();
    let corners: Vec<Pos2> = (0..8)
        .map(|k| {
            let p = handles[k].expect("on screen");
            Pos2::new(p[0], p[1])
        })
        .collect();
    let left = corners.iter().map(|p| p.x).fold(f32::INFINITY, f32::min);
    let right = corners
        .iter()
        .map(|p| p.x)
        .fold(f32::NEG_INFINITY, f32::max);
    let middle = corners.iter().map(|p| p.y).sum::<f32>() / 8.0;
    // Esc: nothing cut, no step.
    harness.key_press(Key::K);
    harness.run_steps(1);
    harness.key_press(Key::Escape);
    harness.run_steps(2);
    assert_eq!(cage_counts(&harness, 0), (8, 6));
    assert_eq!(status::current().undo_steps, steps);
    // A level line through the cube's middle, from left of it to right of it.
    harness.key_press(Key::K);
    harness.run_steps(1);
    let start = Pos2::new(left - 15.0, middle);
    let step = egui::vec2((right - left + 30.0) / 8.0, 0.0);
    let end = drag_from(&mut harness, start, step, 8);
    press(&harness, end, false);
    harness.run_steps(3);
    let s = status::current();
    assert_eq!(
        (s.error.as_deref(), s.undo_steps),
        (None, steps + 1),
        "{s:?}"
    );
    // The plane through the line and the eye crosses the cube's inside: k of its 12 edges
    // (3 to 6, as any plane through a box's inside and no corner), each taking a point, and
    // k faces split in two.
    let (points, faces) = cage_counts(&harness, 0);
    assert!((11..=14).contains(&points), "{points} points");
    assert_eq!(faces, 6 + points - 8);
    harness.key_press_modifiers(Modifiers::COMMAND, Key::Z);
    harness.run_steps(2);
    assert_eq!(cage_counts(&harness, 0), (8, 6));
    // Bevel vertices on a corner: three points for one, a triangle where it was.
    let s = panel_step(&mut harness, "Bevel vertices", vec![0]);
    assert_eq!(
        (s.error.as_deref(), s.undo_steps),
        (None, steps + 1),
        "{s:?}"
    );
    assert_eq!(cage_counts(&harness, 0), (10, 7));
}

/// Selects `points` of the cage and clicks the panel's `label`: the status after.
fn panel_step(
    harness: &mut Harness<'_, KnotworkApp>,
    label: &str,
    points: Vec<usize>,
) -> status::AppStatus {
    harness
        .state()
        .command_sender()
        .send(AppCommand::SelectPoints(points));
    harness.run_steps(2);
    click_label(harness, label);
    status::current()
}

/// How many faces of object 0's cage use point `v`.
fn cage_faces_on(harness: &Harness<'_, KnotworkApp>, v: u32) -> usize {
    let object = &harness.state().document().scene.objects[0];
    let subdiv = object
        .geometry
        .downcast_ref::<knotwork::scene::SubdivObject>()
        .expect("a subdivision surface");
    subdiv
        .surface
        .mesh()
        .faces()
        .filter(|f| f.contains(&v))
        .count()
}

#[test]
fn cage_tools_extrude_inset_and_select_loops_from_the_panel_and_the_mouse() {
    let _turn = ONE_EDITOR_AT_A_TIME
        .lock()
        .unwrap_or_else(|p| p.into_inner());
    let mut harness = subdivided_cube();
    let subdivided = harness.state().document().scene.objects[0].clone();
    let steps = status::current().undo_steps;

    // The top face's points: Extrude lifts it by half the mean edge (0.5), with four sides;
    // the lifted face stays selected, and Inset puts a strip inside it.
    let page = harness.state().command_sender();
    page.send(AppCommand::SelectPoints(vec![4, 5, 6, 7]));
    harness.run_steps(2);
    click_label(&mut harness, "Extrude faces");
    let s = status::current();
    assert_eq!(
        (s.error.as_deref(), s.undo_steps),
        (None, steps + 1),
        "{s:?}"
    );
    assert_eq!(cage_counts(&harness, 0), (12, 10));
    // (The file's y is up: the editor turns it to z, so positions are compared by distance.)
    let centre = |points: &[glam::DVec3], of: &[u32]| {
        of.iter().map(|&k| points[k as usize]).sum::<glam::DVec3>() / of.len() as f64
    };
    let lifted = harness.state().document().scene.objects[0].control_points();
    assert_eq!(s.selected_points, [8, 9, 10, 11]);
    let rise = centre(&lifted, &s.selected_points)
        .distance(centre(&subdivided.control_points(), &[4, 5, 6, 7]));
    assert!((rise - 0.5).abs() < 1e-12, "{rise}");
    click_label(&mut harness, "Inset faces");
    let s = status::current();
    assert_eq!(
        (s.error.as_deref(), s.undo_steps),
        (None, steps + 2),
        "{s:?}"
    );
    assert_eq!(cage_counts(&harness, 0), (16, 14));
    assert_eq!(s.selected_points.len(), 4);

    // Two points of a vertical side edge: Loop selects the loop round the cube's side (the
    // corners there have three edges, so it stops), Ring the four vertical edges round it.
    page.send(AppCommand::SelectPoints(vec![0, 4]));
    harness.run_steps(2);
    click_label(&mut harness, "Ring");
    let ring = status::current().selected_points;
    assert_eq!(ring.len(), 8, "{ring:?}");

    // Alt + click on an edge of the cage on screen selects its loop.
    page.send(AppCommand::SelectPoints(vec![]));
    harness.run_steps(2);
    let handles = status::handles();
    let on_screen = |k: usize| {
        handles
            .get(k)
            .copied()
            .flatten()
            .map(|p| Pos2::new(p[0], p[1]))
    };
    let object = harness.state().document().scene.objects[0].clone();
    let subdiv = object
        .geometry
        .downcast_ref::<knotwork::scene::SubdivObject>()
        .expect("a subdivision surface");
    let mesh = subdiv.surface.mesh();
    // An edge whose middle is clear of every point and every other edge's middle.
    let edges: Vec<(u32, u32)> = mesh
        .faces()
        .flat_map(|f| {
            (0..f.len()).map(move |c| {
                (
                    f[c].min(f[(c + 1) % f.len()]),
                    f[c].max(f[(c + 1) % f.len()]),
                )
            })
        })
        .collect();
    let middles: Vec<Option<Pos2>> = edges
        .iter()
        .map(|&(a, b)| Some(on_screen(a as usize)?.lerp(on_screen(b as usize)?, 0.5)))
        .collect();
    let (k, at) = middles
        .iter()
        .enumerate()
        .filter_map(|(k, m)| m.map(|m| (k, m)))
        .filter(|(_, m)| m.x > 450.0 && m.x < 1200.0 && m.y > 100.0 && m.y < 700.0)
        .find(|(k, m)| {
            let (a, b) = edges[*k];
            handles
                .iter()
                .flatten()
                .all(|p| Pos2::new(p[0], p[1]).distance(*m) > 12.0)
                && middles
                    .iter()
                    .enumerate()
                    .all(|(j, n)| edges[j] == (a, b) || n.is_none_or(|n| n.distance(*m) > 12.0))
        })
        .unwrap_or_else(|| panic!("a clear edge on screen: {middles:?}"));
    harness.event(Event::ModifiersChanged(Modifiers::ALT));
    click_at(&mut harness, at);
    harness.event(Event::ModifiersChanged(Modifiers::NONE));
    harness.run_steps(1);
    let selected = status::current().selected_points;
    let (a, b) = edges[k];
    assert!(
        selected.contains(&a) && selected.contains(&b) && selected.len() >= 2,
        "edge {a}-{b}: {selected:?}"
    );

    // Edge mode (2): a click on the same edge selects just its two points.
    harness.key_press(Key::Num2);
    harness.run_steps(1);
    click_at(&mut harness, at);
    let mut selected = status::current().selected_points;
    selected.sort_unstable();
    assert_eq!(selected, [a.min(b), a.max(b)]);

    // Face mode (3): a click inside a face on screen selects the corners of the nearest face
    // there, which holds the cursor.
    harness.key_press(Key::Num3);
    harness.run_steps(1);
    let faces: Vec<Vec<u32>> = mesh.faces().map(<[u32]>::to_vec).collect();
    let outline =
        |f: &[u32]| -> Option<Vec<Pos2>> { f.iter().map(|&v| on_screen(v as usize)).collect() };
    let (face, at) = faces
        .iter()
        .filter_map(|f| {
            let corners = outline(f)?;
            let centre =
                corners.iter().fold(Pos2::ZERO, |c, p| c + p.to_vec2()) / corners.len() as f32;
            (centre.x > 450.0 && centre.x < 1200.0 && centre.y > 100.0 && centre.y < 700.0)
                .then_some((f.clone(), centre))
        })
        .next()
        .expect("a face on screen");
    click_at(&mut harness, at);
    let picked = status::current().selected_points;
    let holder = faces
        .iter()
        .find(|f| {
            let mut f: Vec<u32> = f.to_vec();
            f.sort_unstable();
            let mut p = picked.clone();
            p.sort_unstable();
            f == p
        })
        .unwrap_or_else(|| panic!("{picked:?} is not a face's corners ({face:?} under {at:?})"));
    let corners = outline(holder).expect("on screen");
    let inside = (0..corners.len()).fold(false, |inside, k| {
        let (p, q) = (corners[k], corners[(k + 1) % corners.len()]);
        if (p.y > at.y) != (q.y > at.y) && at.x < p.x + (at.y - p.y) / (q.y - p.y) * (q.x - p.x) {
            !inside
        } else {
            inside
        }
    });
    assert!(inside, "{holder:?} does not hold {at:?}");

    // A lasso (Ctrl + right drag) round one point selects it alone.
    harness.key_press(Key::Num1);
    let (k, centre) = handles
        .iter()
        .enumerate()
        .filter_map(|(k, p)| p.map(|p| (k, Pos2::new(p[0], p[1]))))
        .find(|(_, p)| {
            p.x > 450.0
                && p.y > 100.0
                && handles
                    .iter()
                    .flatten()
                    .filter(|q| Pos2::new(q[0], q[1]).distance(*p) < 30.0)
                    .count()
                    == 1
        })
        .expect("a point clear of the others");
    harness.event(Event::ModifiersChanged(Modifiers::COMMAND));
    let round: Vec<Pos2> = (0..=12)
        .map(|j| {
            let t = std::f32::consts::TAU * j as f32 / 12.0;
            centre + egui::vec2(t.cos(), t.sin()) * 15.0
        })
        .collect();
    harness.hover_at(round[0]);
    harness.run_steps(1);
    let button = |pos: Pos2, pressed: bool| Event::PointerButton {
        pos,
        button: PointerButton::Secondary,
        pressed,
        modifiers: Modifiers::COMMAND,
    };
    harness.event(button(round[0], true));
    harness.run_steps(1);
    for &p in &round[1..] {
        harness.hover_at(p);
        harness.run_steps(1);
    }
    harness.event(button(round[12], false));
    harness.event(Event::ModifiersChanged(Modifiers::NONE));
    harness.run_steps(2);
    assert_eq!(status::current().selected_points, [k as u32]);

    // Undo twice: the subdivided cube.
    harness.key_press_modifiers(Modifiers::COMMAND, Key::Z);
    harness.run_steps(2);
    harness.key_press_modifiers(Modifiers::COMMAND, Key::Z);
    harness.run_steps(2);
    assert_eq!(harness.state().document().scene.objects[0], subdivided);
}

/// Drags the handle at `at` by `by` with the mouse and checks that it made one undo step;
/// returns object 0's control points after it.
fn drag_as_one_step(
    harness: &mut Harness<'_, KnotworkApp>,
    at: Pos2,
    by: egui::Vec2,
) -> Vec<glam::DVec3> {
    let steps = status::current().undo_steps;
    harness.hover_at(at);
    harness.run_steps(1);
    let end = drag_from(harness, at, by, 4);
    press(harness, end, false);
    harness.run_steps(2);
    let s = status::current();
    assert_eq!(
        (s.error.as_deref(), s.undo_steps),
        (None, steps + 1),
        "{s:?}"
    );
    harness.state().document().scene.objects[0].control_points()
}

#[test]
fn with_x_mirror_editing_a_dragged_cage_point_moves_its_image_across_the_plane() {
    let _turn = ONE_EDITOR_AT_A_TIME
        .lock()
        .unwrap_or_else(|p| p.into_inner());
    let mut harness = editor();
    // A box symmetric across x = 0 (the file's y-up becomes z-up; x stays).
    let cube = "o cube\nv -1 -1 -1\nv 1 -1 -1\nv 1 1 -1\nv -1 1 -1\nv -1 -1 1\nv 1 -1 1\n\
        v 1 1 1\nv -1 1 1\nf 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n";
    harness.state_mut().open_file("cube.obj", cube.as_bytes());
    harness.run_steps(3);
    let (index, at) = select_with_free_handle(&mut harness, 0);
    click_label(&mut harness, "Subdivide");
    let before = harness.state().document().scene.objects[0].control_points();
    let image = glam::DVec3::new(-before[index].x, before[index].y, before[index].z);
    let partner = (0..before.len())
        .find(|&j| before[j].distance(image) < 1e-9)
        .expect("the point's image across x = 0");
    click_label(&mut harness, "X mirror");
    let after = drag_as_one_step(&mut harness, at, egui::vec2(14.0, -9.0));
    let moved = after[index] - before[index];
    assert!(moved.length() > 1e-3, "{moved}");
    let mirrored = after[partner] - before[partner];
    assert!(
        (mirrored - glam::DVec3::new(-moved.x, moved.y, moved.z)).length() < 1e-9,
        "{moved} {mirrored}"
    );
    // Every other point stays.
    for k in (0..after.len()).filter(|&k| k != index && k != partner) {
        assert_eq!(after[k], before[k], "point {k}");
    }
}

#[test]
fn with_proportional_editing_points_near_a_dragged_one_follow_by_the_smooth_falloff() {
    let _turn = ONE_EDITOR_AT_A_TIME
        .lock()
        .unwrap_or_else(|p| p.into_inner());
    let mut harness = editor();
    // A flat 5 × 5 grid of points 0.5 apart: the default radius 1 takes the neighbours.
    let mut grid = String::from("o grid\n");
    for j in 0..5 {
        for i in 0..5 {
            grid += &format!("v {} 0 {}\n", 0.5 * f64::from(i), 0.5 * f64::from(j));
        }
    }
    for j in 0..4 {
        for i in 0..4 {
            let k = j * 5 + i + 1;
            grid += &format!("f {} {} {} {}\n", k, k + 5, k + 6, k + 1);
        }
    }
    harness.state_mut().open_file("grid.obj", grid.as_bytes());
    harness.run_steps(3);
    let (index, at) = select_with_free_handle(&mut harness, 0);
    click_label(&mut harness, "Subdivide");
    let before = harness.state().document().scene.objects[0].control_points();
    key(&mut harness, Key::O, Modifiers::NONE);
    let after = drag_as_one_step(&mut harness, at, egui::vec2(10.0, -12.0));
    let moved = after[index] - before[index];
    assert!(moved.length() > 1e-3, "{moved}");
    let mut followed = 0;
    for k in 0..after.len() {
        let d = before[k].distance(before[index]) / 1.0;
        let share = if d < 1.0 {
            let s = 1.0 - d;
            s * s * (3.0 - 2.0 * s)
        } else {
            0.0
        };
        let offset = after[k] - before[k];
        assert!(
            (offset - moved * share).length() < 1e-9,
            "point {k} at {d}: {offset} vs {moved}"
        );
        followed += usize::from(share > 0.0 && k != index);
    }
    assert!(followed >= 3, "{followed}");
}

fn click_at(harness: &mut Harness<'_, KnotworkApp>, pos: Pos2) {
    harness.hover_at(pos);
    harness.run_steps(1);
    press(harness, pos, true);
    harness.run_steps(1);
    press(harness, pos, false);
    harness.run_steps(2);
}

#[test]
fn a_circle_drawn_on_a_surface_with_the_mouse_cuts_a_hole_and_undo_restores() {
    let _turn = ONE_EDITOR_AT_A_TIME
        .lock()
        .unwrap_or_else(|p| p.into_inner());
    let mut harness = editor();
    let plane = r#"{"type": "nurbs_surface", "name": "Plate", "degree": [1, 1],
        "knots": [[0, 0, 1, 1], [0, 0, 1, 1]],
        "points": [[[-1, -1, 0], [-1, 1, 0]], [[1, -1, 0], [1, 1, 0]]]}"#;
    harness
        .state_mut()
        .open_file("plate.json", plane.as_bytes());
    harness.run_steps(3);
    select_with_free_handle(&mut harness, 0);
    let corners: Vec<Pos2> = status::handles()
        .iter()
        .map(|h| {
            h.map(|p| Pos2::new(p[0], p[1]))
                .expect("every corner on screen")
        })
        .collect();
    // The screen point of (u, v), near enough on the plane: the corners' bilinear blend.
    let at = |u: f32, v: f32| {
        let blend = |a: Pos2, b: Pos2, t: f32| a + (b - a) * t;
        blend(
            blend(corners[0], corners[1], v),
            blend(corners[2], corners[3], v),
            u,
        )
    };
    let centre = at(0.5, 0.5);
    // The pixel at p of the harness's rendering (physical pixels).
    let pixel = |harness: &mut Harness<'_, KnotworkApp>, p: Pos2| -> [u8; 4] {
        let image = harness.render().expect("the harness renders");
        let scale = image.width() as f32 / 1280.0;
        let (x, y) = ((p.x * scale).round() as u32, (p.y * scale).round() as u32);
        let k = 4 * (y * image.width() + x) as usize;
        let raw = image.into_raw();
        [raw[k], raw[k + 1], raw[k + 2], raw[k + 3]]
    };
    let before = pixel(&mut harness, centre);
    let [r, g, b, _] = knotwork::render::BACKGROUND;
    let background = [r, g, b].map(|c| (c * 255.0).round() as u8);
    let is_background = |c: [u8; 4]| {
        c[..3]
            .iter()
            .zip(background)
            .all(|(&a, b)| a.abs_diff(b) < 12)
    };
    assert!(
        !is_background(before),
        "the plate covers its centre: {before:?}"
    );

    harness.get_by_label("Circle").scroll_to_me();
    harness.run_steps(2);
    harness.get_by_label("Circle").click_accesskit();
    harness.run_steps(2);
    click_at(&mut harness, centre);
    click_at(&mut harness, at(0.7, 0.5));
    let s = status::current();
    // Opening the plate, then the trim.
    assert_eq!((s.error.as_deref(), s.undo_steps), (None, 2), "{s:?}");
    let Some(t) = harness.state().document().scene.objects[0]
        .geometry
        .downcast_ref::<knotwork::kernel::TrimmedSurface>()
    else {
        panic!("the plate is trimmed");
    };
    // The boundary and the hole; the hole is around the centre.
    assert_eq!(t.loops().len(), 2);
    assert!(!t.contains(0.5, 0.5) && t.contains(0.02, 0.02));
    harness.run_steps(3);
    let after = pixel(&mut harness, centre);
    assert!(
        is_background(after),
        "the hole shows the background: {after:?}"
    );

    harness.key_press(Key::Escape);
    harness.key_press_modifiers(Modifiers::COMMAND, Key::Z);
    harness.run_steps(3);
    assert!(
        harness.state().document().scene.objects[0]
            .geometry
            .downcast_ref::<knotwork::kernel::NurbsSurface>()
            .is_some()
    );
    let undone = pixel(&mut harness, centre);
    assert!(!is_background(undone), "{undone:?}");
}

/// Runs frames until a camera transition (a quarter of a second) is over.
fn settle(harness: &mut Harness<'_, KnotworkApp>) {
    for _ in 0..40 {
        harness.step();
        std::thread::sleep(std::time::Duration::from_millis(10));
    }
    harness.run_steps(2);
}

fn key(harness: &mut Harness<'_, KnotworkApp>, key: Key, modifiers: Modifiers) {
    harness.event(Event::Key {
        key,
        physical_key: None,
        pressed: true,
        repeat: false,
        modifiers,
    });
    harness.event(Event::Key {
        key,
        physical_key: None,
        pressed: false,
        repeat: false,
        modifiers,
    });
}

/// The harness's picture: width and RGBA rows.
fn picture(harness: &mut Harness<'_, KnotworkApp>) -> (u32, Vec<u8>) {
    let image = harness.render().expect("the harness renders");
    (image.width(), image.into_raw())
}

/// Viewport pixels (right of the panel) that differ between two pictures.
fn viewport_difference(a: &(u32, Vec<u8>), b: &(u32, Vec<u8>)) -> usize {
    let width = a.0 as usize;
    let x0 = (420.0 * a.0 as f32 / 1280.0) as usize;
    a.1.chunks_exact(4)
        .zip(b.1.chunks_exact(4))
        .enumerate()
        .filter(|(k, (p, q))| {
            k % width >= x0 && p.iter().zip(*q).take(3).any(|(u, v)| u.abs_diff(*v) > 24)
        })
        .count()
}

#[test]
fn standard_views_from_the_keypad_the_grid_and_the_triad() {
    let _turn = ONE_EDITOR_AT_A_TIME
        .lock()
        .unwrap_or_else(|e| e.into_inner());
    let mut harness = editor();
    key(&mut harness, Key::Num7, Modifiers::NONE);
    settle(&mut harness);
    let s = status::current();
    assert_eq!((s.view.as_str(), s.orthographic), ("top", true), "{s:?}");
    let camera = harness.state().view().camera;
    assert!((camera.pitch - std::f32::consts::FRAC_PI_2).abs() < 1e-6);
    // Top view: X to the right, Y up on the screen.
    let (right, up, _) = camera.axes();
    assert!(
        right.distance(glam::Vec3::X) < 1e-5 && up.distance(glam::Vec3::Y) < 1e-5,
        "{right} {up}"
    );
    key(&mut harness, Key::Num1, Modifiers::COMMAND);
    settle(&mut harness);
    assert_eq!(status::current().view, "back");
    key(&mut harness, Key::Num3, Modifiers::NONE);
    settle(&mut harness);
    assert_eq!(status::current().view, "right");
    key(&mut harness, Key::Num5, Modifiers::NONE);
    harness.run_steps(2);
    let s = status::current();
    assert!(!s.orthographic && s.view == "custom", "{s:?}");

    // The grid: hiding it from the View menu changes the picture; its step follows the zoom.
    key(&mut harness, Key::Num1, Modifiers::NONE);
    settle(&mut harness);
    let step = status::current().grid_step.expect("the grid is shown");
    assert!(step > 0.0);
    let with_grid = picture(&mut harness);
    harness.get_by_label("View").click();
    harness.run_steps(2);
    harness.get_by_label("Ground grid").click();
    harness.run_steps(3);
    assert_eq!(status::current().grid_step, None);
    key(&mut harness, Key::Escape, Modifiers::NONE);
    harness.run_steps(3);
    let without_grid = picture(&mut harness);
    let changed = viewport_difference(&with_grid, &without_grid);
    assert!(changed > 500, "hiding the grid changed {changed} pixels");

    // The View menu's perspective view.
    harness.get_by_label("View").click();
    harness.run_steps(2);
    harness.get_by_label("Perspective (0)").click();
    settle(&mut harness);
    assert_eq!(status::current().view, "perspective");
}

#[test]
fn the_gizmo_moves_a_point_along_its_axis_and_undo_restores() {
    let _turn = ONE_EDITOR_AT_A_TIME
        .lock()
        .unwrap_or_else(|e| e.into_inner());
    let mut harness = editor();
    let (index, at) = select_with_free_handle(&mut harness, SHEET);
    click_at(&mut harness, at);
    assert_eq!(status::current().selected_points, vec![index as u32]);
    let before = harness.state().document().scene.objects[SHEET].control_points()[index];
    let parts = harness.state().gizmo_screen_parts();
    let arrow = parts
        .iter()
        .find(|(h, _)| *h == knotwork::app::GizmoHandle::Axis(0))
        .map(|(_, p)| p.clone())
        .expect("the move gizmo's X arrow");
    let (base, tip) = (arrow[0], arrow[1]);
    let grab = base + (tip - base) * 0.7;
    let direction = (tip - base).normalized();
    let end = drag_from(&mut harness, grab, direction * 6.0, 8);
    // The hint names the arrow's axis, not the view plane of handle drags.
    let s = status::current();
    assert!(s.dragging, "{s:?}");
    assert_eq!(s.constraint, "gizmo: along the X axis");
    press(&harness, end, false);
    harness.run_steps(3);
    let after = harness.state().document().scene.objects[SHEET].control_points()[index];
    let moved = after - before;
    assert!(moved.x > 1e-3, "{moved}");
    assert!(
        moved.y.abs() < 1e-12 && moved.z.abs() < 1e-12,
        "only x changes: {moved}"
    );
    assert_eq!(status::current().undo_steps, 1);
    harness.event(Event::Key {
        key: Key::Z,
        physical_key: None,
        pressed: true,
        repeat: false,
        modifiers: Modifiers::COMMAND,
    });
    harness.run_steps(3);
    let restored = harness.state().document().scene.objects[SHEET].control_points()[index];
    assert_eq!(restored, before);

    // E switches the gizmo to rotation.
    key(&mut harness, Key::E, Modifiers::NONE);
    harness.run_steps(2);
    assert_eq!(status::current().gizmo, "rotate");
}

#[test]
fn continuity_hair_and_table_cover_the_teapot() {
    let _turn = ONE_EDITOR_AT_A_TIME
        .lock()
        .unwrap_or_else(|e| e.into_inner());
    let mut harness = editor();
    let before = picture(&mut harness);
    harness
        .state()
        .command_sender()
        .send(AppCommand::SetAnalysis(knotwork::view::AnalysisSettings {
            continuity: true,
            ..Default::default()
        }));
    harness.run_steps(4);
    let s = status::current();
    let c = s.continuity.expect("continuity is shown");
    assert!(c.edges >= 40, "{c:?}");
    assert_eq!(c.verdicts.len() as u32, c.edges);
    assert!(c.passing > 0);
    assert!(!c.verdicts.iter().any(|v| v == "open"), "{c:?}");
    let after = picture(&mut harness);
    let changed = viewport_difference(&before, &after);
    assert!(changed > 200, "the hair changed {changed} pixels");
}

#[test]
fn a_lattice_is_added_dragged_with_the_mouse_and_applied_from_the_panel() {
    let _turn = ONE_EDITOR_AT_A_TIME
        .lock()
        .unwrap_or_else(|p| p.into_inner());
    let mut harness = editor();
    let original = harness.state().document().scene.objects[SHEET].clone();
    select_with_free_handle(&mut harness, SHEET);
    harness.get_by_label("Add lattice").scroll_to_me();
    harness.run_steps(2);
    harness.get_by_label("Add lattice").click_accesskit();
    harness.run_steps(3);
    let s = status::current();
    assert_eq!((s.error.as_deref(), s.undo_steps), (None, 1), "{s:?}");
    let with_lattice = harness.state().document().scene.objects[SHEET].clone();
    let lattice = with_lattice
        .lattice
        .clone()
        .expect("the sheet has a lattice");
    assert_eq!(lattice.degrees(), [2, 2, 2]);
    assert_eq!(
        with_lattice.control_point_count(),
        27,
        "the handles are the lattice's"
    );

    // Drag a lattice point with the mouse: one undo step; the sheet stays, the lattice moves.
    let (index, at) = select_with_free_handle(&mut harness, SHEET);
    harness.hover_at(at);
    harness.run_steps(1);
    let end = drag_from(&mut harness, at, egui::vec2(10.0, -12.0), 4);
    press(&harness, end, false);
    harness.run_steps(2);
    let s = status::current();
    assert_eq!((s.error.as_deref(), s.undo_steps), (None, 2), "{s:?}");
    let dragged = harness.state().document().scene.objects[SHEET].clone();
    assert_eq!(dragged.geometry, original.geometry);
    assert_ne!(
        dragged.control_points()[index],
        with_lattice.control_points()[index]
    );

    // Apply: the (2, 5) sheet through a lattice of total degree 6 is refitted, and says so.
    harness.get_by_label("Apply").scroll_to_me();
    harness.run_steps(2);
    harness.get_by_label("Apply").click_accesskit();
    harness.run_steps(3);
    let s = status::current();
    assert_eq!(s.error, None, "{s:?}");
    assert!(
        s.notice.as_deref().is_some_and(|n| n.contains("refitted")),
        "{s:?}"
    );
    let applied = harness.state().document().scene.objects[SHEET].clone();
    assert!(applied.lattice.is_none());
    assert_ne!(applied.geometry, original.geometry);

    // Undo three times: the sheet as it was.
    for _ in 0..3 {
        harness.key_press_modifiers(Modifiers::COMMAND, Key::Z);
        harness.run_steps(2);
    }
    assert_eq!(harness.state().document().scene.objects[SHEET], original);
}

/// New (sample or empty) and Open are undo steps, and the work they replace stays in the Recent
/// list, from which it opens again.
#[test]
fn new_and_open_are_undo_steps_and_the_work_they_replace_is_in_recent() {
    let _turn = ONE_EDITOR_AT_A_TIME
        .lock()
        .unwrap_or_else(|p| p.into_inner());
    let mut harness = editor();
    // Some work: a point moved.
    let page = harness.state().command_sender();
    page.send(AppCommand::Edit(Command::MovePoints {
        object: SHEET,
        moves: vec![(5, glam::DVec3::new(1.0, 2.0, 3.0))],
    }));
    harness.run_steps(2);
    let work = harness.state().document().scene.clone();

    // New → Empty scene, from the menu.
    harness.get_by_label("New").click_accesskit();
    harness.run_steps(2);
    harness.get_by_label("Empty scene").click_accesskit();
    harness.run_steps(3);
    let s = status::current();
    assert_eq!((s.objects, s.undo_steps), (0, 2), "{s:?}");
    assert_eq!(s.last_edit.as_deref(), Some("new empty scene"));
    assert_eq!(s.recent, vec!["sample scene · 6 objects".to_owned()]);

    // Undo: the work is back, exactly.
    harness.key_press_modifiers(Modifiers::COMMAND, Key::Z);
    harness.run_steps(2);
    assert_eq!(harness.state().document().scene, work);

    // Redo, then open a file: one more step; the empty scene was not edited, so it is not
    // remembered.
    harness.key_press_modifiers(Modifiers::COMMAND | Modifiers::SHIFT, Key::Z);
    harness.run_steps(2);
    let cube = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n";
    harness.state_mut().open_file("quad.obj", cube.as_bytes());
    harness.run_steps(2);
    let s = status::current();
    assert_eq!(
        (s.objects, s.undo_steps, s.recent.len()),
        (1, 3, 1),
        "{s:?}"
    );

    // The Recent list opens the work again, as one more step.
    harness.get_by_label("Recent").click_accesskit();
    harness.run_steps(2);
    harness
        .get_by_label("sample scene · 6 objects")
        .click_accesskit();
    harness.run_steps(3);
    let s = status::current();
    assert_eq!(
        (s.objects, s.undo_steps, s.error.as_deref()),
        (6, 4, None),
        "{s:?}"
    );
    assert_eq!(harness.state().document().scene, work);

    // Undo takes the document back to quad.obj, and its name with it: New remembers it as
    // quad.obj, not as the sample scene the Recent entry was.
    page.send(AppCommand::Undo);
    page.send(AppCommand::NewDocument { empty: true });
    harness.run_steps(3);
    let s = status::current();
    assert_eq!(s.objects, 0, "{s:?}");
    assert_eq!(
        s.recent.first().map(String::as_str),
        Some("quad.obj · 1 object")
    );

    // An error is the last command's: a later command that succeeds clears it.
    page.send(AppCommand::Select(Some(99)));
    harness.run_steps(1);
    let error = status::current().error;
    assert!(
        error.as_deref().is_some_and(|e| e.contains("no object 99")),
        "{error:?}"
    );
    page.send(AppCommand::Select(None));
    harness.run_steps(1);
    assert_eq!(status::current().error, None);
}

/// A field shows the current value of what is selected: the weight of the selected point, the
/// transform fields "no change" after Apply and for another object, and the edited point the
/// same point after a knot insertion renumbers the net (as the issue saw with point 15).
#[test]
fn panel_fields_follow_the_selection_and_the_document() {
    let _turn = ONE_EDITOR_AT_A_TIME
        .lock()
        .unwrap_or_else(|p| p.into_inner());
    let mut harness = editor();
    let page = harness.state().command_sender();
    let slider = |harness: &Harness<'_, KnotworkApp>| {
        harness
            .get_by_role_and_label(egui::accesskit::Role::Slider, "w")
            .accesskit_node()
            .numeric_value()
            .expect("the weight slider's value")
    };

    // The rational sphere: point 1 has weight 1/√2, point 0 weight 1.
    const SPHERE: usize = 2;
    select_with_free_handle(&mut harness, SPHERE);
    let half = std::f64::consts::FRAC_1_SQRT_2;
    for (point, weight) in [(1, half), (0, 1.0), (1, half)] {
        page.send(AppCommand::SelectPoints(vec![point]));
        harness.run_steps(2);
        let shown = slider(&harness);
        assert!((shown - weight).abs() < 1e-4, "point {point}: {shown}");
    }

    // Transform: move by −6 in x, Apply; the fields are back to no change, and stay so for
    // another object.
    harness.get_by_label("Transform object").click_accesskit();
    harness.run_steps(2);
    let before = harness.state().document().scene.objects[SPHERE].clone();
    harness
        .get_all_by_label("move")
        .nth(1)
        .unwrap()
        .set_value_accesskit(-6.0);
    harness.run_steps(2);
    harness.get_by_label("Apply transform").click_accesskit();
    harness.run_steps(2);
    let moved = harness.state().document().scene.objects[SPHERE].control_points()[0];
    assert!(
        (moved.x - (before.control_points()[0].x - 6.0)).abs() < 1e-9,
        "{moved}"
    );
    let fields = |harness: &Harness<'_, KnotworkApp>| -> Vec<f64> {
        harness
            .get_all_by_label("move")
            .filter_map(|n| n.accesskit_node().numeric_value())
            .collect()
    };
    assert_eq!(fields(&harness), vec![0.0; 3], "after Apply");
    harness
        .get_all_by_label("move")
        .nth(2)
        .unwrap()
        .set_value_accesskit(4.0);
    harness.run_steps(2);
    page_select(&mut harness, SHEET);
    assert_eq!(fields(&harness), vec![0.0; 3], "for another object");

    // Point 60 of the sheet (the far end in u), then a knot inserted in u: the panel edits the same point, renumbered.
    let point = harness.get_by_label("Point");
    point.set_value_accesskit(60.0);
    harness.run_steps(2);
    let at = harness.state().document().scene.objects[SHEET].control_points()[60];
    harness.get_by_label("Insert knot").scroll_to_me();
    harness.run_steps(2);
    harness.get_by_label("Insert knot").click_accesskit();
    harness.run_steps(3);
    let s = status::current();
    assert_eq!(s.error, None);
    let shown = harness
        .get_by_label("Point")
        .accesskit_node()
        .numeric_value()
        .unwrap() as usize;
    let points = harness.state().document().scene.objects[SHEET].control_points();
    let nearest = (0..points.len())
        .min_by(|&a, &b| points[a].distance(at).total_cmp(&points[b].distance(at)))
        .unwrap();
    assert_eq!(shown, nearest, "{s:?}");
    assert_ne!(shown, 60, "the knot renumbered the point");
    assert!(
        s.notice
            .as_deref()
            .is_some_and(|n| n.starts_with(&format!("point 60 is now point {shown}"))),
        "{s:?}"
    );
}

/// A refused weight shows beside the weight slider and as a toast over the viewport, not only
/// at the panel's end; `?` opens the controls over the viewport, the toolbar switches shading.
#[test]
fn errors_show_where_the_eye_is_and_the_viewport_explains_itself() {
    let _turn = ONE_EDITOR_AT_A_TIME
        .lock()
        .unwrap_or_else(|p| p.into_inner());
    let mut harness = editor();
    page_select(&mut harness, SHEET);
    harness
        .get_by_role_and_label(egui::accesskit::Role::Slider, "w")
        .set_value_accesskit(0.0);
    harness.run_steps(2);
    let message = "a weight must be finite and > 0, got 0";
    assert_eq!(status::current().error.as_deref(), Some(message));
    let slider = harness
        .get_by_role_and_label(egui::accesskit::Role::Slider, "w")
        .rect();
    let shown: Vec<egui::Rect> = harness
        .get_all_by_label(message)
        .map(|n| n.rect())
        .collect();
    // Beside the slider: the next line of the panel.
    assert!(
        shown
            .iter()
            .any(|r| r.left() < 400.0 && (r.top() - slider.bottom()).abs() < 40.0),
        "beside the slider {slider:?}: {shown:?}"
    );
    // A toast over the viewport (right of the panel, near its top).
    assert!(
        shown.iter().any(|r| r.left() > 400.0 && r.top() < 200.0),
        "over the viewport: {shown:?}"
    );

    // `?` shows the controls over the viewport, a second `?` hides them.
    harness.key_press_modifiers(Modifiers::SHIFT, Key::Questionmark);
    harness.run_steps(2);
    for (input, action) in knotwork::app::CONTROLS {
        assert!(harness.query_by_label(input).is_some(), "{input}");
        assert!(harness.query_by_label(action).is_some(), "{action}");
    }
    harness.key_press_modifiers(Modifiers::SHIFT, Key::Questionmark);
    harness.run_steps(2);
    assert!(harness.query_by_label("show or hide this list").is_none());

    // The slider is back at the point's weight: a field shows the document's value.
    let weight = harness
        .get_by_role_and_label(egui::accesskit::Role::Slider, "w")
        .accesskit_node()
        .numeric_value();
    assert_eq!(weight, Some(1.0));

    // The toolbar over the canvas switches the shading.
    harness.get_by_label("Mean").click_accesskit();
    harness.run_steps(2);
    assert_eq!(status::current().shading, "mean");
}

/// Scrolls to the widget labelled `label` and clicks it.
pub(crate) fn click_label(harness: &mut Harness<'_, KnotworkApp>, label: &str) {
    harness.get_by_label(label).scroll_to_me();
    harness.run_steps(2);
    harness.get_by_label(label).click_accesskit();
    harness.run_steps(3);
}

#[test]
fn a_blend_from_the_surface_tools_is_adjusted_in_place_and_stays_one_undo_step() {
    let _turn = ONE_EDITOR_AT_A_TIME
        .lock()
        .unwrap_or_else(|p| p.into_inner());
    let mut harness = editor();
    let plates = r#"{"format": "knotwork", "version": 2, "objects": [
        {"type": "nurbs_surface", "name": "Left", "degree": [1, 1],
         "knots": [[0, 0, 1, 1], [0, 0, 1, 1]],
         "points": [[[-3, 0, 0], [-3, 2, 0]], [[-1, 0, 0], [-1, 2, 0]]]},
        {"type": "nurbs_surface", "name": "Right", "degree": [1, 1],
         "knots": [[0, 0, 1, 1], [0, 0, 1, 1]],
         "points": [[[1, 0, 0.5], [1, 2, 0.5]], [[3, 0, 0.5], [3, 2, 0.5]]]}]}"#;
    harness
        .state_mut()
        .open_file("plates.json", plates.as_bytes());
    harness.run_steps(3);
    page_select(&mut harness, 0);
    click_label(&mut harness, "Blend");
    let across = |harness: &Harness<'_, KnotworkApp>| {
        let doc = harness.state().document();
        let blend = doc.scene.objects.get(2).map(|o| {
            assert_eq!(o.name, "blend");
            o.geometry.nurbs_surface().map(|s| s.degree()[1])
        });
        (doc.scene.objects.len(), doc.history.undo_depth(), blend)
    };
    // Opening, then the blend: G2, a quintic across the gap.
    assert_eq!(
        across(&harness),
        (3, 2, Some(Some(5))),
        "{:?}",
        status::current()
    );
    // G1 applies it again in its place: a cubic across, still the same undo step.
    click_label(&mut harness, "G1");
    assert_eq!(
        across(&harness),
        (3, 2, Some(Some(3))),
        "{:?}",
        status::current()
    );
    assert!(
        status::current()
            .last_edit
            .is_some_and(|l| l.starts_with("G1 blend from Left u1 to Right u0")),
        "{:?}",
        status::current()
    );
    // One undo takes the blend away; after it nothing is adjusted any more.
    harness.state().command_sender().send(AppCommand::Undo);
    harness.run_steps(3);
    assert_eq!(across(&harness), (2, 1, None));
    page_select(&mut harness, 0);
    click_label(&mut harness, "G2");
    assert_eq!(across(&harness), (2, 1, None));
}

/// A STEP file opens a face at a time under a progress window: a command sent right after it
/// waits for it (an undo then takes the open back), Cancel leaves the document as it was, and
/// the opened parts are in millimetres with the file's colours.
#[test]
fn a_step_file_opens_over_frames_with_progress_and_cancel() {
    let _turn = ONE_EDITOR_AT_A_TIME
        .lock()
        .unwrap_or_else(|p| p.into_inner());
    let mut harness = editor();
    let page = harness.state().command_sender();
    let fixture = |name: &str| {
        std::fs::read(format!(
            "{}/tests/reference/occ/step/{name}",
            env!("CARGO_MANIFEST_DIR")
        ))
        .unwrap()
    };
    let before = harness.state().document().scene.clone();

    // Cancel: sent with the open, it stops it before any face is built.
    page.send(AppCommand::Open {
        name: "assembly.step".into(),
        bytes: fixture("assembly.step"),
    });
    page.send(AppCommand::CancelOpen);
    harness.run_steps(4);
    assert_eq!(harness.state().document().scene, before, "cancelled");
    assert_eq!(status::current().open_progress, None);

    // The plate of 20 × 20 filleted holes (806 faces: far more than two frames' 30 ms of
    // work), then Undo at once: the undo waits for the open, so it takes the open back.
    page.send(AppCommand::Open {
        name: "plate-20.step".into(),
        bytes: fixture("plate-20.step"),
    });
    // Two frames: a window's first frame only sizes it.
    harness.run_steps(2);
    let progress = status::current().open_progress;
    assert!(
        progress.is_some_and(|p| (0.0..1.0).contains(&p)),
        "progress while opening: {progress:?}"
    );
    assert!(
        harness.get_all_by_label("Cancel").next().is_some(),
        "the progress window offers Cancel"
    );
    page.send(AppCommand::Undo);
    let mut frames = 2;
    while status::current().open_progress.is_some() && frames < 20_000 {
        harness.run_steps(1);
        frames += 1;
    }
    harness.run_steps(2);
    assert_eq!(
        harness.state().document().scene,
        before,
        "the undo came after the open"
    );
    page.send(AppCommand::Redo);
    harness.run_steps(2);
    let scene = &harness.state().document().scene;
    assert_eq!(scene.objects.len(), 1, "the plate");
    assert_eq!(scene.unit, Some(knotwork::scene::LengthUnit::Millimetre));
    eprintln!("the plate opened over {frames} frames");

    // The assembly's two parts keep their colours.
    page.send(AppCommand::Open {
        name: "assembly.step".into(),
        bytes: fixture("assembly.step"),
    });
    for _ in 0..200 {
        harness.run_steps(1);
        if status::current().open_progress.is_none()
            && harness.state().document().scene.objects.len() == 2
        {
            break;
        }
    }
    let scene = &harness.state().document().scene;
    assert_eq!(scene.objects.len(), 2, "both parts");
    assert!(
        scene.objects.iter().all(|o| o.color.is_some()),
        "their colours"
    );
}

/// A STEP file with a face on a surface knotwork does not read opens with the rest of its
/// faces, and says what it left out: a dialog (not the refusal's "unchanged"), the status's
/// warnings with the per-entity summary first, and the notice.
#[test]
fn a_step_file_with_an_unread_surface_opens_the_rest_and_says_what_was_skipped() {
    let _turn = ONE_EDITOR_AT_A_TIME
        .lock()
        .unwrap_or_else(|p| p.into_inner());
    let mut harness = editor();
    let page = harness.state().command_sender();
    let text = std::fs::read_to_string(format!(
        "{}/tests/reference/occ/step/box-hole-fillets.step",
        env!("CARGO_MANIFEST_DIR")
    ))
    .unwrap();
    let cylinder = "#72 = CYLINDRICAL_SURFACE('',#73,3.);";
    assert!(text.contains(cylinder));
    // A well-formed surface of a kind knotwork does not read.
    let text = text.replace(cylinder, "#72 = CURVE_BOUNDED_SURFACE('',#73,(),.F.);");
    page.send(AppCommand::Open {
        name: "holes.step".into(),
        bytes: text.into_bytes(),
    });
    for _ in 0..200 {
        harness.run_steps(1);
        if status::current().open_progress.is_none()
            && !harness.state().document().scene.objects.is_empty()
        {
            break;
        }
    }
    harness.run_steps(2);
    let state = status::current();
    assert_eq!(
        state.warnings.first().map(String::as_str),
        Some("1 face skipped on CURVE_BOUNDED_SURFACE: this kind of surface is not read"),
        "{:?}",
        state.warnings
    );
    assert!(
        state
            .notice
            .as_deref()
            .is_some_and(|n| n.starts_with("opened holes.step: 1 face")),
        "{:?}",
        state.notice
    );
    assert!(
        harness
            .get_all_by_label("Opened holes.step with warnings")
            .next()
            .is_some(),
        "the dialog"
    );
    assert!(
        harness
            .query_by_label("The open document is unchanged.")
            .is_none(),
        "a warning is not a refusal"
    );
    let scene = &harness.state().document().scene;
    assert_eq!(scene.objects.len(), 1);
    assert_eq!(scene.objects[0].faces().len(), 10, "every other face");
}

/// *Measure* in the editor: the sample torus (R = 2, r = 0.8) shows its exact area 4π²Rr and
/// volume 2π²Rr², and that it does not cross itself; the measure goes when the document
/// changes.
#[test]
fn measure_shows_the_selected_bodys_exact_area_and_volume() {
    let _turn = ONE_EDITOR_AT_A_TIME
        .lock()
        .unwrap_or_else(|p| p.into_inner());
    let mut harness = editor();
    page_select(&mut harness, 1);
    harness.get_by_label("Measure").scroll_to_me();
    harness.run_steps(1);
    harness.get_by_label("Measure").click_accesskit();
    harness.run_steps(3);
    let pi2 = std::f64::consts::PI * std::f64::consts::PI;
    let area = format!("area {:.6}", 4.0 * pi2 * 2.0 * 0.8);
    let volume = format!("volume {:.6}", 2.0 * pi2 * 2.0 * 0.64);
    assert!(harness.query_by_label(&area).is_some(), "{area}");
    assert!(harness.query_by_label(&volume).is_some(), "{volume}");
    assert!(harness.query_by_label("no self-intersection").is_some());
    // An edit of the document takes the figures away until Measure is pressed again.
    let page = harness.state().command_sender();
    page.send(AppCommand::Edit(Command::SetVisible {
        object: 0,
        visible: false,
    }));
    harness.run_steps(3);
    assert!(harness.query_by_label(&volume).is_none());
    assert!(harness.query_by_label("Measure").is_some());
}

/// A long boolean in the editor: a block 8 × 6 × 1 minus 30 pins of radius 0.25 through it
/// (a few hundred milliseconds of work, far more than the first turn's 50 ms) shows its
/// progress with Cancel, and Cancel leaves the document as it was; run again, it is applied
/// as one undo step with the block less the pins' volume (48 − 30 · π r² · 1), the inputs
/// hidden. Commands sent while it runs wait for it.
#[test]
fn a_long_boolean_runs_over_frames_with_progress_and_cancel() {
    use glam::{DAffine3, DVec3};
    use knotwork::ops::boolean::{Boolean, Kind};
    use knotwork::scene::polysurface::Polysurface;
    use knotwork::scene::{ObjectGeometry, Scene, SceneObject};
    let _turn = ONE_EDITOR_AT_A_TIME
        .lock()
        .unwrap_or_else(|p| p.into_inner());
    let mut harness = editor();
    let page = harness.state().command_sender();
    let mut scene = Scene::default();
    scene.objects.clear();
    // The box of planes is [0, 2] × [0, 1] × [0, 1.5].
    let block =
        crate::common::box_of_planes(&DAffine3::from_scale(DVec3::new(4.0, 6.0, 1.0 / 1.5)));
    // 80 pins: long enough that two frames do not finish it on a quiet machine.
    let (r, rows, columns) = (0.2, 8, 10);
    let mut pins = Vec::new();
    for i in 0..columns {
        for j in 0..rows {
            let centre = DVec3::new(0.6 + 0.75 * i as f64, 0.55 + 0.7 * j as f64, -0.5);
            pins.extend(
                knotwork::kernel::solids::capped_cylinder(centre, DVec3::Z * 2.0, r).unwrap(),
            );
        }
    }
    scene
        .objects
        .push(SceneObject::new("plate", ObjectGeometry::new(block)));
    scene.objects.push(SceneObject::new(
        "pins",
        ObjectGeometry::new(Polysurface::new(pins, 1e-6).unwrap()),
    ));
    page.send(AppCommand::Open {
        name: "plate.knotwork".into(),
        bytes: knotwork::io::project::write_scene(&scene, None).into_bytes(),
    });
    harness.run_steps(2);
    let opened = harness.state().document().scene.clone();
    assert_eq!(opened.objects.len(), 2, "{:?}", status::current().error);
    let depth = harness.state().document().history.undo_depth();
    let difference = || AppCommand::Boolean {
        params: Boolean {
            operation: Kind::Difference,
            a: vec![0.into()],
            b: vec![1.into()],
            tolerance: 1e-6,
        },
        keep_history: false,
    };

    // Started, it shows its progress and Cancel; a command sent meanwhile waits; Cancel
    // (sent after it) is carried out at once and leaves the document as it was.
    page.send(difference());
    harness.run_steps(2);
    let progress = status::current().boolean_progress;
    assert!(
        progress.is_some_and(|p| (0.0..1.0).contains(&p)),
        "progress while running: {progress:?}"
    );
    assert!(
        harness.get_all_by_label("Cancel").next().is_some(),
        "the progress window offers Cancel"
    );
    page.send(AppCommand::Edit(Command::SetVisible {
        object: 1,
        visible: false,
    }));
    page.send(AppCommand::CancelBoolean);
    harness.run_steps(2);
    assert_eq!(status::current().boolean_progress, None);
    let scene = &harness.state().document().scene;
    assert_eq!(scene.objects.len(), 2, "cancelled: nothing added");
    assert!(
        !scene.objects[1].visible,
        "the waiting command ran after the cancel"
    );
    page.send(AppCommand::Undo);
    harness.run_steps(2);
    assert_eq!(harness.state().document().scene, opened);

    // Run to its end: one undo step, the inputs hidden, the closed-form volume.
    page.send(difference());
    let mut frames = 0;
    harness.run_steps(2);
    while status::current().boolean_progress.is_some() && frames < 20_000 {
        harness.run_steps(1);
        frames += 1;
    }
    harness.run_steps(1);
    eprintln!("the difference ran over {frames} frames");
    let doc = harness.state().document();
    assert_eq!(status::current().error, None);
    assert_eq!(doc.scene.objects.len(), 3);
    assert_eq!(doc.history.undo_depth(), depth + 1);
    assert!(!doc.scene.objects[0].visible && !doc.scene.objects[1].visible);
    let body = doc.scene.objects[2].body().expect("a body");
    assert!(body.closed());
    let volume = knotwork::kernel::mass::signed_volume(&body.faces).unwrap();
    let expected = 48.0 - (rows * columns) as f64 * std::f64::consts::PI * r * r;
    assert!(
        (volume - expected).abs() < 1e-6 * expected,
        "volume {volume}, expected {expected}"
    );
    page.send(AppCommand::Undo);
    harness.run_steps(2);
    assert_eq!(harness.state().document().scene, opened);
}

/// Adds the 2 × 1 × 1.5 block of planes through the page and returns its index.
fn add_block(harness: &mut Harness<'_, KnotworkApp>) -> usize {
    let page = harness.state().command_sender();
    let body = crate::common::box_of_planes(&glam::DAffine3::IDENTITY);
    page.send(AppCommand::Edit(Command::Add {
        object: knotwork::scene::SceneObject::new(
            "Block",
            knotwork::scene::ObjectGeometry::new(body),
        ),
    }));
    harness.run_steps(3);
    harness.state().document().scene.objects.len() - 1
}

#[test]
fn an_edge_picked_in_the_viewport_is_filleted() {
    let _turn = ONE_EDITOR_AT_A_TIME
        .lock()
        .unwrap_or_else(|p| p.into_inner());
    let mut harness = editor();
    let k = add_block(&mut harness);
    page_select(&mut harness, k);
    harness.run_steps(2);
    // The edge from (0, 0, 0) to (2, 0, 0): the screen middle of its corners' handles lies on
    // it.
    let points = harness.state().document().scene.objects[k].control_points();
    let handles = status::handles();
    let screen = |p: glam::DVec3| {
        let i = points
            .iter()
            .position(|q| q.distance(p) < 1e-12)
            .expect("a corner");
        let h = handles[i].expect("the corner on screen");
        Pos2::new(h[0], h[1])
    };
    let (a, b) = (
        screen(glam::DVec3::ZERO),
        screen(glam::DVec3::new(2.0, 0.0, 0.0)),
    );
    let middle = a + (b - a) * 0.5;
    harness.get_by_label("Operations").scroll_to_me();
    harness.run_steps(1);
    harness.get_by_label("Operations").click_accesskit();
    harness.run_steps(2);
    harness.get_by_label("Pick").scroll_to_me();
    harness.run_steps(2);
    harness.get_by_label("Pick").click_accesskit();
    harness.run_steps(2);
    click_at(&mut harness, middle);
    harness.get_by_label("1 picked").scroll_to_me();
    harness.get_by_label("Fillet edges").click_accesskit();
    harness.run_steps(3);
    let s = status::current();
    assert_eq!(s.error, None, "{s:?}");
    assert!(
        s.last_edit
            .as_deref()
            .is_some_and(|e| e.contains("fillet of 1 edge")),
        "{s:?}"
    );
    let scene = &harness.state().document().scene;
    let made = scene.objects.last().expect("the fillet");
    let volume = |o: &knotwork::scene::SceneObject| {
        knotwork::kernel::mass::signed_volume(&o.body().expect("a body").faces).expect("a volume")
    };
    // The box's 3 less the corner prism of the edge along x: (1 − π/4) r² × 2.
    let r = 0.02 * knotwork::doc::surface_ops::scene_size(scene);
    let want = 3.0 - (1.0 - std::f64::consts::PI / 4.0) * r * r * 2.0;
    assert!(
        (volume(made) - want).abs() < 1e-9,
        "{} against {want}",
        volume(made)
    );
}

/// The block's edge nearest `near` filleted at 0.1 with history, the fillet selected: its
/// index.
fn fillet_with_history(harness: &mut Harness<'_, KnotworkApp>, near: [f64; 3]) -> usize {
    let page = harness.state().command_sender();
    let k = add_block(harness);
    let fillet = knotwork::ops::features::FilletEdges {
        object: k.into(),
        radius: 0.1,
        near: vec![near],
        radius_at: Vec::new(),
        tolerance: knotwork::ops::features::FEATURE_TOLERANCE,
    };
    page.send(AppCommand::Edit(Command::Apply {
        operation: knotwork::scene::operation::Operation::new(fillet),
        keep_history: true,
    }));
    harness.run_steps(3);
    let made = harness.state().document().scene.objects.len() - 1;
    page_select(harness, made);
    harness.run_steps(3);
    made
}

#[test]
fn a_fillets_handle_dragged_in_the_viewport_edits_its_radius_in_one_step() {
    // A block's edge filleted with history, then its radius dragged by the handle beside the
    // picked edge: letting go makes the fillet again at the larger radius (the corner prism's
    // volume, (1 − π/4) r² × 2, grows), as one undo step that undo takes back.
    let _turn = ONE_EDITOR_AT_A_TIME
        .lock()
        .unwrap_or_else(|p| p.into_inner());
    let mut harness = editor();
    let made = fillet_with_history(&mut harness, [1.0, 0.0, 0.0]);
    let radius = |harness: &Harness<'_, KnotworkApp>| {
        let object = &harness.state().document().scene.objects[made];
        object
            .recipe
            .as_ref()
            .and_then(|r| {
                r.operation
                    .params::<knotwork::ops::features::FilletEdges>()
                    .map(|p| p.radius)
            })
            .expect("the fillet's recipe")
    };
    let volume = |harness: &Harness<'_, KnotworkApp>| {
        let object = &harness.state().document().scene.objects[made];
        knotwork::kernel::mass::signed_volume(&object.body().expect("a body").faces)
            .expect("a volume")
    };
    let steps = status::current().undo_steps;
    let handle = harness
        .get_by_role_and_label(egui::accesskit::Role::Slider, "Feature handle")
        .rect()
        .center();
    let end = drag_from(&mut harness, handle, egui::vec2(1.0, 0.0), 3);
    press(&harness, end, false);
    harness.run_steps(3);
    let s = status::current();
    assert_eq!(s.error, None, "{s:?}");
    let r = radius(&harness);
    assert!(r > 0.1, "the radius grew: {r}");
    let want = 3.0 - (1.0 - std::f64::consts::PI / 4.0) * r * r * 2.0;
    assert!(
        (volume(&harness) - want).abs() < 1e-9,
        "{} against {want}",
        volume(&harness)
    );
    assert_eq!(s.undo_steps, steps + 1, "one undo step");
    harness.key_press_modifiers(Modifiers::COMMAND, egui::Key::Z);
    harness.run_steps(3);
    assert_eq!(radius(&harness), 0.1);
}

#[test]
fn a_fillets_vary_radius_button_sets_the_picked_ends_radius_in_one_step() {
    // A block's edge along x filleted with history at 0.1, picked near its end at x = 2:
    // *Vary radius* sets the radius there to twice the fillet's, one undo step, and the
    // fillet runs from 0.1 at x = 0 to 0.2 at x = 2, taking (1 − π/4) ∫ r² dx.
    let _turn = ONE_EDITOR_AT_A_TIME
        .lock()
        .unwrap_or_else(|p| p.into_inner());
    let mut harness = editor();
    let made = fillet_with_history(&mut harness, [1.5, 0.0, 0.0]);
    let steps = status::current().undo_steps;
    harness.get_by_label("Operations").scroll_to_me();
    harness.run_steps(1);
    harness.get_by_label("Operations").click_accesskit();
    harness.run_steps(2);
    harness.get_by_label("Vary radius").scroll_to_me();
    harness.run_steps(2);
    harness.get_by_label("Vary radius").click_accesskit();
    harness.run_steps(3);
    let s = status::current();
    assert_eq!(s.error, None, "{s:?}");
    assert_eq!(s.undo_steps, steps + 1, "one undo step");
    let object = &harness.state().document().scene.objects[made];
    let radii = object
        .recipe
        .as_ref()
        .and_then(|r| {
            r.operation
                .params::<knotwork::ops::features::FilletEdges>()
                .map(|p| p.radius_at.clone())
        })
        .expect("the fillet's recipe");
    assert_eq!(radii, vec![[1.5, 0.0, 0.0, 0.2]]);
    let volume = knotwork::kernel::mass::signed_volume(&object.body().expect("a body").faces)
        .expect("a volume");
    let want = 3.0 - (1.0 - std::f64::consts::PI / 4.0) * 2.0 * (0.01 + 0.02 + 0.04) / 3.0;
    assert!((volume - want).abs() < 1e-9, "{volume} against {want}");
}
