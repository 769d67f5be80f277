//! `knotwork intersect` through the real binary: a plane through a sphere and a torus, checked
//! against the closed forms and, independently of the marching, by point inversion onto both
//! surfaces; names that are not there, and objects without faces, are refused.

use std::process::Command;

use glam::DVec3;
use knotwork::io::project::{self, Project};
use knotwork::kernel::{NurbsSurface, construct};
use knotwork::scene::{ObjectGeometry, Scene, SceneObject};

fn write_project(name: &str, objects: Vec<SceneObject>) -> std::path::PathBuf {
    let dir = crate::common::scratch_dir("intersect");
    let path = dir.join(name);
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

fn run(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_knotwork"))
        .arg("intersect")
        .args(args)
        .output()
        .unwrap()
}

fn surface_object(name: &str, surface: NurbsSurface) -> SceneObject {
    SceneObject::new(name, ObjectGeometry::new(surface))
}

#[test]
fn a_plane_through_a_sphere_and_a_torus_is_found_by_the_command() {
    let sphere = construct::sphere(DVec3::new(0.0, 0.0, 0.0), 1.0).unwrap();
    let torus = construct::torus(DVec3::new(5.0, 0.0, 0.0), DVec3::Z, 2.0, 0.5).unwrap();
    let plane = construct::plane(
        DVec3::new(-2.0, -3.0, 0.3),
        DVec3::new(10.0, 0.0, 0.0),
        DVec3::new(0.0, 6.0, 0.0),
    )
    .unwrap();
    let path = write_project(
        "sphere-torus.json",
        vec![
            surface_object("Ball", sphere.clone()),
            surface_object("Ring", torus.clone()),
            surface_object("Cut", plane.clone()),
        ],
    );
    let size = {
        let (lo, hi) = (DVec3::new(-2.0, -3.0, -1.0), DVec3::new(8.0, 3.0, 1.0));
        lo.distance(hi)
    };
    for (name, surface, radii) in [
        ("Ball", &sphere, vec![(1.0f64 - 0.09).sqrt()]),
        (
            "Ring",
            &torus,
            vec![2.0 + (0.25f64 - 0.09).sqrt(), 2.0 - (0.25f64 - 0.09).sqrt()],
        ),
    ] {
        let out = run(&[path.to_str().unwrap(), "--objects", name, "Cut"]);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "{stderr}");
        eprintln!("{name}: {}", stderr.trim());
        let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        let curves = json["curves"].as_array().unwrap();
        assert!(!curves.is_empty(), "{name}");
        let centre = if name == "Ball" {
            DVec3::ZERO
        } else {
            DVec3::new(5.0, 0.0, 0.0)
        };
        let mut length = 0.0;
        for curve in curves {
            let points = json_points(&curve["points"]);
            assert_eq!(
                curve["uv"][name].as_array().unwrap().len(),
                points.len(),
                "uv per point, keyed by the object's name"
            );
            assert_eq!(curve["uv"]["Cut"].as_array().unwrap().len(), points.len());
            for p in &points {
                // Within 1e-6 of the scene's size of both surfaces, by point inversion.
                let on_surface = surface.closest_point(*p).unwrap().distance;
                let on_plane = plane.closest_point(*p).unwrap().distance;
                assert!(on_surface <= 1e-6 * size && on_plane <= 1e-6 * size, "{p}");
                let rho = (*p - centre).truncate().length();
                let off = radii
                    .iter()
                    .map(|r| (rho - r).abs())
                    .fold(f64::INFINITY, f64::min);
                assert!(off < 1e-7 && (p.z - 0.3).abs() < 1e-7, "{name}: {p}");
            }
            length += points.windows(2).map(|w| w[0].distance(w[1])).sum::<f64>();
        }
        // Chords within e = 1e-3 of the size of a circle of radius r fall short of its length
        // by about e/(3r) of it; a polyline never exceeds its circles' length.
        let expected: f64 = radii.iter().map(|r| std::f64::consts::TAU * r).sum();
        let smallest = radii.iter().copied().fold(f64::INFINITY, f64::min);
        let short = expected * 1e-3 * size / (2.0 * smallest);
        assert!(
            length <= expected * (1.0 + 1e-9) && length >= expected - short,
            "{name}: {length} vs {expected}"
        );
    }

    // A curve meets the sphere at points: a circle in the equator's plane, centred off the
    // axis, crosses the equator at x = 1/4; another circle crosses it at two points too.
    let curve = construct::circle(DVec3::new(0.5, 0.0, 0.0), DVec3::Z, DVec3::X, 1.0).unwrap();
    let other = construct::circle(DVec3::new(-0.5, 0.0, 0.0), DVec3::Z, DVec3::X, 1.0).unwrap();
    let mesh =
        knotwork::kernel::PolygonMesh::new(vec![DVec3::ZERO, DVec3::X, DVec3::Y], &[vec![0, 1, 2]])
            .unwrap();
    let with_curve = write_project(
        "with-curve.json",
        vec![
            surface_object("Ball", sphere),
            SceneObject::new("Hoop", ObjectGeometry::new(curve)),
            SceneObject::new("Ring", ObjectGeometry::new(other)),
            SceneObject::new("Sheet", ObjectGeometry::new(mesh)),
        ],
    );
    let out = run(&[with_curve.to_str().unwrap(), "--objects", "Ball", "Hoop"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let points = json["points"].as_array().unwrap();
    assert_eq!(points.len(), 2, "{json}");
    for p in points {
        let xyz: Vec<f64> = p["point"]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap())
            .collect();
        assert!(
            (xyz[0] - 0.25).abs() < 1e-6 && (xyz[1].abs() - 0.9375f64.sqrt()).abs() < 1e-6,
            "{p}"
        );
        assert!(p["uv"]["Ball"].is_array() && p["t"]["Hoop"].is_number());
    }
    let out = run(&[with_curve.to_str().unwrap(), "--objects", "Hoop", "Ring"]);
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let points = json["points"].as_array().unwrap();
    assert_eq!(points.len(), 2, "{json}");
    assert!(
        points
            .iter()
            .all(|p| p["point"][0].as_f64().unwrap().abs() < 1e-6)
    );
    // An object without faces (a polygon mesh) and a name that is not there are refused.
    let out = run(&[with_curve.to_str().unwrap(), "--objects", "Ball", "Sheet"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        String::from_utf8_lossy(&out.stderr).contains("which has no faces"),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let out = run(&[with_curve.to_str().unwrap(), "--objects", "Ball", "Nowhere"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("no object named \"Nowhere\""));
    let out = run(&[
        with_curve.to_str().unwrap(),
        "--objects",
        "Ball",
        "Ball",
        "--tolerance=-1",
    ]);
    assert_eq!(out.status.code(), Some(1));
}

/// The points of a JSON array of [x, y, z].
fn json_points(v: &serde_json::Value) -> Vec<DVec3> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|p| {
            DVec3::new(
                p[0].as_f64().unwrap(),
                p[1].as_f64().unwrap(),
                p[2].as_f64().unwrap(),
            )
        })
        .collect()
}

/// Two crossing cylinders in general position (a thin one through a thick one, rotated and
/// moved four ways, so that the loops cross the cylinders' seams in different places): the
/// command reports two closed loops, each as one closed branch; every point lies on both
/// cylinders.
#[test]
fn crossing_cylinders_give_two_closed_loops_by_the_command() {
    for (k, angles) in [
        (0.3, -1.2, 2.1),
        (1.7, 0.4, -0.8),
        (-2.5, 1.1, 0.2),
        (0.0, 0.0, 0.0),
    ]
    .into_iter()
    .enumerate()
    {
        let place = glam::DAffine3::from_rotation_translation(
            glam::DQuat::from_euler(glam::EulerRot::ZXY, angles.0, angles.1, angles.2),
            DVec3::new(3.0, -1.0, 0.5 * k as f64),
        );
        let thick = construct::cylinder(DVec3::new(0.0, 0.0, -2.0), DVec3::Z * 4.0, 1.0)
            .unwrap()
            .transformed(&place)
            .unwrap();
        let thin = construct::cylinder(DVec3::new(-2.0, 0.1, 0.2), DVec3::X * 4.0, 0.6)
            .unwrap()
            .transformed(&place)
            .unwrap();
        let path = write_project(
            &format!("crossing-cylinders-{k}.json"),
            vec![surface_object("Thick", thick), surface_object("Thin", thin)],
        );
        let out = run(&[path.to_str().unwrap(), "--objects", "Thick", "Thin"]);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "{stderr}");
        let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        let curves = json["curves"].as_array().unwrap();
        let closed: Vec<bool> = curves
            .iter()
            .map(|c| c["closed"].as_bool().unwrap())
            .collect();
        assert_eq!(closed, [true, true], "placement {k}: {stderr}");
        let back = place.inverse();
        for curve in curves {
            for p in json_points(&curve["points"]) {
                let q = back.transform_point3(p);
                let to_thick = (q.x.hypot(q.y) - 1.0).abs();
                let to_thin = ((q.y - 0.1).hypot(q.z - 0.2) - 0.6).abs();
                assert!(to_thick.max(to_thin) < 1e-6, "{q}");
            }
        }
    }
}

/// Random surface pairs in general position intersected by knotwork and by OpenCASCADE
/// (GeomAPI_IntSS; tests/reference/occ/intersections.jsonl, made by make_intersections.py
/// beside it): every point knotwork finds lies on both surfaces (1e-6 of the size), and every
/// point of OpenCASCADE's lines that lies on both within 1e-3 of the size (the chord
/// tolerance) of knotwork's branches: none missed (but a piece smaller than the smallest loop
/// the marching promises, 1e-2 of the size), none cut short. How far knotwork's points
/// are from OpenCASCADE's lines is printed (where OpenCASCADE misses a branch, far). A longer run:
/// `KNOTWORK_RANDOM_INTERSECT=FILE` (a file the script wrote).
mod against_occ {
    use glam::DVec3;
    use knotwork::kernel::NurbsSurface;
    use knotwork::kernel::intersect::{IntersectOptions, intersect_surfaces};
    use serde_json::Value;

    fn surface(record: &Value) -> NurbsSurface {
        let pair = |v: &Value| {
            [
                v[0].as_u64().unwrap() as usize,
                v[1].as_u64().unwrap() as usize,
            ]
        };
        let numbers = |v: &Value| -> Vec<f64> {
            v.as_array()
                .unwrap()
                .iter()
                .map(|x| x.as_f64().unwrap())
                .collect()
        };
        let points = super::json_points(&record["points"]);
        NurbsSurface::new(
            pair(&record["degree"]),
            [numbers(&record["knots"][0]), numbers(&record["knots"][1])],
            pair(&record["count"]),
            points,
            Some(numbers(&record["weights"])),
        )
        .unwrap()
    }

    fn to_polyline(p: DVec3, line: &[DVec3]) -> f64 {
        line.windows(2)
            .map(|w| {
                let d = w[1] - w[0];
                let t = ((p - w[0]).dot(d) / d.length_squared().max(1e-300)).clamp(0.0, 1.0);
                p.distance(w[0] + d * t)
            })
            .fold(f64::INFINITY, f64::min)
    }

    /// The worst distances, as fractions of the size: knotwork's points off either surface,
    /// off OpenCASCADE's lines, and OpenCASCADE's points off knotwork's branches.
    fn compare(case: &Value) -> Result<[f64; 3], String> {
        let (a, b) = (surface(&case["a"]), surface(&case["b"]));
        let (mut lo, mut hi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
        for s in [&a, &b] {
            for h in s.homogeneous_points() {
                let p = h.truncate() / h.w;
                lo = lo.min(p);
                hi = hi.max(p);
            }
        }
        let size = lo.distance(hi);
        let options = IntersectOptions::for_size(size);
        let found = intersect_surfaces(&a, &b, &options).map_err(|e| e.to_string())?;
        let theirs: Vec<Vec<DVec3>> = case["curves"]
            .as_array()
            .unwrap()
            .iter()
            .map(super::json_points)
            .collect();
        let ours: Vec<&[DVec3]> = found.curves.iter().map(|c| c.points.as_slice()).collect();
        if ours.is_empty() {
            return Err(format!(
                "no branch; OpenCASCADE has {} line(s)",
                theirs.len()
            ));
        }
        let mut worst = [0.0f64; 3];
        for branch in &ours {
            for (k, &p) in branch.iter().enumerate() {
                if k % 4 == 0 {
                    let off = a
                        .closest_point(p)
                        .map_err(|e| e.to_string())?
                        .distance
                        .max(b.closest_point(p).map_err(|e| e.to_string())?.distance);
                    worst[0] = worst[0].max(off / size);
                }
                let near = theirs
                    .iter()
                    .map(|l| to_polyline(p, l))
                    .fold(f64::INFINITY, f64::min);
                worst[1] = worst[1].max(near / size);
            }
        }
        for line in &theirs {
            // A piece smaller than the smallest loop the marching promises to find (1e-2 of
            // the size: a corner clipped by 1e-4, say) may be missed.
            let extent = line.iter().map(|p| p.distance(line[0])).fold(0.0, f64::max);
            if extent < options.smallest {
                continue;
            }
            for &p in line {
                // A point of OpenCASCADE's line that is not on both surfaces is its own error
                // (its lines are approximations): not compared.
                let on_a = a.closest_point(p).map_err(|e| e.to_string())?.distance;
                let on_b = b.closest_point(p).map_err(|e| e.to_string())?.distance;
                if on_a.max(on_b) > 1e-6 * size {
                    continue;
                }
                let near = ours
                    .iter()
                    .map(|l| to_polyline(p, l))
                    .fold(f64::INFINITY, f64::min);
                worst[2] = worst[2].max(near / size);
            }
        }
        Ok(worst)
    }

    fn run(path: &std::path::Path) {
        let text = std::fs::read_to_string(path).unwrap();
        let mut failed = Vec::new();
        let mut count = 0;
        let mut worst_all = [0.0f64; 3];
        for line in text.lines().filter(|l| !l.trim().is_empty()) {
            let case: Value = serde_json::from_str(line).unwrap();
            let seed = case["seed"].as_u64().unwrap();
            count += 1;
            match compare(&case) {
                Ok(worst) => {
                    for k in 0..3 {
                        worst_all[k] = worst_all[k].max(worst[k]);
                    }
                    // Branches of ours away from OpenCASCADE's lines are its misses where
                    // their points lie on both surfaces (worst[0]), so only reported.
                    if worst[0] > 1e-6 || worst[2] > 1e-3 {
                        failed.push(format!(
                            "seed {seed} ({} {}): off the surfaces {:.2e}, off OpenCASCADE's \
                             lines {:.2e}, OpenCASCADE's points off ours {:.2e}",
                            case["kind"], case["rational"], worst[0], worst[1], worst[2]
                        ));
                    }
                }
                Err(e) => failed.push(format!("seed {seed}: {e}")),
            }
        }
        eprintln!(
            "{count} surface pairs; worst (of the size): on the surfaces {:.2e}, to \
             OpenCASCADE's lines {:.2e}, from them {:.2e}; {} failed",
            worst_all[0],
            worst_all[1],
            worst_all[2],
            failed.len()
        );
        assert!(failed.is_empty(), "{}", failed.join("\n"));
    }

    #[test]
    fn random_surface_pairs_meet_where_opencascade_says() {
        run(&std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("tests/reference/occ/intersections.jsonl"));
        if let Ok(more) = std::env::var("KNOTWORK_RANDOM_INTERSECT") {
            run(std::path::Path::new(&more));
        }
    }
}
