//! Continuity numbers (G0 gap, G1 angle, G2 normal curvature difference) on constructed joins
//! whose answers are known in closed form, their independence of the parametrization, and the
//! `knotwork continuity` command.

use glam::DVec3;
use knotwork::kernel::continuity::{Continuity, SharedEdge, Side};
use knotwork::kernel::{Direction, NurbsSurface, construct, samples};
use knotwork::scene::continuity::{ContinuityOptions, analyse};
use knotwork::scene::{ObjectGeometry, Scene, SceneObject};

fn scene_of(surfaces: Vec<NurbsSurface>) -> Scene {
    Scene {
        objects: surfaces
            .into_iter()
            .enumerate()
            .map(|(k, s)| SceneObject::new(format!("S{k}"), ObjectGeometry::new(s)))
            .collect(),
        unit: None,
    }
}

fn edges_of(scene: &Scene) -> Vec<SharedEdge> {
    analyse(scene, None, &ContinuityOptions::default()).edges
}

fn close(a: f64, b: f64, tolerance: f64) -> bool {
    (a - b).abs() <= tolerance
}

#[test]
fn two_planes_meeting_at_thirty_degrees() {
    let a = construct::plane(DVec3::ZERO, DVec3::X, DVec3::Y).unwrap();
    let angle = 30f64.to_radians();
    let b = construct::plane(
        DVec3::X,
        DVec3::new(angle.cos(), 0.0, angle.sin()),
        DVec3::Y,
    )
    .unwrap();
    let edges = edges_of(&scene_of(vec![a, b]));
    assert_eq!(edges.len(), 1, "{edges:#?}");
    let e = &edges[0];
    assert_eq!((e.a, e.b), ((0, Side::U1), (1, Side::U0)));
    assert!(e.max_gap.value < 1e-12, "{}", e.max_gap.value);
    assert!(
        close(e.max_angle_degrees.value, 30.0, 1e-9),
        "{}",
        e.max_angle_degrees.value
    );
    assert!(e.max_curvature_difference.value < 1e-12);
    assert_eq!(e.verdict, Continuity::G0);
    assert_eq!(e.samples.len(), 33);
}

/// A bicubic Bézier patch over x in [x0, x0 + 1], y in [0, 1] whose height is the polynomial
/// with Bernstein coefficients `z` in x (constant in y).
fn height_patch(x0: f64, z: [f64; 4]) -> NurbsSurface {
    let mut points = Vec::new();
    for (i, zi) in z.iter().enumerate() {
        for j in 0..4 {
            points.push(DVec3::new(x0 + i as f64 / 3.0, j as f64 / 3.0, *zi));
        }
    }
    construct::bspline_surface([3, 3], [4, 4], points).unwrap()
}

/// z = a x² on [−1, 0] and z = b x² on [0, 1]: joined C1 at x = 0, where the normal
/// curvatures across the edge are 2a and 2b (z'' / (1 + z'²)^{3/2} with z' = 0).
fn parabolas(a: f64, b: f64) -> (NurbsSurface, NurbsSurface) {
    // With t = x + 1 on the left, a (t − 1)² has Bernstein coefficients a (1, 1/3, 0, 0); on
    // the right b t² has b (0, 0, 1/3, 1).
    (
        height_patch(-1.0, [a, a / 3.0, 0.0, 0.0]),
        height_patch(0.0, [0.0, 0.0, b / 3.0, b]),
    )
}

#[test]
fn a_c1_join_with_a_known_curvature_jump() {
    let (a, b) = (0.5, 2.0);
    let (left, right) = parabolas(a, b);
    let edges = edges_of(&scene_of(vec![left, right]));
    assert_eq!(edges.len(), 1, "{edges:#?}");
    let e = &edges[0];
    assert!(e.max_gap.value < 1e-12);
    assert!(
        e.max_angle_degrees.value < 1e-6,
        "{}",
        e.max_angle_degrees.value
    );
    let jump = 2.0 * (b - a);
    assert!(
        close(e.max_curvature_difference.value, jump, 1e-9),
        "{} vs {jump}",
        e.max_curvature_difference.value
    );
    assert!(close(
        e.max_relative_curvature_difference.value,
        jump / (2.0 * b),
        1e-9
    ));
    assert_eq!(e.verdict, Continuity::G1);
    // Equal curvatures: G2.
    let (left, right) = parabolas(1.5, 1.5);
    let e = &edges_of(&scene_of(vec![left, right]))[0];
    assert!(e.max_curvature_difference.value < 1e-9);
    assert_eq!(e.verdict, Continuity::G2);
}

#[test]
fn numbers_do_not_change_when_a_surface_is_reparametrized() {
    let (left, right) = parabolas(-0.75, 1.25);
    let reference = edges_of(&scene_of(vec![left.clone(), right.clone()]))[0].clone();
    let variants = [
        ("reverse u", left.clone(), right.reverse(Direction::U)),
        ("reverse v", left.reverse(Direction::V), right.clone()),
        ("swap", left.swap_uv(), right.clone()),
        (
            "knots",
            left.insert_knot(Direction::U, 0.3, 1).unwrap(),
            right.insert_knot(Direction::V, 0.6, 2).unwrap(),
        ),
        (
            "elevate",
            left.elevate_degree(Direction::U, 1).unwrap(),
            right.clone(),
        ),
    ];
    for (what, l, r) in variants {
        let edges = edges_of(&scene_of(vec![l, r]));
        assert_eq!(edges.len(), 1, "{what}");
        let e = &edges[0];
        for (name, x, y) in [
            ("gap", e.max_gap.value, reference.max_gap.value),
            (
                "angle",
                e.max_angle_degrees.value,
                reference.max_angle_degrees.value,
            ),
            (
                "curvature",
                e.max_curvature_difference.value,
                reference.max_curvature_difference.value,
            ),
        ] {
            assert!(close(x, y, 1e-8), "{what}: {name} {x} vs {y}");
        }
        assert_eq!(e.verdict, reference.verdict, "{what}");
    }
}

#[test]
fn two_halves_of_a_torus_are_g2_everywhere() {
    let torus = construct::torus(DVec3::ZERO, DVec3::Z, 3.0, 1.0).unwrap();
    let [(u0, u1), _] = torus.domain();
    let (first, second) = torus.split(Direction::U, 0.5 * (u0 + u1)).unwrap();
    let edges = edges_of(&scene_of(vec![first, second]));
    // The two cuts between the halves, and each half's own seam along the tube.
    assert_eq!(edges.len(), 4, "{edges:#?}");
    for e in &edges {
        assert!(e.max_gap.value < 1e-12, "{e:?}");
        // Rounding in the rational derivatives: about 1e-8 radians.
        assert!(
            e.max_angle_degrees.value < 1e-5,
            "{}",
            e.max_angle_degrees.value
        );
        assert!(
            e.max_relative_curvature_difference.value < 1e-6,
            "{}",
            e.max_relative_curvature_difference.value
        );
        assert_eq!(e.verdict, Continuity::G2);
    }
}

#[test]
fn a_gap_of_known_size_is_measured_and_fails_g0() {
    let a = construct::plane(DVec3::ZERO, DVec3::X, DVec3::Y).unwrap();
    let b = construct::plane(DVec3::new(1.0, 0.0, 0.01), DVec3::X, DVec3::Y).unwrap();
    let edges = edges_of(&scene_of(vec![a, b]));
    assert_eq!(edges.len(), 1);
    let e = &edges[0];
    assert!(close(e.max_gap.value, 0.01, 1e-12), "{}", e.max_gap.value);
    assert!(e.max_angle_degrees.value < 1e-9);
    assert_eq!(e.verdict, Continuity::Open);
    // Within a looser tolerance (1 % of the size, 0.022 here) it passes.
    let loose = ContinuityOptions {
        gap: 1e-2,
        ..Default::default()
    };
    let a = construct::plane(DVec3::ZERO, DVec3::X, DVec3::Y).unwrap();
    let b = construct::plane(DVec3::new(1.0, 0.0, 0.01), DVec3::X, DVec3::Y).unwrap();
    let report = analyse(&scene_of(vec![a, b]), None, &loose);
    assert_eq!(report.edges[0].verdict, Continuity::G2);
}

#[test]
fn surfaces_apart_share_no_edge() {
    let a = construct::plane(DVec3::ZERO, DVec3::X, DVec3::Y).unwrap();
    let b = construct::plane(DVec3::new(1.5, 0.0, 0.0), DVec3::X, DVec3::Y).unwrap();
    assert!(edges_of(&scene_of(vec![a, b])).is_empty());
}

#[test]
fn the_teapot_patches_meet_without_gaps() {
    let teapot = samples::utah_teapot().unwrap();
    let scene = Scene {
        objects: vec![SceneObject::new("teapot", ObjectGeometry::new(teapot))],
        unit: None,
    };
    let report = analyse(&scene, None, &ContinuityOptions::default());
    eprintln!("{} shared edges", report.edges.len());
    assert!(report.edges.len() >= 40, "{}", report.edges.len());
    for e in &report.edges {
        assert!(e.max_gap.value < 1e-9, "{e:?}");
        assert_ne!(e.verdict, Continuity::Open);
    }
    // The JSON the CLI prints: one entry per edge, names and numbers.
    let json = report.to_json(&scene);
    let entries = json.as_array().unwrap();
    assert_eq!(entries.len(), report.edges.len());
    assert_eq!(entries[0]["objects"][0], "teapot");
    assert!(entries[0]["edge"]["a"]["patch"].is_u64());
    assert!(entries[0]["max_angle_degrees"].is_f64());
}

/// `scene` saved as a project named `name` and `knotwork continuity` run on it with `args`:
/// the project's path and the printed JSON.
fn continuity_cli(
    scene: Scene,
    name: &str,
    args: &[&str],
) -> (std::path::PathBuf, serde_json::Value) {
    let mut doc = knotwork::doc::Document::default();
    doc.scene = scene;
    let dir = crate::common::scratch_dir("continuity");
    let path = dir.join(format!("{name}.json"));
    std::fs::write(&path, doc.save(None)).unwrap();
    let mut all = vec![std::ffi::OsString::from("continuity"), path.clone().into()];
    all.extend(args.iter().map(std::ffi::OsString::from));
    (path, crate::common::knotwork_json(&all))
}

#[test]
fn the_cli_prints_one_entry_per_shared_edge() {
    let angle = 30f64.to_radians();
    let scene = scene_of(vec![
        construct::plane(DVec3::ZERO, DVec3::X, DVec3::Y).unwrap(),
        construct::plane(
            DVec3::X,
            DVec3::new(angle.cos(), 0.0, angle.sin()),
            DVec3::Y,
        )
        .unwrap(),
    ]);
    let (path, json) = continuity_cli(scene, "planes", &["--objects", "S0", "S1"]);
    let entries = json.as_array().unwrap();
    assert_eq!(entries.len(), 1);
    let e = &entries[0];
    assert_eq!(e["objects"], serde_json::json!(["S0", "S1"]));
    assert_eq!(e["verdict"], "G0");
    assert!((e["max_angle_degrees"].as_f64().unwrap() - 30.0).abs() < 1e-9);
    assert_eq!(e["samples"], 33);
    // A bad name and a bad tolerance are refused with a message.
    for args in [vec!["--objects", "nope"], vec!["--angle", "0"]] {
        let output = std::process::Command::new(env!("CARGO_BIN_EXE_knotwork"))
            .arg("continuity")
            .arg(&path)
            .args(args)
            .output()
            .unwrap();
        assert!(!output.status.success());
        assert!(String::from_utf8_lossy(&output.stderr).contains("knotwork continuity:"));
    }
}

/// The quadratic triangular patch of the graph z = f(x, y) (f linear here) over the triangle
/// with (x, y) corners `corners` at height `z0`.
fn flat_triangle(corners: [(f64, f64); 3], z0: f64, f: impl Fn(f64, f64) -> f64) -> SceneObject {
    use knotwork::kernel::triangle::{TriangleBezier, lattice_index};
    let at = |x: f64, y: f64| DVec3::new(x, y, z0 + f(x, y));
    let [u, v, w] = corners;
    let mid = |a: (f64, f64), b: (f64, f64)| at(0.5 * (a.0 + b.0), 0.5 * (a.1 + b.1));
    let mut points = vec![DVec3::ZERO; 6];
    points[lattice_index(2, 2, 0)] = at(u.0, u.1);
    points[lattice_index(2, 0, 2)] = at(v.0, v.1);
    points[lattice_index(2, 0, 0)] = at(w.0, w.1);
    points[lattice_index(2, 1, 1)] = mid(u, v);
    points[lattice_index(2, 1, 0)] = mid(u, w);
    points[lattice_index(2, 0, 1)] = mid(v, w);
    let patch = TriangleBezier::new(2, points).unwrap();
    SceneObject::new("triangle", ObjectGeometry::boxed(Box::new(patch)))
}

#[test]
fn triangles_and_displaced_and_deformed_pairs_are_measured_as_shown() {
    use knotwork::kernel::displace::{Displacement, Pattern};
    use knotwork::kernel::ffd::Lattice;
    let named = |mut o: SceneObject, name: &str| {
        o.name = name.into();
        o
    };
    let plane_at = |x0: f64, z: f64, name: &str| {
        let p = construct::plane(DVec3::new(x0, 0.0, z), DVec3::X, DVec3::Y).unwrap();
        SceneObject::new(name, ObjectGeometry::new(p))
    };
    // Two triangular patches either side of x = 0, the right one rising at slope 0.4.
    let slope = 0.4;
    let t0 = named(
        flat_triangle([(0.0, 0.0), (0.0, 1.0), (-1.0, 0.0)], 0.0, |_, _| 0.0),
        "T0",
    );
    let t1 = named(
        flat_triangle([(0.0, 1.0), (0.0, 0.0), (1.0, 0.0)], 0.0, |x, _| slope * x),
        "T1",
    );
    // Two flat squares meeting at x = 1, the left one displaced by waves (a sin(wu) sin(wv),
    // zero on its sides): across the edge its slope is a w sin(wv), the largest a w.
    let (a, f) = (0.05, 2.0);
    let mut d0 = plane_at(0.0, 10.0, "D0");
    d0.displacement = Some(Displacement::new(Pattern::Waves, a, f).unwrap());
    let d1 = plane_at(1.0, 10.0, "D1");
    // Two flat squares meeting at x = 1, the left one turned 25° about that edge by an
    // affine lattice (exact: a trilinear lattice of an affine image is that map).
    let theta = 25f64.to_radians();
    let mut l0 = plane_at(0.0, 20.0, "L0");
    let l1 = plane_at(1.0, 20.0, "L1");
    let pivot = DVec3::new(1.0, 0.0, 20.0);
    let turn = glam::DMat3::from_axis_angle(DVec3::Y, theta);
    let box_ = Lattice::around(
        DVec3::new(0.0, 0.0, 20.0),
        DVec3::new(1.0, 1.0, 20.0),
        [1, 1, 1],
    )
    .unwrap();
    let turned = box_
        .points()
        .iter()
        .map(|&p| pivot + turn * (p - pivot))
        .collect();
    l0.lattice = Some(Lattice::new(box_.origin(), box_.axes(), [1, 1, 1], turned).unwrap());
    let scene = Scene {
        objects: vec![t0, t1, d0, d1, l0, l1],
        unit: None,
    };
    // Through the project file and the command line, as a user would ask.
    let (_, json) = continuity_cli(scene.clone(), "shown", &[]);
    let entry = |a: &str, b: &str| {
        let pair = serde_json::json!([a, b]);
        let found: Vec<&serde_json::Value> = json
            .as_array()
            .unwrap()
            .iter()
            .filter(|e| e["objects"] == pair)
            .collect();
        assert_eq!(found.len(), 1, "{a}-{b}: {json:#}");
        found[0].clone()
    };
    let angle = |e: &serde_json::Value| e["max_angle_degrees"].as_f64().unwrap();
    let triangles = entry("T0", "T1");
    assert_eq!(triangles["verdict"], "G0");
    assert!(
        close(angle(&triangles), slope.atan().to_degrees(), 1e-9),
        "{triangles}"
    );
    assert!(triangles["max_gap"].as_f64().unwrap() < 1e-12);
    let displaced = entry("D0", "D1");
    let steepest = (a * std::f64::consts::TAU * f).atan().to_degrees();
    assert!(close(angle(&displaced), steepest, 1e-6), "{displaced}");
    assert!(displaced["max_gap"].as_f64().unwrap() < 1e-12);
    let deformed = entry("L0", "L1");
    assert!(close(angle(&deformed), 25.0, 1e-9), "{deformed}");
    assert!(deformed["max_gap"].as_f64().unwrap() < 1e-12);
    // Without the displacement and the lattice the same squares meet flat (G2).
    let mut scene = scene;
    scene.objects[2].displacement = None;
    scene.objects[4].lattice = None;
    let report = analyse(&scene, None, &ContinuityOptions::default());
    let flat = report
        .edges
        .iter()
        .filter(|e| [e.a.0, e.b.0].iter().all(|&k| report.faces[k].object >= 2))
        .collect::<Vec<_>>();
    assert_eq!(flat.len(), 2, "{flat:#?}");
    assert!(flat.iter().all(|e| e.verdict == Continuity::G2));
}

/// A Catmull-Clark sheet over a 5 × 5 grid of cage points: row i at x = 4 + i cos θ,
/// z = i sin θ (`turned`), or x = i (`!turned`), each row running along y = 0..4.
fn subdivision_sheet(name: &str, turned: Option<f64>) -> SceneObject {
    use knotwork::kernel::PolygonMesh;
    use knotwork::kernel::subdiv::{Options, SubdivisionSurface};
    let mut points = Vec::new();
    for i in 0..5 {
        for j in 0..5 {
            let (i, y) = (f64::from(i), f64::from(j));
            points.push(match turned {
                Some(theta) => DVec3::new(4.0 + i * theta.cos(), y, i * theta.sin()),
                None => DVec3::new(i, y, 0.0),
            });
        }
    }
    let at = |i: u32, j: u32| i * 5 + j;
    let faces: Vec<Vec<u32>> = (0..4)
        .flat_map(|i| {
            (0..4).map(move |j| vec![at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)])
        })
        .collect();
    let mesh = PolygonMesh::new(points, &faces).unwrap();
    let surface =
        SubdivisionSurface::new(mesh, Vec::new(), Vec::new(), Options::default(), 2).unwrap();
    SceneObject::new(
        name,
        ObjectGeometry::new(knotwork::scene::SubdivObject::from(surface)),
    )
}

#[test]
fn subdivision_surfaces_whose_limit_boundaries_meet_share_that_edge() {
    // The left sheet's last row and the right sheet's first row are the same points (x = 4), so
    // the limit boundaries (the cubic B-spline of that row) coincide; flat cages have flat
    // limits, so the angle across is the turn exactly.
    let theta = 35f64.to_radians();
    let scene = Scene {
        objects: vec![
            subdivision_sheet("left", None),
            subdivision_sheet("right", Some(theta)),
        ],
        unit: None,
    };
    // Each sheet's limit boundary is the cubic B-spline of its whole boundary loop, which turns
    // its corners in opposite directions for the two sheets: the boundaries coincide where the
    // corners are out of reach, on the middle cage faces' level-1 children (y from 1 to 3).
    let middle = |scene: &Scene| {
        let report = analyse(scene, None, &ContinuityOptions::default());
        let across: Vec<SharedEdge> = report
            .edges
            .iter()
            .filter(|e| report.faces[e.a.0].object != report.faces[e.b.0].object)
            .cloned()
            .collect();
        // The faces along x = 4: two children of each middle cage face and the non-corner
        // child of each corner face.
        assert_eq!(across.len(), 6, "{across:#?}");
        let inside = |e: &SharedEdge| {
            e.samples
                .iter()
                .all(|s| (1.0 - 1e-9..=3.0 + 1e-9).contains(&s.point.y))
        };
        across.into_iter().filter(inside).collect::<Vec<_>>()
    };
    let edges = middle(&scene);
    assert_eq!(edges.len(), 4);
    for e in &edges {
        assert!(e.max_gap.value < 1e-12, "{}", e.max_gap.value);
        assert!(
            close(e.max_angle_degrees.value, 35.0, 1e-9),
            "{}",
            e.max_angle_degrees.value
        );
        assert_eq!(e.verdict, Continuity::G0);
    }
    // Untilted, the two sheets continue each other there: G2.
    let flat = Scene {
        objects: vec![
            subdivision_sheet("left", None),
            subdivision_sheet("right", Some(0.0)),
        ],
        unit: None,
    };
    let edges = middle(&flat);
    assert_eq!(edges.len(), 4);
    assert!(
        edges.iter().all(|e| e.verdict == Continuity::G2),
        "{edges:#?}"
    );
}

/// In the sample scene the teapot stands among objects set metres apart, so the scene's size
/// is four times the teapot's. Its rim's top and bottom (0.10 apart), its lid's rings and a
/// patch's two sides were paired as "open" edges at the scene's matching distance ("Utah
/// teapot patch 3 v0 · Utah teapot patch 3 v1, open, 180°"). Boundaries match within a share of
/// their own objects' size: the teapot's edges in the scene are those of the teapot alone, and
/// a face meets itself only along a closed surface's seam.
#[test]
fn neighbouring_boundaries_of_one_object_are_not_an_edge_with_a_gap() {
    let scene = Scene::demo().unwrap();
    let teapot = scene
        .objects
        .iter()
        .position(|o| o.name.contains("teapot"))
        .expect("the sample scene has the teapot");
    let report = analyse(&scene, None, &ContinuityOptions::default());
    let within_teapot = report
        .edges
        .iter()
        .filter(|e| report.faces[e.a.0].object == teapot && report.faces[e.b.0].object == teapot)
        .count();
    let alone = Scene {
        objects: vec![scene.objects[teapot].clone()],
        unit: None,
    };
    let alone_edges = analyse(&alone, None, &ContinuityOptions::default()).edges;
    assert_eq!(within_teapot, alone_edges.len());
    assert!(alone_edges.iter().all(|e| e.verdict != Continuity::Open));
    for e in &report.edges {
        if e.a.0 == e.b.0 {
            assert!(e.max_gap.value < 1e-9, "a face paired with itself: {e:?}");
        }
        if report.faces[e.a.0].object == teapot || report.faces[e.b.0].object == teapot {
            assert_ne!(e.verdict, Continuity::Open, "{:?} {:?}", e.a, e.b);
        }
    }
    // Every edge left in the sample scene is a real one: none is open.
    let open: Vec<_> = report
        .edges
        .iter()
        .filter(|e| e.verdict == Continuity::Open)
        .map(|e| (e.a, e.b, e.max_gap.value))
        .collect();
    assert!(open.is_empty(), "{open:?}");
}
