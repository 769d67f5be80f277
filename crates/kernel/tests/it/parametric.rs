//! The one surface interface: the square view of a triangular patch against finite differences,
//! continuity across two triangular patches against the closed-form angle and curvature, and a
//! face shown through a lattice or a displacement against the closed-form map.

use glam::{DVec2, DVec3};
use knotwork_kernel::construct;
use knotwork_kernel::continuity::{Continuity, Tolerances, shared_edges};
use knotwork_kernel::diffgeo::SurfaceDerivatives;
use knotwork_kernel::displace::{Displacement, Pattern};
use knotwork_kernel::ffd::Lattice;
use knotwork_kernel::parametric::{
    FaceDisplacement, ParametricSurface, ShownFace, TriangleAsSquare,
};
use knotwork_kernel::triangle::{TriangleBezier, lattice_index};

/// The quadratic triangular patch of the graph z = f(x, y) over the triangle with (x, y)
/// corners `u`, `v`, `w` (exact for a quadratic f): corner points on the graph, and each edge's
/// middle point 2 f(mid) − (f(a) + f(b)) / 2 high, so that the edge's quadratic passes through
/// the graph at its midpoint.
fn graph_patch(corners: [DVec2; 3], f: impl Fn(DVec2) -> f64) -> TriangleBezier {
    let [u, v, w] = corners;
    let lift = |p: DVec2, z: f64| DVec3::new(p.x, p.y, z);
    let mut points = vec![DVec3::ZERO; 6];
    let corner = |p: DVec2| lift(p, f(p));
    let middle = |a: DVec2, b: DVec2| {
        let m = 0.5 * (a + b);
        lift(m, 2.0 * f(m) - 0.5 * (f(a) + f(b)))
    };
    points[lattice_index(2, 2, 0)] = corner(u);
    points[lattice_index(2, 0, 2)] = corner(v);
    points[lattice_index(2, 0, 0)] = corner(w);
    points[lattice_index(2, 1, 1)] = middle(u, v);
    points[lattice_index(2, 1, 0)] = middle(u, w);
    points[lattice_index(2, 0, 1)] = middle(v, w);
    TriangleBezier::new(2, points).unwrap()
}

fn close(a: DVec3, b: DVec3, tolerance: f64, what: &str) {
    assert!(a.distance(b) <= tolerance, "{what}: {a} against {b}");
}

/// Every derivative of `face` at (s, t) against central differences of its point (step h).
fn check_against_differences(face: &dyn ParametricSurface, s: f64, t: f64, h: f64, tolerance: f64) {
    let p = |a: f64, b: f64| face.point(a, b).unwrap();
    let d = face.derivatives(s, t).unwrap();
    close(
        d.su,
        (p(s + h, t) - p(s - h, t)) / (2.0 * h),
        tolerance,
        "Su",
    );
    close(
        d.sv,
        (p(s, t + h) - p(s, t - h)) / (2.0 * h),
        tolerance,
        "Sv",
    );
    let c = p(s, t);
    close(
        d.suu,
        (p(s + h, t) - c * 2.0 + p(s - h, t)) / (h * h),
        tolerance,
        "Suu",
    );
    close(
        d.svv,
        (p(s, t + h) - c * 2.0 + p(s, t - h)) / (h * h),
        tolerance,
        "Svv",
    );
    let mixed =
        (p(s + h, t + h) - p(s + h, t - h) - p(s - h, t + h) + p(s - h, t - h)) / (4.0 * h * h);
    close(d.suv, mixed, tolerance, "Suv");
}

#[test]
fn a_triangular_patch_over_the_square_has_the_chain_rule_derivatives() {
    // A cubic patch with uneven points, so every second derivative is non-zero.
    let points: Vec<DVec3> = (0..10)
        .map(|k| {
            let k = k as f64;
            DVec3::new((0.7 * k).sin() * 2.0, (1.3 * k).cos(), 0.3 * k * k - k)
        })
        .collect();
    let patch = TriangleBezier::new(3, points).unwrap();
    let square = TriangleAsSquare(&patch);
    for (s, t) in [(0.3, 0.2), (0.5, 0.5), (0.8, 0.1), (0.1, 0.7)] {
        check_against_differences(&square, s, t, 1e-4, 1e-5);
        // The same point of the triangle: u = s (1 − t), v = t.
        close(
            square.point(s, t).unwrap(),
            patch.evaluate(s * (1.0 - t), t).point,
            1e-14,
            "point",
        );
    }
    // The side t = 1 collapses to the corner (0, 1).
    close(
        square.point(0.2, 1.0).unwrap(),
        square.point(0.9, 1.0).unwrap(),
        1e-14,
        "corner",
    );
}

fn tolerances() -> Tolerances {
    Tolerances {
        matching: 1e-3,
        distance: 1e-6,
        angle_degrees: 0.1,
        curvature: 1e-3,
        samples: 17,
    }
}

#[test]
fn two_triangular_patches_share_their_edge_with_its_true_angle_and_curvature() {
    // Two triangles either side of the edge x = 0, 0 ≤ y ≤ 1.
    let left = [
        DVec2::new(0.0, 0.0),
        DVec2::new(0.0, 1.0),
        DVec2::new(-1.0, 0.0),
    ];
    let right = [
        DVec2::new(0.0, 1.0),
        DVec2::new(0.0, 0.0),
        DVec2::new(1.0, 0.0),
    ];
    // One paraboloid on both sides: G2, no gap, no angle.
    let paraboloid = |p: DVec2| p.length_squared();
    let (a, b) = (
        graph_patch(left, paraboloid),
        graph_patch(right, paraboloid),
    );
    let (fa, fb) = (TriangleAsSquare(&a), TriangleAsSquare(&b));
    let edges = shared_edges(&[&fa, &fb], &tolerances(), 2.0);
    assert_eq!(edges.len(), 1, "{edges:?}");
    let edge = &edges[0];
    assert_eq!(edge.verdict, Continuity::G2);
    assert!(edge.max_gap.value < 1e-12 && edge.max_angle_degrees.value < 1e-6);
    // A plane and a plane rising at slope 0.4 across the edge: the angle is atan 0.4.
    let slope = 0.4;
    let (a, b) = (
        graph_patch(left, |_| 0.0),
        graph_patch(right, |p| slope * p.x),
    );
    let (fa, fb) = (TriangleAsSquare(&a), TriangleAsSquare(&b));
    let edges = shared_edges(&[&fa, &fb], &tolerances(), 2.0);
    assert_eq!(edges.len(), 1);
    assert_eq!(edges[0].verdict, Continuity::G0);
    let angle = edges[0].max_angle_degrees.value;
    assert!((angle - slope.atan().to_degrees()).abs() < 1e-9, "{angle}");
    // z = x² to the right of a plane: tangent across the edge, but the normal curvature
    // across it jumps from 0 to 2 (z'' = 2 with z' = 0): G1, difference 2.
    let b = graph_patch(right, |p| p.x * p.x);
    let a = graph_patch(left, |_| 0.0);
    let (fa, fb) = (TriangleAsSquare(&a), TriangleAsSquare(&b));
    let edges = shared_edges(&[&fa, &fb], &tolerances(), 2.0);
    assert_eq!(edges[0].verdict, Continuity::G1);
    let jump = edges[0].max_curvature_difference.value;
    assert!((jump - 2.0).abs() < 1e-9, "{jump}");
}

#[test]
fn a_face_through_an_affine_lattice_has_the_mapped_derivatives() {
    let sphere = construct::sphere(DVec3::new(0.3, -0.2, 0.1), 1.0).unwrap();
    // A trilinear lattice whose points are an affine image of its box's corners is that
    // affine map everywhere: F(X) = M X + c, so every derivative is multiplied by M.
    let m = glam::DMat3::from_cols(
        DVec3::new(1.2, 0.1, -0.3),
        DVec3::new(0.2, 0.8, 0.1),
        DVec3::new(-0.1, 0.4, 1.5),
    );
    let c = DVec3::new(0.5, -1.0, 2.0);
    let undisturbed = Lattice::around(DVec3::splat(-1.5), DVec3::splat(1.5), [1, 1, 1]).unwrap();
    let moved: Vec<DVec3> = undisturbed.points().iter().map(|&p| m * p + c).collect();
    let lattice = Lattice::new(undisturbed.origin(), undisturbed.axes(), [1, 1, 1], moved).unwrap();
    let shown = ShownFace {
        face: &sphere,
        displacement: None,
        lattice: Some(&lattice),
    };
    let [(u0, u1), (v0, v1)] = sphere.domain();
    for (s, t) in [(0.2, 0.3), (0.6, 0.7), (0.9, 0.45)] {
        let (u, v) = (u0 + s * (u1 - u0), v0 + t * (v1 - v0));
        let d = sphere.evaluate(u, v).unwrap();
        let e = shown.derivatives(u, v).unwrap();
        close(e.point, m * d.point + c, 1e-12, "point");
        for (a, b, what) in [
            (e.su, d.su, "Su"),
            (e.sv, d.sv, "Sv"),
            (e.suu, d.suu, "Suu"),
            (e.suv, d.suv, "Suv"),
            (e.svv, d.svv, "Svv"),
        ] {
            close(a, m * b, 1e-10 * (1.0 + b.length()), what);
        }
    }
}

#[test]
fn a_displaced_plane_has_the_derivatives_of_its_height_field() {
    // The unit square z = 0 displaced by waves: P = (u, v, a sin(wu) sin(wv)), w = 2π f.
    let plane = construct::plane(DVec3::ZERO, DVec3::X, DVec3::Y).unwrap();
    let (a, f) = (0.05, 2.0);
    let map = Displacement::new(Pattern::Waves, a, f).unwrap();
    let shown = ShownFace {
        face: &plane,
        displacement: Some(FaceDisplacement {
            map: &map,
            domain: [0.0, 1.0, 0.0, 1.0],
        }),
        lattice: None,
    };
    let w = std::f64::consts::TAU * f;
    let exact = |u: f64, v: f64| {
        let ((su, cu), (sv, cv)) = ((w * u).sin_cos(), (w * v).sin_cos());
        SurfaceDerivatives {
            point: DVec3::new(u, v, a * su * sv),
            su: DVec3::new(1.0, 0.0, a * w * cu * sv),
            sv: DVec3::new(0.0, 1.0, a * w * su * cv),
            suu: DVec3::new(0.0, 0.0, -a * w * w * su * sv),
            suv: DVec3::new(0.0, 0.0, a * w * w * cu * cv),
            svv: DVec3::new(0.0, 0.0, -a * w * w * su * sv),
        }
    };
    // Inside, and on the sides, where the second derivatives are one-sided differences.
    for (u, v) in [
        (0.31, 0.47),
        (0.0, 0.2),
        (1.0, 0.65),
        (0.4, 0.0),
        (0.77, 1.0),
    ] {
        let (d, e) = (shown.derivatives(u, v).unwrap(), exact(u, v));
        close(d.point, e.point, 1e-12, "point");
        close(d.su, e.su, 1e-12, "Su");
        close(d.sv, e.sv, 1e-12, "Sv");
        // Differences with a step of 1e-4: second order, w² a ≈ 7.9 times (w h)² / 6.
        for (x, y, what) in [
            (d.suu, e.suu, "Suu"),
            (d.suv, e.suv, "Suv"),
            (d.svv, e.svv, "Svv"),
        ] {
            close(x, y, 1e-5, what);
        }
    }
}
