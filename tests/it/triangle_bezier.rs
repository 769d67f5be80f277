//! Triangular Bézier patches against analytic surfaces and their own invariants: a quadratic
//! patch is exactly the paraboloid z = x² + y² over its triangle, and the compute shaders'
//! positions and curvatures match the paraboloid's (K = 4/(1 + 4r²)², H = 2(1 + 2r²)/(1 +
//! 4r²)^(3/2)); the GPU matches the f64 de Casteljau for degrees 1 to 7; degree elevation
//! changes nothing on the GPU; the project file round-trips and refuses bad patches with the
//! field named; the export's triangles stay within the tolerance.

use crate::common;

use glam::{DVec2, DVec3};
use knotwork::doc::Document;
use knotwork::gpu::{SceneSync, SurfaceVertex};
use knotwork::io::project::{self, Project};
use knotwork::kernel::tess::Tessellation;
use knotwork::kernel::triangle::{TriangleBezier, lattice_index, point_count};
use knotwork::scene::{ObjectGeometry, ObjectKind, Scene, SceneObject};

/// The paraboloid z = x² + y² over the triangle a, b, c as a quadratic patch: its blossom is
/// f(p, q) = (mean of p and q, p·q), so b_200 = (a, a·a), b_110 = ((a + b)/2, a·b) and so on
/// (u at a, v at b, w at c).
fn paraboloid(a: DVec2, b: DVec2, c: DVec2) -> TriangleBezier {
    let point = |p: DVec2, q: DVec2| {
        let m = (p + q) / 2.0;
        DVec3::new(m.x, m.y, p.dot(q))
    };
    let mut points = vec![DVec3::ZERO; 6];
    for (i, j, p, q) in [
        (2, 0, a, a),
        (0, 2, b, b),
        (0, 0, c, c),
        (1, 1, a, b),
        (1, 0, a, c),
        (0, 1, b, c),
    ] {
        points[lattice_index(2, i, j)] = point(p, q);
    }
    TriangleBezier::new(2, points).unwrap()
}

/// A patch of degree n with points on a wavy dome.
fn dome(n: usize) -> TriangleBezier {
    let mut points = Vec::with_capacity(point_count(n));
    for j in 0..=n {
        for i in 0..=n - j {
            let (x, y) = (i as f64 / n as f64, j as f64 / n as f64);
            let z = (3.0 * x).sin() * (2.0 * y).cos() + 0.3 * x * y;
            points.push(DVec3::new(x + 0.5 * y, y, z));
        }
    }
    TriangleBezier::new(n, points).unwrap()
}

fn object(patch: TriangleBezier) -> SceneObject {
    SceneObject::new("triangle", ObjectGeometry::boxed(Box::new(patch)))
}

/// The compute shaders' vertices of `object` alone, with their lattice (s, t) (slots past the
/// diagonal left out).
fn gpu_vertices(object: &SceneObject) -> Vec<(f64, f64, SurfaceVertex)> {
    let context = common::gpu();
    let doc = Document::new(Scene {
        objects: vec![object.clone()],
        unit: None,
    });
    let mut sync = SceneSync::new(&context.device, &context.queue);
    sync.rebuild(&doc.scene, 1.0).unwrap();
    sync.evaluate_blocking().unwrap();
    let vertices = sync.read_vertices().unwrap();
    let records = sync.records().unwrap();
    assert_eq!(records.len(), 1, "one stencil patch");
    let n = records[0].segments_u;
    let mut out = Vec::new();
    for i in 0..=n {
        for j in 0..=n - i {
            let v = vertices[(records[0].vertex_offset + i * (n + 1) + j) as usize];
            let (s, t) = (f64::from(i) / f64::from(n), f64::from(j) / f64::from(n));
            out.push((s, t, v));
        }
    }
    out
}

#[test]
fn a_quadratic_patch_is_the_paraboloid_and_the_gpu_gives_its_curvature() {
    let (a, b, c) = (
        DVec2::new(1.2, -0.3),
        DVec2::new(-0.4, 0.9),
        DVec2::new(-0.2, -0.8),
    );
    let patch = paraboloid(a, b, c);
    let vertices = gpu_vertices(&object(patch.clone()));
    assert!(vertices.len() > 100);
    let mut worst = [0.0f64; 3];
    for (s, t, v) in vertices {
        let xy = a * s + b * t + c * (1.0 - s - t);
        let exact = DVec3::new(xy.x, xy.y, xy.length_squared());
        let p = DVec3::from(v.position.map(f64::from));
        // f64 de Casteljau: the paraboloid to rounding.
        assert!(patch.evaluate(s, t).point.distance(exact) < 1e-13);
        worst[0] = worst[0].max(p.distance(exact));
        // Curvature of z = r²: K = 4/(1 + 4r²)², |H| = 2(1 + 2r²)/(1 + 4r²)^(3/2).
        let q = 1.0 + 4.0 * xy.length_squared();
        let (k, h) = (
            4.0 / (q * q),
            2.0 * (1.0 + 2.0 * xy.length_squared()) / q.powf(1.5),
        );
        let [gk, gh, _, _] = v.curvature().map(f64::from);
        worst[1] = worst[1].max((gk - k).abs() / k);
        worst[2] = worst[2].max((gh.abs() - h).abs() / h);
        assert_eq!(v.flags() & 2, 0, "curvature defined at ({s}, {t})");
        // The normal is the paraboloid's (up to orientation): (−2x, −2y, 1) normalized.
        let normal = DVec3::new(-2.0 * xy.x, -2.0 * xy.y, 1.0).normalize();
        let n = DVec3::from(v.normal.map(f64::from));
        assert!(n.dot(normal).abs() > 1.0 - 1e-5, "normal {n} vs {normal}");
    }
    eprintln!(
        "paraboloid on the GPU: position {:.1e}, K {:.1e}, H {:.1e} (relative)",
        worst[0], worst[1], worst[2]
    );
    assert!(worst[0] < 1e-5, "{worst:?}");
    assert!(worst[1] < 1e-3 && worst[2] < 1e-3, "{worst:?}");
}

#[test]
fn the_gpu_matches_de_casteljau_and_elevation_changes_nothing() {
    for n in 1..=7 {
        let patch = dome(n);
        let size = {
            let (lo, hi) = patch.bounds().unwrap();
            lo.distance(hi)
        };
        let before = gpu_vertices(&object(patch.clone()));
        let mut worst: f64 = 0.0;
        for &(s, t, v) in &before {
            let p = DVec3::from(v.position.map(f64::from));
            worst = worst.max(p.distance(patch.evaluate(s, t).point) / size);
        }
        assert!(worst < 1e-5, "degree {n}: {worst:e}");
        // Elevation: the same points on the same lattice (the viewport's lattice grows with the
        // degree, so compare at the f64 parameters of each vertex).
        let up = patch.elevated().unwrap();
        assert_eq!(up.degree(), n + 1);
        let after = gpu_vertices(&object(up));
        let mut moved: f64 = 0.0;
        for &(s, t, v) in &after {
            let p = DVec3::from(v.position.map(f64::from));
            moved = moved.max(p.distance(patch.evaluate(s, t).point) / size);
        }
        assert!(moved < 1e-5, "degree {n} elevated: {moved:e}");
    }
}

#[test]
fn the_project_file_round_trips_and_refuses_bad_patches() {
    let patch = dome(3);
    let text = project::write(&Project {
        scene: Scene {
            objects: vec![object(patch.clone())],
            unit: None,
        },
        view: None,
    });
    assert!(text.contains("\"triangular_bezier\""));
    let back = project::read(&text).unwrap();
    assert_eq!(back.scene.objects, vec![object(patch)]);
    let bad = |body: &str| {
        let text = format!(
            r#"{{"format": "knotwork", "version": 2, "objects": [{{"type": "triangular_bezier", {body}}}]}}"#
        );
        project::read(&text).unwrap_err().to_string()
    };
    let e = bad(r#""degree": 2, "points": [[0,0,0],[1,0,0],[0,1,0]]"#);
    assert!(e.contains("points") && e.contains('6'), "{e}");
    let e = bad(r#""degree": 0, "points": [[0,0,0]]"#);
    assert!(e.contains("degree"), "{e}");
    let e = bad(r#""degree": 1, "points": [[0,0,0],[1,0,0],[0,1,1e999]]"#);
    assert!(!e.is_empty(), "{e}");
}

#[test]
fn the_export_stays_within_the_tolerance() {
    let patch = dome(5);
    let tolerance = 1e-3;
    let meshes = object(patch.clone())
        .tessellate(Tessellation::Tolerance(tolerance), true)
        .unwrap();
    let mesh = &meshes[0];
    assert_eq!(mesh.curvatures.len(), mesh.positions.len());
    // Every triangle's centroid against the patch at the centroid's parameters.
    let mut worst: f64 = 0.0;
    for t in &mesh.triangles {
        let uv = t.map(|k| mesh.uvs[k as usize]);
        let (u, v) = (
            (uv[0][0] + uv[1][0] + uv[2][0]) / 3.0,
            (uv[0][1] + uv[1][1] + uv[2][1]) / 3.0,
        );
        let centroid = t
            .iter()
            .fold(DVec3::ZERO, |a, &k| a + mesh.positions[k as usize])
            / 3.0;
        worst = worst.max(centroid.distance(patch.evaluate(u, v).point));
    }
    assert!(worst <= tolerance, "{worst}");
    assert!(worst > tolerance / 100.0, "not needlessly fine: {worst}");
}
