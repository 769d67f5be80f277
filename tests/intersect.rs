//! `knotwork intersect` through the real binary: a plane through a sphere and a torus, checked
//! against the closed forms and, independently of the marching, by point inversion onto both
//! surfaces; names that are not there, and objects without faces, are refused.

use std::process::Command;

use glam::DVec3;
use knotwork::io::project::{self, Project};
use knotwork::kernel::{NurbsSurface, construct};
use knotwork::scene::{ObjectGeometry, Scene, SceneObject};

fn write_project(name: &str, objects: Vec<SceneObject>) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("knotwork-intersect-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
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
            let points: Vec<DVec3> = curve["points"]
                .as_array()
                .unwrap()
                .iter()
                .map(|p| {
                    DVec3::new(
                        p[0].as_f64().unwrap(),
                        p[1].as_f64().unwrap(),
                        p[2].as_f64().unwrap(),
                    )
                })
                .collect();
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
