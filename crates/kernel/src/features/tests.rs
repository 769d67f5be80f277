//! Edge features against closed forms, in general position.

use std::f64::consts::PI;

use glam::{DAffine3, DVec2, DVec3};

use super::*;
use crate::construct::line;
use crate::planar::planar_face;
use crate::solids::{block, transformed};
use crate::test_support::placement;

/// The prism over the counter-clockwise polygon `base` (in the xy plane) of height `h`.
fn prism(base: &[DVec2], h: f64) -> Vec<TrimmedSurface> {
    let at = |p: DVec2, z: f64| DVec3::new(p.x, p.y, z);
    let n = base.len();
    let ring = |z: f64| -> Vec<_> {
        (0..n)
            .map(|i| line(at(base[i], z), at(base[(i + 1) % n], z)).unwrap())
            .collect()
    };
    let mut faces = vec![
        planar_face(&ring(0.0)).unwrap(),
        planar_face(&ring(h)).unwrap(),
    ];
    for i in 0..n {
        let (a, b) = (base[i], base[(i + 1) % n]);
        faces.push(
            planar_face(&[
                line(at(a, 0.0), at(b, 0.0)).unwrap(),
                line(at(b, 0.0), at(b, h)).unwrap(),
                line(at(b, h), at(a, h)).unwrap(),
                line(at(a, h), at(a, 0.0)).unwrap(),
            ])
            .unwrap(),
        );
    }
    faces
}

/// The regular n-gon of circumradius `radius` about the origin, a corner on +x.
fn regular_polygon(n: usize, radius: f64) -> Vec<DVec2> {
    (0..n)
        .map(|k| {
            let a = 2.0 * PI * k as f64 / n as f64;
            DVec2::new(radius * a.cos(), radius * a.sin())
        })
        .collect()
}

/// The L of arms a × w (along x) and w × b (along y), counter-clockwise from the origin:
/// its inner corner at (w, w).
fn l_outline(a: f64, b: f64, w: f64) -> [DVec2; 6] {
    [
        DVec2::new(0.0, 0.0),
        DVec2::new(a, 0.0),
        DVec2::new(a, w),
        DVec2::new(w, w),
        DVec2::new(w, b),
        DVec2::new(0.0, b),
    ]
}

fn placed(faces: Vec<TrimmedSurface>, motion: &DAffine3) -> Vec<TrimmedSurface> {
    transformed(&faces, motion).unwrap()
}

fn assert_volume(result: &FeatureResult, expected: f64, what: &str) {
    let v = result.volume().unwrap();
    assert!(
        (v - expected).abs() <= 1e-7 * expected,
        "{what}: volume {v}, expected {expected} (off by {:.3e})",
        v - expected
    );
}

/// The box a × b × c with every edge filleted at r, spherical corners: the inner box grown by
/// a ball (its faces, quarter cylinders along its edges, eighth balls at its corners).
fn rounded_box(a: f64, b: f64, c: f64, r: f64) -> f64 {
    let (x, y, z) = (a - 2.0 * r, b - 2.0 * r, c - 2.0 * r);
    x * y * z
        + 2.0 * r * (x * y + y * z + z * x)
        + PI * r * r * (x + y + z)
        + 4.0 * PI * r.powi(3) / 3.0
}

#[test]
fn a_box_with_every_edge_filleted_has_the_closed_form_volume() {
    for seed in 0..4 {
        let (motion, s) = placement(700 + seed);
        let (a, b, c, r) = (2.0, 1.5, 1.0, 0.1 + 0.08 * seed as f64);
        let body = placed(block(DVec3::ZERO, DVec3::new(a, b, c)).unwrap(), &motion);
        let result = round_edges(
            &body,
            &EdgePick::All,
            EdgeFeature::Fillet { radius: r * s },
            1e-7 * s,
        )
        .unwrap_or_else(|e| panic!("seed {seed}: {e}"));
        assert_eq!(result.faces.len(), 6 + 12 + 8);
        assert_volume(
            &result,
            rounded_box(a, b, c, r) * s.powi(3),
            &format!("seed {seed}"),
        );
    }
}

#[test]
fn one_box_edge_filleted_or_chamfered_takes_its_corner_prism() {
    for seed in 0..3 {
        let (motion, s) = placement(710 + seed);
        let (a, b, c, r) = (2.0, 1.5, 1.0, 0.3);
        let body = placed(block(DVec3::ZERO, DVec3::new(a, b, c)).unwrap(), &motion);
        // The edge along x at y = b, z = c.
        let near = motion.transform_point3(DVec3::new(1.0, b, c));
        let pick = EdgePick::Near(vec![near]);
        let fillet = round_edges(
            &body,
            &pick,
            EdgeFeature::Fillet { radius: r * s },
            1e-7 * s,
        )
        .unwrap();
        let want = (a * b * c - (1.0 - PI / 4.0) * r * r * a) * s.powi(3);
        assert_volume(&fillet, want, "fillet");
        let chamfer = round_edges(
            &body,
            &pick,
            EdgeFeature::Chamfer {
                distance: r * s,
                other: 0.5 * r * s,
            },
            1e-7 * s,
        )
        .unwrap();
        assert_volume(
            &chamfer,
            (a * b * c - 0.25 * r * r * a) * s.powi(3),
            "chamfer",
        );
    }
}

#[test]
fn two_box_edges_meet_in_a_mitre() {
    // The top edges along x at y = b and along y at x = a: the fillets meet in the bisecting
    // plane; the vertical edge between them keeps its sharp corner below the mitre.
    let (motion, s) = placement(720);
    let (a, b, c, r) = (2.0, 1.5, 1.0, 0.3);
    let body = placed(block(DVec3::ZERO, DVec3::new(a, b, c)).unwrap(), &motion);
    let pick = EdgePick::Near(vec![
        motion.transform_point3(DVec3::new(1.0, b, c)),
        motion.transform_point3(DVec3::new(a, 0.7, c)),
    ]);
    let result = round_edges(
        &body,
        &pick,
        EdgeFeature::Fillet { radius: r * s },
        1e-7 * s,
    )
    .unwrap();
    // Each edge's corner prism over its whole length; the two overlap in the corner cube r³
    // where the removed region is where either of the cylinders' corner regions lies: the
    // square less the quarter disc along x, and along y; their union within the cube is the
    // cube less the intersection of the two quarter cylinders (the Steinmetz solid's eighth
    // ... 2r³/3 of the bicylinder's 16r³/3 lies in one octant: 16r³/3 / 8).
    let removed_x = (1.0 - PI / 4.0) * r * r * a;
    let removed_y = (1.0 - PI / 4.0) * r * r * b;
    let overlap = r.powi(3) - 2.0 * (PI / 4.0) * r.powi(3) + (2.0 / 3.0) * r.powi(3);
    let want = (a * b * c - removed_x - removed_y + overlap) * s.powi(3);
    assert_volume(&result, want, "mitre");
}

#[test]
fn a_chamfered_box_has_the_closed_form_volume() {
    for seed in 0..3 {
        let (motion, s) = placement(730 + seed);
        let (a, b, c, d) = (2.0, 1.5, 1.0, 0.2);
        let body = placed(block(DVec3::ZERO, DVec3::new(a, b, c)).unwrap(), &motion);
        let result = round_edges(
            &body,
            &EdgePick::All,
            EdgeFeature::Chamfer {
                distance: d * s,
                other: d * s,
            },
            1e-7 * s,
        )
        .unwrap();
        assert_eq!(result.faces.len(), 6 + 12 + 8);
        // Each edge's triangular prism between the corner cubes, and in each corner cube the
        // part of u + v + w < 2d (from the corner): (2d)³/6 less three d³/6.
        let removed = 2.0 * d * d * (a + b + c) - 12.0 * d.powi(3) + 8.0 * (5.0 / 6.0) * d.powi(3);
        assert_volume(
            &result,
            (a * b * c - removed) * s.powi(3),
            &format!("seed {seed}"),
        );
    }
}

#[test]
fn a_concave_edge_is_filled_by_its_fillet() {
    // An L-shaped prism: its one concave edge (the inner corner at (1, 1)) filleted adds the
    // square less the quarter disc along the height.
    let l = l_outline(2.0, 2.0, 1.0);
    let (h, r) = (0.7, 0.25);
    for seed in 0..3 {
        let (motion, s) = placement(740 + seed);
        let body = placed(prism(&l, h), &motion);
        let pick = EdgePick::Near(vec![motion.transform_point3(DVec3::new(1.0, 1.0, 0.3))]);
        let fillet = round_edges(
            &body,
            &pick,
            EdgeFeature::Fillet { radius: r * s },
            1e-7 * s,
        )
        .unwrap();
        assert_volume(
            &fillet,
            (3.0 * h + (1.0 - PI / 4.0) * r * r * h) * s.powi(3),
            "fillet",
        );
        let chamfer = round_edges(
            &body,
            &pick,
            EdgeFeature::Chamfer {
                distance: r * s,
                other: r * s,
            },
            1e-7 * s,
        )
        .unwrap();
        assert_volume(&chamfer, (3.0 * h + 0.5 * r * r * h) * s.powi(3), "chamfer");
    }
}

#[test]
fn a_prism_with_every_edge_filleted_is_its_inner_prism_grown_by_a_ball() {
    // A convex pentagonal prism: the rounded solid is the Minkowski sum of the prism moved in
    // by r with a ball, V + A·r + (perimeters' edges)·πr²/4 ... by Steiner's formula:
    // V(K + rB) = V + S r + M r² + 4πr³/3, with M = Σ edges' length × exterior angle / 2.
    let pentagon: Vec<DVec2> = (0..5)
        .map(|i| {
            let t = 2.0 * PI * i as f64 / 5.0 + 0.3;
            DVec2::new(t.cos(), t.sin()) * (1.0 + 0.2 * (i % 2) as f64)
        })
        .collect();
    let (h, r) = (1.2, 0.1);
    let (motion, s) = placement(750);
    let body = placed(prism(&pentagon, h), &motion);
    let result = round_edges(
        &body,
        &EdgePick::All,
        EdgeFeature::Fillet { radius: r * s },
        1e-7 * s,
    )
    .unwrap();
    // The inner prism: each side line moved in by r.
    let n = pentagon.len();
    let lines: Vec<(DVec2, DVec2)> = (0..n)
        .map(|i| {
            let (a, b) = (pentagon[i], pentagon[(i + 1) % n]);
            let d = (b - a).normalize();
            (a + DVec2::new(-d.y, d.x) * r, d)
        })
        .collect();
    let inner: Vec<DVec2> = (0..n)
        .map(|i| {
            let (p, d) = lines[(i + n - 1) % n];
            let (q, e) = lines[i];
            let t = (q - p).perp_dot(e) / d.perp_dot(e);
            p + d * t
        })
        .collect();
    let area = (0..n)
        .map(|i| inner[i].perp_dot(inner[(i + 1) % n]))
        .sum::<f64>()
        / 2.0;
    let perimeter = (0..n)
        .map(|i| inner[i].distance(inner[(i + 1) % n]))
        .sum::<f64>();
    let hi = h - 2.0 * r;
    let volume = area * hi;
    let surface = 2.0 * area + perimeter * hi;
    // Mean width term: vertical edges turn by 2π in all, the 2n cap edges by π/2 each.
    let m = 0.5 * (2.0 * PI * hi + 2.0 * perimeter * PI / 2.0);
    let want = volume + surface * r + m * r * r + 4.0 * PI * r.powi(3) / 3.0;
    assert_volume(&result, want * s.powi(3), "pentagonal prism");
}

#[test]
fn a_shelled_box_has_the_closed_form_volume() {
    for seed in 0..2 {
        let (motion, s) = placement(760 + seed);
        let (a, b, c, t) = (2.0, 1.5, 1.0, 0.1);
        let body = placed(block(DVec3::ZERO, DVec3::new(a, b, c)).unwrap(), &motion);
        let top = motion.transform_point3(DVec3::new(1.0, 0.7, c));
        let tol = 1e-7 * s;
        let s3 = s.powi(3);
        let cases = [
            (
                -t,
                vec![],
                a * b * c - (a - 2.0 * t) * (b - 2.0 * t) * (c - 2.0 * t),
            ),
            (
                -t,
                vec![top],
                a * b * c - (a - 2.0 * t) * (b - 2.0 * t) * (c - t),
            ),
            (
                t,
                vec![],
                (a + 2.0 * t) * (b + 2.0 * t) * (c + 2.0 * t) - a * b * c,
            ),
            (
                t,
                vec![top],
                (a + 2.0 * t) * (b + 2.0 * t) * (c + t) - a * b * c,
            ),
        ];
        for (thickness, open, want) in cases {
            let result = shell(&body, thickness * s, &open, tol)
                .unwrap_or_else(|e| panic!("seed {seed} {thickness} {}: {e}", open.len()));
            assert_volume(
                &result,
                want * s3,
                &format!("seed {seed} {thickness} {}", open.len()),
            );
        }
    }
}

#[test]
fn features_that_cannot_be_built_are_refused_with_the_reason() {
    let body = block(DVec3::ZERO, DVec3::ONE).unwrap();
    let too_large = round_edges(
        &body,
        &EdgePick::All,
        EdgeFeature::Fillet { radius: 0.6 },
        1e-7,
    )
    .unwrap_err()
    .to_string();
    assert!(too_large.contains("too large"), "{too_large}");
    for bad in [0.0, -1.0, f64::NAN] {
        assert!(
            round_edges(
                &body,
                &EdgePick::All,
                EdgeFeature::Fillet { radius: bad },
                1e-7
            )
            .is_err()
        );
        assert!(shell(&body, bad, &[], 1e-7).is_err() || bad < 0.0);
    }
    let thick = shell(&body, -0.6, &[], 1e-7).unwrap_err().to_string();
    assert!(thick.contains("thicker"), "{thick}");
    let ball = crate::solids::ball(DVec3::ZERO, 1.0).unwrap();
    let curved = round_edges(
        &ball,
        &EdgePick::All,
        EdgeFeature::Fillet { radius: 0.1 },
        1e-7,
    )
    .unwrap_err()
    .to_string();
    assert!(curved.contains("no edges"), "{curved}");
    // A curved face that is not a surface of revolution about the body's axis.
    let mut apart = crate::solids::capped_cylinder(DVec3::ZERO, DVec3::Z, 1.0).unwrap();
    apart.extend(crate::solids::ball(DVec3::new(3.0, 0.0, 5.0), 0.5).unwrap());
    let e = round_edges(
        &apart,
        &EdgePick::All,
        EdgeFeature::Fillet { radius: 0.1 },
        1e-7,
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("solids of revolution"), "{e}");
}

#[test]
fn a_cylinders_rims_round_to_tori_and_cut_to_cones() {
    use crate::solids::capped_cylinder;
    for seed in 0..3 {
        let (motion, s) = placement(770 + seed);
        let (radius, h, r) = (1.5, 2.0, 0.3);
        let body = placed(
            capped_cylinder(DVec3::ZERO, DVec3::Z * h, radius).unwrap(),
            &motion,
        );
        let tol = 1e-7 * s;
        let s3 = s.powi(3);
        let cylinder = PI * radius * radius * h;
        // Pappus: the corner region less the quarter disc, about the axis.
        let spandrel = 2.0 * PI * ((radius - r) * (1.0 - PI / 4.0) * r * r + r.powi(3) / 6.0);
        let fillet = round_edges(
            &body,
            &EdgePick::All,
            EdgeFeature::Fillet { radius: r * s },
            tol,
        )
        .unwrap();
        assert_volume(&fillet, (cylinder - 2.0 * spandrel) * s3, "fillet");
        let top = motion.transform_point3(DVec3::new(radius, 0.0, h));
        let one = round_edges(
            &body,
            &EdgePick::Near(vec![top]),
            EdgeFeature::Fillet { radius: r * s },
            tol,
        )
        .unwrap();
        assert_volume(&one, (cylinder - spandrel) * s3, "one rim");
        let cone = 2.0 * PI * (radius - r / 3.0) * r * r / 2.0;
        let chamfer = round_edges(
            &body,
            &EdgePick::All,
            EdgeFeature::Chamfer {
                distance: r * s,
                other: r * s,
            },
            tol,
        )
        .unwrap();
        assert_volume(&chamfer, (cylinder - 2.0 * cone) * s3, "chamfer");
        let t = 0.2;
        let closed = shell(&body, -t * s, &[], tol).unwrap();
        assert_volume(
            &closed,
            (cylinder - PI * (radius - t).powi(2) * (h - 2.0 * t)) * s3,
            "closed shell",
        );
        let cup = shell(
            &body,
            -t * s,
            &[motion.transform_point3(DVec3::new(0.3, 0.2, h))],
            tol,
        )
        .unwrap();
        assert_volume(
            &cup,
            (cylinder - PI * (radius - t).powi(2) * (h - t)) * s3,
            "cup",
        );
        let outer = shell(
            &body,
            t * s,
            &[motion.transform_point3(DVec3::new(0.3, 0.2, h))],
            tol,
        )
        .unwrap();
        assert_volume(
            &outer,
            (PI * (radius + t).powi(2) * (h + t) - cylinder) * s3,
            "outward cup",
        );
    }
}

/// Each curved face of `result` meets a neighbour tangentially along its domain's sides (its
/// boundary, for the untrimmed fillets and corners; seams and poles left out): at 9 points of
/// each side, some other face passes within the tolerance with its normal within 0.1° of this
/// face's.
fn assert_tangent(result: &FeatureResult, tolerance: f64, what: &str) {
    assert_tangent_at(result, tolerance, what, |[(u0, u1), (v0, v1)], t| {
        vec![
            (u0, v0 + (v1 - v0) * t),
            (u1, v0 + (v1 - v0) * t),
            (u0 + (u1 - u0) * t, v0),
            (u0 + (u1 - u0) * t, v1),
        ]
    });
}

/// [`assert_tangent`] at the points `at(domain, t)` names of each untrimmed curved face's
/// boundary, for t in 0, 1/8, …, 1.
fn assert_tangent_at(
    result: &FeatureResult,
    tolerance: f64,
    what: &str,
    at: impl Fn([(f64, f64); 2], f64) -> Vec<(f64, f64)>,
) {
    let faces = &result.faces;
    let mut checked = 0;
    for (k, face) in faces.iter().enumerate() {
        let s = face.surface();
        if s.plane(tolerance).is_some() || face.is_trimmed() {
            continue;
        }
        let [(u0, u1), (v0, v1)] = s.domain();
        for i in 0..=8 {
            let t = i as f64 / 8.0;
            for (u, v) in at(s.domain(), t) {
                let Ok(n) = s.normal(u, v) else { continue };
                let p = s.point_at(u, v).unwrap();
                // A seam (the side meets the opposite one) or a pole meets the face itself.
                let across = [(u0 + u1 - u, v), (u, v0 + v1 - v), (u0, v), (u, v0)];
                if across
                    .iter()
                    .filter(|&&(a, b)| (a, b) != (u, v))
                    .any(|&(a, b)| s.point_at(a, b).unwrap().distance(p) <= tolerance)
                {
                    continue;
                }
                let best = faces
                    .iter()
                    .enumerate()
                    .filter(|&(j, _)| j != k)
                    .filter_map(|(_, other)| {
                        let c = other.surface().closest_point(p).ok()?;
                        (c.distance <= 10.0 * tolerance).then(|| {
                            let m = other.surface().normal(c.u, c.v).ok()?;
                            Some(n.angle_between(m).to_degrees())
                        })?
                    })
                    .fold(f64::INFINITY, f64::min);
                assert!(
                    best < 0.1,
                    "{what}: face {k} at {p} meets its neighbour at {best}°"
                );
                checked += 1;
            }
        }
    }
    assert!(checked > 0, "{what}: nothing checked");
}

#[test]
fn fillets_meet_their_neighbours_tangentially() {
    use crate::solids::capped_cylinder;
    let (motion, s) = placement(780);
    let tol = 1e-7 * s;
    let boxed = placed(
        block(DVec3::ZERO, DVec3::new(2.0, 1.5, 1.0)).unwrap(),
        &motion,
    );
    let rounded = round_edges(
        &boxed,
        &EdgePick::All,
        EdgeFeature::Fillet { radius: 0.2 * s },
        tol,
    )
    .unwrap();
    assert_tangent(&rounded, tol, "box");
    let cylinder = placed(
        capped_cylinder(DVec3::ZERO, DVec3::Z * 2.0, 1.0).unwrap(),
        &motion,
    );
    let rims = round_edges(
        &cylinder,
        &EdgePick::All,
        EdgeFeature::Fillet { radius: 0.2 * s },
        tol,
    )
    .unwrap();
    assert_tangent(&rims, tol, "cylinder");
}

#[test]
fn faces_offset_and_drafted_keep_the_body_closed() {
    for seed in 0..3 {
        let (motion, s) = placement(790 + seed);
        let (a, b, c) = (2.0, 1.5, 1.0);
        let body = placed(block(DVec3::ZERO, DVec3::new(a, b, c)).unwrap(), &motion);
        let tol = 1e-7 * s;
        let s3 = s.powi(3);
        let at = |p: DVec3| motion.transform_point3(p);
        // The top up by 0.3 and the side x = a in by 0.2.
        let top = offset_faces(&body, &[at(DVec3::new(1.0, 0.7, c))], 0.3 * s, tol).unwrap();
        assert_volume(&top, a * b * (c + 0.3) * s3, "top offset");
        let side = offset_faces(&body, &[at(DVec3::new(a, 0.7, 0.5))], -0.2 * s, tol).unwrap();
        assert_volume(&side, (a - 0.2) * b * c * s3, "side offset");
        // The four sides drafted 5° about the bottom, pulled up: a prismatoid,
        // V = c/6 (A₀ + 4 A½ + A₁).
        let theta: f64 = 5f64.to_radians();
        let sides = [
            DVec3::new(0.0, 0.7, 0.5),
            DVec3::new(a, 0.7, 0.5),
            DVec3::new(1.0, 0.0, 0.5),
            DVec3::new(1.0, b, 0.5),
        ]
        .map(at);
        let pull = motion.transform_vector3(DVec3::Z);
        let drafted = draft_faces(&body, &sides, theta, (at(DVec3::ZERO), pull), tol).unwrap();
        let shrink = |h: f64| (a - 2.0 * h * theta.tan()) * (b - 2.0 * h * theta.tan());
        let want = c / 6.0 * (shrink(0.0) + 4.0 * shrink(0.5 * c) + shrink(c));
        assert_volume(&drafted, want * s3, "draft");
        // About the top instead (neutral plane z = c), the sides lean out going down.
        let from_top = draft_faces(
            &body,
            &sides,
            theta,
            (at(DVec3::new(0.0, 0.0, c)), pull),
            tol,
        )
        .unwrap();
        let grow = |h: f64| (a + 2.0 * h * theta.tan()) * (b + 2.0 * h * theta.tan());
        let want = c / 6.0 * (grow(0.0) + 4.0 * grow(0.5 * c) + grow(c));
        assert_volume(&from_top, want * s3, "draft about the top");
    }
    // Refusals: a face through the body, the neutral plane parallel to the face.
    let body = block(DVec3::ZERO, DVec3::ONE).unwrap();
    let e = offset_faces(&body, &[DVec3::new(0.5, 0.5, 1.0)], -1.5, 1e-7)
        .unwrap_err()
        .to_string();
    assert!(e.contains("further"), "{e}");
    let e = draft_faces(
        &body,
        &[DVec3::new(0.5, 0.5, 1.0)],
        0.1,
        (DVec3::ZERO, DVec3::Z),
        1e-7,
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("parallel"), "{e}");
}

#[test]
fn a_frustum_with_every_edge_filleted_follows_steiners_formula() {
    // A box drafted on all four sides: no corner has a face at right angles to the other two,
    // so every corner ball is trimmed by a great arc. The rounded solid is the inner parallel
    // body K' grown by a ball: V' + S' r + M' r² + 4πr³/3, M' = ½ Σ length × (π − dihedral).
    let (motion, s) = placement(800);
    let (a, b, c, r) = (2.0, 1.5, 1.0, 0.12);
    let box_faces = block(DVec3::ZERO, DVec3::new(a, b, c)).unwrap();
    let sides = [
        DVec3::new(0.0, 0.7, 0.5),
        DVec3::new(a, 0.7, 0.5),
        DVec3::new(1.0, 0.0, 0.5),
        DVec3::new(1.0, b, 0.5),
    ];
    let frustum = draft_faces(&box_faces, &sides, 0.2, (DVec3::ZERO, DVec3::Z), 1e-9)
        .unwrap()
        .faces;
    let body = placed(frustum.clone(), &motion);
    let rounded = round_edges(
        &body,
        &EdgePick::All,
        EdgeFeature::Fillet { radius: r * s },
        1e-7 * s,
    )
    .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(rounded.faces.len(), 26);
    let solid = Polyhedron::from_faces(&frustum, 1e-9).unwrap();
    let inner_faces = shell::offset_polyhedron(&solid, |_| -r, 1e-9).unwrap();
    let inner = Polyhedron::from_faces(&inner_faces, 1e-9).unwrap();
    let volume = crate::mass::signed_volume(&inner_faces).unwrap();
    let area = crate::mass::mass_properties(&inner_faces, &[])
        .unwrap()
        .area;
    let m: f64 = (0..inner.edges.len())
        .map(|k| {
            let e = inner.edges[k];
            let length = inner.vertices[e.a].distance(inner.vertices[e.b]);
            let dihedral = inner
                .inward(k, e.left)
                .angle_between(inner.inward(k, e.right));
            0.5 * length * (PI - dihedral)
        })
        .sum();
    let want = volume + area * r + m * r * r + 4.0 * PI * r.powi(3) / 3.0;
    assert_volume(&rounded, want * s.powi(3), "frustum");
    assert_tangent(&rounded, 1e-7 * s, "frustum");
}

#[test]
fn balls_and_rounded_cylinders_shell_to_their_closed_forms() {
    use crate::solids::{ball, capped_cylinder};
    let (motion, s) = placement(810);
    let tol = 1e-7 * s;
    let s3 = s.powi(3);
    let (radius, t) = (1.2, 0.15);
    let sphere = placed(ball(DVec3::new(0.3, -0.2, 0.1), radius).unwrap(), &motion);
    let inward = shell(&sphere, -t * s, &[], tol).unwrap();
    let cube = |r: f64| 4.0 * PI * r.powi(3) / 3.0;
    assert_volume(
        &inward,
        (cube(radius) - cube(radius - t)) * s3,
        "ball inward",
    );
    let outward = shell(&sphere, t * s, &[], tol).unwrap();
    assert_volume(
        &outward,
        (cube(radius + t) - cube(radius)) * s3,
        "ball outward",
    );
    // A cylinder with its rims filleted at r, shelled inward by t < r: the inner body is the
    // cylinder of R − t, h − 2t with its rims filleted at r − t (tangent arcs stay tangent).
    let (big, h, r) = (1.5, 2.0, 0.4);
    let cylinder = placed(
        capped_cylinder(DVec3::ZERO, DVec3::Z * h, big).unwrap(),
        &motion,
    );
    let rounded = round_edges(
        &cylinder,
        &EdgePick::All,
        EdgeFeature::Fillet { radius: r * s },
        tol,
    )
    .unwrap();
    let spandrel =
        |big: f64, r: f64| 2.0 * PI * ((big - r) * (1.0 - PI / 4.0) * r * r + r.powi(3) / 6.0);
    let solid = |big: f64, h: f64, r: f64| PI * big * big * h - 2.0 * spandrel(big, r);
    let hollow = shell(&rounded.faces, -t * s, &[], tol).unwrap();
    assert_volume(
        &hollow,
        (solid(big, h, r) - solid(big - t, h - 2.0 * t, r - t)) * s3,
        "rounded cylinder",
    );
    let grown = shell(&rounded.faces, t * s, &[], tol).unwrap();
    assert_volume(
        &grown,
        (solid(big + t, h + 2.0 * t, r + t) - solid(big, h, r)) * s3,
        "rounded cylinder outward",
    );
}

#[test]
fn an_l_shaped_block_with_every_edge_filleted_has_steiners_volume() {
    // The L of arms a × w and w × b, height h, every edge at r: the rounded profile's area A,
    // the cap moved in by r (the L moved in, its inner corner cut by the arc of radius 2r:
    // A′ = A(L₋ᵣ) + (4 − π) r², P′ = P(L₋ᵣ) − 4r + πr), V = A (h − 2r) + 2 (A′ r + P′ πr²/4
    // + 2πr³/3).
    let (a, b, w, h, r) = (3.0, 2.5, 1.0, 0.8, 0.15);
    let l = l_outline(a, b, w);
    let area_l = a * w + (b - w) * w;
    let spandrel = (1.0 - PI / 4.0) * r * r;
    let area = area_l - 5.0 * spandrel + spandrel;
    let moved_in = (a - 2.0 * r) * (w - 2.0 * r) + (b - w) * (w - 2.0 * r);
    let perimeter_in = 2.0 * (a - 2.0 * r) + 2.0 * (b - 2.0 * r);
    let cap_area = moved_in + (4.0 - PI) * r * r;
    let cap_perimeter = perimeter_in - 4.0 * r + PI * r;
    let want = area * (h - 2.0 * r)
        + 2.0 * (cap_area * r + cap_perimeter * PI * r * r / 4.0 + 2.0 * PI * r.powi(3) / 3.0);
    for seed in 0..3 {
        let (motion, s) = placement(820 + seed);
        let body = placed(prism(&l, h), &motion);
        let result = round_edges(
            &body,
            &EdgePick::All,
            EdgeFeature::Fillet { radius: r * s },
            1e-7 * s,
        )
        .unwrap_or_else(|e| panic!("seed {seed}: {e}"));
        assert_volume(&result, want * s.powi(3), &format!("seed {seed}"));
        assert_tangent(&result, 1e-7 * s, "L");
    }
}

#[test]
fn random_features_either_close_or_say_why() {
    // Random convex prisms, random picks and sizes (many too large): every answer is a closed
    // shell that takes material away (a fillet, a chamfer, an inward shell) or encloses some
    // (an outward shell, which grows spikes at sharp corners: the intersection join), or a
    // refusal with a reason; nothing panics.
    let mut random = crate::test_support::Xorshift::new(59);
    let mut made = 0;
    for case in 0..60 {
        let n = 3 + random.below(5) as usize;
        let base: Vec<DVec2> = (0..n)
            .map(|i| {
                let t = 2.0 * PI * (i as f64 + 0.6 * (random.unit() - 0.5)) / n as f64;
                // On a circle, so convex.
                DVec2::new(t.cos(), t.sin())
            })
            .collect();
        let h = 0.4 + random.unit();
        let (motion, s) = placement(900 + case);
        let body = placed(prism(&base, h), &motion);
        let outward = crate::boolean::outward_faces(&body, 1e-7 * s, "the prism")
            .unwrap()
            .0;
        let original = crate::mass::signed_volume(&outward).unwrap();
        let size = (0.02 + 0.5 * random.unit()) * s;
        let pick = if random.below(2) == 0 {
            EdgePick::All
        } else {
            let k = random.below(n as u64) as usize;
            let p = DVec3::new(base[k].x, base[k].y, h * random.unit());
            EdgePick::Near(vec![motion.transform_point3(p)])
        };
        let tol = 1e-7 * s;
        let results = [
            round_edges(&body, &pick, EdgeFeature::Fillet { radius: size }, tol).map(|r| (r, -1.0)),
            round_edges(
                &body,
                &pick,
                EdgeFeature::Chamfer {
                    distance: size,
                    other: 0.7 * size,
                },
                tol,
            )
            .map(|r| (r, -1.0)),
            shell(&body, -0.3 * size, &[], tol).map(|r| (r, -1.0)),
            shell(&body, 0.3 * size, &[], tol).map(|r| (r, 1.0)),
        ];
        for (which, result) in results.into_iter().enumerate() {
            match result {
                Ok((r, grows)) => {
                    let v = r.volume().unwrap();
                    assert!(v > 0.0, "case {case}: volume {v}");
                    assert!(
                        grows > 0.0 || v < original,
                        "case {case}, feature {which} of size {size} (h {h}, {n} sides, \
                         {pick:?}): volume {v} of {original}"
                    );
                    made += 1;
                }
                Err(e) => assert!(!e.to_string().is_empty()),
            }
        }
    }
    assert!(made > 60, "only {made} of 240 made");
}

#[test]
fn a_rounded_box_shells_to_its_closed_form() {
    // A box with every edge filleted at r, shelled inward by t < r: the inner body is the box
    // moved in by t with every edge filleted at r − t.
    let (motion, s) = placement(830);
    let tol = 1e-7 * s;
    let (a, b, c, r, t) = (2.0, 1.5, 1.0, 0.3, 0.1);
    let body = placed(block(DVec3::ZERO, DVec3::new(a, b, c)).unwrap(), &motion);
    let rounded = round_edges(
        &body,
        &EdgePick::All,
        EdgeFeature::Fillet { radius: r * s },
        tol,
    )
    .unwrap();
    let closed = shell(&rounded.faces, -t * s, &[], tol).unwrap_or_else(|e| panic!("{e}"));
    let inner = rounded_box(a - 2.0 * t, b - 2.0 * t, c - 2.0 * t, r - t);
    assert_volume(
        &closed,
        (rounded_box(a, b, c, r) - inner) * s.powi(3),
        "closed",
    );
    let outer = shell(&rounded.faces, t * s, &[], tol).unwrap_or_else(|e| panic!("{e}"));
    let grown = rounded_box(a + 2.0 * t, b + 2.0 * t, c + 2.0 * t, r + t);
    assert_volume(
        &outer,
        (grown - rounded_box(a, b, c, r)) * s.powi(3),
        "outward",
    );
    // With its top open: the inner body reaches out through the top's flat part.
    let top = motion.transform_point3(DVec3::new(1.0, 0.7, c));
    let cup = shell(&rounded.faces, -t * s, &[top], tol).unwrap_or_else(|e| panic!("{e}"));
    // The cut above the inner body: the inner top's flat part (a − 2r) × (b − 2r) (the inner
    // body's flat top is (a − 2t − 2(r − t)) wide) times t.
    let slot = (a - 2.0 * r) * (b - 2.0 * r) * t;
    assert_volume(
        &cup,
        (rounded_box(a, b, c, r) - inner - slot) * s.powi(3),
        "open top",
    );
}

#[test]
fn faces_split_in_one_plane_are_one_face() {
    // A box whose top is two rectangles (as some files split a face): the seam between them
    // is no edge, so every edge filleted is the rounded box.
    let (a, b, c, r) = (2.0, 1.5, 1.0, 0.2);
    let mut faces = block(DVec3::ZERO, DVec3::new(a, b, c)).unwrap();
    // The top and the sides along x go; the sides come back with the seam's end as a corner.
    faces.retain(|f| {
        let (lo, hi) = f.surface().bounds();
        !(lo.z > c - 1e-9 || hi.y < 1e-9 || lo.y > b - 1e-9)
    });
    for y in [0.0, b] {
        let p = |x: f64, z: f64| DVec3::new(x, y, z);
        let ring = [p(0.0, 0.0), p(a, 0.0), p(a, c), p(0.8, c), p(0.0, c)];
        faces.push(
            planar_face(
                &(0..5)
                    .map(|i| line(ring[i], ring[(i + 1) % 5]).unwrap())
                    .collect::<Vec<_>>(),
            )
            .unwrap(),
        );
    }
    let z = |x: f64, y: f64| DVec3::new(x, y, c);
    for (x0, x1) in [(0.0, 0.8), (0.8, a)] {
        faces.push(
            planar_face(&[
                line(z(x0, 0.0), z(x1, 0.0)).unwrap(),
                line(z(x1, 0.0), z(x1, b)).unwrap(),
                line(z(x1, b), z(x0, b)).unwrap(),
                line(z(x0, b), z(x0, 0.0)).unwrap(),
            ])
            .unwrap(),
        );
    }
    let (motion, s) = placement(840);
    let body = placed(faces, &motion);
    let result = round_edges(
        &body,
        &EdgePick::All,
        EdgeFeature::Fillet { radius: r * s },
        1e-7 * s,
    )
    .unwrap_or_else(|e| panic!("{e}"));
    assert_volume(&result, rounded_box(a, b, c, r) * s.powi(3), "split top");
}

#[test]
fn a_cylinder_split_in_halves_rounds_as_one() {
    // The side as two half cylinders and each cap's circle as two half circles (as some files
    // write a cylinder): one profile, the rims filleted by Pappus.
    use crate::construct::{arc, revolve};
    let (radius, h, r) = (1.5, 2.0, 0.3);
    let mut faces = Vec::new();
    for side in [1.0, -1.0] {
        let foot = DVec3::X * (side * radius);
        let meridian = line(foot, foot + DVec3::Z * h).unwrap();
        faces.push(TrimmedSurface::untrimmed(
            revolve(&meridian, DVec3::ZERO, DVec3::Z, PI).unwrap(),
        ));
    }
    for z in [0.0, h] {
        let centre = DVec3::Z * z;
        let halves = [
            arc(centre, DVec3::X, DVec3::Y, radius, 0.0, PI).unwrap(),
            arc(centre, DVec3::X, DVec3::Y, radius, PI, 2.0 * PI).unwrap(),
        ];
        faces.push(planar_face(&halves).unwrap());
    }
    let (motion, s) = placement(850);
    let body = placed(faces, &motion);
    let result = round_edges(
        &body,
        &EdgePick::All,
        EdgeFeature::Fillet { radius: r * s },
        1e-7 * s,
    )
    .unwrap_or_else(|e| panic!("{e}"));
    let spandrel = 2.0 * PI * ((radius - r) * (1.0 - PI / 4.0) * r * r + r.powi(3) / 6.0);
    assert_volume(
        &result,
        (PI * radius * radius * h - 2.0 * spandrel) * s.powi(3),
        "halves",
    );
}

#[test]
fn a_block_with_a_round_hole_keeps_the_hole_while_its_edges_round() {
    // A block with a through hole (the boolean's result): every edge filleted or chamfered,
    // its twelve straight ones and the hole's two rims (tori or cones, by Pappus).
    use crate::boolean::{BooleanOp, boolean};
    use crate::solids::capped_cylinder;
    let (a, b, c, r, hole) = (3.0, 2.0, 1.0, 0.2, 0.4);
    let (motion, s) = placement(860);
    let block_faces = placed(block(DVec3::ZERO, DVec3::new(a, b, c)).unwrap(), &motion);
    let pin = placed(
        capped_cylinder(DVec3::new(1.2, 1.0, -0.5), DVec3::Z * (c + 1.0), hole).unwrap(),
        &motion,
    );
    let tol = 1e-7 * s;
    let plate = boolean(BooleanOp::Difference, &block_faces, &pin, tol)
        .unwrap()
        .faces();
    let bore = PI * hole * hole * c;
    let fillet = round_edges(
        &plate,
        &EdgePick::All,
        EdgeFeature::Fillet { radius: r * s },
        tol,
    )
    .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(fillet.picked, 14);
    let rims = |chamfer| 2.0 * rim_volume(hole, r, true, chamfer);
    assert_volume(
        &fillet,
        (rounded_box(a, b, c, r) - bore - rims(false)) * s.powi(3),
        "fillet",
    );
    let chamfer = round_edges(
        &plate,
        &EdgePick::All,
        EdgeFeature::Chamfer {
            distance: r * s,
            other: r * s,
        },
        tol,
    )
    .unwrap_or_else(|e| panic!("{e}"));
    let removed = 2.0 * r * r * (a + b + c) - 12.0 * r.powi(3) + 8.0 * (5.0 / 6.0) * r.powi(3);
    assert_volume(
        &chamfer,
        (a * b * c - removed - bore - rims(true)) * s.powi(3),
        "chamfer",
    );
}

/// A fillet of radius r, or a chamfer of r on both faces.
fn fillet_or_chamfer(chamfer: bool, r: f64) -> EdgeFeature {
    if chamfer {
        EdgeFeature::Chamfer {
            distance: r,
            other: r,
        }
    } else {
        EdgeFeature::Fillet { radius: r }
    }
}

/// The corner region a fillet of radius r takes from (or adds to) a right-angled edge: its
/// area r²(1 − π/4) and its centroid's distance from each face, r (10 − 3π) / (3 (4 − π)).
fn spandrel(r: f64) -> (f64, f64) {
    (
        r * r * (1.0 - PI / 4.0),
        r * (10.0 - 3.0 * PI) / (3.0 * (4.0 - PI)),
    )
}

/// The volume a fillet (or, with `chamfer`, a chamfer) of radius r takes from a circular
/// edge of radius `rim` whose flat face runs away from it outward (`outward`) or inward:
/// the corner region revolved about the axis (Pappus).
fn rim_volume(rim: f64, r: f64, outward: bool, chamfer: bool) -> f64 {
    let (area, centroid) = if chamfer {
        (0.5 * r * r, r / 3.0)
    } else {
        spandrel(r)
    };
    let s = if outward { 1.0 } else { -1.0 };
    2.0 * PI * (rim + s * centroid) * area
}

#[test]
fn hole_and_boss_rims_round_to_tori_and_cut_to_cones() {
    // A block with a through hole, one with a blind pocket and one with a pin standing on it
    // (the boolean's results), in general position: each rim is a circle where a plane meets
    // a cylinder square to it, its fillet a torus and its chamfer a cone, whose volumes
    // Pappus gives.
    use crate::boolean::{BooleanOp, boolean};
    use crate::solids::capped_cylinder;
    let (a, b, c) = (4.0, 3.0, 1.0);
    let (hole, pocket, pin) = (0.4, 0.5, 0.3);
    let (depth, height) = (0.6, 0.8);
    let (centre, r) = (DVec2::new(1.7, 1.2), 0.15);
    let at = |x: f64, z: f64| DVec3::new(centre.x + x, centre.y, z);
    // Each body: the tool, the boolean, its plain volume and its rims (a point on each, its
    // radius, whether its flat face runs outward from it, whether it is convex).
    type Rims = Vec<(DVec3, f64, bool, bool)>;
    let bodies: [(Vec<TrimmedSurface>, BooleanOp, f64, Rims); 3] = [
        (
            capped_cylinder(at(0.0, -0.5), DVec3::Z * (c + 1.0), hole).unwrap(),
            BooleanOp::Difference,
            a * b * c - PI * hole * hole * c,
            vec![
                (at(hole, c), hole, true, true),
                (at(hole, 0.0), hole, true, true),
            ],
        ),
        (
            capped_cylinder(at(0.0, c - depth), DVec3::Z * (depth + 1.0), pocket).unwrap(),
            BooleanOp::Difference,
            a * b * c - PI * pocket * pocket * depth,
            vec![
                (at(pocket, c), pocket, true, true),
                (at(pocket, c - depth), pocket, false, false),
            ],
        ),
        (
            capped_cylinder(at(0.0, c - 0.5), DVec3::Z * (height + 0.5), pin).unwrap(),
            BooleanOp::Union,
            a * b * c + PI * pin * pin * height,
            vec![
                (at(pin, c), pin, true, false),
                (at(pin, c + height), pin, false, true),
            ],
        ),
    ];
    for (n, (tool, op, plain, rims)) in bodies.into_iter().enumerate() {
        let seed = 871 + n as u64;
        let (motion, s) = placement(seed);
        let tol = 1e-7 * s;
        let to = |p: DVec3| motion.transform_point3(p);
        let block_faces = block(DVec3::ZERO, DVec3::new(a, b, c)).unwrap();
        let body = boolean(op, &block_faces, &tool, 1e-9).unwrap().faces();
        let body = placed(body, &motion);
        for chamfer in [false, true] {
            let feature = fillet_or_chamfer(chamfer, r * s);
            let change = |rims: &[(DVec3, f64, bool, bool)]| -> f64 {
                rims.iter()
                    .map(|&(_, rim, outward, convex)| {
                        let v = rim_volume(rim, r, outward, chamfer);
                        if convex { -v } else { v }
                    })
                    .sum()
            };
            let made = round_edges(
                &body,
                &EdgePick::Near(rims.iter().map(|q| to(q.0)).collect()),
                feature,
                tol,
            )
            .unwrap_or_else(|e| panic!("body {n}, chamfer {chamfer}: {e}"));
            assert_eq!(made.picked, 2);
            assert_volume(&made, (plain + change(&rims)) * s.powi(3), "both rims");
            if !chamfer {
                assert_tangent(&made, tol, "rim fillets");
            }
            // Each rim alone.
            for rim in &rims {
                let made = round_edges(&body, &EdgePick::Near(vec![to(rim.0)]), feature, tol)
                    .unwrap_or_else(|e| panic!("body {n}, chamfer {chamfer}: {e}"));
                assert_volume(
                    &made,
                    (plain + change(std::slice::from_ref(rim))) * s.powi(3),
                    "one rim",
                );
            }
        }
        // A radius wider than a rim that shrinks, or one whose ends overlap along the wall.
        let wide = round_edges(
            &body,
            &EdgePick::Near(rims.iter().map(|q| to(q.0)).collect()),
            EdgeFeature::Fillet { radius: 0.55 * s },
            tol,
        )
        .err()
        .map(|e| e.to_string())
        .unwrap_or_default();
        assert!(
            wide.contains("wider than the circle") || wide.contains("overlap"),
            "body {n}: {wide}"
        );
    }
}

#[test]
fn a_rounded_outlines_rims_are_tangent_chains_filleted_whole() {
    // A box with its four upright edges filleted at ρ (a rounded rectangle extruded), then with
    // a round hole through it, in general position: each cap's outline is one tangent chain
    // of lines and arcs, picked whole by a point near any of its pieces. Its fillet removes
    // the corner region along the lines and, revolved, about each arc (Pappus: the region's
    // centroid at ρ − k r from the corner's axis); a chamfer the triangle the same way.
    use crate::boolean::{BooleanOp, boolean};
    use crate::solids::capped_cylinder;
    let (a, b, h, rho, hole) = (4.0, 3.0, 1.5, 0.6, 0.5);
    for (n, r) in [(0_u64, 0.25), (1, 0.6)] {
        let (motion, s) = placement(890 + n);
        let tol = 1e-7 * s;
        let to = |p: DVec3| motion.transform_point3(p);
        let upright: Vec<DVec3> = [(0.0, 0.0), (a, 0.0), (a, b), (0.0, b)]
            .iter()
            .map(|&(x, y)| to(DVec3::new(x, y, 0.5 * h)))
            .collect();
        let slab = round_edges(
            &placed(block(DVec3::ZERO, DVec3::new(a, b, h)).unwrap(), &motion),
            &EdgePick::Near(upright),
            EdgeFeature::Fillet { radius: rho * s },
            tol,
        )
        .unwrap_or_else(|e| panic!("{e}"))
        .faces;
        let plain = (a * b - (4.0 - PI) * rho * rho) * h;
        let lines = 2.0 * (a - 2.0 * rho) + 2.0 * (b - 2.0 * rho);
        let rim = |chamfer: bool| {
            let (area, centroid) = if chamfer {
                (0.5 * r * r, r / 3.0)
            } else {
                spandrel(r)
            };
            area * (lines + 2.0 * PI * (rho - centroid))
        };
        for chamfer in [false, true] {
            let feature = fillet_or_chamfer(chamfer, r * s);
            // Every edge: both rims.
            let all = round_edges(&slab, &EdgePick::All, feature, tol)
                .unwrap_or_else(|e| panic!("r {r}, chamfer {chamfer}: {e}"));
            assert_eq!(all.picked, 2);
            assert_volume(&all, (plain - 2.0 * rim(chamfer)) * s.powi(3), "both rims");
            // One point near the top's straight piece takes the whole top chain.
            let top = round_edges(
                &slab,
                &EdgePick::Near(vec![to(DVec3::new(0.5 * a, -0.01, h + 0.01))]),
                feature,
                tol,
            )
            .unwrap_or_else(|e| panic!("r {r}, chamfer {chamfer}: {e}"));
            assert_eq!(top.picked, 1);
            assert_volume(&top, (plain - rim(chamfer)) * s.powi(3), "top rim");
            if !chamfer {
                assert_tangent(&all, tol, "chain fillets");
            }
        }
        // With a round hole through it: the hole's rims are chains too (a torus each, the
        // ball's centre at the hole's radius plus r).
        let holed = boolean(
            BooleanOp::Difference,
            &slab,
            &placed(
                capped_cylinder(DVec3::new(2.0, 1.5, -0.5), DVec3::Z * (h + 1.0), hole).unwrap(),
                &motion,
            ),
            tol,
        )
        .unwrap()
        .faces();
        let all = round_edges(
            &holed,
            &EdgePick::All,
            EdgeFeature::Fillet { radius: 0.25 * s },
            tol,
        )
        .unwrap_or_else(|e| panic!("holed: {e}"));
        if r == 0.25 {
            assert_eq!(all.picked, 4);
            assert_volume(
                &all,
                (plain
                    - PI * hole * hole * h
                    - 2.0 * rim(false)
                    - 2.0 * rim_volume(hole, 0.25, true, false))
                    * s.powi(3),
                "holed",
            );
        }
    }
    // A box with two upright edges filleted keeps two sharp corners: a chain picked alone
    // would end on them, which is refused with the reason.
    let (motion, s) = placement(899);
    let tol = 1e-7 * s;
    let to = |p: DVec3| motion.transform_point3(p);
    let half = round_edges(
        &placed(block(DVec3::ZERO, DVec3::new(a, b, h)).unwrap(), &motion),
        &EdgePick::Near(vec![
            to(DVec3::new(0.0, 0.0, 0.5)),
            to(DVec3::new(a, 0.0, 0.5)),
        ]),
        EdgeFeature::Fillet { radius: rho * s },
        tol,
    )
    .unwrap_or_else(|e| panic!("{e}"))
    .faces;
    let refused = round_edges(
        &half,
        &EdgePick::Near(vec![to(DVec3::new(0.5 * a, 0.0, h))]),
        EdgeFeature::Fillet { radius: 0.2 * s },
        tol,
    )
    .err()
    .map(|e| e.to_string())
    .unwrap_or_default();
    assert!(refused.contains("sharp corners"), "{refused}");
}

#[test]
fn extruded_outlines_with_arcs_shell_to_their_offsets() {
    // A box with rounded upright edges and a block with a round hole through it, in general
    // position, shelled inward and outward, closed or with a cap open: the inner body is the
    // outline offset (lines moved, arcs grown or shrunk about their centres, sharp corners
    // where the moved lines meet) between the caps moved.
    use crate::boolean::{BooleanOp, boolean};
    use crate::solids::capped_cylinder;
    let (a, b, h, rho, hole, t) = (4.0, 3.0, 1.5, 0.6, 0.5, 0.2);
    for (n, holed) in [(0_u64, false), (1, true)] {
        let (motion, s) = placement(900 + n);
        let tol = 1e-7 * s;
        let to = |p: DVec3| motion.transform_point3(p);
        let block_faces = placed(block(DVec3::ZERO, DVec3::new(a, b, h)).unwrap(), &motion);
        // The outline's area offset by d (outward below 0).
        let area: Box<dyn Fn(f64) -> f64> = if holed {
            Box::new(move |d: f64| (a - 2.0 * d) * (b - 2.0 * d) - PI * (hole + d).powi(2))
        } else {
            Box::new(move |d: f64| (a - 2.0 * d) * (b - 2.0 * d) - (4.0 - PI) * (rho - d).powi(2))
        };
        let body = if holed {
            boolean(
                BooleanOp::Difference,
                &block_faces,
                &placed(
                    capped_cylinder(DVec3::new(2.0, 1.5, -0.5), DVec3::Z * (h + 1.0), hole)
                        .unwrap(),
                    &motion,
                ),
                tol,
            )
            .unwrap()
            .faces()
        } else {
            let upright: Vec<DVec3> = [(0.0, 0.0), (a, 0.0), (a, b), (0.0, b)]
                .iter()
                .map(|&(x, y)| to(DVec3::new(x, y, 0.5 * h)))
                .collect();
            round_edges(
                &block_faces,
                &EdgePick::Near(upright),
                EdgeFeature::Fillet { radius: rho * s },
                tol,
            )
            .unwrap()
            .faces
        };
        let v0 = area(0.0) * h;
        let top = vec![to(DVec3::new(0.3, 0.3 + rho, h))];
        for (thickness, open, want) in [
            (-t, vec![], v0 - area(t) * (h - 2.0 * t)),
            (-t, top.clone(), v0 - area(t) * (h - t)),
            (t, vec![], area(-t) * (h + 2.0 * t) - v0),
            (t, top.clone(), area(-t) * (h + t) - v0),
        ] {
            let made = shell(&body, thickness * s, &open, tol).unwrap_or_else(|e| {
                panic!(
                    "holed {holed}, thickness {thickness}, open {}: {e}",
                    open.len()
                )
            });
            assert_volume(&made, want * s.powi(3), "prism shell");
        }
        // A wall open, or a wall thicker than the rounded corner allows.
        let side = shell(&body, -t * s, &[to(DVec3::new(0.5 * a, 0.0, 0.5 * h))], tol)
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default();
        assert!(side.contains("opens only its caps"), "{side}");
    }
}

#[test]
fn an_outline_with_sharp_corners_at_an_arc_rounds_and_shells() {
    // A rectangle whose top side bulges as a circular arc (sharp corners where the arc meets
    // the sides) extruded, in general position. Every edge filleted: the inner prism over the
    // outline moved in by r, grown by the ball (Steiner: V = A′H + (2A′ + P′H) r + (πH +
    // πP′/2) r² + 4πr³/3, H = h − 2r); shelled: the outline's offset area times the inner
    // height. The offset outline is the rectangle moved in and the arc's circle shrunk about
    // its centre, its area (w − 2d)(y − d) + a√(ρ² − a²) + ρ² asin(a/ρ) with a = w/2 − d,
    // ρ = R − d, y the centre's height.
    use crate::construct::{arc_through, extrude};
    let (w, l, c, h) = (3.0_f64, 2.0_f64, 1.0_f64, 1.5_f64);
    let radius = (0.25 * w * w + c * c).sqrt();
    let yc = l - c;
    let offset_area = |d: f64| {
        let (a, rho) = (0.5 * w - d, radius - d);
        (w - 2.0 * d) * (yc - d) + a * (rho * rho - a * a).sqrt() + rho * rho * (a / rho).asin()
    };
    let offset_perimeter = |d: f64| {
        let (a, rho) = (0.5 * w - d, radius - d);
        (w - 2.0 * d) + 2.0 * (yc + (rho * rho - a * a).sqrt() - d) + 2.0 * rho * (a / rho).asin()
    };
    let at = |x: f64, y: f64, z: f64| DVec3::new(x, y, z);
    let outline = |z: f64| {
        vec![
            line(at(0.0, 0.0, z), at(w, 0.0, z)).unwrap(),
            line(at(w, 0.0, z), at(w, l, z)).unwrap(),
            arc_through(at(w, l, z), at(0.5 * w, yc + radius, z), at(0.0, l, z)).unwrap(),
            line(at(0.0, l, z), at(0.0, 0.0, z)).unwrap(),
        ]
    };
    let mut faces = vec![
        planar_face(&outline(0.0)).unwrap(),
        planar_face(&outline(h)).unwrap(),
    ];
    for (p, q) in [
        ((0.0, 0.0), (w, 0.0)),
        ((w, 0.0), (w, l)),
        ((0.0, l), (0.0, 0.0)),
    ] {
        faces.push(
            planar_face(&[
                line(at(p.0, p.1, 0.0), at(q.0, q.1, 0.0)).unwrap(),
                line(at(q.0, q.1, 0.0), at(q.0, q.1, h)).unwrap(),
                line(at(q.0, q.1, h), at(p.0, p.1, h)).unwrap(),
                line(at(p.0, p.1, h), at(p.0, p.1, 0.0)).unwrap(),
            ])
            .unwrap(),
        );
    }
    faces.push(TrimmedSurface::untrimmed(
        extrude(&outline(0.0)[2], DVec3::Z * h).unwrap(),
    ));
    for seed in [910_u64, 911] {
        let (motion, s) = placement(seed);
        let tol = 1e-7 * s;
        let body = placed(faces.clone(), &motion);
        let r = 0.3;
        let big_h = h - 2.0 * r;
        let (a1, p1) = (offset_area(r), offset_perimeter(r));
        let steiner = a1 * big_h
            + (2.0 * a1 + p1 * big_h) * r
            + (PI * big_h + 0.5 * PI * p1) * r * r
            + 4.0 * PI * r.powi(3) / 3.0;
        let made = round_edges(
            &body,
            &EdgePick::All,
            EdgeFeature::Fillet { radius: r * s },
            tol,
        )
        .unwrap_or_else(|e| panic!("seed {seed}: {e}"));
        assert_volume(&made, steiner * s.powi(3), "every edge");
        assert_tangent(&made, tol, "every edge");
        let v0 = offset_area(0.0) * h;
        let t = 0.2;
        for (thickness, want) in [
            (-t, v0 - offset_area(t) * (h - 2.0 * t)),
            (t, offset_area(-t) * (h + 2.0 * t) - v0),
        ] {
            let made = shell(&body, thickness * s, &[], tol)
                .unwrap_or_else(|e| panic!("seed {seed}, shell {thickness}: {e}"));
            assert_volume(&made, want * s.powi(3), "shell");
        }
    }
}

#[test]
fn an_l_shaped_block_with_every_edge_chamfered_closes_its_inner_corners_flat() {
    // The L of area A and perimeter P, height h, every edge chamfered at d. Slices at depth s
    // under a cap (u = d − s): the L moved in by u (A − Pu + (5 − 1)u², five convex corners
    // and one concave), each convex corner cut by the corner triangle's plane (legs s:
    // s²/2), the concave one filled up to the flat quadrilateral from the upright chamfer's
    // end to the cap's straight cut (legs d + u: (d + u)²/2, as OpenCASCADE closes it); in
    // the middle the upright chamfers alone (−5d²/2 + d²/2). Integrated:
    // V = (h − 2d)(A − 2d²) + 2Ad − Pd² + 10d³/3.
    let (a, b, w, h, d) = (3.0, 2.5, 1.0, 0.8, 0.15);
    let l = l_outline(a, b, w);
    let area = a * w + (b - w) * w;
    let perimeter = 2.0 * (a + b);
    let want = (h - 2.0 * d) * (area - 2.0 * d * d) + 2.0 * area * d - perimeter * d * d
        + 10.0 * d.powi(3) / 3.0;
    for seed in 0..3 {
        let (motion, s) = placement(940 + seed);
        let body = placed(prism(&l, h), &motion);
        let result = round_edges(
            &body,
            &EdgePick::All,
            EdgeFeature::Chamfer {
                distance: d * s,
                other: d * s,
            },
            1e-7 * s,
        )
        .unwrap_or_else(|e| panic!("seed {seed}: {e}"));
        assert_volume(&result, want * s.powi(3), &format!("seed {seed}"));
    }
}

/// A block a × b × c with a block w × l × h fused on its top (`up`) or cut from it, away from
/// its edges, as the boolean leaves them.
fn block_with_block(
    (a, b, c): (f64, f64, f64),
    (x, y, w, l, h): (f64, f64, f64, f64, f64),
    up: bool,
) -> Vec<TrimmedSurface> {
    use crate::boolean::{BooleanOp, boolean};
    let base = block(DVec3::ZERO, DVec3::new(a, b, c)).unwrap();
    let (op, z, height) = if up {
        (BooleanOp::Union, c - 0.5, h + 0.5)
    } else {
        (BooleanOp::Difference, c - h, h + 0.5)
    };
    let tool = block(DVec3::new(x, y, z), DVec3::new(w, l, height)).unwrap();
    boolean(op, &base, &tool, 1e-9).unwrap().faces()
}

#[test]
fn a_boss_and_a_pocket_fillet_round_their_feet_and_mouths_on_tori() {
    // Every edge at r: the block is the rounded box; the boss or pocket is its outline
    // rounded at r (area wl − (4 − π)r², perimeter P′) times its height, and the rims' balls
    // roll round that outline: the spandrel S = (1 − π/4)r², centroid x̄ = (10 − 3π)r/(12 − 3π)
    // from the edge, swept on curves moved in or out by x̄ (Pappus: P′ ∓ 2πx̄). The boss's top
    // takes S(P′ − 2πx̄), its foot gives S(P′ + 2πx̄); the pocket the other way round. Net:
    // ± (A′h + 4πx̄S) = ±(A′h + π(10 − 3π)r³/3). Where the foot's concave fillets meet the
    // convex upright one (and the mouth's convex ones the concave upright one), the corner
    // is a torus about the upright fillet's axis.
    let (a, b, c) = (4.0, 3.5, 1.2);
    let (x, y, w, l, h) = (1.1, 0.9, 1.6, 1.3, 0.7);
    let r = 0.12;
    let outline = w * l - (4.0 - PI) * r * r;
    let corners = PI * (10.0 - 3.0 * PI) * r.powi(3) / 3.0;
    for (n, up) in [true, false].into_iter().enumerate() {
        let want = rounded_box(a, b, c, r)
            + if up {
                outline * h + corners
            } else {
                -(outline * h + corners)
            };
        let body = block_with_block((a, b, c), (x, y, w, l, h), up);
        for seed in 0..2 {
            let (motion, s) = placement(950 + 2 * n as u64 + seed);
            let result = round_edges(
                &placed(body.clone(), &motion),
                &EdgePick::All,
                EdgeFeature::Fillet { radius: r * s },
                1e-7 * s,
            )
            .unwrap_or_else(|e| panic!("up {up}, seed {seed}: {e}"));
            assert_volume(&result, want * s.powi(3), &format!("up {up}, seed {seed}"));
            assert_tangent(&result, 1e-7 * s, "boss or pocket");
        }
    }
}

#[test]
fn an_l_whose_caps_are_split_into_rectangles_is_read_whole() {
    // The L prism with each cap given as two rectangles, as a boolean union of two blocks
    // leaves it: the long rectangle's inner side is two edges, one along the inner wall and
    // one along the short rectangle, meeting at the inner corner where it runs straight on.
    // Read whole, it is the L: its fillet and chamfer of every edge and its shell have the
    // L's volumes.
    let (a, b, w, h) = (3.0, 2.5, 1.0, 0.8);
    let l = l_outline(a, b, w);
    let whole = prism(&l, h);
    let polygon = |corners: &[DVec2], z: f64, up: bool| {
        let at = |p: DVec2| DVec3::new(p.x, p.y, z);
        let mut c = corners.to_vec();
        if !up {
            c.reverse();
        }
        let n = c.len();
        let sides: Vec<_> = (0..n)
            .map(|i| line(at(c[i]), at(c[(i + 1) % n])).unwrap())
            .collect();
        planar_face(&sides).unwrap()
    };
    let long = [l[0], l[1], l[2], l[3], DVec2::new(0.0, w)];
    let short = [DVec2::new(0.0, w), l[3], l[4], l[5]];
    // The walls, the one along x = 0 split where the blocks met too.
    let mut split: Vec<TrimmedSurface> = whole[2..7].to_vec();
    let wall = |p: DVec2, q: DVec2| {
        let at = |p: DVec2, z: f64| DVec3::new(p.x, p.y, z);
        planar_face(&[
            line(at(p, 0.0), at(q, 0.0)).unwrap(),
            line(at(q, 0.0), at(q, h)).unwrap(),
            line(at(q, h), at(p, h)).unwrap(),
            line(at(p, h), at(p, 0.0)).unwrap(),
        ])
        .unwrap()
    };
    split.push(wall(l[5], DVec2::new(0.0, w)));
    split.push(wall(DVec2::new(0.0, w), l[0]));
    for (z, up) in [(0.0, false), (h, true)] {
        split.push(polygon(&long, z, up));
        split.push(polygon(&short, z, up));
    }
    let features = [
        EdgeFeature::Fillet { radius: 0.15 },
        EdgeFeature::Chamfer {
            distance: 0.15,
            other: 0.15,
        },
    ];
    let (motion, s) = placement(960);
    for feature in features {
        let want = round_edges(&whole, &EdgePick::All, feature, 1e-9)
            .unwrap()
            .volume()
            .unwrap();
        let scaled = match feature {
            EdgeFeature::Fillet { radius } => EdgeFeature::Fillet { radius: radius * s },
            EdgeFeature::Chamfer { distance, other } => EdgeFeature::Chamfer {
                distance: distance * s,
                other: other * s,
            },
        };
        let result = round_edges(
            &placed(split.clone(), &motion),
            &EdgePick::All,
            scaled,
            1e-7 * s,
        )
        .unwrap_or_else(|e| panic!("{feature:?}: {e}"));
        assert_volume(&result, want * s.powi(3), &format!("{feature:?}"));
    }
    let t = 0.1;
    let want = a * w + (b - w) * w;
    let want = want * h - (want - 2.0 * (a + b) * t + 4.0 * t * t) * (h - 2.0 * t);
    let result = shell(&placed(split, &motion), -t * s, &[], 1e-7 * s).unwrap();
    assert_volume(&result, want * s.powi(3), "shell");
}

#[test]
fn a_block_with_a_pin_shells_with_its_round_wall_offset() {
    // A block a × b × c with a pin of radius ρ standing H on it. Inward by t, closed: the
    // inner body is the block moved in and the pin of radius ρ − t standing H on it; open at
    // the pin's top, the inner pin runs t higher, through it. Outward: the block moved out
    // and the pin of radius ρ + t standing H on it.
    use crate::boolean::{BooleanOp, boolean};
    use crate::solids::capped_cylinder;
    let (a, b, c) = (4.0, 3.0, 1.0);
    let (centre, rho, height) = (DVec2::new(1.7, 1.2), 0.5, 0.8);
    let t = 0.1;
    let base = block(DVec3::ZERO, DVec3::new(a, b, c)).unwrap();
    let pin = capped_cylinder(
        DVec3::new(centre.x, centre.y, c - 0.5),
        DVec3::Z * (height + 0.5),
        rho,
    )
    .unwrap();
    let body = boolean(BooleanOp::Union, &base, &pin, 1e-9)
        .unwrap()
        .faces();
    let solid = a * b * c + PI * rho * rho * height;
    let inner_block = (a - 2.0 * t) * (b - 2.0 * t) * (c - 2.0 * t);
    let top = DVec3::new(centre.x, centre.y, c + height);
    let cases = [
        (
            -t,
            vec![],
            solid - inner_block - PI * (rho - t).powi(2) * height,
        ),
        (
            -t,
            vec![top],
            solid - inner_block - PI * (rho - t).powi(2) * (height + t),
        ),
        (
            t,
            vec![],
            (a + 2.0 * t) * (b + 2.0 * t) * (c + 2.0 * t) + PI * (rho + t).powi(2) * height - solid,
        ),
    ];
    for (n, (thickness, open, want)) in cases.into_iter().enumerate() {
        let (motion, s) = placement(970 + n as u64);
        let open: Vec<DVec3> = open.iter().map(|&p| motion.transform_point3(p)).collect();
        let result = shell(
            &placed(body.clone(), &motion),
            thickness * s,
            &open,
            1e-7 * s,
        )
        .unwrap_or_else(|e| panic!("case {n}: {e}"));
        assert_volume(&result, want * s.powi(3), &format!("case {n}"));
    }
}

#[test]
fn a_hexagonal_and_an_octagonal_prism_chamfered_close_their_corners_with_quadrilaterals() {
    // A regular n-gon prism (area A, perimeter P, interior angle θ ≥ 120°, c = cot(θ/2)),
    // height h, every edge chamfered at d. The upright chamfer cuts each corner's triangle
    // (legs d: d² sin θ / 2) up to d under the caps; there, as OpenCASCADE closes such a
    // corner, a flat quadrilateral runs from its end to the cap's straight cut between the
    // cap strips' square ends. The slice at depth d − u is the n-gon moved in by u
    // (A − Pu + n c u²) less, at each corner, the triangle of legs d − cu:
    // V = (h − 2d)(A − n d² sin θ / 2) + 2 [Ad − Pd²/2 + n c d³/3
    //     − (n sin θ / 2) d³ (1 − (1 − c)³) / (3c)].
    let (radius, h, d) = (2.0, 1.5, 0.2);
    for n in [6usize, 8] {
        let theta = PI - 2.0 * PI / n as f64;
        let c = 1.0 / (theta / 2.0).tan();
        let base = regular_polygon(n, radius);
        let side = 2.0 * radius * (PI / n as f64).sin();
        let perimeter = n as f64 * side;
        let area = 0.5 * n as f64 * radius * radius * (2.0 * PI / n as f64).sin();
        let nf = n as f64;
        let want = (h - 2.0 * d) * (area - nf * d * d * theta.sin() / 2.0)
            + 2.0
                * (area * d - perimeter * d * d / 2.0 + nf * c * d.powi(3) / 3.0
                    - nf * theta.sin() / 2.0 * d.powi(3) * (1.0 - (1.0 - c).powi(3)) / (3.0 * c));
        let (motion, s) = placement(980 + n as u64);
        let result = round_edges(
            &placed(prism(&base, h), &motion),
            &EdgePick::All,
            EdgeFeature::Chamfer {
                distance: d * s,
                other: d * s,
            },
            1e-7 * s,
        )
        .unwrap_or_else(|e| panic!("{n}-gon: {e}"));
        assert_volume(&result, want * s.powi(3), &format!("{n}-gon"));
    }
}

#[test]
fn two_chamfers_at_a_corner_that_is_not_square_cut_as_their_planes_do() {
    // A hexagonal prism with an upright edge and a cap edge at one corner chamfered (the
    // third edge there not): the convex body cut by the two strips' planes, which the
    // boolean gives independently (the body less a large block on the far side of each).
    use crate::boolean::{BooleanOp, boolean};
    use glam::DQuat;
    let (radius, h, d) = (2.0, 1.5, 0.2);
    let base = regular_polygon(6, radius);
    let body = prism(&base, h);
    let corner = DVec3::new(radius, 0.0, h);
    let next = DVec3::new(base[1].x, base[1].y, h);
    let prev = DVec3::new(base[5].x, base[5].y, 0.0);
    // The upright edge's strip: the plane through the points d along both walls.
    let walls = [
        (next - corner).normalize() * d,
        (DVec3::new(prev.x, prev.y, h) - corner).normalize() * d,
    ];
    let upright = (corner + walls[0], DVec3::X);
    // The cap edge's strip: through the line d in on the cap and the line d down the wall.
    let wall_normal = DVec3::new((PI / 6.0).cos(), (PI / 6.0).sin(), 0.0);
    let cap = (corner - DVec3::Z * d, (wall_normal + DVec3::Z).normalize());
    let mut want = body.clone();
    for (point, normal) in [upright, cap] {
        let slab = block(
            DVec3::new(-50.0, -50.0, 0.0),
            DVec3::new(100.0, 100.0, 100.0),
        )
        .unwrap();
        let motion =
            DAffine3::from_rotation_translation(DQuat::from_rotation_arc(DVec3::Z, normal), point);
        let slab = placed(slab, &motion);
        want = boolean(BooleanOp::Difference, &want, &slab, 1e-9)
            .unwrap()
            .faces();
    }
    let want = crate::mass::signed_volume(&want).unwrap();
    let (motion, s) = placement(990);
    let picks = vec![
        motion.transform_point3(DVec3::new(radius, 0.0, 0.5 * h)),
        motion.transform_point3(0.5 * (corner + next)),
    ];
    let result = round_edges(
        &placed(body, &motion),
        &EdgePick::Near(picks),
        EdgeFeature::Chamfer {
            distance: d * s,
            other: d * s,
        },
        1e-7 * s,
    )
    .unwrap();
    assert_volume(&result, want * s.powi(3), "two chamfers");
}

/// The area between a corner of angle ψ and its rolling-ball fillet of radius 1:
/// cot(ψ/2) − (π − ψ)/2 (two right triangles less the arc's sector).
fn spandrel_area(psi: f64) -> f64 {
    1.0 / (0.5 * psi).tan() - 0.5 * (PI - psi)
}

#[test]
fn an_upright_edge_filleted_from_one_radius_to_another_takes_its_integral() {
    // An upright edge of a right prism (height h, interior angle ψ, or ψ outside the
    // material at a concave corner) filleted from r_a at the base to r_b at the top: each
    // level's section is the fillet of the radius there, so the fillet takes (or, concave,
    // adds) ∫ spandrel(ψ) r(z)² dz = spandrel(ψ) h (r_a² + r_a r_b + r_b²) / 3.
    let h = 1.5;
    let mut cases: Vec<(Vec<DVec2>, usize, &str)> = vec![
        (regular_polygon(3, 1.2), 0, "triangle"),
        (regular_polygon(5, 1.2), 2, "pentagon"),
        (regular_polygon(7, 1.2), 4, "heptagon"),
    ];
    let l = l_outline(2.0, 1.6, 0.7).to_vec();
    cases.push((l.clone(), 1, "L outer corner"));
    cases.push((l, 3, "L inner corner"));
    for (i, (base, corner, what)) in cases.into_iter().enumerate() {
        let n = base.len();
        let area = (0..n)
            .map(|j| base[j].perp_dot(base[(j + 1) % n]))
            .sum::<f64>()
            / 2.0;
        let (prev, here, next) = (
            base[(corner + n - 1) % n],
            base[corner],
            base[(corner + 1) % n],
        );
        let (to_prev, to_next) = (prev - here, next - here);
        let convex = to_next.perp_dot(to_prev) > 0.0;
        let psi = to_prev.angle_to(to_next).abs();
        for (ra, rb) in [(0.1, 0.25), (0.3, 0.05)] {
            let (motion, s) = placement(1200 + i as u64);
            let body = placed(prism(&base, h), &motion);
            let at = |z: f64| motion.transform_point3(DVec3::new(here.x, here.y, z));
            let result = round_edges_varying(
                &body,
                &EdgePick::Near(vec![at(0.5 * h)]),
                EdgeFeature::Fillet { radius: 1.0 },
                &[(at(0.0), ra * s), (at(h), rb * s)],
                1e-7 * s,
            )
            .unwrap_or_else(|e| panic!("{what} {ra}→{rb}: {e}"));
            let taken = spandrel_area(psi) * h * (ra * ra + ra * rb + rb * rb) / 3.0;
            let want = area * h + if convex { -taken } else { taken };
            assert_volume(&result, want * s.powi(3), &format!("{what} {ra}→{rb}"));
            // Along its contacts; its ends meet the caps at an angle, as the radius changes.
            assert_tangent_at(&result, 1e-6 * s, what, |[(u0, u1), (v0, v1)], t| {
                let v = v0 + (v1 - v0) * (0.05 + 0.9 * t);
                vec![(u0, v), (u1, v)]
            });
        }
    }
}
