//! Edge features (fillets, chamfers, shells) against OpenCASCADE on random solids in general
//! position (`tests/reference/features/make_fixtures.py`), and through the command line.

use std::path::PathBuf;

use glam::DVec3;
use knotwork::kernel::features::{
    EdgeFeature, EdgePick, FeatureResult, round_edges, round_edges_varying, shell,
};
use knotwork::kernel::mass::mass_properties;

fn fixtures() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/reference/features")
}

fn points(row: &serde_json::Value, key: &str) -> Vec<DVec3> {
    row[key]
        .as_array()
        .expect("a list of points")
        .iter()
        .map(|p| {
            let c: Vec<f64> = p
                .as_array()
                .expect("a point")
                .iter()
                .map(|x| x.as_f64().expect("a coordinate"))
                .collect();
            DVec3::new(c[0], c[1], c[2])
        })
        .collect()
}

/// What the command line does with one solid and one fixture row.
fn run(
    faces: &[knotwork::kernel::trim::TrimmedSurface],
    row: &serde_json::Value,
    tolerance: f64,
) -> Result<FeatureResult, String> {
    let value = row["value"].as_f64().expect("a value");
    let near = points(row, "near");
    let pick = if near.is_empty() {
        EdgePick::All
    } else {
        EdgePick::Near(near)
    };
    match row["feature"].as_str().expect("a feature") {
        "fillet" => round_edges(
            faces,
            &pick,
            EdgeFeature::Fillet { radius: value },
            tolerance,
        ),
        "chamfer" => round_edges(
            faces,
            &pick,
            EdgeFeature::Chamfer {
                distance: value,
                other: value,
            },
            tolerance,
        ),
        _ => shell(faces, value, &points(row, "open"), tolerance),
    }
    .map_err(|e| e.to_string())
}

#[test]
fn random_solids_take_opencascades_fillets_chamfers_and_shells() {
    compare_with_opencascade("inputs.step", "occt-features.jsonl", &[], run);
}

/// Fillets whose radius runs linearly from one end of an edge to the other
/// (`tests/reference/features/make_varying.py`): the radii set at the edges' vertices.
#[test]
fn random_prisms_take_opencascades_fillets_of_varying_radius() {
    // Beyond an edge's end knotwork's radius keeps its rate (the fillet stays one smooth
    // cone) where OpenCASCADE eases it off; where the end face meets the edge at a shallow
    // angle, that contact can leave the face before it reaches the end face, and knotwork
    // refuses (one case of 24).
    compare_with_opencascade(
        "varying.step",
        "occt-varying.jsonl",
        &["runs past the end of the edge"],
        |faces, row, tolerance| {
            let radii = row["radii"]
                .as_array()
                .expect("radii")
                .iter()
                .map(|p| {
                    let c: Vec<f64> = p
                        .as_array()
                        .expect("x, y, z, r")
                        .iter()
                        .map(|x| x.as_f64().expect("a number"))
                        .collect();
                    (DVec3::new(c[0], c[1], c[2]), c[3])
                })
                .collect::<Vec<_>>();
            round_edges_varying(
                faces,
                &EdgePick::Near(points(row, "near")),
                EdgeFeature::Fillet { radius: 1.0 },
                &radii,
                tolerance,
            )
            .map_err(|e| e.to_string())
        },
    );
}

/// Each solid of `step` made by `run` with its row of `jsonl` and its volume and area
/// compared with OpenCASCADE's to 1e-4; a refusal fails unless its reason holds one of
/// `excused`, and at most one case in ten may be excused.
fn compare_with_opencascade(
    step: &str,
    jsonl: &str,
    excused: &[&str],
    run: impl Fn(
        &[knotwork::kernel::trim::TrimmedSurface],
        &serde_json::Value,
        f64,
    ) -> Result<FeatureResult, String>,
) {
    let dir = fixtures();
    let bytes = std::fs::read(dir.join(step)).expect("the fixture");
    let bodies = knotwork::io::step::read::read(&bytes, &mut |_, _| true)
        .expect("a STEP model")
        .bodies;
    let rows: Vec<serde_json::Value> = std::fs::read_to_string(dir.join(jsonl))
        .expect("references")
        .lines()
        .map(|l| serde_json::from_str(l).expect("a JSON row"))
        .collect();
    assert_eq!(bodies.len(), rows.len());
    let mut failures = Vec::new();
    let mut checked = 0;
    let mut worst: f64 = 0.0;
    let mut refused = Vec::new();
    for (body, row) in bodies.iter().zip(&rows) {
        let what = format!(
            "case {} ({} {} {:.4}, {} picked)",
            row["case"],
            row["kind"],
            row["feature"].as_str().unwrap_or("fillet"),
            row["value"].as_f64().unwrap_or(0.0),
            points(row, "near").len() + row["open"].as_array().map_or(0, Vec::len)
        );
        let (lo, hi) = body.faces.iter().map(|f| f.surface().bounds()).fold(
            (DVec3::INFINITY, DVec3::NEG_INFINITY),
            |(lo, hi), (p, q)| (lo.min(p), hi.max(q)),
        );
        let tolerance = 1e-6 * lo.distance(hi);
        let result = match run(&body.faces, row, tolerance) {
            Ok(r) => r,
            Err(e) if excused.iter().any(|x| e.contains(x)) => {
                refused.push(format!("{what}: refused: {e}"));
                continue;
            }
            Err(e) => {
                failures.push(format!("{what}: refused: {e}"));
                continue;
            }
        };
        let mass = mass_properties(&result.faces, &[]).expect("mass properties");
        let (volume, area) = (
            row["volume"].as_f64().unwrap(),
            row["area"].as_f64().unwrap(),
        );
        let dv = (mass.volume - volume).abs() / volume;
        let da = (mass.area - area).abs() / area;
        worst = worst.max(dv).max(da);
        if dv > 1e-4 || da > 1e-4 {
            failures.push(format!(
                "{what}: volume {} against {volume} ({dv:.2e}), area {} against {area} ({da:.2e})",
                mass.volume, mass.area
            ));
        }
        checked += 1;
    }
    eprintln!(
        "{checked} of {} cases of {step} made and compared, worst relative difference {worst:.2e}",
        rows.len()
    );
    for r in &refused {
        eprintln!("excused: {r}");
    }
    assert!(refused.len() * 10 <= rows.len(), "too many refused");
    assert!(
        failures.is_empty(),
        "{} failures:\n{}",
        failures.len(),
        failures.join("\n")
    );
}

/// The command line's contract: `fillet-edges`, `chamfer-edges` and `shell` write a STEP
/// file whose solid OpenCASCADE's volume matches (read back by knotwork), and exit 1 with
/// the reason where the feature cannot be built.
#[test]
fn the_command_line_writes_the_feature_or_exits_1_with_the_reason() {
    let dir = crate::common::scratch_dir("features-cli");
    // A 4 × 3 × 2 box written as STEP.
    let box_faces =
        knotwork::kernel::solids::block(DVec3::new(1.0, -2.0, 0.5), DVec3::new(4.0, 3.0, 2.0))
            .expect("a block");
    let input = dir.join("box.step");
    let topology = knotwork::kernel::join::find_topology(&box_faces, 1e-9).expect("joined");
    let mut scene = knotwork::scene::Scene::default();
    scene.objects.clear();
    scene.objects.push(knotwork::scene::SceneObject::new(
        "box",
        knotwork::scene::ObjectGeometry::new(
            knotwork::scene::polysurface::Polysurface::with_topology(box_faces, 1e-8, topology)
                .expect("a polysurface"),
        ),
    ));
    let written = knotwork::io::step::export_scene(&scene, "box", 1e-9).expect("STEP");
    std::fs::write(&input, written.text).expect("written");
    let run = |args: &[&str]| {
        std::process::Command::new(env!("CARGO_BIN_EXE_knotwork"))
            .args(args)
            .output()
            .expect("the binary runs")
    };
    let volume_of = |path: &std::path::Path| -> f64 {
        let bytes = std::fs::read(path).expect("the output");
        let bodies = knotwork::io::step::read::read(&bytes, &mut |_, _| true)
            .expect("STEP")
            .bodies;
        bodies
            .iter()
            .map(|b| knotwork::kernel::mass::signed_volume(&b.faces).expect("a volume"))
            .sum()
    };
    let out = dir.join("out.step");
    let (i, o) = (input.to_str().unwrap(), out.to_str().unwrap());
    let r: f64 = 0.3;
    let pi = std::f64::consts::PI;
    let rounded = 3.4 * 2.4 * 1.4
        + 2.0 * r * (3.4 * 2.4 + 2.4 * 1.4 + 1.4 * 3.4)
        + pi * r * r * (3.4 + 2.4 + 1.4)
        + 4.0 * pi * r.powi(3) / 3.0;
    let cases: [(&[&str], f64); 7] = [
        (&["fillet-edges", i, "-o", o, "--radius", "0.3"], rounded),
        // The same edge from radius 0.1 at x = 1 to 0.4 at x = 5: each section square to the
        // edge is the fillet of the radius there, so it takes (1 − π/4) ∫ r² dx.
        (
            &[
                "fillet-edges",
                i,
                "-o",
                o,
                "--radius",
                "0.3",
                "--near",
                "3,1,2.5",
                "--radius-at",
                "1,1,2.5,0.1",
                "--radius-at",
                "5.2,1.1,2.5,0.4",
            ],
            24.0 - (1.0 - pi / 4.0) * 4.0 * (0.01 + 0.04 + 0.16) / 3.0,
        ),
        // The edge along x at y = 1, z = 2.5 (picked by its middle); then with the edge along
        // y at x = 5, the two chamfers meet in a mitre: the two corner prisms less their
        // common part at the corner, D³/3.
        (
            &[
                "fillet-edges",
                i,
                "-o",
                o,
                "--radius",
                "0.3",
                "--near",
                "3,1,2.5",
            ],
            24.0 - (1.0 - pi / 4.0) * 0.09 * 4.0,
        ),
        (
            &[
                "chamfer-edges",
                i,
                "-o",
                o,
                "--distance",
                "0.2",
                "--near",
                "3,1,2.5",
                "--near",
                "5,-0.5,2.5",
            ],
            24.0 - 0.02 * 7.0 + 0.008 / 3.0,
        ),
        (
            &[
                "shell",
                i,
                "-o",
                o,
                "--thickness",
                "-0.25",
                "--open",
                "3,-0.5,2.5",
            ],
            24.0 - 3.5 * 2.5 * 1.75,
        ),
        // The top up by 0.5; the faces x = 1 and x = 5 drafted 5° about z = 0.5.
        (
            &[
                "offset-face",
                i,
                "-o",
                o,
                "--distance",
                "0.5",
                "--face",
                "3,-0.5,2.5",
            ],
            4.0 * 3.0 * 2.5,
        ),
        (
            &[
                "draft-face",
                i,
                "-o",
                o,
                "--angle",
                "5",
                "--face",
                "1,0,1",
                "--face",
                "5,0,1",
                "--neutral",
                "0,0,0.5",
            ],
            3.0 * 2.0 * (4.0 - 2.0 * 5f64.to_radians().tan()),
        ),
    ];
    for (args, want) in cases {
        let output = run(args);
        assert!(
            output.status.success(),
            "{args:?}: {}",
            String::from_utf8_lossy(&output.stderr)
        );
        let json: serde_json::Value = serde_json::from_slice(&output.stdout).expect("JSON");
        let printed = json["volume"].as_f64().expect("a volume");
        let read = volume_of(&out);
        assert!(
            (printed - want).abs() < 1e-6 * want,
            "{args:?}: {printed} against {want}"
        );
        assert!(
            (read - printed).abs() < 1e-6 * printed,
            "{args:?}: read back {read}, printed {printed}"
        );
    }
    // Too large a radius, a bad number, a missing file: exit 1 with the reason, nothing written.
    std::fs::remove_file(&out).ok();
    for (args, says) in [
        (
            &["fillet-edges", i, "-o", o, "--radius", "1.5"][..],
            "too large",
        ),
        (
            &["chamfer-edges", i, "-o", o, "--distance", "-1"][..],
            "above 0",
        ),
        (&["shell", i, "-o", o, "--thickness", "-1.2"][..], "thicker"),
        (
            &[
                "fillet-edges",
                i,
                "-o",
                o,
                "--radius",
                "0.1",
                "--near",
                "1,2",
            ][..],
            "X,Y,Z",
        ),
        (
            &["shell", "no-such-file.step", "-o", o, "--thickness", "0.1"][..],
            "no-such-file",
        ),
        (
            &[
                "fillet-edges",
                i,
                "-o",
                o,
                "--radius",
                "0.1",
                "--near",
                "3,1,2.5",
                "--radius-at",
                "5,1,2.5,2.5",
            ][..],
            "too large",
        ),
        (
            &[
                "fillet-edges",
                i,
                "-o",
                o,
                "--radius",
                "0.1",
                "--radius-at",
                "5,1,2.5",
            ][..],
            "X,Y,Z,R",
        ),
    ] {
        let output = run(args);
        assert_eq!(output.status.code(), Some(1), "{args:?}");
        let err = String::from_utf8_lossy(&output.stderr);
        assert!(err.contains(says), "{args:?}: {err}");
        assert!(!out.exists(), "{args:?} wrote a file");
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// `fillet-edges` on a file with a box and a plate with a round hole: a point near the hole's
/// rim goes to the plate (its edges are found on any body, curved or not) and rounds the rim
/// to a torus, whose volume Pappus gives; the box is written unchanged.
#[test]
fn the_command_line_rounds_a_holes_rim_on_the_body_nearest_the_point() {
    use knotwork::kernel::boolean::{BooleanOp, boolean};
    use knotwork::kernel::solids::{block, capped_cylinder};
    let dir = crate::common::scratch_dir("features-rims");
    let (hole, r) = (0.5_f64, 0.2_f64);
    let box_faces = block(DVec3::ZERO, DVec3::new(2.0, 2.0, 2.0)).expect("a block");
    let plate = boolean(
        BooleanOp::Difference,
        &block(DVec3::new(10.0, 0.0, 0.0), DVec3::new(4.0, 3.0, 1.0)).expect("a block"),
        &capped_cylinder(DVec3::new(12.0, 1.5, -0.5), DVec3::Z * 2.0, hole).expect("a pin"),
        1e-9,
    )
    .expect("a plate")
    .faces();
    let mut scene = knotwork::scene::Scene::default();
    scene.objects.clear();
    for (name, faces) in [("box", box_faces), ("plate", plate)] {
        let topology = knotwork::kernel::join::find_topology(&faces, 1e-7).expect("joined");
        scene.objects.push(knotwork::scene::SceneObject::new(
            name,
            knotwork::scene::ObjectGeometry::new(
                knotwork::scene::polysurface::Polysurface::with_topology(faces, 1e-7, topology)
                    .expect("a polysurface"),
            ),
        ));
    }
    let input = dir.join("two.step");
    let written = knotwork::io::step::export_scene(&scene, "two", 1e-9).expect("STEP");
    std::fs::write(&input, written.text).expect("written");
    let out = dir.join("out.step");
    let output = std::process::Command::new(env!("CARGO_BIN_EXE_knotwork"))
        .args([
            "fillet-edges",
            input.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
            "--radius",
            "0.2",
            "--near",
            "12.3,1.9,1.05",
        ])
        .output()
        .expect("the binary runs");
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let json: serde_json::Value = serde_json::from_slice(&output.stdout).expect("JSON");
    assert_eq!(json["picked"].as_u64(), Some(1), "{json}");
    let pi = std::f64::consts::PI;
    // The corner region r²(1 − π/4), its centroid r(10 − 3π)/(3(4 − π)) out from the rim.
    let torus =
        2.0 * pi * (hole + r * (10.0 - 3.0 * pi) / (3.0 * (4.0 - pi))) * r * r * (1.0 - pi / 4.0);
    let want = 8.0 + 12.0 - pi * hole * hole - torus;
    let bytes = std::fs::read(&out).expect("the output");
    let bodies = knotwork::io::step::read::read(&bytes, &mut |_, _| true)
        .expect("STEP")
        .bodies;
    assert_eq!(bodies.len(), 2);
    let read: f64 = bodies
        .iter()
        .map(|b| knotwork::kernel::mass::signed_volume(&b.faces).expect("a volume"))
        .sum();
    assert!(
        (read - want).abs() < 1e-6 * want,
        "read {read}, want {want}"
    );
    std::fs::remove_dir_all(&dir).ok();
}

mod in_the_document {
    use glam::{DAffine3, DVec3};
    use knotwork::doc::{Command, Document};
    use knotwork::ops::features::{FilletEdges, Shell};
    use knotwork::ops::transform::Transform;
    use knotwork::scene::operation::Operation;
    use knotwork::scene::{ObjectGeometry, Scene, SceneObject};

    use crate::common::box_of_planes;

    /// A document holding the 2 × 1 × 1.5 box "A".
    fn box_document() -> Document {
        let mut scene = Scene::default();
        scene.objects.clear();
        scene.objects.push(SceneObject::new(
            "A",
            ObjectGeometry::new(box_of_planes(&DAffine3::IDENTITY)),
        ));
        Document::new(scene)
    }

    fn volume(object: &SceneObject) -> f64 {
        let faces = object.body().expect("a body").faces;
        knotwork::kernel::mass::signed_volume(&faces).expect("a volume")
    }

    /// The rounded 2 × 1 × 1.5 box at radius r.
    fn rounded(r: f64) -> f64 {
        let pi = std::f64::consts::PI;
        let (x, y, z) = (2.0 - 2.0 * r, 1.0 - 2.0 * r, 1.5 - 2.0 * r);
        x * y * z
            + 2.0 * r * (x * y + y * z + z * x)
            + pi * r * r * (x + y + z)
            + 4.0 * pi * r.powi(3) / 3.0
    }

    #[test]
    fn a_fillet_with_history_follows_its_body_edits_in_place_and_undoes() {
        let mut doc = box_document();
        let original = doc.scene.clone();
        let fillet = FilletEdges {
            object: 0.into(),
            radius: 0.1,
            near: Vec::new(),
            radius_at: Vec::new(),
            tolerance: 1e-6,
        };
        doc.execute(&Command::Apply {
            operation: Operation::new(fillet.clone()),
            keep_history: true,
        })
        .expect("the fillet");
        assert_eq!(doc.scene.objects.len(), 2);
        assert!(!doc.scene.objects[0].visible);
        assert_eq!(doc.scene.objects[1].name, "A fillet");
        assert!((volume(&doc.scene.objects[1]) - rounded(0.1)).abs() < 1e-9);
        // Moving the body moves the fillet.
        doc.execute(&Command::operation(Transform::new(
            0,
            &DAffine3::from_translation(DVec3::X),
        )))
        .expect("the move");
        let (lo, _) = doc.scene.objects[1]
            .body()
            .unwrap()
            .faces
            .iter()
            .map(|f| f.surface().bounds())
            .fold(
                (DVec3::INFINITY, DVec3::NEG_INFINITY),
                |(lo, hi), (a, b)| (lo.min(a), hi.max(b)),
            );
        assert!((lo.x - 1.0).abs() < 1e-9, "{lo}");
        // The radius edited in place: one undo step, the history kept.
        let depth = doc.history.undo_depth();
        let bigger = FilletEdges {
            radius: 0.2,
            ..fillet
        };
        let recipe = doc.scene.objects[1].recipe.clone().expect("history");
        let mut edited = recipe
            .operation
            .params::<FilletEdges>()
            .expect("a fillet")
            .clone();
        edited.radius = bigger.radius;
        doc.execute(&Command::EditRecipe {
            object: 1,
            operation: Operation::new(edited),
        })
        .expect("the edit");
        assert_eq!(doc.history.undo_depth(), depth + 1);
        assert!(doc.scene.objects[1].recipe.is_some());
        assert!((volume(&doc.scene.objects[1]) - rounded(0.2)).abs() < 1e-9);
        // Too large a radius is refused, changing nothing.
        let before = doc.scene.clone();
        let mut huge = recipe.operation.params::<FilletEdges>().unwrap().clone();
        huge.radius = 0.6;
        let e = doc
            .execute(&Command::EditRecipe {
                object: 1,
                operation: Operation::new(huge),
            })
            .unwrap_err();
        assert!(e.to_string().contains("too large"), "{e}");
        assert_eq!(doc.scene, before);
        // A shell is refused on an object that is not a closed body.
        let e = doc
            .execute(&Command::operation(Shell {
                object: 0.into(),
                thickness: f64::NAN,
                open: Vec::new(),
                tolerance: 1e-6,
            }))
            .unwrap_err();
        assert!(e.to_string().contains("thickness"), "{e}");
        doc.undo().unwrap();
        doc.undo().unwrap();
        doc.undo().unwrap();
        assert_eq!(doc.scene, original, "undo takes every step back");
    }

    /// The page's fillet with radii at an edge's ends: the box's edge along x at y = z = 0
    /// from 0.1 at x = 0 to 0.3 at x = 2 takes (1 − π/4) ∫ r² dx; the end radius edited in
    /// place is one undo step, and a radius too large for the box is refused, changing
    /// nothing.
    #[test]
    fn a_fillet_of_varying_radius_edits_its_end_radii_in_place() {
        let mut doc = box_document();
        let operation = knotwork::ops::from_value(
            "$",
            serde_json::json!({"op": "fillet_edges", "object": 0, "radius": 0.1,
                "near": [[1.0, 0.0, 0.0]], "radius_at": [[2.0, 0.0, 0.0, 0.3]]}),
        )
        .expect("read");
        doc.execute(&Command::Apply {
            operation,
            keep_history: true,
        })
        .expect("the fillet");
        let taken = |ra: f64, rb: f64| {
            (1.0 - std::f64::consts::PI / 4.0) * 2.0 * (ra * ra + ra * rb + rb * rb) / 3.0
        };
        assert!((volume(&doc.scene.objects[1]) - (3.0 - taken(0.1, 0.3))).abs() < 1e-9);
        let recipe = doc.scene.objects[1].recipe.clone().expect("history");
        let mut edited = recipe
            .operation
            .params::<FilletEdges>()
            .expect("a fillet")
            .clone();
        edited.radius_at[0][3] = 0.5;
        let depth = doc.history.undo_depth();
        let before = doc.scene.clone();
        doc.execute(&Command::EditRecipe {
            object: 1,
            operation: Operation::new(edited.clone()),
        })
        .expect("the edit");
        assert_eq!(doc.history.undo_depth(), depth + 1);
        assert!((volume(&doc.scene.objects[1]) - (3.0 - taken(0.1, 0.5))).abs() < 1e-9);
        let edited_scene = doc.scene.clone();
        edited.radius_at[0][3] = 1.2;
        let e = doc
            .execute(&Command::EditRecipe {
                object: 1,
                operation: Operation::new(edited),
            })
            .unwrap_err();
        assert!(e.to_string().contains("too large"), "{e}");
        assert_eq!(doc.scene, edited_scene);
        doc.undo().unwrap();
        assert_eq!(doc.scene, before);
    }

    #[test]
    fn the_page_reads_each_feature_by_name() {
        for (value, name) in [
            (
                serde_json::json!({"op": "fillet_edges", "object": 0, "radius": 0.1}),
                "fillet_edges",
            ),
            (
                serde_json::json!({"op": "chamfer_edges", "object": 0, "distance": 0.1, "near": [[1.0, 0.0, 0.0]]}),
                "chamfer_edges",
            ),
            (
                serde_json::json!({"op": "shell", "object": 0, "thickness": -0.1, "open": [[1.0, 0.5, 1.5]]}),
                "shell",
            ),
        ] {
            let operation = knotwork::ops::from_value("$", value).expect("read");
            assert_eq!(operation.name(), name);
            let mut doc = box_document();
            doc.execute(&Command::Apply {
                operation,
                keep_history: false,
            })
            .expect("applied");
            assert!(doc.scene.objects[1].body().unwrap().closed());
        }
    }
}

/// A turned part from the CAx-IF round robin (another CAD system's STEP file: a cylinder
/// with a spherical cap, its edges on curved meridians): every sharp edge filleted and
/// chamfered at 0.2, against OpenCASCADE's `BRepFilletAPI_MakeFillet` and `MakeChamfer` on
/// the same file (`tests/reference/features/occ_real_part.py`).
#[test]
fn a_real_turned_part_takes_opencascades_fillet_and_chamfer() {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/reference/step-public/cax-if__s1_pe_214__foot_back_prt.stp");
    let bytes = std::fs::read(path).expect("the part");
    let bodies = knotwork::io::step::read::read(&bytes, &mut |_, _| true)
        .expect("a STEP model")
        .bodies;
    let faces = &bodies[0].faces;
    let (lo, hi) = faces.iter().map(|f| f.surface().bounds()).fold(
        (DVec3::INFINITY, DVec3::NEG_INFINITY),
        |(lo, hi), (p, q)| (lo.min(p), hi.max(q)),
    );
    let tolerance = 1e-6 * lo.distance(hi);
    for (feature, want) in [
        (EdgeFeature::Fillet { radius: 0.2 }, 2357.2641141337044),
        (
            EdgeFeature::Chamfer {
                distance: 0.2,
                other: 0.2,
            },
            2355.9012748780187,
        ),
    ] {
        let made = round_edges(faces, &EdgePick::All, feature, tolerance)
            .unwrap_or_else(|e| panic!("{feature:?}: {e}"));
        assert_eq!(made.picked, 2);
        let v = made.volume().expect("a volume");
        assert!(
            (v - want).abs() < 1e-8 * want,
            "{feature:?}: {v} against OpenCASCADE's {want}"
        );
    }
}
