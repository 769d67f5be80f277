//! The export tessellation of trimmed surfaces keeps its tolerance: every triangle, measured at
//! points inside it (not only at its vertices), lies within the tolerance of the surface, with a
//! triangle count close to the untrimmed surface's. Distances come from closed forms.

use glam::{DVec2, DVec3};
use knotwork_kernel::tess::{self, Tessellation, TriangleMesh};
use knotwork_kernel::trim::polygon_contains;
use knotwork_kernel::trim::shapes::{ellipse, polygon, rectangle};
use knotwork_kernel::trim::tess::{flatten_on_surface, tessellate_trimmed};
use knotwork_kernel::{NurbsSurface, TrimLoop, TrimmedSurface, construct};

/// The largest of `distance` over 15 points of each triangle: a barycentric lattice of step
/// 1/4 (corners, edge points and the interior).
fn worst_distance(mesh: &TriangleMesh, distance: impl Fn(DVec3) -> f64) -> f64 {
    let mut worst: f64 = 0.0;
    for t in &mesh.triangles {
        let [a, b, c] = t.map(|k| mesh.positions[k as usize]);
        for i in 0..=4 {
            for j in 0..=4 - i {
                let (s, r) = (i as f64 / 4.0, j as f64 / 4.0);
                worst = worst.max(distance(a + (b - a) * s + (c - a) * r));
            }
        }
    }
    worst
}

/// Every triangle's centroid in (u, v) lies in the kept region of the loops flattened on the
/// surface at a quarter of the tolerance (the boundary the export promises; a triangle between a
/// chord and the curve is the chord's sag, within that share of the tolerance).
fn assert_kept(t: &TrimmedSurface, mesh: &TriangleMesh, tolerance: f64, what: &str) {
    let [(u0, u1), (v0, v1)] = t.surface().domain();
    let polys = flatten_on_surface(t, 0.25 * tolerance).unwrap();
    for tri in &mesh.triangles {
        let c = tri
            .iter()
            .map(|&k| {
                let [s, r] = mesh.uvs[k as usize];
                DVec2::new(u0 + s * (u1 - u0), v0 + r * (v1 - v0))
            })
            .sum::<DVec2>()
            / 3.0;
        let inside = polys.iter().filter(|q| polygon_contains(q, c)).count() % 2 == 1;
        assert!(
            inside,
            "{what}: a triangle at {c} lies outside the kept region"
        );
    }
}

/// Trimmed by each of `cases` at each tolerance: within the tolerance of `distance` inside
/// every triangle, at most 20 times the untrimmed triangle count, only kept triangles.
fn check_cases(
    surface: &NurbsSurface,
    cases: &[(&str, Vec<TrimLoop>)],
    tolerances: &[f64],
    distance: impl Fn(DVec3) -> f64 + Copy,
) {
    for &tolerance in tolerances {
        let grid = tess::tolerance_grid(surface, tolerance).unwrap();
        let untrimmed = tess::triangulate(surface, &grid, false).unwrap();
        let whole = untrimmed.triangles.len();
        let worst = worst_distance(&untrimmed, distance);
        assert!(worst <= tolerance, "untrimmed at {tolerance}: {worst:.3e}");
        for (name, loops) in cases {
            let t = TrimmedSurface::new(surface.clone(), loops.clone()).unwrap();
            let started = std::time::Instant::now();
            let mesh = tessellate_trimmed(&t, Tessellation::Tolerance(tolerance), false).unwrap();
            let elapsed = started.elapsed().as_secs_f64() * 1e3;
            let worst = worst_distance(&mesh, distance);
            let count = mesh.triangles.len();
            eprintln!(
                "{name} at {tolerance}: {count} triangles (untrimmed {whole}), worst {worst:.3e}, {elapsed:.0} ms"
            );
            assert!(worst <= tolerance, "{name} at {tolerance}: {worst:.3e}");
            assert!(count <= 20 * whole, "{name}: {count} against {whole}");
            assert_kept(&t, &mesh, tolerance, name);
        }
    }
}

/// The loops every surface is tried with, at fractions of its domain: an interior rectangle,
/// a loop along three domain edges, a round hole (round in space on a cylinder of radius 1
/// and height 2), the domain boundary itself.
fn cases(surface: &NurbsSurface) -> Vec<(&'static str, Vec<TrimLoop>)> {
    let [(u0, u1), (v0, v1)] = surface.domain();
    let at = |s: f64, r: f64| DVec2::new(u0 + s * (u1 - u0), v0 + r * (v1 - v0));
    let full = || rectangle(at(0.0, 0.0), at(1.0, 1.0)).unwrap();
    let hole = ellipse(
        at(0.4, 0.5),
        DVec2::new(0.3 * (u1 - u0) / TAU_OVER_HEIGHT, 0.3 * (v1 - v0)),
    )
    .unwrap();
    vec![
        (
            "interior rectangle",
            vec![rectangle(at(0.13, 0.21), at(0.71, 0.83)).unwrap()],
        ),
        (
            "three domain edges",
            vec![polygon(&[at(0.0, 0.0), at(1.0, 0.0), at(1.0, 1.0), at(0.0, 0.6)]).unwrap()],
        ),
        ("round hole", vec![full(), hole]),
        ("domain boundary", vec![full()]),
    ]
}

/// The cylinder's circumference over its height (2π / 2): a hole round in space has this
/// ratio between its (u, v) half-axes' shares of the domain.
const TAU_OVER_HEIGHT: f64 = std::f64::consts::PI;

#[test]
fn trimmed_exact_cylinders_keep_every_triangle_within_the_tolerance() {
    // The rational cylinder: degree (2, 1), four C0 quarter spans around, radius 1, height 2.
    let radius = 1.0;
    let cylinder = construct::cylinder(DVec3::ZERO, DVec3::new(0.0, 0.0, 2.0), radius).unwrap();
    assert_eq!(cylinder.degree(), [2, 1]);
    let distance = move |p: DVec3| (p.x.hypot(p.y) - radius).abs();
    check_cases(
        &cylinder,
        &cases(&cylinder),
        &[2.4e-4, 1e-4, 1e-3],
        distance,
    );
}

#[test]
fn trimmed_spheres_and_tori_keep_every_triangle_within_the_tolerance() {
    let (center, radius) = (DVec3::new(1.0, -2.0, 0.5), 2.0);
    let sphere = construct::sphere(center, radius).unwrap();
    let sphere_distance = move |p: DVec3| ((p - center).length() - radius).abs();
    check_cases(&sphere, &cases(&sphere), &[1e-3, 2e-4], sphere_distance);
    let (major, minor) = (3.0, 1.0);
    let torus = construct::torus(DVec3::ZERO, DVec3::Z, major, minor).unwrap();
    let torus_distance = move |p: DVec3| ((p.x.hypot(p.y) - major).hypot(p.z) - minor).abs();
    check_cases(&torus, &cases(&torus), &[1e-3], torus_distance);
}
