//! Project files: the scene (every kind of object, names, visibility, tessellation, view)
//! round-trips bit for bit, version 1 files open, and a corpus of broken files
//! (`tests/bad-projects/`) is refused with a message naming the problem while the open
//! document and its undo history stay exactly as they were.

use glam::DVec3;
use knotwork::doc::{Command, Document};
use knotwork::io::project::{self, MAX_FILE_BYTES, Project};
use knotwork::kernel::Direction;
use knotwork::scene::Scene;
use knotwork::view::ViewSettings;
use knotwork::view::{OrbitCamera, Overlays, ShadingMode};

/// Each broken file, the JSON path its error must name and words the message must contain.
const CORPUS: &[(&str, &str, &str)] = &[
    ("empty", "", "not valid JSON"),
    ("not-json", "", "not valid JSON"),
    ("truncated", "", "EOF while parsing"),
    ("deep-nesting", "", "recursion limit exceeded"),
    ("nan-literal", "", "not valid JSON"),
    ("infinite-coordinate", "", "number out of range"),
    ("not-knotwork", "format", "expected \"knotwork\""),
    ("future-version", "version", "version 99 is not supported"),
    ("objects-not-array", "objects", "expected an array"),
    ("wrong-type-degree", "objects[0].degree[0]", "invalid type"),
    (
        "decreasing-knots",
        "objects[0].knots[0][3]",
        "knots must not decrease",
    ),
    (
        "zero-weight",
        "objects[0].points[0][1]",
        "weight 0 must be finite and > 0",
    ),
    (
        "negative-weight",
        "objects[0].points[1]",
        "weight -2 must be finite and > 0",
    ),
    (
        "degree-40",
        "objects[0].knots[0]",
        "degree 40 is outside 1..=32",
    ),
    ("absurd-segments", "objects[0].segments", "1..=1024"),
    (
        "unknown-type",
        "objects[0].type",
        "unknown object type \"subd_cage\"",
    ),
    (
        "ragged-net",
        "objects[0].points[1]",
        "the net must be rectangular",
    ),
    (
        "patch-index-out-of-range",
        "objects[0].patches[0].indices[3]",
        "index 99",
    ),
    ("curve-zero-weight", "objects[0].points[1]", "weight"),
    (
        "polysurface-negative-weight",
        "objects[0].faces[0].points[1][1]",
        "weight",
    ),
    ("polysurface-no-faces", "objects[0]", "1 to 10000 faces"),
    (
        "trim-curve-object",
        "objects[0].type",
        "a trim curve is not a scene object",
    ),
    ("bad-view", "view", "finite and positive"),
    ("bad-tolerance", "view", "tolerance_px 0 is outside 0.1..=8"),
];

/// A document with some history: a moved point, an inserted knot, a rename.
fn edited_document() -> Document {
    let mut doc = Document::new(Scene::demo().unwrap());
    for cmd in [
        Command::MovePoints {
            object: 1,
            moves: vec![(3, DVec3::new(1.0, 2.0, 3.0))],
        },
        Command::InsertKnot {
            object: 3,
            direction: Direction::V,
            value: 0.3,
        },
        Command::Rename {
            object: 0,
            name: "Teapot".into(),
        },
    ] {
        doc.execute(&cmd).unwrap();
    }
    doc.undo().unwrap();
    doc
}

#[test]
fn broken_files_are_refused_by_name_and_the_document_is_untouched() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/bad-projects");
    let mut found: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    found.sort();
    let mut listed: Vec<String> = CORPUS.iter().map(|(n, ..)| format!("{n}.json")).collect();
    listed.sort();
    assert_eq!(
        found, listed,
        "every file in tests/bad-projects has an expectation"
    );

    let mut doc = edited_document();
    let before = doc.clone();
    for (name, path, words) in CORPUS {
        let text = std::fs::read_to_string(dir.join(format!("{name}.json"))).unwrap();
        let e = doc.open(&text).unwrap_err();
        assert_eq!(e.path, *path, "{name}: {e}");
        assert!(e.message.contains(words), "{name}: {e:?} lacks {words:?}");
        assert_eq!(doc, before, "{name} changed the document");
    }
    // The history still works after all those refusals.
    doc.redo().unwrap();
    assert_eq!(doc.scene.objects[0].name, "Teapot");
}

#[test]
fn oversized_files_are_refused_before_parsing() {
    let mut text = String::from("{\"format\": \"knotwork\", \"version\": 2, \"objects\": []}");
    text.push_str(&" ".repeat(MAX_FILE_BYTES));
    let e = project::read(&text).unwrap_err();
    assert!(e.message.contains("opens projects up to 64 MiB"), "{e}");
}

#[test]
fn the_demo_scene_round_trips_bit_for_bit_with_its_view() {
    let mut doc = edited_document();
    doc.execute(&Command::SetVisible {
        object: 2,
        visible: false,
    })
    .unwrap();
    doc.execute(&Command::SetWeight {
        object: 3,
        points: vec![4, 5],
        weight: 0.3,
    })
    .unwrap();
    let view = ViewSettings {
        camera: OrbitCamera {
            target: glam::Vec3::new(1.0, 2.0, 0.5),
            distance: 12.5,
            yaw: -0.9,
            pitch: 0.45,
            ..Default::default()
        },
        shading: ShadingMode::Gaussian,
        range: Some((-0.125, 0.375)),
        quality: 0.5,
        adaptive: false,
        tolerance_px: 1.5,
        overlays: Overlays {
            surface: true,
            net: false,
            points: true,
            ..Default::default()
        },
        analysis: knotwork::view::AnalysisSettings {
            zebra_pairs: 12,
            zebra_angle: 30.0,
            zebra_frame: knotwork::view::StripeFrame::World,
            isophote_direction: [1.0, 0.0, 1.0],
            draft_threshold: 5.0,
            ..Default::default()
        },
    };
    let text = doc.save(Some(view));
    let mut opened = Document::default();
    assert_eq!(opened.open(&text).unwrap(), Some(view));
    assert_eq!(opened.scene, doc.scene);
    assert!(!opened.scene.objects[2].visible);
    assert_eq!(
        opened.history.undo_depth(),
        0,
        "a new document starts a new history"
    );
    assert_eq!(opened.save(None), doc.save(None));
}

#[test]
fn version_1_files_open_as_scenes() {
    let surface = knotwork::kernel::construct::sphere(DVec3::ZERO, 2.0).unwrap();
    let text = knotwork::scene::json::write(&[knotwork::scene::json::NamedGeometry {
        name: Some("ball".into()),
        geometry: knotwork::scene::json::Geometry::Surface(surface),
    }]);
    let Project { scene, view } = project::read(&text).unwrap();
    assert_eq!(view, None);
    assert_eq!(scene.objects.len(), 1);
    assert_eq!(scene.objects[0].name, "ball");
    let p = scene.objects[0]
        .geometry
        .nurbs_surface()
        .unwrap()
        .point_at(0.3, 0.7)
        .unwrap();
    assert!((p.length() - 2.0).abs() < 1e-12);
}

#[test]
fn a_saved_view_reads_back_and_a_bad_one_is_refused_by_name() {
    let with_view = |view: &str| {
        format!(r#"{{"format": "knotwork", "version": 2, "objects": [], "view": {view}}}"#)
    };
    // A view written before the range and overlays were saved: the automatic range, all shown.
    let old = with_view(
        r#"{"target": [0, 0, 1], "distance": 5, "yaw": 0.5, "pitch": 0.25, "shading": "mean", "quality": 2}"#,
    );
    let view = project::read(&old).unwrap().view.unwrap();
    assert_eq!(view.shading, ShadingMode::Mean);
    assert_eq!(view.range, None);
    assert_eq!(view.overlays, Overlays::default());
    assert_eq!(view.quality, 2.0);
    assert_eq!(view.camera.distance, 5.0);
    let base = r#""target": [0, 0, 0], "distance": 5, "yaw": 0, "pitch": 0"#;
    for (fields, expected) in [
        (r#""shading": "rainbow", "quality": 1"#, "unknown shading"),
        (r#""shading": "plain", "quality": 100"#, "quality 100"),
        (
            r#""shading": "plain", "quality": 1, "range": [1, -1]"#,
            "increasing",
        ),
        (
            r#""shading": "plain", "quality": 1, "overlays": {"halo": true}"#,
            "halo",
        ),
        (
            r#""shading": "zebra", "quality": 1, "analysis": {"zebra_pairs": 0}"#,
            "zebra_pairs",
        ),
        (
            r#""shading": "draft", "quality": 1, "analysis": {"pull_direction": [0, 0, 0]}"#,
            "pull_direction",
        ),
        (
            r#""shading": "plain", "quality": 1, "analysis": {"stripes": 3}"#,
            "stripes",
        ),
        (r#""shading": "plain", "quality": 1, "colour": 3"#, "colour"),
    ] {
        let text = with_view(&format!("{{{base}, {fields}}}"));
        let error = project::read(&text).unwrap_err();
        assert!(error.path.starts_with("view"), "{fields}: {error}");
        assert!(error.to_string().contains(expected), "{fields}: {error}");
    }
}

#[test]
fn a_length_unit_and_object_colours_are_saved_and_bad_ones_refused_by_name() {
    use knotwork::scene::LengthUnit;
    let text = r#"{"format": "knotwork", "version": 2, "unit": "in", "objects": [
        {"type": "polygon_mesh", "name": "quad", "color": [1, 0.5, 0],
         "points": [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], "faces": [[0, 1, 2, 3]]}]}"#;
    let project = project::read(text).unwrap();
    assert_eq!(project.scene.unit, Some(LengthUnit::Inch));
    assert_eq!(project.scene.objects[0].color, Some([1.0, 0.5, 0.0]));
    let again = project::read(&project::write(&project)).unwrap();
    assert_eq!(again, project, "unit and colour survive a save");
    // Without a unit the project is unitless, and saving writes no unit.
    let unitless = text.replace(r#""unit": "in", "#, "");
    let project = project::read(&unitless).unwrap();
    assert_eq!(project.scene.unit, None);
    assert!(!project::write(&project).contains("\"unit\""));
    for (from, to, path, words) in [
        (r#""unit": "in""#, r#""unit": "parsec""#, "unit", "\"mm\""),
        (r#""unit": "in""#, r#""unit": 25.4"#, "unit", "25.4"),
        ("[1, 0.5, 0]", "[1, 0.5]", "objects[0].color", "[r, g, b]"),
        (
            "[1, 0.5, 0]",
            "[1, 0.5, 2]",
            "objects[0].color",
            "from 0 to 1",
        ),
        ("[1, 0.5, 0]", "\"red\"", "objects[0].color", "red"),
    ] {
        let e = project::read(&text.replace(from, to)).unwrap_err();
        assert_eq!(e.path, path, "{to}: {e}");
        assert!(e.to_string().contains(words), "{to}: {e}");
    }
    // The metres in each unit, from their definitions (the inch is 25.4 mm exactly).
    for (unit, metres) in [
        (LengthUnit::Millimetre, 0.001),
        (LengthUnit::Centimetre, 0.01),
        (LengthUnit::Metre, 1.0),
        (LengthUnit::Inch, 0.0254),
        (LengthUnit::Foot, 12.0 * 0.0254),
    ] {
        assert!((unit.metres() - metres).abs() < 1e-15, "{unit:?}");
        assert_eq!(LengthUnit::from_symbol(unit.symbol()), Some(unit));
    }
}
