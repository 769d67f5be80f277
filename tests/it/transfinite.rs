//! Hermite, bicubically blended Coons and Gordon surfaces against their definitions: the
//! Hermite matrix form evaluated directly, reproduction of polynomial surfaces whose data they
//! are given (a bicubic from its boundary curves and cross derivatives; a bicubic from a network
//! of its isoparametric curves), interpolation of every given curve and derivative, the
//! two-by-two Gordon surface as the bilinear Coons patch, and refusals with reasons.

use crate::common;

use common::Rng;
use glam::DVec3;
use knotwork::kernel::construct;
use knotwork::kernel::transfinite::{self, CORNERS, HermiteData};
use knotwork::kernel::{NurbsCurve, NurbsSurface, SpaceCurve};

fn binomial(n: usize, k: usize) -> f64 {
    (0..k).fold(1.0, |acc, i| acc * (n - i) as f64 / (i + 1) as f64)
}

/// The Bernstein polynomial B_k^n(t), written out.
fn bernstein(n: usize, k: usize, t: f64) -> f64 {
    binomial(n, k) * t.powi(k as i32) * (1.0 - t).powi((n - k) as i32)
}

/// d/dt B_k^n(t) = n (B_{k−1}^{n−1} − B_k^{n−1}).
fn bernstein_derivative(n: usize, k: usize, t: f64) -> f64 {
    let lower = |k: isize| {
        if k < 0 || k as usize > n - 1 {
            0.0
        } else {
            bernstein(n - 1, k as usize, t)
        }
    };
    n as f64 * (lower(k as isize - 1) - lower(k as isize))
}

/// A polynomial surface of degree (p, q): a random net over a gently curved grid.
struct Polynomial {
    p: usize,
    q: usize,
    net: Vec<DVec3>,
}

impl Polynomial {
    fn random(p: usize, q: usize, seed: u64) -> Self {
        let mut rng = Rng(seed);
        let mut net = Vec::new();
        for i in 0..=p {
            for j in 0..=q {
                net.push(DVec3::new(
                    i as f64 / p as f64 * 3.0 + rng.range(-0.2, 0.2),
                    j as f64 / q as f64 * 2.0 + rng.range(-0.2, 0.2),
                    rng.range(-0.8, 0.8),
                ));
            }
        }
        Self { p, q, net }
    }

    fn at(&self, i: usize, j: usize) -> DVec3 {
        self.net[i * (self.q + 1) + j]
    }

    /// S(u, v) by the Bernstein sum.
    fn point(&self, u: f64, v: f64) -> DVec3 {
        let mut s = DVec3::ZERO;
        for i in 0..=self.p {
            for j in 0..=self.q {
                s += self.at(i, j) * (bernstein(self.p, i, u) * bernstein(self.q, j, v));
            }
        }
        s
    }

    /// The curve v ↦ S(u0, v) (or, with `derivative`, ∂S/∂u at u0) as a Bézier curve.
    fn along_v(&self, u0: f64, derivative: bool) -> SpaceCurve {
        let weight = |i| {
            if derivative {
                bernstein_derivative(self.p, i, u0)
            } else {
                bernstein(self.p, i, u0)
            }
        };
        let points = (0..=self.q)
            .map(|j| (0..=self.p).map(|i| self.at(i, j) * weight(i)).sum())
            .collect();
        bezier_curve(self.q, points)
    }

    /// The curve u ↦ S(u, v0) (or ∂S/∂v at v0).
    fn along_u(&self, v0: f64, derivative: bool) -> SpaceCurve {
        let weight = |j| {
            if derivative {
                bernstein_derivative(self.q, j, v0)
            } else {
                bernstein(self.q, j, v0)
            }
        };
        let points = (0..=self.p)
            .map(|i| (0..=self.q).map(|j| self.at(i, j) * weight(j)).sum())
            .collect();
        bezier_curve(self.p, points)
    }
}

fn bezier_curve(degree: usize, points: Vec<DVec3>) -> SpaceCurve {
    let mut knots = vec![0.0; degree + 1];
    knots.extend(vec![1.0; degree + 1]);
    NurbsCurve::new(degree, knots, points, None).unwrap()
}

fn grid(n: usize) -> impl Iterator<Item = (f64, f64)> {
    (0..=n).flat_map(move |a| (0..=n).map(move |b| (a as f64 / n as f64, b as f64 / n as f64)))
}

fn largest_gap(a: impl Fn(f64, f64) -> DVec3, b: impl Fn(f64, f64) -> DVec3, n: usize) -> f64 {
    grid(n)
        .map(|(u, v)| a(u, v).distance(b(u, v)))
        .fold(0.0, f64::max)
}

#[test]
fn the_hermite_patch_is_the_hermite_matrix_form() {
    let mut rng = Rng(7);
    let mut random = || {
        DVec3::new(
            rng.range(-2.0, 2.0),
            rng.range(-2.0, 2.0),
            rng.range(-2.0, 2.0),
        )
    };
    let data = HermiteData {
        points: std::array::from_fn(|_| random()),
        su: std::array::from_fn(|_| random()),
        sv: std::array::from_fn(|_| random()),
        twist: std::array::from_fn(|_| random()),
    };
    let surface = transfinite::hermite_patch(&data).unwrap();
    // The seed's cubic Hermite functions: c(t) = H0 c(0) + H1 c(1) + H2 c'(0) + H3 c'(1).
    let h = |t: f64| {
        [
            2.0 * t.powi(3) - 3.0 * t * t + 1.0,
            -2.0 * t.powi(3) + 3.0 * t * t,
            t.powi(3) - 2.0 * t * t + t,
            t.powi(3) - t * t,
        ]
    };
    // G = [[S00 S01 Sv00 Sv01] [S10 S11 Sv10 Sv11] [Su00 Su01 Suv00 Suv01] [Su10 Su11 Suv10 Suv11]].
    let index = |a: usize, b: usize| CORNERS.iter().position(|&c| c == (a, b)).unwrap();
    let g = |r: usize, c: usize| {
        let (a, b) = (r % 2, c % 2);
        let k = index(a, b);
        match (r < 2, c < 2) {
            (true, true) => data.points[k],
            (true, false) => data.sv[k],
            (false, true) => data.su[k],
            (false, false) => data.twist[k],
        }
    };
    let matrix_form = |u: f64, v: f64| {
        let (hu, hv) = (h(u), h(v));
        let mut s = DVec3::ZERO;
        for (r, a) in hu.iter().enumerate() {
            for (c, b) in hv.iter().enumerate() {
                s += g(r, c) * (a * b);
            }
        }
        s
    };
    let gap = largest_gap(|u, v| surface.point_at(u, v).unwrap(), matrix_form, 12);
    assert!(gap < 1e-12, "Hermite patch vs H(u) G H(v)^T: {gap:e}");
    for (k, &(a, b)) in CORNERS.iter().enumerate() {
        let d = surface.evaluate(a as f64, b as f64).unwrap();
        for (got, want, what) in [
            (d.point, data.points[k], "S"),
            (d.su, data.su[k], "Su"),
            (d.sv, data.sv[k], "Sv"),
            (d.suv, data.twist[k], "Suv"),
        ] {
            assert!(
                got.distance(want) < 1e-11,
                "{what} at ({a}, {b}): {got} vs {want}"
            );
        }
    }
    let mut bad = data;
    bad.twist[2].y = f64::NAN;
    assert!(transfinite::hermite_patch(&bad).is_err());
}

/// The boundary curves [bottom, top, left, right] and cross derivatives [Sv at v = 0, Sv at
/// v = 1, Su at u = 0, Su at u = 1] of `s`.
fn coons_data(s: &Polynomial) -> ([SpaceCurve; 4], [SpaceCurve; 4]) {
    (
        [
            s.along_u(0.0, false),
            s.along_u(1.0, false),
            s.along_v(0.0, false),
            s.along_v(1.0, false),
        ],
        [
            s.along_u(0.0, true),
            s.along_u(1.0, true),
            s.along_v(0.0, true),
            s.along_v(1.0, true),
        ],
    )
}

#[test]
fn the_bicubic_coons_patch_reproduces_a_bicubic_surface_from_its_boundary_data() {
    for seed in 0..4 {
        let s = Polynomial::random(3, 3, seed);
        let (curves, cross) = coons_data(&s);
        let coons = transfinite::bicubic_coons(
            [&curves[0], &curves[1], &curves[2], &curves[3]],
            [&cross[0], &cross[1], &cross[2], &cross[3]],
        )
        .unwrap();
        let gap = largest_gap(
            |u, v| coons.point_at(u, v).unwrap(),
            |u, v| s.point(u, v),
            10,
        );
        assert!(gap < 1e-10, "seed {seed}: {gap:e}");
    }
}

#[test]
fn the_bicubic_coons_patch_interpolates_curves_and_cross_derivatives() {
    // Degree (5, 4) data: the patch cannot reproduce the surface, only its boundary data.
    let s = Polynomial::random(5, 4, 11);
    let (curves, cross) = coons_data(&s);
    let coons = transfinite::bicubic_coons(
        [&curves[0], &curves[1], &curves[2], &curves[3]],
        [&cross[0], &cross[1], &cross[2], &cross[3]],
    )
    .unwrap();
    let mut worst = 0.0f64;
    for k in 0..=20 {
        let t = k as f64 / 20.0;
        for (side, (u, v)) in [(0.0, t), (1.0, t), (t, 0.0), (t, 1.0)]
            .into_iter()
            .enumerate()
        {
            let d = coons.evaluate(u, v).unwrap();
            let curve = match side {
                0 => &curves[2],
                1 => &curves[3],
                2 => &curves[0],
                _ => &curves[1],
            };
            let derivative = match side {
                0 => (&cross[2], d.su),
                1 => (&cross[3], d.su),
                2 => (&cross[0], d.sv),
                _ => (&cross[1], d.sv),
            };
            worst = worst.max(d.point.distance(curve.point_at(t).unwrap()));
            worst = worst.max(derivative.1.distance(derivative.0.point_at(t).unwrap()));
        }
    }
    assert!(worst < 1e-10, "boundary data: {worst:e}");
    let inside = coons
        .point_at(0.5, 0.5)
        .unwrap()
        .distance(s.point(0.5, 0.5));
    assert!(
        inside > 1e-4,
        "a quintic should not be reproduced ({inside:e})"
    );

    // Incompatible data is refused with the corner named.
    let moved = cross[0]
        .map_points(|p| p + DVec3::new(0.0, 0.0, 0.3))
        .unwrap();
    let error = transfinite::bicubic_coons(
        [&curves[0], &curves[1], &curves[2], &curves[3]],
        [&moved, &cross[1], &cross[2], &cross[3]],
    )
    .unwrap_err()
    .to_string();
    assert!(error.contains("(u, v) = (0, 0)"), "{error}");
}

/// The u-curves of `s` at `vs` and its v-curves at `us`.
fn network(s: &Polynomial, us: &[f64], vs: &[f64]) -> (Vec<SpaceCurve>, Vec<SpaceCurve>) {
    (
        vs.iter().map(|&v| s.along_u(v, false)).collect(),
        us.iter().map(|&u| s.along_v(u, false)).collect(),
    )
}

#[test]
fn the_gordon_surface_reproduces_a_bicubic_surface_from_its_isoparametric_curves() {
    for seed in 0..3 {
        let s = Polynomial::random(3, 3, 20 + seed);
        let (u_curves, v_curves) = network(&s, &[0.0, 0.2, 0.5, 0.7, 1.0], &[0.0, 0.3, 0.55, 1.0]);
        let gordon = transfinite::gordon(&u_curves, &v_curves, 3).unwrap();
        let gap = largest_gap(
            |u, v| gordon.point_at(u, v).unwrap(),
            |u, v| s.point(u, v),
            10,
        );
        assert!(gap < 1e-9, "seed {seed}: {gap:e}");
    }
}

#[test]
fn the_gordon_surface_interpolates_every_curve_of_the_network() {
    let s = Polynomial::random(5, 5, 31);
    let (us, vs) = ([0.0, 0.45, 1.0], [0.0, 0.35, 0.6, 1.0]);
    let (u_curves, v_curves) = network(&s, &us, &vs);
    for degree in [1, 2, 3] {
        let gordon = transfinite::gordon(&u_curves, &v_curves, degree).unwrap();
        let mut worst = 0.0f64;
        for k in 0..=30 {
            let t = k as f64 / 30.0;
            for (curve, &v) in u_curves.iter().zip(&vs) {
                worst = worst.max(
                    gordon
                        .point_at(t, v)
                        .unwrap()
                        .distance(curve.point_at(t).unwrap()),
                );
            }
            for (curve, &u) in v_curves.iter().zip(&us) {
                worst = worst.max(
                    gordon
                        .point_at(u, t)
                        .unwrap()
                        .distance(curve.point_at(t).unwrap()),
                );
            }
        }
        assert!(worst < 1e-9, "degree {degree}: {worst:e}");
        let between = gordon
            .point_at(0.2, 0.2)
            .unwrap()
            .distance(s.point(0.2, 0.2));
        assert!(
            between > 1e-4,
            "a quintic should not be reproduced ({between:e})"
        );
    }
}

#[test]
fn a_two_by_two_gordon_surface_is_the_bilinear_coons_patch() {
    let s = Polynomial::random(4, 3, 41);
    let (u_curves, v_curves) = network(&s, &[0.0, 1.0], &[0.0, 1.0]);
    let gordon = transfinite::gordon(&u_curves, &v_curves, 3).unwrap();
    let coons = construct::coons(&u_curves[0], &u_curves[1], &v_curves[0], &v_curves[1]).unwrap();
    let gap = largest_gap(
        |u, v| gordon.point_at(u, v).unwrap(),
        |u, v| coons.point_at(u, v).unwrap(),
        10,
    );
    assert!(gap < 1e-11, "{gap:e}");
}

fn line(a: DVec3, b: DVec3) -> SpaceCurve {
    construct::line(a, b).unwrap()
}

#[test]
fn bad_networks_are_refused_with_the_reason() {
    let u_line = |y: f64| line(DVec3::new(0.0, y, 0.0), DVec3::new(1.0, y, 0.0));
    let v_line = |x: f64| line(DVec3::new(x, 0.0, 0.0), DVec3::new(x, 1.0, 0.0));
    let us = vec![u_line(0.0), u_line(0.5), u_line(1.0)];
    let vs = vec![v_line(0.0), v_line(0.4), v_line(1.0)];
    let flat = transfinite::gordon(&us, &vs, 3).unwrap();
    let p = flat.point_at(0.3, 0.8).unwrap();
    assert!(p.distance(DVec3::new(0.3, 0.8, 0.0)) < 1e-12, "{p}");
    let error =
        |u: &[SpaceCurve], v: &[SpaceCurve]| transfinite::gordon(u, v, 3).unwrap_err().to_string();

    // The same line, travelled at another speed: crossings at other parameters.
    let uneven = bezier_curve(
        2,
        vec![
            DVec3::new(0.0, 0.5, 0.0),
            DVec3::new(0.8, 0.5, 0.0),
            DVec3::new(1.0, 0.5, 0.0),
        ],
    );
    let e = error(&[us[0].clone(), uneven, us[2].clone()], &vs);
    assert!(e.contains("common u"), "{e}");

    let lifted = vs[1].map_points(|p| p + DVec3::Z * 0.1).unwrap();
    let e = error(&us, &[vs[0].clone(), lifted, vs[2].clone()]);
    assert!(e.contains("do not meet"), "{e}");

    let e = error(&us, &[vs[0].clone(), vs[2].clone(), vs[1].clone()]);
    assert!(e.contains("increasing u"), "{e}");

    let e = error(&us[..1], &vs);
    assert!(e.contains("needs 2"), "{e}");

    let rational = NurbsCurve::new(
        2,
        vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0],
        vec![
            DVec3::ZERO,
            DVec3::new(0.5, 0.0, 0.0),
            DVec3::new(1.0, 0.0, 0.0),
        ],
        Some(vec![1.0, 2.0, 1.0]),
    )
    .unwrap();
    let e = error(&[rational, us[1].clone(), us[2].clone()], &vs);
    assert!(e.contains("rational"), "{e}");

    let e = transfinite::gordon(&us, &vs, 0).unwrap_err().to_string();
    assert!(e.contains("degree"), "{e}");
}

#[test]
fn the_boolean_sum_of_a_surface_minus_itself_is_zero() {
    // The degree and knot alignment: a surface plus a differently refined copy of itself minus
    // twice itself vanishes.
    let s: NurbsSurface = construct::bspline_surface(
        [3, 2],
        [5, 4],
        (0..20)
            .map(|k| DVec3::new(k as f64, (k * k % 7) as f64, (k % 3) as f64))
            .collect(),
    )
    .unwrap();
    let refined = s
        .refine(knotwork::kernel::Direction::U, &[0.3, 0.3])
        .unwrap()
        .elevate_degree(knotwork::kernel::Direction::V, 1)
        .unwrap();
    let zero = transfinite::boolean_sum(&[s.clone(), refined], &[s.clone(), s], "test").unwrap();
    let worst = grid(8)
        .map(|(u, v)| zero.point_at(u, v).unwrap().length())
        .fold(0.0, f64::max);
    assert!(worst < 1e-12, "{worst:e}");
}

#[test]
fn isocurves_and_cross_derivative_curves_match_the_surface() {
    let rational = common::random_surface(3, 2, 5);
    let [(u0, u1), (v0, v1)] = rational.domain();
    for k in 0..=6 {
        let (u, v) = (
            u0 + (u1 - u0) * k as f64 / 6.0,
            v0 + (v1 - v0) * (6 - k) as f64 / 6.0,
        );
        let along_v = rational
            .isocurve(knotwork::kernel::Direction::U, u, 0)
            .unwrap();
        let along_u = rational
            .isocurve(knotwork::kernel::Direction::V, v, 0)
            .unwrap();
        for m in 0..=8 {
            let t = m as f64 / 8.0;
            let (vt, ut) = (v0 + (v1 - v0) * t, u0 + (u1 - u0) * t);
            let a = along_v
                .point_at(vt)
                .unwrap()
                .distance(rational.point_at(u, vt).unwrap());
            let b = along_u
                .point_at(ut)
                .unwrap()
                .distance(rational.point_at(ut, v).unwrap());
            assert!(
                a < 1e-10 && b < 1e-10,
                "isocurve at u = {u} / v = {v}: {a:e} {b:e}"
            );
        }
    }
    assert!(
        rational
            .isocurve(knotwork::kernel::Direction::U, u1 + 1.0, 0)
            .is_err()
    );
    assert!(
        rational
            .isocurve(knotwork::kernel::Direction::U, u0, 1)
            .is_err()
    );
    // Derivatives across, on a polynomial surface, against the Bernstein form.
    let s = Polynomial::random(4, 3, 3);
    let surface = NurbsSurface::bezier([4, 3], s.net.clone(), None).unwrap();
    let su = surface
        .isocurve(knotwork::kernel::Direction::U, 0.3, 1)
        .unwrap();
    let sv = surface
        .isocurve(knotwork::kernel::Direction::V, 0.6, 1)
        .unwrap();
    let want_su = s.along_v(0.3, true);
    let want_sv = s.along_u(0.6, true);
    for m in 0..=8 {
        let t = m as f64 / 8.0;
        assert!(
            su.point_at(t)
                .unwrap()
                .distance(want_su.point_at(t).unwrap())
                < 1e-11
        );
        assert!(
            sv.point_at(t)
                .unwrap()
                .distance(want_sv.point_at(t).unwrap())
                < 1e-11
        );
    }
}

fn run_construct(request: &serde_json::Value) -> std::process::Output {
    // One file per call: the tests run in parallel threads of one process.
    static CALLS: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let call = CALLS.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let path = crate::common::scratch_dir(&format!("construct-{call}")).join("request.json");
    std::fs::write(&path, request.to_string()).unwrap();
    std::process::Command::new(env!("CARGO_BIN_EXE_knotwork"))
        .arg("construct")
        .arg(&path)
        .output()
        .unwrap()
}

fn curve_value(c: &SpaceCurve) -> serde_json::Value {
    knotwork::scene::json::object_to_value(&knotwork::scene::json::NamedGeometry {
        name: None,
        geometry: knotwork::scene::json::Geometry::Curve(c.clone()),
    })
}

#[test]
fn knotwork_construct_builds_the_surfaces_from_json() {
    let s = Polynomial::random(3, 3, 51);
    let (u_curves, v_curves) = network(&s, &[0.0, 0.4, 1.0], &[0.0, 0.25, 0.6, 1.0]);
    let request = serde_json::json!({
        "construct": "gordon",
        "u_curves": u_curves.iter().map(curve_value).collect::<Vec<_>>(),
        "v_curves": v_curves.iter().map(curve_value).collect::<Vec<_>>(),
    });
    let out = run_construct(&request);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8(out.stdout).unwrap();
    let value: serde_json::Value = serde_json::from_str(&text).unwrap();
    let read = knotwork::scene::json::object_from_value("", value).unwrap();
    let knotwork::scene::json::Geometry::Surface(gordon) = read.geometry else {
        panic!("expected a surface: {text}");
    };
    for (curve, v) in u_curves.iter().zip([0.0, 0.25, 0.6, 1.0]) {
        for m in 0..=10 {
            let t = m as f64 / 10.0;
            let gap = gordon
                .point_at(t, v)
                .unwrap()
                .distance(curve.point_at(t).unwrap());
            assert!(gap < 1e-9, "u-curve at v = {v}: {gap:e}");
        }
    }

    let (curves, cross) = coons_data(&s);
    let sides = |c: &[SpaceCurve; 4]| {
        serde_json::json!({
            "bottom": curve_value(&c[0]), "top": curve_value(&c[1]),
            "left": curve_value(&c[2]), "right": curve_value(&c[3]),
        })
    };
    let mut request = sides(&curves);
    request["construct"] = "coons".into();
    request["cross"] = sides(&cross);
    let out = run_construct(&request);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let value: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let knotwork::scene::json::Geometry::Surface(coons) =
        knotwork::scene::json::object_from_value("", value)
            .unwrap()
            .geometry
    else {
        panic!("expected a surface");
    };
    let gap = largest_gap(
        |u, v| coons.point_at(u, v).unwrap(),
        |u, v| s.point(u, v),
        6,
    );
    assert!(gap < 1e-9, "bicubic Coons of a bicubic: {gap:e}");

    // Bad requests: the JSON path, or the construction's reason; exit code 1.
    let out =
        run_construct(&serde_json::json!({"construct": "gordon", "u_curves": [1], "v_curves": []}));
    assert!(!out.status.success());
    let e = String::from_utf8_lossy(&out.stderr);
    assert!(e.contains("u_curves[0]"), "{e}");
    let out = run_construct(&serde_json::json!({
        "construct": "hermite", "points": [[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]],
        "su": [[1, 0, 0], [1, 0, 0], [1, 0, 0], [1, 0, 0]],
    }));
    assert!(!out.status.success());
    let e = String::from_utf8_lossy(&out.stderr);
    assert!(e.contains("sv"), "{e}");
    let out = run_construct(&serde_json::json!({
        "construct": "hermite", "points": [[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]],
        "su": [[1, 0, 0], [1, 0, 0], [1, 0, 0], [1, 0, 0]],
        "sv": [[0, 1, 0], [0, 1, 0], [0, 1, 0], [0, 1, 0]],
    }));
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// Asserts that `knotwork construct` refuses the request with exit code 1 and a message on
/// stderr that contains `message`.
fn assert_refused(request: &serde_json::Value, message: &str) {
    let out = run_construct(request);
    assert_eq!(out.status.code(), Some(1), "{request}");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains(message),
        "{}: {stderr}",
        request["construct"]
    );
}

/// The distance from `q` to the curve, by dense sampling refined by golden-section search (an
/// independent measure: it does not use the curve's own parameters).
fn distance_to_curve(curve: &SpaceCurve, q: glam::DVec3) -> f64 {
    let (a, b) = curve.domain();
    let at = |t: f64| curve.point_at(t.clamp(a, b)).unwrap().distance(q);
    let n = 2000;
    let best = (0..=n)
        .map(|k| a + (b - a) * k as f64 / n as f64)
        .min_by(|x, y| at(*x).total_cmp(&at(*y)))
        .unwrap();
    let (mut lo, mut hi) = (best - (b - a) / n as f64, best + (b - a) / n as f64);
    for _ in 0..100 {
        let (m1, m2) = (lo + (hi - lo) * 0.382, lo + (hi - lo) * 0.618);
        if at(m1) < at(m2) {
            hi = m2;
        } else {
            lo = m1;
        }
    }
    at(0.5 * (lo + hi))
}

/// `knotwork construct` builds curves through points: an open interpolant (with end tangents),
/// a closed one and a Catmull-Rom spline, each printed as a `nurbs_curve` that passes through
/// its points; a bad request exits 1 and names the problem.
#[test]
fn knotwork_construct_builds_curves_through_points() {
    let points = [
        [0.0, 0.0, 0.0],
        [1.0, 2.0, 0.5],
        [4.0, 2.5, -1.0],
        [5.0, -1.0, 0.0],
        [7.5, 0.0, 2.0],
    ];
    let requests = [
        (
            serde_json::json!({"construct": "interpolate", "points": points, "degree": 3}),
            0..5,
        ),
        (
            serde_json::json!({"construct": "interpolate", "points": points, "degree": 3,
                "parametrization": "centripetal", "tangents": [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]}),
            0..5,
        ),
        (
            serde_json::json!({"construct": "interpolate", "points": points, "degree": 3, "closed": true}),
            0..5,
        ),
        (
            serde_json::json!({"construct": "catmull_rom", "points": points, "alpha": 0.5}),
            1..4,
        ),
    ];
    for (request, through) in requests {
        let out = run_construct(&request);
        assert!(
            out.status.success(),
            "{request}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        let text = String::from_utf8(out.stdout).unwrap();
        let value: serde_json::Value = serde_json::from_str(&text).unwrap();
        assert_eq!(value["type"], "nurbs_curve", "{text}");
        let read = knotwork::scene::json::object_from_value("", value).unwrap();
        let knotwork::scene::json::Geometry::Curve(curve) = read.geometry else {
            panic!("expected a curve: {text}");
        };
        for k in through {
            let gap = distance_to_curve(&curve, glam::DVec3::from(points[k]));
            assert!(gap < 1e-9, "{request}: point {k} is {gap:e} away");
        }
    }
    // A curve written as a file the editor would refuse: refused here, with what to do.
    let request = crate::common::scratch_dir("curve-refused").join("request.json");
    std::fs::write(
        &request,
        serde_json::json!({"construct": "interpolate", "points": points}).to_string(),
    )
    .unwrap();
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_knotwork"))
        .args(["construct", &request.to_string_lossy(), "-o", "/dev/null"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("leave out -o"));
    for (request, message) in [
        (
            serde_json::json!({"construct": "catmull_rom", "points": points[..3]}),
            "at least 4 points",
        ),
        (
            serde_json::json!({"construct": "interpolate", "points": [[0, 0, 0], [0, 0, 0]]}),
            "coincide",
        ),
        (
            serde_json::json!({"construct": "interpolate", "points": points, "closed": true, "tangents": [[1, 0, 0], [0, 1, 0]]}),
            "no end tangents",
        ),
    ] {
        assert_refused(&request, message);
    }
}

/// The object a `knotwork construct` request printed (of JSON type `kind`) and its stderr; the
/// test fails with the command's message if it did not succeed.
fn constructed(request: &serde_json::Value, kind: &str) -> (serde_json::Value, String) {
    let out = run_construct(request);
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(out.status.success(), "{}: {stderr}", request["construct"]);
    let value: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(value["type"], kind);
    (value, stderr)
}

/// The surface (trimmed or not) a `knotwork construct` request printed; the test fails with
/// the command's message if it did not succeed.
fn constructed_surface(request: &serde_json::Value) -> knotwork::scene::json::Geometry {
    let (value, _) = constructed(request, "nurbs_surface");
    knotwork::scene::json::object_from_value("", value)
        .unwrap()
        .geometry
}

fn untrimmed(geometry: knotwork::scene::json::Geometry) -> knotwork::kernel::NurbsSurface {
    match geometry {
        knotwork::scene::json::Geometry::Surface(s) => s,
        _ => panic!("expected an untrimmed surface"),
    }
}

/// The largest distance from 41 evenly spaced points of the curve to the surface (point
/// inversion from a grid of starts).
fn curve_to_surface(curve: &SpaceCurve, surface: &knotwork::kernel::NurbsSurface) -> f64 {
    (0..=40)
        .map(|i| curve.point_at(curve.parameter_at(i as f64 / 40.0)).unwrap())
        .map(|p| surface.closest_point(p).unwrap().distance)
        .fold(0.0, f64::max)
}

/// `knotwork construct` builds surfaces from a user's curves: loft, network, one- and two-rail
/// sweeps, revolve and planar faces; every input curve lies on the result, and requests that
/// cannot be built exit 1 with the reason.
#[test]
fn knotwork_construct_builds_surfaces_from_the_users_curves() {
    use glam::DVec3;
    use knotwork::kernel::construct::{arc, circle, interpolate};
    use std::f64::consts::PI;
    let values = |cs: &[SpaceCurve]| cs.iter().map(curve_value).collect::<Vec<_>>();

    // Loft: circles at different heights, one reversed and one given a seam elsewhere.
    let ring = |z: f64, r: f64| circle(DVec3::new(0.0, 0.0, z), DVec3::Z, DVec3::X, r).unwrap();
    let sections = vec![
        ring(0.0, 1.0),
        ring(1.0, 1.6).reverse(),
        ring(2.0, 0.8),
        ring(3.0, 1.2),
    ];
    for closed in [false, true] {
        let loft = untrimmed(constructed_surface(&serde_json::json!({
            "construct": "loft", "curves": values(&sections), "degree": 3, "closed": closed
        })));
        for c in &sections {
            let d = curve_to_surface(c, &loft);
            assert!(d < 1e-8, "loft (closed {closed}): a section is {d:e} away");
        }
    }

    // Network: iso-curves of a bicubic surface, shuffled, some reversed, one made rational
    // (weights ρ^i: the same curve under a Möbius reparametrisation), one raised in degree
    // with a knot added, one on another domain.
    let s = Polynomial::random(3, 3, 77);
    let (mut u_curves, mut v_curves) = network(&s, &[0.0, 0.3, 0.65, 1.0], &[0.0, 0.4, 1.0]);
    let mobius = |c: &SpaceCurve| {
        let points = (0..c.count()).map(|i| c.control_point(i)).collect();
        let weights = (0..c.count()).map(|i| 2f64.powi(i as i32)).collect();
        NurbsCurve::new(c.degree(), c.knots().to_vec(), points, Some(weights)).unwrap()
    };
    u_curves[1] = mobius(&u_curves[1]).reverse();
    u_curves.swap(0, 2);
    v_curves[2] = v_curves[2]
        .elevate_degree(1)
        .unwrap()
        .insert_knot(0.37, 1)
        .unwrap();
    v_curves[1] = v_curves[1].reparametrized(2.0, 5.0).unwrap().reverse();
    v_curves.swap(0, 3);
    let request = serde_json::json!({
        "construct": "network", "u_curves": values(&u_curves), "v_curves": values(&v_curves)
    });
    let out = run_construct(&request);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("largest deviation"), "{stderr}");
    let network = untrimmed(constructed_surface(&request));
    let size = 4.0; // the net spans about 3 × 2 × 1.6
    for c in u_curves.iter().chain(&v_curves) {
        let d = curve_to_surface(c, &network);
        assert!(d < 1e-5 * size, "network: a curve is {d:e} away");
    }

    // One rail: a circle along a bent rail; two rails: arcs between two lines.
    let rail = arc(DVec3::ZERO, DVec3::X, DVec3::Z, 5.0, 0.0, PI / 2.0).unwrap();
    let profiles = vec![circle(DVec3::new(5.0, 0.0, 0.0), DVec3::Z, DVec3::X, 0.5).unwrap()];
    for up in [None, Some([0.0, 1.0, 0.0])] {
        let mut request = serde_json::json!({
            "construct": "sweep1", "rail": curve_value(&rail), "profiles": values(&profiles)
        });
        if let Some(up) = up {
            request["up"] = serde_json::json!(up);
        }
        let sweep = untrimmed(constructed_surface(&request));
        let d = curve_to_surface(&profiles[0], &sweep);
        assert!(d < 1e-8, "sweep1: the profile is {d:e} away");
        // The tube keeps its radius about the rail's middle.
        let middle = DVec3::new(1.0, 0.0, 1.0) * 5.0 * std::f64::consts::FRAC_1_SQRT_2;
        let tube = sweep.closest_point(middle).unwrap().distance;
        assert!((tube - 0.5).abs() < 1e-3, "sweep1: radius {tube}");
    }
    let rails = [
        knotwork::kernel::construct::line(DVec3::ZERO, DVec3::new(0.0, 4.0, 0.0)).unwrap(),
        knotwork::kernel::construct::line(DVec3::new(2.0, 0.0, 0.0), DVec3::new(3.0, 4.0, 0.0))
            .unwrap(),
    ];
    let cap = |a: DVec3, b: DVec3| interpolate(&[a, (a + b) * 0.5 + DVec3::Z, b], 2).unwrap();
    let profiles = vec![
        cap(DVec3::new(3.0, 4.0, 0.0), DVec3::new(0.0, 4.0, 0.0)),
        cap(DVec3::ZERO, DVec3::new(2.0, 0.0, 0.0)),
    ];
    let sweep2 = untrimmed(constructed_surface(&serde_json::json!({
        "construct": "sweep2", "rails": values(&rails), "profiles": values(&profiles)
    })));
    for c in profiles.iter() {
        let d = curve_to_surface(c, &sweep2);
        assert!(d < 1e-8, "sweep2: a profile is {d:e} away");
    }
    for c in rails.iter() {
        let d = curve_to_surface(c, &sweep2);
        assert!(d < 1e-6, "sweep2: a rail is {d:e} away");
    }

    // Revolve about a tilted axis by 270°: every point keeps the profile's distance to the
    // axis and its height along it.
    let profile = interpolate(
        &[
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(2.0, 0.5, 1.0),
            DVec3::new(1.5, 0.0, 2.0),
        ],
        2,
    )
    .unwrap();
    let (origin, direction) = (DVec3::new(0.5, -0.5, 0.0), DVec3::new(0.2, 0.1, 1.0));
    let revolution = untrimmed(constructed_surface(&serde_json::json!({
        "construct": "revolve", "profile": curve_value(&profile),
        "axis": {"origin": origin.to_array(), "direction": direction.to_array()}, "angle": 270
    })));
    let axis = direction.normalize();
    let radius = |p: DVec3| (p - origin - axis * (p - origin).dot(axis)).length();
    let [(u0, u1), _] = revolution.domain();
    for j in 0..=10 {
        let v = j as f64 / 10.0;
        let p = profile.point_at(v).unwrap();
        for i in 0..=10 {
            let q = revolution
                .point_at(u0 + (u1 - u0) * i as f64 / 10.0, v)
                .unwrap();
            assert!((radius(q) - radius(p)).abs() < 1e-12, "revolve radius");
            assert!(((q - p).dot(axis)).abs() < 1e-12, "revolve height");
        }
    }
    // Turning right-handed: a quarter turn takes +x (radially) toward axis × x.
    let quarter = revolution.point_at(u0 + (u1 - u0) / 3.0, 0.0).unwrap();
    let start = profile.point_at(0.0).unwrap();
    let radial = start - origin - axis * (start - origin).dot(axis);
    let turned = axis.cross(radial);
    let expected = start - radial + turned;
    assert!(
        quarter.distance(expected) < 1e-12,
        "{quarter} vs {expected}"
    );

    // Planar: a square of four lines, one given backwards, tilted.
    let corners = [
        DVec3::new(0.0, 0.0, 0.0),
        DVec3::new(2.0, 0.0, 1.0),
        DVec3::new(2.0, 2.0, 1.0),
        DVec3::new(0.0, 2.0, 0.0),
    ];
    let mut edges: Vec<SpaceCurve> = (0..4)
        .map(|k| knotwork::kernel::construct::line(corners[k], corners[(k + 1) % 4]).unwrap())
        .collect();
    edges[2] = edges[2].reverse();
    let knotwork::scene::json::Geometry::TrimmedSurface(face) = constructed_surface(
        &serde_json::json!({"construct": "planar", "boundary": values(&edges)}),
    ) else {
        panic!("expected a trimmed surface");
    };
    assert_eq!(face.loops().len(), 1);
    let normal = (corners[1] - corners[0])
        .cross(corners[3] - corners[0])
        .normalize();
    for (u, v) in grid(6) {
        let p = face.surface().point_at(u, v).unwrap();
        assert!((p - corners[0]).dot(normal).abs() < 1e-12);
    }

    // Edge curves: the square's four sides given as a chain, one backwards; and three of them
    // with a closing diagonal.
    let edge = untrimmed(constructed_surface(
        &serde_json::json!({"construct": "edge", "curves": values(&edges)}),
    ));
    for c in &edges {
        let d = curve_to_surface(c, &edge);
        assert!(d < 1e-9, "edge surface: a side is {d:e} away");
    }
    let diagonal = knotwork::kernel::construct::line(corners[2], corners[0]).unwrap();
    let triangle = untrimmed(constructed_surface(&serde_json::json!({
        "construct": "edge", "curves": [curve_value(&edges[0]), curve_value(&edges[1]), curve_value(&diagonal)]
    })));
    for i in 0..=10 {
        let t = i as f64 / 10.0;
        let p = triangle.point_at(t, 0.0).unwrap();
        assert!(p.distance(edges[0].point_at(t).unwrap()) < 1e-12);
    }

    // Extrusions: along a vector, and a rational circle along a rational arc (exact: every
    // point is a circle point plus an arc point minus the arc's start).
    let straight = untrimmed(constructed_surface(&serde_json::json!({
        "construct": "extrude", "curve": curve_value(&profile), "direction": [0, 0, 2]
    })));
    let top = straight.point_at(0.5, 1.0).unwrap();
    assert!(top.distance(profile.point_at(0.5).unwrap() + DVec3::new(0.0, 0.0, 2.0)) < 1e-12);
    let round = circle(DVec3::ZERO, DVec3::Z, DVec3::X, 1.0).unwrap();
    let path = arc(DVec3::ZERO, DVec3::X, DVec3::Z, 3.0, 0.0, PI / 2.0).unwrap();
    let along = untrimmed(constructed_surface(&serde_json::json!({
        "construct": "extrude", "curve": curve_value(&round), "path": curve_value(&path)
    })));
    for (u, v) in grid(5) {
        let expected =
            round.point_at(u).unwrap() + path.point_at(v).unwrap() - path.point_at(0.0).unwrap();
        let got = along.point_at(u, v).unwrap();
        assert!(
            got.distance(expected) < 1e-12,
            "extrude along a path at ({u}, {v})"
        );
    }

    // Requests that cannot be built: exit 1 with the reason.
    let bent = {
        let mut e = edges.clone();
        e[1] = knotwork::kernel::construct::line(corners[1], corners[2] + DVec3::Z).unwrap();
        e[2] = knotwork::kernel::construct::line(corners[3], corners[2] + DVec3::Z).unwrap();
        e
    };
    let apart = vec![
        v_curves[0].map_points(|p| p + DVec3::Z).unwrap(),
        v_curves[1].clone(),
    ];
    for (request, message) in [
        (
            serde_json::json!({"construct": "loft", "curves": values(&sections[..1])}),
            "at least 2 sections",
        ),
        (
            serde_json::json!({"construct": "network", "u_curves": values(&u_curves),
                "v_curves": values(&apart)}),
            "do not cross",
        ),
        (
            serde_json::json!({"construct": "planar", "boundary": values(&bent)}),
            "not planar",
        ),
        (
            serde_json::json!({"construct": "revolve", "profile": curve_value(&profile),
                "axis": {"origin": [0, 0, 0], "direction": [0, 0, 1]}, "angle": 0}),
            "angle",
        ),
        (
            serde_json::json!({"construct": "loft", "curves": values(&sections), "degree": 7}),
            "must be 1 to 3",
        ),
        (
            serde_json::json!({"construct": "extrude", "curve": curve_value(&profile)}),
            "one of them",
        ),
    ] {
        assert_refused(&request, message);
    }
}

/// The curve a `knotwork construct` request printed, and its report line on stderr.
fn constructed_curve(request: &serde_json::Value) -> (SpaceCurve, String) {
    let (value, stderr) = constructed(request, "nurbs_curve");
    let knotwork::scene::json::Geometry::Curve(c) =
        knotwork::scene::json::object_from_value("", value)
            .unwrap()
            .geometry
    else {
        panic!("expected a curve");
    };
    (c, stderr)
}

/// `knotwork construct` edits curves: rebuild and fit (with the largest deviation reported and
/// checked against the circle they approximate), offset, projection and extension, each
/// checked against its closed form; bad requests exit 1.
#[test]
fn knotwork_construct_edits_curves() {
    use glam::DVec3;
    let centre = DVec3::new(1.0, -1.0, 0.5);
    let circle = knotwork::kernel::construct::circle(centre, DVec3::Z, DVec3::X, 2.0).unwrap();
    let radius_error = |c: &SpaceCurve, r: f64| {
        (0..=300)
            .map(|i| c.point_at(c.parameter_at(i as f64 / 300.0)).unwrap())
            .map(|p| (p.distance(centre) - r).abs())
            .fold(0.0, f64::max)
    };
    let (rebuilt, report) = constructed_curve(
        &serde_json::json!({"construct": "rebuild", "curve": curve_value(&circle), "points": 10, "degree": 3}),
    );
    assert_eq!((rebuilt.count(), rebuilt.degree()), (10, 3));
    assert!(rebuilt.is_polynomial());
    assert!(report.contains("largest deviation"), "{report}");
    assert!(radius_error(&rebuilt, 2.0) < 1e-2);
    for tolerance in [1e-3, 1e-6] {
        let (fitted, _) = constructed_curve(
            &serde_json::json!({"construct": "fit", "curve": curve_value(&circle), "tolerance": tolerance}),
        );
        let e = radius_error(&fitted, 2.0);
        assert!(e <= tolerance * 1.01, "fit within {tolerance}: {e:e}");
    }
    let (offset, _) = constructed_curve(
        &serde_json::json!({"construct": "offset", "curve": curve_value(&circle), "distance": 0.75}),
    );
    assert!(radius_error(&offset, 2.75) < 1e-5);
    let (projected, _) = constructed_curve(&serde_json::json!({
        "construct": "project", "curve": curve_value(&circle),
        "plane": {"origin": [0, 0, 3], "normal": [0, 0, 1]}
    }));
    for i in 0..=20 {
        let p = projected
            .point_at(projected.parameter_at(i as f64 / 20.0))
            .unwrap();
        assert!((p.z - 3.0).abs() < 1e-12);
    }
    let arc = knotwork::kernel::construct::arc(centre, DVec3::X, DVec3::Y, 2.0, 0.0, 1.0).unwrap();
    let (longer, _) = constructed_curve(&serde_json::json!({
        "construct": "extend", "curve": curve_value(&arc), "length": 1.5, "end": "end"
    }));
    let tip = longer.point_at(longer.domain().1).unwrap();
    let end = centre + DVec3::new(1f64.cos(), 1f64.sin(), 0.0) * 2.0;
    assert!((tip.distance(end) - 1.5).abs() < 1e-12);
    assert!(
        (tip - end).dot(end - centre).abs() < 1e-12,
        "the extension leaves the tangent"
    );
    for (request, message) in [
        (
            serde_json::json!({"construct": "rebuild", "curve": curve_value(&circle), "points": 1}),
            "2 to",
        ),
        (
            serde_json::json!({"construct": "fit", "curve": curve_value(&circle), "tolerance": -1}),
            "tolerance",
        ),
        (
            serde_json::json!({"construct": "offset", "curve": curve_value(&knotwork::kernel::construct::line(DVec3::ZERO, DVec3::X).unwrap()), "distance": 1}),
            "give the normal",
        ),
        (
            serde_json::json!({"construct": "extend", "curve": curve_value(&arc), "length": 0}),
            "positive",
        ),
    ] {
        assert_refused(&request, message);
    }
}

/// `knotwork construct` makes exact curves: circles and ellipses in any plane, arcs through
/// three points, polylines (open and closed) and Hermite splines, each checked against its
/// closed form.
#[test]
fn knotwork_construct_makes_exact_curves() {
    use glam::DVec3;
    let sample = |c: &SpaceCurve, n: usize| -> Vec<DVec3> {
        (0..=n)
            .map(|i| c.point_at(c.parameter_at(i as f64 / n as f64)).unwrap())
            .collect()
    };
    let centre = DVec3::new(1.0, 2.0, -1.0);
    let normal = DVec3::new(1.0, 1.0, 2.0).normalize();
    let (circle, _) = constructed_curve(&serde_json::json!({
        "construct": "circle", "center": centre.to_array(), "normal": normal.to_array(), "radius": 1.5
    }));
    for p in sample(&circle, 100) {
        assert!((p.distance(centre) - 1.5).abs() < 1e-12);
        assert!((p - centre).dot(normal).abs() < 1e-12);
    }
    let (ellipse, _) = constructed_curve(&serde_json::json!({
        "construct": "ellipse", "center": centre.to_array(), "normal": [0, 0, 1], "radii": [3.0, 1.0]
    }));
    for p in sample(&ellipse, 100) {
        let d = p - centre;
        assert!(
            ((d.x / 3.0).powi(2) + d.y.powi(2) - 1.0).abs() < 1e-12,
            "{p}"
        );
        assert!(d.z.abs() < 1e-12);
    }
    let (a, b, c) = (
        DVec3::new(2.0, 0.0, 1.0),
        DVec3::new(0.0, 1.0, 1.5),
        DVec3::new(-1.0, -1.0, 0.0),
    );
    let (arc, _) = constructed_curve(
        &serde_json::json!({"construct": "arc", "points": [a.to_array(), b.to_array(), c.to_array()]}),
    );
    assert!(arc.point_at(arc.domain().0).unwrap().distance(a) < 1e-12);
    assert!(arc.point_at(arc.domain().1).unwrap().distance(c) < 1e-12);
    assert!(
        distance_to_curve(&arc, b) < 1e-9,
        "the arc misses its middle point"
    );
    // The circumradius R = |AB| |BC| |CA| / (4 · area).
    let area = (b - a).cross(c - a).length() / 2.0;
    let radius = a.distance(b) * b.distance(c) * c.distance(a) / (4.0 * area);
    let points = sample(&arc, 50);
    for w in points.windows(3) {
        // Three neighbouring points of the arc share its circumradius.
        let (p, q, r) = (w[0], w[1], w[2]);
        let area = (q - p).cross(r - p).length() / 2.0;
        let rr = p.distance(q) * q.distance(r) * r.distance(p) / (4.0 * area);
        assert!((rr - radius).abs() < 1e-6 * radius, "{rr} vs {radius}");
    }
    let corners = [[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [2.0, 1.0, 0.0]];
    let (square, _) = constructed_curve(
        &serde_json::json!({"construct": "polyline", "points": corners, "closed": true}),
    );
    assert_eq!(square.degree(), 1);
    assert!(
        square
            .point_at(0.0)
            .unwrap()
            .distance(square.point_at(1.0).unwrap())
            < 1e-15
    );
    for p in corners {
        assert!(distance_to_curve(&square, DVec3::from(p)) < 1e-12);
    }
    let (hermite, _) = constructed_curve(&serde_json::json!({
        "construct": "hermite_spline", "points": [[0, 0, 0], [1, 1, 0], [3, 0, 0]],
        "tangents": [[1, 0, 0], [1, 0, 0], [0, -1, 0]], "parameters": [0, 1, 2]
    }));
    let d = hermite.derivatives(1.0, 1).unwrap();
    assert!(d[0].distance(DVec3::new(1.0, 1.0, 0.0)) < 1e-12);
    assert!(d[1].distance(DVec3::X) < 1e-12);
    let end = hermite.derivatives(2.0, 1).unwrap();
    assert!(end[1].distance(-DVec3::Y) < 1e-12);
    assert_refused(
        &serde_json::json!({"construct": "arc", "points": [[0, 0, 0], [1, 1, 1], [2, 2, 2]]}),
        "one line",
    );
    assert_refused(
        &serde_json::json!({"construct": "ellipse", "center": [0, 0, 0], "radii": [1, 0]}),
        "radius",
    );
}
