//! The NURBS kernel against analytic values: exact sphere, cylinder, cone, torus and plane
//! curvatures, circles, independent Bernstein evaluation, finite differences, point inversion,
//! constructors and the validation errors.

use std::f64::consts::{FRAC_PI_2, PI, TAU};

use glam::{DAffine3, DVec2, DVec3};
use knotwork_kernel::basis::uniform_clamped_knots;
use knotwork_kernel::construct;
use knotwork_kernel::{
    BezierPatchSet, Direction, GeometryError, NurbsSurface, SpaceCurve, TrimCurve, samples,
};

const TOL: f64 = 1e-12;

/// Interior parameters of a surface on an n × n grid (avoiding the domain boundary).
fn interior_params(s: &NurbsSurface, n: usize) -> Vec<(f64, f64)> {
    let [(u0, u1), (v0, v1)] = s.domain();
    let mut out = Vec::new();
    for i in 0..n {
        for j in 0..n {
            let a = (i as f64 + 0.37) / n as f64;
            let b = (j as f64 + 0.61) / n as f64;
            out.push((u0 + (u1 - u0) * a, v0 + (v1 - v0) * b));
        }
    }
    out
}

#[test]
fn sphere_has_constant_curvature() {
    let (c, r) = (DVec3::new(0.5, -1.0, 2.0), 2.5);
    let s = construct::sphere(c, r).unwrap();
    for (u, v) in interior_params(&s, 9) {
        let g = s.local_geometry(u, v).unwrap();
        let p = g.derivatives.point;
        assert!((p.distance(c) - r).abs() < TOL * r, "radius at ({u}, {v})");
        let outward = (p - c) / r;
        assert!(
            g.normal.distance(outward) < 1e-12,
            "normal {:?} vs {outward:?}",
            g.normal
        );
        let k = g.curvature;
        assert!(
            (k.gaussian - 1.0 / (r * r)).abs() < TOL,
            "K = {}",
            k.gaussian
        );
        assert!((k.mean + 1.0 / r).abs() < TOL, "H = {}", k.mean);
        assert!((k.k1 + 1.0 / r).abs() < 1e-7 && (k.k2 + 1.0 / r).abs() < 1e-7);
        assert!(k.directions.is_none(), "a sphere is all umbilics");
    }
}

#[test]
fn sphere_poles_have_limit_normals_and_curvature() {
    let s = construct::sphere(DVec3::ZERO, 1.0).unwrap();
    let [(u0, u1), (v0, v1)] = s.domain();
    for u in [u0, 0.3 * (u0 + u1), u1] {
        for (v, expected) in [(v0, -DVec3::Z), (v1, DVec3::Z)] {
            let g = s.local_geometry(u, v).unwrap();
            assert!(!g.regular);
            assert!(
                g.normal.distance(expected) < 1e-9,
                "pole normal {:?}",
                g.normal
            );
            assert!(
                (g.curvature.gaussian - 1.0).abs() < 1e-4,
                "{:?}",
                g.curvature
            );
            assert!(g.curvature.mean.is_finite());
        }
    }
}

#[test]
fn cylinder_curvature() {
    let r = 0.75;
    let s = construct::cylinder(DVec3::new(1.0, 2.0, 3.0), DVec3::new(0.0, 0.0, 4.0), r).unwrap();
    for (u, v) in interior_params(&s, 8) {
        let g = s.local_geometry(u, v).unwrap();
        let p = g.derivatives.point;
        let radial = DVec3::new(p.x - 1.0, p.y - 2.0, 0.0);
        assert!((radial.length() - r).abs() < TOL);
        assert!(g.normal.distance(radial / r) < 1e-12);
        let k = g.curvature;
        assert!(k.gaussian.abs() < TOL, "K = {}", k.gaussian);
        assert!((k.mean + 1.0 / (2.0 * r)).abs() < TOL, "H = {}", k.mean);
        assert!(k.k1.abs() < TOL && (k.k2 + 1.0 / r).abs() < TOL);
        let [d1, d2] = k.directions.expect("not an umbilic");
        assert!(
            d1.cross(DVec3::Z).length() < 1e-9,
            "k1 = 0 along the axis: {d1:?}"
        );
        assert!(d2.dot(DVec3::Z).abs() < 1e-9 && d2.dot(radial).abs() < 1e-9);
    }
}

#[test]
fn cone_curvature() {
    // Half-angle α: K = 0 and the non-zero principal curvature is −cos α / ρ at distance ρ from
    // the axis (outward normal).
    let (rb, rt, h) = (2.0, 0.5, 3.0);
    let s = construct::cone(DVec3::ZERO, DVec3::new(0.0, 0.0, h), rb, rt).unwrap();
    let alpha = ((rb - rt) / h).atan();
    for (u, v) in interior_params(&s, 6) {
        let g = s.local_geometry(u, v).unwrap();
        let p = g.derivatives.point;
        let rho = p.truncate().length();
        assert!((rho - (rb + (rt - rb) * p.z / h)).abs() < TOL);
        let k = g.curvature;
        assert!(k.gaussian.abs() < TOL);
        assert!(
            (k.k2 + alpha.cos() / rho).abs() < TOL,
            "k2 {} vs {}",
            k.k2,
            -alpha.cos() / rho
        );
    }
    // An apex (top radius 0) evaluates without NaN.
    let apex = construct::cone(DVec3::ZERO, DVec3::Z, 1.0, 0.0).unwrap();
    let [(u0, _), (_, v1)] = apex.domain();
    let g = apex.local_geometry(u0, v1).unwrap();
    assert!(g.normal.is_finite() && g.curvature.gaussian.is_finite());
}

#[test]
fn torus_gaussian_curvature() {
    let (big, small) = (3.0, 1.0);
    let s = construct::torus(DVec3::ZERO, DVec3::Z, big, small).unwrap();
    for (u, v) in interior_params(&s, 10) {
        let g = s.local_geometry(u, v).unwrap();
        let p = g.derivatives.point;
        let rho = p.truncate().length();
        let tube = DVec3::new(p.x / rho * big, p.y / rho * big, 0.0);
        assert!((p.distance(tube) - small).abs() < TOL, "on the tube");
        let cos_v = (rho - big) / small;
        let expected = cos_v / (small * (big + small * cos_v));
        let k = g.curvature;
        assert!(
            (k.gaussian - expected).abs() < TOL,
            "K {} vs {expected}",
            k.gaussian
        );
        // Principal curvatures of the torus: −1/r around the tube, −cos v / (R + r cos v) along it.
        let k_tube = -1.0 / small;
        let k_ring = -cos_v / (big + small * cos_v);
        assert!((k.k1 - k_tube.max(k_ring)).abs() < 1e-10);
        assert!((k.k2 - k_tube.min(k_ring)).abs() < 1e-10);
        assert!(g.normal.distance((p - tube) / small) < 1e-12);
    }
}

#[test]
fn plane_is_flat() {
    let s = construct::plane(
        DVec3::ONE,
        DVec3::new(2.0, 0.0, 0.0),
        DVec3::new(0.0, 3.0, 0.0),
    )
    .unwrap();
    for (u, v) in interior_params(&s, 4) {
        let g = s.local_geometry(u, v).unwrap();
        assert_eq!(g.normal, DVec3::Z);
        assert_eq!(g.curvature.gaussian, 0.0);
        assert_eq!(g.curvature.mean, 0.0);
        assert!(g.curvature.directions.is_none());
    }
}

#[test]
fn circles_and_arcs_are_exact() {
    let c = construct::circle(DVec3::new(1.0, 1.0, 0.0), DVec3::Z, DVec3::X, 2.0).unwrap();
    let (a, b) = c.domain();
    for k in 0..=100 {
        let t = a + (b - a) * k as f64 / 100.0;
        let d = c.derivatives(t, 2).unwrap();
        assert!((d[0].distance(DVec3::new(1.0, 1.0, 0.0)) - 2.0).abs() < TOL);
        // Curvature |C′ × C″| / |C′|³ = 1 / r.
        let kappa = d[1].cross(d[2]).length() / d[1].length().powi(3);
        assert!((kappa - 0.5).abs() < 1e-12, "κ = {kappa}");
    }
    let arc = construct::arc(DVec3::ZERO, DVec3::X, DVec3::Y, 1.0, 0.25, 2.0).unwrap();
    let (a, b) = arc.domain();
    assert!(
        arc.point_at(a)
            .unwrap()
            .distance(DVec3::new(0.25f64.cos(), 0.25f64.sin(), 0.0))
            < TOL
    );
    assert!(
        arc.point_at(b)
            .unwrap()
            .distance(DVec3::new(2f64.cos(), 2f64.sin(), 0.0))
            < TOL
    );
    assert!(matches!(
        construct::arc(DVec3::ZERO, DVec3::X, DVec3::Y, -1.0, 0.0, 1.0),
        Err(GeometryError::Construction { .. })
    ));
}

/// The kernel's NURBS evaluator (Cox–de Boor, A2.3/A3.6/A4.4) against the independent Bernstein
/// evaluator of the Bézier module, on every teapot patch.
#[test]
fn teapot_patches_agree_with_bernstein_evaluator() {
    let set = samples::utah_teapot().unwrap();
    for (index, patch) in set.patches().iter().enumerate() {
        let points = patch
            .indices()
            .iter()
            .map(|&i| set.points()[i as usize])
            .collect();
        let s = NurbsSurface::bezier([patch.degree_u(), patch.degree_v()], points, None).unwrap();
        for (u, v) in [(0.0, 0.0), (0.3, 0.7), (1.0, 0.5), (0.5, 1.0), (0.9, 0.1)] {
            let a = set.evaluate(index, u, v).unwrap();
            let b = s.evaluate(u, v).unwrap();
            for (x, y) in [
                (a.point, b.point),
                (a.su, b.su),
                (a.sv, b.sv),
                (a.suu, b.suu),
                (a.suv, b.suv),
                (a.svv, b.svv),
            ] {
                assert!(
                    x.distance(y) < 1e-11,
                    "patch {index} at ({u}, {v}): {x:?} vs {y:?}"
                );
            }
            let (na, nb) = (set.normal(index, u, v).unwrap(), s.normal(u, v).unwrap());
            assert!(na.distance(nb) < 1e-9, "normal of patch {index}");
        }
    }
    // And the decomposition of a B-spline surface into a patch set gives the same points.
    let s = bumpy_bspline();
    let set: BezierPatchSet = s.to_bezier_patch_set().unwrap();
    let patches = s.bezier_patches();
    assert_eq!(set.patches().len(), patches.len());
    for (index, (_, [[u0, u1], [v0, v1]])) in patches.iter().enumerate() {
        for (a, b) in [(0.2, 0.3), (1.0, 0.0), (0.6, 0.9)] {
            let expected = s.point_at(u0 + (u1 - u0) * a, v0 + (v1 - v0) * b).unwrap();
            let got = set.evaluate(index, a, b).unwrap().point;
            assert!(got.distance(expected) < 1e-12);
        }
    }
}

/// A non-uniform rational B-spline surface of degree (3, 2) with a double knot.
fn bumpy_bspline() -> NurbsSurface {
    let count = [6, 5];
    let mut points = Vec::new();
    let mut weights = Vec::new();
    for i in 0..count[0] {
        for j in 0..count[1] {
            let (x, y) = (i as f64, j as f64);
            points.push(DVec3::new(x, y, (x * 1.3).sin() * (y * 0.9).cos()));
            weights.push(1.0 + 0.5 * ((i + 2 * j) % 3) as f64);
        }
    }
    NurbsSurface::new(
        [3, 2],
        [
            vec![0.0, 0.0, 0.0, 0.0, 0.3, 0.7, 1.0, 1.0, 1.0, 1.0],
            vec![-1.0, -1.0, -1.0, 0.5, 0.5, 2.0, 2.0, 2.0],
        ],
        count,
        points,
        Some(weights),
    )
    .unwrap()
}

#[test]
fn derivatives_match_finite_differences() {
    let s = bumpy_bspline();
    let h = 1e-5;
    for (u, v) in interior_params(&s, 5) {
        let d = s.evaluate(u, v).unwrap();
        let at = |du: f64, dv: f64| s.evaluate(u + du, v + dv).unwrap();
        let su = (at(h, 0.0).point - at(-h, 0.0).point) / (2.0 * h);
        let sv = (at(0.0, h).point - at(0.0, -h).point) / (2.0 * h);
        let suu = (at(h, 0.0).su - at(-h, 0.0).su) / (2.0 * h);
        let suv = (at(0.0, h).su - at(0.0, -h).su) / (2.0 * h);
        let svv = (at(0.0, h).sv - at(0.0, -h).sv) / (2.0 * h);
        for (name, exact, fd) in [
            ("su", d.su, su),
            ("sv", d.sv, sv),
            ("suu", d.suu, suu),
            ("suv", d.suv, suv),
            ("svv", d.svv, svv),
        ] {
            let err = exact.distance(fd) / exact.length().max(1.0);
            assert!(err < 1e-5, "{name} at ({u}, {v}): {exact:?} vs {fd:?}");
        }
    }
}

#[test]
fn grid_evaluation_equals_pointwise_evaluation() {
    let s = bumpy_bspline();
    let us = s.span_parameters(Direction::U, 7);
    let vs = s.span_parameters(Direction::V, 5);
    let grid = s.curvature_grid(&us, &vs).unwrap();
    for (i, &u) in us.iter().enumerate() {
        for (j, &v) in vs.iter().enumerate() {
            let (sample, curvature) = grid[i * vs.len() + j];
            assert!(curvature.k1 >= curvature.k2);
            let g = s.local_geometry(u, v).unwrap();
            assert!(sample.point.distance(g.derivatives.point) < 1e-12);
            assert!(sample.normal.distance(g.normal) < 1e-10);
            assert!(
                (curvature.gaussian - g.curvature.gaussian).abs()
                    < 1e-8 * (1.0 + g.curvature.gaussian.abs())
            );
        }
    }
    let fast = s.tessellate_grid(&us, &vs).unwrap();
    assert!(
        fast.iter()
            .zip(&grid)
            .all(|(a, (b, _))| a.point == b.point && a.normal.distance(b.normal) < 1e-12)
    );
    assert!(matches!(
        s.tessellate_grid(&[5.0], &vs),
        Err(GeometryError::OutsideDomain { parameter: "u", .. })
    ));
}

#[test]
fn point_grid_equals_pointwise_evaluation_and_lies_on_the_sphere() {
    // Rational (the sphere: weights 1/√2 at the arcs' middle points, a degenerate pole row) and
    // polynomial surfaces; a non-uniform grid that includes the domain ends and the knots.
    let radius = 2.5;
    let sphere = construct::sphere(DVec3::new(1.0, -2.0, 0.5), radius).unwrap();
    for s in [bumpy_bspline(), sphere.clone()] {
        let [(u0, u1), (v0, v1)] = s.domain();
        let us: Vec<f64> = (0..=9)
            .map(|k| u0 + (u1 - u0) * (k as f64 / 9.0).powf(1.3))
            .collect();
        let mut vs = s.span_parameters(Direction::V, 3);
        vs.push(v0 + 0.37 * (v1 - v0));
        vs.sort_by(f64::total_cmp);
        let grid = s.point_grid(&us, &vs).unwrap();
        assert_eq!(grid.len(), us.len() * vs.len());
        for (i, &u) in us.iter().enumerate() {
            for (j, &v) in vs.iter().enumerate() {
                let exact = s.point_at(u, v).unwrap();
                assert!(grid[i * vs.len() + j].distance(exact) < TOL * (1.0 + exact.length()));
            }
        }
        assert!(matches!(
            s.point_grid(&us, &[v1 + 1.0]),
            Err(GeometryError::OutsideDomain { parameter: "v", .. })
        ));
    }
    let us = sphere.span_parameters(Direction::U, 5);
    let vs = sphere.span_parameters(Direction::V, 5);
    for p in sphere.point_grid(&us, &vs).unwrap() {
        let r = p.distance(DVec3::new(1.0, -2.0, 0.5));
        assert!((r - radius).abs() < 1e-12, "radius {r}");
    }
}

#[test]
fn closest_point_recovers_parameters() {
    let s = bumpy_bspline();
    for (u, v) in interior_params(&s, 4) {
        let g = s.local_geometry(u, v).unwrap();
        // A point off the surface along the normal, closer than the curvature radius.
        let radius = 1.0 / g.curvature.k1.abs().max(g.curvature.k2.abs()).max(1e-3);
        let offset = 0.2 * radius.min(0.5);
        let target = g.derivatives.point + g.normal * offset;
        let c = s.closest_point(target).unwrap();
        assert!(
            (c.distance - offset).abs() < 1e-9,
            "distance {} vs {offset}",
            c.distance
        );
        assert!(
            (c.u - u).abs() < 1e-7 && (c.v - v).abs() < 1e-7,
            "({}, {}) vs ({u}, {v})",
            c.u,
            c.v
        );
    }
    // Beyond a boundary the answer lies on the boundary.
    let [(u0, _), (v0, v1)] = s.domain();
    let edge = s.local_geometry(u0, 0.5 * (v0 + v1)).unwrap();
    let target = edge.derivatives.point - edge.derivatives.su.normalize() * 0.5;
    let c = s.closest_point(target).unwrap();
    assert_eq!(c.u, u0);
    assert!(c.distance <= 0.5 + 1e-12);
    assert!(matches!(
        s.closest_point(DVec3::NAN),
        Err(GeometryError::NonFinitePoint { .. })
    ));
}

#[test]
fn sphere_closest_point_is_radial() {
    let s = construct::sphere(DVec3::ZERO, 1.0).unwrap();
    for target in [
        DVec3::new(2.0, 1.0, 0.5),
        DVec3::new(-0.1, 0.2, -0.3),
        DVec3::new(0.0, 0.0, 3.0),
    ] {
        let c = s.closest_point(target).unwrap();
        assert!(
            (c.distance - (target.length() - 1.0).abs()).abs() < 1e-9,
            "{target:?}: {c:?}"
        );
    }
}

#[test]
fn constructors_reproduce_their_inputs() {
    // Interpolation passes through every point.
    let pts: Vec<DVec3> = (0..7)
        .map(|i| DVec3::new(i as f64, (i as f64).sin(), 0.1 * (i * i) as f64))
        .collect();
    let c = construct::interpolate(&pts, 3).unwrap();
    let (a, b) = c.domain();
    let hits = (0..=2000)
        .map(|k| c.point_at(a + (b - a) * k as f64 / 2000.0).unwrap())
        .collect::<Vec<_>>();
    assert!(c.point_at(a).unwrap().distance(pts[0]) < TOL);
    assert!(c.point_at(b).unwrap().distance(pts[6]) < TOL);
    for p in &pts {
        assert!(
            hits.iter().any(|h| h.distance(*p) < 0.02),
            "passes near {p:?}"
        );
        // Exactly through it at its chord-length parameter: the closest sampled point converges.
    }
    // Polyline and line.
    let poly = construct::polyline(&[DVec2::ZERO, DVec2::X, DVec2::new(1.0, 3.0)]).unwrap();
    assert!(poly.point_at(0.25).unwrap().distance(DVec2::X) < TOL);
    assert!(construct::polyline(&[DVec2::ZERO, DVec2::ZERO]).is_err());

    // Extrusion and ruled surfaces contain their curves.
    let base = construct::circle(DVec3::ZERO, DVec3::Z, DVec3::X, 1.0).unwrap();
    let top = construct::interpolate(&pts[..4], 2).unwrap();
    let ext = construct::extrude(&base, DVec3::new(0.0, 0.0, 2.0)).unwrap();
    let ruled = construct::ruled(&base, &top).unwrap();
    for k in 0..=20 {
        let t = k as f64 / 20.0;
        let p = base.point_at(t).unwrap();
        assert!(ext.point_at(t, 0.0).unwrap().distance(p) < TOL);
        assert!(
            ext.point_at(t, 1.0)
                .unwrap()
                .distance(p + DVec3::new(0.0, 0.0, 2.0))
                < TOL
        );
        assert!(ruled.point_at(t, 0.0).unwrap().distance(p) < 1e-12);
        let (ta, tb) = top.domain();
        assert!(
            ruled
                .point_at(t, 1.0)
                .unwrap()
                .distance(top.point_at(ta + (tb - ta) * t).unwrap())
                < 1e-12
        );
    }

    // A loft passes through its sections at the section parameters (found by inversion).
    let sections: Vec<SpaceCurve> = (0..4)
        .map(|k| {
            let z = k as f64;
            construct::circle(
                DVec3::new(0.0, 0.0, z),
                DVec3::Z,
                DVec3::X,
                1.0 + 0.3 * (z * 1.7).sin(),
            )
            .unwrap()
        })
        .collect();
    let loft = construct::loft(&sections, 3).unwrap();
    for (k, section) in sections.iter().enumerate() {
        let p = section.point_at(0.3).unwrap();
        let c = loft.closest_point(p).unwrap();
        assert!(c.distance < 1e-9, "section {k}: {}", c.distance);
    }

    // Coons: the four boundaries are reproduced.
    let bottom = construct::interpolate(
        &[
            DVec3::ZERO,
            DVec3::new(1.0, 0.0, 0.5),
            DVec3::new(2.0, 0.0, 0.0),
        ],
        2,
    )
    .unwrap();
    let top = construct::line(DVec3::new(0.0, 2.0, 0.0), DVec3::new(2.0, 2.0, 0.0)).unwrap();
    let left = construct::interpolate(
        &[
            DVec3::ZERO,
            DVec3::new(-0.3, 1.0, 0.2),
            DVec3::new(0.0, 2.0, 0.0),
        ],
        2,
    )
    .unwrap();
    let right = construct::polyline(&[
        DVec3::new(2.0, 0.0, 0.0),
        DVec3::new(2.2, 1.0, 0.0),
        DVec3::new(2.0, 2.0, 0.0),
    ])
    .unwrap();
    let coons = construct::coons(&bottom, &top, &left, &right).unwrap();
    for k in 0..=10 {
        let t = k as f64 / 10.0;
        let on = |c: &SpaceCurve| {
            let (a, b) = c.domain();
            c.point_at(a + (b - a) * t).unwrap()
        };
        assert!(coons.point_at(t, 0.0).unwrap().distance(on(&bottom)) < 1e-12);
        assert!(coons.point_at(t, 1.0).unwrap().distance(on(&top)) < 1e-12);
        assert!(coons.point_at(0.0, t).unwrap().distance(on(&left)) < 1e-12);
        assert!(coons.point_at(1.0, t).unwrap().distance(on(&right)) < 1e-12);
    }
    let bad_top = construct::line(DVec3::new(0.0, 2.5, 0.0), DVec3::new(2.0, 2.0, 0.0)).unwrap();
    assert!(construct::coons(&bottom, &bad_top, &left, &right).is_err());
}

#[test]
fn sweep_follows_the_rail() {
    // Along a straight rail a sweep is an extrusion.
    let profile = construct::circle(DVec3::ZERO, DVec3::Z, DVec3::X, 0.5).unwrap();
    let rail = construct::line(DVec3::ZERO, DVec3::new(0.0, 0.0, 3.0)).unwrap();
    let s = construct::sweep(&profile, &rail, 4).unwrap();
    for (u, v) in interior_params(&s, 5) {
        let p = s.point_at(u, v).unwrap();
        assert!((p.truncate().length() - 0.5).abs() < 1e-12, "{p:?}");
    }
    // Along a quarter circle (radius 4) the tube keeps its radius at the sections; a
    // rotation-minimizing frame does not twist, so the profile's start point stays on the
    // outside of the bend.
    let rail = construct::arc(DVec3::ZERO, DVec3::X, DVec3::Z, 4.0, -FRAC_PI_2, 0.0).unwrap();
    let profile = construct::circle(DVec3::new(0.0, 0.0, -4.0), DVec3::X, DVec3::Y, 0.5).unwrap();
    let s = construct::sweep(&profile, &rail, 9).unwrap();
    let [(u0, u1), (v0, v1)] = s.domain();
    for k in 0..=16 {
        let v = v0 + (v1 - v0) * k as f64 / 16.0;
        for m in 0..8 {
            let p = s.point_at(u0 + (u1 - u0) * m as f64 / 8.0, v).unwrap();
            // Distance to the rail circle (radius 4 in the xz-plane).
            let q = DVec3::new(p.x, 0.0, p.z).normalize() * 4.0;
            assert!(
                (p.distance(q) - 0.5).abs() < 2e-3,
                "tube radius {} at v = {v}",
                p.distance(q)
            );
        }
    }
    assert!(construct::sweep(&profile, &rail, 1).is_err());
}

#[test]
fn revolve_of_a_line_is_a_cylinder_and_partial_angles_work() {
    let profile = construct::line(DVec3::new(2.0, 0.0, 0.0), DVec3::new(2.0, 0.0, 1.0)).unwrap();
    let s = construct::revolve(&profile, DVec3::ZERO, DVec3::Z, PI).unwrap();
    let [(u0, u1), _] = s.domain();
    assert!(
        s.point_at(u1, 0.0)
            .unwrap()
            .distance(DVec3::new(-2.0, 0.0, 0.0))
            < TOL
    );
    assert!(
        s.point_at(u0, 1.0)
            .unwrap()
            .distance(DVec3::new(2.0, 0.0, 1.0))
            < TOL
    );
    for (u, v) in interior_params(&s, 5) {
        let p = s.point_at(u, v).unwrap();
        assert!((p.truncate().length() - 2.0).abs() < TOL && p.y >= -TOL);
    }
    assert!(construct::revolve(&profile, DVec3::ZERO, DVec3::ZERO, TAU).is_err());
}

#[test]
fn affine_transforms_map_the_surface() {
    let s = bumpy_bspline();
    let t = DAffine3::from_scale_rotation_translation(
        DVec3::new(2.0, 1.0, 0.5),
        glam::DQuat::from_rotation_y(0.7),
        DVec3::new(1.0, -2.0, 3.0),
    );
    let m = s.transformed(&t).unwrap();
    for (u, v) in interior_params(&s, 4) {
        let expected = t.transform_point3(s.point_at(u, v).unwrap());
        assert!(m.point_at(u, v).unwrap().distance(expected) < 1e-12);
    }
    // Reversal and swapping re-parametrize the same surface and flip the normal.
    let [(u0, u1), (v0, v1)] = s.domain();
    let r = s.reverse(Direction::U);
    let w = s.swap_uv();
    for (u, v) in interior_params(&s, 4) {
        let p = s.point_at(u, v).unwrap();
        assert!(r.point_at(u0 + u1 - u, v).unwrap().distance(p) < 1e-12);
        assert!(w.point_at(v, u).unwrap().distance(p) < 1e-12);
        assert!(
            r.normal(u0 + u1 - u, v)
                .unwrap()
                .distance(-s.normal(u, v).unwrap())
                < 1e-9
        );
    }
    let _ = (v0, v1);
}

#[test]
fn knot_removal_undoes_insertion() {
    let s = bumpy_bspline();
    let inserted = s.insert_knot(Direction::U, 0.5, 2).unwrap();
    assert_eq!(inserted.count()[0], s.count()[0] + 2);
    let (removed, n) = inserted.remove_knot(Direction::U, 0.5, 5, 1e-9);
    assert_eq!(n, 2, "both inserted copies come out, no more");
    assert_eq!(removed.count(), s.count());
    for (a, b) in removed
        .homogeneous_points()
        .iter()
        .zip(s.homogeneous_points())
    {
        assert!(a.distance(*b) < 1e-10);
    }
    // A knot the shape needs stays: 0.3 is a simple knot of a generic cubic.
    let (kept, n) = s.remove_knot(Direction::U, 0.3, 1, 1e-9);
    assert_eq!(n, 0);
    assert_eq!(kept, s);
    // Curves too.
    let c = construct::interpolate(
        &[
            DVec3::ZERO,
            DVec3::X,
            DVec3::new(2.0, 1.0, 0.0),
            DVec3::Y * 3.0,
            DVec3::ONE,
        ],
        3,
    )
    .unwrap();
    let ci = c.insert_knot(0.42, 1).unwrap();
    let (cr, n) = ci.remove_knot(0.42, 1, 1e-9);
    assert_eq!(n, 1);
    assert_eq!(cr.count(), c.count());
}

#[test]
fn validation_errors_name_field_and_index() {
    let pts = vec![DVec3::ZERO; 4];
    let knots = || [vec![0.0, 0.0, 1.0, 1.0], vec![0.0, 0.0, 1.0, 1.0]];
    let make = |degree: [usize; 2], knots: [Vec<f64>; 2], count, points: Vec<DVec3>, weights| {
        NurbsSurface::new(degree, knots, count, points, weights).unwrap_err()
    };
    assert!(matches!(
        make([0, 1], knots(), [2, 2], pts.clone(), None),
        GeometryError::Degree {
            at,
            ..
        } if at == "knots[0]"
    ));
    assert!(matches!(
        make([1, 33], knots(), [2, 2], pts.clone(), None),
        GeometryError::Degree { max: 32, .. }
    ));
    assert!(matches!(
        make(
            [2, 1],
            [vec![0.0, 0.0, 0.0, 1.0, 1.0], vec![0.0, 0.0, 1.0, 1.0]],
            [2, 2],
            pts.clone(),
            None
        ),
        GeometryError::TooFewControlPoints {
            at,
            count: 2,
            degree: 2
        } if at == "knots[0]"
    ));
    assert!(matches!(
        make(
            [1, 1],
            [vec![0.0, 0.0, 1.0], vec![0.0, 0.0, 1.0, 1.0]],
            [2, 2],
            pts.clone(),
            None
        ),
        GeometryError::KnotCount {
            at,
            found: 3,
            expected: 4,
            ..
        } if at == "knots[0]"
    ));
    assert!(matches!(
        make(
            [1, 1],
            [vec![0.0, 0.0, 1.0, 1.0], vec![0.0, f64::NAN, 1.0, 1.0]],
            [2, 2],
            pts.clone(),
            None
        ),
        GeometryError::NonFiniteKnot {
            at,
            ..
        } if at == "knots[1][1]"
    ));
    assert!(matches!(
        make(
            [1, 1],
            [vec![0.0, 0.0, 1.0, 0.5], vec![0.0, 0.0, 1.0, 1.0]],
            [2, 2],
            pts.clone(),
            None
        ),
        GeometryError::DecreasingKnot {
            at,
            ..
        } if at == "knots[0][3]"
    ));
    let err = make(
        [1, 1],
        [vec![0.0; 4], vec![0.0, 0.0, 1.0, 1.0]],
        [2, 2],
        pts.clone(),
        None,
    );
    assert!(
        matches!(
            &err,
            GeometryError::KnotMultiplicity {
                at,
                multiplicity: 4,
                max: 2,
                ..
            } if at == "knots[0][0]"
        ),
        "{err}"
    );
    assert!(matches!(
        make(
            [1, 1],
            [vec![0.0, 0.0, 0.5, 0.5, 1.0, 1.0], vec![0.0, 0.0, 1.0, 1.0]],
            [4, 2],
            vec![DVec3::ZERO; 8],
            None
        ),
        GeometryError::KnotMultiplicity {
            at,
            multiplicity: 2,
            max: 1,
            ..
        } if at == "knots[0][2]"
    ));
    assert!(matches!(
        make(
            [1, 1],
            [vec![0.0, 1.0, 1.0, 2.0], vec![0.0, 0.0, 1.0, 1.0]],
            [2, 2],
            pts.clone(),
            None
        ),
        GeometryError::EmptyDomain { .. } | GeometryError::KnotMultiplicity { .. }
    ));
    let mut nan = pts.clone();
    nan[3].y = f64::INFINITY;
    let err = make([1, 1], knots(), [2, 2], nan, None);
    assert_eq!(err.to_string(), "points[1][1]: coordinate 1 is not finite");
    for w in [0.0, -1.0, f64::NAN] {
        let err = make(
            [1, 1],
            knots(),
            [2, 2],
            pts.clone(),
            Some(vec![1.0, 1.0, w, 1.0]),
        );
        assert!(
            matches!(&err, GeometryError::BadWeight { at, .. } if at == "points[1][0]"),
            "{err}"
        );
    }
    assert!(matches!(
        make([1, 1], knots(), [2, 2], vec![DVec3::ZERO; 3], None),
        GeometryError::PointCount {
            found: 3,
            expected: 4,
            ..
        }
    ));
    // Curves, 2D and 3D.
    assert!(matches!(
        TrimCurve::new(1, vec![0.0, 0.0, 1.0], vec![DVec2::ZERO; 2], None),
        Err(GeometryError::KnotCount { at, .. }) if at == "knots"
    ));
    assert!(matches!(
        SpaceCurve::new(
            1,
            vec![0.0, 0.0, 1.0, 1.0],
            vec![DVec3::ZERO; 2],
            Some(vec![1.0, 0.0])
        ),
        Err(GeometryError::BadWeight { .. })
    ));
    // Operations refuse bad requests and leave the input alone.
    let s = NurbsSurface::new(
        [3, 3],
        [uniform_clamped_knots(3, 5), uniform_clamped_knots(3, 4)],
        [5, 4],
        vec![DVec3::ONE; 20],
        None,
    )
    .unwrap();
    assert!(matches!(
        s.insert_knot(Direction::U, 2.0, 1),
        Err(GeometryError::NotInterior { .. })
    ));
    assert!(matches!(
        s.insert_knot(Direction::U, 0.5, 3),
        Err(GeometryError::InsertionTooMany { .. })
    ));
    assert!(matches!(
        s.split(Direction::V, 0.0),
        Err(GeometryError::NotInterior { .. })
    ));
    assert!(matches!(
        s.elevate_degree(Direction::V, 30),
        Err(GeometryError::Degree { .. })
    ));
    assert!(matches!(
        s.evaluate(0.5, 1.5),
        Err(GeometryError::OutsideDomain { parameter: "v", .. })
    ));
    let mut moved = s.clone();
    assert!(moved.set_point(0, 0, DVec3::NAN).is_err());
    assert!(moved.set_weight(0, 0, 0.0).is_err());
    assert!(moved.set_point(9, 0, DVec3::ONE).is_err());
    assert_eq!(moved, s);
}

#[test]
fn moving_the_seam_of_a_closed_surface_keeps_its_shape() {
    // A torus (closed both ways, rational) with its seam moved in u and in v: every point
    // is the old one at the same parameter modulo the period.
    let t = construct::torus(
        DVec3::new(1.0, -2.0, 0.5),
        DVec3::new(0.0, 0.3, 1.0),
        5.0,
        1.5,
    )
    .unwrap();
    for (direction, d) in [(Direction::U, 0), (Direction::V, 1)] {
        let (lo, hi) = t.domain()[d];
        let period = hi - lo;
        for cut in [lo + 0.137 * period, lo + 0.5 * period, lo + 0.9 * period] {
            let moved = t.moved_seam(direction, cut, 1e-9).unwrap();
            let (a, b) = moved.domain()[d];
            assert!((a - cut).abs() < 1e-12 && (b - cut - period).abs() < 1e-12);
            for k in 0..=40 {
                let x = a + (b - a) * f64::from(k) / 40.0;
                let old = if x > hi { x - period } else { x };
                for y in [0.1, 0.45, 0.8] {
                    let (mu, mv, ou, ov) = if d == 0 {
                        (x, y, old, y)
                    } else {
                        (y, x, y, old)
                    };
                    let p = moved.point_at(mu, mv).unwrap();
                    let q = t.point_at(ou, ov).unwrap();
                    assert!(
                        p.distance(q) < 1e-12,
                        "{direction:?} cut {cut} at {x}: {p} vs {q}"
                    );
                }
            }
            // Moved again to the old end: the old surface one period on.
            let back = moved.moved_seam(direction, hi, 1e-9).unwrap();
            assert!((back.domain()[d].0 - hi).abs() < 1e-12);
            for k in 0..=10 {
                let x = hi + period * f64::from(k) / 10.0;
                let (bu, bv, ou, ov) = if d == 0 {
                    (x, 0.3, x - period, 0.3)
                } else {
                    (0.3, x, 0.3, x - period)
                };
                let p = back.point_at(bu, bv).unwrap();
                assert!(p.distance(t.point_at(ou, ov).unwrap()) < 1e-12);
            }
        }
    }
    // A surface that is not closed is refused.
    let open = construct::cylinder(DVec3::ZERO, DVec3::Z, 2.0)
        .unwrap()
        .split(Direction::U, 0.5)
        .unwrap()
        .0;
    let (lo, hi) = open.domain()[0];
    assert!(
        open.moved_seam(Direction::U, 0.5 * (lo + hi), 1e-9)
            .is_err()
    );
}

#[test]
fn moving_the_seam_of_a_closed_curve_keeps_its_shape() {
    // A full rational circle (four arcs, weights 1 and √2/2) and a closed cubic: every point
    // of the moved curve is the old one at the same parameter modulo the period.
    let circle =
        construct::arc(DVec3::new(1.0, 2.0, 3.0), DVec3::X, DVec3::Y, 2.5, 0.0, TAU).unwrap();
    let points = [
        DVec3::new(0.0, 0.0, 0.0),
        DVec3::new(2.0, 1.0, 0.0),
        DVec3::new(3.0, -1.0, 1.0),
        DVec3::new(1.0, -2.0, 0.5),
        DVec3::new(0.0, 0.0, 0.0),
    ];
    let cubic = SpaceCurve::new(
        3,
        vec![0.0, 0.0, 0.0, 0.0, 0.5, 1.0, 1.0, 1.0, 1.0],
        points.to_vec(),
        Some(vec![1.0, 2.0, 0.5, 1.0, 3.0]),
    )
    .unwrap();
    for c in [circle, cubic] {
        let (lo, hi) = c.domain();
        let period = hi - lo;
        for cut in [lo + 0.1 * period, lo + 0.5 * period, lo + 0.77 * period] {
            let moved = c.moved_seam(cut, 1e-12).unwrap();
            let (a, b) = moved.domain();
            assert!((a - cut).abs() < 1e-12 && (b - cut - period).abs() < 1e-12);
            for k in 0..=50 {
                let t = a + (b - a) * f64::from(k) / 50.0;
                let old = if t > hi { t - period } else { t };
                let (p, q) = (moved.point_at(t).unwrap(), c.point_at(old).unwrap());
                assert!(p.distance(q) < 1e-12, "cut {cut} at {t}: {p} vs {q}");
            }
        }
    }
    // An open curve is refused.
    let open = construct::arc(DVec3::ZERO, DVec3::X, DVec3::Y, 1.0, 0.0, PI).unwrap();
    assert!(open.moved_seam(0.5, 1e-9).is_err());
}
