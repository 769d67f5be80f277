//! The editor's UI driven headlessly with egui_kittest on wgpu (lavapipe in CI): select an
//! object in the outliner, pick a control point by clicking its projected position, drag it with
//! the X constraint, check that only x changed and only the point's local support was
//! re-evaluated, then undo with Ctrl+Z and find the document as it was.

use eframe::egui::{self, Event, Key, Modifiers, PointerButton, Pos2};
use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use knotwork::app::{KnotworkApp, wgpu_configuration};
use knotwork::scene::ObjectGeometry;
use knotwork::status;

fn press(harness: &Harness<'_, KnotworkApp>, pos: Pos2, pressed: bool) {
    harness.event(Event::PointerButton {
        pos,
        button: PointerButton::Primary,
        pressed,
        modifiers: Modifiers::NONE,
    });
}

#[test]
fn click_drag_with_axis_constraint_and_undo() {
    let setup = wgpu_configuration(false).wgpu_setup;
    let mut harness = Harness::builder()
        .with_size(egui::vec2(1280.0, 800.0))
        .wgpu_setup(setup)
        .build_eframe(|cc| KnotworkApp::new(cc, None, false));
    harness.run_steps(3);
    assert_eq!(status::current().error, None, "{:?}", status::current());

    // The non-uniform B-spline (polynomial: coordinates are stored exactly).
    const OBJECT: usize = 3;
    let label = harness.state().document().scene.objects[OBJECT]
        .name
        .clone();
    harness.get_by_label(&label).click();
    harness.run_steps(3);
    assert_eq!(status::current().selected, Some(OBJECT as u32));
    let before = harness.state().document().scene.objects[OBJECT].clone();

    // A handle well inside the viewport (right of the panel), not hidden behind another.
    let handles = status::handles();
    let (index, at) = handles
        .iter()
        .enumerate()
        .filter_map(|(k, h)| h.map(|p| (k, Pos2::new(p[0], p[1]))))
        .filter(|(_, p)| p.x > 450.0 && p.x < 1200.0 && p.y > 100.0 && p.y < 700.0)
        .find(|(k, p)| {
            handles.iter().enumerate().all(|(j, h)| {
                j == *k || h.is_none_or(|q| Pos2::new(q[0], q[1]).distance(*p) > 20.0)
            })
        })
        .expect("a free handle on screen");

    // Click it: it becomes the selection.
    harness.hover_at(at);
    harness.run_steps(1);
    press(&harness, at, true);
    harness.run_steps(1);
    press(&harness, at, false);
    harness.run_steps(2);
    assert_eq!(status::current().selected_points, vec![index as u32]);

    // Drag it: start freely, press X, keep moving, release.
    press(&harness, at, true);
    harness.run_steps(1);
    for step in 1..=4 {
        harness.hover_at(at + egui::vec2(10.0 * step as f32, -6.0 * step as f32));
        harness.run_steps(1);
    }
    assert!(status::current().dragging);
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
    assert!(matches!(after.geometry, ObjectGeometry::Nurbs(_)));

    // Ctrl+Z restores the document exactly; Ctrl+Shift+Z redoes.
    harness.key_press_modifiers(Modifiers::COMMAND, Key::Z);
    harness.run_steps(2);
    assert_eq!(harness.state().document().scene.objects[OBJECT], before);
    assert_eq!(status::current().redo_steps, 1);
    harness.key_press_modifiers(Modifiers::COMMAND | Modifiers::SHIFT, Key::Z);
    harness.run_steps(2);
    assert_eq!(harness.state().document().scene.objects[OBJECT], after);
}
