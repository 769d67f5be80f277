//! The surface operations through the real binary and the document: `knotwork offset` against
//! OpenCASCADE's offset surface (tests/reference/occ/surface_ops.json, made by
//! make_surface_ops.py beside it) and against the closed forms of the sphere and the torus;
//! the document's Offset command with undo; refusals that leave everything as it was.

use crate::common;
use knotwork::ops::contour::Contour;
use knotwork::ops::explode::Explode;
use knotwork::ops::join::Join;
use knotwork::ops::offset::Offset;
use knotwork::ops::project::ProjectCurves;
use knotwork::ops::split::Split;
use knotwork::ops::trim::Trim;

use std::process::Command as Process;

use glam::{DVec2, DVec3};
use knotwork::doc::{Command, document::Document};
use knotwork::io::project::{self, Project};
use knotwork::kernel::{NurbsSurface, TrimmedSurface, construct, trim};
use knotwork::scene::{ObjectGeometry, Scene, SceneObject};
use serde_json::Value;

/// One folder for every file this file's tests write (their names differ).
fn temp_dir() -> std::path::PathBuf {
    crate::common::scratch_dir("surface-ops")
}

fn write_project(name: &str, objects: Vec<SceneObject>) -> std::path::PathBuf {
    let path = temp_dir().join(name);
    let text = project::write(&Project {
        scene: Scene {
            objects,
            unit: None,
        },
        view: None,
    });
    std::fs::write(&path, text).unwrap();
    path
}

fn read_project(path: &std::path::Path) -> Project {
    project::read(&std::fs::read_to_string(path).unwrap()).unwrap()
}

fn knotwork(args: &[&str]) -> std::process::Output {
    Process::new(env!("CARGO_BIN_EXE_knotwork"))
        .args(args)
        .output()
        .unwrap()
}

fn surface_object(name: &str, surface: NurbsSurface) -> SceneObject {
    SceneObject::new(name, ObjectGeometry::new(surface))
}

fn named<'a>(project: &'a Project, name: &str) -> &'a SceneObject {
    project
        .scene
        .objects
        .iter()
        .find(|o| o.name == name)
        .unwrap_or_else(|| panic!("no object {name:?}"))
}

/// The NURBS surface of the object named `name`.
fn nurbs_named(project: &Project, name: &str) -> NurbsSurface {
    named(project, name)
        .geometry
        .nurbs_surface()
        .unwrap_or_else(|| panic!("{name} is not a NURBS surface"))
        .clone()
}

fn scene_size(objects: &[&NurbsSurface]) -> f64 {
    let mut lo = DVec3::splat(f64::INFINITY);
    let mut hi = DVec3::splat(f64::NEG_INFINITY);
    for s in objects {
        let (a, b) = s.bounds();
        lo = lo.min(a);
        hi = hi.max(b);
    }
    lo.distance(hi)
}

fn numbers(v: &Value) -> Vec<f64> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect()
}

fn vectors(v: &Value) -> Vec<Vec<f64>> {
    v.as_array().unwrap().iter().map(numbers).collect()
}

/// Runs `knotwork offset` on a one-surface project and returns the output project and the
/// printed JSON.
fn offset_by_command(
    file: &str,
    name: &str,
    surface: &NurbsSurface,
    distance: f64,
    tolerance: Option<f64>,
) -> (Project, Value) {
    let path = write_project(file, vec![surface_object(name, surface.clone())]);
    let out_path = temp_dir().join(format!("out-{file}"));
    let distance = distance.to_string();
    let tolerance_text = tolerance.map(|t| t.to_string());
    let mut args = vec![
        "offset",
        path.to_str().unwrap(),
        "--object",
        name,
        "--distance",
        &distance,
        "-o",
        out_path.to_str().unwrap(),
    ];
    if let Some(t) = &tolerance_text {
        args.extend(["--tolerance", t]);
    }
    let out = knotwork(&args);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    eprintln!("{file}: {}", stderr.trim());
    let json: Value = serde_json::from_slice(&out.stdout).unwrap();
    (read_project(&out_path), json)
}

#[test]
fn a_rational_bicubic_offset_matches_opencascade() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/reference/occ/surface_ops.json"
    );
    let fixtures: Value = serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    for (k, case) in fixtures["offsets"].as_array().unwrap().iter().enumerate() {
        let record = &case["surface"];
        let degree = numbers(&record["degree"]);
        let knots = record["knots"].as_array().unwrap();
        let count = numbers(&record["count"]);
        let surface = NurbsSurface::new(
            [degree[0] as usize, degree[1] as usize],
            [numbers(&knots[0]), numbers(&knots[1])],
            [count[0] as usize, count[1] as usize],
            vectors(&record["points"])
                .iter()
                .map(|p| DVec3::new(p[0], p[1], p[2]))
                .collect(),
            Some(numbers(&record["weights"])),
        )
        .unwrap();
        let distance = case["distance"].as_f64().unwrap();
        let (project, json) =
            offset_by_command(&format!("occ-{k}.json"), "Wing", &surface, distance, None);
        assert_eq!(json["objects"][0], "Wing offset");
        assert_eq!(json["exact"], false);
        // The input stays as it was.
        assert_eq!(
            named(&project, "Wing").geometry.nurbs_surface(),
            Some(&surface)
        );
        let result = named(&project, "Wing offset")
            .geometry
            .nurbs_surface()
            .expect("a NURBS surface")
            .clone();
        assert_eq!(result.domain(), surface.domain());
        let size = scene_size(&[&surface]);
        let mut worst = 0.0f64;
        for (uv, p) in vectors(&case["params"])
            .iter()
            .zip(vectors(&case["points"]))
        {
            let q = result.point_at(uv[0], uv[1]).unwrap();
            worst = worst.max(q.distance(DVec3::new(p[0], p[1], p[2])));
        }
        eprintln!("d = {distance}: {worst:.3e} from OpenCASCADE (size {size:.3})");
        assert!(worst <= 1e-4 * size, "{worst} > {}", 1e-4 * size);
    }
}

#[test]
fn a_sphere_offset_is_exact_and_a_torus_offset_keeps_its_distance() {
    let centre = DVec3::new(0.5, 0.0, -1.0);
    let sphere = construct::sphere(centre, 1.5).unwrap();
    let (project, json) = offset_by_command("sphere.json", "Ball", &sphere, -0.4, None);
    assert_eq!(json["exact"], true, "{json}");
    let inner = named(&project, "Ball offset")
        .geometry
        .nurbs_surface()
        .unwrap();
    for i in 0..=10 {
        for j in 0..=10 {
            let p = inner.point_at(i as f64 / 10.0, j as f64 / 10.0).unwrap();
            assert!((p.distance(centre) - 1.1).abs() < 1e-12);
        }
    }
    let (major, minor) = (2.0, 0.6);
    let torus = construct::torus(DVec3::ZERO, DVec3::Z, major, minor).unwrap();
    let tolerance = 1e-5;
    let (project, json) = offset_by_command("torus.json", "Ring", &torus, 0.3, Some(tolerance));
    // Exact: the torus of tube radius 0.6 + 0.3 (a surface of revolution of a circle).
    assert_eq!(json["exact"], true, "{json}");
    assert!(json["deviation"].as_f64().unwrap() <= 1e-9 * scene_size(&[&torus]));
    let outer = named(&project, "Ring offset")
        .geometry
        .nurbs_surface()
        .unwrap();
    let size = scene_size(&[&torus]);
    let mut worst = 0.0f64;
    for i in 0..=50 {
        for j in 0..=50 {
            let p = outer.point_at(i as f64 / 50.0, j as f64 / 50.0).unwrap();
            let d = ((p.x.hypot(p.y) - major).hypot(p.z) - minor).abs();
            worst = worst.max((d - 0.3).abs());
        }
    }
    assert!(worst <= 1e-9 * size, "{worst}");
}

#[test]
fn an_offset_past_the_radius_of_curvature_says_where_it_folds() {
    let cylinder = construct::cylinder(DVec3::ZERO, DVec3::Z * 2.0, 0.5).unwrap();
    let (_, json) = offset_by_command("fold.json", "Tube", &cylinder, -0.8, None);
    assert!(json["fold_samples"].as_u64().unwrap() > 0, "{json}");
    let radius = json["folds"][0]["radius"].as_f64().unwrap();
    assert!((radius - 0.5).abs() < 1e-6, "{radius}");
    assert!(json["summary"].as_str().unwrap().contains("folds"));
}

#[test]
fn the_offset_command_refuses_what_it_cannot_offset_and_writes_nothing() {
    let plane = construct::plane(DVec3::ZERO, DVec3::X, DVec3::Y).unwrap();
    let circle = construct::circle(DVec3::ZERO, DVec3::Z, DVec3::X, 1.0).unwrap();
    let path = write_project(
        "refuse.json",
        vec![
            surface_object("Floor", plane),
            SceneObject::new("Hoop", ObjectGeometry::new(circle)),
        ],
    );
    let out_path = temp_dir().join("refused-out.json");
    let _ = std::fs::remove_file(&out_path);
    for (args, says) in [
        (
            vec!["--object", "Nothing", "--distance", "1"],
            "no object named",
        ),
        (vec!["--object", "Hoop", "--distance", "1"], "no faces"),
        (vec!["--object", "Floor", "--distance", "0"], "distance"),
        (vec!["--object", "Floor", "--distance", "NaN"], "distance"),
        (
            vec!["--object", "Floor", "--distance", "1", "--tolerance", "-1"],
            "tolerance",
        ),
    ] {
        let mut all = vec![
            "offset",
            path.to_str().unwrap(),
            "-o",
            out_path.to_str().unwrap(),
        ];
        all.extend(args.iter().copied());
        let out = knotwork(&all);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {stderr}");
        assert!(stderr.contains(says), "{args:?}: {stderr}");
        assert!(!out_path.exists());
    }
}

#[test]
fn the_offset_command_in_the_document_adds_one_undo_step_and_keeps_trims() {
    let surface = construct::plane(DVec3::ZERO, DVec3::X * 4.0, DVec3::Y * 2.0).unwrap();
    let lo = DVec2::new(0.2, 0.2);
    let hi = DVec2::new(0.7, 0.9);
    let trimmed =
        TrimmedSurface::new(surface, vec![trim::shapes::rectangle(lo, hi).unwrap()]).unwrap();
    let mut doc = Document::new(Scene {
        objects: vec![SceneObject::new(
            "Plate",
            ObjectGeometry::new(trimmed.clone()),
        )],
        unit: None,
    });
    let edit = doc
        .execute(&Command::operation(Offset {
            object: 0.into(),
            distance: 0.25,
            tolerance: 1e-4,
        }))
        .unwrap();
    assert!(edit.label.contains("exact"), "{}", edit.label);
    assert_eq!(doc.scene.objects.len(), 2);
    let made = &doc.scene.objects[1];
    assert_eq!(made.name, "Plate offset");
    let result = made.geometry.as_trimmed().unwrap();
    assert_eq!(result.loops(), trimmed.loops());
    let p = result.surface().point_at(0.5, 0.5).unwrap();
    assert!((p.z.abs() - 0.25).abs() < 1e-12 && (p.x - 2.0).abs() < 1e-12);
    // A zero distance is refused and changes nothing.
    let before = doc.scene.clone();
    assert!(
        doc.execute(&Command::operation(Offset {
            object: 0.into(),
            distance: 0.0,
            tolerance: 1e-4,
        }))
        .is_err()
    );
    assert_eq!(doc.scene, before);
    doc.undo().unwrap();
    assert_eq!(doc.scene.objects.len(), 1);
}

fn floor_and_wall() -> (NurbsSurface, NurbsSurface) {
    knotwork::kernel::samples::floor_and_wall().unwrap()
}

/// Runs `knotwork fillet` and returns the output project and printed JSON.
fn fillet_by_command(file: &str, objects: Vec<SceneObject>, args: &[&str]) -> (Project, Value) {
    let path = write_project(file, objects);
    let out_path = temp_dir().join(format!("out-{file}"));
    let mut all = vec![
        "fillet",
        path.to_str().unwrap(),
        "-o",
        out_path.to_str().unwrap(),
    ];
    all.extend_from_slice(args);
    let out = knotwork(&all);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    eprintln!("{file}: {}", stderr.trim());
    (
        read_project(&out_path),
        serde_json::from_slice(&out.stdout).unwrap(),
    )
}

/// The angle in degrees between two lines (normals up to sign).
fn line_angle(a: DVec3, b: DVec3) -> f64 {
    a.normalize()
        .dot(b.normalize())
        .abs()
        .min(1.0)
        .acos()
        .to_degrees()
}

#[test]
fn a_fillet_between_bicubic_surfaces_rolls_a_ball_that_touches_both() {
    let (floor, wall) = floor_and_wall();
    let (project, json) = fillet_by_command(
        "fillet-bicubic.json",
        vec![
            surface_object("Floor", floor.clone()),
            surface_object("Wall", wall.clone()),
        ],
        &[
            "--objects",
            "Floor",
            "Wall",
            "--radius",
            "0.4",
            "--side-a",
            "front",
            "--side-b",
            "front",
        ],
    );
    assert_eq!(json["fillet"], "fillet", "{json}");
    let fillet = nurbs_named(&project, "fillet");
    let size = scene_size(&[&floor, &wall]);
    let tol = 1e-4 * size;
    let r = 0.4;
    let normal = |s: &NurbsSurface, u: f64, v: f64| s.normal(u, v).unwrap();
    let mut worst = [0.0f64; 5];
    for j in 0..=23 {
        let v = j as f64 / 23.0;
        let (x0, x1) = (
            fillet.point_at(0.0, v).unwrap(),
            fillet.point_at(1.0, v).unwrap(),
        );
        let (f0, f1) = (
            floor.closest_point(x0).unwrap(),
            wall.closest_point(x1).unwrap(),
        );
        worst[0] = worst[0].max(f0.distance).max(f1.distance);
        // The ball's centre from the floor's side, and its distance to both surfaces.
        let centre = f0.point + r * normal(&floor, f0.u, f0.v);
        let to_floor = floor.closest_point(centre).unwrap().distance;
        let to_wall = wall.closest_point(centre).unwrap().distance;
        worst[1] = worst[1].max((to_floor - r).abs()).max((to_wall - r).abs());
        for i in 0..=10 {
            let x = fillet.point_at(i as f64 / 10.0, v).unwrap();
            worst[2] = worst[2].max((x.distance(centre) - r).abs());
        }
        // Tangent to both along the boundaries.
        worst[3] = worst[3].max(line_angle(
            normal(&fillet, 0.0, v),
            normal(&floor, f0.u, f0.v),
        ));
        worst[4] = worst[4].max(line_angle(
            normal(&fillet, 1.0, v),
            normal(&wall, f1.u, f1.v),
        ));
    }
    eprintln!(
        "contact {:.2e}, centre {:.2e}, sphere {:.2e}, angles {:.4}° {:.4}° (tolerance {tol:.2e})",
        worst[0], worst[1], worst[2], worst[3], worst[4]
    );
    assert!(
        worst[0] <= tol && worst[1] <= tol && worst[2] <= tol,
        "{worst:?}"
    );
    assert!(worst[3] <= 0.1 && worst[4] <= 0.1, "{worst:?}");
    // Both trimmed back: the floor keeps its side away from the wall, the wall its top.
    let floor_after = named(&project, "Floor").geometry.as_trimmed().unwrap();
    let wall_after = named(&project, "Wall").geometry.as_trimmed().unwrap();
    assert!(floor_after.is_trimmed() && wall_after.is_trimmed());
    let at = |s: &NurbsSurface, p: DVec3| {
        let c = s.closest_point(p).unwrap();
        (c.u, c.v)
    };
    let (u, v) = at(&floor, DVec3::new(2.0, 0.5, 0.0));
    assert!(floor_after.contains(u, v));
    let (u, v) = at(&floor, DVec3::new(2.0, 3.5, 0.0));
    assert!(!floor_after.contains(u, v));
    let (u, v) = at(&wall, DVec3::new(2.0, 2.2, 1.8));
    assert!(wall_after.contains(u, v));
    let (u, v) = at(&wall, DVec3::new(2.0, 2.2, -0.8));
    assert!(!wall_after.contains(u, v));
}

#[test]
fn a_fillet_between_two_planes_is_a_quarter_cylinder_and_bad_requests_are_refused() {
    let floor = construct::plane(
        DVec3::new(-1.0, -2.0, 0.0),
        DVec3::new(2.0, 0.0, 0.0),
        DVec3::new(0.0, 4.0, 0.0),
    )
    .unwrap();
    let wall = construct::plane(
        DVec3::new(-1.0, 0.0, -2.0),
        DVec3::new(2.0, 0.0, 0.0),
        DVec3::new(0.0, 0.0, 4.0),
    )
    .unwrap();
    let objects = vec![
        surface_object("Floor", floor.clone()),
        surface_object("Wall", wall.clone()),
    ];
    // Default sides (back, back): below the floor (−z) and on the wall's +y side.
    let (project, _) = fillet_by_command(
        "fillet-planes.json",
        objects.clone(),
        &["--objects", "Floor", "Wall", "--radius", "0.5"],
    );
    let fillet = nurbs_named(&project, "fillet");
    for i in 0..=8 {
        for j in 0..=8 {
            let p = fillet.point_at(i as f64 / 8.0, j as f64 / 8.0).unwrap();
            assert!(p.z <= 1e-9 && p.y >= -1e-9, "{p}");
            let d = DVec2::new(p.y - 0.5, p.z + 0.5).length();
            assert!((d - 0.5).abs() < 1e-9, "{d}");
        }
    }
    // A radius that runs from 0.2 at x = −1 (where the contact on the floor starts, at its
    // lower u) to 0.6 at x = 1: every section is the arc of radius r(x) about (x, r, −r).
    let (project, _) = fillet_by_command(
        "fillet-varying.json",
        objects.clone(),
        &[
            "--objects",
            "Floor",
            "Wall",
            "--radius",
            "0.2",
            "--radius-end",
            "0.6",
        ],
    );
    let fillet = nurbs_named(&project, "fillet");
    let mut worst = 0.0f64;
    for i in 0..=8 {
        for j in 0..=32 {
            let p = fillet.point_at(i as f64 / 8.0, j as f64 / 32.0).unwrap();
            let r = 0.2 + 0.4 * (p.x + 1.0) / 2.0;
            worst = worst.max((DVec2::new(p.y - r, p.z + r).length() - r).abs());
        }
    }
    assert!(worst < 1e-4, "{worst}");
    let [(_, _), (v0, v1)] = fillet.domain();
    let (start, end) = (
        fillet.point_at(0.0, v0).unwrap(),
        fillet.point_at(0.0, v1).unwrap(),
    );
    assert!(
        (start.x + 1.0).abs() < 1e-6 && (end.x - 1.0).abs() < 1e-6,
        "{start} {end}"
    );
    let path = write_project("fillet-refuse.json", objects);
    let out_path = temp_dir().join("fillet-refused.json");
    let _ = std::fs::remove_file(&out_path);
    for (args, says) in [
        (
            vec!["--objects", "Floor", "Nope", "--radius", "0.5"],
            "no object named",
        ),
        (
            vec!["--objects", "Floor", "Wall", "--radius", "-1"],
            "radius",
        ),
        (
            vec!["--objects", "Floor", "Wall", "--radius", "9"],
            "no ball",
        ),
        (
            vec!["--objects", "Floor", "Floor", "--radius", "0.5"],
            "itself",
        ),
    ] {
        let mut all = vec![
            "fillet",
            path.to_str().unwrap(),
            "-o",
            out_path.to_str().unwrap(),
        ];
        all.extend(args.iter().copied());
        let out = knotwork(&all);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {stderr}");
        assert!(stderr.contains(says), "{args:?}: {stderr}");
        assert!(!out_path.exists());
    }
}

/// The six faces of the box [0, 2] × [0, 1] × [0, 1.5] as separate plane objects, with their
/// normals pointing every which way.
fn box_objects() -> Vec<SceneObject> {
    let (x, y, z) = (DVec3::X * 2.0, DVec3::Y, DVec3::Z * 1.5);
    [
        (DVec3::ZERO, x, y),
        (z, y, x),
        (DVec3::ZERO, x, z),
        (y, z, x),
        (DVec3::ZERO, z, y),
        (x, y, z),
    ]
    .into_iter()
    .enumerate()
    .map(|(k, (o, u, v))| surface_object(&format!("Side {k}"), construct::plane(o, u, v).unwrap()))
    .collect()
}

/// The triangles of every mesh of a `.glb` as position triples (f32, as stored).
fn glb_triangles(bytes: &[u8]) -> Vec<Vec<[[f32; 3]; 3]>> {
    let file = gltf::Gltf::from_slice(bytes).unwrap();
    let blob = file.blob.as_deref().unwrap();
    let mut out = Vec::new();
    for mesh in file.meshes() {
        let mut triangles = Vec::new();
        for primitive in mesh.primitives() {
            if primitive.mode() != gltf::mesh::Mode::Triangles {
                continue;
            }
            let reader = primitive.reader(|b| (b.index() == 0).then_some(blob));
            let positions: Vec<[f32; 3]> = reader.read_positions().unwrap().collect();
            let indices: Vec<usize> = reader
                .read_indices()
                .unwrap()
                .into_u32()
                .map(|i| i as usize)
                .collect();
            for t in indices.chunks(3) {
                triangles.push([positions[t[0]], positions[t[1]], positions[t[2]]]);
            }
        }
        out.push(triangles);
    }
    out
}

/// How many edges of the mesh (its vertices welded where their positions are equal) belong
/// to other than exactly two triangles, and the signed volume it encloses.
fn open_edges_and_volume(triangles: &[[[f32; 3]; 3]]) -> (usize, f64) {
    use std::collections::HashMap;
    let mut ids: HashMap<[u32; 3], usize> = HashMap::new();
    let mut id = |p: [f32; 3]| {
        let n = ids.len();
        *ids.entry(p.map(f32::to_bits)).or_insert(n)
    };
    let mut uses: HashMap<(usize, usize), usize> = HashMap::new();
    let mut volume = 0.0;
    for t in triangles {
        let k = t.map(&mut id);
        for e in 0..3 {
            let (a, b) = (k[e], k[(e + 1) % 3]);
            *uses.entry((a.min(b), a.max(b))).or_insert(0) += 1;
        }
        let [a, b, c] = t.map(|p| DVec3::from(p.map(f64::from)));
        volume += a.dot(b.cross(c)) / 6.0;
    }
    (uses.values().filter(|&&n| n != 2).count(), volume)
}

#[test]
fn a_joined_box_exports_as_a_closed_mesh_that_passes_the_validator() {
    let path = write_project("box.json", box_objects());
    let joined = temp_dir().join("box-joined.json");
    let out = knotwork(&[
        "join",
        path.to_str().unwrap(),
        "-o",
        joined.to_str().unwrap(),
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    eprintln!("{}", stderr.trim());
    let json: Value = serde_json::from_slice(&out.stdout).unwrap();
    let p = &json["polysurfaces"][0];
    assert_eq!(json["polysurfaces"].as_array().unwrap().len(), 1, "{json}");
    assert_eq!(
        (p["faces"].as_u64(), p["shared_edges"].as_u64()),
        (Some(6), Some(12))
    );
    assert_eq!(
        (p["naked_edges"].as_u64(), &p["closed"]),
        (Some(0), &Value::Bool(true))
    );
    assert_eq!(read_project(&joined).scene.objects.len(), 1);
    let glb = temp_dir().join("box.glb");
    let out = knotwork(&[
        "export",
        joined.to_str().unwrap(),
        "-o",
        glb.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let meshes = glb_triangles(&std::fs::read(&glb).unwrap());
    assert_eq!(meshes.len(), 1, "one mesh for the polysurface");
    let (open, volume) = open_edges_and_volume(&meshes[0]);
    assert_eq!(open, 0, "every edge belongs to exactly two triangles");
    assert!((volume.abs() - 3.0).abs() < 1e-5, "{volume}");
    common::validate_gltf(&[glb]);
    // The same faces not joined: the export is six open meshes.
    let glb = temp_dir().join("box-apart.glb");
    let out = knotwork(&[
        "export",
        path.to_str().unwrap(),
        "-o",
        glb.to_str().unwrap(),
    ]);
    assert!(out.status.success());
    let apart = glb_triangles(&std::fs::read(&glb).unwrap());
    assert_eq!(apart.len(), 6);
    assert!(open_edges_and_volume(&apart.concat()).0 > 0);
}

#[test]
fn a_trimmed_cylinder_with_caps_joins_watertight_and_explodes_back() {
    // The side as a NURBS cylinder, the caps planes trimmed by circles.
    let side = construct::cylinder(DVec3::ZERO, DVec3::Z * 1.2, 0.7).unwrap();
    let cap = |z: f64| {
        let circle = construct::circle(DVec3::Z * z, DVec3::Z, DVec3::X, 0.7).unwrap();
        knotwork::kernel::planar::planar_face(&[circle]).unwrap()
    };
    let objects = vec![
        surface_object("Side", side),
        SceneObject::new("Bottom", ObjectGeometry::from_trimmed(cap(0.0))),
        SceneObject::new("Top", ObjectGeometry::from_trimmed(cap(1.2))),
    ];
    let mut doc = Document::new(Scene {
        objects: objects.clone(),
        unit: None,
    });
    let edit = doc
        .execute(&Command::operation(Join {
            objects: Vec::new(),
            tolerance: 1e-6,
        }))
        .unwrap();
    eprintln!("{}", edit.label);
    assert_eq!(doc.scene.objects.len(), 1);
    let joined = &doc.scene.objects[0];
    assert_eq!(joined.name, "Side");
    let meshes = joined
        .tessellate(knotwork::kernel::tess::Tessellation::Tolerance(1e-3), false)
        .unwrap();
    assert_eq!(meshes.len(), 1);
    let triangles: Vec<[[f32; 3]; 3]> = meshes[0]
        .triangles
        .iter()
        .map(|t| t.map(|k| meshes[0].positions[k as usize].as_vec3().to_array()))
        .collect();
    let (open, volume) = open_edges_and_volume(&triangles);
    assert_eq!(open, 0);
    let exact = std::f64::consts::PI * 0.49 * 1.2;
    assert!(
        (volume.abs() - exact).abs() < 2e-3 * exact,
        "{volume} vs {exact}"
    );
    doc.execute(&Command::operation(Explode { object: 0.into() }))
        .unwrap();
    assert_eq!(doc.scene.objects.len(), 3);
    doc.undo().unwrap();
    doc.undo().unwrap();
    assert_eq!(doc.scene.objects, objects);
    // Surfaces apart: nothing to join, and nothing changes.
    let mut apart = Document::new(Scene {
        objects: box_objects()[..2].to_vec(),
        unit: None,
    });
    let e = apart
        .execute(&Command::operation(Join {
            objects: Vec::new(),
            tolerance: 1e-6,
        }))
        .unwrap_err();
    assert!(e.to_string().contains("nothing to join"), "{e}");
    assert!(e.to_string().starts_with("the scene's objects: "), "{e}");
    assert_eq!(apart.scene.objects.len(), 2);
    // Picked, they are named: the join is theirs, not the first object's alone.
    let e = apart
        .execute(&Command::operation(Join {
            objects: vec![1.into(), 0.into()],
            tolerance: 1e-6,
        }))
        .unwrap_err();
    assert!(e.to_string().starts_with("Side 0 and Side 1: "), "{e}");
}

#[test]
fn a_fillet_and_the_surfaces_it_trimmed_join_into_one_polysurface() {
    let floor = construct::plane(
        DVec3::new(-1.0, -2.0, 0.0),
        DVec3::new(2.0, 0.0, 0.0),
        DVec3::new(0.0, 2.0, 0.0),
    )
    .unwrap();
    let wall = construct::plane(
        DVec3::new(-1.0, 0.0, 0.0),
        DVec3::new(2.0, 0.0, 0.0),
        DVec3::new(0.0, 0.0, 2.0),
    )
    .unwrap();
    let mut doc = Document::new(Scene {
        objects: vec![surface_object("Floor", floor), surface_object("Wall", wall)],
        unit: None,
    });
    // The floor's normal is +z, the wall's −y: the ball sits in the corner, in front of both.
    doc.execute(&Command::operation(
        knotwork::doc::surface_ops::FilletRequest {
            a: 0.into(),
            b: 1.into(),
            radius: 0.4,
            radius_end: None,
            front_a: true,
            front_b: true,
            tolerance: 1e-4,
        },
    ))
    .unwrap();
    assert_eq!(doc.scene.objects.len(), 3);
    let label = doc
        .execute(&Command::operation(Join {
            objects: Vec::new(),
            tolerance: 1e-6,
        }))
        .unwrap()
        .label
        .clone();
    eprintln!("{label}");
    assert_eq!(doc.scene.objects.len(), 1, "{label}");
    let p = doc.scene.objects[0]
        .geometry
        .downcast_ref::<knotwork::scene::polysurface::Polysurface>()
        .unwrap();
    let topology = p.topology().unwrap();
    assert_eq!((p.faces().len(), topology.shared.len()), (3, 2), "{label}");
    // An L-shaped sheet with a rounded corner: 8 naked edges round its outline.
    assert_eq!(topology.naked.len(), 8, "{topology:?}");
}

/// The area of an object's export tessellation at `tolerance`.
fn mesh_area(object: &SceneObject, tolerance: f64) -> f64 {
    object
        .tessellate(
            knotwork::kernel::tess::Tessellation::Tolerance(tolerance),
            false,
        )
        .unwrap()
        .iter()
        .map(|m| m.area())
        .sum()
}

#[test]
fn a_plane_trimmed_and_split_by_a_sphere_and_by_a_curve_on_it() {
    let plane = construct::plane(
        DVec3::new(-2.0, -2.0, 0.0),
        DVec3::new(4.0, 0.0, 0.0),
        DVec3::new(0.0, 4.0, 0.0),
    )
    .unwrap();
    let sphere = construct::sphere(DVec3::ZERO, 1.0).unwrap();
    let hoop = construct::circle(DVec3::ZERO, DVec3::Z, DVec3::X, 0.5).unwrap();
    let objects = vec![
        surface_object("Plate", plane),
        surface_object("Ball", sphere),
        SceneObject::new("Hoop", ObjectGeometry::new(hoop)),
        SceneObject::new(
            "Above",
            ObjectGeometry::new(
                construct::circle(DVec3::Z * 0.3, DVec3::Z, DVec3::X, 0.5).unwrap(),
            ),
        ),
    ];
    let pi = std::f64::consts::PI;
    let mut doc = Document::new(Scene {
        objects: objects.clone(),
        unit: None,
    });
    // Keep the outside of the sphere's circle: a square with a round hole.
    let label = doc
        .execute(&Command::operation(Trim {
            object: 0.into(),
            cutters: vec![1.into()],
            keep: DVec3::new(1.8, 1.8, 0.0).to_array(),
        }))
        .unwrap()
        .label
        .clone();
    assert_eq!(label, "trim Plate by Ball");
    let area = mesh_area(&doc.scene.objects[0], 1e-4);
    assert!((area - (16.0 - pi)).abs() < 2e-3, "{area}");
    doc.undo().unwrap();
    // Keep the inside: the unit disc.
    doc.execute(&Command::operation(Trim {
        object: 0.into(),
        cutters: vec![1.into()],
        keep: DVec3::new(0.1, 0.0, 0.0).to_array(),
    }))
    .unwrap();
    let area = mesh_area(&doc.scene.objects[0], 1e-4);
    assert!((area - pi).abs() < 2e-3, "{area}");
    doc.undo().unwrap();
    // Split by the sphere and by the hoop lying on the plate: three parts.
    let label = doc
        .execute(&Command::operation(Split {
            object: 0.into(),
            cutters: vec![1.into(), 2.into()],
        }))
        .unwrap()
        .label
        .clone();
    assert_eq!(doc.scene.objects.len(), 6, "{label}");
    let parts = [0, 4, 5].map(|k| mesh_area(&doc.scene.objects[k], 1e-4));
    let mut sorted = parts;
    sorted.sort_by(f64::total_cmp);
    let expected = [0.25 * pi, 0.75 * pi, 16.0 - pi];
    for (got, want) in sorted.iter().zip(expected) {
        assert!((got - want).abs() < 2e-3, "{parts:?}");
    }
    doc.undo().unwrap();
    // A curve off the surface is refused, and nothing changes.
    let e = doc
        .execute(&Command::operation(Trim {
            object: 0.into(),
            cutters: vec![3.into()],
            keep: DVec3::ZERO.to_array(),
        }))
        .unwrap_err();
    assert!(e.to_string().contains("project it onto the surface"), "{e}");
    assert_eq!(doc.scene.objects, objects);
}

#[test]
fn a_cylinder_standing_on_a_plane_gets_a_fillet_all_round() {
    let floor = construct::plane(
        DVec3::new(-2.0, -2.0, 0.0),
        DVec3::new(4.0, 0.0, 0.0),
        DVec3::new(0.0, 4.0, 0.0),
    )
    .unwrap();
    let post = construct::cylinder(DVec3::new(0.0, 0.0, -1.0), DVec3::Z * 3.0, 0.6).unwrap();
    let objects = vec![
        surface_object("Floor", floor.clone()),
        surface_object("Post", post.clone()),
    ];
    // Above the floor (its front, +z) and outside the post (its front: outward normals).
    let (project, json) = fillet_by_command(
        "fillet-post.json",
        objects,
        &[
            "--objects",
            "Floor",
            "Post",
            "--radius",
            "0.25",
            "--side-a",
            "front",
            "--side-b",
            "front",
        ],
    );
    let fillet = nurbs_named(&project, "fillet");
    // A quarter torus: every point at 0.25 from the circle of centres (radius 0.85, z = 0.25).
    let mut worst = 0.0f64;
    for i in 0..=10 {
        for j in 0..=40 {
            let p = fillet.point_at(i as f64 / 10.0, j as f64 / 40.0).unwrap();
            let d = (p.x.hypot(p.y) - 0.85).hypot(p.z - 0.25);
            worst = worst.max((d - 0.25).abs());
        }
    }
    let size = scene_size(&[&floor, &post]);
    assert!(worst <= 1e-4 * size, "{worst} {json}");
    // The floor keeps everything outside the contact circle (radius 0.85), the post everything
    // above its contact line (z = 0.25).
    let floor_after = named(&project, "Floor").geometry.as_trimmed().unwrap();
    let at = |x: f64, y: f64| ((x + 2.0) / 4.0, (y + 2.0) / 4.0);
    for (x, y, kept) in [
        (1.5, 0.0, true),
        (0.0, -1.2, true),
        (0.7, 0.0, false),
        (0.0, 0.0, false),
    ] {
        let (u, v) = at(x, y);
        assert_eq!(floor_after.contains(u, v), kept, "floor at ({x}, {y})");
    }
    let post_after = named(&project, "Post").geometry.as_trimmed().unwrap();
    for (z, kept) in [(1.5, true), (0.1, false), (-0.5, false)] {
        let v = (z + 1.0) / 3.0;
        assert_eq!(post_after.contains(0.3, v), kept, "post at z = {z}");
    }
}

#[test]
fn a_sphere_contoured_and_curves_projected_and_pulled_onto_it() {
    let sphere = construct::sphere(DVec3::ZERO, 1.0).unwrap();
    let hoop = construct::circle(DVec3::Z * 2.0, DVec3::Z, DVec3::X, 0.5).unwrap();
    let mut doc = Document::new(Scene {
        objects: vec![
            surface_object("Ball", sphere),
            SceneObject::new("Hoop", ObjectGeometry::new(hoop)),
        ],
        unit: None,
    });
    // Planes z = -0.5, 0 and 0.5 cut circles; z = ±1 only touch at the poles.
    doc.execute(&Command::operation(Contour {
        object: 0.into(),
        origin: [0.0; 3],
        normal: [0.0, 0.0, 1.0],
        spacing: 0.5,
    }))
    .unwrap();
    let mut levels = Vec::new();
    for object in &doc.scene.objects[2..] {
        assert!(object.name.starts_with("Ball contour"), "{}", object.name);
        let curve = object.kind().space_curve().unwrap();
        let (t0, t1) = curve.domain();
        let mut worst = 0.0f64;
        let z = curve.point_at(t0).unwrap().z;
        for i in 0..=50 {
            let p = curve.point_at(t0 + (t1 - t0) * i as f64 / 50.0).unwrap();
            worst = worst.max((p.length() - 1.0).abs()).max((p.z - z).abs());
        }
        assert!(worst < 1e-5, "{worst}");
        levels.push((z * 2.0).round() as i32);
    }
    levels.sort();
    levels.dedup();
    assert_eq!(levels, vec![-1, 0, 1]);
    let count = doc.scene.objects.len();
    // Projected straight down: on the upper half at height √(1 − 0.25).
    doc.execute(&Command::operation(ProjectCurves {
        curves: vec![1.into()],
        onto: 0.into(),
        direction: Some((-DVec3::Z).to_array()),
    }))
    .unwrap();
    let projected = doc.scene.objects[count]
        .kind()
        .space_curve()
        .unwrap()
        .clone();
    // Pulled: to the nearest points, along the radius.
    doc.execute(&Command::operation(ProjectCurves {
        curves: vec![1.into()],
        onto: 0.into(),
        direction: None,
    }))
    .unwrap();
    let pulled = doc.scene.objects[count + 1]
        .kind()
        .space_curve()
        .unwrap()
        .clone();
    let height = 0.75f64.sqrt();
    let along = |c: &knotwork::kernel::SpaceCurve, check: &dyn Fn(DVec3) -> f64| {
        let (t0, t1) = c.domain();
        (0..=64)
            .map(|i| check(c.point_at(t0 + (t1 - t0) * i as f64 / 64.0).unwrap()))
            .fold(0.0f64, f64::max)
    };
    let off = along(&projected, &|p| {
        (p.z - height).abs().max((p.x.hypot(p.y) - 0.5).abs())
    });
    assert!(off < 1e-6, "projected {off}");
    let radial = DVec3::new(0.5, 0.0, 2.0).normalize();
    let off = along(&pulled, &|p| {
        (p.length() - 1.0).abs().max((p.z - radial.z).abs())
    });
    assert!(off < 1e-6, "pulled {off}");
    // The projection lies on the sphere: it trims it.
    doc.execute(&Command::operation(Trim {
        object: 0.into(),
        cutters: vec![count.into()],
        keep: DVec3::Z.to_array(),
    }))
    .unwrap();
    let area = mesh_area(&doc.scene.objects[0], 1e-4);
    let cap = 2.0 * std::f64::consts::PI * (1.0 - height);
    assert!((area - cap).abs() < 1e-2 * cap, "{area} vs {cap}");
}

/// A bicubic sheet over [x0, x0 + 2] × [0, 2] at heights `h`.
fn sheet(x0: f64, h: impl Fn(f64, f64) -> f64) -> NurbsSurface {
    let knots = vec![0.0, 0.0, 0.0, 0.0, 0.5, 1.0, 1.0, 1.0, 1.0];
    let mut points = Vec::new();
    for i in 0..5 {
        for j in 0..5 {
            let (x, y) = (x0 + 0.5 * i as f64, 0.5 * j as f64);
            points.push(DVec3::new(x, y, h(x, y)));
        }
    }
    NurbsSurface::new([3, 3], [knots.clone(), knots], [5, 5], points, None).unwrap()
}

/// Runs knotwork, which must succeed, and parses what it prints.
fn knotwork_json(args: &[&str]) -> Value {
    let out = knotwork(args);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).unwrap()
}

/// `knotwork continuity` on `path` for `objects`: every shared edge's JSON.
fn continuity_of(path: &std::path::Path, objects: &[&str]) -> Vec<Value> {
    let mut args = vec!["continuity", path.to_str().unwrap(), "--objects"];
    args.extend_from_slice(objects);
    knotwork_json(&args).as_array().unwrap().clone()
}

#[test]
fn a_blend_between_two_sheets_is_g2_to_both_by_knotwork_continuity() {
    let left = sheet(-3.0, |x, y| 0.2 * (0.7 * x).sin() + 0.1 * y * y);
    let right = sheet(1.0, |x, y| 0.5 + 0.3 * (0.5 * x).cos() * y);
    let input = write_project(
        "blend-in.json",
        vec![surface_object("Left", left), surface_object("Right", right)],
    );
    for (continuity, verdict) in [("g1", "G1"), ("g2", "G2")] {
        let output = temp_dir().join(format!("blend-{continuity}.json"));
        let json = knotwork_json(&[
            "blend",
            input.to_str().unwrap(),
            "--objects",
            "Left",
            "Right",
            "--continuity",
            continuity,
            "-o",
            output.to_str().unwrap(),
        ]);
        assert_eq!(json["blend"], "blend");
        let edges = continuity_of(&output, &["Left", "blend", "Right"]);
        assert_eq!(edges.len(), 2, "{edges:?}");
        for e in &edges {
            assert!(e["verdict"] == verdict || e["verdict"] == "G2", "{e}");
            assert!(e["max_angle_degrees"].as_f64().unwrap() < 1e-3, "{e}");
        }
        // The blend runs from Left's x = -1 edge to Right's x = 1 edge.
        let blend = named(&read_project(&output), "blend")
            .geometry
            .nurbs_surface()
            .unwrap()
            .clone();
        let [(u0, u1), (v0, v1)] = blend.domain();
        for k in 0..=4 {
            let u = u0 + (u1 - u0) * k as f64 / 4.0;
            assert!((blend.point_at(u, v0).unwrap().x + 1.0).abs() < 1e-6);
            assert!((blend.point_at(u, v1).unwrap().x - 1.0).abs() < 1e-6);
        }
    }
    // Edges named explicitly; a bad side or continuity is refused by name.
    let output = temp_dir().join("blend-named.json");
    knotwork_json(&[
        "blend",
        input.to_str().unwrap(),
        "--objects",
        "Left",
        "Right",
        "--edges",
        "u1",
        "0:u0",
        "--continuity",
        "G0",
        "--tension",
        "0.5",
        "2",
        "-o",
        output.to_str().unwrap(),
    ]);
    for (flag, value, message) in [
        ("--edges", "w9", "the side must be u0, u1, v0 or v1"),
        ("--continuity", "g7", "the continuity must be g0, g1 or g2"),
    ] {
        let mut args = vec![
            "blend",
            input.to_str().unwrap(),
            "--objects",
            "Left",
            "Right",
            flag,
            value,
        ];
        if flag == "--edges" {
            args.push("u0");
        }
        args.extend(["-o", output.to_str().unwrap()]);
        let out = knotwork(&args);
        assert_eq!(out.status.code(), Some(1));
        assert!(
            String::from_utf8_lossy(&out.stderr).contains(message),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
}

#[test]
fn matching_a_sheet_to_a_rounded_roof_by_the_command_line_and_the_document() {
    // A quarter cylinder of radius 1 about the y axis from x = 1 up to the top, z = 1, where it
    // leaves horizontally towards −x; a tilted sheet beside its top edge, a little apart.
    let arc = construct::arc(
        DVec3::ZERO,
        DVec3::X,
        DVec3::Z,
        1.0,
        0.0,
        std::f64::consts::FRAC_PI_2,
    )
    .unwrap();
    let roof = construct::extrude(&arc, DVec3::Y * 2.0).unwrap();
    let flat = sheet(-2.1, |x, y| 1.05 + 0.05 * (x + 0.1) + 0.02 * y);
    let objects = vec![
        surface_object("Sheet", flat.clone()),
        surface_object("Roof", roof),
    ];
    let input = write_project("match-in.json", objects.clone());
    for (continuity, verdicts) in [
        ("g0", &["G0", "G1", "G2"][..]),
        ("g1", &["G1", "G2"][..]),
        ("g2", &["G2"][..]),
    ] {
        let output = temp_dir().join(format!("match-{continuity}.json"));
        knotwork_json(&[
            "match",
            input.to_str().unwrap(),
            "--object",
            "Sheet",
            "--to",
            "Roof",
            "--continuity",
            continuity,
            "-o",
            output.to_str().unwrap(),
        ]);
        let edges = continuity_of(&output, &["Sheet", "Roof"]);
        assert_eq!(edges.len(), 1, "{continuity}: {edges:?}");
        let verdict = edges[0]["verdict"].as_str().unwrap();
        assert!(verdicts.contains(&verdict), "{continuity}: {}", edges[0]);
        if continuity == "g2" {
            // The roof's curvature across the edge is 1: the sheet bends to it.
            let e = &edges[0];
            assert!(
                e["max_relative_curvature_difference"].as_f64().unwrap() < 1e-3,
                "{e}"
            );
        }
    }

    // In the document: one undo step, and the far edge stays.
    let mut doc = Document::new(Scene {
        objects,
        unit: None,
    });
    doc.execute(&Command::operation(
        knotwork::doc::surface_ops::MatchRequest {
            object: 0.into(),
            target: 1.into(),
            edges: None,
            continuity: knotwork::kernel::blend::EdgeContinuity::G2,
            tolerance: 1e-8,
        },
    ))
    .unwrap();
    let moved = doc.scene.objects[0]
        .geometry
        .nurbs_surface()
        .unwrap()
        .clone();
    for k in 0..=4 {
        let v = k as f64 / 4.0;
        let far = moved.point_at(0.0, v).unwrap();
        assert!(far.distance(flat.point_at(0.0, v).unwrap()) < 1e-12);
        let near = moved.point_at(1.0, v).unwrap();
        assert!(
            (near - DVec3::new(0.0, 2.0 * v, 1.0)).length() < 1e-6,
            "{near}"
        );
    }
    doc.undo().unwrap();
    assert_eq!(doc.scene.objects[0].geometry.nurbs_surface(), Some(&flat));

    // Refusals say why and leave the document as it was: a match onto itself, an edge of a
    // face the object does not have, a blend with a tension of 0.
    let before = doc.scene.clone();
    let request = knotwork::doc::surface_ops::BlendRequest {
        a: 0.into(),
        b: 1.into(),
        edges: None,
        continuity: knotwork::kernel::blend::EdgeContinuity::G1,
        tension: [1.0, 1.0],
        tolerance: 1e-6,
    };
    let refusals = [
        (
            Command::operation(knotwork::doc::surface_ops::MatchRequest {
                object: 0.into(),
                target: 0.into(),
                edges: None,
                continuity: knotwork::kernel::blend::EdgeContinuity::G1,
                tolerance: 1e-6,
            }),
            "needs two different objects",
        ),
        (
            Command::operation(knotwork::doc::surface_ops::BlendRequest {
                edges: Some([
                    (3, knotwork::kernel::continuity::Side::U1),
                    (0, knotwork::kernel::continuity::Side::V0),
                ]),
                ..request
            }),
            "not a face 3",
        ),
        (
            Command::operation(knotwork::doc::surface_ops::BlendRequest {
                tension: [0.0, 1.0],
                ..request
            }),
            "tension",
        ),
    ];
    for (command, message) in refusals {
        let e = doc.execute(&command).unwrap_err().to_string();
        assert!(e.contains(message), "{e}");
        assert_eq!(doc.scene, before);
    }
    doc.execute(&Command::operation(request)).unwrap();
    assert_eq!(doc.scene.objects.len(), 3);
    assert_eq!(doc.scene.objects[2].name, "blend");
    doc.undo().unwrap();
    assert_eq!(doc.scene, before);
}

/// A fillet between a wavy bicubic sheet and a cylinder through it, in general position
/// (rotated, moved, scaled): the ball touches both tangentially along the contact curves, both
/// are trimmed back in the same undo step, and the fillet joins them into one polysurface at
/// the editor's join tolerance, as Rhino's FilletSrf then Join does.
#[test]
fn a_fillet_between_a_wavy_sheet_and_a_cylinder_in_general_position_trims_both_and_joins() {
    let place = glam::DAffine3::from_scale_rotation_translation(
        DVec3::splat(3.7),
        glam::DQuat::from_euler(glam::EulerRot::ZXY, 0.7, -1.1, 2.3),
        DVec3::new(12.0, -5.0, 8.0),
    );
    let wavy = sheet(0.0, |x, y| 0.15 * (2.0 * x).sin() * (1.5 * y).cos())
        .transformed(&place)
        .unwrap();
    let post = construct::cylinder(DVec3::new(1.0, 1.0, -1.0), DVec3::Z * 2.5, 0.4)
        .unwrap()
        .transformed(&place)
        .unwrap();
    let size = scene_size(&[&wavy, &post]);
    for (front_a, front_b) in [(true, true), (false, true), (true, false), (false, false)] {
        let mut doc = Document::new(Scene {
            objects: vec![
                surface_object("Sheet", wavy.clone()),
                surface_object("Post", post.clone()),
            ],
            unit: None,
        });
        let result = doc.execute(&Command::operation(
            knotwork::doc::surface_ops::FilletRequest {
                a: 0.into(),
                b: 1.into(),
                radius: 0.15 * 3.7,
                radius_end: None,
                front_a,
                front_b,
                tolerance: knotwork::doc::surface_ops::EDITOR_TOLERANCE,
            },
        ));
        let label = match result {
            Ok(edit) => edit.label.clone(),
            Err(e) => {
                eprintln!("sides {front_a} {front_b}: refused: {e}");
                assert_eq!(doc.scene.objects.len(), 2);
                continue;
            }
        };
        eprintln!("sides {front_a} {front_b}: {label}");
        let fillet = doc.scene.objects[2].geometry.as_trimmed().unwrap();
        let fillet = fillet.surface().clone();
        let mut worst = [0.0f64; 2];
        let mut facing = [0usize; 2];
        for (k, input) in [&wavy, &post].into_iter().enumerate() {
            for j in 0..=40 {
                let v = j as f64 / 40.0;
                let x = fillet.point_at(k as f64, v).unwrap();
                let c = input.closest_point(x).unwrap();
                let (nf, ni) = (
                    fillet.normal(k as f64, v).unwrap(),
                    input.normal(c.u, c.v).unwrap(),
                );
                worst[k] = worst[k].max(line_angle(nf, ni));
                facing[k] += usize::from(nf.dot(ni) > 0.0);
            }
        }
        eprintln!(
            "angles at the contacts {:.4}° {:.4}°, normals along {facing:?} of 41",
            worst[0], worst[1]
        );
        assert!(worst[0] <= 0.1 && worst[1] <= 0.1, "{worst:?} {label}");
        // The fillet faces as the sheet does across their edge (whichever side the ball is
        // on), and the same way all along the post: a join is consistently oriented where
        // the sheet and the post are.
        assert_eq!(facing[0], 41, "{label}");
        let post_agrees = front_a == front_b;
        assert_eq!(facing[1], if post_agrees { 41 } else { 0 }, "{label}");
        for k in 0..2 {
            assert!(
                doc.scene.objects[k]
                    .geometry
                    .as_trimmed()
                    .unwrap()
                    .is_trimmed(),
                "{label}"
            );
        }
        let joined = doc.execute(&Command::operation(Join {
            objects: Vec::new(),
            tolerance: knotwork::doc::surface_ops::JOIN_TOLERANCE,
        }));
        let joined = match joined {
            Ok(edit) => edit.label.clone(),
            Err(e) => panic!("sides {front_a} {front_b}: {e} (size {size})"),
        };
        assert_eq!(doc.scene.objects.len(), 1, "{joined}");
    }
}

/// Two overlapping cuts on one surface, as in Rhino: a plate in general position trimmed by
/// one ball, then by a second ball that overlaps the first hole, keeps the plate less the
/// union of the two discs (closed form: two discs less their lens), within the mesh's
/// tolerance; undo takes each cut back.
#[test]
fn a_second_trim_across_the_first_keeps_what_both_keep() {
    use std::f64::consts::PI;
    let place = glam::DAffine3::from_scale_rotation_translation(
        DVec3::splat(2.3),
        glam::DQuat::from_euler(glam::EulerRot::XYZ, 0.4, -0.9, 1.7),
        DVec3::new(-3.0, 7.0, 2.0),
    );
    let plate = construct::plane(
        DVec3::new(-2.0, -2.0, 0.0),
        DVec3::new(4.0, 0.0, 0.0),
        DVec3::new(0.0, 4.0, 0.0),
    )
    .unwrap()
    .transformed(&place)
    .unwrap();
    let ball = |x: f64| {
        construct::sphere(DVec3::new(x, 0.2, 0.0), 1.0)
            .unwrap()
            .transformed(&place)
            .unwrap()
    };
    let objects = vec![
        surface_object("Plate", plate),
        surface_object("Ball", ball(-0.4)),
        surface_object("Other ball", ball(0.6)),
    ];
    let mut doc = Document::new(Scene {
        objects: objects.clone(),
        unit: None,
    });
    let corner = place.transform_point3(DVec3::new(1.8, 1.8, 0.0));
    for cutter in [1, 2] {
        let trimmed = doc.execute(&Command::operation(Trim {
            object: 0.into(),
            cutters: vec![cutter.into()],
            keep: corner.to_array(),
        }));
        if let Err(e) = trimmed {
            panic!("trim by {cutter}: {e}");
        }
    }
    let scale = 2.3f64 * 2.3;
    let segment = |r: f64, d: f64| r * r * (d / r).acos() - d * (r * r - d * d).sqrt();
    let union = 2.0 * PI - 2.0 * segment(1.0, 0.5);
    let exact = (16.0 - union) * scale;
    let area = mesh_area(&doc.scene.objects[0], 1e-4);
    assert!((area - exact).abs() < 2e-3 * scale, "{area} vs {exact}");
    // The lens between the holes is gone, the plate's far side is kept.
    let kept = |doc: &Document, x: f64, y: f64| {
        let t = doc.scene.objects[0].geometry.as_trimmed().unwrap();
        let c = t
            .surface()
            .closest_point(place.transform_point3(DVec3::new(x, y, 0.0)))
            .unwrap();
        t.contains(c.u, c.v)
    };
    assert!(!kept(&doc, 0.1, 0.2) && kept(&doc, 1.8, -1.8) && !kept(&doc, 1.3, 0.2));
    doc.undo().unwrap();
    assert!(kept(&doc, 1.3, 0.2) && !kept(&doc, -0.9, 0.2));
    doc.undo().unwrap();
    assert_eq!(doc.scene.objects, objects);
}
