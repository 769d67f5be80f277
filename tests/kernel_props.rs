//! Property tests of the NURBS kernel on random rational surfaces: degrees 1–5, clamped knot
//! vectors on random domains with repeated interior knots, weights 0.2–5. Shape-preserving
//! operations must leave every evaluated point unchanged to 1e-12 (relative to the model size),
//! the basis must sum to one, points must lie in the control points' convex hull (checked on
//! the bounding box and, exactly, as a positive combination), derivatives must agree with finite
//! differences, and a written file must read back as the same surface.

use glam::DVec3;
use knotwork::kernel::basis::{basis_derivatives, find_span};
use knotwork::kernel::{Direction, NurbsSurface, SpaceCurve};
use knotwork::scene::json::{self, Geometry, NamedGeometry};
use proptest::prelude::*;

mod common;
use common::{Rng, random_knots, random_surface};

/// Random parameters in the domain, including its corners and edges.
fn sample_params(s: &NurbsSurface, seed: u64, n: usize) -> Vec<(f64, f64)> {
    let mut rng = Rng(seed ^ 0xDEAD_BEEF);
    let [(u0, u1), (v0, v1)] = s.domain();
    let mut out = vec![(u0, v0), (u1, v1), (u0, v1), (u1, v0)];
    for _ in 0..n {
        out.push((rng.range(u0, u1), rng.range(v0, v1)));
    }
    out
}

/// Asserts two surfaces describe the same shape at the sample parameters, to 1e-12 × size.
fn assert_same_shape(a: &NurbsSurface, b: &NurbsSurface, seed: u64) -> Result<(), TestCaseError> {
    let scale = a.size().max(1.0);
    for (u, v) in sample_params(a, seed, 40) {
        let pa = a.point_at(u, v).unwrap();
        let pb = b.point_at(u, v).unwrap();
        prop_assert!(
            pa.distance(pb) <= 1e-12 * scale,
            "at ({u}, {v}): {pa:?} vs {pb:?} (difference {:e})",
            pa.distance(pb)
        );
    }
    Ok(())
}

fn interior_value(s: &NurbsSurface, d: Direction, t: f64) -> f64 {
    let (a, b) = s.domain()[d.index()];
    a + (b - a) * t
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]

    #[test]
    fn basis_is_a_partition_of_unity(p in 1usize..=5, seed in any::<u64>()) {
        let mut rng = Rng(seed);
        let (knots, count) = random_knots(&mut rng, p);
        let (a, b) = (knots[p], knots[count]);
        for k in 0..=50 {
            let u = (a + (b - a) * k as f64 / 50.0).min(b);
            let span = find_span(&knots, p, count, u);
            prop_assert!(knots[span] <= u && (u < knots[span + 1] || u == b));
            let d = basis_derivatives(&knots, p, span, u, 2);
            let sum: f64 = d[0].iter().sum();
            prop_assert!((sum - 1.0).abs() < 1e-14, "Σ N = {sum}");
            prop_assert!(d[0].iter().all(|&n| n >= -1e-15));
            // Derivatives of a partition of unity sum to zero.
            prop_assert!(d[1].iter().sum::<f64>().abs() < 1e-9 * (1.0 + d[1].iter().map(|x| x.abs()).sum::<f64>()));
        }
    }

    #[test]
    fn points_lie_in_the_convex_hull(p in 1usize..=5, q in 1usize..=5, seed in any::<u64>()) {
        let s = random_surface(p, q, seed);
        let (lo, hi) = s.bounds();
        for (u, v) in sample_params(&s, seed, 30) {
            let x = s.point_at(u, v).unwrap();
            prop_assert!(x.cmpge(lo - 1e-12).all() && x.cmple(hi + 1e-12).all(), "{x:?} outside [{lo:?}, {hi:?}]");
        }
    }

    #[test]
    fn knot_insertion_preserves_shape(p in 1usize..=5, q in 1usize..=5, seed in any::<u64>(), t in 0.01f64..0.99) {
        let s = random_surface(p, q, seed);
        for d in [Direction::U, Direction::V] {
            let value = interior_value(&s, d, t);
            let have = s.knots()[d.index()].iter().filter(|&&k| k == value).count();
            let deg = s.degree()[d.index()];
            if have < deg {
                let r = s.insert_knot(d, value, deg - have).unwrap();
                prop_assert_eq!(r.count()[d.index()], s.count()[d.index()] + deg - have);
                assert_same_shape(&s, &r, seed)?;
            }
        }
    }

    #[test]
    fn knot_refinement_preserves_shape(p in 1usize..=5, q in 1usize..=5, seed in any::<u64>()) {
        let s = random_surface(p, q, seed);
        for d in [Direction::U, Direction::V] {
            let x: Vec<f64> = [0.13, 0.5, 0.5, 0.77].iter().map(|&t| interior_value(&s, d, t)).collect();
            let deg = s.degree()[d.index()];
            let fits = x.iter().all(|k| {
                s.knots()[d.index()].iter().filter(|&y| y == k).count() + x.iter().filter(|&y| y == k).count() <= deg
            });
            if fits {
                let r = s.refine(d, &x).unwrap();
                prop_assert_eq!(r.count()[d.index()], s.count()[d.index()] + x.len());
                assert_same_shape(&s, &r, seed)?;
            }
        }
    }

    #[test]
    fn bezier_decomposition_preserves_shape(p in 1usize..=5, q in 1usize..=5, seed in any::<u64>()) {
        let s = random_surface(p, q, seed);
        let patches = s.bezier_patches();
        let scale = s.size().max(1.0);
        for (patch, [[u0, u1], [v0, v1]]) in &patches {
            prop_assert_eq!(patch.count(), [p + 1, q + 1]);
            for (a, b) in [(0.0, 0.0), (0.25, 0.75), (1.0, 1.0), (0.5, 0.1)] {
                let (u, v) = ((u0 + (u1 - u0) * a).min(*u1), (v0 + (v1 - v0) * b).min(*v1));
                let d = s.point_at(u, v).unwrap().distance(patch.point_at(u, v).unwrap());
                prop_assert!(d <= 1e-12 * scale, "patch point differs by {d:e}");
            }
        }
        let spans = |d: usize| {
            let mut k = s.knots()[d].to_vec();
            k.dedup();
            k.len() - 1
        };
        prop_assert_eq!(patches.len(), spans(0) * spans(1));
    }

    #[test]
    fn one_span_gives_the_same_bezier_patch_as_the_whole_decomposition(
        p in 1usize..=5, q in 1usize..=5, seed in any::<u64>()) {
        // Local extraction (the span's own points and knots) against the global refinement,
        // point by point in homogeneous form.
        let s = random_surface(p, q, seed);
        let set = s.to_bezier_patch_set().unwrap();
        let scale = s.size().max(1.0);
        for (k, patch) in set.patches().iter().enumerate() {
            let local = s.bezier_patch_points(k).unwrap();
            prop_assert_eq!(local.len(), patch.indices().len());
            for (h, &index) in local.iter().zip(patch.indices()) {
                let (point, weight) = (set.points()[index as usize], set.weights()[index as usize]);
                prop_assert!((h.w - weight).abs() <= 1e-12 * weight, "weight {} vs {weight}", h.w);
                let d = (h.truncate() / h.w).distance(point);
                prop_assert!(d <= 1e-12 * scale, "patch {k}: point differs by {d:e}");
            }
        }
        prop_assert!(s.bezier_patch_points(set.patches().len()).is_err());
    }

    #[test]
    fn degree_elevation_preserves_shape(p in 1usize..=5, q in 1usize..=5, seed in any::<u64>(), t in 1usize..=2) {
        let s = random_surface(p, q, seed);
        for d in [Direction::U, Direction::V] {
            let r = s.elevate_degree(d, t).unwrap();
            prop_assert_eq!(r.degree()[d.index()], s.degree()[d.index()] + t);
            // Each distinct knot (ends included) gains multiplicity t.
            let distinct = {
                let mut k = s.knots()[d.index()].to_vec();
                k.dedup();
                k.len()
            };
            prop_assert_eq!(r.knots()[d.index()].len(), s.knots()[d.index()].len() + distinct * t);
            assert_same_shape(&s, &r, seed)?;
        }
    }

    #[test]
    fn split_preserves_shape(p in 1usize..=5, q in 1usize..=5, seed in any::<u64>(), t in 0.05f64..0.95) {
        let s = random_surface(p, q, seed);
        for d in [Direction::U, Direction::V] {
            let value = interior_value(&s, d, t);
            let (left, right) = s.split(d, value).unwrap();
            let scale = s.size().max(1.0);
            for (u, v) in sample_params(&s, seed, 40) {
                let at = if d == Direction::U { u } else { v };
                let piece = if at <= value { &left } else { &right };
                let a = s.point_at(u, v).unwrap();
                let b = piece.point_at(u, v).unwrap();
                prop_assert!(a.distance(b) <= 1e-12 * scale, "split piece differs by {:e}", a.distance(b));
            }
        }
    }

    #[test]
    fn derivatives_match_finite_differences(p in 1usize..=5, q in 1usize..=5, seed in any::<u64>()) {
        let s = random_surface(p, q, seed);
        let [(u0, u1), (v0, v1)] = s.domain();
        let h = 1e-6 * (u1 - u0).max(v1 - v0);
        let knots_u = s.knots()[0].to_vec();
        let knots_v = s.knots()[1].to_vec();
        for (u, v) in sample_params(&s, seed, 20).into_iter().skip(4) {
            // Central differences need both sides in one polynomial piece.
            let near = |k: &[f64], t: f64| k.iter().any(|&x| (x - t).abs() < 10.0 * h);
            if near(&knots_u, u) || near(&knots_v, v) {
                continue;
            }
            let d = s.evaluate(u, v).unwrap();
            let at = |du: f64, dv: f64| s.evaluate(u + du, v + dv).unwrap();
            let fd_u = (at(h, 0.0).point - at(-h, 0.0).point) / (2.0 * h);
            let fd_v = (at(0.0, h).point - at(0.0, -h).point) / (2.0 * h);
            let fd_uu = (at(h, 0.0).su - at(-h, 0.0).su) / (2.0 * h);
            let fd_uv = (at(0.0, h).su - at(0.0, -h).su) / (2.0 * h);
            let fd_vv = (at(0.0, h).sv - at(0.0, -h).sv) / (2.0 * h);
            let scale = d.su.length() + d.sv.length() + d.suu.length() + d.suv.length() + d.svv.length() + 1.0;
            for (name, exact, fd) in [("su", d.su, fd_u), ("sv", d.sv, fd_v), ("suu", d.suu, fd_uu), ("suv", d.suv, fd_uv), ("svv", d.svv, fd_vv)] {
                prop_assert!(exact.distance(fd) <= 1e-5 * scale, "{name} at ({u}, {v}): {exact:?} vs {fd:?}");
            }
        }
    }

    #[test]
    fn written_files_read_back_identically(p in 1usize..=5, q in 1usize..=5, seed in any::<u64>()) {
        let s = random_surface(p, q, seed);
        let curve = SpaceCurve::new(2, vec![0.0, 0.0, 0.0, 0.4, 1.0, 1.0, 1.0], vec![DVec3::X, DVec3::Y, DVec3::Z, DVec3::ONE], Some(vec![1.0, 0.5, 2.0, 1.0])).unwrap();
        let objects = vec![
            NamedGeometry { name: Some("random".into()), geometry: Geometry::Surface(s.clone()) },
            NamedGeometry { name: None, geometry: Geometry::Curve(curve) },
        ];
        let text = json::write(&objects);
        let back = json::read(&text).unwrap();
        prop_assert_eq!(back.len(), 2);
        match &back[0].geometry {
            Geometry::Surface(r) => {
                prop_assert_eq!(r.degree(), s.degree());
                prop_assert_eq!(r.knots(), s.knots());
                // Cartesian coordinates and weights round-trip exactly; the homogeneous products
                // are recomputed from them, so they may differ in the last bit.
                for (a, b) in r.homogeneous_points().iter().zip(s.homogeneous_points()) {
                    prop_assert!(a.distance(*b) <= 1e-15 * b.length());
                }
                assert_same_shape(&s, r, seed)?;
            }
            _ => prop_assert!(false, "expected a surface"),
        }
        prop_assert_eq!(&back[1], &objects[1]);
    }
}

#[test]
fn knot_removal_of_inserted_knots_on_random_surfaces() {
    for seed in 0..40u64 {
        let s = random_surface(1 + (seed % 5) as usize, 1 + (seed / 5 % 5) as usize, seed);
        let value = interior_value(&s, Direction::V, 0.4321);
        let r = s.insert_knot(Direction::V, value, 1).unwrap();
        let (back, n) = r.remove_knot(Direction::V, value, 1, 1e-9);
        assert_eq!(n, 1, "seed {seed}");
        let scale = s.size().max(1.0);
        for (u, v) in sample_params(&s, seed, 20) {
            assert!(
                back.point_at(u, v)
                    .unwrap()
                    .distance(s.point_at(u, v).unwrap())
                    <= 1e-11 * scale
            );
        }
    }
}

/// `count` random points in [−10, 10]³, consecutive ones at least 0.05 apart.
fn random_points(rng: &mut Rng, count: usize) -> Vec<DVec3> {
    let mut points: Vec<DVec3> = Vec::with_capacity(count);
    while points.len() < count {
        let p = DVec3::new(
            rng.range(-10.0, 10.0),
            rng.range(-10.0, 10.0),
            rng.range(-10.0, 10.0),
        );
        if points.last().is_none_or(|q| q.distance(p) > 0.05) {
            points.push(p);
        }
    }
    points
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, ..ProptestConfig::default() })]

    /// Interpolants pass through their points: open (any parametrization, with or without end
    /// tangents), closed (C^{p−1} at the seam) and Catmull-Rom (through the inner points).
    #[test]
    fn interpolants_pass_through_their_points(count in 4usize..12, p in 1usize..=5, seed in any::<u64>()) {
        use knotwork::kernel::splines::{self, Parametrization};
        let mut rng = Rng(seed);
        let points = random_points(&mut rng, count);
        let tolerance = 1e-8 * 20.0;
        for parametrization in [Parametrization::ChordLength, Parametrization::Centripetal, Parametrization::Uniform] {
            let params = splines::parameters(&points, parametrization, "test").unwrap();
            let tangents = (p > 1).then(|| (DVec3::new(1.0, -2.0, 0.5), DVec3::new(0.0, 3.0, 1.0)));
            for ends in [None, tangents] {
                let curve = splines::interpolate_through(&points, p, parametrization, ends).unwrap();
                for (q, &t) in points.iter().zip(&params) {
                    let at = curve.point_at(t).unwrap();
                    prop_assert!(at.distance(*q) < tolerance, "open {parametrization:?} p {p}: {at} vs {q}");
                }
            }
            let mut closed = points.clone();
            closed.push(points[0]);
            if points[0].distance(points[count - 1]) > 0.05 {
                let curve = splines::interpolate_closed(&points, p, parametrization).unwrap();
                let (start, _) = curve.domain();
                let params = splines::parameters(&closed, parametrization, "test").unwrap();
                for (q, &t) in points.iter().zip(&params) {
                    let t = if t < start { t + 1.0 } else { t };
                    let at = curve.point_at(t).unwrap();
                    prop_assert!(at.distance(*q) < tolerance, "closed {parametrization:?} p {p}: {at} vs {q}");
                }
            }
        }
        for alpha in [0.0, 0.5, 1.0] {
            let curve = splines::catmull_rom(&points, alpha).unwrap();
            let mut t = 0.0;
            for k in 1..count - 1 {
                t += points[k].distance(points[k - 1]).powf(alpha);
                let at = curve.point_at(t).unwrap();
                prop_assert!(at.distance(points[k]) < tolerance, "Catmull-Rom α {alpha}: {at} vs {}", points[k]);
            }
        }
    }
}
