//! Operations as modules: [`MovedCopy`] below is an operation defined in this test module alone
//! ("a copy of an object with every control point moved by a vector"), registered at run time,
//! and run with no other edit through every road an operation has:
//!
//! 1. the page's road: its JSON value read by the registry ([`knotwork::ops::parse`], what the
//!    page's `apply` call does) and sent to the editor as one command;
//! 2. the panel road: the editor's Operations panel offers it for the selection, and a click
//!    runs it;
//! 3. the command line's road: `knotwork apply OP.json PROJECT -o OUT.json`'s body
//!    ([`knotwork::app::apply_to_file`]) on a project file, whose history survives the file;
//! 4. construction history: with history kept, dragging an input's control point, moving it by a
//!    command, renaming it and giving another object its name all leave the result following
//!    the input it was made from (inputs are kept by id, not by name); undo restores each; a
//!    removed input ends the history and says so.
//!
//! Every check compares the result with the input moved by the vector (an invariant of the
//! operation), on random rational surfaces.

use std::sync::Once;

use glam::DVec3;
use knotwork::doc::{Command, Document, EditError};
use knotwork::ops;
use knotwork::scene::operation::{
    ObjectRef, Operation, OperationEntry, OperationParams, Planned, entry,
};
use knotwork::scene::{ObjectGeometry, Scene, SceneObject};
use serde::{Deserialize, Serialize};

use crate::common;

/// `{"op": "moved_copy", "object": k, "by": [x, y, z]}`: a copy of object k named "NAME moved"
/// with every control point moved by `by`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct MovedCopy {
    object: ObjectRef,
    by: [f64; 3],
}

impl OperationParams for MovedCopy {
    const NAME: &'static str = "moved_copy";

    fn objects_mut(&mut self) -> Vec<&mut ObjectRef> {
        vec![&mut self.object]
    }

    fn plan(&self, scene: &Scene) -> Result<Planned, EditError> {
        let by = DVec3::from_array(self.by);
        if !by.is_finite() {
            return Err(EditError::BadParameter {
                operation: Self::NAME,
                field: "by",
                message: format!("must be three finite numbers (got {by})"),
            });
        }
        let k = scene.resolve(self.object)?;
        let input = &scene.objects[k];
        let geometry = input
            .kind()
            .transformed(&glam::DAffine3::from_translation(by))
            .map_err(|source| EditError::Geometry {
                name: input.name.clone(),
                source,
            })?;
        let object = SceneObject::new(
            scene.unique_name(&format!("{} moved", input.name)),
            geometry,
        );
        let label = format!("move a copy of {} by {by}", input.name);
        Ok((
            vec![knotwork::doc::Change::Insert {
                index: scene.objects.len(),
                object,
            }],
            label,
        ))
    }
}

const MOVED_COPY: OperationEntry = entry::<MovedCopy>(
    "a copy of the object with every control point moved up by 1",
    |scene, selection| match selection {
        [k] if *k < scene.objects.len() => Some(Operation::new(MovedCopy {
            object: (*k).into(),
            by: [0.0, 0.0, 1.0],
        })),
        _ => None,
    },
);

fn register() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| ops::register(MOVED_COPY).unwrap());
}

/// Whether `result`'s control points are `input`'s moved by `by` (to 1e-12 of their size).
fn moved_by(input: &SceneObject, result: &SceneObject, by: DVec3) -> bool {
    let (a, b) = (input.control_points(), result.control_points());
    let size = a.iter().fold(1.0f64, |m, p| m.max(p.abs().max_element()));
    a.len() == b.len()
        && a.iter()
            .zip(&b)
            .all(|(p, q)| (*p + by - *q).abs().max_element() <= 1e-12 * size)
        && input.kind().weights() == result.kind().weights()
}

/// A scene of two random rational surfaces in general position, "Wing" and "Tail".
fn two_surfaces(seed: u64) -> Scene {
    let object = |name: &str, seed| {
        SceneObject::new(
            name,
            ObjectGeometry::new(common::random_surface(3, 2, seed)),
        )
    };
    Scene {
        objects: vec![object("Wing", seed), object("Tail", seed + 1)],
        unit: None,
    }
}

fn moved_copy(object: usize, by: [f64; 3], keep_history: bool) -> Command {
    Command::Apply {
        operation: Operation::new(MovedCopy {
            object: object.into(),
            by,
        }),
        keep_history,
    }
}

#[test]
fn the_registry_reads_operations_and_names_what_is_wrong() {
    register();
    let op = ops::parse(r#"{"op": "moved_copy", "object": 1, "by": [0, 2, 0]}"#).unwrap();
    assert_eq!(
        op.params::<MovedCopy>(),
        Some(&MovedCopy {
            object: ObjectRef::Index(1),
            by: [0.0, 2.0, 0.0]
        })
    );
    // Its JSON value reads back as the same operation.
    assert_eq!(ops::parse(&op.to_json().to_string()).unwrap(), op);
    let refusal = |text: &str| ops::parse(text).unwrap_err().to_string();
    let e = refusal(r#"{"op": "moved_copy", "object": 1, "by": "up"}"#);
    assert!(e.contains("by"), "{e}");
    let e = refusal(r#"{"op": "moved_copy", "object": 1, "by": [0, 0, 1], "speed": 2}"#);
    assert!(e.contains("speed"), "{e}");
    let e = refusal(r#"{"op": "twist", "object": 1}"#);
    assert!(
        e.contains("twist") && e.contains("moved_copy") && e.contains("offset"),
        "{e}"
    );
    let e = refusal(r#"{"object": 1}"#);
    assert!(e.contains("op"), "{e}");
    let e = refusal(r#"{"op": "offset", "object": 0, "distance": "far"}"#);
    assert!(e.contains("distance"), "{e}");
    // A transform's value gives back the affine map bit for bit, through JSON too.
    let t = glam::DAffine3::from_scale_rotation_translation(
        DVec3::new(0.7, 1.3, 2.1),
        glam::DQuat::from_euler(glam::EulerRot::XYZ, 0.3, -1.1, 2.9),
        DVec3::new(-4.5, 0.25, 1e-3),
    );
    let transform = knotwork::ops::transform::Transform::new(3, &t);
    assert_eq!(transform.affine(), t);
    let read = ops::parse(&Operation::new(transform.clone()).to_json().to_string()).unwrap();
    assert_eq!(read.params(), Some(&transform));
    // A second operation of the same name is refused.
    assert!(ops::register(MOVED_COPY).is_err());
    // A refused plan names the field and changes nothing.
    let mut doc = Document::new(two_surfaces(3));
    let before = doc.scene.clone();
    let e = doc
        .execute(&moved_copy(0, [f64::NAN, 0.0, 0.0], false))
        .unwrap_err()
        .to_string();
    assert!(e.contains("by"), "{e}");
    let e = doc
        .execute(&Command::operation(knotwork::ops::offset::Offset {
            object: 0.into(),
            distance: f64::INFINITY,
            tolerance: 1e-4,
        }))
        .unwrap_err()
        .to_string();
    assert!(e.contains("distance"), "{e}");
    let e = doc
        .execute(&moved_copy(7, [0.0; 3], false))
        .unwrap_err()
        .to_string();
    assert!(e.contains("no object 7"), "{e}");
    assert_eq!(doc.scene, before);
}

#[test]
fn history_follows_its_input_by_id_through_drags_commands_renames_and_files() {
    register();
    let by = DVec3::new(0.3, -1.25, 2.5);
    let mut doc = Document::new(two_surfaces(11));
    doc.execute(&moved_copy(0, by.to_array(), true)).unwrap();
    assert_eq!(doc.scene.objects.len(), 3);
    assert_eq!(doc.scene.objects[2].name, "Wing moved");
    assert!(moved_by(&doc.scene.objects[0], &doc.scene.objects[2], by));
    let ids: Vec<_> = doc.scene.objects.iter().map(|o| o.id).collect();
    assert!(ids[0] != ids[1] && ids[1] != ids[2] && ids[0] != ids[2]);

    // A drag of the input: every step makes the result again.
    let start = doc.scene.clone();
    doc.begin_drag(0, &[5]).unwrap();
    assert_eq!(doc.drag().unwrap().dependents(), vec![2]);
    for step in 1..=3 {
        let moved = doc
            .drag_by(DVec3::new(0.1, 0.2, -0.3) * step as f64)
            .unwrap();
        assert_eq!(moved.rebuilt, vec![2]);
        assert!(moved_by(&doc.scene.objects[0], &doc.scene.objects[2], by));
    }
    let edit = doc.commit_drag().unwrap().clone();
    assert_eq!(edit.changes.len(), 2, "{}", edit.label);
    assert!(doc.scene.objects[2].recipe.is_some());
    doc.undo().unwrap();
    assert_eq!(doc.scene, start);
    doc.redo().unwrap();
    assert!(moved_by(&doc.scene.objects[0], &doc.scene.objects[2], by));

    // A command that moves the input's points, in the same undo step.
    let p = doc.scene.objects[0].control_points()[2];
    doc.execute(&Command::MovePoints {
        object: 0,
        moves: vec![(2, p + DVec3::new(-0.5, 0.0, 0.7))],
    })
    .unwrap();
    assert!(moved_by(&doc.scene.objects[0], &doc.scene.objects[2], by));

    // Names are labels: renaming the input, and giving the other surface its old name, leave
    // the result following the object it was made from.
    doc.execute(&Command::Rename {
        object: 0,
        name: "Flap".into(),
    })
    .unwrap();
    doc.execute(&Command::Rename {
        object: 1,
        name: "Wing".into(),
    })
    .unwrap();
    doc.execute(&Command::operation(
        knotwork::ops::transform::Transform::new(0, &glam::DAffine3::from_rotation_z(0.4)),
    ))
    .unwrap();
    assert!(moved_by(&doc.scene.objects[0], &doc.scene.objects[2], by));
    let tail = doc.scene.objects[1].clone();
    doc.execute(&Command::operation(
        knotwork::ops::transform::Transform::new(1, &glam::DAffine3::from_translation(DVec3::X)),
    ))
    .unwrap();
    assert!(moved_by(&doc.scene.objects[0], &doc.scene.objects[2], by));
    assert_ne!(doc.scene.objects[1], tail);

    // The history survives a project file (inputs by position there) and still follows.
    let text = knotwork::io::project::write_scene(&doc.scene, None);
    let mut reopened = Document::new(knotwork::io::project::read(&text).unwrap().scene);
    for (a, b) in reopened.scene.objects.iter().zip(&doc.scene.objects) {
        assert_eq!((&a.name, &a.geometry), (&b.name, &b.geometry));
    }
    // Its inputs are the reopened objects (ids are the program's, positions the file's).
    let recipe = reopened.scene.objects[2].recipe.as_ref().unwrap();
    assert!(recipe.operation.reads(reopened.scene.objects[0].id));
    let p = reopened.scene.objects[0].control_points()[7];
    reopened
        .execute(&Command::MovePoints {
            object: 0,
            moves: vec![(7, p + DVec3::Z)],
        })
        .unwrap();
    assert!(moved_by(
        &reopened.scene.objects[0],
        &reopened.scene.objects[2],
        by
    ));

    // A direct edit of the result ends its history, and the label says so.
    let q = doc.scene.objects[2].control_points()[0];
    let edit = doc
        .execute(&Command::MovePoints {
            object: 2,
            moves: vec![(0, q + DVec3::X)],
        })
        .unwrap()
        .clone();
    assert!(edit.label.contains("history ends"), "{}", edit.label);
    assert!(doc.scene.objects[2].recipe.is_none());
    doc.undo().unwrap();
    assert!(doc.scene.objects[2].recipe.is_some());

    // Removing the input ends the history, says why, and undo brings both back.
    let before = doc.scene.clone();
    let edit = doc.execute(&Command::Delete { object: 0 }).unwrap().clone();
    assert!(edit.label.contains("history ends"), "{}", edit.label);
    assert!(doc.scene.objects[1].recipe.is_none());
    doc.undo().unwrap();
    assert_eq!(doc.scene, before);

    // A copy of the result is a plain object with its own id.
    doc.execute(&Command::Duplicate { object: 2 }).unwrap();
    let copy = &doc.scene.objects[3];
    assert!(copy.recipe.is_none());
    assert!(doc.scene.objects.iter().take(3).all(|o| o.id != copy.id));
}

#[test]
fn knotwork_apply_runs_a_registered_operation_on_a_project_file() {
    register();
    let dir = common::artifact_path("operations-apply");
    std::fs::create_dir_all(&dir).unwrap();
    let (project, output) = (dir.join("in.json"), dir.join("out.json"));
    let scene = two_surfaces(29);
    std::fs::write(&project, knotwork::io::project::write_scene(&scene, None)).unwrap();
    let report = knotwork::app::apply_to_file(
        r#"{"op": "moved_copy", "object": 1, "by": [1.5, 0, -2]}"#,
        &project,
        &output,
        true,
    )
    .unwrap();
    assert_eq!(report["added"], serde_json::json!(["Tail moved"]));
    let written = knotwork::io::project::read(&std::fs::read_to_string(&output).unwrap()).unwrap();
    let objects = &written.scene.objects;
    assert_eq!(objects.len(), 3);
    let by = DVec3::new(1.5, 0.0, -2.0);
    assert!(moved_by(&objects[1], &objects[2], by));
    // The history came through the file: it reads object 1 of the reopened scene.
    let recipe = objects[2].recipe.as_ref().unwrap();
    assert!(recipe.operation.reads(objects[1].id));
    // A refusal writes nothing and says why.
    std::fs::remove_file(&output).unwrap();
    let e = knotwork::app::apply_to_file(
        r#"{"op": "moved_copy", "object": 5, "by": [0, 0, 1]}"#,
        &project,
        &output,
        false,
    )
    .unwrap_err();
    assert!(e.contains("no object 5"), "{e}");
    assert!(!output.exists());
}

#[test]
fn the_page_and_the_panel_run_a_registered_operation_in_the_editor() {
    use egui_kittest::kittest::Queryable;
    use knotwork::app::AppCommand;
    register();
    let _turn = crate::editor_ui::ONE_EDITOR_AT_A_TIME
        .lock()
        .unwrap_or_else(|e| e.into_inner());
    let mut harness = crate::editor_ui::editor();
    let page = harness.state().command_sender();
    let count = harness.state().document().scene.objects.len();
    // The page's road: the JSON value, read by the registry, as one command.
    let operation = ops::parse(r#"{"op": "moved_copy", "object": 0, "by": [0, 0, 1]}"#).unwrap();
    page.send(AppCommand::Edit(Command::Apply {
        operation,
        keep_history: true,
    }));
    harness.run_steps(3);
    let scene = harness.state().document().scene.clone();
    assert_eq!(scene.objects.len(), count + 1);
    assert!(moved_by(&scene.objects[0], &scene.objects[count], DVec3::Z));
    assert!(scene.objects[count].recipe.is_some());
    // The panel's road: select object 1, open Operations, click the operation's button.
    page.send(AppCommand::Select(Some(1)));
    harness.run_steps(2);
    crate::editor_ui::click_label(&mut harness, "Operations");
    crate::editor_ui::click_label(&mut harness, "moved_copy");
    let scene = harness.state().document().scene.clone();
    assert_eq!(
        scene.objects.len(),
        count + 2,
        "{:?}",
        knotwork::status::current()
    );
    assert!(moved_by(
        &scene.objects[1],
        &scene.objects[count + 1],
        DVec3::Z
    ));
    // Undo takes back the panel's step alone.
    page.send(AppCommand::Undo);
    harness.run_steps(2);
    assert_eq!(harness.state().document().scene.objects.len(), count + 1);
    let _ = harness.get_by_label("Keep history");
}

/// The signed distance of `p` from the plane through `origin` with unit normal `normal`.
fn height(p: DVec3, origin: DVec3, normal: DVec3) -> f64 {
    (p - origin).dot(normal)
}

#[test]
fn built_in_operations_kept_with_history_follow_their_inputs_exactly() {
    use knotwork::kernel::NurbsSurface;
    use knotwork::ops::contour::Contour;
    use knotwork::ops::offset::Offset;
    // A plane in general position (a bilinear patch on a random frame) and a sphere.
    let frame = glam::DAffine3::from_scale_rotation_translation(
        DVec3::splat(1.7),
        glam::DQuat::from_euler(glam::EulerRot::ZYX, 0.9, -0.4, 1.3),
        DVec3::new(3.0, -2.0, 0.5),
    );
    let corners = [
        DVec3::new(-1.0, -1.0, 0.0),
        DVec3::new(-1.0, 1.0, 0.0),
        DVec3::new(1.0, -1.0, 0.0),
        DVec3::new(1.0, 1.0, 0.0),
    ]
    .map(|p| frame.transform_point3(p));
    let plane = NurbsSurface::bezier([1, 1], corners.to_vec(), None).unwrap();
    let sphere = knotwork::doc::create::PrimitiveParams::default()
        .build()
        .unwrap();
    let mut doc = Document::new(Scene {
        objects: vec![
            SceneObject::new("Plate", ObjectGeometry::new(plane)),
            SceneObject {
                name: "Ball".into(),
                ..sphere
            },
        ],
        unit: None,
    });
    let d = 0.35;
    doc.execute(&Command::Apply {
        operation: Operation::new(Offset {
            object: 0.into(),
            distance: d,
            tolerance: 1e-4,
        }),
        keep_history: true,
    })
    .unwrap();
    doc.execute(&Command::Apply {
        operation: Operation::new(Contour {
            object: 1.into(),
            origin: [0.0; 3],
            normal: [0.0, 0.0, 1.0],
            spacing: 0.5,
        }),
        keep_history: true,
    })
    .unwrap();
    let contours: Vec<usize> = (3..doc.scene.objects.len()).collect();
    assert!(contours.len() >= 7, "{}", contours.len());
    // The plate turned and moved by a command, then one corner dragged along the plane: the
    // offset stays the plane moved by d along its normal (exact), every point of it.
    let turn = glam::DAffine3::from_rotation_translation(
        glam::DQuat::from_axis_angle(DVec3::new(1.0, 2.0, -0.5).normalize(), 0.7),
        DVec3::new(-1.0, 0.25, 2.0),
    );
    doc.execute(&Command::operation(
        knotwork::ops::transform::Transform::new(0, &turn),
    ))
    .unwrap();
    let points = doc.scene.objects[0].control_points();
    let (u, v) = (points[2] - points[0], points[1] - points[0]);
    doc.begin_drag(0, &[3]).unwrap();
    doc.drag_by(0.3 * u + 0.2 * v).unwrap();
    doc.commit_drag().unwrap();
    let p = doc.scene.objects[0].control_points();
    let (origin, normal) = (p[0], (p[2] - p[0]).cross(p[1] - p[0]).normalize());
    // The dragged corner stayed in the plane, so the plate is still flat.
    assert!(height(p[3], origin, normal).abs() < 1e-12);
    let offset = doc.scene.objects[2].clone();
    assert!(offset.recipe.is_some());
    let made = offset.faces();
    let [(u0, u1), (v0, v1)] = made[0].1.domain();
    for i in 0..=8 {
        for j in 0..=8 {
            let (s, t) = (
                u0 + (u1 - u0) * i as f64 / 8.0,
                v0 + (v1 - v0) * j as f64 / 8.0,
            );
            let p = made[0].1.point(s, t).unwrap();
            let h = height(p, origin, normal);
            assert!((h.abs() - d).abs() < 1e-12, "height {h} at ({s}, {t})");
        }
    }
    // The ball moved up by a quarter: every contour it still has lies on its plane z = c, on
    // the circle of radius sqrt(4 - (c - 1/4)²).
    doc.execute(&Command::operation(
        knotwork::ops::transform::Transform::new(
            1,
            &glam::DAffine3::from_translation(DVec3::new(0.0, 0.0, 0.25)),
        ),
    ))
    .unwrap();
    for &k in &contours {
        let object = &doc.scene.objects[k];
        assert!(object.recipe.is_some(), "{}", object.name);
        let curve = object.kind().space_curve().unwrap();
        let (t0, t1) = curve.domain();
        let first = curve.point_at(t0).unwrap();
        let c = (first.z / 0.5).round() * 0.5;
        let radius = (4.0 - (c - 0.25) * (c - 0.25)).sqrt();
        for n in 0..=32 {
            let p = curve.point_at(t0 + (t1 - t0) * n as f64 / 32.0).unwrap();
            assert!(
                (p.z - c).abs() < 1e-6,
                "{}: z {} on plane {c}",
                object.name,
                p.z
            );
            let r = p.truncate().length();
            assert!(
                (r - radius).abs() < 1e-3 * radius,
                "{}: radius {r} vs {radius}",
                object.name
            );
        }
    }
    // Undo brings back the ball and its contours as they were.
    let moved = doc.scene.clone();
    doc.undo().unwrap();
    assert_ne!(doc.scene.objects[3].geometry, moved.objects[3].geometry);
    doc.redo().unwrap();
    assert_eq!(doc.scene, moved);
}
