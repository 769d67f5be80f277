//! Independent checks of the f64 Bézier reference evaluator: closed forms, exact rational
//! geometry, finite differences, and the teapot data.

use glam::DVec3;
use knotwork_kernel::{BezierPatch, BezierPatchSet, GeometryError, samples};

fn grid(n: usize) -> impl Iterator<Item = (f64, f64)> {
    (0..=n).flat_map(move |i| (0..=n).map(move |j| (i as f64 / n as f64, j as f64 / n as f64)))
}

/// A single patch over its own points, row-major with i along u.
fn single_patch(
    p: usize,
    q: usize,
    points: Vec<DVec3>,
    weights: Option<Vec<f64>>,
) -> BezierPatchSet {
    let indices = (0..points.len() as u32).collect();
    BezierPatchSet::new(points, weights, vec![BezierPatch::new(p, q, indices)])
        .expect("test patch is valid")
}

/// A small deterministic pseudo-random sequence (no dependency, reproducible).
struct Lcg(u64);
impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
    fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.next()
    }
}

fn random_patch(rng: &mut Lcg, p: usize, q: usize) -> BezierPatchSet {
    let n = (p + 1) * (q + 1);
    let points = (0..n)
        .map(|_| {
            DVec3::new(
                rng.range(-2.0, 2.0),
                rng.range(-2.0, 2.0),
                rng.range(-2.0, 2.0),
            )
        })
        .collect();
    let weights = (0..n).map(|_| rng.range(0.2, 5.0)).collect();
    single_patch(p, q, points, Some(weights))
}

fn binomial(n: usize, k: usize) -> f64 {
    if k > n {
        return 0.0;
    }
    (0..k).fold(1.0, |acc, i| acc * (n - i) as f64 / (i + 1) as f64)
}

#[test]
fn corners_interpolate_their_control_points() {
    let mut rng = Lcg(7);
    for (p, q) in [(1, 1), (2, 3), (3, 3), (5, 2), (7, 7)] {
        let set = random_patch(&mut rng, p, q);
        let corner = |i: usize, j: usize| set.points()[i * (q + 1) + j];
        for (u, v, expected) in [
            (0.0, 0.0, corner(0, 0)),
            (1.0, 0.0, corner(p, 0)),
            (0.0, 1.0, corner(0, q)),
            (1.0, 1.0, corner(p, q)),
        ] {
            let d = set.evaluate(0, u, v).unwrap();
            assert!(
                (d.point - expected).length() < 1e-13,
                "({p},{q}) at ({u},{v})"
            );
        }
    }
}

#[test]
fn constant_net_reproduces_the_constant_partition_of_unity() {
    // Σ B_i(u) B_j(v) = 1: a net of equal points (any weights) evaluates to that point, and every
    // derivative vanishes.
    let c = DVec3::new(1.25, -0.5, 3.0);
    let mut rng = Lcg(11);
    for (p, q) in [(1, 2), (3, 3), (6, 4)] {
        let n = (p + 1) * (q + 1);
        let weights = (0..n).map(|_| rng.range(0.2, 5.0)).collect();
        let set = single_patch(p, q, vec![c; n], Some(weights));
        for (u, v) in grid(9) {
            let d = set.evaluate(0, u, v).unwrap();
            assert!((d.point - c).length() < 1e-13);
            for derivative in [d.su, d.sv, d.suu, d.suv, d.svv] {
                assert!(derivative.length() < 1e-12, "{derivative}");
            }
        }
    }
}

/// f(u, v) = Σ a_kl u^k v^l, bicubic.
const COEFFICIENTS: [[f64; 4]; 4] = [
    [0.5, -1.0, 0.25, 2.0],
    [1.5, 0.75, -2.0, 0.5],
    [-0.5, 1.0, 0.3, -1.25],
    [2.0, -0.4, 1.1, 0.6],
];

fn poly(u: f64, v: f64, du: i32, dv: i32) -> f64 {
    let term = |t: f64, k: i32, d: i32| -> f64 {
        if k < d {
            return 0.0;
        }
        let falling = (0..d).fold(1.0, |acc, m| acc * (k - m) as f64);
        falling * t.powi(k - d)
    };
    let mut sum = 0.0;
    for (k, row) in COEFFICIENTS.iter().enumerate() {
        for (l, a) in row.iter().enumerate() {
            sum += a * term(u, k as i32, du) * term(v, l as i32, dv);
        }
    }
    sum
}

#[test]
fn bicubic_graph_is_reproduced_exactly() {
    // The graph (u, v, f(u, v)) of a bicubic polynomial is a bicubic Bézier patch whose net follows
    // from the power-to-Bernstein conversion u^k = Σ_{i≥k} C(i,k)/C(n,k) B_{i,n}(u): z_ij =
    // Σ a_kl C(i,k)/C(3,k) C(j,l)/C(3,l), and x_ij = i/3, y_ij = j/3 (linear precision).
    let mut points = Vec::new();
    for i in 0..4 {
        for j in 0..4 {
            let mut z = 0.0;
            for (k, row) in COEFFICIENTS.iter().enumerate() {
                for (l, a) in row.iter().enumerate() {
                    z += a * binomial(i, k) / binomial(3, k) * binomial(j, l) / binomial(3, l);
                }
            }
            points.push(DVec3::new(i as f64 / 3.0, j as f64 / 3.0, z));
        }
    }
    let set = single_patch(3, 3, points, None);
    for (u, v) in grid(16) {
        let d = set.evaluate(0, u, v).unwrap();
        let close = |a: DVec3, b: DVec3| (a - b).length() < 1e-12;
        assert!(
            close(d.point, DVec3::new(u, v, poly(u, v, 0, 0))),
            "({u},{v})"
        );
        assert!(close(d.su, DVec3::new(1.0, 0.0, poly(u, v, 1, 0))));
        assert!(close(d.sv, DVec3::new(0.0, 1.0, poly(u, v, 0, 1))));
        assert!(close(d.suu, DVec3::new(0.0, 0.0, poly(u, v, 2, 0))));
        assert!(close(d.suv, DVec3::new(0.0, 0.0, poly(u, v, 1, 1))));
        assert!(close(d.svv, DVec3::new(0.0, 0.0, poly(u, v, 0, 2))));
        // Normal of a graph: (−f_u, −f_v, 1) / |…|.
        let n = set.normal(0, u, v).unwrap();
        let expected = DVec3::new(-poly(u, v, 1, 0), -poly(u, v, 0, 1), 1.0).normalize();
        assert!(close(n, expected));
    }
}

#[test]
fn rational_quarter_cylinder_is_exact() {
    // Quarter circle of radius r as a rational quadratic (weights 1, √2/2, 1), extruded along z
    // (degree 1 in v): every point lies at distance r from the z axis, and the normal is radial.
    let r = 2.5;
    let h = 4.0;
    let w = std::f64::consts::FRAC_1_SQRT_2;
    let arc = [
        DVec3::new(r, 0.0, 0.0),
        DVec3::new(r, r, 0.0),
        DVec3::new(0.0, r, 0.0),
    ];
    let mut points = Vec::new();
    let mut weights = Vec::new();
    for (i, p) in arc.iter().enumerate() {
        for z in [0.0, h] {
            points.push(*p + DVec3::new(0.0, 0.0, z));
            weights.push(if i == 1 { w } else { 1.0 });
        }
    }
    let set = single_patch(2, 1, points, Some(weights));
    for (u, v) in grid(20) {
        let d = set.evaluate(0, u, v).unwrap();
        let radial = DVec3::new(d.point.x, d.point.y, 0.0);
        assert!((radial.length() - r).abs() < 1e-12, "({u},{v})");
        assert!((d.point.z - v * h).abs() < 1e-12);
        // Su × Sv: Su is tangent (counter-clockwise), Sv = +z, so the normal points outward.
        let n = set.normal(0, u, v).unwrap();
        assert!((n - radial / r).length() < 1e-12, "({u},{v}) {n}");
        // The circle's curvature: |Su × Suu| / |Su|³ = 1/r.
        let kappa = d.su.cross(d.suu).length() / d.su.length().powi(3);
        assert!((kappa - 1.0 / r).abs() < 1e-12);
    }
}

#[test]
fn derivatives_match_finite_differences() {
    let mut rng = Lcg(3);
    let h = 1e-5;
    for (p, q) in [(1, 1), (2, 3), (3, 3), (4, 5), (7, 2)] {
        let set = random_patch(&mut rng, p, q);
        for _ in 0..20 {
            let (u, v) = (rng.range(0.05, 0.95), rng.range(0.05, 0.95));
            let at = |u: f64, v: f64| set.evaluate(0, u, v).unwrap();
            let d = at(u, v);
            let scale = 1.0 + d.su.length() + d.sv.length();
            let central = |plus: DVec3, minus: DVec3| (plus - minus) / (2.0 * h);
            let (up, um, vp, vm) = (at(u + h, v), at(u - h, v), at(u, v + h), at(u, v - h));
            for (name, exact, fd, tol) in [
                ("su", d.su, central(up.point, um.point), 1e-6),
                ("sv", d.sv, central(vp.point, vm.point), 1e-6),
                ("suu", d.suu, central(up.su, um.su), 1e-5),
                ("suv", d.suv, central(vp.su, vm.su), 1e-5),
                ("svv", d.svv, central(vp.sv, vm.sv), 1e-5),
            ] {
                let error = (exact - fd).length();
                assert!(error < tol * scale, "({p},{q}) {name}: {exact} vs {fd}");
            }
        }
    }
}

#[derive(serde::Deserialize)]
struct TeapotTables {
    patches: Vec<Vec<[f64; 3]>>,
}

#[test]
fn teapot_matches_the_explicit_patch_table() {
    // The JSON holds each patch twice: as indices into the vertex table (what the crate loads) and
    // as explicit coordinates with S(u,v) = Σ_r Σ_c B_r(u) B_c(v) P[r*4+c]. The crate transposes
    // each net, so its S(u, v) must equal the table's S(v, u).
    let tables: TeapotTables = serde_json::from_str(samples::TEAPOT_JSON).unwrap();
    let teapot = samples::utah_teapot().unwrap();
    assert_eq!(teapot.patches().len(), 32);
    assert_eq!(teapot.points().len(), 290);
    assert_eq!(tables.patches.len(), 32);
    for (k, net) in tables.patches.iter().enumerate() {
        let source = single_patch(3, 3, net.iter().map(|&p| DVec3::from(p)).collect(), None);
        for (u, v) in grid(6) {
            let ours = teapot.evaluate(k, u, v).unwrap().point;
            let theirs = source.evaluate(0, v, u).unwrap().point;
            assert!((ours - theirs).length() < 1e-12, "patch {k} ({u},{v})");
        }
    }
}

#[test]
fn teapot_normals_point_outward_and_are_never_nan() {
    let teapot = samples::utah_teapot().unwrap();
    for k in 0..32 {
        for (u, v) in grid(64) {
            let n = teapot.normal(k, u, v).unwrap();
            assert!(
                n.is_finite() && (n.length() - 1.0).abs() < 1e-12,
                "patch {k} ({u},{v})"
            );
        }
    }
    // Body (4..=11): the outward normal leans away from the z axis at every patch centre.
    for k in 4..=11 {
        let d = teapot.evaluate(k, 0.5, 0.5).unwrap();
        let n = teapot.normal(k, 0.5, 0.5).unwrap();
        assert!(
            n.dot(DVec3::new(d.point.x, d.point.y, 0.0)) > 0.0,
            "body patch {k}"
        );
    }
    // The ball-shaped knob (20..=23) also faces away from the axis around its middle.
    for k in 20..=23 {
        for v in [0.25, 0.5, 0.75] {
            let d = teapot.evaluate(k, 0.5, v).unwrap();
            let n = teapot.normal(k, 0.5, v).unwrap();
            assert!(
                n.dot(DVec3::new(d.point.x, d.point.y, 0.0)) > 0.0,
                "knob patch {k} v={v}"
            );
        }
    }
    // The bottom (28..=31) faces down; the lid's dome (24..=27) faces up.
    for k in 28..=31 {
        assert!(
            teapot.normal(k, 0.5, 0.5).unwrap().z < 0.0,
            "bottom patch {k}"
        );
    }
    for k in 24..=27 {
        assert!(teapot.normal(k, 0.5, 0.5).unwrap().z > 0.0, "lid patch {k}");
    }
}

#[test]
fn teapot_poles_have_the_axis_as_normal() {
    // The lid knob (patches 20..=23) and the bottom (28..=31) are surfaces of revolution whose
    // v = 0 edge collapses onto the z axis; there the limit normal is ±z.
    let teapot = samples::utah_teapot().unwrap();
    for (patches, pole, normal) in [
        (20..=23, DVec3::new(0.0, 0.0, 3.15), DVec3::Z),
        (28..=31, DVec3::ZERO, -DVec3::Z),
    ] {
        for k in patches {
            for step in 0..=8 {
                let u = step as f64 / 8.0;
                let d = teapot.evaluate(k, u, 0.0).unwrap();
                assert!((d.point - pole).length() < 1e-12, "patch {k}");
                assert_eq!(
                    d.su,
                    DVec3::ZERO,
                    "patch {k}: the collapsed edge has Su = 0 exactly"
                );
                let n = teapot.normal(k, u, 0.0).unwrap();
                assert!((n - normal).length() < 1e-9, "patch {k} at u={u}: {n}");
            }
        }
    }
}

#[test]
fn invalid_input_is_rejected_with_the_offending_index() {
    let unit = |n: usize| vec![DVec3::ZERO; n];
    let patch = |p, q, n: u32| vec![BezierPatch::new(p, q, (0..n).collect())];
    assert!(matches!(
        BezierPatchSet::new(unit(4), None, patch(0, 1, 4)),
        Err(GeometryError::Degree { at, degree: 0, .. }) if at == "patches[0].degree[0]"
    ));
    assert!(matches!(
        BezierPatchSet::new(unit(400), None, patch(16, 1, 34)),
        Err(GeometryError::Degree { degree: 16, .. })
    ));
    assert!(matches!(
        BezierPatchSet::new(unit(4), None, patch(1, 1, 3)),
        Err(GeometryError::PointCount {
            at,
            expected: 4,
            found: 3,
        }) if at == "patches[0].indices"
    ));
    assert!(matches!(
        BezierPatchSet::new(unit(3), None, patch(1, 1, 4)),
        Err(GeometryError::IndexOutOfRange { at, index: 3, .. }) if at == "patches[0].indices[3]"
    ));
    let mut points = unit(4);
    points[2].y = f64::NAN;
    assert!(matches!(
        BezierPatchSet::new(points, None, patch(1, 1, 4)),
        Err(GeometryError::NonFinitePoint { at, coordinate: 1 }) if at == "points[2]"
    ));
    for bad in [0.0, -1.0, f64::INFINITY, f64::NAN] {
        assert!(matches!(
            BezierPatchSet::new(unit(4), Some(vec![1.0, 1.0, 1.0, bad]), patch(1, 1, 4)),
            Err(GeometryError::BadWeight { at, .. }) if at == "points[3]"
        ));
    }
    assert!(matches!(
        BezierPatchSet::new(unit(4), Some(vec![1.0; 3]), patch(1, 1, 4)),
        Err(GeometryError::WeightCount {
            points: 4,
            weights: 3
        })
    ));

    let mut set = BezierPatchSet::new(unit(4), None, patch(1, 1, 4)).unwrap();
    assert!(matches!(
        set.evaluate(1, 0.5, 0.5),
        Err(GeometryError::NoSuchPatch { .. })
    ));
    for (u, v) in [(-0.1, 0.5), (0.5, 1.5), (f64::NAN, 0.5)] {
        assert!(matches!(
            set.evaluate(0, u, v),
            Err(GeometryError::OutsideDomain { .. })
        ));
    }
    let before = set.clone();
    assert!(set.set_point(9, DVec3::ONE).is_err());
    assert!(
        set.set_point(1, DVec3::new(0.0, f64::INFINITY, 0.0))
            .is_err()
    );
    assert_eq!(set, before, "a rejected edit leaves the set unchanged");
    set.set_point(1, DVec3::ONE).unwrap();
    assert_eq!(set.points()[1], DVec3::ONE);
}
