//! Surfaces built from the user's curve objects in the document, with construction history: a
//! loft, sweep or network made from curve objects follows them when a curve is dragged (every
//! drag step, on the GPU too) or edited by a command, in the same undo step; a rename follows,
//! a removal or a direct edit of the surface ends the history; projects keep it. And the curve
//! commands (knots, degree, direction, split and join, close and open, remove a point, rebuild
//! in place) keep what they promise.

use crate::common;
use knotwork::ops::intersect::Intersect;

use glam::DVec3;
use knotwork::doc::{Command, CurveEdit, Document, Touched};
use knotwork::gpu::SceneSync;
use knotwork::io::project::{self, Project};
use knotwork::kernel::{Direction, NurbsSurface, SpaceCurve, splines};
use knotwork::ops::construct::Construct;
use knotwork::scene::operation::Operation;
use knotwork::scene::{ObjectGeometry, Scene, SceneObject};

/// A closed section: a wobbly ellipse of 8 points through which a cubic is interpolated, at
/// height z.
fn section(z: f64, wobble: f64) -> SpaceCurve {
    let points: Vec<DVec3> = (0..8)
        .map(|i| {
            let a = i as f64 / 8.0 * std::f64::consts::TAU;
            DVec3::new(
                a.cos() * (2.0 + wobble * (3.0 * a).sin()),
                1.5 * a.sin(),
                z + 0.2 * wobble * (2.0 * a).cos(),
            )
        })
        .collect();
    splines::interpolate_closed(&points, 3, splines::Parametrization::ChordLength).unwrap()
}

fn curve_object(name: &str, curve: SpaceCurve) -> SceneObject {
    SceneObject::new(name, ObjectGeometry::new(curve))
}

/// Three section curves named "s0", "s1", "s2".
fn sections() -> Document {
    Document::new(Scene {
        objects: vec![
            curve_object("s0", section(0.0, 0.2)),
            curve_object("s1", section(1.2, 0.5)),
            curve_object("s2", section(2.5, 0.1)),
        ],
        unit: None,
    })
}

/// The loft of objects 0, 1 and 2 ("s0", "s1", "s2").
fn loft_construction() -> Operation {
    construct(serde_json::json!({"construct": "loft", "curves": [0, 1, 2], "degree": 3}))
}

/// The construct operation `request` (its curves objects by index).
fn construct(request: serde_json::Value) -> Operation {
    Operation::new(Construct::read("", request).unwrap())
}

/// Runs `operation` with its history kept.
fn with_history(operation: Operation) -> Command {
    Command::Apply {
        operation,
        keep_history: true,
    }
}

fn surface(object: &SceneObject) -> &NurbsSurface {
    object.geometry.nurbs_surface().expect("a NURBS surface")
}

fn curve(object: &SceneObject) -> &SpaceCurve {
    object.kind().space_curve().expect("a curve")
}

/// The largest distance from 60 points of `curve` to `surface` (point inversion).
fn curve_to_surface(curve: &SpaceCurve, surface: &NurbsSurface) -> f64 {
    (0..=60)
        .map(|k| {
            let p = curve.point_at(curve.parameter_at(k as f64 / 60.0)).unwrap();
            surface.closest_point(p).unwrap().distance
        })
        .fold(0.0, f64::max)
}

/// The largest distance between the two curves at 50 equal parameter fractions.
fn curve_distance(a: &SpaceCurve, b: &SpaceCurve) -> f64 {
    (0..=50)
        .map(|k| {
            let f = k as f64 / 50.0;
            let (p, q) = (
                a.point_at(a.parameter_at(f)).unwrap(),
                b.point_at(b.parameter_at(f)).unwrap(),
            );
            p.distance(q)
        })
        .fold(0.0, f64::max)
}

fn lofted() -> Document {
    let mut doc = sections();
    doc.execute(&with_history(loft_construction())).unwrap();
    doc
}

#[test]
fn a_loft_of_curve_objects_follows_a_dragged_section_and_undoes_in_one_step() {
    let mut doc = lofted();
    assert_eq!(doc.scene.objects.len(), 4);
    let loft = &doc.scene.objects[3];
    assert_eq!(loft.name, "loft");
    let kept = &loft.recipe.as_ref().expect("history").operation;
    assert_eq!(kept.by_index(&doc.scene).unwrap(), loft_construction());
    for k in 0..3 {
        let d = curve_to_surface(curve(&doc.scene.objects[k]), surface(loft));
        assert!(d < 1e-7, "section {k}: {d:e}");
    }
    let original = doc.scene.clone();
    let undo_depth = doc.history.undo_depth();

    // Drag point 3 of the middle section: every step builds the loft again through it.
    doc.begin_drag(1, &[3]).unwrap();
    for step in 1..=3 {
        let moved = doc
            .drag_by(DVec3::new(0.1, 0.2, 0.15) * f64::from(step))
            .unwrap();
        assert_eq!(moved.rebuilt, vec![3], "step {step}");
        let d = curve_to_surface(curve(&doc.scene.objects[1]), surface(&doc.scene.objects[3]));
        assert!(
            d < 1e-7,
            "step {step}: the loft misses the moved section by {d:e}"
        );
    }
    assert_ne!(doc.scene.objects[3], original.objects[3]);
    assert!(doc.scene.objects[3].recipe.is_some());
    doc.commit_drag().unwrap();
    assert_eq!(doc.history.undo_depth(), undo_depth + 1, "one undo step");
    doc.undo().unwrap();
    assert_eq!(
        doc.scene, original,
        "undo brings back the curve and the loft"
    );
    doc.redo().unwrap();
    let d = curve_to_surface(curve(&doc.scene.objects[1]), surface(&doc.scene.objects[3]));
    assert!(d < 1e-7);

    // A cancelled drag puts the loft back too.
    let before = doc.scene.clone();
    doc.begin_drag(0, &[0]).unwrap();
    doc.drag_by(DVec3::new(0.0, 0.0, -0.4)).unwrap();
    doc.cancel_drag().unwrap();
    assert_eq!(doc.scene, before);
}

#[test]
fn commands_on_input_curves_rebuild_rename_or_end_the_history() {
    let mut doc = lofted();
    // A transform of a section rebuilds the loft in the same step.
    doc.execute(&Command::operation(
        knotwork::ops::transform::Transform::new(
            2,
            &glam::DAffine3::from_translation(DVec3::new(0.0, 0.0, 0.8)),
        ),
    ))
    .unwrap();
    let d = curve_to_surface(curve(&doc.scene.objects[2]), surface(&doc.scene.objects[3]));
    assert!(d < 1e-7, "{d:e}");
    assert_eq!(doc.undo().unwrap().touched(), Touched::Structure);
    assert_eq!(doc.scene, lofted().scene);

    // A rename follows.
    doc.execute(&Command::Rename {
        object: 0,
        name: "bottom".into(),
    })
    .unwrap();
    let recipe = doc.scene.objects[3].recipe.clone().unwrap();
    assert_eq!(recipe.describe(&doc.scene), "loft of bottom, s1, s2");
    // History holds its inputs by id: a name that another object has captures nothing, and
    // the loft still follows the curve renamed.
    doc.execute(&Command::Rename {
        object: 2,
        name: "s1".into(),
    })
    .unwrap();
    assert_eq!(
        doc.scene.objects[3]
            .recipe
            .as_ref()
            .unwrap()
            .describe(&doc.scene),
        "loft of bottom, s1, s1"
    );
    doc.execute(&Command::operation(
        knotwork::ops::transform::Transform::new(
            2,
            &glam::DAffine3::from_translation(DVec3::new(0.1, 0.0, 0.3)),
        ),
    ))
    .unwrap();
    let d = curve_to_surface(curve(&doc.scene.objects[2]), surface(&doc.scene.objects[3]));
    assert!(d < 1e-7, "the loft follows the renamed curve: {d:e}");
    doc.undo().unwrap();
    doc.undo().unwrap();
    // The curve edits rebuild too (knot insertion keeps the shape, so the loft stays on it).
    doc.execute(&Command::ElevateDegree {
        object: 0,
        direction: Direction::U,
    })
    .unwrap();
    let d = curve_to_surface(curve(&doc.scene.objects[0]), surface(&doc.scene.objects[3]));
    assert!(d < 1e-7, "{d:e}");

    // Removing an input ends the history, and the step says so; undo brings it back.
    let label = doc
        .execute(&Command::Delete { object: 1 })
        .unwrap()
        .label
        .clone();
    assert_eq!(doc.scene.objects[2].recipe, None);
    assert!(
        label.contains("loft's construction history ends: s1 was removed"),
        "{label}"
    );
    doc.undo().unwrap();
    assert!(doc.scene.objects[3].recipe.is_some());

    // A direct edit of the surface ends its history, and the step says so.
    let edit = doc
        .execute(&Command::MovePoints {
            object: 3,
            moves: vec![(0, DVec3::new(5.0, 5.0, 5.0))],
        })
        .unwrap();
    assert!(edit.ends_history());
    let label = edit.label.clone();
    assert!(
        label.contains("loft's construction history ends: it no longer follows its curves"),
        "{label}"
    );
    assert_eq!(doc.scene.objects[3].recipe, None);
    doc.undo().unwrap();
    // Breaking it on purpose is said by its own label.
    let label = doc
        .execute(&Command::BreakHistory { object: 3 })
        .unwrap()
        .label
        .clone();
    assert_eq!(label, "break history");
    assert_eq!(doc.scene.objects[3].recipe, None);
    assert!(doc.execute(&Command::BreakHistory { object: 3 }).is_err());
}

#[test]
fn history_is_saved_and_a_bad_one_is_refused_by_path() {
    let doc = lofted();
    let text = project::write(&Project {
        scene: doc.scene.clone(),
        view: None,
    });
    assert!(text.contains("\"history\""));
    let back = project::read(&text).unwrap();
    assert_eq!(back.scene, doc.scene);
    let bad = text.replace("\"curves\":[0,1,2]", "\"curves\":[0,1,5]");
    assert_ne!(bad, text);
    let error = project::read(&bad).unwrap_err();
    assert!(
        error.path.starts_with("objects[3].history") && error.message.contains("object 5"),
        "{error}"
    );
}

/// A project saved before constructions from curves became operations (by commit 7c54d1f; see
/// `tests/reference/projects/README.md`) opens with its histories: a loft of three sections
/// given in a shuffled order, an extrusion of one of them, and an offset of the extrusion. A
/// drag of a section moves all three, each still exactly on what it was made from.
#[test]
fn a_project_saved_with_the_earlier_construction_history_opens_and_follows() {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/reference/projects/history-2026-11-28.json"
    ))
    .unwrap();
    let project = project::read(&text).unwrap();
    let mut doc = Document::new(project.scene);
    let names: Vec<&str> = doc.scene.objects.iter().map(|o| o.name.as_str()).collect();
    assert_eq!(
        names,
        [
            "ring",
            "waist",
            "rim",
            "loft",
            "extrusion",
            "extrusion offset"
        ]
    );
    let describe = |doc: &Document, k: usize| {
        doc.scene.objects[k]
            .recipe
            .as_ref()
            .map(|r| r.describe(&doc.scene))
    };
    assert_eq!(
        describe(&doc, 3).as_deref(),
        Some("loft of rim, ring, waist")
    );
    assert_eq!(describe(&doc, 4).as_deref(), Some("extrude of rim"));
    assert_eq!(describe(&doc, 5).as_deref(), Some("offset of extrusion"));
    // The loose loft passes through its first and last sections (rim and waist; its middle
    // one is a control row, not interpolated).
    let on_loft = |doc: &Document, k: usize| {
        curve_to_surface(curve(&doc.scene.objects[k]), surface(&doc.scene.objects[3]))
    };
    for k in [2, 1] {
        assert!(
            on_loft(&doc, k) < 1e-7,
            "section {k}: {:e}",
            on_loft(&doc, k)
        );
    }
    assert!(
        on_loft(&doc, 0) > 1e-3,
        "the middle section is a control row"
    );
    // Drag the rim: the loft, the extrusion and its offset follow in one step.
    let before = doc.scene.clone();
    doc.begin_drag(2, &[1, 2]).unwrap();
    let moved = doc.drag_by(DVec3::new(0.2, -0.1, 0.25)).unwrap();
    assert_eq!(moved.rebuilt, vec![3, 4, 5]);
    doc.commit_drag().unwrap();
    for k in [2, 1] {
        assert!(
            on_loft(&doc, k) < 1e-7,
            "section {k}: {:e}",
            on_loft(&doc, k)
        );
    }
    let extrusion = surface(&doc.scene.objects[4]);
    let rim = curve(&doc.scene.objects[2]);
    let d = curve_to_surface(rim, extrusion);
    assert!(d < 1e-7, "the extrusion starts on the moved rim: {d:e}");
    // The offset is 0.125 from the extrusion: sample it and measure back.
    let offset = surface(&doc.scene.objects[5]);
    let [(u0, u1), (v0, v1)] = offset.domain();
    for i in 1..8 {
        for j in 1..8 {
            let p = offset
                .point_at(
                    u0 + (u1 - u0) * i as f64 / 8.0,
                    v0 + (v1 - v0) * j as f64 / 8.0,
                )
                .unwrap();
            let d = extrusion.closest_point(p).unwrap().distance;
            assert!((d - 0.125).abs() < 1e-3, "offset distance {d}");
        }
    }
    doc.undo().unwrap();
    assert_eq!(doc.scene, before);
    // The bad reference an old file could hold is refused by path, as that build refused it.
    let bad = text.replace("{\"input\":2}", "{\"input\":5}");
    assert_ne!(bad, text);
    let error = project::read(&bad).unwrap_err();
    assert!(
        error.path.starts_with("objects[3].construction") && error.message.contains("input 5"),
        "{error}"
    );
    let renamed = text.replace("\"inputs\":[\"rim\"]", "\"inputs\":[\"nowhere\"]");
    assert_ne!(renamed, text);
    let error = project::read(&renamed).unwrap_err();
    assert!(
        error.path.starts_with("objects[4].construction.inputs[0]")
            && error.message.contains("nowhere"),
        "{error}"
    );
}

#[test]
fn a_failed_rebuild_keeps_the_surface_and_says_why() {
    // A sweep whose profile is moved far off the rail still sweeps; a loft whose section is
    // collapsed to a point is refused by the kernel and the loft keeps its last shape.
    let mut doc = lofted();
    let before = doc.scene.objects[3].clone();
    let count = curve(&doc.scene.objects[1]).count();
    let moves: Vec<(usize, DVec3)> = (0..count).map(|k| (k, DVec3::new(0.0, 0.0, 1.2))).collect();
    let edit = doc
        .execute(&Command::MovePoints { object: 1, moves })
        .unwrap();
    assert!(edit.label.contains("loft not rebuilt"), "{}", edit.label);
    assert_eq!(doc.scene.objects[3].geometry, before.geometry);
}

#[test]
fn a_construction_from_curves_is_one_undo_step_and_bad_input_changes_nothing() {
    let mut doc = sections();
    let before = doc.clone();
    // A loft of one curve is refused with the kernel's reason.
    let one = construct(serde_json::json!({"construct": "loft", "curves": [0]}));
    let refused = doc.execute(&with_history(one));
    assert!(refused.is_err());
    assert_eq!(doc, before);
    // An input that is not in the scene, or not a curve.
    let missing = construct(serde_json::json!({"construct": "loft", "curves": [0, 7]}));
    let error = doc.execute(&with_history(missing)).unwrap_err().to_string();
    assert!(
        error.contains("curves[1]") && error.contains("object 7"),
        "{error}"
    );
    assert!(
        Construct::with_inputs(
            "",
            serde_json::json!({"construct": "loft", "curves": [{"input": 3}]}),
            &[0.into()]
        )
        .is_err()
    );
    // A rebuild in place (no history): the curve object keeps its name.
    doc.execute(&Command::Apply {
        operation: construct(serde_json::json!(
            {"construct": "rebuild", "curve": 0, "points": 12, "degree": 3, "replace": 0}
        )),
        keep_history: false,
    })
    .unwrap();
    assert_eq!(doc.scene.objects[0].name, "s0");
    assert_eq!(curve(&doc.scene.objects[0]).count(), 12);
    assert!(
        curve_distance(
            curve(&doc.scene.objects[0]),
            curve(&before.scene.objects[0])
        ) < 0.05
    );
    doc.undo().unwrap();
    assert_eq!(doc.scene, before.scene);
}

#[test]
fn curve_commands_keep_the_shape_where_they_promise_to() {
    let open = splines::interpolate_through(
        &[
            DVec3::ZERO,
            DVec3::new(1.0, 1.0, 0.0),
            DVec3::new(2.0, 0.5, 0.3),
            DVec3::new(3.0, -0.5, 0.0),
            DVec3::new(4.0, 0.0, 0.5),
        ],
        3,
        splines::Parametrization::ChordLength,
        None,
    )
    .unwrap();
    let mut doc = Document::new(Scene {
        objects: vec![curve_object("c", open.clone())],
        unit: None,
    });
    let (a, b) = open.domain();
    let middle = 0.5 * (a + b);
    for command in [
        Command::InsertKnot {
            object: 0,
            direction: Direction::U,
            value: middle,
        },
        Command::ElevateDegree {
            object: 0,
            direction: Direction::U,
        },
    ] {
        doc.execute(&command).unwrap();
        let c = curve(&doc.scene.objects[0]);
        assert!(curve_distance(c, &open) < 1e-12, "{command:?}");
        assert!(c.count() > open.count(), "{command:?}");
        doc.undo().unwrap();
    }
    // Reverse runs the other way: its start is the end.
    doc.execute(&Command::Reverse {
        object: 0,
        direction: Direction::U,
    })
    .unwrap();
    let (start, _) = curve(&doc.scene.objects[0]).ends().unwrap();
    assert!(start.distance(open.ends().unwrap().1) < 1e-12);
    doc.undo().unwrap();
    // Split and join give the curve back.
    doc.execute(&Command::Split {
        object: 0,
        direction: Direction::U,
        value: middle,
    })
    .unwrap();
    assert_eq!(doc.scene.objects.len(), 2);
    assert_eq!(doc.scene.objects[1].name, "c (b)");
    doc.execute(&Command::EditCurve {
        object: 0,
        edit: CurveEdit::Join { other: 1 },
    })
    .unwrap();
    assert_eq!(doc.scene.objects.len(), 1);
    let joined = curve(&doc.scene.objects[0]);
    for k in 0..=40 {
        let p = joined
            .point_at(joined.parameter_at(k as f64 / 40.0))
            .unwrap();
        let q = open.point_at(open.closest_parameter(p).unwrap()).unwrap();
        assert!(
            p.distance(q) < 1e-9,
            "joined point {k} is {:e} off",
            p.distance(q)
        );
    }
    // Close puts the end on the start; then a periodic curve opens to the same shape.
    doc.execute(&Command::EditCurve {
        object: 0,
        edit: CurveEdit::Close,
    })
    .unwrap();
    let (s, e) = curve(&doc.scene.objects[0]).ends().unwrap();
    assert!(s.distance(e) < 1e-12);
    assert!(
        doc.execute(&Command::EditCurve {
            object: 0,
            edit: CurveEdit::Close,
        })
        .is_err()
    );
    let ring = section(0.0, 0.3);
    let mut rings = Document::new(Scene {
        objects: vec![curve_object("ring", ring.clone())],
        unit: None,
    });
    rings
        .execute(&Command::EditCurve {
            object: 0,
            edit: CurveEdit::Open,
        })
        .unwrap();
    assert!(curve_distance(curve(&rings.scene.objects[0]), &ring) < 1e-12);
    assert!(
        rings
            .execute(&Command::EditCurve {
                object: 0,
                edit: CurveEdit::Open,
            })
            .is_err()
    );
    // Removing a point leaves one fewer; the ends stay.
    let before = curve(&doc.scene.objects[0]).clone();
    doc.execute(&Command::EditCurve {
        object: 0,
        edit: CurveEdit::RemovePoint { point: 2 },
    })
    .unwrap();
    let after = curve(&doc.scene.objects[0]);
    assert_eq!(after.count(), before.count() - 1);
    assert_eq!(after.ends().unwrap().0, before.ends().unwrap().0);
    // Curves take no lattice and no displacement.
    let lattice = knotwork::kernel::ffd::Lattice::around(DVec3::ZERO, DVec3::ONE, [1, 1, 1]);
    if let Ok(lattice) = lattice {
        assert!(
            doc.execute(&Command::SetLattice {
                objects: vec![0],
                lattice: Some(lattice),
            })
            .is_err()
        );
    }
}

/// The GPU follows: dragging a section re-evaluates the loft (and the curve), and the loft's
/// vertices match the kernel's rebuilt loft; incremental equals a full evaluation.
#[test]
fn the_gpu_follows_a_dragged_section() {
    let context = common::gpu();
    let mut doc = lofted();
    let mut sync = SceneSync::new(&context.device, &context.queue);
    sync.rebuild(&doc.scene, 1.0).unwrap();
    sync.evaluate_blocking().unwrap();
    doc.begin_drag(1, &[2]).unwrap();
    for step in 1..=2 {
        let moved = doc
            .drag_by(DVec3::new(0.0, 0.3, 0.2) * f64::from(step))
            .unwrap();
        sync.points_moved(&doc.scene, &moved).unwrap();
        sync.evaluate_blocking().unwrap();
    }
    let vertices = sync.read_vertices().unwrap();
    let loft = &doc.scene.objects[3];
    let first = sync.first_patch(3).unwrap();
    let records = sync.records().unwrap();
    let size = {
        let (lo, hi) = loft.bounds().unwrap();
        (hi - lo).length()
    };
    let mut worst = 0.0f64;
    for (k, record) in records.iter().enumerate().skip(first) {
        if record.object != 3 {
            continue;
        }
        let n = record.segments_u as usize;
        for i in 0..=n {
            for j in 0..=n {
                let v = vertices[record.vertex_offset as usize + i * (n + 1) + j];
                let exact = loft
                    .kind()
                    .surface_point(k - first, i as f64 / n as f64, j as f64 / n as f64)
                    .unwrap();
                worst = worst.max(DVec3::from(v.position.map(f64::from)).distance(exact));
            }
        }
    }
    eprintln!(
        "dragged loft on the GPU vs f64: {:.2e} of its size",
        worst / size
    );
    assert!(worst / size < 1e-5);
    let mut full = SceneSync::new(&context.device, &context.queue);
    full.rebuild(&doc.scene, 1.0).unwrap();
    full.evaluate_blocking().unwrap();
    assert!(full.read_vertices().unwrap() == vertices);
    assert!(full.read_curve_vertices().unwrap() == sync.read_curve_vertices().unwrap());
}

/// Intersect in the document: a plane through a sphere gives curve objects on both surfaces
/// (by point inversion, within 1e-6 of the scene's size), one undo step; surfaces apart, an
/// object with itself and a curve are refused and change nothing.
#[test]
fn intersecting_two_objects_adds_their_curves_of_intersection() {
    use knotwork::kernel::construct;
    let sphere = construct::sphere(DVec3::ZERO, 1.0).unwrap();
    let plane = construct::plane(
        DVec3::new(-2.0, -2.0, 0.4),
        DVec3::new(4.0, 0.0, 0.0),
        DVec3::new(0.0, 4.0, 0.0),
    )
    .unwrap();
    let high = construct::plane(
        DVec3::new(-2.0, -2.0, 3.0),
        DVec3::new(4.0, 0.0, 0.0),
        DVec3::new(0.0, 4.0, 0.0),
    )
    .unwrap();
    let mut doc = Document::new(Scene {
        objects: vec![
            SceneObject::new("Ball", ObjectGeometry::new(sphere.clone())),
            SceneObject::new("Cut", ObjectGeometry::new(plane.clone())),
            SceneObject::new("High", ObjectGeometry::new(high)),
            curve_object("s0", section(0.0, 0.2)),
        ],
        unit: None,
    });
    let before = doc.scene.clone();
    let edit = doc
        .execute(&Command::operation(Intersect {
            a: 0.into(),
            b: 1.into(),
        }))
        .unwrap()
        .clone();
    assert!(
        edit.label.starts_with("intersect Ball × Cut"),
        "{}",
        edit.label
    );
    let added = &doc.scene.objects[4..];
    assert!(!added.is_empty());
    assert_eq!(added[0].name, "Ball × Cut");
    let size = doc.scene.bounds().map(|(lo, hi)| lo.distance(hi)).unwrap();
    let r = (1.0f64 - 0.16).sqrt();
    let mut length = 0.0;
    for object in added {
        let c = curve(object);
        for k in 0..=100 {
            let p = c.point_at(c.parameter_at(k as f64 / 100.0)).unwrap();
            assert!(
                sphere.closest_point(p).unwrap().distance < 1e-6 * size,
                "{p}"
            );
            assert!(
                plane.closest_point(p).unwrap().distance < 1e-6 * size,
                "{p}"
            );
            assert!(
                ((p.x * p.x + p.y * p.y).sqrt() - r).abs() < 1e-6 * size,
                "{p}"
            );
        }
        length += (0..200)
            .map(|k| {
                let t0 = c.parameter_at(k as f64 / 200.0);
                let t1 = c.parameter_at((k + 1) as f64 / 200.0);
                c.point_at(t0).unwrap().distance(c.point_at(t1).unwrap())
            })
            .sum::<f64>();
    }
    assert!(
        (length - std::f64::consts::TAU * r).abs() < 1e-3,
        "{length}"
    );
    doc.undo().unwrap();
    assert_eq!(doc.scene, before);
    for (a, b, message) in [(0, 2, "do not meet"), (0, 0, "itself"), (0, 3, "no faces")] {
        let error = doc
            .execute(&Command::operation(Intersect {
                a: a.into(),
                b: b.into(),
            }))
            .unwrap_err()
            .to_string();
        assert!(error.contains(message), "{error}");
        assert_eq!(doc.scene, before);
    }
}
