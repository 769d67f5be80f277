//! knotwork's modelling constructions against OpenCASCADE: the points OpenCASCADE computed on
//! the same inputs (tests/reference/occ/modelling.json, made by make_fixtures.py beside it with
//! the cadquery-ocp bindings) must lie on knotwork's result, and measures must agree. The suite
//! reads the committed file; it does not need OpenCASCADE.

use glam::DVec3;
use knotwork::kernel::{NurbsSurface, SpaceCurve, construct, fit, planar};
use serde_json::Value;

fn fixtures() -> Value {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/reference/occ/modelling.json"
    );
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

fn vector(v: &Value) -> DVec3 {
    let c: Vec<f64> = v
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect();
    DVec3::new(c[0], c[1], c[2])
}

fn points(v: &Value) -> Vec<DVec3> {
    v.as_array().unwrap().iter().map(vector).collect()
}

fn numbers(v: &Value) -> Vec<f64> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect()
}

/// The curve of a fixture record (degree, full knot vector, poles, optional weights).
fn curve(record: &Value) -> SpaceCurve {
    let weights = record.get("weights").map(numbers);
    SpaceCurve::new(
        record["degree"].as_u64().unwrap() as usize,
        numbers(&record["knots"]),
        points(&record["points"]),
        weights,
    )
    .unwrap()
}

/// The distance from `p` to the curve (point inversion).
fn to_curve(c: &SpaceCurve, p: DVec3) -> f64 {
    let t = c.closest_parameter(p).unwrap();
    c.point_at(t).unwrap().distance(p)
}

fn to_surface(s: &NurbsSurface, p: DVec3) -> f64 {
    s.closest_point(p).unwrap().distance
}

#[test]
fn a_revolution_contains_opencascades_surface_of_revolution() {
    let case = &fixtures()["revolve"];
    let profile = curve(&case["profile"]);
    let s = construct::revolve(
        &profile,
        vector(&case["origin"]),
        vector(&case["direction"]),
        case["angle"].as_f64().unwrap().to_radians(),
    )
    .unwrap();
    let worst = points(&case["points"])
        .into_iter()
        .map(|p| to_surface(&s, p))
        .fold(0.0, f64::max);
    assert!(worst < 1e-9, "{worst:e}");
}

#[test]
fn an_arc_through_three_points_is_opencascades() {
    let case = &fixtures()["arc"];
    let [a, b, c] = <[DVec3; 3]>::try_from(points(&case["through"])).unwrap();
    let arc = construct::arc_through(a, b, c).unwrap();
    let occ = points(&case["points"]);
    // The same ends, and every point of OpenCASCADE's arc on knotwork's.
    assert!(arc.point_at(0.0).unwrap().distance(occ[0]) < 1e-12);
    assert!(arc.point_at(1.0).unwrap().distance(occ[occ.len() - 1]) < 1e-12);
    let worst = occ.iter().map(|&p| to_curve(&arc, p)).fold(0.0, f64::max);
    assert!(worst < 1e-12, "{worst:e}");
}

#[test]
fn an_ellipse_is_opencascades() {
    let case = &fixtures()["ellipse"];
    let radii = numbers(&case["radii"]);
    let ellipse = construct::ellipse(
        vector(&case["center"]),
        vector(&case["normal"]),
        vector(&case["x_axis"]),
        [radii[0], radii[1]],
    )
    .unwrap();
    let occ = points(&case["points"]);
    // Both start on the major axis.
    assert!(ellipse.point_at(0.0).unwrap().distance(occ[0]) < 1e-12);
    let worst = occ
        .iter()
        .map(|&p| to_curve(&ellipse, p))
        .fold(0.0, f64::max);
    assert!(worst < 1e-12, "{worst:e}");
}

#[test]
fn a_planar_offset_is_opencascades_offset_curve() {
    let case = &fixtures()["offset"];
    let c = curve(&case["curve"]);
    let tolerance = 1e-7;
    let offset = fit::offset_planar(
        &c,
        case["distance"].as_f64().unwrap(),
        Some(vector(&case["normal"])),
        tolerance,
    )
    .unwrap();
    let worst = points(&case["points"])
        .into_iter()
        .map(|p| to_curve(&offset.curve, p))
        .fold(0.0, f64::max);
    assert!(worst < 2.0 * tolerance, "{worst:e}");
}

#[test]
fn a_planar_face_has_opencascades_area() {
    let case = &fixtures()["planar"];
    let edges: Vec<SpaceCurve> = case["edges"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| {
            if let Some(line) = e.get("line") {
                let p = points(line);
                construct::line(p[0], p[1]).unwrap()
            } else {
                let p = points(&e["arc"]);
                construct::arc_through(p[0], p[1], p[2]).unwrap()
            }
        })
        .collect();
    let face = planar::planar_face(&edges).unwrap();
    let s = face.surface();
    let corner = s.point_at(0.0, 0.0).unwrap();
    let side_u = s.point_at(1.0, 0.0).unwrap() - corner;
    let side_v = s.point_at(0.0, 1.0).unwrap() - corner;
    let area = face.parameter_area(1e-7) * side_u.cross(side_v).length();
    let occ = case["area"].as_f64().unwrap();
    assert!((area - occ).abs() < 1e-6 * occ, "{area} vs {occ}");
}
