//! The command layer: random sequences of edits (move, weight, knot insertion and removal,
//! degree elevation, split, reverse, create, duplicate, delete, transform, rename, hide,
//! subdivision settings), each
//! undone and redone through the history, with a save and load in between. Failed commands
//! must leave the document and the history untouched.

use glam::{DAffine3, DVec2, DVec3};
use knotwork::doc::{Command, EditError, History, TrimEdit, apply};
use knotwork::io::project::{self, Project};
use knotwork::kernel::subdiv::patches::Display;
use knotwork::kernel::subdiv::{Crease, Options, Scheme, SubdivisionSurface, cages};
use knotwork::kernel::trim::shapes::ellipse;
use knotwork::kernel::{Direction, construct};
use knotwork::scene::{ObjectGeometry, Scene, SceneObject, SubdivSettings};
use proptest::prelude::*;

/// A small scene with every kind of object: the teapot's lid (Bézier patches over shared
/// points), a rational torus and a non-uniform B-spline.
fn start_scene() -> Scene {
    let demo = Scene::demo().unwrap();
    let mut scene = Scene::default();
    scene.objects.push(demo.objects[0].clone());
    scene.objects.push(demo.objects[1].clone());
    scene.objects.push(demo.objects[3].clone());
    scene
}

/// [`start_scene`] and a subdivision cube at level 2.
fn start_scene_with_cage() -> Scene {
    let mut scene = start_scene();
    let cube = cages::cube(DVec3::new(4.0, 0.0, 0.0), 2.0).unwrap();
    let surface = SubdivisionSurface::from_mesh(cube, 2).unwrap();
    scene.objects.push(SceneObject::new(
        "cage",
        ObjectGeometry::new(knotwork::scene::SubdivObject::from(surface)),
    ));
    scene
}

fn direction(bit: u32) -> Direction {
    if bit & 1 == 0 {
        Direction::U
    } else {
        Direction::V
    }
}

/// A concrete command from random numbers, against the current scene (so most are valid, and
/// some deliberately are not: weights ≤ 0, NaN positions, parameters outside the domain).
fn command(scene: &Scene, kind: u8, r: u32, a: f64, b: f64, c: f64) -> Command {
    let n = scene.objects.len();
    if n == 0 || kind == 5 {
        let origin = DVec3::new(a * 10.0, b * 10.0, c);
        let surface = construct::plane(origin, DVec3::X * (1.0 + a), DVec3::Y * (1.0 + b))
            .unwrap()
            .elevate_degree(Direction::U, (r % 3) as usize)
            .unwrap();
        return Command::Add {
            object: SceneObject::new(format!("Plane {r}"), ObjectGeometry::new(surface)),
        };
    }
    let object = r as usize % n;
    let target = &scene.objects[object];
    let points = target.control_points();
    let index = (r as usize / 7) % points.len().max(1);
    let domain = target
        .geometry
        .nurbs_surface()
        .map_or([(0.0, 1.0), (0.0, 1.0)], |s| s.domain());
    let d = direction(r >> 4);
    let (lo, hi) = domain[d.index()];
    let inside = lo + (hi - lo) * (0.05 + 0.9 * a);
    match kind {
        0 => {
            let mut position =
                points.get(index).copied().unwrap_or_default() + DVec3::new(a - 0.5, b - 0.5, c);
            if c > 1.9 {
                position.y = f64::NAN;
            }
            Command::MovePoints {
                object,
                moves: vec![
                    (index, position),
                    ((index + 1) % points.len().max(1), position),
                ],
            }
        }
        1 => Command::SetWeight {
            object,
            points: vec![index],
            weight: if c < -1.5 { -a } else { 0.2 + 2.0 * a },
        },
        2 => Command::InsertKnot {
            object,
            direction: d,
            // Now and then outside the domain, which must be refused.
            value: if c > 1.8 { hi + 1.0 } else { inside },
        },
        3 => Command::ElevateDegree {
            object,
            direction: d,
        },
        4 => Command::Split {
            object,
            direction: d,
            value: inside,
        },
        6 => Command::Delete { object },
        7 => Command::Duplicate { object },
        8 => {
            if r & 1 == 0 {
                Command::Reverse {
                    object,
                    direction: d,
                }
            } else {
                Command::SwapUv { object }
            }
        }
        9 => Command::operation(knotwork::ops::transform::Transform::new(
            object,
            &DAffine3::from_scale_rotation_translation(
                DVec3::splat(0.5 + a),
                glam::DQuat::from_rotation_z(c),
                DVec3::new(b, -a, c),
            ),
        )),
        11 if r & 4 == 0 => {
            // Trims: a circular hole somewhere in the domain (refused where it leaves the
            // domain or crosses a loop there already), keeping the other side, deleting a loop.
            let [(u0, u1), (v0, v1)] = domain;
            let edit = match r % 3 {
                0 => TrimEdit::Add {
                    curves: ellipse(
                        DVec2::new(u0 + (u1 - u0) * a, v0 + (v1 - v0) * b),
                        DVec2::new((u1 - u0) * 0.2 * c.abs(), (v1 - v0) * 0.15),
                    )
                    .unwrap_or_default(),
                    keep_inside: r & 8 != 0,
                },
                1 => TrimEdit::Invert,
                _ => TrimEdit::Delete {
                    trim_loop: (r as usize >> 5) % 3,
                },
            };
            Command::Trim { object, edit }
        }
        10 => {
            // Remove a knot just inserted (possible) or an arbitrary value (refused).
            Command::RemoveKnot {
                object,
                direction: d,
                value: inside,
                tolerance: 1e-9,
            }
        }
        _ if r & 4 != 0 => {
            // Subdivision settings: refused for surfaces, for Loop on the cube's quads, for a
            // negative sharpness or an edge the cage lacks.
            let scheme = if r & 8 == 0 {
                Scheme::CatmullClark
            } else {
                Scheme::Loop
            };
            Command::SetSubdivision {
                object,
                settings: SubdivSettings {
                    options: Options {
                        scheme,
                        ..Options::default()
                    },
                    level: (r >> 4) % 4,
                    display: Display::Limit,
                    tolerance: 0.002,
                    creases: vec![Crease {
                        a: (r >> 6) % 3,
                        b: (r >> 8) % 3,
                        sharpness: c * 3.0,
                    }],
                    corners: Vec::new(),
                },
            }
        }
        _ => {
            if r & 2 == 0 {
                Command::Rename {
                    object,
                    name: if c > 1.9 {
                        String::new()
                    } else {
                        format!("renamed {r}")
                    },
                }
            } else {
                Command::SetVisible {
                    object,
                    visible: c > 0.0,
                }
            }
        }
    }
}

fn round_trip(scene: &Scene) -> Scene {
    let text = project::write(&Project {
        scene: scene.clone(),
        view: None,
    });
    project::read(&text).unwrap().scene
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    #[test]
    fn undo_all_restores_the_start_and_redo_all_the_end(
        steps in prop::collection::vec(
            (0u8..12, any::<u32>(), 0.0f64..1.0, 0.0f64..1.0, -2.0f64..2.0), 1..14),
        save_at in 0usize..14,
    ) {
        let start = start_scene_with_cage();
        let mut scene = start.clone();
        let mut history = History::default();
        let mut applied = 0;
        for (k, &(kind, r, a, b, c)) in steps.iter().enumerate() {
            if k == save_at {
                let loaded = round_trip(&scene);
                prop_assert_eq!(&loaded, &scene, "save and load changed the document");
                scene = loaded;
            }
            let cmd = command(&scene, kind, r, a, b, c);
            let (before, history_before) = (scene.clone(), history.clone());
            match history.execute(&mut scene, &cmd) {
                Ok(_) => applied += 1,
                Err(_) => {
                    prop_assert_eq!(&scene, &before, "a failed {:?} changed the scene", cmd);
                    prop_assert_eq!(&history, &history_before);
                }
            }
        }
        let end = scene.clone();
        prop_assert_eq!(history.undo_depth(), applied);
        for _ in 0..applied {
            history.undo(&mut scene).unwrap();
        }
        prop_assert_eq!(&scene, &start, "undo all did not restore the start");
        prop_assert!(matches!(history.undo(&mut scene), Err(EditError::NothingTo("undo"))));
        prop_assert_eq!(&scene, &start);
        for _ in 0..applied {
            history.redo(&mut scene).unwrap();
        }
        prop_assert_eq!(&scene, &end, "redo all did not give the end state");
        prop_assert_eq!(&round_trip(&scene), &end);
    }
}

#[test]
fn refused_commands_name_the_problem() {
    let mut scene = start_scene();
    let start = scene.clone();
    let cases: Vec<(Command, &str)> = vec![
        (
            Command::SetWeight {
                object: 1,
                points: vec![0],
                weight: 0.0,
            },
            "a weight must be finite and > 0, got 0",
        ),
        (
            Command::SetWeight {
                object: 1,
                points: vec![0],
                weight: f64::NAN,
            },
            "a weight must be finite and > 0, got NaN",
        ),
        (
            Command::InsertKnot {
                object: 0,
                direction: Direction::U,
                value: 0.5,
            },
            "Utah teapot: knot insertion needs a NURBS surface",
        ),
        (
            Command::SetKnots {
                object: 2,
                direction: Direction::U,
                knots: vec![0.0, 1.0],
            },
            "B-spline (2, 5): knots[0]",
        ),
        (
            Command::MovePoints {
                object: 1,
                moves: vec![(0, DVec3::new(f64::INFINITY, 0.0, 0.0))],
            },
            "is not finite",
        ),
        (
            Command::MovePoints {
                object: 1,
                moves: vec![(2, DVec3::new(0.0, -1e300, 0.0))],
            },
            "point 2: the coordinate -1e300 is outside ±1e9",
        ),
        (
            Command::Delete { object: 7 },
            "there is no object 7 (the scene has 3)",
        ),
        (
            Command::Rename {
                object: 1,
                name: "\u{7}".into(),
            },
            "a name must be 1 to 200 characters",
        ),
    ];
    for (cmd, message) in cases {
        let e = apply(&mut scene, &cmd).unwrap_err().to_string();
        assert!(e.contains(message), "{cmd:?}: {e:?} lacks {message:?}");
        assert_eq!(scene, start);
    }
}

#[test]
fn shape_preserving_edits_keep_the_surface() {
    // Knot insertion and degree elevation through the command layer leave every point in place
    // (compared by evaluation, independent of the control net).
    let mut scene = start_scene();
    let reference = scene.objects[2].geometry.nurbs_surface().unwrap().clone();
    let mut history = History::default();
    for cmd in [
        Command::InsertKnot {
            object: 2,
            direction: Direction::U,
            value: 0.37,
        },
        Command::ElevateDegree {
            object: 2,
            direction: Direction::V,
        },
    ] {
        history.execute(&mut scene, &cmd).unwrap();
    }
    let Some(edited) = scene.objects[2]
        .geometry
        .downcast_ref::<knotwork::kernel::NurbsSurface>()
    else {
        unreachable!()
    };
    assert_ne!(edited.count(), reference.count());
    let [(u0, u1), (v0, v1)] = reference.domain();
    for i in 0..=10 {
        for j in 0..=10 {
            let (u, v) = (
                u0 + (u1 - u0) * i as f64 / 10.0,
                v0 + (v1 - v0) * j as f64 / 10.0,
            );
            let d = edited.point_at(u, v).unwrap() - reference.point_at(u, v).unwrap();
            assert!(d.length() < 1e-12, "moved by {d} at ({u}, {v})");
        }
    }
    // A split gives two objects that meet the original at the split parameter.
    history
        .execute(
            &mut scene,
            &Command::Split {
                object: 2,
                direction: Direction::V,
                value: 0.5 * (v0 + v1),
            },
        )
        .unwrap();
    assert_eq!(scene.objects.len(), 4);
    assert!(scene.objects[3].name.ends_with("(b)"));
    history.undo(&mut scene).unwrap();
    assert_eq!(scene.objects.len(), 3);
}

/// A subdivision change's undo step says what changed: a crease is a crease, not "subdivision
/// level 2".
#[test]
fn a_crease_is_labelled_as_a_crease_in_the_history() {
    use knotwork::scene::{SubdivObject, registry};
    let cage = registry::kinds()
        .into_iter()
        .flat_map(|entry| (entry.examples)())
        .find(|o| o.geometry.downcast_ref::<SubdivObject>().is_some())
        .expect("a subdivision example");
    let mut doc = knotwork::doc::Document::new(Scene {
        objects: vec![cage.clone()],
        unit: None,
    });
    let settings = |doc: &knotwork::doc::Document| {
        doc.scene.objects[0]
            .geometry
            .downcast_ref::<SubdivObject>()
            .unwrap()
            .settings()
    };
    let mut creased = settings(&doc);
    creased.set_crease(0, 1, 2.0);
    let mut deeper = creased.clone();
    deeper.level += 1;
    let mut uncreased = deeper.clone();
    uncreased.set_crease(0, 1, 0.0);
    for (settings, label) in [
        (creased, "crease 0–1 sharpness 2"),
        (deeper, "subdivision level 3"),
        (uncreased, "remove crease 0–1"),
    ] {
        let edit = doc
            .execute(&knotwork::doc::Command::SetSubdivision {
                object: 0,
                settings,
            })
            .unwrap();
        assert_eq!(edit.label, label);
    }
}

#[test]
fn colour_and_unit_edits_undo_and_opening_a_step_file_sets_the_unit_as_one_step() {
    use knotwork::doc::Document;
    use knotwork::scene::LengthUnit;
    let mut doc = Document::new(start_scene());
    let before = doc.clone();
    doc.execute(&Command::SetColor {
        object: 1,
        color: Some([0.8, 0.2, 0.1]),
    })
    .unwrap();
    doc.execute(&Command::SetUnit {
        unit: Some(LengthUnit::Inch),
    })
    .unwrap();
    assert_eq!(doc.scene.objects[1].color, Some([0.8, 0.2, 0.1]));
    assert_eq!(doc.scene.unit, Some(LengthUnit::Inch));
    let refused = doc
        .execute(&Command::SetColor {
            object: 1,
            color: Some([1.5, 0.0, 0.0]),
        })
        .unwrap_err();
    assert_eq!(refused, EditError::InvalidColor);
    assert_eq!(doc.scene.objects[1].color, Some([0.8, 0.2, 0.1]));
    doc.undo().unwrap();
    assert_eq!(doc.scene.unit, None);
    doc.undo().unwrap();
    assert_eq!(doc.scene, before.scene);
    // Opening a STEP model replaces the objects and the unit in one step; Undo brings back both.
    let bytes = std::fs::read(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/reference/occ/step/assembly.step"
    ))
    .unwrap();
    let project = knotwork::io::step::read_project(&bytes, &mut |_, _| true).unwrap();
    doc.execute(&Command::ReplaceScene {
        scene: project.scene.clone(),
        label: "open assembly.step".into(),
        name: "assembly.step".into(),
    })
    .unwrap();
    assert_eq!(doc.scene, project.scene);
    assert_eq!(doc.history.document_name(), Some("assembly.step"));
    assert_eq!(doc.scene.unit, Some(LengthUnit::Millimetre));
    assert!(doc.scene.objects.iter().all(|o| o.color.is_some()));
    doc.undo().unwrap();
    assert_eq!(doc.scene, before.scene);
    assert_eq!(
        doc.history.document_name(),
        None,
        "the document before has no open step"
    );
    doc.redo().unwrap();
    assert_eq!(doc.scene.unit, Some(LengthUnit::Millimetre));
    assert_eq!(doc.history.document_name(), Some("assembly.step"));
}
