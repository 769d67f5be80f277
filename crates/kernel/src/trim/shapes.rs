//! Ready-made trim loops the editor's tools write: rectangles, circles and ellipses, polygons,
//! interpolating cubic loops, and the edits of a loop's control points.

use glam::DVec2;

use super::{TrimLoop, TrimProblem, refuse};
use crate::{GeometryError, TrimCurve};

fn construction(message: String) -> GeometryError {
    GeometryError::Construction {
        what: "trim loop",
        message,
    }
}

/// Curve `c` of loop `l` (loop number `loop_index`, for the message).
fn curve_of(l: &TrimLoop, loop_index: usize, c: usize) -> Result<&TrimCurve, GeometryError> {
    l.get(c)
        .ok_or_else(|| construction(format!("there is no curve {c} in loop {loop_index}")))
}

/// A straight trim curve from a to b (degree 1).
pub fn line(a: DVec2, b: DVec2) -> Result<TrimCurve, GeometryError> {
    TrimCurve::new(1, vec![0.0, 0.0, 1.0, 1.0], vec![a, b], None)
}

/// The axis-aligned rectangle with corners `lo` and `hi`, counter-clockwise, as four lines.
pub fn rectangle(lo: DVec2, hi: DVec2) -> Result<TrimLoop, GeometryError> {
    let corners = [lo, DVec2::new(hi.x, lo.y), hi, DVec2::new(lo.x, hi.y)];
    (0..4)
        .map(|k| line(corners[k], corners[(k + 1) % 4]))
        .collect()
}

/// The closed polygon through `points` (at least 3), one straight curve per edge.
pub fn polygon(points: &[DVec2]) -> Result<TrimLoop, GeometryError> {
    if points.len() < 3 {
        return Err(construction(format!(
            "a polygon needs at least 3 points, got {}",
            points.len()
        )));
    }
    let n = points.len();
    (0..n)
        .map(|k| line(points[k], points[(k + 1) % n]))
        .collect()
}

/// The ellipse with centre `c` and semi-axes `r` (along u and v) as one exact rational
/// quadratic curve of four 90° arcs (The NURBS Book §7.5, the nine-point circle).
pub fn ellipse(c: DVec2, r: DVec2) -> Result<TrimLoop, GeometryError> {
    if !c.is_finite() {
        return Err(construction(format!(
            "a circle needs a finite centre, got ({}, {})",
            c.x, c.y
        )));
    }
    if !(r.x > 0.0 && r.y > 0.0 && r.is_finite()) {
        return Err(construction(format!(
            "a circle needs a finite radius > 0, got ({}, {})",
            r.x, r.y
        )));
    }
    let unit = [
        (1.0, 0.0),
        (1.0, 1.0),
        (0.0, 1.0),
        (-1.0, 1.0),
        (-1.0, 0.0),
        (-1.0, -1.0),
        (0.0, -1.0),
        (1.0, -1.0),
        (1.0, 0.0),
    ];
    let points = unit
        .iter()
        .map(|&(x, y)| c + DVec2::new(x * r.x, y * r.y))
        .collect();
    let h = std::f64::consts::FRAC_1_SQRT_2;
    let weights = (0..9).map(|k| if k % 2 == 1 { h } else { 1.0 }).collect();
    let knots = vec![
        0.0, 0.0, 0.0, 0.25, 0.25, 0.5, 0.5, 0.75, 0.75, 1.0, 1.0, 1.0,
    ];
    Ok(vec![TrimCurve::new(2, knots, points, Some(weights))?])
}

/// The closed uniform cubic B-spline through `points` (at least 3): control points P solving
/// the cyclic system (P_{i−1} + 4 P_i + P_{i+1}) / 6 = Q_i (The NURBS Book §9.2.1 for the
/// periodic case), one curve over n uniform spans.
pub fn interpolating_loop(points: &[DVec2]) -> Result<TrimLoop, GeometryError> {
    let n = points.len();
    if n < 3 {
        return Err(construction(format!(
            "an interpolating loop needs at least 3 points, got {n}"
        )));
    }
    // Gauss–Seidel on the strictly diagonally dominant cyclic system.
    let mut p = points.to_vec();
    for _ in 0..200 {
        let mut change: f64 = 0.0;
        for i in 0..n {
            let next = (6.0 * points[i] - p[(i + n - 1) % n] - p[(i + 1) % n]) / 4.0;
            change = change.max((next - p[i]).length());
            p[i] = next;
        }
        if change < 1e-15 {
            break;
        }
    }
    // The periodic curve: P_{n−1}, P_0 .. P_{n−1}, P_0, P_1 over uniform knots; its domain
    // [3, n + 3] starts at (P_{n−1} + 4 P_0 + P_1) / 6 = Q_0.
    let mut control = vec![p[n - 1]];
    control.extend_from_slice(&p);
    control.extend([p[0], p[1]]);
    let knots = (0..control.len() + 4).map(|k| k as f64).collect();
    let curve = TrimCurve::new(3, knots, control, None)?.clamped();
    let (a, b) = curve.domain();
    Ok(vec![curve.reparametrized(0.0, (b - a).max(1e-300))?])
}

/// Loop `l` with control point `i` of curve `c` moved to `to`; a curve's end point moves the
/// neighbouring curve's matching end with it, so the loop stays closed.
pub fn move_loop_point(
    l: &TrimLoop,
    loop_index: usize,
    c: usize,
    i: usize,
    to: DVec2,
) -> Result<TrimLoop, GeometryError> {
    let curve = curve_of(l, loop_index, c)?;
    if i >= curve.count() || !to.is_finite() {
        return Err(construction(format!(
            "there is no control point {i} in curve {c} of loop {loop_index}"
        )));
    }
    let mut out = l.clone();
    let set = |curve: &TrimCurve, k: usize, to: DVec2| {
        let mut points: Vec<DVec2> = (0..curve.count()).map(|j| curve.control_point(j)).collect();
        let weights = (0..curve.count()).map(|j| curve.weight(j)).collect();
        points[k] = to;
        TrimCurve::new(
            curve.degree(),
            curve.knots().to_vec(),
            points,
            Some(weights),
        )
    };
    out[c] = set(curve, i, to)?;
    let n = l.len();
    if i == 0 && n > 1 {
        let prev = (c + n - 1) % n;
        out[prev] = set(&out[prev], out[prev].count() - 1, to)?;
    } else if i == 0 {
        let last = out[c].count() - 1;
        out[c] = set(&out[c], last, to)?;
    }
    if i == curve.count() - 1 && n > 1 {
        let next = (c + 1) % n;
        out[next] = set(&out[next], 0, to)?;
    } else if i == curve.count() - 1 {
        out[c] = set(&out[c], 0, to)?;
    }
    Ok(out)
}

/// Loop `l` with a control point added to curve `c` without changing its shape: a knot
/// inserted in the middle of the curve's longest span (The NURBS Book A5.1).
pub fn insert_loop_point(
    l: &TrimLoop,
    loop_index: usize,
    c: usize,
) -> Result<TrimLoop, GeometryError> {
    let curve = curve_of(l, loop_index, c)?;
    let knots = curve.knots();
    let (a, b) = curve.domain();
    let mut breaks: Vec<f64> = knots
        .iter()
        .copied()
        .filter(|&k| k >= a && k <= b)
        .collect();
    breaks.dedup();
    let (lo, hi) = breaks
        .windows(2)
        .map(|w| (w[0], w[1]))
        .max_by(|x, y| (x.1 - x.0).total_cmp(&(y.1 - y.0)))
        .unwrap_or((a, b));
    let mut out = l.clone();
    out[c] = curve.insert_knot(0.5 * (lo + hi), 1)?;
    Ok(out)
}

/// Loop `l` with interior control point `i` of curve `c` removed (a curve keeps at least
/// degree + 1 points; its knots become uniform; a curve's end points join the loop and stay).
pub fn delete_loop_point(
    l: &TrimLoop,
    loop_index: usize,
    c: usize,
    i: usize,
) -> Result<TrimLoop, GeometryError> {
    let curve = curve_of(l, loop_index, c)?;
    let n = curve.count();
    if i == 0 || i + 1 >= n {
        return Err(refuse(
            loop_index,
            c,
            TrimProblem::Curve(format!(
                "point {i} joins the curve to its neighbour; delete an interior point"
            )),
        ));
    }
    let degree = curve.degree().min(n - 2);
    if degree == 0 {
        return Err(refuse(
            loop_index,
            c,
            TrimProblem::Curve("the curve has no interior point to delete".into()),
        ));
    }
    let points: Vec<DVec2> = (0..n)
        .filter(|&j| j != i)
        .map(|j| curve.control_point(j))
        .collect();
    let weights = (0..n)
        .filter(|&j| j != i)
        .map(|j| curve.weight(j))
        .collect();
    let (a, b) = curve.domain();
    let m = points.len();
    let spans = m - degree;
    let mut knots = vec![a; degree + 1];
    knots.extend((1..spans).map(|k| a + (b - a) * k as f64 / spans as f64));
    knots.extend(vec![b; degree + 1]);
    let mut out = l.clone();
    out[c] = TrimCurve::new(degree, knots, points, Some(weights))?;
    Ok(out)
}
/// The (u, v) points of a regular `corners`-gon in model space, drawn on `surface`: centred at
/// S(`centre`) in the tangent plane there, through S(`through`), each corner pulled onto the
/// surface at its closest point (The NURBS Book §6.1). A shape that is round (or regular) in
/// model space rather than in the parameters, which a non-square domain would stretch.
pub fn model_space_corners(
    surface: &crate::NurbsSurface,
    centre: DVec2,
    through: DVec2,
    corners: usize,
) -> Result<Vec<DVec2>, GeometryError> {
    let local = surface.local_geometry(centre.x, centre.y)?;
    let (normal, origin) = (local.normal, local.derivatives.point);
    let arm = surface.point_at(through.x, through.y)? - origin;
    let arm = arm - normal * arm.dot(normal);
    if normal == glam::DVec3::ZERO || !(arm.length() > 1e-12) {
        return Err(GeometryError::Construction {
            what: "trim loop",
            message: "the two points are at the same place on the surface".into(),
        });
    }
    (0..corners)
        .map(|k| {
            let a = k as f64 * std::f64::consts::TAU / corners as f64;
            let q = origin + arm * a.cos() + normal.cross(arm) * a.sin();
            surface.closest_point(q).map(|c| DVec2::new(c.u, c.v))
        })
        .collect()
}
